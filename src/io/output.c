/**
 * @file output.c
 * @brief A run's output directory: CSV append-logs (energy.csv, cells.csv)
 *        and VTK XML fields (one .vtu per output time, listed in fields.pvd).
 *
 * The CSV logs stay open and are flushed after every row, so a crash loses at
 * most the row being written. Every other file is written to "<path>.tmp" in
 * the same directory and renamed over <path>: rename within one file system
 * is atomic, so a reader (ParaView, a plotting script, a restart) never sees a
 * half-written file.
 *
 * The .vtu files use VTK's inline base64 "binary" encoding: with 100k nodes
 * and 16 cells, ASCII at round-trip precision would be ~80 MB per output,
 * base64 of the raw doubles is ~34 MB and still exact. Everything is streamed
 * node by node, so no array of the whole output is held in memory.
 */
#define _POSIX_C_SOURCE 200809L

#include "io/output.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "public/error.h"

struct sp_output_s {
  char *dir;
  char *energy_path, *cells_path, *divisions_path;
  FILE *energy, *cells, *divisions;
  int dim; /**< the mesh's: cells.csv has z on a 3D one */
  int named; /**< the scene names its cells: cells.csv and divisions.csv
                  end with name columns */
  int adhesion; /**< the scene has adhesion: energy.csv ends with its column */
  int n_fields, cap_fields;
  sp_output_field *fields; /**< each fields file written, in write order */
};

/* ------------------------------------------------------------------------ */
/* Small helpers                                                            */
/* ------------------------------------------------------------------------ */

/** malloc'd printf; NULL when out of memory. */
static char *sp_strfmt(const char *fmt, ...)
    __attribute__((format(printf, 1, 2)));
static char *sp_strfmt(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (n < 0) return NULL;
  char *s = malloc((size_t)n + 1);
  if (!s) return NULL;
  va_start(ap, fmt);
  vsnprintf(s, (size_t)n + 1, fmt, ap);
  va_end(ap);
  return s;
}

/** A growing text buffer (for the small files built in memory). */
typedef struct {
  char *s;
  size_t len, cap;
  int oom;
} sp_strbuf;

static void sp_strbuf_add(sp_strbuf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static void sp_strbuf_add(sp_strbuf *b, const char *fmt, ...) {
  if (b->oom) return;
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (n < 0) { b->oom = 1; return; }
  if (b->len + (size_t)n + 1 > b->cap) {
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->len + (size_t)n + 1) cap *= 2;
    char *s = realloc(b->s, cap);
    if (!s) { b->oom = 1; return; }
    b->s = s;
    b->cap = cap;
  }
  va_start(ap, fmt);
  vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
  va_end(ap);
  b->len += (size_t)n;
}

/** mkdir -p: create @p dir and its missing parents. An existing directory
 *  is fine; an existing non-directory anywhere on the path is an error. */
static int sp_mkdir_p(const char *dir) {
  SP_CHECK(dir && dir[0], SP_ERR_IO, "output directory: empty path");
  char *p = sp_strfmt("%s", dir);
  SP_CHECK(p, SP_ERR_MEMORY, "out of memory copying path '%s'", dir);
  size_t n = strlen(p);
  while (n > 1 && p[n - 1] == '/') p[--n] = '\0'; /* "a/b/" is "a/b" */
  /* Walk the components left to right; a leading '/' is not a component. */
  for (size_t i = 1; i <= n; ++i) {
    if (i < n && p[i] != '/') continue;
    char saved = p[i];
    p[i] = '\0';
    if (mkdir(p, 0777) != 0) {
      int err = errno;
      struct stat st;
      if (err == EEXIST) {
        /* Something is there: only a directory (or a link to one) will do. */
        if (stat(p, &st) != 0 || !S_ISDIR(st.st_mode)) {
          int rc = sp_error_set(SP_ERR_IO,
                                "cannot create output directory '%s': '%s' "
                                "exists and is not a directory (%s)",
                                dir, p, strerror(ENOTDIR));
          free(p);
          return rc;
        }
      } else {
        int rc = sp_error_set(SP_ERR_IO,
                              "cannot create output directory '%s' (at '%s'): "
                              "%s", dir, p, strerror(err));
        free(p);
        return rc;
      }
    }
    p[i] = saved;
  }
  free(p);
  return SP_OK;
}

/**
 * Open "<path>.tmp" for writing. The temporary lives in the same directory
 * as @p path, so the final rename never crosses file systems.
 */
static int sp_tmp_open(const char *path, char **tmp, FILE **f) {
  *f = NULL;
  *tmp = sp_strfmt("%s.tmp", path);
  SP_CHECK(*tmp, SP_ERR_MEMORY, "out of memory naming a temporary for '%s'",
           path);
  *f = fopen(*tmp, "wb");
  if (!*f) {
    int rc = sp_error_set(SP_ERR_IO, "cannot open '%s' for writing: %s", *tmp,
                          strerror(errno));
    free(*tmp);
    *tmp = NULL;
    return rc;
  }
  return SP_OK;
}

/**
 * Close the temporary opened by sp_tmp_open and rename it over @p path.
 * Write errors are sticky in the FILE (ferror) and buffered data may only
 * fail at fclose, so both are checked before the rename; on any failure the
 * temporary is removed and @p path is left as it was. Frees @p tmp.
 */
