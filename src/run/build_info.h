/**
 * @file build_info.h
 * @brief What this libsoftpack is and what it was built with: its version,
 *        build type, Trilinos, the linear solvers it serves, and the BLAS
 *        and MPI it runs with (`softpack info`).
 */
#ifndef SP_BUILD_INFO_H
#define SP_BUILD_INFO_H

#include <mpi.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The library's version, the project version ("0.1"). */
const char *sp_version(void);

/** @brief The CMake build type the library was compiled in ("Release"). */
const char *sp_build_type(void);

/**
 * @brief Print the build type, the Trilinos version, each linear solver
 *        (solver.linear) with the library serving it or "not in this
 *        build", the BLAS in use, the MPI library and the size of @p comm,
 *        one fact per line.
 * @param[in] out where to print (call on one rank)
 * @param[in] comm the communicator whose size is reported
 */
void sp_build_info_print(FILE *out, MPI_Comm comm);

#ifdef __cplusplus
}
#endif
#endif
