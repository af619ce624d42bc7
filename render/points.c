/*
** points.c — the points engine (see points.h): each face's grid polygon rasterised by
** exact scanline crossings into a per-point (face, depth bounds) buffer.
**
** Numbers (every bound proven here; the scene reader keeps coordinates in 16 bits):
**
** Point centres.  Point (i, j) has its centre at x = XN(i) / xd grid units with
** XN(i) = GRID_ONE (xd XL + (2i + 1)(XR - XL)), xd = 2W, and y = yn_j / yd with
** yn_j = GRID_ONE (yd YT - (2j + 1)(YT - YB)), yd = 2H (CONTRACT.md; the same numbers
** as vis_scan). W <= 133, H <= 100.
**
** Rows of an edge.  An edge from (x0, y0) up to (x1, y1) (y0 < y1) crosses the line of
** row j, with the tie rule (the centre shifted up by e^2), when y0 <= y_j < y1. With
** N(y) = yd (GRID_ONE YT - y) and Dy = GRID_ONE (YT - YB):  y_j >= y  <=>
** (2j + 1) Dy <= N(y); |N| < 2^8 (2^23 + 2^28) < 2^37, Dy < 2^24: 64-bit.
**
** Columns of a crossing.  The crossing's x is (x0 dy yd + (yn - y0 yd) dx) / (dy yd)
** (dx = x1 - x0, dy = y1 - y0 > 0), and the tie rule (the centre shifted right by e)
** counts it left of the centre when x <= x_i. Point i is right of it when
** (2i + 1) D >= R with D = S dy yd, S = GRID_ONE (XR - XL), and
** R = xd (x0 dy yd + (yn - y0 yd) dx) - GRID_ONE xd XL dy yd:
** |dx|, |dy| < 2^29, |x0|, |y0| <= 2^28, |yn| < 2^33, yd < 2^8, xd < 2^9, S < 2^24:
** D < 2^61, |R| < 2^9 (2^65 + 2^37 2^29) + 2^69 < 2^77 — 128-bit. The first such i is
** floor(ceil(R / D) / 2). From one row to the next up, yn grows by 2 Dy, so R grows by a
** constant dR = 2 xd Dy dx; c = ceil(R / D) is stepped with s = c D - R (0 <= s < D <
** 2^61; s - drem > -2^61), with one division per edge for the start and one for the
** step (dR = dq D + drem, 0 <= drem < D). The quotients
** fit 64 bits: R / D = xd (x - GRID_ONE XL) / S at the crossing's x (|x| <= 2^28, S >=
** 2^8), |R / D| < 2^9 2^29 / 2^8 = 2^30; |dR| < 2^9 2^25 2^29 = 2^63. A division is
** done in 64 bits when its dividend fits them, else in 128. R itself is worked out as
** xd (dy yd (x0 - GRID_ONE XL) + (yn - y0 yd) dx) in 64 bits when no product or sum
** overflows them (the compiler's overflow builtins tell), else in 128.
**
** Even-odd.  On one row the crossings of a face (all rings; an even number, each ring
** giving an even number under the half-open rule) are sorted by their first columns c_k;
** a point i is inside when an odd number of crossings lie left of it, i.e. when an odd
** number of c_k are <= i: the points [c_0, c_1), [c_2, c_3), ... Columns clamped to
** [0, W] keep that order, so the clamp changes nothing inside the window.
**
** Two crossings (issue 19).  A face of one ring along which y changes direction twice
** (the signs of its edges' dy, horizontal edges left out, change twice around the ring:
** every triangle that is not flat, every convex face) is an up chain (dy > 0) from its
** lowest vertex to its highest and a down chain back, horizontal edges between. The edges
** of a chain cross the rows y0 <= y_j < y1 of their ends, one after the other: each chain
** crosses each row with ymin <= y_j < ymax, the rows of the face's box, exactly once. So
** every row of the box has two crossings, one of each chain, and even-odd gives the one
** span between them (the smaller column first) whatever the ring's winding; the crossings
** are kept at two slots a row (up, down), with no count and no sort. (Such a ring may
** cross itself; the rule is still even-odd on its two crossings.)
**
** Depth.  With the centre in world units u = (Xc / 2W, Yc / 2H, -Z0) - eye-relative,
** P = 4WH n.u = a 2H Xc + b 2W Yc - c 4WH Z0' is an integer linear in (i, j):
** P = alpha i + beta j + gamma, alpha = 4H (XR - XL) a, beta = -4W (YT - YB) b.
** |a|, |b|, |c| <= 2^33 (cross products of 16-bit differences), |Xc| <= 2W 2^17,
** |Yc| <= 2H 2^17, 4WH < 2^16: |P| < 3 2^66 < 2^68; |alpha|, |beta| < 2^60; |D| = deye
** < 2^51 (mapper.c). A in front of B: |D_B| P_A > |D_A| P_B, products < 2^119 — 128-bit,
** exact. A plane met at or behind the eye (P <= 0) is never in front; equal depth: the
** sign just right of the centre, then just above it, then the coplanar rule
** (mface_tie_front, render/mapper.h).
**
** Float filter (issue 19).  The exact compare is asked only where doubles cannot decide
** it. z = P / D (D = |D| above; 1/t up to a constant: larger is nearer) is computed in
** IEEE doubles rounded to nearest (u = 2^-53) as za = alpha / D, zb = beta / D,
** zc = gamma / D (alpha and beta as the product of their two factors, exact doubles;
** gamma an integer to double, rounded or truncated: error < 2u; D < 2^51 is exact; one
** division: < 3.01u together); zr = zb j + zc a row; z0 = za i0 + zr where a
** span starts; zl = z0 - E and zh = z0 + E, each stepped by + za from point to point;
** E = 2^-40 M' with M' the computed M = (|alpha| W + |beta| H + |gamma|) / D, M' >
** (1 - 8u) M. |z| <= M at every point and E < M / 2^39, so every value computed stays
** below 2M and each rounding costs at most 2uM. Against z - E (and z + E): the errors of
** za, zb, zc count 3.01u (|alpha| i + |beta| j + |gamma|) / D <= 3.01uM (za's is met i0
** times in z0 and once a step: i times, i < W); the roundings, two in zr, two in z0, one
** in zl (zh), one a step (fewer than W steps), (W + 4) 2uM. In all below (2W + 12) uM,
** which is < 2^-42 M < E for W < 2^9 (W <= 133). So zl < z < zh at every centre.
** Two chains: raster_plain and raster_fresh (where no tile is kept) step the even points
** of a span from (zl, zh) and the odd ones from (zl, zh) + za, each by 2 za (exact: a
** doubling), so that a point does not wait on the addition of the point before; the t-th
** point of the span (t < W) then meets za's error t times, as above, and at most t
** roundings of a step, fewer than above: the same bound holds (also when a span goes on
** in one chain from one of its points, raster_hi_rest: a point then met at most one
** rounding and one za a step from there). (With the tiles, the bounds stored feed the
** tiles' bounds and so which parts are skipped, a figure of --stats: there the steps stay
** one chain.)
** With the tiles the buffer keeps at each point, for the face o seen there, hi =
** max(zh, 0) and lo = zl when zl > 0, else -inf (both -inf where no face is yet): z_o <
** hi, 0 <= hi, and lo is finite only when z_o > lo > 0, i.e. P_o > 0. Face k at the point:
**   zl > hi: z_k > zl > hi >= max(z_o, 0), so P_k > 0 and either P_o <= 0 or
**     |D_o| P_k > |D_k| P_o: the exact compare puts k in front (with no face yet, any
**     zl > -inf: k is taken, as before);
**   zh < lo: z_k < zh < lo < z_o with P_o > 0: the exact compare does not;
**   else the exact compare from the two faces' exact alpha, beta, gamma: only where the
**     two depths are within about 2^-38 M of each other (the line where the faces meet,
**     coplanar faces) or a P may be <= 0.
** One bound.  Where no tile is kept (nothing asks a point's lo but the face drawn over
** it), the buffer keeps hi alone (p->zhi: 8 bytes a point, not 16: half the memory the
** spans write and the first clearing fills), and a lower bound is made from it when the
** doubles do not take face k: lo' = fl(hi - m_o), m_o = fl(3 E_o) of the face o seen
** there (p->m3). When lo' > 0, hi = zh (hi >= m_o > 0: not the clamp), and zh < z_o +
** E_o + 2^-42 M_o (above) with 2^-42 M_o < E_o / 3 (E_o = 2^-40 M'_o, M'_o > (1 - 8u)
** M_o): z_o > hi - 4 E_o / 3; while lo' <= hi - 3 E_o (1 - u) + 2u 2M_o (hi < 2M_o, one
** rounding each) < hi - 4 E_o / 3. So z_o > lo' > 0 (P_o > 0), and zh < lo' puts k
** behind, as zh < lo does above; lo' <= 0 decides nothing (then the exact compare). No
** face yet: hi = -inf, any zl > hi (p->m3[0] = 0 for the face -1 makes lo' -inf).
** A face whose least z over its box (at a corner; its double computed as z0 is, within
** 11.01uM < E) is > 4E has zl > z - 2E > 0 at all its points: it stores zl and zh as they
** are. Two faces in one plane get mface_coplanar_front's answer at every point
** (in_front_exact), so the exact compare is asked once for such a pair while the
** face is drawn (struct coplane).
**
** Tiles (coarse coverage, issue 19).  The grid is cut into tiles of TILE x TILE points
** (the last ones cut by the grid). A tile T keeps ninf, the number of its points whose lo
** is -inf (exact: every write adds the change at its point), and a bound T.lo <= lo at
** each of its points whose lo is finite (a write of lo' lowers T.lo to lo' when below it;
** a recount, done when the bound is asked for after a write may have raised the least,
** sets it to the least). Face k's bound over a rectangle [i0, i1] x [j0, j1] of its box:
** z is linear in (i, j) with the signs of alpha and beta (D > 0), greatest at the corner
** i = (alpha > 0 ? i1 : i0), j = (beta > 0 ? j1 : j0); there its double z0, computed as
** the box's corner above, is within 11.01uM of z, so z0 + 2E > z + E, and the addition's
** rounding (under 2uM < E) keeps zh_T = fl(z0 + 2E) > z at every point of the rectangle.
** Where T.ninf = 0 and zh_T < T.lo over T's part of the box, at each of face k's points
** there the face o seen has a finite lo: z_o > lo > 0 (P_o > 0), and z_k < zh_T < T.lo <=
** lo < z_o. So P_k <= 0 (never in front) or |D_o| P_k < |D_k| P_o strictly: the exact
** compare keeps o (no tie to break). Skipping those points leaves every face and bound as
** the point-by-point loop leaves them. Face k writes nowhere it is behind, so the tiles a
** band's test finds hold for all of the band's rows while k is drawn. A band's test asks
** of each tile T: T.ninf = 0 and zh_T < the least lo of T's points (T.lo is at or below
** that least, and is recounted when it is not below zh_T and may be stale), so a test made
** before k is drawn (face_hidden's, kept) gives the answer face_draw's would: k's writes
** in the bands above it touch other tiles. A face behind all
** over its box is not drawn; only whether it covers a centre is asked (faces_culled):
** its middle row's crossings, as face_draw finds them, say yes, or face_draw runs with
** every part skipped. The faces are drawn in the Mapper's order without the tiles' tests
** until their boxes have covered the grid COARSE_DEPTH times over (below that the tests
** cost more than they save), the rest nearest first with them; every write keeps the
** bounds, so they hold however a face was drawn, and the frame is the same ("Order").
** When the boxes of all the faces cover the grid fewer times than that, no face is drawn
** with the tests and no bound is kept (nothing would read one).
**
** Clearing.  Where no tile is kept, nothing reads a point's face or bounds but the spans
** of later faces over it. So where the faces' boxes are LAZY_BOX points or more a face
** (smaller faces lose more to a test a span than the clearing costs), a row's buffer is
** not cleared for the frame (lazy): the row keeps
** its ready columns [a, b) (p->ready), where the face and hi are a face's or
** nothing's (-1, -inf), a run that grows as spans come (row_ready). A span over them
** first clears its columns outside them; a span on a row with none, or beside them (the
** columns between then cleared), sees nothing anywhere and writes its face and bounds
** without reading, as the compare would take them at every point (zl, a finite double,
** > -inf = hi). At the end the faces outside each row's ready columns are set to -1.
** The buffer's own contents are kept from frame to frame (nothing of the view): after a
** frame without tiles the faces are -1 outside its ready columns (a frame that clears
** over the faces' boxes counts the boxes' columns on their rows as ready), which are kept
** (p->ready_kept), so the next such frame sets to -1 only the columns the last one made
** ready and it does not (and, clearing over the boxes, those). The effects write into the
** buffer only where it shows a face (fx_points' cuts), so only in ready columns.
**
** Order.  The faces kept are drawn nearest first (buckets of their nearest vertex's z in
** doubles; speed only; a lazy frame's faces, with no tile kept, farthest first instead:
** paint_order), which gives the frame of the Mapper's order when "in front" is a
** strict total order on the faces covering each centre. It is, as the exact compare
** decides it (the float filter and the coplanar cache answer as it does): faces with
** P > 0 before those with P <= 0; among P > 0 by z = P / |D| (real numbers), equal z by
** a / |D|, then b / |D| (mface_tie_front), all three equal only for one plane (a depth and
** both slopes equal at a point); within one plane, and among P <= 0, the coplanar rule:
** a pattern before the face it lies on, a pattern before a face that is none, else the
** larger number. Without a pattern lying on a pattern, the first part only ever compares
** a pattern with a face that is none, as the second part does: the rule is the order of
** (pattern, number), strict and total except between faces of one number (the triangles
** of a folded face), which strict_front orders by their place in the Mapper's array, the
** first in front. Drawn in that array's order, a later face k meets an earlier o, which
** strict_front keeps as the rule alone did (no both ways): the frame is the one the
** engine always drew. A pattern on a pattern can make the rule go round in a circle
** (3 on 5, 2 on 3, 1 on 2: 2 before 3, 1 before 2, 3 before 1); such scenes are drawn in
** the Mapper's order.
** Needed: double arithmetic as C11 Annex F (x86-64's SSE2, FLT_EVAL_METHOD 0; wider
** intermediates or fused multiply-adds only shrink the errors); never -ffast-math.
*/
#include "render/points.h"