static int sp_tmp_commit(const char *path, char *tmp, FILE *f) {
  int rc = SP_OK;
  int bad = ferror(f);
  int err = bad ? (errno ? errno : EIO) : 0;
  if (fclose(f) != 0 && !bad) {
    bad = 1;
    err = errno;
  }
  if (bad) {
    rc = sp_error_set(SP_ERR_IO, "cannot write '%s': %s", tmp, strerror(err));
  } else if (rename(tmp, path) != 0) {
    rc = sp_error_set(SP_ERR_IO, "cannot rename '%s' to '%s': %s", tmp, path,
                      strerror(errno));
  }
  if (rc != SP_OK) remove(tmp);
  free(tmp);
  return rc;
}

int sp_write_file_atomic(const char *path, const char *text, size_t len) {
  char *tmp;
  FILE *f;
  SP_CALL(sp_tmp_open(path, &tmp, &f));
  if (len) fwrite(text, 1, len, f); /* a short write sets ferror */
  return sp_tmp_commit(path, tmp, f);
}

/* ------------------------------------------------------------------------ */
/* Open, CSV logs, close                                                    */
/* ------------------------------------------------------------------------ */

/** Flush a log after a row; report a failed row (disk full, ...) by path. */
static int sp_log_done(FILE *f, const char *path, int printed) {
  if (printed < 0 || fflush(f) != 0 || ferror(f))
    return sp_error_set(SP_ERR_IO, "cannot write '%s': %s", path,
                        strerror(errno ? errno : EIO));
  return SP_OK;
}

/** A log's buffer: a step's rows (cells.csv: one per cell) go to the file
 *  in one write at the flush, so a killed run leaves whole lines. */
#define SP_LOG_BUFFER (1 << 20)

/** Open a log: a new one with its header (@p header), or an existing one
 *  to append to (@p header NULL). */
static int sp_log_open(const char *path, const char *header, FILE **f) {
  *f = fopen(path, header ? "w" : "a");
  SP_CHECK(*f, SP_ERR_IO, "cannot open '%s' for writing: %s", path,
           strerror(errno));
  setvbuf(*f, NULL, _IOFBF, SP_LOG_BUFFER);
  return header ? sp_log_done(*f, path, fprintf(*f, "%s\n", header)) : SP_OK;
}

/**
 * Cut the log @p path back to its header and the rows whose column
 * @p column (0-based) is a step <= @p step; a last line without its newline
 * (a killed run's) goes too. Rewritten atomically; a missing log is fine
 * (it is started anew). Sets *@p exists.
 */
static int sp_log_cut(const char *path, int column, int step, int *exists) {
  size_t len;
  FILE *f = fopen(path, "rb");
  *exists = f != NULL;
  if (!f) return SP_OK;
  fseek(f, 0, SEEK_END);
  len = (size_t)ftell(f);
  rewind(f);
  char *text = malloc(len + 1);
  if (!text) {
    fclose(f);
    return sp_error_set(SP_ERR_MEMORY, "out of memory reading '%s'", path);
  }
  const size_t got = fread(text, 1, len, f);
  fclose(f);
  SP_CHECK(got == len, SP_ERR_IO, "cannot read '%s'", path);
  text[len] = '\0';
  size_t keep = 0;
  for (size_t at = 0; at < len;) {
    const char *nl = memchr(text + at, '\n', len - at);
    if (!nl) break; /* a torn last line */
    const size_t end = (size_t)(nl - text) + 1;
    if (at > 0) { /* a row: its step column */
      const char *p = text + at;
      for (int c = 0; c < column && p < nl; ++c) {
        p = memchr(p, ',', (size_t)(nl - p));
        p = p ? p + 1 : nl;
      }
      char *num_end;
      const long row_step = strtol(p, &num_end, 10);
      if (num_end == p || row_step > step) break; /* rows are in step order */
    }
    keep = end;
    at = end;
  }
  const int rc = sp_write_file_atomic(path, text, keep);
  free(text);
  return rc;
}

/** The logs: file name, header, the 0-based column holding the step. */
static const struct {
  const char *name, *header;
  int step_column;
} sp_logs[3] = {
    {"energy.csv",
     "step,t,dt,newton_its,n_cells,energy,bulk,gradient,repulsion,buffer,shape,seconds,"
     "assembly_s,factorisation_s,solves_s,supports_s,support_changed,unknowns,factorisations,"
     "failed_attempts,failed_factorisations,residual_rise,linear_its,error_estimate",
     0},
    {"cells.csv", "step,t,cell,mass,xc,yc,I1,I2,angle,core_mass,area", 0},
    {"divisions.csv",
     "t,step,parent,child,axis_angle,parent_mass_before,parent_mass_after,child_mass_after", 1}};

/** cells.csv's header on a 3D mesh: the centre with z, the three principal
 *  moments, the long axis (the unit eigenvector of the smallest moment I3,
 *  the normal of a division's cut), the volume inside the membrane. */
static const char sp_cells_header_3d[] =
    "step,t,cell,mass,xc,yc,zc,I1,I2,I3,long_x,long_y,long_z,core_mass,volume";

