/* Cell division building blocks (src/model/division.c): the axis of elliptical
 * cells at several orientations, the split's exact mass conservation and
 * equal halves (sharp and smoothed), the crossing-safe criteria, the paper's
 * dt sequence after a division (algorithm 2) and N_max. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "model/division.h"
#include "division_fixtures.h"
#include "public/error.h"
#include "fixtures.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"

#define PI 3.14159265358979323846

/** Centre and inertia integrate c >= this, as the stepper does. */
#define WEIGHT_THRESHOLD 0.05

/** The equilibrium interface width d = sqrt(kappa / (2 alpha)) of the
 *  paper's parameters (kappa = 1e-3, alpha = 4). */
static double interface_width(void) { return sqrt(1e-3 / 8.0); }

/** c_k = a tanh ellipse with semi-axes (a, b), the a axis at angle phi,
 *  centred at (x, y), on a background b_c (no noise); mu_k = 0.1 (so the
 *  split of mu is visible). The profile is symmetric under both reflections
 *  of the ellipse, so its principal axes are exactly the ellipse's. */
static void set_ellipse_bg(const sp_mesh *mesh, const sp_layout *layout, double *state, int k,
                           double x, double y, double a, double b, double phi,
                           double background) {
  /* eps = d / b in rho units: (rho - 1) b is the distance to the boundary
   * near the minor axis (fixtures.h) */
  set_ellipse(mesh, layout, state, k, x, y, a, b, phi, interface_width() / b);
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, k, i);
    if (p < 0) continue;
    state[2 * p] += (1.0 - state[2 * p]) * background;
    state[2 * p + 1] = 0.1;
  }
}

/** Angle between two lines (undirected), in [0, pi/2]. */
static double line_angle(double ax, double ay, double bx, double by) {
  const double cross = fabs(ax * by - ay * bx), dot = fabs(ax * bx + ay * by);
  return atan2(cross, dot);
}

/* The axis runs perpendicular to the long axis of an ellipse, through its
 * centre, at every orientation. */
static void test_axis_of_ellipses(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 160, 160, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  const double orientations[] = {0.0, 0.3, PI / 4, 1.2, PI / 2};
  /* off the mesh nodes, so no orientation is helped by mesh symmetry */
  const double xc = 0.5031, yc = 0.4957;
  printf("division axis of a 0.12 x 0.06 tanh ellipse, 160x160 mesh on [0,1]^2:\n");
  printf("  long axis (rad) | axis angle (rad) | expected (rad) | error (rad) | "
         "centre error | I1/I2\n");
  double worst = 0;
  for (size_t j = 0; j < sizeof orientations / sizeof *orientations; ++j) {
    const double phi = orientations[j];
    set_ellipse_bg(mesh, layout, state, 0, xc, yc, 0.12, 0.06, phi, 0.0);
    sp_cell_obs obs;
    CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &obs));
    double point[3], normal[3];
    sp_division_plane(&obs, 2, point, normal);
    /* the cut's line: the normal turned by -90 degrees */
    const double px = point[0], py = point[1], dx = normal[1], dy = -normal[0];
    /* expected: perpendicular to the long axis (cos phi, sin phi) */
    const double ex = -sin(phi), ey = cos(phi);
    const double error = line_angle(dx, dy, ex, ey);
    const double centre_error = hypot(px - xc, py - yc);
    double expected = atan2(ey, ex);
    if (expected > PI / 2) expected -= PI;
    printf("  %15.4f | %16.6f | %14.6f | %11.2e | %12.2e | %.4f\n", phi,
           atan2(dy, dx), expected, error, centre_error, obs.moments[0] / obs.moments[1]);
    if (error > worst) worst = error;
    CHECK(error < 1e-3, "orientation %g: axis off by %.3g rad", phi, error);
    /* the c >= 0.05 cut of the weight is not resolved by the quadrature */
    CHECK(centre_error < 5e-5, "orientation %g: centre off by %.3g", phi, centre_error);
    CHECK_NEAR(hypot(dx, dy), 1.0, 1e-14);
    CHECK(obs.moments[0] > 2.0 * obs.moments[1], "orientation %g: I1/I2 = %g, an ellipse 2:1 has ~4",
          phi, obs.moments[0] / obs.moments[1]);
  }
  printf("  largest axis error: %.3g rad\n", worst);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/** Nodal mass weights w_i = int N_i dV (2x2 Gauss, as the observables). */
