/* test_scene: the scene file reader (src/scene/scene*.c).
 *
 * - a minimal scene gets every default of the key table;
 * - a scene setting every key gets every value;
 * - --set overrides apply, bad ones fail with SP_ERR_INPUT naming the key;
 * - every file in tests/scenes/bad/ fails with SP_ERR_INPUT and a message
 *   containing the key named in its first line, "# expect: <key>";
 * - missing, unreadable and empty files fail the same way;
 * - docs/scene.md holds exactly the table sp_scene_print_keys prints;
 * - every scene shipped under inputs/, inputs/paper/, inputs/embryo/ and
 *   inputs/3d/ loads;
 * - sp_scene_load_text reads text as sp_scene_load reads the file, and
 *   names the given name in its messages;
 * - a scene whose initial layout (nodes x cells pairs, 2 x pairs unknowns)
 *   would overflow 32-bit indices is refused, one just below the limit is
 *   not. */
#define _POSIX_C_SOURCE 200809L /* opendir, readdir */

#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "run/run_options.h"
#include "scene/scene.h"

#ifndef SP_SOURCE_DIR
#error "compile with -DSP_SOURCE_DIR=\"<repository root>\""
#endif

enum { PATH_SIZE = 1024, LINE_SIZE = 512, MIN_BAD_SCENES = 12 };

static const char *source_path(const char *relative, char *buf) {
  snprintf(buf, PATH_SIZE, "%s/%s", SP_SOURCE_DIR, relative);
  return buf;
}

/** Load @p path expecting SP_ERR_INPUT and a message containing each of the
 *  non-NULL strings @p want1, @p want2. */
static void expect_input_error(const char *path, int n_set,
                               const char *const *set, const char *want1,
                               const char *want2) {
  static sp_scene sentinel;
  sp_scene *scene = &sentinel; /* sp_scene_load must reset it to NULL */
  int rc = sp_scene_load(path, n_set, set, &scene);
  const char *msg = sp_error_message();
  CHECK(rc == SP_ERR_INPUT, "%s: rc = %d, message: %s", path, rc, msg);
  CHECK(scene == NULL, "%s: the scene was not left NULL", path);
  CHECK(!want1 || strstr(msg, want1), "%s: message lacks '%s': %s", path,
        want1, msg);
  CHECK(!want2 || strstr(msg, want2), "%s: message lacks '%s': %s", path,
        want2, msg);
  if (rc == SP_OK) sp_scene_destroy(&scene);
}

