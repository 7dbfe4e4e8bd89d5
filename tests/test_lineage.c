/* The lineage table's building blocks (src/model/lineage.c) and the asymmetric
 * cut (sp_division_balance_offset with a fraction), no time stepping:
 * - an elliptical parent cut with the long and a fixed axis gives its first
 *   daughter the asked share of its mass: to 1e-9 relative with the smooth
 *   cut; with the sharp cut (whole nodes to a side) to half the largest
 *   node's share of the parent, max_i w_i c_i / (2 M), which is below 1%;
 *   the daughters' masses sum to the parent's to 1e-12 relative; the first
 *   daughter is on the side the normal points away from;
 * - the axis rules' normals (long oriented to +x, fixed as given,
 *   perpendicular in 2D and 3D), the criteria (age, time, mass ratio), the
 *   daughters' names, a scene's table (normalised direction) and the
 *   restart check seeing a changed entry. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cells.h"
#include "check.h"
#include "model/division.h"
#include "public/error.h"
#include "fixtures.h"
#include "mesh/layout.h"
#include "model/lineage.h"
#include "mesh/mesh.h"
#include "scene/scene.h"

/** Centre and inertia integrate c >= this, as the stepper does. */
#define WEIGHT_THRESHOLD 0.05

static double interface_width(void) { return sqrt(1e-3 / 8.0); }

static double dot2(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1]; }

/* An ellipse (0.12 x 0.06 at 0.3 rad) split at fractions
 * 0.59, 0.3 and 0.8 by the long axis and a fixed one, sharp and smooth. */
static void test_asymmetric_split(void) {
  sp_mesh *mesh;
  sp_layout *layout, *new_layout;
  double *state, *new_state;
  split_setup(&mesh, &layout, &new_layout, &state, &new_state);
  double *w = calloc((size_t)mesh->n_nodes, sizeof(double));
  const double width = interface_width();
  /* (no background: a domain-wide one sums to the parent's mass to 1e-11,
   * over 25600 elements, tests/test_division.c) */
  set_ellipse(mesh, layout, state, 0, 0.5, 0.5, 0.12, 0.06, 0.3, width / 0.06);
  sp_cell_obs before, after[2];
  CHECK_OK(sp_cells_observe(mesh, layout, state, WEIGHT_THRESHOLD, &before));
  /* the sharp cut's resolution: the largest node's share of the mass */
  CHECK_OK(sp_cells_node_weights(mesh, layout, 0, w));
  double node_max = 0;
  for (int i = 0; i < mesh->n_nodes; ++i) node_max = fmax(node_max, w[i] * state[2 * i]);
  const double sharp_tolerance = node_max / (2 * before.mass);
  printf("sharp cut: half the largest node's share %.3g\n", sharp_tolerance);
  CHECK(sharp_tolerance < 0.01, "the sharp cut's tolerance %.3g is not below 1%%",
        sharp_tolerance);
  const double fractions[] = {0.59, 0.3, 0.8};
  printf("  axis  | cut    | fraction | first daughter's share | off by\n");
  for (int fixed = 0; fixed <= 1; ++fixed)
    for (int smooth = 0; smooth <= 1; ++smooth)
      for (size_t f = 0; f < sizeof fractions / sizeof fractions[0]; ++f) {
        const sp_lineage_entry e = {.fraction = fractions[f],
                                    .axis = fixed ? SP_AXIS_FIXED : SP_AXIS_LONG,
                                    .direction = {cos(1.2), sin(1.2), 0}};
        double long_axis[3], normal[3], zero[3] = {0, 0, 0};
        sp_lineage_obs_normal(&before, 2, long_axis);
        sp_lineage_normal(&e, 2, long_axis, zero, normal);
        sp_cell_obs cut = before;
        sp_lineage_set_obs_normal(&cut, normal);
        double check[3];
        sp_lineage_obs_normal(&cut, 2, check);
        CHECK(fabs(check[0] - normal[0]) + fabs(check[1] - normal[1]) < 1e-15,
              "the observables do not give the normal back");
        double offset;
        CHECK_OK(sp_division_balance_offset(mesh, layout, state, 0, &cut, smooth, width,
                                            1.0 - e.fraction, &offset));
        CHECK_OK(sp_division_split(mesh, layout, state, 0, &cut, smooth, width, offset,
                                   new_layout, new_state, 1));
        CHECK_OK(sp_cells_observe(mesh, new_layout, new_state, WEIGHT_THRESHOLD, after));
        const double total = after[0].mass + after[1].mass;
        CHECK(fabs(total - before.mass) <= 1e-12 * before.mass,
              "fixed %d smooth %d f %g: mass %.17g -> %.17g", fixed, smooth, e.fraction,
              before.mass, total);
        const double share = after[0].mass / before.mass, off = fabs(share - e.fraction);
        printf("  %-5s | %-6s | %8.3f | %.12f         | %.2e\n", fixed ? "fixed" : "long",
               smooth ? "smooth" : "sharp", e.fraction, share, off);
        const double allowed = smooth ? 1e-9 : sharp_tolerance * (1 + 1e-9);
        CHECK(off <= allowed, "fixed %d smooth %d: share %.12f for %g (allowed %.3g)", fixed,
              smooth, share, e.fraction, allowed);
        /* the first daughter on the side the normal points away from */
        const double c0[2] = {after[0].centre[0], after[0].centre[1]}, c1[2] = {after[1].centre[0], after[1].centre[1]};
        CHECK(dot2(c0, normal) < dot2(c1, normal), "fixed %d: the first daughter is on the "
              "normal's side", fixed);
        if (fixed) /* the user's direction */
          CHECK(fabs(normal[0] - cos(1.2)) + fabs(normal[1] - sin(1.2)) < 1e-15,
                "fixed normal (%g, %g)", normal[0], normal[1]);
        else /* the long axis, at 0.3 rad, pointing to +x */
          CHECK(fabs(normal[0] - cos(0.3)) < 1e-3 && fabs(normal[1] - sin(0.3)) < 1e-3,
                "long normal (%g, %g)", normal[0], normal[1]);
      }
  free(w);
  split_teardown(&mesh, &layout, &new_layout, &state, &new_state);
}


