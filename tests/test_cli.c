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
  TEST_DONE();
}