#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "emu/core.h"
#include "emu/cost.h"
#include "emu/grow.h"
#include "render/geom.h"
#include "render/segment.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

struct points_edge {
  int32_t jtop, jbot;       /* rows crossed: jtop .. jbot (j from the top), jtop <= jbot */
  bool up;                  /* y grows along the edge in its ring's order */
  int64_t c;                /* ceil(R / D) at row jbot */
  int64_t s;                /* c D - R, 0 <= s < D */
  int64_t D;
  int64_t dq;               /* floor(dR / D) for a row up */
  int64_t drem;             /* dR - dq D */
};

/* A face's depth numerator P = alpha i + beta j + gamma over the grid (exact). */
struct points_plane {
  wide alpha, beta, gamma;
};

/* What a point's buffer knows of the face seen there in doubles where tiles are kept:
   z = P / D lies strictly between lo and hi; hi >= 0 and lo > 0 (else -inf) once a face
   is seen, both -inf while none is (see the top of the file). */
struct points_z {
  double lo, hi;
};

/* A face's box of points (columns ilo .. ihi - 1, rows jlo .. jhi) and its depth z in
   doubles: z0 = za i + (zb j + zc), within E (see the top of the file). */
struct points_box {
  int32_t k;                                /* the face (index in map.f) */
  int32_t ilo, ihi, jlo, jhi;
  double za, zb, zc, E;
  bool plus;                                /* zl > 0 at every point of the box */
  bool inside;                              /* the box's columns not cut by the grid: every
                                               crossing's column within [0, W] (face_draw) */
  bool arise, brise;                        /* alpha > 0, beta > 0 (exact): z grows with i, j */
};

/* A tile of TILE x TILE points (the last ones cut by the grid): lo <= the lo of each of
   its points whose lo is finite, exactly their least when !dirty; ninf: its points whose
   lo is -inf (no face yet, or a face not proven in front of the eye there). */
struct points_tile {
  double lo;
  int32_t ninf;
  bool dirty;
};

#define TILE_SHIFT 3
#define TILE (1 << TILE_SHIFT)
#define BUCKETS_MAX 4096                    /* nearest-first order: buckets of depth */
#define COARSE_DEPTH 3                      /* tiles where boxes cover the grid as often */
#define LAZY_BOX 64                         /* rows made ready span by span ("Clearing")
                                               where the boxes are this many points a face */

#define Z_MARGIN 0x1p-40                    /* E = Z_MARGIN M (the filter's bound) */

/* Division by a number d fixed for a frame (the grid's Dy and S), by a multiply: for
   0 <= a < 2^62, floor(a / d) = floor(a m / 2^k) with k = max(64, 62 + l), l = ceil(log2 d)
   (2^(l - 1) < d <= 2^l), m = ceil(2^k / d). Proof: m d = 2^k + e with 0 <= e < d, so
   a m / 2^k = a / d + a e / (d 2^k), and the second term is below 2^62 / 2^k <= 2^-l <=
   1 / d; a / d = q + r / d with r <= d - 1, so a m / 2^k < q + 1 and its floor is q. For
   2 <= d < 2^40, m < 2^k / d + 1 <= 2^63 + 1 (k = 62 + l: 2^k / d < 2^(62 + l) / 2^(l - 1);
   k = 64 > 62 + l: d >= 2) fits 64 bits, and a m < 2^125. A 64-bit divide's latency is
   what this saves: a multiply and a shift instead. */
struct divconst {
  int64_t d;
  uint64_t m;
  int k;                        /* k - 64 (in [0, 38]) */
};

static struct divconst divconst_make(int64_t d)              /* 2 <= d < 2^40 */
{
  int l = 0;
  while (((int64_t)1 << l) < d) l++;
  const int k = 62 + l > 64 ? 62 + l : 64;
  const unsigned __int128 one = 1;
  return (struct divconst){ d, (uint64_t)(((one << k) + (unsigned __int128)d - 1) /
                                          (unsigned __int128)d), k - 64 };
}

/* floor(n / c->d): for n < 0, -ceil(-n / d) = -floor((d - 1 - n) / d); by the multiply
   while the dividend is below 2^62 (always on the grid: |n| < 2^38), else the divide. */
static inline int64_t floor_div_const(int64_t n, const struct divconst *c)
{
  const int64_t neg = -(int64_t)(n < 0);
  const uint64_t a = (uint64_t)(n ^ neg) + ((uint64_t)c->d & (uint64_t)neg);   /* n, or
                                                      ~n + d = d - 1 - n */
  if (__builtin_expect(a >= (uint64_t)1 << 62, 0)) {
    const int64_t q = n / c->d, r = n % c->d;
    return q - (r < 0);
  }
  const uint64_t q = (uint64_t)(((unsigned __int128)a * c->m) >> 64) >> c->k;
  return ((int64_t)q ^ neg) - neg;              /* q, or -q */
}

/* *q = floor(n / d), *r = n - *q d (0 <= *r < d), d > 0, for a quotient that fits 64
   bits: in 64-bit arithmetic when n does (nearly always), else in 128-bit. */
static inline void floor_divmod(wide n, int64_t d, int64_t *q, int64_t *r)
{
  if (n == (int64_t)n) {
    int64_t n64 = (int64_t)n, q64 = n64 / d, r64 = n64 % d;
    const int64_t neg = -(int64_t)(r64 < 0);    /* -1 when r64 < 0 (no branch: a compare) */
    *q = q64 + neg;
    *r = r64 + (d & neg);
    return;
  }
  wide qw = n / d, rw = n % d;
  if (rw < 0) { qw--; rw += d; }
  *q = (int64_t)qw;
  *r = (int64_t)rw;
}

/* plain_convex's step at a corner: the edge into it (*ex, *ey), the edge out (fx, fy).
   geom_orient(a, b, c) at the corner b is the cross product (b - a) x (c - b) of the two
   edges: the same number as (b - a) x (c - a) (their difference is (b - a) x (b - a) = 0),
   each edge's differences made once; in 64 bits: differences < 2^29, products < 2^58.
   False: the ring turns right there, or goes straight on and does not go on forward (the
   dot product of the edges <= 0: it doubles back, or an edge has no length). The out
   edge's dy sign, when not 0, counted into *first (the first such sign), *prev (the last)
   and *changes. */
static inline bool corner_left(int64_t *ex, int64_t *ey, int64_t fx, int64_t fy, int *first,
                               int *prev, int *changes)
{
  const int64_t cross = *ex * fy - *ey * fx;
  if (cross < 0) return false;
  if (cross == 0 && *ex * fx + *ey * fy <= 0) return false;
  *ex = fx;
  *ey = fy;
  const int sg = (fy > 0) - (fy < 0);
  if (!sg) return true;
  if (!*first) *first = sg;
  else if (sg != *prev) (*changes)++;
  *prev = sg;
  return true;
}

/* A face the Segment Generator takes as it is without asking it: a triangle, or one
   outer ring that turns left or goes straight on forward at every corner (no corner to
   the right) and winds once (the sign of dy changes exactly twice around it).

   Such a ring with corners where it goes straight on (a vertex inside a side: a
   T-junction's) is what seg_check takes, decision by decision (generate, segment.c; the
   Mapper's rings are on the grid, the outer one counter-clockwise, render/mapper.h).
   The edges' directions turn left, never right, and, dy changing sign twice, go round
   exactly once (each sign change is a pass of the direction through the horizontal, twice
   a turn): the ring is a convex polygon's boundary gone round once counter-clockwise, its
   vertices distinct points. So check_input passes it (no two consecutive vertices at one
   point and no doubling back: both are a straight corner whose dot product is not
   positive; twice its area > 0); lowest_concave finds no concave vertex (its turn of two
   sides' lines, a = -dy, b = dx, is this cross product: never negative), so the ring is
   one finished piece; tidy_ring drops each vertex inside a side (the two sides, on one
   line through the vertex and of one direction, are same_line) and no other (no two
   vertices coincide), leaving the corners where the ring turns, each a strict left turn
   between the same lines as before (a side's line is proportional to its parts', by a
   positive factor: the same turns and half-planes), at least three of them, whose sides'
   directions wrap round once (winds_once). Only the tables' room in core and the host's
   memory can stop seg_check there: segment_takes grows the core; out of memory is an
   error, not a refusal. */
static __attribute__((noinline)) bool convex_once(const struct gpoint *p, int n);

static inline bool plain_convex(const struct mface *f)
{
  if (f->nring != 1) return false;
  const int n = f->ring_start[1];
  return n == 3 || convex_once(f->pt, n);
}

/* plain_convex for a ring of n > 3 points: turns left or goes straight on forward at
   every corner and winds once (out of line: a triangle, the common face, needs none of
   it). */
static __attribute__((noinline)) bool convex_once(const struct gpoint *p, int n)
{
  const int64_t lx = p[0].x - p[n - 1].x, ly = p[0].y - p[n - 1].y;  /* the edge into p[0] */
  int64_t ex = lx, ey = ly;
  int first = 0, prev = 0, changes = 0;
  for (int k = 0; k + 1 < n; k++)               /* the corners p[0] .. p[n - 2] */
    if (!corner_left(&ex, &ey, p[k + 1].x - p[k].x, p[k + 1].y - p[k].y, &first, &prev,
                     &changes))
      return false;
  if (!corner_left(&ex, &ey, lx, ly, &first, &prev, &changes)) return false;   /* p[n - 1] */
  if (prev != first) changes++;
  return changes == 2;
}

/* Would the 1974 engine's Segment Generator take face k as it is? 1 yes, 0 it refuses it
   (not simple on the grid), or a negative status. The check (seg_check: seg_generate's
   decisions without its pieces) runs in a core of its own, grown when a face's tables
   need more, with scratch kept between frames. */
static int segment_takes(struct points *p, const struct mface *f, struct t74_error *err)
{
  for (;;) {
    if (!p->segcore) {
      p->segcore = core_new(1u << 16);
      if (!p->segcore) return -t74_fail(err, T74_EIO, "out of host memory");
    }
    if (!p->segscr) {
      p->segscr = seg_scratch_new();
      if (!p->segscr) return -t74_fail(err, T74_EIO, "out of host memory");
    }
    struct seg_input in = { f->id, f->nring, f->ring_start, f->pt, f->vid, 1 };
    uint32_t mark = core_mark(p->segcore);
    int st = seg_check(&in, p->segscr, p->segcore, err);
    core_release(p->segcore, mark);
    if (st == T74_OK) return 1;
    if (st == T74_EINPUT) { memset(err, 0, sizeof *err); return 0; }
    if (st != T74_ECORE || core_words(p->segcore) >= (1u << 30)) return -st;
    uint32_t w = core_words(p->segcore) * 4;
    memset(err, 0, sizeof *err);
    core_free(p->segcore);
    p->segcore = core_new(w);
    if (!p->segcore) return -t74_fail(err, T74_EIO, "out of host memory");
  }
}

