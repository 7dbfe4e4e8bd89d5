#include "model/support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "public/error.h"
#include "model/far_field.h"
#include "mesh/q1.h"

struct sp_support_s {
  const sp_mesh *mesh;
  sp_support_params params;
  int *ne_start, *ne_list; /* elements around each node (CSR) */
  /* scratch, n_nodes each */
  int *source, *queue;
  double *best;
  unsigned char *in_set;
  /* scratch marks, n_nodes each, all 0 between calls: a candidate support
   * and the nodes of its whole elements (closing a support) */
  unsigned char *member, *kept;
};

/** Per-cell node lists being built (CSR: cell k's nodes are
 *  node[start[k] .. start[k+1]-1]); grown by doubling. */
typedef struct {
  int64_t *start;
  int *node;
  int64_t cap;
} cell_lists;

/** The elements around each node (s->ne_start, s->ne_list). */
static int node_elements(struct sp_support_s *s) {
  const sp_mesh *mesh = s->mesh;
  const int nn = mesh->n_nodes, ne = mesh->n_elems, nen = mesh->nodes_per_elem;
  for (int e = 0; e < ne; ++e)
    for (int a = 0; a < nen; ++a) ++s->ne_start[sp_mesh_elem_nodes(mesh, e)[a] + 1];
  for (int i = 0; i < nn; ++i) s->ne_start[i + 1] += s->ne_start[i];
  int *fill;
  SP_ALLOC(fill, nn);
  for (int e = 0; e < ne; ++e) {
    for (int a = 0; a < nen; ++a) {
      int n = sp_mesh_elem_nodes(mesh, e)[a];
      s->ne_list[s->ne_start[n] + fill[n]++] = e;
    }
  }
  free(fill);
  return SP_OK;
}

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
  SP_ALLOC(s->ne_list, (size_t)mesh->nodes_per_elem * ne);
  SP_ALLOC(s->source, nn);
  SP_ALLOC(s->queue, nn);
  SP_ALLOC(s->best, nn);
  SP_ALLOC(s->in_set, nn);
  SP_ALLOC(s->member, nn);
  SP_ALLOC(s->kept, nn);
  return node_elements(s);
}

void sp_support_destroy(sp_support *s) {
  if (!s || !*s) return;
  free((*s)->ne_start);
  free((*s)->ne_list);
  free((*s)->source);
  free((*s)->queue);
  free((*s)->best);
  free((*s)->in_set);
  free((*s)->member);
  free((*s)->kept);
  free(*s);
  *s = NULL;
}

/** The straight distance between nodes i and j in the mesh's dimension,
 *  accumulated by hypot one coordinate at a time: hypot(0, dx) = |dx|, so
 *  in 2D this is hypot(dx, dy) exactly. */
