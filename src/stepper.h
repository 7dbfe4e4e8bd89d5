/**
 * @file stepper.h
 * @brief The time loop: backward-Euler steps of all cells by Newton, with dt
 *        control (a failed Newton solve shrinks dt and retries the step; dt
 *        grows back toward the scene's dt after successes; an unconverged
 *        step is never accepted), observables and output.
 */
#ifndef SP_STEPPER_H
#define SP_STEPPER_H

#include <mpi.h>

#include "cells.h"
#include "dt_control.h"
#include "layout.h"
#include "mesh.h"
#include "scene.h"
#include "softpack_solver.h"

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
  int newton;            /**< sp_newton_failure (softpack_solver.h) when why is
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
} sp_step_info;

/** Called after every accepted step (and its output) on every rank; a
 *  non-zero return on any rank stops the run there: the state is written
 *  as at the end and the run returns SP_OK with summary->stopped = 1. */
typedef int (*sp_step_callback)(const sp_step_info *info, void *user);

/** @brief The mesh a scene describes. */
int sp_mesh_from_scene(const sp_scene *scene, sp_mesh **out);
/** @brief Solver options and model parameters from a scene. */
void sp_solver_options_from_scene(const sp_scene *scene, sp_solver_options *opt);
void sp_model_from_scene(const sp_scene *scene, sp_model_params *model);

/** @brief The time-step controller's parameters from a scene (dt_control.h). */
void sp_dt_params_from_scene(const sp_scene *scene, sp_dt_params *params);

/** @brief Hand the solver a mesh and layout (maps and graph are rebuilt
 *         when the layout changed). */
int sp_solver_attach(sp_solver solver, const sp_mesh *mesh, const sp_layout *layout);

/**
 * @brief Run a scene into @p out_dir. Everything that can be checked before
 *        the first step (mesh, solver choice) is checked before @p out_dir is
 *        created, so bad input leaves nothing behind.
 * @return SP_OK; SP_ERR_INPUT for bad input; SP_ERR_SOLVER when a step failed
 *         beyond the retries allowed (the last good state is written first)
 */
int sp_stepper_run(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                   sp_run_summary *summary);

/** @brief sp_stepper_run with @p on_step (may be NULL) called after every
 *         accepted step with @p user. */
int sp_stepper_run_with(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary);

/** How a run starts: from the scene's initial cells (checkpoint NULL), or
 *  from a checkpoint (checkpoint.h) opened by the caller, whose scene the
 *  caller checked against @p scene; @p as_initial: its fields and cells as
 *  a new run's initial state at t = 0. The scene's text and overrides are
 *  saved in the run's checkpoints (text NULL: none saved, and none can be
 *  resumed). */
typedef struct sp_checkpoint_s *sp_checkpoint_handle;
typedef struct {
  sp_checkpoint_handle checkpoint;
  int as_initial;
  const char *scene_text;
  size_t scene_len;
  int n_set;
  const char *const *set;
} sp_run_start;

/** @brief sp_stepper_run_with, started as @p start says (NULL: the scene's
 *         cells, no scene text saved). */
int sp_stepper_run_from(const sp_scene *scene, const sp_run_start *start, const char *out_dir,
                        MPI_Comm comm, sp_step_callback on_step, void *user,
                        sp_run_summary *summary);

/**
 * @brief Ask the run in progress (this process's) to write a checkpoint at
 *        the end of the step in progress and stop there (summary.stopped =
 *        SP_STOPPED_SIGNAL). Async-signal-safe: `softpack run` calls it on
 *        SIGTERM, SIGINT and SIGUSR1. One rank asking stops every rank.
 */
void sp_run_request_stop(void);

#ifdef __cplusplus
}
#endif
#endif
