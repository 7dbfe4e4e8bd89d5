/* What test_division and test_division_3d share: a cell's mass summed in
 * long double, and the equal-mass line (2D) or plane (3D) check
 * (division.line: equal_mass). */
#ifndef SP_TEST_DIVISION_FIXTURES_H
#define SP_TEST_DIVISION_FIXTURES_H
#include <math.h>
#include <stdio.h>

#include "model/cells.h"
#include "check.h"
#include "model/division.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

/** Mass of cell k = sum_i w_i c_k(i) (w_i the node weights), summed in
 *  long double: the same integral as sp_cells_observe's, but with a
 *  round-off far below the ~1e-13 of a plain double sum over 1e5
 *  quadrature points, so that it can show the split's own conservation. */
static inline double cell_mass(const sp_layout *layout, const double *state, const double *w,
                               int k) {
  long double sum = 0;
  for (int i = 0; i < layout->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, k, i);
    if (p >= 0) sum += (long double)w[i] * state[2 * p];
  }
  return (double)sum;
}

/**
 * Split cell 0 of @p state (one cell on @p layout; @p new_layout has two)
 * through the centre and on the equal-mass cut, and check: each split
 * keeps the total mass (@p mass_tolerance relative: the observables' sums),
 * the equal-mass daughters differ by at most @p allowed (relative to half
 * the total); an @p egg (an unequal parent) is split >= 3% unequal through
 * the centre and its cut moves by more than 0.1 h (less than 0.1), a
 * symmetric cell's smoothed cut by at most 1e-3 h. Prints a table row.
 * @p weight_threshold is the observables' (the stepper's 0.05).
 */
static inline void check_equal_mass_cut(const sp_mesh *mesh, const sp_layout *layout,
                                        const sp_layout *new_layout, const double *state,
                                        double *new_state, int egg, int smooth, double width,
                                        double weight_threshold, double mass_tolerance,
                                        double allowed) {
  const char *cut = mesh->dim == 3 ? "plane" : "line";
  sp_cell_obs before, after[2];
  CHECK_OK(sp_cells_observe(mesh, layout, state, weight_threshold, &before));
  double unequal[2], offset = 0;
  for (int balanced = 0; balanced <= 1; ++balanced) {
    if (balanced)
      CHECK_OK(sp_division_balance_offset(mesh, layout, state, 0, &before, smooth, width, 0.5,
                                          &offset));
    CHECK_OK(sp_division_split(mesh, layout, state, 0, &before, smooth, width,
                               balanced ? offset : 0.0, new_layout, new_state, 1));
    CHECK_OK(sp_cells_observe(mesh, new_layout, new_state, weight_threshold, after));
    const double total = after[0].mass + after[1].mass;
    CHECK(fabs(total - before.mass) <= mass_tolerance * before.mass,
          "egg %d smooth %d balanced %d: mass %.17g -> %.17g", egg, smooth, balanced,
          before.mass, total);
    unequal[balanced] = fabs(after[0].mass - after[1].mass) / (0.5 * total);
  }
  printf("  %-16s | %-6s | %+9.2e | %.2e | %.2e (%.1e)\n",
         egg ? "egg" : mesh->dim == 3 ? "ellipsoid" : "ellipse", smooth ? "smooth" : "sharp",
         offset, unequal[0], unequal[1], allowed);
  CHECK(unequal[1] <= allowed, "egg %d smooth %d: equal-mass daughters differ by %.3g "
        "(allowed %.1g)", egg, smooth, unequal[1], allowed);
  if (egg) {
    CHECK(unequal[0] >= 0.03, "egg smooth %d: the centre %s splits it %.3g: the test "
          "needs an unequal parent", smooth, cut, unequal[0]);
    CHECK(fabs(offset) > 0.1 * mesh->h && fabs(offset) < 0.1, "egg smooth %d: offset %g",
          smooth, offset);
  } else if (smooth) {
    CHECK(fabs(offset) <= 1e-3 * mesh->h, "symmetric cell: the %s moved by %g", cut, offset);
  }
}

#endif
