/**
 * @file output.h
 * @brief A run's output directory: energy.csv, cells.csv, fields.pvd with
 *        one .vtu per output time. Files are written whole (to a temporary
 *        name, then renamed), so a crash never leaves a half-written file.
 */
#ifndef SP_OUTPUT_H
#define SP_OUTPUT_H

#include <stdio.h>

#include "model/cells.h"
#include "model/division.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "softpack_solver.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sp_output_s *sp_output;

/** @brief Create @p dir (and parents) and start the CSV logs with headers
 *         (a 2D mesh's). */
int sp_output_open(const char *dir, sp_output *out);

/** What a scene adds to the logs (sp_output_open_dim's @p flags). */
enum {
  SP_OUTPUT_NAMED = 1,   /**< the scene names its cells */
  SP_OUTPUT_ADHESION = 2 /**< the scene has adhesion */
};

/** @brief sp_output_open for a mesh of dimension @p dim (2 or 3): on a 3D
 *         mesh cells.csv is step,t,cell,mass,xc,yc,zc,I1,I2,I3,long_x,long_y,
 *         long_z,core_mass,volume (docs/3d.md); with SP_OUTPUT_NAMED in
 *         @p flags (the scene names its cells) cells.csv ends with a name
 *         column, divisions.csv with parent_name,first_name,second_name,
 *         fraction; with SP_OUTPUT_ADHESION energy.csv ends with the
 *         adhesion part of the energy (in its total). */
int sp_output_open_dim(const char *dir, int dim, int flags, sp_output *out);

/** One fields file of fields.pvd: fields_<step>.vtu, or .pvtu of pieces. */
typedef struct {
  int step;
  double t;
  int pvtu;
} sp_output_field;

/**
 * @brief Continue a run in @p dir from its step @p step (a restart): the
 *        CSV logs are cut back to the rows of steps <= @p step (and a torn
 *        last line) and appended to; fields.pvd lists @p fields up to
 *        @p step. Logs that do not exist are started with their headers
 *        (cells.csv's for a mesh of dimension @p dim, as sp_output_open_dim).
 */
int sp_output_resume(const char *dir, int dim, int step, int flags, int n_fields,
                     const sp_output_field *fields, sp_output *out);

/** @brief The fields files written so far, in order (a checkpoint saves
 *         them): their number, and *fields. */
int sp_output_fields_list(sp_output out, const sp_output_field **fields);

/** What one accepted step cost, in wall-clock seconds of rank 0: the whole
 *  step (every attempt, divisions, support changes), the solver's phases
 *  and the support change (local supports), whether one happened, and the
 *  unknowns of the Newton system the step solved (2 x the (cell, node)
 *  pairs of the layout before any support change after it), the
 *  factorisations of the accepted attempt (fewer than its Newton
 *  iterations with solver.jacobian_reuse), the failed attempts before
 *  it and their factorisations, and the largest rise of the residual norm
 *  over its first in the accepted attempt (below 1: |F| never rose; what
 *  solver.newton_divergence must stay above), and the accepted attempt's
 *  GMRES iterations (solver.linear gmres_ilu; 0 with a direct solver). */
typedef struct {
  double step, assembly, factorisation, solves, supports;
  int support_changed;
  long unknowns;
  int factorisations, failed_attempts, failed_factorisations;
  double residual_rise; /**< largest ||F_k|| / ||F_0|| of the accepted attempt */
  long linear_its;      /**< GMRES iterations of the accepted attempt (gmres_ilu) */
  double error_estimate; /**< time.control adaptive: the step's local error
                              estimate over its tolerance (<= 1: accepted;
                              -1: no estimate, e.g. a first step) */
} sp_step_costs;

/** @brief Append one row to energy.csv:
 *  step,t,dt,newton_its,n_cells,energy,bulk,gradient,repulsion,buffer,shape,
 *  seconds,assembly_s,factorisation_s,solves_s,supports_s,support_changed,
 *  unknowns,factorisations,failed_attempts,failed_factorisations,
 *  residual_rise,linear_its,error_estimate
 *  (@p seconds NULL: zeros, error_estimate -1) */
int sp_output_energy(sp_output out, int step, double t, double dt,
                     int newton_its, int n_cells, const sp_energy_parts *parts,
                     double shape, const sp_step_costs *seconds);

/** @brief Append one row per cell to cells.csv:
 *  step,t,cell,mass,xc,yc,I1,I2,angle,core_mass,area (cells numbered from 1;
 *  core_mass counts c only where c >= the observables' threshold), and
 *  with named cells (sp_output_open_dim) its name from @p names (NULL: "") */
