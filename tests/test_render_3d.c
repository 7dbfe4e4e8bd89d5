/* Pictures of 3D states (src/io/render_surfaces.c, render_sections.c):
 *  - the c = 1/2 surface (sp_render_level_surface) of a sphere field (tanh
 *    profile) on box meshes of 8, 16, 32 hexahedra a side is closed (every
 *    edge in exactly two triangles, once each way: consistently turned),
 *    every triangle faces away from the centre, and its enclosed volume
 *    and area converge to the sphere's at second order (each order within
 *    0.3 of 2 over the three refinements);
 *  - the mid-plane sections (sp_render_sections) of a sphere centred in a
 *    box: the paper's interior colour (dark red) at the centre pixel of
 *    each panel, the background's (dark blue) at its corner pixels, and
 *    the disc c >= 1/2 (the pixels where jet's red reaches its blue: they
 *    cross at 1/2) covers pi r^2 pixels to within the pixels along its rim
 *    (2 pi r, in pixels);
 *  - with a name (a named scene's), the sections differ from the unnamed
 *    ones only within a label's box at the disc's centre in each panel,
 *    and the 3D view is the unnamed one pixel for pixel above a legend
 *    strip that holds the cell's colour;
 *  - `softpack run` of a 3D scene with pictures writes sections_<step>.png
 *    and surfaces_<step>.png picture_width wide and as high as
 *    sp_render_sections_pixel and sp_render_surfaces_pixel say, the
 *    contact graph contacts_<step>.png as large as the surfaces, and the
 *    800 x 500 energy.png. */
#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "command.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "io/render.h"

static const double pi = 3.14159265358979323846;

/* The sphere field: 1/2 on the sphere of radius R about x0, a tanh profile
 * of width W across it. */
static const double X0[3] = {0.51, 0.48, 0.5}, R = 0.3, W = 0.1;

static double sphere_field(const double *x) {
  const double r = sqrt((x[0] - X0[0]) * (x[0] - X0[0]) + (x[1] - X0[1]) * (x[1] - X0[1]) +
                        (x[2] - X0[2]) * (x[2] - X0[2]));
  return 0.5 * (1 - tanh((r - R) / W));
}

static double *nodal_field(const sp_mesh *m) {
  double *v = malloc(sizeof *v * (size_t)m->n_nodes);
  for (int i = 0; i < m->n_nodes; ++i) v[i] = sphere_field(m->xy + 3 * (size_t)i);
  return v;
}

static int cmp_point(const void *a, const void *b) {
  const double *x = a, *y = b;
  for (int d = 0; d < 3; ++d)
    if (x[d] != y[d]) return x[d] < y[d] ? -1 : 1;
  return 0;
}

static int cmp_edge(const void *a, const void *b) {
  const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

/** The vertex number of point @p x among the sorted distinct points. */
static int64_t point_id(const double *pts, size_t n, const double *x) {
  const double *hit = bsearch(x, pts, n, 3 * sizeof(double), cmp_point);
  return hit ? (hit - pts) / 3 : -1;
}

/** Closedness, orientation, volume and area of the surface on an n^3 box. */
static void level_surface(int n, double *volume, double *area) {
  sp_mesh *m;
  CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, 1, n, n, n, &m));
  double *v = nodal_field(m), *tri;
  size_t nt;
  CHECK_OK(sp_render_level_surface(m, v, 0.5, &tri, &nt));
  CHECK(nt > 0, "n = %d: no triangles", n);
  /* the distinct vertices, matched by their exact coordinates */
  double *pts = malloc(sizeof *pts * 9 * nt);
  memcpy(pts, tri, sizeof *pts * 9 * nt);
  qsort(pts, 3 * nt, 3 * sizeof(double), cmp_point);
  size_t np = 0;
  for (size_t i = 0; i < 3 * nt; ++i)
    if (np == 0 || cmp_point(pts + 3 * i, pts + 3 * (np - 1)) != 0) {
      memmove(pts + 3 * np, pts + 3 * i, 3 * sizeof(double));
      ++np;
    }
  /* directed edges a -> b as a * np + b: closed and consistently turned
   * means each appears once and so does its reverse */
  int64_t *edge = malloc(sizeof *edge * 3 * nt);
  *volume = *area = 0;
  int inward = 0, degenerate = 0;
  for (size_t t = 0; t < nt; ++t) {
    const double *p = tri + 9 * t;
    int64_t id[3];
    for (int a = 0; a < 3; ++a) id[a] = point_id(pts, np, p + 3 * a);
    degenerate += id[0] == id[1] || id[1] == id[2] || id[0] == id[2];
    for (int a = 0; a < 3; ++a) edge[3 * t + a] = id[a] * (int64_t)np + id[(a + 1) % 3];
    double e1[3], e2[3], c[3], nrm[3];
    for (int d = 0; d < 3; ++d) {
      e1[d] = p[3 + d] - p[d];
      e2[d] = p[6 + d] - p[d];
      c[d] = (p[d] + p[3 + d] + p[6 + d]) / 3 - X0[d];
    }
    nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
    nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
    nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
    inward += nrm[0] * c[0] + nrm[1] * c[1] + nrm[2] * c[2] <= 0;
    *area += 0.5 * sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    /* divergence theorem: V = sum over triangles of p0 . (p1 x p2) / 6 */
    *volume += (p[0] * (p[4] * p[8] - p[5] * p[7]) - p[1] * (p[3] * p[8] - p[5] * p[6]) +
                p[2] * (p[3] * p[7] - p[4] * p[6])) / 6;
  }
  qsort(edge, 3 * nt, sizeof *edge, cmp_edge);
  int repeated = 0, unmatched = 0;
  for (size_t i = 0; i < 3 * nt; ++i) {
    if (i + 1 < 3 * nt && edge[i + 1] == edge[i]) ++repeated;
    const int64_t a = edge[i] / (int64_t)np, b = edge[i] % (int64_t)np;
    const int64_t back = b * (int64_t)np + a;
    if (!bsearch(&back, edge, 3 * nt, sizeof *edge, cmp_edge)) ++unmatched;
  }
  printf("n = %2d: %zu triangles, %zu vertices, volume %.10f, area %.10f\n", n, nt, np, *volume,
         *area);
  CHECK(degenerate == 0, "n = %d: %d degenerate triangles", n, degenerate);
  CHECK(repeated == 0, "n = %d: %d directed edges in two triangles", n, repeated);
  CHECK(unmatched == 0, "n = %d: %d edges in one triangle only", n, unmatched);
  CHECK(inward == 0, "n = %d: %d of %zu triangles face the centre", n, inward, nt);
  free(edge);
  free(pts);
  free(tri);
  free(v);
  sp_mesh_destroy(&m);
}