static double *nodal_weights(const sp_mesh *mesh) {
  double *w = calloc((size_t)mesh->n_nodes, sizeof(double));
  for (int e = 0; e < mesh->n_elems; ++e) {
    double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xy);
    for (int q = 0; q < sp_q1_qpoints(2); ++q) {
      double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], weight;
      sp_q1_point(2, xy, q, N, dNdx, x, &weight);
      for (int a = 0; a < 4; ++a) w[mesh->elem[4 * e + a]] += weight * N[a];
    }
  }
  return w;
}

/** Signed distance of node i from the axis of obs, with n = v2 (the side
 *  the child takes is sd > 0). */
static double signed_distance(const sp_mesh *mesh, const sp_cell_obs *obs, int i) {
  const double *n = obs->axes[obs->long_axis]; /* the cut's normal */
  return n[0] * (mesh->xy[2 * i] - obs->centre[0]) + n[1] * (mesh->xy[2 * i + 1] - obs->centre[1]);
}

/** Split cell 0 (an ellipse at (x, y), long axis at phi, on a background)
 *  of a two-cell state (cell 1 a bystander disk) on full layouts and check
 *  what every split must do. Returns the daughters' relative mass
 *  difference |m_p - m_c| / ((m_p + m_c) / 2). */
static double check_split(const sp_mesh *mesh, const double *w, double x, double y, double phi,
                          double background, int smooth, const char *label) {
  sp_layout *layout, *new_layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 3, &new_layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *new_state = calloc(2 * (size_t)new_layout->n_pairs, sizeof(double));
  set_ellipse_bg(mesh, layout, state, 0, x, y, 0.12, 0.06, phi, background);
  set_ellipse_bg(mesh, layout, state, 1, 0.2, 0.8, 0.08, 0.08, 0.0, background);
  sp_cell_obs before[2], after[3];
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, before));
  const double width = interface_width();
  CHECK_OK(sp_division_split(mesh, layout, state, 0, &before[0], smooth, width, 0.0, new_layout,
                             new_state, 2));
  CHECK_OK(sp_cells_observe(mesh, new_layout, new_state, WEIGHT_THRESHOLD, after));

  /* the parent's mass is conserved to round-off */
  const double m_before = cell_mass(layout, state, w, 0);
  const double m_parent = cell_mass(new_layout, new_state, w, 0);
  const double m_child = cell_mass(new_layout, new_state, w, 2);
  const double conservation = fabs(m_parent + m_child - m_before) / m_before;
  CHECK(conservation <= 1e-13, "%s: parent + child mass %.17g, parent before %.17g "
        "(relative %.3g)", label, m_parent + m_child, m_before, conservation);
  /* the same through the observables, whose double sums carry ~1e-13 */
  const double observed = fabs(after[0].mass + after[2].mass - before[0].mass) / before[0].mass;
  CHECK(observed <= 1e-12, "%s: observed masses: relative change %.3g", label, observed);
  /* the bystander is untouched */
  CHECK(after[1].mass == before[1].mass, "%s: bystander mass %.17g -> %.17g", label,
        before[1].mass, after[1].mass);

  /* nodewise: the daughters add up to the parent; sides and mu as documented */
  double worst_sum = 0;
  int wrong_side = 0, bystander_changed = 0;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int q0 = sp_layout_pair(layout, 0, i), q1 = sp_layout_pair(layout, 1, i);
    const int p0 = sp_layout_pair(new_layout, 0, i), p1 = sp_layout_pair(new_layout, 1, i);
    const int p2 = sp_layout_pair(new_layout, 2, i);
    const double c = state[2 * q0], c_parent = new_state[2 * p0], c_child = new_state[2 * p2];
    const double sum_error = fabs(c_parent + c_child - c);
    if (sum_error > worst_sum) worst_sum = sum_error;
    if (fabs(new_state[2 * p0 + 1] + new_state[2 * p2 + 1] - state[2 * q0 + 1]) > 1e-15)
      ++wrong_side;
    if (new_state[2 * p1] != state[2 * q1] || new_state[2 * p1 + 1] != state[2 * q1 + 1])
      ++bystander_changed;
    if (!smooth) {
      const double sd = signed_distance(mesh, &before[0], i);
      if (sd > 1e-6 && (c_child != c || c_parent != 0.0)) ++wrong_side;
      if (sd < -1e-6 && (c_parent != c || c_child != 0.0)) ++wrong_side;
    }
  }
  CHECK(worst_sum <= 1e-15, "%s: |c_parent + c_child - c| up to %.3g", label, worst_sum);
  CHECK(wrong_side == 0, "%s: %d nodes split against the documented side rule", label,
        wrong_side);
  CHECK(bystander_changed == 0, "%s: %d bystander values changed", label, bystander_changed);

  /* the child's centre lies on the side the normal n (the long axis) points to */
  const double *n = before[0].axes[before[0].long_axis];
  const double side = n[0] * (after[2].centre[0] - before[0].centre[0]) +
                      n[1] * (after[2].centre[1] - before[0].centre[1]);
  CHECK(side > 0, "%s: child centre on the wrong side (n . (Xc_child - Xc) = %g)", label, side);
  const double unequal = fabs(m_parent - m_child) / (0.5 * (m_parent + m_child));
  printf("  %-40s | %9.1e | %9.1e | %.6f %.6f | %.2e\n", label, conservation, observed,
         m_parent, m_child, unequal);
  free(state);
  free(new_state);
  sp_layout_destroy(&layout);
  sp_layout_destroy(&new_layout);
  return unequal;
}

