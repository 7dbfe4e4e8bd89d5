/**
 * @file resize.h
 * @brief Every change of the run's layout goes through one function (the
 *        role of PETSc's TSResize): the initial layout, a division, a
 *        support change and a checkpoint restore alike. It takes the new
 *        (layout, state) over, moves or resets the time scheme's history,
 *        resizes the per-pair buffers and the cell registry, and hands the
 *        layout to the solver.
 */
#ifndef SP_RESIZE_H
#define SP_RESIZE_H

#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "run/run_state.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What a layout change does to the time scheme's history. */
typedef enum {
  SP_HISTORY_CARRY, /**< a support change: the past states move with (cell,
                         node) as increments, 0 on new pairs */
  SP_HISTORY_RESET  /**< the initial layout, a restore (which then reads
                         its own), a division (an event: the scheme starts
                         over) */
} sp_history_move;

/**
 * @brief The one place the run's layout changes: (@p layout, @p state)
 *        become the run's own (taken over, freed on failure too), the
 *        history moves as @p how says, the per-pair buffers and the
 *        registry (to layout->n_cells, new entries zeroed) are resized and
 *        the solver gets the layout (collective: agreed first).
 */
int sp_run_resize(sp_run *run, sp_layout *layout, double *state, sp_history_move how);

/**
 * @brief The run's adhesion table (adhesion.h) for its cells and their
 *        sisters as the registry has them, pointed to by opt.model, and the
 *        bound on its layout (SP_ERR_INPUT naming the keys when a cell's
 *        partners on an element sum to kappa or more). Nothing without
 *        adhesion. Called by sp_run_resize, and again where the registry's
 *        sisters change (a division, a checkpoint restore). Sets
 *        run->adhesion_sum, the largest sum of a cell's partners' sigma on
 *        an element.
 */
int sp_run_adhesion_update(sp_run *run);

/** @brief Hand the solver a mesh and layout (its maps and graph are rebuilt
 *         when the layout changed). Collective on the solver's ranks. */
int sp_solver_attach(sp_solver solver, const sp_mesh *mesh, const sp_layout *layout);

#ifdef __cplusplus
}
#endif
#endif
