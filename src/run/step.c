/* One step: an attempt with a verdict, and its completion (step.h). */
#include "run/step.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/agree.h"
#include "model/cells.h"
#include "public/error.h"
#include "run/events.h"
#include "base/fault.h"
#include "run/run_energy.h"
#include "model/shape.h"
#include "run/solver_status.h"
#include "model/source.h"
#include "run/stop.h"
#include "time/time_scheme.h"
#include "base/wall_clock.h"

/** Extrapolations from the last step (solver.predictor linear, the
 *  source's indicator) scale its increment by dt / dt_last, at most this
 *  much: algorithm 2's ramp multiplies dt by up to 64, and after a short
 *  step (a landing on a mass crossing) Newton's error in its increment
 *  would be amplified by the ratio. */
#define SP_PREDICTOR_MAX_RATIO 2.0

/** How far ahead of t^n an extrapolation from the last step reaches for a
 *  step of length dt. */
static double extrapolation_dt(const sp_run *run, double dt) {
  return run->hist.n >= 1 ? fmin(dt, SP_PREDICTOR_MAX_RATIO * run->hist.dt[0]) : dt;
}

void sp_step_begin(sp_run *run) {
  if (run->restarted) sp_dt_resume(&run->dtc, &run->opt.time.dt); /* state: the checkpoint's */
  else sp_dt_init(&run->dtc, &run->opt.time.dt, sp_events_first_dt(run));
}

int sp_step_run_ends(const sp_run *run) {
  const sp_run_time *tc = &run->opt.time;
  return !(run->t < tc->t_end - 1e-12 * tc->t_end && run->step < tc->max_steps);
}

/** The scene has a shape term (a shape.delta* > 0). */
static int shape_on(const sp_run_terms *terms) {
  return terms->shape_delta[0] > 0 || terms->shape_delta[1] > 0 || terms->shape_delta[2] > 0;
}

/** The step's source and shape coefficients from c^n (the state before the
 *  step and its observables). The source's indicator of a BDF2 step is
 *  taken at c extrapolated linearly to t^n + dt (at most twice the last
 *  step ahead, as the predictor; into state_eff, which the step's c_hat
 *  overwrites next): from c^n it would lag the moving
 *  interface by a step, a first-order error in each cell's mass that the
 *  error estimate cannot see (docs/time-stepping.md). */
static int explicit_terms(sp_run *run, sp_scheme_kind kind, double dt) {
  const sp_run_terms *terms = &run->opt.terms;
  sp_registry *cells = &run->cells;
  const int n_cells = run->layout->n_cells;
  if (terms->source_rate > 0) {
    const double *at = run->buf.state_old;
    if (kind == SP_SCHEME_BDF2 && terms->source_extrapolated) {
      sp_scheme_extrapolate(1, &run->hist, extrapolation_dt(run, dt), run->buf.state_old,
                            (size_t)run->layout->n_pairs, run->buf.state_eff);
      at = run->buf.state_eff;
    }
    SP_CALL(sp_source_fill(run->layout, at, n_cells, cells->source_on, terms->source_rate,
                           run->buf.source));
  }
  if (!shape_on(terms)) return SP_OK;
  /* from the observables of c^n; implicit steps follow the new moments
   * through the gains */
  SP_CALL(sp_shape_coefficients(run->mesh->dim, n_cells, cells->obs, cells->birth,
                                terms->shape_delta, cells->shape));
  /* the term is the derivative of the moments, which count c only where
   * c >= the observables' threshold: it acts there only */
  for (int k = 0; k < n_cells; ++k) cells->shape[k].threshold = run->opt.division.observe_threshold;
  return SP_OK;
}

/** The step's data for the solver: backward Euler from c^n, or BDF2 in its
 *  backward-Euler form from c_hat (time_scheme.h); Newton's error a small
 *  part of the step's under adaptive control. */
