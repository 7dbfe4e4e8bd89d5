/**
 * @file adhesion.h
 * @brief Adhesion between chosen pairs of cells (docs/model.md,
 *        "Adhesion"): the energy sum_{k<l} sigma_kl int grad c_k . grad c_l,
 *        sigma_kl from the lineage: the scene's adhesion table for its named
 *        pairs (adhesion[i]: cell, other, sigma), else model.adhesion_sisters
 *        for the two daughters of one division, model.adhesion_non_sisters
 *        for any other pair.
 *
 * Pure building blocks: the run keeps the table of its cells
 * (sp_model_params.adhesion, which the glue reads) and rebuilds it when its
 * cells or layout change (resize.h).
 */
#ifndef SP_ADHESION_H
#define SP_ADHESION_H

#include "mesh/layout.h"
#include "model/lineage.h"
#include "public/cell_obs.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The scene's coefficients (E L^2, as kappa). */
typedef struct {
  double sisters;     /**< sigma of two daughters of one division */
  double non_sisters; /**< sigma of every other pair */
  int n_pairs;        /**< named pairs with a sigma of their own */
  const sp_lineage_pair *pair; /**< borrowed (the lineage table's) */
} sp_adhesion_params;

/** @brief Whether @p p adds anything (a coefficient above 0). */
int sp_adhesion_on(const sp_adhesion_params *p);

/**
 * @brief The n x n table of @p n cells: table[n k + l] = sigma_kl,
 *        symmetric, 0 on the diagonal: a named pair's sigma when k and l
 *        carry its names, else the sisters' or the non-sisters'.
 * @param[in] sister per cell, its sister's index + 1 (0: none; as the
 *            registry keeps it)
 * @param[in] names per cell, its name ("": none; NULL: no names)
 */
void sp_adhesion_table(const sp_adhesion_params *p, int n, const int *sister,
                       const sp_cell_name *names, double *table);

/**
 * @brief The bound that keeps the gradient energy bounded below: on every
 *        element of @p slots, for every cell k living there, the sum of
 *        sigma_kl over the other cells l living there is below @p kappa
 *        (docs/model.md, "Adhesion": kappa Id + sigma is then diagonally
 *        dominant on the element). SP_ERR_INPUT naming the scene's keys,
 *        the cell (its name from @p names when not NULL) and the sum when
 *        it is not.
 * @param[out] largest the largest such sum (kappa minus it bounds the
 *             gradient energy's coefficient from below)
 */
int sp_adhesion_check(const sp_adhesion_params *p, const double *table, int n,
                      const sp_slots *slots, double kappa, const sp_cell_name *names,
                      double *largest);

#ifdef __cplusplus
}
#endif
#endif
