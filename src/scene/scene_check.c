/* scene_check.c: the checks of a loaded scene: across keys, the cells in Omega, the lineage. */
/*
 * What libcyaml and the key table's ranges cannot check alone: keys that
 * depend on each other (time steps, the mesh, the initial fields' source,
 * what a 2D or a 3D scene may ask for), every cell inside Omega, the
 * names and the lineage table, and the size of the initial layout. Each
 * refusal names its key.
 */
#include "scene/scene.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "scene/scene_private.h"

/** Points on a cell's circle tested against the ellipse (the brief's
 *  sampling: enough to catch a disk poking out by more than ~0.1% of R). */
enum { SP_DISK_CHECK_ANGLES = 64 };

static int ends_with(const char *s, const char *tail) {
  const size_t n = strlen(s), m = strlen(tail);
  return n >= m && strcmp(s + n - m, tail) == 0;
}

/** A label volume: a NIfTI file (one file, maybe gzipped), on a 3D mesh. */
static int check_label_volume(const sp_scene *scene, const char *file) {
  const char *volume = scene->initial.label_volume;
  SP_CHECK(ends_with(volume, ".nii") || ends_with(volume, ".nii.gz"), SP_ERR_INPUT,
           "%s: initial.label_volume: expected a NIfTI file (.nii or .nii.gz), got '%s'",
           file, volume);
  SP_CHECK(sp_scene_dim(scene) == 3, SP_ERR_INPUT,
           "%s: initial.label_volume: a label volume is 3D: expected a 3D mesh (mesh.type box "
           "or ellipsoid), got mesh.type %s (a 2D scene takes a PNG, initial.label_image)",
           file, sp_mesh_words[scene->mesh.type].str);
  return SP_OK;
}

/** initial.from names a checkpoint or a .vtu. */
static int check_from(const sp_scene_initial *in, const char *file) {
  const size_t n = strlen(in->from);
  SP_CHECK((n > 3 && strcmp(in->from + n - 3, ".h5") == 0) ||
               (n > 4 && strcmp(in->from + n - 4, ".vtu") == 0),
           SP_ERR_INPUT, "%s: initial.from: expected a softpack checkpoint (.h5) or .vtu, got '%s'",
           file, in->from);
  return SP_OK;
}

/** initial.label_image's box is not empty. */
static int check_image_box(const sp_scene_initial *in, const char *file) {
  SP_CHECK(in->x1 > in->x0, SP_ERR_INPUT,
           "%s: initial.x1: expected a number > initial.x0 = %.15g, got %.15g", file,
           in->x0, in->x1);
  SP_CHECK(in->y1 > in->y0, SP_ERR_INPUT,
           "%s: initial.y1: expected a number > initial.y0 = %.15g, got %.15g", file,
           in->y0, in->y1);
  return SP_OK;
}

/** Cells, or initial fields from a file: one of them. */
static int check_initial(const sp_scene *scene, const char *file) {
  const sp_scene_initial *in = &scene->initial;
  const int from = in->from[0] != '\0', image = in->label_image[0] != '\0';
  const int volume = in->label_volume[0] != '\0';
  /* the file that gives the cells, and its key */
  const char *source = from ? in->from : image ? in->label_image : volume ? in->label_volume
                                                                          : NULL;
  const char *key = from ? "from" : image ? "label_image" : "label_volume";
  SP_CHECK(scene->n_cells > 0 || source, SP_ERR_INPUT,
           "%s: cells: no cells given (the key is missing or its list is "
           "empty); a scene needs at least one cell, or initial.from, "
           "initial.label_image or initial.label_volume",
           file);
  SP_CHECK(!(from && image), SP_ERR_INPUT,
           "%s: initial.label_image: expected none with initial.from (give one "
           "source of initial fields), got '%s'", file, in->label_image);
  SP_CHECK(!(volume && (from || image)), SP_ERR_INPUT,
           "%s: initial.label_volume: expected none with initial.%s (give one source of "
           "initial fields), got '%s'", file, key, in->label_volume);
  SP_CHECK(scene->n_cells == 0 || !source, SP_ERR_INPUT,
           "%s: cells: expected none with initial.%s (the file gives the cells), got %d",
           file, key, scene->n_cells);
  if (volume) SP_CALL(check_label_volume(scene, file));
  if (from) SP_CALL(check_from(in, file));
  SP_CHECK(!source || access(source, R_OK) == 0, SP_ERR_INPUT,
           "%s: initial.%s: cannot read '%s': %s", file, key, source, strerror(errno));
  return image ? check_image_box(in, file) : SP_OK;
}

/** mesh.semi_z given on an ellipsoid (and only there), its refinements at
 *  most SP_MESH_ELLIPSOID_MAX_REFINEMENTS. */
