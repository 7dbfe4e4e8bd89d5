#include "stepper.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cells.h"
#include "error.h"
#include "layout.h"
#include "output.h"
#include "render.h"

/** Centre and inertia integrate c only where c >= this, so a background
 *  of ~0.02 does not count (as in the authors' code). */
#define SP_OBSERVABLE_THRESHOLD 0.05

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
                               SP_SOLVER_MUMPS, SP_SOLVER_KLU2};
  opt->jacobian = jacobian[scene->solver.jacobian];
  opt->linear = linear[scene->solver.linear];
  opt->newton_rtol = scene->solver.newton_rtol;
  opt->newton_atol = scene->solver.newton_atol;
  opt->newton_max_its = scene->solver.newton_max_its;
}

void sp_model_from_scene(const sp_scene *scene, sp_model_params *model) {
  model->alpha = scene->model.alpha;
  model->kappa = scene->model.kappa;
  model->lambda = scene->model.lambda;
  model->lambda_b = scene->model.lambda_b;
  model->mobility = scene->model.mobility;
}

static double wall_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/** Everything one run holds. */
typedef struct {
  const sp_scene *scene;
  sp_mesh *mesh;
  sp_layout *layout;
  sp_solver solver;
  sp_output output;
  sp_model_params model;
  double *state, *state_old;
  sp_cell_obs *obs;
  double *energy_t, *energy_total; /* the energy history for energy.png */
  int n_energy, cap_energy;
  int rank;
} sp_run;

static int record_energy(sp_run *run, int step, double t, double dt, int its) {
  sp_energy_parts parts;
  if (sp_solver_energy(run->solver, &run->model, run->state, &parts) != 0)
    return sp_error_set(SP_ERR_INTERNAL, "energy: %s", sp_solver_last_error(run->solver));
  const double total = parts.bulk + parts.gradient + parts.repulsion + parts.buffer;
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
  SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state, SP_OBSERVABLE_THRESHOLD, run->obs));
  if (run->rank != 0) return SP_OK;
  SP_CALL(sp_output_energy(run->output, step, t, dt, its, run->layout->n_cells, &parts, 0.0));
  SP_CALL(sp_output_cells(run->output, step, t, run->layout->n_cells, run->obs));
  return SP_OK;
}

static int write_snapshot(sp_run *run, int step, double t) {
  if (run->rank != 0) return SP_OK;
  SP_CALL(sp_output_fields(run->output, run->mesh, run->layout, run->state, step, t));
  char path[4096];
  if (run->scene->output.pictures) {
    snprintf(path, sizeof path, "%s/cells_%06d.png", sp_output_dir(run->output), step);
    SP_CALL(sp_render_cells(run->mesh, run->layout, run->state, t,
                            run->scene->output.picture_width, path));
  }
  snprintf(path, sizeof path, "%s/energy.png", sp_output_dir(run->output));
  return sp_render_energy(run->energy_t, run->energy_total, run->n_energy, NULL, 0, path);
}

