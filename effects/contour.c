/*
** contour.c — contour smoothing (paper 004 §5, procedures (C), (D)); see contour.h.
**
** Cost: building the contour is charged per front triangle side (a sort key, 3 loads);
** each corner's control points (2 projections of a space point, eq. (1): 2 multiplies,
** 1 divide each coordinate) and its CONTOUR_STEPS + 1 curve points (4 multiply-adds a
** coordinate, Horner); each row of a corner's region its edge tests and crossings
** (geom_x_at: a multi-word multiply and divide); each cut point the span of every piece
** whose height range holds the row (seginfo_span counts its own work) and the priority
** look-ups (prio_order counts into the Priority Matrix's stage).
** Tables in core: CONTOUR CURVES, the region polygon of the corner being cut (4 words a
** point, CONTOUR_STEPS + 2 points), reused from corner to corner.
*/
#include "effects/contour.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif
/* region_exact on AVX-512 where the processor has it (a run-time test, region_avx512) */
#if defined(__SSE2__) && (defined(__x86_64__) || defined(__i386__)) && \
    (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define REGION_AVX512 1
#endif

#define CONTOUR_TABLE "CONTOUR CURVES"

/* The quartic Bernstein weights at t. */
static void bernstein(double t, double b[5])
{
  double u = 1 - t;
  b[0] = u * u * u * u;
  b[1] = 4 * u * u * u * t;
  b[2] = 6 * u * u * t * t;
  b[3] = 4 * u * t * t * t;
  b[4] = t * t * t * t;
}

/* The curve's point with the weights b (contour_bezier's sum). */
static inline __attribute__((always_inline)) void
bezier_with(const double q[5][2], const double b[5], double out[2])
{
  for (int c = 0; c < 2; c++)
    out[c] = b[0] * q[0][c] + b[1] * q[1][c] + b[2] * q[2][c] + b[3] * q[3][c] + b[4] * q[4][c];
}

void contour_bezier(const double q[5][2], double t, double out[2])
{
  double b[5];
  bernstein(t, b);
  bezier_with(q, b, out);
}

/* The weights at the curve polygon's points t = m / CONTOUR_STEPS, the same doubles
   bernstein makes at each: t = m / 64 and u = 1 - t = (64 - m) / 64 are exact, and every
   product of a weight, taken left to right as bernstein takes them (4 u u u t: 4 u, then
   times u, u, t), is an integer below 6 * 64^4 < 2^27 over a power of two: exact. So each
   weight is exactly C(4, k) (64 - m)^(4 - k) m^k / 2^24, which the constant expressions
   below give exactly too (an integer below 2^53, divided by a power of two). A table:
   nothing made a frame. */
_Static_assert(CONTOUR_STEPS == 64, "the weights' table is made for 64 steps");
#define CW_(c, a, b) ((double)((c) * (a) * (b)) / 16777216.0)
#define CW_U(m) (64 - (m))
#define CW_W(m, k)                                                                 \
  ((k) == 0 ? CW_(1, CW_U(m) * CW_U(m), CW_U(m) * CW_U(m)) :                   \
   (k) == 1 ? CW_(4, CW_U(m) * CW_U(m), CW_U(m) * (m)) :                       \
   (k) == 2 ? CW_(6, CW_U(m) * CW_U(m), (m) * (m)) :                           \
   (k) == 3 ? CW_(4, CW_U(m) * (m), (m) * (m)) : CW_(1, (m) * (m), (m) * (m)))
#define CW_B(m) { CW_W(m, 0), CW_W(m, 1), CW_W(m, 2), CW_W(m, 3), CW_W(m, 4) }
#define CW_B2(m) { { CW_W(m, 0), CW_W(m, 0) }, { CW_W(m, 1), CW_W(m, 1) },         \
                   { CW_W(m, 2), CW_W(m, 2) }, { CW_W(m, 3), CW_W(m, 3) },         \
                   { CW_W(m, 4), CW_W(m, 4) } }
#define CW_8(F, m) F(m), F(m + 1), F(m + 2), F(m + 3), F(m + 4), F(m + 5), F(m + 6), F(m + 7)
#define CW_65(F) CW_8(F, 0), CW_8(F, 8), CW_8(F, 16), CW_8(F, 24), CW_8(F, 32), CW_8(F, 40), \
                 CW_8(F, 48), CW_8(F, 56), F(64)
struct curve_weights {
  double b[CONTOUR_STEPS + 1][5];
  _Alignas(16) double b2[CONTOUR_STEPS + 1][5][2];   /* each b twice: a lane for x, one for y */
};
static const struct curve_weights curve_table = { { CW_65(CW_B) }, { CW_65(CW_B2) } };

void contour_bezier_d(const double q[5][2], double t, double out[2])
{
  double u = 1 - t;
  double b[4] = { u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t };
  for (int c = 0; c < 2; c++) {
    out[c] = 0;
    for (int i = 0; i < 4; i++) out[c] += 4 * b[i] * (q[i + 1][c] - q[i][c]);
  }
}

void contour_controls(const double q0[2], const double q2[2], const double q4[2], double cc,
                      double q[5][2])
{
  for (int c = 0; c < 2; c++) {
    q[0][c] = q0[c];
    q[1][c] = q2[c] + cc * (q0[c] - q2[c]);
    q[2][c] = q2[c];
    q[3][c] = q2[c] + cc * (q4[c] - q2[c]);
    q[4][c] = q4[c];
  }
}

