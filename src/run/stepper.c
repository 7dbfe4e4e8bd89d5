/* The run (stepper.h): set-up, the time loop, the end. */
#include "run/stepper.h"

#include <math.h>

#include "base/agree.h"
#include "base/resident.h"
#include "public/error.h"
#include "run/events.h"
#include "run/monitor.h"
#include "run/step.h"
#include "base/wall_clock.h"

/** The time loop: attempts until one is accepted, then its completion, its
 *  events and its report, until t_end, time.max_steps or a stop. */
static int run_steps(sp_run *run) {
  sp_step_begin(run);
  int rc = sp_monitor_begin(run), stop = 0;
  while (rc == SP_OK && !stop && !sp_step_run_ends(run)) {
    sp_step_attempt a;
    sp_step_events ev;
    rc = sp_monitor_attempt(run, &a, sp_step_try(run, &a));
    if (rc == SP_OK && a.verdict == SP_STEP_INTERRUPTED) rc = sp_monitor_interrupted(run, &stop);
    if (rc != SP_OK || a.verdict != SP_STEP_ACCEPTED) continue;
    rc = sp_step_complete(run, &a);
    if (rc == SP_OK) rc = sp_events_after_step(run, a.t, &ev);
    if (rc == SP_OK) rc = sp_monitor_step(run, &a, &ev, &stop);
  }
  sp_monitor_end(run);
  return rc;
}

/** The summary's memory per rank and messages per Newton iteration, each
 *  the largest over the ranks (docs/parallel.md, "Memory and messages per
 *  rank"): the core's and the glue's tables and state copies, the matrix,
 *  and the rest of the resident peak above what the process held before
 *  the set-up (@p mb_before). Collective on the agreement communicator. */
static void memory_report(const sp_run *run, double mb_before, sp_run_summary *sum) {
  const double MB = 1048576.0;
  sp_solver_usage u = {0};
  if (run->solver) sp_solver_usage_of(run->solver, &u);
  double v[5] = {(run->bytes_mesh + u.mesh_bytes) / MB, (run->bytes_state + u.state_bytes) / MB,
                 u.matrix_bytes / MB, 0.0, u.newton_its > 0 ? u.sent_bytes / MB / u.newton_its : 0};
  double now, peak;
  if (sp_resident_mb(&now, &peak) == 0) v[3] = fmax(0.0, peak - mb_before - v[0] - v[1] - v[2]);
  MPI_Allreduce(MPI_IN_PLACE, v, 5, MPI_DOUBLE, MPI_MAX, run->agree_comm);
  sum->mb_mesh = v[0];
  sum->mb_state = v[1];
  sum->mb_matrix = v[2];
  sum->mb_solver = v[3];
  sum->mb_sent_per_newton = v[4];
}

int sp_stepper_run_from(const sp_scene *scene, const sp_run_start *start, const char *out_dir,
                        MPI_Comm comm, sp_step_callback on_step, void *user,
                        sp_run_summary *summary) {
  sp_run_summary sum = {0};
  const double t0 = sp_wall_clock();
  double mb_before;
  sp_resident_mb(&mb_before, NULL);
  sp_run run = {.mon = {.sum = &sum, .out_dir = out_dir, .on_step = on_step,
                        .on_step_user = user, .t_start = t0, .t_checkpoint = t0}};
  int rc = sp_run_setup(&run, scene, comm, start);
  /* Only now, with the input known good on every rank, does anything get
   * written (the other ranks write pieces into rank 0's directory). */
  if (rc == SP_OK) rc = sp_monitor_open(&run);
  if (rc == SP_OK) rc = run_steps(&run);
  /* A rank that failed alone meets here the other ranks' next agreement
   * (none without an agreement communicator: its creation failed). */
  if (run.agree_comm != MPI_COMM_NULL) {
    rc = sp_agree(run.agree_comm, rc);
    memory_report(&run, mb_before, &sum);
  }
  sum.wall_seconds = sp_wall_clock() - t0;
  if (summary) *summary = sum;
  sp_run_free(&run);
  return rc;
}

int sp_stepper_run_with(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary) {
  return sp_stepper_run_from(scene, NULL, out_dir, comm, on_step, user, summary);
}

int sp_stepper_run(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                   sp_run_summary *summary) {
  return sp_stepper_run_from(scene, NULL, out_dir, comm, NULL, NULL, summary);
}
