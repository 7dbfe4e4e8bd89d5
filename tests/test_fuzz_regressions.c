/* Inputs that once broke the scene reader under the fuzz target
 * (tests/fuzz/fuzz_scene.c, docs/robustness.md), kept in tests/scenes/fuzz/:
 * each must load to SP_OK or fail with SP_ERR_INPUT and a message naming
 * the file, never crash or return another code. */
#define _POSIX_C_SOURCE 200809L /* opendir, readdir */

#include <dirent.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "scene/scene.h"

int main(void) {
  const char *dir_path = SP_SOURCE_DIR "/tests/scenes/fuzz";
  DIR *dir = opendir(dir_path);
  CHECK(dir, "cannot open %s", dir_path);
  if (!dir) TEST_DONE();
  int n_files = 0;
  for (struct dirent *e; (e = readdir(dir));) {
    if (e->d_name[0] == '.') continue;
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", dir_path, e->d_name);
    sp_error_clear();
    sp_scene *scene = NULL;
    const int rc = sp_scene_load(path, 0, NULL, &scene);
    printf("%s: %d %s\n", e->d_name, rc, sp_error_message());
    CHECK(rc == SP_OK || rc == SP_ERR_INPUT, "%s: code %d: %s", path, rc, sp_error_message());
    CHECK(rc == SP_OK || strstr(sp_error_message(), e->d_name), "%s: message: %s", path,
          sp_error_message());
    CHECK((rc == SP_OK) == (scene != NULL), "%s: code %d with scene %p", path, rc,
          (void *)scene);
    sp_scene_destroy(&scene);
    ++n_files;
  }
  closedir(dir);
  CHECK(n_files >= 1, "no inputs in %s", dir_path);
  TEST_DONE();
}
