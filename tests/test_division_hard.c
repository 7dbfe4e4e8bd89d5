/* Hard cases of division:
 * - eight cells dividing in the same step: 8 -> 16 cells, eight rows of
 *   divisions.csv with the same step, each split conserving its parent's
 *   mass, total mass conserved; one cell is pressed against the buffer ring;
 * - a division whose first step fails Newton: without algorithm 2
 *   (n_div = 0, m = 0) the first step after a sharp cut is taken at the
 *   full dt and needs 5 Newton iterations where a steady step needs 2;
 *   with solver.newton_max_its = 4 it fails, is retried with a smaller dt
 *   and the run goes on (never accepting the failed step);
 * - solver.newton_divergence: attempts that blow up stop as soon as |F|
 *   passes the ratio, the run is otherwise the same. */
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

static int count_rows(const char *path, int *same_step) {
  FILE *f = fopen(path, "r");
  char line[1024];
  int rows = 0, first_step = -1;
  *same_step = 1;
  if (!f) return -1;
  if (!fgets(line, sizeof line, f)) { fclose(f); return -1; }
  while (fgets(line, sizeof line, f)) {
    double t, angle, before, after_p, after_c;
    int step, parent, child;
    if (sscanf(line, "%lf,%d,%d,%d,%lf,%lf,%lf,%lf", &t, &step, &parent, &child, &angle, &before,
               &after_p, &after_c) != 8)
      continue;
    if (first_step < 0) first_step = step;
    if (step != first_step) *same_step = 0;
    CHECK(fabs(after_p + after_c - before) <= 1e-12 * before, "split of cell %d: %.17g + %.17g != %.17g",
          parent, after_p, after_c, before);
    ++rows;
  }
  fclose(f);
  return rows;
}

/* The failed attempts of a run, as the step callback sees them
 * (sp_step_info.attempts), in order. */
#define MAX_ATTEMPTS 64
typedef struct {
  int n;
  sp_attempt a[MAX_ATTEMPTS];
} attempt_log;

static int log_attempts(const sp_step_info *info, void *user) {
  attempt_log *log = user;
  for (int i = 0; i < info->failed_attempts; ++i)
    if (log->n < MAX_ATTEMPTS) log->a[log->n++] = info->attempts[i];
  return 0;
}

/* Runs @p scene into @p out, its failed attempts into @p log; stderr (one
 * line per failed attempt, for the user) into @p err_path, to keep the
 * test's output readable. */
static void run_logging(const sp_scene *scene, const char *out, const char *err_path,
                        attempt_log *log, sp_run_summary *sum) {
  log->n = 0;
  fflush(stderr);
  const int saved = dup(fileno(stderr));
  CHECK(freopen(err_path, "w", stderr) != NULL, "cannot redirect stderr to %s", err_path);
  CHECK_OK(sp_stepper_run_with(scene, out, MPI_COMM_WORLD, log_attempts, log, sum));
  fflush(stderr);
  dup2(saved, fileno(stderr));
  close(saved);
  CHECK(log->n == sum->failed_attempts && log->n <= MAX_ATTEMPTS,
        "%d failed attempts seen by the callback, %d in the summary", log->n,
        sum->failed_attempts);
}

static void print_history(const sp_attempt *a) {
  for (int i = 0; i < a->n_residuals; ++i) printf(" %.2e", a->residual_norms[i]);
}

/* Runs divide_1_2_4 without algorithm 2 at dt = 4e-3 with the given
 * newton_divergence ("0": off); Newton blows up after the cut. */
static void run_divergent(const char *ratio, const char *out, const char *err,
                          attempt_log *log, sp_run_summary *sum) {
  char set_ratio[64];
  snprintf(set_ratio, sizeof set_ratio, "solver.newton_divergence=%s", ratio);
  /* steps of 4e-3 and 2e-3 (output.interval makes the first land on
   * 4e-3, where an even split of t_end would take two of 3e-3) */
  const char *set[] = {"division.n_div=0", "division.m=0", "time.dt=4e-3", "time.t_end=0.006",
                       "output.interval=4e-3", "output.pictures=false", set_ratio};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 7, set, &scene));
  run_logging(scene, out, err, log, sum);
  sp_scene_destroy(&scene);
}

/* solver.newton_divergence = 100 against off on a run whose attempts after
 * the cut blow up: each failed attempt stops at the first |F| above 100 x
 * its first (its history is a prefix of the unchecked one, bit for bit),
 * says it diverged, the retries and the accepted states are the same, and
 * the factorisations saved are exactly the iterations cut off. */
