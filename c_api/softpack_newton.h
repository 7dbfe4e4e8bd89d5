/**
 * @file softpack_newton.h
 * @brief What a Newton solve reports that a program running scenes sees
 *        (run_types.h: sp_attempt): why it failed, and how many residual
 *        norms a report holds. Shared by the shim (softpack_solver.h) and
 *        the public run API; installed with it.
 */
#ifndef SP_SOFTPACK_NEWTON_H
#define SP_SOFTPACK_NEWTON_H

/** The residual norms a Newton report holds (|F| at the guess and after
 *  each iteration, the first ones). */
#define SP_MAX_NEWTON_HISTORY 64

/** Why a Newton solve failed (sp_step_report.failure). */
typedef enum {
  SP_NEWTON_CONVERGED = 0,
  SP_NEWTON_MAX_ITERATIONS, /**< solver.newton_max_its reached */
  SP_NEWTON_DIVERGED,       /**< |F| above solver.newton_divergence x the first */
  SP_NEWTON_NOT_FINITE,     /**< a residual norm was not finite */
  SP_NEWTON_LINEAR_FAILED,  /**< a linear solve failed (reason says how) */
  SP_NEWTON_OTHER_FAILURE,  /**< NOX stopped for another reason */
  SP_NEWTON_INTERRUPTED,    /**< sp_step_data.interrupt asked it to stop (a
                                 stop signal during the step): not a failure
                                 of the step, which is dropped, not retried */
  SP_NEWTON_OUT_OF_MEMORY   /**< the linear solver could not allocate its
                                 factors (reason says how much it asked
                                 for): a smaller step has a matrix of the
                                 same size, so the run ends, not retried */
} sp_newton_failure;

#endif
