// Amesos (v1) direct solvers (KLU; MUMPS has its own, linear_mumps.cpp) on the caller's Epetra matrix
// when it has one that is the rows (the Jacobian on one process), else on
// an Epetra copy of the CSR rows (epetra_rows.hpp), built once per pattern
// with SymbolicFactorization() once; each factor() overwrites the copy's
// values in place (the caller's matrix has them already) and calls
// NumericFactorization() (the stock NOX Amesos class redoes the symbolic
// step every time).
#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Epetra_CrsMatrix.h>
#include <Epetra_LinearProblem.h>
#include <Epetra_Vector.h>
#include <Teuchos_ParameterList.hpp>

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "epetra_rows.hpp"
#include "errors.hpp"
#include "linear.hpp"

namespace sp {
namespace {

class AmesosSolver final : public DirectSolver {
 public:
  AmesosSolver(MPI_Comm comm, const std::string &which) : comm_(comm), which_(which) {
    Amesos factory;
    if (!factory.Query(which_))
      throw input_error("solver.linear: " + which_ + " is not available in this Amesos build");
  }
  ~AmesosSolver() override { release(); }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    const bool rebuild = !same_pattern || !solver_ || A.matrix != matrix_ ||
                         (!A.matrix && !rows_->same_pattern(A));
    if (rebuild && !build(A, why)) return false;
    if (!matrix_) rows_->set_values(A);  // (the caller's matrix holds them)
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
    const int n = rhs_->MyLength();
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
  void forget_matrix() override {
    if (matrix_) release();  // Amesos' solver refers to it, its destructor too
  }

 private:
  void release() {
    solver_.reset();
    problem_.reset();
    rows_.reset();
    own_lhs_.reset();
    own_rhs_.reset();
    matrix_ = nullptr;
    lhs_ = rhs_ = nullptr;
    factored_ = false;
  }

  // The problem on the caller's matrix (A.matrix) or on an Epetra copy of
  // the rows (EpetraRows), and the symbolic factorisation.
  bool build(const CsrRows &A, std::string &why) {
    release();
    Epetra_RowMatrix *M;
    if (A.matrix) {
      matrix_ = A.matrix;
      own_lhs_ = std::make_unique<Epetra_Vector>(matrix_->RowMap());
      own_rhs_ = std::make_unique<Epetra_Vector>(matrix_->RowMap());
      M = matrix_;
      lhs_ = own_lhs_.get();
      rhs_ = own_rhs_.get();
    } else {
      rows_ = std::make_unique<EpetraRows>(comm_, A);
      M = &rows_->matrix();
      lhs_ = &rows_->lhs();
      rhs_ = &rows_->rhs();
    }
    problem_ = std::make_unique<Epetra_LinearProblem>(M, lhs_, rhs_);
    Amesos factory;
    solver_.reset(factory.Create(which_, *problem_));
    if (!solver_) throw std::runtime_error("Amesos: could not create " + which_);
    Teuchos::ParameterList params;
    params.set("PrintTiming", false);
    params.set("PrintStatus", false);
    params.set("ComputeTrueResidual", false);
    params.set("OutputLevel", 0);
    solver_->SetParameters(params);
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
  std::unique_ptr<EpetraRows> rows_;   // the copy, when the caller has no matrix
  Epetra_CrsMatrix *matrix_ = nullptr;  // else the caller's (CsrRows.matrix)
  std::unique_ptr<Epetra_Vector> own_lhs_, own_rhs_;
  Epetra_Vector *lhs_ = nullptr, *rhs_ = nullptr;
  std::unique_ptr<Epetra_LinearProblem> problem_;
  std::unique_ptr<Amesos_BaseSolver> solver_;
  bool factored_ = false;
  int symbolic_ = 0;
};

}  // namespace

std::unique_ptr<DirectSolver> make_amesos(MPI_Comm comm, const std::string &which) {
  return std::make_unique<AmesosSolver>(comm, which);
}

bool amesos_available(const std::string &which) { return Amesos().Query(which); }

const char *amesos_version(const std::string &which) {
  if (which == "Amesos_Klu") return "Amesos' own KLU (gathered on rank 0 under MPI)";
  return "unknown";
}

}  // namespace sp