/* Sharp and smoothed splits conserve the parent's mass exactly and halve a
 * symmetric cell. */
static void test_split_conserves_and_halves(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 160, 160, &mesh));
  double *w = nodal_weights(mesh);
  const double h = 1.0 / 160;
  printf("splits of a 0.12 x 0.06 ellipse beside a bystander cell, 160x160 mesh:\n"
         "  %-40s | mass cons | observed  | daughters         | differ\n", "case");
  /* with the background 0.02 of the paper's runs: the domain is not
   * symmetric about the line, so the halves differ by the background's
   * share (up to ~0.6% here) */
  struct { double x, y, phi; const char *where; } cases[] = {
      {0.5031, 0.4957, 0.3, "rotated 0.3"},
      {0.5031, 0.4957, PI / 4, "rotated pi/4"},
      {0.5031, 0.4957, 1.2, "rotated 1.2"},
      {0.5, 0.5, 0.0, "line through mesh nodes"},
      {0.5 + 0.5 * h, 0.5, 0.0, "line between mesh nodes"}};
  const int n_cases = (int)(sizeof cases / sizeof *cases);
  for (int background = 1; background >= 0; --background)
    for (int j = 0; j < n_cases; ++j)
      for (int smooth = 0; smooth <= 1; ++smooth) {
        char label[64];
        snprintf(label, sizeof label, "%s, %s%s", smooth ? "smooth" : "sharp", cases[j].where,
                 background ? ", bg 0.02" : "");
        const double unequal = check_split(mesh, w, cases[j].x, cases[j].y, cases[j].phi,
                                           background ? 0.02 : 0.0, smooth, label);
        if (background) continue;
        /* Without background the cell is symmetric about its line. The
         * smoothed cut integrates across the line and halves it to well
         * within 2%. The sharp nodal cut (the paper's) hands each node
         * wholly to one side, which moves the effective line by up to half
         * a node spacing: the halves then differ by up to
         * 2 (h/2) x chord 2b / (m/2) = 4 h b x 2 / m (O(h): 6% here, 2.6%
         * measured at pi/4). */
        const double m_cell = PI * 0.12 * 0.06;
        const double sharp_bound = 2.0 * (0.5 * h) * (2 * 0.06) / (0.5 * m_cell);
        CHECK(unequal < (smooth ? 2e-2 : sharp_bound), "%s: daughters differ by %.3g", label,
              unequal);
        /* Axis-aligned: symmetric on the mesh too; a line through nodes
         * shares them half and half, so the halves are equal. */
        if (cases[j].phi == 0.0)
          CHECK(unequal < 1e-8, "%s: symmetric daughters differ by %.3g", label, unequal);
      }
  free(w);
  sp_mesh_destroy(&mesh);
}

