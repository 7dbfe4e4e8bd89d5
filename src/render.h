/**
 * @file render.h
 * @brief PNG pictures (cairo): the cells in the paper's colours (the field
 *        phi = max_k c_k on a jet colour map: interiors red, membranes
 *        cyan-yellow, background blue) and the energy against time.
 */
#ifndef SP_RENDER_H
#define SP_RENDER_H

#include "layout.h"
#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Picture of the cells of @p state, @p width_px wide (height from the
 *         domain's aspect ratio), with the time in a corner. */
int sp_render_cells(const sp_mesh *mesh, const sp_layout *layout,
                    const double *state, double t, int width_px,
                    const char *path);

/**
 * @brief Where sp_render_cells puts the point (x, y): pixel coordinates
 *        (@p px right, @p py down, pixel centres at half-integers) in a
 *        picture @p width_px wide, and that picture's height (any output
 *        pointer may be NULL). For tests and for annotating pictures.
 */
int sp_render_cells_pixel(const sp_mesh *mesh, int width_px, double x,
                          double y, double *px, double *py, int *height_px);

/**
 * @brief The contact graph on the cells picture's frame (the same size and
 *        world-to-pixel map as sp_render_cells, the outline of Omega): cell
 *        k a numbered disc at (@p centre[2k], @p centre[2k+1]), edge j a line
 *        between cells @p edge[2j] and @p edge[2j+1] (from 0) whose width is
 *        a quarter of @p length[j] (a contact length, in the mesh's units)
 *        at the picture's scale, at least one pixel; the time in a corner.
 */
int sp_render_contact_graph(const sp_mesh *mesh, int n_cells, const double *centre,
                            int n_edges, const int *edge, const double *length, double t,
                            int width_px, const char *path);

/** @brief Energy against time, with vertical marks at @p marks (e.g.
 *         division times; may be NULL). */
int sp_render_energy(const double *t, const double *energy, int n,
                     const double *marks, int n_marks, const char *path);

#ifdef __cplusplus
}
#endif
#endif
