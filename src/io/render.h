/**
 * @file render.h
 * @brief PNG pictures (cairo): the cells in the paper's colours (the field
 *        phi = max_k c_k on a jet colour map: interiors red, membranes
 *        cyan-yellow, background blue) and the energy against time.
 *
 * One file per picture, on a drawing base of their own (render_base.h,
 * private to io/): render_2d.c (sp_render_cells), render_plot.c
 * (sp_render_energy), render_sections.c (sp_render_sections),
 * render_surfaces.c (sp_render_level_surface, sp_render_surfaces) and
 * render_contacts.c (sp_render_contact_graph).
 */
#ifndef SP_RENDER_H
#define SP_RENDER_H

#include "public/cell_obs.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Picture of the cells of @p state, @p width_px wide (height from the
 *         domain's aspect ratio), with the time in a corner; with @p names
 *         (a named scene's, NULL: none) each cell's name (its number if it
 *         has none) in bold black on a white halo at the mean position of
 *         the nodes where it is the cell_id (the largest c > 1/2). */
int sp_render_cells(const sp_mesh *mesh, const sp_layout *layout,
                    const double *state, double t, const sp_cell_name *names, int width_px,
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
 *        world-to-pixel map as sp_render_cells, the outline of Omega; in 3D
 *        the frame, camera and translucent Omega of sp_render_surfaces): cell
 *        k a numbered disc at its centre (@p centre[dim k + d], d < the
 *        mesh's dim; in 3D drawn far to near), edge j a line between cells
 *        @p edge[2j] and @p edge[2j+1] (from 0) whose width is a quarter of
 *        @p length[j] (a contact length, in the mesh's units; in 3D a contact
 *        area, and a quarter of its square root) at the picture's scale, at
 *        least one pixel; the time in a corner.
 */
int sp_render_contact_graph(const sp_mesh *mesh, int n_cells, const double *centre,
                            int n_edges, const int *edge, const double *length, double t,
                            int width_px, const char *path);

/**
 * @brief The three mid-plane sections of a 3D state (x, y and z = the
 *        middle of the mesh's bounding box), side by side in one picture
 *        @p width_px wide: phi = max_k c_k interpolated trilinearly in the
 *        hexahedron under each pixel, in the 2D picture's colours (buffer
 *        elements washed out, white outside the mesh), each panel with its
 *        plane and axes labelled, the time above; with @p names (NULL:
 *        none) each cell's name, as in sp_render_cells, at the mean of the
 *        pixels of each panel where it has the largest c > 1/2 (trilinear),
 *        if they are at least a label's height squared.
 */
int sp_render_sections(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path);

/**
 * @brief Where sp_render_sections puts the point @p x (3 coordinates) in the
 *        panel of plane @p plane (0: x = middle, showing y right and z up;
 *        1: y = middle, x right, z up; 2: z = middle, x right, y up): pixel
 *        coordinates as sp_render_cells_pixel's, and the picture's height
 *        (any output pointer may be NULL).
 */
int sp_render_sections_pixel(const sp_mesh *mesh, int width_px, int plane, const double *x,
                             double *px, double *py, int *height_px);

/**
 * @brief A 3D view of the cells: each cell's c = 1/2 surface (marching
 *        tetrahedra, sp_render_level_surface) in a colour of its own, shaded
 *        by one light (Lambert), drawn far to near (painter's algorithm) by
 *        a fixed oblique orthographic camera, inside the boundary of Omega
 *        drawn translucent (the eggshell's inner surface, or the box), with
 *        the axes' directions in a corner and the time above; @p width_px
 *        wide, the height from the mesh's projection. With @p names (NULL:
 *        none) a legend strip below the view, as many rows as it needs:
 *        each cell's colour in a square and its name (its number if it has
 *        none); the view above it is the same pixel for pixel.
 */
int sp_render_surfaces(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path);

/** @brief Where sp_render_surfaces puts the point @p x (3 coordinates), as
 *         sp_render_cells_pixel, and the picture's height without names
 *         (a legend strip adds to it). */
int sp_render_surfaces_pixel(const sp_mesh *mesh, int width_px, const double *x, double *px,
                             double *py, int *height_px);

/**
 * @brief The level surface {v = @p level} of the Q1 field @p v (one value
 *        per node) on a 3D mesh: each hexahedron cut into 24 tetrahedra
 *        (an edge of a face, the face's centre, the element's centre),
 *        marching tetrahedra on each. Closed where it does not reach the
 *        mesh's boundary (neighbouring elements cut their shared face alike
 *        and make bit-identical points on it); every triangle turned so
 *        that (p1 - p0) x (p2 - p0) points towards v < level.
 * @param[out] tri malloc'd 9 coordinates per triangle (the caller frees it)
 * @param[out] n_tri the number of triangles
 */
int sp_render_level_surface(const sp_mesh *mesh, const double *v, double level, double **tri,
                            size_t *n_tri);

/** @brief Energy against time, with vertical marks at @p marks (e.g.
 *         division times; may be NULL). */
int sp_render_energy(const double *t, const double *energy, int n,
                     const double *marks, int n_marks, const char *path);

#ifdef __cplusplus
}
#endif
#endif