double contour_cut_share(double cc)
{
  return (8 * cc * cc + 8 * cc + 1) / 35;
}

/* llround(x), the same integer (half away from zero), without the library call: the
   part of x after its truncation is exact in a double. */
static inline gcoord round_small(double x)   /* round_grid's for |x| < 2^62 */
{
  int64_t t = (int64_t)x;
  double f = x - (double)t;
  /* the two steps as 0 or 1, not branches: along a curve f's sign is anyone's guess */
  return (gcoord)(t + (f >= 0.5) - (f <= -0.5));
}

static gcoord round_grid(double x)
{
  if (!(fabs(x) < 0x1p62)) return (gcoord)llround(x);
  return round_small(x);
}

/* The curve's points when Q0..Q4 are within 2^29 of the origin: exactly, in integers.
**
** The sum bezier_with makes at m / 64 is then exact, so its rounding is that of an
** integer over 2^24: each weight is n_k / 2^24 with n_k = C(4, k) (64 - m)^(4 - k) m^k an
** integer, 0 <= n_k < 2^24 for 1 <= m <= 63, the n_k summing to 64^4 = 2^24; each product
** n_k d_k / 2^24 (d_k an integer, |d_k| < 2^29) has a numerator below 2^53 in magnitude,
** and so has each partial sum (at most sum n_k |d_k| < 2^24 2^29): every product and sum
** is exact, and the double is P(m) / 2^24, P(m) = sum n_k d_k, an integer with |P| < 2^53.
** round_small rounds it half away from zero, which is floor((P + 2^23 - [P < 0]) / 2^24)
** (P >= 0: floor(P / 2^24 + 1/2); P < 0: -floor((-P + 2^23) / 2^24) = ceil((P - 2^23) /
** 2^24)). P, a polynomial of degree 4 in i = 64 - m with integer coefficients, is stepped
** from i = 1 to 63 by its forward differences (four adds a point; at i <= 68 the sum of
** the |n_k| is (i + |64 - i|)^4 < 2^25, so each value |P| < 2^54 and each difference,
** a sum of at most 16 values, < 2^58: no overflow), begun from P at i = 1 .. 5. The
** floor by a logical shift of P + 2^23 - [P < 0] + 2^54 (>= 2^54 - 2^53 > 0, below 2^64),
** less 2^30 after it. Four adds, the rounding and a store a point, against bezier_with's
** five products and four sums and round_small's steps on doubles (issue 19). */
#define CURVE_EXACT ((gcoord)1 << 29)

/* The region polygon's blocks: one ring of CONTOUR_STEPS + 2 points, FX_POLY_BLOCK a block. */
enum { REGION_BLOCKS = (CONTOUR_STEPS + 2 + FX_POLY_BLOCK - 1) / FX_POLY_BLOCK };
_Static_assert(FX_POLY_BLOCK == 8 && CONTOUR_STEPS == 64 && REGION_BLOCKS == 9,
               "region_exact's blocks are laid out for 66 points, 8 a block");

/* Made without SSE2, or with coordinates outside CURVE_EXACT: the blocks and box
   fx_polys_close would make (fx_ring_blocks over the one ring). */
static void region_blocks(const struct gpoint poly[CONTOUR_STEPS + 2], gcoord (*blk)[2],
                          gcoord box[4])
{
  box[0] = INT64_MAX; box[1] = INT64_MIN; box[2] = INT64_MAX; box[3] = INT64_MIN;
  fx_ring_blocks(poly, CONTOUR_STEPS + 2, blk, 0, box);
}

#ifdef __SSE2__
/* region_exact's and region_exact512's last step: each block's y extremes into blk and the
   ring's box from the blocks' keys bl, bh (the doubles 2^52 + r, x and y a lane, that
   region_exact's REGION_KEY makes), r taken back as the key's bits less those of
   2^52 + 2^30. */
static inline void region_keys_out(const __m128d bl[REGION_BLOCKS],
                                   const __m128d bh[REGION_BLOCKS], gcoord (*blk)[2],
                                   gcoord box[4])
{
  const __m128i back = _mm_set1_epi64x((int64_t)0x4330000000000000 + ((int64_t)1 << 30));
  __m128d blo = bl[0], bhi = bh[0];
  for (int b = 0; b < REGION_BLOCKS; b++) {
    const __m128i l = _mm_sub_epi64(_mm_castpd_si128(bl[b]), back);
    const __m128i h = _mm_sub_epi64(_mm_castpd_si128(bh[b]), back);
    _mm_storeu_si128((__m128i *)(void *)blk[b], _mm_unpackhi_epi64(l, h));   /* y lo, y hi */
    blo = _mm_min_pd(blo, bl[b]);
    bhi = _mm_max_pd(bhi, bh[b]);
  }
  const __m128i l = _mm_sub_epi64(_mm_castpd_si128(blo), back);
  const __m128i h = _mm_sub_epi64(_mm_castpd_si128(bhi), back);
  _mm_storeu_si128((__m128i *)(void *)&box[0], _mm_unpacklo_epi64(l, h));    /* x lo, x hi */
  _mm_storeu_si128((__m128i *)(void *)&box[2], _mm_unpackhi_epi64(l, h));    /* y lo, y hi */
}
#endif