static void test_defaults(void) {
  char path[PATH_SIZE];
  sp_scene *s = NULL;
  CHECK_OK(sp_scene_load(source_path("tests/scenes/ellipse_minimal.yaml",
                                     path), 0, NULL, &s));
  CHECK(s->mesh.type == SP_MESH_ELLIPSE, "mesh.type %d", s->mesh.type);
  CHECK_NEAR(s->mesh.x0, 0.0, 0.0);
  CHECK_NEAR(s->mesh.y0, 0.0, 0.0);
  CHECK_NEAR(s->mesh.x1, 1.0, 0.0);
  CHECK_NEAR(s->mesh.y1, 1.0, 0.0);
  CHECK(s->mesh.nx == 64 && s->mesh.ny == 64, "nx %d ny %d", s->mesh.nx,
        s->mesh.ny);
  CHECK(s->mesh.refinements == 5, "refinements %d", s->mesh.refinements);
  CHECK_NEAR(s->mesh.semi_x, 0.5, 0.0);
  CHECK_NEAR(s->mesh.semi_y, 0.25, 0.0);
  CHECK(s->mesh.buffer_layers == 0, "buffer_layers %d",
        s->mesh.buffer_layers);
  CHECK_NEAR(s->mesh.buffer_width, 0.1, 0.0);
  CHECK_NEAR(s->model.alpha, 4.0, 0.0);
  CHECK_NEAR(s->model.kappa, 1e-3, 0.0);
  CHECK_NEAR(s->model.lambda, 80.0, 0.0); /* the file's value */
  CHECK_NEAR(s->model.lambda_b, 100.0, 0.0);
  CHECK_NEAR(s->model.mobility, 1.0, 0.0);
  CHECK_NEAR(s->time.dt, 2e-4, 0.0);
  CHECK_NEAR(s->time.t_end, 0.02, 0.0);
  CHECK(s->time.max_steps == 1000000, "max_steps %d", s->time.max_steps);
  CHECK_NEAR(s->time.dt_min, 1e-14, 0.0);
  CHECK_NEAR(s->time.shrink, 0.25, 0.0);
  CHECK_NEAR(s->time.grow, 2.0, 0.0);
  CHECK(s->time.grow_after == 3, "grow_after %d", s->time.grow_after);
  CHECK(s->time.max_retries == 30, "max_retries %d", s->time.max_retries);
  /* the fast path by default (docs/time-stepping.md) */
  CHECK(s->time.control == SP_CONTROL_ADAPTIVE && s->time.scheme == SP_TIME_BDF2,
        "control %d scheme %d", s->time.control, s->time.scheme);
  CHECK_NEAR(s->time.rtol, 1e-2, 0.0);
  CHECK_NEAR(s->time.atol, 1e-2, 0.0);
  CHECK_NEAR(s->time.dt_max, 1.0, 0.0);
  CHECK_NEAR(s->output.interval, 0.0, 0.0);
  CHECK_NEAR(s->noise.background, 0.0, 0.0);
  CHECK_NEAR(s->noise.amplitude, 0.0, 0.0);
  CHECK(s->noise.seed == 1u, "seed %u", s->noise.seed);
  CHECK(s->solver.jacobian == SP_JAC_AD, "jacobian %d", s->solver.jacobian);
  CHECK(s->solver.linear == SP_LINEAR_AUTO, "linear %d", s->solver.linear);
  CHECK(s->solver.auto_unknowns == 250000, "auto_unknowns %d", s->solver.auto_unknowns);
  CHECK_NEAR(s->solver.krylov_tol, 0.0, 0.0);
  CHECK(s->solver.predictor == SP_PREDICT_LINEAR, "predictor %d", s->solver.predictor);
  CHECK_NEAR(s->solver.jacobian_reuse, 0.1, 0.0);
  CHECK_NEAR(s->solver.jacobian_carry, 0.35, 0.0);
  CHECK_NEAR(s->solver.newton_rtol, 1e-8, 0.0);
  CHECK_NEAR(s->solver.newton_atol, 1e-10, 0.0);
  CHECK(s->solver.newton_max_its == 12, "newton_max_its %d",
        s->solver.newton_max_its);
  CHECK(s->output.every == 10, "every %d", s->output.every);
  CHECK(s->output.pictures == 1, "pictures %d", s->output.pictures);
  CHECK(s->output.picture_width == 800, "picture_width %d",
        s->output.picture_width);

  CHECK(s->n_cells == 2, "n_cells %d", s->n_cells);
  if (s->n_cells == 2) {
    CHECK_NEAR(s->cells[0].x, -0.2, 0.0);
    CHECK_NEAR(s->cells[0].y, 0.0, 0.0);
    CHECK_NEAR(s->cells[0].radius, 0.04, 0.0);
    CHECK(s->cells[0].profile == SP_PROFILE_TANH, "profile %d",
          s->cells[0].profile);
    CHECK_NEAR(s->cells[1].x, 0.2, 0.0);
    CHECK_NEAR(s->cells[1].y, 0.05, 0.0);
    CHECK_NEAR(s->cells[1].radius, 0.05, 0.0);
    CHECK(s->cells[1].profile == SP_PROFILE_SHARP, "profile %d",
          s->cells[1].profile);
  }
  /* d = sqrt(kappa / (2 alpha)) = sqrt(1e-3 / 8), about 0.011 (docs/model.md) */
  CHECK_NEAR(sp_scene_interface_width(s), sqrt(1e-3 / 8.0), 1e-15);

  sp_scene_destroy(&s);
  CHECK(s == NULL, "sp_scene_destroy left the pointer set");
  sp_scene_destroy(&s); /* a second destroy is harmless */
}

