/* MPI runs against one-process runs (ctest label mpi; tests/CMakeLists.txt
 * runs it under mpirun with np = 1, 2, 3). Not a test_*.c: it needs mpirun.
 *
 *   mpi_compare steps LABEL SCENE [section.key=value]...
 *     Rank 0 runs the scene alone (MPI_COMM_SELF) into mpi_LABEL_ref, then
 *     every rank runs it together (MPI_COMM_WORLD) into mpi_LABEL_np<P>;
 *     rank 0 compares the CSVs: same steps, times and cell counts, the same
 *     divisions (step, parent, child), energies equal to 1e-9 relative (each
 *     part to 1e-9 of the total), cell masses to 1e-10 relative, the same
 *     rows of contacts.csv with contacts and surfaces to 1e-9 relative; with
 *     P > 1, the .pvtu pieces cover the mesh once and hold the one-process
 *     fields (compare_fields; 2D and 3D scenes).
 *
 *   mpi_compare iterates LINEAR...
 *     The first Newton iterates of one step (three touching cells, 40 x 40
 *     rectangle) with each backend LINEAR (superlu, superlu_dist, mumps,
 *     klu, klu2) on MPI_COMM_WORLD against serial SuperLU on MPI_COMM_SELF:
 *     max |x_k - x_k,ref| <= 1e-10 max |x_k,ref| for k = 1..4.
 *
 *   mpi_compare library SCENE [section.key=value]...
 *     The library under faults (src/base/fault.h): with SOFTPACK_FAULT set on
 *     every rank to a fault on one rank (at set-up, in the solver's
 *     creation, in a step, at output, inside the glue's residual fill
 *     and where it takes a layout, each before its collective; rank 1,
 *     and rank 0 for some),
 *     sp_run_file returns on every rank with the fault's class
 *     (memory, solver, output) and a message naming it; then a run without
 *     a fault succeeds on every rank (the library is usable after them),
 *     stopped after step 2 on every rank by a callback that stops on rank 1.
 *     On several processes, solver.linear=klu2 is refused on every rank
 *     with an input error naming the key, the value and the reason (wrong
 *     answers there), and nothing written.
 *
 *   mpi_compare faults         (run without mpirun)
 *     The real program under `mpirun -np 2` with a fault on rank 1 at
 *     set-up, in the solver's creation, in a step, at output, in the
 *     glue's residual fill and layout hand-over, and check-jacobian with
 *     the residual fill's: every run
 *     ends within seconds (timeout -s KILL 60 makes a hang fail), exit
 *     status 1, the message on stderr; and rank 1 killed by SIGKILL in a
 *     step ends the run (mpirun tears the job down), not a hang.
 *
 *   mpi_compare cli            (run without mpirun)
 *     The real program under `mpirun -np 2`: a bad scene, klu2 (refused on
 *     several processes) and an unwritable output directory each end within
 *     60 s (timeout -s KILL) with the right status and the message.
 */
#include <errno.h>
#include <stdint.h>
#include <mpi.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>

#include "fixtures.h"
#include "scene/scene.h"
#include "output_read.h"
#include "public/run.h"

static double rel(double a, double b) {
  double s = fmax(fabs(a), fabs(b));
  return s > 0 ? fabs(a - b) / s : 0.0;
}

/* ---------- steps: a scene on P ranks against one ---------- */

/** Read DIR/NAME of both runs into @p r and @p p (a failed read is a failed
 *  check). */
static void read_both(const char *ref, const char *par, const char *name, csv_table *r,
                      csv_table *p) {
  char path[2048];
  snprintf(path, sizeof path, "%s/%s", ref, name);
  CHECK(csv_read(path, r) == 0, "cannot read %s", path);
  snprintf(path, sizeof path, "%s/%s", par, name);
  CHECK(csv_read(path, p) == 0, "cannot read %s", path);
}

/** contacts.csv: the same rows (step, cell, other: the same pairs in
 *  contact), contacts and surfaces equal to 1e-9 relative (each rank
 *  integrates its elements, one reduction sums them: round-off apart, and
 *  the states differ by Newton's tolerance). */
