/* The shape penalty (src/model/shape.c, docs/model.md "Shape penalty"):
 * - inertia tensors of a disk, an ellipse and a rotated ellipse with a thin
 *   tanh profile against the profile's exact integrals, on three meshes
 *   (second order in h), and the area inside c = 1/2 against pi a b;
 * - Ihat^i(X) = v_i . Ibar(X) v_i: int N_j Ihat^i equals the central
 *   difference dI^i/dc_j, and the glue's mu term is minus the derivative of
 *   the reported shape energy (its sign);
 * - round cells with delta1 != delta2: coefficients finite, bounded and
 *   direction-free; solver steps with the term stay finite and obey the
 *   scheme's energy law (below);
 * - the dynamics: I^2 moves toward I^2,ref (compared with delta = 0);
 * - the stepper: energy.csv's shape column is the energy of cells.csv's
 *   moments against the birth moments. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/division.h"
#include "scene/scene.h"
#include "shape_fixtures.h"

#define PI 3.14159265358979323846

/** int_0^inf rho^3 / (1 + exp((rho - 1)/eps)) d rho (Sommerfeld expansion,
 *  exact up to O(exp(-1/eps))): 1/4 + pi^2 eps^2 / 2 + 7 pi^4 eps^4 / 60. */
static double profile_moment(double eps) {
  return 0.25 + PI * PI * eps * eps / 2.0 + 7.0 * pow(PI, 4) * pow(eps, 4) / 60.0;
}

/* 1. Tensors of the tanh disk and ellipses against their exact integrals:
 * int c v^2 = pi a b^3 J, int c u^2 = pi a^3 b J (u, v along the axes),
 * J = profile_moment(eps); rotated: I = tr(S) Id - S, S = R diag R^T. */
static void test_tensors(void) {
  const struct {
    const char *name;
    double a, b, phi, eps;
  } shapes[] = {{"disk R = 0.2", 0.2, 0.2, 0.0, 0.03},
                {"ellipse 0.25 x 0.12", 0.25, 0.12, 0.0, 0.05},
                {"ellipse 0.25 x 0.12 at 0.6 rad", 0.25, 0.12, 0.6, 0.05}};
  const int meshes[] = {100, 200, 400};
  /* off the mesh nodes and off centre, so no symmetry helps */
  const double xc = 0.0131, yc = -0.0077;
  printf("inertia tensors of thin tanh profiles (weight threshold 0) on [-0.5,0.5]^2:\n");
  printf("  %-32s | mesh | max |I_ij - exact| / I1 | I1/I2 (exact)   | v1 angle error\n",
         "shape");
  for (size_t s = 0; s < sizeof shapes / sizeof *shapes; ++s) {
    const double a = shapes[s].a, b = shapes[s].b, phi = shapes[s].phi;
    const double J = profile_moment(shapes[s].eps);
    const double Su = PI * a * a * a * b * J, Sv = PI * a * b * b * b * J;
    const double cs = cos(phi), sn = sin(phi);
    /* S = int c X X^T, I = tr(S) Id - S */
    const double Sxx = Su * cs * cs + Sv * sn * sn, Syy = Su * sn * sn + Sv * cs * cs;
    const double Sxy = (Su - Sv) * sn * cs;
    const double exact[3] = {Syy, Sxx, -Sxy}; /* Ixx, Iyy, Ixy */
    double error[3];
    for (int m = 0; m < 3; ++m) {
      sp_mesh *mesh;
      sp_layout *layout;
      CHECK_OK(sp_mesh_rectangle(-0.5, -0.5, 0.5, 0.5, meshes[m], meshes[m], &mesh));
      CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
      double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
      set_ellipse(mesh, layout, state, 0, xc, yc, a, b, phi, shapes[s].eps);
      sp_cell_obs obs;
      CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, &obs));
      const double got[3] = {obs.inertia[0][0], obs.inertia[1][1], obs.inertia[0][1]};
      error[m] = 0;
      for (int c = 0; c < 3; ++c) error[m] = fmax(error[m], fabs(got[c] - exact[c]) / Su);
      /* v1 is the larger moment's: perpendicular to the long axis */
      const double angle_error =
          a > b ? asin(fmin(1.0, fabs(obs.axes[0][0] * cs + obs.axes[0][1] * sn))) : 0.0;
      printf("  %-32s | %4d | %22.3e | %.4f (%.4f) | %.2e\n", shapes[s].name, meshes[m],
             error[m], obs.moments[0] / obs.moments[1], Su / Sv, angle_error);
      /* the c = 1/2 level set is rho = 1: the area inside is pi a b */
      const double area_error = fabs(obs.volume - PI * a * b) / (PI * a * b);
      printf("  %-32s | %4d | area (c >= 1/2) %.6f, pi a b %.6f: relative error %.1e\n",
             shapes[s].name, meshes[m], obs.volume, PI * a * b, area_error);
      if (m == 2) {
        CHECK(area_error < 2e-3, "%s: area off by %.3g relative", shapes[s].name, area_error);
        CHECK(error[m] < 2e-4, "%s: tensor error %.3g on the finest mesh", shapes[s].name,
              error[m]);
        if (a > b) CHECK(angle_error < 1e-4, "%s: v1 off by %.3g rad", shapes[s].name,
                         angle_error);
      }
      free(state);
      sp_layout_destroy(&layout);
      sp_mesh_destroy(&mesh);
    }
    const double order = log(error[1] / error[2]) / log(2.0);
    printf("  %-32s | observed order (200 -> 400): %.2f\n", shapes[s].name, order);
    CHECK(order > 1.7, "%s: order %.2f", shapes[s].name, order);
  }
}

