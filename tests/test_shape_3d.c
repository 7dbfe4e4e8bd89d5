/* The shape penalty on the three principal moments of a 3D cell (src/model/shape.h,
 * docs/3d.md "Shape term in 3D"):
 * 1. on a tanh ellipsoid with three distinct moments (rotated, on a box of
 *    hexahedra): the glue's Ihat_i = |v_i x Xb|^2 integrated against N_j is
 *    the central difference dI^i/dc_j of the observed moments (i = 1, 2, 3),
 *    and the glue's mu term with the coefficients of sp_shape_coefficients
 *    is minus the central difference of sp_shape_energy, both to 1e-6;
 * 2. degenerate moments (a sphere: three equal; prolate and oblate
 *    spheroids: two equal): the coefficients of equal moments are equal
 *    (the mean of their exact values, to 1e-12), the others exact; with the
 *    moments split by 1e-7 and the eigenvectors of the (near-)degenerate
 *    eigenspace turned, the force tensor sum_i coef_i v_i v_i^T moves by
 *    at most 1e-4 of the exact coefficients' spread (the exact eigenvector
 *    form jumps by that spread); on random near-degenerate moments every
 *    coefficient is bounded by max_j |c_j| and the force tensor is
 *    continuous in the moments (a split of 1e-9 of the trace moves it by
 *    less than 1e-5 of the spread); exact once every gap is >= the
 *    tolerance; no NaN for empty or non-finite cells; delta3 refused in 2D;
 * 3. solver steps of a prolate spheroid (I^1 = I^2) with I^3,ref below
 *    I^3 (after 10 steps without the term, while it keeps rounding): with
 *    delta3 (1e6 explicit, 2e6 implicit, delta1 = 2e5 and delta2 = 6e5 on
 *    the equal pair) the gap |I^3,ref - I^3| shrinks over 10 steps (and I^3 ends
 *    below the run without the term), the moments stay finite, I^1 = I^2
 *    to 1e-9 under delta1 != delta2 (the blend keeps the force isotropic
 *    in the degenerate eigenspace), and each cell's mass is conserved to
 *    1e-12 relative per step (s = 0), explicit and linearised implicit;
 * 4. the implicit term's Jacobian in 3D (the sparse part plus the rank-3
 *    low-rank part per cell): J y equals the central difference of the
 *    residual to 1e-6 of max |J y|, and the sparse part alone misses it;
 * 5. the stepper (tests/scenes/shape_3d.yaml): energy.csv's shape column is
 *    sum_i delta_i (I^i(0) - I^i(t))^2 of cells.csv's three moments, and
 *    the cell's mass is conserved to 1e-12 relative per step. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "model/division.h"
#include "scene/scene.h"
#include "shape_fixtures.h"
#include "run/stepper.h"

/** The moment I^(i+1) of observables @p o. */
static double moment(const sp_cell_obs *o, int i) {
  return i == 0 ? o->moments[0] : i == 1 ? o->moments[1] : o->moments[2];
}

/** The unit eigenvector of I^(i+1). */
static const double *axis(const sp_cell_obs *o, int i) {
  return i == 0 ? o->axes[0] : i == 1 ? o->axes[1] : o->axes[2];
}

/** A box of n^3 hexahedra on [0, L]^3 with one cell (full layout). */
static void box_one_cell(int n, double L, sp_mesh **mesh, sp_layout **layout) {
  CHECK_OK(sp_mesh_box(0, 0, 0, L, L, L, n, n, n, mesh));
  CHECK_OK(sp_layout_create_full((*mesh)->n_nodes, 1, layout));
}