/* On layouts with restricted supports the split still conserves, and a child
 * support too small to hold its half is an error, not a silent loss. */
static void test_split_local_supports(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 80, 80, &mesh));
  const int n = mesh->n_nodes;
  unsigned char *mask = calloc(3 * (size_t)n, 1);
  /* cell 0 (parent) and the child: the box [0.3, 0.7]^2; cell 1 elsewhere */
  for (int i = 0; i < n; ++i) {
    const double x = mesh->xy[2 * i], y = mesh->xy[2 * i + 1];
    const int in_box = x >= 0.3 && x <= 0.7 && y >= 0.3 && y <= 0.7;
    mask[i] = (unsigned char)in_box;
    mask[n + i] = (unsigned char)(x <= 0.3 || y >= 0.6);
    mask[2 * n + i] = (unsigned char)in_box;
  }
  sp_layout *layout, *new_layout, *bad_layout;
  CHECK_OK(sp_layout_create_from_masks(n, 2, mask, &layout));
  CHECK_OK(sp_layout_create_from_masks(n, 3, mask, &new_layout));
  /* a child support of only the left half of the box: too small */
  for (int i = 0; i < n; ++i) mask[2 * n + i] &= (unsigned char)(mesh->xy[2 * i] <= 0.5);
  CHECK_OK(sp_layout_create_from_masks(n, 3, mask, &bad_layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *new_state = calloc(2 * (size_t)new_layout->n_pairs, sizeof(double));
  double *bad_state = calloc(2 * (size_t)bad_layout->n_pairs, sizeof(double));
  set_ellipse_bg(mesh, layout, state, 0, 0.51, 0.49, 0.12, 0.06, 1.0, 0.02);
  set_ellipse_bg(mesh, layout, state, 1, 0.15, 0.8, 0.08, 0.08, 0.0, 0.02);
  sp_cell_obs before[2], after[3];
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, before));
  for (int smooth = 0; smooth <= 1; ++smooth) {
    CHECK_OK(sp_division_split(mesh, layout, state, 0, &before[0], smooth, interface_width(), 0.0,
                               new_layout, new_state, 2));
    CHECK_OK(sp_cells_observe(mesh, new_layout, new_state, WEIGHT_THRESHOLD, after));
    const double rel = fabs(after[0].mass + after[2].mass - before[0].mass) / before[0].mass;
    CHECK(rel <= 1e-13, "local supports, smooth %d: relative mass change %.3g", smooth, rel);
    CHECK(after[1].mass == before[1].mass, "local supports: bystander mass changed");
    const int rc = sp_division_split(mesh, layout, state, 0, &before[0], smooth,
                                     interface_width(), 0.0, bad_layout, bad_state, 2);
    CHECK(rc == SP_ERR_INTERNAL, "child support too small, smooth %d: returned %d", smooth, rc);
    printf("  local supports, %s: mass conservation %.1e; too small a child support: "
           "\"%s\"\n", smooth ? "smooth" : "sharp", rel, sp_error_message());
    sp_error_clear();
  }
  /* a wrong child index or cell count is refused */
  CHECK(sp_division_split(mesh, layout, state, 0, &before[0], 0, 0.0, 0.0, new_layout, new_state,
                          1) == SP_ERR_INTERNAL, "child index 1 accepted");
  CHECK(sp_division_split(mesh, layout, state, 0, &before[0], 1, 0.0, 0.0, new_layout, new_state,
                          2) == SP_ERR_INTERNAL, "smoothed cut with width 0 accepted");
  sp_error_clear();
  free(mask);
  free(state);
  free(new_state);
  free(bad_state);
  sp_layout_destroy(&layout);
  sp_layout_destroy(&new_layout);
  sp_layout_destroy(&bad_layout);
  sp_mesh_destroy(&mesh);
}

/* Age criterion: due once the age reaches T_div, also across a step that
 * jumps over it; the crossing fraction is exact. */
