/*
** geom.h — exact plane geometry of tube74: the plane grid, oriented lines, exact rationals.
**
** This file contains the number formats every render/ stage shares and the few exact
** predicates built on them. Paper 003 decides side, crossing type and concavity "logically
** from the order of coordinates and the slopes of edges" (003 §2.2), never from angles;
** tube74 goes one step further and makes every such decision exactly, in integers.
**
** Formats (all bounds are proven in the comments and asserted where values are made):
**   gcoord  a plane-grid coordinate: perspective-plane position in 1/GRID_ONE world units.
**           The Mapper rounds each projected vertex to this grid once; from then on the
**           grid polygon IS the face for coverage, and nothing is rounded again except
**           the two grid points that carry an interpenetration line (priority.c).
**           |gcoord| <= GRID_LIMIT (2^28), so any difference fits 29 bits.
**   gline   an oriented line a*x + b*y + c = 0 through two grid points p -> q:
**           a = py - qy, b = qx - px, c = -(a*px + b*py); |a|,|b| < 2^29, |c| < 2^58.
**           L(r) = a*rx + b*ry + c is twice the signed area of (p, q, r): > 0 when r lies
**           to the LEFT of p -> q. Pieces keep their interior on the left of every line.
**   grat    an exact rational num/den, den > 0, used for x where a line meets a
**           horizontal line y = n/d (d <= GRID_YDEN_MAX): |num| < 2^75, den < 2^46, so a
**           cross-multiplied comparison stays below 2^121 in 128-bit integers.
**   hpoint  a homogeneous point (X/W, Y/W) where two lines meet: |X|,|Y| < 2^88,
**           0 < W < 2^59; a side test a*X + b*Y + c*W stays below 2^119.
**   i256    a 256-bit integer for the one product that exceeds 128 bits: depth order,
**           plane coefficients (2^85) times homogeneous coordinates (2^89).
**
** Tie rule for points exactly on a boundary (documented in README "Exactness"):
**   a point on a non-horizontal line belongs to the side of larger x; a point on a
**   horizontal line belongs to the side of larger y. So a piece owns its left and bottom
**   boundaries and not its right and top ones: two pieces that share an edge never both
**   cover a point of it, and never both miss one (no cracks, no double coverage).
*/
#ifndef T74_GEOM_H
#define T74_GEOM_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#define GRID_BITS  8                          /* fraction bits of a grid coordinate */
#define GRID_ONE   ((int64_t)1 << GRID_BITS)  /* grid units per world unit */
#define GRID_LIMIT ((int64_t)1 << 28)         /* |gcoord| <= GRID_LIMIT (2^20 world units) */
#define GRID_YDEN_MAX ((int64_t)1 << 16)      /* largest denominator of a scanline's y */

__extension__ typedef __int128 wide;          /* exact intermediate products */
__extension__ typedef unsigned __int128 uwide;

typedef int64_t gcoord;                       /* plane-grid coordinate (see above) */

struct gpoint { gcoord x, y; };

struct gline  { int64_t a, b, c; };           /* a*x + b*y + c = 0, interior on the left */

struct grat   { wide num; wide den; };        /* num/den, den > 0 */

struct hpoint { wide X, Y, W; };              /* (X/W, Y/W), W > 0 */

struct i256   { uint64_t w[4]; };             /* two's complement, w[0] least significant */

/* ---- orientation and lines ---------------------------------------------------------- */

/* Twice the signed area of triangle (p, q, r): > 0 counter-clockwise, 0 collinear.
   Inline, as geom_line: the Mapper's and the Segment Generator's every face and side
   (issue 19). */
static inline wide geom_orient(struct gpoint p, struct gpoint q, struct gpoint r)
{
  return (wide)(q.x - p.x) * (r.y - p.y) - (wide)(q.y - p.y) * (r.x - p.x);
}

/* The oriented line through p -> q (p != q). */
static inline struct gline geom_line(struct gpoint p, struct gpoint q)
{
  struct gline l;
  l.a = p.y - q.y;
  l.b = q.x - p.x;
  l.c = -(l.a * p.x + l.b * p.y);   /* |a*px| < 2^57: no overflow in 64 bits */
  return l;
}

/* The horizontal line y = y0 with its interior above (up=true) or below (up=false). */
struct gline geom_hline(gcoord y0, bool up);

static inline bool geom_is_horizontal(struct gline l) { return l.a == 0; }

