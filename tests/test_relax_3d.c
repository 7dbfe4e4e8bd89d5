/* Relaxation in 3D (phase 1), through the run as `softpack run`
 * makes it (scene, box of hexahedra, spheres, RCB, MUMPS, backward Euler,
 * s = 0, no division, no shape term):
 *  - tests/scenes/sphere_3d.yaml (one sphere), two_spheres_3d.yaml (two
 *    touching spheres) and two_spheres_ellipsoid.yaml (two touching spheres
 *    in an ellipsoid with a buffer shell, mesh.type ellipsoid): every
 *    cell's mass is conserved to 1e-12 relative
 *    at every step (cells.csv, %.17g), and the energy (the pair term over
 *    k < l) never rises (1e-13 relative, as test_energy.c) and falls;
 *  - the 3D observables at t = 0: the volume inside the membrane is the
 *    sphere's 4/3 pi r^3 (within 6%: the level set counted at
 *    the Gauss points of elements of 0.36 r in the box, up to 0.6 r in the
 *    ellipsoid) and the centre its (x, y, z) (within 1e-3);
 *  - what a 3D run writes: energy.csv, cells.csv with the z centre
 *    (step,t,cell,mass,xc,yc,zc,I1,I2,I3,long_x,long_y,long_z,core_mass,
 *    volume), energy.png, no 2D cells_<step>.png (3D pictures are
 *    test_render_3d's; these scenes turn them off), and the VTU
 *    fields of hexahedra (check_vtu: counts, VTK type 12, the mesh's points
 *    with z and connectivity, VTK's node order), on the box and on the
 *    ellipsoid. */
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "mesh/partition.h"
#include "run/run_options.h"
#include "scene/scene.h"
#include "run/stepper.h"

enum { MAX_CELLS = 4 };

static int exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0;
}

/** The .vtu of step 0 (the hexahedra of the scene's mesh, as VTK reads
 *  them): its header counts, every cell of VTK type 12 with offsets 8, 16,
 *  ..., the points with their z and the connectivity of the first and last
 *  elements as the mesh's (renumbered as the run does), and every hexahedron in VTK's node order: the
 *  bottom face 0-1-2-3 counterclockwise seen from the top face, whose
 *  nodes 4-7 lie above 0-3 in order (the triple products at nodes 0 and 6,
 *  computed from the points alone, are positive). */
