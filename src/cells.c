#include "cells.h"

#include <math.h>
#include <stdlib.h>

#include "error.h"
#include "q1.h"

void sp_cells_principal(double Ixx, double Iyy, double Ixy, double *I1,
                        double *I2, double v1[2], double v2[2]) {
  const double mean = 0.5 * (Ixx + Iyy);
  const double radius = hypot(0.5 * (Ixx - Iyy), Ixy);
  *I1 = mean + radius;
  *I2 = mean - radius;
  /* Eigenvector of the larger eigenvalue at angle theta with
   * tan(2 theta) = 2 Ixy / (Ixx - Iyy); any direction when round. */
  double theta = 0.5 * atan2(2.0 * Ixy, Ixx - Iyy);
  /* A line has two unit directions, and v1's sign decides which daughter
   * takes the new label at a division (the side v2 points to). theta above
   * lies in (-pi/2, pi/2], whose ends are both the vertical direction:
   * there the sign of a round-off-sized Ixy picks the end, so the labels of
   * a vertical cut (symmetric scenes make them) flipped between runs that
   * differ only in round-off. Wrapped into (phi0 - pi/2, phi0 + pi/2], the
   * flip sits at phi0 + pi/2 = 101.5 degrees, away from the axes and the
   * diagonals. */
  const double phi0 = 0.2;
  if (theta <= phi0 - M_PI / 2) theta += M_PI;
  v1[0] = cos(theta);
  v1[1] = sin(theta);
  v2[0] = -v1[1];
  v2[1] = v1[0];
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
    const int *nodes = mesh->elem + (size_t)nen * e;
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

int sp_cells_observe(const sp_mesh *mesh, const sp_layout *layout,
                     const double *state, double weight_threshold,
                     sp_cell_obs *obs) {
  const int nc = layout->n_cells;
  const sp_slots *t;
  SP_CALL(elements_of(mesh, layout, &t));
  const int dim = mesh->dim, nen = mesh->nodes_per_elem, nq = sp_q1_qpoints(dim);
  double N[SP_Q1_MAX_QPOINTS][SP_Q1_MAX_NODES];
  reference_shapes(dim, N);
  /* Per cell: mass, weighted mass, first and second moments (x, y), the
   * area (2D) or volume (3D) inside the membrane, and the first moment in
   * z (3D). */
  enum { SUMS = 9 };
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
        s[0] += w * c;
        if (c >= 0.5) s[7] += w;
        const double cw = c >= weight_threshold ? c : 0.0;
        s[1] += w * cw;
        s[2] += w * cw * x[0];
        s[3] += w * cw * x[1];
        if (dim == 3) {
          s[8] += w * cw * x[2];
          continue; /* the inertia tensor in 3D: issue 29's next phase */
        }
        s[4] += w * cw * x[0] * x[0];
        s[5] += w * cw * x[1] * x[1];
        s[6] += w * cw * x[0] * x[1];
      }
    }
  }
  for (int k = 0; k < nc; ++k) {
    const double *s = sums + SUMS * k;
    sp_cell_obs *o = obs + k;
    o->mass = s[0];
    o->area = s[7];
    o->mass_core = s[1];
    const double m = s[1] > 0 ? s[1] : 1.0;
    o->xc = s[2] / m;
    o->yc = s[3] / m;
    o->zc = dim == 3 ? s[8] / m : 0.0;
    if (dim == 3) { /* no moments yet in 3D: zero, and v1, v2 the x and y axes */
      *o = (sp_cell_obs){.mass = o->mass, .mass_core = o->mass_core, .area = o->area,
                         .xc = o->xc, .yc = o->yc, .zc = o->zc, .v1 = {1, 0}, .v2 = {0, 1}};
      continue;
    }
    /* Central moments: int c Xb1^2 = int c x^2 - m xc^2, etc. */
    const double xx = s[4] - m * o->xc * o->xc;
    const double yy = s[5] - m * o->yc * o->yc;
    const double xy = s[6] - m * o->xc * o->yc;
    o->Ixx = yy;
    o->Iyy = xx;
    o->Ixy = -xy;
    sp_cells_principal(o->Ixx, o->Iyy, o->Ixy, &o->I1, &o->I2, o->v1, o->v2);
    o->angle = atan2(o->v1[1], o->v1[0]);
    if (o->angle <= -M_PI / 2) o->angle += M_PI;
    if (o->angle > M_PI / 2) o->angle -= M_PI;
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

/** The scene's cell k: a disk (2D) or a sphere (3D) with the
 *  tanh profile of width d, or sharp. */
static double disk_profile(int k, const double *x, int dim, void *ctx) {
  const sp_scene *scene = ctx;
  const sp_scene_cell *cell = &scene->cells[k];
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
