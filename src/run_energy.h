/**
 * @file run_energy.h
 * @brief The field energy of the run's state (the events compare it across
 *        a support change, the monitor writes it).
 */
#ifndef SP_RUN_ENERGY_H
#define SP_RUN_ENERGY_H

#include "run_state.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief The sum of the field energy's parts (without the shape term). */
double sp_energy_fields(const sp_energy_parts *parts);

/** @brief The field energy of the run's state (collective: agreed first). */
int sp_run_energy(sp_run *run, sp_energy_parts *parts);

#ifdef __cplusplus
}
#endif
#endif
