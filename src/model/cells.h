/**
 * @file cells.h
 * @brief The geometric observables of each cell computed from its field c_k
 *        alone (mesh integrals, 2x2 or 2x2x2 Gauss; the registry: registry.h).
 */
#ifndef SP_CELLS_H
#define SP_CELLS_H

#include "public/cell_obs.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif


/**
 * @brief Observables of every cell of a state.
 * @param[in] weight_threshold centre and inertia integrate c only where
 *            c >= this (0: everywhere), so a background does not count;
 *            the mass is always the full integral
 * @param[out] obs n_cells entries
 */
int sp_cells_observe(const sp_mesh *mesh, const sp_layout *layout,
                     const double *state, double weight_threshold,
                     sp_cell_obs *obs);

/** @brief @p obs with the mass replaced by the core mass (c >= the
 *         threshold): what division and source decisions see. */
void sp_cells_core_view(const sp_cell_obs *obs, int n, sp_cell_obs *out);

/**
 * @brief Node weights of one cell: w[i] = int phi_i over the elements of
 *        cell k's domain (all four nodes in its support, the solver's rule),
 *        0 elsewhere. The mass is then sum_i w_i c_i exactly (the Q1 shape
 *        functions sum to one), so a nodal change of c_k by d_i changes the
 *        mass by sum_i w_i d_i.
 * @param[out] w n_nodes values
 */
int sp_cells_node_weights(const sp_mesh *mesh, const sp_layout *layout, int k, double *w);

/**
 * @brief The node weights of every cell at once, per pair: w[p] = the node
 *        weight (sp_cells_node_weights) of pair p's node for pair p's cell.
 *        One pass over the elements (not one per cell).
 * @param[out] w layout->n_pairs values
 */
int sp_cells_pair_weights(const sp_mesh *mesh, const sp_layout *layout, double *w);

/** @brief The angle from the x axis of the line along (@p dx, @p dy), in
 *         (-pi/2, pi/2] (a line has no direction: cells.csv's angle of v1,
 *         divisions.csv's of the division line). */
double sp_cells_line_angle(double dx, double dy);

/**
 * @brief Principal moments and unit eigenvectors of a symmetric tensor's
 *        leading @p dim x @p dim block (cyclic Jacobi), largest first:
 *        moments[0] >= ... >= moments[dim - 1], v[i] the unit eigenvector
 *        of moments[i]; entries beyond dim are 0.
 *
 * Well defined when moments are equal (a round cell): the eigenvectors are
 * then an orthonormal basis of the degenerate space, never NaN. Each v[i]
 * is signed so that its component along a fixed generic direction
 * (cells.c) is >= 0: the same sign from runs that differ in round-off.
 */
void sp_cells_principal(int dim, const double tensor[3][3], double moments[3], double v[3][3]);

/** @brief cells.csv's angle in 2D: of axes[0] (the line of a division's
 *         cut) from the x axis, in (-pi/2, pi/2]; 0 in 3D. */
double sp_cells_obs_angle(const sp_cell_obs *o, int dim);

/**
 * @brief The initial fields of a scene (docs/model.md): cell k's profile p_k
 *        (tanh with the equilibrium width d, or sharp) plus the seeded
 *        background, c_k = p_k + (1 - p_k) (b + a U(-1,1)), and mu_k = 0.
 * @param[out] state 2 n_pairs values in layout order
 */
int sp_cells_initial_state(const sp_scene *scene, const sp_mesh *mesh,
                           const sp_layout *layout, double *state);

/** @brief Uniform random number in [-1, 1) from a 64-bit state (splitmix64):
 *         the same sequence on every machine for a given seed. */
double sp_random_symmetric(unsigned long long *rng);

/** The equilibrium profile across an interface of width @p d at signed
 *  distance @p signed_distance from it (> 0 outside): 1 / (1 + e^(s/d)). */
double sp_cells_profile(double signed_distance, double d);

/** Cell k's profile (c without noise, in [0, 1]) at the point x[0..dim). */
typedef double (*sp_profile_fn)(int k, const double *x, int dim, void *ctx);

/** @brief The initial state of every cell of @p layout from @p profile_of,
 *         with the scene's noise outside the cells (mu = 0). */
int sp_cells_fill(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                  sp_profile_fn profile_of, void *ctx, double *state);

#ifdef __cplusplus
}
#endif
#endif
