/* Adhesion between chosen pairs of cells (docs/model.md, "Adhesion"):
 *  - the element Jacobians with an adhesion table (a different sigma for
 *    every pair) on quadrilaterals (2, 3 and 5 cells: SFad and DFad) and
 *    hexahedra (2 and 3 cells): hand = AD to 1e-12, AD = central
 *    differences to 1e-6, hand = FD to 1e-6;
 *  - the residual is the derivative of the reported energy: with mu = 0
 *    the mu rows are -dPi/dc_p, Pi with its adhesion part (central
 *    differences of sp_solver_energy, 1e-7 of the largest row), and the
 *    adhesion part of two touching disks is negative (it rewards contact);
 *  - the energy law (tests/scenes/adhesion_pair.yaml: backward Euler, no
 *    source, division or shape term): the energy with its adhesion part
 *    never rises, step by step; each cell's mass is conserved to 1e-12;
 *  - adhesion changes the dynamics: the same two cells' contact A_12
 *    (contacts.csv) grows more, and their centres come closer, than
 *    without it;
 *  - sigma from the lineage: with sisters' adhesion only, the two
 *    daughters of a division adhere (energy.csv's adhesion part non-zero
 *    at 2 cells); with non-sisters' only, they do not (exactly 0 at 2
 *    cells) but cousins do (non-zero at 4 cells);
 *  - named pairs (the scene's adhesion sequence): a pair's own sigma
 *    replaces the non-sisters' (the same run, bit for bit, as with that
 *    sigma for non-sisters), and a pair's 0 switches it off (adhesion
 *    exactly 0); unknown names are refused naming the key;
 *  - bad input, exit 2 naming the key: a coefficient >= kappa (the
 *    scene's check), and partners on an element summing to kappa or more
 *    (the run's, on its layout);
 *  - `softpack check-jacobian` on 2D and 3D scenes with adhesion: exit 0,
 *    hand = AD to 1e-12. */
#include "command.h"
#include "fixtures.h"
#include "output_read.h"
#include "public/error.h"
#include "run/stepper.h"
#include "scene/scene.h"

/* sigma_kl = 1e-4 (1 + k + 2 l) for k < l, symmetric, 0 on the diagonal. */
static void pair_table(int n, double *table) {
  for (int k = 0; k < n; ++k)
    for (int l = 0; l < n; ++l) {
      const int a = k < l ? k : l, b = k < l ? l : k;
      table[n * k + l] = k == l ? 0.0 : 1e-4 * (1 + a + 2 * b);
    }
}

static void jacobians(const sp_mesh *mesh, int n_cells, unsigned long long seed, const char *what) {
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, n_cells, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  double *state, *old, *source, table[25];
  random_step_arrays(layout, seed, &state, &old, &source);
  pair_table(n_cells, table);
  sp_step_data data = {.dt = 1e-3, .model = paper_model(), .state_old = old, .source = source};
  data.model.adhesion = table;
  data.model.adhesion_cells = n_cells;
  const double hand_ad = jacobian_difference(s, &data, state, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_AD);
  const double ad_fd = jacobian_difference(s, &data, state, SP_SOLVER_JAC_AD, SP_SOLVER_JAC_FD);
  const double hand_fd = jacobian_difference(s, &data, state, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD);
  const double dfad_ad =
      jacobian_difference(s, &data, state, SP_SOLVER_JAC_AD_DFAD, SP_SOLVER_JAC_AD);
  /* the adhesion blocks are there: the hand Jacobian without them is not
   * the AD one with them */
  sp_step_data without = data;
  without.model.adhesion = NULL;
  double R_with = 0, R_without = 0;
  {
    const int n = 2 * layout->n_pairs;
    double *r1 = malloc(n * sizeof(double)), *r2 = malloc(n * sizeof(double));
    CHECK_OK(sp_solver_residual(s, &data, state, r1));
    CHECK_OK(sp_solver_residual(s, &without, state, r2));
    for (int i = 0; i < n; ++i) {
      R_with = fmax(R_with, fabs(r1[i] - r2[i]));
      R_without = fmax(R_without, fabs(r2[i]));
    }
    free(r1);
    free(r2);
  }
  printf("%s, %d cells: hand vs ad %.3g, ad vs fd %.3g, hand vs fd %.3g, dfad vs ad %.3g; "
         "adhesion moves the residual by %.3g of its size\n",
         what, n_cells, hand_ad, ad_fd, hand_fd, dfad_ad, R_with / R_without);
  CHECK(hand_ad >= 0 && hand_ad < 1e-12, "%s, %d cells: hand vs ad %g", what, n_cells, hand_ad);
  CHECK(ad_fd >= 0 && ad_fd < 1e-6, "%s, %d cells: ad vs fd %g", what, n_cells, ad_fd);
  CHECK(hand_fd >= 0 && hand_fd < 1e-6, "%s, %d cells: hand vs fd %g", what, n_cells, hand_fd);
  CHECK(dfad_ad >= 0 && dfad_ad < 1e-12, "%s, %d cells: dfad vs ad %g", what, n_cells, dfad_ad);
  CHECK(R_with > 1e-6 * R_without, "%s: the adhesion table changed nothing", what);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  free(state); free(old); free(source);
}

