#include "mesh/partition.h"

#include <stdlib.h>

#include "public/error.h"

/** A node with its sort key along the current axis, and the ties: the
 *  other coordinates in axis order (0 beyond the dimension). */
typedef struct {
  double key, tie, tie2;
  int node;
} sp_rcb_key;

static int rcb_compare(const void *a, const void *b) {
  const sp_rcb_key *x = a, *y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  if (x->tie != y->tie) return x->tie < y->tie ? -1 : 1;
  if (x->tie2 != y->tie2) return x->tie2 < y->tie2 ? -1 : 1;
  return (x->node > y->node) - (x->node < y->node);
}

/** Order nodes[0..n) in RCB order, in place (keys: scratch of n entries):
 *  split along the bounding box's longest axis (the first of equals). */
static void rcb(const double *xy, int dim, int *nodes, int n, sp_rcb_key *keys) {
  if (n <= 1) return;
  double lo[3], hi[3];
  for (int d = 0; d < dim; ++d) lo[d] = hi[d] = xy[(size_t)dim * nodes[0] + d];
  for (int j = 1; j < n; ++j)
    for (int d = 0; d < dim; ++d) {
      const double v = xy[(size_t)dim * nodes[j] + d];
      if (v < lo[d]) lo[d] = v;
      if (v > hi[d]) hi[d] = v;
    }
  int axis = 0;
  for (int d = 1; d < dim; ++d)
    if (hi[d] - lo[d] > hi[axis] - lo[axis]) axis = d;
  for (int j = 0; j < n; ++j) {
    const double *x = xy + (size_t)dim * nodes[j];
    const int t1 = (axis + 1) % dim, t2 = (axis + 2) % dim;
    keys[j] = (sp_rcb_key){x[axis], x[dim == 2 ? 1 - axis : t1], dim == 3 ? x[t2] : 0.0,
                           nodes[j]};
  }
  qsort(keys, (size_t)n, sizeof *keys, rcb_compare);
  for (int j = 0; j < n; ++j) nodes[j] = keys[j].node;
  const int half = n / 2;
  rcb(xy, dim, nodes, half, keys);
  rcb(xy, dim, nodes + half, n - half, keys);
}

int sp_partition_rcb_order(const sp_mesh *mesh, int *order) {
  sp_rcb_key *keys;
  SP_ALLOC(keys, (size_t)mesh->n_nodes);
  for (int i = 0; i < mesh->n_nodes; ++i) order[i] = i;
  rcb(mesh->xy, mesh->dim, order, mesh->n_nodes, keys);
  free(keys);
  return SP_OK;
}

int sp_partition_renumber(sp_mesh *mesh, const int *order) {
  const int n = mesh->n_nodes;
  int *new_of_old;
  SP_ALLOC(new_of_old, (size_t)n);
  for (int i = 0; i < n; ++i) new_of_old[i] = -1;
  for (int j = 0; j < n; ++j) {
    const int old = order[j];
    if (old < 0 || old >= n || new_of_old[old] >= 0) {
      free(new_of_old);
      return sp_error_set(SP_ERR_INTERNAL, "node renumbering: entry %d (%d) is not a "
                          "permutation of 0..%d", j, old, n - 1);
    }
    new_of_old[old] = j;
  }
  const int dim = mesh->dim;
  double *xy = malloc(sizeof(double) * dim * (size_t)(n > 0 ? n : 1));
  if (!xy) {
    free(new_of_old);
    return sp_error_set(SP_ERR_MEMORY, "out of memory renumbering %d nodes", n);
  }
  for (int j = 0; j < n; ++j)
    for (int d = 0; d < dim; ++d) xy[(size_t)dim * j + d] = mesh->xy[(size_t)dim * order[j] + d];
  free(mesh->xy);
  mesh->xy = xy;
  const size_t n_entries = (size_t)mesh->nodes_per_elem * mesh->n_elems;
  for (size_t a = 0; a < n_entries; ++a) mesh->elem[a] = new_of_old[mesh->elem[a]];
  free(new_of_old);
  return SP_OK;
}

void sp_partition_ranges(const sp_layout *layout, int n_ranks, int *first_node) {
  const int nn = layout->n_nodes;
  const long pairs = layout->n_pairs;
  first_node[0] = 0;
  int i = 0;
  for (int r = 1; r < n_ranks; ++r) {
    const long target = pairs * r / n_ranks; /* floor(r P / n_ranks) */
    while (i < nn && layout->node_start[i] < target) ++i;
    first_node[r] = i;
  }
  first_node[n_ranks] = nn;
}