static void region_exact(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2],
                         gcoord (*blk)[2], gcoord box[4])
{
  /* P at i = 1 and its differences there, found from Q1 - Q0 .. Q4 - Q0: the n_k sum to
     2^24 at every i, so P = 2^24 Q0 + sum over k = 1 .. 4 of n_k (Qk - Q0), and the
     differences of the constant 2^24 Q0 are 0: the l-th difference of P at i = 1 is the sum
     of the l-th differences of the n_k there (dn[l][k - 1], below) times Qk - Q0. The same
     integers as P at i = 1 .. 5 differenced (no overflow: |Qk - Q0| < 2^30 and |dn| < 2^24,
     each sum below 2^57), with 40 multiplies a corner where that took 50 and the
     differences' 20 subtracts; the constants are n_k(i) = C(4, k) i^(4 - k) (64 - i)^k
     at i = 1 .. 5 differenced (test_region_is_bezier checks the points they give). */
  static const int64_t dn[5][4] = {
    { 252, 23814, 1000188, 15752961 },       /* n_1 .. n_4 at i = 1 */
    { 1732, 68442, 906436, -976625 },        /* their first differences there */
    { 2872, 40236, -89288, 46130 },
    { 1296, -4248, 4368, -1476 },
    { -96, 144, -96, 24 },                   /* the fourth: 24 C(4, k) (-1)^k */
  };
  int64_t v[5][2];                          /* P at i = 1, then its differences; x and y */
  const int64_t ex[4] = { q[1].x - q[0].x, q[2].x - q[0].x, q[3].x - q[0].x, q[4].x - q[0].x };
  const int64_t ey[4] = { q[1].y - q[0].y, q[2].y - q[0].y, q[3].y - q[0].y, q[4].y - q[0].y };
  for (int l = 0; l < 5; l++) {
    v[l][0] = dn[l][0] * ex[0] + dn[l][1] * ex[1] + dn[l][2] * ex[2] + dn[l][3] * ex[3];
    v[l][1] = dn[l][0] * ey[0] + dn[l][1] * ey[1] + dn[l][2] * ey[2] + dn[l][3] * ey[3];
  }
  v[0][0] += q[0].x * ((int64_t)1 << 24);
  v[0][1] += q[0].y * ((int64_t)1 << 24);
#ifdef __SSE2__
  /* x and y a lane each (64-bit adds and a logical shift: SSE2's) */
  __m128i d0 = _mm_set_epi64x(v[0][1], v[0][0]), d1 = _mm_set_epi64x(v[1][1], v[1][0]);
  __m128i d2 = _mm_set_epi64x(v[2][1], v[2][0]), d3 = _mm_set_epi64x(v[3][1], v[3][0]);
  const __m128i d4 = _mm_set_epi64x(v[4][1], v[4][0]);
  const __m128i bias = _mm_set1_epi64x(((int64_t)1 << 23) + ((int64_t)1 << 54));
  const __m128i off = _mm_set1_epi64x((int64_t)1 << 30);
  /* The blocks and box (fx_ring_blocks') made on the way, in doubles: every point here is
     within 2^29 of the origin (Q0..Q4 are, and each curve point is the rounding of a
     convex combination of them: its integer within 2^29 too), so s = r + 2^30 lies in
     [0, 2^31), and the double with s's bits ORed into those of 2^52 is 2^52 + s exactly
     (s < 2^52: a mantissa's bits). That map is increasing in r, so MINPD and MAXPD of
     the doubles (x, y a lane; positive normal numbers, no NaN) pick the points that the
     integer compares pick, and r comes back as the double's bits less those of 2^52 + 2^30.
     Two instructions a point for the four extremes, where fx_ring_blocks' compares and
     selects make four chains of eight (issue 19: about a quarter of contour_build). */
  const __m128i expo = _mm_set1_epi64x((int64_t)0x4330000000000000);
#define REGION_KEY(p) _mm_castsi128_pd(_mm_or_si128(                                    \
    _mm_add_epi64(_mm_loadu_si128((const __m128i *)(const void *)(p)), off), expo))
  const __m128d k0 = REGION_KEY(&poly[0]), k1 = REGION_KEY(&poly[1]);
  __m128d lo = _mm_min_pd(k0, k1), hi = _mm_max_pd(k0, k1);
  __m128d bl[REGION_BLOCKS], bh[REGION_BLOCKS];
  int i = 1;                                   /* the curve's point i is poly[1 + i] */
  for (int b = 0; b < REGION_BLOCKS - 1; b++)
    for (;; i++) {                             /* poly[8 b + 2 ..] up to poly[8 b + 8] */
      /* [P < 0] as -1 in a lane: the sign of its high half, spread over the lane */
      const __m128i neg = _mm_shuffle_epi32(_mm_srai_epi32(d0, 31), _MM_SHUFFLE(3, 3, 1, 1));
      const __m128i sh = _mm_srli_epi64(_mm_add_epi64(_mm_add_epi64(d0, bias), neg), 24);
      const __m128i r = _mm_sub_epi64(sh, off);
      _mm_storeu_si128((__m128i *)(void *)&poly[1 + i], r);
      const __m128d k = _mm_castsi128_pd(_mm_or_si128(sh, expo));   /* sh = r + 2^30 */
      d0 = _mm_add_epi64(d0, d1);
      d1 = _mm_add_epi64(d1, d2);
      d2 = _mm_add_epi64(d2, d3);
      d3 = _mm_add_epi64(d3, d4);
      if (i == 8 * b + 7) {                    /* poly[8 b + 8]: block b's last, b + 1's first */
        bl[b] = _mm_min_pd(lo, k);
        bh[b] = _mm_max_pd(hi, k);
        lo = hi = k;
        i++;
        break;
      }
      lo = _mm_min_pd(lo, k);
      hi = _mm_max_pd(hi, k);
    }
  {                                            /* poly[64], poly[65] (Q0), then poly[0] */
    const __m128d k65 = REGION_KEY(&poly[CONTOUR_STEPS + 1]);
    bl[REGION_BLOCKS - 1] = _mm_min_pd(_mm_min_pd(lo, k65), k0);
    bh[REGION_BLOCKS - 1] = _mm_max_pd(_mm_max_pd(hi, k65), k0);
  }
