/* Manufactured solution for one Cahn-Hilliard cell on the unit square or,
 * with the argument 3 (ctest test_mms_3d), the unit cube (no-flux
 * boundaries hold for the product of cos(pi x_d)):
 *   c(x,t) = C0 + A g(t) phi(x),  phi = prod_d cos(pi x_d),
 *   s = c_t - M lap mu,  mu = f'(c) - kappa lap c.
 * One code for both dimensions: the mesh (sp_mesh_rectangle, sp_mesh_box),
 * the source and the L2 error take dim.
 * Space: g(t) = 1 + t is linear in time, so backward Euler has no time
 * error and the L2 error of c at t = T converges with order 2 in h
 * (within 0.15).
 * Time, 2D: g(t) = exp(-RATE t) on a fine mesh, uniform steps: backward
 * Euler's error against the exact c has order 1 in dt (within 0.1).
 * Time, both dimensions: steps that are not uniform (the repeating pattern
 * 0.7, 1.3, 0.9, 1.1 of tests/test_time_order.c), through the stepper's
 * time scheme (src/time/time_scheme.h: BDF2 as a backward-Euler step from
 * c_hat): backward Euler order 1 and BDF2 order 2 (within 0.1), measured
 * from the differences of successive step refinements,
 * ||u_N - u_2N|| / ||u_2N - u_4N||, so the fixed spatial error of a coarse
 * mesh cancels. */
#include <time.h>

#include "fixtures.h"
#include "time/time_scheme.h"

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

static double phi_of(const double *x, int dim) {
  double phi = 1;
  for (int d = 0; d < dim; ++d) phi *= cos(M_PI * x[d]);
  return phi;
}

static double exact_c(const double *x, int dim, double t, time_fn g) {
  return C0 + AMP * g(t, 0) * phi_of(x, dim);
}

/* s = c_t - M lap mu with lap mu = f'''(c)|grad c|^2 + f''(c) lap c - kappa lap lap c,
 * lap phi = -dim pi^2 phi */
static double exact_source(const double *x, int dim, double t, time_fn g) {
  const double phi = phi_of(x, dim);
  const double c = C0 + AMP * g(t, 0) * phi;
  const double k2 = dim * M_PI * M_PI;
  const double lap_c = -k2 * AMP * g(t, 0) * phi;
  const double lap2_c = k2 * k2 * AMP * g(t, 0) * phi;
  const double a = AMP * g(t, 0) * M_PI;
  double grad2 = 0; /* |grad phi|^2 / pi^2 */
  for (int d = 0; d < dim; ++d) {
    double term = sin(M_PI * x[d]) * sin(M_PI * x[d]);
    for (int e = 0; e < dim; ++e)
      if (e != d) term *= cos(M_PI * x[e]) * cos(M_PI * x[e]);
    grad2 += term;
  }
  grad2 *= a * a;
  const double f2 = 2 * ALPHA * (6 * c * c - 6 * c + 1), f3 = 2 * ALPHA * (12 * c - 6);
  const double lap_mu = f3 * grad2 + f2 * lap_c - KAPPA * lap2_c;
  return AMP * g(t, 1) * phi - MOB * lap_mu;
}

typedef struct {
  int dim, n;
  sp_mesh *mesh;
  sp_layout *layout;
  sp_solver solver;
} problem;

static problem problem_create(int dim, int n) {
  problem pb = {.dim = dim, .n = n};
  if (dim == 2) CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, n, n, &pb.mesh));
  else CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, 1, n, n, n, &pb.mesh));
  CHECK_OK(sp_layout_create_full(pb.mesh->n_nodes, 1, &pb.layout));
  pb.solver = make_solver(pb.mesh, pb.layout, SP_SOLVER_JAC_AD);
  return pb;
}

static void problem_free(problem *pb) {
  sp_solver_destroy(&pb->solver);
  sp_layout_destroy(&pb->layout);
  sp_mesh_destroy(&pb->mesh);
}

/* Integrate to T with n_steps steps, uniform or of the pattern (mean T /
 * n_steps, the last one landing on T), by @p scheme; c at T into out (one
 * per node: one cell, pair p = node i). */
