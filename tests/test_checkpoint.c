/* Checkpoints alone (src/run/checkpoint.c), no time stepping:
 * - a round trip of the run state: a run set up from a scene as a run is
 *   (scene_fixture.h), moved to random supports with every member set (two
 *   past states, a registry with names and cut normals, the controller,
 *   the counters, the energy history), is written, and a run set up from
 *   the checkpoint as a
 *   restart is compares equal to it member by member, bit for bit;
 * - output.checkpoint_keep keeps the newest files only, and the newest
 *   valid one is found past a damaged newer one;
 * - a truncated file, a flipped byte, an HDF5 file that is not a
 *   checkpoint and one of another format version are refused as bad input
 *   (SP_ERR_INPUT) with a message saying which. */
#include <hdf5.h>
#include <hdf5_hl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "run/checkpoint.h"
#include "public/error.h"
#include "run/resize.h"
#include "scene_fixture.h"

#define DIR "checkpoint_test"

static unsigned long long rng = 88172645463325252ULL;
static double uniform(void) { /* xorshift64 */
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

static double *random_array(size_t n) {
  double *a = malloc(sizeof(double) * n + 1);
  for (size_t i = 0; i < n; ++i) a[i] = uniform() - 0.25;
  return a;
}

/** A run of @p scene (three cells) as the run sets it up (scene_fixture.h),
 *  then moved to random supports and every member of the state set to
 *  values of its own (a set-up leaves the history, controller and counters
 *  empty and the registry plain). */
static scene_run *fill_run(const sp_scene *scene) {
  scene_run *s = scene_run_setup(scene);
  sp_run *run = &s->run;
  static const char text[] = "a scene's text";
  static const char *const set[] = {"time.t_end=1", "output.every=3"};
  run->scene_text.text = text;
  run->scene_text.len = strlen(text);
  run->scene_text.n_set = 2;
  run->scene_text.set = set;
  const int nn = run->mesh->n_nodes, nc = 3;
  CHECK(run->layout->n_cells == nc, "the scene's set-up has %d cells", run->layout->n_cells);
  unsigned char *mask = malloc((size_t)nn * nc);
  for (size_t i = 0; i < (size_t)nn * nc; ++i) mask[i] = uniform() < 0.6;
  sp_layout *layout;
  CHECK_OK(sp_layout_create_from_masks(nn, nc, mask, &layout));
  free(mask);
  const size_t nv = 2 * (size_t)layout->n_pairs;
  CHECK_OK(sp_run_resize(run, layout, random_array(nv), SP_HISTORY_RESET));
  run->hist.n = 2;
  run->hist.past[0] = random_array(nv);
  run->hist.past[1] = random_array(nv);
  run->hist.dt[0] = 1.5e-4;
  run->hist.dt[1] = 1.25e-4;
  run->step = 17;
  run->t = 0.0123;
  run->n_max = 9;
  for (int k = 0; k < nc; ++k) {
    run->cells.birth[k] = (sp_cell_birth){.birth_time = uniform(), .birth_mass = uniform(),
                                    .Iref = {uniform(), uniform()}, .generation = k + 1};
    run->cells.source_on[k] = k != 1;
    run->cells.division_skipped[k] = k == 2;
    run->cells.divided_now[k] = k == 0;
    /* names (the lineage table's, up to SP_CELL_NAME_MAX - 1 characters;
     * the last cell unnamed) and the normals of the cuts that made them */
    static const char *const names[] = {"P0", "ABCDEFGHIJKLMNOPQRSTUVWXYZabcde", ""};
    snprintf(run->cells.name[k], SP_CELL_NAME_MAX, "%s", names[k]);
    for (int d = 0; d < 3; ++d) run->cells.cut_normal[k][d] = uniform();
  }
  run->dtc = (sp_dt_control){.dt_next = uniform(), .failures = 2, .successes = 3,
                             .ceiling = uniform(), .ceiling_steps = 4, .since_restart = 5,
                             .err_prev = uniform(), .dt_last = uniform(), .rejected_last = 1,
                             .n_accepted = 6, .n_rejected = 7, .n_newton_failed = 8,
                             .event_dt = uniform()};
  s->sum = (sp_run_summary){.steps = 17, .failed_attempts = 2, .newton_its = 40,
                            .factorisations = 30, .failed_factorisations = 5, .linear_its = 9,
                            .t_final = 0.0123, .dt_smallest = 1e-6, .wall_seconds = 3.5,
                            .t_assembly = 1, .t_factor = 2, .t_solve = 0.5, .divisions = 2,
                            .n_cells = 3, .layout_changes = 4, .support_mass_correction = 1e-3,
                            .t_layout = 0.1, .support_mass_dropped = 1e-14,
                            .support_energy_rise = 0.01, .unknowns_max = 1234,
                            .checkpoints = 3, .t_checkpoints = 0.25};
  run->mon.n_energy = run->mon.cap_energy = 5;
  run->mon.energy_t = random_array(5);
  run->mon.energy_total = random_array(5);
  run->mon.n_divisions = 2;
  run->mon.division_t = random_array(2);
  return s;
}

/** The members in which two runs' states differ (printed if @p say). */
static int differences(const sp_run *a, const sp_run *b, int say) {
  int n = 0;
#define DIFF(cond, what)                                                        \
  do {                                                                         \
    if (!(cond)) {                                                             \
      ++n;                                                                     \
      if (say) fprintf(stderr, "differs: %s\n", what);                         \
    }                                                                          \
  } while (0)
  const sp_layout *la = a->layout, *lb = b->layout;
  DIFF(la->n_nodes == lb->n_nodes && la->n_cells == lb->n_cells && la->n_pairs == lb->n_pairs,
       "layout sizes");
  if (n) return n;
  DIFF(!memcmp(la->node_start, lb->node_start, sizeof(int) * (la->n_nodes + 1)), "node_start");
  DIFF(!memcmp(la->pair_cell, lb->pair_cell, sizeof(int) * la->n_pairs), "pair_cell");
  const size_t nv = 2 * (size_t)la->n_pairs;
  DIFF(!memcmp(a->state, b->state, sizeof(double) * nv), "state");
  DIFF(b->hist.n == a->hist.n && b->hist.dt[0] == a->hist.dt[0] &&
       b->hist.dt[1] == a->hist.dt[1], "history n, dt");
  for (int i = 0; i < a->hist.n && i < b->hist.n; ++i)
    DIFF(!memcmp(a->hist.past[i], b->hist.past[i], sizeof(double) * nv), "history past");
  DIFF(b->step == a->step && b->t == a->t && b->n_max == a->n_max, "step, t, n_max");
  for (int k = 0; k < la->n_cells; ++k) {
    const sp_cell_birth *ba = &a->cells.birth[k], *bb = &b->cells.birth[k];
    DIFF(bb->birth_time == ba->birth_time && bb->birth_mass == ba->birth_mass &&
             bb->Iref[0] == ba->Iref[0] && bb->Iref[1] == ba->Iref[1] &&
             bb->generation == ba->generation,
         "birth");
    DIFF(b->cells.source_on[k] == a->cells.source_on[k] &&
             b->cells.division_skipped[k] == a->cells.division_skipped[k] &&
             b->cells.divided_now[k] == a->cells.divided_now[k],
         "registry");
    DIFF(strcmp(b->cells.name[k], a->cells.name[k]) == 0, "name");
    DIFF(!memcmp(b->cells.cut_normal[k], a->cells.cut_normal[k], sizeof a->cells.cut_normal[k]),
         "cut normal");
  }
  sp_dt_control da = a->dtc, db = b->dtc;
  db.p = da.p; /* the parameters come from the scene */
  DIFF(!memcmp(&da, &db, sizeof da), "the controller");
  DIFF(!memcmp(a->mon.sum, b->mon.sum, sizeof *a->mon.sum), "the summary");
  DIFF(b->mon.n_energy == a->mon.n_energy && b->mon.n_divisions == a->mon.n_divisions,
       "energy history sizes");
  if (b->mon.n_energy == a->mon.n_energy) {
    const size_t bytes = sizeof(double) * a->mon.n_energy;
    DIFF(!memcmp(a->mon.energy_t, b->mon.energy_t, bytes), "energy_t");
    DIFF(!memcmp(a->mon.energy_total, b->mon.energy_total, bytes), "energy_total");
  }
  if (b->mon.n_divisions == a->mon.n_divisions)
    DIFF(!memcmp(a->mon.division_t, b->mon.division_t, sizeof(double) * a->mon.n_divisions),
         "division_t");
#undef DIFF
  return n;
}

/** A run of @p scene set up from the checkpoint @p path, as a run
 *  continued from it is (sp_run_setup from a checkpoint); *out NULL if
 *  that fails, with its code returned. */
static int restore(const char *path, const sp_scene *scene, scene_run **out) {
  *out = NULL;
  sp_checkpoint ck;
  int rc = sp_checkpoint_open(path, &ck);
  if (rc != SP_OK) return rc;
  const sp_run_start start = {.checkpoint = ck};
  rc = scene_run_start(scene, &start, out);
  sp_checkpoint_close(&ck);
  return rc;
}

static void round_trip(const sp_scene *scene) {
  scene_run *sa = fill_run(scene), *sb;
  sp_run *a = &sa->run;
  char path[4096];
  CHECK_OK(sp_checkpoint_write(a, DIR, path, sizeof path));
  CHECK(strcmp(path, DIR "/checkpoint_000017.h5") == 0, "written to %s", path);
  sp_checkpoint ck;
  CHECK_OK(sp_checkpoint_open(path, &ck));
  CHECK(sp_checkpoint_step(ck) == 17 && sp_checkpoint_time(ck) == 0.0123 &&
            sp_checkpoint_mpi_size(ck) == 1, "step %d, t %g", sp_checkpoint_step(ck),
        sp_checkpoint_time(ck));
  size_t len;
  int n_set;
  const char *const *set;
  const char *text = sp_checkpoint_scene(ck, &len, &n_set, &set);
  CHECK(len == a->scene_text.len && memcmp(text, a->scene_text.text, len) == 0, "scene text");
  CHECK(n_set == 2 && strcmp(set[0], a->scene_text.set[0]) == 0 &&
            strcmp(set[1], a->scene_text.set[1]) == 0,
        "overrides");
  sp_checkpoint_close(&ck);
  CHECK_OK(restore(path, scene, &sb));
  CHECK(sb->run.restarted && differences(a, &sb->run, 1) == 0,
        "the state differs after the round trip");
  /* keep 2: writing steps 18 and 19 leaves 18 and 19 */
  a->step = 18;
  CHECK_OK(sp_checkpoint_write(a, DIR, NULL, 0));
  a->step = 19;
  CHECK_OK(sp_checkpoint_write(a, DIR, NULL, 0));
  CHECK(access(DIR "/checkpoint_000017.h5", F_OK) != 0, "checkpoint 17 kept (keep = 2)");
  CHECK(access(DIR "/checkpoint_000018.h5", F_OK) == 0, "checkpoint 18 deleted");
  char newest[4096];
  CHECK_OK(sp_checkpoint_find_newest(DIR, newest, sizeof newest));
  CHECK(strcmp(newest, DIR "/checkpoint_000019.h5") == 0, "newest: %s", newest);
  CHECK(truncate(DIR "/checkpoint_000019.h5", 4000) == 0, "truncate");
  CHECK_OK(sp_checkpoint_find_newest(DIR, newest, sizeof newest));
  CHECK(strcmp(newest, DIR "/checkpoint_000018.h5") == 0, "newest past a damaged one: %s",
        newest);
  scene_run_free(&sa);
  scene_run_free(&sb);
}

/** sp_checkpoint_open must refuse @p path as bad input with @p words in its message. */
static void refused(const char *path, const char *words) {
  sp_checkpoint ck = NULL;
  const int rc = sp_checkpoint_open(path, &ck);
  CHECK(rc == SP_ERR_INPUT && ck == NULL, "%s: rc %d", path, rc);
  CHECK(strstr(sp_error_message(), words) != NULL, "%s: message '%s' lacks '%s'", path,
        sp_error_message(), words);
}

static void copy_file(const char *from, const char *to) {
  FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
  char buf[65536];
  for (size_t n; in && out && (n = fread(buf, 1, sizeof buf, in)) > 0;) fwrite(buf, 1, n, out);
  if (in) fclose(in);
  if (out) fclose(out);
}

static void bad_files(const sp_scene *scene) {
  const char *good = DIR "/checkpoint_000018.h5";
  /* truncated */
  copy_file(good, DIR "/truncated.h5");
  struct stat st;
  stat(good, &st);
  CHECK(truncate(DIR "/truncated.h5", st.st_size / 2) == 0, "truncate");
  refused(DIR "/truncated.h5", "damaged");
  /* one byte flipped at 64 places: refused, or (a byte nothing reads)
   * the same state restored */
  scene_run *g, *r;
  CHECK_OK(restore(good, scene, &g));
  int n_refused = 0;
  for (int where = 0; where < 64; ++where) {
    copy_file(good, DIR "/flipped.h5");
    FILE *f = fopen(DIR "/flipped.h5", "r+b");
    const long at = (long)((st.st_size - 1) * (where + 0.5) / 64);
    fseek(f, at, SEEK_SET);
    const int c = fgetc(f);
    fseek(f, at, SEEK_SET);
    fputc(c ^ 0x5a, f);
    fclose(f);
    const int rc = restore(DIR "/flipped.h5", scene, &r);
    CHECK(rc == SP_OK || rc == SP_ERR_INPUT, "byte %ld flipped: rc %d", at, rc);
    if (rc == SP_OK)
      CHECK(differences(&g->run, &r->run, 1) == 0,
            "byte %ld flipped: a different state was accepted", at);
    n_refused += rc != SP_OK;
    scene_run_free(&r);
  }
  printf("a byte flipped at 64 places: %d refused, %d in bytes nothing reads\n", n_refused,
         64 - n_refused);
  scene_run_free(&g);
  /* a byte of each array's values flipped (a bit error in the data that
   * HDF5's own structures would not notice): refused by its checksum */
  static const char *const arrays[] = {"/state", "/history/past0", "/history/past1",
                                       "/cells/birth_mass", "/layout/pair_cell", "/header_t"};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; ++i) {
    hid_t h = H5Fopen(good, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t d = H5Dopen2(h, arrays[i], H5P_DEFAULT);
    const haddr_t offset = H5Dget_offset(d);
    H5Dclose(d);
    H5Fclose(h);
    CHECK(offset != HADDR_UNDEF, "%s: no offset", arrays[i]);
    copy_file(good, DIR "/flipped.h5");
    FILE *f = fopen(DIR "/flipped.h5", "r+b");
    fseek(f, (long)offset + 3, SEEK_SET);
    const int c = fgetc(f);
    fseek(f, (long)offset + 3, SEEK_SET);
    fputc(c ^ 0x10, f);
    fclose(f);
    const int rc = restore(DIR "/flipped.h5", scene, &r);
    CHECK(rc == SP_ERR_INPUT, "a byte of %s flipped: rc %d", arrays[i], rc);
    CHECK(strstr(sp_error_message(), "checksum"), "a byte of %s flipped: '%s'", arrays[i],
          sp_error_message());
    scene_run_free(&r);
  }
  /* not HDF5 */
  FILE *f = fopen(DIR "/text.h5", "w");
  fputs("not a checkpoint\n", f);
  fclose(f);
  refused(DIR "/text.h5", "not an HDF5 file");
  /* HDF5, but not softpack's */
  hid_t h = H5Fcreate(DIR "/foreign.h5", H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const int one = 1;
  H5LTset_attribute_int(h, "/", "format_version", &one, 1);
  H5Fclose(h);
  refused(DIR "/foreign.h5", "not a softpack checkpoint");
  /* another format version */
  copy_file(good, DIR "/version.h5");
  h = H5Fopen(DIR "/version.h5", H5F_ACC_RDWR, H5P_DEFAULT);
  const int v = SP_CHECKPOINT_VERSION + 1;
  H5LTset_attribute_int(h, "/", "format_version", &v, 1);
  H5Fclose(h);
  refused(DIR "/version.h5", "format version");
  refused(DIR "/missing.h5", "cannot read");
  /* a version 1 file (before names and cut normals) restores the same
   * state with unnamed cells */
  copy_file(good, DIR "/v1.h5");
  h = H5Fopen(DIR "/v1.h5", H5F_ACC_RDWR, H5P_DEFAULT);
  const int v1 = 1;
  H5LTset_attribute_int(h, "/", "format_version", &v1, 1);
  H5Ldelete(h, "/cells/name", H5P_DEFAULT);
  H5Ldelete(h, "/cells/cut_normal", H5P_DEFAULT);
  H5Adelete_by_name(h, "/controller", "event_dt", H5P_DEFAULT); /* newer than version 2 */
  H5Fclose(h);
  scene_run *g1, *r1;
  CHECK_OK(restore(good, scene, &g1));
  CHECK_OK(restore(DIR "/v1.h5", scene, &r1));
  if (g1 && r1) {
    const sp_run *a = &g1->run, *b = &r1->run;
    CHECK(b->layout->n_pairs == a->layout->n_pairs &&
              !memcmp(a->state, b->state, sizeof(double) * 2 * (size_t)a->layout->n_pairs),
          "version 1: another state restored");
    int named = 0;
    for (int k = 0; k < b->cells.n; ++k) named += b->cells.name[k][0] != '\0';
    CHECK(named == 0, "version 1: %d cells named", named);
    CHECK(a->dtc.event_dt != 0 && b->dtc.event_dt == 0,
          "without its event_dt attribute: event_dt %g (written %g)", b->dtc.event_dt,
          a->dtc.event_dt);
  }
  scene_run_free(&g1);
  scene_run_free(&r1);
}

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  CHECK(system("rm -rf " DIR) == 0, "cannot clear " DIR);
  mkdir(DIR, 0777);
  static const char text[] = "mesh: {type: rectangle, nx: 8, ny: 6}\n"
                             "output: {checkpoint_keep: 2}\n"
                             "cells:\n  - {x: 0.3, y: 0.5, radius: 0.15}\n"
                             "  - {x: 0.7, y: 0.5, radius: 0.15}\n"
                             "  - {x: 0.5, y: 0.8, radius: 0.1}\n";
  sp_scene *scene;
  CHECK_OK(sp_scene_load_text("test", text, strlen(text), 0, NULL, &scene));
  round_trip(scene);
  bad_files(scene);
  sp_scene_destroy(&scene);
  MPI_Finalize();
  TEST_DONE();
}
