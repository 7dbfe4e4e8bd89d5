/* render_surfaces.c: the cells' level surfaces (marching tetrahedra) seen by a 3D camera. */
/*
 * The level surfaces of Q1 fields on hexahedra (sp_render_level_surface),
 * and the 3D view of the cells (sp_render_surfaces): a fixed oblique
 * camera, flat shaded polygons drawn far to near (painter's algorithm),
 * the translucent boundary of Omega and, for a named scene, a legend. The
 * contact graph draws with the same camera and painter (render_surfaces.h).
 */
#define _POSIX_C_SOURCE 200809L

#include "io/render_surfaces.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"
#include "io/render_base.h"

/* ------------------------------------------------------------------------ */
/* 3D: the level surfaces of Q1 fields on hexahedra                         */
/* ------------------------------------------------------------------------ */

/** The faces of a hexahedron, each as its local nodes in cyclic order
 *  (q1.h's numbering: 0..3 the bottom face, 4..7 the top one). */
static const int sp_hex_faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                       {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

/** A growing list of triangles, 9 coordinates each. */
typedef struct {
  double *xyz;
  size_t n, cap;
} sp_tris;

static int sp_tris_push(sp_tris *t, const double *p0, const double *p1, const double *p2) {
  if (t->n == t->cap) {
    size_t cap = t->cap ? 2 * t->cap : 1024;
    double *xyz = realloc(t->xyz, 9 * sizeof(double) * cap);
    SP_CHECK(xyz, SP_ERR_MEMORY, "render: out of memory for %zu triangles", cap);
    t->xyz = xyz;
    t->cap = cap;
  }
  double *q = t->xyz + 9 * t->n++;
  for (int d = 0; d < 3; ++d) q[d] = p0[d], q[3 + d] = p1[d], q[6 + d] = p2[d];
  return SP_OK;
}

/** Add triangle (p0, p1, p2), turned so that its normal (p1 - p0) x
 *  (p2 - p0) has a positive component along @p out. */
static int sp_tris_push_facing(sp_tris *t, const double *p0, const double *p1,
                               const double *p2, const double out[3]) {
  double a[3], b[3];
  for (int d = 0; d < 3; ++d) a[d] = p1[d] - p0[d], b[d] = p2[d] - p0[d];
  const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
  const double dot = n[0] * out[0] + n[1] * out[1] + n[2] * out[2];
  return dot >= 0 ? sp_tris_push(t, p0, p1, p2) : sp_tris_push(t, p0, p2, p1);
}

/**
 * The point where v = level on the edge from @p pi (v = vi >= level) to
 * @p po (vo < level). Always computed from the inside end, so the two
 * tetrahedra sharing an edge make bit-identical points.
 */
static void sp_edge_point(const double *pi, double vi, const double *po, double vo,
                          double level, double x[3]) {
  const double s = (level - vi) / (vo - vi);
  for (int d = 0; d < 3; ++d) x[d] = pi[d] + s * (po[d] - pi[d]);
}

/**
 * The piece of {v = level} in one tetrahedron (marching tetrahedra on the
 * linear interpolant): a triangle when one or three vertices are inside
 * (v >= level), a quadrilateral as two triangles when two are; turned to
 * face from the inside vertices to the outside ones.
 */
static int sp_march_tet(const double *p[4], const double v[4], double level, sp_tris *t) {
  int in[4], out[4], n_in = 0, n_out = 0;
  for (int a = 0; a < 4; ++a) {
    if (v[a] >= level) in[n_in++] = a;
    else out[n_out++] = a;
  }
  if (n_in == 0 || n_out == 0) return SP_OK;
  double dir[3] = {0, 0, 0}; /* from the inside vertices' centroid to the outside ones' */
  for (int d = 0; d < 3; ++d) {
    for (int j = 0; j < n_out; ++j) dir[d] += p[out[j]][d] / n_out;
    for (int j = 0; j < n_in; ++j) dir[d] -= p[in[j]][d] / n_in;
  }
  double q[4][3];
#define SP_EDGE(k, i, o) sp_edge_point(p[i], v[i], p[o], v[o], level, q[k])
  if (n_in == 1) {
    for (int j = 0; j < 3; ++j) SP_EDGE(j, in[0], out[j]);
    return sp_tris_push_facing(t, q[0], q[1], q[2], dir);
  }
  if (n_in == 3) {
    for (int j = 0; j < 3; ++j) SP_EDGE(j, in[j], out[0]);
    return sp_tris_push_facing(t, q[0], q[1], q[2], dir);
  }
  /* in a, b and out c, d: the crossed edges ac, ad, bd, bc in cyclic order */
  SP_EDGE(0, in[0], out[0]);
  SP_EDGE(1, in[0], out[1]);
  SP_EDGE(2, in[1], out[1]);
  SP_EDGE(3, in[1], out[0]);
#undef SP_EDGE
  SP_CALL(sp_tris_push_facing(t, q[0], q[1], q[2], dir));
  return sp_tris_push_facing(t, q[0], q[2], q[3], dir);
}

/**
 * The piece of {v = level} in hexahedron @p e: the hexahedron is cut into
 * 24 tetrahedra, each made of one edge of a face, the face's centre and the
 * hexahedron's centre (the trilinear field's values there: the means of the
 * face's 4 and the element's 8 nodal values). Every face is cut the same
 * way from both sides whatever the two elements' orientations (the cubed
 * ball's patches meet at differently oriented hexahedra), so the surface
 * closes; the face centre is summed over its nodes in the order of their
 * global numbers, so both sides compute it to the same bits.
 */
static int sp_march_hex(const sp_mesh *m, int e, const double *v, double level, sp_tris *t) {
  const int *node = sp_mesh_elem_nodes(m, e);
  double val[8];
  int n_in = 0;
  for (int a = 0; a < 8; ++a) {
    val[a] = v[node[a]];
    n_in += val[a] >= level;
  }
  if (n_in == 0 || n_in == 8) return SP_OK;
  double x[8][3], xc[3] = {0, 0, 0}, vc = 0;
  for (int a = 0; a < 8; ++a) {
    for (int d = 0; d < 3; ++d) {
      x[a][d] = m->xy[3 * (size_t)node[a] + d];
      xc[d] += 0.125 * x[a][d];
    }
    vc += 0.125 * val[a];
  }
  for (int f = 0; f < 6; ++f) {
    int order[4];
    for (int j = 0; j < 4; ++j) { /* the face's nodes by global number */
      int a = sp_hex_faces[f][j], i = j;
      for (; i > 0 && node[order[i - 1]] > node[a]; --i) order[i] = order[i - 1];
      order[i] = a;
    }
    double xf[3] = {0, 0, 0}, vf = 0;
    for (int j = 0; j < 4; ++j) {
      for (int d = 0; d < 3; ++d) xf[d] += 0.25 * x[order[j]][d];
      vf += 0.25 * val[order[j]];
    }
    for (int j = 0; j < 4; ++j) {
      const int a = sp_hex_faces[f][j], b = sp_hex_faces[f][(j + 1) % 4];
      const double *p[4] = {x[a], x[b], xf, xc};
      const double vt[4] = {val[a], val[b], vf, vc};
      SP_CALL(sp_march_tet(p, vt, level, t));
    }
  }
  return SP_OK;
}

static int sp_level_surface(const sp_mesh *mesh, const double *v, double level, sp_tris *t) {
  for (int e = 0; e < mesh->n_elems; ++e) SP_CALL(sp_march_hex(mesh, e, v, level, t));
  return SP_OK;
}

int sp_render_level_surface(const sp_mesh *mesh, const double *v, double level, double **tri,
                            size_t *n_tri) {
  SP_CHECK(mesh && mesh->dim == 3 && v && tri && n_tri, SP_ERR_INTERNAL,
           "render: a level surface needs a 3D mesh and its nodal values");
  sp_tris t = {NULL, 0, 0};
  const int rc = sp_level_surface(mesh, v, level, &t);
  if (rc != SP_OK) {
    free(t.xyz);
    return rc;
  }
  *tri = t.xyz;
  *n_tri = t.n;
  return SP_OK;
}

/* ------------------------------------------------------------------------ */
/* 3D: the cells' surfaces seen by a fixed oblique camera                   */
/* ------------------------------------------------------------------------ */

static double sp_dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void sp_cross3(const double *a, const double *b, double *c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static void sp_normalise3(double *a) {
  const double n = sqrt(sp_dot3(a, a));
  if (n > 0)
    for (int d = 0; d < 3; ++d) a[d] /= n;
}

void sp_render_camera_map(const sp_render_camera *cam, const double *x, double *px,
                          double *py, double *depth) {
  const double r[3] = {x[0] - cam->centre[0], x[1] - cam->centre[1], x[2] - cam->centre[2]};
  *px = cam->ox + cam->s * sp_dot3(r, cam->right);
  *py = cam->oy - cam->s * sp_dot3(r, cam->up);
  if (depth) *depth = sp_dot3(r, cam->view);
}

int sp_render_camera_make(const sp_mesh *m, int width_px, sp_render_camera *cam) {
  SP_CHECK(m && m->dim == 3, SP_ERR_INTERNAL, "render: a 3D view needs a 3D mesh");
  SP_CALL(sp_render_width_check(width_px));
  double lo[3], hi[3];
  SP_CALL(sp_render_mesh_bbox(m, lo, hi));
  const double az = 35 * SP_RENDER_PI / 180, el = 25 * SP_RENDER_PI / 180;
  const double eye[3] = {sin(az) * cos(el), -cos(az) * cos(el), sin(el)}; /* towards the eye */
  const double z[3] = {0, 0, 1};
  for (int d = 0; d < 3; ++d) {
    cam->view[d] = -eye[d];
    cam->centre[d] = 0.5 * (lo[d] + hi[d]);
  }
  sp_cross3(cam->view, z, cam->right);
  sp_normalise3(cam->right);
  sp_cross3(cam->right, cam->view, cam->up);
  for (int d = 0; d < 3; ++d) /* one light, above and left of the eye */
    cam->light[d] = eye[d] + 0.6 * cam->up[d] - 0.4 * cam->right[d];
  sp_normalise3(cam->light);
  cam->s = 1;
  cam->ox = cam->oy = 0;
  double u0 = HUGE_VAL, u1 = -HUGE_VAL, v0 = HUGE_VAL, v1 = -HUGE_VAL;
  for (int i = 0; i < m->n_nodes; ++i) { /* the mesh's outline at scale 1 */
    double u, v;
    sp_render_camera_map(cam, m->xy + 3 * (size_t)i, &u, &v, NULL);
    u0 = fmin(u0, u), u1 = fmax(u1, u), v0 = fmin(v0, v), v1 = fmax(v1, v);
  }
  const double margin = width_px / 50 > 4 ? width_px / 50 : 4;
  cam->font = fmax(10.0, width_px / 45.0);
  const double band = ceil(1.8 * cam->font);
  cam->s = (width_px - 2 * margin) / (u1 - u0);
  cam->ox = margin - u0 * cam->s;
  cam->oy = band + margin - v0 * cam->s; /* v grows downwards here */
  const double h = ceil(band + 2 * margin + (v1 - v0) * cam->s);
  SP_CHECK(h <= 32768, SP_ERR_INPUT, "render: a %d px wide 3D view would be %.0f px high",
           width_px, h);
  cam->w = width_px;
  cam->h = (int)h;
  return SP_OK;
}

/** Project the polygon @p x (n corners) and shade @p rgb by Lambert's law
 *  for its unit normal @p normal: ambient 0.3 plus 0.7 n.light. */
static int sp_faces2d_push(sp_render_faces2d *fs, const sp_render_camera *cam, int n,
                           const double *x, const double normal[3], const double rgb[3]) {
  if (fs->n == fs->cap) {
    size_t cap = fs->cap ? 2 * fs->cap : 4096;
    sp_render_face2d *f = realloc(fs->f, sizeof *f * cap);
    SP_CHECK(f, SP_ERR_MEMORY, "render: out of memory for %zu faces", cap);
    fs->f = f;
    fs->cap = cap;
  }
  sp_render_face2d *f = fs->f + fs->n++;
  double depth = 0;
  for (int a = 0; a < n; ++a) {
    double px, py, dz;
    sp_render_camera_map(cam, x + 3 * a, &px, &py, &dz);
    f->p[a][0] = (float)px;
    f->p[a][1] = (float)py;
    depth += dz / n;
  }
  f->n = n;
  f->depth = (float)depth;
  const double lambert = 0.3 + 0.7 * fmax(0.0, sp_dot3(normal, cam->light));
  for (int c = 0; c < 3; ++c) f->rgb[c] = (float)(lambert * rgb[c]);
  return SP_OK;
}

int sp_render_cmp_far_first(const void *a, const void *b) {
  const float x = ((const sp_render_face2d *)a)->depth, y = ((const sp_render_face2d *)b)->depth;
  return (x < y) - (x > y);
}

/** Cell colours of the 3D view, cycled: distinct hues, none of them the
 *  background's white or the eggshell's grey. */
static const double sp_cell_palette[10][3] = {
    {0.86, 0.25, 0.20}, {0.22, 0.49, 0.85}, {0.30, 0.70, 0.30}, {0.95, 0.65, 0.15},
    {0.58, 0.38, 0.78}, {0.15, 0.70, 0.72}, {0.90, 0.45, 0.70}, {0.62, 0.62, 0.20},
    {0.60, 0.36, 0.22}, {0.45, 0.45, 0.55}};

/** The front-facing triangles of each cell's c = 1/2 surface, coloured
 *  per cell and shaded. */
static int sp_cell_faces(const sp_mesh *m, const sp_layout *l, const double *state,
                         const sp_render_camera *cam, sp_render_faces2d *fs) {
  const sp_cell_pairs *cp;
  SP_CALL(sp_layout_cells(l, &cp));
  double *c;
  SP_ALLOC(c, m->n_nodes);
  sp_tris t = {NULL, 0, 0};
  int rc = SP_OK;
  for (int k = 0; k < l->n_cells && rc == SP_OK; ++k) {
    memset(c, 0, sizeof *c * (size_t)m->n_nodes); /* 0 off the cell's support */
    for (int64_t j = cp->cell_start[k]; j < cp->cell_start[k + 1]; ++j)
      c[cp->cell_node[j]] = state[2 * (size_t)cp->cell_pair[j]];
    t.n = 0;
    rc = sp_level_surface(m, c, 0.5, &t);
    for (size_t i = 0; i < t.n && rc == SP_OK; ++i) {
      const double *x = t.xyz + 9 * i;
      double a[3], b[3], n[3];
      for (int d = 0; d < 3; ++d) a[d] = x[3 + d] - x[d], b[d] = x[6 + d] - x[d];
      sp_cross3(a, b, n);
      sp_normalise3(n);
      if (sp_dot3(n, cam->view) >= 0) continue; /* faces away: hidden by the front */
      rc = sp_faces2d_push(fs, cam, 3, x, n, sp_cell_palette[k % 10]);
    }
  }
  free(t.xyz);
  free(c);
  return rc;
}

/** A hexahedron face by its sorted global nodes, for finding the faces only
 *  one Omega element has. */
typedef struct {
  int key[4];
  int elem, face;
} sp_face_key;

static int sp_cmp_face_key(const void *a, const void *b) {
  const int *x = ((const sp_face_key *)a)->key, *y = ((const sp_face_key *)b)->key;
  for (int i = 0; i < 4; ++i)
    if (x[i] != y[i]) return (x[i] > y[i]) - (x[i] < y[i]);
  return 0;
}

/** Face @p f of element @p e, a quadrilateral of Omega's boundary turned
 *  outwards (away from the element's centre), to @p front if it faces the
 *  camera, else to @p back. */
static int sp_omega_face_push(const sp_mesh *m, int e, int f, const sp_render_camera *cam,
                              sp_render_faces2d *front, sp_render_faces2d *back) {
  static const double shell[3] = {0.70, 0.74, 0.80};
  const int *node = sp_mesh_elem_nodes(m, e);
  double x[4][3], xf[3] = {0, 0, 0}, xc[3] = {0, 0, 0};
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) xc[d] += 0.125 * m->xy[3 * (size_t)node[a] + d];
  for (int a = 0; a < 4; ++a)
    for (int d = 0; d < 3; ++d) {
      x[a][d] = m->xy[3 * (size_t)node[sp_hex_faces[f][a]] + d];
      xf[d] += 0.25 * x[a][d];
    }
  double d1[3], d2[3], n[3], out[3];
  for (int d = 0; d < 3; ++d) {
    d1[d] = x[2][d] - x[0][d];
    d2[d] = x[3][d] - x[1][d];
    out[d] = xf[d] - xc[d];
  }
  sp_cross3(d1, d2, n);
  sp_normalise3(n);
  if (sp_dot3(n, out) < 0)
    for (int d = 0; d < 3; ++d) n[d] = -n[d];
  return sp_faces2d_push(sp_dot3(n, cam->view) < 0 ? front : back, cam, 4, &x[0][0], n, shell);
}

/**
 * The boundary of Omega (the inner surface of the eggshell, or the box):
 * the faces of Omega elements that no other Omega element shares, as
 * quadrilaterals facing outwards; those facing the camera go to @p front,
 * the others to @p back.
 */
int sp_render_omega_faces(const sp_mesh *m, const sp_render_camera *cam,
                          sp_render_faces2d *front, sp_render_faces2d *back) {
  sp_face_key *keys;
  SP_ALLOC(keys, 6 * (size_t)m->n_elems);
  size_t nk = 0;
  for (int e = 0; e < m->n_elems; ++e) {
    if (m->region && m->region[e] != SP_REGION_OMEGA) continue;
    for (int f = 0; f < 6; ++f) {
      sp_face_key *k = keys + nk++;
      for (int j = 0; j < 4; ++j) {
        int v = sp_mesh_elem_nodes(m, e)[sp_hex_faces[f][j]], i = j;
        for (; i > 0 && k->key[i - 1] > v; --i) k->key[i] = k->key[i - 1];
        k->key[i] = v;
      }
      k->elem = e;
      k->face = f;
    }
  }
  qsort(keys, nk, sizeof *keys, sp_cmp_face_key);
  int rc = SP_OK;
  for (size_t i = 0; i < nk && rc == SP_OK;) {
    size_t j = i + 1;
    while (j < nk && sp_cmp_face_key(keys + j, keys + i) == 0) ++j;
    if (j - i == 1) rc = sp_omega_face_push(m, keys[i].elem, keys[i].face, cam, front, back);
    i = j;
  }
  free(keys);
  return rc;
}

/** Fill the polygons of @p fs in their order, without antialiasing (the
 *  polygons' own edges, antialiased, would let the background show
 *  through as seams between neighbours); with @p alpha < 1 as one
 *  translucent layer (drawn opaque into a group, painted with alpha, so
 *  their shared edges do not show). */
void sp_render_faces2d_fill(cairo_t *cr, const sp_render_faces2d *fs, double alpha) {
  const cairo_antialias_t antialias = cairo_get_antialias(cr);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  if (alpha < 1) cairo_push_group(cr);
  for (size_t i = 0; i < fs->n; ++i) {
    const sp_render_face2d *f = fs->f + i;
    cairo_move_to(cr, f->p[0][0], f->p[0][1]);
    for (int a = 1; a < f->n; ++a) cairo_line_to(cr, f->p[a][0], f->p[a][1]);
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, f->rgb[0], f->rgb[1], f->rgb[2]);
    cairo_fill(cr);
  }
  if (alpha < 1) {
    cairo_pop_group_to_source(cr);
    cairo_paint_with_alpha(cr, alpha);
  }
  cairo_set_antialias(cr, antialias);
}

