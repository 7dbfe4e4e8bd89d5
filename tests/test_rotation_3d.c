/* Frame indifference of the 3D model: a scene and the same scene
 * turned by the rotation P (x, y, z) -> (y, z, x), or by the quarter turn
 * about z Q (x, y, z) -> (y, -x, z), give the same run, turned.
 *
 * Scene A: a box of 14 x 12 x 10 hexahedra (0.56 x 0.48 x 0.40: cubes of
 * side 0.04), three cells off-centre and near each other (a prolate
 * spheroid turned along (1, 0.6, 0.35), a triaxial ellipsoid along the axes,
 * a sphere), no noise (its draws follow the node numbering, which P does
 * not keep), s = 0, backward Euler at a fixed dt, full supports, MUMPS; the
 * spheroid (cell 1, the first due: N_max = 4) divides by age at step 3 with
 * the smoothed cut through its centre (no node is decided by a sign), then
 * 2 more steps. Scene B: A with every coordinate turned by P: the box's
 * extents and counts (x <- y, y <- z, z <- x: 12 x 10 x 14 hexahedra), the
 * centres, the ellipsoid's semi-axes and the spheroid's axis. P is a
 * rotation (a cyclic permutation, determinant +1), so B's mesh is A's
 * turned, node for node, with its hexahedra still positively oriented, and
 * B's discrete problem is A's turned: the runs may differ only in round-off
 * (nodes and elements are numbered otherwise, so every sum is taken in
 * another order, and the LU's pivots differ). Scene C: A turned by Q the
 * same way (12 x 14 x 10 hexahedra; a point's new y is the box's width
 * minus its x).
 *
 * Asserted, at every step: the energy equal to 1e-10 relative, every cell's
 * mass equal to 1e-10 relative, its centre turned by P to 1e-10 (absolute;
 * the box is 0.5 across), its three principal moments equal to 1e-10
 * relative, and its long axis turned by P, up to its sign (the sign rule,
 * r . v >= 0 for a fixed r, is not invariant under P), to 1e-10 / gap rad
 * where the gap (I2 - I3) / I1 > 0.01 (a nearly round cell has no long
 * axis to speak of: an eigenvector moves by the tensor's change over the
 * gap); the division at the same step and t, its cut normal turned by P
 * (to 1e-8 rad: the same bound at the smallest gap allowed), the masses
 * before and after the split equal. Why 1e-10: each run's state carries
 * round-off from the assembly's sums and the LU (about eps times the
 * Jacobian's condition number per solve) through 5 steps, a few 1e-13
 * relative in these runs (docs/3d.md has the measured differences), and
 * another LU ordering or BLAS may make more; 1e-10 leaves that room and is
 * still orders of magnitude below what a frame-dependent discretisation
 * does to these quantities (docs/3d.md: B with one cell's semi-axes left
 * unturned). The daughters' labels follow the cut normal's sign: when a
 * turn flips it (see above), the daughters swap their labels, which the
 * comparison follows. P keeps this scene's sign, Q flips it (asserted:
 * both paths are taken). */
#include <string.h>

#include "check.h"
#include "public/error.h"
#include "output_read.h"
#include "scene/scene.h"
#include "run/stepper.h"

enum { MAX_CELLS = 4, CAP = 16 };

static const double TOL = 1e-10;

/** A cell of scene A: centre, semi-axes (0: the radius), radius, axis of a
 *  turned cell (all 0: along the coordinate axes). */
typedef struct {
  double c[3], semi[3], radius, axis[3];
} cell_spec;

static const double box[3] = {0.56, 0.48, 0.40};
static const int counts[3] = {14, 12, 10};
static const cell_spec cells[3] = {
    {{0.22, 0.25, 0.19}, {0.13, 0, 0}, 0.085, {1, 0.6, 0.35}},
    {{0.39, 0.16, 0.23}, {0.075, 0.06, 0.09}, 0.07, {0, 0, 0}},
    {{0.37, 0.34, 0.25}, {0, 0, 0}, 0.075, {0, 0, 0}},
};

/** The turns: 0 none, 1 P (x, y, z) -> (y, z, x), 2 Q (x, y, z) -> (y,
 *  -x, z) (a quarter turn about z): (R v)_j = sign_j v_{perm_j}. */
