/* scene_keys.c: the scene file's key table, its keyword lists and `softpack keys`. */
/*
 * Everything a key is (section, name, type, where it lives in sp_scene,
 * default, allowed range, unit, meaning) is written once, in sp_keys[]
 * (scene_private.h): scene.c builds the libcyaml schema, the defaults, the
 * `--set` parser and the messages from it, and sp_scene_print_keys the
 * documentation table (docs/scene.md holds its output verbatim).
 */
#include "scene/scene.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene_private.h"

/** The sections' names, by sp_section. */
const char *const sp_section_names[SP_N_SECTIONS] = {
    "mesh", "model", "time", "noise", "solver", "output", "division", "source",
    "layout", "shape", "initial", "cells", "lineage", "adhesion"};

static const char *const sp_key_type_names[] = {"float", "int", "uint", "bool",
                                                 "enum",  "path", "name"};

/* Range ends, spelt for reading the table (lower: AT_LEAST / ABOVE, upper:
 * AT_MOST / BELOW). */
#define UNBOUNDED {SP_UNBOUNDED, 0.0}
#define AT_LEAST(v) {SP_INCLUSIVE, (v)}
#define ABOVE(v) {SP_EXCLUSIVE, (v)}
#define AT_MOST(v) {SP_INCLUSIVE, (v)}
#define BELOW(v) {SP_EXCLUSIVE, (v)}

const cyaml_strval_t sp_mesh_words[] = {
    {"rectangle", SP_MESH_RECTANGLE}, {"ellipse", SP_MESH_ELLIPSE}, {"box", SP_MESH_BOX},
    {"ellipsoid", SP_MESH_ELLIPSOID}};
static const cyaml_strval_t sp_profile_words[] = {
    {"tanh", SP_PROFILE_TANH}, {"sharp", SP_PROFILE_SHARP}};
static const cyaml_strval_t sp_jacobian_words[] = {
    {"ad", SP_JAC_AD}, {"hand", SP_JAC_HAND}, {"fd", SP_JAC_FD}};
#define SP_LINEAR_WORD_(id, name, ranks) {#name, SP_LINEAR_##id},
static const cyaml_strval_t sp_linear_words[] = {SP_LINEAR_SOLVERS(SP_LINEAR_WORD_){"auto", SP_LINEAR_AUTO}};
#undef SP_LINEAR_WORD_
static const cyaml_strval_t sp_ordering_words[] = {
    {"pairs", SP_ORDER_PAIRS}, {"unknowns", SP_ORDER_UNKNOWNS}};
static const cyaml_strval_t sp_control_words[] = {
    {"fixed", SP_CONTROL_FIXED}, {"adaptive", SP_CONTROL_ADAPTIVE}};
static const cyaml_strval_t sp_time_scheme_words[] = {
    {"be", SP_TIME_BE}, {"bdf2", SP_TIME_BDF2}};
static const cyaml_strval_t sp_predictor_words[] = {
    {"none", SP_PREDICT_NONE}, {"linear", SP_PREDICT_LINEAR}};
static const cyaml_strval_t sp_line_search_words[] = {
    {"full", SP_STEP_FULL}, {"backtrack", SP_STEP_BACKTRACK}};
static const cyaml_strval_t sp_division_words[] = {
    {"none", SP_DIVIDE_NONE}, {"age", SP_DIVIDE_BY_AGE}, {"mass", SP_DIVIDE_BY_MASS}};
static const cyaml_strval_t sp_cut_words[] = {
    {"sharp", SP_CUT_SHARP}, {"smooth", SP_CUT_SMOOTH}};
static const cyaml_strval_t sp_line_words[] = {
    {"centre", SP_LINE_CENTRE}, {"equal_mass", SP_LINE_EQUAL_MASS}};
static const cyaml_strval_t sp_shape_scheme_words[] = {
    {"explicit", SP_SHAPE_EXPLICIT}, {"implicit", SP_SHAPE_IMPLICIT}};
static const cyaml_strval_t sp_shrink_words[] = {
    {"divisions", SP_SHRINK_DIVISIONS}, {"always", SP_SHRINK_ALWAYS}};
static const cyaml_strval_t sp_fill_words[] = {{"edge", SP_FILL_EDGE},
                                                  {"relax", SP_FILL_RELAX}};
static const cyaml_strval_t sp_restore_words[] = {{"interior", SP_RESTORE_INTERIOR},
                                                     {"potential", SP_RESTORE_POTENTIAL}};
static const cyaml_strval_t sp_buffer_elements_words[] = {
    {"margin", SP_BUFFER_ELEMENTS_MARGIN}, {"whole", SP_BUFFER_ELEMENTS_WHOLE}};
static const cyaml_strval_t sp_axis_words[] = {
    {"long", SP_AXIS_LONG}, {"fixed", SP_AXIS_FIXED}, {"perpendicular", SP_AXIS_PERPENDICULAR}};
static const cyaml_strval_t sp_indicator_words[] = {
    {"extrapolated", SP_INDICATOR_EXTRAPOLATED}, {"previous", SP_INDICATOR_PREVIOUS}};
static const cyaml_strval_t sp_contact_measure_words[] = {
    {"isosurface", SP_CONTACT_ISOSURFACE}, {"overlap", SP_CONTACT_OVERLAP}};
static const cyaml_strval_t sp_support_words[] = {
    {"auto", SP_SUPPORT_AUTO}, {"full", SP_SUPPORT_FULL}, {"local", SP_SUPPORT_LOCAL}};
/* The YAML 1.1 booleans; the first word of each value is the one printed. */
static const cyaml_strval_t sp_bool_words[] = {
    {"true", 1}, {"false", 0}, {"yes", 1}, {"no", 0}, {"on", 1}, {"off", 0}};

/* Enum keys are stored through an int *: every enum of scene.h must be
 * int-sized (GCC and Clang make them unsigned int, which may alias int). */
_Static_assert(sizeof(sp_mesh_kind) == sizeof(int), "enum size");
_Static_assert(sizeof(sp_profile_kind) == sizeof(int), "enum size");
_Static_assert(sizeof(sp_jacobian_kind) == sizeof(int), "enum size");
_Static_assert(sizeof(sp_linear_kind) == sizeof(int), "enum size");

/* Offset of a member, which must have C type ctype: a table entry whose
 * type does not match its struct member fails to compile. */
#define MEMBER_OFFSET(strct, member, ctype)                                    \
  (offsetof(strct, member) +                                                   \
   0 * sizeof(_Generic(((strct *)0)->member, ctype: 0)))
#define ENUM_MEMBER_OFFSET(strct, member)                                      \
  (offsetof(strct, member) +                                                   \
   0 * sizeof(char[sizeof(((strct *)0)->member) == sizeof(int) ? 1 : -1]))

#define KEY_FLOAT(sec, name, member, def, lo, hi, unit, meaning)               \
  {sec, name, SP_KEY_FLOAT, MEMBER_OFFSET(sp_scene, member, double), def, 0,   \
   lo, hi, NULL, 0, unit, meaning}
#define KEY_INT(sec, name, member, def, lo, hi, unit, meaning)                 \
  {sec, name, SP_KEY_INT, MEMBER_OFFSET(sp_scene, member, int), def, 0, lo,    \
   hi, NULL, 0, unit, meaning}
