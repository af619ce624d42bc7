/*
** test_shade.c — cmocka tests of the shading law's two-points-an-instruction form
** (render/shade.h: shade_pair_init, shade_pair_sum, shade_pair_greys,
** shade_pair_dot_axis).
**
** The points engine shades a flat face's lit points two at a time (effects/model.c,
** flat_lit_pairs). Each lane must give shade_grey_lit's grey bit for bit: at points spread
** through space under parallel and point lights, with each lane's own reflectance and
** blocked lights, and at points bisected onto the borders between two greys (neighbouring
** doubles of the parameter), where a sum one unit in the last place off would show as
** another grey; also where the grey's f leaves the range the packed conversion takes
** (a reflectance out of [0, 1], NaN and infinite points).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "render/shade.h"

#ifdef __SSE2__
static uint64_t next(uint64_t *s)
{
  *s = *s * 6364136223846793005u + 1442695040888963407u;
  return *s >> 11;
}

static double uniform(uint64_t *s, double lo, double hi)
{
  return lo + (hi - lo) * (double)next(s) / 0x1p53;
}

/* v made a unit vector in place (the divisions shade_lights_init and face_normal make). */
static void unit3(double v[3])
{
  const double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int c = 0; c < 3; c++) v[c] /= len;
}

/* The unit normal turned away from plane p's coefficients (-p, made a unit vector). */
static void plane_normal(const int p[3], double n[3])
{
  for (int c = 0; c < 3; c++) n[c] = -(double)p[c];
  unit3(n);
}

/* The greys of points A (lane 0) and B (lane 1) by shade_pair_* and by shade_grey_lit;
   the number of lanes that differ. */
static int pair_differs(const struct shade_lights *L, const struct shade_pair *P,
                        const double n[3], const double A[3], const double B[3], double ra,
                        double rb, unsigned ba, unsigned bb, int *ga)
{
  const __m128d x = _mm_set_pd(B[0], A[0]), y = _mm_set_pd(B[1], A[1]);
  const __m128d z = _mm_set_pd(B[2], A[2]);
  const unsigned g = shade_pair_greys(_mm_set_pd(rb, ra), shade_pair_sum(P, x, y, z, ba, bb));
  const int one = shade_grey_lit(L, n, A, ra, ba), two = shade_grey_lit(L, n, B, rb, bb);
  *ga = one;
  return ((g & 0xffu) != (unsigned)(uint8_t)one) + ((g >> 8) != (unsigned)(uint8_t)two);
}

