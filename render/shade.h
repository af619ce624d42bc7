/*
** shade.h — a face's intensity from the scene's lights (Lambert's law with an ambient
** floor; paper 003 reads intensities from its input, paper 000 §3.3 (1) makes a polygon's
** colour I(S) its reflectance times its illumination, from several lights).
**
** This file declares the one shading law every stage uses: the Mapper for a face's flat
** grey, the effects (effects/) for the intensity at a point of a face (smooth shading's
** interpolated normals, a texture's reflectance, the lights a shadow blocks).
**
**   grey = AMBIENT + (255 - AMBIENT) * r * sum over the lights k not blocked of max(0, n.l_k)
**
** clamped to 255 and rounded to nearest, with n the unit normal on the eye's side, l_k
** the unit direction towards light k (a parallel light's own direction; a point light's
** from the shaded point), r the reflectance 0..1 (1 without a texture). The ambient floor
** is what a face turned away from every light (or in every light's shadow) shows; it is
** not scaled by r, so a texture's dark parts stay visible as the ambient grey (the tube
** cannot go below it for a lit face). With one parallel light and r = 1 this is exactly
** the Mapper's integer law (render/mapper.c), which it keeps for that case.
*/
#ifndef T74_SHADE_H
#define T74_SHADE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "render/scene.h"

#define SHADE_AMBIENT 48            /* the grey of a face no light reaches (tuned by eye) */

/* The unit direction from space point at towards light k of s. */
void shade_dir(const struct scene *s, int k, const double at[3], double l[3]);

/* Grey at space point at with unit normal n (on the eye's side) and reflectance r; the
   lights whose bit is set in blocked (bit k: light k) are in shadow there. */
int shade_grey(const struct scene *s, const double n[3], const double at[3], double r,
               unsigned blocked);

/* The scene's lights made ready for shading many points (the effects' per-point work):
   a parallel light's unit direction found once (shade_dir's, the same doubles), a point
   light's position as doubles. */
struct shade_lights {
  int n;
  bool point[SCENE_LIGHT_MAX];
  double v[SCENE_LIGHT_MAX][3];     /* unit direction (parallel) or position (point) */
};
void shade_lights_init(struct shade_lights *L, const struct scene *s);

/* The unit direction from at towards a point light at v (shade_dir's). */
void shade_point_dir(const double v[3], const double at[3], double l[3]);

/* The grey of reflectance r under the lights' sum of n.l (shade_grey_lit's last step). */
static inline int shade_grey_of_sum(double r, double sum)
{
  /* floor of a non-negative double below 2^62 is its truncation: no library call */
  double f = (255 - SHADE_AMBIENT) * r * sum + 0.5;
  double g = SHADE_AMBIENT + (f >= 0 && f < 0x1p62 ? (double)(int64_t)f : floor(f));
  return g > 255 ? 255 : (int)g;
}

/* shade_grey with the lights made ready: the same value, bit for bit. Inline: the effects
   call it at every shaded point. */
static inline int shade_grey_lit(const struct shade_lights *L, const double n[3],
                                 const double at[3], double r, unsigned blocked)
{
  double sum = 0;
  for (int k = 0; k < L->n; k++) {
    if (blocked >> k & 1u) continue;
    const double *l = L->v[k];
    double pl[3];
    if (L->point[k]) {
      shade_point_dir(l, at, pl);
      l = pl;
    }
    double d = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    if (d > 0) sum += d;
  }
  return shade_grey_of_sum(r, sum);
}

/* shade_grey_lit at np <= SHADE_RUN points at[p] that share the unit normal n (a flat
   face's), with reflectance r[p] and the lights blocked[p]: the same greys, bit for bit
   (each point's own operations on its own values, in its own order), found together: a
   parallel light's n.l once for all of them, a point light's directions with two points'
   square roots and divides an instruction (SSE2's are correctly rounded, as the scalar
   ones are). */
#define SHADE_RUN 16
void shade_grey_lit_run(const struct shade_lights *L, const double n[3], int np,
                        const double (*at)[3], const double *r, const unsigned *blocked,
                        int *grey);


#ifdef __SSE2__
#include <emmintrin.h>