#define KEY_UINT(sec, name, member, def, lo, hi, unit, meaning)                \
  {sec, name, SP_KEY_UINT, MEMBER_OFFSET(sp_scene, member, unsigned), def, 0,  \
   lo, hi, NULL, 0, unit, meaning}
#define KEY_BOOL(sec, name, member, def, unit, meaning)                        \
  {sec, name, SP_KEY_BOOL, MEMBER_OFFSET(sp_scene, member, int), def, 0,       \
   UNBOUNDED, UNBOUNDED, sp_bool_words, CYAML_ARRAY_LEN(sp_bool_words), unit,  \
   meaning}
#define KEY_ENUM(sec, name, member, def, words, unit, meaning)                 \
  {sec, name, SP_KEY_ENUM, ENUM_MEMBER_OFFSET(sp_scene, member), def, 0,       \
   UNBOUNDED, UNBOUNDED, words, CYAML_ARRAY_LEN(words), unit, meaning}
#define KEY_PATH(sec, name, member, meaning)                                    \
  {sec, name, SP_KEY_PATH,                                                     \
   offsetof(sp_scene, member) +                                                \
       0 * sizeof(char[sizeof(((sp_scene *)0)->member) == SP_SCENE_PATH_MAX ? 1 : -1]), \
   0.0, 0, UNBOUNDED, UNBOUNDED, NULL, 0, "-", meaning}
#define CELL_FLOAT_REQUIRED(name, member, lo, hi, unit, meaning)               \
  {SP_SEC_CELLS, name, SP_KEY_FLOAT,                                           \
   MEMBER_OFFSET(sp_scene_cell, member, double), 0.0, 1, lo, hi, NULL, 0,      \
   unit, meaning}
#define CELL_FLOAT(name, member, def, lo, hi, unit, meaning)                   \
  {SP_SEC_CELLS, name, SP_KEY_FLOAT,                                           \
   MEMBER_OFFSET(sp_scene_cell, member, double), def, 0, lo, hi, NULL, 0,      \
   unit, meaning}
#define CELL_ENUM(name, member, def, words, unit, meaning)                     \
  {SP_SEC_CELLS, name, SP_KEY_ENUM, ENUM_MEMBER_OFFSET(sp_scene_cell, member), \
   def, 0, UNBOUNDED, UNBOUNDED, words, CYAML_ARRAY_LEN(words), unit, meaning}
/* A name key of a record (required or "": none) */
#define NAME_KEY(sec, strct, name, member, required, meaning)                  \
  {sec, name, SP_KEY_NAME,                                                     \
   MEMBER_OFFSET(strct, member, char *) +                                      \
       0 * sizeof(char[sizeof(((strct *)0)->member) == SP_CELL_NAME_MAX ? 1 : -1]), \
   0.0, required, UNBOUNDED, UNBOUNDED, NULL, 0, "-", meaning}
#define LINEAGE_FLOAT(name, member, def, lo, hi, unit, meaning)                \
  {SP_SEC_LINEAGE, name, SP_KEY_FLOAT,                                         \
   MEMBER_OFFSET(sp_scene_lineage, member, double), def, 0, lo, hi, NULL, 0,   \
   unit, meaning}
#define LINEAGE_ENUM(name, member, def, words, unit, meaning)                  \
  {SP_SEC_LINEAGE, name, SP_KEY_ENUM,                                          \
   ENUM_MEMBER_OFFSET(sp_scene_lineage, member), def, 0, UNBOUNDED, UNBOUNDED, \
   words, CYAML_ARRAY_LEN(words), unit, meaning}

#define ADHESION_FLOAT_REQUIRED(name, member, lo, hi, unit, meaning)          \
  {SP_SEC_ADHESION, name, SP_KEY_FLOAT,                                        \
   MEMBER_OFFSET(sp_scene_adhesion, member, double), 0.0, 1, lo, hi, NULL, 0,  \
   unit, meaning}

/* Units: L = the model's length unit, T = its time unit, E = its energy per
 * unit area (the energy density of Pi); "-" = dimensionless. Defaults are
 * the paper's values (table 1) where the paper has one. */
