/**
 * @file scene.c
 * @brief The scene file: one key table, a libcyaml schema built from it,
 *        range and cross-key validation, `--set` overrides.
 *
 * Everything a key is (section, name, type, where it lives in sp_scene,
 * default, allowed range, unit, meaning) is written once, in sp_keys[]. The
 * libcyaml schema, the defaults, the checks, the error messages, the
 * `--set` parser and the documentation table are all derived from it.
 *
 * How libcyaml 1.3.1 is used, and why:
 * - Each section is loaded as an array of void * slots, one per key in table
 *   order; every key field is CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL, so a
 *   key absent from the file leaves its slot NULL and keeps its default.
 * - Numbers (float, int, uint keys) are loaded as strings and converted here
 *   with a strict parser. libcyaml 1.3.1's own scalar readers are lax: its
 *   FLOAT reader takes "1,5" as 1 and "2e-4s" as 2e-4, its INT reader takes
 *   "1.5" as 1, and its BOOL reader takes any word it does not know ("maybe")
 *   as true. A silently misread parameter is worse than a missing line
 *   number, which is all the string route costs (libcyaml reports lines only
 *   for what it rejects itself).
 * - Enums, and booleans (an enum of the YAML 1.1 words true/false, yes/no,
 *   on/off), are libcyaml ENUMs with CYAML_FLAG_STRICT: libcyaml rejects
 *   unknown words itself and reports the line.
 * - Errors: libcyaml logs a message ("Unexpected key: zz", "Invalid ENUM
 *   value: foo", "libyaml: did not find expected key", ...) followed by a
 *   backtrace, innermost first, of lines such as
 *   "  in mapping field 'linear' (line: 12, column: 11)" and
 *   "  in sequence entry '2' (line: 20, column: 5)" (1-based). A log_fn
 *   captures those lines; the backtrace is turned into a key path
 *   (solver.linear, cells[1].x) and the line of the innermost entry.
 * - `--set section.key=value` values are loaded by libcyaml with the very
 *   value schema the key has in the file and then go through the same
 *   conversion and range check, so a value means the same in both places.
 */
#include "scene/scene.h"

#include <cyaml/cyaml.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"

/* ------------------------------------------------------------------------ */
/* The key table                                                            */
/* ------------------------------------------------------------------------ */

/** Sections of a scene file, in the order they are documented. */
typedef enum {
  SP_SEC_MESH,
  SP_SEC_MODEL,
  SP_SEC_TIME,
  SP_SEC_NOISE,
  SP_SEC_SOLVER,
  SP_SEC_OUTPUT,
  SP_SEC_DIVISION,
  SP_SEC_SOURCE,
  SP_SEC_LAYOUT,
  SP_SEC_SHAPE,
  SP_SEC_INITIAL,
  SP_SEC_CELLS, /**< a sequence of cell mappings, not a mapping of scalars */
  SP_SEC_LINEAGE, /**< a sequence of lineage entries, like cells */
  SP_N_SECTIONS
} sp_section;

/** The sections before SP_SEC_CELLS are mappings of scalars, the rest
 *  sequences of mappings (one record each: sp_sequences[]). */
#define SP_N_MAPPINGS SP_SEC_CELLS
#define SP_N_SEQUENCES (SP_N_SECTIONS - SP_N_MAPPINGS)

static const char *const sp_section_names[SP_N_SECTIONS] = {
    "mesh", "model", "time", "noise", "solver", "output", "division", "source",
    "layout", "shape", "initial", "cells", "lineage"};

/** A sequence section: where its records and their count live in sp_scene,
 *  a record's size, and what one entry is called in messages. */
typedef struct {
  size_t records, count, size;
  const char *entry;
} sp_sequence;

static const sp_sequence sp_sequences[SP_N_SEQUENCES] = {
    {offsetof(sp_scene, cells), offsetof(sp_scene, n_cells), sizeof(sp_scene_cell), "a cell"},
    {offsetof(sp_scene, lineage), offsetof(sp_scene, n_lineage), sizeof(sp_scene_lineage),
     "a lineage entry"}};

static int is_sequence(sp_section section) { return section >= SP_N_MAPPINGS; }

/** The sequence of a sequence section. */
static const sp_sequence *sequence_of(sp_section section) {
  return &sp_sequences[section - SP_N_MAPPINGS];
}

/** Record @p i of a sequence section of @p scene. */
static void *sequence_record(const sp_scene *scene, sp_section section, int i) {
  const sp_sequence *q = sequence_of(section);
  return *(char *const *)((const char *)scene + q->records) + (size_t)i * q->size;
}

static int sequence_count(const sp_scene *scene, sp_section section) {
  return *(const int *)((const char *)scene + sequence_of(section)->count);
}

/** Scalar type of a key as the user sees it. */
typedef enum {
  SP_KEY_FLOAT, /**< double */
  SP_KEY_INT,   /**< int (written as an integer-valued number, 1e6 is fine) */
  SP_KEY_UINT,  /**< unsigned */
  SP_KEY_BOOL,  /**< int 0/1, written true/false (yes/no, on/off) */
  SP_KEY_ENUM,  /**< int, written as one of a list of words */
  SP_KEY_PATH,  /**< char[SP_SCENE_PATH_MAX], a file name ("": none) */
  SP_KEY_NAME   /**< sp_cell_name: a cell's name ("": none; name_valid) */
} sp_key_type;

static const char *const sp_key_type_names[] = {"float", "int", "uint", "bool",
                                                 "enum",  "path", "name"};

/** How one end of an allowed range is closed. */
typedef enum {
  SP_UNBOUNDED = 0, /**< no limit at this end */
  SP_INCLUSIVE,     /**< the limit itself is allowed */
  SP_EXCLUSIVE      /**< the limit itself is not allowed */
} sp_bound_kind;

typedef struct {
  sp_bound_kind kind;
  double value;
} sp_bound;

/* Range ends, spelt for reading the table (lower: AT_LEAST / ABOVE, upper:
 * AT_MOST / BELOW). */
#define UNBOUNDED {SP_UNBOUNDED, 0.0}
#define AT_LEAST(v) {SP_INCLUSIVE, (v)}
#define ABOVE(v) {SP_EXCLUSIVE, (v)}
#define AT_MOST(v) {SP_INCLUSIVE, (v)}
#define BELOW(v) {SP_EXCLUSIVE, (v)}

/** One key of the scene file. */
typedef struct {
  sp_section section;
  const char *name;
  sp_key_type type;
  size_t offset;   /**< into sp_scene, or into the record of a sequence
                        section (sp_scene_cell, sp_scene_lineage) */
  double fallback; /**< the default (enum/bool: the value of the word) */
  int required;    /**< 1: no default, the key must be given (sequences only) */
  sp_bound lower, upper;
  const cyaml_strval_t *words; /**< enum and bool: the accepted words */
  unsigned n_words;
  const char *unit;
  const char *meaning;
} sp_key;

static const cyaml_strval_t sp_mesh_words[] = {
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

/* Units: L = the model's length unit, T = its time unit, E = its energy per
 * unit area (the energy density of Pi); "-" = dimensionless. Defaults are
 * the paper's values (table 1) where the paper has one. */
static const sp_key sp_keys[] = {
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
             "(gmres_cells: no fill between cells, docs/3d.md); auto: "
             "gmres_cells on a 3D mesh, mumps on a 2D one (the fastest "
             "measured in each, docs/3d.md)"),
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
              "gmres_ilu, gmres_cells: a linear solve ends when its residual is below this "
              "fraction of the right-hand side's norm (a solve not there in "
              "500 iterations fails the Newton attempt); 0: the solver's "
              "own, 1e-10 for gmres_ilu, 1e-4 for gmres_cells (docs/3d.md)"),
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
             "diffuse and free surface, each pair in contact with its contact "
             "area, a length in 2D) and, with pictures, contacts_<step>.png "
             "(docs/model.md, \"Contacts\")"),
    KEY_FLOAT(SP_SEC_OUTPUT, "contact_threshold", output.contact_threshold, 0.01,
              AT_LEAST(0.0), AT_MOST(1.0), "-",
              "two cells are in contact (a row of contacts.csv, an edge of the "
              "contact graph) when their measured contact is at least this "
              "fraction of the smaller of their two diffuse surfaces"),
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
};

#define SP_N_KEYS (sizeof sp_keys / sizeof sp_keys[0])

/** Points on a cell's circle tested against the ellipse (the brief's
 *  sampling: enough to catch a disk poking out by more than ~0.1% of R). */
enum { SP_DISK_CHECK_ANGLES = 64 };

/** Room for formatted keys, ranges and libcyaml log lines. */
enum { SP_TEXT = 256, SP_LIST_TEXT = 512, SP_LOG_LINES = 16 };

/* ------------------------------------------------------------------------ */
/* Table queries and descriptions                                           */
/* ------------------------------------------------------------------------ */

/** Position of @p key among the keys of its section: its raw slot. */
static size_t key_slot(const sp_key *key) {
  size_t slot = 0;
  for (const sp_key *k = sp_keys; k != key; ++k)
    slot += k->section == key->section;
  return slot;
}

static size_t section_key_count(sp_section section) {
  size_t n = 0;
  for (size_t i = 0; i < SP_N_KEYS; ++i) n += sp_keys[i].section == section;
  return n;
}

/** The key named @p name (length @p len) in @p section, or NULL. */
static const sp_key *find_key(sp_section section, const char *name,
                              size_t len) {
  for (size_t i = 0; i < SP_N_KEYS; ++i)
    if (sp_keys[i].section == section && strlen(sp_keys[i].name) == len &&
        strncmp(sp_keys[i].name, name, len) == 0)
      return &sp_keys[i];
  return NULL;
}

/** The section named @p name (length @p len), or SP_N_SECTIONS. */
static sp_section find_section(const char *name, size_t len) {
  for (int s = 0; s < SP_N_SECTIONS; ++s)
    if (strlen(sp_section_names[s]) == len &&
        strncmp(sp_section_names[s], name, len) == 0)
      return (sp_section)s;
  return SP_N_SECTIONS;
}

