/**
 * @file monitor.h
 * @brief What the run reports, behind one interface (the role of PETSc's
 *        TSMonitor): the energy and cells rows, divisions.csv, field
 *        snapshots and pictures, the failure lines of rejected attempts,
 *        the costs of each step (energy.csv's columns) summed once into
 *        the run's summary, the user's step callback, and checkpoints
 *        (output.checkpoint_*, or a stop a signal asked for).
 */
#ifndef SP_MONITOR_H
#define SP_MONITOR_H

#include "events.h"
#include "run_state.h"
#include "softpack_solver.h"
#include "step.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Seconds on a monotonic clock. */
double sp_wall_clock(void);

/** @brief The sum of the field energy's parts (without the shape term). */
double sp_energy_fields(const sp_energy_parts *parts);

/** @brief The field energy of the run's state (collective: agreed first). */
int sp_run_energy(sp_run *run, sp_energy_parts *parts);

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

/** @brief A division of @p parent into @p parent and @p child (after the
 *         layout change): its row of divisions.csv and its time on
 *         energy.png. @p parent_mass: the parent's mass before the cut. */
int sp_monitor_division(sp_run *run, int parent, int child, double angle, double parent_mass);

/** @brief After an accepted step and its events: the counters, the energy
 *         and cells rows, the callback (*stop = 1 if it asks to stop on any
 *         rank), the snapshot when due, a checkpoint when due (*stop = 1 if
 *         a signal asked for one). Collective. */
int sp_monitor_step(sp_run *run, const sp_step_attempt *a, const sp_step_events *ev, int *stop);

/** @brief At the run's end (whatever its code). */
void sp_monitor_end(sp_run *run);

/** @brief Free what the monitor holds (not the summary: the caller's). */
void sp_monitor_free(sp_monitor *mon);

/** @brief Forget an earlier sp_run_request_stop (run.h): a new run starts. */
void sp_monitor_clear_stop(void);

#ifdef __cplusplus
}
#endif
#endif
