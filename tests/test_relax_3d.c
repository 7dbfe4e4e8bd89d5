/* Relaxation in 3D (issue 29, phase 1), through the run as `softpack run`
 * makes it (scene, box of hexahedra, spheres, RCB, MUMPS, backward Euler,
 * s = 0, no division, no shape term):
 *  - tests/scenes/sphere_3d.yaml (one sphere), two_spheres_3d.yaml (two
 *    touching spheres) and two_spheres_ellipsoid.yaml (two touching spheres
 *    in an ellipsoid with a buffer shell, mesh.type ellipsoid): every
 *    cell's mass is conserved to 1e-12 relative
 *    at every step (cells.csv, %.17g), and the energy (the pair term over
 *    k < l) never rises (1e-13 relative, as test_energy.c) and falls;
 *  - the 3D observables at t = 0: the volume inside the membrane is the
 *    sphere's 4/3 pi r^3 (within 6%: the level set counted at
 *    the Gauss points of elements of 0.36 r in the box, up to 0.6 r in the
 *    ellipsoid) and the centre its (x, y, z) (within 1e-3);
 *  - what a 3D run writes: energy.csv, cells.csv with the z centre
 *    (step,t,cell,mass,xc,yc,zc,core_mass,volume), energy.png, and no VTU
 *    fields or cell pictures (not yet in 3D). */
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "error.h"
#include "output_read.h"
#include "scene.h"
#include "stepper.h"

enum { MAX_CELLS = 4 };

static int exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

static void relax(const char *scene_file, const char *out, int expect_cells) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load(scene_file, 0, NULL, &scene));
  CHECK(scene->n_cells == expect_cells, "%s: %d cells", scene_file, scene->n_cells);
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  const int steps = scene->time.max_steps;
  CHECK(sum.steps == steps, "%s: %d steps of %d", scene_file, sum.steps, steps);

  /* energy.csv: never rises, falls overall */
  char path[512], line[2048];
  snprintf(path, sizeof path, "%s/energy.csv", out);
  const energy_trend tr = energy_trend_read(path);

  /* cells.csv: the 3D header; each cell's mass per step */
  snprintf(path, sizeof path, "%s/cells.csv", out);
  FILE *f = fopen(path, "r");
  CHECK(f != NULL, "%s missing", path);
  CHECK(fgets(line, sizeof line, f) &&
            strcmp(line, "step,t,cell,mass,xc,yc,zc,core_mass,volume\n") == 0,
        "cells.csv header: %s", line);
  double last_mass[MAX_CELLS], worst_mass = 0;
  int cell_rows = 0;
  while (fgets(line, sizeof line, f)) {
    int step, k;
    double t, mass, xc, yc, zc, core, volume;
    CHECK(sscanf(line, "%d,%lf,%d,%lf,%lf,%lf,%lf,%lf,%lf", &step, &t, &k, &mass, &xc, &yc, &zc,
                 &core, &volume) == 9,
          "cells row %s", line);
    CHECK(k >= 1 && k <= expect_cells, "cell %d", k);
    if (step == 0) {
      const sp_scene_cell *c = &scene->cells[k - 1];
      const double sphere = 4.0 / 3.0 * M_PI * c->radius * c->radius * c->radius;
      printf("%s: cell %d at t = 0: volume %.6g (sphere %.6g), centre (%.4f, %.4f, %.4f) "
             "(given (%.4f, %.4f, %.4f))\n",
             scene_file, k, volume, sphere, xc, yc, zc, c->x, c->y, c->z);
      CHECK(fabs(volume - sphere) < 0.06 * sphere, "cell %d: volume %g, sphere %g", k, volume,
            sphere);
      CHECK(fabs(xc - c->x) < 1e-3 && fabs(yc - c->y) < 1e-3 && fabs(zc - c->z) < 1e-3,
            "cell %d: centre (%g, %g, %g), given (%g, %g, %g)", k, xc, yc, zc, c->x, c->y, c->z);
    } else {
      const double rel = fabs(mass - last_mass[k - 1]) / last_mass[k - 1];
      worst_mass = fmax(worst_mass, rel);
      CHECK(rel <= 1e-12, "step %d cell %d: mass %.17g -> %.17g (relative %.3g)", step, k,
            last_mass[k - 1], mass, rel);
    }
    last_mass[k - 1] = mass;
    ++cell_rows;
  }
  fclose(f);
  printf("%s: %d steps, energy %.10g -> %.10g, %d rises (largest %.3g); largest relative mass "
         "change per step %.3g\n",
         scene_file, tr.rows - 1, tr.first, tr.last, tr.rises, tr.worst_rise, worst_mass);
  CHECK(tr.rows == steps + 1, "%d energy rows", tr.rows);
  CHECK(cell_rows == (steps + 1) * expect_cells, "%d cells rows", cell_rows);
  CHECK(tr.rises == 0, "the energy rose %d times (largest rise %.3g)", tr.rises, tr.worst_rise);
  CHECK(tr.last < tr.first, "the energy did not decrease: %g -> %g", tr.first, tr.last);

  /* what is written in 3D */
  snprintf(path, sizeof path, "%s/energy.png", out);
  CHECK(exists(path), "%s missing", path);
  snprintf(path, sizeof path, "%s/fields_000000.vtu", out);
  CHECK(!exists(path), "%s written on a 3D mesh", path);
  snprintf(path, sizeof path, "%s/cells_000000.png", out);
  CHECK(!exists(path), "%s written on a 3D mesh", path);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  relax(SP_SOURCE_DIR "/tests/scenes/sphere_3d.yaml", "test_relax_3d_one", 1);
  relax(SP_SOURCE_DIR "/tests/scenes/two_spheres_3d.yaml", "test_relax_3d_two", 2);
  relax(SP_SOURCE_DIR "/tests/scenes/two_spheres_ellipsoid.yaml", "test_relax_3d_ellipsoid", 2);
  MPI_Finalize();
  TEST_DONE();
}
