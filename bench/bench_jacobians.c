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
 *   OMP_NUM_THREADS=1 ./bench/bench_jacobians [repeat_scale] [timing|newton]
 *
 * repeat_scale (default 1) multiplies the repeats (fd is capped at 1
 * repeat for 16 cells); timing or newton runs only that part. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cells.h"
#include "error.h"
#include "layout.h"
#include "mesh.h"
#include "softpack_solver.h"
#include "stepper.h"

static sp_model_params paper_model(void) {
  sp_model_params m = {.alpha = 4, .kappa = 1e-3, .lambda = 100, .lambda_b = 100,
                       .mobility = 1};
  return m;
}

static sp_solver make_solver(const sp_mesh *mesh, const sp_layout *layout, int jacobian) {
  sp_solver_options opt = {.jacobian = jacobian, .linear = SP_SOLVER_SUPERLU,
                           .newton_rtol = 1e-10, .newton_atol = 1e-11, .newton_max_its = 20};
  sp_solver s = NULL;
  if (sp_solver_create(MPI_COMM_WORLD, &opt, &s) != 0) {
    fprintf(stderr, "sp_solver_create: %s\n", sp_solver_last_error(s));
    exit(1);
  }
  if (sp_solver_attach(s, mesh, layout) != SP_OK) {
    fprintf(stderr, "%s\n", sp_error_message());
    exit(1);
  }
  return s;
}

/* n tanh disks on a sunflower spiral inside the ellipse (semi-axes a, b),
 * radius 0.45 of the closest centre distance (near neighbours almost
 * touch, none overlap); a small seeded background. */
static void spread_disks(const sp_mesh *mesh, const sp_layout *layout, int n, double a,
                         double b, double *state) {
  const double d = sqrt(1e-3 / 8), golden = 2.39996322972865332;
  double x[64], y[64], closest = 1e300;
  for (int k = 0; k < n && k < 64; ++k) {
    const double r = n == 1 ? 0.0 : 0.7 * sqrt((k + 0.5) / n);
    x[k] = a * r * cos(k * golden);
    y[k] = b * r * sin(k * golden);
    for (int l = 0; l < k; ++l) closest = fmin(closest, hypot(x[k] - x[l], y[k] - y[l]));
  }
  const double R = n == 1 ? 0.12 : 0.45 * closest;
  unsigned long long rng = 12345;
  for (int k = 0; k < n && k < 64; ++k) {
    const double xk = x[k], yk = y[k];
    for (int i = 0; i < mesh->n_nodes; ++i) {
      int p = sp_layout_pair(layout, k, i);
      if (p < 0) continue;
      double dist = hypot(mesh->xy[2 * i] - xk, mesh->xy[2 * i + 1] - yk);
      double prof = 1.0 / (1.0 + exp((dist - R) / d));
      state[2 * p] = prof + (1 - prof) * (0.02 + 0.01 * sp_random_symmetric(&rng));
      state[2 * p + 1] = 0.0;
    }
  }
}

static const char *kind_name(int kind, int n_cells) {
  switch (kind) {
    case SP_SOLVER_JAC_AD: return n_cells <= 4 ? "ad (SFad)" : "ad (DFad)";
    case SP_SOLVER_JAC_AD_DFAD: return "ad forced DFad";
    case SP_SOLVER_JAC_HAND: return "hand";
    default: return "fd";
  }
}

static void time_kinds(const sp_mesh *mesh, int n_cells, int scale) {
  sp_layout *layout;
  if (sp_layout_create_full(mesh->n_nodes, n_cells, &layout) != SP_OK) exit(1);
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  const int n = 2 * layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *old = calloc(n, sizeof(double));
  spread_disks(mesh, layout, n_cells, 0.5, 0.25, state);
  memcpy(old, state, n * sizeof(double));
  sp_step_data data = {.dt = 1e-5, .model = paper_model(), .state_old = old};
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
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  free(state);
  free(old);
}

static void newton_kinds(const sp_mesh *mesh) {
  const int n_cells = 4, steps = 3;
  sp_layout *layout;
  if (sp_layout_create_full(mesh->n_nodes, n_cells, &layout) != SP_OK) exit(1);
  const int n = 2 * layout->n_pairs;
  double *init = calloc(n, sizeof(double));
  spread_disks(mesh, layout, n_cells, 0.5, 0.25, init);
  int kinds[3] = {SP_SOLVER_JAC_AD, SP_SOLVER_JAC_HAND, SP_SOLVER_JAC_FD};
  for (int k = 0; k < 3; ++k) {
    sp_solver s = make_solver(mesh, layout, kinds[k]);
    double *state = malloc(n * sizeof(double)), *old = malloc(n * sizeof(double));
    memcpy(state, init, n * sizeof(double));
    printf("| %-9s |", kind_name(kinds[k], n_cells));
    double t_asm = 0, t_fac = 0, t_tot = 0;
    int its = 0;
    for (int step = 0; step < steps; ++step) {
      memcpy(old, state, n * sizeof(double));
      sp_step_data data = {.dt = 1e-5, .model = paper_model(), .state_old = old};
      sp_step_report rep;
      int rc = sp_solver_step(s, &data, state, &rep);
      if (rc != 0) {
        printf(" step %d failed: %s |", step + 1, sp_solver_last_error(s));
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
    sp_solver_destroy(&s);
    free(state);
    free(old);
  }
  sp_layout_destroy(&layout);
  free(init);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int scale = argc > 1 ? atoi(argv[1]) : 1;
  if (scale < 1) scale = 1;
  sp_mesh *mesh;
  if (sp_mesh_ellipse(5, 0.5, 0.25, 0, 0, &mesh) != SP_OK) {
    fprintf(stderr, "%s\n", sp_error_message());
    return 1;
  }
  printf("ellipse: %d nodes, %d elements\n\n", mesh->n_nodes, mesh->n_elems);
  const int cells[3] = {1, 4, 16};
  const char *part = argc > 2 ? argv[2] : "all";
  if (strcmp(part, "newton") != 0) {
    printf("Seconds per Jacobian (mean over repeats): whole fill, and element matrices "
           "alone\n\n");
    printf("| cells | unknowns | kind | repeats | fill s | / hand | elements s | / hand |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    fflush(stdout);
    for (int c = 0; c < 3; ++c) time_kinds(mesh, cells[c], scale);
  }
  if (strcmp(part, "timing") == 0) {
    sp_mesh_destroy(&mesh);
    MPI_Finalize();
    return 0;
  }
  printf("\nNewton on 3 steps of the 4-cell state at dt = 1e-5 (assembly = residual +"
         " Jacobian fills)\n\n");
  printf("| kind | iterations per step | total | assembly s per step | factorisation s per step"
         " | step s |\n");
  printf("|---|---|---|---|---|---|\n");
  fflush(stdout);
  newton_kinds(mesh);
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  return 0;
}