static void test_age_criterion(void) {
  const sp_division_params age = {.criterion = SP_DIVIDE_AGE, .age = 0.5};
  CHECK_OK(sp_division_params_check(&age));
  const sp_cell_birth born = {.birth_time = 1.0, .birth_mass = 1.0, .generation = 1};
  CHECK(!sp_division_due(&age, &born, 1.40, 1.49, 0, 0), "age 0.49 < 0.5 due");
  CHECK(sp_division_due(&age, &born, 1.40, 1.50, 0, 0), "age exactly 0.5 not due");
  CHECK(sp_division_due(&age, &born, 1.45, 1.60, 0, 0), "a step over the age not due");
  CHECK(sp_division_due(&age, &born, 1.60, 1.70, 0, 0), "an age already exceeded not due");
  CHECK_NEAR(sp_division_crossing_fraction(&age, &born, 1.45, 1.60, 0, 0), 1.0 / 3.0, 1e-14);
  CHECK(sp_division_crossing_fraction(&age, &born, 1.60, 1.70, 0, 0) == 0.0,
        "already exceeded: fraction not 0");
  CHECK(sp_division_crossing_fraction(&age, &born, 1.40, 1.49, 0, 0) == 1.0,
        "not reached: fraction not 1");
  /* an age accumulated in steps of 0.1 (0.9999999999999999) reaches 1 */
  const sp_division_params age1 = {.criterion = SP_DIVIDE_AGE, .age = 1.0};
  const sp_cell_birth at_zero = {.birth_time = 0.0};
  double t = 0;
  for (int j = 0; j < 10; ++j) t += 0.1;
  CHECK(sp_division_due(&age1, &at_zero, t - 0.1, t, 0, 0),
        "age %.17g accumulated from 10 x 0.1 does not reach 1", t);
}

/* Mass criterion: 1.9 m0 -> 2.3 m0 in one step divides (a window
 * eps1 < m/m0 - 1 < eps2 of, say, 0.99 .. 1.01 would miss it), the crossing
 * is at 1/4 of the step; the reference mass option; the tolerance. */
static void test_mass_criterion(void) {
  const sp_division_params own = {.criterion = SP_DIVIDE_MASS,
                                  .mass_ratio = SP_DIVISION_MASS_RATIO_PAPER};
  CHECK_OK(sp_division_params_check(&own));
  const double m0 = 0.0137;
  const sp_cell_birth born = {.birth_time = 0.2, .birth_mass = m0};
  CHECK(sp_division_due(&own, &born, 1, 1.1, 1.9 * m0, 2.3 * m0), "1.9 -> 2.3 m0 not due");
  CHECK_NEAR(sp_division_crossing_fraction(&own, &born, 1, 1.1, 1.9 * m0, 2.3 * m0), 0.25,
             1e-12);
  CHECK(!sp_division_due(&own, &born, 1, 1.1, 1.9 * m0, 1.99 * m0), "1.99 m0 due");
  CHECK(sp_division_due(&own, &born, 1, 1.1, 2.1 * m0, 2.2 * m0), "2.2 m0 (after 2.1) not due");
  CHECK(sp_division_crossing_fraction(&own, &born, 1, 1.1, 2.1 * m0, 2.2 * m0) == 0.0,
        "already exceeded: fraction not 0");
  CHECK(sp_division_due(&own, &born, 1, 1.1, 1.9 * m0, 2.0 * m0), "exactly 2 m0 not due");

  /* a daughter born lighter (0.8 m0) divides at 1.6 m0 by its own birth
   * mass, but at 2 m0 with the initial cell's mass as the reference */
  const sp_cell_birth light = {.birth_time = 0.5, .birth_mass = 0.8 * m0};
  const sp_division_params initial = {.criterion = SP_DIVIDE_MASS,
                                      .mass_ratio = SP_DIVISION_MASS_RATIO_PAPER,
                                      .reference_mass = m0};
  CHECK(sp_division_due(&own, &light, 1, 1.1, 1.5 * m0, 1.7 * m0), "own birth mass: 1.7 m0 "
        "not due at 2 x 0.8 m0");
  CHECK(!sp_division_due(&initial, &light, 1, 1.1, 1.5 * m0, 1.7 * m0), "reference m0: 1.7 m0 "
        "due");
  CHECK(sp_division_due(&initial, &light, 1, 1.1, 1.9 * m0, 2.3 * m0), "reference m0: 2.3 m0 "
        "not due");

  /* tolerance: a step shortened to the interpolated crossing that lands a
   * hair short (curved mass history) still counts */
  const sp_division_params tolerant = {.criterion = SP_DIVIDE_MASS, .mass_ratio = 2,
                                       .tolerance = 1e-6};
  CHECK(!sp_division_due(&own, &born, 1, 1.1, 1.9 * m0, (2 - 1e-8) * m0),
        "no tolerance: 2 - 1e-8 due");
  CHECK(sp_division_due(&tolerant, &born, 1, 1.1, 1.9 * m0, (2 - 1e-8) * m0),
        "tolerance 1e-6: 2 - 1e-8 not due");
  CHECK(sp_division_crossing_fraction(&tolerant, &born, 1, 1.1, 1.9 * m0, (2 - 1e-8) * m0) ==
        1.0, "landed short within the tolerance: step shortened again");

  /* bad parameters are refused with a message */
  const sp_division_params bad_age = {.criterion = SP_DIVIDE_AGE, .age = 0};
  const sp_division_params bad_ratio = {.criterion = SP_DIVIDE_MASS, .mass_ratio = -1};
  CHECK(sp_division_params_check(&bad_age) == SP_ERR_INPUT, "T_div = 0 accepted");
  CHECK(sp_division_params_check(&bad_ratio) == SP_ERR_INPUT, "mass ratio -1 accepted");
  sp_error_clear();
}

