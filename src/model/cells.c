#include "model/cells.h"

#include <math.h>
#include <stdlib.h>

#include "public/error.h"
#include "mesh/q1.h"

double sp_cells_line_angle(double dx, double dy) {
  double angle = atan2(dy, dx);
  if (angle <= -M_PI / 2) angle += M_PI;
  if (angle > M_PI / 2) angle -= M_PI;
  return angle;
}

double sp_cells_obs_angle(const sp_cell_obs *o, int dim) {
  return dim == 2 ? sp_cells_line_angle(o->axes[0][0], o->axes[0][1]) : 0.0;
}

/** Cyclic Jacobi sweeps of sp_cells_principal: each sweep squares the
 *  off-diagonal part's size (quadratic convergence); 3x3 tensors reach
 *  round-off in 4 to 6, so this bound is never the one that stops. */
#define SP_JACOBI_MAX_SWEEPS 50

/** The off-diagonal part counts as zero below this fraction of the
 *  diagonal's size (under half an ulp of its largest entry). */
#define SP_JACOBI_OFF_DIAGONAL 1e-17

/** Beyond this |theta| the rotation's tangent is 1 / (2 theta) (theta^2
 *  would overflow; the two agree to round-off long before). */
#define SP_JACOBI_THETA_LARGE 1e150

/** A generic direction, r = (-sin 0.2 cos 0.5, cos 0.2 cos 0.5, sin 0.5):
 *  sp_cells_principal makes every eigenvector's r component >= 0. Its
 *  plane r . v = 0, where round-off can flip a sign, contains no
 *  coordinate axis, face or body diagonal; and for an axis in the xy plane
 *  the sign of an axis in the xy plane depends on its direction there
 *  only, so an extruded 2D scene gets the 2D signs. In 2D the flip line is
 *  at 0.2 + pi/2 rad (101.5 degrees) from the x axis, away from the axes
 *  and the diagonals, where symmetric scenes put their cuts. */
static void reference_direction(double r[3]) {
  const double phi0 = 0.2, beta = 0.5;
  r[0] = -sin(phi0) * cos(beta);
  r[1] = cos(phi0) * cos(beta);
  r[2] = sin(beta);
}

void sp_cells_principal(int dim, const double tensor[3][3], double moments[3], double v[3][3]) {
  double a[3][3] = {{0}}, e[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; /* e: columns */
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j) a[i][j] = 0.5 * (tensor[i][j] + tensor[j][i]);
  for (int sweep = 0; sweep < SP_JACOBI_MAX_SWEEPS; ++sweep) {
    const double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
    const double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
    if (off == 0.0 || off <= SP_JACOBI_OFF_DIAGONAL * diag) break;
    for (int p = 0; p < dim - 1; ++p)
      for (int q = p + 1; q < dim; ++q) {
        if (a[p][q] == 0.0) continue;
        /* the rotation in the (p, q) plane that zeroes a[p][q]: t = tan of
         * its angle, the smaller root of t^2 + 2 theta t - 1 = 0 */
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = fabs(theta) > SP_JACOBI_THETA_LARGE ? 0.5 / theta
                                             : copysign(1.0, theta) /
                                                   (fabs(theta) + sqrt(theta * theta + 1.0));
        const double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) { /* a <- a J (columns p, q) */
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) { /* a <- J^T a (rows p, q) */
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        a[p][q] = a[q][p] = 0.0;
        for (int k = 0; k < 3; ++k) { /* e <- e J */
          const double ekp = e[k][p], ekq = e[k][q];
          e[k][p] = c * ekp - s * ekq;
          e[k][q] = s * ekp + c * ekq;
        }
      }
  }
  /* largest first: an insertion sort of the dim column indices */
  int order[3] = {0, 1, 2};
  for (int i = 1; i < dim; ++i)
    for (int j = i; j > 0 && a[order[j]][order[j]] > a[order[j - 1]][order[j - 1]]; --j) {
      const int swap = order[j];
      order[j] = order[j - 1];
      order[j - 1] = swap;
    }
  double r[3];
  reference_direction(r);
  for (int i = 0; i < 3; ++i) {
    const int col = order[i];
    moments[i] = i < dim ? a[col][col] : 0.0;
    for (int k = 0; k < 3; ++k) v[i][k] = 0.0;
    if (i >= dim) continue;
    double norm = 0, dot = 0;
    for (int k = 0; k < dim; ++k) {
      norm += e[k][col] * e[k][col];
      dot += e[k][col] * r[k];
    }
    /* one line, two unit directions: the one with r . v >= 0 */
    const double scale = (dot < 0 ? -1.0 : 1.0) / sqrt(norm);
    for (int k = 0; k < dim; ++k) v[i][k] = e[k][col] * scale;
  }
}

