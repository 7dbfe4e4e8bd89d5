/* The growth source in time under BDF2 (source.indicator, src/run/step.c): one
 * cell growing by 1.4x (tests/scenes/grow_one.yaml, fixed steps
 * dt = T / N). The source is s_bar on the nodes inside omega_k (c_k >= 1/2).
 * Taken from c^n (`previous`, the paper's algorithm 3) the indicator lags
 * the moving interface by a step, where BDF2 takes its right-hand side at
 * t^{n+1}: the cell's mass misses about s_bar x dA x dt, dA the growth of
 * omega's area over the run (dA ~ the mass's growth dm, c ~ 1 inside): a
 * first-order error, smooth in time, which BDF2's error estimate cannot
 * see. Taken from c extrapolated linearly to t^{n+1} (`extrapolated`, the
 * default) the lag is O(dt^2). What remains is the nodes' switching: a node
 * whose c hovers near 1/2 switches a step earlier or later, a jump of
 * s_bar x its weight that does not shrink with dt (here ~1e-5 of mass
 * from N = 32 on; N = 128 and 256 agree to round-off).
 * Asserted, against the mass at T of N = 256 (`extrapolated`):
 * - `previous` has the lag: at N = 8 ... 64 its error is within a factor 2
 *   of s_bar dm dt, and its observed order over N = 16 -> 64 is 1 (within
 *   0.3); at N = 256 it is within twice its lag of the limit;
 * - `extrapolated` has not: where the lag dominates (N = 8, 16) its error
 *   is below a quarter of the lag (and of 0.2% of the mass at N = 8, the
 *   paper's dt = 2.5e-4), whatever the switching adds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

#define T_END 0.002
#define S_BAR 200.0

/** The cell's mass at T of a run with N steps and the indicator @p ind;
 *  *m0: its mass at t = 0. */
static double mass_at_end(int n, const char *ind, double *m0) {
  char out[64], set_dt[64], set_ind[64];
  snprintf(out, sizeof out, "source_time_%s_%d", ind, n);
  snprintf(set_dt, sizeof set_dt, "time.dt=%.17g", T_END / n);
  snprintf(set_ind, sizeof set_ind, "source.indicator=%s", ind);
  const char *set[] = {set_dt, set_ind};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/grow_one.yaml", 2, set, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  CHECK(sum.steps == n && fabs(sum.t_final - T_END) < 1e-15, "%s N = %d: %d steps to t = %g",
        ind, n, sum.steps, sum.t_final);
  char path[128];
  snprintf(path, sizeof path, "%s/cells.csv", out);
  csv_table c;
  CHECK(csv_read(path, &c) == 0, "%s unreadable", path);
  *m0 = at(&c, 0, "mass");
  const double m = at(&c, c.n_rows - 1, "mass");
  free(c.v);
  return m;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  double m0;
  const double ref = mass_at_end(256, "extrapolated", &m0);
  const double ref_prev = mass_at_end(256, "previous", &m0);
  const double dm = ref - m0;
  const int ns[] = {8, 16, 32, 64};
  double err_prev[4];
  for (int i = 0; i < 4; ++i) {
    double m;
    err_prev[i] = fabs(mass_at_end(ns[i], "previous", &m) - ref);
    const double err_ext = fabs(mass_at_end(ns[i], "extrapolated", &m) - ref);
    const double lag = S_BAR * dm * T_END / ns[i];
    printf("N = %3d: mass error previous %.3e (the lag s dm dt %.3e), extrapolated %.3e\n",
           ns[i], err_prev[i], lag, err_ext);
    CHECK(err_prev[i] > 0.5 * lag && err_prev[i] < 2 * lag,
          "N = %d: previous's error %.3g is not the one-step lag %.3g", ns[i], err_prev[i], lag);
    if (ns[i] <= 16)
      CHECK(err_ext < 0.25 * lag, "N = %d: extrapolated's error %.3g, the lag %.3g", ns[i],
            err_ext, lag);
    if (ns[i] == 8)
      CHECK(err_ext < 2e-3 * ref, "extrapolated, N = 8: relative error %.3g", err_ext / ref);
  }
  const double order = log(err_prev[1] / err_prev[3]) / log(4.0);
  printf("previous: observed order %.2f (N = 16 -> 64); mass %.6f -> %.6f; previous at "
         "N = 256 off by %.2e\n", order, m0, ref, fabs(ref_prev - ref));
  CHECK(order > 0.7 && order < 1.3, "previous: order %.2f, expected 1", order);
  CHECK(fabs(ref_prev - ref) < 2 * S_BAR * dm * T_END / 256,
        "previous at N = 256 is %.3g from the limit, more than its lag", fabs(ref_prev - ref));
  MPI_Finalize();
  TEST_DONE();
}
