/**
 * @file q1.h
 * @brief The bilinear quadrilateral (Q1) reference element and its 2x2 Gauss
 *        rule. Header-only and valid C and C++, so geometry is written once
 *        for the C core (observables) and the C++ glue (residuals).
 *
 * Reference square [-1,1]^2, local nodes counterclockwise:
 * 0 (-1,-1), 1 (1,-1), 2 (1,1), 3 (-1,1).
 */
#ifndef SP_Q1_H
#define SP_Q1_H

#include <math.h>

#define SP_Q1_NODES 4
#define SP_Q1_QPOINTS 4

/** Gauss point coordinate 1/sqrt(3) of the 2-point rule (weights 1). */
#define SP_Q1_GAUSS 0.57735026918962576451

static inline void sp_q1_qpoint(int q, double *xi, double *eta) {
  static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  *xi = sx[q] * SP_Q1_GAUSS;
  *eta = sy[q] * SP_Q1_GAUSS;
}

/** Shape functions and their reference gradients at (xi, eta). */
static inline void sp_q1_shape(double xi, double eta, double N[4],
                               double dN[4][2]) {
  static const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int a = 0; a < 4; ++a) {
    N[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
    dN[a][0] = 0.25 * sx[a] * (1 + sy[a] * eta);
    dN[a][1] = 0.25 * sy[a] * (1 + sx[a] * xi);
  }
}

/**
 * Values at one quadrature point of an element with node coordinates xy:
 * shape functions N, physical gradients dNdx, physical point x, and the
 * weight w = |det J| (Gauss weights are 1). Returns det J (<= 0: inverted).
 */
static inline double sp_q1_point(const double xy[4][2], int q, double N[4],
                                 double dNdx[4][2], double x[2], double *w) {
  double xi, eta, dN[4][2];
  sp_q1_qpoint(q, &xi, &eta);
  sp_q1_shape(xi, eta, N, dN);
  double J[2][2] = {{0, 0}, {0, 0}};
  x[0] = x[1] = 0;
  for (int a = 0; a < 4; ++a) {
    x[0] += N[a] * xy[a][0];
    x[1] += N[a] * xy[a][1];
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) J[i][j] += xy[a][i] * dN[a][j];
  }
  double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
  double inv[2][2] = {{J[1][1] / det, -J[0][1] / det},
                      {-J[1][0] / det, J[0][0] / det}};
  for (int a = 0; a < 4; ++a) {
    dNdx[a][0] = dN[a][0] * inv[0][0] + dN[a][1] * inv[1][0];
    dNdx[a][1] = dN[a][0] * inv[0][1] + dN[a][1] * inv[1][1];
  }
  *w = fabs(det);
  return det;
}

#endif
