/* Newton converges quadratically on a typical step: for successive
 * residual norms r_k, the order estimate log(r_{k+1}/r_k) / log(r_k/r_{k-1})
 * reaches 2 (>= 1.8) before round-off; and the step converges in few
 * iterations. Three touching cells, paper parameters, dt = 1e-4. */
#include "fixtures.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  const int n = 2 * layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *old = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, state);
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  /* A first step to get off the initial state (mu = 0), then the typical one. */
  sp_step_report rep;
  for (int step = 0; step < 2; ++step) {
    for (int i = 0; i < n; ++i) old[i] = state[i];
    CHECK(sp_solver_step(s, &data, state, &rep) == 0, "step %d: %s", step, sp_solver_last_error(s));
  }
  printf("Newton iterations %d, residual norms:", rep.newton_its);
  for (int i = 0; i < rep.n_residuals; ++i) printf(" %.3e", rep.residual_norms[i]);
  printf("\n");
  double best_order = 0;
  for (int k = 1; k + 1 < rep.n_residuals; ++k) {
    const double *r = rep.residual_norms;
    if (r[k + 1] < 1e-13) break; /* round-off floor */
    double order = log(r[k + 1] / r[k]) / log(r[k] / r[k - 1]);
    printf("order estimate at iteration %d: %.3f\n", k + 1, order);
    if (order > best_order) best_order = order;
  }
  CHECK(best_order >= 1.8, "Newton order estimate %.3f < 1.8", best_order);
  CHECK(rep.newton_its <= 6, "%d Newton iterations on a typical step", rep.newton_its);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(state); free(old);
  MPI_Finalize();
  TEST_DONE();
}
