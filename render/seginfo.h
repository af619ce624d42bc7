/*
** seginfo.h — Segment Information (paper 003 §2.2, §3.2, Fig. 8): the convex pieces.
**
** After the Segment Generator every face is a set of convex pieces (the paper's divided
** faces S_i). A piece is the intersection of the half-planes left of its oriented lines
** (geom.h), listed counter-clockwise; its vertices are where consecutive lines meet,
** exactly, as homogeneous points. Pieces are only ever added: a piece cut along an
** intersection line (priority.c) is marked dead and its two halves are appended, so a
** piece number, once given, always means the same region.
**
** In core (Fig. 8): B-BLOCK, one row per piece: piece number (2 words), face (1), y-min and
** y-max floored/ceiled to the grid (2 + 2), sides k (1), C-block address (2) = 10 words;
** C-BLOCK, per piece k sides of a, b (2 words each) and c (4 words) = 8k words.
*/
#ifndef T74_SEGINFO_H
#define T74_SEGINFO_H

#include <stdbool.h>
#include <stdint.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"
#include "render/pool.h"

struct piece {
  struct gline  *line;     /* n oriented lines, counter-clockwise */
  struct hpoint *v;        /* v[k]: where line[k-1] meets line[k] (start of side k) */
  int    face;             /* index in mapped.f */
  int    n;                /* number of sides, >= 3 */
  int    parent;           /* the piece it is a half of (cut by priority.c), else -1 */
  int    lo, hi;           /* its lowest and highest vertex: v[lo], v[hi] (issue 19: an
                              index, not a copy: 40 bytes a piece instead of 144) */
  bool   alive;            /* false once cut in two */
};

/* Piece p's lowest and highest vertex (the first of equal y in p's order). */
static inline struct hpoint piece_ylo(const struct piece *p) { return p->v[p->lo]; }
static inline struct hpoint piece_yhi(const struct piece *p) { return p->v[p->hi]; }

struct seginfo {
  int    n, cap;
  struct piece *p;
  struct core *core;
  struct cost *cost;
  struct pool pool;        /* host blocks of the pieces' lines and vertices */
};

void seginfo_init(struct seginfo *t, struct core *core, struct cost *cost);
void seginfo_free(struct seginfo *t);

/* Room for n pieces in all, taken now (issue 19: the table sized from an estimate of the
   pieces, not by doubling from 64, which leaves it up to twice as large as it needs and
   its smaller copies freed behind it). false when the host is out of memory. */
bool seginfo_reserve(struct seginfo *t, int n);

/* Append a piece given by its lines (consecutive lines must meet). Returns the piece's
   number, or -1 with err set (T74_ECORE when its blocks do not fit the core). */
int seginfo_add(struct seginfo *t, int face, int n, const struct gline *line,
                struct t74_error *err);

/* A convex polygon under construction (for clipping). */
struct cpoly {
  int n, cap;
  struct gline  *line;
  struct hpoint *v;
};

void cpoly_free(struct cpoly *c);

/* Clip piece p by the half-plane left of h (closed). Returns true when what remains has
   a non-empty interior, and then fills out (lines only; vertices computed too). */
bool seginfo_clip(const struct piece *p, struct gline h, struct cpoly *out, struct cost *cost);

/* seginfo_clip by h into left and by the reversed h (-a, -b, -c) into right, each of p's
   vertices placed once: the same halves, results and charges as the two calls. */
void seginfo_clip_both(const struct piece *p, struct gline h, struct cpoly *left, bool *hasl,
                       struct cpoly *right, bool *hasr, struct cost *cost);

/* seginfo_clip_both where the caller knows that the half on side `known` of h (1 the left,
   2 the right; 0 neither) has an interior: that half is only counted, its number of sides
   (out->n) and *has (true) what seginfo_clip_both gives, its sides and vertices not made;
   the same charges, counted: the products (88 x 58 bits) seginfo_clip_both charges are
   added to *prod instead. sides: NULL, or the side of h of each of p's vertices as
   geom_side_h gives it, found already (p->n entries). */
void seginfo_clip_both_known(const struct piece *p, struct gline h, const signed char *sides,
                             int known, struct cpoly *left, bool *hasl, struct cpoly *right,
                             bool *hasr, uint64_t *prod);

/* Do the interiors of two convex polygons overlap? (exact separating-line test) */
bool seginfo_overlap(int n1, const struct gline *l1, const struct hpoint *v1,
                     int n2, const struct gline *l2, const struct hpoint *v2,
                     struct cost *cost);

/* seginfo_overlap with the products it charges (88 x 58 bits) added to *prod instead. */
bool seginfo_overlap_n(int n1, const struct gline *l1, const struct hpoint *v1,
                       int n2, const struct gline *l2, const struct hpoint *v2,
                       uint64_t *prod);

/* The x-span of piece p on the horizontal line y = yn/yd: [xl, xr) by the tie rule of
   geom.h, by definition (the largest x of its left sides, the smallest of its right
   ones). Returns false when the line misses the piece (or meets only its boundary in a
   way the piece does not own). The scan itself gets the same spans incrementally from
   D-blocks (visible.c); the tests hold the two to each other. */
bool seginfo_span(const struct piece *p, int64_t yn, int64_t yd, struct grat *xl,
                  struct grat *xr, struct cost *cost);

#endif