#undef REGION_KEY
  region_keys_out(bl, bh, blk, box);
#else
  for (int i = 1; i < CONTOUR_STEPS; i++) {
    gcoord r[2];
    for (int c = 0; c < 2; c++) {
      const uint64_t u = (uint64_t)v[0][c] + (((uint64_t)1 << 23) + ((uint64_t)1 << 54)) -
                         (v[0][c] < 0);
      r[c] = (gcoord)(u >> 24) - ((gcoord)1 << 30);
      for (int l = 0; l < 4; l++) v[l][c] += v[l + 1][c];
    }
    poly[1 + i] = (struct gpoint){ r[0], r[1] };
  }
  region_blocks(poly, blk, box);
#endif
}

#ifdef REGION_AVX512
/* region_exact four curve points a step (AVX-512F's 512-bit registers, x and y of four
   points: eight 64-bit lanes; AVX-512DQ's VPMULLQ for the start), chosen at run time where
   the processor has both (region_avx512). The same integers: lane l of a step holds the
   point i = 4 s + l (poly[1 + i]), P(i) and its differences of step 4, each found as
   region_exact finds P at i = 1 and its differences of step 1 there: P(i) = 2^24 Q0 + sum
   over k = 1 .. 4 of n_k(i) (Qk - Q0), and each difference of step 4 the sum of the n_k's
   differences of step 4 at i (dn4: n_k(i) = C(4, k) i^(4 - k) (64 - i)^k at i = 0 .. 19
   differenced, l = 0 .. 3) times Qk - Q0; a step then adds each difference to the one
   below it (P is a polynomial of degree 4 in i: the fourth difference is constant). Every
   value is an exact integer in 64 bits: |Qk - Q0| < 2^30, the n_k's differences of step 4
   are below 2^25 (an o-th difference of values within [0, 2^24] is within 2^o 2^24), each
   sum of four products below 2^57; P(i) is within 2^24 (2^29 + 1) of 0 and a difference of
   order o of it within 2^o 2^54. So P(i) is region_exact's, and each point's rounding the
   same operations (the sign spread by VPSRAQ, not the shuffle of the high half's). Point
   i = 0 (poly[1], Q4 itself) is not stored; i = 1 .. 63 are poly[2 .. 64]. The blocks' and
   the box's extremes are taken from the same doubles (region_exact's keys) over the same
   points, so the same; a block b's points are poly[8 b .. 8 b + 8]: steps 2 b and 2 b + 1
   (poly[8 b + 1 .. 8 b + 8]) and the last lane of step 2 b - 1 (poly[0] for block 0); the
   last block poly[64] (step 15's last lane), poly[65] and poly[0]. A step of four points is
   about as many instructions as a point was (issue 19, round 41). */
#define REGION512_ATTR __attribute__((target("avx512f,avx512dq")))
static REGION512_ATTR void region_exact512(const struct gpoint q[5],
                                           struct gpoint poly[CONTOUR_STEPS + 2],
                                           gcoord (*blk)[2], gcoord box[4])
{
  /* dn4[o][k - 1][l]: the o-th difference of step 4 of n_k at i = l */
  static const int64_t dn4[5][4][4] = {
    { { 0, 252, 1984, 6588 }, { 0, 23814, 92256, 200934 },
      { 0, 1000188, 1906624, 2723772 }, { 16777216, 15752961, 14776336, 13845841 } },
    { { 15360, 29248, 48128, 71616 }, { 345600, 498336, 634368, 754272 },
      { 3456000, 3107392, 2776064, 2461632 }, { -3817216, -3635600, -3459840, -3289840 } },
    { { 83968, 101632, 117760, 132352 }, { 513024, 449664, 388608, 329856 },
      { -1292288, -1225472, -1160192, -1096448 }, { 691712, 668864, 646400, 624320 } },
    { { 61440, 55296, 49152, 43008 }, { -239616, -230400, -221184, -211968 },
      { 258048, 251904, 245760, 239616 }, { -89088, -87552, -86016, -84480 } },
    { { -24576, -24576, -24576, -24576 }, { 36864, 36864, 36864, 36864 },
      { -24576, -24576, -24576, -24576 }, { 6144, 6144, 6144, 6144 } },
  };
  __m512i e[4];                             /* (Qk - Q0) in each point's lanes: x, y */
  for (int k = 0; k < 4; k++)
    e[k] = _mm512_broadcast_i64x2(_mm_set_epi64x(q[k + 1].y - q[0].y, q[k + 1].x - q[0].x));
  __m512i d[5];
  for (int o = 0; o < 5; o++) {
    __m512i v = _mm512_setzero_si512();
    for (int k = 0; k < 4; k++) {
      const int64_t *c = dn4[o][k];
      const __m512i ck = _mm512_set_epi64(c[3], c[3], c[2], c[2], c[1], c[1], c[0], c[0]);
      v = _mm512_add_epi64(v, _mm512_mullo_epi64(ck, e[k]));
    }
    d[o] = v;
  }
  d[0] = _mm512_add_epi64(d[0], _mm512_broadcast_i64x2(_mm_set_epi64x(
                                  q[0].y * ((int64_t)1 << 24), q[0].x * ((int64_t)1 << 24))));
  const __m512i bias = _mm512_set1_epi64(((int64_t)1 << 23) + ((int64_t)1 << 54));
  const __m512i off = _mm512_set1_epi64((int64_t)1 << 30);
  const __m512i expo = _mm512_set1_epi64((int64_t)0x4330000000000000);
  const __m128i off2 = _mm_set1_epi64x((int64_t)1 << 30), expo2 = _mm_set1_epi64x((int64_t)0x4330000000000000);
#define REGION_KEY(p) _mm_castsi128_pd(_mm_or_si128(                                    \
    _mm_add_epi64(_mm_loadu_si128((const __m128i *)(const void *)(p)), off2), expo2))
  const __m128d k0 = REGION_KEY(&poly[0]), k65 = REGION_KEY(&poly[CONTOUR_STEPS + 1]);