static sp_step_data step_data(sp_run *run, sp_scheme_kind kind, double dt) {
  const sp_run_options *o = &run->opt;
  sp_step_data data = {.dt = dt, .model = o->model, .state_old = run->buf.state_old,
                       .source = o->terms.source_rate > 0 ? run->buf.source : NULL,
                       .shape = shape_on(&o->terms) ? run->cells.shape : NULL,
                       .shape_implicit = o->terms.shape_implicit,
                       .interrupt = sp_stop_poll, .interrupt_ctx = run};
  if (kind != SP_SCHEME_BE) {
    sp_scheme_be_form(kind, &run->hist, dt, run->buf.state_old, (size_t)run->layout->n_pairs,
                      run->buf.state_eff, &data.dt);
    data.state_old = run->buf.state_eff;
  }
  if (o->time.adaptive) {
    data.update_rtol = SP_SCHEME_NEWTON_FRACTION * o->time.rtol;
    data.update_atol = SP_SCHEME_NEWTON_FRACTION * o->time.atol;
  }
  return data;
}

/** The verdict on a solved attempt (Newton's status @p solved): the
 *  controller's on Newton and on the error estimate, then the landing
 *  rule of the mass criterion (events.h). */
static int judge(sp_run *run, sp_scheme_kind kind, int solved, sp_step_attempt *a) {
  const sp_run_time *tc = &run->opt.time;
  a->why = a->report.reason;
  if (solved == 0 && tc->adaptive) {
    a->err = sp_scheme_error(kind, &run->hist, a->dt, run->buf.state_old, run->state,
                             (size_t)run->layout->n_pairs, tc->rtol, tc->atol, run->buf.scratch);
    snprintf(a->why_text, sizeof a->why_text,
             "local error estimate %.3g x the tolerance (time.rtol, time.atol)", a->err);
    a->why = a->why_text;
  }
  if (solved != 0 && a->report.failure == SP_NEWTON_INTERRUPTED) {
    /* dropped: the controller and the carried factorisation as before the
     * step's first attempt, so a checkpoint now is the one the last step's
     * end would have written */
    a->verdict = SP_STEP_INTERRUPTED;
    run->dtc = run->dtc_step_start;
    const int rc = sp_solver_carry_rewind(run->solver);
    return rc == SP_SOLVER_OK
               ? SP_OK
               : sp_solver_failed(run->solver, rc, "dropping step %d", run->step + 1);
  }
  if (solved != 0) {
    a->verdict = SP_STEP_NEWTON_FAILED;
    a->give_up = sp_dt_newton_failed(&run->dtc, a->dt);
    /* the factors did not fit in memory: a smaller step has a matrix of
     * the same size and pattern, so retrying only repeats the failure */
    if (a->report.failure == SP_NEWTON_OUT_OF_MEMORY) a->give_up = 1;
    return SP_OK;
  }
  if (sp_dt_judge(&run->dtc, a->dt, a->err) == SP_DT_REJECT) {
    a->verdict = SP_STEP_ERROR_TOO_LARGE;
    a->give_up = sp_dt_give_up(&run->dtc);
    return SP_OK;
  }
  double theta;
  SP_CALL(sp_events_landing(run, a->t, a->dt, &a->observed, &theta));
  if (theta < 1) { /* land on the crossing: redo the step shorter */
    sp_dt_land(&run->dtc, theta * a->dt);
    a->why = "a cell's mass passed its division mass inside the step (landing on it)";
    a->err = -1.0;
    a->verdict = SP_STEP_LANDING;
    return SP_OK;
  }
  a->verdict = SP_STEP_ACCEPTED;
  return SP_OK;
}

/** The error that ends a run whose step @p a failed and will not be
 *  retried: out of memory (a smaller step has a matrix of the same size),
 *  or the retries spent. */
static int gave_up(const sp_run *run, const sp_step_attempt *a) {
  const sp_dt_params *p = &run->opt.time.dt;
  if (a->verdict == SP_STEP_NEWTON_FAILED && a->report.failure == SP_NEWTON_OUT_OF_MEMORY)
    return sp_error_set(SP_ERR_MEMORY,
                        "step %d at t = %.6g: %s. A smaller step has a matrix of the same size, "
                        "so it is not retried; per unknown solver.linear gmres_amg needs the "
                        "least memory (no factorisation), gmres_cells less than mumps or "
                        "superlu_dist, and processes on more machines split it "
                        "(docs/solvers.md)",
                        run->step + 1, run->t, a->why);
  return sp_error_set(SP_ERR_SOLVER,
                      "step %d at t = %.6g failed %d attempts "
                      "(last dt = %.3g; time.max_retries = %d, time.dt_min = %.3g): %s",
                      run->step + 1, run->t, run->dtc.failures, a->dt, p->max_retries,
                      p->dt_min, a->why);
}

