#include "error.h"

#include <stdarg.h>
#include <stdio.h>

static char sp_error_buffer[2048];

int sp_error_set(int code, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(sp_error_buffer, sizeof sp_error_buffer, fmt, ap);
  va_end(ap);
  return code;
}

const char *sp_error_message(void) { return sp_error_buffer; }

void sp_error_clear(void) { sp_error_buffer[0] = '\0'; }

int sp_error_exit_status(int code) {
  if (code == SP_OK) return 0;
  if (code == SP_ERR_INPUT) return 2;
  return 1;
}
