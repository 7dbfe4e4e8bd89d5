/* Divisions through the run in 3D, as `softpack run`
 * makes them (scene, box of hexahedra, full supports, MUMPS):
 *  - tests/scenes/divide_3d.yaml: one ellipsoidal cell (semi-axes 0.17,
 *    0.11, 0.11, long along x) at constant volume (s = 0, backward Euler,
 *    fixed dt) divides once by age at t = 0.001 with the smoothed cut on
 *    the equal-mass plane: the split gives the parent's mass to its
 *    daughters (1e-12 relative, divisions.csv and cells.csv) in equal
 *    halves (1e-10, test_division_3d's bound), every cell's mass is
 *    conserved to 1e-12 relative at every other step, the cut's normal is
 *    a unit vector along x (within 0.01 rad: the background noise of
 *    +-0.01 tilts the moments) and the daughters' centres lie apart along
 *    it (within 0.01 rad);
 *  - tests/scenes/grow_divide_3d.yaml: with the source on (s = 5e2,
 *    adaptive steps, backward Euler), one cell grows, divides once by mass
 *    (N_max = 2) and the run reaches t_end: before the division its mass
 *    grows every step and its core mass stays below twice its birth mass;
 *    the split conserves mass (1e-12); each daughter grows until its core
 *    mass passes 1.1 x its birth mass (source.off_ratio, N = N_max), and
 *    from the next step on its mass is constant to 1e-12 relative. */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

enum { MAX_CELLS = 2 };

static const char divisions_header[] =
    "t,step,parent,child,long_x,long_y,long_z,parent_mass_before,parent_mass_after,"
    "child_mass_after\n";

/** Run @p scene_file into @p out; the summary. */
static sp_run_summary run(const char *scene_file, const char *out) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load(scene_file, 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  CHECK(fabs(sum.t_final - scene->time.t_end) <= 1e-12 * scene->time.t_end ||
            sum.steps == scene->time.max_steps,
        "%s: stopped at t = %g after %d steps", scene_file, sum.t_final, sum.steps);
  printf("%s: %d steps to t = %.6g, %d division(s), %d cells, smallest dt %.3g\n", scene_file,
         sum.steps, sum.t_final, sum.divisions, sum.n_cells, sum.dt_smallest);
  sp_scene_destroy(&scene);
  return sum;
}

/** The one row of @p out's divisions.csv: its step, the parent's long axis,
 *  |m_parent / m_child - 1| after the split (@p halves, if not NULL);
 *  checks the header, |axis| = 1 and the split's mass balance. */
static int read_division(const char *out, double axis[3], double *halves) {
  char path[512];
  snprintf(path, sizeof path, "%s/divisions.csv", out);
  csv_table d;
  CHECK(csv_read(path, &d) == 0, "%s missing", path);
  CHECK(strcmp(d.header, divisions_header) == 0, "divisions.csv header: %s", d.header);
  CHECK(d.n_rows == 1, "%d divisions", d.n_rows);
  if (d.n_rows < 1) return -1;
  const char *names[3] = {"long_x", "long_y", "long_z"};
  for (int j = 0; j < 3; ++j) axis[j] = at(&d, 0, names[j]);
  const double before = at(&d, 0, "parent_mass_before");
  const double after = at(&d, 0, "parent_mass_after") + at(&d, 0, "child_mass_after");
  const int step = (int)at(&d, 0, "step");
  if (halves) *halves = fabs(at(&d, 0, "parent_mass_after") / at(&d, 0, "child_mass_after") - 1);
  printf("  division at step %d: long axis (%.4f, %.4f, %.4f), parent %.17g -> %.17g + %.17g\n",
         step, axis[0], axis[1], axis[2], before, at(&d, 0, "parent_mass_after"),
         at(&d, 0, "child_mass_after"));
  CHECK(at(&d, 0, "parent") == 1 && at(&d, 0, "child") == 2, "parent %g child %g",
        at(&d, 0, "parent"), at(&d, 0, "child"));
  CHECK(fabs(sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]) - 1) <= 1e-12,
        "|long axis| = %.17g", sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]));
  CHECK(fabs(after - before) <= 1e-12 * before, "split: %.17g -> %.17g (relative %.3g)", before,
        after, fabs(after - before) / before);
  free(d.v);
  return step;
}

/** cells.csv of @p out: per step and cell the values of @p name (NAN where
 *  the cell does not exist); the number of steps + 1. */
static int read_cells(const char *out, const char *name, double (*v)[MAX_CELLS], int cap) {
  return cells_column(out, name, &v[0][0], cap, MAX_CELLS);
}

/** Relative change of a mass from one row to the next. */
static double change(double from, double to) { return fabs(to - from) / from; }

