/* Orders in time with steps that are not uniform: backward Euler 1, BDF2 2
 * (within 0.1), through the time scheme the stepper uses (src/time/time_scheme.h:
 * the history, BDF2 as a backward-Euler step from c_hat), on a manufactured
 * solution of the two-cell equations with repulsion:
 *   c_k(x, y, t) = C0 + A g(t) phi_k(x, y),  phi_1 = cos(pi x) cos(pi y),
 *   phi_2 = cos(2 pi x) cos(pi y) (no-flux on the unit square),
 *   s_k = d c_k / dt - M lap mu_k,
 *   mu_k = f'(c_k) - kappa lap c_k + 2 lambda c_k c_l^2,
 * the source taken at t^{n+1}. The order is measured from the differences of
 * successive step refinements, ||u_h - u_{h/2}|| / ||u_{h/2} - u_{h/4}||,
 * so the (fixed) spatial error cancels; the error against the exact c at T
 * is printed too. Steps: N steps in the repeating pattern 0.7, 1.3, 0.9, 1.1
 * (ratios up to 1.86, below BDF2's 1 + sqrt 2). Mass: with s = 0 each
 * cell's mass is conserved to round-off by both schemes on the same
 * sequences. */
#include "fixtures.h"
#include "time/time_scheme.h"

#define C0 0.1
#define AMP 0.08
#define ALPHA 1.0
#define KAPPA 0.01
#define LAMBDA 10.0
#define MOB 1.0
#define RATE 4.0
#define T_END 0.4
#define MESH 24

static double g(double t) { return exp(-RATE * t); }
static double g_t(double t) { return -RATE * exp(-RATE * t); }

/* phi_k, its gradient and Laplacian factor K (lap phi = -K phi) */
static void mode(int k, double x, double y, double *phi, double grad[2], double *K) {
  const double m = k == 0 ? 1 : 2;
  *phi = cos(m * M_PI * x) * cos(M_PI * y);
  grad[0] = -m * M_PI * sin(m * M_PI * x) * cos(M_PI * y);
  grad[1] = -M_PI * cos(m * M_PI * x) * sin(M_PI * y);
  *K = M_PI * M_PI * (m * m + 1);
}

static double exact_c(int k, double x, double y, double t) {
  double phi, grad[2], K;
  mode(k, x, y, &phi, grad, &K);
  return C0 + AMP * g(t) * phi;
}

static double exact_source(int k, double x, double y, double t) {
  double phi[2], grad[2][2], K[2], c[2], lap[2], gc[2][2];
  for (int j = 0; j < 2; ++j) {
    mode(j, x, y, &phi[j], grad[j], &K[j]);
    c[j] = C0 + AMP * g(t) * phi[j];
    lap[j] = -K[j] * AMP * g(t) * phi[j];
    gc[j][0] = AMP * g(t) * grad[j][0];
    gc[j][1] = AMP * g(t) * grad[j][1];
  }
  const int l = 1 - k;
  const double lap2 = K[k] * K[k] * AMP * g(t) * phi[k];
  const double grad2 = gc[k][0] * gc[k][0] + gc[k][1] * gc[k][1];
  const double f2 = 2 * ALPHA * (6 * c[k] * c[k] - 6 * c[k] + 1), f3 = 2 * ALPHA * (12 * c[k] - 6);
  /* lap(c_k c_l^2) = c_l^2 lap c_k + c_k (2 c_l lap c_l + 2 |grad c_l|^2)
   *                 + 4 c_l grad c_k . grad c_l */
  const double gl2 = gc[l][0] * gc[l][0] + gc[l][1] * gc[l][1];
  const double dot = gc[k][0] * gc[l][0] + gc[k][1] * gc[l][1];
  const double lap_rep = c[l] * c[l] * lap[k] + c[k] * (2 * c[l] * lap[l] + 2 * gl2) +
                         4 * c[l] * dot;
  const double lap_mu = f3 * grad2 + f2 * lap[k] - KAPPA * lap2 + 2 * LAMBDA * lap_rep;
  return AMP * g_t(t) * phi[k] - MOB * lap_mu;
}

typedef struct {
  sp_mesh *mesh;
  sp_layout *layout;
  sp_solver solver;
} problem;

/* Integrate to T_END with n steps of the pattern; c at T into out (one per
 * pair); with_source 0: s = 0 and *mass_drift = the largest relative change
 * of a cell's mass over the steps. */