/** The shape functions at the Gauss points, N[q][b] (the same on every
 *  element: Q1's reference values in dimension @p dim). */
static void reference_shapes(int dim, double N[SP_Q1_MAX_QPOINTS][SP_Q1_MAX_NODES]) {
  for (int q = 0; q < sp_q1_qpoints(dim); ++q) {
    double xi[SP_Q1_MAX_DIM], dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM];
    sp_q1_qpoint(dim, q, xi);
    sp_q1_shape(dim, xi, N[q], dN);
  }
}

/** The slot table of @p layout on @p mesh, and the mesh's Q1 geometry. */
static int elements_of(const sp_mesh *mesh, const sp_layout *layout, const sp_slots **slots) {
  SP_CHECK(layout->n_nodes == mesh->n_nodes && mesh->q1_w && mesh->q1_x, SP_ERR_INTERNAL,
           "cells: %d nodes in the layout, %d in the mesh (or a mesh without its Q1 "
           "geometry: made outside mesh.c)", layout->n_nodes, mesh->n_nodes);
  return sp_layout_slots(layout, mesh, slots);
}

int sp_cells_node_weights(const sp_mesh *mesh, const sp_layout *layout, int k, double *w) {
  SP_CHECK(k >= 0 && k < layout->n_cells, SP_ERR_INTERNAL, "node weights: cell %d of %d", k,
           layout->n_cells);
  const sp_slots *t;
  SP_CALL(elements_of(mesh, layout, &t));
  const int nen = mesh->nodes_per_elem, nq = sp_q1_qpoints(mesh->dim);
  double N[SP_Q1_MAX_QPOINTS][SP_Q1_MAX_NODES];
  reference_shapes(mesh->dim, N);
  for (int i = 0; i < mesh->n_nodes; ++i) w[i] = 0.0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    const int *nodes = sp_mesh_elem_nodes(mesh, e);
    int64_t s = t->elem_start[e]; /* slots by increasing cell */
    while (s < t->elem_start[e + 1] && t->slot_cell[s] < k) ++s;
    if (s == t->elem_start[e + 1] || t->slot_cell[s] != k) continue;
    for (int q = 0; q < nq; ++q) {
      const double wq = mesh->q1_w[(size_t)nq * e + q];
      for (int b = 0; b < nen; ++b) w[nodes[b]] += wq * N[q][b];
    }
  }
  return SP_OK;
}

int sp_cells_pair_weights(const sp_mesh *mesh, const sp_layout *layout, double *w) {
  const sp_slots *t;
  SP_CALL(elements_of(mesh, layout, &t));
  const int nen = mesh->nodes_per_elem, nq = sp_q1_qpoints(mesh->dim);
  double N[SP_Q1_MAX_QPOINTS][SP_Q1_MAX_NODES];
  reference_shapes(mesh->dim, N);
  for (int p = 0; p < layout->n_pairs; ++p) w[p] = 0.0;
  for (int e = 0; e < mesh->n_elems; ++e)
    for (int64_t s = t->elem_start[e]; s < t->elem_start[e + 1]; ++s) {
      const int *pairs = t->slot_pair + (size_t)nen * s;
      for (int q = 0; q < nq; ++q) {
        const double wq = mesh->q1_w[(size_t)nq * e + q];
        for (int b = 0; b < nen; ++b) w[pairs[b]] += wq * N[q][b];
      }
    }
  return SP_OK;
}

/** The tensor I = int c (|Xb|^2 Id - Xb Xb^T) of a cell from its central
 *  second moments M[i][j] = int c Xb_i Xb_j (i, j < dim): I_ii is the sum
 *  of the other diagonal moments, I_ij = -M_ij; then its principal moments
 *  and axes. */
