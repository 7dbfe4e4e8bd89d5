#include "support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cells.h"
#include "error.h"
#include "q1.h"

struct sp_support_s {
  const sp_mesh *mesh;
  sp_support_params params;
  int *ne_start, *ne_list; /* elements around each node (CSR) */
  /* scratch, n_nodes each */
  int *source, *queue;
  double *best;
  unsigned char *in_set;
};

int sp_support_create(const sp_mesh *mesh, const sp_support_params *params, sp_support *out) {
  SP_CHECK(params->margin > 0 && params->band > 0 && params->band < params->margin,
           SP_ERR_INPUT, "layout: need 0 < band (%g) < margin (%g)", params->band,
           params->margin);
  struct sp_support_s *s;
  SP_ALLOC(s, 1);
  *out = s;
  s->mesh = mesh;
  s->params = *params;
  const int nn = mesh->n_nodes, ne = mesh->n_elems;
  SP_ALLOC(s->ne_start, nn + 1);
  SP_ALLOC(s->ne_list, 4 * (size_t)ne);
  SP_ALLOC(s->source, nn);
  SP_ALLOC(s->queue, nn);
  SP_ALLOC(s->best, nn);
  SP_ALLOC(s->in_set, nn);
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < 4; ++a) ++s->ne_start[mesh->elem[4 * e + a] + 1];
  for (int i = 0; i < nn; ++i) s->ne_start[i + 1] += s->ne_start[i];
  int *fill;
  SP_ALLOC(fill, nn);
  for (int e = 0; e < ne; ++e) {
    for (int a = 0; a < 4; ++a) {
      int n = mesh->elem[4 * e + a];
      s->ne_list[s->ne_start[n] + fill[n]++] = e;
    }
  }
  free(fill);
  return SP_OK;
}

void sp_support_destroy(sp_support *s) {
  if (!s || !*s) return;
  free((*s)->ne_start);
  free((*s)->ne_list);
  free((*s)->source);
  free((*s)->queue);
  free((*s)->best);
  free((*s)->in_set);
  free(*s);
  *s = NULL;
}

static double node_distance(const sp_mesh *m, int i, int j) {
  return hypot(m->xy[2 * i] - m->xy[2 * j], m->xy[2 * i + 1] - m->xy[2 * j + 1]);
}

/**
 * Multi-source search from the n_seeds nodes in s->queue[0..n_seeds):
 * every node reachable through element neighbours whose straight distance
 * to the nearest seed found along the way is <= radius, restricted to
 * allowed nodes (NULL: all), is marked in s->in_set with s->best its
 * distance. Returns the number of nodes reached; their list is s->queue.
 */
static int grow_from_seeds(sp_support s, int n_seeds, double radius,
                           const unsigned char *allowed) {
  const sp_mesh *m = s->mesh;
  int head = 0, tail = n_seeds;
  for (int q = 0; q < n_seeds; ++q) {
    int i = s->queue[q];
    s->in_set[i] = 1;
    s->best[i] = 0;
    s->source[i] = i;
  }
  while (head < tail) {
    const int i = s->queue[head++];
    for (int t = s->ne_start[i]; t < s->ne_start[i + 1]; ++t) {
      const int *nodes = m->elem + 4 * s->ne_list[t];
      for (int a = 0; a < 4; ++a) {
        const int j = nodes[a];
        if (allowed && !allowed[j]) continue;
        const double d = node_distance(m, j, s->source[i]);
        if (d > radius || (s->in_set[j] && d >= s->best[j])) continue;
        if (!s->in_set[j]) s->queue[tail++] = j;
        s->in_set[j] = 1;
        s->best[j] = d;
        s->source[j] = s->source[i];
      }
    }
  }
  return tail;
}

static void clear_set(sp_support s, int n) {
  for (int q = 0; q < n; ++q) s->in_set[s->queue[q]] = 0;
}

int sp_support_masks(sp_support s, const sp_layout *layout, const double *state,
                     unsigned char *mask) {
  const int nn = s->mesh->n_nodes;
  memset(mask, 0, (size_t)nn * layout->n_cells);
  for (int k = 0; k < layout->n_cells; ++k) {
    unsigned char *mk = mask + (size_t)k * nn;
    int n_seeds = 0;
    for (int i = 0; i < nn; ++i) {
      int p = sp_layout_pair(layout, k, i);
      if (p >= 0 && state[2 * p] >= s->params.core_threshold) s->queue[n_seeds++] = i;
    }
    if (n_seeds == 0) { /* no core: keep the support it has */
      for (int i = 0; i < nn; ++i) mk[i] = sp_layout_pair(layout, k, i) >= 0;
      continue;
    }
    int reached = grow_from_seeds(s, n_seeds, s->params.margin, NULL);
    for (int q = 0; q < reached; ++q) mk[s->queue[q]] = 1;
    clear_set(s, reached);
  }
  return SP_OK;
}

