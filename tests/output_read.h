/* Reading what src/io/output.c writes, for tests: whole files, the CSV logs
 * (energy.csv, cells.csv, divisions.csv) by column name, and the
 * DataArrays of a .vtu (inline base64 with a UInt64 byte-count header). */
#ifndef SP_TEST_OUTPUT_READ_H
#define SP_TEST_OUTPUT_READ_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* The energy column of an energy.csv: its rows, first and last values,
 * and the rises between consecutive rows larger than 1e-13 relative. */
typedef struct {
  int rows, rises;
  double first, last, worst_rise;
} energy_trend;

static inline energy_trend energy_trend_read(const char *path) {
  energy_trend tr = {0, 0, 0, INFINITY, 0};
  FILE *f = fopen(path, "r");
  CHECK(f != NULL, "%s missing", path);
  char line[2048];
  CHECK(fgets(line, sizeof line, f) && strstr(line, "energy"), "%s: header", path);
  while (fgets(line, sizeof line, f)) {
    int step, its, n;
    double t, dt, e;
    CHECK(sscanf(line, "%d,%lf,%lf,%d,%d,%lf", &step, &t, &dt, &its, &n, &e) == 6, "row %s",
          line);
    if (tr.rows == 0) tr.first = e;
    if (e > tr.last + 1e-13 * fabs(tr.last)) {
      ++tr.rises;
      if (e - tr.last > tr.worst_rise) tr.worst_rise = e - tr.last;
    }
    tr.last = e;
    ++tr.rows;
  }
  fclose(f);
  return tr;
}

/* A CSV log with a header line: every value as a double (0 where it is not
 * a number) and as its text (the name columns; at most 39 characters).
 * One allocation: free(t.v) or csv_free frees both. */
typedef struct {
  int n_rows, n_cols;
  char header[1024];
  double *v;       /* n_rows x n_cols */
  char (*str)[40]; /* n_rows x n_cols, after v's room in the same block */
} csv_table;

static inline void csv_free(csv_table *t) {
  free(t->v);
  t->v = NULL;
  t->str = NULL;
}

static inline int csv_read(const char *path, csv_table *t) {
  memset(t, 0, sizeof *t);
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  char line[4096];
  int cap = 0;
  if (!fgets(t->header, sizeof t->header, f)) {
    fclose(f);
    return -1;
  }
  t->n_cols = 1;
  for (const char *c = t->header; *c; ++c) t->n_cols += *c == ',';
  while (fgets(line, sizeof line, f)) {
    if (t->n_rows == cap) { /* doubles for cap rows, then their texts */
      const size_t old = (size_t)cap * t->n_cols;
      cap = cap ? 2 * cap : 256;
      const size_t room = (size_t)cap * t->n_cols;
      t->v = realloc(t->v, room * (sizeof(double) + sizeof *t->str));
      t->str = (char(*)[40])(t->v + room);
      memmove(t->str, t->v + old, old * sizeof *t->str);
    }
    line[strcspn(line, "\r\n")] = '\0';
    const char *s = line;
    for (int j = 0; j < t->n_cols; ++j) { /* field j: up to the next comma */
      const size_t len = strcspn(s, ",");
      const size_t ij = (size_t)t->n_rows * t->n_cols + j;
      snprintf(t->str[ij], sizeof t->str[ij], "%.*s", (int)len, s);
      t->v[ij] = strtod(t->str[ij], NULL);
      s += len + (s[len] == ',');
    }
    ++t->n_rows;
  }
  fclose(f);
  return 0;
}

/* The index of column @p name, or -1. */
static inline int csv_find(const csv_table *t, const char *name) {
  char h[1024];
  snprintf(h, sizeof h, "%s", t->header);
  h[strcspn(h, "\r\n")] = '\0';
  int j = 0;
  for (char *tok = strtok(h, ","); tok; tok = strtok(NULL, ","), ++j)
    if (strcmp(tok, name) == 0) return j;
  return -1;
}

static inline int csv_col(const csv_table *t, const char *name) {
  const int j = csv_find(t, name);
  CHECK(j >= 0, "no column %s", name);
  return j < 0 ? 0 : j;
}

static inline double at(const csv_table *t, int i, const char *name) {
  return t->v[(size_t)i * t->n_cols + csv_col(t, name)];
}

/* The text of column @p name in row @p i (a name column). */
static inline const char *at_str(const csv_table *t, int i, const char *name) {
  return t->str[(size_t)i * t->n_cols + csv_col(t, name)];
}

