/* The time-step controller alone (src/time/dt_control.h), no solver: accept and
 * reject, growth and cut bounds, Newton failures, restart after a division,
 * landing on events and on t_end without a sliver, and the fixed policy's
 * rules (the paper's runs). */
#include <math.h>

#include "check.h"
#include "model/division.h"
#include "time/dt_control.h"
#include "public/error.h"

static sp_dt_params adaptive_params(int order) {
  sp_dt_params p = {.policy = SP_DT_ADAPTIVE, .dt = 1e-3, .dt_min = 1e-12, .dt_max = 0.5,
                    .max_retries = 5, .shrink = 0.25, .grow = 2, .grow_after = 3,
                    .order = order, .event_first = 0.1, .event_growth = 2.4,
                    .event_steps = 3};
  return p;
}

static void check_judge(void) {
  sp_dt_control c;
  sp_dt_params p = adaptive_params(1);
  sp_dt_init(&c, &p, 1e-3);
  CHECK(c.dt_next == 1e-3, "first dt %g", c.dt_next);
  /* too large an error: rejected, cut, never by more than SP_DT_CUT_MIN */
  CHECK(sp_dt_judge(&c, 1e-3, 4.0) == SP_DT_REJECT, "err 4 accepted");
  CHECK(c.dt_next < 1e-3 && c.dt_next >= SP_DT_CUT_MIN * 1e-3 * (1 - 1e-15),
        "retry after err 4: %g", c.dt_next);
  CHECK_NEAR(c.dt_next, SP_DT_SAFETY * pow(4.0, -0.5) * 1e-3, 1e-18);
  CHECK(sp_dt_judge(&c, 1e-3, 1e6) == SP_DT_REJECT, "err 1e6 accepted");
  CHECK_NEAR(c.dt_next, SP_DT_CUT_MIN * 1e-3, 1e-18);
  CHECK(sp_dt_judge(&c, 1e-3, NAN) == SP_DT_REJECT, "a NaN estimate accepted");
  CHECK(sp_dt_judge(&c, 1e-3, INFINITY) == SP_DT_REJECT, "an infinite estimate accepted");
  CHECK(c.failures == 4 && c.n_rejected == 4, "failures %d, rejected %ld", c.failures,
        c.n_rejected);
  CHECK(!sp_dt_give_up(&c), "gave up after 4 of 5 retries");
  CHECK(sp_dt_judge(&c, 1e-3, 3.0) == SP_DT_REJECT, "err 3 accepted");
  CHECK(!sp_dt_give_up(&c), "gave up after 5 of 5 retries");
  CHECK(sp_dt_judge(&c, 1e-3, 3.0) == SP_DT_REJECT && sp_dt_give_up(&c),
        "no give-up after 6 failed attempts (max_retries 5)");
  /* on tolerance: accepted */
  sp_dt_init(&c, &p, 1e-3);
  CHECK(sp_dt_judge(&c, 1e-3, 1.0) == SP_DT_ACCEPT, "err 1 rejected");
  CHECK(sp_dt_judge(&c, 1e-3, 0.999) == SP_DT_ACCEPT, "err 0.999 rejected");
  /* the fixed policy accepts whatever the estimate (it has none) */
  sp_dt_params f = p;
  f.policy = SP_DT_FIXED;
  sp_dt_init(&c, &f, 0);
  CHECK(sp_dt_judge(&c, 1e-3, 100.0) == SP_DT_ACCEPT, "fixed policy rejected a step");
}

static void check_growth(void) {
  sp_dt_control c;
  sp_dt_params p = adaptive_params(2);
  sp_dt_init(&c, &p, 1e-3);
  /* a tiny error: growth by exactly SP_DT_GROW_MAX, never more */
  sp_dt_accepted(&c, 1e-3, 1e-12);
  CHECK_NEAR(c.dt_next, SP_DT_GROW_MAX * 1e-3, 1e-18);
  sp_dt_accepted(&c, c.dt_next, 0.0);
  CHECK_NEAR(c.dt_next, SP_DT_GROW_MAX * SP_DT_GROW_MAX * 1e-3, 1e-18);
  /* the PI law: err 0.5 after err_prev */
  sp_dt_init(&c, &p, 1e-3);
  sp_dt_accepted(&c, 1e-3, 0.8);
  const double expect1 = 1e-3 * SP_DT_SAFETY * pow(0.8, -0.7 / 3);
  CHECK_NEAR(c.dt_next, expect1, 1e-15);
  sp_dt_accepted(&c, 1e-3, 0.5);
  const double expect2 = 1e-3 * SP_DT_SAFETY * pow(0.5, -0.7 / 3) * pow(0.8, 0.4 / 3);
  CHECK_NEAR(c.dt_next, expect2, 1e-15);
  /* after a rejection the next accepted step does not grow dt */
  sp_dt_init(&c, &p, 1e-3);
  CHECK(sp_dt_judge(&c, 1e-3, 2.0) == SP_DT_REJECT, "err 2 accepted");
  const double retry = c.dt_next;
  sp_dt_accepted(&c, retry, 1e-6);
  CHECK(c.dt_next <= retry, "grew right after a rejection: %g > %g", c.dt_next, retry);
  CHECK(c.failures == 0, "failures not reset by an accepted step");
  /* bounded by dt_max and dt_min */
  sp_dt_init(&c, &p, 0.4);
  sp_dt_accepted(&c, 0.4, 1e-9);
  CHECK(c.dt_next == 0.5, "dt_max not respected: %g", c.dt_next);
  /* no estimate (first step): dt held */
  sp_dt_init(&c, &p, 1e-7);
  sp_dt_accepted(&c, 1e-7, -1.0);
  CHECK(c.dt_next == 1e-7, "dt changed without an estimate: %g", c.dt_next);
}

