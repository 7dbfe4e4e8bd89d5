/* Local supports:
 * - local and full supports agree on a short scene (10 steps): energy to
 *   1e-5 relative with a margin of 40 interface widths (measured 7e-7),
 *   1e-3 with 20 widths (measured 5e-4): the cut far field of each field
 *   (its Gibbs-Thomson level) is what differs, not the interface, so the
 *   issue's 1e-8 is not reached with round cells (flat ones, which keep
 *   no far field, reach it: tests/test_local_exact.c); cell masses to
 *   1e-9 and centres to 1e-7 with 40 widths;
 * - a cell pushed across the mesh keeps its mass to 1e-10 across support
 *   changes (which do happen), and the mass the changes drop in all (the
 *   run's total, like the division run's below) stays below 1e-10;
 * - supports reaching the domain boundary and the buffer ring behave: each
 *   cell's mass is kept to 1e-10 at every step, and the energy law of
 *   backward Euler holds at every step (no rise beyond round-off, except
 *   the rise a support change itself reports), with the buffer ring's
 *   elements by the margin (the scene's) and taken whole (the default,
 *   which needs fewer changes there);
 * - after a division the children's supports cover the children; the
 *   run's first step solves on the local layout sp_run_setup builds for
 *   the scene (scene_fixture.h). */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "scene/scene.h"
#include "run/stepper.h"
#include "model/support.h"
#include "model/cells.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "output_read.h"
#include "scene_fixture.h"

/* The solutions are compared through cells.csv and energy.csv
 * (output_read.h), not the nodal fields. */

/** Mass and centre of cells 1..n_cells at @p step of cells.csv (step < 0:
 *  the last step); returns the number of rows read. */
static int cells_at_step(const char *path, int step, int n_cells, double *mass, double *xc,
                         double *yc) {
  csv_table t;
  int rows = 0;
  if (csv_read(path, &t) == 0 && t.n_rows > 0) {
    if (step < 0) step = (int)at(&t, t.n_rows - 1, "step");
    for (int i = 0; i < t.n_rows; ++i) {
      const int cell = (int)at(&t, i, "cell");
      if ((int)at(&t, i, "step") != step || cell < 1 || cell > n_cells) continue;
      mass[cell - 1] = at(&t, i, "mass");
      xc[cell - 1] = at(&t, i, "xc");
      yc[cell - 1] = at(&t, i, "yc");
      ++rows;
    }
  }
  free(t.v);
  return rows;
}

/** The last energy of energy.csv (NAN if unreadable), the first in *first. */
static double first_and_last_energy(const char *path, double *first) {
  csv_table t;
  double e = NAN;
  if (csv_read(path, &t) == 0 && t.n_rows > 0) {
    *first = at(&t, 0, "energy");
    e = at(&t, t.n_rows - 1, "energy");
  }
  free(t.v);
  return e;
}

/* The edge scene (backward Euler, no source, no shape term, no division):
 * - mass: every cell's mass at every step of cells.csv equals its first to
 *   1e-10 relative (each step conserves it to round-off, 1e-12 per step
 *   asserted by test_conservation; a support change restores what it cut,
 *   and the run summary's dropped mass is below 1e-10);
 * - energy: a step minimises the energy plus the H^-1 distance to its
 *   start (docs/model.md), so energy.csv never rises from one row to the
 *   next beyond round-off (1e-13 relative, as test_energy), except on a row
 *   whose step changed the supports: its energy is logged after the change,
 *   which may raise it by at most the run's largest reported rise. */
