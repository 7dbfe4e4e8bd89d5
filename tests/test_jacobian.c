/* The AD element Jacobian equals a central finite-difference Jacobian to
 * 1e-6 relative on random states with 1, 2 and 3 cells, with the repulsion,
 * the buffer ring, a source and the explicit shape term present. */
#include "fixtures.h"

static double check_random_state(const sp_mesh *mesh, int n_cells, unsigned long long seed) {
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, n_cells, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  double *state, *old, *source;
  random_step_arrays(layout, seed, &state, &old, &source);
  sp_shape_coef shape[3];
  for (int k = 0; k < n_cells; ++k) {
    double th = 0.3 + k;
    shape[k] = (sp_shape_coef){.xc = 0.1 * k, .yc = -0.05 * k,
                               .v = {{cos(th), sin(th)}, {-sin(th), cos(th)}},
                               .coef = {1e3 * (k + 1), -2e3}};
  }
  sp_step_data data = {.dt = 1e-3, .model = paper_model(), .state_old = old,
                       .source = source, .shape = shape};
  double err = -1;
  if (sp_solver_check_jacobian(s, &data, state, SP_SOLVER_JAC_AD, &err) != 0)
    fprintf(stderr, "check_jacobian: %s\n", sp_solver_last_error(s));
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  free(state); free(old); free(source);
  return err;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *rect, *ellipse;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 0.8, 6, 5, &rect));
  CHECK_OK(sp_mesh_ellipse(2, 0.5, 0.25, 2, 0.2, &ellipse)); /* with a buffer ring */
  for (int n_cells = 1; n_cells <= 3; ++n_cells) {
    double e_rect = check_random_state(rect, n_cells, 17 + n_cells);
    double e_ell = check_random_state(ellipse, n_cells, 91 + n_cells);
    printf("cells %d: max relative |J_ad - J_fd| rectangle %.3g, ellipse+buffer %.3g\n",
           n_cells, e_rect, e_ell);
    CHECK(e_rect >= 0 && e_rect < 1e-6, "rectangle, %d cells: %g", n_cells, e_rect);
    CHECK(e_ell >= 0 && e_ell < 1e-6, "ellipse, %d cells: %g", n_cells, e_ell);
  }
  sp_mesh_destroy(&rect);
  sp_mesh_destroy(&ellipse);
  MPI_Finalize();
  TEST_DONE();
}
