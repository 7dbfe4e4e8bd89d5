/**
 * @file render.c
 * @brief PNG pictures with cairo: the cells (phi = max_k c_k on the jet
 *        colour map, membranes as black contours, the outline of Omega) and
 *        the energy against time.
 *
 * The field is rasterised by hand into the image surface's pixels: each quad
 * is split into two triangles and every pixel centre inside a triangle gets
 * the colour of the linearly interpolated phi. Cairo's gradient meshes could
 * do the same, but per-pixel colouring is exact (no banding, no seams between
 * triangles) and costs one pass over the pixels each triangle covers. The
 * lines and text are then drawn with cairo on top.
 *
 * Files are written to "<path>.tmp" and renamed, so a picture is either the
 * old one or the new one, never half of one.
 */
#define _POSIX_C_SOURCE 200809L

#include "io/render.h"

#include <cairo.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"

/* sp_pi is not in strict C11. */
static const double sp_pi = 3.14159265358979323846;

/* ------------------------------------------------------------------------ */
/* Shared helpers                                                           */
/* ------------------------------------------------------------------------ */

/** Write @p surf as PNG to "<path>.tmp", then rename it to @p path. */
static int sp_png_write(cairo_surface_t *surf, const char *path) {
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
static int sp_cairo_check(cairo_status_t st, const char *what,
                          const char *path) {
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
static void sp_jet(double v, double rgb[3]) {
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
static uint32_t sp_pixel(const double rgb[3]) {
  uint32_t c[3];
  for (int i = 0; i < 3; ++i) {
    double x = rgb[i] < 0 ? 0 : rgb[i] > 1 ? 1 : rgb[i];
    c[i] = (uint32_t)lround(255.0 * x);
  }
  return 0xff000000u | c[0] << 16 | c[1] << 8 | c[2];
}

/** A white RGB24 surface of w x h pixels, or an error. */
static int sp_white_surface(int w, int h, const char *path, cairo_surface_t **out) {
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
  const int rc = sp_cairo_check(cairo_surface_status(surf), "creating a surface", path);
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
static int sp_layout_check(const sp_mesh *mesh, const sp_layout *layout) {
  SP_CHECK(layout && layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "render: mesh has %d nodes but layout has %d", mesh->n_nodes,
           layout ? layout->n_nodes : -1);
  return SP_OK;
}

/** The outputs of the *_pixel functions (any pointer may be NULL). */
static void sp_pixel_out(double u, double v, int h, double *px, double *py, int *height_px) {
  if (px) *px = u;
  if (py) *py = v;
  if (height_px) *height_px = h;
}

/** Cell k's label (from 0): its name, or its number (from 1, as in
 *  cells.csv) for an unnamed cell of a named scene. */
static const char *sp_cell_label(const sp_cell_name *names, int k, char buf[16]) {
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
static void sp_name_labels(cairo_t *cr, int n_cells, const double *sum, double min_count,
                           double font, const sp_cell_name *names) {
  for (int k = 0; k < n_cells; ++k) {
    const double n = sum[3 * k + 2];
    char buf[16];
    if (n > min_count)
      sp_name_label(cr, sum[3 * k] / n, sum[3 * k + 1] / n, font, sp_cell_label(names, k, buf));
  }
}

/* ------------------------------------------------------------------------ */
/* Cells picture                                                            */
/* ------------------------------------------------------------------------ */

/** World-to-pixel map of the cells picture. */
typedef struct {
  double x0, y1;  /**< left and top of the mesh's bounding box */
  double s;       /**< pixels per unit length */
  double ox, oy;  /**< pixel position of (x0, y1) */
  int w, h;       /**< picture size */
  double font;    /**< font size of the time label */
} sp_frame;

/**
 * The bounding box lo[d] .. hi[d] (d < mesh->dim; the rest 0) of the
 * mesh's nodes, not mesh->bounds: with a buffer the mesh reaches beyond
 * Omega.
 */
static int sp_mesh_bbox(const sp_mesh *m, double lo[3], double hi[3]) {
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
static int sp_width_check(int width_px) {
  SP_CHECK(width_px >= 16 && width_px <= 16384, SP_ERR_INPUT,
           "render: picture width %d px is outside [16, 16384]", width_px);
  return SP_OK;
}

static int sp_frame_make(const sp_mesh *m, int width_px, sp_frame *fr) {
  SP_CALL(sp_width_check(width_px));
  double lo[3], hi[3];
  SP_CALL(sp_mesh_bbox(m, lo, hi));
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

static void sp_frame_map(const sp_frame *fr, double x, double y, double *px,
                         double *py) {
  *px = fr->ox + (x - fr->x0) * fr->s;
  *py = fr->oy + (fr->y1 - y) * fr->s; /* image y grows downwards */
}

int sp_render_cells_pixel(const sp_mesh *mesh, int width_px, double x,
                          double y, double *px, double *py, int *height_px) {
  sp_frame fr = {0};
  SP_CALL(sp_frame_make(mesh, width_px, &fr));
  double u, v;
  sp_frame_map(&fr, x, y, &u, &v);
  sp_pixel_out(u, v, fr.h, px, py, height_px);
  return SP_OK;
}

/** The local node triples of the two triangles of a quad. */
static const int sp_quad_tris[2][3] = {{0, 1, 2}, {0, 2, 3}};

/**
 * Colour every pixel whose centre lies in triangle P (pixel coordinates)
 * with jet(linear interpolation of v). Centres on an edge are taken by both
 * neighbours (same colour), so triangles leave no seams.
 */
static void sp_fill_triangle(uint32_t *data, int stride, int w, int h,
                             double P[3][2], const double v[3],
                             int lighten) {
  double area = (P[1][0] - P[0][0]) * (P[2][1] - P[0][1]) -
                (P[2][0] - P[0][0]) * (P[1][1] - P[0][1]);
  if (!(fabs(area) > 1e-12)) return; /* degenerate: covers no pixel */
  double xmin = fmin(P[0][0], fmin(P[1][0], P[2][0]));
  double xmax = fmax(P[0][0], fmax(P[1][0], P[2][0]));
  double ymin = fmin(P[0][1], fmin(P[1][1], P[2][1]));
  double ymax = fmax(P[0][1], fmax(P[1][1], P[2][1]));
  int i0 = (int)fmax(0, ceil(xmin - 0.5)), i1 = (int)fmin(w - 1, floor(xmax - 0.5));
  int j0 = (int)fmax(0, ceil(ymin - 0.5)), j1 = (int)fmin(h - 1, floor(ymax - 0.5));
  const double eps = 1e-9;
  for (int j = j0; j <= j1; ++j) {
    double Y = j + 0.5;
    uint32_t *row = data + (size_t)j * stride;
    for (int i = i0; i <= i1; ++i) {
      double X = i + 0.5;
      double l1 = ((X - P[0][0]) * (P[2][1] - P[0][1]) -
                   (P[2][0] - P[0][0]) * (Y - P[0][1])) / area;
      double l2 = ((P[1][0] - P[0][0]) * (Y - P[0][1]) -
                   (X - P[0][0]) * (P[1][1] - P[0][1])) / area;
      double l0 = 1.0 - l1 - l2;
      if (l0 < -eps || l1 < -eps || l2 < -eps) continue;
      double rgb[3];
      sp_jet(l0 * v[0] + l1 * v[1] + l2 * v[2], rgb);
      if (lighten) /* the buffer ring: same colours, washed out */
        for (int c = 0; c < 3; ++c) rgb[c] = 0.55 * rgb[c] + 0.45;
      row[i] = sp_pixel(rgb);
    }
  }
}

/** c of (cell, node), 0 outside the cell's support. */
static double sp_c_at(const sp_layout *l, const double *state, int k, int n) {
  int p = sp_layout_pair(l, k, n);
  return p >= 0 ? state[2 * p] : 0.0;
}

/**
 * Add to the current path the piece of the level set c = level inside one
 * triangle (P in pixels). Nodes are classified c >= level or not, so a
 * crossed triangle has exactly two crossed edges and the pieces of
 * neighbouring triangles meet.
 */
static void sp_contour_triangle(cairo_t *cr, double P[3][2],
                                const double c[3], double level) {
  double pts[2][2];
  int n = 0;
  for (int a = 0; a < 3; ++a) {
    int b = (a + 1) % 3;
    int ina = c[a] >= level, inb = c[b] >= level;
    if (ina == inb || n == 2) continue;
    double s = (level - c[a]) / (c[b] - c[a]);
    pts[n][0] = P[a][0] + s * (P[b][0] - P[a][0]);
    pts[n][1] = P[a][1] + s * (P[b][1] - P[a][1]);
    ++n;
  }
  if (n == 2) {
    cairo_move_to(cr, pts[0][0], pts[0][1]);
    cairo_line_to(cr, pts[1][0], pts[1][1]);
  }
}

static int sp_cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

/**
 * Add to the current path the boundary of the Omega region: the edges of
 * region-0 elements that no other region-0 element shares.
 */
static int sp_omega_outline(cairo_t *cr, const sp_mesh *m, const sp_frame *fr) {
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
      sp_frame_map(fr, m->xy[2 * u], m->xy[2 * u + 1], &px, &py);
      cairo_move_to(cr, px, py);
      sp_frame_map(fr, m->xy[2 * v], m->xy[2 * v + 1], &px, &py);
      cairo_line_to(cr, px, py);
    }
    i = j;
  }
  free(edges);
  return SP_OK;
}

/** "t = ..." in black, its baseline starting at (x, y). */
static void sp_time_label(cairo_t *cr, double x, double y, double font, double t) {
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
static int sp_outline_and_time(cairo_t *cr, const sp_mesh *m, const sp_frame *fr, double lw,
                               double t, const char *what) {
  SP_CALL(sp_omega_outline(cr, m, fr));
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_set_line_width(cr, 1.5 * lw);
  cairo_stroke(cr);
  sp_time_label(cr, fr->ox, 1.3 * fr->font, fr->font, t);
  return sp_cairo_check(cairo_status(cr), "drawing", what);
}

/** phi = max_k c_k at the nodes (NaN wins, so a broken state shows grey). */
static int sp_phi_nodes(const sp_mesh *m, const sp_layout *l, const double *state,
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

/** Everything drawn on an existing white RGB24 surface. */
static int sp_draw_cells(cairo_surface_t *surf, const sp_frame *fr,
                         const sp_mesh *m, const sp_layout *l,
                         const double *state, double t, const sp_cell_name *names) {
  /* phi at the nodes: the max over the cells supported there. */
  double *phi;
  SP_CALL(sp_phi_nodes(m, l, state, &phi));

  cairo_surface_flush(surf);
  uint32_t *data = (uint32_t *)cairo_image_surface_get_data(surf);
  int stride = cairo_image_surface_get_stride(surf) / 4;
  for (int e = 0; e < m->n_elems; ++e) {
    int lighten = m->region && m->region[e] != SP_REGION_OMEGA;
    for (int tri = 0; tri < 2; ++tri) {
      double P[3][2], v[3];
      for (int a = 0; a < 3; ++a) {
        int n = sp_mesh_elem_nodes(m, e)[sp_quad_tris[tri][a]];
        sp_frame_map(fr, m->xy[2 * n], m->xy[2 * n + 1], &P[a][0], &P[a][1]);
        v[a] = phi[n];
      }
      sp_fill_triangle(data, stride, fr->w, fr->h, P, v, lighten);
    }
  }
  free(phi);
  cairo_surface_mark_dirty(surf);

  cairo_t *cr = cairo_create(surf);
  int rc = sp_cairo_check(cairo_status(cr), "creating a context", "cells");
  if (rc != SP_OK) {
    cairo_destroy(cr);
    return rc;
  }
  double lw = fmax(1.0, fr->w / 700.0);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);

  /* Membranes: the level 1/2 of each c_k, one path per cell. */
  cairo_set_source_rgba(cr, 0, 0, 0, 0.85);
  cairo_set_line_width(cr, lw);
  for (int k = 0; k < l->n_cells; ++k) {
    for (int e = 0; e < m->n_elems; ++e)
      for (int tri = 0; tri < 2; ++tri) {
        double P[3][2], c[3];
        int any = 0;
        for (int a = 0; a < 3; ++a) {
          int n = sp_mesh_elem_nodes(m, e)[sp_quad_tris[tri][a]];
          sp_frame_map(fr, m->xy[2 * n], m->xy[2 * n + 1], &P[a][0],
                       &P[a][1]);
          c[a] = sp_c_at(l, state, k, n);
          any |= c[a] >= 0.5;
        }
        if (any) sp_contour_triangle(cr, P, c, 0.5);
      }
    cairo_stroke(cr);
  }

  rc = sp_outline_and_time(cr, m, fr, lw, t, "cells");
  if (rc == SP_OK && names) { /* each name at the mean of its cell's nodes */
    double *sum = calloc(3 * (size_t)l->n_cells + 1, sizeof *sum);
    if (!sum) rc = sp_error_set(SP_ERR_MEMORY, "out of memory labelling the cells");
    for (int i = 0; rc == SP_OK && i < m->n_nodes; ++i) {
      const int k = sp_layout_node_cell(l, state, i);
      if (k < 0) continue;
      double px, py;
      sp_frame_map(fr, m->xy[2 * i], m->xy[2 * i + 1], &px, &py);
      sum[3 * k] += px, sum[3 * k + 1] += py, sum[3 * k + 2] += 1;
    }
    if (rc == SP_OK) sp_name_labels(cr, l->n_cells, sum, 0, fr->font, names);
    free(sum);
    if (rc == SP_OK) rc = sp_cairo_check(cairo_status(cr), "drawing", "cells");
  }
  cairo_destroy(cr);
  return rc;
}

int sp_render_cells(const sp_mesh *mesh, const sp_layout *layout,
                    const double *state, double t, const sp_cell_name *names, int width_px,
                    const char *path) {
  SP_CHECK(mesh->dim == 2, SP_ERR_INTERNAL,
           "render: the cells picture is 2D (a 3D state has sp_render_sections and "
           "sp_render_surfaces)");
  SP_CALL(sp_layout_check(mesh, layout));
  sp_frame fr = {0};
  SP_CALL(sp_frame_make(mesh, width_px, &fr));
  /* White first: whatever the mesh does not cover stays white. */
  cairo_surface_t *surf = NULL;
  int rc = sp_white_surface(fr.w, fr.h, path, &surf);
  if (rc == SP_OK) rc = sp_draw_cells(surf, &fr, mesh, layout, state, t, names);
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* Energy plot                                                              */
/* ------------------------------------------------------------------------ */

/** A "nice" tick spacing (1, 2 or 5 times a power of ten) near @p raw. */
static double sp_nice_step(double raw) {
  double p = pow(10.0, floor(log10(raw)));
  double f = raw / p;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

/**
 * Widen [*lo, *hi] when it is empty or too narrow to tick (a single point,
 * constant energy), so nothing divides by zero; otherwise pad by @p pad of
 * the range on each side.
 */
static void sp_axis_range(double *lo, double *hi, double pad) {
  double scale = fmax(fabs(*lo), fabs(*hi));
  if (!(*hi - *lo > 1e-12 * scale) || !(*hi - *lo > 1e-300)) {
    double d = scale > 0 ? 0.05 * scale : 1.0;
    *lo -= d;
    *hi += d;
    return;
  }
  double d = pad * (*hi - *lo);
  *lo -= d;
  *hi += d;
}

/**
 * Tick label for @p v on an axis with tick spacing @p step: as many decimals
 * as the spacing needs, and exponent notation for very large or small
 * magnitudes, so neighbouring labels always differ.
 */
static void sp_tick_label(char *buf, size_t len, double v, double step,
                          double maxabs) {
  if (fabs(v) < 1e-9 * step) v = 0.0; /* -1.2e-17 is 0 */
  int step_exp = (int)floor(log10(step) + 1e-9);
  if (maxabs >= 1e5 || maxabs < 1e-3) {
    int mag = v != 0 ? (int)floor(log10(fabs(v))) : step_exp;
    int digits = mag - step_exp;
    digits = digits < 0 ? 0 : digits > 12 ? 12 : digits;
    snprintf(buf, len, "%.*e", digits, v);
  } else {
    int dec = step_exp < 0 ? -step_exp : 0;
    snprintf(buf, len, "%.*f", dec > 12 ? 12 : dec, v);
  }
}

int sp_render_energy(const double *t, const double *energy, int n,
                     const double *marks, int n_marks, const char *path) {
  SP_CHECK(n >= 0 && (n == 0 || (t && energy)), SP_ERR_INTERNAL,
           "render: %d energy values but no arrays", n);
  const int W = 800, H = 500;
  const double L = 100, R = W - 25, T = 25, B = H - 60; /* plot area */

  /* Data range over the finite points only. */
  double t0 = HUGE_VAL, t1 = -HUGE_VAL, e0 = HUGE_VAL, e1 = -HUGE_VAL;
  int n_ok = 0;
  for (int i = 0; i < n; ++i)
    if (isfinite(t[i]) && isfinite(energy[i])) {
      t0 = fmin(t0, t[i]);
      t1 = fmax(t1, t[i]);
      e0 = fmin(e0, energy[i]);
      e1 = fmax(e1, energy[i]);
      ++n_ok;
    }
  if (!n_ok) t0 = e0 = 0, t1 = e1 = 1;
  sp_axis_range(&t0, &t1, 0.0);
  sp_axis_range(&e0, &e1, 0.05);
  const double sx = (R - L) / (t1 - t0), sy = (B - T) / (e1 - e0);
#define SP_PX(tv) (L + ((tv) - t0) * sx)
#define SP_PY(ev) (B - ((ev) - e0) * sy)

  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
  SP_CALL(sp_cairo_check(cairo_surface_status(surf), "creating a surface",
                         path));
  cairo_t *cr = cairo_create(surf);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 13);

  /* Ticks, grid lines and labels on both axes. */
  char label[64];
  cairo_text_extents_t ext;
  for (int axis = 0; axis < 2; ++axis) {
    double lo = axis ? e0 : t0, hi = axis ? e1 : t1;
    double step = sp_nice_step((hi - lo) / 5.0);
    double maxabs = fmax(fabs(lo), fabs(hi));
    double first = ceil(lo / step - 1e-9) * step;
    for (int i = 0; i < 40; ++i) {
      double v = first + i * step;
      if (v > hi + 1e-9 * step) break;
      sp_tick_label(label, sizeof label, v, step, maxabs);
      cairo_text_extents(cr, label, &ext);
      cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
      cairo_set_line_width(cr, 1);
      if (axis == 0) {
        double x = floor(SP_PX(v)) + 0.5;
        cairo_move_to(cr, x, T);
        cairo_line_to(cr, x, B + 5);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, x - ext.width / 2 - ext.x_bearing, B + 20);
      } else {
        double y = floor(SP_PY(v)) + 0.5;
        cairo_move_to(cr, L - 5, y);
        cairo_line_to(cr, R, y);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, L - 9 - ext.width - ext.x_bearing,
                      y - ext.height / 2 - ext.y_bearing);
      }
      cairo_show_text(cr, label);
    }
  }

  /* Axis titles. */
  cairo_set_font_size(cr, 15);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_text_extents(cr, "t", &ext);
  cairo_move_to(cr, (L + R) / 2 - ext.width / 2, H - 15);
  cairo_show_text(cr, "t");
  cairo_text_extents(cr, "energy", &ext);
  cairo_save(cr);
  cairo_move_to(cr, 22, (T + B) / 2 + ext.width / 2);
  cairo_rotate(cr, -sp_pi / 2);
  cairo_show_text(cr, "energy");
  cairo_restore(cr);

  /* Plot contents, clipped to the plot area. */
  cairo_save(cr);
  cairo_rectangle(cr, L, T, R - L, B - T);
  cairo_clip(cr);
  if (marks && n_marks > 0) { /* e.g. divisions: dashed verticals */
    const double dash[] = {6, 4};
    cairo_set_dash(cr, dash, 2, 0);
    cairo_set_source_rgb(cr, 0.8, 0.3, 0.2);
    cairo_set_line_width(cr, 1);
    for (int i = 0; i < n_marks; ++i)
      if (isfinite(marks[i]) && marks[i] >= t0 && marks[i] <= t1) {
        double x = floor(SP_PX(marks[i])) + 0.5;
        cairo_move_to(cr, x, T);
        cairo_line_to(cr, x, B);
      }
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
  }
  cairo_set_source_rgb(cr, 0.1, 0.3, 0.75);
  cairo_set_line_width(cr, 1.8);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  int pen_down = 0; /* a non-finite value breaks the line */
  for (int i = 0; i < n; ++i) {
    if (!(isfinite(t[i]) && isfinite(energy[i]))) {
      pen_down = 0;
      continue;
    }
    if (pen_down) cairo_line_to(cr, SP_PX(t[i]), SP_PY(energy[i]));
    else cairo_move_to(cr, SP_PX(t[i]), SP_PY(energy[i]));
    pen_down = 1;
  }
  cairo_stroke(cr);
  if (n_ok <= 30) /* few points (n = 1 has no line at all): mark them */
    for (int i = 0; i < n; ++i)
      if (isfinite(t[i]) && isfinite(energy[i])) {
        cairo_new_sub_path(cr);
        cairo_arc(cr, SP_PX(t[i]), SP_PY(energy[i]), 3, 0, 2 * sp_pi);
        cairo_fill(cr);
      }
  cairo_restore(cr);
#undef SP_PX
#undef SP_PY

  /* Frame. */
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, floor(L) + 0.5, floor(T) + 0.5, floor(R - L),
                  floor(B - T));
  cairo_stroke(cr);

  int rc = sp_cairo_check(cairo_status(cr), "drawing", path);
  cairo_destroy(cr);
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  cairo_surface_destroy(surf);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* 3D: the level surfaces of Q1 fields on hexahedra                         */
/* ------------------------------------------------------------------------ */

/** The faces of a hexahedron, each as its local nodes in cyclic order
 *  (q1.h's numbering: 0..3 the bottom face, 4..7 the top one). */
static const int sp_hex_faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                       {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

/** A growing list of triangles, 9 coordinates each. */
typedef struct {
  double *xyz;
  size_t n, cap;
} sp_tris;

static int sp_tris_push(sp_tris *t, const double *p0, const double *p1, const double *p2) {
  if (t->n == t->cap) {
    size_t cap = t->cap ? 2 * t->cap : 1024;
    double *xyz = realloc(t->xyz, 9 * sizeof(double) * cap);
    SP_CHECK(xyz, SP_ERR_MEMORY, "render: out of memory for %zu triangles", cap);
    t->xyz = xyz;
    t->cap = cap;
  }
  double *q = t->xyz + 9 * t->n++;
  for (int d = 0; d < 3; ++d) q[d] = p0[d], q[3 + d] = p1[d], q[6 + d] = p2[d];
  return SP_OK;
}

/** Add triangle (p0, p1, p2), turned so that its normal (p1 - p0) x
 *  (p2 - p0) has a positive component along @p out. */
static int sp_tris_push_facing(sp_tris *t, const double *p0, const double *p1,
                               const double *p2, const double out[3]) {
  double a[3], b[3];
  for (int d = 0; d < 3; ++d) a[d] = p1[d] - p0[d], b[d] = p2[d] - p0[d];
  const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
  const double dot = n[0] * out[0] + n[1] * out[1] + n[2] * out[2];
  return dot >= 0 ? sp_tris_push(t, p0, p1, p2) : sp_tris_push(t, p0, p2, p1);
}

/**
 * The point where v = level on the edge from @p pi (v = vi >= level) to
 * @p po (vo < level). Always computed from the inside end, so the two
 * tetrahedra sharing an edge make bit-identical points.
 */
static void sp_edge_point(const double *pi, double vi, const double *po, double vo,
                          double level, double x[3]) {
  const double s = (level - vi) / (vo - vi);
  for (int d = 0; d < 3; ++d) x[d] = pi[d] + s * (po[d] - pi[d]);
}

/**
 * The piece of {v = level} in one tetrahedron (marching tetrahedra on the
 * linear interpolant): a triangle when one or three vertices are inside
 * (v >= level), a quadrilateral as two triangles when two are; turned to
 * face from the inside vertices to the outside ones.
 */
static int sp_march_tet(const double *p[4], const double v[4], double level, sp_tris *t) {
  int in[4], out[4], n_in = 0, n_out = 0;
  for (int a = 0; a < 4; ++a) {
    if (v[a] >= level) in[n_in++] = a;
    else out[n_out++] = a;
  }
  if (n_in == 0 || n_out == 0) return SP_OK;
  double dir[3] = {0, 0, 0}; /* from the inside vertices' centroid to the outside ones' */
  for (int d = 0; d < 3; ++d) {
    for (int j = 0; j < n_out; ++j) dir[d] += p[out[j]][d] / n_out;
    for (int j = 0; j < n_in; ++j) dir[d] -= p[in[j]][d] / n_in;
  }
  double q[4][3];
#define SP_EDGE(k, i, o) sp_edge_point(p[i], v[i], p[o], v[o], level, q[k])
  if (n_in == 1) {
    for (int j = 0; j < 3; ++j) SP_EDGE(j, in[0], out[j]);
    return sp_tris_push_facing(t, q[0], q[1], q[2], dir);
  }
  if (n_in == 3) {
    for (int j = 0; j < 3; ++j) SP_EDGE(j, in[j], out[0]);
    return sp_tris_push_facing(t, q[0], q[1], q[2], dir);
  }
  /* in a, b and out c, d: the crossed edges ac, ad, bd, bc in cyclic order */
  SP_EDGE(0, in[0], out[0]);
  SP_EDGE(1, in[0], out[1]);
  SP_EDGE(2, in[1], out[1]);
  SP_EDGE(3, in[1], out[0]);
#undef SP_EDGE
  SP_CALL(sp_tris_push_facing(t, q[0], q[1], q[2], dir));
  return sp_tris_push_facing(t, q[0], q[2], q[3], dir);
}

/**
 * The piece of {v = level} in hexahedron @p e: the hexahedron is cut into
 * 24 tetrahedra, each made of one edge of a face, the face's centre and the
 * hexahedron's centre (the trilinear field's values there: the means of the
 * face's 4 and the element's 8 nodal values). Every face is cut the same
 * way from both sides whatever the two elements' orientations (the cubed
 * ball's patches meet at differently oriented hexahedra), so the surface
 * closes; the face centre is summed over its nodes in the order of their
 * global numbers, so both sides compute it to the same bits.
 */
static int sp_march_hex(const sp_mesh *m, int e, const double *v, double level, sp_tris *t) {
  const int *node = sp_mesh_elem_nodes(m, e);
  double val[8];
  int n_in = 0;
  for (int a = 0; a < 8; ++a) {
    val[a] = v[node[a]];
    n_in += val[a] >= level;
  }
  if (n_in == 0 || n_in == 8) return SP_OK;
  double x[8][3], xc[3] = {0, 0, 0}, vc = 0;
  for (int a = 0; a < 8; ++a) {
    for (int d = 0; d < 3; ++d) {
      x[a][d] = m->xy[3 * (size_t)node[a] + d];
      xc[d] += 0.125 * x[a][d];
    }
    vc += 0.125 * val[a];
  }
  for (int f = 0; f < 6; ++f) {
    int order[4];
    for (int j = 0; j < 4; ++j) { /* the face's nodes by global number */
      int a = sp_hex_faces[f][j], i = j;
      for (; i > 0 && node[order[i - 1]] > node[a]; --i) order[i] = order[i - 1];
      order[i] = a;
    }
    double xf[3] = {0, 0, 0}, vf = 0;
    for (int j = 0; j < 4; ++j) {
      for (int d = 0; d < 3; ++d) xf[d] += 0.25 * x[order[j]][d];
      vf += 0.25 * val[order[j]];
    }
    for (int j = 0; j < 4; ++j) {
      const int a = sp_hex_faces[f][j], b = sp_hex_faces[f][(j + 1) % 4];
      const double *p[4] = {x[a], x[b], xf, xc};
      const double vt[4] = {val[a], val[b], vf, vc};
      SP_CALL(sp_march_tet(p, vt, level, t));
    }
  }
  return SP_OK;
}

static int sp_level_surface(const sp_mesh *mesh, const double *v, double level, sp_tris *t) {
  for (int e = 0; e < mesh->n_elems; ++e) SP_CALL(sp_march_hex(mesh, e, v, level, t));
  return SP_OK;
}

int sp_render_level_surface(const sp_mesh *mesh, const double *v, double level, double **tri,
                            size_t *n_tri) {
  SP_CHECK(mesh && mesh->dim == 3 && v && tri && n_tri, SP_ERR_INTERNAL,
           "render: a level surface needs a 3D mesh and its nodal values");
  sp_tris t = {NULL, 0, 0};
  const int rc = sp_level_surface(mesh, v, level, &t);
  if (rc != SP_OK) {
    free(t.xyz);
    return rc;
  }
  *tri = t.xyz;
  *n_tri = t.n;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* 3D: the three mid-plane sections                                         */
/* ------------------------------------------------------------------------ */

/** Panel a of the sections picture is the plane x_a = the box's middle,
 *  seen with axis [a][0] to the right and axis [a][1] up. */
static const int sp_section_axes[3][2] = {{1, 2}, {0, 2}, {0, 1}};
static const char *const sp_axis_names[3] = {"x", "y", "z"};

/** World-to-pixel map of the sections picture: one scale for the three
 *  panels, side by side, each with room on its left for its vertical
 *  axis's labels. */
typedef struct {
  double lo[3], hi[3], mid[3]; /**< the nodes' bounding box, its middle */
  double s;                    /**< pixels per unit length */
  double left[3];              /**< pixel x of each panel's left edge */
  double top;                  /**< pixel y of the panels' top edge */
  int w, h;
  double font;
} sp_sections_frame;

static int sp_sections_frame_make(const sp_mesh *m, int width_px, sp_sections_frame *fr) {
  SP_CHECK(m && m->dim == 3, SP_ERR_INTERNAL, "render: sections need a 3D mesh");
  SP_CALL(sp_width_check(width_px));
  SP_CALL(sp_mesh_bbox(m, fr->lo, fr->hi));
  for (int d = 0; d < 3; ++d) fr->mid[d] = 0.5 * (fr->lo[d] + fr->hi[d]);
  const double margin = width_px / 50 > 4 ? width_px / 50 : 4;
  fr->font = fmax(10.0, width_px / 60.0);
  const double room = 3.5 * fr->font; /* left of each panel: its vertical axis */
  double across = 0, tall = 0;        /* the panels' total width, largest height */
  for (int a = 0; a < 3; ++a) {
    const int hx = sp_section_axes[a][0], vx = sp_section_axes[a][1];
    across += fr->hi[hx] - fr->lo[hx];
    tall = fmax(tall, fr->hi[vx] - fr->lo[vx]);
  }
  fr->s = (width_px - 2 * margin - 3 * room) / across;
  SP_CHECK(fr->s > 0, SP_ERR_INPUT, "render: a %d px wide picture leaves no room for sections",
           width_px);
  double x = margin;
  for (int a = 0; a < 3; ++a) {
    const int hx = sp_section_axes[a][0];
    fr->left[a] = x + room;
    x = fr->left[a] + (fr->hi[hx] - fr->lo[hx]) * fr->s;
  }
  fr->top = margin + 3.6 * fr->font; /* the time, then the panels' titles */
  const double h = ceil(fr->top + tall * fr->s + 2.4 * fr->font + margin);
  SP_CHECK(h <= 32768, SP_ERR_INPUT, "render: %d px wide sections would be %.0f px high",
           width_px, h);
  fr->w = width_px;
  fr->h = (int)h;
  return SP_OK;
}

/** Pixel of the point @p x (3 coordinates) in panel @p a. */
static void sp_sections_map(const sp_sections_frame *fr, int a, const double *x, double *px,
                            double *py) {
  const int hx = sp_section_axes[a][0], vx = sp_section_axes[a][1];
  *px = fr->left[a] + (x[hx] - fr->lo[hx]) * fr->s;
  *py = fr->top + (fr->hi[vx] - x[vx]) * fr->s;
}

int sp_render_sections_pixel(const sp_mesh *mesh, int width_px, int plane, const double *x,
                             double *px, double *py, int *height_px) {
  SP_CHECK(plane >= 0 && plane < 3, SP_ERR_INTERNAL, "render: section plane %d", plane);
  sp_sections_frame fr = {0};
  SP_CALL(sp_sections_frame_make(mesh, width_px, &fr));
  double u, v;
  sp_sections_map(&fr, plane, x, &u, &v);
  sp_pixel_out(u, v, fr.h, px, py, height_px);
  return SP_OK;
}

/**
 * The reference point xi of the physical point @p X in the hexahedron with
 * nodes @p xe (Newton on the trilinear map from the centre). Returns 1 if X
 * lies in the element (xi in [-1, 1]^3 to 1e-9), else 0.
 */
static int sp_hex_locate(const double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], const double *X,
                         double xi[SP_Q1_MAX_DIM]) {
  xi[0] = xi[1] = xi[2] = 0;
  for (int it = 0; it < 20; ++it) {
    double N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_q1_shape(3, xi, N, dN);
    double r[3], J[3][3] = {{0}};
    for (int d = 0; d < 3; ++d) {
      r[d] = -X[d];
      for (int a = 0; a < 8; ++a) {
        r[d] += N[a] * xe[a][d];
        for (int k = 0; k < 3; ++k) J[d][k] += xe[a][d] * dN[a][k];
      }
    }
    const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                       J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                       J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    if (!(fabs(det) > 0)) return 0;
    double step = 0;
    for (int k = 0; k < 3; ++k) { /* Cramer: column k of J replaced by -r */
      double M[3][3];
      for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 3; ++c) M[d][c] = c == k ? -r[d] : J[d][c];
      const double dk = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                         M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                         M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
      xi[k] += dk;
      step = fmax(step, fabs(dk));
    }
    if (fabs(xi[0]) > 4 || fabs(xi[1]) > 4 || fabs(xi[2]) > 4) return 0; /* far outside */
    if (step < 1e-12) break;
  }
  return fabs(xi[0]) <= 1 + 1e-9 && fabs(xi[1]) <= 1 + 1e-9 && fabs(xi[2]) <= 1 + 1e-9;
}

/** The cell (from 0) with the largest c > 1/2 at a point of the hexahedron
 *  with nodes @p en and shape function values @p N (each c_k interpolated
 *  trilinearly, 0 off its support), or -1. */
static int sp_section_cell(const sp_layout *l, const double *state, const int *en,
                           const double N[SP_Q1_MAX_NODES]) {
  enum { MAX = 64 }; /* the distinct cells at 8 nodes: more are not labelled */
  int cell[MAX], n = 0, best = -1;
  double c[MAX], top = 0.5;
  for (int a = 0; a < 8; ++a)
    for (int p = l->node_start[en[a]]; p < l->node_start[en[a] + 1]; ++p) {
      int i = 0;
      while (i < n && cell[i] != l->pair_cell[p]) ++i;
      if (i == n && n == MAX) continue;
      if (i == n) cell[n] = l->pair_cell[p], c[n++] = 0;
      c[i] += N[a] * state[2 * p];
    }
  for (int i = 0; i < n; ++i) /* equal values keep the lower cell, as cell_id's */
    if (c[i] > top || (c[i] == top && best >= 0 && cell[i] < best)) top = c[i], best = cell[i];
  return best;
}

/**
 * Colour the pixels of panel @p a that lie in the plane's section of each
 * element with jet(phi), phi interpolated trilinearly at the pixel centre
 * (the element walked, its slice rasterised over its bounding box's
 * pixels); buffer elements washed out as in 2D. With @p sum (names), add
 * each pixel to its cell's sums (sp_name_labels).
 */
static void sp_section_fill(uint32_t *data, int stride, const sp_sections_frame *fr, int a,
                            const sp_mesh *m, const double *phi, const sp_layout *l,
                            const double *state, double *sum) {
  const int hx = sp_section_axes[a][0], vx = sp_section_axes[a][1];
  const double x0 = fr->left[a], x1 = x0 + (fr->hi[hx] - fr->lo[hx]) * fr->s;
  const double y0 = fr->top, y1 = y0 + (fr->hi[vx] - fr->lo[vx]) * fr->s;
  for (int e = 0; e < m->n_elems; ++e) {
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(m, e, xe);
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int n = 0; n < 8; ++n)
      for (int d = 0; d < 3; ++d) lo[d] = fmin(lo[d], xe[n][d]), hi[d] = fmax(hi[d], xe[n][d]);
    if (fr->mid[a] < lo[a] || fr->mid[a] > hi[a]) continue;
    double plo, phi_, qlo, qhi; /* the element's pixel box */
    sp_sections_map(fr, a, lo, &plo, &qhi);
    sp_sections_map(fr, a, hi, &phi_, &qlo);
    const int i0 = (int)fmax(ceil(fmax(plo, x0) - 0.5), 0);
    const int i1 = (int)fmin(floor(fmin(phi_, x1) - 0.5), fr->w - 1);
    const int j0 = (int)fmax(ceil(fmax(qlo, y0) - 0.5), 0);
    const int j1 = (int)fmin(floor(fmin(qhi, y1) - 0.5), fr->h - 1);
    const int lighten = m->region && m->region[e] != SP_REGION_OMEGA;
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        double X[3], xi[SP_Q1_MAX_DIM];
        X[a] = fr->mid[a];
        X[hx] = fr->lo[hx] + (i + 0.5 - fr->left[a]) / fr->s;
        X[vx] = fr->hi[vx] - (j + 0.5 - fr->top) / fr->s;
        if (!sp_hex_locate(xe, X, xi)) continue;
        double N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], v = 0;
        sp_q1_shape(3, xi, N, dN);
        const int *en = sp_mesh_elem_nodes(m, e);
        for (int n = 0; n < 8; ++n) v += N[n] * phi[en[n]];
        if (sum) { /* names: the pixel's cell, as the .vtu's cell_id */
          const int k = sp_section_cell(l, state, en, N);
          if (k >= 0) sum[3 * k] += i + 0.5, sum[3 * k + 1] += j + 0.5, sum[3 * k + 2] += 1;
        }
        double rgb[3];
        sp_jet(v, rgb);
        if (lighten)
          for (int c = 0; c < 3; ++c) rgb[c] = 0.55 * rgb[c] + 0.45;
        data[(size_t)j * stride + i] = sp_pixel(rgb);
      }
  }
}

/** Text with its left (@p align 0), centre (0.5) or right (1) at x, its
 *  baseline at y. */
static void sp_text(cairo_t *cr, double x, double y, double align, const char *text) {
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text, &ext);
  cairo_move_to(cr, x - align * ext.width - ext.x_bearing, y);
  cairo_show_text(cr, text);
}

/** The time, and each panel's frame, title (its plane) and axes (names and
 *  end values). */
static int sp_sections_labels(cairo_surface_t *surf, const sp_sections_frame *fr, double t) {
  cairo_t *cr = cairo_create(surf);
  char label[64];
  sp_time_label(cr, fr->left[0] - 3.5 * fr->font, 1.4 * fr->font, 1.2 * fr->font, t);
  cairo_set_line_width(cr, 1);
  for (int a = 0; a < 3; ++a) {
    const int hx = sp_section_axes[a][0], vx = sp_section_axes[a][1];
    const double x0 = fr->left[a], x1 = x0 + (fr->hi[hx] - fr->lo[hx]) * fr->s;
    const double y0 = fr->top, y1 = y0 + (fr->hi[vx] - fr->lo[vx]) * fr->s;
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    cairo_rectangle(cr, floor(x0) - 0.5, floor(y0) - 0.5, ceil(x1) - floor(x0) + 1,
                    ceil(y1) - floor(y0) + 1);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, 1.1 * fr->font);
    snprintf(label, sizeof label, "%s = %.3g", sp_axis_names[a], fr->mid[a]);
    sp_text(cr, 0.5 * (x0 + x1), y0 - 0.6 * fr->font, 0.5, label);
    cairo_set_font_size(cr, fr->font);
    /* horizontal axis: its ends' values, its name in the middle */
    snprintf(label, sizeof label, "%.3g", fr->lo[hx]);
    sp_text(cr, x0, y1 + 1.3 * fr->font, 0, label);
    snprintf(label, sizeof label, "%.3g", fr->hi[hx]);
    sp_text(cr, x1, y1 + 1.3 * fr->font, 1, label);
    sp_text(cr, 0.5 * (x0 + x1), y1 + 1.6 * fr->font, 0.5, sp_axis_names[hx]);
    /* vertical axis: the same on the panel's left */
    snprintf(label, sizeof label, "%.3g", fr->lo[vx]);
    sp_text(cr, x0 - 0.4 * fr->font, y1, 1, label);
    snprintf(label, sizeof label, "%.3g", fr->hi[vx]);
    sp_text(cr, x0 - 0.4 * fr->font, y0 + fr->font, 1, label);
    sp_text(cr, x0 - 0.6 * fr->font, 0.5 * (y0 + y1) + 0.4 * fr->font, 1, sp_axis_names[vx]);
  }
  const int rc = sp_cairo_check(cairo_status(cr), "drawing", "sections");
  cairo_destroy(cr);
  return rc;
}

