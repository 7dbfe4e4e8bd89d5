#include "stepper.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "agree.h"
#include "cells.h"
#include "checkpoint.h"
#include "division.h"
#include "dt_control.h"
#include "error.h"
#include "fault.h"
#include "layout.h"
#include "output.h"
#include "run_setup.h"
#include "partition.h"
#include "render.h"
#include "shape.h"
#include "solver_status.h"
#include "source.h"
#include "support.h"
#include "time_scheme.h"

int sp_mesh_from_scene(const sp_scene *scene, sp_mesh **out) {
  const sp_scene_mesh *m = &scene->mesh;
  if (m->type == SP_MESH_RECTANGLE)
    return sp_mesh_rectangle(m->x0, m->y0, m->x1, m->y1, m->nx, m->ny, out);
  return sp_mesh_ellipse(m->refinements, m->semi_x, m->semi_y, m->buffer_layers,
                         m->buffer_width, out);
}

void sp_solver_options_from_scene(const sp_scene *scene, sp_solver_options *opt) {
  static const int jacobian[] = {SP_SOLVER_JAC_AD, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD};
  static const int linear[] = {SP_SOLVER_SUPERLU, SP_SOLVER_SUPERLU_DIST,
                               SP_SOLVER_MUMPS, SP_SOLVER_KLU2, SP_SOLVER_GMRES_ILU,
                               SP_SOLVER_KLU};
  opt->jacobian = jacobian[scene->solver.jacobian];
  opt->linear = linear[scene->solver.linear];
  opt->newton_rtol = scene->solver.newton_rtol;
  opt->newton_atol = scene->solver.newton_atol;
  opt->newton_max_its = scene->solver.newton_max_its;
  opt->ilu_fill = scene->solver.ilu_fill;
  opt->krylov_tol = scene->solver.krylov_tol;
  opt->jacobian_reuse = scene->solver.jacobian_reuse;
  opt->jacobian_carry = scene->solver.jacobian_carry;
  opt->newton_divergence = scene->solver.newton_divergence;
  opt->ordering = scene->solver.ordering == SP_ORDER_PAIRS ? SP_SOLVER_ORDER_PAIRS
                                                           : SP_SOLVER_ORDER_UNKNOWNS;
  opt->refine = scene->solver.refine;
  opt->line_search = scene->solver.line_search == SP_STEP_BACKTRACK ? SP_SOLVER_STEP_BACKTRACK
                                                                    : SP_SOLVER_STEP_FULL;
}

void sp_model_from_scene(const sp_scene *scene, sp_model_params *model) {
  model->alpha = scene->model.alpha;
  model->kappa = scene->model.kappa;
  model->lambda = scene->model.lambda;
  model->lambda_b = scene->model.lambda_b;
  model->mobility = scene->model.mobility;
}

int sp_solver_attach(sp_solver solver, const sp_mesh *mesh, const sp_layout *layout) {
  const long long nonzeros = sp_layout_nonzeros_bound(layout);
  SP_CHECK(nonzeros <= SP_LAYOUT_MAX_NONZEROS, SP_ERR_MEMORY,
           "layout: %d cells on %d (cell, node) pairs: the Jacobian would hold up to %lld "
           "nonzeros, more than the %lld the solvers' 32-bit offsets count (fewer cells per "
           "node: layout.support: local, a smaller layout.margin)",
           layout->n_cells, layout->n_pairs, nonzeros, SP_LAYOUT_MAX_NONZEROS);
  const int n_ranks = sp_solver_ranks(solver);
  SP_CHECK(n_ranks >= 1, SP_ERR_INTERNAL, "solver setup: the solver has no communicator");
  int *first_node;
  SP_ALLOC(first_node, (size_t)n_ranks + 1);
  sp_partition_ranges(layout, n_ranks, first_node);
  sp_mesh_view mv = {mesh->n_nodes, mesh->n_elems, mesh->xy, mesh->elem, mesh->region};
  const sp_slots *slots; /* the element-slot table: the glue's too */
  const int rc = sp_layout_slots(layout, mesh, &slots);
  if (rc != SP_OK) {
    free(first_node);
    return rc;
  }
  sp_layout_view lv = {layout->n_nodes, layout->n_cells, layout->n_pairs, layout->node_start,
                       layout->pair_cell, first_node, n_ranks, slots->n_slots,
                       slots->elem_start, slots->slot_cell, slots->slot_pair};
  const int status = sp_solver_set_problem(solver, &mv, &lv);
  free(first_node);
  if (status != SP_SOLVER_OK) return sp_solver_failed(solver, status, "solver setup");
  return SP_OK;
}

/** solver.predictor linear: the last increment is scaled by dt / dt_last,
 *  at most this much (algorithm 2's ramp multiplies dt by up to 64). */
#define SP_PREDICTOR_MAX_RATIO 2.0

