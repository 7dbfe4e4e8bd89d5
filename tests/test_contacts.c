/* Contacts measured from the fields (src/model/contacts.h; docs/model.md,
 * "Contacts"), on the exact equilibrium profile c = 1 / (1 + e^(s/d))
 * interpolated on Q1 meshes of decreasing h (2D quadrilaterals, 3D
 * hexahedra; d fixed):
 * - two cells pressed flat against each other across an oblique line (2D)
 *   or plane (3D) through a box: the contact converges to the segment's
 *   length (the plane's area) at the order asserted below, and each cell's
 *   free surface is 0; two flat faces a film of 2 d apart: the contact
 *   converges to g(2) = 2 / (1 + e) times it;
 * - a round cell alone (a quarter disk, an octant of a ball, in the corner
 *   of the box: the walls are symmetry planes): its diffuse surface
 *   converges to 2 pi R / 4 (exact for the diffuse profile in 2D) and to
 *   (4 pi R^2 / 8)(1 + (pi^2 / 3)(d / R)^2) in 3D, the diffuse interface's
 *   own excess over the sphere, derived in docs/model.md;
 * - a lone cell has only its cell row in contacts.csv; a cell 10 d from it
 *   is not in contact (no pair row), one touching it is (a pair row);
 * - two halves of the elements (an MPI run's ranks) add up to the whole to
 *   round-off; local supports covering the interfaces give the full
 *   layout's values (a pair counts only where both cells live).
 *
 * The expected order is 2. The measures integrate |grad I c| (and the
 * smaller of two such) for the Q1 interpolant I c of a smooth profile:
 * |grad I c| - |grad c| = n . grad e + O(|grad e|^2) with e = I c - c and
 * n = grad c / |grad c|; grad e is O(h) pointwise, but its first-order
 * term integrates to -int div(n) e + (boundary) = O(h^2) since e = O(h^2),
 * and the quadratic term is O(h^2); where the minimum switches from one
 * cell to the other (a line, a surface) the kink costs O(h^2) too. The
 * 2x2(x2) Gauss rule adds O(h^2) at most. Measured (printed below),
 * between the two finest meshes: 2.00 in 2D (pressed, film, round), 2.02,
 * 1.98 and 1.96 in 3D (d / h = 1.4 and 1.9 at the finest); asserted:
 * [1.8, 2.3], and the finest relative errors below 1e-3 (2D) and 1e-2
 * (3D), measured 2.6e-5, 4.6e-4, 4.0e-5 (2D) and 2.0e-4, 7.7e-3, 4.3e-4
 * (3D). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "model/cells.h"
#include "check.h"
#include "model/contacts.h"
#include "io/contacts_out.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "output_read.h"

/** A cell's signed distance function (> 0 outside) at x[0..dim). */
typedef double (*distance_fn)(const double *x, int dim);

/* The oblique contact: x = 1/2 + A (y - 1/2) [+ B (z - 1/2)], cell 0 on the
 * side x smaller. Its length (area) in the unit square (cube):
 * sqrt(1 + A^2 [+ B^2]), with A = 0.3 in 2D, A = 0.15 and B = 0.1 in 3D.
 * The line stays 16.8 d (2D, d = 0.02) and the plane 12.3 d (3D, d = 0.03)
 * from the walls x = 0, 1: the profiles' tails cut off there are below
 * e^-16 and e^-12 (the surfaces' relative truncation, below the finest
 * discretisation errors by 30 and more). */
static double slope(int dim, int i) {
  static const double s[2][2] = {{0.3, 0.0}, {0.15, 0.1}};
  return s[dim - 2][i];
}

static double plane_distance(const double *x, int dim) {
  const double a = slope(dim, 0), b = slope(dim, 1), z = dim == 3 ? x[2] - 0.5 : 0.0;
  return (x[0] - 0.5 - a * (x[1] - 0.5) - b * z) / sqrt(1 + a * a + b * b);
}
/* the other cell, beyond a film of this width (0: pressed, the membranes
 * coincide) */
static double film;
static double plane_distance_other(const double *x, int dim) {
  return film - plane_distance(x, dim);
}

/* The round cell: radius R about the box's corner at the origin. */
static const double radius = 0.5;
static double ball_distance(const double *x, int dim) {
  double r2 = 0;
  for (int i = 0; i < dim; ++i) r2 += x[i] * x[i];
  return sqrt(r2) - radius;
}

/* A disk of radius 0.1 on the diagonal, disk_gap from the round cell
 * above (2D). */