static void check_vtu(const sp_scene *scene, const char *out) {
  sp_mesh *mesh; /* numbered as the run numbers it: in RCB order (run_setup.c) */
  CHECK_OK(sp_mesh_from_scene(scene, &mesh));
  int *order = malloc(sizeof(int) * (size_t)mesh->n_nodes);
  CHECK_OK(sp_partition_rcb_order(mesh, order));
  CHECK_OK(sp_partition_renumber(mesh, order));
  free(order);
  char path[512];
  snprintf(path, sizeof path, "%s/fields_000000.vtu", out);
  char *xml = slurp(path, NULL);
  CHECK(xml != NULL, "%s missing", path);
  if (!xml) {
    sp_mesh_destroy(&mesh);
    return;
  }
  int nn = -1, ne = -1;
  const char *piece = strstr(xml, "<Piece");
  CHECK(piece && sscanf(piece, "<Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\"", &nn, &ne) == 2,
        "%s: no Piece header", path);
  CHECK(nn == mesh->n_nodes && ne == mesh->n_elems, "%s: %d points, %d cells; the mesh has %d "
        "nodes, %d elements", path, nn, ne, mesh->n_nodes, mesh->n_elems);
  size_t bp = 0, bc = 0, bo = 0, bt = 0;
  double *pts = (double *)vtu_array_data(xml, "Points", &bp);
  int32_t *conn = (int32_t *)vtu_array_data(xml, "connectivity", &bc);
  int64_t *offsets = (int64_t *)vtu_array_data(xml, "offsets", &bo);
  unsigned char *types = vtu_array_data(xml, "types", &bt);
  const size_t n_nodes = (size_t)mesh->n_nodes, n_elems = (size_t)mesh->n_elems;
  const int sizes_ok = pts && conn && offsets && types && bp == 3 * n_nodes * sizeof(double) &&
                       bc == 8 * n_elems * sizeof(int32_t) && bo == n_elems * sizeof(int64_t) &&
                       bt == n_elems;
  CHECK(sizes_ok, "%s: array sizes %zu %zu %zu %zu", path, bp, bc, bo, bt);
  if (sizes_ok) {
    int wrong_type = 0, wrong_offset = 0, wrong_point = 0, inverted = 0;
    for (size_t e = 0; e < n_elems; ++e) {
      wrong_type += types[e] != 12;
      wrong_offset += offsets[e] != 8 * ((int64_t)e + 1);
    }
    for (size_t i = 0; i < 3 * n_nodes; ++i) wrong_point += pts[i] != mesh->xy[i];
    for (size_t e = 0; e < n_elems; e += n_elems - 1) {
      for (int a = 0; a < 8; ++a)
        CHECK(conn[8 * e + a] == mesh->elem[8 * e + a], "%s: cell %zu node %d: %d, mesh %d",
              path, e, a, conn[8 * e + a], mesh->elem[8 * e + a]);
      if (n_elems == 1) break;
    }
    for (size_t e = 0; e < n_elems; ++e) {
      const double *p[8];
      for (int a = 0; a < 8; ++a) p[a] = pts + 3 * (size_t)conn[8 * e + a];
      /* at node 0: (p1 - p0) x (p3 - p0) . (p4 - p0); at node 6, the top
       * face's corner opposite: (p7 - p6) x (p5 - p6) . (p6 - p2) */
      const int corner[2][4] = {{0, 1, 3, 4}, {6, 7, 5, 2}};
      for (int c = 0; c < 2; ++c) {
        const double *o = p[corner[c][0]], *u = p[corner[c][1]], *v = p[corner[c][2]];
        const double *w = p[corner[c][3]];
        double du[3], dv[3], dw[3];
        for (int d = 0; d < 3; ++d) {
          du[d] = u[d] - o[d];
          dv[d] = v[d] - o[d];
          dw[d] = c == 0 ? w[d] - o[d] : o[d] - w[d];
        }
        const double triple = (du[1] * dv[2] - du[2] * dv[1]) * dw[0] +
                              (du[2] * dv[0] - du[0] * dv[2]) * dw[1] +
                              (du[0] * dv[1] - du[1] * dv[0]) * dw[2];
        inverted += !(triple > 0);
      }
    }
    printf("%s: %d points, %d hexahedra; %d wrong types, %d wrong offsets, %d points not the "
           "mesh's, %d corners not in VTK's order\n",
           path, nn, ne, wrong_type, wrong_offset, wrong_point, inverted);
    CHECK(wrong_type == 0 && wrong_offset == 0, "%s: %d cell types not 12, %d offsets wrong",
          path, wrong_type, wrong_offset);
    CHECK(wrong_point == 0, "%s: %d point coordinates differ from the mesh's", path,
          wrong_point);
    CHECK(inverted == 0, "%s: %d hexahedron corners with a non-positive triple product", path,
          inverted);
  }
  free(pts);
  free(conn);
  free(offsets);
  free(types);
  free(xml);
  sp_mesh_destroy(&mesh);
}

