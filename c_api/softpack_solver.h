/**
 * @file softpack_solver.h
 * @brief The only door from the C core into the C++/Trilinos glue.
 *
 * Plain C, an opaque handle, error codes, no Trilinos types. Every entry point
 * catches every exception and returns a code (sp_solver_status: the class of
 * the error); the message is kept in the handle (sp_solver_last_error).
 *
 * The unknowns follow a layout (src/mesh/layout.h): pairs (cell, node), numbered
 * node-major, two unknowns per pair: state[2p] = c, state[2p+1] = mu.
 */
#ifndef SOFTPACK_SOLVER_H
#define SOFTPACK_SOLVER_H

#include <mpi.h>
#include <stdint.h>

#include "softpack_linear.h"
#include "softpack_newton.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * What every entry point returns: 0, Newton's failure to converge
 * (sp_solver_step only: retry with a smaller dt), or the class of a hard
 * error. The C core maps the classes to its own codes (src/run/solver_status.h)
 * and so to exit statuses: only SP_SOLVER_ERR_INPUT is bad input (exit 2),
 * every other class exits 1 (docs/robustness.md).
 */
typedef enum {
  SP_SOLVER_OK = 0,
  SP_SOLVER_NOT_CONVERGED = 1, /**< sp_solver_step: Newton did not converge */
  SP_SOLVER_ERR_INPUT = 2,     /**< options the glue refuses (the scene key is
                                    named), or a backend this build lacks */
  SP_SOLVER_ERR_MEMORY = 3,    /**< out of memory (std::bad_alloc) */
  SP_SOLVER_ERR_SOLVER = 4,    /**< a library failed: Trilinos, NOX, a linear
                                    solver (e.g. a singular factorisation) */
  SP_SOLVER_ERR_MPI = 5,       /**< an MPI call failed */
  SP_SOLVER_ERR_INTERNAL = 6   /**< a bug: an invariant or argument check */
} sp_solver_status;

/**
 * Jacobian of the element residual: Sacado forward AD (SFad for 1-4 cells on
 * an element, DFad beyond), hand-derived, or central differences.
 * SP_SOLVER_JAC_AD_DFAD (DFad at every element size) is for benchmarks and
 * the comparison entry points only; sp_solver_create does not accept it.
 */
enum {
  SP_SOLVER_JAC_AD = 0,
  SP_SOLVER_JAC_HAND = 1,
  SP_SOLVER_JAC_FD = 2,
  SP_SOLVER_JAC_AD_DFAD = 3
};
/** SuperLU_DIST's fill-reducing column order: METIS on the graph of the
 *  (cell, node) pairs (c and mu of a pair together), or on the unknowns
 *  (SuperLU_DIST's own METIS_AT_PLUS_A). */
enum { SP_SOLVER_ORDER_PAIRS = 0, SP_SOLVER_ORDER_UNKNOWNS = 1 };
/** The length of each Newton update: the full step, or NOX's backtracking
 *  line search (halve the step until ||F|| falls, down to 1e-12 of it;
 *  failing that, the full step). */
enum { SP_SOLVER_STEP_FULL = 0, SP_SOLVER_STEP_BACKTRACK = 1 };

typedef struct sp_solver_s *sp_solver;