/* 1. Ihat and the mu term against central differences. */
static void test_derivatives(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  box_one_cell(20, 0.5, &mesh, &layout);
  const size_t n_values = 2 * (size_t)layout->n_pairs;
  double *state = calloc(n_values, sizeof(double));
  const double centre[3] = {0.251, 0.247, 0.253}, semi[3] = {0.16, 0.12, 0.09};
  double axes[3][3];
  rotated_axes(0.3, 0.7, -0.4, axes);
  set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, 0.1);
  /* a background: with threshold 0, c < 0 does not count */
  for (int p = 0; p < layout->n_pairs; ++p) state[2 * p] += 0.02;
  sp_cell_obs obs;
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, &obs));
  printf("derivatives on a rotated ellipsoid (20^3 hexahedra, threshold 0): I = %.4e, %.4e, "
         "%.4e\n", obs.moments[0], obs.moments[1], obs.moments[2]);
  sp_solver solver = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  double *without = malloc(n_values * sizeof(double)), *with = malloc(n_values * sizeof(double));
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = state};
  CHECK(sp_solver_residual(solver, &data, state, without) == 0, "%s",
        sp_solver_last_error(solver));
  const double step = 1e-4;
  const int stride = 37;
  /* (a) unit coefficient on moment i: the term -coef_i Ihat_i in mu_k
   * enters R_mu = int N (mu - ...) as +int N_j Ihat_i */
  for (int i = 0; i < 3; ++i) {
    sp_shape_coef unit = {.xc = obs.centre[0], .yc = obs.centre[1], .zc = obs.centre[2]};
    for (int m = 0; m < 3; ++m)
      for (int d = 0; d < 3; ++d) unit.v[m][d] = axis(&obs, m)[d];
    unit.coef[i] = 1.0;
    data.shape = &unit;
    CHECK(sp_solver_residual(solver, &data, state, with) == 0, "%s",
          sp_solver_last_error(solver));
    double worst = 0, scale = 0;
    for (int j = 0; j < mesh->n_nodes; j += stride) {
      const int p = sp_layout_pair(layout, 0, j);
      sp_cell_obs plus, minus;
      observe_plus_minus(mesh, layout, state, p, step, &plus, &minus);
      const double fd = (moment(&plus, i) - moment(&minus, i)) / (2 * step);
      const double glue = with[2 * p + 1] - without[2 * p + 1];
      worst = fmax(worst, fabs(fd - glue));
      scale = fmax(scale, fabs(fd));
    }
    printf("  dI%d/dc_j: max |central difference - int N_j Ihat%d| / max = %.2e\n", i + 1, i + 1,
           worst / scale);
    CHECK(scale > 0 && worst <= 1e-6 * scale, "dI%d/dc: relative error %.3g", i + 1,
          worst / scale);
  }
  /* (b) the coefficients of three moduli: the mu term is -dE/dc */
  const double delta[3] = {3e4, 7e4, 5e4};
  sp_cell_birth birth = {.birth_mass = obs.mass,
                         .Iref = {0.9 * obs.moments[0], 1.2 * obs.moments[1], 0.8 * obs.moments[2]}};
  const double trace = obs.moments[0] + obs.moments[1] + obs.moments[2];
  printf("  relative gaps (I1 - I2, I2 - I3) / tr I = %.3f, %.3f (blend below %g)\n",
         (obs.moments[0] - obs.moments[1]) / trace, (obs.moments[1] - obs.moments[2]) / trace, SP_SHAPE_ROUND_TOL);
  sp_shape_coef coef;
  CHECK_OK(sp_shape_coefficients(3, 1, &obs, &birth, delta, &coef));
  data.shape = &coef;
  CHECK(sp_solver_residual(solver, &data, state, with) == 0, "%s", sp_solver_last_error(solver));
  double worst = 0, scale = 0, worst_c = 0;
  for (int j = 0; j < mesh->n_nodes; j += stride) {
    const int p = sp_layout_pair(layout, 0, j);
    sp_cell_obs plus, minus;
    observe_plus_minus(mesh, layout, state, p, step, &plus, &minus);
    const double dE = (sp_shape_energy(1, &plus, &birth, delta) -
                       sp_shape_energy(1, &minus, &birth, delta)) / (2 * step);
    worst = fmax(worst, fabs(with[2 * p + 1] - without[2 * p + 1] + dE));
    scale = fmax(scale, fabs(dE));
    worst_c = fmax(worst_c, fabs(with[2 * p] - without[2 * p]));
  }
  printf("  glue: max |(R_mu with - without) + dE_shape/dc_j| / max |dE/dc_j| = %.2e; c rows "
         "changed by %.1e\n", worst / scale, worst_c);
  CHECK(scale > 0 && worst <= 1e-6 * scale, "mu term vs -dE/dc: relative %.3g", worst / scale);
  CHECK(worst_c == 0.0, "the shape term changed a c row by %.3g", worst_c);
  free(without);
  free(with);
  free(state);
  sp_solver_destroy(&solver);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/** Observables with moments I[3] and eigenvectors the rows of @p axes. */
