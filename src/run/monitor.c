/* What the run reports (monitor.h). */
#include "run/monitor.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/agree.h"
#include "run/checkpoint.h"
#include "public/error.h"
#include "base/fault.h"
#include "io/output.h"
#include "mesh/partition.h"
#include "io/render.h"
#include "run/stop.h"
#include "run/run_energy.h"
#include "base/wall_clock.h"
#include "model/shape.h"
#include "run/solver_status.h"

/** Grow a double array of *n entries by one, appending @p x. */
static int append(double **array, int *n, double x) {
  double *p = realloc(*array, sizeof(double) * ((size_t)*n + 1));
  SP_CHECK(p, SP_ERR_MEMORY, "out of memory for the energy history");
  p[(*n)++] = x;
  *array = p;
  return SP_OK;
}

/** The contacts of the current state into mon->contacts (output.contacts):
 *  each rank integrates the elements it assembles, then one reduction.
 *  Collective. */
static int measure_contacts(sp_run *run) {
  int *first_node;
  SP_ALLOC(first_node, (size_t)run->n_ranks + 1);
  sp_partition_ranges(run->layout, run->n_ranks, first_node);
  int rc = sp_contacts_integrate(run->mesh, run->layout, run->state, first_node[run->rank],
                                 first_node[run->rank + 1], run->opt.output.contact_measure,
                                 run->opt.output.contact_level, &run->mon.contacts);
  free(first_node);
  SP_CALL(sp_agree(run->agree_comm, rc)); /* a collective follows */
  return sp_contacts_reduce(run->agree_comm, &run->mon.contacts);
}

/** Energy and observables rows of the current state (the registry's
 *  observables are those of the state: every change of the state refreshes
 *  them). @p known: the field energy of this state if already computed
 *  (NULL: computed here). */
static int record_energy(sp_run *run, double dt, int its, const sp_step_costs *costs,
                         const sp_energy_parts *known) {
  sp_monitor *mon = &run->mon;
  sp_energy_parts parts;
  if (known) parts = *known;
  else SP_CALL(sp_run_energy(run, &parts));
  const int n_cells = run->layout->n_cells;
  const double shape =
      sp_shape_energy(n_cells, run->cells.obs, run->cells.birth, run->opt.terms.shape_delta);
  const double total = sp_energy_fields(&parts) + shape;
  if (mon->n_energy == mon->cap_energy) {
    const int cap = mon->cap_energy ? 2 * mon->cap_energy : 1024;
    double *t_new = realloc(mon->energy_t, cap * sizeof(double));
    SP_CHECK(t_new, SP_ERR_MEMORY, "out of memory for the energy history");
    mon->energy_t = t_new;
    double *e_new = realloc(mon->energy_total, cap * sizeof(double));
    SP_CHECK(e_new, SP_ERR_MEMORY, "out of memory for the energy history");
    mon->energy_total = e_new;
    mon->cap_energy = cap;
  }
  mon->energy_t[mon->n_energy] = run->t;
  mon->energy_total[mon->n_energy++] = total;
  if (run->opt.output.contacts) SP_CALL(measure_contacts(run));
  if (run->rank != 0) return SP_OK;
  SP_CALL(sp_output_energy(mon->output, run->step, run->t, dt, its, n_cells, &parts, shape,
                           costs));
  SP_CALL(sp_output_cells(mon->output, run->step, run->t, n_cells, run->cells.obs,
                          run->cells.name));
  if (!run->opt.output.contacts) return SP_OK;
  return sp_contacts_log_write(&mon->contacts_log, run->step, run->t, &mon->contacts,
                               run->cells.obs, run->opt.output.contact_threshold);
}

/** The cells' names for the fields and pictures: a named scene's, else
 *  NULL (its outputs as they were before names). */
static const sp_cell_name *cell_names(const sp_run *run) {
  return run->lineage.named ? (const sp_cell_name *)run->cells.name : NULL;
}

/** The fields of the state: a piece per rank and the .pvtu by rank 0 under
 *  MPI, else one .vtu. */
