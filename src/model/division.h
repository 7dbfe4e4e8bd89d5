/**
 * @file division.h
 * @brief Cell division (docs/model.md "Division", paper section 2.3, algorithms 1
 *        and 2): the per-cell birth record, the crossing-safe criteria (age,
 *        mass), the division axis, the split of one field into two, the
 *        paper's time-step sequence after a division and N_max.
 *
 * Pure building blocks: nothing here decides *when* the time loop divides
 * (the stepper does). A division in the loop reads:
 *
 *   1. after an accepted step t_old -> t_new, for each cell k:
 *        sp_division_due(&params, &birth[k], t_old, t_new, m_old[k], m_new[k]);
 *      optionally redo the step with dt * sp_division_crossing_fraction(...)
 *      to land on the crossing (then count it as due, see
 *      sp_division_params.tolerance);
 *   2. if N < N_max (sp_division_max_cells): build a layout with N + 1 cells
 *      whose cell N has (at least) the parent's support, and call
 *      sp_division_split(..., parent, &obs[parent], ..., child = N);
 *   3. observe the new state and sp_division_record_births(t, ...) for the
 *      parent and the child;
 *   4. take the next steps with dt = sp_division_dt(dt_bar, n_div, m, a),
 *      a = 1, 2, ... counting the steps after the division.
 */
#ifndef SP_DIVISION_H
#define SP_DIVISION_H

#include "model/cells.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The paper's mass criterion: a cell divides at twice its birth mass. */
#define SP_DIVISION_MASS_RATIO_PAPER 2.0

/** Relative slack within which a threshold counts as reached even with
 *  sp_division_params.tolerance = 0: t = 0.1 + ... + 0.1 (ten times) is
 *  0.9999999999999999 and must reach an age threshold of 1. */
#define SP_DIVISION_ROUNDOFF 1e-12

/**
 * What the division logic (and the source switch, the shape penalty) must
 * remember about a cell from its birth: the registry entry of one cell.
 * Initial cells are "born" at t = 0 with their initial observables.
 */
typedef struct {
  double birth_time; /**< t at which the cell was born (0 for initial cells) */
  double birth_mass; /**< m_k^0: its mass right after birth */
  double Iref[3];    /**< reference principal moments I^1,ref >= I^2,ref
                          (>= I^3,ref in 3D; Iref[2] = 0 in 2D): the
                          cell's moments right after birth */
  int generation;    /**< 0 for initial cells; both daughters of a division
                          get the parent's generation + 1 */
} sp_cell_birth;

/** A division, as divisions.csv reports it. */
typedef struct {
  int parent, child;
  double angle;          /**< 2D: of the division axis, in (-pi/2, pi/2] */
  double axis[3];        /**< the parent's long axis, the cut's unit normal
                              (sp_division_plane; 2D: z = 0) */
  double parent_mass;    /**< before the cut */
  double mass_a, mass_b; /**< the daughters' right after it */
  sp_cell_name parent_name, name_a, name_b; /**< named cells (lineage.h) */
  double fraction;       /**< the lineage table's share of the first daughter
                              (NaN: no entry) */
} sp_division_record;

/** Division criterion (docs/model.md "Division"), chosen per scene. */
typedef enum {
  SP_DIVIDE_AGE = 0, /**< divide when t - birth_time reaches T_div */
  SP_DIVIDE_MASS = 1 /**< divide when the mass reaches ratio x a reference */
} sp_division_criterion;

/** Parameters of the division criterion. */
typedef struct {
  sp_division_criterion criterion;
  double age;            /**< T_div (age criterion), > 0 */
  double mass_ratio;     /**< mass criterion: divide at mass_ratio x the
                              reference mass (paper: 2), > 0 */
  double reference_mass; /**< mass criterion: > 0: every cell divides at
                              mass_ratio x this (the authors' code: "m > 2
                              m(initial cell)", pass the initial cell's birth
                              mass); 0: at mass_ratio x its own birth mass
                              (docs/model.md) */
  double tolerance;      /**< relative: due once the watched quantity (age or
                              mass) is >= (1 - tolerance) x its threshold; 0
                              means exactly at the threshold. A step shortened
                              to the linearly interpolated crossing can land a
                              hair short of a nonlinear mass history; a small
                              tolerance (e.g. 1e-6) makes that landing count,
                              so the step is not shortened again and again.
                              A relative SP_DIVISION_ROUNDOFF is always
                              allowed on top (times accumulated in floating
                              point that should land on the threshold). */
} sp_division_params;