static sp_cell_obs make_obs(const double I[3], const double axes[3][3]) {
  sp_cell_obs o = {.mass = 1, .mass_core = 1, .centre = {0.3, 0.2, 0.1},
                   .moments = {I[0], I[1], I[2]}, .long_axis = 2};
  for (int d = 0; d < 3; ++d) {
    o.axes[0][d] = axes[0][d];
    o.axes[1][d] = axes[1][d];
    o.axes[2][d] = axes[2][d];
  }
  return o;
}

/** The force tensor sum_i coef_i v_i v_i^T. */
static void force_tensor(const sp_shape_coef *s, double t[3][3]) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      t[a][b] = 0;
      for (int i = 0; i < 3; ++i) t[a][b] += s->coef[i] * s->v[i][a] * s->v[i][b];
    }
}

static double tensor_distance(const sp_shape_coef *a, const sp_shape_coef *b) {
  double ta[3][3], tb[3][3], d = 0;
  force_tensor(a, ta);
  force_tensor(b, tb);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d = fmax(d, fabs(ta[i][j] - tb[i][j]));
  return d;
}

/* 2. Degenerate moments. */
static void test_round(void) {
  const double delta[3] = {1e5, 4e5, 2e5}, I0 = 1e-4;
  const sp_cell_birth birth = {.birth_mass = 1, .Iref = {0.9 * I0, 1.1 * I0, 1.3 * I0}};
  double frame_a[3][3], frame_b[3][3];
  rotated_axes(0.2, 0.5, 0.1, frame_a);
  const struct {
    const char *name;
    double I[3];
    int equal_from, equal_to; /* the equal moments i in [from, to] */
  } cases[] = {{"sphere (I1 = I2 = I3)", {I0, I0, I0}, 0, 2},
               {"prolate (I1 = I2 > I3)", {I0, I0, 0.7 * I0}, 0, 1},
               {"oblate (I1 > I2 = I3)", {1.3 * I0, I0, I0}, 1, 2}};
  printf("degenerate moments, delta = (%g, %g, %g):\n", delta[0], delta[1], delta[2]);
  for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
    const double *I = cases[k].I;
    double c[3], spread = 0;
    for (int i = 0; i < 3; ++i) c[i] = 2 * delta[i] * (birth.Iref[i] - I[i]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) spread = fmax(spread, fabs(c[i] - c[j]));
    const int lo = cases[k].equal_from, hi = cases[k].equal_to;
    double mean = 0;
    for (int i = lo; i <= hi; ++i) mean += c[i] / (hi - lo + 1);
    sp_cell_obs o = make_obs(I, frame_a);
    sp_shape_coef s;
    CHECK_OK(sp_shape_coefficients(3, 1, &o, &birth, delta, &s));
    printf("  %-24s exact c = (%.4g, %.4g, %.4g), coef = (%.4g, %.4g, %.4g)\n", cases[k].name,
           c[0], c[1], c[2], s.coef[0], s.coef[1], s.coef[2]);
    for (int i = 0; i < 3; ++i) {
      const double want = i >= lo && i <= hi ? mean : c[i];
      CHECK_NEAR(s.coef[i], want, 1e-12 * spread);
      CHECK(isfinite(s.coef[i]), "%s: coef %d not finite", cases[k].name, i);
    }
    /* the equal moments' gain rows are equal too (the same blend) */
    for (int j = 0; j < 3; ++j) CHECK_NEAR(s.gain[lo][j], s.gain[hi][j], 1e-12 * 2 * delta[j]);
    /* split by 1e-7 and turn the frame within the degenerate eigenspace */
    const double tiny = 1e-7;
    double Ia[3] = {I[0], I[1], I[2]}, Ib[3];
    Ia[lo] *= 1 + tiny;
    Ia[hi] *= 1 - tiny;
    for (int i = 0; i < 3; ++i) Ib[i] = Ia[i];
    if (hi - lo == 2) rotated_axes(1.1, -0.8, 2.3, frame_b); /* any frame */
    else {
      /* rotate rows lo and hi of frame_a about the third by 1 rad */
      const double cs = cos(1.0), sn = sin(1.0);
      for (int d = 0; d < 3; ++d) {
        frame_b[lo][d] = cs * frame_a[lo][d] + sn * frame_a[hi][d];
        frame_b[hi][d] = -sn * frame_a[lo][d] + cs * frame_a[hi][d];
        frame_b[3 - lo - hi][d] = frame_a[3 - lo - hi][d];
      }
    }
    sp_cell_obs oa = make_obs(Ia, frame_a), ob = make_obs(Ib, frame_b);
    sp_shape_coef sa, sb;
    CHECK_OK(sp_shape_coefficients(3, 1, &oa, &birth, delta, &sa));
    CHECK_OK(sp_shape_coefficients(3, 1, &ob, &birth, delta, &sb));
    /* the exact eigenvector form: the coefficients c, unblended */
    sp_shape_coef ea = sa, eb = sb;
    for (int i = 0; i < 3; ++i) {
      ea.coef[i] = 2 * delta[i] * (birth.Iref[i] - Ia[i]);
      eb.coef[i] = 2 * delta[i] * (birth.Iref[i] - Ib[i]);
    }
    const double jump = tensor_distance(&sa, &sb), exact_jump = tensor_distance(&ea, &eb);
    printf("    split 1e-7, frame turned: force tensor moves by %.2e (exact form: %.2e)\n", jump,
           exact_jump);
    CHECK(jump <= 1e-4 * spread, "%s: the force jumps by %.3g", cases[k].name, jump);
    CHECK(exact_jump >= 1e-2 * spread, "%s: the exact form does not jump (%.3g): the case "
          "tests nothing", cases[k].name, exact_jump);
  }

  /* random near-degenerate moments: bounded, continuous, exact when apart */
  unsigned long long rng = 11;
  double worst_bound = 0, worst_cont = 0, worst_exact = 0;
  int n_exact = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    double I[3];
    I[2] = I0 * (0.5 + 0.5 * (sp_random_symmetric(&rng) + 1));
    I[1] = I[2] * (1 + 0.03 * (sp_random_symmetric(&rng) + 1) * (trial % 3 == 0 ? 0.01 : 1));
    I[0] = I[1] * (1 + 0.03 * (sp_random_symmetric(&rng) + 1) * (trial % 4 == 0 ? 0.01 : 1));
    double frame[3][3];
    rotated_axes(3 * sp_random_symmetric(&rng), 3 * sp_random_symmetric(&rng),
                 3 * sp_random_symmetric(&rng), frame);
    sp_cell_obs o = make_obs(I, frame);
    sp_shape_coef s, s2;
    CHECK_OK(sp_shape_coefficients(3, 1, &o, &birth, delta, &s));
    double c[3], bound = 0, spread = 0;
    for (int i = 0; i < 3; ++i) {
      c[i] = 2 * delta[i] * (birth.Iref[i] - I[i]);
      bound = fmax(bound, fabs(c[i]));
    }
    for (int i = 0; i < 3; ++i) {
      worst_bound = fmax(worst_bound, fabs(s.coef[i]) / bound);
      for (int j = 0; j < 3; ++j) spread = fmax(spread, fabs(c[i] - c[j]));
    }
    const double tr = I[0] + I[1] + I[2];
    if ((I[0] - I[1]) / tr >= SP_SHAPE_ROUND_TOL && (I[1] - I[2]) / tr >= SP_SHAPE_ROUND_TOL) {
      ++n_exact;
      for (int i = 0; i < 3; ++i) worst_exact = fmax(worst_exact, fabs(s.coef[i] - c[i]) / bound);
    }
    /* continuity: move the middle moment by 1e-9 of the trace */
    sp_cell_obs o2 = o;
    o2.moments[1] += 1e-9 * tr;
    if (o2.moments[1] > o2.moments[0]) o2.moments[1] = o2.moments[0];
    CHECK_OK(sp_shape_coefficients(3, 1, &o2, &birth, delta, &s2));
    worst_cont = fmax(worst_cont, tensor_distance(&s, &s2) / spread);
  }
  printf("  2000 random near-degenerate moments: max |coef| / max |c| = %.15f; force tensor "
         "change under a 1e-9 tr I move / spread = %.2e; %d with every gap >= %g: max |coef - c| "
         "/ max |c| = %.1e\n", worst_bound, worst_cont, n_exact, SP_SHAPE_ROUND_TOL, worst_exact);
  CHECK(worst_bound <= 1 + 1e-14, "a coefficient exceeds max |c|: %.17g", worst_bound);
  CHECK(worst_cont <= 1e-5, "the force moved by %.3g of the spread", worst_cont);
  CHECK(n_exact > 100 && worst_exact <= 1e-15, "exact coefficients: %d, off by %.3g", n_exact,
        worst_exact);

  /* no mass, NaN moments, NaN birth moment: zero coefficients, no NaN */
  const double zero[3] = {0, 0, 0}, nan_I[3] = {NAN, 1e-4, 1e-4}, neg[3] = {1e-4, -1e-4, -2e-4};
  sp_cell_obs bad[4] = {make_obs(zero, frame_a), make_obs(nan_I, frame_a), make_obs(neg, frame_a),
                        make_obs(cases[1].I, frame_a)};
  sp_cell_birth births[4] = {birth, birth, birth, birth};
  births[3].Iref[2] = NAN; /* a 3D checkpoint written before the 3D term */
  sp_shape_coef out[4];
  CHECK_OK(sp_shape_coefficients(3, 4, bad, births, delta, out));
  for (int k = 0; k < 4; ++k)
    CHECK(out[k].coef[0] == 0 && out[k].coef[1] == 0 && out[k].coef[2] == 0 &&
              isfinite(out[k].xc) && isfinite(out[k].zc) && isfinite(out[k].v[2][2]),
          "degenerate case %d: coef (%g, %g, %g)", k, out[k].coef[0], out[k].coef[1],
          out[k].coef[2]);
  /* bad moduli */
  sp_cell_obs round = make_obs(cases[0].I, frame_a);
  sp_shape_coef s;
  CHECK(sp_shape_coefficients(3, 1, &round, &birth, (double[3]){1, 1, -1}, &s) == SP_ERR_INPUT,
        "negative delta3 accepted");
  sp_error_clear();
  CHECK(sp_shape_coefficients(2, 1, &round, &birth, (double[3]){1, 1, 1}, &s) == SP_ERR_INPUT,
        "delta3 accepted in 2D");
  printf("  delta3 in 2D: %s\n", sp_error_message());
  sp_error_clear();
  /* the energy of three moduli */
  const double I[3] = {1.2e-4, 1e-4, 0.8e-4};
  sp_cell_obs o = make_obs(I, frame_a);
  double want = 0;
  for (int i = 0; i < 3; ++i) want += delta[i] * (birth.Iref[i] - I[i]) * (birth.Iref[i] - I[i]);
  CHECK_NEAR(sp_shape_energy(1, &o, &birth, delta), want, 1e-14 * want);
}