/* The axis rules' normals. */
static void test_normals(void) {
  double n[3];
  const double zero[3] = {0, 0, 0};
  const sp_lineage_entry lng = {.axis = SP_AXIS_LONG}, perp = {.axis = SP_AXIS_PERPENDICULAR};
  /* long: oriented to +x, or +y when along y */
  sp_lineage_normal(&lng, 2, (const double[3]){-0.6, -0.8, 0}, zero, n);
  CHECK(n[0] == 0.6 && n[1] == 0.8, "long (-0.6, -0.8) -> (%g, %g)", n[0], n[1]);
  sp_lineage_normal(&lng, 2, (const double[3]){-1e-17, -1, 0}, zero, n);
  CHECK(n[0] == 1e-17 && n[1] == 1, "long (0, -1) -> (%g, %g)", n[0], n[1]);
  /* the paper's (no entry): the long axis as it is */
  sp_lineage_normal(NULL, 2, (const double[3]){-0.6, -0.8, 0}, zero, n);
  CHECK(n[0] == -0.6 && n[1] == -0.8, "no entry (-0.6, -0.8) -> (%g, %g)", n[0], n[1]);
  /* perpendicular, 2D: the parent's normal turned by 90 degrees, whatever
   * the long axis (but one along the parent's normal) */
  const double parents[][3] = {{1, 0, 0}, {0.6, 0.8, 0}, {-0.28, 0.96, 0}};
  const double longs[][3] = {{1, 0, 0}, {0.3, 0.95393920141694566, 0}, {-0.8, 0.6, 0}};
  for (int p = 0; p < 3; ++p)
    for (int l = 0; l < 3; ++l) {
      sp_lineage_normal(&perp, 2, longs[l], parents[p], n);
      CHECK(fabs(norm3(n) - 1) < 1e-14 && fabs(dot2(n, parents[p])) < 1e-14 && n[2] == 0,
            "perpendicular to (%g, %g) with long (%g, %g): (%g, %g, %g)", parents[p][0],
            parents[p][1], longs[l][0], longs[l][1], n[0], n[1], n[2]);
      CHECK(n[0] > 1e-9 || (fabs(n[0]) <= 1e-9 && n[1] > 0), "not oriented: (%g, %g)", n[0],
            n[1]);
    }
  /* perpendicular, 3D: normal to the parent's, the closest to the long axis */
  sp_lineage_normal(&perp, 3, (const double[3]){-0.57735, -0.57735, -0.57735},
                    (const double[3]){0, 0, 1}, n);
  CHECK(fabs(n[0] - sqrt(0.5)) < 1e-14 && fabs(n[1] - sqrt(0.5)) < 1e-14 && n[2] == 0,
        "3D perpendicular: (%g, %g, %g)", n[0], n[1], n[2]);
  /* ... and any unit perpendicular when the long axis is the parent's normal */
  sp_lineage_normal(&perp, 3, (const double[3]){0, 0, 1}, (const double[3]){0, 0, 1}, n);
  CHECK(fabs(norm3(n) - 1) < 1e-14 && fabs(n[2]) < 1e-14, "3D degenerate: (%g, %g, %g)", n[0],
        n[1], n[2]);
  /* 3D, generic: the long axis l projected on the plane normal to the
   * parent's p, normalised, orthogonal to p to 1e-15 even when l is only
   * 1e-5 rad off p (the second projection); within 1e-6 rad of p the
   * fallback p x (the axis least along p) */
  const double p3[3] = {1 / sqrt(14.0), 2 / sqrt(14.0), 3 / sqrt(14.0)};
  for (int k = 0; k < 3; ++k) {
    const double off = k == 0 ? 0.7 : k == 1 ? 1e-5 : 1e-7; /* rad */
    const double q[3] = {2 / sqrt(5.0), -1 / sqrt(5.0), 0}; /* (unit, normal to p3) */
    double l[3], want[3];
    for (int d = 0; d < 3; ++d) l[d] = cos(off) * p3[d] + sin(off) * q[d];
    if (k < 2)
      memcpy(want, q, sizeof want);
    else /* p x e_x, e_x being the axis least along p3, normalised */
      for (int d = 0; d < 3; ++d)
        want[d] = (double[3]){0, p3[2], -p3[1]}[d] / sqrt(p3[1] * p3[1] + p3[2] * p3[2]);
    sp_lineage_normal(&perp, 3, l, p3, n);
    const double along = n[0] * p3[0] + n[1] * p3[1] + n[2] * p3[2];
    const double miss = fabs(n[0] - want[0]) + fabs(n[1] - want[1]) + fabs(n[2] - want[2]);
    printf("3D perpendicular, long axis %.1e rad off the parent's normal: (%.15f, %.15f, "
           "%.15f), n . p = %.2e\n", off, n[0], n[1], n[2], along);
    CHECK(fabs(along) <= 1e-15 && fabs(norm3(n) - 1) <= 1e-15,
          "3D perpendicular (%g rad): n . p = %.3g, |n| - 1 = %.3g", off, along, norm3(n) - 1);
    CHECK(miss <= (k == 1 ? 1e-10 : 1e-14), "3D perpendicular (%g rad): (%.17g, %.17g, %.17g)",
          off, n[0], n[1], n[2]);
  }
  /* a zero parent normal (no parent's cut): long */
  sp_lineage_normal(&perp, 2, (const double[3]){0, -1, 0}, zero, n);
  CHECK(n[0] == 0 && n[1] == 1, "perpendicular without a parent: (%g, %g)", n[0], n[1]);
}

