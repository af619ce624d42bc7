/*
** plane.h — exact predicates on points of a coordinate plane (64-bit integers).
**
** This file holds the few integer tests that the scene checks (render/scene.c: a face
** projected onto a coordinate plane must be simple, its holes inside it) and the import's
** ear clipping (render/import.c: a rounded face projected the same way) both make before
** anything reaches the Mapper. Every decision is exact, no epsilons (paper 003 §2.1 takes
** integer vertices; the project's rule for topological decisions). Callers keep the
** coordinates below 2^31 in magnitude (both stay below 2^18), so the products below
** cannot overflow. Static inline: they sit in the inner loops of those checks.
*/
#ifndef T74_PLANE_H
#define T74_PLANE_H

#include <stdbool.h>
#include <stdint.h>

struct pl_pt { int64_t u, v; };

/* Twice the signed area of a, b, c: > 0 when they turn counter-clockwise, 0 collinear. */
static inline int64_t pl_orient(struct pl_pt a, struct pl_pt b, struct pl_pt c)
{
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

static inline int pl_sgn(int64_t x) { return (x > 0) - (x < 0); }

static inline bool pl_eq(struct pl_pt a, struct pl_pt b) { return a.u == b.u && a.v == b.v; }

/* Is c, known to be collinear with a and b, on the closed segment ab? */
static inline bool pl_on_seg(struct pl_pt a, struct pl_pt b, struct pl_pt c)
{
  return (c.u >= (a.u < b.u ? a.u : b.u)) && (c.u <= (a.u > b.u ? a.u : b.u)) &&
         (c.v >= (a.v < b.v ? a.v : b.v)) && (c.v <= (a.v > b.v ? a.v : b.v));
}

/* Do the closed segments ab and cd have a point in common? */
static inline bool pl_meet(struct pl_pt a, struct pl_pt b, struct pl_pt c, struct pl_pt d)
{
  int o1 = pl_sgn(pl_orient(a, b, c)), o2 = pl_sgn(pl_orient(a, b, d));
  int o3 = pl_sgn(pl_orient(c, d, a)), o4 = pl_sgn(pl_orient(c, d, b));
  if (o1 && o2 && o3 && o4) return o1 != o2 && o3 != o4;
  return (o1 == 0 && pl_on_seg(a, b, c)) || (o2 == 0 && pl_on_seg(a, b, d)) ||
         (o3 == 0 && pl_on_seg(c, d, a)) || (o4 == 0 && pl_on_seg(c, d, b));
}

/* Edges pq and pr leave their common end p: do they overlap beyond p (same direction)? */
static inline bool pl_fold(struct pl_pt p, struct pl_pt q, struct pl_pt r)
{
  return pl_orient(p, q, r) == 0 &&
         (q.u - p.u) * (r.u - p.u) + (q.v - p.v) * (r.v - p.v) > 0;
}

#endif
