// Direct linear solvers behind one small interface on plain CSR arrays, so
// the Newton code never depends on a backend and the backends never see the
// Jacobian's Tpetra objects. MUMPS, KLU, SuperLU and SuperLU_DIST take the
// arrays through their own C interfaces; KLU2 (Amesos2) and GMRES/ILU
// (Belos, Ifpack2) build a Tpetra matrix of their own from them
// (tpetra_rows.hpp).
#ifndef SP_LINEAR_HPP
#define SP_LINEAR_HPP

#include <mpi.h>

#include <memory>
#include <string>

#include "softpack_linear.h"
#include "softpack_solver.h"

namespace sp {

// This rank's rows of a square n_global x n_global matrix distributed by
// contiguous row blocks in rank order: rank r holds rows first_row ..
// first_row + n_rows - 1, and the blocks of ranks 0, 1, ... follow each
// other (what SuperLU_DIST's SLU_NR_loc format wants). One rank: first_row
// = 0, n_rows = n_global. Column indices are global and 0-based. The
// arrays are borrowed for the call only, and the values are the backend's
// to overwrite: the caller fills them anew before every factor() (Solver's
// sorted copy of the Jacobian's rows, linear_gather's gathered rows), so a
// backend that works in place (SuperLU_DIST scales and permutes them)
// needs no copy of its own, and one that only reads them during the call
// (serial SuperLU) neither. How many copies of the Jacobian's values that
// makes per backend and process count: docs/design.md ("How many copies of
// the Jacobian"; once on one process for serial SuperLU, MUMPS and KLU).
struct CsrRows {
  int n_global = 0;
  int first_row = 0;
  int n_rows = 0;
  const int *row_ptr = nullptr;  // n_rows + 1 offsets into col/val
  const int *col = nullptr;      // global column indices
  double *val = nullptr;         // overwritten by some backends' factor()
};

// Every call is collective over the solver's communicator.
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  // Factor A. same_pattern: the sparsity pattern (and row distribution)
  // equals the previous call's, so the symbolic work (ordering, symbolic
  // factorisation) can be reused. Returns false on a singular matrix or
  // another failure, with why set (possibly on some ranks only: the caller
  // makes the ranks agree).
  virtual bool factor(const CsrRows &A, bool same_pattern, std::string &why) = 0;
  // After a failed factor(): whether it failed for want of memory (an
  // allocation of the factors refused), which a smaller time step, the
  // same matrix's size, would not cure. On this rank.
  virtual bool out_of_memory() const { return false; }
  // Solve A x = b with the last factorisation; b and x are this rank's
  // n_rows entries.
  virtual bool solve(const double *b, double *x, std::string &why) = 0;
  // Solve A X = B for nrhs columns (column-major, each of this rank's
  // n_rows entries). The default solves column by column.
  virtual bool solve_many(const double *B, double *X, int nrhs, int n_rows, std::string &why) {
    for (int j = 0; j < nrhs; ++j)
      if (!solve(B + (size_t)j * n_rows, X + (size_t)j * n_rows, why)) return false;
    return true;
  }
  // How many columns the solves after the next factor() will take (a
  // backend whose solve set-up depends on it prepares for that count).
  virtual void set_rhs_count(int) {}
  // Inner iterations of all solves so far (iterative solvers; 0 otherwise).
  virtual long iterations() const { return 0; }
  // Number of symbolic analyses done (for tests of the reuse).
  virtual int symbolic_count() const = 0;
  // Whether factor() writes into A.val (else it only reads A during the
  // call, and the caller may hand it storage it keeps using: Solver gives
  // the Jacobian's own arrays on one process).
  virtual bool overwrites_values() const { return false; }
  // The cell of each of the n_global rows (a new layout): for solvers that
  // work on the cells' blocks (uses_blocks()); the others ignore it.
  virtual bool uses_blocks() const { return false; }
  virtual void set_blocks(const int *, int) {}
  // The scales of the next factorisation's Jacobian: its c rows are
  // M dc + dt_mobility K dmu, its mu rows M dmu - (kappa K + W) dc
  // (residual.hpp), W the mass matrix weighted by f''(c) and the pairs'
  // terms. For the solvers that build a preconditioner from the blocks'
  // structure; the others ignore it.
  virtual void set_scales(double /*dt_mobility*/, double /*kappa*/) {}
};