/* ---- two points an instruction (SSE2) ----
   A flat face's points shaded two at a time, each lane's operations shade_grey_lit's on
   its own values in their order (SSE2's adds, multiplies, divides and square roots are
   correctly rounded, as the scalar ones are): a point light's direction from the point
   divided by its length where the length is > 0 (else divided by 1, which leaves it);
   a light blocked at a lane, or a dot not > 0, adds +0 there, which leaves the lane's
   sum as it is (it starts at +0 and only grows: never -0). */

/* The lights made ready for the points of one flat face of unit normal n (shade_pair_sum),
   in the scene's order: each value broadcast to both lanes. */
struct shade_pair {
  int n;
  struct shade_pair_light {
    __m128d v[3];                   /* a point light's position; a parallel light's n.l
                                       where > 0, else +0, in v[0] */
    __m128i bit;                    /* its bit in a blocked mask, in every lane */
    bool point;
  } l[SCENE_LIGHT_MAX];
  __m128d nv[3];                    /* the normal */
  int axis;                         /* the one coordinate where the normal is not 0 (the
                                       other two are), or -1 (shade_pair_dot_axis) */
};
void shade_pair_init(struct shade_pair *P, const struct shade_lights *L, const double n[3]);

/* Light l's n.l where > 0, else +0, at space points (x, y, z) (nv: the normal). */
static inline __m128d shade_pair_dot(const struct shade_pair_light *l, const __m128d nv[3],
                                     __m128d x, __m128d y, __m128d z)
{
  if (!l->point) return l->v[0];
  const __m128d zero = _mm_setzero_pd();
  const __m128d lx = _mm_sub_pd(l->v[0], x), ly = _mm_sub_pd(l->v[1], y);
  const __m128d lz = _mm_sub_pd(l->v[2], z);
  const __m128d s = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(lx, lx), _mm_mul_pd(ly, ly)),
                                           _mm_mul_pd(lz, lz)));
  const __m128d pos = _mm_cmpgt_pd(s, zero);
  const __m128d div = _mm_or_pd(_mm_and_pd(pos, s), _mm_andnot_pd(pos, _mm_set1_pd(1)));
  const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(nv[0], _mm_div_pd(lx, div)),
                                          _mm_mul_pd(nv[1], _mm_div_pd(ly, div))),
                               _mm_mul_pd(nv[2], _mm_div_pd(lz, div)));
  return _mm_and_pd(_mm_cmpgt_pd(d, zero), d);
}

/* shade_pair_dot of point light l where the normal is 0 in every coordinate but c (P's
   axis; nc: the normal's coordinate c), space points (x, y, z): the same doubles, with one
   divide and one multiply where shade_pair_dot has three of each. Its d is
   (n0 q0 + n1 q1) + n2 q2 with q the direction l / div; here it is nc qc alone, qc made as
   there (the same subtraction, the same divisor where s is not NaN). Lane by lane:
   - s > 0 and finite: every l is finite (an infinite or NaN one makes s infinite or NaN)
     and every q is finite (|q| = |l| / s, s at least about |l| or the other squares' root
     where l's square underflows: far below any overflow), so each dropped term 0 q is a
     zero; a zero added to the kept term x leaves x when x is not a zero, and where x is a
     zero (or NaN) so is the whole sum (or NaN), not > 0: +0 both ways.
   - s a zero: div is 1, each q is its finite l, the same as above.
   - s infinite: each finite l gives q a zero, an infinite l gives NaN; a NaN term anywhere
     makes shade_pair_dot's d NaN, so +0; here qc is a zero or NaN: +0 too (and where no l
     is infinite every term is a zero: +0 both ways).
   - s NaN (some l NaN): shade_pair_dot divides by 1 and the NaN q makes its d NaN, +0;
     here the divisor is s itself (the compare "not equal to 0" holds for a NaN as for an
     s > 0), so qc is NaN and the answer +0.
   The compare and the AND are shade_pair_dot's. */
static inline __m128d shade_pair_dot_axis(const struct shade_pair_light *l, __m128d nc, int c,
                                          const __m128d X[3])
{
  const __m128d zero = _mm_setzero_pd();
  const __m128d lx = _mm_sub_pd(l->v[0], X[0]), ly = _mm_sub_pd(l->v[1], X[1]);
  const __m128d lz = _mm_sub_pd(l->v[2], X[2]);
  const __m128d s = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(lx, lx), _mm_mul_pd(ly, ly)),
                                           _mm_mul_pd(lz, lz)));
  const __m128d keep = _mm_cmpneq_pd(s, zero);
  const __m128d div = _mm_or_pd(_mm_and_pd(keep, s), _mm_andnot_pd(keep, _mm_set1_pd(1)));
  const __m128d d = _mm_mul_pd(nc, _mm_div_pd(_mm_sub_pd(l->v[c], X[c]), div));
  return _mm_and_pd(_mm_cmpgt_pd(d, zero), d);
}

