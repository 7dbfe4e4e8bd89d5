/**
 * @file run.h
 * @brief Running a scene from another program: the entry point the
 *        `softpack run` command is a client of.
 *
 *     #include <softpack/run.h>
 *     static int watch(const sp_step_info *s, void *user) {
 *       printf("step %d t = %g, %d cells\n", s->step, s->t, s->n_cells);
 *       return s->n_cells >= 8;          // non-zero: stop after this step
 *     }
 *     ...
 *     MPI_Init(&argc, &argv);
 *     const char *set[] = {"time.t_end=0.01"};
 *     sp_run_summary sum;
 *     int rc = sp_run_file("scene.yaml", 1, set, "out/mine", MPI_COMM_WORLD,
 *                          watch, NULL, &sum);
 *     if (rc != SP_OK) fprintf(stderr, "%s\n", sp_error_message());
 *
 * Every rank of @p comm calls it alike, and every rank returns: a failure
 * on any rank is an error on all of them (agree.h), never a hang. Return
 * codes are sp_error_code (error.h): SP_ERR_INPUT for a bad scene or
 * override (nothing written), SP_ERR_SOLVER when a step failed beyond its
 * retries (the last good state is written) or a solver library failed,
 * others for I/O, memory, MPI and internal errors; the message is
 * sp_error_message() (on a rank that did not fail: "on rank R of P: "
 * and the failing rank's message). The ranks agree over a duplicate of
 * @p comm with MPI_ERRORS_RETURN; @p comm's own error handler is left as
 * it is (with MPI's default, an MPI error inside the solver aborts). The callback (may be NULL) sees every accepted step
 * (run_types.h: sp_step_info, the cells' observables included) and stops the
 * run by returning non-zero (summary->stopped = 1, the state written as at
 * the end).
 */
#ifndef SP_RUN_H
#define SP_RUN_H

#include <mpi.h>
#include <stddef.h>

#include "error.h"
#include "run_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** @brief Run the scene file @p path with @p n_set "section.key=value"
 *         overrides into @p out_dir. @p summary may be NULL. */
int sp_run_file(const char *path, int n_set, const char *const *set, const char *out_dir,
                MPI_Comm comm, sp_step_callback on_step, void *user, sp_run_summary *summary);

/** @brief The same for a scene given as YAML text (@p len bytes; @p name
 *         names it in messages). */
int sp_run_text(const char *name, const char *text, size_t len, int n_set,
                const char *const *set, const char *out_dir, MPI_Comm comm,
                sp_step_callback on_step, void *user, sp_run_summary *summary);

/** How `softpack run` continues a run (docs/restart.md). */
typedef struct {
  const char *checkpoint; /**< --restart FILE: continue from this checkpoint */
  const char *resume_dir; /**< --resume DIR: from DIR's newest valid checkpoint */
  int as_initial;         /**< --restart-as-initial: the checkpoint's fields and
                               cells as a new run's initial state (t = 0) */
} sp_restart;

/**
 * @brief sp_run_file continued from a checkpoint (@p restart NULL or with
 *        neither file nor directory: a new run). The scene (with its
 *        overrides) must be the checkpoint's but for time.t_end,
 *        time.max_steps and output.*, unless as_initial; else
 *        SP_ERR_INPUT naming the first key that differs, nothing written.
 *        Checkpoints of this run are written as the scene says
 *        (output.checkpoint_*) and when sp_run_request_stop is called.
 */
int sp_run_file_restart(const char *path, int n_set, const char *const *set,
                        const char *out_dir, const sp_restart *restart, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary);

/**
 * @brief Ask the run in progress (this process's) to write a checkpoint at
 *        the end of the step in progress and stop there (summary.stopped =
 *        SP_STOPPED_SIGNAL). Async-signal-safe; a request made before a
 *        run starts (while its scene is read) stops that run at its first
 *        step, and is forgotten once acted on. One rank asking stops every
 *        rank. `softpack run` calls it on SIGTERM, SIGINT and SIGUSR1, from
 *        a thread that takes them with sigwait while every other thread
 *        blocks them: a handler that interrupts a library can break it
 *        (Debian's METIS, used by SuperLU_DIST, returns a garbage ordering
 *        when a SIGTERM lands inside it; docs/restart.md). A program of
 *        your own should do the same.
 */
void sp_run_request_stop(void);

/** @brief The library's version, "MAJOR.MINOR" (0.2 here): the soname's. */
const char *sp_version(void);

/**
 * @brief The mesh of the run whose step callback got @p info (valid during
 *        that callback only; the same on every rank: each holds the whole
 *        mesh). Any output pointer may be NULL.
 * @param[out] coords n_nodes x dim coordinates, a node's together
 * @param[out] elements nodes_per_element node ids (0-based) per element:
 *        quadrilaterals in 2D, hexahedra in 3D, in the order of the VTU
 *        files' connectivity
 * @return SP_OK, or SP_ERR_INPUT for an @p info not from a callback
 */
int sp_step_mesh(const sp_step_info *info, int *dim, int *n_nodes, const double **coords,
                 int *n_elements, int *nodes_per_element, const int **elements);

/**
 * @brief Cell @p cell's (0-based) field c after the step of @p info, on
 *        every node of the mesh: @p c gets n_nodes values, 0 on the nodes
 *        outside the cell's support (layout.support: local).
 * @return SP_OK, or SP_ERR_INPUT for a cell out of range or an @p info not
 *         from a callback
 */
int sp_step_cell_field(const sp_step_info *info, int cell, double *c);

#ifdef __cplusplus
}
#endif
#endif
