// The object behind the sp_solver handle: an Assembly for the current
// layout, the Jacobian (a sparse matrix and, with the implicit shape term,
// a low-rank part beside it), a linear solver for it, and NOX's Newton
// solve of each time step's equations. What NOX needs is built ahead of the
// steps (newton.cpp, Solver::Nox): the parameter list and the status tests
// once per solver, the group (NOX::Thyra::Group over a Thyra model of the
// step on Tpetra vectors) and the NOX solver once per layout; a step only
// loads its guess and its tolerances into them.
#ifndef SP_NEWTON_HPP
#define SP_NEWTON_HPP

#include <mpi.h>
#include <Teuchos_RCP.hpp>

#include <memory>
#include <string>
#include <vector>

#include "assembly/assembly.hpp"
#include "linear/linear.hpp"
#include "linear/linear_low_rank.hpp"
#include "assembly/shape_implicit.hpp"
#include "softpack_solver.h"

namespace sp {

class Solver {
 public:
  Solver(MPI_Comm comm, const sp_solver_options &options);
  ~Solver();  // (out of line: Nox is complete only in newton.cpp)
  Solver(const Solver &) = delete;
  Solver &operator=(const Solver &) = delete;

  void set_problem(const sp_mesh_view &mesh, const sp_layout_view &layout);
  // Another linear solver from the next set_problem on (which rebuilds).
  void set_linear(int linear, double krylov_tol);
  // What this rank holds and has sent (sp_solver_usage).
  sp_solver_usage usage() const { return usage_; }
  /// Whether the next step may begin on the current factorisation
  /// (jacobian_carry), and the point its Jacobian was filled at: dt, the
  /// full state, the step's shape coefficients (for a checkpoint).
  bool carry_point(double &dt, const std::vector<double> *&x,
                   const std::vector<sp_shape_coef> *&shape, int &shape_implicit) const;
  /// Fill the Jacobian at x with d and factor it: the next step may begin
  /// on it, as in the run whose carry_point this is.
  void carry_restore(const sp_step_data &d, const double *x);
  /// Remember the carry point carry_point reports now; carry_rewind reports
  /// it again (a step given up half-way) and makes the next step begin with
  /// a new Jacobian (the factorisation is the given-up attempt's).
  void carry_mark();
  void carry_rewind();
  /// Whether sp_step_data.interrupt asks the current solve to stop (polled
  /// by the Newton status tests, newton.cpp's InterruptTest).
  bool interrupt_requested();
  int ranks() const { return n_ranks_; }
  // Returns 0 when converged, 1 when Newton failed (state untouched).
  int step(const sp_step_data &data, double *state, sp_step_report &report);
  sp_energy_parts energy(const sp_model_params &m, const double *state) const;
  // (not const: an implicit shape term needs its weights for data)
  void residual(const sp_step_data &data, const double *state, double *residual);
  double check_jacobian(const sp_step_data &data, const double *state, int kind) const;
  double compare_jacobians(const sp_step_data &data, const double *state, int kind_a,
                           int kind_b) const;
  // Mean seconds of one Jacobian fill into a scratch matrix, and (if
  // elements is not null) of the element matrices alone.
  double time_jacobian(const sp_step_data &data, const double *state, int kind,
                       int repeats, double *elements) const;

  // Called by NOX's model of the step and its Jacobian solve (newton.cpp),
  // on this rank's rows (Assembly::my_rows(), in that order): the local
  // arrays of NOX's vectors (Thyra vectors on Tpetra ones); F is NOX's
  // residual vector's Tpetra vector, assembled into directly.
  void fill_residual(const sp_step_data &data, const double *x, TpetraVector &F);
  void fill_jacobian(const sp_step_data &data, const double *x);
  // Solves J x = b (factoring J first if it changed); false: the reason is
  // kept for the step's report (a failed linear solve fails the attempt).
  bool solve_linear(const double *b, double *x);
  // out = J in (or J^T in), J the sparse matrix plus the implicit shape
  // term's low-rank part.
  bool apply_jacobian(const double *in, double *out, bool transpose);
  // The Jacobian of the step equations at state applied to x (or its
  // transpose): a test hook (sp_solver_apply_jacobian); full vectors.
  void jacobian_times(const sp_step_data &data, const double *state, bool transpose,
                      const double *x, double *y);
  // ||F|| after each iteration of the current step (and at its guess).
  void note_residual(double norm) { step_norms_.push_back(norm); }
  // Modified Newton (sp_solver_options.jacobian_reuse): whether the next
  // iteration may keep the factorisation of this step's last Jacobian.
  bool may_reuse_jacobian() const;
  int step_factorisations() const { return step_factorisations_; }
  // ||F|| at the current step's guess (NaN before it is recorded).
  double step_first_norm() const { return step_norms_.empty() ? NAN : step_norms_.front(); }

