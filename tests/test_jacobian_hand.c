/* The hand-derived element Jacobian (solver.jacobian: hand):
 *  - equals the AD one to 1e-12 relative (and AD equals central differences
 *    to 1e-6; DFad equals SFad) on random states with 1 to 4 overlapping
 *    cells, on a rectangle and on an ellipse with a buffer ring, with a
 *    source and the explicit shape term present; the same with 5 and 6
 *    cells on every element, where AD itself is DFad (SFad is compiled for
 *    1-4 cells);
 *  - the same on a state just after a sharp division cut;
 *  - Newton takes the same iterations with ad and hand on steps of a
 *    3-cell scene (test_newton.c's), to the same states (1e-10);
 *  - `softpack check-jacobian` on tests/scenes/two_overlapping.yaml and on
 *    tests/scenes/five_overlapping.yaml (5 cells on the central elements
 *    of the run's local supports: DFad) exits 0, and the figures it prints, at the initial state and after a
 *    step, are hand = ad to 1e-12 and ad = fd to 1e-6. */
#include <string.h>

#include "command.h"
#include "fixtures.h"

/* hand vs ad, ad vs fd and DFad vs ad at one state; checks and prints. */
static void check_all(sp_solver s, const sp_step_data *data, const double *state,
                      const char *what) {
  double hand_ad = jacobian_difference(s, data, state, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_AD);
  double ad_fd = jacobian_difference(s, data, state, SP_SOLVER_JAC_AD, SP_SOLVER_JAC_FD);
  double dfad_ad = jacobian_difference(s, data, state, SP_SOLVER_JAC_AD_DFAD, SP_SOLVER_JAC_AD);
  double hand_fd = -1;
  if (sp_solver_check_jacobian(s, data, state, SP_SOLVER_JAC_HAND, &hand_fd) != 0)
    fprintf(stderr, "check_jacobian: %s\n", sp_solver_last_error(s));
  printf("%-34s hand vs ad %.3g, ad vs fd %.3g, hand vs fd %.3g, dfad vs ad %.3g\n", what,
         hand_ad, ad_fd, hand_fd, dfad_ad);
  CHECK(hand_ad >= 0 && hand_ad < 1e-12, "%s: hand vs ad %g", what, hand_ad);
  CHECK(ad_fd >= 0 && ad_fd < 1e-6, "%s: ad vs fd %g", what, ad_fd);
  CHECK(hand_fd >= 0 && hand_fd < 1e-6, "%s: hand vs fd %g", what, hand_fd);
  CHECK(dfad_ad >= 0 && dfad_ad < 1e-12, "%s: dfad vs ad %g", what, dfad_ad);
}

static void random_state(const sp_mesh *mesh, int n_cells, unsigned long long seed,
                         const char *mesh_name) {
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, n_cells, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  double *state, *old, *source;
  random_step_arrays(layout, seed, &state, &old, &source);
  sp_shape_coef shape[8];
  for (int k = 0; k < n_cells; ++k) {
    double th = 0.3 + k;
    shape[k] = (sp_shape_coef){.xc = 0.1 * k, .yc = -0.05 * k,
                               .v = {{cos(th), sin(th)}, {-sin(th), cos(th)}},
                               .coef = {1e3 * (k + 1), -2e3}};
  }
  sp_step_data data = {.dt = 1e-3, .model = paper_model(), .state_old = old,
                       .source = source, .shape = shape};
  char what[128];
  snprintf(what, sizeof what, "random, %d cell%s, %s:", n_cells, n_cells > 1 ? "s" : "",
           mesh_name);
  check_all(s, &data, state, what);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  free(state); free(old); free(source);
}

/* One tanh disk cut sharply at x = xc: c for x > xc moves to a second cell. */
static void division_cut(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 0.8, 40, 32, &mesh));
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  const int n = 2 * layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *old = calloc(n, sizeof(double));
  const double xc = 0.51, yc = 0.4, d = sqrt(1e-3 / 8);
  set_disk(mesh, layout, state, 0, xc, yc, 0.25, d);
  unsigned long long rng = 7;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    int p0 = sp_layout_pair(layout, 0, i), p1 = sp_layout_pair(layout, 1, i);
    state[2 * p0 + 1] = 0.1 * sp_random_symmetric(&rng);
    if (mesh->xy[2 * i] > xc) {
      state[2 * p1] = state[2 * p0];
      state[2 * p0] = 0.0;
    }
    state[2 * p1 + 1] = 0.1 * sp_random_symmetric(&rng);
  }
  memcpy(old, state, n * sizeof(double));
  sp_step_data data = {.dt = 2e-4, .model = paper_model(), .state_old = old,
                       .source = NULL, .shape = NULL};
  check_all(s, &data, state, "division cut, 2 cells, rectangle:");
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(state); free(old);
}

