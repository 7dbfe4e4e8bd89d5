/* Jacobian kinds compared on the paper's ellipse (5 refinements, 5120
 * elements, 5185 nodes, no buffer), full layout:
 *  1. seconds per Jacobian fill (whole fill: gather, element matrices,
 *     insertion, global assembly) and per pass of the element matrices
 *     alone, for ad (SFad on elements with <= 4 cells, DFad beyond), ad
 *     forced to DFad, hand and fd, with 1, 4 and 16 cells, mean over a few
 *     repeats, and the ratio to hand;
 *  2. Newton iterations and assembly seconds per step for ad, hand and fd on
 *     3 steps of a 4-cell scene at dt = 1e-5.
 *
 * Both parts start from a scene text set up as a run is (sp_run_setup,
 * run_setup.h: RCB node numbering, the scene's solver keys, layout.support
 * full): n disks on a sunflower spiral, the run's initial profile and
 * seeded background noise. (The bench once built the mesh,
 * layout and tanh disks by hand, in the mesh's own numbering: figures in
 * docs/jacobians.md measured before then come from that state, which was
 * the same up to the noise's draws and the numbering.)
 *
 *   OMP_NUM_THREADS=1 ./bench/bench_jacobians [repeat_scale] [timing|newton]
 *
 * repeat_scale (default 1) multiplies the repeats (fd is capped at 1
 * repeat for 16 cells); timing or newton runs only that part. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"
#include "run/run_setup.h"
#include "softpack_solver.h"

/** A scene of @p n disks on a sunflower spiral inside the ellipse (semi-axes
 *  0.5, 0.25), radius 0.45 of the closest centre distance (near neighbours
 *  almost touch, none overlap; 0.12 alone), a small seeded background; the
 *  paper's model, Newton with the Jacobian @p jacobian ("ad", "hand",
 *  "fd") from scratch every iteration; set up in @p run (exits on
 *  failure). */
static sp_scene *disks_run(int n, const char *jacobian, sp_run *run) {
  const double golden = 2.39996322972865332;
  double x[64], y[64], closest = 1e300;
  for (int k = 0; k < n && k < 64; ++k) {
    const double r = n == 1 ? 0.0 : 0.7 * sqrt((k + 0.5) / n);
    x[k] = 0.5 * r * cos(k * golden);
    y[k] = 0.25 * r * sin(k * golden);
    for (int l = 0; l < k; ++l) closest = fmin(closest, hypot(x[k] - x[l], y[k] - y[l]));
  }
  const double R = n == 1 ? 0.12 : 0.45 * closest;
  char text[8192];
  int len = snprintf(text, sizeof text,
                     "mesh: {type: ellipse, refinements: 5, semi_x: 0.5, semi_y: 0.25, "
                     "buffer_layers: 0}\n"
                     "model: {alpha: 4, kappa: 1.0e-3, lambda: 100, lambda_b: 100, mobility: 1}\n"
                     "time: {dt: 1.0e-5}\n"
                     "noise: {background: 0.02, amplitude: 0.01, seed: 12345}\n"
                     "layout: {support: full}\n"
                     "solver: {linear: superlu, jacobian: %s, newton_rtol: 1.0e-10, "
                     "newton_atol: 1.0e-11, newton_max_its: 20, jacobian_reuse: 0}\n"
                     "cells:\n", jacobian);
  for (int k = 0; k < n && k < 64; ++k)
    len += snprintf(text + len, sizeof text - len, "  - {x: %.17g, y: %.17g, radius: %.17g}\n",
                    x[k], y[k], R);
  sp_scene *scene = NULL;
  *run = (sp_run){0};
  if (sp_scene_load_text("bench_jacobians", text, (size_t)len, 0, NULL, &scene) != SP_OK ||
      sp_run_setup(run, scene, MPI_COMM_WORLD, NULL) != SP_OK) {
    fprintf(stderr, "%s\n", sp_error_message());
    exit(1);
  }
  return scene;
}

static void disks_free(sp_scene **scene, sp_run *run) {
  sp_run_free(run);
  sp_scene_destroy(scene);
}

static const char *kind_name(int kind, int n_cells) {
  switch (kind) {
    case SP_SOLVER_JAC_AD: return n_cells <= 4 ? "ad (SFad)" : "ad (DFad)";
    case SP_SOLVER_JAC_AD_DFAD: return "ad forced DFad";
    case SP_SOLVER_JAC_HAND: return "hand";
    default: return "fd";
  }
}