/* The criteria: age after the birth, absolute time (at once when born
 * later), mass ratio of the birth core mass. */
static void test_due(void) {
  const sp_cell_birth birth = {.birth_time = 0.5, .birth_mass = 2.0};
  const sp_lineage_entry age = {.when = SP_LINEAGE_AGE, .value = 0.25},
                         time = {.when = SP_LINEAGE_TIME, .value = 0.6},
                         late = {.when = SP_LINEAGE_TIME, .value = 0.4},
                         mass = {.when = SP_LINEAGE_MASS, .value = 1.5};
  CHECK(!sp_lineage_due(&age, &birth, 0.7499, 2, 0) && sp_lineage_due(&age, &birth, 0.75, 2, 0),
        "age 0.25 after 0.5");
  CHECK(sp_lineage_due_time(&age, &birth) == 0.75, "age: due at %g",
        sp_lineage_due_time(&age, &birth));
  CHECK(!sp_lineage_due(&time, &birth, 0.5999, 2, 0) && sp_lineage_due(&time, &birth, 0.6, 2, 0),
        "time 0.6");
  CHECK(sp_lineage_due_time(&time, &birth) == 0.6, "time: due at %g",
        sp_lineage_due_time(&time, &birth));
  CHECK(sp_lineage_due(&late, &birth, 0.5, 2, 0), "time 0.4, born at 0.5: not due at once");
  CHECK(!sp_lineage_due(&mass, &birth, 9, 2.99, 0) && sp_lineage_due(&mass, &birth, 9, 3.0, 0),
        "mass ratio 1.5 of 2");
  CHECK(isinf(sp_lineage_due_time(&mass, &birth)), "mass: a due time");
  /* the tolerance, as division.h's */
  CHECK(sp_lineage_due(&age, &birth, 0.7499, 2, 1e-3), "age with tolerance 1e-3");
}