/* A row of a named scene's divisions.csv (README.md, "Outputs"): the cut's
 * normal from long_x, long_y, long_z in 3D, (cos, sin) of axis_angle in
 * 2D (angle: axis_angle, NAN in 3D). */
typedef struct {
  double t, angle, normal[3], before, a, b, fraction;
  int step, parent, child;
  char parent_name[32], first[32], second[32];
} division_row;

/* The rows of @p dir/divisions.csv, at most @p cap: their number; -1 if it
 * cannot be read or its header is not @p header (NULL: any). */
static inline int divisions_read(const char *dir, const char *header, division_row *rows,
                                 int cap) {
  char path[512];
  snprintf(path, sizeof path, "%s/divisions.csv", dir);
  csv_table t;
  if (csv_read(path, &t) != 0) return -1;
  if (header && strcmp(t.header, header) != 0) {
    csv_free(&t);
    return -1;
  }
  const int in_3d = csv_find(&t, "long_x") >= 0;
  int n = 0;
  for (int i = 0; i < t.n_rows && n < cap; ++i, ++n) {
    division_row *r = &rows[n];
    r->t = at(&t, i, "t");
    r->step = (int)at(&t, i, "step");
    r->parent = (int)at(&t, i, "parent");
    r->child = (int)at(&t, i, "child");
    r->angle = in_3d ? NAN : at(&t, i, "axis_angle");
    if (in_3d) {
      r->normal[0] = at(&t, i, "long_x");
      r->normal[1] = at(&t, i, "long_y");
      r->normal[2] = at(&t, i, "long_z");
    } else {
      r->normal[0] = cos(r->angle), r->normal[1] = sin(r->angle), r->normal[2] = 0;
    }
    r->before = at(&t, i, "parent_mass_before");
    r->a = at(&t, i, "parent_mass_after");
    r->b = at(&t, i, "child_mass_after");
    r->fraction = at(&t, i, "fraction");
    snprintf(r->parent_name, sizeof r->parent_name, "%s", at_str(&t, i, "parent_name"));
    snprintf(r->first, sizeof r->first, "%s", at_str(&t, i, "first_name"));
    snprintf(r->second, sizeof r->second, "%s", at_str(&t, i, "second_name"));
  }
  csv_free(&t);
  return n;
}

/** The total mass of the cells at @p step in cells.csv (NAN if unreadable);
 *  the first @p cap masses go to @p masses and their count to @p n_cells
 *  (both may be NULL). */
static inline double cells_mass_at(const char *path, int step, int cap, int *n_cells,
                                   double *masses) {
  csv_table t;
  if (n_cells) *n_cells = 0;
  if (csv_read(path, &t) != 0) return NAN;
  double total = 0;
  for (int i = 0; i < t.n_rows; ++i) {
    if (at(&t, i, "step") != step) continue;
    const double m = at(&t, i, "mass");
    total += m;
    if (n_cells && masses && *n_cells < cap) masses[(*n_cells)++] = m;
  }
  csv_free(&t);
  return total;
}

/** Column @p name of @p dir/cells.csv as a table by step and cell: v[s *
 *  n_cells + k] is cell k + 1's value at step s (NAN where it does not
 *  exist), s < cap and k < n_cells (a row beyond them fails a check);
 *  returns the number of steps + 1. */
static inline int cells_column(const char *dir, const char *name, double *v, int cap,
                               int n_cells) {
  char path[512];
  snprintf(path, sizeof path, "%s/cells.csv", dir);
  csv_table t;
  CHECK(csv_read(path, &t) == 0, "%s missing", path);
  for (int i = 0; i < cap * n_cells; ++i) v[i] = NAN;
  int steps = 0;
  for (int i = 0; i < t.n_rows; ++i) {
    const int s = (int)at(&t, i, "step"), k = (int)at(&t, i, "cell") - 1;
    CHECK(s >= 0 && s < cap && k >= 0 && k < n_cells, "row %d: step %d cell %d", i, s, k + 1);
    if (s < 0 || s >= cap || k < 0 || k >= n_cells) continue;
    v[s * n_cells + k] = at(&t, i, name);
    if (s + 1 > steps) steps = s + 1;
  }
  csv_free(&t);
  return steps;
}

/* The largest relative energy difference between two runs' energy.csv
 * (which must have the same steps at the same t). */
