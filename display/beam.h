/*
** beam.h — the writing beam's timing: when each tube dot was written (paper 003 §4).
** Sources: paper 003 appendix (the tube: 21 x 16.3 cm face, 400 x 300 points);
** docs/hardware.md "The storage tube" (Tektronix 613 beam settling).
**
** This file contains code to put 1974 times on the dots of a picture. The program of
** paper 003 displayed while it computed: each point's halftone cell went to the tube as
** soon as the point's visible face was known, one display command per lit dot. So dot k
** could not be written before the computer had produced it (its COMPUTING time, from the
** cost model through the pipeline's clock hook), nor before the beam had finished dot k-1.
** Then the beam moves to it and settles (Tektronix 613: 14 us + 6 us/cm up to 2 cm,
** 3 us/cm beyond) and dwells long enough to store it:
**
**     start_k = max(compute_k, written_{k-1})
**     written_k = start_k + settle(distance from dot k-1 to dot k) + dwell
**
** Two totals come out: tube_seconds, the time the beam spent moving and dwelling (the
** sum of the settles and dwells), and total_1974_seconds, when the last dot was written
** (or the last computing time reported, if that is later: the picture is complete when
** both the computer and the beam are done).
**
** THE INTERFACE
**   struct beam_params          the timing constants, one row each (beam_param_rows)
**   beam_params_default(p)      the documented defaults
**   beam_params_set(p, "NAME=VALUE", err)     change one row (T74_EINPUT if unknown/bad)
**   beam_params_list(p, f)      print name, value, unit, source
**   beam_settle_us(p, cm)       settling time of a move of `cm` centimetres
**   beam_init(b, p)             a beam at rest at (home_x, home_y), nothing written yet
**   beam_dot(b, x, y, compute_s)     write one dot; returns the time it was written (s)
**   beam_clock(b, compute_s)    note computing time without a dot (end of the picture)
**   beam_wait(b, until_s)       the tube takes no dot before until_s (an erase under way)
**   beam_tube_seconds(b), beam_total_seconds(b), beam_dots(b)
** Nothing here allocates; a struct beam is plain data the caller owns.
*/
#ifndef T74_BEAM_H
#define T74_BEAM_H

#include <stdint.h>
#include <stdio.h>

#include "emu/param.h"
#include "emu/status.h"

enum beam_param {
  BP_FACE_W_CM,         /* width of the tube face (400 points across) */
  BP_FACE_H_CM,         /* height of the tube face (300 points up) */
  BP_SETTLE_BASE_US,    /* settling: fixed part of every move */
  BP_SETTLE_NEAR_US_CM, /* settling: per cm, for the first near_cm of a move */
  BP_SETTLE_NEAR_CM,    /* settling: length of the "short move" range */
  BP_SETTLE_FAR_US_CM,  /* settling: per cm beyond near_cm */
  BP_DWELL_US,          /* beam rests on the dot to store it */
  BP_HOME_X,            /* where the beam rests before the first dot (tube x) */
  BP_HOME_Y,            /* ... (tube y) */
  BP_NPARAM
};

struct beam_params { double v[BP_NPARAM]; };  /* indexed by enum beam_param */

extern const struct param_row beam_param_rows[BP_NPARAM];   /* emu/param.h */

void beam_params_default(struct beam_params *p);
int  beam_params_set(struct beam_params *p, const char *name_eq_value, struct t74_error *err);
int  beam_params_list(const struct beam_params *p, FILE *f);

/* Settling time, microseconds, of a move of `cm` centimetres on the face (0 for no move). */
double beam_settle_us(const struct beam_params *p, double cm);

/* Distance on the face, centimetres, between tube dots (x0, y0) and (x1, y1). */
double beam_distance_cm(const struct beam_params *p, int x0, int y0, int x1, int y1);

struct beam {
  struct beam_params p; /* the constants in force */
  int x, y;             /* where the beam is now (tube coordinates) */
  double free_s;        /* when the beam finished its last dot (1974 seconds) */
  double tube_s;        /* sum of settles and dwells so far */
  double compute_s;     /* latest computing time reported */
  uint64_t dots;        /* dots written */
};

void beam_init(struct beam *b, const struct beam_params *p);

/* Write dot (x, y), which the computer produced at compute_s (1974 seconds since the
** start of the job). Returns the time it was written (its dwell ends then). */
double beam_dot(struct beam *b, int x, int y, double compute_s);

/* Note computing time with no dot (e.g. the end of the job). */
void beam_clock(struct beam *b, double compute_s);

/* The tube stores nothing before until_s (1974 seconds): an erase (ESC FF) is under way.
** The next dot starts no earlier, and the picture is not complete before then
** (beam_total_seconds); the beam is not busy meanwhile (beam_tube_seconds unchanged). */
void beam_wait(struct beam *b, double until_s);

double beam_tube_seconds(const struct beam *b);
double beam_total_seconds(const struct beam *b);
uint64_t beam_dots(const struct beam *b);

#endif
