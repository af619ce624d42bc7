/*
** test_render.c — unit tests of the render core (render/geom, seginfo, priority, visible)
** linked against build/libtube74.a.
**
** geom: orientation signs, oriented lines, rationals at exact ties, 256-bit products at
** the ends of the 128-bit range. seginfo: the tie rule of seginfo_span, clipping by a line
** (diagonal, through a vertex, along a side), the overlap test. priority: parallel,
** crossing and coplanar faces, each pair computed once, dense and sparse stores agree.
** visible: exact spans on hand-made lines. Run from the repository root.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"
#include "render/mapper.h"
#include "render/points.h"
#include "render/pool.h"
#include "render/priority.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/seginfo.h"
#include "render/visible.h"
#include "render/vis_x.h"

#define G(v) ((gcoord)(v) * GRID_ONE)          /* world units -> plane grid */

static const wide W128_MAX = (wide)(((uwide)1 << 127) - 1);
static const wide W128_MIN = -(wide)(((uwide)1 << 127) - 1) - 1;

/* ---- helpers ------------------------------------------------------------------------ */

static char tmpdir[64];

static int group_setup(void **state)
{
  (void)state;
  strcpy(tmpdir, "/tmp/t74render.XXXXXX");
  return mkdtemp(tmpdir) ? 0 : -1;
}

static int group_teardown(void **state)
{
  (void)state;
  char cmd[128];
  /* remove the scenes written (plain unlink of the files we know, then the dir) */
  for (int k = 0; k < 64; k++) {
    snprintf(cmd, sizeof cmd, "%s/s%d.s74", tmpdir, k);
    unlink(cmd);
  }
  rmdir(tmpdir);
  return 0;
}

static int nscene;

/* Write a scene and load it. */
static struct scene *load_scene(const char *text)
{
  char path[128];
  snprintf(path, sizeof path, "%s/s%d.s74", tmpdir, nscene++ % 64);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct scene *s = NULL;
  struct t74_error err = { 0, "" };
  int st = scene_load(path, &so, &s, &err);
  if (st) print_message("scene_load: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  assert_non_null(s);
  return s;
}

/* render_prepare (or render_prepare_lazy) of a loaded scene on 2^22 words of core. */
static void prepare_scene(struct render *r, const struct scene *s, int store, bool lazy,
                          struct render_keep *keep)
{
  struct render_opts o;
  memset(&o, 0, sizeof o);
  o.core_words = 1u << 22;
  o.store = store;
  o.keep = keep;
  struct t74_error err = { 0, "" };
  int st = lazy ? render_prepare_lazy(r, s, &o, &err) : render_prepare(r, s, &o, &err);
  if (st) print_message("render_prepare: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
}

static struct scene *prepare(struct render *r, const char *text, int store)
{
  struct scene *s = load_scene(text);
  prepare_scene(r, s, store, false, NULL);
  return s;
}

static bool h_is(struct hpoint p, gcoord x, gcoord y)
{
  return p.W > 0 && p.X == (wide)x * p.W && p.Y == (wide)y * p.W;
}

static bool rat_is(struct grat r, int64_t n, int64_t d)
{
  return r.den > 0 && geom_rat_cmp_frac(r, n, d) == 0;
}

/* A piece from a CCW list of grid points (n <= 80). Returns its index. */
static int add_piece(struct seginfo *t, int face, int n, const gcoord *xy)
{
  struct gline l[80];
  assert_true(n <= 80);
  for (int k = 0; k < n; k++) {
    struct gpoint p = { xy[2 * k], xy[2 * k + 1] };
    struct gpoint q = { xy[2 * ((k + 1) % n)], xy[2 * ((k + 1) % n) + 1] };
    l[k] = geom_line(p, q);
  }
  struct t74_error err = { 0, "" };
  int idx = seginfo_add(t, face, n, l, &err);
  if (idx < 0) print_message("seginfo_add: %s\n", err.msg);
  assert_true(idx >= 0);
  return idx;
}

/* Does the polygon (n vertices) have exactly the vertices xy (any cyclic start)? */
static bool poly_has(int n, const struct hpoint *v, int m, const gcoord *xy)
{
  if (n != m) return false;
  for (int k = 0; k < m; k++) {
    bool found = false;
    for (int j = 0; j < n; j++) found |= h_is(v[j], xy[2 * k], xy[2 * k + 1]);
    if (!found) return false;
  }
  return true;
}

/* ---- geom ----------------------------------------------------------------------------- */

/* geom_orient: CCW positive, CW negative, collinear zero, exact at the grid's corners. */
static void test_geom_orient(void **state)
{
  (void)state;
  struct gpoint o = { 0, 0 }, x = { 1, 0 }, y = { 0, 1 }, d = { 2, 2 };
  assert_true(geom_orient(o, x, y) == 1);
  assert_true(geom_orient(o, y, x) == -1);
  assert_true(geom_orient(o, (struct gpoint){ 1, 1 }, d) == 0);
  const gcoord L = GRID_LIMIT;
  struct gpoint a = { -L, -L }, b = { L, -L }, c = { L, L };
  assert_true(geom_orient(a, b, c) == (wide)4 * L * L);
  assert_true(geom_orient(a, c, b) == -(wide)4 * L * L);
  /* one unit off a long diagonal */
  assert_true(geom_orient(a, c, (struct gpoint){ L - 1, L }) > 0);
  assert_true(geom_orient(a, c, (struct gpoint){ L, L - 1 }) < 0);
}

/* geom_line / geom_side / geom_hline: the interior (positive side) is on the LEFT. */
static void test_geom_lines(void **state)
{
  (void)state;
  struct gline l = geom_line((struct gpoint){ 0, 0 }, (struct gpoint){ 10, 0 });
  assert_true(geom_is_horizontal(l));
  assert_int_equal(geom_side(l, (struct gpoint){ 5, 1 }), 1);
  assert_int_equal(geom_side(l, (struct gpoint){ 5, -1 }), -1);
  assert_int_equal(geom_side(l, (struct gpoint){ 50, 0 }), 0);
  struct gline up = geom_line((struct gpoint){ 3, -7 }, (struct gpoint){ 3, 9 });
  assert_int_equal(geom_side(up, (struct gpoint){ 2, 100 }), 1);    /* left = smaller x */
  assert_int_equal(geom_side(up, (struct gpoint){ 4, 100 }), -1);
  assert_int_equal(geom_side(up, (struct gpoint){ 3, 1000 }), 0);
  struct gline h = geom_hline(5, true), hd = geom_hline(5, false);
  assert_int_equal(geom_side(h, (struct gpoint){ -9, 6 }), 1);
  assert_int_equal(geom_side(h, (struct gpoint){ -9, 5 }), 0);
  assert_int_equal(geom_side(h, (struct gpoint){ -9, 4 }), -1);
  assert_int_equal(geom_side(hd, (struct gpoint){ -9, 4 }), 1);
  /* meet: x = 3 and y = 5 meet at (3, 5); parallel lines do not meet */
  struct hpoint m = { 0, 0, 1 };
  assert_true(geom_meet(up, h, &m));
  assert_true(h_is(m, 3, 5));
  assert_int_equal(geom_side_h(l, m), 1);
  assert_int_equal(geom_side_h(h, m), 0);
  assert_false(geom_meet(h, hd, &m));
  assert_false(geom_meet(l, h, &m));
  /* a meet with a rational position: x - y = 0 and x + 2y = 1 -> (1/3, 1/3) */
  struct gline d1 = geom_line((struct gpoint){ 0, 0 }, (struct gpoint){ 1, 1 });
  struct gline d2 = geom_line((struct gpoint){ 1, 0 }, (struct gpoint){ -1, 1 });
  assert_true(geom_meet(d1, d2, &m));
  assert_true(m.W > 0 && 3 * m.X == m.W && 3 * m.Y == m.W);
  assert_int_equal(geom_hy_cmp(m, 1, 3), 0);
  assert_int_equal(geom_hy_cmp(m, 1, 2), -1);
  assert_int_equal(geom_hy_cmp(m, 1, 4), 1);
}

/* geom_x_at and the rational compares are exact at ties, whatever the line's direction. */
static void test_geom_rationals(void **state)
{
  (void)state;
  struct gline up = geom_line((struct gpoint){ 0, 0 }, (struct gpoint){ 3, 7 });
  struct gline dn = geom_line((struct gpoint){ 3, 7 }, (struct gpoint){ 0, 0 });
  struct grat a = geom_x_at(up, 7, 1), b = geom_x_at(dn, 7, 1);
  assert_true(a.den > 0 && b.den > 0);
  assert_true(rat_is(a, 3, 1) && rat_is(b, 3, 1));
  assert_int_equal(geom_rat_cmp(a, b), 0);
  a = geom_x_at(up, 7, 2);                  /* y = 3.5 -> x = 1.5 */
  assert_true(rat_is(a, 3, 2));
  assert_int_equal(geom_rat_cmp_frac(a, 3000001, 2000000), -1);
  assert_int_equal(geom_rat_cmp_frac(a, 2999999, 2000000), 1);
  a = geom_x_at(dn, -14, 4);                /* y = -3.5 -> x = -1.5 */
  assert_true(rat_is(a, -3, 2));
  assert_true(geom_rat_floor(a) == -2 && geom_rat_ceil(a) == -1);
  /* equal values with different denominators compare equal */
  struct grat t1 = { 1, 3 }, t2 = { 2, 6 }, t3 = { -1, 3 }, t4 = { -2, 6 };
  assert_int_equal(geom_rat_cmp(t1, t2), 0);
  assert_int_equal(geom_rat_cmp(t3, t4), 0);
  assert_int_equal(geom_rat_cmp(t3, t1), -1);
  assert_int_equal(geom_rat_cmp(t1, t3), 1);
  /* floor / ceil at and around integers */
  struct grat r72 = { 7, 2 }, rm72 = { -7, 2 }, rm62 = { -6, 2 }, r0 = { 0, 5 };
  assert_true(geom_rat_floor(r72) == 3 && geom_rat_ceil(r72) == 4);
  assert_true(geom_rat_floor(rm72) == -4 && geom_rat_ceil(rm72) == -3);
  assert_true(geom_rat_floor(rm62) == -3 && geom_rat_ceil(rm62) == -3);
  assert_true(geom_rat_floor(r0) == 0 && geom_rat_ceil(r0) == 0);
  /* largest documented operands: |num| < 2^75, den < 2^46, differing by one unit */
  struct grat big1 = { ((wide)1 << 74) + 1, ((wide)1 << 45) };
  struct grat big2 = { ((wide)1 << 74), ((wide)1 << 45) };
  struct grat big3 = { -((wide)1 << 74) * 2 + 1, ((wide)1 << 45) * 2 - 1 };
  assert_int_equal(geom_rat_cmp(big1, big2), 1);
  assert_int_equal(geom_rat_cmp(big2, big1), -1);
  assert_int_equal(geom_rat_cmp(big3, big2), -1);
  /* a steep line through grid-limit points, at y exactly on a vertex */
  const gcoord L = GRID_LIMIT;
  struct gline st = geom_line((struct gpoint){ -L, -L }, (struct gpoint){ L - 1, L });
  struct grat e = geom_x_at(st, L, 1);
  assert_true(rat_is(e, L - 1, 1));
  e = geom_x_at(st, -L * GRID_YDEN_MAX, GRID_YDEN_MAX);
  assert_true(rat_is(e, -L, 1));
}

static bool i256_is(struct i256 v, uint64_t w0, uint64_t w1, uint64_t w2, uint64_t w3)
{
  return v.w[0] == w0 && v.w[1] == w1 && v.w[2] == w2 && v.w[3] == w3;
}

/* i256_mul / i256_add / i256_sign against known 256-bit products, signs and carries. */
static void test_i256(void **state)
{
  (void)state;
  const uint64_t ONES = ~(uint64_t)0;
  /* (2^127 - 1)^2 = 2^254 - 2^128 + 1 */
  struct i256 p = i256_mul(W128_MAX, W128_MAX);
  assert_true(i256_is(p, 1, 0, ONES, 0x3FFFFFFFFFFFFFFFull));
  assert_int_equal(i256_sign(p), 1);
  /* (-2^127)^2 = 2^254 */
  p = i256_mul(W128_MIN, W128_MIN);
  assert_true(i256_is(p, 0, 0, 0, 0x4000000000000000ull));
  assert_int_equal(i256_sign(p), 1);
  /* -2^127 * (2^127 - 1) = -2^254 + 2^127 */
  p = i256_mul(W128_MIN, W128_MAX);
  assert_true(i256_is(p, 0, 0x8000000000000000ull, 0, 0xC000000000000000ull));
  assert_int_equal(i256_sign(p), -1);
  p = i256_mul(W128_MAX, W128_MIN);
  assert_true(i256_is(p, 0, 0x8000000000000000ull, 0, 0xC000000000000000ull));
  /* small ones */
  assert_true(i256_is(i256_mul(-1, 1), ONES, ONES, ONES, ONES));
  assert_true(i256_is(i256_mul(-3, 5), 0xFFFFFFFFFFFFFFF1ull, ONES, ONES, ONES));
  assert_true(i256_is(i256_mul(-3, -5), 15, 0, 0, 0));
  assert_int_equal(i256_sign(i256_mul(0, W128_MIN)), 0);
  assert_int_equal(i256_sign(i256_mul(-7, 0)), 0);
  assert_true(i256_is(i256_mul(-7, 0), 0, 0, 0, 0));
  /* 2^64 * 2^64 = 2^128, and its negative */
  const wide T64 = (wide)1 << 64;
  assert_true(i256_is(i256_mul(T64, T64), 0, 0, 1, 0));
  assert_true(i256_is(i256_mul(-T64, T64), 0, 0, ONES, ONES));
  /* i256_from sign-extends */
  assert_true(i256_is(i256_from(W128_MIN), 0, 0x8000000000000000ull, ONES, ONES));
  assert_true(i256_is(i256_from(-1), ONES, ONES, ONES, ONES));
  /* add: carries through every word, a + (-a) = 0 */
  struct i256 m1 = i256_from(-1), one = i256_from(1);
  assert_true(i256_is(i256_add(m1, one), 0, 0, 0, 0));
  assert_true(i256_is(i256_add(i256_from((wide)ONES), one), 0, 1, 0, 0));
  struct i256 big = i256_mul(W128_MAX, W128_MAX), nbig = i256_mul(W128_MAX, -W128_MAX);
  assert_true(i256_is(i256_add(big, nbig), 0, 0, 0, 0));
  assert_int_equal(i256_sign(nbig), -1);
  /* (2^100 + 1)(2^100 - 1) - 2^100 * 2^100 = -1 */
  const wide T100 = (wide)1 << 100;
  struct i256 d = i256_add(i256_mul(T100 + 1, T100 - 1), i256_mul(-T100, T100));
  assert_true(i256_is(d, ONES, ONES, ONES, ONES));
  assert_int_equal(i256_sign(d), -1);
  /* a difference of one in the lowest word of two products near 2^250 */
  d = i256_add(i256_mul(W128_MAX, W128_MAX - 1), i256_mul(-(W128_MAX - 1), W128_MAX));
  assert_int_equal(i256_sign(d), 0);
  d = i256_add(i256_mul(W128_MAX, W128_MAX), i256_mul(-(W128_MAX - 1), W128_MAX));
  assert_int_equal(i256_sign(d), 1);
  /* random products that fit 128 bits agree with the compiler's */
  uint64_t s = 0x1234567887654321ull;
  for (int k = 0; k < 20000; k++) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    int64_t a = (int64_t)s >> (s & 31);
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    int64_t b = (int64_t)s >> ((s >> 7) & 31);
    wide ref = (wide)a * b;
    struct i256 r = i256_mul(a, b), f = i256_from(ref);
    assert_true(i256_is(r, f.w[0], f.w[1], f.w[2], f.w[3]));
    assert_int_equal(i256_sign(r), (ref > 0) - (ref < 0));
  }
}

/* A value of bit length n <= 127 (|v| < 2^n, at least 2^(n-1); 0 for n = 0): all ones, or
   only the top bit, by the seed's low bit; negative by its next one. */
static wide bitlen_value(unsigned n, uint64_t seed)
{
  if (n == 0) return 0;
  uwide u = (seed & 1) ? ((uwide)1 << (n - 1)) : ((uwide)1 << n) - 1;
  wide v = (wide)u;
  return (seed & 2) ? -v : v;
}

/* geom_cross_sign and geom_dot3_sign (their 128-bit paths taken by bit lengths) against the
   256-bit long way: each product's operands of bit lengths adding up to 118..135 (around
   the borders: 126 for a product pair, 125 for three products), signs and forms at
   random, a fifth of the pairs equal products, a fifth with one second factor (b = d);
   then the extremes. */
static void test_cross_dot_sign(void **state)
{
  (void)state;
  uint64_t s = 0x9E3779B97F4A7C15ull;
  for (int k = 0; k < 200000; k++) {
    wide v[6];
    for (int m = 0; m < 6; m += 2) {
      s = s * 6364136223846793005ull + 1442695040888963407ull;
      unsigned la = (unsigned)(s >> 40) % 128, sum = 118 + (unsigned)(s >> 20) % 18;
      unsigned lb = sum > la ? sum - la : 0;
      if (lb > 127) lb = 127;
      v[m] = bitlen_value(la, s >> 3);
      v[m + 1] = bitlen_value(lb, s >> 9);
    }
    if (k % 5 == 0) { v[2] = v[1]; v[3] = v[0]; }           /* equal products: 0 */
    if (k % 5 == 1) v[3] = v[1];                /* one second factor: a and c compared */
    if (k % 25 == 6) v[2] = v[0];
    wide a = v[0], b = v[1], c = v[2], d = v[3], e = v[4], f = v[5];
    int ref = i256_sign(i256_add(i256_mul(a, b), i256_mul(-c, d)));
    assert_int_equal(geom_cross_sign(a, b, c, d), ref);
    int ref3 = i256_sign(i256_add(i256_add(i256_mul(a, b), i256_mul(-c, d)), i256_mul(e, f)));
    assert_int_equal(geom_dot3_sign(a, b, -c, d, e, f), ref3);
  }
  /* the sum of three products each just below 2^125, all one sign: below 2^127 */
  const wide m = ((wide)1 << 62) - 1, n = ((wide)1 << 63) - 1;
  assert_int_equal(geom_dot3_sign(m, n, m, n, m, n), 1);
  assert_int_equal(geom_dot3_sign(-m, n, m, -n, -m, n), -1);
  assert_int_equal(geom_dot3_sign(m, n, -m, n, 0, 5), 0);
  /* the 192-bit path at its extremes: a, c of the largest magnitudes, b, d below 2^64 */
  const wide wmax = (wide)(~(uwide)0 >> 1), wmin = -wmax - 1;
  const wide u64max = (wide)~(uint64_t)0;
  const wide ext[6] = { wmax, wmax - 1, wmin, wmin + 1, -1, 0 };
  const wide ext2[4] = { u64max, u64max - 1, 1, 0 };
  for (int p = 0; p < 6; p++)
    for (int q = 0; q < 4; q++)
      for (int r = 0; r < 6; r++)
        for (int t = 0; t < 4; t++) {
          wide a = ext[p], b = ext2[q], c = ext[r], d = ext2[t];
          struct i256 ab = i256_mul(a, b), cd = i256_mul(c, d), ncd;
          /* -(c*d) by two's complement (-c overflows for the most negative c) */
          unsigned carry = 1;
          for (int w = 0; w < 4; w++) {
            ncd.w[w] = ~cd.w[w] + carry;
            carry = carry && ncd.w[w] == 0;
          }
          assert_int_equal(geom_cross_sign(a, b, c, d), i256_sign(i256_add(ab, ncd)));
        }
  /* the 64-bit path (geom.h: a, c in [-2^63, 2^63), b, d in [0, 2^63)) at its borders,
     with values just outside it, and at random within it, against the long way */
  const wide i64max = (wide)INT64_MAX, i64min = (wide)INT64_MIN;
  const wide e64[9] = { i64max, i64max - 1, i64min, i64min + 1, i64max + 1, i64min - 1,
                        -1, 0, 1 };
  const wide f64[6] = { i64max, i64max - 1, i64max + 1, i64max + 2, 1, 0 };
  for (int p = 0; p < 9; p++)
    for (int q = 0; q < 6; q++)
      for (int r = 0; r < 9; r++)
        for (int u = 0; u < 6; u++) {
          wide a = e64[p], b = f64[q], c = e64[r], d = f64[u];
          assert_int_equal(geom_cross_sign(a, b, c, d),
                           i256_sign(i256_add(i256_mul(a, b), i256_mul(-c, d))));
          assert_int_equal(geom_cross_sign(a, b, c, d), geom_cross_sign_long(a, b, c, d));
        }
  for (int k = 0; k < 200000; k++) {
    wide v[4];
    for (int j = 0; j < 4; j++) {
      s = s * 6364136223846793005ull + 1442695040888963407ull;
      uint64_t r = s ^ (s >> 29);
      v[j] = j % 2 ? (wide)(r >> (1 + (s >> 58) % 8))                /* [0, 2^63) */
                   : (wide)((int64_t)r >> ((s >> 58) % 8));           /* [-2^63, 2^63) */
    }
    if (k % 4 == 0) v[2] = v[0] + (k % 8 ? 1 : -1) * (wide)(k % 3);   /* near products */
    wide a = v[0], b = v[1], c = v[2], d = v[3];
    if (c != (int64_t)c) c = a;
    assert_int_equal(geom_cross_sign(a, b, c, d),
                     i256_sign(i256_add(i256_mul(a, b), i256_mul(-c, d))));
  }
  /* products just above the 128-bit range, differing by one */
  const wide t = (wide)1 << 100;
  assert_int_equal(geom_cross_sign(t + 1, t - 1, t, t), -1);
  assert_int_equal(geom_cross_sign(t, t, t + 1, t - 1), 1);
  assert_int_equal(geom_dot3_sign(t + 1, t - 1, -t, t, 1, 1), 0);
}

/* ---- seginfo --------------------------------------------------------------------------- */

/* seginfo_span on a square: left side owned, right side not, bottom owned, top not. */
static void test_span_tie_rule(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 16);
  struct cost cost = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &cost);
  const gcoord sq[] = { 0, 0, 10, 0, 10, 10, 0, 10 };
  int i = add_piece(&t, 0, 4, sq);
  struct piece *p = &t.p[i];
  struct grat xl, xr;
  assert_true(seginfo_span(p, 5, 1, &xl, &xr, &cost));
  assert_true(rat_is(xl, 0, 1) && rat_is(xr, 10, 1));   /* [0, 10): x = 0 in, x = 10 out */
  assert_true(seginfo_span(p, 0, 1, &xl, &xr, &cost));   /* bottom side owned */
  assert_true(rat_is(xl, 0, 1) && rat_is(xr, 10, 1));
  assert_false(seginfo_span(p, 10, 1, &xl, &xr, &cost)); /* top side not */
  assert_false(seginfo_span(p, -1, 2, &xl, &xr, &cost));
  assert_true(seginfo_span(p, 19, 2, &xl, &xr, &cost));
  assert_false(seginfo_span(p, 21, 2, &xl, &xr, &cost));
  /* a triangle with slanted sides: exact rational ends */
  const gcoord tri[] = { 0, 0, 12, 0, 4, 8 };
  i = add_piece(&t, 0, 3, tri);
  p = &t.p[i];
  assert_true(seginfo_span(p, 3, 1, &xl, &xr, &cost));
  assert_true(rat_is(xl, 3, 2) && rat_is(xr, 9, 1));
  assert_true(seginfo_span(p, 1, 3, &xl, &xr, &cost));
  assert_true(rat_is(xl, 1, 6) && rat_is(xr, 35, 3));
  /* the apex: both sides meet at one point, which the piece does not own */
  assert_false(seginfo_span(p, 8, 1, &xl, &xr, &cost));
  /* a diamond: at its bottom vertex and top vertex nothing, in between a span */
  const gcoord dia[] = { 5, 0, 10, 5, 5, 10, 0, 5 };
  i = add_piece(&t, 0, 4, dia);
  p = &t.p[i];
  assert_false(seginfo_span(p, 0, 1, &xl, &xr, &cost));
  assert_false(seginfo_span(p, 10, 1, &xl, &xr, &cost));
  assert_true(seginfo_span(p, 5, 1, &xl, &xr, &cost));
  assert_true(rat_is(xl, 0, 1) && rat_is(xr, 10, 1));
  assert_true(seginfo_span(p, 1, 1, &xl, &xr, &cost));
  assert_true(rat_is(xl, 4, 1) && rat_is(xr, 6, 1));
  seginfo_free(&t);
  core_free(core);
}

