// GMRES (Belos) preconditioned by a Cahn-Hilliard block preconditioner
// whose only solves are algebraic multigrid V-cycles (MueLu): no
// factorisation, memory linear in the unknowns.
//
// Each cell's rows (c_k, mu_k) of the Jacobian are (residual.hpp)
//     [ M          b K ] [c ]      M: the mass matrix, K: the stiffness,
//     [ -(kK + W)  M   ] [mu]      b = dt x mobility, k = kappa,
// W the mass matrix weighted by w = f''(c_k) and the pair and buffer terms
// (up to 2 lambda where cells overlap). Eliminating mu leaves the Schur
// complement S = M + b K M^-1 (k K + W) on c. Bosch, Kay, Stoll and
// Wathen (2014) approximate its part M + b k K M^-1 K by
// (M + g K) M^-1 (M + g K), g = sqrt(b k); the same product with the
// second factor M + g K + (b / g) W equals S + 2 g K + (b / g) W, so it
// also carries the b K M^-1 W that dominates S where cells overlap. Here
//     S~ = P1 M^-1 P2,   P1 = M + g K,   P2 = P1 + (b / g) W+,
// W+ the lumped W where positive (w < 0 in the interfaces would make P2
// indefinite), both symmetric positive definite, each applied by one AMG
// V-cycle. The block-triangular preconditioner applied to (r_c, r_mu) is
//     t    = r_c - b K Ml^-1 r_mu
//     x_c  = P2^-1 Ml P1^-1 t              (two V-cycles)
//     x_mu = Ml^-1 (r_mu + (k K + W) x_c)
// with Ml the lumped mass matrix. Every matrix comes from the Jacobian's
// own entries: P1 = A_cc + A_cmu g / b (A_cc = M, A_cmu = b K), the cell's
// own mu -> c block A_muc = -(k K + W), whose row sums are -W's lumped
// (K's rows sum to zero); the entries coupling two cells (the pairs'
// d mu_k / d c_l) stay out of the preconditioner and enter through GMRES,
// as in gmres_cells. All cells' P blocks form one matrix with no entry
// between cells, so one MueLu hierarchy per factor serves them all and
// its aggregates never cross a cell; its rows are distributed as the
// Jacobian's (no gather).
//
// Each cell's mass: after GMRES, each cell's c rows of the linear residual
// b - A x sum to the mass the Newton update would lose (the c rows of A
// sum, over a cell, to 1^T M dc: K's rows sum to zero). The solve adds to
// each cell's c the constant that makes that sum zero (A's c-c block
// summed over the cell is 1^T M 1 > 0), and to its mu -Ml^-1 A_muc times
// that constant so that the mu rows stay as the solve left them; each
// cell's mass is conserved to round-off at any GMRES tolerance.
//
// The two MueLu hierarchies are built at the first factorisation of a
// pattern and afterwards only refreshed on the new values, keeping their
// aggregates and tentative prolongators (MueLu's "reuse: type" tP).
#include <MueLu_CreateTpetraPreconditioner.hpp>
#include <Teuchos_DefaultMpiComm.hpp>
#include <Tpetra_Operator.hpp>
#include <Tpetra_Vector.hpp>
#include <Trilinos_version.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>
#include <utility>
#include <vector>

#include "base/memory.hpp"
#include "linear/gmres.hpp"
#include "linear/linear.hpp"
#include "linear/tpetra_rows.hpp"

