/**
 * @file shape.h
 * @brief The shape penalty on principal moments of inertia (MODEL.md "Shape
 *        penalty", paper section 3), explicit in time as in the paper, or
 *        linearised implicit (shape.scheme; softpack_solver.h, the gains):
 *
 *     Pi_MI = sum_k sum_i delta^i (I_k^i,ref - I_k^i)^2,
 *     mu_k += - sum_i 2 delta^i (I_k^i,ref - I_k^i) Ihat_k^i(X),
 *     Ihat^i(X) = dI^i/dc(X) = v_i . Ibar(X) v_i,
 *     Ibar(X) = [[Xb2^2, -Xb1 Xb2], [-Xb1 Xb2, Xb1^2]],  Xb = X - X^c,
 *
 * with I^1 >= I^2 the principal moments and v_1, v_2 their unit
 * eigenvectors, all from the observables at t^n (sp_cells_observe). The glue
 * adds -sum_i coef_i v_i . Ibar(X) v_i to mu_k for the sp_shape_coef of each
 * cell (cxx_glue/physics.hpp, shape_mu); when the step is implicit it first
 * moves coef by -gain dI, dI the new state's change of the moments.
 *
 * Round cells. For I^1 = I^2 the eigenvectors are arbitrary, and for
 * I^1 ~ I^2 they swing with every small change of c: the exact force
 * sum_i coef_i v_i v_i^T is then a discontinuous function of I (a fixed
 * magnitude (coef_1 - coef_2)/2 along a direction set by noise). With
 * e = (I^1 - I^2) / (I^1 + I^2) the anisotropy and
 * w = min(1, e / SP_SHAPE_ROUND_TOL), the coefficients handed to the glue are
 *
 *     coef_1,2 = (c_1 + c_2)/2 +- w (c_1 - c_2)/2,   c_i = 2 delta^i (I^i,ref - I^i),
 *
 * i.e. the isotropic part of the force is kept and its deviatoric part
 * (c_1 - c_2)/2 (v_1 v_1^T - v_2 v_2^T) is scaled linearly to zero at the
 * round state. Since e (v_1 v_1^T - v_2 v_2^T) = 2 dev(I) / tr(I), the force
 * tensor is then a continuous function of I (direction-free at e = 0) and is
 * bounded by max(|c_1|, |c_2|); for e >= SP_SHAPE_ROUND_TOL (aspect ratio
 * sqrt(I^1/I^2) above ~1.01) it is exactly the derivative of Pi_MI. Below,
 * it is the derivative of Pi_MI with the kink of I^1 and I^2 at the round
 * state rounded off (the eigenvalues are not differentiable there); the round
 * state, unstable when the penalty favours elongation, still leaves it at a
 * rate that grows with e. Everything is finite for any finite input; a cell
 * without core mass (I^1 + I^2 <= 0) or with non-finite observables gets
 * zero coefficients (no shape force).
 */
#ifndef SP_SHAPE_H
#define SP_SHAPE_H

#include "cells.h"
#include "division.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Anisotropy e = (I^1 - I^2)/(I^1 + I^2) below which the deviatoric part of
 *  the shape force is scaled down by e / SP_SHAPE_ROUND_TOL (see above):
 *  e = 0.01 is an aspect ratio sqrt(I^1/I^2) of about 1.01. */
#define SP_SHAPE_ROUND_TOL 1e-2

/**
 * @brief Explicit shape-penalty coefficients of every cell (eigenvector form,
 *        round cells treated as in the file comment).
 * @param[in] n_cells number of cells
 * @param[in] obs per cell, the observables of c^n (centre, I^1, I^2, v_1, v_2)
 * @param[in] birth per cell, the reference moments Iref[0] = I^1,ref,
 *            Iref[1] = I^2,ref
 * @param[in] delta1, delta2 the moduli on I^1 (the larger moment) and I^2
 * @param[out] out n_cells entries for sp_step_data.shape; their gain is
 *             -d coef / d I with w frozen (used when the step is implicit)
 * @return SP_OK; SP_ERR_INPUT when a delta is negative or not finite
 */
int sp_shape_coefficients(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                          double delta1, double delta2, sp_shape_coef *out);

/**
 * @brief The shape energy sum_k sum_i delta^i (I_k^i,ref - I_k^i)^2 of the
 *        observables @p obs (0 when both deltas are 0).
 */
double sp_shape_energy(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                       double delta1, double delta2);

#ifdef __cplusplus
}
#endif
#endif