/** "model.kappa", or "cells[3].x", "lineage[0].cell" (cell < 0:
 *  "cells[i].x"). */
static const char *key_path(const sp_key *key, int cell, char *buf,
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
static const char *section_key_list(sp_section section, int only_required,
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

static const char *section_list(char *buf, size_t size) {
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
static const char *word_of(const sp_key *key, double value) {
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
static const char *expectation(const sp_key *key, char *buf, size_t size) {
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

/* ------------------------------------------------------------------------ */
/* Values: parse, check, store                                              */
/* ------------------------------------------------------------------------ */

/** Strict number: the whole text must be one finite strtod number. */
static int parse_number(const char *text, double *value) {
  char *end;
  if (!text || !*text) return 0;
  *value = strtod(text, &end);
  return end != text && *end == '\0' && isfinite(*value);
}

/** 1 if @p text is a cell name: 1 to SP_CELL_NAME_MAX - 1 letters, digits,
 *  '_', '.' or '-' (it goes into CSV columns and file names unquoted). */
static int name_valid(const char *text) {
  const size_t n = strlen(text);
  if (n == 0 || n >= SP_CELL_NAME_MAX) return 0;
  for (size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
          c == '_' || c == '.' || c == '-'))
      return 0;
  }
  return 1;
}

/** 1 if @p value is allowed for @p key (range; integers: integral). */
static int value_allowed(const sp_key *key, double value) {
  if (!isfinite(value)) return 0;
  if ((key->type == SP_KEY_INT || key->type == SP_KEY_UINT) &&
      value != floor(value))
    return 0;
  const sp_bound *lo = &key->lower, *hi = &key->upper;
  if (lo->kind == SP_INCLUSIVE && !(value >= lo->value)) return 0;
  if (lo->kind == SP_EXCLUSIVE && !(value > lo->value)) return 0;
  if (hi->kind == SP_INCLUSIVE && !(value <= hi->value)) return 0;
  if (hi->kind == SP_EXCLUSIVE && !(value < hi->value)) return 0;
  return 1;
}

/** Write @p value into the member of @p base (sp_scene or sp_scene_cell). */
static void store_value(void *base, const sp_key *key, double value) {
  char *member = (char *)base + key->offset;
  switch (key->type) {
  case SP_KEY_PATH:
  case SP_KEY_NAME: member[0] = '\0'; break; /* the default: none */
  case SP_KEY_FLOAT: *(double *)member = value; break;
  case SP_KEY_UINT: *(unsigned *)member = (unsigned)value; break;
  default: *(int *)member = (int)value; break; /* int, bool, enum */
  }
}

/** The member of @p base (sp_scene or sp_scene_cell) @p key names. */
static double load_value(const void *base, const sp_key *key) {
  const char *member = (const char *)base + key->offset;
  switch (key->type) {
  case SP_KEY_PATH:
  case SP_KEY_NAME: return 0.0; /* compared as text */
  case SP_KEY_FLOAT: return *(const double *)member;
  case SP_KEY_UINT: return *(const unsigned *)member;
  default: return *(const int *)member; /* int, bool, enum */
  }
}

/** 1 if @p key's values in @p a and @p b (sp_scene or records) differ:
 *  text compared as text, numbers bit for bit. */
static int values_differ(const void *a, const void *b, const sp_key *key) {
  if (key->type == SP_KEY_PATH || key->type == SP_KEY_NAME)
    return strcmp((const char *)a + key->offset, (const char *)b + key->offset) != 0;
  return memcmp(&(double){load_value(a, key)}, &(double){load_value(b, key)},
                sizeof(double)) != 0;
}

int sp_scene_first_difference(const sp_scene *a, const sp_scene *b,
                              int (*skip)(const char *key), char *buf, size_t size) {
  for (size_t i = 0; i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    if (is_sequence(key->section)) continue;
    key_path(key, -1, buf, size);
    if (skip && skip(buf)) continue;
    if (values_differ(a, b, key)) return 1;
  }
  for (int s = SP_N_MAPPINGS; s < SP_N_SECTIONS; ++s) {
    const int n = sequence_count(a, (sp_section)s);
    if (n != sequence_count(b, (sp_section)s)) {
      snprintf(buf, size, "%s", sp_section_names[s]);
      if (skip && skip(buf)) continue;
      return 1;
    }
    for (int c = 0; c < n; ++c)
      for (size_t i = 0; i < SP_N_KEYS; ++i) {
        const sp_key *key = &sp_keys[i];
        if (key->section != (sp_section)s) continue;
        key_path(key, c + 1, buf, size);
        if (skip && skip(buf)) continue;
        if (values_differ(sequence_record(a, key->section, c),
                          sequence_record(b, key->section, c), key))
          return 1;
      }
  }
  return 0;
}

static void store_defaults(void *base, sp_section section) {
  for (size_t i = 0; i < SP_N_KEYS; ++i)
    if (sp_keys[i].section == section && !sp_keys[i].required)
      store_value(base, &sp_keys[i], sp_keys[i].fallback);
}

/**
 * @brief Convert one loaded slot (a string for numbers, an int for enum and
 *        bool keys), check it and store it.
 * @param where message prefix: the file, or "--set ..."
 * @param cell the cell index for cells keys, else -1
 */
static int store_slot(void *base, const sp_key *key, const void *slot,
                      const char *where, int cell) {
  char path[SP_TEXT], expected[SP_LIST_TEXT];
  double value;
  const char *text = NULL;
  if (key->type == SP_KEY_NAME) {
    text = slot;
    if (!name_valid(text))
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got '%s'", where,
                          key_path(key, cell, path, sizeof path),
                          expectation(key, expected, sizeof expected), text);
    strcpy((char *)base + key->offset, text);
    return SP_OK;
  }
  if (key->type == SP_KEY_PATH) {
    text = slot;
    if (strlen(text) >= SP_SCENE_PATH_MAX)
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got one of %zu", where,
                          key_path(key, cell, path, sizeof path),
                          expectation(key, expected, sizeof expected), strlen(text));
    strcpy((char *)base + key->offset, text);
    return SP_OK;
  }
  if (key->type == SP_KEY_BOOL || key->type == SP_KEY_ENUM) {
    value = *(const int *)slot;
  } else {
    text = slot;
    if (!parse_number(text, &value))
      return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got '%s'", where,
                          key_path(key, cell, path, sizeof path),
                          expectation(key, expected, sizeof expected), text);
  }
  if (!value_allowed(key, value))
    return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s, got %s", where,
                        key_path(key, cell, path, sizeof path),
                        expectation(key, expected, sizeof expected),
                        text ? text : word_of(key, value));
  store_value(base, key, value);
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* The libcyaml schema, built from the table                                */
/* ------------------------------------------------------------------------ */

/** What libcyaml loads: per mapping section an array of key slots (NULL =
 *  absent), and per sequence section (cells, lineage) its entries as
 *  consecutive arrays of key slots. */
typedef struct {
  void **section[SP_N_MAPPINGS];
  void **entries[SP_N_SEQUENCES];
  uint32_t n_entries[SP_N_SEQUENCES];
} sp_raw_scene;

/** The schema. It points into itself: build it in place, never copy it. */
typedef struct {
  /* every section's key fields, each list closed by an end entry */
  cyaml_schema_field_t key_fields[SP_N_KEYS + SP_N_SECTIONS];
  cyaml_schema_field_t section_fields[SP_N_SECTIONS + 1];
  cyaml_schema_value_t entry[SP_N_SEQUENCES]; /**< one entry of a sequence */
  cyaml_schema_value_t top;
} sp_schema;

/** The value schema of one key (a pointer: the slot receives it). */
static cyaml_schema_value_t key_value_schema(const sp_key *key) {
  cyaml_schema_value_t v;
  memset(&v, 0, sizeof v);
  v.flags = CYAML_FLAG_POINTER;
  switch (key->type) {
  case SP_KEY_BOOL:
    v.flags |= CYAML_FLAG_CASE_INSENSITIVE; /* True, YES as YAML allows */
    /* fall through */
  case SP_KEY_ENUM:
    v.type = CYAML_ENUM;
    v.flags |= CYAML_FLAG_STRICT; /* words only: no bare numbers */
    v.data_size = sizeof(int);
    v.enumeration.strings = key->words;
    v.enumeration.count = key->n_words;
    break;
  default: /* numbers: loaded as text, see the file comment */
    v.type = CYAML_STRING;
    v.data_size = sizeof(char *);
    v.string.min = 0;
    v.string.max = CYAML_UNLIMITED;
  }
  return v;
}

