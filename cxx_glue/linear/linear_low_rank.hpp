// A sparse matrix plus a low-rank term, A + U C V^T, solved with any
// LinearSolver for A by Sherman-Morrison-Woodbury (the idea of PETSc's
// MATLRC): the backend never sees the dense coupling, and the Newton code
// never sees Woodbury. The implicit shape term (shape_implicit.hpp) is the
// one user: rank dim (two in 2D, three in 3D) per cell, dense over the cell.
#ifndef SP_LINEAR_LOW_RANK_HPP
#define SP_LINEAR_LOW_RANK_HPP

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "linear/linear.hpp"

namespace sp {

// U C V^T on this rank's rows of a matrix distributed as CsrRows: U and V
// are n_global x m, sparse, stored by this rank's rows (CSR over the m
// columns); C is m x m, dense, row-major, the same on every rank. m = 0:
// no term.
struct LowRankTerm {
  int m = 0;
  std::vector<int> u_ptr{0}, u_col, v_ptr{0}, v_col;
  std::vector<double> u_val, v_val, c;

  bool empty() const { return m == 0; }
  // t = V^T x (length m, reduced over comm); x is this rank's rows.
  void v_dots(MPI_Comm comm, const double *x, std::vector<double> &t) const;
  // y += U C V^T x, or with transpose y += V C^T U^T x (collective).
  void add_apply(MPI_Comm comm, const double *x, double *y, bool transpose) const;
};

// Every rank learns whether all ranks succeeded and, if not, the message of
// the lowest failing rank (collective: what a rank does next must not
// depend on its own outcome alone).
bool all_agree(MPI_Comm comm, bool ok, std::string &why);

// A LinearSolver for A + U C V^T around a LinearSolver for A. factor()
// factors A; the first solve after it solves the right-hand sides and the m
// columns of U as one block (Z = A^-1 U, kept) and LU-factors the m x m
// K = I + C V^T Z (identical on every rank); every solve then corrects
// y = A^-1 b to x = y - Z K^-1 C V^T y. Without a term it passes through.
class LowRankSolver final : public LinearSolver {
 public:
  LowRankSolver(MPI_Comm comm, std::unique_ptr<LinearSolver> sparse);
  // The term of the next factorisations and solves (replaces the last;
  // the factorisation of A stays, Z and K are redone at the next solve).
  void set_term(LowRankTerm term);
  const LowRankTerm &term() const { return term_; }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override;
  bool solve(const double *b, double *x, std::string &why) override {
    return solve_many(b, x, 1, n_rows_, why);
  }
  bool solve_many(const double *B, double *X, int nrhs, int n_rows, std::string &why) override;
  void set_rhs_count(int nrhs) override {
    rhs_count_ = nrhs;
    sparse_->set_rhs_count(nrhs + term_.m);
  }
  long iterations() const override { return sparse_->iterations(); }
  int symbolic_count() const override { return sparse_->symbolic_count(); }
  bool out_of_memory() const override { return sparse_->out_of_memory(); }
  bool overwrites_values() const override { return sparse_->overwrites_values(); }
  bool uses_blocks() const override { return sparse_->uses_blocks(); }
  void set_blocks(const int *block_of_row, int n_global) override {
    sparse_->set_blocks(block_of_row, n_global);
  }
  void set_scales(double dt_mobility, double kappa) override {
    sparse_->set_scales(dt_mobility, kappa);
  }

 private:
  // Z = A^-1 U and K's LU from the block solve [B, U] (X gets A^-1 B).
  bool factor_term(const double *B, double *X, int nrhs, std::string &why);
  // x = y - Z K^-1 C V^T y, in place.
  void correct(double *x) const;

  MPI_Comm comm_;
  std::unique_ptr<LinearSolver> sparse_;
  LowRankTerm term_;
  int n_rows_ = 0;
  int rhs_count_ = 1;
  bool term_ready_ = false;     // Z and K belong to the current factorisation and term
  std::vector<double> z_;       // Z = A^-1 U, this rank's rows, by column
  std::vector<double> k_lu_;    // K = I + C V^T Z, LU in place (row-major)
  std::vector<int> k_piv_;
};

}  // namespace sp
#endif
