/* The run's set-up (run_setup.h): everything a run is before its first
 * step, built in one place for the run, check-jacobian, the benchmarks and
 * the tests. Moved here from stepper.c unchanged (issue 19), so the runs'
 * outputs are bit-identical to what they were. */
#include "run_setup.h"

#include <stdlib.h>
#include <string.h>

#include "agree.h"
#include "cells.h"
#include "checkpoint.h"
#include "division.h"
#include "error.h"
#include "fault.h"
#include "initial.h"
#include "layout.h"
#include "partition.h"
#include "solver_status.h"
#include "support.h"
#include "time_scheme.h"

/** layout.support: auto turns local supports on beyond this many cells. */
#define SP_AUTO_LOCAL_CELLS 4

/** The per-pair buffers of a step on the run's layout: c^n and the source,
 *  and only what the scheme uses: c_hat (BDF2) and the error estimate's
 *  extrapolation (adaptive control). */
static int alloc_step_buffers(sp_run *run) {
  const size_t n_pairs = (size_t)run->layout->n_pairs;
  free(run->state_old);
  free(run->state_eff);
  free(run->scratch);
  free(run->source);
  run->state_old = run->state_eff = run->scratch = run->source = NULL;
  SP_ALLOC(run->state_old, 2 * n_pairs);
  SP_ALLOC(run->source, n_pairs);
  if (run->scene->time.scheme == SP_TIME_BDF2) SP_ALLOC(run->state_eff, 2 * n_pairs);
  if (run->scene->time.control == SP_CONTROL_ADAPTIVE) SP_ALLOC(run->scratch, 2 * n_pairs);
  return SP_OK;
}

/** What follows every new layout of the run (sp_run_adopt_layout's, a
 *  checkpoint's): the per-pair buffers resized, the solver given it. */
static int layout_taken(sp_run *run) {
  SP_CALL(alloc_step_buffers(run));
  SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* attaching is collective */
  return sp_solver_attach(run->solver, run->mesh, run->layout);
}

int sp_run_adopt_layout(sp_run *run, sp_layout *layout, double *state, sp_history_move how) {
  if (how == SP_HISTORY_CARRY) {
    const int rc =
        sp_history_transfer(&run->hist, run->mesh, run->layout, run->state, layout, state);
    if (rc != SP_OK) {
      sp_layout_destroy(&layout);
      free(state);
      return rc;
    }
  } else {
    sp_history_reset(&run->hist);
  }
  sp_layout_destroy(&run->layout);
  free(run->state);
  run->layout = layout;
  run->state = state;
  return layout_taken(run);
}

/** Renumber the mesh nodes in RCB order (partition.h), for every number of
 *  ranks, after the initial fields were drawn in the mesh's own numbering
 *  (so the seeded noise does not depend on the numbering) and carry the
 *  fields along. The layout is still the full one, node-major. */
static int renumber_rcb(sp_run *run) {
  const int nn = run->mesh->n_nodes, nc = run->layout->n_cells;
  SP_CHECK(run->layout->n_pairs == nn * nc, SP_ERR_INTERNAL,
           "renumbering: the layout must be the full one");
  int *order;
  SP_ALLOC(order, (size_t)nn);
  double *state = malloc(sizeof(double) * 2 * (size_t)run->layout->n_pairs + 1);
  int rc = state ? sp_partition_rcb_order(run->mesh, order)
                 : sp_error_set(SP_ERR_MEMORY, "out of memory renumbering the mesh");
  if (rc == SP_OK) rc = sp_partition_renumber(run->mesh, order);
  if (rc == SP_OK) {
    for (int j = 0; j < nn; ++j)
      memcpy(state + 2 * (size_t)j * nc, run->state + 2 * (size_t)order[j] * nc,
             2 * (size_t)nc * sizeof(double));
    free(run->state);
    run->state = state;
    state = NULL;
  }
  free(state);
  free(order);
  return rc;
}

/** The registry of a new run from the fields: every cell born at t = 0
 *  with its core mass and moments now, its source on; N_max. */