static void check_newton_failure(void) {
  sp_dt_control c;
  sp_dt_params p = adaptive_params(1);
  p.dt_min = 1e-6;
  sp_dt_init(&c, &p, 1e-3);
  CHECK(!sp_dt_newton_failed(&c, 1e-3), "gave up after one failure");
  CHECK_NEAR(c.dt_next, 0.25e-3, 1e-18);
  CHECK(!sp_dt_newton_failed(&c, c.dt_next), "gave up after two failures");
  CHECK(!sp_dt_newton_failed(&c, c.dt_next), "gave up after three failures");
  CHECK(!sp_dt_newton_failed(&c, c.dt_next), "gave up after four failures");
  /* 1e-3 / 4^5 < dt_min = 1e-6 */
  CHECK(sp_dt_newton_failed(&c, c.dt_next), "no give-up below dt_min: %g", c.dt_next);
}

/* The paper's policy as the stepper had it: shrink on failure, grow by grow
 * every grow_after successes up to dt_bar, failure memory, algorithm 2. */
static void check_fixed(void) {
  sp_dt_params p = {.policy = SP_DT_FIXED, .dt = 2e-4, .dt_min = 1e-14, .dt_max = 1,
                    .max_retries = 30, .shrink = 0.25, .grow = 2, .grow_after = 3,
                    .ramp_n_div = 3, .ramp_m = 6, .order = 1};
  sp_dt_control c;
  sp_dt_init(&c, &p, 123.0);
  CHECK(sp_dt_propose(&c, 0, 1, NULL) == 2e-4, "fixed first dt %g", c.dt_next);
  sp_dt_newton_failed(&c, 2e-4);
  CHECK(c.dt_next == 5e-5, "after a failure %g", c.dt_next);
  double seen[7];
  for (int i = 0; i < 7; ++i) {
    seen[i] = sp_dt_propose(&c, 0, 1, NULL);
    sp_dt_accepted(&c, seen[i], -1);
  }
  CHECK(seen[0] == 5e-5 && seen[2] == 5e-5 && seen[3] == 1e-4 && seen[5] == 1e-4 &&
            seen[6] == 2e-4,
        "regrowth %g %g %g %g %g %g %g", seen[0], seen[1], seen[2], seen[3], seen[4], seen[5],
        seen[6]);
  /* algorithm 2 after a division: dt_bar 10^-m ramp^m, n_div steps first */
  sp_dt_restart(&c, 99.0);
  for (int a = 1; a <= 6; ++a) {
    const double dt = sp_dt_propose(&c, 0, 1, NULL);
    CHECK(dt == sp_division_dt(2e-4, 3, 6, a), "ramp step %d: %g, expected %g", a, dt,
          sp_division_dt(2e-4, 3, 6, a));
    sp_dt_accepted(&c, dt, -1);
  }
  /* failure memory: dt stays <= dt_f / grow for so many steps */
  p.failure_memory = 4;
  sp_dt_init(&c, &p, 0);
  sp_dt_newton_failed(&c, 2e-4);
  double largest = 0;
  for (int i = 0; i < 4; ++i) {
    const double dt = sp_dt_propose(&c, 0, 1, NULL);
    largest = fmax(largest, dt);
    sp_dt_accepted(&c, dt, -1);
  }
  CHECK(largest <= 1e-4, "failure memory: %g after failing at 2e-4", largest);
}