static double node_distance(const sp_mesh *m, int i, int j) {
  const int dim = m->dim;
  const double *xi = m->xy + (size_t)dim * i, *xj = m->xy + (size_t)dim * j;
  double r = 0;
  for (int d = 0; d < dim; ++d) r = hypot(r, xi[d] - xj[d]);
  return r;
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
      const int *nodes = sp_mesh_elem_nodes(m, s->ne_list[t]);
      for (int a = 0; a < m->nodes_per_elem; ++a) {
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

/**
 * Cell k's support computed from its field, into s->queue[0..return): the
 * nodes within the margin of its core (c_k >= core threshold), or the
 * support it has when the core is empty (so it cannot vanish). Costs cell
 * k's pairs and the nodes reached, not the mesh's nodes.
 */
static int computed_support(sp_support s, const sp_cell_pairs *cp, const double *state, int k) {
  int n_seeds = 0; /* seeds by increasing node, as the search expects */
  for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
    if (state[2 * cp->cell_pair[j]] >= s->params.core_threshold)
      s->queue[n_seeds++] = cp->cell_node[j];
  if (n_seeds == 0) {
    int n = 0;
    for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
      s->queue[n++] = cp->cell_node[j];
    return n;
  }
  const int reached = grow_from_seeds(s, n_seeds, s->params.margin, NULL);
  clear_set(s, reached);
  return reached;
}

/** Mark s->queue[0..n) in s->member; returns n. */
static int mark_members(sp_support s, int n) {
  for (int q = 0; q < n; ++q) s->member[s->queue[q]] = 1;
  return n;
}

/** Append node @p i to cell list @p L (the cell being built is the last). */
static int lists_push(cell_lists *L, int n_cells_done, int i) {
  const int64_t len = L->start[n_cells_done + 1];
  if (len == L->cap) {
    const int64_t cap = L->cap ? 2 * L->cap : 1024;
    int *grown = realloc(L->node, sizeof(int) * (size_t)cap);
    if (!grown) return sp_error_set(SP_ERR_MEMORY, "supports: out of memory for %lld nodes",
                                    (long long)cap);
    L->node = grown;
    L->cap = cap;
  }
  L->node[len] = i;
  L->start[n_cells_done + 1] = len + 1;
  return SP_OK;
}

/** Every node of element e is marked in s->member. */
static int all_members(sp_support s, int e) {
  const int *nodes = sp_mesh_elem_nodes(s->mesh, e);
  for (int a = 0; a < s->mesh->nodes_per_elem; ++a)
    if (!s->member[nodes[a]]) return 0;
  return 1;
}

/**
 * Close the candidate support s->queue[0..n) (marked in s->member) to whole
 * elements, the solver's rule: its nodes that belong to an element whose
 * nodes (4 or 8) are all candidates. They are appended to @p L as cell
 * @p k's list; the marks are cleared. Costs the candidates' elements.
 */
static int close_to_elements(sp_support s, int n, int k, cell_lists *L) {
  const sp_mesh *m = s->mesh;
  int rc = SP_OK;
  L->start[k + 1] = L->start[k];
  for (int q = 0; q < n && rc == SP_OK; ++q)
    for (int t = s->ne_start[s->queue[q]]; t < s->ne_start[s->queue[q] + 1]; ++t) {
      if (!all_members(s, s->ne_list[t])) continue;
      const int *nodes = sp_mesh_elem_nodes(m, s->ne_list[t]);
      for (int a = 0; a < m->nodes_per_elem && rc == SP_OK; ++a)
        if (!s->kept[nodes[a]]) {
          s->kept[nodes[a]] = 1;
          rc = lists_push(L, k, nodes[a]);
        }
    }
  for (int q = 0; q < n; ++q) s->member[s->queue[q]] = s->kept[s->queue[q]] = 0;
  return rc;
}

/** Mark (@p on 1) or unmark (0) cell k's list in @p L in s->member. */
static void mark_list(sp_support s, int k, const cell_lists *L, unsigned char on) {
  for (int64_t j = L->start[k]; j < L->start[k + 1]; ++j) s->member[L->node[j]] = on;
}

/**
 * Append to cell k's list (L's last, its nodes marked in s->member) every
 * node not yet in it of the elements around its nodes up to @p j1 (only
 * buffer-ring elements with @p buffer_only): a layer of whole elements.
 */
static int add_touching_elements(sp_support s, int k, int64_t j1, int buffer_only,
                                 cell_lists *L) {
  const sp_mesh *m = s->mesh;
  int rc = SP_OK;
  for (int64_t j = L->start[k]; j < j1 && rc == SP_OK; ++j)
    for (int t = s->ne_start[L->node[j]]; t < s->ne_start[L->node[j] + 1] && rc == SP_OK; ++t) {
      if (buffer_only && m->region[s->ne_list[t]] != SP_REGION_BUFFER) continue;
      const int *nodes = sp_mesh_elem_nodes(m, s->ne_list[t]);
      for (int a = 0; a < m->nodes_per_elem && rc == SP_OK; ++a)
        if (!s->member[nodes[a]]) {
          s->member[nodes[a]] = 1;
          rc = lists_push(L, k, nodes[a]);
        }
    }
  return rc;
}

/**
 * Widen cell k's support, L's last list (closed to whole elements), by
 * @p layers layers of elements: each layer adds every element touching it
 * (so the list stays closed). Costs the elements around the support.
 */
static int widen_by_layers(sp_support s, int k, int layers, cell_lists *L) {
  int rc = SP_OK;
  mark_list(s, k, L, 1);
  for (int layer = 0; layer < layers && rc == SP_OK; ++layer)
    rc = add_touching_elements(s, k, L->start[k + 1], 0, L); /* around the support so far */
  mark_list(s, k, L, 0);
  return rc;
}

/**
 * layout.buffer_elements = whole: cell k's support, L's last list (closed
 * to whole elements), takes every buffer element one of its nodes touches,
 * whole (one pass: the nodes this adds are not taken further). A node of
 * the support's edge then never sits beside a buffer element the cell does
 * not count: beside one it is a node of a whole buffer element, held down
 * by the ring's term. With the margin alone an edge node between a free
 * element and an uncounted buffer element sits at the free far-field
 * level, and when that element becomes whole at the next change its
 * buffer energy appears at once (the eggshell's term jumping 3-5x at a
 * change in the 3D run 5: docs/local-support.md). Costs the support's
 * elements.
 */
static int take_buffer_elements(sp_support s, int k, cell_lists *L) {
  if (s->params.buffer != SP_SUPPORT_BUFFER_WHOLE || !s->mesh->region) return SP_OK;
  mark_list(s, k, L, 1);
  const int rc = add_touching_elements(s, k, L->start[k + 1], 1, L);
  mark_list(s, k, L, 0);
  return rc;
}

static void lists_free(cell_lists *L) {
  free(L->start);
  free(L->node);
}

int sp_support_masks(sp_support s, const sp_layout *layout, const double *state,
                     unsigned char *mask) {
  const int nn = s->mesh->n_nodes;
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(layout, &cp));
  /* (cells x nodes bytes: the set-up's interface, not a step's) */
  memset(mask, 0, (size_t)nn * layout->n_cells);
  for (int k = 0; k < layout->n_cells; ++k) {
    const int n = computed_support(s, cp, state, k);
    for (int q = 0; q < n; ++q) mask[(size_t)k * nn + s->queue[q]] = 1;
  }
  return SP_OK;
}

int sp_support_layout_from_masks(sp_support s, int n_cells, unsigned char *mask,
                                 sp_layout **out) {
  const int nn = s->mesh->n_nodes;
  cell_lists L = {0};
  L.start = calloc((size_t)n_cells + 1, sizeof *L.start);
  int rc = L.start ? SP_OK : sp_error_set(SP_ERR_MEMORY, "supports: out of memory");
  for (int k = 0; k < n_cells && rc == SP_OK; ++k) {
    unsigned char *mk = mask + (size_t)k * nn;
    int n = 0;
    for (int i = 0; i < nn; ++i)
      if (mk[i]) s->queue[n++] = i;
    rc = close_to_elements(s, mark_members(s, n), k, &L);
    if (rc == SP_OK) rc = take_buffer_elements(s, k, &L);
    /* the mask closed, as the caller may read it */
    memset(mk, 0, (size_t)nn);
    for (int64_t j = L.start[k]; j < L.start[k + 1] && rc == SP_OK; ++j) mk[L.node[j]] = 1;
  }
  if (rc == SP_OK) rc = sp_layout_create_from_lists(nn, n_cells, L.start, L.node, out);
  lists_free(&L);
  return rc;
}

/** sp_support_layout with cell k's support widened by layers[k] layers of
 *  elements (@p layers NULL: none). */
static int widened_layout(sp_support s, const sp_layout *layout, const double *state,
                          const unsigned char *may_shrink, const int *layers, sp_layout **out) {
  const int nc = layout->n_cells;
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(layout, &cp));
  cell_lists L = {0};
  L.start = calloc((size_t)nc + 1, sizeof *L.start);
  int rc = L.start ? SP_OK : sp_error_set(SP_ERR_MEMORY, "supports: out of memory");
  for (int k = 0; k < nc && rc == SP_OK; ++k) {
    int n = mark_members(s, computed_support(s, cp, state, k));
    if (may_shrink && !may_shrink[k]) /* the union with the support it has */
      for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
        if (!s->member[cp->cell_node[j]]) {
          s->member[cp->cell_node[j]] = 1;
          s->queue[n++] = cp->cell_node[j];
        }
    rc = close_to_elements(s, n, k, &L);
    if (rc == SP_OK && layers && layers[k] > 0) rc = widen_by_layers(s, k, layers[k], &L);
    /* after the widening, whose last layer would otherwise end beside
     * the ring */
    if (rc == SP_OK) rc = take_buffer_elements(s, k, &L);
  }
  if (rc == SP_OK) rc = sp_layout_create_from_lists(layout->n_nodes, nc, L.start, L.node, out);
  lists_free(&L);
  return rc;
}

