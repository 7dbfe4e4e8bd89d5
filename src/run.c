#include "run.h"

#include "agree.h"
#include "scene.h"

static int run_loaded(int rc, sp_scene *scene, const char *out_dir, MPI_Comm comm,
                      sp_step_callback on_step, void *user, sp_run_summary *summary) {
  sp_run_summary sum = {0};
  if (rc == SP_OK && !out_dir) rc = sp_error_set(SP_ERR_INPUT, "no output directory given");
  /* every rank loaded the scene, or every rank returns the error */
  rc = sp_agree(comm, rc);
  if (rc == SP_OK) rc = sp_stepper_run_with(scene, out_dir, comm, on_step, user, &sum);
  if (summary) *summary = sum;
  sp_scene_destroy(&scene);
  return rc;
}

int sp_run_file(const char *path, int n_set, const char *const *set, const char *out_dir,
                MPI_Comm comm, sp_step_callback on_step, void *user, sp_run_summary *summary) {
  sp_scene *scene = NULL;
  const int rc = sp_scene_load(path, n_set, set, &scene);
  return run_loaded(rc, scene, out_dir, comm, on_step, user, summary);
}

int sp_run_text(const char *name, const char *text, size_t len, int n_set,
                const char *const *set, const char *out_dir, MPI_Comm comm,
                sp_step_callback on_step, void *user, sp_run_summary *summary) {
  sp_scene *scene = NULL;
  const int rc = sp_scene_load_text(name, text, len, n_set, set, &scene);
  return run_loaded(rc, scene, out_dir, comm, on_step, user, summary);
}
