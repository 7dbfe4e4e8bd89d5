#include "run/checkpoint.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <hdf5_hl.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/agree.h"
#include "run/build_info.h"
#include "public/error.h"
#include "run/resize.h"
#include "run/solver_status.h"

#define SP_CHECKPOINT_FORMAT "softpack checkpoint"

unsigned long long sp_fnv1a(unsigned long long h, const void *data, size_t len) {
  const unsigned char *p = data;
  for (size_t i = 0; i < len; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

/* ------------------------------------------------------------------------ */
/* Plain-data members saved one attribute each                              */
/* ------------------------------------------------------------------------ */

typedef struct {
  const char *name;
  size_t offset;
  char type; /* 'i' int, 'l' long, 'd' double */
} sp_member;

#define MEMBER(strct, m, ty) {#m, offsetof(strct, m), ty}

/** The controller's state (its parameters p come from the scene; event_dt,
 *  newer than the format, is an attribute of its own: controller_extra). */
static const sp_member controller_members[] = {
    MEMBER(sp_dt_control, dt_next, 'd'),       MEMBER(sp_dt_control, failures, 'i'),
    MEMBER(sp_dt_control, successes, 'i'),     MEMBER(sp_dt_control, ceiling, 'd'),
    MEMBER(sp_dt_control, ceiling_steps, 'i'), MEMBER(sp_dt_control, since_restart, 'i'),
    MEMBER(sp_dt_control, err_prev, 'd'),      MEMBER(sp_dt_control, dt_last, 'd'),
    MEMBER(sp_dt_control, rejected_last, 'i'), MEMBER(sp_dt_control, n_accepted, 'l'),
    MEMBER(sp_dt_control, n_rejected, 'l'),    MEMBER(sp_dt_control, n_newton_failed, 'l')};

static const sp_member summary_members[] = {
    MEMBER(sp_run_summary, steps, 'i'),
    MEMBER(sp_run_summary, failed_attempts, 'i'),
    MEMBER(sp_run_summary, newton_its, 'l'),
    MEMBER(sp_run_summary, factorisations, 'l'),
    MEMBER(sp_run_summary, failed_factorisations, 'l'),
    MEMBER(sp_run_summary, linear_its, 'l'),
    MEMBER(sp_run_summary, t_final, 'd'),
    MEMBER(sp_run_summary, dt_smallest, 'd'),
    MEMBER(sp_run_summary, wall_seconds, 'd'),
    MEMBER(sp_run_summary, t_assembly, 'd'),
    MEMBER(sp_run_summary, t_factor, 'd'),
    MEMBER(sp_run_summary, t_solve, 'd'),
    MEMBER(sp_run_summary, divisions, 'i'),
    MEMBER(sp_run_summary, n_cells, 'i'),
    MEMBER(sp_run_summary, layout_changes, 'i'),
    MEMBER(sp_run_summary, support_mass_correction, 'd'),
    MEMBER(sp_run_summary, t_layout, 'd'),
    MEMBER(sp_run_summary, support_mass_dropped, 'd'),
    MEMBER(sp_run_summary, support_energy_rise, 'd'),
    MEMBER(sp_run_summary, unknowns_max, 'l'),
    MEMBER(sp_run_summary, checkpoints, 'i'),
    MEMBER(sp_run_summary, t_checkpoints, 'd')};

#define N_OF(a) (sizeof(a) / sizeof((a)[0]))

/** The checksum of the members' values, in table order. */
static void members_hash(const void *base, const sp_member *m, size_t n, char out[32]) {
  unsigned long long h = SP_FNV_OFFSET;
  for (size_t i = 0; i < n; ++i) {
    const size_t size = m[i].type == 'i' ? sizeof(int) : m[i].type == 'l' ? sizeof(long)
                                                                           : sizeof(double);
    h = sp_fnv1a(h, (const char *)base + m[i].offset, size);
  }
  snprintf(out, 32, "%016llx", h);
}

static int put_members(hid_t file, const char *group, const void *base, const sp_member *m,
                       size_t n) {
  char hash[32];
  members_hash(base, m, n, hash);
  herr_t bad = H5LTset_attribute_string(file, group, "fnv1a", hash);
  for (size_t i = 0; i < n; ++i) {
    const char *p = (const char *)base + m[i].offset;
    if (m[i].type == 'i') bad |= H5LTset_attribute_int(file, group, m[i].name, (const int *)p, 1);
    else if (m[i].type == 'l')
      bad |= H5LTset_attribute_long(file, group, m[i].name, (const long *)p, 1);
    else bad |= H5LTset_attribute_double(file, group, m[i].name, (const double *)p, 1);
  }
  return bad < 0;
}

static int get_members(hid_t file, const char *path, const char *group, void *base,
                       const sp_member *m, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    char *p = (char *)base + m[i].offset;
    herr_t rc;
    if (m[i].type == 'i') rc = H5LTget_attribute_int(file, group, m[i].name, (int *)p);
    else if (m[i].type == 'l') rc = H5LTget_attribute_long(file, group, m[i].name, (long *)p);
    else rc = H5LTget_attribute_double(file, group, m[i].name, (double *)p);
    if (rc < 0)
      return sp_error_set(SP_ERR_INPUT, "checkpoint '%s': %s: no attribute %s (damaged?)", path,
                          group, m[i].name);
  }
  char want[32], got[32] = "";
  members_hash(base, m, n, want);
  hsize_t dims[1];
  H5T_class_t cls;
  size_t size;
  if (H5LTget_attribute_info(file, group, "fnv1a", dims, &cls, &size) < 0 || size >= 32 ||
      H5LTget_attribute_string(file, group, "fnv1a", got) < 0 || strcmp(got, want) != 0)
    return sp_error_set(SP_ERR_INPUT, "checkpoint '%s': %s does not match its checksum "
                                      "(damaged)", path, group);
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* Writing                                                                  */
/* ------------------------------------------------------------------------ */

/** The FNV-1a 64 of @p bytes bytes as 16 hex digits. */
static void hex_hash(const void *data, size_t bytes, char out[32]) {
  snprintf(out, 32, "%016llx", sp_fnv1a(SP_FNV_OFFSET, data, bytes));
}

/** A 1-d dataset of @p n values of @p type (nothing for n = 0: read as
 *  empty) with the checksum of its bytes (attribute fnv1a). */
static int put_array(hid_t file, const char *name, hid_t type, const void *data, size_t n) {
  if (n == 0) return 0;
  const hsize_t dims[1] = {n};
  char hash[32];
  hex_hash(data, n * H5Tget_size(type), hash);
  return H5LTmake_dataset(file, name, 1, dims, type, data) < 0 ||
         H5LTset_attribute_string(file, name, "fnv1a", hash) < 0;
}

static int make_group(hid_t file, const char *name) {
  hid_t g = H5Gcreate2(file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (g < 0) return 1;
  H5Gclose(g);
  return 0;
}

/** The scene's overrides joined by newlines (malloc'd). */
static char *join_overrides(int n_set, const char *const *set) {
  size_t len = 1;
  for (int i = 0; i < n_set; ++i) len += strlen(set[i]) + 1;
  char *s = malloc(len);
  if (!s) return NULL;
  s[0] = '\0';
  for (int i = 0; i < n_set; ++i) {
    strcat(s, set[i]);
    strcat(s, "\n");
  }
  return s;
}

static unsigned long long scene_hash(const char *text, size_t len, const char *overrides) {
  return sp_fnv1a(sp_fnv1a(SP_FNV_OFFSET, text, len), overrides, strlen(overrides));
}

/** The checksum of the node coordinates (dim per node: a 2D mesh's as
 *  before 3D meshes existed). */
static unsigned long long mesh_hash(const sp_mesh *mesh) {
  return sp_fnv1a(SP_FNV_OFFSET, mesh->xy,
                  (size_t)mesh->dim * (size_t)mesh->n_nodes * sizeof(double));
}

/** The run's scalars, checksummed like every array: /header (ints) and
 *  /header_t (doubles), in this order. */
enum { H_STEP, H_N_MAX, H_MPI_SIZE, H_N_CELLS, H_HIST_N, H_N_ENERGY, H_N_DIVISIONS, H_N_FIELDS,
       HEADER_INTS };
enum { H_T, H_DT0, H_DT1, HEADER_DOUBLES };

/** sp_shape_coef as doubles in /carry/shape, the members a mesh of
 *  dimension @p dim uses in this order: xc, yc (, zc), v[i][d], coef[i],
 *  gain[i][j] (i, j, d < dim), threshold; 13 in 2D (the order of the 2D
 *  struct the first files were written from), 25 in 3D. With @p unpack
 *  the doubles are read back into @p s. */
static size_t shape_doubles(int dim, sp_shape_coef *s, double *d, int unpack) {
  double *m[32];
  size_t n = 0;
  m[n++] = &s->xc;
  m[n++] = &s->yc;
  if (dim == 3) m[n++] = &s->zc;
  for (int i = 0; i < dim; ++i)
    for (int e = 0; e < dim; ++e) m[n++] = &s->v[i][e];
  for (int i = 0; i < dim; ++i) m[n++] = &s->coef[i];
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j) m[n++] = &s->gain[i][j];
  m[n++] = &s->threshold;
  for (size_t i = 0; d && i < n; ++i) {
    if (unpack) *m[i] = d[i];
    else d[i] = *m[i];
  }
  return n;
}

/** /carry: where the factorisation the next step begins on was filled. */
static int put_carry(hid_t f, const sp_run *run) {
  int carry = 0, n_shape = 0, shape_implicit = 0;
  double dt = 0;
  const double *x = NULL;
  const sp_shape_coef *shape = NULL;
  if (run->solver && sp_solver_carry_point(run->solver, &carry, &dt, &x, &shape, &n_shape,
                                           &shape_implicit) != SP_SOLVER_OK)
    return 1;
  const int header[3] = {carry, carry ? n_shape : 0, shape_implicit};
  int bad = make_group(f, "/carry");
  bad |= put_array(f, "/carry/header", H5T_NATIVE_INT, header, 3);
  if (!carry) return bad;
  bad |= put_array(f, "/carry/dt", H5T_NATIVE_DOUBLE, &dt, 1);
  bad |= put_array(f, "/carry/x", H5T_NATIVE_DOUBLE, x, 2 * (size_t)run->layout->n_pairs);
  if (n_shape > 0) {
    const int dim = run->mesh->dim;
    const size_t per = shape_doubles(dim, &(sp_shape_coef){0}, NULL, 0);
    double *packed = malloc(sizeof(double) * per * (size_t)n_shape);
    if (!packed) return 1;
    for (int k = 0; k < n_shape; ++k) {
      sp_shape_coef s = shape[k];
      shape_doubles(dim, &s, packed + per * k, 0);
    }
    bad |= put_array(f, "/carry/shape", H5T_NATIVE_DOUBLE, packed, per * (size_t)n_shape);
    free(packed);
  }
  return bad;
}

/** Write the whole state into the open file @p f; nonzero on an HDF5 error. */
static int write_state(hid_t f, const sp_run *run) {
  const sp_layout *ly = run->layout;
  const size_t n_pairs = (size_t)ly->n_pairs, nc = (size_t)ly->n_cells;
  int bad = 0;
  char *overrides = join_overrides(run->scene_text.n_set, run->scene_text.set);
  if (!overrides) return 1;
  char *text = malloc(run->scene_text.len + 1);
  if (!text) {
    free(overrides);
    return 1;
  }
  if (run->scene_text.len) memcpy(text, run->scene_text.text, run->scene_text.len);
  text[run->scene_text.len] = '\0';
  char hash[32];
  snprintf(hash, sizeof hash, "%016llx", scene_hash(text, run->scene_text.len, overrides));
  const int version = SP_CHECKPOINT_VERSION;
  const unsigned long long mh = mesh_hash(run->mesh);
  char mesh_h[32];
  snprintf(mesh_h, sizeof mesh_h, "%016llx", mh);
  bad |= H5LTset_attribute_string(f, "/", "format", SP_CHECKPOINT_FORMAT) < 0;
  bad |= H5LTset_attribute_int(f, "/", "format_version", &version, 1) < 0;
  bad |= H5LTset_attribute_string(f, "/", "softpack_version", sp_version()) < 0;
  bad |= H5LTset_attribute_int(f, "/", "mpi_size", &run->n_ranks, 1) < 0;
  bad |= H5LTset_attribute_int(f, "/", "step", &run->step, 1) < 0;
  bad |= H5LTset_attribute_double(f, "/", "t", &run->t, 1) < 0;
  bad |= H5LTset_attribute_int(f, "/", "n_max", &run->n_max, 1) < 0;
  bad |= H5LTset_attribute_string(f, "/", "scene_hash", hash) < 0;
  bad |= H5LTset_attribute_string(f, "/", "mesh_hash", mesh_h) < 0;
  bad |= H5LTmake_dataset_string(f, "/scene_text", text) < 0;
  bad |= H5LTmake_dataset_string(f, "/scene_overrides", overrides) < 0;
  free(text);
  free(overrides);
  for (const char *g = "/layout\0/history\0/cells\0/controller\0/summary\0/output\0"; *g;
       g += strlen(g) + 1)
    bad |= make_group(f, g);
  const int n_fields_now =
      run->mon.output
          ? sp_output_fields_list(run->mon.output, &(const sp_output_field *){NULL})
          : 0;
  const int header[HEADER_INTS] = {run->step,         run->n_max,          run->n_ranks,
                                   ly->n_cells,       run->hist.n,         run->mon.n_energy,
                                   run->mon.n_divisions, n_fields_now};
  const double header_t[HEADER_DOUBLES] = {run->t, run->hist.dt[0], run->hist.dt[1]};
  bad |= put_array(f, "/header", H5T_NATIVE_INT, header, HEADER_INTS);
  bad |= put_array(f, "/header_t", H5T_NATIVE_DOUBLE, header_t, HEADER_DOUBLES);
  bad |= put_array(f, "/layout/node_start", H5T_NATIVE_INT, ly->node_start,
                   (size_t)ly->n_nodes + 1);
  bad |= put_array(f, "/layout/pair_cell", H5T_NATIVE_INT, ly->pair_cell, n_pairs);
  bad |= put_array(f, "/state", H5T_NATIVE_DOUBLE, run->state, 2 * n_pairs);
  const sp_history *h = &run->hist;
  if (h->n >= 1) bad |= put_array(f, "/history/past0", H5T_NATIVE_DOUBLE, h->past[0], 2 * n_pairs);
  if (h->n >= 2) bad |= put_array(f, "/history/past1", H5T_NATIVE_DOUBLE, h->past[1], 2 * n_pairs);
  double *col = malloc(sizeof(double) * (2 * nc + 1));
  int *icol = malloc(sizeof(int) * (nc + 1));
  if (!col || !icol) bad = 1;
  else {
    for (size_t k = 0; k < nc; ++k) col[k] = run->cells.birth[k].birth_time;
    bad |= put_array(f, "/cells/birth_time", H5T_NATIVE_DOUBLE, col, nc);
    for (size_t k = 0; k < nc; ++k) col[k] = run->cells.birth[k].birth_mass;
    bad |= put_array(f, "/cells/birth_mass", H5T_NATIVE_DOUBLE, col, nc);
    for (size_t k = 0; k < nc; ++k) {
      col[2 * k] = run->cells.birth[k].Iref[0];
      col[2 * k + 1] = run->cells.birth[k].Iref[1];
    }
    bad |= put_array(f, "/cells/Iref", H5T_NATIVE_DOUBLE, col, 2 * nc);
    if (run->mesh->dim == 3) { /* the third moment's, apart: 2D files as before */
      for (size_t k = 0; k < nc; ++k) col[k] = run->cells.birth[k].Iref[2];
      bad |= put_array(f, "/cells/Iref3", H5T_NATIVE_DOUBLE, col, nc);
    }
    for (size_t k = 0; k < nc; ++k) icol[k] = run->cells.birth[k].generation;
    bad |= put_array(f, "/cells/generation", H5T_NATIVE_INT, icol, nc);
  }
  free(col);
  free(icol);
  bad |= put_array(f, "/cells/source_on", H5T_NATIVE_INT, run->cells.source_on, nc);
  bad |= put_array(f, "/cells/division_skipped", H5T_NATIVE_INT, run->cells.division_skipped, nc);
  bad |= put_array(f, "/cells/divided_now", H5T_NATIVE_UCHAR, run->cells.divided_now, nc);
  bad |= put_array(f, "/cells/name", H5T_NATIVE_CHAR, run->cells.name, nc * SP_CELL_NAME_MAX);
  bad |= put_array(f, "/cells/cut_normal", H5T_NATIVE_DOUBLE, run->cells.cut_normal, 3 * nc);
  bad |= put_array(f, "/cells/sister", H5T_NATIVE_INT, run->cells.sister, nc);
  bad |= put_members(f, "/controller", &run->dtc, controller_members, N_OF(controller_members));
  bad |= H5LTset_attribute_double(f, "/controller", "event_dt", &run->dtc.event_dt, 1) < 0;
  bad |= put_members(f, "/summary", run->mon.sum, summary_members, N_OF(summary_members));
  bad |= put_array(f, "/output/energy_t", H5T_NATIVE_DOUBLE, run->mon.energy_t,
                   run->mon.n_energy);
  bad |= put_array(f, "/output/energy_total", H5T_NATIVE_DOUBLE, run->mon.energy_total,
                   run->mon.n_energy);
  bad |= put_array(f, "/output/division_t", H5T_NATIVE_DOUBLE, run->mon.division_t,
                   run->mon.n_divisions);
  bad |= put_carry(f, run);
  const sp_output_field *fields = NULL;
  const int n_fields = run->mon.output ? sp_output_fields_list(run->mon.output, &fields) : 0;
  if (n_fields > 0) {
    int *steps = malloc(sizeof(int) * n_fields), *pvtu = malloc(sizeof(int) * n_fields);
    double *ts = malloc(sizeof(double) * n_fields);
    if (!steps || !pvtu || !ts) bad = 1;
    else {
      for (int i = 0; i < n_fields; ++i) {
        steps[i] = fields[i].step;
        ts[i] = fields[i].t;
        pvtu[i] = fields[i].pvtu;
      }
      bad |= put_array(f, "/output/field_step", H5T_NATIVE_INT, steps, n_fields);
      bad |= put_array(f, "/output/field_t", H5T_NATIVE_DOUBLE, ts, n_fields);
      bad |= put_array(f, "/output/field_pvtu", H5T_NATIVE_INT, pvtu, n_fields);
    }
    free(steps);
    free(pvtu);
    free(ts);
  }
  return bad;
}

/** The step of a file named checkpoint_<digits>.h5, or -1. */
static long checkpoint_step_of(const char *name) {
  if (strncmp(name, "checkpoint_", 11) != 0) return -1;
  char *end;
  const long step = strtol(name + 11, &end, 10);
  if (end == name + 11 || strcmp(end, ".h5") != 0 || step < 0) return -1;
  return step;
}

/** The checkpoints in @p dir, newest first (malloc'd steps; count). */
static int list_checkpoints(const char *dir, long **steps) {
  *steps = NULL;
  DIR *d = opendir(dir);
  if (!d) return 0;
  int n = 0, cap = 0;
  for (struct dirent *e; (e = readdir(d));) {
    const long s = checkpoint_step_of(e->d_name);
    if (s < 0) continue;
    if (n == cap) {
      cap = cap ? 2 * cap : 16;
      long *grown = realloc(*steps, sizeof(long) * cap);
      if (!grown) break;
      *steps = grown;
    }
    (*steps)[n++] = s;
  }
  closedir(d);
  for (int i = 1; i < n; ++i) /* insertion sort, newest first */
    for (int j = i; j > 0 && (*steps)[j] > (*steps)[j - 1]; --j) {
      const long x = (*steps)[j];
      (*steps)[j] = (*steps)[j - 1];
      (*steps)[j - 1] = x;
    }
  return n;
}

static void checkpoint_path(const char *dir, long step, char *path, size_t size) {
  snprintf(path, size, "%s/checkpoint_%06ld.h5", dir, step);
}

/** fsync a file or directory by path (best effort: durability, not correctness). */
static void sync_path(const char *path) {
  const int fd = open(path, O_RDONLY);
  if (fd >= 0) {
    fsync(fd);
    close(fd);
  }
}

int sp_checkpoint_write(const sp_run *run, const char *dir, char *path_out, size_t size) {
  char path[4096], tmp[4200];
  checkpoint_path(dir, run->step, path, sizeof path);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  const hid_t f = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) return sp_error_set(SP_ERR_IO, "cannot create checkpoint '%s'", tmp);
  const int bad = write_state(f, run);
  const int bad_close = H5Fclose(f) < 0;
  if (bad || bad_close) {
    remove(tmp);
    return sp_error_set(SP_ERR_IO, "cannot write checkpoint '%s' (disk full?)", tmp);
  }
  sync_path(tmp);
  if (rename(tmp, path) != 0) {
    const int err = errno;
    remove(tmp);
    return sp_error_set(SP_ERR_IO, "cannot rename '%s' to '%s': %s", tmp, path, strerror(err));
  }
  sync_path(dir);
  if (path_out) snprintf(path_out, size, "%s", path);
  long *steps;
  const int n = list_checkpoints(dir, &steps);
  for (int i = run->opt.output.checkpoint_keep; i < n; ++i) {
    char old[4096];
    checkpoint_path(dir, steps[i], old, sizeof old);
    remove(old);
  }
  free(steps);
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* Reading                                                                  */
/* ------------------------------------------------------------------------ */

struct sp_checkpoint_s {
  hid_t file;
  char *path;
  char *scene_text;
  size_t scene_len;
  char *overrides; /* the overrides' text, cut into set[] */
  const char **set;
  int n_set;
  int step, mpi_size;
  int version; /* the file's format version (1: no names, no cut normals) */
  double t;
  int header[HEADER_INTS];
  double header_t[HEADER_DOUBLES];
};

static int get_array(const sp_checkpoint ck, const char *name, hid_t type, void *buf, size_t n);

/** A string attribute of "/" (malloc'd), or NULL. */
static char *root_string(hid_t f, const char *name) {
  hsize_t dims[1];
  H5T_class_t cls;
  size_t size;
  if (H5Aexists(f, name) <= 0 ||
      H5LTget_attribute_info(f, "/", name, dims, &cls, &size) < 0 || cls != H5T_STRING)
    return NULL;
  char *s = calloc(size + 1, 1);
  if (s && H5LTget_attribute_string(f, "/", name, s) < 0) {
    free(s);
    return NULL;
  }
  return s;
}

/** A string dataset (malloc'd), or NULL. */
static char *string_dataset(hid_t f, const char *name, size_t *len) {
  hsize_t dims[1];
  H5T_class_t cls;
  size_t size;
  if (H5LTpath_valid(f, name, 1) <= 0 || H5LTget_dataset_info(f, name, dims, &cls, &size) < 0 ||
      cls != H5T_STRING)
    return NULL;
  char *s = calloc(size + 1, 1);
  if (s && H5LTread_dataset_string(f, name, s) < 0) {
    free(s);
    return NULL;
  }
  if (len) *len = strlen(s);
  return s;
}

void sp_checkpoint_close(sp_checkpoint *ck) {
  if (!ck || !*ck) return;
  if ((*ck)->file >= 0) H5Fclose((*ck)->file);
  free((*ck)->path);
  free((*ck)->scene_text);
  free((*ck)->overrides);
  free((*ck)->set);
  free(*ck);
  *ck = NULL;
}

int sp_checkpoint_open(const char *path, sp_checkpoint *out) {
  *out = NULL;
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  SP_CHECK(access(path, R_OK) == 0, SP_ERR_INPUT, "checkpoint '%s': cannot read it: %s", path,
           strerror(errno));
  SP_CHECK(H5Fis_hdf5(path) > 0, SP_ERR_INPUT,
           "checkpoint '%s': not an HDF5 file, or truncated or damaged", path);
  struct sp_checkpoint_s *ck;
  SP_ALLOC(ck, 1);
  ck->file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
  ck->path = strdup(path);
  *out = ck;
  int rc = SP_OK;
  char *format = ck->file >= 0 ? root_string(ck->file, "format") : NULL;
  int version = -1;
  if (ck->file < 0)
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': HDF5 cannot open it (truncated or "
                                    "damaged)", path);
  else if (!format || strcmp(format, SP_CHECKPOINT_FORMAT) != 0)
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': not a softpack checkpoint (its format "
                                    "attribute is %s%s%s)", path, format ? "'" : "missing",
                      format ? format : "", format ? "'" : "");
  else if (H5LTget_attribute_int(ck->file, "/", "format_version", &version) < 0 ||
           version < SP_CHECKPOINT_VERSION_OLDEST || version > SP_CHECKPOINT_VERSION)
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': format version %d, this softpack (%s) "
                                    "reads versions %d to %d", path, version, sp_version(),
                      SP_CHECKPOINT_VERSION_OLDEST, SP_CHECKPOINT_VERSION);
  ck->version = version;
  free(format);
  if (rc == SP_OK) rc = get_array(ck, "/header", H5T_NATIVE_INT, ck->header, HEADER_INTS);
  if (rc == SP_OK) rc = get_array(ck, "/header_t", H5T_NATIVE_DOUBLE, ck->header_t, HEADER_DOUBLES);
  if (rc == SP_OK) {
    ck->step = ck->header[H_STEP];
    ck->mpi_size = ck->header[H_MPI_SIZE];
    ck->t = ck->header_t[H_T];
    if (!(ck->scene_text = string_dataset(ck->file, "/scene_text", &ck->scene_len)) ||
        !(ck->overrides = string_dataset(ck->file, "/scene_overrides", NULL)))
      rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': damaged (its scene is missing)", path);
  }
  if (rc == SP_OK) { /* check the scene against its hash */
    char *hash = root_string(ck->file, "scene_hash");
    char want[32];
    snprintf(want, sizeof want, "%016llx",
             scene_hash(ck->scene_text, ck->scene_len, ck->overrides));
    if (!hash || strcmp(hash, want) != 0)
      rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': damaged (its scene does not match its "
                                      "hash)", path);
    free(hash);
  }
  if (rc == SP_OK) { /* cut the overrides into lines */
    int n = 0;
    for (const char *p = ck->overrides; *p; ++p) n += *p == '\n';
    ck->set = calloc((size_t)n + 1, sizeof(char *));
    if (!ck->set) rc = sp_error_set(SP_ERR_MEMORY, "out of memory");
    for (char *p = ck->overrides; rc == SP_OK && *p;) {
      char *nl = strchr(p, '\n');
      ck->set[ck->n_set++] = p;
      if (!nl) break;
      *nl = '\0';
      p = nl + 1;
    }
  }
  if (rc != SP_OK) sp_checkpoint_close(out);
  return rc;
}

