#include "run/checkjac.h"

#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/agree.h"
#include "public/error.h"
#include "run/run_setup.h"
#include "scene/scene.h"
#include "softpack_solver.h"
#include "run/solver_status.h"
#include "run/step.h"

/** What the command holds: the scene and the run set up from it
 *  (run_setup.h), so the Jacobians are checked on exactly the layout, node
 *  numbering and local supports a run of the scene steps on. */
typedef struct {
  sp_scene *scene;
  sp_run run;
  int set_up; /* sp_run_setup was called: run to free */
} checkjac;

static void checkjac_free(checkjac *c) {
  if (c->set_up) sp_run_free(&c->run);
  sp_scene_destroy(&c->scene);
}

static int compare(checkjac *c, const sp_step_data *data, int a, int b, double *out) {
  const sp_run *run = &c->run;
  const int status = sp_solver_compare_jacobians(run->solver, data, run->state, a, b, out);
  if (status != SP_SOLVER_OK) return sp_solver_failed(run->solver, status, "comparing Jacobians");
  return SP_OK;
}

/** The table for the current state; *worst_hand_ad gets the largest
 *  hand-vs-ad figure over its rows. */
static int check_state(checkjac *c, const char *what, double t, double *worst_hand_ad) {
  const sp_run *run = &c->run;
  /* At the start of a step: state_old = state, Jacobian at the state. */
  memcpy(run->buf.state_old, run->state, 2 * (size_t)run->layout->n_pairs * sizeof(double));
  static const char *rows[] = {"all terms", "lambda = 0", "lambda_b = 0",
                               "lambda = lambda_b = 0", "no adhesion"};
  /* a scene with adhesion: also without it (its blocks alone are the
   * difference between the first row and this one) */
  const int n_rows = run->opt.model.adhesion ? 5 : 4;
  if (run->rank == 0)
    printf("\n%s (t = %.6g):\n  %-24s %12s %12s %12s\n", what, t, "terms", "hand vs ad",
           "ad vs fd", "hand vs fd");
  for (int r = 0; r < n_rows; ++r) {
    sp_step_data data = {.dt = run->opt.time.dt.dt, .model = run->opt.model,
                         .state_old = run->buf.state_old, .source = NULL, .shape = NULL};
    if (r == 1 || r == 3) data.model.lambda = 0.0;
    if (r == 2 || r == 3) data.model.lambda_b = 0.0;
    if (r == 4) data.model.adhesion = NULL;
    double hand_ad, ad_fd, hand_fd;
    SP_CALL(compare(c, &data, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_AD, &hand_ad));
    SP_CALL(compare(c, &data, SP_SOLVER_JAC_AD, SP_SOLVER_JAC_FD, &ad_fd));
    SP_CALL(compare(c, &data, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD, &hand_fd));
    if (run->rank == 0)
      printf("  %-24s %12.3e %12.3e %12.3e\n", rows[r], hand_ad, ad_fd, hand_fd);
    if (!(hand_ad <= *worst_hand_ad)) *worst_hand_ad = hand_ad; /* NaN sticks */
  }
  return SP_OK;
}

/** K steps of the run's state, taken as a run takes them (step.h: the
 *  scene's scheme, controller, source and shape term; a failed attempt is
 *  retried smaller, never accepted), without the events after a step
 *  (divisions, support changes): the layout stays the set-up's. */
static int take_steps(checkjac *c, int steps, double *dt_last, int *retries) {
  sp_run *run = &c->run;
  sp_step_begin(run);
  while (run->step < steps) {
    sp_step_attempt a;
    SP_CALL(sp_step_try(run, &a)); /* (an attempt that gives up returns its error) */
    if (a.verdict == SP_STEP_ACCEPTED) {
      SP_CALL(sp_step_complete(run, &a));
      *dt_last = a.dt;
      continue;
    }
    ++*retries;
  }
  return SP_OK;
}