static void build_schema(sp_schema *schema) {
  memset(schema, 0, sizeof *schema);
  size_t n = 0;
  for (int s = 0; s < SP_N_SECTIONS; ++s) {
    cyaml_schema_field_t *first = &schema->key_fields[n];
    size_t slots = 0;
    for (size_t i = 0; i < SP_N_KEYS; ++i) {
      const sp_key *key = &sp_keys[i];
      if (key->section != (sp_section)s) continue;
      cyaml_schema_field_t *f = &schema->key_fields[n++];
      f->key = key->name;
      f->data_offset = (uint32_t)(slots++ * sizeof(void *));
      f->value = key_value_schema(key);
      if (!key->required) f->value.flags |= CYAML_FLAG_OPTIONAL;
    }
    ++n; /* the zeroed end entry */
    cyaml_schema_field_t *sf = &schema->section_fields[s];
    sf->key = sp_section_names[s];
    if (is_sequence((sp_section)s)) {
      const int q = s - SP_N_MAPPINGS;
      cyaml_schema_value_t *entry = &schema->entry[q];
      entry->type = CYAML_MAPPING;
      entry->flags = CYAML_FLAG_DEFAULT;
      entry->data_size = (uint32_t)(slots * sizeof(void *));
      entry->mapping.fields = first;
      sf->data_offset = (uint32_t)(offsetof(sp_raw_scene, entries) + (size_t)q * sizeof(void **));
      sf->count_offset =
          (uint32_t)(offsetof(sp_raw_scene, n_entries) + (size_t)q * sizeof(uint32_t));
      sf->count_size = sizeof(uint32_t);
      sf->value.type = CYAML_SEQUENCE;
      /* cells: absent or empty is reported by sp_scene_load itself */
      sf->value.flags = CYAML_FLAG_POINTER_NULL | CYAML_FLAG_OPTIONAL;
      sf->value.data_size = entry->data_size;
      sf->value.sequence.entry = entry;
      sf->value.sequence.min = 0;
      sf->value.sequence.max = CYAML_UNLIMITED;
    } else {
      sf->data_offset = (uint32_t)(offsetof(sp_raw_scene, section) +
                                   (size_t)s * sizeof(void **));
      sf->value.type = CYAML_MAPPING;
      /* a section left empty ("model:") just keeps the defaults */
      sf->value.flags = CYAML_FLAG_POINTER_NULL | CYAML_FLAG_OPTIONAL;
      sf->value.data_size = (uint32_t)(slots * sizeof(void *));
      sf->value.mapping.fields = first;
    }
  }
  schema->top.type = CYAML_MAPPING;
  schema->top.flags = CYAML_FLAG_POINTER;
  schema->top.data_size = sizeof(sp_raw_scene);
  schema->top.mapping.fields = schema->section_fields;
}

/* ------------------------------------------------------------------------ */
/* libcyaml errors -> one message naming the key                            */
/* ------------------------------------------------------------------------ */

/** The log lines libcyaml wrote during one load. */
typedef struct {
  char line[SP_LOG_LINES][SP_TEXT];
  int n;
} sp_cyaml_log;

static void capture_log(cyaml_log_t level, void *ctx, const char *fmt,
                        va_list args) {
  sp_cyaml_log *log = ctx;
  if (level < CYAML_LOG_ERROR || log->n >= SP_LOG_LINES) return;
  char *line = log->line[log->n++];
  vsnprintf(line, SP_TEXT, fmt, args);
  line[strcspn(line, "\n")] = '\0';
}

static cyaml_config_t cyaml_config(sp_cyaml_log *log) {
  cyaml_config_t config;
  memset(&config, 0, sizeof config);
  config.log_fn = capture_log;
  config.log_ctx = log;
  config.mem_fn = cyaml_mem;
  config.log_level = CYAML_LOG_ERROR;
  config.flags = CYAML_CFG_DEFAULT; /* unknown keys are errors */
  return config;
}

/** libcyaml's own message (its first log line without "Load: "). */
static const char *cyaml_message(const sp_cyaml_log *log, cyaml_err_t err) {
  static const char load_tag[] = "Load: ";
  const char *message = log->n ? log->line[0] : cyaml_strerror(err);
  if (strncmp(message, load_tag, sizeof load_tag - 1) == 0)
    message += sizeof load_tag - 1;
  return message;
}

/** Where libcyaml stopped: key path from the backtrace and its line. */
typedef struct {
  char path[SP_TEXT];
  unsigned line; /**< 0: unknown */
} sp_yaml_where;

/**
 * @brief Turn the captured backtrace into a key path ("solver.linear",
 *        "cells[1].x") and the line of its innermost entry.
 * @param drop_innermost_field for a missing field libcyaml's innermost entry
 *        is the last field it read in that mapping, not the missing one
 */
static void backtrace_where(const sp_cyaml_log *log, int drop_innermost_field,
                            sp_yaml_where *where) {
  static const char field_tag[] = "in mapping field '";
  static const char entry_tag[] = "in sequence entry '";
  static const char line_tag[] = "(line: ";
  int innermost = -1, first = log->n;
  where->path[0] = '\0';
  where->line = 0;
  for (int i = 0; i < log->n; ++i)
    if (strstr(log->line[i], "Backtrace:")) {
      first = i + 1;
      break;
    }
  if (drop_innermost_field && first < log->n &&
      strstr(log->line[first], field_tag))
    ++first;
  for (int i = log->n - 1; i >= first; --i) { /* outermost first */
    const char *l = log->line[i], *name;
    size_t used = strlen(where->path);
    if ((name = strstr(l, field_tag))) {
      name += sizeof field_tag - 1;
      snprintf(where->path + used, sizeof where->path - used, "%s%.*s",
               used ? "." : "", (int)strcspn(name, "'"), name);
    } else if ((name = strstr(l, entry_tag))) {
      /* libcyaml counts entries from 1, the messages from 0 */
      long entry = strtol(name + sizeof entry_tag - 1, NULL, 10);
      snprintf(where->path + used, sizeof where->path - used, "[%ld]",
               entry - 1);
    }
    innermost = i;
  }
  if (innermost >= 0) {
    const char *l = strstr(log->line[innermost], line_tag);
    if (l) where->line = (unsigned)strtoul(l + sizeof line_tag - 1, NULL, 10);
  }
}

/** "scene.yaml:12" or "scene.yaml" when the line is unknown. */
static const char *file_line(const char *file, unsigned line, char *buf,
                             size_t size) {
  if (line)
    snprintf(buf, size, "%s:%u", file, line);
  else
    snprintf(buf, size, "%s", file);
  return buf;
}

/** What belongs at @p path ("", "model", "cells", "cells[2]",
 *  "model.kappa", "cells[2].x"), for messages. */
static const char *path_expectation(const char *path, char *buf,
                                    size_t size) {
  char list[SP_LIST_TEXT];
  size_t head = strcspn(path, ".[");
  sp_section s = find_section(path, head);
  if (!*path) {
    snprintf(buf, size, "a mapping of sections (%s)",
             section_list(list, sizeof list));
  } else if (s == SP_N_SECTIONS) {
    snprintf(buf, size, "a known section");
  } else if (path[head] == '\0') {
    if (is_sequence(s))
      snprintf(buf, size, "a sequence of %s entries, each a mapping of %s", sp_section_names[s],
               section_key_list(s, 0, list, sizeof list));
    else
      snprintf(buf, size, "a mapping of %s keys (%s)", sp_section_names[s],
               section_key_list(s, 0, list, sizeof list));
  } else {
    const char *name = strrchr(path, '.');
    const sp_key *key = name ? find_key(s, name + 1, strlen(name + 1)) : NULL;
    if (key)
      expectation(key, buf, size);
    else /* a cells entry itself, "cells[2]" */
      snprintf(buf, size, "a mapping of %s",
               section_key_list(s, 0, list, sizeof list));
  }
  return buf;
}

/** The message for a failed cyaml_load_*; returns the error code. */
static int report_cyaml_error(const char *file, cyaml_err_t err,
                              const sp_cyaml_log *log) {
  static const char key_tag[] = "Unexpected key: ";
  static const char missing_tag[] = "Missing required mapping field: ";
  static const char seen_tag[] = "Mapping field already seen";
  char at[SP_TEXT + SP_TEXT], expected[SP_LIST_TEXT], list[SP_LIST_TEXT];
  sp_yaml_where where;
  const char *message = cyaml_message(log, err);

  if (err == CYAML_ERR_OOM)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory while loading",
                        file);
  if (err == CYAML_ERR_INVALID_KEY) {
    /* the innermost backtrace entry is the enclosing mapping; libcyaml's
     * line there is that of the previous value, so no line is given */
    backtrace_where(log, 0, &where);
    const char *name = strstr(message, key_tag);
    name = name ? name + sizeof key_tag - 1 : "?";
    if (!where.path[0])
      return sp_error_set(SP_ERR_INPUT,
                          "%s: %s: unknown section; the sections are %s "
                          "(libcyaml: %s)",
                          file, name, section_list(list, sizeof list),
                          message);
    sp_section s = find_section(where.path, strcspn(where.path, ".["));
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s.%s: unknown key; %s has %s (libcyaml: %s)",
                        file, where.path, name,
                        s < SP_N_SECTIONS && is_sequence(s) ? sequence_of(s)->entry
                                                            : where.path,
                        s < SP_N_SECTIONS
                            ? section_key_list(s, 0, list, sizeof list)
                            : "no such key",
                        message);
  }
  if (err == CYAML_ERR_MAPPING_FIELD_MISSING) {
    backtrace_where(log, 1, &where);
    const char *name = strstr(message, missing_tag);
    name = name ? name + sizeof missing_tag - 1 : "?";
    sp_section s = find_section(where.path, strcspn(where.path, ".["));
    if (s == SP_N_SECTIONS || !is_sequence(s)) s = SP_SEC_CELLS;
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s%s%s: missing; every %s needs %s "
                        "(libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at),
                        where.path, where.path[0] ? "." : "", name,
                        sequence_of(s)->entry + 2, /* "cell", "lineage entry" */
                        section_key_list(s, 1, list, sizeof list), message);
  }
  backtrace_where(log, 0, &where);
  if (err == CYAML_ERR_LIBYAML_PARSER) {
    /* libcyaml knows only where the last good event was, not the error */
    if (where.path[0])
      return sp_error_set(SP_ERR_INPUT,
                          "%s: malformed YAML in %s, after line %u: %s",
                          file, where.path, where.line, message);
    return sp_error_set(SP_ERR_INPUT, "%s: malformed YAML: %s", file,
                        message);
  }
  if (strncmp(message, seen_tag, sizeof seen_tag - 1) == 0)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: given twice (libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at),
                        where.path, message);
  const char *path = where.path[0] ? where.path : "top level";
  file_line(file, where.line, at, sizeof at);
  if (err == CYAML_ERR_INVALID_VALUE || err == CYAML_ERR_UNEXPECTED_EVENT)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: expected %s (libcyaml: %s)",
                        at, path,
                        path_expectation(where.path, expected,
                                         sizeof expected),
                        message);
  if (err == CYAML_ERR_INVALID_ALIAS || err == CYAML_ERR_ALIAS)
    return sp_error_set(SP_ERR_INPUT, "%s: %s: bad YAML alias (libcyaml: %s)",
                        at, path, message);
  if (err == CYAML_ERR_INTERNAL_ERROR) {
    /* libcyaml 1.3.1 says "internal error" for an event its state has no
     * handler for, which input can cause: a key that is itself a mapping
     * or a sequence, "{x: 1, y}: 2" (tests/scenes/fuzz/). The backtrace's
     * innermost field is the last one read, not the bad key. */
    backtrace_where(log, 1, &where);
    path = where.path[0] ? where.path : "top level";
    return sp_error_set(SP_ERR_INPUT,
                        "%s: %s: expected %s; libcyaml cannot read what follows "
                        "there (a key that is a mapping or a sequence?) (libcyaml: %s)",
                        file_line(file, where.line, at, sizeof at), path,
                        path_expectation(where.path, expected, sizeof expected),
                        cyaml_strerror(err));
  }
  /* anything else is a schema or library problem, not the user's */
  return sp_error_set(SP_ERR_INTERNAL, "%s: libcyaml failed (%s): %s", file,
                      cyaml_strerror(err), message);
}