namespace sp {
namespace {

using GO = TpetraRows::GO;
using MV = TpetraRows::MV;
using Vec = Tpetra::Vector<double, int, GO>;
using OP = Tpetra::Operator<double, int, GO>;
using Map = TpetraRows::Map;
using Node = TpetraRows::Matrix::node_type;
using MueLuOp = MueLu::TpetraOperator<double, int, GO, Node>;

// A matrix on the pairs' rows (row p: the pair p = row 2p / 2 of A) whose
// entries are sums of A's entries with weights: entry k of row p is
// sum over its terms t of weight(t) A.val[from(t)].
struct PairMatrix {
  std::vector<int> ptr{0}, col, term_ptr{0}, from, weight_of;  // weight_of: 0 or 1
  std::vector<double> val;
  std::unique_ptr<TpetraRows> rows;
  void clear() {
    ptr.assign(1, 0);
    col.clear();
    term_ptr.assign(1, 0);
    from.clear();
    weight_of.clear();
    val.clear();
    rows.reset();
  }
  // Row by row: a new entry at pair column q, then its terms.
  void entry(int q) {
    col.push_back(q);
    term_ptr.push_back(term_ptr.back());
  }
  void term(int k, int w) {
    from.push_back(k);
    weight_of.push_back(w);
    ++term_ptr.back();
  }
  void end_row() { ptr.push_back((int)col.size()); }
  CsrRows csr(int n_global, int first, int n) {
    CsrRows R;
    R.n_global = n_global;
    R.first_row = first;
    R.n_rows = n;
    R.row_ptr = ptr.data();
    R.col = col.data();
    R.val = val.data();
    return R;
  }
  void set_values(const double *a, const double w[2], int n_global, int first, int n) {
    val.resize(col.size());
    for (size_t e = 0; e < col.size(); ++e) {
      double v = 0;
      for (int t = term_ptr[e]; t < term_ptr[e + 1]; ++t) v += w[weight_of[t]] * a[from[t]];
      val[e] = v;
    }
    rows->set_values(csr(n_global, first, n));
  }
};

// The block preconditioner (the file's header), on A's rows.
class BlockPreconditioner final : public OP {
 public:
  BlockPreconditioner(Teuchos::RCP<const Map> map, Teuchos::RCP<const Map> pairs)
      : map_(std::move(map)), pairs_(std::move(pairs)), xc_(pairs_), xm_(pairs_), t_(pairs_),
        u_(pairs_), yc_(pairs_), v_(pairs_) {}
  Teuchos::RCP<const Map> getDomainMap() const override { return map_; }
  Teuchos::RCP<const Map> getRangeMap() const override { return map_; }
  void set(const TpetraRows::Matrix *b, const TpetraRows::Matrix *c, MueLuOp *amg1,
           MueLuOp *amg2, const std::vector<double> *lumped) {
    b_ = b;
    c_ = c;
    amg_[0] = amg1;
    amg_[1] = amg2;
    lumped_ = lumped;
  }
  void apply(const MV &X, MV &Y, Teuchos::ETransp mode, double alpha,
             double beta) const override {
    if (mode != Teuchos::NO_TRANS) throw std::logic_error("CH blocks: transpose not supported");
    const size_t n = pairs_->getNodeNumElements();
    const std::vector<double> &ml = *lumped_;
    for (size_t j = 0; j < X.getNumVectors(); ++j) {
      {
        auto x = X.getLocalViewHost(Tpetra::Access::ReadOnly);
        auto xc = xc_.getLocalViewHost(Tpetra::Access::OverwriteAll);
        auto xm = xm_.getLocalViewHost(Tpetra::Access::OverwriteAll);
        auto t = t_.getLocalViewHost(Tpetra::Access::OverwriteAll);
        for (size_t i = 0; i < n; ++i) {
          xc(i, 0) = x(2 * i, j);
          xm(i, 0) = x(2 * i + 1, j);
          t(i, 0) = x(2 * i + 1, j) / ml[i];
        }
      }
      b_->apply(t_, u_);            // u = b K Ml^-1 r_mu
      t_.update(1.0, xc_, -1.0, u_, 0.0);  // t = r_c - u
      amg_[0]->apply(t_, u_);  // u = P1^-1 t
      {
        auto u = u_.getLocalViewHost(Tpetra::Access::ReadWrite);
        for (size_t i = 0; i < n; ++i) u(i, 0) *= ml[i];
      }
      amg_[1]->apply(u_, yc_);  // x_c = P2^-1 Ml P1^-1 t
      c_->apply(yc_, v_);           // v = A_muc x_c = -(k K + W) x_c
      auto yc = yc_.getLocalViewHost(Tpetra::Access::ReadOnly);
      auto xm = xm_.getLocalViewHost(Tpetra::Access::ReadOnly);
      auto v = v_.getLocalViewHost(Tpetra::Access::ReadOnly);
      auto y = Y.getLocalViewHost(Tpetra::Access::ReadWrite);
      for (size_t i = 0; i < n; ++i) {
        const double c = yc(i, 0), m = (xm(i, 0) - v(i, 0)) / ml[i];
        if (beta == 0) {
          y(2 * i, j) = alpha * c;
          y(2 * i + 1, j) = alpha * m;
        } else {
          y(2 * i, j) = alpha * c + beta * y(2 * i, j);
          y(2 * i + 1, j) = alpha * m + beta * y(2 * i + 1, j);
        }
      }
    }
  }