/* The birth records after a split: time, masses, moments, generation. */
static void test_birth_records(void) {
  sp_cell_obs obs[3] = {{.mass = 1.0, .moments = {3.0, 1.0}},
                        {.mass = 0.52, .moments = {0.9, 0.4}},
                        {.mass = 0.48, .moments = {0.8, 0.5}}};
  sp_cell_birth registry[3];
  registry[0] = sp_cell_birth_make(0.0, &obs[0], 0);
  registry[1] = sp_cell_birth_make(0.0, &obs[0], 0);
  CHECK(registry[0].birth_mass == 1.0 && registry[0].Iref[0] == 3.0 &&
        registry[0].Iref[1] == 1.0 && registry[0].generation == 0, "initial birth record");
  sp_cell_obs split[3] = {obs[1], obs[0], obs[2]};
  sp_division_record_births(2.5, split, 0, 2, registry);
  CHECK(registry[0].birth_time == 2.5 && registry[0].birth_mass == 0.52 &&
        registry[0].Iref[0] == 0.9 && registry[0].generation == 1, "parent's new record");
  CHECK(registry[2].birth_time == 2.5 && registry[2].birth_mass == 0.48 &&
        registry[2].Iref[1] == 0.5 && registry[2].generation == 1, "child's record");
  CHECK(registry[1].birth_time == 0.0 && registry[1].generation == 0, "bystander's record");
}

/* Algorithm 2 with the authors' n_div = 3, m = 6: exact values for
 * a = 1..12, dt_bar from a = 13 on; and n_div = 2, m = 4. */