static void test_every_key(void) {
  char path[PATH_SIZE];
  sp_scene *s = NULL;
  CHECK_OK(sp_scene_load(source_path("tests/scenes/rectangle_full.yaml",
                                     path), 0, NULL, &s));
  CHECK(s->mesh.type == SP_MESH_RECTANGLE, "mesh.type %d", s->mesh.type);
  CHECK_NEAR(s->mesh.x0, -1.0, 0.0);
  CHECK_NEAR(s->mesh.y0, -0.5, 0.0);
  CHECK_NEAR(s->mesh.x1, 1.0, 0.0);
  CHECK_NEAR(s->mesh.y1, 0.5, 0.0);
  CHECK(s->mesh.nx == 128 && s->mesh.ny == 64, "nx %d ny %d", s->mesh.nx,
        s->mesh.ny);
  CHECK(s->mesh.refinements == 3, "refinements %d", s->mesh.refinements);
  CHECK_NEAR(s->mesh.semi_x, 0.6, 0.0);
  CHECK_NEAR(s->mesh.semi_y, 0.3, 0.0);
  CHECK(s->mesh.buffer_layers == 2, "buffer_layers %d",
        s->mesh.buffer_layers);
  CHECK_NEAR(s->mesh.buffer_width, 0.2, 0.0);
  CHECK_NEAR(s->model.alpha, 2.0, 0.0);
  CHECK_NEAR(s->model.kappa, 2e-3, 0.0);
  CHECK_NEAR(s->model.lambda, 50.0, 0.0);
  CHECK_NEAR(s->model.lambda_b, 25.0, 0.0);
  CHECK_NEAR(s->model.mobility, 0.5, 0.0);
  CHECK_NEAR(s->time.dt, 1e-4, 0.0);
  CHECK_NEAR(s->time.t_end, 0.5, 0.0);
  CHECK(s->time.max_steps == 100000, "max_steps %d", s->time.max_steps);
  CHECK_NEAR(s->time.dt_min, 1e-12, 0.0);
  CHECK_NEAR(s->time.shrink, 0.5, 0.0);
  CHECK_NEAR(s->time.grow, 1.5, 0.0);
  CHECK(s->time.grow_after == 5, "grow_after %d", s->time.grow_after);
  CHECK(s->time.max_retries == 10, "max_retries %d", s->time.max_retries);
  CHECK_NEAR(s->noise.background, 0.01, 0.0);
  CHECK_NEAR(s->noise.amplitude, 0.02, 0.0);
  CHECK(s->noise.seed == 4294967295u, "seed %u", s->noise.seed);
  CHECK(s->solver.jacobian == SP_JAC_FD, "jacobian %d", s->solver.jacobian);
  CHECK(s->solver.linear == SP_LINEAR_KLU2, "linear %d", s->solver.linear);
  CHECK_NEAR(s->solver.newton_rtol, 1e-6, 0.0);
  CHECK_NEAR(s->solver.newton_atol, 1e-9, 0.0);
  CHECK(s->solver.newton_max_its == 20, "newton_max_its %d",
        s->solver.newton_max_its);
  CHECK(s->output.every == 5, "every %d", s->output.every);
  CHECK(s->output.pictures == 0, "pictures %d", s->output.pictures);
  CHECK(s->output.picture_width == 400, "picture_width %d",
        s->output.picture_width);
  CHECK(s->n_cells == 3, "n_cells %d", s->n_cells);
  if (s->n_cells == 3) {
    CHECK_NEAR(s->cells[2].y, 0.3, 0.0);
    CHECK_NEAR(s->cells[2].radius, 0.2, 0.0);
    CHECK(s->cells[2].profile == SP_PROFILE_TANH, "profile %d",
          s->cells[2].profile);
  }
  CHECK_NEAR(sp_scene_interface_width(s), sqrt(2e-3 / 4.0), 1e-15);
  sp_scene_destroy(&s);
}

/* solver.linear auto: on a 2D mesh mumps below solver.auto_unknowns
 * unknowns (default 250,000) and gmres_cells from there, on a 3D one
 * gmres_cells below SP_LINEAR_AUTO_AMG_NODES nodes and gmres_amg from
 * there, whatever the unknowns; krylov_tol 0: 1e-10 for gmres_ilu, 1e-4
 * for gmres_cells, 1e-6 for gmres_amg, else as given */
