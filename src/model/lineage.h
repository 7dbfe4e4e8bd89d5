/**
 * @file lineage.h
 * @brief The lineage table (the scene's `lineage:`, docs/embryo.md): named
 *        cells that divide on their own schedule (an age, an absolute time
 *        or a mass ratio), asymmetrically (the first daughter's share of the
 *        parent's mass) and along their own axis rule (the long axis, a
 *        fixed direction, or perpendicular to the parent's cut), into named
 *        daughters. Cells without an entry follow the scene's `division:`.
 *
 * Pure building blocks, like division.h: the events (events.c) ask whether
 * a named cell's entry is due, which normal its cut has, and give the
 * daughters their names. The scene reader has checked the table (names
 * known and unique, no cycle, one criterion per entry, a fixed axis's
 * direction nonzero).
 *
 * Vectors have 3 components; a 2D mesh uses the first 2 (z = 0).
 */
#ifndef SP_LINEAGE_H
#define SP_LINEAGE_H

#include "public/cell_obs.h"
#include "model/division.h"
#include "scene/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** When an entry's cell divides. */
typedef enum {
  SP_LINEAGE_AGE = 0,  /**< at an age (t - its birth time) */
  SP_LINEAGE_TIME = 1, /**< at an absolute time */
  SP_LINEAGE_MASS = 2  /**< at a multiple of its birth core mass */
} sp_lineage_when;

/** One entry, resolved from the scene. */
typedef struct {
  sp_cell_name cell, first, second;
  sp_lineage_when when;
  double value;        /**< the age, the time or the mass ratio */
  double fraction;     /**< the first daughter's share of the parent's mass */
  sp_axis_kind axis;
  double direction[3]; /**< axis fixed: the unit normal */
} sp_lineage_entry;

/** A named pair with an adhesion coefficient of its own (adhesion.h). */
typedef struct {
  sp_cell_name cell, other;
  double sigma;
} sp_lineage_pair;

/** The table. */
typedef struct {
  int n;
  sp_lineage_entry *entry;
  int named; /**< the scene names its cells: the CSV logs get name columns */
  int n_pairs;           /**< the scene's adhesion pairs (0: none) */
  sp_lineage_pair *pair;
} sp_lineage;

/** @brief The table of a checked scene (an empty one when it has none),
 *         with its named adhesion pairs. */
int sp_lineage_from_scene(const sp_scene *scene, sp_lineage *out);

/** @brief Free the table (it is empty after). */
void sp_lineage_free(sp_lineage *lineage);

/** @brief The entry of the cell named @p name, or NULL (also for ""). */
const sp_lineage_entry *sp_lineage_find(const sp_lineage *lineage, const char *name);

/** @brief The division criterion of an age or mass entry as division.h's
 *         parameters (with @p tolerance, as sp_division_params.tolerance);
 *         a time entry gives an age criterion of its time minus the birth
 *         time (0 when born at or after it: due at once). */
sp_division_params sp_lineage_params(const sp_lineage_entry *e, const sp_cell_birth *birth,
                                     double tolerance);

/** @brief Whether the entry's division is due at @p t with core mass
 *         @p mass (sp_division_due with sp_lineage_params). */
int sp_lineage_due(const sp_lineage_entry *e, const sp_cell_birth *birth, double t, double mass,
                   double tolerance);

/** @brief The time an age or time entry's cell divides (INFINITY for a
 *         mass entry), for the steps to land on. */
double sp_lineage_due_time(const sp_lineage_entry *e, const sp_cell_birth *birth);

/**
 * @brief The unit normal of the cut of the entry's cell (NULL @p e: the
 *        paper's, the long axis as it is).
 *
 * - long: @p long_axis (the cell's long principal axis);
 * - fixed: the entry's direction;
 * - perpendicular: perpendicular to @p parent_normal p (the normal of the
 *   cut that made the cell): in 2D p turned by 90 degrees; in 3D the one
 *   closest to @p long_axis l, l - (l . p) p normalised (the long axis
 *   projected on the plane normal to p; orthogonal to p to round-off).
 *   When that projection is shorter than 1e-6 (l within 1e-6 rad of p: the
 *   cell is longest along its parent's normal and names no direction in
 *   that plane), the fallback is p crossed with the coordinate axis least
 *   along p, normalised. A zero @p parent_normal gives long.
 * long and perpendicular are oriented so that the first component above
 * 1e-9 in size (x, then y, then z) is positive: the first daughter (on the
 * side the normal points away from) is the one at lower x. fixed keeps the
 * user's sign.
 */
void sp_lineage_normal(const sp_lineage_entry *e, int dim, const double long_axis[3],
                       const double parent_normal[3], double normal[3]);

/**
 * @brief The cut's geometry as division.h reads it from a cell's
 *        observables: the cut normal of @p obs (sp_division_plane's: the
 *        long axis) into @p normal, and the converse, @p obs made to give
 *        @p normal (its long axis set to it).
 */
void sp_lineage_obs_normal(const sp_cell_obs *obs, int dim, double normal[3]);
void sp_lineage_set_obs_normal(sp_cell_obs *obs, const double normal[3]);

/** @brief The daughters' names of a division of the cell named @p parent:
 *         its entry's first and second; without an entry "<parent>.1" and
 *         "<parent>.2" when they fit SP_CELL_NAME_MAX, else "" (unnamed
 *         too for an unnamed parent). */
void sp_lineage_daughter_names(const sp_lineage_entry *e, const char *parent, sp_cell_name first,
                               sp_cell_name second);

#ifdef __cplusplus
}
#endif
#endif
