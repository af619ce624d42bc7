/*
** test_shadow.c — cmocka tests of the shadow polygons' keep (paper 000 §3; effects/shadow.h,
** issue 19).
**
** The points engine keeps each face's shadows in space from one frame to the next and does
** only the view's part at each frame. On the shipped scenes with a parallel and a point
** light (fig6-room, fig6-building) and with a parallel one alone (lprism, sphere), frame
** after frame, with the eye moved between frames (to places where faces turn their other
** side to it, and to where a face's box in space reaches the eye, which that face does the
** long way), the polygons built with the keep are those built without it: the same
** polygons, rings, grid points, owners and lights, in the same order, and the same
** statistics. The 1974 engine's call (counted) neither makes nor reads a keep. The kept
** frames take their vertices onto the grid four an instruction where the processor has
** AVX-512 (grid_all4) and, every other frame, with SSE2's code (shadow_keep_sse2); the long
** way without a keep as the processor takes it; both against the counted one, each vertex
** by itself.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "effects/model.h"
#include "effects/see.h"
#include "effects/shadow.h"
#include "render/points.h"
#include "render/render.h"
#include "render/scene.h"

/* The shadows of s as its view now maps it (keep NULL: the long way); false (nothing
   built) when the view does not map s (a vertex projects off the plane grid). */
static bool build(const struct scene *s, struct shadow_keep **keep, struct fx_polys *out,
                  struct fx_stats *st, struct cost *cost)
{
  struct render r;
  struct render_opts o;
  memset(&r, 0, sizeof r);
  memset(&o, 0, sizeof o);
  o.core_words = 1u << 20;
  struct t74_error err = { 0, "" };
  const int st_ = render_prepare(&r, s, &o, &err);
  if (st_ == T74_EINPUT && strstr(err.msg, "outside the perspective plane")) {
    render_free(&r);
    return false;
  }
  assert_int_equal(st_, T74_OK);
  memset(out, 0, sizeof *out);
  memset(st, 0, sizeof *st);
  assert_int_equal(shadow_build(&r.map, s, keep, out, st, cost, &err), T74_OK);
  render_free(&r);
  return true;
}

/* Each polygon's box and blocks as fx_ring_blocks makes them from its points, ring by ring
   (draw_casts makes a ring of at most FX_POLY_BLOCK points' box and block in a loop of its
   own: the same values). */
static void assert_blocks(const struct fx_polys *a)
{
  for (int k = 0; k < a->n; k++) {
    const struct fx_poly *p = &a->p[k];
    gcoord blk[64][2], box[4] = { INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN };
    size_t nblk = 0;
    for (int r = 0; r < p->nring; r++) {
      assert_true(nblk + (size_t)(p->rs[r + 1] - p->rs[r]) / FX_POLY_BLOCK + 1 <= 64);
      nblk = fx_ring_blocks(p->pt + p->rs[r], p->rs[r + 1] - p->rs[r], blk, nblk, box);
    }
    assert_true(p->xlo == box[0] && p->xhi == box[1] && p->ylo == box[2] && p->yhi == box[3]);
    assert_memory_equal(p->blk, blk, nblk * sizeof *blk);
  }
}

static void assert_same(const struct fx_polys *a, const struct fx_polys *b,
                        const struct fx_stats *sa, const struct fx_stats *sb)
{
  assert_int_equal(a->n, b->n);
  for (int k = 0; k < a->n; k++) {
    const struct fx_poly *p = &a->p[k], *q = &b->p[k];
    assert_int_equal(p->owner, q->owner);
    assert_int_equal(p->light, q->light);
    assert_int_equal(p->nring, q->nring);
    assert_memory_equal(p->rs, q->rs, ((size_t)p->nring + 1) * sizeof *p->rs);
    assert_memory_equal(p->pt, q->pt, (size_t)p->rs[p->nring] * sizeof *p->pt);
    assert_true(p->xlo == q->xlo && p->xhi == q->xhi && p->ylo == q->ylo && p->yhi == q->yhi);
  }
  assert_blocks(a);
  assert_blocks(b);
  assert_int_equal(sa->n, sb->n);
  for (int k = 0; k < sa->n; k++) {
    assert_string_equal(sa->name[k], sb->name[k]);
    assert_true(sa->value[k] == sb->value[k]);
  }
}

/* One frame seen from the scene's view: kept, long way and counted the same (the counted
   one takes each vertex onto the grid by itself, shadow_grid_near or shadow_grid_ld; the
   others by a receiver's bound, shadow_grid_spanned, where it decides); the polygons
   found (-1: the view does not map s). */