static void inertia(int dim, const double M[3][3], sp_cell_obs *o) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) o->inertia[i][j] = 0.0;
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j) {
      if (j == i) continue;
      o->inertia[i][i] += M[j][j];
      o->inertia[i][j] = -M[i][j];
    }
  sp_cells_principal(dim, (const double(*)[3])o->inertia, o->moments, o->axes);
  o->long_axis = dim - 1;
}

int sp_cells_observe(const sp_mesh *mesh, const sp_layout *layout,
                     const double *state, double weight_threshold,
                     sp_cell_obs *obs) {
  const int nc = layout->n_cells;
  const sp_slots *t;
  SP_CALL(elements_of(mesh, layout, &t));
  const int dim = mesh->dim, nen = mesh->nodes_per_elem, nq = sp_q1_qpoints(dim);
  double N[SP_Q1_MAX_QPOINTS][SP_Q1_MAX_NODES];
  reference_shapes(dim, N);
  /* Per cell: mass, weighted mass, the volume (an area in 2D) inside the
   * membrane, the weighted first moments (x, y, z) and second moments
   * (xx, xy, xz, yy, yz, zz: the upper triangle by rows) */
  enum { MASS, CORE, VOLUME, FIRST, SECOND = FIRST + 3, SUMS = SECOND + 6 };
  double *sums;
  SP_ALLOC(sums, SUMS * (size_t)nc);
  for (int e = 0; e < mesh->n_elems; ++e) {
    for (int q = 0; q < nq; ++q) {
      const size_t eq = (size_t)nq * e + q;
      const double w = mesh->q1_w[eq], *x = mesh->q1_x + (size_t)dim * eq;
      /* the cells living on the element (the slot table's rule) */
      for (int64_t slot = t->elem_start[e]; slot < t->elem_start[e + 1]; ++slot) {
        const int *pairs = t->slot_pair + (size_t)nen * slot;
        double c = 0;
        for (int b = 0; b < nen; ++b) c += N[q][b] * state[2 * pairs[b]];
        double *s = sums + SUMS * t->slot_cell[slot];
        s[MASS] += w * c;
        if (c >= 0.5) s[VOLUME] += w;
        const double cw = c >= weight_threshold ? c : 0.0;
        s[CORE] += w * cw;
        for (int i = 0, ij = SECOND; i < dim; ++i) {
          s[FIRST + i] += w * cw * x[i];
          for (int j = i; j < dim; ++j) s[ij++] += w * cw * x[i] * x[j];
        }
      }
    }
  }
  for (int k = 0; k < nc; ++k) {
    const double *s = sums + SUMS * k;
    sp_cell_obs *o = obs + k;
    *o = (sp_cell_obs){.mass = s[MASS], .mass_core = s[CORE], .volume = s[VOLUME]};
    const double m = s[CORE] > 0 ? s[CORE] : 1.0;
    for (int i = 0; i < dim; ++i) o->centre[i] = s[FIRST + i] / m;
    /* central moments: int c Xb_i Xb_j = int c x_i x_j - m c_i c_j */
    double M[3][3] = {{0}};
    for (int i = 0, ij = SECOND; i < dim; ++i)
      for (int j = i; j < dim; ++j, ++ij)
        M[i][j] = M[j][i] = s[ij] - m * o->centre[i] * o->centre[j];
    inertia(dim, M, o);
  }
  free(sums);
  return SP_OK;
}

void sp_cells_core_view(const sp_cell_obs *obs, int n, sp_cell_obs *out) {
  for (int k = 0; k < n; ++k) {
    out[k] = obs[k];
    out[k].mass = obs[k].mass_core;
  }
}

