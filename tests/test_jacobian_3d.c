/* The element Jacobians on hexahedra (3D), as tight as the 2D
 * tests (test_jacobian.c, test_jacobian_hand.c) assert them:
 *  - on random states with 1, 2 and 3 cells (SFad 16 and 32 unknowns, and
 *    DFad at 48), on a box of hexahedra whose nodes are moved at random
 *    (no two faces parallel) with a buffer layer, with a source and the
 *    shape term on the three moments present (src/model/shape.h; its implicit
 *    variant's Jacobian: tests/test_shape_3d.c):
 *    hand = AD to 1e-12, AD = central differences to 1e-6, hand = FD to
 *    1e-6, DFad = AD to 1e-12;
 *  - a backward-Euler step of two touching spheres solved with the AD and
 *    with the hand Jacobian takes the same Newton iterations to the same
 *    state (1e-10);
 *  - `softpack check-jacobian` on a 3D scene with the shape term on the
 *    three moments (tests/scenes/shape_3d.yaml, implicit): exit 0, hand
 *    = AD to 1e-12 (its largest relative difference). */
#include "command.h"
#include "fixtures.h"

/* A 4 x 3 x 3 box with every node moved by up to 0.15 of an element, and
 * its top layer of elements a buffer. */
static sp_mesh *distorted_box(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.4, 0.3, 0.3, 4, 3, 3, &mesh));
  unsigned long long rng = 5;
  for (int i = 0; i < 3 * mesh->n_nodes; ++i) mesh->xy[i] += 0.015 * sp_random_symmetric(&rng);
  for (int e = 0; e < mesh->n_elems; ++e)
    if (e >= 4 * 3 * 2) mesh->region[e] = SP_REGION_BUFFER;
  return mesh;
}

static void random_state(const sp_mesh *mesh, int n_cells, unsigned long long seed) {
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, n_cells, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  double *state, *old, *source;
  random_step_arrays(layout, seed, &state, &old, &source);
  sp_shape_coef shape[3];
  for (int k = 0; k < n_cells; ++k) {
    shape[k] = (sp_shape_coef){.xc = 0.1 + 0.1 * k, .yc = 0.15 - 0.05 * k, .zc = 0.1 + 0.02 * k,
                               .coef = {1e3 * (k + 1), -2e3, 1.5e3}};
    rotated_axes(0.3 + k, 0.5, -0.2 * k, shape[k].v);
  }
  sp_step_data data = {.dt = 1e-3, .model = paper_model(), .state_old = old, .source = source,
                       .shape = shape};
  const double hand_ad = jacobian_difference(s, &data, state, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_AD);
  const double ad_fd = jacobian_difference(s, &data, state, SP_SOLVER_JAC_AD, SP_SOLVER_JAC_FD);
  const double hand_fd = jacobian_difference(s, &data, state, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD);
  const double dfad_ad = jacobian_difference(s, &data, state, SP_SOLVER_JAC_AD_DFAD, SP_SOLVER_JAC_AD);
  printf("hexahedra, random, %d cell%s: hand vs ad %.3g, ad vs fd %.3g, hand vs fd %.3g, "
         "dfad vs ad %.3g\n",
         n_cells, n_cells > 1 ? "s" : "", hand_ad, ad_fd, hand_fd, dfad_ad);
  CHECK(hand_ad >= 0 && hand_ad < 1e-12, "%d cells: hand vs ad %g", n_cells, hand_ad);
  CHECK(ad_fd >= 0 && ad_fd < 1e-6, "%d cells: ad vs fd %g", n_cells, ad_fd);
  CHECK(hand_fd >= 0 && hand_fd < 1e-6, "%d cells: hand vs fd %g", n_cells, hand_fd);
  CHECK(dfad_ad >= 0 && dfad_ad < 1e-12, "%d cells: dfad vs ad %g", n_cells, dfad_ad);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  free(state); free(old); free(source);
}

/* c_k = tanh sphere of radius R at (x, y, z) with width d; mu_k = 0. */
static void set_sphere(const sp_mesh *mesh, const sp_layout *layout, double *state, int k,
                       const double centre[3], double R, double d) {
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, k, i);
    if (p < 0) continue;
    const double *x = mesh->xy + 3 * i;
    const double r = sqrt((x[0] - centre[0]) * (x[0] - centre[0]) +
                          (x[1] - centre[1]) * (x[1] - centre[1]) +
                          (x[2] - centre[2]) * (x[2] - centre[2]));
    state[2 * p] = 1.0 / (1.0 + exp((r - R) / d));
    state[2 * p + 1] = 0.0;
  }
}

/* One step from two touching spheres with each Jacobian: same iterations,
 * same state. */
static void newton_step(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.4, 0.4, 10, 8, 8, &mesh));
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  const int n = 2 * layout->n_pairs, kinds[2] = {SP_SOLVER_JAC_AD, SP_SOLVER_JAC_HAND};
  double *start = calloc(n, sizeof(double)), *result[2];
  const double d = sqrt(4e-3 / 8), a[3] = {0.16, 0.2, 0.2}, b[3] = {0.34, 0.21, 0.19};
  set_sphere(mesh, layout, start, 0, a, 0.1, d);
  set_sphere(mesh, layout, start, 1, b, 0.08, d);
  sp_model_params model = paper_model();
  model.kappa = 4e-3;
  int its[2];
  for (int j = 0; j < 2; ++j) {
    sp_solver s = make_solver_with(mesh, layout, kinds[j], SP_LINEAR_MUMPS);
    result[j] = malloc(n * sizeof(double));
    memcpy(result[j], start, n * sizeof(double));
    sp_step_data data = {.dt = 2e-4, .model = model, .state_old = start};
    sp_step_report rep;
    CHECK(sp_solver_step(s, &data, result[j], &rep) == 0, "%s step: %s", j ? "hand" : "ad",
          sp_solver_last_error(s));
    its[j] = rep.newton_its;
    sp_solver_destroy(&s);
  }
  double diff = 0;
  for (int i = 0; i < n; ++i) diff = fmax(diff, fabs(result[0][i] - result[1][i]));
  printf("two spheres, one step: Newton iterations ad %d, hand %d; states differ by %.3g\n",
         its[0], its[1], diff);
  CHECK(its[0] == its[1], "Newton iterations: ad %d, hand %d", its[0], its[1]);
  CHECK(diff < 1e-10, "the states differ by %g", diff);
  free(start); free(result[0]); free(result[1]);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/* The program's check-jacobian on a 3D scene with the shape term. */
static void cli_check_jacobian(void) {
  static char out[16384];
  const int status =
      run_softpack("check-jacobian " SP_SOURCE_DIR "/tests/scenes/shape_3d.yaml", out, sizeof out);
  const char *line = strstr(out, "hand vs ad: largest relative difference ");
  double hand_ad = INFINITY;
  if (line) sscanf(line + strlen("hand vs ad: largest relative difference "), "%lf", &hand_ad);
  printf("check-jacobian shape_3d.yaml: exit %d, hand vs ad %.3g\n", status, hand_ad);
  CHECK(status == 0, "exit %d: %s", status, out);
  CHECK(hand_ad <= 1e-12, "hand vs AD %.3g: %s", hand_ad, out);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh = distorted_box();
  for (int n_cells = 1; n_cells <= 3; ++n_cells) random_state(mesh, n_cells, 23 + n_cells);
  sp_mesh_destroy(&mesh);
  newton_step();
  cli_check_jacobian();
  MPI_Finalize();
  TEST_DONE();
}
