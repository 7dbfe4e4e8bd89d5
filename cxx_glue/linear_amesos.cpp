// Amesos (v1) direct solvers (MUMPS, KLU) on an Epetra copy of the CSR rows
// (epetra_rows.hpp), built once per pattern with SymbolicFactorization()
// once; each factor() overwrites the values in place and calls
// NumericFactorization() (the stock NOX Amesos class redoes the symbolic
// step every time).
#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Amesos_Mumps.h>
#include <Epetra_LinearProblem.h>
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
    if (!same_pattern || !solver_ || !rows_->same_pattern(A)) {
      if (!build(A, why)) return false;
    }
    rows_->set_values(A);
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
    const int n = rows_->n_local();
    std::copy(b, b + n, rows_->rhs().Values());
    const int err = solver_->Solve();
    if (err != 0) {
      why = which_ + ": solve failed (error " + std::to_string(err) + ")";
      return false;
    }
    std::copy(rows_->lhs().Values(), rows_->lhs().Values() + n, x);
    return true;
  }

  int symbolic_count() const override { return symbolic_; }

 private:
  void release() {
    solver_.reset();
    problem_.reset();
    rows_.reset();
    factored_ = false;
  }

  bool build(const CsrRows &A, std::string &why) {
    release();
    rows_ = std::make_unique<EpetraRows>(comm_, A);
    problem_ =
        std::make_unique<Epetra_LinearProblem>(&rows_->matrix(), &rows_->lhs(), &rows_->rhs());
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
  std::unique_ptr<EpetraRows> rows_;
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
  if (which == "Amesos_Mumps") return "MUMPS " MUMPS_VERSION " through Amesos";
  if (which == "Amesos_Klu") return "Amesos' own KLU (gathered on rank 0 under MPI)";
  return "unknown";
}

}  // namespace sp
