/* solver.linear = gmres_ilu: GMRES preconditioned by ILU(k) solves each
 * Newton iteration to krylov_tol x |b| instead of exactly. On three
 * touching cells (paper parameters, 3 steps of dt = 1e-4) it takes the
 * same Newton iterations as serial SuperLU and the states agree to 1e-9 of
 * the largest value, at ILU(2) and ILU(4) (the default 1e-10 is tight
 * enough that Newton cannot tell the difference); the step reports its
 * GMRES iterations (at least one per Newton iteration; none for SuperLU).
 * A tolerance GMRES cannot reach in its 500 iterations makes the step fail
 * with a reason naming GMRES and leaves the state untouched (the stepper
 * retries with a smaller dt), instead of ending the run. ILU(0) can be
 * asked for (0 is no default): its first step differs from ILU(2)'s. Bad
 * fill or tolerance, 0 included, is refused naming its key
 * (solver.ilu_fill, solver.krylov_tol). */
#include <string.h>

#include "fixtures.h"

enum { N_STEPS = 3 };

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_ILU);
  opt.ilu_fill = 2;
  opt.krylov_tol = 1e-10; /* the scene's default */
  sp_solver ilu2 = make_solver_opts(mesh, layout, &opt);
  opt.ilu_fill = 4;
  sp_solver ilu4 = make_solver_opts(mesh, layout, &opt);
  sp_solver serial = make_solver_with(mesh, layout, SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU);
  sp_solver solvers[3] = {ilu2, ilu4, serial};
  const char *names[3] = {"ILU(2)", "ILU(4)", "SuperLU"};
  const int n = 2 * layout->n_pairs;
  double *x[3], *old = calloc(n, sizeof(double));
  for (int s = 0; s < 3; ++s) {
    x[s] = calloc(n, sizeof(double));
    set_three_touching_disks(mesh, layout, x[s]);
  }
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  long ilu2_first_gmres = -1;
  for (int step = 0; step < N_STEPS; ++step) {
    int its[3];
    long gmres[3];
    for (int s = 0; s < 3; ++s) {
      sp_step_report rep;
      for (int i = 0; i < n; ++i) old[i] = x[s][i];
      CHECK(sp_solver_step(solvers[s], &data, x[s], &rep) == 0, "%s, step %d: %s", names[s], step,
            rep.reason);
      its[s] = rep.newton_its;
      gmres[s] = rep.linear_its;
    }
    if (step == 0) ilu2_first_gmres = gmres[0];
    CHECK(gmres[0] >= its[0] && gmres[1] >= its[1] && gmres[2] == 0,
          "step %d: GMRES iterations %ld / %ld / %ld", step, gmres[0], gmres[1], gmres[2]);
    double scale = 0, d2 = 0, d4 = 0;
    for (int i = 0; i < n; ++i) {
      scale = fmax(scale, fabs(x[2][i]));
      d2 = fmax(d2, fabs(x[0][i] - x[2][i]));
      d4 = fmax(d4, fabs(x[1][i] - x[2][i]));
    }
    printf("step %d: Newton iterations %d / %d / %d (ILU(2) / ILU(4) / SuperLU), GMRES iterations "
           "%ld / %ld; states against SuperLU %.2e / %.2e (of %.3g)\n",
           step, its[0], its[1], its[2], gmres[0], gmres[1], d2, d4, scale);
    CHECK(its[0] == its[2] && its[1] == its[2], "step %d: Newton iterations %d, %d against %d",
          step, its[0], its[1], its[2]);
    CHECK(d2 <= 1e-9 * scale && d4 <= 1e-9 * scale, "step %d: states differ by %.3e and %.3e",
          step, d2, d4);
  }

  /* ILU(0), the first step from the same state: if 0 meant "the default"
   * it would repeat ILU(2)'s GMRES iterations exactly */
  opt.ilu_fill = 0;
  sp_solver ilu0 = make_solver_opts(mesh, layout, &opt);
  double *z = malloc(sizeof(double) * n);
  set_three_touching_disks(mesh, layout, z);
  for (int i = 0; i < n; ++i) old[i] = z[i];
  sp_step_report rep0;
  const int failed0 = sp_solver_step(ilu0, &data, z, &rep0);
  printf("ILU(0), first step: %s, %d Newton and %ld GMRES iterations (ILU(2): %ld) %s\n",
         failed0 ? "failed" : "converged", rep0.newton_its, rep0.linear_its, ilu2_first_gmres,
         failed0 ? rep0.reason : "");
  /* failed: only through a failed GMRES solve, which ends the attempt
   * before Newton's own limit */
  CHECK(failed0 ? rep0.newton_its < opt.newton_max_its && rep0.linear_its > 0
                : rep0.linear_its != ilu2_first_gmres,
        "ILU(0): %s with %ld GMRES iterations (ILU(2): %ld)", failed0 ? rep0.reason : "converged",
        rep0.linear_its, ilu2_first_gmres);
  sp_solver_destroy(&ilu0);
  free(z);

  /* an unreachable tolerance: the step fails, the state stays */
  opt.ilu_fill = 2;
  check_unreachable_tolerance(mesh, layout, opt, x[0]);

  /* each bad value refused naming its own key */
  const struct {
    int fill;
    double tol;
    const char *key;
  } bad[] = {{-1, 1e-10, "solver.ilu_fill"},
             {2, 1.5, "solver.krylov_tol"},
             {2, -1e-8, "solver.krylov_tol"},
             {2, 0, "solver.krylov_tol"}};
  for (size_t b = 0; b < sizeof bad / sizeof bad[0]; ++b) {
    opt.ilu_fill = bad[b].fill;
    opt.krylov_tol = bad[b].tol;
    expect_solver_refused(&opt, bad[b].key);
  }
  for (int s = 0; s < 3; ++s) {
    sp_solver_destroy(&solvers[s]);
    free(x[s]);
  }
  free(old);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  TEST_DONE();
}