static void test_linear_auto(void) {
  CHECK(sp_linear_auto(2, 10000000, 249999, 250000) == SP_LINEAR_MUMPS,
        "auto in 2D on 1e7 nodes, 249,999 unknowns: mumps");
  CHECK(sp_linear_auto(2, 1000, 250000, 250000) == SP_LINEAR_GMRES_CELLS,
        "auto in 2D from solver.auto_unknowns: gmres_cells");
  CHECK(sp_linear_auto(3, SP_LINEAR_AUTO_AMG_NODES - 1, 100000000, 250000) ==
            SP_LINEAR_GMRES_CELLS,
        "auto in 3D below the crossover: gmres_cells");
  CHECK(sp_linear_auto(3, SP_LINEAR_AUTO_AMG_NODES, 0, 250000) == SP_LINEAR_GMRES_AMG,
        "auto in 3D from the crossover: gmres_amg");
  CHECK(sp_krylov_tol(SP_LINEAR_GMRES_CELLS, 0) == 1e-4 &&
            sp_krylov_tol(SP_LINEAR_GMRES_AMG, 0) == 1e-6 &&
            sp_krylov_tol(SP_LINEAR_MUMPS, 0) == 1e-10 &&
            sp_krylov_tol(SP_LINEAR_GMRES_CELLS, 3e-5) == 3e-5,
        "krylov_tol: the solver's own for 0, else as given");
  const struct {
    const char *scene, *set[2];
    int linear;
    double tol;
    long nodes;
  } cases[] = {
      {"tests/scenes/ellipse_minimal.yaml", {NULL, NULL}, SP_LINEAR_MUMPS, 1e-10, 0},
      {"tests/scenes/ellipse_minimal.yaml", {"solver.linear=gmres_ilu", NULL},
       SP_LINEAR_GMRES_ILU, 1e-10, 0},
      {"tests/scenes/ellipse_minimal.yaml", {"solver.linear=gmres_cells", NULL},
       SP_LINEAR_GMRES_CELLS, 1e-4, 0},
      {"tests/scenes/restart_3d.yaml", {NULL, NULL}, SP_LINEAR_GMRES_CELLS, 1e-4, 0},
      {"tests/scenes/restart_3d.yaml", {"solver.krylov_tol=1e-6", NULL}, SP_LINEAR_GMRES_CELLS,
       1e-6, 0},
      {"tests/scenes/divide_3d.yaml", {"solver.linear=auto", "solver.krylov_tol=1e-6"},
       SP_LINEAR_GMRES_CELLS, 1e-6, 0},
      {"tests/scenes/divide_3d.yaml", {"solver.linear=mumps", NULL}, SP_LINEAR_MUMPS, 1e-10, 0},
      {"tests/scenes/restart_3d.yaml", {NULL, NULL}, SP_LINEAR_GMRES_AMG, 1e-6, 50000},
      {"tests/scenes/restart_3d.yaml", {"solver.linear=gmres_cells", NULL}, SP_LINEAR_GMRES_CELLS,
       1e-4, 50000},
      {"tests/scenes/ellipse_minimal.yaml", {NULL, NULL}, SP_LINEAR_MUMPS, 1e-10, 50000},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    char path[PATH_SIZE];
    const int n_set = cases[i].set[1] ? 2 : cases[i].set[0] ? 1 : 0;
    sp_scene *s = NULL;
    CHECK_OK(sp_scene_load(source_path(cases[i].scene, path), n_set, cases[i].set, &s));
    sp_solver_options opt;
    sp_solver_options_from_scene(s, cases[i].nodes, &opt);
    CHECK(opt.linear == cases[i].linear && opt.krylov_tol == cases[i].tol,
          "%s %s %s: linear %d (want %d), krylov_tol %g (want %g)", cases[i].scene,
          cases[i].set[0] ? cases[i].set[0] : "", cases[i].set[1] ? cases[i].set[1] : "",
          opt.linear, cases[i].linear, opt.krylov_tol, cases[i].tol);
    sp_scene_destroy(&s);
  }
}

