/* Shared set-up of the method tests: a solver on a mesh and full layout,
 * cells as tanh disks, model parameters. */
#ifndef SP_TEST_FIXTURES_H
#define SP_TEST_FIXTURES_H
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"
#include "softpack_solver.h"
#include "run/resize.h"
#include "run/stepper.h"

/** A division's set-up: a 160 x 160 mesh of the unit square, full layouts
 *  of 1 cell (the parent) and 2 (the daughters), their states zeroed;
 *  split_teardown frees them. */
static inline void split_setup(sp_mesh **mesh, sp_layout **layout, sp_layout **new_layout,
                               double **state, double **new_state) {
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 160, 160, mesh));
  CHECK_OK(sp_layout_create_full((*mesh)->n_nodes, 1, layout));
  CHECK_OK(sp_layout_create_full((*mesh)->n_nodes, 2, new_layout));
  *state = calloc(2 * (size_t)(*layout)->n_pairs, sizeof(double));
  *new_state = calloc(2 * (size_t)(*new_layout)->n_pairs, sizeof(double));
}

static inline void split_teardown(sp_mesh **mesh, sp_layout **layout, sp_layout **new_layout,
                                  double **state, double **new_state) {
  free(*state);
  free(*new_state);
  *state = *new_state = NULL;
  sp_layout_destroy(layout);
  sp_layout_destroy(new_layout);
  sp_mesh_destroy(mesh);
}

/** The paper's parameters (table 1). */
static inline sp_model_params paper_model(void) {
  sp_model_params m = {.alpha = 4, .kappa = 1e-3, .lambda = 100, .lambda_b = 100, .mobility = 1};
  return m;
}

/** Two solvers' step from the same state, rep[0] and x0 the solver tested,
 *  rep[1] and x1 the reference (@p names says which is which): the same
 *  Newton iterations, the states equal to @p tol of the largest value of
 *  x1; prints both. */
static inline void check_same_step(const char *what, int step, const char *names,
                                   const sp_step_report rep[2], const double *x0,
                                   const double *x1, int n, double tol) {
  double scale = 0, diff = 0;
  for (int i = 0; i < n; ++i) {
    scale = fmax(scale, fabs(x1[i]));
    diff = fmax(diff, fabs(x0[i] - x1[i]));
  }
  printf("%s, step %d: Newton iterations %d / %d (%s), GMRES %ld; states differ by %.2e (of "
         "%.3g)\n",
         what, step, rep[0].newton_its, rep[1].newton_its, names, rep[0].linear_its, diff, scale);
  CHECK(rep[0].newton_its == rep[1].newton_its, "%s, step %d: Newton iterations %d against %d",
        what, step, rep[0].newton_its, rep[1].newton_its);
  CHECK(diff <= tol * scale, "%s, step %d: states differ by %.3e", what, step, diff);
}

/** The tests' Newton options: tight tolerances, a new Jacobian every iteration. */
static inline sp_solver_options test_options(int jacobian, int linear) {
  sp_solver_options opt = {.jacobian = jacobian, .linear = linear,
                           .newton_rtol = 1e-10, .newton_atol = 1e-11, .newton_max_its = 20};
  return opt;
}

/** A solver with @p opt on the mesh and layout. */
static inline sp_solver make_solver_opts(const sp_mesh *mesh, const sp_layout *layout,
                                         const sp_solver_options *opt) {
  sp_solver s = NULL;
  if (sp_solver_create(MPI_COMM_WORLD, opt, &s) != 0) {
    fprintf(stderr, "sp_solver_create: %s\n", sp_solver_last_error(s));
    exit(1);
  }
  if (sp_solver_attach(s, mesh, layout) != SP_OK) {
    fprintf(stderr, "%s\n", sp_error_message());
    exit(1);
  }
  return s;
}

/** sp_solver_create refuses @p opt, with a message naming @p key. */
static inline void expect_solver_refused(const sp_solver_options *opt, const char *key) {
  sp_solver s = NULL;
  CHECK(sp_solver_create(MPI_COMM_WORLD, opt, &s) != 0, "options bad in %s were accepted", key);
  CHECK(strstr(sp_solver_last_error(s), key) != NULL, "the message does not name %s: %s", key,
        sp_solver_last_error(s));
  sp_solver_destroy(&s);
}

