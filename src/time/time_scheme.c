#include "time/time_scheme.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "public/error.h"

int sp_history_push(sp_history *h, const double *state_old, double dt, size_t n_values) {
  double *oldest = h->past[1];
  h->past[1] = h->past[0];
  h->dt[1] = h->dt[0];
  if (!oldest) {
    oldest = malloc(n_values * sizeof(double) + 1);
    SP_CHECK(oldest, SP_ERR_MEMORY, "out of memory for the time scheme's history");
  }
  memcpy(oldest, state_old, n_values * sizeof(double));
  h->past[0] = oldest;
  h->dt[0] = dt;
  if (h->n < 2) ++h->n;
  return SP_OK;
}

void sp_history_free(sp_history *h) {
  free(h->past[0]);
  free(h->past[1]);
  *h = (sp_history){0};
}

void sp_history_reset(sp_history *h) { /* the layout may change next: no stale sizes */
  sp_history_free(h);
}

/** A linear map of per-pair values from one layout to another. */
typedef int (*sp_history_map)(void *ctx, const double *from_values, double *to_values);

/** sp_history_transfer's map: (cell, node) values, 0 on new pairs. */
static int transfer_map(void *ctx, const double *from_values, double *to_values) {
  const sp_layout *const *layouts = ctx;
  sp_layout_transfer(layouts[0], from_values, layouts[1], to_values, 0.0);
  return SP_OK;
}

/** Move the past states by their increments against the state through
 *  @p map, each cell's increment shifted to the mass it had on @p from. */
static int history_move(sp_history *h, const sp_mesh *mesh, const sp_layout *from,
                        const double *state_from, const sp_layout *to,
                        const double *state_to, sp_history_map map, void *ctx) {
  const size_t n_from = 2 * (size_t)from->n_pairs, n_to = 2 * (size_t)to->n_pairs;
  const int nc = to->n_cells;
  if (h->n == 0) {
    sp_history_free(h);
    return SP_OK;
  }
  double *w_from = malloc(sizeof(double) * ((size_t)from->n_pairs + (size_t)to->n_pairs +
                                            3 * (size_t)nc) + 1);
  SP_CHECK(w_from, SP_ERR_MEMORY, "out of memory moving the time scheme's history");
  double *w_to = w_from + from->n_pairs, *mass_from = w_to + to->n_pairs;
  double *mass_to = mass_from + nc, *weight = mass_to + nc;
  int rc = sp_cells_pair_weights(mesh, from, w_from);
  if (rc == SP_OK) rc = sp_cells_pair_weights(mesh, to, w_to);
  for (int j = 0; j < 2 && rc == SP_OK; ++j) {
    if (j >= h->n) { /* nothing valid to carry: drop the storage */
      free(h->past[j]);
      h->past[j] = NULL;
      continue;
    }
    double *past = malloc(n_to * sizeof(double) + 1);
    if (!past) {
      rc = sp_error_set(SP_ERR_MEMORY, "out of memory moving the time scheme's history");
      break;
    }
    double *inc = h->past[j]; /* the increment state - past, in place */
    for (size_t i = 0; i < n_from; ++i) inc[i] = state_from[i] - inc[i];
    rc = map(ctx, inc, past);
    if (rc != SP_OK) {
      free(past);
      break;
    }
    /* each cell's increment of c keeps the mass it had (0 when s = 0, so a
     * BDF2 step after the change still conserves mass): the difference
     * spread evenly over the cell's new support */
    for (int k = 0; k < nc; ++k) mass_from[k] = mass_to[k] = weight[k] = 0.0;
    for (int p = 0; p < from->n_pairs; ++p) mass_from[from->pair_cell[p]] += w_from[p] * inc[2 * p];
    for (int p = 0; p < to->n_pairs; ++p) {
      mass_to[to->pair_cell[p]] += w_to[p] * past[2 * p];
      weight[to->pair_cell[p]] += w_to[p];
    }
    for (int k = 0; k < nc; ++k)
      mass_to[k] = weight[k] > 0 ? (mass_to[k] - mass_from[k]) / weight[k] : 0.0;
    for (int p = 0; p < to->n_pairs; ++p) past[2 * p] -= mass_to[to->pair_cell[p]];
    for (size_t i = 0; i < n_to; ++i) past[i] = state_to[i] - past[i];
    free(h->past[j]);
    h->past[j] = past;
  }
  free(w_from);
  return rc;
}

int sp_history_transfer(sp_history *h, const sp_mesh *mesh, const sp_layout *from,
                        const double *state_from, const sp_layout *to,
                        const double *state_to) {
  const sp_layout *layouts[2] = {from, to};
  return history_move(h, mesh, from, state_from, to, state_to, transfer_map, (void *)layouts);
}

sp_scheme_kind sp_scheme_of_step(sp_scheme_kind scheme, const sp_history *h) {
  return scheme == SP_SCHEME_BDF2 && h->n >= 1 ? SP_SCHEME_BDF2 : SP_SCHEME_BE;
}

int sp_scheme_has_estimate(sp_scheme_kind kind, const sp_history *h) {
  (void)kind; /* BDF2 with one past state: BE's estimate, a bound */
  return h->n >= 1;
}