static void check_edge_laws(const char *dir, const sp_run_summary *sum) {
  char path[256];
  csv_table cells, energy;
  snprintf(path, sizeof path, "%s/cells.csv", dir);
  CHECK(csv_read(path, &cells) == 0 && cells.n_rows > 0, "%s", path);
  snprintf(path, sizeof path, "%s/energy.csv", dir);
  CHECK(csv_read(path, &energy) == 0 && energy.n_rows > 1, "%s", path);
  if (sp_test_failures) return;
  double first_mass[2] = {NAN, NAN}, worst_mass = 0;
  int steps_seen = 0;
  for (int i = 0; i < cells.n_rows; ++i) {
    const int cell = (int)at(&cells, i, "cell");
    CHECK(cell == 1 || cell == 2, "row %d: cell %d (no division expected)", i, cell);
    if (cell != 1 && cell != 2) continue;
    const double m = at(&cells, i, "mass");
    if (isnan(first_mass[cell - 1])) first_mass[cell - 1] = m;
    worst_mass = fmax(worst_mass, fabs(m / first_mass[cell - 1] - 1));
    steps_seen += cell == 1;
  }
  int rises = 0, changes = 0;
  double worst_rise = 0;
  for (int i = 1; i < energy.n_rows; ++i) {
    const double e0 = at(&energy, i - 1, "energy"), e1 = at(&energy, i, "energy");
    const int changed = at(&energy, i, "support_changed") == 1;
    changes += changed;
    const double allowed = (changed ? sum->support_energy_rise : 0.0) + 1e-13;
    if (e1 > e0 + allowed * fabs(e0)) ++rises;
    if (!changed) worst_rise = fmax(worst_rise, (e1 - e0) / fabs(e0));
  }
  printf("edge scene laws: %d steps in cells.csv, largest relative mass change %.2e; energy: "
         "%d rows, %d with a support change (reported rise at most %.2e), largest rise on the "
         "others %.2e, %d rows break the law\n", steps_seen, worst_mass, energy.n_rows, changes,
         sum->support_energy_rise, worst_rise, rises);
  CHECK(steps_seen == sum->steps + 1, "cells.csv has %d steps of %d", steps_seen,
        sum->steps + 1);
  CHECK(worst_mass <= 1e-10, "a cell's mass changed by %.3g relative", worst_mass);
  CHECK(changes == sum->layout_changes, "energy.csv marks %d support changes, the run %d",
        changes, sum->layout_changes);
  CHECK(rises == 0, "the energy rose beyond the law on %d rows", rises);
  free(cells.v);
  free(energy.v);
}

static sp_run_summary run(const char *scene_file, int n_set, const char **set, const char *out) {
  sp_scene *scene;
  sp_run_summary sum = {0};
  char path[1024];
  snprintf(path, sizeof path, "%s/tests/scenes/%s", SP_SOURCE_DIR, scene_file);
  CHECK_OK(sp_scene_load(path, n_set, set, &scene));
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  sp_scene_destroy(&scene);
  return sum;
}

/** The rebuild scene of the two tests below: cell 0 (a tanh disk with a
 *  far field c_e = 0.02) on a support of 3 widths, cell 1 everywhere, mu =
 *  0.1 throughout; rebuilt with a margin of 10 widths (no cell may shrink)
 *  by @p fill. */
typedef struct {
  sp_mesh *mesh;
  sp_layout *full, *layout, *grown;
  sp_support s_narrow, s_wide;
  double *state, *st, *next, correction, dropped;
  unsigned char *mask;
} rebuild_case;

static const double rb_cx[2] = {0.40, 0.63}, rb_r[2] = {0.12, 0.10}, rb_c_e = 0.02,
                    rb_mu = 0.1, rb_kappa = 1e-3, rb_alpha = 4, rb_lambda = 100;

static void rebuild_setup(sp_support_fill_kind fill, sp_support_restore_kind restore, double mu,
                          rebuild_case *rc) {
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 0.6, 80, 48, &rc->mesh));
  const int nn = rc->mesh->n_nodes;
  const double d = sqrt(rb_kappa / (2 * rb_alpha));
  CHECK_OK(sp_layout_create_full(nn, 2, &rc->full));
  rc->state = calloc(2 * (size_t)rc->full->n_pairs, sizeof(double));
  for (int i = 0; i < nn; ++i)
    for (int k = 0; k < 2; ++k) {
      const double dist =
          hypot(rc->mesh->xy[2 * i] - rb_cx[k], rc->mesh->xy[2 * i + 1] - 0.3) - rb_r[k];
      const double p = 1.0 / (1.0 + exp(dist / d));
      rc->state[2 * sp_layout_pair(rc->full, k, i)] = p + (1 - p) * (k == 0 ? rb_c_e : 0.0);
      rc->state[2 * sp_layout_pair(rc->full, k, i) + 1] = mu;
    }
  sp_support_params narrow = {.margin = 3 * d, .core_threshold = 0.1, .grow_threshold = 0.1,
                              .band = 2 * d, .alpha = rb_alpha, .kappa = rb_kappa,
                              .lambda = rb_lambda, .lambda_b = 0, .fill = fill,
                              .restore = restore};
  sp_support_params wide = narrow;
  wide.margin = 10 * d;
  CHECK_OK(sp_support_create(rc->mesh, &narrow, &rc->s_narrow));
  CHECK_OK(sp_support_create(rc->mesh, &wide, &rc->s_wide));
  rc->mask = calloc((size_t)nn * 2, 1);
  CHECK_OK(sp_support_masks(rc->s_narrow, rc->full, rc->state, rc->mask));
  for (int i = 0; i < nn; ++i) rc->mask[nn + i] = 1; /* cell 1 everywhere */
  CHECK_OK(sp_support_layout_from_masks(rc->s_narrow, 2, rc->mask, &rc->layout));
  rc->st = calloc(2 * (size_t)rc->layout->n_pairs, sizeof(double));
  sp_layout_transfer(rc->full, rc->state, rc->layout, rc->st, 0.0);
  const unsigned char keep[2] = {0, 0};
  CHECK_OK(sp_support_rebuild(rc->s_wide, rc->layout, rc->st, keep, &rc->grown, &rc->next,
                              &rc->correction, &rc->dropped));
}