static int check_ellipsoid_keys(const sp_scene_mesh *m, const char *file) {
  if (m->type == SP_MESH_ELLIPSOID) {
    SP_CHECK(!isnan(m->semi_z), SP_ERR_INPUT,
             "%s: mesh.semi_z: required with mesh.type ellipsoid: expected the semi-axis "
             "along z, a number > 0", file);
    SP_CHECK(m->refinements <= SP_MESH_ELLIPSOID_MAX_REFINEMENTS, SP_ERR_INPUT,
             "%s: mesh.refinements: expected at most %d with mesh.type ellipsoid (%d gives "
             "%lld hexahedra), got %d", file, SP_MESH_ELLIPSOID_MAX_REFINEMENTS,
             m->refinements, sp_mesh_ellipsoid_elements(m->refinements, m->buffer_layers),
             m->refinements);
  } else {
    SP_CHECK(isnan(m->semi_z), SP_ERR_INPUT,
             "%s: mesh.semi_z: only with mesh.type ellipsoid, got %.15g with mesh.type %s",
             file, m->semi_z, sp_mesh_words[m->type].str);
  }
  return SP_OK;
}

/** output.length_scale (time_scale) only with its unit. */
static int check_unit_keys(const sp_scene *scene, const char *file) {
  const sp_scene_output *o = &scene->output;
  SP_CHECK(o->length_unit[0] || o->length_scale == 1.0, SP_ERR_INPUT,
           "%s: output.length_scale: only with output.length_unit (the unit it counts), got "
           "%.15g without one", file, o->length_scale);
  SP_CHECK(o->time_unit[0] || o->time_scale == 1.0, SP_ERR_INPUT,
           "%s: output.time_scale: only with output.time_unit (the unit it counts), got %.15g "
           "without one", file, o->time_scale);
  return SP_OK;
}

/** mesh.flatten: 0, or on an ellipse (ellipsoid) below its last semi-axis. */
static int check_flatten_key(const sp_scene *scene, const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  if (m->flatten == 0) return SP_OK;
  SP_CHECK(m->type == SP_MESH_ELLIPSE || m->type == SP_MESH_ELLIPSOID, SP_ERR_INPUT,
           "%s: mesh.flatten: only with mesh.type ellipse or ellipsoid, got %.15g with "
           "mesh.type %s", file, m->flatten, sp_mesh_words[m->type].str);
  const int dim = sp_scene_dim(scene);
  const double semi = dim == 3 ? m->semi_z : m->semi_y;
  SP_CHECK(m->flatten < semi, SP_ERR_INPUT,
           "%s: mesh.flatten: expected a number < mesh.%s = %.15g (the planes must cut the "
           "%s; 0: no cut), got %.15g", file, dim == 3 ? "semi_z" : "semi_y", semi,
           dim == 3 ? "ellipsoid" : "ellipse", m->flatten);
  return SP_OK;
}

/** model.adhesion_*: each below kappa, which bounds the gradient energy of
 *  a pair alone (docs/model.md, "Adhesion"); the sum over a cell's partners
 *  on an element is checked by the run on each layout (model/adhesion.h). */
static int check_adhesion_keys(const sp_scene *scene, const char *file) {
  const sp_scene_model *m = &scene->model;
  SP_CHECK(m->adhesion_sisters < m->kappa, SP_ERR_INPUT,
           "%s: model.adhesion_sisters: expected a number < model.kappa = %.15g (the "
           "gradient energy is bounded below only then), got %.15g",
           file, m->kappa, m->adhesion_sisters);
  SP_CHECK(m->adhesion_non_sisters < m->kappa, SP_ERR_INPUT,
           "%s: model.adhesion_non_sisters: expected a number < model.kappa = %.15g (the "
           "gradient energy is bounded below only then), got %.15g",
           file, m->kappa, m->adhesion_non_sisters);
  return SP_OK;
}

