/* The lineage table (lineage.h). */
#include "model/lineage.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"

/** A component below this (of a unit vector) does not decide its sign. */
#define SP_LINEAGE_SIGN_EPS 1e-9

/** The perpendicular rule in 3D: the long axis's part perpendicular to the
 *  parent's cut normal names the new normal when it is at least this long
 *  (the long axis at least 1e-6 rad off the parent's normal); closer to it
 *  the projection's direction is round-off, and the rule falls back to
 *  any_perpendicular's fixed choice. */
#define SP_LINEAGE_PROJECTION_MIN 1e-6

int sp_lineage_from_scene(const sp_scene *scene, sp_lineage *out) {
  *out = (sp_lineage){0};
  for (int i = 0; i < scene->n_cells; ++i) out->named |= scene->cells[i].name[0] != '\0';
  if (scene->n_adhesion > 0) {
    SP_ALLOC(out->pair, scene->n_adhesion);
    out->n_pairs = scene->n_adhesion;
    for (int i = 0; i < out->n_pairs; ++i) {
      memcpy(out->pair[i].cell, scene->adhesion[i].cell, sizeof out->pair[i].cell);
      memcpy(out->pair[i].other, scene->adhesion[i].other, sizeof out->pair[i].other);
      out->pair[i].sigma = scene->adhesion[i].sigma;
    }
  }
  if (scene->n_lineage == 0) return SP_OK;
  SP_ALLOC(out->entry, scene->n_lineage);
  out->n = scene->n_lineage;
  for (int i = 0; i < out->n; ++i) {
    const sp_scene_lineage *s = &scene->lineage[i];
    sp_lineage_entry *e = &out->entry[i];
    memcpy(e->cell, s->cell, sizeof e->cell);
    memcpy(e->first, s->first, sizeof e->first);
    memcpy(e->second, s->second, sizeof e->second);
    e->when = !isnan(s->age) ? SP_LINEAGE_AGE : !isnan(s->time) ? SP_LINEAGE_TIME : SP_LINEAGE_MASS;
    e->value = e->when == SP_LINEAGE_AGE ? s->age : e->when == SP_LINEAGE_TIME ? s->time
                                                                               : s->mass_ratio;
    e->fraction = s->fraction;
    e->axis = s->axis;
    if (s->axis == SP_AXIS_FIXED) {
      double norm = 0;
      for (int d = 0; d < 3; ++d) {
        e->direction[d] = isnan(s->direction[d]) ? 0.0 : s->direction[d];
        norm += e->direction[d] * e->direction[d];
      }
      norm = sqrt(norm); /* > 0: checked by the scene */
      for (int d = 0; d < 3; ++d) e->direction[d] /= norm;
    }
  }
  return SP_OK;
}

void sp_lineage_free(sp_lineage *lineage) {
  free(lineage->entry);
  free(lineage->pair);
  *lineage = (sp_lineage){0};
}

const sp_lineage_entry *sp_lineage_find(const sp_lineage *lineage, const char *name) {
  if (!name[0]) return NULL;
  for (int i = 0; i < lineage->n; ++i)
    if (strcmp(lineage->entry[i].cell, name) == 0) return &lineage->entry[i];
  return NULL;
}

sp_division_params sp_lineage_params(const sp_lineage_entry *e, const sp_cell_birth *birth,
                                     double tolerance) {
  sp_division_params p = {.criterion = SP_DIVIDE_AGE, .tolerance = tolerance};
  if (e->when == SP_LINEAGE_MASS) {
    p.criterion = SP_DIVIDE_MASS;
    p.mass_ratio = e->value;
  } else {
    p.age = e->when == SP_LINEAGE_AGE ? e->value : e->value - birth->birth_time;
    /* born at or after its time: due at once (age 0 is reached at birth) */
    if (!(p.age > 0)) p.age = 0.0;
  }
  return p;
}

int sp_lineage_due(const sp_lineage_entry *e, const sp_cell_birth *birth, double t, double mass,
                   double tolerance) {
  const sp_division_params p = sp_lineage_params(e, birth, tolerance);
  return sp_division_due(&p, birth, t, t, mass, mass);
}

double sp_lineage_due_time(const sp_lineage_entry *e, const sp_cell_birth *birth) {
  if (e->when == SP_LINEAGE_MASS) return INFINITY;
  return e->when == SP_LINEAGE_AGE ? birth->birth_time + e->value : e->value;
}

