/* libFuzzer target for the scene reader (src/scene/scene*.c): any bytes, read as
 * a scene file's text, must give SP_OK or SP_ERR_INPUT with a message, never
 * a crash, a sanitizer report, a hang or another error code. Built by
 * -DSOFTPACK_FUZZ=ON with clang and run by `tools/softpack.sh fuzz`
 * (docs/robustness.md); inputs that crashed it are kept in
 * tests/scenes/fuzz/ and loaded by tests/test_fuzz_regressions.c. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "public/error.h"
#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  sp_scene *scene = NULL;
  const int rc = sp_scene_load_text("fuzz.yaml", (const char *)data, size, 0, NULL, &scene);
  if (rc != SP_OK && rc != SP_ERR_INPUT) {
    fprintf(stderr, "fuzz_scene: error code %d: %s\n", rc, sp_error_message());
    abort();
  }
  if ((rc == SP_OK) != (scene != NULL) || (rc == SP_OK && scene->n_cells < 1) ||
      (rc != SP_OK && sp_error_message()[0] == '\0')) {
    fprintf(stderr, "fuzz_scene: code %d with scene %p (%d cells), message '%s'\n", rc,
            (void *)scene, scene ? scene->n_cells : -1, sp_error_message());
    abort();
  }
  sp_scene_destroy(&scene);
  sp_error_clear();
  return 0;
}
