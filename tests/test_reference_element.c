/* The Q1 reference elements of q1.h, quadrilateral and hexahedron:
 *  - the shape functions partition unity and their reference gradients sum
 *    to zero, at random points (1e-15);
 *  - on a distorted hexahedron (a random trilinear map, faces not planar)
 *    the 2x2x2 rule integrates the shape functions' physical gradients and
 *    the volume exactly: equal to a 5x5x5 Gauss rule to 1e-14 (the
 *    integrands det J and adj(J) grad_xi N are polynomials of degree <= 3
 *    in each variable), and the gradients reproduce a linear field exactly
 *    at every Gauss point;
 *  - the volume of a mapped box is exact: an affine image of the reference
 *    cube (|det A| 8), and sp_mesh_box's boxes, whose volume, node and
 *    element counts, positive det J and largest edge are as built. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "public/error.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"

static double uniform(unsigned long long *s) { /* in [-1, 1) */
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return 2.0 * (double)(*s >> 11) / 9007199254740992.0 - 1.0;
}

/* Shape functions sum to one, reference gradients to zero. */
static void partition_of_unity(int dim) {
  unsigned long long s = 7 + dim;
  double worst = 0;
  for (int t = 0; t < 1000; ++t) {
    double xi[SP_Q1_MAX_DIM] = {0, 0, 0}, N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    for (int d = 0; d < dim; ++d) xi[d] = uniform(&s);
    sp_q1_shape(dim, xi, N, dN);
    double sum = 0, grad[3] = {0, 0, 0};
    for (int a = 0; a < sp_q1_nodes(dim); ++a) {
      sum += N[a];
      for (int d = 0; d < dim; ++d) grad[d] += dN[a][d];
    }
    worst = fmax(worst, fabs(sum - 1));
    for (int d = 0; d < dim; ++d) worst = fmax(worst, fabs(grad[d]));
  }
  printf("dim %d: partition of unity and zero gradient sum to %.3g\n", dim, worst);
  CHECK(worst < 1e-15, "dim %d: shape functions off unity by %g", dim, worst);
  /* node a's function is 1 at its corner, 0 at the others */
  for (int a = 0; a < sp_q1_nodes(dim); ++a) {
    double xi[SP_Q1_MAX_DIM] = {0, 0, 0}, N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    for (int d = 0; d < dim; ++d) xi[d] = sp_q1_corner(a, d);
    sp_q1_shape(dim, xi, N, dN);
    for (int b = 0; b < sp_q1_nodes(dim); ++b)
      CHECK(N[b] == (a == b), "dim %d: N_%d at node %d's corner is %g", dim, b, a, N[b]);
  }
}

/* det J and the physical gradients at a reference point, for any rule. */
static double jacobian_at(const double xe[8][3], const double xi[3], double dNdx[8][3]) {
  double N[8], dN[8][3], J[3][3] = {{0}};
  sp_q1_shape(3, xi, N, dN);
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J[i][j] += xe[a][i] * dN[a][j];
  double c[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      c[i][j] = J[(i + 1) % 3][(j + 1) % 3] * J[(i + 2) % 3][(j + 2) % 3] -
                J[(i + 1) % 3][(j + 2) % 3] * J[(i + 2) % 3][(j + 1) % 3];
  const double det = J[0][0] * c[0][0] + J[0][1] * c[0][1] + J[0][2] * c[0][2];
  for (int a = 0; a < 8; ++a)
    for (int j = 0; j < 3; ++j)
      dNdx[a][j] = (dN[a][0] * c[j][0] + dN[a][1] * c[j][1] + dN[a][2] * c[j][2]) / det;
  return det;
}

/* A distorted hexahedron: the unit cube's corners moved by up to 0.2. */
static void distorted_hex(double xe[8][3]) {
  unsigned long long s = 2024;
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) xe[a][d] = 0.5 * (sp_q1_corner(a, d) + 1) + 0.2 * uniform(&s);
}

