/* Initial fields from files (src/io/initial.c):
 * - a label image (three disks of three colours drawn with cairo, no
 *   antialiasing): three cells, numbered by colour; each cell's mass is its
 *   label's pixel area plus the equilibrium profile's own excess
 *   pi^3 d^2 / 3 (the Sommerfeld expansion of the profile across a closed
 *   edge of total curvature 2 pi: 6% here) to 1%, where what is left is the
 *   pixels' staircase and the mesh's quadrature; its centre is the pixels'
 *   centroid to half a pixel;
 * - a .vtu start: a run's fields file read back on the same mesh gives the
 *   state it was written from: the cells' masses and centres of cells.csv at
 *   that step to 1e-12, and a run started from it has that step's energy
 *   to 1e-12 (no shape term, whose reference moments start anew; full
 *   supports, which do not depend on the run's history). */
#include <cairo.h>
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "public/error.h"
#include "io/initial.h"
#include "output_read.h"
#include "scene/scene.h"
#include "scene_fixture.h"
#include "run/stepper.h"

#define W 200
#define H 100
/* the image covers [-0.5, 0.5] x [-0.25, 0.25]: 0.005 a pixel */
static const double box[4] = {-0.5, -0.25, 0.5, 0.25};
static const struct {
  double x, y, r;
  unsigned rgb;
} disks[3] = {{0.05, 0.08, 0.07, 0x00ff00}, {-0.25, 0.0, 0.08, 0xff0000},
              {0.28, -0.05, 0.09, 0x0000ff}};

/** A scene's initial fields as a run sets them up (scene_fixture.h: the
 *  scenes here have at most 3 cells and no division, so their layout is
 *  the full one; the mesh is in RCB numbering, which the coordinates the
 *  checks use do not see), and the cells' observables (threshold
 *  @p threshold): what the files say. */
typedef struct {
  int n;
  scene_run *set_up;
  sp_cell_obs *obs;
} initial_fields;

static initial_fields initial_of(const sp_scene *scene, double threshold) {
  initial_fields f;
  f.set_up = scene_run_setup(scene);
  const sp_run *run = &f.set_up->run;
  f.n = run->layout->n_cells;
  CHECK(!run->support, "a scene of %d cells on local supports", f.n);
  f.obs = calloc(f.n, sizeof *f.obs);
  CHECK_OK(sp_cells_observe(run->mesh, run->layout, run->state, threshold, f.obs));
  return f;
}

static void initial_free(initial_fields *f) {
  free(f->obs);
  scene_run_free(&f->set_up);
}

static void label_image(void) {
  const double px = (box[2] - box[0]) / W;
  cairo_surface_t *img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  cairo_t *cr = cairo_create(img);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_paint(cr);
  for (int i = 0; i < 3; ++i) {
    cairo_set_source_rgb(cr, (disks[i].rgb >> 16) / 255.0, ((disks[i].rgb >> 8) & 255) / 255.0,
                         (disks[i].rgb & 255) / 255.0);
    cairo_arc(cr, (disks[i].x - box[0]) / px, (box[3] - disks[i].y) / px, disks[i].r / px, 0,
              2 * M_PI);
    cairo_fill(cr);
  }
  cairo_destroy(cr);
  cairo_surface_flush(img);
  CHECK(cairo_surface_write_to_png(img, "labels.png") == CAIRO_STATUS_SUCCESS, "write png");
  /* what the image says: per colour, its pixel area and centroid */
  const unsigned char *data = cairo_image_surface_get_data(img);
  const int stride = cairo_image_surface_get_stride(img);
  static const unsigned order[3] = {0x0000ff, 0x00ff00, 0xff0000}; /* cells 1, 2, 3 */
  double area[3] = {0}, sx[3] = {0}, sy[3] = {0};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned rgb = *(const uint32_t *)(data + (size_t)y * stride + 4 * x) & 0xffffff;
      for (int k = 0; k < 3; ++k)
        if (rgb == order[k]) {
          area[k] += px * px;
          sx[k] += px * px * (box[0] + (x + 0.5) * px);
          sy[k] += px * px * (box[3] - (y + 0.5) * px);
        }
    }
  cairo_surface_destroy(img);

  const char *text = "mesh: {type: rectangle, x0: -0.5, y0: -0.25, x1: 0.5, y1: 0.25, "
                     "nx: 160, ny: 80}\n"
                     "initial: {label_image: labels.png}\n";
  sp_scene *scene;
  CHECK_OK(sp_scene_load_text("labels", text, strlen(text), 0, NULL, &scene));
  initial_fields f = initial_of(scene, 0.0);
  int n = f.n;
  CHECK(n == 3, "%d cells found, the image has 3 labels", n);
  const sp_cell_obs *obs = f.obs;
  const double d = sp_scene_interface_width(scene);
  const double excess = M_PI * M_PI * M_PI * d * d / 3;
  for (int k = 0; k < 3; ++k) {
    const double want = area[k] + excess;
    printf("cell %d: mass %.6f, pixels %.6f + profile %.6f = %.6f (%.2e); centre (%.5f, %.5f), "
           "pixels (%.5f, %.5f)\n", k + 1, obs[k].mass, area[k], excess, want,
           obs[k].mass / want - 1, obs[k].centre[0], obs[k].centre[1], sx[k] / area[k], sy[k] / area[k]);
    CHECK(fabs(obs[k].mass / want - 1) < 0.01, "cell %d: mass %.6f, expected %.6f", k + 1,
          obs[k].mass, want);
    CHECK(hypot(obs[k].centre[0] - sx[k] / area[k], obs[k].centre[1] - sy[k] / area[k]) < 0.5 * px,
          "cell %d: centre off the image's by more than half a pixel", k + 1);
  }
  /* a missing image: bad input naming the key, when the scene is read */
  const char *missing = "mesh: {type: rectangle}\ninitial: {label_image: no_such.png}\n";
  sp_scene *bad = NULL;
  CHECK(sp_scene_load_text("missing", missing, strlen(missing), 0, NULL, &bad) == SP_ERR_INPUT &&
            !bad && strstr(sp_error_message(), "initial.label_image"),
        "missing image: %s", sp_error_message());
  /* an image that is not a PNG: bad input naming the key, at set-up */
  FILE *junk = fopen("not_a.png", "w");
  fputs("not a png\n", junk);
  fclose(junk);
  const char *not_png = "mesh: {type: rectangle}\ninitial: {label_image: not_a.png}\n";
  CHECK_OK(sp_scene_load_text("not_png", not_png, strlen(not_png), 0, NULL, &bad));
  CHECK(sp_initial_cell_count(bad, NULL, &n) == SP_ERR_INPUT &&
            strstr(sp_error_message(), "initial.label_image"), "not a PNG: %s",
        sp_error_message());
  sp_scene_destroy(&bad);
  initial_free(&f);
  sp_scene_destroy(&scene);
}

