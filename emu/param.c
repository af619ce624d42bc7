/*
** param.c — tables of named constants (see param.h).
**
** This file contains code to look a row up by name, to read a user's value for it with
** its range checked (exactly as written: a finite decimal number, whole where the row
** says so), and to print a table with the sources of its numbers.
*/
#include "emu/param.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int param_find(const struct param_row *rows, int n, const char *name, size_t len)
{
  for (int k = 0; k < n; k++)
    if (strlen(rows[k].name) == len && strncmp(rows[k].name, name, len) == 0) return k;
  return -1;
}

int param_parse(const struct param_row *r, const char *text, double *v)
{
  char *end;
  errno = 0;
  double x = strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !isfinite(x)) return PARAM_NOT_NUMBER;
  if (x < r->min || x > r->max || (r->integer && x != floor(x))) return PARAM_OUT_OF_RANGE;
  *v = x;
  return PARAM_OK;
}

void param_defaults(const struct param_row *rows, int n, double *v)
{
  for (int k = 0; k < n; k++) v[k] = rows[k].def;
}

void param_list(const struct param_row *rows, int n, const double *v, int name_w, FILE *f)
{
  for (int k = 0; k < n; k++)
    fprintf(f, "%-*s %12g  %-12s %s\n", name_w, rows[k].name, v[k], rows[k].unit,
            rows[k].source);
}