static const int turn_perm[3][3] = {{0, 1, 2}, {1, 2, 0}, {1, 0, 2}};
static const double turn_sign[3][3] = {{1, 1, 1}, {1, 1, 1}, {1, -1, 1}};

/** The vector @p v turned by turn @p turn. */
static void turned(const double v[3], int turn, double out[3]) {
  for (int j = 0; j < 3; ++j) out[j] = turn_sign[turn][j] * v[turn_perm[turn][j]];
}

/** The point @p p of scene A's box turned into the turned scene's box (a
 *  reversed axis runs from the box's far side: x' = L - x). */
static void turned_point(const double p[3], int turn, double out[3]) {
  for (int j = 0; j < 3; ++j) {
    const int i = turn_perm[turn][j];
    out[j] = turn_sign[turn][j] > 0 ? p[i] : box[i] - p[i];
  }
}

/** A length triple (extents, semi-axes) turned: its components permuted. */
static void turned_lengths(const double v[3], int turn, double out[3]) {
  for (int j = 0; j < 3; ++j) out[j] = v[turn_perm[turn][j]];
}

/** Write scene A (@p turn 0) or A turned (1: B, 2: C) to @p path. */
static void write_scene(const char *path, int turn) {
  FILE *f = fopen(path, "w");
  CHECK(f != NULL, "cannot write %s", path);
  if (!f) exit(1);
  double L[3];
  turned_lengths(box, turn, L);
  const int *perm = turn_perm[turn];
  const int n[3] = {counts[perm[0]], counts[perm[1]], counts[perm[2]]};
  fprintf(f, "mesh: {type: box, x0: 0, y0: 0, z0: 0, x1: %.17g, y1: %.17g, z1: %.17g, "
             "nx: %d, ny: %d, nz: %d}\n", L[0], L[1], L[2], n[0], n[1], n[2]);
  fprintf(f, "model: {alpha: 4, kappa: 4.0e-3, lambda: 100, mobility: 1}\n"
             "time: {control: fixed, scheme: be, dt: 2.0e-4, t_end: 1.0, max_steps: 5}\n"
             "division: {criterion: age, t_div: 0.0006, n_div: 1, m: 2, max_cells: 4, "
             "cut: smooth}\n"
             "layout: {support: full}\n"
             "output: {every: 100, pictures: false, timings: false}\n"
             "solver: {linear: mumps, predictor: none, jacobian_reuse: 0}\n"
             "cells:\n");
  static const char *xyz = "xyz";
  for (int k = 0; k < 3; ++k) {
    double c[3], s[3], a[3];
    turned_point(cells[k].c, turn, c);
    turned(cells[k].axis, turn, a);
    /* a turned cell's semi_x lies along its axis, which the turn turns */
    turned_lengths(cells[k].semi, a[0] == 0 && a[1] == 0 && a[2] == 0 ? turn : 0, s);
    fprintf(f, "  - {x: %.17g, y: %.17g, z: %.17g, radius: %.17g", c[0], c[1], c[2],
            cells[k].radius);
    for (int j = 0; j < 3; ++j)
      if (s[j] > 0) fprintf(f, ", semi_%c: %.17g", xyz[j], s[j]);
    if (a[0] != 0 || a[1] != 0 || a[2] != 0)
      fprintf(f, ", axis_x: %.17g, axis_y: %.17g, axis_z: %.17g", a[0], a[1], a[2]);
    fprintf(f, "}\n");
  }
  fclose(f);
}

/** Write and run scene A, B or C into @p out; the summary. */
static sp_run_summary run(int turn, const char *out) {
  char path[256];
  snprintf(path, sizeof path, "%s.yaml", out);
  write_scene(path, turn);
  sp_scene *scene;
  CHECK_OK(sp_scene_load(path, 0, NULL, &scene));
  sp_run_summary sum;
  CHECK_OK(sp_stepper_run(scene, out, MPI_COMM_WORLD, &sum));
  printf("%s: %d steps to t = %.6g, %d division(s), %d cells\n", path, sum.steps, sum.t_final,
         sum.divisions, sum.n_cells);
  sp_scene_destroy(&scene);
  return sum;
}

static double rel(double a, double b) { return fabs(a - b) / fmax(fabs(a), fabs(b)); }

/** The angle between the lines along unit vectors @p a and @p b. */
static double line_angle(const double a[3], const double b[3]) {
  const double dot = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
  double cross[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]};
  return atan2(sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]), dot);
}

