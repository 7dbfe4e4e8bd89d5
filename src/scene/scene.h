/**
 * @file scene.h
 * @brief The input deck: a YAML scene file read through a libcyaml schema,
 *        validated (types, ranges, cells inside the domain), with
 *        `--set section.key=value` overrides. Every key, its unit, default
 *        and range live in one table in scene_keys.c; docs/scene.md is printed
 *        from that table (`softpack keys`).
 */
#ifndef SP_SCENE_H
#define SP_SCENE_H

#include <stddef.h>
#include <stdio.h>

#include "public/cell_obs.h"
#include "softpack_linear.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The domain: 2D rectangle or ellipse, 3D box or ellipsoid (hexahedra). */
typedef enum {
  SP_MESH_RECTANGLE = 0,
  SP_MESH_ELLIPSE = 1,
  SP_MESH_BOX = 2,
  SP_MESH_ELLIPSOID = 3
} sp_mesh_kind;
typedef enum { SP_PROFILE_TANH = 0, SP_PROFILE_SHARP = 1 } sp_profile_kind;
typedef enum { SP_JAC_AD = 0, SP_JAC_HAND = 1, SP_JAC_FD = 2 } sp_jacobian_kind;
/** Newton's initial guess: the last state, or extrapolated from the last two. */
typedef enum { SP_PREDICT_NONE = 0, SP_PREDICT_LINEAR = 1 } sp_predictor_kind;
/** The length of a Newton update: the full step, or NOX's backtracking line search. */
typedef enum { SP_STEP_FULL = 0, SP_STEP_BACKTRACK = 1 } sp_line_search_kind;
/** SuperLU_DIST's column order: METIS on the (cell, node) pairs or on the unknowns. */
typedef enum { SP_ORDER_PAIRS = 0, SP_ORDER_UNKNOWNS = 1 } sp_ordering_kind;
/* solver.linear: sp_linear_kind, the table of c_api/softpack_linear.h */

/** mesh: the domain and its discretisation. */
typedef struct {
  sp_mesh_kind type;   /**< rectangle | ellipse | box | ellipsoid */
  double x0, y0, x1, y1; /**< rectangle (and box) corners */
  int nx, ny;          /**< rectangle (and box) elements per direction */
  double z0, z1;       /**< box: bottom and top */
  int nz;              /**< box: elements along z */
  int refinements;     /**< ellipse (ellipsoid): five-patch disk (cubed
                            ball) refined r times */
  double semi_x, semi_y; /**< ellipse (and ellipsoid) semi-axes (x, y) */
  double semi_z;       /**< ellipsoid: semi-axis z (NaN: not given) */
  int buffer_layers;   /**< ellipse, ellipsoid: element rings (shells) of the
                            buffer (0 = none) */
  double buffer_width; /**< ellipse, ellipsoid: buffer width as a fraction
                            of the axes */
  double flatten;      /**< ellipse, ellipsoid: Omega cut by |y| (2D), |z|
                            (3D) <= flatten, the coverslip (0: no cut) */
} sp_scene_mesh;

/** model: the energy and the dynamics (paper table 1). */
typedef struct {
  double alpha;    /**< double-well height, f = alpha c^2 (c-1)^2 */
  double kappa;    /**< gradient energy coefficient */
  double lambda;   /**< pair repulsion */
  double lambda_b; /**< buffer-ring penalty */
  double mobility; /**< M */
  double adhesion_sisters;     /**< sigma of two sisters (docs/model.md, "Adhesion") */
  double adhesion_non_sisters; /**< sigma of any other two cells */
} sp_scene_model;

/** How dt is chosen (src/time/dt_control.h). */
typedef enum { SP_CONTROL_FIXED = 0, SP_CONTROL_ADAPTIVE = 1 } sp_control_kind;
/** What a step solves (src/time/time_scheme.h). */
typedef enum { SP_TIME_BE = 0, SP_TIME_BDF2 = 1 } sp_time_scheme_kind;