static void integrate(problem *pb, sp_scheme_kind scheme, int n_steps, int uniform, double T,
                      time_fn g, double *out) {
  static const double pattern[4] = {0.7, 1.3, 0.9, 1.1}; /* mean 1 */
  const sp_mesh *mesh = pb->mesh;
  const int nn = mesh->n_nodes, dim = mesh->dim;
  double *state = calloc(2 * nn, sizeof(double)), *old = calloc(2 * nn, sizeof(double));
  double *eff = calloc(2 * nn, sizeof(double)), *source = calloc(nn, sizeof(double));
  for (int i = 0; i < nn; ++i) state[2 * i] = exact_c(mesh->xy + (size_t)dim * i, dim, 0, g);
  sp_history hist = {0};
  const sp_model_params model = {.alpha = ALPHA, .kappa = KAPPA, .lambda = 0, .lambda_b = 0,
                                 .mobility = MOB};
  double t = 0;
  for (int step = 0; step < n_steps; ++step) {
    const double dt = uniform              ? T / n_steps
                      : step == n_steps - 1 ? T - t
                                            : T / n_steps * pattern[step % 4];
    memcpy(old, state, 2 * (size_t)nn * sizeof(double));
    const sp_scheme_kind kind = sp_scheme_of_step(scheme, &hist);
    double dt_eff;
    sp_scheme_be_form(kind, &hist, dt, old, (size_t)nn, eff, &dt_eff);
    const double t_new = uniform ? (step + 1) * dt : t + dt;
    for (int i = 0; i < nn; ++i)
      source[i] = exact_source(mesh->xy + (size_t)dim * i, dim, t_new, g);
    sp_step_data data = {.dt = dt_eff, .model = model, .state_old = eff, .source = source,
                         .shape = NULL};
    sp_step_report rep;
    const int rc = sp_solver_step(pb->solver, &data, state, &rep);
    CHECK(rc == 0, "MMS step %d on %d^%d: %s", step + 1, pb->n, dim,
          sp_solver_last_error(pb->solver));
    if (rc) break;
    CHECK_OK(sp_history_push(&hist, old, dt, 2 * (size_t)nn));
    t = t_new;
  }
  for (int i = 0; i < nn; ++i) out[i] = state[2 * i];
  sp_history_free(&hist);
  free(state); free(old); free(eff); free(source);
}

/* L2 error of the nodal c against the exact c at T, with a 3-point Gauss
 * rule per direction (the exact c varies inside an element). */
static double l2_error(const problem *pb, const double *c, double T, time_fn g) {
  static const double gp[3] = {-0.7745966692414834, 0, 0.7745966692414834};
  static const double gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  const sp_mesh *mesh = pb->mesh;
  const int dim = mesh->dim, nen = mesh->nodes_per_elem, nq = dim == 3 ? 27 : 9;
  double err2 = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xe);
    double measure = 1; /* axis-aligned elements: det J = prod of half edges */
    for (int d = 0; d < dim; ++d) {
      double lo = xe[0][d], hi = xe[0][d];
      for (int a = 1; a < nen; ++a) {
        lo = fmin(lo, xe[a][d]);
        hi = fmax(hi, xe[a][d]);
      }
      measure *= (hi - lo) / 2;
    }
    for (int q = 0; q < nq; ++q) {
      const int idx[3] = {q % 3, q / 3 % 3, q / 9};
      double xi[SP_Q1_MAX_DIM] = {0, 0, 0}, w = 1;
      for (int d = 0; d < dim; ++d) {
        xi[d] = gp[idx[d]];
        w *= gw[idx[d]];
      }
      double N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
      sp_q1_shape(dim, xi, N, dN);
      double x[3] = {0, 0, 0}, ch = 0;
      for (int a = 0; a < nen; ++a) {
        for (int d = 0; d < dim; ++d) x[d] += N[a] * xe[a][d];
        ch += N[a] * c[mesh->elem[nen * e + a]];
      }
      const double diff = ch - exact_c(x, dim, T, g);
      err2 += w * measure * diff * diff;
    }
  }
  return sqrt(err2);
}

