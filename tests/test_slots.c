/* The element-slot table and the per-cell lists ("costs that
 * follow the cells"):
 * - sp_layout_slots gives, for every element, exactly the cells whose four
 *   nodes all carry them, by increasing cell, with their pairs (checked
 *   against the rule applied element by element, cell by cell);
 * - sp_layout_cells gives each cell's pairs by increasing node;
 * - layouts from per-cell lists (sp_layout_create_from_lists,
 *   sp_layout_with_child) equal those from cells x nodes masks;
 * - the per-step supports (sp_support_layout, with and without the union
 *   of may_shrink) equal the set-up's masks path;
 * - the mesh's cached Q1 geometry is sp_q1_point's, bit for bit. */
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"
#include "model/support.h"

/** 1 if the two layouts number the same pairs. */
static int same_layout(const sp_layout *a, const sp_layout *b) {
  return a->n_nodes == b->n_nodes && a->n_cells == b->n_cells && a->n_pairs == b->n_pairs &&
         !memcmp(a->node_start, b->node_start, sizeof(int) * ((size_t)a->n_nodes + 1)) &&
         !memcmp(a->pair_cell, b->pair_cell, sizeof(int) * (size_t)a->n_pairs);
}

/** Cells x nodes masks: cell k on the nodes within radius r_k of its centre,
 *  plus random nodes (holes and islands: any layout must work). */
static unsigned char *random_masks(const sp_mesh *m, int nc, unsigned long long seed) {
  unsigned char *mask = calloc((size_t)m->n_nodes * nc, 1);
  for (int k = 0; k < nc; ++k)
    for (int i = 0; i < m->n_nodes; ++i) {
      const double cx = 0.2 + 0.15 * k, cy = 0.3, r = 0.12 + 0.02 * k;
      const double u = sp_random_symmetric(&seed);
      const int near = hypot(m->xy[2 * i] - cx, m->xy[2 * i + 1] - cy) < r;
      mask[(size_t)k * m->n_nodes + i] = (near && u > -0.9) || u > 0.95;
    }
  return mask;
}

static void check_slots(const sp_mesh *m, const sp_layout *l) {
  const sp_slots *t, *again;
  CHECK_OK(sp_layout_slots(l, m, &t));
  CHECK_OK(sp_layout_slots(l, m, &again));
  CHECK(t == again, "the slot table is built once per layout");
  CHECK(t->n_elems == m->n_elems && t->elem_start[0] == 0 &&
            t->elem_start[m->n_elems] == t->n_slots,
        "slot offsets: %d elements, %lld slots", t->n_elems, (long long)t->n_slots);
  int64_t s = 0, bad = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    CHECK(t->elem_start[e] == s, "element %d starts at slot %lld, not %lld", e,
          (long long)t->elem_start[e], (long long)s);
    for (int k = 0; k < l->n_cells; ++k) {
      int pairs[4], whole = 1;
      for (int a = 0; a < 4; ++a) whole &= (pairs[a] = sp_layout_pair(l, k, m->elem[4 * e + a])) >= 0;
      if (!whole) continue;
      bad += s >= t->elem_start[e + 1] || t->slot_cell[s] != k ||
             memcmp(t->slot_pair + 4 * s, pairs, sizeof pairs) != 0;
      ++s;
    }
  }
  CHECK(bad == 0 && s == t->n_slots, "%lld wrong slots; %lld slots by the rule, %lld in the table",
        (long long)bad, (long long)s, (long long)t->n_slots);

  const sp_cell_pairs *cp;
  CHECK_OK(sp_layout_cells(l, &cp));
  int64_t wrong = 0;
  for (int k = 0; k < l->n_cells; ++k)
    for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
      wrong += cp->cell_pair[j] != sp_layout_pair(l, k, cp->cell_node[j]) ||
               (j > cp->cell_start[k] && cp->cell_node[j] <= cp->cell_node[j - 1]);
  CHECK(wrong == 0 && cp->cell_start[l->n_cells] == l->n_pairs,
        "cell-major pairs: %lld wrong, %lld of %d pairs", (long long)wrong,
        (long long)cp->cell_start[l->n_cells], l->n_pairs);
}

/** The layout of @p mask built from per-cell lists instead. */
static void check_lists(const sp_mesh *m, int nc, const unsigned char *mask, const sp_layout *l) {
  const int nn = m->n_nodes;
  int64_t *start = calloc((size_t)nc + 1, sizeof *start);
  int *nodes = malloc(sizeof(int) * ((size_t)l->n_pairs + 1));
  for (int k = 0; k < nc; ++k) { /* decreasing node order: any order will do */
    start[k + 1] = start[k];
    for (int i = nn - 1; i >= 0; --i)
      if (mask[(size_t)k * nn + i]) nodes[start[k + 1]++] = i;
  }
  sp_layout *from_lists;
  CHECK_OK(sp_layout_create_from_lists(nn, nc, start, nodes, &from_lists));
  CHECK(same_layout(l, from_lists), "the layout from lists differs from the one from masks");
  sp_layout_destroy(&from_lists);
  free(start);
  free(nodes);

  for (int parent = 0; parent < nc; parent += nc - 1) {
    unsigned char *with = malloc((size_t)nn * (nc + 1));
    memcpy(with, mask, (size_t)nn * nc);
    memcpy(with + (size_t)nn * nc, mask + (size_t)nn * parent, (size_t)nn);
    sp_layout *by_mask, *by_child;
    CHECK_OK(sp_layout_create_from_masks(nn, nc + 1, with, &by_mask));
    CHECK_OK(sp_layout_with_child(l, parent, &by_child));
    CHECK(same_layout(by_mask, by_child), "the layout with a child of cell %d differs", parent);
    sp_layout_destroy(&by_mask);
    sp_layout_destroy(&by_child);
    free(with);
  }
}

