/* solver.linear = gmres_amg: GMRES preconditioned by the Cahn-Hilliard
 * block preconditioner whose solves are AMG V-cycles on each cell's
 * M + sqrt(dt kappa) K (cxx_glue/linear/linear_gmres_amg.cpp).
 * - On three touching cells (paper parameters, 3 steps of dt = 1e-4) at a
 *   tight GMRES tolerance it takes the same Newton iterations as serial
 *   SuperLU and the states agree to 1e-9 of the largest value.
 * - At its default tolerance (1e-6), with Newton ending on a solve's
 *   update (rtol 1e-3), it takes the same Newton iterations as SuperLU
 *   with the same Newton tolerances, and each cell's mass is conserved to
 *   1e-12 per step (the solve restores it: the preconditioner is not
 *   exact in the c rows).
 * - The GMRES iterations per Newton iteration do not grow with the mesh
 *   (40^2, 80^2, 160^2 elements) nor with dt (1e-7 to 1e-4): the largest is
 *   within 2x of the smallest over each range (what a preconditioner
 *   whose blocks are solved by multigrid must give). Past dt = 1e-4 the
 *   step nears the scheme's convexity bound (b < kappa / 4 on this
 *   problem) and the approximation of the Schur complement fails
 *   (docs/solvers.md).
 * - A tolerance GMRES cannot reach fails the step and leaves the state. */
#include <string.h>

#include "fixtures.h"

enum { N_STEPS = 3 };

/* N_STEPS steps of gmres_amg (tolerance tol) and SuperLU from the same
 * state, Newton iterations equal; with compare, tight Newton tolerances
 * and states equal to 1e-9, without, Newton's rtol 1e-3. Returns
 * the GMRES iterations per Newton iteration of gmres_amg and, in
 * mass_change, the largest relative change of a cell's mass in a step. */
static double run_steps(const sp_mesh *mesh, const sp_layout *layout, const double *start,
                        double dt, double tol, int compare, const char *what,
                        double *mass_change) {
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_AMG);
  opt.krylov_tol = tol;
  if (!compare) {
    opt.newton_rtol = 1e-3; /* Newton ends on a solve's update: its */
    opt.newton_atol = 1e-9; /* residual is the GMRES's */
  }
  sp_solver_options direct = opt;
  direct.linear = SP_LINEAR_SUPERLU;
  sp_solver solvers[2] = {make_solver_opts(mesh, layout, &opt),
                          make_solver_opts(mesh, layout, &direct)};
  const int n = 2 * layout->n_pairs, n_cells = layout->n_cells;
  double *x[2], *old = malloc(sizeof(double) * n);
  for (int s = 0; s < 2; ++s) {
    x[s] = malloc(sizeof(double) * n);
    memcpy(x[s], start, sizeof(double) * n);
  }
  sp_step_data data = {.dt = dt, .model = paper_model(), .state_old = old};
  long gmres = 0, newton = 0;
  *mass_change = 0;
  sp_cell_obs *before = malloc(sizeof(sp_cell_obs) * n_cells),
              *after = malloc(sizeof(sp_cell_obs) * n_cells);
  for (int step = 0; step < N_STEPS; ++step) {
    sp_step_report rep[2];
    for (int s = 0; s < 2; ++s) {
      memcpy(old, x[s], sizeof(double) * n);
      if (s == 0) CHECK_OK(sp_cells_observe(mesh, layout, x[s], 0, before));
      CHECK(sp_solver_step(solvers[s], &data, x[s], &rep[s]) == 0, "%s, step %d: %s", what, step,
            rep[s].reason);
      if (s == 0) {
        CHECK_OK(sp_cells_observe(mesh, layout, x[s], 0, after));
        for (int k = 0; k < n_cells; ++k)
          *mass_change = fmax(*mass_change, fabs(after[k].mass - before[k].mass) / before[k].mass);
      }
    }
    gmres += rep[0].linear_its;
    newton += rep[0].newton_its;
    if (compare) {
      check_same_step(what, step, "gmres_amg / SuperLU", rep, x[0], x[1], n, 1e-9);
    } else {
      CHECK(rep[0].newton_its == rep[1].newton_its,
            "%s, step %d: Newton iterations %d against %d", what, step, rep[0].newton_its,
            rep[1].newton_its);
    }
  }
  for (int s = 0; s < 2; ++s) {
    sp_solver_destroy(&solvers[s]);
    free(x[s]);
  }
  free(old);
  free(before);
  free(after);
  return (double)gmres / (double)newton;
}

/* Three touching disks on the unit square in m x m elements. */
static void three_disks(int m, sp_mesh **mesh, sp_layout **layout, double **x) {
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, m, m, mesh));
  CHECK_OK(sp_layout_create_full((*mesh)->n_nodes, 3, layout));
  *x = calloc(2 * (*layout)->n_pairs, sizeof(double));
  set_three_touching_disks(*mesh, *layout, *x);
}

static void free_problem(sp_mesh **mesh, sp_layout **layout, double **x) {
  sp_mesh_destroy(mesh);
  sp_layout_destroy(layout);
  free(*x);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  double *x, change;

  three_disks(40, &mesh, &layout, &x);
  run_steps(mesh, layout, x, 1e-4, 1e-10, 1, "three cells, tolerance 1e-10", &change);

  /* the default tolerance: the masses stay to round-off */
  const double its_40 = run_steps(mesh, layout, x, 1e-4, 1e-6, 0, "1e-6", &change);
  printf("krylov_tol 1e-6: %.1f GMRES iterations per Newton iteration; largest relative mass "
         "change per step %.2e\n",
         its_40, change);
  CHECK(change <= 1e-12, "krylov_tol 1e-6: a cell's mass changed by %.3e in a step", change);

  /* dt over three decades */
  double lo = its_40, hi = its_40;
  const double dts[] = {1e-7, 1e-6, 1e-5};
  for (int i = 0; i < 3; ++i) {
    const double its = run_steps(mesh, layout, x, dts[i], 1e-6, 0, "dt", &change);
    printf("40^2 elements, dt %.0e: %.1f GMRES iterations per Newton iteration\n", dts[i], its);
    lo = fmin(lo, its);
    hi = fmax(hi, its);
  }
  CHECK(hi <= 2 * lo, "GMRES iterations per Newton iteration from %.1f to %.1f over dt 1e-7..1e-4",
        lo, hi);

  /* an unreachable tolerance: the step fails, the state stays */
  check_unreachable_tolerance(mesh, layout, test_options(SP_SOLVER_JAC_AD, SP_LINEAR_GMRES_AMG),
                              x);
  free_problem(&mesh, &layout, &x);

  /* the mesh refined twice */
  lo = hi = its_40;
  for (int m = 80; m <= 160; m *= 2) {
    three_disks(m, &mesh, &layout, &x);
    const double its = run_steps(mesh, layout, x, 1e-4, 1e-6, 0, "h", &change);
    printf("%d^2 elements, dt 1e-4: %.1f GMRES iterations per Newton iteration; mass change "
           "%.2e\n",
           m, its, change);
    CHECK(change <= 1e-12, "%d^2 elements: a cell's mass changed by %.3e in a step", m, change);
    lo = fmin(lo, its);
    hi = fmax(hi, its);
    free_problem(&mesh, &layout, &x);
  }
  CHECK(hi <= 2 * lo, "GMRES iterations per Newton iteration from %.1f to %.1f over 40^2..160^2",
        lo, hi);
  MPI_Finalize();
  TEST_DONE();
}
