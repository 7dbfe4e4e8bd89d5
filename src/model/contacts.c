/* Contacts measured from the fields (contacts.h; docs/model.md, "Contacts"). */
#include "model/contacts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/agree.h"
#include "public/error.h"
#include "mesh/q1.h"

/** Size @p c for @p n cells, every sum zero. */
static int contacts_reset(sp_contacts *c, int n) {
  const size_t pairs = (size_t)n * (size_t)(n > 0 ? n - 1 : 0) / 2;
  if (n > c->cap || !c->surface) {
    sp_contacts_clear(c);
    SP_ALLOC(c->surface, n);
    SP_ALLOC(c->overlap, pairs);
    c->cap = n;
  }
  c->n_cells = n;
  memset(c->surface, 0, sizeof(double) * (size_t)n);
  memset(c->overlap, 0, sizeof(double) * (pairs ? pairs : 1));
  return SP_OK;
}

int sp_contacts_integrate(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                          int first_node, int end_node, sp_contacts *out) {
  SP_CHECK(layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "contacts: %d nodes in the layout, %d in the mesh", layout->n_nodes, mesh->n_nodes);
  const int n = layout->n_cells, dim = mesh->dim, nen = mesh->nodes_per_elem;
  const int nq = sp_q1_qpoints(dim);
  SP_CALL(contacts_reset(out, n));
  const sp_slots *t;
  SP_CALL(sp_layout_slots(layout, mesh, &t));
  double *grad; /* |grad c| of each slot of an element at one point */
  SP_ALLOC(grad, (size_t)n + 1);
  for (int e = 0; e < mesh->n_elems; ++e) {
    const int first = sp_mesh_elem_nodes(mesh, e)[0];
    const int64_t s0 = t->elem_start[e], s1 = t->elem_start[e + 1];
    if (first < first_node || first >= end_node || s0 == s1) continue;
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_mesh_elem_xy(mesh, e, xe);
    for (int q = 0; q < nq; ++q) {
      double N[SP_Q1_MAX_NODES], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
      sp_q1_point(dim, xe, q, N, dN, x, &w);
      for (int64_t s = s0; s < s1; ++s) {
        const int *pairs = t->slot_pair + (size_t)nen * s;
        double g[SP_Q1_MAX_DIM] = {0, 0, 0};
        for (int b = 0; b < nen; ++b)
          for (int i = 0; i < dim; ++i) g[i] += dN[b][i] * state[2 * pairs[b]];
        const double norm = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        grad[s - s0] = norm;
        out->surface[t->slot_cell[s]] += w * norm;
      }
      /* the pairs living on the element (slots by increasing cell, so
       * k < l): the interface density they share, the smaller of the two */
      for (int64_t s = s0; s < s1; ++s)
        for (int64_t r = s + 1; r < s1; ++r)
          out->overlap[sp_contacts_pair(n, t->slot_cell[s], t->slot_cell[r])] +=
              w * fmin(grad[s - s0], grad[r - s0]);
    }
  }
  free(grad);
  return SP_OK;
}

int sp_contacts_reduce(MPI_Comm comm, sp_contacts *c) {
  const int n = c->n_cells;
  const size_t pairs = (size_t)n * (size_t)(n > 0 ? n - 1 : 0) / 2;
  SP_CHECK(n + pairs <= (size_t)INT_MAX, SP_ERR_INTERNAL, "contacts: %d cells", n);
  double *sums;
  SP_ALLOC(sums, (size_t)n + pairs);
  memcpy(sums, c->surface, sizeof(double) * (size_t)n);
  memcpy(sums + n, c->overlap, sizeof(double) * pairs);
  const int rc = MPI_Allreduce(MPI_IN_PLACE, sums, (int)((size_t)n + pairs), MPI_DOUBLE,
                               MPI_SUM, comm);
  if (rc == MPI_SUCCESS) {
    memcpy(c->surface, sums, sizeof(double) * (size_t)n);
    memcpy(c->overlap, sums + n, sizeof(double) * pairs);
  }
  free(sums);
  return rc == MPI_SUCCESS ? SP_OK : sp_mpi_error(rc, "MPI_Allreduce (contacts)");
}

int sp_contacts_touch(const sp_contacts *c, int k, int l, double threshold) {
  if (k == l) return 0;
  if (k > l) {
    const int swap = k;
    k = l;
    l = swap;
  }
  const double a = c->overlap[sp_contacts_pair(c->n_cells, k, l)];
  return a > 0 && a >= threshold * fmin(c->surface[k], c->surface[l]);
}

void sp_contacts_of_cell(const sp_contacts *c, int k, double threshold, double *contact,
                         double *free_surface) {
  double sum = 0;
  for (int l = 0; l < c->n_cells; ++l)
    if (sp_contacts_touch(c, k, l, threshold))
      sum += c->overlap[k < l ? sp_contacts_pair(c->n_cells, k, l)
                              : sp_contacts_pair(c->n_cells, l, k)];
  *contact = sum;
  *free_surface = c->surface[k] - sum;
}

void sp_contacts_clear(sp_contacts *c) {
  free(c->surface);
  free(c->overlap);
  *c = (sp_contacts){0};
}
