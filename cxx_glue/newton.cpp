#include "newton.hpp"

#include <NOX.H>
#include <NOX_Observer.hpp>
#include <NOX_StatusTest_Combo.H>
#include <NOX_StatusTest_Divergence.H>
#include <NOX_StatusTest_FiniteValue.H>
#include <NOX_StatusTest_MaxIters.H>
#include <NOX_StatusTest_NormF.H>
#include <NOX_Thyra_Group.H>
#include <NOX_Thyra_Vector.H>
#include <Teuchos_ParameterList.hpp>
#include <Thyra_LinearOpWithSolveBase.hpp>
#include <Thyra_LinearOpWithSolveFactoryBase.hpp>
#include <Thyra_StateFuncModelEvaluatorBase.hpp>
#include <Thyra_TpetraThyraWrappers.hpp>
#include <Tpetra_CrsMatrix.hpp>
#include <Tpetra_Vector.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "base/errors.hpp"

namespace sp {
namespace {

double now() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// NOX's vectors are Thyra vectors on Tpetra ones (Thyra::TpetraVector)
// over the assembly's row map, so their local arrays are this rank's rows
// in Assembly::my_rows() order: Solver works on those arrays directly.
using ThyraSpace = Thyra::VectorSpaceBase<double>;
using ThyraMV = Thyra::MultiVectorBase<double>;
using Extract = Thyra::TpetraOperatorVectorExtraction<double, int, GlobalId>;

// The local array of column j of a Thyra multivector on Tpetra (NOX's
// vectors are one column; the Tpetra vector outlives the pointer).
const double *local(const ThyraMV &v, int j = 0) {
  const auto t = Extract::getConstTpetraMultiVector(Teuchos::rcpFromRef(v));
  return t->getLocalViewHost(Tpetra::Access::ReadOnly).data() + j * t->getStride();
}
double *local(ThyraMV &v, int j = 0) {
  const auto t = Extract::getTpetraMultiVector(Teuchos::rcpFromRef(v));
  return t->getLocalViewHost(Tpetra::Access::ReadWrite).data() + j * t->getStride();
}
double *local(NOX::Abstract::Vector &v) {
  return local(dynamic_cast<NOX::Thyra::Vector &>(v).getThyraVector());
}
const double *local(const NOX::Abstract::Vector &v) {
  return local(dynamic_cast<const NOX::Thyra::Vector &>(v).getThyraVector());
}

// The GMRES solvers' options from the scene's: the tolerance as resolved
// (src/run/run_options.c turns the scene's 0 into the solver's default).
// NOX's model of a step's equations (a Thyra ModelEvaluator): F(x) and
// the Jacobian at x into the operator NOX passes (JacobianSolve, which
// stands for Solver's matrix). Built once per layout with the group;
// Solver::step points it at its sp_step_data for the length of the step
// (Scope). Under modified Newton (jacobian_reuse) a Jacobian NOX asks for
// is not filled while the factorisation may be kept (may_reuse_jacobian).
class StepModel : public Thyra::StateFuncModelEvaluatorBase<double> {
 public:
  StepModel(Solver &s, Teuchos::RCP<const ThyraSpace> space) : s_(s), space_(std::move(space)) {}
  Teuchos::RCP<const ThyraSpace> get_x_space() const override { return space_; }
  Teuchos::RCP<const ThyraSpace> get_f_space() const override { return space_; }
  Thyra::ModelEvaluatorBase::InArgs<double> createInArgs() const override {
    Thyra::ModelEvaluatorBase::InArgsSetup<double> in;
    in.setModelEvalDescription("softpack step");
    in.setSupports(Thyra::ModelEvaluatorBase::IN_ARG_x);
    return std::move(in);
  }
  // Points the callbacks at d until the scope ends.
  class Scope {
   public:
    Scope(StepModel &m, const sp_step_data &d) : m_(m) { m_.d_ = &d; }
    ~Scope() { m_.d_ = nullptr; }
    Scope(const Scope &) = delete;
    Scope &operator=(const Scope &) = delete;

   private:
    StepModel &m_;
  };

 private:
  Thyra::ModelEvaluatorBase::OutArgs<double> createOutArgsImpl() const override {
    Thyra::ModelEvaluatorBase::OutArgsSetup<double> out;
    out.setModelEvalDescription("softpack step");
    out.setSupports(Thyra::ModelEvaluatorBase::OUT_ARG_f);
    out.setSupports(Thyra::ModelEvaluatorBase::OUT_ARG_W_op);
    return std::move(out);
  }
  void evalModelImpl(const Thyra::ModelEvaluatorBase::InArgs<double> &in,
                     const Thyra::ModelEvaluatorBase::OutArgs<double> &out) const override {
    const double *x = local(*in.get_x());
    if (const auto f = out.get_f(); !f.is_null())  // (assembled into NOX's vector itself)
      s_.fill_residual(data(), x, *Extract::getTpetraVector(f));
    if (!out.get_W_op().is_null() && !s_.may_reuse_jacobian())  // (else keep matrix and factors)
      s_.fill_jacobian(data(), x);
  }
  const sp_step_data &data() const {
    if (!d_) throw std::logic_error("NOX evaluated the step equations outside a step");
    return *d_;
  }
  Solver &s_;
  Teuchos::RCP<const ThyraSpace> space_;
  const sp_step_data *d_ = nullptr;
};

// The Jacobian as NOX sees it, both as the operator the model fills (W_op)
// and as the operator with a solve: apply is Solver::apply_jacobian (the
// sparse matrix plus the implicit shape term's low-rank part), solve is
// Solver::solve_linear, which factors the matrix first if it was filled
// since the last factorisation. There is no preconditioner.
class JacobianSolve : public Thyra::LinearOpWithSolveBase<double> {
 public:
  JacobianSolve(Solver &s, Teuchos::RCP<const ThyraSpace> space)
      : s_(s), space_(std::move(space)) {}
  Teuchos::RCP<const ThyraSpace> range() const override { return space_; }
  Teuchos::RCP<const ThyraSpace> domain() const override { return space_; }