int sp_render_sections(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path) {
  SP_CALL(sp_layout_check(mesh, layout));
  sp_sections_frame fr = {0};
  SP_CALL(sp_sections_frame_make(mesh, width_px, &fr));
  double *phi, *sum = NULL; /* names: each cell's pixel sums, per panel */
  SP_CALL(sp_phi_nodes(mesh, layout, state, &phi));
  cairo_surface_t *surf = NULL;
  int rc = sp_white_surface(fr.w, fr.h, path, &surf);
  if (rc == SP_OK && names && !(sum = calloc(9 * (size_t)layout->n_cells + 1, sizeof *sum)))
    rc = sp_error_set(SP_ERR_MEMORY, "out of memory labelling the cells");
  if (rc == SP_OK) {
    cairo_surface_flush(surf);
    uint32_t *data = (uint32_t *)cairo_image_surface_get_data(surf);
    const int stride = cairo_image_surface_get_stride(surf) / 4;
    for (int a = 0; a < 3; ++a)
      sp_section_fill(data, stride, &fr, a, mesh, phi, layout, state,
                      sum ? sum + 3 * (size_t)a * layout->n_cells : NULL);
    cairo_surface_mark_dirty(surf);
    rc = sp_sections_labels(surf, &fr, t);
  }
  if (rc == SP_OK && sum) { /* a name where its cell's section is at least a label's height */
    cairo_t *cr = cairo_create(surf);
    for (int a = 0; a < 3; ++a)
      sp_name_labels(cr, layout->n_cells, sum + 3 * (size_t)a * layout->n_cells,
                     fr.font * fr.font, fr.font, names);
    rc = sp_cairo_check(cairo_status(cr), "drawing", "sections");
    cairo_destroy(cr);
  }
  free(sum);
  free(phi);
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  cairo_surface_destroy(surf);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* 3D: the cells' surfaces seen by a fixed oblique camera                   */
/* ------------------------------------------------------------------------ */

/** The camera: orthographic, looking along @p view from the front right,
 *  above (azimuth 35 degrees from -y towards +x, elevation 25 degrees);
 *  a point X goes to pixel (ox + s (X - centre).right, oy - s (X - centre).up)
 *  at depth (X - centre).view. */
typedef struct {
  double right[3], up[3], view[3], light[3];
  double centre[3];
  double s, ox, oy;
  int w, h;
  double font;
} sp_camera;

static double sp_dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void sp_cross3(const double *a, const double *b, double *c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static void sp_normalise3(double *a) {
  const double n = sqrt(sp_dot3(a, a));
  if (n > 0)
    for (int d = 0; d < 3; ++d) a[d] /= n;
}

static void sp_camera_map(const sp_camera *cam, const double *x, double *px, double *py,
                          double *depth) {
  const double r[3] = {x[0] - cam->centre[0], x[1] - cam->centre[1], x[2] - cam->centre[2]};
  *px = cam->ox + cam->s * sp_dot3(r, cam->right);
  *py = cam->oy - cam->s * sp_dot3(r, cam->up);
  if (depth) *depth = sp_dot3(r, cam->view);
}

static int sp_camera_make(const sp_mesh *m, int width_px, sp_camera *cam) {
  SP_CHECK(m && m->dim == 3, SP_ERR_INTERNAL, "render: a 3D view needs a 3D mesh");
  SP_CALL(sp_width_check(width_px));
  double lo[3], hi[3];
  SP_CALL(sp_mesh_bbox(m, lo, hi));
  const double az = 35 * sp_pi / 180, el = 25 * sp_pi / 180;
  const double eye[3] = {sin(az) * cos(el), -cos(az) * cos(el), sin(el)}; /* towards the eye */
  const double z[3] = {0, 0, 1};
  for (int d = 0; d < 3; ++d) {
    cam->view[d] = -eye[d];
    cam->centre[d] = 0.5 * (lo[d] + hi[d]);
  }
  sp_cross3(cam->view, z, cam->right);
  sp_normalise3(cam->right);
  sp_cross3(cam->right, cam->view, cam->up);
  for (int d = 0; d < 3; ++d) /* one light, above and left of the eye */
    cam->light[d] = eye[d] + 0.6 * cam->up[d] - 0.4 * cam->right[d];
  sp_normalise3(cam->light);
  cam->s = 1;
  cam->ox = cam->oy = 0;
  double u0 = HUGE_VAL, u1 = -HUGE_VAL, v0 = HUGE_VAL, v1 = -HUGE_VAL;
  for (int i = 0; i < m->n_nodes; ++i) { /* the mesh's outline at scale 1 */
    double u, v;
    sp_camera_map(cam, m->xy + 3 * (size_t)i, &u, &v, NULL);
    u0 = fmin(u0, u), u1 = fmax(u1, u), v0 = fmin(v0, v), v1 = fmax(v1, v);
  }
  const double margin = width_px / 50 > 4 ? width_px / 50 : 4;
  cam->font = fmax(10.0, width_px / 45.0);
  const double band = ceil(1.8 * cam->font);
  cam->s = (width_px - 2 * margin) / (u1 - u0);
  cam->ox = margin - u0 * cam->s;
  cam->oy = band + margin - v0 * cam->s; /* v grows downwards here */
  const double h = ceil(band + 2 * margin + (v1 - v0) * cam->s);
  SP_CHECK(h <= 32768, SP_ERR_INPUT, "render: a %d px wide 3D view would be %.0f px high",
           width_px, h);
  cam->w = width_px;
  cam->h = (int)h;
  return SP_OK;
}

/** A flat polygon to draw: its corners in pixels, its depth (the centroid's;
 *  larger is farther) and its colour. */
typedef struct {
  float p[4][2];
  float depth;
  float rgb[3];
  int n; /**< 3 or 4 corners */
} sp_face2d;

typedef struct {
  sp_face2d *f;
  size_t n, cap;
} sp_faces2d;

/** Project the polygon @p x (n corners) and shade @p rgb by Lambert's law
 *  for its unit normal @p normal: ambient 0.3 plus 0.7 n.light. */
static int sp_faces2d_push(sp_faces2d *fs, const sp_camera *cam, int n, const double *x,
                           const double normal[3], const double rgb[3]) {
  if (fs->n == fs->cap) {
    size_t cap = fs->cap ? 2 * fs->cap : 4096;
    sp_face2d *f = realloc(fs->f, sizeof *f * cap);
    SP_CHECK(f, SP_ERR_MEMORY, "render: out of memory for %zu faces", cap);
    fs->f = f;
    fs->cap = cap;
  }
  sp_face2d *f = fs->f + fs->n++;
  double depth = 0;
  for (int a = 0; a < n; ++a) {
    double px, py, dz;
    sp_camera_map(cam, x + 3 * a, &px, &py, &dz);
    f->p[a][0] = (float)px;
    f->p[a][1] = (float)py;
    depth += dz / n;
  }
  f->n = n;
  f->depth = (float)depth;
  const double lambert = 0.3 + 0.7 * fmax(0.0, sp_dot3(normal, cam->light));
  for (int c = 0; c < 3; ++c) f->rgb[c] = (float)(lambert * rgb[c]);
  return SP_OK;
}

static int sp_cmp_far_first(const void *a, const void *b) {
  const float x = ((const sp_face2d *)a)->depth, y = ((const sp_face2d *)b)->depth;
  return (x < y) - (x > y);
}

/** Cell colours of the 3D view, cycled: distinct hues, none of them the
 *  background's white or the eggshell's grey. */
static const double sp_cell_palette[10][3] = {
    {0.86, 0.25, 0.20}, {0.22, 0.49, 0.85}, {0.30, 0.70, 0.30}, {0.95, 0.65, 0.15},
    {0.58, 0.38, 0.78}, {0.15, 0.70, 0.72}, {0.90, 0.45, 0.70}, {0.62, 0.62, 0.20},
    {0.60, 0.36, 0.22}, {0.45, 0.45, 0.55}};

/** The front-facing triangles of each cell's c = 1/2 surface, coloured
 *  per cell and shaded. */
static int sp_cell_faces(const sp_mesh *m, const sp_layout *l, const double *state,
                         const sp_camera *cam, sp_faces2d *fs) {
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(l, &cp));
  double *c;
  SP_ALLOC(c, m->n_nodes);
  sp_tris t = {NULL, 0, 0};
  int rc = SP_OK;
  for (int k = 0; k < l->n_cells && rc == SP_OK; ++k) {
    memset(c, 0, sizeof *c * (size_t)m->n_nodes); /* 0 off the cell's support */
    for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
      c[cp->cell_node[j]] = state[2 * (size_t)cp->cell_pair[j]];
    t.n = 0;
    rc = sp_level_surface(m, c, 0.5, &t);
    for (size_t i = 0; i < t.n && rc == SP_OK; ++i) {
      const double *x = t.xyz + 9 * i;
      double a[3], b[3], n[3];
      for (int d = 0; d < 3; ++d) a[d] = x[3 + d] - x[d], b[d] = x[6 + d] - x[d];
      sp_cross3(a, b, n);
      sp_normalise3(n);
      if (sp_dot3(n, cam->view) >= 0) continue; /* faces away: hidden by the front */
      rc = sp_faces2d_push(fs, cam, 3, x, n, sp_cell_palette[k % 10]);
    }
  }
  free(t.xyz);
  free(c);
  return rc;
}

/** A hexahedron face by its sorted global nodes, for finding the faces only
 *  one Omega element has. */
typedef struct {
  int key[4];
  int elem, face;
} sp_face_key;

static int sp_cmp_face_key(const void *a, const void *b) {
  const int *x = ((const sp_face_key *)a)->key, *y = ((const sp_face_key *)b)->key;
  for (int i = 0; i < 4; ++i)
    if (x[i] != y[i]) return (x[i] > y[i]) - (x[i] < y[i]);
  return 0;
}

/** Face @p f of element @p e, a quadrilateral of Omega's boundary turned
 *  outwards (away from the element's centre), to @p front if it faces the
 *  camera, else to @p back. */
static int sp_omega_face_push(const sp_mesh *m, int e, int f, const sp_camera *cam,
                              sp_faces2d *front, sp_faces2d *back) {
  static const double shell[3] = {0.70, 0.74, 0.80};
  const int *node = sp_mesh_elem_nodes(m, e);
  double x[4][3], xf[3] = {0, 0, 0}, xc[3] = {0, 0, 0};
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) xc[d] += 0.125 * m->xy[3 * (size_t)node[a] + d];
  for (int a = 0; a < 4; ++a)
    for (int d = 0; d < 3; ++d) {
      x[a][d] = m->xy[3 * (size_t)node[sp_hex_faces[f][a]] + d];
      xf[d] += 0.25 * x[a][d];
    }
  double d1[3], d2[3], n[3], out[3];
  for (int d = 0; d < 3; ++d) {
    d1[d] = x[2][d] - x[0][d];
    d2[d] = x[3][d] - x[1][d];
    out[d] = xf[d] - xc[d];
  }
  sp_cross3(d1, d2, n);
  sp_normalise3(n);
  if (sp_dot3(n, out) < 0)
    for (int d = 0; d < 3; ++d) n[d] = -n[d];
  return sp_faces2d_push(sp_dot3(n, cam->view) < 0 ? front : back, cam, 4, &x[0][0], n, shell);
}

