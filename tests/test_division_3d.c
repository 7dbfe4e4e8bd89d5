/* Division on a 3D mesh (src/model/division.c; docs/3d.md):
 * the cut is the plane through the centre of mass normal to the long axis
 * (the eigenvector of the smallest principal moment, sp_division_plane).
 *  - an ellipsoid 0.14 x 0.08 x 0.07 long along x, and the same turned to a
 *    generic orientation, split by the sharp and the smoothed cut: the
 *    plane's normal is the long axis (1e-3 rad, test_cells_3d's bound),
 *    the parent's mass is conserved (1e-13 relative in long double, 1e-12
 *    through the observables), c_parent + c_child = c at every node, the
 *    bystander cell is untouched, the child lies on the normal's side, and
 *    the daughters' centres are separated along the long axis: their
 *    difference within 1e-2 rad of it, and as far apart as the halves of
 *    the continuous profile, 2 a int f rho^3 / (2 int f rho^2) over rho
 *    (f the tanh profile where >= 0.05; 3a/4 for a sharp one): the sharp
 *    cut within 1%, the smoothed one within 3% (its logistic share of
 *    width d leaves each daughter a tail across the plane, which pulls
 *    the centres together by O(d^2 / a) each);
 *  - the equal-mass plane (division.line: equal_mass) halves an egg (two
 *    overlapping spheres, 0.1 and 0.07, 0.12 apart along a generic
 *    direction) that the centre plane splits unequally: the smoothed cut to
 *    1e-10 relative, the sharp cut within one node's share (max_i w_i c_i
 *    over half the mass); and leaves a symmetric ellipsoid's plane where it
 *    is (1e-3 h);
 *  - N_max = meas(Omega) / m^0 (sp_division_max_cells) with the box's
 *    volume (sp_mesh_region_area in 3D: 0.06 to 5e-13 relative, the
 *    round-off of its 3840 quadrature weights). */
#include <math.h>
#include <stdlib.h>

#include "model/cells.h"
#include "check.h"
#include "model/division.h"
#include "division_fixtures.h"
#include "public/error.h"
#include "fixtures.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

/** Centre and inertia integrate c >= this, as the stepper does. */
#define WEIGHT_THRESHOLD 0.05

static double interface_width(void) { return sqrt(1e-3 / 8.0); }

/** How far apart the centres of the two halves of a tanh ellipsoid (cut
 *  through its centre normal to the semi-axis @p a, profile width @p eps in
 *  rho units, weight where c >= WEIGHT_THRESHOLD) lie: 2 a E[u] with
 *  E[u] = (1/2) int f rho^3 / int f rho^2 (a hemisphere's mean cos is 1/2),
 *  by the midpoint rule. */
static double halves_apart(double a, double eps) {
  const int n = 200000;
  const double rho_max = 3.0;
  double m3 = 0, m2 = 0;
  for (int i = 0; i < n; ++i) {
    const double rho = (i + 0.5) * rho_max / n, c = 1.0 / (1.0 + exp((rho - 1.0) / eps));
    if (c < WEIGHT_THRESHOLD) continue;
    m3 += c * rho * rho * rho;
    m2 += c * rho * rho;
  }
  return a * m3 / m2;
}

/** One split of an ellipsoid with long axis @p axes[0] (cell 0 of two;
 *  cell 1 a bystander sphere) and the checks every split must pass. */
