/* The command line on bad input: every broken scene in tests/scenes/bad/,
 * a missing file, a bad --set and a bad option each end with exit status 2,
 * one message on stderr naming the key, and nothing written to --out. */
#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "command.h"

static int exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

static void expect_input_error(const char *args, const char *key) {
  char out[8192];
  system("rm -rf cli_out");
  int status = run_softpack(args, out, sizeof out);
  CHECK(status == 2, "'%s': exit status %d, output: %s", args, status, out);
  CHECK(strstr(out, key) != NULL, "'%s': message does not name '%s': %s", args, key, out);
  CHECK(!exists("cli_out"), "'%s': the output directory was created", args);
}

/* The progress line: drawn in place (ESC[K) on a terminal (a pty from
 * util-linux's script), absent with --quiet and when stderr is a pipe. */
static void check_progress_line(void) {
  const char *scene = SP_SOURCE_DIR "/tests/scenes/local_short.yaml";
  const char *sets = "--set time.max_steps=2 --set mesh.nx=20 --set mesh.ny=12 "
                     "--set layout.support=full";
  char cmd[4096], out[16384];
  snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 %s run %s --out cli_progress %s 2>&1",
           SP_BINARY, scene, sets);
  CHECK(run_command(cmd, out, sizeof out) == 0 && !strchr(out, '\033'),
        "progress drawn into a pipe: %s", out);
  for (int quiet = 0; quiet < 2; ++quiet) {
    snprintf(cmd, sizeof cmd,
             "script -qec 'OMP_NUM_THREADS=1 %s run %s --out cli_progress %s%s' /dev/null",
             SP_BINARY, scene, sets, quiet ? " --quiet" : "");
    const int status = run_command(cmd, out, sizeof out);
    const int drawn = strstr(out, "\033[Kstep 2  t ") != NULL;
    CHECK(status == 0 && drawn == !quiet, "%s: status %d, progress line %s: %s",
          quiet ? "--quiet" : "a terminal", status, drawn ? "drawn" : "absent", out);
  }
}

int main(void) {
  const char *bad_dir = SP_SOURCE_DIR "/tests/scenes/bad";
  DIR *dir = opendir(bad_dir);
  CHECK(dir != NULL, "cannot open %s", bad_dir);
  int n_files = 0;
  struct dirent *ent;
  while (dir && (ent = readdir(dir))) {
    if (!strstr(ent->d_name, ".yaml")) continue;
    char path[2048], args[4096], key[256] = "";
    snprintf(path, sizeof path, "%s/%s", bad_dir, ent->d_name);
    FILE *f = fopen(path, "r");
    if (!f || fscanf(f, "# expect: %255s", key) != 1) {
      CHECK(0, "%s has no '# expect: key' first line", path);
      if (f) fclose(f);
      continue;
    }
    fclose(f);
    snprintf(args, sizeof args, "run %s --out cli_out", path);
    expect_input_error(args, key);
    ++n_files;
  }
  if (dir) closedir(dir);
  printf("%d broken scene files checked\n", n_files);
  CHECK(n_files >= 10, "only %d broken scenes", n_files);
  const char *good = SP_SOURCE_DIR "/tests/scenes/two_overlapping.yaml";
  char args[4096];
  expect_input_error("run /nonexistent/scene.yaml --out cli_out", "/nonexistent/scene.yaml");
  snprintf(args, sizeof args, "run %s --out cli_out --set model.kapa=1", good);
  expect_input_error(args, "model.kapa");
  snprintf(args, sizeof args, "run %s --out cli_out --set time.dt=-1", good);
  expect_input_error(args, "time.dt");
  snprintf(args, sizeof args, "run %s --out cli_out --set solver.linear=klu3", good);
  expect_input_error(args, "solver.linear");
  snprintf(args, sizeof args, "run %s --out cli_out --frobnicate", good);
  expect_input_error(args, "--frobnicate");
  expect_input_error("explode", "explode");
  char out[8192];
  CHECK(run_softpack("--help", out, sizeof out) == 0 && strstr(out, "usage"), "--help: %s", out);
  check_progress_line();
  TEST_DONE();
}