/* ------------------------------------------------------------------------ */
/* Loading                                                                  */
/* ------------------------------------------------------------------------ */

/** Read the whole file (libcyaml's own open gives no reason on failure). */
static int read_file(const char *path, char **text, size_t *len) {
  FILE *f = fopen(path, "rb");
  SP_CHECK(f, SP_ERR_INPUT, "%s: cannot open the scene file: %s", path,
           strerror(errno));
  size_t size = 0, capacity = BUFSIZ;
  char *buf = malloc(capacity);
  while (buf) {
    size += fread(buf + size, 1, capacity - size, f);
    if (size < capacity) break;
    char *bigger = realloc(buf, 2 * capacity);
    if (!bigger) {
      free(buf);
      buf = NULL;
    } else {
      buf = bigger;
      capacity *= 2;
    }
  }
  int failed = !buf || ferror(f);
  int err = errno;
  fclose(f);
  if (!buf)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory reading the file",
                        path);
  if (failed) {
    free(buf);
    return sp_error_set(SP_ERR_INPUT, "%s: cannot read the scene file: %s",
                        path, strerror(err));
  }
  *text = buf;
  *len = size;
  return SP_OK;
}

/** Defaults, then the values of the loaded file. */
static int apply_raw(sp_scene *scene, const sp_raw_scene *raw,
                     const char *file) {
  for (size_t i = 0; i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    void **slots = is_sequence(key->section) ? NULL : raw->section[key->section];
    if (slots && slots[key_slot(key)])
      SP_CALL(store_slot(scene, key, slots[key_slot(key)], file, -1));
  }
  /* file names in the scene are relative to the scene file's directory */
  const char *slash = strrchr(file, '/');
  for (size_t i = 0; slash && i < SP_N_KEYS; ++i) {
    const sp_key *key = &sp_keys[i];
    char *value = (char *)scene + key->offset;
    if (key->type != SP_KEY_PATH || !value[0] || value[0] == '/') continue;
    char joined[SP_SCENE_PATH_MAX + 1];
    const int n = snprintf(joined, sizeof joined, "%.*s/%s", (int)(slash - file), file, value);
    char path[SP_TEXT];
    SP_CHECK(n > 0 && n < SP_SCENE_PATH_MAX, SP_ERR_INPUT,
             "%s: %s: the file name with the scene's directory is longer than %d characters",
             file, key_path(key, -1, path, sizeof path), SP_SCENE_PATH_MAX - 1);
    memcpy(value, joined, (size_t)n + 1);
  }
  /* libcyaml loads "cells: []", "cells:" and no cells key alike; none is
   * right only with initial.from or initial.label_image (check_initial) */
  for (int s = SP_N_MAPPINGS; s < SP_N_SECTIONS; ++s) {
    const sp_sequence *q = sequence_of((sp_section)s);
    const uint32_t n = raw->n_entries[s - SP_N_MAPPINGS];
    char *records = calloc(n ? n : 1, q->size);
    SP_CHECK(records, SP_ERR_MEMORY, "%s: out of memory for %u %s entries", file, n,
             sp_section_names[s]);
    *(char **)((char *)scene + q->records) = records;
    *(int *)((char *)scene + q->count) = (int)n;
    const size_t n_keys = section_key_count((sp_section)s);
    for (uint32_t c = 0; c < n; ++c) {
      void **slots = raw->entries[s - SP_N_MAPPINGS] + (size_t)c * n_keys;
      void *record = records + (size_t)c * q->size;
      store_defaults(record, (sp_section)s);
      for (size_t i = 0; i < SP_N_KEYS; ++i) {
        const sp_key *key = &sp_keys[i];
        if (key->section == (sp_section)s && slots[key_slot(key)])
          SP_CALL(store_slot(record, key, slots[key_slot(key)], file, (int)c));
      }
    }
  }
  return SP_OK;
}

/** The values of a scene file's text; @p name is the file in messages. */
static int load_text(sp_scene *scene, const char *name, const char *text,
                     size_t len) {
  sp_schema schema;
  build_schema(&schema);
  sp_cyaml_log log = {.n = 0};
  cyaml_config_t config = cyaml_config(&log);
  sp_raw_scene *raw = NULL;
  cyaml_err_t err = CYAML_OK;
  if (len > 0)
    err = cyaml_load_data((const uint8_t *)text, len, &config, &schema.top,
                          (cyaml_data_t **)&raw, NULL);
  if (err != CYAML_OK) return report_cyaml_error(name, err, &log);
  /* an empty file, or only comments: libcyaml succeeds with no data */
  SP_CHECK(raw, SP_ERR_INPUT,
           "%s: cells: missing; the file holds no YAML document (empty or "
           "only comments) and a scene needs at least one cell",
           name);
  int rc = apply_raw(scene, raw, name);
  cyaml_free(&config, &schema.top, raw, 0);
  return rc;
}

static int load_file(sp_scene *scene, const char *path) {
  char *text = NULL;
  size_t len = 0;
  SP_CALL(read_file(path, &text, &len));
  int rc = load_text(scene, path, text, len);
  free(text);
  return rc;
}

/** Apply one "section.key=value" override. */
static int apply_override(sp_scene *scene, const char *arg) {
  char where[SP_TEXT + SP_TEXT], list[SP_LIST_TEXT], expected[SP_LIST_TEXT];
  snprintf(where, sizeof where, "--set %s", arg);
  const char *eq = strchr(arg, '=');
  SP_CHECK(eq, SP_ERR_INPUT,
           "%s: expected section.key=value, but '%s' has no '='", where, arg);
  size_t name_len = (size_t)(eq - arg);
  const char *dot = memchr(arg, '.', name_len);
  SP_CHECK(dot, SP_ERR_INPUT,
           "%s: %.*s: expected section.key=value (no section given); the "
           "sections are %s",
           where, (int)name_len, arg, section_list(list, sizeof list));
  sp_section s = find_section(arg, (size_t)(dot - arg));
  SP_CHECK(s != SP_N_SECTIONS, SP_ERR_INPUT,
           "%s: %.*s: unknown section; the sections are %s", where,
           (int)name_len, arg, section_list(list, sizeof list));
  SP_CHECK(!is_sequence(s), SP_ERR_INPUT,
           "%s: %.*s: %s cannot be set from the command line; edit the "
           "%s list of the scene file",
           where, (int)name_len, arg, sp_section_names[s], sp_section_names[s]);
  const sp_key *key = find_key(s, dot + 1, (size_t)(eq - dot - 1));
  SP_CHECK(key, SP_ERR_INPUT, "%s: %.*s: unknown key; %s has %s", where,
           (int)name_len, arg, sp_section_names[s],
           section_key_list(s, 0, list, sizeof list));

  /* the value is read by libcyaml as a one-scalar YAML document with the
   * key's own value schema: the same words and text as in a file */
  char path[SP_TEXT];
  key_path(key, -1, path, sizeof path);
  cyaml_schema_value_t schema = key_value_schema(key);
  sp_cyaml_log log = {.n = 0};
  cyaml_config_t config = cyaml_config(&log);
  void *value = NULL;
  const char *text = eq + 1;
  cyaml_err_t err = cyaml_load_data((const uint8_t *)text, strlen(text),
                                    &config, &schema, &value, NULL);
  if (err == CYAML_ERR_OOM)
    return sp_error_set(SP_ERR_MEMORY, "%s: out of memory", where);
  SP_CHECK(err == CYAML_OK, SP_ERR_INPUT,
           "%s: %s: expected %s, got '%s' (libcyaml: %s)", where, path,
           expectation(key, expected, sizeof expected), text,
           cyaml_message(&log, err));
  SP_CHECK(value, SP_ERR_INPUT, "%s: %s: expected %s, got nothing", where,
           path, expectation(key, expected, sizeof expected));
  int rc = store_slot(scene, key, value, where, -1);
  cyaml_free(&config, &schema, value, 0);
  return rc;
}

/* ------------------------------------------------------------------------ */
/* Checks across keys                                                       */
/* ------------------------------------------------------------------------ */

static int ends_with(const char *s, const char *tail) {
  const size_t n = strlen(s), m = strlen(tail);
  return n >= m && strcmp(s + n - m, tail) == 0;
}

/** A label volume: a NIfTI file (one file, maybe gzipped), on a 3D mesh. */
static int check_label_volume(const sp_scene *scene, const char *file) {
  const char *volume = scene->initial.label_volume;
  SP_CHECK(ends_with(volume, ".nii") || ends_with(volume, ".nii.gz"), SP_ERR_INPUT,
           "%s: initial.label_volume: expected a NIfTI file (.nii or .nii.gz), got '%s'",
           file, volume);
  SP_CHECK(sp_scene_dim(scene) == 3, SP_ERR_INPUT,
           "%s: initial.label_volume: a label volume is 3D: expected a 3D mesh (mesh.type box "
           "or ellipsoid), got mesh.type %s (a 2D scene takes a PNG, initial.label_image)",
           file, sp_mesh_words[scene->mesh.type].str);
  return SP_OK;
}