static int new_registry(sp_run *run) {
  const sp_scene_division *dv = &run->scene->division;
  const int n = run->layout->n_cells;
  SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state, dv->observe_threshold, run->obs));
  sp_cell_obs *core;
  SP_ALLOC(core, n);
  sp_cells_core_view(run->obs, n, core);
  for (int k = 0; k < n; ++k) {
    run->birth[k] = sp_cell_birth_make(0.0, &core[k], 0);
    run->source_on[k] = 1;
    run->division_skipped[k] = 0;
    run->divided_now[k] = 0;
  }
  free(core);
  run->n_max = dv->max_cells > 0 ? dv->max_cells
               : sp_division_max_cells(sp_mesh_region_area(run->mesh, SP_REGION_OMEGA),
                                       run->birth[0].birth_mass);
  return SP_OK;
}

/** sp_run_setup after the agreement communicator: its errors are not
 *  agreed yet. */
static int setup(sp_run *run, MPI_Comm comm, const sp_run_start *start) {
  const sp_scene *scene = run->scene;
  SP_MPI_CALL(MPI_Comm_rank(run->agree_comm, &run->rank));
  SP_MPI_CALL(MPI_Comm_size(run->agree_comm, &run->n_ranks));
  SP_CALL(sp_mesh_from_scene(scene, &run->mesh));
  /* The initial cells: the scene's disks or a file's (initial.h). A
   * checkpoint's replace them below; a scene without cells (initial.from a
   * checkpoint) has one placeholder cell until then. */
  const int placeholder = start && start->checkpoint && scene->n_cells == 0;
  int n = 1;
  if (!placeholder) SP_CALL(sp_initial_cell_count(scene, &n));
  SP_CALL(sp_layout_create_full(run->mesh->n_nodes, n, &run->layout));
  SP_CALL(sp_fault_check(SP_FAULT_SETUP, run->rank));
  sp_solver_options opt;
  sp_solver_options_from_scene(scene, &opt);
  sp_model_from_scene(scene, &run->model);
  SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* creating the solver is collective */
  const int status = sp_solver_create(comm, &opt, &run->solver);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "solver");
  const size_t n_values = 2 * (size_t)run->layout->n_pairs;
  SP_ALLOC(run->state, n_values);
  SP_CALL(alloc_step_buffers(run));
  SP_ALLOC(run->obs, n);
  SP_ALLOC(run->birth, n);
  SP_ALLOC(run->source_on, n);
  SP_ALLOC(run->division_skipped, n);
  SP_ALLOC(run->divided_now, n);
  if (!placeholder) SP_CALL(sp_initial_state(scene, run->mesh, run->layout, run->state));
  SP_CALL(renumber_rcb(run));
  if (placeholder) /* what decides on local supports: the checkpoint's cells */
    sp_checkpoint_cells(start->checkpoint, &n, &run->n_max);
  else SP_CALL(new_registry(run));
  /* use_initial_mass: the first initial cell's birth mass (the same for a
   * run continued from a checkpoint, whose scene has the same cells) */
  double reference_mass = run->birth[0].birth_mass;
  const sp_scene_division *dv = &scene->division;
  const sp_scene_layout *ly = &scene->layout;
  const int can_divide = dv->criterion != SP_DIVIDE_NONE;
  const int local = ly->support == SP_SUPPORT_LOCAL ||
                    (ly->support == SP_SUPPORT_AUTO &&
                     (n > SP_AUTO_LOCAL_CELLS || (can_divide && run->n_max > SP_AUTO_LOCAL_CELLS)));
  if (local) {
    const double d = sp_scene_interface_width(scene);
    sp_support_params sp = {.margin = ly->margin * d, .core_threshold = ly->core_threshold,
                            .grow_threshold = ly->grow_threshold, .band = ly->band * d,
                            .alpha = run->model.alpha, .lambda = run->model.lambda,
                            .lambda_b = run->model.lambda_b};
    SP_CALL(sp_support_create(run->mesh, &sp, &run->support));
  }
  if (start && start->checkpoint) { /* the layout and state (and more) saved */
    SP_CHECK(run->sum, SP_ERR_INTERNAL, "set-up from a checkpoint: no summary to restore into");
    sp_output_field *fields = NULL;
    int n_fields = 0;
    int rc = sp_checkpoint_restore(start->checkpoint, run, start->as_initial, &fields, &n_fields);
    if (rc == SP_OK && start->as_initial) free(fields);
    else {
      run->fields = fields;
      run->n_fields = n_fields;
    }
    SP_CALL(rc);
    run->restarted = !start->as_initial;
    SP_CALL(layout_taken(run)); /* the checkpoint's layout, history with it */
    if (!start->as_initial) SP_CALL(sp_checkpoint_restore_carry(start->checkpoint, run));
    if (start->as_initial) { /* observes too */
      SP_CALL(new_registry(run));
      reference_mass = run->birth[0].birth_mass;
    } else SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state, dv->observe_threshold,
                                  run->obs));
  } else if (local) {
    /* The initial fields are cut to the initial supports: background and
     * noise exist only there (docs/local-support.md). */
    unsigned char *mask;
    SP_ALLOC(mask, (size_t)run->mesh->n_nodes * n);
    sp_layout *layout = NULL;
    int rc = sp_support_masks(run->support, run->layout, run->state, mask);
    if (rc == SP_OK) rc = sp_support_layout_from_masks(run->support, n, mask, &layout);
    free(mask);
    SP_CALL(rc);
    double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
    if (!state) {
      sp_layout_destroy(&layout);
      return sp_error_set(SP_ERR_MEMORY, "out of memory for the local layout");
    }
    sp_layout_transfer(run->layout, run->state, layout, state, 0.0);
    SP_CALL(sp_run_adopt_layout(run, layout, state, SP_HISTORY_RESET));
    SP_CALL(sp_cells_observe(run->mesh, run->layout, run->state, dv->observe_threshold, run->obs));
  } else {
    SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* attaching is collective */
    SP_CALL(sp_solver_attach(run->solver, run->mesh, run->layout));
  }
  /* (With local supports the solver sees only the local layout: the full
   * one's graph couples every pair of cells at every node, N^2 x nodes
   * entries, 20 GB for 256 cells on 84k nodes.) */
  run->division = (sp_division_params){
      .criterion = dv->criterion == SP_DIVIDE_BY_AGE ? SP_DIVIDE_AGE : SP_DIVIDE_MASS,
      .age = dv->t_div, .mass_ratio = dv->mass_ratio,
      .reference_mass = dv->use_initial_mass ? reference_mass : 0.0,
      .tolerance = scene->time.control == SP_CONTROL_ADAPTIVE ? SP_MASS_LANDING_TOLERANCE : 0.0};
  return SP_OK;
}

