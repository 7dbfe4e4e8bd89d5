// GMRES (Belos' pseudo-block GMRES) preconditioned by the Jacobian's
// cell-diagonal part: A with every entry that couples two different cells
// dropped (the repulsion's d mu_k / d c_l, l != k), factored exactly by
// MUMPS. That matrix is block diagonal, one block (c_k, mu_k) per cell, so
// its LU has no fill between cells: the 3D 8-cell stage whose coupled LU
// MUMPS could not allocate (docs/3d.md, "Solvers in 3D") factors as
// eight one-cell problems. The cells couple only where their
// interfaces overlap, so GMRES needs few iterations (docs/3d.md, "Solvers in 3D").
//
// One MUMPS instance factors all blocks at once (its ordering finds the
// independent blocks); under MPI the rows stay distributed as they are.
// The preconditioner is on the right (A M^-1 y = b, x = M^-1 y), the start
// x0 = 0, the test |b - A x| <= tolerance |b|, as linear_gmres_ilu.cpp's.
// The filter (which entries of A stay) is built once per pattern; each
// factor() copies the values through it.
//
// Each cell's mass at any GMRES tolerance: a cell's c rows involve its own
// c and mu only (the mass matrix and the no-flux stiffness), so they are
// the same in A and in the preconditioner P, and the c rows of B = A P^-1
// are the identity's. Every Krylov vector b, (B - I) b, (B - I)^2 b, ...
// past the first has zero c part, so GMRES's residual is r_c = (1 - beta)
// b_c for one number beta: what the mass of a cell loses is that fraction
// of b_c's sum over its rows, which GMRES's least squares drives down with
// the rest (test_cell_blocks: at a tolerance of 1e-4, and Newton ending on
// a solve's update, each cell's mass to 1e-14 per step).
#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Operator.hpp>

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <utility>
#include <vector>

#include "linear/gmres.hpp"
#include "linear/linear.hpp"
#include "linear/tpetra_rows.hpp"

namespace sp {
namespace {

using GO = TpetraRows::GO;
using MV = TpetraRows::MV;
using OP = Tpetra::Operator<double, int, GO>;
using Map = TpetraRows::Map;

// y = alpha M^-1 x + beta y, M^-1 by the inner solver's solves, one column
// at a time. A failed solve throws (Belos passes it on to solve()).
class InnerSolveOperator final : public OP {
 public:
  InnerSolveOperator(Teuchos::RCP<const Map> map, LinearSolver *inner)
      : map_(std::move(map)), inner_(inner) {}
  Teuchos::RCP<const Map> getDomainMap() const override { return map_; }
  Teuchos::RCP<const Map> getRangeMap() const override { return map_; }
  void apply(const MV &X, MV &Y, Teuchos::ETransp mode, double alpha,
             double beta) const override {
    if (mode != Teuchos::NO_TRANS) throw std::logic_error("cell blocks: transpose not supported");
    const int n = (int)X.getLocalLength();
    b_.resize(n);
    x_.resize(n);
    auto xv = X.getLocalViewHost(Tpetra::Access::ReadOnly);
    auto yv = Y.getLocalViewHost(Tpetra::Access::ReadWrite);
    for (size_t j = 0; j < X.getNumVectors(); ++j) {
      for (int i = 0; i < n; ++i) b_[i] = xv(i, j);
      std::string why;
      if (!inner_->solve(b_.data(), x_.data(), why))
        throw std::runtime_error("the cells' blocks: " + why);
      for (int i = 0; i < n; ++i)
        yv(i, j) = beta == 0 ? alpha * x_[i] : alpha * x_[i] + beta * yv(i, j);
    }
  }

 private:
  Teuchos::RCP<const Map> map_;
  LinearSolver *inner_;
  mutable std::vector<double> b_, x_;
};

class CellBlockSolver final : public LinearSolver {
 public:
  CellBlockSolver(MPI_Comm comm, const KrylovOptions &o, std::unique_ptr<LinearSolver> inner)
      : comm_(Teuchos::rcp(new Teuchos::MpiComm<int>(comm))), o_(o), inner_(std::move(inner)) {
    ensure_kokkos();
  }

  bool uses_blocks() const override { return true; }
  void set_blocks(const int *block_of_row, int n_global) override {
    block_.assign(block_of_row, block_of_row + n_global);
    rows_.reset();  // the filter depends on the blocks: the next factor() starts over
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    gmres_.set_factored(false);
    if ((int)block_.size() != A.n_global) {
      why = "cell blocks: the rows' cells were not given (set_blocks)";
      return false;
    }
    bool new_pattern = false;
    if (!rows_ || !same_pattern || !rows_->same_pattern(A)) {
      try {
        set_up(A);
      } catch (const std::exception &e) {
        rows_.reset();
        why = std::string("GMRES on the cells' blocks: set-up failed: ") + e.what();
        return false;
      }
      new_pattern = true;
    }
    try {
      rows_->set_values(A);
    } catch (const std::exception &e) {
      why = std::string("GMRES on the cells' blocks: ") + e.what();
      return false;
    }
    for (size_t k = 0; k < keep_.size(); ++k) val_[k] = A.val[keep_[k]];
    CsrRows D = A;
    D.row_ptr = ptr_.data();
    D.col = col_.data();
    D.val = val_.data();
    if (!inner_->factor(D, !new_pattern, why)) return false;
    gmres_.set_factored(true);
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return gmres_.solve(*rows_, b, x, why, iterations_);
  }

  long iterations() const override { return iterations_; }
  int symbolic_count() const override { return inner_->symbolic_count(); }
  bool out_of_memory() const override { return inner_->out_of_memory(); }

 private:
  // A new pattern: the Tpetra copy of A, the filter to its cell-diagonal
  // part, the GMRES on them.
  void set_up(const CsrRows &A) {
    gmres_.reset();
    rows_.reset();
    auto rows = std::make_unique<TpetraRows>(comm_, A);
    keep_.clear();
    col_.clear();
    ptr_.assign(1, 0);
    for (int i = 0; i < A.n_rows; ++i) {
      const int cell = block_[A.first_row + i];
      for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k)
        if (block_[A.col[k]] == cell) {
          keep_.push_back(k);
          col_.push_back(A.col[k]);
        }
      ptr_.push_back((int)col_.size());
    }
    val_.resize(col_.size());
    prec_ = Teuchos::rcp(new InnerSolveOperator(rows->matrix()->getRowMap(), inner_.get()));
    gmres_.set_up(*rows, prec_, o_, "GMRES on the cells' blocks");
    rows_ = std::move(rows);
  }

  Teuchos::RCP<const Teuchos::Comm<int>> comm_;
  KrylovOptions o_;
  std::unique_ptr<LinearSolver> inner_;
  std::vector<int> block_;               // the cell of each global row
  std::unique_ptr<TpetraRows> rows_;     // A, for GMRES
  std::vector<int> keep_, ptr_, col_;    // the cell-diagonal part's entries of A
  std::vector<double> val_;
  Teuchos::RCP<OP> prec_;
  Gmres gmres_;
  long iterations_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_cell_blocks(MPI_Comm comm, const KrylovOptions &options) {
  return std::make_unique<CellBlockSolver>(comm, options, make_mumps(comm));
}

std::unique_ptr<LinearSolver> make_linear_gmres_cells(MPI_Comm comm,
                                                     const sp_solver_options &options) {
  return make_cell_blocks(comm, krylov_options(options));
}

const char *linear_gmres_cells_version(bool *) {
  return "Belos GMRES preconditioned by the cells' diagonal blocks, factored by MUMPS";
}

}  // namespace sp
