/* render_base.c: what the pictures share: PNG files, the jet map, labels, the 2D frame. */
/*
 * The drawing base of the renderers of io/ (render_base.h). Files are
 * written to "<path>.tmp" and renamed, so a picture is either the old one
 * or the new one, never half of one.
 */
#define _POSIX_C_SOURCE 200809L

#include "io/render_base.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"

/** The axes' names, x, y and z. */
const char *const sp_render_axis_names[3] = {"x", "y", "z"};

/** Write @p surf as PNG to "<path>.tmp", then rename it to @p path. */
int sp_render_png_write(cairo_surface_t *surf, const char *path) {
  size_t n = strlen(path);
  char *tmp = malloc(n + 5);
  SP_CHECK(tmp, SP_ERR_MEMORY, "out of memory naming a temporary for '%s'",
           path);
  memcpy(tmp, path, n);
  memcpy(tmp + n, ".tmp", 5);
  errno = 0;
  cairo_status_t st = cairo_surface_write_to_png(surf, tmp);
  int rc = SP_OK;
  if (st != CAIRO_STATUS_SUCCESS) {
    /* cairo only says "write error"; errno from its fopen/fwrite says why. */
    rc = sp_error_set(SP_ERR_IO, "cannot write '%s': %s (%s)", tmp,
                      errno ? strerror(errno) : "no system error",
                      cairo_status_to_string(st));
    remove(tmp);
  } else if (rename(tmp, path) != 0) {
    rc = sp_error_set(SP_ERR_IO, "cannot rename '%s' to '%s': %s", tmp, path,
                      strerror(errno));
    remove(tmp);
  }
  free(tmp);
  return rc;
}

/** Turn a failed cairo context or surface into an error code. */
int sp_render_cairo_check(cairo_status_t st, const char *what, const char *path) {
  SP_CHECK(st == CAIRO_STATUS_SUCCESS,
           st == CAIRO_STATUS_NO_MEMORY ? SP_ERR_MEMORY : SP_ERR_INTERNAL,
           "cairo failed %s for '%s': %s", what, path,
           cairo_status_to_string(st));
  return SP_OK;
}

/** Piecewise-linear interpolation through (x, y) knots sorted by x. */
static double sp_knots(const double (*k)[2], int n, double v) {
  if (v <= k[0][0]) return k[0][1];
  for (int i = 1; i < n; ++i)
    if (v <= k[i][0])
      return k[i - 1][1] + (k[i][1] - k[i - 1][1]) * (v - k[i - 1][0]) /
                               (k[i][0] - k[i - 1][0]);
  return k[n - 1][1];
}

/**
 * The "jet" colour map (matplotlib's knots): 0 dark blue, 0.35 cyan,
 * 0.5 green-yellow, 0.65 yellow, 1 dark red. NaN is grey, so a broken state
 * shows as such instead of as some colour of the map.
 */
void sp_render_jet(double v, double rgb[3]) {
  static const double r[][2] = {{0, 0}, {0.35, 0}, {0.66, 1}, {0.89, 1},
                                {1, 0.5}};
  static const double g[][2] = {{0, 0},    {0.125, 0}, {0.375, 1},
                                {0.64, 1}, {0.91, 0},  {1, 0}};
  static const double b[][2] = {{0, 0.5}, {0.11, 1}, {0.34, 1}, {0.65, 0},
                                {1, 0}};
  if (isnan(v)) {
    rgb[0] = rgb[1] = rgb[2] = 0.5;
    return;
  }
  v = v < 0 ? 0 : v > 1 ? 1 : v;
  rgb[0] = sp_knots(r, 5, v);
  rgb[1] = sp_knots(g, 6, v);
  rgb[2] = sp_knots(b, 5, v);
}

/** An opaque pixel of a CAIRO_FORMAT_RGB24 surface. */
uint32_t sp_render_rgb24(const double rgb[3]) {
  uint32_t c[3];
  for (int i = 0; i < 3; ++i) {
    double x = rgb[i] < 0 ? 0 : rgb[i] > 1 ? 1 : rgb[i];
    c[i] = (uint32_t)lround(255.0 * x);
  }
  return 0xff000000u | c[0] << 16 | c[1] << 8 | c[2];
}

