/* A lineage table run (tests/scenes/lineage_two_gen.yaml: P0 -> AB, P1 at
 * 59:41 by a fixed axis; AB -> ABa, ABp across its parent's cut; P1 ->
 * EMS, P2 at 57.4:42.6 later), a few seconds:
 * - divisions.csv has three rows, in the table's order (P0, then AB, then
 *   P1), at the table's times (to 1e-12: the steps land on them), with the
 *   names and the table's fractions; each first daughter's share of its
 *   parent's mass is the fraction to 1e-9 (the smooth cut), the daughters
 *   sum to the parent to 1e-12; AB's cut is perpendicular to P0's (the
 *   division lines at pi/2 and 0 rad, to 1e-12);
 * - cells.csv names the cells: P0 at the start; ABa, EMS, ABp, P2 (cells
 *   1 to 4) at the end;
 * - the run stopped after P0's division and continued from its checkpoint
 *   writes cells.csv and divisions.csv byte for byte as the whole run:
 *   the names (and the cut normal AB's perpendicular axis turns) survive
 *   the checkpoint. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "public/run.h"

#define SCENE SP_SOURCE_DIR "/tests/scenes/lineage_two_gen.yaml"
#define PI 3.14159265358979323846

/** The names of cells.csv's rows of step @p step, in order (at most @p cap):
 *  their number. */
static int names_at(const char *path, int step, char names[][32], int cap) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  char line[2048];
  int n = 0;
  if (!fgets(line, sizeof line, f) || !strstr(line, ",area,name\n")) {
    fclose(f);
    return 0;
  }
  while (fgets(line, sizeof line, f)) {
    const char *name = strrchr(line, ',');
    if (atoi(line) != step || !name || n >= cap) continue;
    snprintf(names[n], 32, "%.*s", (int)strcspn(name + 1, "\n"), name + 1);
    ++n;
  }
  fclose(f);
  return n;
}

static int same_file(const char *a, const char *b) {
  size_t la, lb;
  char *ta = slurp(a, &la), *tb = slurp(b, &lb);
  const int same = ta && tb && la == lb && memcmp(ta, tb, la) == 0;
  free(ta);
  free(tb);
  return same;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  CHECK(system("rm -rf lineage_whole lineage_parts") == 0, "cannot clear the output");
  sp_run_summary whole, part, rest;
  CHECK_OK(sp_run_file(SCENE, 0, NULL, "lineage_whole", MPI_COMM_WORLD, NULL, NULL, &whole));
  printf("whole run: %d steps, %d divisions, %d cells\n", whole.steps, whole.divisions,
         whole.n_cells);
  CHECK(whole.divisions == 3 && whole.n_cells == 4, "%d divisions, %d cells", whole.divisions,
        whole.n_cells);

  division_row rows[8];
  const int n = divisions_read("lineage_whole",
                               "t,step,parent,child,axis_angle,parent_mass_before,"
                               "parent_mass_after,child_mass_after,parent_name,first_name,"
                               "second_name,fraction\n",
                               rows, 8);
  CHECK(n == 3, "%d named rows in divisions.csv", n);
  static const struct {
    const char *parent, *first, *second;
    double t, fraction, angle;
  } want[3] = {{"P0", "AB", "P1", 0.001, 0.59, PI / 2},
               {"AB", "ABa", "ABp", 0.003, 0.5, 0.0},
               {"P1", "EMS", "P2", 0.004, 0.574, NAN}};
  for (int i = 0; i < n && i < 3; ++i) {
    const division_row *r = &rows[i];
    const double share = r->a / r->before;
    printf("division %d at t = %.17g: %s -> %s, %s: share %.12f (table %g), line at %.3g rad\n",
           i + 1, r->t, r->parent_name, r->first, r->second, share, r->fraction, r->angle);
    CHECK(!strcmp(r->parent_name, want[i].parent) && !strcmp(r->first, want[i].first) &&
              !strcmp(r->second, want[i].second),
          "division %d: %s -> %s, %s", i + 1, r->parent_name, r->first, r->second);
    CHECK(fabs(r->t - want[i].t) <= 1e-12, "division %d at t = %.17g, not %g", i + 1, r->t,
          want[i].t);
    CHECK(r->fraction == want[i].fraction, "division %d: fraction %.17g", i + 1, r->fraction);
    CHECK(fabs(share - want[i].fraction) <= 1e-9, "division %d: share %.12f, not %g", i + 1,
          share, want[i].fraction);
    CHECK(fabs(r->a + r->b - r->before) <= 1e-12 * r->before,
          "division %d: %.17g + %.17g != %.17g", i + 1, r->a, r->b, r->before);
    if (!isnan(want[i].angle))
      CHECK(fabs(r->angle - want[i].angle) <= 1e-12, "division %d: the line at %.17g rad",
            i + 1, r->angle);
  }
  char names[8][32];
  CHECK(names_at("lineage_whole/cells.csv", 0, names, 8) == 1 && !strcmp(names[0], "P0"),
        "cells.csv at the start: not just P0");
  static const char *const last[4] = {"ABa", "EMS", "ABp", "P2"};
  const int n_last = names_at("lineage_whole/cells.csv", whole.steps, names, 8);
  CHECK(n_last == 4, "%d cells named at the end", n_last);
  for (int k = 0; k < n_last && k < 4; ++k)
    CHECK(!strcmp(names[k], last[k]), "cell %d at the end: %s, not %s", k + 1, names[k],
          last[k]);

  /* stopped after P0's division (and before AB's), then continued from
   * the checkpoint of that step */
  int stop = 0;
  for (int s = 5; s < whole.steps && !stop; s += 5) {
    char path[256];
    snprintf(path, sizeof path, "lineage_whole/checkpoint_%06d.h5", s);
    FILE *f = fopen(path, "r");
    if (!f) continue;
    fclose(f);
    double m[8];
    int n_cells;
    if (cells_mass_at("lineage_whole/cells.csv", s, 8, &n_cells, m) > 0 && n_cells == 2) stop = s;
  }
  CHECK(stop > 0, "no checkpoint with two cells in the whole run");
  char max_steps[64];
  /* (a run writes no checkpoint at its last step: stop one later) */
  snprintf(max_steps, sizeof max_steps, "time.max_steps=%d", stop + 1);
  const char *set[1] = {max_steps};
  CHECK_OK(sp_run_file(SCENE, 1, set, "lineage_parts", MPI_COMM_WORLD, NULL, NULL, &part));
  char checkpoint[256];
  snprintf(checkpoint, sizeof checkpoint, "lineage_parts/checkpoint_%06d.h5", stop);
  const sp_restart restart = {.checkpoint = checkpoint};
  CHECK_OK(sp_run_file_restart(SCENE, 0, NULL, "lineage_parts", &restart, MPI_COMM_WORLD, NULL,
                               NULL, &rest));
  printf("stopped at step %d, continued to step %d\n", part.steps, rest.steps);
  CHECK(rest.steps == whole.steps, "the continued run ends at step %d, the whole at %d",
        rest.steps, whole.steps);
  CHECK(same_file("lineage_whole/divisions.csv", "lineage_parts/divisions.csv"),
        "divisions.csv of the continued run differs from the whole run's");
  CHECK(same_file("lineage_whole/cells.csv", "lineage_parts/cells.csv"),
        "cells.csv of the continued run differs from the whole run's");
  MPI_Finalize();
  TEST_DONE();
}