/**
 * The boundary of Omega (the inner surface of the eggshell, or the box):
 * the faces of Omega elements that no other Omega element shares, as
 * quadrilaterals facing outwards; those facing the camera go to @p front,
 * the others to @p back.
 */
static int sp_omega_faces(const sp_mesh *m, const sp_camera *cam, sp_faces2d *front,
                          sp_faces2d *back) {
  sp_face_key *keys;
  SP_ALLOC(keys, 6 * (size_t)m->n_elems);
  size_t nk = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    if (m->region && m->region[e] != SP_REGION_OMEGA) continue;
    for (int f = 0; f < 6; ++f) {
      sp_face_key *k = keys + nk++;
      for (int j = 0; j < 4; ++j) {
        int v = sp_mesh_elem_nodes(m, e)[sp_hex_faces[f][j]], i = j;
        for (; i > 0 && k->key[i - 1] > v; --i) k->key[i] = k->key[i - 1];
        k->key[i] = v;
      }
      k->elem = e;
      k->face = f;
    }
  }
  qsort(keys, nk, sizeof *keys, sp_cmp_face_key);
  int rc = SP_OK;
  for (size_t i = 0; i < nk && rc == SP_OK;) {
    size_t j = i + 1;
    while (j < nk && sp_cmp_face_key(keys + j, keys + i) == 0) ++j;
    if (j - i == 1) rc = sp_omega_face_push(m, keys[i].elem, keys[i].face, cam, front, back);
    i = j;
  }
  free(keys);
  return rc;
}