int sp_step_try(sp_run *run, sp_step_attempt *a) {
  *a = (sp_step_attempt){.verdict = SP_STEP_FATAL, .wall_start = sp_wall_clock(), .t = run->t,
                         .err = -1.0};
  const size_t n_pairs = (size_t)run->layout->n_pairs, n_values = 2 * n_pairs;
  const int first_attempt = run->marked_step != run->step + 1;
  if (first_attempt) {
    run->dtc_step_start = run->dtc;
    run->marked_step = run->step + 1;
    const int rc = sp_solver_carry_mark(run->solver);
    if (rc != SP_SOLVER_OK) return sp_solver_failed(run->solver, rc, "step %d", run->step + 1);
  }
  sp_fault_attempt_begin(run->step + 1, first_attempt);
  const double t_event = sp_events_next(run, run->t);
  a->dt = sp_dt_propose(&run->dtc, run->t, t_event, &a->lands);
  a->t_new = a->lands ? t_event : run->t + a->dt;
  memcpy(run->buf.state_old, run->state, n_values * sizeof(double));
  if (run->opt.time.predictor_linear) /* Newton starts from the extrapolation */
    sp_scheme_extrapolate(1, &run->hist, extrapolation_dt(run, a->dt), run->buf.state_old,
                          n_pairs, run->state);
  const sp_scheme_kind kind = sp_scheme_of_step(run->opt.time.scheme, &run->hist);
  int rc = explicit_terms(run, kind, a->dt);
  if (rc == SP_OK) rc = sp_fault_check(SP_FAULT_STEP, run->rank);
  SP_CALL(sp_agree(run->agree_comm, rc)); /* Newton's collectives follow */
  const sp_step_data data = step_data(run, kind, a->dt);
  const int solved = sp_solver_step(run->solver, &data, run->state, &a->report);
  if (solved > SP_SOLVER_NOT_CONVERGED)
    return sp_solver_failed(run->solver, solved, "step %d at t = %g", run->step + 1, run->t);
  SP_CALL(judge(run, kind, solved, a));
  if (a->verdict != SP_STEP_ACCEPTED) /* retried from the last good state */
    memcpy(run->state, run->buf.state_old, n_values * sizeof(double));
  return a->give_up ? gave_up(run, a) : SP_OK;
}

int sp_step_complete(sp_run *run, const sp_step_attempt *a) {
  const sp_run_options *o = &run->opt;
  sp_registry *cells = &run->cells;
  const int n_cells = run->layout->n_cells;
  const size_t n_values = 2 * (size_t)run->layout->n_pairs;
  run->t = a->t_new;
  ++run->step;
  sp_dt_accepted(&run->dtc, a->dt, a->err);
  if (o->time.adaptive && a->err < 0) /* the next step from this one's increment */
    sp_dt_unestimated(&run->dtc, a->dt,
                      sp_scheme_increment(run->buf.state_old, run->state,
                                          (size_t)run->layout->n_pairs, o->time.rtol,
                                          o->time.atol));
  /* the past states: for the scheme, the error estimate, the predictor */
  if (sp_run_keeps_history(o))
    SP_CALL(sp_history_push(&run->hist, run->buf.state_old, a->dt, n_values));
  /* the core masses before the step, for crossing-safe criteria */
  for (int k = 0; k < n_cells; ++k) cells->core_mass_old[k] = cells->obs[k].mass_core;
  if (a->observed) {
    memcpy(cells->obs, cells->obs_new, sizeof *cells->obs * (size_t)n_cells);
    return SP_OK;
  }
  return sp_run_observe(run, cells->obs);
}
