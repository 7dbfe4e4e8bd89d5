/**
 * @file events.h
 * @brief The run's events in one place: the times a step must land on
 *        (t_end, output times, age divisions and the lineage table's age
 *        and time divisions), the mass criterion's landing rule inside an
 *        attempt, and what happens after an accepted step: divisions
 *        (algorithm 1; a named cell by its lineage entry, lineage.h), the
 *        local supports' change, the controller's restart after a
 *        division, the source switch.
 */
#ifndef SP_EVENTS_H
#define SP_EVENTS_H

#include "run/run_state.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Adaptive control, mass criterion: a step whose end overshoots a cell's
 *  division mass by more than this (relative) is redone, shortened to the
 *  interpolated crossing (sp_division_crossing_fraction); a landing within
 *  it counts as the crossing (sp_division_params.tolerance). */
#define SP_MASS_LANDING_TOLERANCE 1e-3

/** What the events after a step did (the monitor reports it). */
typedef struct {
  int n_divided;         /**< divisions */
  const sp_division_record *divisions; /**< n_divided of them (the run's scratch) */
  int support_changed;   /**< the local supports were rebuilt */
  double t_supports;     /**< seconds rebuilding them */
  double mass_correction; /**< the largest relative mass change it restored */
  double mass_dropped;   /**< |total after - total before| / total */
  double energy_rise;    /**< relative rise of the field energy (may be < 0) */
  int have_energy;       /**< energy: the field energy of the new state */
  sp_energy_parts energy;
} sp_step_events;

/** @brief The next time a step must land on after @p t: t_end, the next
 *         output time (output.interval), and with adaptive control the
 *         next age division (or a lineage entry's age or time). */
double sp_events_next(const sp_run *run, double t);

/** @brief The first dt of a run from its state: the convexity bound over
 *         the mesh (sp_scheme_first_dt), at most time.dt and time.dt_max, at
 *         least time.dt_min. (After a division the bound is taken over the
 *         daughters' nodes: sp_events_after_step.) */
double sp_events_first_dt(const sp_run *run);

/** @brief 1 if @p t is a multiple of output.interval (to round-off). */
int sp_events_on_output_time(const sp_run *run, double t);

/** @brief Whether a checkpoint is due after the step just completed
 *         (output.checkpoint_every, output.checkpoint_seconds since the
 *         last one, or a stop request: @p signalled), agreed by every
 *         rank. Collective. */
int sp_events_checkpoint_due(const sp_run *run, int *due, int *signalled);

/** @brief Adaptive control, mass criterion, N < N_max: the observables of
 *         the end of the step from @p t of @p dt (the run's state; into
 *         run->cells.obs_new, *observed = 1) and the fraction @p theta of
 *         the step at which the first mass division due in it was reached
 *         when it overshot by more than SP_MASS_LANDING_TOLERANCE; 1
 *         otherwise. */
int sp_events_landing(sp_run *run, double t, double dt, int *observed, double *theta);

/** @brief After the accepted step from @p t_old (completed): every cell
 *         whose criterion was crossed divides, the supports follow the
 *         cells, the controller restarts after divisions (an event: the
 *         history starts over; the first step from the convexity bound
 *         over the daughters' own nodes), the source switches.
 *         Collective. */
int sp_events_after_step(sp_run *run, double t_old, sp_step_events *ev);

#ifdef __cplusplus
}
#endif
#endif