static void test_overrides(void) {
  char path[PATH_SIZE];
  source_path("tests/scenes/ellipse_minimal.yaml", path);
  const char *const set[] = {"model.lambda=50",     "time.dt=1e-4",
                             "solver.linear=mumps", "output.pictures=off",
                             "noise.seed=7",        "mesh.nx=1e2",
                             "model.kappa=3e-3",    "model.kappa=2e-3"};
  sp_scene *s = NULL;
  CHECK_OK(sp_scene_load(path, (int)(sizeof set / sizeof set[0]), set, &s));
  CHECK_NEAR(s->model.lambda, 50.0, 0.0);
  CHECK_NEAR(s->time.dt, 1e-4, 0.0);
  CHECK(s->solver.linear == SP_LINEAR_MUMPS, "linear %d", s->solver.linear);
  CHECK(s->output.pictures == 0, "pictures %d", s->output.pictures);
  CHECK(s->noise.seed == 7u, "seed %u", s->noise.seed);
  CHECK(s->mesh.nx == 100, "nx %d", s->mesh.nx);
  CHECK_NEAR(s->model.kappa, 2e-3, 0.0); /* the last override wins */
  CHECK_NEAR(s->model.alpha, 4.0, 0.0);  /* untouched keys keep theirs */
  sp_scene_destroy(&s);

  /* the two KLUs are different backends: klu (Amesos), klu2 (Amesos2) */
  static const struct {
    const char *set;
    sp_linear_kind want;
  } klu[] = {{"solver.linear=klu", SP_LINEAR_KLU}, {"solver.linear=klu2", SP_LINEAR_KLU2}};
  for (size_t i = 0; i < sizeof klu / sizeof klu[0]; ++i) {
    CHECK_OK(sp_scene_load(path, 1, &klu[i].set, &s));
    CHECK(s && s->solver.linear == klu[i].want, "%s: linear %d", klu[i].set,
          s ? (int)s->solver.linear : -1);
    sp_scene_destroy(&s);
  }

  /* each bad override alone: SP_ERR_INPUT, the key in the message */
  static const struct {
    const char *set, *want;
  } bad[] = {
      {"model.lambda=-1", "model.lambda"},     /* out of range */
      {"model.lambda=abc", "model.lambda"},    /* not a number */
      {"model.lambda=", "model.lambda"},       /* no value */
      {"model.lambda", "model.lambda"},        /* no '=' */
      {"model.lamda=1", "model.lamda"},        /* unknown key */
      {"modle.lambda=1", "modle.lambda"},      /* unknown section */
      {"lambda=1", "lambda"},                  /* no section */
      {"solver.linear=foo", "solver.linear"},  /* bad enum word */
      {"output.pictures=2", "output.pictures"},/* bad bool */
      {"mesh.nx=1.5", "mesh.nx"},              /* not an integer */
      {"noise.seed=-1", "noise.seed"},         /* negative unsigned */
      {"cells.x=0", "cells.x"},                /* cells are file only */
      {"time.dt=1e-15", "time.dt_min"},        /* cross-key: dt_min > dt */
      {"solver.newton_divergence=0.5", "solver.newton_divergence"}, /* 0 or > 1 */
      {"solver.ilu_fill=-1", "solver.ilu_fill"},      /* ILU(k), k >= 0 */
      {"solver.krylov_tol=0.5", "solver.krylov_tol"}, /* at most 1e-3 */
      {"mesh.semi_y=0.1", "cells[1].radius"},  /* cells no longer fit */
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i)
    expect_input_error(path, 1, &bad[i].set, bad[i].want, "--set");
}

/** The expected key of a bad scene: its first line, "# expect: <key>". */
static int read_expectation(const char *path, char *want, size_t size) {
  static const char tag[] = "# expect: ";
  char line[LINE_SIZE];
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  int ok = fgets(line, sizeof line, f) &&
           strncmp(line, tag, sizeof tag - 1) == 0;
  fclose(f);
  if (!ok) return 0;
  snprintf(want, size, "%s", line + sizeof tag - 1);
  want[strcspn(want, "\r\n")] = '\0';
  return want[0] != '\0';
}

static void test_bad_scenes(void) {
  char dir_path[PATH_SIZE], path[2 * PATH_SIZE], want[LINE_SIZE];
  source_path("tests/scenes/bad", dir_path);
  DIR *dir = opendir(dir_path);
  CHECK(dir, "cannot open %s", dir_path);
  if (!dir) return;
  int n_bad = 0;
  for (struct dirent *e; (e = readdir(dir));) {
    size_t len = strlen(e->d_name);
    if (len < 5 || strcmp(e->d_name + len - 5, ".yaml") != 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir_path, e->d_name);
    CHECK(read_expectation(path, want, sizeof want),
          "%s: the first line must be '# expect: <key>'", path);
    expect_input_error(path, 0, NULL, want, e->d_name);
    ++n_bad;
  }
  closedir(dir);
  CHECK(n_bad >= MIN_BAD_SCENES, "only %d bad scenes in %s", n_bad, dir_path);
}