/**
 * @brief Check the parameters of a criterion.
 * @return SP_OK, or SP_ERR_INPUT with a message naming the bad value
 */
int sp_division_params_check(const sp_division_params *params);

/**
 * @brief The birth record of a cell with observables @p obs at time @p t.
 * @param[in] obs the cell's observables right after birth (mass, I1, I2)
 * @param[in] generation 0 for an initial cell
 */
sp_cell_birth sp_cell_birth_make(double t, const sp_cell_obs *obs, int generation);

/**
 * @brief Whether a cell's division is due after the step t_old -> t_new.
 *
 * Crossing-safe: the criterion is "the watched quantity (age t - birth_time,
 * or mass) is at or above its threshold at t_new", which holds when the
 * threshold was crossed anywhere within (t_old, t_new] and also when it was
 * exceeded already (a division that had to wait, e.g. for N < N_max). The
 * paper's window test eps1 < ratio - 1 < eps2 instead misses a step that jumps
 * over the window, and the cell then never divides.
 *
 * @param[in] params criterion and thresholds (sp_division_params_check'ed)
 * @param[in] birth the cell's birth record
 * @param[in] t_old, t_new the step's start and end times
 * @param[in] mass_old, mass_new the cell's mass at t_old and t_new (ignored
 *            by the age criterion)
 * @return 1 if due, else 0
 */
int sp_division_due(const sp_division_params *params, const sp_cell_birth *birth,
                    double t_old, double t_new, double mass_old, double mass_new);

/** @brief The threshold of the watched quantity (age or mass) at which a
 *         cell with birth record @p birth divides. */
double sp_division_threshold(const sp_division_params *params, const sp_cell_birth *birth);

/**
 * @brief Fraction theta of the step t_old -> t_new at which the division
 *        threshold is crossed, so the caller can redo the step with theta dt
 *        and divide at the crossing instead of past it.
 *
 * Age: exact (the age is linear in t). Mass: linear interpolation of the mass
 * between mass_old and mass_new. theta aims at the threshold itself; the
 * step redone with theta dt then lands on it up to the mass history's
 * curvature, which sp_division_params.tolerance absorbs.
 *
 * @return theta in [0, 1]: 0 when the division was due already at t_old
 *         (divide now, nothing to shorten); in (0, 1) when the threshold is
 *         crossed inside the step; 1 when it is reached only at t_new or
 *         not at all (use sp_division_due to tell those apart)
 */
double sp_division_crossing_fraction(const sp_division_params *params,
                                     const sp_cell_birth *birth, double t_old,
                                     double t_new, double mass_old,
                                     double mass_new);

/** A node within this fraction of the mesh size h of the division line is
 *  "on" it for the sharp cut (round-off in the centre of mass is ~1e-16). */
#define SP_DIVISION_ON_LINE_FRACTION 1e-9

/** @brief The child's share H(sd) of the parent's value at a node at
 *         signed distance @p sd from the division line: the sharp cut (1
 *         beyond the line, 0 before it, 1/2 within @p on_line of it) or the
 *         smoothed one (a logistic of width @p width). */
double sp_division_child_share(double sd, int smooth, double width, double on_line);

/**
 * @brief The cut of a division: through the centre of mass Xc, normal to
 *        the cell's long axis, in either dimension (a line in 2D, a plane
 *        in 3D).
 *
 * The long axis is the unit eigenvector of the SMALLEST principal moment of
 * the inertia tensor (the direction of largest variance of c about Xc;
 * obs->axes[obs->long_axis]). In 2D the cut runs along the eigenvector of
 * the LARGEST moment (docs/model.md): for an ellipse elongated along x
 * the larger moment, int c Xb1^2, is about the y axis, so the cut runs
 * along y, across the cell's length. In 3D the largest moment does not name the cut: a
 * prolate cell (a cigar) has I1 = I2, and a plane normal to any of their
 * eigenvectors would contain the long axis; the plane normal to the long
 * axis cuts it across its length, as the 2D line does.
 *
 * @param[out] point Xc (2D: z = 0)
 * @param[out] normal the unit normal n (2D: n_z = 0)
 */
