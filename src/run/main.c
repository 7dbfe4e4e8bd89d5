/*
 * softpack: the phase-field model of multi-cell aggregates that grow, divide
 * and pack softly (Jiang, Garikipati, Rudraraju; see docs/model.md).
 *
 *   softpack run SCENE.yaml [--out DIR] [--set section.key=value]... [--quiet]
 *                [--restart CHECKPOINT | --resume DIR] [--restart-as-initial]
 *   softpack keys        print every scene key (the table of docs/scene.md)
 *   softpack check-jacobian SCENE.yaml [--steps K] [--set section.key=value]...
 *   softpack info        the build: type, Trilinos, linear solvers, BLAS, MPI
 *   softpack --version   the version and the git revision it was built from
 *   softpack --help
 *
 * Exit status: 0 success, 2 bad input (nothing written), 1 any other failure,
 * 75 stopped by SIGTERM, SIGINT or SIGUSR1 after writing a checkpoint (resume
 * with --resume DIR; docs/restart.md).
 */
#include <dlfcn.h>
#include <math.h>
#include <mpi.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "run/build_info.h"
#include "run/checkjac.h"
#include "public/error.h"
#include "scene/scene.h"
#include "sp_revision.h" /* SP_GIT_REVISION, generated at build time */
#include "public/run.h"

static void usage(FILE *to) {
  fprintf(to,
          "usage: softpack run SCENE.yaml [--out DIR] [--set section.key=value]... [--quiet]\n"
          "                    [--restart CHECKPOINT | --resume DIR] [--restart-as-initial]\n"
          "                          continue from a checkpoint, or DIR's newest (docs/restart.md)\n"
          "       softpack keys      print every scene key with unit, default and range\n"
          "       softpack check-jacobian SCENE.yaml [--steps K] [--set section.key=value]...\n"
          "                          compare the ad, hand and fd element Jacobians\n"
          "       softpack info      the build: type, Trilinos, linear solvers, BLAS, MPI\n"
          "       softpack --version the version and the git revision\n"
          "       softpack --help\n"
          "Outputs go to DIR (default out/<scene name>): energy.csv, cells.csv,\n"
          "fields.pvd + fields_*.vtu (ParaView), cells_*.png (3D: sections_*.png,\n"
          "surfaces_*.png), energy.png.\n"
          "Exit status: 0 ok, 2 bad input (nothing written), 1 failure, 75 stopped by\n"
          "SIGTERM/SIGINT/SIGUSR1 after writing a checkpoint (resume with --resume DIR).\n");
}

/** "softpack 0.1 (git 0123456789ab)": --version, and the first line of info. */
static void print_version(FILE *to) {
  fprintf(to, "softpack %s (git %s)\n", sp_version(), SP_GIT_REVISION);
}

/** out/<basename of the scene without .yaml> */
static void default_out_dir(const char *scene_path, char *out, size_t size) {
  const char *base = strrchr(scene_path, '/');
  base = base ? base + 1 : scene_path;
  size_t len = strlen(base);
  if (len > 5 && strcmp(base + len - 5, ".yaml") == 0) len -= 5;
  else if (len > 4 && strcmp(base + len - 4, ".yml") == 0) len -= 4;
  snprintf(out, size, "out/%.*s", (int)len, base);
}