static int check_time_and_mesh(const sp_scene *scene, const char *file) {
  const sp_scene_time *t = &scene->time;
  SP_CHECK(t->dt_min <= t->dt, SP_ERR_INPUT,
           "%s: time.dt_min: expected a number <= time.dt = %.15g, got "
           "%.15g",
           file, t->dt, t->dt_min);
  SP_CHECK(!(t->scheme == SP_TIME_BDF2 && scene->shape.scheme == SP_SHAPE_IMPLICIT &&
             (scene->shape.delta1 > 0 || scene->shape.delta2 > 0 || scene->shape.delta3 > 0)),
           SP_ERR_INPUT,
           "%s: time.scheme: expected be with shape.scheme implicit (its linearised moments "
           "need c^n, which a BDF2 step does not solve from), got bdf2",
           file);
  SP_CHECK(t->dt_max >= t->dt_min, SP_ERR_INPUT,
           "%s: time.dt_max: expected a number >= time.dt_min = %.15g, got %.15g", file,
           t->dt_min, t->dt_max);
  SP_CHECK(scene->solver.newton_divergence == 0 || scene->solver.newton_divergence > 1,
           SP_ERR_INPUT,
           "%s: solver.newton_divergence: expected 0 (off) or a number > 1, got %.15g",
           file, scene->solver.newton_divergence);
  SP_CHECK(scene->layout.band < scene->layout.margin, SP_ERR_INPUT,
           "%s: layout.band: expected a number < layout.margin = %.15g, got "
           "%.15g",
           file, scene->layout.margin, scene->layout.band);
  if (scene->mesh.type == SP_MESH_RECTANGLE || scene->mesh.type == SP_MESH_BOX) {
    const sp_scene_mesh *m = &scene->mesh;
    SP_CHECK(m->x1 > m->x0, SP_ERR_INPUT,
             "%s: mesh.x1: expected a number > mesh.x0 = %.15g, got %.15g",
             file, m->x0, m->x1);
    SP_CHECK(m->y1 > m->y0, SP_ERR_INPUT,
             "%s: mesh.y1: expected a number > mesh.y0 = %.15g, got %.15g",
             file, m->y0, m->y1);
  }
  if (scene->mesh.type == SP_MESH_BOX) {
    const sp_scene_mesh *m = &scene->mesh;
    SP_CHECK(m->z1 > m->z0, SP_ERR_INPUT,
             "%s: mesh.z1: expected a number > mesh.z0 = %.15g, got %.15g",
             file, m->z0, m->z1);
  }
  SP_CALL(check_ellipsoid_keys(&scene->mesh, file));
  SP_CALL(check_unit_keys(scene, file));
  return check_flatten_key(scene, file);
}

/** What a scene of one dimension cannot ask for, each refused naming its
 *  key: on a 3D mesh a PNG label image, on a 2D mesh the third moment's
 *  shape.delta3. */
static int check_3d(const sp_scene *scene, const char *file) {
  if (sp_scene_dim(scene) != 3) {
    SP_CHECK(scene->shape.delta3 == 0, SP_ERR_INPUT,
             "%s: shape.delta3: the third principal moment is a 3D cell's (mesh.type box or "
             "ellipsoid): expected 0 on a 2D mesh, got %.15g",
             file, scene->shape.delta3);
    return SP_OK;
  }
  SP_CHECK(scene->initial.label_image[0] == '\0', SP_ERR_INPUT,
           "%s: initial.label_image: a PNG label image is 2D: expected none on a 3D mesh "
           "(a 3D scene takes a NIfTI label volume, initial.label_volume), got '%s'", file,
           scene->initial.label_image);
  return SP_OK;
}

/** The key that sets cell @p c's extent along @p d: its semi-axis if
 *  given, else its radius. */
static const char *extent_key(const sp_scene_cell *c, int d) {
  static const char *const semi[3] = {"semi_x", "semi_y", "semi_z"};
  if (sp_scene_cell_is_turned(c)) return "axis_x"; /* (its extents come from the turn) */
  const double given[3] = {c->semi_x, c->semi_y, c->semi_z};
  return isnan(given[d]) ? "radius" : semi[d];
}

/** Points on a cell's sphere tested against the ellipsoid: latitude
 *  circles of SP_DISK_CHECK_ANGLES points, half as many latitudes. */
enum { SP_SPHERE_CHECK_LATITUDES = SP_DISK_CHECK_ANGLES / 2 };

/** (x/a)^2 + (y/b)^2 + (z/c)^2: <= 1 inside the ellipsoid of the mesh. */
static double ellipsoid_level(const sp_scene_mesh *m, const double x[3]) {
  const double semi[3] = {m->semi_x, m->semi_y, m->semi_z};
  double level = 0;
  for (int d = 0; d < 3; ++d) level += (x[d] / semi[d]) * (x[d] / semi[d]);
  return level;
}

/** Cell @p i's centre, and its whole sphere (or ellipsoid: its semi-axes),
 *  inside the ellipsoid. */
static int check_sphere_in_ellipsoid(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                     const char *file) {
  const double centre[3] = {c->x, c->y, c->z}, r = c->radius;
  const double level = ellipsoid_level(m, centre);
  SP_CHECK(level <= 1.0, SP_ERR_INPUT,
           "%s: cells[%d].x, cells[%d].y, cells[%d].z: the centre (%.15g, %.15g, %.15g) is "
           "outside the ellipsoid (x/%.15g)^2 + (y/%.15g)^2 + (z/%.15g)^2 <= 1 (it gives %.6g)",
           file, i, i, i, c->x, c->y, c->z, m->semi_x, m->semi_y, m->semi_z, level);
  const double half_turn = acos(-1.0);
  for (int la = 0; la <= SP_SPHERE_CHECK_LATITUDES; ++la)
    for (int j = 0; j < SP_DISK_CHECK_ANGLES; ++j) {
      const double polar = half_turn * la / SP_SPHERE_CHECK_LATITUDES;
      const double azimuth = 2 * half_turn * j / SP_DISK_CHECK_ANGLES;
      const double local[3] = {sp_scene_cell_semi_axis(c, 0) * sin(polar) * cos(azimuth),
                               sp_scene_cell_semi_axis(c, 1) * sin(polar) * sin(azimuth),
                               sp_scene_cell_semi_axis(c, 2) * cos(polar)};
      double p[3];
      sp_scene_cell_point(c, 3, centre, local, p);
      SP_CHECK(ellipsoid_level(m, p) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].radius: the sphere (or semi-axes) of radius %.15g around (%.15g, "
               "%.15g, %.15g) is not inside the ellipsoid with semi-axes (%.15g, %.15g, %.15g): its point "
               "(%.6g, %.6g, %.6g) is outside",
               file, i, r, c->x, c->y, c->z, m->semi_x, m->semi_y, m->semi_z, p[0], p[1], p[2]);
    }
  return SP_OK;
}