static void test_dt_after_division(void) {
  /* dt_bar = 1: each value is the double nearest to the decimal */
  const double paper[] = {1e-6, 1e-6, 1e-6, 1e-6, 6.4e-5, 7.29e-4, 4.096e-3, 1.5625e-2,
                          4.6656e-2, 0.117649, 0.262144, 0.531441, 1.0};
  printf("dt after a division (algorithm 2), n_div = 3, m = 6, dt_bar = 2e-4:\n  a:");
  for (int a = 1; a <= 13; ++a) {
    CHECK(sp_division_dt(1.0, 3, 6, a) == paper[a - 1], "n_div 3, m 6, a = %d: %.17g != %.17g",
          a, sp_division_dt(1.0, 3, 6, a), paper[a - 1]);
    const double dt = sp_division_dt(2e-4, 3, 6, a);
    CHECK(dt == 2e-4 * paper[a - 1], "dt_bar 2e-4, a = %d: %.17g", a, dt);
    printf(" %d:%.4g", a, dt);
  }
  printf("\n");
  for (int a = 13; a <= 40; ++a)
    CHECK(sp_division_dt(2e-4, 3, 6, a) == 2e-4, "a = %d: not dt_bar", a);
  CHECK(sp_division_dt(2e-4, 3, 6, 0) == 2e-4, "no division (a = 0): not dt_bar");
  CHECK(sp_division_dt(2e-4, 3, 0, 1) == 2e-4, "m = 0: not dt_bar");

  const double other[] = {1e-4, 1e-4, 1e-4, 1.6e-3, 8.1e-3, 2.56e-2, 6.25e-2, 0.1296, 0.2401,
                          0.4096, 0.6561, 1.0};
  double previous = 0;
  for (int a = 1; a <= 12; ++a) {
    const double dt = sp_division_dt(1.0, 2, 4, a);
    CHECK(dt == other[a - 1], "n_div 2, m 4, a = %d: %.17g != %.17g", a, dt, other[a - 1]);
    CHECK(dt >= previous, "n_div 2, m 4: dt decreases at a = %d", a);
    previous = dt;
  }
  CHECK(sp_division_dt(1.0, 2, 4, 13) == 1.0, "n_div 2, m 4: a = 13 not dt_bar");
  /* n_div = 0: the ramp starts at once */
  CHECK(sp_division_dt(1.0, 0, 2, 1) == 1e-2, "n_div 0, m 2, a = 1: %g",
        sp_division_dt(1.0, 0, 2, 1));
}

/* N_max = floor(meas(Omega) / m0), robust to round-off in the ratio. */
static void test_max_cells(void) {
  CHECK(sp_division_max_cells(1.0, 1.0 / 16) == 16, "1 / (1/16)");
  CHECK(sp_division_max_cells(1.0, 0.07) == 14, "1 / 0.07 = 14.3");
  const double ellipse = PI * 0.5 * 0.25;
  for (int n = 1; n <= 40; ++n) {
    /* m0 a hair above area / n: the ratio is n minus round-off */
    const double m0 = ellipse / n * (1 + 1e-15);
    CHECK(sp_division_max_cells(ellipse, m0) == n, "ellipse / (ellipse / %d): %d", n,
          sp_division_max_cells(ellipse, m0));
  }
  CHECK(sp_division_max_cells(1.0, 2.0) == 1, "a cell larger than Omega: N_max not 1");
  CHECK(sp_division_max_cells(1.0, 0.0) == 0, "m0 = 0 not refused");
  CHECK(sp_division_max_cells(-1.0, 0.1) == 0, "negative area not refused");
  /* the paper's seed: radius 1/15 in the 0.5 x 0.25 ellipse */
  const double seed = PI / 225;
  printf("N_max of the paper's ellipse and seed (interior only): %d\n",
         sp_division_max_cells(ellipse, seed));
}

/** c = an egg: the union (max) of two tanh disks along the direction phi,
 *  the larger at (x, y), on a background; mu = 0. */
static void set_egg(const sp_mesh *mesh, const sp_layout *layout, double *state, double x,
                    double y, double phi, double background) {
  const double d = interface_width(), r1 = 0.1, r2 = 0.07, gap = 0.12;
  const double x2 = x + gap * cos(phi), y2 = y + gap * sin(phi);
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, 0, i);
    const double *X = mesh->xy + 2 * i;
    const double d1 = hypot(X[0] - x, X[1] - y) - r1, d2 = hypot(X[0] - x2, X[1] - y2) - r2;
    const double profile = 1.0 / (1.0 + exp(fmin(d1, d2) / d));
    state[2 * p] = profile + (1.0 - profile) * background;
    state[2 * p + 1] = 0.0;
  }
}

/* division.line = equal_mass: the line moved along its normal halves an
 * egg-shaped parent that the centre line splits unequally; the direction is
 * unchanged, and a symmetric cell's line does not move. */