int sp_support_layout(sp_support s, const sp_layout *layout, const double *state,
                      const unsigned char *may_shrink, sp_layout **out) {
  return widened_layout(s, layout, state, may_shrink, NULL, out);
}

/** Node i of cell k's support is on its edge: an element around it is not
 *  whole for cell k. */
static int on_edge(sp_support s, const sp_layout *layout, int k, int i) {
  for (int t = s->ne_start[i]; t < s->ne_start[i + 1]; ++t) {
    const int *nodes = sp_mesh_elem_nodes(s->mesh, s->ne_list[t]);
    for (int a = 0; a < s->mesh->nodes_per_elem; ++a)
      if (sp_layout_pair(layout, k, nodes[a]) < 0) return 1;
  }
  return 0;
}

/** Whether cell k's c_k >= grow_threshold within the band of its
 *  support's edge (sp_support_needs_update for one cell). */
static int cell_needs_update(sp_support s, const sp_layout *layout, const sp_cell_pairs *cp,
                             const double *state, int k) {
  /* the search stays in cell k's support, from its edge (by increasing
   * node): cell k's pairs, not the mesh's nodes */
  const int64_t j0 = cp->cell_start[k], j1 = cp->cell_start[k + 1];
  int n_seeds = 0, grow = 0;
  for (int64_t j = j0; j < j1; ++j) {
    const int i = cp->cell_node[j];
    s->member[i] = 1;
    if (on_edge(s, layout, k, i)) s->queue[n_seeds++] = i;
  }
  int reached = grow_from_seeds(s, n_seeds, s->params.band, s->member);
  for (int q = 0; q < reached && !grow; ++q) {
    int p = sp_layout_pair(layout, k, s->queue[q]);
    grow = state[2 * p] >= s->params.grow_threshold;
  }
  clear_set(s, reached);
  for (int64_t j = j0; j < j1; ++j) s->member[cp->cell_node[j]] = 0;
  return grow;
}