 protected:
  bool opSupportedImpl(Thyra::EOpTransp t) const override {
    return t == Thyra::NOTRANS || t == Thyra::TRANS;
  }
  // Y = alpha op(J) X + beta Y (NOX's applyJacobian and its transpose)
  void applyImpl(Thyra::EOpTransp t, const ThyraMV &X, const Teuchos::Ptr<ThyraMV> &Y,
                 double alpha, double beta) const override {
    const size_t n = Extract::getConstTpetraMultiVector(Teuchos::rcpFromRef(X))->getLocalLength();
    std::vector<double> JX(n);
    for (int j = 0; j < X.domain()->dim(); ++j) {
      s_.apply_jacobian(local(X, j), JX.data(), t != Thyra::NOTRANS);
      double *y = local(*Y, j);
      for (size_t i = 0; i < n; ++i) y[i] = alpha * JX[i] + (beta == 0 ? 0.0 : beta * y[i]);
    }
  }
  Thyra::SolveStatus<double> solveImpl(Thyra::EOpTransp t, const ThyraMV &B,
                                       const Teuchos::Ptr<ThyraMV> &X,
                                       const Teuchos::Ptr<const Thyra::SolveCriteria<double>>)
      const override {
    if (t != Thyra::NOTRANS) throw std::logic_error("NOX asked for a transposed solve");
    // A failed solve (the reason kept by Solver): NOX's Newton direction
    // throws, as it did with NOX::Epetra.
    Thyra::SolveStatus<double> status;
    status.solveStatus = Thyra::SOLVE_STATUS_CONVERGED;
    for (int j = 0; j < B.domain()->dim(); ++j)
      if (!s_.solve_linear(local(B, j), local(*X, j)))
        status.solveStatus = Thyra::SOLVE_STATUS_UNKNOWN;
    return status;
  }

 private:
  Solver &s_;
  Teuchos::RCP<const ThyraSpace> space_;
};

// Hands NOX the one JacobianSolve: "initialising" it with the operator NOX
// just had filled changes nothing (Solver knows whether the matrix changed
// since its last factorisation: the carry and jacobian_reuse decide there).
class JacobianSolveFactory : public Thyra::LinearOpWithSolveFactoryBase<double> {
 public:
  explicit JacobianSolveFactory(Teuchos::RCP<JacobianSolve> op) : op_(std::move(op)) {}
  bool isCompatible(const Thyra::LinearOpSourceBase<double> &) const override { return true; }
  Teuchos::RCP<Thyra::LinearOpWithSolveBase<double>> createOp() const override { return op_; }
  void initializeOp(const Teuchos::RCP<const Thyra::LinearOpSourceBase<double>> &,
                    Thyra::LinearOpWithSolveBase<double> *,
                    Thyra::ESupportSolveUse) const override {}
  void uninitializeOp(Thyra::LinearOpWithSolveBase<double> *,
                      Teuchos::RCP<const Thyra::LinearOpSourceBase<double>> *,
                      Teuchos::RCP<const Thyra::PreconditionerBase<double>> *,
                      Teuchos::RCP<const Thyra::LinearOpSourceBase<double>> *,
                      Thyra::ESupportSolveUse *) const override {}
  void setParameterList(const Teuchos::RCP<Teuchos::ParameterList> &) override {}
  Teuchos::RCP<Teuchos::ParameterList> getNonconstParameterList() override {
    return Teuchos::null;
  }
  Teuchos::RCP<Teuchos::ParameterList> unsetParameterList() override { return Teuchos::null; }

 private:
  Teuchos::RCP<JacobianSolve> op_;
};

// Records ||F|| at the start and after every iteration (Solver::note_residual).
class ResidualRecorder : public NOX::Observer {
 public:
  explicit ResidualRecorder(Solver &s) : s_(s) {}
  void runPreSolve(const NOX::Solver::Generic &solver) override { record(solver); }
  void runPostIterate(const NOX::Solver::Generic &solver) override { record(solver); }

 private:
  void record(const NOX::Solver::Generic &solver) {
    s_.note_residual(solver.getSolutionGroup().getNormF());
  }
  Solver &s_;
};

// Our status tests: `outcome` once a condition holds, Unconverged before;
// print() names the condition. Each check decides afresh (from the solver
// and the Solver's counters of the current step), so one test object
// serves every step.
class ConditionTest : public NOX::StatusTest::Generic {
 public:
  ConditionTest(NOX::StatusTest::StatusType outcome, std::string what)
      : outcome_(outcome), what_(std::move(what)) {}
  NOX::StatusTest::StatusType checkStatus(const NOX::Solver::Generic &solver,
                                          NOX::StatusTest::CheckType) override {
    status_ = holds(solver) ? outcome_ : NOX::StatusTest::Unconverged;
    return status_;
  }
  NOX::StatusTest::StatusType getStatus() const override { return status_; }
  std::ostream &print(std::ostream &s, int indent) const override {
    for (int i = 0; i < indent; ++i) s << ' ';
    s << status_ << what_ << "\n";
    return s;
  }

 protected:
  virtual bool holds(const NOX::Solver::Generic &solver) const = 0;