static void test_pairs_are_single(void **state)
{
  (void)state;
  struct shade_lights L;
  memset(&L, 0, sizeof L);
  static const double lv[][4] = {           /* point?, position or direction */
    { 0, 4, 3, -2 }, { 1, -300, 650, 1200 }, { 1, 900, 500, -200 }, { 0, -3, 2, -2 },
    { 1, 40, -2000, 310 }, { 0, 0, 0, 1 } };
  static const int planes[][3] = { { 0, 0, -1 }, { -3, 2, -5 }, { 7, -1, -4 }, { 1, 1, 1 },
                                   { 0, -1, 0 }, { -20, 3, 11 } };
  uint64_t seed = 2026;
  long differ = 0, borders = 0, pairs = 0;
  int greys[256] = { 0 };
  /* the lights' first 1 .. 6 in the table's order, and the point lights alone */
  for (int set = 1; set <= 7; set++) {
    L.n = 0;
    for (int k = 0; k < 6; k++) {
      if (set <= 6 ? k >= set : lv[k][0] == 0) continue;
      L.point[L.n] = lv[k][0] != 0;
      for (int c = 0; c < 3; c++) L.v[L.n][c] = lv[k][c + 1];
      L.n++;
    }
    struct shade_lights ready;
    memset(&ready, 0, sizeof ready);
    ready.n = L.n;
    for (int k = 0; k < L.n; k++) {         /* shade_lights_init's unit directions */
      ready.point[k] = L.point[k];
      memcpy(ready.v[k], L.v[k], sizeof ready.v[k]);
      if (!ready.point[k]) unit3(ready.v[k]);
    }
    for (size_t pl = 0; pl < sizeof planes / sizeof *planes; pl++) {
      double n[3];
      plane_normal(planes[pl], n);
      struct shade_pair P;
      shade_pair_init(&P, &ready, n);
      for (int it = 0; it < 600; it++) {
        double A[3], B[3];
        for (int c = 0; c < 3; c++) { A[c] = uniform(&seed, -1500, 1500); B[c] = uniform(&seed, -1500, 1500); }
        const unsigned mask = (1u << L.n) - 1;
        const unsigned ba = it % 3 ? (unsigned)next(&seed) & mask : 0;
        const unsigned bb = it % 5 ? (unsigned)next(&seed) & mask : 0;
        const double ra = it % 4 ? (double)(next(&seed) & 255) / 255 : 1.0;
        const double rb = it % 7 ? (double)(next(&seed) & 255) / 255 : 1.0;
        int ga;
        differ += pair_differs(&ready, &P, n, A, B, ra, rb, ba, bb, &ga);
        greys[ga & 255] = 1;
        pairs++;
        /* the border between A's and B's greys (unblocked, r = 1), in both lanes */
        const int g0 = shade_grey_lit(&ready, n, A, 1.0, 0), g1 = shade_grey_lit(&ready, n, B, 1.0, 0);
        if (g0 == g1) continue;
        double s0 = 0, s1 = 1, M0[3], M1[3];
        for (int b = 0; b < 200; b++) {
          const double sm = 0.5 * (s0 + s1);
          if (!(sm > s0 && sm < s1)) break;
          double M[3];
          for (int c = 0; c < 3; c++) M[c] = A[c] + sm * (B[c] - A[c]);
          if (shade_grey_lit(&ready, n, M, 1.0, 0) == g0) s0 = sm; else s1 = sm;
        }
        for (int c = 0; c < 3; c++) {
          M0[c] = A[c] + s0 * (B[c] - A[c]);
          M1[c] = A[c] + s1 * (B[c] - A[c]);
        }
        differ += pair_differs(&ready, &P, n, M0, M1, 1.0, 1.0, 0, 0, &ga);
        differ += pair_differs(&ready, &P, n, M1, M0, 1.0, 1.0, 0, 0, &ga);
        borders++;
      }
      /* outside the packed conversion's range: a negative reflectance, a huge one, NaN
         and infinite points (each lane on its own; the other an ordinary one) */
      const double odd[][3] = { { NAN, 0, 0 }, { INFINITY, 5, 5 }, { 1e300, -1e300, 1e300 },
                                { 0, 0, 0 }, { -300, 650, 1200 } };
      const double rs[] = { -1.0 / 255, 1e12, 1.0, NAN };
      const double ok[3] = { 10, 20, 30 };
      for (size_t o = 0; o < sizeof odd / sizeof *odd; o++)
        for (size_t r = 0; r < sizeof rs / sizeof *rs; r++) {
          int ga2;
          differ += pair_differs(&ready, &P, n, odd[o], ok, rs[r], 1.0, 0, 1, &ga2);
          differ += pair_differs(&ready, &P, n, ok, odd[o], 0.5, rs[r], 2, 0, &ga2);
        }
    }
  }
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += greys[g];
  print_message("pairs: %ld pairs, %ld borders, %d greys, %ld lanes differ\n", pairs, borders,
                distinct, differ);
  assert_int_equal(differ, 0);
  assert_true(borders > 1000 && distinct > 100);
}

/* flat_lit_pairs keeps a pair's sums while the next pair's masks are the same, where both
   lanes have every point light blocked: there shade_pair_sum must not depend on the space
   points (the same bits at any X, NaN and infinite ones too, as at X = 0), and the greys
   from those sums must be shade_grey_lit's at each lane's own point. Fails if a blocked
   light's term were made by a multiply (NaN times 0 is NaN) or the sum read X for a
   parallel light. */
static void test_point_lights_blocked(void **state)
{
  (void)state;
  static const double lv[][4] = {           /* point?, position or direction */
    { 0, 4, 3, -2 }, { 1, -300, 650, 1200 }, { 0, -3, 2, -2 }, { 1, 900, 500, -200 },
    { 0, 0, 0, 1 } };
  static const int planes[][3] = { { 0, 0, -1 }, { -3, 2, -5 }, { 0, -1, 0 }, { 7, -1, -4 } };
  struct shade_lights L;
  memset(&L, 0, sizeof L);
  unsigned pm = 0;
  for (int k = 0; k < 5; k++) {
    L.point[k] = lv[k][0] != 0;
    for (int c = 0; c < 3; c++) L.v[k][c] = lv[k][c + 1];
    if (!L.point[k]) unit3(L.v[k]);
    else pm |= 1u << k;
  }
  L.n = 5;
  uint64_t seed = 74;
  long differ = 0, tried = 0;
  int greys[256] = { 0 };
  const __m128d zero = _mm_setzero_pd();
  for (size_t pl = 0; pl < sizeof planes / sizeof *planes; pl++) {
    double n[3];
    plane_normal(planes[pl], n);
    struct shade_pair P;
    shade_pair_init(&P, &L, n);
    for (int it = 0; it < 400; it++) {
      /* both lanes with the point lights blocked, the parallel ones as it comes */
      const unsigned ba = pm | ((unsigned)next(&seed) & 31u), bb = pm | ((unsigned)next(&seed) & 31u);
      double A[3], B[3];
      for (int c = 0; c < 3; c++) { A[c] = uniform(&seed, -1500, 1500); B[c] = uniform(&seed, -1500, 1500); }
      if (it % 50 == 0) { A[0] = NAN; B[1] = INFINITY; }
      const __m128d s0 = shade_pair_sum(&P, zero, zero, zero, ba, bb);
      const __m128d sx = shade_pair_sum(&P, _mm_set_pd(B[0], A[0]), _mm_set_pd(B[1], A[1]),
                                        _mm_set_pd(B[2], A[2]), ba, bb);
      differ += _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_castpd_si128(s0), _mm_castpd_si128(sx))) != 0xffff;
      if (it % 50 == 0) { A[0] = 1; B[1] = 2; }   /* (shade_grey_lit reads no point here) */
      const double ra = it % 3 ? (double)(next(&seed) & 255) / 255 : 1.0, rb = 1.0;
      const unsigned g = shade_pair_greys(_mm_set_pd(rb, ra), s0);
      const int one = shade_grey_lit(&L, n, A, ra, ba), two = shade_grey_lit(&L, n, B, rb, bb);
      differ += ((g & 0xffu) != (unsigned)(uint8_t)one) + ((g >> 8) != (unsigned)(uint8_t)two);
      greys[one & 255] = greys[two & 255] = 1;
      tried++;
    }
  }
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += greys[g];
  print_message("point lights blocked: %ld pairs, %d greys, %ld differ\n", tried, distinct, differ);
  assert_int_equal(differ, 0);
  assert_true(distinct > 10);
}

