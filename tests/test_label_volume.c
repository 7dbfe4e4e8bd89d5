/* Initial fields from a 3D label volume (initial.label_volume, src/io/initial.c),
 * on NIfTI files this test writes with libnifti2:
 * - three ellipsoidal labels (values 3, 7, 12) in a volume whose sform turns
 *   the voxel axes by 90 degrees about z and moves them, placed with
 *   initial.scale and offset_*: three cells, numbered by label value; each
 *   cell's volume (c >= 1/2) is its label's voxel volume, its mass that
 *   plus the equilibrium profile's excess, and its centre the voxels'
 *   centroid. The excess of a closed surface: across it the profile
 *   1 / (1 + e^(s/d)) differs from the step by an odd function whose first
 *   moment is pi^2 d^2 / 6 (Sommerfeld), and the area of the parallel
 *   surface at distance s grows as 1 + 2 H s (H the mean curvature), so the
 *   excess is (pi^2 d^2 / 3) int H dA = (2 pi^3 d^2 / 3) w, w the mean
 *   width (for a sphere of radius R, w = 2R: 4 pi^3 d^2 R / 3; the 2D
 *   label image's pi^3 d^2 / 3 is the same expansion with int kappa dl =
 *   2 pi). Tolerances from the voxel size h: centres within h / 2 (as the 2D
 *   label image); the volume within the layer of half a voxel over the
 *   label's surface, area * h / 2, at most, and the mass likewise, plus 2%
 *   of the excess (the voxels' staircase against the smooth ellipsoid);
 * - the same labels with a qform only (voxel sizes 0.4, 0.5, 0.6 and a
 *   flipped axis, qfac = -1) and initial.centre: the labelled voxels'
 *   bounding box centred at the offset: each cell's centre the voxels'
 *   centroid so placed, within h_max / 2;
 * - bad volumes: not NIfTI, a 2D image, non-integer labels, negative labels,
 *   no labels, a label outside the mesh, too many labels for the layout, a
 *   sheared sform, a 4D series: softpack run exits 2 naming
 *   initial.label_volume and writes nothing (the scene-level errors,
 *   missing file, wrong extension, a 2D mesh, are tests/scenes/bad/
 *   label_volume_*.yaml);
 * - a short run from a volume: the program runs it (exit 0) with its cells.
 */
#include <nifti2_io.h>
#include <string.h>
#include <sys/stat.h>

#include "model/cells.h"
#include "check.h"
#include "command.h"
#include "public/error.h"
#include "io/initial.h"
#include "mesh/layout.h"
#include "mesh/mesh.h"
#include "run/run_options.h"
#include "scene/scene.h"

#define N 120              /* voxels a side */
#define VOXEL 0.5          /* the file's unit (say um) */
#define SCALE 0.01         /* mesh length per file unit */
enum { N_LABELS = 3 };
static const double offset[3] = {0.01, -0.02, 0.015};
static const struct {
  double c[3], s[3];
  int value;
} ellipsoids[N_LABELS] = {{{0.11, -0.06, 0.05}, {0.07, 0.08, 0.09}, 7},
                          {{-0.12, -0.08, 0.0}, {0.09, 0.07, 0.08}, 3},
                          {{0.0, 0.14, -0.06}, {0.10, 0.06, 0.07}, 12}};
/* cells by ascending label value: 3, 7, 12 */
static const int cell_of_entry[N_LABELS] = {1, 0, 2};

/** The label value at mesh point x (0: none). */
static int label_at(const double *x) {
  for (int e = 0; e < N_LABELS; ++e) {
    double r = 0;
    for (int a = 0; a < 3; ++a) {
      const double u = (x[a] - ellipsoids[e].c[a]) / ellipsoids[e].s[a];
      r += u * u;
    }
    if (r <= 1) return ellipsoids[e].value;
  }
  return 0;
}

/** The mean width of an ellipsoid with semi-axes s: the mean over
 *  directions u of 2 h(u), h(u) = |diag(s) u| its support function
 *  (midpoint rule in theta, phi). */