/** int N_j Ihat(X) dX over the elements around node j (2x2 Gauss, as the
 *  observables), Ihat = v . Ibar(X) v about (xc, yc). */
static double node_integral_ihat(const sp_mesh *mesh, int node, double xc, double yc,
                                 const double v[2]) {
  double sum = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    int a = -1;
    for (int l = 0; l < 4; ++l)
      if (mesh->elem[4 * e + l] == node) a = l;
    if (a < 0) continue;
    double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xy);
    for (int q = 0; q < sp_q1_qpoints(2); ++q) {
      double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
      sp_q1_point(2, xy, q, N, dNdx, x, &w);
      const double xb = x[0] - xc, yb = x[1] - yc;
      const double ihat = v[0] * v[0] * yb * yb - 2 * v[0] * v[1] * xb * yb + v[1] * v[1] * xb * xb;
      sum += w * N[a] * ihat;
    }
  }
  return sum;
}

/* 2. Ihat is the derivative of the principal moments, and the glue's mu term
 * is minus the derivative of the reported energy. */
static void test_derivatives(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 40, 40, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  const size_t n_values = 2 * (size_t)layout->n_pairs;
  double *state = calloc(n_values, sizeof(double));
  set_ellipse(mesh, layout, state, 0, 0.507, 0.489, 0.22, 0.12, 0.4, 0.1);
  /* a background of 0.02: with threshold 0, c < 0 does not count, and a
   * central difference at c ~ 0 would step across that kink */
  for (int p = 0; p < layout->n_pairs; ++p) state[2 * p] += 0.02;
  sp_cell_obs obs;
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, &obs));
  printf("derivatives on an elongated cell (I1/I2 = %.3f, 40x40 mesh, threshold 0):\n",
         obs.moments[0] / obs.moments[1]);
  /* (a) int N_j Ihat^i against central differences of I^i */
  const double step = 1e-4;
  double worst[2] = {0, 0}, scale[2] = {0, 0};
  for (int j = 0; j < mesh->n_nodes; j += 7) {
    const int p = sp_layout_pair(layout, 0, j);
    sp_cell_obs plus, minus;
    observe_plus_minus(mesh, layout, state, p, step, &plus, &minus);
    const double fd[2] = {(plus.moments[0] - minus.moments[0]) / (2 * step), (plus.moments[1] - minus.moments[1]) / (2 * step)};
    const double an[2] = {node_integral_ihat(mesh, j, obs.centre[0], obs.centre[1], obs.axes[0]),
                          node_integral_ihat(mesh, j, obs.centre[0], obs.centre[1], obs.axes[1])};
    for (int i = 0; i < 2; ++i) {
      worst[i] = fmax(worst[i], fabs(fd[i] - an[i]));
      scale[i] = fmax(scale[i], fabs(an[i]));
    }
  }
  for (int i = 0; i < 2; ++i) {
    printf("  dI%d/dc_j: max |central difference - int N_j Ihat%d| / max |int N_j Ihat%d| "
           "= %.2e (%d nodes)\n", i + 1, i + 1, i + 1, worst[i] / scale[i],
           (mesh->n_nodes + 6) / 7);
    CHECK(worst[i] <= 1e-6 * scale[i], "dI%d/dc: relative error %.3g", i + 1,
          worst[i] / scale[i]);
  }

  /* (b) the glue: R_mu(with shape) - R_mu(without) = -dE_shape/dc_j */
  const double delta1 = 3e4, delta2 = 7e4;
  sp_cell_birth birth = {.birth_mass = obs.mass, .Iref = {0.9 * obs.moments[0], 1.2 * obs.moments[1]}};
  sp_shape_coef coef;
  CHECK_OK(sp_shape_coefficients(2, 1, &obs, &birth, (double[3]){delta1, delta2, 0}, &coef));
  sp_solver solver = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  double *without = malloc(n_values * sizeof(double)), *with = malloc(n_values * sizeof(double));
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = state};
  CHECK(sp_solver_residual(solver, &data, state, without) == 0, "residual: %s",
        sp_solver_last_error(solver));
  data.shape = &coef;
  CHECK(sp_solver_residual(solver, &data, state, with) == 0, "residual: %s",
        sp_solver_last_error(solver));
  double worst_e = 0, scale_e = 0, worst_c = 0;
  for (int j = 0; j < mesh->n_nodes; j += 7) {
    const int p = sp_layout_pair(layout, 0, j);
    const double dE = shape_energy_fd(mesh, layout, state, p, step, &birth, delta1, delta2);
    const double glue = with[2 * p + 1] - without[2 * p + 1];
    worst_e = fmax(worst_e, fabs(glue + dE));
    scale_e = fmax(scale_e, fabs(dE));
    worst_c = fmax(worst_c, fabs(with[2 * p] - without[2 * p])); /* c rows untouched */
  }
  printf("  glue: max |(R_mu with - without) + dE_shape/dc_j| / max |dE/dc_j| = %.2e; "
         "c rows changed by %.1e\n", worst_e / scale_e, worst_c);
  CHECK(worst_e <= 1e-6 * scale_e, "mu term vs -dE/dc: relative %.3g", worst_e / scale_e);
  CHECK(worst_c == 0.0, "the shape term changed a c row by %.3g", worst_c);
  free(without);
  free(with);
  sp_solver_destroy(&solver);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/** Force tensor sum_i coef_i v_i v_i^T of one cell: xx, yy, xy. */
