/*
** xsort.c — XSORT, the crossings of a horizontal line with a face's edges.
** Stage: Segment Generator (003 §2.2, Fig. 3, Fig. 4; used by §3.1 eq. (3), Fig. 6).
**
** INVARIANT: xsort_build's rows are in x order, ties counter-clockwise (003 Fig. 3): at a
** vertex on the line, the edge arriving at it before the edge leaving it. xsort_half's
** crossings are in x order, ties by the x an infinitesimal step below (XS_BELOW) or
** above (XS_ABOVE) the line.
**
** This file contains the two sorts. The paper classifies each crossing "logically from
** the order of coordinates and the slopes of edges" (003 §2.2); so does this code, and
** exactly: a vertex's y is an integer and is compared with c directly; x values are
** rationals compared by cross-multiplication (geom_rat_cmp); the order just below or
** just above a common crossing point is the order of dx/dy = -b/a of the two lines,
** compared as -b1*a2 against -b2*a1 with a1, a2 > 0 (|a|, |b| < 2^29: products < 2^58).
** Sorting is a stable merge sort on a caller's scratch array (no allocation here); the
** comparison keys make the order total, so the result does not depend on where a ring
** starts except through the documented ring/side tie-break of coincident lines.
*/
#include "render/xsort.h"
#include "render/rsort.h"

#include <stdbool.h>
#include <string.h>

/* Operation counts: a y compare is a 30-bit subtract; an x compare two 64 x 32-bit
   products and a 96-bit compare; a slope compare two 32 x 32 products and a 64-bit
   compare. Cost may be NULL (tests): then nothing is counted. */
static void count_ycmp(struct cost *k)
{
  if (k) cost_mw_add(k, 30);
}

static void count_xcmp(struct cost *k)
{
  if (!k) return;
  cost_mw_mul(k, 64, 32);
  cost_mw_mul(k, 64, 32);
  cost_mw_add(k, 96);
}

static void count_slope(struct cost *k)
{
  if (!k) return;
  cost_mw_mul(k, 30, 30);
  cost_mw_mul(k, 30, 30);
  cost_mw_add(k, 60);
}

/* x where the (non-horizontal) line of a side meets y = c: one product and a sum. */
static struct grat x_at_c(struct gline l, gcoord c, struct cost *k)
{
  if (k) { cost_mw_mul(k, 30, 30); cost_mw_add(k, 60); }
  return geom_x_at(l, c, 1);
}

/* ---- XSORT ------------------------------------------------------------------------------ */

const char *xsort_code_name(int code)
{
  switch (code) {
  case XS_MIDDLE:     return "middle";
  case XS_ENDPOINT:   return "endpoint";
  case XS_COINCIDENT: return "coincident";
  default:            return "?";
  }
}

/* x order, then the counter-clockwise rule of Fig. 3: at one vertex the arriving edge
   (role 0) before the leaving one (role 1); different vertices or rings at one point
   in ring order. */
static int row_cmp(const void *pa, const void *pb, void *ctx)
{
  const struct xsort_row *a = pa, *b = pb;
  count_xcmp(ctx);
  int s = geom_rat_cmp(a->x, b->x);
  if (s) return s;
  if (a->ring != b->ring) return a->ring < b->ring ? -1 : 1;
  if (a->touch != b->touch) return a->touch < b->touch ? -1 : 1;
  if (a->role != b->role) return a->role < b->role ? -1 : 1;
  return (a->side > b->side) - (a->side < b->side);
}

/* Does the side from a vertex at y0 to one at y1 meet y = c (a row of XSORT)? */
static inline bool side_meets(gcoord y0, gcoord y1, gcoord c)
{
  return !((y0 < c && y1 < c) || (y0 > c && y1 > c));
}

int xsort_rows(const struct xs_ring *rings, int nring, gcoord c)
{
  int m = 0;
  for (int r = 0; r < nring; r++)
    for (int k = 0; k < rings[r].n; k++)
      m += side_meets(rings[r].v[k].y, rings[r].v[(k + 1) % rings[r].n].y, c);
  return m;
}