static void compare_contacts(const char *ref, const char *par) {
  csv_table r, p;
  read_both(ref, par, "contacts.csv", &r, &p);
  if (sp_test_failures) return;
  CHECK(r.n_rows == p.n_rows, "contacts rows %d vs %d", r.n_rows, p.n_rows);
  double worst = 0;
  int pairs = 0;
  static const char *values[] = {"contact", "surface", "free_surface"};
  for (int i = 0; i < r.n_rows && i < p.n_rows; ++i) {
    CHECK(at(&r, i, "step") == at(&p, i, "step") && at(&r, i, "cell") == at(&p, i, "cell") &&
              at(&r, i, "other") == at(&p, i, "other"),
          "contacts row %d: (step, cell, other) differ", i);
    pairs += at(&r, i, "other") > 0;
    for (int j = 0; j < 3; ++j) {
      const double a = at(&r, i, values[j]), b = at(&p, i, values[j]);
      /* (a free surface is a difference: relative to the surface) */
      worst = fmax(worst, fabs(a - b) / fmax(fabs(at(&r, i, "surface")), fabs(a)));
    }
  }
  printf("contacts.csv: %d rows (%d pair rows); largest relative difference %.2e\n", r.n_rows,
         pairs, worst);
  CHECK(worst <= 1e-9, "contacts differ by %.3g relative", worst);
  free(r.v);
  free(p.v);
}

static void compare_runs(const char *ref, const char *par, int divides) {
  csv_table er, ep, cr, cp, dr, dp;
  read_both(ref, par, "energy.csv", &er, &ep);
  read_both(ref, par, "cells.csv", &cr, &cp);
  read_both(ref, par, "divisions.csv", &dr, &dp);
  if (sp_test_failures) return;

  CHECK(er.n_rows == ep.n_rows, "energy rows %d vs %d", er.n_rows, ep.n_rows);
  static const char *parts[] = {"bulk", "gradient", "repulsion", "buffer", "shape"};
  double worst_e = 0, worst_part = 0, worst_t = 0;
  int its_differ = 0;
  for (int i = 0; i < er.n_rows && i < ep.n_rows; ++i) {
    CHECK(at(&er, i, "step") == at(&ep, i, "step"), "row %d: step %g vs %g", i,
          at(&er, i, "step"), at(&ep, i, "step"));
    CHECK(at(&er, i, "n_cells") == at(&ep, i, "n_cells"), "step %g: %g vs %g cells",
          at(&er, i, "step"), at(&er, i, "n_cells"), at(&ep, i, "n_cells"));
    worst_t = fmax(worst_t, fmax(rel(at(&er, i, "t"), at(&ep, i, "t")),
                                 rel(at(&er, i, "dt"), at(&ep, i, "dt"))));
    const double e = at(&er, i, "energy");
    worst_e = fmax(worst_e, rel(e, at(&ep, i, "energy")));
    for (int k = 0; k < 5; ++k)
      worst_part = fmax(worst_part, fabs(at(&er, i, parts[k]) - at(&ep, i, parts[k])) / fabs(e));
    its_differ += at(&er, i, "newton_its") != at(&ep, i, "newton_its");
  }
  printf("energy.csv: %d steps; largest relative difference: t/dt %.2e, energy %.2e, "
         "parts (of the energy) %.2e; Newton iteration counts differ on %d steps\n",
         er.n_rows, worst_t, worst_e, worst_part, its_differ);
  CHECK(worst_t <= 1e-12, "t or dt differ by %.3g", worst_t);
  CHECK(worst_e <= 1e-9, "energies differ by %.3g relative", worst_e);
  CHECK(worst_part <= 1e-9, "energy parts differ by %.3g of the energy", worst_part);

  CHECK(cr.n_rows == cp.n_rows, "cells rows %d vs %d", cr.n_rows, cp.n_rows);
  double worst_m = 0, worst_x = 0;
  for (int i = 0; i < cr.n_rows && i < cp.n_rows; ++i) {
    CHECK(at(&cr, i, "step") == at(&cp, i, "step") && at(&cr, i, "cell") == at(&cp, i, "cell"),
          "cells row %d: (step, cell) differ", i);
    worst_m = fmax(worst_m, rel(at(&cr, i, "mass"), at(&cp, i, "mass")));
    worst_x = fmax(worst_x, fmax(fabs(at(&cr, i, "xc") - at(&cp, i, "xc")),
                                 fabs(at(&cr, i, "yc") - at(&cp, i, "yc"))));
  }
  printf("cells.csv: %d rows; largest relative mass difference %.2e, centre difference %.2e\n",
         cr.n_rows, worst_m, worst_x);
  CHECK(worst_m <= 1e-10, "cell masses differ by %.3g relative", worst_m);
  CHECK(worst_x <= 1e-8, "cell centres differ by %.3g", worst_x);

  CHECK(dr.n_rows == dp.n_rows, "divisions %d vs %d", dr.n_rows, dp.n_rows);
  double worst_dm = 0;
  for (int i = 0; i < dr.n_rows && i < dp.n_rows; ++i) {
    CHECK(at(&dr, i, "step") == at(&dp, i, "step") && at(&dr, i, "parent") == at(&dp, i, "parent") &&
              at(&dr, i, "child") == at(&dp, i, "child"),
          "division %d: step/parent/child %g/%g/%g vs %g/%g/%g", i, at(&dr, i, "step"),
          at(&dr, i, "parent"), at(&dr, i, "child"), at(&dp, i, "step"), at(&dp, i, "parent"),
          at(&dp, i, "child"));
    worst_dm = fmax(worst_dm, fmax(rel(at(&dr, i, "parent_mass_after"), at(&dp, i, "parent_mass_after")),
                                   rel(at(&dr, i, "child_mass_after"), at(&dp, i, "child_mass_after"))));
  }
  printf("divisions.csv: %d divisions at steps", dr.n_rows);
  for (int i = 0; i < dr.n_rows; ++i) printf(" %g", at(&dr, i, "step"));
  printf("; largest relative mass difference %.2e\n", worst_dm);
  CHECK(dr.n_rows >= 1 || !divides, "the scene should divide");
  CHECK(worst_dm <= 1e-10, "division masses differ by %.3g relative", worst_dm);
  free(er.v); free(ep.v); free(cr.v); free(cp.v); free(dr.v); free(dp.v);
  compare_contacts(ref, par);
}