#undef REGION_KEY
  __m128d bl[REGION_BLOCKS], bh[REGION_BLOCKS];
  __m128d before = k0;                      /* the point before the block: poly[8 b] */
  for (int b = 0; b < REGION_BLOCKS - 1; b++) {
    __m512d k[2];
    for (int h = 0; h < 2; h++) {           /* steps 2 b + h: points i = 8 b + 4 h .. + 3 */
      const __m512i neg = _mm512_srai_epi64(d[0], 63);
      const __m512i sh = _mm512_srli_epi64(_mm512_add_epi64(_mm512_add_epi64(d[0], bias), neg), 24);
      const __m512i r = _mm512_sub_epi64(sh, off);
      /* (i = 0, poly[1]: Q4, not stored) */
      _mm512_mask_storeu_epi64(&poly[1 + 8 * b + 4 * h], (__mmask8)(b || h ? 0xff : 0xfc), r);
      k[h] = _mm512_castsi512_pd(_mm512_or_si512(sh, expo));
      d[0] = _mm512_add_epi64(d[0], d[1]);
      d[1] = _mm512_add_epi64(d[1], d[2]);
      d[2] = _mm512_add_epi64(d[2], d[3]);
      d[3] = _mm512_add_epi64(d[3], d[4]);
    }
    const __m512d lo8 = _mm512_min_pd(k[0], k[1]), hi8 = _mm512_max_pd(k[0], k[1]);
    const __m256d lo4 = _mm256_min_pd(_mm512_castpd512_pd256(lo8), _mm512_extractf64x4_pd(lo8, 1));
    const __m256d hi4 = _mm256_max_pd(_mm512_castpd512_pd256(hi8), _mm512_extractf64x4_pd(hi8, 1));
    const __m128d lo2 = _mm_min_pd(_mm256_castpd256_pd128(lo4), _mm256_extractf128_pd(lo4, 1));
    const __m128d hi2 = _mm_max_pd(_mm256_castpd256_pd128(hi4), _mm256_extractf128_pd(hi4, 1));
    bl[b] = _mm_min_pd(lo2, before);
    bh[b] = _mm_max_pd(hi2, before);
    before = _mm512_extractf64x2_pd(k[1], 3);   /* poly[8 b + 8] */
  }
  bl[REGION_BLOCKS - 1] = _mm_min_pd(_mm_min_pd(before, k65), k0);
  bh[REGION_BLOCKS - 1] = _mm_max_pd(_mm_max_pd(before, k65), k0);
  region_keys_out(bl, bh, blk, box);
}

/* Whether region_with takes region_exact512: where the processor has AVX-512F and DQ (and
   the system saves the registers: __builtin_cpu_supports) and sse2 (tests only:
   contour_region_sse2) is not asked. */
static inline bool region_avx512(bool sse2)
{
  return !sse2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
}
#endif

/* contour_region with the weights made, and the polygon's blocks and box (REGION_BLOCKS
   into blk: fx_ring_blocks' over the one ring). */