/** divisions.csv's header on a 3D mesh: the parent's long axis (the cut
 *  plane's normal) instead of the 2D line's angle. */
static const char sp_divisions_header_3d[] =
    "t,step,parent,child,long_x,long_y,long_z,parent_mass_before,parent_mass_after,"
    "child_mass_after";

/** What named cells add to cells.csv and divisions.csv (lineage.h): the
 *  names and the lineage table's share of the first daughter. */
static const char sp_cells_names[] = ",name";
static const char sp_divisions_names[] = ",parent_name,first_name,second_name,fraction";
/** What adhesion adds to energy.csv: its part of the energy (in the total). */
static const char sp_energy_adhesion[] = ",adhesion";

/** Open @p dir's logs for a mesh of dimension @p dim: new ones
 *  (@p resume_step < 0), or the existing ones cut back to the rows of steps
 *  <= @p resume_step and appended to. */
static int output_open(const char *dir, int dim, int flags, int resume_step, sp_output *out) {
  const int named = (flags & SP_OUTPUT_NAMED) != 0;
  *out = NULL;
  SP_CALL(sp_mkdir_p(dir));
  struct sp_output_s *o;
  SP_ALLOC(o, 1);
  o->dir = sp_strfmt("%s", dir);
  o->dim = dim;
  o->named = named;
  o->adhesion = (flags & SP_OUTPUT_ADHESION) != 0;
  o->energy_path = sp_strfmt("%s/%s", dir, sp_logs[0].name);
  o->cells_path = sp_strfmt("%s/%s", dir, sp_logs[1].name);
  o->divisions_path = sp_strfmt("%s/%s", dir, sp_logs[2].name);
  char *paths[3] = {o->energy_path, o->cells_path, o->divisions_path};
  FILE **files[3] = {&o->energy, &o->cells, &o->divisions};
  int rc = SP_OK;
  if (!o->dir || !o->energy_path || !o->cells_path || !o->divisions_path)
    rc = sp_error_set(SP_ERR_MEMORY, "out of memory naming files in '%s'",
                      dir);
  for (int i = 0; i < 3 && rc == SP_OK; ++i) {
    int exists = 0;
    if (resume_step >= 0) rc = sp_log_cut(paths[i], sp_logs[i].step_column, resume_step, &exists);
    const char *header = dim != 3 ? sp_logs[i].header
                         : i == 1     ? sp_cells_header_3d
                         : i == 2     ? sp_divisions_header_3d
                                      : sp_logs[i].header;
    char *named_header =
        sp_strfmt("%s%s", header, i == 0 ? (o->adhesion ? sp_energy_adhesion : "")
                                  : !named ? ""
                                  : i == 1 ? sp_cells_names
                                           : sp_divisions_names);
    if (!named_header && rc == SP_OK)
      rc = sp_error_set(SP_ERR_MEMORY, "out of memory for the header of '%s'", paths[i]);
    if (rc == SP_OK) rc = sp_log_open(paths[i], exists ? NULL : named_header, files[i]);
    free(named_header);
  }
  if (rc != SP_OK) {
    sp_output_close(&o); /* keeps the first error's message */
    return rc;
  }
  *out = o;
  return SP_OK;
}

int sp_output_open(const char *dir, sp_output *out) { return output_open(dir, 2, 0, -1, out); }

int sp_output_open_dim(const char *dir, int dim, int flags, sp_output *out) {
  SP_CHECK(dim == 2 || dim == 3, SP_ERR_INTERNAL, "output: dimension %d", dim);
  return output_open(dir, dim, flags, -1, out);
}

int sp_output_log_open(const char *dir, const char *name, const char *header,
                       int step_column, int resume_step, FILE **f, char **path) {
  *f = NULL;
  *path = sp_strfmt("%s/%s", dir, name);
  SP_CHECK(*path, SP_ERR_MEMORY, "out of memory naming '%s' in '%s'", name, dir);
  int exists = 0;
  if (resume_step >= 0) SP_CALL(sp_log_cut(*path, step_column, resume_step, &exists));
  return sp_log_open(*path, exists ? NULL : header, f);
}

int sp_output_log_done(FILE *f, const char *path, int printed) {
  return sp_log_done(f, path, printed);
}

int sp_output_energy(sp_output out, int step, double t, double dt,
                     int newton_its, int n_cells, const sp_energy_parts *parts,
                     double shape, const sp_step_costs *seconds) {
  sp_energy_parts p = {0, 0, 0, 0, 0};
  if (parts) p = *parts;
  sp_step_costs w = {.error_estimate = -1};
  if (seconds) w = *seconds;
  double total = p.bulk + p.gradient + p.repulsion + p.buffer + shape;
  if (out->adhesion) total += p.adhesion;
  /* %.17g: every double prints to a string that reads back bit-exact. */
  int n = fprintf(out->energy,
                  "%d,%.17g,%.17g,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                  "%.4g,%.4g,%.4g,%.4g,%.4g,%d,%ld,%d,%d,%d,%.4g,%ld,%.6g",
                  step, t, dt, newton_its, n_cells, total, p.bulk, p.gradient,
                  p.repulsion, p.buffer, shape, w.step, w.assembly, w.factorisation,
                  w.solves, w.supports, w.support_changed, w.unknowns, w.factorisations,
                  w.failed_attempts, w.failed_factorisations, w.residual_rise, w.linear_its,
                  w.error_estimate);
  if (n >= 0 && out->adhesion) n = fprintf(out->energy, ",%.17g", p.adhesion);
  if (n >= 0) n = fprintf(out->energy, "\n");
  return sp_log_done(out->energy, out->energy_path, n);
}

