/* bench_contact_levels: the contacts of a state by the overlap measure and
 * by the isosurface measure at several levels (docs/model.md, "Contacts"),
 * and the time per call of each.
 *
 *   build/bench/bench_contact_levels SCENE.yaml FIELDS.vtu [LEVEL...]
 *       a run's fields_<step>.vtu (one process) on SCENE's mesh: per
 *       measure, each pair's contact as a fraction of the smaller of the
 *       two cells' surfaces (cells numbered as in contacts.csv) and the
 *       pairs in contact at output.contact_threshold 0.01;
 *   build/bench/bench_contact_levels box N
 *       eight balls of radius 0.24 (d = 0.02) at the centres of the eight
 *       octants of an N^3 box of the unit cube, every cell on every node:
 *       the time per call of each measure.
 * LEVELs default to 0.01 0.02 0.05 0.1 0.25. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "io/vtu_read.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "model/cells.h"
#include "model/contacts.h"
#include "run/run_options.h"
#include "scene/scene.h"

static double seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/** One measure's contacts: the pairs' fractions, the count in contact, the
 *  time per call (mean of @p repeat). */
static void report(const sp_mesh *m, const sp_layout *layout, const double *state,
                   sp_contacts_measure how, double level, int repeat, int print_pairs) {
  sp_contacts c = {0};
  const double t0 = seconds();
  for (int r = 0; r < repeat; ++r)
    if (sp_contacts_integrate(m, layout, state, 0, m->n_nodes, how, level, &c) != 0) {
      fprintf(stderr, "bench_contact_levels: %s\n", "sp_contacts_integrate failed");
      exit(1);
    }
  const double per_call = (seconds() - t0) / repeat;
  int touching = 0;
  if (how == SP_CONTACTS_OVERLAP) printf("overlap           ");
  else printf("isosurface %-6g ", level);
  for (int k = 0; k < c.n_cells; ++k)
    for (int l = k + 1; l < c.n_cells; ++l) {
      touching += sp_contacts_touch(&c, k, l, 0.01);
      const double s = fmin(c.surface[k], c.surface[l]);
      if (print_pairs)
        printf(" %d-%d %.2f", k + 1, l + 1, s > 0 ? c.overlap[sp_contacts_pair(c.n_cells, k, l)] / s : 0.0);
    }
  printf("  | %d of %d pairs in contact, %.3g s per call\n", touching,
         c.n_cells * (c.n_cells - 1) / 2, per_call);
  sp_contacts_clear(&c);
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: bench_contact_levels SCENE.yaml FIELDS.vtu [LEVEL...] | box N\n");
    return 2;
  }
  double levels[32] = {0.01, 0.02, 0.05, 0.1, 0.25};
  int n_levels = 5;
  sp_mesh *m = NULL;
  sp_layout *layout = NULL;
  double *state = NULL;
  int print_pairs = 1, repeat = 1;
  if (strcmp(argv[1], "box") == 0) {
    const int n = atoi(argv[2]), cells = 8;
    if (n < 2 || sp_mesh_box(0, 0, 0, 1, 1, 1, n, n, n, &m) != 0 ||
        sp_layout_create_full(m->n_nodes, cells, &layout) != 0)
      return 2;
    state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
    for (int k = 0; k < cells; ++k)
      for (int i = 0; i < m->n_nodes; ++i) {
        double r2 = 0;
        for (int d = 0; d < 3; ++d) {
          const double centre = 0.25 + 0.5 * ((k >> d) & 1);
          r2 += (m->xy[3 * i + d] - centre) * (m->xy[3 * i + d] - centre);
        }
        state[2 * sp_layout_pair(layout, k, i)] = sp_cells_profile(sqrt(r2) - 0.24, 0.02);
      }
    print_pairs = 0;
    repeat = 3;
  } else {
    sp_scene *scene = NULL;
    sp_vtu_fields v = {0};
    if (sp_scene_load(argv[1], 0, NULL, &scene) != 0 || sp_mesh_from_scene(scene, &m) != 0 ||
        sp_vtu_read(argv[2], &v) != 0 || v.n_points != m->n_nodes ||
        sp_layout_create_full(m->n_nodes, v.n_cells, &layout) != 0) {
      fprintf(stderr, "bench_contact_levels: cannot read %s on %s's mesh\n", argv[2], argv[1]);
      return 2;
    }
    state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
    /* the run numbers its nodes its own way: match each point to the
     * mesh's node at the same place */
    for (int i = 0; i < v.n_points; ++i) {
      int node = 0;
      double best = INFINITY;
      for (int j = 0; j < m->n_nodes; ++j) {
        double dist = 0;
        for (int d = 0; d < m->dim; ++d)
          dist += (v.xyz[3 * i + d] - m->xy[m->dim * j + d]) * (v.xyz[3 * i + d] - m->xy[m->dim * j + d]);
        if (dist < best) {
          best = dist;
          node = j;
        }
      }
      for (int k = 0; k < v.n_cells; ++k)
        state[2 * sp_layout_pair(layout, k, node)] = v.c[(size_t)k * v.n_points + i];
    }
    if (argc > 3) {
      n_levels = 0;
      for (int a = 3; a < argc && n_levels < 32; ++a) levels[n_levels++] = atof(argv[a]);
    }
    sp_vtu_fields_free(&v);
    sp_scene_destroy(&scene);
  }
  report(m, layout, state, SP_CONTACTS_OVERLAP, 0, repeat, print_pairs);
  for (int j = 0; j < n_levels; ++j)
    if (levels[j] > 0 && levels[j] <= 0.5)
      report(m, layout, state, SP_CONTACTS_ISOSURFACE, levels[j], repeat, print_pairs);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&m);
  return 0;
}
