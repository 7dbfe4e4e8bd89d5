/**
 * @file dt_control.h
 * @brief How dt is chosen: the one time-step controller (in the spirit of
 *        PETSc's TSAdapt and SUNDIALS' SUNAdaptController). Every dt
 *        decision of a run lives here; the step (step.c) asks for a dt,
 *        reports what happened and obeys, and nothing else writes the
 *        controller's fields:
 *
 *     sp_dt_init(&c, &p, dt_first);                 a new run's first step
 *     sp_dt_resume(&c, &p);                         a run from a checkpoint
 *     dt = sp_dt_propose(&c, t, t_event, &lands);   the step to try
 *     ...solve...
 *     Newton failed:          give_up = sp_dt_newton_failed(&c, dt);
 *     error estimate err:     if (sp_dt_judge(&c, dt, err) == SP_DT_REJECT)
 *                               give_up = sp_dt_give_up(&c);
 *     overshot a mass event:  sp_dt_land(&c, theta * dt);
 *     accepted:               sp_dt_accepted(&c, dt, err);
 *     ... without estimate:   sp_dt_unestimated(&c, dt, increment);
 *     a cell divided:         sp_dt_restart(&c, dt_first);
 *
 * Two policies (time.control):
 * - fixed (the paper's): the scene's dt_bar; after a failed Newton solve dt
 *   shrinks by time.shrink and grows back by time.grow every
 *   time.grow_after accepted steps (with time.failure_memory); after a
 *   division the paper's algorithm 2 ramp (sp_division_dt) caps dt.
 * - adaptive: dt from a local error estimate err (a weighted max-norm of
 *   the estimated local error of c, 1 = on tolerance; the time scheme
 *   computes it, time_scheme.h). A step with err > 1 is rejected and
 *   retried with a smaller dt, never accepted: dt x safety x err^(-1/k),
 *   or, at a second rejection of the same step whose estimate fell more
 *   slowly than dt^k (a transient that does not scale with dt, such as the
 *   relaxation after a support change), with the exponent observed over
 *   the two attempts. The next dt comes from a PI
 *   controller, dt_new = dt * safety * err^(-0.7/k) * err_prev^(0.4/k)
 *   (k = the estimate's order + 1), bounded by SP_DT_GROW_MAX and
 *   SP_DT_CUT_MIN and by [dt_min, dt_max]. The first step has no
 *   estimate: the caller passes dt_first, chosen from the state
 *   (time_scheme.h: sp_scheme_first_dt).
 *   A division is an event of the integrator: the history starts over
 *   (the next step is backward Euler, the one after it BDF2 judged by BE's
 *   estimate: no estimate mixes states from before and after the cut),
 *   the step restarts from dt_first (the caller's starting-step estimate
 *   of the post-event state), at most time.event_first of the step before,
 *   and the next time.event_steps steps grow from their estimate alone by
 *   up to time.event_growth (within BDF2's step-ratio limit) back to the
 *   step wanted before the event, beyond it no faster than the PI law,
 *   which then takes over again. A rejected step is retried all the same.
 *
 * Both policies land on events (t_end, output times, age divisions in
 * adaptive mode) without a sliver step: a step that would stop short of an
 * event by less than its own length is stretched to it when within
 * SP_DT_STRETCH of dt, else the rest is split into two equal steps.
 */
#ifndef SP_DT_CONTROL_H
#define SP_DT_CONTROL_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { SP_DT_FIXED = 0, SP_DT_ADAPTIVE = 1 } sp_dt_policy;
typedef enum { SP_DT_ACCEPT = 0, SP_DT_REJECT = 1 } sp_dt_verdict;

/** The largest factor dt grows by from one step to the next (adaptive); it
 *  also keeps variable-step BDF2's step ratio below its zero-stability
 *  limit 1 + sqrt(2). */
#define SP_DT_GROW_MAX 2.0
/** The smallest factor a rejected step is cut by (adaptive). */
#define SP_DT_CUT_MIN 0.2
/** Safety factor of the adaptive controller. */
#define SP_DT_SAFETY 0.9
/** Variable-step BDF2 is zero-stable for step ratios below 1 + sqrt(2):
 *  the largest growth of a BDF2 step after an event (time.event_growth). */
#define SP_DT_BDF2_RATIO_MAX 2.4
/** A step may be stretched by this relative amount to land on an event. */
#define SP_DT_STRETCH 1e-6

