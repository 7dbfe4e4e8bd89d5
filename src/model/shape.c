#include "model/shape.h"

#include <math.h>

#include "public/error.h"

/** The blend of n >= 2 coefficients of the file comment (shape.h, "Round
 *  cells"): W[i][j] = K_ij / sum_l K_il with K_ij = (1 - w_ij) / (1 + w_ij),
 *  w_ij = min(1, |I^i - I^j| / (tr I SP_SHAPE_ROUND_TOL)). */
static void round_blend(int n, const double *I, double trace, double W[3][3]) {
  for (int i = 0; i < n; ++i) {
    double sum = 0.0;
    for (int j = 0; j < n; ++j) {
      const double w = fmin(1.0, fabs(I[i] - I[j]) / (SP_SHAPE_ROUND_TOL * trace));
      W[i][j] = (1.0 - w) / (1.0 + w);
      sum += W[i][j];
    }
    for (int j = 0; j < n; ++j) W[i][j] /= sum;
  }
}

int sp_shape_coefficients(int dim, int n_cells, const sp_cell_obs *obs,
                          const sp_cell_birth *birth, const double delta[3],
                          sp_shape_coef *out) {
  SP_CHECK(dim == 2 || dim == 3, SP_ERR_INPUT,
           "shape coefficients: dimension %d, expected 2 or 3", dim);
  for (int i = 0; i < 3; ++i)
    SP_CHECK(delta[i] >= 0 && isfinite(delta[i]), SP_ERR_INPUT,
             "shape moduli must be >= 0 and finite (got delta%d = %g)", i + 1, delta[i]);
  SP_CHECK(dim == 3 || delta[2] == 0, SP_ERR_INPUT,
           "shape modulus delta3 is on the third principal moment, which a 2D cell has not "
           "(got %g, expected 0)", delta[2]);
  for (int k = 0; k < n_cells; ++k) {
    const sp_cell_obs *o = &obs[k];
    sp_shape_coef *s = &out[k];
    *s = (sp_shape_coef){.v = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    const double *I = o->moments;
    const double(*v)[3] = o->axes;
    double trace = I[0] + I[1];
    if (dim == 3) trace += I[2];
    int finite = isfinite(trace);
    for (int d = 0; d < 3; ++d) finite = finite && isfinite(o->centre[d]);
    for (int i = 0; i < dim; ++i) {
      finite = finite && isfinite(birth[k].Iref[i]);
      for (int d = 0; d < 3; ++d) finite = finite && isfinite(v[i][d]);
    }
    if (!finite || !(trace > 0)) continue; /* no core mass (or garbage): no force */
    double c[3] = {0, 0, 0};
    for (int i = 0; i < dim; ++i)
      c[i] = delta[i] > 0 ? 2.0 * delta[i] * (birth[k].Iref[i] - I[i]) : 0.0;
    s->xc = o->centre[0];
    s->yc = o->centre[1];
    s->zc = o->centre[2];
    for (int i = 0; i < dim; ++i)
      for (int d = 0; d < 3; ++d) s->v[i][d] = v[i][d];
    /* coef = W c, gain = W diag(2 delta) (W frozen) */
    double W[3][3];
    round_blend(dim, I, trace, W);
    for (int i = 0; i < dim; ++i) {
      s->coef[i] = 0.0;
      for (int j = 0; j < dim; ++j) {
        s->coef[i] += W[i][j] * c[j];
        s->gain[i][j] = W[i][j] * 2.0 * delta[j];
      }
    }
  }
  return SP_OK;
}

double sp_shape_energy(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                       const double delta[3]) {
  double energy = 0.0;
  for (int k = 0; k < n_cells; ++k) {
    const double *I = obs[k].moments;
    for (int i = 0; i < 3; ++i)
      if (delta[i] > 0) {
        const double gap = birth[k].Iref[i] - I[i];
        energy += delta[i] * gap * gap;
      }
  }
  return energy;
}
