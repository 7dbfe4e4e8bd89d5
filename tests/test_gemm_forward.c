/* libsoftpack's dgemm_ (cxx_glue/base/blas_forward.cpp) is the one the
 * process calls (MUMPS and Trilinos resolve the same global symbol), and
 * computes C = alpha op(A) B + beta C as the BLAS does: products with one
 * column of B (handed to dgemv_) and with two (handed to the BLAS's
 * dgemm_), op(A) = A and A^T, against sums written out here to 1e-14 of
 * the terms' magnitude; an empty A (m = 0 or k = 0) leaves C scaled by beta
 * (where DGEMV would not touch it). */
#define _GNU_SOURCE /* dladdr, RTLD_DEFAULT */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "softpack_solver.h"

void dgemm_(const char *ta, const char *tb, const int *m, const int *n, const int *k,
            const double *alpha, const double *a, const int *lda, const double *b, const int *ldb,
            const double *beta, double *c, const int *ldc, size_t la, size_t lb);

enum { M = 37, K = 23, N = 2, LD = 41 };

/** C = alpha op(A) B + beta C with the sums written out; the largest
 *  difference from @p got relative to the sum of the terms' magnitudes. */
static double worst_error(char ta, int m, int n, int k, double alpha, const double *a,
                          const double *b, double beta, const double *c0, const double *got) {
  double worst = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) {
      double sum = 0, mag = fabs(beta * c0[i + j * LD]);
      for (int l = 0; l < k; ++l) {
        const double ail = ta == 'N' ? a[i + l * LD] : a[l + i * LD];
        sum += ail * b[l + j * LD];
        mag += fabs(alpha * ail * b[l + j * LD]);
      }
      const double want = alpha * sum + beta * c0[i + j * LD];
      const double e = fabs(got[i + j * LD] - want) / (mag > 0 ? mag : 1);
      if (e > worst) worst = e;
    }
  return worst;
}

int main(void) {
  static double a[LD * LD], b[LD * N], c0[LD * N], c[LD * N];
  unsigned seed = 12345;
  for (int i = 0; i < LD * LD; ++i) a[i] = (seed = seed * 1103515245u + 12345u) / 4294967296.0 - 0.5;
  for (int i = 0; i < LD * N; ++i) b[i] = (seed = seed * 1103515245u + 12345u) / 4294967296.0 - 0.5;
  for (int i = 0; i < LD * N; ++i) c0[i] = (seed = seed * 1103515245u + 12345u) / 4294967296.0;

  /* the process's dgemm_ is libsoftpack's */
  Dl_info where;
  void *f = dlsym(RTLD_DEFAULT, "dgemm_");
  CHECK(f && dladdr(f, &where) && where.dli_fname && strstr(where.dli_fname, "libsoftpack"),
        "dgemm_ resolves to %s, want libsoftpack's", f && where.dli_fname ? where.dli_fname : "?");
  CHECK(sp_solver_gemm_forward() == 1, "forwarding is off without SOFTPACK_GEMM_FORWARD=0");

  const int ld = LD;
  const double alpha = -1.5, beta = 0.75;
  const char trans[2] = {'N', 'T'};
  for (int t = 0; t < 2; ++t)
    for (int n = 1; n <= N; ++n) {
      const int m = M, k = K;
      memcpy(c, c0, sizeof c);
      dgemm_(&trans[t], "N", &m, &n, &k, &alpha, a, &ld, b, &ld, &beta, c, &ld, 1, 1);
      const double e = worst_error(trans[t], m, n, k, alpha, a, b, beta, c0, c);
      printf("op(A) = %s, %d column(s): largest relative error %.2e\n", t ? "A^T" : "A", n, e);
      CHECK(e <= 1e-14, "op %c, n = %d: error %.3g", trans[t], n, e);
      /* the columns of C past n untouched */
      for (int j = n; j < N; ++j)
        for (int i = 0; i < M; ++i)
          CHECK(c[i + j * LD] == c0[i + j * LD], "column %d of C changed", j);
    }
  /* an empty A: C = beta C */
  const int one = 1, zero = 0, m = M;
  memcpy(c, c0, sizeof c);
  dgemm_("N", "N", &m, &one, &zero, &alpha, a, &ld, b, &ld, &beta, c, &ld, 1, 1);
  for (int i = 0; i < M; ++i)
    CHECK(c[i] == beta * c0[i], "k = 0: C[%d] = %g, want beta C = %g", i, c[i], beta * c0[i]);
  TEST_DONE();
}