/** A prolate spheroid (semi-axes 0.13, 0.1, 0.1 along x, so I^1 = I^2) on
 *  a box of 16^3 hexahedra of [0, 0.4]^3, kappa = 4e-3, no source: first
 *  @p relax steps without the term (the tanh profile settles on the
 *  mesh), then I^ref = the moments there with I^3,ref = 0.85 I^3, and
 *  @p steps steps with delta3 on I^3. */
typedef struct {
  double i3_start, i3_ref, i3_end, mass_drift, i1_end, i2_end;
  int finite;
} prolate_result;

static prolate_result prolate_steps(double delta3, int implicit, int relax, int steps) {
  prolate_result r = {.finite = 1};
  sp_mesh *mesh;
  sp_layout *layout;
  box_one_cell(16, 0.4, &mesh, &layout);
  const size_t n = 2 * (size_t)layout->n_pairs;
  double *state = calloc(n, sizeof(double)), *old = malloc(n * sizeof(double));
  sp_model_params model = paper_model();
  model.kappa = 4e-3;
  const double d = sqrt(model.kappa / (2 * model.alpha));
  const double centre[3] = {0.2, 0.2, 0.2}, semi[3] = {0.13, 0.1, 0.1};
  const double axes[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, d / 0.1);
  const double threshold = 0.05;
  sp_cell_obs obs;
  CHECK_OK(sp_cells_observe(mesh, layout, state, threshold, &obs));
  sp_cell_birth birth = {.birth_mass = obs.mass_core};
  sp_solver solver = make_solver_with(mesh, layout, SP_SOLVER_JAC_AD, SP_LINEAR_MUMPS);
  /* delta1 != delta2 on the equal pair: their coefficients differ, and
   * only the blend keeps the force isotropic in their eigenspace */
  const double delta[3] = {2e5, 6e5, delta3};
  for (int step = 0; step < relax + steps; ++step) {
    if (step == relax) {
      birth.Iref[0] = obs.moments[0];
      birth.Iref[1] = obs.moments[1];
      birth.Iref[2] = 0.85 * obs.moments[2];
      r.i3_start = obs.moments[2];
      r.i3_ref = birth.Iref[2];
    }
    const int on = step >= relax && delta3 > 0;
    sp_shape_coef sc;
    CHECK_OK(sp_shape_coefficients(3, 1, &obs, &birth, delta, &sc));
    sc.threshold = threshold;
    memcpy(old, state, n * sizeof(double));
    sp_step_data data = {.dt = 2e-4, .model = model, .state_old = old,
                         .shape = on ? &sc : NULL, .shape_implicit = implicit};
    sp_step_report rep;
    CHECK(sp_solver_step(solver, &data, state, &rep) == 0, "step %d: %s", step, rep.reason);
    const double mass_before = obs.mass;
    CHECK_OK(sp_cells_observe(mesh, layout, state, threshold, &obs));
    r.mass_drift = fmax(r.mass_drift, fabs(obs.mass - mass_before) / fabs(mass_before));
    r.finite &= isfinite(obs.moments[0]) && isfinite(obs.moments[1]) && isfinite(obs.moments[2]);
  }
  r.i3_end = obs.moments[2];
  r.i1_end = obs.moments[0];
  r.i2_end = obs.moments[1];
  sp_solver_destroy(&solver);
  free(state);
  free(old);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  return r;
}

