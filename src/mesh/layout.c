#include "mesh/layout.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"
#include "mesh/mesh.h"

/** What a layout derives on first use (sp_layout_slots, sp_layout_cells). */
struct sp_layout_cache {
  const sp_mesh *slots_mesh; /**< the mesh the slot table is for */
  const int *slots_elem;     /**< ... and its element array (a new mesh at
                                  a freed one's address is still caught) */
  sp_slots *slots;
  sp_cell_pairs *cells;
};

/** SP_OK if a layout of @p count pairs can be numbered (SP_LAYOUT_MAX_PAIRS). */
static int check_pair_count(int64_t count, int n_nodes, int n_cells) {
  SP_CHECK(count <= SP_LAYOUT_MAX_PAIRS, SP_ERR_MEMORY,
           "layout: %lld (cell, node) pairs (%d cells on %d nodes), more than %d: "
           "their 2 x pairs unknowns would overflow the solver's 32-bit indices "
           "(the solver's global ids are 32-bit)",
           (long long)count, n_cells, n_nodes, SP_LAYOUT_MAX_PAIRS);
  return SP_OK;
}

/** A layout of @p count pairs with its arrays allocated (node_start zero). */
static int layout_allocate(int n_nodes, int n_cells, int64_t count, sp_layout **out) {
  SP_CHECK(n_nodes > 0 && n_cells >= 0, SP_ERR_INTERNAL,
           "layout needs nodes (got %d) and a cell count >= 0 (got %d)",
           n_nodes, n_cells);
  SP_CALL(check_pair_count(count, n_nodes, n_cells));
  sp_layout *l;
  SP_ALLOC(l, 1);
  l->n_nodes = n_nodes;
  l->n_cells = n_cells;
  l->n_pairs = (int)count;
  l->node_start = calloc((size_t)n_nodes + 1, sizeof *l->node_start);
  l->pair_cell = calloc(count ? (size_t)count : 1, sizeof *l->pair_cell);
  l->cache = calloc(1, sizeof *l->cache);
  if (!l->node_start || !l->pair_cell || !l->cache) {
    sp_layout_destroy(&l);
    return sp_error_set(SP_ERR_MEMORY, "layout: out of memory for %lld (cell, node) pairs",
                        (long long)count);
  }
  *out = l;
  return SP_OK;
}

