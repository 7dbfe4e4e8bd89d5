/**
 * @file mesh.h
 * @brief Quadrilateral meshes: rectangles and the paper's five-patch disk
 *        mapped to an ellipse, optionally with a buffer ring outside Omega.
 */
#ifndef SP_MESH_H
#define SP_MESH_H

#ifdef __cplusplus
extern "C" {
#endif

/** Element regions. */
enum { SP_REGION_OMEGA = 0, SP_REGION_BUFFER = 1 };

/** A replicated Q1 mesh. Elements list their nodes counterclockwise. */
typedef struct sp_mesh {
  int n_nodes, n_elems;
  double *xy;       /**< 2 * n_nodes coordinates */
  int *elem;        /**< 4 * n_elems node indices, counterclockwise */
  int *region;      /**< per element: SP_REGION_OMEGA or SP_REGION_BUFFER */
  int is_ellipse;   /**< 1 for the ellipse mesh, 0 for a rectangle */
  double bounds[4]; /**< Omega: rectangle x0, y0, x1, y1; ellipse 0, 0, a, b */
  double h;         /**< largest element edge length */
  /** The Q1 geometry at element e's Gauss point q (sp_q1_point), made once
   *  with the mesh so that loops over elements (src/cells.c) need not
   *  recompute it: the weight |det J| at [4 e + q], the point at
   *  [2 (4 e + q)] and [2 (4 e + q) + 1]. NULL in a mesh not made here. */
  double *q1_w, *q1_x;
} sp_mesh;

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

/** @brief The number of nodes sp_mesh_rectangle makes for @p nx x @p ny
 *         elements, (nx+1)(ny+1), computed without building the mesh. */
long long sp_mesh_rectangle_nodes(int nx, int ny);

/** @brief The number of nodes sp_mesh_ellipse makes, (n+1)^2 + 4n(n + L) with
 *         n = 2^refinements and L = buffer_layers, without building the mesh. */
long long sp_mesh_ellipse_nodes(int refinements, int buffer_layers);

/** @brief Area of the elements of one region (2x2 Gauss quadrature). */
double sp_mesh_region_area(const sp_mesh *mesh, int region);

/** @brief 1 if (x, y) lies in Omega (closed), else 0. */
int sp_mesh_contains(const sp_mesh *mesh, double x, double y);

/** @brief Free the mesh and set *mesh to NULL. */
void sp_mesh_destroy(sp_mesh **mesh);

/** @brief Copy element e's node coordinates into xy[4][2]. */
static inline void sp_mesh_elem_xy(const sp_mesh *m, int e, double xy[4][2]) {
  for (int a = 0; a < 4; ++a) {
    int n = m->elem[4 * e + a];
    xy[a][0] = m->xy[2 * n];
    xy[a][1] = m->xy[2 * n + 1];
  }
}

#ifdef __cplusplus
}
#endif
#endif