static double mean_width(const double *s) {
  enum { NT = 400, NP = 800 };
  double sum = 0;
  for (int i = 0; i < NT; ++i) {
    const double t = (i + 0.5) * M_PI / NT;
    for (int j = 0; j < NP; ++j) {
      const double p = (j + 0.5) * 2 * M_PI / NP;
      const double u[3] = {sin(t) * cos(p), sin(t) * sin(p), cos(t)};
      sum += 2 * sqrt(s[0] * s[0] * u[0] * u[0] + s[1] * s[1] * u[1] * u[1] +
                      s[2] * s[2] * u[2] * u[2]) * sin(t);
    }
  }
  return sum * (M_PI / NT) * (2 * M_PI / NP) / (4 * M_PI);
}

/** What a volume's labels are: per cell the voxel count, centroid, and the
 *  area of the voxel faces between it and the rest. */
typedef struct {
  double volume[N_LABELS], centre[N_LABELS][3], faces[N_LABELS];
} label_stats;

/** A volume of n[0] x n[1] x n[2] voxels of @p type written to @p path,
 *  with the voxel -> file-coordinates affine m (sform) or, with qform set,
 *  voxel sizes h and a qform of qfac -1 (the k axis flipped) moved by m's
 *  last column. @p value gives each voxel. */
static void write_volume(const char *path, const int n[3], int type, const double m[3][4],
                         int qform, const double h[3], double (*value)(size_t, size_t, size_t,
                                                                        void *), void *ctx) {
  const int64_t dims[8] = {3, n[0], n[1], n[2], 1, 1, 1, 1};
  nifti_image *nim = nifti_make_new_nim(dims, type, 1);
  CHECK(nim, "nifti_make_new_nim");
  for (size_t k = 0; k < (size_t)n[2]; ++k)
    for (size_t j = 0; j < (size_t)n[1]; ++j)
      for (size_t i = 0; i < (size_t)n[0]; ++i) {
        const size_t v = i + (size_t)n[0] * (j + (size_t)n[1] * k);
        const double x = value(i, j, k, ctx);
        switch (type) {
        case NIFTI_TYPE_UINT16: ((uint16_t *)nim->data)[v] = (uint16_t)x; break;
        case NIFTI_TYPE_INT16: ((int16_t *)nim->data)[v] = (int16_t)x; break;
        case NIFTI_TYPE_FLOAT32: ((float *)nim->data)[v] = (float)x; break;
        default: CHECK(0, "type %d", type);
        }
      }
  if (qform) {
    nim->qform_code = 1;
    nim->sform_code = 0;
    nim->quatern_b = nim->quatern_c = nim->quatern_d = 0;
    nim->qfac = -1;
    nim->qoffset_x = m[0][3];
    nim->qoffset_y = m[1][3];
    nim->qoffset_z = m[2][3];
  } else {
    nim->qform_code = 0;
    nim->sform_code = 1;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) nim->sto_xyz.m[r][c] = m[r][c];
    nim->sto_xyz.m[3][3] = 1;
  }
  nim->dx = nim->pixdim[1] = h[0];
  nim->dy = nim->pixdim[2] = h[1];
  nim->dz = nim->pixdim[3] = h[2];
  nim->xyz_units = NIFTI_UNITS_MICRON;
  CHECK(nifti_set_filenames(nim, path, 0, 1) == 0, "nifti_set_filenames %s", path);
  nifti_image_write(nim);
  nifti_image_free(nim);
}

/* The volume of the first case: the sform turns i to +y, j to -x, k to +z
 * (90 degrees about z) with voxel size VOXEL, and moves the origin; with
 * SCALE and the offset the grid covers the mesh box [-0.3, 0.3]^3. */
static const double sform[3][4] = {{0, -VOXEL, 0, 30}, {VOXEL, 0, 0, -30}, {0, 0, VOXEL, -30}};

static void voxel_mesh_point(const double m[3][4], const double *shift, size_t i, size_t j,
                             size_t k, double *x) {
  for (int a = 0; a < 3; ++a)
    x[a] = SCALE * (m[a][0] * i + m[a][1] * j + m[a][2] * k + m[a][3]) + shift[a];
}