// Serial SuperLU (dgstrf/dgstrs on the transposed CSC view of the CSR); one
// rank holding all rows.
std::unique_ptr<LinearSolver> make_superlu();
// A serial solver run on rank 0 of comm: factor() gathers the rows there,
// solve() gathers b and scatters x. serial is used on rank 0 only (may be
// null elsewhere).
std::unique_ptr<LinearSolver> make_gathered(MPI_Comm comm, std::unique_ptr<LinearSolver> serial);
// SuperLU_DIST (pdgssvx, SLU_NR_loc rows as they are distributed).
// pair_order: METIS on the (cell, node) pair graph (rows in (c, mu) pairs),
// else SuperLU_DIST's METIS on the unknowns. refine: one step of iterative
// refinement per solve.
std::unique_ptr<LinearSolver> make_superlu_dist(MPI_Comm comm, bool pair_order, bool refine);
// MUMPS through its own C interface (dmumps_c) on the rows as they are
// distributed (linear_mumps.cpp).
std::unique_ptr<LinearSolver> make_mumps(MPI_Comm comm);
// Serial KLU (SuiteSparse's libklu, linear_klu.cpp); one rank holding all
// rows (make_gathered under MPI).
std::unique_ptr<LinearSolver> make_klu();
// KLU2 through Amesos2 on a Tpetra copy of the rows; one process only
// (Debian 13.2's Amesos2 is wrong on several: docs/building.md).
std::unique_ptr<LinearSolver> make_amesos2_klu2(MPI_Comm comm);
// GMRES (Belos) preconditioned by ILU(fill) (Ifpack2 RILUK; additive
// Schwarz across ranks), to a residual of tolerance x |b|. fill and
// tolerance come from the caller (the scene's solver.ilu_fill and
// solver.krylov_tol hold the defaults).
struct KrylovOptions {
  int fill = -1;
  int restart = 100;
  int max_iterations = 500;
  double tolerance = 0;
};
std::unique_ptr<LinearSolver> make_krylov(MPI_Comm comm, const KrylovOptions &options);
// GMRES (Belos) preconditioned by the Jacobian's cell-diagonal blocks (the
// entries coupling two cells dropped), factored by MUMPS (linear_gmres_cells.cpp);
// needs set_blocks. options.fill is not used.
std::unique_ptr<LinearSolver> make_cell_blocks(MPI_Comm comm, const KrylovOptions &options);
// Kokkos initialised once per process (Amesos2's and Tpetra's arrays are
// Kokkos views), finalised at exit if this started it (linear_gmres_ilu.cpp).
void ensure_kokkos();

// The Krylov options of the scene's solver options (krylov_tol checked).
KrylovOptions krylov_options(const sp_solver_options &options);

// Each solver of the table (c_api/softpack_linear.h) defines, in its
// linear_NAME.cpp, its factory from the scene's solver options and the
// library behind it with its version, from the headers the glue was
// compiled with (softpack info; static text; *available set to false when
// this build cannot serve it, left as it is otherwise). SP_STR makes a
// string of a version macro's value.
#define SP_STR_(x) #x
#define SP_STR(x) SP_STR_(x)
#define SP_LINEAR_DECLARE_(id, name, ranks)                                              \
  std::unique_ptr<LinearSolver> make_linear_##name(MPI_Comm comm,                        \
                                                   const sp_solver_options &options);   \
  const char *linear_##name##_version(bool *available);
SP_LINEAR_SOLVERS(SP_LINEAR_DECLARE_)
#undef SP_LINEAR_DECLARE_

// The solver options.linear names (an sp_linear_kind, not auto) on comm:
// its factory, wrapped by make_gathered for a serial solver on several
// ranks; a one-process solver on several ranks is bad input.
std::unique_ptr<LinearSolver> make_linear_solver(MPI_Comm comm, const sp_solver_options &options);
// The library and version behind options.linear kind @p kind (-1: no such
// kind, 0: not served by this build, 1: served).
int linear_solver_version(int kind, const char **version);

}  // namespace sp
#endif