static void region_with(const struct gpoint q[5], const struct curve_weights *w,
                        struct gpoint poly[CONTOUR_STEPS + 2], gcoord (*blk)[2], gcoord box[4],
                        bool sse2)
{
  poly[0] = q[2];
  /* Q4, the curve back towards Q0, then Q0: CONTOUR_STEPS + 1 points */
  poly[1] = q[4];
  poly[1 + CONTOUR_STEPS] = q[0];
  bool exact = true;
  for (int k = 0; k < 5; k++)
    exact = exact && q[k].x > -CURVE_EXACT && q[k].x < CURVE_EXACT &&
            q[k].y > -CURVE_EXACT && q[k].y < CURVE_EXACT;
  if (exact) {
#ifdef REGION_AVX512
    if (region_avx512(sse2)) {
      region_exact512(q, poly, blk, box);
      return;
    }
#else
    (void)sse2;
#endif
    region_exact(q, poly, blk, box);
    return;
  }
  double d[5][2];
  for (int k = 0; k < 5; k++) { d[k][0] = (double)q[k].x; d[k][1] = (double)q[k].y; }
#ifdef __SSE2__
  /* a point's x and y an instruction: each lane bezier_with's products and sums on its
     values in its order (correctly rounded, as the scalar ones are) */
  __m128d dv[5];
  for (int k = 0; k < 5; k++) dv[k] = _mm_loadu_pd(d[k]);
#endif
  /* each curve point's coordinates below 2^62 when Q0..Q4's are below 2^61: the weights
     at m / 64 are exact (products of (64 - m) / 64 and m / 64, numerators below 2^27), in
     [0, 1] and summing to 1, and the five products and four sums each round within u, so
     |o| <= (1 + u)^5 max |d| < 2^62; round_grid's test then always passes: left out */
  bool small = true;
  for (int k = 0; k < 5; k++)
    small = small && fabs(d[k][0]) < 0x1p61 && fabs(d[k][1]) < 0x1p61;
  for (int m = CONTOUR_STEPS - 1; m >= 1; m--) {
    double o[2];
#ifdef __SSE2__
    const double (*b)[2] = w->b2[m];
    __m128d v = _mm_mul_pd(_mm_load_pd(b[0]), dv[0]);
    for (int k = 1; k < 5; k++) v = _mm_add_pd(v, _mm_mul_pd(_mm_load_pd(b[k]), dv[k]));
    _mm_storeu_pd(o, v);
#else
    bezier_with(d, w->b[m], o);
#endif
    poly[1 + CONTOUR_STEPS - m] = small ? (struct gpoint){ round_small(o[0]), round_small(o[1]) }
                                        : (struct gpoint){ round_grid(o[0]), round_grid(o[1]) };
  }
  region_blocks(poly, blk, box);
}

void contour_region(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2])
{
  gcoord blk[REGION_BLOCKS][2], box[4];
  region_with(q, &curve_table, poly, blk, box, false);
}

int contour_region_blocked(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2],
                           gcoord (*blk)[2], gcoord box[4])
{
  region_with(q, &curve_table, poly, blk, box, false);
  return REGION_BLOCKS;
}

int contour_region_sse2(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2],
                        gcoord (*blk)[2], gcoord box[4])
{
  region_with(q, &curve_table, poly, blk, box, true);
  return REGION_BLOCKS;
}

/* ---- the contour ------------------------------------------------------------------ */

struct cedge {
  int object;
  int a, b;                 /* scene vertices, directed with the triangle on the left */
  int tri;                  /* the front triangle */
};

enum { CONTOUR_INSERT = 64 };   /* contour sides sorted by insertion, at most */

static inline int by_from(const void *pa, const void *pb)
{
  const struct cedge *x = pa, *y = pb;
  if (x->object != y->object) return x->object < y->object ? -1 : 1;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  if (x->b != y->b) return x->b < y->b ? -1 : 1;
  return x->tri < y->tri ? -1 : x->tri > y->tri;
}

/* The projected grid point of scene vertex v in the mapped face mf. A triangle's (the
   smoothed objects' faces): its three points compared and the first match kept by
   selects (the last one made is the first), as which point matches is anyone's guess and
   a loop left there mispredicted about once a call (issue 19). The points are matched by
   their places in the scene's vertices (vix) rather than by their ids (vid = the id of
   vertex vix, and no two of the scene's vertices have one id: the scene reader refuses
   it), the same points without a load of v's id first. */
static inline bool mapped_point(const struct scene *s, const struct mface *mf, int v,
                                struct gpoint *out)
{
  (void)s;
  if (mf->ring_start[1] == 3) {
    const int32_t *vix = mf->vix;
    int at = vix[2] == v ? 2 : 3;
    at = vix[1] == v ? 1 : at;
    at = vix[0] == v ? 0 : at;
    if (at == 3) return false;
    *out = mf->pt[at];
    return true;
  }
  for (int k = 0; k < mf->ring_start[1]; k++)
    if (mf->vix[k] == v) { *out = mf->pt[k]; return true; }
  return false;
}

/* Whether a front triangle's three scene vertices v[0 .. 3) all lie on the mapped face mf
   (*ok) and turn counter-clockwise on the grid in that order (*ccw: geom_orient of their
   mapped points > 0), as mapped_point and geom_orient find them. Where mf's outer ring is
   a triangle (the smoothed objects' faces) without its points: the Mapper keeps an outer
   ring counter-clockwise with an area that is not 0 (mface.pt: its geom_orient > 0), so
   three points taken from it at places a0, a1, a2 turn counter-clockwise exactly when
   (a0, a1, a2) is a rotation of (0, 1, 2); taken another way round they turn clockwise,
   and with a place twice two of them are one point (geom_orient 0). */
static inline void tri_on_face(const struct scene *s, const struct mface *mf, const int v[3],
                               bool *ok, bool *ccw)
{
  if (mf->ring_start[1] == 3) {
    const int32_t *vix = mf->vix;
    int at[3];
    for (int k = 0; k < 3; k++) {             /* mapped_point's places, by selects */
      int a = vix[2] == v[k] ? 2 : 3;
      a = vix[1] == v[k] ? 1 : a;
      at[k] = vix[0] == v[k] ? 0 : a;
    }
    *ok = at[0] != 3 && at[1] != 3 && at[2] != 3;
    const int r1 = at[0] == 2 ? 0 : at[0] + 1, r2 = r1 == 2 ? 0 : r1 + 1;
    *ccw = at[1] == r1 && at[2] == r2;
    return;
  }
  struct gpoint p[3];
  bool found = true;
  for (int k = 0; k < 3; k++) found = found && mapped_point(s, mf, v[k], &p[k]);
  *ok = found;
  *ccw = found && geom_orient(p[0], p[1], p[2]) > 0;
}