int sp_output_cells(sp_output out, int step, double t, int n_cells,
                    const sp_cell_obs *obs, const sp_cell_name *names) {
  int n = 0;
  /* a named scene's rows end with the name */
  for (int k = 0; k < n_cells && n >= 0; ++k) {
    const sp_cell_obs *o = &obs[k];
    const double *c = o->centre, *I = o->moments, *v = o->axes[o->long_axis];
    if (out->dim == 3)
      n = fprintf(out->cells,
                  "%d,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                  "%.17g,%.17g",
                  step, t, k + 1, o->mass, c[0], c[1], c[2], I[0], I[1], I[2], v[0], v[1], v[2],
                  o->mass_core, o->volume);
    else
      n = fprintf(out->cells, "%d,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                  step, t, k + 1, o->mass, c[0], c[1], I[0], I[1], sp_cells_obs_angle(o, 2),
                  o->mass_core, o->volume);
    if (n >= 0 && out->named) n = fprintf(out->cells, ",%s", names ? names[k] : "");
    if (n >= 0) n = fprintf(out->cells, "\n");
  }
  return sp_log_done(out->cells, out->cells_path, n);
}

int sp_output_division(sp_output out, double t, int step, const sp_division_record *d) {
  int n = out->dim == 3
              ? fprintf(out->divisions, "%.17g,%d,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                        t, step, d->parent + 1, d->child + 1, d->axis[0], d->axis[1],
                        d->axis[2], d->parent_mass, d->mass_a, d->mass_b)
              : fprintf(out->divisions, "%.17g,%d,%d,%d,%.17g,%.17g,%.17g,%.17g", t, step,
                        d->parent + 1, d->child + 1, d->angle, d->parent_mass, d->mass_a,
                        d->mass_b);
  if (n >= 0 && out->named) {
    n = fprintf(out->divisions, ",%s,%s,%s,", d->parent_name, d->name_a, d->name_b);
    if (n >= 0 && !isnan(d->fraction)) n = fprintf(out->divisions, "%.17g", d->fraction);
  }
  if (n >= 0) n = fprintf(out->divisions, "\n");
  return sp_log_done(out->divisions, out->divisions_path, n);
}

/** The columns with a dimension (sp_output_units_write): in which file,
 *  on which meshes (2, 3; 0: both), and their powers of the model's length
 *  (dim_power: times the dimension; length_power: plus this) and time. */
static const struct {
  const char *file, *column;
  int only_dim, dim_power, length_power, time_power;
} sp_unit_columns[] = {
    {"energy.csv", "t", 0, 0, 0, 1},         {"energy.csv", "dt", 0, 0, 0, 1},
    {"cells.csv", "t", 0, 0, 0, 1},          {"cells.csv", "mass", 0, 1, 0, 0},
    {"cells.csv", "xc", 0, 0, 1, 0},         {"cells.csv", "yc", 0, 0, 1, 0},
    {"cells.csv", "zc", 3, 0, 1, 0},         {"cells.csv", "I1", 0, 1, 2, 0},
    {"cells.csv", "I2", 0, 1, 2, 0},         {"cells.csv", "I3", 3, 1, 2, 0},
    {"cells.csv", "core_mass", 0, 1, 0, 0},  {"cells.csv", "area", 2, 1, 0, 0},
    {"cells.csv", "volume", 3, 1, 0, 0},     {"divisions.csv", "t", 0, 0, 0, 1},
    {"divisions.csv", "parent_mass_before", 0, 1, 0, 0},
    {"divisions.csv", "parent_mass_after", 0, 1, 0, 0},
    {"divisions.csv", "child_mass_after", 0, 1, 0, 0},
    {"contacts.csv", "t", 0, 0, 0, 1},       {"contacts.csv", "contact", 0, 1, -1, 0},
    {"contacts.csv", "volume", 0, 1, 0, 0},  {"contacts.csv", "surface", 0, 1, -1, 0},
    {"contacts.csv", "free_surface", 0, 1, -1, 0}};

int sp_output_units_write(const char *dir, int dim, const sp_output_units *units) {
  if (!units->length[0] && !units->time[0]) return SP_OK;
  size_t cap = 4096, used = 0;
  char *text = malloc(cap);
  SP_CHECK(text, SP_ERR_MEMORY, "out of memory writing units.csv");
  used += (size_t)snprintf(text, cap, "file,column,unit,scale\n");
  for (size_t i = 0; i < sizeof sp_unit_columns / sizeof sp_unit_columns[0]; ++i) {
    const int only = sp_unit_columns[i].only_dim;
    const int length = sp_unit_columns[i].dim_power * dim + sp_unit_columns[i].length_power;
    const int time = sp_unit_columns[i].time_power;
    if ((only && only != dim) || (length && !units->length[0]) || (time && !units->time[0]))
      continue;
    const char *name = length ? units->length : units->time;
    const int power = length ? length : time;
    const double scale = pow(length ? units->length_scale : units->time_scale, power);
    char unit[2 * SP_CELL_NAME_MAX];
    if (power == 1) snprintf(unit, sizeof unit, "%s", name);
    else snprintf(unit, sizeof unit, "%s^%d", name, power);
    used += (size_t)snprintf(text + used, cap - used, "%s,%s,%s,%.17g\n",
                             sp_unit_columns[i].file, sp_unit_columns[i].column, unit, scale);
  }
  char *path = sp_strfmt("%s/units.csv", dir);
  const int rc = path ? sp_write_file_atomic(path, text, used)
                      : sp_error_set(SP_ERR_MEMORY, "out of memory naming units.csv");
  free(path);
  free(text);
  return rc;
}