/** Every cell's centre, and its whole sphere (ellipsoid), inside the box
 *  or the ellipsoid; its z given. */
static int check_sphere(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                        const char *file) {
  SP_CHECK(!isnan(c->z), SP_ERR_INPUT,
           "%s: cells[%d].z: required on a 3D mesh (mesh.type %s): the cell is a sphere", file,
           i, sp_mesh_words[m->type].str);
  if (m->type == SP_MESH_ELLIPSOID) return check_sphere_in_ellipsoid(m, c, i, file);
  const double lo[3] = {m->x0, m->y0, m->z0}, hi[3] = {m->x1, m->y1, m->z1};
  const double x[3] = {c->x, c->y, c->z}, r = c->radius;
  static const char *const name[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d)
    SP_CHECK(x[d] >= lo[d] && x[d] <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].%s: the centre %s = %.15g is outside the box's [mesh.%s0, "
             "mesh.%s1] = [%.15g, %.15g]",
             file, i, name[d], name[d], x[d], name[d], name[d], lo[d], hi[d]);
  for (int d = 0; d < 3 && sp_scene_cell_is_ellipsoid(c); ++d) {
    const double s = sp_scene_cell_extent(c, 3, d);
    SP_CHECK(x[d] - s >= lo[d] && x[d] + s <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].%s: the ellipsoid's extent %.15g along %s around (%.15g, "
             "%.15g, %.15g) is not inside the box [%.15g, %.15g] x [%.15g, %.15g] x [%.15g, "
             "%.15g]",
             file, i, extent_key(c, d), s, name[d], x[0], x[1], x[2], lo[0], hi[0], lo[1],
             hi[1], lo[2], hi[2]);
  }
  for (int d = 0; d < 3 && !sp_scene_cell_is_ellipsoid(c); ++d)
    SP_CHECK(x[d] - r >= lo[d] && x[d] + r <= hi[d], SP_ERR_INPUT,
             "%s: cells[%d].radius: the sphere of radius %.15g around (%.15g, %.15g, %.15g) "
             "is not inside the box [%.15g, %.15g] x [%.15g, %.15g] x [%.15g, %.15g]",
             file, i, r, x[0], x[1], x[2], lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]);
  return SP_OK;
}

/** (x/a)^2 + (y/b)^2: <= 1 inside the ellipse of the mesh. */
static double ellipse_level(const sp_scene_mesh *m, double x, double y) {
  return (x / m->semi_x) * (x / m->semi_x) + (y / m->semi_y) * (y / m->semi_y);
}

/** Cell @p i's centre, and its whole disk (ellipse), inside the rectangle. */
static int check_disk_in_rectangle(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                   const char *file) {
  const double r = c->radius;
  SP_CHECK(c->x >= m->x0 && c->x <= m->x1, SP_ERR_INPUT,
           "%s: cells[%d].x: the centre x = %.15g is outside the "
           "rectangle's [mesh.x0, mesh.x1] = [%.15g, %.15g]",
           file, i, c->x, m->x0, m->x1);
  SP_CHECK(c->y >= m->y0 && c->y <= m->y1, SP_ERR_INPUT,
           "%s: cells[%d].y: the centre y = %.15g is outside the "
           "rectangle's [mesh.y0, mesh.y1] = [%.15g, %.15g]",
           file, i, c->y, m->y0, m->y1);
  if (sp_scene_cell_is_ellipsoid(c)) {
    for (int d = 0; d < 2; ++d) {
      const double x = d == 0 ? c->x : c->y, s = sp_scene_cell_extent(c, 2, d);
      const double lo = d == 0 ? m->x0 : m->y0, hi = d == 0 ? m->x1 : m->y1;
      SP_CHECK(x - s >= lo && x + s <= hi, SP_ERR_INPUT,
               "%s: cells[%d].%s: the ellipse's extent %.15g along %s around (%.15g, "
               "%.15g) is not inside the rectangle [%.15g, %.15g] x [%.15g, %.15g]",
               file, i, extent_key(c, d), s, d == 0 ? "x" : "y", c->x, c->y, m->x0, m->x1,
               m->y0, m->y1);
    }
    return SP_OK;
  }
  SP_CHECK(c->x - r >= m->x0 && c->x + r <= m->x1 && c->y - r >= m->y0 &&
               c->y + r <= m->y1,
           SP_ERR_INPUT,
           "%s: cells[%d].radius: the disk of radius %.15g around "
           "(%.15g, %.15g) is not inside the rectangle [%.15g, %.15g] x "
           "[%.15g, %.15g]",
           file, i, r, c->x, c->y, m->x0, m->x1, m->y0, m->y1);
  return SP_OK;
}

