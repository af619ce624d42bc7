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
** statistics. The 1974 engine's call (counted) neither makes nor reads a keep.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdbool.h>
#include <string.h>

#include "effects/shadow.h"
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
  }
  assert_int_equal(sa->n, sb->n);
  for (int k = 0; k < sa->n; k++) {
    assert_string_equal(sa->name[k], sb->name[k]);
    assert_true(sa->value[k] == sb->value[k]);
  }
}

/* One frame seen from the scene's view: kept and long way the same; the polygons found
   (-1: the view does not map s). */
static int frame(const struct scene *s, struct shadow_keep **keep)
{
  struct fx_polys a, b;
  struct fx_stats sa, sb;
  if (!build(s, NULL, &a, &sa, NULL)) return -1;
  assert_true(build(s, keep, &b, &sb, NULL));
  assert_non_null(*keep);
  assert_same(&a, &b, &sa, &sb);
  const int n = a.n;
  fx_polys_free(&a);
  fx_polys_free(&b);
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
    for (int f = 0; f < 3; f++) assert_true(frame(s, &keep) > 0);   /* made, then taken */
    /* the eye moved: other sides of faces seen, other faces kept by the Mapper; then the
       eye one unit before the nearest vertex (a face there: its box reaches the eye), where
       that view maps the scene (fig6-room's does) */
    const int32_t moved[][3] = { { view[0] + 700, view[1] - 400, view[2] },
                                 { view[0] - 900, view[1] + 650, view[2] },
                                 { nv->x, nv->y, nv->z - 1 },
                                 { view[0], view[1], view[2] } };
    for (size_t m = 0; m < sizeof moved / sizeof *moved; m++) {
      memcpy(s->view, moved[m], sizeof s->view);
      for (int f = 0; f < 2; f++) near_maps += frame(s, &keep) >= 0 && m == 2;
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

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_kept_is_long_way),
    cmocka_unit_test(test_counted_keeps_nothing),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
