/* The classes of errors at the C/C++ boundary (c_api/softpack_solver.h,
 * src/run/solver_status.h) and their exit statuses: only bad input exits 2.
 * - the glue refuses options as bad input, and null arguments as internal;
 * - every glue status maps to its core code, an unknown one to internal;
 * - a solver creation that fails (the fault hook SOFTPACK_FAULT=solver:0)
 *   is a solver error, through the library (SP_ERR_SOLVER) and the program
 *   (exit 1, "softpack: error (solver)"), not bad input;
 * - a failed allocation at set-up (SOFTPACK_FAULT=setup:0) is a memory
 *   error, exit 1; a malformed SOFTPACK_FAULT is bad input naming it;
 * - a factorisation out of memory (SOFTPACK_FAULT=factor:0) ends the run
 *   at its first attempt, a memory error, the last good state written;
 * - a layout whose Jacobian would overflow 32-bit offsets is refused (memory)
 *   before the glue sees it;
 * - bad input in the scene still exits 2. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "command.h"
#include "mesh/layout.h"
#include "public/run.h"
#include "run/solver_status.h"
#include "run/resize.h"
#include "run/stepper.h"

static const char scene[] =
    "mesh: {type: rectangle, x0: 0, y0: 0, x1: 1, y1: 1, nx: 12, ny: 12}\n"
    "time: {dt: 1.0e-4, t_end: 3.0e-4}\n"
    "cells:\n"
    "  - {x: 0.5, y: 0.5, radius: 0.2}\n"
    "output: {every: 1000, pictures: false}\n";

/** sp_run_text of the scene with SOFTPACK_FAULT = @p fault (NULL: unset). */
static int run_with_fault(const char *fault, const char *out_dir) {
  if (fault) setenv("SOFTPACK_FAULT", fault, 1);
  else unsetenv("SOFTPACK_FAULT");
  const int rc = sp_run_text("classes", scene, strlen(scene), 0, NULL, out_dir, MPI_COMM_WORLD,
                             NULL, NULL, NULL);
  unsetenv("SOFTPACK_FAULT");
  return rc;
}

/** The program with SOFTPACK_FAULT = @p fault (NULL: unset) and @p args:
 *  its exit status, and its output must contain @p needle. */