int sp_run_setup(sp_run *run, const sp_scene *scene, MPI_Comm comm, const sp_run_start *start) {
  run->scene = scene;
  run->comm = comm;
  run->agree_comm = MPI_COMM_NULL;
  if (start) { /* saved in the run's checkpoints */
    run->scene_text = start->scene_text;
    run->scene_len = start->scene_len;
    run->n_set = start->n_set;
    run->set = start->set;
  }
  SP_CALL(sp_agree_comm_create(comm, &run->agree_comm));
  return sp_agree(run->agree_comm, setup(run, comm, start));
}

void sp_run_free(sp_run *run) {
  sp_agree_comm_free(&run->agree_comm);
  sp_output_close(&run->output);
  sp_solver_destroy(&run->solver);
  sp_layout_destroy(&run->layout);
  sp_mesh_destroy(&run->mesh);
  free(run->state);
  free(run->state_old);
  free(run->state_eff);
  free(run->scratch);
  sp_history_free(&run->hist);
  free(run->obs);
  free(run->energy_t);
  free(run->energy_total);
  free(run->division_t);
  free(run->birth);
  free(run->source_on);
  free(run->division_skipped);
  free(run->divided_now);
  free(run->source);
  sp_support_destroy(&run->support);
  free(run->fields);
  run->fields = NULL;
}
