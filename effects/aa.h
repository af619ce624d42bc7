/*
** aa.h — anti-aliasing of papers 000 (Nishita & Nakamae, multi-scanning) and 001
** (Kumamoto, area sampling), with supersampling and an exact reference: the "aa" slot of
** the effects stage (effects/fx.h), between the Visible Surface Procedure and the halftone.
**
** This file contains the interface of the aa_ module. aa_run replaces each point's flat
** grey in the frame by the mix of what the point's filter sees, for the method named by
** `aa=`: multiscan (filter=box: 000 §2.2.1 eq. (1)-(3); filter=gauss: 000 §2.2.2, §3.3
** eq. (4), (5)), area (001), super (000 method D), exact (the yardstick). Every method
** asks the engine that drew the frame (effects/see.h) what is seen: with the 1974 engine,
** its exact visible-span procedure (vis_spans, render/visible.h) along sub-scanlines, whose
** covering set with the front piece from the Priority Matrix is paper 000's NEXT stack
** (§3.2); with the points engine (aa=super only: the other methods integrate the 1974
** program's stretches), its exact answer at each sample. There is no second visibility
** code, and a hidden face contributes nothing.
**
** Light, not grey: grey G lights round((L+1)^(G/255) - 1) of a cell's L dots
** (patterns/halftone.c), so every method mixes the dot fraction ((L+1)^(G/255) - 1) / L
** of its fragments and converts the mix back to the grey whose light is nearest
** (aa_light / aa_grey; a 256-word table in core, searched by halving).
**
** The machine model: each method's tables (light table, F table, area table) and row
** buffers are allocated in the engine's core; its operations are counted in the cost it
** is given.
** Details and choices: docs/aa.md.
*/
#ifndef T74_AA_H
#define T74_AA_H

#include <stdint.h>
#include "emu/cost.h"
#include "emu/status.h"
#include "render/effects.h"
#include "effects/fx.h"
#include "render/render.h"

/* Run the method e->aa (not EFFECTS_AA_NONE) over frame f (see fx_run), drawn by eng on
   its grid eng->g. */
int aa_run(const struct fx_engine *eng, const struct effects *e, struct fx_frame *f,
           struct fx_stats *st, struct cost *cost, struct t74_error *err);

/* The same, but the light (0..1, the fraction of the cell's dots) of every point into
   light[j * W + i], the frame untouched: for tests and the bench. */
int aa_light_map(const struct fx_engine *eng, const struct effects *e, const struct fx_frame *f,
                 struct fx_stats *st, struct cost *cost, double *light, struct t74_error *err);

/* ---- light <-> grey (exposed for tests and the bench) ------------------------------- */

#define AA_LIGHT_ONE 32768      /* light fixed point: 32768 = every dot of the cell lit */

/* Light of grey g (0..255) in a cell of `cell` x `cell` dots, in 1/AA_LIGHT_ONE:
   round(AA_LIGHT_ONE * ((L+1)^(g/255) - 1) / L), L = cell * cell. */
int aa_light(int cell, int g);

/* The grey 0..255 whose light is nearest to `light` (a fraction 0..1 of the cell's
   dots; values outside are clamped). Ties go to the darker grey. */
int aa_grey(int cell, double light);

/* ---- the tables (exposed for tests) ------------------------------------------------- */

#define AA_FSTEPS 64            /* F_l(x') tabulated at 64 steps of x' (000 §2.2.2) */
#define AA_FONE   32768         /* the F table's unit: a filter volume of 1 */

/* The F table of multiscan gauss for n sub-scanline intervals and Gaussian sigma (in
   points), truncated at one point's radius: t[l * (AA_FSTEPS + 1) + k] = F_l(k / 64) in
   1/AA_FONE, l = 0 .. n-1 (F_n, the outermost line, is ignored as in the paper), with
   2 F_0(1) + 4 (F_1(1) + .. + F_{n-1}(1)) = AA_FONE exactly. t holds n * 65 values. */
void aa_ftable(int n, double sigma, uint16_t *t);

/* F_l(x') from the table by linear interpolation between the 64 steps; xq is x' in
   1/65536 (0 .. 65536). */
int aa_ftable_at(const uint16_t *t, int l, int32_t xq);

#define AA_AREA_STEPS 32        /* the area table: 33 x 33 entries (see aa_area.c) */
#define AA_AREA_WORDS ((AA_AREA_STEPS + 1) * (AA_AREA_STEPS + 1))

/* Coverage (0..1) of the unit square centred at the origin by the side of a straight
   edge that holds the centre, computed exactly (polygon clipping): h and v are the
   horizontal and vertical distances from the centre to the edge, in units of the
   square's side (>= 0; HUGE_VAL or anything beyond 1e30 for "never"). */
double aa_area_cover_exact(double h, double v);

/* The area table (001): t[a * 33 + b] = that coverage at h = s/(1-s), v = w/(1-w),
   s = a/32, w = b/32 (s = 1: never), in 1/AA_LIGHT_ONE. */
void aa_area_table(uint16_t *t);

/* The coverage from the table: indexed by h/(1+h) and v/(1+v), bilinear between the
   1/32 steps. */
double aa_area_lookup(const uint16_t *t, double h, double v);

/* ---- one frame from a scene file, for tests and the bench (effects/aa_frame.c) ----------- */

struct aa_frame {
  int W, H, cell;
  double *light;            /* W * H light 0..1 after the method (aa=none: the flat grey's) */
  uint8_t *grey;            /* W * H grey, as --dump grey shows it */
  int *face;                /* W * H face at each point centre, -1 none */
  struct cost render;       /* Mapper + Segment Generator + Priority Matrix/Visible Surface */
  struct cost fx;           /* the anti-aliasing method */
  uint32_t core_peak;       /* core_words_used */
  double host_seconds;      /* Mapper to the frame's intensities (no halftone, no tube) */
  struct fx_stats st;
};

/* Load scene `path` (.s74), apply the effects text (NULL: the scene's own), render in a
   core of core_words words and run the anti-aliasing named (aa=none: none). cell 0:
   the scene's. On failure, the status with err set, and f holds nothing to free. */
int aa_frame_render(const char *path, const char *effects, int cell, uint32_t core_words,
                    struct aa_frame *f, struct t74_error *err);
void aa_frame_free(struct aa_frame *f);

#endif
