/* The 3x3 inertia tensor of a cell on a 3D mesh (src/model/cells.c
 * phase 2; docs/3d.md):
 *  - the eigensolver (sp_cells_principal): a tensor R diag(3, 2, 1) R^T
 *    gives back 3, 2, 1 (1e-14 relative) and the rotated axes (1e-14);
 *    two and three equal moments give an orthonormal basis, no NaN;
 *  - an extrusion of a 2D ellipse (c independent of z on a slab) has the
 *    2D tensor's axes and moments: 3D v3 = 2D v2 (the long axis, with its
 *    sign), v2 = 2D v1 (1e-12), and its moments are the 2D ones times the
 *    slab's thickness plus int c Xb3^2 (1e-12 relative);
 *  - a triaxial tanh ellipsoid (semi-axes 0.15, 0.09, 0.06), aligned with x
 *    and turned to a generic orientation: v3 is its long axis, v1 its short
 *    one (1e-3 rad, as the 2D axis test), the centre its centre;
 *  - a sphere centred on a cube of the mesh's symmetry: three equal moments
 *    (1e-12 relative) and orthonormal axes;
 *  - the same ellipsoid rotated by 90 degrees about z on a box with that
 *    symmetry: the rotated centre (1e-14), the same moments (1e-12
 *    relative) and the rotated axes (1e-11 rad: round-off over the
 *    moments' relative gaps, ~0.1);
 *  - a scene's ellipsoidal cell (cells[0].semi_x, semi_z): the initial
 *    membrane encloses 4/3 pi a b c (within 3%), its long and short axes
 *    are x and z (1e-3 rad); in 2D an ellipse (semi_x) encloses pi a b
 *    (3%) with its long axis x;
 *  - the same cell turned (cells[0].axis_x, axis_y, axis_z = (1, 2, 2)):
 *    the same volume (3%), its long axis (v3, cells.csv's long_x, _y,
 *    _z) the given direction and its short one the turned z (1e-3 rad,
 *    the unturned cell's tolerance), and the turn takes x onto it by the
 *    smallest rotation; turned onto y (axis (0, 1, 0)) the field is the
 *    one of semi_y = 0.16 to round-off (1e-15); a zero axis and axis_z
 *    in 2D are refused naming the key. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "public/error.h"
#include "fixtures.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "scene/scene.h"

/** Centre and inertia integrate c >= this, as the stepper does. */
#define WEIGHT_THRESHOLD 0.05

/** The interface width of the paper's parameters, sqrt(1e-3 / 8). */
static double interface_width(void) { return sqrt(1e-3 / 8.0); }

/** |v_i . v_j - delta_ij| over the three eigenvectors of @p o. */
static double orthonormality(const sp_cell_obs *o) {
  const double *v[3] = {o->axes[0], o->axes[1], o->axes[2]};
  double worst = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) worst = fmax(worst, fabs(dot3(v[i], v[j]) - (i == j)));
  return worst;
}