/* The Mapper, then the faces folded by rounding split as the 1974 engine splits them. */
static int map_faces(struct points *p, const struct scene *s, struct t74_error *err)
{
  if (p->keep) mapper_keep_faces(&p->map, p->keep);   /* the last call's blocks */
  mapper_free(&p->map);
  /* the core's words, a sum over the scene's faces: the scene alone, so the last call's
     where the keep holds this scene (every call until it is freed is of this scene, and
     freeing it forgets its scene: mapper_keep.s), not a pass over every face a frame (at
     10,000 boxes about 2% of a frame, most of it waiting on the faces' ring arrays) */
  uint64_t words;
  if (p->keep && p->keep->s == s && p->words_s == s) {
    words = p->words_n;
  } else {
    words = 1024 + 6 * (uint64_t)s->nv + 10 * (uint64_t)s->nf;
    for (int k = 0; k < s->nf; k++) words += 10 * (uint64_t)s->f[k].ring_start[s->f[k].nring];
    if (words > (UINT64_C(1) << 31)) words = UINT64_C(1) << 31;
    p->words_s = s;
    p->words_n = words;
  }
  if (p->core && core_words(p->core) < words) { core_free(p->core); p->core = NULL; }
  if (!p->core && !(p->core = core_new_lazy((uint32_t)words)))
    return t74_fail(err, T74_EIO, "out of host memory");
  core_release(p->core, 0);
  int st = mapper_run_kept(s, &p->map, p->core, NULL, p->keep, err);   /* not counted */
  struct cost cost;                         /* the splits' charges, never reported */
  memset(&cost, 0, sizeof cost);
  if (st != T74_OK) return st;
  p->faces_split = 0;
  int n0 = p->map.nface;
  int *left = NULL, nleft = 0;
  size_t capleft = 0;
  for (int k = 0; k < n0; k++) {
    if (plain_convex(&p->map.f[k])) continue;
    int takes = segment_takes(p, &p->map.f[k], err);
    if (takes < 0) { free(left); return -takes; }
    if (takes) continue;
    const struct mface *f = &p->map.f[k];
    int ntri = 0;
    st = mapper_split_face(&p->map, k, p->core, &cost, &ntri, err);
    if (st == T74_EINPUT) {
      f = &p->map.f[k];
      st = t74_fail_at(err, T74_EINPUT, s->file, f->sline,
                       "face %u: rounded onto the plane grid (1/%d unit) its boundary is "
                       "no longer simple, and no split into triangles was found; it "
                       "is seen almost edge-on or from far away: move the eye or the face",
                       (unsigned)f->id, (int)GRID_ONE);
    }
    if (st != T74_OK) { free(left); return st; }
    p->faces_split++;
    if (ntri == 0) {
      if (!t74_grow((void **)&left, &capleft, nleft + 1, sizeof *left)) {
        free(left);
        return t74_fail(err, T74_EIO, "out of host memory");
      }
      left[nleft++] = k;
    }
  }
  if (!t74_grow((void **)&p->skip, &p->skipcap, p->map.nface + 1, 1)) {
    free(left);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  if (p->map.nface > 0) memset(p->skip, 0, (size_t)p->map.nface);
  for (int k = 0; k < nleft; k++) p->skip[left[k]] = 1;
  free(left);
  return T74_OK;
}

/* The grid's constants for one render. */
struct grid {
  int W, H;
  int64_t XL, YB, XR, YT, xd, yd, S, Dy;
  wide Ex, Ey, Ez;
  wide ga, gb, gc;              /* gamma = a ga + b gb + c gc for a plane (a, b, c) (face_box) */
  int64_t ga64, gb64, gc64;     /* the same, when g64: all three fit 64 bits */
  bool g64;
  double i0, ki, j0, kj;        /* a grid point (x, y) is at (i0 + ki x, j0 - kj y) in points */
  struct divconst dDy, dS;      /* division by Dy, by S (both in [2, 2^24]) */
  bool lazy;                    /* rows made ready span by span ("Clearing") */
  /* face_edges' numbers: ytop = yd GRID_ONE YT (row_q(y) = floor((ytop - yd y) / Dy); yn
     of row j: ytop - (2j + 1) Dy), xoff = GRID_ONE XL, Syd = S yd (< 2^32), dRx = 2 xd Dy
     (dR = dRx dx; < 2^34) */
  int64_t ytop, xoff, Syd, dRx;
  /* face_box's numbers: alpha = a ca, beta = -b cb (ca = 4 H (XR - XL), cb = 4 W (YT - YB),
     both < 2^26), and ca, cb, W, H as doubles (exact: integers below 2^53) */
  int64_t ca, cb;
  double cad, cbd, Wd, Hd;
};

/* Row j (from the top) has y_j >= y exactly when 2j + 1 <= row_q(y). */
static inline int64_t row_q(const struct grid *g, int64_t y)
{
  return floor_div_const(g->yd * (GRID_ONE * g->YT - y), &g->dDy);
}

/* floor(m / 2) as the exact quotient of the even number at or below m (m & 1 is m's
   parity in two's complement, negative m too; no shift of a negative number, whose
   result C leaves to the implementation): no divide. */
static inline int64_t floor_half(int64_t m) { return (m - (m & 1)) / 2; }

/* Rows with y_j >= y, from q = row_q(y): j <= floor((q - 1) / 2). */
static inline int64_t rows_at_or_above(int64_t q) { return floor_half(q - 1); }

/* Rows with y_j < y (2j + 1 > q): j >= ceil(q / 2), the exact quotient of the even number
   at or above q. */
static inline int64_t rows_below(int64_t q) { return (q + (q & 1)) / 2; }

/* Columns i with x_i >= x (grid units, an integer): i >= col_first_at_or_right(x). */
static inline int64_t col_first_at_or_right(const struct grid *g, int64_t x)
{
  /* (2i + 1) S >= xd (x - GRID_ONE XL) */
  int64_t R = g->xd * (x - GRID_ONE * g->XL);
  int64_t q = -floor_div_const(-R, &g->dS);                         /* ceil */
  return floor_half(q);
}

/* Vertices.  Each scene vertex's row_q (of its y) and first column at or right (of its
   x) made once a frame from the Mapper's projection (map.proj, pt[k] = proj[vix[k]]), not
   again for each face the vertex is on (face_box, face_edges). They are kept clamped, row_q
   to [-2, 2H + 2] and the column to [-1, W + 1], in 32 bits; every use decides as the
   numbers themselves (both maps rise or fall together, so the clamped least and greatest
   are the least and greatest clamped):
   - face_box: jlo = max(rows_below(q), 0) of the least q; jhi = min(rows_at_or_above(q),
     H - 1) of the greatest. For q > 2H + 2 rows_below(q) >= H + 1, as of 2H + 2: the face is
     culled either way (jlo > H - 1 >= jhi); for q < -2 it is <= -1, as of -2: jlo = 0.
     rows_at_or_above(q) >= H for q > 2H + 2 and of 2H + 2 (H): jhi = H - 1; <= -2 for q < -2
     and of -2 (-2): culled either way (jhi < 0 <= jlo). Columns: ilo >= 0 and ihi <= W
     (inside) as the clamped ones are, and clamped to [0, W] alike.
   - face_edges: jb = min(rows_at_or_above(q), jhi), jt = max(rows_below(q), jlo), with
     0 <= jlo <= jhi <= H - 1, an edge kept when jt <= jb. Beyond the clamps as above: jb =
     jhi or < 0 (then jt >= 0 > jb), jt = jlo or > H (then jt > jhi >= jb), the same for the
     number and the clamped one; an edge kept has the same jb and jt. */
static int vertex_rows(struct points *p, const struct scene *s, const struct grid *g,
                       struct t74_error *err)
{
  const int nv = s->nv;
  if (!t74_grow((void **)&p->vrc, &p->vrccap, 2 * nv + 2, sizeof *p->vrc))
    return t74_fail(err, T74_EIO, "out of host memory");
  const struct gpoint *const proj = p->map.proj;
  int32_t *const vrc = p->vrc;
  const int64_t qhi = 2 * (int64_t)g->H + 2, chi = (int64_t)g->W + 1;
  for (int v = 0; v < nv; v++) {
    int64_t q = row_q(g, proj[v].y), c = col_first_at_or_right(g, proj[v].x);
    q = q < -2 ? -2 : q > qhi ? qhi : q;
    c = c < -1 ? -1 : c > chi ? chi : c;
    vrc[2 * v] = (int32_t)q;
    vrc[2 * v + 1] = (int32_t)c;
  }
  return T74_OK;
}

/* Edge a -> b of a ring (qa, qb: its ends' row_q, as vertex_rows keeps them) into *e,
   stepped from its bottom row; 1 when it crosses a row of jlo..jhi (kept), else 0. Every
   edge goes through the same steps up to its crossing, a horizontal one or one that
   crosses no row of the box too, and is kept or not at the end (the caller's count grows
   by the answer): which edges cross a row is known only at the end of the chain from the
   vertices' rows, and a branch on it that the predictor guesses wrong would throw away the
   next edges' work begun meanwhile. A horizontal edge divides by D = 1 instead of 0; an
   edge not kept leaves *e written, the caller's next slot. The step a row up is made only
   for an edge of more than one row (a branch: its divide a row cost more than the
   branch's misses, measured on the sphere). */
static inline __attribute__((always_inline)) int
edge_make(const struct grid *g, struct gpoint a, struct gpoint b, int64_t qa, int64_t qb,
          int64_t jlo, int64_t jhi, struct points_edge *e)
{
  /* its lower and upper ends, without branches (an edge's way has no pattern the
     predictor learns) */
  const bool up = a.y < b.y, flat = a.y == b.y;
  const int64_t dn = -(int64_t)!up;             /* all ones: a and b swapped */
  const int64_t sx = (a.x ^ b.x) & dn, sy = (a.y ^ b.y) & dn, sq = (qa ^ qb) & dn;
  a.x ^= sx;
  b.x ^= sx;
  a.y ^= sy;
  b.y ^= sy;
  const int64_t qbot = qa ^ sq, qtop = qb ^ sq; /* of the lower end a, the upper b */
  int64_t jb = rows_at_or_above(qbot), jt = rows_below(qtop);
  jb = jb > jhi ? jhi : jb;
  jt = jt < jlo ? jlo : jt;
  const int64_t dx = b.x - a.x, dy = b.y - a.y;
  const int64_t D = (g->Syd * dy) | (int64_t)flat;   /* > 0 (flat: 1) */
  /* R = xd (dy yd (x0 - GRID_ONE XL) + (yn - y0 yd) dx): in 64 bits while no product
     or sum overflows them (the builtins say so), else in 128 */
  const int64_t yd = g->yd, xd = g->xd;
  const int64_t yn = g->ytop - (2 * jb + 1) * g->Dy;
  const int64_t u = a.x - g->xoff, v = yn - a.y * yd, dyy = dy * yd;
  int64_t t0, t1, t2, R64, c, s;
  if (!__builtin_mul_overflow(dyy, u, &t0) && !__builtin_mul_overflow(v, dx, &t1) &&
      !__builtin_add_overflow(t0, t1, &t2) && !__builtin_mul_overflow(xd, t2, &R64))
    floor_divmod(R64, D, &c, &s);
  else
    floor_divmod((wide)xd * ((wide)dyy * u + (wide)v * dx), D, &c, &s);
  const int64_t nz = -(int64_t)(s != 0);        /* from floor to ceiling, no branch */
  e->jtop = (int32_t)jt;
  e->jbot = (int32_t)jb;
  e->up = up;
  e->D = D;
  e->c = c - nz;
  e->s = (D - s) & nz;
  if (jt < jb) {                                /* dR = dRx dx, |dR| < 2^63: 64 bits */
    const int64_t dR = g->dRx * dx, q = dR / D, m = dR % D, neg = -(int64_t)(m < 0);
    e->dq = q + neg;
    e->drem = m + (D & neg);
  } else {
    e->dq = e->drem = 0;                        /* one row or none: never stepped */
  }
  return !flat && jt <= jb;                     /* (flat: jt > jb already) */
}

/* The sign of dy from a to b: 1 up, -1 down, 0 horizontal. */
static inline int dy_sign(struct gpoint a, struct gpoint b)
{
  return (int)(a.y < b.y) - (int)(a.y > b.y);
}

/* One edge's sign sg in face_edges' count of dy's changes of sign around a ring: *turns
   the changes so far, *first the first sign not 0, *last the last (a 0 leaves them). */
static inline void dy_turn(int sg, int *turns, int *first, int *last)
{
  *turns += *last != 0 && sg != 0 && sg != *last;
  *first += sg & -(*first == 0);
  *last = sg != 0 ? sg : *last;
}

/* Face k's edges with their rows inside jlo..jhi, each stepped from its bottom row.
   *monotone: the face is one ring along which y changes direction twice (the signs of
   the edges' dy, horizontal edges left out, change twice around it: every triangle that
   is not flat, every convex ring; "Two crossings" at the top of the file). A triangle:
   its three edges in the ring's order, as the loop below takes them, and monotone unless
   its three y are equal (then no sign at all): else the signs, 0 for a horizontal edge,
   sum to 0 (the dy do), so both signs are there, and around three edges with one or none
   left out they change exactly twice. */
static int face_edges(struct points *p, const struct grid *g, const struct mface *f,
                      int64_t jlo, int64_t jhi, int *nedge, bool *monotone,
                      struct t74_error *err)
{
  int n = f->ring_start[f->nring];
  if (!t74_grow((void **)&p->edge, &p->edgecap, n, sizeof *p->edge))
    return t74_fail(err, T74_EIO, "out of host memory");
  struct points_edge *const edge = p->edge;
  const int32_t *const vrc = p->vrc, *const vix = f->vix;
  if (n == 3 && f->nring == 1) {
    const struct gpoint p0 = f->pt[0], p1 = f->pt[1], p2 = f->pt[2];
    const int64_t q0 = vrc[2 * vix[0]], q1 = vrc[2 * vix[1]], q2 = vrc[2 * vix[2]];
    int ne = edge_make(g, p0, p1, q0, q1, jlo, jhi, &edge[0]);
    ne += edge_make(g, p1, p2, q1, q2, jlo, jhi, &edge[ne]);
    ne += edge_make(g, p2, p0, q2, q0, jlo, jhi, &edge[ne]);
    *nedge = ne;
    *monotone = !(p0.y == p1.y && p1.y == p2.y);
    return T74_OK;
  }
  int turns = 0, first = 0, last = 0;           /* dy's changes of sign, its first, last */
  if (n == 4 && f->nring == 1) {                /* a quadrilateral (the street's, the boxes'):
                                                   the loop below without its steps */
    const struct gpoint p0 = f->pt[0], p1 = f->pt[1], p2 = f->pt[2], p3 = f->pt[3];
    const int64_t q0 = vrc[2 * vix[0]], q1 = vrc[2 * vix[1]], q2 = vrc[2 * vix[2]],
                  q3 = vrc[2 * vix[3]];
    int ne = edge_make(g, p0, p1, q0, q1, jlo, jhi, &edge[0]);
    ne += edge_make(g, p1, p2, q1, q2, jlo, jhi, &edge[ne]);
    ne += edge_make(g, p2, p3, q2, q3, jlo, jhi, &edge[ne]);
    ne += edge_make(g, p3, p0, q3, q0, jlo, jhi, &edge[ne]);
    dy_turn(dy_sign(p0, p1), &turns, &first, &last);   /* the loop's count */
    dy_turn(dy_sign(p1, p2), &turns, &first, &last);
    dy_turn(dy_sign(p2, p3), &turns, &first, &last);
    dy_turn(dy_sign(p3, p0), &turns, &first, &last);
    *nedge = ne;
    *monotone = turns + (first != last) == 2;
    return T74_OK;
  }
  int ne = 0;
  for (int r = 0; r < f->nring; r++) {
    int lo = f->ring_start[r], hi = f->ring_start[r + 1];
    const int64_t qlo = vrc[2 * vix[lo]];
    int64_t qb = qlo;
    for (int k = lo; k < hi; k++) {
      int nk = k + 1 < hi ? k + 1 : lo;
      const struct gpoint a = f->pt[k], b = f->pt[nk];
      const int64_t qa = qb;
      qb = vrc[2 * vix[nk]];
      dy_turn(dy_sign(a, b), &turns, &first, &last);
      ne += edge_make(g, a, b, qa, qb, jlo, jhi, &edge[ne]);
    }
  }
  *nedge = ne;
  *monotone = f->nring == 1 && turns + (first != last) == 2;
  return T74_OK;
}

/* The column of a crossing from c = ceil(R / D): floor(c / 2) clamped to [0, W]. */
static inline int32_t col_of(const struct grid *g, int64_t c)
{
  c = c > 0 ? c >> 1 : 0;                       /* floor(c / 2) <= 0: 0 */
  return c > g->W ? g->W : (int32_t)c;
}

/* An edge's crossing a row up: R grows by dR = dq D + drem, so c grows by dq, and by one
   more when s - drem < 0 (then s gains D): a carry the branch predictor cannot guess, so
   taken without a branch. */
static inline void edge_step(const struct points_edge *e, int64_t *c, int64_t *s)
{
  const int64_t t = *s - e->drem, carry = -(int64_t)(t < 0);   /* -1 or 0, no branch */
  *s = t + (e->D & carry);
  *c += e->dq - carry;
}

/* Edge e's crossings' columns of its rows jbot .. jtop (c, s: at jbot) into x[0], x[-2],
   ... (a row up, two slots down: face_draw's two crossings a row), col_of's, or with
   inside floor(c / 2) as it is (face_draw says when that is the same). In two chains,
   rows jbot, jbot - 2, ... and jbot - 1, jbot - 3, ..., each stepped two rows at a time:
   one chain's steps wait on each other (s's subtract, sign, mask and add: about 4 cycles
   a row, 95% of face_draw's samples on t1-a), two chains' do not. Two rows up, R grows by
   2 dR = (2 dq) D + 2 drem with 0 <= 2 drem < 2D (drem < D < 2^61: no overflow), so
   dq2 = 2 dq + 1, drem2 = 2 drem - D where 2 drem >= D, else 2 dq and 2 drem, and
   0 <= drem2 < D: edge_step's carry with (dq2, drem2) gives c = ceil(R / D) and s = c D -
   R two rows up exactly as two of its steps do. The last step of a chain may go a row
   past jtop (written nowhere; |dq| < 2^31 as |R / D| < 2^30 along the edge: no
   overflow). */
static inline __attribute__((always_inline)) void
edge_rows(const struct grid *g, const struct points_edge *e, int64_t c, int64_t s, int32_t *x,
          bool inside)
{
  int32_t j = e->jbot;
  const int32_t jtop = e->jtop;
  if (j - jtop < 3) {                           /* up to three rows: one chain (the second's
                                                   set-up would cost more than it saves) */
    for (;; j--, x -= 2) {
      *x = inside ? (int32_t)(c >> 1) : col_of(g, c);
      if (j == jtop) return;
      edge_step(e, &c, &s);
    }
  }
  int64_t c1 = c, s1 = s;                       /* the second chain: a row up */
  edge_step(e, &c1, &s1);
  const int64_t D = e->D, r2 = 2 * e->drem, ge = -(int64_t)(r2 >= D);
  const struct points_edge two = { .D = D, .dq = 2 * e->dq - ge, .drem = r2 - (D & ge) };
  for (;;) {
    x[0] = inside ? (int32_t)(c >> 1) : col_of(g, c);
    x[-2] = inside ? (int32_t)(c1 >> 1) : col_of(g, c1);
    j -= 2;
    x -= 4;
    if (j < jtop) return;
    edge_step(&two, &c, &s);
    if (j == jtop) {
      x[0] = inside ? (int32_t)(c >> 1) : col_of(g, c);
      return;
    }
    edge_step(&two, &c1, &s1);
  }
}

/* The rule's answer for a pair it leaves undecided both ways (two faces of one number in
   one plane: the triangles of one folded face) made strict: the one first in the Mapper's
   order is in front, as drawing the faces in that order has always made it ("Order"). */
static bool strict_front(bool ab, const struct mface *A, const struct mface *B, bool ba)
{
  return ab || (!ba && A < B);
}

/* Is face k (P_k) in front of the face o seen so far (P_o) at a centre? */
static inline bool in_front(wide Pk, const struct mface *fk, wide Po, const struct mface *fo)
{
  int s;
  if (Pk <= 0 || Po <= 0) s = (Pk > 0) - (Po > 0);
  else {
    wide l = (wide)fo->deye * Pk, r = (wide)fk->deye * Po;
    s = (l > r) - (l < r);
    if (s == 0)                                   /* equal depth: render/mapper.h */
      return strict_front(mface_tie_front(fk, fo), fk, fo, mface_tie_front(fo, fk));
  }
  if (s == 0)
    return strict_front(mface_coplanar_front(fk, fo), fk, fo, mface_coplanar_front(fo, fk));
  return s > 0;
}

/* The exact compare at point (i, j) between face k and the face o seen there, from the
   faces' exact depth numerators (out of line: the spans' loop keeps no 128-bit state).
   *same: the two planes are one (P_k |D_o| = P_o |D_k| everywhere: |alpha| |D| < 2^111,
   |gamma| |D| < 2^119), where the answer is mface_coplanar_front's at every point: the
   signs of P_k and P_o agree, so in_front finds either both <= 0 or equal depths and
   equal slopes (alpha and -beta are mface_tie_front's a and b times positive factors). */
static __attribute__((noinline)) bool in_front_exact(const struct points *p, int k, int o,
                                                     int64_t i, int64_t j, bool *same)
{
  const struct points_plane *A = &p->plane[k], *B = &p->plane[o];
  const wide Dk = p->map.f[k].deye, Do = p->map.f[o].deye;
  *same = A->alpha * Do == B->alpha * Dk && A->beta * Do == B->beta * Dk &&
          A->gamma * Do == B->gamma * Dk;
  wide Pk = A->alpha * i + A->beta * j + A->gamma, Po = B->alpha * i + B->beta * j + B->gamma;
  return in_front(Pk, &p->map.f[k], Po, &p->map.f[o]);
}

/* A face in face k's plane met while k is drawn (-1: none yet), and the exact compare's
   answer against it: in_front_exact's *same, where that answer is the one at every point
   (so kept from span to span and row to row of face k). */
struct coplane {
  int o;
  bool front;
};

/* The least of the depth of the face o seen at a point whose hi is h (see "One bound" at
   the top of the file): z_o > lo_of(h, m_o) when that is > 0, m_o = p->m3[o + 1]. */
static inline double lo_of(double h, double m)
{
  return h - m;
}

/* Is face k (bounds zl, zh at point i of a row: faces fb, bounds hb) decided at the point
   where the doubles do not take it (!(zl > hb[i])), and in front there? Behind for certain
   when zh < lo_of(hb[i], m_o) and that is > 0 ("One bound"); else the exact compare, the
   answer against a face in k's plane kept in *co, *cofront (in_front_exact's *same). */
static inline __attribute__((always_inline)) bool
point_front(const struct points *p, int k, int64_t j, const int32_t *fb, const double *hb,
            int32_t i, double zh, int *co, bool *cofront)
{
  const int o = fb[i];
  if (o == *co) return *cofront;                /* (first: no load of the margin) */
  const double lo = lo_of(hb[i], p->m3[o + 1]);
  if (zh < lo && lo > 0) return false;          /* behind, certainly */
  bool same;
  const bool front = in_front_exact(p, k, o, i, j, &same);
  if (same) { *co = o; *cofront = front; }
  return front;
}

/* Where no tile is kept: face k over columns i0 .. i1 - 1 of row j (faces fb, bounds hb),
   from point i on, bounds zl, zh at i stepped by + za (one chain), the exact compare asked
   where the doubles do not decide (out of line: the call's saved registers stay off
   raster_hi's loop). plus: zl > 0 over the box (hi = zh, else max(zh, 0)). */
static __attribute__((noinline)) void
raster_hi_rest(const struct points *p, int k, int64_t j, int32_t *fb, double *hb, int32_t i,
               int32_t i1, double zl, double zh, double za, bool plus, struct coplane *cp)
{
  int co = cp->o;                               /* a face in face k's plane met so far */
  bool cofront = cp->front;                     /* and the exact compare's answer against it */
  for (; i < i1; i++, zl += za, zh += za) {
    if (!(zl > hb[i]) && !point_front(p, k, j, fb, hb, i, zh, &co, &cofront)) continue;
    fb[i] = k;
    hb[i] = plus || zh > 0 ? zh : 0;
  }
  cp->o = co;
  cp->front = cofront;
}

/* raster_hi_rest's points where the doubles decide (zl > hi: in front; behind for
   certain, "One bound"), from the first the exact compare must decide on handed to it. */
static inline __attribute__((always_inline)) void
raster_hi(const struct points *p, int k, int64_t j, int32_t *fb, double *hb, int32_t i0,
          int32_t i1, double zl, double zh, double za, bool plus, struct coplane *cp)
{
  for (int32_t i = i0; i < i1; i++, zl += za, zh += za) {
    if (__builtin_expect(!(zl > hb[i]), 0)) {
      const double lo = lo_of(hb[i], p->m3[fb[i] + 1]);
      if (zh < lo && lo > 0) continue;          /* behind, certainly */
      raster_hi_rest(p, k, j, fb, hb, i, i1, zl, zh, za, plus, cp);
      return;
    }
    fb[i] = k;
    hb[i] = plus || zh > 0 ? zh : 0;
  }
}

#ifdef __SSE2__
/* raster_hi for a face with zl > 0 over its box, two points a step: V = (zl, zl + za) the
   lower bounds of points i and i + 1, H = (zh, zh + za) the upper, each lane stepped by
   2 za (exact: a doubling) so that a point does not wait on the addition of the point
   before ("Float filter", two chains); both points taken at once where both lower bounds
   are above the points' hi (one compare of two lanes), or where each is in front or
   behind for certain; from the first pair where one is neither, raster_hi_rest, in one
   chain from the pair's first point (its t-th point from the span's start met at most t
   additions, za's error t times: the bound holds, "Float filter"). */
static inline __attribute__((always_inline)) void
raster_plain(const struct points *p, int k, int64_t j, int32_t *fb, double *hb, int32_t i0,
             int32_t i1, double zl, double zh, double za, struct coplane *cp)
{
  const __m128d dv = _mm_set1_pd(za), dv2 = _mm_add_pd(dv, dv);   /* 2 za: exact */
  __m128d V = _mm_add_pd(_mm_set1_pd(zl), _mm_set_pd(za, 0));   /* (zl, zl + za) */
  __m128d H = _mm_add_pd(_mm_set1_pd(zh), _mm_set_pd(za, 0));
  const __m128i kk = _mm_set1_epi32(k);
  const double *const m3 = p->m3 + 1;
  int32_t i = i0;
  for (; i + 1 < i1; i += 2, V = _mm_add_pd(V, dv2), H = _mm_add_pd(H, dv2)) {
    const __m128d h = _mm_loadu_pd(hb + i);
    const int f = _mm_movemask_pd(_mm_cmpgt_pd(V, h));   /* in front: zl > hi */
    if (__builtin_expect(f != 3, 0)) {
      /* behind for certain: zh < lo_of(hi, m_o) (> 0 then, as zh > zl > 0), where the
         face seen is one (-1: m3[-1], 0, with hi -inf; such a lane is in front) */
      const __m128d lo = _mm_sub_pd(h, _mm_set_pd(m3[fb[i + 1]], m3[fb[i]]));
      const int b = _mm_movemask_pd(_mm_cmplt_pd(H, lo));
      if ((f | b) != 3) {                       /* the exact compare, at one of the two */
        raster_hi_rest(p, k, j, fb, hb, i, i1, _mm_cvtsd_f64(V), _mm_cvtsd_f64(H), za, true,
                       cp);
        return;
      }
      if (f) {                                  /* one in front, the other behind */
        const int l = f >> 1;
        fb[i + l] = k;
        hb[i + l] = _mm_cvtsd_f64(l ? _mm_unpackhi_pd(H, H) : H);
      }
      continue;
    }
    _mm_storel_epi64((__m128i *)(void *)(fb + i), kk);
    _mm_storeu_pd(hb + i, H);
  }
  if (i < i1) {                                 /* the last point: lane 0 */
    if (!(_mm_cvtsd_f64(V) > hb[i])) {
      raster_hi_rest(p, k, j, fb, hb, i, i1, _mm_cvtsd_f64(V), _mm_cvtsd_f64(H), za, true,
                     cp);
      return;
    }
    fb[i] = k;
    hb[i] = _mm_cvtsd_f64(H);
  }
}
#endif

/* Points i0 .. i1 - 1 of a row where no tile is kept (faces fb, bounds hb) set to nothing
   seen: face -1, hi -inf. */
static void points_none(int32_t *fb, double *hb, int32_t i0, int32_t i1)
{
  for (int32_t i = i0; i < i1; i++) {
    fb[i] = -1;
    hb[i] = -HUGE_VAL;
  }
}

/* Row j's columns [i0, i1) made to hold a face and bounds where no tile is kept
   ("Clearing"): those of them outside the row's ready columns set to nothing seen (face -1,
   hi -inf), the ready columns grown to take them in. True: nothing is seen at any of
   [i0, i1) (the row had no ready column, or [i0, i1) lies beside its ready columns, which
   then take in it and the columns between, those cleared): [i0, i1) is left untouched,
   for the caller to write as raster_fresh does. */
static inline bool row_ready(struct points *p, const struct grid *g, int64_t j, int32_t i0,
                             int32_t i1)
{
  int32_t *r = p->ready + 2 * j;
  const int32_t a = r[0], e = r[1];
  if (a >= e) {
    r[0] = i0;
    r[1] = i1;
    return true;
  }
  const size_t row = (size_t)j * (size_t)g->W;
  if (i1 <= a) {                                /* left of them: the gap between cleared */
    points_none(p->face + row, p->zhi + row, i1, a);
    r[0] = i0;
    return true;
  }
  if (i0 >= e) {                                /* right of them */
    points_none(p->face + row, p->zhi + row, e, i0);
    r[1] = i1;
    return true;
  }
  if (i0 < a) {
    points_none(p->face + row, p->zhi + row, i0, a);
    r[0] = i0;
  }
  if (i1 > e) {
    points_none(p->face + row, p->zhi + row, e, i1);
    r[1] = i1;
  }
  return false;
}

/* Face k over columns i0 .. i1 - 1 of row j (faces fb, bounds hb) where nothing is seen
   yet (row_ready's true): taken at every point, as the compare takes it there (zl is a
   finite double, > hi = -inf), with the hi raster_hi and raster_plain store (zh stepped
   by + za as they step it: the same values); nothing read. */
static inline __attribute__((always_inline)) void
raster_fresh(int k, int32_t *fb, double *hb, int32_t i0, int32_t i1, double zh, double za,
             bool plus)
{
#ifdef __SSE2__
  if (plus) {                                   /* in raster_plain's two chains */
    const __m128d dv2 = _mm_set1_pd(za + za);
    __m128d H = _mm_add_pd(_mm_set1_pd(zh), _mm_set_pd(za, 0));
    const __m128i kk = _mm_set1_epi32(k);
    int32_t i = i0;
    /* four points a step while four are left: the faces in one 16-byte store, the bounds
       of the two pairs in two (the second pair H + 2 za, the next step's first that + 2 za:
       the pairs, bit for bit, the loop below steps to); where the span is written fresh it
       is often long (a face over rows no face reached yet), and its time went to waiting
       on the stores (3 stores for 4 points here, 4 below) */
    for (; i + 3 < i1; i += 4) {
      const __m128d H2 = _mm_add_pd(H, dv2);
      _mm_storeu_si128((__m128i *)(void *)(fb + i), kk);
      _mm_storeu_pd(hb + i, H);
      _mm_storeu_pd(hb + i + 2, H2);
      H = _mm_add_pd(H2, dv2);
    }
    for (; i + 1 < i1; i += 2, H = _mm_add_pd(H, dv2)) {
      _mm_storel_epi64((__m128i *)(void *)(fb + i), kk);
      _mm_storeu_pd(hb + i, H);
    }
    if (i < i1) {
      fb[i] = k;
      hb[i] = _mm_cvtsd_f64(H);
    }
    return;
  }
#endif
  for (int32_t i = i0; i < i1; i++, zh += za) {
    fb[i] = k;
    hb[i] = plus || zh > 0 ? zh : 0;
  }
}

/* Face k's write at point i of row j (faces fb, bounds lb, hb; trow: the row's tiles) where
   it is in front, with the tiles kept: the face, its bounds lo and hi, and the tile's
   bounds kept ("Tiles"); was: the point's lo before. */
static inline __attribute__((always_inline)) void
raster_take(int k, int32_t i, int32_t *fb, struct points_z *zb, double zl, double zh,
            double was, bool plus, struct points_tile *trow)
{
  fb[i] = k;
  double lo;
  if (plus) {
    zb[i].hi = zh;
    lo = zl;
  } else {
    zb[i].hi = zh > 0 ? zh : 0;
    lo = zl > 0 ? zl : -HUGE_VAL;
  }
  if (!trow) { zb[i].lo = lo; return; }        /* (never: kept for the loop's place, below) */
  struct points_tile *T = trow + (i >> TILE_SHIFT);
  const int dn = (!plus && lo == -HUGE_VAL) - (was == -HUGE_VAL);   /* plus: lo = zl > 0 */
  T->ninf += dn;                                /* (no branch: where it is not 0 is unguessable) */
  zb[i].lo = lo;
  /* the bound lowered to lo, or marked when the least may have risen; no branch */
  const double tl = T->lo;
  T->lo = lo < tl ? lo : tl;
  T->dirty |= !(lo < tl) & (was <= tl);
}

/* raster_span's points from i on with the tiles kept (zl, zh their bounds at i), the exact
   compare asked where the doubles do not decide (out of line: the call's saved registers
   stay off raster_loop's loop). */
static __attribute__((noinline)) void
raster_span_rest(const struct points *p, int k, int64_t j, int32_t *fb, struct points_z *zb,
                 int32_t i, int32_t i1, double zl, double zh, double za, bool plus,
                 struct points_tile *trow, struct coplane *cp)
{
  int co = cp->o;                               /* a face in face k's plane met so far */
  bool cofront = cp->front;                     /* and the exact compare's answer against it */
  for (; i < i1; i++, zl += za, zh += za) {
    const double was = zb[i].lo;
    if (!(zl > zb[i].hi)) {
      if (zh < was) continue;                   /* behind, certainly */
      int o = fb[i];
      bool front = cofront, same;
      if (o != co) {
        front = in_front_exact(p, k, o, i, j, &same);
        if (same) { co = o; cofront = front; }
      }
      if (!front) continue;
    }
    raster_take(k, i, fb, zb, zl, zh, was, plus, trow);
  }
  cp->o = co;
  cp->front = cofront;
}

/* raster_span's loop with the tiles kept: the points the doubles decide (zl > hi: in
   front; zh < lo: behind) here; from the first the exact compare must decide on,
   raster_span_rest. */
static inline __attribute__((always_inline)) void
raster_loop(const struct points *p, int k, int64_t j, int32_t *fb, struct points_z *zb,
            int32_t i0, int32_t i1, double zl, double zh, double za, bool plus,
            struct points_tile *trow, struct coplane *cp)
{
  for (int32_t i = i0; i < i1; i++, zl += za, zh += za) {
    const double was = zb[i].lo;
    if (__builtin_expect(!(zl > zb[i].hi), 0)) {
      if (zh < was) continue;                   /* behind, certainly */
      raster_span_rest(p, k, j, fb, zb, i, i1, zl, zh, za, plus, trow, cp);
      return;
    }
    raster_take(k, i, fb, zb, zl, zh, was, plus, trow);
  }
}

/* raster_loop with the tiles kept, for zl > 0 over the box and not: out of line and on a
   64-byte boundary, so that where the loop lies does not move with the code around it
   (its speed on tris160 changed by a quarter with a 16-byte shift; raster_take's test of
   trow, never NULL here, keeps the loop 8 bytes on: without it, tris160's points engine
   took a fifth longer). */
static __attribute__((noinline, aligned(64))) void
raster_tiles_plus(const struct points *p, int k, int64_t j, int32_t *fb, struct points_z *zb,
                  int32_t i0, int32_t i1, double zl, double zh, double za,
                  struct points_tile *trow, struct coplane *cp)
{
  raster_loop(p, k, j, fb, zb, i0, i1, zl, zh, za, true, trow, cp);
}

static __attribute__((noinline, aligned(64))) void
raster_tiles_any(const struct points *p, int k, int64_t j, int32_t *fb, struct points_z *zb,
                 int32_t i0, int32_t i1, double zl, double zh, double za,
                 struct points_tile *trow, struct coplane *cp)
{
  raster_loop(p, k, j, fb, zb, i0, i1, zl, zh, za, false, trow, cp);
}

/* Face k over the columns i0 .. i1 - 1 of row j: zl, zh its bounds at i0, stepped by za
   (see the top of the file). `plus`: zl > 0 at every point of the face's box (so are zh
   and max(zh, 0)), as the caller proved. trow: row j's tiles, whose bounds are kept
   ("Tiles"); NULL when no face of the frame asks them (none is drawn with their tests):
   then only hi is kept ("One bound"). cp: face k's coplane, kept while it is drawn. */
static inline __attribute__((always_inline)) void
raster_span(struct points *p, const struct grid *g, int k, int64_t j, int32_t i0, int32_t i1,
            double zl, double zh, double za, bool plus, struct points_tile *trow,
            struct coplane *cp)
{
  p->points_visited += i1 - i0;
  size_t row = (size_t)j * (size_t)g->W;
  int32_t *fb = p->face + row;
  if (trow) {
    if (plus) raster_tiles_plus(p, k, j, fb, p->z + row, i0, i1, zl, zh, za, trow, cp);
    else raster_tiles_any(p, k, j, fb, p->z + row, i0, i1, zl, zh, za, trow, cp);
    return;
  }
  double *hb = p->zhi + row;
  if (g->lazy && row_ready(p, g, j, i0, i1)) {  /* nothing seen there yet */
    raster_fresh(k, fb, hb, i0, i1, zh, za, plus);
    return;
  }
#ifdef __SSE2__
  if (plus) {
    raster_plain(p, k, j, fb, hb, i0, i1, zl, zh, za, cp);
    return;
  }
#endif
  raster_hi(p, k, j, fb, hb, i0, i1, zl, zh, za, plus, cp);
}
/* *d = v as two 64-bit stores, from the two registers a 128-bit product leaves (gcc,
   given `*d = v`, kept the product on the stack a half at a time and copied it out with one
   16-byte load: a load no store forwards to, which waits until both halves are written). */
static inline void wide_put(wide *d, wide v)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  const uint64_t lo = (uint64_t)v, hi = (uint64_t)((unsigned __int128)v >> 64);
  memcpy((char *)d, &lo, sizeof lo);
  memcpy((char *)d + sizeof lo, &hi, sizeof hi);
#else
  *d = v;
#endif
}

