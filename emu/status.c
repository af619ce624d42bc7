/*
** status.c — the sticky error record of status.h.
*/
#include "emu/status.h"

#include <stdarg.h>
#include <stdio.h>

int t74_fail(struct t74_error *e, int status, const char *fmt, ...)
{
  if (!e) return status;                  /* a verdict alone: nothing formatted */
  if (e->status != T74_OK) return e->status;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e->msg, sizeof e->msg, fmt, ap);
  va_end(ap);
  e->status = status;
  return status;
}

int t74_fail_at(struct t74_error *e, int status, const char *file, int line,
                const char *fmt, ...)
{
  if (!e) return status;
  if (e->status != T74_OK) return e->status;
  int n = snprintf(e->msg, sizeof e->msg, "%s:%d: ", file, line);
  if (n < 0 || (size_t)n >= sizeof e->msg) n = 0;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e->msg + n, sizeof e->msg - (size_t)n, fmt, ap);
  va_end(ap);
  e->status = status;
  return status;
}