 private:
  NOX::StatusTest::StatusType outcome_;
  std::string what_;
  NOX::StatusTest::StatusType status_ = NOX::StatusTest::Unevaluated;
};

// Converged only after at least one Newton update: the update conserves
// each cell's mass to round-off, a residual tolerance alone would not.
class AtLeastOneIteration : public ConditionTest {
 public:
  AtLeastOneIteration() : ConditionTest(NOX::StatusTest::Converged, "At least one Newton update") {}

 protected:
  bool holds(const NOX::Solver::Generic &solver) const override {
    return solver.getNumIterations() >= 1;
  }
};

// Converged (with at least one update) once every c entry of the last
// update is within update_atol + update_rtol |c| (sp_step_data): the time
// control's tolerance, scaled down, decides how exactly a step is solved.
// The tolerances are the step's (set_tolerances); both 0 switch the test
// off (it never holds and reduces nothing). The state is (c, mu) per pair:
// even global indices are c.
class UpdateSmall : public ConditionTest {
 public:
  explicit UpdateSmall(MPI_Comm comm)
      : ConditionTest(NOX::StatusTest::Converged, "|dc| <= update_atol + update_rtol |c|"),
        comm_(comm) {}
  void set_tolerances(double rtol, double atol) {
    rtol_ = rtol;
    atol_ = atol;
  }

 protected:
  bool holds(const NOX::Solver::Generic &solver) const override {
    if (!(rtol_ > 0 || atol_ > 0) || solver.getNumIterations() < 1) return false;
    const auto &X = dynamic_cast<const NOX::Thyra::Vector &>(solver.getSolutionGroup().getX());
    const double *x = local(X), *xp = local(solver.getPreviousSolutionGroup().getX());
    const auto rows = Extract::getConstTpetraMultiVector(X.getThyraRCPVector())->getMap();
    double worst = 0;
    for (size_t i = 0; i < rows->getNodeNumElements(); ++i) {
      if (rows->getGlobalElement((int)i) % 2 != 0) continue;
      const double e = std::fabs(x[i] - xp[i]) / (atol_ + rtol_ * std::fabs(x[i]));
      worst = std::isnan(e) ? INFINITY : std::max(worst, e);  // (a NaN anywhere fails)
    }
    MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, comm_);
    return worst <= 1;
  }

 private:
  MPI_Comm comm_;
  double rtol_ = 0, atol_ = 0;
};

// A stop requested during the step (sp_step_data.interrupt, polled at the
// guess and after each iteration, every rank alike): the solve fails with
// SP_NEWTON_INTERRUPTED and the caller drops the step.
class InterruptTest : public ConditionTest {
 public:
  explicit InterruptTest(Solver &s)
      : ConditionTest(NOX::StatusTest::Failed, "No stop requested"), s_(s) {}

 protected:
  bool holds(const NOX::Solver::Generic &) const override { return s_.interrupt_requested(); }

 private:
  Solver &s_;
};

// Modified Newton's iteration limit: this many factorisations (each
// iteration that reused one was cheap, and followed one that cut ||F|| by
// jacobian_reuse).
class FactorisationLimit : public ConditionTest {
 public:
  FactorisationLimit(const Solver &s, int limit)
      : ConditionTest(NOX::StatusTest::Failed, "Factorisations < " + std::to_string(limit)),
        s_(s), limit_(limit) {}

 protected:
  bool holds(const NOX::Solver::Generic &) const override {
    return s_.step_factorisations() >= limit_;
  }

 private:
  const Solver &s_;
  int limit_;
};

// Fails a step as soon as ||F_k|| > ratio ||F_0|| (sp_solver_options.
// newton_divergence): the failed attempts of a packed aggregate all blow
// up within a few iterations, and the retry with a smaller dt comes the
// same whether the step fails now or after newton_max_its iterations.
class RelativeDivergence : public ConditionTest {
 public:
  RelativeDivergence(const Solver &s, double ratio)
      : ConditionTest(NOX::StatusTest::Failed, "||F|| <= " + std::to_string(ratio) + " ||F_0||"),
        s_(s), ratio_(ratio) {}

 protected:
  // ||F_0|| was recorded before the first iteration (ResidualRecorder).
  bool holds(const NOX::Solver::Generic &solver) const override {
    return solver.getNumIterations() >= 1 &&
           solver.getSolutionGroup().getNormF() > ratio_ * s_.step_first_norm();
  }

 private:
  const Solver &s_;
  double ratio_;
};

}  // namespace

// What NOX needs for a step, built ahead of the steps; Solver::step only
// loads its guess and tolerances.
struct Solver::Nox {
  // Once per solver: they depend on the options only.
  Teuchos::RCP<Teuchos::ParameterList> params;
  Teuchos::RCP<std::ostringstream> errors;  // NOX's error stream (cleared each step)
  Teuchos::RCP<NOX::StatusTest::Generic> tests;
  // ||F|| < newton_rtol ||F(guess)||: NOX's relative NormF takes ||F(guess)||
  // from the group it is built with, so this one is an absolute NormF whose
  // tolerance each step sets to the product NOX's relative test forms.
  Teuchos::RCP<NOX::StatusTest::NormF> relative;
  Teuchos::RCP<UpdateSmall> update;           // the step's update tolerances
  Teuchos::RCP<RelativeDivergence> diverged;  // null: newton_divergence off
  int max_its = 0;
  // Once per layout (set_problem): NOX's model of the step, the Jacobian
  // it solves with, and vectors on the layout's rows (a Thyra vector space
  // on the assembly's Tpetra map).
  Teuchos::RCP<StepModel> model;
  Teuchos::RCP<NOX::Thyra::Vector> guess;
  Teuchos::RCP<NOX::Thyra::Group> group;
  Teuchos::RCP<NOX::Solver::Generic> solver;
};

