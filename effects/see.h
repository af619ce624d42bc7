/*
** see.h — the engine as the effects see it: its faces, room for the effects' tables, and
** one question, "which face is seen here", answered by each engine its own exact way.
**
** The effects of papers 000-004 work on the picture, not on how visibility was found.
** What they need from the engine that drew the frame is small:
**   - the Mapper's faces (render/mapper.h: planes, greys, grid polygons; the frame's face
**     numbers index them), the same for both engines;
**   - a core for their tables: the 1974 engine's own (its words are charged and show in
**     --stats), or under the points engine a host core of the effects' own that grows as
**     needed and is never reported (the points engine models no machine);
**   - the face seen at the samples of a lattice K times finer than the points (fx_see_row;
**     K = 1: the point centres), optionally with some faces taken away (what a contour cut
**     shows behind its object). The 1974 engine answers from the Visible Surface
**     Procedure's exact stretches along the sample row (render/visible.h), the points
**     engine from its exact per-sample test (render/points_at.h). Both use the same
**     coverage and tie rules; they differ only where the 1974 program cuts crossing faces
**     along a carrier line a few grid units from the true intersection (README
**     "Exactness"), where the points engine is the exact one.
**
** The 1974 engine also answers with whole stretches along any horizontal line
** (fx_see_spans): anti-aliasing by multi-scanning (paper 000) and by area sampling (001)
** and the exact reference integrate coverage over sub-scanlines, and enhanced edges (002)
** draw the lines along which its Priority Matrix cut crossing faces. Those work on the
** 1974 program's own stretches and cuts, which the points engine does not make: they run
** with the 1974 engine only, and fx_needs_1974 names them for the refusal.
*/
#ifndef T74_SEE_H
#define T74_SEE_H

#include <stdbool.h>
#include <stdint.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/effects.h"
#include "render/mapper.h"
#include "render/visible.h"

struct render;
struct points;
struct smooth_scene;
struct fx_textures;
struct shadow_keep;

struct fx_engine {
  const struct mapped *map;         /* the Mapper's faces */
  struct core *core;                /* where the effects keep their tables */
  const struct vis_grid *g;         /* the grid the frame was drawn on */
  struct render *r;                 /* the 1974 engine (prepared and scanned), or NULL */
  const struct points *pts;         /* the points engine (rendered), or NULL */
  bool own_core;                    /* core is the effects' own (points engine) */
  struct core **keep;               /* fx_engine_free leaves the core here, or NULL */
  struct smooth_scene **smooth_keep;   /* the smoothing's scene part kept for the next
                                       frame (effects/smooth.h), or NULL; set by the caller */
  struct fx_textures **tex_keep;    /* the scene's textures kept for the next frame
                                       (effects/model.c), or NULL; set by the caller */
  struct shadow_keep **shadow_keep; /* the shadows in space kept for the next frame
                                       (effects/shadow.h), or NULL; set by the caller */
};

/* A scene's textures as the effects read them (effects/model.c), kept by the caller of
   many frames of one scene through tex_keep; fx_textures_free(NULL) does nothing. */
void fx_textures_free(struct fx_textures *t);

/* The 1974 engine r, scanned on grid g (both kept by the caller while e is used). */
void fx_engine_1974(struct fx_engine *e, struct render *r, const struct vis_grid *g);

/* The points engine p, rendered on grid g, with a host core of its own for the effects'
   tables (T74_EIO when the host has no room). Free with fx_engine_free. keep (may be NULL):
   where a frame's core is kept for the next frame's (issue 19, --frames: no fresh host
   memory a frame): *keep, when set, is taken (core_reset: as a new one), and
   fx_engine_free leaves the core there when it is still its first size (else frees it and
   sets *keep NULL); the caller core_frees *keep at the end. */
int fx_engine_points(struct fx_engine *e, const struct points *p, const struct vis_grid *g,
                     struct core **keep, struct t74_error *err);
void fx_engine_free(struct fx_engine *e);

/* What of the effects e only the 1974 engine can draw, as a sentence for a refusal
   ("... work on ..."), or NULL when the points engine draws them all. */
const char *fx_needs_1974(const struct effects *e);

/* ---- which face is seen ------------------------------------------------------------ */

struct fx_see;                      /* one question: an engine, faces taken away */

/* Ask engine e, with the faces whose skip[face] is set taken away (skip NULL: none; kept by
   the caller while the question lives). Lines and rows must then come in non-decreasing
   y. Work is counted in cost (the 1974 engine's; the points engine counts nothing). */
int fx_see_open(struct fx_see **out, const struct fx_engine *e, const uint8_t *skip,
                struct cost *cost, struct t74_error *err);
void fx_see_close(struct fx_see *s);

/* Does the engine give whole stretches (fx_see_spans)? The 1974 engine does. */
bool fx_see_has_spans(const struct fx_see *s);

/* The visible stretches of the line y = yn / yd (grid units), left to right, gaps where
   nothing is seen (the 1974 engine only: T74_EIO otherwise). */
int fx_see_spans(struct fx_see *s, int64_t yn, int64_t yd, const struct vis_span **span,
                 int *nspan, struct t74_error *err);

/* The face seen (index in map.f, or -1) at samples k0 .. k0 + n - 1 of row m of the lattice
   K times finer than the points: sample (k, m) at u = (k + 1/2) / K across, v = (m + 1/2) / K
   down, in point units from the window's top left; K <= 16 and at most one point beyond
   the grid. */
int fx_see_row(struct fx_see *s, int K, int64_t m, int64_t k0, int n, int *face,
               struct t74_error *err);

/* fx_see_row, and into *drawn the engine's row that face is a copy of (the points
   engine's frame, at the centres, with no face taken away), or NULL where the row was
   found another way. A reader of the row may read the same faces there, long written,
   where a load of the copy's stores, still on their way, waits for them. */
int fx_see_row_drawn(struct fx_see *s, int K, int64_t m, int64_t k0, int n, int *face,
                     const int **drawn, struct t74_error *err);

/* The engine's row that fx_see_row_drawn would copy into face and give as *drawn (the
   points engine's frame, at the centres, with no face taken away), without copying it;
   NULL where fx_see_row_drawn would find the row another way. A reader that holds those
   faces already (the same buffer) may then work on them in place. */
const int *fx_see_drawn_row(const struct fx_see *s, int K, int64_t m, int64_t k0, int n);

/* True when fx_see_row would answer -1 at every sample of that row without looking (the
   points engine with every face taken away or left out, on a lattice it takes): a reader
   may then take -1 without the row. False says nothing. */
bool fx_see_row_none(const struct fx_see *s, int K, int64_t m, int64_t k0, int n);

#endif
