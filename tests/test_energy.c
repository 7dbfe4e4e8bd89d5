/* Without source, division or shape term the energy (pair term over k<l)
 * is the Lyapunov function of the dynamics: over 200 steps of two
 * overlapping cells it never increases (up to round-off, 1e-13 relative). */
#include <string.h>

#include "check.h"
#include "error.h"
#include "scene.h"
#include "stepper.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/two_overlapping.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_energy_out", MPI_COMM_WORLD, &sum));
  CHECK(sum.steps == 200, "%d steps", sum.steps);
  FILE *f = fopen("test_energy_out/energy.csv", "r");
  CHECK(f != NULL, "energy.csv missing");
  char line[1024];
  CHECK(fgets(line, sizeof line, f) && strstr(line, "energy"), "header");
  int rows = 0, rises = 0;
  double prev = INFINITY, first = 0, worst_rise = 0;
  while (fgets(line, sizeof line, f)) {
    int step, its, n;
    double t, dt, e;
    CHECK(sscanf(line, "%d,%lf,%lf,%d,%d,%lf", &step, &t, &dt, &its, &n, &e) == 6, "row %s", line);
    if (rows == 0) first = e;
    if (e > prev + 1e-13 * fabs(prev)) {
      ++rises;
      if (e - prev > worst_rise) worst_rise = e - prev;
    }
    prev = e;
    ++rows;
  }
  fclose(f);
  printf("%d rows, energy %.10g -> %.10g, %d rises (largest %.3g)\n", rows, first, prev, rises,
         worst_rise);
  CHECK(rows == 201, "%d energy rows", rows);
  CHECK(rises == 0, "the energy rose %d times (largest rise %.3g)", rises, worst_rise);
  CHECK(prev < first, "the energy did not decrease: %g -> %g", first, prev);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