typedef struct {
  int jacobian;        /**< SP_SOLVER_JAC_* */
  int linear;          /**< sp_linear_kind (softpack_linear.h), not auto */
  double newton_rtol;  /**< ||F|| <= rtol ||F_0|| ... */
  double newton_atol;  /**< ... or ||F|| <= atol (unscaled 2-norm) */
  int newton_max_its;  /**< more iterations count as a failure */
  /** Modified Newton: an iteration keeps the last Jacobian and its
   *  factorisation when the previous iteration cut ||F|| at least this
   *  much (||F_k|| <= jacobian_reuse ||F_k-1||); the first iteration of a
   *  step has a fresh one unless jacobian_carry keeps the last step's.
   *  0: a new Jacobian every iteration (Newton's method). */
  double jacobian_reuse;
  /** With jacobian_reuse > 0: a step begins on the last step's
   *  factorisation (same layout, the last step converged) and keeps it
   *  while each iteration cuts ||F|| by at least this factor; the first
   *  iteration that does not gets a fresh Jacobian. 0: every step begins
   *  with a fresh Jacobian. */
  double jacobian_carry;
  /** A step fails as soon as an iteration's ||F_k|| exceeds this multiple
   *  of the step's first ||F_0|| (it is retried with a smaller dt without
   *  spending the rest of newton_max_its). 0: off; otherwise > 1. */
  double newton_divergence;
  int line_search; /**< SP_SOLVER_STEP_*; 0: full steps */
  int ordering;  /**< SP_SOLVER_ORDER_* (SuperLU_DIST only); 0: pairs */
  /** SuperLU_DIST only: 1 for one step of iterative refinement per solve
   *  (SuperLU_DIST's default), 0 for none. */
  int refine;
  /** SP_LINEAR_GMRES_ILU only, taken as given (no defaults here: the
   *  scene's solver.ilu_fill and solver.krylov_tol have them): the ILU(k)
   *  level of fill, >= 0 (0: ILU(0)), and the relative residual of a
   *  linear solve, in (0, 1). */
  int ilu_fill;
  double krylov_tol;
} sp_solver_options;

/** The mesh, borrowed (must outlive the solver's use of it): Q1
 *  quadrilaterals (dim 2, 4 nodes per element) or hexahedra (dim 3, 8),
 *  nodes in the order of src/mesh/q1.h. */
typedef struct {
  int n_nodes, n_elems;
  const double *xy;       /**< dim * n_nodes */
  const int *elem;        /**< nodes_per_elem * n_elems */
  const int *region;      /**< per element, 0 = Omega, 1 = buffer ring */
  int dim;                /**< 2 or 3 */
  int nodes_per_elem;     /**< 4 (dim 2) or 8 (dim 3) */
} sp_mesh_view;

/** The layout, borrowed; copied by sp_solver_set_problem. */
typedef struct {
  int n_nodes, n_cells, n_pairs;
  const int *node_start;  /**< n_nodes + 1 */
  const int *pair_cell;   /**< n_pairs */
  /** Node partition (optional): rank r owns nodes rank_first_node[r] ..
   *  rank_first_node[r+1]-1 (n_ranks + 1 entries, n_ranks = the solver's
   *  communicator size). NULL: equal node counts per rank. */
  const int *rank_first_node;
  int n_ranks;
  /** The element-slot table (src/mesh/layout.h, sp_slots; required): element
   *  e's cells are slot_cell[elem_start[e] .. elem_start[e+1]-1], by
   *  increasing cell, each with the pairs of the element's nodes at
   *  slot_pair[n s .. n s + n - 1], n = the mesh's nodes_per_elem. The C
   *  core applies the whole-element rule once (sp_layout_slots); the glue
   *  takes the table as it is. */
  int64_t n_slots;
  const int64_t *elem_start; /**< n_elems + 1 (the mesh's) */
  const int *slot_cell;      /**< n_slots */
  const int *slot_pair;      /**< nodes_per_elem n_slots */
} sp_layout_view;

/** Model parameters (docs/model.md). */
typedef struct {
  double alpha, kappa, lambda, lambda_b, mobility;
  /** Adhesion (docs/model.md, "Adhesion"): sigma_kl of cells k and l at
   *  adhesion[adhesion_cells k + l], symmetric, zero diagonal, borrowed;
   *  the energy gets sum_{k<l} sigma_kl int grad c_k . grad c_l. NULL: none
   *  (then adhesion_cells is not read). adhesion_cells is at least the
   *  layout's cell count. */
  const double *adhesion;
  int adhesion_cells;
} sp_model_params;

