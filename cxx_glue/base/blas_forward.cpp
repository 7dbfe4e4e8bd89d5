// A matrix times one column through the BLAS's matrix-vector product.
//
// MUMPS' solve phase multiplies each front's factor block by the one
// right-hand side with DGEMM (N = 1), and so do Belos' inner products of
// the Krylov basis against one vector. OpenBLAS 0.3.21 (Debian 12) runs
// such a DGEMM as a general product: it first copies ("packs") the whole
// factor block, which costs more than the product itself (about a quarter
// of a gmres_cells run on 256^2 elements, docs/solvers.md). Later OpenBLAS
// versions hand these calls to DGEMV themselves; this file does the same
// here: libsoftpack defines dgemm_, which every library the process loads
// after it (MUMPS, Trilinos, SuperLU) calls; a product with one column of
// B not transposed goes to the BLAS's dgemv_, every other to the BLAS's
// own dgemm_ (the next definition, found with dlsym(RTLD_NEXT)). The same
// product, in the matrix-vector kernel's order of summation.
//
// SOFTPACK_GEMM_FORWARD=0 in the environment turns it off (every call to
// the BLAS's dgemm_), for comparisons (bench/gemm_forward.sh).
#include <dlfcn.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "softpack_solver.h"

namespace {

using GemmFn = void(const char *, const char *, const int *, const int *, const int *,
                    const double *, const double *, const int *, const double *, const int *,
                    const double *, double *, const int *, std::size_t, std::size_t);

struct Forward {
  GemmFn *gemm = nullptr;
  bool on = true;
  Forward() {
    void *next = dlsym(RTLD_NEXT, "dgemm_");
    if (!next) {
      std::fprintf(stderr, "softpack: no BLAS dgemm_ after libsoftpack's in the process\n");
      std::abort();
    }
    std::memcpy(&gemm, &next, sizeof next);
    const char *env = std::getenv("SOFTPACK_GEMM_FORWARD");
    on = !(env && std::strcmp(env, "0") == 0);
  }
};

const Forward &forward() {
  static const Forward f;  // (initialised once, thread-safe)
  return f;
}

bool is_n(const char *trans) { return *trans == 'N' || *trans == 'n'; }

}  // namespace

extern "C" {

int sp_solver_gemm_forward(void) { return forward().on ? 1 : 0; }

void dgemv_(const char *trans, const int *m, const int *n, const double *alpha, const double *a,
            const int *lda, const double *x, const int *incx, const double *beta, double *y,
            const int *incy, std::size_t len_trans);

// C = alpha op(A) op(B) + beta C, op(A) m x k, op(B) k x n (the BLAS's
// interface, with gfortran's hidden lengths of the two character arguments).
void dgemm_(const char *transa, const char *transb, const int *m, const int *n, const int *k,
            const double *alpha, const double *a, const int *lda, const double *b,
            const int *ldb, const double *beta, double *c, const int *ldc, std::size_t len_a,
            std::size_t len_b) {
  const Forward &f = forward();
  // (m, k > 0: DGEMV returns at once on an empty A, where DGEMM still scales C by beta)
  if (f.on && *n == 1 && *m > 0 && *k > 0 && is_n(transb)) {
    // C(:,1) = alpha op(A) B(:,1) + beta C(:,1): A is stored m x k (N) or k x m (T)
    const int one = 1;
    const int rows = is_n(transa) ? *m : *k;
    const int cols = is_n(transa) ? *k : *m;
    dgemv_(transa, &rows, &cols, alpha, a, lda, b, &one, beta, c, &one, 1);
    return;
  }
  f.gemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, len_a, len_b);
}

}  // extern "C"
