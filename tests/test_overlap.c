/* The hard case of the stack issue: cells overlapping at t = 0 with
 * lambda = 100 at the paper's dt. Newton must fail at that dt (else the
 * case tests nothing), the stepper must shrink dt, retry, never accept an
 * unconverged step, grow dt back and reach t_end. */
#include "check.h"
#include "public/error.h"
#include "scene/scene.h"
#include "softpack_solver.h"
#include "run/stepper.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/overlap_hard.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_overlap_out", MPI_COMM_WORLD, &sum));
  printf("%d steps, %d failed attempts retried, smallest dt %.3g, t = %.6g\n", sum.steps,
         sum.failed_attempts, sum.dt_smallest, sum.t_final);
  CHECK(sum.failed_attempts >= 1, "Newton never failed: the case is not hard");
  CHECK(sum.dt_smallest <= scene->time.dt * 1e-2, "smallest dt %g", sum.dt_smallest);
  CHECK_NEAR(sum.t_final, scene->time.t_end, 1e-12);
  /* dt grew back: far fewer steps than t_end / smallest dt */
  CHECK(sum.steps < 0.2 * scene->time.t_end / sum.dt_smallest, "%d steps", sum.steps);

  /* The same scene with retries forbidden stops with SP_ERR_SOLVER. */
  sp_scene *strict;
  const char *set[] = {"time.max_retries=1"};
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/overlap_hard.yaml", 1, set, &strict));
  int rc = sp_stepper_run(strict, "test_overlap_strict_out", MPI_COMM_WORLD, &sum);
  CHECK(rc == SP_ERR_SOLVER, "rc %d: %s", rc, sp_error_message());
  printf("with time.max_retries=1: %s\n", sp_error_message());
  CHECK(sum.steps == 0, "an unconverged step was accepted (%d steps)", sum.steps);
  sp_scene_destroy(&scene);
  sp_scene_destroy(&strict);
  MPI_Finalize();
  TEST_DONE();
}