/**
 * Shape-penalty data of one cell (docs/model.md, shape penalty): the term adds
 * -sum_i coef_i * (v_i . Ibar(X) v_i) to mu_k, Ibar about the centre (xc,
 * yc[, zc]), i over the mesh's dim principal moments (2 in 2D, 3 in 3D;
 * Ibar = |Xb|^2 Id - Xb Xb^T, src/model/shape.h). Entries beyond dim are unused.
 *
 * Explicit (sp_step_data.shape_implicit = 0): coef as given, from c^n.
 * Linearised implicit (shape_implicit = 1): with the centre, eigenvectors
 * and mask frozen at c^n, the moments of the new state are
 * I_j = I_j^n + dI_j, dI_j = int_mask Ihat_j (c - c^n) (exact to first
 * order: the centre's shift does not move central moments at first order),
 * and the term uses coef_i - sum_j gain[i][j] dI_j. Its Jacobian adds, per
 * cell, u_i gain[i][j] u_j^T (u_i = int_mask Ihat_i N: rank dim per cell),
 * applied by Sherman-Morrison-Woodbury on the sparse factorisation.
 */
typedef struct {
  double xc, yc;
  double zc;       /**< 3D: the centre's z (0 in 2D) */
  double v[3][3];  /**< unit eigenvectors v_1 (largest moment), v_2 (, v_3) */
  double coef[3];  /**< 2 delta^i (I^i,ref - I^i) (round cells: src/model/shape.h) */
  double gain[3][3]; /**< -d coef_i / d I_j (implicit only; 0: none) */
  double threshold; /**< the term acts only where c^n >= threshold (at the
                         quadrature point), as the observables count c only
                         where c >= their weight threshold */
} sp_shape_coef;

/** What one backward-Euler step needs besides the state. */
typedef struct {
  double dt;
  sp_model_params model;
  const double *state_old;  /**< c^n (and mu^n) in layout order */
  const double *source;     /**< per pair: nodal source s_k (NULL: none) */
  const sp_shape_coef *shape; /**< per cell (NULL: no shape term) */
  int shape_implicit;         /**< 1: shape coefficients follow the new
                                   state's moments through gain */
  /** Newton also converges (after at least one update) once every c entry
   *  of the last update is at most update_atol + update_rtol |c|: the
   *  adaptive time control's tolerances scaled down, so Newton's error is a
   *  small part of the step's (mu is algebraic: it follows c). 0, 0: off,
   *  the residual tolerances alone. */
  double update_rtol, update_atol;
  /** Polled before each Newton iteration (NULL: never): non-zero stops the
   *  solve with SP_NEWTON_INTERRUPTED, the state as on entry. Collective:
   *  every rank must return the same (softpack's agrees over MPI). */
  int (*interrupt)(void *ctx);
  void *interrupt_ctx;
} sp_step_data;


/** What a step did. */
typedef struct {
  int converged;        /**< 1 only if Newton met its tolerance */
  int failure;          /**< sp_newton_failure: why not (0 when converged) */
  int newton_its;
  int factorisations;   /**< Jacobians filled and factored (<= newton_its) */
  long linear_its;      /**< iterative solver (gmres_ilu): its GMRES iterations
                             over the step's linear solves; 0 for direct ones */
  int n_residuals;      /**< entries of residual_norms */
  double residual_norms[SP_MAX_NEWTON_HISTORY]; /**< ||F|| per iteration */
  double t_assembly;    /**< seconds: residual + Jacobian fills */
  double t_factor;      /**< seconds: LU factorisations */
  double t_solve;       /**< seconds: triangular solves */
  double t_total;       /**< seconds: the whole step */
  char reason[512];     /**< why it failed (empty when converged) */
} sp_step_report;

/** Energy parts (docs/model.md); shape is added by the C core. adhesion:
 *  sum_{k<l} sigma_kl int grad c_k . grad c_l (0 without adhesion). */
typedef struct {
  double bulk, gradient, repulsion, buffer, adhesion;
} sp_energy_parts;

