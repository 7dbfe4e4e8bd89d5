#include "io/initial.h"

#include <cairo.h>
#include <math.h>
#include <nifti2_io.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "public/error.h"
#include "io/vtu_read.h"

static int ends_with(const char *s, const char *tail) {
  const size_t n = strlen(s), m = strlen(tail);
  return n >= m && strcmp(s + n - m, tail) == 0;
}

int sp_initial_from_checkpoint(const sp_scene *scene) {
  return scene->initial.from[0] && ends_with(scene->initial.from, ".h5");
}

/* ------------------------------------------------------------------------ */
/* Label grids: a 2D label image (PNG) or a 3D label volume (NIfTI)          */
/* ------------------------------------------------------------------------ */

/** A label grid in dim dimensions: per sample (x fastest) the index of its
 *  label (-1: background), the samples' spacings in the mesh's length, and
 *  the map from a mesh point to grid coordinates (sample centres at
 *  integers). The distance transforms and the profile are one code for
 *  both; only the file readers and the maps differ. */
typedef struct sp_label_grid {
  int dim, n[3], n_labels;
  size_t n_samples;
  double h[3];
  int *label;
  /** a mesh point -> grid coordinates */
  void (*to_grid)(const struct sp_label_grid *g, const double *x, double *at);
  double box[4];          /* label_image: x0, y0, x1, y1 of the image */
  double to_ijk[3][4];    /* label_volume: grid = to_ijk (x, 1) */
  double to_mesh[3][4];   /* label_volume: mesh point of a voxel = to_mesh (i, j, k, 1) */
  double *value;          /* label_volume: each label's value in the file */
} sp_label_grid;

static void label_grid_free(sp_label_grid *g) {
  free(g->label);
  free(g->value);
  *g = (sp_label_grid){0};
}

/** The image's pixel coordinates of (x, y): row 0 at the top. */
static void image_to_grid(const sp_label_grid *g, const double *x, double *at) {
  const double *b = g->box;
  at[0] = (x[0] - b[0]) / (b[2] - b[0]) * g->n[0] - 0.5;
  at[1] = (b[3] - x[1]) / (b[3] - b[1]) * g->n[1] - 0.5;
}

