/**
 * @file checkpoint.h
 * @brief What a checkpoint holds, and writing, finding and reading one
 *        (docs/restart.md).
 *
 * A checkpoint is one HDF5 file, OUT/checkpoint_<step>.h5, written by
 * rank 0 (every rank holds the whole state) to a temporary name and renamed
 * over the final one, so a run killed while writing leaves the previous
 * checkpoints intact. It holds the whole run state (run_state.h):
 *
 *   /                 attributes: format "softpack checkpoint", format_version,
 *                     softpack_version, mpi_size, step, t, n_max, scene_hash
 *   /scene_text       the scene file's text; /scene_overrides: its --set
 *                     overrides, one per line (scene_hash: FNV-1a 64 of both)
 *   /layout           node_start (n_nodes + 1), pair_cell (n_pairs)
 *   /state            c and mu of every pair (2 n_pairs)
 *   /history          past0, past1 (2 n_pairs each, as many as valid);
 *                     attributes n, dt0, dt1
 *   /cells            birth_time, birth_mass, Iref (2 per cell: I^1,ref,
 *                     I^2,ref), 3D: Iref3 (I^3,ref per cell; absent in 3D
 *                     files written before the 3D shape term), generation,
 *                     source_on, division_skipped, divided_now
 *   /controller       the time-step controller's state (dt_control.h), one
 *                     attribute per member; its parameters come from the scene
 *   /summary          the run's counters (run_types.h: sp_run_summary)
 *   /output           energy_t, energy_total (energy.png), division_t,
 *                     field_step, field_t, field_pvtu (fields.pvd)
 *   /carry            header (carry, n_shape, shape_implicit); with carry = 1
 *                     dt, x (2 n_pairs), shape (13 per cell in 2D, 25 in
 *                     3D: checkpoint.c, shape_doubles; or none): where
 *                     the factorisation the next step begins on
 *                     (solver.jacobian_carry) was filled, so a continued
 *                     run rebuilds it (absent in older files: no carry)
 *
 * The same file in 2D and 3D: everything is per (cell, node) pair or per
 * cell; the root attribute mesh_hash checksums the nodes' dim coordinates.
 * The mesh, its RCB numbering, the solver and the supports' search
 * structures are rebuilt from the scene (the carried factorisation from
 * /carry); there is no random state after the
 * initial fields (the seeded noise is drawn once).
 */
#ifndef SP_CHECKPOINT_H
#define SP_CHECKPOINT_H

#include <stddef.h>

#include "run/run_state.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The checkpoint format this build writes and reads (2: the registry
 *  holds the cells' names and cut normals, lineage.h). */
#define SP_CHECKPOINT_VERSION 2
/** The oldest format it still reads (a version 1 file restores with no
 *  names and no cut normals: it was written before they existed). */
#define SP_CHECKPOINT_VERSION_OLDEST 1

/** An open checkpoint (sp_checkpoint_open). */
typedef struct sp_checkpoint_s *sp_checkpoint;

/** @brief Write the run's state to DIR/checkpoint_<step>.h5 (rank 0 only;
 *         temporary name, then rename) and delete all but the newest
 *         output.checkpoint_keep checkpoints. @p path_out (may be NULL, size
 *         @p size) receives the file's path. */
int sp_checkpoint_write(const sp_run *run, const char *dir, char *path_out, size_t size);

/**
 * @brief Open and check a checkpoint: an HDF5 file softpack wrote, of this
 *        format version, with the scene in it. Failures are SP_ERR_INPUT
 *        with a message saying what is wrong (truncated or not HDF5,
 *        foreign, another version).
 */
int sp_checkpoint_open(const char *path, sp_checkpoint *out);

/** @brief Delete the checkpoints in @p dir of steps after @p step (a run
 *         continued from @p step replaces that future), and temporaries
 *         left by writes a kill cut short. */
void sp_checkpoint_remove_after(const char *dir, int step);

/** @brief The newest checkpoint in @p dir that sp_checkpoint_open accepts
 *         (its path into @p path, size @p size). SP_ERR_INPUT if none. */
int sp_checkpoint_find_newest(const char *dir, char *path, size_t size);

/** @brief The scene text, its overrides (n, strings), step and t. */
const char *sp_checkpoint_scene(const sp_checkpoint ck, size_t *len, int *n_set,
                                const char *const **set);
int sp_checkpoint_step(const sp_checkpoint ck);
double sp_checkpoint_time(const sp_checkpoint ck);
int sp_checkpoint_mpi_size(const sp_checkpoint ck);
/** @brief Its number of cells and N_max. */
void sp_checkpoint_cells(const sp_checkpoint ck, int *n_cells, int *n_max);

/**
 * @brief Put the checkpoint's state into @p run, set up from the same
 *        scene (mesh, solver, registry arrays of the initial cells): the
 *        layout and fields (through the one layout change, resize.h: the
 *        solver gets the layout; collective), history, registry,
 *        controller state, step, t, counters and the energy history.
 *        @p fields / @p n_fields: the fields.pvd list (free()).
 *        @p as_initial: the fields and cells only, as a new run's initial
 *        state at t = 0 (every cell born then, with its mass now).
 */
int sp_checkpoint_restore(const sp_checkpoint ck, sp_run *run, int as_initial,
                          sp_output_field **fields, int *n_fields);

/**
 * @brief Rebuild the factorisation the next step of the checkpointed run
 *        began on (/carry), on the solver that has the restored layout.
 *        Nothing to do without one. Collective.
 */
int sp_checkpoint_restore_carry(const sp_checkpoint ck, sp_run *run);

void sp_checkpoint_close(sp_checkpoint *ck);

/** @brief FNV-1a 64 of @p len bytes, continued from @p h (start:
 *         SP_FNV_OFFSET). */
#define SP_FNV_OFFSET 0xcbf29ce484222325ULL
unsigned long long sp_fnv1a(unsigned long long h, const void *data, size_t len);

#ifdef __cplusplus
}
#endif
#endif
