/* Shared set-up of the shape-penalty tests (test_shape.c,
 * test_shape_implicit.c): the central difference of the shape energy in one
 * nodal value, and an elongated cell relaxing under the penalty. */
#ifndef SP_TEST_SHAPE_FIXTURES_H
#define SP_TEST_SHAPE_FIXTURES_H
#include <string.h>

#include "fixtures.h"
#include "model/shape.h"

/** The observables (threshold 0) with the nodal c of pair @p p moved by
 *  +step and -step; the state is restored. */
static inline void observe_plus_minus(const sp_mesh *mesh, const sp_layout *layout,
                                      double *state, int p, double step, sp_cell_obs *plus,
                                      sp_cell_obs *minus) {
  const double c0 = state[2 * p];
  state[2 * p] = c0 + step;
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, plus));
  state[2 * p] = c0 - step;
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, minus));
  state[2 * p] = c0;
}

/** dE_shape/dc_p by a central difference of step @p step in the nodal value
 *  of pair @p p (cell 0, moments counting every c: threshold 0). */
static inline double shape_energy_fd(const sp_mesh *mesh, const sp_layout *layout,
                                     double *state, int p, double step,
                                     const sp_cell_birth *birth, double delta1,
                                     double delta2) {
  sp_cell_obs plus, minus;
  observe_plus_minus(mesh, layout, state, p, step, &plus, &minus);
  return (sp_shape_energy(1, &plus, birth, (double[3]){delta1, delta2, 0}) -
          sp_shape_energy(1, &minus, birth, (double[3]){delta1, delta2, 0})) / (2 * step);
}

/** The implicit shape term's Jacobian against the residual: for a random
 *  y (seed @p seed), J y (sp_solver_apply_jacobian with @p d, implicit)
 *  against the central difference (F(s + h y) - F(s - h y)) / 2h,
 *  h = 1e-6, and the sparse part alone (d explicit) against the same;
 *  both as max |. - FD| / max |J y|. */
static inline void implicit_jacobian_vs_fd(sp_solver solver, const sp_step_data *d,
                                           const double *state, size_t n,
                                           unsigned long long seed, double *err,
                                           double *err_sparse) {
  double *y = malloc(n * sizeof(double)), *jy = malloc(n * sizeof(double));
  double *sparse_jy = malloc(n * sizeof(double)), *plus = malloc(n * sizeof(double));
  double *minus = malloc(n * sizeof(double)), *fp = malloc(n * sizeof(double));
  double *fm = malloc(n * sizeof(double));
  for (size_t i = 0; i < n; ++i) y[i] = sp_random_symmetric(&seed);
  sp_step_data explicit_d = *d;
  explicit_d.shape_implicit = 0;
  CHECK(sp_solver_apply_jacobian(solver, d, state, 0, y, jy) == 0, "%s",
        sp_solver_last_error(solver));
  CHECK(sp_solver_apply_jacobian(solver, &explicit_d, state, 0, y, sparse_jy) == 0, "%s",
        sp_solver_last_error(solver));
  const double h = 1e-6;
  for (size_t i = 0; i < n; ++i) {
    plus[i] = state[i] + h * y[i];
    minus[i] = state[i] - h * y[i];
  }
  CHECK(sp_solver_residual(solver, d, plus, fp) == 0, "%s", sp_solver_last_error(solver));
  CHECK(sp_solver_residual(solver, d, minus, fm) == 0, "%s", sp_solver_last_error(solver));
  double e = 0, e_sparse = 0, scale = 0;
  for (size_t i = 0; i < n; ++i) {
    const double fd = (fp[i] - fm[i]) / (2 * h);
    e = fmax(e, fabs(jy[i] - fd));
    e_sparse = fmax(e_sparse, fabs(sparse_jy[i] - fd));
    scale = fmax(scale, fabs(jy[i]));
  }
  *err = e / scale;
  *err_sparse = e_sparse / scale;
  free(y); free(jy); free(sparse_jy); free(plus); free(minus); free(fp); free(fm);
}

/** An elongated cell relaxing under the penalty (relax_ellipse). */
typedef struct {
  double delta2;       /**< delta1 = 0 */
  double iref2_factor; /**< I2,ref = this x the cell's I2 at the start */
  double threshold;    /**< the moments count c >= this (and the term acts there) */
  double background;   /**< c += background (1 - c) */
  int implicit;        /**< sp_step_data.shape_implicit */
  int linear;          /**< SP_LINEAR_SUPERLU, ... */
  int steps;
  double dt;
} relax_setup;