static int frame(const struct scene *s, struct shadow_keep **keep, bool sse2)
{
  shadow_keep_sse2(*keep, sse2);            /* (NULL at the first frame: nothing) */
  struct fx_polys a, b, c;
  struct fx_stats sa, sb, sc;
  struct cost cost;
  memset(&cost, 0, sizeof cost);
  if (!build(s, NULL, &a, &sa, NULL)) return -1;
  assert_true(build(s, keep, &b, &sb, NULL));
  assert_true(build(s, NULL, &c, &sc, &cost));
  assert_non_null(*keep);
  assert_same(&a, &b, &sa, &sb);
  assert_same(&a, &c, &sa, &sc);
  const int n = a.n;
  fx_polys_free(&a);
  fx_polys_free(&b);
  fx_polys_free(&c);
  return n;
}

static void test_kept_is_long_way(void **state)
{
  (void)state;
  int near_maps = 0;
  const char *scenes[] = { "scenes/fig6-room.s74", "scenes/fig6-building.s74",
                           "scenes/lprism.s74", "scenes/sphere.s74" };
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
    struct scene *s = NULL;
    struct scene_opts so;
    memset(&so, 0, sizeof so);
    struct t74_error err = { 0, "" };
    assert_int_equal(scene_load(scenes[i], &so, &s, &err), T74_OK);
    assert_true(s->has_light);
    struct shadow_keep *keep = NULL;
    const int32_t view[3] = { s->view[0], s->view[1], s->view[2] };
    int near = 0;                            /* the nearest vertex: z > view[2] */
    for (int v = 1; v < s->nv; v++) if (s->v[v].z < s->v[near].z) near = v;
    const struct scene_vertex *nv = &s->v[near];
    for (int f = 0; f < 3; f++) assert_true(frame(s, &keep, f == 2) > 0);   /* made, taken */
    /* the eye moved: other sides of faces seen, other faces kept by the Mapper; then the
       eye one unit before the nearest vertex (a face there: its box reaches the eye), where
       that view maps the scene (fig6-room's does) */
    const int32_t moved[][3] = { { view[0] + 700, view[1] - 400, view[2] },
                                 { view[0] - 900, view[1] + 650, view[2] },
                                 { nv->x, nv->y, nv->z - 1 },
                                 { view[0], view[1], view[2] } };
    for (size_t m = 0; m < sizeof moved / sizeof *moved; m++) {
      memcpy(s->view, moved[m], sizeof s->view);
      for (int f = 0; f < 2; f++) near_maps += frame(s, &keep, f == 1) >= 0 && m == 2;
    }
    shadow_keep_free(keep);
    scene_free(s);
  }
  assert_true(near_maps > 0);
}

/* The 1974 engine counts the long way at every frame: no keep made, the same charges. */
static void test_counted_keeps_nothing(void **state)
{
  (void)state;
  struct scene *s = NULL;
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct t74_error err = { 0, "" };
  assert_int_equal(scene_load("scenes/fig6-room.s74", &so, &s, &err), T74_OK);
  struct shadow_keep *keep = NULL;
  struct cost ca, cb;
  memset(&ca, 0, sizeof ca);
  memset(&cb, 0, sizeof cb);
  struct fx_polys a, b;
  struct fx_stats sa, sb;
  assert_true(build(s, NULL, &a, &sa, &ca));
  assert_true(build(s, &keep, &b, &sb, &cb));
  assert_null(keep);
  assert_same(&a, &b, &sa, &sb);
  assert_memory_equal(&ca, &cb, sizeof ca);
  assert_true(ca.n[COST_MUL] > 0);
  fx_polys_free(&a);
  fx_polys_free(&b);
  scene_free(s);
}

/* A uniform long double in [lo, hi) (a 64-bit generator's step). */
static long double uni(uint64_t *seed, long double lo, long double hi)
{
  *seed = *seed * 6364136223846793005u + 1442695040888963407u;
  return lo + (hi - lo) * ldexpl((long double)(*seed >> 1), -63);
}

/* shadow_grid_near's filter (a kept shadow vertex onto the grid in doubles, with a bound)
   decides only as shadow_grid_ld's long doubles do: over eyes near and far, vertices at
   random (before, at and behind the eye, near it, past the grid's limit) and vertices
   placed on a grid point's half and the long doubles around it (ties and their
   neighbours, which it must leave to the long way). It decides nearly every vertex well
   before the eye and leaves every tie; it fails when its bound is a tenth of what it is. */