static inline double energy_difference(const char *a_dir, const char *b_dir) {
  char pa[512], pb[512];
  snprintf(pa, sizeof pa, "%s/energy.csv", a_dir);
  snprintf(pb, sizeof pb, "%s/energy.csv", b_dir);
  csv_table a, b;
  CHECK(csv_read(pa, &a) == 0 && csv_read(pb, &b) == 0, "%s or %s unreadable", pa, pb);
  CHECK(a.n_rows == b.n_rows, "%d rows against %d", a.n_rows, b.n_rows);
  double worst = 0;
  for (int i = 0; i < a.n_rows && i < b.n_rows; ++i) {
    CHECK(fabs(at(&a, i, "t") - at(&b, i, "t")) <= 1e-15, "row %d: t %.17g against %.17g", i,
          at(&a, i, "t"), at(&b, i, "t"));
    CHECK(at(&a, i, "n_cells") == at(&b, i, "n_cells"), "row %d: cells differ", i);
    const double ea = at(&a, i, "energy"), eb = at(&b, i, "energy");
    worst = fmax(worst, fabs(ea - eb) / fabs(ea));
  }
  free(a.v);
  free(b.v);
  return worst;
}

/* The whole file as a string (NULL if unreadable); its length in *len. */
static inline char *slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = malloc((size_t)n + 1);
  size_t got = fread(s, 1, (size_t)n, f);
  s[got] = '\0';
  fclose(f);
  if (len) *len = got;
  return s;
}

static inline int b64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/* Decode base64 from s up to '<'. A padded quad may also occur mid-stream
 * (some writers encode the header separately), so accept that too.
 * Returns the byte count. */
static inline size_t b64_decode(const char *s, unsigned char *out, size_t cap) {
  size_t n = 0;
  char q[4];
  int nq = 0;
  for (; *s && *s != '<'; ++s) {
    if (*s == ' ' || *s == '\n' || *s == '\r' || *s == '\t') continue;
    q[nq++] = *s;
    if (nq < 4) continue;
    nq = 0;
    int pad = (q[2] == '=') + (q[3] == '=');
    unsigned v = 0;
    for (int i = 0; i < 4; ++i)
      v = v << 6 | (unsigned)(q[i] == '=' ? 0 : b64_value(q[i]));
    unsigned char b[3] = {(unsigned char)(v >> 16), (unsigned char)(v >> 8),
                          (unsigned char)v};
    for (int i = 0; i < 3 - pad && n < cap; ++i) out[n++] = b[i];
  }
  return n;
}

/* The data of DataArray @p name in @p xml after its UInt64 byte-count
 * header: a malloc'd copy, its length in *bytes; NULL if absent or short. */
static inline unsigned char *vtu_array_data(const char *xml, const char *name, size_t *bytes) {
  char key[64];
  snprintf(key, sizeof key, "Name=\"%s\"", name);
  const char *p = strstr(xml, key);
  if (!p || !(p = strchr(p, '>'))) return NULL;
  const size_t cap = strlen(p);
  unsigned char *raw = malloc(cap + 8);
  const size_t n = b64_decode(p + 1, raw, cap);
  uint64_t header = 0;
  if (n >= 8) memcpy(&header, raw, 8);
  if (n < 8 || n != 8 + header) {
    free(raw);
    return NULL;
  }
  memmove(raw, raw + 8, header);
  *bytes = header;
  return raw;
}

/* The strings of the String DataArray @p name in @p xml (VTK's ASCII form:
 * each string's character codes, then a 0) into @p out, at most @p cap of
 * at most 31 characters: their number, -1 if the array is absent or its
 * NumberOfTuples is not the number of strings. */
static inline int vtu_strings(const char *xml, const char *name, char (*out)[32], int cap) {
  char key[64];
  snprintf(key, sizeof key, "type=\"String\" Name=\"%s\"", name);
  const char *p = strstr(xml, key);
  const char *tuples = p ? strstr(p, "NumberOfTuples=\"") : NULL;
  if (!p || !tuples || !(p = strchr(p, '>'))) return -1;
  const int declared = atoi(tuples + strlen("NumberOfTuples=\""));
  int n = 0, len = 0;
  char *end;
  for (long c = strtol(p + 1, &end, 10); end != p + 1; c = strtol(p + 1, &end, 10)) {
    p = end;
    if (c == 0) {
      if (n < cap) out[n][len < 31 ? len : 31] = '\0';
      ++n, len = 0;
    } else if (n < cap && len < 31) {
      out[n][len++] = (char)c;
    }
  }
  return n == declared ? n : -1;
}
#endif