const char *sp_output_dir(sp_output out) { return out ? out->dir : NULL; }

int sp_output_fields_list(sp_output out, const sp_output_field **fields) {
  *fields = out->fields;
  return out->n_fields;
}

int sp_output_close(sp_output *out) {
  if (!out || !*out) return SP_OK;
  struct sp_output_s *o = *out;
  int rc = SP_OK;
  /* fclose flushes; its failure is the last chance to notice a lost row. */
  if (o->energy && fclose(o->energy) != 0)
    rc = sp_error_set(SP_ERR_IO, "cannot close '%s': %s", o->energy_path,
                      strerror(errno));
  if (o->cells && fclose(o->cells) != 0 && rc == SP_OK)
    rc = sp_error_set(SP_ERR_IO, "cannot close '%s': %s", o->cells_path,
                      strerror(errno));
  if (o->divisions && fclose(o->divisions) != 0 && rc == SP_OK)
    rc = sp_error_set(SP_ERR_IO, "cannot close '%s': %s", o->divisions_path,
                      strerror(errno));
  free(o->dir);
  free(o->energy_path);
  free(o->cells_path);
  free(o->divisions_path);
  free(o->fields);
  free(o);
  *out = NULL;
  return rc;
}

/* ------------------------------------------------------------------------ */
/* VTK XML fields                                                           */
/* ------------------------------------------------------------------------ */

/**
 * Streaming base64 encoder for VTK "binary" inline data. Bytes are grouped
 * in triplets; the encoded text is buffered and written in blocks.
 */
typedef struct {
  FILE *f;
  unsigned char in[3];
  int n_in;
  char out[4096];
  size_t n_out;
} sp_b64;

static const char sp_b64_alphabet[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

static void sp_b64_flush_out(sp_b64 *b) {
  if (b->n_out) fwrite(b->out, 1, b->n_out, b->f); /* errors: ferror */
  b->n_out = 0;
}

/** Emit one quad of characters for the n (1..3) bytes in b->in. */
static void sp_b64_quad(sp_b64 *b, int n) {
  unsigned v = (unsigned)b->in[0] << 16 |
               (unsigned)(n > 1 ? b->in[1] : 0) << 8 |
               (unsigned)(n > 2 ? b->in[2] : 0);
  if (b->n_out + 4 > sizeof b->out) sp_b64_flush_out(b);
  char *o = b->out + b->n_out;
  o[0] = sp_b64_alphabet[v >> 18 & 63];
  o[1] = sp_b64_alphabet[v >> 12 & 63];
  o[2] = n > 1 ? sp_b64_alphabet[v >> 6 & 63] : '=';
  o[3] = n > 2 ? sp_b64_alphabet[v & 63] : '=';
  b->n_out += 4;
}

static void sp_b64_put(sp_b64 *b, const void *data, size_t len) {
  const unsigned char *p = data;
  for (size_t i = 0; i < len; ++i) {
    b->in[b->n_in++] = p[i];
    if (b->n_in == 3) {
      sp_b64_quad(b, 3);
      b->n_in = 0;
    }
  }
}

/** Pad the last partial triplet and write everything out. */
static void sp_b64_end(sp_b64 *b) {
  if (b->n_in) sp_b64_quad(b, b->n_in);
  b->n_in = 0;
  sp_b64_flush_out(b);
}

/**
 * Start a DataArray's data: the UInt64 byte count, then (same base64 run,
 * as vtkXMLWriter does for uncompressed data) the values.
 */
static void sp_b64_begin_array(sp_b64 *b, FILE *f, uint64_t nbytes) {
  b->f = f;
  b->n_in = 0;
  b->n_out = 0;
  sp_b64_put(b, &nbytes, sizeof nbytes);
}

static void sp_vtu_array_open(FILE *f, const char *type, const char *name,
                              int ncomp) {
  fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\"", type, name);
  if (ncomp > 1) fprintf(f, " NumberOfComponents=\"%d\"", ncomp);
  fprintf(f, " format=\"binary\">\n          ");
}

static void sp_vtu_array_close(FILE *f) { fprintf(f, "\n        </DataArray>\n"); }

/** VTK's cell types (vtkCellType.h). */
enum { SP_VTK_QUAD = 9, SP_VTK_HEXAHEDRON = 12 };

/** The points and elements of one .vtu: all of the mesh, or (a piece of
 *  an MPI run) a subset of the elements and the nodes they use. */