static void rebuild_free(rebuild_case *rc) {
  free(rc->state); free(rc->st); free(rc->next); free(rc->mask);
  sp_layout_destroy(&rc->full); sp_layout_destroy(&rc->layout); sp_layout_destroy(&rc->grown);
  sp_support_destroy(&rc->s_narrow); sp_support_destroy(&rc->s_wide);
  sp_mesh_destroy(&rc->mesh);
}

/* sp_support_rebuild on its own: cell 0 (a disk with a far field c_e =
 * 0.02) on a support of 3 interface widths grows to 10 widths, into its
 * neighbour cell 1. Checked: with may_shrink = 0 every old node is kept;
 * the masses are kept to round-off; the nodes already in the support keep
 * their values except in the interior (c >= 1/2), which alone takes the
 * mass correction; new nodes where the cell is alone all get the old
 * edge's mean c, new nodes inside the neighbour (c_1 > 0.9) at most that x
 * 2 alpha / (2 alpha + 2 lambda 0.81) ~ 1/21. The one-pass pair weights
 * the rebuild uses equal each cell's node weights exactly. */
static void test_rebuild_growth(void) {
  rebuild_case rc;
  rebuild_setup(SP_SUPPORT_FILL_EDGE, SP_SUPPORT_RESTORE_INTERIOR, rb_mu, &rc);
  const sp_mesh *mesh = rc.mesh;
  const int nn = mesh->n_nodes;
  const double c_e = rb_c_e, alpha = rb_alpha, lambda = rb_lambda;
  const sp_layout *full = rc.full, *layout = rc.layout, *grown = rc.grown;
  const double *state = rc.state, *st = rc.st, *next = rc.next, correction = rc.correction,
               dropped = rc.dropped;
  printf("rebuild: total mass dropped %.2e (relative)\n", dropped);
  CHECK(dropped <= 1e-13, "the rebuild dropped %.3e of the mass", dropped);
  sp_cell_obs before[2], after[2];
  CHECK_OK(sp_cells_observe(mesh, layout, st, 0.0, before));
  CHECK_OK(sp_cells_observe(mesh, grown, next, 0.0, after));
  int lost = 0, changed_outside = 0, n_new_alone = 0, n_new_inside = 0, n_old = 0, n_new = 0;
  double shift = 0, worst_alone = 0, worst_inside = 0, c_alone = 0;
  for (int i = 0; i < nn; ++i) {
    const int p_old = sp_layout_pair(layout, 0, i), p_new = sp_layout_pair(grown, 0, i);
    if (p_old >= 0 && p_new < 0) ++lost;
    n_old += p_old >= 0;
    n_new += p_new >= 0;
    if (p_new < 0) continue;
    const double c = next[2 * p_new];
    if (p_old >= 0) {
      const double c_old = st[2 * p_old];
      if (c_old < 0.5 && c != c_old) ++changed_outside;
      if (c_old >= 0.5) shift = c - c_old;
      continue;
    }
    const double c1 = state[2 * sp_layout_pair(full, 1, i)];
    if (c1 < 1e-3) {
      if (n_new_alone++ == 0) c_alone = c;
      worst_alone = fmax(worst_alone, fabs(c - c_alone));
    } else if (c1 > 0.9) {
      ++n_new_inside;
      worst_inside = fmax(worst_inside, c);
    }
  }
  worst_inside /= c_alone;
  printf("rebuild: %d -> %d pairs of cell 0; new nodes alone %d (c = %.4f = %.2f c_e, spread "
         "%.1e), inside the neighbour %d (c <= %.3f of that); interior shift %.2e; mass %.17g -> "
         "%.17g (correction %.2e)\n", n_old, n_new, n_new_alone, c_alone, c_alone / c_e,
         worst_alone, n_new_inside, worst_inside, shift,
         before[0].mass, after[0].mass, correction);
  CHECK(lost == 0, "%d nodes of a support that may not shrink were dropped", lost);
  CHECK(changed_outside == 0, "%d nodes outside the interior changed", changed_outside);
  CHECK(n_new_alone > 0 && n_new_inside > 0, "the growth must reach both kinds of node "
        "(%d alone, %d inside)", n_new_alone, n_new_inside);
  /* away from the neighbour: the old edge's mean c, the same at every new
   * node but for the 1e-3 of the neighbour nearby (with a 3-width support
   * the tanh tail still adds to c_e there) */
  CHECK(worst_alone <= 1e-4 * c_alone && c_alone > c_e && c_alone < 5 * c_e,
        "new nodes away from the neighbour: c = %.4g (c_e %.3g), spread %.3g", c_alone, c_e,
        worst_alone);
  CHECK(worst_inside <= 2 * alpha / (2 * alpha + 2 * lambda * 0.81),
        "new nodes inside the neighbour: c up to %.3g x the free far field", worst_inside);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(after[k].mass - before[k].mass) <= 1e-13 * before[k].mass,
          "cell %d mass %.17g -> %.17g", k + 1, before[k].mass, after[k].mass);
  /* the rebuild's one-pass pair weights are each cell's node weights, and
   * sum_p w_p c_p is the cell's mass */
  double *w_pair = malloc(sizeof(double) * (size_t)grown->n_pairs);
  double *w_node = malloc(sizeof(double) * (size_t)nn);
  CHECK_OK(sp_cells_pair_weights(mesh, grown, w_pair));
  int weights_differ = 0;
  for (int k = 0; k < 2; ++k) {
    CHECK_OK(sp_cells_node_weights(mesh, grown, k, w_node));
    double mass = 0;
    for (int i = 0; i < nn; ++i) {
      const int p = sp_layout_pair(grown, k, i);
      weights_differ += p >= 0 ? w_pair[p] != w_node[i] : w_node[i] != 0.0;
      if (p >= 0) mass += w_pair[p] * next[2 * p];
    }
    CHECK(fabs(mass - after[k].mass) <= 1e-13 * after[k].mass,
          "cell %d: sum w c = %.17g, mass %.17g", k + 1, mass, after[k].mass);
  }
  CHECK(weights_differ == 0, "%d pair weights differ from the cells' node weights",
        weights_differ);
  free(w_pair); free(w_node);
  rebuild_free(&rc);
}