static void test_files_and_lines(void) {
  char path[PATH_SIZE];
  /* missing file, a directory (opens but cannot be read), an empty file */
  expect_input_error(source_path("tests/scenes/no_such_scene.yaml", path), 0,
                     NULL, "no_such_scene.yaml", "cannot open");
  expect_input_error(source_path("tests/scenes", path), 0, NULL,
                     "tests/scenes", "cannot read");
  expect_input_error("/dev/null", 0, NULL, "/dev/null", "cells");
  /* where libcyaml reports a line, the message has file:line */
  expect_input_error(source_path("tests/scenes/bad/bad_enum.yaml", path), 0,
                     NULL, "bad_enum.yaml:4: solver.linear", "foo");
  expect_input_error(source_path("tests/scenes/bad/missing_radius.yaml",
                                 path),
                     0, NULL, "missing_radius.yaml:3: cells[0].radius", NULL);
  /* the message of an out-of-range value says what is allowed */
  expect_input_error(source_path("tests/scenes/bad/negative_kappa.yaml",
                                 path),
                     0, NULL, "model.kappa: expected a number > 0, got -1",
                     NULL);
}

/** Whole file into a NUL-terminated buffer (NULL on failure). */
static char *slurp(FILE *f) {
  if (fseek(f, 0, SEEK_END) != 0) return NULL;
  long size = ftell(f);
  if (size < 0 || fseek(f, 0, SEEK_SET) != 0) return NULL;
  char *text = malloc((size_t)size + 1);
  if (!text) return NULL;
  size_t got = fread(text, 1, (size_t)size, f);
  text[got] = '\0';
  return text;
}

static void test_key_table_documented(void) {
  char path[PATH_SIZE];
  FILE *printed = tmpfile();
  CHECK(printed, "tmpfile failed");
  if (!printed) return;
  sp_scene_print_keys(printed);
  char *table = slurp(printed);
  fclose(printed);
  FILE *doc_file = fopen(source_path("docs/scene.md", path), "r");
  CHECK(doc_file, "cannot open %s", path);
  char *doc = doc_file ? slurp(doc_file) : NULL;
  if (doc_file) fclose(doc_file);
  CHECK(table && strstr(table, "| `model.kappa` | float |"),
        "the printed table lacks model.kappa");
  CHECK(table && strstr(table, "| `cells[i].radius` | float |"),
        "the printed table lacks cells[i].radius");
  /* docs/scene.md must hold the printed table verbatim */
  CHECK(table && doc && strstr(doc, table),
        "docs/scene.md does not contain the output of sp_scene_print_keys; "
        "regenerate the table");
  free(table);
  free(doc);
}

/* Every shipped scene is valid (a scene only a long run reads would
 * otherwise break unseen). Returns the number loaded. */
static int load_dir(const char *relative) {
  char dir_path[PATH_SIZE], path[2 * PATH_SIZE + 2];
  DIR *dir = opendir(source_path(relative, dir_path));
  CHECK(dir != NULL, "cannot open %s", dir_path);
  if (!dir) return 0;
  int n = 0;
  for (struct dirent *e; (e = readdir(dir));) {
    const size_t len = strlen(e->d_name);
    if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir_path, e->d_name);
    sp_scene *scene = NULL;
    int rc = sp_scene_load(path, 0, NULL, &scene);
    /* cells, or initial fields from a file */
    CHECK(rc == SP_OK && scene &&
              (scene->n_cells >= 1 || scene->initial.from[0] || scene->initial.label_image[0]),
          "%s: rc %d: %s", path, rc, sp_error_message());
    if (rc == SP_OK) sp_scene_destroy(&scene);
    ++n;
  }
  closedir(dir);
  return n;
}

static void test_shipped_scenes(void) {
  const int n = load_dir("inputs") + load_dir("inputs/paper") + load_dir("inputs/embryo") +
                load_dir("inputs/3d");
  CHECK(n >= 12, "only %d scenes under inputs/", n);
}

/* tests/scenes/bad/too_many_pairs.yaml: 64 cells on a rectangle. The limit is
 * 2^30 - 1 pairs: (4094+1)(4096+1) x 64 = (2^24 - 1) x 64 = 2^30 - 64 fits,
 * (4095+1)(4096+1) x 64 = 2^30 + 2^18 does not. Loading a scene builds no
 * mesh, so the accepted one costs nothing here. */