int sp_support_needs_update(sp_support s, const sp_layout *layout, const double *state,
                            int *needed) {
  *needed = 0;
  const sp_cell_pairs *cp;
  /* (a failure is an error, not "rebuild": every rank must decide alike) */
  SP_CALL(sp_layout_cells(layout, &cp));
  int grow = 0;
  for (int k = 0; k < layout->n_cells && !grow; ++k) grow = cell_needs_update(s, layout, cp, state, k);
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

/** Per cell, the means of c and mu over the nodes on the edge of its
 *  support (@p n_edge: their number; the arrays zeroed by the caller). */
static void edge_means(sp_support s, const sp_layout *layout, const double *state,
                       double *edge_c, double *edge_mu, int *n_edge) {
  const int nn = s->mesh->n_nodes, nc = layout->n_cells;
  for (int i = 0; i < nn; ++i)
    for (int p = layout->node_start[i]; p < layout->node_start[i + 1]; ++p) {
      const int k = layout->pair_cell[p];
      if (!on_edge(s, layout, k, i)) continue;
      edge_c[k] += state[2 * p];
      edge_mu[k] += state[2 * p + 1];
      ++n_edge[k];
    }
  for (int k = 0; k < nc; ++k)
    if (n_edge[k]) {
      edge_c[k] /= n_edge[k];
      edge_mu[k] /= n_edge[k];
    }
}

/** The stiffness of a cell's far field for small c at node i: mu = c (2
 *  alpha + 2 lambda sum_{l != k} c_l^2 + 2 lambda_b b), @p others the sum
 *  of the other cells' c_l^2 there (b: the node's share of buffer
 *  elements). */
static double far_field_stiffness(sp_support s, double others, int i) {
  return 2 * s->params.alpha + 2 * s->params.lambda * others +
         2 * s->params.lambda_b * buffer_share(s, i);
}

/** New nodes continue the far field: the old edge's mean c_e where the
 *  cell is alone. Where a neighbour or the buffer ring is, the far field
 *  is held down: for small c, mu = c (2 alpha + 2 lambda sum_{l != k}
 *  c_l^2 + 2 lambda_b b) (b: the node's share of buffer elements), so at
 *  the free far field's chemical potential 2 alpha c_e the node gets
 *  c_e 2 alpha / (that stiffness) (~ c_e / 25 inside a neighbour). The
 *  edge's c_e copied into a neighbour would raise the repulsion energy
 *  at first order. mu: the edge's mean. */
static void continue_far_field(sp_support s, const sp_layout *layout, const double *state,
                               const sp_layout *to, double *next, const double *edge_c,
                               const double *edge_mu) {
  const int nn = s->mesh->n_nodes;
  for (int i = 0; i < nn; ++i)
    for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q) {
      const int k = to->pair_cell[q];
      if (sp_layout_pair(layout, k, i) >= 0) continue;
      double others = 0; /* sum over l != k of c_l^2 at node i (old state) */
      for (int p = layout->node_start[i]; p < layout->node_start[i + 1]; ++p)
        if (layout->pair_cell[p] != k) others += state[2 * p] * state[2 * p];
      const double stiffness = far_field_stiffness(s, others, i);
      next[2 * q] = stiffness > 0 ? edge_c[k] * (2 * s->params.alpha) / stiffness : edge_c[k];
      next[2 * q + 1] = edge_mu[k];
    }
}

