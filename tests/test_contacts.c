/* Contacts measured from the fields (src/model/contacts.h; docs/model.md,
 * "Contacts"), on the exact equilibrium profile c = 1 / (1 + e^(s/d))
 * interpolated on Q1 meshes of decreasing h (2D quadrilaterals, 3D
 * hexahedra; d fixed).
 *
 * The isosurface measure (the default; level theta = 0.01, so two flat
 * membranes switch off at a film of gamma_off = ln 99 = 4.595 d):
 * - two cells pressed flat across an oblique line (plane) through a box:
 *   the contact is the cut's length (area) within 5% at every mesh and
 *   converges at order 4 (asserted [3.0, 4.5]; measured 3.99 in 2D, 3.90
 *   in 3D between the two finest meshes, finest relative errors 2.5e-8 and
 *   4.9e-6), the free surfaces 0 to round-off; pressed round (a ball in
 *   its cavity), the sphere's measure to 3.4e-6 (2D) and 7.9e-4 (3D);
 * - two flat membranes a film of 1 to 4 d apart: the whole cut (1%);
 *   5, 6 and 8 d apart: exactly 0;
 * - two round cells (R = 12 d) 0 to 4 d apart: the caps of their membranes
 *   within gamma_off d of each other (exact geometry, 5%; 10% at 4 d);
 *   5, 6 and 10 d apart: exactly 0 and no pair row in contacts.csv;
 * - halves of the elements and local supports as below.
 *
 * The overlap measure:
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
 * Its expected order is 2. The measures integrate |grad I c| (and the
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

/** The level theta the isosurface tests use, and the film beyond which two
 *  flat membranes read no contact: c_l = 1 / (1 + e^gamma) at gamma d
 *  outside cell l's membrane, so gamma_off = ln((1 - theta) / theta). */
static const double level = 0.01;
static double switch_off(void) { return log((1 - level) / level); }

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

/** Contacts of the cells @p dist on a full layout of the mesh @p m by
 *  @p how (the isosurface measure at level @p level). */
static sp_contacts measure_on(sp_mesh *m, int n_cells, const distance_fn *dist, double d,
                              sp_contacts_measure how, double level) {
  sp_layout *layout = NULL;
  CHECK_OK(sp_layout_create_full(m->n_nodes, n_cells, &layout));
  double *state = profiles(m, layout, n_cells, dist, d);
  sp_contacts c = {0};
  CHECK_OK(sp_contacts_integrate(m, layout, state, 0, m->n_nodes, how, level, &c));
  free(state);
  sp_layout_destroy(&layout);
  return c;
}

/** The overlap measure's contacts of the cells @p dist on a full layout of
 *  the unit box in n^dim elements. */