static void test_grid_near_is_long_way(void **state)
{
  (void)state;
  uint64_t seed = 74;
  long decided = 0, random = 0, ties = 0, tie_decided = 0, differ = 0, regular = 0,
       regular_decided = 0;
  const int64_t eyes[][3] = { { 0, 420, -1500 }, { 0, 0, -1 }, { 1200, -800, -40000 },
                              { -3, 7, -200000 }, { 5, 5, 3000 } };
  for (size_t e = 0; e < sizeof eyes / sizeof *eyes; e++) {
    struct shadow_eye v;
    shadow_eye_set(&v, eyes[e]);
    assert_true(v.near);
    const long double *E = v.E;
    for (int i = 0; i < 200000; i++) {
      long double Y[3];
      const int kind = i % 4;
      Y[0] = uni(&seed, -5000, 5000);
      Y[1] = uni(&seed, -5000, 5000);
      Y[2] = kind == 0 ? E[2] + uni(&seed, -10, 10)        /* around the eye */
           : kind == 1 ? E[2] + ldexpl(1, -(int)(i % 60))   /* just before it */
           : E[2] + uni(&seed, 1, 20000);
      if (kind == 3) {                      /* x on a half (a tie) or next to one */
        const long double dz = Y[2] - E[2], f = -E[2];
        const long double k = floorl(uni(&seed, -3000, 3000)) + 0.5L;
        Y[0] = E[0] + (k / GRID_ONE - E[0]) * dz / f;
        for (int s = (int)(i % 7) - 3; s != 0; s += s > 0 ? -1 : 1)
          Y[0] = nextafterl(Y[0], s > 0 ? INFINITY : -INFINITY);
      }
      double yd[3];
      shadow_near(Y, yd);
      struct gpoint a, b = { 0, 0 };
      const bool lands = shadow_grid_ld(&v, Y, &a);
      const int r = shadow_grid_near(&v, yd, &b);
      if (kind == 3) {
        const long double gx = GRID_ONE * (E[0] + -E[2] * (Y[0] - E[0]) / (Y[2] - E[2]));
        const bool tie = fabsl(gx - floorl(gx) - 0.5L) < 0x1p-30L;
        ties += tie;
        tie_decided += tie && r >= 0;
      } else {
        random++;
        regular += kind == 2 && lands;
      }
      if (r < 0) continue;
      decided += kind != 3;
      regular_decided += kind == 2;
      differ += !lands || a.x != b.x || a.y != b.y;
    }
  }
  print_message("grid filter: %ld random vertices, %ld decided (%ld of the %ld landing well "
                "before the eye); %ld near ties, %ld decided; %ld differ\n", random, decided,
                regular_decided, regular, ties, tie_decided, differ);
  assert_int_equal(differ, 0);
  assert_int_equal(tie_decided, 0);
  assert_true(ties > 10000);
  assert_true(regular_decided * 1000 > regular * 999);
  /* not a normal double's size: left to the long way */
  double yd[3];
  shadow_near((const long double[3]){ 1, 0x1p-1010L, 3 }, yd);
  assert_true(isnan(yd[0]) && isnan(yd[2]));
  shadow_near((const long double[3]){ 1, 0, -3 }, yd);
  assert_true(yd[0] == 1 && yd[1] == 0 && yd[2] == -3);
}

/* shadow_grid_spanned (one bound for all the vertices of a span, shadow_bound_set)
   decides only where shadow_grid_near decides, and as it does (so as shadow_grid_ld
   does): over eyes near and far, spans of vertices in boxes of sizes from 1 to 20,000
   units (as a receiver's shadows lie in its box), before the eye near it and far from it,
   each with vertices on a grid point's half (ties) and the long doubles around them. It
   decides nearly every vertex of a span well before the eye and no tie. No bound when a
   vertex of the span lies at or behind the eye, or is NaN. Fails when the bound is a
   thousandth of what it is, or when the span leaves out the z of its vertices. */
