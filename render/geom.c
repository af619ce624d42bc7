/*
** geom.c — exact plane geometry: orientation, oriented lines, rationals, 256-bit products.
**
** See geom.h for the formats and the bounds that make every expression here fit.
*/
#include "render/geom.h"

#include <assert.h>

struct gline geom_hline(gcoord y0, bool up)
{
  struct gline l = { 0, up ? 1 : -1, up ? -y0 : y0 };
  return l;
}

int geom_side(struct gline l, struct gpoint p)
{
  wide v = (wide)l.a * p.x + (wide)l.b * p.y + l.c;
  return (v > 0) - (v < 0);
}

struct grat geom_x_at(struct gline l, int64_t yn, int64_t yd)
{
  assert(l.a != 0 && yd > 0);
  /* a*x + b*y + c = 0  =>  x = -(b*yn + c*yd) / (a*yd) */
  struct grat r;
  r.num = -((wide)l.b * yn + (wide)l.c * yd);
  r.den = (wide)l.a * yd;
  if (r.den < 0) { r.den = -r.den; r.num = -r.num; }
  return r;
}

int geom_rat_cmp_frac(struct grat p, int64_t n, int64_t d)
{
  wide l = p.num * d, r = (wide)n * p.den;
  return (l > r) - (l < r);
}

wide geom_rat_floor(struct grat p)
{
  wide q = p.num / p.den;
  if (p.num % p.den != 0 && p.num < 0) q -= 1;
  return q;
}

wide geom_rat_ceil(struct grat p)
{
  wide q = p.num / p.den;
  if (p.num % p.den != 0 && p.num > 0) q += 1;
  return q;
}


/* ---- the 1974 arithmetic ------------------------------------------------------------- */

struct grat geom_h10_x(struct grat x)
{
  struct grat r;
  r.num = x.num * GEOM_H10_XONE / x.den;            /* C division truncates toward zero */
  r.den = GEOM_H10_XONE;
  return r;
}

wide geom_h10_dx(wide sl, int64_t dyn, wide den)
{
  return sl * dyn * GEOM_H10_XONE / den;
}

void geom_h10_plane(const int64_t in[4], int64_t out[4])
{
  int64_t m = 0;
  for (int k = 0; k < 3; k++) {
    int64_t a = in[k] < 0 ? -in[k] : in[k];
    if (a > m) m = a;
  }
  int64_t div = 1;
  while (m / div >= ((int64_t)1 << 15)) div *= 2;  /* the shift the program would use */
  for (int k = 0; k < 4; k++) out[k] = in[k] / div;
}

/* ---- 256-bit integers ---------------------------------------------------------------- */

struct i256 i256_from(wide a)
{
  struct i256 r;
  uwide u = (uwide)a;
  uint64_t fill = a < 0 ? ~(uint64_t)0 : 0;
  r.w[0] = (uint64_t)u;
  r.w[1] = (uint64_t)(u >> 64);
  r.w[2] = fill;
  r.w[3] = fill;
  return r;
}

static struct i256 i256_neg(struct i256 a)
{
  struct i256 r;
  unsigned carry = 1;
  for (int k = 0; k < 4; k++) {
    uint64_t v = ~a.w[k];
    r.w[k] = v + carry;
    carry = carry && r.w[k] == 0;
  }
  return r;
}

struct i256 i256_add(struct i256 a, struct i256 b)
{
  struct i256 r;
  unsigned carry = 0;
  for (int k = 0; k < 4; k++) {
    uint64_t s = a.w[k] + b.w[k];
    unsigned c1 = s < a.w[k];
    uint64_t t = s + carry;
    unsigned c2 = t < s;
    r.w[k] = t;
    carry = c1 | c2;
  }
  return r;
}