/* Issue 19: a piece of its own lines (seginfo_add) keeps its lines, its lowest vertex's
   height and its vertices (before the lines); piece_v and piece_verts give every vertex
   as geom_meet of its two lines, to the bit, and the kept height is that of piece_ylo.
   Pieces with Y beyond 64 bits, of 70 sides, of 65 sides merged to 4 (kept where the 4
   begin, in the block made for 65) and of 72 merged to 68. */
/* Piece p's B and C blocks (its B row at b): the row (number i, y-min, y-max, the C
   block's address) and the C block (n, then a side's vertex number, a and b, 0). */
static void check_blocks(const struct core *core, uint32_t b, int i, const struct piece *p)
{
  struct hpoint lo = piece_ylo(p), hi = piece_yhi(p);
  assert_int_equal(core_read(core, b), (uint16_t)i);
  assert_int_equal(core_read(core, b + 1), (uint16_t)(lo.Y / lo.W / GRID_ONE));
  assert_int_equal(core_read(core, b + 2), (uint16_t)(hi.Y / hi.W / GRID_ONE));
  assert_int_equal(core_read(core, b + 4), 0);
  assert_int_equal(core_read(core, b + 5), 0);
  uint32_t c = core_read(core, b + 3);
  assert_int_equal(core_read(core, c), (uint16_t)p->n);
  for (int k = 0; k < p->n; k++) {
    struct gline l = piece_line(p, k);
    assert_int_equal(core_read(core, c + 1 + 4 * (uint32_t)k), (uint16_t)k);
    assert_int_equal(core_read(core, c + 2 + 4 * (uint32_t)k), (uint16_t)l.a);
    assert_int_equal(core_read(core, c + 3 + 4 * (uint32_t)k), (uint16_t)l.b);
    assert_int_equal(core_read(core, c + 4 + 4 * (uint32_t)k), 0);
  }
}

static void check_piece(const struct piece *p, int n, const gcoord *xy)
{
  assert_int_equal(p->n, n);
  struct hpoint buf[PIECE_VBUF];
  const struct hpoint *pv = piece_verts(p, buf);
  assert_true((pv == buf) == p->onface);           /* kept unless on its face's points */
  for (int k = 0; k < n; k++) {
    struct hpoint m, v = piece_v(p, k);
    assert_true(geom_meet(piece_line(p, (k + n - 1) % n), piece_line(p, k), &m));
    assert_memory_equal(&m, &v, sizeof m);
    assert_memory_equal(&m, &pv[k], sizeof m);
    if (xy) assert_true(h_is(v, xy[2 * k], xy[2 * k + 1]));
    struct hpoint lo = piece_v(p, p->lo), hi = piece_v(p, p->hi);
    assert_true(geom_cross_sign(lo.Y, v.W, v.Y, lo.W) <= 0);
    assert_true(geom_cross_sign(hi.Y, v.W, v.Y, hi.W) >= 0);
  }
  struct hpoint lo = piece_ylo(p);
  assert_true(piece_ylo_y(p) == lo.Y);
  assert_true(p->ylo_w == lo.W);
}

