// Does this Trilinos' Amesos2 KLU2 solve right on several MPI processes?
// Debian 12's libtrilinos_amesos2.so (Trilinos 13.2, gcc 12, -O2) does not:
// the call to klu_lsolve in KLU2's solve is optimised away, and every
// solve on 2 or more ranks returns a wrong x (docs/building.md). Built with
// cmake -DSOFTPACK_KLU2_CHECK=ON; run on 1 and 2 processes:
//   mpiexec -np 2 build/klu2_miscompile_check     (exit 0 right, 1 wrong)
// A nonsymmetric tridiagonal matrix (1D convection-diffusion, n = 1000,
// rows in contiguous blocks per rank), b = A x* for a known x*; KLU2 solves
// A x = b; the relative error |x - x*|_inf / |x*|_inf must be round-off.
// With KLU2_FROM_HEADERS defined (the klu2_miscompile_check_local target)
// KLU2 is compiled in this unit from the installed headers, with this
// unit's compiler and flags, instead of taken from libtrilinos_amesos2:
// gcc 12 at -O2 gets it wrong, at -O0 right (docs/building.md).
#include <Amesos2.hpp>
#ifdef KLU2_FROM_HEADERS
#include <Amesos2_KLU2_def.hpp>
#endif
#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Core.hpp>
#include <Tpetra_CrsMatrix.hpp>

#include <cstdio>

int main(int argc, char **argv) {
  using GO = long long;  // the only global ordinal Debian's Tpetra has
  using Matrix = Tpetra::CrsMatrix<double, int, GO>;
  using MV = Tpetra::MultiVector<double, int, GO>;
  Tpetra::ScopeGuard scope(&argc, &argv);
  auto comm = Tpetra::getDefaultComm();
  const GO n = 1000;
  auto map = Teuchos::rcp(new Tpetra::Map<int, GO>(n, 0, comm));
  auto A = Teuchos::rcp(new Matrix(map, 3));
  for (GO i = map->getMinGlobalIndex(); i <= map->getMaxGlobalIndex(); ++i) {
    GO cols[3] = {i - 1, i, i + 1};
    double vals[3] = {-1.5, 4.0, -0.5};  // diffusion plus upwinded convection
    const int first = i == 0 ? 1 : 0, count = (i == 0 || i == n - 1) ? 2 : 3;
    A->insertGlobalValues(i, count, vals + first, cols + first);
  }
  A->fillComplete();
  auto x_true = Teuchos::rcp(new MV(map, 1)), b = Teuchos::rcp(new MV(map, 1)),
       x = Teuchos::rcp(new MV(map, 1));
  {
    auto v = x_true->getLocalViewHost(Tpetra::Access::OverwriteAll);
    for (size_t l = 0; l < v.extent(0); ++l) v(l, 0) = 1.0 + 0.001 * map->getGlobalElement(l);
  }
  A->apply(*x_true, *b);
#ifdef KLU2_FROM_HEADERS
  Teuchos::RCP<Amesos2::Solver<Matrix, MV>> solver =
      Teuchos::rcp(new Amesos2::KLU2<Matrix, MV>(A, x, b));
#else
  auto solver = Amesos2::create<Matrix, MV>("KLU2", A, x, b);
#endif
  solver->symbolicFactorization().numericFactorization().solve();
  x->update(-1.0, *x_true, 1.0);  // x - x*
  const double err = x->getVector(0)->normInf() / x_true->getVector(0)->normInf();
  const bool right = err < 1e-12;
  if (comm->getRank() == 0)
    std::printf("Amesos2 KLU2 on %d process(es): relative error %.2e: %s\n", comm->getSize(), err,
                right ? "right" : "WRONG (docs/building.md: the gcc 12 miscompile)");
  return right ? 0 : 1;
}