static void test_spanned_is_near(void **state)
{
  (void)state;
  uint64_t seed = 1974;
  long n = 0, decided = 0, ties = 0, tie_decided = 0, differ = 0, spans = 0, bounded = 0;
  long far = 0, far_decided = 0;            /* spans 1 unit or more before the eye */
  const int64_t eyes[][3] = { { 0, 420, -1500 }, { -900, 1400, -5000 }, { 0, 0, -1 },
                              { 1200, -800, -40000 }, { 5, 5, 3000 } };
  enum { NV = 64 };
  for (size_t e = 0; e < sizeof eyes / sizeof *eyes; e++) {
    struct shadow_eye v;
    shadow_eye_set(&v, eyes[e]);
    const long double *E = v.E;
    for (int t = 0; t < 3000; t++) {
      long double Y[NV][3], lo[3], size = ldexpl(1, t % 15) * (1 + (t % 7));
      for (int c = 0; c < 3; c++) lo[c] = uni(&seed, -5000, 5000);
      lo[2] = E[2] + (t % 3 == 0 ? uni(&seed, 0.5L, 4) : uni(&seed, 1, 20000));
      double yd[NV][3];
      struct shadow_span sp;
      shadow_span_init(&sp);
      for (int i = 0; i < NV; i++) {
        for (int c = 0; c < 3; c++) Y[i][c] = lo[c] + uni(&seed, 0, size);
        if (i % 4 == 3) {                   /* x on a half (a tie) or next to one */
          const long double dz = Y[i][2] - E[2], f = -E[2];
          const long double k = floorl(GRID_ONE * (E[0] + f * (Y[i][0] - E[0]) / dz)) + 0.5L;
          Y[i][0] = E[0] + (k / GRID_ONE - E[0]) * dz / f;
          for (int s = i % 7 - 3; s != 0; s += s > 0 ? -1 : 1)
            Y[i][0] = nextafterl(Y[i][0], s > 0 ? INFINITY : -INFINITY);
        }
        shadow_near(Y[i], yd[i]);
        shadow_span_add(&sp, yd[i]);
      }
      spans++;
      struct shadow_bound b;
      if (!shadow_bound_set(&b, &v, &sp)) continue;
      bounded++;
      for (int i = 0; i < NV; i++) {
        struct gpoint a, g = { 0, 0 }, h = { 0, 0 };
        const bool lands = shadow_grid_ld(&v, Y[i], &a);
        const int r = shadow_grid_spanned(&v, &b, yd[i], &g);
        const int rn = shadow_grid_near(&v, yd[i], &h);
        const long double gx = GRID_ONE * (E[0] + -E[2] * (Y[i][0] - E[0]) / (Y[i][2] - E[2]));
        const bool tie = fabsl(gx - floorl(gx) - 0.5L) < 0x1p-30L;
        n += !tie && rn >= 0;
        far += !tie && rn >= 0 && t % 3 != 0;
        ties += tie;
        tie_decided += tie && r >= 0;
        if (r < 0) continue;
        decided += !tie;
        far_decided += !tie && t % 3 != 0;
        differ += rn < 0 || !lands || a.x != g.x || a.y != g.y || h.x != g.x || h.y != g.y;
      }
    }
  }
  print_message("spanned filter: %ld spans, %ld bounded; of the %ld vertices shadow_grid_near "
                "decides %ld decided (%ld of the %ld of spans 1 unit or more before the eye); "
                "%ld near ties, %ld decided; %ld differ\n", spans, bounded, n, decided,
                far_decided, far, ties, tie_decided, differ);
  assert_int_equal(differ, 0);
  assert_int_equal(tie_decided, 0);
  assert_true(ties > 10000);
  assert_true(bounded * 2 > spans);
  assert_true(decided * 10 > n * 9);
  assert_true(far_decided * 1000 > far * 999);
  /* a vertex at or behind the eye, or NaN: no bound */
  struct shadow_eye v;
  shadow_eye_set(&v, (const int64_t[3]){ 0, 0, -1000 });
  struct shadow_span sp;
  struct shadow_bound b;
  shadow_span_init(&sp);
  shadow_span_add(&sp, (const double[3]){ 10, 20, 30 });
  assert_true(shadow_bound_set(&b, &v, &sp));
  shadow_span_add(&sp, (const double[3]){ 10, 20, -1000 });
  assert_false(shadow_bound_set(&b, &v, &sp));
  shadow_span_init(&sp);
  shadow_span_add(&sp, (const double[3]){ 10, 20, 30 });
  shadow_span_add(&sp, (const double[3]){ NAN, NAN, NAN });
  assert_false(shadow_bound_set(&b, &v, &sp));
}

/* fx_first_at_or_right (effects/poly.h: a shadow stretch's end as a sample of the row,
   its guess taken as it is when a bound shows it right) is the least i in [0, n] whose
   sample lies at or right of x, as found by the exact compares alone: over rows of
   windows wide and narrow, 1, 2 and 4 samples a point, at crossings at random and at
   crossings on a sample and within a few parts in 2^50 of one on either side (where the
   guess must be left to the compares). Fails when the bound is 0. */