/** The run's summary lines on stdout. */
static void print_summary(const sp_run_summary *sum, const char *out_dir) {
  if (sum->layout_changes)
    printf("softpack: local supports: %d changes (%.1f s), largest relative mass change restored "
           "%.2e, mass dropped in all %.2e of the total, largest relative energy rise at a change "
           "%.2e, at most %ld unknowns\n",
           sum->layout_changes, sum->t_layout, sum->support_mass_correction,
           sum->support_mass_dropped, sum->support_energy_rise, sum->unknowns_max);
  else
    printf("softpack: at most %ld unknowns per step\n", sum->unknowns_max);
  printf("softpack: memory per rank (MB): mesh %.1f, state %.1f, matrix %.1f, solver %.1f; "
         "sent per Newton iteration (MB): %.3f\n",
         sum->mb_mesh, sum->mb_state, sum->mb_matrix, sum->mb_solver, sum->mb_sent_per_newton);
  if (sum->checkpoints)
    printf("softpack: %d checkpoints written (%.2f s)\n", sum->checkpoints, sum->t_checkpoints);
  char gmres[64] = "";
  if (sum->linear_its > 0)
    snprintf(gmres, sizeof gmres, "; %ld GMRES iterations", sum->linear_its);
  printf("softpack: %d steps to t = %.6g (%d failed attempts retried, smallest dt %.3g), "
         "%ld Newton iterations (%ld factorisations, and %ld in failed attempts%s), %.1f s "
         "(assembly %.1f, factorisation %.1f, solves %.1f); output in %s\n",
         sum->steps, sum->t_final, sum->failed_attempts, sum->dt_smallest, sum->newton_its,
         sum->factorisations, sum->failed_factorisations, gmres, sum->wall_seconds,
         sum->t_assembly, sum->t_factor, sum->t_solve, out_dir);
}

/** The progress line on a terminal: redrawn in place at most
 *  SP_PROGRESS_HZ times a second (failure lines go above it, monitor.c). */
#define SP_PROGRESS_HZ 4
typedef struct {
  int rank, drawn;
  double last_draw;
} progress;

static int draw_progress(const sp_step_info *s, void *user) {
  progress *p = user;
  if (p->rank != 0 || (p->drawn && !s->last &&
                       s->wall_seconds - p->last_draw < 1.0 / SP_PROGRESS_HZ))
    return 0; /* the first and the last step always, between at most 4 a second */
  p->last_draw = s->wall_seconds;
  const double done = s->t / s->t_end;
  char eta[32] = "-";
  if (done > 0 && done < 1) {
    const double left = s->wall_seconds * (1 - done) / done;
    if (left < 3600) snprintf(eta, sizeof eta, "%d:%02d", (int)(left / 60), (int)left % 60);
    else if (left < 1e7) snprintf(eta, sizeof eta, "%dh%02d", (int)(left / 3600),
                                  (int)(left / 60) % 60);
  }
  fprintf(stderr, "\r\033[Kstep %d  t %.4g / %.4g (%.0f%%)  dt %.2e  cells %d  Newton %d  "
                  "%.2f steps/s  ETA %s",
          s->step, s->t, s->t_end, 100 * done, s->dt, s->n_cells, s->newton_its,
          s->step / fmax(s->wall_seconds, 1e-9), eta);
  fflush(stderr);
  p->drawn = 1;
  return 0;
}

/** Exit status of a run stopped by a signal after writing its checkpoint
 *  (EX_TEMPFAIL: "try again", here with --resume). */
#define SP_EXIT_STOPPED 75

/* The stop signals: SIGTERM (a job's time limit), SIGINT (^C), SIGUSR1 (a
 * scheduler's warning). The first asks for a checkpoint at the end of the
 * step in progress and a stop (in `softpack run`, once the run has begun);
 * a second one (^C again), or any before the run, ends the process at once,
 * as without a handler.
 *
 * They are blocked in every thread from the first line of main, before
 * MPI_Init starts Open MPI's threads, and taken by a thread of their own
 * (sigwait): no handler runs inside the solver. A handler is not enough
 * ("SIGTERM: status 139"; tools/sigterm_in_metis.sh): Debian's
 * METIS (GKlib) installs its own SIGTERM handler for the length of
 * METIS_NodeND (gk_sigtrap) and longjmps out of it on a SIGTERM. METIS then
 * returns METIS_ERROR with the ordering unwritten, SuperLU_DIST (which does
 * not look at the code) factorises with that garbage column permutation and
 * segfaults in sp_colorder, and the stop never reaches softpack: no
 * checkpoint, no message. GKlib also puts the handler it displaced back with
 * System V semantics (one-shot, no SA_RESTART). A blocked signal waits for
 * sigwait whatever handler is installed. The handler below stays for threads
 * started before main with the signals unblocked (OpenBLAS's, which
 * hold_signals restarts blocked). */
static sigset_t stop_signals;
static atomic_int stop_signals_seen;
static atomic_int run_stops; /* 1 once a first signal means "checkpoint and stop" */