static void program_fails(const char *fault, const char *args, int want_status,
                          const char *needle) {
  char out[16384];
  if (fault) setenv("SOFTPACK_FAULT", fault, 1);
  const int status = run_softpack(args, out, sizeof out);
  unsetenv("SOFTPACK_FAULT");
  printf("SOFTPACK_FAULT=%s softpack %s: exit status %d\n", fault ? fault : "", args, status);
  CHECK(status == want_status, "%s: exit status %d, want %d:\n%s", fault ? fault : "no fault",
        status, want_status, out);
  CHECK(strstr(out, needle) != NULL, "%s: no '%s' in:\n%s", fault ? fault : "no fault",
        needle, out);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  struct stat st;

  /* options the glue refuses: bad input; a null argument: a bug */
  sp_solver_options opt = {.jacobian = 99, .linear = SP_LINEAR_SUPERLU, .newton_rtol = 1e-8,
                           .newton_atol = 1e-10, .newton_max_its = 10};
  sp_solver s = NULL;
  int status = sp_solver_create(MPI_COMM_WORLD, &opt, &s);
  CHECK(status == SP_SOLVER_ERR_INPUT && strstr(sp_solver_last_error(s), "solver.jacobian"),
        "unknown Jacobian: status %d, %s", status, sp_solver_last_error(s));
  CHECK(sp_solver_failed(s, status, "solver") == SP_ERR_INPUT &&
            strstr(sp_error_message(), "solver: solver.jacobian"),
        "as a core error: %s", sp_error_message());
  sp_solver_destroy(&s);
  opt.jacobian = SP_SOLVER_JAC_AD;
  CHECK(sp_solver_create(MPI_COMM_WORLD, NULL, &s) == SP_SOLVER_ERR_INTERNAL,
        "null options are not an internal error");
  CHECK(sp_solver_create(MPI_COMM_WORLD, &opt, &s) == SP_SOLVER_OK, "create: %s",
        sp_solver_last_error(s));
  sp_step_report report;
  int rc;
  status = sp_solver_step(s, NULL, NULL, &report);
  CHECK(status == SP_SOLVER_ERR_INTERNAL, "a step with null data: status %d", status);
  sp_solver_destroy(&s);

  /* a layout whose Jacobian could not be counted in 32 bits (4 cells on
   * each of 2938 x 2901 nodes: up to 2,147,830,776 nonzeros) is refused
   * before the glue sees it, as too large (memory), not as bad input */
  sp_layout *huge = NULL;
  CHECK_OK(sp_layout_create_full(2938 * 2901, 4, &huge));
  CHECK(sp_layout_nonzeros_bound(huge, 2) == 2147830776LL, "bound %lld",
        sp_layout_nonzeros_bound(huge, 2));
  rc = sp_solver_attach(NULL, NULL, huge);
  CHECK(rc == SP_ERR_MEMORY && strstr(sp_error_message(), "nonzeros"),
        "a layout with too many nonzeros: rc %d: %s", rc, sp_error_message());
  sp_layout_destroy(&huge);

  /* each class its code, and only bad input exits 2 */
  const int classes[][2] = {{SP_SOLVER_OK, SP_OK},
                            {SP_SOLVER_ERR_INPUT, SP_ERR_INPUT},
                            {SP_SOLVER_ERR_MEMORY, SP_ERR_MEMORY},
                            {SP_SOLVER_ERR_SOLVER, SP_ERR_SOLVER},
                            {SP_SOLVER_ERR_MPI, SP_ERR_MPI},
                            {SP_SOLVER_ERR_INTERNAL, SP_ERR_INTERNAL},
                            {77, SP_ERR_INTERNAL}};
  for (size_t i = 0; i < sizeof classes / sizeof classes[0]; ++i) {
    const int code = sp_error_code_of_solver(classes[i][0]);
    CHECK(code == classes[i][1], "status %d: code %d, want %d", classes[i][0], code,
          classes[i][1]);
    const int exit_status = sp_error_exit_status(code);
    CHECK(exit_status == (code == SP_OK ? 0 : code == SP_ERR_INPUT ? 2 : 1),
          "%s: exit status %d", sp_error_class_name(code), exit_status);
  }

  /* a failed solver creation through the library: a solver error */
  system("rm -rf classes_solver");
  rc = run_with_fault("solver:0", "classes_solver");
  printf("solver fault: %d, %s\n", rc, sp_error_message());
  CHECK(rc == SP_ERR_SOLVER && strstr(sp_error_message(), "SOFTPACK_FAULT=solver:0"),
        "solver fault: rc %d: %s", rc, sp_error_message());
  CHECK(stat("classes_solver", &st) != 0, "a failed set-up wrote its output directory");
  /* a fault for another rank does nothing on this one */
  system("rm -rf classes_other_rank");
  CHECK_OK(run_with_fault("solver:1", "classes_other_rank"));
  rc = run_with_fault("setup:0", "classes_setup");
  CHECK(rc == SP_ERR_MEMORY && strstr(sp_error_message(), "out of memory at setup"),
        "setup fault: rc %d: %s", rc, sp_error_message());
  rc = run_with_fault("setup:zero", "classes_setup");
  CHECK(rc == SP_ERR_INPUT && strstr(sp_error_message(), "SOFTPACK_FAULT"),
        "malformed fault: rc %d: %s", rc, sp_error_message());

  /* a factorisation that could not allocate its factors (as MUMPS's
   * INFOG(1) = -13): a memory error at once, not retried with smaller
   * steps (the same matrix's size), the last good state written */
  system("rm -rf classes_factor");
  sp_run_summary sum = {0};
  setenv("SOFTPACK_FAULT", "factor:0", 1);
  rc = sp_run_text("classes", scene, strlen(scene), 0, NULL, "classes_factor", MPI_COMM_WORLD,
                   NULL, NULL, &sum);
  unsetenv("SOFTPACK_FAULT");
  printf("factor fault: %d after %d failed attempts, %s\n", rc, sum.failed_attempts,
         sp_error_message());
  CHECK(rc == SP_ERR_MEMORY && strstr(sp_error_message(), "SOFTPACK_FAULT=factor:0") &&
            strstr(sp_error_message(), "not retried"),
        "factor fault: rc %d: %s", rc, sp_error_message());
  CHECK(sum.failed_attempts == 1 && sum.steps == 0, "factor fault: %d failed attempts, %d steps",
        sum.failed_attempts, sum.steps);
  CHECK(stat("classes_factor/fields_000000.vtu", &st) == 0, "the last good state is not written");

  /* the program: the class in the message, exit 1 unless bad input */
  char args[4096];
  snprintf(args, sizeof args, "run %s/tests/scenes/rectangle_full.yaml --out classes_cli",
           SP_SOURCE_DIR);
  program_fails("solver:0", args, 1, "softpack: error (solver): solver: solver "
                "creation failed on rank 0");
  program_fails("setup:0", args, 1, "softpack: error (memory): out of memory");
  program_fails("step", args, 2, "softpack: error: SOFTPACK_FAULT: expected");
  snprintf(args, sizeof args, "run %s/tests/scenes/rectangle_full.yaml --out classes_cli_factor",
           SP_SOURCE_DIR);
  program_fails("factor:0", args, 1, "softpack: error (memory): step 1 at t = 0: out of memory "
                "in the factorisation");
  snprintf(args, sizeof args,
           "run %s/tests/scenes/rectangle_full.yaml --out classes_cli --set time.dt=-1",
           SP_SOURCE_DIR);
  program_fails(NULL, args, 2, "time.dt");
  CHECK(stat("classes_cli", &st) != 0, "a failed set-up wrote its output directory");
  MPI_Finalize();
  TEST_DONE();
}