static void test_first_sample_is_exact(void **state)
{
  (void)state;
  uint64_t seed = 1974;
  long checked = 0, differ = 0, near = 0;
  for (int w = 0; w < 300; w++) {
    seed = seed * 6364136223846793005u + 1442695040888963407u;
    const int K = 1 << (seed >> 62 & 1) << (seed >> 61 & 1);
    const int W = 50 + (int)(seed >> 40 & 1023);
    const int32_t XL = (int32_t)(seed >> 20 & 4095) - 2048;
    const int32_t win[4] = { XL, 0, XL + 1 + (int32_t)(seed >> 8 & 4095), 100 };
    const int64_t xd = 2 * (int64_t)K * W, k0 = -K;
    const int n = K * (W + 2);
    struct fx_sample_row r;
    fx_sample_row_set(&r, win, xd, k0, n);
    for (int c = 0; c < 400; c++) {
      seed = seed * 6364136223846793005u + 1442695040888963407u;
      const int i = (int)(seed >> 40) % (n + 8) - 4;
      const int64_t xn = GRID_ONE * (xd * XL + (2 * (k0 + i) + 1) * ((int64_t)win[2] - XL));
      struct grat x;
      if (c % 4 == 0) {                     /* anywhere on the row */
        x.den = 1 + (wide)(seed >> 44);
        x.num = (wide)xn * x.den / xd + (wide)(int64_t)(seed << 20 >> 20) % (x.den * 2 * GRID_ONE);
      } else {                              /* on sample i, or within d / den of it */
        x.den = ((wide)1 << (20 + (int)(seed >> 58 & 31))) + (wide)(seed >> 30 & 255);
        const wide d = (wide)(int)(c % 7) - 3, prod = (wide)xn * x.den;
        x.num = prod / xd - (prod % xd != 0 && prod < 0) + d;
        near++;
      }
      int lo = 0, hi = n;                   /* the least i where x <= its sample */
      while (lo < hi) {
        const int mid = (lo + hi) / 2;
        const int64_t m = GRID_ONE * (xd * XL + (2 * (k0 + mid) + 1) * ((int64_t)win[2] - XL));
        if (geom_rat_cmp_frac(x, m, xd) <= 0) hi = mid; else lo = mid + 1;
      }
      differ += fx_first_at_or_right(&x, geom_rat_key(x), &r) != lo;
      checked++;
    }
  }
  print_message("first sample: %ld crossings (%ld at or near a sample), %ld differ\n",
                checked, near, differ);
  assert_int_equal(differ, 0);
}


/* A grid polygon through point centres (i, j) of grid g (lattice 1). */
static void add_on_centres(struct fx_polys *ps, const struct vis_grid *g, const int (*ij)[2],
                           int n, int owner, int light)
{
  struct gpoint pt[16];
  const int64_t xd = 2 * (int64_t)g->W, yd = 2 * (int64_t)g->H;
  for (int k = 0; k < n; k++) {
    const int64_t xn = GRID_ONE * (xd * g->window[0] + (2 * (int64_t)ij[k][0] + 1) *
                                                        ((int64_t)g->window[2] - g->window[0]));
    const int64_t yn = GRID_ONE * (yd * g->window[3] - (2 * (int64_t)ij[k][1] + 1) *
                                                        ((int64_t)g->window[3] - g->window[1]));
    assert_int_equal(xn % xd, 0);
    assert_int_equal(yn % yd, 0);
    pt[k] = (struct gpoint){ xn / xd, yn / yd };
  }
  int rs[2] = { 0, n };
  assert_true(fx_polys_add(ps, 1, rs, pt, owner, light));
}

/* The lights blocked at sample xn / xd of the line yn / yd on face f, from the model's
   shadows by their exact crossings alone: a light whose polygon has an odd number of
   crossings at or left of the sample. */
static unsigned blocked_exactly(const struct fx_model *m, int f, int64_t yn, int64_t yd,
                                int64_t xn, int64_t xd)
{
  unsigned b = 0;
  if (f < 0) return 0;
  for (int k = m->shadow_first[f]; k < m->shadow_first[f + 1]; k++) {
    const struct fx_poly *p = &m->shadows.p[k];
    struct grat x[64];
    const int nx = fx_poly_cross(p, yn, yd, x, 64, NULL);
    assert_true(nx >= 0);
    int left = 0;
    for (int h = 0; h < nx; h++) left += geom_rat_cmp_frac(x[h], xn, xd) <= 0;
    if (left & 1) b |= 1u << p->light;
  }
  return b;
}

/* What the two tests below set up for a scene under shadows=on on a W x H grid: the scene,
   the points engine's frame and the effects model on it (the engine and the model keep
   pointers to the grid and the effects, so they live together here). */
struct shadow_rig {
  struct scene *s;
  struct effects e;
  struct vis_grid g;
  struct points pts;
  struct fx_engine eng;
  struct fx_stats st;
  struct cost cost;
  struct fx_model m;
};

static void rig_open(struct shadow_rig *r, const char *path, int W, int H)
{
  memset(r, 0, sizeof *r);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.quiet = true;
  struct t74_error err = { 0, "" };
  assert_int_equal(scene_load(path, &so, &r->s, &err), T74_OK);
  assert_int_equal(effects_parse("shadows=on", &r->e, "test", 1, &err), T74_OK);
  r->g = (struct vis_grid){ W, H, { r->s->window[0], r->s->window[1], r->s->window[2],
                                    r->s->window[3] } };
  assert_int_equal(points_render(&r->pts, r->s, &r->g, &err), T74_OK);
  assert_int_equal(fx_engine_points(&r->eng, &r->pts, &r->g, NULL, &err), T74_OK);
  assert_int_equal(fx_model_build(&r->m, &r->eng, r->s, &r->e, NULL, &r->st, &r->cost, &err),
                   T74_OK);
}

