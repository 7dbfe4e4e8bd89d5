/* The tests that start from a scene: a run set up exactly as `softpack
 * run` sets it up (sp_run_setup, run_setup.h: mesh in RCB numbering,
 * initial fields, registry, local supports if the scene chooses them,
 * solver attached), without stepping. (The method tests of fixtures.h
 * build synthetic states, which are not scenes, on purpose.) */
#ifndef SP_TEST_SCENE_FIXTURE_H
#define SP_TEST_SCENE_FIXTURE_H
#include <mpi.h>
#include <stdlib.h>

#include "check.h"
#include "public/error.h"
#include "run/run_setup.h"

/** A set-up run and its summary (the run points into it: not movable). */
typedef struct {
  sp_run run;
  sp_run_summary sum;
} scene_run;

/** @p scene set up as a run on MPI_COMM_WORLD starts, from @p start (NULL:
 *  the scene's initial cells); *out NULL on failure, whose code is
 *  returned (the message in sp_error_message). Free with scene_run_free. */
static inline int scene_run_start(const sp_scene *scene, const sp_run_start *start,
                                  scene_run **out) {
  scene_run *s = calloc(1, sizeof *s);
  *out = NULL;
  if (!s) return sp_error_set(SP_ERR_MEMORY, "out of memory");
  s->run.mon.sum = &s->sum;
  const int rc = sp_run_setup(&s->run, scene, MPI_COMM_WORLD, start);
  if (rc != SP_OK) {
    sp_run_free(&s->run);
    free(s);
    return rc;
  }
  *out = s;
  return SP_OK;
}

/** @p scene set up from its initial cells; the test exits if that fails. */
static inline scene_run *scene_run_setup(const sp_scene *scene) {
  scene_run *s;
  CHECK_OK(scene_run_start(scene, NULL, &s));
  return s;
}

static inline void scene_run_free(scene_run **s) {
  if (!*s) return;
  sp_run_free(&(*s)->run);
  free(*s);
  *s = NULL;
}

#endif
