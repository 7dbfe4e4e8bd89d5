/**
 * @file cell_obs.h
 * @brief What is observed of each cell after a step (public: a step
 *        callback sees them, run_types.h); computed by cells.h.
 */
#ifndef SP_CELL_OBS_H
#define SP_CELL_OBS_H

#ifdef __cplusplus
extern "C" {
#endif

/** Room for a cell's name with its NUL: at most 31 characters, letters,
 *  digits, '_', '.' and '-' (the scene's cells[i].name and lineage
 *  table; "" for an unnamed cell). */
#define SP_CELL_NAME_MAX 32

/** A cell's name ("": none). */
typedef char sp_cell_name[SP_CELL_NAME_MAX];

/** The largest dimension of a mesh: the arrays below have this many
 *  entries in 2D too (the unused ones 0). */
#define SP_DIM_MAX 3

/** Observables of one cell, the same in 2D and 3D (docs/model.md, "Observables";
 *  Xb = X - centre, the sums over the mesh's dim coordinates). */
typedef struct {
  double mass;      /**< m_k = int c_k dV (the conserved quantity) */
  double mass_core; /**< int c_k dV over c_k >= weight_threshold only: the
                         cell without its background (division, source) */
  double centre[SP_DIM_MAX]; /**< centre of mass int c X / int c (core
                                  weights); 0 beyond the mesh's dim */
  double inertia[SP_DIM_MAX][SP_DIM_MAX]; /**< the inertia tensor about the
                         centre, I_ij = int c (|Xb|^2 delta_ij - Xb_i Xb_j),
                         i, j < dim (0 beyond) */
  double moments[SP_DIM_MAX]; /**< its principal moments, descending
                                   (moments[2] = 0 in 2D) */
  double axes[SP_DIM_MAX][SP_DIM_MAX]; /**< axes[i]: the unit eigenvector of
                         moments[i] (0 beyond dim), signed by a fixed rule
                         (the same sign from runs that differ in round-off) */
  int long_axis;    /**< the index in axes of the long axis, the smallest
                         moment's: dim - 1 (the normal of a division's cut) */
  double volume;    /**< the measure where c_k >= 1/2 (inside the membrane):
                         an area in 2D, a volume in 3D (at the quadrature
                         points, whatever the weight threshold) */
} sp_cell_obs;

#ifdef __cplusplus
}
#endif
#endif
