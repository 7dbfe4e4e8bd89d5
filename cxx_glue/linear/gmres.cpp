#include "linear/gmres.hpp"

#include <BelosSolverFactory_Tpetra.hpp>
#include <BelosTpetraAdapter.hpp>
#include <Teuchos_ParameterList.hpp>

#include <cstdio>
#include <exception>

namespace sp {

void Gmres::set_up(const TpetraRows &rows, const Teuchos::RCP<OP> &prec, const KrylovOptions &o,
                   const char *name) {
  reset();
  auto problem = Teuchos::rcp(new Belos::LinearProblem<double, TpetraRows::MV, OP>(
      rows.matrix(), rows.lhs(), rows.rhs()));
  problem->setRightPrec(prec);
  auto params = Teuchos::rcp(new Teuchos::ParameterList);
  params->set("Num Blocks", o.restart);
  params->set("Maximum Iterations", o.max_iterations);
  // the iteration limit ends the solve, not the restarts
  params->set("Maximum Restarts", o.max_iterations);
  params->set("Convergence Tolerance", o.tolerance);
  params->set("Implicit Residual Scaling", "Norm of RHS");
  params->set("Explicit Residual Scaling", "Norm of RHS");
  params->set("Orthogonalization", "ICGS");
  params->set("Verbosity", 0);  // failures are reported through why
  Belos::SolverFactory<double, TpetraRows::MV, OP> factory;
  solver_ = factory.create("Pseudoblock GMRES", params);
  solver_->setProblem(problem);
  problem_ = problem;
  tolerance_ = o.tolerance;
  name_ = name;
}

void Gmres::reset() {
  factored_ = false;
  solver_ = Teuchos::null;
  problem_ = Teuchos::null;
}

bool Gmres::solve(const TpetraRows &rows, const double *b, double *x, std::string &why,
                  long &iterations) {
  if (!factored_ || solver_.is_null()) {
    why = name_ + ": solve without a factorisation";
    return false;
  }
  const int n = rows.n_local();
  Belos::ReturnType result;
  int its = 0;
  try {
    {
      auto rhs = rows.rhs()->getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (int i = 0; i < n; ++i) rhs(i, 0) = b[i];
    }
    rows.lhs()->putScalar(0.0);
    problem_->setProblem();  // the new right-hand side and the initial residual
    result = solver_->solve();
    its = solver_->getNumIters();
  } catch (const std::exception &e) {
    why = name_ + ": the solve failed: " + e.what();
    return false;
  }
  iterations += its;
  if (result != Belos::Converged) {
    char text[200];
    std::snprintf(text, sizeof text, "%s: no convergence to %g x |b| in %d iterations (Belos: %s)",
                  name_.c_str(), tolerance_, its,
                  solver_->isLOADetected() ? "loss of accuracy: the true residual stays above it"
                                           : "unconverged");
    why = text;
    return false;
  }
  auto lhs = rows.lhs()->getLocalViewHost(Tpetra::Access::ReadOnly);
  for (int i = 0; i < n; ++i) x[i] = lhs(i, 0);
  return true;
}

}  // namespace sp