/** Make @p v point to +x (else +y, else +z): the first component above
 *  SP_LINEAGE_SIGN_EPS in size is positive. */
static void orient(double v[3], int dim) {
  for (int d = 0; d < dim; ++d)
    if (fabs(v[d]) > SP_LINEAGE_SIGN_EPS) {
      if (v[d] < 0)
        for (int j = 0; j < 3; ++j) v[j] = -v[j];
      return;
    }
}

/** @p v / |v| into @p out; 0 if |v| is (nearly) zero. */
static int unit(const double v[3], double out[3]) {
  const double norm = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(norm > SP_LINEAGE_SIGN_EPS)) return 0;
  for (int d = 0; d < 3; ++d) out[d] = v[d] / norm;
  return 1;
}

/** The unit vector along @p v without its part along the unit @p p, into
 *  @p out (which may be @p v); 0 (and @p out untouched) when that part is
 *  shorter than SP_LINEAGE_PROJECTION_MIN: @p v (nearly) along @p p names no
 *  direction perpendicular to it. */
static int project_out(const double v[3], const double p[3], double out[3]) {
  const double along = v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
  double w[3];
  for (int d = 0; d < 3; ++d) w[d] = v[d] - along * p[d];
  const double norm = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (!(norm >= SP_LINEAGE_PROJECTION_MIN)) return 0;
  for (int d = 0; d < 3; ++d) out[d] = w[d] / norm;
  return 1;
}

/** A unit vector perpendicular to the unit @p p: in 2D p turned by +90
 *  degrees; in 3D p crossed with the coordinate axis least along it. */
static void any_perpendicular(const double p[3], int dim, double out[3]) {
  if (dim == 2) {
    const double v[3] = {-p[1], p[0], 0.0};
    unit(v, out);
    return;
  }
  int least = 0;
  for (int d = 1; d < 3; ++d)
    if (fabs(p[d]) < fabs(p[least])) least = d;
  double e[3] = {0, 0, 0};
  e[least] = 1.0;
  const double v[3] = {p[1] * e[2] - p[2] * e[1], p[2] * e[0] - p[0] * e[2],
                       p[0] * e[1] - p[1] * e[0]};
  unit(v, out);
}

void sp_lineage_normal(const sp_lineage_entry *e, int dim, const double long_axis[3],
                       const double parent_normal[3], double normal[3]) {
  double p[3];
  if (e && e->axis == SP_AXIS_FIXED) {
    for (int d = 0; d < 3; ++d) normal[d] = e->direction[d];
    return;
  }
  for (int d = 0; d < 3; ++d) normal[d] = d < dim ? long_axis[d] : 0.0;
  if (!e) return; /* the paper's cut, exactly as it always was */
  if (e->axis == SP_AXIS_PERPENDICULAR && unit(parent_normal, p)) {
    /* 2D: the parent's normal turned by 90 degrees (exactly); 3D: the long
     * axis without its part along the parent's normal, normalised (twice:
     * the second pass leaves a part along p of round-off, ~1e-16, even
     * when the projection is short) */
    if (dim == 2 || !project_out(long_axis, p, normal) || !project_out(normal, p, normal))
      any_perpendicular(p, dim, normal);
  }
  orient(normal, dim);
}

void sp_lineage_obs_normal(const sp_cell_obs *obs, int dim, double normal[3]) {
  double point[3];
  sp_division_plane(obs, dim, point, normal);
}

void sp_lineage_set_obs_normal(sp_cell_obs *obs, const double normal[3]) {
  for (int d = 0; d < 3; ++d) obs->axes[obs->long_axis][d] = normal[d];
}

void sp_lineage_daughter_names(const sp_lineage_entry *e, const char *parent, sp_cell_name first,
                               sp_cell_name second) {
  if (e) {
    memcpy(first, e->first, SP_CELL_NAME_MAX);
    memcpy(second, e->second, SP_CELL_NAME_MAX);
    return;
  }
  first[0] = second[0] = '\0';
  if (!parent[0] || strlen(parent) + 2 >= SP_CELL_NAME_MAX) return;
  snprintf(first, SP_CELL_NAME_MAX, "%s.1", parent);
  snprintf(second, SP_CELL_NAME_MAX, "%s.2", parent);
}
