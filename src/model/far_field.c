#include "model/far_field.h"

#include <math.h>
#include <stdlib.h>

#include "public/error.h"
#include "mesh/q1.h"

/** The sweeps stop when no c changes by more than this (c is O(1)). */
#define SP_FAR_FIELD_TOL 1e-9
#define SP_FAR_FIELD_MAX_SWEEPS 200

/** One new pair's row of the far-field equations: sum_b K_ab v_b over the
 *  elements whole for its cell (off-diagonal entries by pair), K_aa,
 *  the lumped mass and its part on the buffer ring. */
typedef struct {
  int pair, node, cell;
  int start, end; /* its entries in the row table */
  double k_diag, mass, mass_buffer;
} far_row;

typedef struct {
  far_row *row;
  int *entry_pair;
  double *entry_k;
  int n_rows;
} far_rows;

/** Element e is whole for cell k in @p to: every node carries k. */
static int whole(const sp_mesh *mesh, const sp_layout *to, int e, int k) {
  const int nen = mesh->nodes_per_elem;
  for (int a = 0; a < nen; ++a)
    if (sp_layout_pair(to, k, sp_mesh_elem_nodes(mesh, e)[a]) < 0)
      return 0;
  return 1;
}

/** Element e's stiffness row of local node a and its lumped mass there
 *  (the mesh's Q1 element and Gauss rule, q1.h). */
static void element_row(const sp_mesh *mesh, int e, int a, double k_row[SP_Q1_MAX_NODES],
                        double *mass) {
  double xy[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], N[SP_Q1_MAX_NODES],
      dNdx[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
  const int dim = mesh->dim, nen = mesh->nodes_per_elem;
  sp_mesh_elem_xy(mesh, e, xy);
  *mass = 0;
  for (int b = 0; b < nen; ++b)
    k_row[b] = 0;
  for (int q = 0; q < sp_q1_qpoints(dim); ++q) {
    sp_q1_point(dim, xy, q, N, dNdx, x, &w);
    *mass += w * N[a];
    for (int b = 0; b < nen; ++b) {
      double grad_dot = 0; /* (0 + x = x: in 2D the sum of two products as before) */
      for (int d = 0; d < dim; ++d)
        grad_dot += dNdx[a][d] * dNdx[b][d];
      k_row[b] += w * grad_dot;
    }
  }
}

static int build_row(const sp_mesh *mesh, const int *ne_start, const int *ne_list,
                     const sp_layout *to, far_rows *R, int *n_entries, far_row *r) {
  const int i = r->node, k = r->cell;
  r->start = *n_entries;
  r->k_diag = r->mass = r->mass_buffer = 0;
  for (int t = ne_start[i]; t < ne_start[i + 1]; ++t) {
    const int e = ne_list[t];
    if (!whole(mesh, to, e, k))
      continue;
    const int nen = mesh->nodes_per_elem;
    const int *nodes = sp_mesh_elem_nodes(mesh, e);
    int a = 0;
    while (nodes[a] != i)
      ++a;
    double k_row[SP_Q1_MAX_NODES], m;
    element_row(mesh, e, a, k_row, &m);
    r->k_diag += k_row[a];
    r->mass += m;
    if (mesh->region && mesh->region[e] == SP_REGION_BUFFER)
      r->mass_buffer += m;
    for (int b = 0; b < nen; ++b) {
      if (b == a)
        continue;
      R->entry_pair[*n_entries] = sp_layout_pair(to, k, nodes[b]);
      R->entry_k[(*n_entries)++] = k_row[b];
    }
  }
  r->end = *n_entries;
  return SP_OK;
}

static void rows_free(far_rows *R) {
  free(R->row);
  free(R->entry_pair);
  free(R->entry_k);
}

static int rows_build(const sp_mesh *mesh, const int *ne_start, const int *ne_list,
                      const sp_layout *to, const unsigned char *is_new, far_rows *R) {
  int64_t n_rows = 0, cap = 0;
  for (int i = 0; i < to->n_nodes; ++i)
    for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q)
      if (is_new[q]) {
        ++n_rows;
        cap += (mesh->nodes_per_elem - 1) * (int64_t)(ne_start[i + 1] - ne_start[i]);
      }
  SP_ALLOC(R->row, n_rows);
  SP_ALLOC(R->entry_pair, cap);
  SP_ALLOC(R->entry_k, cap);
  int n_entries = 0;
  for (int i = 0; i < to->n_nodes; ++i)
    for (int q = to->node_start[i]; q < to->node_start[i + 1]; ++q) {
      if (!is_new[q])
        continue;
      far_row *r = &R->row[R->n_rows++];
      *r = (far_row){.pair = q, .node = i, .cell = to->pair_cell[q]};
      build_row(mesh, ne_start, ne_list, to, R, &n_entries, r);
    }
  return SP_OK;
}

/** One Gauss-Seidel update of row r; returns |change of c|. */
static double update(const sp_far_field_params *p, const far_row *r, const far_rows *R,
                     const sp_layout *to, double *state) {
  if (r->k_diag <= 0 || r->mass <= 0)
    return 0.0;
  double off_c = 0;
  for (int j = r->start; j < r->end; ++j)
    off_c += R->entry_k[j] * state[2 * R->entry_pair[j]];
  const double mu = p->mu_far[r->cell];
  state[2 * r->pair + 1] = mu;
  double others = 0; /* sum over l != k of c_l^2 at the node */
  for (int q = to->node_start[r->node]; q < to->node_start[r->node + 1]; ++q)
    if (q != r->pair)
      others += state[2 * q] * state[2 * q];
  /* g(c) = M (f'(c) + 2 lambda S c - mu) + 2 lambda_b M_b c + kappa (K_aa c + off) */
  const double c0 = state[2 * r->pair];
  double c = c0;
  for (int it = 0; it < 4; ++it) {
    const double fp = 2 * p->alpha * c * (c - 1) * (2 * c - 1);
    const double fpp = 2 * p->alpha * (6 * c * c - 6 * c + 1);
    const double g = r->mass * (fp + 2 * p->lambda * others * c - mu) +
                     2 * p->lambda_b * r->mass_buffer * c + p->kappa * (r->k_diag * c + off_c);
    const double dg = r->mass * (fpp + 2 * p->lambda * others) + 2 * p->lambda_b * r->mass_buffer +
                      p->kappa * r->k_diag;
    if (!(dg > 0))
      break;
    double next = c - g / dg;
    if (!isfinite(next))
      break;
    if (next > SP_FAR_FIELD_SPINODAL)
      next = SP_FAR_FIELD_SPINODAL;
    c = next;
  }
  state[2 * r->pair] = c;
  return fabs(c - c0);
}

int sp_far_field_relax(const sp_mesh *mesh, const int *ne_start, const int *ne_list,
                       const sp_far_field_params *params, const sp_layout *to,
                       const unsigned char *is_new, double *state, int *sweeps) {
  far_rows R = {0};
  int rc = rows_build(mesh, ne_start, ne_list, to, is_new, &R);
  int n = 0;
  double change = R.n_rows ? 1.0 : 0.0;
  for (; rc == SP_OK && n < SP_FAR_FIELD_MAX_SWEEPS && change > SP_FAR_FIELD_TOL; ++n) {
    change = 0;
    for (int r = 0; r < R.n_rows; ++r) {
      const double d = update(params, &R.row[r], &R, to, state);
      if (d > change)
        change = d;
    }
  }
  if (sweeps)
    *sweeps = n;
  rows_free(&R);
  return rc;
}
