// SuperLU_DIST: pdgssvx on this rank's rows as they are (SLU_NR_loc), on a
// 1 x P (or near-square) process grid of the solver's communicator.
//
// pdgssvx works in place: the factorisation rescales the values (Equil,
// MC64), applies the column permutation to the column indices, and the
// first solve with iterative refinement renumbers them again (pdgsmv_init).
// So every factorisation starts from fresh copies of the caller's arrays,
// and after a refactorisation the refinement's communication pattern is
// rebuilt on the next solve. With an unchanged pattern the factorisation
// reuses the orderings, scalings and the symbolic factorisation
// (Fact = SamePattern_SameRowPerm, the row permutation of the first matrix
// of this pattern). Factorisation (nrhs = 0) and solves (Fact = FACTORED) are
// separate calls, so they are timed separately.
//
// superlu_ddefs.h clashes with SuperLU's slu_ddefs.h: keep it alone in this TU.
#include <superlu_ddefs.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "linear.hpp"

namespace sp {
namespace {

class SuperLUDist final : public DirectSolver {
 public:
  explicit SuperLUDist(MPI_Comm comm) {
    int P = 1;
    MPI_Comm_size(comm, &P);
    // The squarest grid with nprow <= npcol (SuperLU_DIST prefers wide grids).
    int nprow = (int)std::sqrt((double)P);
    while (nprow > 1 && P % nprow != 0) --nprow;
    superlu_gridinit(comm, nprow, P / nprow, &grid_);
    set_default_options_dist(&options_);
    options_.PrintStat = NO;
    // Defaults kept: Equil = YES, RowPerm = LargeDiag_MC64, ColPerm =
    // METIS_AT_PLUS_A, IterRefine = SLU_DOUBLE (one refinement step makes
    // the solves as accurate as SuperLU's partial pivoting here).
  }
  ~SuperLUDist() override {
    release();
    superlu_gridexit(&grid_);
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    const bool reuse = same_pattern && have_structs_ && factored_once_ && A.n_global == n_ &&
                       A.n_rows == m_loc_ && A.first_row == fst_row_ &&
                       A.row_ptr[A.n_rows] == (int)col_saved_.size();
    if (!reuse) {
      release();
      n_ = A.n_global;
      m_loc_ = A.n_rows;
      fst_row_ = A.first_row;
      const int nnz = A.row_ptr[A.n_rows];
      ptr_saved_.assign(A.row_ptr, A.row_ptr + A.n_rows + 1);
      col_saved_.assign(A.col, A.col + nnz);
      dScalePermstructInit(n_, n_, &scale_perm_);
      dLUstructInit(n_, &lu_);
      have_structs_ = true;
      options_.Fact = DOFACT;
      ++symbolic_;
    } else {
      options_.Fact = SamePattern_SameRowPerm;
      // The solve set-up is for solve_nrhs_ columns: for another count,
      // drop it (with the refinement's), the next solve rebuilds it on the
      // fresh matrix below.
      if (options_.SolveInitialized == YES && next_nrhs_ != solve_nrhs_)
        dSolveFinalize(&options_, &solve_);
      // The refinement's matrix-vector pattern was built on the previous
      // (renumbered) matrix: drop it, the next solve rebuilds it.
      if (options_.SolveInitialized == YES && options_.RefineInitialized == YES) {
        pdgsmv_finalize(solve_.gsmv_comm);
        options_.RefineInitialized = NO;
      }
    }
    // Fresh copies of what pdgssvx overwrote last time.
    const int nnz = A.row_ptr[A.n_rows];
    ptr_.assign(ptr_saved_.begin(), ptr_saved_.end());
    col_.assign(col_saved_.begin(), col_saved_.end());
    val_.assign(A.val, A.val + nnz);
    if (have_matrix_) Destroy_SuperMatrix_Store_dist(&A_);
    dCreate_CompRowLoc_Matrix_dist(&A_, n_, n_, nnz, m_loc_, fst_row_, val_.data(), col_.data(),
                                   ptr_.data(), SLU_NR_loc, SLU_D, SLU_GE);
    have_matrix_ = true;

    SuperLUStat_t stat;
    PStatInit(&stat);
    int info = 0;
    double berr = 0;
    pdgssvx(&options_, &A_, &scale_perm_, nullptr, m_loc_ > 0 ? m_loc_ : 1, 0, &grid_, &lu_,
            &solve_, &berr, &stat, &info);
    PStatFree(&stat);
    have_lu_ = info >= 0 && info <= n_;  // L and U were distributed (maybe singular)
    factored_once_ = info == 0;
    if (info != 0) {
      why = info > 0 && info <= n_
                ? "SuperLU_DIST: the matrix is singular (zero pivot in column " +
                      std::to_string(info) + ")"
            : info > n_ ? "SuperLU_DIST: out of memory in the factorisation"
                        : "SuperLU_DIST: pdgssvx rejected argument " + std::to_string(-info);
      release();  // the next factorisation starts from scratch
      return false;
    }
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return solve_many(b, x, 1, m_loc_, why);
  }