static double ellipsoid_value(size_t i, size_t j, size_t k, void *ctx) {
  (void)ctx;
  double x[3];
  voxel_mesh_point(sform, offset, i, j, k, x);
  return label_at(x);
}

/** The cells of @p scene_text's initial fields (threshold 0: the full
 *  mass; its volume where c >= 1/2). */
static int cells_of(const char *scene_text, sp_cell_obs *obs, int max, double *d) {
  sp_scene *scene;
  CHECK_OK(sp_scene_load_text("label_volume", scene_text, strlen(scene_text), 0, NULL, &scene));
  sp_mesh *mesh;
  CHECK_OK(sp_mesh_from_scene(scene, &mesh));
  int n = 0;
  CHECK_OK(sp_initial_cell_count(scene, mesh, &n));
  CHECK(n == max, "%d cells, the volume has %d labels", n, max);
  sp_layout *layout;
  CHECK_OK(sp_layout_create_full(mesh->n_nodes, n, &layout));
  double *state = calloc(2 * (size_t)layout->n_pairs, sizeof(double));
  CHECK_OK(sp_initial_state(scene, mesh, layout, state));
  CHECK_OK(sp_cells_observe(mesh, layout, state, 0.0, obs));
  *d = sp_scene_interface_width(scene);
  free(state);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  sp_scene_destroy(&scene);
  return n;
}

/** The labels' voxel volumes, centroids and surface areas (faces between a
 *  label's voxel and another's), voxel centres at mesh points @p at. */
static void label_stats_of(const int n[3], double voxel_volume, const double face_area[3],
                           void (*at)(size_t, size_t, size_t, double *), label_stats *st) {
  memset(st, 0, sizeof *st);
  for (size_t k = 0; k < (size_t)n[2]; ++k)
    for (size_t j = 0; j < (size_t)n[1]; ++j)
      for (size_t i = 0; i < (size_t)n[0]; ++i) {
        double x[3];
        at(i, j, k, x);
        const int value = label_at(x);
        for (int e = 0; e < N_LABELS; ++e) {
          if (value != ellipsoids[e].value) continue;
          const int c = cell_of_entry[e];
          st->volume[c] += voxel_volume;
          for (int a = 0; a < 3; ++a) st->centre[c][a] += voxel_volume * x[a];
          /* faces to a neighbour of another label (none at the grid's edge:
           * the labels lie inside) */
          const size_t ijk[3] = {i, j, k};
          for (int a = 0; a < 3; ++a)
            for (int side = -1; side <= 1; side += 2) {
              size_t nb[3] = {ijk[0], ijk[1], ijk[2]};
              nb[a] += side;
              double y[3];
              at(nb[0], nb[1], nb[2], y);
              if (label_at(y) != value) st->faces[c] += face_area[a];
            }
        }
      }
  for (int c = 0; c < N_LABELS; ++c)
    for (int a = 0; a < 3; ++a) st->centre[c][a] /= st->volume[c];
}

static void sform_point(size_t i, size_t j, size_t k, double *x) {
  voxel_mesh_point(sform, offset, i, j, k, x);
}

static const char *box_mesh = "mesh: {type: box, x0: -0.3, y0: -0.3, z0: -0.3, x1: 0.3, "
                              "y1: 0.3, z1: 0.3, nx: 48, ny: 48, nz: 48}\n"
                              "output: {pictures: false}\n";

