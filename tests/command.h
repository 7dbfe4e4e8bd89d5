/* Run a shell command and keep what it prints, for tests of the program. */
#ifndef SP_TEST_COMMAND_H
#define SP_TEST_COMMAND_H
#include <stdio.h>
#include <sys/wait.h>

/** Run @p cmd_line with popen; its stdout (the first @p size - 1 bytes)
 *  goes to @p out. Returns its exit status, or -1 if it did not exit. */
static int run_command(const char *cmd_line, char *out, size_t size) {
  FILE *p = popen(cmd_line, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, size - 1, p);
  out[n] = '\0';
  int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#ifdef SP_BINARY
/** Run the program under test (SP_BINARY) with @p args, one thread per
 *  process, its stderr with its stdout into @p out. */
static int run_softpack(const char *args, char *out, size_t size) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 %s %s 2>&1", SP_BINARY, args);
  return run_command(cmd, out, size);
}
#endif

#endif