Solver::~Solver() = default;

Solver::Solver(MPI_Comm comm, const sp_solver_options &options)
    : comm_(comm), options_(options) {
  check_mpi(MPI_Comm_rank(comm, &rank_), "MPI_Comm_rank");
  check_mpi(MPI_Comm_size(comm, &n_ranks_), "MPI_Comm_size");
  if (options.jacobian < SP_SOLVER_JAC_AD || options.jacobian > SP_SOLVER_JAC_FD)
    throw input_error("solver.jacobian: unknown kind");
  if (!(options.jacobian_reuse >= 0 && options.jacobian_reuse < 1))
    throw input_error("solver.jacobian_reuse: expected 0 <= value < 1");
  if (!(options.jacobian_carry >= 0 && options.jacobian_carry < 1))
    throw input_error("solver.jacobian_carry: expected 0 <= value < 1");
  if (options.ordering != SP_SOLVER_ORDER_PAIRS && options.ordering != SP_SOLVER_ORDER_UNKNOWNS)
    throw input_error("solver.ordering: unknown kind");
  if (options.line_search != SP_SOLVER_STEP_FULL && options.line_search != SP_SOLVER_STEP_BACKTRACK)
    throw input_error("solver.line_search: unknown kind");
  if (!(options.newton_divergence == 0 || options.newton_divergence > 1))
    throw input_error("solver.newton_divergence: expected 0 (off) or a value > 1");
  std::unique_ptr<LinearSolver> direct = make_linear_solver(comm, options);
  linear_ = std::make_unique<LowRankSolver>(comm, std::move(direct));

  nox_ = std::make_unique<Nox>();
  auto params = Teuchos::rcp(new Teuchos::ParameterList);
  params->set("Nonlinear Solver", "Line Search Based");
  // Backtrack: NOX's defaults (halve the step until the sum of squares of
  // F falls, down to 1e-12, else the full step), spelled out.
  Teuchos::ParameterList &search = params->sublist("Line Search");
  if (options_.line_search == SP_SOLVER_STEP_BACKTRACK) {
    search.set("Method", "Backtrack");
    search.sublist("Backtrack").set("Default Step", 1.0);
    search.sublist("Backtrack").set("Reduction Factor", 0.5);
    search.sublist("Backtrack").set("Minimum Step", 1e-12);
    search.sublist("Backtrack").set("Max Iters", 100);
  } else {
    search.set("Method", "Full Step");
  }
  params->sublist("Direction").set("Method", "Newton");
  params->sublist("Direction").sublist("Newton").set("Rescue Bad Newton Solve", false);
  params->sublist("Printing").set("Output Information", 0);
  // NOX prints its errors before throwing: keep them for the message.
  nox_->errors = Teuchos::rcp(new std::ostringstream);
  params->sublist("Printing").set<Teuchos::RCP<std::ostream>>("Error Stream", nox_->errors);
  params->sublist("Solver Options").set("Status Test Check Type", "Complete");
  params->sublist("Solver Options").set<Teuchos::RCP<NOX::Observer>>(
      "User Defined Pre/Post Operator", Teuchos::rcp(new ResidualRecorder(*this)));
  nox_->params = params;

  // Converged: (||F|| < newton_atol, or < newton_rtol ||F(guess)||, or the
  // update below the step's update tolerances) after at least one update.
  // Failed: F not finite, the iteration limits, ||F|| > 1e30, or (with
  // newton_divergence) ||F|| above that factor of ||F(guess)||.
  using namespace NOX::StatusTest;
  auto converged = Teuchos::rcp(new Combo(Combo::AND));
  auto tolerance = Teuchos::rcp(new Combo(Combo::OR));
  tolerance->addStatusTest(Teuchos::rcp(new NormF(options_.newton_atol, NormF::Unscaled)));
  nox_->relative = Teuchos::rcp(new NormF(0.0, NormF::Unscaled));
  tolerance->addStatusTest(nox_->relative);
  nox_->update = Teuchos::rcp(new UpdateSmall(comm_));
  tolerance->addStatusTest(nox_->update);
  converged->addStatusTest(tolerance);
  converged->addStatusTest(Teuchos::rcp(new AtLeastOneIteration));
  auto all = Teuchos::rcp(new Combo(Combo::OR));
  all->addStatusTest(Teuchos::rcp(new InterruptTest(*this)));
  all->addStatusTest(Teuchos::rcp(new FiniteValue));
  all->addStatusTest(converged);
  // Newton: newton_max_its iterations; modified Newton: as many
  // factorisations, and at most twice as many iterations.
  nox_->max_its = options_.jacobian_reuse > 0 ? 2 * options_.newton_max_its
                                              : options_.newton_max_its;
  if (options_.jacobian_reuse > 0)
    all->addStatusTest(Teuchos::rcp(new FactorisationLimit(*this, options_.newton_max_its)));
  all->addStatusTest(Teuchos::rcp(new MaxIters(nox_->max_its)));
  all->addStatusTest(Teuchos::rcp(new Divergence(1e30)));
  if (options_.newton_divergence > 0) {
    nox_->diverged = Teuchos::rcp(new RelativeDivergence(*this, options_.newton_divergence));
    all->addStatusTest(nox_->diverged);
  }
  nox_->tests = all;
}