static void force_tensor(const sp_shape_coef *s, double t[3]) {
  t[0] = t[1] = t[2] = 0;
  for (int i = 0; i < 2; ++i) {
    t[0] += s->coef[i] * s->v[i][0] * s->v[i][0];
    t[1] += s->coef[i] * s->v[i][1] * s->v[i][1];
    t[2] += s->coef[i] * s->v[i][0] * s->v[i][1];
  }
}

/** Observables with given principal moments and v1 at angle theta. */
static sp_cell_obs make_obs(double I1, double I2, double theta) {
  sp_cell_obs o = {.mass = 1, .mass_core = 1, .centre = {0.3, 0.2}, .moments = {I1, I2},
                   .long_axis = 1};
  o.axes[0][0] = cos(theta);
  o.axes[0][1] = sin(theta);
  o.axes[1][0] = -o.axes[0][1];
  o.axes[1][1] = o.axes[0][0];
  return o;
}

/* 3. Round cells with delta1 != delta2. */
static void test_round(void) {
  const double delta1 = 1e5, delta2 = 4e5, I = 1e-4;
  const sp_cell_birth birth = {.birth_mass = 1, .Iref = {0.9 * I, 1.1 * I}};
  const double c1 = 2 * delta1 * (birth.Iref[0] - I), c2 = 2 * delta2 * (birth.Iref[1] - I);
  printf("round cells, delta1 = %g, delta2 = %g: exact coefficients c1 = %g, c2 = %g\n",
         delta1, delta2, c1, c2);
  /* exactly round: isotropic, both coefficients the mean */
  sp_cell_obs round = make_obs(I, I, 0.0);
  sp_shape_coef s;
  CHECK_OK(sp_shape_coefficients(2, 1, &round, &birth, (double[3]){delta1, delta2, 0}, &s));
  printf("  I1 = I2: coef = (%g, %g)\n", s.coef[0], s.coef[1]);
  CHECK(s.coef[0] == s.coef[1], "round: coef %g != %g", s.coef[0], s.coef[1]);
  CHECK_NEAR(s.coef[0], 0.5 * (c1 + c2), 1e-12 * fabs(c1 - c2));
  /* nearly round: the eigenvectors swap under a tiny change (v1 along x or
   * along y), the force tensor must not */
  const double tiny = 1e-7;
  sp_cell_obs a = make_obs(I * (1 + tiny), I * (1 - tiny), 0.0);
  sp_cell_obs b = make_obs(I * (1 + tiny), I * (1 - tiny), PI / 2);
  sp_shape_coef sa, sb;
  CHECK_OK(sp_shape_coefficients(2, 1, &a, &birth, (double[3]){delta1, delta2, 0}, &sa));
  CHECK_OK(sp_shape_coefficients(2, 1, &b, &birth, (double[3]){delta1, delta2, 0}, &sb));
  double ta[3], tb[3], jump = 0;
  force_tensor(&sa, ta);
  force_tensor(&sb, tb);
  for (int c = 0; c < 3; ++c) jump = fmax(jump, fabs(ta[c] - tb[c]));
  printf("  e = 1e-7, v1 along x vs along y: force tensors differ by %.2e (exact eigenvector "
         "form: |c1 - c2| = %.3g)\n", jump, fabs(c1 - c2));
  CHECK(jump <= 1e-4 * fabs(c1 - c2), "nearly round: force jumps by %.3g", jump);
  /* blend: linear in e below SP_SHAPE_ROUND_TOL, exact above */
  const double es[] = {0.0, 0.25 * SP_SHAPE_ROUND_TOL, 0.5 * SP_SHAPE_ROUND_TOL,
                       SP_SHAPE_ROUND_TOL, 2 * SP_SHAPE_ROUND_TOL, 0.5};
  printf("  e        | coef1      | coef2      | exact c1   | exact c2   | |coef| <= max|c|\n");
  for (size_t k = 0; k < sizeof es / sizeof *es; ++k) {
    const double e = es[k];
    sp_cell_obs o = make_obs(I * (1 + e), I * (1 - e), 0.3);
    sp_shape_coef t;
    CHECK_OK(sp_shape_coefficients(2, 1, &o, &birth, (double[3]){delta1, delta2, 0}, &t));
    const double e1 = 2 * delta1 * (birth.Iref[0] - o.moments[0]), e2 = 2 * delta2 * (birth.Iref[1] - o.moments[1]);
    const double bound = fmax(fabs(e1), fabs(e2));
    const int bounded = fabs(t.coef[0]) <= bound * (1 + 1e-14) &&
                        fabs(t.coef[1]) <= bound * (1 + 1e-14);
    printf("  %.2e | %10.4g | %10.4g | %10.4g | %10.4g | %s\n", e, t.coef[0], t.coef[1], e1, e2,
           bounded ? "yes" : "NO");
    CHECK(bounded, "e = %g: coefficients exceed max |c_i|", e);
    if (e >= SP_SHAPE_ROUND_TOL) {
      CHECK_NEAR(t.coef[0], e1, 1e-12 * bound);
      CHECK_NEAR(t.coef[1], e2, 1e-12 * bound);
    } else {
      const double w = e / SP_SHAPE_ROUND_TOL;
      CHECK_NEAR(t.coef[0] - t.coef[1], w * (e1 - e2), 1e-12 * bound);
      CHECK_NEAR(t.coef[0] + t.coef[1], e1 + e2, 1e-12 * bound);
    }
  }
  /* degenerate input: no mass, NaN moments: zero coefficients, no NaN */
  sp_cell_obs bad[3] = {make_obs(0, 0, 0), make_obs(NAN, 1e-4, 0), make_obs(1e-4, -2e-4, 0)};
  sp_cell_birth births[3] = {birth, birth, birth};
  sp_shape_coef out[3];
  CHECK_OK(sp_shape_coefficients(2, 3, bad, births, (double[3]){delta1, delta2, 0}, out));
  for (int k = 0; k < 3; ++k)
    CHECK(out[k].coef[0] == 0 && out[k].coef[1] == 0 && isfinite(out[k].xc) &&
              isfinite(out[k].v[0][0]),
          "degenerate case %d: coef (%g, %g)", k, out[k].coef[0], out[k].coef[1]);
  CHECK(sp_shape_coefficients(2, 1, &round, &birth, (double[3]){-1.0, delta2, 0}, &s) ==
            SP_ERR_INPUT,
        "negative delta1 accepted");
  sp_error_clear();
  CHECK(sp_shape_energy(1, &round, &birth, (double[3]){0.0, 0.0, 0}) == 0.0,
        "energy with zero moduli");

  /* a symmetric round tanh disk (I1 = I2 to round-off) with Iref pulling
   * the moments apart: a few solver steps stay finite, and obey the energy
   * law of backward Euler with the explicit shape term. That term adds
   * -sum_i coef_i Ihat_i to mu with coef and Ihat (centre, axes, mask) fixed
   * at c^n: the potential of the linear functional L(c) = -sum_i coef_i
   * J_i(c), J_i(c) = int_mask Ihat_i c. The step is then the minimiser of
   * Pi_CH(c) + L(c) + |c - c^n|^2_{H^-1} / (2 M dt), as the step without
   * the term is of the same without L (docs/model.md, "Fields and energy";
   * tests/test_energy.c), so
   *     Pi_CH(c^n+1) - Pi_CH(c^n) <= -(L(c^n+1) - L(c^n)) = sum_p D_p (c^n+1_p - c^n_p),
   * D_p = sum_i coef_i int N_p Ihat_i: the term's part of the mu residual
   * (the residual with the term minus without, which does not depend on
   * the state). The reported total (Pi_CH + the shape energy of the new
   * moments) has no such bound: the lagged coefficients miss the shape
   * energy's curvature, delta_i (dI_i)^2 per step. */
  one_cell o = one_cell_create();
  const sp_mesh *mesh = o.mesh;
  const sp_layout *layout = o.layout;
  const size_t n_values = o.n_values;
  double *state = o.state, *old = o.old;
  const sp_model_params model = paper_model();
  set_disk(mesh, layout, state, 0, 0.25, 0.25, 0.1, sqrt(model.kappa / (2 * model.alpha)));
  sp_cell_obs obs;
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.05, &obs));
  const sp_cell_birth disk_birth = {.birth_mass = obs.mass_core,
                                    .Iref = {0.8 * obs.moments[0], 1.2 * obs.moments[1]}};
  sp_solver solver = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  const double e0 = energy_total(solver, &model, state) +
                    sp_shape_energy(1, &obs, &disk_birth, (double[3]){delta1, delta2, 0});
  printf("  disk R = 0.1 on a 64x64 mesh, (I1 - I2)/(I1 + I2) = %.1e, Iref = (0.8, 1.2) I:\n",
         (obs.moments[0] - obs.moments[1]) / (obs.moments[0] + obs.moments[1]));
  printf("    step | energy (CH + shape) | I1/I2    | coef1     | coef2     | dPi_CH     | "
         "-dL\n");
  printf("    %4d | %19.10g | %.6f |           |           |            |\n", 0, e0,
         obs.moments[0] / obs.moments[1]);
  int finite = 1;
  double *with = malloc(n_values * sizeof(double)), *without = malloc(n_values * sizeof(double));
  for (int n = 1; n <= 5; ++n) {
    sp_shape_coef sc;
    CHECK_OK(sp_shape_coefficients(2, 1, &obs, &disk_birth, (double[3]){delta1, delta2, 0}, &sc));
    memcpy(old, state, n_values * sizeof(double));
    sp_step_data data = {.dt = 2e-4, .model = model, .state_old = old, .shape = &sc};
    sp_step_data bare = data;
    bare.shape = NULL;
    CHECK(sp_solver_residual(solver, &data, old, with) == 0, "%s", sp_solver_last_error(solver));
    CHECK(sp_solver_residual(solver, &bare, old, without) == 0, "%s",
          sp_solver_last_error(solver));
    const double pi_old = energy_total(solver, &model, old);
    sp_step_report rep;
    const int rc = sp_solver_step(solver, &data, state, &rep);
    CHECK(rc == 0, "round disk, step %d: %s", n, rep.reason);
    CHECK_OK(sp_cells_observe(mesh, layout, state, 0.05, &obs));
    const double pi_new = energy_total(solver, &model, state);
    const double e = pi_new + sp_shape_energy(1, &obs, &disk_birth, (double[3]){delta1, delta2, 0});
    double minus_dl = 0; /* sum_p D_p (c^n+1_p - c^n_p) */
    for (int p = 0; p < layout->n_pairs; ++p)
      minus_dl += (with[2 * p + 1] - without[2 * p + 1]) * (state[2 * p] - old[2 * p]);
    for (size_t i = 0; i < n_values; ++i) finite &= isfinite(state[i]) != 0;
    finite &= isfinite(e) && isfinite(sc.coef[0]) && isfinite(sc.coef[1]);
    printf("    %4d | %19.10g | %.6f | %9.4g | %9.4g | %10.3e | %10.3e\n", n, e,
           obs.moments[0] / obs.moments[1], sc.coef[0], sc.coef[1], pi_new - pi_old, minus_dl);
    /* round-off: the energies are sums over elements (1e-13 relative) */
    CHECK(pi_new - pi_old <= minus_dl + 1e-12 * fabs(pi_old),
          "round disk, step %d: Pi_CH changed by %.6g, the law allows %.6g", n, pi_new - pi_old,
          minus_dl);
  }
  free(with);
  free(without);
  CHECK(finite, "non-finite values in the round-disk steps");
  CHECK(obs.moments[0] / obs.moments[1] < 1.01, "round disk: became elongated (I1/I2 = %.4f)", obs.moments[0] / obs.moments[1]);
  sp_solver_destroy(&solver);
  one_cell_destroy(&o);
}