static void time_kinds(int n_cells, int scale) {
  sp_run run;
  sp_scene *scene = disks_run(n_cells, "ad", &run);
  const sp_solver s = run.solver;
  const int n = 2 * run.layout->n_pairs;
  const double *state = run.state;
  memcpy(run.buf.state_old, state, n * sizeof(double));
  sp_step_data data = {.dt = 1e-5, .model = run.opt.model, .state_old = run.buf.state_old};
  /* hand first: the ratios are to it. ad at 16 cells is DFad already. */
  int kinds[4] = {SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_AD, SP_SOLVER_JAC_AD_DFAD, SP_SOLVER_JAC_FD};
  int base = n_cells == 1 ? 20 : n_cells == 4 ? 6 : 2;
  double t_hand_fill = 0, t_hand_elem = 0;
  for (int k = 0; k < 4; ++k) {
    if (kinds[k] == SP_SOLVER_JAC_AD_DFAD && n_cells > 4) continue;
    int repeats = base * scale;
    if (kinds[k] == SP_SOLVER_JAC_FD) repeats = n_cells >= 16 ? 1 : (repeats + 3) / 4;
    double fill = 0, elem = 0;
    /* One untimed fill first (page faults, caches). */
    if (sp_solver_time_jacobian(s, &data, state, kinds[k], 1, &fill, NULL) != 0 ||
        sp_solver_time_jacobian(s, &data, state, kinds[k], repeats, &fill, &elem) != 0) {
      fprintf(stderr, "time_jacobian: %s\n", sp_solver_last_error(s));
      exit(1);
    }
    if (kinds[k] == SP_SOLVER_JAC_HAND) {
      t_hand_fill = fill;
      t_hand_elem = elem;
    }
    printf("| %2d | %6d | %-15s | %7d | %10.4f | %6.2f | %10.4f | %6.2f |\n", n_cells, n,
           kind_name(kinds[k], n_cells), repeats, fill, fill / t_hand_fill, elem,
           elem / t_hand_elem);
    fflush(stdout);
  }
  disks_free(&scene, &run);
}

static void newton_kinds(void) {
  const int n_cells = 4, steps = 3;
  int kinds[3] = {SP_SOLVER_JAC_AD, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD};
  const char *words[3] = {"ad", "hand", "fd"};
  for (int k = 0; k < 3; ++k) {
    sp_run run;
    sp_scene *scene = disks_run(n_cells, words[k], &run);
    const int n = 2 * run.layout->n_pairs;
    printf("| %-9s |", kind_name(kinds[k], n_cells));
    double t_asm = 0, t_fac = 0, t_tot = 0;
    int its = 0;
    for (int step = 0; step < steps; ++step) {
      memcpy(run.buf.state_old, run.state, n * sizeof(double));
      sp_step_data data = {.dt = 1e-5, .model = run.opt.model, .state_old = run.buf.state_old};
      sp_step_report rep;
      int rc = sp_solver_step(run.solver, &data, run.state, &rep);
      if (rc != 0) {
        printf(" step %d failed: %s |", step + 1, sp_solver_last_error(run.solver));
        break;
      }
      printf(" %d", rep.newton_its);
      its += rep.newton_its;
      t_asm += rep.t_assembly;
      t_fac += rep.t_factor;
      t_tot += rep.t_total;
    }
    printf(" | %d | %.3f | %.3f | %.3f |\n", its, t_asm / steps, t_fac / steps, t_tot / steps);
    fflush(stdout);
    disks_free(&scene, &run);
  }
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int scale = argc > 1 ? atoi(argv[1]) : 1;
  if (scale < 1) scale = 1;
  {
    sp_run run;
    sp_scene *scene = disks_run(1, "ad", &run);
    printf("ellipse: %d nodes, %d elements\n\n", run.mesh->n_nodes, run.mesh->n_elems);
    disks_free(&scene, &run);
  }
  const int cells[3] = {1, 4, 16};
  const char *part = argc > 2 ? argv[2] : "all";
  if (strcmp(part, "newton") != 0) {
    printf("Seconds per Jacobian (mean over repeats): whole fill, and element matrices "
           "alone\n\n");
    printf("| cells | unknowns | kind | repeats | fill s | / hand | elements s | / hand |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    fflush(stdout);
    for (int c = 0; c < 3; ++c) time_kinds(cells[c], scale);
  }
  if (strcmp(part, "timing") == 0) {
    MPI_Finalize();
    return 0;
  }
  printf("\nNewton on 3 steps of the 4-cell state at dt = 1e-5 (assembly = residual +"
         " Jacobian fills)\n\n");
  printf("| kind | iterations per step | total | assembly s per step | factorisation s per step"
         " | step s |\n");
  printf("|---|---|---|---|---|---|\n");
  fflush(stdout);
  newton_kinds();
  MPI_Finalize();
  return 0;
}