/* Eq. (1) for a point in space, rounded onto the grid. */
static struct gpoint project(const struct mapped *map, const double x[3], struct cost *cost)
{
  const int64_t *e = map->eye;
  double f = (double)-e[2], w = x[2] - (double)e[2];
  struct gpoint p = {
    round_grid((double)GRID_ONE * ((double)e[0] + f * (x[0] - (double)e[0]) / w)),
    round_grid((double)GRID_ONE * ((double)e[1] + f * (x[1] - (double)e[1]) / w)) };
  if (cost)
    for (int k = 0; k < 2; k++) { cost_mw_mul(cost, 32, 32); cost_mw_div(cost, 64, 32); }
  return p;
}

/* The inset of triangle tr's side through corner vertex b other than the side b-a
   (the side opposite a), capped at 1/2 so neighbouring corners' curves do not meet. */
static double inset_at(const struct smooth_tri *tr, int a)
{
  for (int k = 0; k < 3; k++)
    if (tr->v[k] == a) return tr->t[k] < 0.5 ? tr->t[k] : 0.5;
  return 0.5;
}

void contour_corners_free(struct contour_corners *cs)
{
  free(cs->c);
  memset(cs, 0, sizeof *cs);
}

static bool corner_add(struct contour_corners *cs, const struct contour_corner *k)
{
  if (cs->n == cs->cap) {
    int cap = cs->cap ? 2 * cs->cap : 16;
    struct contour_corner *n = realloc(cs->c, (size_t)cap * sizeof *n);
    if (!n) return false;
    cs->c = n;
    cs->cap = cap;
  }
  cs->c[cs->n++] = *k;
  return true;
}