/** K steps of a slightly elongated cell on a background, with (delta2 > 0)
 *  or without the shape term, moments with weight threshold @p threshold;
 *  returns I2 at the end. */
static double evolve_i2(double delta2, double iref2_factor, int steps, double threshold,
                        double background, double *i2_start, double *i2_ref) {
  const relax_result r = relax_ellipse((relax_setup){
      .delta2 = delta2, .iref2_factor = iref2_factor, .threshold = threshold,
      .background = background, .linear = SP_LINEAR_SUPERLU, .steps = steps, .dt = 2e-4});
  CHECK(r.ok, "step %d: %s", r.steps_done + 1, r.failed.reason);
  *i2_start = r.i2_start;
  *i2_ref = r.i2_ref;
  return r.i2_end;
}

/* 4. The sign in the dynamics: I^2 moves toward I^2,ref, with weight
 * threshold 0 on a background of 0.02 and with the stepper's threshold 0.05
 * (the term then acts only where c^n >= 0.05, where the moments count c:
 * the exact derivative of the thresholded moments at t^n). */
static void test_sign(void) {
  const int steps = 10;
  const double delta2 = 2e5;
  printf("sign: a 0.11 x 0.09 tanh ellipse, %d steps of dt = 2e-4, delta1 = 0, delta2 = %g:\n",
         steps, delta2);
  printf("  threshold, background | I2,ref / I2 | I2 start   | I2 (delta = 0) | I2 (delta2)  | "
         "toward I2,ref\n");
  const double factors[] = {1.3, 0.7};
  const double settings[2][2] = {{0.0, 0.02}, {0.05, 0.0}};
  for (int c = 0; c < 2; ++c)
    for (int f = 0; f < 2; ++f) {
      double start, ref;
      const double free_i2 =
          evolve_i2(0.0, factors[f], steps, settings[c][0], settings[c][1], &start, &ref);
      const double shaped =
          evolve_i2(delta2, factors[f], steps, settings[c][0], settings[c][1], &start, &ref);
      /* the penalty must move I2 further toward Iref than relaxation alone */
      const int toward = factors[f] > 1 ? shaped > free_i2 : shaped < free_i2;
      printf("  %9.2f, %10.2f | %11.2f | %.4e | %14.6e | %12.6e | %s (%+.1f%% of the gap)%s\n",
             settings[c][0], settings[c][1], factors[f], start, free_i2, shaped,
             toward ? "yes" : "no", 100 * (shaped - free_i2) / (ref - start), "");
      CHECK(toward, "Iref2 = %.2f I2: I2 %.6g with delta2, %.6g without", factors[f], shaped,
              free_i2);
    }
}