/** End the process by @p sig as without a handler. */
static void end_by_signal(int sig) {
  signal(sig, SIG_DFL);
  sigset_t one;
  sigemptyset(&one);
  sigaddset(&one, sig);
  pthread_sigmask(SIG_UNBLOCK, &one, NULL);
  raise(sig);
  _exit(128 + sig); /* (another handler got in first) */
}

/** A stop signal, taken by the waiting thread or (async-signal-safe) a handler. */
static void on_stop_signal(int sig) {
  if (atomic_fetch_add(&stop_signals_seen, 1) > 0 || !atomic_load(&run_stops))
    end_by_signal(sig);
  sp_run_request_stop();
}

static void *wait_stop_signals(void *unused) {
  (void)unused;
  for (;;) {
    int sig = 0;
    if (sigwait(&stop_signals, &sig) == 0) on_stop_signal(sig);
  }
  return NULL;
}

/** Block the stop signals in this thread and every thread it starts, start
 *  the thread that takes them, and restart OpenBLAS's threads (started when
 *  the library was loaded, before main) so that they block them too. */
static void hold_signals(void) {
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &stop_signals, NULL);
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
  /* OpenBLAS starts its threads again, from the thread that calls it */
  int (*blas_shutdown)(void) = (int (*)(void))dlsym(RTLD_DEFAULT, "blas_thread_shutdown_");
  if (blas_shutdown) blas_shutdown();
  pthread_t waiter;
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
  if (pthread_create(&waiter, &attr, wait_stop_signals, NULL) != 0) {
    /* no thread: the handler takes them, unblocked */
    pthread_sigmask(SIG_UNBLOCK, &stop_signals, NULL);
  }
  pthread_attr_destroy(&attr);
}

static int cmd_run(int argc, char **argv, int rank, int *stopped) {
  const char *scene_path = NULL, *out_dir = NULL;
  sp_restart restart = {0};
  const char **sets = calloc(argc > 0 ? argc : 1, sizeof(char *));
  int n_set = 0, quiet = 0;
  SP_CHECK(sets, SP_ERR_MEMORY, "out of memory");
  int rc = SP_OK;
  for (int i = 0; i < argc && rc == SP_OK; ++i) {
    if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) out_dir = argv[++i];
    else if (strcmp(argv[i], "--quiet") == 0) quiet = 1;
    else if (strcmp(argv[i], "--restart") == 0 && i + 1 < argc) restart.checkpoint = argv[++i];
    else if (strcmp(argv[i], "--resume") == 0 && i + 1 < argc) restart.resume_dir = argv[++i];
    else if (strcmp(argv[i], "--restart-as-initial") == 0) restart.as_initial = 1;
    else if (strcmp(argv[i], "--set") == 0 && i + 1 < argc) sets[n_set++] = argv[++i];
    else if (argv[i][0] == '-')
      rc = sp_error_set(SP_ERR_INPUT, "unknown option or missing value: %s", argv[i]);
    else if (!scene_path) scene_path = argv[i];
    else rc = sp_error_set(SP_ERR_INPUT, "more than one scene file: %s and %s", scene_path, argv[i]);
  }
  if (rc == SP_OK && !scene_path) rc = sp_error_set(SP_ERR_INPUT, "softpack run needs a scene file");
  if (rc == SP_OK && restart.checkpoint && restart.resume_dir)
    rc = sp_error_set(SP_ERR_INPUT, "--restart and --resume: give one");
  if (rc == SP_OK && restart.as_initial && !restart.checkpoint && !restart.resume_dir)
    rc = sp_error_set(SP_ERR_INPUT, "--restart-as-initial needs --restart or --resume");
  if (rc == SP_OK && !out_dir && restart.resume_dir && !restart.as_initial)
    out_dir = restart.resume_dir; /* continue where it ran */
  char out_default[4096];
  if (rc == SP_OK && !out_dir) {
    default_out_dir(scene_path, out_default, sizeof out_default);
    out_dir = out_default;
  }
  sp_run_summary sum = {0};
  /* a progress line only where someone watches: on a terminal, not --quiet */
  progress prog = {.rank = rank};
  const int show = !quiet && isatty(fileno(stderr));
  if (rc == SP_OK) {
    atomic_store(&run_stops, 1); /* a first stop signal: checkpoint and stop */
    rc = sp_run_file_restart(scene_path, n_set, sets, out_dir, &restart, MPI_COMM_WORLD,
                             show ? draw_progress : NULL, &prog, &sum);
  }
  if (prog.drawn) fputc('\n', stderr);
  *stopped = rc == SP_OK && sum.stopped == SP_STOPPED_SIGNAL;
  /* the summary means something only after a run that succeeded */
  if (rc == SP_OK && rank == 0) print_summary(&sum, out_dir);
  free(sets);
  return rc;
}