static double wall_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/** The energy parts of the fields (without the shape term) of the run's state. */
static int state_energy(sp_run *run, sp_energy_parts *parts) {
  SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* a collective follows */
  const int status = sp_solver_energy(run->solver, &run->model, run->state, parts);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "energy");
  return SP_OK;
}

static double field_total(const sp_energy_parts *p) {
  return p->bulk + p->gradient + p->repulsion + p->buffer;
}

/** Energy and observables rows of the current state (run->obs must be the
 *  observables of run->state: every change of the state refreshes them).
 *  @p known: the field energy of this state if already computed (NULL:
 *  computed here). */
static int record_energy(sp_run *run, int step, double t, double dt, int its,
                         const sp_step_costs *seconds, const sp_energy_parts *known) {
  sp_energy_parts parts;
  if (known) parts = *known;
  else SP_CALL(state_energy(run, &parts));
  const double shape = sp_shape_energy(run->layout->n_cells, run->obs, run->birth,
                                       run->scene->shape.delta1, run->scene->shape.delta2);
  const double total = field_total(&parts) + shape;
  if (run->n_energy == run->cap_energy) {
    int cap = run->cap_energy ? 2 * run->cap_energy : 1024;
    double *t_new = realloc(run->energy_t, cap * sizeof(double));
    SP_CHECK(t_new, SP_ERR_MEMORY, "out of memory for the energy history");
    run->energy_t = t_new;
    double *e_new = realloc(run->energy_total, cap * sizeof(double));
    SP_CHECK(e_new, SP_ERR_MEMORY, "out of memory for the energy history");
    run->energy_total = e_new;
    run->cap_energy = cap;
  }
  run->energy_t[run->n_energy] = t;
  run->energy_total[run->n_energy++] = total;
  if (run->rank != 0) return SP_OK;
  SP_CALL(sp_output_energy(run->output, step, t, dt, its, run->layout->n_cells, &parts, shape,
                           seconds));
  SP_CALL(sp_output_cells(run->output, step, t, run->layout->n_cells, run->obs));
  return SP_OK;
}

static int write_snapshot(sp_run *run, int step, double t) {
  SP_CALL(sp_fault_check(SP_FAULT_OUTPUT, run->rank));
  if (run->n_ranks > 1) { /* a piece per rank, the .pvtu by rank 0 */
    int *first_node;
    SP_ALLOC(first_node, (size_t)run->n_ranks + 1);
    sp_partition_ranges(run->layout, run->n_ranks, first_node);
    int rc = sp_output_fields_piece(run->out_dir, run->mesh, run->layout, run->state, step, t,
                                    run->rank, first_node[run->rank],
                                    first_node[run->rank + 1]);
    free(first_node);
    SP_CALL(rc);
    if (run->rank != 0) return SP_OK;
    SP_CALL(sp_output_fields_pvtu(run->output, run->layout, step, t, run->n_ranks));
  } else {
    if (run->rank != 0) return SP_OK;
    SP_CALL(sp_output_fields(run->output, run->mesh, run->layout, run->state, step, t));
  }
  char path[4096];
  if (run->scene->output.pictures) {
    snprintf(path, sizeof path, "%s/cells_%06d.png", sp_output_dir(run->output), step);
    SP_CALL(sp_render_cells(run->mesh, run->layout, run->state, t,
                            run->scene->output.picture_width, path));
  }
  snprintf(path, sizeof path, "%s/energy.png", sp_output_dir(run->output));
  return sp_render_energy(run->energy_t, run->energy_total, run->n_energy, run->division_t,
                          run->n_divisions, path);
}

/** Grow a per-cell array to n entries (new entries zeroed). */
static int grow_array(void **ptr, size_t elem, int n_old, int n) {
  void *p = realloc(*ptr, elem * (size_t)n);
  SP_CHECK(p, SP_ERR_MEMORY, "out of memory for %d cells", n);
  memset((char *)p + elem * (size_t)n_old, 0, elem * (size_t)(n - n_old));
  *ptr = p;
  return SP_OK;
}

/** Local supports: recompute every support from the fields (they follow
 *  the cells), keeping each cell's mass exactly. @p after: the field
 *  energy of the new state (for the energy row of the step). */
