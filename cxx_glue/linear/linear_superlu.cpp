// Serial SuperLU. The CSR arrays of A are the CSC arrays of A^T: we factor
// A^T = Pr^T L U Pc^T and solve A x = b with the transposed triangular
// solves, exactly what dgssvx does for SLU_NR input, but with the
// factorisation and the solves split (they are timed separately) and the
// column ordering kept while the pattern is unchanged.
// slu_ddefs.h clashes with SuperLU_DIST's headers: keep it alone in this TU.
#include <slu_ddefs.h>

#include <cstring>
#include <vector>

#include "linear/linear.hpp"

namespace sp {
namespace {

class SuperLU final : public LinearSolver {
 public:
  static constexpr double kDiagonalPivotThreshold = 1e-3;

  // Ordering and pivoting measured on a 3-cell step (one factorisation,
  // 14k / 99k unknowns, OpenBLAS): COLAMD with partial pivoting 1.3 s /
  // 36 s; MMD on A^T A 0.38 s / 10 s; MMD on A^T + A with threshold pivoting
  // (0.001, diagonal preferred) 0.18 s / 3.5 s, Newton still converging to
  // |F| ~ 1e-16. The mixed form's diagonal (mass matrices) is a safe pivot.
  SuperLU() {
    set_default_options(&options_);
    options_.ColPerm = MMD_AT_PLUS_A;
    options_.SymmetricMode = YES;
    options_.DiagPivotThresh = kDiagonalPivotThreshold;
    StatInit(&stat_);
  }
  ~SuperLU() override {
    release_factors();
    StatFree(&stat_);
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    release_factors();
    out_of_memory_ = false;
    if (A.first_row != 0 || A.n_rows != A.n_global) {
      why = "SuperLU: the serial solver needs all rows on one process";
      return false;
    }
    const int n = A.n_global;
    const int nnz = A.row_ptr[n];
    // A view of the caller's rows (SuperLU's matrix types take non-const
    // pointers): dgstrf reads A during this call only and changes nothing
    // in it (no equilibration here); the factors L and U are SuperLU's own.
    SuperMatrix At;  // CSC of A^T = CSR of A
    dCreate_CompCol_Matrix(&At, n, n, nnz, A.val, const_cast<int *>(A.col),
                           const_cast<int *>(A.row_ptr), SLU_NC, SLU_D, SLU_GE);
    if (!same_pattern || (int)perm_c_.size() != n) {
      perm_c_.assign(n, 0);
      get_perm_c(options_.ColPerm, &At, perm_c_.data());
      ++symbolic_;
    }
    perm_r_.assign(n, 0);
    etree_.assign(n, 0);
    SuperMatrix AC;
    options_.Fact = DOFACT;
    sp_preorder(&options_, &At, perm_c_.data(), etree_.data(), &AC);
    int info = 0;
    GlobalLU_t glu;
    dgstrf(&options_, &AC, sp_ienv(2), sp_ienv(1), etree_.data(), nullptr, 0,
           perm_c_.data(), perm_r_.data(), &L_, &U_, &glu, &stat_, &info);
    Destroy_CompCol_Permuted(&AC);
    Destroy_SuperMatrix_Store(&At);
    have_factors_ = info <= n;  // info > n: allocation failure, no L/U
    out_of_memory_ = info > n;
    if (info != 0) {
      why = info <= n ? "SuperLU: the matrix is singular (zero pivot in column " +
                            std::to_string(info) + ")"
                      : "SuperLU: out of memory in the factorisation (" +
                            std::to_string((long)info - n) + " bytes held when an allocation failed)";
      release_factors();
      return false;
    }
    n_ = n;
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return solve_many(b, x, 1, n_, why);
  }

  bool solve_many(const double *b, double *x, int nrhs, int n_rows, std::string &why) override {
    if (!have_factors_ || n_rows != n_) {
      why = "SuperLU: solve without a factorisation";
      return false;
    }
    std::memcpy(x, b, sizeof(double) * n_ * (size_t)nrhs);
    SuperMatrix B;
    dCreate_Dense_Matrix(&B, n_, nrhs, x, n_, SLU_DN, SLU_D, SLU_GE);
    int info = 0;
    dgstrs(TRANS, &L_, &U_, perm_c_.data(), perm_r_.data(), &B, &stat_, &info);
    Destroy_SuperMatrix_Store(&B);
    if (info != 0) {
      why = "SuperLU: triangular solve failed (info " + std::to_string(info) + ")";
      return false;
    }
    return true;
  }

  int symbolic_count() const override { return symbolic_; }
  bool out_of_memory() const override { return out_of_memory_; }

 private:
  void release_factors() {
    if (!have_factors_) return;
    Destroy_SuperNode_Matrix(&L_);
    Destroy_CompCol_Matrix(&U_);
    have_factors_ = false;
  }

  superlu_options_t options_;
  SuperLUStat_t stat_;
  SuperMatrix L_, U_;
  bool have_factors_ = false, out_of_memory_ = false;
  int n_ = 0, symbolic_ = 0;
  std::vector<int> perm_c_, perm_r_, etree_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_superlu() { return std::make_unique<SuperLU>(); }

std::unique_ptr<LinearSolver> make_linear_superlu(MPI_Comm, const sp_solver_options &) {
  return make_superlu();
}

const char *linear_superlu_version(bool *) {
  return "SuperLU " SP_STR(SUPERLU_MAJOR_VERSION) "." SP_STR(SUPERLU_MINOR_VERSION) "." SP_STR(
      SUPERLU_PATCH_VERSION) " (dgstrf; gathered on rank 0 under MPI)";
}

}  // namespace sp