/** Check the .pvtu output of an MPI run against the one-process .vtu files:
 *  fields.pvd lists .pvtu files at the same steps, each names one piece per
 *  rank, the pieces' elements add up to the mesh's, and c_1 at every node of
 *  every piece (by node_id) equals the one-process value to 1e-9. */
static void compare_fields(const char *ref, const char *par, int size) {
  char path[2048];
  snprintf(path, sizeof path, "%s/fields.pvd", ref);
  char *pvd_ref = slurp(path, NULL);
  snprintf(path, sizeof path, "%s/fields.pvd", par);
  char *pvd_par = slurp(path, NULL);
  CHECK(pvd_ref && pvd_par, "fields.pvd missing in %s or %s", ref, par);
  if (!pvd_ref || !pvd_par) { free(pvd_ref); free(pvd_par); return; }
  int files = 0, worst_elems = 0;
  double worst_c = 0;
  const char *pr = pvd_ref, *pp = pvd_par;
  while ((pr = strstr(pr, "file=\"")) != NULL) {
    int step_ref = -1, step_par = -1;
    sscanf(pr, "file=\"fields_%d.vtu\"", &step_ref);
    pp = pp ? strstr(pp, "file=\"") : NULL;
    CHECK(pp != NULL, "fields.pvd of %s lists fewer files", par);
    if (!pp) break;
    char ext[8] = "";
    sscanf(pp, "file=\"fields_%d.%4[a-z]\"", &step_par, ext);
    CHECK(step_par == step_ref && strcmp(ext, "pvtu") == 0, "listed %s step %d vs step %d",
          ext, step_par, step_ref);
    ++pr;
    ++pp;
    snprintf(path, sizeof path, "%s/fields_%06d.vtu", ref, step_ref);
    char *vref = slurp(path, NULL);
    CHECK(vref != NULL, "cannot read %s", path);
    if (!vref) break;
    int ref_nodes = 0, ref_elems = 0;
    sscanf(strstr(vref, "<Piece"), "<Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\"",
           &ref_nodes, &ref_elems);
    size_t nb = 0;
    double *c_ref = (double *)vtu_array_data(vref, "c_1", &nb);
    CHECK(c_ref && nb == sizeof(double) * (size_t)ref_nodes, "c_1 of %s", path);
    snprintf(path, sizeof path, "%s/fields_%06d.pvtu", par, step_ref);
    char *pvtu = slurp(path, NULL);
    CHECK(pvtu != NULL, "cannot read %s", path);
    int elems = 0;
    for (int r = 0; r < size && pvtu && c_ref; ++r) {
      char piece[64];
      snprintf(piece, sizeof piece, "Source=\"fields_%06d_p%d.vtu\"", step_ref, r);
      CHECK(strstr(pvtu, piece) != NULL, "%s does not name piece %d", path, r);
      snprintf(path, sizeof path, "%s/fields_%06d_p%d.vtu", par, step_ref, r);
      char *vp = slurp(path, NULL);
      CHECK(vp != NULL, "cannot read %s", path);
      if (!vp) continue;
      int n_nodes = 0, n_elems = 0;
      sscanf(strstr(vp, "<Piece"), "<Piece NumberOfPoints=\"%d\" NumberOfCells=\"%d\"",
             &n_nodes, &n_elems);
      elems += n_elems;
      size_t bc = 0, bi = 0;
      double *c = (double *)vtu_array_data(vp, "c_1", &bc);
      int32_t *id = (int32_t *)vtu_array_data(vp, "node_id", &bi);
      CHECK(c && id && bc == sizeof(double) * (size_t)n_nodes &&
            bi == sizeof(int32_t) * (size_t)n_nodes, "arrays of %s", path);
      for (int j = 0; c && id && j < n_nodes; ++j) {
        CHECK(id[j] >= 0 && id[j] < ref_nodes, "%s: node_id %d", path, id[j]);
        if (id[j] >= 0 && id[j] < ref_nodes) worst_c = fmax(worst_c, fabs(c[j] - c_ref[id[j]]));
      }
      free(c); free(id); free(vp);
    }
    CHECK(elems == ref_elems, "step %d: the pieces hold %d elements, the mesh %d", step_ref,
          elems, ref_elems);
    if (abs(elems - ref_elems) > worst_elems) worst_elems = abs(elems - ref_elems);
    free(pvtu); free(c_ref); free(vref);
    ++files;
  }
  printf("fields: %d .pvtu files of %d pieces; elements missing or doubled %d; largest "
         "difference of c_1 from one process %.2e\n", files, size, worst_elems, worst_c);
  CHECK(files >= 2, "only %d field files compared", files);
  CHECK(worst_c <= 1e-9, "c_1 differs from one process by %.3g", worst_c);
  free(pvd_ref); free(pvd_par);
}