static void vtu_start(void) {
  const char *scene_file = SP_SOURCE_DIR "/tests/scenes/restart_grow.yaml";
  const char *set[] = {"shape.delta2=0", "time.t_end=0.003", "output.every=1",
                       "output.checkpoint_every=0", "layout.support=full"};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(scene_file, 5, set, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "initial_vtu_a", MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  const int step = sum.steps - 2; /* a fields file with divided cells */
  char vtu[256], set_from[320];
  snprintf(vtu, sizeof vtu, "initial_vtu_a/fields_%06d.vtu", step);
  snprintf(set_from, sizeof set_from, "initial.from=%s", vtu);
  /* the same scene without cells, from that file */
  const char *text = "mesh: {type: ellipse, refinements: 4, semi_x: 0.5, semi_y: 0.25, "
                     "buffer_layers: 2, buffer_width: 0.1}\n"
                     "time: {t_end: 0.001, max_steps: 2}\nlayout: {support: full}\n"
                     "output: {pictures: false}\n";
  const char *set2[] = {set_from};
  CHECK_OK(sp_scene_load_text("from_vtu", text, strlen(text), 1, set2, &scene));
  csv_table cells, energy;
  CHECK(csv_read("initial_vtu_a/cells.csv", &cells) == 0, "cells.csv");
  CHECK(csv_read("initial_vtu_a/energy.csv", &energy) == 0, "energy.csv");
  initial_fields f = initial_of(scene, scene->division.observe_threshold);
  const int n = f.n;
  const sp_cell_obs *obs = f.obs;
  int matched = 0;
  for (int i = 0; i < cells.n_rows; ++i) {
    if ((int)at(&cells, i, "step") != step) continue;
    const int k = (int)at(&cells, i, "cell") - 1;
    CHECK(k >= 0 && k < n, "cell %d of cells.csv", k + 1);
    if (k < 0 || k >= n) continue;
    ++matched;
    CHECK(fabs(obs[k].mass / at(&cells, i, "mass") - 1) < 1e-12, "cell %d: mass %.17g, cells.csv "
          "%.17g", k + 1, obs[k].mass, at(&cells, i, "mass"));
    CHECK(hypot(obs[k].centre[0] - at(&cells, i, "xc"), obs[k].centre[1] - at(&cells, i, "yc")) < 1e-12,
          "cell %d: centre", k + 1);
  }
  CHECK(matched == n && n >= 2, "%d cells in the file, %d in cells.csv at step %d", n, matched,
        step);
  /* a run from it starts with that state's energy */
  CHECK_OK(sp_stepper_run(scene, "initial_vtu_b", MPI_COMM_WORLD, &sum));
  csv_table e2;
  CHECK(csv_read("initial_vtu_b/energy.csv", &e2) == 0, "energy.csv of the run from the .vtu");
  double e_then = NAN;
  for (int i = 0; i < energy.n_rows; ++i)
    if ((int)at(&energy, i, "step") == step) e_then = at(&energy, i, "energy");
  printf(".vtu start: %d cells, energy %.17g, at step %d of the run it came from %.17g\n", n,
         at(&e2, 0, "energy"), step, e_then);
  CHECK(fabs(at(&e2, 0, "energy") / e_then - 1) < 1e-12, "energy %.17g, written from %.17g",
        at(&e2, 0, "energy"), e_then);
  initial_free(&f);
  free(cells.v);
  free(energy.v);
  free(e2.v);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  label_image();
  vtu_start();
  MPI_Finalize();
  TEST_DONE();
}