/** initial.from names a checkpoint or a .vtu. */
static int check_from(const sp_scene_initial *in, const char *file) {
  const size_t n = strlen(in->from);
  SP_CHECK((n > 3 && strcmp(in->from + n - 3, ".h5") == 0) ||
               (n > 4 && strcmp(in->from + n - 4, ".vtu") == 0),
           SP_ERR_INPUT, "%s: initial.from: expected a softpack checkpoint (.h5) or .vtu, got '%s'",
           file, in->from);
  return SP_OK;
}

/** initial.label_image's box is not empty. */
static int check_image_box(const sp_scene_initial *in, const char *file) {
  SP_CHECK(in->x1 > in->x0, SP_ERR_INPUT,
           "%s: initial.x1: expected a number > initial.x0 = %.15g, got %.15g", file,
           in->x0, in->x1);
  SP_CHECK(in->y1 > in->y0, SP_ERR_INPUT,
           "%s: initial.y1: expected a number > initial.y0 = %.15g, got %.15g", file,
           in->y0, in->y1);
  return SP_OK;
}

/** Cells, or initial fields from a file: one of them. */
static int check_initial(const sp_scene *scene, const char *file) {
  const sp_scene_initial *in = &scene->initial;
  const int from = in->from[0] != '\0', image = in->label_image[0] != '\0';
  const int volume = in->label_volume[0] != '\0';
  /* the file that gives the cells, and its key */
  const char *source = from ? in->from : image ? in->label_image : volume ? in->label_volume
                                                                          : NULL;
  const char *key = from ? "from" : image ? "label_image" : "label_volume";
  SP_CHECK(scene->n_cells > 0 || source, SP_ERR_INPUT,
           "%s: cells: no cells given (the key is missing or its list is "
           "empty); a scene needs at least one cell, or initial.from, "
           "initial.label_image or initial.label_volume",
           file);
  SP_CHECK(!(from && image), SP_ERR_INPUT,
           "%s: initial.label_image: expected none with initial.from (give one "
           "source of initial fields), got '%s'", file, in->label_image);
  SP_CHECK(!(volume && (from || image)), SP_ERR_INPUT,
           "%s: initial.label_volume: expected none with initial.%s (give one source of "
           "initial fields), got '%s'", file, key, in->label_volume);
  SP_CHECK(scene->n_cells == 0 || !source, SP_ERR_INPUT,
           "%s: cells: expected none with initial.%s (the file gives the cells), got %d",
           file, key, scene->n_cells);
  if (volume) SP_CALL(check_label_volume(scene, file));
  if (from) SP_CALL(check_from(in, file));
  SP_CHECK(!source || access(source, R_OK) == 0, SP_ERR_INPUT,
           "%s: initial.%s: cannot read '%s': %s", file, key, source, strerror(errno));
  return image ? check_image_box(in, file) : SP_OK;
}

/** mesh.semi_z given on an ellipsoid (and only there), its refinements at
 *  most SP_MESH_ELLIPSOID_MAX_REFINEMENTS. */
static int check_ellipsoid_keys(const sp_scene_mesh *m, const char *file) {
  if (m->type == SP_MESH_ELLIPSOID) {
    SP_CHECK(!isnan(m->semi_z), SP_ERR_INPUT,
             "%s: mesh.semi_z: required with mesh.type ellipsoid: expected the semi-axis "
             "along z, a number > 0", file);
    SP_CHECK(m->refinements <= SP_MESH_ELLIPSOID_MAX_REFINEMENTS, SP_ERR_INPUT,
             "%s: mesh.refinements: expected at most %d with mesh.type ellipsoid (%d gives "
             "%lld hexahedra), got %d", file, SP_MESH_ELLIPSOID_MAX_REFINEMENTS,
             m->refinements, sp_mesh_ellipsoid_elements(m->refinements, m->buffer_layers),
             m->refinements);
  } else {
    SP_CHECK(isnan(m->semi_z), SP_ERR_INPUT,
             "%s: mesh.semi_z: only with mesh.type ellipsoid, got %.15g with mesh.type %s",
             file, m->semi_z, sp_mesh_words[m->type].str);
  }
  return SP_OK;
}

/** output.length_scale (time_scale) only with its unit. */
static int check_unit_keys(const sp_scene *scene, const char *file) {
  const sp_scene_output *o = &scene->output;
  SP_CHECK(o->length_unit[0] || o->length_scale == 1.0, SP_ERR_INPUT,
           "%s: output.length_scale: only with output.length_unit (the unit it counts), got "
           "%.15g without one", file, o->length_scale);
  SP_CHECK(o->time_unit[0] || o->time_scale == 1.0, SP_ERR_INPUT,
           "%s: output.time_scale: only with output.time_unit (the unit it counts), got %.15g "
           "without one", file, o->time_scale);
  return SP_OK;
}

/** mesh.flatten: 0, or on an ellipse (ellipsoid) below its last semi-axis. */
static int check_flatten_key(const sp_scene *scene, const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  if (m->flatten == 0) return SP_OK;
  SP_CHECK(m->type == SP_MESH_ELLIPSE || m->type == SP_MESH_ELLIPSOID, SP_ERR_INPUT,
           "%s: mesh.flatten: only with mesh.type ellipse or ellipsoid, got %.15g with "
           "mesh.type %s", file, m->flatten, sp_mesh_words[m->type].str);
  const int dim = sp_scene_dim(scene);
  const double semi = dim == 3 ? m->semi_z : m->semi_y;
  SP_CHECK(m->flatten < semi, SP_ERR_INPUT,
           "%s: mesh.flatten: expected a number < mesh.%s = %.15g (the planes must cut the "
           "%s; 0: no cut), got %.15g", file, dim == 3 ? "semi_z" : "semi_y", semi,
           dim == 3 ? "ellipsoid" : "ellipse", m->flatten);
  return SP_OK;
}

static int check_time_and_mesh(const sp_scene *scene, const char *file) {
  const sp_scene_time *t = &scene->time;
  SP_CHECK(t->dt_min <= t->dt, SP_ERR_INPUT,
           "%s: time.dt_min: expected a number <= time.dt = %.15g, got "
           "%.15g",
           file, t->dt, t->dt_min);
  SP_CHECK(!(t->scheme == SP_TIME_BDF2 && scene->shape.scheme == SP_SHAPE_IMPLICIT &&
             (scene->shape.delta1 > 0 || scene->shape.delta2 > 0 || scene->shape.delta3 > 0)),
           SP_ERR_INPUT,
           "%s: time.scheme: expected be with shape.scheme implicit (its linearised moments "
           "need c^n, which a BDF2 step does not solve from), got bdf2",
           file);
  SP_CHECK(t->dt_max >= t->dt_min, SP_ERR_INPUT,
           "%s: time.dt_max: expected a number >= time.dt_min = %.15g, got %.15g", file,
           t->dt_min, t->dt_max);
  SP_CHECK(scene->solver.newton_divergence == 0 || scene->solver.newton_divergence > 1,
           SP_ERR_INPUT,
           "%s: solver.newton_divergence: expected 0 (off) or a number > 1, got %.15g",
           file, scene->solver.newton_divergence);
  SP_CHECK(scene->layout.band < scene->layout.margin, SP_ERR_INPUT,
           "%s: layout.band: expected a number < layout.margin = %.15g, got "
           "%.15g",
           file, scene->layout.margin, scene->layout.band);
  if (scene->mesh.type == SP_MESH_RECTANGLE || scene->mesh.type == SP_MESH_BOX) {
    const sp_scene_mesh *m = &scene->mesh;
    SP_CHECK(m->x1 > m->x0, SP_ERR_INPUT,
             "%s: mesh.x1: expected a number > mesh.x0 = %.15g, got %.15g",
             file, m->x0, m->x1);
    SP_CHECK(m->y1 > m->y0, SP_ERR_INPUT,
             "%s: mesh.y1: expected a number > mesh.y0 = %.15g, got %.15g",
             file, m->y0, m->y1);
  }
  if (scene->mesh.type == SP_MESH_BOX) {
    const sp_scene_mesh *m = &scene->mesh;
    SP_CHECK(m->z1 > m->z0, SP_ERR_INPUT,
             "%s: mesh.z1: expected a number > mesh.z0 = %.15g, got %.15g",
             file, m->z0, m->z1);
  }
  SP_CALL(check_ellipsoid_keys(&scene->mesh, file));
  SP_CALL(check_unit_keys(scene, file));
  return check_flatten_key(scene, file);
}

/** What a scene of one dimension cannot ask for, each refused naming its
 *  key: on a 3D mesh a PNG label image, on a 2D mesh the third moment's
 *  shape.delta3. */
static int check_3d(const sp_scene *scene, const char *file) {
  if (sp_scene_dim(scene) != 3) {
    SP_CHECK(scene->shape.delta3 == 0, SP_ERR_INPUT,
             "%s: shape.delta3: the third principal moment is a 3D cell's (mesh.type box or "
             "ellipsoid): expected 0 on a 2D mesh, got %.15g",
             file, scene->shape.delta3);
    return SP_OK;
  }
  SP_CHECK(scene->initial.label_image[0] == '\0', SP_ERR_INPUT,
           "%s: initial.label_image: a PNG label image is 2D: expected none on a 3D mesh "
           "(a 3D scene takes a NIfTI label volume, initial.label_volume), got '%s'", file,
           scene->initial.label_image);
  return SP_OK;
}

/** The key that sets cell @p c's extent along @p d: its semi-axis if
 *  given, else its radius. */