static void test_piece_vertices(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 16);
  struct cost cost = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &cost);
  const gcoord L = GRID_LIMIT;
  const gcoord tri[][6] = {
    { -L, -L, L, -L + 3, L - 7, L },                   /* corners: Y beyond 64 bits */
    { -L + 5, L - 1, -L, -L + 2, L, -L + 9 },
    { 1, 1, 9, 2, 4, 7 },
  };
  int i;                                       /* (t.p moves as pieces are added) */
  for (int k = 0; k < 3; k++) { i = add_piece(&t, 0, 3, tri[k]); check_piece(&t.p[i], 3, tri[k]); }
  gcoord par[2 * 80], sq[2 * 80], chord[2 * 80];
  for (int k = 0; k < 70; k++) { par[2 * k] = k - 30; par[2 * k + 1] = (gcoord)k * k - 900; }
  uint32_t b = core_mark(core);
  i = add_piece(&t, 1, 70, par);
  check_piece(&t.p[i], 70, par);
  check_blocks(core, b, i, &t.p[i]);
  int m = 0;                                   /* 63 points on the bottom side, 2 on top */
  for (int k = 0; k <= 62; k++) { sq[2 * m] = k; sq[2 * m + 1] = 0; m++; }
  sq[2 * m] = 62; sq[2 * m + 1] = 62; m++;
  sq[2 * m] = 0; sq[2 * m + 1] = 62; m++;
  assert_int_equal(m, 65);
  const gcoord corners[] = { 0, 0, 62, 0, 62, 62, 0, 62 };
  b = core_mark(core);
  i = add_piece(&t, 2, m, sq);
  check_piece(&t.p[i], 4, corners);
  check_blocks(core, b, i, &t.p[i]);
  m = 0;                                       /* a 68-gon, 4 more points on its chord */
  for (int k = 0; k < 68; k++) { chord[2 * m] = k; chord[2 * m + 1] = (gcoord)k * k; m++; }
  const int on[] = { 50, 30, 20, 10 };
  for (int k = 0; k < 4; k++) { chord[2 * m] = on[k]; chord[2 * m + 1] = 67 * on[k]; m++; }
  i = add_piece(&t, 3, m, chord);
  check_piece(&t.p[i], 68, chord);
  seginfo_free(&t);
  core_free(core);
}

/* Issue 19: seginfo_add_face makes seginfo_add's piece (the same lines, vertices, lowest
   and highest, core words and charges) without copying the lines where they are the
   points' sides, and falls back to seginfo_add where they are not (lines from another
   start, two sides on one line). */
static void test_piece_on_face(void **state)
{
  (void)state;
  const gcoord L = GRID_LIMIT;
  const gcoord tri[] = { -L, -L, L, -L + 3, L - 7, L };
  const gcoord quad[] = { 0, 0, 9, 1, 8, 7, -1, 5 };
  const gcoord flat[] = { 0, 0, 4, 0, 8, 0, 8, 8, 0, 8 };      /* two sides on y = 0 */
  /* lowest and highest y each held by two vertices: the first of them is lo (hi), as
     seginfo_add's strict compares on Y / W choose (seginfo_add_face compares the points) */
  const gcoord sq[] = { 8, 0, 8, 8, 0, 8, 0, 0 };
  const gcoord sq2[] = { 0, 8, 0, 0, 8, 0, 8, 8 };
  const struct { const gcoord *xy; int n, shift; bool onface; } cs[] = {
    { tri, 3, 0, true }, { quad, 4, 0, true }, { quad, 4, 1, false }, { flat, 5, 0, false },
    { sq, 4, 0, true }, { sq2, 4, 0, true },
  };
  for (size_t t = 0; t < sizeof cs / sizeof cs[0]; t++) {
    struct core *core[2] = { core_new(1u << 16), core_new(1u << 16) };
    struct cost cost[2] = { { { 0 } }, { { 0 } } };
    struct seginfo si[2];
    int n = cs[t].n;
    struct gpoint pt[8];
    struct gline l[8];
    for (int k = 0; k < n; k++) pt[k] = (struct gpoint){ cs[t].xy[2 * k], cs[t].xy[2 * k + 1] };
    for (int k = 0; k < n; k++) {
      int j = (k + cs[t].shift) % n;
      l[k] = geom_line(pt[j], pt[(j + 1) % n]);
    }
    struct t74_error err = { 0, "" };
    for (int w = 0; w < 2; w++) {
      seginfo_init(&si[w], core[w], &cost[w]);
      int i = w ? seginfo_add_face(&si[w], 0, n, pt, l, &err) : seginfo_add(&si[w], 0, n, l, &err);
      assert_int_equal(i, 0);
    }
    const struct piece *a = &si[0].p[0], *b = &si[1].p[0];
    assert_int_equal(b->onface, cs[t].onface);
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->lo, b->lo);
    assert_int_equal(a->hi, b->hi);
    /* the same lowest height, Y / W (kept as (y, 1) on the face's points: seginfo.h) */
    assert_int_equal(geom_cross_sign(piece_ylo_y(a), b->ylo_w, piece_ylo_y(b), a->ylo_w), 0);
    assert_true(b->ylo_w == 1 || !b->onface);
    for (int k = 0; k < a->n; k++) {
      struct gline la = piece_line(a, k), lb = piece_line(b, k);
      assert_memory_equal(&la, &lb, sizeof la);
      struct hpoint va = piece_v(a, k), vb = piece_v(b, k);
      assert_memory_equal(&va, &vb, sizeof va);
    }
    assert_memory_equal(&cost[0], &cost[1], sizeof cost[0]);
    assert_int_equal(core_mark(core[0]), core_mark(core[1]));
    for (uint32_t k = 0; k < core_mark(core[0]); k++)
      assert_int_equal(core_read(core[0], k), core_read(core[1], k));
    for (int w = 0; w < 2; w++) {
      seginfo_free(&si[w]);
      core_free(core[w]);
    }
  }
}

/* seginfo_add's B-BLOCK row: y-min and y-max of the piece, Y / W / GRID_ONE truncated in
   128 bits (issue 19: in 64 where Y fits them): pieces near the grid's corners with
   slanted sides (vertices whose Y needs more than 64 bits), small ones, below y = 0 and
   off the world grid (where truncation and floor differ). */
static void test_bblock_y(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 16);
  struct cost cost = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &cost);
  const gcoord L = GRID_LIMIT, G = GRID_ONE;
  const gcoord tri[][6] = {
    { -L, -L, L, -L + 3, L - 7, L },                   /* corners: Y beyond 64 bits */
    { -L + 5, L - 1, -L, -L + 2, L, -L + 9 },
    { 0, -3 * G - 5, 7 * G + 1, -G + 3, 2, 5 * G - 1 }, /* below 0, off the world grid */
    { 1, 1, 9, 2, 4, 7 },                              /* small */
    { 3, -G - 1, 5 * G, -2 * G + 7, 4, -1 },
  };
  bool wide_y = false, narrow_y = false;
  for (int k = 0; k < 5; k++) {
    uint32_t b = core_mark(core);
    int i = add_piece(&t, 0, 3, tri[k]);
    const struct piece *p = &t.p[i];
    struct hpoint lo = piece_ylo(p), hi = piece_yhi(p);
    for (int j = 0; j < 3; j++) {
      if (piece_v(p, j).Y != (int64_t)piece_v(p, j).Y) wide_y = true; else narrow_y = true;
    }
    assert_int_equal(core_read(core, b + 1), (uint16_t)(lo.Y / lo.W / GRID_ONE));
    assert_int_equal(core_read(core, b + 2), (uint16_t)(hi.Y / hi.W / GRID_ONE));
  }
  assert_true(wide_y && narrow_y);
  seginfo_free(&t);
  core_free(core);
}

/* seginfo_clip: a diagonal makes two triangles; a line along a side or through a vertex
   keeps all or nothing; a cut through two sides gives the right rectangle. */
static void test_clip(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 16);
  struct cost cost = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &cost);
  const gcoord sq[] = { 0, 0, 10, 0, 10, 10, 0, 10 };
  int i = add_piece(&t, 0, 4, sq);
  const struct piece *p = &t.p[i];
  struct cpoly c = { 0 };
  struct gline diag = geom_line((struct gpoint){ 0, 0 }, (struct gpoint){ 10, 10 });
  struct gline rdiag = { -diag.a, -diag.b, -diag.c };
  assert_true(seginfo_clip(p, diag, &c, &cost));
  const gcoord ul[] = { 0, 0, 10, 10, 0, 10 };
  assert_true(poly_has(c.n, c.v, 3, ul));
  /* the lines of the result carry its vertices and keep the interior on their left */
  for (int k = 0; k < c.n; k++) {
    assert_int_equal(geom_side_h(c.line[k], c.v[k]), 0);
    assert_int_equal(geom_side_h(c.line[k], c.v[(k + 1) % c.n]), 0);
    assert_int_equal(geom_side_h(c.line[k], c.v[(k + 2) % c.n]), 1);
  }
  assert_true(seginfo_clip(p, rdiag, &c, &cost));
  const gcoord lr[] = { 0, 0, 10, 0, 10, 10 };
  assert_true(poly_has(c.n, c.v, 3, lr));
  /* along the bottom side: the square is on the left -> whole; reversed -> empty */
  struct gline bot = geom_line((struct gpoint){ -5, 0 }, (struct gpoint){ 20, 0 });
  struct gline rbot = { -bot.a, -bot.b, -bot.c };
  assert_true(seginfo_clip(p, bot, &c, &cost));
  assert_true(poly_has(c.n, c.v, 4, sq));
  assert_false(seginfo_clip(p, rbot, &c, &cost));
  /* through the vertex (10, 0) only, square on the left -> whole; reversed -> empty */
  struct gline tv = geom_line((struct gpoint){ 10, 0 }, (struct gpoint){ 20, 10 });
  struct gline rtv = { -tv.a, -tv.b, -tv.c };
  assert_true(seginfo_clip(p, tv, &c, &cost));
  assert_true(poly_has(c.n, c.v, 4, sq));
  assert_false(seginfo_clip(p, rtv, &c, &cost));
  /* through a vertex and the middle of a side: (0,0) -> (10,5) */
  struct gline vm = geom_line((struct gpoint){ 0, 0 }, (struct gpoint){ 10, 5 });
  assert_true(seginfo_clip(p, vm, &c, &cost));
  const gcoord vmq[] = { 0, 0, 10, 5, 10, 10, 0, 10 };
  assert_true(poly_has(c.n, c.v, 4, vmq));
  /* x = 5 running down: its left is x > 5 */
  struct gline x5 = geom_line((struct gpoint){ 5, 10 }, (struct gpoint){ 5, 0 });
  assert_true(seginfo_clip(p, x5, &c, &cost));
  const gcoord half[] = { 5, 0, 10, 0, 10, 10, 5, 10 };
  assert_true(poly_has(c.n, c.v, 4, half));
  struct gline rx5 = { -x5.a, -x5.b, -x5.c };
  assert_true(seginfo_clip(p, rx5, &c, &cost));
  const gcoord lhalf[] = { 0, 0, 5, 0, 5, 10, 0, 10 };
  assert_true(poly_has(c.n, c.v, 4, lhalf));
  /* a line missing the square: x = 100 running up, left is x < 100 (all of it) */
  struct gline far = geom_line((struct gpoint){ 100, 0 }, (struct gpoint){ 100, 10 });
  assert_true(seginfo_clip(p, far, &c, &cost));
  assert_true(poly_has(c.n, c.v, 4, sq));
  struct gline rfar = { -far.a, -far.b, -far.c };
  assert_false(seginfo_clip(p, rfar, &c, &cost));
  cpoly_free(&c);
  seginfo_free(&t);
  core_free(core);
}

static uint32_t lcg(uint32_t *s)
{
  *s = *s * 1664525u + 1013904223u;
  return *s >> 8;
}

/* Issue 19: seginfo_clip_both is seginfo_clip by a line and by its reverse, to the bit:
   the halves' lines and vertices, whether each has an interior, the operations charged;
   on random convex pieces (up to the grid's size) and lines through their vertices, along
   their sides and anywhere, and on a piece of more sides than it places at once. */