 private:
  Teuchos::RCP<const Map> map_, pairs_;
  const TpetraRows::Matrix *b_ = nullptr, *c_ = nullptr;
  MueLuOp *amg_[2] = {nullptr, nullptr};
  const std::vector<double> *lumped_ = nullptr;
  mutable Vec xc_, xm_, t_, u_, yc_, v_;
};

class AmgBlockSolver final : public LinearSolver {
 public:
  AmgBlockSolver(MPI_Comm comm, const KrylovOptions &o)
      : mpi_(comm), comm_(Teuchos::rcp(new Teuchos::MpiComm<int>(comm))), o_(o) {
    ensure_kokkos();
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &machine_);
  }
  ~AmgBlockSolver() override { MPI_Comm_free(&machine_); }
  bool out_of_memory() const override { return out_of_memory_; }

  bool uses_blocks() const override { return true; }
  void set_blocks(const int *block_of_row, int n_global) override {
    block_.assign(block_of_row, block_of_row + n_global);
    n_cells_ = 0;
    for (int b : block_) n_cells_ = std::max(n_cells_, b + 1);
    rows_.reset();
  }
  void set_scales(double dt_mobility, double kappa) override {
    b_scale_ = dt_mobility;
    g_ = std::sqrt(dt_mobility * kappa);
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    gmres_.set_factored(false);
    out_of_memory_ = false;
    if ((int)block_.size() != A.n_global) {
      why = "CH blocks: the rows' cells were not given (set_blocks)";
      return false;
    }
    if (!(g_ > 0 && b_scale_ > 0)) {
      why = "CH blocks: the step's dt and kappa were not given (set_scales)";
      return false;
    }
    try {
      bool new_pattern = false;
      if (!rows_ || !same_pattern || !rows_->same_pattern(A)) {
        rows_.reset();
        amg_ = amg2_ = Teuchos::null;
        if (does_not_fit(A, why)) return false;
        set_up(A);
        new_pattern = true;
      }
      rows_->set_values(A);
      const double w_p[2] = {1.0, g_ / b_scale_}, w_one[2] = {1.0, 1.0};
      const int np = A.n_global / 2, first = A.first_row / 2, n = A.n_rows / 2;
      p_.set_values(A.val, w_p, np, first, n);
      c_.set_values(A.val, w_one, np, first, n);
      // P2 = P1 + (b / g) W+ on the diagonal (W's lumped: -A_muc's row sums)
      p2_.val = p_.val;
      for (int i = 0; i < n; ++i) {
        double w = 0;
        for (int e = c_.ptr[i]; e < c_.ptr[i + 1]; ++e) w -= c_.val[e];
        if (w > 0) p2_.val[diagonal_[i]] += b_scale_ / g_ * w;
      }
      p2_.rows->set_values(p2_.csr(np, first, n));
      b_.set_values(A.val, w_one, np, first, n);
      // the lumped mass (the mu-mu block's row sums) and each cell's 1^T M 1
      std::fill(cell_mass_.begin(), cell_mass_.end(), 0.0);
      for (int i = 0; i < n; ++i) {
        double row = 0;
        for (int k : mm_[i]) row += A.val[k];
        lumped_[i] = row;
        double crow = 0;
        for (int k : cc_[i]) crow += A.val[k];
        cell_mass_[block_[A.first_row + 2 * i]] += crow;
        if (!(row > 0)) throw std::runtime_error("a lumped mass is not positive");
      }
      MPI_Allreduce(MPI_IN_PLACE, cell_mass_.data(), n_cells_, MPI_DOUBLE, MPI_SUM, mpi_);
      hierarchy(amg_, p_, new_pattern);
      hierarchy(amg2_, p2_, new_pattern);
      prec_->set(b_.rows->matrix().get(), c_.rows->matrix().get(), amg_.get(), amg2_.get(),
                 &lumped_);
    } catch (const std::bad_alloc &) {
      rows_.reset();
      amg_ = amg2_ = Teuchos::null;
      why = "GMRES with the CH block preconditioner: set-up failed: out of memory (an "
            "allocation refused)";
      out_of_memory_ = true;
      return false;
    } catch (const std::exception &e) {
      rows_.reset();
      amg_ = amg2_ = Teuchos::null;
      why = std::string("GMRES with the CH block preconditioner: set-up failed: ") + e.what();
      return false;
    }
    gmres_.set_factored(true);
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    if (!gmres_.solve(*rows_, b, x, why, iterations_)) return false;
    conserve_masses(x);
    return true;
  }

