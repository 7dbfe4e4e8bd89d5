/* Reading what src/output.c writes, for tests: whole files, the CSV logs
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

/* A CSV log with a header line: every value as a double. */
typedef struct {
  int n_rows, n_cols;
  char header[1024];
  double *v; /* n_rows x n_cols */
} csv_table;

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
    if (t->n_rows == cap) {
      cap = cap ? 2 * cap : 256;
      t->v = realloc(t->v, (size_t)cap * t->n_cols * sizeof(double));
    }
    char *s = line;
    for (int j = 0; j < t->n_cols; ++j) {
      t->v[(size_t)t->n_rows * t->n_cols + j] = strtod(s, &s);
      if (*s == ',') ++s;
    }
    ++t->n_rows;
  }
  fclose(f);
  return 0;
}

static inline int csv_col(const csv_table *t, const char *name) {
  char h[1024];
  snprintf(h, sizeof h, "%s", t->header);
  h[strcspn(h, "\r\n")] = '\0';
  int j = 0;
  for (char *tok = strtok(h, ","); tok; tok = strtok(NULL, ","), ++j)
    if (strcmp(tok, name) == 0) return j;
  CHECK(0, "no column %s", name);
  return 0;
}

static inline double at(const csv_table *t, int i, const char *name) {
  return t->v[(size_t)i * t->n_cols + csv_col(t, name)];
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
  free(t.v);
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
  free(t.v);
  return steps;
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
#endif
