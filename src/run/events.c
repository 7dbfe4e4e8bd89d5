/* The run's events (events.h). */
#include "run/events.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/agree.h"
#include "model/cells.h"
#include "model/division.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "model/lineage.h"
#include "run/resize.h"
#include "run/run_energy.h"
#include "model/source.h"
#include "run/stop.h"
#include "model/support.h"
#include "time/time_scheme.h"
#include "base/wall_clock.h"

double sp_events_next(const sp_run *run, double t) {
  const double t_end = run->opt.time.t_end, slack = 1e-12 * t_end;
  double event = t_end;
  const double every = run->opt.output.interval;
  if (every > 0) {
    const double k = floor((t + slack) / every) + 1;
    event = fmin(event, k * every);
  }
  if (!run->opt.time.adaptive) return event;
  const sp_run_division *dv = &run->opt.division;
  const int by_age = dv->divides && dv->rule.criterion == SP_DIVIDE_AGE &&
                     run->layout->n_cells < run->n_max;
  for (int k = 0; k < run->layout->n_cells; ++k) {
    const sp_lineage_entry *e = sp_lineage_find(&run->lineage, run->cells.name[k]);
    if (!e && !by_age) continue;
    const double due = e ? sp_lineage_due_time(e, &run->cells.birth[k])
                         : run->cells.birth[k].birth_time + dv->rule.age;
    if (due > t + slack) event = fmin(event, due);
  }
  return event;
}

int sp_events_on_output_time(const sp_run *run, double t) {
  const double every = run->opt.output.interval;
  if (!(every > 0)) return 0;
  const double k = floor(t / every + 0.5);
  return k > 0 && fabs(t - k * every) <= 1e-12 * run->opt.time.t_end;
}

/** The model of the first step's convexity bound: with adhesion the
 *  gradient energy's coefficient is at least kappa minus the largest sum
 *  of a cell's partners' sigma on an element (docs/model.md, "Adhesion"). */
static sp_model_params convexity_model(const sp_run *run) {
  sp_model_params m = run->opt.model;
  m.kappa -= run->adhesion_sum;
  return m;
}

/** The starting step after this step's @p n_divided divisions: the
 *  convexity bound over the daughters' own nodes (c >=
 *  division.observe_threshold), not the mesh's worst overlap; the
 *  controller caps it by the step before (sp_dt_restart). */
static int first_dt_after_divisions(const sp_run *run, int n_divided, double *dt) {
  const sp_dt_params *p = &run->opt.time.dt;
  unsigned char *daughters;
  SP_ALLOC(daughters, (size_t)run->layout->n_cells);
  for (int i = 0; i < n_divided; ++i)
    daughters[run->cells.divisions[i].parent] = daughters[run->cells.divisions[i].child] = 1;
  const sp_model_params model = convexity_model(run);
  *dt = fmax(sp_scheme_first_dt_cells(run->layout, run->state, &model,
                                      fmin(p->dt, p->dt_max), daughters,
                                      run->opt.division.observe_threshold),
             p->dt_min);
  free(daughters);
  return SP_OK;
}

double sp_events_first_dt(const sp_run *run) {
  const sp_dt_params *p = &run->opt.time.dt;
  const sp_model_params model = convexity_model(run);
  const double dt = sp_scheme_first_dt(run->layout, run->state, &model, fmin(p->dt, p->dt_max));
  return fmax(dt, p->dt_min);
}

int sp_events_checkpoint_due(const sp_run *run, int *due, int *signalled) {
  const sp_run_output *o = &run->opt.output;
  /* a signal may reach one rank only, and the clocks differ: agreed */
  int want_stop = sp_stop_requested();
  int want_time = o->checkpoint_seconds > 0 &&
                  sp_wall_clock() - run->mon.t_checkpoint >= o->checkpoint_seconds;
  SP_CALL(sp_agree_any(run->agree_comm, &want_stop));
  SP_CALL(sp_agree_any(run->agree_comm, &want_time));
  *signalled = want_stop;
  *due = want_stop || want_time ||
         (o->checkpoint_every > 0 && run->step % o->checkpoint_every == 0);
  return SP_OK;
}

int sp_events_landing(sp_run *run, double t, double dt, int *observed, double *theta) {
  *theta = 1.0;
  const sp_registry *cells = &run->cells;
  const int n_cells = run->layout->n_cells;
  const sp_run_division *dv = &run->opt.division;
  const int by_mass = dv->divides && dv->rule.criterion == SP_DIVIDE_MASS && n_cells < run->n_max;
  int lineage_mass = 0;
  for (int i = 0; i < run->lineage.n; ++i)
    lineage_mass |= run->lineage.entry[i].when == SP_LINEAGE_MASS;
  if (!(run->opt.time.adaptive && (by_mass || lineage_mass))) return SP_OK;
  /* observed here, kept if the step stands */
  SP_CALL(sp_run_observe(run, cells->obs_new));
  *observed = 1;
  for (int k = 0; k < n_cells; ++k) {
    const sp_lineage_entry *e = sp_lineage_find(&run->lineage, cells->name[k]);
    if (e ? e->when != SP_LINEAGE_MASS : !by_mass) continue;
    const sp_division_params p =
        e ? sp_lineage_params(e, &cells->birth[k], dv->rule.tolerance) : dv->rule;
    const double m_old = cells->obs[k].mass_core, m_new = cells->obs_new[k].mass_core;
    if (!sp_division_due(&p, &cells->birth[k], t, t + dt, m_old, m_new)) continue;
    const double f = sp_division_crossing_fraction(&p, &cells->birth[k], t, t + dt, m_old, m_new);
    /* overshot: past the threshold by more than the tolerance */
    const double over =
        m_new - sp_division_threshold(&p, &cells->birth[k]) * (1 + SP_MASS_LANDING_TOLERANCE);
    if (f > 0 && f < 1 && over > 0) *theta = fmin(*theta, f);
  }
  return SP_OK;
}