static const char *extent_key(const sp_scene_cell *c, int d) {
  static const char *const semi[3] = {"semi_x", "semi_y", "semi_z"};
  if (sp_scene_cell_is_turned(c)) return "axis_x"; /* (its extents come from the turn) */
  const double given[3] = {c->semi_x, c->semi_y, c->semi_z};
  return isnan(given[d]) ? "radius" : semi[d];
}

/** Points on a cell's sphere tested against the ellipsoid: latitude
 *  circles of SP_DISK_CHECK_ANGLES points, half as many latitudes. */
enum { SP_SPHERE_CHECK_LATITUDES = SP_DISK_CHECK_ANGLES / 2 };

/** (x/a)^2 + (y/b)^2 + (z/c)^2: <= 1 inside the ellipsoid of the mesh. */
static double ellipsoid_level(const sp_scene_mesh *m, const double x[3]) {
  const double semi[3] = {m->semi_x, m->semi_y, m->semi_z};
  double level = 0;
  for (int d = 0; d < 3; ++d) level += (x[d] / semi[d]) * (x[d] / semi[d]);
  return level;
}

/** Cell @p i's centre, and its whole sphere (or ellipsoid: its semi-axes),
 *  inside the ellipsoid. */
static int check_sphere_in_ellipsoid(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                     const char *file) {
  const double centre[3] = {c->x, c->y, c->z}, r = c->radius;
  const double level = ellipsoid_level(m, centre);
  SP_CHECK(level <= 1.0, SP_ERR_INPUT,
           "%s: cells[%d].x, cells[%d].y, cells[%d].z: the centre (%.15g, %.15g, %.15g) is "
           "outside the ellipsoid (x/%.15g)^2 + (y/%.15g)^2 + (z/%.15g)^2 <= 1 (it gives %.6g)",
           file, i, i, i, c->x, c->y, c->z, m->semi_x, m->semi_y, m->semi_z, level);
  const double half_turn = acos(-1.0);
  for (int la = 0; la <= SP_SPHERE_CHECK_LATITUDES; ++la)
    for (int j = 0; j < SP_DISK_CHECK_ANGLES; ++j) {
      const double polar = half_turn * la / SP_SPHERE_CHECK_LATITUDES;
      const double azimuth = 2 * half_turn * j / SP_DISK_CHECK_ANGLES;
      const double local[3] = {sp_scene_cell_semi_axis(c, 0) * sin(polar) * cos(azimuth),
                               sp_scene_cell_semi_axis(c, 1) * sin(polar) * sin(azimuth),
                               sp_scene_cell_semi_axis(c, 2) * cos(polar)};
      double p[3];
      sp_scene_cell_point(c, 3, centre, local, p);
      SP_CHECK(ellipsoid_level(m, p) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].radius: the sphere (or semi-axes) of radius %.15g around (%.15g, "
               "%.15g, %.15g) is not inside the ellipsoid with semi-axes (%.15g, %.15g, %.15g): its point "
               "(%.6g, %.6g, %.6g) is outside",
               file, i, r, c->x, c->y, c->z, m->semi_x, m->semi_y, m->semi_z, p[0], p[1], p[2]);
    }
  return SP_OK;
}

/** Every cell's centre, and its whole sphere (ellipsoid), inside the box
 *  or the ellipsoid; its z given. */
static int check_sphere(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                        const char *file) {
  SP_CHECK(!isnan(c->z), SP_ERR_INPUT,
           "%s: cells[%d].z: required on a 3D mesh (mesh.type %s): the cell is a sphere", file,
           i, sp_mesh_words[m->type].str);
  if (m->type == SP_MESH_ELLIPSOID) return check_sphere_in_ellipsoid(m, c, i, file);
  const double lo[3] = {m->x0, m->y0, m->z0}, hi[3] = {m->x1, m->y1, m->z1};
  const double x[3] = {c->x, c->y, c->z}, r = c->radius;
  static const char *const name[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d)
    SP_CHECK(x[d] >= lo[d] && x[d] <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].%s: the centre %s = %.15g is outside the box's [mesh.%s0, "
             "mesh.%s1] = [%.15g, %.15g]",
             file, i, name[d], name[d], x[d], name[d], name[d], lo[d], hi[d]);
  for (int d = 0; d < 3 && sp_scene_cell_is_ellipsoid(c); ++d) {
    const double s = sp_scene_cell_extent(c, 3, d);
    SP_CHECK(x[d] - s >= lo[d] && x[d] + s <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].%s: the ellipsoid's extent %.15g along %s around (%.15g, "
             "%.15g, %.15g) is not inside the box [%.15g, %.15g] x [%.15g, %.15g] x [%.15g, "
             "%.15g]",
             file, i, extent_key(c, d), s, name[d], x[0], x[1], x[2], lo[0], hi[0], lo[1],
             hi[1], lo[2], hi[2]);
  }
  for (int d = 0; d < 3 && !sp_scene_cell_is_ellipsoid(c); ++d)
    SP_CHECK(x[d] - r >= lo[d] && x[d] + r <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].radius: the sphere of radius %.15g around (%.15g, %.15g, %.15g) "
             "is not inside the box [%.15g, %.15g] x [%.15g, %.15g] x [%.15g, %.15g]",
             file, i, r, x[0], x[1], x[2], lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
  return SP_OK;
}

/** (x/a)^2 + (y/b)^2: <= 1 inside the ellipse of the mesh. */
static double ellipse_level(const sp_scene_mesh *m, double x, double y) {
  return (x / m->semi_x) * (x / m->semi_x) + (y / m->semi_y) * (y / m->semi_y);
}

/** Cell @p i's centre, and its whole disk (ellipse), inside the rectangle. */
static int check_disk_in_rectangle(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                   const char *file) {
  const double r = c->radius;
  SP_CHECK(c->x >= m->x0 && c->x <= m->x1, SP_ERR_INPUT,
           "%s: cells[%d].x: the centre x = %.15g is outside the "
           "rectangle's [mesh.x0, mesh.x1] = [%.15g, %.15g]",
           file, i, c->x, m->x0, m->x1);
  SP_CHECK(c->y >= m->y0 && c->y <= m->y1, SP_ERR_INPUT,
           "%s: cells[%d].y: the centre y = %.15g is outside the "
           "rectangle's [mesh.y0, mesh.y1] = [%.15g, %.15g]",
           file, i, c->y, m->y0, m->y1);
  if (sp_scene_cell_is_ellipsoid(c)) {
    for (int d = 0; d < 2; ++d) {
      const double x = d == 0 ? c->x : c->y, s = sp_scene_cell_extent(c, 2, d);
      const double lo = d == 0 ? m->x0 : m->y0, hi = d == 0 ? m->x1 : m->y1;
      SP_CHECK(x - s >= lo && x + s <= hi, SP_ERR_INPUT,
               "%s: cells[%d].%s: the ellipse's extent %.15g along %s around (%.15g, "
               "%.15g) is not inside the rectangle [%.15g, %.15g] x [%.15g, %.15g]",
               file, i, extent_key(c, d), s, d == 0 ? "x" : "y", c->x, c->y, m->x0, m->x1,
               m->y0, m->y1);
    }
    return SP_OK;
  }
  SP_CHECK(c->x - r >= m->x0 && c->x + r <= m->x1 && c->y - r >= m->y0 &&
               c->y + r <= m->y1,
           SP_ERR_INPUT,
           "%s: cells[%d].radius: the disk of radius %.15g around "
           "(%.15g, %.15g) is not inside the rectangle [%.15g, %.15g] x "
           "[%.15g, %.15g]",
           file, i, r, c->x, c->y, m->x0, m->x1, m->y0, m->y1);
  return SP_OK;
}

/** Cell @p i's centre, and its whole disk, inside the ellipse. */
static int check_disk_in_ellipse(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                 const char *file) {
  const double r = c->radius;
  double level = ellipse_level(m, c->x, c->y);
  SP_CHECK(level <= 1.0, SP_ERR_INPUT,
           "%s: cells[%d].x, cells[%d].y: the centre (%.15g, %.15g) is "
           "outside the ellipse (x/%.15g)^2 + (y/%.15g)^2 <= 1 (it gives "
           "%.6g)",
           file, i, i, c->x, c->y, m->semi_x, m->semi_y, level);
  const double full_turn = 2.0 * acos(-1.0);
  const double rx = sp_scene_cell_semi_axis(c, 0), ry = sp_scene_cell_semi_axis(c, 1);
  for (int j = 0; j < SP_DISK_CHECK_ANGLES; ++j) {
    double angle = full_turn * j / SP_DISK_CHECK_ANGLES;
    const double centre[2] = {c->x, c->y}, local[2] = {rx * cos(angle), ry * sin(angle)};
    double p[2];
    sp_scene_cell_point(c, 2, centre, local, p);
    const double px = p[0], py = p[1];
    if (!sp_scene_cell_is_ellipsoid(c))
      SP_CHECK(ellipse_level(m, px, py) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].radius: the disk of radius %.15g around "
               "(%.15g, %.15g) is not inside the ellipse with semi-axes "
               "(%.15g, %.15g): its point (%.6g, %.6g) is outside",
               file, i, r, c->x, c->y, m->semi_x, m->semi_y, px, py);
    else
      SP_CHECK(ellipse_level(m, px, py) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].semi_x, cells[%d].semi_y: the cell's ellipse with semi-axes "
               "(%.15g, %.15g) around (%.15g, %.15g) is not inside the ellipse with "
               "semi-axes (%.15g, %.15g): its point (%.6g, %.6g) is outside",
               file, i, i, rx, ry, c->x, c->y, m->semi_x, m->semi_y, px, py);
  }
  return SP_OK;
}

/** On a flattened mesh (mesh.flatten), cell @p i's extent along the last
 *  axis (y in 2D, z in 3D) between the planes. */
