/* solver.line_search backtrack (NOX's backtracking line search) against
 * full Newton steps, on three touching cells (paper parameters) after one
 * step of 1e-4:
 * - a step of 4e-3, where full Newton's residual falls at every
 *   iteration: the line search never shortens a step, so both take the
 *   same iterations to the same state (to the bit);
 * - a step of 1.6e-2, where full Newton's residual climbs to ~1e4 and the
 *   step fails in 20 iterations: with the line search it converges, its
 *   residual norms fall at every iteration, the state solves the step
 *   equations (|F| <= max(atol, rtol |F_0|), checked by an independent
 *   residual), every cell keeps its mass to 1e-12 (s = 0) and the energy
 *   does not rise;
 * - an unknown kind is refused, naming solver.line_search. */
#include "fixtures.h"

#define N_CELLS 3

static double norm2(const double *v, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += v[i] * v[i];
  return sqrt(s);
}

/* One step of @p dt from @p old with line search @p kind; @p state: the
 * result (the old state on failure). Returns sp_solver_step's code. */
static int step_with(const sp_mesh *mesh, const sp_layout *layout, int kind, double dt,
                     const double *old, double *state, sp_step_report *rep, double *energy,
                     double *residual_norm) {
  sp_solver_options opt = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU);
  opt.line_search = kind;
  sp_solver s = make_solver_opts(mesh, layout, &opt);
  const int n = 2 * layout->n_pairs;
  memcpy(state, old, n * sizeof(double));
  sp_step_data data = {.dt = dt, .model = paper_model(), .state_old = old};
  const int rc = sp_solver_step(s, &data, state, rep);
  sp_model_params m = paper_model();
  *energy = energy_total(s, &m, state);
  double *F = malloc(n * sizeof(double));
  CHECK(sp_solver_residual(s, &data, state, F) == 0, "residual: %s", sp_solver_last_error(s));
  *residual_norm = norm2(F, n);
  free(F);
  sp_solver_destroy(&s);
  return rc;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  const int n = 2 * layout->n_pairs;
  double *old = calloc(n, sizeof(double)), *full = calloc(n, sizeof(double)),
         *back = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, old);
  sp_step_report rep_full, rep_back;
  double e_full, e_back, r_full, r_back;
  /* Off the initial state (mu = 0): one step of 1e-4; its end (and
   * energy) is the old state of the steps below. */
  double e_old;
  CHECK(step_with(mesh, layout, SP_SOLVER_STEP_FULL, 1e-4, old, full, &rep_full, &e_old,
                  &r_full) == 0,
        "the first step failed");
  memcpy(old, full, n * sizeof(double));
  const double tol = test_options(0, 0).newton_rtol, atol = test_options(0, 0).newton_atol;

  /* An easy step: the same iterations and state. */
  CHECK(step_with(mesh, layout, SP_SOLVER_STEP_FULL, 4e-3, old, full, &rep_full, &e_full,
                  &r_full) == 0,
        "dt = 4e-3 failed with full steps");
  CHECK(step_with(mesh, layout, SP_SOLVER_STEP_BACKTRACK, 4e-3, old, back, &rep_back, &e_back,
                  &r_back) == 0,
        "dt = 4e-3 failed with the line search");
  for (int i = 1; i < rep_full.n_residuals; ++i) /* the case's premise */
    CHECK(rep_full.residual_norms[i] < rep_full.residual_norms[i - 1],
          "dt = 4e-3: full Newton's |F| rose at iteration %d: not the easy case", i);
  double diff = 0;
  for (int i = 0; i < n; ++i) diff = fmax(diff, fabs(full[i] - back[i]));
  printf("dt = 4e-3: %d / %d iterations, states differ by %.3g\n", rep_full.newton_its,
         rep_back.newton_its, diff);
  CHECK(rep_full.newton_its == rep_back.newton_its, "%d iterations with full steps, %d with "
        "the line search", rep_full.newton_its, rep_back.newton_its);
  CHECK(diff == 0, "the line search changed a step whose residual fell: %.3g", diff);

  /* A hard step: full Newton fails, the line search converges. */
  const double dt = 1.6e-2;
  const int rc_full = step_with(mesh, layout, SP_SOLVER_STEP_FULL, dt, old, full, &rep_full,
                                &e_full, &r_full);
  const int rc_back = step_with(mesh, layout, SP_SOLVER_STEP_BACKTRACK, dt, old, back,
                                &rep_back, &e_back, &r_back);
  printf("dt = %.1e: full steps rc %d after %d iterations, largest |F| ", dt, rc_full,
         rep_full.newton_its);
  double largest = 0;
  for (int i = 0; i < rep_full.n_residuals; ++i)
    largest = fmax(largest, rep_full.residual_norms[i]);
  printf("%.3g; line search rc %d after %d iterations, |F|:", largest, rc_back,
         rep_back.newton_its);
  for (int i = 0; i < rep_back.n_residuals; ++i) printf(" %.2e", rep_back.residual_norms[i]);
  printf("\n");
  CHECK(rc_full == 1, "full Newton steps converged at dt = %g (rc %d): the case is not hard",
        dt, rc_full);
  CHECK(largest > 100 * rep_full.residual_norms[0], "full Newton's residual did not climb");
  CHECK(rc_back == 0, "the line search failed at dt = %g: %s", dt, rep_back.reason);
  for (int i = 1; i < rep_back.n_residuals; ++i)
    CHECK(rep_back.residual_norms[i] < rep_back.residual_norms[i - 1],
          "iteration %d: |F| rose from %.3e to %.3e under the line search", i,
          rep_back.residual_norms[i - 1], rep_back.residual_norms[i]);
  const double f0 = rep_back.residual_norms[0];
  printf("independent residual %.3e (bound %.3e); energy %.10g -> %.10g\n", r_back,
         fmax(atol, tol * f0), e_old, e_back);
  CHECK(r_back <= fmax(atol, tol * f0) * (1 + 1e-6), "|F| = %.3e at the converged state",
        r_back);
  CHECK(e_back <= e_old, "the energy rose over the step: %.15g -> %.15g", e_old, e_back);
  sp_cell_obs before[N_CELLS], after[N_CELLS];
  CHECK_OK(sp_cells_observe(mesh, layout, old, 0, before));
  CHECK_OK(sp_cells_observe(mesh, layout, back, 0, after));
  for (int k = 0; k < N_CELLS; ++k) {
    const double rel = fabs(after[k].mass - before[k].mass) / before[k].mass;
    printf("cell %d: mass %.15g -> %.15g (relative %.3g)\n", k, before[k].mass, after[k].mass,
           rel);
    CHECK(rel <= 1e-12, "cell %d lost mass under the line search: relative %.3g", k, rel);
  }

  sp_solver_options bad = test_options(SP_SOLVER_JAC_AD, SP_LINEAR_SUPERLU);
  bad.line_search = 7;
  expect_solver_refused(&bad, "solver.line_search");
  free(old);
  free(full);
  free(back);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  TEST_DONE();
}
