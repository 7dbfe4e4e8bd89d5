/* render_base.h: the drawing base the renderers of io/ share (private to io/). */
/*
 * What more than one picture of render.h draws with: writing a PNG file
 * whole, cairo's errors, the jet colour map and RGB24 pixels, the white
 * surface, text and cell labels, the time label, the mesh's bounding box
 * and the 2D frame (the cells picture's, which the contact graph shares)
 * with the outline of Omega. Each renderer has its own file:
 * render_2d.c (the cells picture), render_plot.c (energy.png),
 * render_sections.c (3D mid-plane sections), render_surfaces.c (level
 * surfaces and the 3D view; its camera and painter in render_surfaces.h)
 * and render_contacts.c (the contact graph).
 */
#ifndef SP_RENDER_BASE_H
#define SP_RENDER_BASE_H

#include <cairo.h>
#include <stdint.h>

#include "io/render.h"

/* pi is not in strict C11. */
#define SP_RENDER_PI 3.14159265358979323846

/** Write @p surf as PNG to "<path>.tmp", then rename it to @p path. */
int sp_render_png_write(cairo_surface_t *surf, const char *path);

/** Turn a failed cairo context or surface into an error code. */
int sp_render_cairo_check(cairo_status_t st, const char *what, const char *path);

/** The "jet" colour map of @p v in [0, 1] (clamped; NaN grey). */
void sp_render_jet(double v, double rgb[3]);

/** An opaque pixel of a CAIRO_FORMAT_RGB24 surface. */
uint32_t sp_render_rgb24(const double rgb[3]);

/** A white RGB24 surface of w x h pixels, or an error. */
int sp_render_white_surface(int w, int h, const char *path, cairo_surface_t **out);

/** The layout is one of the mesh's nodes. */
int sp_render_layout_check(const sp_mesh *mesh, const sp_layout *layout);

/** The outputs of the *_pixel functions (any pointer may be NULL). */
void sp_render_pixel_out(double u, double v, int h, double *px, double *py, int *height_px);

/** Cell k's label (from 0): its name, or its number (from 1). */
const char *sp_render_cell_label(const sp_cell_name *names, int k, char buf[16]);

/** Label each cell k with sum[3 k + 2] > @p min_count at its mean pixel
 *  (sum[3 k] / n, sum[3 k + 1] / n, n = sum[3 k + 2]): bold black letters
 *  on a white halo. */
void sp_render_name_labels(cairo_t *cr, int n_cells, const double *sum, double min_count,
                           double font, const sp_cell_name *names);

/** Text with its left (@p align 0), centre (0.5) or right (1) at x, its
 *  baseline at y. */
void sp_render_text(cairo_t *cr, double x, double y, double align, const char *text);

/** "t = ..." in black, its baseline starting at (x, y). */
void sp_render_time_label(cairo_t *cr, double x, double y, double font, double t);

/** The axes' names, x, y and z. */
extern const char *const sp_render_axis_names[3];

/** The bounding box lo[d] .. hi[d] (d < mesh->dim; the rest 0) of the
 *  mesh's nodes. */
int sp_render_mesh_bbox(const sp_mesh *m, double lo[3], double hi[3]);

/** The picture width @p width_px is one the renderers draw. */
int sp_render_width_check(int width_px);

/** phi = max_k c_k at the nodes (malloc'd in *out; NaN wins). */
int sp_render_phi_nodes(const sp_mesh *m, const sp_layout *l, const double *state,
                        double **out);

/** World-to-pixel map of the cells picture (2D; the contact graph's too). */
typedef struct {
  double x0, y1;  /**< left and top of the mesh's bounding box */
  double s;       /**< pixels per unit length */
  double ox, oy;  /**< pixel position of (x0, y1) */
  int w, h;       /**< picture size */
  double font;    /**< font size of the time label */
} sp_render_frame;

/** The frame of a 2D mesh's picture @p width_px wide. */
int sp_render_frame_make(const sp_mesh *m, int width_px, sp_render_frame *fr);

/** Pixel of the point (x, y). */
void sp_render_frame_map(const sp_render_frame *fr, double x, double y, double *px,
                         double *py);

/** The outline of Omega (line width 1.5 @p lw) and the time in the white
 *  strip above the picture: what every picture on the 2D frame has. */
int sp_render_outline_and_time(cairo_t *cr, const sp_mesh *m, const sp_render_frame *fr,
                               double lw, double t, const char *what);

#endif
