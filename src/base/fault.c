#include "base/fault.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "public/error.h"

static const char *const phase_names[] = {"setup",  "solver",    "step",  "output", "assembly",
                                          "attach", "interrupt", "factor"};
#define N_PHASES (int)(sizeof phase_names / sizeof phase_names[0])

/** What SOFTPACK_FAULT asks for: 0 and *phase, *rank, *kill (and for
 *  interrupt *step) set; -1 if it is malformed; 1 if it is unset or empty. */
static int fault_wanted(int *phase, int *rank, int *kill, long *step, long *attempt) {
  const char *spec = getenv("SOFTPACK_FAULT");
  if (!spec || !*spec) return 1;
  const char *colon = strchr(spec, ':');
  if (!colon) return -1;
  *phase = -1;
  for (int p = 0; p < N_PHASES; ++p)
    if ((size_t)(colon - spec) == strlen(phase_names[p]) &&
        strncmp(spec, phase_names[p], (size_t)(colon - spec)) == 0)
      *phase = p;
  char *end;
  const long r = strtol(colon + 1, &end, 10);
  *kill = strcmp(end, ":kill") == 0;
  *step = *attempt = -1;
  if (*phase == SP_FAULT_INTERRUPT) { /* interrupt:RANK:STEP[:ATTEMPT] */
    char *end2 = end, *end3;
    *step = *end == ':' ? strtol(end + 1, &end2, 10) : -1;
    *attempt = *end2 == ':' ? strtol(end2 + 1, &end3, 10) : 1;
    if (*end2 == ':' && (end3 == end2 + 1 || *end3)) return -1;
    if (end == colon + 1 || r < 0 || r > 1 << 30 || *step < 1 || end2 == end + 1 ||
        (*end2 && *end2 != ':') || *attempt < 1)
      return -1;
    *rank = (int)r;
    return 0;
  }
  if (*phase < 0 || end == colon + 1 || r < 0 || r > 1 << 30 || (*end && !*kill) ||
      (*kill && *phase == SP_FAULT_SOLVER))
    return -1;
  *rank = (int)r;
  return 0;
}

int sp_fault_due(sp_fault_phase phase, int rank) {
  int p, r, kill;
  long step, attempt;
  if (fault_wanted(&p, &r, &kill, &step, &attempt) != 0 || p != (int)phase || r != rank)
    return 0;
  if (kill) raise(SIGKILL);
  return 1;
}

int sp_fault_interrupt_due(int rank, int step, int attempt) {
  int p, r, kill;
  long s, a;
  return fault_wanted(&p, &r, &kill, &s, &a) == 0 && p == SP_FAULT_INTERRUPT && r == rank &&
         s == step && a == attempt;
}

/* The attempt in progress of this process's run, as an interrupt fault
 * counts it: its step, its number within the step, the stop polls in it. */
static int attempt_step, attempt_number, attempt_polls;

void sp_fault_attempt_begin(int step, int first_of_step) {
  if (first_of_step) attempt_number = 0;
  attempt_step = step;
  ++attempt_number;
  attempt_polls = 0;
}

int sp_fault_interrupt_poll(int rank) {
  return ++attempt_polls == 2 && sp_fault_interrupt_due(rank, attempt_step, attempt_number);
}

int sp_fault_check(sp_fault_phase phase, int rank) {
  int p, r, kill;
  long step, attempt;
  if (phase == SP_FAULT_SETUP && fault_wanted(&p, &r, &kill, &step, &attempt) < 0)
    return sp_error_set(SP_ERR_INPUT, "SOFTPACK_FAULT: expected PHASE:RANK or PHASE:RANK:kill "
                        "with PHASE setup, solver, step, output, assembly, attach or factor, or "
                        "interrupt:RANK:STEP[:ATTEMPT] (STEP, ATTEMPT >= 1), got '%s'",
                        getenv("SOFTPACK_FAULT"));
  if (!sp_fault_due(phase, rank)) return SP_OK;
  const char *name = phase_names[phase];
  switch (phase) {
    case SP_FAULT_OUTPUT:
      return sp_error_set(SP_ERR_IO, "cannot write the fields on rank %d (fault injected by "
                          "SOFTPACK_FAULT=%s:%d)", rank, name, rank);
    default:
      return sp_error_set(SP_ERR_MEMORY, "out of memory at %s on rank %d (fault injected by "
                          "SOFTPACK_FAULT=%s:%d)", name, rank, name, rank);
  }
}
