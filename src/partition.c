#include "partition.h"

#include <stdlib.h>

#include "error.h"

/** A node with its sort key along the current axis. */
typedef struct {
  double key, tie;
  int node;
} sp_rcb_key;

static int rcb_compare(const void *a, const void *b) {
  const sp_rcb_key *x = a, *y = b;
  if (x->key != y->key) return x->key < y->key ? -1 : 1;
  if (x->tie != y->tie) return x->tie < y->tie ? -1 : 1;
  return (x->node > y->node) - (x->node < y->node);
}

/** Order nodes[0..n) in RCB order, in place (keys: scratch of n entries). */
static void rcb(const double *xy, int *nodes, int n, sp_rcb_key *keys) {
  if (n <= 1) return;
  double lo[2] = {xy[2 * nodes[0]], xy[2 * nodes[0] + 1]}, hi[2] = {lo[0], lo[1]};
  for (int j = 1; j < n; ++j)
    for (int d = 0; d < 2; ++d) {
      const double v = xy[2 * nodes[j] + d];
      if (v < lo[d]) lo[d] = v;
      if (v > hi[d]) hi[d] = v;
    }
  const int axis = hi[0] - lo[0] >= hi[1] - lo[1] ? 0 : 1;
  for (int j = 0; j < n; ++j)
    keys[j] = (sp_rcb_key){xy[2 * nodes[j] + axis], xy[2 * nodes[j] + 1 - axis], nodes[j]};
  qsort(keys, (size_t)n, sizeof *keys, rcb_compare);
  for (int j = 0; j < n; ++j) nodes[j] = keys[j].node;
  const int half = n / 2;
  rcb(xy, nodes, half, keys);
  rcb(xy, nodes + half, n - half, keys);
}

int sp_partition_rcb_order(const sp_mesh *mesh, int *order) {
  sp_rcb_key *keys;
  SP_ALLOC(keys, (size_t)mesh->n_nodes);
  for (int i = 0; i < mesh->n_nodes; ++i) order[i] = i;
  rcb(mesh->xy, order, mesh->n_nodes, keys);
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
  double *xy = malloc(sizeof(double) * 2 * (size_t)(n > 0 ? n : 1));
  if (!xy) {
    free(new_of_old);
    return sp_error_set(SP_ERR_MEMORY, "out of memory renumbering %d nodes", n);
  }
  for (int j = 0; j < n; ++j) {
    xy[2 * j] = mesh->xy[2 * order[j]];
    xy[2 * j + 1] = mesh->xy[2 * order[j] + 1];
  }
  free(mesh->xy);
  mesh->xy = xy;
  for (int a = 0; a < 4 * mesh->n_elems; ++a) mesh->elem[a] = new_of_old[mesh->elem[a]];
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