  // The solve set-up (pdgstrs_init) is for one column count, and rebuilding
  // it after a solve would redo the refinement's set-up on the already
  // renumbered column indices: other counts are solved in blocks of the
  // set-up's count, padded with zero columns. set_rhs_count() before a
  // factorisation changes the count safely (factor() starts from fresh
  // arrays).
  bool solve_many(const double *b, double *x, int nrhs, int n_rows, std::string &why) override {
    if (!factored_once_ || n_rows != m_loc_) {
      why = "SuperLU_DIST: solve without a factorisation";
      return false;
    }
    const int ld = m_loc_ > 0 ? m_loc_ : 1;
    if (options_.SolveInitialized == NO) solve_nrhs_ = nrhs;
    if (nrhs == solve_nrhs_) {
      std::memcpy(x, b, sizeof(double) * m_loc_ * (size_t)nrhs);
      return pdgssvx_solve(x, ld, nrhs, why);
    }
    std::vector<double> block((size_t)ld * solve_nrhs_);
    for (int j0 = 0; j0 < nrhs; j0 += solve_nrhs_) {
      const int cols = std::min(solve_nrhs_, nrhs - j0);
      std::fill(block.begin(), block.end(), 0.0);
      std::memcpy(block.data(), b + (size_t)j0 * m_loc_, sizeof(double) * m_loc_ * (size_t)cols);
      if (!pdgssvx_solve(block.data(), ld, solve_nrhs_, why)) return false;
      std::memcpy(x + (size_t)j0 * m_loc_, block.data(), sizeof(double) * m_loc_ * (size_t)cols);
    }
    return true;
  }

  void set_rhs_count(int nrhs) override { next_nrhs_ = nrhs; }

  int symbolic_count() const override { return symbolic_; }

 private:
  bool pdgssvx_solve(double *x, int ld, int nrhs, std::string &why) {
    options_.Fact = FACTORED;
    SuperLUStat_t stat;
    PStatInit(&stat);
    int info = 0;
    std::vector<double> berr(nrhs, 0.0);
    pdgssvx(&options_, &A_, &scale_perm_, x, ld, nrhs, &grid_, &lu_, &solve_, berr.data(), &stat,
            &info);
    PStatFree(&stat);
    if (info != 0) {
      why = "SuperLU_DIST: the solve failed (info " + std::to_string(info) + ")";
      return false;
    }
    return true;
  }

  void release() {
    if (options_.SolveInitialized == YES) dSolveFinalize(&options_, &solve_);
    if (have_structs_) {
      if (have_lu_) dDestroy_LU(n_, &grid_, &lu_);
      dScalePermstructFree(&scale_perm_);
      dLUstructFree(&lu_);
      have_structs_ = have_lu_ = false;
    }
    if (have_matrix_) {
      Destroy_SuperMatrix_Store_dist(&A_);
      have_matrix_ = false;
    }
    factored_once_ = false;
  }

  gridinfo_t grid_;
  superlu_dist_options_t options_;
  dScalePermstruct_t scale_perm_;
  dLUstruct_t lu_;
  dSOLVEstruct_t solve_;
  SuperMatrix A_;
  bool have_structs_ = false, have_lu_ = false, have_matrix_ = false, factored_once_ = false;
  int n_ = 0, m_loc_ = 0, fst_row_ = 0, symbolic_ = 0;
  int solve_nrhs_ = 1, next_nrhs_ = 1;  // columns of the solve set-up, and of the next
  std::vector<int_t> ptr_saved_, col_saved_, ptr_, col_;
  std::vector<double> val_;
};

static_assert(sizeof(int_t) == sizeof(int), "SuperLU_DIST built with 64-bit indices");

}  // namespace

std::unique_ptr<DirectSolver> make_superlu_dist(MPI_Comm comm) {
  return std::make_unique<SuperLUDist>(comm);
}

}  // namespace sp