static void check_split(const sp_mesh *mesh, const double axes[3][3], int smooth,
                        const char *label) {
  const double centre[3] = {0.2517, 0.2483, 0.2509}, semi[3] = {0.14, 0.08, 0.07};
  const double other[3] = {0.07, 0.07, 0.07}, other_centre[3] = {0.43, 0.43, 0.43};
  const double width = interface_width();
  sp_layout *layout, *new_layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &layout));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 3, &new_layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *new_state = calloc(2 * (size_t)new_layout->n_pairs, sizeof(double));
  double *w = calloc((size_t)mesh->n_nodes, sizeof(double));
  set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, width / semi[2]);
  set_ellipsoid(mesh, layout, state, 1, other_centre, axes, other, width / other[0]);
  for (int i = 0; i < mesh->n_nodes; ++i) state[2 * sp_layout_pair(layout, 0, i) + 1] = 0.1;
  sp_cell_obs before[2], after[3];
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, before));
  double point[3], normal[3];
  sp_division_plane(&before[0], 3, point, normal);
  CHECK_OK(sp_division_split(mesh, layout, state, 0, &before[0], smooth, width, 0.0, new_layout,
                             new_state, 2));
  CHECK_OK(sp_cells_observe(mesh, new_layout, new_state, WEIGHT_THRESHOLD, after));
  CHECK_OK(sp_cells_node_weights(mesh, layout, 0, w));

  const double normal_error = line_angle3(normal, axes[0]);
  CHECK(normal_error < 1e-3, "%s: the cut's normal off the long axis by %.3g rad", label,
        normal_error);
  CHECK(fabs(norm3(normal) - 1) <= 1e-15, "%s: |n| = %.17g", label, norm3(normal));
  const double m_before = cell_mass(layout, state, w, 0);
  const double m_parent = cell_mass(new_layout, new_state, w, 0);
  const double m_child = cell_mass(new_layout, new_state, w, 2);
  const double conservation = fabs(m_parent + m_child - m_before) / m_before;
  CHECK(conservation <= 1e-13, "%s: parent + child %.17g, parent before %.17g (relative %.3g)",
        label, m_parent + m_child, m_before, conservation);
  const double observed = fabs(after[0].mass + after[2].mass - before[0].mass) / before[0].mass;
  CHECK(observed <= 1e-12, "%s: observed masses: relative change %.3g", label, observed);
  CHECK(after[1].mass == before[1].mass, "%s: bystander mass %.17g -> %.17g", label,
        before[1].mass, after[1].mass);
  double worst_sum = 0;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const double c = state[2 * sp_layout_pair(layout, 0, i)];
    const double cp = new_state[2 * sp_layout_pair(new_layout, 0, i)];
    const double cc = new_state[2 * sp_layout_pair(new_layout, 2, i)];
    worst_sum = fmax(worst_sum, fabs(cp + cc - c));
  }
  CHECK(worst_sum <= 1e-15, "%s: |c_parent + c_child - c| up to %.3g", label, worst_sum);

  /* the daughters' centres: apart along the long axis, the child on n's side */
  const double apart[3] = {after[2].centre[0] - after[0].centre[0], after[2].centre[1] - after[0].centre[1],
                           after[2].centre[2] - after[0].centre[2]};
  const double child_side[3] = {after[2].centre[0] - point[0], after[2].centre[1] - point[1],
                                after[2].centre[2] - point[2]};
  const double apart_angle = line_angle3(apart, axes[0]), distance = norm3(apart);
  const double expected = halves_apart(semi[0], width / semi[2]);
  const double unequal = fabs(m_parent - m_child) / (0.5 * (m_parent + m_child));
  printf("  %-34s | %.1e | %.1e | %.2e rad | %.4f (%.4f) | %.2e rad | %.2e\n", label,
         conservation, observed, normal_error, distance, expected, apart_angle, unequal);
  CHECK(dot3(child_side, normal) > 0, "%s: the child's centre is not on n's side", label);
  CHECK(apart_angle < 1e-2, "%s: the daughters' centres apart at %.3g rad off the long axis",
        label, apart_angle);
  CHECK(fabs(distance - expected) < (smooth ? 0.03 : 0.01) * expected,
        "%s: the daughters' centres %.4f apart, the continuous halves' %.4f", label, distance,
        expected);
  free(w);
  free(state);
  free(new_state);
  sp_layout_destroy(&layout);
  sp_layout_destroy(&new_layout);
}

static void test_split(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.5, 0.5, 40, 40, 40, &mesh));
  printf("  split                              | mass    | observed | normal error | "
         "centres apart (expected) | their angle | daughters differ\n");
  double axes[3][3];
  for (int turned = 0; turned <= 1; ++turned) {
    rotated_axes(turned ? 0.5 : 0.0, turned ? 0.9 : 0.0, turned ? 0.3 : 0.0, axes);
    for (int smooth = 0; smooth <= 1; ++smooth) {
      char label[64];
      snprintf(label, sizeof label, "%s, %s cut", turned ? "turned (0.5, 0.9, 0.3)" : "along x",
               smooth ? "smooth" : "sharp");
      check_split(mesh, axes, smooth, label);
    }
  }
  sp_mesh_destroy(&mesh);
}