/** layout.fill = relax: the far field's own equations relaxed on the new
 *  pairs (far_field.h) at each cell's free-edge mu, from
 *  continue_far_field's values. */
static int relax_new_pairs(sp_support s, const sp_layout *layout, const sp_layout *to,
                           double *next, const double *mu_far) {
  unsigned char *is_new;
  double *guess; /* the edge rule's values: a cell whose far field has no
                    stable state keeps them */
  SP_ALLOC(is_new, to->n_pairs);
  guess = malloc(sizeof(double) * 2 * (size_t)to->n_pairs + 1);
  unsigned char *unstable = calloc((size_t)to->n_cells + 1, 1);
  if (!guess || !unstable) {
    free(is_new);
    free(guess);
    free(unstable);
    return sp_error_set(SP_ERR_MEMORY, "out of memory filling supports");
  }
  memcpy(guess, next, sizeof(double) * 2 * (size_t)to->n_pairs);
  for (int i = 0; i < to->n_nodes; ++i)
    for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q)
      is_new[q] = sp_layout_pair(layout, to->pair_cell[q], i) < 0;
  const sp_far_field_params fp = {.alpha = s->params.alpha, .kappa = s->params.kappa,
                                  .lambda = s->params.lambda, .lambda_b = s->params.lambda_b,
                                  .mu_far = mu_far};
  const int rc = sp_far_field_relax(s->mesh, s->ne_start, s->ne_list, &fp, to, is_new, next, NULL);
  /* A new pair held at the spinodal: the cell's edge mu has no stable far
   * field (a small, pressed cell); relaxed values there would nucleate a
   * second piece or, spread over a large new area, carry many times the
   * cell's mass, which the interior shift then takes out (run 2 with the
   * defaults: c -> -2). That cell keeps the edge rule's values. */
  for (int q = 0; q < to->n_pairs; ++q)
    if (is_new[q] && next[2 * q] >= SP_FAR_FIELD_SPINODAL * (1 - 1e-12))
      unstable[to->pair_cell[q]] = 1;
  for (int q = 0; q < to->n_pairs; ++q)
    if (is_new[q] && unstable[to->pair_cell[q]]) {
      next[2 * q] = guess[2 * q];
      next[2 * q + 1] = guess[2 * q + 1];
    }
  free(is_new);
  free(guess);
  free(unstable);
  return rc;
}

