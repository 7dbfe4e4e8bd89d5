// SuperLU_DIST: pdgssvx on this rank's rows as they are (SLU_NR_loc), on a
// 1 x P (or near-square) process grid of the solver's communicator.
//
// pdgssvx works in place: the factorisation rescales the values (Equil,
// MC64), applies the column permutation to the column indices, and the
// first solve with iterative refinement renumbers them again (pdgsmv_init).
// So every factorisation starts from fresh copies of the caller's arrays,
// and after a refactorisation the refinement's communication pattern is
// rebuilt on the next solve. With an unchanged pattern the factorisation
// reuses the column ordering (Fact = SamePattern) and computes the row
// permutation and scalings (MC64) of each matrix anew, so a factorisation
// depends on its matrix alone, not on the matrices before it: a run
// continued from a checkpoint factorises exactly as the run that wrote it.
// SamePattern_SameRowPerm (the first matrix's row permutation kept) spent
// 21-26% less time factorising: the price of bit-identical continuation,
// measured in docs/restart.md. Factorisation (nrhs = 0) and
// solves (Fact = FACTORED) are separate calls, so they are timed separately.
//
// superlu_ddefs.h clashes with SuperLU's slu_ddefs.h: keep it alone in this TU.
#include <superlu_ddefs.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "linear/linear.hpp"

