/**
 * @file initial.h
 * @brief Where a run's initial fields come from: the scene's cells (disks,
 *        cells.c), or a file (the scene's initial section):
 *        - initial.from: a softpack .vtu of one process on the same mesh
 *          (every cell's c and mu at every node, as written); a softpack
 *          checkpoint (.h5) is read by the stepper as a new run's state
 *          (checkpoint.h, as with --restart-as-initial);
 *        - initial.label_image: a PNG in which every colour but black (and
 *          fully transparent pixels) is one cell, mapped onto the box
 *          [x0, x1] x [y0, y1] of the domain; each label's edge (half-way
 *          between its pixels and the others) becomes an interface with
 *          the equilibrium profile 1 / (1 + e^(s/d)) of the signed
 *          distance s to it. Cells are numbered by colour (0xRRGGBB,
 *          ascending).
 *        - initial.label_volume: the same in 3D from a NIfTI volume whose
 *          nonzero integer voxels are labels, numbered by value (ascending),
 *          placed by the file's sform (else qform, else voxel sizes), scaled
 *          by initial.scale and moved by initial.offset_* (docs/3d.md).
 */
#ifndef SP_INITIAL_H
#define SP_INITIAL_H

#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The number of initial cells: the scene's, or the labels of
 *         initial.label_image or initial.label_volume, or the cells of
 *         initial.from (.vtu). Bad files are SP_ERR_INPUT naming the key:
 *         also too many labels for the initial layout, and (with @p mesh,
 *         which may be NULL) a label volume's labelled voxel outside Omega. */
int sp_initial_cell_count(const sp_scene *scene, const sp_mesh *mesh, int *n_cells);

/** @brief The initial fields of those cells on @p layout (full, the mesh's
 *         own numbering), the seeded noise outside the cells as with disks
 *         (label image), or as the file holds them (.vtu). */
int sp_initial_state(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                     double *state);

/** @brief 1 if initial.from names a checkpoint (.h5). */
int sp_initial_from_checkpoint(const sp_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
