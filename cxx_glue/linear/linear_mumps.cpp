// MUMPS through its own C interface (dmumps_c, Debian's libmumps-dev), on
// the CSR rows as they are distributed, with no Trilinos solver package
// in between.
//
// One process: the centralised assembled input (ICNTL(18) = 0), the rows'
// own arrays as the values. Several: the distributed assembled input
// (ICNTL(18) = 3), each rank handing MUMPS its own rows; the right-hand
// side and the solution are centralised on rank 0 (ICNTL(21) = 0) and
// gathered / scattered here. The analysis (job 1) runs once per pattern,
// each factor() is a numeric factorisation (job 2) on the new values.
//
// The controls are those softpack gave MUMPS through Amesos, so the
// factors are the same: general unsymmetric (SYM = 0), the host working
// (PAR = 1), automatic column permutation and ordering (ICNTL(6) = ICNTL(7)
// = 7), row and column iterative scaling (ICNTL(8) = 7, what Amesos sets),
// no iterative refinement, workspace relaxation 100% (ICNTL(14): delayed
// pivots need room; 20% from the first factorisation whose workspace
// could not be allocated with 100%: docs/3d.md, "Solvers in 3D"), the
// pivoting threshold CNTL(1) = 0.01 (MUMPS' default for unsymmetric
// matrices). Unlike Amesos, which ends the process
// on any MUMPS error, a failed factorisation or solve returns false with
// MUMPS' INFOG(1), INFOG(2) in why, so Newton fails the attempt and the
// step is retried (but for a refused allocation, INFOG(1) = -13:
// out_of_memory(), and the run ends, docs/robustness.md).
#include <dmumps_c.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "base/memory.hpp"
#include "linear/linear.hpp"