void sp_checkpoint_remove_after(const char *dir, int step) {
  DIR *d = opendir(dir); /* and the temporaries of writes a kill cut short */
  for (struct dirent *e; d && (e = readdir(d));) {
    const size_t len = strlen(e->d_name);
    if (strncmp(e->d_name, "checkpoint_", 11) == 0 && len > 7 &&
        strcmp(e->d_name + len - 7, ".h5.tmp") == 0) {
      char tmp[4096];
      snprintf(tmp, sizeof tmp, "%s/%s", dir, e->d_name);
      remove(tmp);
    }
  }
  if (d) closedir(d);
  long *steps;
  const int n = list_checkpoints(dir, &steps);
  for (int i = 0; i < n; ++i)
    if (steps[i] > step) {
      char old[4096];
      checkpoint_path(dir, steps[i], old, sizeof old);
      remove(old);
    }
  free(steps);
}

int sp_checkpoint_find_newest(const char *dir, char *path, size_t size) {
  long *steps;
  const int n = list_checkpoints(dir, &steps);
  for (int i = 0; i < n; ++i) {
    checkpoint_path(dir, steps[i], path, size);
    sp_checkpoint ck;
    if (sp_checkpoint_open(path, &ck) == SP_OK) {
      sp_checkpoint_close(&ck);
      free(steps);
      return SP_OK;
    }
    fprintf(stderr, "softpack: skipping %s: %s\n", path, sp_error_message());
  }
  free(steps);
  return sp_error_set(SP_ERR_INPUT, "--resume %s: no valid checkpoint there (checkpoint_*.h5)",
                      dir);
}

