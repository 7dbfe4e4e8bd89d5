#include "time/dt_control.h"

#include <math.h>

#include "model/division.h"

void sp_dt_init(sp_dt_control *c, const sp_dt_params *p, double dt_first) {
  *c = (sp_dt_control){.p = *p, .ceiling = p->dt, .since_restart = -1};
  c->dt_next = p->policy == SP_DT_FIXED ? p->dt : fmin(dt_first, p->dt_max);
}

/** The fixed policy's cap: dt_bar, or below a failed dt for a while. */
static double fixed_cap(const sp_dt_control *c) {
  return c->ceiling_steps > 0 ? fmin(c->p.dt, c->ceiling) : c->p.dt;
}

double sp_dt_propose(const sp_dt_control *c, double t, double t_event, int *lands) {
  double dt = c->dt_next;
  if (c->p.policy == SP_DT_FIXED && c->since_restart >= 0 && c->p.ramp_m > 0)
    dt = fmin(dt, sp_division_dt(c->p.dt, c->p.ramp_n_div, c->p.ramp_m, c->since_restart + 1));
  const double rest = t_event - t;
  int land = 0;
  if (rest <= dt * (1 + SP_DT_STRETCH)) { /* the event is within reach: land on it */
    dt = rest;
    land = 1;
  } else if (rest < 2 * dt * (1 - SP_DT_STRETCH)) { /* one step would leave a sliver */
    dt = 0.5 * rest;
  }
  if (lands) *lands = land;
  return dt;
}

int sp_dt_give_up(const sp_dt_control *c) {
  return c->failures > c->p.max_retries || c->dt_next < c->p.dt_min;
}

int sp_dt_newton_failed(sp_dt_control *c, double dt) {
  ++c->failures;
  ++c->n_newton_failed;
  c->successes = 0;
  c->dt_next = dt * c->p.shrink;
  if (c->p.policy == SP_DT_FIXED && c->p.failure_memory > 0) {
    c->ceiling = fmax(c->dt_next, dt / c->p.grow);
    c->ceiling_steps = c->p.failure_memory;
  }
  c->rejected_last = 1;
  c->rejected_dt = c->rejected_err = 0; /* (judge's exponent: rejections only) */
  return sp_dt_give_up(c);
}

/** The PI controller's factor for an estimate err of an accepted step. */
static double pi_factor(const sp_dt_control *c, double err) {
  const double k = c->p.order + 1;
  if (!(err > 0)) return SP_DT_GROW_MAX;
  double f = SP_DT_SAFETY * pow(err, -0.7 / k);
  if (c->err_prev > 0) f *= pow(c->err_prev, 0.4 / k);
  f = fmin(f, c->rejected_last ? 1.0 : SP_DT_GROW_MAX);
  return fmax(f, SP_DT_CUT_MIN);
}

/** Adaptive: the accepted step is one of the first time.event_steps after
 *  an event (a division), whose history started over. */
static int after_event(const sp_dt_control *c) {
  return c->p.policy == SP_DT_ADAPTIVE && c->since_restart >= 1 &&
         c->since_restart <= c->p.event_steps;
}

/** The growth cap of a step just after an event: time.event_growth instead
 *  of SP_DT_GROW_MAX, within BDF2's step-ratio limit. */
static double event_cap(const sp_dt_control *c) {
  return c->p.order >= 2 ? fmin(c->p.event_growth, SP_DT_BDF2_RATIO_MAX) : c->p.event_growth;
}

/** The growth factor of a step just after an event: the estimate alone (no
 *  PI memory: the step before the event says nothing about the state after
 *  it), up to event_cap; no growth right after a rejection, as the PI law. */
static double event_factor(const sp_dt_control *c, double err) {
  const double k = c->p.order + 1;
  const double cap = c->rejected_last ? 1.0 : event_cap(c);
  const double f = err > 0 ? SP_DT_SAFETY * pow(err, -1.0 / k) : cap;
  return fmax(fmin(f, cap), SP_DT_CUT_MIN);
}

