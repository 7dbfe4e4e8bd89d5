/**
 * @file run_types.h
 * @brief The types a program that runs scenes sees (public, installed with
 *        run.h): what a run did (sp_run_summary), what a step callback is
 *        shown after each accepted step (sp_step_info) and the failed
 *        attempts before it (sp_attempt).
 */
#ifndef SP_RUN_TYPES_H
#define SP_RUN_TYPES_H

#include "cell_obs.h"
#include "softpack_newton.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What a run did, for the caller's summary line and for tests. */
typedef struct {
  int steps;           /**< accepted steps */
  int failed_attempts; /**< Newton failures that were retried */
  long newton_its;     /**< Newton iterations of accepted steps */
  long factorisations; /**< their factorisations (solver.jacobian_reuse) */
  long failed_factorisations; /**< factorisations of the failed attempts */
  long linear_its;     /**< GMRES iterations of accepted steps (gmres_ilu) */
  double t_final;      /**< time reached */
  double dt_smallest;  /**< smallest accepted dt */
  double wall_seconds;
  double t_assembly, t_factor, t_solve; /**< seconds over the run */
  int divisions;       /**< cell divisions */
  int n_cells;         /**< cells at the end */
  int layout_changes;  /**< local supports: times the supports were rebuilt */
  double support_mass_correction; /**< largest relative mass change a
                                       support change caused (restored) */
  double t_layout;     /**< seconds spent rebuilding supports */
  double support_mass_dropped; /**< the mass support changes lost or gained
                                   in all, relative: sum over the changes of
                                   |total after - total before| / total */
  double support_energy_rise; /**< largest relative rise of the field
                                   energy at a support change (0 if none
                                   rose) */
  long unknowns_max;   /**< largest number of unknowns of a step */
  int checkpoints;     /**< checkpoints written (output.checkpoint_*, signals) */
  double t_checkpoints; /**< seconds spent writing them (rank 0) */
  int stopped;         /**< SP_STOPPED_CALLBACK or SP_STOPPED_SIGNAL if the run
                            stopped early, else 0 */
  /* Memory per rank (MB), each the largest over the ranks, and what a rank
   * sent per Newton iteration (docs/parallel.md, "Memory and messages per
   * rank"): */
  double mb_mesh;      /**< the mesh, layout and support tables, the glue's copies */
  double mb_state;     /**< the state, its history, the step's buffers, the
                            glue's full copy */
  double mb_matrix;    /**< the Jacobian's rows and ghost rows, the CSR arrays */
  double mb_solver;    /**< the rest of the resident peak: the linear solver's
                            factors or hierarchies and work arrays */
  double mb_sent_per_newton; /**< the state's gathers and the residual's and
                                  Jacobian's Exports, per Newton iteration */
} sp_run_summary;

/** Why a run stopped before t_end (sp_run_summary.stopped). */
enum { SP_STOPPED_CALLBACK = 1, /**< a step callback returned non-zero */
       SP_STOPPED_SIGNAL = 2    /**< sp_run_request_stop: a checkpoint was written */ };

/** Why an attempt at a step was not accepted (sp_attempt.why). */
typedef enum {
  SP_ATTEMPT_NEWTON = 1, /**< Newton failed (sp_attempt.newton says why) */
  SP_ATTEMPT_ERROR,      /**< its local error estimate was above 1 */
  SP_ATTEMPT_LANDING     /**< a cell's mass passed its division mass inside it:
                              redone shorter, to land on the crossing */
} sp_attempt_failure;

/** A failed attempt at a step, retried with a smaller dt: what stderr
 *  reports in words, as data (sp_step_info.attempts). */
typedef struct {
  double dt;             /**< the dt tried */
  int why;               /**< sp_attempt_failure */
  int newton;            /**< sp_newton_failure (softpack_newton.h) when why is
                              SP_ATTEMPT_NEWTON, else 0 */
  int newton_its;
  int factorisations;
  int n_residuals;       /**< entries of residual_norms: |F| per iteration */
  double residual_norms[SP_MAX_NEWTON_HISTORY];
  double error_estimate; /**< over its tolerance (SP_ATTEMPT_ERROR), else -1 */
  double dt_next;        /**< the dt of the retry */
} sp_attempt;

/** What a step callback sees after each accepted step (the same on every
 *  MPI rank). */
typedef struct {
  int step;              /**< accepted steps so far */
  double t, dt, t_end;   /**< time reached, the step's dt, the scene's t_end */
  int n_cells;
  int newton_its;        /**< of the accepted attempt */
  int failed_attempts;   /**< retried before it was accepted */
  const sp_attempt *attempts; /**< those failed attempts, in order */
  double error_estimate; /**< over its tolerance (adaptive); -1: none */
  const sp_cell_obs *cells; /**< n_cells observables of the new state */
  double wall_seconds;   /**< since the run began */
  int last;              /**< 1 on the run's last step (t_end or max_steps) */
  int dim;               /**< the mesh's dimension, 2 or 3 */
  const sp_cell_name *names; /**< n_cells names ("" for an unnamed cell) */
  const void *run;       /**< the run, for sp_step_mesh and sp_step_cell_field
                              (opaque; valid during the callback only) */
} sp_step_info;

/** Called after every accepted step (and its output) on every rank; a
 *  non-zero return on any rank stops the run there: the state is written
 *  as at the end and the run returns SP_OK with summary->stopped = 1. */
typedef int (*sp_step_callback)(const sp_step_info *info, void *user);

#ifdef __cplusplus
}
#endif
#endif
