// Amesos (v1) direct solvers (MUMPS, KLU) on an Epetra copy of the CSR rows.
// The Epetra matrix is built once per pattern (rows distributed as given,
// contiguous in rank order) with SymbolicFactorization() once; each
// factor() overwrites its values in place through a precomputed slot table
// and calls NumericFactorization() (the stock NOX Amesos class redoes the
// symbolic step every time). The copy costs one pass over the values.
#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Amesos_Mumps.h>
#include <Epetra_CrsMatrix.h>
#include <Epetra_LinearProblem.h>
#include <Epetra_Map.h>
#include <Epetra_MpiComm.h>
#include <Epetra_Vector.h>
#include <Teuchos_ParameterList.hpp>

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "linear.hpp"

namespace sp {
namespace {

class AmesosSolver final : public DirectSolver {
 public:
  AmesosSolver(MPI_Comm comm, const std::string &which) : comm_(comm), which_(which) {
    Amesos factory;
    if (!factory.Query(which_))
      throw std::runtime_error("solver.linear: " + which_ + " is not available in this Amesos build");
  }
  ~AmesosSolver() override { release(); }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    const int nnz = A.row_ptr[A.n_rows];
    if (!same_pattern || !solver_ || (int)slot_.size() != nnz || map_->NumMyElements() != A.n_rows ||
        map_->NumGlobalElements() != A.n_global) {
      if (!build(A, why)) return false;
    }
    for (int k = 0; k < nnz; ++k) *slot_[k] = A.val[k];
    const int err = solver_->NumericFactorization();
    if (err != 0) {
      why = which_ + ": numeric factorisation failed (error " + std::to_string(err) +
            "; singular matrix?)";
      factored_ = false;
      return false;
    }
    factored_ = true;
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    if (!factored_) {
      why = which_ + ": solve without a factorisation";
      return false;
    }
    const int n = map_->NumMyElements();
    std::copy(b, b + n, rhs_->Values());
    const int err = solver_->Solve();
    if (err != 0) {
      why = which_ + ": solve failed (error " + std::to_string(err) + ")";
      return false;
    }
    std::copy(lhs_->Values(), lhs_->Values() + n, x);
    return true;
  }

  int symbolic_count() const override { return symbolic_; }

 private:
  void release() {
    solver_.reset();
    problem_.reset();
    lhs_.reset();
    rhs_.reset();
    matrix_.reset();
    map_.reset();
    slot_.clear();
    factored_ = false;
  }

  bool build(const CsrRows &A, std::string &why) {
    release();
    // Epetra's (global size, local size) constructor numbers the rows
    // contiguously in rank order: exactly the layout of CsrRows.
    map_ = std::make_unique<Epetra_Map>(A.n_global, A.n_rows, 0, comm_);
    if (map_->MinMyGID() != A.first_row && A.n_rows > 0)
      throw std::logic_error("Amesos backend: rows are not contiguous in rank order");
    std::vector<int> lengths(A.n_rows);
    for (int i = 0; i < A.n_rows; ++i) lengths[i] = A.row_ptr[i + 1] - A.row_ptr[i];
    matrix_ = std::make_unique<Epetra_CrsMatrix>(Copy, *map_, lengths.data(), true);
    std::vector<double> zeros;
    for (int i = 0; i < A.n_rows; ++i) {
      zeros.assign(lengths[i], 0.0);
      if (matrix_->InsertGlobalValues(A.first_row + i, lengths[i], zeros.data(),
                                      const_cast<int *>(A.col + A.row_ptr[i])) < 0)
        throw std::runtime_error("Amesos backend: matrix insertion failed");
    }
    if (matrix_->FillComplete() != 0) throw std::runtime_error("Amesos backend: FillComplete failed");
    // slot_[k]: where entry k of the caller's rows lives in the matrix.
    slot_.resize(A.row_ptr[A.n_rows]);
    std::vector<std::pair<int, int>> gid_pos;
    for (int i = 0; i < A.n_rows; ++i) {
      int len;
      double *vals;
      int *idx;
      matrix_->ExtractMyRowView(i, len, vals, idx);
      gid_pos.resize(len);
      for (int p = 0; p < len; ++p) gid_pos[p] = {matrix_->ColMap().GID(idx[p]), p};
      std::sort(gid_pos.begin(), gid_pos.end());
      for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k) {
        auto it = std::lower_bound(gid_pos.begin(), gid_pos.end(), std::make_pair(A.col[k], -1));
        if (it == gid_pos.end() || it->first != A.col[k])
          throw std::logic_error("Amesos backend: entry missing from the matrix");
        slot_[k] = vals + it->second;
      }
    }
    lhs_ = std::make_unique<Epetra_Vector>(*map_);
    rhs_ = std::make_unique<Epetra_Vector>(*map_);
    problem_ = std::make_unique<Epetra_LinearProblem>(matrix_.get(), lhs_.get(), rhs_.get());
    Amesos factory;
    solver_.reset(factory.Create(which_, *problem_));
    if (!solver_) throw std::runtime_error("Amesos: could not create " + which_);
    Teuchos::ParameterList params;
    params.set("PrintTiming", false);
    params.set("PrintStatus", false);
    params.set("ComputeTrueResidual", false);
    params.set("OutputLevel", 0);
    // MUMPS on every process of the communicator (the default, -1, picks a
    // subset from MPI_COMM_WORLD, which is wrong for any other communicator).
    params.set("MaxProcs", -3);
    solver_->SetParameters(params);
    if (auto *mumps = dynamic_cast<Amesos_Mumps *>(solver_.get())) {
      mumps->SetICNTL(14, 100);  // workspace relaxation (%): delayed pivots need room
      // Amesos 13.2 copies all five CNTL values into MUMPS, unset ones as
      // -123456.789: give the pivoting threshold MUMPS' own default.
      mumps->SetCNTL(1, 0.01);
    }
    const int err = solver_->SymbolicFactorization();
    ++symbolic_;
    if (err != 0) {
      why = which_ + ": symbolic factorisation failed (error " + std::to_string(err) + ")";
      release();
      return false;
    }
    return true;
  }

  Epetra_MpiComm comm_;
  std::string which_;
  std::unique_ptr<Epetra_Map> map_;
  std::unique_ptr<Epetra_CrsMatrix> matrix_;
  std::unique_ptr<Epetra_Vector> lhs_, rhs_;
  std::unique_ptr<Epetra_LinearProblem> problem_;
  std::unique_ptr<Amesos_BaseSolver> solver_;
  std::vector<double *> slot_;
  bool factored_ = false;
  int symbolic_ = 0;
};

}  // namespace

std::unique_ptr<DirectSolver> make_amesos(MPI_Comm comm, const std::string &which) {
  return std::make_unique<AmesosSolver>(comm, which);
}

}  // namespace sp
