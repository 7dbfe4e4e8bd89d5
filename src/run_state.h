/**
 * @file run_state.h
 * @brief The run's state in one object: everything a step depends on, with
 *        one lifecycle (set up and freed by run_setup.h, stepped by the
 *        stepper, saved and restored whole by checkpoint.c). A field
 *        added here that a step reads must be added to the checkpoint too
 *        (checkpoint.c lists what it holds).
 *
 * What a step depends on:
 * - the layout and the fields on it: state (c, mu), and the history of
 *   the time scheme, error estimate and predictor (sp_history);
 * - the cell registry: birth (time, mass, reference moments, generation),
 *   source on/off, division skipped, divided this step;
 * - the time-step controller (sp_dt_control, plain data), step and t;
 * - N_max; the energy history and division times (energy.png); the
 *   summary counters. There is no random state after set-up: the seeded
 *   noise is drawn once, into the initial fields.
 * Everything else (mesh, solver, supports' search structures, per-step
 * buffers) is rebuilt from the scene.
 */
#ifndef SP_RUN_STATE_H
#define SP_RUN_STATE_H

#include <mpi.h>

#include "cells.h"
#include "division.h"
#include "dt_control.h"
#include "layout.h"
#include "mesh.h"
#include "output.h"
#include "scene.h"
#include "softpack_solver.h"
#include "stepper.h"
#include "support.h"
#include "time_scheme.h"

typedef struct {
  const sp_scene *scene;
  sp_mesh *mesh;
  sp_layout *layout;
  sp_solver solver;
  sp_output output;
  sp_model_params model;
  int step;           /* accepted steps so far */
  double t;           /* time reached */
  double *state, *state_old; /* the state, and c^n of the step in progress */
  double *state_eff;  /* the step's backward-Euler form of c^n (BDF2: c_hat) */
  double *scratch;    /* the error estimate's extrapolation */
  /* the past states (time scheme, error estimate, solver.predictor) on the
   * current layout; emptied by a division */
  sp_history hist;
  sp_dt_control dtc;  /* how dt is chosen: dt_control.h */
  sp_cell_obs *obs;
  double *energy_t, *energy_total; /* the energy history for energy.png */
  int n_energy, cap_energy;
  double *division_t; /* division times, marked on energy.png */
  int n_divisions;
  int rank, n_ranks;
  const char *out_dir;   /* the output directory (every rank writes its piece) */
  /* the cell registry */
  sp_cell_birth *birth;
  int *source_on;
  int *division_skipped; /* due but no field left: reported once */
  unsigned char *divided_now; /* parent or daughter of a division this step:
                                 its support may shrink (layout.shrink) */
  double *source;        /* per pair, from c^n */
  int n_max;             /* N_max */
  sp_support support;    /* local supports (NULL: full) */
  sp_run_summary *sum;
  sp_division_params division;
  MPI_Comm comm;
  MPI_Comm agree_comm; /* errors are agreed on it before every collective
                          (agree.h); MPI errors return codes there */
  sp_step_callback on_step; /* may be NULL */
  void *on_step_user;
  double t_start;           /* wall clock at the run's start */
  double t_checkpoint;      /* wall clock at the last checkpoint (or start) */
  int restarted;            /* 1: continued from a checkpoint (not as initial) */
  sp_output_field *fields;  /* restarted: the checkpoint's fields.pvd list, */
  int n_fields;             /* until the output is opened */
  const char *scene_text;   /* the scene file's text, its overrides: */
  size_t scene_len;         /* saved in checkpoints (may be NULL) */
  int n_set;
  const char *const *set;
} sp_run;

#endif
