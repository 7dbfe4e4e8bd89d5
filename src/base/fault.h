/**
 * @file fault.h
 * @brief The fault hook: make one rank fail on purpose, to test that a
 *        failure on any rank ends every rank with its message.
 *
 * Always compiled, inert unless the environment variable SOFTPACK_FAULT is
 * set (one getenv per hook passed):
 *
 *     SOFTPACK_FAULT=PHASE:RANK[:kill]
 *
 * PHASE is where rank RANK (of the run's communicator) fails:
 *  - setup:  at set-up, after the mesh, before the solver (SP_ERR_MEMORY,
 *            as if an allocation had failed);
 *  - solver: in the glue's sp_solver_create (a solver error, class
 *            SP_SOLVER_ERR_SOLVER);
 *  - step:   before every Newton solve (SP_ERR_MEMORY);
 *  - output: at every field snapshot, step 0's included (SP_ERR_IO);
 *  - assembly: in the glue's residual fill (its element loop, before the
 *            fill's collective: a memory error on that rank, the other
 *            ranks told before the collective, cxx_glue/base/errors.hpp);
 *  - attach: where the glue takes a new layout (sp_solver_set_problem,
 *            before its node map's collective: a memory error, likewise);
 *  - factor: each factorisation of the Jacobian on that rank reports
 *            that it could not allocate its factors, as MUMPS's INFOG(1)
 *            = -13 (the step is not retried: docs/robustness.md).
 * With ":kill" the rank sends itself SIGKILL there instead (not for
 * solver). And SOFTPACK_FAULT=interrupt:RANK:STEP[:ATTEMPT]: rank RANK is
 * asked to stop (as by SIGTERM) during step STEP, after the first Newton
 * iteration of the step's attempt ATTEMPT (1 if not given; the first,
 * then each retry after a rejection), sp_fault_interrupt_due: a stop
 * during a long step, docs/restart.md.
 * Anything else in SOFTPACK_FAULT is bad input at set-up.
 * docs/robustness.md, "MPI failures".
 */
#ifndef SP_FAULT_H
#define SP_FAULT_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  SP_FAULT_SETUP = 0,
  SP_FAULT_SOLVER = 1,
  SP_FAULT_STEP = 2,
  SP_FAULT_OUTPUT = 3,
  SP_FAULT_ASSEMBLY = 4,
  SP_FAULT_ATTACH = 5,
  SP_FAULT_INTERRUPT = 6,
  SP_FAULT_FACTOR = 7
} sp_fault_phase;

/** @brief 1 if SOFTPACK_FAULT asks @p rank to fail at @p phase (a ":kill"
 *         fault kills the process here and does not return), else 0. */
int sp_fault_due(sp_fault_phase phase, int rank);

/** @brief 1 if SOFTPACK_FAULT=interrupt:RANK:STEP[:ATTEMPT] names @p rank,
 *         @p step and @p attempt (1, 2, ...). */
int sp_fault_interrupt_due(int rank, int step, int attempt);

/** @brief An attempt at step @p step (1, 2, ...) begins: the first of its
 *         step, or a retry (the interrupt fault's ATTEMPT counts them). */
void sp_fault_attempt_begin(int step, int first_of_step);

/** @brief A stop poll of the attempt in progress (after each Newton
 *         iteration): 1 at its second poll, the first one after an
 *         iteration, if SOFTPACK_FAULT=interrupt names @p rank, the step
 *         and the attempt. */
int sp_fault_interrupt_poll(int rank);

/**
 * @brief SP_OK, or the error a fault at @p phase stands for on @p rank
 *        (message naming the phase, the rank and SOFTPACK_FAULT). At
 *        SP_FAULT_SETUP, also SP_ERR_INPUT for a malformed SOFTPACK_FAULT.
 */
int sp_fault_check(sp_fault_phase phase, int rank);

#ifdef __cplusplus
}
#endif
#endif
