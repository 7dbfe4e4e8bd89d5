// GMRES (Belos' pseudo-block GMRES) preconditioned by an incomplete LU
// factorisation (Ifpack2 RILUK, ILU(k); under MPI additive Schwarz without
// overlap, one ILU per rank) on a Tpetra copy of the CSR rows: global
// ordinal long long, the only one Debian's Trilinos 13.2 instantiates
// (docs/building.md). factor() computes the ILU of A; solve() runs GMRES on
// the A of the last factor() to a residual of tolerance x |b|.
//
// The method: the preconditioner on the right (A M^-1 y = b,
// x = M^-1 y), the start x0 = 0, the test
// |b - A x| <= tolerance |b| (AZ_conv = AZ_rhs) on the recursive residual
// and then, as AztecOO does, on the true one; classical Gram-Schmidt with
// a second pass (AztecOO's AZ_classic, Belos' ICGS); the restart and the
// iteration limit. One process: RILUK alone, several: Schwarz, as Ifpack's
// factory did ("ILU" with overlap 0). Round-off differs (another
// orthogonalisation code, another ILU code).
//
// The Tpetra copy (tpetra_rows.hpp) is built once per pattern; each
// factor() writes the values into the matrix's own array through a slot
// table (one pass, the graph stays), recomputes the ILU's values and keeps
// its symbolic part.
#include <Ifpack2_Factory.hpp>
#include <Kokkos_Core.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Teuchos_ParameterList.hpp>
#include <Trilinos_version.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <utility>
#include <vector>

#include "base/errors.hpp"
#include "linear/gmres.hpp"
#include "linear/linear.hpp"
#include "linear/tpetra_rows.hpp"

namespace sp {

// Amesos2 and Tpetra keep their arrays in Kokkos views, which need Kokkos
// initialised (the Serial space in Debian's build: no threads). Done once
// per process, finalised at exit if we started it.
void ensure_kokkos() {
  if (Kokkos::is_initialized()) return;
  Kokkos::initialize();
  std::atexit([] {
    if (Kokkos::is_initialized()) Kokkos::finalize();
  });
}

namespace {

using GO = TpetraRows::GO;
using RowMatrix = Tpetra::RowMatrix<double, int, GO>;
using MV = TpetraRows::MV;
using OP = Tpetra::Operator<double, int, GO>;
using Prec = Ifpack2::Preconditioner<double, int, GO>;

class KrylovSolver final : public LinearSolver {
 public:
  KrylovSolver(MPI_Comm comm, const KrylovOptions &o)
      : comm_(Teuchos::rcp(new Teuchos::MpiComm<int>(comm))), o_(o) {
    ensure_kokkos();
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    gmres_.set_factored(false);
    if (!rows_ || !same_pattern || !rows_->same_pattern(A)) {
      try {
        if (!set_up(A, why)) return false;
      } catch (const std::exception &e) {
        rows_.reset();  // the next factor() starts over
        why = std::string("GMRES/ILU: set-up failed: ") + e.what();
        return false;
      }
    }
    try {
      rows_->set_values(A);
      prec_->compute();
    } catch (const std::exception &e) {
      why = std::string("ILU: factorisation failed (zero pivot?): ") + e.what();
      return false;
    }
    gmres_.set_factored(true);
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return gmres_.solve(*rows_, b, x, why, iterations_);
  }

  long iterations() const override { return iterations_; }
  int symbolic_count() const override { return symbolic_; }

 private:
  // A new pattern: the Tpetra copy, the ILU's symbolic part, the GMRES.
  bool set_up(const CsrRows &A, std::string &why) {
    gmres_.reset();
    prec_ = Teuchos::null;
    rows_.reset();
    auto rows = std::make_unique<TpetraRows>(comm_, A);
    Teuchos::RCP<const RowMatrix> matrix = rows->matrix();
    // Ifpack's ILU (Ifpack_ILU, Ifpack_CrsRiluk) and Ifpack2's RILUK take
    // the same parameters with the same defaults: no relaxation, no
    // diagonal perturbation.
    Teuchos::ParameterList ilu;
    ilu.set("fact: iluk level-of-fill", o_.fill);
    ilu.set("fact: relax value", 0.0);
    ilu.set("fact: absolute threshold", 0.0);
    ilu.set("fact: relative threshold", 1.0);
    Teuchos::RCP<Prec> prec;
    if (comm_->getSize() == 1) {
      prec = Ifpack2::Factory::create<RowMatrix>("RILUK", matrix);
      prec->setParameters(ilu);
    } else {
      prec = Ifpack2::Factory::create<RowMatrix>("SCHWARZ", matrix);
      Teuchos::ParameterList schwarz;
      schwarz.set("schwarz: overlap level", 0);
      schwarz.set("schwarz: combine mode", "ZERO");
      schwarz.set("schwarz: use reordering", false);
      schwarz.set("inner preconditioner name", "RILUK");
      schwarz.set("inner preconditioner parameters", ilu);
      prec->setParameters(schwarz);
    }
    try {
      prec->initialize();
    } catch (const std::exception &e) {
      why = std::string("ILU: symbolic set-up failed: ") + e.what();
      return false;  // rows_ stays empty: the next factor() starts over
    }
    gmres_.set_up(*rows, prec, o_, "GMRES");
    rows_ = std::move(rows);
    prec_ = prec;
    ++symbolic_;
    return true;
  }

  Teuchos::RCP<const Teuchos::Comm<int>> comm_;
  KrylovOptions o_;
  std::unique_ptr<TpetraRows> rows_;
  Teuchos::RCP<Prec> prec_;
  Gmres gmres_;
  int symbolic_ = 0;
  long iterations_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_krylov(MPI_Comm comm, const KrylovOptions &options) {
  return std::make_unique<KrylovSolver>(comm, options);
}

std::unique_ptr<LinearSolver> make_linear_gmres_ilu(MPI_Comm comm,
                                                   const sp_solver_options &options) {
  // taken as given: 0 is ILU(0), not a default (the scene has those)
  if (options.ilu_fill < 0)
    throw input_error("solver.ilu_fill: expected a fill level >= 0, got " +
                      std::to_string(options.ilu_fill));
  KrylovOptions k = krylov_options(options);
  k.fill = options.ilu_fill;
  return make_krylov(comm, k);
}

const char *linear_gmres_ilu_version(bool *) {
  return "Belos GMRES, Ifpack2 RILUK ILU(k) (Trilinos " TRILINOS_VERSION_STRING
         "; additive Schwarz under MPI)";
}

}  // namespace sp
