#include "run/solver_status.h"

#include <stdarg.h>
#include <stdio.h>

int sp_error_code_of_solver(int status) {
  switch (status) {
    case SP_SOLVER_OK: return SP_OK;
    case SP_SOLVER_ERR_INPUT: return SP_ERR_INPUT;
    case SP_SOLVER_ERR_MEMORY: return SP_ERR_MEMORY;
    case SP_SOLVER_ERR_SOLVER: return SP_ERR_SOLVER;
    case SP_SOLVER_ERR_MPI: return SP_ERR_MPI;
    default: return SP_ERR_INTERNAL;
  }
}

int sp_solver_failed(sp_solver solver, int status, const char *fmt, ...) {
  char what[512];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(what, sizeof what, fmt, ap);
  va_end(ap);
  return sp_error_set(sp_error_code_of_solver(status), "%s: %s", what,
                      sp_solver_last_error(solver));
}