/** What the controller is told once, from the scene. */
typedef struct {
  sp_dt_policy policy;
  double dt;       /**< fixed: dt_bar, the step; adaptive: the first step's
                        cap (and the step where there is no estimate) */
  double dt_min;   /**< a retry below this ends the run */
  double dt_max;   /**< adaptive: the largest step */
  int max_retries; /**< failed attempts of one step before the run stops */
  /* fixed */
  double shrink;   /**< dt factor after a failed Newton solve */
  double grow;     /**< dt factor after grow_after accepted steps */
  int grow_after;
  int failure_memory;
  int ramp_n_div, ramp_m; /**< algorithm 2 after a division (m = 0: none) */
  /* adaptive */
  int order;       /**< order of the error estimate's method (1 BE, 2 BDF2) */
  double event_first;  /**< after an event: the first step at most this
                            fraction of the step before */
  double event_growth; /**< ... and the next event_steps steps grow by up
                            to this factor (BDF2: at most
                            SP_DT_BDF2_RATIO_MAX) from their estimate alone */
  int event_steps;
} sp_dt_params;

/** The controller's whole state (plain data: a checkpoint can save it). */
typedef struct {
  sp_dt_params p;
  double dt_next;     /**< the step the policy wants next */
  int failures;       /**< failed attempts of the step in progress */
  int successes;      /**< fixed: accepted steps since dt last grew */
  double ceiling;     /**< fixed: failure memory's cap on dt ... */
  int ceiling_steps;  /**< ... for this many more accepted steps */
  int since_restart;  /**< accepted steps since the last division, an event
                           (-1: none) */
  double err_prev;    /**< adaptive: the last accepted step's estimate (0: none) */
  double dt_last;     /**< the last accepted step (0: none yet) */
  double event_dt;    /**< adaptive: the step wanted before the last
                           division (the fast regrowth's goal; 0: none) */
  int rejected_last;  /**< adaptive: the last attempt was rejected */
  double rejected_dt, rejected_err; /**< adaptive: the last rejected attempt of
                                         the step in progress (0: none; so 0
                                         between steps, never checkpointed) */
  long n_accepted, n_rejected, n_newton_failed;
} sp_dt_control;

/** @brief Start a controller; @p dt_first: the first step (adaptive; the
 *         fixed policy starts at p->dt). */
void sp_dt_init(sp_dt_control *c, const sp_dt_params *p, double dt_first);

/**
 * @brief The step to try from @p t: the policy's dt, capped by algorithm 2
 *        (fixed, after a division) and landing on @p t_event (the next
 *        event: t_end, an output time, an age division) without a sliver.
 *        Steps that land on the event return exactly t_event - t.
 * @param[out] lands 1 if t + dt is the event (the caller then sets t =
 *        t_event exactly), else 0 (may be NULL)
 */
double sp_dt_propose(const sp_dt_control *c, double t, double t_event, int *lands);

/** @brief Adaptive: accept a step with error estimate @p err (err < 0: no
 *         estimate, accepted), or reject it (err > 1) and set the retry's dt.
 *         Fixed: always accept. */
sp_dt_verdict sp_dt_judge(sp_dt_control *c, double dt, double err);

/** @brief A Newton solve at @p dt failed: the retry's dt.
 *  @return 1 if the run must give up (time.max_retries failures of this step
 *          or the retry's dt below dt_min), else 0 */
int sp_dt_newton_failed(sp_dt_control *c, double dt);

/** @brief 1 if the step in progress has failed too often (rejections and
 *         Newton failures together) or its retry fell below dt_min. */
int sp_dt_give_up(const sp_dt_control *c);

/** @brief A step of @p dt was accepted with estimate @p err (< 0: none):
 *         the next dt. */
void sp_dt_accepted(sp_dt_control *c, double dt, double err);

/** @brief The accepted step of @p dt had no estimate (the first after a
 *         start or an event): the next dt from its weighted @p increment
 *         (time_scheme.h, sp_scheme_increment), so that the next step's
 *         estimate is on tolerance if the state stops changing (the
 *         relaxation of a cut that the step has made): r^2 / (2r + 1) x
 *         increment = SP_DT_SAFETY, r = dt_next / dt, within the growth cap.
 *         Adaptive only; call after sp_dt_accepted. */
void sp_dt_unestimated(sp_dt_control *c, double dt, double increment);

/** @brief A step of @p dt_full overshot an event inside it (a cell's mass
 *         passed its division mass): redo it with @p dt, at least dt_min
 *         (not a failure: nothing counts against the step). */
void sp_dt_land(sp_dt_control *c, double dt);

/** @brief A controller restored from a checkpoint takes the continued
 *         run's parameters (time.* may differ: t_end, max_steps). */
void sp_dt_resume(sp_dt_control *c, const sp_dt_params *p);

/** @brief A cell divided (an event): fixed restarts algorithm 2's ramp;
 *         adaptive starts again without an error history from @p dt_first,
 *         at most time.event_first of the last accepted step, and lets the
 *         next time.event_steps steps grow fast. */
void sp_dt_restart(sp_dt_control *c, double dt_first);

#ifdef __cplusplus
}
#endif
#endif