/** time: the time scheme and its step control. */
typedef struct {
  sp_control_kind control;    /**< fixed (the paper's) | adaptive */
  sp_time_scheme_kind scheme; /**< be (the paper's) | bdf2 */
  double rtol, atol;  /**< adaptive: local error tolerances on c */
  double dt_max;      /**< adaptive: the largest step */
  double dt;        /**< the scene's (base) step dt_bar */
  double t_end;     /**< final time */
  int max_steps;    /**< stop after this many accepted steps */
  double dt_min;    /**< smallest step tried before giving up */
  double shrink;    /**< dt factor after a failed Newton solve (< 1) */
  double grow;      /**< dt factor after grow_after successes (> 1) */
  int grow_after;   /**< consecutive successes before dt grows */
  int max_retries;  /**< failed attempts of one step before the run stops */
  int failure_memory; /**< accepted steps after a failure at dt_f during
                           which dt stays <= dt_f / grow (0: none) */
  double event_first;  /**< adaptive, after a division: the first step's
                            cap as a fraction of the step before */
  double event_growth; /**< ... the growth cap of the steps after it */
  int event_steps;     /**< ... for this many steps, then the PI law */
} sp_scene_time;

/** One initial cell. */
typedef struct {
  double x, y;     /**< centre */
  double z;        /**< centre z: given on a 3D mesh (a sphere), NaN (not
                        given) on a 2D one */
  double radius;   /**< radius of the c = 1/2 level set */
  double semi_x, semi_y, semi_z; /**< semi-axes of an ellipse (ellipsoid)
                        cell along x, y, z; NaN (not given): the radius
                        (sp_scene_cell_semi_axis); semi_z only in 3D */
  double axis[3];  /**< the direction the semi_x axis is turned onto
                        (axis_x, _y, _z; NaN: not given; all NaN: along
                        x; sp_scene_cell_frame) */
  sp_profile_kind profile; /**< tanh (equilibrium width) or sharp */
  char name[SP_CELL_NAME_MAX]; /**< its name ("": none; lineage.h) */
} sp_scene_cell;

/** The cut's normal rule of a lineage entry (src/model/lineage.h). */
typedef enum {
  SP_AXIS_LONG = 0,          /**< normal along the cell's long axis (the paper's) */
  SP_AXIS_FIXED = 1,         /**< normal = direction_x, _y (, _z) */
  SP_AXIS_PERPENDICULAR = 2  /**< normal perpendicular to the parent's cut normal */
} sp_axis_kind;

/** One entry of the lineage table: how the cell named @c cell divides. */
typedef struct {
  char cell[SP_CELL_NAME_MAX];   /**< the dividing cell's name */
  double age;        /**< divide at this age (NaN: not this criterion) */
  double time;       /**< ... at this absolute time (NaN: not this one) */
  double mass_ratio; /**< ... at this x its birth mass (NaN: not this one) */
  double fraction;   /**< the first daughter's share of the parent's mass */
  char first[SP_CELL_NAME_MAX];  /**< the first daughter's name */
  char second[SP_CELL_NAME_MAX]; /**< the second daughter's name */
  sp_axis_kind axis;             /**< the cut's normal */
  double direction[3]; /**< axis fixed: the normal (x, y, z; NaN: not given) */
} sp_scene_lineage;

/** One named pair of the adhesion table: its sigma, instead of the sisters'
 *  or non-sisters' (src/model/adhesion.h). */
typedef struct {
  char cell[SP_CELL_NAME_MAX];  /**< one cell's name */
  char other[SP_CELL_NAME_MAX]; /**< the other's */
  double sigma;                 /**< their adhesion coefficient */
} sp_scene_adhesion;

/** @brief The semi-axis of @p cell along coordinate @p d (0, 1, 2): its
 *         semi_x, semi_y or semi_z if given, else its radius. */
double sp_scene_cell_semi_axis(const sp_scene_cell *cell, int d);

/** @brief 1 if @p cell gives any semi-axis (an ellipse or ellipsoid), 0 for
 *         a disk or sphere of its radius. */
int sp_scene_cell_is_ellipsoid(const sp_scene_cell *cell);

/** @brief 1 if @p cell is turned (axis_x, axis_y or axis_z given). */
int sp_scene_cell_is_turned(const sp_scene_cell *cell);

/**
 * @brief The cell's frame: R[d][j] is coordinate d of its j-th semi-axis
 *        direction (semi_x, semi_y, semi_z). Not turned: the identity;
 *        turned: the smallest rotation taking x onto its axis (normalised;
 *        components not given are 0), about x cross axis (a half turn
 *        about z when the axis is -x). In 2D (no axis_z) a turn in the
 *        plane by the axis' angle.
 */