const char *sp_checkpoint_scene(const sp_checkpoint ck, size_t *len, int *n_set,
                                const char *const **set) {
  *len = ck->scene_len;
  *n_set = ck->n_set;
  *set = ck->set;
  return ck->scene_text;
}
int sp_checkpoint_step(const sp_checkpoint ck) { return ck->step; }
double sp_checkpoint_time(const sp_checkpoint ck) { return ck->t; }
int sp_checkpoint_mpi_size(const sp_checkpoint ck) { return ck->mpi_size; }
void sp_checkpoint_cells(const sp_checkpoint ck, int *n_cells, int *n_max) {
  *n_cells = ck->header[H_N_CELLS];
  *n_max = ck->header[H_N_MAX];
}

/** Read the 1-d dataset @p name of exactly @p n values of @p type into
 *  @p buf (n = 0: nothing to read). */
static int get_array(const sp_checkpoint ck, const char *name, hid_t type, void *buf, size_t n) {
  if (n == 0) return SP_OK;
  hsize_t dims[1] = {0};
  int rank = 0;
  H5T_class_t cls;
  size_t size;
  if (H5LTpath_valid(ck->file, name, 1) <= 0 || H5LTget_dataset_ndims(ck->file, name, &rank) < 0 ||
      rank != 1 || H5LTget_dataset_info(ck->file, name, dims, &cls, &size) < 0 || dims[0] != n ||
      H5LTread_dataset(ck->file, name, type, buf) < 0)
    return sp_error_set(SP_ERR_INPUT, "checkpoint '%s': %s is missing or has %llu values, "
                                      "expected %zu (damaged)", ck->path, name,
                        (unsigned long long)dims[0], n);
  char want[32], got[32] = "";
  hex_hash(buf, n * H5Tget_size(type), want);
  if (H5LTget_attribute_info(ck->file, name, "fnv1a", dims, &cls, &size) < 0 || size >= 32 ||
      H5LTget_attribute_string(ck->file, name, "fnv1a", got) < 0 || strcmp(got, want) != 0)
    return sp_error_set(SP_ERR_INPUT, "checkpoint '%s': %s does not match its checksum "
                                      "(damaged)", ck->path, name);
  return SP_OK;
}