/* The same growth with layout.fill = relax (far_field.h): masses kept to
 * round-off; new nodes where cell 0 is alone, 9 or more interface widths
 * from its centre line (4 beyond the old edge), sit at the far field in
 * equilibrium with the free edge's mu (0.1 everywhere here): the lower
 * root of f'(c) = mu, to 5% (the tail's exp(-4) remnant); new nodes
 * inside the neighbour stay below that (held down by the repulsion). */
static void test_rebuild_relax(void) {
  rebuild_case rc;
  rebuild_setup(SP_SUPPORT_FILL_RELAX, SP_SUPPORT_RESTORE_INTERIOR, rb_mu, &rc);
  const sp_mesh *mesh = rc.mesh;
  const int nn = mesh->n_nodes;
  const double alpha = rb_alpha, mu = rb_mu, d = sqrt(rb_kappa / (2 * rb_alpha));
  const double *cx = rb_cx, *r = rb_r, *state = rc.state, *next = rc.next, dropped = rc.dropped;
  const sp_layout *full = rc.full, *layout = rc.layout, *grown = rc.grown;
  const double *st = rc.st;
  double c_ff = 0; /* the lower root of 2 alpha c (c - 1) (2 c - 1) = mu */
  for (int it = 0; it < 50; ++it)
    c_ff -= (2 * alpha * c_ff * (c_ff - 1) * (2 * c_ff - 1) - mu) /
            (2 * alpha * (6 * c_ff * c_ff - 6 * c_ff + 1));
  sp_cell_obs before[2], after[2];
  CHECK_OK(sp_cells_observe(mesh, layout, st, 0.0, before));
  CHECK_OK(sp_cells_observe(mesh, grown, next, 0.0, after));
  int n_far = 0, n_inside = 0;
  double worst_far = 0, worst_inside = 0;
  for (int i = 0; i < nn; ++i) {
    const int p_new = sp_layout_pair(grown, 0, i);
    if (p_new < 0 || sp_layout_pair(layout, 0, i) >= 0) continue;
    const double c = next[2 * p_new], c1 = state[2 * sp_layout_pair(full, 1, i)];
    const double dist = hypot(mesh->xy[2 * i] - cx[0], mesh->xy[2 * i + 1] - 0.3) - r[0];
    if (c1 < 1e-3 && dist >= 9 * d) {
      ++n_far;
      worst_far = fmax(worst_far, fabs(c - c_ff) / c_ff);
    } else if (c1 > 0.9) {
      ++n_inside;
      worst_inside = fmax(worst_inside, c);
    }
  }
  printf("rebuild (relax): far field c_ff = %.5f; %d new nodes far from the edge within %.2e "
         "of it (relative), %d inside the neighbour at most %.2e; dropped %.1e\n", c_ff, n_far,
         worst_far, n_inside, worst_inside, dropped);
  CHECK(n_far > 0 && n_inside > 0, "the growth must reach both kinds of node (%d, %d)", n_far,
        n_inside);
  CHECK(worst_far <= 0.05, "new nodes far from the edge: %.3g from the far field", worst_far);
  CHECK(worst_inside < c_ff, "new nodes inside the neighbour up to %.3g (c_ff %.3g)",
        worst_inside, c_ff);
  CHECK(dropped <= 1e-13, "the rebuild dropped %.3e of the mass", dropped);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(after[k].mass - before[k].mass) <= 1e-13 * before[k].mass,
          "cell %d mass %.17g -> %.17g", k + 1, before[k].mass, after[k].mass);
  rebuild_free(&rc);
}