int xsort_build(const struct xs_ring *rings, int nring, gcoord c,
                struct xsort_row *rows, struct xsort_row *scratch, struct cost *cost)
{
  int m = 0;
  for (int r = 0; r < nring; r++) {
    const struct xs_ring *g = &rings[r];
    for (int k = 0; k < g->n; k++) {
      int k1 = (k + 1) % g->n;
      const struct xs_vertex *p = &g->v[k], *q = &g->v[k1];
      count_ycmp(cost);
      count_ycmp(cost);
      if (!side_meets(p->y, q->y, c)) continue;   /* wholly above or below */
      int sp = (p->y > c) - (p->y < c), sq = (q->y > c) - (q->y < c);
      struct xsort_row row;
      memset(&row, 0, sizeof row);
      row.ring = r;
      row.side = k;
      if (sp == 0 && sq == 0) {               /* along the line: keyed at its smaller x */
        count_xcmp(cost);
        row.code = XS_COINCIDENT;
        if (geom_rat_cmp(p->x, q->x) <= 0) { row.x = p->x; row.touch = k;  row.role = 1; }
        else                               { row.x = q->x; row.touch = k1; row.role = 0; }
      } else if (sp == 0) {                   /* leaves the vertex p on the line */
        row.code = XS_ENDPOINT; row.x = p->x; row.touch = k; row.role = 1;
      } else if (sq == 0) {                   /* arrives at the vertex q on the line */
        row.code = XS_ENDPOINT; row.x = q->x; row.touch = k1; row.role = 0;
      } else {                                /* through the middle (sp != sq) */
        row.code = XS_MIDDLE; row.x = x_at_c(g->s[k].line, c, cost);
        row.touch = k; row.role = 1;
      }
      if (cost) COST_ADD_N(cost, COST_MEM, XSORT_ROW_WORDS);   /* the row is stored */
      rows[m++] = row;
    }
  }
  rsort_merge(rows, m, sizeof rows[0], scratch, row_cmp, cost);
  return m;
}

/* ---- One half ----------------------------------------------------------------------------- */

struct half_ctx {
  const struct xs_ring *rings;
  int half;
  struct cost *cost;
};

/* Compare dx/dy of two non-horizontal lines: -1, 0, 1. dx/dy = -b/a. */
static int slope_cmp(struct gline l1, struct gline l2)
{
  wide a1 = l1.a, b1 = l1.b, a2 = l2.a, b2 = l2.b;
  if (a1 < 0) { a1 = -a1; b1 = -b1; }
  if (a2 < 0) { a2 = -a2; b2 = -b2; }
  wide s1 = -b1 * a2, s2 = -b2 * a1;
  return (s1 > s2) - (s1 < s2);
}

static int cross_cmp(const void *pa, const void *pb, void *vctx)
{
  const struct xsort_cross *a = pa, *b = pb;
  const struct half_ctx *ctx = vctx;
  count_xcmp(ctx->cost);
  int s = geom_rat_cmp(a->x, b->x);
  if (s) return s;
  /* Same point: order an infinitesimal step into the half. Below the line (y = c - e)
     x = x_c - e*dx/dy, so the larger dx/dy is further left; above, the smaller. */
  count_slope(ctx->cost);
  s = slope_cmp(ctx->rings[a->ring].s[a->side].line, ctx->rings[b->ring].s[b->side].line);
  if (s) return ctx->half == XS_BELOW ? -s : s;
  /* Two sides on one line through one point: the boundary touches itself along a
     segment. Close an interval before opening the next (below: exit first; above:
     entry first), so the zero-width gap between them stays outside. */
  if (a->enter != b->enter) {
    int a_first = ctx->half == XS_BELOW ? !a->enter : a->enter;
    return a_first ? -1 : 1;
  }
  if (a->ring != b->ring) return a->ring < b->ring ? -1 : 1;
  return (a->side > b->side) - (a->side < b->side);
}

int xsort_half(const struct xs_ring *rings, int nring, gcoord c, int half,
               struct xsort_cross *out, struct xsort_cross *scratch, struct cost *cost)
{
  int m = 0;
  for (int r = 0; r < nring; r++) {
    const struct xs_ring *g = &rings[r];
    for (int k = 0; k < g->n; k++) {
      const struct xs_vertex *p = &g->v[k], *q = &g->v[(k + 1) % g->n];
      count_ycmp(cost);
      count_ycmp(cost);
      int ip = xsort_in_half(p->y, c, half), iq = xsort_in_half(q->y, c, half);
      if (ip == iq) continue;
      struct xsort_cross x;
      memset(&x, 0, sizeof x);
      x.ring = r;
      x.side = k;
      x.enter = (uint8_t)iq;
      if (p->y == c)      { x.at = 1; x.x = p->x; }
      else if (q->y == c) { x.at = 2; x.x = q->x; }
      else                { x.at = 0; x.x = x_at_c(g->s[k].line, c, cost); }
      out[m++] = x;
    }
  }
  struct half_ctx ctx = { rings, half, cost };
  rsort_merge(out, m, sizeof out[0], scratch, cross_cmp, &ctx);
  return m;
}