static void volume_to_grid(const sp_label_grid *g, const double *x, double *at) {
  for (int a = 0; a < 3; ++a)
    at[a] = g->to_ijk[a][0] * x[0] + g->to_ijk[a][1] * x[1] + g->to_ijk[a][2] * x[2] +
            g->to_ijk[a][3];
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/** Sort @p v (n values) and keep each value once, ascending: the labels
 *  (colours, voxel values; exact in a double); returns how many. */
static int distinct_labels(double *v, size_t n) {
  qsort(v, n, sizeof *v, cmp_double);
  int k = 0;
  for (size_t i = 0; i < n; ++i)
    if (i == 0 || v[i] != v[i - 1]) v[k++] = v[i];
  return k;
}

/** The index of label value @p x among the @p n distinct ones. */
static int label_index(double x, const double *distinct, int n) {
  const double *at = bsearch(&x, distinct, (size_t)n, sizeof *distinct, cmp_double);
  return (int)(at - distinct);
}

static int labels_load(const char *path, const sp_scene_initial *box, sp_label_grid *out) {
  *out = (sp_label_grid){0};
  cairo_surface_t *img = cairo_image_surface_create_from_png(path);
  if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS) {
    const char *why = cairo_status_to_string(cairo_surface_status(img));
    cairo_surface_destroy(img);
    return sp_error_set(SP_ERR_INPUT, "initial.label_image: '%s': cannot read it as a PNG (%s)",
                        path, why);
  }
  const cairo_format_t format = cairo_image_surface_get_format(img);
  const int w = cairo_image_surface_get_width(img), h = cairo_image_surface_get_height(img);
  const int stride = cairo_image_surface_get_stride(img);
  const unsigned char *data = cairo_image_surface_get_data(img);
  int rc = SP_OK;
  if (format != CAIRO_FORMAT_ARGB32 && format != CAIRO_FORMAT_RGB24)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_image: '%s': expected an RGB or RGBA PNG",
                      path);
  uint32_t *colour = rc == SP_OK ? malloc(sizeof(uint32_t) * (size_t)w * h + 4) : NULL;
  double *sorted = rc == SP_OK ? malloc(sizeof(double) * (size_t)w * h + 8) : NULL;
  out->label = rc == SP_OK ? malloc(sizeof(int) * (size_t)w * h + 4) : NULL;
  if (rc == SP_OK && (!colour || !sorted || !out->label))
    rc = sp_error_set(SP_ERR_MEMORY, "out of memory reading '%s'", path);
  size_t n_fg = 0;
  for (int y = 0; rc == SP_OK && y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint32_t px = *(const uint32_t *)(data + (size_t)y * stride + 4 * (size_t)x);
      const int transparent = format == CAIRO_FORMAT_ARGB32 && (px >> 24) == 0;
      const uint32_t rgb = px & 0xffffffu; /* premultiplied: opaque labels are exact */
      colour[(size_t)y * w + x] = transparent ? 0 : rgb;
      if (!transparent && rgb != 0) sorted[n_fg++] = rgb;
    }
  const int n = rc == SP_OK ? distinct_labels(sorted, n_fg) : 0; /* colours, ascending */
  if (rc == SP_OK && n == 0)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_image: '%s': no labels (every pixel is "
                                    "black or transparent)", path);
  for (size_t i = 0; rc == SP_OK && i < (size_t)w * h; ++i)
    out->label[i] = colour[i] == 0 ? -1 : label_index(colour[i], sorted, n);
  free(colour);
  free(sorted);
  cairo_surface_destroy(img);
  if (rc != SP_OK) {
    label_grid_free(out);
    return rc;
  }
  *out = (sp_label_grid){.dim = 2, .n = {w, h, 1}, .n_labels = n, .n_samples = (size_t)w * h,
                         .h = {(box->x1 - box->x0) / w, (box->y1 - box->y0) / h},
                         .label = out->label, .to_grid = image_to_grid,
                         .box = {box->x0, box->y0, box->x1, box->y1}};
  return SP_OK;
}

/** 1 if voxels of NIfTI type @p datatype can hold labels: integers and
 *  reals (which must then be integers), not complex numbers or colours. */
static int label_type(int datatype) {
  switch (datatype) {
  case NIFTI_TYPE_UINT8: case NIFTI_TYPE_INT8: case NIFTI_TYPE_UINT16: case NIFTI_TYPE_INT16:
  case NIFTI_TYPE_UINT32: case NIFTI_TYPE_INT32: case NIFTI_TYPE_UINT64: case NIFTI_TYPE_INT64:
  case NIFTI_TYPE_FLOAT32: case NIFTI_TYPE_FLOAT64: return 1;
  default: return 0;
  }
}

/** Voxel @p i of @p nim as a number (NAN for a type that holds no labels). */
static double voxel_value(const nifti_image *nim, size_t i) {
  const void *d = nim->data;
  switch (nim->datatype) {
  case NIFTI_TYPE_UINT8: return ((const uint8_t *)d)[i];
  case NIFTI_TYPE_INT8: return ((const int8_t *)d)[i];
  case NIFTI_TYPE_UINT16: return ((const uint16_t *)d)[i];
  case NIFTI_TYPE_INT16: return ((const int16_t *)d)[i];
  case NIFTI_TYPE_UINT32: return ((const uint32_t *)d)[i];
  case NIFTI_TYPE_INT32: return ((const int32_t *)d)[i];
  case NIFTI_TYPE_UINT64: return (double)((const uint64_t *)d)[i];
  case NIFTI_TYPE_INT64: return (double)((const int64_t *)d)[i];
  case NIFTI_TYPE_FLOAT32: return ((const float *)d)[i];
  case NIFTI_TYPE_FLOAT64: return ((const double *)d)[i];
  default: return NAN;
  }
}

