#include "model/division.h"

#include <math.h>
#include <stdlib.h>

#include "public/error.h"

/** Relative slack of sp_division_max_cells' rounding down. */
#define SP_DIVISION_MAX_CELLS_SLACK 1e-9

/** Largest exponent m of algorithm 2 whose powers stay exact in double. */
#define SP_DIVISION_DT_MAX_EXPONENT 15

/** Steps of the algorithm-2 ramp: ((a - n_div) / 10)^m reaches 1 here. */
#define SP_DIVISION_DT_RAMP_STEPS 10

int sp_division_params_check(const sp_division_params *params) {
  SP_CHECK(params->criterion == SP_DIVIDE_AGE || params->criterion == SP_DIVIDE_MASS,
           SP_ERR_INPUT, "division criterion must be age or mass (got %d)",
           (int)params->criterion);
  if (params->criterion == SP_DIVIDE_AGE)
    SP_CHECK(params->age > 0 && isfinite(params->age), SP_ERR_INPUT,
             "division age T_div must be positive and finite (got %g)", params->age);
  else {
    SP_CHECK(params->mass_ratio > 0 && isfinite(params->mass_ratio), SP_ERR_INPUT,
             "division mass ratio must be positive and finite (got %g)", params->mass_ratio);
    SP_CHECK(params->reference_mass >= 0 && isfinite(params->reference_mass), SP_ERR_INPUT,
             "division reference mass must be >= 0 (0: each cell's birth mass; got %g)",
             params->reference_mass);
  }
  SP_CHECK(params->tolerance >= 0 && params->tolerance < 1, SP_ERR_INPUT,
           "division tolerance must be in [0, 1) (got %g)", params->tolerance);
  return SP_OK;
}

sp_cell_birth sp_cell_birth_make(double t, const sp_cell_obs *obs, int generation) {
  sp_cell_birth birth = {.birth_time = t, .birth_mass = obs->mass,
                         .Iref = {obs->moments[0], obs->moments[1], obs->moments[2]}, .generation = generation};
  return birth;
}

/** The quantity a criterion watches at (t, mass) and its threshold. */
static void watched(const sp_division_params *params, const sp_cell_birth *birth, double t,
                    double mass, double *quantity, double *threshold) {
  if (params->criterion == SP_DIVIDE_AGE) {
    *quantity = t - birth->birth_time;
    *threshold = params->age;
  } else {
    *quantity = mass;
    const double reference = params->reference_mass > 0 ? params->reference_mass
                                                        : birth->birth_mass;
    *threshold = params->mass_ratio * reference;
  }
}

/** The threshold relaxed by the tolerance: reaching it makes a division due. */
static double due_level(const sp_division_params *params, double threshold) {
  return threshold * (1.0 - params->tolerance - SP_DIVISION_ROUNDOFF);
}

int sp_division_due(const sp_division_params *params, const sp_cell_birth *birth,
                    double t_old, double t_new, double mass_old, double mass_new) {
  (void)t_old;
  (void)mass_old; /* at or above at t_new covers crossed and already exceeded */
  double quantity, threshold;
  watched(params, birth, t_new, mass_new, &quantity, &threshold);
  return quantity >= due_level(params, threshold);
}

double sp_division_threshold(const sp_division_params *params, const sp_cell_birth *birth) {
  double quantity, threshold;
  watched(params, birth, 0.0, 0.0, &quantity, &threshold);
  return threshold;
}

double sp_division_crossing_fraction(const sp_division_params *params,
                                     const sp_cell_birth *birth, double t_old,
                                     double t_new, double mass_old,
                                     double mass_new) {
  double q_old, q_new, threshold;
  watched(params, birth, t_old, mass_old, &q_old, &threshold);
  watched(params, birth, t_new, mass_new, &q_new, &threshold);
  if (q_old >= due_level(params, threshold)) return 0.0;
  if (q_new <= threshold) return 1.0; /* q_new > threshold > q_old below */
  const double theta = (threshold - q_old) / (q_new - q_old);
  return theta < 0 ? 0.0 : theta > 1 ? 1.0 : theta;
}

void sp_division_plane(const sp_cell_obs *obs, int dim, double point[3], double normal[3]) {
  for (int d = 0; d < 3; ++d) {
    point[d] = d < dim ? obs->centre[d] : 0.0;
    normal[d] = d < dim ? obs->axes[obs->long_axis][d] : 0.0;
  }
}

/** Signed distance n . (X_i - P) of node i from the cut through P normal
 *  to n. */