/* The relaxed fill where the far field has no stable state: with mu = 1
 * on cell 0's edge (above 2 alpha c (c - 1) (2 c - 1)'s largest value on
 * the lower branch, 0.77 at the spinodal c = 0.211) the relaxation would
 * hold every new pair at the spinodal, where a uniform state is unstable
 * (a second piece of the cell grows there) and which over the new area is
 * many times the cell's mass. The cell keeps the edge rule's values: the
 * rebuild equals the edge rule's value for value, its new pairs below the
 * spinodal, and the masses are kept. */
static void test_rebuild_relax_unstable(void) {
  rebuild_case relax, edge;
  rebuild_setup(SP_SUPPORT_FILL_RELAX, SP_SUPPORT_RESTORE_INTERIOR, 1.0, &relax);
  rebuild_setup(SP_SUPPORT_FILL_EDGE, SP_SUPPORT_RESTORE_INTERIOR, 1.0, &edge);
  CHECK(relax.grown->n_pairs == edge.grown->n_pairs, "layouts differ: %d vs %d pairs",
        relax.grown->n_pairs, edge.grown->n_pairs);
  int n_new = 0;
  double largest = 0, differ = 0;
  for (int i = 0; i < relax.mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(relax.grown, 0, i);
    if (p < 0 || sp_layout_pair(relax.layout, 0, i) >= 0) continue;
    ++n_new;
    largest = fmax(largest, relax.next[2 * p]);
  }
  for (int q = 0; q < 2 * relax.grown->n_pairs; ++q)
    differ = fmax(differ, fabs(relax.next[q] - edge.next[q]));
  printf("rebuild (relax, mu = 1): %d new pairs, largest c %.4f, largest difference from the "
         "edge rule %.1e, mass correction %.3e (edge rule %.3e)\n", n_new, largest, differ,
         relax.correction, edge.correction);
  CHECK(n_new > 0, "cell 0's support did not grow");
  CHECK(largest < 0.211, "a new pair at c = %.4f, at or above the spinodal", largest);
  CHECK(differ == 0, "the fill differs from the edge rule's by %.3e", differ);
  CHECK(relax.dropped <= 1e-13, "the rebuild dropped %.3e of the mass", relax.dropped);
  rebuild_free(&relax);
  rebuild_free(&edge);
}

/** The free share of cell 0 at a node where cell 1 has c1 (no buffer
 *  ring): 2 alpha / (2 alpha + 2 lambda c1^2), restore_profile's rule. */
static double rb_free_share(double c1) {
  return 2 * rb_alpha / (2 * rb_alpha + 2 * rb_lambda * c1 * c1);
}

/* The same growth with layout.restore = potential (support.c,
 * restore_profile): the mass the fill added comes back as one shift of
 * cell 0's chemical potential, each value moving by delta x 2 alpha /
 * (2 alpha + 2 lambda c_1^2) (no buffer ring here), over the whole
 * support: checked value by value against the fill (sp_support_fill) to
 * 1e-12 of delta, with delta < 0 (the fill added far-field mass). Cell 1
 * (support unchanged, mass unchanged) keeps its values; the masses are
 * kept to round-off. The shift is spread: its largest value is below the
 * interior rule's uniform shift of the same growth, which steps at the 1/2
 * level set. */