/**
 * @brief Create a solver on @p comm with @p options (collective on @p comm).
 * @return SP_SOLVER_OK, SP_SOLVER_ERR_INPUT for options it refuses (e.g.
 *         klu2 on several processes), or another class. On failure *out may
 *         still hold a handle carrying the message: destroy it.
 */
int sp_solver_create(MPI_Comm comm, const sp_solver_options *options,
                     sp_solver *out);

/** @brief The number of ranks of the solver's communicator (0 on error). */
int sp_solver_ranks(sp_solver s);

/** What the solver holds on this rank and what this rank has sent
 *  (sp_solver_usage_of; docs/parallel.md, "Memory and messages per rank"). */
typedef struct {
  double mesh_bytes;   /**< its copies of the mesh and layout: element geometry,
                            slot, pair and DOF tables (the largest so far) */
  double state_bytes;  /**< its full copy of the state, gathered each Newton
                            iteration (the largest so far) */
  double matrix_bytes; /**< the Jacobian's rows of this rank, its ghost rows
                            and the CSR arrays handed to the linear solver
                            (the largest so far) */
  double sent_bytes;   /**< sent since creation: its rows in the state's
                            gathers, its ghost rows in the residual's and
                            the Jacobian's Exports (not the linear solver's
                            own messages) */
  long newton_its;     /**< the Newton iterations since creation, failed
                            attempts' too */
} sp_solver_usage;

/** @brief What the solver holds on this rank and has sent. Local. */
int sp_solver_usage_of(sp_solver s, sp_solver_usage *out);

/**
 * @brief Take another linear solver (@p linear, sp_linear_kind, not auto)
 *        with @p krylov_tol for its solves from the next
 *        sp_solver_set_problem on, which then rebuilds everything, as for
 *        a new layout. Collective; between steps only.
 * @return SP_SOLVER_OK, SP_SOLVER_ERR_INPUT for a solver this run cannot
 *         take (as sp_solver_create), or another class.
 */
int sp_solver_set_linear(sp_solver s, int linear, double krylov_tol);

/** @brief (Re)build maps, graph and matrix for a mesh and layout. Cheap to
 *         call again with the same layout; a new layout rebuilds everything. */
int sp_solver_set_problem(sp_solver s, const sp_mesh_view *mesh,
                          const sp_layout_view *layout);

/**
 * @brief Whether the next step may begin on the current factorisation
 *        (solver.jacobian_carry), and where its Jacobian was filled: for a
 *        checkpoint, so a continued run rebuilds it (sp_solver_carry_restore)
 *        and goes on as the run that wrote it.
 * @param carry 1: it may (then the rest is set), 0: the next step begins
 *        with a new Jacobian
 * @param dt the step's dt (dt_eff for BDF2) at the fill
 * @param x the full state (layout order, 2 n_pairs values), owned by the
 *        solver, valid until its next step
 * @param shape the step's shape coefficients, n_shape of them (0: none),
 *        owned by the solver; @p shape_implicit their mode
 */
int sp_solver_carry_point(sp_solver s, int *carry, double *dt, const double **x,
                          const sp_shape_coef **shape, int *n_shape, int *shape_implicit);

/**
 * @brief Fill the Jacobian at @p x with @p data (dt, model, shape as at the
 *        fill sp_solver_carry_point described) and factor it: the next step
 *        may begin on it. Collective.
 */
int sp_solver_carry_restore(sp_solver s, const sp_step_data *data, const double *x);

/**
 * @brief Remember where the factorisation carried into the next step was
 *        filled (what sp_solver_carry_point reports now), for
 *        sp_solver_carry_rewind. Cheap: a copy of the state it was filled at.
 */
int sp_solver_carry_mark(sp_solver s);

/**
 * @brief Report the marked carry point again (a step given up half-way, so
 *        that a checkpoint written now equals the one written before the
 *        step: a stop during a long step). The factorisation itself
 *        is the given-up attempt's: the next step begins with a new one.
 */