/* L2 norm (nodal, lumped on the uniform mesh) of a - b */
static double l2_diff(const problem *pb, const double *a, const double *b) {
  double h_dim = 1, sum = 0;
  for (int d = 0; d < pb->dim; ++d) h_dim /= pb->n;
  for (int i = 0; i < pb->mesh->n_nodes; ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return sqrt(sum * h_dim);
}

/* The L2 error at T of an n^dim mesh, n_steps uniform backward-Euler steps. */
static double mms_error(int dim, int n, int n_steps, double T, time_fn g) {
  problem pb = problem_create(dim, n);
  double *c = calloc((size_t)pb.mesh->n_nodes, sizeof(double));
  integrate(&pb, SP_SCHEME_BE, n_steps, 1, T, g, c);
  const double e = l2_error(&pb, c, T, g);
  free(c);
  problem_free(&pb);
  return e;
}

static void space_order(int dim) {
  /* 2D: 8 to 64 in 10 steps; 3D: 6, 12, 18 in 2 (the time error is 0
   * with g linear: fewer solves of the largest system, whose direct
   * factorisations cost the most); the last two ratios checked in each */
  const int meshes[2][4] = {{8, 16, 32, 64}, {6, 12, 18, 0}};
  const int *n = meshes[dim - 2], levels = dim == 2 ? 4 : 3, n_steps = dim == 2 ? 10 : 2;
  printf("space, %dD: g(t) = 1 + t, T = 0.1, %d steps\n  n   L2 error     order\n", dim,
         n_steps);
  double prev = 0;
  for (int i = 0; i < levels; ++i) {
    const double e = mms_error(dim, n[i], n_steps, 0.1, g_linear);
    const double order = i ? log(prev / e) / log((double)n[i] / n[i - 1]) : 0;
    printf("%4d  %.4e  %.3f\n", n[i], e, order);
    if (i >= levels - 2 && i > 0)
      CHECK(fabs(order - 2.0) <= 0.15, "%dD space order %.3f at n = %d", dim, order, n[i]);
    prev = e;
  }
}

/* 2D: backward Euler's error against the exact c on a fine mesh */
static void time_order_exact(void) {
  printf("time, 2D: g(t) = exp(-%g t), T = 0.4, %d x %d mesh, uniform BE steps\n steps  L2 "
         "error     order\n", RATE, TIME_MESH, TIME_MESH);
  const int steps[] = {8, 16, 32, 64};
  double prev = 0;
  for (int i = 0; i < 4; ++i) {
    const double e = mms_error(2, TIME_MESH, steps[i], 0.4, g_exp);
    const double order = i ? log(prev / e) / log(2.0) : 0;
    printf("%5d  %.4e  %.3f\n", steps[i], e, order);
    if (i >= 2) CHECK(fabs(order - 1.0) <= 0.1, "time order %.3f at %d steps", order, steps[i]);
    prev = e;
  }
}

/* BE and BDF2 with the non-uniform steps: orders from successive
 * differences on a coarse mesh */
static void time_orders_nonuniform(int dim) {
  enum { LEVELS = 5 };
  const int steps[LEVELS] = {10, 20, 40, 80, 160};
  const int n = dim == 2 ? 24 : 6;
  problem pb = problem_create(dim, n);
  const size_t nn = (size_t)pb.mesh->n_nodes;
  for (int s = 0; s < 2; ++s) {
    const sp_scheme_kind scheme = s ? SP_SCHEME_BDF2 : SP_SCHEME_BE;
    const double expected = s ? 2.0 : 1.0;
    printf("time, %dD: g(t) = exp(-%g t), T = 0.4, %d^%d mesh, %s, steps 0.7, 1.3, 0.9, 1.1 x "
           "T/N\n  N  error against the exact c at T, ||u_N - u_2N||, order\n", dim, RATE, n,
           dim, s ? "BDF2" : "BE");
    double *u[LEVELS];
    for (int i = 0; i < LEVELS; ++i) {
      u[i] = calloc(nn, sizeof(double));
      integrate(&pb, scheme, steps[i], 0, 0.4, g_exp, u[i]);
    }
    double prev = 0;
    for (int i = 0; i + 1 < LEVELS; ++i) {
      const double d = l2_diff(&pb, u[i], u[i + 1]);
      const double order = i ? log(prev / d) / log(2.0) : 0;
      printf("  %4d  %.4e  %.4e  %.3f\n", steps[i], l2_error(&pb, u[i], 0.4, g_exp), d, order);
      if (i >= 2)
        CHECK(fabs(order - expected) <= 0.1, "%dD %s order %.3f between %d and %d steps", dim,
              s ? "BDF2" : "BE", order, steps[i], steps[i + 1]);
      prev = d;
    }
    for (int i = 0; i < LEVELS; ++i) free(u[i]);
  }
  problem_free(&pb);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const int dim = argc > 1 ? atoi(argv[1]) : 2;
  CHECK(dim == 2 || dim == 3, "dimension %d: expected 2 or 3", dim);
  if (dim == 2 || dim == 3) {
    clock_t start = clock();
    space_order(dim);
    printf("(%.1f s of CPU)\n", (double)(clock() - start) / CLOCKS_PER_SEC);
    if (dim == 2) {
      start = clock();
      time_order_exact();
      printf("(%.1f s of CPU)\n", (double)(clock() - start) / CLOCKS_PER_SEC);
    }
    start = clock();
    time_orders_nonuniform(dim);
    printf("(%.1f s of CPU)\n", (double)(clock() - start) / CLOCKS_PER_SEC);
  }
  MPI_Finalize();
  TEST_DONE();
}
