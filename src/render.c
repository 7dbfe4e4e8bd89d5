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

#include "render.h"

#include <cairo.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"

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

static int sp_frame_make(const sp_mesh *m, int width_px, sp_frame *fr) {
  SP_CHECK(m && m->n_nodes > 0 && m->xy, SP_ERR_INTERNAL,
           "render: empty mesh");
  SP_CHECK(width_px >= 16 && width_px <= 16384, SP_ERR_INPUT,
           "render: picture width %d px is outside [16, 16384]", width_px);
  /* The bounding box of the nodes, not mesh->bounds: with a buffer ring
   * the mesh reaches beyond Omega. */
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
  for (int i = 0; i < m->n_nodes; ++i) {
    double x = m->xy[2 * i], y = m->xy[2 * i + 1];
    x0 = fmin(x0, x);
    x1 = fmax(x1, x);
    y0 = fmin(y0, y);
    y1 = fmax(y1, y);
  }
  SP_CHECK(isfinite(x0) && isfinite(x1) && isfinite(y0) && isfinite(y1) &&
               x1 > x0 && y1 > y0,
           SP_ERR_INTERNAL, "render: degenerate mesh bounding box "
           "[%g, %g] x [%g, %g]", x0, x1, y0, y1);
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
  sp_frame fr;
  SP_CALL(sp_frame_make(mesh, width_px, &fr));
  double u, v;
  sp_frame_map(&fr, x, y, &u, &v);
  if (px) *px = u;
  if (py) *py = v;
  if (height_px) *height_px = fr.h;
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
    for (int a = 0; a < 4; ++a) {
      uint32_t u = (uint32_t)m->elem[4 * e + a];
      uint32_t v = (uint32_t)m->elem[4 * e + (a + 1) % 4];
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

/** The outline of Omega (line width 1.5 @p lw) and the time in the white
 *  strip above the picture: what every picture on the cells' frame has. */
static int sp_outline_and_time(cairo_t *cr, const sp_mesh *m, const sp_frame *fr, double lw,
                               double t, const char *what) {
  SP_CALL(sp_omega_outline(cr, m, fr));
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_set_line_width(cr, 1.5 * lw);
  cairo_stroke(cr);
  char label[64];
  snprintf(label, sizeof label, "t = %.2e", t);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, fr->font);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, fr->ox, 1.3 * fr->font);
  cairo_show_text(cr, label);
  return sp_cairo_check(cairo_status(cr), "drawing", what);
}

