/* Time per 3D picture: the 3D run 5's domain (the ellipsoid
 * 0.5 x 0.25 x 0.25 with a buffer shell of 2 layers, width 0.1) at
 * `refinements` r (default 4: 28672 hexahedra in Omega), 8 spherical cells
 * of radius 0.1 (tanh profile of width 0.02) at the corners of a 2 x 2 x 2
 * block, a full layout. Prints the mesh's size, then for sections_*.png
 * and surfaces_*.png at picture width w (default 800) the best of 3
 * wall-clock times and the file's size.
 *   build/bench/bench_render_3d [r=4] [w=800] [out directory=.]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "io/render.h"
#include "base/wall_clock.h"

#define N_CELLS 8

typedef int (*render_fn)(const sp_mesh *, const sp_layout *, const double *, double,
                         const sp_cell_name *, int, const char *);

static void time_picture(const char *what, render_fn fn, const sp_mesh *m, const sp_layout *l,
                         const double *state, int width, const char *dir) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s_000000.png", dir, what);
  double best = HUGE_VAL;
  for (int rep = 0; rep < 3; ++rep) {
    const double t0 = sp_wall_clock();
    if (fn(m, l, state, 0.0, NULL, width, path) != SP_OK) {
      fprintf(stderr, "%s: %s\n", what, sp_error_message());
      exit(1);
    }
    best = fmin(best, sp_wall_clock() - t0);
  }
  struct stat st;
  stat(path, &st);
  printf("%-9s %d px wide: %.3f s (best of 3), %lld bytes\n", what, width, best,
         (long long)st.st_size);
}

int main(int argc, char **argv) {
  const int r = argc > 1 ? atoi(argv[1]) : 4, width = argc > 2 ? atoi(argv[2]) : 800;
  const char *dir = argc > 3 ? argv[3] : ".";
  sp_mesh *m;
  sp_layout *l;
  if (sp_mesh_ellipsoid(r, 0.5, 0.25, 0.25, 2, 0.1, &m) != SP_OK ||
      sp_layout_create_full(m->n_nodes, N_CELLS, &l) != SP_OK) {
    fprintf(stderr, "%s\n", sp_error_message());
    return 1;
  }
  double *state = calloc(2 * (size_t)l->n_pairs, sizeof *state);
  for (int k = 0; k < N_CELLS; ++k) {
    const double c[3] = {k & 1 ? 0.11 : -0.11, k & 2 ? 0.1 : -0.1, k & 4 ? 0.1 : -0.1};
    for (int i = 0; i < m->n_nodes; ++i) {
      const double *x = m->xy + 3 * (size_t)i;
      const double d = sqrt((x[0] - c[0]) * (x[0] - c[0]) + (x[1] - c[1]) * (x[1] - c[1]) +
                            (x[2] - c[2]) * (x[2] - c[2]));
      state[2 * (size_t)sp_layout_pair(l, k, i)] = 0.5 * (1 - tanh((d - 0.1) / 0.02));
    }
  }
  printf("ellipsoid 0.5 x 0.25 x 0.25, refinements %d, buffer 2 layers: %d hexahedra, %d nodes, "
         "%d cells\n", r, m->n_elems, m->n_nodes, N_CELLS);
  time_picture("sections", sp_render_sections, m, l, state, width, dir);
  time_picture("surfaces", sp_render_surfaces, m, l, state, width, dir);
  free(state);
  sp_layout_destroy(&l);
  sp_mesh_destroy(&m);
  return 0;
}