const sp_key sp_keys[] = {
    /* mesh */
    KEY_ENUM(SP_SEC_MESH, "type", mesh.type, SP_MESH_ELLIPSE, sp_mesh_words,
             "-", "domain Omega: a rectangle or the paper's ellipse (2D), or a box "
             "or an ellipsoid of hexahedra (3D)"),
    KEY_FLOAT(SP_SEC_MESH, "x0", mesh.x0, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "rectangle, box: left edge"),
    KEY_FLOAT(SP_SEC_MESH, "y0", mesh.y0, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "rectangle, box: bottom edge (front in a box)"),
    KEY_FLOAT(SP_SEC_MESH, "x1", mesh.x1, 1.0, UNBOUNDED, UNBOUNDED, "L",
              "rectangle, box: right edge (> x0)"),
    KEY_FLOAT(SP_SEC_MESH, "y1", mesh.y1, 1.0, UNBOUNDED, UNBOUNDED, "L",
              "rectangle, box: top edge (back in a box; > y0)"),
    KEY_INT(SP_SEC_MESH, "nx", mesh.nx, 64, AT_LEAST(1), AT_MOST(4096),
            "elements", "rectangle, box: elements along x"),
    KEY_INT(SP_SEC_MESH, "ny", mesh.ny, 64, AT_LEAST(1), AT_MOST(4096),
            "elements", "rectangle, box: elements along y"),
    KEY_FLOAT(SP_SEC_MESH, "z0", mesh.z0, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "box: bottom face"),
    KEY_FLOAT(SP_SEC_MESH, "z1", mesh.z1, 1.0, UNBOUNDED, UNBOUNDED, "L",
              "box: top face (> z0)"),
    KEY_INT(SP_SEC_MESH, "nz", mesh.nz, 16, AT_LEAST(1), AT_MOST(1024),
            "elements", "box: elements along z"),
    KEY_INT(SP_SEC_MESH, "refinements", mesh.refinements, 5, AT_LEAST(0),
            AT_MOST(9), "-",
            "ellipse: uniform refinements of the five-patch disk "
            "(5: the paper's 5120 elements); ellipsoid: of the cubed ball, at "
            "most 7 (4: 28672 elements)"),
    KEY_FLOAT(SP_SEC_MESH, "semi_x", mesh.semi_x, 0.5, ABOVE(0.0), UNBOUNDED,
              "L", "ellipse, ellipsoid: semi-axis along x (centred at the origin)"),
    KEY_FLOAT(SP_SEC_MESH, "semi_y", mesh.semi_y, 0.25, ABOVE(0.0), UNBOUNDED,
              "L", "ellipse, ellipsoid: semi-axis along y"),
    KEY_FLOAT(SP_SEC_MESH, "semi_z", mesh.semi_z, NAN, ABOVE(0.0), UNBOUNDED,
              "L", "ellipsoid: semi-axis along z (required there; not allowed on "
              "other meshes)"),
    KEY_INT(SP_SEC_MESH, "buffer_layers", mesh.buffer_layers, 0, AT_LEAST(0),
            AT_MOST(64), "elements",
            "ellipse, ellipsoid: element rings (shells) of the buffer zone outside "
            "Omega (0: no buffer)"),
    KEY_FLOAT(SP_SEC_MESH, "buffer_width", mesh.buffer_width, 0.1, ABOVE(0.0),
              AT_MOST(1.0), "-",
              "ellipse, ellipsoid: radial width of the buffer as a fraction of the "
              "semi-axes"),
    KEY_FLOAT(SP_SEC_MESH, "flatten", mesh.flatten, 0.0, AT_LEAST(0.0), UNBOUNDED, "L",
              "ellipse, ellipsoid: the coverslip: Omega is the ellipse (ellipsoid) between "
              "the lines y = -flatten and y = flatten in 2D, the planes z = -flatten and "
              "z = flatten in 3D (flatten < semi_y, semi_z), its nodes moved onto that cut "
              "shape (docs/embryo.md, \"The eggshell\"); 0: no cut"),
    /* model */
    KEY_FLOAT(SP_SEC_MODEL, "alpha", model.alpha, 4.0, ABOVE(0.0), UNBOUNDED,
              "E", "double-well height: f(c) = alpha c^2 (c-1)^2"),
    KEY_FLOAT(SP_SEC_MODEL, "kappa", model.kappa, 1e-3, ABOVE(0.0), UNBOUNDED,
              "E L^2",
              "gradient energy coefficient; interface width "
              "d = sqrt(kappa / (2 alpha))"),
    KEY_FLOAT(SP_SEC_MODEL, "lambda", model.lambda, 100.0, AT_LEAST(0.0),
              UNBOUNDED, "E", "pair repulsion lambda c_k^2 c_l^2"),
    KEY_FLOAT(SP_SEC_MODEL, "lambda_b", model.lambda_b, 100.0, AT_LEAST(0.0),
              UNBOUNDED, "E",
              "buffer penalty lambda_b c_k^2 in the buffer zone"),
    KEY_FLOAT(SP_SEC_MODEL, "mobility", model.mobility, 1.0, ABOVE(0.0),
              UNBOUNDED, "L^2/(E T)", "Cahn-Hilliard mobility M"),
    KEY_FLOAT(SP_SEC_MODEL, "adhesion_sisters", model.adhesion_sisters, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "E L^2",
              "adhesion sigma of two sisters (the daughters of one division): energy "
              "sigma int grad c_k . grad c_l, negative where they touch (docs/model.md, "
              "\"Adhesion\"); on every element, a cell's sigma summed over the other cells "
              "there must stay below kappa; 0: none"),
    KEY_FLOAT(SP_SEC_MODEL, "adhesion_non_sisters", model.adhesion_non_sisters, 0.0,
              AT_LEAST(0.0), UNBOUNDED, "E L^2",
              "adhesion sigma of two cells that are not sisters (initial cells, cousins, "
              "a cell and its aunt); as adhesion_sisters"),
    /* time */
    KEY_ENUM(SP_SEC_TIME, "control", time.control, SP_CONTROL_ADAPTIVE,
             sp_control_words, "-",
             "how dt is chosen: fixed (the paper's: dt, shrunk after a failed "
             "Newton solve, algorithm 2 after a division) or adaptive (from a "
             "local error estimate of c against rtol and atol; "
             "docs/time-stepping.md)"),
    KEY_ENUM(SP_SEC_TIME, "scheme", time.scheme, SP_TIME_BDF2,
             sp_time_scheme_words, "-",
             "time scheme: backward Euler (be, the paper's) or variable-step "
             "BDF2 (bdf2, second order; BE after the start and each "
             "division)"),
    KEY_FLOAT(SP_SEC_TIME, "rtol", time.rtol, 1e-2, ABOVE(0.0), UNBOUNDED, "-",
              "adaptive: relative tolerance of a step's local error in c"),
    KEY_FLOAT(SP_SEC_TIME, "atol", time.atol, 1e-2, ABOVE(0.0), UNBOUNDED, "-",
              "adaptive: absolute tolerance of a step's local error in c"),
    KEY_FLOAT(SP_SEC_TIME, "dt_max", time.dt_max, 1.0, ABOVE(0.0), UNBOUNDED,
              "T", "adaptive: the largest step (must be >= dt_min)"),
    KEY_FLOAT(SP_SEC_TIME, "dt", time.dt, 2e-4, ABOVE(0.0), UNBOUNDED, "T",
              "base time step dt_bar (backward Euler)"),
    KEY_FLOAT(SP_SEC_TIME, "t_end", time.t_end, 0.02, ABOVE(0.0), UNBOUNDED,
              "T", "final time"),
    KEY_INT(SP_SEC_TIME, "max_steps", time.max_steps, 1000000, AT_LEAST(1),
            AT_MOST(INT_MAX), "steps", "stop after this many accepted steps"),
    KEY_FLOAT(SP_SEC_TIME, "dt_min", time.dt_min, 1e-14, ABOVE(0.0),
              UNBOUNDED, "T",
              "smallest step tried before the run stops (must be <= dt)"),
    KEY_FLOAT(SP_SEC_TIME, "shrink", time.shrink, 0.25, ABOVE(0.0),
              BELOW(1.0), "-", "dt factor after a failed Newton solve"),
    KEY_FLOAT(SP_SEC_TIME, "grow", time.grow, 2.0, AT_LEAST(1.0), UNBOUNDED,
              "-", "dt factor after grow_after consecutive successes"),
    KEY_INT(SP_SEC_TIME, "grow_after", time.grow_after, 3, AT_LEAST(1),
            AT_MOST(INT_MAX), "steps",
            "consecutive successful steps before dt grows"),
    KEY_INT(SP_SEC_TIME, "max_retries", time.max_retries, 30, AT_LEAST(1),
            AT_MOST(1000), "-",
            "failed attempts of one step before the run stops"),
    KEY_INT(SP_SEC_TIME, "failure_memory", time.failure_memory, 0, AT_LEAST(0),
            AT_MOST(INT_MAX), "steps",
            "after a failed attempt at dt_f, dt stays <= dt_f / grow for this "
            "many accepted steps (0: it grows back to dt_f after grow_after)"),
    KEY_FLOAT(SP_SEC_TIME, "event_first", time.event_first, 0.1, ABOVE(0.0),
              AT_MOST(1.0), "-",
              "adaptive: the first step after a division is at most this "
              "fraction of the step the controller wanted next (and at most "
              "the convexity bound over the daughters' nodes; "
              "docs/time-stepping.md)"),
    KEY_FLOAT(SP_SEC_TIME, "event_growth", time.event_growth, 2.4,
              AT_LEAST(1.0), AT_MOST(10.0), "-",
              "adaptive: the largest growth of dt a step in the event_steps "
              "steps after a division, each from its own estimate (bdf2: at "
              "most 2.4, its step-ratio limit); then the PI law, at most 2"),
    KEY_INT(SP_SEC_TIME, "event_steps", time.event_steps, 20, AT_LEAST(0),
            AT_MOST(1000), "steps",
            "adaptive: how many steps after a division grow by up to "
            "event_growth from their own estimate before the PI law"),
    /* noise */
    KEY_FLOAT(SP_SEC_NOISE, "background", noise.background, 0.0,
              AT_LEAST(0.0), AT_MOST(1.0), "-",
              "initial background value b of every c_k outside its cell"),
    KEY_FLOAT(SP_SEC_NOISE, "amplitude", noise.amplitude, 0.0, AT_LEAST(0.0),
              AT_MOST(1.0), "-",
              "uniform noise amplitude a of the initial fields: "
              "b + a U(-1, 1)"),
    KEY_UINT(SP_SEC_NOISE, "seed", noise.seed, 1, AT_LEAST(0),
             AT_MOST(UINT_MAX), "-",
             "random seed (a run is reproducible from it)"),
    /* solver */
    KEY_ENUM(SP_SEC_SOLVER, "jacobian", solver.jacobian, SP_JAC_AD,
             sp_jacobian_words, "-",
             "Newton Jacobian: automatic differentiation, hand-coded or "
             "finite differences"),
    KEY_ENUM(SP_SEC_SOLVER, "linear", solver.linear, SP_LINEAR_AUTO,
             sp_linear_words, "-",
             "linear solver of each Newton step: direct (superlu, "
             "superlu_dist, mumps, klu: SuiteSparse's KLU, klu2: Amesos2's "
             "KLU2, one process only: Debian's is wrong on several, "
             "docs/building.md) or GMRES with an ILU(k) preconditioner "
             "(gmres_ilu: Belos GMRES, Ifpack2 RILUK, one ILU per process) "
             "or with the Jacobian's cell-diagonal blocks factored by MUMPS "
             "(gmres_cells: no fill between cells, docs/3d.md) or with a "
             "Cahn-Hilliard block preconditioner of AMG V-cycles (gmres_amg: "
             "no factorisation, docs/solvers.md); auto: "
             "on a 2D mesh mumps below solver.auto_unknowns unknowns and "
             "gmres_cells from there, decided again at each layout change, "
             "on a 3D one gmres_cells below 15,000 "
             "nodes and gmres_amg from there (the fastest measured in "
             "each, the least memory where they tie, docs/solvers.md)"),
    KEY_INT(SP_SEC_SOLVER, "auto_unknowns", solver.auto_unknowns, 250000, AT_LEAST(0),
            AT_MOST(2000000000), "-",
            "with solver.linear auto on a 2D mesh: the unknowns (2 per "
            "(cell, node) pair of the layout) from which auto takes gmres_cells "
            "instead of mumps; between 134,000 and 371,000 unknowns "
            "gmres_cells became the faster, in about two thirds of "
            "mumps' memory (docs/solvers.md)"),
    KEY_FLOAT(SP_SEC_SOLVER, "newton_rtol", solver.newton_rtol, 1e-8,
              ABOVE(0.0), BELOW(1.0), "-",
              "Newton: residual reduction relative to the first residual (with "
              "time.control adaptive Newton also stops once its update of c is "
              "below 1% of time.rtol and time.atol)"),
    KEY_FLOAT(SP_SEC_SOLVER, "newton_atol", solver.newton_atol, 1e-10,
              ABOVE(0.0), UNBOUNDED, "-",
              "Newton: absolute residual (unscaled 2-norm)"),
    KEY_INT(SP_SEC_SOLVER, "newton_max_its", solver.newton_max_its, 12,
            AT_LEAST(1), AT_MOST(60), "-",
            "Newton iterations (with jacobian_reuse: factorisations, and at "
            "most twice as many iterations) before a step counts as failed"),
    KEY_FLOAT(SP_SEC_SOLVER, "jacobian_reuse", solver.jacobian_reuse, 0.1,
              AT_LEAST(0.0), BELOW(1.0), "-",
              "modified Newton: an iteration keeps the last Jacobian and its "
              "factorisation while the previous one cut the residual norm by "
              "at least this factor (0: a new Jacobian every iteration)"),
    KEY_FLOAT(SP_SEC_SOLVER, "jacobian_carry", solver.jacobian_carry, 0.35,
              AT_LEAST(0.0), BELOW(1.0), "-",
              "with jacobian_reuse > 0: a step begins on the last step's "
              "factorisation and keeps it while each iteration cuts the "
              "residual norm by at least this factor (0: every step begins "
              "with a new Jacobian)"),
    KEY_FLOAT(SP_SEC_SOLVER, "newton_divergence", solver.newton_divergence, 0.0,
              AT_LEAST(0.0), UNBOUNDED, "-",
              "a step fails (and is retried with a smaller dt) as soon as an "
              "iteration's residual norm exceeds this multiple of the step's "
              "first one (0: off; otherwise > 1)"),
    KEY_ENUM(SP_SEC_SOLVER, "line_search", solver.line_search, SP_STEP_FULL,
             sp_line_search_words, "-",
             "the length of each Newton update: the full step (as in the "
             "paper) or NOX's backtracking line search, which halves it "
             "until the residual norm falls (down to 1e-12 of it, then the "
             "full step): fewer failed attempts and larger steps in packed "
             "aggregates"),
    KEY_ENUM(SP_SEC_SOLVER, "ordering", solver.ordering, SP_ORDER_PAIRS,
             sp_ordering_words, "-",
             "superlu_dist's fill-reducing order: METIS on the graph of the "
             "(cell, node) pairs (quicker to build) or on the unknowns "
             "(SuperLU_DIST's own; a little less fill with hundreds of cells)"),
    KEY_BOOL(SP_SEC_SOLVER, "refine", solver.refine, 0, "-",
             "superlu_dist: one step of iterative refinement after each "
             "solve (SuperLU_DIST's default; off: solves cost a third, and "
             "the paper's run 5 and the aggregate take the same Newton "
             "iterations to the same energies within 1e-15)"),
    KEY_INT(SP_SEC_SOLVER, "ilu_fill", solver.ilu_fill, 2, AT_LEAST(0), AT_MOST(20), "-",
            "gmres_ilu: level of fill of the incomplete LU preconditioner "
            "(ILU(k), 0: no fill; 1 stalls on these matrices, 2 is the "
            "cheapest that converges well)"),
    KEY_FLOAT(SP_SEC_SOLVER, "krylov_tol", solver.krylov_tol, 0.0, AT_LEAST(0.0), AT_MOST(1e-3),
              "-",
              "gmres_ilu, gmres_cells, gmres_amg: a linear solve ends when its residual is below this "
              "fraction of the right-hand side's norm (a solve not there in "
              "500 iterations fails the Newton attempt); 0: the solver's "
              "own, 1e-10 for gmres_ilu, 1e-4 for gmres_cells (docs/3d.md), 1e-6 for "
              "gmres_amg (docs/solvers.md)"),
    KEY_ENUM(SP_SEC_SOLVER, "predictor", solver.predictor, SP_PREDICT_LINEAR,
             sp_predictor_words, "-",
             "Newton's initial guess: the last state (none) or the last state "
             "plus its last increment x min(dt / dt_last, 2) (linear; not "
             "across a division)"),
    /* output */
    KEY_INT(SP_SEC_OUTPUT, "every", output.every, 10, AT_LEAST(1),
            AT_MOST(INT_MAX), "steps",
            "write fields and pictures every this many steps"),
    KEY_BOOL(SP_SEC_OUTPUT, "pictures", output.pictures, 1, "-",
             "write PNG pictures (2D: cells_<step>.png; 3D: sections_<step>.png "
             "and surfaces_<step>.png, docs/3d.md)"),
    KEY_INT(SP_SEC_OUTPUT, "picture_width", output.picture_width, 800,
            AT_LEAST(64), AT_MOST(8192), "px", "picture width"),
    KEY_BOOL(SP_SEC_OUTPUT, "contacts", output.contacts, 1, "-",
             "write contacts.csv (every step, as cells.csv: each cell's volume, "
             "surface and free surface, each pair in contact with its contact "
             "area, a length in 2D) and, with pictures, contacts_<step>.png "
             "(docs/model.md, \"Contacts\")"),
    KEY_ENUM(SP_SEC_OUTPUT, "contact_measure", output.contact_measure, SP_CONTACT_ISOSURFACE,
             sp_contact_measure_words, "-",
             "isosurface: a cell's surface is its membrane c = 1/2, a pair's contact "
             "the part of each membrane where the other cell's field is at least "
             "contact_level (zero for membranes further apart than "
             "d ln((1 - level) / level)); overlap: the diffuse surface (the integral "
             "of the gradient's norm) and the overlap of two cells' interface "
             "densities, which reads every pair within a few d as touching "
             "(docs/model.md, \"Contacts\")"),
    KEY_FLOAT(SP_SEC_OUTPUT, "contact_level", output.contact_level, 0.05,
              ABOVE(0.0), AT_MOST(0.5), "-",
              "contact_measure isosurface: the part of a cell's membrane where another "
              "cell's field is at least this is in contact with it"),
    KEY_FLOAT(SP_SEC_OUTPUT, "contact_threshold", output.contact_threshold, 0.01,
              AT_LEAST(0.0), AT_MOST(1.0), "-",
              "two cells are in contact (a row of contacts.csv, an edge of the "
              "contact graph) when their measured contact is above 0 and at least this "
              "fraction of the smaller of their two surfaces"),
    KEY_FLOAT(SP_SEC_OUTPUT, "interval", output.interval, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "T",
              "also write fields and pictures at every multiple of this time "
              "(steps land on them; 0: off)"),
    KEY_BOOL(SP_SEC_OUTPUT, "timings", output.timings, 1, "-",
             "energy.csv's wall-clock columns (seconds, assembly_s, ...): the "
             "measured seconds, or zeros (false: two runs' logs compare byte "
             "for byte)"),
    KEY_INT(SP_SEC_OUTPUT, "checkpoint_every", output.checkpoint_every, 0,
            AT_LEAST(0), AT_MOST(INT_MAX), "steps",
            "write a checkpoint every this many steps (0: off; docs/restart.md)"),
    KEY_FLOAT(SP_SEC_OUTPUT, "checkpoint_seconds", output.checkpoint_seconds, 0.0,
              AT_LEAST(0.0), UNBOUNDED, "s",
              "also write a checkpoint after this much wall-clock time since "
              "the last one (0: off)"),
    KEY_INT(SP_SEC_OUTPUT, "checkpoint_keep", output.checkpoint_keep, 2,
            AT_LEAST(1), AT_MOST(1000000), "files",
            "keep the newest this many checkpoints, delete older ones"),
    NAME_KEY(SP_SEC_OUTPUT, sp_scene, "length_unit", output.length_unit, 0,
             "the unit outputs may be read in (e.g. um): units.csv gives each length, area, "
             "volume, moment, contact and surface column's unit and factor (none: no "
             "units.csv; docs/embryo.md, \"Units\")"),
    KEY_FLOAT(SP_SEC_OUTPUT, "length_scale", output.length_scale, 1.0, ABOVE(0.0), UNBOUNDED,
              "-", "one model length is this many length_unit (e.g. 50: 1 L = 50 um)"),
    NAME_KEY(SP_SEC_OUTPUT, sp_scene, "time_unit", output.time_unit, 0,
             "the unit times may be read in (e.g. min): units.csv gives each time column's "
             "unit and factor"),
    KEY_FLOAT(SP_SEC_OUTPUT, "time_scale", output.time_scale, 1.0, ABOVE(0.0), UNBOUNDED, "-",
              "one model time is this many time_unit"),
    /* division */
    KEY_ENUM(SP_SEC_DIVISION, "criterion", division.criterion, SP_DIVIDE_NONE,
             sp_division_words, "-",
             "when a cell divides: never, at age t_div, or at mass_ratio x "
             "its birth mass"),
    KEY_FLOAT(SP_SEC_DIVISION, "t_div", division.t_div, 0.01, ABOVE(0.0),
              UNBOUNDED, "T", "age criterion: age at division"),
    KEY_FLOAT(SP_SEC_DIVISION, "mass_ratio", division.mass_ratio, 2.0,
              ABOVE(1.0), UNBOUNDED, "-",
              "mass criterion: divide when m_k reaches this x m_k^0"),
    KEY_BOOL(SP_SEC_DIVISION, "use_initial_mass", division.use_initial_mass, 0,
             "-",
             "mass criterion: m_k^0 is the first cell's birth mass for every "
             "cell (the authors' code) instead of each cell's own"),
    KEY_INT(SP_SEC_DIVISION, "max_cells", division.max_cells, 0, AT_LEAST(0),
            AT_MOST(100000), "cells",
            "N_max: no division beyond this many cells (0: meas(Omega) / m^0 "
            "of the first cell)"),
    KEY_INT(SP_SEC_DIVISION, "n_div", division.n_div, 3, AT_LEAST(0),
            AT_MOST(100), "steps",
            "algorithm 2: steps at dt_bar 10^-m after a division"),
    KEY_INT(SP_SEC_DIVISION, "m", division.m, 6, AT_LEAST(0), AT_MOST(12),
            "-", "algorithm 2: dt = dt_bar 10^-m (a - n_div)^m while ramping"),
    KEY_ENUM(SP_SEC_DIVISION, "cut", division.cut, SP_CUT_SHARP, sp_cut_words,
             "-",
             "the split: sharp (the paper) or smooth (tanh of the distance "
             "to the division line (3D: plane), width d)"),
    KEY_ENUM(SP_SEC_DIVISION, "line", division.line, SP_LINE_CENTRE, sp_line_words,
             "-",
             "the division line (3D: plane), normal to the cell's long axis: "
             "through the centre of mass (the paper) or moved along that axis so "
             "the daughters get equal masses"),
    KEY_FLOAT(SP_SEC_DIVISION, "observe_threshold", division.observe_threshold,
              0.05, AT_LEAST(0.0), BELOW(0.5), "-",
              "centre, inertia and the mass criterion count c_k only where "
              "c_k >= this, so the background does not count"),
    /* source */
    KEY_FLOAT(SP_SEC_SOURCE, "rate", source.rate, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "1/T",
              "growth source s_bar inside each cell (the paper: 0 or 5e2)"),
    KEY_FLOAT(SP_SEC_SOURCE, "off_ratio", source.off_ratio, 1.1, ABOVE(1.0),
              UNBOUNDED, "-",
              "a cell's source stops once N >= N_max and m_k / m_k^0 > this"),
    KEY_ENUM(SP_SEC_SOURCE, "indicator", source.indicator, SP_INDICATOR_EXTRAPOLATED,
             sp_indicator_words, "-",
             "where a BDF2 step evaluates omega_k (c_k >= 1/2): c extrapolated "
             "linearly to the step's end (second order) or c^n (first order); "
             "backward-Euler steps use c^n (the paper's algorithm 3)"),
    /* layout */
    KEY_ENUM(SP_SEC_LAYOUT, "support", layout.support, SP_SUPPORT_AUTO,
             sp_support_words, "-",
             "each field on the whole mesh (full: the paper) or on a moving "
             "neighbourhood of its cell (local); auto: local when the scene "
             "can hold more than 4 cells"),
    KEY_FLOAT(SP_SEC_LAYOUT, "margin", layout.margin, 8.0, ABOVE(0.0),
              UNBOUNDED, "d",
              "local: the support reaches this many interface widths d "
              "beyond the cell's core"),
    KEY_FLOAT(SP_SEC_LAYOUT, "core_threshold", layout.core_threshold, 0.1,
              ABOVE(0.0), BELOW(1.0), "-", "local: the core is c_k >= this"),
    KEY_FLOAT(SP_SEC_LAYOUT, "grow_threshold", layout.grow_threshold, 0.2,
              ABOVE(0.0), BELOW(1.0), "-",
              "local: supports are recomputed when c_k >= this within band "
              "of a support's edge (0.2; at 0.1 the far field piling up at "
              "the no-flux edge triggers a change every few steps: "
              "docs/local-support.md)"),
    KEY_FLOAT(SP_SEC_LAYOUT, "band", layout.band, 4.0, ABOVE(0.0), UNBOUNDED,
              "d", "local: width of that band in interface widths (< margin)"),
    KEY_ENUM(SP_SEC_LAYOUT, "shrink", layout.shrink, SP_SHRINK_ALWAYS, sp_shrink_words,
             "-",
             "local: supports grow whenever a cell needs it; they shrink at "
             "every support change (always), or only for the two daughters "
             "of a division (divisions: no energy rise from dropping "
             "far-field mass, but supports trail moving and growing cells: "
             "many more unknowns in growth runs)"),
    KEY_ENUM(SP_SEC_LAYOUT, "fill", layout.fill, SP_FILL_RELAX, sp_fill_words, "-",
             "local: what new (cell, node) pairs of a support change start "
             "from: the old edge's mean c at the node's stiffness (edge: "
             "the published runs), or that relaxed to the far field's "
             "equations at the free edge's chemical potential (relax: far "
             "fewer steps with narrow margins, docs/local-support.md)"),
    KEY_ENUM(SP_SEC_LAYOUT, "restore", layout.restore, SP_RESTORE_POTENTIAL,
             sp_restore_words, "-",
             "local: how a support change gives each cell back the mass it "
             "moved: a uniform shift of c_k over the cell's interior c_k >= "
             "1/2 (interior: the published runs; a small, pressed cell's few "
             "interior nodes can take shifts of 0.5 and more), or the far "
             "field's response to one rise of the chemical potential over "
             "the whole support, held down inside neighbours and the buffer "
             "ring (potential: smooth, docs/local-support.md)"),
    KEY_ENUM(SP_SEC_LAYOUT, "buffer_elements", layout.buffer_elements,
             SP_BUFFER_ELEMENTS_WHOLE, sp_buffer_elements_words, "-",
             "local: a support that reaches the buffer ring takes every "
             "buffer element it touches whole, so no node of its edge sits "
             "beside the ring unheld (whole: far smaller energy rises at a "
             "change in the eggshell, docs/local-support.md), or the "
             "elements within the margin alone (margin: the published runs)"),
    KEY_BOOL(SP_SEC_LAYOUT, "widen", layout.widen, 1, "-",
             "local: a support that would call for another update as soon "
             "as it is built (elements wider than margin - band, a far field "
             "above grow_threshold at its edge) is widened by layers of "
             "elements until it does not (true: one change where there were "
             "one per step on coarse 3D meshes; false: the supports as "
             "computed, the published aggregates, docs/local-support.md)"),
    /* shape: Pi_MI = delta^i (I^i,ref - I^i)^2 with moments in L^4 and Pi
     * in E L^2, so delta is in E / L^6 (3D: L^5, E L^3, E / L^7) */
    KEY_FLOAT(SP_SEC_SHAPE, "delta1", shape.delta1, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "E/L^6",
              "shape penalty modulus on the largest principal moment I^1 "
              "(0: none; the paper's single-cell study: -> 0)"),
    KEY_FLOAT(SP_SEC_SHAPE, "delta2", shape.delta2, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "E/L^6",
              "shape penalty modulus on the second principal moment I^2, the "
              "smaller in 2D (0: none; the paper: 5e4 to 2e5)"),
    KEY_FLOAT(SP_SEC_SHAPE, "delta3", shape.delta3, 0.0, AT_LEAST(0.0),
              UNBOUNDED, "E/L^7",
              "3D only: shape penalty modulus on the smallest principal "
              "moment I^3, the long axis's (0: none; docs/3d.md)"),
    KEY_ENUM(SP_SEC_SHAPE, "scheme", shape.scheme, SP_SHAPE_EXPLICIT, sp_shape_scheme_words,
             "-",
             "explicit: coefficients from c^n (the paper); implicit: the "
             "moments of the new state, linearised about c^n (stable for "
             "stiff moduli; 2 (3D: 3) extra right-hand sides per cell in each Newton "
             "iteration's solve)"),
    /* initial: the initial fields from files (src/io/initial.h) */
    KEY_PATH(SP_SEC_INITIAL, "from", initial.from,
             "start from the fields of a softpack checkpoint (.h5) or .vtu on the "
             "same mesh instead of the cells' disks (docs/restart.md)"),
    KEY_PATH(SP_SEC_INITIAL, "label_image", initial.label_image,
             "start from a PNG label image: every colour but black (and "
             "transparent) is one cell, smoothed to the equilibrium profile "
             "(docs/restart.md)"),
    KEY_FLOAT(SP_SEC_INITIAL, "x0", initial.x0, -0.5, UNBOUNDED, UNBOUNDED, "L",
              "label_image: x of the image's left edge"),
    KEY_FLOAT(SP_SEC_INITIAL, "y0", initial.y0, -0.25, UNBOUNDED, UNBOUNDED, "L",
              "label_image: y of the image's bottom edge"),
    KEY_FLOAT(SP_SEC_INITIAL, "x1", initial.x1, 0.5, UNBOUNDED, UNBOUNDED, "L",
              "label_image: x of the image's right edge (> x0)"),
    KEY_FLOAT(SP_SEC_INITIAL, "y1", initial.y1, 0.25, UNBOUNDED, UNBOUNDED, "L",
              "label_image: y of the image's top edge (> y0)"),
    KEY_PATH(SP_SEC_INITIAL, "label_volume", initial.label_volume,
             "3D meshes: start from a NIfTI label volume (.nii, .nii.gz): every "
             "nonzero integer label is one cell, smoothed to the equilibrium "
             "profile, placed by the file's sform (else qform, else voxel size) "
             "(docs/3d.md)"),
    KEY_FLOAT(SP_SEC_INITIAL, "scale", initial.scale, 1.0, ABOVE(0.0), UNBOUNDED, "L",
              "label_volume: mesh length per unit of the file's coordinates (e.g. 0.01 "
              "for a file in micrometres on a mesh in units of 100 um)"),
    KEY_FLOAT(SP_SEC_INITIAL, "offset_x", initial.offset_x, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "label_volume: x where the file's origin lands (with centre: the labels' "
              "centre)"),
    KEY_FLOAT(SP_SEC_INITIAL, "offset_y", initial.offset_y, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "label_volume: y where the file's origin lands (see offset_x)"),
    KEY_FLOAT(SP_SEC_INITIAL, "offset_z", initial.offset_z, 0.0, UNBOUNDED, UNBOUNDED, "L",
              "label_volume: z where the file's origin lands (see offset_x)"),
    KEY_BOOL(SP_SEC_INITIAL, "centre", initial.centre, 0, "-",
             "label_volume: place the centre of the labelled voxels' bounding box, not "
             "the file's origin, at (offset_x, offset_y, offset_z)"),
    /* cells: one mapping per initial cell */
    CELL_FLOAT_REQUIRED("x", x, UNBOUNDED, UNBOUNDED, "L",
                        "centre x; the cell's disk must lie inside Omega"),
    CELL_FLOAT_REQUIRED("y", y, UNBOUNDED, UNBOUNDED, "L",
                        "centre y; the cell's disk must lie inside Omega"),
    CELL_FLOAT("z", z, NAN, UNBOUNDED, UNBOUNDED, "L",
               "centre z: required on a 3D mesh (mesh.type box, ellipsoid), where the "
               "cell is a sphere inside Omega; not allowed on a 2D one"),
    CELL_FLOAT_REQUIRED("radius", radius, ABOVE(0.0), UNBOUNDED, "L",
                        "radius of the c = 1/2 level set"),
    CELL_FLOAT("semi_x", semi_x, NAN, ABOVE(0.0), UNBOUNDED, "L",
               "semi-axis along x of an elongated cell (none: radius): with semi_y, "
               "semi_z the cell is the ellipse (ellipsoid) with these semi-axes along "
               "the coordinate axes (or turned: axis_x), radius the ones not given; it must "
               "lie inside Omega"),
    CELL_FLOAT("semi_y", semi_y, NAN, ABOVE(0.0), UNBOUNDED, "L",
               "semi-axis along y (none: radius); see semi_x"),
    CELL_FLOAT("semi_z", semi_z, NAN, ABOVE(0.0), UNBOUNDED, "L",
               "semi-axis along z (none: radius); only on a 3D mesh; see semi_x"),
    CELL_FLOAT("axis_x", axis[0], NAN, UNBOUNDED, UNBOUNDED, "-",
               "an ellipse's (ellipsoid's) orientation: the direction (axis_x, axis_y, "
               "axis_z; any length > 0, components not given 0) its semi_x axis is turned "
               "onto, by the smallest rotation (semi_y, semi_z turn with it; docs/scene.md, "
               "\"Cells\"); none: along the coordinate axes"),
    CELL_FLOAT("axis_y", axis[1], NAN, UNBOUNDED, UNBOUNDED, "-",
               "y component of the semi_x axis' direction; see axis_x"),
    CELL_FLOAT("axis_z", axis[2], NAN, UNBOUNDED, UNBOUNDED, "-",
               "z component of the semi_x axis' direction; only on a 3D mesh; see axis_x"),
    CELL_ENUM("profile", profile, SP_PROFILE_TANH, sp_profile_words, "-",
              "initial profile: tanh (equilibrium width d) or sharp (0/1)"),
    NAME_KEY(SP_SEC_CELLS, sp_scene_cell, "name", name, 0,
             "the cell's name (e.g. P0; unique; cells.csv and divisions.csv get a name "
             "column when the scene names its cells); the lineage table refers to it"),
    /* lineage: one mapping per named cell that divides by it (src/model/lineage.h) */
    NAME_KEY(SP_SEC_LINEAGE, sp_scene_lineage, "cell", cell, 1,
             "the dividing cell: an initial cell's name or a daughter of another entry"),
    LINEAGE_FLOAT("age", age, NAN, ABOVE(0.0), UNBOUNDED, "T",
                  "it divides at this age (after its birth); exactly one of age, time "
                  "and mass_ratio"),
    LINEAGE_FLOAT("time", time, NAN, ABOVE(0.0), UNBOUNDED, "T",
                  "it divides at this time t (absolute; at once if born later)"),
    LINEAGE_FLOAT("mass_ratio", mass_ratio, NAN, ABOVE(1.0), UNBOUNDED, "-",
                  "it divides when its core mass reaches this x its birth core mass "
                  "(as division.mass_ratio)"),
    LINEAGE_FLOAT("fraction", fraction, 0.5, ABOVE(0.0), BELOW(1.0), "-",
                  "the first daughter's share of the parent's mass (the cut is moved "
                  "along its normal to give it: docs/model.md)"),
    NAME_KEY(SP_SEC_LINEAGE, sp_scene_lineage, "first", first, 1,
             "the first daughter's name: the side the cut's normal points away from"),
    NAME_KEY(SP_SEC_LINEAGE, sp_scene_lineage, "second", second, 1,
             "the second daughter's name: the side the normal points to"),
    LINEAGE_ENUM("axis", axis, SP_AXIS_LONG, sp_axis_words, "-",
                 "the cut's normal: long (the cell's long principal axis, the paper's "
                 "rule), fixed (direction_x, _y, _z) or perpendicular (to the parent's "
                 "own cut normal: turned by 90 degrees in 2D, in 3D the long axis "
                 "projected on the plane normal to it); long and perpendicular "
                 "point to +x (then +y, +z), so the first daughter is the one at lower x"),
    LINEAGE_FLOAT("direction_x", direction[0], NAN, UNBOUNDED, UNBOUNDED, "-",
                  "axis fixed: x component of the cut's normal (any length > 0)"),
    LINEAGE_FLOAT("direction_y", direction[1], NAN, UNBOUNDED, UNBOUNDED, "-",
                  "axis fixed: y component of the cut's normal"),
    LINEAGE_FLOAT("direction_z", direction[2], NAN, UNBOUNDED, UNBOUNDED, "-",
                  "axis fixed: z component of the cut's normal (3D meshes only)"),
    /* adhesion: one mapping per named pair with a sigma of its own (src/model/adhesion.h) */
    NAME_KEY(SP_SEC_ADHESION, sp_scene_adhesion, "cell", cell, 1,
             "one cell of the pair: an initial cell's name or a daughter of a lineage entry"),
    NAME_KEY(SP_SEC_ADHESION, sp_scene_adhesion, "other", other, 1,
             "the other cell of the pair (as cell)"),
    ADHESION_FLOAT_REQUIRED("sigma", sigma, AT_LEAST(0.0), UNBOUNDED, "E L^2",
                            "the pair's adhesion sigma while both cells exist, instead of "
                            "model.adhesion_sisters or model.adhesion_non_sisters (0: none "
                            "between them); below kappa"),
};