/* The residual's mu rows at mu = 0 against -dPi/dc of the reported energy,
 * two touching disks with adhesion; the adhesion part's sign. */
static void residual_is_energy_derivative(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 0.6, 0.4, 36, 24, &mesh));
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_HAND);
  const int n = 2 * layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *R = malloc(n * sizeof(double));
  const double d = sqrt(1e-3 / 8);
  set_disk(mesh, layout, state, 0, 0.2, 0.2, 0.1, d);
  set_disk(mesh, layout, state, 1, 0.4, 0.2, 0.1, d);
  double table[4];
  pair_table(2, table);
  sp_step_data data = {.dt = 1e-3, .model = paper_model(), .state_old = state};
  data.model.adhesion = table;
  data.model.adhesion_cells = 2;
  CHECK_OK(sp_solver_residual(s, &data, state, R));
  sp_energy_parts parts;
  CHECK_OK(sp_solver_energy(s, &data.model, state, &parts));
  double scale = 0, worst = 0;
  for (int p = 0; p < layout->n_pairs; ++p) scale = fmax(scale, fabs(R[2 * p + 1]));
  /* every 7th pair: nodes across both interfaces and the film */
  for (int p = 0; p < layout->n_pairs; p += 7) {
    const double c = state[2 * p], h = 1e-5;
    state[2 * p] = c + h;
    const double e_plus = energy_total(s, &data.model, state);
    state[2 * p] = c - h;
    const double e_minus = energy_total(s, &data.model, state);
    state[2 * p] = c;
    worst = fmax(worst, fabs(R[2 * p + 1] + (e_plus - e_minus) / (2 * h)));
  }
  CHECK_OK(sp_solver_energy(s, &data.model, state, &parts));
  printf("two touching disks: mu rows vs -dPi/dc: %.3g of the largest row; adhesion energy "
         "%.6g (gradient %.6g)\n", worst / scale, parts.adhesion, parts.gradient);
  CHECK(worst < 1e-7 * scale, "the residual is not the energy's derivative: %g of %g", worst,
        scale);
  CHECK(parts.adhesion < 0, "adhesion energy of touching cells %g, expected < 0", parts.adhesion);
  free(state); free(R);
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/* A run of @p scene_path with @p n_set overrides into @p out; its status. */
static int run_scene(const char *scene_path, int n_set, const char **set, const char *out) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load(scene_path, n_set, set, &scene));
  sp_run_summary sum;
  const int rc = sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum);
  sp_scene_destroy(&scene);
  return rc;
}

/* The last contacts.csv row of the pair (1, 2): its contact (0: none). */
static double last_contact(const char *dir, int *step) {
  char path[512];
  snprintf(path, sizeof path, "%s/contacts.csv", dir);
  csv_table t;
  CHECK(csv_read(path, &t) == 0, "%s unreadable", path);
  double contact = 0;
  *step = -1;
  for (int i = 0; i < t.n_rows; ++i)
    if (at(&t, i, "cell") == 1 && at(&t, i, "other") == 2) {
      contact = at(&t, i, "contact");
      *step = (int)at(&t, i, "step");
    }
  csv_free(&t);
  return contact;
}