int sp_layout_create_from_masks(int n_nodes, int n_cells,
                                const unsigned char *in_support,
                                sp_layout **out) {
  int64_t count = 0;
  for (int i = 0; i < n_nodes; ++i)
    for (int k = 0; k < n_cells; ++k)
      count += in_support[(size_t)k * n_nodes + i] != 0;
  sp_layout *l;
  SP_CALL(layout_allocate(n_nodes, n_cells, count, &l));
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

int sp_layout_create_from_lists(int n_nodes, int n_cells, const int64_t *cell_start,
                                const int *cell_node, sp_layout **out) {
  sp_layout *l;
  SP_CALL(layout_allocate(n_nodes, n_cells, n_cells > 0 ? cell_start[n_cells] : 0, &l));
  /* Count per node, then place the cells in increasing order: each node's
   * pairs come out sorted by cell, as from the masks. */
  int *fill = l->node_start + 1;
  for (int64_t j = 0; j < l->n_pairs; ++j) {
    const int i = cell_node[j];
    if (i < 0 || i >= n_nodes) {
      sp_layout_destroy(&l);
      return sp_error_set(SP_ERR_INTERNAL, "layout: node %d of a cell's list is not in 0..%d",
                          i, n_nodes - 1);
    }
    ++fill[i];
  }
  for (int i = 0; i < n_nodes; ++i) l->node_start[i + 1] += l->node_start[i];
  int *next = malloc(sizeof(int) * (size_t)n_nodes);
  if (!next) {
    sp_layout_destroy(&l);
    return sp_error_set(SP_ERR_MEMORY, "layout: out of memory for %d nodes", n_nodes);
  }
  memcpy(next, l->node_start, sizeof(int) * (size_t)n_nodes);
  for (int k = 0; k < n_cells; ++k)
    for (int64_t j = cell_start[k]; j < cell_start[k + 1]; ++j)
      l->pair_cell[next[cell_node[j]]++] = k;
  free(next);
  *out = l;
  return SP_OK;
}

int sp_layout_with_child(const sp_layout *layout, int parent, sp_layout **out) {
  const int n = layout->n_cells;
  SP_CHECK(parent >= 0 && parent < n, SP_ERR_INTERNAL, "layout: no cell %d of %d to divide",
           parent, n);
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(layout, &cp));
  const int64_t n_parent = cp->cell_start[parent + 1] - cp->cell_start[parent];
  int64_t *start;
  int *nodes;
  SP_ALLOC(start, (size_t)n + 2);
  nodes = malloc(sizeof(int) * ((size_t)layout->n_pairs + (size_t)n_parent + 1));
  if (!nodes) {
    free(start);
    return sp_error_set(SP_ERR_MEMORY, "layout: out of memory adding a cell");
  }
  memcpy(start, cp->cell_start, sizeof(int64_t) * ((size_t)n + 1));
  start[n + 1] = start[n] + n_parent;
  memcpy(nodes, cp->cell_node, sizeof(int) * (size_t)layout->n_pairs);
  memcpy(nodes + layout->n_pairs, cp->cell_node + cp->cell_start[parent],
         sizeof(int) * (size_t)n_parent);
  const int rc = sp_layout_create_from_lists(layout->n_nodes, n + 1, start, nodes, out);
  free(start);
  free(nodes);
  return rc;
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

int sp_layout_node_cell(const sp_layout *l, const double *state, int node) {
  int cell = -1;
  double best = 0.5;
  for (int p = l->node_start[node]; p < l->node_start[node + 1]; ++p)
    if (state[2 * p] > best) { /* strict: ties keep the lower cell */
      best = state[2 * p];
      cell = l->pair_cell[p];
    }
  return cell;
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

static void slots_free(sp_slots **t) {
  if (!*t) return;
  free((*t)->elem_start);
  free((*t)->slot_cell);
  free((*t)->slot_pair);
  free(*t);
  *t = NULL;
}

static void cells_free(sp_cell_pairs **t) {
  if (!*t) return;
  free((*t)->cell_start);
  free((*t)->cell_node);
  free((*t)->cell_pair);
  free(*t);
  *t = NULL;
}

/** Build the slot table (sp_slots) of @p l on @p m. */
static int slots_build(const sp_layout *l, const sp_mesh *m, sp_slots **out) {
  sp_slots *t;
  SP_ALLOC(t, 1);
  *out = t;
  const int nen = m->nodes_per_elem;
  t->n_elems = m->n_elems;
  t->nodes_per_elem = nen;
  /* At most one slot per pair of an element's first node. */
  int64_t bound = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    const int n0 = sp_mesh_elem_nodes(m, e)[0];
    bound += l->node_start[n0 + 1] - l->node_start[n0];
  }
  SP_ALLOC(t->elem_start, (size_t)m->n_elems + 1);
  SP_ALLOC(t->slot_cell, (size_t)bound);
  SP_ALLOC(t->slot_pair, (size_t)nen * (size_t)bound);
  int64_t s = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    const int *nodes = sp_mesh_elem_nodes(m, e);
    t->elem_start[e] = s;
    /* Cell k lives on element e only if all its nodes carry it. */
    for (int p0 = l->node_start[nodes[0]]; p0 < l->node_start[nodes[0] + 1]; ++p0) {
      const int k = l->pair_cell[p0];
      int *pairs = t->slot_pair + (size_t)nen * (size_t)s, whole = 1;
      pairs[0] = p0;
      for (int a = 1; a < nen && whole; ++a)
        whole = (pairs[a] = sp_layout_pair(l, k, nodes[a])) >= 0;
      if (whole) t->slot_cell[s++] = k;
    }
  }
  t->elem_start[m->n_elems] = s;
  t->n_slots = s;
  return SP_OK;
}