/** Fill the polygons of @p fs in their order, without antialiasing (the
 *  polygons' own edges, antialiased, would let the background show
 *  through as seams between neighbours); with @p alpha < 1 as one
 *  translucent layer (drawn opaque into a group, painted with alpha, so
 *  their shared edges do not show). */
static void sp_faces2d_fill(cairo_t *cr, const sp_faces2d *fs, double alpha) {
  const cairo_antialias_t antialias = cairo_get_antialias(cr);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  if (alpha < 1) cairo_push_group(cr);
  for (size_t i = 0; i < fs->n; ++i) {
    const sp_face2d *f = fs->f + i;
    cairo_move_to(cr, f->p[0][0], f->p[0][1]);
    for (int a = 1; a < f->n; ++a) cairo_line_to(cr, f->p[a][0], f->p[a][1]);
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, f->rgb[0], f->rgb[1], f->rgb[2]);
    cairo_fill(cr);
  }
  if (alpha < 1) {
    cairo_pop_group_to_source(cr);
    cairo_paint_with_alpha(cr, alpha);
  }
  cairo_set_antialias(cr, antialias);
}

/** The axes' directions in a corner, so the oblique view can be read. */
static void sp_axes_triad(cairo_t *cr, const sp_camera *cam) {
  const double len = 2.2 * cam->font;
  const double ox = cam->w - 2.2 * len, oy = cam->h - 1.6 * len;
  cairo_set_line_width(cr, fmax(1.0, cam->w / 500.0));
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 0.9 * cam->font);
  for (int d = 0; d < 3; ++d) {
    const double e[3] = {d == 0, d == 1, d == 2};
    const double ex = sp_dot3(e, cam->right), ey = -sp_dot3(e, cam->up);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    cairo_move_to(cr, ox, oy);
    cairo_line_to(cr, ox + len * ex, oy + len * ey);
    cairo_stroke(cr);
    sp_text(cr, ox + 1.3 * len * ex, oy + 1.3 * len * ey + 0.35 * cam->font, 0.5,
            sp_axis_names[d]);
  }
}