static double disk_gap;
static double near_disk_distance(const double *x, int dim) {
  (void)dim;
  const double at = (radius + disk_gap + 0.1) / sqrt(2.0);
  return hypot(x[0] - at, x[1] - at) - 0.1;
}

static sp_mesh *unit_box(int dim, int n) {
  sp_mesh *m = NULL;
  if (dim == 2) CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, n, n, &m));
  else CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, 1, n, n, n, &m));
  return m;
}

/** The state of @p n_cells cells with profiles of width @p d about the
 *  distance functions @p dist on @p layout (mu = 0). */
static double *profiles(const sp_mesh *m, const sp_layout *layout, int n_cells,
                        const distance_fn *dist, double d) {
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  for (int k = 0; k < n_cells; ++k)
    for (int i = 0; i < m->n_nodes; ++i) {
      const int p = sp_layout_pair(layout, k, i);
      if (p >= 0) state[2 * p] = sp_cells_profile(dist[k](m->xy + (size_t)m->dim * i, m->dim), d);
    }
  return state;
}

/** Contacts of the cells @p dist on a full layout of the unit box in n^dim
 *  elements. */
static sp_contacts measure(int dim, int n, int n_cells, const distance_fn *dist, double d) {
  sp_mesh *m = unit_box(dim, n);
  sp_layout *layout = NULL;
  CHECK_OK(sp_layout_create_full(m->n_nodes, n_cells, &layout));
  double *state = profiles(m, layout, n_cells, dist, d);
  sp_contacts c = {0};
  CHECK_OK(sp_contacts_integrate(m, layout, state, 0, m->n_nodes, &c));
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&m);
  return c;
}

/** Errors |value(h) - exact| on meshes n[0..levels) and the observed order
 *  between the two finest; checks it lies in [lo, hi] and the finest error
 *  is below @p finest_tol (relative). */
static void check_order(const char *what, const int *n, const double *value, int levels,
                        double exact, double lo, double hi, double finest_tol) {
  double err[8];
  for (int i = 0; i < levels; ++i) {
    err[i] = fabs(value[i] - exact) / exact;
    printf("%s: n = %3d  value %.10f  exact %.10f  relative error %.3e", what, n[i], value[i],
           exact, err[i]);
    if (i > 0) printf("  order %.3f", log(err[i - 1] / err[i]) / log((double)n[i] / n[i - 1]));
    printf("\n");
  }
  const double order =
      log(err[levels - 2] / err[levels - 1]) / log((double)n[levels - 1] / n[levels - 2]);
  CHECK(order >= lo && order <= hi, "%s: observed order %.3f outside [%g, %g]", what, order,
        lo, hi);
  CHECK(err[levels - 1] <= finest_tol, "%s: finest relative error %.3e > %.3e", what,
        err[levels - 1], finest_tol);
}

/** Two flat faces a film of @p gamma d apart: contact -> g(gamma) times the
 *  length (area) of the cut, g = 2 / (1 + e^(gamma/2)) (docs/model.md), at
 *  order 2; pressed (gamma = 0), the free surfaces are 0. */
static void test_flat_contact(int dim, const int *n, int levels, double d, double gamma,
                              double finest_tol) {
  const distance_fn pair[2] = {plane_distance, plane_distance_other};
  const double cut = sqrt(1 + slope(dim, 0) * slope(dim, 0) + slope(dim, 1) * slope(dim, 1));
  const double exact = cut * 2 / (1 + exp(gamma / 2));
  film = gamma * d;
  double contact[8], free_surface[8];
  for (int i = 0; i < levels; ++i) {
    sp_contacts c = measure(dim, n[i], 2, pair, d);
    CHECK(sp_contacts_touch(&c, 0, 1, 0.01) && sp_contacts_touch(&c, 1, 0, 0.01),
          "pressed cells in contact");
    contact[i] = c.overlap[sp_contacts_pair(2, 0, 1)];
    double total;
    sp_contacts_of_cell(&c, 0, 0.01, &total, &free_surface[i]);
    CHECK(total == contact[i], "the cell's contact is its one pair's");
    sp_contacts_clear(&c);
  }
  char what[64];
  snprintf(what, sizeof what, "%dD flat contact, film %g d", dim, gamma);
  check_order(what, n, contact, levels, exact, 1.8, 2.3, finest_tol);
  if (gamma > 0) return;
  /* pressed: c_l = 1 - c_k at the nodes, so |grad c_l| = |grad c_k| at every
   * point, A_kl = S_k and the free surface vanishes to round-off */
  for (int i = 0; i < levels; ++i)
    CHECK(fabs(free_surface[i]) <= 1e-12 * cut, "n = %d: free surface %.3e, not 0", n[i],
          free_surface[i]);
}

