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

/** The overlap measure: S_k = int |grad c_k| dV and
 *  A_kl = int min(|grad c_k|, |grad c_l|) dV at the Gauss points. */
static int integrate_overlap(const sp_mesh *mesh, const sp_slots *t, int n, const double *state,
                             int first_node, int end_node, sp_contacts *out) {
  const int dim = mesh->dim, nen = mesh->nodes_per_elem;
  const int nq = sp_q1_qpoints(dim);
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

/* The isosurface measure. Each Q1 element is split into simplices along
 * its diagonal from local node 0 to the opposite corner (Kuhn's split: 2
 * triangles, 6 tetrahedra, each a path of element edges from node 0 to the
 * far corner). On a simplex the linear interpolants of the fields are
 * linear, c_k = 1/2 is a segment (triangle) or a triangle or quadrilateral
 * (tetrahedron), and one line (plane) c_l = theta cuts off the part where
 * the other field reaches the level: both measures are exact for the
 * interpolants. */
static const int quad_triangles[2][3] = {{0, 1, 2}, {0, 2, 3}};
static const int hex_tetrahedra[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                         {0, 4, 7, 6}, {0, 4, 5, 6}, {0, 1, 5, 6}};

/** The piece of a membrane in one simplex: n corners (0, 2 in 2D, 3 or 4
 *  in 3D, in order around the polygon), corner i on the simplex's edge
 *  from vertex from[i] (inside, c >= 1/2) to to[i] at parameter t[i]. */
typedef struct {
  int n;
  int from[4], to[4];
  double t[4];
  double x[4][SP_Q1_MAX_DIM];
} membrane_piece;

/** The piece of {f = 0} in the simplex of dim + 1 vertices @p x with values
 *  @p f (f >= 0 inside). */
static void membrane_piece_of(int dim, const double x[4][SP_Q1_MAX_DIM], const double f[4],
                              membrane_piece *p) {
  int in[4], out[4], n_in = 0, n_out = 0;
  for (int v = 0; v <= dim; ++v) {
    if (f[v] >= 0) in[n_in++] = v;
    else out[n_out++] = v;
  }
  p->n = 0;
  if (n_in == 0 || n_out == 0) return;
  if (n_in == 2 && n_out == 2) { /* a quadrilateral: its corners in turn */
    const int from[4] = {in[0], in[0], in[1], in[1]}, to[4] = {out[0], out[1], out[1], out[0]};
    for (int i = 0; i < 4; ++i) {
      p->from[i] = from[i];
      p->to[i] = to[i];
    }
    p->n = 4;
  } else {
    for (int i = 0; i < n_in; ++i)
      for (int o = 0; o < n_out; ++o) {
        p->from[p->n] = in[i];
        p->to[p->n++] = out[o];
      }
  }
  for (int i = 0; i < p->n; ++i) {
    const int a = p->from[i], b = p->to[i];
    p->t[i] = f[a] / (f[a] - f[b]); /* f[a] >= 0 > f[b] */
    for (int d = 0; d < dim; ++d) p->x[i][d] = x[a][d] + p->t[i] * (x[b][d] - x[a][d]);
  }
}

/** Length (2D) or area (3D) of the part of the segment or convex polygon
 *  @p x[0..n) where the linear function with corner values @p g is >= 0
 *  (@p g NULL: the whole). */
static double piece_measure(int dim, int n, const double x[4][SP_Q1_MAX_DIM], const double *g) {
  double y[8][SP_Q1_MAX_DIM]; /* the part: at most n + 1 corners */
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const int keep_i = !g || g[i] >= 0;
    if (keep_i) {
      for (int d = 0; d < dim; ++d) y[m][d] = x[i][d];
      ++m;
    }
    if (g && (g[i] >= 0) != (g[j] >= 0) && (dim == 3 || j != 0)) {
      const double s = g[i] / (g[i] - g[j]);
      for (int d = 0; d < dim; ++d) y[m][d] = x[i][d] + s * (x[j][d] - x[i][d]);
      ++m;
    }
  }
  if (dim == 2) {
    if (m < 2) return 0;
    return hypot(y[1][0] - y[0][0], y[1][1] - y[0][1]);
  }
  double a[3] = {0, 0, 0};
  for (int i = 1; i + 1 < m; ++i) {
    double u[3], v[3];
    for (int d = 0; d < 3; ++d) {
      u[d] = y[i][d] - y[0][d];
      v[d] = y[i + 1][d] - y[0][d];
    }
    a[0] += u[1] * v[2] - u[2] * v[1];
    a[1] += u[2] * v[0] - u[0] * v[2];
    a[2] += u[0] * v[1] - u[1] * v[0];
  }
  return 0.5 * sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

/** Element @p e's membrane pieces (slots @p s0 .. @p s1 - 1, their nodal
 *  values @p value and maxima @p largest): each slot's piece of c_k = 1/2
 *  into S_k, and its part where another slot's field reaches @p level
 *  into A_kl. */
static void add_membranes(const sp_mesh *mesh, int e, const sp_slots *t, int n, int64_t s0,
                          int64_t s1, const double *value, const double *largest, double level,
                          sp_contacts *out) {
  const int dim = mesh->dim, nen = mesh->nodes_per_elem;
  const int n_simplices = dim == 3 ? 6 : 2;
  double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
  sp_mesh_elem_xy(mesh, e, xe);
  for (int64_t s = s0; s < s1; ++s) {
    const double *vk = value + (size_t)nen * (s - s0);
    const int k = t->slot_cell[s];
    for (int q = 0; q < n_simplices; ++q) {
      const int *vertex = dim == 3 ? hex_tetrahedra[q] : quad_triangles[q];
      double x[4][SP_Q1_MAX_DIM], f[4];
      for (int a = 0; a <= dim; ++a) {
        for (int d = 0; d < dim; ++d) x[a][d] = xe[vertex[a]][d];
        f[a] = vk[vertex[a]] - 0.5;
      }
      membrane_piece p;
      membrane_piece_of(dim, x, f, &p);
      if (p.n == 0) continue;
      out->surface[k] += piece_measure(dim, p.n, p.x, NULL);
      for (int64_t r = s0; r < s1; ++r) {
        if (r == s || largest[r - s0] < level) continue;
        const double *vl = value + (size_t)nen * (r - s0);
        double g[4];
        for (int i = 0; i < p.n; ++i) {
          const double ga = vl[vertex[p.from[i]]], gb = vl[vertex[p.to[i]]];
          g[i] = ga + p.t[i] * (gb - ga) - level;
        }
        const int l = t->slot_cell[r];
        out->overlap[k < l ? sp_contacts_pair(n, k, l) : sp_contacts_pair(n, l, k)] +=
            0.5 * piece_measure(dim, p.n, p.x, g);
      }
    }
  }
}

/** The isosurface measure: S_k = |{c_k = 1/2}| and
 *  A_kl = (|S_k and {c_l >= level}| + |S_l and {c_k >= level}|) / 2. */
static int integrate_isosurface(const sp_mesh *mesh, const sp_slots *t, int n,
                                const double *state, int first_node, int end_node, double level,
                                sp_contacts *out) {
  const int nen = mesh->nodes_per_elem;
  double *value, *largest; /* each slot's nodal values on an element, and their maximum */
  SP_ALLOC(value, (size_t)nen * ((size_t)n + 1));
  largest = malloc(sizeof(double) * ((size_t)n + 1));
  if (!largest) {
    free(value);
    return sp_error_set(SP_ERR_MEMORY, "out of memory for the contacts");
  }
  for (int e = 0; e < mesh->n_elems; ++e) {
    const int first = sp_mesh_elem_nodes(mesh, e)[0];
    const int64_t s0 = t->elem_start[e], s1 = t->elem_start[e + 1];
    if (first < first_node || first >= end_node || s0 == s1) continue;
    int crossed = 0; /* a membrane crosses the element */
    for (int64_t s = s0; s < s1; ++s) {
      const int *pairs = t->slot_pair + (size_t)nen * s;
      double *v = value + (size_t)nen * (s - s0), lo = INFINITY, hi = -INFINITY;
      for (int b = 0; b < nen; ++b) {
        v[b] = state[2 * pairs[b]];
        lo = fmin(lo, v[b]);
        hi = fmax(hi, v[b]);
      }
      largest[s - s0] = hi;
      crossed |= lo < 0.5 && hi >= 0.5;
    }
    if (!crossed) continue;
    add_membranes(mesh, e, t, n, s0, s1, value, largest, level, out);
  }
  free(value);
  free(largest);
  return SP_OK;
}

int sp_contacts_integrate(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                          int first_node, int end_node, sp_contacts_measure measure,
                          double level, sp_contacts *out) {
  SP_CHECK(layout->n_nodes == mesh->n_nodes, SP_ERR_INTERNAL,
           "contacts: %d nodes in the layout, %d in the mesh", layout->n_nodes, mesh->n_nodes);
  SP_CHECK(measure == SP_CONTACTS_OVERLAP || (level > 0 && level <= 0.5), SP_ERR_INTERNAL,
           "contacts: level %g outside (0, 1/2]", level);
  const int n = layout->n_cells;
  SP_CALL(contacts_reset(out, n));
  const sp_slots *t;
  SP_CALL(sp_layout_slots(layout, mesh, &t));
  if (measure == SP_CONTACTS_OVERLAP)
    return integrate_overlap(mesh, t, n, state, first_node, end_node, out);
  return integrate_isosurface(mesh, t, n, state, first_node, end_node, level, out);
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