double sp_random_symmetric(unsigned long long *rng) {
  unsigned long long z = (*rng += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return 2.0 * (double)(z >> 11) / 9007199254740992.0 - 1.0;
}

int sp_cells_fill(const sp_scene *scene, const sp_mesh *mesh, const sp_layout *layout,
                  sp_profile_fn profile_of, void *ctx, double *state) {
  const sp_scene_noise *noise = &scene->noise;
  for (int k = 0; k < layout->n_cells; ++k) {
    /* One stream per cell, so adding a cell does not change the others. */
    unsigned long long rng = (unsigned long long)noise->seed * 1000003ULL + (unsigned long long)k;
    for (int i = 0; i < mesh->n_nodes; ++i) {
      const double xi = noise->amplitude > 0 ? sp_random_symmetric(&rng) : 0.0;
      const int p = sp_layout_pair(layout, k, i);
      if (p < 0) continue;
      const double profile = profile_of(k, mesh->xy + (size_t)mesh->dim * i, mesh->dim, ctx);
      state[2 * p] = profile + (1.0 - profile) * (noise->background + noise->amplitude * xi);
      state[2 * p + 1] = 0.0;
    }
  }
  return SP_OK;
}

/** The signed distance from an ellipse (ellipsoid) with semi-axes s along
 *  the coordinate axes centred at c, to first order: (rho - 1) / |grad rho|
 *  with rho^2 = sum_j ((x_j - c_j) / s_j)^2, exact on the boundary's normals
 *  near it and for a sphere; -min s at the centre, where rho has no
 *  gradient. */
static double ellipsoid_distance(const double *x, const double *c, const double *s, int dim) {
  double rho2 = 0, grad2 = 0, smallest = s[0];
  for (int j = 0; j < dim; ++j) {
    const double u = (x[j] - c[j]) / s[j];
    rho2 += u * u;
    grad2 += (u / s[j]) * (u / s[j]);
    smallest = fmin(smallest, s[j]);
  }
  if (grad2 == 0) return -smallest;
  const double rho = sqrt(rho2);
  return (rho - 1.0) * rho / sqrt(grad2); /* |grad rho| = sqrt(grad2) / rho */
}

/** The scene's cell k: a disk (2D) or a sphere (3D), or with semi-axes an
 *  ellipse (ellipsoid), turned by its frame (sp_scene_cell_frame) if it
 *  gives an axis, with the tanh profile of width d, or sharp. */
static double disk_profile(int k, const double *x, int dim, void *ctx) {
  const sp_scene *scene = ctx;
  const sp_scene_cell *cell = &scene->cells[k];
  if (sp_scene_cell_is_ellipsoid(cell)) {
    const double c[3] = {cell->x, cell->y, cell->z};
    double s[3] = {1, 1, 1}; /* (z unused in 2D) */
    for (int j = 0; j < dim; ++j) s[j] = sp_scene_cell_semi_axis(cell, j);
    double distance;
    if (sp_scene_cell_is_turned(cell)) { /* in the cell's frame: R^T (x - c) */
      double R[3][3], local[3] = {0, 0, 0};
      const double origin[3] = {0, 0, 0};
      sp_scene_cell_frame(cell, R);
      for (int j = 0; j < dim; ++j)
        for (int d = 0; d < dim; ++d) local[j] += R[d][j] * (x[d] - c[d]);
      distance = ellipsoid_distance(local, origin, s, dim);
    } else {
      distance = ellipsoid_distance(x, c, s, dim);
    }
    if (cell->profile == SP_PROFILE_SHARP) return distance <= 0 ? 1.0 : 0.0;
    return sp_cells_profile(distance, sp_scene_interface_width(scene));
  }
  const double r = dim == 2 ? hypot(x[0] - cell->x, x[1] - cell->y)
                            : sqrt((x[0] - cell->x) * (x[0] - cell->x) +
                                   (x[1] - cell->y) * (x[1] - cell->y) +
                                   (x[2] - cell->z) * (x[2] - cell->z));
  if (cell->profile == SP_PROFILE_SHARP) return r <= cell->radius ? 1.0 : 0.0;
  return sp_cells_profile(r - cell->radius, sp_scene_interface_width(scene));
}

double sp_cells_profile(double signed_distance, double d) {
  return 1.0 / (1.0 + exp(signed_distance / d));
}

int sp_cells_initial_state(const sp_scene *scene, const sp_mesh *mesh,
                           const sp_layout *layout, double *state) {
  return sp_cells_fill(scene, mesh, layout, disk_profile, (void *)scene, state);
}