/** The layout and state of the checkpoint (checked against the mesh). */
static int read_layout(const sp_checkpoint ck, const sp_mesh *mesh, sp_layout **layout,
                       double **state) {
  const int nc = ck->header[H_N_CELLS];
  const int nn = mesh->n_nodes;
  char *hash = root_string(ck->file, "mesh_hash");
  char want[32];
  snprintf(want, sizeof want, "%016llx", mesh_hash(mesh));
  const int same_mesh = hash && strcmp(hash, want) == 0;
  free(hash);
  SP_CHECK(same_mesh, SP_ERR_INPUT, "checkpoint '%s': its mesh is not this scene's mesh",
           ck->path);
  SP_CHECK(nc >= 1 && (size_t)nc * (size_t)nn <= (size_t)SP_LAYOUT_MAX_PAIRS * 8, SP_ERR_INPUT,
           "checkpoint '%s': %d cells (damaged)", ck->path, nc);
  int *node_start = malloc(sizeof(int) * ((size_t)nn + 1));
  SP_CHECK(node_start, SP_ERR_MEMORY, "out of memory");
  int rc = get_array(ck, "/layout/node_start", H5T_NATIVE_INT, node_start, (size_t)nn + 1);
  int n_pairs = rc == SP_OK ? node_start[nn] : 0;
  if (rc == SP_OK && (node_start[0] != 0 || n_pairs < 0 || n_pairs > SP_LAYOUT_MAX_PAIRS))
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /layout/node_start is not a layout",
                      ck->path);
  int *pair_cell = rc == SP_OK ? malloc(sizeof(int) * ((size_t)n_pairs + 1)) : NULL;
  unsigned char *mask = rc == SP_OK ? calloc((size_t)nn * nc, 1) : NULL;
  if (rc == SP_OK && (!pair_cell || !mask)) rc = sp_error_set(SP_ERR_MEMORY, "out of memory");
  if (rc == SP_OK)
    rc = get_array(ck, "/layout/pair_cell", H5T_NATIVE_INT, pair_cell, (size_t)n_pairs);
  for (int i = 0; rc == SP_OK && i < nn; ++i)
    for (int p = node_start[i]; rc == SP_OK && p < node_start[i + 1]; ++p) {
      if (p < 0 || p >= n_pairs || pair_cell[p] < 0 || pair_cell[p] >= nc)
        rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /layout is not a layout", ck->path);
      else mask[(size_t)pair_cell[p] * nn + i] = 1;
    }
  *layout = NULL;
  if (rc == SP_OK) rc = sp_layout_create_from_masks(nn, nc, mask, layout);
  if (rc == SP_OK &&
      ((*layout)->n_pairs != n_pairs ||
       memcmp((*layout)->pair_cell, pair_cell, sizeof(int) * (size_t)n_pairs) != 0))
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /layout is not a layout", ck->path);
  *state = NULL;
  if (rc == SP_OK) {
    *state = malloc(sizeof(double) * 2 * (size_t)n_pairs + 1);
    rc = *state ? get_array(ck, "/state", H5T_NATIVE_DOUBLE, *state, 2 * (size_t)n_pairs)
                : sp_error_set(SP_ERR_MEMORY, "out of memory");
  }
  free(node_start);
  free(pair_cell);
  free(mask);
  if (rc != SP_OK) {
    sp_layout_destroy(layout);
    free(*state);
    *state = NULL;
  }
  return rc;
}