_Static_assert(sizeof sp_keys / sizeof sp_keys[0] == SP_N_KEYS,
               "SP_N_KEYS (scene_private.h) must be the number of rows of sp_keys[]");

/* ------------------------------------------------------------------------ */
/* Table queries and descriptions                                           */
/* ------------------------------------------------------------------------ */

/** Position of @p key among the keys of its section: its raw slot. */
size_t sp_keys_slot(const sp_key *key) {
  size_t slot = 0;
  for (const sp_key *k = sp_keys; k != key; ++k)
    slot += k->section == key->section;
  return slot;
}

size_t sp_keys_section_count(sp_section section) {
  size_t n = 0;
  for (size_t i = 0; i < SP_N_KEYS; ++i) n += sp_keys[i].section == section;
  return n;
}

/** The key named @p name (length @p len) in @p section, or NULL. */
const sp_key *sp_keys_find(sp_section section, const char *name,
                              size_t len) {
  for (size_t i = 0; i < SP_N_KEYS; ++i)
    if (sp_keys[i].section == section && strlen(sp_keys[i].name) == len &&
        strncmp(sp_keys[i].name, name, len) == 0)
      return &sp_keys[i];
  return NULL;
}

/** The section named @p name (length @p len), or SP_N_SECTIONS. */
sp_section sp_keys_find_section(const char *name, size_t len) {
  for (int s = 0; s < SP_N_SECTIONS; ++s)
    if (strlen(sp_section_names[s]) == len &&
        strncmp(sp_section_names[s], name, len) == 0)
      return (sp_section)s;
  return SP_N_SECTIONS;
}

