/*
** vis_x.h — the order of two x of the Visible Surface Procedure's sweep (visible.c), exactly,
** and from doubles where these lie apart.
**
** The sweep orders span ends on its line thousands of times a line (the insertion sorts of
** each line, the binary searches where a cut's halves come in, the sweep's own merge); the
** exact compare is two 128 x 64-bit products. Each item's ends are also kept as doubles
** (x_key, made once a line with the span), and a compare is decided from them when they lie
** apart by more than their errors can bridge (kx_cmp, or band_cmp against a band made once
** for a fixed end), else exactly (x_cmp): every answer is x_cmp's. The 1974 program's
** compares are counted where they are asked, as before; only the host's work changes.
** (effects/poly.h's fx_x_key and fx_x_cmp are the same idea for the effects' crossings.)
*/
#ifndef T74_VIS_X_H
#define T74_VIS_X_H

#include <math.h>
#include <stdint.h>
#include "render/geom.h"

/* geom_rat_cmp of two x of the sweep. Every x here is a span end on the line, or made
   from them: geom_x_at's, whose denominator is |a| yd with |a| <= 2^29 (geom.h: a grid
   line's) and yd < 2^34 (asserted by vis_spans; a scanline's is at most GRID_YDEN_MAX),
   stepped from line to line by its numerator only, or under --arith hitac geom_h10_x's,
   GEOM_H10_XONE. So each denominator fits 64 bits, unsigned, and each product is a
   128-bit numerator by a 64-bit number: the same products, with the part of the
   multiply that a denominator's high word would take left out (it is zero). */
static inline int x_cmp(struct grat p, struct grat q)
{
  wide l = p.num * (wide)(uint64_t)q.den, r = q.num * (wide)(uint64_t)p.den;
  return (l > r) - (l < r);
}

/* An x of the sweep in a double, k = fl(fl(num) / fl(den)): each of the three roundings
   is within u = 2^-53 relatively (|num| < 2^127 and 0 < den < 2^63: no overflow; den >= 1
   and |x| >= 2^-63 unless 0: no underflow), so |k - x| <= ((1 + u)^2 / (1 - u) - 1) |x|
   < 2^-51 |x|, and k has x's sign (0 exactly when x is). A numerator that fits 64 bits is
   converted from the 64-bit value: the same double (each conversion rounds to nearest),
   without the library's 128-bit conversion. (effects/poly.h's fx_x_key, the same.) */
static inline double x_key(struct grat x)
{
  const double num = x.num == (int64_t)x.num ? (double)(int64_t)x.num : (double)x.num;
  return num / (double)(int64_t)x.den;
}

/* x_cmp(*p, *q) from their keys kp, kq (x_key) when these lie apart: d = fl(kp - kq) and
   t = fl(|kp| + |kq|) 2^-49 are each within u relatively of kp - kq and 2^-49 (|kp| + |kq|)
   (one rounding each, within u; the scaling is exact), so d > t means kp - kq > 2^-50 (|kp| + |kq|),
   more than the two keys' errors together (< 2^-51 |p| + 2^-51 |q| < 2^-50.9 (|kp| + |kq|)):
   then p > q, exactly as x_cmp finds; likewise d < -t. Else (the keys within about 2^-49 of
   each other: equal ends, or nearly) x_cmp itself. */
static inline int kx_cmp(double kp, double kq, const struct grat *p, const struct grat *q)
{
  const double d = kp - kq, t = (fabs(kp) + fabs(kq)) * 0x1p-49;
  if (d > t) return 1;
  if (-d > t) return -1;
  return x_cmp(*p, *q);
}

/* The band of a key kq (x_key of q) outside which another key decides its order with q:
   kp < lo gives p < q, kp > hi gives p > q, exactly. With w = |kq| 2^-47 (exact: a
   power-of-two scaling), lo = fl(kq - w) is within u (|kq| + w) of kq - w, so kp < lo
   means D = kq - kp > |kq| (2^-47 - 2^-52.9) > 2^-47.1 |kq|; then |kp| <= |kq| + D, and the
   two keys' errors (x_key: each under 2^-51 |x| <= 2^-50.99 |k|) are under
   2^-50.99 (2 |kq| + D), less than D: q - p > 0. Likewise kp > hi = fl(kq + w). When
   kq = 0 (q = 0), lo = hi = 0 and p has kp's sign. Between lo and hi: x_cmp. */
static inline void key_band(double kq, double *lo, double *hi)
{
  const double w = fabs(kq) * 0x1p-47;
  *lo = kq - w;
  *hi = kq + w;
}

static inline int band_cmp(double kp, double lo, double hi, const struct grat *p,
                           const struct grat *q)
{
  if (kp < lo) return -1;
  if (kp > hi) return 1;
  return x_cmp(*p, *q);
}

#endif