void Solver::build_nox_solve() {
  Nox &n = *nox_;
  n.solver = Teuchos::null;  // (it holds the old group)
  const auto space = Thyra::createVectorSpace<double>(assembly_->map());
  n.model = Teuchos::rcp(new StepModel(*this, space));
  auto jacobian = Teuchos::rcp(new JacobianSolve(*this, space));
  n.guess = Teuchos::rcp(new NOX::Thyra::Vector(Thyra::createMember(space)));
  // (NOX's constructor for a given linear operator and solver factory; no
  // preconditioner; the casts pick it among the overloads)
  const Teuchos::RCP<Thyra::LinearOpBase<double>> op = jacobian;
  const Teuchos::RCP<const Thyra::LinearOpWithSolveFactoryBase<double>> factory =
      Teuchos::rcp(new JacobianSolveFactory(jacobian));
  n.group = Teuchos::rcp(new NOX::Thyra::Group(
      *n.guess, n.model, op, factory, Teuchos::RCP<Thyra::PreconditionerBase<double>>(),
      Teuchos::RCP<Thyra::PreconditionerFactoryBase<double>>()));
  // (evaluates nothing: F is first computed in step)
  n.solver = NOX::Solver::buildSolver(n.group, n.tests, n.params);
}

void Solver::set_linear(int linear, double krylov_tol) {
  sp_solver_options options = options_;
  options.linear = linear;
  options.krylov_tol = krylov_tol;
  std::unique_ptr<LinearSolver> direct = make_linear_solver(comm_, options);
  linear_ = std::make_unique<LowRankSolver>(comm_, std::move(direct));
  options_ = options;
  assembly_.reset();  // the next set_problem builds all for the new solver
}

void Solver::set_problem(const sp_mesh_view &mesh, const sp_layout_view &layout) {
  if (assembly_ && assembly_->same_layout(layout)) return;
  assembly_.reset(new Assembly(comm_, mesh, layout));
  // The CSR rows handed to the direct solver: this rank's rows, global
  // column indices. The backends need each rank's rows contiguous and the
  // blocks in rank order (the node partition of Assembly gives that).
  const TpetraGraph &g = *assembly_->graph();
  const std::vector<GlobalId> &rows = assembly_->my_rows();
  const int n = (int)rows.size();
  agree_local(comm_, [&] {  // (the gathers below are collective)
    jacobian_matrix_ = Teuchos::rcp(new TpetraMatrix(assembly_->graph()));
    jacobian_matrix_->fillComplete(assembly_->map(), assembly_->map());
    apply_in_ = Teuchos::rcp(new TpetraVector(assembly_->map()));
    apply_out_ = Teuchos::rcp(new TpetraVector(assembly_->map()));
    build_nox_solve();
    first_row_ = n > 0 ? (int)rows[0] : 0;
    for (int i = 0; i < n; ++i)
      if (rows[i] != first_row_ + i) throw std::logic_error("the rows of a rank are not contiguous");
  });
  const int P = n_ranks_;
  std::vector<int> firsts(P), counts(P);
  MPI_Allgather(&first_row_, 1, MPI_INT, firsts.data(), 1, MPI_INT, comm_);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (int r = 0, next = 0; r < P; next += counts[r], ++r)
    if (counts[r] > 0 && firsts[r] != next)
      throw std::logic_error("the row blocks of the ranks are not in rank order");
  first_row_ = 0;  // (also right for a rank without rows)
  for (int r = 0; r < rank_; ++r) first_row_ += counts[r];
  n_global_ = (int)g.getGlobalNumRows();
  if (linear_->uses_blocks()) {  // the cell of every row, for the solvers on the cells' blocks
    std::vector<int> cell_of_row((size_t)n_global_);
    for (int p = 0; p < n_global_ / 2; ++p)
      cell_of_row[2 * (size_t)p] = cell_of_row[2 * (size_t)p + 1] = assembly_->pair_cell(p);
    linear_->set_blocks(cell_of_row.data(), n_global_);
  }
  // On one process the column map is the row map (Assembly) and each row
  // is sorted by local column, so the local arrays are the sorted rows
  // already: a backend that only reads them reads the Jacobian's own
  // columns and values (its row offsets are size_t: an int copy is kept).
  const auto local = g.getLocalGraphHost();
  const auto &cols = *g.getColMap();
  rows_in_place_ = P == 1 && !linear_->overwrites_values() &&
                   (int)cols.getNodeNumElements() == n_global_;
  for (int k = 0; rows_in_place_ && k < n_global_; ++k)
    rows_in_place_ = cols.getGlobalElement(k) == k;
  // Else columns sorted by global index within each row: the same arrays
  // for any number of ranks (a row is ordered by local column index, which
  // depends on the partition, and orderings break ties by entry order).
  // csr_from_[k]: the position in the Tpetra row of sorted entry k.
  std::vector<int>().swap(csr_ptr_);
  std::vector<int>().swap(csr_col_);
  std::vector<int>().swap(csr_from_);
  std::vector<double>().swap(csr_val_);
  csr_ptr_.assign(1, 0);
  std::vector<std::pair<int, int>> row;
  for (int i = 0; i < n; ++i) {
    const size_t begin = local.row_map(i), end = local.row_map(i + 1);
    if (rows_in_place_) {
      for (size_t k = begin + 1; k < end; ++k)
        if (local.entries(k - 1) >= local.entries(k)) throw std::logic_error("a row is not sorted");
      csr_ptr_.push_back((int)end);
      continue;
    }
    row.resize(end - begin);
    for (size_t k = begin; k < end; ++k)
      row[k - begin] = {(int)cols.getGlobalElement(local.entries(k)), (int)(k - begin)};
    std::sort(row.begin(), row.end());
    for (const auto &e : row) {
      csr_col_.push_back(e.first);
      csr_from_.push_back(e.second);
    }
    csr_ptr_.push_back((int)csr_col_.size());
  }
  csr_val_.assign(csr_col_.size(), 0.0);
  pattern_changed_ = true;
  jacobian_fresh_ = false;
  const double matrix = matrix_bytes(*jacobian_matrix_) + assembly_->ghost_matrix_bytes() +
                        bytes_of(csr_ptr_) + bytes_of(csr_col_) + bytes_of(csr_from_) +
                        bytes_of(csr_val_);
  usage_.matrix_bytes = std::max(usage_.matrix_bytes, matrix);
  usage_.mesh_bytes = std::max(usage_.mesh_bytes, assembly_->table_bytes());
  usage_.state_bytes = std::max(usage_.state_bytes, 8.0 * assembly_->n_dofs());
}

