/* solver.predictor = linear: Newton starts from the last state plus its
 * last increment x min(dt / dt_last, 2), against the last state (none).
 * - A pushed cell on local supports (tests/scenes/local_push.yaml to
 *   t = 0.01, 72 steps; its supports change as it moves: the increment
 *   moves with (cell, node)): fewer Newton iterations over the run, the same steps,
 *   the energy at every step and every cell's mass and centre at the end
 *   the same to the Newton tolerance (1e-8 relative, centres 1e-7), every
 *   cell's mass conserved to 1e-10 across the support changes.
 * - One cell dividing into two and four (tests/scenes/divide_1_2_4.yaml,
 *   the predictor starts over after each division): the same divisions
 *   at the same steps and the same energies to 1e-8, fewer iterations. */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

static sp_run_summary run(const char *scene_file, const char *predictor, const char *out) {
  char path[1024], set_pred[64];
  snprintf(path, sizeof path, "%s/tests/scenes/%s", SP_SOURCE_DIR, scene_file);
  snprintf(set_pred, sizeof set_pred, "solver.predictor=%s", predictor);
  const char *set[] = {set_pred, "output.pictures=false"};
  sp_scene *scene;
  sp_run_summary sum = {0};
  CHECK_OK(sp_scene_load(path, 2, set, &scene));
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  return sum;
}

/* Cell k's mass and centre at the last step of out/cells.csv. */
static void last_cells(const char *dir, int n, double *m, double *x, double *y) {
  char path[512];
  snprintf(path, sizeof path, "%s/cells.csv", dir);
  csv_table c;
  CHECK(csv_read(path, &c) == 0, "%s unreadable", path);
  const double last = at(&c, c.n_rows - 1, "step");
  for (int i = 0; i < c.n_rows; ++i) {
    if (at(&c, i, "step") != last) continue;
    const int k = (int)at(&c, i, "cell") - 1;
    if (k < 0 || k >= n) continue;
    m[k] = at(&c, i, "mass");
    x[k] = at(&c, i, "xc");
    y[k] = at(&c, i, "yc");
  }
  free(c.v);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);

  /* 1. the pushed cell: support changes carry the increment */
  const sp_run_summary none = run("local_push.yaml", "none", "pred_push_none");
  const sp_run_summary lin = run("local_push.yaml", "linear", "pred_push_linear");
  const double de = energy_difference("pred_push_none", "pred_push_linear");
  double m0[2] = {0, 0}, m1[2] = {0, 0}, x0[2], y0[2], x1[2], y1[2];
  last_cells("pred_push_none", 2, m0, x0, y0);
  last_cells("pred_push_linear", 2, m1, x1, y1);
  double m_start[2] = {0, 0};
  int n_start = 0;
  cells_mass_at("pred_push_linear/cells.csv", 0, 2, &n_start, m_start);
  CHECK(n_start == 2, "%d cells at step 0", n_start);
  printf("pushed cell: %d steps, %ld Newton iterations with the predictor against %ld without; "
         "%d / %d support changes; energy within %.2e\n",
         lin.steps, lin.newton_its, none.newton_its, lin.layout_changes, none.layout_changes, de);
  CHECK(lin.steps == none.steps && lin.layout_changes >= 1, "steps %d / %d, %d support changes",
        lin.steps, none.steps, lin.layout_changes);
  CHECK(lin.newton_its < none.newton_its, "%ld iterations with the predictor, %ld without",
        lin.newton_its, none.newton_its);
  CHECK(de <= 1e-8, "energies differ by %.3e", de);
  for (int k = 0; k < 2; ++k) {
    printf("cell %d: mass %.15g (start %.15g), centre (%.9f, %.9f) against (%.9f, %.9f)\n", k + 1,
           m1[k], m_start[k], x1[k], y1[k], x0[k], y0[k]);
    CHECK(fabs(m1[k] - m_start[k]) <= 1e-10 * m_start[k], "cell %d mass %.17g -> %.17g", k + 1,
          m_start[k], m1[k]);
    CHECK(fabs(m1[k] - m0[k]) <= 1e-8 * m0[k], "cell %d mass %.17g against %.17g", k + 1, m1[k],
          m0[k]);
    CHECK(fabs(x1[k] - x0[k]) <= 1e-7 && fabs(y1[k] - y0[k]) <= 1e-7, "cell %d centre", k + 1);
  }

  /* 2. divisions: the predictor starts over */
  const sp_run_summary dn = run("divide_1_2_4.yaml", "none", "pred_div_none");
  const sp_run_summary dl = run("divide_1_2_4.yaml", "linear", "pred_div_linear");
  const double dd = energy_difference("pred_div_none", "pred_div_linear");
  printf("divisions: %d cells, %d divisions, %ld Newton iterations with the predictor against "
         "%ld without; energy within %.2e\n",
         dl.n_cells, dl.divisions, dl.newton_its, dn.newton_its, dd);
  CHECK(dl.n_cells == 4 && dn.n_cells == 4 && dl.divisions == dn.divisions && dl.steps == dn.steps,
        "cells %d / %d, divisions %d / %d, steps %d / %d", dl.n_cells, dn.n_cells, dl.divisions,
        dn.divisions, dl.steps, dn.steps);
  CHECK(dl.newton_its < dn.newton_its, "%ld iterations with the predictor, %ld without",
        dl.newton_its, dn.newton_its);
  CHECK(dd <= 1e-8, "energies differ by %.3e", dd);
  MPI_Finalize();
  TEST_DONE();
}