/** Cell @p i's centre, and its whole disk, inside the ellipse. */
static int check_disk_in_ellipse(const sp_scene_mesh *m, const sp_scene_cell *c, int i,
                                 const char *file) {
  const double r = c->radius;
  double level = ellipse_level(m, c->x, c->y);
  SP_CHECK(level <= 1.0, SP_ERR_INPUT,
           "%s: cells[%d].x, cells[%d].y: the centre (%.15g, %.15g) is "
           "outside the ellipse (x/%.15g)^2 + (y/%.15g)^2 <= 1 (it gives "
           "%.6g)",
           file, i, i, c->x, c->y, m->semi_x, m->semi_y, level);
  const double full_turn = 2.0 * acos(-1.0);
  const double rx = sp_scene_cell_semi_axis(c, 0), ry = sp_scene_cell_semi_axis(c, 1);
  for (int j = 0; j < SP_DISK_CHECK_ANGLES; ++j) {
    double angle = full_turn * j / SP_DISK_CHECK_ANGLES;
    const double centre[2] = {c->x, c->y}, local[2] = {rx * cos(angle), ry * sin(angle)};
    double p[2];
    sp_scene_cell_point(c, 2, centre, local, p);
    const double px = p[0], py = p[1];
    if (!sp_scene_cell_is_ellipsoid(c))
      SP_CHECK(ellipse_level(m, px, py) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].radius: the disk of radius %.15g around "
               "(%.15g, %.15g) is not inside the ellipse with semi-axes "
               "(%.15g, %.15g): its point (%.6g, %.6g) is outside",
               file, i, r, c->x, c->y, m->semi_x, m->semi_y, px, py);
    else
      SP_CHECK(ellipse_level(m, px, py) <= 1.0, SP_ERR_INPUT,
               "%s: cells[%d].semi_x, cells[%d].semi_y: the cell's ellipse with semi-axes "
               "(%.15g, %.15g) around (%.15g, %.15g) is not inside the ellipse with "
               "semi-axes (%.15g, %.15g): its point (%.6g, %.6g) is outside",
               file, i, i, rx, ry, c->x, c->y, m->semi_x, m->semi_y, px, py);
  }
  return SP_OK;
}

/** On a flattened mesh (mesh.flatten), cell @p i's extent along the last
 *  axis (y in 2D, z in 3D) between the planes. */
static int check_cell_under_coverslip(const sp_scene_mesh *m, int dim, const sp_scene_cell *c,
                                      int i, const char *file) {
  if (!(m->flatten > 0)) return SP_OK;
  const double centre = dim == 3 ? c->z : c->y, semi = sp_scene_cell_extent(c, dim, dim - 1);
  const char *axis = dim == 3 ? "z" : "y";
  SP_CHECK(fabs(centre) + semi <= m->flatten, SP_ERR_INPUT,
           "%s: cells[%d].%s: the cell reaches %s = %.15g, beyond the plane |%s| = "
           "mesh.flatten = %.15g (its centre %.15g, its extent %.15g along %s)",
           file, i, extent_key(c, dim - 1), axis, fabs(centre) + semi, axis, m->flatten,
           centre, semi, axis);
  return SP_OK;
}

/** Cell @p i's axis_x, _y, _z: on an ellipse (ellipsoid) only, axis_z on
 *  a 3D mesh only, not the zero vector. */
static int check_cell_axis(const sp_scene_cell *c, int i, int dim, const char *file) {
  if (!sp_scene_cell_is_turned(c)) return SP_OK;
  SP_CHECK(dim == 3 || isnan(c->axis[2]), SP_ERR_INPUT,
           "%s: cells[%d].axis_z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g", file,
           i, c->axis[2]);
  SP_CHECK(sp_scene_cell_is_ellipsoid(c), SP_ERR_INPUT,
           "%s: cells[%d].axis_x: turns an ellipse (ellipsoid): expected semi_x, semi_y or "
           "semi_z with it, got a %s of radius %.15g", file, i, dim == 3 ? "sphere" : "disk",
           c->radius);
  double norm = 0;
  for (int d = 0; d < 3; ++d) norm = hypot(norm, isnan(c->axis[d]) ? 0.0 : c->axis[d]);
  SP_CHECK(norm > 0 && isfinite(norm), SP_ERR_INPUT,
           "%s: cells[%d].axis_x, axis_y%s: expected a direction (a vector of finite "
           "length > 0), got one of length %g", file, i, dim == 3 ? ", axis_z" : "", norm);
  return SP_OK;
}

