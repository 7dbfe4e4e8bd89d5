/* solver.linear = gmres_cells: GMRES preconditioned by the Jacobian's
 * cell-diagonal part (the entries coupling two cells dropped), factored by
 * MUMPS. On three touching cells (paper parameters, 3 steps of dt = 1e-4)
 * it takes the same Newton iterations as serial SuperLU and the states
 * agree to 1e-9 of the largest value; the cells couple, so the
 * preconditioner is not A and GMRES needs more than one iteration per
 * Newton iteration. With one cell the cell-diagonal part is the whole
 * Jacobian: GMRES then converges in one iteration per solve (were the
 * filter to drop a cell's own entries it could not). At a loose
 * tolerance (1e-4), with Newton ending on a solve's update, each cell's
 * mass is still conserved to 1e-12 per step (the c rows of A and of the
 * preconditioner are the same: linear_gmres_cells.cpp says why that keeps the
 * masses). A tolerance GMRES
 * cannot reach fails the step and leaves the state; a bad tolerance is
 * refused naming solver.krylov_tol. */
#include <string.h>

#include "fixtures.h"

enum { N_STEPS = 3 };

/* N_STEPS steps of both solvers from the same state: Newton iterations
 * equal, states to 1e-9; returns the GMRES and Newton iterations. */
static void compare_with_superlu(const sp_mesh *mesh, const sp_layout *layout,
                                 const double *start, const char *what, long *gmres_its,
                                 long *newton_its) {
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_CELLS);
  opt.krylov_tol = 1e-10; /* the scene's default */
  sp_solver solvers[2] = {make_solver_opts(mesh, layout, &opt),
                          make_solver_with(mesh, layout, SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU)};
  const int n = 2 * layout->n_pairs;
  double *x[2], *old = malloc(sizeof(double) * n);
  for (int s = 0; s < 2; ++s) {
    x[s] = malloc(sizeof(double) * n);
    memcpy(x[s], start, sizeof(double) * n);
  }
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  *gmres_its = *newton_its = 0;
  for (int step = 0; step < N_STEPS; ++step) {
    sp_step_report rep[2];
    for (int s = 0; s < 2; ++s) {
      memcpy(old, x[s], sizeof(double) * n);
      CHECK(sp_solver_step(solvers[s], &data, x[s], &rep[s]) == 0, "%s, step %d: %s", what, step,
            rep[s].reason);
    }
    check_same_step(what, step, "cells' blocks / SuperLU", rep, x[0], x[1], n, 1e-9);
    CHECK(rep[1].linear_its == 0, "SuperLU reports %ld GMRES iterations", rep[1].linear_its);
    *gmres_its += rep[0].linear_its;
    *newton_its += rep[0].newton_its;
  }
  for (int s = 0; s < 2; ++s) {
    sp_solver_destroy(&solvers[s]);
    free(x[s]);
  }
  free(old);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const double d = sqrt(1e-3 / 8);
  long gmres, newton;

  /* three touching cells: coupled, so more than one GMRES iteration a solve */
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  int n = 2 * layout->n_pairs;
  double *x = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, x);
  compare_with_superlu(mesh, layout, x, "three cells", &gmres, &newton);
  CHECK(gmres > newton, "three cells: %ld GMRES iterations for %ld Newton iterations", gmres,
        newton);

  /* a loose tolerance: the masses stay to round-off */
  {
    sp_solver_options loose = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_CELLS);
    loose.krylov_tol = 1e-4;
    loose.newton_rtol = 1e-3; /* Newton ends on a solve's update: its */
    loose.newton_atol = 1e-9; /* residual is the GMRES's */
    sp_solver s = make_solver_opts(mesh, layout, &loose);
    double *z = malloc(sizeof(double) * n), *zold = malloc(sizeof(double) * n);
    memcpy(z, x, sizeof(double) * n);
    sp_step_data zdata = {.dt = 1e-4, .model = paper_model(), .state_old = zold};
    double worst = 0;
    long its = 0;
    for (int step = 0; step < N_STEPS; ++step) {
      sp_cell_obs before[3], after[3];
      memcpy(zold, z, sizeof(double) * n);
      CHECK_OK(sp_cells_observe(mesh, layout, z, 0, before));
      sp_step_report zrep;
      CHECK(sp_solver_step(s, &zdata, z, &zrep) == 0, "krylov_tol 1e-4, step %d: %s", step,
            zrep.reason);
      its += zrep.linear_its;
      CHECK_OK(sp_cells_observe(mesh, layout, z, 0, after));
      for (int k = 0; k < 3; ++k)
        worst = fmax(worst, fabs(after[k].mass - before[k].mass) / before[k].mass);
    }
    printf("krylov_tol 1e-4: %ld GMRES iterations in %d steps (1e-10: %ld); largest relative mass "
           "change per step %.2e\n",
           its, N_STEPS, gmres, worst);
    CHECK(worst <= 1e-12, "krylov_tol 1e-4: a cell's mass changed by %.3e in a step", worst);
    CHECK(its < gmres, "krylov_tol 1e-4 took %ld GMRES iterations, 1e-10 %ld", its, gmres);
    sp_solver_destroy(&s);
    free(z);
    free(zold);
  }

  /* an unreachable tolerance: the step fails, the state stays */
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_CELLS);
  check_unreachable_tolerance(mesh, layout, opt, x);
  free(x);
  sp_layout_destroy(&layout);

  /* one cell: the preconditioner is the Jacobian itself */
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  n = 2 * layout->n_pairs;
  x = calloc(n, sizeof(double));
  set_disk(mesh, layout, x, 0, 0.45, 0.5, 0.2, d);
  compare_with_superlu(mesh, layout, x, "one cell", &gmres, &newton);
  CHECK(gmres == newton, "one cell: %ld GMRES iterations for %ld Newton iterations (want one each)",
        gmres, newton);
  free(x);
  sp_layout_destroy(&layout);

  const double bad[] = {1.5, -1e-8, 0};
  for (size_t b = 0; b < sizeof bad / sizeof bad[0]; ++b) {
    opt.krylov_tol = bad[b];
    expect_solver_refused(&opt, "solver.krylov_tol");
  }
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  TEST_DONE();
}
