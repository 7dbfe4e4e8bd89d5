#include "linear/linear_low_rank.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "base/errors.hpp"

namespace sp {

bool all_agree(MPI_Comm comm, bool ok, std::string &why) {
  int status = 0;  // (no class here: a failed factorisation or solve)
  const int first = lowest_failure(comm, !ok, status, why);
  if (first < 0) return true;
  if (why.empty()) why = "the linear solver failed";
  if (first > 0) why += " (rank " + std::to_string(first) + ")";
  return false;
}

namespace {

// y = C t (C m x m row-major). Zeros of C are skipped: C is block-diagonal
// for the shape term, and an exact zero adds nothing.
void times_c(const std::vector<double> &c, int m, const std::vector<double> &t,
             std::vector<double> &y, bool transpose) {
  y.assign(m, 0.0);
  for (int r = 0; r < m; ++r)
    for (int j = 0; j < m; ++j) {
      const double cij = transpose ? c[(size_t)j * m + r] : c[(size_t)r * m + j];
      if (cij != 0.0) y[r] += cij * t[j];
    }
}

// t = W^T x for W stored by rows (ptr, col, val), reduced over comm.
void dots(MPI_Comm comm, int m, const std::vector<int> &ptr, const std::vector<int> &col,
          const std::vector<double> &val, const double *x, std::vector<double> &t) {
  std::vector<double> mine(m, 0.0);
  const int n = (int)ptr.size() - 1;
  for (int r = 0; r < n; ++r)
    for (int k = ptr[r]; k < ptr[r + 1]; ++k) mine[col[k]] += val[k] * x[r];
  t.resize(m);
  MPI_Allreduce(mine.data(), t.data(), m, MPI_DOUBLE, MPI_SUM, comm);
}

// y += W w for W stored by rows.
void add_times(const std::vector<int> &ptr, const std::vector<int> &col,
               const std::vector<double> &val, const std::vector<double> &w, double *y) {
  const int n = (int)ptr.size() - 1;
  for (int r = 0; r < n; ++r) {
    if (ptr[r] == ptr[r + 1]) continue;
    double s = 0.0;
    for (int k = ptr[r]; k < ptr[r + 1]; ++k) s += val[k] * w[col[k]];
    y[r] += s;
  }
}

}  // namespace

void LowRankTerm::v_dots(MPI_Comm comm, const double *x, std::vector<double> &t) const {
  dots(comm, m, v_ptr, v_col, v_val, x, t);
}

void LowRankTerm::add_apply(MPI_Comm comm, const double *x, double *y, bool transpose) const {
  if (empty()) return;
  // U C V^T x, or its transpose V C^T U^T x: the roles of U and V swap
  const auto &in_ptr = transpose ? u_ptr : v_ptr, &in_col = transpose ? u_col : v_col;
  const auto &in_val = transpose ? u_val : v_val;
  const auto &out_ptr = transpose ? v_ptr : u_ptr, &out_col = transpose ? v_col : u_col;
  const auto &out_val = transpose ? v_val : u_val;
  std::vector<double> t, w;
  dots(comm, m, in_ptr, in_col, in_val, x, t);
  times_c(c, m, t, w, transpose);
  add_times(out_ptr, out_col, out_val, w, y);
}

LowRankSolver::LowRankSolver(MPI_Comm comm, std::unique_ptr<LinearSolver> sparse)
    : comm_(comm), sparse_(std::move(sparse)) {}

void LowRankSolver::set_term(LowRankTerm term) {
  term_ = std::move(term);
  term_ready_ = false;
  z_.clear();
  k_lu_.clear();
  k_piv_.clear();
  sparse_->set_rhs_count(rhs_count_ + term_.m);
}

bool LowRankSolver::factor(const CsrRows &A, bool same_pattern, std::string &why) {
  term_ready_ = false;
  n_rows_ = A.n_rows;
  return sparse_->factor(A, same_pattern, why);
}

bool LowRankSolver::solve_many(const double *B, double *X, int nrhs, int n_rows,
                               std::string &why) {
  if (term_.empty()) {
    bool ok = nrhs == 1 ? sparse_->solve(B, X, why) : sparse_->solve_many(B, X, nrhs, n_rows, why);
    return all_agree(comm_, ok, why);
  }
  if (!term_ready_) {
    // the first solve after a factorisation: [B, U] as one block
    if (!factor_term(B, X, nrhs, why)) return false;
  } else {
    bool ok = nrhs == 1 ? sparse_->solve(B, X, why) : sparse_->solve_many(B, X, nrhs, n_rows, why);
    if (!all_agree(comm_, ok, why)) return false;
  }
  for (int j = 0; j < nrhs; ++j) correct(X + (size_t)j * n_rows);
  return true;
}

// Woodbury: (A + U C V^T)^-1 b = y - Z w, y = A^-1 b, Z = A^-1 U and
// (I + C V^T Z) w = C V^T y.
bool LowRankSolver::factor_term(const double *B, double *X, int nrhs, std::string &why) {
  const int m = term_.m, n = n_rows_;
  std::vector<double> block((size_t)n * (nrhs + m), 0.0), solved((size_t)n * (nrhs + m));
  std::copy(B, B + (size_t)n * nrhs, block.begin());
  double *u = block.data() + (size_t)n * nrhs;
  for (int r = 0; r < n; ++r)
    for (int k = term_.u_ptr[r]; k < term_.u_ptr[r + 1]; ++k)
      u[(size_t)term_.u_col[k] * n + r] = term_.u_val[k];
  bool ok = sparse_->solve_many(block.data(), solved.data(), nrhs + m, n, why);
  if (!all_agree(comm_, ok, why)) return false;
  std::copy(solved.begin(), solved.begin() + (size_t)n * nrhs, X);
  z_.assign(solved.begin() + (size_t)n * nrhs, solved.end());
  // S = V^T Z (m x m), then K = I + C S row by row, C's zeros skipped.
  std::vector<double> S((size_t)m * m), t;
  for (int c = 0; c < m; ++c) {
    term_.v_dots(comm_, z_.data() + (size_t)c * n, t);
    for (int r = 0; r < m; ++r) S[(size_t)r * m + c] = t[r];
  }
  k_lu_.assign((size_t)m * m, 0.0);
  for (int r = 0; r < m; ++r)
    for (int c = 0; c < m; ++c) {
      double k = r == c ? 1.0 : 0.0;
      for (int j = 0; j < m; ++j) {
        const double crj = term_.c[(size_t)r * m + j];
        if (crj != 0.0) k += crj * S[(size_t)j * m + c];
      }
      k_lu_[(size_t)r * m + c] = k;
    }
  // LU with partial pivoting (small and dense).
  k_piv_.assign(m, 0);
  double *K = k_lu_.data();
  for (int k = 0; k < m; ++k) {
    int p = k;
    for (int r = k + 1; r < m; ++r)
      if (std::fabs(K[(size_t)r * m + k]) > std::fabs(K[(size_t)p * m + k])) p = r;
    k_piv_[k] = p;
    if (!(std::fabs(K[(size_t)p * m + k]) > 0) || !std::isfinite(K[(size_t)p * m + k])) {
      why = "low-rank term: the Woodbury matrix I + C V^T A^-1 U is singular";
      return false;
    }
    if (p != k)
      for (int c = 0; c < m; ++c) std::swap(K[(size_t)k * m + c], K[(size_t)p * m + c]);
    for (int r = k + 1; r < m; ++r) {
      const double l = K[(size_t)r * m + k] /= K[(size_t)k * m + k];
      for (int c = k + 1; c < m; ++c) K[(size_t)r * m + c] -= l * K[(size_t)k * m + c];
    }
  }
  term_ready_ = true;
  return true;
}

void LowRankSolver::correct(double *x) const {
  const int m = term_.m, n = n_rows_;
  std::vector<double> t, w;
  term_.v_dots(comm_, x, t);
  times_c(term_.c, m, t, w, false);  // C V^T y
  const double *K = k_lu_.data();
  for (int k = 0; k < m; ++k) std::swap(w[k], w[k_piv_[k]]);
  for (int r = 0; r < m; ++r)
    for (int c = 0; c < r; ++c) w[r] -= K[(size_t)r * m + c] * w[c];
  for (int r = m - 1; r >= 0; --r) {
    for (int c = r + 1; c < m; ++c) w[r] -= K[(size_t)r * m + c] * w[c];
    w[r] /= K[(size_t)r * m + r];
  }
  for (int c = 0; c < m; ++c)
    for (int i = 0; i < n; ++i) x[i] -= z_[(size_t)c * n + i] * w[c];
}

}  // namespace sp