static void rig_close(struct shadow_rig *r)
{
  fx_model_free(&r->m);
  fx_engine_free(&r->eng);
  points_free(&r->pts);
  scene_free(r->s);
}

/* The points engine's lights blocked, sample by sample (fx_lines_samples: a polygon of two
   crossings has its ends stepped from row to row, effects/model.c), are those of the
   exact crossings: on fig6-room and fig6-building with their own shadows and with
   polygons whose vertices lie on point centres and whose edges pass through centres
   (slopes 0, 1/2, 4/5, 1, 3 and a ring of many points), the rows from the bottom up at 1,
   2 and 3 samples a point, every third row (wrapping round: steps of other sizes and
   back), and top down. Fails when a crossing exactly on a sample is taken as left of it.
   Also with polygons whose vertices lie far outside the window (2^26 .. 2^27 grid units
   from its centre), one edge through it: their steps' products do not fit in 64 bits
   (edge_start's 128-bit way), beside the others' 64-bit way; fails when an overflow there
   is not seen. And with a rectangle alone on each face, its bottom edge along a row of
   centres: that row, the lowest of the face's polygons, holds a stretch (fails when
   face_ranges takes a face's rows to begin above its polygons' least ylo). Where the row
   passes a vertex and one edge is still crossed, that edge is moved on from the row
   before (fails when it is kept where it was). */