/* Face k's box of points and depth in doubles, its plane's exact P kept in p->plane[k];
   false: the box holds no point centre (the face is culled). */
static bool face_box(struct points *p, const struct grid *g, int k, struct points_box *b)
{
  const struct mface *f = &p->map.f[k];
  const int n = f->ring_start[f->nring];
  /* the vertices' rows and columns ("Vertices"): row_q falls and the first column at or
     right rises as y and x grow, so row_q(ymax) is the least of the vertices' row_q and
     row_q(ymin) the greatest, the column of xmin the least and of xmax the greatest (of
     the clamped numbers: the clamped least and greatest) */
  const int32_t *const vrc = p->vrc;
  const int32_t *const vix = f->vix;
  int32_t qmin = vrc[2 * vix[0]], qmax = qmin, cmin = vrc[2 * vix[0] + 1], cmax = cmin;
  int v = 1;
  if (n == 3) {                                 /* a triangle (the common face): no loop */
    const int32_t q1 = vrc[2 * vix[1]], c1 = vrc[2 * vix[1] + 1];
    const int32_t q2 = vrc[2 * vix[2]], c2 = vrc[2 * vix[2] + 1];
    const int32_t ql = q1 < q2 ? q1 : q2, qh = q1 < q2 ? q2 : q1;
    const int32_t cl = c1 < c2 ? c1 : c2, ch = c1 < c2 ? c2 : c1;
    qmin = ql < qmin ? ql : qmin;
    qmax = qh > qmax ? qh : qmax;
    cmin = cl < cmin ? cl : cmin;
    cmax = ch > cmax ? ch : cmax;
    v = 3;                                      /* (the loop below: none left) */
  }
  for (; v < n; v++) {
    const int32_t q = vrc[2 * vix[v]], c = vrc[2 * vix[v] + 1];
    qmin = q < qmin ? q : qmin;
    qmax = q > qmax ? q : qmax;
    cmin = c < cmin ? c : cmin;
    cmax = c > cmax ? c : cmax;
  }
  int64_t jlo = rows_below(qmin), jhi = rows_at_or_above(qmax);
  if (jlo < 0) jlo = 0;
  if (jhi > g->H - 1) jhi = g->H - 1;
  int64_t ilo = cmin, ihi = cmax;
  b->inside = ilo >= 0 && ihi <= g->W;
  if (ilo < 0) ilo = 0;
  if (ihi > g->W) ihi = g->W;
  if (jlo > jhi || ilo >= ihi) return false;
  b->ilo = (int32_t)ilo; b->ihi = (int32_t)ihi; b->jlo = (int32_t)jlo; b->jhi = (int32_t)jhi;
  /* depth: P = alpha i + beta j + gamma exactly (kept for the exact compare), z = P / D
     in doubles with its error bound E (the filter, see the top of the file) */
  const wide a = f->plane[0], bb = f->plane[1], c = f->plane[2];
  const int64_t ca = g->ca, cb = g->cb;
  struct points_plane *pl = &p->plane[k];
  /* each one 64 x 64-bit product (-cb fits 64 bits): the same integers as a ca and
     -(bb cb), without a 128-bit negate and a 128 x 128-bit multiply */
  const wide alpha = (wide)f->plane[0] * ca, beta = (wide)f->plane[1] * -cb;
  wide_put(&pl->alpha, alpha);
  wide_put(&pl->beta, beta);
  wide gamma;
  if (g->g64)                                      /* the grid's factors found once (exact) */
    gamma = (wide)f->plane[0] * g->ga64 + (wide)f->plane[1] * g->gb64 +
            (wide)f->plane[2] * g->gc64;          /* 64 x 64 bits: a multiply each */
  else
    gamma = a * g->ga + bb * g->gb + c * g->gc;
  wide_put(&pl->gamma, gamma);
  const double Dd = (double)f->deye;
  const double Ad = (double)f->plane[0] * g->cad, Bd = -(double)f->plane[1] * g->cbd,
               Gd = gamma == (int64_t)gamma ? (double)(int64_t)gamma  /* same value */
                                            : (double)gamma;
  b->za = Ad / Dd;
  b->zb = Bd / Dd;
  b->zc = Gd / Dd;
  b->E = Z_MARGIN * ((fabs(Ad) * g->Wd + fabs(Bd) * g->Hd + fabs(Gd)) / Dd);
  b->arise = alpha > 0;
  b->brise = beta > 0;
  /* z > 2E over the box: z is least at a corner, where its double (computed as z0 is,
     error < 11uM < E) is > 4E; so zl > z - 2E > 0 at every point */
  /* (the corner's column and row by masks, not branches: the signs of alpha and beta
     follow no pattern from face to face that the predictor learns, as round the globe) */
  const int64_t ma = -(int64_t)b->arise, mb = -(int64_t)b->brise;
  const int64_t ic = (ihi - 1) ^ ((ilo ^ (ihi - 1)) & ma), jc = jhi ^ ((jlo ^ jhi) & mb);
  const double zmin = b->za * (double)ic + (b->zb * (double)jc + b->zc);
  b->plus = zmin > 4 * b->E;
  p->m3[k + 1] = 3 * b->E;                        /* "One bound" */
  return true;
}

