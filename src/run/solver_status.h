/**
 * @file solver_status.h
 * @brief The glue's error classes (sp_solver_status, c_api/softpack_solver.h)
 *        as the core's error codes, so that only bad input exits with 2.
 */
#ifndef SP_SOLVER_STATUS_H
#define SP_SOLVER_STATUS_H

#include "public/error.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The sp_error_code of a glue status: input, memory, solver, MPI
 *         and internal map to their codes, anything unknown to internal. */
int sp_error_code_of_solver(int status);

/**
 * @brief Record a failed call into the glue: the message @p fmt (printf
 *        format: what the core was doing) followed by ": " and the glue's
 *        message, under the code of @p status.
 * @return that code
 */
int sp_solver_failed(sp_solver solver, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#ifdef __cplusplus
}
#endif
#endif
