/* softpack info: the facts are asked of the libraries this process runs
 * with (the BLAS and MPI actually loaded, the solvers the glue serves),
 * not of what the build hoped to find. */
#define _GNU_SOURCE /* dladdr, RTLD_DEFAULT */
#include "run/build_info.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"
#include "softpack_solver.h"

/* info names the glue's solvers by their scene words: same numbering. */

const char *sp_version(void) { return SP_VERSION; }

const char *sp_build_type(void) { return SP_BUILD_TYPE; }

/** The BLAS in use: the file that serves dgemm_ (Debian's alternatives
 *  resolved; the next after libsoftpack's own, which hands products with
 *  one column to dgemv_), and OpenBLAS' own description when it is loaded. */
static void print_blas(FILE *out) {
  char path[PATH_MAX] = "no dgemm_ loaded";
  Dl_info where;
  void *dgemm = dlsym(RTLD_NEXT, "dgemm_");
  if (dgemm && dladdr(dgemm, &where) && where.dli_fname &&
      !realpath(where.dli_fname, path))
    snprintf(path, sizeof path, "%s", where.dli_fname);
  char *(*openblas_config)(void) = NULL;
  *(void **)&openblas_config = dlsym(RTLD_DEFAULT, "openblas_get_config");
  const char *forward = sp_solver_gemm_forward()
                            ? "one-column products through dgemv_"
                            : "one-column products through dgemm_ (SOFTPACK_GEMM_FORWARD=0)";
  if (openblas_config)
    fprintf(out, "BLAS: %s; dgemm_ from %s; %s\n", openblas_config(), path, forward);
  else
    fprintf(out, "BLAS: dgemm_ from %s (not OpenBLAS); %s\n", path, forward);
}

void sp_build_info_print(FILE *out, MPI_Comm comm) {
  fprintf(out, "build type: %s\n", sp_build_type());
  fprintf(out, "Trilinos: %s\n", sp_solver_trilinos_version());
  fprintf(out, "linear solvers (solver.linear):\n");
  for (int kind = 0; kind < SP_LINEAR_COUNT; ++kind) {
    const char *backend = NULL;
    const int served = sp_solver_linear_backend(kind, &backend);
    fprintf(out, "  %-13s %s%s\n", sp_scene_linear_name((sp_linear_kind)kind),
            backend ? backend : "?",
            served == 1 ? "" : ": not in this build");
  }
  print_blas(out);
  char library[MPI_MAX_LIBRARY_VERSION_STRING] = "";
  int length = 0, major = 0, minor = 0, size = 0;
  MPI_Get_library_version(library, &length);
  library[strcspn(library, "\n")] = '\0'; /* the first line names it */
  MPI_Get_version(&major, &minor);
  MPI_Comm_size(comm, &size);
  fprintf(out, "MPI: %s (MPI standard %d.%d)\n", library, major, minor);
  fprintf(out, "MPI processes: %d\n", size);
}