static int write_fields(sp_run *run) {
  sp_monitor *mon = &run->mon;
  if (run->n_ranks > 1) {
    int *first_node;
    SP_ALLOC(first_node, (size_t)run->n_ranks + 1);
    sp_partition_ranges(run->layout, run->n_ranks, first_node);
    const int rc = sp_output_fields_piece(mon->out_dir, run->mesh, run->layout, run->state,
                                          run->step, run->t, cell_names(run), run->rank,
                                          first_node[run->rank], first_node[run->rank + 1]);
    free(first_node);
    SP_CALL(rc);
    if (run->rank != 0) return SP_OK;
    return sp_output_fields_pvtu(mon->output, run->layout, run->step, run->t, run->n_ranks);
  }
  return sp_output_fields(mon->output, run->mesh, run->layout, run->state, run->step, run->t,
                          cell_names(run));
}

/** The pictures of the state (output.pictures; rank 0): in 2D
 *  cells_<step>.png, in 3D sections_<step>.png and surfaces_<step>.png,
 *  and with output.contacts contacts_<step>.png. */
static int write_pictures(sp_run *run) {
  sp_monitor *mon = &run->mon;
  const char *dir = sp_output_dir(mon->output);
  const int width = run->opt.output.picture_width;
  char path[4096];
  if (run->mesh->dim == 3) {
    snprintf(path, sizeof path, "%s/sections_%06d.png", dir, run->step);
    SP_CALL(sp_render_sections(run->mesh, run->layout, run->state, run->t, cell_names(run), width,
                               path));
    snprintf(path, sizeof path, "%s/surfaces_%06d.png", dir, run->step);
    SP_CALL(sp_render_surfaces(run->mesh, run->layout, run->state, run->t, cell_names(run), width,
                               path));
  } else {
    snprintf(path, sizeof path, "%s/cells_%06d.png", dir, run->step);
    SP_CALL(sp_render_cells(run->mesh, run->layout, run->state, run->t, cell_names(run), width,
                            path));
  }
  if (!run->opt.output.contacts) return SP_OK;
  snprintf(path, sizeof path, "%s/contacts_%06d.png", dir, run->step);
  return sp_contacts_picture(&mon->contacts, run->mesh, run->cells.obs,
                             run->opt.output.contact_threshold, run->t, width, path);
}

/** The fields of the state, its pictures (output.pictures)
 *  and energy.png. */
static int write_snapshot(sp_run *run) {
  sp_monitor *mon = &run->mon;
  SP_CALL(sp_fault_check(SP_FAULT_OUTPUT, run->rank));
  SP_CALL(write_fields(run));
  if (run->rank != 0) return SP_OK;
  if (run->opt.output.pictures) SP_CALL(write_pictures(run));
  char path[4096];
  snprintf(path, sizeof path, "%s/energy.png", sp_output_dir(mon->output));
  return sp_render_energy(mon->energy_t, mon->energy_total, mon->n_energy, mon->division_t,
                          mon->n_divisions, path);
}

/** The run ends with the error @p rc of a step that gave up: the last good
 *  state written, and the message says so (or why it could not be). */
static int write_last_state(sp_run *run, int rc) {
  char why[1024];
  snprintf(why, sizeof why, "%s", sp_error_message());
  if (write_snapshot(run) == SP_OK)
    return sp_error_set(rc, "%s. The last good state (t = %.6g) is written.", why, run->t);
  return sp_error_set(rc, "%s. Writing the last good state (t = %.6g) failed: %s", why, run->t,
                      sp_error_message());
}

/** What the scene adds to the logs (output.h). */
static int output_flags(const sp_run *run) {
  return (run->lineage.named ? SP_OUTPUT_NAMED : 0) |
         (sp_adhesion_on(&run->opt.adhesion) ? SP_OUTPUT_ADHESION : 0);
}