static int check_cell_under_coverslip(const sp_scene_mesh *m, int dim, const sp_scene_cell *c,
                                      int i, const char *file) {
  if (!(m->flatten > 0)) return SP_OK;
  const double centre = dim == 3 ? c->z : c->y, semi = sp_scene_cell_extent(c, dim, dim - 1);
  const char *axis = dim == 3 ? "z" : "y";
  SP_CHECK(fabs(centre) + semi <= m->flatten, SP_ERR_INPUT,
           "%s: cells[%d].%s: the cell reaches %s = %.15g, beyond the plane |%s| = "
           "mesh.flatten = %.15g (its centre %.15g, its extent %.15g along %s)",
           file, i, extent_key(c, dim - 1), axis, fabs(centre) + semi, axis, m->flatten,
           centre, semi, axis);
  return SP_OK;
}

/** Cell @p i's axis_x, _y, _z: on an ellipse (ellipsoid) only, axis_z on
 *  a 3D mesh only, not the zero vector. */
static int check_cell_axis(const sp_scene_cell *c, int i, int dim, const char *file) {
  if (!sp_scene_cell_is_turned(c)) return SP_OK;
  SP_CHECK(dim == 3 || isnan(c->axis[2]), SP_ERR_INPUT,
           "%s: cells[%d].axis_z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g", file,
           i, c->axis[2]);
  SP_CHECK(sp_scene_cell_is_ellipsoid(c), SP_ERR_INPUT,
           "%s: cells[%d].axis_x: turns an ellipse (ellipsoid): expected semi_x, semi_y or "
           "semi_z with it, got a %s of radius %.15g", file, i, dim == 3 ? "sphere" : "disk",
           c->radius);
  double norm = 0;
  for (int d = 0; d < 3; ++d) norm = hypot(norm, isnan(c->axis[d]) ? 0.0 : c->axis[d]);
  SP_CHECK(norm > 0 && isfinite(norm), SP_ERR_INPUT,
           "%s: cells[%d].axis_x, axis_y%s: expected a direction (a vector of finite "
           "length > 0), got one of length %g", file, i, dim == 3 ? ", axis_z" : "", norm);
  return SP_OK;
}

/** Every cell's centre, and its whole disk (sphere), inside Omega; z
 *  given exactly on a 3D mesh. */
static int check_cells(const sp_scene *scene, const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  for (int i = 0; i < scene->n_cells; ++i) {
    const sp_scene_cell *c = &scene->cells[i];
    SP_CALL(check_cell_axis(c, i, sp_scene_dim(scene), file));
    if (sp_scene_dim(scene) == 3) {
      SP_CALL(check_sphere(m, c, i, file));
      SP_CALL(check_cell_under_coverslip(m, 3, c, i, file));
      continue;
    }
    SP_CHECK(isnan(c->z), SP_ERR_INPUT,
             "%s: cells[%d].z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g with "
             "mesh.type %s",
             file, i, c->z, sp_mesh_words[m->type].str);
    SP_CHECK(isnan(c->semi_z), SP_ERR_INPUT,
             "%s: cells[%d].semi_z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g "
             "with mesh.type %s",
             file, i, c->semi_z, sp_mesh_words[m->type].str);
    if (m->type == SP_MESH_RECTANGLE) SP_CALL(check_disk_in_rectangle(m, c, i, file));
    else SP_CALL(check_disk_in_ellipse(m, c, i, file));
    SP_CALL(check_cell_under_coverslip(m, 2, c, i, file));
  }
  return SP_OK;
}

/** The initial cell named @p name, or -1. */
static int initial_named(const sp_scene *scene, const char *name) {
  for (int i = 0; i < scene->n_cells; ++i)
    if (strcmp(scene->cells[i].name, name) == 0) return i;
  return -1;
}

/** The lineage entry with @p name as a daughter (*which: "first" or
 *  "second"), from entry @p from on, or -1. */
static int daughter_entry(const sp_scene *scene, const char *name, int from, const char **which) {
  for (int j = from; j < scene->n_lineage; ++j) {
    const sp_scene_lineage *e = &scene->lineage[j];
    if (strcmp(e->first, name) == 0 || strcmp(e->second, name) == 0) {
      *which = strcmp(e->first, name) == 0 ? "first" : "second";
      return j;
    }
  }
  return -1;
}

/** One lineage entry's own keys: one criterion, a fixed axis's direction. */
static int check_lineage_entry(const sp_scene *scene, int i, const char *file) {
  const sp_scene_lineage *e = &scene->lineage[i];
  const int dim = sp_scene_dim(scene);
  const double when[3] = {e->age, e->time, e->mass_ratio};
  static const char *const when_key[3] = {"age", "time", "mass_ratio"};
  int given = 0;
  char list[SP_TEXT] = "";
  for (int k = 0; k < 3; ++k)
    if (!isnan(when[k])) {
      ++given;
      snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", given > 1 ? ", " : "",
               when_key[k]);
    }
  SP_CHECK(given == 1, SP_ERR_INPUT,
           "%s: lineage[%d].age, lineage[%d].time, lineage[%d].mass_ratio: expected exactly "
           "one (when '%s' divides), got %s%s",
           file, i, i, i, e->cell, given ? list : "none", given ? "" : " of them");
  static const char *const axis_key[3] = {"direction_x", "direction_y", "direction_z"};
  double norm2 = 0;
  for (int d = 0; d < 3; ++d) {
    const int wanted = e->axis == SP_AXIS_FIXED && d < dim;
    SP_CHECK(wanted || isnan(e->direction[d]), SP_ERR_INPUT,
             "%s: lineage[%d].%s: expected none %s, got %.15g", file, i, axis_key[d],
             d >= dim ? "on a 2D mesh (no z)" : "unless axis is fixed", e->direction[d]);
    SP_CHECK(!wanted || !isnan(e->direction[d]), SP_ERR_INPUT,
             "%s: lineage[%d].%s: missing; axis fixed needs the cut's normal direction_x, "
             "direction_y%s",
             file, i, axis_key[d], dim == 3 ? ", direction_z" : "");
    if (wanted) norm2 += e->direction[d] * e->direction[d];
  }
  SP_CHECK(e->axis != SP_AXIS_FIXED || norm2 > 0, SP_ERR_INPUT,
           "%s: lineage[%d].direction_x: expected a nonzero direction (the cut's normal), "
           "got the zero vector", file, i);
  SP_CHECK(strcmp(e->first, e->second) != 0, SP_ERR_INPUT,
           "%s: lineage[%d].second: expected a name other than first's, got '%s' twice", file,
           i, e->second);
  return SP_OK;
}

/** Entry @p i's place in the table: its cell has no other entry, its
 *  daughters' names are new, and its cell is reached from an initial cell
 *  (perpendicular needs a parent's cut). */
static int check_lineage_place(const sp_scene *scene, int i, const char *file) {
  const sp_scene_lineage *e = &scene->lineage[i];
  for (int j = 0; j < i; ++j)
    SP_CHECK(strcmp(scene->lineage[j].cell, e->cell) != 0, SP_ERR_INPUT,
             "%s: lineage[%d].cell: '%s' has an entry already (lineage[%d]): a cell "
             "divides once", file, i, e->cell, j);
  const char *daughter[2] = {e->first, e->second}, *key[2] = {"first", "second"}, *which;
  for (int d = 0; d < 2; ++d) {
    const int k = initial_named(scene, daughter[d]);
    SP_CHECK(k < 0, SP_ERR_INPUT,
             "%s: lineage[%d].%s: expected a new name, got '%s', the name of cells[%d]",
             file, i, key[d], daughter[d], k);
    const int j = daughter_entry(scene, daughter[d], i + 1, &which);
    SP_CHECK(j < 0, SP_ERR_INPUT,
             "%s: lineage[%d].%s: '%s' is a daughter of two entries: also "
             "lineage[%d].%s", file, j, which, daughter[d], i, key[d]);
  }
  /* the cell's ancestry: up the table to an initial cell */
  const char *name = e->cell;
  int parent = -1;
  for (int up = 0; initial_named(scene, name) < 0; ++up) {
    const int j = daughter_entry(scene, name, 0, &which);
    SP_CHECK(j >= 0, SP_ERR_INPUT,
             "%s: lineage[%d].cell: unknown name '%s': expected an initial cell's name "
             "(cells[i].name) or a daughter of another entry (first, second)",
             file, i, name);
    SP_CHECK(up < scene->n_lineage, SP_ERR_INPUT,
             "%s: lineage[%d].cell: '%s' is its own ancestor (a cycle through "
             "lineage[%d].%s): the table must lead down from the initial cells",
             file, i, e->cell, j, which);
    if (parent < 0) parent = j;
    name = scene->lineage[j].cell;
  }
  SP_CHECK(e->axis != SP_AXIS_PERPENDICULAR || parent >= 0, SP_ERR_INPUT,
           "%s: lineage[%d].axis: perpendicular needs the parent's cut, but '%s' is an "
           "initial cell: expected long or fixed", file, i, e->cell);
  return SP_OK;
}

/** The names and the lineage table: names unique; every entry's cell an
 *  initial cell or a daughter of another entry, once; every daughter's name
 *  new; no cycle; perpendicular only for a cell that has a parent. */
static int check_lineage(const sp_scene *scene, const char *file) {
  int named = 0;
  for (int i = 0; i < scene->n_cells; ++i) {
    const char *name = scene->cells[i].name;
    if (!name[0]) continue;
    ++named;
    const int first = initial_named(scene, name);
    SP_CHECK(first == i, SP_ERR_INPUT,
             "%s: cells[%d].name: expected a name of its own, got '%s', the name of cells[%d]",
             file, i, name, first);
  }
  if (scene->n_lineage == 0) return SP_OK;
  SP_CHECK(named > 0, SP_ERR_INPUT,
           "%s: lineage: expected named cells (cells[i].name), got none: the table's "
           "cell, first and second refer to names", file);
  for (int i = 0; i < scene->n_lineage; ++i) {
    SP_CALL(check_lineage_entry(scene, i, file));
    SP_CALL(check_lineage_place(scene, i, file));
  }
  return SP_OK;
}