/** One cell on a 64 x 64 mesh of [0, 0.5]^2 (full layout): the state (zero)
 *  and a c^n buffer of the same size. */
typedef struct {
  sp_mesh *mesh;
  sp_layout *layout;
  size_t n_values;
  double *state, *old;
} one_cell;

static inline one_cell one_cell_create(void) {
  one_cell o;
  CHECK_OK(sp_mesh_rectangle(0, 0, 0.5, 0.5, 64, 64, &o.mesh));
  CHECK_OK(sp_layout_create_full(o.mesh->n_nodes, 1, &o.layout));
  o.n_values = 2 * (size_t)o.layout->n_pairs;
  o.state = calloc(o.n_values, sizeof(double));
  o.old = malloc(o.n_values * sizeof(double));
  return o;
}

static inline void one_cell_destroy(one_cell *o) {
  free(o->state);
  free(o->old);
  sp_layout_destroy(&o->layout);
  sp_mesh_destroy(&o->mesh);
}

typedef struct {
  int ok;                  /**< every step converged */
  int steps_done, newton_its;
  double rise;             /**< largest relative energy rise (fields + shape) over a step */
  double i2_start, i2_end, i2_ref, energy_start, energy_end;
  sp_step_report first;    /**< the first step's report */
  sp_step_report failed;   /**< the failed step's report (when !ok) */
} relax_result;

/** A 0.11 x 0.09 tanh ellipse (width d across its minor axis) on a 64 x 64
 *  mesh of [0, 0.5]^2, no source, steps of dt with the shape coefficients
 *  of each c^n (shape term off when delta2 = 0); stops at a failed step. */
static inline relax_result relax_ellipse(relax_setup r) {
  relax_result out = {.ok = 1};
  one_cell o = one_cell_create();
  const sp_mesh *mesh = o.mesh;
  const sp_layout *layout = o.layout;
  const size_t n_values = o.n_values;
  double *state = o.state, *old = o.old;
  const sp_model_params model = paper_model();
  const double d = sqrt(model.kappa / (2 * model.alpha));
  /* eps in rho units: the width d across the minor axis */
  set_ellipse(mesh, layout, state, 0, 0.2517, 0.2489, 0.11, 0.09, 0.0, d / 0.09);
  for (int p = 0; p < layout->n_pairs; ++p) state[2 * p] += r.background * (1 - state[2 * p]);
  sp_cell_obs obs;
  CHECK_OK(sp_cells_observe(mesh, layout, state, r.threshold, &obs));
  const sp_cell_birth birth = {.birth_mass = obs.mass_core,
                               .Iref = {obs.moments[0], r.iref2_factor * obs.moments[1]}};
  out.i2_start = obs.moments[1];
  out.i2_ref = birth.Iref[1];
  sp_solver solver = make_solver_with(mesh, layout, SP_SOLVER_JAC_AD, r.linear);
  double energy = energy_total(solver, &model, state) +
                  sp_shape_energy(1, &obs, &birth, (double[3]){0.0, r.delta2, 0});
  out.energy_start = energy;
  for (int n = 0; n < r.steps; ++n) {
    sp_shape_coef sc;
    CHECK_OK(sp_shape_coefficients(2, 1, &obs, &birth, (double[3]){0.0, r.delta2, 0}, &sc));
    sc.threshold = r.threshold; /* the term acts where the moments count c */
    memcpy(old, state, n_values * sizeof(double));
    sp_step_data data = {.dt = r.dt, .model = model, .state_old = old,
                         .shape = r.delta2 > 0 ? &sc : NULL, .shape_implicit = r.implicit};
    sp_step_report rep;
    const int rc = sp_solver_step(solver, &data, state, &rep);
    if (n == 0) out.first = rep;
    if (rc != 0) {
      out.ok = 0;
      out.failed = rep;
      break;
    }
    out.newton_its += rep.newton_its;
    CHECK_OK(sp_cells_observe(mesh, layout, state, r.threshold, &obs));
    const double e = energy_total(solver, &model, state) +
                     sp_shape_energy(1, &obs, &birth, (double[3]){0.0, r.delta2, 0});
    out.rise = fmax(out.rise, (e - energy) / fabs(energy));
    energy = e;
    ++out.steps_done;
  }
  out.energy_end = energy;
  out.i2_end = obs.moments[1];
  sp_solver_destroy(&solver);
  one_cell_destroy(&o);
  return out;
}
#endif