int sp_monitor_open(sp_run *run) {
  sp_monitor *mon = &run->mon;
  int rc = SP_OK;
  if (run->rank == 0) {
    if (run->restarted) { /* the logs cut back to the checkpoint's step */
      sp_checkpoint_remove_after(mon->out_dir, run->step);
      rc = sp_output_resume(mon->out_dir, run->mesh->dim, run->step, output_flags(run),
                            mon->n_fields, mon->fields, &mon->output);
    } else {
      rc = sp_output_open_dim(mon->out_dir, run->mesh->dim, output_flags(run), &mon->output);
    }
    if (rc == SP_OK)
      rc = sp_output_units_write(mon->out_dir, run->mesh->dim, &run->opt.output.units);
    if (rc == SP_OK && run->opt.output.contacts)
      rc = sp_contacts_log_open(mon->out_dir, run->restarted ? run->step : -1,
                                &mon->contacts_log);
  }
  free(mon->fields);
  mon->fields = NULL;
  mon->n_fields = 0;
  return rc;
}

int sp_monitor_begin(sp_run *run) {
  sp_monitor *mon = &run->mon;
  mon->costs = (sp_step_costs){0};
  mon->step_start = -1;
  if (run->restarted) return SP_OK; /* the counters came from the checkpoint */
  mon->sum->dt_smallest = run->opt.time.adaptive ? run->opt.time.dt.dt_max : run->opt.time.dt.dt;
  SP_CALL(record_energy(run, 0.0, 0, NULL, NULL));
  return write_snapshot(run);
}

/** Report a failed attempt (Newton failed, its error estimate was too
 *  large, or it is redone to land) on stderr: no silent retries. */
static void report_failure(const sp_run *run, const sp_step_attempt *a) {
  if (run->rank != 0) return;
  if (isatty(fileno(stderr))) fputs("\r\033[K", stderr); /* above a progress line */
  fprintf(stderr, "softpack: step %d at t = %.6g, dt = %.3g: %s", run->step + 1, run->t, a->dt,
          a->why);
  if (a->err < 0 && a->report.reason[0]) {
    fprintf(stderr, "; |F|:");
    for (int i = 0; i < a->report.n_residuals; ++i)
      fprintf(stderr, " %.2e", a->report.residual_norms[i]);
  }
  if (a->give_up) fprintf(stderr, "; no retry\n");
  else fprintf(stderr, "; retried with dt = %.3g\n", run->dtc.dt_next);
}

/** The attempt @p a, not accepted, as data (sp_step_info.attempts). */
static int record_attempt(sp_monitor *mon, const sp_step_attempt *a, double dt_next) {
  const int i = mon->costs.failed_attempts;
  if (i == mon->cap_attempts) {
    const int cap = 2 * mon->cap_attempts + 4;
    sp_attempt *grown = realloc(mon->attempts, sizeof *grown * (size_t)cap);
    SP_CHECK(grown, SP_ERR_MEMORY, "out of memory");
    mon->attempts = grown;
    mon->cap_attempts = cap;
  }
  static const int why[] = {[SP_STEP_NEWTON_FAILED] = SP_ATTEMPT_NEWTON,
                            [SP_STEP_ERROR_TOO_LARGE] = SP_ATTEMPT_ERROR,
                            [SP_STEP_LANDING] = SP_ATTEMPT_LANDING};
  sp_attempt *r = &mon->attempts[i];
  *r = (sp_attempt){.dt = a->dt, .why = why[a->verdict],
                    .newton = a->verdict == SP_STEP_NEWTON_FAILED ? a->report.failure : 0,
                    .newton_its = a->report.newton_its,
                    .factorisations = a->report.factorisations,
                    .n_residuals = a->report.n_residuals,
                    .error_estimate = a->verdict == SP_STEP_ERROR_TOO_LARGE ? a->err : -1.0,
                    .dt_next = dt_next};
  memcpy(r->residual_norms, a->report.residual_norms, sizeof r->residual_norms);
  ++mon->costs.failed_attempts;
  return SP_OK;
}