static void ellipsoids_sform(void) {
  const int n[3] = {N, N, N};
  const double h[3] = {VOXEL, VOXEL, VOXEL};
  write_volume("labels_sform.nii.gz", n, NIFTI_TYPE_UINT16, sform, 0, h, ellipsoid_value, NULL);
  const double hv = SCALE * VOXEL, face[3] = {hv * hv, hv * hv, hv * hv};
  label_stats st;
  label_stats_of(n, hv * hv * hv, face, sform_point, &st);
  char text[1024];
  snprintf(text, sizeof text, "%sinitial: {label_volume: labels_sform.nii.gz, scale: %g, "
           "offset_x: %g, offset_y: %g, offset_z: %g}\n", box_mesh, SCALE, offset[0], offset[1],
           offset[2]);
  sp_cell_obs obs[N_LABELS];
  double d;
  cells_of(text, obs, N_LABELS, &d);
  printf("sform, voxel %g, d = %.4f: cell, volume (voxels, |diff| / (area h/2)), mass (voxels + "
         "excess, |diff| / tolerance), centre - voxels' centroid (/ h/2)\n", hv, d);
  for (int e = 0; e < N_LABELS; ++e) {
    const int c = cell_of_entry[e];
    const double excess = 2 * M_PI * M_PI * M_PI * d * d / 3 * mean_width(ellipsoids[e].s);
    const double want = st.volume[c] + excess, layer = st.faces[c] * hv / 2;
    const double tol = layer + 0.02 * excess;
    const double off = sqrt(pow(obs[c].centre[0] - st.centre[c][0], 2) +
                            pow(obs[c].centre[1] - st.centre[c][1], 2) +
                            pow(obs[c].centre[2] - st.centre[c][2], 2));
    printf("  %d (label %d): %.6f (%.6f, %.2f), %.6f (%.6f + %.6f, %.2f), %.2e (%.2f)\n", c + 1,
           ellipsoids[e].value, obs[c].volume, st.volume[c],
           fabs(obs[c].volume - st.volume[c]) / layer, obs[c].mass, st.volume[c], excess,
           fabs(obs[c].mass - want) / tol, off, off / (hv / 2));
    CHECK(fabs(obs[c].volume - st.volume[c]) <= layer, "cell %d: volume %.6f, the label's %.6f",
          c + 1, obs[c].volume, st.volume[c]);
    CHECK(fabs(obs[c].mass - want) <= tol, "cell %d: mass %.6f, expected %.6f +- %.6f", c + 1,
          obs[c].mass, want, tol);
    CHECK(off <= hv / 2, "cell %d: centre %.3e from the voxels' centroid", c + 1, off);
  }
}

/* The second case: a qform with voxel sizes (0.4, 0.5, 0.6), the k axis
 * flipped (qfac -1), its origin moved anywhere: with initial.centre the
 * labelled voxels' bounding box is centred at the offset. */
static const double qsize[3] = {0.4, 0.5, 0.6};
static const int qn[3] = {150, 120, 100};
static const double qform_m[3][4] = {{0.4, 0, 0, 1000}, {0, 0.5, 0, -500}, {0, 0, -0.6, 77}};
/* where the labels are drawn: the grid centred on the origin */
static void qform_draw_point(size_t i, size_t j, size_t k, double *x) {
  const double shift[3] = {-SCALE * (qform_m[0][3] + qform_m[0][0] * (qn[0] - 1) / 2.0),
                           -SCALE * (qform_m[1][3] + qform_m[1][1] * (qn[1] - 1) / 2.0),
                           -SCALE * (qform_m[2][3] + qform_m[2][2] * (qn[2] - 1) / 2.0)};
  voxel_mesh_point(qform_m, shift, i, j, k, x);
}

static double qform_value(size_t i, size_t j, size_t k, void *ctx) {
  (void)ctx;
  double x[3];
  qform_draw_point(i, j, k, x);
  return label_at(x);
}

