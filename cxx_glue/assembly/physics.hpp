// The pointwise physics of docs/model.md, written once and templated on the
// scalar type: double for residuals and energies, Sacado Fad types for the
// AD Jacobian. The hand Jacobian uses the explicit derivatives below.
#ifndef SP_PHYSICS_HPP
#define SP_PHYSICS_HPP

#include "softpack_solver.h"

namespace sp {

// Bulk double well f(c) = alpha c^2 (c-1)^2 and its derivatives.
template <class S> S well(const sp_model_params &m, const S &c) {
  return m.alpha * c * c * (c - 1.0) * (c - 1.0);
}
template <class S> S well_d1(const sp_model_params &m, const S &c) {
  return 2.0 * m.alpha * c * (c - 1.0) * (2.0 * c - 1.0);
}
inline double well_d2(const sp_model_params &m, double c) {
  return 2.0 * m.alpha * (6.0 * c * c - 6.0 * c + 1.0);
}

// Pair repulsion: energy lambda sum_{k<l} c_k^2 c_l^2 (unordered pairs), so
// its derivative in c_k is 2 lambda c_k sum_{l!=k} c_l^2 = 2 lambda c_k
// (sum_sq - c_k^2), with sum_sq = sum_l c_l^2.
template <class S>
S repulsion_d1(const sp_model_params &m, const S &c, const S &sum_sq) {
  return 2.0 * m.lambda * c * (sum_sq - c * c);
}

// Second derivatives of the repulsion energy (the hand Jacobian):
// d/dc_k [2 lambda c_k (sum_sq - c_k^2)] = 2 lambda (sum_sq - c_k^2) (the
// c_k^2 terms cancel: d/dc_k [c_k sum_sq - c_k^3] = sum_sq + 2 c_k^2 - 3 c_k^2),
// and d/dc_l of the same, l != k, = 4 lambda c_k c_l (symmetric in k, l).
inline double repulsion_d2_self(const sp_model_params &m, double c, double sum_sq) {
  return 2.0 * m.lambda * (sum_sq - c * c);
}
inline double repulsion_d2_cross(const sp_model_params &m, double c_k, double c_l) {
  return 4.0 * m.lambda * c_k * c_l;
}

// Buffer ring penalty lambda_b c^2 per field, derivative 2 lambda_b c.
template <class S> S buffer_d1(const sp_model_params &m, const S &c) {
  return 2.0 * m.lambda_b * c;
}
inline double buffer_d2(const sp_model_params &m) { return 2.0 * m.lambda_b; }

// Ihat = v . Ibar(Xb) v with Ibar(Xb) = |Xb|^2 Id - Xb Xb^T (docs/model.md; in 2D
// [[Xb2^2, -Xb1 Xb2], [-Xb1 Xb2, Xb1^2]]): the derivative of the principal
// moment of eigenvector v in c. In 3D written as |v x Xb|^2 (the same for a
// unit v: no cancellation where Xb is along v, never negative); the 2D
// expression is the one the 2D outputs were made with.
inline double shape_ihat(const double v[3], const double *xb, int dim) {
  if (dim == 2)
    return v[0] * v[0] * xb[1] * xb[1] - 2.0 * v[0] * v[1] * xb[0] * xb[1] +
           v[1] * v[1] * xb[0] * xb[0];
  const double a = v[1] * xb[2] - v[2] * xb[1], b = v[2] * xb[0] - v[0] * xb[2],
               c = v[0] * xb[1] - v[1] * xb[0];
  return a * a + b * b + c * c;
}

// The shape term's value in mu_k at the point x (dim coordinates):
// -sum_i coef_i Ihat_i(x), i over the dim principal moments, with the
// coefficients of the step (explicit, or updated by the Newton iterate's
// moments when implicit: newton.cpp).
inline double shape_mu(const sp_shape_coef &s, const double *x, int dim) {
  const double xb[3] = {x[0] - s.xc, x[1] - s.yc, dim == 3 ? x[2] - s.zc : 0.0};
  double value = 0.0;
  for (int i = 0; i < dim; ++i) value -= s.coef[i] * shape_ihat(s.v[i], xb, dim);
  return value;
}

}  // namespace sp
#endif