static void test_stepped_ends_are_exact(void **state)
{
  (void)state;
  static const char *const scenes[] = { "scenes/fig6-room.s74", "scenes/fig6-building.s74" };
  long samples = 0, blocked = 0, on_centres = 0, far = 0, differ = 0;
  for (int sc = 0; sc < 2; sc++)
    for (int own = 0; own < 4; own++) {     /* 1: the scene's own; 0: on centres; 2: far;
                                               3: a rectangle alone on centres */
      const int W = 120, H = 90;             /* (centres on the plane grid: 1024 and 1600 apart) */
      struct shadow_rig R;
      rig_open(&R, scenes[sc], W, H);
      struct t74_error err = { 0, "" };
      assert_false(R.m.count);
      assert_true(R.m.shadows.n > 0);
      if (own == 2) {                       /* far polygons, on every face */
        const int64_t cx = GRID_ONE * ((int64_t)R.g.window[0] + R.g.window[2]) / 2;
        const int64_t cy = GRID_ONE * ((int64_t)R.g.window[1] + R.g.window[3]) / 2;
        const int64_t T = (int64_t)1 << 27, U = (int64_t)1 << 26;
        /* a wedge whose edge from (-T, -U) to (T, U + 12345) crosses the window; a steeper
           one (the other light); a triangle round the whole window */
        const struct gpoint wedge[3] = { { cx - T, cy - U }, { cx + T, cy + U + 12345 },
                                         { cx + T, cy - T } };
        const struct gpoint steep[3] = { { cx - U - 777, cy - T }, { cx + U, cy + T },
                                         { cx - T, cy + T } };
        const struct gpoint whole[3] = { { cx - T, cy - T }, { cx + T, cy - U },
                                         { cx, cy + T } };
        const int rs[2] = { 0, 3 };
        fx_polys_free(&R.m.shadows);
        memset(&R.m.shadows, 0, sizeof R.m.shadows);
        for (int f = 0; f < R.eng.map->nface; f++) {
          R.m.shadow_first[f] = R.m.shadows.n;
          assert_true(fx_polys_add(&R.m.shadows, 1, rs, wedge, f, 0));
          assert_true(fx_polys_add(&R.m.shadows, 1, rs, steep, f, 1));
          if (f % 2) assert_true(fx_polys_add(&R.m.shadows, 1, rs, whole, f, 1));
        }
        R.m.shadow_first[R.eng.map->nface] = R.m.shadows.n;
      }
      if (!own) {                           /* polygons on the centres, on every face */
        static const int rect[4][2] = { { 20, 20 }, { 60, 20 }, { 60, 50 }, { 20, 50 } };
        static const int diamond[4][2] = { { 10, 37 }, { 50, 5 }, { 90, 37 }, { 50, 69 } };
        static const int slant[4][2] = { { 5, 60 }, { 45, 40 }, { 51, 58 }, { 15, 70 } };
        static const int steep[3][2] = { { 70, 10 }, { 73, 19 }, { 64, 19 } };
        static const int ring[12][2] = { { 30, 30 }, { 40, 28 }, { 50, 30 }, { 56, 36 },
                                         { 58, 44 }, { 56, 52 }, { 50, 58 }, { 40, 60 },
                                         { 30, 58 }, { 24, 52 }, { 22, 44 }, { 24, 36 } };
        fx_polys_free(&R.m.shadows);
        memset(&R.m.shadows, 0, sizeof R.m.shadows);
        for (int f = 0; f < R.eng.map->nface; f++) {
          R.m.shadow_first[f] = R.m.shadows.n;
          add_on_centres(&R.m.shadows, &R.g, rect, 4, f, 0);
          add_on_centres(&R.m.shadows, &R.g, diamond, 4, f, 1);
          add_on_centres(&R.m.shadows, &R.g, slant, 4, f, 1);
          add_on_centres(&R.m.shadows, &R.g, steep, 3, f, 0);
          add_on_centres(&R.m.shadows, &R.g, ring, 12, f, 1);
        }
        R.m.shadow_first[R.eng.map->nface] = R.m.shadows.n;
      }
      if (own == 3) {                       /* each face's lowest row a stretch's */
        static const int rect[4][2] = { { 20, 20 }, { 60, 20 }, { 60, 50 }, { 20, 50 } };
        fx_polys_free(&R.m.shadows);
        memset(&R.m.shadows, 0, sizeof R.m.shadows);
        for (int f = 0; f < R.eng.map->nface; f++) {
          R.m.shadow_first[f] = R.m.shadows.n;
          add_on_centres(&R.m.shadows, &R.g, rect, 4, f, f % 2);
        }
        R.m.shadow_first[R.eng.map->nface] = R.m.shadows.n;
      }
      for (int K = 1; K <= 3; K++)
        for (int order = 0; order < 3; order++) {
          struct fx_lines *L;
          assert_int_equal(fx_lines_open(&L, &R.m, true, &R.cost, &err), T74_OK);
          const int nk = K * (W + 2), k0 = -K, rows = K * (H + 2);
          int *face = calloc((size_t)nk, sizeof *face);
          unsigned *b = calloc((size_t)nk, sizeof *b);
          assert_true(face && b);
          const int64_t xd = 2 * (int64_t)K * W, yd = 2 * (int64_t)K * H;
          for (int t = 0; t < rows; t++) {
            /* 0: bottom up; 1: every third row up, round again from the bottom; 2: top down */
            const int mr = order == 0 ? rows - 1 - K - t
                         : order == 1 ? rows - 1 - K - (3 * t) % rows
                         : t - K;
            assert_int_equal(fx_lines_samples(L, K, mr, k0, nk, face, b, &err), T74_OK);
            const int64_t yn = GRID_ONE * (yd * R.g.window[3] - (2 * (int64_t)mr + 1) *
                                                              ((int64_t)R.g.window[3] - R.g.window[1]));
            for (int i = 0; i < nk; i++) {
              const int64_t xn = GRID_ONE * (xd * R.g.window[0] + (2 * (int64_t)(k0 + i) + 1) *
                                                                ((int64_t)R.g.window[2] - R.g.window[0]));
              const unsigned want = blocked_exactly(&R.m, face[i], yn, yd, xn, xd);
              if (b[i] != want && differ++ < 4)
                print_message("%s%s K=%d order %d sample (%d, %d) face %d: blocked %u, exactly %u\n",
                              scenes[sc], own == 1 ? "" : own == 2 ? " (far)" : " (on centres)",
                              K, order, k0 + i, mr,
                              face[i], b[i], want);
              samples++;
              blocked += want != 0;
              on_centres += (!own || own == 3) && want != 0;
              far += own == 2 && want != 0;
            }
          }
          free(face);
          free(b);
          fx_lines_close(L);
        }
      rig_close(&R);
    }
  print_message("stepped ends: %ld samples, %ld blocked (%ld by polygons on centres, %ld by far "
                "ones), %ld differ\n", samples, blocked, on_centres, far, differ);
  assert_int_equal(differ, 0);
  assert_true(blocked > 10000 && on_centres > 1000 && far > 1000);
}

/* The points engine's lights blocked on the rows of its own frame (fx_lines_samples at
   K = 1 over the whole row, k0 = 0, n = W: the row the engine drew, whose runs of faces
   shadow_ranges finds on the engine's row with loads of samples i + 1 .. as they lie,
   fx_see_row_drawn), sample by sample, against the exact count (blocked_exactly), and the
   same rows with one sample more on the left (k0 = -1: not the drawn row, the runs found
   on the copy), on grids whose widths end the row at each place in its last word of 64
   samples and in its last four (64 .. 133). With the scenes' own shadows (fig6-room,
   fig6-building) and with a rectangle round the window on every face, of light f % 2
   (those two, the sphere's 160 faces and t1-e's 24: runs of one sample, where a face
   between two runs of another takes their light when its run's ends are not seen). Fails
   when a run's end is missed or the row's last samples are not read. (A run's end found
   where there is none splits a run of one face in two: the same masks.) */