static int update_supports(sp_run *run, sp_energy_parts *after) {
  const double t0 = wall_clock();
  sp_layout *layout;
  double *state, correction, dropped;
  sp_energy_parts before;
  SP_CALL(state_energy(run, &before));
  const int always = run->scene->layout.shrink == SP_SHRINK_ALWAYS;
  SP_CALL(sp_support_rebuild(run->support, run->layout, run->state,
                             always ? NULL : run->divided_now, &layout, &state, &correction,
                             &dropped));
  memset(run->divided_now, 0, (size_t)run->layout->n_cells);
  SP_CALL(sp_run_adopt_layout(run, layout, state, SP_HISTORY_CARRY));
  SP_CALL(state_energy(run, after));
  SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state,
                           run->scene->division.observe_threshold, run->obs));
  run->sum->layout_changes += 1;
  if (correction > run->sum->support_mass_correction) run->sum->support_mass_correction = correction;
  run->sum->support_mass_dropped += dropped;
  const double e_before = field_total(&before);
  const double rise = (field_total(after) - e_before) / fabs(e_before);
  if (rise > run->sum->support_energy_rise) run->sum->support_energy_rise = rise;
  run->sum->t_layout += wall_clock() - t0;
  return SP_OK;
}

/** The layout after a division: full, or every support as it is plus the
 *  child on the parent's support (the next update tightens both). */
static int layout_with_child(sp_run *run, int parent, sp_layout **out) {
  const int n = run->layout->n_cells, nn = run->mesh->n_nodes;
  if (!run->support) return sp_layout_create_full(nn, n + 1, out);
  return sp_layout_with_child(run->layout, parent, out);
}

/**
 * Divide cell @p parent (paper algorithm 1): a new layout with one more
 * cell, the split state on it, the registry entries of both daughters, a
 * row of divisions.csv.
 */
static int divide_cell(sp_run *run, int parent, double t, int step) {
  const int n = run->layout->n_cells, child = n;
  sp_layout *new_layout = NULL;
  SP_CALL(layout_with_child(run, parent, &new_layout));
  const size_t n_values = 2 * (size_t)new_layout->n_pairs;
  double *new_state = calloc(n_values, sizeof(double));
  if (!new_state) {
    sp_layout_destroy(&new_layout);
    return sp_error_set(SP_ERR_MEMORY, "out of memory dividing cell %d", parent + 1);
  }
  const sp_cell_obs parent_obs = run->obs[parent];
  const int smooth = run->scene->division.cut == SP_CUT_SMOOTH;
  const double width = sp_scene_interface_width(run->scene);
  double offset = 0.0;
  int rc = SP_OK;
  if (run->scene->division.line == SP_LINE_EQUAL_MASS)
    rc = sp_division_balance_offset(run->mesh, run->layout, run->state, parent, &parent_obs,
                                    smooth, width, &offset);
  if (rc == SP_OK)
    rc = sp_division_split(run->mesh, run->layout, run->state, parent, &parent_obs, smooth,
                           width, offset, new_layout, new_state, child);
  if (rc != SP_OK) {
    free(new_state);
    sp_layout_destroy(&new_layout);
    return rc;
  }
  SP_CALL(sp_run_adopt_layout(run, new_layout, new_state, SP_HISTORY_RESET));
  SP_CALL(grow_array((void **)&run->obs, sizeof *run->obs, n, n + 1));
  SP_CALL(grow_array((void **)&run->birth, sizeof *run->birth, n, n + 1));
  SP_CALL(grow_array((void **)&run->source_on, sizeof *run->source_on, n, n + 1));
  SP_CALL(grow_array((void **)&run->division_skipped, sizeof(int), n, n + 1));
  SP_CALL(grow_array((void **)&run->divided_now, 1, n, n + 1));
  run->divided_now[parent] = run->divided_now[child] = 1;
  run->source_on[child] = run->source_on[parent];
  SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state,
                           run->scene->division.observe_threshold, run->obs));
  sp_cell_obs *core = malloc(sizeof *core * (size_t)(n + 1));
  SP_CHECK(core, SP_ERR_MEMORY, "out of memory");
  sp_cells_core_view(run->obs, n + 1, core);
  sp_division_record_births(t, core, parent, child, run->birth);
  free(core);
  double px, py, dx, dy;
  sp_division_axis(&parent_obs, &px, &py, &dx, &dy);
  double angle = atan2(dy, dx);
  if (angle <= -M_PI / 2) angle += M_PI;
  if (angle > M_PI / 2) angle -= M_PI;
  SP_CALL(grow_array((void **)&run->division_t, sizeof(double), run->n_divisions,
                     run->n_divisions + 1));
  run->division_t[run->n_divisions++] = t;
  if (run->rank == 0)
    SP_CALL(sp_output_division(run->output, t, step, parent, child, angle, parent_obs.mass,
                               run->obs[parent].mass, run->obs[child].mass));
  return SP_OK;
}

/** After an accepted step from t_old to t: divide every cell whose
 *  criterion was crossed. Returns the number of divisions in *n_divided. */