void sp_division_plane(const sp_cell_obs *obs, int dim, double point[3], double normal[3]);

/**
 * @brief Split cell @p parent into itself and a new cell @p child on a layout
 *        with one more cell (paper section 2.3).
 *
 * With the cut of sp_division_plane (2D: the line through Xc along v1,
 * with the unit normal n = v2 = (-v1_y, v1_x), v1 turned by +90 degrees;
 * 3D: the plane through Xc normal to n = v3, the long axis) moved by
 * @p offset along n (0: through the centre of mass, the paper;
 * sp_division_balance_offset: the cut that halves the mass), the signed
 * distance of node X is sd = n . (X - Xc) - offset. At each node the parent's value
 * c is shared as
 *     c_child = c H(sd),   c_parent = c - c_child,
 * so c_parent + c_child = c at every node and, the mass being linear in the
 * nodal values, the parent's mass is conserved to round-off. H is
 *   - sharp (@p smooth = 0, the paper's cut): 1 for sd > 0, 0 for sd < 0,
 *     and 1/2 for a node on the cut (|sd| <= 1e-9 h): a symmetric cell whose
 *     line runs through mesh nodes then splits into equal halves, instead of
 *     the line's nodes all going to one side;
 *   - smoothed (@p smooth = 1): H(sd) = 1 / (1 + exp(-sd / width)), the
 *     initial tanh profile's shape, so width = the equilibrium interface
 *     width d gives a cut that is already near equilibrium.
 * The sharp cut hands each node wholly to one side, which moves the
 * effective line by up to half a node spacing: the daughters of a symmetric
 * cell differ in mass by up to ~ 2 h x (the cell's chord along the line) /
 * (cell mass), i.e. O(h) (tests/test_division.c: 2.6% for a 0.12 x 0.06
 * cell with h = 1/160 at 45 degrees; worst case ~6%). The smoothed cut
 * halves the same cell to ~1e-4.
 * The whole field is shared, background included: the parent's background
 * noise goes with the side of the line it is on.
 *
 * mu is only Newton's initial guess (the backward-Euler residual uses c^n
 * alone): it is shared with the same weights, mu_child = mu H and mu_parent =
 * mu (1 - H), i.e. each daughter keeps the parent's mu on its own side and
 * gets ~0 on the other, where its c ~ 0 and so is its equilibrium mu
 * (f'(0) = 0).
 *
 * Every other cell is copied by (cell, node) (sp_layout_transfer); pairs of
 * @p new_layout absent from @p layout get c = mu = 0.
 *
 * @param[in] mesh the mesh (node coordinates)
 * @param[in] layout, state the layout and state before the split
 * @param[in] parent the cell to split
 * @param[in] parent_obs its observables in @p state (the axis)
 * @param[in] smooth 0: sharp cut; 1: smoothed
 * @param[in] width the smoothed cut's width (> 0; ignored when sharp)
 * @param[in] offset the line's shift along n from the centre of mass
 * @param[in] new_layout layout->n_cells + 1 cells on the same nodes; the
 *            child must have a pair wherever it receives a nonzero value
 *            (sharp: the parent's nodes with sd > -1e-9 h; smoothed: all
 *            the parent's nodes), and the parent wherever it keeps one
 * @param[out] new_state 2 new_layout->n_pairs values
 * @param[in] child the new cell's index: layout->n_cells
 * @return SP_OK; SP_ERR_INTERNAL when the layouts do not fit (the message
 *         names the first node that has no pair for a value that must be
 *         kept, since dropping it would lose mass)
 */
int sp_division_split(const sp_mesh *mesh, const sp_layout *layout,
                      const double *state, int parent,
                      const sp_cell_obs *parent_obs, int smooth, double width,
                      double offset, const sp_layout *new_layout, double *new_state,
                      int child);