/** c = an egg: the union (max) of two tanh spheres along @p dir, the
 *  larger at @p x; mu = 0. */
static void set_egg(const sp_mesh *mesh, const sp_layout *layout, double *state,
                    const double x[3], const double dir[3]) {
  const double d = interface_width(), r1 = 0.1, r2 = 0.07, gap = 0.12;
  const double x2[3] = {x[0] + gap * dir[0], x[1] + gap * dir[1], x[2] + gap * dir[2]};
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, 0, i);
    const double *X = mesh->xy + 3 * (size_t)i;
    const double a[3] = {X[0] - x[0], X[1] - x[1], X[2] - x[2]};
    const double b[3] = {X[0] - x2[0], X[1] - x2[1], X[2] - x2[2]};
    const double profile = 1.0 / (1.0 + exp(fmin(norm3(a) - r1, norm3(b) - r2) / d));
    state[2 * p] = profile;
    state[2 * p + 1] = 0.0;
  }
}

static void test_equal_mass_plane(void) {
  sp_mesh *mesh;
  sp_layout *layout, *new_layout;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.5, 0.5, 40, 40, 40, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 2, &new_layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *new_state = calloc(2 * (size_t)new_layout->n_pairs, sizeof(double));
  double *w = calloc((size_t)mesh->n_nodes, sizeof(double));
  CHECK_OK(sp_cells_node_weights(mesh, layout, 0, w));
  const double width = interface_width();
  double axes[3][3];
  rotated_axes(0.5, 0.9, 0.3, axes);
  const double egg_at[3] = {0.2017, 0.1983, 0.2009};
  printf("  equal-mass plane | cut    | offset    | centre plane: daughters off by | "
         "equal mass: off by (allowed)\n");
  for (int egg = 0; egg <= 1; ++egg)
    for (int smooth = 0; smooth <= 1; ++smooth) {
      if (egg) {
        set_egg(mesh, layout, state, egg_at, axes[0]);
      } else {
        const double centre[3] = {0.2517, 0.2483, 0.2509}, semi[3] = {0.14, 0.08, 0.07};
        set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, width / semi[2]);
      }
      double largest_share = 0, mass = 0;
      for (int i = 0; i < mesh->n_nodes; ++i) {
        const double share = w[i] * state[2 * sp_layout_pair(layout, 0, i)];
        largest_share = fmax(largest_share, share);
        mass += share;
      }
      /* the sharp cut's child mass jumps by one node's w_i c_i at a time */
      check_equal_mass_cut(mesh, layout, new_layout, state, new_state, egg, smooth, width,
                           WEIGHT_THRESHOLD, 1e-12, smooth ? 1e-10 : largest_share / (0.5 * mass));
    }
  free(w);
  free(state);
  free(new_state);
  sp_layout_destroy(&layout);
  sp_layout_destroy(&new_layout);
  sp_mesh_destroy(&mesh);
}

/* N_max = meas(Omega) / m^0 is the volume over the birth mass in 3D. */
static void test_max_cells(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.4, 0.3, 10, 8, 6, &mesh));
  const double volume = sp_mesh_region_area(mesh, SP_REGION_OMEGA);
  const double sphere = 4.0 / 3.0 * acos(-1.0) * 0.1 * 0.1 * 0.1; /* m^0 of a sphere r = 0.1 */
  printf("N_max: box volume %.17g, birth mass %.6g: %d cells\n", volume, sphere,
         sp_division_max_cells(volume, sphere));
  /* a sum of 3840 quadrature weights: round-off up to 3840 x 2^-53 relative */
  CHECK(fabs(volume - 0.06) <= 5e-13 * 0.06, "box volume %.17g, expected 0.06", volume);
  CHECK(sp_division_max_cells(volume, sphere) == 14, "N_max %d, floor(0.06 / %g) = 14",
        sp_division_max_cells(volume, sphere), sphere);
  sp_mesh_destroy(&mesh);
}

int main(void) {
  test_max_cells();
  test_split();
  test_equal_mass_plane();
  TEST_DONE();
}
