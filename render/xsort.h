/*
** xsort.h — XSORT: where a horizontal line meets the edges of a face (Segment Generator,
** 003 §2.2 and Fig. 3, Fig. 4; used by §3.1 eq. (3), Fig. 6).
**
** INVARIANT (003 Fig. 3): XSORT rows are ordered by the exact x of the crossing point;
** rows with the same x (edges meeting at a vertex on the line) are ordered as the
** boundary is traversed counter-clockwise with the face on the left: the edge that
** arrives at the vertex before the edge that leaves it.
**
** This file contains the working form of a face (or of a piece of it) while the Segment
** Generator cuts it, and the two x-ordered lists built for one cut line y = c:
**
**   xsort_build  the paper's XSORT table: every edge that meets y = c, with the paper's
**                crossing code (Fig. 4): through the edge's middle, at an endpoint, or
**                along the edge (a horizontal edge lying on the line), in x order with
**                the counter-clockwise tie rule above. It is the table the trace shows.
**   xsort_half   the crossings of one side of the line, which the cut is made from:
**                edges with exactly one endpoint strictly below (XS_BELOW) or strictly
**                above (XS_ABOVE) the line, ordered by x at y = c and, on ties, by x
**                at y = c - e (below) or c + e (above) for an infinitesimal e, i.e. by
**                the slopes of the edges. The Segment Generator types each crossing
**                point (a..e of Fig. 4, 5: segment.c type_crossings) and matches the
**                rules of eq. (3) on the types to decide the cut intervals (rule_pairs);
**                this slope order is the tie rule between crossing points at one x (two
**                rings touching), and the pairing (1,2), (3,4), ... it gives is kept as
**                a check that the rules agree with it.
**
** Every x is an exact rational (geom.h grat): a ring vertex's y is always an integer
** (input grid points, or crossing points on earlier cut lines y = c, c an integer), and
** its x is either an integer or x of an edge's line at an integer y. Comparisons are
** cross-multiplied in 128 bits; no floating point.
*/
#ifndef T74_XSORT_H
#define T74_XSORT_H

#include <stdint.h>
#include "emu/cost.h"
#include "render/geom.h"

/* Kinds of working vertices; the same values as enum seg_vkind (segment.h). */
#define XS_ORIG  0                 /* an input vertex */
#define XS_CROSS 1                 /* a crossing point made by a cut */

/* One vertex of a working ring. */
struct xs_vertex {
  uint8_t  kind;                   /* XS_ORIG or XS_CROSS */
  uint32_t num;                    /* ORIG: vertex id; CROSS: crossing number (11, 12, ..) */
  int      src;                    /* ORIG: index into the face's point array; CROSS: -1 */
  gcoord   y;                      /* exact y: always on the grid */
  struct grat x;                   /* exact x */
  struct hpoint p;                 /* the same point, homogeneous (for the output) */
};

/* The side of a working ring from vertex k to vertex k+1. */
struct xs_side {
  struct gline line;               /* its oriented line, the face on the left */
  uint32_t ea, eb;                 /* ids of the input edge it lies on ("ea-eb") */
  uint8_t  cut;                    /* 1: it lies on a cut line (then ea, eb unused) */
};

/* A cyclic sequence of vertices; side k runs from v[k] to v[(k+1) % n]. */
struct xs_ring {
  int n;
  struct xs_vertex *v;
  struct xs_side   *s;
};

/* ---- XSORT (the paper's table) --------------------------------------------------------- */

enum xsort_code {
  XS_MIDDLE     = 1,               /* the line passes through the edge's interior */
  XS_ENDPOINT   = 2,               /* exactly one endpoint of the edge is on the line */
  XS_COINCIDENT = 3                /* the edge lies on the line (horizontal, both ends on it) */
};

/* One row: 9 words on the 16-bit machine: x numerator 4 words (|num| < 2^60 for an
   integer c), x denominator 2 words (< 2^29), the edge as its two vertex numbers 2 words,
   the crossing code 1 word. */
#define XSORT_ROW_WORDS 9

struct xsort_row {
  struct grat x;                   /* x of the crossing; a coincident edge: its smaller x */
  int ring, side;                  /* which side of which ring */
  uint8_t code;                    /* enum xsort_code */
  int touch;                       /* tie key: ring vertex at the crossing (or the side) */
  int role;                        /* tie key: 0 arriving at `touch`, 1 leaving it */
};

/* Rows for every side of rings[0..nring-1] meeting y = c, at most the total number of
   sides; written to rows (scratch: as many rows, for the merge sort). Returns the count. */
int xsort_build(const struct xs_ring *rings, int nring, gcoord c,
                struct xsort_row *rows, struct xsort_row *scratch, struct cost *cost);

/* How many rows xsort_build makes for y = c, without making them or counting anything
   (seg_check takes XSORT's room in core and writes nothing into it). */
int xsort_rows(const struct xs_ring *rings, int nring, gcoord c);

/* The name of a crossing code: "middle", "endpoint", "coincident". */
const char *xsort_code_name(int code);

/* ---- One side of the line (what the cut pairs) ----------------------------------------- */

enum xsort_half_side { XS_BELOW = 0, XS_ABOVE = 1 };

struct xsort_cross {
  struct grat x;                   /* x where the side's line meets y = c */
  int ring, side;                  /* the ring side (from v[side] to v[side+1]) */
  uint8_t enter;                   /* 1: v[side] is off this half, v[side+1] on it */
  uint8_t at;                      /* 0 middle, 1 at v[side], 2 at v[side+1] */
};

/* The crossings of half `half` (XS_BELOW: y < c, XS_ABOVE: y > c): every side with one
   endpoint strictly inside the half and the other not. Sorted by x at c; ties by x at
   c -/+ e (slopes compared exactly); remaining ties (two sides on one line) put the
   crossing that closes an interval first (below: the exit, above: the entry), then ring
   and side order. Returns the count (at most the number of sides). */
int xsort_half(const struct xs_ring *rings, int nring, gcoord c, int half,
               struct xsort_cross *out, struct xsort_cross *scratch, struct cost *cost);

/* Is a vertex of y-coordinate y strictly inside half `half` of the line y = c? */
static inline int xsort_in_half(gcoord y, gcoord c, int half)
{
  return half == XS_BELOW ? y < c : y > c;
}

#endif
