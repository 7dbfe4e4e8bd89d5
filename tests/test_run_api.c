/* The public run entry point (src/public/run.h): a scene given as text with an
 * override, a step callback that sees every accepted step in order (the
 * cells' observables with it) and stops the run after step 3: the run
 * returns SP_OK with summary.stopped, and energy.csv and the fields end at
 * that step. A bad override is bad input (SP_ERR_INPUT), nothing written. */
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "output_read.h"
#include "public/run.h"

static const char scene[] =
    "mesh: {type: rectangle, x0: 0, y0: 0, x1: 1, y1: 1, nx: 16, ny: 16}\n"
    "time: {dt: 1.0e-4, t_end: 0.01}\n"
    "cells:\n"
    "  - {x: 0.3, y: 0.5, radius: 0.15}\n"
    "  - {x: 0.7, y: 0.5, radius: 0.15}\n"
    "output: {every: 1000, pictures: false}\n";

typedef struct {
  int calls, last_step, ordered;
  double last_t, mass0;
} watch;

static int on_step(const sp_step_info *s, void *user) {
  watch *w = user;
  w->ordered &= s->step == w->last_step + 1 && s->t > w->last_t && s->dt > 0 &&
                s->n_cells == 2 && s->cells != NULL;
  if (w->calls == 0) w->mass0 = s->cells[0].mass;
  w->last_step = s->step;
  w->last_t = s->t;
  ++w->calls;
  return s->step >= 3; /* stop after the third step */
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  watch w = {.ordered = 1};
  const char *set[] = {"model.lambda=50"};
  sp_run_summary sum;
  CHECK_OK(sp_run_text("api_scene", scene, strlen(scene), 1, set, "run_api_out", MPI_COMM_WORLD,
                       on_step, &w, &sum));
  printf("%d callbacks, stopped %d after %d steps at t = %g\n", w.calls, sum.stopped, sum.steps,
         w.last_t);
  CHECK(w.calls == 3 && w.ordered, "%d callbacks, in order %d", w.calls, w.ordered);
  CHECK(sum.stopped == 1 && sum.steps == 3, "stopped %d, steps %d", sum.stopped, sum.steps);
  CHECK(w.mass0 > 0, "the callback saw no cell mass");
  csv_table e;
  CHECK(csv_read("run_api_out/energy.csv", &e) == 0 && e.n_rows == 4,
        "energy.csv: %d rows, expected 4 (steps 0-3)", e.n_rows);
  if (e.n_rows == 4) CHECK(at(&e, 3, "t") == w.last_t, "last row t %g", at(&e, 3, "t"));
  free(e.v);
  struct stat st;
  CHECK(stat("run_api_out/fields_000003.vtu", &st) == 0, "no fields at the stopping step");
  /* bad input: the code, and nothing written */
  const char *bad[] = {"time.scheme=rk4"};
  system("rm -rf run_api_bad");
  const int rc = sp_run_text("api_scene", scene, strlen(scene), 1, bad, "run_api_bad",
                             MPI_COMM_WORLD, NULL, NULL, NULL);
  CHECK(rc == SP_ERR_INPUT && strstr(sp_error_message(), "time.scheme"), "rc %d: %s", rc,
        sp_error_message());
  CHECK(stat("run_api_bad", &st) != 0, "bad input wrote its output directory");
  MPI_Finalize();
  TEST_DONE();
}