int sp_monitor_attempt(sp_run *run, const sp_step_attempt *a, int rc) {
  sp_monitor *mon = &run->mon;
  sp_run_summary *sum = mon->sum;
  sp_step_costs *costs = &mon->costs;
  if (mon->step_start < 0) mon->step_start = a->wall_start; /* the step's first attempt */
  const long unknowns = 2 * (long)run->layout->n_pairs;
  if (unknowns > sum->unknowns_max) sum->unknowns_max = unknowns;
  costs->unknowns = unknowns; /* of the attempt that is accepted */
  sum->t_assembly += a->report.t_assembly;
  sum->t_factor += a->report.t_factor;
  sum->t_solve += a->report.t_solve;
  costs->assembly += a->report.t_assembly;
  costs->factorisation += a->report.t_factor;
  costs->solves += a->report.t_solve;
  if ((rc != SP_OK && !a->give_up) || a->verdict == SP_STEP_ACCEPTED ||
      a->verdict == SP_STEP_INTERRUPTED)
    return rc;
  SP_CALL(record_attempt(mon, a, run->dtc.dt_next));
  ++sum->failed_attempts;
  costs->failed_factorisations += a->report.factorisations;
  sum->failed_factorisations += a->report.factorisations;
  report_failure(run, a);
  return a->give_up ? write_last_state(run, rc) : SP_OK;
}

/** The divisions of the step: their rows of divisions.csv, their times on
 *  energy.png. */
static int record_divisions(sp_run *run, const sp_step_events *ev) {
  sp_monitor *mon = &run->mon;
  for (int i = 0; i < ev->n_divided; ++i) {
    const sp_division_record *d = &ev->divisions[i];
    SP_CALL(append(&mon->division_t, &mon->n_divisions, run->t));
    if (run->rank == 0)
      SP_CALL(sp_output_division(mon->output, run->t, run->step, d));
  }
  return SP_OK;
}

/** The counters and costs of the accepted step @p a and its events. */
static void count_step(sp_run *run, const sp_step_attempt *a, const sp_step_events *ev) {
  sp_run_summary *sum = run->mon.sum;
  sp_step_costs *costs = &run->mon.costs;
  const sp_step_report *r = &a->report;
  costs->error_estimate = a->err;
  sum->steps = run->step;
  sum->newton_its += r->newton_its;
  sum->factorisations += r->factorisations;
  costs->factorisations = r->factorisations;
  sum->linear_its += r->linear_its;
  costs->linear_its = r->linear_its;
  costs->residual_rise = 0;
  for (int i = 1; i < r->n_residuals; ++i)
    costs->residual_rise = fmax(costs->residual_rise, r->residual_norms[i] / r->residual_norms[0]);
  sum->t_final = run->t;
  if (a->dt < sum->dt_smallest) sum->dt_smallest = a->dt;
  if (ev->support_changed) {
    sum->layout_changes += 1;
    if (ev->mass_correction > sum->support_mass_correction)
      sum->support_mass_correction = ev->mass_correction;
    sum->support_mass_dropped += ev->mass_dropped;
    if (ev->energy_rise > sum->support_energy_rise) sum->support_energy_rise = ev->energy_rise;
    sum->t_layout += ev->t_supports;
    costs->supports = ev->t_supports;
    costs->support_changed = 1;
  }
  sum->divisions += ev->n_divided;
  costs->step = sp_wall_clock() - run->mon.step_start;
  if (!run->opt.output.timings) /* logs that compare byte for byte */
    costs->step = costs->assembly = costs->factorisation = costs->solves = costs->supports = 0;
}

/** The step in progress is over (accepted or dropped): its costs and its
 *  first attempt's clock start afresh. */
static void forget_step(sp_monitor *mon) {
  mon->costs = (sp_step_costs){0};
  mon->step_start = -1;
}

/** After an accepted step: write a checkpoint if one is due (every
 *  output.checkpoint_every steps, output.checkpoint_seconds since the last)
 *  or a stop was requested on any rank (*signalled = 1). All ranks decide
 *  alike; rank 0 writes. */
static int checkpoint_if_due(sp_run *run, int *signalled) {
  sp_monitor *mon = &run->mon;
  int due;
  SP_CALL(sp_events_checkpoint_due(run, &due, signalled));
  const int want_stop = *signalled;
  if (!due) return SP_OK;
  char path[4096] = "";
  const double t0 = sp_wall_clock();
  int rc = SP_OK;
  if (run->rank == 0) rc = sp_checkpoint_write(run, mon->out_dir, path, sizeof path);
  mon->sum->t_checkpoints += sp_wall_clock() - t0;
  ++mon->sum->checkpoints;
  SP_CALL(sp_agree(run->agree_comm, rc)); /* every rank learns whether it was written */
  mon->t_checkpoint = sp_wall_clock();
  /* a request is forgotten once acted on, not when a run starts: one that
   * came while the scene was read still stops this run */
  if (want_stop) sp_stop_clear();
  /* (the run goes on as if none was written: a run continued from it
   * rebuilds the factorisation this one carries, from /carry) */
  if (want_stop && run->rank == 0) {
    if (isatty(fileno(stderr))) fputs("\r\033[K", stderr);
    fprintf(stderr, "softpack: stopped on a signal after step %d (t = %.6g): checkpoint %s\n",
            run->step, run->t, path);
  }
  return SP_OK;
}

