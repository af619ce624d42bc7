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
#include <stddef.h>
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
/* A polygon made in place, without a copy: fx_polys_room gives room for up to npt points
   (NULL when out of host memory), where the caller writes its rings, each of 3 points or
   more, one after the other; fx_polys_close then makes the polygon of nring rings
   rs[0..nring] (offsets into the room, rs[0] = 0), and adds it only when its box meets the
   open box meet (x lo, x hi, y lo, y hi: its xhi > meet[0], xlo < meet[1], yhi > meet[2]
   and ylo < meet[3]; NULL: always), setting *added (may be NULL) when it does. Nothing else
   is done with ps in between. false when out of host memory. */
static inline struct gpoint *fx_polys_room(struct fx_polys *ps, int npt);
static inline bool fx_polys_close(struct fx_polys *ps, int nring, const int *rs, int owner,
                                  int light, const gcoord meet[4], bool *added);
/* Room for n polygons in all (none added): false when out of host memory. */
bool fx_polys_reserve(struct fx_polys *ps, int n);
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

/* The order of *a and *b (-1, 0, 1; ka, kb their geom_rat_key): from the keys where they
   tell it (geom_key_order), else exactly (geom_rat_cmp). */
static inline int fx_x_cmp(const struct grat *a, double ka, const struct grat *b, double kb)
{
  const int o = geom_key_order(ka, kb);
  return o ? o : geom_rat_cmp(*a, *b);
}

/* ---- a row of samples (the points engine's rows, effects/model.c) ----
   Where the samples k0 .. k0 + n - 1 of a row lie, on a window rising left to right:
   sample i at xn / xd, xn = GRID_ONE (xd XL + (2 (k0 + i) + 1) S), S = XR - XL, rising
   with i; and in doubles, i = x ka - kb at x, kb within kbe of its real value. */
struct fx_sample_row { int64_t XL, S, xd, k0; int n; double ka, kb, kbe; };

static inline void fx_sample_row_set(struct fx_sample_row *r, const int32_t *win, int64_t xd,
                                     int64_t k0, int n)
{
  r->XL = win[0];
  r->S = (int64_t)win[2] - win[0];
  r->xd = xd;
  r->k0 = k0;
  r->n = n;
  r->ka = (double)xd / ((double)GRID_ONE * (double)r->S) / 2;
  const double b = (double)xd * (double)r->XL / (double)r->S;
  r->kb = (b + 1) / 2 + (double)k0;
  /* xd XL (exact in int64: rounded once to a double, or exact), / S, + 1, + k0: four
     roundings, each within u = 2^-53 of its value, the values at most
     |b| (1 + 2u) + 1 + |k0|: kbe twice that sum times 4u, found in doubles (a few more
     roundings well within the factor 2) */
  r->kbe = 0x1p-50 * (fabs(b) + 1 + fabs((double)k0) + fabs(r->kb));
}

/* The order of a crossing's x and a sample's xn / xd (-1, 0, 1), kx = fl(k xd) (k: x's
   geom_rat_key): from doubles when they lie apart, else exactly (geom_rat_cmp_frac). k is
   within 2^-51 |x| of x (geom_rat_key) and xd is exact in a double (2 K W), so kx is
   within (2^-51 + 2^-53 + 2^-104) |x xd| < 2^-50.5 |x xd| of x xd, and fl(xn) within
   2^-53 |xn| of xn: when
   fl(xn) - kx > 2^-49 (|kx| + |fl(xn)|) as computed (the difference and the bound each
   within u of their values), xn - x xd > 0 (the two errors together are below
   2^-50.4 (|kx| + |fl(xn)|)): x < xn / xd; likewise the other way. */
static inline int fx_sample_cmp(const struct grat *x, double kx, int64_t xn, int64_t xd)
{
  const double s = (double)xn, d = s - kx, t = (fabs(kx) + fabs(s)) * 0x1p-49;
  if (d > t) return -1;
  if (-d > t) return 1;
  return geom_rat_cmp_frac(*x, xn, xd);
}