static double worst_mass, worst_centre, worst_moment, worst_axis;

/** @p dir/cells.csv's columns, by step and cell. */
typedef struct {
  double mass[CAP][MAX_CELLS], c[3][CAP][MAX_CELLS], I[3][CAP][MAX_CELLS],
      v[3][CAP][MAX_CELLS];
  int rows;
} cells_log;

static void read_cells(const char *dir, cells_log *log) {
  static const char *names[3][3] = {{"xc", "yc", "zc"}, {"I1", "I2", "I3"},
                                    {"long_x", "long_y", "long_z"}};
  log->rows = cells_column(dir, "mass", &log->mass[0][0], CAP, MAX_CELLS);
  for (int j = 0; j < 3; ++j) {
    cells_column(dir, names[0][j], &log->c[j][0][0], CAP, MAX_CELLS);
    cells_column(dir, names[1][j], &log->I[j][0][0], CAP, MAX_CELLS);
    cells_column(dir, names[2][j], &log->v[j][0][0], CAP, MAX_CELLS);
  }
}

/** Cell @p ka at step @p s of run A against cell @p kb of run B, A's
 *  turned by @p turn. */
static void compare_cell(const cells_log *A, const cells_log *B, int turn, int s, int ka,
                         int kb) {
  const double m = rel(A->mass[s][ka], B->mass[s][kb]);
  worst_mass = fmax(worst_mass, m);
  CHECK(m <= TOL, "step %d cell %d/%d: mass %.17g turned %.17g", s, ka + 1, kb + 1,
        A->mass[s][ka], B->mass[s][kb]);
  double ca[3], va[3], pc[3], pv[3], vb[3];
  for (int j = 0; j < 3; ++j) {
    ca[j] = A->c[j][s][ka];
    va[j] = A->v[j][s][ka];
    vb[j] = B->v[j][s][kb];
  }
  turned_point(ca, turn, pc);
  turned(va, turn, pv);
  for (int j = 0; j < 3; ++j) {
    const double d = fabs(pc[j] - B->c[j][s][kb]);
    worst_centre = fmax(worst_centre, d);
    CHECK(d <= TOL, "step %d cell %d/%d: centre component %d: P c_A %.17g, c_B %.17g", s,
          ka + 1, kb + 1, j, pc[j], B->c[j][s][kb]);
    const double i = rel(A->I[j][s][ka], B->I[j][s][kb]);
    worst_moment = fmax(worst_moment, i);
    CHECK(i <= TOL, "step %d cell %d/%d: moment I%d %.17g turned %.17g", s, ka + 1, kb + 1,
          j + 1, A->I[j][s][ka], B->I[j][s][kb]);
  }
  const double gap = (A->I[1][s][ka] - A->I[2][s][ka]) / A->I[0][s][ka];
  if (gap > 0.01) {
    const double angle = line_angle(pv, vb);
    worst_axis = fmax(worst_axis, angle * gap);
    CHECK(angle <= TOL / gap, "step %d cell %d/%d: long axis P v_A (%.6f, %.6f, %.6f), v_B "
          "(%.6f, %.6f, %.6f): %.3g rad apart (gap %.3g)", s, ka + 1, kb + 1, pv[0], pv[1],
          pv[2], vb[0], vb[1], vb[2], angle, gap);
  }
}

/** The one row of @p dir/divisions.csv (an unnamed scene's). */
static void read_division(const char *dir, division_row *r) {
  char path[256];
  snprintf(path, sizeof path, "%s/divisions.csv", dir);
  csv_table t;
  *r = (division_row){.step = -1};
  CHECK(csv_read(path, &t) == 0 && t.n_rows == 1, "%s: one division", path);
  if (t.n_rows < 1) return;
  static const char *normal[3] = {"long_x", "long_y", "long_z"};
  for (int j = 0; j < 3; ++j) r->normal[j] = at(&t, 0, normal[j]);
  r->t = at(&t, 0, "t");
  r->step = (int)at(&t, 0, "step");
  r->parent = (int)at(&t, 0, "parent");
  r->child = (int)at(&t, 0, "child");
  r->before = at(&t, 0, "parent_mass_before");
  r->a = at(&t, 0, "parent_mass_after");
  r->b = at(&t, 0, "child_mass_after");
  csv_free(&t);
}