void sp_scene_cell_frame(const sp_scene_cell *cell, double R[3][3]);

/** @brief The cell's half-extent along coordinate @p d: its semi-axis
 *         along d when not turned, else sqrt(sum_j (R[d][j] s_j)^2) (the
 *         frame R, semi-axes s; @p dim of them). */
double sp_scene_cell_extent(const sp_scene_cell *cell, int dim, int d);

/** @brief The point @p centre + R @p local of cell @p cell's frame (dim
 *         coordinates; exactly centre + local when not turned). */
void sp_scene_cell_point(const sp_scene_cell *cell, int dim, const double *centre,
                         const double *local, double *out);

/** noise: the initial background of every field. */
typedef struct {
  double background; /**< background value b of c outside cells */
  double amplitude;  /**< uniform noise amplitude a: b + a U(-1,1) */
  unsigned seed;     /**< RNG seed (runs are reproducible from it) */
} sp_scene_noise;

/** solver: Newton and the linear solver. */
typedef struct {
  sp_jacobian_kind jacobian;
  sp_linear_kind linear;
  double newton_rtol;  /**< relative residual tolerance */
  double newton_atol;  /**< absolute residual tolerance (unscaled 2-norm) */
  int newton_max_its;  /**< iterations before a step counts as failed */
  int ilu_fill;        /**< gmres_ilu: ILU(k) level of fill */
  int auto_unknowns;   /**< auto in 2D: gmres_cells from this many unknowns */
  double krylov_tol;   /**< gmres_ilu: relative residual of a linear solve */
  double jacobian_reuse; /**< modified Newton: keep the factorisation while
                              each iteration cuts ||F|| by this (0: never) */
  double jacobian_carry; /**< a step begins on the last step's
                              factorisation while it cuts ||F|| by this */
  double newton_divergence; /**< fail a step once ||F_k|| > this x ||F_0||
                                 (0: off) */
  sp_line_search_kind line_search; /**< the length of a Newton update */
  sp_predictor_kind predictor; /**< Newton's initial guess */
  sp_ordering_kind ordering;   /**< SuperLU_DIST's column order */
  int refine;                  /**< SuperLU_DIST: iterative refinement */
} sp_scene_solver;

/** How contacts are measured (contacts.h's sp_contacts_measure). */
typedef enum { SP_CONTACT_ISOSURFACE = 0, SP_CONTACT_OVERLAP = 1 } sp_contact_measure_kind;

/** output: what is written and when. */
typedef struct {
  int every;          /**< fields and pictures every this many steps */
  int pictures;       /**< 1: write PNG pictures */
  int picture_width;  /**< picture width in pixels */
  int contacts;       /**< 1: write contacts.csv (and contacts_<step>.png) */
  double contact_threshold; /**< in contact: A_kl >= this x min(S_k, S_l) */
  sp_contact_measure_kind contact_measure; /**< isosurface or overlap */
  double contact_level; /**< isosurface: the other field's level theta */
  double interval;    /**< also write at multiples of this time (0: off);
                           steps land on those times */
  int timings;        /**< 1: energy.csv's wall-clock columns hold the
                           seconds; 0: zeros (runs compare byte for byte) */
  int checkpoint_every;      /**< a checkpoint every this many steps (0: off) */
  double checkpoint_seconds; /**< ... and after this much wall time (0: off) */
  int checkpoint_keep;       /**< the newest this many checkpoints are kept */
  char length_unit[SP_CELL_NAME_MAX]; /**< the unit units.csv reads lengths in
                                           ("": none) */
  double length_scale;       /**< one model length is this many length_unit */
  char time_unit[SP_CELL_NAME_MAX];   /**< ... times in ("": none) */
  double time_scale;         /**< one model time is this many time_unit */
} sp_scene_output;

typedef enum {
  SP_DIVIDE_NONE = 0,
  SP_DIVIDE_BY_AGE = 1,
  SP_DIVIDE_BY_MASS = 2
} sp_division_kind;
typedef enum { SP_CUT_SHARP = 0, SP_CUT_SMOOTH = 1 } sp_cut_kind;
/** Where the division line runs (its direction is always v1). */
typedef enum { SP_LINE_CENTRE = 0, SP_LINE_EQUAL_MASS = 1 } sp_line_kind;