static void test_equal_mass_line(void) {
  sp_mesh *mesh;
  sp_layout *layout, *new_layout;
  double *state, *new_state;
  split_setup(&mesh, &layout, &new_layout, &state, &new_state);
  const double width = interface_width();
  printf("  equal-mass line  | cut    | offset    | centre line: daughters off by | "
         "equal mass: off by (allowed)\n");
  for (int egg = 0; egg <= 1; ++egg)
    for (int smooth = 0; smooth <= 1; ++smooth) {
      if (egg)
        set_egg(mesh, layout, state, 0.42, 0.45, 0.7, 0.01);
      else
        set_ellipse_bg(mesh, layout, state, 0, 0.5, 0.5, 0.12, 0.06, 0.3, 0.01);
      /* sums over 1e5 quadrature points of a domain-wide background: 1e-11;
       * the sharp cut moves in steps of one node's share: h^2 / (area / 2)
       * ~ 2e-3 here; the smoothed cut is continuous in the offset */
      check_equal_mass_cut(mesh, layout, new_layout, state, new_state, egg, smooth, width,
                           WEIGHT_THRESHOLD, 1e-11, smooth ? 1e-10 : 3e-3);
    }
  split_teardown(&mesh, &layout, &new_layout, &state, &new_state);
}

/* Which daughter takes the new label follows the sign of the cut's normal,
 * the long axis (axes[1] in 2D). For a cut along the vertical (symmetric
 * scenes make them) a round-off-sized Ixy of either sign must give the
 * same normal; everywhere the normal is the unit eigenvector of the
 * smaller moment, at an angle in [0.2, 0.2 + pi] from the x axis, and
 * axes[0] the larger moment's. */
static void test_axis_sign_convention(void) {
  double I[3], v[3][3], w[3][3];
  sp_cells_principal(2, (const double[3][3]){{1.0, 1e-17, 0}, {1e-17, 2.0, 0}, {0, 0, 0}}, I, v);
  sp_cells_principal(2, (const double[3][3]){{1.0, -1e-17, 0}, {-1e-17, 2.0, 0}, {0, 0, 0}}, I, w);
  printf("vertical cut, Ixy = +-1e-17: normal = (%.3g, %.3g) and (%.3g, %.3g)\n", v[1][0],
         v[1][1], w[1][0], w[1][1]);
  CHECK(fabs(v[1][0] - w[1][0]) < 1e-15 && fabs(v[1][1] - w[1][1]) < 1e-15 && v[1][0] < -0.99,
        "vertical cut: normal (%g, %g) against (%g, %g)", v[1][0], v[1][1], w[1][0], w[1][1]);
  double worst = 0;
  for (int j = 0; j < 360; ++j) {
    const double phi = M_PI * (j + 0.5) / 180.0 - M_PI; /* the long axis, all ways */
    const double a = 2.0, b = 1.0, c = cos(phi), s = sin(phi);
    const double Ixx = a * c * c + b * s * s, Iyy = a * s * s + b * c * c, Ixy = (a - b) * c * s;
    sp_cells_principal(2, (const double[3][3]){{Ixx, Ixy, 0}, {Ixy, Iyy, 0}, {0, 0, 0}}, I, v);
    for (int i = 0; i < 2; ++i) {
      const double r0 = Ixx * v[i][0] + Ixy * v[i][1] - I[i] * v[i][0];
      const double r1 = Ixy * v[i][0] + Iyy * v[i][1] - I[i] * v[i][1];
      worst = fmax(worst, hypot(r0, r1));
    }
    double angle = atan2(v[1][1], v[1][0]);
    if (angle < 0.2 - 1e-12) angle += 2 * M_PI;
    CHECK(I[0] >= I[1] && I[2] == 0 && v[2][0] == 0 && v[2][1] == 0 && v[2][2] == 0,
          "long axis %g: moments %g, %g, %g", phi, I[0], I[1], I[2]);
    CHECK(angle >= 0.2 - 1e-12 && angle <= 0.2 + M_PI + 1e-12, "long axis %g: normal at %g rad",
          phi, angle);
  }
  CHECK(worst < 1e-14, "eigenvector residual %.3g", worst);
}

int main(void) {
  test_axis_sign_convention();
  test_axis_of_ellipses();
  test_split_conserves_and_halves();
  test_split_local_supports();
  test_equal_mass_line();
  test_age_criterion();
  test_mass_criterion();
  test_birth_records();
  test_dt_after_division();
  test_max_cells();
  TEST_DONE();
}