static int divide_due_cells(sp_run *run, double t_old, double t, int step,
                            const double *core_mass_old, int *n_divided) {
  *n_divided = 0;
  if (run->scene->division.criterion == SP_DIVIDE_NONE) return SP_OK;
  const int n = run->layout->n_cells; /* daughters born now wait a step */
  for (int k = 0; k < n; ++k) {
    if (!sp_division_due(&run->division, &run->birth[k], t_old, t, core_mass_old[k],
                         run->obs[k].mass_core))
      continue;
    if (run->layout->n_cells >= run->n_max) {
      if (!run->division_skipped[k] && run->rank == 0)
        fprintf(stderr, "softpack: cell %d is due to divide at t = %.6g but N_max = %d cells "
                        "exist already; it does not divide\n", k + 1, t, run->n_max);
      run->division_skipped[k] = 1;
      continue;
    }
    SP_CALL(divide_cell(run, k, t, step));
    ++*n_divided;
  }
  return SP_OK;
}

void sp_dt_params_from_scene(const sp_scene *scene, sp_dt_params *p) {
  const sp_scene_time *tc = &scene->time;
  *p = (sp_dt_params){
      .policy = tc->control == SP_CONTROL_ADAPTIVE ? SP_DT_ADAPTIVE : SP_DT_FIXED,
      .dt = tc->dt, .dt_min = tc->dt_min, .dt_max = tc->dt_max,
      .max_retries = tc->max_retries, .shrink = tc->shrink, .grow = tc->grow,
      .grow_after = tc->grow_after, .failure_memory = tc->failure_memory,
      .ramp_n_div = scene->division.n_div, .ramp_m = scene->division.m,
      .order = tc->scheme == SP_TIME_BDF2 ? 2 : 1};
}

/** The first step from the run's state: the convexity bound
 *  (sp_scheme_first_dt), at most time.dt and time.dt_max. */
static double first_dt(const sp_run *run) {
  const sp_scene_time *tc = &run->scene->time;
  const double dt = sp_scheme_first_dt(run->layout, run->state, &run->model,
                                       fmin(tc->dt, tc->dt_max));
  return fmax(dt, tc->dt_min);
}

/** The next time a step must land on after @p t: t_end, the next output
 *  time (output.interval), and with adaptive control the next age division. */
static double next_event(const sp_run *run, double t) {
  const sp_scene *scene = run->scene;
  const double t_end = scene->time.t_end, slack = 1e-12 * t_end;
  double event = t_end;
  const double every = scene->output.interval;
  if (every > 0) {
    const double k = floor((t + slack) / every) + 1;
    event = fmin(event, k * every);
  }
  if (scene->time.control == SP_CONTROL_ADAPTIVE &&
      scene->division.criterion == SP_DIVIDE_BY_AGE && run->layout->n_cells < run->n_max) {
    for (int k = 0; k < run->layout->n_cells; ++k) {
      const double due = run->birth[k].birth_time + scene->division.t_div;
      if (due > t + slack) event = fmin(event, due);
    }
  }
  return event;
}

/** 1 if @p t is a multiple of output.interval (to round-off). */
static int on_output_time(const sp_scene *scene, double t) {
  const double every = scene->output.interval;
  if (!(every > 0)) return 0;
  const double k = floor(t / every + 0.5);
  return k > 0 && fabs(t - k * every) <= 1e-12 * scene->time.t_end;
}

/** The step's source and shape coefficients from c^n (run->state_old and
 *  run->obs). */
static int explicit_terms(sp_run *run, sp_shape_coef **shape_coef) {
  const int n_cells = run->layout->n_cells;
  if (run->scene->source.rate > 0)
    SP_CALL(sp_source_fill(run->layout, run->state_old, n_cells, run->source_on,
                           run->scene->source.rate, run->source));
  if (!(run->scene->shape.delta1 > 0 || run->scene->shape.delta2 > 0)) return SP_OK;
  /* from the observables of c^n; implicit steps follow the new moments
   * through the gains */
  sp_shape_coef *grown = realloc(*shape_coef, sizeof *grown * (size_t)n_cells);
  SP_CHECK(grown, SP_ERR_MEMORY, "out of memory");
  *shape_coef = grown;
  SP_CALL(sp_shape_coefficients(n_cells, run->obs, run->birth, run->scene->shape.delta1,
                                run->scene->shape.delta2, grown));
  /* the term is the derivative of the moments, which count c only where
   * c >= the observables' threshold: it acts there only */
  for (int k = 0; k < n_cells; ++k) grown[k].threshold = run->scene->division.observe_threshold;
  return SP_OK;
}

/** Report a failed attempt (Newton failed, or its error estimate was too
 *  large) on stderr: no silent retries. */
static void report_failure(const sp_run *run, int step, double t, double dt, const char *why,
                           const sp_step_report *report, int give_up) {
  if (run->rank != 0) return;
  if (isatty(fileno(stderr))) fputs("\r\033[K", stderr); /* above a progress line */
  fprintf(stderr, "softpack: step %d at t = %.6g, dt = %.3g: %s", step + 1, t, dt, why);
  if (report) {
    fprintf(stderr, "; |F|:");
    for (int i = 0; i < report->n_residuals; ++i)
      fprintf(stderr, " %.2e", report->residual_norms[i]);
  }
  if (give_up) fprintf(stderr, "; no retry\n");
  else fprintf(stderr, "; retried with dt = %.3g\n", run->dtc.dt_next);
}

