/* A lineage table in 3D (tests/scenes/lineage_3d.yaml: a box of
 * hexahedra, s = 0, backward Euler with a fixed dt, smoothed cut), through
 * `softpack run`'s stepper, about 20 s of CPU:
 * - divisions.csv has three named rows in the table's order (P0 -> AB, P1;
 *   AB -> ABa, ABp; P1 -> EMS, P2) with the table's fractions; each first
 *   daughter's share of its parent's mass is the fraction to 1e-9 (the
 *   smoothed cut, test_lineage's bound), the daughters sum to the parent to
 *   1e-12 relative;
 * - the axis rules in 3D: P0's cut (long) is normal to its long axis, x
 *   within 0.01 rad (the noise tilts it), pointing to +x; AB's
 *   (perpendicular) is orthogonal to P0's cut normal to 1e-12; P1's (fixed)
 *   is (0, 1, 1)/sqrt 2 to 1e-15;
 * - every cell's mass is conserved to 1e-12 relative at every step that is
 *   not a division (s = 0), and at a division the parent's mass goes to
 *   its daughters (1e-12);
 * - cells.csv names P0 at the start and ABa, EMS, ABp, P2 (cells 1 to 4)
 *   at the end. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

#define OUT "test_lineage_3d_out"
enum { MAX_CELLS = 4, CAP = 200 };

static const char divisions_header[] =
    "t,step,parent,child,long_x,long_y,long_z,parent_mass_before,parent_mass_after,"
    "child_mass_after,parent_name,first_name,second_name,fraction\n";

/** cells.csv: mass[step][cell] (NAN where the cell does not exist), the
 *  names of the last step's cells; the number of steps + 1. */
static int read_cells(double (*mass)[MAX_CELLS], char names[MAX_CELLS][32], char *first) {
  csv_table t;
  CHECK(csv_read(OUT "/cells.csv", &t) == 0, "no cells.csv");
  for (int s = 0; s < CAP; ++s)
    for (int k = 0; k < MAX_CELLS; ++k) mass[s][k] = NAN;
  const size_t hl = strlen(t.header), tail = strlen(",core_mass,volume,name\n");
  CHECK(hl >= tail && !strcmp(t.header + hl - tail, ",core_mass,volume,name\n"),
        "cells.csv header: %s", t.header);
  int steps = 0;
  for (int i = 0; i < t.n_rows; ++i) {
    const int s = (int)at(&t, i, "step"), k = (int)at(&t, i, "cell");
    if (s < 0 || s >= CAP || k < 1 || k > MAX_CELLS) continue;
    mass[s][k - 1] = at(&t, i, "mass");
    const char *name = at_str(&t, i, "name");
    if (s == 0 && k == 1) snprintf(first, 32, "%s", name);
    if (s + 1 > steps) steps = s + 1;
    snprintf(names[k - 1], 32, "%s", name);
  }
  csv_free(&t);
  return steps;
}

