/* render_contacts.c: the contact graph: numbered discs at the cells' centres, lines between them. */
#define _POSIX_C_SOURCE 200809L

#include "io/render.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "public/error.h"
#include "io/render_base.h"
#include "io/render_surfaces.h"

/** The frame of a picture of either dimension: the cells picture's (2D) or
 *  the 3D view's camera. */
typedef struct {
  const sp_render_frame *fr;   /**< 2D, else NULL */
  const sp_render_camera *cam; /**< 3D, else NULL */
  double s, font;       /**< pixels per unit length, font size */
} sp_view;

/** Pixel of the point @p x (the mesh's dim coordinates) and its depth (0 in
 *  2D). */
static void sp_view_map(const sp_view *v, const double *x, double *px, double *py,
                        double *depth) {
  if (v->fr) {
    sp_render_frame_map(v->fr, x[0], x[1], px, py);
    *depth = 0;
  } else {
    sp_render_camera_map(v->cam, x, px, py, depth);
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
    cairo_arc(cr, x, y, radius, 0, 2 * SP_RENDER_PI);
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
  return sp_render_cairo_check(cairo_status(cr), "drawing", "contact graph");
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
  sp_render_frame fr = {0};
  sp_render_camera cam = {0};
  sp_view v = {NULL, NULL, 0, 0};
  sp_render_faces2d shell[2] = {{NULL, 0, 0}, {NULL, 0, 0}}; /* 3D: Omega's far and near sides */
  if (dim == 3) {
    SP_CALL(sp_render_camera_make(mesh, width_px, &cam));
    v = (sp_view){NULL, &cam, cam.s, cam.font};
  } else {
    SP_CALL(sp_render_frame_make(mesh, width_px, &fr));
    v = (sp_view){&fr, NULL, fr.s, fr.font};
  }
  const int w = dim == 3 ? cam.w : fr.w, h = dim == 3 ? cam.h : fr.h;
  const double lw = fmax(1.0, w / 700.0);
  cairo_surface_t *surf = NULL;
  int rc = dim == 3 ? sp_render_omega_faces(mesh, &cam, &shell[1], &shell[0]) : SP_OK;
  if (rc == SP_OK) rc = sp_render_white_surface(w, h, path, &surf);
  if (rc == SP_OK) {
    cairo_t *cr = cairo_create(surf);
    if (dim == 3) {
      for (int i = 0; i < 2; ++i)
        if (shell[i].n) qsort(shell[i].f, shell[i].n, sizeof *shell[i].f, sp_render_cmp_far_first);
      sp_render_faces2d_fill(cr, &shell[0], 0.3);
      sp_render_time_label(cr, w / 50.0, 1.3 * cam.font, cam.font, t);
    } else {
      rc = sp_render_outline_and_time(cr, mesh, &fr, lw, t, "contact graph");
    }
    if (rc == SP_OK)
      rc = sp_draw_contact_graph(cr, &v, dim, n_cells, centre, n_edges, edge, length, lw);
    if (rc == SP_OK && dim == 3) {
      sp_render_faces2d_fill(cr, &shell[1], 0.12);
      sp_render_axes_triad(cr, &cam);
      rc = sp_render_cairo_check(cairo_status(cr), "drawing", path);
    }
    cairo_destroy(cr);
  }
  if (rc == SP_OK) rc = sp_render_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  for (int i = 0; i < 2; ++i) free(shell[i].f);
  return rc;
}
