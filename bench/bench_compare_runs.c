/* Compare a run's output directory with a reference run's (the
 * work-precision report, bench/work_precision.sh):
 *
 *   build/bench/bench_compare_runs RUN_DIR REFERENCE_DIR [INTERVAL]
 *
 * prints one line:
 *   steps factorisations failed_attempts wall_s energy_err mass_err
 *   centre_err l2_err
 * - factorisations: of accepted and failed attempts (energy.csv);
 * - wall_s: the sum of energy.csv's per-step seconds;
 * - energy_err: the largest |E - E_ref| / |E_ref| over the times both runs
 *   logged (with output.interval both land on its multiples); with
 *   INTERVAL, over its multiples only (the runs' other common times can
 *   fall between two runs' divisions of the same cell, where the energies
 *   differ by the cut's spike, not by the runs' accuracy);
 * - mass_err, centre_err: the largest relative mass difference and centre
 *   distance over the cells at the last step present in both runs
 *   (cells.csv);
 * - l2_err: ||c - c_ref|| / ||c_ref|| over those cells' c at the last
 *   field output (the last file of fields.pvd), nodal with lumped quad
 *   weights.
 * Cells are matched by generation and position, not by number: with the
 * mass criterion the cells of one generation divide one at a time, in an
 * order (and so with child numbers) that can differ between runs. A cell
 * of the reference at T matches the run's cell of the same generation (its
 * number of divisions since the start, from divisions.csv) whose centre is
 * nearest, if that cell's nearest reference cell of its generation is it
 * in turn; a cell that has divided in one run and not yet in the other has
 * no match (different generations) and is left out, with a note on stderr
 * (runs whose cells all match, as with age divisions, compare every cell,
 * number for number).
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

/* The generation of every cell (divisions since the start) at the end of
 * DIR's run, from divisions.csv (absent or empty: no division), for cell
 * numbers 1 .. cap - 1. */
static void generations(const char *dir, int *gen, int cap) {
  for (int k = 0; k < cap; ++k) gen[k] = 0;
  char path[4096];
  snprintf(path, sizeof path, "%s/divisions.csv", dir);
  csv_table t;
  if (csv_read(path, &t) != 0) return;
  for (int i = 0; i < t.n_rows; ++i) {
    const int p = (int)at(&t, i, "parent"), c = (int)at(&t, i, "child");
    if (p <= 0 || c <= 0 || p >= cap || c >= cap) die("cell number out of range", path);
    gen[c] = ++gen[p];
  }
  free(t.v);
}

enum { MAX_CELLS = 4096 };

/* The cells at the last step of a run's cells.csv: number, generation,
 * mass, centre. */
typedef struct {
  int n, id[MAX_CELLS], gen[MAX_CELLS];
  double mass[MAX_CELLS], x[MAX_CELLS], y[MAX_CELLS];
} last_cells;

static void read_last_cells(const char *dir, last_cells *lc) {
  static int gen[MAX_CELLS + 1];
  generations(dir, gen, MAX_CELLS + 1);
  csv_table t = read_csv(dir, "cells.csv");
  const double last = at(&t, t.n_rows - 1, "step");
  lc->n = 0;
  for (int i = 0; i < t.n_rows; ++i) {
    if (at(&t, i, "step") != last) continue;
    const int id = (int)at(&t, i, "cell");
    if (id <= 0 || id > MAX_CELLS || lc->n == MAX_CELLS) die("too many cells in", dir);
    lc->id[lc->n] = id;
    lc->gen[lc->n] = gen[id];
    lc->mass[lc->n] = at(&t, i, "mass");
    lc->x[lc->n] = at(&t, i, "xc");
    lc->y[lc->n] = at(&t, i, "yc");
    ++lc->n;
  }
  free(t.v);
}

/* The cell of @p b of @p a's cell i's generation nearest to it, or -1. */
static int nearest(const last_cells *a, int i, const last_cells *b) {
  int best = -1;
  double d_best = INFINITY;
  for (int j = 0; j < b->n; ++j) {
    if (b->gen[j] != a->gen[i]) continue;
    const double d = hypot(b->x[j] - a->x[i], b->y[j] - a->y[i]);
    if (d < d_best) d_best = d, best = j;
  }
  return best;
}

static double *array(const char *xml, const char *name, size_t *n, const char *dir) {
  size_t bytes;
  double *v = (double *)vtu_array_data(xml, name, &bytes);
  if (!v) die("missing array", name);
  (void)dir;
  *n = bytes / sizeof(double);
  return v;
}

/* pair[j]: the run's cell number matched to the reference's cell number j
 * (0: none), for j < n_pair. */
static double l2_error(const char *run, const char *ref, const int *pair, int n_pair) {
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
  for (int k = 1; k < n_pair; ++k) {
    if (pair[k] == 0) continue;
    char name[32], name_a[32];
    snprintf(name, sizeof name, "c_%d", k);
    snprintf(name_a, sizeof name_a, "c_%d", pair[k]);
    size_t na;
    double *ca = array(a, name_a, &na, run), *cb = array(b, name, &n_b, ref);
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
  if (argc != 3 && argc != 4) {
    fprintf(stderr, "usage: bench_compare_runs RUN_DIR REFERENCE_DIR [INTERVAL]\n");
    return 2;
  }
  const char *run = argv[1], *ref = argv[2];
  const double interval = argc == 4 ? strtod(argv[3], NULL) : 0;
  if (argc == 4 && !(interval > 0)) die("INTERVAL must be positive", argv[3]);
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
    if (interval > 0 && fabs(t / interval - round(t / interval)) > 1e-9) continue;
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
  static last_cells ca, cb;
  static int pair[MAX_CELLS + 1];
  read_last_cells(run, &ca);
  read_last_cells(ref, &cb);
  double mass_err = 0, centre_err = 0;
  int matched = 0, renumbered = 0;
  for (int j = 0; j < cb.n; ++j) {
    const int i = nearest(&cb, j, &ca);
    if (i < 0 || nearest(&ca, i, &cb) != j) continue;
    pair[cb.id[j]] = ca.id[i];
    renumbered += ca.id[i] != cb.id[j];
    mass_err = fmax(mass_err, fabs(ca.mass[i] - cb.mass[j]) / cb.mass[j]);
    centre_err = fmax(centre_err, hypot(ca.x[i] - cb.x[j], ca.y[i] - cb.y[j]));
    ++matched;
  }
  if (matched == 0) die("no cell at the end matches the reference's", run);
  if (matched != cb.n || matched != ca.n || renumbered)
    fprintf(stderr,
            "bench_compare_runs: %s: %d of its %d cells at T matched the reference's %d "
            "(%d under another number)\n",
            run, matched, ca.n, cb.n, renumbered);
  const double l2 = l2_error(run, ref, pair, MAX_CELLS + 1);
  printf("%d %ld %ld %.2f %.3e %.3e %.3e %.3e\n", (int)at(&ea, ea.n_rows - 1, "step"),
         factorisations, failed, wall, energy_err, mass_err, centre_err, l2);
  if (common < 2) fprintf(stderr, "bench_compare_runs: only %d common times\n", common);
  free(ea.v);
  free(eb.v);
  return 0;
}