/** Run A against the run of A turned by @p turn in @p b_dir: every step's
 *  energy, cells and the division; returns whether the turn flipped the
 *  cut normal's sign (the daughters' labels swapped). */
static int compare_runs(const char *a_dir, const char *b_dir, int turn) {
  worst_mass = worst_centre = worst_moment = worst_axis = 0;
  const double worst_energy = energy_difference(a_dir, b_dir); /* (same t and cells at every step) */
  CHECK(worst_energy <= TOL, "turn %d: the energies differ by %.3g (relative)", turn,
        worst_energy);
  /* the division: same step and t, the cut normal turned (up to its sign) */
  division_row da, db;
  read_division(a_dir, &da);
  read_division(b_dir, &db);
  double pn[3];
  turned(da.normal, turn, pn);
  const double flip = pn[0] * db.normal[0] + pn[1] * db.normal[1] + pn[2] * db.normal[2];
  const double normal_angle = line_angle(pn, db.normal);
  printf("  turn %d: division at step %d (A) and %d: normal R n_A (%.6f, %.6f, %.6f), n "
         "(%.6f, %.6f, %.6f), %.3g rad apart, %s sign\n", turn, da.step, db.step, pn[0], pn[1],
         pn[2], db.normal[0], db.normal[1], db.normal[2], normal_angle,
         flip < 0 ? "the opposite" : "the same");
  CHECK(da.step == 3 && db.step == 3 && da.t == db.t, "divisions at steps %d, %d, t %.17g, %.17g",
        da.step, db.step, da.t, db.t);
  CHECK(da.parent == 1 && da.child == 4 && db.parent == 1 && db.child == 4,
        "A: %d -> %d, turned: %d -> %d", da.parent, da.child, db.parent, db.child);
  CHECK(normal_angle <= TOL / 0.01, "the cut normals are %.3g rad apart", normal_angle);
  CHECK(rel(da.before, db.before) <= TOL, "parent mass %.17g, %.17g", da.before, db.before);
  /* a flipped normal swaps the daughters' labels: the turned run's 1 is A's 4 */
  CHECK(rel(flip < 0 ? da.b : da.a, db.a) <= TOL && rel(flip < 0 ? da.a : da.b, db.b) <= TOL,
        "daughters' masses: A %.17g, %.17g; turned %.17g, %.17g", da.a, da.b, db.a, db.b);
  static cells_log A, B;
  read_cells(a_dir, &A);
  read_cells(b_dir, &B);
  CHECK(A.rows == 6 && B.rows == 6, "cells.csv: %d and %d steps", A.rows, B.rows);
  for (int s = 0; s < A.rows && s < B.rows; ++s)
    for (int kb = 0; kb < MAX_CELLS; ++kb) {
      const int ka = flip < 0 && s >= da.step && (kb == 0 || kb == 3) ? 3 - kb : kb;
      CHECK(isnan(A.mass[s][ka]) == isnan(B.mass[s][kb]), "step %d: cell %d/%d in one run only",
            s, ka + 1, kb + 1);
      if (!isnan(A.mass[s][ka]) && !isnan(B.mass[s][kb])) compare_cell(&A, &B, turn, s, ka, kb);
    }
  printf("  turn %d: largest differences: energy %.3g and mass %.3g (relative), centre %.3g, "
         "moments %.3g (relative), long axis angle x gap %.3g rad\n", turn, worst_energy,
         worst_mass, worst_centre, worst_moment, worst_axis);
  return flip < 0;
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const char *dirs[3] = {"test_rotation_3d_a", "test_rotation_3d_b", "test_rotation_3d_c"};
  for (int turn = 0; turn < 3; ++turn) {
    const sp_run_summary sum = run(turn, dirs[turn]);
    CHECK(sum.steps == 5 && sum.divisions == 1 && sum.n_cells == 4,
          "turn %d: %d steps, %d divisions, %d cells", turn, sum.steps, sum.divisions,
          sum.n_cells);
  }
  /* P keeps the sign rule's choice of the cut normal here, Q flips it: both
   * label paths are taken */
  CHECK(!compare_runs(dirs[0], dirs[1], 1), "P flipped the cut normal's sign");
  CHECK(compare_runs(dirs[0], dirs[2], 2), "Q kept the cut normal's sign: the label swap is "
        "not exercised");
  MPI_Finalize();
  TEST_DONE();
}