/** "model.kappa", or "cells[3].x", "lineage[0].cell" (cell < 0:
 *  "cells[i].x"). */
const char *sp_keys_path(const sp_key *key, int cell, char *buf,
                            size_t size) {
  const char *section = sp_section_names[key->section];
  if (!is_sequence(key->section))
    snprintf(buf, size, "%s.%s", section, key->name);
  else if (cell >= 0)
    snprintf(buf, size, "%s[%d].%s", section, cell, key->name);
  else
    snprintf(buf, size, "%s[i].%s", section, key->name);
  return buf;
}

/** The keys of @p section, comma separated (only_required: those only). */
const char *sp_keys_section_list(sp_section section, int only_required,
                                    char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (size_t i = 0; i < SP_N_KEYS && used < size; ++i) {
    const sp_key *k = &sp_keys[i];
    if (k->section != section || (only_required && !k->required)) continue;
    used += (size_t)snprintf(buf + used, size - used, "%s%s",
                             used ? ", " : "", k->name);
  }
  return buf;
}

const char *sp_keys_sections(char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (int s = 0; s < SP_N_SECTIONS && used < size; ++s)
    used += (size_t)snprintf(buf + used, size - used, "%s%s",
                             used ? ", " : "", sp_section_names[s]);
  return buf;
}