/** Local supports: recompute every support from the fields (they follow
 *  the cells), keeping each cell's mass exactly. */
static int update_supports(sp_run *run, sp_step_events *ev) {
  const double t0 = sp_wall_clock();
  sp_layout *layout;
  double *state, correction, dropped;
  sp_energy_parts before;
  SP_CALL(sp_run_energy(run, &before));
  SP_CALL(sp_support_rebuild(run->support, run->layout, run->state,
                             run->opt.terms.shrink_always ? NULL : run->cells.divided_now, &layout,
                             &state, &correction, &dropped));
  memset(run->cells.divided_now, 0, (size_t)run->layout->n_cells);
  SP_CALL(sp_run_resize(run, layout, state, SP_HISTORY_CARRY));
  SP_CALL(sp_run_energy(run, &ev->energy));
  ev->have_energy = 1;
  SP_CALL(sp_run_observe(run, run->cells.obs));
  const double e_before = sp_energy_fields(&before);
  ev->support_changed = 1;
  ev->mass_correction = correction;
  ev->mass_dropped = dropped;
  ev->energy_rise = (sp_energy_fields(&ev->energy) - e_before) / fabs(e_before);
  ev->t_supports = sp_wall_clock() - t0;
  return SP_OK;
}

/** The layout after a division: full, or every support as it is plus the
 *  child on the parent's support (the next update tightens both). */
static int layout_with_child(sp_run *run, int parent, sp_layout **out) {
  const int n = run->layout->n_cells, nn = run->mesh->n_nodes;
  if (!run->support) return sp_layout_create_full(nn, n + 1, out);
  return sp_layout_with_child(run->layout, parent, out);
}

/** The split state of a division of @p parent on @p new_layout, the child
 *  being its last cell (the division line through the centre, or moved to
 *  halve the mass: division.line; to give the first daughter, the parent's
 *  slot, its share of a lineage entry @p e). */
static int split_state(sp_run *run, int parent, const sp_cell_obs *parent_obs,
                       const sp_lineage_entry *e, const sp_layout *new_layout,
                       double *new_state) {
  const sp_run_division *dv = &run->opt.division;
  double offset = 0.0;
  if (e || dv->equal_mass_line)
    SP_CALL(sp_division_balance_offset(run->mesh, run->layout, run->state, parent, parent_obs,
                                       dv->smooth_cut, dv->interface_width,
                                       e ? 1.0 - e->fraction : 0.5, &offset));
  return sp_division_split(run->mesh, run->layout, run->state, parent, parent_obs,
                           dv->smooth_cut, dv->interface_width, offset, new_layout, new_state,
                           new_layout->n_cells - 1);
}

/**
 * Divide cell @p parent (paper algorithm 1; by its lineage entry @p e, or
 * the scene's rules for NULL): a new layout with one more cell, the split
 * state on it, the registry entries of both daughters, a row of
 * divisions.csv.
 */