/** A round cell alone: its diffuse surface -> 2 pi R / 4 (2D) or
 *  (4 pi R^2 / 8)(1 + (pi^2/3)(d/R)^2) (3D) at order 2. */
static void test_round_cell(int dim, const int *n, int levels, double d, double finest_tol) {
  const distance_fn one[1] = {ball_distance};
  const double geometric = dim == 2 ? 2 * M_PI * radius / 4 : 4 * M_PI * radius * radius / 8;
  /* the diffuse surface's excess over the membrane's (docs/model.md): 0
   * in 2D, (pi^2/3)(d/R)^2 relative in 3D */
  const double excess = dim == 2 ? 0.0 : M_PI * M_PI / 3 * (d / radius) * (d / radius);
  double surface[8];
  for (int i = 0; i < levels; ++i) {
    sp_contacts c = measure(dim, n[i], 1, one, d);
    surface[i] = c.surface[0];
    sp_contacts_clear(&c);
  }
  char what[64];
  snprintf(what, sizeof what, "%dD round cell's surface", dim);
  check_order(what, n, surface, levels, geometric * (1 + excess), 1.8, 2.3, finest_tol);
  const double off = surface[levels - 1] / geometric - 1;
  printf("%s: %.4f of the geometric %.4f (%+.3e relative; the diffuse excess %.3e)\n", what,
         surface[levels - 1], geometric, off, excess);
  /* the geometric value to the diffuse interface's accuracy */
  CHECK(fabs(off) <= excess + finest_tol, "%s off the geometric by %.3e", what, off);
}

/** contacts.csv of a lone cell: its cell row, no pair row; of a cell 10 d
 *  from it: no pair row either (not in contact); of a cell touching it
 *  (membranes tangent, not pressed): in contact, with its pair row. */
static void test_lone_and_apart(void) {
  const double d = 0.01;
  const distance_fn two[2] = {ball_distance, near_disk_distance};
  sp_mesh *m = unit_box(2, 100);
  for (int run = 0; run < 3; ++run) {
    const int n_cells = run == 0 ? 1 : 2, touching = run == 2;
    disk_gap = touching ? 0.0 : 10 * d;
    sp_layout *layout = NULL;
    CHECK_OK(sp_layout_create_full(m->n_nodes, n_cells, &layout));
    double *state = profiles(m, layout, n_cells, two, d);
    sp_contacts c = {0};
    CHECK_OK(sp_contacts_integrate(m, layout, state, 0, m->n_nodes, &c));
    sp_cell_obs obs[2];
    CHECK_OK(sp_cells_observe(m, layout, state, 0.0, obs));
    if (n_cells == 2) {
      const double a = c.overlap[0];
      printf("two cells %g d apart: contact %.3e, %.3e of the smaller surface\n", disk_gap / d,
             a, a / fmin(c.surface[0], c.surface[1]));
      CHECK(sp_contacts_touch(&c, 0, 1, 0.01) == touching, "cells %g d apart: in contact %d",
            disk_gap / d, !touching);
    }
    const char *dir = "test_contacts_out";
    mkdir(dir, 0777);
    sp_contacts_log log = {0};
    CHECK_OK(sp_contacts_log_open(dir, -1, &log));
    CHECK_OK(sp_contacts_log_write(&log, 3, 0.5, &c, obs, 0.01));
    CHECK_OK(sp_contacts_log_close(&log));
    csv_table t;
    CHECK(csv_read("test_contacts_out/contacts.csv", &t) == 0, "contacts.csv unreadable");
    CHECK(strncmp(t.header, SP_CONTACTS_HEADER, strlen(SP_CONTACTS_HEADER)) == 0, "header %s",
          t.header);
    CHECK(t.n_rows == n_cells + touching, "%d cells: %d rows, not one per cell (and a pair row "
          "if touching)", n_cells, t.n_rows);
    if (touching && t.n_rows == 3) {
      CHECK(at(&t, 2, "cell") == 1 && at(&t, 2, "other") == 2 &&
                at(&t, 2, "contact") == c.overlap[0] && at(&t, 0, "contact") == c.overlap[0],
            "the pair row");
      t.n_rows = 2; /* the cell rows below */
    }
    for (int i = 0; i < t.n_rows && !touching; ++i) {
      CHECK(at(&t, i, "other") == 0 && at(&t, i, "cell") == i + 1, "row %d not a cell row", i);
      CHECK(at(&t, i, "contact") == 0, "row %d: contact %g", i, at(&t, i, "contact"));
      CHECK(at(&t, i, "free_surface") == at(&t, i, "surface"), "row %d: free != total", i);
      CHECK(at(&t, i, "volume") == obs[i].volume, "row %d: volume is not cells.csv's area", i);
    }
    free(t.v);
    free(state);
    sp_contacts_clear(&c);
    sp_layout_destroy(&layout);
  }
  sp_mesh_destroy(&m);
}