/* The first sample of the row whose x is at or right of x (k: x in a double, geom_rat_key), or
   n: the least i in [0, n] where x <= xn / xd. With S > 0 that is x xd <= GRID_ONE (xd XL
   + (2 (k0 + i) + 1) S), that is i >= T = x ka' - kb' (ka', kb': ka and kb as real
   numbers), so i = ceil(T) put into [0, n]. The guess t = fl(fl(k ka) - kb): k within
   2^-51 |x| of x (geom_rat_key), ka within u of ka' (one divide; the product G S and the
   halving exact), the product rounded, so fl(k ka) within (2^-51 + 2u + 4u^2) < 2^-49.9 of
   its size of x ka'; kb within kbe of kb' (fx_sample_row_set); the difference rounded (u |t|):
   |t - T| < bound = 2^-49 |fl(k ka)| + kbe + 2^-52 |t|, found in doubles (a few roundings
   within the slack). When t lies further than that from both of the integers around it,
   c - 1 < t <= c, T lies strictly between them too: ceil(T) = c. Else (T may be an integer,
   x on a sample) the guess is settled by the compares (whatever the guess: usually two,
   decided in doubles when they can be, fx_sample_cmp). */
static inline int fx_first_at_or_right(const struct grat *x, double k,
                                       const struct fx_sample_row *r)
{
  const double p = k * r->ka, t = p - r->kb, gi = ceil(t);
  const double bound = 0x1p-49 * fabs(p) + r->kbe + 0x1p-52 * fabs(t);
  int i = !(gi > 0) ? 0 : gi >= r->n ? r->n : (int)gi;
  if (gi - t > bound && t - (gi - 1) > bound) return i;
  const double kx = k * (double)r->xd;
  while (i > 0 && fx_sample_cmp(x, kx, GRID_ONE * (r->xd * r->XL + (2 * (r->k0 + i - 1) + 1) *
                                                     r->S), r->xd) <= 0)
    i--;
  while (i < r->n && fx_sample_cmp(x, kx, GRID_ONE * (r->xd * r->XL + (2 * (r->k0 + i) + 1) *
                                                        r->S), r->xd) > 0)
    i++;
  return i;
}

/* The stretches of polygon p on the line y = yn/yd (0 < yd <= GRID_YDEN_MAX): up to max
   crossings in x (sorted) written, their count returned (even; -1 when more than max).
   Counted in cost (NULL: not counted). */
int fx_poly_cross(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x, int max,
                  struct cost *cost);

/* ---- fx_polys_room and fx_polys_close, inline (a shadow's polygons, each frame) ---- */

/* A chunk of a list's memory: used of cap bytes taken, from data on. */
struct fx_chunk {
  struct fx_chunk *next;
  size_t used, cap;
  max_align_t data[];
};

/* size rounded up to a whole number of max_align_t: what a piece of a chunk takes. */
static inline size_t fx_piece(size_t size)
{
  return (size + sizeof(max_align_t) - 1) / sizeof(max_align_t) * sizeof(max_align_t);
}

/* The room fx_polys_room makes for npt points: theirs, a block's for each (a block holds
   one point or more) and an offset for each and one more (a ring holds 3 or more). */
static inline size_t fx_room_bytes(int npt)
{
  return (size_t)npt * (sizeof(struct gpoint) + sizeof(gcoord[2]) + sizeof(int)) + sizeof(int);
}

/* A ring's blocks: the ring of n points q into blk[nblk ..] (block v0 .. v0 + FX_POLY_BLOCK
   - 1 holds the edges from those points, so its points are those and the next, the ring's
   first after its last: its y range), the box (xlo, xhi, ylo, yhi) widened over the ring.
   Returns the blocks made so far. */
static inline size_t fx_ring_blocks(const struct gpoint *q, int n, gcoord (*blk)[2],
                                    size_t nblk, gcoord box[4])
{
  gcoord xlo = box[0], xhi = box[1], ylo = box[2], yhi = box[3];
  for (int v0 = 0; v0 < n; v0 += FX_POLY_BLOCK, nblk++) {
    const int v1 = v0 + FX_POLY_BLOCK < n ? v0 + FX_POLY_BLOCK : n;
    gcoord lo = q[v1 == n ? 0 : v1].y, hi = lo;
    for (int v = v0; v < v1; v++) {         /* (the box's x on the way) */
      lo = q[v].y < lo ? q[v].y : lo;
      hi = q[v].y > hi ? q[v].y : hi;
      xlo = q[v].x < xlo ? q[v].x : xlo;
      xhi = q[v].x > xhi ? q[v].x : xhi;
    }
    blk[nblk][0] = lo;
    blk[nblk][1] = hi;
    ylo = lo < ylo ? lo : ylo;              /* the box's y: each point is in a block */
    yhi = hi > yhi ? hi : yhi;
  }
  box[0] = xlo; box[1] = xhi; box[2] = ylo; box[3] = yhi;
  return nblk;
}