  long iterations() const override { return iterations_; }
  int symbolic_count() const override { return set_ups_; }

 private:
  // This rank's memory for a new pattern of A, in MB, before any of it is
  // allocated: the GMRES basis (restart + 1 vectors and a few more), the
  // Tpetra copy of A, the four pair matrices (host arrays and Tpetra
  // copies) and the two MueLu hierarchies. Bytes per entry and the
  // hierarchies' factor are this file's storage and MueLu's smoothed
  // aggregation on these blocks as measured against the resident memory
  // (docs/solvers.md, "Memory checked before it is spent").
  double estimate_mb(const CsrRows &A) const {
    const double n = A.n_rows, nnz = A.row_ptr[A.n_rows];
    double pair_entries = 0;  // the cells' own entries of the c rows, per pair column
    for (int i = 0; i < A.n_rows; i += 2) {
      const int cell = block_[A.first_row + i];
      for (int k = A.row_ptr[i]; k < A.row_ptr[i + 1]; ++k)
        pair_entries += block_[A.col[k]] == cell;
    }
    pair_entries /= 2;
    const double basis = (o_.restart + 6.0) * n * 8;
    const double matrix = nnz * kTpetraEntry + n * 24;
    const double pairs = pair_entries * (kPairHostEntry + 4 * kTpetraEntry) + n * 60;
    const double hierarchies = 2 * kHierarchy * pair_entries * kTpetraEntry;
    return (basis + matrix + pairs + hierarchies) / 1048576.0;
  }

  // Whether the set-up for A would not fit in the memory the machine still
  // offers (memory.hpp); if so why says what it needs and what is left.
  // Collective over the solver's ranks: all go on or stop together.
  bool does_not_fit(const CsrRows &A, std::string &why) {
    const MachineMemory m = check_machine_memory(mpi_, machine_, estimate_mb(A));
    if (m.fits) return false;
    char text[320];
    if (m.fits_here)
      snprintf(text, sizeof text,
               "GMRES with the CH block preconditioner: its set-up does not fit on another "
               "machine of the run: out of memory, not started");
    else
      snprintf(text, sizeof text,
               "GMRES with the CH block preconditioner: its matrices, multigrid hierarchies and "
               "Krylov basis need about %.0f MB on this machine and %.0f MB are left (%s): out "
               "of memory, not started",
               m.need_mb, m.left_mb, m.source.c_str());
    why = text;
    out_of_memory_ = true;
    return true;
  }

  void hierarchy(Teuchos::RCP<MueLuOp> &amg, PairMatrix &p, bool new_pattern) {
    if (new_pattern || amg.is_null()) {
      Teuchos::ParameterList params = amg_params();
      Teuchos::RCP<OP> op = p.rows->matrix();
      amg = MueLu::CreateTpetraPreconditioner<double, int, GO, Node>(op, params);
    } else {
      MueLu::ReuseTpetraPreconditioner<double, int, GO, Node>(p.rows->matrix(), *amg);
    }
  }