int contour_build(const struct mapped *map, struct core *core, const struct scene *s,
                  const struct effects *e, const struct smooth_model *m, struct fx_polys *cuts,
                  struct contour_corners *corners, struct fx_stats *st, struct cost *cost,
                  struct t74_error *err)
{
  int nfront = 0;
  for (int t = 0; t < m->ntri; t++) nfront += m->tri[t].front;
  struct cedge *ce = malloc(((size_t)nfront * 3 + 1) * sizeof *ce);
  int *cnt = calloc((size_t)m->ngroup + 1, sizeof *cnt);
  bool *use = malloc((size_t)m->ntri + 1);
  bool *ccw = malloc((size_t)m->ntri + 1);
  if (!ce || !cnt || !use || !ccw) {
    free(ce); free(cnt); free(use); free(ccw);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  /* the front triangles' sides, each group of sides on the same two vertices counted */
  int n = 0;
  for (int t = 0; t < m->ntri; t++) {
    const struct smooth_tri *tr = &m->tri[t];
    use[t] = false;
    if (!tr->front) continue;
    bool ok, turn;
    tri_on_face(s, &map->f[tr->mface], tr->v, &ok, &turn);
    if (!ok) continue;
    use[t] = true;
    ccw[t] = turn;
    for (int k = 0; k < 3; k++) cnt[m->edge_group[3 * t + k]]++;
    n += 3;
    if (cost) COST_ADD_N(cost, COST_MEM, 9);
  }
  /* contour sides: shared with no other front triangle of the object (a group of one) */
  int nc = 0;
  for (int t = 0; t < m->ntri; t++) {
    if (!use[t]) continue;
    const struct smooth_tri *tr = &m->tri[t];
    for (int k = 0; k < 3; k++) {
      if (cnt[m->edge_group[3 * t + k]] != 1) continue;
      int a = tr->v[k], b = tr->v[(k + 1) % 3];
      if (!ccw[t]) { int x = a; a = b; b = x; }
      ce[nc++] = (struct cedge){ tr->object, a, b, t };
    }
  }
  free(cnt); free(use); free(ccw);
  if (cost) COST_ADD_N(cost, COST_ADD, (uint64_t)n * 4);
  /* sorted by (object, a, b), then by triangle (a total order: the sides were listed by
     triangle, so ties keep the order they were listed in, as a stable sort keeps them,
     whichever sort runs and whatever the C library's qsort does with equal keys): a few
     dozen sides a frame by insertion, without qsort's call a compare; many by qsort */
  if (nc <= CONTOUR_INSERT)
    for (int k = 1; k < nc; k++) {
      const struct cedge x = ce[k];
      int h = k;
      for (; h > 0 && by_from(&ce[h - 1], &x) > 0; h--) ce[h] = ce[h - 1];
      ce[h] = x;
    }
  else
    qsort(ce, (size_t)nc, sizeof *ce, by_from);
  long convex = 0, concave = 0, junction = 0;
  uint32_t mark = core_mark(core), at = 0;
  int rc = T74_OK;
  /* one corner's region polygon at a time: each corner is cut before the next is made */
  if (nc > 0) rc = core_alloc(core, CONTOUR_TABLE, (CONTOUR_STEPS + 2) * 4, &at, err);
  /* each side's count of sides ending where it begins (in its object) and the last of
     them, and of sides beginning there: the sides sorted by (object, a), those beginning
     at a vertex lie together, found by halving */
  int *nin = calloc((size_t)nc + 1, sizeof *nin), *inc = malloc(((size_t)nc + 1) * sizeof *inc);
  if (rc == T74_OK && (!nin || !inc)) rc = t74_fail(err, T74_EIO, "out of host memory");
  for (int q = 0; rc == T74_OK && q < nc; q++) {
    const struct cedge key = { ce[q].object, ce[q].b, INT_MIN, 0 };
    int lo = 0, hi = nc;                     /* the first side at or after key */
    while (lo < hi) {
      const int mid = lo + (hi - lo) / 2;
      if (by_from(&ce[mid], &key) < 0) lo = mid + 1; else hi = mid;
    }
    for (; lo < nc && ce[lo].object == key.object && ce[lo].a == key.a; lo++) {
      nin[lo]++;
      inc[lo] = q;                           /* q rising: the last one */
    }
  }
  for (int k = 0; rc == T74_OK && k < nc; k++) {
    /* the incoming side of vertex ce[k].a: a side ending there, in the same object */
    const struct cedge *out = &ce[k];
    int nout = 1;
    for (int q = k - 1; q >= 0 && ce[q].object == out->object && ce[q].a == out->a; q--) nout++;
    for (int q = k + 1; q < nc && ce[q].object == out->object && ce[q].a == out->a; q++) nout++;
    if (cost) COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)nc);
    if (nin[k] != 1 || nout != 1) { junction++; continue; }
    const struct cedge *inw = &ce[inc[k]];
    const struct smooth_tri *A = &m->tri[inw->tri], *B = &m->tri[out->tri];
    struct gpoint pa, pb, pc;
    if (!mapped_point(s, &map->f[A->mface], inw->a, &pa) ||
        !mapped_point(s, &map->f[A->mface], out->a, &pb) ||
        !mapped_point(s, &map->f[B->mface], out->b, &pc)) { junction++; continue; }
    if (geom_orient(pa, pb, pc) <= 0) { concave++; continue; }
    convex++;
    /* Q0 on the incoming side, Q4 on the outgoing one, in space, then eq. (1) */
    const struct scene_vertex *va = &s->v[inw->a], *vb = &s->v[out->a], *vc = &s->v[out->b];
    double ta = inset_at(A, inw->a), tc = inset_at(B, out->b);
    double x0[3] = { vb->x + ta * (va->x - vb->x), vb->y + ta * (va->y - vb->y), vb->z + ta * (va->z - vb->z) };
    double x4[3] = { vb->x + tc * (vc->x - vb->x), vb->y + tc * (vc->y - vb->y), vb->z + tc * (vc->z - vb->z) };
    struct gpoint q[5];
    q[0] = project(map, x0, cost);
    q[2] = pb;
    q[4] = project(map, x4, cost);
    q[1].x = round_grid((double)q[2].x + e->contour * (double)(q[0].x - q[2].x));
    q[1].y = round_grid((double)q[2].y + e->contour * (double)(q[0].y - q[2].y));
    q[3].x = round_grid((double)q[2].x + e->contour * (double)(q[4].x - q[2].x));
    q[3].y = round_grid((double)q[2].y + e->contour * (double)(q[4].y - q[2].y));
    /* the region's polygon made where the list keeps it (fx_polys_room: no copy) */
    struct gpoint *poly = fx_polys_room(cuts, CONTOUR_STEPS + 2);
    if (!poly) { rc = t74_fail(err, T74_EIO, "out of host memory"); break; }
    gcoord box[4];
    region_with(q, &curve_table, poly, fx_polys_blocks_at(poly, CONTOUR_STEPS + 2), box, false);
    if (cost) {                   /* the 1974 engine's machine: counted, through core */
      COST_ADD_N(cost, COST_MEM, 4 * (CONTOUR_STEPS + 2));
      for (int c = 0; c < 2 * (CONTOUR_STEPS + 1); c++) {
        for (int h = 0; h < 4; h++) cost_mw_mul(cost, 32, 16);
        COST_ADD_N(cost, COST_ADD, 4);
      }
      for (int v = 0; v < CONTOUR_STEPS + 2; v++) {
        core_put_int(core, at + 4 * (uint32_t)v, 2, poly[v].x);
        core_put_int(core, at + 4 * (uint32_t)v + 2, 2, poly[v].y);
      }
    }
    /* the region joins the frame model (effects/model.h), which cuts it out of the
       object's stretches on every line asked for: procedure (D) (6) */
    int rs[2] = { 0, CONTOUR_STEPS + 2 };
    struct contour_corner cn = { out->object, inw->a, out->a, out->b, A->mface, B->mface,
                                { q[0], q[1], q[2], q[3], q[4] } };
    if (!fx_polys_close_made(cuts, 1, rs, out->object, 0, NULL, NULL, REGION_BLOCKS, box) ||
        !corner_add(corners, &cn))
      rc = t74_fail(err, T74_EIO, "out of host memory");
  }
  if (rc == T74_OK) {
    fx_count(st, "contour_sides", nc, true);
    fx_count(st, "contour_corners_convex", (double)convex, true);
    fx_count(st, "contour_corners_concave", (double)concave, true);
    fx_count(st, "contour_corners_junction", (double)junction, true);
  }
  core_release(core, mark);
  free(nin); free(inc);
  free(ce);
  return rc;
}