static void level_surface_converges(void) {
  const double v_exact = 4.0 / 3.0 * pi * R * R * R, a_exact = 4 * pi * R * R;
  double ev[3], ea[3];
  for (int i = 0; i < 3; ++i) {
    double v, a;
    level_surface(8 << i, &v, &a);
    ev[i] = fabs(v - v_exact);
    ea[i] = fabs(a - a_exact);
    printf("  volume error %.3e, area error %.3e\n", ev[i], ea[i]);
  }
  for (int i = 1; i < 3; ++i) {
    const double ov = log2(ev[i - 1] / ev[i]), oa = log2(ea[i - 1] / ea[i]);
    printf("  orders %d -> %d: volume %.3f, area %.3f\n", 4 << i, 8 << i, ov, oa);
    CHECK(fabs(ov - 2) <= 0.3, "volume order %.3f", ov);
    CHECK(fabs(oa - 2) <= 0.3, "area order %.3f", oa);
  }
}

/** Pixel (i, j) of a PNG read back: r, g, b in 0..255. */
static void pixel(cairo_surface_t *s, int i, int j, int rgb[3]) {
  const uint32_t p =
      *(const uint32_t *)(cairo_image_surface_get_data(s) +
                          (size_t)j * cairo_image_surface_get_stride(s) + 4 * (size_t)i);
  rgb[0] = p >> 16 & 0xff, rgb[1] = p >> 8 & 0xff, rgb[2] = p & 0xff;
}

/** The pixels of @p b that differ from @p a's (same width; a's rows
 *  only): within (half-width @p rx, half-height @p ry) of one of the @p n
 *  points (px[i], py[i]) into near[i], elsewhere into *far. */
static void differences(cairo_surface_t *a, cairo_surface_t *b, int n, const double *px,
                        const double *py, double rx, double ry, int *near, int *far) {
  *far = 0;
  for (int i = 0; i < n; ++i) near[i] = 0;
  for (int j = 0; j < cairo_image_surface_get_height(a); ++j)
    for (int i = 0; i < cairo_image_surface_get_width(a); ++i) {
      int ca[3], cb[3], inside = 0;
      pixel(a, i, j, ca);
      pixel(b, i, j, cb);
      const int differs = ca[0] != cb[0] || ca[1] != cb[1] || ca[2] != cb[2];
      for (int k = 0; k < n; ++k)
        if (fabs(i + 0.5 - px[k]) <= rx && fabs(j + 0.5 - py[k]) <= ry) {
          near[k] += differs;
          inside = 1;
        }
      *far += differs && !inside;
    }
}

/** A named sphere: its name in each section panel at the disc's centre,
 *  and nothing else changed; the 3D view the unnamed one's pixel for pixel
 *  above a legend strip holding the cell's colour (the first of the view's
 *  palette, 0.86 0.25 0.20). */
