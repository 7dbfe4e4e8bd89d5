/* The run's options from the scene (run_options.h). */
#include "run/run_options.h"

#include <string.h>

#include "public/error.h"

int sp_mesh_from_scene(const sp_scene *scene, sp_mesh **out) {
  const sp_scene_mesh *m = &scene->mesh;
  if (m->type == SP_MESH_RECTANGLE)
    return sp_mesh_rectangle(m->x0, m->y0, m->x1, m->y1, m->nx, m->ny, out);
  if (m->type == SP_MESH_BOX)
    return sp_mesh_box(m->x0, m->y0, m->z0, m->x1, m->y1, m->z1, m->nx, m->ny, m->nz, out);
  if (m->type == SP_MESH_ELLIPSOID)
    SP_CALL(sp_mesh_ellipsoid(m->refinements, m->semi_x, m->semi_y, m->semi_z, m->buffer_layers,
                              m->buffer_width, out));
  else
    SP_CALL(sp_mesh_ellipse(m->refinements, m->semi_x, m->semi_y, m->buffer_layers,
                            m->buffer_width, out));
  if (!(m->flatten > 0)) return SP_OK;
  const int rc = sp_mesh_flatten(*out, m->flatten);
  if (rc != SP_OK) sp_mesh_destroy(out);
  return rc;
}

sp_linear_kind sp_linear_auto(int dim, long n_mesh_nodes, long n_unknowns, long auto_unknowns) {
  /* In 2D MUMPS, and past a few hundred thousand unknowns GMRES on the
   * cells' blocks, faster in less memory; in 3D the cells' blocks (a
   * direct LU of the coupled cells runs out of memory, docs/3d.md), by
   * MUMPS up to about refinements 3 of the 3D run 5's ellipsoid and by
   * multigrid from refinements 4, where it takes the time of the blocks'
   * LU in half their memory and from where only it fits (docs/solvers.md,
   * "Which solver auto picks") */
  if (dim != 3) return n_unknowns >= auto_unknowns ? SP_LINEAR_GMRES_CELLS : SP_LINEAR_MUMPS;
  return n_mesh_nodes >= SP_LINEAR_AUTO_AMG_NODES ? SP_LINEAR_GMRES_AMG : SP_LINEAR_GMRES_CELLS;
}

double sp_krylov_tol(int linear, double given) {
  /* GMRES on the cells' blocks keeps each cell's mass at any tolerance
   * (cxx_glue/linear/linear_gmres_cells.cpp), and 1e-4 changes the 3D
   * run 5 by 1e-8 (docs/3d.md); gmres_amg restores each cell's mass after
   * each solve, and at 1e-4 its Newton takes more iterations than with
   * exact solves, at 1e-6 the same (docs/solvers.md); ILU's keeps no
   * mass, hence its 1e-10 */
  return given > 0                           ? given
         : linear == SP_LINEAR_GMRES_CELLS ? 1e-4
         : linear == SP_LINEAR_GMRES_AMG   ? 1e-6
                                           : 1e-10;
}

