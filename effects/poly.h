/*
** poly.h — the polygons the effects lay over the visible picture: a contour cut's region
** (paper 004 §5), a shadow on a face (paper 000 §3). Each is a set of rings on the plane
** grid (render/geom.h), filled by the even-odd rule, its vertices rounded once onto the
** grid: from there the polygon IS the region, and every decision about it is exact.
**
** On a horizontal line y = yn/yd a polygon covers the stretches between its crossings
** taken in pairs, left to right, each [x0, x1): a point exactly on a crossing belongs to
** the stretch on its right, the renderer's tie rule (geom.h), so a shadow and the face
** beside it, or a cut and the surface it leaves, never both own a point and never both
** miss one.
*/
#ifndef T74_POLY_H
#define T74_POLY_H

#include <math.h>
#include <stdbool.h>
#include "emu/cost.h"
#include "render/geom.h"

/* A ring's edges go FX_POLY_BLOCK at a time: a block whose points (its edges' ends) all
   lie on one side of a line has no crossing with it, found from its lowest and highest y
   without a look at each point. */
#define FX_POLY_BLOCK 8

struct fx_poly {
  int nring;
  int *rs;                  /* nring + 1 offsets into pt */
  struct gpoint *pt;        /* (one piece with rs and the blocks) */
  gcoord (*blk)[2];         /* per block of a ring's edges, ring by ring: its points'
                               lowest and highest y */
  gcoord xlo, xhi, ylo, yhi;   /* bounding box */
  int owner;                /* the mapped face a shadow lies on; the object a cut belongs to */
  int light;                /* a shadow: the light it hides (index in scene.light) */
};

/* The polygons; their points, blocks and offsets are taken from chunks of memory (mem,
   a chain) that go when the list does: a frame's shadows are a few allocations, not one
   a polygon. */
struct fx_polys { struct fx_poly *p; int n, cap; struct fx_chunk *mem; };

/* llroundl(x) as a grid coordinate: the same integer (half away from zero), without the
   library call (the part of x after its truncation is exact in a long double). */
static inline gcoord fx_round_ld(long double x)
{
  if (!(fabsl(x) < 0x1p62L)) return (gcoord)llroundl(x);
  const int64_t t = (int64_t)x;
  const long double f = x - (long double)t;
  return (gcoord)(t + (f >= 0.5L) - (f <= -0.5L));
}

/* Append a polygon of nring rings (rs[0..nring], pt) — copied; the box is computed.
   false when out of host memory. Rings of fewer than 3 points are dropped (and a polygon
   left with none is not added). */
bool fx_polys_add(struct fx_polys *ps, int nring, const int *rs, const struct gpoint *pt,
                  int owner, int light);
void fx_polys_free(struct fx_polys *ps);

/* The grid row of the line y = yn/yd (yd > 0): floor(yn / yd). A grid point lies on or
   below the line (y yd <= yn) exactly when y <= the row, and the line meets polygon p's
   height range [ylo, yhi) exactly when fx_poly_on_row: one divide a line instead of a
   wide product a vertex. */
static inline int64_t fx_line_row(int64_t yn, int64_t yd)
{
  return yn / yd - (yn % yd != 0 && yn < 0);
}

static inline bool fx_poly_on_row(const struct fx_poly *p, int64_t row)
{
  return row >= p->ylo && row < p->yhi;
}

/* A crossing's x in a double, k = fl(fl(num) / fl(den)): each of the three roundings is
   within u = 2^-53 relatively (|num|, den < 2^127: no overflow; den >= 1, |x| >= 2^-127
   unless 0: no underflow), so |k - x| <= ((1 + u)^2 / (1 - u) - 1) |x| < 2^-51 |x|, with k
   of x's sign (0 exactly when x is). */
static inline double fx_x_key(struct grat x)
{
  /* fl(v) of a wide v that fits in 64 bits taken from the 64-bit value: the same double
     (each conversion rounds v to nearest), without the library's 128-bit conversion */
  const double num = x.num == (int64_t)x.num ? (double)(int64_t)x.num : (double)x.num;
  const double den = x.den == (int64_t)x.den ? (double)(int64_t)x.den : (double)x.den;
  return num / den;
}

/* The order of *a and *b (-1, 0, 1; ka, kb their fx_x_key): from the keys when they lie
   apart by more than 2^-49 (|ka| + |kb|) as computed (the difference and the bound each
   within a few u of their values, so then |kb - ka| > 2^-50 (|ka| + |kb|), more than the
   keys' two errors together: the order is the keys'), else exactly (geom_rat_cmp). */
static inline int fx_x_cmp(const struct grat *a, double ka, const struct grat *b, double kb)
{
  const double d = kb - ka, t = (fabs(ka) + fabs(kb)) * 0x1p-49;
  if (d > t) return -1;
  if (-d > t) return 1;
  return geom_rat_cmp(*a, *b);
}

/* The stretches of polygon p on the line y = yn/yd (0 < yd <= GRID_YDEN_MAX): up to max
   crossings in x (sorted) written, their count returned (even; -1 when more than max).
   Counted in cost (NULL: not counted). */
int fx_poly_cross(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x, int max,
                  struct cost *cost);

#endif
