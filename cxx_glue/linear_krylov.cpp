// GMRES (AztecOO) preconditioned by an incomplete LU factorisation
// (Ifpack ILU(k); under MPI additive Schwarz, one ILU per rank) on an
// Epetra copy of the CSR rows. factor() computes the ILU of A; solve()
// runs GMRES on the A of the last factor() to a relative residual.
#include <AztecOO.h>
#include <Ifpack.h>
#include <Ifpack_Preconditioner.h>
#include <Teuchos_ParameterList.hpp>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "epetra_rows.hpp"
#include "linear.hpp"

namespace sp {
namespace {

class KrylovSolver final : public DirectSolver {
 public:
  KrylovSolver(MPI_Comm comm, const KrylovOptions &o) : comm_(comm), o_(o) {}

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    if (!rows_ || !same_pattern || !rows_->same_pattern(A)) {
      prec_.reset();
      gmres_.reset();
      rows_ = std::make_unique<EpetraRows>(comm_, A);
      Ifpack factory;
      prec_.reset(factory.Create("ILU", &rows_->matrix(), 0));
      Teuchos::ParameterList p;
      p.set("fact: level-of-fill", o_.fill);
      prec_->SetParameters(p);
      if (prec_->Initialize() != 0) {
        why = "ILU: symbolic set-up failed";
        prec_.reset();
        rows_.reset();  // the next factor() starts over
        factored_ = false;
        return false;
      }
      gmres_ = std::make_unique<AztecOO>(&rows_->matrix(), &rows_->lhs(), &rows_->rhs());
      gmres_->SetPrecOperator(prec_.get());
      gmres_->SetAztecOption(AZ_solver, AZ_gmres);
      gmres_->SetAztecOption(AZ_kspace, o_.restart);
      gmres_->SetAztecOption(AZ_conv, AZ_rhs);
      gmres_->SetAztecOption(AZ_output, AZ_none);
      ++symbolic_;
    }
    rows_->set_values(A);
    factored_ = prec_->Compute() == 0;
    if (!factored_) why = "ILU: factorisation failed (zero pivot?)";
    return factored_;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    if (!factored_) {
      why = "GMRES: solve without a factorisation";
      return false;
    }
    const int n = rows_->n_local();
    std::copy(b, b + n, rows_->rhs().Values());
    rows_->lhs().PutScalar(0.0);
    gmres_->Iterate(o_.max_iterations, o_.tolerance);
    const double *status = gmres_->GetAztecStatus();
    iterations_ += (long)status[AZ_its];
    if (status[AZ_why] != AZ_normal) {
      char text[128];
      std::snprintf(text, sizeof text,
                    "GMRES: no convergence to %g x |b| in %d iterations (AztecOO status %d)",
                    o_.tolerance, (int)status[AZ_its], (int)status[AZ_why]);
      why = text;
      return false;
    }
    std::copy(rows_->lhs().Values(), rows_->lhs().Values() + n, x);
    return true;
  }

  long iterations() const override { return iterations_; }
  int symbolic_count() const override { return symbolic_; }

 private:
  Epetra_MpiComm comm_;
  KrylovOptions o_;
  std::unique_ptr<EpetraRows> rows_;
  std::unique_ptr<Ifpack_Preconditioner> prec_;
  std::unique_ptr<AztecOO> gmres_;
  bool factored_ = false;
  int symbolic_ = 0;
  long iterations_ = 0;
};

}  // namespace

std::unique_ptr<DirectSolver> make_krylov(MPI_Comm comm, const KrylovOptions &options) {
  return std::make_unique<KrylovSolver>(comm, options);
}

const char *krylov_version() { return "AztecOO GMRES, Ifpack ILU(k)"; }

}  // namespace sp