static void test_sizes(void) {
  char path[PATH_SIZE];
  source_path("tests/scenes/bad/too_many_pairs.yaml", path);
  const char *fits[] = {"mesh.nx=4094"}, *too_large[] = {"mesh.nx=4095"};
  sp_scene *s = NULL;
  CHECK(sp_scene_load(path, 1, fits, &s) == SP_OK, "nx = 4094: %s", sp_error_message());
  CHECK(s && s->n_cells == 64 && s->mesh.nx == 4094 && s->mesh.ny == 4096,
        "the scene with nx = 4094 was not loaded as written");
  sp_scene_destroy(&s);
  expect_input_error(path, 1, too_large, "mesh.nx", "64 cells");
  expect_input_error(path, 0, NULL, "mesh.ny", "64 cells");
  /* too_many_nonzeros.yaml: 4 cells on every node; the pairs fit, the
   * Jacobian's nonzeros (9 x 4 x 7 per node) fit up to nx = 2936:
   * 2937 x 2901 x 252 = 2,147,099,724 <= 2^31 - 1 < 2938 x 2901 x 252 */
  source_path("tests/scenes/bad/too_many_nonzeros.yaml", path);
  const char *nz_fits[] = {"mesh.nx=2936"}, *nz_auto[] = {"layout.support=auto"},
             *nz_local[] = {"layout.support=local"};
  CHECK(sp_scene_load(path, 1, nz_fits, &s) == SP_OK, "nx = 2936: %s", sp_error_message());
  sp_scene_destroy(&s);
  expect_input_error(path, 0, NULL, "layout.support", "nonzeros");
  expect_input_error(path, 1, nz_auto, "mesh.nx", "nonzeros"); /* auto: full for 4 cells */
  CHECK(sp_scene_load(path, 1, nz_local, &s) == SP_OK, "local supports: %s", sp_error_message());
  sp_scene_destroy(&s);
}

/* The scene reader from memory (what the fuzz target feeds): the same
 * scene as from the file, and the same errors under the given name. */
static void test_load_text(void) {
  char path[PATH_SIZE];
  source_path("tests/scenes/ellipse_minimal.yaml", path);
  FILE *f = fopen(path, "rb");
  CHECK(f, "cannot open %s", path);
  if (!f) return;
  char *text = slurp(f);
  fclose(f);
  CHECK(text, "cannot read %s", path);
  if (!text) return;
  /* the text in a buffer of exactly its length, no NUL after it (an
   * over-read shows under tools/softpack.sh sanitize) */
  const size_t len = strlen(text);
  char *exact = malloc(len);
  CHECK(exact, "out of memory");
  if (!exact) return;
  memcpy(exact, text, len);
  sp_scene *from_file = NULL, *from_text = NULL;
  CHECK_OK(sp_scene_load(path, 0, NULL, &from_file));
  CHECK_OK(sp_scene_load_text("memory.yaml", exact, len, 0, NULL, &from_text));
  CHECK(from_text->n_cells == from_file->n_cells && from_text->n_cells == 2, "%d cells",
        from_text->n_cells);
  for (int c = 0; c < 2 && from_text->n_cells == 2; ++c) {
    const sp_scene_cell *a = &from_text->cells[c], *b = &from_file->cells[c];
    CHECK(a->x == b->x && a->y == b->y && a->radius == b->radius && a->profile == b->profile,
          "cells[%d] differs", c);
  }
  CHECK_NEAR(from_text->model.lambda, 80.0, 0.0);
  CHECK(from_text->mesh.refinements == from_file->mesh.refinements, "refinements %d",
        from_text->mesh.refinements);
  sp_scene_destroy(&from_file);
  sp_scene_destroy(&from_text);
  free(exact);
  free(text);
  static const char bad[] = "model: {lambda: -1}\ncells: [{x: 0, y: 0, radius: 0.05}]\n";
  CHECK(sp_scene_load_text("memory.yaml", bad, sizeof bad - 1, 0, NULL, &from_text) ==
            SP_ERR_INPUT && !from_text,
        "a bad scene from memory: %s", sp_error_message());
  CHECK(strstr(sp_error_message(), "memory.yaml") && strstr(sp_error_message(), "model.lambda"),
        "message: %s", sp_error_message());
}

int main(void) {
  test_shipped_scenes();
  test_load_text();
  test_sizes();
  test_defaults();
  test_every_key();
  test_overrides();
  test_linear_auto();
  test_bad_scenes();
  test_files_and_lines();
  test_key_table_documented();
  TEST_DONE();
}
