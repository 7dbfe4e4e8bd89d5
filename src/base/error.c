#include "public/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static char sp_error_buffer[SP_ERROR_MESSAGE_MAX];
/* whether the recorded error is agreed by every rank, and whether it is
 * another rank's (agree.h) */
static int sp_error_is_agreed, sp_error_is_adopted;

int sp_error_set(int code, const char *fmt, ...) {
  /* through a copy: an argument may be sp_error_message() itself (a
   * message prefixed with the key it came from) */
  char text[sizeof sp_error_buffer];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  memcpy(sp_error_buffer, text, sizeof text);
  sp_error_is_agreed = sp_error_is_adopted = 0;
  return code;
}

const char *sp_error_message(void) { return sp_error_buffer; }

void sp_error_clear(void) {
  sp_error_buffer[0] = '\0';
  sp_error_is_agreed = sp_error_is_adopted = 0;
}

int sp_error_exit_status(int code) {
  if (code == SP_OK) return 0;
  if (code == SP_ERR_INPUT) return 2;
  return 1;
}

const char *sp_error_class_name(int code) {
  switch (code) {
    case SP_OK: return "ok";
    case SP_ERR_SOLVER: return "solver";
    case SP_ERR_INPUT: return "bad input";
    case SP_ERR_IO: return "output";
    case SP_ERR_MEMORY: return "memory";
    case SP_ERR_MPI: return "MPI";
    default: return "internal";
  }
}

void sp_error_mark_agreed(int adopted) {
  sp_error_is_agreed = 1;
  sp_error_is_adopted = adopted != 0;
}

int sp_error_agreed(void) { return sp_error_is_agreed; }

int sp_error_adopted(void) { return sp_error_is_adopted; }
