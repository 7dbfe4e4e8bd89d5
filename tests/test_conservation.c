/* With s = 0 every cell's mass is conserved to 1e-12 relative per step:
 * three overlapping cells on a rectangle, paper parameters, 10 steps. */
#include "fixtures.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 48, 48, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 3, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  const int n = 2 * layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *old = calloc(n, sizeof(double));
  const double d = sqrt(1e-3 / 8);
  set_disk(mesh, layout, state, 0, 0.36, 0.45, 0.16, d);
  set_disk(mesh, layout, state, 1, 0.64, 0.50, 0.14, d);
  set_disk(mesh, layout, state, 2, 0.50, 0.72, 0.12, d);
  sp_step_data data = {.dt = 1e-6, .model = paper_model(), .state_old = old};
  sp_cell_obs before[3], after[3];
  double worst = 0;
  for (int step = 0; step < 10; ++step) {
    for (int i = 0; i < n; ++i) old[i] = state[i];
    CHECK_OK(sp_cells_observe(mesh, layout, state, 0, before));
    sp_step_report rep;
    int rc = sp_solver_step(s, &data, state, &rep);
    CHECK(rc == 0, "step %d: %s", step, sp_solver_last_error(s));
    CHECK_OK(sp_cells_observe(mesh, layout, state, 0, after));
    for (int k = 0; k < 3; ++k) {
      double rel = fabs(after[k].mass - before[k].mass) / before[k].mass;
      if (rel > worst) worst = rel;
      CHECK(rel <= 1e-12, "step %d cell %d: mass %.17g -> %.17g (relative %.3g)", step, k,
            before[k].mass, after[k].mass, rel);
    }
  }
  printf("largest relative mass change per step over 3 cells x 10 steps: %.3g\n", worst);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(state); free(old);
  MPI_Finalize();
  TEST_DONE();
}
