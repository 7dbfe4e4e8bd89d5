/**
 * @file softpack_linear.h
 * @brief The linear solvers of the Newton iterations (the scene's
 *        `solver.linear`): one table, read by the scene reader (its
 *        keywords), `softpack info`, the C door (sp_solver_linear_backend)
 *        and the glue's factory (cxx_glue/linear/backends.cpp).
 *
 * Adding a solver is one line here and its implementation file
 * cxx_glue/linear/linear_NAME.cpp, which defines
 *     std::unique_ptr<sp::LinearSolver> sp::make_linear_NAME(MPI_Comm, const sp_solver_options &);
 *     const char *sp::linear_NAME_version(bool *available);
 * (docs/design.md, "The glue").
 *
 * SP_LINEAR_SOLVERS(X) calls X(ID, NAME, RANKS) for each, in the order
 * `softpack keys` lists them: ID names the enum value SP_LINEAR_ID (the
 * values are 0, 1, ... in this order), NAME the scene's keyword and the
 * implementation's functions, RANKS how it runs under MPI.
 */
#ifndef SOFTPACK_LINEAR_H
#define SOFTPACK_LINEAR_H

#ifdef __cplusplus
extern "C" {
#endif

/** How a linear solver runs on several MPI processes. */
typedef enum {
  SP_LINEAR_PARALLEL = 0, /**< on every rank's rows */
  SP_LINEAR_GATHERED = 1, /**< serial: the matrix gathered on rank 0, solved there */
  SP_LINEAR_SERIAL = 2    /**< one process only: refused with several */
} sp_linear_ranks;

#define SP_LINEAR_SOLVERS(X)                         \
  X(SUPERLU, superlu, SP_LINEAR_GATHERED)            \
  X(SUPERLU_DIST, superlu_dist, SP_LINEAR_PARALLEL)  \
  X(MUMPS, mumps, SP_LINEAR_PARALLEL)                \
  X(KLU, klu, SP_LINEAR_GATHERED)                    \
  X(KLU2, klu2, SP_LINEAR_SERIAL)                    \
  X(GMRES_ILU, gmres_ilu, SP_LINEAR_PARALLEL)        \
  X(GMRES_CELLS, gmres_cells, SP_LINEAR_PARALLEL)    \
  X(GMRES_AMG, gmres_amg, SP_LINEAR_PARALLEL)

/** The linear solvers, and `auto` (the scene's default: mumps on a 2D
 *  mesh, gmres_cells or from 15,000 nodes gmres_amg on a 3D one; resolved
 *  when the run is set up, sp_linear_auto). */
typedef enum {
#define SP_LINEAR_ENUM_(id, name, ranks) SP_LINEAR_##id,
  SP_LINEAR_SOLVERS(SP_LINEAR_ENUM_)
#undef SP_LINEAR_ENUM_
  SP_LINEAR_COUNT, /**< the solvers are 0 .. SP_LINEAR_COUNT - 1 */
  SP_LINEAR_AUTO = SP_LINEAR_COUNT
} sp_linear_kind;

#ifdef __cplusplus
}
#endif
#endif
