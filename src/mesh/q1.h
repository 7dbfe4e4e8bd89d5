/**
 * @file q1.h
 * @brief The Q1 reference elements and their Gauss rules: the bilinear
 *        quadrilateral (dim 2: 4 nodes, 2x2 points) and the trilinear
 *        hexahedron (dim 3: 8 nodes, 2x2x2 points). One code for both:
 *        every function takes the dimension and reads the element's node
 *        and point counts from it (sp_q1_nodes, sp_q1_qpoints); arrays are
 *        sized for the largest element (SP_Q1_MAX_NODES x SP_Q1_MAX_DIM),
 *        and only the first sp_q1_nodes(dim) rows and dim columns are read
 *        or written. Header-only and valid C and C++, so geometry is
 *        written once for the C core (observables) and the C++ glue
 *        (residuals).
 *
 * Reference cube [-1,1]^dim, local nodes in VTK's order: 0 (-1,-1),
 * 1 (1,-1), 2 (1,1), 3 (-1,1) (the quadrilateral, counterclockwise; in 3D
 * at zeta = -1), and in 3D 4..7 the same at zeta = +1. Gauss point q lies
 * at node q's corner scaled by 1/sqrt(3); the weights are 1.
 */
#ifndef SP_Q1_H
#define SP_Q1_H

#include <math.h>

/** The largest dimension, node and point counts (the hexahedron's). */
#define SP_Q1_MAX_DIM 3
#define SP_Q1_MAX_NODES 8
#define SP_Q1_MAX_QPOINTS 8

/** Gauss point coordinate 1/sqrt(3) of the 2-point rule (weights 1). */
#define SP_Q1_GAUSS 0.57735026918962576451

/** Nodes of the Q1 element of dimension @p dim (2: 4, 3: 8). */
static inline int sp_q1_nodes(int dim) { return dim == 3 ? 8 : 4; }
/** Gauss points of its tensor 2-point rule (2: 4, 3: 8). */
static inline int sp_q1_qpoints(int dim) { return dim == 3 ? 8 : 4; }

/** Coordinate d (0, 1, 2) of reference node a's corner: -1 or 1. */
static inline double sp_q1_corner(int a, int d) {
  static const double corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                      {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  return corner[a][d];
}

/** Reference coordinates xi[0..dim) of Gauss point q. */
static inline void sp_q1_qpoint(int dim, int q, double xi[SP_Q1_MAX_DIM]) {
  for (int d = 0; d < dim; ++d) xi[d] = sp_q1_corner(q, d) * SP_Q1_GAUSS;
}

/** Shape functions N[a] and their reference gradients dN[a][d] at xi. */
static inline void sp_q1_shape(int dim, const double xi[SP_Q1_MAX_DIM],
                               double N[SP_Q1_MAX_NODES],
                               double dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM]) {
  if (dim == 2) {
    for (int a = 0; a < 4; ++a) {
      const double sx = sp_q1_corner(a, 0), sy = sp_q1_corner(a, 1);
      N[a] = 0.25 * (1 + sx * xi[0]) * (1 + sy * xi[1]);
      dN[a][0] = 0.25 * sx * (1 + sy * xi[1]);
      dN[a][1] = 0.25 * sy * (1 + sx * xi[0]);
    }
    return;
  }
  for (int a = 0; a < 8; ++a) {
    const double fx = 1 + sp_q1_corner(a, 0) * xi[0], fy = 1 + sp_q1_corner(a, 1) * xi[1],
                 fz = 1 + sp_q1_corner(a, 2) * xi[2];
    N[a] = 0.125 * fx * fy * fz;
    dN[a][0] = 0.125 * sp_q1_corner(a, 0) * fy * fz;
    dN[a][1] = 0.125 * sp_q1_corner(a, 1) * fx * fz;
    dN[a][2] = 0.125 * sp_q1_corner(a, 2) * fx * fy;
  }
}

/**
 * Values at quadrature point q of an element of dimension @p dim with node
 * coordinates xe[a][d]: shape functions N, physical gradients dNdx, the
 * physical point x[0..dim) (only those entries are written), and the weight
 * w = |det J| (Gauss weights are 1). Returns det J (<= 0: inverted).
 */
static inline double sp_q1_point(int dim, const double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM],
                                 int q, double N[SP_Q1_MAX_NODES],
                                 double dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], double *x,
                                 double *w) {
  const int nen = sp_q1_nodes(dim);
  double xi[SP_Q1_MAX_DIM], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
  sp_q1_qpoint(dim, q, xi);
  sp_q1_shape(dim, xi, N, dN);
  double J[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  for (int d = 0; d < dim; ++d) x[d] = 0;
  for (int a = 0; a < nen; ++a) {
    for (int d = 0; d < dim; ++d) x[d] += N[a] * xe[a][d];
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) J[i][j] += xe[a][i] * dN[a][j];
  }
  double det;
  if (dim == 2) {
    det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    double inv[2][2] = {{J[1][1] / det, -J[0][1] / det},
                        {-J[1][0] / det, J[0][0] / det}};
    for (int a = 0; a < 4; ++a) {
      dNdx[a][0] = dN[a][0] * inv[0][0] + dN[a][1] * inv[1][0];
      dNdx[a][1] = dN[a][0] * inv[0][1] + dN[a][1] * inv[1][1];
    }
  } else {
    /* inverse by cofactors: inv = adj(J) / det */
    double cof[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        cof[i][j] = J[i1][j1] * J[i2][j2] - J[i1][j2] * J[i2][j1];
      }
    det = J[0][0] * cof[0][0] + J[0][1] * cof[0][1] + J[0][2] * cof[0][2];
    double inv[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) inv[i][j] = cof[j][i] / det;
    for (int a = 0; a < 8; ++a)
      for (int j = 0; j < 3; ++j)
        dNdx[a][j] = dN[a][0] * inv[0][j] + dN[a][1] * inv[1][j] + dN[a][2] * inv[2][j];
  }
  *w = fabs(det);
  return det;
}

#endif