/** The fraction of the step just solved (observables of c^n in run->obs,
 *  of its end in @p obs_new) at which the first mass division due in it was
 *  reached, when the step overshot it by more than
 *  SP_MASS_LANDING_TOLERANCE; 1 otherwise. */
static double mass_crossing(const sp_run *run, double t_old, double t_new,
                            const sp_cell_obs *obs_new) {
  double theta = 1.0;
  for (int k = 0; k < run->layout->n_cells; ++k) {
    const double m_old = run->obs[k].mass_core, m_new = obs_new[k].mass_core;
    if (!sp_division_due(&run->division, &run->birth[k], t_old, t_new, m_old, m_new)) continue;
    const double f = sp_division_crossing_fraction(&run->division, &run->birth[k], t_old, t_new,
                                                   m_old, m_new);
    /* overshot: past the threshold by more than the tolerance */
    const double over = m_new - sp_division_threshold(&run->division, &run->birth[k]) *
                                    (1 + SP_MASS_LANDING_TOLERANCE);
    if (f > 0 && f < 1 && over > 0) theta = fmin(theta, f);
  }
  return theta;
}

/** Set by sp_run_request_stop (a signal handler): checkpoint and stop. */
static volatile sig_atomic_t stop_requested;

void sp_run_request_stop(void) { stop_requested = 1; }

/** After an accepted step: write a checkpoint if one is due (every
 *  output.checkpoint_every steps, output.checkpoint_seconds since the last)
 *  or a stop was requested on any rank (*signalled = 1). All ranks decide
 *  alike; rank 0 writes. */
static int checkpoint_if_due(sp_run *run, int *signalled) {
  const sp_scene_output *o = &run->scene->output;
  /* a signal may reach one rank only, and the clocks differ: agreed */
  int want_stop = stop_requested != 0;
  int want_time = o->checkpoint_seconds > 0 &&
                  wall_clock() - run->t_checkpoint >= o->checkpoint_seconds;
  SP_CALL(sp_agree_any(run->agree_comm, &want_stop));
  SP_CALL(sp_agree_any(run->agree_comm, &want_time));
  *signalled = want_stop;
  if (!(want_stop || want_time ||
        (o->checkpoint_every > 0 && run->step % o->checkpoint_every == 0)))
    return SP_OK;
  char path[4096] = "";
  const double t0 = wall_clock();
  int rc = SP_OK;
  if (run->rank == 0) rc = sp_checkpoint_write(run, run->out_dir, path, sizeof path);
  run->sum->t_checkpoints += wall_clock() - t0;
  ++run->sum->checkpoints;
  SP_CALL(sp_agree(run->agree_comm, rc)); /* every rank learns whether it was written */
  run->t_checkpoint = wall_clock();
  /* (the run goes on as if none was written: a run continued from it
   * rebuilds the factorisation this one carries, from /carry) */
  if (want_stop && run->rank == 0) {
    if (isatty(fileno(stderr))) fputs("\r\033[K", stderr);
    fprintf(stderr, "softpack: stopped on a signal after step %d (t = %.6g): checkpoint %s\n",
            run->step, run->t, path);
  }
  return SP_OK;
}