/* The lanes' sums of n.l over the lights not blocked at space points (x, y, z), lane 0's
   lights blocked b0, lane 1's b1: shade_grey_lit's sum, lane by lane. */
static inline __m128d shade_pair_sum(const struct shade_pair *P, __m128d x, __m128d y,
                                     __m128d z, unsigned b0, unsigned b1)
{
  const struct shade_pair_light *l = P->l, *end = P->l + P->n;
  __m128d sum = _mm_setzero_pd();
  if (!(b0 | b1)) {                         /* none blocked */
    for (; l < end; l++) sum = _mm_add_pd(sum, shade_pair_dot(l, P->nv, x, y, z));
    return sum;
  }
  /* b0 in lane 0's two halves, b1 in lane 1's: a lane's light is not blocked where its
     bit of them is 0, the whole lane's mask from the halves' compares */
  const __m128i b = _mm_shuffle_epi32(_mm_unpacklo_epi32(_mm_cvtsi32_si128((int)b0),
                                                         _mm_cvtsi32_si128((int)b1)),
                                      _MM_SHUFFLE(1, 1, 0, 0));
  for (; l < end; l++) {
    const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(b, l->bit), _mm_setzero_si128());
    sum = _mm_add_pd(sum, _mm_and_pd(_mm_castsi128_pd(lit), shade_pair_dot(l, P->nv, x, y, z)));
  }
  return sum;
}

/* The greys SHADE_AMBIENT + t of the two low lanes of t (ints in [0, 2^15 - 49)) as two
   bytes, lane 0's low: the two saturating packs leave each at most 255 as it is and make
   it 255 above (the clamp). */
static inline unsigned shade_pair_pack(__m128i t)
{
  const __m128i a = _mm_add_epi32(t, _mm_set1_epi32(SHADE_AMBIENT));
  const __m128i b = _mm_packus_epi16(_mm_packs_epi32(a, a), _mm_setzero_si128());
  return (unsigned)_mm_cvtsi128_si32(b) & 0xffffu;
}

/* The two lanes' greys of reflectance r under sums sum (shade_grey_of_sum's, lane by
   lane) where both lanes' f lie in [0, 2^30) (no NaN): true, lane 0's grey in the low byte
   of *g, lane 1's in the next. There its truncation is CVTTPD2DQ's, f above 512 gives 255
   as f does (48 + 512 > 255), and the two saturating packs leave 48 + t when it is at most
   255 and make it 255 above it: the clamp. Else false, *g not set. */
static inline bool shade_pair_greys_fast(__m128d r, __m128d sum, unsigned *g)
{
  const __m128d f = _mm_add_pd(_mm_mul_pd(_mm_mul_pd(_mm_set1_pd(255 - SHADE_AMBIENT), r), sum),
                               _mm_set1_pd(0.5));
  if (_mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(f, _mm_setzero_pd()),
                                 _mm_cmplt_pd(f, _mm_set1_pd(0x1p30)))) != 3)
    return false;
  *g = shade_pair_pack(_mm_cvttpd_epi32(_mm_min_pd(f, _mm_set1_pd(512))));
  return true;
}

/* The two lanes' greys (shade_grey_of_sum's, lane by lane, as bytes): lane 0's in the low
   byte, lane 1's in the next; shade_pair_greys_fast's where it takes them. */
static inline unsigned shade_pair_greys(__m128d r, __m128d sum)
{
  unsigned g;
  if (shade_pair_greys_fast(r, sum, &g)) return g;
  double rr[2], ss[2];
  _mm_storeu_pd(rr, r);
  _mm_storeu_pd(ss, sum);
  return (unsigned)(uint8_t)shade_grey_of_sum(rr[0], ss[0]) |
         (unsigned)(uint8_t)shade_grey_of_sum(rr[1], ss[1]) << 8;
}
#endif

#endif