int sp_support_layout_from_masks(sp_support s, int n_cells, unsigned char *mask,
                                 sp_layout **out) {
  /* Keep only nodes of whole elements of each cell (the solver's rule). */
  const sp_mesh *m = s->mesh;
  const int nn = m->n_nodes;
  unsigned char *kept;
  SP_ALLOC(kept, nn);
  for (int k = 0; k < n_cells; ++k) {
    unsigned char *mk = mask + (size_t)k * nn;
    memset(kept, 0, nn);
    for (int e = 0; e < m->n_elems; ++e) {
      const int *nodes = m->elem + 4 * e;
      if (mk[nodes[0]] && mk[nodes[1]] && mk[nodes[2]] && mk[nodes[3]])
        for (int a = 0; a < 4; ++a) kept[nodes[a]] = 1;
    }
    memcpy(mk, kept, nn);
  }
  free(kept);
  return sp_layout_create_from_masks(nn, n_cells, mask, out);
}

/** Node i of cell k's support is on its edge: an element around it is not
 *  whole for cell k. */
static int on_edge(sp_support s, const sp_layout *layout, int k, int i) {
  for (int t = s->ne_start[i]; t < s->ne_start[i + 1]; ++t) {
    const int *nodes = s->mesh->elem + 4 * s->ne_list[t];
    for (int a = 0; a < 4; ++a)
      if (sp_layout_pair(layout, k, nodes[a]) < 0) return 1;
  }
  return 0;
}

int sp_support_needs_update(sp_support s, const sp_layout *layout, const double *state,
                            int *needed) {
  const int nn = s->mesh->n_nodes;
  *needed = 0;
  unsigned char *allowed;
  /* (a failure is an error, not "rebuild": every rank must decide alike) */
  SP_ALLOC(allowed, (size_t)nn);
  int grow = 0;
  for (int k = 0; k < layout->n_cells && !grow; ++k) {
    int n_seeds = 0;
    for (int i = 0; i < nn; ++i) {
      allowed[i] = sp_layout_pair(layout, k, i) >= 0;
      if (allowed[i] && on_edge(s, layout, k, i)) s->queue[n_seeds++] = i;
    }
    int reached = grow_from_seeds(s, n_seeds, s->params.band, allowed);
    for (int q = 0; q < reached && !grow; ++q) {
      int p = sp_layout_pair(layout, k, s->queue[q]);
      grow = state[2 * p] >= s->params.grow_threshold;
    }
    clear_set(s, reached);
  }
  free(allowed);
  *needed = grow;
  return SP_OK;
}

/** The fraction of the elements around node i that are buffer ring. */
static double buffer_share(sp_support s, int i) {
  const int n = s->ne_start[i + 1] - s->ne_start[i];
  if (!s->mesh->region || n == 0) return 0.0;
  int buffer = 0;
  for (int j = s->ne_start[i]; j < s->ne_start[i + 1]; ++j)
    buffer += s->mesh->region[s->ne_list[j]] == SP_REGION_BUFFER;
  return (double)buffer / n;
}

/** The interior of a cell, where support changes restore its mass. */
#define SP_SUPPORT_INTERIOR 0.5

