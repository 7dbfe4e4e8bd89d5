/* Output and rendering: CSV logs round-trip exactly, the .vtu holds the
 * right sizes and values (decoded from its base64), fields.pvd lists every
 * output once, the PNGs are PNGs with the paper's colours where expected,
 * a named scene's .vtu holds its cells' names (cell_name) and its cells
 * picture their labels, differing from the unnamed picture only within the
 * labels' boxes, and a directory that cannot be created is an SP_ERR_IO
 * naming the path.
 *
 * The mesh is built by hand (a 6 x 3 rectangle of unit-free quads) so this
 * test depends on no other module than layout and error. */
#define _POSIX_C_SOURCE 200809L

#include <cairo.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "mesh/layout.h"
#include "io/output.h"
#include "io/render.h"
#include "output_read.h"

#define DIR "test_output_tmp/run/a"
#define NX 6
#define NY 3
#define NN ((NX + 1) * (NY + 1))
#define NE (NX * NY)

/* ---- helpers ----------------------------------------------------------- */

static int exists(const char *path) {
  FILE *f = fopen(path, "rb");
  if (f) fclose(f);
  return f != NULL;
}

/* The data of DataArray @p name in @p xml, which must hold @p expect_bytes;
 * malloc'd, NULL if absent. */
static unsigned char *vtu_array(const char *xml, const char *name,
                                size_t expect_bytes) {
  size_t n = 0;
  unsigned char *data = vtu_array_data(xml, name, &n);
  CHECK(data && n == expect_bytes, "array %s: %zu bytes decoded, expected %zu", name,
        data ? n : 0, expect_bytes);
  if (data && n != expect_bytes) {
    free(data);
    return NULL;
  }
  return data;
}

static int count_substr(const char *s, const char *sub) {
  int n = 0;
  for (const char *p = s; (p = strstr(p, sub)); p += strlen(sub)) ++n;
  return n;
}

static int xml_int_attr(const char *xml, const char *attr) {
  char key[64];
  snprintf(key, sizeof key, "%s=\"", attr);
  const char *p = strstr(xml, key);
  return p ? atoi(p + strlen(key)) : -1;
}

static int is_png(const char *path) {
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a,
                                       0x1a, 0x0a};
  unsigned char buf[8] = {0};
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  size_t n = fread(buf, 1, 8, f);
  fclose(f);
  return n == 8 && memcmp(buf, sig, 8) == 0;
}

/* RGB in [0,1] of pixel (i, j) of a PNG read back with cairo. */
static void png_pixel(cairo_surface_t *s, int i, int j, double rgb[3]) {
  cairo_surface_flush(s);
  const unsigned char *d = cairo_image_surface_get_data(s);
  uint32_t v;
  memcpy(&v, d + (size_t)j * cairo_image_surface_get_stride(s) + 4 * i, 4);
  rgb[0] = (v >> 16 & 255) / 255.0;
  rgb[1] = (v >> 8 & 255) / 255.0;
  rgb[2] = (v & 255) / 255.0;
}

/* ---- the test problem ----------------------------------------------------
 * Node (ix, iy) = ix + (NX + 1) iy at (0.5 ix, 0.5 iy).
 * Columns ix 0-1: cell 1 inside (c_1 = 0.9, c_2 = 0.2)  -> cell_id 1
 *         ix 2:   both 0.3 (between)                    -> 0
 *         ix 3:   both 0.05 (background)                -> 0
 *         ix 4-6: cell 2 inside (c_1 = 0.1, c_2 = 0.8)  -> 2 */
static int node(int ix, int iy) { return ix + (NX + 1) * iy; }

static void column_values(int ix, double c[2]) {
  if (ix <= 1) c[0] = 0.9, c[1] = 0.2;
  else if (ix == 2) c[0] = 0.3, c[1] = 0.3;
  else if (ix == 3) c[0] = 0.05, c[1] = 0.05;
  else c[0] = 0.1, c[1] = 0.8;
}

static int expected_id(int ix) { return ix <= 1 ? 1 : ix >= 4 ? 2 : 0; }

