#include "model/registry.h"

#include <stdlib.h>
#include <string.h>

#include "public/error.h"

/** One per-cell array from @p n_old to @p n entries (new ones zeroed). */
static int resize_array(void **ptr, size_t elem, int n_old, int n) {
  void *p = realloc(*ptr, elem * (size_t)(n > 0 ? n : 1));
  SP_CHECK(p, SP_ERR_MEMORY, "out of memory for %d cells", n);
  if (n > n_old) memset((char *)p + elem * (size_t)n_old, 0, elem * (size_t)(n - n_old));
  *ptr = p;
  return SP_OK;
}

/** Every per-cell array of the registry with its element size: the one
 *  list that resizing and freeing read. */
typedef struct {
  void **array;
  size_t size;
} per_cell_array;

#define SP_REGISTRY_ARRAYS 13

static void per_cell_arrays(sp_registry *reg, per_cell_array out[SP_REGISTRY_ARRAYS]) {
  const per_cell_array arrays[] = {
      {(void **)&reg->obs, sizeof *reg->obs},
      {(void **)&reg->birth, sizeof *reg->birth},
      {(void **)&reg->source_on, sizeof *reg->source_on},
      {(void **)&reg->division_skipped, sizeof *reg->division_skipped},
      {(void **)&reg->divided_now, sizeof *reg->divided_now},
      {(void **)&reg->obs_new, sizeof *reg->obs_new},
      {(void **)&reg->core_mass_old, sizeof *reg->core_mass_old},
      {(void **)&reg->core_mass, sizeof *reg->core_mass},
      {(void **)&reg->divisions, sizeof *reg->divisions},
      {(void **)&reg->shape, sizeof *reg->shape},
      {(void **)&reg->name, sizeof *reg->name},
      {(void **)&reg->cut_normal, sizeof *reg->cut_normal},
      {(void **)&reg->sister, sizeof *reg->sister},
  };
  _Static_assert(sizeof arrays / sizeof *arrays == SP_REGISTRY_ARRAYS, "one entry per array");
  memcpy(out, arrays, sizeof arrays);
}

int sp_registry_resize(sp_registry *reg, int n) {
  const int n_old = reg->obs ? reg->n : 0;
  if (reg->obs && n == n_old) return SP_OK; /* (a support change: the arrays stay put) */
  per_cell_array arrays[SP_REGISTRY_ARRAYS];
  per_cell_arrays(reg, arrays);
  for (size_t i = 0; i < SP_REGISTRY_ARRAYS; ++i)
    SP_CALL(resize_array(arrays[i].array, arrays[i].size, n_old, n));
  reg->n = n;
  return SP_OK;
}

void sp_registry_free(sp_registry *reg) {
  per_cell_array arrays[SP_REGISTRY_ARRAYS];
  per_cell_arrays(reg, arrays);
  for (size_t i = 0; i < SP_REGISTRY_ARRAYS; ++i) free(*arrays[i].array);
  *reg = (sp_registry){0};
}