/* Where fx_polys_close puts the blocks of a polygon of npt points made at pt (the room
   fx_polys_room gave): right after the points. */
static inline gcoord (*fx_polys_blocks_at(struct gpoint *pt, int npt))[2]
{
  return (gcoord (*)[2])(void *)(pt + npt);
}

/* The polygon ps->p[ps->n] made of the points at mem (the chunk's room: npt of them, in
   nring rings rs[0..nring] of 3 points or more, rs[0] = 0), its nblk blocks already at
   fx_polys_blocks_at and box (xlo, xhi, ylo, yhi) its points' box, its offsets put after
   the blocks; added (its memory taken) when meet is NULL or its box meets meet's. */
static inline bool fx_polys_close_boxed(struct fx_polys *ps, char *mem, int nring,
                                        const int *rs, int owner, int light, const gcoord *meet,
                                        bool *added, size_t nblk, const gcoord box[4])
{
  struct fx_poly *p = &ps->p[ps->n];
  const int npt = rs[nring];
  const gcoord xlo = box[0], xhi = box[1], ylo = box[2], yhi = box[3];
  if (meet && (xhi <= meet[0] || xlo >= meet[1] || yhi <= meet[2] || ylo >= meet[3]))
    return true;
  p->pt = (struct gpoint *)(void *)mem;
  p->blk = fx_polys_blocks_at(p->pt, npt);
  p->rs = (int *)(mem + (size_t)npt * sizeof *p->pt + nblk * sizeof *p->blk);
  for (int r = 0; r <= nring; r++) p->rs[r] = rs[r];   /* (few: no call) */
  p->nring = nring;
  p->xlo = xlo; p->xhi = xhi; p->ylo = ylo; p->yhi = yhi;
  p->owner = owner;
  p->light = light;
  ps->mem->used += fx_piece((size_t)npt * sizeof *p->pt + nblk * sizeof *p->blk +
                            ((size_t)nring + 1) * sizeof *p->rs);
  ps->n++;
  if (added) *added = true;
  return true;
}

/* fx_polys_close_boxed with the blocks and box made here (fx_ring_blocks, ring by ring). */
static inline bool fx_polys_close_at(struct fx_polys *ps, char *mem, int nring,
                                     const int *rs, int owner, int light, const gcoord *meet,
                                     bool *added)
{
  struct gpoint *pt = (struct gpoint *)(void *)mem;
  gcoord (*blk)[2] = fx_polys_blocks_at(pt, rs[nring]);
  gcoord box[4] = { INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN };
  size_t nblk = 0;
  for (int r = 0; r < nring; r++)
    nblk = fx_ring_blocks(pt + rs[r], rs[r + 1] - rs[r], blk, nblk, box);
  return fx_polys_close_boxed(ps, mem, nring, rs, owner, light, meet, added, nblk, box);
}

/* fx_polys_room when the last chunk has no room or the list none for one more polygon. */
struct gpoint *fx_polys_room_made(struct fx_polys *ps, int npt);

static inline struct gpoint *fx_polys_room(struct fx_polys *ps, int npt)
{
  const struct fx_chunk *c = ps->mem;
  if (ps->n < ps->cap && c && c->cap - c->used >= fx_piece(fx_room_bytes(npt)))
    return (struct gpoint *)((char *)ps->mem->data + c->used);
  return fx_polys_room_made(ps, npt);
}

static inline bool fx_polys_close(struct fx_polys *ps, int nring, const int *rs, int owner,
                                  int light, const gcoord meet[4], bool *added)
{
  return fx_polys_close_at(ps, (char *)ps->mem->data + ps->mem->used, nring, rs, owner, light,
                           meet, added);
}

/* fx_polys_close when the caller has made the polygon's blocks where fx_polys_blocks_at
   says (nblk of them, as fx_ring_blocks makes them ring by ring) and its box. */
static inline bool fx_polys_close_made(struct fx_polys *ps, int nring, const int *rs, int owner,
                                       int light, const gcoord meet[4], bool *added, size_t nblk,
                                       const gcoord box[4])
{
  return fx_polys_close_boxed(ps, (char *)ps->mem->data + ps->mem->used, nring, rs, owner,
                              light, meet, added, nblk, box);
}

#endif
