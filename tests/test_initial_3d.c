/* initial.from in 3D: a new run's initial fields from a short
 * 3D run's .vtu and from its checkpoint (.h5), on the same mesh of
 * hexahedra; a mesh that is not the file's is bad input.
 *  - a run of two spheres in a box of 8 x 8 x 8 hexahedra writes
 *    fields_000004.vtu and checkpoint_000004.h5 at step 4;
 *  - the same box without cells, initial.from each file in turn: its
 *    fields_000000.vtu holds the same points and every cell's c and mu
 *    bit for bit as fields_000004.vtu (both files hold doubles, the
 *    checkpoint the state itself), its cells.csv at step 0 the masses and
 *    centres of step 4 to 1e-12 and its energy.csv the energy to 1e-12;
 *  - with mesh.nz = 7 (another mesh) either file is refused: exit status
 *    2, the message names initial.from, no output directory. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "command.h"
#include "public/error.h"
#include "io/vtu_read.h"
#include "output_read.h"

static const char *const box =
    "mesh: {type: box, x0: 0, y0: 0, z0: 0, x1: 0.6, y1: 0.6, z1: 0.6, nx: 8, ny: 8, nz: 8}\n"
    "model: {alpha: 4, kappa: 4.0e-3, lambda: 100, mobility: 1}\n"
    "solver: {linear: superlu, predictor: none, jacobian_reuse: 0}\n";

static void write_scene(const char *path, const char *rest) {
  FILE *f = fopen(path, "w");
  CHECK(f != NULL, "cannot write %s", path);
  if (!f) return;
  fprintf(f, "%s%s", box, rest);
  fclose(f);
}

/** Largest |difference| of two .vtu's points, c and mu (INFINITY if their
 *  sizes differ). */
static double vtu_difference(const char *a, const char *b) {
  sp_vtu_fields va, vb;
  CHECK_OK(sp_vtu_read(a, &va));
  CHECK_OK(sp_vtu_read(b, &vb));
  double worst = INFINITY;
  if (!sp_test_failures && va.n_points == vb.n_points && va.n_cells == vb.n_cells) {
    const size_t n = (size_t)va.n_points * va.n_cells;
    worst = 0;
    for (size_t i = 0; i < 3 * (size_t)va.n_points; ++i)
      worst = fmax(worst, fabs(va.xyz[i] - vb.xyz[i]));
    for (size_t i = 0; i < n; ++i)
      worst = fmax(worst, fmax(fabs(va.c[i] - vb.c[i]), fabs(va.mu[i] - vb.mu[i])));
  }
  printf("%s against %s: %d and %d points, %d and %d cells, largest difference %.3g\n", a, b,
         va.n_points, vb.n_points, va.n_cells, vb.n_cells, worst);
  sp_vtu_fields_free(&va);
  sp_vtu_fields_free(&vb);
  return worst;
}

/** The run from @p from: the same fields, masses, centres and energy as
 *  the source run's step 4. */
static void started_from(const char *from, const char *out) {
  char args[512], text[8192];
  snprintf(args, sizeof args, "run from.yaml --quiet --out %s --set initial.from=%s", out, from);
  const int status = run_softpack(args, text, sizeof text);
  CHECK(status == 0, "softpack %s: exit %d: %s", args, status, text);
  if (status != 0) return;
  char mine[256];
  snprintf(mine, sizeof mine, "%s/fields_000000.vtu", out);
  CHECK(vtu_difference("source/fields_000004.vtu", mine) == 0,
        "%s: its initial fields are not the file's", from);
  csv_table ca, cb, ea, eb;
  char path[256];
  snprintf(path, sizeof path, "%s/cells.csv", out);
  CHECK(csv_read("source/cells.csv", &ca) == 0 && csv_read(path, &cb) == 0, "cells.csv");
  snprintf(path, sizeof path, "%s/energy.csv", out);
  CHECK(csv_read("source/energy.csv", &ea) == 0 && csv_read(path, &eb) == 0, "energy.csv");
  if (sp_test_failures) return;
  int matched = 0;
  for (int i = 0; i < ca.n_rows; ++i) {
    if ((int)at(&ca, i, "step") != 4) continue;
    for (int j = 0; j < cb.n_rows; ++j) {
      if ((int)at(&cb, j, "step") != 0 || at(&cb, j, "cell") != at(&ca, i, "cell")) continue;
      ++matched;
      const double dm = fabs(at(&cb, j, "mass") / at(&ca, i, "mass") - 1);
      const double dx = fmax(fabs(at(&cb, j, "xc") - at(&ca, i, "xc")),
                             fmax(fabs(at(&cb, j, "yc") - at(&ca, i, "yc")),
                                  fabs(at(&cb, j, "zc") - at(&ca, i, "zc"))));
      CHECK(dm <= 1e-12 && dx <= 1e-12, "%s: cell %g: mass %.3g relative, centre %.3g off",
            from, at(&ca, i, "cell"), dm, dx);
    }
  }
  CHECK(matched == 2, "%s: %d of 2 cells at step 0", from, matched);
  double e_then = NAN;
  for (int i = 0; i < ea.n_rows; ++i)
    if ((int)at(&ea, i, "step") == 4) e_then = at(&ea, i, "energy");
  const double de = fabs(at(&eb, 0, "energy") / e_then - 1);
  printf("%s: energy at step 0 %.17g, the source's at step 4 %.17g (%.2e)\n", from,
         at(&eb, 0, "energy"), e_then, de);
  CHECK(de <= 1e-12, "%s: energy %.3g relative off", from, de);
  free(ca.v); free(cb.v); free(ea.v); free(eb.v);
}

/** The run from @p from on another mesh: exit 2 naming the key, nothing
 *  written. */
static void refused(const char *from) {
  char args[512], text[8192];
  struct stat st;
  snprintf(args, sizeof args, "run from.yaml --quiet --out from_other --set initial.from=%s "
           "--set mesh.nz=7", from);
  const int status = run_softpack(args, text, sizeof text);
  printf("softpack %s: exit %d: %s", args, status, text);
  CHECK(status == 2 && strstr(text, "initial.from"), "exit %d: %s", status, text);
  CHECK(stat("from_other", &st) != 0, "from_other was written");
}

int main(void) {
  CHECK(system("rm -rf source from_vtu from_h5 from_other") == 0, "cannot clean up");
  write_scene("source.yaml",
              "time: {control: fixed, scheme: be, dt: 2.0e-4, t_end: 1.0, max_steps: 5}\n"
              "noise: {background: 0.02, amplitude: 0.01, seed: 3}\n"
              "cells:\n"
              "  - {x: 0.2, y: 0.3, z: 0.3, radius: 0.12}\n"
              "  - {x: 0.42, y: 0.3, z: 0.32, radius: 0.1}\n"
              "output: {every: 2, pictures: false, timings: false, checkpoint_every: 4}\n");
  write_scene("from.yaml",
              "time: {control: fixed, scheme: be, dt: 2.0e-4, t_end: 1.0, max_steps: 1}\n"
              "output: {every: 1, pictures: false, timings: false}\n");
  char text[8192];
  const int status = run_softpack("run source.yaml --quiet --out source", text, sizeof text);
  CHECK(status == 0, "the source run: exit %d: %s", status, text);
  if (sp_test_failures) TEST_DONE();
  started_from("source/fields_000004.vtu", "from_vtu");
  started_from("source/checkpoint_000004.h5", "from_h5");
  refused("source/fields_000004.vtu");
  refused("source/checkpoint_000004.h5");
  TEST_DONE();
}
