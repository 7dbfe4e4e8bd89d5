// The hand-derived element Jacobian of the weak form of residual.hpp:
//
//   R_c[k,a]  = int N_a (c_k - c_k^n - dt s_k) + dt M grad N_a . grad mu_k
//   R_mu[k,a] = int N_a (mu_k - local_k) - kappa grad N_a . grad c_k
//   local_k   = f'(c_k) + 2 lambda c_k (S - c_k^2) [+ 2 lambda_b c_k] + shape
//   S         = sum_l c_l^2
//
// so, with M_ab = int N_a N_b and L_ab = int grad N_a . grad N_b,
//
//   dR_c[k,a]  / dc_k[b]  = M_ab          dR_c[k,a]  / dmu_k[b] = dt M L_ab
//   dR_mu[k,a] / dmu_k[b] = M_ab
//   dR_mu[k,a] / dc_k[b]  = -int N_a N_b [f''(c_k) + 2 lambda (S - c_k^2)
//                                         (+ 2 lambda_b)] - kappa L_ab
//   dR_mu[k,a] / dc_l[b]  = -int N_a N_b 4 lambda c_k c_l - sigma_kl L_ab  (l != k)
//
// (sigma_kl: adhesion, whose R_mu[k,a] term is -sigma_kl int grad N_a .
// grad c_l: linear in c_l, so its block is the stiffness matrix)
//
// and every other block is zero (coupled() in assembly.hpp). The pointwise
// values and derivatives come from physics.hpp. Quadrilaterals and
// hexahedra alike: a kernel templated on the dimension (as
// element_residual_q1), chosen per element at run time.
#include "assembly/jacobian_hand.hpp"

#include <vector>