/* The distance of the two cells' centres at the last row of cells.csv. */
static double last_distance(const char *dir) {
  char path[512];
  snprintf(path, sizeof path, "%s/cells.csv", dir);
  csv_table t;
  CHECK(csv_read(path, &t) == 0, "%s unreadable", path);
  const int last = t.n_rows - 1; /* cell 2 of the last step; cell 1 above */
  const double dist = hypot(at(&t, last, "xc") - at(&t, last - 1, "xc"),
                            at(&t, last, "yc") - at(&t, last - 1, "yc"));
  csv_free(&t);
  return dist;
}

static void energy_law_and_contact(void) {
  const char *scene = SP_SOURCE_DIR "/tests/scenes/adhesion_pair.yaml";
  CHECK_OK(run_scene(scene, 0, NULL, "test_adhesion_out"));
  const energy_trend tr = energy_trend_read("test_adhesion_out/energy.csv");
  csv_table e, c;
  CHECK(csv_read("test_adhesion_out/energy.csv", &e) == 0, "energy.csv unreadable");
  const double adhesion_first = at(&e, 0, "adhesion"), adhesion_last = at(&e, e.n_rows - 1, "adhesion");
  /* the total counts the adhesion part */
  double worst_sum = 0;
  for (int i = 0; i < e.n_rows; ++i) {
    const double parts = at(&e, i, "bulk") + at(&e, i, "gradient") + at(&e, i, "repulsion") +
                         at(&e, i, "buffer") + at(&e, i, "shape") + at(&e, i, "adhesion");
    worst_sum = fmax(worst_sum, fabs(parts - at(&e, i, "energy")) / fabs(at(&e, i, "energy")));
  }
  csv_free(&e);
  /* each cell's mass, every step, against its first */
  CHECK(csv_read("test_adhesion_out/cells.csv", &c) == 0, "cells.csv unreadable");
  double m0[2] = {at(&c, 0, "mass"), at(&c, 1, "mass")}, drift = 0;
  for (int i = 0; i < c.n_rows; ++i) {
    const int k = (int)at(&c, i, "cell") - 1;
    drift = fmax(drift, fabs(at(&c, i, "mass") - m0[k]) / m0[k]);
  }
  csv_free(&c);
  printf("adhesion_pair: %d rows, energy %.10g -> %.10g, %d rises (largest %.3g); adhesion part "
         "%.6g -> %.6g; parts vs total %.3g; mass drift %.3g\n",
         tr.rows, tr.first, tr.last, tr.rises, tr.worst_rise, adhesion_first, adhesion_last,
         worst_sum, drift);
  CHECK(tr.rows == 41, "%d energy rows", tr.rows);
  CHECK(tr.rises == 0, "the energy rose %d times (largest rise %.3g)", tr.rises, tr.worst_rise);
  CHECK(tr.last < tr.first, "the energy did not decrease: %g -> %g", tr.first, tr.last);
  CHECK(worst_sum < 1e-14, "energy is not the sum of its parts: %g", worst_sum);
  CHECK(adhesion_first < 0 && adhesion_last < adhesion_first,
        "the adhesion part should be negative and fall as the cells draw together: %g -> %g",
        adhesion_first, adhesion_last);
  CHECK(drift < 1e-12, "a cell's mass moved by %g relative", drift);

  /* the same run without adhesion: less contact, centres further apart */
  const char *off[] = {"model.adhesion_non_sisters=0"};
  CHECK_OK(run_scene(scene, 1, off, "test_adhesion_off"));
  int step_on, step_off;
  const double contact_on = last_contact("test_adhesion_out", &step_on);
  const double contact_off = last_contact("test_adhesion_off", &step_off);
  const double dist_on = last_distance("test_adhesion_out"),
               dist_off = last_distance("test_adhesion_off");
  printf("after 40 steps: contact A_12 %.6g with adhesion, %.6g without (steps %d, %d); "
         "centres %.6g apart with, %.6g without\n",
         contact_on, contact_off, step_on, step_off, dist_on, dist_off);
  CHECK(step_on == 40, "no contact row of the pair at the last step with adhesion");
  CHECK(contact_on > contact_off, "adhesion did not add contact: %g against %g", contact_on,
        contact_off);
  CHECK(dist_on < dist_off, "adhesion did not draw the cells together: %g against %g", dist_on,
        dist_off);
}

