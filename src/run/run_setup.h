/**
 * @file run_setup.h
 * @brief How a run is set up from its scene, in one function shared by
 *        everything that starts from a scene: the run (stepper.h),
 *        `softpack check-jacobian` (checkjac.c), the benchmarks and the
 *        tests' scene fixture. What they see is what a run steps on: the
 *        same layout, node numbering and local supports. The scene is
 *        read here only: it is resolved into the run's options
 *        (run_options.h), and nothing after set-up reads it.
 */
#ifndef SP_RUN_SETUP_H
#define SP_RUN_SETUP_H

#include <mpi.h>
#include <stddef.h>

#include "run/checkpoint.h"
#include "run/run_state.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How a run starts: from the scene's initial cells (checkpoint NULL), or
 *  from a checkpoint (checkpoint.h) opened by the caller, whose scene the
 *  caller checked against the scene; @p as_initial: its fields and cells as
 *  a new run's initial state at t = 0. The scene's text and overrides are
 *  saved in the run's checkpoints (text NULL: none saved, and none can be
 *  resumed). */
typedef struct {
  sp_checkpoint checkpoint;
  int as_initial;
  int from_scene; /**< the checkpoint is the scene's initial.from (errors name it) */
  const char *scene_text;
  size_t scene_len;
  int n_set;
  const char *const *set;
} sp_run_start;

/**
 * @brief Set up @p run for @p scene, as a run starts:
 *  1. the options (run_options.h); the agreement communicator (agree.h),
 *     a duplicate of @p comm; the mesh; the full layout of the initial
 *     cells; the solver (the scene's solver keys); the per-pair buffers
 *     and the registry (resize.h);
 *  2. the initial fields (initial.h), drawn in the mesh's own numbering
 *     (the seeded noise does not depend on it), then the nodes renumbered
 *     in RCB order (partition.h) for every number of ranks;
 *  3. the registry of a new run: every cell born at t = 0 with its core
 *     mass and moments, its source on; N_max;
 *  4. local supports when layout.support says so (auto: more than 4 cells,
 *     or divisions can make more): the fields cut to the initial supports
 *     and the solver given that layout (else the full one);
 *  5. from a checkpoint (@p start): its layout, state, history, registry
 *     and counters (as_initial: its fields as a new run's, a new registry);
 *  6. the division parameters.
 * Collective on @p comm; every rank returns the same code (agreed).
 *
 * @p run must be zeroed but for its monitor's members, the caller's: sum
 * (needed with a checkpoint, which restores the counters into it),
 * out_dir, on_step, on_step_user, t_start, t_checkpoint. After it,
 * run->state is the initial state on run->layout, the step buffers of its
 * size, run->cells.obs the observables of the state.
 * @param start NULL: the scene's initial cells, no scene text saved
 * @return SP_OK; SP_ERR_INPUT for bad input (an unreadable initial file, a
 *         checkpoint not of this mesh); free @p run with sp_run_free
 *         whatever it returns
 */
int sp_run_setup(sp_run *run, const sp_scene *scene, MPI_Comm comm, const sp_run_start *start);

/** @brief Free what sp_run_setup (and the run since) made; not the scene,
 *         the summary or the scene text, which are the caller's. */
void sp_run_free(sp_run *run);

#ifdef __cplusplus
}
#endif
#endif
