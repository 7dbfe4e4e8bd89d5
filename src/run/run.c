#include "public/run.h"

#include <stdlib.h>
#include <string.h>

#include "base/agree.h"
#include "run/checkpoint.h"
#include "io/initial.h"
#include "run/monitor.h"
#include "scene/scene.h"
#include "run/stepper.h"
#include "run/stop.h"

static int run_loaded(int rc, sp_scene *scene, const sp_run_start *start, const char *out_dir,
                      MPI_Comm comm, sp_step_callback on_step, void *user,
                      sp_run_summary *summary) {
  sp_run_summary sum = {0};
  if (rc == SP_OK && !out_dir) rc = sp_error_set(SP_ERR_INPUT, "no output directory given");
  /* every rank loaded the scene (and its checkpoint), or every rank
   * returns the error */
  rc = sp_agree(comm, rc);
  if (rc == SP_OK) rc = sp_stepper_run_from(scene, start, out_dir, comm, on_step, user, &sum);
  if (summary) *summary = sum;
  sp_scene_destroy(&scene);
  return rc;
}

int sp_run_file(const char *path, int n_set, const char *const *set, const char *out_dir,
                MPI_Comm comm, sp_step_callback on_step, void *user, sp_run_summary *summary) {
  return sp_run_file_restart(path, n_set, set, out_dir, NULL, comm, on_step, user, summary);
}

int sp_run_text(const char *name, const char *text, size_t len, int n_set,
                const char *const *set, const char *out_dir, MPI_Comm comm,
                sp_step_callback on_step, void *user, sp_run_summary *summary) {
  sp_scene *scene = NULL;
  const int rc = sp_scene_load_text(name, text, len, n_set, set, &scene);
  const sp_run_start start = {.scene_text = text, .scene_len = len, .n_set = n_set, .set = set};
  return run_loaded(rc, scene, &start, out_dir, comm, on_step, user, summary);
}

/** Keys a continued run may change: when it ends and what it writes (and
 *  where its initial fields came from, which the checkpoint replaces). */
static int safe_to_change(const char *key) {
  return strncmp(key, "output.", 7) == 0 || strcmp(key, "time.t_end") == 0 ||
         strcmp(key, "time.max_steps") == 0 || strncmp(key, "initial.", 8) == 0;
}

/** Open the checkpoint @p restart names and check @p scene (read from
 *  @p scene_path) against its. */
static int open_checkpoint(const sp_restart *restart, const char *scene_path,
                           const sp_scene *scene, sp_checkpoint *ck) {
  char found[4096];
  const char *path = restart->checkpoint;
  if (!path) {
    SP_CALL(sp_checkpoint_find_newest(restart->resume_dir, found, sizeof found));
    path = found;
  }
  SP_CALL(sp_checkpoint_open(path, ck));
  if (restart->as_initial) return SP_OK; /* any scene on the same mesh */
  size_t len;
  int n_set;
  const char *const *set;
  const char *text = sp_checkpoint_scene(*ck, &len, &n_set, &set);
  sp_scene *saved = NULL; /* its file names as from the scene file's directory */
  int rc = sp_scene_load_text(scene_path, text, len, n_set, set, &saved);
  if (rc != SP_OK) {
    rc = sp_error_set(SP_ERR_INPUT, "checkpoint '%s': its scene does not load with this "
                                    "softpack (%s)", path, sp_error_message());
  } else {
    char key[256];
    if (sp_scene_first_difference(saved, scene, safe_to_change, key, sizeof key))
      rc = sp_error_set(SP_ERR_INPUT,
                        "--restart %s: %s differs from the checkpoint's scene; a continued run "
                        "may change only time.t_end, time.max_steps and output.* "
                        "(--restart-as-initial starts a new run from the checkpoint's state)",
                        path, key);
  }
  sp_scene_destroy(&saved);
  if (rc != SP_OK) sp_checkpoint_close(ck);
  return rc;
}

int sp_run_file_restart(const char *path, int n_set, const char *const *set,
                        const char *out_dir, const sp_restart *restart, MPI_Comm comm,
                        sp_step_callback on_step, void *user, sp_run_summary *summary) {
  char *text = NULL;
  size_t len = 0;
  sp_scene *scene = NULL;
  int rc = sp_scene_read_file(path, &text, &len);
  if (rc == SP_OK) rc = sp_scene_load_text(path, text, len, n_set, set, &scene);
  sp_checkpoint ck = NULL;
  int as_initial = restart && restart->as_initial;
  if (rc == SP_OK && restart && (restart->checkpoint || restart->resume_dir)) {
    rc = open_checkpoint(restart, path, scene, &ck);
  } else if (rc == SP_OK && sp_initial_from_checkpoint(scene)) { /* initial.from: FILE.h5 */
    rc = sp_checkpoint_open(scene->initial.from, &ck);
    if (rc != SP_OK) rc = sp_error_set(rc, "initial.from: %s", sp_error_message());
    as_initial = 1;
  }
  const int from_scene = ck && !(restart && (restart->checkpoint || restart->resume_dir));
  const sp_run_start start = {.checkpoint = ck, .as_initial = as_initial, .from_scene = from_scene,
                              .scene_text = text, .scene_len = len, .n_set = n_set, .set = set};
  rc = run_loaded(rc, scene, &start, out_dir, comm, on_step, user, summary);
  sp_checkpoint_close(&ck);
  free(text);
  return rc;
}

void sp_run_request_stop(void) { sp_stop_request(); }

/** The run of a step callback's @p info (NULL: not from a callback). */
static const sp_run *callback_run(const sp_step_info *info) {
  return info ? (const sp_run *)info->run : NULL;
}

int sp_step_mesh(const sp_step_info *info, int *dim, int *n_nodes, const double **coords,
                 int *n_elements, int *nodes_per_element, const int **elements) {
  const sp_run *run = callback_run(info);
  SP_CHECK(run && run->mesh, SP_ERR_INPUT, "sp_step_mesh: not called with a step callback's info");
  const sp_mesh *m = run->mesh;
  if (dim) *dim = m->dim;
  if (n_nodes) *n_nodes = m->n_nodes;
  if (coords) *coords = m->xy;
  if (n_elements) *n_elements = m->n_elems;
  if (nodes_per_element) *nodes_per_element = m->nodes_per_elem;
  if (elements) *elements = m->elem;
  return SP_OK;
}

int sp_step_cell_field(const sp_step_info *info, int cell, double *c) {
  const sp_run *run = callback_run(info);
  SP_CHECK(run && run->layout && run->state, SP_ERR_INPUT,
           "sp_step_cell_field: not called with a step callback's info");
  SP_CHECK(cell >= 0 && cell < run->layout->n_cells, SP_ERR_INPUT,
           "sp_step_cell_field: cell %d, the run has cells 0 to %d", cell,
           run->layout->n_cells - 1);
  for (int i = 0; i < run->layout->n_nodes; ++i) {
    const int p = sp_layout_pair(run->layout, cell, i);
    c[i] = p >= 0 ? run->state[2 * p] : 0.0;
  }
  return SP_OK;
}
