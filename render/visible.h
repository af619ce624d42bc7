/*
** visible.h — the Visible Surface Procedure of paper 003 (§2.2, §4): the visible face
** along horizontal lines of the perspective plane, and at every point of the grid.
**
** vis_spans gives the exact visible stretches along ANY horizontal line y = yn/yd (lines
** must come in non-decreasing y): the scan of point centres below is built on it, and so
** can be sub-scanline anti-aliasing later, with no second visibility code.
*/
#ifndef T74_VISIBLE_H
#define T74_VISIBLE_H

#include <stddef.h>
#include <stdint.h>
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"
#include "render/priority.h"
#include "render/seginfo.h"

struct vis_span {
  struct grat x0, x1;       /* the stretch [x0, x1) on the line, grid units */
  int piece;                /* the visible piece */
  int face;                 /* its face (index in mapped.f) */
};

struct vis_grid {
  int W, H;                 /* points across and down */
  int32_t window[4];        /* XL YB XR YT, world units */
};

/* An active piece and its D-block (003 Fig. 8): the stretch of the piece between two
   vertex heights where its left side kl and right side kr stay the same, with the span
   [xb, xe) on the current line, the increments of xb and xe from one line to the next,
   and y-max, where the D-block ends. Exact: xb and xe are rationals whose denominators
   stay fixed within a D-block, so the increments are exact integers. */
struct vis_item {
  int    piece;
  bool   on;                 /* the line meets the piece (xl < xr) */
  bool   open;               /* the D-block below is valid */
  int    kl, kr;             /* left and right side (indices into the piece's lines) */
  struct grat xl, xr;        /* xb, xe on the last line */
  wide   sl, sr;             /* d(xb.num)/d(yn), d(xe.num)/d(yn) */
  wide   dxl, dxr;           /* dxb, dxe: increments for a line step of dyn */
  int64_t dyn;               /* the line step the increments are for (0: none yet) */
  wide   hdl, hdr;           /* --arith hitac: the exact denominators of xb, xe */
  int64_t yn, yd;            /* the last line, y = yn / yd */
  struct hpoint ymax;        /* where the D-block ends (the lower top of kl and kr) */
  wide   yhi_y;              /* the height of the piece's highest vertex, Y / W (piece_yhi_y, */
  int64_t yhi_w;             /* made once when it is activated, not on every line) */
  uint32_t core;             /* its row in the core's D-BLOCK table */
  int64_t fdxl, fdxr;        /* that row's dxb, dxe, and y-max (visible.c, dblock_fixed) */
  uint16_t fymax;
};

/* An active item's xb and xe in doubles (visible.c, geom_rat_key) and a copy of its on (the
   line meets it): the sweep's orders compare these first, the exact ends only where they
   lie close, and the insertion sorts read this array alone (24 bytes an item, not 288). */
struct vis_key {
  double l, r;
  int    on;
};

struct vis {
  struct seginfo *seg;
  struct prio    *prio;
  struct cost    *cost;
  int   *order, norder, next;           /* pieces by lowest y; order[next..] not yet met */
  struct vis_item *act; int nact;   /* active pieces, in no order of their own (byxl,
                                       byxr); between lines also the pieces cut on the
                                       last line, dead, until the next line's start */
  struct vis_key *key;                   /* per act index, made with its span on this line */
  int   *byxl, nbyxl;                    /* act indices in order of xl, pieces the line meets
                                            first (the dead left out); kept from line to line */
  int   *byxr, nbyxr;                    /* act indices of the pieces the line meets, in
                                            order of xr; kept from line to line */
  int   *set, nset;                      /* pieces covering the current stretch */
  int   *seti;                           /* their items (act indices), in step with set */
  int   *setpos;                         /* per act index: its place in set while it is
                                            there (seti[setpos[a]] == a), else any value */
  struct vis_span *span; int nspan;
  int   *tmp, *tmp2, *tmp3;              /* scratch for sorts and merges */
  struct vis_span *span2; int nspan2;    /* scratch: spans given to cut halves */
  int   born;                            /* seg->n when the current line's sweep began */
  uint64_t resumes;                      /* splits met in a sweep, which went on from there */
  int   seen;                            /* pieces in seg already placed in order */
  int64_t yn, yd;                        /* the last line asked for */
  uint64_t lines;                        /* lines scanned */
  uint32_t *dfree; int ndfree;           /* free D-block rows in core */
  /* the arrays' room in elements (t74_grow: emu/grow.h) */
  size_t ordcap, actcap, byxlcap, byxrcap, setcap, seticap, setposcap, spancap, tmpcap,
         tmp2cap, tmp3cap, span2cap, dfreecap, keycap;
  /* optional: called before each line y = yn/yd is worked, to add the pieces of the faces
     the line has reached (render.c: the Segment Generator driven by the scan) */
  int (*feed)(void *ctx, int64_t yn, int64_t yd, struct t74_error *err);
  void *feed_ctx;
  int   arith;                           /* GEOM_EXACT, or GEOM_HITAC: xb, xe, dxb, dxe
                                            held as the 1974 program held them */
  const uint8_t *skip_face;              /* NULL, or per mapped face: 1 = leave its pieces
                                            out (vis_init_without) */
  uint64_t pend_ycmp, pend_xcmp;         /* compares of lowest y and of x made and not yet
                                            charged (charged at the end of each line) */
  uint64_t pend_xadd, pend_side;         /* the D-blocks' x steps (75-bit adds) and sides tried
                                            (88 x 17-bit products), likewise */
};

int vis_init(struct vis *v, struct seginfo *seg, struct prio *prio, struct cost *cost,
             struct t74_error *err);
/* The same over the pieces of the faces whose flag skip_face[face] (indexed by mapped
   face, kept by the caller while v lives) is 0: what the other faces would show where
   those are taken away (the effects: a contour cut shows what its object hid). */
int vis_init_without(struct vis *v, struct seginfo *seg, struct prio *prio, struct cost *cost,
                     const uint8_t *skip_face, struct t74_error *err);
void vis_free(struct vis *v);

/* The visible stretches along y = yn/yd, left to right, gaps where nothing is seen. */
int vis_spans(struct vis *v, int64_t yn, int64_t yd, const struct vis_span **span,
              int *nspan, struct t74_error *err);

/* Scan the grid, bottom row first and left to right (the order the 1974 program
   displayed while it computed), calling point() with the visible face of each point
   centre (index in mapped.f, or -1 for none). */
typedef int (*vis_point_fn)(void *ctx, int i, int j, int face);
int vis_scan(struct vis *v, const struct vis_grid *g, vis_point_fn point, void *ctx,
             struct t74_error *err);

#endif