namespace sp {
namespace {

// MUMPS' arrays are 1-based in Fortran's convention.
#define SP_ICNTL(I) icntl[(I) - 1]
#define SP_CNTL(I) cntl[(I) - 1]
#define SP_INFOG(I) infog[(I) - 1]
#define SP_INFO(I) info[(I) - 1]
constexpr int kJobInit = -1, kJobEnd = -2, kJobAnalyse = 1, kJobFactor = 2, kJobSolve = 3;
constexpr int kLeanRelaxation = 20;  // ICNTL(14) as MUMPS itself sets it (unsymmetric, one process)

class MumpsSolver final : public LinearSolver {
 public:
  explicit MumpsSolver(MPI_Comm comm) {
    MPI_Comm_dup(comm, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
    MPI_Comm_split_type(comm_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &machine_);
    id_ = DMUMPS_STRUC_C();
    id_.comm_fortran = (MUMPS_INT)MPI_Comm_c2f(comm_);
    id_.par = 1;  // the host works too
    id_.sym = 0;  // general unsymmetric
    id_.job = kJobInit;
    dmumps_c(&id_);
    started_ = id_.SP_INFOG(1) >= 0;
    if (started_) controls();  // quiet from here on, its end included
  }

  ~MumpsSolver() override {
    if (started_) {
      id_.job = kJobEnd;  // collective, as the solver's destruction is
      dmumps_c(&id_);
    }
    MPI_Comm_free(&machine_);
    MPI_Comm_free(&comm_);
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    if (!started_) {
      why = "MUMPS: initialisation failed (INFOG(1) = " + std::to_string(id_.SP_INFOG(1)) + ")";
      return false;
    }
    factored_ = false;
    const long long nnz = A.row_ptr[A.n_rows];
    if (!analysed_ || !same_pattern || A.n_global != n_global_ || A.n_rows != n_rows_ ||
        nnz != (long long)irn_.size()) {
      analysed_ = false;
      set_pattern(A);
      controls();
      // the values too: the automatic column permutation (ICNTL(6) = 7) and
      // the scaling read them during the analysis (with the pointer of the
      // last factorisation they read a matrix of the old pattern, or freed
      // memory)
      if (size_ == 1) id_.a = A.val;
      else id_.a_loc = A.val;
      id_.job = kJobAnalyse;
      dmumps_c(&id_);
      ++symbolic_;
      if (failed("analysis", why)) return false;
      analysed_ = true;
    }
    if (size_ == 1) id_.a = A.val;  // only read, during this call
    else id_.a_loc = A.val;
    if (does_not_fit(why)) {
      if (relaxation_ <= kLeanRelaxation) return false;
      // The estimate counts the workspace's relaxation, room for delayed
      // pivots that is mostly never touched: with what MUMPS itself sets it
      // may fit (then kept, as after a refused allocation). A new analysis
      // gives its estimate.
      relaxation_ = kLeanRelaxation;
      id_.SP_ICNTL(14) = relaxation_;
      id_.job = kJobAnalyse;
      dmumps_c(&id_);
      ++symbolic_;
      if (failed("analysis", why) || does_not_fit(why)) return false;
    }
    id_.job = kJobFactor;
    dmumps_c(&id_);
    if (id_.SP_INFOG(1) == -13 && relaxation_ > kLeanRelaxation) {
      // The workspace MUMPS allocates is its analysis's estimate plus
      // ICNTL(14) percent; a refused allocation with 100% may fit with
      // what MUMPS itself sets, 20% (room for fewer delayed pivots): once
      // more with that, and with it from now on.
      relaxation_ = kLeanRelaxation;
      id_.SP_ICNTL(14) = relaxation_;
      dmumps_c(&id_);
    }
    if (failed("numeric factorisation", why)) return false;
    factored_ = true;
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    if (!factored_) {
      why = "MUMPS: solve without a factorisation";
      return false;
    }
    if (size_ == 1) {
      std::copy(b, b + n_rows_, x);  // MUMPS overwrites the right-hand side
      id_.rhs = x;
    } else {
      MPI_Gatherv(b, n_rows_, MPI_DOUBLE, rank_ == 0 ? rhs_.data() : nullptr, counts_.data(),
                  firsts_.data(), MPI_DOUBLE, 0, comm_);
      id_.rhs = rank_ == 0 ? rhs_.data() : nullptr;
    }
    id_.nrhs = 1;
    id_.lrhs = n_global_;
    id_.job = kJobSolve;
    dmumps_c(&id_);
    if (failed("solve", why)) return false;
    if (size_ > 1)
      MPI_Scatterv(rank_ == 0 ? rhs_.data() : nullptr, counts_.data(), firsts_.data(),
                   MPI_DOUBLE, x, n_rows_, MPI_DOUBLE, 0, comm_);
    return true;
  }

  int symbolic_count() const override { return symbolic_; }
  bool out_of_memory() const override { return out_of_memory_; }

 private:
  // The triplets (1-based rows and columns) of this rank's rows, kept for
  // the numeric factorisations of the same pattern; on several ranks the
  // row counts and first rows of all ranks, for the right-hand side.
  void set_pattern(const CsrRows &A) {
    n_global_ = A.n_global;
    n_rows_ = A.n_rows;
    const size_t nnz = (size_t)A.row_ptr[A.n_rows];
    irn_.resize(nnz);
    jcn_.resize(nnz);
    for (int i = 0; i < A.n_rows; ++i)
      for (int j = A.row_ptr[i]; j < A.row_ptr[i + 1]; ++j) {
        irn_[j] = A.first_row + i + 1;
        jcn_[j] = A.col[j] + 1;
      }
    id_.n = A.n_global;
    if (size_ == 1) {
      id_.nnz = (MUMPS_INT8)nnz;
      id_.irn = irn_.data();
      id_.jcn = jcn_.data();
    } else {
      id_.nnz_loc = (MUMPS_INT8)nnz;
      id_.irn_loc = irn_.data();
      id_.jcn_loc = jcn_.data();
      counts_.resize(size_);
      firsts_.resize(size_);
      MPI_Allgather(&A.n_rows, 1, MPI_INT, counts_.data(), 1, MPI_INT, comm_);
      MPI_Allgather(&A.first_row, 1, MPI_INT, firsts_.data(), 1, MPI_INT, comm_);
      if (rank_ == 0) rhs_.resize((size_t)A.n_global);
    }
  }

  void controls() {
    id_.SP_ICNTL(1) = -1;  // no error, diagnostic or global messages
    id_.SP_ICNTL(2) = -1;
    id_.SP_ICNTL(3) = -1;
    id_.SP_ICNTL(4) = 0;
    id_.SP_ICNTL(5) = 0;  // assembled input
    id_.SP_ICNTL(6) = 7;  // column permutation: automatic
    id_.SP_ICNTL(7) = 7;  // ordering: automatic
    id_.SP_ICNTL(8) = 7;  // scaling: row and column iterative (as Amesos set it)
    id_.SP_ICNTL(9) = 1;  // A x = b
    id_.SP_ICNTL(10) = 0;  // no iterative refinement
    id_.SP_ICNTL(11) = 0;  // no error analysis
    id_.SP_ICNTL(14) = relaxation_;  // workspace relaxation, % (100, or 20 once 100 did not fit)
    id_.SP_ICNTL(18) = size_ == 1 ? 0 : 3;  // centralised / distributed input
    id_.SP_ICNTL(20) = 0;  // dense right-hand side ...
    id_.SP_ICNTL(21) = 0;  // ... and solution, on the host
    id_.SP_CNTL(1) = 0.01;  // relative pivoting threshold
  }

  // Whether the factorisation would not fit in the memory the machine still
  // offers this job (memory.hpp): the analysis's estimate (INFO(15), MB,
  // this rank's, in-core) summed over the ranks on this machine, against
  // the least any of them may still use. A factorisation that does not fit
  // is not started (out_of_memory(), why says what it needs and what is
  // left): on a machine that overcommits, its allocations would succeed
  // and the kernel's OOM killer end the run when they are touched. Called
  // on every rank alike (collective over the solver's ranks: where one machine
  // does not fit, every rank stops).
  bool does_not_fit(std::string &why) {
    const MachineMemory m =
        check_machine_memory(comm_, machine_, id_.SP_INFO(15) > 0 ? id_.SP_INFO(15) : 0.0);
    if (m.fits) return false;
    char text[320];
    if (m.fits_here)
      snprintf(text, sizeof text,
               "MUMPS: its factorisation does not fit on another machine of the run (%d%% "
               "workspace relaxation): out of memory, not started",
               relaxation_);
    else
      snprintf(text, sizeof text,
               "MUMPS: its factorisation needs about %.0f MB on this machine (its analysis's "
               "estimate, %d%% workspace relaxation) and %.0f MB are left (%s): out of memory, "
               "not started",
               m.need_mb, relaxation_, m.left_mb, m.source.c_str());
    why = text;
    out_of_memory_ = true;
    return true;
  }

  // After a call: true (and why) when MUMPS reports an error. INFOG is
  // global: every rank sees the same.
  bool failed(const char *phase, std::string &why) {
    const int info = id_.SP_INFOG(1);
    out_of_memory_ = false;
    if (info >= 0) return false;
    why = std::string("MUMPS: ") + phase + " failed (INFOG(1) = " + std::to_string(info) +
          ", INFOG(2) = " + std::to_string(id_.SP_INFOG(2)) + ")";
    if (info == -10) why += ": the matrix is numerically singular";
    if (info == -13) {
      // An ALLOCATE refused: INFOG(2) entries (doubles), in millions when
      // negative (the MUMPS users' guide, INFO(1) = -13).
      const double entries = id_.SP_INFOG(2) < 0 ? -1e6 * id_.SP_INFOG(2) : id_.SP_INFOG(2);
      char size[96];
      const double bytes = 8 * entries;
      snprintf(size, sizeof size, ": out of memory (it asked for %.3g entries, %.1f %s)", entries,
               bytes >= 1e9 ? bytes / 1e9 : bytes / 1e6, bytes >= 1e9 ? "GB" : "MB");
      why += size;
      out_of_memory_ = true;
    }
    if (info == -8 || info == -9 || info == -14 || info == -15)
      why += ": out of workspace (internal)";
    return true;
  }

  MPI_Comm comm_, machine_;  // the solver's ranks; those of them on this machine
  int rank_ = 0, size_ = 1;
  DMUMPS_STRUC_C id_;
  bool started_ = false, analysed_ = false, factored_ = false, out_of_memory_ = false;
  int n_global_ = 0, n_rows_ = 0, symbolic_ = 0;
  int relaxation_ = 100;  // ICNTL(14)
  std::vector<MUMPS_INT> irn_, jcn_;
  std::vector<int> counts_, firsts_;  // every rank's rows (several ranks)
  std::vector<double> rhs_;           // the gathered right-hand side (rank 0)
};

}  // namespace

std::unique_ptr<LinearSolver> make_mumps(MPI_Comm comm) {
  return std::make_unique<MumpsSolver>(comm);
}

std::unique_ptr<LinearSolver> make_linear_mumps(MPI_Comm comm, const sp_solver_options &) {
  return make_mumps(comm);
}

const char *linear_mumps_version(bool *) { return "MUMPS " MUMPS_VERSION " (its C interface)"; }

}  // namespace sp