struct i256 i256_mul(wide a, wide b)
{
  bool neg = (a < 0) != (b < 0);
  uwide ua = a < 0 ? (uwide)0 - (uwide)a : (uwide)a;
  uwide ub = b < 0 ? (uwide)0 - (uwide)b : (uwide)b;
  uint64_t x[2] = { (uint64_t)ua, (uint64_t)(ua >> 64) };
  uint64_t y[2] = { (uint64_t)ub, (uint64_t)(ub >> 64) };
  struct i256 r = { { 0, 0, 0, 0 } };
  for (int i = 0; i < 2; i++) {
    uwide carry = 0;
    for (int j = 0; j < 2; j++) {
      uwide t = (uwide)x[i] * y[j] + r.w[i + j] + carry;
      r.w[i + j] = (uint64_t)t;
      carry = t >> 64;
    }
    int k = i + 2;
    while (carry && k < 4) {
      uwide t = (uwide)r.w[k] + carry;
      r.w[k] = (uint64_t)t;
      carry = t >> 64;
      k++;
    }
  }
  return neg ? i256_neg(r) : r;
}

int i256_sign(struct i256 a)
{
  if ((int64_t)a.w[3] < 0) return -1;
  return (a.w[0] | a.w[1] | a.w[2] | a.w[3]) != 0;
}

/* The bit length of |a|: the least n with |a| < 2^n (0 for 0). |a| of the most negative
   wide is 2^127, length 128, as an unsigned magnitude. */
static inline int bits(wide a)
{
  uwide u = a < 0 ? (uwide)0 - (uwide)a : (uwide)a;
  uint64_t hi = (uint64_t)(u >> 64), lo = (uint64_t)u;
  if (hi) return 128 - __builtin_clzll(hi);
  return lo ? 64 - __builtin_clzll(lo) : 0;
}

/* a*b as top * 2^64 + low (low in [0, 2^64)), exactly, for 0 <= b < 2^64: a = ah 2^64 +
   al (ah in [-2^63, 2^63), al in [0, 2^64)), so a*b = ah b 2^64 + al b with |ah b| <
   2^127, and top = ah b + (al b >> 64) is floor(a*b / 2^64), in [-2^127, 2^127): no
   step overflows. */
static inline void mul_u64(wide a, uint64_t b, wide *top, uint64_t *low)
{
  uwide lo = (uwide)(uint64_t)a * b;
  *top = (wide)(int64_t)(a >> 64) * (wide)b + (wide)(lo >> 64);
  *low = (uint64_t)lo;
}

int geom_cross_sign_long(wide a, wide b, wide c, wide d)
{
  if (b >= 0 && d >= 0 && !(b >> 64) && !(d >> 64)) {
    /* in 192 bits: each product's high part and low word, compared in that order */
    wide t1, t2;
    uint64_t l1, l2;
    mul_u64(a, (uint64_t)b, &t1, &l1);
    mul_u64(c, (uint64_t)d, &t2, &l2);
    if (t1 != t2) return t1 > t2 ? 1 : -1;
    return (l1 > l2) - (l1 < l2);
  }
  if (bits(a) + bits(b) <= 127 && bits(c) + bits(d) <= 127) {
    wide l = a * b, r = c * d;             /* |l|, |r| < 2^127: compared, not subtracted */
    return (l > r) - (l < r);
  }
  return i256_sign(i256_add(i256_mul(a, b), i256_mul(-c, d)));
}

int geom_dot3_sign(wide a0, wide b0, wide a1, wide b1, wide a2, wide b2)
{
  if (bits(a0) + bits(b0) <= 125 && bits(a1) + bits(b1) <= 125 && bits(a2) + bits(b2) <= 125) {
    wide s = a0 * b0 + a1 * b1 + a2 * b2;   /* each below 2^125, the sum below 3 * 2^125 */
    return (s > 0) - (s < 0);
  }
  return i256_sign(i256_add(i256_add(i256_mul(a0, b0), i256_mul(a1, b1)), i256_mul(a2, b2)));
}
