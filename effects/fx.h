/*
** fx.h — the effects stage: the picture as intensities, between the Visible Surface
** Procedure and the halftone (the later papers' techniques, applied only when asked).
**
** This file contains the one place where the effects of papers 000/001 (anti-aliasing),
** 002 (enhanced edges) and 004 (smooth and partial smoothing, contour smoothing) meet the
** 1974 pipeline. With no such effect named, the pipeline never enters this stage and runs
** exactly the code path of paper 003 (point -> face -> grey -> halftone -> sinks).
**
** With one named, the pipeline first scans the grid as usual into a frame (struct
** fx_frame: the face seen at each point centre, its flat grey, the background's grey),
** then fx_run hands the frame to each requested effect in a fixed order:
**
**     smooth (004: intensity per point, contour cut)  ->  aa (000/001: coverage mixed in
**     light)  ->  edges (002: lines drawn over the picture)
**
** and the pipeline then sends the frame's points through the halftone to the sinks, in
** the same scan order as ever (bottom row first, left to right). Every effect resolves
** visibility by asking the engine that drew the frame (effects/see.h: the 1974 program or
** the points engine, each its own exact way); none has a visibility code of its own.
** Smoothing, contour cuts, shadows, textures and supersampling run with either engine;
** multi-scanning, area sampling, the exact reference and enhanced edges work on the 1974
** program's sub-scanline stretches and cuts, and run with it alone (fx_needs_1974).
**
** The machine model: each effect allocates its tables and row buffers in the engine's
** core and counts its operations in the cost it is given, so under the 1974 engine
** hitac10_seconds and core_words_used include it (the points engine reports neither).
** Each effect adds its own --stats fields with fx_count().
*/
#ifndef T74_FX_H
#define T74_FX_H

#include <stdbool.h>
#include <stdint.h>
#include "emu/cost.h"
#include "emu/status.h"
#include "effects/see.h"
#include "render/effects.h"
#include "render/scene.h"
#include "render/visible.h"

/* The picture of one render, point by point; index (j * W + i), j counted from the top. */
struct fx_frame {
  int W, H;                 /* points across and down */
  int cell;                 /* halftone cell side (3 or 4) */
  int *face;                /* visible face at each point centre (index in the engine's
                               map.f), -1
                               for none; an effect that changes what is seen (a contour
                               cut) updates it, and the ids dump follows */
  uint8_t *grey;            /* intensity 0..255 (perceptual, as pat_level takes it); on
                               entry the flat face grey, or the background's (or not yet
                               written: face_grey below) */
  const uint8_t *bg;        /* the background picture's intensity per point (NULL: none,
                               the background is black) */
  const struct fx_model *model;   /* while fx_run runs: the frame model every effect reads
                               (effects/model.h); NULL: the Visible Surface Procedure's
                               stretches and the frame's greys as they are */
  const uint8_t *face_grey; /* not NULL: grey is not written yet, each point's being its
                               face's flat grey, face_grey[face + 1] (face_grey[0] for none:
                               no background); fx_run writes it, or leaves it to the point
                               frame, which writes every point's (effects/model.h) */
};

/* Room for every statistic the effects can name in one run: 44 names in all, every aa
   method's included (grep fx_count effects/). Keep it above that count: fx_count drops
   a name that finds no room, and its --stats field would be missing. */
#define FX_MAX_COUNTERS 64
#define FX_NAME_MAX 40

/* Statistics an effect reports: named numbers, written into --stats as they are. Only
   fx_count adds to them (hash[] finds a name again with one string compared). */
struct fx_stats {
  int n;
  char name[FX_MAX_COUNTERS][FX_NAME_MAX];
  double value[FX_MAX_COUNTERS];
  bool integer[FX_MAX_COUNTERS];    /* print as an integer */
  uint64_t hash[FX_MAX_COUNTERS];   /* fx_name_hash of name[k] */
};

struct fx_model;

/* Does e, or scene s, call for an effect that works on the frame (aa, edges, smooth,
   contour, shadows, a texture)? */
bool fx_wanted(const struct effects *e, const struct scene *s);

/* Run the requested effects over f (see the order above). eng is the engine that drew
   the frame (see.h) on its grid eng->g; s is the scene it came from. Operations are counted in
   cost; tables live in eng->core (T74_ECORE when they do not fit). An effect only the 1974
   engine draws, asked of the points engine: T74_EINPUT (fx_needs_1974 says why). */
int fx_run(const struct fx_engine *eng, const struct scene *s, const struct effects *e,
           struct fx_frame *f, struct fx_stats *st, struct cost *cost, struct t74_error *err);

/* Add (or add to) a named statistic. */
void fx_count(struct fx_stats *st, const char *name, double v, bool integer);

#endif