namespace sp {

namespace {

template <int DIM>
void hand_element_q1(const ElementGeometry &geo, int nc, const double *u,
                     const ElementInputs &in, double *R, double *K) {
  const LocalGeometry<DIM> g(geo);  // residual.hpp: why a local copy
  constexpr int Q = q1_nodes<DIM>(), nen = q1_nodes<DIM>(), dim = DIM;
  const int n = 2 * nen * nc;
  const sp_model_params &m = in.model;
  // Per quadrature point and slot: c (for the cross blocks) and the
  // coefficient of N_a N_b in the diagonal block dR_mu/dc.
  thread_local std::vector<double> work;
  if (work.size() < (size_t)2 * Q * nc) work.resize((size_t)2 * Q * nc);
  double *cq = work.data(), *dq = cq + Q * nc;

  // w N_a N_b per point, and the element mass and stiffness matrices.
  double NN[Q][nen][nen], Mab[nen][nen] = {}, Lab[nen][nen] = {};
  for (int q = 0; q < Q; ++q) {
    const double w = g.w[q], *N = g.N[q];
    for (int a = 0; a < nen; ++a)
      for (int b = 0; b < nen; ++b) {
        NN[q][a][b] = w * N[a] * N[b];
        Mab[a][b] += NN[q][a][b];
        Lab[a][b] += w * grad_dot(g.dNdx[q][a], g.dNdx[q][b], dim);
      }
  }

  // The residual, and the pointwise coefficients of the Jacobian.
  for (int i = 0; i < n; ++i) R[i] = 0.0;
  for (int q = 0; q < Q; ++q) {
    const double *N = g.N[q];
    const double w = g.w[q];
    double sum_sq = 0.0;
    for (int j = 0; j < nc; ++j) {
      double c = 0.0;
      for (int a = 0; a < nen; ++a) c += N[a] * u[(nen * j + a) * 2];
      cq[q * nc + j] = c;
      sum_sq += c * c;
    }
    for (int j = 0; j < nc; ++j) {
      const double c = cq[q * nc + j];
      double mu = 0.0, gc[dim] = {}, gmu[dim] = {};
      double c_old = 0.0, s = 0.0;
      for (int a = 0; a < nen; ++a) {
        const double ca = u[(nen * j + a) * 2], mua = u[(nen * j + a) * 2 + 1];
        const double *dN = g.dNdx[q][a];
        mu += N[a] * mua;
        for (int d = 0; d < dim; ++d) {
          gc[d] += dN[d] * ca;
          gmu[d] += dN[d] * mua;
        }
        c_old += N[a] * in.c_old[nen * j + a];
        if (in.source) s += N[a] * in.source[nen * j + a];
      }
      double local = well_d1(m, c) + repulsion_d1(m, c, sum_sq);
      double d2 = well_d2(m, c) + repulsion_d2_self(m, c, sum_sq);
      if (g.buffer) {
        local += buffer_d1(m, c);
        d2 += buffer_d2(m);
      }
      if (in.shape && in.shape[j] && c_old >= in.shape[j]->threshold)
        local += shape_mu(*in.shape[j], g.x[q], dim);
      dq[q * nc + j] = d2;
      double ga[dim] = {};  // sum_l sigma_jl grad c_l: adhesion (residual.hpp)
      if (in.adhesion)
        for (int l = 0; l < nc; ++l) {
          const double sigma = in.adhesion[nc * j + l];
          if (l == j || sigma == 0.0) continue;
          for (int a = 0; a < nen; ++a) {
            const double cla = u[(nen * l + a) * 2];
            for (int d = 0; d < dim; ++d) ga[d] += sigma * g.dNdx[q][a][d] * cla;
          }
        }
      const double rate = c - c_old - in.dt * s;
      for (int a = 0; a < nen; ++a) {
        const double *dN = g.dNdx[q][a];
        R[(nen * j + a) * 2] += w * (N[a] * rate + in.dt * m.mobility * grad_dot(dN, gmu, dim));
        R[(nen * j + a) * 2 + 1] += w * (N[a] * (mu - local) - m.kappa * grad_dot(dN, gc, dim));
        if (in.adhesion) R[(nen * j + a) * 2 + 1] -= w * grad_dot(dN, ga, dim);
      }
    }
  }

  // Diagonal (own-cell) blocks.
  const double dtM = in.dt * m.mobility;
  for (int j = 0; j < nc; ++j) {
    double d[Q];
    for (int q = 0; q < Q; ++q) d[q] = dq[q * nc + j];
    for (int a = 0; a < nen; ++a) {
      double *Kc = K + (size_t)((nen * j + a) * 2) * n + 2 * nen * j;  // row c, cols of slot j
      double *Km = Kc + n;                                              // row mu
      for (int b = 0; b < nen; ++b) {
        double nl = 0.0;
        for (int q = 0; q < Q; ++q) nl += d[q] * NN[q][a][b];
        Kc[2 * b] = Mab[a][b];
        Kc[2 * b + 1] = dtM * Lab[a][b];
        Km[2 * b] = -nl - m.kappa * Lab[a][b];
        Km[2 * b + 1] = Mab[a][b];
      }
    }
  }

  // Cross-cell blocks dR_mu[j]/dc_l = dR_mu[l]/dc_j: once per unordered pair
  // (sigma_jl = sigma_lj: the adhesion table is symmetric).
  for (int j = 0; j < nc; ++j)
    for (int l = j + 1; l < nc; ++l) {
      double d[Q];
      for (int q = 0; q < Q; ++q)
        d[q] = repulsion_d2_cross(m, cq[q * nc + j], cq[q * nc + l]);
      const double sigma = in.adhesion ? in.adhesion[nc * j + l] : 0.0;
      for (int a = 0; a < nen; ++a) {
        double *Kjl = K + (size_t)((nen * j + a) * 2 + 1) * n + 2 * nen * l;  // row mu_j, cols c_l
        double *Klj = K + (size_t)((nen * l + a) * 2 + 1) * n + 2 * nen * j;  // row mu_l, cols c_j
        for (int b = 0; b < nen; ++b) {
          double v = 0.0;
          for (int q = 0; q < Q; ++q) v += d[q] * NN[q][a][b];
          if (sigma != 0.0) v += sigma * Lab[a][b];
          Kjl[2 * b] = -v;
          Klj[2 * b] = -v;
        }
      }
    }
}

}  // namespace

void hand_element(const ElementGeometry &g, int nc, const double *u,
                  const ElementInputs &in, double *R, double *K) {
  if (g.dim == 3) hand_element_q1<3>(g, nc, u, in, R, K);
  else hand_element_q1<2>(g, nc, u, in, R, K);
}

}  // namespace sp
