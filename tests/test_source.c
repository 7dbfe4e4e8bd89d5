/* The growth source (src/model/source.c, paper algorithm 3): nodal s_bar where
 * c^n >= 1/2 and the cell's source is on, 0 elsewhere, per (cell, node)
 * pair; the switch-off needs both N >= N_max and m / m^0 > 1.1, and lasts. */
#include <stdlib.h>

#include "check.h"
#include "model/division.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "model/source.h"

/* The fill on a full layout: nodal values follow c^n (>= 1/2 is inside,
 * including exactly 1/2), per cell, and a cell switched off gets 0. */
static void test_fill_full_layout(void) {
  const int n_nodes = 6, n_cells = 2;
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(n_nodes, n_cells, &layout));
  /* c of cell 0 and cell 1 at the six nodes */
  const double c[2][6] = {{0.0, 0.49, 0.5, 0.51, 1.0, 0.02},
                          {1.0, 0.9, 0.1, 0.5, 0.0, 0.4999999}};
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *source = calloc((size_t)layout->n_pairs, sizeof(double));
  for (int k = 0; k < n_cells; ++k)
    for (int i = 0; i < n_nodes; ++i) {
      const int p = sp_layout_pair(layout, k, i);
      state[2 * p] = c[k][i];
      state[2 * p + 1] = 7.0; /* mu must not matter */
    }
  const double s_bar = 5e2;
  int on[2] = {1, 1};
  CHECK_OK(sp_source_fill(layout, state, n_cells, on, s_bar, source));
  for (int k = 0; k < n_cells; ++k)
    for (int i = 0; i < n_nodes; ++i) {
      const double expected = c[k][i] >= 0.5 ? s_bar : 0.0;
      const double got = source[sp_layout_pair(layout, k, i)];
      CHECK(got == expected, "cell %d node %d (c = %g): source %g, expected %g", k, i,
            c[k][i], got, expected);
    }
  /* NULL switches: every source on, the same values */
  double *source_all = calloc((size_t)layout->n_pairs, sizeof(double));
  CHECK_OK(sp_source_fill(layout, state, n_cells, NULL, s_bar, source_all));
  for (int p = 0; p < layout->n_pairs; ++p)
    CHECK(source_all[p] == source[p], "pair %d: NULL switches differ", p);
  /* cell 1 switched off: its pairs are 0, cell 0's unchanged */
  on[1] = 0;
  CHECK_OK(sp_source_fill(layout, state, n_cells, on, s_bar, source));
  for (int i = 0; i < n_nodes; ++i) {
    CHECK(source[sp_layout_pair(layout, 1, i)] == 0.0, "switched-off cell 1, node %d: %g", i,
          source[sp_layout_pair(layout, 1, i)]);
    CHECK(source[sp_layout_pair(layout, 0, i)] == (c[0][i] >= 0.5 ? s_bar : 0.0),
          "cell 0 node %d changed when cell 1 was switched off", i);
  }
  /* a switch array of the wrong length is refused */
  CHECK(sp_source_fill(layout, state, 3, on, s_bar, source) == SP_ERR_INTERNAL,
        "3 switches for 2 cells accepted");
  sp_error_clear();
  printf("fill on a full layout: s_bar exactly where c >= 1/2 (6 nodes x 2 cells)\n");
  free(state);
  free(source);
  free(source_all);
  sp_layout_destroy(&layout);
}

/* The fill on restricted supports: one value per existing pair. */
static void test_fill_local_supports(void) {
  const int n_nodes = 5, n_cells = 3;
  /* cell 0 on nodes 0-2, cell 1 on 2-4, cell 2 on 1 and 3 */
  const unsigned char mask[3 * 5] = {1, 1, 1, 0, 0, /**/ 0, 0, 1, 1, 1, /**/ 0, 1, 0, 1, 0};
  sp_layout *layout;
  CHECK_OK(sp_layout_create_from_masks(n_nodes, n_cells, mask, &layout));
  CHECK(layout->n_pairs == 8, "pairs: %d", layout->n_pairs);
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  double *source = calloc((size_t)layout->n_pairs, sizeof(double));
  /* c = 0.3 + 0.1 node + 0.2 cell at each pair */
  for (int p = 0, i = 0; i < n_nodes; ++i)
    for (; p < layout->node_start[i + 1]; ++p)
      state[2 * p] = 0.3 + 0.1 * i + 0.2 * layout->pair_cell[p];
  CHECK_OK(sp_source_fill(layout, state, n_cells, NULL, 2.5, source));
  int inside = 0;
  for (int p = 0; p < layout->n_pairs; ++p) {
    CHECK(source[p] == (state[2 * p] >= 0.5 ? 2.5 : 0.0), "pair %d (cell %d, c = %g): %g", p,
          layout->pair_cell[p], state[2 * p], source[p]);
    inside += source[p] != 0.0;
  }
  printf("fill on restricted supports: %d of %d pairs inside\n", inside, layout->n_pairs);
  free(state);
  free(source);
  sp_layout_destroy(&layout);
}