static void test_clip_both(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 20);
  struct cost c0 = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &c0);
  uint32_t seed = 1974;
  static const int dir[16][2] = { { 10, 0 }, { 9, 4 }, { 7, 7 }, { 4, 9 }, { 0, 10 }, { -4, 9 },
                                  { -7, 7 }, { -9, 4 }, { -10, 0 }, { -9, -4 }, { -7, -7 },
                                  { -4, -9 }, { 0, -10 }, { 4, -9 }, { 7, -7 }, { 9, -4 } };
  struct cpoly a = { 0 }, b = { 0 }, l = { 0 }, r = { 0 };
  int both = 0;
  for (int trial = 0; trial < 3000; trial++) {
    gcoord xy[2 * 80];
    int n = 0;
    int64_t R = trial % 3 == 0 ? GRID_LIMIT / 20 : 1 + (int64_t)(lcg(&seed) % 100);
    if (trial == 0) {                          /* more sides than placed at once: a wide */
      for (int k = 0; k < 70; k++) {           /* parabola's arc, closed by its chord */
        xy[2 * n] = 10 * k; xy[2 * n + 1] = (gcoord)k * k; n++;
      }
      for (int k = 0; k < 2 * n; k++) xy[k] = -xy[k];   /* turned half round: counter-clockwise */
    } else
      for (int d = 0; d < 16; d++)             /* a random subset of the directions, in turn */
        if (lcg(&seed) % 2) { xy[2 * n] = R * dir[d][0] + 5; xy[2 * n + 1] = R * dir[d][1] - 3; n++; }
    if (n < 3) continue;
    bool convex = true;
    for (int k = 0; k < n && convex; k++) {
      struct gpoint p0 = { xy[2 * k], xy[2 * k + 1] };
      struct gpoint p1 = { xy[2 * ((k + 1) % n)], xy[2 * ((k + 1) % n) + 1] };
      struct gpoint p2 = { xy[2 * ((k + 2) % n)], xy[2 * ((k + 2) % n) + 1] };
      convex = geom_orient(p0, p1, p2) > 0;
    }
    if (!convex) continue;
    int i = add_piece(&t, 0, n, xy);
    const struct piece *p = &t.p[i];
    struct gpoint u, w;
    int kind = (int)(lcg(&seed) % 3);
    int v0 = (int)(lcg(&seed) % (uint32_t)n), v1 = (v0 + 1 + (int)(lcg(&seed) % (uint32_t)(n - 1))) % n;
    int64_t span = 21 * R;
    u = (struct gpoint){ xy[2 * v0], xy[2 * v0 + 1] };
    if (kind == 0) w = (struct gpoint){ xy[2 * v1], xy[2 * v1 + 1] };      /* two vertices */
    else if (kind == 1) w = (struct gpoint){ xy[2 * ((v0 + 1) % n)], xy[2 * ((v0 + 1) % n) + 1] };
    else {                                                                  /* anywhere */
      u.x = (gcoord)(lcg(&seed) % (uint32_t)span) - span / 2;
      u.y = (gcoord)(lcg(&seed) % (uint32_t)span) - span / 2;
      w.x = (gcoord)(lcg(&seed) % (uint32_t)span) - span / 2;
      w.y = (gcoord)(lcg(&seed) % (uint32_t)span) - span / 2;
    }
    if (u.x == w.x && u.y == w.y) continue;
    struct gline h = geom_line(u, w), rh = { -h.a, -h.b, -h.c };
    struct cost k1 = { { 0 } }, k2 = { { 0 } };
    bool ha = seginfo_clip(p, h, &a, &k1), hb = seginfo_clip(p, rh, &b, &k1);
    bool hl, hr;
    seginfo_clip_both(p, h, &l, &hl, &r, &hr, &k2);
    assert_int_equal(ha, hl);
    assert_int_equal(hb, hr);
    assert_int_equal(a.n, l.n);
    assert_int_equal(b.n, r.n);
    assert_memory_equal(a.line, l.line, (size_t)a.n * sizeof *a.line);
    assert_memory_equal(a.v, l.v, (size_t)a.n * sizeof *a.v);
    assert_memory_equal(b.line, r.line, (size_t)b.n * sizeof *b.line);
    assert_memory_equal(b.v, r.v, (size_t)b.n * sizeof *b.v);
    assert_memory_equal(&k1, &k2, sizeof k1);
    both += ha && hb;
    /* a half known to have an interior only counted: the same count, answer, charges,
       and the other half made as before */
    for (int known = 1; known <= 2; known++) {
      if (!(known == 1 ? ha : hb)) continue;
      struct cost k3 = { { 0 } };
      struct cpoly *made = known == 1 ? &r : &l;
      made->n = -1;
      signed char sides[80];                  /* found here, or by the clip (NULL) */
      for (int v = 0; v < p->n; v++) sides[v] = (signed char)geom_side_h(h, piece_v(p, v));
      uint64_t prod = 0;
      struct hpoint pvb[PIECE_VBUF];         /* its vertices made here, or by the clip */
      struct gline plb[PIECE_VBUF];
      seginfo_clip_both_known(p, trial % 4 < 2 ? piece_lines(p, plb) : NULL,
                              trial % 4 < 2 ? piece_verts(p, pvb) : NULL, h,
                              trial % 2 ? sides : NULL, known, &l, &hl, &r, &hr, &prod);
      cost_mw_mul_n(&k3, 88, 58, prod);
      assert_int_equal(ha, hl);
      assert_int_equal(hb, hr);
      assert_int_equal(a.n, l.n);
      assert_int_equal(b.n, r.n);
      const struct cpoly *want = known == 1 ? &b : &a;
      assert_memory_equal(want->line, made->line, (size_t)want->n * sizeof *want->line);
      assert_memory_equal(want->v, made->v, (size_t)want->n * sizeof *want->v);
      assert_memory_equal(&k1, &k3, sizeof k1);
    }
  }
  assert_true(both > 300);                     /* lines that cut the piece in two */
  cpoly_free(&a);
  cpoly_free(&b);
  cpoly_free(&l);
  cpoly_free(&r);
  seginfo_free(&t);
  core_free(core);
}

static bool ovl(const struct seginfo *t, int a, int b, struct cost *cost)
{
  const struct piece *p = &t->p[a], *q = &t->p[b];
  struct hpoint pb[PIECE_VBUF], qb[PIECE_VBUF];
  const struct hpoint *pv = piece_verts(p, pb), *qv = piece_verts(q, qb);
  struct gline plb[PIECE_VBUF], qlb[PIECE_VBUF];
  const struct gline *pl = piece_lines(p, plb), *ql = piece_lines(q, qlb);
  bool r1 = seginfo_overlap(p->n, pl, pv, q->n, ql, qv, cost);
  bool r2 = seginfo_overlap(q->n, ql, qv, p->n, pl, pv, cost);
  assert_true(r1 == r2);                          /* symmetric */
  return r1;
}

/* seginfo_overlap: disjoint, sharing an edge, touching at a corner -> no; overlapping,
   nested, identical, crossing without a vertex inside -> yes. */
static void test_overlap(void **state)
{
  (void)state;
  struct core *core = core_new(1u << 16);
  struct cost cost = { { 0 } };
  struct seginfo t;
  seginfo_init(&t, core, &cost);
  const gcoord a[] = { 0, 0, 10, 0, 10, 10, 0, 10 };
  const gcoord far[] = { 20, 0, 30, 0, 30, 10, 20, 10 };
  const gcoord edge[] = { 10, 0, 20, 0, 20, 10, 10, 10 };
  const gcoord edgepart[] = { 10, 3, 20, 3, 20, 6, 10, 6 };
  const gcoord corner[] = { 10, 10, 20, 10, 20, 20, 10, 20 };
  const gcoord over[] = { 5, 5, 15, 5, 15, 15, 5, 15 };
  const gcoord inside[] = { 2, 2, 4, 2, 4, 4, 2, 4 };
  const gcoord cross[] = { -5, 4, 15, 4, 15, 6, -5, 6 };   /* a bar through the square */
  const gcoord tri_touch[] = { 10, 10, 20, 0, 20, 20 };    /* corner of a to a triangle's */
  const gcoord diag_touch[] = { 10, 0, 20, 10, 10, 20 };   /* along no edge: corner (10,10)?*/
  int ia = add_piece(&t, 0, 4, a);
  int ifar = add_piece(&t, 1, 4, far);
  int iedge = add_piece(&t, 1, 4, edge);
  int iep = add_piece(&t, 1, 4, edgepart);
  int icor = add_piece(&t, 1, 4, corner);
  int iover = add_piece(&t, 1, 4, over);
  int iin = add_piece(&t, 1, 4, inside);
  int isame = add_piece(&t, 1, 4, a);
  int icross = add_piece(&t, 1, 4, cross);
  int itt = add_piece(&t, 1, 3, tri_touch);
  int idt = add_piece(&t, 1, 3, diag_touch);
  assert_false(ovl(&t, ia, ifar, &cost));
  assert_false(ovl(&t, ia, iedge, &cost));
  assert_false(ovl(&t, ia, iep, &cost));
  assert_false(ovl(&t, ia, icor, &cost));
  assert_true(ovl(&t, ia, iover, &cost));
  assert_true(ovl(&t, ia, iin, &cost));
  assert_true(ovl(&t, ia, isame, &cost));
  assert_true(ovl(&t, ia, icross, &cost));
  assert_false(ovl(&t, ia, itt, &cost));
  assert_false(ovl(&t, ia, idt, &cost));      /* touches the edge x = 10 from (10,0) to (10,10) */
  seginfo_free(&t);
  core_free(core);
}

/* ---- priority ------------------------------------------------------------------------ */

#define HDR "view 0 0 -1000\nwindow -200 -150 200 150\n"

/* The face index (in map.f) of face id. */
static int fidx(const struct render *r, int id)
{
  for (int k = 0; k < r->map.nface; k++)
    if (r->map.f[k].id == (uint32_t)id) return k;
  fail_msg("face %d not mapped", id);
  return -1;
}

static int piece_of(const struct render *r, int id)
{
  int f = fidx(r, id);
  for (int k = 0; k < r->seg.n; k++)
    if (r->seg.p[k].alive && r->seg.p[k].face == f) return k;
  fail_msg("no piece of face %d", id);
  return -1;
}

/* The id of the face in front of pieces a, b, asked in the order (a, b). */
static int front_id(struct render *r, int a, int b)
{
  struct t74_error err = { 0, "" };
  int res = prio_order(&r->prio, a, b, &err);
  assert_true(res == PRIO_FIRST || res == PRIO_SECOND);
  int p = res == PRIO_FIRST ? a : b;
  return r->map.f[r->seg.p[p].face].id;
}

/* Parallel faces (flat and slanted): the nearer is in front whichever order asked, and
   whichever order the faces are listed in; the pair is computed once. */
static void test_prio_parallel(void **state)
{
  (void)state;
  static const char *scenes[] = {
    HDR "vertex 1 -200 -200 1000\nvertex 2 200 -200 1000\nvertex 3 200 200 1000\n"
        "vertex 4 -200 200 1000\nface 9 1 2 3 4\n"
        "vertex 5 -50 -50 0\nvertex 6 50 -50 0\nvertex 7 50 50 0\nvertex 8 -50 50 0\n"
        "face 2 5 6 7 8\n",
    HDR "vertex 5 -50 -50 0\nvertex 6 50 -50 0\nvertex 7 50 50 0\nvertex 8 -50 50 0\n"
        "face 2 5 6 7 8\n"
        "vertex 1 -200 -200 1000\nvertex 2 200 -200 1000\nvertex 3 200 200 1000\n"
        "vertex 4 -200 200 1000\nface 9 1 2 3 4\n",
    /* slanted, z = x + 200 (face 2) and z = x + 400 (face 9) */
    HDR "vertex 1 -100 -100 300\nvertex 2 100 -100 500\nvertex 3 100 100 500\n"
        "vertex 4 -100 100 300\nface 9 1 2 3 4\n"
        "vertex 5 -100 -100 100\nvertex 6 100 -100 300\nvertex 7 100 100 300\n"
        "vertex 8 -100 100 100\nface 2 5 6 7 8\n",
  };
  for (int s = 0; s < 3; s++) {
    for (int store = PRIO_DENSE; store <= PRIO_SPARSE; store++) {
      struct render r;
      struct scene *sc = prepare(&r, scenes[s], store);
      int near = piece_of(&r, 2), farp = piece_of(&r, 9);
      assert_int_equal(front_id(&r, near, farp), 2);
      assert_int_equal(front_id(&r, farp, near), 2);
      assert_int_equal(front_id(&r, near, farp), 2);
      assert_int_equal((int)r.prio.computed, 1);
      assert_int_equal(r.prio.splits, 0);
      render_free(&r);
      scene_free(sc);
    }
  }
}

/* Representative x (world units, double) of a piece: mean of its vertices. */
static double piece_cx(const struct render *r, int k)
{
  const struct piece *p = &r->seg.p[k];
  double s = 0;
  for (int v = 0; v < p->n; v++) s += (double)piece_v(p, v).X / (double)piece_v(p, v).W;
  return s / p->n / GRID_ONE;
}

static const char CROSSING[] =
  HDR "vertex 1 -100 -100 0\nvertex 2 100 -100 0\nvertex 3 100 100 0\nvertex 4 -100 100 0\n"
      "face 1 1 2 3 4 grey 100\n"
      "vertex 5 -50 -50 -100\nvertex 6 150 -50 100\nvertex 7 150 150 100\n"
      "vertex 8 -50 150 -100\nface 2 5 6 7 8 grey 200\n";

/* Crossing squares (face 2: z = x - 50 crosses face 1: z = 0 along x = 50): PRIO_SPLIT
   once; afterwards the halves are ordered (face 2 in front left of x = 50, face 1 right
   of it), consistently in either order asked, and no further split happens. */
static void test_prio_crossing(void **state)
{
  (void)state;
  for (int store = PRIO_DENSE; store <= PRIO_SPARSE; store++) {
    struct render r;
    struct scene *sc = prepare(&r, CROSSING, store);
    assert_int_equal(r.seg.n, 2);
    struct t74_error err = { 0, "" };
    int res = prio_order(&r.prio, 0, 1, &err);
    assert_int_equal(res, PRIO_SPLIT);
    assert_int_equal(r.prio.splits, 1);
    assert_false(r.seg.p[0].alive);
    assert_false(r.seg.p[1].alive);
    assert_int_equal(r.seg.n, 6);
    assert_int_equal(render_pieces_alive(&r), 4);
    /* every half lies on one side of x = 50 (within a grid unit: L~ is rounded) */
    int nchecked = 0;
    for (int a = 2; a < 6; a++)
      for (int b = 2; b < 6; b++) {
        if (r.seg.p[a].face == r.seg.p[b].face || a == b) continue;
        const struct piece *P = &r.seg.p[a], *Q = &r.seg.p[b];
        struct hpoint pb[PIECE_VBUF], qb[PIECE_VBUF];
        struct gline plb[PIECE_VBUF], qlb[PIECE_VBUF];
        if (!seginfo_overlap(P->n, piece_lines(P, plb), piece_verts(P, pb), Q->n,
                             piece_lines(Q, qlb), piece_verts(Q, qb), &r.cost[0]))
          continue;
        double cx = (piece_cx(&r, a) + piece_cx(&r, b)) / 2;
        int want = cx < 50 ? 2 : 1;
        assert_int_equal(front_id(&r, a, b), want);
        assert_int_equal(front_id(&r, b, a), want);
        nchecked++;
      }
    assert_int_equal(nchecked, 4);       /* two overlapping pairs, each asked both ways */
    assert_int_equal(r.prio.splits, 1);
    assert_int_equal(r.seg.n, 6);
    /* the two halves of face 1 (or 2) never overlap each other */
    for (int a = 2; a < 6; a++)
      for (int b = a + 1; b < 6; b++)
        if (r.seg.p[a].face == r.seg.p[b].face) {
          const struct piece *P = &r.seg.p[a], *Q = &r.seg.p[b];
          struct hpoint pb[PIECE_VBUF], qb[PIECE_VBUF];
          struct gline plb[PIECE_VBUF], qlb[PIECE_VBUF];
          assert_false(seginfo_overlap(P->n, piece_lines(P, plb), piece_verts(P, pb), Q->n,
                                       piece_lines(Q, qlb), piece_verts(Q, qb), &r.cost[0]));
        }
    render_free(&r);
    scene_free(sc);
  }
}