static void test_names(void) {
  sp_cell_name a, b;
  const sp_lineage_entry e = {.first = "ABa", .second = "ABp"};
  sp_lineage_daughter_names(&e, "AB", a, b);
  CHECK(!strcmp(a, "ABa") && !strcmp(b, "ABp"), "entry: %s %s", a, b);
  sp_lineage_daughter_names(NULL, "ABa", a, b);
  CHECK(!strcmp(a, "ABa.1") && !strcmp(b, "ABa.2"), "no entry: %s %s", a, b);
  sp_lineage_daughter_names(NULL, "ABCDEFGHIJKLMNOPQRSTUVWXYZabc", a, b); /* 29 + 2 fit */
  CHECK(!strcmp(a, "ABCDEFGHIJKLMNOPQRSTUVWXYZabc.1"), "29 characters: %s", a);
  sp_lineage_daughter_names(NULL, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcd", a, b); /* 30 + 2 do not */
  CHECK(!a[0] && !b[0], "30 characters: '%s' '%s'", a, b);
  sp_lineage_daughter_names(NULL, "", a, b);
  CHECK(!a[0] && !b[0], "unnamed: '%s' '%s'", a, b);
}

/* A scene's table as the run gets it; the restart check sees an entry
 * change. */
static void test_scene_table(void) {
  static const char text[] =
      "mesh: {type: rectangle, nx: 8, ny: 8}\n"
      "cells:\n"
      "  - {name: P0, x: 0.3, y: 0.5, radius: 0.1}\n"
      "  - {x: 0.7, y: 0.5, radius: 0.1}\n"
      "lineage:\n"
      "  - {cell: P0, time: 0.01, fraction: 0.59, first: AB, second: P1, axis: fixed,\n"
      "     direction_x: -3, direction_y: -4}\n"
      "  - {cell: AB, age: 0.02, first: ABa, second: ABp, axis: perpendicular}\n"
      "  - {cell: P1, mass_ratio: 1.5, first: EMS, second: P2}\n";
  sp_scene *scene, *changed;
  CHECK_OK(sp_scene_load_text("table.yaml", text, strlen(text), 0, NULL, &scene));
  CHECK(scene->n_lineage == 3 && !strcmp(scene->cells[0].name, "P0") && !scene->cells[1].name[0],
        "%d entries, names '%s' '%s'", scene->n_lineage, scene->cells[0].name,
        scene->cells[1].name);
  sp_lineage t;
  CHECK_OK(sp_lineage_from_scene(scene, &t));
  CHECK(t.n == 3 && t.named, "table: %d entries, named %d", t.n, t.named);
  const sp_lineage_entry *p0 = sp_lineage_find(&t, "P0"), *ab = sp_lineage_find(&t, "AB"),
                         *p1 = sp_lineage_find(&t, "P1");
  CHECK(p0 && ab && p1 && !sp_lineage_find(&t, "ABa") && !sp_lineage_find(&t, ""),
        "find");
  if (p0 && ab && p1) {
    CHECK(p0->when == SP_LINEAGE_TIME && p0->value == 0.01 && p0->fraction == 0.59 &&
              !strcmp(p0->first, "AB") && !strcmp(p0->second, "P1"),
          "P0's entry");
    CHECK(fabs(p0->direction[0] + 0.6) < 1e-15 && fabs(p0->direction[1] + 0.8) < 1e-15 &&
              p0->direction[2] == 0,
          "fixed direction (-3, -4) -> (%g, %g, %g)", p0->direction[0], p0->direction[1],
          p0->direction[2]);
    CHECK(ab->when == SP_LINEAGE_AGE && ab->fraction == 0.5 && ab->axis == SP_AXIS_PERPENDICULAR,
          "AB's entry");
    CHECK(p1->when == SP_LINEAGE_MASS && p1->value == 1.5 && p1->axis == SP_AXIS_LONG,
          "P1's entry");
  }
  sp_lineage_free(&t);
  static const char *const set[] = {"time.t_end=1"};
  CHECK_OK(sp_scene_load_text("table.yaml", text, strlen(text), 1, set, &changed));
  changed->lineage[1].fraction = 0.6;
  char key[256];
  CHECK(sp_scene_first_difference(scene, changed, NULL, key, sizeof key) &&
            !strcmp(key, "time.t_end"),
        "first difference: %s", key);
  changed->time.t_end = scene->time.t_end;
  CHECK(sp_scene_first_difference(scene, changed, NULL, key, sizeof key) &&
            !strcmp(key, "lineage[2].fraction"),
        "a changed entry: %s", key);
  changed->lineage[1].fraction = scene->lineage[1].fraction;
  snprintf(changed->cells[1].name, SP_CELL_NAME_MAX, "Q0");
  CHECK(sp_scene_first_difference(scene, changed, NULL, key, sizeof key) &&
            !strcmp(key, "cells[2].name"),
        "a changed name: %s", key);
  sp_scene_destroy(&changed);
  sp_scene_destroy(&scene);
}

int main(void) {
  test_asymmetric_split();
  test_normals();
  test_due();
  test_names();
  test_scene_table();
  TEST_DONE();
}