/** The time loop proper. */
static int run_steps(sp_run *run, sp_run_summary *sum) {
  const sp_scene_time *tc = &run->scene->time;
  const int adaptive = tc->control == SP_CONTROL_ADAPTIVE;
  const sp_scheme_kind scheme = tc->scheme == SP_TIME_BDF2 ? SP_SCHEME_BDF2 : SP_SCHEME_BE;
  const int want_history =
      adaptive || scheme == SP_SCHEME_BDF2 || run->scene->solver.predictor == SP_PREDICT_LINEAR;
  sp_dt_params dtp;
  sp_dt_params_from_scene(run->scene, &dtp);
  double t = run->t;
  int step = run->step;
  if (run->restarted) { /* the controller's state came from the checkpoint */
    run->dtc.p = dtp;
  } else {
    sp_dt_init(&run->dtc, &dtp, first_dt(run));
    sum->dt_smallest = adaptive ? tc->dt_max : tc->dt;
    SP_CALL(record_energy(run, 0, t, 0.0, 0, NULL, NULL));
    SP_CALL(write_snapshot(run, 0, t));
  }
  double *core_mass_old = NULL;
  const double t_tol = 1e-12 * tc->t_end;
  sp_shape_coef *shape_coef = NULL; /* per cell, refreshed before each step */
  sp_cell_obs *obs_new = NULL;      /* adaptive, mass criterion: see mass_crossing */
  sp_step_costs seconds = {0}; /* of the step being attempted */
  sp_attempt *attempts = NULL;  /* its failed attempts (seconds.failed_attempts) */
  int cap_attempts = 0;
  double step_start = -1;
  int rc = SP_OK;
  while (rc == SP_OK && t < tc->t_end - t_tol && step < tc->max_steps) {
    if (step_start < 0) step_start = wall_clock(); /* the first attempt of a step */
    const int n_cells = run->layout->n_cells;
    const size_t n_pairs = (size_t)run->layout->n_pairs, n_values = 2 * n_pairs;
    if ((long)n_values > sum->unknowns_max) sum->unknowns_max = (long)n_values;
    seconds.unknowns = (long)n_values; /* of the attempt that is accepted */
    const double t_event = next_event(run, t);
    int lands;
    const double dt_try = sp_dt_propose(&run->dtc, t, t_event, &lands);
    memcpy(run->state_old, run->state, n_values * sizeof(double));
    if (run->scene->solver.predictor == SP_PREDICT_LINEAR && run->hist.n >= 1) {
      /* Newton starts from the extrapolation */
      const double r = fmin(dt_try / run->hist.dt[0], SP_PREDICTOR_MAX_RATIO);
      const double *prev = run->hist.past[0];
      for (size_t i = 0; i < n_values; ++i)
        run->state[i] = run->state_old[i] + r * (run->state_old[i] - prev[i]);
    }
    rc = explicit_terms(run, &shape_coef);
    if (rc == SP_OK) rc = sp_fault_check(SP_FAULT_STEP, run->rank);
    rc = sp_agree(run->agree_comm, rc); /* Newton's collectives follow */
    if (rc != SP_OK) break;
    const sp_scheme_kind kind = sp_scheme_of_step(scheme, &run->hist);
    double dt_eff = dt_try;
    const double *old_eff = run->state_old;
    if (kind != SP_SCHEME_BE) {
      sp_scheme_be_form(kind, &run->hist, dt_try, run->state_old, n_pairs, run->state_eff,
                        &dt_eff);
      old_eff = run->state_eff;
    }
    sp_step_data data = {.dt = dt_eff, .model = run->model, .state_old = old_eff,
                         .source = run->scene->source.rate > 0 ? run->source : NULL,
                         .shape = shape_coef,
                         .shape_implicit = run->scene->shape.scheme == SP_SHAPE_IMPLICIT};
    if (adaptive) { /* Newton's error: a small part of the step's */
      data.update_rtol = SP_SCHEME_NEWTON_FRACTION * tc->rtol;
      data.update_atol = SP_SCHEME_NEWTON_FRACTION * tc->atol;
    }
    sp_step_report report;
    int solved = sp_solver_step(run->solver, &data, run->state, &report);
    sum->t_assembly += report.t_assembly;
    sum->t_factor += report.t_factor;
    sum->t_solve += report.t_solve;
    seconds.assembly += report.t_assembly;
    seconds.factorisation += report.t_factor;
    seconds.solves += report.t_solve;
    if (solved > SP_SOLVER_NOT_CONVERGED) {
      rc = sp_solver_failed(run->solver, solved, "step %d at t = %g", step + 1, t);
      break;
    }
    double err = -1.0;
    int observed = 0; /* obs_new holds the observables of the step's end */
    const char *why = report.reason;
    char why_error[160];
    int attempt_why = SP_ATTEMPT_NEWTON;
    if (solved == 0 && adaptive) {
      err = sp_scheme_error(kind, &run->hist, dt_try, run->state_old, run->state, n_pairs,
                            tc->rtol, tc->atol, run->scratch);
      snprintf(why_error, sizeof why_error,
               "local error estimate %.3g x the tolerance (time.rtol, time.atol)", err);
      why = why_error;
    }
    int give_up = 0;
    if (solved == 1) give_up = sp_dt_newton_failed(&run->dtc, dt_try);
    else if (sp_dt_judge(&run->dtc, dt_try, err) == SP_DT_REJECT) {
      solved = 1; /* never accepted: retried with a smaller step */
      attempt_why = SP_ATTEMPT_ERROR;
      give_up = sp_dt_give_up(&run->dtc);
    } else if (adaptive && run->scene->division.criterion == SP_DIVIDE_BY_MASS &&
               n_cells < run->n_max) { /* observed here, kept if the step stands */
      sp_cell_obs *grown_obs = realloc(obs_new, sizeof *obs_new * (size_t)n_cells);
      if (!grown_obs) { rc = sp_error_set(SP_ERR_MEMORY, "out of memory"); break; }
      obs_new = grown_obs;
      rc = sp_cells_observe(run->mesh, run->layout, run->state,
                            run->scene->division.observe_threshold, obs_new);
      if (rc != SP_OK) break;
      observed = 1;
      const double theta = mass_crossing(run, t, t + dt_try, obs_new);
      if (theta < 1) { /* land on the crossing: redo the step shorter */
        run->dtc.dt_next = fmax(theta * dt_try, tc->dt_min);
        why = "a cell's mass passed its division mass inside the step (landing on it)";
        err = -1.0;
        solved = 1;
        attempt_why = SP_ATTEMPT_LANDING;
      }
    }
    if (solved == 1) { /* retry from the last good state */
      memcpy(run->state, run->state_old, n_values * sizeof(double));
      if (seconds.failed_attempts == cap_attempts) {
        const int cap = 2 * cap_attempts + 4;
        sp_attempt *grown = realloc(attempts, sizeof *attempts * (size_t)cap);
        if (!grown) { rc = sp_error_set(SP_ERR_MEMORY, "out of memory"); break; }
        attempts = grown;
        cap_attempts = cap;
      }
      sp_attempt *a = &attempts[seconds.failed_attempts];
      *a = (sp_attempt){.dt = dt_try, .why = attempt_why,
                        .newton = attempt_why == SP_ATTEMPT_NEWTON ? report.failure : 0,
                        .newton_its = report.newton_its, .factorisations = report.factorisations,
                        .n_residuals = report.n_residuals,
                        .error_estimate = attempt_why == SP_ATTEMPT_ERROR ? err : -1.0,
                        .dt_next = run->dtc.dt_next};
      memcpy(a->residual_norms, report.residual_norms, sizeof a->residual_norms);
      ++seconds.failed_attempts;
      ++sum->failed_attempts;
      seconds.failed_factorisations += report.factorisations;
      sum->failed_factorisations += report.factorisations;
      report_failure(run, step, t, dt_try, why, err < 0 && report.reason[0] ? &report : NULL,
                     give_up);
      if (give_up) {
        int rc_out = write_snapshot(run, step, t);
        rc = sp_error_set(SP_ERR_SOLVER,
                          "step %d at t = %.6g failed %d attempts "
                          "(last dt = %.3g; time.max_retries = %d, time.dt_min = %.3g): %s. "
                          "The last good state (t = %.6g) is written%s.",
                          step + 1, t, run->dtc.failures, dt_try, tc->max_retries, tc->dt_min,
                          why, t, rc_out == SP_OK ? "" : " (failed: see above)");
      }
      continue;
    }
    const double t_old = t;
    t = lands ? t_event : t + dt_try;
    ++step;
    run->t = t;
    run->step = step;
    sp_dt_accepted(&run->dtc, dt_try, err);
    seconds.error_estimate = err;
    if (want_history) {
      rc = sp_history_push(&run->hist, run->state_old, dt_try, n_values);
      if (rc != SP_OK) break;
    }
    sum->steps = step;
    sum->newton_its += report.newton_its;
    sum->factorisations += report.factorisations;
    seconds.factorisations = report.factorisations;
    sum->linear_its += report.linear_its;
    seconds.linear_its = report.linear_its;
    seconds.residual_rise = 0;
    for (int i = 1; i < report.n_residuals; ++i)
      seconds.residual_rise =
          fmax(seconds.residual_rise, report.residual_norms[i] / report.residual_norms[0]);
    sum->t_final = t;
    if (dt_try < sum->dt_smallest) sum->dt_smallest = dt_try;
    /* the core masses before the step, for crossing-safe criteria */
    double *grown = realloc(core_mass_old, sizeof(double) * (size_t)n_cells);
    if (!grown) { rc = sp_error_set(SP_ERR_MEMORY, "out of memory"); break; }
    core_mass_old = grown;
    for (int k = 0; k < n_cells; ++k) core_mass_old[k] = run->obs[k].mass_core;
    if (observed) memcpy(run->obs, obs_new, sizeof *obs_new * (size_t)n_cells);
    else rc = sp_cells_observe(run->mesh, run->layout, run->state,
                               run->scene->division.observe_threshold, run->obs);
    int n_divided = 0, have_energy = 0;
    sp_energy_parts energy_after_supports;
    if (rc == SP_OK) rc = divide_due_cells(run, t_old, t, step, core_mass_old, &n_divided);
    int outgrown = 0; /* a cell reaches its support's edge */
    if (rc == SP_OK && run->support && !n_divided)
      rc = sp_support_needs_update(run->support, run->layout, run->state, &outgrown);
    if (rc != SP_OK) break;
    if (run->support && (n_divided || outgrown)) {
      const double t_layout = run->sum->t_layout;
      rc = update_supports(run, &energy_after_supports);
      have_energy = rc == SP_OK;
      seconds.supports = run->sum->t_layout - t_layout;
      seconds.support_changed = 1;
    }
    if (rc != SP_OK) break;
    if (n_divided) {
      sum->divisions += n_divided;
      sp_dt_restart(&run->dtc, first_dt(run)); /* algorithm 2, or a new first step */
    }
    if (run->scene->source.rate > 0) {
      double *mass = malloc(sizeof(double) * (size_t)run->layout->n_cells);
      if (!mass) { rc = sp_error_set(SP_ERR_MEMORY, "out of memory"); break; }
      for (int k = 0; k < run->layout->n_cells; ++k) mass[k] = run->obs[k].mass_core;
      rc = sp_source_update_switch(run->layout->n_cells, run->n_max, mass, run->birth,
                                   run->source_on, run->scene->source.off_ratio);
      free(mass);
      if (rc != SP_OK) break;
    }
    const int failed_before = seconds.failed_attempts;
    seconds.step = wall_clock() - step_start;
    if (!run->scene->output.timings) /* logs that compare byte for byte */
      seconds.step = seconds.assembly = seconds.factorisation = seconds.solves =
          seconds.supports = 0;
    /* the state is the one update_supports left, if it ran */
    rc = record_energy(run, step, t, dt_try, report.newton_its, &seconds,
                       have_energy ? &energy_after_supports : NULL);
    seconds = (sp_step_costs){0};
    step_start = -1;
    if (rc != SP_OK) break;
    const int ends = !(t < tc->t_end - t_tol && step < tc->max_steps);
    int stop = 0;
    if (run->on_step) {
      const sp_step_info info = {.step = step, .t = t, .dt = dt_try, .t_end = tc->t_end,
                                 .n_cells = run->layout->n_cells,
                                 .newton_its = report.newton_its,
                                 .failed_attempts = failed_before, .attempts = attempts,
                                 .error_estimate = err, .cells = run->obs,
                                 .wall_seconds = wall_clock() - run->t_start,
                                 .last = ends};
      stop = run->on_step(&info, run->on_step_user) != 0;
      rc = sp_agree_any(run->agree_comm, &stop); /* any rank's stop stops every rank */
      if (rc != SP_OK) break;
      sum->stopped = stop ? SP_STOPPED_CALLBACK : 0;
    }
    if (step % run->scene->output.every == 0 || ends || stop || n_divided ||
        (lands && on_output_time(run->scene, t)))
      rc = write_snapshot(run, step, t);
    rc = sp_agree(run->agree_comm, rc); /* the output's errors, before collectives */
    if (rc == SP_OK && !ends) { /* checkpoints: due, or a signal asked for one */
      int signalled = 0;
      rc = checkpoint_if_due(run, &signalled);
      if (rc == SP_OK && signalled) {
        sum->stopped = SP_STOPPED_SIGNAL;
        break;
      }
    }
    if (stop) break;
  }
  sum->n_cells = run->layout->n_cells;
  free(shape_coef);
  free(obs_new);
  free(core_mass_old);
  free(attempts);
  return rc;
}