/** A white RGB24 surface of w x h pixels, or an error. */
int sp_render_white_surface(int w, int h, const char *path, cairo_surface_t **out) {
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  const int rc = sp_render_cairo_check(cairo_surface_status(surf), "creating a surface", path);
  if (rc != SP_OK) {
    cairo_surface_destroy(surf);
    return rc;
  }
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_destroy(cr);
  *out = surf;
  return SP_OK;
}

/** The layout is one of the mesh's nodes. */
int sp_render_layout_check(const sp_mesh *mesh, const sp_layout *layout) {
  SP_CHECK(layout && layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "render: mesh has %d nodes but layout has %d", mesh->n_nodes,
           layout ? layout->n_nodes : -1);
  return SP_OK;
}

/** The outputs of the *_pixel functions (any pointer may be NULL). */
void sp_render_pixel_out(double u, double v, int h, double *px, double *py, int *height_px) {
  if (px) *px = u;
  if (py) *py = v;
  if (height_px) *height_px = h;
}

/** Cell k's label (from 0): its name, or its number (from 1, as in
 *  cells.csv) for an unnamed cell of a named scene. */
const char *sp_render_cell_label(const sp_cell_name *names, int k, char buf[16]) {
  if (names[k][0]) return names[k];
  snprintf(buf, 16, "%d", k + 1);
  return buf;
}

/** @p text in bold centred on the pixel (x, y): black letters on a white
 *  halo, readable on any colour of the map. */
static void sp_name_label(cairo_t *cr, double x, double y, double font, const char *text) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, font);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text, &ext);
  cairo_move_to(cr, x - 0.5 * ext.width - ext.x_bearing, y - 0.5 * ext.height - ext.y_bearing);
  cairo_text_path(cr, text);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_width(cr, 0.25 * font);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_stroke_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_fill(cr);
}

/** Label each cell k with sum[3 k + 2] > @p min_count at its mean pixel
 *  (sum[3 k] / n, sum[3 k + 1] / n, n = sum[3 k + 2]). */
void sp_render_name_labels(cairo_t *cr, int n_cells, const double *sum, double min_count,
                           double font, const sp_cell_name *names) {
  for (int k = 0; k < n_cells; ++k) {
    const double n = sum[3 * k + 2];
    char buf[16];
    if (n > min_count)
      sp_name_label(cr, sum[3 * k] / n, sum[3 * k + 1] / n, font,
                    sp_render_cell_label(names, k, buf));
  }
}

/**
 * The bounding box lo[d] .. hi[d] (d < mesh->dim; the rest 0) of the
 * mesh's nodes, not mesh->bounds: with a buffer the mesh reaches beyond
 * Omega.
 */
int sp_render_mesh_bbox(const sp_mesh *m, double lo[3], double hi[3]) {
  SP_CHECK(m && m->n_nodes > 0 && m->xy, SP_ERR_INTERNAL,
           "render: empty mesh");
  const int dim = m->dim;
  for (int d = 0; d < 3; ++d) {
    lo[d] = d < dim ? HUGE_VAL : 0.0;
    hi[d] = d < dim ? -HUGE_VAL : 0.0;
  }
  for (int i = 0; i < m->n_nodes; ++i)
    for (int d = 0; d < dim; ++d) {
      lo[d] = fmin(lo[d], m->xy[(size_t)dim * i + d]);
      hi[d] = fmax(hi[d], m->xy[(size_t)dim * i + d]);
    }
  for (int d = 0; d < dim; ++d)
    SP_CHECK(isfinite(lo[d]) && isfinite(hi[d]) && hi[d] > lo[d], SP_ERR_INTERNAL,
             "render: degenerate mesh bounding box: [%g, %g] along axis %d", lo[d], hi[d], d);
  return SP_OK;
}

/** The picture width @p width_px is one the renderer draws. */
int sp_render_width_check(int width_px) {
  SP_CHECK(width_px >= 16 && width_px <= 16384, SP_ERR_INPUT,
           "render: picture width %d px is outside [16, 16384]", width_px);
  return SP_OK;
}

