/* Minimal assertions for ctest programs: a failed check prints what and
 * where and makes the program exit 1 at the end (all checks still run). */
#ifndef SP_TEST_CHECK_H
#define SP_TEST_CHECK_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int sp_test_failures = 0;

#define CHECK(cond, ...)                                                       \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                            \
      fprintf(stderr, "\n");                                                   \
      ++sp_test_failures;                                                      \
    }                                                                          \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                  \
  CHECK(fabs((double)(a) - (double)(b)) <= (tol), "%s = %.15g, %s = %.15g, "   \
        "|diff| = %.3g > %.3g", #a, (double)(a), #b, (double)(b),              \
        fabs((double)(a) - (double)(b)), (double)(tol))

#define CHECK_OK(expr)                                                         \
  do {                                                                         \
    int check_rc_ = (expr);                                                    \
    if (check_rc_ != 0) {                                                      \
      fprintf(stderr, "%s:%d: %s returned %d: %s\n", __FILE__, __LINE__,       \
              #expr, check_rc_, sp_error_message());                           \
      exit(1);                                                                 \
    }                                                                          \
  } while (0)

#define TEST_DONE()                                                            \
  do {                                                                         \
    if (sp_test_failures) fprintf(stderr, "%d check(s) failed\n",             \
                                  sp_test_failures);                           \
    else printf("all checks passed\n");                                        \
    return sp_test_failures ? 1 : 0;                                           \
  } while (0)
#endif