/** The accepted words of an enum or bool key, comma separated. */
static const char *word_list(const sp_key *key, char *buf, size_t size) {
  size_t used = 0;
  buf[0] = '\0';
  for (unsigned i = 0; i < key->n_words && used < size; ++i)
    used += (size_t)snprintf(buf + used, size - used, "%s%s",
                             used ? ", " : "", key->words[i].str);
  return buf;
}

/** The first word naming @p value (enum and bool keys). */
const char *sp_keys_word_of(const sp_key *key, double value) {
  for (unsigned i = 0; i < key->n_words; ++i)
    if ((double)key->words[i].val == value) return key->words[i].str;
  return "?";
}

const char *sp_scene_linear_name(sp_linear_kind kind) {
  for (size_t i = 0; i < sizeof sp_linear_words / sizeof sp_linear_words[0]; ++i)
    if (sp_linear_words[i].val == (int64_t)kind) return sp_linear_words[i].str;
  return "?";
}

/** The allowed range: "> 0", ">= 1", "[1, 4096]", "(0, 1)", "any". */
static const char *range_text(const sp_key *key, char *buf, size_t size) {
  const sp_bound *lo = &key->lower, *hi = &key->upper;
  if (lo->kind != SP_UNBOUNDED && hi->kind != SP_UNBOUNDED)
    snprintf(buf, size, "%c%.15g, %.15g%c",
             lo->kind == SP_INCLUSIVE ? '[' : '(', lo->value, hi->value,
             hi->kind == SP_INCLUSIVE ? ']' : ')');
  else if (lo->kind != SP_UNBOUNDED)
    snprintf(buf, size, "%s %.15g", lo->kind == SP_INCLUSIVE ? ">=" : ">",
             lo->value);
  else if (hi->kind != SP_UNBOUNDED)
    snprintf(buf, size, "%s %.15g", hi->kind == SP_INCLUSIVE ? "<=" : "<",
             hi->value);
  else
    snprintf(buf, size, "any");
  return buf;
}