static void test_eigensolver(void) {
  double axes[3][3];
  rotated_axes(0.7, 1.1, -0.4, axes);
  const double diag[3][3] = {{3, 0, 0}, {0, 2, 0}, {0, 0, 1}};
  double tensor[3][3] = {{0}};
  for (int i = 0; i < 3; ++i) /* sum_j lambda_j a_j a_j^T */
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) tensor[i][k] += diag[j][j] * axes[j][i] * axes[j][k];
  double moments[3], v[3][3];
  sp_cells_principal(3, tensor, moments, v);
  for (int j = 0; j < 3; ++j) {
    CHECK(fabs(moments[j] - diag[j][j]) <= 1e-14 * 3, "moment %d: %.17g, expected %g", j,
          moments[j], diag[j][j]);
    CHECK(line_angle3(v[j], axes[j]) <= 1e-14, "eigenvector %d off by %.3g rad", j,
          line_angle3(v[j], axes[j]));
  }
  /* two equal moments, then three: a basis, no NaN, exact moments */
  const double cases[2][3] = {{2, 2, 1}, {1.5, 1.5, 1.5}};
  for (int c = 0; c < 2; ++c) {
    double t[3][3] = {{0}};
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j) t[i][k] += cases[c][j] * axes[j][i] * axes[j][k];
    sp_cells_principal(3, t, moments, v);
    sp_cell_obs o;
    for (int d = 0; d < 3; ++d) {
      o.axes[0][d] = v[0][d];
      o.axes[1][d] = v[1][d];
      o.axes[2][d] = v[2][d];
    }
    const double ortho = orthonormality(&o);
    printf("moments %g %g %g: got %.17g %.17g %.17g, orthonormal to %.2g\n", cases[c][0],
           cases[c][1], cases[c][2], moments[0], moments[1], moments[2], ortho);
    CHECK(ortho <= 1e-14, "degenerate case %d: v_i . v_j off by %.3g", c, ortho);
    for (int j = 0; j < 3; ++j)
      CHECK(fabs(moments[j] - cases[c][j]) <= 1e-14 * 3, "degenerate case %d: moment %d = %.17g",
            c, j, moments[j]);
    if (c == 0) /* the single moment's axis is still determined */
      CHECK(line_angle3(v[2], axes[2]) <= 1e-14, "the distinct axis off by %.3g rad",
            line_angle3(v[2], axes[2]));
  }
}

/* A 2D ellipse extruded along z on a slab has the 2D tensor's axes. */
static void test_extrusion(void) {
  const double L = 0.05, x0 = 0.5031, y0 = 0.4957, a = 0.12, b = 0.06, phi = 0.4;
  sp_mesh *plane, *slab;
  sp_layout *layout2, *layout3;
  CHECK_OK(sp_mesh_rectangle(0, 0, 1, 1, 100, 100, &plane));
  CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, L, 100, 100, 2, &slab));
  CHECK_OK(sp_layout_create_full(plane->n_nodes, 1, &layout2));
  CHECK_OK(sp_layout_create_full(slab->n_nodes, 1, &layout3));
  double *state2 = calloc(2 * (size_t)layout2->n_pairs, sizeof(double));
  double *state3 = calloc(2 * (size_t)layout3->n_pairs, sizeof(double));
  const double eps = interface_width() / b;
  set_ellipse(plane, layout2, state2, 0, x0, y0, a, b, phi, eps);
  /* the same nodal values in every z layer (nodes x fastest, then y, then z) */
  for (int i = 0; i < slab->n_nodes; ++i) state3[2 * i] = state2[2 * (i % plane->n_nodes)];
  sp_cell_obs o2, o3;
  CHECK_OK(sp_cells_observe(plane, layout2, state2, WEIGHT_THRESHOLD, &o2));
  CHECK_OK(sp_cells_observe(slab, layout3, state3, WEIGHT_THRESHOLD, &o3));
  /* int c Xb3^2 from the 3D tensor: Ixx + Iyy - Izz = 2 int c Xb3^2 */
  const double szz = 0.5 * (o3.inertia[0][0] + o3.inertia[1][1] - o3.inertia[2][2]);
  const double long2[3] = {o2.axes[1][0], o2.axes[1][1], 0.0}, short2[3] = {o2.axes[0][0], o2.axes[0][1], 0.0};
  printf("extruded ellipse: 2D I1 %.10g I2 %.10g; 3D (I - int c z^2) / L: %.10g %.10g, Izz / L "
         "%.10g; long axis 2D (%.6f, %.6f), 3D (%.6f, %.6f, %.2g)\n",
         o2.moments[0], o2.moments[1], (o3.moments[1] - szz) / L, (o3.moments[2] - szz) / L, o3.moments[0] / L, o2.axes[1][0], o2.axes[1][1],
         o3.axes[2][0], o3.axes[2][1], o3.axes[2][2]);
  CHECK(fabs((o3.moments[1] - szz) / L - o2.moments[0]) <= 1e-12 * o2.moments[0], "I2 - int c z^2 = %.17g L, 2D I1 %.17g",
        (o3.moments[1] - szz) / L, o2.moments[0]);
  CHECK(fabs((o3.moments[2] - szz) / L - o2.moments[1]) <= 1e-12 * o2.moments[0], "I3 - int c z^2 = %.17g L, 2D I2 %.17g",
        (o3.moments[2] - szz) / L, o2.moments[1]);
  CHECK(fabs(o3.moments[0] / L - (o2.moments[0] + o2.moments[1])) <= 1e-12 * o2.moments[0], "Izz = %.17g L, 2D trace %.17g",
        o3.moments[0] / L, o2.moments[0] + o2.moments[1]);
  /* the long axis with its sign (the division's side rule), and v2 the 2D v1 */
  double worst = 0;
  for (int d = 0; d < 3; ++d) worst = fmax(worst, fabs(o3.axes[2][d] - long2[d]));
  CHECK(worst <= 1e-12, "3D long axis (%.17g, %.17g, %.17g), 2D v2 (%.17g, %.17g)", o3.axes[2][0],
        o3.axes[2][1], o3.axes[2][2], o2.axes[1][0], o2.axes[1][1]);
  CHECK(line_angle3(o3.axes[1], short2) <= 1e-12, "3D v2 off the 2D v1 by %.3g rad",
        line_angle3(o3.axes[1], short2));
  CHECK(fabs(o3.axes[0][2]) >= 1 - 1e-12, "3D v1 = (%g, %g, %g), not z", o3.axes[0][0], o3.axes[0][1], o3.axes[0][2]);
  CHECK(fabs(o3.centre[0] - o2.centre[0]) <= 1e-13 && fabs(o3.centre[1] - o2.centre[1]) <= 1e-13 &&
            fabs(o3.centre[2] - 0.5 * L) <= 1e-13,
        "centre (%.17g, %.17g, %.17g), 2D (%.17g, %.17g)", o3.centre[0], o3.centre[1], o3.centre[2], o2.centre[0], o2.centre[1]);
  CHECK(o2.axes[0][2] == 0.0 && o2.axes[1][2] == 0.0 && o2.moments[2] == 0.0, "2D: z parts not zero");
  free(state2);
  free(state3);
  sp_layout_destroy(&layout2);
  sp_layout_destroy(&layout3);
  sp_mesh_destroy(&plane);
  sp_mesh_destroy(&slab);
}