/* Face k's key for the nearest-first order: z at its nearest vertex (z is linear: its
   greatest over the face), at the vertex's place (i, j) in point units, in doubles (only
   the order depends on it). */
static double face_key(const struct points *p, const struct grid *g, int k,
                       const struct points_box *b)
{
  const struct mface *f = &p->map.f[k];
  double best = -HUGE_VAL;
  for (int v = 0; v < f->ring_start[f->nring]; v++) {
    const double z = b->za * (g->i0 + g->ki * (double)f->pt[v].x) +
                     (b->zb * (g->j0 - g->kj * (double)f->pt[v].y) + b->zc);
    best = z > best ? z : best;                 /* (a select: which vertex is nearest
                                                   is anyone's guess; no NaN here) */
  }
  return best;
}

/* Tile (tx, ty)'s bound made exact: the least lo of its points (all finite). */
static void tile_least(struct points *p, const struct grid *g, struct points_tile *T, int tx,
                       int ty)
{
  int i0 = tx << TILE_SHIFT, i1 = i0 + TILE, j0 = ty << TILE_SHIFT, j1 = j0 + TILE;
  if (i1 > g->W) i1 = g->W;
  if (j1 > g->H) j1 = g->H;
  /* two running minima, even and odd columns (the lo's are > 0 or -inf, no zeros and no
     NaN: the least is the same in any order) */
  double m0 = HUGE_VAL, m1 = HUGE_VAL;
  for (int j = j0; j < j1; j++) {
    const struct points_z *zb = p->z + (size_t)j * (size_t)g->W;
    int i = i0;
    for (; i + 1 < i1; i += 2) {
      m0 = zb[i].lo < m0 ? zb[i].lo : m0;
      m1 = zb[i + 1].lo < m1 ? zb[i + 1].lo : m1;
    }
    if (i < i1) m0 = zb[i].lo < m0 ? zb[i].lo : m0;
  }
  T->lo = m1 < m0 ? m1 : m0;
  T->dirty = false;
}

