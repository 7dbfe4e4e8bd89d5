/**
 * @file registry.h
 * @brief The cell registry: what the run knows of each cell besides its
 *        field, in one object with one lifecycle (sized by the layout
 *        change, resize.h, at set-up, division and checkpoint restore).
 *        Per cell: its observables, its birth (time, mass, reference
 *        moments, generation), its name and the normal of the cut that
 *        made it, its sister, its source switch, whether a due division
 *        was skipped, whether it divided this step; and the per-cell
 *        scratch of a step (the observables of the step's end, the core
 *        masses before it, the shape coefficients), so a step allocates
 *        nothing.
 */
#ifndef SP_REGISTRY_H
#define SP_REGISTRY_H

#include "public/cell_obs.h"
#include "model/division.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  int n;                  /**< cells */
  sp_cell_obs *obs;       /**< the observables of the run's state */
  sp_cell_birth *birth;
  int *source_on;         /**< the growth source is on (source.h) */
  int *division_skipped;  /**< due but N_max reached: reported once */
  unsigned char *divided_now; /**< parent or daughter of a division this
                                   step: its support may shrink */
  sp_cell_name *name;     /**< its name ("": none; the scene's cells[i].name,
                               the lineage table's daughters: lineage.h) */
  double (*cut_normal)[3]; /**< the unit normal of the cut that made it
                                (0 for an initial cell): the axis rule
                                perpendicular turns it */
  int *sister;            /**< its sister's index + 1 (the other daughter of
                               the division that made it), 0: none (an
                               initial cell, or the sister divided since):
                               adhesion.h */
  /* a step's scratch (contents undefined between steps) */
  sp_cell_obs *obs_new;   /**< the observables of the step's end */
  double *core_mass_old;  /**< the core masses before the step */
  double *core_mass;      /**< the core masses after it (the source switch) */
  sp_shape_coef *shape;   /**< the step's shape coefficients */
  sp_division_record *divisions; /**< the step's divisions (one a cell at most) */
} sp_registry;

/** @brief Size @p reg for @p n cells: entries kept up to min(old, n), the
 *         new ones zeroed. */
int sp_registry_resize(sp_registry *reg, int n);

/** @brief Free the registry's arrays (it is empty after). */
void sp_registry_free(sp_registry *reg);

#ifdef __cplusplus
}
#endif
#endif