static int read_fields_list(const sp_checkpoint ck, sp_output_field **fields, int *n_fields) {
  const int n = ck->header[H_N_FIELDS];
  *fields = NULL;
  *n_fields = 0;
  SP_CHECK(n >= 0, SP_ERR_INPUT, "checkpoint '%s': /output damaged", ck->path);
  if (n == 0) return SP_OK;
  int *steps = malloc(sizeof(int) * n), *pvtu = malloc(sizeof(int) * n);
  double *ts = malloc(sizeof(double) * n);
  *fields = malloc(sizeof **fields * n);
  int rc = steps && pvtu && ts && *fields ? SP_OK : sp_error_set(SP_ERR_MEMORY, "out of memory");
  if (rc == SP_OK) rc = get_array(ck, "/output/field_step", H5T_NATIVE_INT, steps, n);
  if (rc == SP_OK) rc = get_array(ck, "/output/field_t", H5T_NATIVE_DOUBLE, ts, n);
  if (rc == SP_OK) rc = get_array(ck, "/output/field_pvtu", H5T_NATIVE_INT, pvtu, n);
  for (int i = 0; rc == SP_OK && i < n; ++i)
    (*fields)[i] = (sp_output_field){steps[i], ts[i], pvtu[i]};
  if (rc == SP_OK) *n_fields = n;
  else {
    free(*fields);
    *fields = NULL;
  }
  free(steps);
  free(pvtu);
  free(ts);
  return rc;
}

