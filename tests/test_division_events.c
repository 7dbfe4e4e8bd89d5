/* A division is an event of the adaptive integrator (docs/time-stepping.md,
 * "After a division"), on a 1 -> 2 -> 4 division scene at constant volume
 * (s = 0), adaptive BDF2 with every default of the controller:
 * - the step right after a division has no error estimate (the history
 *   started over: no estimate mixes states from before and after the cut),
 *   the one after it has one;
 * - at most 2 failed attempts from each division until dt is back to half
 *   the dt of the division's step;
 * - the fast regrowth after it (time.event_steps steps from their own
 *   estimate) gets there in fewer steps than the PI law alone
 *   (time.event_steps = 0);
 * - each cell's mass is conserved to round-off in every step, the dividing
 *   ones included (a parent against its two daughters). */
#include <string.h>

#include "check.h"
#include "output_read.h"
#include "public/error.h"
#include "run/stepper.h"
#include "scene/scene.h"

#define GOAL_FAILED 2
#define MAX_CELLS 8

/** The row of energy.csv (row 0: the initial state) of accepted step @p s. */
static int row_of_step(const csv_table *e, int s) {
  for (int i = 1; i < e->n_rows; ++i)
    if ((int)at(e, i, "step") == s) return i;
  return -1;
}

/** Per division step: the steps until dt >= dt before / 2 and the failed
 *  attempts until then (at most GOAL_FAILED), the estimates of the two steps
 *  after it; returns the steps summed over the divisions. */
static int check_recovery(const char *run, const csv_table *e, const csv_table *d) {
  int last_division = -1, total = 0;
  for (int r = 0; r < d->n_rows; ++r) {
    const int s = (int)at(d, r, "step");
    if (s == last_division) continue; /* several cells at one step: one event */
    last_division = s;
    const int i0 = row_of_step(e, s);
    CHECK(i0 > 0 && i0 + 2 < e->n_rows, "%s: division step %d not followed by two steps", run,
          s);
    if (i0 <= 0 || i0 + 2 >= e->n_rows) continue;
    CHECK(at(e, i0 + 1, "error_estimate") < 0,
          "%s: the step after the division at step %d has an estimate (%g) across the cut", run,
          s, at(e, i0 + 1, "error_estimate"));
    CHECK(at(e, i0 + 2, "error_estimate") >= 0,
          "%s: the second step after the division at step %d has no estimate", run, s);
    const double dt_before = at(e, i0, "dt");
    int recovered = 0, failed = 0;
    for (int i = i0 + 1; i < e->n_rows && !recovered; ++i) {
      failed += (int)at(e, i, "failed_attempts");
      if (at(e, i, "dt") >= 0.5 * dt_before) recovered = i - i0;
    }
    printf("%s: division at step %d: dt before %.3g, first after %.3g, back to half in %d "
           "steps, %d failed attempts\n",
           run, s, dt_before, at(e, i0 + 1, "dt"), recovered, failed);
    CHECK(recovered > 0, "%s: step %d: dt never back to %.3g", run, s, 0.5 * dt_before);
    CHECK(failed <= GOAL_FAILED, "%s: step %d: %d failed attempts before dt recovered", run, s,
          failed);
    total += recovered;
  }
  return total;
}

/** Each cell's mass per step, a parent against its daughters in the step
 *  it divides: constant to round-off (s = 0). */
static void check_cell_masses(const csv_table *c, const csv_table *d) {
  double mass[2][MAX_CELLS] = {{0}};
  int n_prev = 0, cur = -1;
  double worst = 0;
  for (int i = 0; i <= c->n_rows; ++i) {
    const int s_i = i < c->n_rows ? (int)at(c, i, "step") : -1;
    if (i == c->n_rows || s_i != cur) {
      for (int k = 0; cur > 0 && k < n_prev; ++k) {
        double now = mass[1][k];
        for (int r = 0; r < d->n_rows; ++r)
          if ((int)at(d, r, "step") == cur && (int)at(d, r, "parent") == k + 1)
            now += mass[1][(int)at(d, r, "child") - 1];
        worst = fmax(worst, fabs(now - mass[0][k]) / mass[0][k]);
      }
      n_prev = 0;
      for (int k = 0; k < MAX_CELLS; ++k) {
        mass[0][k] = mass[1][k];
        n_prev += mass[1][k] != 0;
        mass[1][k] = 0;
      }
      if (i == c->n_rows) break;
      cur = s_i;
    }
    const int k = (int)at(c, i, "cell") - 1;
    CHECK(k >= 0 && k < MAX_CELLS, "cell %d", k + 1);
    if (k >= 0 && k < MAX_CELLS) mass[1][k] = at(c, i, "mass");
  }
  printf("largest relative change of a cell's mass in a step: %.2e\n", worst);
  CHECK(worst <= 1e-12, "a cell's mass changed by %.3g in a step", worst);
}

/** A run of the scene (@p event_steps: time.event_steps); its checks; the
 *  recovery steps summed over its divisions. */
static int run_scene(const char *out, const char *event_steps) {
  const char *set[] = {"mesh.refinements=3", "division.t_div=0.002", "time.t_end=0.0059",
                       "time.control=adaptive", "time.scheme=bdf2", "output.every=100000",
                       "output.pictures=false", "layout.support=full", event_steps};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml",
                         (int)(sizeof set / sizeof *set), set, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  printf("%s: %d steps, %d failed attempts, %d divisions\n", out, sum.steps, sum.failed_attempts,
         sum.divisions);
  CHECK(sum.divisions == 3 && sum.n_cells == 4, "%s: %d divisions, %d cells", out,
        sum.divisions, sum.n_cells);
  char path[256];
  csv_table e, c, d;
  snprintf(path, sizeof path, "%s/energy.csv", out);
  CHECK(csv_read(path, &e) == 0, "%s unreadable", path);
  snprintf(path, sizeof path, "%s/cells.csv", out);
  CHECK(csv_read(path, &c) == 0, "%s unreadable", path);
  snprintf(path, sizeof path, "%s/divisions.csv", out);
  CHECK(csv_read(path, &d) == 0 && d.n_rows == 3, "%s: divisions.csv", out);
  const int steps = check_recovery(out, &e, &d);
  check_cell_masses(&c, &d);
  csv_free(&e);
  csv_free(&c);
  csv_free(&d);
  sp_scene_destroy(&scene);
  return steps;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const int fast = run_scene("division_events", "time.event_steps=20");
  const int pi = run_scene("division_events_pi", "time.event_steps=0");
  printf("steps back to half the dt before, summed over the divisions: %d with the fast "
         "regrowth, %d with the PI law alone\n", fast, pi);
  CHECK(fast < pi, "the fast regrowth took %d steps, the PI law alone %d", fast, pi);
  MPI_Finalize();
  TEST_DONE();
}
