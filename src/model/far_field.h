/**
 * @file far_field.h
 * @brief The values a support change gives its new (cell, node) pairs: the
 *        field's own far field, relaxed from the old support's edge.
 *
 * On the new pairs of cell k the step's equations are replaced by their
 * quasi-static far-field form, with the old pairs' values held fixed
 * (Dirichlet) and a natural boundary at the new support's edge:
 *   - mu_k is the given far-field chemical potential of cell k (the
 *     caller's: the mean over the old edge's free nodes);
 *   - c_k is in equilibrium with that mu_k:
 *       mu_k = f'(c_k) - kappa lap c_k + 2 lambda c_k sum_{l != k} c_l^2
 *              + 2 lambda_b c_k   (the last on the buffer ring),
 * in Q1 finite elements on the elements whole for k (lumped mass). So
 * the interface's tail continues with its own decay length, and inside a
 * neighbour or the ring the far field is held down by the same
 * stiffness as in the equations; c stays on the well's lower branch
 * (below its inflection point). Gauss-Seidel sweeps over the new pairs
 * (ascending node; a scalar Newton solve per node) until no c changes by
 * more than 1e-9 (at most 200 sweeps).
 *
 * (A harmonic mu_k, continued from the old pairs, was tried: an edge
 * inside a neighbour carries mu ~ 1, which continued into free space puts
 * c at the lower branch's top and the supports run away; see
 * docs/local-support.md.)
 */
#ifndef SP_FAR_FIELD_H
#define SP_FAR_FIELD_H

#include "mesh/layout.h"
#include "mesh/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The largest c the relaxation gives a new pair: the double well's lower
 *  spinodal, (1 - 1/sqrt(3)) / 2, where f(c) = alpha c^2 (c - 1)^2 turns
 *  concave (above it a uniform far field is unstable). Where mu exceeds
 *  what that branch can reach, the equation's other root is a new cell's
 *  interior, which the field beyond the edge does not become in a step;
 *  sp_support_fill then keeps the edge rule for that cell. */
#define SP_FAR_FIELD_SPINODAL 0.21132486540518711775

/** The model's constants the far field depends on. */
typedef struct {
  double alpha, kappa, lambda, lambda_b;
  const double *mu_far; /**< per cell: mu on its new pairs */
} sp_far_field_params;

/**
 * @brief Relax the values of the new pairs of @p to in @p state.
 * @param ne_start,ne_list the elements around each node (CSR)
 * @param is_new  per pair of @p to: 1 for a pair to relax, 0 to hold
 * @param state   (c, mu) per pair of @p to; new pairs hold a first guess
 * @param sweeps  out (may be NULL): the sweeps taken
 */
int sp_far_field_relax(const sp_mesh *mesh, const int *ne_start, const int *ne_list,
                       const sp_far_field_params *params, const sp_layout *to,
                       const unsigned char *is_new, double *state, int *sweeps);

#ifdef __cplusplus
}
#endif
#endif