/* Sign (-1, 0, 1) of L(p) for a grid point. */
int geom_side(struct gline l, struct gpoint p);

/* Sign of L at a homogeneous point, exact (the sum stays below 2^119, by the bounds
   above). Inline: the clipping and overlap tests of the Priority
   Matrix call it for every vertex of every pair decided (issue 12). */
static inline int geom_side_h(struct gline l, struct hpoint p)
{
  wide v = l.a * p.X + l.b * p.Y + l.c * p.W;
  return (v > 0) - (v < 0);
}

/* geom_side_h at a point whose W fits 64 bits, as every meet of two lines through grid
   points has (geom_meet: W = a1 b2 - a2 b1 <= 2^59; the pieces' vertices and their
   clips'): the same sum, c W a 64 by 64-bit product. */
static inline int geom_side_hw(struct gline l, struct hpoint p)
{
  wide v = l.a * p.X + l.b * p.Y + (wide)l.c * (wide)(uint64_t)p.W;
  return (v > 0) - (v < 0);
}

/* Where two lines meet; false when they are parallel. Inline: every piece's vertices and
   every clip's new ones (issue 19). */
static inline bool geom_meet(struct gline l1, struct gline l2, struct hpoint *out)
{
  wide W = (wide)l1.a * l2.b - (wide)l2.a * l1.b;
  if (W == 0) return false;
  wide X = (wide)l1.b * l2.c - (wide)l2.b * l1.c;
  wide Y = (wide)l1.c * l2.a - (wide)l2.c * l1.a;
  if (W < 0) { W = -W; X = -X; Y = -Y; }
  out->X = X; out->Y = Y; out->W = W;
  return true;
}

/* ---- rationals on scanlines --------------------------------------------------------- */

/* x where the non-horizontal line l meets y = yn/yd (yd > 0). */
struct grat geom_x_at(struct gline l, int64_t yn, int64_t yd);

/* Compare two rationals: -1, 0, 1. Inline: the sweep's orders compare a line's span ends
   millions of times a frame (issue 19). */
static inline int geom_rat_cmp(struct grat p, struct grat q)
{
  wide l = p.num * q.den, r = q.num * p.den;
  return (l > r) - (l < r);
}

/* A rational in a double, the key by which the sweeps order their x (issue 19: the
   Visible Surface Procedure's span ends, render/vis_x.h; the effects' crossings,
   effects/poly.h): k = fl(fl(num) / fl(den)). Each of the three roundings is within
   u = 2^-53 relatively (|num|, den < 2^127: no overflow; den >= 1 and |x| >= 2^-127 unless
   0: no underflow), so |k - x| <= ((1 + u)^2 / (1 - u) - 1) |x| < 2^-51 |x|, and k has x's
   sign (0 exactly when x is). A wide that fits 64 bits is converted from its 64-bit value:
   the same double (each conversion rounds to nearest), without the library's 128-bit
   conversion. */
static inline double geom_rat_key(struct grat x)
{
  const double num = x.num == (int64_t)x.num ? (double)(int64_t)x.num : (double)x.num;
  const double den = x.den == (int64_t)x.den ? (double)(int64_t)x.den : (double)x.den;
  return num / den;
}

/* The order of two rationals p and q from their keys kp and kq (geom_rat_key) where the keys
   tell it: 1 when p > q, -1 when p < q, exactly; 0 when they lie within about 2^-49 of each
   other (equal rationals, or nearly), and the rationals themselves must be compared.
   d = fl(kp - kq) and t = fl(|kp| + |kq|) 2^-49 are each within u relatively of kp - kq
   and 2^-49 (|kp| + |kq|) (one rounding each; the scaling is exact), so d > t means
   kp - kq > 2^-50 (|kp| + |kq|), more than the two keys' errors together (< 2^-51 |p| +
   2^-51 |q| < 2^-50.9 (|kp| + |kq|)): p > q. Likewise -d > t: p < q. */
static inline int geom_key_order(double kp, double kq)
{
  const double d = kp - kq, t = (fabs(kp) + fabs(kq)) * 0x1p-49;
  if (d > t) return 1;
  if (-d > t) return -1;
  return 0;
}

/* Compare a rational with n/d (d > 0). */
int geom_rat_cmp_frac(struct grat p, int64_t n, int64_t d);

/* floor and ceiling of a rational. */
wide geom_rat_floor(struct grat p);
wide geom_rat_ceil(struct grat p);