static void names_on_3d_pictures(const sp_mesh *m, const sp_layout *l, const double *state,
                                 const double *centre) {
  const int width = 600;
  const sp_cell_name names[1] = {"P0"};
  CHECK_OK(sp_render_sections(m, l, state, 0.125, names, width, "test_render_3d_named.png"));
  cairo_surface_t *a = cairo_image_surface_create_from_png("test_render_3d_sections.png");
  cairo_surface_t *b = cairo_image_surface_create_from_png("test_render_3d_named.png");
  CHECK(cairo_image_surface_get_width(b) == width &&
            cairo_image_surface_get_height(b) == cairo_image_surface_get_height(a),
        "the named sections are %d x %d", cairo_image_surface_get_width(b),
        cairo_image_surface_get_height(b));
  double px[3], py[3];
  for (int p = 0; p < 3; ++p) CHECK_OK(sp_render_sections_pixel(m, width, p, centre, &px[p], &py[p], NULL));
  const double font = fmax(10.0, width / 60.0); /* the sections' font */
  int near[3], far;
  differences(a, b, 3, px, py, 1.5 * font, font, near, &far);
  printf("sections named: %d, %d, %d pixels differ at the panels' centres, %d elsewhere\n",
         near[0], near[1], near[2], far);
  CHECK(near[0] > 0 && near[1] > 0 && near[2] > 0, "no name in a panel: %d, %d, %d", near[0],
        near[1], near[2]);
  CHECK(far == 0, "%d pixels away from the names differ", far);
  cairo_surface_destroy(a);
  cairo_surface_destroy(b);

  CHECK_OK(sp_render_surfaces(m, l, state, 0.125, NULL, width, "test_render_3d_view.png"));
  CHECK_OK(sp_render_surfaces(m, l, state, 0.125, names, width, "test_render_3d_view_named.png"));
  a = cairo_image_surface_create_from_png("test_render_3d_view.png");
  b = cairo_image_surface_create_from_png("test_render_3d_view_named.png");
  int h;
  CHECK_OK(sp_render_surfaces_pixel(m, width, centre, NULL, NULL, &h));
  const int hb = cairo_image_surface_get_height(b);
  CHECK(cairo_image_surface_get_height(a) == h && hb > h, "the view is %d px high, named %d",
        cairo_image_surface_get_height(a), hb);
  if (hb > h) {
    differences(a, b, 0, NULL, NULL, 0, 0, NULL, &far);
    CHECK(far == 0, "%d pixels of the named view above its legend differ", far);
    int swatch = 0;
    for (int j = h; j < hb; ++j)
      for (int i = 0; i < width; ++i) {
        int rgb[3];
        pixel(b, i, j, rgb);
        swatch += abs(rgb[0] - 219) <= 1 && abs(rgb[1] - 64) <= 1 && abs(rgb[2] - 51) <= 1;
      }
    printf("surfaces named: legend strip %d px high, %d px of the cell's colour\n", hb - h,
           swatch);
    CHECK(swatch > 0, "the legend strip has no pixel of the cell's colour");
  }
  cairo_surface_destroy(a);
  cairo_surface_destroy(b);
}