/** An edge node is free for cell k when no other cell's c exceeds this
 *  there (and no buffer ring is around it). */
#define SP_SUPPORT_FREE_C 1e-2

/** Per cell, the mean mu over the free nodes of its old support's edge:
 *  the far field's chemical potential where the cell is alone (an edge
 *  inside a neighbour has its mu raised by the repulsion); @p edge_mu keeps
 *  the whole edge's mean for a cell without free edge nodes. */
static int free_edge_mu(sp_support s, const sp_layout *layout, const double *state,
                        double *edge_mu) {
  const int nc = layout->n_cells;
  double *sum;
  SP_ALLOC(sum, 2 * (size_t)nc);
  double *count = sum + nc;
  for (int i = 0; i < layout->n_nodes; ++i) {
    if (buffer_share(s, i) > 0) continue;
    for (int p = layout->node_start[i]; p < layout->node_start[i + 1]; ++p) {
      const int k = layout->pair_cell[p];
      int crowded = 0;
      for (int q = layout->node_start[i]; q < layout->node_start[i + 1]; ++q)
        crowded |= q != p && state[2 * q] > SP_SUPPORT_FREE_C;
      if (crowded || !on_edge(s, layout, k, i)) continue;
      sum[k] += state[2 * p + 1];
      count[k] += 1;
    }
  }
  for (int k = 0; k < nc; ++k)
    if (count[k] > 0) edge_mu[k] = sum[k] / count[k];
  free(sum);
  return SP_OK;
}

int sp_support_fill(sp_support s, const sp_layout *layout, const double *state,
                    const sp_layout *to, double *next) {
  const int nc = layout->n_cells;
  sp_layout_transfer(layout, state, to, next, 0.0);
  /* per cell, the old support's edge means of c and mu */
  double *acc = calloc(2 * (size_t)(nc ? nc : 1), sizeof(double));
  int *n_edge = calloc((size_t)(nc ? nc : 1), sizeof(int));
  int rc = acc && n_edge ? SP_OK : sp_error_set(SP_ERR_MEMORY, "out of memory filling supports");
  double *edge_c = acc, *edge_mu = acc + nc;
  if (rc == SP_OK) {
    edge_means(s, layout, state, edge_c, edge_mu, n_edge);
    continue_far_field(s, layout, state, to, next, edge_c, edge_mu);
  }
  if (rc == SP_OK && s->params.fill == SP_SUPPORT_FILL_RELAX) {
    rc = free_edge_mu(s, layout, state, edge_mu);
    if (rc == SP_OK) rc = relax_new_pairs(s, layout, to, next, edge_mu);
  }
  free(acc);
  free(n_edge);
  return rc;
}

/** The interior of a cell, where layout.restore = interior puts the mass
 *  a support change moved. */
#define SP_SUPPORT_INTERIOR 0.5

/** The free far field's stiffness 2 alpha over that of pair @p q's cell
 *  at node i of @p to (far_field_stiffness, the neighbours' values in
 *  @p next): 1 where the cell is alone, ~1/21 inside a neighbour. */
static double free_share(sp_support s, const sp_layout *to, const double *next, int i, int q) {
  double others = 0;
  for (int p = to->node_start[i]; p < to->node_start[i + 1]; ++p)
    if (p != q) others += next[2 * p] * next[2 * p];
  const double stiffness = far_field_stiffness(s, others, i);
  return stiffness > 0 ? 2 * s->params.alpha / stiffness : 1.0;
}