void sp_solver_options_from_scene(const sp_scene *scene, long n_mesh_nodes,
                                  sp_solver_options *opt) {
  static const int jacobian[] = {SP_SOLVER_JAC_AD, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD};
  opt->jacobian = jacobian[scene->solver.jacobian];
  opt->linear = scene->solver.linear == SP_LINEAR_AUTO
                    ? (int)sp_linear_auto(sp_scene_dim(scene), n_mesh_nodes, 0,
                                          scene->solver.auto_unknowns)
                    : (int)scene->solver.linear;
  opt->newton_rtol = scene->solver.newton_rtol;
  opt->newton_atol = scene->solver.newton_atol;
  opt->newton_max_its = scene->solver.newton_max_its;
  opt->ilu_fill = scene->solver.ilu_fill;
  opt->krylov_tol = sp_krylov_tol(opt->linear, scene->solver.krylov_tol);
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

void sp_dt_params_from_scene(const sp_scene *scene, sp_dt_params *p) {
  const sp_scene_time *tc = &scene->time;
  *p = (sp_dt_params){
      .policy = tc->control == SP_CONTROL_ADAPTIVE ? SP_DT_ADAPTIVE : SP_DT_FIXED,
      .dt = tc->dt, .dt_min = tc->dt_min, .dt_max = tc->dt_max,
      .max_retries = tc->max_retries, .shrink = tc->shrink, .grow = tc->grow,
      .grow_after = tc->grow_after, .failure_memory = tc->failure_memory,
      .ramp_n_div = scene->division.n_div, .ramp_m = scene->division.m,
      .order = tc->scheme == SP_TIME_BDF2 ? 2 : 1, .event_first = tc->event_first,
      .event_growth = tc->event_growth, .event_steps = tc->event_steps};
}

int sp_run_keeps_history(const sp_run_options *opt) {
  return opt->time.adaptive || opt->time.scheme == SP_SCHEME_BDF2 || opt->time.predictor_linear;
}

void sp_run_options_from_scene(const sp_scene *scene, sp_run_options *opt) {
  const sp_scene_time *tc = &scene->time;
  const sp_scene_division *dv = &scene->division;
  const sp_scene_output *out = &scene->output;
  *opt = (sp_run_options){0};
  sp_model_from_scene(scene, &opt->model);
  opt->linear_auto = (sp_run_linear_auto){.on = scene->solver.linear == SP_LINEAR_AUTO,
                                          .unknowns = scene->solver.auto_unknowns,
                                          .krylov_tol = scene->solver.krylov_tol};
  opt->adhesion = (sp_adhesion_params){.sisters = scene->model.adhesion_sisters,
                                       .non_sisters = scene->model.adhesion_non_sisters};
  sp_dt_params_from_scene(scene, &opt->time.dt);
  opt->time.scheme = tc->scheme == SP_TIME_BDF2 ? SP_SCHEME_BDF2 : SP_SCHEME_BE;
  opt->time.adaptive = tc->control == SP_CONTROL_ADAPTIVE;
  opt->time.rtol = tc->rtol;
  opt->time.atol = tc->atol;
  opt->time.t_end = tc->t_end;
  opt->time.max_steps = tc->max_steps;
  opt->time.predictor_linear = scene->solver.predictor == SP_PREDICT_LINEAR;
  opt->division = (sp_run_division){.divides = dv->criterion != SP_DIVIDE_NONE,
                                    .rule = {.criterion = dv->criterion == SP_DIVIDE_BY_AGE
                                                              ? SP_DIVIDE_AGE
                                                              : SP_DIVIDE_MASS,
                                             .age = dv->t_div,
                                             .mass_ratio = dv->mass_ratio},
                                    .reference_initial = dv->use_initial_mass,
                                    .smooth_cut = dv->cut == SP_CUT_SMOOTH,
                                    .equal_mass_line = dv->line == SP_LINE_EQUAL_MASS,
                                    .observe_threshold = dv->observe_threshold,
                                    .interface_width = sp_scene_interface_width(scene)};
  opt->terms = (sp_run_terms){.source_rate = scene->source.rate,
                              .source_off_ratio = scene->source.off_ratio,
                              .source_extrapolated =
                                  scene->source.indicator == SP_INDICATOR_EXTRAPOLATED,
                              .shape_delta = {scene->shape.delta1, scene->shape.delta2,
                                              scene->shape.delta3},
                              .shape_implicit = scene->shape.scheme == SP_SHAPE_IMPLICIT,
                              .shrink_always = scene->layout.shrink == SP_SHRINK_ALWAYS};
  opt->output = (sp_run_output){.every = out->every, .interval = out->interval,
                                .pictures = out->pictures, .picture_width = out->picture_width,
                                .contacts = out->contacts,
                                .contact_threshold = out->contact_threshold,
                                .contact_measure = out->contact_measure == SP_CONTACT_OVERLAP
                                                       ? SP_CONTACTS_OVERLAP
                                                       : SP_CONTACTS_ISOSURFACE,
                                .contact_level = out->contact_level,
                                .timings = out->timings,
                                .checkpoint_every = out->checkpoint_every,
                                .checkpoint_seconds = out->checkpoint_seconds,
                                .checkpoint_keep = out->checkpoint_keep,
                                .units = {.length_scale = out->length_scale,
                                          .time_scale = out->time_scale}};
  memcpy(opt->output.units.length, out->length_unit, sizeof opt->output.units.length);
  memcpy(opt->output.units.time, out->time_unit, sizeof opt->output.units.time);
}