static void ellipsoids_qform_centred(void) {
  write_volume("labels_qform.nii", qn, NIFTI_TYPE_INT16, qform_m, 1, qsize, qform_value, NULL);
  const double face[3] = {SCALE * SCALE * qsize[1] * qsize[2], SCALE * SCALE * qsize[0] * qsize[2],
                          SCALE * SCALE * qsize[0] * qsize[1]};
  label_stats st;
  label_stats_of(qn, SCALE * SCALE * SCALE * qsize[0] * qsize[1] * qsize[2], face,
                 qform_draw_point, &st);
  /* the labelled voxels' bounding box as drawn, to be centred at the offset */
  double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (size_t k = 0; k < (size_t)qn[2]; ++k)
    for (size_t j = 0; j < (size_t)qn[1]; ++j)
      for (size_t i = 0; i < (size_t)qn[0]; ++i) {
        double x[3];
        qform_draw_point(i, j, k, x);
        if (!label_at(x)) continue;
        for (int a = 0; a < 3; ++a) {
          lo[a] = fmin(lo[a], x[a]);
          hi[a] = fmax(hi[a], x[a]);
        }
      }
  char text[1024];
  snprintf(text, sizeof text, "%sinitial: {label_volume: labels_qform.nii, scale: %g, "
           "centre: true, offset_x: %g, offset_y: %g, offset_z: %g}\n", box_mesh, SCALE,
           offset[0], offset[1], offset[2]);
  sp_cell_obs obs[N_LABELS];
  double d;
  cells_of(text, obs, N_LABELS, &d);
  const double h_max = SCALE * qsize[2];
  printf("qform, voxels (%g, %g, %g), centre: cell, centre - the voxels' centroid placed (/ "
         "h_max/2)\n", SCALE * qsize[0], SCALE * qsize[1], SCALE * qsize[2]);
  for (int c = 0; c < N_LABELS; ++c) {
    double off2 = 0;
    const double got[3] = {obs[c].centre[0], obs[c].centre[1], obs[c].centre[2]};
    for (int a = 0; a < 3; ++a) {
      const double want = st.centre[c][a] - 0.5 * (lo[a] + hi[a]) + offset[a];
      off2 += (got[a] - want) * (got[a] - want);
    }
    printf("  %d: %.2e (%.2f), volume %.6f, the label's %.6f\n", c + 1, sqrt(off2),
           sqrt(off2) / (h_max / 2), obs[c].volume, st.volume[c]);
    CHECK(sqrt(off2) <= h_max / 2, "cell %d: centre %.3e from the voxels' centroid", c + 1,
          sqrt(off2));
    CHECK(fabs(obs[c].volume - st.volume[c]) <= st.faces[c] * h_max / 2,
          "cell %d: volume %.6f, the label's %.6f", c + 1, obs[c].volume, st.volume[c]);
  }
}

/* ---- bad volumes ---------------------------------------------------------- */

static double small_labels(size_t i, size_t j, size_t k, void *ctx) {
  const double *v = ctx; /* the label value in the middle, 0 around */
  return i >= 3 && i < 7 && j >= 3 && j < 7 && k >= 3 && k < 7 ? *v : 0;
}

static double every_voxel(size_t i, size_t j, size_t k, void *ctx) {
  (void)ctx;
  return 1 + i + 20 * (j + 20 * k);
}

/** softpack run on a 3D scene with @p initial exits 2 naming
 *  initial.label_volume and @p what, and writes nothing. */
static void refused(const char *name, const char *initial, const char *what) {
  char scene[256], args[1024], out[8192], dir[300];
  snprintf(scene, sizeof scene, "bad_%s.yaml", name);
  snprintf(dir, sizeof dir, "bad_%s_out", name);
  FILE *f = fopen(scene, "w");
  fprintf(f, "mesh: {type: box, x0: -0.5, y0: -0.5, z0: -0.5, x1: 0.5, y1: 0.5, z1: 0.5, "
             "nx: 8, ny: 8, nz: 8}\nlayout: {support: full}\n"
             "output: {pictures: false}\ninitial: {%s}\n", initial);
  fclose(f);
  snprintf(args, sizeof args, "run %s --out %s", scene, dir);
  const int status = run_softpack(args, out, sizeof out);
  struct stat sb;
  CHECK(status == 2 && strstr(out, "initial.label_volume") && strstr(out, what) &&
            stat(dir, &sb) != 0,
        "%s: status %d (expected 2), output dir %s, message: %s", name, status,
        stat(dir, &sb) == 0 ? "written" : "absent", out);
  printf("%s: %s", name, out);
}