/** A Krylov solver with @p opt at krylov_tol 1e-30 takes a step of 1e-4
 *  (paper parameters) from @p x: the step fails at the first linear solve
 *  (no Newton update, one factorisation, some GMRES iterations, a reason
 *  naming GMRES) and leaves the state as it was. */
static inline void check_unreachable_tolerance(const sp_mesh *mesh, const sp_layout *layout,
                                               sp_solver_options opt, const double *x) {
  opt.krylov_tol = 1e-30;
  sp_solver strict = make_solver_opts(mesh, layout, &opt);
  const int n = 2 * layout->n_pairs;
  double *y = malloc(sizeof(double) * n), *old = malloc(sizeof(double) * n);
  memcpy(y, x, sizeof(double) * n);
  memcpy(old, x, sizeof(double) * n);
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  sp_step_report rep;
  CHECK(sp_solver_step(strict, &data, y, &rep) == 1, "a step with krylov_tol 1e-30 succeeded");
  printf("krylov_tol 1e-30: %s\n", rep.reason);
  CHECK(rep.converged == 0 && rep.newton_its == 0 && rep.factorisations == 1 &&
            rep.linear_its > 0 && strstr(rep.reason, "GMRES") != NULL,
        "reason: %s; %d Newton iterations, %d factorisations, %ld GMRES iterations", rep.reason,
        rep.newton_its, rep.factorisations, rep.linear_its);
  CHECK(memcmp(y, x, sizeof(double) * n) == 0, "the failed step changed the state");
  sp_solver_destroy(&strict);
  free(y);
  free(old);
}

/** A solver with direct solver @p linear (SP_SOLVER_*) on the mesh and layout. */
static inline sp_solver make_solver_with(const sp_mesh *mesh, const sp_layout *layout,
                                         int jacobian, int linear) {
  sp_solver_options opt = test_options(jacobian, linear);
  return make_solver_opts(mesh, layout, &opt);
}

static inline sp_solver make_solver(const sp_mesh *mesh, const sp_layout *layout, int jacobian) {
  return make_solver_with(mesh, layout, jacobian, SP_LINEAR_SUPERLU);
}

/** The largest relative difference of Jacobian kinds @p a and @p b at
 *  @p state (sp_solver_compare_jacobians); -1, with the solver's message
 *  printed, if the comparison failed. */
static inline double jacobian_difference(sp_solver s, const sp_step_data *data,
                                         const double *state, int a, int b) {
  double diff = -1;
  if (sp_solver_compare_jacobians(s, data, state, a, b, &diff) != 0) {
    fprintf(stderr, "compare_jacobians: %s\n", sp_solver_last_error(s));
    return -1;
  }
  return diff;
}

/** A random step on @p layout for the Jacobian checks: c in [-0.1, 1.1]
 *  (beyond the wells too), mu in [-5, 5], c^n in [0, 1], a source in
 *  [-50, 50]; the three arrays malloc'ed (the caller frees them). */
static inline void random_step_arrays(const sp_layout *layout, unsigned long long seed,
                                      double **state, double **old, double **source) {
  const int n = 2 * layout->n_pairs;
  *state = malloc(n * sizeof(double));
  *old = malloc(n * sizeof(double));
  *source = malloc(layout->n_pairs * sizeof(double));
  unsigned long long rng = seed;
  for (int i = 0; i < n; ++i) {
    (*state)[i] = i % 2 == 0 ? 0.5 + 0.6 * sp_random_symmetric(&rng) : 5 * sp_random_symmetric(&rng);
    (*old)[i] = 0.5 + 0.5 * sp_random_symmetric(&rng);
  }
  for (int p = 0; p < layout->n_pairs; ++p) (*source)[p] = 50 * sp_random_symmetric(&rng);
}

/** c_k = tanh disk of radius R at (x, y) with width d; mu_k = 0. */
static inline void set_disk(const sp_mesh *mesh, const sp_layout *layout, double *state, int k,
                            double x, double y, double R, double d) {
  for (int i = 0; i < mesh->n_nodes; ++i) {
    int p = sp_layout_pair(layout, k, i);
    if (p < 0) continue;
    double r = hypot(mesh->xy[2 * i] - x, mesh->xy[2 * i + 1] - y);
    state[2 * p] = 1.0 / (1.0 + exp((r - R) / d));
    state[2 * p + 1] = 0.0;
  }
}

/** The unit square in 40 x 40 elements with every one of three cells on
 *  every node: the problem of set_three_touching_disks. */
