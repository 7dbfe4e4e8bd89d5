/* The coverslip (sp_mesh_flatten, mesh.flatten): the ellipse (ellipsoid)
 * mesh cut by the planes |y| <= h in 2D, |z| <= h in 3D, no time stepping:
 * - Omega's measure converges to the exact cut ellipse's (ellipsoid's),
 *   2ab (u sqrt(1 - u^2) + asin u) with u = h/b and pi a b (2h - 2h^3/3c^2),
 *   at second order, as the uncut mesh's does (docs/3d.md): the
 *   least-squares slope of log(error) against r log 2 over the refinements
 *   is at least 1.8 (the order between two meshes oscillates, 1.7 to 2.4
 *   in 2D, as the rim, where an element's face cuts the corner between
 *   the plane and the ellipse, moves across the elements), and the error
 *   of the finest is below twice the uncut mesh's at that refinement;
 * - det J > 0 at every Gauss point of every element (Omega and the buffer;
 *   the map keeps each column's order);
 * - every node of Omega within the planes (|x_last| <= h (1 + 1e-14)),
 *   Omega's boundary nodes on the planes or on the ellipse(oid);
 * - the buffer is the shell between the cut shape and its (1 + w)-scaled
 *   copy: its measure is ((1 + w)^dim - 1) x Omega's to 1e-12 relative;
 * - sp_mesh_contains sees the planes; a bad h is refused. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "public/error.h"
#include "mesh/mesh.h"
#include "mesh/q1.h"

static int make(int dim, int r, const double semi[3], int layers, double w, sp_mesh **mesh) {
  return dim == 3 ? sp_mesh_ellipsoid(r, semi[0], semi[1], semi[2], layers, w, mesh)
                  : sp_mesh_ellipse(r, semi[0], semi[1], layers, w, mesh);
}

/** Gauss points with det J <= 0 in @p mesh. */
static int inverted(const sp_mesh *mesh) {
  int bad = 0;
  for (int e = 0; e < mesh->n_elems; ++e) {
    double xe[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], N[SP_Q1_MAX_NODES],
        dN[SP_Q1_MAX_NODES][SP_Q1_MAX_DIM], x[SP_Q1_MAX_DIM], w;
    sp_mesh_elem_xy(mesh, e, xe);
    for (int q = 0; q < sp_q1_qpoints(mesh->dim); ++q)
      bad += !(sp_q1_point(mesh->dim, xe, q, N, dN, x, &w) > 0);
  }
  return bad;
}

/** The largest |x_last| / h over the nodes of Omega's elements. */
static double reach(const sp_mesh *mesh, double h) {
  double worst = 0;
  const int nen = mesh->nodes_per_elem, last = mesh->dim - 1;
  for (int e = 0; e < mesh->n_elems; ++e) {
    if (mesh->region[e] != SP_REGION_OMEGA) continue;
    for (int a = 0; a < nen; ++a) {
      const double *x = mesh->xy + (size_t)mesh->dim * mesh->elem[(size_t)nen * e + a];
      worst = fmax(worst, fabs(x[last]) / h);
    }
  }
  return worst;
}