namespace sp {
namespace {

class SuperLUDist final : public LinearSolver {
 public:
  SuperLUDist(MPI_Comm comm, bool pair_order, bool refine) : pair_order_(pair_order) {
    int P = 1;
    MPI_Comm_size(comm, &P);
    // The squarest grid with nprow <= npcol (SuperLU_DIST prefers wide grids).
    int nprow = (int)std::sqrt((double)P);
    while (nprow > 1 && P % nprow != 0) --nprow;
    superlu_gridinit(comm, nprow, P / nprow, &grid_);
    set_default_options_dist(&options_);
    options_.PrintStat = NO;
    // Defaults kept: Equil = YES, RowPerm = LargeDiag_MC64. ColPerm: METIS
    // on the pair graph (pair_ordering), given as MY_PERMC, or
    // METIS_AT_PLUS_A. IterRefine: SuperLU_DIST's default, one step of
    // iterative refinement per solve (SLU_DOUBLE), only with refine; its
    // residual and second triangular solve cost 2/3 of a solve and change
    // nothing Newton sees here (docs/parallel.md).
    options_.IterRefine = refine ? SLU_DOUBLE : NOREFINE;
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
      // Pairs of rows (c, mu) on every rank: order the pair graph.
      int pairs = pair_order_ && A.n_rows % 2 == 0 && A.first_row % 2 == 0 && n_ % 2 == 0,
          all_pairs = 0;
      MPI_Allreduce(&pairs, &all_pairs, 1, MPI_INT, MPI_MIN, grid_.comm);
      if (all_pairs) pair_ordering(A, scale_perm_.perm_c);
      options_.ColPerm = all_pairs ? MY_PERMC : METIS_AT_PLUS_A;
      have_structs_ = true;
      options_.Fact = DOFACT;
      ++symbolic_;
    } else {
      options_.Fact = SamePattern;
      // SamePattern computes the factors' structure anew (the row
      // permutation may differ): the old L and U are freed first, as
      // pdgssvx expects (kept, they leaked one factorisation's memory per
      // Newton iteration: 24 GB on the aggregate), and the solve set-up,
      // built on them, is dropped with the refinement's; the next solve
      // rebuilds both on the fresh matrix below.
      if (options_.SolveInitialized == YES) dSolveFinalize(&options_, &solve_);
      if (have_lu_) dDestroy_LU(n_, &grid_, &lu_);
    }
    // Fresh copies of the pattern pdgssvx overwrote last time; the values
    // are the caller's to overwrite (linear.hpp: filled anew before every
    // factor(), left alone until the next, so the solves' refinement may
    // read them).
    const int nnz = A.row_ptr[A.n_rows];
    ptr_.assign(ptr_saved_.begin(), ptr_saved_.end());
    col_.assign(col_saved_.begin(), col_saved_.end());
    if (have_matrix_) Destroy_SuperMatrix_Store_dist(&A_);
    dCreate_CompRowLoc_Matrix_dist(&A_, n_, n_, nnz, m_loc_, fst_row_, A.val, col_.data(),
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
  bool overwrites_values() const override { return true; }  // pdgssvx scales, permutes

 private:
  // METIS (as SuperLU_DIST calls it, on A + A^T) on the graph of the
  // (cell, node) pairs instead of the unknowns: the two unknowns of a pair
  // (c and mu) have the same couplings, so the pair graph holds the same
  // structure with a quarter of the edges; each pair's two unknowns take
  // consecutive places. perm_c[j]: the place of column j. Every rank
  // computes it from the whole pattern, as SuperLU_DIST does.
  void pair_ordering(const CsrRows &A, int_t *perm_c) {
    const int my_pairs = A.n_rows / 2;
    std::vector<int> len(my_pairs), col, row;
    for (int r = 0; r < my_pairs; ++r) {
      row.clear();
      for (int k = A.row_ptr[2 * r]; k < A.row_ptr[2 * r + 2]; ++k) row.push_back(A.col[k] / 2);
      std::sort(row.begin(), row.end());
      row.erase(std::unique(row.begin(), row.end()), row.end());
      len[r] = (int)row.size();
      col.insert(col.end(), row.begin(), row.end());
    }
    int P = 1;
    MPI_Comm_size(grid_.comm, &P);
    const int my_nnz = (int)col.size();
    std::vector<int> pairs(P), nnzs(P), pair_at(P, 0), nnz_at(P, 0);
    MPI_Allgather(&my_pairs, 1, MPI_INT, pairs.data(), 1, MPI_INT, grid_.comm);
    MPI_Allgather(&my_nnz, 1, MPI_INT, nnzs.data(), 1, MPI_INT, grid_.comm);
    for (int r = 1; r < P; ++r) {
      pair_at[r] = pair_at[r - 1] + pairs[r - 1];
      nnz_at[r] = nnz_at[r - 1] + nnzs[r - 1];
    }
    const int n_pairs = pair_at[P - 1] + pairs[P - 1], nnz = nnz_at[P - 1] + nnzs[P - 1];
    std::vector<int> all_len(n_pairs);
    std::vector<int_t> rowind(nnz), colptr(n_pairs + 1, 0), order(n_pairs);
    MPI_Allgatherv(len.data(), my_pairs, MPI_INT, all_len.data(), pairs.data(), pair_at.data(),
                   MPI_INT, grid_.comm);
    MPI_Allgatherv(col.data(), my_nnz, MPI_INT, rowind.data(), nnzs.data(), nnz_at.data(),
                   MPI_INT, grid_.comm);
    for (int p = 0; p < n_pairs; ++p) colptr[p + 1] = colptr[p] + all_len[p];
    std::vector<double> values(nnz, 1.0);  // not read: the ordering needs the pattern only
    NCformat store{nnz, values.data(), rowind.data(), colptr.data()};
    SuperMatrix G;
    G.Stype = SLU_NC;
    G.Dtype = SLU_D;
    G.Mtype = SLU_GE;
    G.nrow = G.ncol = n_pairs;
    G.Store = &store;
    get_perm_c_dist(grid_.iam, METIS_AT_PLUS_A, &G, order.data());
    for (int p = 0; p < n_pairs; ++p) {
      perm_c[2 * p] = 2 * order[p];
      perm_c[2 * p + 1] = 2 * order[p] + 1;
    }
  }

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
  bool pair_order_;  // METIS on the pair graph (else on the unknowns)
  int solve_nrhs_ = 1, next_nrhs_ = 1;  // columns of the solve set-up, and of the next
  std::vector<int_t> ptr_saved_, col_saved_, ptr_, col_;
};

static_assert(sizeof(int_t) == sizeof(int), "SuperLU_DIST built with 64-bit indices");

}  // namespace

std::unique_ptr<LinearSolver> make_superlu_dist(MPI_Comm comm, bool pair_order, bool refine) {
  return std::make_unique<SuperLUDist>(comm, pair_order, refine);
}

std::unique_ptr<LinearSolver> make_linear_superlu_dist(MPI_Comm comm,
                                                      const sp_solver_options &options) {
  return make_superlu_dist(comm, options.ordering == SP_SOLVER_ORDER_PAIRS, options.refine != 0);
}

const char *linear_superlu_dist_version(bool *) {
  return "SuperLU_DIST " SP_STR(SUPERLU_DIST_MAJOR_VERSION) "." SP_STR(
      SUPERLU_DIST_MINOR_VERSION) "." SP_STR(SUPERLU_DIST_PATCH_VERSION) " (pdgssvx)";
}

}  // namespace sp
