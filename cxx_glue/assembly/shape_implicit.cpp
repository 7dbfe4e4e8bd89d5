#include "assembly/shape_implicit.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sp {

void ImplicitShape::prepare(const sp_step_data &d, const Assembly &assembly) {
  u_.clear();
  coef_.clear();
  active_of_cell_.clear();
  gain_.clear();
  if (!d.shape || !d.shape_implicit) return;
  const int n_cells = assembly.n_cells(), n = assembly.dim();  // n moments per cell
  n_moments_ = n;
  active_of_cell_.assign(n_cells, -1);
  int n_active = 0;
  for (int k = 0; k < n_cells; ++k) {
    const sp_shape_coef &sc = d.shape[k];
    bool any = false;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (!std::isfinite(sc.gain[i][j]))
          throw std::runtime_error("shape: gain of cell " + std::to_string(k) + " is not finite");
        any = any || sc.gain[i][j] != 0.0;
      }
    if (!any) continue;
    active_of_cell_[k] = n_active++;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) gain_.push_back(sc.gain[i][j]);
  }
  coef_.assign(d.shape, d.shape + n_cells);
  data_ = d;
  data_.shape = coef_.data();
  if (n_active > 0) assembly.shape_weights(d, u_);
}

const sp_step_data &ImplicitShape::data_at(const sp_step_data &d, const Assembly &assembly,
                                           const double *state) {
  if (coef_.empty()) return d;
  // dI_j = int_mask Ihat_j (c - c^n) per cell, from the replicated state.
  const int n_cells = (int)coef_.size(), n = n_moments_;
  std::vector<double> dI(n * (size_t)n_cells, 0.0);
  if (!u_.empty())
    for (int p = 0; p < assembly.n_dofs() / 2; ++p) {
      const int k = assembly.pair_cell(p);
      if (active_of_cell_[k] < 0) continue;
      const double dc = state[2 * p] - d.state_old[2 * p];
      for (int j = 0; j < n; ++j) dI[(size_t)n * k + j] += u_[(size_t)n * p + j] * dc;
    }
  for (int k = 0; k < n_cells; ++k)
    for (int i = 0; i < n; ++i) {
      double value = d.shape[k].coef[i];
      for (int j = 0; j < n; ++j) value -= d.shape[k].gain[i][j] * dI[(size_t)n * k + j];
      coef_[k].coef[i] = value;
    }
  return data_;
}

LowRankTerm ImplicitShape::jacobian_term(const Assembly &assembly) const {
  LowRankTerm term;
  if (u_.empty()) return term;
  const int n = n_moments_, m = (int)gain_.size() / n;  // n columns per active cell
  term.m = m;
  term.c.assign((size_t)m * m, 0.0);
  for (int a = 0; n * a < m; ++a)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        term.c[(size_t)(n * a + i) * m + n * a + j] = -gain_[(size_t)n * n * a + n * i + j];
  // row g = 2p + f of pair p: field f = 0 (c) belongs to V, f = 1 (mu) to U
  for (const GlobalId row : assembly.my_rows()) {
    const int g = (int)row, p = g / 2, f = g % 2;
    const int a = active_of_cell_[assembly.pair_cell(p)];
    std::vector<int> &ptr = f ? term.u_ptr : term.v_ptr, &col = f ? term.u_col : term.v_col;
    std::vector<double> &val = f ? term.u_val : term.v_val;
    if (a >= 0)
      for (int i = 0; i < n; ++i) {
        col.push_back(n * a + i);
        val.push_back(u_[(size_t)n * p + i]);
      }
    ptr.push_back((int)col.size());
    // the other of U and V has no entry in this row
    std::vector<int> &other = f ? term.v_ptr : term.u_ptr;
    other.push_back(other.back());
  }
  return term;
}

}  // namespace sp