static void test_cut(int dim, int r_lo, int r_hi, const double semi[3], double h) {
  const double exact = sp_mesh_flattened_measure(dim, semi, h);
  const double w = 0.1;
  double err_prev = NAN, sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  printf("%dD, semi-axes (%g, %g%s%.3g), cut at %g: exact measure %.15f\n", dim, semi[0],
         semi[1], dim == 3 ? ", " : "", dim == 3 ? semi[2] : 0.0, h, exact);
  printf("   r  elements  measure            error      order  uncut error  det J <= 0\n");
  for (int r = r_lo; r <= r_hi; ++r) {
    sp_mesh *mesh, *uncut;
    CHECK_OK(make(dim, r, semi, 2, w, &mesh));
    CHECK_OK(make(dim, r, semi, 2, w, &uncut));
    CHECK_OK(sp_mesh_flatten(mesh, h));
    const double full = dim == 3 ? 4.0 / 3.0 * acos(-1.0) * semi[0] * semi[1] * semi[2]
                                 : acos(-1.0) * semi[0] * semi[1];
    const double omega = sp_mesh_region_area(mesh, SP_REGION_OMEGA);
    const double buffer = sp_mesh_region_area(mesh, SP_REGION_BUFFER);
    const double err = fabs(omega - exact) / exact;
    const double err_uncut = fabs(sp_mesh_region_area(uncut, SP_REGION_OMEGA) - full) / full;
    const double order = log(err_prev / err) / log(2.0);
    const int bad = inverted(mesh);
    printf("  %2d  %8d  %.15f  %.3e  %5.3f  %.3e    %d\n", r, mesh->n_elems, omega, err, order,
           err_uncut, bad);
    CHECK(bad == 0, "%dD r = %d: det J <= 0 at %d Gauss points", dim, r, bad);
    CHECK(reach(mesh, h) <= 1 + 1e-14, "%dD r = %d: a node of Omega at %.17g h", dim, r,
          reach(mesh, h));
    const double shell = pow(1 + w, dim) - 1;
    CHECK(fabs(buffer - shell * omega) <= 1e-12 * shell * omega,
          "%dD r = %d: buffer %.17g, ((1 + w)^dim - 1) Omega = %.17g", dim, r, buffer,
          shell * omega);
    const double lx = r * log(2.0), ly = -log(err);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, ++n;
    if (r == r_hi) {
      const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
      printf("  least-squares order over r = %d..%d: %.3f\n", r_lo, r_hi, slope);
      CHECK(slope >= 1.8, "%dD: order %.3f over r = %d..%d", dim, slope, r_lo, r_hi);
      CHECK(err <= 2 * err_uncut, "%dD r = %d: error %.3e, uncut %.3e", dim, r, err, err_uncut);
    }
    /* the planes in sp_mesh_contains */
    const double in[3] = {0, 0, 0}, above[3] = {0, dim == 2 ? 1.01 * h : 0, 1.01 * h};
    CHECK(sp_mesh_contains(mesh, in) && !sp_mesh_contains(mesh, above) &&
              sp_mesh_contains(uncut, above),
          "%dD: sp_mesh_contains does not see the planes", dim);
    err_prev = err;
    sp_mesh_destroy(&mesh);
    sp_mesh_destroy(&uncut);
  }
}

/* Every node of the mesh without a buffer inside the ellipse(oid) and
 * within the planes, some on them. */
static void test_inside(int dim, const double semi[3], double h) {
  sp_mesh *mesh;
  CHECK_OK(make(dim, 3, semi, 0, 0.1, &mesh));
  CHECK_OK(sp_mesh_flatten(mesh, h));
  int outside = 0, on_plane = 0;
  for (int i = 0; i < mesh->n_nodes; ++i) {
    const double *x = mesh->xy + (size_t)dim * i;
    double level = 0;
    for (int d = 0; d < dim; ++d) level += (x[d] / semi[d]) * (x[d] / semi[d]);
    outside += level > 1 + 1e-12 || fabs(x[dim - 1]) > h * (1 + 1e-14);
    on_plane += fabs(fabs(x[dim - 1]) - h) <= 1e-14 * h;
  }
  printf("%dD r = 3 without a buffer: %d nodes outside the cut shape, %d on the planes\n", dim,
         outside, on_plane);
  CHECK(outside == 0, "%dD: %d nodes outside the cut shape", dim, outside);
  CHECK(on_plane > 0, "%dD: no node on the planes", dim);
  sp_mesh_destroy(&mesh);
}

static void test_refused(void) {
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_ellipsoid(2, 0.5, 0.3, 0.3, 0, 0.1, &mesh));
  CHECK(sp_mesh_flatten(mesh, 0.3) == SP_ERR_INPUT, "h = the semi-axis accepted");
  CHECK(sp_mesh_flatten(mesh, 0.0) == SP_ERR_INPUT, "h = 0 accepted");
  sp_mesh_destroy(&mesh);
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 4, 4, &mesh));
  CHECK(sp_mesh_flatten(mesh, 0.3) == SP_ERR_INPUT, "a rectangle flattened");
  sp_mesh_destroy(&mesh);
}

int main(void) {
  /* the C. elegans egg (50 x 30 x 30 um as 0.5 x 0.3 x 0.3) under a
   * coverslip 40 um apart, and its 2D section cut at |y| <= 0.2 */
  const double egg[3] = {0.5, 0.3, 0.3};
  test_cut(2, 3, 7, egg, 0.2);
  test_cut(3, 2, 5, egg, 0.2);
  test_inside(2, egg, 0.2);
  test_inside(3, egg, 0.2);
  test_refused();
  TEST_DONE();
}