/* mu values that are not round in binary, to test exact round trips. */
static double mu_value(int k, int i) { return (k + 1) / 3.0 + i * 1e-3 / 7.0; }

static void fill_state(const sp_layout *l, double *state) {
  for (int i = 0; i < NN; ++i) {
    double c[2];
    column_values(i % (NX + 1), c);
    for (int p = l->node_start[i]; p < l->node_start[i + 1]; ++p) {
      state[2 * p] = c[l->pair_cell[p]];
      state[2 * p + 1] = mu_value(l->pair_cell[p], i);
    }
  }
}

int main(void) {
  /* ---- mesh by hand ---- */
  static double xy[2 * NN];
  static int elem[4 * NE], region[NE];
  for (int iy = 0; iy <= NY; ++iy)
    for (int ix = 0; ix <= NX; ++ix) {
      xy[2 * node(ix, iy)] = 0.5 * ix;
      xy[2 * node(ix, iy) + 1] = 0.5 * iy;
    }
  for (int iy = 0; iy < NY; ++iy)
    for (int ix = 0; ix < NX; ++ix) {
      int e = ix + NX * iy;
      elem[4 * e + 0] = node(ix, iy); /* counterclockwise */
      elem[4 * e + 1] = node(ix + 1, iy);
      elem[4 * e + 2] = node(ix + 1, iy + 1);
      elem[4 * e + 3] = node(ix, iy + 1);
      region[e] = ix == NX - 1 ? SP_REGION_BUFFER : SP_REGION_OMEGA;
    }
  sp_mesh mesh = {.n_nodes = NN, .n_elems = NE, .dim = 2, .nodes_per_elem = 4, .xy = xy,
                  .elem = elem,
                  .region = region, .is_ellipse = 0,
                  .bounds = {0, 0, 0.5 * NX, 0.5 * NY}, .h = 0.5};

  sp_layout *full = NULL, *masked = NULL;
  CHECK_OK(sp_layout_create_full(NN, 2, &full));
  /* masked: cell 2 is not supported on node 0 */
  unsigned char mask[2 * NN];
  memset(mask, 1, sizeof mask);
  mask[NN + 0] = 0;
  CHECK_OK(sp_layout_create_from_masks(NN, 2, mask, &masked));
  double *state = calloc(2 * (size_t)full->n_pairs, sizeof *state);
  double *state_m = calloc(2 * (size_t)masked->n_pairs, sizeof *state_m);
  fill_state(full, state);
  fill_state(masked, state_m);

  /* ---- open (creates parents), CSV rows ---- */
  sp_output out = NULL;
  CHECK_OK(sp_output_open(DIR, &out));
  CHECK(out && strcmp(sp_output_dir(out), DIR) == 0, "dir %s",
        out ? sp_output_dir(out) : "(null)");
  const double tv[3] = {0.0, 1.0 / 3.0, 2e-4 * 7.1};
  const sp_energy_parts parts[3] = {{1.0 / 3.0, 1e-300, -2.5e10, 0.1, 0},
                                    {3.14159265358979, 2.0 / 7.0, 0, 0, 0},
                                    {1e17 + 3, -0.0, 5e-324, 1.1, 0}};
  const double shape[3] = {0.0, 1.0 / 9.0, 123.456};
  /* exact in %.4g */
  const sp_step_costs seconds = {2.5, 0.25, 2.0, 0.125, 0.5, 1, 123456789, 3, 2, 17, 37.5, 4321,
                                 0.8125};
  for (int r = 0; r < 3; ++r)
    CHECK_OK(sp_output_energy(out, r * 10, tv[r], 2e-4 / 3.0, r + 2, 2,
                              &parts[r], shape[r], r == 1 ? &seconds : NULL));
  sp_cell_obs obs[2];
  memset(obs, 0, sizeof obs);
  obs[0].mass = 0.1 / 3.0, obs[0].centre[0] = 0.25;
  obs[0].axes[0][0] = cos(-1.0 / 7.0), obs[0].axes[0][1] = sin(-1.0 / 7.0);
  obs[1].mass = 2.0 / 3.0, obs[1].moments[0] = 1e-8 / 3.0;
  CHECK_OK(sp_output_cells(out, 0, 0.0, 2, obs, NULL));
  CHECK_OK(sp_output_cells(out, 10, tv[1], 2, obs, NULL));

  /* ---- two field outputs (the second on the masked layout) ---- */
  CHECK_OK(sp_output_fields(out, &mesh, full, state, 10, tv[1], NULL));
  CHECK_OK(sp_output_fields(out, &mesh, masked, state_m, 20, tv[2], NULL));

  /* ---- energy.csv: rows are there before close (flushed), exact ---- */
  {
    char *csv = slurp(DIR "/energy.csv", NULL);
    CHECK(csv != NULL, "energy.csv missing");
    if (csv) {
      static const char header[] = "step,t,dt,newton_its,n_cells,energy,bulk,gradient,"
                                   "repulsion,buffer,shape,seconds,assembly_s,"
                                   "factorisation_s,solves_s,supports_s,support_changed,"
                                   "unknowns,factorisations,failed_attempts,"
                                   "failed_factorisations,residual_rise,linear_its,"
                                   "error_estimate\n";
      CHECK(strncmp(csv, header, strlen(header)) == 0,
            "energy.csv header: %.80s", csv);
      int rows = 0;
      char *line = strchr(csv, '\n') + 1;
      while (*line) {
        char *end;
        long step = strtol(line, &end, 10);
        double v[12];
        long ints[6];
        double t = strtod(end + 1, &end);
        double dt = strtod(end + 1, &end);
        ints[0] = strtol(end + 1, &end, 10);
        ints[1] = strtol(end + 1, &end, 10);
        for (int j = 0; j < 12; ++j) v[j] = strtod(end + 1, &end);
        ints[2] = strtol(end + 1, &end, 10);
        ints[3] = strtol(end + 1, &end, 10);
        ints[4] = strtol(end + 1, &end, 10);
        ints[5] = strtol(end + 1, &end, 10);
        const double rise = strtod(end + 1, &end);
        const long linear_its = strtol(end + 1, &end, 10);
        const double error_estimate = strtod(end + 1, &end);
        CHECK(*end == '\n', "row %d ends with '%c'", rows, *end);
        if (rows < 3) {
          const sp_step_costs w =
              rows == 1 ? seconds : (sp_step_costs){.error_estimate = -1}; /* NULL: none */
          CHECK(error_estimate == w.error_estimate, "row %d error estimate %g, expected %g",
                rows, error_estimate, w.error_estimate);
          CHECK(v[6] == w.step && v[7] == w.assembly && v[8] == w.factorisation &&
                    v[9] == w.solves && v[10] == w.supports && v[11] == w.support_changed &&
                    ints[2] == w.unknowns && ints[3] == w.factorisations &&
                    ints[4] == w.failed_attempts && ints[5] == w.failed_factorisations &&
                    rise == w.residual_rise && linear_its == w.linear_its,
                "row %d costs %g %g %g %g %g %g %ld %ld %ld %ld", rows, v[6], v[7], v[8], v[9],
                v[10], v[11], ints[2], ints[3], ints[4], ints[5]);
          const sp_energy_parts *p = &parts[rows];
          double total = p->bulk + p->gradient + p->repulsion + p->buffer +
                         shape[rows];
          CHECK(step == rows * 10 && ints[0] == rows + 2 && ints[1] == 2,
                "row %d integers %ld %ld %ld", rows, step, ints[0], ints[1]);
          CHECK(t == tv[rows] && dt == 2e-4 / 3.0, "row %d t %.17g dt %.17g",
                rows, t, dt);
          CHECK(v[0] == total && v[1] == p->bulk && v[2] == p->gradient &&
                    v[3] == p->repulsion && v[4] == p->buffer &&
                    v[5] == shape[rows],
                "row %d values do not round-trip", rows);
        }
        ++rows;
        line = end + 1;
      }
      CHECK(rows == 3, "energy.csv has %d rows, expected 3", rows);
      free(csv);
    }
  }

  /* ---- cells.csv ---- */
  {
    char *csv = slurp(DIR "/cells.csv", NULL);
    CHECK(csv && strncmp(csv, "step,t,cell,mass,xc,yc,I1,I2,angle,core_mass,area\n", 50) == 0,
          "cells.csv header");
    if (csv) {
      CHECK(count_substr(csv, "\n") == 5, "cells.csv: %d lines, expected 5",
            count_substr(csv, "\n"));
      char *row = strchr(csv, '\n') + 1; /* step 0, cell 1 */
      char *end;
      strtol(row, &end, 10);
      strtod(end + 1, &end);
      long cell = strtol(end + 1, &end, 10);
      double mass = strtod(end + 1, &end);
      double xc = strtod(end + 1, &end);
      for (int j = 0; j < 3; ++j) strtod(end + 1, &end);
      double angle = strtod(end + 1, &end);
      CHECK(cell == 1 && mass == obs[0].mass && xc == 0.25 &&
                angle == sp_cells_obs_angle(&obs[0], 2),
            "cells.csv row 1: cell %ld mass %.17g angle %.17g", cell, mass,
            angle);
      free(csv);
    }
  }

  /* ---- the first .vtu ---- */
  {
    char *xml = slurp(DIR "/fields_000010.vtu", NULL);
    CHECK(xml != NULL, "fields_000010.vtu missing");
    if (xml) {
      CHECK(xml_int_attr(xml, "NumberOfPoints") == NN, "NumberOfPoints %d",
            xml_int_attr(xml, "NumberOfPoints"));
      CHECK(xml_int_attr(xml, "NumberOfCells") == NE, "NumberOfCells %d",
            xml_int_attr(xml, "NumberOfCells"));
      CHECK(strstr(xml, "type=\"UnstructuredGrid\"") != NULL, "type");
      int32_t *id = (int32_t *)vtu_array(xml, "cell_id", NN * 4);
      double *c1 = (double *)vtu_array(xml, "c_1", NN * 8);
      double *mu2 = (double *)vtu_array(xml, "mu_2", NN * 8);
      double *pts = (double *)vtu_array(xml, "Points", NN * 24);
      int32_t *conn = (int32_t *)vtu_array(xml, "connectivity", NE * 16);
      unsigned char *types = vtu_array(xml, "types", NE);
      int32_t *reg = (int32_t *)vtu_array(xml, "region", NE * 4);
      CHECK(id && c1 && mu2 && pts && conn && types && reg, "arrays missing");
      if (id && c1 && mu2 && pts && conn && types && reg) {
        /* node (1,1): c_1 = 0.9, c_2 = 0.2 -> 1; node (3,1): both < 1/2 -> 0 */
        CHECK(id[node(1, 1)] == 1, "cell_id at c=(0.9,0.2): %d",
              id[node(1, 1)]);
        CHECK(id[node(3, 1)] == 0, "cell_id at c=(0.05,0.05): %d",
              id[node(3, 1)]);
        int bad = 0;
        for (int i = 0; i < NN; ++i) {
          int ix = i % (NX + 1);
          double c[2];
          column_values(ix, c);
          bad += id[i] != expected_id(ix) || c1[i] != c[0] ||
                 mu2[i] != mu_value(1, i) || pts[3 * i] != xy[2 * i] ||
                 pts[3 * i + 1] != xy[2 * i + 1] || pts[3 * i + 2] != 0.0;
        }
        CHECK(bad == 0, "%d nodes with wrong cell_id, c_1, mu_2 or Points",
              bad);
        bad = 0;
        for (int e = 0; e < NE; ++e)
          bad += types[e] != 9 || reg[e] != region[e] ||
                 memcmp(conn + 4 * e, elem + 4 * e, 16) != 0;
        CHECK(bad == 0, "%d elements with wrong type, region or nodes", bad);
      }
      free(id), free(c1), free(mu2), free(pts), free(conn), free(types),
          free(reg);
      free(xml);
    }
  }

  /* ---- the second .vtu: c_2 is 0 off its support ---- */
  {
    char *xml = slurp(DIR "/fields_000020.vtu", NULL);
    CHECK(xml != NULL, "fields_000020.vtu missing");
    if (xml) {
      double *c2 = (double *)vtu_array(xml, "c_2", NN * 8);
      double *mu2 = (double *)vtu_array(xml, "mu_2", NN * 8);
      if (c2 && mu2) {
        CHECK(c2[0] == 0.0 && mu2[0] == 0.0, "off-support c_2 %g mu_2 %g",
              c2[0], mu2[0]);
        CHECK(c2[1] == 0.2 && c2[node(5, 2)] == 0.8, "c_2 %g %g", c2[1],
              c2[node(5, 2)]);
      }
      free(c2), free(mu2);
      free(xml);
    }
  }

  /* ---- fields.pvd lists both files once, even after a rewrite ---- */
  for (int pass = 0; pass < 2; ++pass) {
    char *pvd = slurp(DIR "/fields.pvd", NULL);
    CHECK(pvd != NULL, "fields.pvd missing");
    if (pvd) {
      CHECK(count_substr(pvd, "<DataSet") == 2, "pass %d: %d DataSets", pass,
            count_substr(pvd, "<DataSet"));
      CHECK(strstr(pvd, "file=\"fields_000010.vtu\"") &&
                strstr(pvd, "file=\"fields_000020.vtu\""),
            "pass %d: files not listed", pass);
      const char *p = strstr(pvd, "timestep=\"");
      double t = p ? strtod(p + 10, NULL) : -1;
      CHECK(t == tv[1], "pass %d: first timestep %.17g", pass, t);
      free(pvd);
    }
    /* Writing step 20 again (a redone step) must replace, not append. */
    if (pass == 0)
      CHECK_OK(sp_output_fields(out, &mesh, masked, state_m, 20, tv[2], NULL));
  }
  CHECK(!exists(DIR "/fields.pvd.tmp") && !exists(DIR "/fields_000010.vtu.tmp"),
        "temporary files left behind");

  CHECK_OK(sp_output_close(&out));
  CHECK(out == NULL, "close must NULL the handle");
  CHECK_OK(sp_output_close(&out)); /* twice is harmless */

  /* ---- cells picture ---- */
  {
    const char *png = "test_output_tmp/cells.png";
    const int width = 480;
    remove(png);
    CHECK_OK(sp_render_cells(&mesh, full, state, 1.234e-2, NULL, width, png));
    CHECK(is_png(png), "%s is not a PNG", png);
    CHECK(!exists("test_output_tmp/cells.png.tmp"), "cells.png.tmp left");
    cairo_surface_t *s = cairo_image_surface_create_from_png(png);
    CHECK(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS, "cannot read %s",
          png);
    if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
      int h = 0;
      double px, py, rgb[3];
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 0.5, 0.5, &px, &py, &h));
      CHECK(cairo_image_surface_get_width(s) == width &&
                cairo_image_surface_get_height(s) == h,
            "size %dx%d, expected %dx%d", cairo_image_surface_get_width(s),
            cairo_image_surface_get_height(s), width, h);
      /* inside cell 1 (node (1,1), phi = 0.9): red */
      png_pixel(s, (int)px, (int)py, rgb);
      CHECK(rgb[0] > 0.5 && rgb[2] < 0.3, "interior pixel (%d,%d) rgb "
            "%.2f %.2f %.2f is not reddish", (int)px, (int)py, rgb[0], rgb[1],
            rgb[2]);
      /* background (node (3,1), phi = 0.05): blue */
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 1.5, 0.5, &px, &py, NULL));
      png_pixel(s, (int)px, (int)py, rgb);
      CHECK(rgb[2] > 0.5 && rgb[0] < 0.3, "background pixel rgb %.2f %.2f "
            "%.2f is not bluish", rgb[0], rgb[1], rgb[2]);
      /* the margin is white */
      png_pixel(s, 1, h - 2, rgb);
      CHECK(rgb[0] > 0.99 && rgb[1] > 0.99 && rgb[2] > 0.99,
            "margin pixel %.2f %.2f %.2f is not white", rgb[0], rgb[1],
            rgb[2]);
    }
    cairo_surface_destroy(s);
  }

  /* ---- a named scene's fields: FieldData's cell_name, one string a cell
   * (an unnamed cell's ""), and none in an unnamed scene's .vtu ---- */
  {
    const sp_cell_name names[2] = {"AB", ""};
    sp_output named = NULL;
    CHECK_OK(sp_output_open_dim("test_output_tmp/named", 2, 1, &named));
    CHECK_OK(sp_output_fields(named, &mesh, full, state, 3, 0.5, names));
    CHECK_OK(sp_output_close(&named));
    char *xml = slurp("test_output_tmp/named/fields_000003.vtu", NULL);
    char got[3][32];
    const int n = xml ? vtu_strings(xml, "cell_name", got, 3) : -1;
    CHECK(n == 2 && !strcmp(got[0], "AB") && !strcmp(got[1], ""),
          "named .vtu: %d names (%s, %s)", n, n > 0 ? got[0] : "-", n > 1 ? got[1] : "-");
    free(xml);
    xml = slurp(DIR "/fields_000010.vtu", NULL);
    CHECK(xml && !strstr(xml, "cell_name"), "an unnamed scene's .vtu has cell_name");
    free(xml);
  }

  /* ---- names on the cells picture: each cell's label at the mean of its
   * nodes (cell 1: columns 0-1, centre (0.25, 0.75); cell 2: columns 4-6,
   * (2.5, 0.75); nodes 0.5 apart); every pixel farther than a label's box from both is the
   * unnamed picture's ---- */
  {
    const int width = 480;
    const sp_cell_name names[2] = {"AB", ""}; /* cell 2 is labelled "2" */
    CHECK_OK(sp_render_cells(&mesh, full, state, 1.234e-2, names, width,
                             "test_output_tmp/cells_named.png"));
    cairo_surface_t *a = cairo_image_surface_create_from_png("test_output_tmp/cells.png");
    cairo_surface_t *b = cairo_image_surface_create_from_png("test_output_tmp/cells_named.png");
    CHECK(cairo_surface_status(b) == CAIRO_STATUS_SUCCESS &&
              cairo_image_surface_get_width(a) == cairo_image_surface_get_width(b) &&
              cairo_image_surface_get_height(a) == cairo_image_surface_get_height(b),
          "the named picture's size differs");
    if (cairo_surface_status(b) == CAIRO_STATUS_SUCCESS &&
        cairo_image_surface_get_height(a) == cairo_image_surface_get_height(b)) {
      const double font = fmax(10.0, width / 45.0); /* the picture's font */
      double px[2], py[2];
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 0.25, 0.75, &px[0], &py[0], NULL));
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 2.5, 0.75, &px[1], &py[1], NULL));
      int near[2] = {0, 0}, far = 0;
      for (int j = 0; j < cairo_image_surface_get_height(a); ++j)
        for (int i = 0; i < width; ++i) {
          double ca[3], cb[3];
          png_pixel(a, i, j, ca);
          png_pixel(b, i, j, cb);
          const int differs = ca[0] != cb[0] || ca[1] != cb[1] || ca[2] != cb[2];
          int inside = 0; /* a label's box: 2 bold letters and the halo */
          for (int k = 0; k < 2; ++k)
            if (fabs(i + 0.5 - px[k]) <= 1.5 * font && fabs(j + 0.5 - py[k]) <= font) {
              near[k] += differs;
              inside = 1;
            }
          far += differs && !inside;
        }
      CHECK(near[0] > 0 && near[1] > 0, "no label at the cells: %d and %d pixels differ",
            near[0], near[1]);
      CHECK(far == 0, "%d pixels away from the labels differ from the unnamed picture", far);
    }
    cairo_surface_destroy(a);
    cairo_surface_destroy(b);
  }

  /* ---- contact graph: the cells picture's frame, an edge a quarter of
   * the contact's length wide, numbered red discs at the centres ---- */
  {
    const char *png = "test_output_tmp/contacts.png";
    const int width = 480;
    const double centre[4] = {0.5, 0.5, 2.5, 0.5}, length[1] = {0.4};
    const int edge[2] = {0, 1};
    CHECK_OK(sp_render_contact_graph(&mesh, 2, centre, 1, edge, length, 1e-2, width, png));
    cairo_surface_t *s = cairo_image_surface_create_from_png(png);
    CHECK(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS, "cannot read %s", png);
    if (cairo_surface_status(s) == CAIRO_STATUS_SUCCESS) {
      int h = 0;
      double px, py, qx, rgb[3];
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 1.5, 0.5, &px, &py, &h));
      CHECK(cairo_image_surface_get_width(s) == width && cairo_image_surface_get_height(s) == h,
            "contact graph %dx%d, the cells picture %dx%d", cairo_image_surface_get_width(s),
            cairo_image_surface_get_height(s), width, h);
      CHECK_OK(sp_render_cells_pixel(&mesh, width, 2.5, 0.5, &qx, NULL, NULL));
      /* the edge's width at its middle: non-white pixels down the column */
      int wide = 0;
      for (int j = 0; j < h; ++j) {
        png_pixel(s, (int)px, j, rgb);
        const int blue = rgb[2] > 0.6 && rgb[0] < 0.5;
        wide += blue && fabs(j - py) < 20;
      }
      const double expected = 0.25 * length[0] * (qx - px) / 1.0; /* pixels per unit: qx - px */
      CHECK(fabs(wide - expected) <= 2, "edge %d px wide, expected %.1f", wide, expected);
      png_pixel(s, (int)qx, (int)(py + 0.6 * fmax(10.0, width / 45.0)), rgb);
      CHECK(rgb[0] > 0.7 && rgb[1] < 0.3, "cell 2's disc is not red: %.2f %.2f %.2f", rgb[0],
            rgb[1], rgb[2]);
    }
    cairo_surface_destroy(s);
  }

  /* ---- energy plots: normal, one point, constant ---- */
  {
    double t[50], e[50], marks[2] = {0.01, 0.03};
    for (int i = 0; i < 50; ++i) {
      t[i] = 1e-3 * i;
      e[i] = 2.0 + exp(-50.0 * t[i]) - (i > 25 ? 0.3 : 0.0);
    }
    const char *paths[3] = {"test_output_tmp/energy.png",
                            "test_output_tmp/energy1.png",
                            "test_output_tmp/energy_const.png"};
    double ec[5] = {1.5, 1.5, 1.5, 1.5, 1.5};
    CHECK_OK(sp_render_energy(t, e, 50, marks, 2, paths[0]));
    CHECK_OK(sp_render_energy(t, e, 1, NULL, 0, paths[1]));
    CHECK_OK(sp_render_energy(t, ec, 5, NULL, 0, paths[2]));
    for (int i = 0; i < 3; ++i) {
      CHECK(is_png(paths[i]), "%s is not a PNG", paths[i]);
      cairo_surface_t *s = cairo_image_surface_create_from_png(paths[i]);
      CHECK(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS &&
                cairo_image_surface_get_width(s) == 800 &&
                cairo_image_surface_get_height(s) == 500,
            "%s: not an 800x500 picture", paths[i]);
      cairo_surface_destroy(s);
    }
  }

  /* ---- a directory where a regular file is: SP_ERR_IO naming the path ---- */
  {
    FILE *f = fopen("test_output_tmp/afile", "w");
    CHECK(f != NULL, "cannot create test_output_tmp/afile");
    if (f) fclose(f);
    const char *bad[2] = {"test_output_tmp/afile", "test_output_tmp/afile/sub"};
    for (int i = 0; i < 2; ++i) {
      sp_output o = (sp_output)&mesh; /* must be reset to NULL */
      sp_error_clear();
      int rc = sp_output_open(bad[i], &o);
      CHECK(rc == SP_ERR_IO, "open %s: rc %d", bad[i], rc);
      CHECK(o == NULL, "open %s: handle not NULL", bad[i]);
      CHECK(strstr(sp_error_message(), bad[i]) != NULL,
            "message '%s' does not name %s", sp_error_message(), bad[i]);
    }
  }

  free(state);
  free(state_m);
  sp_layout_destroy(&full);
  sp_layout_destroy(&masked);
  TEST_DONE();
}