/* The largest |adhesion| of energy.csv's rows with @p n_cells cells (-1: no
 * such row). */
static double adhesion_at(const char *dir, int n_cells) {
  char path[512];
  snprintf(path, sizeof path, "%s/energy.csv", dir);
  csv_table t;
  CHECK(csv_read(path, &t) == 0, "%s unreadable", path);
  double worst = -1;
  for (int i = 0; i < t.n_rows; ++i)
    if ((int)at(&t, i, "n_cells") == n_cells) worst = fmax(worst, fabs(at(&t, i, "adhesion")));
  csv_free(&t);
  return worst;
}

static void sisters_from_lineage(void) {
  const char *scene = SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml";
  const char *sisters[] = {"model.adhesion_sisters=3e-4", "output.every=1000",
                           "output.pictures=false"};
  const char *others[] = {"model.adhesion_non_sisters=3e-4", "output.every=1000",
                          "output.pictures=false"};
  CHECK_OK(run_scene(scene, 3, sisters, "test_adhesion_sisters"));
  CHECK_OK(run_scene(scene, 3, others, "test_adhesion_others"));
  const double s2 = adhesion_at("test_adhesion_sisters", 2),
               s4 = adhesion_at("test_adhesion_sisters", 4),
               o2 = adhesion_at("test_adhesion_others", 2),
               o4 = adhesion_at("test_adhesion_others", 4);
  printf("divide_1_2_4: |adhesion| with sisters' sigma: %.3g at 2 cells, %.3g at 4; with "
         "non-sisters' sigma: %.3g at 2 cells, %.3g at 4\n", s2, s4, o2, o4);
  CHECK(s2 > 0 && s4 > 0, "sisters do not adhere: %g, %g", s2, s4);
  CHECK(o2 == 0, "non-sisters' sigma acted between sisters: %g", o2);
  CHECK(o4 > 0, "cousins do not adhere: %g", o4);
}

/* adhesion_pair.yaml with named cells and @p pairs, @p steps steps. */
static const char named_scene[] =
    "mesh: {type: rectangle, x0: 0, y0: 0, x1: 0.6, y1: 0.4, nx: 72, ny: 48}\n"
    "model: {alpha: 4, kappa: 1.0e-3, lambda: 100, mobility: 1, adhesion_non_sisters: %s}\n"
    "time: {control: fixed, scheme: be, dt: 2.0e-4, t_end: 1.0, max_steps: 6}\n"
    "noise: {background: 0.0, amplitude: 0.0}\n"
    "cells:\n"
    "  - {x: 0.185, y: 0.2, radius: 0.1, name: A}\n"
    "  - {x: 0.415, y: 0.2, radius: 0.1, name: B}\n"
    "adhesion:\n"
    "  - {cell: B, other: %s, sigma: %s}\n"
    "output: {every: 1000, pictures: false}\n"
    "solver: {linear: superlu, predictor: none, jacobian_reuse: 0}\n";

static int run_named(const char *non_sisters, const char *other, const char *sigma,
                     const char *out) {
  char text[2048];
  snprintf(text, sizeof text, named_scene, non_sisters, other, sigma);
  sp_scene *scene;
  const int rc = sp_scene_load_text("named.yaml", text, strlen(text), 0, NULL, &scene);
  if (rc != SP_OK) return rc;
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  return SP_OK;
}