/** Voxel @p i's label: its value scaled by scl_slope and scl_inter where
 *  the file sets them (slope 0 means unset). */
static double voxel_label(const nifti_image *nim, size_t i) {
  const double v = voxel_value(nim, i);
  const int scaled = nim->scl_slope != 0 && !(nim->scl_slope == 1 && nim->scl_inter == 0);
  return scaled ? nim->scl_slope * v + nim->scl_inter : v;
}

/** Labels are integers below 2^53 (exact in a double). */
#define SP_LABEL_MAX 9007199254740992.0

/** The volume's voxel -> world affine: the sform if its code is set, else
 *  the qform if its code is set, else the voxel sizes (NIfTI's "method 1",
 *  the origin at voxel (0, 0, 0)); as nibabel's get_best_affine. */
static int volume_affine(const nifti_image *nim, const char *path, double m[3][4],
                         const char **which) {
  const nifti_dmat44 *a = nim->sform_code > 0 ? &nim->sto_xyz
                          : nim->qform_code > 0 ? &nim->qto_xyz : NULL;
  *which = nim->sform_code > 0 ? "sform" : nim->qform_code > 0 ? "qform" : "voxel sizes";
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      m[r][c] = a ? a->m[r][c] : r == c ? fabs(nim->pixdim[r + 1]) : 0.0;
  /* orthogonal axes of nonzero length: the distance transform's spacing is
   * each axis' length (a shear would make the voxel grid's distances wrong) */
  double len[3];
  for (int c = 0; c < 3; ++c) {
    len[c] = sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
    SP_CHECK(isfinite(len[c]) && len[c] > 0, SP_ERR_INPUT,
             "initial.label_volume: '%s': the %s gives voxel axis %d length %g: expected a "
             "positive voxel size", path, *which, c, len[c]);
  }
  for (int c = 0; c < 3; ++c)
    for (int e = c + 1; e < 3; ++e) {
      const double dot = m[0][c] * m[0][e] + m[1][c] * m[1][e] + m[2][c] * m[2][e];
      SP_CHECK(fabs(dot) <= 1e-6 * len[c] * len[e], SP_ERR_INPUT,
               "initial.label_volume: '%s': the %s's voxel axes %d and %d are not orthogonal "
               "(cosine %g): expected a rotation and voxel sizes, no shear", path, *which, c, e,
               dot / (len[c] * len[e]));
    }
  return SP_OK;
}

/** The label volume's samples: per voxel the index of its label among the
 *  distinct nonzero values, ascending (-1: 0, the background). */
static int volume_labels(const nifti_image *nim, const char *path, sp_label_grid *g) {
  const size_t nv = g->n_samples;
  double *sorted = malloc(sizeof(double) * nv + 8);
  g->label = malloc(sizeof(int) * nv + 4); /* (freed by the caller on failure) */
  if (!sorted || !g->label) {
    free(sorted);
    return sp_error_set(SP_ERR_MEMORY, "out of memory reading '%s'", path);
  }
  size_t n_fg = 0;
  int rc = SP_OK;
  for (size_t i = 0; i < nv; ++i) {
    const double v = voxel_label(nim, i);
    if (!(isfinite(v) && v == floor(v) && v >= 0 && v < SP_LABEL_MAX)) {
      const size_t nx = (size_t)g->n[0], ny = (size_t)g->n[1];
      rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': voxel (%zu, %zu, %zu) holds "
                        "%.17g: expected integer labels >= 0 (0: background)", path, i % nx,
                        i / nx % ny, i / (nx * ny), v);
      break;
    }
    g->label[i] = v == 0 ? -1 : 0;
    if (v != 0) sorted[n_fg++] = v;
  }
  const int n = rc == SP_OK ? distinct_labels(sorted, n_fg) : 0;
  if (rc == SP_OK && n == 0)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': no labels (every voxel is "
                                    "0): expected nonzero labels, one a cell", path);
  for (size_t i = 0; rc == SP_OK && i < nv; ++i) {
    if (g->label[i] < 0) continue;
    g->label[i] = label_index(voxel_label(nim, i), sorted, n);
  }
  if (rc != SP_OK) {
    free(sorted);
    return rc;
  }
  g->n_labels = n;
  g->value = sorted; /* (the first n) */
  return SP_OK;
}