/* Compare the y of a homogeneous point with n/d (d > 0): -1, 0, 1. Inline, with n W a 64
   by 64-bit product (W < 2^59, the format above): the sweep compares every active
   piece's ends with each line (issue 19). */
static inline int geom_hy_cmp(struct hpoint p, int64_t n, int64_t d)
{
  wide l = p.Y * d, r = (wide)n * (wide)(uint64_t)p.W;
  return (l > r) - (l < r);
}

/* ---- the 1974 arithmetic (--arith hitac) --------------------------------------------
** tube74 decides exactly by default. With --arith hitac the decisions are made as the
** HITAC-10 program would make them, in its word sizes (docs/machine.md, "Which quantity
** is held in what"): these helpers turn an exact quantity into the value that program
** would hold, truncating (toward zero, as a shift or a divide of the machine does), and
** the exact predicates then decide on the held values. Where a stage asks (struct vis,
** struct prio: `arith`), GEOM_HITAC routes it through them; nothing else changes, so the
** renderer is one renderer with one switch.
*/
enum geom_arith { GEOM_EXACT = 0, GEOM_HITAC = 1 };

/* Fraction bits of a scanline crossing x (xb, xe of a D-block) held in a double word:
   x in world units with 16 fraction bits = grid units with 8 more (GEOM_H10_XBITS). */
#define GEOM_H10_XBITS 8
#define GEOM_H10_XONE ((wide)1 << GEOM_H10_XBITS)

/* x as the 1974 program holds it: truncated to 1/GEOM_H10_XONE grid unit (a double word,
   16.16 fixed point in world units); the result has denominator GEOM_H10_XONE. */
struct grat geom_h10_x(struct grat x);

/* The increment of xb (or xe) for a line step: the exact increment sl * dyn / den, as a
   double word of the same fixed point, truncated. */
wide geom_h10_dx(wide sl, int64_t dyn, wide den);

/* A plane a x + b y + c z + d = 0 as the 1974 program holds it: a, b, c in one word each
   (|.| < 2^15) and d in a double word, all shifted right by the same count, truncating. */
void geom_h10_plane(const int64_t in[4], int64_t out[4]);

/* ---- 256-bit integers for depth order ---------------------------------------------- */

struct i256 i256_mul(wide a, wide b);
struct i256 i256_add(struct i256 a, struct i256 b);
struct i256 i256_from(wide a);
int i256_sign(struct i256 a);

/* The sign of a*b - c*d, exactly: by comparing a and c when b = d; in 128 bits (a 64 by
** 64-bit product a side) when a and c fit 64 bits and b and d are in [0, 2^63); in 192
** bits when b and d are in [0, 2^64) (a coordinate
** by a homogeneous W, the common case); else in 128 bits when
** the magnitudes' bit lengths of a and b add up to at most 127, and those of c and d too
** (each product is then below 2^127 in magnitude and held exactly; the two are compared,
** never subtracted); else in 256 bits. -1, 0, 1. */
int geom_cross_sign_long(wide a, wide b, wide c, wide d);   /* the same, past the first two */
static inline int geom_cross_sign(wide a, wide b, wide c, wide d)
{
  /* one factor on both sides (two points of one W, a third of the sweep's compares at
     30,000 boxes): a*b - c*b = (a - c) b, whose sign is that of a - c times b's; a and c
     are compared, not subtracted */
  if (b == d) return ((a > c) - (a < c)) * ((b > 0) - (b < 0));
  if ((((uwide)b | (uwide)d) >> 63) == 0 && a == (int64_t)a && c == (int64_t)c) {
    /* (inline, issue 19: the vertices' y order of every piece and scan) a, c in
       [-2^63, 2^63), b, d in [0, 2^63): each product below 2^126 in magnitude, held
       exactly as a 64 by 64-bit product; compared, not subtracted */
    wide l = (wide)(int64_t)a * (int64_t)b, r = (wide)(int64_t)c * (int64_t)d;
    return (l > r) - (l < r);
  }
  return geom_cross_sign_long(a, b, c, d);
}

/* The sign of a0*b0 + a1*b1 + a2*b2, exactly: in 128 bits when each product's operands'
** bit lengths add up to at most 125 (each product below 2^125, the sum of three below
** 2^127), else in 256 bits. -1, 0, 1. */
int geom_dot3_sign(wide a0, wide b0, wide a1, wide b1, wide a2, wide b2);

#endif