/* 3. The dynamics in 3D. */
static void test_prolate(void) {
  /* delta3: 1e6 explicit; the implicit scheme (for stiffer moduli) pulls
   * less per step at the same modulus and gets 2e6 */
  const int relax = 10, steps = 10;
  const prolate_result free_run = prolate_steps(0.0, 0, relax, steps);
  printf("prolate spheroid 0.13 x 0.1 x 0.1, %d steps of dt = 2e-4 to settle, then %d with "
         "I3,ref = 0.85 I3:\n", relax, steps);
  printf("  delta3 = 0:   I3 %.6e -> %.6e (gap %.3e -> %.3e), mass drift %.1e\n",
         free_run.i3_start, free_run.i3_end, fabs(free_run.i3_ref - free_run.i3_start),
         fabs(free_run.i3_ref - free_run.i3_end), free_run.mass_drift);
  for (int implicit = 0; implicit < 2; ++implicit) {
    const double delta3 = implicit ? 2e6 : 1e6;
    const prolate_result r = prolate_steps(delta3, implicit, relax, steps);
    const double gap0 = fabs(r.i3_ref - r.i3_start), gap1 = fabs(r.i3_ref - r.i3_end);
    printf("  delta3 = %g (%s): I3 %.6e -> %.6e (gap %.3e -> %.3e), I1/I2 - 1 = %.1e, mass "
           "drift %.1e\n", delta3, implicit ? "implicit" : "explicit", r.i3_start, r.i3_end,
           gap0, gap1, r.i1_end / r.i2_end - 1, r.mass_drift);
    CHECK(r.finite, "non-finite moments");
    CHECK(fabs(r.i1_end / r.i2_end - 1) <= 1e-9, "the prolate cell lost its symmetry: I1/I2 - 1 "
          "= %.3g", r.i1_end / r.i2_end - 1);
    CHECK(gap1 < gap0, "%s: the gap grew: %.6g -> %.6g", implicit ? "implicit" : "explicit",
          gap0, gap1);
    CHECK(r.i3_end < free_run.i3_end, "I3 %.6g with the term, %.6g without", r.i3_end,
          free_run.i3_end);
    CHECK(r.mass_drift <= 1e-12, "mass changed by %.3g relative in a step", r.mass_drift);
  }
  CHECK(free_run.mass_drift <= 1e-12, "mass changed by %.3g without the term",
        free_run.mass_drift);
}