/** One thread per process unless the user set OMP_NUM_THREADS: Debian's
 *  SuperLU_DIST (OpenMP) and OpenBLAS (its own threads) otherwise start a
 *  thread per core in every MPI process, which oversubscribes the cores and
 *  slowed SuperLU_DIST several-fold (docs/benchmarks.md). Looked up at run
 *  time: neither library is a link dependency of the program. */
static void hold_threads(void) {
  if (getenv("OMP_NUM_THREADS")) return;
  void (*set_omp)(int) = (void (*)(int))dlsym(RTLD_DEFAULT, "omp_set_num_threads");
  if (set_omp) set_omp(1);
  void (*set_blas)(int) = (void (*)(int))dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
  if (set_blas) set_blas(1);
}

int main(int argc, char **argv) {
  hold_signals(); /* before MPI_Init: its threads block them too */
  MPI_Init(&argc, &argv);
  hold_threads();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int rc = SP_OK, stopped = 0;
  if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
    if (rank == 0) usage(stdout);
  } else if ((argc >= 2 && strcmp(argv[1], "--version") == 0) ||
             (argc >= 2 && strcmp(argv[1], "info") == 0)) {
    if (argc > 2)
      rc = sp_error_set(SP_ERR_INPUT, "softpack %s takes no arguments, got %s", argv[1], argv[2]);
    else if (rank == 0) {
      print_version(stdout);
      if (strcmp(argv[1], "info") == 0) sp_build_info_print(stdout, MPI_COMM_WORLD);
    }
  } else if (argc >= 2 && strcmp(argv[1], "keys") == 0) {
    if (rank == 0) sp_scene_print_keys(stdout);
  } else if (argc >= 2 && strcmp(argv[1], "run") == 0) {
    rc = cmd_run(argc - 2, argv + 2, rank, &stopped);
  } else if (argc >= 2 && strcmp(argv[1], "check-jacobian") == 0) {
    rc = sp_check_jacobian_command(argc - 2, argv + 2);
  } else {
    rc = sp_error_set(SP_ERR_INPUT, "unknown command%s%s (try softpack --help)",
                      argc >= 2 ? ": " : "", argc >= 2 ? argv[1] : "");
  }
  const int status = stopped ? SP_EXIT_STOPPED : sp_error_exit_status(rc);
  if (rc != SP_OK) {
    /* One rank's failure ends all ranks, never a hang. Rank 0 prints the
     * error (its own or, agreed, the failing rank's), and every other rank
     * that failed itself its own: an error seen by rank > 0 alone is not
     * lost. The class is named unless it is bad input. */
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    char what[64] = "";
    if (rc != SP_ERR_INPUT) snprintf(what, sizeof what, "%s", sp_error_class_name(rc));
    if (rank > 0)
      snprintf(what + strlen(what), sizeof what - strlen(what), "%srank %d of %d",
               what[0] ? ", " : "", rank, size);
    if (rank == 0 || !sp_error_adopted())
      fprintf(stderr, "softpack: error%s%s%s: %s\n", what[0] ? " (" : "", what,
              what[0] ? ")" : "", sp_error_message());
    /* an error the ranks agreed on ends each of them here; any other may
     * leave ranks waiting in a collective: MPI_Abort ends them */
    if (size > 1 && !sp_error_agreed()) MPI_Abort(MPI_COMM_WORLD, status);
  }
  MPI_Finalize();
  return status;
}