/* A triaxial ellipsoid's principal axes at two orientations. */
static void test_ellipsoid_axes(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.5, 0.5, 0.5, 48, 48, 48, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  const double centre[3] = {0.2517, 0.2483, 0.2509}, semi[3] = {0.15, 0.09, 0.06};
  const double turns[2][3] = {{0, 0, 0}, {0.5, 0.9, 0.3}};
  for (int j = 0; j < 2; ++j) {
    double axes[3][3];
    rotated_axes(turns[j][0], turns[j][1], turns[j][2], axes);
    set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, interface_width() / semi[2]);
    sp_cell_obs o;
    CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &o));
    const double long_error = line_angle3(o.axes[2], axes[0]), short_error = line_angle3(o.axes[0], axes[2]);
    const double centre_error =
        sqrt((o.centre[0] - centre[0]) * (o.centre[0] - centre[0]) + (o.centre[1] - centre[1]) * (o.centre[1] - centre[1]) +
             (o.centre[2] - centre[2]) * (o.centre[2] - centre[2]));
    printf("ellipsoid 0.15 x 0.09 x 0.06, turned (%g, %g, %g): I1 %.6g I2 %.6g I3 %.6g; long "
           "axis off by %.2e rad, short by %.2e; centre off by %.2e\n",
           turns[j][0], turns[j][1], turns[j][2], o.moments[0], o.moments[1], o.moments[2], long_error, short_error,
           centre_error);
    CHECK(long_error < 1e-3, "turn %d: long axis off by %.3g rad", j, long_error);
    CHECK(short_error < 1e-3, "turn %d: short axis off by %.3g rad", j, short_error);
    CHECK(centre_error < 5e-5, "turn %d: centre off by %.3g", j, centre_error);
    CHECK(orthonormality(&o) <= 1e-14, "turn %d: axes orthonormal to %.3g", j, orthonormality(&o));
    /* the continuum's moments: I3 ~ b^2 + c^2, I2 ~ a^2 + c^2, I1 ~ a^2 + b^2 */
    CHECK(o.moments[0] > o.moments[1] && o.moments[1] > 1.5 * o.moments[2], "turn %d: moments %g %g %g", j, o.moments[0], o.moments[1], o.moments[2]);
  }
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/* A sphere centred on the mesh's cubic symmetry: three equal moments. */
static void test_sphere(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_box(-0.3, -0.3, -0.3, 0.3, 0.3, 0.3, 24, 24, 24, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  const double centre[3] = {0, 0, 0}, semi[3] = {0.15, 0.15, 0.15};
  double axes[3][3];
  rotated_axes(0, 0, 0, axes);
  set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, interface_width() / semi[0]);
  sp_cell_obs o;
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &o));
  const double spread = (o.moments[0] - o.moments[2]) / o.moments[0];
  printf("sphere: I1 %.17g I2 %.17g I3 %.17g (spread %.2g), long axis (%.6f, %.6f, %.6f), "
         "orthonormal to %.2g\n",
         o.moments[0], o.moments[1], o.moments[2], spread, o.axes[2][0], o.axes[2][1], o.axes[2][2], orthonormality(&o));
  CHECK(spread <= 1e-12, "sphere: moments %.17g %.17g %.17g", o.moments[0], o.moments[1], o.moments[2]);
  CHECK(orthonormality(&o) <= 1e-14, "sphere: axes orthonormal to %.3g", orthonormality(&o));
  CHECK(isfinite(o.axes[2][0]) && isfinite(o.axes[2][1]) && isfinite(o.axes[2][2]), "sphere: NaN axis");
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/* The scene turned by 90 degrees about z, (x, y, z) -> (-y, x, z), on a
 * box with that symmetry: the turned observables. */
