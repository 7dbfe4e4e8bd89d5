/* Run a scene from your own program with softpack's C entry point
 * (softpack/run.h) and watch it step by step:
 *
 *   run_scene SCENE.yaml OUT_DIR [MAX_CELLS] [section.key=value]...
 *
 * prints one line per accepted step (step, t, dt, cells, the total cell
 * mass and the cells' mass-weighted centre, x y in 2D, x y z in 3D) and
 * stops the run once MAX_CELLS cells exist (default: never).
 * Exit status: 0, or the run's error code's exit status (2: bad input). */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

#include <softpack/run.h>

typedef struct {
  int max_cells;
} limits;

static int watch(const sp_step_info *s, void *user) {
  const limits *lim = user;
  double mass = 0, centre[SP_DIM_MAX] = {0};
  for (int k = 0; k < s->n_cells; ++k) {
    mass += s->cells[k].mass;
    for (int d = 0; d < s->dim; ++d) centre[d] += s->cells[k].mass * s->cells[k].centre[d];
  }
  int rank;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    printf("step %d t %.6g dt %.3g cells %d mass %.10g centre", s->step, s->t, s->dt,
           s->n_cells, mass);
    for (int d = 0; d < s->dim; ++d) printf(" %.10g", centre[d] / mass);
    printf("\n");
  }
  return lim->max_cells > 0 && s->n_cells >= lim->max_cells;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: run_scene SCENE.yaml OUT_DIR [MAX_CELLS] [section.key=value]...\n");
    return 2;
  }
  MPI_Init(&argc, &argv);
  limits lim = {.max_cells = argc > 3 ? atoi(argv[3]) : 0};
  sp_run_summary sum;
  const int rc = sp_run_file(argv[1], argc > 4 ? argc - 4 : 0,
                             (const char *const *)(argv + 4), argv[2], MPI_COMM_WORLD, watch,
                             &lim, &sum);
  if (rc != SP_OK) fprintf(stderr, "run_scene: %s\n", sp_error_message());
  else printf("%d steps, stopped early: %s\n", sum.steps, sum.stopped ? "yes" : "no");
  MPI_Finalize();
  return sp_error_exit_status(rc);
}