/** The user's callback after the accepted step @p a; *stop = 1 if it
 *  asks to stop on any rank. */
static int call_back(sp_run *run, const sp_step_attempt *a, int failed, int ends, int *stop) {
  sp_monitor *mon = &run->mon;
  const sp_step_info info = {.step = run->step, .t = run->t, .dt = a->dt,
                             .t_end = run->opt.time.t_end, .n_cells = run->layout->n_cells,
                             .newton_its = a->report.newton_its, .failed_attempts = failed,
                             .attempts = mon->attempts, .error_estimate = a->err,
                             .cells = run->cells.obs,
                             .wall_seconds = sp_wall_clock() - mon->t_start, .last = ends,
                             .dim = run->mesh->dim, .names = (const sp_cell_name *)run->cells.name,
                             .run = run};
  *stop = mon->on_step(&info, mon->on_step_user) != 0;
  SP_CALL(sp_agree_any(run->agree_comm, stop)); /* any rank's stop stops every rank */
  mon->sum->stopped = *stop ? SP_STOPPED_CALLBACK : 0;
  return SP_OK;
}

int sp_monitor_step(sp_run *run, const sp_step_attempt *a, const sp_step_events *ev, int *stop) {
  sp_monitor *mon = &run->mon;
  *stop = 0;
  SP_CALL(record_divisions(run, ev));
  count_step(run, a, ev);
  const int failed = mon->costs.failed_attempts;
  /* the state is the one the support change left, if there was one */
  const int rc_row = record_energy(run, a->dt, a->report.newton_its, &mon->costs,
                                   ev->have_energy ? &ev->energy : NULL);
  forget_step(mon);
  SP_CALL(rc_row);
  const int ends = sp_step_run_ends(run);
  if (mon->on_step) SP_CALL(call_back(run, a, failed, ends, stop));
  int rc = SP_OK;
  if (run->step % run->opt.output.every == 0 || ends || *stop || ev->n_divided ||
      (a->lands && sp_events_on_output_time(run, run->t)))
    rc = write_snapshot(run);
  SP_CALL(sp_agree(run->agree_comm, rc)); /* the output's errors, before collectives */
  if (ends) return SP_OK;
  int signalled = 0; /* checkpoints: due, or a signal asked for one */
  SP_CALL(checkpoint_if_due(run, &signalled));
  if (signalled) {
    mon->sum->stopped = SP_STOPPED_SIGNAL;
    *stop = 1;
  }
  return SP_OK;
}

int sp_monitor_interrupted(sp_run *run, int *stop) {
  if (run->rank == 0) {
    if (isatty(fileno(stderr))) fputs("\r\033[K", stderr);
    fprintf(stderr, "softpack: a stop was requested during step %d: the step is dropped\n",
            run->step + 1);
  }
  forget_step(&run->mon);
  int signalled = 0;
  SP_CALL(checkpoint_if_due(run, &signalled));
  run->mon.sum->stopped = SP_STOPPED_SIGNAL;
  *stop = 1;
  return SP_OK;
}

void sp_monitor_end(sp_run *run) {
  if (run->layout) run->mon.sum->n_cells = run->layout->n_cells;
}

void sp_monitor_free(sp_monitor *mon) {
  sp_output_close(&mon->output);
  sp_contacts_log_close(&mon->contacts_log);
  sp_contacts_clear(&mon->contacts);
  free(mon->energy_t);
  free(mon->energy_total);
  free(mon->division_t);
  free(mon->attempts);
  free(mon->fields);
  mon->energy_t = mon->energy_total = mon->division_t = NULL;
  mon->attempts = NULL;
  mon->fields = NULL;
}