  // Smoothed aggregation with Chebyshev smoothing of degree 4 (degree 2
  // takes 1.1-1.7x the GMRES iterations on 40^2-160^2 meshes; docs/solvers.md).
  static Teuchos::ParameterList amg_params() {
    Teuchos::ParameterList p;
    p.set("verbosity", "none");
    p.set("number of equations", 1);
    p.set("multigrid algorithm", "sa");
    p.set("max levels", 10);
    p.set("coarse: max size", 500);
    p.set("smoother: type", "CHEBYSHEV");
    Teuchos::ParameterList &sm = p.sublist("smoother: params");
    sm.set("chebyshev: degree", 4);
    sm.set("chebyshev: ratio eigenvalue", 20.0);
    // the coarse level by relaxation: Amesos2's KLU2 is wrong on several
    // ranks in this Trilinos (docs/building.md), and M dominates P there
    p.set("coarse: type", "RELAXATION");
    Teuchos::ParameterList &cp = p.sublist("coarse: params");
    cp.set("relaxation: type", "Symmetric Gauss-Seidel");
    cp.set("relaxation: sweeps", 4);
    p.set("reuse: type", "tP");
    p.set("aggregation: drop tol", 0.0);
    return p;
  }

  // A new pattern: the Tpetra copy of A, the pair matrices' patterns, the
  // GMRES on them.
  void set_up(const CsrRows &A) {
    gmres_.reset();
    rows_.reset();
    amg_ = amg2_ = Teuchos::null;
    if (A.first_row % 2 || A.n_rows % 2)
      throw std::logic_error("a rank's rows are not whole (c, mu) pairs");
    auto rows = std::make_unique<TpetraRows>(comm_, A);
    const int n = A.n_rows / 2;
    p_.clear();
    b_.clear();
    c_.clear();
    mm_.assign(n, {});
    cc_.assign(n, {});
    for (int i = 0; i < n; ++i) {
      const int rc = 2 * i, rm = 2 * i + 1, cell = block_[A.first_row + rc];
      // row c: P1 (c-c, and c-mu by g / b), b K (c-mu), the cell's c-c sum
      const int row_start = (int)p_.col.size();
      for (int k = A.row_ptr[rc]; k < A.row_ptr[rc + 1]; ++k) {
        const int j = A.col[k], q = j / 2;
        if (block_[j] != cell) continue;
        // (a row's columns are sorted: a pair's c and mu columns are neighbours)
        if ((int)p_.col.size() == row_start || p_.col.back() != q) p_.entry(q);
        p_.term(k, j % 2);
        if (j % 2) {
          b_.entry(q);
          b_.term(k, 0);
        } else {
          cc_[i].push_back(k);
        }
      }
      p_.end_row();
      b_.end_row();
      // row mu: C (the cell's own mu -> c block), the lumped mass
      for (int k = A.row_ptr[rm]; k < A.row_ptr[rm + 1]; ++k) {
        const int j = A.col[k];
        if (block_[j] != cell) continue;
        if (j % 2) {
          mm_[i].push_back(k);
        } else {
          c_.entry(j / 2);
          c_.term(k, 0);
        }
      }
      c_.end_row();
    }
    const int np = A.n_global / 2, first = A.first_row / 2;
    for (PairMatrix *m : {&p_, &b_, &c_}) {
      m->val.assign(m->col.size(), 0.0);
      m->rows = std::make_unique<TpetraRows>(comm_, m->csr(np, first, n));
    }
    p2_.ptr = p_.ptr;
    p2_.col = p_.col;
    p2_.val = p_.val;
    p2_.rows = std::make_unique<TpetraRows>(comm_, p2_.csr(np, first, n));
    diagonal_.assign(n, -1);
    for (int i = 0; i < n; ++i)
      for (int e = p_.ptr[i]; e < p_.ptr[i + 1]; ++e)
        if (p_.col[e] == first + i) diagonal_[i] = e;
    if (std::count(diagonal_.begin(), diagonal_.end(), -1))
      throw std::logic_error("a pair's row has no diagonal entry");
    lumped_.assign(n, 0.0);
    cell_mass_.assign(n_cells_, 0.0);
    pairs_ = p_.rows->matrix()->getRowMap();
    prec_ = Teuchos::rcp(new BlockPreconditioner(rows->matrix()->getRowMap(), pairs_));
    gmres_.set_up(*rows, prec_, o_, "GMRES with the CH block preconditioner");
    rows_ = std::move(rows);
    ++set_ups_;
  }