/** sp_support_layout against the masks path (sp_support_masks, the union
 *  with the old support where a cell may not shrink, closing). */
static void check_supports(const sp_mesh *m, const sp_layout *l) {
  const int nn = m->n_nodes, nc = l->n_cells;
  double *state = calloc(2 * (size_t)l->n_pairs, sizeof(double));
  for (int i = 0; i < nn; ++i)
    for (int p = l->node_start[i]; p < l->node_start[i + 1]; ++p) {
      const int k = l->pair_cell[p];
      const double r = hypot(m->xy[2 * i] - (0.25 + 0.15 * k), m->xy[2 * i + 1] - 0.3);
      state[2 * p] = k == 1 ? 0.0 : 1.0 / (1.0 + exp((r - 0.08) / 0.02)); /* cell 1: no core */
    }
  sp_support_params prm = {.margin = 0.06, .core_threshold = 0.3, .grow_threshold = 0.1,
                           .band = 0.03, .alpha = 4, .lambda = 100, .lambda_b = 0};
  sp_support s;
  CHECK_OK(sp_support_create(m, &prm, &s));
  unsigned char *may_shrink = malloc((size_t)nc);
  for (int k = 0; k < nc; ++k) may_shrink[k] = k % 2;
  for (int variant = 0; variant < 2; ++variant) {
    const unsigned char *flags = variant ? may_shrink : NULL;
    unsigned char *mask = calloc((size_t)nn * nc, 1);
    CHECK_OK(sp_support_masks(s, l, state, mask));
    for (int k = 0; k < nc; ++k)
      if (flags && !flags[k])
        for (int i = 0; i < nn; ++i)
          if (sp_layout_pair(l, k, i) >= 0) mask[(size_t)k * nn + i] = 1;
    sp_layout *by_mask, *by_lists;
    CHECK_OK(sp_support_layout_from_masks(s, nc, mask, &by_mask));
    CHECK_OK(sp_support_layout(s, l, state, flags, &by_lists));
    CHECK(same_layout(by_mask, by_lists), "supports (may_shrink %s): lists and masks differ",
          flags ? "given" : "NULL");
    CHECK(by_lists->n_pairs > 0, "the supports are not empty");
    int needed = -1;
    CHECK_OK(sp_support_needs_update(s, by_lists, state, &needed));
    CHECK(needed == 0 || needed == 1, "needs_update answers 0 or 1, not %d", needed);
    sp_layout_destroy(&by_mask);
    sp_layout_destroy(&by_lists);
    free(mask);
  }
  free(may_shrink);
  free(state);
  sp_support_destroy(&s);
}

static void check_geometry(const sp_mesh *m) {
  int64_t differ = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(m, e, xy);
    const int nq = sp_q1_qpoints(m->dim);
    for (int q = 0; q < nq; ++q) {
      double N[SP_Q1_MAX_NODES], dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
      sp_q1_point(m->dim, xy, q, N, dNdx, x, &w);
      const size_t eq = (size_t)nq * e + q;
      differ += memcmp(&w, m->q1_w + eq, sizeof w) ||
                memcmp(x, m->q1_x + (size_t)m->dim * eq, sizeof(double) * m->dim);
    }
  }
  CHECK(differ == 0, "%lld cached Gauss points differ from sp_q1_point's", (long long)differ);
}

int main(void) {
  sp_mesh *rect, *ellipse;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 0.6, 40, 24, &rect));
  CHECK_OK(sp_mesh_ellipse(3, 0.8, 0.5, 2, 0.1, &ellipse));
  sp_mesh *meshes[2] = {rect, ellipse};
  for (int which = 0; which < 2; ++which) {
    const sp_mesh *m = meshes[which];
    check_geometry(m);
    const int nc = 5;
    unsigned char *mask = random_masks(m, nc, 7 + which);
    sp_layout *l;
    CHECK_OK(sp_layout_create_from_masks(m->n_nodes, nc, mask, &l));
    check_slots(m, l);
    check_lists(m, nc, mask, l);
    check_supports(m, l);
    sp_layout *full;
    CHECK_OK(sp_layout_create_full(m->n_nodes, 3, &full));
    check_slots(m, full);
    const sp_slots *t;
    CHECK_OK(sp_layout_slots(full, m, &t));
    CHECK(t->n_slots == 3 * (int64_t)m->n_elems, "full supports: every cell on every element");
    sp_layout_destroy(&full);
    sp_layout_destroy(&l);
    free(mask);
  }
  sp_mesh_destroy(&rect);
  sp_mesh_destroy(&ellipse);
  TEST_DONE();
}