/** The legend of a named scene's 3D view: each cell's colour (a square)
 *  and name, in rows across the picture, in a strip below the view. Lays
 *  the items out from the top of the strip @p y0 and returns the strip's
 *  height; draws them only if @p draw. */
static double sp_legend(cairo_t *cr, const sp_camera *cam, int n_cells, const sp_cell_name *names,
                        double y0, int draw) {
  const double font = cam->font, row = 1.5 * font, margin = cam->w / 50.0;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, font);
  double x = margin, y = y0 + 0.5 * font;
  for (int k = 0; k < n_cells; ++k) {
    char buf[16];
    const char *text = sp_cell_label(names, k, buf);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text, &ext);
    const double item = 0.8 * font + 0.4 * font + ext.x_advance;
    if (x > margin && x + item > cam->w - margin) x = margin, y += row; /* next row */
    if (draw) {
      const double *rgb = sp_cell_palette[k % 10];
      cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
      cairo_rectangle(cr, round(x), round(y + 0.2 * font), round(0.8 * font), round(0.8 * font));
      cairo_fill(cr);
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_move_to(cr, x + 1.2 * font, y + font);
      cairo_show_text(cr, text);
    }
    x += item + 1.2 * font;
  }
  return ceil(y + row + margin - y0);
}

static int sp_draw_surfaces(cairo_surface_t *surf, const sp_camera *cam, sp_faces2d fs[3],
                            double t, int n_cells, const sp_cell_name *names) {
  cairo_t *cr = cairo_create(surf);
  sp_faces2d_fill(cr, &fs[0], 0.3);  /* the far side of the eggshell */
  sp_faces2d_fill(cr, &fs[1], 1.0);  /* the cells, far to near */
  sp_faces2d_fill(cr, &fs[2], 0.12); /* the near side, over them */
  sp_axes_triad(cr, cam);
  sp_time_label(cr, cam->w / 50.0, 1.3 * cam->font, cam->font, t);
  if (names) sp_legend(cr, cam, n_cells, names, cam->h, 1);
  const int rc = sp_cairo_check(cairo_status(cr), "drawing", "surfaces");
  cairo_destroy(cr);
  return rc;
}

