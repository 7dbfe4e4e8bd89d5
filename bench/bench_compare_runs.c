/* Compare a run's output directory with a reference run's (the
 * work-precision report, bench/work_precision.sh):
 *
 *   build/bench/bench_compare_runs RUN_DIR REFERENCE_DIR
 *
 * prints one line:
 *   steps factorisations failed_attempts wall_s energy_err mass_err
 *   centre_err l2_err
 * - factorisations: of accepted and failed attempts (energy.csv);
 * - wall_s: the sum of energy.csv's per-step seconds;
 * - energy_err: the largest |E - E_ref| / |E_ref| over the times both runs
 *   logged (with output.interval both land on its multiples);
 * - mass_err, centre_err: the largest relative mass difference and centre
 *   distance over the cells at the last step (cells.csv, by cell number);
 * - l2_err: ||c - c_ref|| / ||c_ref|| over all cells' c at the last field
 *   output (the last file of fields.pvd), nodal with lumped quad weights.
 * Exit status 2 if a file is missing or the runs do not match up. */
#include <math.h>
#include <stdint.h>

#include "../tests/output_read.h"

static void die(const char *what, const char *path) {
  fprintf(stderr, "bench_compare_runs: %s: %s\n", what, path);
  exit(2);
}

static csv_table read_csv(const char *dir, const char *name) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  csv_table t;
  if (csv_read(path, &t) != 0 || t.n_rows == 0) die("cannot read", path);
  return t;
}

/* The last .vtu listed in DIR/fields.pvd, read whole. */
static char *last_vtu(const char *dir) {
  char path[4096];
  snprintf(path, sizeof path, "%s/fields.pvd", dir);
  char *pvd = slurp(path, NULL);
  if (!pvd) die("cannot read", path);
  const char *last = NULL;
  for (const char *p = pvd; (p = strstr(p, "file=\"")); ++p) last = p + 6;
  if (!last) die("no file in", path);
  char name[1024];
  snprintf(name, sizeof name, "%.*s", (int)strcspn(last, "\""), last);
  free(pvd);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  char *xml = slurp(path, NULL);
  if (!xml) die("cannot read", path);
  return xml;
}

static double *array(const char *xml, const char *name, size_t *n, const char *dir) {
  size_t bytes;
  double *v = (double *)vtu_array_data(xml, name, &bytes);
  if (!v) die("missing array", name);
  (void)dir;
  *n = bytes / sizeof(double);
  return v;
}

static double l2_error(const char *run, const char *ref) {
  char *a = last_vtu(run), *b = last_vtu(ref);
  size_t n_pts, n_conn_bytes, n_b;
  double *pts = array(b, "Points", &n_pts, ref);
  int32_t *conn = (int32_t *)vtu_array_data(b, "connectivity", &n_conn_bytes);
  if (!conn) die("missing connectivity", ref);
  const size_t n_nodes = n_pts / 3, n_quads = n_conn_bytes / (4 * sizeof(int32_t));
  double *w = calloc(n_nodes, sizeof(double));
  for (size_t e = 0; e < n_quads; ++e) { /* shoelace area, a quarter to each node */
    double area = 0;
    for (int i = 0; i < 4; ++i) {
      const int32_t p = conn[4 * e + i], q = conn[4 * e + (i + 1) % 4];
      area += pts[3 * p] * pts[3 * q + 1] - pts[3 * q] * pts[3 * p + 1];
    }
    for (int i = 0; i < 4; ++i) w[conn[4 * e + i]] += fabs(area) / 8;
  }
  double diff = 0, norm = 0;
  for (int k = 1;; ++k) {
    char name[32];
    snprintf(name, sizeof name, "c_%d", k);
    char key[48];
    snprintf(key, sizeof key, "Name=\"%s\"", name);
    const int in_a = strstr(a, key) != NULL, in_b = strstr(b, key) != NULL;
    if (!in_a && !in_b) break;
    if (in_a != in_b) die("the runs end with different cells", name);
    size_t na;
    double *ca = array(a, name, &na, run), *cb = array(b, name, &n_b, ref);
    if (na != n_nodes || n_b != n_nodes) die("different meshes", name);
    for (size_t i = 0; i < n_nodes; ++i) {
      diff += w[i] * (ca[i] - cb[i]) * (ca[i] - cb[i]);
      norm += w[i] * cb[i] * cb[i];
    }
    free(ca);
    free(cb);
  }
  free(w);
  free(pts);
  free(conn);
  free(a);
  free(b);
  return sqrt(diff / norm);
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: bench_compare_runs RUN_DIR REFERENCE_DIR\n");
    return 2;
  }
  const char *run = argv[1], *ref = argv[2];
  csv_table ea = read_csv(run, "energy.csv"), eb = read_csv(ref, "energy.csv");
  double wall = 0, energy_err = 0;
  long factorisations = 0, failed = 0;
  const double t_end = at(&eb, eb.n_rows - 1, "t");
  int common = 0;
  for (int i = 0; i < ea.n_rows; ++i) {
    wall += at(&ea, i, "seconds");
    factorisations += (long)(at(&ea, i, "factorisations") + at(&ea, i, "failed_factorisations"));
    failed += (long)at(&ea, i, "failed_attempts");
    const double t = at(&ea, i, "t");
    for (int j = 0; j < eb.n_rows; ++j)
      if (fabs(at(&eb, j, "t") - t) <= 1e-12 * t_end) {
        const double e = at(&eb, j, "energy");
        energy_err = fmax(energy_err, fabs(at(&ea, i, "energy") - e) / fabs(e));
        ++common;
        break;
      }
  }
  if (fabs(at(&ea, ea.n_rows - 1, "t") - t_end) > 1e-12 * t_end)
    die("the runs end at different times", run);
  csv_table ca = read_csv(run, "cells.csv"), cb = read_csv(ref, "cells.csv");
  const double last_a = at(&ca, ca.n_rows - 1, "step"), last_b = at(&cb, cb.n_rows - 1, "step");
  double mass_err = 0, centre_err = 0;
  int matched = 0, n_b = 0;
  for (int j = 0; j < cb.n_rows; ++j) {
    if (at(&cb, j, "step") != last_b) continue;
    ++n_b;
    for (int i = 0; i < ca.n_rows; ++i) {
      if (at(&ca, i, "step") != last_a || at(&ca, i, "cell") != at(&cb, j, "cell")) continue;
      const double m = at(&cb, j, "mass");
      mass_err = fmax(mass_err, fabs(at(&ca, i, "mass") - m) / m);
      centre_err = fmax(centre_err, hypot(at(&ca, i, "xc") - at(&cb, j, "xc"),
                                          at(&ca, i, "yc") - at(&cb, j, "yc")));
      ++matched;
    }
  }
  if (matched != n_b) die("the runs end with different cells", run);
  const double l2 = l2_error(run, ref);
  printf("%d %ld %ld %.2f %.3e %.3e %.3e %.3e\n", (int)at(&ea, ea.n_rows - 1, "step"),
         factorisations, failed, wall, energy_err, mass_err, centre_err, l2);
  if (common < 2) fprintf(stderr, "bench_compare_runs: only %d common times\n", common);
  free(ea.v);
  free(eb.v);
  free(ca.v);
  free(cb.v);
  return 0;
}