int sp_stepper_run(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                   sp_run_summary *summary) {
  return sp_stepper_run_with(scene, out_dir, comm, NULL, NULL, summary);
}

int sp_stepper_run_with(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary) {
  return sp_stepper_run_from(scene, NULL, out_dir, comm, on_step, user, summary);
}

int sp_stepper_run_from(const sp_scene *scene, const sp_run_start *start, const char *out_dir,
                        MPI_Comm comm, sp_step_callback on_step, void *user,
                        sp_run_summary *summary) {
  sp_run_summary sum = {0};
  const double t0 = wall_clock();
  sp_run run = {.sum = &sum, .out_dir = out_dir, .on_step = on_step, .on_step_user = user,
                .t_start = t0, .t_checkpoint = t0};
  stop_requested = 0;
  int rc = sp_run_setup(&run, scene, comm, start);
  /* Only now, with the input known good on every rank, does anything get
   * written (the other ranks write pieces into rank 0's directory). */
  if (rc == SP_OK && run.rank == 0) {
    if (run.restarted) { /* the logs cut back to the checkpoint's step */
      sp_checkpoint_remove_after(out_dir, run.step);
      rc = sp_output_resume(out_dir, run.step, run.n_fields, run.fields, &run.output);
    } else {
      rc = sp_output_open(out_dir, &run.output);
    }
  }
  free(run.fields);
  run.fields = NULL;
  if (rc == SP_OK) rc = run_steps(&run, &sum);
  /* A rank that failed alone meets here the other ranks' next agreement
   * (none without an agreement communicator: its creation failed). */
  if (run.agree_comm != MPI_COMM_NULL) rc = sp_agree(run.agree_comm, rc);
  sum.wall_seconds = wall_clock() - t0;
  if (summary) *summary = sum;
  sp_run_free(&run);
  return rc;
}
