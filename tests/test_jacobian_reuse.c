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
 * Carried across steps (solver.jacobian_carry = theta_c, same problem, a
 * third solver):
 * - the rule, exactly: a step after a converged one begins on the last
 *   factorisation, which serves while each iteration cuts ||F|| by
 *   theta_c; then theta as above;
 * - fewer factorisations than without the carry, and some step with none;
 * - the same states to 1e-8 and masses to 1e-12 per step.
 * Newton stopped on the update (sp_step_data.update_rtol/atol, the adaptive
 * control's), modified Newton from the last state: it stops in fewer
 * iterations than the residual test alone takes, and c is within the
 * update tolerance of the exact solve (the error left after an update is
 * at most theta / (1 - theta) < 1 times the update).
 * Bad values are refused by sp_solver_create / sp_solver_step. */
#include "fixtures.h"

enum { N_STEPS = 6 };

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  const double theta = 0.25;
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU);
  sp_solver newton = make_solver_opts(mesh, layout, &opt);
  opt.jacobian_reuse = theta;
  sp_solver modified = make_solver_opts(mesh, layout, &opt);
  const double theta_c = 0.35;
  opt.jacobian_carry = theta_c;
  sp_solver carry = make_solver_opts(mesh, layout, &opt);
  opt.jacobian_carry = 0;
  const int n = 2 * layout->n_pairs;
  double *a = calloc(n, sizeof(double)), *b = calloc(n, sizeof(double));
  double *old = calloc(n, sizeof(double)), *c = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, a);
  for (int i = 0; i < n; ++i) c[i] = b[i] = a[i];
  int carry_factorisations = 0, carry_steps_without = 0;
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

    for (int i = 0; i < n; ++i) old[i] = c[i];
    CHECK_OK(sp_cells_observe(mesh, layout, c, 0, before));
    CHECK(sp_solver_step(carry, &data, c, &rep) == 0, "carried step %d: %s", step,
          sp_solver_last_error(carry));
    CHECK_OK(sp_cells_observe(mesh, layout, c, 0, after));
    printf("carried step %d: %d iterations, %d factorisations\n", step, rep.newton_its,
           rep.factorisations);
    int fresh = step == 0; /* the first step has no factorisation to carry */
    expected = fresh;
    for (int k = 1; k < rep.newton_its; ++k)
      if (rep.residual_norms[k] > (expected ? theta : theta_c) * rep.residual_norms[k - 1])
        ++expected;
    CHECK(rep.factorisations == expected, "carried step %d: %d factorisations, the rule says %d",
          step, rep.factorisations, expected);
    carry_factorisations += rep.factorisations;
    carry_steps_without += rep.factorisations == 0;
    for (int k = 0; k < 3; ++k) {
      double rel = fabs(after[k].mass - before[k].mass) / before[k].mass;
      if (rel > worst_mass) worst_mass = rel;
    }
    diff = 0;
    for (int i = 0; i < n; ++i)
      if (fabs(a[i] - c[i]) > diff) diff = fabs(a[i] - c[i]);
    if (diff / big > worst_diff) worst_diff = diff / big;
  }
  printf("carried: %d factorisations, %d steps without one\n", carry_factorisations,
         carry_steps_without);
  CHECK(carry_factorisations < factorisations, "the carry saved nothing (%d against %d)",
        carry_factorisations, factorisations);
  CHECK(carry_steps_without >= 1, "no step ran on a carried factorisation alone");

  /* Stopping on the update: from the same state, one step with the
   * residual test alone (a) and one that may also stop on the update (b). */
  const double u_rtol = 1e-5, u_atol = 1e-5;
  for (int i = 0; i < n; ++i) old[i] = b[i] = a[i];
  sp_step_report tight, loose;
  CHECK(sp_solver_step(modified, &data, a, &tight) == 0, "tight step: %s",
        sp_solver_last_error(modified));
  sp_step_data by_update = data;
  by_update.update_rtol = u_rtol;
  by_update.update_atol = u_atol;
  CHECK(sp_solver_step(modified, &by_update, b, &loose) == 0, "step stopped on the update: %s",
        sp_solver_last_error(modified));
  double worst_c = 0;
  for (int p = 0; p < n / 2; ++p) {
    const double e = fabs(a[2 * p] - b[2 * p]) / (u_atol + u_rtol * fabs(a[2 * p]));
    if (e > worst_c) worst_c = e;
  }
  printf("stopped on the update: %d iterations (residual test: %d), c within %.3g of its "
         "tolerance of the exact solve\n", loose.newton_its, tight.newton_its, worst_c);
  CHECK(loose.newton_its < tight.newton_its, "no iteration saved (%d, %d)", loose.newton_its,
        tight.newton_its);
  CHECK(worst_c <= 1, "c off by %.3g x the update tolerance", worst_c);
  by_update.update_atol = 0; /* a relative tolerance alone is 0/0 where c = 0 */
  CHECK(sp_solver_step(newton, &by_update, b, &loose) != 0, "update_atol = 0 was accepted");
  CHECK(strstr(sp_solver_last_error(newton), "update_atol") != NULL,
        "the message does not name update_atol: %s", sp_solver_last_error(newton));
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
  opt.jacobian_reuse = theta;
  opt.jacobian_carry = -0.1;
  expect_solver_refused(&opt, "jacobian_carry");
  sp_solver_destroy(&carry);
  free(c);
  sp_solver_destroy(&newton);
  sp_solver_destroy(&modified);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(a); free(b); free(old);
  MPI_Finalize();
  TEST_DONE();
}