static void named_pairs(void) {
  const char *six[] = {"time.max_steps=6"};
  CHECK_OK(run_scene(SP_SOURCE_DIR "/tests/scenes/adhesion_pair.yaml", 1, six,
                     "test_adhesion_six"));
  CHECK_OK(run_named("0", "A", "5.0e-4", "test_adhesion_named"));
  CHECK_OK(run_named("5.0e-4", "A", "0", "test_adhesion_named_off"));
  csv_table ref, named, off;
  CHECK(csv_read("test_adhesion_six/energy.csv", &ref) == 0, "energy.csv unreadable");
  CHECK(csv_read("test_adhesion_named/energy.csv", &named) == 0, "energy.csv unreadable");
  CHECK(csv_read("test_adhesion_named_off/energy.csv", &off) == 0, "energy.csv unreadable");
  CHECK(ref.n_rows == 7 && named.n_rows == 7 && off.n_rows == 7, "rows %d, %d, %d", ref.n_rows,
        named.n_rows, off.n_rows);
  int same = 1, zero = 1;
  for (int i = 0; i < 7 && i < named.n_rows && i < off.n_rows && i < ref.n_rows; ++i) {
    same &= at(&ref, i, "energy") == at(&named, i, "energy") &&
            at(&ref, i, "adhesion") == at(&named, i, "adhesion");
    zero &= at(&off, i, "adhesion") == 0.0;
  }
  printf("named pair B, A: sigma 5e-4 %s the non-sisters' run (adhesion %.6g at step 6); "
         "sigma 0 over non-sisters' 5e-4: adhesion %s\n", same ? "equals" : "differs from",
         at(&named, 6, "adhesion"), zero ? "0 at every step" : "not 0");
  CHECK(same, "a named pair's sigma is not the non-sisters' run");
  CHECK(zero, "a named pair's 0 did not switch adhesion off");
  csv_free(&ref);
  csv_free(&named);
  csv_free(&off);
  const int rc = run_named("0", "C", "5.0e-4", "test_adhesion_named_bad");
  printf("unknown name: %s\n", sp_error_message());
  CHECK(rc == SP_ERR_INPUT && strstr(sp_error_message(), "adhesion[0].other"),
        "an unknown name: status %d, %s", rc, sp_error_message());
}

static void bad_input(void) {
  static char out[16384];
  int status = run_softpack("run " SP_SOURCE_DIR "/tests/scenes/adhesion_pair.yaml --out "
                            "test_adhesion_bad --set model.adhesion_non_sisters=1e-3", out,
                            sizeof out);
  printf("adhesion_non_sisters = kappa: exit %d\n", status);
  CHECK(status == 2 && strstr(out, "model.adhesion_non_sisters"), "exit %d: %s", status, out);
  /* three cells on every element, 0.6 kappa each: 1.2 kappa per cell */
  status = run_softpack("run " SP_SOURCE_DIR "/tests/scenes/adhesion_3d.yaml --out "
                        "test_adhesion_bad --set model.adhesion_non_sisters=6e-3 "
                        "--set layout.support=full", out, sizeof out);
  printf("three cells at 0.6 kappa each: exit %d\n", status);
  CHECK(status == 2 && strstr(out, "model.adhesion_non_sisters"), "exit %d: %s", status, out);
}

static void cli_check_jacobian(const char *scene, const char *sets) {
  static char out[16384];
  char args[1024];
  snprintf(args, sizeof args, "check-jacobian %s %s", scene, sets);
  const int status = run_softpack(args, out, sizeof out);
  const char *line = strstr(out, "hand vs ad: largest relative difference ");
  double hand_ad = INFINITY;
  if (line) sscanf(line + strlen("hand vs ad: largest relative difference "), "%lf", &hand_ad);
  printf("check-jacobian %s: exit %d, hand vs ad %.3g\n", scene, status, hand_ad);
  CHECK(status == 0, "exit %d: %s", status, out);
  CHECK(hand_ad <= 1e-12, "hand vs AD %.3g: %s", hand_ad, out);
  CHECK(strstr(out, "no adhesion") != NULL, "no row without adhesion: %s", out);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 0.3, 0.2, 6, 4, &mesh));
  jacobians(mesh, 2, 11, "quadrilaterals");
  jacobians(mesh, 3, 12, "quadrilaterals");
  jacobians(mesh, 5, 13, "quadrilaterals");
  sp_mesh_destroy(&mesh);
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.4, 0.3, 0.3, 4, 3, 3, &mesh));
  jacobians(mesh, 2, 21, "hexahedra");
  jacobians(mesh, 3, 22, "hexahedra");
  sp_mesh_destroy(&mesh);
  residual_is_energy_derivative();
  cli_check_jacobian(SP_SOURCE_DIR "/tests/scenes/adhesion_pair.yaml", "--steps 2");
  cli_check_jacobian(SP_SOURCE_DIR "/tests/scenes/adhesion_3d.yaml", "--steps 1");
  bad_input();
  named_pairs();
  energy_law_and_contact();
  sisters_from_lineage();
  MPI_Finalize();
  TEST_DONE();
}