typedef struct {
  int n_nodes, n_elems;
  const int *node;     /**< NULL: all nodes; else the global node of each point */
  const int *elem;     /**< NULL: all elements; else the elements of the piece */
  const int *local;    /**< global node -> point index (pieces only) */
} sp_vtu_part;

static int part_node(const sp_vtu_part *p, int j) { return p->node ? p->node[j] : j; }
static int part_elem(const sp_vtu_part *p, int j) { return p->elem ? p->elem[j] : j; }

/** The cells' names in a .vtu's FieldData: the String array cell_name, one
 *  tuple per cell (tuple k - 1 names c_k and cell_id k), in VTK's ASCII
 *  form for strings (vtkXMLWriter's): each character as its code, each
 *  string ended by a 0. */
static void sp_vtu_names(FILE *f, int n_cells, const sp_cell_name *names) {
  fprintf(f, "      <DataArray type=\"String\" Name=\"cell_name\" NumberOfTuples=\"%d\" "
             "format=\"ascii\">",
          n_cells);
  for (int k = 0; k < n_cells; ++k) {
    for (const unsigned char *c = (const unsigned char *)names[k]; *c; ++c) fprintf(f, "%d ", *c);
    fprintf(f, k + 1 < n_cells ? "0 " : "0");
  }
  fprintf(f, "</DataArray>\n");
}

/** Write a .vtu to @p f (errors are left in ferror(f)); @p names (NULL:
 *  none) adds the cell_name array. */