static void test_rebuild_potential(void) {
  rebuild_case pot, inter;
  rebuild_setup(SP_SUPPORT_FILL_EDGE, SP_SUPPORT_RESTORE_POTENTIAL, rb_mu, &pot);
  rebuild_setup(SP_SUPPORT_FILL_EDGE, SP_SUPPORT_RESTORE_INTERIOR, rb_mu, &inter);
  const sp_layout *grown = pot.grown;
  CHECK(grown->n_pairs == inter.grown->n_pairs, "layouts differ: %d vs %d pairs",
        grown->n_pairs, inter.grown->n_pairs);
  double *fill = malloc(sizeof(double) * 2 * (size_t)grown->n_pairs);
  CHECK_OK(sp_support_fill(pot.s_wide, pot.layout, pot.st, grown, fill));
  /* delta from the freest pair of cell 0, then every pair against it */
  double delta = 0, best_share = 0, worst = 0, cell1 = 0, largest = 0, largest_inter = 0;
  int n0 = 0;
  for (int i = 0; i < pot.mesh->n_nodes; ++i) {
    const int q = sp_layout_pair(grown, 0, i), q1 = sp_layout_pair(grown, 1, i);
    if (q < 0) continue;
    const double share = rb_free_share(fill[2 * q1]);
    if (share > best_share) {
      best_share = share;
      delta = (pot.next[2 * q] - fill[2 * q]) / share;
    }
  }
  for (int i = 0; i < pot.mesh->n_nodes; ++i) {
    const int q = sp_layout_pair(grown, 0, i), q1 = sp_layout_pair(grown, 1, i);
    cell1 = fmax(cell1, fabs(pot.next[2 * q1] - fill[2 * q1]));
    if (q < 0) continue;
    ++n0;
    const double share = rb_free_share(fill[2 * q1]);
    worst = fmax(worst, fabs(pot.next[2 * q] - fill[2 * q] - delta * share));
    largest = fmax(largest, fabs(pot.next[2 * q] - fill[2 * q]));
    largest_inter = fmax(largest_inter, fabs(inter.next[2 * q] - fill[2 * q]));
  }
  sp_cell_obs before[2], after[2];
  CHECK_OK(sp_cells_observe(pot.mesh, pot.layout, pot.st, 0.0, before));
  CHECK_OK(sp_cells_observe(pot.mesh, grown, pot.next, 0.0, after));
  printf("rebuild (potential): %d pairs of cell 0, delta %.4e, largest departure from delta x "
         "share %.1e, cell 1 moved %.1e; largest change %.3e (interior rule %.3e); mass %.17g "
         "-> %.17g\n", n0, delta, worst, cell1, largest, largest_inter, before[0].mass,
         after[0].mass);
  CHECK(delta < 0, "the fill added mass: delta should be < 0, is %.3e", delta);
  CHECK(worst <= 1e-12 * fabs(delta), "a value departs from delta x share by %.3e", worst);
  CHECK(cell1 <= 1e-15, "cell 1 (mass unchanged) moved by %.3e", cell1);
  CHECK(largest < largest_inter, "the potential shift %.3e is not below the interior's %.3e",
        largest, largest_inter);
  CHECK(pot.dropped <= 1e-13, "the rebuild dropped %.3e of the mass", pot.dropped);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(after[k].mass - before[k].mass) <= 1e-13 * before[k].mass,
          "cell %d mass %.17g -> %.17g", k + 1, before[k].mass, after[k].mass);
  free(fill);
  rebuild_free(&pot);
  rebuild_free(&inter);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  test_rebuild_growth();
  test_rebuild_relax();
  test_rebuild_relax_unstable();
  test_rebuild_potential();
  /* 1. local = full on a short scene with a wide margin */
  const char *full_set[] = {"layout.support=full"};
  const char *wide_set[] = {"layout.margin=40", "layout.band=10"};
  sp_run_summary f = run("local_short.yaml", 1, full_set, "local_ref_full");
  sp_run_summary l = run("local_short.yaml", 2, wide_set, "local_ref_local");
  sp_run_summary l20 = run("local_short.yaml", 0, NULL, "local_ref_local20");
  double mf[2], xf[2], yf[2], ml[2], xl[2], yl[2], e0f, e0l;
  CHECK(cells_at_step("local_ref_full/cells.csv", -1, 2, mf, xf, yf) > 0, "full cells.csv");
  CHECK(cells_at_step("local_ref_local/cells.csv", -1, 2, ml, xl, yl) > 0, "local cells.csv");
  double ef = first_and_last_energy("local_ref_full/energy.csv", &e0f);
  double el = first_and_last_energy("local_ref_local/energy.csv", &e0l);
  double e0l20, el20 = first_and_last_energy("local_ref_local20/energy.csv", &e0l20);
  printf("full vs local margin 40 d: unknowns %ld vs %ld, energy %.12g vs %.12g (%.2e)\n",
         f.unknowns_max, l.unknowns_max, ef, el, fabs(el / ef - 1));
  printf("full vs local margin 20 d: unknowns %ld vs %ld, energy %.12g vs %.12g (%.2e)\n",
         f.unknowns_max, l20.unknowns_max, ef, el20, fabs(el20 / ef - 1));
  CHECK(fabs(el - ef) <= 1e-5 * fabs(ef), "energy %.15g vs %.15g", el, ef);
  CHECK(fabs(el20 - ef) <= 1e-3 * fabs(ef), "margin 20: energy %.15g vs %.15g", el20, ef);
  CHECK(l20.unknowns_max < 0.7 * f.unknowns_max, "local %ld unknowns, full %ld",
        l20.unknowns_max, f.unknowns_max);
  for (int k = 0; k < 2; ++k) {
    printf("cell %d: mass %.12g vs %.12g, centre (%.9f, %.9f) vs (%.9f, %.9f)\n", k + 1, mf[k],
           ml[k], xf[k], yf[k], xl[k], yl[k]);
    CHECK(fabs(ml[k] - mf[k]) <= 1e-9 * mf[k], "cell %d mass", k + 1);
    CHECK(fabs(xl[k] - xf[k]) <= 1e-7 && fabs(yl[k] - yf[k]) <= 1e-7, "cell %d centre", k + 1);
  }

  /* 2. a pushed cell's support follows it; masses kept */
  sp_run_summary p = run("local_push.yaml", 0, NULL, "local_push");
  double m0[2] = {0, 0}, x0[2] = {0, 0}, y0[2], m1[2], x1[2], y1[2];
  cells_at_step("local_push/cells.csv", 0, 2, m0, x0, y0);
  cells_at_step("local_push/cells.csv", -1, 2, m1, x1, y1);
  printf("pushed cell: x %.4f -> %.4f, %d support changes, mass %.15g -> %.15g; largest mass "
         "change restored %.2e, mass dropped in all %.2e, largest energy rise at a change %.2e\n",
         x0[1], x1[1], p.layout_changes, m0[1], m1[1], p.support_mass_correction,
         p.support_mass_dropped, p.support_energy_rise);
  CHECK(p.support_mass_dropped <= 1e-10, "support changes dropped %.3e of the mass in all",
        p.support_mass_dropped);
  CHECK(p.layout_changes >= 1, "the supports never changed");
  CHECK(x1[1] - x0[1] > 0.01, "the small cell did not move: %g -> %g", x0[1], x1[1]);
  for (int k = 0; k < 2; ++k)
    CHECK(fabs(m1[k] - m0[k]) <= 1e-10 * m0[k], "cell %d mass %.17g -> %.17g", k + 1, m0[k],
          m1[k]);
  /* the same push with the interior restore: the same masses kept, and the
   * potential restore (the default) raises the energy less at its changes
   * (docs/local-support.md, "How it works") */
  const char *interior_set[] = {"layout.restore=interior"};
  sp_run_summary pi = run("local_push.yaml", 1, interior_set, "local_push_interior");
  printf("pushed cell, layout.restore interior: %d support changes, largest energy rise at a "
         "change %.2e (potential %.2e)\n", pi.layout_changes, pi.support_energy_rise,
         p.support_energy_rise);
  CHECK(pi.support_mass_dropped <= 1e-10, "interior: support changes dropped %.3e of the mass",
        pi.support_mass_dropped);
  CHECK(pi.layout_changes >= 1 && p.support_energy_rise < pi.support_energy_rise,
        "the potential restore rose %.3e at a change, the interior one %.3e",
        p.support_energy_rise, pi.support_energy_rise);

  /* 3. supports clipped by the ellipse and its buffer ring */
  sp_run_summary b = run("local_edge.yaml", 0, NULL, "local_edge");
  printf("edge scene: %d steps, %d support changes, %ld unknowns at most; largest mass change "
         "restored %.2e, largest energy rise at a change %.2e\n", b.steps, b.layout_changes,
         b.unknowns_max, b.support_mass_correction, b.support_energy_rise);
  CHECK(b.steps > 0 && fabs(b.t_final - 0.004) < 1e-12, "edge scene reached t = %g", b.t_final);
  CHECK(b.layout_changes >= 1, "the edge scene's supports never changed: nothing tested");
  check_edge_laws("local_edge", &b);
  /* the same with the buffer ring's elements taken whole (the default):
   * the laws hold, and the change the margin rule needed is not needed
   * (the cell's edge beside the ring is held down by the ring's term, so
   * its far field does not pile up there) */
  const char *whole_set[] = {"layout.buffer_elements=whole"};
  sp_run_summary bw = run("local_edge.yaml", 1, whole_set, "local_edge_whole");
  printf("edge scene, buffer elements whole: %d steps, %d support changes (margin: %d), %ld "
         "unknowns at most (margin: %ld); largest energy rise at a change %.2e\n", bw.steps,
         bw.layout_changes, b.layout_changes, bw.unknowns_max, b.unknowns_max,
         bw.support_energy_rise);
  CHECK(bw.steps > 0 && fabs(bw.t_final - 0.004) < 1e-12, "edge scene (whole) reached t = %g",
        bw.t_final);
  CHECK(bw.layout_changes < b.layout_changes, "whole: %d support changes, margin %d",
        bw.layout_changes, b.layout_changes);
  check_edge_laws("local_edge_whole", &bw);

  /* 4. division under local supports */
  const char *div_set[] = {"layout.support=local", "layout.grow_threshold=0.1",
                           "layout.fill=edge"};
  sp_scene *scene;
  CHECK_OK(sp_scene_load(SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml", 3, div_set, &scene));
  sp_run_summary d;
  CHECK_OK(sp_stepper_run(scene, "local_divide", MPI_COMM_WORLD, &d));
  printf("division, local supports: %d cells, %d divisions, %d support changes, max %ld unknowns; "
         "largest mass change restored %.2e, mass dropped in all %.2e, largest energy rise at a "
         "change %.2e\n", d.n_cells, d.divisions, d.layout_changes, d.unknowns_max,
         d.support_mass_correction, d.support_mass_dropped, d.support_energy_rise);
  CHECK(d.support_mass_dropped <= 1e-10, "support changes dropped %.3e of the mass in all",
        d.support_mass_dropped);
  CHECK(d.n_cells == 4 && d.divisions == 3, "%d cells, %d divisions", d.n_cells, d.divisions);
  double md[4], xd[4], yd[4];
  cells_at_step("local_divide/cells.csv", -1, 4, md, xd, yd);
  double total = md[0] + md[1] + md[2] + md[3];
  for (int k = 0; k < 4; ++k)
    CHECK(fabs(md[k] / (total / 4) - 1) < 0.1, "cell %d mass %g vs mean %g", k + 1, md[k],
          total / 4);
  /* energy.csv logs the unknowns each step solved: the largest is the
   * run's, they change only after a step that changed the supports, and
   * with 4 cells on local supports they stay below the 4 x 2 x nodes of
   * full supports (the full run of the same scene logs exactly that). */
  csv_table e;
  CHECK(csv_read("local_divide/energy.csv", &e) == 0 && e.n_rows > 2, "local_divide/energy.csv");
  /* the scene set up as the run set it up (scene_fixture.h): the first
   * step solved on its initial local supports */
  scene_run *set_up = scene_run_setup(scene);
  const sp_mesh *mesh = set_up->run.mesh;
  CHECK(set_up->run.support && (long)at(&e, 1, "unknowns") == 2L * set_up->run.layout->n_pairs,
        "the first step solved %ld unknowns, the set-up has %d pairs on %s supports",
        (long)at(&e, 1, "unknowns"), set_up->run.layout->n_pairs,
        set_up->run.support ? "local" : "full");
  long u_max = 0;
  int u_changes = 0, bad_changes = 0;
  for (int i = 1; i < e.n_rows; ++i) {
    const long u = (long)at(&e, i, "unknowns");
    if (u > u_max) u_max = u;
    if (i > 1 && u != (long)at(&e, i - 1, "unknowns")) {
      ++u_changes;
      bad_changes += at(&e, i - 1, "support_changed") != 1;
    }
    CHECK(u > 0 && u % 2 == 0 && u <= 2L * 4 * mesh->n_nodes, "row %d: %ld unknowns", i, u);
  }
  printf("local_divide: unknowns change %d times, largest %ld (full with 4 cells: %d)\n",
         u_changes, u_max, 2 * 4 * mesh->n_nodes);
  CHECK(u_max == d.unknowns_max, "largest logged %ld, summary %ld", u_max, d.unknowns_max);
  CHECK(u_changes >= d.divisions && bad_changes == 0,
        "%d changes of the unknowns, %d not after a support change", u_changes, bad_changes);
  CHECK(u_max < 2L * 4 * mesh->n_nodes / 2, "local supports: %ld unknowns of %d", u_max,
        2 * 4 * mesh->n_nodes);
  free(e.v);
  scene_run_free(&set_up);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
