/**
 * @file monitor.h
 * @brief What the run reports, behind one interface (the role of PETSc's
 *        TSMonitor): the energy and cells rows, divisions.csv, field
 *        snapshots and pictures, the failure lines of rejected attempts,
 *        the costs of each step (energy.csv's columns) summed once into
 *        the run's summary, the user's step callback, and checkpoints
 *        (output.checkpoint_*, or a stop a signal asked for). It sits
 *        above the step and the events and reports what they did
 *        (sp_step_attempt, sp_step_events).
 */
#ifndef SP_MONITOR_H
#define SP_MONITOR_H

#include "run/events.h"
#include "run/run_state.h"
#include "softpack_solver.h"
#include "run/step.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Open the output directory (rank 0): a new one, or for a run
 *         continued from a checkpoint the logs cut back to its step. */
int sp_monitor_open(sp_run *run);

/** @brief Before the first step: the initial state's energy and cells rows
 *         and snapshot (a new run only). */
int sp_monitor_begin(sp_run *run);

/** @brief After every attempt (@p rc: sp_step_try's code): its costs; for
 *         one not accepted, the failure line and the attempt recorded; when
 *         the controller gives up, the last good state written and
 *         SP_ERR_SOLVER returned. */
int sp_monitor_attempt(sp_run *run, const sp_step_attempt *a, int rc);

/** @brief After an accepted step and its events: the divisions' rows, the
 *         counters, the energy
 *         and cells rows, the callback (*stop = 1 if it asks to stop on any
 *         rank), the snapshot when due, a checkpoint when due (*stop = 1 if
 *         a signal asked for one). Collective. */
int sp_monitor_step(sp_run *run, const sp_step_attempt *a, const sp_step_events *ev, int *stop);

/** @brief After an attempt dropped on a stop request (SP_STEP_INTERRUPTED):
 *         the message, a checkpoint of the last accepted step (the one a
 *         stop after that step would have written), *stop = 1. Collective. */
int sp_monitor_interrupted(sp_run *run, int *stop);

/** @brief At the run's end (whatever its code). */
void sp_monitor_end(sp_run *run);

/** @brief Free what the monitor holds (not the summary: the caller's). */
void sp_monitor_free(sp_monitor *mon);

#ifdef __cplusplus
}
#endif
#endif