/** A double array of @p n values into *@p p (realloc'd; n = 0 is fine). */
static int read_doubles(const sp_checkpoint ck, const char *name, double **p, int n) {
  double *q = realloc(*p, sizeof(double) * (size_t)(n > 0 ? n : 1));
  SP_CHECK(q, SP_ERR_MEMORY, "out of memory");
  *p = q;
  return get_array(ck, name, H5T_NATIVE_DOUBLE, q, (size_t)n);
}

/** The time scheme's history (past states of @p n_values values). */
static int read_history(const sp_checkpoint ck, sp_history *h, size_t n_values) {
  h->n = ck->header[H_HIST_N];
  SP_CHECK(h->n >= 0 && h->n <= 2, SP_ERR_INPUT, "checkpoint '%s': /history damaged", ck->path);
  h->dt[0] = ck->header_t[H_DT0];
  h->dt[1] = ck->header_t[H_DT1];
  for (int i = 0; i < h->n; ++i) {
    h->past[i] = malloc(sizeof(double) * n_values + 1);
    SP_CHECK(h->past[i], SP_ERR_MEMORY, "out of memory for the history");
    SP_CALL(get_array(ck, i == 0 ? "/history/past0" : "/history/past1", H5T_NATIVE_DOUBLE,
                      h->past[i], n_values));
  }
  return SP_OK;
}