/** division: when and how cells divide (paper algorithms 1 and 2). */
typedef struct {
  sp_division_kind criterion; /**< none | age | mass */
  double t_div;          /**< age criterion: divide at this age */
  double mass_ratio;     /**< mass criterion: divide at this x birth mass */
  int use_initial_mass;  /**< mass criterion against the first cell's mass */
  int max_cells;         /**< N_max (0: meas(Omega) / birth mass) */
  int n_div;             /**< algorithm 2: steps at dt_bar 10^-m */
  int m;                 /**< algorithm 2: exponent */
  sp_cut_kind cut;       /**< sharp (paper) or smooth (tanh) */
  sp_line_kind line;     /**< through the centre of mass (paper) or moved
                              along its normal to halve the mass */
  double observe_threshold; /**< c below this is left out of centre,
                                 inertia and the mass criterion */
} sp_scene_division;

/** Where a BDF2 step evaluates the source's indicator c_k >= 1/2. */
typedef enum { SP_INDICATOR_EXTRAPOLATED = 0, SP_INDICATOR_PREVIOUS = 1 } sp_indicator_kind;

/** source: the adaptive growth source (paper algorithm 3). */
typedef struct {
  double rate;      /**< s_bar inside each cell (0: no source) */
  double off_ratio; /**< switch off once N >= N_max and m/m0 > this */
  sp_indicator_kind indicator; /**< BDF2 steps: c extrapolated to t^{n+1}, or c^n */
} sp_scene_source;

typedef enum { SP_SUPPORT_AUTO = 0, SP_SUPPORT_FULL = 1, SP_SUPPORT_LOCAL = 2 } sp_support_kind;
/** When a local support may shrink (it may always grow). */
typedef enum { SP_SHRINK_DIVISIONS = 0, SP_SHRINK_ALWAYS = 1 } sp_shrink_kind;

/** What new (cell, node) pairs of a support change start from. */
typedef enum { SP_FILL_EDGE = 0, SP_FILL_RELAX = 1 } sp_fill_kind;

/** Where a support change restores each cell's mass. */
typedef enum { SP_RESTORE_INTERIOR = 0, SP_RESTORE_POTENTIAL = 1 } sp_restore_kind;

/** Which buffer-ring elements a local support takes. */
typedef enum { SP_BUFFER_ELEMENTS_MARGIN = 0, SP_BUFFER_ELEMENTS_WHOLE = 1 } sp_buffer_elements_kind;

/** layout: where each cell's field lives. */
typedef struct {
  sp_support_kind support; /**< auto | full (the paper) | local */
  double margin;           /**< local: support = core + this many widths d */
  double core_threshold;   /**< local: the core is c_k >= this */
  double grow_threshold;   /**< local: grow when c_k >= this ... */
  double band;             /**< ... within this many widths of the edge */
  sp_shrink_kind shrink;   /**< local: shrink at every support change, or
                                only the supports of dividing cells */
  sp_fill_kind fill;       /**< local: what new pairs of a change start from */
  sp_restore_kind restore; /**< local: where a change restores the masses */
  sp_buffer_elements_kind buffer_elements; /**< local: the buffer ring's elements a
                                                support touches: whole, or by margin */
  int widen;               /**< local: widen a support that would call for
                                another update at once */
} sp_scene_layout;

/** How the shape term enters a step (src/model/shape.h). */
typedef enum { SP_SHAPE_EXPLICIT = 0, SP_SHAPE_IMPLICIT = 1 } sp_shape_scheme;

/** shape: the shape penalty on principal moments (docs/model.md, paper sec. 3). */
typedef struct {
  double delta1; /**< modulus on the larger principal moment I^1 */
  double delta2; /**< modulus on the second principal moment I^2 (the
                      smaller in 2D) */
  double delta3; /**< 3D: modulus on the smallest principal moment I^3 */
  sp_shape_scheme scheme; /**< explicit (the paper) or linearised implicit */
} sp_scene_shape;

/** Longest file path a scene key holds. */
#define SP_SCENE_PATH_MAX 1024

/** initial: initial fields from files instead of the cells' disks
 *  (src/io/initial.h). */