static inline void three_cell_problem(sp_mesh **mesh, sp_layout **layout) {
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 40, 40, mesh));
  CHECK_OK(sp_layout_create_full((*mesh)->n_nodes, 3, layout));
}

/** Three touching cells on the unit square (width d = sqrt(kappa / 2 alpha)
 *  of the paper's parameters): the typical step of test_newton,
 *  test_jacobian_reuse, test_jacobian_hand, test_ordering and mpi_compare's
 *  iterates. */
static inline void set_three_touching_disks(const sp_mesh *mesh, const sp_layout *layout,
                                            double *state) {
  const double d = sqrt(1e-3 / 8);
  set_disk(mesh, layout, state, 0, 0.35, 0.5, 0.15, d);
  set_disk(mesh, layout, state, 1, 0.65, 0.5, 0.15, d);
  set_disk(mesh, layout, state, 2, 0.5, 0.75, 0.11, d);
}

/** c_k = 1 / (1 + exp((rho - 1) / eps)), rho = sqrt((u/a)^2 + (v/b)^2),
 *  (u, v) the coordinates along the ellipse's axes (the a axis at angle
 *  phi), centred at (x, y), no background; mu_k = 0. */
static inline void set_ellipse(const sp_mesh *mesh, const sp_layout *layout, double *state, int k,
                               double x, double y, double a, double b, double phi,
                               double eps) {
  const double cs = cos(phi), sn = sin(phi);
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, k, i);
    if (p < 0) continue;
    const double dx = mesh->xy[2 * i] - x, dy = mesh->xy[2 * i + 1] - y;
    const double u = cs * dx + sn * dy, v = -sn * dx + cs * dy;
    const double rho = sqrt((u / a) * (u / a) + (v / b) * (v / b));
    state[2 * p] = 1.0 / (1.0 + exp((rho - 1.0) / eps));
    state[2 * p + 1] = 0.0;
  }
}

static inline double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double norm3(const double *a) { return sqrt(dot3(a, a)); }

/** The angle between two lines (undirected) in 3D, in [0, pi/2]. */
static inline double line_angle3(const double *a, const double *b) {
  const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
  return atan2(norm3(c), fabs(dot3(a, b)));
}

/** The 3D twin of set_ellipse on a 3D mesh: c_k = 1 / (1 + exp((rho - 1) /
 *  eps)), rho^2 = sum_j (u_j / semi[j])^2 with u_j = axes[j] . (X - centre)
 *  (axes: three orthonormal rows), no background; mu_k = 0. */
static inline void set_ellipsoid(const sp_mesh *mesh, const sp_layout *layout, double *state,
                                 int k, const double centre[3], const double axes[3][3],
                                 const double semi[3], double eps) {
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, k, i);
    if (p < 0) continue;
    const double *x = mesh->xy + 3 * (size_t)i;
    double rho2 = 0;
    for (int j = 0; j < 3; ++j) {
      const double u = axes[j][0] * (x[0] - centre[0]) + axes[j][1] * (x[1] - centre[1]) +
                       axes[j][2] * (x[2] - centre[2]);
      rho2 += (u / semi[j]) * (u / semi[j]);
    }
    state[2 * p] = 1.0 / (1.0 + exp((sqrt(rho2) - 1.0) / eps));
    state[2 * p + 1] = 0.0;
  }
}

/** Orthonormal rows: the rotation R_z(a) R_y(b) R_z(c) applied to the x,
 *  y, z axes (row j = R e_j). */
static inline void rotated_axes(double a, double b, double c, double axes[3][3]) {
  const double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
  const double R[3][3] = {{ca * cb * cc - sa * sc, -ca * cb * sc - sa * cc, ca * sb},
                          {sa * cb * cc + ca * sc, -sa * cb * sc + ca * cc, sa * sb},
                          {-sb * cc, sb * sc, cb}};
  for (int j = 0; j < 3; ++j)
    for (int d = 0; d < 3; ++d) axes[j][d] = R[d][j];
}

static inline double energy_total(sp_solver s, const sp_model_params *m, const double *state) {
  sp_energy_parts e;
  if (sp_solver_energy(s, m, state, &e) != 0) {
    fprintf(stderr, "energy: %s\n", sp_solver_last_error(s));
    exit(1);
  }
  return e.bulk + e.gradient + e.repulsion + e.buffer + e.adhesion;
}
#endif
