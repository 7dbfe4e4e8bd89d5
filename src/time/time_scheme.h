/**
 * @file time_scheme.h
 * @brief What a step solves and what error it made: backward Euler or
 *        variable-step BDF2 on c (mu is algebraic: no time derivative, no
 *        history, no error estimate), the local error estimate the
 *        controller (dt_control.h) judges, and the first step.
 *
 * BDF2 through the BE solver. With omega = dt / dt_prev, variable-step BDF2
 *
 *   (1+2w)/(1+w) c^{n+1} - (1+w) c^n + w^2/(1+w) c^{n-1} = dt F(c^{n+1})
 *
 * is a backward-Euler step (c^{n+1} - c_hat) = dt_eff F(c^{n+1}) from
 *
 *   c_hat = ((1+w)^2 c^n - w^2 c^{n-1}) / (1+2w),  dt_eff = dt (1+w)/(1+2w),
 *
 * so the glue solves both schemes with one residual. The weights of c_hat
 * sum to one, so each cell's mass is conserved when c^n and c^{n-1} have the
 * same mass (s = 0), whatever the step ratios. Zero-stability needs
 * w < 1 + sqrt(2): the controller grows dt by at most SP_DT_GROW_MAX = 2.
 *
 * Error estimates (Milne's device): the new c against an extrapolation of
 * the past states, P, at t^{n+1}; with h = dt, h1 = t^n - t^{n-1},
 * h2 = t^{n-1} - t^{n-2}:
 *   BE   (P linear through c^{n-1}, c^n):   e = h / (2h + h1) (c - P)
 *   BDF2 (P quadratic through c^{n-2..n}): e = h (h + h1) /
 *        (3h^2 + 4h h1 + 2h h2 + h1^2 + h1 h2) (c - P)      (2/11 for equal steps)
 *   BDF2 with one past state (the second step after a start or an event):
 *        BE's estimate, which bounds the second-order step's error, so
 *        that step is judged too.
 * weighed as max_i |e_i| / (atol + rtol max(|c^n_i|, |c_i|)) over the c
 * unknowns of every cell: 1 is on tolerance. A max norm, not an RMS, so the
 * tolerance means the same with full and local supports.
 */
#ifndef SP_TIME_SCHEME_H
#define SP_TIME_SCHEME_H

#include <stddef.h>

#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { SP_SCHEME_BE = 0, SP_SCHEME_BDF2 = 1 } sp_scheme_kind;

/** Adaptive control: Newton also stops once its last update of c is below
 *  this fraction of the error tolerance (sp_step_data.update_rtol/atol). */
#define SP_SCHEME_NEWTON_FRACTION 0.01

/** Safety factor on the convexity bound of the first step. */
#define SP_SCHEME_FIRST_SAFETY 0.5

/**
 * The past states a step needs, on the current layout (2 values per pair,
 * as the state): past[0] at t^{n-1}, past[1] at t^{n-2}; dt[0] = t^n -
 * t^{n-1}, dt[1] = t^{n-1} - t^{n-2}. n: how many are valid (0 after the
 * start and after a division: an event starts the scheme over).
 */
typedef struct {
  int n;
  double *past[2];
  double dt[2];
} sp_history;

/** @brief Record the accepted step state_old -> (new state) of length dt:
 *         state_old becomes past[0] (n_values values copied). */
int sp_history_push(sp_history *h, const double *state_old, double dt, size_t n_values);

/** @brief Forget the past (after a division, an event): the next step is
 *         BE, and no estimate mixes states from before and after it. */
void sp_history_reset(sp_history *h);

void sp_history_free(sp_history *h);

/**
 * @brief Carry the past states to a new layout by their increments against
 *        the state: past_new = state_new - transfer(state_old - past_old),
 *        0 increments on new pairs, then each cell's increment shifted to
 *        the mass it had on the old layout (0 with s = 0; weights:
 *        sp_cells_pair_weights), so a BDF2 step after a support change
 *        still conserves each cell's mass, and a growing cell's history
 *        keeps its growth.
 */
int sp_history_transfer(sp_history *h, const sp_mesh *mesh, const sp_layout *from,
                        const double *state_from, const sp_layout *to,
                        const double *state_to);

/** @brief The scheme a step takes: BDF2 needs one past state, else BE. */
sp_scheme_kind sp_scheme_of_step(sp_scheme_kind scheme, const sp_history *h);

/** @brief 1 if the step of this kind has an error estimate: one past state
 *         (BDF2 with one is judged by BE's estimate, with two by its own). */
int sp_scheme_has_estimate(sp_scheme_kind kind, const sp_history *h);

/**
 * @brief The backward-Euler form of the step: c_hat into @p state_old_eff
 *        (mu copied from @p state) and *dt_eff. BE: the state and dt.
 */
void sp_scheme_be_form(sp_scheme_kind kind, const sp_history *h, double dt,
                       const double *state, size_t n_pairs, double *state_old_eff,
                       double *dt_eff);

/** @brief Extrapolate the past to t^n + dt (order 1: linear, needs one past
 *         state; order 2: quadratic, needs two), c and mu alike. */
void sp_scheme_extrapolate(int order, const sp_history *h, double dt, const double *state,
                           size_t n_pairs, double *out);

/**
 * @brief The weighted local error estimate of a step of this kind from
 *        @p state (c^n) to @p state_new (see the file comment); -1 if the
 *        step has none. @p scratch: 2 n_pairs doubles.
 */
double sp_scheme_error(sp_scheme_kind kind, const sp_history *h, double dt,
                       const double *state, const double *state_new, size_t n_pairs,
                       double rtol, double atol, double *scratch);

/**
 * @brief The weighted max-norm of a step's increment of c, max_i |c_i -
 *        c^n_i| / (atol + rtol max(|c^n_i|, |c_i|)) (the estimate's
 *        weights): what a step without an estimate tells the next one
 *        (dt_control.h, sp_dt_unestimated).
 */
double sp_scheme_increment(const double *state, const double *state_new, size_t n_pairs,
                           double rtol, double atol);

/**
 * @brief A first step small enough that the backward-Euler step is a convex
 *        problem from @p state: the step minimises Pi + |c - c^n|^2_{H^-1} /
 *        (2 M dt), which is convex when dt < 4 kappa / (M L^2), L the
 *        largest negative curvature of the energy density over the nodes
 *        (double well and pair repulsion; a Gershgorin bound on each node's
 *        cell-by-cell Hessian). Returns SP_SCHEME_FIRST_SAFETY times that,
 *        at most @p dt_cap.
 */
double sp_scheme_first_dt(const sp_layout *layout, const double *state,
                          const sp_model_params *model, double dt_cap);

/**
 * @brief The same bound over the nodes where one of @p cells (a flag per
 *        cell; NULL: every node) has c >= @p threshold: the post-event
 *        step of the cells an event changed, not the mesh's worst overlap.
 */
double sp_scheme_first_dt_cells(const sp_layout *layout, const double *state,
                                const sp_model_params *model, double dt_cap,
                                const unsigned char *cells, double threshold);

#ifdef __cplusplus
}
#endif
#endif