static void bad_volumes(void) {
  const int n10[3] = {10, 10, 10}, flat[3] = {10, 10, 1}, n20[3] = {20, 20, 20};
  /* 10 voxels of 0.05 from -0.25: inside the default box [-0.5, 0.5]^3 */
  const double m[3][4] = {{0.05, 0, 0, -0.25}, {0, 0.05, 0, -0.25}, {0, 0, 0.05, -0.25}};
  const double h[3] = {0.05, 0.05, 0.05};
  FILE *f = fopen("not_nifti.nii", "w");
  fputs("this is not a NIfTI file\n", f);
  fclose(f);
  refused("not_nifti", "label_volume: not_nifti.nii", "NIfTI");
  double one = 1, half = 1.5, negative = -2, zero = 0;
  write_volume("flat.nii", flat, NIFTI_TYPE_UINT16, m, 0, h, small_labels, &one);
  refused("flat", "label_volume: flat.nii", "expected a 3D volume");
  write_volume("real.nii", n10, NIFTI_TYPE_FLOAT32, m, 0, h, small_labels, &half);
  refused("real", "label_volume: real.nii", "expected integer labels");
  write_volume("negative.nii", n10, NIFTI_TYPE_INT16, m, 0, h, small_labels, &negative);
  refused("negative", "label_volume: negative.nii", "expected integer labels >= 0");
  write_volume("empty.nii", n10, NIFTI_TYPE_UINT16, m, 0, h, small_labels, &zero);
  refused("empty", "label_volume: empty.nii", "no labels");
  write_volume("good.nii", n10, NIFTI_TYPE_UINT16, m, 0, h, small_labels, &one);
  refused("outside", "label_volume: good.nii, offset_x: 0.6", "outside the mesh");
  refused("outside_scaled", "label_volume: good.nii, scale: 10", "outside the mesh");
  /* 8000 labels, every cell on every node of the 8^3 box: 27 x 8000 x 8003
   * x 729 nonzeros, more than 2^31 - 1 */
  const double m20[3][4] = {{0.02, 0, 0, -0.2}, {0, 0.02, 0, -0.2}, {0, 0, 0.02, -0.2}};
  write_volume("many.nii", n20, NIFTI_TYPE_UINT16, m20, 0, h, every_voxel, NULL);
  refused("too_many", "label_volume: many.nii", "8000 cells");
  const double shear[3][4] = {{0.05, 0.01, 0, -0.25}, {0, 0.05, 0, -0.25}, {0, 0, 0.05, -0.25}};
  write_volume("sheared.nii", n10, NIFTI_TYPE_UINT16, shear, 0, h, small_labels, &one);
  refused("sheared", "label_volume: sheared.nii", "not orthogonal");
  /* a series of 2 volumes */
  const int64_t dims[8] = {4, 10, 10, 10, 2, 1, 1, 1};
  nifti_image *nim = nifti_make_new_nim(dims, NIFTI_TYPE_UINT8, 1);
  ((uint8_t *)nim->data)[555] = 1;
  nifti_set_filenames(nim, "series.nii", 0, 1);
  nifti_image_write(nim);
  nifti_image_free(nim);
  refused("series", "label_volume: series.nii", "expected one 3D volume");
}

/** A short run from a volume: the program sets it up and steps. */
static void short_run(void) {
  FILE *f = fopen("volume_run.yaml", "w");
  fputs("mesh: {type: box, x0: -0.3, y0: -0.3, z0: -0.3, x1: 0.3, y1: 0.3, z1: 0.3, "
        "nx: 12, ny: 12, nz: 12}\nmodel: {kappa: 0.01}\ntime: {dt: 1e-5, max_steps: 2}\n"
        "output: {pictures: false}\n"
        "initial: {label_volume: labels_sform.nii.gz, scale: 0.01, offset_x: 0.01, "
        "offset_y: -0.02, offset_z: 0.015}\n", f);
  fclose(f);
  char out[8192];
  const int status = run_softpack("run volume_run.yaml --out volume_run --quiet", out, sizeof out);
  CHECK(status == 0, "a run from a label volume: status %d: %s", status, out);
  FILE *cells = fopen("volume_run/cells.csv", "r");
  CHECK(cells, "volume_run/cells.csv");
  int rows = 0;
  char line[4096];
  while (cells && fgets(line, sizeof line, cells)) ++rows;
  if (cells) fclose(cells);
  /* the header, then 3 cells at step 0 and at each of the 2 steps */
  CHECK(rows == 1 + 3 * 3, "cells.csv: %d lines, expected 10", rows);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  ellipsoids_sform();
  ellipsoids_qform_centred();
  bad_volumes();
  short_run();
  MPI_Finalize();
  TEST_DONE();
}