/* Landing: on an event within reach, exactly; no sliver short of it. */
static void check_landing(void) {
  sp_dt_params p = adaptive_params(1);
  sp_dt_control c;
  sp_dt_init(&c, &p, 1e-3);
  int lands;
  double dt = sp_dt_propose(&c, 0.0, 0.0009, &lands);
  CHECK(lands && dt == 0.0009, "within reach: dt %g, lands %d", dt, lands);
  dt = sp_dt_propose(&c, 0.0, 0.0015, &lands);
  CHECK(!lands && dt == 0.00075, "1.5 steps away: dt %g (expected two of 7.5e-4)", dt);
  dt = sp_dt_propose(&c, 0.0, 0.0025, &lands);
  CHECK(!lands && dt == 1e-3, "2.5 steps away: dt %g", dt);
  dt = sp_dt_propose(&c, 0.1, 0.1 + 1e-3 * (1 + 1e-9), &lands);
  CHECK(lands, "round-off beyond one step does not land");

  /* A whole run to t_end = 0.0137 with events at 0.005 and 0.01 and an
   * error model err = (dt / 1e-3)^2: every event hit exactly, the last step
   * on t_end, and no step below half of the one before it that was not cut
   * by the error (no sliver). */
  const double t_end = 0.0137, events[] = {0.005, 0.01, t_end};
  sp_dt_init(&c, &p, 1e-5);
  double t = 0, dt_prev = 0;
  int e = 0, steps = 0, hit = 0;
  while (t < t_end && steps < 10000) {
    dt = sp_dt_propose(&c, t, events[e], &lands);
    const double err = (dt / 1e-3) * (dt / 1e-3);
    if (sp_dt_judge(&c, dt, err) == SP_DT_REJECT) continue;
    sp_dt_accepted(&c, dt, err);
    CHECK(!(dt_prev > 0 && dt < 0.45 * dt_prev), "sliver: step %d of %g after %g", steps, dt,
          dt_prev);
    t = lands ? events[e] : t + dt;
    dt_prev = dt;
    ++steps;
    if (lands) {
      CHECK(t == events[e], "landed at %.17g, event %.17g", t, events[e]);
      ++hit;
      ++e;
    }
  }
  CHECK(hit == 3 && t == t_end, "%d events hit, t = %.17g", hit, t);
  CHECK(c.n_rejected <= 2, "%ld rejections on a smooth error model", c.n_rejected);
  printf("landing: %d steps, %ld rejected, last dt %g\n", steps, c.n_rejected, dt_prev);
}

static void check_restart(void) {
  sp_dt_params p = adaptive_params(2);
  sp_dt_control c;
  sp_dt_init(&c, &p, 1e-6);
  sp_dt_accepted(&c, 1e-6, 0.3);
  sp_dt_accepted(&c, c.dt_next, 0.3);
  CHECK(c.err_prev > 0 && c.dt_next > 1e-6, "no growth on small errors");
  sp_dt_restart(&c, 2e-8);
  CHECK(c.dt_next == 2e-8 && c.err_prev == 0 && c.since_restart == 0,
        "restart: dt %g, err_prev %g, since %d", c.dt_next, c.err_prev, c.since_restart);
  sp_dt_accepted(&c, 2e-8, -1);
  CHECK(c.dt_next == 2e-8, "first step after a restart has no estimate: dt %g", c.dt_next);
  /* at most event_first of the step the controller wanted next */
  sp_dt_accepted(&c, 3e-6, 0.5);
  const double wanted = c.dt_next;
  sp_dt_restart(&c, 1.0);
  CHECK(c.dt_next == p.event_first * wanted, "restart after 3e-6 (next %g): dt %g", wanted,
        c.dt_next);
  /* the event_steps steps after it grow from their estimate alone, up to
   * event_growth within BDF2's ratio limit (the PI law would give 0.9
   * 1e-4^(-0.7/3) 0.5^(0.4/3) > 2, capped at 2); no growth after a
   * rejection; then the PI law again */
  double dt = c.dt_next;
  sp_dt_accepted(&c, dt, -1);
  CHECK(c.dt_next == dt, "no estimate after the event: dt held, %g", c.dt_next);
  /* ... unless its increment says more: an increment of 30 x the
   * tolerance (a cut relaxing) gives r^2 / (2r + 1) x 30 = 0.9 */
  sp_dt_unestimated(&c, dt, 30.0);
  const double r = 0.03 + sqrt(0.03 * 0.03 + 0.03);
  CHECK_NEAR(c.dt_next, r * dt, 1e-15 * dt);
  CHECK_NEAR(r * r / (2 * r + 1) * 30.0, SP_DT_SAFETY, 1e-12);
  sp_dt_unestimated(&c, dt, 1e-3); /* a small one: the growth cap */
  CHECK_NEAR(c.dt_next, SP_DT_BDF2_RATIO_MAX * dt, 1e-15 * dt);
  c.dt_next = dt;
  sp_dt_accepted(&c, dt, 1e-4);
  CHECK_NEAR(c.dt_next, fmin(p.event_growth, SP_DT_BDF2_RATIO_MAX) * dt, 1e-15 * dt);
  dt = c.dt_next;
  CHECK(sp_dt_judge(&c, dt, 2.0) == SP_DT_REJECT, "err 2 accepted after the event");
  const double retry = c.dt_next;
  sp_dt_accepted(&c, retry, 0.5);
  CHECK(c.dt_next == retry, "growth right after a rejection: %g from %g", c.dt_next, retry);
  dt = c.dt_next;
  sp_dt_accepted(&c, dt, 1e-4); /* the 4th step: the PI law, at most 2 */
  CHECK_NEAR(c.dt_next, SP_DT_GROW_MAX * dt, 1e-15 * dt);
  /* BE: no ratio limit, event_growth itself */
  sp_dt_params pb = adaptive_params(1);
  pb.event_growth = 8.0;
  sp_dt_init(&c, &pb, 1e-6);
  sp_dt_accepted(&c, 1e-6, 0.5);
  sp_dt_restart(&c, 1.0);
  dt = c.dt_next;
  sp_dt_accepted(&c, dt, 1e-6);
  CHECK_NEAR(c.dt_next, 8.0 * dt, 1e-15 * dt);
  /* beyond the step wanted before the event no faster than the PI law */
  CHECK(c.dt_next < c.event_dt, "regrowth %g past the step before %g", c.dt_next, c.event_dt);
  dt = c.dt_next;
  sp_dt_accepted(&c, dt, 1e-6);
  CHECK_NEAR(c.dt_next, SP_DT_GROW_MAX * dt, 1e-15 * dt);
}

