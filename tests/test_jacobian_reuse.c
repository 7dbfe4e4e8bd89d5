/* Modified Newton (solver.jacobian_reuse = theta): an iteration keeps the
 * last Jacobian's factorisation when the previous iteration cut ||F|| by
 * at least theta. Three touching cells, paper parameters, 6 steps of
 * dt = 1e-4 from tanh disks, against Newton's method (theta = 0):
 * - the rule, exactly: per step, factorisations = 1 + the iterations k >= 1
 *   (not the last) with ||F_k|| > theta ||F_k-1||;
 * - fewer factorisations than iterations over the run;
 * - the same states (both converge to the same tolerance) to 1e-8 of the
 *   largest value;
 * - every cell's mass conserved to 1e-12 per step (any Jacobian with the
 *   exact, linear mass rows conserves it).
 * A bad value is refused by sp_solver_create. */
#include "fixtures.h"

enum { N_STEPS = 6 };

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  const double theta = 0.25;
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_SOLVER_SUPERLU);
  sp_solver newton = make_solver_opts(mesh, layout, &opt);
  opt.jacobian_reuse = theta;
  sp_solver modified = make_solver_opts(mesh, layout, &opt);
  const int n = 2 * layout->n_pairs;
  double *a = calloc(n, sizeof(double)), *b = calloc(n, sizeof(double));
  double *old = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, a);
  for (int i = 0; i < n; ++i) b[i] = a[i];
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  int its_newton = 0, its = 0, factorisations = 0;
  double worst_diff = 0, worst_mass = 0;
  for (int step = 0; step < N_STEPS; ++step) {
    sp_step_report rep;
    for (int i = 0; i < n; ++i) old[i] = a[i];
    CHECK(sp_solver_step(newton, &data, a, &rep) == 0, "Newton step %d: %s", step,
          sp_solver_last_error(newton));
    CHECK(rep.factorisations == rep.newton_its, "Newton step %d: %d factorisations, %d its",
          step, rep.factorisations, rep.newton_its);
    its_newton += rep.newton_its;

    sp_cell_obs before[3], after[3];
    for (int i = 0; i < n; ++i) old[i] = b[i];
    CHECK_OK(sp_cells_observe(mesh, layout, b, 0, before));
    CHECK(sp_solver_step(modified, &data, b, &rep) == 0, "modified step %d: %s", step,
          sp_solver_last_error(modified));
    CHECK_OK(sp_cells_observe(mesh, layout, b, 0, after));
    int expected = 1;
    printf("step %d: %d iterations, %d factorisations, |F|:", step, rep.newton_its,
           rep.factorisations);
    for (int k = 0; k < rep.n_residuals; ++k) printf(" %.2e", rep.residual_norms[k]);
    printf("\n");
    for (int k = 1; k < rep.newton_its; ++k)
      expected += rep.residual_norms[k] > theta * rep.residual_norms[k - 1];
    CHECK(rep.factorisations == expected, "step %d: %d factorisations, the rule says %d", step,
          rep.factorisations, expected);
    its += rep.newton_its;
    factorisations += rep.factorisations;
    for (int k = 0; k < 3; ++k) {
      double rel = fabs(after[k].mass - before[k].mass) / before[k].mass;
      if (rel > worst_mass) worst_mass = rel;
    }
    double big = 0, diff = 0;
    for (int i = 0; i < n; ++i) {
      if (fabs(a[i]) > big) big = fabs(a[i]);
      if (fabs(a[i] - b[i]) > diff) diff = fabs(a[i] - b[i]);
    }
    if (diff / big > worst_diff) worst_diff = diff / big;
  }
  printf("Newton: %d iterations = factorisations; modified: %d iterations, %d factorisations\n",
         its_newton, its, factorisations);
  printf("largest state difference %.3g (of the largest value), largest relative mass change "
         "per step %.3g\n", worst_diff, worst_mass);
  CHECK(factorisations < its, "no iteration reused a factorisation (%d of %d)", factorisations,
        its);
  CHECK(worst_diff <= 1e-8, "states differ by %.3g", worst_diff);
  CHECK(worst_mass <= 1e-12, "mass changed by %.3g", worst_mass);

  opt.jacobian_reuse = 1.0;
  expect_solver_refused(&opt, "jacobian_reuse");
  sp_solver_destroy(&newton);
  sp_solver_destroy(&modified);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(a); free(b); free(old);
  MPI_Finalize();
  TEST_DONE();
}