/** The axes' directions in a corner, so the oblique view can be read. */
void sp_render_axes_triad(cairo_t *cr, const sp_render_camera *cam) {
  const double len = 2.2 * cam->font;
  const double ox = cam->w - 2.2 * len, oy = cam->h - 1.6 * len;
  cairo_set_line_width(cr, fmax(1.0, cam->w / 500.0));
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, 0.9 * cam->font);
  for (int d = 0; d < 3; ++d) {
    const double e[3] = {d == 0, d == 1, d == 2};
    const double ex = sp_dot3(e, cam->right), ey = -sp_dot3(e, cam->up);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    cairo_move_to(cr, ox, oy);
    cairo_line_to(cr, ox + len * ex, oy + len * ey);
    cairo_stroke(cr);
    sp_render_text(cr, ox + 1.3 * len * ex, oy + 1.3 * len * ey + 0.35 * cam->font, 0.5,
                   sp_render_axis_names[d]);
  }
}

/** The legend of a named scene's 3D view: each cell's colour (a square)
 *  and name, in rows across the picture, in a strip below the view. Lays
 *  the items out from the top of the strip @p y0 and returns the strip's
 *  height; draws them only if @p draw. */
static double sp_legend(cairo_t *cr, const sp_render_camera *cam, int n_cells,
                        const sp_cell_name *names, double y0, int draw) {
  const double font = cam->font, row = 1.5 * font, margin = cam->w / 50.0;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, font);
  double x = margin, y = y0 + 0.5 * font;
  for (int k = 0; k < n_cells; ++k) {
    char buf[16];
    const char *text = sp_render_cell_label(names, k, buf);
    cairo_text_extents_t ext;
    cairo_text_extents(cr, text, &ext);
    const double item = 0.8 * font + 0.4 * font + ext.x_advance;
    if (x > margin && x + item > cam->w - margin) x = margin, y += row; /* next row */
    if (draw) {
      const double *rgb = sp_cell_palette[k % 10];
      cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
      cairo_rectangle(cr, round(x), round(y + 0.2 * font), round(0.8 * font), round(0.8 * font));
      cairo_fill(cr);
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_move_to(cr, x + 1.2 * font, y + font);
      cairo_show_text(cr, text);
    }
    x += item + 1.2 * font;
  }
  return ceil(y + row + margin - y0);
}

