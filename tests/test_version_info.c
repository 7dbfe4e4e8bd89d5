/* softpack --version names the project version and the git revision the
 * program was built from ("unknown" outside a git work tree); softpack info
 * names the build type, the Trilinos release, every solver.linear word as
 * served, the BLAS file in use, the MPI library and one MPI process; extra
 * arguments to either are bad input (exit status 2). */
#include <mpi.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "command.h"
#include "scene/scene.h"
#include "softpack_solver.h"

/** The text after "key: " up to the end of its line, or "" if absent. */
static void line_after(const char *text, const char *key, char *value, size_t size) {
  const char *at = strstr(text, key);
  value[0] = '\0';
  if (!at) return;
  at += strlen(key);
  snprintf(value, size, "%.*s", (int)strcspn(at, "\n"), at);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  char out[8192], want[512], git[128] = "";

  /* The revision the source is at: what the build must have recorded. */
  run_command("cd " SP_SOURCE_DIR " && test \"$(git rev-parse --show-toplevel 2>/dev/null)\" = "
      "\"$(pwd -P)\" && git rev-parse --short=12 HEAD",
      git, sizeof git);
  git[strcspn(git, "\n")] = '\0';
  CHECK(run_softpack("--version", out, sizeof out) == 0, "--version: %s", out);
  snprintf(want, sizeof want, "softpack %s (git %s", SP_PROJECT_VERSION,
           git[0] ? git : "unknown)");
  printf("--version: %s", out);
  CHECK(strncmp(out, want, strlen(want)) == 0, "--version prints '%s', want it to begin '%s'",
        out, want);

  CHECK(run_softpack("info", out, sizeof out) == 0, "info: %s", out);
  printf("info:\n%s", out);
  CHECK(strncmp(out, want, strlen(want)) == 0, "info does not begin with the version line");
  char value[1024];
  line_after(out, "build type: ", value, sizeof value);
  CHECK(strcmp(value, SP_CONFIG) == 0, "build type '%s', want '%s'", value, SP_CONFIG);
  line_after(out, "Trilinos: ", value, sizeof value);
  CHECK(strcmp(value, SP_TRILINOS_VERSION) == 0, "Trilinos '%s', want '%s'", value,
        SP_TRILINOS_VERSION);
  /* Debian's Trilinos serves every solver the scene accepts. */
  for (int kind = 0; kind < SP_LINEAR_COUNT; ++kind) {
    char key[64];
    snprintf(key, sizeof key, "  %s ", sp_scene_linear_name((sp_linear_kind)kind));
    line_after(out, key, value, sizeof value);
    CHECK(value[0] != '\0', "info lists no linear solver '%s'", key);
    CHECK(strstr(value, "not in this build") == NULL, "%s: %s", key, value);
  }
  /* klu2 is served by Amesos2, klu by SuiteSparse's own KLU and mumps by
   * MUMPS' own C interface (not through Amesos2): not one library twice */
  const char *klu2 = NULL, *klu = NULL;
  CHECK(sp_solver_linear_backend(SP_LINEAR_KLU2, &klu2) == 1 && klu2 &&
            strstr(klu2, "Amesos2") != NULL,
        "klu2 is served by '%s', want Amesos2", klu2 ? klu2 : "(none)");
  CHECK(sp_solver_linear_backend(SP_LINEAR_KLU, &klu) == 1 && klu &&
            strstr(klu, "SuiteSparse") != NULL && strstr(klu, "Amesos") == NULL,
        "klu is served by '%s', want SuiteSparse's KLU", klu ? klu : "(none)");
  const char *mumps = NULL;
  CHECK(sp_solver_linear_backend(SP_LINEAR_MUMPS, &mumps) == 1 && mumps &&
            strstr(mumps, "MUMPS") != NULL && strstr(mumps, "Amesos") == NULL,
        "mumps is served by '%s', want MUMPS' own interface", mumps ? mumps : "(none)");
  /* gmres_ilu: Belos and Ifpack2 (only those) */
  const char *gmres = NULL;
  CHECK(sp_solver_linear_backend(SP_LINEAR_GMRES_ILU, &gmres) == 1 && gmres &&
            strstr(gmres, "Belos") != NULL && strstr(gmres, "Ifpack2") != NULL &&
            strstr(gmres, "AztecOO") == NULL,
        "gmres_ilu is served by '%s', want Belos and Ifpack2", gmres ? gmres : "(none)");
  /* The BLAS line names a file that exists. */
  line_after(out, "BLAS: ", value, sizeof value);
  const char *from = strstr(value, "dgemm_ from ");
  CHECK(from != NULL, "BLAS line '%s' names no library", value);
  if (from) {
    char path[1024];
    snprintf(path, sizeof path, "%.*s", (int)strcspn(from + 12, " ;"), from + 12);
    struct stat st;
    CHECK(stat(path, &st) == 0, "BLAS library '%s' does not exist", path);
  }
  char library[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(library, &length);
  library[strcspn(library, "\n")] = '\0';
  line_after(out, "MPI: ", value, sizeof value);
  CHECK(strncmp(value, library, strlen(library)) == 0, "MPI '%s', want '%s'", value, library);
  line_after(out, "MPI processes: ", value, sizeof value);
  CHECK(strcmp(value, "1") == 0, "MPI processes '%s', want 1", value);

  CHECK(run_softpack("info extra", out, sizeof out) == 2 && strstr(out, "extra"),
        "info extra: %s", out);
  CHECK(run_softpack("--version extra", out, sizeof out) == 2 && strstr(out, "extra"),
        "--version extra: %s", out);
  CHECK(run_softpack("--help", out, sizeof out) == 0 && strstr(out, "softpack info") &&
            strstr(out, "softpack --version"),
        "--help names neither info nor --version: %s", out);
  MPI_Finalize();
  TEST_DONE();
}