int sp_layout_slots(const sp_layout *layout, const sp_mesh *mesh, const sp_slots **out) {
  SP_CHECK(layout->cache && layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "slot table: a layout of %d nodes on a mesh of %d (or a layout not made by "
           "layout.c)", layout->n_nodes, mesh->n_nodes);
  sp_layout_cache *c = layout->cache;
  if (c->slots && (c->slots_mesh != mesh || c->slots_elem != mesh->elem ||
                   c->slots->n_elems != mesh->n_elems))
    slots_free(&c->slots);
  if (!c->slots) {
    const int rc = slots_build(layout, mesh, &c->slots);
    if (rc != SP_OK) {
      slots_free(&c->slots);
      return rc;
    }
    c->slots_mesh = mesh;
    c->slots_elem = mesh->elem;
  }
  *out = c->slots;
  return SP_OK;
}

/** Build the cell-major pairs (sp_cell_pairs) of @p l. */
static int cells_build(const sp_layout *l, sp_cell_pairs **out) {
  sp_cell_pairs *t;
  SP_ALLOC(t, 1);
  *out = t;
  SP_ALLOC(t->cell_start, (size_t)l->n_cells + 1);
  SP_ALLOC(t->cell_node, (size_t)l->n_pairs);
  SP_ALLOC(t->cell_pair, (size_t)l->n_pairs);
  for (int p = 0; p < l->n_pairs; ++p) ++t->cell_start[l->pair_cell[p] + 1];
  for (int k = 0; k < l->n_cells; ++k) t->cell_start[k + 1] += t->cell_start[k];
  int64_t *next;
  SP_ALLOC(next, (size_t)l->n_cells + 1);
  memcpy(next, t->cell_start, sizeof(int64_t) * ((size_t)l->n_cells + 1));
  for (int i = 0; i < l->n_nodes; ++i) /* nodes in increasing order */
    for (int p = l->node_start[i]; p < l->node_start[i + 1]; ++p) {
      const int64_t j = next[l->pair_cell[p]]++;
      t->cell_node[j] = i;
      t->cell_pair[j] = p;
    }
  free(next);
  return SP_OK;
}

int sp_layout_cells(const sp_layout *layout, const sp_cell_pairs **out) {
  SP_CHECK(layout->cache, SP_ERR_INTERNAL, "cell pairs: a layout not made by layout.c");
  sp_layout_cache *c = layout->cache;
  if (!c->cells) {
    const int rc = cells_build(layout, &c->cells);
    if (rc != SP_OK) {
      cells_free(&c->cells);
      return rc;
    }
  }
  *out = c->cells;
  return SP_OK;
}

void sp_layout_destroy(sp_layout **layout) {
  if (!layout || !*layout) return;
  if ((*layout)->cache) {
    slots_free(&(*layout)->cache->slots);
    cells_free(&(*layout)->cache->cells);
    free((*layout)->cache);
  }
  free((*layout)->node_start);
  free((*layout)->pair_cell);
  free(*layout);
  *layout = NULL;
}

long long sp_layout_nonzeros_bound(const sp_layout *layout, int dim) {
  long long bound = 0;
  for (int i = 0; i < layout->n_nodes; ++i)
    bound += sp_nonzeros_bound(dim, 1, layout->node_start[i + 1] - layout->node_start[i]);
  return bound;
}

double sp_layout_bytes(const sp_layout *layout) {
  double b = sizeof(int) * ((double)layout->n_nodes + 1 + (double)layout->n_pairs);
  const sp_layout_cache *c = layout->cache;
  if (c && c->slots)
    b += sizeof(int64_t) * ((double)c->slots->n_elems + 1) +
         sizeof(int) * (double)c->slots->n_slots * (1.0 + c->slots->nodes_per_elem);
  if (c && c->cells) b += sizeof(int64_t) * ((double)layout->n_cells + 1) +
                          2.0 * sizeof(int) * (double)layout->n_pairs;
  return b;
}
