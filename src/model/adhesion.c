/* Adhesion between chosen pairs of cells (adhesion.h). */
#include "model/adhesion.h"

#include <stdio.h>

#include "public/error.h"

int sp_adhesion_on(const sp_adhesion_params *p) {
  return p->sisters > 0 || p->non_sisters > 0;
}

void sp_adhesion_table(const sp_adhesion_params *p, int n, const int *sister, double *table) {
  for (int k = 0; k < n; ++k)
    for (int l = 0; l < n; ++l)
      table[(size_t)n * k + l] = l == k                                       ? 0.0
                                 : sister[k] == l + 1 && sister[l] == k + 1 ? p->sisters
                                                                            : p->non_sisters;
}

int sp_adhesion_check(const sp_adhesion_params *p, const double *table, int n,
                      const sp_slots *slots, double kappa, const sp_cell_name *names) {
  double worst = 0.0;
  int worst_cell = -1, worst_elem = -1, worst_count = 0;
  for (int e = 0; e < slots->n_elems; ++e) {
    const int64_t s0 = slots->elem_start[e], s1 = slots->elem_start[e + 1];
    for (int64_t s = s0; s < s1; ++s) {
      const int k = slots->slot_cell[s];
      double sum = 0.0;
      for (int64_t t = s0; t < s1; ++t)
        if (t != s) sum += table[(size_t)n * k + slots->slot_cell[t]];
      if (sum > worst) {
        worst = sum;
        worst_cell = k;
        worst_elem = e;
        worst_count = (int)(s1 - s0);
      }
    }
  }
  if (worst < kappa) return SP_OK;
  char cell[SP_CELL_NAME_MAX + 32];
  if (names && names[worst_cell][0])
    snprintf(cell, sizeof cell, "cell %d (%s)", worst_cell + 1, names[worst_cell]);
  else
    snprintf(cell, sizeof cell, "cell %d", worst_cell + 1);
  return sp_error_set(SP_ERR_INPUT,
                      "model.adhesion_sisters = %.6g, model.adhesion_non_sisters = %.6g: on "
                      "element %d, where %d cells live, %s has adhesion summed over the "
                      "others of %.6g, not below model.kappa = %.6g (the gradient energy "
                      "would not be bounded below): lower the coefficients to below kappa "
                      "divided by the cells that meet on an element",
                      p->sisters, p->non_sisters, worst_elem, worst_count, cell, worst, kappa);
}
