#include "shape.h"

#include <math.h>

#include "error.h"

int sp_shape_coefficients(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                          double delta1, double delta2, sp_shape_coef *out) {
  SP_CHECK(delta1 >= 0 && isfinite(delta1) && delta2 >= 0 && isfinite(delta2), SP_ERR_INPUT,
           "shape moduli must be >= 0 and finite (got delta1 = %g, delta2 = %g)", delta1,
           delta2);
  const double delta[2] = {delta1, delta2};
  for (int k = 0; k < n_cells; ++k) {
    const sp_cell_obs *o = &obs[k];
    sp_shape_coef *s = &out[k];
    *s = (sp_shape_coef){.xc = 0, .yc = 0, .v = {{1, 0}, {0, 1}}, .coef = {0, 0},
                         .gain = {{0, 0}, {0, 0}}};
    const double I[2] = {o->I1, o->I2};
    const double trace = I[0] + I[1];
    const int finite = isfinite(o->xc) && isfinite(o->yc) && isfinite(trace) &&
                       isfinite(birth[k].Iref[0]) && isfinite(birth[k].Iref[1]) &&
                       isfinite(o->v1[0]) && isfinite(o->v1[1]) && isfinite(o->v2[0]) &&
                       isfinite(o->v2[1]);
    if (!finite || !(trace > 0)) continue; /* no core mass (or garbage): no force */
    double c[2];
    for (int i = 0; i < 2; ++i)
      c[i] = delta[i] > 0 ? 2.0 * delta[i] * (birth[k].Iref[i] - I[i]) : 0.0;
    /* anisotropy e in [0, 1]; the deviatoric part fades out below the tolerance */
    const double e = fmax(0.0, (I[0] - I[1]) / trace);
    const double w = fmin(1.0, e / SP_SHAPE_ROUND_TOL);
    const double mean = 0.5 * (c[0] + c[1]), half_diff = 0.5 * (c[0] - c[1]);
    s->xc = o->xc;
    s->yc = o->yc;
    s->v[0][0] = o->v1[0];
    s->v[0][1] = o->v1[1];
    s->v[1][0] = o->v2[0];
    s->v[1][1] = o->v2[1];
    s->coef[0] = mean + w * half_diff;
    s->coef[1] = mean - w * half_diff;
    /* coef = W c with W = [[1+w, 1-w], [1-w, 1+w]] / 2 and dc_j/dI_j =
     * -2 delta^j: gain = -dcoef/dI = W diag(2 delta) (w frozen) */
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        s->gain[i][j] = 0.5 * (i == j ? 1.0 + w : 1.0 - w) * 2.0 * delta[j];
  }
  return SP_OK;
}

double sp_shape_energy(int n_cells, const sp_cell_obs *obs, const sp_cell_birth *birth,
                       double delta1, double delta2) {
  const double delta[2] = {delta1, delta2};
  double energy = 0.0;
  for (int k = 0; k < n_cells; ++k) {
    const double I[2] = {obs[k].I1, obs[k].I2};
    for (int i = 0; i < 2; ++i)
      if (delta[i] > 0) {
        const double gap = birth[k].Iref[i] - I[i];
        energy += delta[i] * gap * gap;
      }
  }
  return energy;
}
