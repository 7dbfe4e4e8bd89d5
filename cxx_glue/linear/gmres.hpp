// Belos' pseudo-block GMRES on a TpetraRows matrix with a right
// preconditioner, as AztecOO's GMRES did: x0 = 0, the test
// |b - A x| <= tolerance |b| on the recursive and then the true residual,
// classical Gram-Schmidt with a second pass (ICGS), the restart and the
// iteration limit of KrylovOptions. Shared by gmres_ilu (linear_gmres_ilu.cpp)
// and gmres_cells (linear_gmres_cells.cpp).
#ifndef SP_GMRES_HPP
#define SP_GMRES_HPP

#include <BelosLinearProblem.hpp>
#include <BelosSolverManager.hpp>
#include <Tpetra_Operator.hpp>

#include <string>

#include "linear/linear.hpp"
#include "linear/tpetra_rows.hpp"

namespace sp {

class Gmres {
 public:
  using OP = Tpetra::Operator<double, int, TpetraRows::GO>;
  // GMRES on rows' matrix (its lhs and rhs vectors) preconditioned on the
  // right by prec; name starts the messages of a failed solve.
  void set_up(const TpetraRows &rows, const Teuchos::RCP<OP> &prec, const KrylovOptions &o,
              const char *name);
  void reset();
  // Whether the preconditioner holds the current matrix's factorisation:
  // false at the start of each factor(), true when it succeeded; solve()
  // refuses while it is false.
  void set_factored(bool factored) { factored_ = factored; }
  // Solve A x = b (this rank's entries); false with why on no convergence,
  // a failure or no factorisation. The iterations are added to iterations.
  bool solve(const TpetraRows &rows, const double *b, double *x, std::string &why,
             long &iterations);

 private:
  Teuchos::RCP<Belos::LinearProblem<double, TpetraRows::MV, OP>> problem_;
  Teuchos::RCP<Belos::SolverManager<double, TpetraRows::MV, OP>> solver_;
  double tolerance_ = 0;
  std::string name_ = "GMRES";
  bool factored_ = false;
};

}  // namespace sp
#endif