/* 4. The implicit term's Jacobian in 3D against central differences. */
static void test_implicit_jacobian(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.4, 0.4, 10, 8, 8, &mesh));
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  const size_t n = 2 * (size_t)layout->n_pairs;
  double *old = calloc(n, sizeof(double)), *state = malloc(n * sizeof(double));
  double axes[3][3];
  rotated_axes(0.4, 0.9, -0.3, axes);
  set_ellipsoid(mesh, layout, old, 0, (double[3]){0.18, 0.2, 0.21}, axes,
                (double[3]){0.14, 0.1, 0.08}, 0.12);
  rotated_axes(-0.7, 0.3, 1.2, axes);
  set_ellipsoid(mesh, layout, old, 1, (double[3]){0.33, 0.19, 0.2}, axes,
                (double[3]){0.12, 0.09, 0.1}, 0.12);
  for (int p = 0; p < layout->n_pairs; ++p) old[2 * p] += 0.02;
  for (size_t i = 0; i < n; ++i)
    state[i] = old[i] + (i % 2 == 0 ? 0.01 * sin(0.37 * (double)i) : 0.0);
  sp_cell_obs obs[2];
  sp_cell_birth birth[2];
  CHECK_OK(sp_cells_observe(mesh, layout, old, 0.05, obs));
  for (int k = 0; k < 2; ++k)
    birth[k] = (sp_cell_birth){.birth_mass = obs[k].mass,
                               .Iref = {0.8 * obs[k].moments[0], 1.1 * obs[k].moments[1], 0.9 * obs[k].moments[2]}};
  sp_shape_coef coef[2];
  CHECK_OK(sp_shape_coefficients(3, 2, obs, birth, (double[3]){2e5, 5e5, 3e5}, coef));
  for (int k = 0; k < 2; ++k) coef[k].threshold = 0.05;
  sp_solver solver = make_solver(mesh, layout, SP_SOLVER_JAC_AD);
  sp_step_data d = {.dt = 1e-4, .model = paper_model(), .state_old = old, .shape = coef,
                    .shape_implicit = 1};
  double err, err_sparse;
  implicit_jacobian_vs_fd(solver, &d, state, n, 7, &err, &err_sparse);
  printf("implicit shape term in 3D (two ellipsoids, rank 3 per cell): max |J y - FD| / max |J y| "
         "= %.2e (sparse part alone: %.2e)\n", err, err_sparse);
  CHECK(err <= 1e-6, "J y differs from the residual's derivative by %.3g", err);
  CHECK(err_sparse >= 1e-3, "the sparse part alone is within %.3g", err_sparse);
  free(old);
  free(state);
  sp_solver_destroy(&solver);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/** The CSV row of @p step (and cell @p cell, -1: any) of @p path: its
 *  numbers into @p v (at most @p n); the count read, 0 if none. */
