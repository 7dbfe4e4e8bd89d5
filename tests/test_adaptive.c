/* Adaptive time stepping in whole runs (time.control adaptive, BE and BDF2)
 * on a 1 -> 2 -> 4 division scene at constant volume (s = 0):
 * - every accepted step's error estimate is <= 1 (rejected steps are never
 *   accepted) and the runs did estimate;
 * - the cells' total mass changes by at most 1e-12 relative per step,
 *   through both divisions and every step sequence, with full supports and
 *   with local ones (BDF2's history carried across support changes);
 * - the age divisions land on their times (t_div and 2 t_div) to 1e-12;
 * - output.interval writes fields at its multiples (to 1e-12), the last
 *   step lands on t_end. */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

#define T_DIV 0.002
#define T_END 0.0045
#define INTERVAL 0.001

static void check_run(const char *scheme, const char *support) {
  char out[64], set_scheme[64], set_support[64];
  snprintf(out, sizeof out, "adaptive_%s_%s", scheme, support);
  snprintf(set_scheme, sizeof set_scheme, "time.scheme=%s", scheme);
  snprintf(set_support, sizeof set_support, "layout.support=%s", support);
  const char *set[] = {"mesh.refinements=3", "division.t_div=0.002", "time.t_end=0.0045",
                       "time.control=adaptive", set_scheme, "time.rtol=1e-2",
                       "time.atol=1e-2", "output.interval=0.001", "output.every=100000",
                       "output.pictures=false", set_support};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 11, set, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  printf("%s, %s supports: %d steps, %d failed attempts, %d divisions, %d support changes, "
         "t = %.17g\n", scheme, support, sum.steps, sum.failed_attempts, sum.divisions,
         sum.layout_changes, sum.t_final);
  if (strcmp(support, "local") == 0)
    CHECK(sum.layout_changes >= 3, "only %d support changes", sum.layout_changes);
  CHECK(sum.divisions == 3 && sum.n_cells == 4, "%d divisions, %d cells", sum.divisions,
        sum.n_cells);
  CHECK(sum.t_final == T_END, "ended at t = %.17g", sum.t_final);

  char path[256];
  csv_table e;
  snprintf(path, sizeof path, "%s/energy.csv", out);
  CHECK(csv_read(path, &e) == 0, "%s unreadable", path);
  int estimated = 0;
  for (int i = 1; i < e.n_rows; ++i) {
    const double err = at(&e, i, "error_estimate");
    CHECK(err <= 1.0, "%s: step %g accepted with error estimate %g", scheme, at(&e, i, "step"),
          err);
    estimated += err >= 0;
  }
  CHECK(estimated >= e.n_rows / 2, "%s: only %d of %d steps estimated", scheme, estimated,
        e.n_rows - 1);

  /* the total mass per step: constant to round-off */
  csv_table c;
  snprintf(path, sizeof path, "%s/cells.csv", out);
  CHECK(csv_read(path, &c) == 0, "%s unreadable", path);
  double total_prev = -1, total = 0, worst = 0;
  int step = 0;
  for (int i = 0; i <= c.n_rows; ++i) {
    if (i == c.n_rows || at(&c, i, "step") != step) {
      if (total_prev > 0) worst = fmax(worst, fabs(total - total_prev) / total_prev);
      total_prev = total;
      total = 0;
      if (i == c.n_rows) break;
      step = (int)at(&c, i, "step");
    }
    total += at(&c, i, "mass");
  }
  printf("%s: largest relative change of the total mass in a step %.2e\n", scheme, worst);
  CHECK(worst <= 1e-12, "%s: total mass changed by %.3g in a step", scheme, worst);

  /* each cell's own mass per step (a parent against its two daughters in
   * the step it divides): with s = 0 every step conserves it, the steps
   * after a cut too (BE from the cut state, then BDF2 whose c_hat weights
   * sum to one) */
  csv_table d0;
  snprintf(path, sizeof path, "%s/divisions.csv", out);
  CHECK(csv_read(path, &d0) == 0, "%s unreadable", path);
  double mass[2][8] = {{0}};
  int n_prev = 0, cur = -1, worst_cell_step = -1;
  double worst_cell = 0;
  for (int i = 0; i <= c.n_rows; ++i) {
    const int s_i = i < c.n_rows ? (int)at(&c, i, "step") : -1;
    if (i == c.n_rows || s_i != cur) { /* step cur complete: compare with the last */
      for (int k = 0; cur > 0 && k < n_prev; ++k) {
        double now = mass[1][k];
        for (int r = 0; r < d0.n_rows; ++r)
          if ((int)at(&d0, r, "step") == cur && (int)at(&d0, r, "parent") == k + 1)
            now += mass[1][(int)at(&d0, r, "child") - 1];
        const double rel = fabs(now - mass[0][k]) / mass[0][k];
        if (rel > worst_cell) worst_cell = rel, worst_cell_step = cur;
      }
      n_prev = 0;
      for (int k = 0; k < 8; ++k) {
        mass[0][k] = mass[1][k];
        n_prev += mass[1][k] != 0;
        mass[1][k] = 0;
      }
      if (i == c.n_rows) break;
      cur = s_i;
    }
    const int k = (int)at(&c, i, "cell") - 1;
    CHECK(k >= 0 && k < 8, "cell %d", k + 1);
    mass[1][k] = at(&c, i, "mass");
  }
  printf("%s: largest relative change of a cell's mass in a step %.2e (step %d)\n", scheme,
         worst_cell, worst_cell_step);
  CHECK(worst_cell <= 1e-12, "%s: a cell's mass changed by %.3g in step %d", scheme, worst_cell,
        worst_cell_step);

  /* a division is an event: the step right after it starts the scheme
   * over without an estimate (none mixes states from before and after the
   * cut), and the one after that is estimated */
  for (int r = 0; r < d0.n_rows; ++r) {
    const int after = (int)at(&d0, r, "step") + 1;
    for (int i = 1; i < e.n_rows; ++i) {
      if ((int)at(&e, i, "step") == after)
        CHECK(at(&e, i, "error_estimate") < 0,
              "%s: the step %d after a division has an estimate across the cut", scheme, after);
      if ((int)at(&e, i, "step") == after + 1)
        CHECK(at(&e, i, "error_estimate") >= 0,
              "%s: the second step %d after a division has no error estimate", scheme,
              after + 1);
    }
  }
  free(d0.v);
  free(c.v);
  free(e.v);

  /* divisions at t_div (the first cell) and 2 t_div (its daughters) */
  csv_table d;
  snprintf(path, sizeof path, "%s/divisions.csv", out);
  CHECK(csv_read(path, &d) == 0 && d.n_rows == 3, "%s: divisions.csv", scheme);
  for (int i = 0; i < d.n_rows; ++i) {
    const double t = at(&d, i, "t"), want = i == 0 ? T_DIV : 2 * T_DIV;
    CHECK(fabs(t - want) <= 1e-12, "%s: division %d at t = %.17g, due at %.17g", scheme, i + 1,
          t, want);
  }
  free(d.v);

  /* fields at every multiple of output.interval */
  snprintf(path, sizeof path, "%s/fields.pvd", out);
  char *pvd = slurp(path, NULL);
  CHECK(pvd != NULL, "%s missing", path);
  for (int k = 1; pvd && k * INTERVAL <= T_END; ++k) {
    int found = 0;
    for (const char *p = pvd; (p = strstr(p, "timestep=\"")); ++p)
      found |= fabs(strtod(p + 10, NULL) - k * INTERVAL) <= 1e-12;
    CHECK(found, "%s: no fields written at t = %g", scheme, k * INTERVAL);
  }
  free(pvd);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  check_run("be", "full");
  check_run("bdf2", "full");
  check_run("bdf2", "local");
  MPI_Finalize();
  TEST_DONE();
}