/* Coplanar overlapping faces (flat and slanted): the larger face number is in front,
   whichever is listed first and whichever order asked. */
static void test_prio_coplanar(void **state)
{
  (void)state;
  static const char *scenes[] = {
    HDR "vertex 1 -100 -100 0\nvertex 2 50 -100 0\nvertex 3 50 50 0\nvertex 4 -100 50 0\n"
        "vertex 5 -50 -50 0\nvertex 6 100 -50 0\nvertex 7 100 100 0\nvertex 8 -50 100 0\n"
        "face 7 1 2 3 4\nface 3 5 6 7 8\n",
    HDR "vertex 1 -100 -100 0\nvertex 2 50 -100 0\nvertex 3 50 50 0\nvertex 4 -100 50 0\n"
        "vertex 5 -50 -50 0\nvertex 6 100 -50 0\nvertex 7 100 100 0\nvertex 8 -50 100 0\n"
        "face 3 5 6 7 8\nface 7 1 2 3 4\n",
    /* both on z = x + 200 */
    HDR "vertex 1 -100 -100 100\nvertex 2 50 -100 250\nvertex 3 50 50 250\n"
        "vertex 4 -100 50 100\nvertex 5 -50 -50 150\nvertex 6 100 -50 300\n"
        "vertex 7 100 100 300\nvertex 8 -50 100 150\n"
        "face 3 5 6 7 8\nface 7 1 2 3 4\n",
    HDR "vertex 1 -100 -100 100\nvertex 2 50 -100 250\nvertex 3 50 50 250\n"
        "vertex 4 -100 50 100\nvertex 5 -50 -50 150\nvertex 6 100 -50 300\n"
        "vertex 7 100 100 300\nvertex 8 -50 100 150\n"
        "face 7 1 2 3 4\nface 3 5 6 7 8\n",
  };
  for (int s = 0; s < 4; s++) {
    struct render r;
    struct scene *sc = prepare(&r, scenes[s], PRIO_AUTO);
    int p7 = piece_of(&r, 7), p3 = piece_of(&r, 3);
    assert_int_equal(front_id(&r, p7, p3), 7);
    assert_int_equal(front_id(&r, p3, p7), 7);
    assert_int_equal(r.prio.splits, 0);
    assert_int_equal((int)r.prio.computed, 1);
    render_free(&r);
    scene_free(sc);
  }
}

/* Grid scan into an array of face ids (0 = none). */
struct grab { const struct render *r; uint16_t *ids; int W; int order_ok; int last; };

#define GW 100
#define GH 75

static int grab_point(void *ctx, int i, int j, int face)
{
  struct grab *g = ctx;
  int key = (GH - 1 - j) * g->W + i;      /* bottom row first, left to right: increasing */
  if (g->last != INT32_MIN && key <= g->last) g->order_ok = 0;
  g->last = key;
  g->ids[j * g->W + i] = face < 0 ? 0 : g->r->map.f[face].id;
  return T74_OK;
}