void Solver::require_problem() const {
  if (!assembly_) throw std::runtime_error("sp_solver_set_problem was not called");
}

void Solver::gather(const double *x, std::vector<double> &full) const {
  // Each rank owns a contiguous DOF range in rank order: an allgather.
  const int P = n_ranks_;
  std::vector<int> counts(P), displs(P, 0);
  int mine = (int)assembly_->my_rows().size();
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (int r = 1; r < P; ++r) displs[r] = displs[r - 1] + counts[r - 1];
  full.resize(assembly_->n_dofs());
  usage_.sent_bytes += 8.0 * mine * (P - 1);  // its rows to every other rank
  MPI_Allgatherv(x, mine, MPI_DOUBLE, full.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 comm_);
}

void Solver::scatter(const double *x, double *mine) const {
  const std::vector<GlobalId> &rows = assembly_->my_rows();
  for (size_t i = 0; i < rows.size(); ++i) mine[i] = x[rows[i]];
}

namespace {

// The local array of a Tpetra vector to or from a plain one (this rank's rows).
void copy_from(const TpetraVector &v, double *out) {
  const auto view = v.getLocalViewHost(Tpetra::Access::ReadOnly);
  for (size_t i = 0; i < view.extent(0); ++i) out[i] = view(i, 0);
}
void copy_into(const double *in, TpetraVector &v) {
  const auto view = v.getLocalViewHost(Tpetra::Access::OverwriteAll);
  for (size_t i = 0; i < view.extent(0); ++i) view(i, 0) = in[i];
}

}  // namespace

void Solver::fill_residual(const sp_step_data &d, const double *x, TpetraVector &F) {
  double t0 = now();
  gather(x, full_);
  assembly_->residual(shape_.data_at(d, *assembly_, full_.data()), full_.data(), F);
  usage_.sent_bytes += assembly_->residual_export_bytes();
  t_assembly_ += now() - t0;
}

void Solver::fill_jacobian(const sp_step_data &d, const double *x) {
  double t0 = now();
  gather(x, full_);
  // The element Jacobians take the shape coefficients as constants; their
  // dependence on the moments is the low-rank part (prepare_shape).
  assembly_->jacobian(shape_.data_at(d, *assembly_, full_.data()), full_.data(),
                      options_.jacobian, *jacobian_matrix_);
  usage_.sent_bytes += assembly_->jacobian_export_bytes();
  linear_->set_scales(d.dt * d.model.mobility, d.model.kappa);
  jacobian_fresh_ = true;
  if (carries()) {
    jac_x_ = full_;
    jac_dt_ = d.dt;
    jac_shape_implicit_ = d.shape_implicit;
    if (d.shape) jac_shape_.assign(d.shape, d.shape + assembly_->n_cells());
    else jac_shape_.clear();
  }
  t_assembly_ += now() - t0;
}

void Solver::prepare_shape(const sp_step_data &d) {
  shape_.prepare(d, *assembly_);
  linear_->set_term(shape_.jacobian_term(*assembly_));
}

bool Solver::apply_jacobian(const double *in, double *out, bool transpose) {
  copy_into(in, *apply_in_);
  jacobian_matrix_->apply(*apply_in_, *apply_out_, transpose ? Teuchos::TRANS : Teuchos::NO_TRANS);
  copy_from(*apply_out_, out);
  linear_->term().add_apply(comm_, in, out, transpose);
  return true;
}

void Solver::jacobian_times(const sp_step_data &d, const double *state, bool transpose,
                            const double *x, double *y) {
  require_problem();
  const size_t n = assembly_->my_rows().size();
  std::vector<double> at(n), in(n), out(n);
  scatter(state, at.data());
  scatter(x, in.data());
  prepare_shape(d);
  fill_jacobian(d, at.data());
  apply_jacobian(in.data(), out.data(), transpose);
  std::vector<double> full;
  gather(out.data(), full);
  std::copy(full.begin(), full.end(), y);
}

bool Solver::carry_point(double &dt, const std::vector<double> *&x,
                         const std::vector<sp_shape_coef> *&shape, int &shape_implicit) const {
  if (rewound_) {  // what it was at carry_mark
    dt = mark_.dt;
    x = &mark_.x;
    shape = &mark_.shape;
    shape_implicit = mark_.shape_implicit;
    return mark_.carryable;
  }
  dt = jac_dt_;
  x = &jac_x_;
  shape = &jac_shape_;
  shape_implicit = jac_shape_implicit_;
  return factor_carryable() && !jac_x_.empty();
}

void Solver::carry_mark() {
  const std::vector<double> *x;
  const std::vector<sp_shape_coef> *shape;
  double dt;
  int shape_implicit;
  const bool carryable = carry_point(dt, x, shape, shape_implicit);
  if (&mark_.x != x) mark_.x = *x;  // (a second mark after a rewind keeps it)
  if (&mark_.shape != shape) mark_.shape = *shape;
  mark_.carryable = carryable;
  mark_.dt = dt;
  mark_.shape_implicit = shape_implicit;
}

