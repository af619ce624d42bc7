/*
** vis_x.h — the order of two x of the Visible Surface Procedure's sweep (visible.c), exactly,
** and from doubles where these lie apart.
**
** The sweep orders span ends on its line thousands of times a line (the insertion sorts of
** each line, the binary searches where a cut's halves come in, the sweep's own merge); the
** exact compare is two 128 x 64-bit products. Each item's ends are also kept as doubles
** (geom_rat_key, render/geom.h, made once a line with the span), and a compare is decided
** from them when they lie apart by more than their errors can bridge (kx_cmp, or band_cmp
** against a band made once for a fixed end), else exactly (x_cmp): every answer is
** x_cmp's. The 1974 program's
** compares are counted where they are asked, as before; only the host's work changes.
** (effects/poly.h's fx_x_cmp orders the effects' crossings by the same keys.)
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

/* x_cmp(*p, *q) from their keys kp, kq (geom_rat_key) where the keys tell it
   (geom_key_order), else (the keys within about 2^-49 of each other: equal ends, or
   nearly) x_cmp itself. */
static inline int kx_cmp(double kp, double kq, const struct grat *p, const struct grat *q)
{
  const int o = geom_key_order(kp, kq);
  return o ? o : x_cmp(*p, *q);
}

/* The band of a key kq (geom_rat_key of q) outside which another key decides its order
   with q: kp < lo gives p < q, kp > hi gives p > q, exactly. With w = |kq| 2^-47 (exact: a
   power-of-two scaling), lo = fl(kq - w) is within u (|kq| + w) of kq - w, so kp < lo
   means D = kq - kp > |kq| (2^-47 - 2^-52.9) > 2^-47.1 |kq|; then |kp| <= |kq| + D, and the
   two keys' errors (geom_rat_key: each under 2^-51 |x| <= 2^-50.99 |k|) are under
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