static void scan_ids(struct render *r, uint16_t *ids)
{
  struct vis_grid g = { GW, GH, { -200, -150, 200, 150 } };
  struct grab gb = { r, ids, GW, 1, INT32_MIN };
  struct t74_error err = { 0, "" };
  int st = render_scan(r, &g, grab_point, &gb, &err);
  if (st) print_message("render_scan: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  assert_true(gb.order_ok);                 /* bottom row first, left to right */
}

static const char CYCLIC[] =
  "view 0 0 -1000\nwindow -200 -150 200 150\n"
  "vertex 1 -140 -60 400\nvertex 2 140 -60 0\nvertex 3 140 -20 0\nvertex 4 -140 -20 400\n"
  "face 1 1 2 3 4 grey 90\n"
  "vertex 5 80 -120 300\nvertex 6 120 -120 300\nvertex 7 -20 120 0\nvertex 8 -60 120 0\n"
  "face 2 5 6 7 8 grey 160\n"
  "vertex 9 -120 -120 0\nvertex 10 -80 -120 0\nvertex 11 60 120 400\nvertex 12 20 120 400\n"
  "face 3 9 10 11 12 grey 230\n";

static const char COPLANAR3[] =
  HDR "vertex 1 -100 -100 0\nvertex 2 50 -100 0\nvertex 3 50 50 0\nvertex 4 -100 50 0\n"
      "vertex 5 -50 -50 0\nvertex 6 100 -50 0\nvertex 7 100 100 0\nvertex 8 -50 100 0\n"
      "vertex 9 -150 -20 0\nvertex 10 150 -20 0\nvertex 11 0 130 0\n"
      "face 7 1 2 3 4\nface 3 5 6 7 8\nface 12 9 10 11\n";

/* A concave face with a hole in front of a slanted face that crosses the crossing pair. */
static const char MIXED[] =
  HDR "vertex 1 -180 -130 0\nvertex 2 180 -130 0\nvertex 3 180 130 0\nvertex 4 0 0 0\n"
      "vertex 5 -180 130 0\nvertex 6 -120 -60 0\nvertex 7 -60 -60 0\nvertex 8 -90 -10 0\n"
      "face 4 1 2 3 4 5 * 6 7 8 grey 120\n"
      "vertex 9 -150 -140 -200\nvertex 10 150 -140 200\nvertex 11 150 140 200\n"
      "vertex 12 -150 140 -200\nface 5 9 10 11 12\n"
      "vertex 13 -100 -100 50\nvertex 14 100 -100 50\nvertex 15 0 120 -300\n"
      "face 6 13 14 15\n";

/* Each pair is computed at most once: a second scan over the same matrix computes no new
   pair, and computed never exceeds the pairs of pieces that ever existed. */
static void test_prio_computed_once(void **state)
{
  (void)state;
  const char *scenes[] = { CROSSING, CYCLIC, COPLANAR3, MIXED };
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  for (int s = 0; s < 4; s++) {
    struct render r;
    struct scene *sc = prepare(&r, scenes[s], PRIO_AUTO);
    scan_ids(&r, a);
    uint64_t c1 = r.prio.computed;
    int n = r.seg.n;
    assert_true(c1 <= (uint64_t)n * (uint64_t)(n - 1) / 2);
    assert_true(c1 >= 1);
    /* scan again through a fresh visible-surface state on the same pieces and matrix */
    struct t74_error err = { 0, "" };
    vis_free(&r.vis);
    assert_int_equal(vis_init(&r.vis, &r.seg, &r.prio, &r.cost[RS_VISIBLE], &err), T74_OK);
    scan_ids(&r, b);
    assert_true(r.prio.computed == c1);
    assert_int_equal(r.seg.n, n);
    assert_memory_equal(a, b, GW * GH * sizeof *a);
    render_free(&r);
    scene_free(sc);
  }
  free(a);
  free(b);
}

/* Dense and sparse stores give identical pictures, counts, splits and answers. */
static void test_prio_dense_sparse(void **state)
{
  (void)state;
  const char *scenes[] = { CROSSING, CYCLIC, COPLANAR3, MIXED };
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  for (int s = 0; s < 4; s++) {
    struct render rd, rs;
    struct scene *sd = prepare(&rd, scenes[s], PRIO_DENSE);
    struct scene *ss = prepare(&rs, scenes[s], PRIO_SPARSE);
    assert_int_equal(rd.prio.store, PRIO_DENSE);
    assert_int_equal(rs.prio.store, PRIO_SPARSE);
    scan_ids(&rd, a);
    scan_ids(&rs, b);
    assert_memory_equal(a, b, GW * GH * sizeof *a);
    assert_true(rd.prio.computed == rs.prio.computed);
    assert_int_equal(rd.prio.splits, rs.prio.splits);
    assert_int_equal(rd.seg.n, rs.seg.n);
    for (int i = 0; i < rd.seg.n; i++)
      for (int j = 0; j < rd.seg.n; j++) {
        if (i == j || !rd.seg.p[i].alive || !rd.seg.p[j].alive) continue;
        struct t74_error err = { 0, "" };
        int x = prio_order(&rd.prio, i, j, &err), y = prio_order(&rs.prio, i, j, &err);
        assert_int_equal(x, y);
      }
    render_free(&rd);
    render_free(&rs);
    scene_free(sd);
    scene_free(ss);
  }
  free(a);
  free(b);
}

/* Large triangles at random slants in depth (as tools/mktris.py makes them): nearly every
   pair overlaps and many pierce each other, so the interpenetration cuts multiply the
   pieces long after the start. */
static char *tris_scene(int n, uint32_t seed)
{
  size_t cap = 128 + (size_t)n * 160, len = 0;
  char *t = malloc(cap);
  assert_non_null(t);
  len += (size_t)snprintf(t + len, cap - len, "view 0 0 -3000\nwindow -200 -150 200 150\n");
  uint32_t x = seed;
#define RND(lo, hi) (x = x * 1103515245u + 12345u, (int)(lo) + (int)((x >> 8) % (uint32_t)((hi) - (lo) + 1)))
  for (int k = 0; k < n; k++) {
    int cx = RND(-120, 120), cy = RND(-90, 90), r = RND(60, 130);
    for (int v = 0; v < 3; v++) {
      int vx = cx + RND(-r, r), vy = cy + RND(-r, r), vz = RND(500, 2500);
      len += (size_t)snprintf(t + len, cap - len, "vertex %d %d %d %d\n", 3 * k + v + 1, vx, vy, vz);
    }
    len += (size_t)snprintf(t + len, cap - len, "face %d %d %d %d grey %d\n", k + 1, 3 * k + 1,
                            3 * k + 2, 3 * k + 3, RND(60, 255));
  }
#undef RND
  assert_true(len < cap);
  return t;
}

/* PRIO_AUTO starts a scene of few faces with the dense triangle and, when the cuts have
   made the triangle larger than the pairs met need, moves the pairs to the sparse store:
   the picture, the pairs computed and every answer stay those of the dense store, the
   core taken is smaller than the dense store's; when every pair has been asked for, the
   store goes back to the triangle; a scene that stays small keeps the dense store. */
static void test_prio_auto_migrates(void **state)
{
  (void)state;
  char *text = tris_scene(100, 7);
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  struct render rd, ra;
  struct scene *sd = prepare(&rd, text, PRIO_DENSE);
  struct scene *sa = prepare(&ra, text, PRIO_AUTO);
  assert_int_equal(ra.prio.store, PRIO_DENSE);        /* 100 pieces at the start */
  scan_ids(&rd, a);
  scan_ids(&ra, b);
  assert_int_equal(rd.prio.store, PRIO_DENSE);
  assert_int_equal(ra.prio.store, PRIO_SPARSE);
  assert_true(ra.prio.migrated);
  assert_memory_equal(a, b, GW * GH * sizeof *a);
  assert_true(rd.prio.computed == ra.prio.computed);
  assert_true(rd.prio.hused == ra.prio.hused);
  assert_int_equal(rd.prio.splits, ra.prio.splits);
  assert_int_equal(rd.seg.n, ra.seg.n);
  print_message("# %d pieces, %llu pairs held: dense %u words at peak, auto %u\n", rd.seg.n,
                (unsigned long long)rd.prio.hused, core_peak(rd.core), core_peak(ra.core));
  assert_true(core_peak(ra.core) < core_peak(rd.core));
  /* the matrix dumps list the same pairs (all but the heading, which names the store) */
  char *da = NULL, *db = NULL;
  size_t la = 0, lb = 0;
  FILE *fa = open_memstream(&da, &la), *fb = open_memstream(&db, &lb);
  assert_non_null(fa);
  assert_non_null(fb);
  prio_dump(&rd.prio, fa);
  prio_dump(&ra.prio, fb);
  fclose(fa);
  fclose(fb);
  const char *ba = strchr(da, '\n'), *bb = strchr(db, '\n');
  assert_non_null(ba);
  assert_non_null(bb);
  assert_non_null(strstr(ba, "a(1,"));
  assert_string_equal(ba, bb);
  free(da);
  free(db);
  for (int i = 0; i < rd.seg.n; i++)
    for (int j = 0; j < rd.seg.n; j++) {
      if (i == j || !rd.seg.p[i].alive || !rd.seg.p[j].alive) continue;
      struct t74_error e1 = { 0, "" }, e2 = { 0, "" };
      int x = prio_order(&rd.prio, i, j, &e1), y = prio_order(&ra.prio, i, j, &e2);
      if (x != y) print_message("# %d %d: %d %s / %d %s\n", i, j, x, e1.msg, y, e2.msg);
      assert_int_equal(x, y);
    }
  /* every pair of living pieces is now known: the pairs need more than the triangle, and
     the automatic store has gone back to it */
  assert_true(rd.prio.hused == ra.prio.hused);
  assert_int_equal(ra.prio.store, PRIO_DENSE);
  render_free(&rd);
  render_free(&ra);
  scene_free(sd);
  scene_free(sa);
  free(text);
  /* few crossings: the triangle stays */
  text = tris_scene(12, 3);
  sa = prepare(&ra, text, PRIO_AUTO);
  scan_ids(&ra, b);
  assert_int_equal(ra.prio.store, PRIO_DENSE);
  assert_false(ra.prio.migrated);
  render_free(&ra);
  scene_free(sa);
  free(text);
  free(a);
  free(b);
}

/* ---- mapper ------------------------------------------------------------------------ */

/* eq. (1) rounded once, half up, to the grid: with the eye at z = -1 a vertex at z = 511
   shrinks 512 times, so x = +-1, +-3 land on +-0.5, +-1.5 grid units and round to 1, 0,
   2, -1; edge-on faces are dropped; rings come out outer CCW, holes CW. */
static void test_mapper_rounding(void **state)
{
  (void)state;
  static const char text[] =
    "view 0 0 -1\nwindow -200 -150 200 150\n"
    "vertex 1 1 -1 511\nvertex 2 3 -3 511\nvertex 3 -1 1 511\nvertex 4 -3 3 511\n"
    "vertex 5 1000 1000 511\nface 1 1 5 2\nface 2 3 4 5\n"
    /* edge-on: the plane x = 0 holds the eye */
    "vertex 6 0 0 0\nvertex 7 0 10 0\nvertex 8 0 10 10\nface 3 6 7 8\n"
    /* clockwise outer ring and counter-clockwise hole, as given */
    "vertex 10 -100 -100 0\nvertex 11 -100 100 0\nvertex 12 100 100 0\nvertex 13 100 -100 0\n"
    "vertex 14 -10 -10 0\nvertex 15 10 -10 0\nvertex 16 10 10 0\nvertex 17 -10 10 0\n"
    "face 4 10 11 12 13 * 14 15 16 17\n";
  struct render r;
  struct scene *sc = prepare(&r, text, PRIO_AUTO);
  assert_int_equal(r.map.nface, 3);
  assert_int_equal(r.map.dropped, 1);
  const struct mface *f1 = &r.map.f[fidx(&r, 1)], *f2 = &r.map.f[fidx(&r, 2)];
  bool s1 = false, s2 = false, s3 = false, s4 = false;
  for (int k = 0; k < f1->ring_start[1]; k++) {
    if (f1->vid[k] == 1) { s1 = true; assert_true(f1->pt[k].x == 1 && f1->pt[k].y == 0); }
    if (f1->vid[k] == 2) { s2 = true; assert_true(f1->pt[k].x == 2 && f1->pt[k].y == -1); }
  }
  for (int k = 0; k < f2->ring_start[1]; k++) {
    if (f2->vid[k] == 3) { s3 = true; assert_true(f2->pt[k].x == 0 && f2->pt[k].y == 1); }
    if (f2->vid[k] == 4) { s4 = true; assert_true(f2->pt[k].x == -1 && f2->pt[k].y == 2); }
  }
  assert_true(s1 && s2 && s3 && s4);
  const struct mface *f4 = &r.map.f[fidx(&r, 4)];
  assert_int_equal(f4->nring, 2);
  for (int ring = 0; ring < 2; ring++) {
    wide a = 0;
    int b = f4->ring_start[ring], e = f4->ring_start[ring + 1];
    for (int k = b; k < e; k++) {
      const struct gpoint *u = &f4->pt[k], *v = &f4->pt[k + 1 < e ? k + 1 : b];
      a += (wide)u->x * v->y - (wide)v->x * u->y;
    }
    assert_true(ring == 0 ? a > 0 : a < 0);
  }
  /* the plane is signed so the eye is on its negative side */
  for (int k = 0; k < r.map.nface; k++) {
    const struct mface *m = &r.map.f[k];
    wide pe = (wide)m->plane[0] * 0 + (wide)m->plane[1] * 0 + (wide)m->plane[2] * -1 + m->plane[3];
    assert_true(pe < 0 && -pe == m->deye);
  }
  render_free(&r);
  scene_free(sc);
}

/* ---- visible ------------------------------------------------------------------------- */

/* face 1 (z = 1000, projected [-100, 0] x [-100, 100]) behind face 2 ([-50, 50]^2, z = 0);
   face 3 ([80, 120] x [-50, 50], z = 0) apart, a gap [50, 80) between. */
static const char VISCFG[] =
  HDR "vertex 1 -200 -200 1000\nvertex 2 0 -200 1000\nvertex 3 0 200 1000\n"
      "vertex 4 -200 200 1000\nface 1 1 2 3 4\n"
      "vertex 5 -50 -50 0\nvertex 6 50 -50 0\nvertex 7 50 50 0\nvertex 8 -50 50 0\n"
      "face 2 5 6 7 8\n"
      "vertex 9 80 -50 0\nvertex 10 120 -50 0\nvertex 11 120 50 0\nvertex 12 80 50 0\n"
      "face 3 9 10 11 12\n";

struct want_span { int64_t x0, x1; int id; };     /* world units, id 0 = none expected */

static void check_spans(struct render *r, int64_t yn, int64_t yd, int nw,
                        const struct want_span *w)
{
  const struct vis_span *sp;
  int ns;
  struct t74_error err = { 0, "" };
  assert_int_equal(vis_spans(&r->vis, yn, yd, &sp, &ns, &err), T74_OK);
  bool same = ns == nw;
  for (int k = 0; same && k < ns; k++)
    same = rat_is(sp[k].x0, G(w[k].x0), 1) && rat_is(sp[k].x1, G(w[k].x1), 1) &&
           r->map.f[sp[k].face].id == (uint32_t)w[k].id;
  for (int k = 0; !same && k < ns; k++)
    print_message("  y=%lld/%lld span %d: [%g, %g) face %d\n", (long long)yn, (long long)yd, k,
                  (double)sp[k].x0.num / (double)sp[k].x0.den / GRID_ONE,
                  (double)sp[k].x1.num / (double)sp[k].x1.den / GRID_ONE,
                  r->map.f[sp[k].face].id);
  assert_int_equal(ns, nw);
  for (int k = 0; k < ns; k++) {
    assert_true(rat_is(sp[k].x0, G(w[k].x0), 1));
    assert_true(rat_is(sp[k].x1, G(w[k].x1), 1));
    assert_int_equal(r->map.f[sp[k].face].id, w[k].id);
    assert_int_equal(sp[k].face, r->seg.p[sp[k].piece].face);
  }
}

/* vis_spans on a hand-made configuration: exact ends, disjoint and ordered, gaps where
   nothing is, bottom edges owned and top edges not. */
/* The sweep's x compares from doubles (render/vis_x.h): kx_cmp, and band_cmp against
   key_band's band, answer x_cmp's on 2,000,000 pairs of rationals of the sweep's kind
   (denominators below 2^63, products below 2^121): random ones, neighbours (numerators
   1 or 2 apart), near multiples (with a wider band, w = 0 or 2^-60 |kq|, some go wrong)
   and equal ones; the keys decide most, the exact compare the rest. */
static void test_vis_x_keys(void **state)
{
  (void)state;
  uint64_t x = 88172645463325252u;
#define XRND() (x ^= x << 13, x ^= x >> 7, x ^= x << 17, x)
  long bad = 0, keyed = 0, exact = 0;
  for (long it = 0; it < 2000000; it++) {
    const int bn = 1 + (int)(XRND() % 62), bd0 = 1 + (int)(XRND() % 52);
    const int bd = bn + bd0 > 100 ? 100 - bn : bd0;   /* products below 2^121 */
    wide an = (wide)(XRND() & (((uint64_t)1 << bn) - 1));
    wide ad = (wide)(XRND() % ((uint64_t)1 << bd));
    wide bn2 = (wide)(XRND() & (((uint64_t)1 << bn) - 1));
    if (XRND() & 1) an = -an;
    if (XRND() & 1) bn2 = -bn2;
    struct grat a = { an, ad > 0 ? ad : 1 }, b;
    switch (XRND() % 4) {
    case 0: b = (struct grat){ bn2, 1 + (wide)(XRND() % ((uint64_t)1 << bd)) }; break;
    case 1: b = (struct grat){ a.num + (wide)(XRND() % 5) - 2, a.den }; break;
    case 2: { const wide k = 1 + (wide)(XRND() % 1000);
              b = (struct grat){ a.num * k + (wide)(XRND() % 3) - 1, a.den * k }; break; }
    default: b = (struct grat){ a.num * 3, a.den * 3 }; break;
    }
    const int want = geom_rat_cmp(a, b);
    const double ka = geom_rat_key(a), kb = geom_rat_key(b);
    double lo, hi;
    key_band(kb, &lo, &hi);
    bad += kx_cmp(ka, kb, &a, &b) != want;
    bad += band_cmp(ka, lo, hi, &a, &b) != want;
    if (ka < lo || ka > hi) keyed++; else exact++;
  }
#undef XRND
  print_message("sweep x order: %ld pairs by the keys, %ld exactly, %ld wrong\n", keyed, exact, bad);
  assert_int_equal(bad, 0);
  assert_true(keyed > 500000 && exact > 300000);
}

static void test_vis_spans(void **state)
{
  (void)state;
  struct render r;
  struct scene *sc = prepare(&r, VISCFG, PRIO_AUTO);
  /* y = -100: bottom of face 1 */
  const struct want_span w0[] = { { -100, 0, 1 } };
  check_spans(&r, G(-100), 1, 1, w0);
  /* y = -50: bottom of faces 2 and 3 (owned) */
  const struct want_span w1[] = { { -100, -50, 1 }, { -50, 50, 2 }, { 80, 120, 3 } };
  check_spans(&r, G(-50), 1, 3, w1);
  /* y = 1/3: the same, exactly */
  check_spans(&r, G(1), 3, 3, w1);
  /* y = 50: top of faces 2 and 3 (not owned) */
  const struct want_span w2[] = { { -100, 0, 1 } };
  check_spans(&r, G(50), 1, 1, w2);
  /* y = 100: top of face 1: nothing */
  check_spans(&r, G(100), 1, 0, NULL);
  render_free(&r);
  scene_free(sc);
}

/* On the crossing scene, on many lines: spans disjoint, ordered, each inside its piece's
   own span, and a point is in a span exactly when some alive piece owns it. */
static void test_vis_spans_invariant(void **state)
{
  (void)state;
  char *tris[2] = { tris_scene(24, 1), tris_scene(16, 7) };
  const char *scenes[] = { CROSSING, MIXED, CYCLIC, tris[0], tris[1] };
  for (int s = 0; s < 5; s++) {
    struct render r;
    struct scene *sc = prepare(&r, scenes[s], PRIO_AUTO);
    int lines = 0;
    for (int64_t y = -150 * 4; y <= 150 * 4; y += 7) {    /* y = y/4 world, some ties */
      const struct vis_span *sp;
      int ns;
      struct t74_error err = { 0, "" };
      assert_int_equal(vis_spans(&r.vis, G(y), 4, &sp, &ns, &err), T74_OK);
      lines++;
      for (int k = 0; k < ns; k++) {
        assert_int_equal(geom_rat_cmp(sp[k].x0, sp[k].x1), -1);
        if (k > 0) assert_true(geom_rat_cmp(sp[k - 1].x1, sp[k].x0) <= 0);
        const struct piece *p = &r.seg.p[sp[k].piece];
        assert_true(p->alive);
        struct grat xl, xr;
        assert_true(seginfo_span(p, G(y), 4, &xl, &xr, &r.cost[0]));
        assert_true(geom_rat_cmp(xl, sp[k].x0) <= 0 && geom_rat_cmp(sp[k].x1, xr) <= 0);
      }
      /* sample x on a fine lattice: covered <=> some alive piece owns it */
      for (int64_t x = -200 * 8; x <= 200 * 8; x += 5) {
        int64_t xn = G(x), xd = 8;
        bool in_span = false;
        for (int k = 0; k < ns; k++)
          if (geom_rat_cmp_frac(sp[k].x0, xn, xd) <= 0 && geom_rat_cmp_frac(sp[k].x1, xn, xd) > 0)
            in_span = true;
        bool owned = false;
        for (int q = 0; q < r.seg.n && !owned; q++) {
          if (!r.seg.p[q].alive) continue;
          struct grat xl, xr;
          if (seginfo_span(&r.seg.p[q], G(y), 4, &xl, &xr, &r.cost[0]) &&
              geom_rat_cmp_frac(xl, xn, xd) <= 0 && geom_rat_cmp_frac(xr, xn, xd) > 0)
            owned = true;
        }
        if (in_span != owned)
          fail_msg("scene %d y=%g x=%g: in a span %d, owned by a piece %d", s, y / 4.0,
                   x / 8.0, in_span, owned);
      }
    }
    assert_true(lines > 100);
    /* the triangles: splits were met inside sweeps, which went on from there */
    if (s >= 3) assert_true(r.vis.resumes > 0);
    render_free(&r);
    scene_free(sc);
  }
  free(tris[0]);
  free(tris[1]);
}

/* Two renders of one scene, one with a host shortcut turned off, did the same work: the
   same picture (a, b), pairs computed and cut, pieces, 1974 operations in every stage and
   core words. */
static void same_work(const struct render *r1, const struct render *r2, const uint16_t *a,
                      const uint16_t *b)
{
  assert_memory_equal(a, b, GW * GH * sizeof *a);
  assert_true(r1->prio.computed == r2->prio.computed);
  assert_int_equal(r1->prio.splits, r2->prio.splits);
  assert_int_equal(r1->seg.n, r2->seg.n);
  assert_memory_equal(r1->cost, r2->cost, sizeof r1->cost);
  assert_int_equal(core_peak(r1->core), core_peak(r2->core));
}

/* The sparse store's tags (priority.c) change nothing but host time: looks walked through
   them and looks that probe the table itself give the same picture, the same pairs
   computed and cut, the same 1974 operations counted in every stage (the words each probe
   compares) and the same core words, on triangles that pierce each other (pairs held and
   not held asked again and again while the table fills and is rebuilt). Pieces numbered
   from 2^16 on (a slot's first word not 0) are the 100,000 boxes of tools/cmp_stats.sh. */
static void test_prio_tags_exact(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  struct render r1, r2;
  struct scene *s1 = prepare(&r1, tris, PRIO_SPARSE);
  struct scene *s2 = prepare(&r2, tris, PRIO_SPARSE);
  free(tris);
  r2.prio.tag_off = 1;
  scan_ids(&r1, a);
  scan_ids(&r2, b);
  assert_true(r1.prio.tag_looks > 0);
  assert_true(r2.prio.tag_looks == 0);
  assert_true(r1.prio.splits > 0);
  same_work(&r1, &r2, a, b);
  free(a);
  free(b);
  render_free(&r1);
  render_free(&r2);
  scene_free(s1);
  scene_free(s2);
}

/* The vertices of pieces on their face's points taken from the points as (x, y, 1)
   (priority.c face_verts) against those geom_meet makes, (W x, W y, W): the same
   picture, pairs computed and cut, 1974 operations and core words, in both stores, on
   triangles that pierce each other (such pieces decided, cut, and their halves decided)
   and on two shipped scenes whose faces share edges (the pairs decided at the vertex
   farthest from the common edge): the sphere and the street. */
static void test_prio_face_verts_exact(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  const char *shipped[2] = { "scenes/sphere.s74", "scenes/street.s74" };
  const int stores[2] = { PRIO_DENSE, PRIO_SPARSE };
  for (int k = 0; k < 6; k++) {
    uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
    struct render r[2];
    struct scene *sc[2];
    for (int w = 0; w < 2; w++) {
      if (k < 2) {
        sc[w] = prepare(&r[w], tris, stores[k % 2]);
      } else {
        struct scene_opts so;
        memset(&so, 0, sizeof so);
        struct t74_error err = { 0, "" };
        sc[w] = NULL;
        assert_int_equal(scene_load(shipped[(k - 2) / 2], &so, &sc[w], &err), T74_OK);
        prepare_scene(&r[w], sc[w], stores[k % 2], false, NULL);
      }
    }
    r[1].prio.verts_off = 1;
    scan_ids(&r[0], a);
    scan_ids(&r[1], b);
    if (k < 2) assert_true(r[0].prio.splits > 0);
    assert_true(r[0].prio.computed > 0);
    same_work(&r[0], &r[1], a, b);
    free(a);
    free(b);
    for (int w = 0; w < 2; w++) {
      render_free(&r[w]);
      scene_free(sc[w]);
    }
  }
  free(tris);
}

/* Two host shortcuts of the deciding change nothing but host time: the stretch a pair is
   met on (priority.c, "The stretch"), which answers overlap tests, against every test
   made (meet_off); the face pairs kept (priority.c, "Face pairs") against each found
   afresh (faces_off), also with the table started at its smallest size, so that it grows
   while the frame is decided (its entries moved). Each way gives the same picture, pairs
   computed and cut, 1974 operations in every stage and core words, on triangles that
   pierce each other (both stores: the triangle and the hashed pairs). */
static void test_prio_shortcuts_exact(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  const int stores[2] = { PRIO_DENSE, PRIO_SPARSE };
  for (int k = 0; k < 6; k++) {
    uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
    struct render r1, r2;
    struct scene *s1 = prepare(&r1, tris, stores[k % 2]);
    struct scene *s2 = prepare(&r2, tris, stores[k % 2]);
    if (k < 2) r2.prio.meet_off = 1;
    else r2.prio.faces_off = 1;
    if (k >= 4) r1.prio.faces_first_bits = 6;
    scan_ids(&r1, a);
    scan_ids(&r2, b);
    if (k < 2) {
      assert_true(r1.prio.meet_known > 0);
      assert_true(r2.prio.meet_known == 0);
    } else {
      assert_true(r1.prio.faces_kept > 0);
      assert_true(r2.prio.faces_kept == 0);
      assert_true((r1.prio.faces_grown > 0) == (k >= 4));
    }
    assert_true(r1.prio.splits > 0);
    same_work(&r1, &r2, a, b);
    free(a);
    free(b);
    render_free(&r1);
    render_free(&r2);
    scene_free(s1);
    scene_free(s2);
  }
  free(tris);
}

/* render/pool.h: each request aligned and inside a block, what is handed out not reused
   before pool_reset, the same blocks (the same addresses, in the order handed out) after
   it, a request larger than a block in a block of its own. */
static void test_pool(void **state)
{
  (void)state;
  struct pool p = { 0 };
  char *got[200];
  size_t size[200];
  for (int k = 0; k < 200; k++) {
    size[k] = (size_t)(k % 7) * 1000 + 1 + (k == 100 ? ((size_t)3 << 20) : 0);
    size_t align = (size_t)1 << (k % 5);
    got[k] = pool_alloc(&p, size[k], align);
    assert_non_null(got[k]);
    assert_int_equal((uintptr_t)got[k] % align, 0);
    memset(got[k], k, size[k]);
  }
  for (int k = 0; k < 200; k++)                /* nothing overwritten: no overlap */
    for (size_t b = 0; b < size[k]; b += 97) assert_int_equal((unsigned char)got[k][b], k);
  pool_reset(&p);
  assert_null(p.used);
  assert_non_null(p.spare);
  for (int k = 0; k < 200; k++) {
    char *again = pool_alloc(&p, size[k], (size_t)1 << (k % 5));
    if (k == 0) assert_true(again != NULL);
    assert_true(again == got[k]);              /* the same blocks, handed out alike */
  }
  pool_free(&p);
  assert_null(p.used);
  assert_null(p.spare);
}

/* Three coplanar squares, the upper two meeting the lower one's top edge at a vertex of
   theirs inside it (a T-junction: the Mapper inserts vertex 5 into face 1's edge 3-4). */
static const char TJUNCTION[] =
  HDR "vertex 1 -100 -100 0\nvertex 2 100 -100 0\nvertex 3 100 0 0\nvertex 4 -100 0 0\n"
      "vertex 5 0 0 0\nvertex 6 100 100 0\nvertex 7 -100 100 0\nvertex 8 0 100 0\n"
      "face 1 1 2 3 4 grey 90\nface 2 4 5 8 7 grey 160\nface 3 5 3 6 8 grey 230\n";

/* A render of one loaded scene, the T-junctions kept in `keep` (NULL: none kept); scanned. */
static void render_kept(struct render *r, const struct scene *s, struct render_keep *keep,
                        uint16_t *ids)
{
  prepare_scene(r, s, PRIO_AUTO, true, keep);
  scan_ids(r, ids);
}

/* Two mapped scenes are the same: every face's number, plane, rings, points and vertices. */
static void same_mapped(const struct mapped *x, const struct mapped *y)
{
  assert_int_equal(x->nface, y->nface);
  assert_int_equal(x->dropped, y->dropped);
  for (int f = 0; f < x->nface; f++) {
    const struct mface *a = &x->f[f], *b = &y->f[f];
    assert_int_equal(a->id, b->id);
    assert_int_equal(a->on, b->on);
    assert_int_equal(a->sface, b->sface);
    assert_int_equal(a->sline, b->sline);
    assert_memory_equal(a->plane, b->plane, sizeof a->plane);
    assert_true(a->deye == b->deye);
    assert_int_equal(a->nring, b->nring);
    assert_memory_equal(a->ring_start, b->ring_start, (size_t)(a->nring + 1) * sizeof *a->ring_start);
    int n = a->ring_start[a->nring];
    assert_memory_equal(a->pt, b->pt, (size_t)n * sizeof *a->pt);
    assert_memory_equal(a->vid, b->vid, (size_t)n * sizeof *a->vid);
    assert_memory_equal(a->vix, b->vix, (size_t)n * sizeof *a->vix);
    assert_int_equal(a->grey, b->grey);
  }
}

/* The figures of two renders of one scene agree: the operations charged per stage, the
   core, the mapped faces, the pieces. */
static void same_render(const struct render *x, const struct render *y)
{
  assert_memory_equal(x->cost, y->cost, sizeof x->cost);
  assert_int_equal(core_peak(x->core), core_peak(y->core));
  assert_int_equal(core_words(x->core), core_words(y->core));
  same_mapped(&x->map, &y->map);
  assert_int_equal(x->seg.n, y->seg.n);
}

/* Issue 19: the T-junctions found by one render are kept for the next of the same scene,
   and so is its core once it is freed; that render searches no more, and every figure is
   as the search would have made it on a new core: the mapped faces, the pieces, the
   picture, the operations charged per stage, the core's peak. */
static void test_keep_tjunctions(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  const char *scenes[] = { TJUNCTION, tris, MIXED, CROSSING };
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  for (int k = 0; k < 4; k++) {
    struct scene *sc = load_scene(scenes[k]);
    struct render_keep keep;
    memset(&keep, 0, sizeof keep);
    struct render r0, r1;
    render_kept(&r0, sc, NULL, a);            /* nothing kept */
    render_kept(&r1, sc, &keep, b);           /* searched, kept */
    assert_true(keep.map.s == sc);
    assert_null(keep.core);
    assert_memory_equal(a, b, GW * GH * sizeof *a);
    same_render(&r0, &r1);
    struct core *used = r1.core;
    render_free(&r1);
    assert_true(keep.core == used);           /* the core kept for the next frame */
    assert_non_null(keep.seg.spare);          /* and the blocks of the pieces and faces */
    assert_null(keep.seg.used);
    assert_non_null(keep.map.pool.spare);
    for (int again = 0; again < 2; again++) {
      memset(b, 0, GW * GH * sizeof *b);
      render_kept(&r1, sc, &keep, b);         /* taken from keep, on the kept core */
      assert_true(r1.core == used);
      assert_null(keep.core);
      assert_memory_equal(a, b, GW * GH * sizeof *a);
      same_render(&r0, &r1);
      if (k == 0) {                           /* vertex 5 inserted into face 1's top edge */
        assert_int_equal(r1.map.f[0].id, 1);
        assert_int_equal(r1.map.f[0].ring_start[1], 5);
      }
      render_free(&r1);
    }
    render_free(&r0);
    render_keep_free(&keep);
    scene_free(sc);
  }
  free(tris);
  free(a);
  free(b);
}

/* Issue 19: the face-pair table's block is kept from frame to frame (render_keep), at the
   size it grew to, but what it held is of the last frame's view: a next frame seen from
   another eye finds its pairs afresh (its table starts empty), and its picture, pieces and
   priority work are those of a render with nothing kept; the block is the one kept, and
   a kept pair is used again within the frame. */
static void test_keep_face_pairs(void **state)
{
  (void)state;
  char *tris = tris_scene(64, 11);
  struct scene *sc = load_scene(tris);
  uint16_t *a = calloc(GW * GH, sizeof *a), *b = calloc(GW * GH, sizeof *b);
  struct render_keep keep;
  memset(&keep, 0, sizeof keep);
  struct render r0, r1;
  render_kept(&r1, sc, &keep, b);             /* the first view fills the table */
  unsigned bits = r1.prio.faces_bits;
  assert_true(r1.prio.faces_kept > 0);
  render_free(&r1);
  assert_non_null(keep.prio.faces);
  assert_int_equal(keep.prio.faces_bits, bits);
  for (int k = 0; k < 3; k++) {
    sc->view[0] = 40 * (k + 1);               /* another eye */
    sc->view[1] = -30 * (k + 1);
    const struct prio_faces *block = keep.prio.faces;
    render_kept(&r0, sc, NULL, a);            /* nothing kept */
    memset(b, 0, GW * GH * sizeof *b);
    render_kept(&r1, sc, &keep, b);           /* the last view's table kept */
    assert_null(keep.prio.faces);
    assert_true(r1.prio.faces == block);
    assert_int_equal(r1.prio.faces_bits, bits);
    assert_memory_equal(a, b, GW * GH * sizeof *a);
    /* the Mapper's charges are its first search's, kept with the T-junctions (of the
       first view here); the priorities' and the scan's are the frame's own */
    assert_memory_equal(&r0.cost[RS_VISIBLE], &r1.cost[RS_VISIBLE], sizeof r0.cost[RS_VISIBLE]);
    assert_int_equal(r0.seg.n, r1.seg.n);
    assert_true(r1.prio.computed == r0.prio.computed);
    assert_true(r1.prio.faces_kept > 0);
    render_free(&r1);
    render_free(&r0);
  }
  render_keep_free(&keep);
  assert_null(keep.prio.faces);
  scene_free(sc);
  free(tris);
  free(a);
  free(b);
}

/* The points engine's frame: the mapped faces, the faces seen and the counts. */
static void same_points(const struct points *x, const struct points *y)
{
  same_mapped(&x->map, &y->map);
  assert_int_equal(x->faces_split, y->faces_split);
  assert_int_equal(x->faces_culled, y->faces_culled);
  assert_int_equal(x->W, y->W);
  assert_int_equal(x->H, y->H);
  assert_memory_equal(x->face, y->face, (size_t)x->W * (size_t)x->H * sizeof *x->face);
}

/* Issue 19 under --engine points: the rings (T-junctions inserted) found by the first
   call of a scene are kept in points.keep, and a later call maps the very same faces and
   sees the very same face at every point as a call that searched afresh. The kept rings
   are what a later call uses: with face 1's inserted vertex 5 taken out of them, its
   ring has one vertex fewer. */
static void test_points_keep_tjunctions(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  const char *scenes[] = { TJUNCTION, tris, MIXED, CROSSING };
  for (int k = 0; k < 4; k++) {
    struct scene *sc = load_scene(scenes[k]);
    struct vis_grid g = { GW, GH, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
    struct t74_error err = { 0, "" };
    struct mapper_keep keep;
    memset(&keep, 0, sizeof keep);
    struct points p0, p1;
    memset(&p0, 0, sizeof p0);
    memset(&p1, 0, sizeof p1);
    p1.keep = &keep;
    assert_int_equal(points_render(&p0, sc, &g, &err), T74_OK);   /* nothing kept */
    for (int again = 0; again < 3; again++) {  /* searched and kept, then taken from keep */
      assert_int_equal(points_render(&p1, sc, &g, &err), T74_OK);
      assert_true(keep.s == sc);
      same_points(&p0, &p1);
    }
    if (k == 0) {                 /* face 1's ring 1 2 3 4 (indices 0..3) with 5 after 3 */
      assert_int_equal(p1.map.f[0].ring_start[1], 5);
      assert_int_equal(keep.start[0], 0);
      assert_int_equal(keep.start[1], 5);
      assert_int_equal(keep.ring[3], 4);
      keep.ring[3] = keep.ring[2];            /* vertex 3 twice: the second is dropped */
      assert_int_equal(points_render(&p1, sc, &g, &err), T74_OK);
      assert_int_equal(p1.map.f[0].ring_start[1], 4);
    }
    points_free(&p0);
    points_free(&p1);
    mapper_keep_free(&keep);
    scene_free(sc);
  }
  free(tris);
}

/* Issue 19: one points scratch drawing a scene over the whole grid and then one of a
   band across its middle, farther away, sees what a fresh scratch sees in the second (the
   depth bounds are set anew over the rows the second scene's faces visit, not over the
   whole grid: a row left out would still hold the first scene's nearer depths). */
static void test_points_scratch_reuse(void **state)
{
  (void)state;
  static const char FULL[] =
    HDR "vertex 1 -400 -400 -50\nvertex 2 400 -400 -50\nvertex 3 400 400 -50\n"
        "vertex 4 -400 400 -50\nface 1 1 2 3 4 grey 100\n";
  static const char BAND[] =
    HDR "vertex 1 -100 -20 100\nvertex 2 100 -20 100\nvertex 3 100 20 100\n"
        "vertex 4 -100 20 100\nface 1 1 2 3 4 grey 200\n"
        "vertex 5 -30 -60 150\nvertex 6 30 -60 150\nvertex 7 0 60 150\n"
        "face 2 5 6 7 grey 50\n";
  struct scene *full = load_scene(FULL), *band = load_scene(BAND);
  struct vis_grid g = { GW, GH, { band->window[0], band->window[1], band->window[2], band->window[3] } };
  struct t74_error err = { 0, "" };
  struct points p0, p1;
  memset(&p0, 0, sizeof p0);
  memset(&p1, 0, sizeof p1);
  assert_int_equal(points_render(&p0, band, &g, &err), T74_OK);
  assert_int_equal(points_render(&p1, full, &g, &err), T74_OK);
  long seen = 0;
  for (int k = 0; k < GW * GH; k++) seen += p1.face[k] >= 0;
  assert_int_equal(seen, GW * GH);            /* the first scene covers every point */
  assert_int_equal(points_render(&p1, band, &g, &err), T74_OK);
  long drawn = 0;
  for (int k = 0; k < GW * GH; k++) drawn += p0.face[k] >= 0;
  assert_true(drawn > 0 && drawn < GW * GH / 2);
  same_points(&p0, &p1);
  points_free(&p0);
  points_free(&p1);
  scene_free(full);
  scene_free(band);
}

/* Issue 19: the table of faces of one run serves the next (mapper_keep_faces), whatever
   the scene: each run's faces are those of a fresh mapper_run, face for face, also where
   the scene before had more faces, other rings and no face dropped (an edge-on face is
   dropped here, and a face has a hole). */
static void test_mapper_keep_table(void **state)
{
  (void)state;
  static const char dropping[] =
    "view 0 0 -1\nwindow -200 -150 200 150\n"
    "vertex 6 0 0 0\nvertex 7 0 10 0\nvertex 8 0 10 10\nface 3 6 7 8\n"   /* edge-on */
    "vertex 1 1 -1 511\nvertex 2 3 -3 511\nvertex 5 1000 1000 511\nface 1 1 5 2 grey 7\n"
    "vertex 10 -100 -100 0\nvertex 11 -100 100 0\nvertex 12 100 100 0\nvertex 13 100 -100 0\n"
    "vertex 14 -10 -10 0\nvertex 15 10 -10 0\nvertex 16 10 10 0\nvertex 17 -10 10 0\n"
    "face 4 10 11 12 13 * 14 15 16 17\n";
  char *tris = tris_scene(48, 7);
  struct scene *sc[3] = { load_scene(tris), load_scene(dropping), load_scene(TJUNCTION) };
  struct mapper_keep keep;
  memset(&keep, 0, sizeof keep);
  struct t74_error err = { 0, "" };
  struct core *c0 = core_new(1u << 20), *c1 = core_new(1u << 20);
  assert_non_null(c0);
  assert_non_null(c1);
  const struct mface *table = NULL;
  for (int run = 0; run < 5; run++) {
    const struct scene *s = sc[run % 3];
    core_release(c0, 0);
    core_release(c1, 0);
    struct mapped fresh, kept;
    assert_int_equal(mapper_run(s, &fresh, c0, NULL, &err), T74_OK);
    assert_int_equal(mapper_run_kept(s, &kept, c1, NULL, &keep, &err), T74_OK);
    if (run > 0) assert_ptr_equal(kept.f, table);     /* the last run's, not a new one */
    same_mapped(&fresh, &kept);
    if (run % 3 == 1) assert_int_equal(kept.dropped, 1);
    table = kept.f;
    mapper_keep_faces(&kept, &keep);
    assert_null(kept.f);
    mapper_free(&kept);
    mapper_free(&fresh);
  }
  mapper_keep_free(&keep);
  core_free(c0);
  core_free(c1);
  for (int k = 0; k < 3; k++) scene_free(sc[k]);
  free(tris);
}

/* The Mapper with a NULL cost (the points engine) counts nothing and maps exactly as with
   one, which it charges: the faces are the same, T-junctions and all. */
static void test_mapper_uncounted(void **state)
{
  (void)state;
  char *tris = tris_scene(48, 7);
  const char *scenes[] = { TJUNCTION, tris, MIXED };
  for (int k = 0; k < 3; k++) {
    struct scene *sc = load_scene(scenes[k]);
    struct t74_error err = { 0, "" };
    struct core *c0 = core_new(1u << 20), *c1 = core_new(1u << 20);
    assert_non_null(c0);
    assert_non_null(c1);
    struct cost cost = { { 0 } }, none = { { 0 } };
    struct mapped m0, m1;
    assert_int_equal(mapper_run(sc, &m0, c0, &cost, &err), T74_OK);
    assert_int_equal(mapper_run(sc, &m1, c1, NULL, &err), T74_OK);
    assert_true(memcmp(&cost, &none, sizeof cost) != 0);
    same_mapped(&m0, &m1);
    assert_int_equal(core_peak(c0), core_peak(c1));
    mapper_free(&m0);
    mapper_free(&m1);
    core_free(c0);
    core_free(c1);
    scene_free(sc);
  }
  free(tris);
}

/* prio_known only looks: it never decides a pair (computed does not move), says 0 for a
   pair not decided, and for a decided one what prio_order says, both ways round. */
static void test_prio_known(void **state)
{
  (void)state;
  char *tris = tris_scene(20, 3);
  struct render r;
  struct scene *sc = prepare(&r, tris, PRIO_AUTO);
  free(tris);
  uint64_t c0 = r.prio.computed;
  int n = r.seg.n;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) assert_int_equal(prio_known(&r.prio, i, j), 0);
  assert_true(r.prio.computed == c0);
  uint16_t *a = calloc(GW * GH, sizeof *a);
  scan_ids(&r, a);
  uint64_t c1 = r.prio.computed;
  assert_true(c1 > c0);
  int known = 0;
  struct t74_error err = { 0, "" };
  for (int i = 0; i < r.seg.n; i++)
    for (int j = i + 1; j < r.seg.n; j++) {
      int k = prio_known(&r.prio, i, j);
      assert_true(r.prio.computed == c1);
      if (!k) continue;
      known++;
      assert_int_equal(prio_known(&r.prio, j, i), k == PRIO_FIRST ? PRIO_SECOND : PRIO_FIRST);
      assert_int_equal(prio_order(&r.prio, i, j, &err), k);
      assert_true(r.prio.computed == c1);
    }
  assert_true(known > 0);
  free(a);
  render_free(&r);
  scene_free(sc);
}

/* Halves know the piece they were cut from; a piece the Segment Generator made has none;
   a half lies inside its parent (each of its vertices is in every half-plane of the
   parent's, exactly), and both halves of a cut share its face. */
static void test_piece_parents(void **state)
{
  (void)state;
  char *tris = tris_scene(20, 5);
  struct render r;
  struct scene *sc = prepare(&r, tris, PRIO_AUTO);
  free(tris);
  int n0 = r.seg.n;
  for (int k = 0; k < n0; k++) assert_int_equal(r.seg.p[k].parent, -1);
  uint16_t *a = calloc(GW * GH, sizeof *a);
  scan_ids(&r, a);
  assert_true(r.seg.n > n0);
  for (int k = n0; k < r.seg.n; k++) {
    const struct piece *h = &r.seg.p[k];
    assert_true(h->parent >= 0 && h->parent < k);
    const struct piece *P = &r.seg.p[h->parent];
    assert_false(P->alive);
    assert_int_equal(h->face, P->face);
    for (int v = 0; v < h->n; v++)
      for (int l = 0; l < P->n; l++) assert_true(geom_side_h(piece_line(P, l), piece_v(h, v)) >= 0);
  }
  free(a);
  render_free(&r);
  scene_free(sc);
}

/* The D-blocks' incremental spans equal the definition (seginfo_span) exactly on every
   line, whatever the steps between lines: regular rows, irregular steps, and lines with
   another denominator in between (sub-scanlines), on scenes with splits and T-junctions. */
static void test_dblock_matches_definition(void **state)
{
  (void)state;
  const char *scenes[] = { CROSSING, MIXED, CYCLIC };
  for (int s = 0; s < 3; s++) {
    struct render r;
    struct scene *sc = prepare(&r, scenes[s], PRIO_AUTO);
    int checked = 0;
    int64_t y12 = -150 * 12;                 /* y in 1/12 world units, increasing */
    for (int step = 0; y12 <= 150 * 12; step++) {
      /* mostly rows of 7/12; every fifth line a step of 5/12; every seventh line at
         denominator 36 (a third of the way to the next row) */
      int64_t yn = G(y12), yd = 12;
      if (step % 7 == 3) { yn = G(3 * y12 + 1); yd = 36; }
      const struct vis_span *sp;
      int ns;
      struct t74_error err = { 0, "" };
      assert_int_equal(vis_spans(&r.vis, yn, yd, &sp, &ns, &err), T74_OK);
      for (int a = 0; a < r.vis.nact; a++) {
        const struct vis_item *it = &r.vis.act[a];
        const struct piece *p = &r.seg.p[it->piece];
        if (!p->alive) continue;
        struct grat xl, xr;
        bool on = seginfo_span(p, yn, yd, &xl, &xr, &r.cost[0]);
        assert_int_equal(it->on, on);
        if (on) {
          assert_int_equal(geom_rat_cmp(it->xl, xl), 0);
          assert_int_equal(geom_rat_cmp(it->xr, xr), 0);
          checked++;
        }
      }
      y12 += step % 5 == 4 ? 5 : 7;
    }
    assert_true(checked > 100);
    render_free(&r);
    scene_free(sc);
  }
}

/* Each active piece's row in the core's D-BLOCK table holds, after every line, its xb, xe,
   dxb, dxe (16.16, truncated) and y-max as worked from the item itself: dxb, dxe and y-max
   are kept in the item between the lines where they change (visible.c, dblock_fixed), and
   the irregular steps below change the increments within a D-block (a row left with the
   last step's dxb fails). */
static const char SLANTED[] =
  HDR "vertex 1 -120 -100 0\nvertex 2 130 -90 0\nvertex 3 10 140 0\nface 1 1 2 3 grey 100\n"
      "vertex 4 -150 50 50\nvertex 5 100 -130 50\nvertex 6 160 120 50\n"
      "face 2 4 5 6 grey 200\n";

static void test_dblock_rows_match_items(void **state)
{
  (void)state;
  const char *scenes[] = { SLANTED, MIXED, CYCLIC };
  for (int s = 0; s < 3; s++) {
    struct render r;
    struct scene *sc = prepare(&r, scenes[s], PRIO_AUTO);
    int checked = 0, steps = 0;
    int64_t y12 = -150 * 12;
    for (int step = 0; y12 <= 150 * 12; step++) {
      int64_t yn = G(y12), yd = 12;
      if (step % 7 == 3) { yn = G(3 * y12 + 1); yd = 36; }
      const struct vis_span *sp;
      int ns;
      struct t74_error err = { 0, "" };
      assert_int_equal(vis_spans(&r.vis, yn, yd, &sp, &ns, &err), T74_OK);
      const struct core *c = r.vis.seg->core;
      for (int a = 0; a < r.vis.nact; a++) {
        const struct vis_item *it = &r.vis.act[a];
        if (!it->on || !it->core || !r.seg.p[it->piece].alive) continue;
        wide f[4] = { it->xl.num * GEOM_H10_XONE / it->xl.den,
                      it->xr.num * GEOM_H10_XONE / it->xr.den,
                      it->dxl * GEOM_H10_XONE / it->xl.den,
                      it->dxr * GEOM_H10_XONE / it->xr.den };
        for (int w = 0; w < 4; w++)
          assert_int_equal((uint32_t)core_get_int(c, it->core + 2 * (uint32_t)w, 2),
                           (uint32_t)(int64_t)f[w]);
        assert_int_equal(core_read(c, it->core + 8),
                         (uint16_t)(it->ymax.Y / it->ymax.W / GRID_ONE));
        checked++;
        if (it->dxl != 0 && it->dxr != 0) steps++;
      }
      y12 += step % 5 == 4 ? 5 : 7;
    }
    if (s == 0) assert_true(checked > 100 && steps > 50);   /* (the others: upright sides) */
    render_free(&r);
    scene_free(sc);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_geom_orient),
    cmocka_unit_test(test_bblock_y),
    cmocka_unit_test(test_piece_vertices),
    cmocka_unit_test(test_piece_on_face),
    cmocka_unit_test(test_geom_lines),
    cmocka_unit_test(test_geom_rationals),
    cmocka_unit_test(test_i256),
    cmocka_unit_test(test_cross_dot_sign),
    cmocka_unit_test(test_span_tie_rule),
    cmocka_unit_test(test_clip),
    cmocka_unit_test(test_overlap),
    cmocka_unit_test(test_mapper_rounding),
    cmocka_unit_test(test_prio_parallel),
    cmocka_unit_test(test_prio_crossing),
    cmocka_unit_test(test_prio_coplanar),
    cmocka_unit_test(test_prio_computed_once),
    cmocka_unit_test(test_prio_dense_sparse),
    cmocka_unit_test(test_prio_auto_migrates),
    cmocka_unit_test(test_vis_x_keys),
    cmocka_unit_test(test_vis_spans),
    cmocka_unit_test(test_vis_spans_invariant),
    cmocka_unit_test(test_dblock_rows_match_items),
    cmocka_unit_test(test_prio_known),
    cmocka_unit_test(test_prio_shortcuts_exact),
    cmocka_unit_test(test_prio_face_verts_exact),
    cmocka_unit_test(test_prio_tags_exact),
    cmocka_unit_test(test_clip_both),
    cmocka_unit_test(test_pool),
    cmocka_unit_test(test_keep_tjunctions),
    cmocka_unit_test(test_keep_face_pairs),
    cmocka_unit_test(test_points_keep_tjunctions),
    cmocka_unit_test(test_points_scratch_reuse),
    cmocka_unit_test(test_mapper_uncounted),
    cmocka_unit_test(test_mapper_keep_table),
    cmocka_unit_test(test_piece_parents),
    cmocka_unit_test(test_dblock_matches_definition),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