static double node_distance(const sp_mesh *mesh, int i, const double point[3],
                            const double normal[3]) {
  const double *x = mesh->xy + (size_t)mesh->dim * i;
  double sd = 0.0;
  for (int d = 0; d < mesh->dim; ++d) sd += normal[d] * (x[d] - point[d]);
  return sd;
}

double sp_division_child_share(double sd, int smooth, double width, double on_line) {
  if (smooth) return 1.0 / (1.0 + exp(-sd / width));
  if (sd > on_line) return 1.0;
  if (sd < -on_line) return 0.0;
  return 0.5; /* on the line: half each, so a symmetric cell halves exactly */
}

int sp_division_split(const sp_mesh *mesh, const sp_layout *layout,
                      const double *state, int parent,
                      const sp_cell_obs *parent_obs, int smooth, double width,
                      double offset, const sp_layout *new_layout, double *new_state,
                      int child) {
  SP_CHECK(layout->n_nodes == mesh->n_nodes && new_layout->n_nodes == mesh->n_nodes,
           SP_ERR_INTERNAL, "division split: layouts have %d and %d nodes, the mesh %d",
           layout->n_nodes, new_layout->n_nodes, mesh->n_nodes);
  SP_CHECK(parent >= 0 && parent < layout->n_cells, SP_ERR_INTERNAL,
           "division split: parent %d is not a cell (%d cells)", parent, layout->n_cells);
  SP_CHECK(child == layout->n_cells && new_layout->n_cells == layout->n_cells + 1,
           SP_ERR_INTERNAL,
           "division split: the child must be the new last cell %d of a layout with "
           "one more cell (got child %d, %d -> %d cells)",
           layout->n_cells, child, layout->n_cells, new_layout->n_cells);
  SP_CHECK(!smooth || (width > 0 && isfinite(width)), SP_ERR_INTERNAL,
           "division split: the smoothed cut needs a positive width (got %g)", width);

  /* Every cell, the parent included, by (cell, node); the child is absent
   * from the old layout, so its pairs start at c = mu = 0. */
  sp_layout_transfer(layout, state, new_layout, new_state, 0.0);

  double point[3], normal[3];
  sp_division_plane(parent_obs, mesh->dim, point, normal);
  const double on_line = SP_DIVISION_ON_LINE_FRACTION * mesh->h;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p_old = sp_layout_pair(layout, parent, i);
    if (p_old < 0) continue;
    const double sd = node_distance(mesh, i, point, normal) - offset;
    const double share = sp_division_child_share(sd, smooth, width, on_line);
    const double c = state[2 * p_old], mu = state[2 * p_old + 1];
    /* parent = c - child, not c (1 - H): the two then add up to c. */
    const double c_child = c * share, c_parent = c - c_child;
    const double mu_child = mu * share, mu_parent = mu - mu_child;
    const int p_parent = sp_layout_pair(new_layout, parent, i);
    const int p_child = sp_layout_pair(new_layout, child, i);
    SP_CHECK(p_child >= 0 || c_child == 0.0, SP_ERR_INTERNAL,
             "division split: node %d (%g, %g) has no pair of the child %d but receives "
             "c = %g from parent %d: the child's support must cover the parent's side",
             i, mesh->xy[(size_t)mesh->dim * i], mesh->xy[(size_t)mesh->dim * i + 1], child,
             c_child, parent);
    SP_CHECK(p_parent >= 0 || c_parent == 0.0, SP_ERR_INTERNAL,
             "division split: node %d (%g, %g) has no pair of the parent %d in the new "
             "layout but keeps c = %g", i, mesh->xy[(size_t)mesh->dim * i],
             mesh->xy[(size_t)mesh->dim * i + 1], parent, c_parent);
    if (p_child >= 0) {
      new_state[2 * p_child] = c_child;
      new_state[2 * p_child + 1] = mu_child;
    }
    if (p_parent >= 0) {
      new_state[2 * p_parent] = c_parent;
      new_state[2 * p_parent + 1] = mu_parent;
    }
  }
  return SP_OK;
}

/** Bisection steps of sp_division_balance_offset: the bracket (the cell's
 *  extent plus a margin) shrinks by 2^-60, below round-off. */
#define SP_DIVISION_BALANCE_STEPS 60

/** Margin of the bracket, in smoothed-cut widths: H(+-40) differs from 1, 0
 *  by 4e-18. */
#define SP_DIVISION_BALANCE_MARGIN 40.0

/** The child's mass for the line shifted by s (sp_division_balance_offset). */
static double child_mass(int n, const double *w, const double *c, const double *sd,
                         double s, int smooth, double width, double on_line) {
  double m = 0;
  for (int j = 0; j < n; ++j)
    m += w[j] * c[j] * sp_division_child_share(sd[j] - s, smooth, width, on_line);
  return m;
}