int sp_output_cells(sp_output out, int step, double t, int n_cells,
                    const sp_cell_obs *obs, const sp_cell_name *names);

/**
 * @brief Write fields_<step>.vtu (unstructured grid of the mesh's elements,
 *        quads (VTK type 9) in 2D, hexahedra (type 12) in 3D; point arrays
 *        c_k and mu_k per cell, 0 outside a cell's support, and cell_id = the
 *        k (from 1) with the largest c_k where that c_k > 1/2, else 0) and
 *        rewrite fields.pvd listing every .vtu written so far with its time.
 *        With @p names (a named scene's; NULL: none) its FieldData holds
 *        the String array cell_name, one name per cell, cell k's at tuple
 *        k - 1 (docs/embryo.md, "Names in the fields and the pictures").
 */
int sp_output_fields(sp_output out, const sp_mesh *mesh,
                     const sp_layout *layout, const double *state, int step,
                     double t, const sp_cell_name *names);

/**
 * @brief MPI runs: write this rank's piece fields_<step>_p<rank>.vtu: the
 *        elements whose first node is in [first_node, end_node) (the rule
 *        by which the solver's ranks assemble) and the nodes they use, with
 *        the arrays of sp_output_fields (and cell_name with @p names) plus
 *        node_id (the global node). Any rank may call it; it needs only the
 *        output directory.
 */
int sp_output_fields_piece(const char *dir, const sp_mesh *mesh, const sp_layout *layout,
                           const double *state, int step, double t, const sp_cell_name *names,
                           int rank, int first_node, int end_node);

/**
 * @brief MPI runs, rank 0: write fields_<step>.pvtu naming the pieces of
 *        ranks 0 .. n_ranks-1, and list it in fields.pvd.
 */
int sp_output_fields_pvtu(sp_output out, const sp_layout *layout, int step, double t,
                          int n_ranks);

/** @brief Append one row to divisions.csv: t,step,parent,child,axis_angle,
 *         parent_mass_before,parent_mass_after,child_mass_after (cells
 *         numbered from 1; the angle is the division line's, from x; the
 *         first daughter keeps the parent's number); on a 3D mesh the
 *         angle's column is three, long_x,long_y,long_z: the parent's long
 *         axis d->axis, the cut plane's unit normal; with named cells
 *         parent_name,first_name,second_name,fraction (the lineage table's
 *         share of the first daughter; empty for a division by the scene's
 *         division: rules). */
int sp_output_division(sp_output out, double t, int step, const sp_division_record *d);

/**
 * @brief Another CSV log of the output directory (contacts.csv), kept by
 *        its module: @p dir/@p name started with @p header (@p resume_step
 *        < 0), or, continuing a run, cut back like the others to the rows
 *        whose column @p step_column is a step <= @p resume_step and
 *        appended to. Rows are fprintf'd to *@p f and checked with
 *        sp_output_log_done; the caller closes *@p f and frees *@p path.
 */
int sp_output_log_open(const char *dir, const char *name, const char *header,
                       int step_column, int resume_step, FILE **f, char **path);

/** @brief Flush a log's rows; an error naming @p path if @p printed < 0
 *         (fprintf's result) or the write failed. */
int sp_output_log_done(FILE *f, const char *path, int printed);

/** @brief The directory path (borrowed). */
const char *sp_output_dir(sp_output out);

/** @brief Flush and close; *out becomes NULL. */
int sp_output_close(sp_output *out);

/** The units the outputs may be read in (output.length_unit, ...): one
 *  model length is length_scale `length`, one model time time_scale
 *  `time`; an empty name: not given. */
typedef struct {
  sp_cell_name length, time;
  double length_scale, time_scale;
} sp_output_units;

/**
 * @brief Write @p dir/units.csv for a run on a mesh of dimension @p dim:
 *        `file,column,unit,scale`, one row per column of cells.csv,
 *        divisions.csv, contacts.csv and energy.csv that has a length or
 *        time dimension (a time, a centre, a mass = area or volume, a
 *        moment of inertia, a contact or surface), its unit (e.g. um^3) and
 *        the factor that turns the column's model value into it (e.g.
 *        length_scale^3). Rows of a dimension whose unit is not given are
 *        left out; nothing is written when neither is given (the outputs
 *        are then what they always were).
 */
int sp_output_units_write(const char *dir, int dim, const sp_output_units *units);

/** @brief Write @p text to @p path atomically (temporary file + rename). */
int sp_write_file_atomic(const char *path, const char *text, size_t len);

#ifdef __cplusplus
}
#endif
#endif
