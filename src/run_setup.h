/**
 * @file run_setup.h
 * @brief How a run is set up from its scene, in one function shared by
 *        everything that starts from a scene: the run (stepper.c),
 *        `softpack check-jacobian` (checkjac.c), the benchmarks and the
 *        tests' scene fixture. What they see is what a run steps on: the
 *        same layout, node numbering and local supports. Also the one
 *        place a run's layout changes afterwards (sp_run_adopt_layout),
 *        which the set-up and the stepper's divisions and support changes
 *        share.
 */
#ifndef SP_RUN_SETUP_H
#define SP_RUN_SETUP_H

#include <mpi.h>

#include "run_state.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Adaptive control, mass criterion: a step whose end overshoots a cell's
 *  division mass by more than this (relative) is redone, shortened to the
 *  interpolated crossing (sp_division_crossing_fraction); a landing within
 *  it counts as the crossing (sp_division_params.tolerance, set here). */
#define SP_MASS_LANDING_TOLERANCE 1e-3

/**
 * @brief Set up @p run for @p scene, as a run starts:
 *  1. the agreement communicator (agree.h), a duplicate of @p comm; the
 *     mesh; the full layout of the initial cells; the solver (the scene's
 *     solver keys) and model; the per-pair buffers; the registry arrays;
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
 * @p run must be zeroed; the members the set-up leaves alone are the
 * caller's: sum (needed with a checkpoint, which restores the counters
 * into it), out_dir, on_step, on_step_user, t_start, t_checkpoint. After
 * it, run->state is the initial state on run->layout, run->state_old a
 * buffer of its size, run->obs the observables of the state.
 * @param start NULL: the scene's initial cells, no scene text saved
 * @return SP_OK; SP_ERR_INPUT for bad input (an unreadable initial file, a
 *         checkpoint not of this mesh); free @p run with sp_run_free
 *         whatever it returns
 */
int sp_run_setup(sp_run *run, const sp_scene *scene, MPI_Comm comm, const sp_run_start *start);

/** @brief Free what sp_run_setup (and the run since) made; not the scene,
 *         the summary or the scene text, which are the caller's. */
void sp_run_free(sp_run *run);

/** What a layout change does to the time scheme's history. */
typedef enum {
  SP_HISTORY_CARRY, /**< a support change: the past states move with (cell,
                         node) as increments, 0 on new pairs */
  SP_HISTORY_RESET  /**< a division, the initial layout: the scheme starts over */
} sp_history_move;

/** @brief The one place the run's layout changes: (layout, state) become
 *         the run's own (taken over, freed on failure too), the history
 *         moves as @p how says, the per-pair buffers are resized and the
 *         solver gets the layout (collective: agreed first). */
int sp_run_adopt_layout(sp_run *run, sp_layout *layout, double *state, sp_history_move how);

#ifdef __cplusplus
}
#endif
#endif