int sp_division_balance_offset(const sp_mesh *mesh, const sp_layout *layout,
                               const double *state, int parent,
                               const sp_cell_obs *parent_obs, int smooth, double width,
                               double fraction, double *offset) {
  *offset = 0.0;

  /* w_i = int phi_i over the parent's whole elements (sp_cells_observe's rule) */
  const size_t nn = (size_t)mesh->n_nodes;
  double *buffer; /* one block: nothing leaks on the error return */
  SP_ALLOC(buffer, 4 * nn);
  double *w_node = buffer, *w = buffer + nn, *c = buffer + 2 * nn, *sd = buffer + 3 * nn;
  const int rc = sp_cells_node_weights(mesh, layout, parent, w_node);
  if (rc != SP_OK) {
    free(buffer);
    return rc;
  }
  /* the parent's nodes: weight, value, signed distance from the centre cut */
  int n = 0;
  double point[3], normal[3];
  sp_division_plane(parent_obs, mesh->dim, point, normal);
  double lo = 0, hi = 0, total = 0;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const int p = sp_layout_pair(layout, parent, i);
    if (p < 0 || w_node[i] == 0) continue;
    w[n] = w_node[i];
    c[n] = state[2 * p];
    sd[n] = node_distance(mesh, i, point, normal);
    total += w[n] * c[n];
    if (sd[n] < lo) lo = sd[n];
    if (sd[n] > hi) hi = sd[n];
    ++n;
  }
  const double margin = smooth ? SP_DIVISION_BALANCE_MARGIN * width : mesh->h;
  lo -= margin;
  hi += margin;
  const double on_line = SP_DIVISION_ON_LINE_FRACTION * mesh->h;
  /* M(lo) ~ total > fraction total > M(hi) ~ 0: keep M(lo) >= target >= M(hi) */
  const double target = fraction * total;
  double m_lo = child_mass(n, w, c, sd, lo, smooth, width, on_line);
  double m_hi = child_mass(n, w, c, sd, hi, smooth, width, on_line);
  for (int it = 0; it < SP_DIVISION_BALANCE_STEPS && m_lo >= target && m_hi <= target; ++it) {
    const double mid = 0.5 * (lo + hi);
    const double m_mid = child_mass(n, w, c, sd, mid, smooth, width, on_line);
    if (m_mid >= target) { lo = mid; m_lo = m_mid; }
    else { hi = mid; m_hi = m_mid; }
  }
  *offset = fabs(m_lo - target) <= fabs(m_hi - target) ? lo : hi;
  free(buffer);
  return SP_OK;
}

void sp_division_record_births(double t, const sp_cell_obs *obs, int parent, int child,
                               sp_cell_birth *registry) {
  const int generation = registry[parent].generation + 1;
  registry[parent] = sp_cell_birth_make(t, &obs[parent], generation);
  registry[child] = sp_cell_birth_make(t, &obs[child], generation);
}

/** x^n for a small integer n >= 0, by repeated products: exact while the
 *  result is an integer below 2^53. */
static double integer_power(double x, int n) {
  double result = 1.0;
  for (int j = 0; j < n; ++j) result *= x;
  return result;
}

double sp_division_dt(double dt_bar, int n_div, int m, int steps_since_division) {
  const int a = steps_since_division;
  if (a <= 0 || m <= 0) return dt_bar;
  if (n_div < 0) n_div = 0;
  if (m > SP_DIVISION_DT_MAX_EXPONENT) m = SP_DIVISION_DT_MAX_EXPONENT;
  const int ramp = a <= n_div ? 1 : a - n_div;
  if (ramp >= SP_DIVISION_DT_RAMP_STEPS) return dt_bar;
  /* dt_bar 10^-m ramp^m as dt_bar x (one correctly rounded quotient of two
   * exact integers): for dt_bar = 1 this is the double nearest to the
   * decimal value, e.g. exactly 6.4e-5 for m = 6, ramp = 2. */
  return dt_bar * (integer_power(ramp, m) / integer_power(10.0, m));
}

int sp_division_max_cells(double area_omega, double birth_mass) {
  if (!(area_omega > 0) || !(birth_mass > 0) || !isfinite(area_omega) ||
      !isfinite(birth_mass))
    return 0;
  const double cells = floor(area_omega / birth_mass * (1.0 + SP_DIVISION_MAX_CELLS_SLACK));
  if (cells < 1) return 1;
  if (cells > 1e9) return 1000000000; /* a tiny m^0: no practical limit */
  return (int)cells;
}