static void sp_vtu_write(FILE *f, const sp_mesh *mesh, const sp_layout *l, const double *state,
                         int step, double t, const sp_cell_name *names, const sp_vtu_part *part) {
  const int nn = part->n_nodes, ne = part->n_elems;
  const uint16_t probe = 1;
  const int little = *(const unsigned char *)&probe == 1;
  sp_b64 b;

  fprintf(f, "<?xml version=\"1.0\"?>\n"
             "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
             "byte_order=\"%s\" header_type=\"UInt64\">\n"
             "  <UnstructuredGrid>\n",
          little ? "LittleEndian" : "BigEndian");
  /* TIME and CYCLE let ParaView show the time of a lone .vtu as well. */
  fprintf(f, "    <FieldData>\n"
             "      <DataArray type=\"Float64\" Name=\"TIME\" "
             "NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n"
             "      <DataArray type=\"Int32\" Name=\"CYCLE\" "
             "NumberOfTuples=\"1\" format=\"ascii\">%d</DataArray>\n",
          t, step);
  if (names) sp_vtu_names(f, l->n_cells, names);
  fprintf(f, "    </FieldData>\n");
  fprintf(f, "    <Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\">\n", nn,
          ne);

  /* Point data: c_k, mu_k per cell (0 off the support), then cell_id
   * (and node_id, the global node number, in the pieces of MPI runs). */
  fprintf(f, "      <PointData Scalars=\"cell_id\">\n");
  for (int k = 0; k < l->n_cells; ++k)
    for (int field = 0; field < 2; ++field) {
      char name[32];
      snprintf(name, sizeof name, "%s_%d", field ? "mu" : "c", k + 1);
      sp_vtu_array_open(f, "Float64", name, 1);
      sp_b64_begin_array(&b, f, (uint64_t)nn * sizeof(double));
      for (int j = 0; j < nn; ++j) {
        int p = sp_layout_pair(l, k, part_node(part, j));
        double v = p >= 0 ? state[2 * p + field] : 0.0;
        sp_b64_put(&b, &v, sizeof v);
      }
      sp_b64_end(&b);
      sp_vtu_array_close(f);
    }
  sp_vtu_array_open(f, "Int32", "cell_id", 1);
  sp_b64_begin_array(&b, f, (uint64_t)nn * sizeof(int32_t));
  for (int j = 0; j < nn; ++j) {
    /* the k (1-based) of the largest c_k > 1/2, else 0 */
    int32_t id = sp_layout_node_cell(l, state, part_node(part, j)) + 1;
    sp_b64_put(&b, &id, sizeof id);
  }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  if (part->node) {
    sp_vtu_array_open(f, "Int32", "node_id", 1);
    sp_b64_begin_array(&b, f, (uint64_t)nn * sizeof(int32_t));
    for (int j = 0; j < nn; ++j) {
      int32_t id = part->node[j];
      sp_b64_put(&b, &id, sizeof id);
    }
    sp_b64_end(&b);
    sp_vtu_array_close(f);
  }
  fprintf(f, "      </PointData>\n");

  fprintf(f, "      <CellData Scalars=\"region\">\n");
  sp_vtu_array_open(f, "Int32", "region", 1);
  sp_b64_begin_array(&b, f, (uint64_t)ne * sizeof(int32_t));
  for (int j = 0; j < ne; ++j) {
    int32_t r = mesh->region ? mesh->region[part_elem(part, j)] : 0;
    sp_b64_put(&b, &r, sizeof r);
  }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  fprintf(f, "      </CellData>\n");

  /* Points: 3 components (ParaView wants 3D points; z = 0 in 2D). */
  const int dim = mesh->dim, nen = mesh->nodes_per_elem;
  fprintf(f, "      <Points>\n");
  sp_vtu_array_open(f, "Float64", "Points", 3);
  sp_b64_begin_array(&b, f, (uint64_t)nn * 3 * sizeof(double));
  for (int j = 0; j < nn; ++j) {
    const double *xi = mesh->xy + (size_t)dim * part_node(part, j);
    double x[3] = {xi[0], xi[1], dim == 3 ? xi[2] : 0.0};
    sp_b64_put(&b, x, sizeof x);
  }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  fprintf(f, "      </Points>\n");

  /* Cells: the elements' nodes as listed: q1.h's order is VTK's, for
   * VTK_QUAD (counterclockwise) and VTK_HEXAHEDRON (the bottom face
   * counterclockwise seen from the top face, then the top face). */
  fprintf(f, "      <Cells>\n");
  sp_vtu_array_open(f, "Int32", "connectivity", 1);
  sp_b64_begin_array(&b, f, (uint64_t)ne * nen * sizeof(int32_t));
  for (int j = 0; j < ne; ++j)
    for (int a = 0; a < nen; ++a) {
      const int node = sp_mesh_elem_nodes(mesh, part_elem(part, j))[a];
      int32_t n = part->local ? part->local[node] : node;
      sp_b64_put(&b, &n, sizeof n);
    }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  sp_vtu_array_open(f, "Int64", "offsets", 1);
  sp_b64_begin_array(&b, f, (uint64_t)ne * sizeof(int64_t));
  for (int e = 0; e < ne; ++e) {
    int64_t off = nen * ((int64_t)e + 1);
    sp_b64_put(&b, &off, sizeof off);
  }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  sp_vtu_array_open(f, "UInt8", "types", 1);
  sp_b64_begin_array(&b, f, (uint64_t)ne);
  const uint8_t vtk_type = dim == 3 ? SP_VTK_HEXAHEDRON : SP_VTK_QUAD;
  for (int e = 0; e < ne; ++e) {
    sp_b64_put(&b, &vtk_type, 1);
  }
  sp_b64_end(&b);
  sp_vtu_array_close(f);
  fprintf(f, "      </Cells>\n");

  fprintf(f, "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
}

/** Rewrite fields.pvd from the list of .vtu files written so far. */
static int sp_pvd_write(const struct sp_output_s *o) {
  sp_strbuf b = {0};
  sp_strbuf_add(&b, "<?xml version=\"1.0\"?>\n"
                    "<VTKFile type=\"Collection\" version=\"0.1\" "
                    "byte_order=\"LittleEndian\">\n  <Collection>\n");
  for (int i = 0; i < o->n_fields; ++i)
    sp_strbuf_add(&b, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" "
                      "file=\"fields_%06d.%s\"/>\n",
                  o->fields[i].t, o->fields[i].step, o->fields[i].pvtu ? "pvtu" : "vtu");
  sp_strbuf_add(&b, "  </Collection>\n</VTKFile>\n");
  int rc;
  char *path = sp_strfmt("%s/fields.pvd", o->dir);
  if (b.oom || !path)
    rc = sp_error_set(SP_ERR_MEMORY, "out of memory writing fields.pvd in "
                      "'%s'", o->dir);
  else
    rc = sp_write_file_atomic(path, b.s, b.len);
  free(path);
  free(b.s);
  return rc;
}

/** Record (step, t) and its kind; writing the same step again replaces it
 *  (a step redone after a failure must not be listed twice). */
static int sp_fields_record(struct sp_output_s *o, int step, double t, int pvtu) {
  const sp_output_field entry = {step, t, pvtu};
  for (int i = 0; i < o->n_fields; ++i)
    if (o->fields[i].step == step) {
      o->fields[i] = entry;
      return SP_OK;
    }
  if (o->n_fields == o->cap_fields) {
    int cap = o->cap_fields ? 2 * o->cap_fields : 16;
    sp_output_field *f = realloc(o->fields, (size_t)cap * sizeof *f);
    SP_CHECK(f, SP_ERR_MEMORY, "out of memory listing output files");
    o->fields = f;
    o->cap_fields = cap;
  }
  o->fields[o->n_fields++] = entry;
  return SP_OK;
}

int sp_output_fields(sp_output out, const sp_mesh *mesh,
                     const sp_layout *layout, const double *state, int step,
                     double t, const sp_cell_name *names) {
  SP_CHECK(mesh->n_nodes == layout->n_nodes, SP_ERR_INTERNAL,
           "output: mesh has %d nodes but layout has %d", mesh->n_nodes,
           layout->n_nodes);
  SP_CHECK(step >= 0, SP_ERR_INTERNAL, "output: negative step %d", step);
  char *path = sp_strfmt("%s/fields_%06d.vtu", out->dir, step);
  SP_CHECK(path, SP_ERR_MEMORY, "out of memory naming a .vtu in '%s'",
           out->dir);
  char *tmp;
  FILE *f;
  int rc = sp_tmp_open(path, &tmp, &f);
  if (rc == SP_OK) {
    const sp_vtu_part all = {mesh->n_nodes, mesh->n_elems, NULL, NULL, NULL};
    sp_vtu_write(f, mesh, layout, state, step, t, names, &all);
    rc = sp_tmp_commit(path, tmp, f);
  }
  free(path);
  SP_CALL(rc);
  SP_CALL(sp_fields_record(out, step, t, 0));
  return sp_pvd_write(out);
}

int sp_output_fields_piece(const char *dir, const sp_mesh *mesh, const sp_layout *layout,
                           const double *state, int step, double t, const sp_cell_name *names,
                           int rank, int first_node, int end_node) {
  SP_CHECK(mesh->n_nodes == layout->n_nodes && first_node >= 0 && first_node <= end_node &&
           end_node <= mesh->n_nodes && step >= 0 && rank >= 0, SP_ERR_INTERNAL,
           "output piece: nodes %d..%d of %d (layout %d), step %d, rank %d", first_node,
           end_node, mesh->n_nodes, layout->n_nodes, step, rank);
  const size_t nn = (size_t)mesh->n_nodes, ne = (size_t)mesh->n_elems;
  int *block; /* elements of the piece, its nodes, global -> point */
  SP_ALLOC(block, ne + 2 * nn);
  int *elems = block, *nodes = block + ne, *local = block + ne + nn;
  int n_elems = 0, n_nodes = 0;
  for (size_t i = 0; i < nn; ++i) local[i] = -1;
  const int nen = mesh->nodes_per_elem;
  for (size_t e = 0; e < ne; ++e) {
    const int *en = sp_mesh_elem_nodes(mesh, e);
    if (en[0] < first_node || en[0] >= end_node) continue; /* the solver's rule */
    elems[n_elems++] = (int)e;
    for (int a = 0; a < nen; ++a) local[en[a]] = 0;
  }
  for (size_t i = 0; i < nn; ++i)
    if (local[i] == 0) {
      local[i] = n_nodes;
      nodes[n_nodes++] = (int)i;
    }
  const sp_vtu_part part = {n_nodes, n_elems, nodes, elems, local};
  char *path = sp_strfmt("%s/fields_%06d_p%d.vtu", dir, step, rank);
  char *tmp = NULL;
  FILE *f = NULL;
  int rc = path ? sp_tmp_open(path, &tmp, &f)
                : sp_error_set(SP_ERR_MEMORY, "out of memory naming a .vtu in '%s'", dir);
  if (rc == SP_OK) {
    sp_vtu_write(f, mesh, layout, state, step, t, names, &part);
    rc = sp_tmp_commit(path, tmp, f);
  }
  free(path);
  free(block);
  return rc;
}

int sp_output_fields_pvtu(sp_output out, const sp_layout *layout, int step, double t,
                          int n_ranks) {
  SP_CHECK(step >= 0 && n_ranks >= 1, SP_ERR_INTERNAL, "output: step %d, %d ranks", step,
           n_ranks);
  sp_strbuf b = {0};
  sp_strbuf_add(&b, "<?xml version=\"1.0\"?>\n"
                    "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" "
                    "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
                    "  <PUnstructuredGrid GhostLevel=\"0\">\n"
                    "    <PPointData Scalars=\"cell_id\">\n");
  for (int k = 0; k < layout->n_cells; ++k)
    sp_strbuf_add(&b, "      <PDataArray type=\"Float64\" Name=\"c_%d\"/>\n"
                      "      <PDataArray type=\"Float64\" Name=\"mu_%d\"/>\n", k + 1, k + 1);
  sp_strbuf_add(&b, "      <PDataArray type=\"Int32\" Name=\"cell_id\"/>\n"
                    "      <PDataArray type=\"Int32\" Name=\"node_id\"/>\n"
                    "    </PPointData>\n"
                    "    <PCellData Scalars=\"region\">\n"
                    "      <PDataArray type=\"Int32\" Name=\"region\"/>\n"
                    "    </PCellData>\n"
                    "    <PPoints>\n"
                    "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
                    "    </PPoints>\n");
  for (int r = 0; r < n_ranks; ++r)
    sp_strbuf_add(&b, "    <Piece Source=\"fields_%06d_p%d.vtu\"/>\n", step, r);
  sp_strbuf_add(&b, "  </PUnstructuredGrid>\n</VTKFile>\n");
  char *path = sp_strfmt("%s/fields_%06d.pvtu", out->dir, step);
  int rc = b.oom || !path ? sp_error_set(SP_ERR_MEMORY, "out of memory writing a .pvtu in '%s'",
                                         out->dir)
                          : sp_write_file_atomic(path, b.s, b.len);
  free(path);
  free(b.s);
  SP_CALL(rc);
  SP_CALL(sp_fields_record(out, step, t, 1));
  return sp_pvd_write(out);
}

int sp_output_resume(const char *dir, int dim, int step, int flags, int n_fields,
                     const sp_output_field *fields, sp_output *out) {
  SP_CHECK(dim == 2 || dim == 3, SP_ERR_INTERNAL, "output: dimension %d", dim);
  SP_CALL(output_open(dir, dim, flags, step, out));
  for (int i = 0; i < n_fields; ++i)
    if (fields[i].step <= step) {
      int rc = sp_fields_record(*out, fields[i].step, fields[i].t, fields[i].pvtu);
      if (rc != SP_OK) {
        sp_output_close(out);
        return rc;
      }
    }
  return (*out)->n_fields ? sp_pvd_write(*out) : SP_OK;
}