void sp_scheme_be_form(sp_scheme_kind kind, const sp_history *h, double dt,
                       const double *state, size_t n_pairs, double *state_old_eff,
                       double *dt_eff) {
  memcpy(state_old_eff, state, 2 * n_pairs * sizeof(double));
  *dt_eff = dt;
  if (kind != SP_SCHEME_BDF2) return;
  const double w = dt / h->dt[0];
  const double a = (1 + w) * (1 + w) / (1 + 2 * w), b = w * w / (1 + 2 * w);
  const double *past = h->past[0];
  for (size_t p = 0; p < n_pairs; ++p) state_old_eff[2 * p] = a * state[2 * p] - b * past[2 * p];
  *dt_eff = dt * (1 + w) / (1 + 2 * w);
}

void sp_scheme_extrapolate(int order, const sp_history *h, double dt, const double *state,
                           size_t n_pairs, double *out) {
  const size_t n = 2 * n_pairs;
  if (order >= 2 && h->n >= 2) { /* Lagrange through t^{n-2}, t^{n-1}, t^n at t^n + dt */
    const double t0 = 0, t1 = -h->dt[0], t2 = -h->dt[0] - h->dt[1], s = dt;
    const double l0 = (s - t1) * (s - t2) / ((t0 - t1) * (t0 - t2));
    const double l1 = (s - t0) * (s - t2) / ((t1 - t0) * (t1 - t2));
    const double l2 = (s - t0) * (s - t1) / ((t2 - t0) * (t2 - t1));
    for (size_t i = 0; i < n; ++i)
      out[i] = l0 * state[i] + l1 * h->past[0][i] + l2 * h->past[1][i];
  } else if (order >= 1 && h->n >= 1) {
    const double r = dt / h->dt[0];
    for (size_t i = 0; i < n; ++i) out[i] = state[i] + r * (state[i] - h->past[0][i]);
  } else {
    memcpy(out, state, n * sizeof(double));
  }
}

/** factor max_i |c_i - other_i| / (atol + rtol max(|c^n_i|, |c_i|)) over
 *  the c entries: the estimate's weighted max-norm (NaN at the first NaN:
 *  the step is rejected). */
static double weighted_max(const double *state, const double *state_new, const double *other,
                           size_t n_pairs, double rtol, double atol, double factor) {
  double norm = 0.0;
  for (size_t p = 0; p < n_pairs; ++p) {
    const double c = state_new[2 * p];
    const double scale = atol + rtol * fmax(fabs(state[2 * p]), fabs(c));
    const double e = factor * fabs(c - other[2 * p]) / scale;
    if (isnan(e)) return e;
    if (e > norm) norm = e;
  }
  return norm;
}

double sp_scheme_error(sp_scheme_kind kind, const sp_history *h, double dt,
                       const double *state, const double *state_new, size_t n_pairs,
                       double rtol, double atol, double *scratch) {
  if (!sp_scheme_has_estimate(kind, h)) return -1.0;
  const double h0 = dt, h1 = h->dt[0];
  const int quadratic = kind == SP_SCHEME_BDF2 && h->n >= 2;
  double factor;
  if (quadratic) {
    const double h2 = h->dt[1];
    factor = h0 * (h0 + h1) /
             (3 * h0 * h0 + 4 * h0 * h1 + 2 * h0 * h2 + h1 * h1 + h1 * h2);
  } else {
    factor = h0 / (2 * h0 + h1);
  }
  sp_scheme_extrapolate(quadratic ? 2 : 1, h, dt, state, n_pairs, scratch);
  return weighted_max(state, state_new, scratch, n_pairs, rtol, atol, factor);
}

double sp_scheme_increment(const double *state, const double *state_new, size_t n_pairs,
                           double rtol, double atol) {
  return weighted_max(state, state_new, state, n_pairs, rtol, atol, 1.0);
}

double sp_scheme_first_dt_cells(const sp_layout *layout, const double *state,
                                const sp_model_params *model, double dt_cap,
                                const unsigned char *cells, double threshold) {
  const double alpha = model->alpha, lambda = model->lambda;
  double curvature = 0.0; /* the largest negative curvature L over the nodes */
  for (int i = 0; i < layout->n_nodes; ++i) {
    const int p0 = layout->node_start[i], p1 = layout->node_start[i + 1];
    double sum_sq = 0.0, sum_abs = 0.0;
    int counted = !cells; /* a node of one of @p cells */
    for (int p = p0; p < p1; ++p) {
      sum_sq += state[2 * p] * state[2 * p];
      sum_abs += fabs(state[2 * p]);
      if (cells && cells[layout->pair_cell[p]] && state[2 * p] >= threshold) counted = 1;
    }
    if (!counted) continue;
    for (int p = p0; p < p1; ++p) { /* Gershgorin: row k of the Hessian */
      const double c = state[2 * p];
      const double diag = 2 * alpha * (6 * c * c - 6 * c + 1) + 2 * lambda * (sum_sq - c * c);
      const double off = 4 * lambda * fabs(c) * (sum_abs - fabs(c));
      curvature = fmax(curvature, off - diag);
    }
  }
  if (!(curvature > 0)) return dt_cap;
  const double dt = SP_SCHEME_FIRST_SAFETY * 4 * model->kappa /
                    (model->mobility * curvature * curvature);
  return fmin(dt, dt_cap);
}

double sp_scheme_first_dt(const sp_layout *layout, const double *state,
                          const sp_model_params *model, double dt_cap) {
  return sp_scheme_first_dt_cells(layout, state, model, dt_cap, NULL, 0.0);
}
