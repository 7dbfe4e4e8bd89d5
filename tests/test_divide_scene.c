/* A short 1 -> 2 -> 4 division scene at constant volume (s = 0, age
 * criterion, sharp cut, algorithm 2 after each division): it ends with
 * 4 cells after 3 divisions, the total cell mass drifts by at most 1e-8
 * relative, each cell's mass is within 10% of the mean, and
 * divisions.csv records the splits with each split conserving the parent's
 * mass. */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_divide_out", MPI_COMM_WORLD, &sum));
  printf("%d steps, %d divisions, %d cells, smallest dt %.3g\n", sum.steps, sum.divisions,
         sum.n_cells, sum.dt_smallest);
  CHECK(sum.n_cells == 4, "%d cells at the end", sum.n_cells);
  CHECK(sum.divisions == 3, "%d divisions", sum.divisions);
  /* algorithm 2: dt = dt_bar 1e-6 right after a division */
  CHECK_NEAR(sum.dt_smallest, scene->time.dt * 1e-6, 1e-20);

  int n0, n1;
  double m0[16], m1[16];
  double total0 = cells_mass_at("test_divide_out/cells.csv", 0, 16, &n0, m0);
  double total1 = cells_mass_at("test_divide_out/cells.csv", sum.steps, 16, &n1, m1);
  double drift = fabs(total1 - total0) / total0;
  printf("total cell mass %.15g -> %.15g (relative drift %.3g)\n", total0, total1, drift);
  CHECK(n0 == 1 && n1 == 4, "cells at start %d, end %d", n0, n1);
  CHECK(drift <= 1e-8, "total mass drift %.3g", drift);
  for (int k = 0; k < n1; ++k) {
    double dev = fabs(m1[k] / (total1 / n1) - 1);
    printf("cell %d: mass %.6g (%.1f%% from the mean)\n", k + 1, m1[k], 100 * dev);
    CHECK(dev <= 0.10, "cell %d mass %.3g is %.1f%% from the mean", k + 1, m1[k], 100 * dev);
  }

  FILE *f = fopen("test_divide_out/divisions.csv", "r");
  CHECK(f != NULL, "divisions.csv missing");
  char line[1024];
  int rows = 0;
  if (f && fgets(line, sizeof line, f)) {
    while (fgets(line, sizeof line, f)) {
      double t, angle, before, after_p, after_c;
      int step, parent, child;
      if (sscanf(line, "%lf,%d,%d,%d,%lf,%lf,%lf,%lf", &t, &step, &parent, &child, &angle,
                 &before, &after_p, &after_c) != 8)
        continue;
      ++rows;
      CHECK(fabs(after_p + after_c - before) <= 1e-12 * before,
            "division %d: %.17g + %.17g != %.17g", rows, after_p, after_c, before);
      CHECK(fabs(after_p / after_c - 1) < 0.1, "division %d: unequal daughters %g %g", rows,
            after_p, after_c);
    }
  }
  if (f) fclose(f);
  CHECK(rows == 3, "%d rows in divisions.csv", rows);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
