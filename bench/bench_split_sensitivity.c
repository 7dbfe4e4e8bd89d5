/* How a sharp division's split depends on where its line falls (* report (b)): from the fields a run wrote right after a division (the
 * parent is the sum of its two daughters there, up to the support change's
 * restored mass), the parent's centre and axis as the division saw them,
 * and the child's mass when the line is moved by s along its normal:
 *     M(s) = sum over the parent's nodes of w_i c_i H(sd_i - s)
 * (H = sp_division_child_share, the cut of sp_division_split: sharp, 1
 * beyond the line, 0 before it, 1/2 on it; w_i the node weights of the
 * observables). M is a staircase:
 * it jumps by w_i c_i wherever the line crosses a node. A line that runs
 * along a column of nodes crosses the whole column within a tiny offset,
 * so there the split is nearly discontinuous in the parent's state. The
 * smoothed cut (division.cut: smooth) is printed beside it for contrast.
 *
 *   bench_split_sensitivity SCENE FIELDS.vtu [PARENT CHILD]
 *
 * SCENE: the run's scene (its mesh, division.observe_threshold, the
 * interface width); FIELDS.vtu: a one-process snapshot written at the
 * division's step; PARENT, CHILD: the daughters' cell numbers (1-based;
 * default 1 2). Prints M(s) - M(0) for offsets from 1e-8 to 1e-3 and the
 * nodes within each offset of the line. */
#include <math.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "model/division.h"
#include "public/error.h"
#include "io/initial.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "scene/scene.h"
#include "run/stepper.h"

/** The scene's text without its cells, starting from @p vtu instead. */
static char *scene_from_vtu(const char *scene_path, const char *vtu) {
  FILE *f = fopen(scene_path, "r");
  if (!f) return NULL;
  size_t cap = 1 << 16, len = 0;
  char *text = malloc(cap), line[4096];
  int in_cells = 0;
  while (text && fgets(line, sizeof line, f)) {
    if (strncmp(line, "cells:", 6) == 0) in_cells = 1;
    else if (line[0] != ' ' && line[0] != '#' && line[0] != '\n') in_cells = 0;
    if (in_cells || len + strlen(line) + 1 >= cap) continue;
    strcpy(text + len, line);
    len += strlen(line);
  }
  fclose(f);
  if (text) snprintf(text + len, cap - len, "initial: {from: %s}\n", vtu);
  return text;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  if (argc < 3) {
    fprintf(stderr, "usage: bench_split_sensitivity SCENE FIELDS.vtu [PARENT CHILD]\n");
    return 2;
  }
  const int a = argc > 4 ? atoi(argv[3]) - 1 : 0, b = argc > 4 ? atoi(argv[4]) - 1 : 1;
  char *text = scene_from_vtu(argv[1], argv[2]);
  sp_scene *scene = NULL;
  sp_mesh *mesh = NULL;
  sp_layout *all = NULL, *one = NULL;
  int n = 0;
  if (!text || sp_scene_load_text(argv[1], text, strlen(text), 0, NULL, &scene) != SP_OK ||
      sp_initial_cell_count(scene, NULL, &n) != SP_OK || n <= (a > b ? a : b) || a < 0 || b < 0 ||
      sp_mesh_from_scene(scene, &mesh) != SP_OK ||
      sp_layout_create_full(mesh->n_nodes, n, &all) != SP_OK ||
      sp_layout_create_full(mesh->n_nodes, 1, &one) != SP_OK) {
    fprintf(stderr, "bench_split_sensitivity: %s\n", text ? sp_error_message() : "no scene");
    return 1;
  }
  const int nn = mesh->n_nodes;
  double *state = calloc(2 * (size_t)nn * n, sizeof(double));
  double *parent = calloc(2 * (size_t)nn, sizeof(double)), *w = calloc(nn, sizeof(double));
  double *sd = calloc(nn, sizeof(double));
  if (sp_initial_state(scene, mesh, all, state) != SP_OK) {
    fprintf(stderr, "bench_split_sensitivity: %s\n", sp_error_message());
    return 1;
  }
  for (int i = 0; i < nn; ++i)
    parent[2 * i] = state[2 * sp_layout_pair(all, a, i)] + state[2 * sp_layout_pair(all, b, i)];
  sp_cell_obs obs;
  if (sp_cells_observe(mesh, one, parent, scene->division.observe_threshold, &obs) != SP_OK ||
      sp_cells_node_weights(mesh, one, 0, w) != SP_OK) {
    fprintf(stderr, "bench_split_sensitivity: %s\n", sp_error_message());
    return 1;
  }
  double point[3], normal[3];
  sp_division_plane(&obs, 2, point, normal);
  const double px = point[0], py = point[1], nx = normal[0], ny = normal[1], on_line = SP_DIVISION_ON_LINE_FRACTION * mesh->h;
  const double width = sp_scene_interface_width(scene);
  for (int i = 0; i < nn; ++i)
    sd[i] = nx * (mesh->xy[2 * i] - px) + ny * (mesh->xy[2 * i + 1] - py);
  double m0[2] = {0, 0};
  for (int s = 0; s < 2; ++s)
    for (int i = 0; i < nn; ++i)
      m0[s] += w[i] * parent[2 * i] * sp_division_child_share(sd[i], s, width, on_line);
  printf("%s, %s: parent = cells %d + %d, mass %.8f, centre (%.4e, %.4e), axis angle %.8f "
         "(pi/2 %+.3e), mesh h %.4g; child mass at the line: sharp %.8f, smooth %.8f\n",
         argv[1], argv[2], a + 1, b + 1, obs.mass, px, py, sp_cells_obs_angle(&obs, 2), sp_cells_obs_angle(&obs, 2) - M_PI / 2,
         mesh->h, m0[0], m0[1]);
  printf("\n| offset s | nodes within s of the line (c >= 1/2) | sharp: M(s) - M(0) | relative "
         "| M(-s) - M(0) | smooth: M(s) - M(0) | relative |\n|---|---|---|---|---|---|---|\n");
  for (double s = 1e-8; s < 1.5e-3; s *= sqrt(10.0)) {
    double m[3] = {0, 0, 0};
    int near = 0;
    for (int i = 0; i < nn; ++i) {
      const double wc = w[i] * parent[2 * i];
      m[0] += wc * sp_division_child_share(sd[i] - s, 0, width, on_line);
      m[1] += wc * sp_division_child_share(sd[i] + s, 0, width, on_line);
      m[2] += wc * sp_division_child_share(sd[i] - s, 1, width, on_line);
      near += fabs(sd[i]) <= s && parent[2 * i] >= 0.5;
    }
    printf("| %.1e | %d | %+.3e | %.1e | %+.3e | %+.3e | %.1e |\n", s, near, m[0] - m0[0],
           fabs(m[0] - m0[0]) / m0[0], m[1] - m0[0], m[2] - m0[1], fabs(m[2] - m0[1]) / m0[1]);
  }
  free(text);
  free(state);
  free(parent);
  free(w);
  free(sd);
  sp_layout_destroy(&all);
  sp_layout_destroy(&one);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  return 0;
}
