/**
 * @file run_energy.h
 * @brief What is computed from the run's state alone: its field energy (the
 *        events compare it across a support change, the monitor writes it)
 *        and its cells' observables (set-up, step, events).
 */
#ifndef SP_RUN_ENERGY_H
#define SP_RUN_ENERGY_H

#include "run/run_state.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The sum of the field energy's parts (without the shape term;
 *         with adhesion). */
double sp_energy_fields(const sp_energy_parts *parts);

/** @brief The field energy of the run's state (collective: agreed first). */
int sp_run_energy(sp_run *run, sp_energy_parts *parts);

/** @brief The observables of the run's cells in its state (with the
 *         observables' threshold, division.observe_threshold) into @p obs. */
int sp_run_observe(const sp_run *run, sp_cell_obs *obs);

#ifdef __cplusplus
}
#endif
#endif
