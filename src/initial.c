#include "initial.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cells.h"
#include "error.h"
#include "output.h"

static int ends_with(const char *s, const char *tail) {
  const size_t n = strlen(s), m = strlen(tail);
  return n >= m && strcmp(s + n - m, tail) == 0;
}

int sp_initial_from_checkpoint(const sp_scene *scene) {
  return scene->initial.from[0] && ends_with(scene->initial.from, ".h5");
}

/* ------------------------------------------------------------------------ */
/* Label images                                                             */
/* ------------------------------------------------------------------------ */

/** A label image: per pixel the index of its label (-1: background). */
typedef struct {
  int width, height, n_labels;
  int *label;
} sp_labels;

static int cmp_u32(const void *a, const void *b) {
  const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

static int labels_load(const char *path, sp_labels *out) {
  *out = (sp_labels){0};
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
  uint32_t *sorted = rc == SP_OK ? malloc(sizeof(uint32_t) * (size_t)w * h + 4) : NULL;
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
  int n = 0;
  if (rc == SP_OK) { /* the distinct colours, ascending */
    qsort(sorted, n_fg, sizeof *sorted, cmp_u32);
    for (size_t i = 0; i < n_fg; ++i)
      if (i == 0 || sorted[i] != sorted[i - 1]) sorted[n++] = sorted[i];
    if (n == 0)
      rc = sp_error_set(SP_ERR_INPUT, "initial.label_image: '%s': no labels (every pixel is "
                                      "black or transparent)", path);
  }
  for (size_t i = 0; rc == SP_OK && i < (size_t)w * h; ++i) {
    if (colour[i] == 0) {
      out->label[i] = -1;
      continue;
    }
    const uint32_t *at = bsearch(&colour[i], sorted, (size_t)n, sizeof *sorted, cmp_u32);
    out->label[i] = (int)(at - sorted);
  }
  free(colour);
  free(sorted);
  cairo_surface_destroy(img);
  if (rc != SP_OK) {
    free(out->label);
    *out = (sp_labels){0};
    return rc;
  }
  out->width = w;
  out->height = h;
  out->n_labels = n;
  return SP_OK;
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

/** The Euclidean distance from each pixel centre to the nearest pixel
 *  centre where @p in says 1 (pixel sizes hx, hy); 1e10 if there is none. */
static int edt_2d(const unsigned char *in, int w, int h, double hx, double hy, double *dist) {
  const int n = w > h ? w : h;
  double *f = calloc(n, sizeof(double)), *d = calloc(n, sizeof(double)),
         *z = malloc(sizeof(double) * (n + 1));
  int *v = malloc(sizeof(int) * n);
  if (!f || !d || !z || !v) {
    free(f);
    free(d);
    free(z);
    free(v);
    return sp_error_set(SP_ERR_MEMORY, "out of memory for a distance transform");
  }
  for (int x = 0; x < w; ++x) { /* columns */
    for (int y = 0; y < h; ++y) f[y] = in[(size_t)y * w + x] ? 0.0 : SP_FAR;
    edt_1d(f, d, h, hy, v, z);
    for (int y = 0; y < h; ++y) dist[(size_t)y * w + x] = d[y];
  }
  for (int y = 0; y < h; ++y) { /* rows */
    memcpy(f, dist + (size_t)y * w, sizeof(double) * w);
    edt_1d(f, d, w, hx, v, z);
    for (int x = 0; x < w; ++x) dist[(size_t)y * w + x] = sqrt(fmin(d[x], SP_FAR));
  }
  free(f);
  free(d);
  free(z);
  free(v);
  return SP_OK;
}

/** What label_profile samples: per label the signed distance to its edge
 *  at every pixel centre (< 0 inside). */
typedef struct {
  const sp_scene_initial *box;
  int width, height;
  double *sd; /* n_labels x width x height */
  double d;   /* interface width */
} sp_label_fields;

static double label_profile(int k, const double *point, int dim, void *ctx) {
  (void)dim; /* a 2D label image (3D scenes refuse one: scene.c) */
  const double x = point[0], y = point[1];
  const sp_label_fields *lf = ctx;
  const sp_scene_initial *b = lf->box;
  const int w = lf->width, h = lf->height;
  /* pixel coordinates of (x, y): centres at integers, row 0 at the top */
  const double px = (x - b->x0) / (b->x1 - b->x0) * w - 0.5;
  const double py = (b->y1 - y) / (b->y1 - b->y0) * h - 0.5;
  if (px < -0.5 || px > w - 0.5 || py < -0.5 || py > h - 0.5) return 0.0; /* off the image */
  const double cx = fmin(fmax(px, 0.0), w - 1.0), cy = fmin(fmax(py, 0.0), h - 1.0);
  const int x0 = (int)fmin(floor(cx), w - 2 >= 0 ? w - 2 : 0),
            y0 = (int)fmin(floor(cy), h - 2 >= 0 ? h - 2 : 0);
  const int x1 = x0 + 1 < w ? x0 + 1 : x0, y1 = y0 + 1 < h ? y0 + 1 : y0;
  const double fx = cx - x0, fy = cy - y0;
  const double *sd = lf->sd + (size_t)k * w * h;
  const double s = (1 - fy) * ((1 - fx) * sd[(size_t)y0 * w + x0] + fx * sd[(size_t)y0 * w + x1]) +
                   fy * ((1 - fx) * sd[(size_t)y1 * w + x0] + fx * sd[(size_t)y1 * w + x1]);
  return sp_cells_profile(s, lf->d);
}

static int label_image_state(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                             double *state) {
  sp_labels lab;
  SP_CALL(labels_load(scene->initial.label_image, &lab));
  const int w = lab.width, h = lab.height;
  const size_t n_px = (size_t)w * h;
  const double hx = (scene->initial.x1 - scene->initial.x0) / w,
               hy = (scene->initial.y1 - scene->initial.y0) / h;
  sp_label_fields lf = {.box = &scene->initial, .width = w, .height = h,
                        .d = sp_scene_interface_width(scene)};
  lf.sd = malloc(sizeof(double) * n_px * lab.n_labels + 1);
  unsigned char *in = malloc(n_px + 1);
  double *d_in = malloc(sizeof(double) * n_px + 1), *d_out = malloc(sizeof(double) * n_px + 1);
  int rc = lf.sd && in && d_in && d_out ? SP_OK
                                        : sp_error_set(SP_ERR_MEMORY, "out of memory for the "
                                                                      "label image's distances");
  const double half = 0.5 * fmin(hx, hy); /* the edge: half-way between pixel centres */
  for (int k = 0; rc == SP_OK && k < lab.n_labels; ++k) {
    for (size_t i = 0; i < n_px; ++i) in[i] = lab.label[i] == k;
    rc = edt_2d(in, w, h, hx, hy, d_in); /* to the label's pixels */
    for (size_t i = 0; i < n_px; ++i) in[i] = !in[i];
    if (rc == SP_OK) rc = edt_2d(in, w, h, hx, hy, d_out); /* to the others' */
    if (rc != SP_OK) break;
    double *sd = lf.sd + (size_t)k * n_px;
    for (size_t i = 0; i < n_px; ++i)
      sd[i] = lab.label[i] == k ? -(d_out[i] - half) : d_in[i] - half;
  }
  if (rc == SP_OK) rc = sp_cells_fill(scene, mesh, layout, label_profile, &lf, state);
  free(lf.sd);
  free(in);
  free(d_in);
  free(d_out);
  free(lab.label);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* .vtu                                                                     */
/* ------------------------------------------------------------------------ */

typedef struct {
  double x, y;
  int index;
} sp_point;

static int cmp_point(const void *a, const void *b) {
  const sp_point *p = a, *q = b;
  if (p->x != q->x) return p->x < q->x ? -1 : 1;
  if (p->y != q->y) return p->y < q->y ? -1 : 1;
  return 0;
}

/** Every mesh node's point of the .vtu (the same coordinates, bit for bit:
 *  the same mesh, whatever its numbering there). */
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
    a[i] = (sp_point){mesh->xy[2 * i], mesh->xy[2 * i + 1], i};
    b[i] = (sp_point){v.xy[2 * i], v.xy[2 * i + 1], i};
  }
  if (rc == SP_OK) {
    qsort(a, nn, sizeof *a, cmp_point);
    qsort(b, nn, sizeof *b, cmp_point);
  }
  for (int j = 0; rc == SP_OK && j < nn; ++j) {
    if (a[j].x != b[j].x || a[j].y != b[j].y) {
      rc = sp_error_set(SP_ERR_INPUT, "initial.from: '%s': its points are not this scene's "
                                      "mesh nodes (node at (%g, %g))", path, a[j].x, a[j].y);
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

int sp_initial_cell_count(const sp_scene *scene, int *n_cells) {
  *n_cells = scene->n_cells;
  if (scene->initial.label_image[0]) {
    sp_labels lab;
    SP_CALL(labels_load(scene->initial.label_image, &lab));
    *n_cells = lab.n_labels;
    free(lab.label);
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
  SP_CHECK(mesh->dim == 2 || !(scene->initial.label_image[0] || scene->initial.from[0]),
           SP_ERR_INPUT, "initial: fields from files are not yet on a 3D mesh (issue 29)");
  if (scene->initial.label_image[0]) return label_image_state(scene, mesh, layout, state);
  if (scene->initial.from[0]) return vtu_state(scene, mesh, layout, state);
  return sp_cells_initial_state(scene, mesh, layout, state);
}
