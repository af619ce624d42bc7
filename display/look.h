/*
** look.h — how the storage tube LOOKED, over time (paper 003 §4 and appendix; hardware-
** facts.md "The storage tube"; the constants of rricharz/Tek4010).
**
** This file contains code to model the face of a direct-view bistable storage tube as it
** changes in time, and to render it to an RGBA picture at any integer scale. It is a
** layer for looks only: the exact stored picture is display/tube.h (what --dump tube
** shows and every check uses); nothing here feeds back into it (style.md).
**
** The model keeps events, each with its 1974 time in seconds (display/beam.h gives the
** times of the dots a render writes):
**   look_dot(l, x, y, t)          the writing beam stores dot (x, y) at time t. While being
**                                 written it flashes bright (LOOK_FLASH), then glows at
**                                 the stored level until erased; with LOOK_FADE the stored
**                                 charge slowly spreads and dims.
**   look_writethrough(l, x, y, t) a write-through dot: dim, NOT stored, fading at once
**                                 (the cursor / refreshed-trace mode of the 4010 family).
**   look_erase(l, t)              the whole face flashes green, then is clear after
**                                 erase_s (paper 003: under 500 ms). Dots stored before the
**                                 erase are gone afterwards; a dot given a time inside the
**                                 last erase is written when it ends.
** and look_render(l, t, scale, rgba) draws the face as it is at time t: the faint flood
** glow everywhere, each stored dot a P1-green spot whose size comes from the dot pitch
** (0.525 mm across x 0.543 mm up), flashes, traces and the erase flash added on top.
** look_intensity gives the same picture as linear intensities (1.0 = the bright spot),
** for tests and for anyone who wants to map colours differently.
**
** Every constant is one row of look_param_rows with its source or "tuned by eye";
** look_params_set changes a row from "NAME=VALUE".
**
** Pictures are 400*scale x 300*scale pixels, row 0 = the TOP of the tube (tube y 299),
** as image files store them; dot (x, y) covers pixels [x*s, x*s+s) x [(299-y)*s, ..+s).
*/
#ifndef T74_LOOK_H
#define T74_LOOK_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "display/outfile.h"
#include "emu/param.h"
#include "emu/status.h"

#define LOOK_SCALE_MAX 8        /* largest --scale */

enum look_param {
  LP_STORED,            /* intensity of a stored dot's peak */
  LP_WRITETHRU,         /* intensity of a write-through dot when written */
  LP_WRITETHRU_S,       /* a write-through dot fades to nothing over this time */
  LP_BRIGHT,            /* intensity of the writing beam's bright spot */
  LP_FLASH_S,           /* the bright spot fades to the stored level over this time */
  LP_GLOW,              /* flood-gun glow over the whole face */
  LP_ERASE_S,           /* erase: flash, then the face is clear after this time */
  LP_ERASE_LEVEL,       /* intensity of the erase flash at its start */
  LP_PITCH_X_MM,        /* dot pitch across */
  LP_PITCH_Y_MM,        /* dot pitch up */
  LP_SPOT_MM,           /* sigma of the Gaussian spot of a stored dot */
  LP_FADE_S,            /* fade: time constant of dimming (when fading is asked) */
  LP_FADE_SPREAD_MM,    /* fade: the spot's sigma grows by this (in quadrature) per fade_s */
  LP_P1_R, LP_P1_G, LP_P1_B,   /* P1 phosphor colour at intensity 1 (0..1 each) */
  LP_BLOOM,             /* intensity above 1 whitens by this much per unit */
  LP_NPARAM
};

struct look_params { double v[LP_NPARAM]; };   /* indexed by enum look_param */

extern const struct param_row look_param_rows[LP_NPARAM];   /* emu/param.h */

void look_params_default(struct look_params *p);
int  look_params_set(struct look_params *p, const char *name_eq_value, struct t74_error *err);
int  look_params_list(const struct look_params *p, FILE *f);

/* What is simulated beyond the stored dots and the glow (both always drawn). */
enum {
  LOOK_FLASH = 1u << 0,  /* the bright writing spot, fading over flash_s */
  LOOK_FADE  = 1u << 1   /* stored charge spreads and dims (fade_s) */
};

struct look;            /* opaque: parameters, flags, the events so far */

/* A new face with no events; NULL when out of memory. */
struct look *look_new(const struct look_params *p, unsigned flags);
void look_free(struct look *l);

/* Events. T74_OK, T74_EINPUT for a dot outside the tube, T74_EIO when out of memory. */
int look_dot(struct look *l, int x, int y, double t);
int look_writethrough(struct look *l, int x, int y, double t);
int look_erase(struct look *l, double t);

/* Forget every event (a fresh face; parameters and flags kept). */
void look_clear(struct look *l);

size_t look_count(const struct look *l);          /* dots stored (look_dot calls) */
/* Time of the k-th look_dot event (k < look_count) and its dot; T74_EINPUT if out of range. */
int look_event(const struct look *l, size_t k, int *x, int *y, double *t);
/* When the face stops changing (last event plus its flash / erase / trace), fade aside. */
double look_settled(const struct look *l);
const struct look_params *look_get_params(const struct look *l);
unsigned look_flags(const struct look *l);

/* The face at time t as linear intensities, (400*scale) x (300*scale) floats, row 0 at
** the top. T74_OK, T74_EINPUT for a scale outside 1..LOOK_SCALE_MAX, T74_EIO if out of
** memory (for a fading spot's kernel). */
int look_intensity(const struct look *l, double t, int scale, float *out);

/* The face at time t as RGBA bytes (4 per pixel, alpha 255), same layout. */
int look_render(const struct look *l, double t, int scale, uint8_t *rgba);

/* Intensity -> RGBA with the P1 colour and bloom of p (one pixel). */
void look_colour(const struct look_params *p, float intensity, uint8_t rgba[4]);

/* look_render at time t, written as an RGB PNG, atomically (display/outfile.h). */
int look_write_png(const struct look *l, double t, int scale, const char *path,
                   struct t74_error *err);

/* Any RGBA picture (w x h, row 0 at the top) as an RGB PNG, atomically. */
int look_png_rgba(const uint8_t *rgba, int w, int h, const char *path, struct t74_error *err);

/* The same two onto an output already opened (display/outfile.h: one of a set); they
   finish it (outfile_commit) or discard it on failure. */
int look_write_png_to(const struct look *l, double t, int scale, struct outfile *o,
                      struct t74_error *err);
int look_png_rgba_to(const uint8_t *rgba, int w, int h, struct outfile *o,
                     struct t74_error *err);

#endif
