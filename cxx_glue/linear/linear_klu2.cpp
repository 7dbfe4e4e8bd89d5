// KLU2 through Amesos2 on a Tpetra copy of the CSR rows (tpetra_rows.hpp):
// solver.linear: klu2. One process only: Debian 13.2's Amesos2 returns wrong
// solutions with several ranks (docs/building.md), so Solver refuses klu2 there and
// this backend checks it again. Amesos2's symbolic factorisation (KLU's
// ordering) is done once per pattern, each factor() overwrites the values
// in place and refactors numerically.
#include <Amesos2.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_RCP.hpp>
#include <Trilinos_version.h>

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <vector>

#include "base/errors.hpp"
#include "linear/linear.hpp"
#include "linear/tpetra_rows.hpp"

namespace sp {
namespace {

using Matrix = TpetraRows::Matrix;
using MV = TpetraRows::MV;

class Amesos2Klu2 final : public LinearSolver {
 public:
  explicit Amesos2Klu2(MPI_Comm comm) : comm_(Teuchos::rcp(new Teuchos::MpiComm<int>(comm))) {
    if (comm_->getSize() != 1)
      throw std::runtime_error("solver.linear: klu2 (Amesos2) runs on one MPI process only");
    if (!Amesos2::query("KLU2"))
      throw std::runtime_error("solver.linear: klu2 is not available in this Amesos2 build");
    ensure_kokkos();
  }
  ~Amesos2Klu2() override { release(); }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    try {
      if (!same_pattern || solver_.is_null() || !rows_->same_pattern(A)) build(A);
      rows_->set_values(A);
      solver_->numericFactorization();
      factored_ = true;
      return true;
    } catch (const std::exception &e) {
      // KLU2 throws on a singular matrix ("KLU2 numeric factorization failed")
      why = std::string("klu2 (Amesos2): factorisation failed (singular matrix?): ") + e.what();
      factored_ = false;
      return false;
    }
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return solve_many(b, x, 1, rows_ ? rows_->n_local() : 0, why);
  }

  bool solve_many(const double *B, double *X, int nrhs, int n_rows, std::string &why) override {
    if (!factored_) {
      why = "klu2 (Amesos2): solve without a factorisation";
      return false;
    }
    try {
      if (b_.is_null() || (int)b_->getNumVectors() != nrhs) {
        b_ = Teuchos::rcp(new MV(rows_->matrix()->getRowMap(), nrhs));
        x_ = Teuchos::rcp(new MV(rows_->matrix()->getRowMap(), nrhs));
      }
      {
        auto b = b_->getLocalViewHost(Tpetra::Access::OverwriteAll);
        for (int j = 0; j < nrhs; ++j)
          for (int i = 0; i < n_rows; ++i) b(i, j) = B[(size_t)j * n_rows + i];
      }
      solver_->solve(x_.ptr(), b_.ptr().getConst());
      auto x = x_->getLocalViewHost(Tpetra::Access::ReadOnly);
      for (int j = 0; j < nrhs; ++j)
        for (int i = 0; i < n_rows; ++i) X[(size_t)j * n_rows + i] = x(i, j);
      return true;
    } catch (const std::exception &e) {
      why = std::string("klu2 (Amesos2): solve failed: ") + e.what();
      return false;
    }
  }

  int symbolic_count() const override { return symbolic_; }

 private:
  void release() {
    solver_ = Teuchos::null;
    b_ = x_ = Teuchos::null;
    rows_.reset();
    factored_ = false;
  }

  void build(const CsrRows &A) {
    release();
    rows_ = std::make_unique<TpetraRows>(comm_, A);
    Teuchos::RCP<const Matrix> matrix = rows_->matrix();
    solver_ = Amesos2::create<Matrix, MV>("KLU2", matrix);
    solver_->symbolicFactorization();
    ++symbolic_;
  }

  Teuchos::RCP<const Teuchos::Comm<int>> comm_;
  std::unique_ptr<TpetraRows> rows_;
  Teuchos::RCP<Amesos2::Solver<Matrix, MV>> solver_;
  Teuchos::RCP<MV> b_, x_;
  bool factored_ = false;
  int symbolic_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_amesos2_klu2(MPI_Comm comm) {
  return std::make_unique<Amesos2Klu2>(comm);
}

std::unique_ptr<LinearSolver> make_linear_klu2(MPI_Comm comm, const sp_solver_options &) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size > 1)
    throw input_error("solver.linear: klu2 runs on one MPI process only (this run has " +
                      std::to_string(size) +
                      "): Debian's Amesos2 KLU2 (Trilinos 13.2) is miscompiled by gcc 12 and "
                      "gives wrong answers on 2 or more processes (docs/building.md); use "
                      "superlu_dist, mumps or klu with several processes");
  return make_amesos2_klu2(comm);
}

// Debian 13.2's Amesos2 KLU2 returns wrong solutions on several ranks (a
// gcc 12 miscompile, docs/building.md): the table marks it SP_LINEAR_SERIAL.
const char *linear_klu2_version(bool *available) {
  *available = Amesos2::query("KLU2");
  return "KLU2 through Amesos2 (Trilinos " TRILINOS_VERSION_STRING "; one process only)";
}

}  // namespace sp