/**
 * Per pair of @p to, the profile of the shift that restores a cell's mass
 * (the shift of cell k is delta_k x profile, delta_k set by the mass):
 * - interior: 1 where c_k >= 1/2, else 0; a cell without interior nodes
 *   takes it over its whole support (profile 1). No other cell and no
 *   buffer ring is there (a shift where they are raises the repulsion or
 *   buffer energy at first order) and f'(c) ~ 0; but a small, pressed
 *   cell's few interior nodes take it all (shifts of 0.67 in the 3D run 5
 *   at refinements 3: docs/local-support.md).
 * - potential: the linear response of c_k to a uniform rise of its
 *   chemical potential where its field is near a well (f'' = 2 alpha at
 *   c = 0 and at c = 1): free_share, over the whole support. Smooth (no
 *   step at the 1/2 level set), spread over the support, held down inside
 *   neighbours (~ 1/21) and the buffer ring.
 */
static int restore_profile(sp_support s, const sp_layout *to, const double *next,
                           double *profile) {
  if (s->params.restore == SP_SUPPORT_RESTORE_POTENTIAL) {
    for (int i = 0; i < to->n_nodes; ++i)
      for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q)
        profile[q] = free_share(s, to, next, i, q);
    return SP_OK;
  }
  unsigned char *has_interior;
  SP_ALLOC(has_interior, (size_t)to->n_cells + 1);
  for (int q = 0; q < to->n_pairs; ++q) {
    profile[q] = next[2 * q] >= SP_SUPPORT_INTERIOR;
    if (profile[q] > 0) has_interior[to->pair_cell[q]] = 1;
  }
  for (int q = 0; q < to->n_pairs; ++q)
    if (!has_interior[to->pair_cell[q]]) profile[q] = 1.0;
  free(has_interior);
  return SP_OK;
}

/** sp_support_rebuild with cell k's support widened by layers[k] layers of
 *  elements. */
static int rebuild_widened(sp_support s, const sp_layout *layout, const double *state,
                           const unsigned char *may_shrink, const int *layers,
                           sp_layout **new_layout, double **new_state, double *mass_correction,
                           double *mass_dropped) {
  const int nc = layout->n_cells;
  *new_layout = NULL;
  *new_state = NULL;
  *mass_correction = 0;
  *mass_dropped = 0;
  SP_CALL(widened_layout(s, layout, state, may_shrink, layers, new_layout));
  sp_layout *to = *new_layout;
  double *next;
  SP_ALLOC(next, 2 * (size_t)to->n_pairs);
  *new_state = next;
  int rc = sp_support_fill(s, layout, state, to, next);
  sp_cell_obs *before, *after;
  SP_ALLOC(before, nc);
  SP_ALLOC(after, nc);
  /* per cell, the weight of its shift's profile; per pair, the weights and
   * the profile */
  double *delta = calloc((size_t)(nc ? nc : 1), sizeof(double));
  const size_t np = (size_t)(to->n_pairs ? to->n_pairs : 1);
  double *w = malloc(sizeof(double) * 2 * np), *profile = w ? w + np : NULL;
  if (!delta || !w) rc = sp_error_set(SP_ERR_MEMORY, "out of memory restoring masses");
  if (rc == SP_OK) rc = sp_cells_observe(s->mesh, layout, state, 0.0, before);
  if (rc == SP_OK) rc = sp_cells_observe(s->mesh, to, next, 0.0, after);
  /* A shift of c_k by delta_k x profile changes the mass by delta_k x (sum
   * of weight x profile over its pairs) exactly: the shape functions of a
   * whole-element domain sum to one. */
  if (rc == SP_OK) rc = sp_cells_pair_weights(s->mesh, to, w);
  if (rc == SP_OK) rc = restore_profile(s, to, next, profile);
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q) delta[to->pair_cell[q]] += w[q] * profile[q];
  for (int k = 0; k < nc && rc == SP_OK; ++k) {
    const double change = after[k].mass - before[k].mass;
    const double rel = before[k].mass != 0 ? fabs(change / before[k].mass) : fabs(change);
    if (rel > *mass_correction) *mass_correction = rel;
    delta[k] = delta[k] > 0 ? -change / delta[k] : 0.0;
  }
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q)
    next[2 * q] += delta[to->pair_cell[q]] * profile[q];
  /* The total mass before and after, integral of sum_k c_k: the cells'
   * observed masses on the old layout, sum over pairs of (weight x c) on
   * the new one (the same quadrature). */
  double total_after = 0, total_before = 0;
  for (int q = 0; q < to->n_pairs && rc == SP_OK; ++q) total_after += w[q] * next[2 * q];
  for (int k = 0; k < nc && rc == SP_OK; ++k) total_before += before[k].mass;
  if (rc == SP_OK)
    *mass_dropped = fabs(total_after - total_before) / (total_before != 0 ? fabs(total_before) : 1);
  free(delta);
  free(w);
  free(before);
  free(after);
  return rc;
}

