/*
** effects.h — the `effects KEY=VALUE ...` line: which simulated effects a scene calls for.
**
** Paper references: halftone cells (paper 003), multi-scanning anti-aliasing (paper 000),
** adaptive area sampling (paper 001), enhanced edges (paper 002), smooth and partial
** smoothing (paper 004). The keys and their defaults are fixed by shared/CONTRACT.md,
** section "Effects": only the effects named are simulated; a key given without `=VALUE`
** takes the value listed first in the contract (halftone=4x4, aa=none, filter=box, n=3,
** super=3, depth=3, edges=on, smooth=gouraud, tube=stored); sigma= and contour= need
** a value (contour=none is the default: no contour smoothing).
**
** The same parser serves the scene file's `effects` line and the `--effects` option, so
** a bad key or value is reported once, as "FILE:LINE: effects: ...".
*/
#ifndef T74_EFFECTS_H
#define T74_EFFECTS_H

#include <stdbool.h>
#include <stddef.h>
#include "emu/status.h"

/* Bits of struct effects.given: which keys the text named. */
enum {
  EFFECTS_HALFTONE = 1u << 0,
  EFFECTS_PATTERN  = 1u << 1,
  EFFECTS_AA       = 1u << 2,
  EFFECTS_FILTER   = 1u << 3,
  EFFECTS_N        = 1u << 4,
  EFFECTS_SUPER    = 1u << 5,
  EFFECTS_EDGES    = 1u << 6,
  EFFECTS_OUTLINE  = 1u << 7,
  EFFECTS_INNER    = 1u << 8,
  EFFECTS_SMOOTH   = 1u << 9,
  EFFECTS_CONTOUR  = 1u << 10,
  EFFECTS_TUBE     = 1u << 11,
  EFFECTS_SIGMA    = 1u << 12,
  EFFECTS_DEPTH    = 1u << 13,
  EFFECTS_HALO     = 1u << 14,
  EFFECTS_SHADOWS  = 1u << 15
};

enum effects_aa     { EFFECTS_AA_NONE, EFFECTS_AA_MULTISCAN, EFFECTS_AA_AREA,
                      EFFECTS_AA_SUPER, EFFECTS_AA_EXACT };
enum effects_filter { EFFECTS_FILTER_BOX, EFFECTS_FILTER_GAUSS };
enum effects_smooth { EFFECTS_SMOOTH_NONE,      /* flat: one intensity per face (absent) */
                      EFFECTS_SMOOTH_GOURAUD, EFFECTS_SMOOTH_PHONG,
                      EFFECTS_SMOOTH_FIXED,     /* fixed:C, C in smooth_c */
                      EFFECTS_SMOOTH_PROP };    /* prop:C,  C in smooth_c */
enum effects_tube   { EFFECTS_TUBE_STORED, EFFECTS_TUBE_FADE, EFFECTS_TUBE_FLASH };

#define EFFECTS_PATTERN_MAX 31      /* longest pattern name */
#define EFFECTS_NSUB_MAX    16      /* largest n= and super= */
#define EFFECTS_WIDTH_MAX   16      /* largest outline/inner/halo width, in points */
#define EFFECTS_DEPTH_MAX   8       /* largest depth= (area sampling's subdivision limit) */
#define EFFECTS_SIGMA_MAX   4.0     /* largest sigma=, in points */
#define EFFECTS_FADE_MIN    1e-3    /* tube=fade:S range in seconds, the same as the */
#define EFFECTS_FADE_MAX    1e6     /* --look fade:S option's and the look's fade_s row */

struct effects {
  unsigned given;                   /* EFFECTS_* bits of the keys named */
  int   halftone;                   /* 3 or 4: dot cell side (absent: 4) */
  char  pattern[EFFECTS_PATTERN_MAX + 1];  /* cell family; "" = the default family */
  enum effects_aa aa;               /* absent: none */
  enum effects_filter filter;       /* absent: box */
  int   n;                          /* sub-scanlines per point, 1..16 (absent: 3) */
  int   super;                      /* samples per axis, 1..16 (absent: 3) */
  double sigma;                     /* Gaussian filter's sigma in points, (0, 4] (0.5) */
  int   depth;                      /* area sampling's subdivision depth 1..8 (absent: 3) */
  bool  edges;                      /* enhanced edges (absent: off; given alone: on) */
  bool  shadows;                    /* shadows of the scene's lights, paper 000 §3 (absent:
                                       off; given alone: on) */
  double outline_w; int outline_g;  /* outline width 0..16 points (fractions allowed),
                                       grey 0..255 (absent: 1.5 wide, 0 dark) */
  double inner_w;   int inner_g;    /* inner-edge width and grey (absent: 0.75, 160) */
  double halo_w;    int halo_g;     /* halo just outside an outline (absent: 0.75, 255) */
  enum effects_smooth smooth;       /* absent: none (flat shading) */
  double smooth_c;                  /* C of fixed:C / prop:C, finite, 0..1e6 */
  bool  contour_on;                 /* contour=CC given (not `none`) */
  double contour;                   /* contour=CC: a real in 0..1 (absent / none: off) */
  enum effects_tube tube;           /* absent: stored */
  double fade_seconds;              /* tube=fade:SECONDS, EFFECTS_FADE_MIN..MAX */
};

/* The effects in force when none are named. */
void effects_default(struct effects *out);

/* Parse blank-separated KEY[=VALUE] tokens (text may be NULL or empty: no effects).
   Starts from effects_default. A repeated key, an unknown key or a bad value fails with
   T74_EINPUT "FILE:LINE: effects: ..." (file may be NULL: the message then starts
   "effects: "). Returns T74_OK or the status held by err. */
int effects_parse(const char *text, struct effects *out, const char *file, int line,
                  struct t74_error *err);

/* Canonical text of the keys given (fixed key order, full values), like snprintf:
   returns the length the whole text needs; buf (n bytes) always NUL-terminated if n>0. */
int effects_format(const struct effects *e, char *buf, size_t n);

#endif
