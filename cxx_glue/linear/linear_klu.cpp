// KLU through SuiteSparse's own library (Debian's libsuitesparse-dev), not
// Amesos (v1), which Trilinos 17 removes. Serial: one rank
// holds all rows (under MPI, make_gathered runs it on rank 0).
//
// As for serial SuperLU, the CSR arrays of A are the CSC arrays of A^T:
// KLU factors A^T (its analysis, the BTF and AMD orderings, once per
// pattern; a numeric factorisation with partial pivoting per factor()) and
// klu_tsolve solves with its transpose, A x = b. KLU only reads the values,
// during factor(). A zero pivot (KLU_SINGULAR) fails the factorisation
// with the column that has it.
#include <klu.h>

#include <algorithm>
#include <string>

#include "linear/linear.hpp"

namespace sp {
namespace {

class Klu final : public LinearSolver {
 public:
  Klu() { klu_defaults(&common_); }
  ~Klu() override {
    klu_free_numeric(&numeric_, &common_);
    klu_free_symbolic(&symbolic_, &common_);
  }

  bool factor(const CsrRows &A, bool same_pattern, std::string &why) override {
    klu_free_numeric(&numeric_, &common_);
    out_of_memory_ = false;
    if (A.first_row != 0 || A.n_rows != A.n_global) {
      why = "KLU: the serial solver needs all rows on one process";
      return false;
    }
    const int n = A.n_global;
    // KLU's arrays are not const, and it changes none of them
    int *Ap = const_cast<int *>(A.row_ptr), *Ai = const_cast<int *>(A.col);
    if (!symbolic_ || !same_pattern || n != n_) {
      klu_free_symbolic(&symbolic_, &common_);
      symbolic_ = klu_analyze(n, Ap, Ai, &common_);
      ++analyses_;
      if (!symbolic_) {
        out_of_memory_ = common_.status == KLU_OUT_OF_MEMORY;
        why = "KLU: analysis failed (status " + std::to_string(common_.status) + ")";
        return false;
      }
      n_ = n;
    }
    numeric_ = klu_factor(Ap, Ai, A.val, symbolic_, &common_);
    if (!numeric_ || common_.status != KLU_OK) {
      out_of_memory_ = common_.status == KLU_OUT_OF_MEMORY;
      klu_free_numeric(&numeric_, &common_);
      why = common_.status == KLU_SINGULAR
                ? "KLU: the matrix is singular (zero pivot in column " +
                      std::to_string(common_.singular_col + 1) + ")"
                : "KLU: numeric factorisation failed (status " + std::to_string(common_.status) +
                      (common_.status == KLU_OUT_OF_MEMORY ? ": out of memory)" : ")");
      return false;
    }
    return true;
  }

  bool solve(const double *b, double *x, std::string &why) override {
    return solve_many(b, x, 1, n_, why);
  }

  bool solve_many(const double *B, double *X, int nrhs, int n_rows, std::string &why) override {
    if (!numeric_) {
      why = "KLU: solve without a factorisation";
      return false;
    }
    std::copy(B, B + (size_t)nrhs * n_rows, X);  // KLU solves in place
    if (!klu_tsolve(symbolic_, numeric_, n_rows, nrhs, X, &common_)) {
      why = "KLU: solve failed (status " + std::to_string(common_.status) + ")";
      return false;
    }
    return true;
  }

  int symbolic_count() const override { return analyses_; }
  bool out_of_memory() const override { return out_of_memory_; }

 private:
  klu_common common_;
  klu_symbolic *symbolic_ = nullptr;
  klu_numeric *numeric_ = nullptr;
  int n_ = 0, analyses_ = 0;
  bool out_of_memory_ = false;
};

}  // namespace

std::unique_ptr<LinearSolver> make_klu() { return std::make_unique<Klu>(); }

std::unique_ptr<LinearSolver> make_linear_klu(MPI_Comm, const sp_solver_options &) {
  return make_klu();
}

const char *linear_klu_version(bool *) {
  return "KLU " SP_STR(KLU_MAIN_VERSION) "." SP_STR(KLU_SUB_VERSION) "." SP_STR(
      KLU_SUBSUB_VERSION) " (SuiteSparse; gathered on rank 0 under MPI)";
}

}  // namespace sp
