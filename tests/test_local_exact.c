/* Local supports reproduce full supports where the margin holds the whole
 * diffuse interface. Two cells face each other across a 2 x
 * 0.05 strip: c_1 fills x < 1/2, c_2 x > 3/2, with flat interfaces. A
 * flat interface keeps no far field (its chemical potential is 0, and so
 * is c = mu / 2 alpha away from it), so its profile decays as
 * exp(-distance / d) and a margin of 30 d beyond the cell holds all of it
 * but 5e-14 (curved cells keep a Gibbs-Thomson far field at every
 * distance, which no margin holds: tests/test_local_support.c,
 * docs/local-support.md). The flat profiles are relaxed to the discrete
 * equilibrium with full supports (|mu| ~ 1e-16), then both interfaces are
 * rippled (one wavelength along the strip, amplitude 0.3 d: zero mean,
 * so the ripple's chemical potential decays away from the interface as
 * exp(-2 pi distance / 0.05)), the fields are cut to the local supports,
 * and both layouts take 10 backward-Euler steps of 1e-4 from the same
 * fields with the paper's parameters while the ripples flatten (mu up to
 * 0.037). The phase fields agree to 1e-8 (measured 1.1e-9) and the full
 * ones stay below 1e-8 beyond the local supports (1.0e-9), mu agrees to
 * 1e-8 alpha (8.5e-9, at the support's edge, where the local field's
 * no-flux edge replaces the full field's vanishing tail), the energies to
 * 1e-8 relative (4e-15), with the same Newton iterations and fewer than
 * half the unknowns. */
#include "fixtures.h"

enum { NX = 320, NY = 8, N_STEPS = 10, RELAX_STEPS = 60 };
static const double LX = 2.0, LY = 0.05; /* the strip; LY: one ripple wavelength */
static const double X1 = 0.5, X2 = 1.5;  /* c_1 fills x < X1, c_2 x > X2 */
static const double RELAX_DT = 0.05;     /* the relaxation's largest step */

