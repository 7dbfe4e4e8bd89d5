/**
 * @file shape.h
 * @brief The shape penalty on principal moments of inertia (docs/model.md "Shape
 *        penalty", paper section 3), explicit in time as in the paper, or
 *        linearised implicit (shape.scheme; softpack_solver.h, the gains),
 *        on a 2D or a 3D mesh (n = dim principal moments):
 *
 *     Pi_MI = sum_k sum_{i<=n} delta^i (I_k^i,ref - I_k^i)^2,
 *     mu_k += - sum_i 2 delta^i (I_k^i,ref - I_k^i) Ihat_k^i(X),
 *     Ihat^i(X) = dI^i/dc(X) = v_i . Ibar(X) v_i,
 *     Ibar(X) = |Xb|^2 Id - Xb Xb^T,  Xb = X - X^c
 *             (2D: [[Xb2^2, -Xb1 Xb2], [-Xb1 Xb2, Xb1^2]]),
 *
 * with I^1 >= I^2 (>= I^3) the principal moments of the inertia tensor
 * I = int c Ibar (cell_obs.h) and v_i their unit eigenvectors, all from the
 * observables at t^n (sp_cells_observe); in 3D Ihat^i = |v_i x Xb|^2. The
 * glue adds -sum_i coef_i v_i . Ibar(X) v_i to mu_k for the sp_shape_coef of
 * each cell (cxx_glue/assembly/physics.hpp, shape_mu); when the step is implicit it
 * first moves coef by -gain dI, dI the new state's change of the moments.
 * The moduli: delta^1 on the largest moment, delta^2 on the next, delta^3
 * (3D only; 0 on a 2D mesh) on the smallest, the long axis's.
 *
 * Round cells. For equal moments I^i = I^j the eigenvectors of that
 * eigenspace are arbitrary, and for I^i ~ I^j they swing with every small
 * change of c: the exact force tensor sum_i c_i v_i v_i^T,
 * c_i = 2 delta^i (I^i,ref - I^i), is then a discontinuous function of I (a
 * fixed magnitude (c_i - c_j)/2 along directions set by noise). The
 * coefficients handed to the glue are instead coef = W c, each a weighted
 * mean of the c_j of the moments close to I^i:
 *
 *     W_ij = K_ij / sum_l K_il,  K_ij = (1 - w_ij) / (1 + w_ij),
 *     w_ij = min(1, |I^i - I^j| / (tr(I) SP_SHAPE_ROUND_TOL)).
 *
 * K_ii = 1, K_ij = 0 once I^i and I^j are SP_SHAPE_ROUND_TOL tr(I) apart:
 * with every gap that large W = Id and coef = c exactly, the derivative of
 * Pi_MI. When I^i = I^j, rows i and j of K are equal (K depends on the gaps
 * only), so coef_i = coef_j: the force is isotropic in that eigenspace,
 * where the eigenvectors do not matter, and since W is continuous in the
 * moments the force tensor sum_i coef_i v_i v_i^T is a continuous function
 * of I at every degenerate state (a sphere: all three equal; a prolate or
 * oblate spheroid: two), bounded by max_j |c_j| (each coef_i is a convex
 * combination of the c_j). In 2D (n = 2) the same rule reads, with
 * e = (I^1 - I^2) / (I^1 + I^2) and w = min(1, e / SP_SHAPE_ROUND_TOL),
 *
 *     coef_1,2 = (c_1 + c_2)/2 +- w (c_1 - c_2)/2:
 *
 * the isotropic part of the force is kept and its deviatoric part
 * (c_1 - c_2)/2 (v_1 v_1^T - v_2 v_2^T) is scaled linearly to zero at the
 * round state (shape.c computes it in this closed form, the arithmetic the
 * 2D outputs were made with). Since e (v_1 v_1^T - v_2 v_2^T) =
 * 2 dev(I) / tr(I), the 2D force tensor is then direction-free at e = 0.
 * Below the tolerance (aspect ratio sqrt(I^1/I^2) below ~1.01) the force is
 * the derivative of Pi_MI with the kink of the eigenvalues at the
 * degenerate state rounded off (the eigenvalues are not differentiable
 * there); a degenerate state that the penalty makes unstable is still left
 * at a rate that grows with the gap. Everything is finite for any finite
 * input; a cell without core mass (tr I <= 0) or with non-finite
 * observables gets zero coefficients (no shape force).
 */
#ifndef SP_SHAPE_H
#define SP_SHAPE_H

#include "model/cells.h"
#include "model/division.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Relative gap (I^i - I^j)/tr(I) below which the coefficients of the two
 *  moments are blended toward each other (see above; 2D: the deviatoric
 *  part scaled down by e / SP_SHAPE_ROUND_TOL): 0.01 is an aspect ratio
 *  sqrt(I^1/I^2) of about 1.01. */
#define SP_SHAPE_ROUND_TOL 1e-2

/**
 * @brief Explicit shape-penalty coefficients of every cell (eigenvector form,
 *        round cells treated as in the file comment).
 * @param[in] dim the mesh's dimension: 2 or 3 principal moments
 * @param[in] n_cells number of cells
 * @param[in] obs per cell, the observables of c^n (centre, I^i, v_i)
 * @param[in] birth per cell, the reference moments Iref[i] = I^i+1,ref
 * @param[in] delta the moduli on I^1 (the largest moment), I^2, I^3 (0 in 2D)
 * @param[out] out n_cells entries for sp_step_data.shape; their gain is
 *             -d coef / d I with W frozen (used when the step is implicit)
 * @return SP_OK; SP_ERR_INPUT when a delta is negative or not finite, or
 *         delta[2] != 0 in 2D
 */
int sp_shape_coefficients(int dim, int n_cells, const sp_cell_obs *obs,
                          const sp_cell_birth *birth, const double delta[3],
                          sp_shape_coef *out);

/**
 * @brief The shape energy sum_k sum_i delta^i (I_k^i,ref - I_k^i)^2 of the
 *        observables @p obs (terms with delta^i = 0 left out; 0 when all are
 *        0; a 2D cell's delta[2] is 0).
 */
double sp_shape_energy(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                       const double delta[3]);

#ifdef __cplusplus
}
#endif
#endif