int sp_check_jacobian_command(int argc, char **argv) {
  const char *scene_path = NULL;
  const char **sets = calloc(argc > 0 ? argc : 1, sizeof(char *));
  SP_CHECK(sets, SP_ERR_MEMORY, "out of memory");
  int n_set = 0, steps = 1, rc = SP_OK;
  for (int i = 0; i < argc && rc == SP_OK; ++i) {
    if (strcmp(argv[i], "--set") == 0 && i + 1 < argc) {
      sets[n_set++] = argv[++i];
    } else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
      char *end;
      long k = strtol(argv[++i], &end, 10);
      if (*argv[i] == '\0' || *end != '\0' || k < 0 || k > 1000000)
        rc = sp_error_set(SP_ERR_INPUT, "--steps: expected an integer >= 0, got '%s'", argv[i]);
      steps = (int)k;
    } else if (argv[i][0] == '-') {
      rc = sp_error_set(SP_ERR_INPUT, "unknown option or missing value: %s", argv[i]);
    } else if (!scene_path) {
      scene_path = argv[i];
    } else {
      rc = sp_error_set(SP_ERR_INPUT, "more than one scene file: %s and %s", scene_path, argv[i]);
    }
  }
  if (rc == SP_OK && !scene_path)
    rc = sp_error_set(SP_ERR_INPUT, "softpack check-jacobian needs a scene file");
  checkjac c = {0};
  if (rc == SP_OK) rc = sp_scene_load(scene_path, n_set, sets, &c.scene);
  free(sets);
  /* Every phase below is collective: the ranks agree on their errors
   * before each (agree.h), so a failure on one rank ends every rank with
   * its message, never a hang or an MPI_Abort. */
  MPI_Comm agree = MPI_COMM_NULL;
  const int rc_comm = sp_agree_comm_create(MPI_COMM_WORLD, &agree);
  if (rc_comm != SP_OK) {
    checkjac_free(&c);
    return rc_comm;
  }
  rc = sp_agree(agree, rc);
  if (rc == SP_OK) {
    c.set_up = 1;
    rc = sp_run_setup(&c.run, c.scene, MPI_COMM_WORLD, NULL);
  }
  rc = sp_agree(agree, rc);
  double t = 0.0, worst = 0.0;
  if (rc == SP_OK && c.run.rank == 0)
    printf("softpack check-jacobian %s: %d nodes, %d elements, %d cells; "
           "max over elements of max|J_a - J_b| / max|J_b|\n",
           scene_path, c.run.mesh->n_nodes, c.run.mesh->n_elems, c.run.layout->n_cells);
  if (rc == SP_OK) rc = sp_agree(agree, check_state(&c, "initial state", t, &worst));
  if (rc == SP_OK && steps > 0) {
    double dt_last = 0.0;
    int retries = 0;
    rc = sp_agree(agree, take_steps(&c, steps, &dt_last, &retries));
    t = c.run.t;
    char what[160];
    snprintf(what, sizeof what, "after %d step%s (last dt %.3g, %d failed attempt%s retried)",
             steps, steps == 1 ? "" : "s", dt_last, retries, retries == 1 ? "" : "s");
    if (rc == SP_OK) rc = sp_agree(agree, check_state(&c, what, t, &worst));
  }
  if (rc == SP_OK && c.run.rank == 0)
    printf("\nhand vs ad: largest relative difference %.3e (tolerance %.0e): %s\n", worst,
           SP_CHECKJAC_TOLERANCE, worst <= SP_CHECKJAC_TOLERANCE ? "ok" : "DIFFERENT");
  if (rc == SP_OK && !(worst <= SP_CHECKJAC_TOLERANCE))
    rc = sp_error_set(SP_ERR_SOLVER, "the hand and ad Jacobians differ by %.3e relative "
                      "(> %.0e)", worst, SP_CHECKJAC_TOLERANCE);
  rc = sp_agree(agree, rc);
  sp_agree_comm_free(&agree);
  checkjac_free(&c);
  return rc;
}
