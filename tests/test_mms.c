/* Manufactured solution for one Cahn-Hilliard cell on the unit square
 * (no-flux boundaries hold for cos(pi x) cos(pi y)):
 *   c(x,y,t) = C0 + A g(t) cos(pi x) cos(pi y),  s = c_t - M lap mu,
 *   mu = f'(c) - kappa lap c.
 * Space: g(t) = 1 + t is linear in time, so backward Euler has no time
 * error and the L2 error of c at t = T converges with order 2 in h.
 * Time: g(t) = exp(-RATE t) on a fine mesh, order 1 in dt. */
#include "fixtures.h"

#define C0 0.1
#define AMP 0.08
#define ALPHA 1.0
#define KAPPA 0.01
#define MOB 1.0
#define RATE 4.0
#ifndef TIME_MESH
#define TIME_MESH 128
#endif

typedef double (*time_fn)(double t, int derivative);
static double g_linear(double t, int d) { return d ? 1.0 : 1.0 + t; }
static double g_exp(double t, int d) { return d ? -RATE * exp(-RATE * t) : exp(-RATE * t); }

static double exact_c(double x, double y, double t, time_fn g) {
  return C0 + AMP * g(t, 0) * cos(M_PI * x) * cos(M_PI * y);
}

/* s = c_t - M lap mu with lap mu = f'''(c)|grad c|^2 + f''(c) lap c - kappa lap lap c */
static double exact_source(double x, double y, double t, time_fn g) {
  const double phi = cos(M_PI * x) * cos(M_PI * y);
  const double c = C0 + AMP * g(t, 0) * phi;
  const double k2 = 2 * M_PI * M_PI;
  const double lap_c = -k2 * AMP * g(t, 0) * phi;
  const double lap2_c = k2 * k2 * AMP * g(t, 0) * phi;
  const double a = AMP * g(t, 0) * M_PI;
  const double grad2 = a * a * (pow(sin(M_PI * x) * cos(M_PI * y), 2) +
                                pow(cos(M_PI * x) * sin(M_PI * y), 2));
  const double f2 = 2 * ALPHA * (6 * c * c - 6 * c + 1), f3 = 2 * ALPHA * (12 * c - 6);
  const double lap_mu = f3 * grad2 + f2 * lap_c - KAPPA * lap2_c;
  return AMP * g(t, 1) * phi - MOB * lap_mu;
}

/* L2 error of c at time T on an n x n mesh with n_steps steps. */
static double mms_error(int n, int n_steps, double T, time_fn g) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, n, n, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  sp_solver s = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  const int nn = mesh->n_nodes; /* one cell: pair p = node i */
  double *state = calloc(2 * nn, sizeof(double)), *old = calloc(2 * nn, sizeof(double));
  double *source = calloc(nn, sizeof(double));
  for (int i = 0; i < nn; ++i) state[2 * i] = exact_c(mesh->xy[2 * i], mesh->xy[2 * i + 1], 0, g);
  sp_step_data data = {.dt = T / n_steps,
                       .model = {.alpha = ALPHA, .kappa = KAPPA, .lambda = 0, .lambda_b = 0,
                                 .mobility = MOB},
                       .state_old = old, .source = source, .shape = NULL};
  for (int step = 1; step <= n_steps; ++step) {
    const double t = step * data.dt;
    for (int i = 0; i < 2 * nn; ++i) old[i] = state[i];
    for (int i = 0; i < nn; ++i) source[i] = exact_source(mesh->xy[2 * i], mesh->xy[2 * i + 1], t, g);
    sp_step_report rep;
    int rc = sp_solver_step(s, &data, state, &rep);
    CHECK(rc == 0, "MMS step %d on %d x %d: %s", step, n, n, sp_solver_last_error(s));
    if (rc) break;
  }
  /* L2 error with a 3x3 Gauss rule per element (exact c varies inside). */
  static const double gp[3] = {-0.7745966692414834, 0, 0.7745966692414834};
  static const double gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double err2 = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xy);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
        sp_q1_shape(2, (double[SP_Q1_MAX_DIM]){gp[i], gp[j], 0}, N, dN);
        double x = 0, y = 0, ch = 0;
        for (int a = 0; a < 4; ++a) {
          x += N[a] * xy[a][0];
          y += N[a] * xy[a][1];
          ch += N[a] * state[2 * mesh->elem[4 * e + a]];
        }
        const double area = fabs((xy[1][0] - xy[0][0]) * (xy[3][1] - xy[0][1])) / 4;
        const double d = ch - exact_c(x, y, T, g);
        err2 += gw[i] * gw[j] * area * d * d;
      }
  }
  sp_solver_destroy(&s);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  free(state); free(old); free(source);
  return sqrt(err2);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  printf("space: g(t) = 1 + t, T = 0.1, 10 steps\n  n   L2 error     order\n");
  const int meshes[] = {8, 16, 32, 64};
  double prev = 0;
  for (int i = 0; i < 4; ++i) {
    double e = mms_error(meshes[i], 10, 0.1, g_linear);
    double order = i ? log(prev / e) / log(2.0) : 0;
    printf("%4d  %.4e  %.3f\n", meshes[i], e, order);
    if (i >= 2) CHECK(fabs(order - 2.0) <= 0.15, "space order %.3f at n = %d", order, meshes[i]);
    prev = e;
  }
  printf("time: g(t) = exp(-%g t), T = 0.4, %d x %d mesh\n steps  L2 error     order\n", RATE, TIME_MESH, TIME_MESH);
  const int steps[] = {8, 16, 32, 64};
  for (int i = 0; i < 4; ++i) {
    double e = mms_error(TIME_MESH, steps[i], 0.4, g_exp);
    double order = i ? log(prev / e) / log(2.0) : 0;
    printf("%5d  %.4e  %.3f\n", steps[i], e, order);
    if (i >= 2) CHECK(fabs(order - 1.0) <= 0.1, "time order %.3f at %d steps", order, steps[i]);
    prev = e;
  }
  MPI_Finalize();
  TEST_DONE();
}