/* The tiles of band ty (columns tx0 .. tx1 of it, a bit each from tx0) where face b is
   proven behind the faces seen: zh_T below the tile's bound ("Tiles"); *nhid: how many.
   zh_T, the proven bound zh_T > z of face b at every point of its box within the tile, is
   fl(z0 + 2E) with z0 = za i + (zb j + zc) at the corner of the tile's part of the box
   where z is greatest; the row part zb j + zc is the band's, found once. */
static uint32_t band_hidden(struct points *p, const struct grid *g, const struct points_box *b,
                            int ty, int tx0, int tx1, int *nhid)
{
  const int ntx = (g->W + TILE - 1) >> TILE_SHIFT;
  struct points_tile *trow = p->tile + (size_t)ty * (size_t)ntx;
  int32_t j0 = ty << TILE_SHIFT, j1 = ((ty + 1) << TILE_SHIFT) - 1;
  if (j0 < b->jlo) j0 = b->jlo;
  if (j1 > b->jhi) j1 = b->jhi;
  const int32_t jc = j0 + ((j1 - j0) & -(int32_t)b->brise);  /* brise ? j1 : j0 */
  const int32_t off = (TILE - 1) & -(int32_t)b->arise;        /* arise ? TILE - 1 : 0 */
  const double zr = b->zb * (double)jc + b->zc, E2 = 2 * b->E;
  uint32_t hid = 0;
  int n = 0;
  /* each tile's answer without a branch (which tiles are hidden does not follow a pattern
     the predictor can learn); only a stale bound is asked for with one */
  for (int t = tx0; t <= tx1; t++) {
    struct points_tile *T = trow + t;
    /* the column of the greatest z: the tile's last (arise) or first, within the box
       (the tile's last is >= ilo, its first <= ihi - 1: the other clamp does nothing) */
    int32_t ic = (t << TILE_SHIFT) + off;
    ic = ic < b->ihi - 1 ? ic : b->ihi - 1;
    ic = ic > b->ilo ? ic : b->ilo;
    const double h = (b->za * (double)ic + zr) + E2;
    const unsigned full = !T->ninf;
    if (full & !(h < T->lo) & T->dirty) tile_least(p, g, T, t, ty);
    const unsigned yes = full & (h < T->lo);
    hid |= yes << (t - tx0);
    n += (int)yes;
  }
  *nhid = n;
  return hid;
}

/* A band's answer from band_hidden, kept for face_draw: the tiles hidden and how many. */
struct points_band {
  uint32_t hid;
  int n;
};

#define BANDS_KEPT 16                       /* bands of a box kept (the grid has at most 13) */

/* Is face b proven behind at every tile of its box? The bands asked, from the box's first,
   are kept in band[0 .. *nband) (at most BANDS_KEPT): the tiles a band's test finds
   hold until face b writes in that band ("Tiles"), so face_draw takes them as they are. */
static bool face_hidden(struct points *p, const struct grid *g, const struct points_box *b,
                        struct points_band *band, int *nband)
{
  const int tx0 = b->ilo >> TILE_SHIFT, tx1 = (b->ihi - 1) >> TILE_SHIFT;
  const uint32_t all = (uint32_t)((UINT64_C(1) << (tx1 - tx0 + 1)) - 1);
  *nband = 0;
  for (int ty = b->jlo >> TILE_SHIFT; ty <= b->jhi >> TILE_SHIFT; ty++) {
    int n;
    const uint32_t hid = band_hidden(p, g, b, ty, tx0, tx1, &n);
    if (*nband < BANDS_KEPT) band[(*nband)++] = (struct points_band){ hid, n };
    if (hid != all) return false;
  }
  p->tiles_skipped += (long)((b->jhi >> TILE_SHIFT) - (b->jlo >> TILE_SHIFT) + 1) * (tx1 - tx0 + 1);
  return true;
}

/* Face k (box b) over the columns i0 .. i1 - 1 of row j (zr = zb j + zc), the parts over
   the tiles in hid (bits from tile tx0) left out: each part's bounds z0 -+ E at its first
   point, z0 = za a + zr ("Float filter"). trow: row j's tiles, their bounds kept (NULL:
   none kept; then hid is 0). */
static inline __attribute__((always_inline)) void
span_parts(struct points *p, const struct grid *g, int k, const struct points_box *b, int64_t j,
           int32_t i0, int32_t i1, double zr, uint32_t hid, int tx0, struct points_tile *trow,
           struct coplane *cp)
{
  const double za = b->za, E = b->E;
  int32_t a = i0;                               /* the span's parts over tiles not hidden */
  /* the span's tiles t0 .. t1 that are hidden, a bit each from t0 (t1 - t0 <= tx1 - tx0
     < 17), taken a run of neighbours at a time: within a run, a tile after the first
     starts where the one before ends, so only the run's first can leave a part before it */
  const int t0 = i0 >> TILE_SHIFT, t1 = (i1 - 1) >> TILE_SHIFT;
  uint32_t m = (hid >> (t0 - tx0)) & ((2u << (t1 - t0)) - 1);
  if (m) {
    do {
      const int rs = __builtin_ctz(m), re = rs + __builtin_ctz(~(m >> rs));   /* [rs, re) */
      m &= ~((2u << (re - 1)) - 1);
      int32_t ts = (t0 + rs) << TILE_SHIFT, te = (t0 + re) << TILE_SHIFT;
      if (ts > a) {                             /* (hid: the tiles are kept) */
        const double z0 = za * (double)a + zr;
        if (b->plus) raster_span(p, g, k, j, a, ts, z0 - E, z0 + E, za, true, trow, cp);
        else raster_span(p, g, k, j, a, ts, z0 - E, z0 + E, za, false, trow, cp);
      }
      a = te < i1 ? te : i1;
    } while (m);
    if (a >= i1) return;
  }
  const double z0 = za * (double)a + zr;
  if (!trow) {
    if (b->plus) raster_span(p, g, k, j, a, i1, z0 - E, z0 + E, za, true, NULL, cp);
    else raster_span(p, g, k, j, a, i1, z0 - E, z0 + E, za, false, NULL, cp);
  } else if (b->plus) raster_span(p, g, k, j, a, i1, z0 - E, z0 + E, za, true, trow, cp);
  else raster_span(p, g, k, j, a, i1, z0 - E, z0 + E, za, false, trow, cp);
}

/* Does face k (box b) cover a point centre of its box's middle row? (*yes; no says
   nothing of the other rows.) The row's crossings as face_draw finds them. */
static int covers_middle(struct points *p, const struct grid *g, int k, const struct points_box *b,
                         bool *yes, struct t74_error *err)
{
  const int64_t jm = (b->jlo + b->jhi) / 2;
  int ne;
  bool monotone;
  int st = face_edges(p, g, &p->map.f[k], jm, jm, &ne, &monotone, err);
  if (st != T74_OK) return st;
  if (!t74_grow((void **)&p->cross, &p->crosscap, ne + 1, sizeof *p->cross))
    return t74_fail(err, T74_EIO, "out of host memory");
  int32_t *cs = p->cross;
  for (int e = 0; e < ne; e++) {                /* insertion sort */
    int32_t v = col_of(g, p->edge[e].c);
    int y = e - 1;
    while (y >= 0 && cs[y] > v) { cs[y + 1] = cs[y]; y--; }
    cs[y + 1] = v;
  }
  *yes = false;
  for (int x = 0; x + 1 < ne; x += 2) *yes = *yes || cs[x] < cs[x + 1];
  return T74_OK;
}

/* The faces fb and bounds zb of a row's span between the columns x[0] and x[1] (either
   first) asked of the memory ahead of their writes: they are seldom in the first-level
   cache, as the stages after the points engine go through much more memory from frame
   to frame, and a write that misses waits for its line. Not for a span of fewer than
   PREFETCH_MIN points: there the asking costs more than it saves (street, whose faces
   are small, was 2.5% slower with it; fig6-room, whose faces are large, 3% faster).
   Sixteen points a step, the bounds' two lines and the faces' one in one loop (round
   42: two loops, one a buffer, had two exits a span that the predictor misses, for
   lengths that change from row to row; one loop, sphere, t1-g, t1-h, street, fig6-room
   1.7 to 3.3% faster in turn). The second bounds line only while it is in the span (a
   select: no pointer past the buffer). */
#define PREFETCH_MIN 16
static inline void span_prefetch(const int32_t *fb, const double *hb, const int32_t *x)
{
  const int32_t a = x[0] < x[1] ? x[0] : x[1], e = x[0] < x[1] ? x[1] : x[0];
  if (e - a < PREFETCH_MIN) return;
  for (int32_t i = a; i < e; i += 16) {
    const int32_t i8 = i + 8 < e ? i + 8 : i;
    __builtin_prefetch(hb + i, 1);              /* 8 a line */
    __builtin_prefetch(hb + i8, 1);
    __builtin_prefetch(fb + i, 1);              /* 16 a line */
  }
}

#ifdef __SSE2__
/* face_draw's rows of face k (box b, rows jlo .. jlo + nrow - 1, two crossings a row at
   p->cross) where no tile is kept and zl > 0 over the box: span_parts' steps without its
   tests (out of line: the paths with the tiles keep their own registers). */
static __attribute__((noinline)) void draw_plain(struct points *p, const struct grid *g, int k,
                                                 const struct points_box *b, int64_t jlo,
                                                 int nrow, struct coplane *cp)
{
  const double za = b->za, zb = b->zb, zc = b->zc, E = b->E;
  const size_t W = (size_t)g->W;
  const bool lazy = g->lazy;                    /* (kept in registers: the calls and the
                                                   stores below would have them read again) */
  const int32_t *const cross = p->cross;
  int32_t *fb = p->face + (size_t)jlo * W;
  double *zrow = p->zhi + (size_t)jlo * W;
  long visited = 0;
  span_prefetch(fb, zrow, cross);
  double dj = (double)jlo;                      /* j as a double: + 1 a row is exact */
  for (int r = 0; r < nrow; r++, fb += W, zrow += W, dj += 1) {
    int32_t i0 = cross[2 * r], i1 = cross[2 * r + 1];
    const int32_t c0 = i0, c1 = i1;             /* the smaller first (no branch) */
    i0 = c0 < c1 ? c0 : c1;
    i1 = c0 < c1 ? c1 : c0;
    if (i0 >= i1) continue;
    visited += i1 - i0;
    const int64_t j = jlo + r;
    if (r + 1 < nrow)                           /* the next row's span asked for ahead */
      span_prefetch(fb + W, zrow + W, cross + 2 * r + 2);
    const double z0 = za * (double)i0 + (zb * dj + zc);
    if (lazy && row_ready(p, g, j, i0, i1))     /* nothing seen there yet */
      raster_fresh(k, fb, zrow, i0, i1, z0 + E, za, true);
    else
      raster_plain(p, k, j, fb, zrow, i0, i1, z0 - E, z0 + E, za, cp);
  }
  p->points_visited += visited;
  if (!visited) p->faces_culled++;
}
#endif

/* Face k, its box b, into the buffer: by exact scanline crossings, each span's part over a
   tile skipped when the tile's bound proves the face behind there (coarse, "Tiles"). tiles:
   the tiles' bounds are kept (some face of the frame is drawn coarse; always when this one
   is). band[0 .. nband): the first bands' tests, made by face_hidden before k is drawn. */