static double dot(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  CHECK(system("rm -rf " OUT) == 0, "cannot clear the output");
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/lineage_3d.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, OUT, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  printf("%d steps to t = %.6g, %d divisions, %d cells\n", sum.steps, sum.t_final,
         sum.divisions, sum.n_cells);
  CHECK(sum.divisions == 3 && sum.n_cells == 4, "%d divisions, %d cells", sum.divisions,
        sum.n_cells);

  division_row rows[4];
  const int n = divisions_read(OUT, divisions_header, rows, 4);
  CHECK(n == 3, "%d named rows in divisions.csv (-1: unreadable or not the header %s)", n,
        divisions_header);
  static const struct {
    const char *parent, *first, *second;
    double fraction;
  } want[3] = {{"P0", "AB", "P1", 0.59}, {"AB", "ABa", "ABp", 0.45}, {"P1", "EMS", "P2", 0.574}};
  for (int i = 0; i < n && i < 3; ++i) {
    const division_row *r = &rows[i];
    const double share = r->a / r->before;
    printf("division %d at step %d: %s -> %s, %s: share %.12f (table %g), normal (%.6f, %.6f, "
           "%.6f)\n", i + 1, r->step, r->parent_name, r->first, r->second, share, r->fraction,
           r->normal[0], r->normal[1], r->normal[2]);
    CHECK(!strcmp(r->parent_name, want[i].parent) && !strcmp(r->first, want[i].first) &&
              !strcmp(r->second, want[i].second),
          "division %d: %s -> %s, %s", i + 1, r->parent_name, r->first, r->second);
    CHECK(r->fraction == want[i].fraction, "division %d: fraction %.17g", i + 1, r->fraction);
    CHECK(fabs(share - want[i].fraction) <= 1e-9, "division %d: share %.12f, not %g", i + 1,
          share, want[i].fraction);
    CHECK(fabs(r->a + r->b - r->before) <= 1e-12 * r->before,
          "division %d: %.17g + %.17g != %.17g", i + 1, r->a, r->b, r->before);
    CHECK(fabs(sqrt(dot(r->normal, r->normal)) - 1) <= 1e-14, "division %d: |n| - 1 = %.3g",
          i + 1, sqrt(dot(r->normal, r->normal)) - 1);
  }
  if (n == 3) {
    const double off_x = acos(fmin(1.0, rows[0].normal[0]));
    const double across = dot(rows[0].normal, rows[1].normal);
    const double s = sqrt(0.5);
    const double fixed_miss = fabs(rows[2].normal[0]) + fabs(rows[2].normal[1] - s) +
                              fabs(rows[2].normal[2] - s);
    printf("P0's cut normal %.3g rad from +x; AB's . P0's = %.3g; P1's off (0, 1, 1)/sqrt 2 by "
           "%.3g\n", off_x, across, fixed_miss);
    CHECK(off_x <= 0.01, "P0's cut normal %.3g rad from +x", off_x);
    CHECK(fabs(across) <= 1e-12, "AB's cut normal . P0's = %.3g", across);
    CHECK(fixed_miss <= 1e-15, "P1's cut normal off by %.3g", fixed_miss);
  }

  static double mass[CAP][MAX_CELLS];
  char names[MAX_CELLS][32] = {{0}}, first[32] = "";
  const int steps = read_cells(mass, names, first);
  CHECK(steps == sum.steps + 1, "%d cells.csv steps, %d steps", steps, sum.steps);
  double worst = 0;
  for (int s = 1; s < steps; ++s) {
    int division = -1;
    for (int i = 0; i < n; ++i)
      if (rows[i].step == s) division = i;
    for (int k = 0; k < MAX_CELLS; ++k) {
      if (isnan(mass[s][k])) continue;
      if (division >= 0 && (k == rows[division].parent - 1 || k == rows[division].child - 1)) {
        if (k != rows[division].parent - 1) continue;
        const double before = mass[s - 1][k];
        const double after = mass[s][k] + mass[s][rows[division].child - 1];
        CHECK(fabs(after - before) <= 1e-12 * before,
              "step %d: parent %.17g -> daughters %.17g", s, before, after);
        continue;
      }
      const double rel = fabs(mass[s][k] - mass[s - 1][k]) / mass[s - 1][k];
      worst = fmax(worst, rel);
      CHECK(rel <= 1e-12, "step %d cell %d: mass %.17g -> %.17g (relative %.3g)", s, k + 1,
            mass[s - 1][k], mass[s][k], rel);
    }
  }
  printf("largest relative mass change of a cell over a step without its division: %.3g\n",
         worst);
  CHECK(!strcmp(first, "P0"), "cells.csv at the start: %s, not P0", first);
  static const char *const last[MAX_CELLS] = {"ABa", "EMS", "ABp", "P2"};
  for (int k = 0; k < MAX_CELLS; ++k)
    CHECK(!strcmp(names[k], last[k]), "cell %d at the end: %s, not %s", k + 1, names[k], last[k]);
  MPI_Finalize();
  TEST_DONE();
}