/* shade_pair_dot_axis against shade_pair_dot, bit for bit, on faces square to each axis
   (either side) under point lights: at points spread through space, at the light itself
   (length 0), a hair from it (squares that underflow), far from it (squares that
   overflow) and at NaN and infinite points, a NaN or infinite coordinate in each place
   (the case where shade_pair_dot divides by 1 and this one must still give +0). Also
   shade_pair_init's axis: the one coordinate where the normal is not 0, else -1. Fails if
   the divisor of a NaN length were 1 here, or a dropped term could change the sum. */
static void test_dot_axis(void **state)
{
  (void)state;
  static const int planes[][3] = { { 0, 0, -1 }, { 0, 0, 3 }, { 0, -1, 0 }, { 0, 7, 0 },
                                   { -2, 0, 0 }, { 5, 0, 0 }, { -3, 2, -5 }, { 0, 1, 1 } };
  static const int axis[] = { 2, 2, 1, 1, 0, 0, -1, -1 };
  static const double lp[][3] = { { -300, 650, 1200 }, { 900, 500, -200 }, { 0, 0, 0 },
                                  { 1e-160, -1e-161, 3e-162 } };
  struct shade_lights L;
  memset(&L, 0, sizeof L);
  L.n = 4;
  for (int k = 0; k < 4; k++) {
    L.point[k] = true;
    memcpy(L.v[k], lp[k], sizeof L.v[k]);
  }
  uint64_t seed = 36;
  long differ = 0, tried = 0, positive = 0;
  for (size_t pl = 0; pl < sizeof planes / sizeof *planes; pl++) {
    double n[3];
    plane_normal(planes[pl], n);
    struct shade_pair P;
    shade_pair_init(&P, &L, n);
    assert_int_equal(P.axis, axis[pl]);
    if (P.axis < 0) continue;
    for (int k = 0; k < L.n; k++)
      for (int it = 0; it < 400; it++) {
        double A[3], B[3];
        for (int c = 0; c < 3; c++) {
          A[c] = uniform(&seed, -1500, 1500);
          B[c] = lp[k][c] + uniform(&seed, -1, 1) * 1e-170;   /* a hair from the light */
        }
        if (it % 4 == 1) memcpy(B, lp[k], sizeof B);         /* at the light */
        if (it % 4 == 2)
          for (int c = 0; c < 3; c++) B[c] = uniform(&seed, -1, 1) * 1e300;
        if (it % 8 == 3) {                  /* a NaN or infinite coordinate, each place */
          const double odd[] = { NAN, INFINITY, -INFINITY };
          A[it / 8 % 3] = odd[it / 24 % 3];
          B[(it / 8 + 1) % 3] = odd[(it / 24 + 1) % 3];
        }
        const __m128d X[3] = { _mm_set_pd(B[0], A[0]), _mm_set_pd(B[1], A[1]),
                               _mm_set_pd(B[2], A[2]) };
        const __m128d d0 = shade_pair_dot(&P.l[k], P.nv, X[0], X[1], X[2]);
        const __m128d d1 = shade_pair_dot_axis(&P.l[k], P.nv[P.axis], P.axis, X);
        differ += _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_castpd_si128(d0),
                                                   _mm_castpd_si128(d1))) != 0xffff;
        positive += _mm_movemask_pd(_mm_cmpgt_pd(d0, _mm_setzero_pd())) != 0;
        tried++;
      }
  }
  print_message("dot axis: %ld pairs, %ld with a lit lane, %ld differ\n", tried, positive, differ);
  assert_int_equal(differ, 0);
  assert_true(positive > tried / 4);
}
#endif

int main(void)
{
#ifdef __SSE2__
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_pairs_are_single),
    cmocka_unit_test(test_point_lights_blocked),
    cmocka_unit_test(test_dot_axis),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
#else
  return 77;                                /* no SSE2: nothing of it to test */
#endif
}
