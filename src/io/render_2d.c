/* render_2d.c: the cells picture of a 2D state (phi, membranes, Omega's outline, names). */
/*
 * The field is rasterised by hand into the image surface's pixels: each quad
 * is split into two triangles and every pixel centre inside a triangle gets
 * the colour of the linearly interpolated phi. Cairo's gradient meshes could
 * do the same, but per-pixel colouring is exact (no banding, no seams between
 * triangles) and costs one pass over the pixels each triangle covers. The
 * lines and text are then drawn with cairo on top.
 */
#define _POSIX_C_SOURCE 200809L

#include "io/render.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "public/error.h"
#include "io/render_base.h"

int sp_render_cells_pixel(const sp_mesh *mesh, int width_px, double x,
                          double y, double *px, double *py, int *height_px) {
  sp_render_frame fr = {0};
  SP_CALL(sp_render_frame_make(mesh, width_px, &fr));
  double u, v;
  sp_render_frame_map(&fr, x, y, &u, &v);
  sp_render_pixel_out(u, v, fr.h, px, py, height_px);
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
      sp_render_jet(l0 * v[0] + l1 * v[1] + l2 * v[2], rgb);
      if (lighten) /* the buffer ring: same colours, washed out */
        for (int c = 0; c < 3; ++c) rgb[c] = 0.55 * rgb[c] + 0.45;
      row[i] = sp_render_rgb24(rgb);
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

/** Everything drawn on an existing white RGB24 surface. */
static int sp_draw_cells(cairo_surface_t *surf, const sp_render_frame *fr,
                         const sp_mesh *m, const sp_layout *l,
                         const double *state, double t, const sp_cell_name *names) {
  /* phi at the nodes: the max over the cells supported there. */
  double *phi;
  SP_CALL(sp_render_phi_nodes(m, l, state, &phi));

  cairo_surface_flush(surf);
  uint32_t *data = (uint32_t *)cairo_image_surface_get_data(surf);
  int stride = cairo_image_surface_get_stride(surf) / 4;
  for (int e = 0; e < m->n_elems; ++e) {
    int lighten = m->region && m->region[e] != SP_REGION_OMEGA;
    for (int tri = 0; tri < 2; ++tri) {
      double P[3][2], v[3];
      for (int a = 0; a < 3; ++a) {
        int n = sp_mesh_elem_nodes(m, e)[sp_quad_tris[tri][a]];
        sp_render_frame_map(fr, m->xy[2 * n], m->xy[2 * n + 1], &P[a][0], &P[a][1]);
        v[a] = phi[n];
      }
      sp_fill_triangle(data, stride, fr->w, fr->h, P, v, lighten);
    }
  }
  free(phi);
  cairo_surface_mark_dirty(surf);

  cairo_t *cr = cairo_create(surf);
  int rc = sp_render_cairo_check(cairo_status(cr), "creating a context", "cells");
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
          sp_render_frame_map(fr, m->xy[2 * n], m->xy[2 * n + 1], &P[a][0], &P[a][1]);
          c[a] = sp_c_at(l, state, k, n);
          any |= c[a] >= 0.5;
        }
        if (any) sp_contour_triangle(cr, P, c, 0.5);
      }
    cairo_stroke(cr);
  }

  rc = sp_render_outline_and_time(cr, m, fr, lw, t, "cells");
  if (rc == SP_OK && names) { /* each name at the mean of its cell's nodes */
    double *sum = calloc(3 * (size_t)l->n_cells + 1, sizeof *sum);
    if (!sum) rc = sp_error_set(SP_ERR_MEMORY, "out of memory labelling the cells");
    for (int i = 0; rc == SP_OK && i < m->n_nodes; ++i) {
      const int k = sp_layout_node_cell(l, state, i);
      if (k < 0) continue;
      double px, py;
      sp_render_frame_map(fr, m->xy[2 * i], m->xy[2 * i + 1], &px, &py);
      sum[3 * k] += px, sum[3 * k + 1] += py, sum[3 * k + 2] += 1;
    }
    if (rc == SP_OK) sp_render_name_labels(cr, l->n_cells, sum, 0, fr->font, names);
    free(sum);
    if (rc == SP_OK) rc = sp_render_cairo_check(cairo_status(cr), "drawing", "cells");
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
  SP_CALL(sp_render_layout_check(mesh, layout));
  sp_render_frame fr = {0};
  SP_CALL(sp_render_frame_make(mesh, width_px, &fr));
  /* White first: whatever the mesh does not cover stays white. */
  cairo_surface_t *surf = NULL;
  int rc = sp_render_white_surface(fr.w, fr.h, path, &surf);
  if (rc == SP_OK) rc = sp_draw_cells(surf, &fr, mesh, layout, state, t, names);
  if (rc == SP_OK) rc = sp_render_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  return rc;
}