/** The height of the 3D view's legend strip (0 without names). */
static int sp_legend_height(const sp_camera *cam, int n_cells, const sp_cell_name *names,
                            const char *path, int *height) {
  *height = 0;
  if (!names) return SP_OK;
  cairo_surface_t *scratch = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
  cairo_t *cr = cairo_create(scratch);
  *height = (int)sp_legend(cr, cam, n_cells, names, 0, 0);
  const int rc = sp_cairo_check(cairo_status(cr), "measuring the legend", path);
  cairo_destroy(cr);
  cairo_surface_destroy(scratch);
  return rc;
}

int sp_render_surfaces_pixel(const sp_mesh *mesh, int width_px, const double *x, double *px,
                             double *py, int *height_px) {
  sp_camera cam = {0};
  SP_CALL(sp_camera_make(mesh, width_px, &cam));
  double u, v;
  sp_camera_map(&cam, x, &u, &v, NULL);
  sp_pixel_out(u, v, cam.h, px, py, height_px);
  return SP_OK;
}

int sp_render_surfaces(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path) {
  SP_CALL(sp_layout_check(mesh, layout));
  sp_camera cam = {0};
  SP_CALL(sp_camera_make(mesh, width_px, &cam));
  sp_faces2d fs[3] = {{NULL, 0, 0}, {NULL, 0, 0}, {NULL, 0, 0}}; /* back shell, cells, front */
  int rc = sp_omega_faces(mesh, &cam, &fs[2], &fs[0]);
  if (rc == SP_OK) rc = sp_cell_faces(mesh, layout, state, &cam, &fs[1]);
  cairo_surface_t *surf = NULL;
  if (rc == SP_OK) {
    for (int i = 0; i < 3; ++i)
      if (fs[i].n) qsort(fs[i].f, fs[i].n, sizeof *fs[i].f, sp_cmp_far_first);
    int legend = 0;
    rc = sp_legend_height(&cam, layout->n_cells, names, path, &legend);
    if (rc == SP_OK) rc = sp_white_surface(cam.w, cam.h + legend, path, &surf);
  }
  if (rc == SP_OK) rc = sp_draw_surfaces(surf, &cam, fs, t, layout->n_cells, names);
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  for (int i = 0; i < 3; ++i) free(fs[i].f);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* Contact graph                                                            */
/* ------------------------------------------------------------------------ */

/** The frame of a picture of either dimension: the cells picture's (2D) or
 *  the 3D view's camera. */
typedef struct {
  const sp_frame *fr;   /**< 2D, else NULL */
  const sp_camera *cam; /**< 3D, else NULL */
  double s, font;       /**< pixels per unit length, font size */
} sp_view;

/** Pixel of the point @p x (the mesh's dim coordinates) and its depth (0 in
 *  2D). */
static void sp_view_map(const sp_view *v, const double *x, double *px, double *py,
                        double *depth) {
  if (v->fr) {
    sp_frame_map(v->fr, x[0], x[1], px, py);
    *depth = 0;
  } else {
    sp_camera_map(v->cam, x, px, py, depth);
  }
}

/** A cell of the contact graph, for drawing the discs far to near. */
typedef struct {
  double px, py, depth;
  int k;
} sp_graph_node;

static int sp_cmp_node_far_first(const void *a, const void *b) {
  const sp_graph_node *x = a, *y = b;
  if (x->depth != y->depth) return (x->depth < y->depth) - (x->depth > y->depth);
  return (x->k > y->k) - (x->k < y->k);
}

/** The graph on a white surface: the edges, then the numbered discs on top
 *  (in 3D far to near). */
static int sp_draw_contact_graph(cairo_t *cr, const sp_view *v, int dim, int n_cells,
                                 const double *centre, int n_edges, const int *edge,
                                 const double *length, double lw) {
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_source_rgba(cr, 0.15, 0.3, 0.7, 0.8);
  for (int j = 0; j < n_edges; ++j) {
    double ax, ay, bx, by, depth;
    sp_view_map(v, centre + dim * edge[2 * j], &ax, &ay, &depth);
    sp_view_map(v, centre + dim * edge[2 * j + 1], &bx, &by, &depth);
    /* a quarter of the contact's length (in 3D of the side of a square of
     * its area) at the picture's scale */
    const double size = dim == 3 ? sqrt(length[j]) : length[j];
    cairo_set_line_width(cr, fmax(1.0, 0.25 * size * v->s));
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, bx, by);
    cairo_stroke(cr);
  }
  sp_graph_node *node;
  SP_ALLOC(node, n_cells);
  for (int k = 0; k < n_cells; ++k) {
    node[k].k = k;
    sp_view_map(v, centre + dim * k, &node[k].px, &node[k].py, &node[k].depth);
  }
  if (dim == 3) qsort(node, n_cells, sizeof *node, sp_cmp_node_far_first);
  const double radius = 0.8 * v->font;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 0.9 * v->font);
  for (int i = 0; i < n_cells; ++i) {
    const double x = node[i].px, y = node[i].py;
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, radius, 0, 2 * sp_pi);
    cairo_set_source_rgb(cr, 0.85, 0.15, 0.1);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, lw);
    cairo_stroke(cr);
    char label[16];
    snprintf(label, sizeof label, "%d", node[i].k + 1); /* numbered from 1, as in cells.csv */
    cairo_text_extents_t ext;
    cairo_text_extents(cr, label, &ext);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_move_to(cr, x - ext.width / 2 - ext.x_bearing, y - ext.height / 2 - ext.y_bearing);
    cairo_show_text(cr, label);
  }
  free(node);
  return sp_cairo_check(cairo_status(cr), "drawing", "contact graph");
}

