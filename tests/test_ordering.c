/* solver.ordering: SuperLU_DIST ordered by METIS on the (cell, node) pair
 * graph (pairs, the default) or on the unknowns (SuperLU_DIST's own). The
 * order changes only the round-off: three touching cells, paper
 * parameters, 3 steps of dt = 1e-4, the states after every step agree to
 * 1e-10 of the largest value and the Newton iterations are the same; both
 * agree with serial SuperLU to the same. The two orders are not the same
 * (the states differ in the last bits at some step: a fallback of one to
 * the other would show). solver.refine (one step of iterative refinement
 * per solve, off by default) changes only the round-off too: the same
 * Newton iterations, states within 1e-10, and not the same bits. An
 * unknown ordering is refused. */
#include "fixtures.h"

enum { N_STEPS = 3, N_SOLVERS = 4 };

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU_DIST);
  opt.ordering = SP_SOLVER_ORDER_PAIRS;
  sp_solver pairs = make_solver_opts(mesh, layout, &opt);
  opt.ordering = SP_SOLVER_ORDER_UNKNOWNS;
  sp_solver unknowns = make_solver_opts(mesh, layout, &opt);
  opt.ordering = SP_SOLVER_ORDER_PAIRS;
  opt.refine = 1;
  sp_solver refined = make_solver_opts(mesh, layout, &opt);
  sp_solver serial = make_solver_with(mesh, layout, SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU);
  sp_solver solvers[N_SOLVERS] = {pairs, unknowns, serial, refined};
  const char *names[N_SOLVERS] = {"pairs", "unknowns", "serial SuperLU", "pairs, refined"};
  const int n = 2 * layout->n_pairs;
  double *x[N_SOLVERS], *old = calloc(n, sizeof(double));
  for (int s = 0; s < N_SOLVERS; ++s) {
    x[s] = calloc(n, sizeof(double));
    set_three_touching_disks(mesh, layout, x[s]);
  }
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  double any_difference = 0, any_refined = 0;
  for (int step = 0; step < N_STEPS; ++step) {
    int its[N_SOLVERS];
    for (int s = 0; s < N_SOLVERS; ++s) {
      sp_step_report rep;
      for (int i = 0; i < n; ++i) old[i] = x[s][i];
      CHECK(sp_solver_step(solvers[s], &data, x[s], &rep) == 0, "%s, step %d: %s", names[s], step,
            sp_solver_last_error(solvers[s]));
      its[s] = rep.newton_its;
    }
    double scale = 0, d_orders = 0, d_serial = 0, d_refined = 0;
    for (int i = 0; i < n; ++i) {
      scale = fmax(scale, fabs(x[2][i]));
      d_orders = fmax(d_orders, fabs(x[0][i] - x[1][i]));
      d_serial = fmax(d_serial, fmax(fabs(x[0][i] - x[2][i]), fabs(x[1][i] - x[2][i])));
      d_refined = fmax(d_refined, fabs(x[0][i] - x[3][i]));
    }
    printf("step %d: Newton iterations %d / %d / %d / %d (pairs / unknowns / serial / refined); "
           "pairs against unknowns %.2e, against serial %.2e, against refined %.2e (of %.3g)\n",
           step, its[0], its[1], its[2], its[3], d_orders, d_serial, d_refined, scale);
    any_difference = fmax(any_difference, d_orders);
    any_refined = fmax(any_refined, d_refined);
    CHECK(its[0] == its[1] && its[0] == its[3],
          "step %d: %d iterations with pairs, %d with unknowns, %d refined", step, its[0], its[1],
          its[3]);
    CHECK(d_orders <= 1e-10 * scale && d_serial <= 1e-10 * scale && d_refined <= 1e-10 * scale,
          "step %d: states differ by %.3e (orders), %.3e (serial) and %.3e (refined)", step,
          d_orders, d_serial, d_refined);
  }
  CHECK(any_difference > 0, "the two orderings gave the same bits: one of them is not used");
  CHECK(any_refined > 0, "refined and unrefined solves gave the same bits: refine is not used");
  opt.ordering = 7;
  expect_solver_refused(&opt, "solver.ordering");
  for (int s = 0; s < N_SOLVERS; ++s) {
    sp_solver_destroy(&solvers[s]);
    free(x[s]);
  }
  free(old);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  TEST_DONE();
}