/** Every cell's centre, and its whole disk (sphere), inside Omega; z
 *  given exactly on a 3D mesh. */
static int check_cells(const sp_scene *scene, const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  for (int i = 0; i < scene->n_cells; ++i) {
    const sp_scene_cell *c = &scene->cells[i];
    SP_CALL(check_cell_axis(c, i, sp_scene_dim(scene), file));
    if (sp_scene_dim(scene) == 3) {
      SP_CALL(check_sphere(m, c, i, file));
      SP_CALL(check_cell_under_coverslip(m, 3, c, i, file));
      continue;
    }
    SP_CHECK(isnan(c->z), SP_ERR_INPUT,
             "%s: cells[%d].z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g with "
             "mesh.type %s",
             file, i, c->z, sp_mesh_words[m->type].str);
    SP_CHECK(isnan(c->semi_z), SP_ERR_INPUT,
             "%s: cells[%d].semi_z: only on a 3D mesh (mesh.type box, ellipsoid), got %.15g "
             "with mesh.type %s",
             file, i, c->semi_z, sp_mesh_words[m->type].str);
    if (m->type == SP_MESH_RECTANGLE) SP_CALL(check_disk_in_rectangle(m, c, i, file));
    else SP_CALL(check_disk_in_ellipse(m, c, i, file));
    SP_CALL(check_cell_under_coverslip(m, 2, c, i, file));
  }
  return SP_OK;
}

/** The initial cell named @p name, or -1. */
static int initial_named(const sp_scene *scene, const char *name) {
  for (int i = 0; i < scene->n_cells; ++i)
    if (strcmp(scene->cells[i].name, name) == 0) return i;
  return -1;
}

/** The lineage entry with @p name as a daughter (*which: "first" or
 *  "second"), from entry @p from on, or -1. */
static int daughter_entry(const sp_scene *scene, const char *name, int from, const char **which) {
  for (int j = from; j < scene->n_lineage; ++j) {
    const sp_scene_lineage *e = &scene->lineage[j];
    if (strcmp(e->first, name) == 0 || strcmp(e->second, name) == 0) {
      *which = strcmp(e->first, name) == 0 ? "first" : "second";
      return j;
    }
  }
  return -1;
}

/** One lineage entry's own keys: one criterion, a fixed axis's direction. */
static int check_lineage_entry(const sp_scene *scene, int i, const char *file) {
  const sp_scene_lineage *e = &scene->lineage[i];
  const int dim = sp_scene_dim(scene);
  const double when[3] = {e->age, e->time, e->mass_ratio};
  static const char *const when_key[3] = {"age", "time", "mass_ratio"};
  int given = 0;
  char list[SP_TEXT] = "";
  for (int k = 0; k < 3; ++k)
    if (!isnan(when[k])) {
      ++given;
      snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", given > 1 ? ", " : "",
               when_key[k]);
    }
  SP_CHECK(given == 1, SP_ERR_INPUT,
           "%s: lineage[%d].age, lineage[%d].time, lineage[%d].mass_ratio: expected exactly "
           "one (when '%s' divides), got %s%s",
           file, i, i, i, e->cell, given ? list : "none", given ? "" : " of them");
  static const char *const axis_key[3] = {"direction_x", "direction_y", "direction_z"};
  double norm2 = 0;
  for (int d = 0; d < 3; ++d) {
    const int wanted = e->axis == SP_AXIS_FIXED && d < dim;
    SP_CHECK(wanted || isnan(e->direction[d]), SP_ERR_INPUT,
             "%s: lineage[%d].%s: expected none %s, got %.15g", file, i, axis_key[d],
             d >= dim ? "on a 2D mesh (no z)" : "unless axis is fixed", e->direction[d]);
    SP_CHECK(!wanted || !isnan(e->direction[d]), SP_ERR_INPUT,
             "%s: lineage[%d].%s: missing; axis fixed needs the cut's normal direction_x, "
             "direction_y%s",
             file, i, axis_key[d], dim == 3 ? ", direction_z" : "");
    if (wanted) norm2 += e->direction[d] * e->direction[d];
  }
  SP_CHECK(e->axis != SP_AXIS_FIXED || norm2 > 0, SP_ERR_INPUT,
           "%s: lineage[%d].direction_x: expected a nonzero direction (the cut's normal), "
           "got the zero vector", file, i);
  SP_CHECK(strcmp(e->first, e->second) != 0, SP_ERR_INPUT,
           "%s: lineage[%d].second: expected a name other than first's, got '%s' twice", file,
           i, e->second);
  return SP_OK;
}