/** Everything drawn on an existing white RGB24 surface. */
static int sp_draw_cells(cairo_surface_t *surf, const sp_frame *fr,
                         const sp_mesh *m, const sp_layout *l,
                         const double *state, double t) {
  /* phi at the nodes: the max over the cells supported there. */
  double *phi;
  SP_ALLOC(phi, m->n_nodes);
  for (int i = 0; i < m->n_nodes; ++i) {
    double v = 0.0;
    for (int p = l->node_start[i]; p < l->node_start[i + 1]; ++p)
      if (state[2 * p] > v || isnan(state[2 * p])) v = state[2 * p];
    phi[i] = v;
  }

  cairo_surface_flush(surf);
  uint32_t *data = (uint32_t *)cairo_image_surface_get_data(surf);
  int stride = cairo_image_surface_get_stride(surf) / 4;
  for (int e = 0; e < m->n_elems; ++e) {
    int lighten = m->region && m->region[e] != SP_REGION_OMEGA;
    for (int tri = 0; tri < 2; ++tri) {
      double P[3][2], v[3];
      for (int a = 0; a < 3; ++a) {
        int n = m->elem[4 * e + sp_quad_tris[tri][a]];
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
          int n = m->elem[4 * e + sp_quad_tris[tri][a]];
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
  cairo_destroy(cr);
  return rc;
}

int sp_render_cells(const sp_mesh *mesh, const sp_layout *layout,
                    const double *state, double t, int width_px,
                    const char *path) {
  SP_CHECK(mesh->dim == 2, SP_ERR_INPUT,
           "render: pictures are not yet on a 3D mesh (issue 29)");
  SP_CHECK(layout && layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "render: mesh has %d nodes but layout has %d", mesh->n_nodes,
           layout ? layout->n_nodes : -1);
  sp_frame fr;
  SP_CALL(sp_frame_make(mesh, width_px, &fr));
  cairo_surface_t *surf =
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, fr.w, fr.h);
  int rc = sp_cairo_check(cairo_surface_status(surf), "creating a surface",
                          path);
  if (rc == SP_OK) {
    /* White first: whatever the mesh does not cover stays white. */
    cairo_t *cr = cairo_create(surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_destroy(cr);
    rc = sp_draw_cells(surf, &fr, mesh, layout, state, t);
  }
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  cairo_surface_destroy(surf);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* Contact graph                                                            */
/* ------------------------------------------------------------------------ */

/** The graph on a white surface: the outline and the time, then the
 *  edges, then the numbered discs on top. */
static int sp_draw_contact_graph(cairo_t *cr, const sp_frame *fr, const sp_mesh *m,
                                 int n_cells, const double *centre, int n_edges,
                                 const int *edge, const double *length, double t) {
  const double lw = fmax(1.0, fr->w / 700.0);
  SP_CALL(sp_outline_and_time(cr, m, fr, lw, t, "contact graph"));
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_source_rgba(cr, 0.15, 0.3, 0.7, 0.8);
  for (int j = 0; j < n_edges; ++j) {
    double ax, ay, bx, by;
    sp_frame_map(fr, centre[2 * edge[2 * j]], centre[2 * edge[2 * j] + 1], &ax, &ay);
    sp_frame_map(fr, centre[2 * edge[2 * j + 1]], centre[2 * edge[2 * j + 1] + 1], &bx, &by);
    /* a quarter of the contact's length at the picture's scale */
    cairo_set_line_width(cr, fmax(1.0, 0.25 * length[j] * fr->s));
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, bx, by);
    cairo_stroke(cr);
  }
  const double radius = 0.8 * fr->font;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr, 0.9 * fr->font);
  for (int k = 0; k < n_cells; ++k) {
    double x, y;
    sp_frame_map(fr, centre[2 * k], centre[2 * k + 1], &x, &y);
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, radius, 0, 2 * sp_pi);
    cairo_set_source_rgb(cr, 0.85, 0.15, 0.1);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, lw);
    cairo_stroke(cr);
    char label[16];
    snprintf(label, sizeof label, "%d", k + 1); /* cells numbered from 1, as in cells.csv */
    cairo_text_extents_t ext;
    cairo_text_extents(cr, label, &ext);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_move_to(cr, x - ext.width / 2 - ext.x_bearing, y - ext.height / 2 - ext.y_bearing);
    cairo_show_text(cr, label);
  }
  return sp_cairo_check(cairo_status(cr), "drawing", "contact graph");
}

int sp_render_contact_graph(const sp_mesh *mesh, int n_cells, const double *centre,
                            int n_edges, const int *edge, const double *length, double t,
                            int width_px, const char *path) {
  SP_CHECK(mesh->dim == 2, SP_ERR_INPUT,
           "render: pictures are not yet on a 3D mesh (issue 29)");
  for (int j = 0; j < n_edges; ++j)
    SP_CHECK(edge[2 * j] >= 0 && edge[2 * j] < n_cells && edge[2 * j + 1] >= 0 &&
                 edge[2 * j + 1] < n_cells,
             SP_ERR_INTERNAL, "render: contact %d joins cells %d and %d of %d", j, edge[2 * j],
             edge[2 * j + 1], n_cells);
  sp_frame fr;
  SP_CALL(sp_frame_make(mesh, width_px, &fr));
  cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, fr.w, fr.h);
  int rc = sp_cairo_check(cairo_surface_status(surf), "creating a surface", path);
  if (rc == SP_OK) {
    cairo_t *cr = cairo_create(surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    rc = sp_draw_contact_graph(cr, &fr, mesh, n_cells, centre, n_edges, edge, length, t);
    cairo_destroy(cr);
  }
  if (rc == SP_OK) rc = sp_png_write(surf, path);
  cairo_surface_destroy(surf);
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