sp_dt_verdict sp_dt_judge(sp_dt_control *c, double dt, double err) {
  if (c->p.policy == SP_DT_FIXED || err <= 1) return SP_DT_ACCEPT; /* NaN rejects */
  double k = c->p.order + 1;
  /* A second rejection of the step: the estimate's exponent as observed
   * over the two attempts, when it is below the method's (the estimate is
   * dominated by something that does not scale as dt^k, e.g. a transient
   * after a support change). 0 < exponent: as observed; no decrease: the
   * largest cut. */
  if (c->rejected_dt > dt && isfinite(err)) {
    const double q = log(c->rejected_err / err) / log(c->rejected_dt / dt);
    k = q > 0 ? fmin(q, k) : 0;
  }
  double f = isfinite(err) && k > 0 ? SP_DT_SAFETY * pow(err, -1.0 / k) : SP_DT_CUT_MIN;
  f = fmin(fmax(f, SP_DT_CUT_MIN), SP_DT_SAFETY);
  ++c->failures;
  ++c->n_rejected;
  c->dt_next = dt * f;
  c->rejected_last = 1;
  c->rejected_dt = isfinite(err) ? dt : 0;
  c->rejected_err = isfinite(err) ? err : 0;
  return SP_DT_REJECT;
}

void sp_dt_accepted(sp_dt_control *c, double dt, double err) {
  ++c->n_accepted;
  c->failures = 0;
  c->rejected_dt = c->rejected_err = 0;
  c->dt_last = dt;
  if (c->since_restart >= 0) ++c->since_restart;
  if (c->p.policy == SP_DT_FIXED) { /* today's policy, the paper's runs */
    if (c->ceiling_steps > 0) --c->ceiling_steps;
    const double cap = fixed_cap(c);
    if (++c->successes >= c->p.grow_after && c->dt_next < cap) {
      c->dt_next = fmin(c->dt_next * c->p.grow, cap);
      c->successes = 0;
    }
    return;
  }
  double next;
  if (err < 0) next = dt; /* no estimate: hold dt until there is one */
  else if (!after_event(c)) next = dt * pi_factor(c, err);
  else /* fast back to the step wanted before the event, beyond it the PI law */
    next = fmin(dt * event_factor(c, err), fmax(c->event_dt, dt * pi_factor(c, err)));
  /* a step shortened to land on an event says nothing against the step
   * the controller wanted: go back to it unless the estimate says shrink */
  if (dt < c->dt_next * (1 - SP_DT_STRETCH) && !(next < dt)) next = fmax(next, c->dt_next);
  c->dt_next = fmax(fmin(next, c->p.dt_max), c->p.dt_min);
  if (err >= 0) c->err_prev = fmax(err, 1e-4);
  c->rejected_last = 0;
}

void sp_dt_unestimated(sp_dt_control *c, double dt, double increment) {
  if (c->p.policy != SP_DT_ADAPTIVE || !(increment > 0)) return;
  /* the next step's estimate is BE's, r / (2r + 1) |c - P| with P linear
   * through this step: if the state then stops changing (a transient that
   * has relaxed), |c - P| = r x this increment; r such that r^2 / (2r + 1)
   * x increment = SP_DT_SAFETY */
  const double a = SP_DT_SAFETY / increment, r = a + sqrt(a * a + a);
  const double cap = after_event(c) ? event_cap(c) : SP_DT_GROW_MAX;
  c->dt_next = fmax(fmin(dt * fmin(r, cap), c->p.dt_max), c->p.dt_min);
}

void sp_dt_restart(sp_dt_control *c, double dt_first) {
  c->since_restart = 0;
  if (c->p.policy == SP_DT_FIXED) {
    c->dt_next = fixed_cap(c); /* algorithm 2's ramp now sets the pace */
    return;
  }
  /* the step before: the one the controller wanted next (a step shortened
   * to land on the division is not the pace of the run) */
  c->event_dt = c->dt_next;
  if (c->dt_last > 0) dt_first = fmin(dt_first, c->p.event_first * c->dt_next);
  c->dt_next = fmax(fmin(dt_first, c->p.dt_max), c->p.dt_min);
  c->err_prev = 0;
  c->rejected_last = 0;
  c->rejected_dt = c->rejected_err = 0;
}

void sp_dt_land(sp_dt_control *c, double dt) { c->dt_next = fmax(dt, c->p.dt_min); }

void sp_dt_resume(sp_dt_control *c, const sp_dt_params *p) { c->p = *p; }