static sp_contacts measure(int dim, int n, int n_cells, const distance_fn *dist, double d) {
  sp_mesh *m = unit_box(dim, n);
  sp_contacts c = measure_on(m, n_cells, dist, d, SP_CONTACTS_OVERLAP, 0);
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
    CHECK_OK(sp_contacts_integrate(m, layout, state, 0, m->n_nodes, SP_CONTACTS_OVERLAP, 0, &c));
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
static void test_parts_and_supports(sp_contacts_measure how) {
  const double d = 0.01;
  const distance_fn pair[2] = {plane_distance, plane_distance_other};
  film = 0;
  sp_mesh *m = unit_box(2, 80);
  printf("%s measure:\n", how == SP_CONTACTS_OVERLAP ? "overlap" : "isosurface");
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
  CHECK_OK(sp_contacts_integrate(m, full, sf, 0, m->n_nodes, how, level, &whole));
  const int mid = m->n_nodes / 2;
  CHECK_OK(sp_contacts_integrate(m, full, sf, 0, mid, how, level, &sum));
  CHECK_OK(sp_contacts_integrate(m, full, sf, mid, m->n_nodes, how, level, &part));
  for (int k = 0; k < 2; ++k) sum.surface[k] += part.surface[k];
  sum.overlap[0] += part.overlap[0];
  CHECK(part.overlap[0] > 0.2 * whole.overlap[0], "the second half holds %.3g of %.3g",
        part.overlap[0], whole.overlap[0]);
  CHECK(fabs(sum.overlap[0] - whole.overlap[0]) <= 1e-13 * whole.overlap[0],
        "halves %.17g, whole %.17g", sum.overlap[0], whole.overlap[0]);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(sum.surface[k] - whole.surface[k]) <= 1e-13 * whole.surface[k],
          "surface %d: halves %.17g, whole %.17g", k, sum.surface[k], whole.surface[k]);
  CHECK_OK(sp_contacts_integrate(m, local, sl, 0, m->n_nodes, how, level, &loc));
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

/* ---- the isosurface measure ---- */

/* A round cell of radius inner_r about the corner and its complement: a
 * cell holding it in a round cavity. */
static const double inner_r = 0.3;
static double inner_distance(const double *x, int dim) {
  double r2 = 0;
  for (int i = 0; i < dim; ++i) r2 += x[i] * x[i];
  return sqrt(r2) - inner_r;
}
static double cavity_distance(const double *x, int dim) { return -inner_distance(x, dim); }

/** Two cells pressed against each other (c_l = 1 - c_k at the nodes): the
 *  other field is 1/2 on each membrane, so the contact is the membrane's
 *  measure and each free surface 0. @p round 0: across the oblique line
 *  (plane) through the unit box, the contact is the cut's length (area);
 *  1: the round cell in its cavity (a quarter circle, an octant of a
 *  sphere), 2 pi R / 4 or 4 pi R^2 / 8. The orders asserted: 2 for the
 *  round membrane (the interpolant's membrane is a polygon (polyhedron) of
 *  edges h cutting the circle (sphere): O(h^2)); 4 for the flat one, where
 *  the profile's inflection at c = 1/2 removes the O(h^2) term (the linear
 *  interpolant's root on an element edge is off by h^2 c'' / (8 c') with
 *  c'' = O(h) within the edge of the root, and its mean displacement
 *  cancels between edges). */
static void test_iso_pressed(int dim, const int *n, int levels, double d, int round) {
  const distance_fn flat[2] = {plane_distance, plane_distance_other},
                    curved[2] = {inner_distance, cavity_distance};
  const double cut = sqrt(1 + slope(dim, 0) * slope(dim, 0) + slope(dim, 1) * slope(dim, 1));
  const double exact = !round ? cut
                       : dim == 2 ? 2 * M_PI * inner_r / 4
                                  : 4 * M_PI * inner_r * inner_r / 8;
  film = 0;
  double contact[8];
  for (int i = 0; i < levels; ++i) {
    sp_mesh *m = unit_box(dim, n[i]);
    sp_contacts c = measure_on(m, 2, round ? curved : flat, d, SP_CONTACTS_ISOSURFACE, level);
    contact[i] = c.overlap[0];
    CHECK(fabs(contact[i] / exact - 1) <= 0.05, "n = %d: contact %.6f, not %.6f within 5%%",
          n[i], contact[i], exact);
    double total, free_surface;
    sp_contacts_of_cell(&c, 0, 0.01, &total, &free_surface);
    CHECK(fabs(free_surface) <= 1e-12 * exact &&
              fabs(c.surface[0] - c.surface[1]) <= 1e-12 * exact,
          "n = %d: free surface %.3e, surfaces %.17g and %.17g", n[i], free_surface,
          c.surface[0], c.surface[1]);
    sp_contacts_clear(&c);
    sp_mesh_destroy(&m);
  }
  char what[64];
  snprintf(what, sizeof what, "%dD isosurface, pressed %s", dim, round ? "round" : "flat");

  if (!round) {
    check_order(what, n, contact, levels, exact, 3.0, 4.5, dim == 2 ? 1e-6 : 1e-4);
    return;
  }
  /* round: the chord's deficit and the profile's interpolation error are
   * both O(h^2) and of opposite signs; their sum falls below 1e-5 (2D) and
   * 3e-3 (3D) but with no steady order on these meshes, so only its size
   * is asserted */
  for (int i = 0; i < levels; ++i)
    printf("%s: n = %3d  value %.10f  exact %.10f  relative error %+.3e\n", what, n[i],
           contact[i], exact, contact[i] / exact - 1);
  const double finest = fabs(contact[levels - 1] / exact - 1);
  CHECK(finest <= (dim == 2 ? 1e-5 : 3e-3), "%s: finest relative error %.3e", what, finest);
}

/** Two flat membranes a film of gamma d apart: the whole cut is in contact
 *  while gamma < gamma_off (the other field >= theta all along it), none
 *  beyond, exactly (no pair row). */
static void test_iso_film(int dim, int n, double d) {
  const distance_fn pair[2] = {plane_distance, plane_distance_other};
  const double cut = sqrt(1 + slope(dim, 0) * slope(dim, 0) + slope(dim, 1) * slope(dim, 1));
  const double gammas[] = {1, 2, 3, 4, 5, 6, 8};
  sp_mesh *m = unit_box(dim, n);
  for (size_t i = 0; i < sizeof gammas / sizeof gammas[0]; ++i) {
    film = gammas[i] * d;
    sp_contacts c = measure_on(m, 2, pair, d, SP_CONTACTS_ISOSURFACE, level);
    const double a = c.overlap[0];
    printf("%dD isosurface, film %g d (off from %.3f d): contact %.6f of the cut %.6f\n", dim,
           gammas[i], switch_off(), a, cut);
    if (gammas[i] < switch_off()) {
      CHECK(fabs(a / cut - 1) <= 0.01, "film %g d: contact %.6f, not the cut %.6f", gammas[i],
            a, cut);
      CHECK(sp_contacts_touch(&c, 0, 1, 0.01), "film %g d: not in contact", gammas[i]);
    } else {
      CHECK(a == 0 && !sp_contacts_touch(&c, 0, 1, 0), "film %g d: contact %.3e, not 0",
            gammas[i], a);
    }
    sp_contacts_clear(&c);
  }
  sp_mesh_destroy(&m);
}

/* Two round cells (discs, balls) of radius round_r on the last axis of a
 * box [0, 0.4]^(dim-1) x [0, 1] (the walls through the axis are symmetry
 * planes: the box holds half of each disc, a quarter of each ball), their
 * membranes round_gap apart about z = 1/2. */
static const double round_r = 0.18;
static double round_gap;
static double round_distance(const double *x, int dim, double z0) {
  double r2 = (x[dim - 1] - z0) * (x[dim - 1] - z0);
  for (int i = 0; i < dim - 1; ++i) r2 += x[i] * x[i];
  return sqrt(r2) - round_r;
}
static double round_below(const double *x, int dim) {
  return round_distance(x, dim, 0.5 - round_r - round_gap / 2);
}
static double round_above(const double *x, int dim) {
  return round_distance(x, dim, 0.5 + round_r + round_gap / 2);
}

/** The exact contact of two round cells of radius R whose membranes are g
 *  apart, in the box (half a disc, a quarter of a ball): the cap of each
 *  membrane within gamma_off d of the other's, where the other's profile is
 *  >= theta. With C = 2 R + g between the centres, the cap's edge lies at
 *  angle phi from the axis, cos phi = (R^2 + C^2 - (R + gamma_off d)^2) /
 *  (2 R C); its measure is 2 R phi (2D) or 2 pi R^2 (1 - cos phi) (3D). */
static double round_contact_exact(int dim, double g, double d) {
  const double R = round_r, C = 2 * R + g, reach = R + switch_off() * d;
  const double cos_phi = (R * R + C * C - reach * reach) / (2 * R * C);
  if (cos_phi >= 1) return 0;
  return dim == 2 ? 2 * R * acos(cos_phi) / 2 : 2 * M_PI * R * R * (1 - cos_phi) / 4;
}

/** Round cells: tangent and a few d apart they read the cap within a
 *  gamma_off d film of each other (exact above, to the discretisation);
 *  further apart than gamma_off d exactly 0: no pair row in contacts.csv. */
static void test_iso_round_pair(int dim) {
  const double d = 0.015, gaps[] = {0, 2, 3, 4, 5, 6, 10};
  const int nx = 32, nz = 80; /* h = 0.0125 */
  sp_mesh *m = NULL;
  if (dim == 2) CHECK_OK(sp_mesh_rectangle(0, 0, 0.4, 1, nx, nz, &m));
  else CHECK_OK(sp_mesh_box(0, 0, 0, 0.4, 0.4, 1, nx, nx, nz, &m));
  const distance_fn two[2] = {round_below, round_above};
  const double membrane = dim == 2 ? M_PI * round_r : M_PI * round_r * round_r;
  for (size_t i = 0; i < sizeof gaps / sizeof gaps[0]; ++i) {
    round_gap = gaps[i] * d;
    sp_contacts c = measure_on(m, 2, two, d, SP_CONTACTS_ISOSURFACE, level);
    const double a = c.overlap[0], exact = round_contact_exact(dim, round_gap, d);
    printf("%dD isosurface, round cells %g d apart: contact %.6f, exact %.6f (%.4f of the "
           "membrane; its measure %.6f, exact %.6f)\n", dim, gaps[i], a, exact, exact / membrane,
           c.surface[0], membrane);
    CHECK(fabs(c.surface[0] / membrane - 1) <= 0.01, "membrane %.6f, not %.6f", c.surface[0],
          membrane);
    if (gaps[i] < switch_off()) {
      /* 4 d apart the cap's edge lies where c_l is 0.01, whose interpolant
       * is (h/d)^2 / 8 = 9% high (the tail's c'' = c / d^2): 10% */
      const double tol = gaps[i] < 4 ? 0.05 : 0.10;
      CHECK(fabs(a / exact - 1) <= tol, "%g d apart: contact %.6f, not %.6f within %g",
            gaps[i], a, exact, tol);
      sp_contacts_clear(&c);
      continue;
    }
    CHECK(a == 0, "%g d apart: contact %.3e, not 0", gaps[i], a);
    /* contacts.csv: two cell rows, no pair row (whatever the threshold) */
    sp_cell_obs obs[2];
    memset(obs, 0, sizeof obs);
    const char *dir = "test_contacts_iso_out";
    mkdir(dir, 0777);
    sp_contacts_log log = {0};
    CHECK_OK(sp_contacts_log_open(dir, -1, &log));
    CHECK_OK(sp_contacts_log_write(&log, 1, 0.0, &c, obs, 0.0));
    CHECK_OK(sp_contacts_log_close(&log));
    csv_table t;
    CHECK(csv_read("test_contacts_iso_out/contacts.csv", &t) == 0, "contacts.csv unreadable");
    CHECK(t.n_rows == 2 && at(&t, 0, "other") == 0 && at(&t, 1, "other") == 0 &&
              at(&t, 0, "contact") == 0,
          "%g d apart: %d rows, not the two cell rows", gaps[i], t.n_rows);
    free(t.v);
    sp_contacts_clear(&c);
  }
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
  test_parts_and_supports(SP_CONTACTS_OVERLAP);
  test_parts_and_supports(SP_CONTACTS_ISOSURFACE);
  for (int dim = 2; dim <= 3; ++dim) {
    test_iso_pressed(dim, dim == 2 ? n2 : n3, 4, dim == 2 ? 0.02 : 0.03, 0);
    test_iso_pressed(dim, dim == 2 ? n2 : n3, 4, dim == 2 ? 0.02 : 0.04, 1);
    test_iso_film(dim, dim == 2 ? 80 : 32, dim == 2 ? 0.02 : 0.03);
    test_iso_round_pair(dim);
  }
  TEST_DONE();
}
