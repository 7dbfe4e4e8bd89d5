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
 *   field output (the last file of fields.pvd; a .pvtu, written by a run
 *   on several processes, has its pieces gathered by their node_id), nodal
 *   with lumped quad weights.
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

/* DIR/NAME read whole (dies if it cannot be). */
static char *slurp_in(const char *dir, const char *name) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  char *text = slurp(path, NULL);
  if (!text) die("cannot read", path);
  return text;
}

/* The name of the last file listed in DIR/fields.pvd (a .vtu, or a .pvtu
 * with a piece per process), into @p name. */
static void last_fields(const char *dir, char *name, size_t cap) {
  char *pvd = slurp_in(dir, "fields.pvd");
  const char *last = NULL;
  for (const char *p = pvd; (p = strstr(p, "file=\"")); ++p) last = p + 6;
  if (!last) die("no file in", dir);
  snprintf(name, cap, "%.*s", (int)strcspn(last, "\""), last);
  free(pvd);
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
  (void)dir; /* (kept for the callers) */
  *n = bytes / sizeof(double);
  return v;
}

enum { MAX_PIECES = 256 };

/* A run's last field output: its pieces (one for a .vtu; one per process
 * for a .pvtu), each with its global node numbers (node_id; a .vtu without
 * them: 0, 1, ...), and the number of global nodes. */
typedef struct {
  int n_pieces;
  char *xml[MAX_PIECES];
  int32_t *id[MAX_PIECES];
  size_t n_local[MAX_PIECES], n;
} fields_out;

static void fields_read(const char *dir, fields_out *f) {
  char name[1024];
  last_fields(dir, name, sizeof name);
  memset(f, 0, sizeof *f);
  const size_t len = strlen(name);
  if (len > 5 && strcmp(name + len - 5, ".pvtu") == 0) {
    char *top = slurp_in(dir, name);
    const char *key = "<Piece Source=\"";
    for (const char *p = top; (p = strstr(p, key)); ++p) {
      if (f->n_pieces == MAX_PIECES) die("too many pieces in", name);
      p += strlen(key);
      char piece[1024];
      snprintf(piece, sizeof piece, "%.*s", (int)strcspn(p, "\""), p);
      f->xml[f->n_pieces++] = slurp_in(dir, piece);
    }
    free(top);
    if (f->n_pieces == 0) die("no piece in", name);
  } else {
    f->xml[f->n_pieces++] = slurp_in(dir, name);
  }
  for (int q = 0; q < f->n_pieces; ++q) {
    size_t n_pts;
    free(array(f->xml[q], "Points", &n_pts, dir));
    f->n_local[q] = n_pts / 3;
    size_t bytes;
    f->id[q] = (int32_t *)vtu_array_data(f->xml[q], "node_id", &bytes);
    if (!f->id[q]) {
      if (f->n_pieces > 1) die("a piece without node_id in", dir);
      f->id[q] = malloc(f->n_local[q] * sizeof(int32_t));
      for (size_t i = 0; i < f->n_local[q]; ++i) f->id[q][i] = (int32_t)i;
    } else if (bytes != f->n_local[q] * sizeof(int32_t)) {
      die("node_id does not match the points in", dir);
    }
    for (size_t i = 0; i < f->n_local[q]; ++i)
      if ((size_t)f->id[q][i] + 1 > f->n) f->n = (size_t)f->id[q][i] + 1;
  }
}

static void fields_free(fields_out *f) {
  for (int q = 0; q < f->n_pieces; ++q) free(f->xml[q]), free(f->id[q]);
}

/* Array @p name (components per node: @p nc) on the global nodes. */
static double *fields_global(const fields_out *f, const char *name, int nc) {
  double *g = calloc(f->n * nc, sizeof(double));
  for (int q = 0; q < f->n_pieces; ++q) {
    size_t n;
    double *v = array(f->xml[q], name, &n, NULL);
    if (n != f->n_local[q] * nc) die("an array of another length", name);
    for (size_t i = 0; i < f->n_local[q]; ++i)
      for (int c = 0; c < nc; ++c) g[(size_t)f->id[q][i] * nc + c] = v[i * nc + c];
    free(v);
  }
  return g;
}

/* The nodes' lumped quad weights: a quarter of each element's area (the
 * pieces' elements are disjoint). */
static double *fields_weights(const fields_out *f) {
  double *w = calloc(f->n, sizeof(double));
  for (int q = 0; q < f->n_pieces; ++q) {
    size_t n_pts, n_conn_bytes;
    double *pts = array(f->xml[q], "Points", &n_pts, NULL);
    int32_t *conn = (int32_t *)vtu_array_data(f->xml[q], "connectivity", &n_conn_bytes);
    if (!conn) die("missing connectivity", "fields");
    const size_t n_quads = n_conn_bytes / (4 * sizeof(int32_t));
    for (size_t e = 0; e < n_quads; ++e) { /* shoelace area, a quarter to each node */
      double area = 0;
      for (int i = 0; i < 4; ++i) {
        const int32_t p = conn[4 * e + i], r = conn[4 * e + (i + 1) % 4];
        area += pts[3 * p] * pts[3 * r + 1] - pts[3 * r] * pts[3 * p + 1];
      }
      for (int i = 0; i < 4; ++i) w[f->id[q][conn[4 * e + i]]] += fabs(area) / 8;
    }
    free(pts);
    free(conn);
  }
  return w;
}

/* ||c - c_ref|| / ||c_ref|| over the matched cells at both runs' last field
 * output, on the global nodes (a .pvtu's pieces gathered by node_id).
 * pair[j]: the run's cell number matched to the reference's cell number j
 * (0: none), for j < n_pair. */
static double l2_error(const char *run, const char *ref, const int *pair, int n_pair) {
  static fields_out a, b;
  fields_read(run, &a);
  fields_read(ref, &b);
  if (a.n != b.n) die("different meshes", run);
  double *pa = fields_global(&a, "Points", 3), *pb = fields_global(&b, "Points", 3);
  if (memcmp(pa, pb, 3 * b.n * sizeof(double)) != 0) die("different meshes", run);
  free(pa);
  free(pb);
  double *w = fields_weights(&b);
  double diff = 0, norm = 0;
  for (int k = 1; k < n_pair; ++k) {
    if (pair[k] == 0) continue;
    char name[32], name_a[32];
    snprintf(name, sizeof name, "c_%d", k);
    snprintf(name_a, sizeof name_a, "c_%d", pair[k]);
    double *ca = fields_global(&a, name_a, 1), *cb = fields_global(&b, name, 1);
    for (size_t i = 0; i < b.n; ++i) {
      diff += w[i] * (ca[i] - cb[i]) * (ca[i] - cb[i]);
      norm += w[i] * cb[i] * cb[i];
    }
    free(ca);
    free(cb);
  }
  free(w);
  fields_free(&a);
  fields_free(&b);
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