/** The mesh point of the voxel centre (i, j, k). */
static void voxel_point(const sp_label_grid *g, size_t v, double *x) {
  const size_t nx = (size_t)g->n[0], ny = (size_t)g->n[1];
  const double ijk[3] = {(double)(v % nx), (double)(v / nx % ny), (double)(v / (nx * ny))};
  for (int a = 0; a < 3; ++a)
    x[a] = g->to_mesh[a][0] * ijk[0] + g->to_mesh[a][1] * ijk[1] + g->to_mesh[a][2] * ijk[2] +
           g->to_mesh[a][3];
}

/** The maps between voxels and the mesh: the affine scaled by
 *  initial.scale and moved by the offset (with initial.centre: the labelled
 *  voxels' bounding box centred there), and its inverse. */
static void volume_placement(const sp_scene_initial *in, const double affine[3][4],
                             sp_label_grid *g) {
  const double offset[3] = {in->offset_x, in->offset_y, in->offset_z};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) g->to_mesh[r][c] = in->scale * affine[r][c];
  for (int r = 0; r < 3; ++r) g->to_mesh[r][3] += offset[r];
  if (in->centre) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < g->n_samples; ++v) {
      if (g->label[v] < 0) continue;
      double x[3];
      voxel_point(g, v, x);
      for (int a = 0; a < 3; ++a) {
        lo[a] = fmin(lo[a], x[a]);
        hi[a] = fmax(hi[a], x[a]);
      }
    }
    for (int r = 0; r < 3; ++r) g->to_mesh[r][3] -= 0.5 * (lo[r] + hi[r]) - offset[r];
  }
  nifti_dmat44 f = {{{0}}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) f.m[r][c] = g->to_mesh[r][c];
  f.m[3][3] = 1;
  const nifti_dmat44 inv = nifti_dmat44_inverse(f);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) g->to_ijk[r][c] = inv.m[r][c];
  for (int a = 0; a < 3; ++a)
    g->h[a] = sqrt(g->to_mesh[0][a] * g->to_mesh[0][a] + g->to_mesh[1][a] * g->to_mesh[1][a] +
                   g->to_mesh[2][a] * g->to_mesh[2][a]);
}

/** Largest label volume read (voxels): a header claiming more is refused
 *  before its data are read. */
#define SP_LABEL_VOLUME_MAX_VOXELS ((int64_t)1 << 30)