typedef struct {
  char from[SP_SCENE_PATH_MAX];        /**< a softpack checkpoint (.h5) or .vtu ("": none) */
  char label_image[SP_SCENE_PATH_MAX]; /**< a PNG of labels, one colour a cell ("": none) */
  double x0, y0, x1, y1;               /**< label_image: the box of Omega it covers */
  char label_volume[SP_SCENE_PATH_MAX]; /**< a NIfTI volume of labels, 3D ("": none) */
  double scale;                        /**< label_volume: L per unit of its coordinates */
  double offset_x, offset_y, offset_z; /**< label_volume: where its origin (or centre) lands */
  int centre;                          /**< label_volume: centre its labels at the offset */
} sp_scene_initial;

typedef struct sp_scene {
  sp_scene_mesh mesh;
  sp_scene_model model;
  sp_scene_time time;
  sp_scene_noise noise;
  sp_scene_solver solver;
  sp_scene_output output;
  sp_scene_division division;
  sp_scene_source source;
  sp_scene_shape shape;
  sp_scene_layout layout;
  sp_scene_initial initial;
  int n_cells;         /**< 0 when initial.from, label_image or label_volume gives the cells */
  sp_scene_cell *cells;
  int n_lineage;       /**< entries of the lineage table (0: none) */
  sp_scene_lineage *lineage;
  int n_adhesion;      /**< named pairs with their own adhesion (0: none) */
  sp_scene_adhesion *adhesion;
} sp_scene;

/**
 * @brief Read and validate a scene file, then apply overrides.
 * @param[in] path the YAML file
 * @param[in] n_set number of overrides
 * @param[in] set overrides "section.key=value" (e.g. "time.dt=1e-4")
 * @param[out] out the scene (free with sp_scene_destroy)
 * @return SP_OK, or SP_ERR_INPUT with a message naming the key, the line
 *         where known, and what was expected
 */
int sp_scene_load(const char *path, int n_set, const char *const *set,
                  sp_scene **out);

/**
 * @brief sp_scene_load from a scene file's text held in memory (@p len
 *        bytes, no terminating NUL needed); @p name stands for the file in
 *        messages. The same checks and results as sp_scene_load.
 */
int sp_scene_load_text(const char *name, const char *text, size_t len,
                       int n_set, const char *const *set, sp_scene **out);

/**
 * @brief The first key whose value differs between @p a and @p b, skipping
 *        keys @p skip says yes to (NULL: none), as "section.key" or
 *        "cells[i].key" into @p buf ("cells" when the counts differ).
 * @return 1 if a difference was found, 0 if the scenes agree
 */
int sp_scene_first_difference(const sp_scene *a, const sp_scene *b,
                              int (*skip)(const char *key), char *buf, size_t size);

/** @brief A scene file's text (malloc'd, NUL-terminated, @p len bytes
 *         without the NUL), for sp_scene_load_text. */
int sp_scene_read_file(const char *path, char **text, size_t *len);

/** @brief The dimension of the scene's mesh: 3 for mesh.type box and
 *         ellipsoid, else 2. */
int sp_scene_dim(const sp_scene *scene);

/** @brief SP_OK if the initial layout of @p n_cells cells (every cell on
 *         every node of the scene's mesh) fits the solver's 32-bit indices,
 *         else SP_ERR_INPUT beginning with @p where and naming the mesh keys
 *         and @p cells_key (what gave the cells: "cells", or a file's key
 *         such as "initial.label_volume"); the scene load checks its own
 *         cells so. */
int sp_scene_check_cell_count(const sp_scene *scene, int n_cells, const char *cells_key,
                              const char *where);

/** @brief Interface width d = sqrt(kappa / (2 alpha)) of the scene's model. */
double sp_scene_interface_width(const sp_scene *scene);

/** @brief The scene word of a linear solver (solver.linear): "superlu",
 *         ...; "?" for an unknown @p kind. */
const char *sp_scene_linear_name(sp_linear_kind kind);

/** @brief Print every key (markdown table: key, type, unit, default, range,
 *         meaning): the source of docs/scene.md. */
void sp_scene_print_keys(FILE *out);

/** @brief Free the scene and its cells and leave *scene NULL (a NULL
 *         @p scene or *scene is fine). */
void sp_scene_destroy(sp_scene **scene);

#ifdef __cplusplus
}
#endif
#endif
