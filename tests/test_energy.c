/* Without source, division or shape term the energy (pair term over k<l)
 * is the Lyapunov function of the dynamics: over 200 steps of two
 * overlapping cells it never increases (up to round-off, 1e-13 relative). */
#include <string.h>

#include "check.h"
#include "output_read.h"
#include "public/error.h"
#include "scene/scene.h"
#include "run/stepper.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/two_overlapping.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_energy_out", MPI_COMM_WORLD, &sum));
  CHECK(sum.steps == 200, "%d steps", sum.steps);
  const energy_trend tr = energy_trend_read("test_energy_out/energy.csv");
  printf("%d rows, energy %.10g -> %.10g, %d rises (largest %.3g)\n", tr.rows, tr.first,
         tr.last, tr.rises, tr.worst_rise);
  CHECK(tr.rows == 201, "%d energy rows", tr.rows);
  CHECK(tr.rises == 0, "the energy rose %d times (largest rise %.3g)", tr.rises, tr.worst_rise);
  CHECK(tr.last < tr.first, "the energy did not decrease: %g -> %g", tr.first, tr.last);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