static int face_draw(struct points *p, const struct grid *g, int k, const struct points_box *b,
                     bool coarse, bool tiles, const struct points_band *band, int nband,
                     struct t74_error *err)
{
  const struct mface *f = &p->map.f[k];
  const int64_t jlo = b->jlo, jhi = b->jhi;
  struct coplane cp = { -1, false };            /* (raster_plain_rest, raster_span_rest) */
  int ne;
  bool two;                                     /* two crossings a row ("Two crossings") */
  int st = face_edges(p, g, f, jlo, jhi, &ne, &two, err);
  if (st != T74_OK) return st;
  int nrow = (int)(jhi - jlo + 1);
  if (!t74_grow((void **)&p->rowcount, &p->rowcap, nrow + 1, sizeof *p->rowcount))
    return t74_fail(err, T74_EIO, "out of host memory");
  int *rc = p->rowcount;
  if (!two) {                                   /* (two: row r at cross[2r] (up), cross[2r + 1]) */
    memset(rc, 0, (size_t)(nrow + 1) * sizeof *rc);
    for (int e = 0; e < ne; e++)
      for (int32_t j = p->edge[e].jtop; j <= p->edge[e].jbot; j++) rc[j - jlo + 1]++;
    for (int r = 0; r < nrow; r++) rc[r + 1] += rc[r];
  }
  if (!t74_grow((void **)&p->cross, &p->crosscap, (two ? 2 * nrow : rc[nrow]) + 1, sizeof *p->cross))
    return t74_fail(err, T74_EIO, "out of host memory");
  /* fill: rc[r] is the next free slot of row r (rc[r] ends as row r+1's start); with two
     a row, the up edges' crossings at even slots, the others' at odd */
  for (int e = 0; e < ne; e++) {
    struct points_edge *E = &p->edge[e];
    int64_t c = E->c, sc = E->s;
    const int32_t jtop = E->jtop;
    if (two && b->inside) {
      /* a crossing's x lies between the face's least and greatest x, and the first
         column at or right of an x does not fall as x grows: its column, floor(c / 2),
         is within the box's [ilo, ihi] before the grid cuts it, here within [0, W], so
         col_of's clamps change nothing (and c >= 0) */
      edge_rows(g, E, c, sc, p->cross + 2 * (E->jbot - jlo) + !E->up, true);
      continue;
    }
    if (two) {
      edge_rows(g, E, c, sc, p->cross + 2 * (E->jbot - jlo) + !E->up, false);
      continue;
    }
    for (int32_t j = E->jbot;; j--) {
      p->cross[rc[j - jlo]++] = col_of(g, c);
      if (j == jtop) break;
      edge_step(E, &c, &sc);
    }
  }
  const double zb = b->zb, zc = b->zc;
  const int ntx = (g->W + TILE - 1) >> TILE_SHIFT;
  const int tx0 = b->ilo >> TILE_SHIFT, tx1 = (b->ihi - 1) >> TILE_SHIFT;
  const uint32_t all = (uint32_t)((UINT64_C(1) << (tx1 - tx0 + 1)) - 1);
  uint32_t hid = 0;                             /* the band's tiles where face k is behind */
  int tyat = -1;
  bool any = false;
#ifdef __SSE2__
  if (two && !coarse && !tiles && b->plus) {    /* span_parts' steps, no tile, zl > 0 */
    draw_plain(p, g, k, b, jlo, nrow, &cp);
    return T74_OK;
  }
#endif
  if (two && !coarse) {                         /* a row: one span, often empty (slivers) */
    for (int r = 0; r < nrow; r++) {
      int32_t i0 = p->cross[2 * r], i1 = p->cross[2 * r + 1];
      const int32_t c0 = i0, c1 = i1;             /* the smaller first (no branch) */
      i0 = c0 < c1 ? c0 : c1;
      i1 = c0 < c1 ? c1 : c0;
      if (i0 >= i1) continue;
      any = true;
      const int64_t j = jlo + r;
      span_parts(p, g, k, b, j, i0, i1, zb * (double)j + zc, 0, tx0,   /* no tile skipped */
                 tiles ? p->tile + (size_t)(j >> TILE_SHIFT) * (size_t)ntx : NULL, &cp);
    }
    if (!any) p->faces_culled++;
    return T74_OK;
  }
  int start = 0;                                /* coarse, or not two crossings a row */
  for (int r = 0; r < nrow; r++) {
    int64_t j = jlo + r;
    const int ty = (int)(j >> TILE_SHIFT);
    struct points_tile *trow = tiles ? p->tile + (size_t)ty * (size_t)ntx : NULL;
    if (coarse && ty != tyat) {                 /* a new band of tiles */
      const int nb = ty - (b->jlo >> TILE_SHIFT);
      int nhid;
      if (nb < nband) {                         /* face_hidden's answer */
        hid = band[nb].hid;
        nhid = band[nb].n;
      } else {
        hid = band_hidden(p, g, b, ty, tx0, tx1, &nhid);
      }
      p->tiles_skipped += nhid;
      tyat = ty;
    }
    if (two) {                                  /* one span, often empty (slivers) */
      if (hid == all && any) continue;          /* behind all along the band's rows */
      int32_t i0 = p->cross[2 * r], i1 = p->cross[2 * r + 1];
      const int32_t c0 = i0, c1 = i1;             /* the smaller first (no branch) */
      i0 = c0 < c1 ? c0 : c1;
      i1 = c0 < c1 ? c1 : c0;
      if (i0 >= i1) continue;
      any = true;
      const double zr = zb * (double)j + zc;
      span_parts(p, g, k, b, j, i0, i1, zr, hid, tx0, trow, &cp);
      continue;
    }
    int end = rc[r];                            /* row r: cross[start .. end) */
    int32_t *cs = p->cross + start;
    int m = end - start;
    start = end;
    if (hid == all && any) continue;            /* behind all along the band's rows */
    for (int x = 1; x < m; x++) {               /* insertion sort: rows hold few */
      int32_t v = cs[x];
      int y = x - 1;
      while (y >= 0 && cs[y] > v) { cs[y + 1] = cs[y]; y--; }
      cs[y + 1] = v;
    }
    const double zr = zb * (double)j + zc;
    for (int x = 0; x + 1 < m; x += 2) {
      int32_t i0 = cs[x], i1 = cs[x + 1];
      if (i0 >= i1) continue;
      any = true;
      span_parts(p, g, k, b, j, i0, i1, zr, hid, tx0, trow, &cp);
    }
  }
  if (!any) p->faces_culled++;
  return T74_OK;
}

static uint64_t splitmix(uint64_t *x)
{
  uint64_t z = (*x += UINT64_C(0x9e3779b97f4a7c15));
  z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
  z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
  return z ^ (z >> 31);
}

/* Does a pattern lie on a pattern in s? Then mface_coplanar_front is no order (three
   patterns can go round in a circle) and the faces are drawn in the Mapper's order. */
static bool pattern_chain(const struct scene *s)
{
  for (int k = 0; k < s->nf; k++)
    if (s->f[k].on_id && s->f[s->f[k].on].on_id) return true;
  return false;
}

/* p->order[0 .. n): the kept faces (p->box[0 .. n), their keys p->key) in drawing order:
   nearest first by buckets of their keys (a matter of speed only, "Order"), or shuffled
   by p->shuffle, or as they came. */
static int draw_order(struct points *p, const struct scene *s, int n, struct t74_error *err)
{
  if (n < 2 || pattern_chain(s)) return T74_OK;
  int *o = p->order;
  if (p->shuffle) {
    uint64_t x = p->shuffle;
    for (int k = n - 1; k > 0; k--) {
      int r = (int)(splitmix(&x) % (uint64_t)(k + 1)), t = o[k];
      o[k] = o[r];
      o[r] = t;
    }
    return T74_OK;
  }
  double kmin = p->key[0], kmax = kmin;
  for (int k = 1; k < n; k++) {
    if (p->key[k] < kmin) kmin = p->key[k];
    if (p->key[k] > kmax) kmax = p->key[k];
  }
  if (!(kmax > kmin)) return T74_OK;
  int nb = n < BUCKETS_MAX ? n : BUCKETS_MAX;
  const double scale = (nb - 1) / (kmax - kmin);
  if (!t74_grow((void **)&p->bucket, &p->bucketcap, nb + 1 + n, sizeof *p->bucket))
    return t74_fail(err, T74_EIO, "out of host memory");
  int *cnt = p->bucket, *out = p->bucket + nb + 1;
  memset(cnt, 0, (size_t)(nb + 1) * sizeof *cnt);
  for (int k = 0; k < n; k++) {             /* bucket 0 the nearest */
    const double t = (kmax - p->key[k]) * scale;
    int bk = t >= 0 ? (t < nb - 1 ? (int)t : nb - 1) : 0;
    p->key[k] = (double)bk;
    cnt[bk + 1]++;
  }
  for (int bk = 0; bk < nb; bk++) cnt[bk + 1] += cnt[bk];
  for (int k = 0; k < n; k++) out[cnt[(int)p->key[k]]++] = o[k];
  memcpy(o, out, (size_t)n * sizeof *o);
  return T74_OK;
}

/* p->order[0 .. n): the faces of p->box[0 .. n) farthest first (a painter's order), the
   order in which a lazy frame without tiles draws them ("Order": any order gives the same
   frame; which one is a matter of speed only; not with no_tiles, whose frame is the
   Mapper's order's, which tests hold the engine's to). Where a face comes after the faces it
   hides, each of its points is taken by raster_plain's first test (zl > hi), two points a
   compare; where it comes first, each point it hides of a later face is behind, known only
   after a second test that loads the face seen there and its margin, and the exact compare
   is asked more often where two faces meet. Measured on t1-g (12 faces, drawn as the
   Mapper gives them): 2,142 points a frame behind, 69 exact compares; in this order none,
   the frame's instructions -3.9%. The key is z at the box's centre in doubles (cheap;
   no bound is needed of it), ordered by draw_order's buckets (a key's sign turned: its
   nearest first is this farthest first). With p->shuffle (tests) the Mapper's order. */
static int paint_order(struct points *p, const struct scene *s, int n, struct t74_error *err)
{
  for (int d = 0; d < n; d++) {
    const struct points_box *b = &p->box[d];
    p->key[d] = -(b->za * (0.5 * (double)(b->ilo + b->ihi)) +
                  (b->zb * (0.5 * (double)(b->jlo + b->jhi)) + b->zc));
    p->order[d] = d;
  }
  return p->shuffle ? T74_OK : draw_order(p, s, n, err);
}

/* f[0 .. n) set to no face (-1), 16 bytes a store. Not by memset: the fills are
   many and mostly shorter than a row (the lazy frame's, about one a row), where the
   call's own work is a good part of the cost; gcc turns a memset (or this loop, without
   the empty asm) whose length it can bound into `rep stos`, slow to start, and the C
   library fills a block over 2 kB with `rep stosb` (valgrind counts either as an
   instruction a word or a byte). Measured against the memsets and memcpys it replaced
   (perf's samples, round 37): the points frame's clearing about 1% of the frame less on
   lprism, the sphere and t1-e. */
static void faces_none(int32_t *f, size_t n)
{
#ifdef __SSE2__
  if (n >= 4) {                                 /* the last four by one store, which may
                                                   overlap the ones before */
    const __m128i none = _mm_set1_epi32(-1);
    for (size_t i = 0; i + 8 <= n; i += 8) {
#ifdef __GNUC__
      __asm__("" : "+r"(i));
#endif
      _mm_storeu_si128((__m128i *)(void *)(f + i), none);
      _mm_storeu_si128((__m128i *)(void *)(f + i + 4), none);
    }
    if (n & 4) _mm_storeu_si128((__m128i *)(void *)(f + (n & ~(size_t)7)), none);
    _mm_storeu_si128((__m128i *)(void *)(f + n - 4), none);
    return;
  }
  if (n > 0) f[0] = -1;                         /* (not a loop: gcc makes one a memset) */
  if (n > 1) f[1] = -1;
  if (n > 2) f[2] = -1;
#else
  for (size_t i = 0; i < n; i++) f[i] = -1;
#endif
}

/* Row fb where a frame's ready columns were [wa, we) (none where wa >= we) and the row
   -1 outside them: the columns of [wa, we) outside [a, e) set to -1, and with both all of
   [a, e) as well (none where a >= e). */
static inline void faces_span_none(int32_t *fb, int32_t wa, int32_t we, int32_t a,
                                   int32_t e, bool both)
{
  if (both && a < e) faces_none(fb + a, (size_t)(e - a));
  if (wa >= we) return;                         /* the row all -1 already */
  if (a >= e) {                                 /* none now: all of [wa, we) */
    faces_none(fb + wa, (size_t)(we - wa));
    return;
  }
  if (wa < a) faces_none(fb + wa, (size_t)((we < a ? we : a) - wa));
  if (we > e) faces_none(fb + (wa > e ? wa : e), (size_t)(we - (wa > e ? wa : e)));
}

/* h[0 .. n) set to -inf (nothing seen), 16 bytes a store, as faces_none does (not a
   memcpy of a row cleared first, which reads each row as well as writing it). */
static void bounds_none(double *h, size_t n)
{
  size_t i = 0;
#ifdef __SSE2__
  const __m128d none = _mm_set1_pd(-HUGE_VAL);
  for (; i + 4 <= n; i += 4) {
#ifdef __GNUC__
    __asm__("" : "+r"(i));
#endif
    _mm_storeu_pd(h + i, none);
    _mm_storeu_pd(h + i + 2, none);
  }
#endif
  for (; i < n; i++) h[i] = -HUGE_VAL;
}

