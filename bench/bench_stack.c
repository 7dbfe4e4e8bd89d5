/* Speed next to error for the stack: a three-cell scene on
 * n x n rectangles (default n = 64, 128, 256), K steps of dt each from the
 * same initial state. Prints, per mesh: unknowns, Newton iterations per step,
 * seconds per step split into assembly (residual + Jacobian fills),
 * factorisation, triangular solves and the rest, and the L2 difference of
 * each cell's c at the final time to the next finer mesh (nested meshes: the
 * fine solution is read at the coarse nodes; discrete L2 norm over the
 * coarse mesh).
 * The mesh, full layout and state are built by hand, not with the run's
 * set-up (run_setup.h): the L2 comparison reads each field at the nested
 * rectangles' natural node numbering, which the set-up's RCB renumbering
 * would scramble.
 *   build/bench/bench_stack [steps=5] [dt=1e-5] [n1 n2 ...]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "model/cells.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"
#include "softpack_solver.h"
#include "run/resize.h"
#include "run/stepper.h"

#define N_CELLS 3

typedef struct {
  int n, unknowns, newton_its, failed;
  double t_asm, t_fac, t_sol, t_total;
  double *c;  /* final c of every cell at every node, cell-major */
} result;

static double wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static result run(int n, int steps, double dt) {
  result r = {.n = n};
  sp_mesh *mesh;
  sp_layout *layout;
  if (sp_mesh_rectangle(0, 0, 1, 1, n, n, &mesh) || sp_layout_create_full(mesh->n_nodes, N_CELLS, &layout)) {
    fprintf(stderr, "setup failed\n");
    exit(1);
  }
  sp_solver_options opt = {.jacobian = SP_SOLVER_JAC_AD, .linear = SP_LINEAR_SUPERLU,
                           .newton_rtol = 1e-8, .newton_atol = 1e-10, .newton_max_its = 12};
  sp_solver s;
  if (sp_solver_create(MPI_COMM_WORLD, &opt, &s) || sp_solver_attach(s, mesh, layout)) {
    fprintf(stderr, "solver: %s %s\n", sp_solver_last_error(s), sp_error_message());
    exit(1);
  }
  const int nv = 2 * layout->n_pairs;
  r.unknowns = nv;
  double *state = calloc(nv, sizeof(double)), *old = calloc(nv, sizeof(double));
  const double d = sqrt(1e-3 / 8.0);
  const double cx[N_CELLS] = {0.34, 0.64, 0.50}, cy[N_CELLS] = {0.45, 0.47, 0.74},
               R[N_CELLS] = {0.15, 0.14, 0.11};
  for (int k = 0; k < N_CELLS; ++k)
    for (int i = 0; i < mesh->n_nodes; ++i) {
      int p = sp_layout_pair(layout, k, i);
      double rr = hypot(mesh->xy[2 * i] - cx[k], mesh->xy[2 * i + 1] - cy[k]);
      state[2 * p] = 1.0 / (1.0 + exp((rr - R[k]) / d));
    }
  sp_step_data data = {.dt = dt, .model = {4, 1e-3, 100, 100, 1}, .state_old = old};
  const double t0 = wall();
  for (int step = 0; step < steps; ++step) {
    for (int i = 0; i < nv; ++i) old[i] = state[i];
    sp_step_report rep;
    if (sp_solver_step(s, &data, state, &rep) != 0) {
      ++r.failed;
      fprintf(stderr, "n = %d step %d failed: %s\n", n, step, sp_solver_last_error(s));
    }
    r.newton_its += rep.newton_its;
    r.t_asm += rep.t_assembly;
    r.t_fac += rep.t_factor;
    r.t_sol += rep.t_solve;
  }
  r.t_total = wall() - t0;
  r.c = malloc(sizeof(double) * N_CELLS * mesh->n_nodes);
  for (int k = 0; k < N_CELLS; ++k)
    for (int i = 0; i < mesh->n_nodes; ++i)
      r.c[k * mesh->n_nodes + i] = state[2 * sp_layout_pair(layout, k, i)];
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(state);
  free(old);
  return r;
}

/* Discrete L2 difference over the coarse mesh (node-lumped quadrature). */
static double l2_diff(const result *coarse, const result *fine) {
  const int nc = coarse->n + 1, nf = fine->n + 1, ratio = fine->n / coarse->n;
  const double h = 1.0 / coarse->n;
  double sum = 0;
  for (int k = 0; k < N_CELLS; ++k)
    for (int j = 0; j < nc; ++j)
      for (int i = 0; i < nc; ++i) {
        double a = coarse->c[k * nc * nc + j * nc + i];
        double b = fine->c[k * nf * nf + (j * ratio) * nf + i * ratio];
        double w = h * h * ((i == 0 || i == nc - 1) ? 0.5 : 1) * ((j == 0 || j == nc - 1) ? 0.5 : 1);
        sum += w * (a - b) * (a - b);
      }
  return sqrt(sum);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int steps = argc > 1 ? atoi(argv[1]) : 5;
  double dt = argc > 2 ? atof(argv[2]) : 1e-5;
  int meshes[16] = {64, 128, 256}, n_meshes = 3;
  if (argc > 3) {
    n_meshes = 0;
    for (int i = 3; i < argc && n_meshes < 16; ++i) meshes[n_meshes++] = atoi(argv[i]);
  }
  result res[16];
  for (int m = 0; m < n_meshes; ++m) res[m] = run(meshes[m], steps, dt);
  printf("three cells, paper parameters, %d steps of dt = %g, serial SuperLU, AD Jacobian\n", steps, dt);
  printf("%6s %9s %8s %10s %10s %10s %10s %10s %12s\n", "mesh", "unknowns", "its/step",
         "s/step", "assembly", "factor", "solve", "rest", "L2 to finer");
  for (int m = 0; m < n_meshes; ++m) {
    const result *r = &res[m];
    double per = r->t_total / steps;
    char diff[32] = "-";
    if (m + 1 < n_meshes && meshes[m + 1] % meshes[m] == 0)
      snprintf(diff, sizeof diff, "%.3e", l2_diff(r, &res[m + 1]));
    printf("%3dx%-3d %9d %8.2f %10.3f %10.3f %10.3f %10.3f %10.3f %12s%s\n", r->n, r->n,
           r->unknowns, (double)r->newton_its / steps, per, r->t_asm / steps, r->t_fac / steps,
           r->t_sol / steps, (r->t_total - r->t_asm - r->t_fac - r->t_sol) / steps, diff,
           r->failed ? "  (failed steps!)" : "");
  }
  MPI_Finalize();
  return 0;
}
