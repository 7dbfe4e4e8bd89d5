/* The C layout of the public structures, as JSON, for test_abi.py to
 * compare with the package's ctypes declarations (src/python/softpack/_capi.py):
 * sizeof and offsetof of every field the package reads. Built by
 * tests/CMakeLists.txt against the public headers (<softpack/run.h>'s). */
#include <stddef.h>
#include <stdio.h>

#include "public/run.h"

#define F(type, field) printf("%s\"%s\": %zu", first++ ? ", " : "", #field, offsetof(type, field))
#define S(type, name)                                                                 \
  do {                                                                                \
    printf("%s\"%s\": {\"size\": %zu", nstruct++ ? ",\n " : "", name, sizeof(type)); \
    first = 1;                                                                        \
  } while (0)
#define E() printf("}")

int main(void) {
  int first, nstruct = 0;
  printf("{");
#ifdef SP_DIM_MAX /* API 0.2 */
  printf("\"api\": \"0.2\",\n ");
  S(sp_cell_obs, "cell_obs");
  F(sp_cell_obs, mass); F(sp_cell_obs, mass_core); F(sp_cell_obs, centre);
  F(sp_cell_obs, inertia); F(sp_cell_obs, moments); F(sp_cell_obs, axes);
  F(sp_cell_obs, long_axis); F(sp_cell_obs, volume);
  E();
#else
  printf("\"api\": \"0.1\",\n ");
  S(sp_cell_obs, "cell_obs");
  F(sp_cell_obs, mass); F(sp_cell_obs, mass_core); F(sp_cell_obs, xc); F(sp_cell_obs, yc);
  F(sp_cell_obs, zc); F(sp_cell_obs, Ixx); F(sp_cell_obs, Izz); F(sp_cell_obs, I1);
  F(sp_cell_obs, I3); F(sp_cell_obs, v1); F(sp_cell_obs, v3); F(sp_cell_obs, angle);
  F(sp_cell_obs, area);
  E();
#endif
  S(sp_step_info, "step_info");
  F(sp_step_info, step); F(sp_step_info, t); F(sp_step_info, dt); F(sp_step_info, t_end);
  F(sp_step_info, n_cells); F(sp_step_info, newton_its); F(sp_step_info, failed_attempts);
  F(sp_step_info, attempts); F(sp_step_info, error_estimate); F(sp_step_info, cells);
  F(sp_step_info, wall_seconds); F(sp_step_info, last);
#ifdef SP_DIM_MAX
  F(sp_step_info, dim); F(sp_step_info, names); F(sp_step_info, run);
#endif
  E();
  S(sp_attempt, "attempt");
  F(sp_attempt, dt); F(sp_attempt, why); F(sp_attempt, n_residuals);
  F(sp_attempt, residual_norms); F(sp_attempt, error_estimate); F(sp_attempt, dt_next);
  E();
  S(sp_run_summary, "run_summary");
  F(sp_run_summary, steps); F(sp_run_summary, newton_its); F(sp_run_summary, t_final);
  F(sp_run_summary, divisions); F(sp_run_summary, unknowns_max);
  F(sp_run_summary, t_checkpoints); F(sp_run_summary, stopped);
  E();
  S(sp_restart, "restart");
  F(sp_restart, checkpoint); F(sp_restart, resume_dir); F(sp_restart, as_initial);
  E();
  printf("}\n");
  return 0;
}