static void test_rotation(void) {
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_box(-0.25, -0.25, 0, 0.25, 0.25, 0.3, 40, 40, 24, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  const double centre[3] = {0.0213, -0.0371, 0.1493}, semi[3] = {0.13, 0.08, 0.06};
  const double turned_centre[3] = {-centre[1], centre[0], centre[2]};
  double axes[3][3], turned[3][3];
  rotated_axes(0.5, 0.9, 0.3, axes);
  for (int j = 0; j < 3; ++j) { /* R_z(90) a = (-a_y, a_x, a_z) */
    turned[j][0] = -axes[j][1];
    turned[j][1] = axes[j][0];
    turned[j][2] = axes[j][2];
  }
  const double eps = interface_width() / semi[2];
  sp_cell_obs o, r;
  set_ellipsoid(mesh, layout, state, 0, centre, axes, semi, eps);
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &o));
  set_ellipsoid(mesh, layout, state, 0, turned_centre, turned, semi, eps);
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &r));
  const double centre_error = fmax(fabs(r.centre[0] + o.centre[1]), fmax(fabs(r.centre[1] - o.centre[0]), fabs(r.centre[2] - o.centre[2])));
  const double moment_error =
      fmax(fabs(r.moments[0] - o.moments[0]), fmax(fabs(r.moments[1] - o.moments[1]), fabs(r.moments[2] - o.moments[2]))) / o.moments[0];
  const double *vo[3] = {o.axes[0], o.axes[1], o.axes[2]}, *vr[3] = {r.axes[0], r.axes[1], r.axes[2]};
  double axis_error = 0;
  for (int j = 0; j < 3; ++j) {
    const double rotated[3] = {-vo[j][1], vo[j][0], vo[j][2]};
    axis_error = fmax(axis_error, line_angle3(vr[j], rotated));
  }
  printf("turned by 90 degrees about z: centre %.2e, moments %.2e relative, axes %.2e rad\n",
         centre_error, moment_error, axis_error);
  CHECK(centre_error <= 1e-14, "turned centre off by %.3g", centre_error);
  CHECK(moment_error <= 1e-12, "turned moments off by %.3g relative", moment_error);
  CHECK(axis_error <= 1e-11, "turned axes off by %.3g rad", axis_error);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
}