/** The initial layout (every cell on every node: a run starts with it, also
 *  before cutting local supports) must be numberable by ints and Epetra's
 *  32-bit global ids; checked here, before anything that large is allocated. */
static int check_sizes(const sp_scene *scene, int n_cells, const char *cells_key,
                       const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  const int rectangle = m->type == SP_MESH_RECTANGLE, box = m->type == SP_MESH_BOX;
  const int ellipsoid = m->type == SP_MESH_ELLIPSOID;
  const long long nodes = rectangle ? sp_mesh_rectangle_nodes(m->nx, m->ny)
                          : box     ? sp_mesh_box_nodes(m->nx, m->ny, m->nz)
                          : ellipsoid ? sp_mesh_ellipsoid_nodes(m->refinements, m->buffer_layers)
                                      : sp_mesh_ellipse_nodes(m->refinements, m->buffer_layers);
  const long long pairs = nodes * n_cells;
  char mesh_keys[SP_TEXT];
  if (rectangle)
    snprintf(mesh_keys, sizeof mesh_keys, "mesh.nx, mesh.ny (%d x %d elements)", m->nx, m->ny);
  else if (box)
    snprintf(mesh_keys, sizeof mesh_keys, "mesh.nx, mesh.ny, mesh.nz (%d x %d x %d elements)",
             m->nx, m->ny, m->nz);
  else
    snprintf(mesh_keys, sizeof mesh_keys,
             "mesh.refinements, mesh.buffer_layers (%d refinements, %d buffer layers)",
             m->refinements, m->buffer_layers);
  SP_CHECK(pairs <= SP_LAYOUT_MAX_PAIRS, SP_ERR_INPUT,
           "%s: %s and %s (%d cells): too large: %lld nodes x %d cells = %lld (cell, node) "
           "pairs in the initial layout, 2 x %lld unknowns; at most %d pairs fit the "
           "solver's 32-bit indices (Epetra's global ids): use fewer elements or cells",
           file, mesh_keys, cells_key, n_cells, nodes, n_cells, pairs, pairs,
           SP_LAYOUT_MAX_PAIRS);
  /* A run that keeps every cell on every node hands that layout to the
   * solver: its matrix's nonzeros must fit too (sp_nonzeros_bound). Local
   * supports are checked when each layout is handed over (the run's). */
  const int full = scene->layout.support == SP_SUPPORT_FULL ||
                   (scene->layout.support == SP_SUPPORT_AUTO &&
                    n_cells + scene->n_lineage <= 4 &&
                    scene->division.criterion == SP_DIVIDE_NONE);
  const int dim = sp_scene_dim(scene);
  const long long nonzeros = sp_nonzeros_bound(dim, nodes, n_cells);
  SP_CHECK(!full || nonzeros <= SP_LAYOUT_MAX_NONZEROS, SP_ERR_INPUT,
           "%s: %s, %s (%d cells) and layout.support (every cell on every node): too "
           "large: the Jacobian would hold up to %lld nonzeros (%lld nodes x %d x %d x %d), "
           "more than the %lld the solvers' 32-bit offsets count: use fewer elements or "
           "cells, or layout.support: local",
           file, mesh_keys, cells_key, n_cells, nonzeros, nodes, dim == 3 ? 27 : 9, n_cells,
           n_cells + 3, SP_LAYOUT_MAX_NONZEROS);
  return SP_OK;
}

int sp_scene_check_cell_count(const sp_scene *scene, int n_cells, const char *cells_key,
                              const char *where) {
  return check_sizes(scene, n_cells, cells_key, where);
}

/* ------------------------------------------------------------------------ */
/* Public functions                                                         */
/* ------------------------------------------------------------------------ */

/** Everything sp_scene_load does to a zeroed scene, from the file @p path
 *  or, when @p text is not NULL, from @p text standing for it; the caller
 *  frees the scene on failure, so this may return from anywhere. */
static int fill_scene(sp_scene *scene, const char *path, const char *text,
                      size_t len, int n_set, const char *const *set) {
  for (int s = 0; s < SP_N_MAPPINGS; ++s) store_defaults(scene, (sp_section)s);
  SP_CALL(text ? load_text(scene, path, text, len) : load_file(scene, path));
  for (int i = 0; i < n_set; ++i) SP_CALL(apply_override(scene, set[i]));
  /* a clash may come from an override: say so in the prefix */
  char where[SP_TEXT + SP_TEXT];
  snprintf(where, sizeof where, "%s%s", path,
           n_set ? " (with its --set overrides)" : "");
  SP_CALL(check_time_and_mesh(scene, where));
  SP_CALL(check_3d(scene, where));
  SP_CALL(check_initial(scene, where));
  SP_CALL(check_cells(scene, where));
  SP_CALL(check_lineage(scene, where));
  SP_CALL(check_sizes(scene, scene->n_cells, "cells", where));
  return SP_OK;
}

int sp_scene_cell_is_turned(const sp_scene_cell *cell) {
  return !isnan(cell->axis[0]) || !isnan(cell->axis[1]) || !isnan(cell->axis[2]);
}

void sp_scene_cell_frame(const sp_scene_cell *cell, double R[3][3]) {
  for (int d = 0; d < 3; ++d)
    for (int j = 0; j < 3; ++j) R[d][j] = d == j;
  if (!sp_scene_cell_is_turned(cell)) return;
  double a[3], norm = 0;
  for (int d = 0; d < 3; ++d) {
    a[d] = isnan(cell->axis[d]) ? 0.0 : cell->axis[d];
    norm = hypot(norm, a[d]);
  }
  for (int d = 0; d < 3; ++d) a[d] /= norm; /* (not 0: check_cell_axis) */
  if (a[0] <= -1.0) { /* -x: a half turn about z */
    R[0][0] = R[1][1] = -1;
    return;
  }
  /* Rodrigues: R = I + [v]x + [v]x^2 / (1 + c), v = x cross a, c = x . a */
  const double v[3] = {0, -a[2], a[1]}, f = 1 / (1 + a[0]);
  const double K[3][3] = {{0, -v[2], v[1]}, {v[2], 0, -v[0]}, {-v[1], v[0], 0}};
  for (int d = 0; d < 3; ++d)
    for (int j = 0; j < 3; ++j) {
      double kk = 0;
      for (int m = 0; m < 3; ++m) kk += K[d][m] * K[m][j];
      R[d][j] += K[d][j] + f * kk;
    }
}

double sp_scene_cell_extent(const sp_scene_cell *cell, int dim, int d) {
  if (!sp_scene_cell_is_turned(cell)) return sp_scene_cell_semi_axis(cell, d);
  double R[3][3], e = 0;
  sp_scene_cell_frame(cell, R);
  for (int j = 0; j < dim; ++j) e = hypot(e, R[d][j] * sp_scene_cell_semi_axis(cell, j));
  return e;
}

void sp_scene_cell_point(const sp_scene_cell *cell, int dim, const double *centre,
                         const double *local, double *out) {
  if (!sp_scene_cell_is_turned(cell)) {
    for (int d = 0; d < dim; ++d) out[d] = centre[d] + local[d];
    return;
  }
  double R[3][3];
  sp_scene_cell_frame(cell, R);
  for (int d = 0; d < dim; ++d) {
    out[d] = centre[d];
    for (int j = 0; j < dim; ++j) out[d] += R[d][j] * local[j];
  }
}

double sp_scene_cell_semi_axis(const sp_scene_cell *cell, int d) {
  const double given = d == 0 ? cell->semi_x : d == 1 ? cell->semi_y : cell->semi_z;
  return isnan(given) ? cell->radius : given;
}

int sp_scene_cell_is_ellipsoid(const sp_scene_cell *cell) {
  return !isnan(cell->semi_x) || !isnan(cell->semi_y) || !isnan(cell->semi_z);
}

int sp_scene_dim(const sp_scene *scene) {
  return scene->mesh.type == SP_MESH_BOX || scene->mesh.type == SP_MESH_ELLIPSOID ? 3 : 2;
}

int sp_scene_read_file(const char *path, char **text, size_t *len) {
  return read_file(path, text, len);
}

static int load_scene(const char *path, const char *text, size_t len,
                      int n_set, const char *const *set, sp_scene **out) {
  SP_CHECK(path && out && n_set >= 0 && (n_set == 0 || set), SP_ERR_INTERNAL,
           "sp_scene_load: bad arguments");
  *out = NULL;
  sp_scene *scene;
  SP_ALLOC(scene, 1);
  int rc = fill_scene(scene, path, text, len, n_set, set);
  if (rc != SP_OK) {
    sp_scene_destroy(&scene);
    return rc;
  }
  *out = scene;
  return SP_OK;
}

int sp_scene_load(const char *path, int n_set, const char *const *set,
                  sp_scene **out) {
  return load_scene(path, NULL, 0, n_set, set, out);
}

int sp_scene_load_text(const char *name, const char *text, size_t len,
                       int n_set, const char *const *set, sp_scene **out) {
  SP_CHECK(text || len == 0, SP_ERR_INTERNAL, "sp_scene_load_text: no text");
  return load_scene(name, text ? text : "", len, n_set, set, out);
}

double sp_scene_interface_width(const sp_scene *scene) {
  return sqrt(scene->model.kappa / (2.0 * scene->model.alpha));
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
      snprintf(fallback, sizeof fallback, "%s", word_of(key, key->fallback));
    else if (isnan(key->fallback))
      snprintf(fallback, sizeof fallback, "none");
    else
      snprintf(fallback, sizeof fallback, "%.15g", key->fallback);
    fprintf(out, "| `%s` | %s | %s | %s | %s | %s |\n",
            key_path(key, -1, path, sizeof path),
            sp_key_type_names[key->type], key->unit, fallback, range,
            key->meaning);
  }
}

void sp_scene_destroy(sp_scene **scene) {
  if (!scene || !*scene) return;
  free((*scene)->cells);
  free((*scene)->lineage);
  free(*scene);
  *scene = NULL;
}
