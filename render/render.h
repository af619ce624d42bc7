/*
** render.h — the 1974 renderer as one object: Mapper -> Segment Generator -> Priority
** Matrix + Visible Surface Procedure (paper 003, Fig. 1), in the machine's core.
**
** render_prepare runs the Mapper and the Segment Generator over a checked scene; render_scan
** then walks the perspective-plane grid and hands each point's visible face to a callback,
** bottom row first. Everything lives in one struct render passed explicitly.
*/
#ifndef T74_RENDER_H
#define T74_RENDER_H

#include <stdint.h>
#include <stdio.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/mapper.h"
#include "render/priority.h"
#include "render/scene.h"
#include "render/seginfo.h"
#include "render/visible.h"

enum render_stage { RS_MAPPER, RS_SEGMENT, RS_VISIBLE, RS_NSTAGE };

/* What one render of a scene keeps for the next renders of the same scene (--frames,
   issue 19): the T-junctions the Mapper found (mapper.h), so a later frame does not
   search again (its charges are added all the same: every figure is the first frame's),
   and the host memory render_free is done with: the core model (core_renew: a core as
   new, its block kept even when it grew), the blocks of the faces and pieces, so a later
   frame works in memory already touched, and the face-pair table's block at the size it
   grew to (priority.h: empty again each frame). Zeroed before the first render;
   render_keep_free when done. */
struct render_keep {
  struct mapper_keep map;    /* the T-junctions, and the faces' blocks */
  struct core *core;         /* a core not in use (renewed to render_opts.core_words words), or NULL */
  struct pool seg;           /* the pieces' blocks */
  struct prio_keep prio;     /* the face-pair table's block (empty again each frame) */
};

void render_keep_free(struct render_keep *k);

struct render_opts {
  uint32_t core_words;       /* words of core (16384 in 1974) */
  uint32_t program_words;    /* core taken by the 1974 program itself (0: not charged) */
  int      store;            /* PRIO_AUTO / PRIO_DENSE / PRIO_SPARSE */
  FILE    *tables;           /* teaching dump (--dump tables), or NULL */
  uint32_t core_max;         /* > core_words: the core grows up to this many words instead
                                of refusing (core_set_growth; imports without --core) */
  struct render_keep *keep;  /* kept from render to render of one scene, or NULL */
};

struct render {
  struct core    *core;
  struct mapped   map;
  struct seginfo  seg;
  struct prio     prio;
  struct vis      vis;
  struct cost     cost[RS_NSTAGE];   /* operations counted per stage */
  int             faces_in;
  int             concave_splits;
  int             ran[RS_NSTAGE];
  FILE           *tables;
  const struct scene *scene;         /* for messages while the scan cuts faces */
  int            *cut_order;         /* the order faces are cut in (lazy: by lowest y) */
  int64_t        *cut_y;             /* cut_y[i]: the lowest grid y of face cut_order[i] */
  int             cut_n, cut_cap;    /* faces in it, room */
  int             cut_next;          /* faces cut so far (a prefix of cut_order) */
  int             lazy;              /* 1: the scan drives the Segment Generator */
  int             arith;             /* GEOM_EXACT or GEOM_HITAC (--arith) */
  int             arith_skipped;     /* hitac: faces folded by 1974 coordinates, not drawn */
  struct render_keep *keep;          /* render_opts.keep: render_free gives the core to it */
};

int render_prepare(struct render *r, const struct scene *s, const struct render_opts *o,
                   struct t74_error *err);

/* The same, but the Segment Generator is driven by the scan (003 §3.1: cut bottom to top
   so that the picture is displayed while it is computed): render_scan cuts each face when
   its line reaches the face's lowest vertex, and the faces above the last line at its end.
   The scene must live until render_scan returns. Nothing but render_scan may look at the
   pieces before then. */
int render_prepare_lazy(struct render *r, const struct scene *s, const struct render_opts *o,
                        struct t74_error *err);

/* render_prepare_lazy with the decisions in `arith` (--arith): GEOM_EXACT, the same, or
   GEOM_HITAC, in the HITAC-10's word sizes as the 1974 program made them (geom.h). */
int render_prepare_lazy_arith(struct render *r, const struct scene *s,
                              const struct render_opts *o, int arith, struct t74_error *err);

/* The grid scan; face passed to point() is an index in r->map.f, or -1. */
int render_scan(struct render *r, const struct vis_grid *g, vis_point_fn point, void *ctx,
                struct t74_error *err);

/* Pieces alive now (faces after all splits). */
int render_pieces_alive(const struct render *r);

/* Everything freed; the core to r's keep when there is one. */
void render_free(struct render *r);

#endif
