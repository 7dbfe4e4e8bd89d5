// The element residual of the mixed backward-Euler weak form (docs/model.md,
// "Dynamics"), templated on the scalar type so one code gives residuals
// (double) and AD Jacobians (Sacado Fad).
//
// One code for quadrilaterals and hexahedra: the kernel is a template on
// the dimension DIM (2 or 3; nodes and points 2^DIM, q1.h's reference
// elements), and element_residual dispatches on the element's dimension at
// run time (docs/design.md says why).
//
// Element unknowns, for the n_cells cells present on the element: slot j,
// local node a, field f (0 = c, 1 = mu) at index (n j + a) 2 + f.
// Per slot and node, the residual rows are:
//   R_c  = int N_a (c - c_old) + dt M grad N_a . grad mu - dt N_a s
//   R_mu = int N_a mu - N_a [f'(c) + 2 lambda c sum_{l!=k} c_l^2
//                            (+ 2 lambda_b c in the buffer) + shape(X)]
//          - kappa grad N_a . grad c - sum_{l!=k} sigma_kl grad N_a . grad c_l
// (the last sum: adhesion, docs/model.md "Adhesion"; only when the step has
// an adhesion table)
#ifndef SP_RESIDUAL_HPP
#define SP_RESIDUAL_HPP

#include <vector>

#include "assembly/physics.hpp"
#include "mesh/q1.h"