/** One more layer of elements (++layers[k]) for each cell whose support in
 *  @p to would call for an update at once with the values @p state;
 *  *outgrown: whether any would. */
static int widen_outgrown(sp_support s, const sp_layout *to, const double *state, int *layers,
                          int *outgrown) {
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(to, &cp));
  *outgrown = 0;
  for (int k = 0; k < to->n_cells; ++k)
    if (cell_needs_update(s, to, cp, state, k)) {
      ++layers[k];
      *outgrown = 1;
    }
  return SP_OK;
}

int sp_support_initial(sp_support s, const sp_layout *layout, const double *state,
                       sp_layout **out, double **out_state) {
  const int nc = layout->n_cells;
  int *layers;
  SP_ALLOC(layers, nc ? nc : 1);
  double *cut = NULL;
  int rc = SP_OK, outgrown = 1;
  *out = NULL;
  *out_state = NULL;
  /* as sp_support_rebuild: a support that would call for an update at
   * once (an element wider than margin - band, docs/local-support.md
   * "Coarse meshes") is widened by layers of elements until none would;
   * the fields are cut to the supports, not filled */
  while (rc == SP_OK && outgrown) {
    sp_layout_destroy(out);
    free(cut);
    cut = NULL;
    rc = widened_layout(s, layout, state, NULL, layers, out);
    if (rc == SP_OK && !(cut = malloc(2 * sizeof(double) * (size_t)(*out)->n_pairs + 1)))
      rc = sp_error_set(SP_ERR_MEMORY, "supports: out of memory");
    if (rc == SP_OK) sp_layout_transfer(layout, state, *out, cut, 0.0);
    if (rc == SP_OK) rc = widen_outgrown(s, *out, cut, layers, &outgrown);
    if (s->params.no_widening) outgrown = 0;
  }
  free(layers);
  if (rc != SP_OK) {
    sp_layout_destroy(out);
    free(cut);
    cut = NULL;
  }
  *out_state = cut;
  return rc;
}

int sp_support_rebuild(sp_support s, const sp_layout *layout, const double *state,
                       const unsigned char *may_shrink, sp_layout **new_layout,
                       double **new_state, double *mass_correction, double *mass_dropped) {
  const int nc = layout->n_cells;
  int *layers;
  SP_ALLOC(layers, nc ? nc : 1);
  int rc = SP_OK, outgrown = 1;
  *new_layout = NULL;
  *new_state = NULL;
  /* A support closed to whole elements can lose up to an element's width
   * of its margin, and new nodes start from the far field: a support just
   * rebuilt can already call for an update (elements wider than margin -
   * band around the cell, or a far field above grow_threshold), and the
   * supports would change at every step. Each such cell's support is
   * widened by one more layer of elements until none is (a support that
   * covers the mesh has no edge, so this ends). Supports that do not call
   * for one are as computed (docs/local-support.md, "What differs from full supports"). */
  while (rc == SP_OK && outgrown) {
    sp_layout_destroy(new_layout);
    free(*new_state);
    rc = rebuild_widened(s, layout, state, may_shrink, layers, new_layout, new_state,
                         mass_correction, mass_dropped);
    if (rc == SP_OK) rc = widen_outgrown(s, *new_layout, *new_state, layers, &outgrown);
    if (s->params.no_widening) outgrown = 0;
  }
  free(layers);
  return rc;
}

double sp_support_bytes(const sp_support s) {
  const double nn = s->mesh->n_nodes;
  return sizeof(int) * (nn + 1 + (double)s->mesh->n_elems * s->mesh->nodes_per_elem) +
         (2 * sizeof(int) + sizeof(double) + 2) * nn + nn;
}
