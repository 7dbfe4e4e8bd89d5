/* render_sections.c: the three mid-plane sections of a 3D state, side by side. */
#define _POSIX_C_SOURCE 200809L

#include "io/render.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "public/error.h"
#include "io/render_base.h"

/** Panel a of the sections picture is the plane x_a = the box's middle,
 *  seen with axis [a][0] to the right and axis [a][1] up. */
static const int sp_section_axes[3][2] = {{1, 2}, {0, 2}, {0, 1}};

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
  SP_CALL(sp_render_width_check(width_px));
  SP_CALL(sp_render_mesh_bbox(m, fr->lo, fr->hi));
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
  sp_render_pixel_out(u, v, fr.h, px, py, height_px);
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
 * each pixel to its cell's sums (sp_render_name_labels).
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
        sp_render_jet(v, rgb);
        if (lighten)
          for (int c = 0; c < 3; ++c) rgb[c] = 0.55 * rgb[c] + 0.45;
        data[(size_t)j * stride + i] = sp_render_rgb24(rgb);
      }
  }
}

/** The time, and each panel's frame, title (its plane) and axes (names and
 *  end values). */
static int sp_sections_labels(cairo_surface_t *surf, const sp_sections_frame *fr, double t) {
  cairo_t *cr = cairo_create(surf);
  char label[64];
  sp_render_time_label(cr, fr->left[0] - 3.5 * fr->font, 1.4 * fr->font, 1.2 * fr->font, t);
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
    snprintf(label, sizeof label, "%s = %.3g", sp_render_axis_names[a], fr->mid[a]);
    sp_render_text(cr, 0.5 * (x0 + x1), y0 - 0.6 * fr->font, 0.5, label);
    cairo_set_font_size(cr, fr->font);
    /* horizontal axis: its ends' values, its name in the middle */
    snprintf(label, sizeof label, "%.3g", fr->lo[hx]);
    sp_render_text(cr, x0, y1 + 1.3 * fr->font, 0, label);
    snprintf(label, sizeof label, "%.3g", fr->hi[hx]);
    sp_render_text(cr, x1, y1 + 1.3 * fr->font, 1, label);
    sp_render_text(cr, 0.5 * (x0 + x1), y1 + 1.6 * fr->font, 0.5, sp_render_axis_names[hx]);
    /* vertical axis: the same on the panel's left */
    snprintf(label, sizeof label, "%.3g", fr->lo[vx]);
    sp_render_text(cr, x0 - 0.4 * fr->font, y1, 1, label);
    snprintf(label, sizeof label, "%.3g", fr->hi[vx]);
    sp_render_text(cr, x0 - 0.4 * fr->font, y0 + fr->font, 1, label);
    sp_render_text(cr, x0 - 0.6 * fr->font, 0.5 * (y0 + y1) + 0.4 * fr->font, 1,
                   sp_render_axis_names[vx]);
  }
  const int rc = sp_render_cairo_check(cairo_status(cr), "drawing", "sections");
  cairo_destroy(cr);
  return rc;
}

int sp_render_sections(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path) {
  SP_CALL(sp_render_layout_check(mesh, layout));
  sp_sections_frame fr = {0};
  SP_CALL(sp_sections_frame_make(mesh, width_px, &fr));
  double *phi, *sum = NULL; /* names: each cell's pixel sums, per panel */
  SP_CALL(sp_render_phi_nodes(mesh, layout, state, &phi));
  cairo_surface_t *surf = NULL;
  int rc = sp_render_white_surface(fr.w, fr.h, path, &surf);
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
      sp_render_name_labels(cr, layout->n_cells, sum + 3 * (size_t)a * layout->n_cells,
                            fr.font * fr.font, fr.font, names);
    rc = sp_render_cairo_check(cairo_status(cr), "drawing", "sections");
    cairo_destroy(cr);
  }
  free(sum);
  free(phi);
  if (rc == SP_OK) rc = sp_render_png_write(surf, path);
  cairo_surface_destroy(surf);
  return rc;
}