static void check_divergence_ratio(void) {
  sp_run_summary off, on;
  static attempt_log l_off, l_on;
  run_divergent("0", "hard_div_off", "hard_div_off_stderr.txt", &l_off, &off);
  run_divergent("100", "hard_div_on", "hard_div_on_stderr.txt", &l_on, &on);
  printf("divergence ratio 100: %d failed attempts (%ld factorisations) against %d (%ld) "
         "unchecked\n", on.failed_attempts, on.failed_factorisations, off.failed_attempts,
         off.failed_factorisations);
  CHECK(off.failed_attempts >= 1 && on.failed_attempts == off.failed_attempts &&
            on.steps == off.steps,
        "failed attempts %d/%d, steps %d/%d", on.failed_attempts, off.failed_attempts, on.steps,
        off.steps);
  long cut = 0;
  for (int a = 0; a < l_on.n && a < l_off.n; ++a) {
    const sp_attempt *x = &l_on.a[a], *y = &l_off.a[a];
    const int n = x->n_residuals;
    printf("  attempt %d:", a);
    print_history(x);
    printf("\n     unchecked:");
    print_history(y);
    printf("\n");
    CHECK(x->why == SP_ATTEMPT_NEWTON && x->newton == SP_NEWTON_DIVERGED,
          "attempt %d: failure %d (Newton: %d), not 'diverged'", a, x->why, x->newton);
    CHECK(y->why == SP_ATTEMPT_NEWTON && y->newton != SP_NEWTON_DIVERGED,
          "unchecked attempt %d: failure %d (Newton: %d)", a, y->why, y->newton);
    CHECK(x->dt == y->dt, "attempt %d: dt %.17g against %.17g", a, x->dt, y->dt);
    CHECK(n >= 2 && x->residual_norms[n - 1] > 100 * x->residual_norms[0],
          "attempt %d did not end above 100 |F_0|", a);
    for (int k = 1; k < n - 1; ++k)
      CHECK(x->residual_norms[k] <= 100 * x->residual_norms[0],
            "attempt %d went on past |F_%d| = %g", a, k, x->residual_norms[k]);
    CHECK(n <= y->n_residuals &&
              memcmp(x->residual_norms, y->residual_norms, sizeof(double) * (size_t)n) == 0,
          "attempt %d is not the start of the unchecked one", a);
    cut += y->n_residuals - n;
  }
  CHECK(on.factorisations == off.factorisations &&
            on.failed_factorisations == off.failed_factorisations - cut,
        "%ld + %ld factorisations, expected %ld + (%ld - %ld)", on.factorisations,
        on.failed_factorisations, off.factorisations, off.failed_factorisations, cut);
  csv_table a, b;
  CHECK(csv_read("hard_div_off/energy.csv", &a) == 0 && csv_read("hard_div_on/energy.csv", &b) == 0,
        "energy.csv unreadable");
  CHECK(a.n_rows == b.n_rows, "%d rows against %d", b.n_rows, a.n_rows);
  for (int i = 0; i < a.n_rows && i < b.n_rows; ++i)
    CHECK(at(&a, i, "t") == at(&b, i, "t") &&
              at(&a, i, "residual_rise") == at(&b, i, "residual_rise") &&
              fabs(at(&a, i, "energy") - at(&b, i, "energy")) <= 1e-13 * fabs(at(&a, i, "energy")),
          "row %d: t %.17g / %.17g, energy %.17g / %.17g, |F| rise %g / %g", i, at(&b, i, "t"),
          at(&a, i, "t"), at(&b, i, "energy"), at(&a, i, "energy"), at(&b, i, "residual_rise"),
          at(&a, i, "residual_rise"));
  free(a.v);
  free(b.v);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_scene *scene;
  sp_run_summary sum;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_eight.yaml", 0, NULL, &scene));
  CHECK_OK(sp_stepper_run(scene, "hard_eight", MPI_COMM_WORLD, &sum));
  int same_step;
  int rows = count_rows("hard_eight/divisions.csv", &same_step);
  double m0 = cells_mass_at("hard_eight/cells.csv", 0, 0, NULL, NULL),
         m1 = cells_mass_at("hard_eight/cells.csv", sum.steps, 0, NULL, NULL);
  printf("eight at once: %d cells, %d divisions (same step: %s), total mass %.15g -> %.15g\n",
         sum.n_cells, rows, same_step ? "yes" : "no", m0, m1);
  CHECK(sum.n_cells == 16 && rows == 8 && same_step, "%d cells, %d divisions", sum.n_cells, rows);
  CHECK(fabs(m1 - m0) <= 1e-10 * m0, "total mass %.17g -> %.17g", m0, m1);
  sp_scene_destroy(&scene);

  const char *set[] = {"division.n_div=0", "division.m=0", "solver.newton_max_its=4"};
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 3, set, &scene));
  scene->time.t_end = 0.0046; /* the first division and a few steps */
  static attempt_log log;
  run_logging(scene, "hard_retry", "hard_retry_stderr.txt", &log, &sum);
  printf("no algorithm 2: %d cells, %d failed attempts retried, smallest dt %.3g\n", sum.n_cells,
         sum.failed_attempts, sum.dt_smallest);
  CHECK(sum.n_cells == 2, "%d cells", sum.n_cells);
  CHECK(sum.failed_attempts >= 1, "Newton never failed after the sharp cut at the full dt");
  CHECK(sum.dt_smallest < scene->time.dt, "smallest dt %g", sum.dt_smallest);
  /* each failure: Newton out of its 4 iterations, retried with a smaller dt */
  for (int i = 0; i < log.n; ++i) {
    const sp_attempt *a = &log.a[i];
    printf("  failed attempt %d: dt %.3g, %d iterations, |F|:", i, a->dt, a->newton_its);
    print_history(a);
    printf("; retried with dt %.3g\n", a->dt_next);
    CHECK(a->why == SP_ATTEMPT_NEWTON && a->newton == SP_NEWTON_MAX_ITERATIONS &&
              a->newton_its == 4 && a->n_residuals == 5 && a->dt_next < a->dt,
          "attempt %d: failure %d (Newton %d), %d iterations, %d norms, dt %g -> %g", i, a->why,
          a->newton, a->newton_its, a->n_residuals, a->dt, a->dt_next);
  }
  int logged = 0;
  csv_table e;
  CHECK(csv_read("hard_retry/energy.csv", &e) == 0, "hard_retry/energy.csv unreadable");
  for (int i = 0; i < e.n_rows; ++i) logged += (int)at(&e, i, "failed_attempts");
  free(e.v);
  CHECK(logged == sum.failed_attempts, "%d failed attempts, %d in energy.csv",
        sum.failed_attempts, logged);
  sp_scene_destroy(&scene);

  /* time.failure_memory = 6: after the failure at dt_f, dt climbs back to
   * dt_f / grow and stays there for 6 accepted steps, then grows again */
  const char *mem[] = {"division.n_div=0", "division.m=0", "solver.newton_max_its=4",
                       "time.failure_memory=6", "time.t_end=0.0054"};
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 5, mem, &scene));
  run_logging(scene, "hard_memory", "hard_memory_stderr.txt", &log, &sum);
  CHECK(csv_read("hard_memory/energy.csv", &e) == 0, "hard_memory/energy.csv unreadable");
  int first = -1;
  for (int i = 0; i < e.n_rows && first < 0; ++i)
    if (at(&e, i, "failed_attempts") > 0) first = i;
  CHECK(first > 0 && sum.failed_attempts == 1, "failure memory run: %d failed attempts",
        sum.failed_attempts);
  if (first > 0) {
    const double dt_f = at(&e, first, "dt") / scene->time.shrink;
    const double ceiling = dt_f / scene->time.grow;
    double largest_in = 0, largest_after = 0;
    for (int i = first; i < e.n_rows; ++i) {
      const double dt = at(&e, i, "dt");
      if (i < first + 6) largest_in = fmax(largest_in, dt);
      else if (i < e.n_rows - 1) largest_after = fmax(largest_after, dt); /* not the last: t_end */
    }
    printf("failure memory: failed at dt %.3g; largest dt in the 6 steps after %.3g (ceiling "
           "%.3g), then %.3g; t = %.6g\n", dt_f, largest_in, ceiling, largest_after, sum.t_final);
    CHECK(largest_in <= ceiling * (1 + 1e-12) && largest_in >= ceiling * (1 - 1e-12),
          "dt in the memory window %.17g, ceiling %.17g", largest_in, ceiling);
    CHECK(largest_after > ceiling * 1.5, "dt did not grow after the memory: %g", largest_after);
  }
  CHECK(fabs(sum.t_final - 0.0054) < 1e-12, "the run ended at t = %.17g", sum.t_final);
  free(e.v);
  sp_scene_destroy(&scene);

  check_divergence_ratio();
  MPI_Finalize();
  TEST_DONE();
}