int sp_render_frame_make(const sp_mesh *m, int width_px, sp_render_frame *fr) {
  SP_CALL(sp_render_width_check(width_px));
  double lo[3], hi[3];
  SP_CALL(sp_render_mesh_bbox(m, lo, hi));
  const double x0 = lo[0], y0 = lo[1], x1 = hi[0], y1 = hi[1];
  int margin = width_px / 50 > 4 ? width_px / 50 : 4;
  fr->font = fmax(10.0, width_px / 45.0);
  int band = (int)ceil(1.8 * fr->font); /* a white strip for the time */
  fr->x0 = x0;
  fr->y1 = y1;
  fr->s = (width_px - 2.0 * margin) / (x1 - x0);
  fr->ox = margin;
  fr->oy = band + margin;
  double h = band + 2.0 * margin + ceil((y1 - y0) * fr->s);
  SP_CHECK(h <= 32768, SP_ERR_INPUT, "render: a %d px wide picture of a "
           "%g x %g domain would be %.0f px high", width_px, x1 - x0, y1 - y0,
           h);
  fr->w = width_px;
  fr->h = (int)h;
  return SP_OK;
}

void sp_render_frame_map(const sp_render_frame *fr, double x, double y, double *px,
                         double *py) {
  *px = fr->ox + (x - fr->x0) * fr->s;
  *py = fr->oy + (fr->y1 - y) * fr->s; /* image y grows downwards */
}

static int sp_cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/**
 * Add to the current path the boundary of the Omega region: the edges of
 * region-0 elements that no other region-0 element shares.
 */
static int sp_omega_outline(cairo_t *cr, const sp_mesh *m, const sp_render_frame *fr) {
  uint64_t *edges;
  SP_ALLOC(edges, 4 * (size_t)m->n_elems);
  size_t ne = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    if (m->region && m->region[e] != SP_REGION_OMEGA) continue;
    const int *node = sp_mesh_elem_nodes(m, e);
    for (int a = 0; a < 4; ++a) {
      uint32_t u = (uint32_t)node[a];
      uint32_t v = (uint32_t)node[(a + 1) % 4];
      edges[ne++] = u < v ? (uint64_t)u << 32 | v : (uint64_t)v << 32 | u;
    }
  }
  qsort(edges, ne, sizeof *edges, sp_cmp_u64);
  for (size_t i = 0; i < ne;) {
    size_t j = i + 1;
    while (j < ne && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      int u = (int)(edges[i] >> 32), v = (int)(edges[i] & 0xffffffffu);
      double px, py;
      sp_render_frame_map(fr, m->xy[2 * u], m->xy[2 * u + 1], &px, &py);
      cairo_move_to(cr, px, py);
      sp_render_frame_map(fr, m->xy[2 * v], m->xy[2 * v + 1], &px, &py);
      cairo_line_to(cr, px, py);
    }
    i = j;
  }
  free(edges);
  return SP_OK;
}

/** Text with its left (@p align 0), centre (0.5) or right (1) at x, its
 *  baseline at y. */
void sp_render_text(cairo_t *cr, double x, double y, double align, const char *text) {
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text, &ext);
  cairo_move_to(cr, x - align * ext.width - ext.x_bearing, y);
  cairo_show_text(cr, text);
}

/** "t = ..." in black, its baseline starting at (x, y). */
void sp_render_time_label(cairo_t *cr, double x, double y, double font, double t) {
  char label[64];
  snprintf(label, sizeof label, "t = %.2e", t);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, font);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, label);
}

/** The outline of Omega (line width 1.5 @p lw) and the time in the white
 *  strip above the picture: what every picture on the cells' frame has. */
int sp_render_outline_and_time(cairo_t *cr, const sp_mesh *m, const sp_render_frame *fr,
                               double lw, double t, const char *what) {
  SP_CALL(sp_omega_outline(cr, m, fr));
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_set_line_width(cr, 1.5 * lw);
  cairo_stroke(cr);
  sp_render_time_label(cr, fr->ox, 1.3 * fr->font, fr->font, t);
  return sp_render_cairo_check(cairo_status(cr), "drawing", what);
}

/** phi = max_k c_k at the nodes (NaN wins, so a broken state shows grey). */
int sp_render_phi_nodes(const sp_mesh *m, const sp_layout *l, const double *state,
                        double **out) {
  double *phi;
  SP_ALLOC(phi, m->n_nodes);
  for (int i = 0; i < m->n_nodes; ++i) {
    double v = 0.0;
    for (int p = l->node_start[i]; p < l->node_start[i + 1]; ++p)
      if (state[2 * p] > v || isnan(state[2 * p])) v = state[2 * p];
    phi[i] = v;
  }
  *out = phi;
  return SP_OK;
}