static void sections_of_a_sphere(void) {
  sp_mesh *m;
  CHECK_OK(sp_mesh_box(0, 0, 0, 1, 1, 1, 24, 24, 24, &m));
  sp_layout *l;
  CHECK_OK(sp_layout_create_full(m->n_nodes, 1, &l));
  double *state = calloc(2 * (size_t)m->n_nodes, sizeof *state);
  const double centre[3] = {0.5, 0.5, 0.5};
  for (int i = 0; i < m->n_nodes; ++i) {
    const double *x = m->xy + 3 * (size_t)i;
    const double r = sqrt((x[0] - 0.5) * (x[0] - 0.5) + (x[1] - 0.5) * (x[1] - 0.5) +
                          (x[2] - 0.5) * (x[2] - 0.5));
    state[2 * sp_layout_pair(l, 0, i)] = 0.5 * (1 - tanh((r - R) / W));
  }
  const int width = 600;
  CHECK_OK(sp_render_sections(m, l, state, 0.125, NULL, width, "test_render_3d_sections.png"));
  cairo_surface_t *png = cairo_image_surface_create_from_png("test_render_3d_sections.png");
  CHECK(cairo_surface_status(png) == CAIRO_STATUS_SUCCESS, "cannot read the sections back");
  int h;
  CHECK_OK(sp_render_sections_pixel(m, width, 0, centre, NULL, NULL, &h));
  CHECK(cairo_image_surface_get_width(png) == width && cairo_image_surface_get_height(png) == h,
        "sections are %d x %d, expected %d x %d", cairo_image_surface_get_width(png),
        cairo_image_surface_get_height(png), width, h);
  for (int a = 0; a < 3; ++a) {
    double px, py, x0, y0, x1, y1;
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    CHECK_OK(sp_render_sections_pixel(m, width, a, centre, &px, &py, NULL));
    CHECK_OK(sp_render_sections_pixel(m, width, a, lo, &x0, &y1, NULL)); /* bottom left */
    CHECK_OK(sp_render_sections_pixel(m, width, a, hi, &x1, &y0, NULL)); /* top right */
    const double scale = x1 - x0;                                       /* px per unit */
    int rgb[3];
    /* jet(1) = (0.5, 0, 0) inside, jet(0) = (0, 0, 0.5) outside */
    pixel(png, (int)floor(px), (int)floor(py), rgb);
    CHECK(abs(rgb[0] - 128) <= 2 && rgb[1] == 0 && rgb[2] == 0,
          "panel %d centre pixel (%d, %d, %d)", a, rgb[0], rgb[1], rgb[2]);
    pixel(png, (int)ceil(x0), (int)ceil(y0), rgb);
    CHECK(rgb[0] == 0 && rgb[1] == 0 && abs(rgb[2] - 128) <= 2,
          "panel %d corner pixel (%d, %d, %d)", a, rgb[0], rgb[1], rgb[2]);
    long disc = 0;
    for (int j = (int)ceil(y0); j < (int)floor(y1); ++j)
      for (int i = (int)ceil(x0); i < (int)floor(x1); ++i) {
        pixel(png, i, j, rgb);
        disc += rgb[0] > rgb[2]; /* jet's red passes its blue at 1/2 */
      }
    const double rp = R * scale, expect = pi * rp * rp, rim = 2 * pi * rp;
    printf("panel %d: %.1f px per unit, disc %ld px, pi r^2 = %.1f px, rim %.1f px\n", a, scale,
           disc, expect, rim);
    CHECK(fabs(disc - expect) <= rim, "panel %d: disc of %ld px, pi r^2 = %.1f (rim %.1f)", a,
          disc, expect, rim);
  }
  cairo_surface_destroy(png);
  names_on_3d_pictures(m, l, state, centre);
  free(state);
  sp_layout_destroy(&l);
  sp_mesh_destroy(&m);
}

/** Width and height of a PNG, or -1 if it cannot be read or is empty. */
static void png_size(const char *path, int *w, int *h) {
  cairo_surface_t *png = cairo_image_surface_create_from_png(path);
  *w = *h = -1;
  if (cairo_surface_status(png) == CAIRO_STATUS_SUCCESS) {
    *w = cairo_image_surface_get_width(png);
    *h = cairo_image_surface_get_height(png);
  }
  cairo_surface_destroy(png);
}

static void run_writes_pictures(void) {
  const char *scene = SP_SOURCE_DIR "/tests/scenes/two_spheres_3d.yaml";
  char out[8192];
  const int status = run_softpack(
      "run " SP_SOURCE_DIR "/tests/scenes/two_spheres_3d.yaml --quiet --out test_render_3d_run "
      "--set output.pictures=true --set output.picture_width=500 --set time.max_steps=1 "
      "--set output.every=1 --set mesh.nx=8 --set mesh.ny=8 --set mesh.nz=8",
      out, sizeof out);
  CHECK(status == 0, "softpack run %s: exit %d: %s", scene, status, out);
  sp_mesh *m;
  CHECK_OK(sp_mesh_box(0, 0, 0, 0.6, 0.6, 0.6, 8, 8, 8, &m));
  const double x[3] = {0.3, 0.3, 0.3};
  int hs, hv;
  CHECK_OK(sp_render_sections_pixel(m, 500, 0, x, NULL, NULL, &hs));
  CHECK_OK(sp_render_surfaces_pixel(m, 500, x, NULL, NULL, &hv));
  struct {
    const char *name;
    int w, h;
  } expect[] = {{"sections_000000.png", 500, hs}, {"sections_000001.png", 500, hs},
                {"surfaces_000000.png", 500, hv}, {"surfaces_000001.png", 500, hv},
                {"contacts_000001.png", 500, hv},
                {"energy.png", 800, 500}};
  for (size_t i = 0; i < sizeof expect / sizeof *expect; ++i) {
    char path[256];
    snprintf(path, sizeof path, "test_render_3d_run/%s", expect[i].name);
    int w, h;
    png_size(path, &w, &h);
    printf("%s: %d x %d\n", path, w, h);
    CHECK(w == expect[i].w && h == expect[i].h, "%s is %d x %d, expected %d x %d", path, w, h,
          expect[i].w, expect[i].h);
  }
  sp_mesh_destroy(&m);
}

int main(void) {
  level_surface_converges();
  sections_of_a_sphere();
  run_writes_pictures();
  TEST_DONE();
}