static void test_drawn_rows_are_exact(void **state)
{
  (void)state;
  static const char *const scenes[] = { "scenes/fig6-room.s74", "scenes/fig6-building.s74",
                                         "scenes/sphere.s74", "scenes/t1-e.s74" };
  static const int widths[] = { 64, 65, 66, 67, 68, 69, 70, 71, 72, 80, 84, 85, 100, 101,
                                117, 127, 128, 129, 130, 131, 132, 133 };
  long samples = 0, blocked = 0, differ = 0;
  for (int sc = 0; sc < 4; sc++)
    for (int own = sc < 2; own >= 0; own--)   /* 1: the scene's own; 0: rectangles */
      for (size_t wi = 0; wi < sizeof widths / sizeof *widths; wi++) {
        const int W = widths[wi], H = 3 * W / 4;
        struct shadow_rig R;
        rig_open(&R, scenes[sc], W, H);
        struct t74_error err = { 0, "" };
        assert_true(R.m.shadow_first != NULL && R.m.ncut == 0);
        if (!own) {
          const int64_t G = GRID_ONE;
          const struct gpoint rect[4] = {
            { G * (R.g.window[0] - 1), G * (R.g.window[1] - 1) },
            { G * (R.g.window[2] + 1), G * (R.g.window[1] - 1) },
            { G * (R.g.window[2] + 1), G * (R.g.window[3] + 1) },
            { G * (R.g.window[0] - 1), G * (R.g.window[3] + 1) } };
          const int rs[2] = { 0, 4 };
          fx_polys_free(&R.m.shadows);
          memset(&R.m.shadows, 0, sizeof R.m.shadows);
          for (int f = 0; f < R.eng.map->nface; f++) {
            R.m.shadow_first[f] = R.m.shadows.n;
            assert_true(fx_polys_add(&R.m.shadows, 1, rs, rect, f, f % 2));
          }
          R.m.shadow_first[R.eng.map->nface] = R.m.shadows.n;
        }
        assert_true(R.m.shadows.n > 0);
        for (int left = 0; left < 2; left++) {   /* 0: the drawn row; 1: one sample more */
          struct fx_lines *L;
          assert_int_equal(fx_lines_open(&L, &R.m, true, &R.cost, &err), T74_OK);
          const int k0 = -left, nk = W + left;
          int *face = calloc((size_t)nk, sizeof *face);
          unsigned *b = calloc((size_t)nk, sizeof *b);
          assert_true(face && b);
          const int64_t xd = 2 * (int64_t)W, yd = 2 * (int64_t)H;
          for (int mr = H - 1; mr >= 0; mr--) {   /* (bottom up, as fx_points) */
            assert_int_equal(fx_lines_samples(L, 1, mr, k0, nk, face, b, &err), T74_OK);
            const int64_t SY = (int64_t)R.g.window[3] - R.g.window[1];
            const int64_t SX = (int64_t)R.g.window[2] - R.g.window[0];
            const int64_t yn = GRID_ONE * (yd * R.g.window[3] - (2 * (int64_t)mr + 1) * SY);
            for (int i = 0; i < nk; i++) {
              const int64_t xn = GRID_ONE * (xd * R.g.window[0] + (2 * (int64_t)(k0 + i) + 1) * SX);
              const unsigned want = blocked_exactly(&R.m, face[i], yn, yd, xn, xd);
              const bool bad = b[i] != want ||
                               (k0 + i >= 0 && face[i] != R.pts.face[(size_t)mr * W + k0 + i]);
              if (bad && differ++ < 4)
                print_message("%s%s W=%d k0=%d sample (%d, %d) face %d: blocked %u, exactly "
                              "%u\n", scenes[sc], own ? "" : " (rectangles)", W, k0, k0 + i,
                              mr, face[i], b[i], want);
              samples++;
              blocked += want != 0;
            }
          }
          free(face);
          free(b);
          fx_lines_close(L);
        }
        rig_close(&R);
      }
  print_message("drawn rows: %ld samples, %ld blocked, %ld differ\n", samples, blocked, differ);
  assert_int_equal(differ, 0);
  assert_true(blocked > 100000);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_kept_is_long_way),
    cmocka_unit_test(test_counted_keeps_nothing),
    cmocka_unit_test(test_grid_near_is_long_way),
    cmocka_unit_test(test_spanned_is_near),
    cmocka_unit_test(test_first_sample_is_exact),
    cmocka_unit_test(test_stepped_ends_are_exact),
    cmocka_unit_test(test_drawn_rows_are_exact),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
