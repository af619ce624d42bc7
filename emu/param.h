/*
** param.h — tables of named constants: one row per number, with its source.
**
** Every number tube74 takes from the hardware or the papers — the HITAC-10's timings
** (emu/params.c), the beam's settling (display/beam.c), the look of the phosphor
** (display/look.c), each USB device's settings (display/usb*.c) — is a row of such a table
** (as SIMH's REG and MTAB rows): its name, unit, default, accepted range, and where it
** comes from ("inferred: why" or "tuned by eye" when no document gives it). The user
** changes a row as NAME=VALUE; each module keeps its own messages and reads its values
** from a plain array of doubles indexed like its table.
*/
#ifndef T74_PARAM_H
#define T74_PARAM_H

#include <stddef.h>
#include <stdio.h>

struct param_row {
  const char *name;     /* as given in NAME=VALUE */
  const char *unit;     /* "us", "states", "mm", ... */
  double      def;      /* default value */
  double      min, max; /* accepted range, inclusive */
  int         integer;  /* 1: whole numbers only */
  const char *source;   /* the document's words, or "inferred: why", or "tuned by eye" */
};

enum param_check {
  PARAM_OK = 0,
  PARAM_NOT_NUMBER,     /* not a finite decimal number */
  PARAM_OUT_OF_RANGE    /* outside [min, max], or not whole for an integer row */
};

/* The row named name[0..len) (len: its length; name need not end there), or -1. */
int param_find(const struct param_row *rows, int n, const char *name, size_t len);

/* Read text as the value of row r: PARAM_OK with *v, else why not (*v untouched). */
int param_parse(const struct param_row *r, const char *text, double *v);

/* Every row's default into v[0..n). */
void param_defaults(const struct param_row *rows, int n, double *v);

/* One line a row: name, value, unit, source (name_w: the width of the name column). */
void param_list(const struct param_row *rows, int n, const double *v, int name_w, FILE *f);

#endif
