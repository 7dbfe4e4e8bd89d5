/**
 * @file checkjac.h
 * @brief `softpack check-jacobian SCENE.yaml [--steps K] [--set k=v]...`:
 *        the element Jacobians of the kinds ad, hand and fd compared on a
 *        scene's initial state and after K backward-Euler steps, on the
 *        run's own set-up (run_setup.h: the same layout, node numbering
 *        and local supports as `softpack run` of the scene).
 */
#ifndef SP_CHECKJAC_H
#define SP_CHECKJAC_H

#ifdef __cplusplus
extern "C" {
#endif

/** Largest hand-vs-ad relative difference accepted (exit status 1 beyond). */
#define SP_CHECKJAC_TOLERANCE 1e-10

/**
 * @brief The check-jacobian command. @p argc and @p argv are the arguments
 *        after the command name. Prints, for each state checked, the largest
 *        relative difference |J_a - J_b| / max|J_b| over elements for hand vs
 *        ad, ad vs fd and hand vs fd, with all terms and with lambda = 0,
 *        lambda_b = 0 and both zeroed (to isolate the repulsion and buffer).
 * @return SP_OK; SP_ERR_INPUT for bad input; SP_ERR_SOLVER when hand and ad
 *         differ beyond SP_CHECKJAC_TOLERANCE or a step failed
 */
int sp_check_jacobian_command(int argc, char **argv);

#ifdef __cplusplus
}
#endif
#endif
