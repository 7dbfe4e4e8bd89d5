// The element residual of the mixed backward-Euler weak form (MODEL.md,
// "Dynamics"), templated on the scalar type so one code gives residuals
// (double) and AD Jacobians (Sacado Fad).
//
// Element unknowns, for the n_cells cells present on the element: slot j,
// local node a, field f (0 = c, 1 = mu) at index (4 j + a) 2 + f.
// Per slot and node, the residual rows are:
//   R_c  = int N_a (c - c_old) + dt M grad N_a . grad mu - dt N_a s
//   R_mu = int N_a mu - N_a [f'(c) + 2 lambda c sum_{l!=k} c_l^2
//                            (+ 2 lambda_b c in the buffer) + shape(X)]
//          - kappa grad N_a . grad c
#ifndef SP_RESIDUAL_HPP
#define SP_RESIDUAL_HPP

#include <vector>

#include "physics.hpp"
#include "q1.h"

namespace sp {

// Geometry of one element at its 4 Gauss points, computed once per mesh.
struct ElementGeometry {
  double N[SP_Q1_QPOINTS][4];
  double dNdx[SP_Q1_QPOINTS][4][2];
  double x[SP_Q1_QPOINTS][2];
  double w[SP_Q1_QPOINTS];
  bool buffer;
};

// Per-step data an element reads besides its unknowns.
struct ElementInputs {
  const double *c_old;   // 4 n_cells nodal c^n (slot-major)
  const double *source;  // 4 n_cells nodal s_k (slot-major), or nullptr
  const sp_shape_coef *const *shape;  // n_cells entries or nullptr
  double dt;
  sp_model_params model;
};

template <class S>
void element_residual(const ElementGeometry &g, int n_cells, const S *u,
                      const ElementInputs &in, S *R) {
  const int n = 8 * n_cells;
  for (int i = 0; i < n; ++i) R[i] = 0.0;
  const sp_model_params &m = in.model;
  // Per-slot values at one quadrature point.
  std::vector<S> c(n_cells), mu(n_cells), gc(2 * n_cells), gmu(2 * n_cells);
  for (int q = 0; q < SP_Q1_QPOINTS; ++q) {
    const double *N = g.N[q];
    S sum_sq = 0.0;
    for (int j = 0; j < n_cells; ++j) {
      c[j] = 0.0; mu[j] = 0.0;
      gc[2 * j] = 0.0; gc[2 * j + 1] = 0.0;
      gmu[2 * j] = 0.0; gmu[2 * j + 1] = 0.0;
      for (int a = 0; a < 4; ++a) {
        const S &ca = u[(4 * j + a) * 2], &mua = u[(4 * j + a) * 2 + 1];
        c[j] += N[a] * ca;
        mu[j] += N[a] * mua;
        for (int d = 0; d < 2; ++d) {
          gc[2 * j + d] += g.dNdx[q][a][d] * ca;
          gmu[2 * j + d] += g.dNdx[q][a][d] * mua;
        }
      }
      sum_sq += c[j] * c[j];
    }
    const double w = g.w[q];
    for (int j = 0; j < n_cells; ++j) {
      double c_old = 0.0, s = 0.0;
      for (int a = 0; a < 4; ++a) {
        c_old += N[a] * in.c_old[4 * j + a];
        if (in.source) s += N[a] * in.source[4 * j + a];
      }
      // Everything in mu_k that is not the Laplacian: f', pairs, buffer, shape.
      S local = well_d1(m, c[j]) + repulsion_d1(m, c[j], sum_sq);
      if (g.buffer) local += buffer_d1(m, c[j]);
      if (in.shape && in.shape[j] && c_old >= in.shape[j]->threshold)
        local += shape_mu(*in.shape[j], g.x[q][0], g.x[q][1]);
      const S rate = c[j] - c_old - in.dt * s;
      for (int a = 0; a < 4; ++a) {
        const double *dN = g.dNdx[q][a];
        R[(4 * j + a) * 2] += w * (N[a] * rate + in.dt * m.mobility *
                                   (dN[0] * gmu[2 * j] + dN[1] * gmu[2 * j + 1]));
        R[(4 * j + a) * 2 + 1] += w * (N[a] * (mu[j] - local) - m.kappa *
                                       (dN[0] * gc[2 * j] + dN[1] * gc[2 * j + 1]));
      }
    }
  }
}

}  // namespace sp
#endif