namespace sp {

// Geometry of one element at its Gauss points, computed once per mesh: a
// view into the mesh's arrays (Assembly), sized by the element's dimension,
// nodes and points, so a 2D mesh keeps no 3D-sized storage.
struct ElementGeometry {
  int dim, nodes, qpoints;
  const double *N_;     // [q nodes + a]
  const double *dNdx_;  // [(q nodes + a) dim + d]
  const double *x_;     // [q dim + d]
  const double *w_;     // [q]
  bool buffer;
  const double *N(int q) const { return N_ + q * nodes; }           // N(q)[a]
  const double *dNdx(int q, int a) const { return dNdx_ + (q * nodes + a) * dim; }
  const double *x(int q) const { return x_ + q * dim; }
  double w(int q) const { return w_[q]; }
};

// a . b for vectors of the element's dimension: a[0] b[0] + a[1] b[1]
// (+ a[2] b[2]), in that order (doubles: the hand Jacobian, energies).
inline double grad_dot(const double *a, const double *b, int dim) {
  double s = a[0] * b[0];
  for (int d = 1; d < dim; ++d) s += a[d] * b[d];
  return s;
}

// Nodes (and Gauss points) of the Q1 element of dimension DIM.
template <int DIM> constexpr int q1_nodes() { return DIM == 3 ? 8 : 4; }

// The element's geometry copied into fixed-size arrays of the kernel's own
// (compile-time shapes, as e931375's per-element struct had): the kernels
// read it in their innermost loops, and a local array no store to the
// residual or the Jacobian can alias lets the compiler keep its values in
// registers and vectorise the Fad derivative loops (read through the
// mesh-wide arrays' pointers, the 2D AD kernel ran 1.5x slower and the
// hand kernel 1.3x). Same values, same arithmetic.
template <int DIM> struct LocalGeometry {
  static constexpr int nen = q1_nodes<DIM>(), nq = nen;
  double N[nq][nen];
  double dNdx[nq][nen][DIM];
  double x[nq][DIM];
  double w[nq];
  bool buffer;
  explicit LocalGeometry(const ElementGeometry &g) : buffer(g.buffer) {
    for (int q = 0; q < nq; ++q) {
      for (int a = 0; a < nen; ++a) {
        N[q][a] = g.N_[q * nen + a];
        for (int d = 0; d < DIM; ++d) dNdx[q][a][d] = g.dNdx_[(q * nen + a) * DIM + d];
      }
      for (int d = 0; d < DIM; ++d) x[q][d] = g.x_[q * DIM + d];
      w[q] = g.w_[q];
    }
  }
};

// Per-step data an element reads besides its unknowns.
struct ElementInputs {
  const double *c_old;   // nodes x n_cells nodal c^n (slot-major)
  const double *source;  // nodes x n_cells nodal s_k (slot-major), or nullptr
  const sp_shape_coef *const *shape;  // n_cells entries or nullptr
  // sigma of the element's slots j and l at [n_cells j + l] (symmetric,
  // zero diagonal), or nullptr: no adhesion on the element
  const double *adhesion;
  double dt;
  sp_model_params model;
};

template <int DIM, class S>
void element_residual_q1(const ElementGeometry &geo, int n_cells, const S *u,
                         const ElementInputs &in, S *R) {
  const LocalGeometry<DIM> g(geo);
  constexpr int nen = q1_nodes<DIM>(), nq = nen, dim = DIM;
  const int n = 2 * nen * n_cells;
  for (int i = 0; i < n; ++i) R[i] = 0.0;
  const sp_model_params &m = in.model;
  // Per-slot values at one quadrature point.
  std::vector<S> c(n_cells), mu(n_cells), gc(dim * n_cells), gmu(dim * n_cells);
  for (int q = 0; q < nq; ++q) {
    const double *N = g.N[q];
    S sum_sq = 0.0;
    for (int j = 0; j < n_cells; ++j) {
      c[j] = 0.0; mu[j] = 0.0;
      for (int d = 0; d < dim; ++d) {
        gc[dim * j + d] = 0.0;
        gmu[dim * j + d] = 0.0;
      }
      for (int a = 0; a < nen; ++a) {
        const S &ca = u[(nen * j + a) * 2], &mua = u[(nen * j + a) * 2 + 1];
        const double *dN = g.dNdx[q][a];
        c[j] += N[a] * ca;
        mu[j] += N[a] * mua;
        for (int d = 0; d < dim; ++d) {
          gc[dim * j + d] += dN[d] * ca;
          gmu[dim * j + d] += dN[d] * mua;
        }
      }
      sum_sq += c[j] * c[j];
    }
    const double w = g.w[q];
    for (int j = 0; j < n_cells; ++j) {
      double c_old = 0.0, s = 0.0;
      for (int a = 0; a < nen; ++a) {
        c_old += N[a] * in.c_old[nen * j + a];
        if (in.source) s += N[a] * in.source[nen * j + a];
      }
      // Everything in mu_k that is not the Laplacian: f', pairs, buffer, shape.
      S local = well_d1(m, c[j]) + repulsion_d1(m, c[j], sum_sq);
      if (g.buffer) local += buffer_d1(m, c[j]);
      if (in.shape && in.shape[j] && c_old >= in.shape[j]->threshold)
        local += shape_mu(*in.shape[j], g.x[q], dim);
      const S rate = c[j] - c_old - in.dt * s;
      const S *gm = &gmu[dim * j], *gcj = &gc[dim * j];
      for (int a = 0; a < nen; ++a) {
        // grad N_a . grad mu and grad N_a . grad c written out per dimension
        // (a loop would store each in a Fad temporary: a copy, or with DFad
        // an allocation, per node and point)
        const double *dN = g.dNdx[q][a];
        S &Rc = R[(nen * j + a) * 2], &Rmu = R[(nen * j + a) * 2 + 1];
        if constexpr (DIM == 2) {
          Rc += w * (N[a] * rate + in.dt * m.mobility * (dN[0] * gm[0] + dN[1] * gm[1]));
          Rmu += w * (N[a] * (mu[j] - local) - m.kappa * (dN[0] * gcj[0] + dN[1] * gcj[1]));
        } else {
          Rc += w * (N[a] * rate + in.dt * m.mobility *
                                       (dN[0] * gm[0] + dN[1] * gm[1] + dN[2] * gm[2]));
          Rmu += w * (N[a] * (mu[j] - local) -
                      m.kappa * (dN[0] * gcj[0] + dN[1] * gcj[1] + dN[2] * gcj[2]));
        }
      }
      if (in.adhesion) {
        // adhesion: mu_k gets -sum_l sigma_kl lap c_l, in weak form
        // -sigma_kl grad N_a . grad c_l in R_mu
        S ga[dim];
        for (int d = 0; d < dim; ++d) ga[d] = 0.0;
        for (int l = 0; l < n_cells; ++l) {
          const double sigma = in.adhesion[n_cells * j + l];
          if (l == j || sigma == 0.0) continue;
          for (int d = 0; d < dim; ++d) ga[d] += sigma * gc[dim * l + d];
        }
        for (int a = 0; a < nen; ++a) {
          const double *dN = g.dNdx[q][a];
          S &Rmu = R[(nen * j + a) * 2 + 1];
          for (int d = 0; d < dim; ++d) Rmu -= w * dN[d] * ga[d];
        }
      }
    }
  }
}

// The element residual on either element: the kernel for its dimension.
template <class S>
void element_residual(const ElementGeometry &g, int n_cells, const S *u,
                      const ElementInputs &in, S *R) {
  if (g.dim == 3) element_residual_q1<3>(g, n_cells, u, in, R);
  else element_residual_q1<2>(g, n_cells, u, in, R);
}

}  // namespace sp
#endif