/** The time loop proper. */
static int run_steps(sp_run *run, sp_run_summary *sum) {
  const sp_scene_time *tc = &run->scene->time;
  const size_t n_values = 2 * (size_t)run->layout->n_pairs;
  double t = 0.0, dt = tc->dt;
  int step = 0, successes = 0, failures = 0;
  sum->dt_smallest = tc->dt;
  SP_CALL(record_energy(run, 0, t, 0.0, 0));
  SP_CALL(write_snapshot(run, 0, t));
  const double t_tol = 1e-12 * tc->t_end;
  while (t < tc->t_end - t_tol && step < tc->max_steps) {
    const double dt_try = fmin(dt, tc->t_end - t);
    memcpy(run->state_old, run->state, n_values * sizeof(double));
    sp_step_data data = {.dt = dt_try, .model = run->model, .state_old = run->state_old,
                         .source = NULL, .shape = NULL};
    sp_step_report report;
    int rc = sp_solver_step(run->solver, &data, run->state, &report);
    sum->t_assembly += report.t_assembly;
    sum->t_factor += report.t_factor;
    sum->t_solve += report.t_solve;
    if (rc > 1)
      return sp_error_set(SP_ERR_SOLVER, "step %d at t = %g: %s", step + 1, t,
                          sp_solver_last_error(run->solver));
    if (rc == 1) { /* never accept: shrink and retry from the last good state */
      memcpy(run->state, run->state_old, n_values * sizeof(double));
      ++failures;
      ++sum->failed_attempts;
      successes = 0;
      dt = dt_try * tc->shrink;
      if (failures > tc->max_retries || dt < tc->dt_min) {
        int rc_out = write_snapshot(run, step, t);
        sp_error_set(SP_ERR_SOLVER,
                     "Newton failed on step %d at t = %.6g after %d attempts "
                     "(last dt = %.3g; time.max_retries = %d, time.dt_min = %.3g): %s. "
                     "The last good state (t = %.6g) is written%s.",
                     step + 1, t, failures, dt_try, tc->max_retries, tc->dt_min,
                     report.reason, t, rc_out == SP_OK ? "" : " (failed: see above)");
        return SP_ERR_SOLVER;
      }
      continue;
    }
    t += dt_try;
    ++step;
    failures = 0;
    sum->steps = step;
    sum->newton_its += report.newton_its;
    sum->t_final = t;
    if (dt_try < sum->dt_smallest) sum->dt_smallest = dt_try;
    if (++successes >= tc->grow_after && dt < tc->dt) {
      dt = fmin(dt * tc->grow, tc->dt);
      successes = 0;
    }
    SP_CALL(record_energy(run, step, t, dt_try, report.newton_its));
    const int last = !(t < tc->t_end - t_tol && step < tc->max_steps);
    if (step % run->scene->output.every == 0 || last) SP_CALL(write_snapshot(run, step, t));
  }
  return SP_OK;
}

static void run_free(sp_run *run) {
  sp_output_close(&run->output);
  sp_solver_destroy(&run->solver);
  sp_layout_destroy(&run->layout);
  sp_mesh_destroy(&run->mesh);
  free(run->state);
  free(run->state_old);
  free(run->obs);
  free(run->energy_t);
  free(run->energy_total);
}

static int run_setup(sp_run *run, MPI_Comm comm) {
  const sp_scene *scene = run->scene;
  MPI_Comm_rank(comm, &run->rank);
  SP_CALL(sp_mesh_from_scene(scene, &run->mesh));
  SP_CALL(sp_layout_create_full(run->mesh->n_nodes, scene->n_cells, &run->layout));
  sp_solver_options opt;
  sp_solver_options_from_scene(scene, &opt);
  sp_model_from_scene(scene, &run->model);
  if (sp_solver_create(comm, &opt, &run->solver) != 0)
    return sp_error_set(SP_ERR_INPUT, "solver: %s", sp_solver_last_error(run->solver));
  sp_mesh_view mv = {run->mesh->n_nodes, run->mesh->n_elems, run->mesh->xy,
                     run->mesh->elem, run->mesh->region};
  sp_layout_view lv = {run->layout->n_nodes, run->layout->n_cells, run->layout->n_pairs,
                       run->layout->node_start, run->layout->pair_cell};
  if (sp_solver_set_problem(run->solver, &mv, &lv) != 0)
    return sp_error_set(SP_ERR_INTERNAL, "solver setup: %s", sp_solver_last_error(run->solver));
  const size_t n_values = 2 * (size_t)run->layout->n_pairs;
  SP_ALLOC(run->state, n_values);
  SP_ALLOC(run->state_old, n_values);
  SP_ALLOC(run->obs, scene->n_cells);
  return sp_cells_initial_state(scene, run->mesh, run->layout, run->state);
}

int sp_stepper_run(const sp_scene *scene, const char *out_dir, MPI_Comm comm,
                   sp_run_summary *summary) {
  sp_run run = {.scene = scene};
  sp_run_summary sum = {0};
  const double t0 = wall_clock();
  int rc = run_setup(&run, comm);
  /* Only now, with the input known good, does anything get written. */
  if (rc == SP_OK && run.rank == 0) rc = sp_output_open(out_dir, &run.output);
  if (rc == SP_OK) rc = run_steps(&run, &sum);
  sum.wall_seconds = wall_clock() - t0;
  if (summary) *summary = sum;
  run_free(&run);
  return rc;
}