void Solver::carry_rewind() { rewound_ = true; }

bool Solver::interrupt_requested() {
  if (!interrupted_ && interrupt_) interrupted_ = interrupt_(interrupt_ctx_) != 0;
  return interrupted_;
}

void Solver::carry_restore(const sp_step_data &d, const double *x) {
  require_problem();
  if (!carries()) return;  // (a continued run with the carry switched off: nothing to carry)
  std::vector<double> mine(assembly_->my_rows().size());
  scatter(x, mine.data());
  prepare_shape(d);
  fill_jacobian(d, mine.data());
  std::string why;
  if (!factor_jacobian(why))  // (agreed inside)
    throw std::runtime_error("rebuilding the carried factorisation: " + why);
  step_factorisations_ = 0;
  last_converged_ = true;
}

bool Solver::may_reuse_jacobian() const {
  const size_t n = step_norms_.size();
  if (options_.jacobian_reuse <= 0 || jacobian_fresh_ || pattern_changed_) return false;
  // The step's first iteration: on the last step's factorisation if carried.
  if (step_factorisations_ == 0 && n == 1) return carried_;
  // Later ones keep the factorisation while the last iteration cut ||F|| by
  // jacobian_reuse (by jacobian_carry while it is still the carried one).
  // The norms are global, so every rank decides alike.
  const double theta = step_factorisations_ == 0 ? options_.jacobian_carry
                                                 : options_.jacobian_reuse;
  return (step_factorisations_ > 0 || carried_) && n >= 2 &&
         step_norms_[n - 1] <= theta * step_norms_[n - 2];
}

bool Solver::factor_jacobian(std::string &why) {
  double t0 = now();
  const int n = (int)assembly_->my_rows().size();
  CsrRows A;
  A.n_global = n_global_;
  A.first_row = first_row_;
  A.n_rows = n;
  const auto local = jacobian_matrix_->getLocalMatrixHost();
  if (rows_in_place_) {
    A.row_ptr = csr_ptr_.data();
    A.col = local.graph.entries.data();
    A.val = local.values.data();
  } else {
    const double *vals = local.values.data();
    for (int i = 0; i < n; ++i) {
      const double *row = vals + local.graph.row_map(i);
      for (int k = csr_ptr_[i]; k < csr_ptr_[i + 1]; ++k) csr_val_[k] = row[csr_from_[k]];
    }
    A.row_ptr = csr_ptr_.data();
    A.col = csr_col_.data();
    A.val = csr_val_.data();
  }
  linear_->set_rhs_count(1);
  bool ok = linear_->factor(A, !pattern_changed_, why);
  int oom = !ok && linear_->out_of_memory();
  if (ok && sp_fault_due(SP_FAULT_FACTOR, rank_)) {  // (src/base/fault.h)
    ok = false;
    oom = 1;
    why = "out of memory in the factorisation on rank " + std::to_string(rank_) +
          " (fault injected by SOFTPACK_FAULT=factor:" + std::to_string(rank_) + ")";
  }
  ok = all_agree(comm_, ok, why);
  // (ok is agreed now: the ranks reduce the memory flag only after a failure)
  if (!ok)
    check_mpi(MPI_Allreduce(MPI_IN_PLACE, &oom, 1, MPI_INT, MPI_MAX, comm_), "MPI_Allreduce");
  linear_out_of_memory_ = !ok && oom;
  t_factor_ += now() - t0;
  if (!ok) {
    pattern_changed_ = true;  // start the next factorisation from scratch
    return false;
  }
  pattern_changed_ = false;
  jacobian_fresh_ = false;
  ++step_factorisations_;
  return true;
}

bool Solver::solve_linear(const double *b, double *x) {
  std::string why;
  const bool fresh = jacobian_fresh_;
  if (fresh && !factor_jacobian(why)) {
    linear_failure_ = why;
    return false;
  }
  // (the first solve after a factorisation also does the low-rank term's
  // block solve and small factorisation: counted as solve time)
  double t0 = now();
  bool ok = linear_->solve(b, x, why);
  t_solve_ += now() - t0;
  if (!ok && fresh) jacobian_fresh_ = true;  // refactor before the next solve
  if (!ok) linear_failure_ = why;
  return ok;
}