/** The registry of @p nc cells (sized and zeroed by the caller) on a mesh
 *  of dimension @p dim. */
static int read_registry(const sp_checkpoint ck, sp_registry *cells, int nc, int dim) {
  double *col = malloc(sizeof(double) * (2 * (size_t)nc + 1));
  int *icol = malloc(sizeof(int) * ((size_t)nc + 1));
  int rc = col && icol ? SP_OK : sp_error_set(SP_ERR_MEMORY, "out of memory");
  if (rc == SP_OK) rc = get_array(ck, "/cells/birth_time", H5T_NATIVE_DOUBLE, col, nc);
  for (int k = 0; rc == SP_OK && k < nc; ++k) cells->birth[k].birth_time = col[k];
  if (rc == SP_OK) rc = get_array(ck, "/cells/birth_mass", H5T_NATIVE_DOUBLE, col, nc);
  for (int k = 0; rc == SP_OK && k < nc; ++k) cells->birth[k].birth_mass = col[k];
  if (rc == SP_OK) rc = get_array(ck, "/cells/Iref", H5T_NATIVE_DOUBLE, col, 2 * (size_t)nc);
  for (int k = 0; rc == SP_OK && k < nc; ++k) {
    cells->birth[k].Iref[0] = col[2 * k];
    cells->birth[k].Iref[1] = col[2 * k + 1];
    /* 2D: no third moment; a 3D file without /cells/Iref3 was written
     * before the 3D shape term (its scene has none): unknown */
    cells->birth[k].Iref[2] = dim == 3 ? NAN : 0.0;
  }
  if (rc == SP_OK && dim == 3 && H5LTpath_valid(ck->file, "/cells/Iref3", 1) > 0) {
    rc = get_array(ck, "/cells/Iref3", H5T_NATIVE_DOUBLE, col, nc);
    for (int k = 0; rc == SP_OK && k < nc; ++k) cells->birth[k].Iref[2] = col[k];
  }
  if (rc == SP_OK) rc = get_array(ck, "/cells/generation", H5T_NATIVE_INT, icol, nc);
  for (int k = 0; rc == SP_OK && k < nc; ++k) cells->birth[k].generation = icol[k];
  free(col);
  free(icol);
  SP_CALL(rc);
  SP_CALL(get_array(ck, "/cells/source_on", H5T_NATIVE_INT, cells->source_on, nc));
  SP_CALL(get_array(ck, "/cells/division_skipped", H5T_NATIVE_INT, cells->division_skipped, nc));
  SP_CALL(get_array(ck, "/cells/divided_now", H5T_NATIVE_UCHAR, cells->divided_now, nc));
  if (ck->version < 2) { /* written before names and cut normals: none */
    memset(cells->name, 0, (size_t)nc * SP_CELL_NAME_MAX);
    memset(cells->cut_normal, 0, 3 * (size_t)nc * sizeof(double));
    return SP_OK;
  }
  SP_CALL(get_array(ck, "/cells/name", H5T_NATIVE_CHAR, cells->name,
                    (size_t)nc * SP_CELL_NAME_MAX));
  for (int k = 0; k < nc; ++k) cells->name[k][SP_CELL_NAME_MAX - 1] = '\0';
  SP_CALL(get_array(ck, "/cells/cut_normal", H5T_NATIVE_DOUBLE, cells->cut_normal,
                    3 * (size_t)nc));
  /* a file written before sisters were kept: none known */
  if (H5LTpath_valid(ck->file, "/cells/sister", 1) > 0)
    SP_CALL(get_array(ck, "/cells/sister", H5T_NATIVE_INT, cells->sister, nc));
  for (int k = 0; k < nc; ++k)
    if (cells->sister[k] < 0 || cells->sister[k] > nc) cells->sister[k] = 0;
  return SP_OK;
}