 private:
  // NOX's side of the solve (newton.cpp): the parameter list and the status
  // tests, built by the constructor; the group (the Newton iterate and its
  // F, J, update) and the NOX solver over it, built by set_problem for each
  // layout.
  struct Nox;
  // Builds NOX's group and solver on the current layout's map.
  void build_nox_solve();
  void require_problem() const;
  // A step's implicit shape term: its coefficients (shape_) and its
  // Jacobian part, handed to the linear solver.
  void prepare_shape(const sp_step_data &data);
  // The full (replicated) state from this rank's rows of a vector.
  void gather(const double *mine, std::vector<double> &full) const;
  // This rank's rows of the full vector x.
  void scatter(const double *x, double *mine) const;

  // The sparse part of J (declared first, so destroyed last), and vectors
  // on its rows: Apply's input and output.
  Teuchos::RCP<TpetraMatrix> jacobian_matrix_;
  Teuchos::RCP<TpetraVector> apply_in_, apply_out_;
  // Why the current step's last linear solve failed (empty: none did).
  std::string linear_failure_;
  bool linear_out_of_memory_ = false;  // the last factorisation failed for memory
  // Seconds of the current step: residual and Jacobian fills,
  // factorisations, solves (sp_step_report).
  double t_assembly_ = 0, t_factor_ = 0, t_solve_ = 0;
  MPI_Comm comm_;
  int rank_ = 0, n_ranks_ = 1;
  sp_solver_options options_;
  // Bytes held (largest so far) and sent (mutable: the const gathers send).
  mutable sp_solver_usage usage_{};
  std::unique_ptr<Assembly> assembly_;
  // The backend of solver.linear inside the low-rank (Woodbury) wrapper.
  std::unique_ptr<LowRankSolver> linear_;
  std::unique_ptr<Nox> nox_;
  std::vector<int> csr_ptr_, csr_col_;  // this rank's rows: pattern, global columns (sorted)
  std::vector<int> csr_from_;           // position of each entry in its Tpetra row
  int first_row_ = 0, n_global_ = 0;    // the rows are first_row_ .. + n_rows - 1
  std::vector<double> csr_val_;
  // One process, a backend that only reads, and Tpetra's rows already in
  // the sorted order: the backend reads the Jacobian's own column and value
  // arrays (csr_ptr_ holds its row offsets as int) and no copy of the
  // values is kept (the values exist once, docs/design.md).
  bool rows_in_place_ = false;
  bool jacobian_fresh_ = false;  // the matrix changed since the last factor
  bool pattern_changed_ = true;  // the layout changed since the last factor
  int step_factorisations_ = 0;  // factorisations in the current step
  // Across steps (sp_solver_options.jacobian_carry): whether the last step
  // converged, and whether this one began on its factorisation.
  bool last_converged_ = false;
  bool carried_ = false;
  // Where the current Jacobian was filled (fill_jacobian): a checkpoint
  // saves it, so a continued run rebuilds the factorisation it carries.
  double jac_dt_ = 0;
  int jac_shape_implicit_ = 0;
  std::vector<double> jac_x_;
  std::vector<sp_shape_coef> jac_shape_;
  // carry_mark's copy of what carry_point reports; rewound_: the next step
  // may not begin on the factorisation (carry_rewind).
  struct CarryMark {
    bool carryable = false;
    double dt = 0;
    int shape_implicit = 0;
    std::vector<double> x;
    std::vector<sp_shape_coef> shape;
  } mark_;
  bool rewound_ = false;
  // The current step's interrupt poll (sp_step_data) and whether it fired.
  int (*interrupt_)(void *) = nullptr;
  void *interrupt_ctx_ = nullptr;
  bool interrupted_ = false;
  // Factor jacobian_matrix_ (solve_linear's first part); false: why says.
  bool factor_jacobian(std::string &why);
  // Factorisations may carry across steps (jacobian_carry, with modified
  // Newton), and the current one may: the last step converged on it, on
  // this layout, and no Jacobian was filled since.
  bool carries() const { return options_.jacobian_reuse > 0 && options_.jacobian_carry > 0; }
  bool factor_carryable() const {
    return carries() && last_converged_ && !pattern_changed_ && !jacobian_fresh_ && !rewound_;
  }
  std::vector<double> step_norms_;  // ||F|| at the guess and after each iteration
  std::vector<double> full_;     // scratch: the replicated state
  ImplicitShape shape_;          // the current step's implicit shape term
};

}  // namespace sp
#endif