static int volume_load(const char *path, const sp_scene_initial *in, sp_label_grid *out) {
  *out = (sp_label_grid){0};
  nifti_set_debug_level(0); /* its messages on stderr: ours name the key */
  nifti_image *nim = nifti_image_read(path, 0);
  SP_CHECK(nim, SP_ERR_INPUT, "initial.label_volume: '%s': cannot read it as a NIfTI-1 or "
                              "NIfTI-2 file", path);
  int rc = SP_OK;
  int64_t extra = 1; /* the 4th to 7th dimensions: one volume */
  for (int d = 4; d <= 7 && d <= nim->dim[0]; ++d) extra *= nim->dim[d];
  if (nim->dim[0] < 3 || nim->nz < 2)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': a %lld x %lld x %lld image "
                      "(%lld dimensions): expected a 3D volume (at least 2 voxels along each "
                      "axis; a 2D image is initial.label_image, on a 2D mesh)", path,
                      (long long)nim->nx, (long long)nim->ny,
                      (long long)(nim->dim[0] >= 3 ? nim->nz : 1), (long long)nim->dim[0]);
  else if (nim->nx < 2 || nim->ny < 2 || extra != 1)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': dimensions %lld x %lld x %lld "
                      "x %lld: expected one 3D volume, at least 2 voxels along each axis", path,
                      (long long)nim->nx, (long long)nim->ny, (long long)nim->nz,
                      (long long)extra);
  else if (nim->nvox > SP_LABEL_VOLUME_MAX_VOXELS)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': %lld voxels: expected at most "
                      "%lld", path, (long long)nim->nvox, (long long)SP_LABEL_VOLUME_MAX_VOXELS);
  else if (!label_type(nim->datatype))
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': voxels of type %s: expected "
                      "integer (or integer-valued real) labels", path,
                      nifti_datatype_string(nim->datatype));
  else if (nifti_image_load(nim) != 0)
    rc = sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': cannot read its voxels", path);
  double affine[3][4];
  const char *which;
  if (rc == SP_OK) rc = volume_affine(nim, path, affine, &which);
  if (rc == SP_OK) {
    *out = (sp_label_grid){.dim = 3, .n = {(int)nim->nx, (int)nim->ny, (int)nim->nz},
                           .n_samples = (size_t)nim->nvox, .to_grid = volume_to_grid};
    rc = volume_labels(nim, path, out);
  }
  if (rc == SP_OK) volume_placement(in, affine, out);
  nifti_image_free(nim);
  if (rc != SP_OK) label_grid_free(out);
  return rc;
}

/** The labels of initial.label_image (2D) or initial.label_volume (3D). */
static int label_grid_load(const sp_scene *scene, sp_label_grid *g) {
  if (scene->initial.label_image[0])
    return labels_load(scene->initial.label_image, &scene->initial, g);
  return volume_load(scene->initial.label_volume, &scene->initial, g);
}

/** "No pixel of the set on this line": large, finite, so that the
 *  envelope's intersections stay numbers (it never wins against a real
 *  distance). */
#define SP_FAR 1e20

/**
 * The squared distance transform of a sampled function along one line
 * (Felzenszwalb and Huttenlocher, "Distance transforms of sampled
 * functions", 2012): d[q] = min_p (h (q - p))^2 + f[p], for n samples of
 * spacing h, by the lower envelope of the parabolas rooted at each p.
 * v, z: scratch of n and n + 1.
 */
