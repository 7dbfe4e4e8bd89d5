/**
 * @file stop.h
 * @brief A stop asked of the run: set asynchronously (softpack run's signal
 *        thread on SIGTERM, SIGINT, SIGUSR1, through sp_run_request_stop;
 *        or the test hook SOFTPACK_FAULT=interrupt:..., fault.h), polled by
 *        Newton during a step (the step is dropped, step.c), acted on by
 *        the monitor after a step or a dropped one (a checkpoint, status 75:
 *        docs/restart.md).
 */
#ifndef SP_STOP_H
#define SP_STOP_H

#include "run/run_state.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Ask for a stop (async-signal-safe). The request stands until a
 *         run acts on it (sp_stop_clear). */
void sp_stop_request(void);

/** @brief This rank's request: 1 if one stands. */
int sp_stop_requested(void);

/** @brief Forget the request (a run acted on it). */
void sp_stop_clear(void);

/**
 * @brief Newton's poll before each iteration of a step (sp_step_data.interrupt,
 *        @p run the sp_run): 1 if a stop stands on any rank (agreed:
 *        collective; an MPI failure also answers 1). Counts the attempt's
 *        polls, and at the second (after the first iteration) makes the
 *        request that SOFTPACK_FAULT=interrupt:RANK:STEP[:ATTEMPT] asks for.
 */
int sp_stop_poll(void *run);

#ifdef __cplusplus
}
#endif
#endif