/** Entry @p i's place in the table: its cell has no other entry, its
 *  daughters' names are new, and its cell is reached from an initial cell
 *  (perpendicular needs a parent's cut). */
static int check_lineage_place(const sp_scene *scene, int i, const char *file) {
  const sp_scene_lineage *e = &scene->lineage[i];
  for (int j = 0; j < i; ++j)
    SP_CHECK(strcmp(scene->lineage[j].cell, e->cell) != 0, SP_ERR_INPUT,
             "%s: lineage[%d].cell: '%s' has an entry already (lineage[%d]): a cell "
             "divides once", file, i, e->cell, j);
  const char *daughter[2] = {e->first, e->second}, *key[2] = {"first", "second"}, *which;
  for (int d = 0; d < 2; ++d) {
    const int k = initial_named(scene, daughter[d]);
    SP_CHECK(k < 0, SP_ERR_INPUT,
             "%s: lineage[%d].%s: expected a new name, got '%s', the name of cells[%d]",
             file, i, key[d], daughter[d], k);
    const int j = daughter_entry(scene, daughter[d], i + 1, &which);
    SP_CHECK(j < 0, SP_ERR_INPUT,
             "%s: lineage[%d].%s: '%s' is a daughter of two entries: also "
             "lineage[%d].%s", file, j, which, daughter[d], i, key[d]);
  }
  /* the cell's ancestry: up the table to an initial cell */
  const char *name = e->cell;
  int parent = -1;
  for (int up = 0; initial_named(scene, name) < 0; ++up) {
    const int j = daughter_entry(scene, name, 0, &which);
    SP_CHECK(j >= 0, SP_ERR_INPUT,
             "%s: lineage[%d].cell: unknown name '%s': expected an initial cell's name "
             "(cells[i].name) or a daughter of another entry (first, second)",
             file, i, name);
    SP_CHECK(up < scene->n_lineage, SP_ERR_INPUT,
             "%s: lineage[%d].cell: '%s' is its own ancestor (a cycle through "
             "lineage[%d].%s): the table must lead down from the initial cells",
             file, i, e->cell, j, which);
    if (parent < 0) parent = j;
    name = scene->lineage[j].cell;
  }
  SP_CHECK(e->axis != SP_AXIS_PERPENDICULAR || parent >= 0, SP_ERR_INPUT,
           "%s: lineage[%d].axis: perpendicular needs the parent's cut, but '%s' is an "
           "initial cell: expected long or fixed", file, i, e->cell);
  return SP_OK;
}

/** The names and the lineage table: names unique; every entry's cell an
 *  initial cell or a daughter of another entry, once; every daughter's name
 *  new; no cycle; perpendicular only for a cell that has a parent. */
static int check_lineage(const sp_scene *scene, const char *file) {
  int named = 0;
  for (int i = 0; i < scene->n_cells; ++i) {
    const char *name = scene->cells[i].name;
    if (!name[0]) continue;
    ++named;
    const int first = initial_named(scene, name);
    SP_CHECK(first == i, SP_ERR_INPUT,
             "%s: cells[%d].name: expected a name of its own, got '%s', the name of cells[%d]",
             file, i, name, first);
  }
  if (scene->n_lineage == 0) return SP_OK;
  SP_CHECK(named > 0, SP_ERR_INPUT,
           "%s: lineage: expected named cells (cells[i].name), got none: the table's "
           "cell, first and second refer to names", file);
  for (int i = 0; i < scene->n_lineage; ++i) {
    SP_CALL(check_lineage_entry(scene, i, file));
    SP_CALL(check_lineage_place(scene, i, file));
  }
  return SP_OK;
}

/** The named pairs of the adhesion table: names known, two cells, each pair
 *  once, sigma below kappa. */
static int check_adhesion_pairs(const sp_scene *scene, const char *file) {
  const char *which;
  for (int i = 0; i < scene->n_adhesion; ++i) {
    const sp_scene_adhesion *a = &scene->adhesion[i];
    const char *name[2] = {a->cell, a->other}, *key[2] = {"cell", "other"};
    for (int k = 0; k < 2; ++k)
      SP_CHECK(initial_named(scene, name[k]) >= 0 || daughter_entry(scene, name[k], 0, &which) >= 0,
               SP_ERR_INPUT,
               "%s: adhesion[%d].%s: unknown name '%s': expected an initial cell's name "
               "(cells[i].name) or a daughter of a lineage entry (first, second)",
               file, i, key[k], name[k]);
    SP_CHECK(strcmp(a->cell, a->other) != 0, SP_ERR_INPUT,
             "%s: adhesion[%d].other: expected a name other than cell's, got '%s' twice",
             file, i, a->other);
    for (int j = 0; j < i; ++j) {
      const sp_scene_adhesion *b = &scene->adhesion[j];
      SP_CHECK(!((strcmp(a->cell, b->cell) == 0 && strcmp(a->other, b->other) == 0) ||
                 (strcmp(a->cell, b->other) == 0 && strcmp(a->other, b->cell) == 0)),
               SP_ERR_INPUT, "%s: adhesion[%d]: the pair '%s', '%s' has a sigma already "
               "(adhesion[%d])", file, i, a->cell, a->other, j);
    }
    SP_CHECK(a->sigma < scene->model.kappa, SP_ERR_INPUT,
             "%s: adhesion[%d].sigma: expected a number < model.kappa = %.15g (the gradient "
             "energy is bounded below only then), got %.15g",
             file, i, scene->model.kappa, a->sigma);
  }
  return SP_OK;
}