/** What a key accepts, for messages: "a number > 0", "one of ad, hand". */
const char *sp_keys_expectation(const sp_key *key, char *buf, size_t size) {
  char words[SP_LIST_TEXT], range[SP_TEXT];
  static const char *const what[] = {"a number", "an integer",
                                     "an unsigned integer"};
  switch (key->type) {
  case SP_KEY_BOOL:
  case SP_KEY_ENUM:
    snprintf(buf, size, "one of %s", word_list(key, words, sizeof words));
    break;
  case SP_KEY_PATH:
    snprintf(buf, size, "a file name of at most %d characters", SP_SCENE_PATH_MAX - 1);
    break;
  case SP_KEY_NAME:
    snprintf(buf, size, "a name of 1 to %d letters, digits, '_', '.' or '-'",
             SP_CELL_NAME_MAX - 1);
    break;
  default:
    range_text(key, range, sizeof range);
    if (key->lower.kind != SP_UNBOUNDED && key->upper.kind != SP_UNBOUNDED)
      snprintf(buf, size, "%s in %s", what[key->type], range);
    else if (key->lower.kind != SP_UNBOUNDED ||
             key->upper.kind != SP_UNBOUNDED)
      snprintf(buf, size, "%s %s", what[key->type], range);
    else
      snprintf(buf, size, "%s", what[key->type]);
  }
  return buf;
}

