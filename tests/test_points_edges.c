/*
** test_points_edges.c — the points engine's crossings of long edges and its drawing order
** (render/points.c: edge_rows, paint_order), judged point by point against the exact
** reference (tests/ref/exactref.h).
**
** edge_rows steps an edge of four rows or more in two chains, two rows a step (2 dR's
** quotient and remainder made from dR's); paint_order draws a lazy frame's faces farthest
** first. Scenes: 150 seeds of six triangles each, spread over up to twice the window's
** height (edges of many rows, of every slope, some leaving the grid so that col_of's
** clamps are asked too), each triangle in a plane of its own at depths apart (so the
** reference's answer is never in its band), in both cell sizes. Every point's face must
** be the reference's, in the engine's order (paint_order) and in the Mapper's (no_tiles);
** the frames are lazy (large faces), as the test checks.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/points.h"
#include "render/scene.h"
#include "tests/ref/exactref.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/xdiff.h"

/* A whole number in lo .. hi from the generators' random stream (scenegen.h's splitmix64). */
static int32_t rnd(sg_rng *x, int32_t lo, int32_t hi) { return (int32_t)sg_range(x, lo, hi); }

/* Six triangles of seed `seed`, eye (0, 0, -1000), window -200 .. 200 x -150 .. 150:
   triangle t in the plane z = 100 t + a tilt of up to 20 across it, none meeting another
   (their depths 100 apart), vertices up to 300 units up or down (edges of up to about
   twice the window's height). */
static void build(struct xr_scene *s, uint64_t seed)
{
  memset(s, 0, sizeof *s);
  s->eye[0] = 0, s->eye[1] = 0, s->eye[2] = -1000;
  s->win[0] = -200, s->win[1] = -150, s->win[2] = 200, s->win[3] = 150;
  sg_rng x = { seed };
  for (int t = 0; t < 6; t++) {
    int vi[3];
    for (int k = 0; k < 3; k++) {
      const int32_t z = 100 * (6 - t) + rnd(&x, 0, 20);
      vi[k] = xr_vertex(s, rnd(&x, -260, 260), rnd(&x, -300, 300), z);
      assert_true(vi[k] >= 0);
    }
    const int f = xr_face(s, (unsigned)t + 1, 3, vi);
    assert_true(f >= 0);
    s->f[f].grey = 40 + 30 * t;
  }
}

/* Scene x in one cell size and order (0: the engine's, 1: no_tiles, the Mapper's), judged
   point by point; returns the points the reference does not accept, and adds the points
   showing a face to *shown. */
static long judge(struct xr_scene *x, int cell, int order, uint64_t seed, long *shown)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  if (xd_load(x, &sc, &err) != T74_OK) return -1;   /* (refused: the caller counts it) */
  int W = 400 / cell, H = 300 / cell;
  struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  struct points p;
  memset(&p, 0, sizeof p);
  p.no_tiles = order == 1;
  assert_int_equal(points_render(&p, sc, &g, &err), T74_OK);
  struct xr_ref ref;
  assert_int_equal(xr_prepare(x, cell, &ref), 0);
  long bad = 0;
  for (int j = 0; j < H; j++)
    for (int i = 0; i < W; i++) {
      int32_t f = p.face[(size_t)j * (size_t)W + (size_t)i];
      unsigned got = f < 0 ? 0u : p.map.f[f].id, want;
      if (got) (*shown)++;
      if (xr_judge(&ref, i, j, got, &want) < 0 && bad++ < 4)
        print_message("seed %llu cell %d order %d: point (%d, %d) shows %u, the reference "
                      "%u\n", (unsigned long long)seed, cell, order, i, j, got, want);
    }
  xr_ref_free(&ref);
  points_free(&p);
  scene_free(sc);
  return bad;
}

static void test_long_edges_point_by_point(void **state)
{
  (void)state;
  long bad = 0, shown = 0, scenes = 0;
  for (uint64_t seed = 1; seed <= 150; seed++) {
    struct xr_scene x;
    build(&x, seed);
    for (int cell = 3; cell <= 4; cell++)
      for (int order = 0; order < 2; order++) {
        const long b = judge(&x, cell, order, seed, &shown);
        if (b < 0) continue;
        bad += b;
        scenes++;
      }
    xr_scene_free(&x);
  }
  print_message("long edges: %ld renders, %ld points showing a face, %ld differ\n", scenes,
                shown, bad);
  assert_int_equal(bad, 0);
  assert_true(scenes >= 500);                   /* (few refused) */
  assert_true(shown > scenes * 2000);           /* large faces: lazy frames, long edges */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_long_edges_point_by_point),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