int points_render(struct points *p, const struct scene *s, const struct vis_grid *vg,
                  struct t74_error *err)
{
  if (vg->window[0] >= vg->window[2] || vg->window[1] >= vg->window[3])
    return t74_fail(err, T74_EINPUT, "%s: the window needs XL < XR and YB < YT", s->file);
  int st = map_faces(p, s, err);
  if (st != T74_OK) return st;
  size_t n = (size_t)vg->W * (size_t)vg->H;
  if (!p->face || p->W != vg->W || p->H != vg->H) {
    free(p->face);
    free(p->z);
    free(p->zhi);
    p->z = NULL;                                  /* (made when a frame needs it, below) */
    p->zhi = NULL;
    p->face = malloc((n ? n : 1) * sizeof *p->face);
    if (!p->face) return t74_fail(err, T74_EIO, "out of host memory");
    p->W = vg->W;
    p->H = vg->H;
    p->ready_kept = false;                        /* (a new buffer: nothing in it known) */
  }
  /* the last frame's ready columns, if known (cleared here: a frame that does not end
     whole, as on an error, leaves what it wrote unknown) */
  const bool kept = p->ready_kept;
  p->ready_kept = false;
  if (!t74_grow((void **)&p->plane, &p->planecap, p->map.nface + 1, sizeof *p->plane))
    return t74_fail(err, T74_EIO, "out of host memory");
  struct grid g;
  g.W = vg->W; g.H = vg->H;
  g.XL = vg->window[0]; g.YB = vg->window[1]; g.XR = vg->window[2]; g.YT = vg->window[3];
  g.xd = 2 * (int64_t)g.W;
  g.yd = 2 * (int64_t)g.H;
  g.S = GRID_ONE * (g.XR - g.XL);
  g.Dy = GRID_ONE * (g.YT - g.YB);
  g.Ex = p->map.eye[0]; g.Ey = p->map.eye[1]; g.Ez = p->map.eye[2];
  g.ga = 2 * (wide)g.H * (2 * g.W * (g.XL - g.Ex) + (g.XR - g.XL));
  g.gb = 2 * (wide)g.W * (2 * g.H * (g.YT - g.Ey) - (g.YT - g.YB));
  g.gc = 4 * (wide)g.W * g.H * (-g.Ez);
  g.g64 = g.ga == (int64_t)g.ga && g.gb == (int64_t)g.gb && g.gc == (int64_t)g.gc;
  g.ga64 = (int64_t)g.ga;                         /* (used only when g64) */
  g.gb64 = (int64_t)g.gb;
  g.gc64 = (int64_t)g.gc;
  g.ki = (double)g.xd / (2.0 * (double)GRID_ONE * (double)(g.XR - g.XL));
  g.kj = (double)g.yd / (2.0 * (double)GRID_ONE * (double)(g.YT - g.YB));
  g.i0 = -((double)g.xd * (double)g.XL / (double)(g.XR - g.XL) + 1) / 2;
  g.j0 = ((double)g.yd * (double)g.YT / (double)(g.YT - g.YB) - 1) / 2;
  g.dDy = divconst_make(g.Dy);                    /* (Dy, S >= GRID_ONE: >= 2) */
  g.dS = divconst_make(g.S);
  g.ytop = g.yd * (GRID_ONE * g.YT);
  g.xoff = GRID_ONE * g.XL;
  g.Syd = g.S * g.yd;
  g.dRx = 2 * g.xd * g.Dy;
  g.ca = 4 * (int64_t)g.H * (g.XR - g.XL);
  g.cb = 4 * (int64_t)g.W * (g.YT - g.YB);
  g.cad = (double)g.ca;
  g.cbd = (double)g.cb;
  g.Wd = (double)g.W;
  g.Hd = (double)g.H;
  if ((st = vertex_rows(p, s, &g, err)) != T74_OK) return st;
  p->faces_culled = 0;
  p->tiles_skipped = 0;
  p->points_visited = 0;
  int nf = p->map.nface;
  if (!t74_grow((void **)&p->m3, &p->m3cap, nf + 1, sizeof *p->m3))
    return t74_fail(err, T74_EIO, "out of host memory");
  p->m3[0] = 0;                                   /* (no face: hi -inf, "One bound") */
  if (!t74_grow((void **)&p->box, &p->boxcap, nf + 1, sizeof *p->box) ||
      !t74_grow((void **)&p->order, &p->ordercap, nf + 1, sizeof *p->order) ||
      !t74_grow((void **)&p->key, &p->keycap, nf + 1, sizeof *p->key))
    return t74_fail(err, T74_EIO, "out of host memory");
  const int ntx = (g.W + TILE - 1) >> TILE_SHIFT, nty = (g.H + TILE - 1) >> TILE_SHIFT;
  if (!t74_grow((void **)&p->tile, &p->tilecap, ntx * nty + 1, sizeof *p->tile))
    return t74_fail(err, T74_EIO, "out of host memory");
  /* The faces are drawn in the Mapper's order while their boxes cover the grid less than
     COARSE_DEPTH times over (there the tiles' tests and the order cost more than they
     save); the rest are kept, then drawn nearest first with the tiles (always all of
     them when asked to shuffle, none with no_tiles). The tiles' bounds are kept by every
     write, so they hold for the faces drawn either way ("Tiles", "Order"); where no face
     is left for the tiles (the boxes' whole area under the limit), none are kept. */
  long area = 0;
  const long limit = p->no_tiles || ntx > 32 ? LONG_MAX    /* a band's tiles: bits of 32 */
                    : p->shuffle ? 0 : COARSE_DEPTH * (long)g.W * g.H;
  int nb = 0;                                     /* faces with a box */
  int nfirst = 0;                                 /* of them the first nfirst: drawn in the
                                                     Mapper's order (the area before each
                                                     under the limit; area only grows) */
  for (int k = 0; k < nf; k++) {
    if (p->skip[k]) continue;
    struct points_box *b = &p->box[nb];
    if (!face_box(p, &g, k, b)) { p->faces_culled++; continue; }
    b->k = k;
    nb++;
    if (area < limit) {
      area += (long)(b->ihi - b->ilo) * (b->jhi - b->jlo + 1);
      nfirst++;
    }
  }
  const bool tiles = area >= limit;               /* a face is left for the tiles */
  for (int ty = 0; tiles && ty < nty; ty++)       /* (read only with the tiles: face_draw
                                                     is given none without them) */
    for (int tx = 0; tx < ntx; tx++) {
      int w = g.W - (tx << TILE_SHIFT), h = g.H - (ty << TILE_SHIFT);
      struct points_tile *T = &p->tile[ty * ntx + tx];
      T->lo = -HUGE_VAL;
      T->ninf = (w < TILE ? w : TILE) * (h < TILE ? h : TILE);
      T->dirty = true;
    }
  if (tiles && !p->z && !(p->z = malloc((n ? n : 1) * sizeof *p->z)))   /* (lo, hi) */
    return t74_fail(err, T74_EIO, "out of host memory");
  if (!tiles && !p->zhi && !(p->zhi = malloc((n ? n : 1) * sizeof *p->zhi)))   /* hi alone */
    return t74_fail(err, T74_EIO, "out of host memory");
  /* nothing seen yet. With the tiles, over the whole grid (their bounds are the least over
     whole tiles, and face_hidden may ask any); lazy, no row has a ready column: each span
     makes its columns ready as it comes (row_ready, "Clearing") and the faces of the
     columns no span made ready are set to -1 at the end (faces_none, bounds_none: why
     not memset) */
  /* (lazy only where the faces' boxes are LAZY_BOX points or more on the whole: a span's
     test of its row's ready columns is a branch no predictor guesses, which costs more
     than the clearing it saves where faces are small, as on the sphere and boxes1000) */
  g.lazy = !tiles && area >= LAZY_BOX * (long)nb;
  /* without the tiles: this frame's ready columns, then the last frame's (ready_kept) */
  if (!tiles &&
      !t74_grow((void **)&p->ready, &p->readycap, 4 * (size_t)g.H + 1, sizeof *p->ready))
    return t74_fail(err, T74_EIO, "out of host memory");
  if (g.lazy) {
    memset(p->ready, 0, (size_t)(2 * g.H) * sizeof *p->ready);
  } else {
    /* the depth bounds over every row with the tiles (lo and hi), else (hi only, "One
       bound") over the rows and columns of the faces' boxes, the only ones their spans
       visit (a span's columns lie in its face's box, [ilo, ihi), as its crossings lie
       between the face's least and greatest x and the first column at or right of an x
       does not fall as x grows) */
    int zj0 = tiles ? 0 : g.H, zj1 = tiles ? g.H - 1 : -1;
    int zi0 = tiles ? 0 : g.W, zi1 = tiles ? g.W : 0;
    for (int d = 0; !tiles && d < nb; d++) {
      zj0 = p->box[d].jlo < zj0 ? p->box[d].jlo : zj0;
      zj1 = p->box[d].jhi > zj1 ? p->box[d].jhi : zj1;
      zi0 = p->box[d].ilo < zi0 ? p->box[d].ilo : zi0;
      zi1 = p->box[d].ihi > zi1 ? p->box[d].ihi : zi1;
    }
    if (tiles) {
      for (int i = 0; i < g.W; i++) p->z[i].hi = p->z[i].lo = -HUGE_VAL;
      for (int j = 1; j < g.H; j++)               /* the other rows as the first */
        memcpy(p->z + (size_t)j * (size_t)g.W, p->z, (size_t)g.W * sizeof *p->z);
    } else if (zj0 <= zj1 && zi0 < zi1) {
      for (int j = zj0; j <= zj1; j++)
        bounds_none(p->zhi + (size_t)j * (size_t)g.W + (size_t)zi0, (size_t)(zi1 - zi0));
    }
    if (tiles) faces_none(p->face, n);
    else {
      /* the spans write faces only in the faces' boxes' rows and columns (above), so only
         there; with the last frame's ready columns known (kept, as a lazy frame leaves
         them), only those and this frame's box are set to -1, the other points -1
         already. This frame's box is kept as its ready columns, a row's the same [zi0,
         zi1) on the box's rows, none elsewhere. */
      if (!(zj0 <= zj1 && zi0 < zi1)) { zj0 = 0; zj1 = -1; zi0 = zi1 = 0; }   /* no box */
      int32_t *was = p->ready + 2 * (size_t)g.H;
      if (!kept) faces_none(p->face, n);
      for (int j = 0; j < g.H; j++) {
        const int32_t a = j >= zj0 && j <= zj1 ? zi0 : 0, e = j >= zj0 && j <= zj1 ? zi1 : 0;
        if (kept) faces_span_none(p->face + (size_t)j * (size_t)g.W, was[2 * j], was[2 * j + 1],
                                  a, e, true);
        was[2 * j] = a;
        was[2 * j + 1] = e;
      }
    }
  }
  const int *paint = NULL;                        /* the first nfirst's order, if not
                                                     the Mapper's */
  if (g.lazy && !p->no_tiles) {                   /* (lazy: no tiles, nfirst is all) */
    if ((st = paint_order(p, s, nfirst, err)) != T74_OK) return st;
    paint = p->order;
  }
  for (int d = 0; d < nfirst; d++) {
    const struct points_box *b = &p->box[paint ? paint[d] : d];
    if ((st = face_draw(p, &g, b->k, b, false, tiles, NULL, 0, err)) != T74_OK) return st;
  }
  int nd = 0;                                     /* faces kept */
  for (int d = nfirst; d < nb; d++) {
    const struct points_box *b = &p->box[d];
    p->box[nd] = *b;                              /* nd <= d */
    p->key[nd] = face_key(p, &g, b->k, b);
    p->order[nd] = nd;
    nd++;
  }
  if ((st = draw_order(p, s, nd, err)) != T74_OK) return st;
  for (int d = 0; d < nd; d++) {
    const struct points_box *b = &p->box[p->order[d]];
    const int k = b->k;
    struct points_band band[BANDS_KEPT];
    int nband = 0;
    if (b->jhi - b->jlo >= 2 && face_hidden(p, &g, b, band, &nband)) {
      /* behind all over: its points are not visited; drawn only when it is not yet
         known to cover a point centre (faces_culled counts the ones that cover none) */
      bool yes = false;
      if ((st = covers_middle(p, &g, k, b, &yes, err)) != T74_OK) return st;
      if (yes) continue;
    }
    if (p->retest_bands) nband = 0;
    if ((st = face_draw(p, &g, k, b, true, true, band, nband, err)) != T74_OK) return st;
  }
  /* the columns no span made ready: no face. Row j's columns right of its ready ones and
     row j + 1's left of them lie side by side in the buffer, so each stretch between two
     rows' ready columns is one fill (a row with none is wholly in the stretch): about one
     fill a row, not two */
  if (g.lazy && kept) {
    /* the last frame was lazy too, on this buffer, and left -1 outside its ready columns
       (was): the columns it made ready that this frame did not are the only ones to set
       to -1 (its others are this frame's ready ones, written this frame, or -1 already).
       The effects write the frame's faces in this buffer only where it shows a face
       (fx_points' cuts: a point showing a cut face shows what lies behind it, or none),
       so in ready columns, and -1 stays -1. */
    const int32_t *was = p->ready + 2 * (size_t)g.H;
    for (int j = 0; j < g.H; j++)
      faces_span_none(p->face + (size_t)j * (size_t)g.W, was[2 * j], was[2 * j + 1],
                      p->ready[2 * j], p->ready[2 * j + 1], false);
  } else if (g.lazy) {
    size_t from = 0;                              /* the stretch's start */
    for (int j = 0; j < g.H; j++) {
      const int32_t a = p->ready[2 * j], e = p->ready[2 * j + 1];
      if (a >= e) continue;                       /* none: the whole row */
      const size_t row = (size_t)j * (size_t)g.W;
      faces_none(p->face + from, row + (size_t)a - from);
      from = row + (size_t)e;
    }
    faces_none(p->face + from, n - from);
  }
  if (g.lazy)                                     /* this frame's ready columns kept for the
                                                     next (nothing else: it does a frame's
                                                     work, the fills only spared) */
    memcpy(p->ready + 2 * (size_t)g.H, p->ready, 2 * (size_t)g.H * sizeof *p->ready);
  p->ready_kept = !tiles;                         /* (with the tiles a span may write any
                                                     point) */
  return T74_OK;
}

void points_free(struct points *p)
{
  mapper_free(&p->map);
  core_free(p->core);
  core_free(p->segcore);
  seg_scratch_free(p->segscr);
  free(p->face);
  free(p->z);
  free(p->zhi);
  free(p->m3);
  free(p->plane);
  free(p->edge);
  free(p->vrc);
  free(p->cross);
  free(p->rowcount);
  free(p->skip);
  free(p->box);
  free(p->order);
  free(p->key);
  free(p->bucket);
  free(p->tile);
  free(p->ready);
  memset(p, 0, sizeof *p);
}