/* A second rejection of a step whose estimate falls more slowly than
 * dt^k (k = order + 1): the cut uses the exponent observed over the two
 * attempts. An estimate err = 4 (dt / 1e-3)^(1/2) (BDF2, k = 3) is met
 * within three rejections; one that scales as dt^3 keeps k; one that does
 * not fall takes the largest cut; an accepted step forgets. */
static void check_observed_exponent(void) {
  sp_dt_control c;
  sp_dt_params p = adaptive_params(2);
  sp_dt_init(&c, &p, 1e-3);
  double dt = 1e-3;
  int rejected = 0;
  while (sp_dt_judge(&c, dt, 4 * sqrt(dt / 1e-3)) == SP_DT_REJECT && rejected < 10) {
    const double err = 4 * sqrt(dt / 1e-3);
    if (rejected == 0)
      CHECK_NEAR(c.dt_next, dt * SP_DT_SAFETY * pow(err, -1.0 / 3), 1e-18);
    else /* the observed exponent 1/2 */
      CHECK_NEAR(c.dt_next, dt * fmax(SP_DT_CUT_MIN, SP_DT_SAFETY * pow(err, -2.0)), 1e-18);
    dt = c.dt_next;
    ++rejected;
  }
  CHECK(rejected <= 3, "%d rejections of an estimate ~ dt^(1/2)", rejected);
  /* an estimate that falls as fast as dt^4 (> k): the cut keeps k = 3 */
  sp_dt_init(&c, &p, 1e-3);
  CHECK(sp_dt_judge(&c, 1e-3, 1e3) == SP_DT_REJECT, "err 1e3 accepted");
  dt = c.dt_next; /* the largest cut, 2e-4: err 1e3 x 0.2^4 = 1.6 */
  const double err_fast = 1e3 * pow(dt / 1e-3, 4);
  CHECK(sp_dt_judge(&c, dt, err_fast) == SP_DT_REJECT, "err %g accepted", err_fast);
  CHECK_NEAR(c.dt_next, dt * SP_DT_SAFETY * pow(err_fast, -1.0 / 3), 1e-18);
  /* no decrease: the largest cut */
  sp_dt_init(&c, &p, 1e-3);
  CHECK(sp_dt_judge(&c, 1e-3, 2.0) == SP_DT_REJECT, "err 2 accepted");
  dt = c.dt_next;
  CHECK(sp_dt_judge(&c, dt, 2.5) == SP_DT_REJECT, "err 2.5 accepted");
  CHECK_NEAR(c.dt_next, dt * SP_DT_CUT_MIN, 1e-18);
  /* accepted: the next step's first rejection uses k again */
  sp_dt_accepted(&c, c.dt_next, 0.5);
  dt = c.dt_next;
  CHECK(sp_dt_judge(&c, dt, 4.0) == SP_DT_REJECT, "err 4 accepted");
  CHECK_NEAR(c.dt_next, dt * SP_DT_SAFETY * pow(4.0, -1.0 / 3), 1e-18);
}

int main(void) {
  check_judge();
  check_observed_exponent();
  check_growth();
  check_newton_failure();
  check_fixed();
  check_landing();
  check_restart();
  TEST_DONE();
}