static int cmd_steps(int argc, char **argv, int rank, int size) {
  if (argc < 2) {
    fprintf(stderr, "usage: mpi_compare steps LABEL SCENE [key=value]...\n");
    return 2;
  }
  const char *label = argv[0], *scene_path = argv[1];
  sp_scene *scene = NULL;
  CHECK_OK(sp_scene_load(scene_path, argc - 2, (const char *const *)argv + 2, &scene));
  char ref[512], par[512], cmd[1200];
  snprintf(ref, sizeof ref, "mpi_%s_ref", label);
  snprintf(par, sizeof par, "mpi_%s_np%d", label, size);
  sp_run_summary sum_ref = {0}, sum_par = {0};
  if (rank == 0) {
    snprintf(cmd, sizeof cmd, "rm -rf %s %s", ref, par);
    CHECK(system(cmd) == 0, "%s", cmd);
    double t0 = MPI_Wtime();
    CHECK_OK(sp_stepper_run(scene, ref, MPI_COMM_SELF, &sum_ref));
    printf("one process: %d steps, %.1f s\n", sum_ref.steps, MPI_Wtime() - t0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  double t0 = MPI_Wtime();
  CHECK_OK(sp_stepper_run(scene, par, MPI_COMM_WORLD, &sum_par));
  if (rank == 0) {
    printf("%d processes: %d steps, %.1f s\n", size, sum_par.steps, MPI_Wtime() - t0);
    CHECK(sum_ref.steps == sum_par.steps, "%d vs %d steps", sum_ref.steps, sum_par.steps);
    compare_runs(ref, par, scene->division.criterion != SP_DIVIDE_NONE);
    if (size > 1) compare_fields(ref, par, size);
  }
  sp_scene_destroy(&scene);
  return 0;
}

/* ---------- iterates: one step's Newton iterates per backend ---------- */

static int linear_kind(const char *name) {
  if (strcmp(name, "superlu") == 0) return SP_LINEAR_SUPERLU;
  if (strcmp(name, "superlu_dist") == 0) return SP_LINEAR_SUPERLU_DIST;
  if (strcmp(name, "mumps") == 0) return SP_LINEAR_MUMPS;
  if (strcmp(name, "klu2") == 0) return SP_LINEAR_KLU2;
  if (strcmp(name, "klu") == 0) return SP_LINEAR_KLU;
  return -1;
}

enum { N_ITERATES = 4 };

/* x_1..x_4 of the step from `old` with `guess` as x_0: each call does
 * exactly one Newton update (atol huge: converged after one update). */
static void newton_iterates(MPI_Comm comm, int linear, const sp_mesh *mesh, const sp_layout *layout,
                            const double *old, const double *guess, double *iterates,
                            double *seconds) {
  const int n = 2 * layout->n_pairs;
  sp_solver_options opt = {.jacobian = SP_SOLVER_JAC_AD, .linear = linear, .newton_rtol = 1e-10,
                           .newton_atol = 1e300, .newton_max_its = 3};
  sp_solver s = NULL;
  if (sp_solver_create(comm, &opt, &s) != 0) {
    fprintf(stderr, "sp_solver_create: %s\n", sp_solver_last_error(s));
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  CHECK_OK(sp_solver_attach(s, mesh, layout));
  double *x = malloc(n * sizeof(double));
  memcpy(x, guess, n * sizeof(double));
  sp_step_data data = {.dt = 1e-4, .model = paper_model(), .state_old = old};
  sp_step_report rep;
  double t0 = MPI_Wtime();
  for (int k = 0; k < N_ITERATES; ++k) {
    int rc = sp_solver_step(s, &data, x, &rep);
    CHECK(rc == 0 && rep.newton_its == 1, "iterate %d: rc %d, %d its: %s", k + 1, rc,
          rep.newton_its, sp_solver_last_error(s));
    memcpy(iterates + (size_t)k * n, x, n * sizeof(double));
  }
  *seconds = MPI_Wtime() - t0;
  free(x);
  sp_solver_destroy(&s);
}

static int cmd_iterates(int argc, char **argv, int rank, int size) {
  sp_mesh *mesh;
  sp_layout *layout;
  three_cell_problem(&mesh, &layout);
  const int n = 2 * layout->n_pairs;
  double *old = calloc(n, sizeof(double)), *guess = calloc(n, sizeof(double));
  set_three_touching_disks(mesh, layout, old);
  /* x_0: the old state with a perturbed c, so that every iterate moves. */
  for (int i = 0; i < n; ++i) guess[i] = old[i] + (i % 2 == 0 ? 0.01 * sin(0.37 * i) : 0.0);
  double *ref = malloc((size_t)N_ITERATES * n * sizeof(double));
  double *got = malloc((size_t)N_ITERATES * n * sizeof(double));
  double t_ref;
  /* Every rank computes the serial reference alone (the same numbers). */
  newton_iterates(MPI_COMM_SELF, SP_LINEAR_SUPERLU, mesh, layout, old, guess, ref, &t_ref);
  if (rank == 0) printf("%d unknowns; serial superlu: 4 iterates in %.2f s\n", n, t_ref);
  for (int a = 0; a < argc; ++a) {
    const int kind = linear_kind(argv[a]);
    CHECK(kind >= 0, "unknown backend %s", argv[a]);
    if (kind < 0) continue;
    double t;
    newton_iterates(MPI_COMM_WORLD, kind, mesh, layout, old, guess, got, &t);
    for (int k = 0; k < N_ITERATES; ++k) {
      double diff = 0, scale = 0;
      for (int i = 0; i < n; ++i) {
        diff = fmax(diff, fabs(got[(size_t)k * n + i] - ref[(size_t)k * n + i]));
        scale = fmax(scale, fabs(ref[(size_t)k * n + i]));
      }
      if (rank == 0)
        printf("%s on %d process(es): iterate %d, max difference %.2e (relative %.2e)%s\n", argv[a],
               size, k + 1, diff, diff / scale, k == N_ITERATES - 1 ? "" : "");
      CHECK(diff <= 1e-10 * scale, "%s, np %d, iterate %d: relative difference %.3g", argv[a], size,
            k + 1, diff / scale);
    }
    if (rank == 0) printf("%s on %d process(es): 4 iterates in %.2f s\n", argv[a], size, t);
  }
  free(old); free(guess); free(ref); free(got);
  sp_layout_destroy(&layout);
  sp_mesh_destroy(&mesh);
  return 0;
}

/* ---------- library: faults on one rank, every rank returns ---------- */

/** A step callback that stops the run after step 2 on rank 1 only. */
static int stop_on_rank_1(const sp_step_info *s, void *user) {
  return *(const int *)user == 1 && s->step >= 2;
}

static int cmd_library(int argc, char **argv, int rank, int size) {
  if (argc < 1) {
    fprintf(stderr, "usage: mpi_compare library SCENE [key=value]...\n");
    return 2;
  }
  const char *const *set = (const char *const *)argv + 1;
  static const struct {
    const char *fault;
    int code;
  } cases[] = {{"setup:1", SP_ERR_MEMORY}, {"solver:1", SP_ERR_SOLVER},
               {"step:1", SP_ERR_MEMORY},  {"output:1", SP_ERR_IO},
               {"step:0", SP_ERR_MEMORY},  {"output:0", SP_ERR_IO},
               {"assembly:1", SP_ERR_MEMORY}, {"assembly:0", SP_ERR_MEMORY},
               {"attach:1", SP_ERR_MEMORY}, {"attach:0", SP_ERR_MEMORY},
               {"factor:1", SP_ERR_MEMORY}, {"factor:0", SP_ERR_MEMORY}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    setenv("SOFTPACK_FAULT", cases[i].fault, 1);
    const double t0 = MPI_Wtime();
    const int rc = sp_run_file(argv[0], argc - 1, set, "mpi_library_out", MPI_COMM_WORLD, NULL,
                               NULL, NULL);
    unsetenv("SOFTPACK_FAULT");
    char needle[64];
    snprintf(needle, sizeof needle, "SOFTPACK_FAULT=%s", cases[i].fault);
    printf("rank %d, %s: code %d after %.1f s: %s\n", rank, cases[i].fault, rc,
           MPI_Wtime() - t0, sp_error_message());
    CHECK(rc == cases[i].code, "rank %d, %s: code %d, want %d", rank, cases[i].fault, rc,
          cases[i].code);
    CHECK(strstr(sp_error_message(), needle) != NULL, "rank %d, %s: message %s", rank,
          cases[i].fault, sp_error_message());
  }
  /* klu2 on several processes: refused at set-up on every rank (an input
   * error, exit status 2 for the program), with the reason */
  if (size > 1) {
    const char **with_klu2 = malloc(sizeof(char *) * (size_t)argc);
    for (int i = 0; i < argc - 1; ++i) with_klu2[i] = set[i];
    with_klu2[argc - 1] = "solver.linear=klu2";
    system(rank == 0 ? "rm -rf mpi_library_klu2" : "true");
    MPI_Barrier(MPI_COMM_WORLD);
    const int rc = sp_run_file(argv[0], argc, with_klu2, "mpi_library_klu2", MPI_COMM_WORLD, NULL,
                               NULL, NULL);
    free(with_klu2);
    printf("rank %d, klu2 on %d processes: code %d: %s\n", rank, size, rc, sp_error_message());
    CHECK(rc == SP_ERR_INPUT, "rank %d, klu2 on %d processes: code %d, want %d (input)", rank,
          size, rc, SP_ERR_INPUT);
    static const char *const names[] = {"solver.linear", "klu2", "wrong answers"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
      CHECK(strstr(sp_error_message(), names[i]) != NULL, "rank %d, klu2: the message does not "
            "name '%s': %s", rank, names[i], sp_error_message());
    MPI_Barrier(MPI_COMM_WORLD);
    CHECK(system("test -e mpi_library_klu2") != 0, "klu2 on %d processes wrote output", size);
  }
  sp_run_summary sum = {0};
  CHECK_OK(sp_run_file(argv[0], argc - 1, set, "mpi_library_out", MPI_COMM_WORLD,
                       stop_on_rank_1, &rank, &sum));
  CHECK(sum.stopped == 1 && sum.steps == 2,
        "rank %d: rank 1's stop after step 2: stopped %d after %d steps", rank, sum.stopped,
        sum.steps);
  return 0;
}

/* ---------- cli: the real program under mpirun ---------- */

static int run_mpi(int np, const char *args, char *out, size_t size, double *seconds) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
           "timeout -s KILL 60 %s %s %d %s %s %s 2>&1",
           SP_MPIEXEC, SP_MPIEXEC_NUMPROC_FLAG, np, SP_MPIEXEC_PREFLAGS, SP_BINARY, args);
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  FILE *p = popen(cmd, "r");
  if (!p) return -1;
  size_t n = fread(out, 1, size - 1, p);
  out[n] = '\0';
  int status = pclose(p);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  *seconds = (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/* The run ends within 50 s with @p want_status and its message names each
 * of @p names (the key, the value, the path: not the wording). */
static void expect_failure(const char *what, const char *args, int want_status,
                           const char *const *names) {
  char out[16384];
  double seconds = 0;
  int status = run_mpi(2, args, out, sizeof out, &seconds);
  printf("%s: exit status %d after %.1f s\n", what, status, seconds);
  CHECK(status == want_status, "%s: exit status %d (want %d), output:\n%s", what, status,
        want_status, out);
  for (const char *const *name = names; *name; ++name)
    CHECK(strstr(out, *name) != NULL, "%s: the output does not name '%s':\n%s", what, *name,
          out);
  CHECK(seconds < 50, "%s: took %.1f s", what, seconds);
}

static int cmd_cli(void) {
  const char *scene = SP_SOURCE_DIR "/tests/scenes/divide_1_2_4.yaml";
  char args[4096];
  system("rm -rf mpi_cli_out");
  snprintf(args, sizeof args, "run %s/tests/scenes/bad/negative_kappa.yaml --out mpi_cli_out",
           SP_SOURCE_DIR);
  static const char *const kappa[] = {"model.kappa", NULL};
  expect_failure("bad scene, np 2", args, 2, kappa);
  CHECK(system("test -e mpi_cli_out") != 0, "the bad scene created the output directory");
  snprintf(args, sizeof args,
           "run %s --out mpi_cli_out --set solver.linear=klu2 --set output.pictures=false", scene);
  /* the key, the value and the reason (Debian's Amesos2 KLU2 is wrong there) */
  static const char *const klu2[] = {"solver.linear", "klu2", "wrong answers", NULL};
  expect_failure("klu2, np 2", args, 2, klu2);
  CHECK(system("test -e mpi_cli_out") != 0, "klu2 on 2 processes created the output directory");
  /* Only rank 0 writes: an unwritable output directory fails there alone,
   * while rank 1 goes on into the first step's collectives. */
  snprintf(args, sizeof args,
           "run %s --out /proc/mpi_compare_cannot_write --set output.pictures=false", scene);
  static const char *const unwritable[] = {"/proc/mpi_compare_cannot_write", NULL};
  expect_failure("unwritable --out, np 2", args, 1, unwritable);
  /* info reports the processes it runs on, once (rank 0 prints). */
  char out[16384];
  double seconds = 0;
  CHECK(run_mpi(2, "info", out, sizeof out, &seconds) == 0, "info, np 2: %s", out);
  const char *size_line = strstr(out, "MPI processes: ");
  CHECK(size_line && strncmp(size_line, "MPI processes: 2\n", 17) == 0 &&
            !strstr(size_line + 1, "MPI processes: "),
        "info, np 2 does not say 'MPI processes: 2' once:\n%s", out);
  TEST_DONE();
}

/* ---------- faults: the real program with a fault on one rank ---------- */

static int cmd_faults(void) {
  char args[4096];
  snprintf(args, sizeof args,
           "run %s/tests/scenes/divide_1_2_4.yaml --out mpi_faults_out --set output.pictures=false "
           "--set layout.support=local --set time.max_steps=4",
           SP_SOURCE_DIR);
  /* the class, the failing rank and the phase named (not the wording) */
  static const char *const faults[][4] = {
      {"setup:1", "(memory)", "rank 1 of 2", "setup"},
      {"solver:1", "(solver)", "rank 1", "solver"},
      {"step:1", "(memory)", "rank 1 of 2", "step"},
      {"output:1", "(output)", "rank 1 of 2", "fields"},
      {"assembly:1", "(memory)", "rank 1", "assembly"},
      {"attach:1", "(memory)", "rank 1", "attach"}};
  for (size_t i = 0; i < sizeof faults / sizeof faults[0]; ++i) {
    char what[64];
    snprintf(what, sizeof what, "SOFTPACK_FAULT=%s, np 2", faults[i][0]);
    setenv("SOFTPACK_FAULT", faults[i][0], 1);
    const char *const names[] = {faults[i][1], faults[i][2], faults[i][3], NULL};
    expect_failure(what, args, 1, names);
  }
  /* check-jacobian agrees its errors too: a fault in rank 1's residual
   * fill (its steps) ends both ranks with exit 1, not by MPI_Abort */
  char checkjac[4096];
  snprintf(checkjac, sizeof checkjac, "check-jacobian %s/tests/scenes/divide_1_2_4.yaml "
           "--steps 1 --set layout.support=local", SP_SOURCE_DIR);
  setenv("SOFTPACK_FAULT", "assembly:1", 1);
  {
    static const char *const names[] = {"(memory)", "rank 1", "assembly", NULL};
    expect_failure("check-jacobian, SOFTPACK_FAULT=assembly:1, np 2", checkjac, 1, names);
  }
  char abort_out[16384];
  double abort_seconds = 0;
  run_mpi(2, checkjac, abort_out, sizeof abort_out, &abort_seconds);
  unsetenv("SOFTPACK_FAULT");
  CHECK(strstr(abort_out, "MPI_ABORT") == NULL && strstr(abort_out, "MPI_Abort") == NULL,
        "check-jacobian with a fault on rank 1 ended by MPI_Abort:\n%s", abort_out);
  /* a rank killed: mpirun ends the job (its status is the signal's) */
  setenv("SOFTPACK_FAULT", "step:1:kill", 1);
  char out[16384];
  double seconds = 0;
  const int status = run_mpi(2, args, out, sizeof out, &seconds);
  unsetenv("SOFTPACK_FAULT");
  printf("rank 1 killed in a step: exit status %d after %.1f s\n", status, seconds);
  CHECK(status != 0 && seconds < 50, "rank 1 killed: exit status %d after %.1f s:\n%s", status,
        seconds, out);
  CHECK(strstr(out, "Killed") != NULL, "rank 1 killed: mpirun does not say so:\n%s", out);
  TEST_DONE();
}

int main(int argc, char **argv) {
  /* no MPI_Init for these: they run mpirun */
  if (argc >= 2 && strcmp(argv[1], "cli") == 0) return cmd_cli();
  if (argc >= 2 && strcmp(argv[1], "faults") == 0) return cmd_faults();
  MPI_Init(&argc, &argv);
  int rank, size;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int rc = 2;
  if (argc >= 2 && strcmp(argv[1], "steps") == 0) rc = cmd_steps(argc - 2, argv + 2, rank, size);
  else if (argc >= 2 && strcmp(argv[1], "iterates") == 0) rc = cmd_iterates(argc - 2, argv + 2, rank, size);
  else if (argc >= 2 && strcmp(argv[1], "library") == 0) rc = cmd_library(argc - 2, argv + 2, rank, size);
  else if (rank == 0) fprintf(stderr, "usage: mpi_compare steps|iterates|library|faults|cli ...\n");
  /* Every rank's failures count (the comparisons are made on rank 0). */
  int failures = sp_test_failures + (rc != 0), total = 0;
  MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (rank == 0) {
    if (total) fprintf(stderr, "%d check(s) failed\n", total);
    else printf("all checks passed\n");
  }
  MPI_Finalize();
  return total ? 1 : 0;
}