/* A scene's ellipsoidal cell (cells[i].semi_x, semi_y, semi_z): the
 * initial field's membrane encloses the ellipsoid's volume and its axes
 * are the given ones. */
static void test_initial_ellipsoid(void) {
  static const char text[] =
      "mesh: {type: box, x0: 0, y0: 0, z0: 0, x1: 0.5, y1: 0.5, z1: 0.5, nx: 40, ny: 40, "
      "nz: 40}\n"
      "noise: {background: 0, amplitude: 0}\n"
      "output: {pictures: false}\n"
      "cells:\n"
      "  - {x: 0.2517, y: 0.2483, z: 0.2509, radius: 0.1, semi_x: 0.16, semi_z: 0.07}\n";
  sp_scene *scene;
  CHECK_OK(sp_scene_load_text("ellipsoid.yaml", text, sizeof text - 1, 0, NULL, &scene));
  const sp_scene_mesh *m = &scene->mesh;
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_box(m->x0, m->y0, m->z0, m->x1, m->y1, m->z1, m->nx, m->ny, m->nz, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  CHECK_OK(sp_cells_initial_state(scene, mesh, layout, state));
  sp_cell_obs o;
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &o));
  const double volume = 4.0 / 3.0 * acos(-1.0) * 0.16 * 0.1 * 0.07;
  const double x[3] = {1, 0, 0}, z[3] = {0, 0, 1};
  printf("initial ellipsoid 0.16 x 0.1 x 0.07: volume inside the membrane %.6g (%.6g), "
         "long axis off x by %.2e rad, short off z by %.2e\n",
         o.volume, volume, line_angle3(o.axes[2], x), line_angle3(o.axes[0], z));
  /* the c = 1/2 set is the ellipsoid (the profile's distance is exact on
   * it), counted at the Gauss points of elements of h = 0.18 x the
   * shortest semi-axis: half test_relax_3d's 0.36 r, so half its 6% */
  CHECK(fabs(o.volume - volume) <= 0.03 * volume, "volume %g, ellipsoid %g", o.volume, volume);
  CHECK(line_angle3(o.axes[2], x) < 1e-3 && line_angle3(o.axes[0], z) < 1e-3,
        "axes: long (%g, %g, %g), short (%g, %g, %g)", o.axes[2][0], o.axes[2][1], o.axes[2][2], o.axes[0][0],
        o.axes[0][1], o.axes[0][2]);
  CHECK(fabs(o.centre[0] - 0.2517) < 5e-5 && fabs(o.centre[1] - 0.2483) < 5e-5 && fabs(o.centre[2] - 0.2509) < 5e-5,
        "centre (%g, %g, %g)", o.centre[0], o.centre[1], o.centre[2]);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
}

/** The initial state of @p text's one cell on its box: observables, and
 *  the field in *state (the caller frees it). */