/* Steps of a 3-cell scene with ad and with hand from identical inputs. */
static void newton_same_iterations(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  sp_solver s_ad = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  sp_solver s_hand = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  const int n = 2 * layout->n_pairs;
  double *u_ad = calloc(n, sizeof(double)), *u_hand = calloc(n, sizeof(double));
  double *old_ad = calloc(n, sizeof(double)), *old_hand = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, u_ad);
  memcpy(u_hand, u_ad, n * sizeof(double));
  double t = 0.0, dt = 1e-4;
  int total_its = 0;
  for (int step = 1; step <= 3; ++step) {
    memcpy(old_ad, u_ad, n * sizeof(double));
    memcpy(old_hand, u_hand, n * sizeof(double));
    sp_step_data d_ad = {.dt = dt, .model = paper_model(), .state_old = old_ad};
    sp_step_data d_hand = {.dt = dt, .model = paper_model(), .state_old = old_hand};
    sp_step_report r_ad, r_hand;
    int rc_ad = sp_solver_step(s_ad, &d_ad, u_ad, &r_ad);
    int rc_hand = sp_solver_step(s_hand, &d_hand, u_hand, &r_hand);
    double diff = 0.0;
    for (int i = 0; i < n; ++i) diff = fmax(diff, fabs(u_ad[i] - u_hand[i]));
    t += dt;
    printf("newton step %d (t = %.3g): ad %d its (rc %d), hand %d its (rc %d), "
           "max |u_ad - u_hand| %.3g\n", step, t, r_ad.newton_its, rc_ad, r_hand.newton_its,
           rc_hand, diff);
    CHECK(rc_ad == 0 && rc_hand == 0, "step %d: rc ad %d (%s), hand %d (%s)", step, rc_ad,
          r_ad.reason, rc_hand, r_hand.reason);
    CHECK(r_ad.newton_its == r_hand.newton_its, "step %d: ad %d its, hand %d its", step,
          r_ad.newton_its, r_hand.newton_its);
    CHECK(diff <= 1e-10, "step %d: states differ by %g", step, diff);
    total_its += r_hand.newton_its;
  }
  CHECK(total_its >= 3, "only %d Newton iterations in 3 steps", total_its);
  sp_solver_destroy(&s_ad);
  sp_solver_destroy(&s_hand);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(u_ad); free(u_hand); free(old_ad); free(old_hand);
}

/* `softpack check-jacobian SCENE --steps 1 EXTRA`: exit status 0, and the
 * "all terms" row of both tables (the initial state, after one step) read
 * back: hand = ad to 1e-12, ad = fd to 1e-6. */
static void command_line(const char *scene, const char *extra) {
  char args[2048], out[16384];
  snprintf(args, sizeof args, "check-jacobian %s/tests/scenes/%s --steps 1 %s", SP_SOURCE_DIR,
           scene, extra);
  const int code = run_softpack(args, out, sizeof out);
  printf("--- softpack check-jacobian %s (exit status %d) ---\n%s---\n", scene, code, out);
  CHECK(code == 0, "%s: check-jacobian exit status %d", scene, code);
  int tables = 0;
  for (const char *row = strstr(out, "all terms"); row; row = strstr(row + 1, "all terms")) {
    double hand_ad = -1, ad_fd = -1, hand_fd = -1;
    CHECK(sscanf(row, "all terms %lf %lf %lf", &hand_ad, &ad_fd, &hand_fd) == 3,
          "%s, table %d: cannot read the all-terms row", scene, tables + 1);
    CHECK(hand_ad >= 0 && hand_ad <= 1e-12, "%s, table %d: hand vs ad %g", scene, tables + 1,
          hand_ad);
    CHECK(ad_fd >= 0 && ad_fd <= 1e-6, "%s, table %d: ad vs fd %g", scene, tables + 1, ad_fd);
    ++tables;
  }
  CHECK(tables == 2, "%s: %d tables (want the initial state and after one step)", scene, tables);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *rect, *ellipse;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 0.8, 6, 5, &rect));
  CHECK_OK(sp_mesh_ellipse(2, 0.5, 0.25, 2, 0.2, &ellipse)); /* with a buffer ring */
  /* 1 to 4 cells on every element: AD is SFad; 5 and 6: AD is DFad */
  for (int n_cells = 1; n_cells <= 6; ++n_cells) {
    random_state(rect, n_cells, 17 + n_cells, "rectangle");
    random_state(ellipse, n_cells, 91 + n_cells, "ellipse+buffer");
  }
  sp_mesh_destroy(&rect);
  sp_mesh_destroy(&ellipse);
  division_cut();
  newton_same_iterations();
  command_line("two_overlapping.yaml", "--set mesh.nx=16 --set mesh.ny=16");
  command_line("five_overlapping.yaml", ""); /* 5 cells on central elements: DFad */
  MPI_Finalize();
  TEST_DONE();
}