/** Column @p col (from 0) of the row of @p step in a CSV file (NAN if absent). */
static double csv_value(const char *path, int step, int col, int cell) {
  FILE *f = fopen(path, "r");
  char line[2048];
  double value = NAN;
  if (!f) return NAN;
  if (!fgets(line, sizeof line, f)) { fclose(f); return NAN; }
  while (fgets(line, sizeof line, f)) {
    int row_step = atoi(line);
    if (row_step != step) continue;
    char *p = line;
    int this_cell = -1;
    for (int c = 0; c < col && p; ++c) {
      p = strchr(p, ',');
      if (p) ++p;
      if (c == 1 && p) this_cell = atoi(p); /* cells.csv: step,t,cell,... */
    }
    if (p && (cell < 0 || this_cell == cell)) { value = atof(p); break; }
  }
  fclose(f);
  return value;
}

/* 5. The stepper: energy.csv's shape column is delta2 (I2(0) - I2(t))^2 of
 * cells.csv's moments (the initial cell's birth moments are at t = 0), and
 * it is in the total. */
static void test_stepper(void) {
  const char *path = "test_shape_scene.yaml";
  FILE *f = fopen(path, "w");
  CHECK(f != NULL, "cannot write %s", path);
  if (!f) return;
  fprintf(f, "mesh: {type: rectangle, x0: 0, y0: 0, x1: 0.5, y1: 0.5, nx: 48, ny: 48}\n"
             "time: {dt: 2.0e-4, t_end: 0.002}\n"
             "source: {rate: 5.0e2, off_ratio: 1.5}\n"
             "division: {criterion: none, max_cells: 1}\n"
             "shape: {delta1: 0, delta2: 2.0e5}\n"
             "cells:\n  - {x: 0.25, y: 0.25, radius: 0.08}\n"
             "output: {every: 100, pictures: false}\n");
  fclose(f);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(path, 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_shape_out", MPI_COMM_WORLD, &sum));
  printf("stepper: %d steps with delta2 = %g and a source\n", sum.steps, scene->shape.delta2);
  const double i2_0 = csv_value("test_shape_out/cells.csv", 0, 7, 1);
  double worst = 0, largest = 0;
  for (int step = 0; step <= sum.steps; ++step) {
    const double shape = csv_value("test_shape_out/energy.csv", step, 10, -1);
    const double i2 = csv_value("test_shape_out/cells.csv", step, 7, 1);
    const double expected = scene->shape.delta2 * (i2_0 - i2) * (i2_0 - i2);
    double parts = 0;
    for (int c = 6; c <= 10; ++c) parts += csv_value("test_shape_out/energy.csv", step, c, -1);
    const double total = csv_value("test_shape_out/energy.csv", step, 5, -1);
    worst = fmax(worst, fabs(shape - expected) / fmax(expected, 1e-300));
    largest = fmax(largest, shape);
    CHECK(fabs(total - parts) <= 1e-12 * fabs(total), "step %d: total %.15g, parts %.15g",
          step, total, parts);
  }
  printf("  shape column vs delta2 (I2,ref - I2)^2 from cells.csv: largest relative difference "
         "%.1e; largest shape energy %.3g\n", worst, largest);
  CHECK(largest > 0, "the shape column stayed 0");
  CHECK(worst <= 1e-9, "shape column off by %.3g relative", worst);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  test_tensors();
  test_derivatives();
  test_round();
  test_sign();
  test_stepper();
  MPI_Finalize();
  TEST_DONE();
}
