#include "layout.h"

#include <stdint.h>
#include <stdlib.h>

#include "error.h"

/** SP_OK if a layout of @p count pairs can be numbered (SP_LAYOUT_MAX_PAIRS). */
static int check_pair_count(int64_t count, int n_nodes, int n_cells) {
  SP_CHECK(count <= SP_LAYOUT_MAX_PAIRS, SP_ERR_MEMORY,
           "layout: %lld (cell, node) pairs (%d cells on %d nodes), more than %d: "
           "their 2 x pairs unknowns would overflow the solver's 32-bit indices "
           "(Epetra's global ids)",
           (long long)count, n_cells, n_nodes, SP_LAYOUT_MAX_PAIRS);
  return SP_OK;
}

int sp_layout_create_from_masks(int n_nodes, int n_cells,
                                const unsigned char *in_support,
                                sp_layout **out) {
  SP_CHECK(n_nodes > 0 && n_cells >= 0, SP_ERR_INTERNAL,
           "layout needs nodes (got %d) and a cell count >= 0 (got %d)",
           n_nodes, n_cells);
  sp_layout *l;
  int64_t count = 0;
  for (int i = 0; i < n_nodes; ++i)
    for (int k = 0; k < n_cells; ++k)
      count += in_support[(size_t)k * n_nodes + i] != 0;
  SP_CALL(check_pair_count(count, n_nodes, n_cells));
  SP_ALLOC(l, 1);
  l->n_nodes = n_nodes;
  l->n_cells = n_cells;
  l->n_pairs = (int)count;
  l->node_start = calloc((size_t)n_nodes + 1, sizeof *l->node_start);
  l->pair_cell = calloc(count ? (size_t)count : 1, sizeof *l->pair_cell);
  if (!l->node_start || !l->pair_cell) {
    sp_layout_destroy(&l);
    return sp_error_set(SP_ERR_MEMORY, "layout: out of memory for %lld (cell, node) pairs",
                        (long long)count);
  }
  int p = 0;
  for (int i = 0; i < n_nodes; ++i) {
    l->node_start[i] = p;
    for (int k = 0; k < n_cells; ++k)
      if (in_support[(size_t)k * n_nodes + i]) l->pair_cell[p++] = k;
  }
  l->node_start[n_nodes] = p;
  *out = l;
  return SP_OK;
}

int sp_layout_create_full(int n_nodes, int n_cells, sp_layout **out) {
  SP_CALL(check_pair_count((int64_t)n_nodes * n_cells, n_nodes, n_cells));
  unsigned char *mask;
  SP_ALLOC(mask, (size_t)n_nodes * (n_cells ? n_cells : 1));
  for (size_t i = 0; i < (size_t)n_nodes * n_cells; ++i) mask[i] = 1;
  int rc = sp_layout_create_from_masks(n_nodes, n_cells, mask, out);
  free(mask);
  return rc;
}

int sp_layout_pair(const sp_layout *l, int cell, int node) {
  int lo = l->node_start[node], hi = l->node_start[node + 1] - 1;
  while (lo <= hi) { /* pairs of a node are sorted by cell */
    int mid = (lo + hi) / 2;
    if (l->pair_cell[mid] == cell) return mid;
    if (l->pair_cell[mid] < cell) lo = mid + 1;
    else hi = mid - 1;
  }
  return -1;
}

void sp_layout_transfer(const sp_layout *from, const double *state_from,
                        const sp_layout *to, double *state_to, double fill_c) {
  for (int i = 0; i < to->n_nodes; ++i)
    for (int p = to->node_start[i]; p < to->node_start[i + 1]; ++p) {
      int q = i < from->n_nodes ? sp_layout_pair(from, to->pair_cell[p], i) : -1;
      state_to[2 * p] = q >= 0 ? state_from[2 * q] : fill_c;
      state_to[2 * p + 1] = q >= 0 ? state_from[2 * q + 1] : 0.0;
    }
}

void sp_layout_destroy(sp_layout **layout) {
  if (!layout || !*layout) return;
  free((*layout)->node_start);
  free((*layout)->pair_cell);
  free(*layout);
  *layout = NULL;
}

long long sp_layout_nonzeros_bound(const sp_layout *layout) {
  long long bound = 0;
  for (int i = 0; i < layout->n_nodes; ++i)
    bound += sp_nonzeros_bound(1, layout->node_start[i + 1] - layout->node_start[i]);
  return bound;
}