/* The two cells' flat tanh profiles on @p layout, mu = 0. */
static void set_flat(const sp_mesh *mesh, const sp_layout *layout, double *state, double d) {
  for (int i = 0; i < mesh->n_nodes; ++i)
    for (int k = 0; k < 2; ++k) {
      const int p = sp_layout_pair(layout, k, i);
      if (p < 0) continue;
      const double x = mesh->xy[2 * i], s = k == 0 ? x - X1 : X2 - x;
      state[2 * p] = 1.0 / (1.0 + exp(s / d));
      state[2 * p + 1] = 0.0;
    }
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const double d = sqrt(1e-3 / 8.0), margin = 30 * d;
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, LX, LY, NX, NY, &mesh));
  /* the local supports: each cell plus the margin (whole element columns) */
  unsigned char *mask = calloc(2 * (size_t)mesh->n_nodes, 1);
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const double x = mesh->xy[2 * i];
    mask[i] = x <= X1 + margin;
    mask[mesh->n_nodes + i] = x >= X2 - margin;
  }
  sp_layout *full, *local;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &full));
  CHECK_OK(sp_layout_create_from_masks(mesh->n_nodes, 2, mask, &local));
  const int nf = 2 * full->n_pairs, nl = 2 * local->n_pairs;
  double *xl = calloc(nl, sizeof(double)), *xf = calloc(nf, sizeof(double));
  double *old_l = calloc(nl, sizeof(double)), *old_f = calloc(nf, sizeof(double));
  double *lf = calloc(nf, sizeof(double));
  /* relax the flat profiles to the discrete equilibrium on the full layout
   * (the tanh profile is the continuous one), then cut them to the local
   * supports: both layouts start from the same fields */
  sp_solver sf = make_solver(mesh, full, SP_SOLVER_JAC_AD);
  const sp_model_params model = paper_model();
  sp_step_data df = {.dt = 1e-4, .model = model, .state_old = old_f};
  set_flat(mesh, full, xf, d);
  for (int step = 0; step < RELAX_STEPS; ++step) {
    sp_step_report r;
    df.dt = fmin(RELAX_DT, 1e-4 * pow(1.5, step));
    memcpy(old_f, xf, sizeof(double) * nf);
    CHECK(sp_solver_step(sf, &df, xf, &r) == 0, "relaxation, step %d: %s", step, r.reason);
  }
  df.dt = 1e-4;
  double edge = 0, mu_relaxed = 0;  /* edge: the largest c the local supports cut off */
  for (int i = 0; i < mesh->n_nodes; ++i)
    for (int k = 0; k < 2; ++k) {
      const int p = sp_layout_pair(full, k, i);
      mu_relaxed = fmax(mu_relaxed, fabs(xf[2 * p + 1]));
      if (!mask[k * mesh->n_nodes + i]) edge = fmax(edge, xf[2 * p]);
    }
  printf("relaxed: |mu| up to %.2e\n", mu_relaxed);
  CHECK(mu_relaxed < 1e-12, "the flat profiles did not relax: |mu| up to %.3e", mu_relaxed);
  /* ripple both interfaces: c += A cos(2 pi y / LY) dc/dx (central
   * differences; zero mean over y at every x) */
  {
    const double A = 0.3 * d, h = LX / NX;
    double *rippled = malloc(sizeof(double) * nf);
    memcpy(rippled, xf, sizeof(double) * nf);
    for (int j = 0; j <= NY; ++j)
      for (int i = 1; i < NX; ++i) {
        const int node = j * (NX + 1) + i;
        const double y = mesh->xy[2 * node + 1];
        for (int k = 0; k < 2; ++k) {
          const int p = sp_layout_pair(full, k, node), pl = sp_layout_pair(full, k, node - 1),
                    pr = sp_layout_pair(full, k, node + 1);
          rippled[2 * p] += A * cos(2 * M_PI * y / LY) * (xf[2 * pr] - xf[2 * pl]) / (2 * h);
        }
      }
    memcpy(xf, rippled, sizeof(double) * nf);
    free(rippled);
  }
  sp_layout_transfer(full, xf, local, xl, 0.0);
  sp_layout_transfer(local, xl, full, xf, 0.0);
  printf("unknowns: full %d, local %d; the largest c outside the local supports at t = 0: "
         "%.2e\n", nf, nl, edge);
  CHECK(edge < 1e-12 && edge > 0, "margin 30 d cuts off c up to %.3e", edge);
  CHECK(nl < 0.5 * nf, "local %d unknowns against full %d", nl, nf);

  sp_solver sl = make_solver(mesh, local, SP_SOLVER_JAC_AD);
  sp_step_data dl = df;
  dl.state_old = old_l;
  double worst_mu_x = 0, worst_c = 0, worst_mu = 0, worst_out = 0, worst_e = 0, mu_scale = 0;
  for (int step = 0; step < N_STEPS; ++step) {
    memcpy(old_f, xf, sizeof(double) * nf);
    memcpy(old_l, xl, sizeof(double) * nl);
    sp_step_report rf, rl;
    CHECK(sp_solver_step(sf, &df, xf, &rf) == 0, "full, step %d: %s", step, rf.reason);
    CHECK(sp_solver_step(sl, &dl, xl, &rl) == 0, "local, step %d: %s", step, rl.reason);
    CHECK(rf.newton_its == rl.newton_its, "step %d: Newton iterations %d (full) against %d", step,
          rf.newton_its, rl.newton_its);
    /* the local state on the full layout (zero off the supports) */
    sp_layout_transfer(local, xl, full, lf, 0.0);
    for (int i = 0; i < mesh->n_nodes; ++i)
      for (int k = 0; k < 2; ++k) {
        const int p = sp_layout_pair(full, k, i);
        const double dc = fabs(xf[2 * p] - lf[2 * p]);
        mu_scale = fmax(mu_scale, fabs(xf[2 * p + 1]));
        if (mask[k * mesh->n_nodes + i]) {
          worst_c = fmax(worst_c, dc);
          if (fabs(xf[2 * p + 1] - lf[2 * p + 1]) > worst_mu) worst_mu_x = mesh->xy[2 * i];
          worst_mu = fmax(worst_mu, fabs(xf[2 * p + 1] - lf[2 * p + 1]));
        } else {
          worst_out = fmax(worst_out, dc);
        }
      }
    const double Ef = energy_total(sf, &model, xf), El = energy_total(sl, &model, xl);
    worst_e = fmax(worst_e, fabs(El - Ef) / fabs(Ef));
    if (step == 0 || step == N_STEPS - 1)
      printf("step %d: Newton %d / %d, energy %.12g (full) %.12g (local)\n", step,
             rf.newton_its, rl.newton_its, Ef, El);
  }
  printf("over %d steps: |c_full - c_local| %.2e on the supports, full c beyond them %.2e; "
         "|mu_full - mu_local| %.2e at x = %.4f (mu up to %.3g); energies %.2e relative\n",
         N_STEPS, worst_c, worst_out, worst_mu, worst_mu_x, mu_scale, worst_e);
  CHECK(worst_c <= 1e-8, "c differs by %.3e", worst_c);
  CHECK(worst_out <= 1e-8, "the full fields reach %.3e beyond the local supports", worst_out);
  CHECK(worst_mu <= 1e-8 * model.alpha, "mu differs by %.3e", worst_mu);
  CHECK(worst_e <= 1e-8, "energies differ by %.3e relative", worst_e);

  sp_solver_destroy(&sf);
  sp_solver_destroy(&sl);
  free(xl), free(xf), free(old_l), free(old_f), free(lf), free(mask);
  sp_layout_destroy(&full);
  sp_layout_destroy(&local);
  sp_mesh_destroy(&mesh);
  MPI_Finalize();
  TEST_DONE();
}