static void distorted_integrals(void) {
  double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
  distorted_hex(xe);
  /* 2x2x2 through q1.h */
  double vol2 = 0, grad2[8][3] = {{0}}, worst_linear = 0;
  const double b[3] = {0.3, -1.7, 2.2}, b0 = 0.9; /* u = b0 + b . x */
  for (int q = 0; q < sp_q1_qpoints(3); ++q) {
    double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
    CHECK(sp_q1_point(3, xe, q, N, dNdx, x, &w) > 0, "distorted hexahedron inverted at %d", q);
    vol2 += w;
    double gu[3] = {0, 0, 0}, u = 0;
    for (int a = 0; a < 8; ++a) {
      const double ua = b0 + b[0] * xe[a][0] + b[1] * xe[a][1] + b[2] * xe[a][2];
      u += N[a] * ua;
      for (int d = 0; d < 3; ++d) {
        grad2[a][d] += w * dNdx[a][d];
        gu[d] += dNdx[a][d] * ua;
      }
    }
    for (int d = 0; d < 3; ++d) worst_linear = fmax(worst_linear, fabs(gu[d] - b[d]));
    worst_linear = fmax(worst_linear, fabs(u - (b0 + b[0] * x[0] + b[1] * x[1] + b[2] * x[2])));
  }
  /* 5x5x5 Gauss-Legendre */
  static const double gx[5] = {-0.9061798459386640, -0.5384693101056831, 0.0,
                               0.5384693101056831, 0.9061798459386640};
  static const double gw[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                               0.4786286704993665, 0.2369268850561891};
  double vol5 = 0, grad5[8][3] = {{0}};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k) {
        const double xi[3] = {gx[i], gx[j], gx[k]}, w = gw[i] * gw[j] * gw[k];
        double dNdx[8][3];
        const double det = jacobian_at((const double(*)[3])xe, xi, dNdx);
        vol5 += w * det;
        for (int a = 0; a < 8; ++a)
          for (int d = 0; d < 3; ++d) grad5[a][d] += w * det * dNdx[a][d];
      }
  double worst_grad = 0, sum_grad[3] = {0, 0, 0};
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) {
      worst_grad = fmax(worst_grad, fabs(grad2[a][d] - grad5[a][d]));
      sum_grad[d] += grad2[a][d];
    }
  printf("distorted hexahedron: volume 2x2x2 %.17g, 5x5x5 %.17g (diff %.3g); int grad N_a: "
         "largest diff %.3g; linear field reproduced to %.3g\n",
         vol2, vol5, fabs(vol2 - vol5), worst_grad, worst_linear);
  CHECK(fabs(vol2 - vol5) < 1e-14 * vol5, "volume: 2x2x2 %.17g, 5x5x5 %.17g", vol2, vol5);
  CHECK(worst_grad < 1e-14, "int grad N_a: 2x2x2 and 5x5x5 differ by %g", worst_grad);
  for (int d = 0; d < 3; ++d)
    CHECK(fabs(sum_grad[d]) < 1e-14, "sum_a int dN_a/dx_%d = %g, not 0", d, sum_grad[d]);
  CHECK(worst_linear < 1e-13, "a linear field's value or gradient off by %g", worst_linear);
}

/* An affine image x = x0 + A xi of the reference cube: volume 8 |det A|. */
static void affine_volume(void) {
  const double A[3][3] = {{0.4, 0.1, -0.05}, {0.02, 0.3, 0.1}, {-0.1, 0.05, 0.25}};
  const double x0[3] = {1.0, -2.0, 0.5};
  double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) {
      xe[a][i] = x0[i];
      for (int j = 0; j < 3; ++j) xe[a][i] += A[i][j] * sp_q1_corner(a, j);
    }
  const double detA = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                      A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                      A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  double vol = 0;
  for (int q = 0; q < 8; ++q) {
    double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
    sp_q1_point(3, xe, q, N, dNdx, x, &w);
    vol += w;
  }
  printf("affine hexahedron: volume %.17g, 8 |det A| = %.17g\n", vol, 8 * fabs(detA));
  CHECK(fabs(vol - 8 * fabs(detA)) < 1e-15, "affine volume %.17g, expected %.17g", vol,
        8 * fabs(detA));
}

static void box_meshes(void) {
  sp_mesh *m;
  CHECK_OK(sp_mesh_box(0.1, -0.2, 1.0, 0.7, 0.3, 1.4, 6, 5, 4, &m));
  CHECK(m->dim == 3 && m->nodes_per_elem == 8, "box: dim %d, %d nodes per element", m->dim,
        m->nodes_per_elem);
  CHECK(m->n_nodes == 7 * 6 * 5 && m->n_elems == 6 * 5 * 4, "box: %d nodes, %d elements",
        m->n_nodes, m->n_elems);
  CHECK(sp_mesh_box_nodes(6, 5, 4) == m->n_nodes, "sp_mesh_box_nodes %lld",
        sp_mesh_box_nodes(6, 5, 4));
  const double vol = sp_mesh_region_area(m, SP_REGION_OMEGA), exact = 0.6 * 0.5 * 0.4;
  printf("box [0.1,0.7]x[-0.2,0.3]x[1,1.4] in 6x5x4: volume %.17g (exact %.17g), h %.17g\n", vol,
         exact, m->h);
  CHECK(fabs(vol - exact) < 1e-14 * exact, "box volume %.17g, expected %.17g", vol, exact);
  CHECK(fabs(m->h - 0.1) < 1e-15, "box: largest edge %.17g, expected 0.1", m->h);
  int bad = 0;
  for (size_t i = 0; i < (size_t)8 * m->n_elems; ++i) bad += m->q1_w[i] <= 0;
  for (int e = 0; e < m->n_elems; ++e) {
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(m, e, xe);
    for (int q = 0; q < 8; ++q) {
      double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
      bad += sp_q1_point(3, xe, q, N, dNdx, x, &w) <= 0; /* node order keeps det J > 0 */
    }
  }
  CHECK(bad == 0, "%d Gauss points with det J <= 0", bad);
  sp_mesh_destroy(&m);
  CHECK(sp_mesh_box(0, 0, 1, 1, 1, 1, 2, 2, 2, &m) == SP_ERR_INPUT && !m,
        "a box with z0 = z1 was accepted");
  /* the 2D meshes say they are 2D */
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 3, 3, &m));
  CHECK(m->dim == 2 && m->nodes_per_elem == 4, "rectangle: dim %d, %d nodes per element",
        m->dim, m->nodes_per_elem);
  sp_mesh_destroy(&m);
}

int main(void) {
  partition_of_unity(2);
  partition_of_unity(3);
  distorted_integrals();
  affine_volume();
  box_meshes();
  TEST_DONE();
}