int sp_support_rebuild(sp_support s, const sp_layout *layout, const double *state,
                       const unsigned char *may_shrink, sp_layout **new_layout,
                       double **new_state, double *mass_correction, double *mass_dropped) {
  const int nn = s->mesh->n_nodes, nc = layout->n_cells;
  *new_layout = NULL;
  *new_state = NULL;
  *mass_correction = 0;
  *mass_dropped = 0;
  unsigned char *mask;
  SP_ALLOC(mask, (size_t)nn * (nc ? nc : 1));
  int rc = sp_support_masks(s, layout, state, mask);
  for (int k = 0; k < nc && rc == SP_OK; ++k)
    if (may_shrink && !may_shrink[k])
      for (int i = 0; i < nn; ++i)
        if (sp_layout_pair(layout, k, i) >= 0) mask[(size_t)k * nn + i] = 1;
  if (rc == SP_OK) rc = sp_support_layout_from_masks(s, nc, mask, new_layout);
  free(mask);
  SP_CALL(rc);
  sp_layout *to = *new_layout;
  double *next;
  SP_ALLOC(next, 2 * (size_t)to->n_pairs);
  *new_state = next;
  sp_layout_transfer(layout, state, to, next, 0.0);
  sp_cell_obs *before, *after;
  SP_ALLOC(before, nc);
  SP_ALLOC(after, nc);
  /* Per cell (every loop below runs over pairs, not cells x nodes):
   * the old support's edge means of c and mu, then the interior's and the
   * support's weights. */
  double *acc = calloc(4 * (size_t)(nc ? nc : 1), sizeof(double));
  int *n_edge = calloc((size_t)(nc ? nc : 1), sizeof(int));
  double *w = malloc(sizeof(double) * (size_t)(to->n_pairs ? to->n_pairs : 1));
  if (!acc || !n_edge || !w) rc = sp_error_set(SP_ERR_MEMORY, "out of memory restoring masses");
  double *edge_c = acc, *edge_mu = acc + nc, *w_interior = acc + 2 * (size_t)nc,
         *w_all = acc + 3 * (size_t)nc;
  for (int i = 0; i < nn && rc == SP_OK; ++i)
    for (int p = layout->node_start[i]; p < layout->node_start[i + 1]; ++p) {
      const int k = layout->pair_cell[p];
      if (!on_edge(s, layout, k, i)) continue;
      edge_c[k] += state[2 * p];
      edge_mu[k] += state[2 * p + 1];
      ++n_edge[k];
    }
  for (int k = 0; k < nc && rc == SP_OK; ++k)
    if (n_edge[k]) {
      edge_c[k] /= n_edge[k];
      edge_mu[k] /= n_edge[k];
    }
  /* New nodes continue the far field: the old edge's mean c_e where the
   * cell is alone. Where a neighbour or the buffer ring is, the far field
   * is held down: for small c, mu = c (2 alpha + 2 lambda sum_{l != k}
   * c_l^2 + 2 lambda_b b) (b: the node's share of buffer elements), so at
   * the free far field's chemical potential 2 alpha c_e the node gets
   * c_e 2 alpha / (that stiffness) (~ c_e / 25 inside a neighbour). The
   * edge's c_e copied into a neighbour would raise the repulsion energy
   * at first order. mu: the edge's mean. */
  for (int i = 0; i < nn && rc == SP_OK; ++i)
    for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q) {
      const int k = to->pair_cell[q];
      if (sp_layout_pair(layout, k, i) >= 0) continue;
      double others = 0; /* sum over l != k of c_l^2 at node i (old state) */
      for (int p = layout->node_start[i]; p < layout->node_start[i + 1]; ++p)
        if (layout->pair_cell[p] != k) others += state[2 * p] * state[2 * p];
      const double free_stiffness = 2 * s->params.alpha;
      const double stiffness = free_stiffness + 2 * s->params.lambda * others +
                               2 * s->params.lambda_b * buffer_share(s, i);
      next[2 * q] = stiffness > 0 ? edge_c[k] * free_stiffness / stiffness : edge_c[k];
      next[2 * q + 1] = edge_mu[k];
    }
  if (rc == SP_OK) rc = sp_cells_observe(s->mesh, layout, state, 0.0, before);
  if (rc == SP_OK) rc = sp_cells_observe(s->mesh, to, next, 0.0, after);
  /* A shift of c_k by d on a set of nodes changes the mass by d x (their
   * weights) exactly. It goes on the cell's interior (c_k >= 1/2): there
   * no other cell and no buffer ring is (a shift where a neighbour or the
   * ring is raises the repulsion or buffer energy at first order) and
   * f'(c) ~ 0; a cell without interior nodes takes it over its support. */
  if (rc == SP_OK) rc = sp_cells_pair_weights(s->mesh, to, w);
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q) {
    const int k = to->pair_cell[q];
    w_all[k] += w[q];
    if (next[2 * q] >= SP_SUPPORT_INTERIOR) w_interior[k] += w[q];
  }
  for (int k = 0; k < nc && rc == SP_OK; ++k) {
    const double change = after[k].mass - before[k].mass;
    const double rel = before[k].mass != 0 ? fabs(change / before[k].mass) : fabs(change);
    if (rel > *mass_correction) *mass_correction = rel;
    /* the shift of cell k, kept in w_all[k]; w_interior[k] > 0 marks an
     * interior to shift (a cell without one shifts its whole support) */
    const double weight = w_interior[k] > 0 ? w_interior[k] : w_all[k];
    w_all[k] = weight > 0 ? -change / weight : 0.0;
  }
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q) {
    const int k = to->pair_cell[q];
    if (w_interior[k] <= 0 || next[2 * q] >= SP_SUPPORT_INTERIOR) next[2 * q] += w_all[k];
  }
  /* The total mass before and after, integral of sum_k c_k: the cells'
   * observed masses on the old layout, sum over pairs of (weight x c) on
   * the new one (the same quadrature). */
  double total_after = 0, total_before = 0;
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q) total_after += w[q] * next[2 * q];
  for (int k = 0; k < nc && rc == SP_OK; ++k) total_before += before[k].mass;
  if (rc == SP_OK)
    *mass_dropped = fabs(total_after - total_before) / (total_before != 0 ? fabs(total_before) : 1);
  free(acc);
  free(n_edge);
  free(w);
  free(before);
  free(after);
  return rc;
}
