#include "model/source.h"

#include "public/error.h"

int sp_source_fill(const sp_layout *layout, const double *state_old, int n_cells,
                   const int *source_on, double s_bar, double *source_per_pair) {
  SP_CHECK(n_cells == layout->n_cells, SP_ERR_INTERNAL,
           "source: %d cell switches for a layout of %d cells", n_cells, layout->n_cells);
  for (int p = 0; p < layout->n_pairs; ++p) {
    const int cell = layout->pair_cell[p];
    const int on = source_on ? source_on[cell] != 0 : 1;
    const int inside = state_old[2 * p] >= SP_SOURCE_INTERIOR_LEVEL;
    source_per_pair[p] = on && inside ? s_bar : 0.0;
  }
  return SP_OK;
}

int sp_source_update_switch(int n_cells, int n_max, const double *mass,
                            const sp_cell_birth *birth, int *source_on,
                            double ratio_off) {
  SP_CHECK(n_cells >= 0, SP_ERR_INTERNAL, "source switch: %d cells", n_cells);
  SP_CHECK(ratio_off > 0, SP_ERR_INTERNAL,
           "source switch: the switch-off mass ratio must be positive (got %g)", ratio_off);
  if (n_cells < n_max) return SP_OK; /* room for more cells: everyone grows */
  for (int k = 0; k < n_cells; ++k)
    /* m_k > ratio_off m_k^0, written without dividing by m_k^0 */
    if (source_on[k] && mass[k] > ratio_off * birth[k].birth_mass) source_on[k] = 0;
  return SP_OK;
}