static int sp_draw_surfaces(cairo_surface_t *surf, const sp_render_camera *cam,
                            sp_render_faces2d fs[3], double t, int n_cells,
                            const sp_cell_name *names) {
  cairo_t *cr = cairo_create(surf);
  sp_render_faces2d_fill(cr, &fs[0], 0.3);  /* the far side of the eggshell */
  sp_render_faces2d_fill(cr, &fs[1], 1.0);  /* the cells, far to near */
  sp_render_faces2d_fill(cr, &fs[2], 0.12); /* the near side, over them */
  sp_render_axes_triad(cr, cam);
  sp_render_time_label(cr, cam->w / 50.0, 1.3 * cam->font, cam->font, t);
  if (names) sp_legend(cr, cam, n_cells, names, cam->h, 1);
  const int rc = sp_render_cairo_check(cairo_status(cr), "drawing", "surfaces");
  cairo_destroy(cr);
  return rc;
}

/** The height of the 3D view's legend strip (0 without names). */
static int sp_legend_height(const sp_render_camera *cam, int n_cells, const sp_cell_name *names,
                            const char *path, int *height) {
  *height = 0;
  if (!names) return SP_OK;
  cairo_surface_t *scratch = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
  cairo_t *cr = cairo_create(scratch);
  *height = (int)sp_legend(cr, cam, n_cells, names, 0, 0);
  const int rc = sp_render_cairo_check(cairo_status(cr), "measuring the legend", path);
  cairo_destroy(cr);
  cairo_surface_destroy(scratch);
  return rc;
}