/** The initial layout (every cell on every node: a run starts with it, also
 *  before cutting local supports) must be numberable by ints and the solver's
 *  32-bit global ids; checked here, before anything that large is allocated. */
static int check_sizes(const sp_scene *scene, int n_cells, const char *cells_key,
                       const char *file) {
  const sp_scene_mesh *m = &scene->mesh;
  const int rectangle = m->type == SP_MESH_RECTANGLE, box = m->type == SP_MESH_BOX;
  const int ellipsoid = m->type == SP_MESH_ELLIPSOID;
  const long long nodes = rectangle ? sp_mesh_rectangle_nodes(m->nx, m->ny)
                          : box     ? sp_mesh_box_nodes(m->nx, m->ny, m->nz)
                          : ellipsoid ? sp_mesh_ellipsoid_nodes(m->refinements, m->buffer_layers)
                                      : sp_mesh_ellipse_nodes(m->refinements, m->buffer_layers);
  const long long pairs = nodes * n_cells;
  char mesh_keys[SP_TEXT];
  if (rectangle)
    snprintf(mesh_keys, sizeof mesh_keys, "mesh.nx, mesh.ny (%d x %d elements)", m->nx, m->ny);
  else if (box)
    snprintf(mesh_keys, sizeof mesh_keys, "mesh.nx, mesh.ny, mesh.nz (%d x %d x %d elements)",
             m->nx, m->ny, m->nz);
  else
    snprintf(mesh_keys, sizeof mesh_keys,
             "mesh.refinements, mesh.buffer_layers (%d refinements, %d buffer layers)",
             m->refinements, m->buffer_layers);
  SP_CHECK(pairs <= SP_LAYOUT_MAX_PAIRS, SP_ERR_INPUT,
           "%s: %s and %s (%d cells): too large: %lld nodes x %d cells = %lld (cell, node) "
           "pairs in the initial layout, 2 x %lld unknowns; at most %d pairs fit the "
           "solver's 32-bit indices (the solver's global ids are 32-bit): use fewer elements or cells",
           file, mesh_keys, cells_key, n_cells, nodes, n_cells, pairs, pairs,
           SP_LAYOUT_MAX_PAIRS);
  /* A run that keeps every cell on every node hands that layout to the
   * solver: its matrix's nonzeros must fit too (sp_nonzeros_bound). Local
   * supports are checked when each layout is handed over (the run's). */
  const int full = scene->layout.support == SP_SUPPORT_FULL ||
                   (scene->layout.support == SP_SUPPORT_AUTO &&
                    n_cells + scene->n_lineage <= 4 &&
                    scene->division.criterion == SP_DIVIDE_NONE);
  const int dim = sp_scene_dim(scene);
  const long long nonzeros = sp_nonzeros_bound(dim, nodes, n_cells);
  SP_CHECK(!full || nonzeros <= SP_LAYOUT_MAX_NONZEROS, SP_ERR_INPUT,
           "%s: %s, %s (%d cells) and layout.support (every cell on every node): too "
           "large: the Jacobian would hold up to %lld nonzeros (%lld nodes x %d x %d x %d), "
           "more than the %lld the solvers' 32-bit offsets count: use fewer elements or "
           "cells, or layout.support: local",
           file, mesh_keys, cells_key, n_cells, nonzeros, nodes, dim == 3 ? 27 : 9, n_cells,
           n_cells + 3, SP_LAYOUT_MAX_NONZEROS);
  return SP_OK;
}

int sp_scene_check_cell_count(const sp_scene *scene, int n_cells, const char *cells_key,
                              const char *where) {
  return check_sizes(scene, n_cells, cells_key, where);
}

int sp_scene_validate(const sp_scene *scene, const char *where) {
  SP_CALL(check_time_and_mesh(scene, where));
  SP_CALL(check_adhesion_keys(scene, where));
  SP_CALL(check_3d(scene, where));
  SP_CALL(check_initial(scene, where));
  SP_CALL(check_cells(scene, where));
  SP_CALL(check_lineage(scene, where));
  SP_CALL(check_adhesion_pairs(scene, where));
  return check_sizes(scene, scene->n_cells, "cells", where);
}
