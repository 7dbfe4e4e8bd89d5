#include "run/stop.h"

#include <stdatomic.h>

#include "base/agree.h"
#include "public/error.h"
#include "base/fault.h"

/* (lock-free: async-signal-safe; set from softpack run's signal thread) */
static atomic_int stop_requested;

void sp_stop_request(void) { atomic_store(&stop_requested, 1); }

int sp_stop_requested(void) { return atomic_load(&stop_requested) != 0; }

void sp_stop_clear(void) { atomic_store(&stop_requested, 0); }

int sp_stop_poll(void *ctx) {
  sp_run *run = ctx;
  if (sp_fault_interrupt_poll(run->rank)) sp_stop_request();
  int want_stop = sp_stop_requested();
  return sp_agree_any(run->agree_comm, &want_stop) != SP_OK || want_stop;
}