/* The switch-off needs N >= N_max AND m / m^0 > ratio_off (strictly). */
static void test_switch_needs_both_conditions(void) {
  const double ratio_off = SP_SOURCE_RATIO_OFF_PAPER;
  sp_cell_birth birth[4] = {{.birth_mass = 1.0}, {.birth_mass = 2.0}, {.birth_mass = 1.0},
                            {.birth_mass = 0.5}};
  /* ratios 1.5, 1.05, exactly 1.1, 1.2 */
  const double mass[4] = {1.5, 2.1, 1.1, 0.6};
  int on[4] = {1, 1, 1, 1};
  /* N < N_max: nobody stops, however grown */
  CHECK_OK(sp_source_update_switch(4, 5, mass, birth, on, ratio_off));
  for (int k = 0; k < 4; ++k) CHECK(on[k] == 1, "N < N_max: cell %d switched off", k);
  /* N = N_max: only the cells grown past 1.1 stop */
  CHECK_OK(sp_source_update_switch(4, 4, mass, birth, on, ratio_off));
  CHECK(on[0] == 0, "ratio 1.5 at N = N_max: still on");
  CHECK(on[1] == 1, "ratio 1.05 at N = N_max: switched off");
  CHECK(on[2] == 1, "ratio exactly 1.1 at N = N_max: switched off (needs > 1.1)");
  CHECK(on[3] == 0, "ratio 1.2 at N = N_max: still on");
  /* N > N_max (N_max overridden below N) counts as reached */
  int on_over[4] = {1, 1, 1, 1};
  CHECK_OK(sp_source_update_switch(4, 3, mass, birth, on_over, ratio_off));
  CHECK(on_over[0] == 0 && on_over[1] == 1 && on_over[2] == 1 && on_over[3] == 0,
        "N > N_max: on = %d %d %d %d", on_over[0], on_over[1], on_over[2], on_over[3]);
  /* bad arguments are refused */
  CHECK(sp_source_update_switch(4, 3, mass, birth, on_over, 0.0) == SP_ERR_INTERNAL,
        "ratio_off = 0 accepted");
  sp_error_clear();
  printf("switch: N < N_max keeps all on; N >= N_max stops ratios 1.5 and 1.2, keeps 1.05 "
         "and 1.1\n");
}

/* A switched-off source stays off: neither a mass back below 1.1 m^0 nor a
 * cell count below N_max turns it on again. */
static void test_switch_off_is_permanent(void) {
  sp_cell_birth birth[2] = {{.birth_mass = 1.0}, {.birth_mass = 1.0}};
  double mass[2] = {1.3, 1.0};
  int on[2] = {1, 1};
  CHECK_OK(sp_source_update_switch(2, 2, mass, birth, on, 1.1));
  CHECK(on[0] == 0 && on[1] == 1, "after the switch: on = %d %d", on[0], on[1]);
  mass[0] = 1.0;
  CHECK_OK(sp_source_update_switch(2, 2, mass, birth, on, 1.1));
  CHECK(on[0] == 0, "mass back to m^0: switched on again");
  CHECK_OK(sp_source_update_switch(2, 10, mass, birth, on, 1.1));
  CHECK(on[0] == 0, "N < N_max: switched on again");
  /* the switched-off cell gives no source even deep inside */
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(1, 2, &layout));
  double state[4] = {0.99, 0.0, 0.99, 0.0}, source[2];
  CHECK_OK(sp_source_fill(layout, state, 2, on, 5e2, source));
  CHECK(source[0] == 0.0 && source[1] == 5e2, "fill after switch-off: %g %g", source[0],
        source[1]);
  sp_layout_destroy(&layout);
}

int main(void) {
  test_fill_full_layout();
  test_fill_local_supports();
  test_switch_needs_both_conditions();
  test_switch_off_is_permanent();
  TEST_DONE();
}