static sp_cell_obs initial_cell(const char *text, double **state, int *n) {
  sp_scene *scene;
  sp_cell_obs o = {0};
  CHECK_OK(sp_scene_load_text("turned.yaml", text, strlen(text), 0, NULL, &scene));
  if (sp_test_failures) return o;
  const sp_scene_mesh *m = &scene->mesh;
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_box(m->x0, m->y0, m->z0, m->x1, m->y1, m->z1, m->nx, m->ny, m->nz, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  *n = layout->n_pairs;
  *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  CHECK_OK(sp_cells_initial_state(scene, mesh, layout, *state));
  CHECK_OK(sp_cells_observe(mesh, layout, *state, WEIGHT_THRESHOLD, &o));
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
  return o;
}

/* A turned ellipsoid (cells[0].axis_x, axis_y, axis_z): its long axis is
 * the given direction, the frame the smallest rotation onto it. */
static void test_turned_ellipsoid(void) {
  static const char box[] =
      "mesh: {type: box, x0: 0, y0: 0, z0: 0, x1: 0.5, y1: 0.5, z1: 0.5, nx: 40, ny: 40, "
      "nz: 40}\n"
      "noise: {background: 0, amplitude: 0}\n"
      "output: {pictures: false}\n"
      "cells:\n";
  char text[1024];
  double *state = NULL, *along_y = NULL;
  int n = 0, m = 0;
  snprintf(text, sizeof text, "%s  - {x: 0.2517, y: 0.2483, z: 0.2509, radius: 0.1, semi_x: "
           "0.16, semi_z: 0.07, axis_x: 1, axis_y: 2, axis_z: 2}\n", box);
  const sp_cell_obs o = initial_cell(text, &state, &n);
  if (sp_test_failures) return;
  /* x onto u = (1, 2, 2) / 3 by the smallest rotation, about v = x cross
   * u = (0, -2, 2) / 3 (Rodrigues, c = x . u = 1/3): z goes to
   * (-2, -1, 2) / 3, normal to u */
  const double u[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3}, c = u[0], f = 1 / (1 + c);
  const double v[3] = {0, -u[2], u[1]};
  /* R e3 = e3 + v x e3 + f v x (v x e3) */
  const double vxz[3] = {v[1], -v[0], 0};
  const double vxvxz[3] = {v[1] * vxz[2] - v[2] * vxz[1], v[2] * vxz[0] - v[0] * vxz[2],
                           v[0] * vxz[1] - v[1] * vxz[0]};
  const double z_turned[3] = {vxz[0] + f * vxvxz[0], vxz[1] + f * vxvxz[1],
                              1 + vxz[2] + f * vxvxz[2]};
  const double volume = 4.0 / 3.0 * acos(-1.0) * 0.16 * 0.1 * 0.07;
  printf("turned ellipsoid 0.16 x 0.1 x 0.07, axis (1, 2, 2): volume %.6g (%.6g), long axis "
         "(%.6f, %.6f, %.6f) off by %.2e rad, short off the turned z (%.4f, %.4f, %.4f) by "
         "%.2e\n", o.volume, volume, o.axes[2][0], o.axes[2][1], o.axes[2][2], line_angle3(o.axes[2], u),
         z_turned[0], z_turned[1], z_turned[2], line_angle3(o.axes[0], z_turned));
  CHECK(fabs(dot3(z_turned, z_turned) - 1) < 1e-15 && fabs(dot3(z_turned, u)) < 1e-15,
        "the turned z is not a unit vector normal to u");
  CHECK(fabs(o.volume - volume) <= 0.03 * volume, "volume %g, ellipsoid %g", o.volume, volume);
  CHECK(line_angle3(o.axes[2], u) < 1e-3, "long axis (%g, %g, %g), given (1, 2, 2) / 3", o.axes[2][0],
        o.axes[2][1], o.axes[2][2]);
  CHECK(line_angle3(o.axes[0], z_turned) < 1e-3, "short axis (%g, %g, %g), turned z (%g, %g, %g)",
        o.axes[0][0], o.axes[0][1], o.axes[0][2], z_turned[0], z_turned[1], z_turned[2]);
  free(state);

  /* turned onto y: the cell of semi_y = 0.16 (a quarter turn about z,
   * whose frame is exact) */
  snprintf(text, sizeof text, "%s  - {x: 0.2517, y: 0.2483, z: 0.2509, radius: 0.1, semi_x: "
           "0.16, semi_z: 0.07, axis_y: 1}\n", box);
  initial_cell(text, &state, &n);
  snprintf(text, sizeof text, "%s  - {x: 0.2517, y: 0.2483, z: 0.2509, radius: 0.1, semi_y: "
           "0.16, semi_z: 0.07}\n", box);
  initial_cell(text, &along_y, &m);
  double worst = 0;
  for (int p = 0; p < n && n == m && state && along_y; ++p)
    worst = fmax(worst, fabs(state[2 * p] - along_y[2 * p]));
  printf("turned onto y against semi_y: largest difference of c %.2e\n", worst);
  CHECK(n == m && worst <= 1e-15, "turned onto y: c differs by %.3g from semi_y's", worst);
  free(state);
  free(along_y);

  /* bad input: a zero axis, axis_z in 2D, an axis on a sphere, a turned
   * cell leaving the box */
  static const char *const bad[][2] = {
      {"mesh: {type: box, x1: 0.5, y1: 0.5, z1: 0.5, nx: 4, ny: 4, nz: 4}\ncells:\n  - {x: "
       "0.25, y: 0.25, z: 0.25, radius: 0.1, semi_x: 0.15, axis_x: 0, axis_y: 0, axis_z: 0}\n",
       "cells[0].axis_x"},
      {"mesh: {type: rectangle, x1: 0.5, y1: 0.5, nx: 4, ny: 4}\ncells:\n  - {x: 0.25, y: "
       "0.25, radius: 0.1, semi_x: 0.15, axis_z: 1}\n", "cells[0].axis_z"},
      {"mesh: {type: box, x1: 0.5, y1: 0.5, z1: 0.5, nx: 4, ny: 4, nz: 4}\ncells:\n  - {x: "
       "0.25, y: 0.25, z: 0.25, radius: 0.1, axis_x: 1}\n", "cells[0].axis_x"},
      /* fits along x (extent 0.2 in x, 0.05 in z), not turned onto (1, 0, 1):
       * its extent in z is then 0.146 > 0.1 */
      {"mesh: {type: box, x1: 0.5, y1: 0.5, z1: 0.2, nx: 4, ny: 4, nz: 4}\ncells:\n  - {x: "
       "0.25, y: 0.25, z: 0.1, radius: 0.05, semi_x: 0.2, axis_x: 1, axis_z: 1}\n",
       "cells[0].axis_x"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    sp_scene *scene = NULL;
    sp_error_clear();
    const int rc = sp_scene_load_text("bad.yaml", bad[i][0], strlen(bad[i][0]), 0, NULL, &scene);
    printf("refused: %s\n", sp_error_message());
    CHECK(rc == SP_ERR_INPUT && !scene && strstr(sp_error_message(), bad[i][1]),
          "rc %d, %s: %s", rc, bad[i][1], sp_error_message());
    sp_scene_destroy(&scene);
  }
}

/* The same keys in 2D: an elliptical cell (semi_x) on a rectangle. */
static void test_initial_ellipse_2d(void) {
  static const char text[] =
      "mesh: {type: rectangle, x0: 0, y0: 0, x1: 0.5, y1: 0.5, nx: 80, ny: 80}\n"
      "noise: {background: 0, amplitude: 0}\n"
      "cells:\n"
      "  - {x: 0.2517, y: 0.2483, radius: 0.07, semi_x: 0.16}\n";
  sp_scene *scene;
  CHECK_OK(sp_scene_load_text("ellipse.yaml", text, sizeof text - 1, 0, NULL, &scene));
  sp_mesh *mesh;
  sp_layout *layout;
  CHECK_OK(sp_mesh_rectangle(0, 0, 0.5, 0.5, 80, 80, &mesh));
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, 1, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  CHECK_OK(sp_cells_initial_state(scene, mesh, layout, state));
  sp_cell_obs o;
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &o));
  const double area = acos(-1.0) * 0.16 * 0.07;
  printf("initial ellipse 0.16 x 0.07: area inside the membrane %.6g (%.6g), long axis (v2) "
         "(%.6f, %.6f)\n",
         o.volume, area, o.axes[1][0], o.axes[1][1]);
  /* elements of h = 0.09 x the short semi-axis */
  CHECK(fabs(o.volume - area) <= 0.03 * area, "area %g, ellipse %g", o.volume, area);
  CHECK(fabs(o.axes[1][1]) < 1e-3, "long axis (%g, %g), not x", o.axes[1][0], o.axes[1][1]);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
}

int main(void) {
  test_eigensolver();
  test_extrusion();
  test_ellipsoid_axes();
  test_sphere();
  test_rotation();
  test_initial_ellipsoid();
  test_initial_ellipse_2d();
  test_turned_ellipsoid();
  TEST_DONE();
}
