/* render_surfaces.h: the 3D camera and painter of render_surfaces.c (private to io/). */
/*
 * The 3D view's fixed oblique camera and its painter's algorithm (flat
 * polygons, shaded, drawn far to near), with the boundary of Omega and the
 * axes' triad: what sp_render_surfaces draws with, and the contact graph
 * of a 3D state too (render_contacts.c).
 */
#ifndef SP_RENDER_SURFACES_H
#define SP_RENDER_SURFACES_H

#include <cairo.h>
#include <stddef.h>

#include "io/render.h"

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
} sp_render_camera;

/** The camera of a 3D mesh's view @p width_px wide (the height from the
 *  mesh's projection). */
int sp_render_camera_make(const sp_mesh *m, int width_px, sp_render_camera *cam);

/** Pixel of the point @p x (3 coordinates) and its depth (larger is
 *  farther; @p depth may be NULL). */
void sp_render_camera_map(const sp_render_camera *cam, const double *x, double *px,
                          double *py, double *depth);

/** A flat polygon to draw: its corners in pixels, its depth (the centroid's;
 *  larger is farther) and its colour. */
typedef struct {
  float p[4][2];
  float depth;
  float rgb[3];
  int n; /**< 3 or 4 corners */
} sp_render_face2d;

/** A growing list of polygons (free f). */
typedef struct {
  sp_render_face2d *f;
  size_t n, cap;
} sp_render_faces2d;

/** qsort's order of polygons far to near. */
int sp_render_cmp_far_first(const void *a, const void *b);

/** The boundary of Omega as quadrilaterals facing outwards: those facing
 *  the camera to @p front, the others to @p back. */
int sp_render_omega_faces(const sp_mesh *m, const sp_render_camera *cam,
                          sp_render_faces2d *front, sp_render_faces2d *back);

/** Fill the polygons of @p fs in their order; with @p alpha < 1 as one
 *  translucent layer. */
void sp_render_faces2d_fill(cairo_t *cr, const sp_render_faces2d *fs, double alpha);

/** The axes' directions in a corner, so the oblique view can be read. */
void sp_render_axes_triad(cairo_t *cr, const sp_render_camera *cam);

#endif