static int csv_row(const char *path, int step, int cell, double *v, int n) {
  FILE *f = fopen(path, "r");
  char line[4096];
  int got = 0;
  if (!f) return 0;
  if (!fgets(line, sizeof line, f)) { fclose(f); return 0; }
  while (!got && fgets(line, sizeof line, f)) {
    if (atoi(line) != step) continue;
    int m = 0;
    for (char *p = line; p && m < n; p = strchr(p, ','), p = p ? p + 1 : NULL) v[m++] = atof(p);
    if (cell < 0 || (m > 2 && (int)v[2] == cell)) got = m;
  }
  fclose(f);
  return got;
}

/* 5. The stepper on tests/scenes/shape_3d.yaml. */
static void test_stepper(void) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/shape_3d.yaml", 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, "test_shape_3d_out", MPI_COMM_WORLD, &sum));
  const double delta[3] = {scene->shape.delta1, scene->shape.delta2, scene->shape.delta3};
  printf("stepper: %d steps of tests/scenes/shape_3d.yaml, delta = (%g, %g, %g)\n", sum.steps,
         delta[0], delta[1], delta[2]);
  /* cells.csv: step,t,cell,mass,xc,yc,zc,I1,I2,I3,...; energy.csv: shape at 10 */
  double row0[16], row[16], erow[16], prev_mass = NAN;
  CHECK(csv_row("test_shape_3d_out/cells.csv", 0, 1, row0, 16) >= 10, "no cells.csv row 0");
  double worst = 0, largest = 0, drift = 0;
  for (int step = 0; step <= sum.steps; ++step) {
    CHECK(csv_row("test_shape_3d_out/cells.csv", step, 1, row, 16) >= 10, "cells.csv step %d",
          step);
    CHECK(csv_row("test_shape_3d_out/energy.csv", step, -1, erow, 16) >= 11,
          "energy.csv step %d", step);
    double expected = 0;
    for (int i = 0; i < 3; ++i)
      if (delta[i] > 0) {
        const double gap = row0[7 + i] - row[7 + i];
        expected += delta[i] * gap * gap;
      }
    if (step > 0) worst = fmax(worst, fabs(erow[10] - expected) / fmax(expected, 1e-300));
    largest = fmax(largest, erow[10]);
    if (step > 0) drift = fmax(drift, fabs(row[3] - prev_mass) / fabs(prev_mass));
    prev_mass = row[3];
  }
  printf("  shape column vs sum_i delta_i (I_i(0) - I_i)^2 of cells.csv: largest relative "
         "difference %.1e (largest shape energy %.3g); mass drift per step %.1e\n",
         worst, largest, drift);
  CHECK(sum.steps >= 5, "only %d steps", sum.steps);
  CHECK(largest > 0, "the shape column stayed 0");
  CHECK(worst <= 1e-9, "shape column off by %.3g relative", worst);
  CHECK(drift <= 1e-12, "mass changed by %.3g relative in a step", drift);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  test_derivatives();
  test_round();
  test_implicit_jacobian();
  test_prolate();
  test_stepper();
  MPI_Finalize();
  TEST_DONE();
}
