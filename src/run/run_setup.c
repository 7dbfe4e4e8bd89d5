/* The run's set-up (run_setup.h): everything a run is before its first
 * step, built in one place for the run, check-jacobian, the benchmarks and
 * the tests. The scene's settings reach the run as its options
 * (run_options.h); set-up reads the scene only for the objects it builds
 * (the mesh, the initial fields and cells, the supports). */
#include "run/run_setup.h"

#include <stdlib.h>
#include <string.h>

#include "base/agree.h"
#include "model/cells.h"
#include "run/checkpoint.h"
#include "model/division.h"
#include "run/events.h"
#include "public/error.h"
#include "base/fault.h"
#include "io/initial.h"
#include "mesh/layout.h"
#include "run/monitor.h"
#include "mesh/partition.h"
#include "run/resize.h"
#include "run/run_energy.h"
#include "run/run_options.h"
#include "run/solver_status.h"
#include "model/support.h"
#include "time/time_scheme.h"

/** layout.support: auto turns local supports on beyond this many cells. */
#define SP_AUTO_LOCAL_CELLS 4

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
 *  with its core mass and moments now, its source on, its scene's name (the
 *  cells of a file have none); N_max. */
static int new_registry(sp_run *run, const sp_scene *scene) {
  const sp_scene_division *dv = &scene->division;
  sp_registry *cells = &run->cells;
  const int n = run->layout->n_cells;
  SP_CALL(sp_run_observe(run, cells->obs));
  sp_cells_core_view(cells->obs, n, cells->obs_new); /* (scratch) */
  for (int k = 0; k < n; ++k) {
    cells->birth[k] = sp_cell_birth_make(0.0, &cells->obs_new[k], 0);
    cells->source_on[k] = 1;
    cells->division_skipped[k] = 0;
    cells->divided_now[k] = 0;
    memset(cells->cut_normal[k], 0, sizeof cells->cut_normal[k]);
    memset(cells->name[k], 0, sizeof cells->name[k]);
    if (n == scene->n_cells) memcpy(cells->name[k], scene->cells[k].name, sizeof cells->name[k]);
  }
  run->n_max = dv->max_cells > 0 ? dv->max_cells
               : sp_division_max_cells(sp_mesh_region_area(run->mesh, SP_REGION_OMEGA),
                                       cells->birth[0].birth_mass);
  return SP_OK;
}

/** Local supports, if layout.support asks for them (auto: more than
 *  SP_AUTO_LOCAL_CELLS cells now, or divisions can make more). */
static int maybe_local_supports(sp_run *run, const sp_scene *scene, int n_cells) {
  const sp_scene_layout *ly = &scene->layout;
  const int can_divide = scene->division.criterion != SP_DIVIDE_NONE;
  /* (each lineage entry makes one cell more) */
  const int local =
      ly->support == SP_SUPPORT_LOCAL ||
      (ly->support == SP_SUPPORT_AUTO &&
       (n_cells + scene->n_lineage > SP_AUTO_LOCAL_CELLS ||
        (can_divide && run->n_max > SP_AUTO_LOCAL_CELLS)));
  if (!local) return SP_OK;
  const double d = sp_scene_interface_width(scene);
  sp_support_params sp = {.margin = ly->margin * d, .core_threshold = ly->core_threshold,
                          .grow_threshold = ly->grow_threshold, .band = ly->band * d,
                          .alpha = run->opt.model.alpha, .kappa = run->opt.model.kappa,
                          .lambda = run->opt.model.lambda,
                          .lambda_b = run->opt.model.lambda_b,
                          .fill = ly->fill == SP_FILL_RELAX ? SP_SUPPORT_FILL_RELAX
                                                            : SP_SUPPORT_FILL_EDGE,
                          .restore = ly->restore == SP_RESTORE_POTENTIAL
                                         ? SP_SUPPORT_RESTORE_POTENTIAL
                                         : SP_SUPPORT_RESTORE_INTERIOR,
                          .buffer = ly->buffer_elements == SP_BUFFER_ELEMENTS_WHOLE
                                        ? SP_SUPPORT_BUFFER_WHOLE
                                        : SP_SUPPORT_BUFFER_MARGIN,
                          .no_widening = !ly->widen};
  return sp_support_create(run->mesh, &sp, &run->support);
}

/** The run from a checkpoint: its layout, state, history, registry and
 *  counters (restored through the one layout change, resize.h), and the
 *  factorisation it carried; as_initial: its fields as a new run's. */
static int from_checkpoint(sp_run *run, const sp_scene *scene, const sp_run_start *start,
                           double *reference_mass) {
  SP_CHECK(run->mon.sum, SP_ERR_INTERNAL, "set-up from a checkpoint: no summary to restore into");
  sp_output_field *fields = NULL;
  int n_fields = 0;
  const int rc =
      sp_checkpoint_restore(start->checkpoint, run, start->as_initial, &fields, &n_fields);
  if (rc == SP_OK && start->as_initial) free(fields);
  else {
    run->mon.fields = fields;
    run->mon.n_fields = n_fields;
  }
  if (rc != SP_OK && start->from_scene) /* (a mesh not the scene's, ...) */
    return sp_error_set(rc, "initial.from: %s", sp_error_message());
  SP_CALL(rc);
  run->restarted = !start->as_initial;
  if (!start->as_initial) {
    SP_CALL(sp_checkpoint_restore_carry(start->checkpoint, run));
    return sp_run_observe(run, run->cells.obs);
  }
  SP_CALL(new_registry(run, scene)); /* observes too */
  *reference_mass = run->cells.birth[0].birth_mass;
  return SP_OK;
}