static void test_constant_volume(void) {
  const char *out = "test_divide_3d_volume";
  const sp_run_summary sum = run(SP_SOURCE_DIR "/tests/scenes/divide_3d.yaml", out);
  CHECK(sum.divisions == 1 && sum.n_cells == 2, "%d divisions, %d cells", sum.divisions,
        sum.n_cells);
  double axis[3], halves;
  const int at_step = read_division(out, axis, &halves);
  const double off_x = acos(fmin(1.0, fabs(axis[0])));
  printf("  the cut's normal at %.3g rad from x; daughters' masses differ by %.3g\n", off_x,
         halves);
  CHECK(off_x <= 0.01, "the cut's normal (%g, %g, %g) is %.3g rad from x", axis[0], axis[1],
        axis[2], off_x);
  CHECK(halves <= 1e-10, "equal-mass plane: the daughters differ by %.3g", halves);
  enum { CAP = 64 };
  double mass[CAP][MAX_CELLS], x[CAP][MAX_CELLS], y[CAP][MAX_CELLS], z[CAP][MAX_CELLS];
  const int rows = read_cells(out, "mass", mass, CAP);
  read_cells(out, "xc", x, CAP);
  read_cells(out, "yc", y, CAP);
  read_cells(out, "zc", z, CAP);
  CHECK(rows == sum.steps + 1, "%d cells.csv steps, %d steps", rows, sum.steps);
  CHECK(at_step == 5, "divided at step %d, t_div = 5 dt", at_step);
  double worst = 0;
  for (int s = 1; s < rows; ++s) {
    if (s == at_step) { /* the parent's mass went to both daughters */
      const double split = change(mass[s - 1][0], mass[s][0] + mass[s][1]);
      printf("  step %d: parent %.17g, daughters %.17g + %.17g (relative %.3g)\n", s,
             mass[s - 1][0], mass[s][0], mass[s][1], split);
      CHECK(split <= 1e-12, "step %d: parent %.17g -> daughters %.17g", s, mass[s - 1][0],
            mass[s][0] + mass[s][1]);
      continue;
    }
    for (int k = 0; k < MAX_CELLS; ++k) {
      if (isnan(mass[s][k])) continue;
      const double rel = change(mass[s - 1][k], mass[s][k]);
      worst = fmax(worst, rel);
      CHECK(rel <= 1e-12, "step %d cell %d: mass %.17g -> %.17g (relative %.3g)", s, k + 1,
            mass[s - 1][k], mass[s][k], rel);
    }
  }
  printf("  largest relative mass change per step (other steps): %.3g\n", worst);
  /* the daughters' centres apart along the cut's normal, the child on its side */
  if (at_step > 0 && at_step < rows) {
    const double d[3] = {x[at_step][1] - x[at_step][0], y[at_step][1] - y[at_step][0],
                         z[at_step][1] - z[at_step][0]};
    const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double cosine = (d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]) / len;
    printf("  daughters' centres %.4f apart, at %.3g rad from the long axis\n", len,
           acos(fmin(1.0, cosine)));
    CHECK(cosine >= cos(0.01), "the daughters' centres apart at %.3g rad from the axis",
          acos(fmin(1.0, cosine)));
  }
}

static void test_growth(void) {
  const char *out = "test_divide_3d_growth";
  const sp_run_summary sum = run(SP_SOURCE_DIR "/tests/scenes/grow_divide_3d.yaml", out);
  CHECK(sum.divisions == 1 && sum.n_cells == 2, "%d divisions, %d cells", sum.divisions,
        sum.n_cells);
  double axis[3];
  const int at_step = read_division(out, axis, NULL);
  enum { CAP = 400 };
  static double mass[CAP][MAX_CELLS], core[CAP][MAX_CELLS];
  const int rows = read_cells(out, "mass", mass, CAP);
  read_cells(out, "core_mass", core, CAP);
  CHECK(rows == sum.steps + 1 && at_step > 1 && at_step < rows - 2, "%d rows, division at %d",
        rows, at_step);
  if (!(at_step > 1 && at_step < rows - 2)) return;
  /* growth to the division: more mass every step, the core below 2 m0 */
  const double m0 = core[0][0];
  for (int s = 1; s < at_step; ++s) {
    CHECK(mass[s][0] > mass[s - 1][0] * (1 + 1e-6), "step %d: no growth (%.17g -> %.17g)", s,
          mass[s - 1][0], mass[s][0]);
    CHECK(core[s][0] < 2 * m0, "step %d: core mass %.17g >= 2 m0 = %.17g, but no division", s,
          core[s][0], 2 * m0);
  }
  printf("  before the division: core mass %.6g = %.4f m0\n", core[at_step - 1][0],
         core[at_step - 1][0] / m0);
  /* each daughter: grows until its core passes 1.1 x its birth core mass,
   * then (source off) keeps its mass */
  for (int k = 0; k < MAX_CELLS; ++k) {
    const double birth = core[at_step][k];
    int off = -1;
    for (int s = at_step; s < rows && off < 0; ++s)
      if (core[s][k] > 1.1 * birth) off = s;
    printf("  daughter %d: birth core mass %.6g, passes 1.1 x at step %d of %d\n", k + 1, birth,
           off, rows - 1);
    CHECK(off > at_step && off < rows - 1, "daughter %d: source still on at the end (%d)", k + 1,
          off);
    if (off < 0) continue;
    for (int s = at_step + 1; s <= off; ++s)
      CHECK(mass[s][k] > mass[s - 1][k], "daughter %d step %d: no growth with the source on",
            k + 1, s);
    double worst = 0;
    for (int s = off + 1; s < rows; ++s) worst = fmax(worst, change(mass[s - 1][k], mass[s][k]));
    printf("  daughter %d: largest relative mass change per step after the source stops: "
           "%.3g\n", k + 1, worst);
    CHECK(worst <= 1e-12, "daughter %d: mass changes by %.3g after its source stops", k + 1,
          worst);
  }
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  test_constant_volume();
  test_growth();
  MPI_Finalize();
  TEST_DONE();
}