  // Each cell's c rows of b - A x summed to zero by a constant added to
  // its c (the file's header).
  void conserve_masses(double *x) {
    auto r = rows_->rhs();  // b, as the solve left it
    MV ax(r->getMap(), 1);
    rows_->matrix()->apply(*rows_->lhs(), ax);
    std::vector<double> lost(n_cells_, 0.0);
    const int n = rows_->n_local();
    const int first = (int)rows_->matrix()->getRowMap()->getMinGlobalIndex();
    {
      auto bv = r->getLocalViewHost(Tpetra::Access::ReadOnly);
      auto av = ax.getLocalViewHost(Tpetra::Access::ReadOnly);
      for (int i = 0; i < n; i += 2) lost[block_[first + i]] += bv(i, 0) - av(i, 0);
    }
    MPI_Allreduce(MPI_IN_PLACE, lost.data(), n_cells_, MPI_DOUBLE, MPI_SUM, mpi_);
    // x_c += delta, and x_mu -= Ml^-1 A_muc delta so that the mu rows stay
    // as the solve left them
    Vec delta(pairs_), v(pairs_);
    {
      auto d = delta.getLocalViewHost(Tpetra::Access::OverwriteAll);
      for (int i = 0; i < n; i += 2) {
        const int k = block_[first + i];
        d(i / 2, 0) = cell_mass_[k] > 0 ? lost[k] / cell_mass_[k] : 0.0;
        x[i] += d(i / 2, 0);
      }
    }
    c_.rows->matrix()->apply(delta, v);
    auto vv = v.getLocalViewHost(Tpetra::Access::ReadOnly);
    for (int i = 0; i < n; i += 2) x[i + 1] -= vv(i / 2, 0) / lumped_[i / 2];
  }

  static constexpr double kTpetraEntry = 24;    // value, local column, slot table
  static constexpr double kPairHostEntry = 72;  // PairMatrix's arrays, P1, P2, b K, C together
  static constexpr double kHierarchy = 3;       // a hierarchy's entries per entry of its matrix
  MPI_Comm mpi_, machine_;
  Teuchos::RCP<const Teuchos::Comm<int>> comm_;
  KrylovOptions o_;
  double g_ = 0, b_scale_ = 0;  // P1 = M + g K; b = dt mobility
  std::vector<int> block_;           // the cell of each global row
  int n_cells_ = 0;
  std::unique_ptr<TpetraRows> rows_;  // A, for GMRES
  PairMatrix p_, p2_, b_, c_;  // P1, P2, b K, -(k K + W) on the pairs
  std::vector<int> diagonal_;  // per pair: its diagonal entry in P1's and P2's rows
  std::vector<std::vector<int>> mm_, cc_;  // per pair: A's mu-mu and c-c entries of its cell
  std::vector<double> lumped_, cell_mass_;
  Teuchos::RCP<const Map> pairs_;
  Teuchos::RCP<MueLuOp> amg_, amg2_;
  Teuchos::RCP<BlockPreconditioner> prec_;
  Gmres gmres_;
  long iterations_ = 0;
  int set_ups_ = 0;
  bool out_of_memory_ = false;
};

}  // namespace

std::unique_ptr<LinearSolver> make_linear_gmres_amg(MPI_Comm comm,
                                                   const sp_solver_options &options) {
  return std::make_unique<AmgBlockSolver>(comm, krylov_options(options));
}

const char *linear_gmres_amg_version(bool *) {
  return "Belos GMRES preconditioned by a Cahn-Hilliard block preconditioner, "
         "MueLu smoothed-aggregation AMG (Trilinos " TRILINOS_VERSION_STRING ")";
}

}  // namespace sp