int sp_render_surfaces_pixel(const sp_mesh *mesh, int width_px, const double *x, double *px,
                             double *py, int *height_px) {
  sp_render_camera cam = {0};
  SP_CALL(sp_render_camera_make(mesh, width_px, &cam));
  double u, v;
  sp_render_camera_map(&cam, x, &u, &v, NULL);
  sp_render_pixel_out(u, v, cam.h, px, py, height_px);
  return SP_OK;
}

int sp_render_surfaces(const sp_mesh *mesh, const sp_layout *layout, const double *state,
                       double t, const sp_cell_name *names, int width_px, const char *path) {
  SP_CALL(sp_render_layout_check(mesh, layout));
  sp_render_camera cam = {0};
  SP_CALL(sp_render_camera_make(mesh, width_px, &cam));
  /* back shell, cells, front */
  sp_render_faces2d fs[3] = {{NULL, 0, 0}, {NULL, 0, 0}, {NULL, 0, 0}};
  int rc = sp_render_omega_faces(mesh, &cam, &fs[2], &fs[0]);
  if (rc == SP_OK) rc = sp_cell_faces(mesh, layout, state, &cam, &fs[1]);
  cairo_surface_t *surf = NULL;
  if (rc == SP_OK) {
    for (int i = 0; i < 3; ++i)
      if (fs[i].n) qsort(fs[i].f, fs[i].n, sizeof *fs[i].f, sp_render_cmp_far_first);
    int legend = 0;
    rc = sp_legend_height(&cam, layout->n_cells, names, path, &legend);
    if (rc == SP_OK) rc = sp_render_white_surface(cam.w, cam.h + legend, path, &surf);
  }
  if (rc == SP_OK) rc = sp_draw_surfaces(surf, &cam, fs, t, layout->n_cells, names);
  if (rc == SP_OK) rc = sp_render_png_write(surf, path);
  if (surf) cairo_surface_destroy(surf);
  for (int i = 0; i < 3; ++i) free(fs[i].f);
  return rc;
}