void sp_scene_print_keys(FILE *out) {
  char path[SP_TEXT], range[SP_LIST_TEXT], fallback[SP_TEXT];
  fprintf(out, "| key | type | unit | default | allowed | meaning |\n"
               "|---|---|---|---|---|---|\n");
  for (size_t i = 0; i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    if (key->type == SP_KEY_BOOL || key->type == SP_KEY_ENUM)
      word_list(key, range, sizeof range);
    else if (key->type == SP_KEY_PATH)
      snprintf(range, sizeof range, "a file");
    else if (key->type == SP_KEY_NAME)
      snprintf(range, sizeof range, "1 to %d of A-Z a-z 0-9 _ . -", SP_CELL_NAME_MAX - 1);
    else
      range_text(key, range, sizeof range);
    if (key->required)
      snprintf(fallback, sizeof fallback, "required");
    else if (key->type == SP_KEY_PATH || key->type == SP_KEY_NAME)
      snprintf(fallback, sizeof fallback, "none");
    else if (key->type == SP_KEY_BOOL || key->type == SP_KEY_ENUM)
      snprintf(fallback, sizeof fallback, "%s", sp_keys_word_of(key, key->fallback));
    else if (isnan(key->fallback))
      snprintf(fallback, sizeof fallback, "none");
    else
      snprintf(fallback, sizeof fallback, "%.15g", key->fallback);
    fprintf(out, "| `%s` | %s | %s | %s | %s | %s |\n",
            sp_keys_path(key, -1, path, sizeof path),
            sp_key_type_names[key->type], key->unit, fallback, range,
            key->meaning);
  }
}