static void edt_1d(const double *f, double *d, int n, double h, int *v, double *z) {
  const double h2 = h * h;
  int k = 0;
  v[0] = 0;
  z[0] = -INFINITY;
  z[1] = INFINITY;
  for (int q = 1; q < n; ++q) {
    double s;
    for (;;) {
      const int p = v[k];
      s = ((f[q] + h2 * q * q) - (f[p] + h2 * p * p)) / (2 * h2 * (q - p));
      if (s <= z[k]) --k; /* never below 0: z[0] = -inf */
      else break;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = INFINITY;
  }
  for (int q = 0, j = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = h * (q - v[j]);
    d[q] = dq * dq + f[v[j]];
  }
}

/** What the distance transforms and the profile need besides the grid: a
 *  label's signed distance at every sample, and scratch, allocated once. */
typedef struct {
  const sp_label_grid *grid;
  double d;     /* interface width */
  int current;  /* the label sd holds (-1: none yet) */
  double *sd, *d_in, *d_out;
  unsigned char *in;
  double *f, *fd, *z; /* one line: n, n, n + 1 */
  int *v;
} sp_label_fields;

static void label_fields_free(sp_label_fields *lf) {
  free(lf->sd);
  free(lf->d_in);
  free(lf->d_out);
  free(lf->in);
  free(lf->f);
  free(lf->fd);
  free(lf->z);
  free(lf->v);
}

static int label_fields_create(const sp_label_grid *g, double d, sp_label_fields *lf) {
  int n = 0;
  for (int a = 0; a < g->dim; ++a) n = g->n[a] > n ? g->n[a] : n;
  const size_t ns = g->n_samples;
  *lf = (sp_label_fields){.grid = g, .d = d, .current = -1,
                          .sd = malloc(sizeof(double) * ns + 8),
                          .d_in = malloc(sizeof(double) * ns + 8),
                          .d_out = malloc(sizeof(double) * ns + 8), .in = malloc(ns + 1),
                          .f = calloc(n, sizeof(double)), .fd = calloc(n, sizeof(double)),
                          .z = malloc(sizeof(double) * (n + 1)), .v = malloc(sizeof(int) * n)};
  if (lf->sd && lf->d_in && lf->d_out && lf->in && lf->f && lf->fd && lf->z && lf->v)
    return SP_OK;
  label_fields_free(lf);
  return sp_error_set(SP_ERR_MEMORY, "out of memory for the distance transforms of %zu samples",
                      ns);
}

/** The Euclidean distance from each sample to the nearest sample where
 *  lf->in says 1 (1e10 if there is none), into @p dist: the 1D transform
 *  along the last axis, then along each axis before it down to x (whose
 *  pass takes the square root). */
static void edt(sp_label_fields *lf, double *dist) {
  const sp_label_grid *g = lf->grid;
  size_t stride[3] = {1, 1, 1};
  for (int a = 1; a < g->dim; ++a) stride[a] = stride[a - 1] * (size_t)g->n[a - 1];
  for (int a = g->dim - 1; a >= 0; --a) {
    const size_t n = (size_t)g->n[a], s = stride[a], outer = g->n_samples / (n * s);
    for (size_t o = 0; o < outer; ++o)
      for (size_t i = 0; i < s; ++i) {
        const size_t base = o * n * s + i;
        for (size_t q = 0; q < n; ++q)
          lf->f[q] = a == g->dim - 1 ? (lf->in[base + q * s] ? 0.0 : SP_FAR)
                                     : dist[base + q * s];
        edt_1d(lf->f, lf->fd, (int)n, g->h[a], lf->v, lf->z);
        for (size_t q = 0; q < n; ++q)
          dist[base + q * s] = a == 0 ? sqrt(fmin(lf->fd[q], SP_FAR)) : lf->fd[q];
      }
  }
}

/** Label k's signed distance to its edge (half-way between its samples and
 *  the others') at every sample, < 0 inside. */
static void label_distance(sp_label_fields *lf, int k) {
  const sp_label_grid *g = lf->grid;
  const size_t ns = g->n_samples;
  double half = g->h[0];
  for (int a = 1; a < g->dim; ++a) half = fmin(half, g->h[a]);
  half *= 0.5;
  for (size_t i = 0; i < ns; ++i) lf->in[i] = g->label[i] == k;
  edt(lf, lf->d_in); /* to the label's samples */
  for (size_t i = 0; i < ns; ++i) lf->in[i] = !lf->in[i];
  edt(lf, lf->d_out); /* to the others' */
  for (size_t i = 0; i < ns; ++i)
    lf->sd[i] = g->label[i] == k ? -(lf->d_out[i] - half) : lf->d_in[i] - half;
  lf->current = k;
}

/** The multilinear interpolation of the samples at grid point @p at (in
 *  the grid), each axis clamped to its first and last sample. */
static double grid_sample(const sp_label_grid *g, const double *sd, const double *at) {
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  double fr[3] = {0, 0, 0};
  for (int a = 0; a < g->dim; ++a) {
    const int n = g->n[a];
    const double c = fmin(fmax(at[a], 0.0), n - 1.0);
    lo[a] = (int)fmin(floor(c), n - 2 >= 0 ? n - 2 : 0);
    hi[a] = lo[a] + 1 < n ? lo[a] + 1 : lo[a];
    fr[a] = c - lo[a];
  }
  const size_t w = (size_t)g->n[0], plane = w * (size_t)g->n[1];
  double s = 0;
  for (int layer = 0; layer < (g->dim == 3 ? 2 : 1); ++layer) {
    const size_t z = (size_t)(layer ? hi[2] : lo[2]) * plane;
    const double *p0 = sd + z + (size_t)lo[1] * w, *p1 = sd + z + (size_t)hi[1] * w;
    const double fx = fr[0], fy = fr[1];
    const double in_plane = (1 - fy) * ((1 - fx) * p0[lo[0]] + fx * p0[hi[0]]) +
                            fy * ((1 - fx) * p1[lo[0]] + fx * p1[hi[0]]);
    if (g->dim == 2) return in_plane;
    s += (layer ? fr[2] : 1 - fr[2]) * in_plane;
  }
  return s;
}

/** Cell k's profile at a mesh point: 0 off the grid. Label k's distances
 *  are computed when first asked for (sp_cells_fill goes cell by cell), so
 *  one label's are held at a time. */
static double label_profile(int k, const double *point, int dim, void *ctx) {
  sp_label_fields *lf = ctx;
  const sp_label_grid *g = lf->grid;
  (void)dim; /* the grid's: scene_check.c pairs a label image with 2D, a volume with 3D */
  double at[3];
  g->to_grid(g, point, at);
  for (int a = 0; a < g->dim; ++a)
    if (at[a] < -0.5 || at[a] > g->n[a] - 0.5) return 0.0; /* off the grid */
  if (lf->current != k) label_distance(lf, k);
  return sp_cells_profile(grid_sample(g, lf->sd, at), lf->d);
}

/** Every labelled voxel's centre in Omega: a label outside the mesh is bad
 *  input, not a cell cut off. */
static int volume_inside(const sp_label_grid *g, const sp_mesh *mesh, const char *path) {
  for (size_t v = 0; v < g->n_samples; ++v) {
    if (g->label[v] < 0) continue;
    double x[3];
    voxel_point(g, v, x);
    if (sp_mesh_contains(mesh, x)) continue;
    const size_t nx = (size_t)g->n[0], ny = (size_t)g->n[1];
    return sp_error_set(SP_ERR_INPUT, "initial.label_volume: '%s': label %.17g (cell %d) has "
                        "voxel (%zu, %zu, %zu) at (%g, %g, %g), outside the mesh's Omega: "
                        "expected every labelled voxel's centre inside (place the volume with "
                        "initial.scale, offset_x, offset_y, offset_z, centre)", path,
                        g->value[g->label[v]], g->label[v] + 1, v % nx, v / nx % ny,
                        v / (nx * ny), x[0], x[1], x[2]);
  }
  return SP_OK;
}

static int label_grid_state(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                            double *state) {
  sp_label_grid g;
  SP_CALL(label_grid_load(scene, &g));
  int rc = g.dim == mesh->dim ? SP_OK
                              : sp_error_set(SP_ERR_INPUT, "initial.label_%s: a %dD label grid "
                                             "on a %dD mesh", g.dim == 3 ? "volume" : "image",
                                             g.dim, mesh->dim);
  sp_label_fields lf = {0};
  if (rc == SP_OK) rc = label_fields_create(&g, sp_scene_interface_width(scene), &lf);
  if (rc == SP_OK) {
    rc = sp_cells_fill(scene, mesh, layout, label_profile, &lf, state);
    label_fields_free(&lf);
  }
  label_grid_free(&g);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* .vtu                                                                     */
/* ------------------------------------------------------------------------ */

typedef struct {
  double x[3]; /* (z = 0 on a 2D mesh, as the .vtu has it) */
  int index;
} sp_point;

static int cmp_point(const void *a, const void *b) {
  const sp_point *p = a, *q = b;
  for (int d = 0; d < 3; ++d)
    if (p->x[d] != q->x[d]) return p->x[d] < q->x[d] ? -1 : 1;
  return 0;
}

/** Every mesh node's point of the .vtu (the same coordinates, bit for bit:
 *  the same mesh, 2D or 3D, whatever its numbering there). */
static int vtu_state(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                     double *state) {
  const char *path = scene->initial.from;
  sp_vtu_fields v;
  SP_CALL(sp_vtu_read(path, &v));
  const int nn = mesh->n_nodes;
  int rc = v.n_points == nn && v.n_cells == layout->n_cells
               ? SP_OK
               : sp_error_set(SP_ERR_INPUT, "initial.from: '%s': %d points and %d cells; this "
                                            "scene's mesh has %d nodes", path, v.n_points,
                              v.n_cells, nn);
  sp_point *a = rc == SP_OK ? malloc(sizeof *a * nn) : NULL, *b = rc == SP_OK ? malloc(sizeof *b * nn) : NULL;
  if (rc == SP_OK && (!a || !b)) rc = sp_error_set(SP_ERR_MEMORY, "out of memory");
  for (int i = 0; rc == SP_OK && i < nn; ++i) {
    a[i] = b[i] = (sp_point){.index = i};
    for (int d = 0; d < mesh->dim; ++d) a[i].x[d] = mesh->xy[(size_t)mesh->dim * i + d];
    for (int d = 0; d < 3; ++d) b[i].x[d] = v.xyz[3 * (size_t)i + d];
  }
  if (rc == SP_OK) {
    qsort(a, nn, sizeof *a, cmp_point);
    qsort(b, nn, sizeof *b, cmp_point);
  }
  for (int j = 0; rc == SP_OK && j < nn; ++j) {
    if (cmp_point(&a[j], &b[j]) != 0) {
      rc = sp_error_set(SP_ERR_INPUT, "initial.from: '%s': its points are not this scene's "
                                      "mesh nodes (node at (%g, %g, %g))", path, a[j].x[0],
                        a[j].x[1], a[j].x[2]);
      break;
    }
    for (int k = 0; k < layout->n_cells; ++k) {
      const int p = sp_layout_pair(layout, k, a[j].index);
      if (p < 0) continue;
      state[2 * p] = v.c[(size_t)k * nn + b[j].index];
      state[2 * p + 1] = v.mu[(size_t)k * nn + b[j].index];
    }
  }
  free(a);
  free(b);
  sp_vtu_fields_free(&v);
  return rc;
}

/* ------------------------------------------------------------------------ */

int sp_initial_cell_count(const sp_scene *scene, const sp_mesh *mesh, int *n_cells) {
  *n_cells = scene->n_cells;
  if (scene->initial.label_image[0] || scene->initial.label_volume[0]) {
    const int image = scene->initial.label_image[0] != '\0';
    const char *path = image ? scene->initial.label_image : scene->initial.label_volume;
    sp_label_grid g;
    SP_CALL(label_grid_load(scene, &g));
    *n_cells = g.n_labels;
    int rc = mesh && g.dim == 3 ? volume_inside(&g, mesh, path) : SP_OK;
    label_grid_free(&g);
    SP_CALL(rc);
    const char *key = image ? "initial.label_image" : "initial.label_volume";
    char where[SP_SCENE_PATH_MAX + 64];
    snprintf(where, sizeof where, "%s: '%s'", key, path);
    return sp_scene_check_cell_count(scene, *n_cells, key, where);
  } else if (scene->initial.from[0] && !sp_initial_from_checkpoint(scene)) {
    SP_CHECK(ends_with(scene->initial.from, ".vtu"), SP_ERR_INPUT,
             "initial.from: expected a softpack checkpoint (.h5) or .vtu, got '%s'",
             scene->initial.from);
    sp_vtu_fields v;
    const int rc = sp_vtu_read(scene->initial.from, &v);
    if (rc != SP_OK)
      return sp_error_set(rc, "initial.from: %s", sp_error_message());
    *n_cells = v.n_cells;
    sp_vtu_fields_free(&v);
  }
  return SP_OK;
}

int sp_initial_state(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                     double *state) {
  if (scene->initial.label_image[0] || scene->initial.label_volume[0])
    return label_grid_state(scene, mesh, layout, state);
  if (scene->initial.from[0]) return vtu_state(scene, mesh, layout, state);
  return sp_cells_initial_state(scene, mesh, layout, state);
}