static void integrate(problem *pb, sp_scheme_kind scheme, int n, int with_source, double *out,
                      double *mass_drift) {
  static const double pattern[4] = {0.7, 1.3, 0.9, 1.1}; /* mean 1 */
  const sp_mesh *mesh = pb->mesh;
  const sp_layout *layout = pb->layout;
  const size_t n_pairs = (size_t)layout->n_pairs, nv = 2 * n_pairs;
  double *state = calloc(nv, sizeof(double)), *old = calloc(nv, sizeof(double));
  double *eff = calloc(nv, sizeof(double)), *source = calloc(n_pairs, sizeof(double));
  double *w = calloc(n_pairs, sizeof(double));
  CHECK_OK(sp_cells_pair_weights(mesh, layout, w));
  for (int node = 0; node < mesh->n_nodes; ++node)
    for (int p = layout->node_start[node]; p < layout->node_start[node + 1]; ++p)
      state[2 * p] = exact_c(layout->pair_cell[p], mesh->xy[2 * node], mesh->xy[2 * node + 1],
                             0.0);
  double mass0[2] = {0, 0};
  for (size_t p = 0; p < n_pairs; ++p) mass0[layout->pair_cell[p]] += w[p] * state[2 * p];
  *mass_drift = 0;
  sp_history hist = {0};
  const sp_model_params model = {.alpha = ALPHA, .kappa = KAPPA, .lambda = LAMBDA,
                                 .lambda_b = 0, .mobility = MOB};
  double t = 0;
  for (int step = 0; step < n; ++step) {
    const double dt = step == n - 1 ? T_END - t : T_END / n * pattern[step % 4];
    memcpy(old, state, nv * sizeof(double));
    const sp_scheme_kind kind = sp_scheme_of_step(scheme, &hist);
    double dt_eff;
    sp_scheme_be_form(kind, &hist, dt, old, n_pairs, eff, &dt_eff);
    if (with_source)
      for (int node = 0; node < mesh->n_nodes; ++node)
        for (int p = layout->node_start[node]; p < layout->node_start[node + 1]; ++p)
          source[p] = exact_source(layout->pair_cell[p], mesh->xy[2 * node],
                                   mesh->xy[2 * node + 1], t + dt);
    sp_step_data data = {.dt = dt_eff, .model = model, .state_old = eff,
                         .source = with_source ? source : NULL};
    sp_step_report rep;
    const int rc = sp_solver_step(pb->solver, &data, state, &rep);
    CHECK(rc == 0, "step %d of %d: %s", step + 1, n, rep.reason);
    if (rc) break;
    CHECK_OK(sp_history_push(&hist, old, dt, nv));
    t += dt;
    double mass[2] = {0, 0};
    for (size_t p = 0; p < n_pairs; ++p) mass[layout->pair_cell[p]] += w[p] * state[2 * p];
    for (int k = 0; k < 2; ++k)
      *mass_drift = fmax(*mass_drift, fabs(mass[k] - mass0[k]) / mass0[k]);
  }
  for (size_t p = 0; p < n_pairs; ++p) out[p] = state[2 * p];
  sp_history_free(&hist);
  free(state); free(old); free(eff); free(source); free(w);
}

/* L2 norm (nodal, lumped on the uniform mesh) of a - b over both cells */
static double l2_diff(const problem *pb, const double *a, const double *b) {
  const double h = 1.0 / MESH;
  double sum = 0;
  for (int p = 0; p < pb->layout->n_pairs; ++p) sum += (a[p] - b[p]) * (a[p] - b[p]);
  return sqrt(sum * h * h);
}

static double l2_exact(const problem *pb, const double *a) {
  const sp_mesh *mesh = pb->mesh;
  const double h = 1.0 / MESH;
  double sum = 0;
  for (int node = 0; node < mesh->n_nodes; ++node)
    for (int p = pb->layout->node_start[node]; p < pb->layout->node_start[node + 1]; ++p) {
      const double d = a[p] - exact_c(pb->layout->pair_cell[p], mesh->xy[2 * node],
                                      mesh->xy[2 * node + 1], T_END);
      sum += d * d;
    }
  return sqrt(sum * h * h);
}

static void check_order(problem *pb, sp_scheme_kind scheme, double expected) {
  enum { LEVELS = 5 };
  const int steps[LEVELS] = {10, 20, 40, 80, 160};
  double *u[LEVELS];
  const size_t n_pairs = (size_t)pb->layout->n_pairs;
  printf("%s: steps, error against the exact c at T, ||u_N - u_2N||, order\n",
         scheme == SP_SCHEME_BDF2 ? "BDF2" : "BE");
  for (int i = 0; i < LEVELS; ++i) {
    u[i] = calloc(n_pairs, sizeof(double));
    double drift;
    integrate(pb, scheme, steps[i], 1, u[i], &drift);
  }
  double prev = 0;
  for (int i = 0; i + 1 < LEVELS; ++i) {
    const double d = l2_diff(pb, u[i], u[i + 1]);
    const double order = i ? log(prev / d) / log(2.0) : 0;
    printf("  %4d  %.4e  %.4e  %.3f\n", steps[i], l2_exact(pb, u[i]), d, order);
    if (i >= 2)
      CHECK(fabs(order - expected) <= 0.1, "%s order %.3f between %d and %d steps",
            scheme == SP_SCHEME_BDF2 ? "BDF2" : "BE", order, steps[i], steps[i + 1]);
    prev = d;
  }
  for (int i = 0; i < LEVELS; ++i) free(u[i]);
}

int main(int argc, char **argv) {
  (void)argc; (void)argv;
  MPI_Init(&argc, &argv);
  problem pb;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, MESH, MESH, &pb.mesh));
  CHECK_OK(sp_layout_create_full(pb.mesh->n_nodes, 2, &pb.layout));
  pb.solver = make_solver(pb.mesh, pb.layout, SP_SOLVER_JAC_AD);
  check_order(&pb, SP_SCHEME_BE, 1.0);
  check_order(&pb, SP_SCHEME_BDF2, 2.0);
  /* s = 0: each cell's mass to round-off, whatever the scheme and steps */
  double *u = calloc((size_t)pb.layout->n_pairs, sizeof(double)), drift_be, drift_bdf2;
  integrate(&pb, SP_SCHEME_BE, 13, 0, u, &drift_be);
  integrate(&pb, SP_SCHEME_BDF2, 13, 0, u, &drift_bdf2);
  printf("s = 0, 13 steps: largest relative mass change BE %.2e, BDF2 %.2e\n", drift_be,
         drift_bdf2);
  CHECK(drift_be <= 1e-12 && drift_bdf2 <= 1e-12, "mass drift BE %.3g, BDF2 %.3g", drift_be,
        drift_bdf2);
  free(u);
  sp_solver_destroy(&pb.solver);
  sp_layout_destroy(&pb.layout);
  sp_mesh_destroy(&pb.mesh);
  MPI_Finalize();
  TEST_DONE();
}
