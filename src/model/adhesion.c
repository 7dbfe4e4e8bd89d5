/* Adhesion between chosen pairs of cells (adhesion.h). */
#include "model/adhesion.h"

#include <stdio.h>
#include <string.h>

#include "public/error.h"

int sp_adhesion_on(const sp_adhesion_params *p) {
  int on = p->sisters > 0 || p->non_sisters > 0;
  for (int i = 0; i < p->n_pairs; ++i) on |= p->pair[i].sigma > 0;
  return on;
}

/** The cell named @p name among @p n (-1: none). */
static int cell_named(int n, const sp_cell_name *names, const char *name) {
  for (int k = 0; k < n; ++k)
    if (strcmp(names[k], name) == 0) return k;
  return -1;
}

void sp_adhesion_table(const sp_adhesion_params *p, int n, const int *sister,
                       const sp_cell_name *names, double *table) {
  for (int k = 0; k < n; ++k)
    for (int l = 0; l < n; ++l)
      table[(size_t)n * k + l] = l == k                                       ? 0.0
                                 : sister[k] == l + 1 && sister[l] == k + 1 ? p->sisters
                                                                            : p->non_sisters;
  if (!names) return;
  for (int i = 0; i < p->n_pairs; ++i) {
    const int k = cell_named(n, names, p->pair[i].cell),
              l = cell_named(n, names, p->pair[i].other);
    if (k < 0 || l < 0) continue; /* not both alive (yet, or any more) */
    table[(size_t)n * k + l] = table[(size_t)n * l + k] = p->pair[i].sigma;
  }
}

int sp_adhesion_check(const sp_adhesion_params *p, const double *table, int n,
                      const sp_slots *slots, double kappa, const sp_cell_name *names,
                      double *largest) {
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
  *largest = worst;
  if (worst < kappa) return SP_OK;
  char cell[SP_CELL_NAME_MAX + 32];
  if (names && names[worst_cell][0])
    snprintf(cell, sizeof cell, "cell %d (%s)", worst_cell + 1, names[worst_cell]);
  else
    snprintf(cell, sizeof cell, "cell %d", worst_cell + 1);
  return sp_error_set(SP_ERR_INPUT,
                      "model.adhesion_sisters = %.6g, model.adhesion_non_sisters = %.6g%s: "
                      "on element %d, where %d cells live, %s has adhesion summed over the "
                      "others of %.6g, not below model.kappa = %.6g (the gradient energy "
                      "would not be bounded below): lower the coefficients to below kappa "
                      "divided by the cells that meet on an element",
                      p->sisters, p->non_sisters,
                      p->n_pairs ? " and the named pairs' adhesion[i].sigma" : "", worst_elem,
                      worst_count, cell, worst, kappa);
}
