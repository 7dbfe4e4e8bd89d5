/**
 * @file stepper.h
 * @brief A run of a scene: set up (run_setup.h), the time loop of one-line
 *        calls (step.h: an attempt with a verdict and its completion;
 *        events.h; monitor.h), and the end. The entry points of run.h are
 *        its clients.
 */
#ifndef SP_STEPPER_H
#define SP_STEPPER_H

#include <mpi.h>

#include "run/run_setup.h"
#include "public/run_types.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Run @p scene into @p out_dir, started as @p start says (NULL: the
 *        scene's cells, no scene text saved), with @p on_step (may be NULL)
 *        called after every accepted step with @p user. Everything that can
 *        be checked before the first step (mesh, solver choice) is checked
 *        before @p out_dir is created, so bad input leaves nothing behind.
 * @return SP_OK; SP_ERR_INPUT for bad input; SP_ERR_SOLVER when a step failed
 *         beyond the retries allowed (the last good state is written first)
 */
int sp_stepper_run_from(const sp_scene *scene, const sp_run_start *start, const char *out_dir,
                        MPI_Comm comm, sp_step_callback on_step, void *user,
                        sp_run_summary *summary);

/** @brief sp_stepper_run_from the scene's cells, with @p on_step (may be
 *         NULL). */
int sp_stepper_run_with(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary);

/** @brief sp_stepper_run_from the scene's cells, without a callback. */
int sp_stepper_run(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                   sp_run_summary *summary);

#ifdef __cplusplus
}
#endif
#endif
