/**
 * @file agree.h
 * @brief Errors every MPI rank agrees on, and MPI return codes checked.
 *
 * A rank-local failure (an allocation, a file one rank cannot write) must
 * not leave the other ranks waiting in the next collective. The rule the
 * core follows (docs/robustness.md, "MPI failures"): before every call into
 * a collective, the ranks agree on their codes (sp_agree), and a run ends
 * with one more agreement unless its error was agreed already. A failing
 * rank returns straight to that last agreement, which meets the other
 * ranks' next one, so every rank returns the error with a message.
 */
#ifndef SP_AGREE_H
#define SP_AGREE_H

#include <mpi.h>

#include "public/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Record SP_ERR_MPI for the MPI call @p call that returned
 *         @p mpi_code (MPI's own text in the message) and return it. */
int sp_mpi_error(int mpi_code, const char *call);

/** Return SP_ERR_MPI with MPI's message unless the MPI call @p expr
 *  succeeds (the communicator must have MPI_ERRORS_RETURN for a code to
 *  come back at all; with MPI's default handler an error aborts the job). */
#define SP_MPI_CALL(expr)                                                      \
  do {                                                                         \
    const int sp_mpi_rc_ = (expr);                                             \
    if (sp_mpi_rc_ != MPI_SUCCESS) return sp_mpi_error(sp_mpi_rc_, #expr);     \
  } while (0)

/**
 * @brief A communicator for agreements: a duplicate of @p comm whose MPI
 *        errors return codes (MPI_ERRORS_RETURN). Collective.
 * @param[out] out free it with sp_agree_comm_free
 */
int sp_agree_comm_create(MPI_Comm comm, MPI_Comm *out);

/** @brief Free a communicator of sp_agree_comm_create (MPI_COMM_NULL after). */
void sp_agree_comm_free(MPI_Comm *comm);

/**
 * @brief Collective: every rank of @p comm passes its code @p rc.
 * @return SP_OK on every rank if every rank passed SP_OK. Otherwise a rank
 *         that failed keeps its code and message; every other rank gets the
 *         code and message of the lowest failing rank ("on rank R of P:
 *         ..."). Either way the error is marked agreed (sp_error_agreed).
 *         An error already agreed is returned at once, without
 *         communicating: every rank knows it and agrees no more.
 */
int sp_agree(MPI_Comm comm, int rc);

/**
 * @brief Collective: sp_agree(comm, SP_OK), then @p flag becomes 1 on every
 *        rank if it is non-zero on any (e.g. a callback's "stop").
 * @return SP_OK, or the agreed error (@p flag unchanged)
 */
int sp_agree_any(MPI_Comm comm, int *flag);

#ifdef __cplusplus
}
#endif
#endif
