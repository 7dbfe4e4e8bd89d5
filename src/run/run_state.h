/**
 * @file run_state.h
 * @brief The run in one object (sp_run), grouped by what each part is for.
 *        Set up and freed by run_setup.h; its layout changes only through
 *        resize.h; stepped by step.h; its events are events.h's, its
 *        output the monitor's (monitor.h); saved and restored whole by
 *        checkpoint.h. A field added here that a step reads must be added
 *        to the checkpoint too (checkpoint.c lists what it holds).
 *
 * What a step depends on (the checkpoint holds exactly this):
 * - the layout and the fields on it: state (c, mu), and the history of
 *   the time scheme, error estimate and predictor (sp_history);
 * - the cell registry (registry.h);
 * - the time-step controller (sp_dt_control, plain data), step and t;
 * - N_max; the energy history and division times (energy.png); the
 *   summary counters. There is no random state after set-up: the seeded
 *   noise is drawn once, into the initial fields.
 * Everything else (options, mesh, solver, the supports' search
 * structures, per-step buffers) is rebuilt from the scene.
 */
#ifndef SP_RUN_STATE_H
#define SP_RUN_STATE_H

#include <mpi.h>
#include <stddef.h>

#include "io/contacts_out.h"
#include "model/division.h"
#include "time/dt_control.h"
#include "mesh/layout.h"
#include "model/lineage.h"
#include "mesh/mesh.h"
#include "io/output.h"
#include "model/registry.h"
#include "run/run_options.h"
#include "public/run_types.h"
#include "softpack_solver.h"
#include "model/support.h"
#include "time/time_scheme.h"

/** The per-pair buffers of a step on the current layout (resize.h sizes
 *  them). */
typedef struct {
  double *state_old; /**< c^n of the step in progress */
  double *state_eff; /**< BDF2: the step's backward-Euler form of c^n (c_hat) */
  double *scratch;   /**< adaptive: the error estimate's extrapolation */
  double *source;    /**< per pair: the growth source from c^n */
} sp_step_buffers;

/** What the monitor (monitor.h) keeps: the output, the energy history of
 *  energy.png, the costs of the step in progress, the caller's hook. */
typedef struct {
  sp_output output;
  const char *out_dir;  /**< every rank writes its piece there */
  sp_run_summary *sum;  /**< the caller's: the run's counters, summed once */
  double *energy_t, *energy_total; /**< the energy history */
  int n_energy, cap_energy;
  double *division_t;   /**< division times, marked on energy.png */
  int n_divisions;
  sp_step_costs costs;  /**< of the step being attempted (energy.csv) */
  sp_attempt *attempts; /**< its failed attempts (costs.failed_attempts) */
  int cap_attempts;
  double step_start;    /**< wall clock at its first attempt (< 0: none yet) */
  double t_start;       /**< wall clock at the run's start */
  double t_checkpoint;  /**< wall clock at the last checkpoint (or start) */
  sp_step_callback on_step; /**< may be NULL */
  void *on_step_user;
  sp_output_field *fields; /**< restarted: the checkpoint's fields.pvd list, */
  int n_fields;            /**< until the output is opened */
  sp_contacts contacts;    /**< of the last energy row's state (output.contacts) */
  sp_contacts_log contacts_log; /**< contacts.csv (rank 0) */
} sp_monitor;

/** What a checkpoint saves of the scene (may be NULL: none saved, and
 *  none can be resumed). */
typedef struct {
  const char *text; /**< the scene file's text */
  size_t len;
  int n_set;        /**< its overrides */
  const char *const *set;
} sp_scene_source_text;

typedef struct {
  sp_run_options opt;   /**< the scene, resolved once (run_options.h) */
  /* MPI */
  MPI_Comm comm;
  MPI_Comm agree_comm;  /**< errors are agreed on it before every collective
                             (agree.h); MPI errors return codes there */
  int rank, n_ranks;
  /* the discretisation */
  sp_mesh *mesh;
  sp_layout *layout;
  sp_support support;   /**< local supports (NULL: full) */
  sp_solver solver;
  /* the state */
  int step;             /**< accepted steps so far */
  double t;             /**< time reached */
  double *state;        /**< c and mu on the layout */
  sp_history hist;      /**< the past states (time scheme, error estimate,
                             predictor) on the layout; emptied by a division */
  sp_dt_control dtc;    /**< how dt is chosen: dt_control.h */
  sp_dt_control dtc_step_start; /**< dtc before the first attempt of the step
                                     in progress (a step dropped on a stop
                                     signal goes back to it) */
  int marked_step;      /**< the step whose start dtc_step_start and the
                             solver's carry mark hold (0: none yet) */
  sp_registry cells;    /**< the cell registry */
  double *adhesion;     /**< the cells' adhesion table (n_cells^2, from the
                             registry's sisters; NULL without adhesion):
                             opt.model.adhesion points to it (resize.h) */
  double adhesion_sum;  /**< the largest sum of a cell's partners' sigma on
                             an element of the layout (0 without adhesion) */
  int n_max;            /**< N_max */
  sp_lineage lineage;   /**< the lineage table (lineage.h; from the scene) */
  int restarted;        /**< 1: continued from a checkpoint (not as initial) */
  /* scratch of a step */
  sp_step_buffers buf;
  /* what this rank's core holds, the largest so far (resize.c): the mesh,
   * layout and support tables; the state, its history and the buffers */
  double bytes_mesh, bytes_state;
  /* output */
  sp_monitor mon;
  sp_scene_source_text scene_text;
} sp_run;

#endif
