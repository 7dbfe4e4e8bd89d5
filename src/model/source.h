/**
 * @file source.h
 * @brief The adaptive growth source (docs/model.md "Growth source", the paper's
 *        algorithm 3): s_k = s_bar inside omega_k, 0 outside, and switched
 *        off for good once no new cell can be created and the cell has grown
 *        past ratio_off x its birth mass.
 *
 * In the time loop: after every accepted step (and after divisions),
 * sp_source_update_switch with the current cell count and masses; before
 * every step, sp_source_fill from c^n into the per-pair array handed to the
 * solver (sp_step_data.source), which interpolates the nodal values.
 */
#ifndef SP_SOURCE_H
#define SP_SOURCE_H

#include "model/division.h"
#include "mesh/layout.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The paper's switch-off mass ratio nu_k = m_k / m_k^0 (algorithm 3). */
#define SP_SOURCE_RATIO_OFF_PAPER 1.1

/** A cell's interior omega_k is where c_k >= 1/2: its membrane is the 1/2
 *  level set (docs/model.md "Fields and energy"). */
#define SP_SOURCE_INTERIOR_LEVEL 0.5

/**
 * @brief Nodal source values of every (cell, node) pair from c^n.
 *
 * source_per_pair[p] = s_bar where the pair's cell has its source on and
 * c^n >= 1/2 at the pair's node, else 0. The indicator is evaluated with
 * c^n, not c^{n+1}: a source that switches with the unknown would make the
 * Newton residual non-smooth (docs/model.md).
 *
 * @param[in] layout the pairs
 * @param[in] state_old c^n, mu^n in layout order (2 n_pairs values)
 * @param[in] n_cells layout->n_cells (checked: the switch array's length)
 * @param[in] source_on per cell, nonzero when its source is on (NULL: all on)
 * @param[in] s_bar the source rate s_bar
 * @param[out] source_per_pair n_pairs values
 * @return SP_OK; SP_ERR_INTERNAL when n_cells does not match the layout
 */
int sp_source_fill(const sp_layout *layout, const double *state_old, int n_cells,
                   const int *source_on, double s_bar, double *source_per_pair);

/**
 * @brief Switch off the source of every cell k with n_cells >= n_max and
 *        m_k / m_k^0 > ratio_off (both: a cell that can still divide keeps
 *        growing; a cell that cannot stops once it has grown a little past its
 *        birth size). The switch-off is permanent: a switched-off cell is
 *        never switched on again here, whatever the masses or the count do
 *        later. A new cell should inherit its parent's switch.
 * @param[in] n_cells the current number of cells N
 * @param[in] n_max N_max (sp_division_max_cells, or the scene's)
 * @param[in] mass per cell m_k (the same mass measure as birth_mass)
 * @param[in] birth per cell, m_k^0 = birth[k].birth_mass
 * @param[in,out] source_on per cell switch
 * @param[in] ratio_off the mass ratio above which the source stops (paper 1.1)
 * @return SP_OK; SP_ERR_INTERNAL for a negative n_cells or a ratio_off that
 *         is not positive. (Which cells this call switched off: compare
 *         source_on before and after.)
 */
int sp_source_update_switch(int n_cells, int n_max, const double *mass,
                            const sp_cell_birth *birth, int *source_on,
                            double ratio_off);

#ifdef __cplusplus
}
#endif
#endif
