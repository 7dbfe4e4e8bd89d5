/**
 * @file mesh.h
 * @brief Q1 meshes of either dimension (q1.h): quadrilateral rectangles and
 *        the paper's five-patch disk mapped to an ellipse, optionally with a
 *        buffer ring outside Omega (2D), and hexahedral boxes and the cubed
 *        ball mapped to an ellipsoid, optionally with a buffer shell (3D). The
 *        dimension is the mesh's: code that loops over elements reads
 *        dim and nodes_per_elem from it.
 */
#ifndef SP_MESH_H
#define SP_MESH_H

#include <stddef.h>

#include "mesh/q1.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Element regions. */
enum { SP_REGION_OMEGA = 0, SP_REGION_BUFFER = 1 };

/** A replicated Q1 mesh. Elements list their nodes in q1.h's order
 *  (a quadrilateral counterclockwise; a hexahedron's bottom face
 *  counterclockwise seen from above, then its top face). */
typedef struct sp_mesh {
  int n_nodes, n_elems;
  int dim;            /**< 2 (quadrilaterals) or 3 (hexahedra) */
  int nodes_per_elem; /**< sp_q1_nodes(dim): 4 or 8 */
  double *xy;       /**< dim * n_nodes coordinates: x, y (and z in 3D) */
  int *elem;        /**< nodes_per_elem * n_elems node indices */
  int *region;      /**< per element: SP_REGION_OMEGA or SP_REGION_BUFFER */
  int is_ellipse;   /**< 1 for the ellipse or ellipsoid mesh, 0 for a
                         rectangle or box */
  double bounds[6]; /**< Omega: rectangle x0, y0, x1, y1; ellipse 0, 0, a, b;
                         box x0, y0, x1, y1, z0, z1; ellipsoid 0, 0, a, b,
                         0, c */
  double flatten;   /**< ellipse, ellipsoid: > 0 when Omega is cut by the
                         planes |x_{dim-1}| <= flatten (the coverslip:
                         |y| in 2D, |z| in 3D; sp_mesh_flatten); 0: no cut */
  double h;         /**< largest element edge length */
  /** The Q1 geometry at element e's Gauss point q (sp_q1_point), made once
   *  with the mesh so that loops over elements (src/model/cells.c) need not
   *  recompute it: with nq = sp_q1_qpoints(dim), the weight |det J| at
   *  [nq e + q], the point's coordinate d at [dim (nq e + q) + d]. NULL in
   *  a mesh not made here. */
  double *q1_w, *q1_x;
} sp_mesh;

/** @brief Bytes the mesh holds: coordinates, connectivity, regions and
 *  the Gauss points' geometry. */
double sp_mesh_bytes(const sp_mesh *mesh);

/**
 * @brief Rectangle [x0,x1] x [y0,y1] with nx x ny elements.
 * @param[out] out the new mesh (destroy with sp_mesh_destroy)
 * @return SP_OK or an error code with a message
 */
int sp_mesh_rectangle(double x0, double y0, double x1, double y1, int nx,
                      int ny, sp_mesh **out);

/**
 * @brief The five-patch disk (a centre square and four patches to the
 *        circle) refined @p refinements times, mapped to the ellipse with
 *        semi-axes @p a (x) and @p b (y) centred at the origin; @p r = 5 gives
 *        5120 elements and 5185 nodes. With @p buffer_layers > 0, that many
 *        rings of elements of total radial width @p buffer_width (a fraction
 *        of the semi-axes) are added outside, with region SP_REGION_BUFFER.
 */
int sp_mesh_ellipse(int refinements, double a, double b, int buffer_layers,
                    double buffer_width, sp_mesh **out);

/**
 * @brief The box [x0,x1] x [y0,y1] x [z0,z1] with nx x ny x nz hexahedra
 *        (a 3D mesh). Nodes are numbered x fastest, then y, then z.
 * @param[out] out the new mesh (destroy with sp_mesh_destroy)
 * @return SP_OK or an error code with a message
 */
int sp_mesh_box(double x0, double y0, double z0, double x1, double y1, double z1, int nx,
                int ny, int nz, sp_mesh **out);

/** Largest refinement of sp_mesh_ellipsoid: r = 7 has 14.7e6 hexahedra. */
#define SP_MESH_ELLIPSOID_MAX_REFINEMENTS 7

/**
 * @brief The cubed ball (a centre cube and six patches to the sphere, the 3D
 *        twin of sp_mesh_ellipse's five-patch disk) refined @p refinements
 *        times, mapped to the ellipsoid with semi-axes @p a (x), @p b (y),
 *        @p c (z) centred at the origin: with n = 2^refinements, n^3 cube
 *        hexahedra and 6 n^3 in the patches (r = 3: 3584 elements, 3817
 *        nodes). With @p buffer_layers > 0, that many shells of 6 n^2
 *        hexahedra of total radial width @p buffer_width (a fraction of the
 *        semi-axes) are added outside, with region SP_REGION_BUFFER.
 * @param[out] out the new mesh (destroy with sp_mesh_destroy)
 * @return SP_OK or an error code with a message
 */
