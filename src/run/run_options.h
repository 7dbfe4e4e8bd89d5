/**
 * @file run_options.h
 * @brief The run's options: the scene's settings resolved once, at
 *        set-up (sp_run_setup builds the run's objects from the scene and
 *        these); nothing after set-up reads the scene (sp_scene) itself. Each part goes to the module that uses
 *        it: the solver's options and the model to the glue, the
 *        controller's parameters to dt_control.h, the division rule to
 *        division.h, the rest to the step, the events and the monitor.
 */
#ifndef SP_RUN_OPTIONS_H
#define SP_RUN_OPTIONS_H

#include "model/adhesion.h"
#include "model/contacts.h"
#include "model/division.h"
#include "time/dt_control.h"
#include "mesh/mesh.h"
#include "io/output.h"
#include "scene/scene.h"
#include "softpack_solver.h"
#include "time/time_scheme.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How the run steps in time (time.*, solver.predictor). */
typedef struct {
  sp_dt_params dt;        /**< the controller's parameters (dt_control.h) */
  sp_scheme_kind scheme;  /**< time.scheme */
  int adaptive;           /**< time.control: adaptive */
  double rtol, atol;      /**< adaptive: the local error tolerances on c */
  double t_end;           /**< the final time */
  int max_steps;          /**< accepted steps before the run stops */
  int predictor_linear;   /**< solver.predictor: linear */
} sp_run_time;

/** Divisions (division.*) as the events and the cut use them: the one
 *  division configuration of a run. */
typedef struct {
  int divides;                /**< division.criterion is not none */
  sp_division_params rule;    /**< the criterion (division.h); its reference
                                   mass and landing tolerance are set with the
                                   initial cells (sp_run_setup) */
  int reference_initial;      /**< division.use_initial_mass */
  int smooth_cut;             /**< division.cut: smooth */
  int equal_mass_line;        /**< division.line: equal_mass */
  double observe_threshold;   /**< the observables' threshold on c */
  double interface_width;     /**< d = sqrt(kappa / alpha): the smooth cut's width */
} sp_run_division;

/** The explicit terms (source.*, shape.*) and the local supports' shrink rule. */
typedef struct {
  double source_rate;      /**< source.rate (0: no source) */
  double source_off_ratio; /**< source.off_ratio */
  int source_extrapolated; /**< source.indicator extrapolated: BDF2 steps take
                                omega_k from c extrapolated to t^{n+1} */
  double shape_delta[3];   /**< shape.delta1/2/3 (delta3 0 in 2D) */
  int shape_implicit;      /**< shape.scheme: implicit */
  int shrink_always;       /**< layout.shrink: always */
} sp_run_terms;

/** What is written and when (output.*). */
typedef struct {
  int every;               /**< fields every this many steps */
  double interval;         /**< and at multiples of this time (0: off) */
  int pictures;            /**< PNG pictures */
  int picture_width;
  int contacts;            /**< contacts.csv and contacts_<step>.png */
  double contact_threshold; /**< contacts.h's threshold */
  sp_contacts_measure contact_measure; /**< output.contact_measure */
  double contact_level;    /**< output.contact_level */
  int timings;             /**< energy.csv's wall-clock columns */
  int checkpoint_every;
  double checkpoint_seconds;
  int checkpoint_keep;
  sp_output_units units;   /**< units.csv (output.length_unit, ...) */
} sp_run_output;

/** solver.linear: auto, decided again at each layout (sp_linear_auto). */
typedef struct {
  int on;            /**< the scene says auto */
  long unknowns;     /**< solver.auto_unknowns */
  double krylov_tol; /**< the scene's solver.krylov_tol (0: the solver's own) */
} sp_run_linear_auto;

/** Everything a run reads of its scene after set-up. */
typedef struct {
  sp_model_params model;  /**< (model.adhesion: the run's table, resize.h) */
  sp_adhesion_params adhesion;
  sp_solver_options solver;
  sp_run_linear_auto linear_auto;
  sp_run_time time;
  sp_run_division division;
  sp_run_terms terms;
  sp_run_output output;
} sp_run_options;

/** @brief The run's options from @p scene (a checked scene: no errors). */
void sp_run_options_from_scene(const sp_scene *scene, sp_run_options *opt);

/** @brief Whether a run keeps its past states: the BDF2 scheme, the error
 *         estimate and the linear predictor read them. */
int sp_run_keeps_history(const sp_run_options *opt);

/** @brief The mesh a scene describes. */
int sp_mesh_from_scene(const sp_scene *scene, sp_mesh **out);
/** @brief The mesh nodes from which `auto` picks gmres_amg in 3D (between
 *  the 3D run 5's ellipsoid at refinements 3, 4,589 nodes, and 4, 32,597). */
#define SP_LINEAR_AUTO_AMG_NODES 15000
/** @brief The solver `solver.linear: auto` picks on a mesh of @p dim and
 *  @p n_mesh_nodes nodes for a layout of @p n_unknowns unknowns: in 2D
 *  gmres_cells from @p auto_unknowns (solver.auto_unknowns), else mumps;
 *  in 3D by the mesh alone. */
sp_linear_kind sp_linear_auto(int dim, long n_mesh_nodes, long n_unknowns, long auto_unknowns);
/** @brief The relative residual of @p linear's solves: @p given, or for 0
 *  the solver's own (1e-4 gmres_cells, 1e-6 gmres_amg, else 1e-10). */
double sp_krylov_tol(int linear, double given);
/** @brief Solver options from a scene on a mesh of @p n_mesh_nodes nodes
 *  (which `auto` depends on; in 2D auto starts from mumps and the set-up
 *  decides again on its first layout); the run's options leave them to
 *  the set-up, which knows its mesh. */
void sp_solver_options_from_scene(const sp_scene *scene, long n_mesh_nodes,
                                  sp_solver_options *opt);
/** @brief Model parameters from a scene. */
void sp_model_from_scene(const sp_scene *scene, sp_model_params *model);
/** @brief The time-step controller's parameters from a scene (dt_control.h). */
void sp_dt_params_from_scene(const sp_scene *scene, sp_dt_params *params);

#ifdef __cplusplus
}
#endif
#endif
