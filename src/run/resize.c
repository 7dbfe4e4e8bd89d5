#include "run/resize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "base/agree.h"
#include "model/adhesion.h"
#include "public/error.h"
#include "mesh/partition.h"
#include "run/solver_status.h"

int sp_solver_attach(sp_solver solver, const sp_mesh *mesh, const sp_layout *layout) {
  /* (checked first, before the mesh is read: a NULL mesh counts as 2D) */
  const long long nonzeros = sp_layout_nonzeros_bound(layout, mesh ? mesh->dim : 2);
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
  sp_mesh_view mv = {.n_nodes = mesh->n_nodes, .n_elems = mesh->n_elems, .xy = mesh->xy,
                     .elem = mesh->elem, .region = mesh->region, .dim = mesh->dim,
                     .nodes_per_elem = mesh->nodes_per_elem};
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

/** The per-pair buffers of a step on the run's layout: c^n and the source,
 *  and only what the scheme uses: c_hat (BDF2) and the error estimate's
 *  extrapolation (adaptive control). */
static int alloc_step_buffers(sp_run *run) {
  const size_t n_pairs = (size_t)run->layout->n_pairs;
  sp_step_buffers *b = &run->buf;
  free(b->state_old);
  free(b->state_eff);
  free(b->scratch);
  free(b->source);
  *b = (sp_step_buffers){0};
  SP_ALLOC(b->state_old, 2 * n_pairs);
  SP_ALLOC(b->source, n_pairs);
  if (run->opt.time.scheme == SP_SCHEME_BDF2) SP_ALLOC(b->state_eff, 2 * n_pairs);
  if (run->opt.time.adaptive) SP_ALLOC(b->scratch, 2 * n_pairs);
  return SP_OK;
}

/** The largest so far of what the core holds on this rank: the mesh, the
 *  layout and the support module; the state, the history (up to two past
 *  states where the scheme, the estimate or the predictor keeps them) and
 *  the step's buffers. */
static void count_bytes(sp_run *run) {
  const double pair = 8.0 * (double)run->layout->n_pairs; /* one double per pair */
  const sp_step_buffers *b = &run->buf;
  const double *buffers[] = {b->state_old, b->state_eff, b->scratch};
  double state = 2 * pair /* the state */ + (b->source ? pair : 0);
  for (size_t i = 0; i < sizeof buffers / sizeof *buffers; ++i) state += buffers[i] ? 2 * pair : 0;
  if (sp_run_keeps_history(&run->opt)) state += 4 * pair; /* (allocated at the first push) */
  double mesh = sp_mesh_bytes(run->mesh) + sp_layout_bytes(run->layout);
  if (run->support) mesh += sp_support_bytes(run->support);
  run->bytes_mesh = fmax(run->bytes_mesh, mesh);
  run->bytes_state = fmax(run->bytes_state, state);
}

/** solver.linear auto: the solver for the run's layout (in 2D it depends on
 *  the unknowns); a change takes effect at the attach that follows. */
static int pick_linear(sp_run *run) {
  const sp_run_linear_auto *a = &run->opt.linear_auto;
  if (!a->on) return SP_OK;
  const long unknowns = 2L * run->layout->n_pairs;
  const int linear = (int)sp_linear_auto(run->mesh->dim, run->mesh->n_nodes, unknowns, a->unknowns);
  if (linear == run->opt.solver.linear) return SP_OK;
  const double tol = sp_krylov_tol(linear, a->krylov_tol);
  const int status = sp_solver_set_linear(run->solver, linear, tol);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "solver.linear auto");
  if (run->rank == 0)
    printf("softpack: solver.linear auto: %s from here (%ld unknowns, solver.auto_unknowns %ld)\n",
           sp_scene_linear_name((sp_linear_kind)linear), unknowns, a->unknowns);
  run->opt.solver.linear = linear;
  run->opt.solver.krylov_tol = tol;
  return SP_OK;
}

int sp_run_resize(sp_run *run, sp_layout *layout, double *state, sp_history_move how) {
  if (how == SP_HISTORY_CARRY && run->layout) {
    const int rc =
        sp_history_transfer(&run->hist, run->mesh, run->layout, run->state, layout, state);
    if (rc != SP_OK) {
      sp_layout_destroy(&layout);
      free(state);
      return rc;
    }
  } else if (how == SP_HISTORY_RESET) {
    sp_history_reset(&run->hist);
  }
  if (layout != run->layout) sp_layout_destroy(&run->layout);
  if (state != run->state) free(run->state);
  run->layout = layout;
  run->state = state;
  SP_CALL(alloc_step_buffers(run));
  SP_CALL(sp_registry_resize(&run->cells, layout->n_cells));
  /* (every rank has the same registry and layout: the same verdict) */
  SP_CALL(sp_agree(run->agree_comm, sp_run_adhesion_update(run))); /* attaching is collective */
  SP_CALL(pick_linear(run));
  SP_CALL(sp_solver_attach(run->solver, run->mesh, run->layout));
  count_bytes(run); /* (after the attach: the slot table is built) */
  return SP_OK;
}

int sp_run_adhesion_update(sp_run *run) {
  if (!sp_adhesion_on(&run->opt.adhesion)) return SP_OK;
  const int n = run->cells.n;
  double *table = realloc(run->adhesion, sizeof(double) * ((size_t)n * n + 1));
  SP_CHECK(table, SP_ERR_MEMORY, "out of memory for the adhesion table of %d cells", n);
  run->adhesion = table;
  sp_adhesion_table(&run->opt.adhesion, n, run->cells.sister,
                    (const sp_cell_name *)run->cells.name, table);
  run->opt.model.adhesion = table;
  run->opt.model.adhesion_cells = n;
  const sp_slots *slots;
  SP_CALL(sp_layout_slots(run->layout, run->mesh, &slots));
  return sp_adhesion_check(&run->opt.adhesion, table, n, slots, run->opt.model.kappa,
                           (const sp_cell_name *)run->cells.name, &run->adhesion_sum);
}