/** The initial fields cut to the initial supports: background and noise
 *  exist only there (docs/local-support.md). */
static int cut_to_supports(sp_run *run) {
  sp_layout *layout = NULL;
  double *state = NULL;
  SP_CALL(sp_support_initial(run->support, run->layout, run->state, &layout, &state));
  SP_CALL(sp_run_resize(run, layout, state, SP_HISTORY_RESET));
  return sp_run_observe(run, run->cells.obs);
}

/** The mesh, the solver and the initial cells on the full layout, in RCB
 *  numbering, with the registry of a new run; from a checkpoint without
 *  cells of the scene's, one placeholder cell (*n: the checkpoint's cells). */
static int initial_run(sp_run *run, const sp_scene *scene, MPI_Comm comm,
                       const sp_run_start *start, int *n) {
  SP_MPI_CALL(MPI_Comm_rank(run->agree_comm, &run->rank));
  SP_MPI_CALL(MPI_Comm_size(run->agree_comm, &run->n_ranks));
  SP_CALL(sp_mesh_from_scene(scene, &run->mesh));
  sp_solver_options_from_scene(scene, run->mesh->n_nodes, &run->opt.solver);
  /* The initial cells: the scene's disks or a file's (initial.h). A
   * checkpoint's replace them later; a scene without cells (initial.from a
   * checkpoint) has one placeholder cell until then. */
  const int placeholder = start && start->checkpoint && scene->n_cells == 0;
  *n = 1;
  if (!placeholder) SP_CALL(sp_initial_cell_count(scene, run->mesh, n));
  SP_CALL(sp_layout_create_full(run->mesh->n_nodes, *n, &run->layout));
  SP_CALL(sp_fault_check(SP_FAULT_SETUP, run->rank));
  SP_CALL(sp_agree(run->agree_comm, SP_OK)); /* creating the solver is collective */
  const int status = sp_solver_create(comm, &run->opt.solver, &run->solver);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "solver");
  SP_ALLOC(run->state, 2 * (size_t)run->layout->n_pairs);
  SP_CALL(sp_registry_resize(&run->cells, *n));
  if (!placeholder) SP_CALL(sp_initial_state(scene, run->mesh, run->layout, run->state));
  SP_CALL(renumber_rcb(run));
  if (!placeholder) return new_registry(run, scene);
  /* what decides on local supports: the checkpoint's cells */
  sp_checkpoint_cells(start->checkpoint, n, &run->n_max);
  return SP_OK;
}

/** sp_run_setup after the agreement communicator: its errors are not
 *  agreed yet. */
static int setup(sp_run *run, const sp_scene *scene, MPI_Comm comm, const sp_run_start *start) {
  int n;
  SP_CALL(sp_lineage_from_scene(scene, &run->lineage));
  run->opt.adhesion.n_pairs = run->lineage.n_pairs; /* (the lineage owns them) */
  run->opt.adhesion.pair = run->lineage.pair;
  SP_CALL(initial_run(run, scene, comm, start, &n));
  /* use_initial_mass: the first initial cell's birth mass (the same for a
   * run continued from a checkpoint, whose scene has the same cells) */
  double reference_mass = run->cells.birth[0].birth_mass;
  SP_CALL(maybe_local_supports(run, scene, n));
  if (start && start->checkpoint) SP_CALL(from_checkpoint(run, scene, start, &reference_mass));
  else if (run->support) SP_CALL(cut_to_supports(run));
  else SP_CALL(sp_run_resize(run, run->layout, run->state, SP_HISTORY_RESET));
  /* (With local supports the solver sees only the local layout: the full
   * one's graph couples every pair of cells at every node, N^2 x nodes
   * entries, 20 GB for 256 cells on 84k nodes.) */
  sp_run_division *dv = &run->opt.division;
  dv->rule.reference_mass = dv->reference_initial ? reference_mass : 0.0;
  dv->rule.tolerance = run->opt.time.adaptive ? SP_MASS_LANDING_TOLERANCE : 0.0;
  return SP_OK;
}

int sp_run_setup(sp_run *run, const sp_scene *scene, MPI_Comm comm, const sp_run_start *start) {
  sp_run_options_from_scene(scene, &run->opt);
  run->comm = comm;
  run->agree_comm = MPI_COMM_NULL;
  if (start) /* saved in the run's checkpoints */
    run->scene_text = (sp_scene_source_text){.text = start->scene_text, .len = start->scene_len,
                                             .n_set = start->n_set, .set = start->set};
  SP_CALL(sp_agree_comm_create(comm, &run->agree_comm));
  return sp_agree(run->agree_comm, setup(run, scene, comm, start));
}

void sp_run_free(sp_run *run) {
  sp_agree_comm_free(&run->agree_comm);
  sp_monitor_free(&run->mon);
  sp_solver_destroy(&run->solver);
  sp_layout_destroy(&run->layout);
  sp_mesh_destroy(&run->mesh);
  free(run->state);
  run->state = NULL;
  free(run->buf.state_old);
  free(run->buf.state_eff);
  free(run->buf.scratch);
  free(run->buf.source);
  run->buf = (sp_step_buffers){0};
  sp_history_free(&run->hist);
  sp_registry_free(&run->cells);
  free(run->adhesion);
  run->adhesion = NULL;
  sp_lineage_free(&run->lineage);
  sp_support_destroy(&run->support);
}