int sp_render_contact_graph(const sp_mesh *mesh, int n_cells, const double *centre,
                            int n_edges, const int *edge, const double *length, double t,
                            int width_px, const char *path) {
  for (int j = 0; j < n_edges; ++j)
    SP_CHECK(edge[2 * j] >= 0 && edge[2 * j] < n_cells && edge[2 * j + 1] >= 0 &&
                 edge[2 * j + 1] < n_cells,
             SP_ERR_INTERNAL, "render: contact %d joins cells %d and %d of %d", j, edge[2 * j],
             edge[2 * j + 1], n_cells);
  const int dim = mesh->dim;
  sp_frame fr = {0};
  sp_camera cam = {0};
  sp_view v = {NULL, NULL, 0, 0};
  sp_faces2d shell[2] = {{NULL, 0, 0}, {NULL, 0, 0}}; /* 3D: Omega's far and near sides */
  if (dim == 3) {
    SP_CALL(sp_camera_make(mesh, width_px, &cam));
    v = (sp_view){NULL, &cam, cam.s, cam.font};
  } else {
    SP_CALL(sp_frame_make(mesh, width_px, &fr));
    v = (sp_view){&fr, NULL, fr.s, fr.font};
  }
  const int w = dim == 3 ? cam.w : fr.w, h = dim == 3 ? cam.h : fr.h;
  const double lw = fmax(1.0, w / 700.0);
  cairo_surface_t *surf = NULL;
  int rc = dim == 3 ? sp_omega_faces(mesh, &cam, &shell[1], &shell[0]) : SP_OK;
  if (rc == SP_OK) rc = sp_white_surface(w, h, path, &surf);
  if (rc == SP_OK) {
    cairo_t *cr = cairo_create(surf);
    if (dim == 3) {
      for (int i = 0; i < 2; ++i)
        if (shell[i].n) qsort(shell[i].f, shell[i].n, sizeof *shell[i].f, sp_cmp_far_first);
      sp_faces2d_fill(cr, &shell[0], 0.3);
      sp_time_label(cr, w / 50.0, 1.3 * cam.font, cam.font, t);
    } else {
      rc = sp_outline_and_time(cr, mesh, &fr, lw, t, "contact graph");
    }
    if (rc == SP_OK)
      rc = sp_draw_contact_graph(cr, &v, dim, n_cells, centre, n_edges, edge, length, lw);
    if (rc == SP_OK && dim == 3) {
      sp_faces2d_fill(cr, &shell[1], 0.12);
      sp_axes_triad(cr, &cam);
      rc = sp_cairo_check(cairo_status(cr), "drawing", path);
    }
    cairo_destroy(cr);
  }
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  for (int i = 0; i < 2; ++i) free(shell[i].f);
  return rc;
}