/** Two halves of the elements (by first node, the ranks' rule) add up to
 *  the whole; local supports covering both interfaces (+-0.3 about the
 *  cut, 30 d) give the full layout's contact. */
static void test_parts_and_supports(void) {
  const double d = 0.01;
  const distance_fn pair[2] = {plane_distance, plane_distance_other};
  film = 0;
  sp_mesh *m = unit_box(2, 80);
  sp_layout *full = NULL, *local = NULL;
  CHECK_OK(sp_layout_create_full(m->n_nodes, 2, &full));
  unsigned char *mask = calloc(2 * (size_t)m->n_nodes, 1);
  for (int i = 0; i < m->n_nodes; ++i) {
    const double s = plane_distance(m->xy + 2 * i, 2);
    mask[i] = s < 0.3;                  /* cell 0: its side and the band */
    mask[m->n_nodes + i] = s > -0.3;    /* cell 1 */
  }
  CHECK_OK(sp_layout_create_from_masks(m->n_nodes, 2, mask, &local));
  CHECK(local->n_pairs < full->n_pairs, "the local layout is not smaller");
  double *sf = profiles(m, full, 2, pair, d), *sl = profiles(m, local, 2, pair, d);
  sp_contacts whole = {0}, part = {0}, sum = {0}, loc = {0};
  CHECK_OK(sp_contacts_integrate(m, full, sf, 0, m->n_nodes, &whole));
  const int mid = m->n_nodes / 2;
  CHECK_OK(sp_contacts_integrate(m, full, sf, 0, mid, &sum));
  CHECK_OK(sp_contacts_integrate(m, full, sf, mid, m->n_nodes, &part));
  for (int k = 0; k < 2; ++k) sum.surface[k] += part.surface[k];
  sum.overlap[0] += part.overlap[0];
  CHECK(part.overlap[0] > 0.2 * whole.overlap[0], "the second half holds %.3g of %.3g",
        part.overlap[0], whole.overlap[0]);
  CHECK(fabs(sum.overlap[0] - whole.overlap[0]) <= 1e-13 * whole.overlap[0],
        "halves %.17g, whole %.17g", sum.overlap[0], whole.overlap[0]);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(sum.surface[k] - whole.surface[k]) <= 1e-13 * whole.surface[k],
          "surface %d: halves %.17g, whole %.17g", k, sum.surface[k], whole.surface[k]);
  CHECK_OK(sp_contacts_integrate(m, local, sl, 0, m->n_nodes, &loc));
  printf("local supports: contact %.12f, full %.12f\n", loc.overlap[0], whole.overlap[0]);
  CHECK(fabs(loc.overlap[0] - whole.overlap[0]) <= 1e-9 * whole.overlap[0],
        "local %.17g, full %.17g", loc.overlap[0], whole.overlap[0]);
  sp_contacts_clear(&whole);
  sp_contacts_clear(&part);
  sp_contacts_clear(&sum);
  sp_contacts_clear(&loc);
  free(sf);
  free(sl);
  free(mask);
  sp_layout_destroy(&full);
  sp_layout_destroy(&local);
  sp_mesh_destroy(&m);
}

int main(void) {
  const int n2[] = {40, 80, 160, 320}, n3[] = {16, 24, 32, 48};
  for (int gamma = 0; gamma <= 2; gamma += 2) {
    test_flat_contact(2, n2, 4, 0.02, gamma, 1e-3);
    test_flat_contact(3, n3, 4, 0.03, gamma, 1e-2);
  }
  test_round_cell(2, n2, 4, 0.02, 1e-3);
  test_round_cell(3, n3, 4, 0.04, 1e-2);
  test_lone_and_apart();
  test_parts_and_supports();
  TEST_DONE();
}