int Solver::step(const sp_step_data &d, double *state, sp_step_report &report) {
  require_problem();
  if (!(d.update_rtol >= 0 && d.update_atol >= 0) ||
      (d.update_rtol > 0 && !(d.update_atol > 0)))
    throw input_error("sp_step_data: expected update_atol > 0 with update_rtol > 0, both >= 0");
  report = sp_step_report{};
  t_assembly_ = t_factor_ = t_solve_ = 0;
  step_factorisations_ = 0;
  step_norms_.clear();
  linear_failure_.clear();
  linear_out_of_memory_ = false;
  const double t_start = now();
  const long linear_its_before = linear_->iterations();
  Nox &n = *nox_;
  const StepModel::Scope scope(*n.model, d);
  scatter(state, local(*n.guess));

  prepare_shape(d);
  // Carry the last step's factorisation: same layout, the last step
  // converged, no low-rank term (its Woodbury factors belong to the last
  // step's shape coefficients); the first iteration's contraction decides.
  carried_ = factor_carryable() && linear_->term().empty();
  last_converged_ = false;
  rewound_ = false;
  interrupt_ = d.interrupt;
  interrupt_ctx_ = d.interrupt_ctx;
  interrupted_ = false;
  // The guess into the group (every value it held is now invalid), F at the
  // guess, and the step's tolerances into the tests. F(guess) is evaluated
  // here once, as NOX's relative NormF did when it was built per step; the
  // fill is not a Newton iteration's work but is counted in assembly.
  n.solver->reset(*n.guess);
  n.group->computeF();
  n.relative->reset(options_.newton_rtol * n.group->getNormF());
  n.update->set_tolerances(d.update_rtol, d.update_atol);
  n.errors->str("");
  n.errors->clear();

  // A failed linear solve (applyJacobianInverse false, linear_failure_ set):
  // NOX's Newton direction throws; the attempt failed, as a diverging one.
  // Any other NOX error ends the run with what NOX printed.
  using NOX::StatusTest::Converged;
  using NOX::StatusTest::Failed;
  NOX::StatusTest::StatusType status = Failed;
  try {
    status = n.solver->solve();
  } catch (...) {
    if (linear_failure_.empty()) {
      std::string text = n.errors->str();
      while (!text.empty() && std::isspace((unsigned char)text.back())) text.pop_back();
      if (text.empty()) throw;
      throw std::runtime_error("NOX: " + text);
    }
  }
  report.newton_its = n.solver->getNumIterations();
  usage_.newton_its += report.newton_its;
  report.factorisations = step_factorisations_;
  report.linear_its = linear_->iterations() - linear_its_before;
  report.n_residuals = (int)std::min<size_t>(step_norms_.size(), SP_MAX_NEWTON_HISTORY);
  std::copy(step_norms_.begin(), step_norms_.begin() + report.n_residuals, report.residual_norms);
  report.t_assembly = t_assembly_;
  report.t_factor = t_factor_;
  report.t_solve = t_solve_;
  if (status == Converged) {
    gather(local(n.solver->getSolutionGroup().getX()), full_);
    std::copy(full_.begin(), full_.end(), state);
    report.converged = 1;
    last_converged_ = true;
    report.t_total = now() - t_start;
    return 0;
  }
  const double last = report.n_residuals ? report.residual_norms[report.n_residuals - 1] : NAN;
  char ratio[32];
  snprintf(ratio, sizeof ratio, "%g", options_.newton_divergence);
  // (the divergence test's status is this solve's: every test is checked at
  // the guess and after each iteration)
  report.failure = interrupted_ ? SP_NEWTON_INTERRUPTED
                   : !linear_failure_.empty()
                       ? (linear_out_of_memory_ ? SP_NEWTON_OUT_OF_MEMORY : SP_NEWTON_LINEAR_FAILED)
                   : !std::isfinite(last) ? SP_NEWTON_NOT_FINITE
                   : !n.diverged.is_null() && n.diverged->getStatus() == Failed
                       ? SP_NEWTON_DIVERGED
                   : report.newton_its >= n.max_its ||
                             report.factorisations >= options_.newton_max_its
                       ? SP_NEWTON_MAX_ITERATIONS
                       : SP_NEWTON_OTHER_FAILURE;
  const std::string counts = std::to_string(report.newton_its) + " Newton iterations (" +
                             std::to_string(report.factorisations) + " factorisations)";
  std::string why;
  switch (report.failure) {
    case SP_NEWTON_LINEAR_FAILED:
    case SP_NEWTON_OUT_OF_MEMORY: why = linear_failure_; break;
    case SP_NEWTON_NOT_FINITE: why = "the residual is not finite"; break;
    case SP_NEWTON_DIVERGED:
      why = "diverged: |F| above " + std::string(ratio) + " x the first |F| after " + counts;
      break;
    case SP_NEWTON_MAX_ITERATIONS: why = "no convergence in " + counts; break;
    case SP_NEWTON_INTERRUPTED: why = "a stop was requested during the step"; break;
    default: why = "Newton failed";
  }
  snprintf(report.reason, sizeof report.reason, "%s (last |F| = %.3g)", why.c_str(), last);
  report.t_total = now() - t_start;
  return 1;  // state untouched: the guess was a copy
}

sp_energy_parts Solver::energy(const sp_model_params &m, const double *state) const {
  require_problem();
  return assembly_->energy(m, state);
}

void Solver::residual(const sp_step_data &d, const double *state, double *out) {
  require_problem();
  TpetraVector F(assembly_->map());
  shape_.prepare(d, *assembly_);
  assembly_->residual(shape_.data_at(d, *assembly_, state), state, F);
  std::vector<double> mine(assembly_->my_rows().size()), full;
  copy_from(F, mine.data());
  gather(mine.data(), full);
  std::copy(full.begin(), full.end(), out);
}

double Solver::check_jacobian(const sp_step_data &d, const double *state, int kind) const {
  require_problem();
  return assembly_->check_jacobian(d, state, kind);
}

double Solver::compare_jacobians(const sp_step_data &d, const double *state, int kind_a,
                                 int kind_b) const {
  require_problem();
  return assembly_->compare_jacobians(d, state, kind_a, kind_b);
}

double Solver::time_jacobian(const sp_step_data &d, const double *state, int kind,
                             int repeats, double *elements) const {
  require_problem();
  if (repeats < 1) throw std::invalid_argument("time_jacobian: repeats must be >= 1");
  TpetraMatrix J(assembly_->graph());
  J.fillComplete(assembly_->map(), assembly_->map());
  double t0 = now();
  for (int r = 0; r < repeats; ++r) assembly_->jacobian(d, state, kind, J);
  const double fill = (now() - t0) / repeats;
  if (elements) {
    t0 = now();
    for (int r = 0; r < repeats; ++r) assembly_->element_pass(d, state, kind);
    *elements = (now() - t0) / repeats;
  }
  return fill;
}

}  // namespace sp