static int divide_cell(sp_run *run, int parent, const sp_lineage_entry *e,
                       sp_division_record *record) {
  const int n = run->layout->n_cells, child = n;
  sp_layout *new_layout = NULL;
  SP_CALL(layout_with_child(run, parent, &new_layout));
  double *new_state = calloc(2 * (size_t)new_layout->n_pairs, sizeof(double));
  if (!new_state) {
    sp_layout_destroy(&new_layout);
    return sp_error_set(SP_ERR_MEMORY, "out of memory dividing cell %d", parent + 1);
  }
  /* the parent's observables, with the cut's normal of its entry */
  sp_cell_obs parent_obs = run->cells.obs[parent];
  double long_axis[3], normal[3];
  sp_lineage_obs_normal(&parent_obs, run->mesh->dim, long_axis);
  sp_lineage_normal(e, run->mesh->dim, long_axis, run->cells.cut_normal[parent], normal);
  if (e) sp_lineage_set_obs_normal(&parent_obs, normal);
  const int rc = split_state(run, parent, &parent_obs, e, new_layout, new_state);
  if (rc != SP_OK) {
    free(new_state);
    sp_layout_destroy(&new_layout);
    return rc;
  }
  /* an event: the scheme starts over, no estimate reaches across it */
  SP_CALL(sp_run_resize(run, new_layout, new_state, SP_HISTORY_RESET));
  sp_registry *cells = &run->cells;
  cells->divided_now[parent] = cells->divided_now[child] = 1;
  cells->source_on[child] = cells->source_on[parent];
  SP_CALL(sp_run_observe(run, cells->obs));
  sp_cells_core_view(cells->obs, n + 1, cells->obs_new); /* (scratch) */
  sp_division_record_births(run->t, cells->obs_new, parent, child, cells->birth);
  sp_cell_name parent_name;
  memcpy(parent_name, cells->name[parent], sizeof parent_name);
  sp_lineage_daughter_names(e, parent_name, cells->name[parent], cells->name[child]);
  memcpy(cells->cut_normal[parent], normal, sizeof normal);
  memcpy(cells->cut_normal[child], normal, sizeof normal);
  /* the daughters are sisters; the parent's sister is no one's now */
  for (int k = 0; k < n; ++k)
    if (cells->sister[k] == parent + 1) cells->sister[k] = 0;
  cells->sister[parent] = child + 1;
  cells->sister[child] = parent + 1;
  SP_CALL(sp_agree(run->agree_comm, sp_run_adhesion_update(run)));
  const int dim = run->mesh->dim;
  /* 2D: the angle of the division line, the normal turned by -90 degrees
   * (+0, not -0, in divisions.csv) */
  const double angle = dim == 2 ? sp_cells_line_angle(normal[1], -normal[0] + 0.0) : 0.0;
  *record = (sp_division_record){.parent = parent, .child = child, .angle = angle,
                                 .parent_mass = parent_obs.mass,
                                 .mass_a = cells->obs[parent].mass,
                                 .mass_b = cells->obs[child].mass,
                                 .fraction = e ? e->fraction : NAN};
  memcpy(record->parent_name, parent_name, sizeof parent_name);
  memcpy(record->name_a, cells->name[parent], sizeof record->name_a);
  memcpy(record->name_b, cells->name[child], sizeof record->name_b);
  double centre[3];
  sp_division_plane(&parent_obs, run->mesh->dim, centre, record->axis);
  return SP_OK;
}

/** After the step from @p t_old: divide every cell whose criterion was
 *  crossed, its lineage entry's or the scene's (daughters born now wait a
 *  step). N_max limits the scene's divisions only: the table is a schedule. */
static int divide_due_cells(sp_run *run, double t_old, int *n_divided) {
  *n_divided = 0;
  const sp_run_division *dv = &run->opt.division;
  const int by_rule = dv->divides;
  if (!by_rule && run->lineage.n == 0) return SP_OK;
  const int n = run->layout->n_cells;
  for (int k = 0; k < n; ++k) {
    sp_registry *cells = &run->cells;
    const sp_lineage_entry *e = sp_lineage_find(&run->lineage, cells->name[k]);
    if (e ? !sp_lineage_due(e, &cells->birth[k], run->t, cells->obs[k].mass_core,
                            dv->rule.tolerance)
          : !by_rule || !sp_division_due(&dv->rule, &cells->birth[k], t_old, run->t,
                                         cells->core_mass_old[k], cells->obs[k].mass_core))
      continue;
    if (!e && run->layout->n_cells >= run->n_max) {
      if (!cells->division_skipped[k] && run->rank == 0)
        fprintf(stderr, "softpack: cell %d is due to divide at t = %.6g but N_max = %d cells "
                        "exist already; it does not divide\n", k + 1, run->t, run->n_max);
      cells->division_skipped[k] = 1;
      continue;
    }
    sp_division_record record; /* (the registry grows in the division) */
    SP_CALL(divide_cell(run, k, e, &record));
    run->cells.divisions[*n_divided] = record;
    ++*n_divided;
  }
  return SP_OK;
}

int sp_events_after_step(sp_run *run, double t_old, sp_step_events *ev) {
  *ev = (sp_step_events){0};
  SP_CALL(divide_due_cells(run, t_old, &ev->n_divided));
  int outgrown = 0; /* a cell reaches its support's edge */
  if (run->support && !ev->n_divided)
    SP_CALL(sp_support_needs_update(run->support, run->layout, run->state, &outgrown));
  if (run->support && (ev->n_divided || outgrown)) SP_CALL(update_supports(run, ev));
  if (ev->n_divided) { /* algorithm 2, or a restart from the post-event state */
    double dt_first = 0.0;
    SP_CALL(first_dt_after_divisions(run, ev->n_divided, &dt_first));
    sp_dt_restart(&run->dtc, dt_first);
  }
  if (run->opt.terms.source_rate > 0) {
    sp_registry *cells = &run->cells;
    for (int k = 0; k < run->layout->n_cells; ++k) cells->core_mass[k] = cells->obs[k].mass_core;
    SP_CALL(sp_source_update_switch(run->layout->n_cells, run->n_max, cells->core_mass,
                                    cells->birth, cells->source_on,
                                    run->opt.terms.source_off_ratio));
  }
  ev->divisions = run->cells.divisions; /* (after every resize of the registry) */
  return SP_OK;
}