int sp_solver_carry_rewind(sp_solver s);

/**
 * @brief One backward-Euler step by Newton. On entry @p state is the initial
 *        guess; on success it holds the new state. On failure it is restored
 *        to its value on entry and report->reason says why.
 * @return SP_SOLVER_OK, SP_SOLVER_NOT_CONVERGED (retry with a smaller dt)
 *         or the sp_solver_status class of a hard error
 */
int sp_solver_step(sp_solver s, const sp_step_data *data, double *state,
                   sp_step_report *report);

/** @brief Energy parts of a state. */
int sp_solver_energy(sp_solver s, const sp_model_params *model,
                     const double *state, sp_energy_parts *parts);

/**
 * @brief Residual of the step equations at @p state (layout order, length
 *        2 n_pairs); a test and tooling hook.
 */
int sp_solver_residual(sp_solver s, const sp_step_data *data,
                       const double *state, double *residual);

/**
 * @brief The Jacobian of the step equations at @p state, as Newton uses it
 *        (the solver's Jacobian kind; with an implicit shape term, its
 *        low-rank part included), applied to @p x: y = J x, or y = J^T x if
 *        @p transpose is non-zero; a test hook. x and y: layout order,
 *        length 2 n_pairs. Collective.
 */
int sp_solver_apply_jacobian(sp_solver s, const sp_step_data *data,
                             const double *state, int transpose,
                             const double *x, double *y);

/**
 * @brief Compare the element Jacobian of kind @p jacobian with a central
 *        finite-difference one at @p state: largest |J - J_fd| / max|J_fd|
 *        over all elements.
 */
int sp_solver_check_jacobian(sp_solver s, const sp_step_data *data,
                             const double *state, int jacobian,
                             double *max_rel_err);

/**
 * @brief Compare the element Jacobians of kinds @p kind_a and @p kind_b
 *        (SP_SOLVER_JAC_*, including SP_SOLVER_JAC_AD_DFAD) at @p state: the
 *        largest over elements of max|J_a - J_b| / max|J_b|, entries of
 *        present unknowns only.
 */
int sp_solver_compare_jacobians(sp_solver s, const sp_step_data *data,
                                const double *state, int kind_a, int kind_b,
                                double *max_rel_diff);

/**
 * @brief Time the Jacobian fill of kind @p kind at @p state (benchmarks):
 *        @p repeats fills into a scratch matrix (the solver's own matrix and
 *        factors are untouched); *seconds_fill is the mean seconds of one
 *        whole fill (gather, element matrices, insertion, global assembly).
 *        If @p seconds_elements is not NULL it gets the mean seconds of the
 *        element matrices alone (gather + element kernel, no insertion).
 */
int sp_solver_time_jacobian(sp_solver s, const sp_step_data *data,
                            const double *state, int kind, int repeats,
                            double *seconds_fill, double *seconds_elements);

/** @brief The Trilinos release the glue was compiled against ("13.2"). */
const char *sp_solver_trilinos_version(void);

/**
 * @brief What serves a linear solver in this build (softpack info).
 * @param[in] linear SP_LINEAR_SUPERLU, ...
 * @param[out] backend the library behind it and its version, e.g.
 *             "SuperLU 5.3.0 (dgstrf)" (static text; NULL: not wanted)
 * @return 1 if this build can use it, 0 if not (an Amesos built without
 *         it), -1 for an unknown @p linear
 */
int sp_solver_linear_backend(int linear, const char **backend);

/** @brief 1 when the glue's dgemm_ hands products with one column to the
 *         BLAS's dgemv_ (cxx_glue/base/blas_forward.cpp), 0 when
 *         SOFTPACK_GEMM_FORWARD=0 turned it off. */
int sp_solver_gemm_forward(void);

/** @brief The message of the last failed call on @p s. */
const char *sp_solver_last_error(sp_solver s);

void sp_solver_destroy(sp_solver *s);

#ifdef __cplusplus
}
#endif
#endif