static void relax(const char *scene_file, const char *out, int expect_cells) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load(scene_file, 0, NULL, &scene));
  CHECK(scene->n_cells == expect_cells, "%s: %d cells", scene_file, scene->n_cells);
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  const int steps = scene->time.max_steps;
  CHECK(sum.steps == steps, "%s: %d steps of %d", scene_file, sum.steps, steps);

  /* energy.csv: never rises, falls overall */
  char path[512], line[2048];
  snprintf(path, sizeof path, "%s/energy.csv", out);
  const energy_trend tr = energy_trend_read(path);

  /* cells.csv: the 3D header; each cell's mass per step */
  snprintf(path, sizeof path, "%s/cells.csv", out);
  FILE *f = fopen(path, "r");
  CHECK(f != NULL, "%s missing", path);
  CHECK(fgets(line, sizeof line, f) &&
            strcmp(line, "step,t,cell,mass,xc,yc,zc,I1,I2,I3,long_x,long_y,long_z,core_mass,"
                         "volume\n") == 0,
        "cells.csv header: %s", line);
  double last_mass[MAX_CELLS], worst_mass = 0;
  int cell_rows = 0;
  while (fgets(line, sizeof line, f)) {
    int step, k;
    double t, mass, xc, yc, zc, moment[3], axis[3], core, volume;
    CHECK(sscanf(line, "%d,%lf,%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &step, &t, &k,
                 &mass, &xc, &yc, &zc, &moment[0], &moment[1], &moment[2], &axis[0], &axis[1],
                 &axis[2], &core, &volume) == 15,
          "cells row %s", line);
    CHECK(k >= 1 && k <= expect_cells, "cell %d", k);
    if (step == 0) {
      const sp_scene_cell *c = &scene->cells[k - 1];
      const double sphere = 4.0 / 3.0 * M_PI * c->radius * c->radius * c->radius;
      printf("%s: cell %d at t = 0: volume %.6g (sphere %.6g), centre (%.4f, %.4f, %.4f) "
             "(given (%.4f, %.4f, %.4f))\n",
             scene_file, k, volume, sphere, xc, yc, zc, c->x, c->y, c->z);
      CHECK(fabs(volume - sphere) < 0.06 * sphere, "cell %d: volume %g, sphere %g", k, volume,
            sphere);
      CHECK(fabs(xc - c->x) < 1e-3 && fabs(yc - c->y) < 1e-3 && fabs(zc - c->z) < 1e-3,
            "cell %d: centre (%g, %g, %g), given (%g, %g, %g)", k, xc, yc, zc, c->x, c->y, c->z);
    } else {
      const double rel = fabs(mass - last_mass[k - 1]) / last_mass[k - 1];
      worst_mass = fmax(worst_mass, rel);
      CHECK(rel <= 1e-12, "step %d cell %d: mass %.17g -> %.17g (relative %.3g)", step, k,
            last_mass[k - 1], mass, rel);
    }
    last_mass[k - 1] = mass;
    ++cell_rows;
  }
  fclose(f);
  printf("%s: %d steps, energy %.10g -> %.10g, %d rises (largest %.3g); largest relative mass "
         "change per step %.3g\n",
         scene_file, tr.rows - 1, tr.first, tr.last, tr.rises, tr.worst_rise, worst_mass);
  CHECK(tr.rows == steps + 1, "%d energy rows", tr.rows);
  CHECK(cell_rows == (steps + 1) * expect_cells, "%d cells rows", cell_rows);
  CHECK(tr.rises == 0, "the energy rose %d times (largest rise %.3g)", tr.rises, tr.worst_rise);
  CHECK(tr.last < tr.first, "the energy did not decrease: %g -> %g", tr.first, tr.last);

  /* what is written in 3D */
  snprintf(path, sizeof path, "%s/energy.png", out);
  CHECK(exists(path), "%s missing", path);
  check_vtu(scene, out);
  snprintf(path, sizeof path, "%s/cells_000000.png", out);
  CHECK(!exists(path), "%s written on a 3D mesh", path);
  sp_scene_destroy(&scene);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  relax(SP_SOURCE_DIR "/tests/scenes/sphere_3d.yaml", "test_relax_3d_one", 1);
  relax(SP_SOURCE_DIR "/tests/scenes/two_spheres_3d.yaml", "test_relax_3d_two", 2);
  relax(SP_SOURCE_DIR "/tests/scenes/two_spheres_ellipsoid.yaml", "test_relax_3d_ellipsoid", 2);
  MPI_Finalize();
  TEST_DONE();
}