int sp_mesh_ellipsoid(int refinements, double a, double b, double c, int buffer_layers,
                      double buffer_width, sp_mesh **out);

/**
 * @brief Cut the ellipse (ellipsoid) mesh by the planes |x_{dim-1}| <= @p h
 *        (|y| in 2D, |z| in 3D): an embryo flattened under a coverslip.
 *
 * The nodes are moved, nothing is added or removed. In Omega each column
 * along the last axis (x_{dim-1} = t, the others fixed) is scaled: its
 * extent [-T, T] on the ellipse(oid), T = c sqrt(1 - sum_{d<last}
 * (x_d/s_d)^2) with c the last semi-axis, goes to [-min(T, h), min(T, h)]
 * (t -> t min(T, h)/T). So Omega becomes exactly the cut ellipse(oid)
 * (its boundary nodes lie on the planes or on the ellipse(oid)) and the
 * map, the identity where T <= h, keeps every column's order: det of the
 * map is min(T, h)/T > 0. A buffer node at level rho > 1 (rho^2 =
 * sum_d (x_d/s_d)^2) goes to t -> sign(t) min(|t|, rho h): the buffer
 * becomes the shell between the cut ellipse(oid) and its (1 + w)-scaled
 * copy, as it is for the uncut one. Sets mesh->flatten and recomputes the
 * Gauss point geometry and mesh->h.
 *
 * @return SP_OK; SP_ERR_INPUT when @p mesh is not an ellipse(oid) mesh or
 *         @p h is not in (0, c)
 */
int sp_mesh_flatten(sp_mesh *mesh, double h);

/** @brief Measure of the ellipse (ellipsoid) with semi-axes @p semi cut by
 *         |x_{dim-1}| <= @p h (h >= the last semi-axis: uncut):
 *         2D 2 a b (u sqrt(1 - u^2) + asin u), u = h/b; 3D
 *         pi a b (2 h - 2 h^3 / (3 c^2)). */
double sp_mesh_flattened_measure(int dim, const double semi[3], double h);

/** @brief The number of nodes sp_mesh_ellipsoid makes, (n+1)^3 + (n + L)(6n^2 + 2)
 *         with n = 2^refinements and L = buffer_layers, without building the mesh. */
long long sp_mesh_ellipsoid_nodes(int refinements, int buffer_layers);

/** @brief The number of elements sp_mesh_ellipsoid makes, n^3 + 6n^2 (n + L). */
long long sp_mesh_ellipsoid_elements(int refinements, int buffer_layers);

/** @brief The number of nodes sp_mesh_box makes, (nx+1)(ny+1)(nz+1). */
long long sp_mesh_box_nodes(int nx, int ny, int nz);

/** @brief The number of nodes sp_mesh_rectangle makes for @p nx x @p ny
 *         elements, (nx+1)(ny+1), computed without building the mesh. */
long long sp_mesh_rectangle_nodes(int nx, int ny);

/** @brief The number of nodes sp_mesh_ellipse makes, (n+1)^2 + 4n(n + L) with
 *         n = 2^refinements and L = buffer_layers, without building the mesh. */
long long sp_mesh_ellipse_nodes(int refinements, int buffer_layers);

/** @brief Measure of the elements of one region: area in 2D, volume in 3D
 *         (the Gauss rule of q1.h). */
double sp_mesh_region_area(const sp_mesh *mesh, int region);

/** @brief 1 if the point @p x (mesh->dim coordinates) lies in Omega
 *         (closed, to a relative 1e-12), else 0. */
int sp_mesh_contains(const sp_mesh *mesh, const double *x);

/** @brief Free the mesh and set *mesh to NULL. */
void sp_mesh_destroy(sp_mesh **mesh);

/** @brief Element e's node list: mesh->nodes_per_elem node indices, in
 *         the reference element's order (q1.h). */
static inline const int *sp_mesh_elem_nodes(const sp_mesh *m, int e) {
  return m->elem + (size_t)m->nodes_per_elem * e;
}

/** @brief Copy element e's node coordinates into xe[a][d], a <
 *         nodes_per_elem, d < dim (the rest of xe is left as it is). */
static inline void sp_mesh_elem_xy(const sp_mesh *m, int e,
                                   double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM]) {
  const int nen = m->nodes_per_elem, dim = m->dim;
  const int *nodes = sp_mesh_elem_nodes(m, e);
  for (int a = 0; a < nen; ++a) {
    const int n = nodes[a];
    for (int d = 0; d < dim; ++d) xe[a][d] = m->xy[(size_t)dim * n + d];
  }
}

#ifdef __cplusplus
}
#endif
#endif
