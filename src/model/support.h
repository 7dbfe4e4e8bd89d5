/**
 * @file support.h
 * @brief Local supports (beyond the paper; docs/model.md "Beyond the paper"):
 *        each cell's field lives on the whole elements within a margin of
 *        its core (c_k >= core threshold), and the support follows the cell.
 *
 * A field's domain is a union of whole elements (the solver's rule), with a
 * natural no-flux boundary, so mass is conserved exactly between support
 * changes. When a cell's c_k exceeds the grow threshold within a band at
 * its support's edge, every support is recomputed from the current fields
 * (which may also shrink it); values move with (cell, node), new nodes get
 * the far-field value in equilibrium with the old edge's mean chemical
 * potential, relaxed to the far field's equations with layout.fill = relax
 * (far_field.h; sp_support_rebuild), and each cell's mass is then
 * restored exactly by one shift of its chemical potential over its whole
 * support (layout.restore = potential) or a uniform shift of c_k over its
 * interior c_k >= 1/2 (interior). The mass changes that shift corrects are
 * reported. With layout.buffer_elements = whole a support takes every
 * buffer-ring element one of its nodes touches, whole, so no edge node
 * sits beside the ring unheld by its term.
 */
#ifndef SP_SUPPORT_H
#define SP_SUPPORT_H

#include "mesh/layout.h"
#include "mesh/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_support_s *sp_support;

/** What new (cell, node) pairs of a support change start from. */
typedef enum {
  SP_SUPPORT_FILL_EDGE = 0, /**< the old edge's mean c at the node's stiffness */
  SP_SUPPORT_FILL_RELAX = 1 /**< that, relaxed to the far field's equations */
} sp_support_fill_kind;

/** Where a support change restores each cell's mass (the mass its fill
 *  added and its shrinking dropped). */
typedef enum {
  SP_SUPPORT_RESTORE_INTERIOR = 0, /**< a uniform shift of c_k where c_k >= 1/2 */
  SP_SUPPORT_RESTORE_POTENTIAL = 1 /**< delta x 2 alpha / (the node's stiffness), everywhere */
} sp_support_restore_kind;

/** Which buffer-ring elements a support takes (layout.buffer_elements). */
typedef enum {
  SP_SUPPORT_BUFFER_MARGIN = 0, /**< those the margin closes to whole elements */
  SP_SUPPORT_BUFFER_WHOLE = 1   /**< also every buffer element one of its nodes touches */
} sp_support_buffer_kind;

/** Parameters (lengths in the model's length unit). */
typedef struct {
  double margin;         /**< support = elements within this of the core */
  double core_threshold; /**< the core: nodes with c_k >= this */
  double grow_threshold; /**< grow when c_k >= this ... */
  double band;           /**< ... within this distance of the support edge */
  /* The model (for the far-field value new nodes start from): f''(0) =
   * 2 alpha, the repulsion lambda and the buffer ring's lambda_b. */
  double alpha, kappa, lambda, lambda_b;
  sp_support_fill_kind fill; /**< layout.fill */
  sp_support_restore_kind restore; /**< layout.restore */
  sp_support_buffer_kind buffer;   /**< layout.buffer_elements */
  int no_widening; /**< layout.widen false: supports as computed, also where
                        they would call for another update at once */
} sp_support_params;

/** @brief Bytes the support module holds: the elements around each node
 *  and its per-node scratch. */
double sp_support_bytes(const sp_support s);

/** @brief Node adjacency of a mesh and the parameters. */
int sp_support_create(const sp_mesh *mesh, const sp_support_params *params,
                      sp_support *out);

/**
 * @brief Support masks of every cell from its field: mask[k * n_nodes + i]
 *        is 1 when node i is in cell k's support. A cell with an empty core
 *        keeps its current support (so it cannot vanish). Writes
 *        cells x nodes bytes (tests; the set-up takes sp_support_initial,
 *        a step sp_support_rebuild).
 */
int sp_support_masks(sp_support s, const sp_layout *layout,
                     const double *state, unsigned char *mask);

/**
 * @brief Whether some cell's c_k >= grow_threshold within the band of its
 *        support's edge (the domain boundary is not an edge).
 * @param[out] needed 1 if so, else 0
 * @return SP_OK or SP_ERR_MEMORY (never "rebuild" on one rank alone: the
 *         answer feeds collectives, so every rank must give the same)
 */
int sp_support_needs_update(sp_support s, const sp_layout *layout,
                            const double *state, int *needed);

/**
 * @brief The values of @p state (on @p layout) on the layout @p to, each
 *        cell's mass not yet restored: kept pairs by (cell, node), new
 *        pairs the far field continued from the old edge
 *        (sp_support_rebuild's first half).
 */
int sp_support_fill(sp_support s, const sp_layout *layout, const double *state,
                    const sp_layout *to, double *next);

/**
 * @brief New supports from the fields, values moved to them, masses
 *        restored. @p new_layout and @p new_state are allocated here.
 *
 * A cell k with may_shrink[k] = 0 keeps every node of its old support (the
 * new one is the union of the old and the computed one). A support that
 * would already call for an update (sp_support_needs_update on the new
 * layout and state: a support closed to whole elements loses up to an
 * element's width of its margin, new nodes start from the far field) is
 * widened by layers of elements until it does not, so the supports just
 * rebuilt never call for another change before the cells move
 * (docs/local-support.md, "What differs from full supports"). Shrinking drops
 * the far field c_k keeps outside its cell (its Gibbs-Thomson level, not 0)
 * and puts that mass back into the cell, which costs mu x (mass) against
 * the f(c) x (area) removed: the energy rises (docs/local-support.md).
 * Growing does the opposite and lowers it.
 *
 * @param[in] may_shrink n_cells flags (NULL: every cell may shrink)
 * @param[out] mass_correction largest |mass change before correction| /
 *             mass over the cells (what the shift restored)
 * @param[out] mass_dropped |total mass after - total mass before| / total
 *             mass before, with the total mass the integral of sum_k c_k
 *             (what the change lost or gained in the end: round-off)
 */
int sp_support_rebuild(sp_support s, const sp_layout *layout,
                       const double *state, const unsigned char *may_shrink,
                       sp_layout **new_layout, double **new_state,
                       double *mass_correction, double *mass_dropped);

/**
 * @brief The supports computed from the fields (sp_support_masks' rule;
 *        with may_shrink[k] = 0 the union with cell k's current support),
 *        closed to whole elements, as a new layout. Costs the pairs and the
 *        nodes the searches reach, not cells x nodes.
 * @param[in] may_shrink n_cells flags (NULL: every cell may shrink)
 */
int sp_support_layout(sp_support s, const sp_layout *layout, const double *state,
                      const unsigned char *may_shrink, sp_layout **out);

/**
 * @brief The set-up's supports: sp_support_layout's from the fields on
 *        @p layout (every cell may shrink), each cell's widened by layers
 *        of elements while, with the fields cut to it, it would call for
 *        an update at once (as sp_support_rebuild widens; coarse meshes),
 *        so the first step does not change them again.
 * @param[out] out_state the fields cut to them ((c, mu) per pair of *out;
 *             the caller frees it)
 */
int sp_support_initial(sp_support s, const sp_layout *layout, const double *state,
                       sp_layout **out, double **out_state);

/** @brief Layout from per-cell masks, with every cell's mask closed to
 *         whole elements (no node without a whole element of its cell). */
int sp_support_layout_from_masks(sp_support s, int n_cells,
                                 unsigned char *mask, sp_layout **out);

void sp_support_destroy(sp_support *s);

#ifdef __cplusplus
}
#endif
#endif