/**
 * @brief The shift of the division line (3D: plane) along its normal n that
 *        gives the child the share @p fraction of the parent's mass (0.5:
 *        equal halves, `division.line: equal_mass`; the lineage table's
 *        asymmetric divisions, lineage.h).
 *
 * The line through the centre of mass halves only a symmetric cell: a
 * packed, egg-shaped parent is split 46/54 by it (docs/paper-runs.md, run
 * 1). The child's mass after sp_division_split with offset s,
 *     M(s) = sum_i w_i c_i H(n . (X_i - Xc) - s),
 * where w_i = int phi_i over the parent's elements (all four nodes in its
 * support: the rule of sp_cells_observe, so M(s) is exactly the mass the
 * observables will report), decreases with s; bisection finds M(s) =
 * fraction M_parent. The smoothed cut's M is continuous, so the share is
 * met to round-off (tests/test_lineage.c: 1e-9 relative); the sharp cut's
 * M jumps by one node's share w_i c_i (half of it at a time: a node on the
 * line is shared 1/2), and the offset returned is the side of the last jump
 * closer to the target: the share is met to half a jump, at most
 * max_i w_i c_i / (2 M_parent).
 * The axis (direction) is unchanged: the cell is still cut across its
 * length; only the line's position moves (by much less than the cell's
 * radius for any parent that is nearly convex).
 *
 * @param[out] offset the shift s (0 for a cell whose centre line halves it)
 * @return SP_OK; SP_ERR_MEMORY
 */
int sp_division_balance_offset(const sp_mesh *mesh, const sp_layout *layout,
                               const double *state, int parent,
                               const sp_cell_obs *parent_obs, int smooth, double width,
                               double fraction, double *offset);

/**
 * @brief Birth records of both daughters after a split at time @p t: birth
 *        time t, birth mass and reference moments from their observables
 *        after the split, generation = the parent's + 1.
 * @param[in,out] registry new_layout->n_cells entries; entry @p parent holds
 *                the parent's record on entry
 * @param[in] obs the observables of the state after the split
 */
void sp_division_record_births(double t, const sp_cell_obs *obs, int parent,
                               int child, sp_cell_birth *registry);

/**
 * @brief The time step after a division, the paper's algorithm 2.
 *
 * a = @p steps_since_division counts the steps after the division: a = 1 is
 * the first step taken from the split state. Then
 *   dt = dt_bar 10^-m                   for a = 1 .. n_div,
 *   dt = dt_bar 10^-m (a - n_div)^m     while that is < dt_bar,
 *   dt = dt_bar                         from then on (a >= n_div + 10).
 * The authors' code (n_div = 3, m = 6): dt_bar 1e-6 for a = 1..3, and from
 * the 4th step on dt_bar 1e-6 (a - 3)^6 (again 1e-6 dt_bar at a = 4, 6.4e-5
 * at a = 5, ..., 0.531441 at a = 12), dt_bar from a = 13. The ramp's end
 * n_div + 10 does not depend on m, since 10^-m (a - n_div)^m =
 * ((a - n_div) / 10)^m. Computed with exact integer powers (m <= 15).
 *
 * @param[in] dt_bar the base step
 * @param[in] n_div steps held at the smallest dt (paper: n_div < 5), >= 0
 * @param[in] m the reduction exponent (paper: m < 7), 0 .. 15
 * @param[in] steps_since_division a; a <= 0 means no division is being
 *            recovered from and gives dt_bar
 */
double sp_division_dt(double dt_bar, int n_div, int m, int steps_since_division);

/**
 * @brief N_max = meas(Omega) / m^0 (docs/model.md, growth source): the number of
 *        birth-size cells that fill Omega.
 *
 * Rounded down (a cell more than fits would have no room), after adding a
 * relative 1e-9 so that a ratio that is an integer up to quadrature round-off
 * (e.g. 15.999999999999998) gives that integer. A scene may override it.
 *
 * @param[in] area_omega meas(Omega) (sp_mesh_region_area(mesh, SP_REGION_OMEGA))
 * @param[in] birth_mass m^0 of the initial cell
 * @return N_max >= 1 (at least the initial cell); 0 when an argument is not
 *         positive and finite (invalid)
 */
int sp_division_max_cells(double area_omega, double birth_mass);

#ifdef __cplusplus
}
#endif
#endif
