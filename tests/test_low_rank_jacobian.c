/* The Jacobian as Newton applies it with the implicit shape term on
 * (sp_solver_apply_jacobian; the sparse matrix plus the low-rank part U C V^T
 * that cxx_glue/linear/linear_low_rank.hpp solves by Woodbury), on three tanh
 * ellipses that overlap (a full layout on a 32 x 32 mesh), each with its own
 * shape gains:
 * 1. J^T is the transpose of J: <J^T x, y> = <x, J y> for random x, y, to
 *    1e-12 of sum |x_i| |(J y)_i| (round-off of the two sums); the low-rank
 *    part's share <x, U C V^T y> is checked to be far above that, so a
 *    transpose that forgot it (the sparse matrix's alone) fails;
 * 2. J is the derivative of the residual: J y equals the central difference
 *    (F(s + h y) - F(s - h y)) / 2h to 1e-6 of max |J y| (measured 1.4e-10),
 *    while the sparse part alone misses it by more than 1e-3. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "shape_fixtures.h"

enum { N_CELLS = 3 };

/* uniform in [-1, 1), a fixed sequence (LCG) */
static double random_unit(unsigned long long *seed) {
  *seed = *seed * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*seed >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

static double dot(const double *a, const double *b, size_t n) {
  double s = 0;
  for (size_t i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

typedef struct {
  sp_mesh *mesh;
  sp_layout *layout;
  size_t n;
  double *old, *state;
  sp_shape_coef coef[N_CELLS];
  sp_solver solver;
} problem;

/* c^n: three overlapping tanh ellipses on a background of 0.02; the state
 * the Jacobian is taken at: c^n moved by a smooth perturbation (so the
 * shape coefficients at the state differ from those at c^n). */
static problem problem_create(void) {
  problem pb;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 32, 32, &pb.mesh));
  CHECK_OK(sp_layout_create_full(pb.mesh->n_nodes, N_CELLS, &pb.layout));
  pb.n = 2 * (size_t)pb.layout->n_pairs;
  pb.old = calloc(pb.n, sizeof(double));
  pb.state = malloc(pb.n * sizeof(double));
  set_ellipse(pb.mesh, pb.layout, pb.old, 0, 0.36, 0.45, 0.2, 0.12, 0.3, 0.1);
  set_ellipse(pb.mesh, pb.layout, pb.old, 1, 0.62, 0.48, 0.18, 0.13, -0.5, 0.1);
  set_ellipse(pb.mesh, pb.layout, pb.old, 2, 0.5, 0.68, 0.15, 0.1, 1.2, 0.1);
  for (int p = 0; p < pb.layout->n_pairs; ++p) pb.old[2 * p] += 0.02;
  for (size_t i = 0; i < pb.n; ++i)
    pb.state[i] = pb.old[i] + (i % 2 == 0 ? 0.01 * sin(0.37 * (double)i) : 0.0);
  sp_cell_obs obs[N_CELLS];
  sp_cell_birth birth[N_CELLS];
  CHECK_OK(sp_cells_observe(pb.mesh, pb.layout, pb.old, 0.05, obs));
  for (int k = 0; k < N_CELLS; ++k)
    birth[k] = (sp_cell_birth){.birth_mass = obs[k].mass,
                               .Iref = {0.8 * obs[k].moments[0], 1.1 * obs[k].moments[1]}};
  CHECK_OK(sp_shape_coefficients(2, N_CELLS, obs, birth, (double[3]){2e5, 5e5, 0}, pb.coef));
  for (int k = 0; k < N_CELLS; ++k) pb.coef[k].threshold = 0.05;
  pb.solver = make_solver(pb.mesh, pb.layout, SP_SOLVER_JAC_AD);
  return pb;
}

static void problem_destroy(problem *pb) {
  sp_solver_destroy(&pb->solver);
  free(pb->old);
  free(pb->state);
  sp_layout_destroy(&pb->layout);
  sp_mesh_destroy(&pb->mesh);
}

static sp_step_data step_data(problem *pb, int implicit) {
  sp_step_data d = {.dt = 1e-4, .model = paper_model(), .state_old = pb->old,
                    .shape = pb->coef, .shape_implicit = implicit};
  return d;
}

static void apply(problem *pb, int implicit, int transpose, const double *x, double *y) {
  sp_step_data d = step_data(pb, implicit);
  CHECK(sp_solver_apply_jacobian(pb->solver, &d, pb->state, transpose, x, y) == 0, "%s",
        sp_solver_last_error(pb->solver));
}

/* 1. <J^T x, y> = <x, J y>, the low-rank part included. */
static void test_transpose(problem *pb) {
  const size_t n = pb->n;
  double *x = malloc(n * sizeof(double)), *y = malloc(n * sizeof(double));
  double *jy = malloc(n * sizeof(double)), *jtx = malloc(n * sizeof(double));
  double *sparse_jy = malloc(n * sizeof(double));
  unsigned long long seed = 20;
  for (int trial = 0; trial < 3; ++trial) {
    for (size_t i = 0; i < n; ++i) {
      x[i] = random_unit(&seed);
      y[i] = random_unit(&seed);
    }
    apply(pb, 1, 0, y, jy);
    apply(pb, 1, 1, x, jtx);
    apply(pb, 0, 0, y, sparse_jy); /* the sparse part alone */
    const double lhs = dot(jtx, y, n), rhs = dot(x, jy, n);
    double scale = 0;
    for (size_t i = 0; i < n; ++i) scale += fabs(x[i] * jy[i]);
    const double low_rank = rhs - dot(x, sparse_jy, n); /* <x, U C V^T y> */
    printf("transpose, trial %d: <J^T x, y> = %.15e, <x, J y> = %.15e, difference %.1e of "
           "sum |x||Jy| = %.3e; low-rank share %.3e\n",
           trial, lhs, rhs, fabs(lhs - rhs) / scale, scale, fabs(low_rank) / scale);
    CHECK(fabs(lhs - rhs) <= 1e-12 * scale, "trial %d: <J^T x, y> - <x, J y> = %.3g (scale %.3g)",
          trial, lhs - rhs, scale);
    CHECK(fabs(low_rank) >= 1e-6 * scale, "trial %d: the low-rank share %.3g is too small for "
          "the test to see it", trial, fabs(low_rank) / scale);
  }
  free(x);
  free(y);
  free(jy);
  free(jtx);
  free(sparse_jy);
}

/* 2. J y against central differences of the residual. */
static void test_derivative(problem *pb) {
  sp_step_data d = step_data(pb, 1);
  double err, err_sparse;
  implicit_jacobian_vs_fd(pb->solver, &d, pb->state, pb->n, 7, &err, &err_sparse);
  printf("derivative: max |J y - FD| / max |J y| = %.2e (sparse part alone: %.2e)\n", err,
         err_sparse);
  CHECK(err <= 1e-6, "J y differs from the residual's derivative by %.3g relative", err);
  CHECK(err_sparse >= 1e-3, "the sparse part alone is within %.3g: no low-rank part to test",
        err_sparse);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  problem pb = problem_create();
  test_transpose(&pb);
  test_derivative(&pb);
  problem_destroy(&pb);
  MPI_Finalize();
  TEST_DONE();
}
