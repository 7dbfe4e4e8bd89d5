/**
 * @file step.h
 * @brief One step of the run, in two calls (as SUNDIALS ARKODE's attempt
 *        loop: each attempt returns a verdict, the controller only
 *        proposes dt):
 *
 *     sp_step_try(run, &a);       an attempt from (t, state): a verdict
 *     sp_step_complete(run, &a);  an accepted attempt becomes the state
 *
 * An attempt asks the controller (dt_control.h) for dt, landing on the
 * next event (events.h); starts Newton from the scheme's extrapolation
 * (solver.predictor: linear) or from c^n; computes the explicit terms
 * (source, shape) from c^n; solves the step of the scheme (backward Euler,
 * or BDF2 in its backward-Euler form, time_scheme.h); with adaptive control
 * estimates its local error; and gives its verdict. Every verdict but
 * SP_STEP_ACCEPTED leaves the run's state as it was before the attempt
 * (the controller has set the retry's dt), so the caller tries again.
 */
#ifndef SP_STEP_H
#define SP_STEP_H

#include "run/run_state.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What became of an attempt. */
typedef enum {
  SP_STEP_ACCEPTED = 0,    /**< the step stands: sp_step_complete it */
  SP_STEP_NEWTON_FAILED,   /**< Newton did not converge: retry smaller */
  SP_STEP_ERROR_TOO_LARGE, /**< its error estimate was above the tolerance */
  SP_STEP_LANDING,         /**< a cell's mass passed its division mass inside
                                it: redo it shorter, landing on the crossing */
  SP_STEP_INTERRUPTED,     /**< a stop was requested during it: the step is
                                dropped (the run as before its first attempt,
                                sp_step_try), the run checkpoints and stops */
  SP_STEP_FATAL            /**< a hard error (sp_step_try's return code) */
} sp_step_verdict;

/** An attempt and what it cost (why may point into the struct itself:
 *  pass it by pointer, do not copy it). */
typedef struct {
  sp_step_verdict verdict;
  double wall_start; /**< wall clock when it began */
  double t;         /**< where it started */
  double dt;        /**< the dt tried */
  double t_new;     /**< where it ends (the event exactly, if it lands on one) */
  int lands;        /**< 1: t_new is an event (t_end, output, age division) */
  double err;       /**< error estimate over its tolerance (-1: none) */
  int observed;     /**< run->cells.obs_new holds the observables of its end */
  int give_up;      /**< not accepted and not to be retried: sp_step_try
                         returned the error that ends the run (the last
                         good state is still the run's) */
  sp_step_report report; /**< Newton's (its costs, |F| history, failure) */
  const char *why;  /**< not accepted: why, in words */
  char why_text[160];
} sp_step_attempt;

/**
 * @brief Attempt the next step of @p run. Collective.
 * @return SP_OK with a->verdict set; or the error that ends the run with
 *         the verdict of an attempt not to be retried (a->give_up: the
 *         retries spent, SP_ERR_SOLVER; the factors out of memory,
 *         SP_ERR_MEMORY); or another error code (a->verdict SP_STEP_FATAL:
 *         a hard solver error, a failed allocation, a fault)
 */
int sp_step_try(sp_run *run, sp_step_attempt *a);

/** @brief Make the accepted attempt @p a the run's step: t and step, the
 *         controller told, the history pushed, the observables of the new
 *         state (and the core masses before it, for the division criteria). */
int sp_step_complete(sp_run *run, const sp_step_attempt *a);

/** @brief The controller's first dt of a run (or its parameters back, for a
 *         run continued from a checkpoint): before the first attempt. */
void sp_step_begin(sp_run *run);

/** @brief 1 once the run has reached t_end or time.max_steps. */
int sp_step_run_ends(const sp_run *run);

#ifdef __cplusplus
}
#endif
#endif