int sp_checkpoint_restore(const sp_checkpoint ck, sp_run *run, int as_initial,
                          sp_output_field **fields, int *n_fields) {
  *fields = NULL;
  *n_fields = 0;
  sp_layout *layout = NULL;
  double *state = NULL;
  SP_CALL(read_layout(ck, run->mesh, &layout, &state));
  /* the one layout change (resize.h): the registry sized, new entries
   * zeroed (all of them: emptied first), the history reset (read below),
   * the solver given the layout */
  const int rc_empty = sp_registry_resize(&run->cells, 0);
  if (rc_empty != SP_OK) {
    sp_layout_destroy(&layout);
    free(state);
    return rc_empty;
  }
  SP_CALL(sp_run_resize(run, layout, state, SP_HISTORY_RESET));
  const int nc = layout->n_cells;
  const size_t n_values = 2 * (size_t)layout->n_pairs;
  if (as_initial) return SP_OK; /* the caller makes the registry of a new run */
  SP_CALL(read_history(ck, &run->hist, n_values));
  SP_CALL(read_registry(ck, &run->cells, nc, run->mesh->dim));
  SP_CALL(sp_run_adhesion_update(run)); /* (the sisters read) */
  /* the controller, the counters, step and time */
  SP_CALL(get_members(ck->file, ck->path, "/controller", &run->dtc, controller_members,
                      N_OF(controller_members)));
  /* the step wanted before the last division: absent from a checkpoint
   * written before it existed (0: the regrowth after the next division
   * knows only its own steps) */
  run->dtc.event_dt = 0.0;
  if (H5Aexists_by_name(ck->file, "/controller", "event_dt", H5P_DEFAULT) > 0 &&
      H5LTget_attribute_double(ck->file, "/controller", "event_dt", &run->dtc.event_dt) < 0)
    return sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /controller: event_dt unreadable "
                                      "(damaged?)", ck->path);
  SP_CALL(get_members(ck->file, ck->path, "/summary", run->mon.sum, summary_members,
                      N_OF(summary_members)));
  run->n_max = ck->header[H_N_MAX];
  run->step = ck->step;
  run->t = ck->t;
  /* the energy history and division times (energy.png), fields.pvd */
  const int n_energy = ck->header[H_N_ENERGY], n_div = ck->header[H_N_DIVISIONS];
  SP_CHECK(n_energy >= 0 && n_div >= 0, SP_ERR_INPUT, "checkpoint '%s': /output damaged",
           ck->path);
  SP_CALL(read_doubles(ck, "/output/energy_t", &run->mon.energy_t, n_energy));
  SP_CALL(read_doubles(ck, "/output/energy_total", &run->mon.energy_total, n_energy));
  run->mon.n_energy = run->mon.cap_energy = n_energy;
  SP_CALL(read_doubles(ck, "/output/division_t", &run->mon.division_t, n_div));
  run->mon.n_divisions = n_div;
  return read_fields_list(ck, fields, n_fields);
}

int sp_checkpoint_restore_carry(const sp_checkpoint ck, sp_run *run) {
  if (H5LTpath_valid(ck->file, "/carry/header", 1) <= 0) return SP_OK; /* an older file */
  int header[3] = {0, 0, 0};
  int rc = get_array(ck, "/carry/header", H5T_NATIVE_INT, header, 3);
  const int carry = header[0], n_shape = header[1];
  if (rc == SP_OK && !((carry == 0 || carry == 1) && n_shape >= 0 &&
                       (n_shape == 0 || n_shape == run->layout->n_cells)))
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /carry damaged", ck->path);
  const size_t n_values = 2 * (size_t)run->layout->n_pairs;
  const int dim = run->mesh->dim;
  const size_t per = shape_doubles(dim, &(sp_shape_coef){0}, NULL, 0);
  double dt = 0, *x = NULL, *packed = NULL;
  sp_shape_coef *shape = NULL;
  if (rc == SP_OK && carry) {
    x = malloc(sizeof(double) * n_values + 1);
    shape = n_shape ? calloc((size_t)n_shape, sizeof *shape) : NULL;
    packed = n_shape ? malloc(sizeof(double) * per * (size_t)n_shape) : NULL;
    if (!x || (n_shape && (!shape || !packed)))
      rc = sp_error_set(SP_ERR_MEMORY, "out of memory");
    if (rc == SP_OK) rc = get_array(ck, "/carry/dt", H5T_NATIVE_DOUBLE, &dt, 1);
    if (rc == SP_OK) rc = get_array(ck, "/carry/x", H5T_NATIVE_DOUBLE, x, n_values);
    if (rc == SP_OK && n_shape)
      rc = get_array(ck, "/carry/shape", H5T_NATIVE_DOUBLE, packed, per * (size_t)n_shape);
    for (int k = 0; rc == SP_OK && k < n_shape; ++k)
      shape_doubles(dim, &shape[k], packed + per * k, 1);
    if (rc == SP_OK && !(dt > 0))
      rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': /carry/dt damaged", ck->path);
  }
  rc = sp_agree(run->agree_comm, rc); /* the rebuild is collective */
  if (rc == SP_OK && carry) {
    const sp_step_data data = {.dt = dt, .model = run->opt.model, .state_old = x, .shape = shape,
                               .shape_implicit = header[2]};
    const int status = sp_solver_carry_restore(run->solver, &data, x);
    if (status != SP_SOLVER_OK)
      rc = sp_solver_failed(run->solver, status, "checkpoint '%s': the carried factorisation",
                            ck->path);
  }
  free(x);
  free(shape);
  free(packed);
  return rc;
}
