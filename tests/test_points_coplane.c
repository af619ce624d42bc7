/*
** test_points_coplane.c — the points engine's exact compare where the doubles cannot
** decide (render/points.c, "Float filter" and struct coplane), point by point against the
** exact reference (tests/ref/exactref.h).
**
** points.c keeps the exact compare's answer against a face o for the rest of face k's
** draw only when the two faces lie in one plane (in_front_exact's *same): there the answer
** is the same at every point. For any other pair the answer changes where the planes
** cross, and must be asked again at each point the doubles leave open.
**
** The scenes make the doubles leave open every point of a crossing: two triangles whose
** planes cross along a line through the window at a dihedral angle of about 2^-45 rad.
** Plane o is x + N y + N^2 (z - Z0) = 0 with N = 32767: its lattice points are far apart
** (|n| ~ 2^30), and the lattice points next to it lie 1/|n| off it. Triangle o has three of
** its lattice points; triangle k has one of them and two lattice points one step in x off
** it (v = x + N y + N^2 (z - Z0) = +1 and -1), so plane k crosses plane o along the line
** through its on-plane vertex and the middle of the other two: x = 0. At 2000 units from
** the eye, a point (about 6 units there) away from that line, the two depths differ by
** about 2^-45 6 / 2000, some 2^-53 of the depth, far below the filter's 2^-40 M: the exact
** compare decides the whole overlap, with k in front on one side of the line and o on the
** other. Kept from the first point for the whole draw (a break of struct coplane's rule)
** the answer is wrong on one side: thousands of points.
**
** A pattern coplanar with o, drawn before k, keeps its answer against o while it is drawn;
** that answer must not reach k's draw (struct coplane is face k's, made anew for each face).
**
** Every point of every scene, in both cell sizes and in four drawing orders (the engine's
** own, the Mapper's order without tiles, two shuffled), must agree with xr_judge (0, or 1
** on the crossing line itself: the reference's band there).
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
#include "tests/ref/xdiff.h"

#define N 32767
#define Z0 1000

static int vtx(struct xr_scene *s, int32_t x, int32_t y, int32_t z)
{
  int v = xr_vertex(s, x, y, z);
  assert_true(v >= 0);
  return v;
}

static void tri(struct xr_scene *s, unsigned id, int a, int b, int c, int grey)
{
  int vi[3] = { a, b, c };
  int f = xr_face(s, id, 3, vi);
  assert_true(f >= 0);
  s->f[f].grey = grey;
}

/* v(x, y, z) = x + N y + N^2 (z - Z0): 0 on plane o, the lattice's steps off it. */
static long long plane_o(int32_t x, int32_t y, int32_t z)
{
  return (long long)x + (long long)N * y + (long long)N * N * (z - Z0);
}

/* The scene: eye (0, 0, -1000), the window of crossing.s74. `which`:
   0: o (face 1) and k (face 2) crossing along x = 0;
   1: the same with the face numbers swapped (k drawn against o with the coplanar rule's
      other side of the numbers);
   2: scene 0 and a pattern p (face 3) in plane o over the quadrant x > 0, y > 0, so that
      face k meets o and p by turns; p (and o with it, a pair of one plane whose answer
      is kept while p is drawn) comes before k in the file. */
static void build(struct xr_scene *s, int which)
{
  memset(s, 0, sizeof *s);
  s->eye[0] = 0, s->eye[1] = 0, s->eye[2] = -1000;
  s->win[0] = -200, s->win[1] = -150, s->win[2] = 200, s->win[3] = 150;
  /* plane o's lattice points: (-N, 1 - N, Z0 + 1), (N, -1, Z0), (0, N, Z0 - 1), (0, 0, Z0) */
  int a = vtx(s, -N, 1 - N, Z0 + 1), b = vtx(s, N, -1, Z0), c = vtx(s, 0, N, Z0 - 1);
  assert_true(plane_o(-N, 1 - N, Z0 + 1) == 0 && plane_o(N, -1, Z0) == 0 &&
              plane_o(0, N, Z0 - 1) == 0 && plane_o(0, 0, Z0) == 0);
  int ka = vtx(s, -N + 1, 1 - N, Z0 + 1), kb = vtx(s, N - 1, -1, Z0);
  assert_true(plane_o(-N + 1, 1 - N, Z0 + 1) == 1 && plane_o(N - 1, -1, Z0) == -1);
  unsigned io = which == 1 ? 2 : 1, ik = which == 1 ? 1 : 2;
  tri(s, io, a, b, c, 80);
  if (which == 2) {                   /* before k in the file: drawn before it in the Mapper's
                                         order, its answer against o kept while it is drawn
                                         must not reach k's draw */
    int z = vtx(s, 0, 0, Z0);
    tri(s, 3, z, b, c, 140);
  }
  tri(s, ik, ka, kb, c, 200);
}

/* The engine's ids of scene x in one cell size and one drawing order, judged point by
   point; returns the points outside the reference's band, and adds the points the two
   faces' crossing leaves to the band (on the line) to *band, the points where face k
   (id ik) is seen to *seen_k. */
static long judge(struct xr_scene *x, int cell, int order, const char *name, long *band,
                  long *seen_k, unsigned ik)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  assert_int_equal(xd_load(x, &sc, &err), T74_OK);
  int W = 400 / cell, H = 300 / cell;
  struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  struct points p;
  memset(&p, 0, sizeof p);
  p.no_tiles = order == 1;
  p.shuffle = order >= 2 ? (uint64_t)order * 7919u : 0;
  assert_int_equal(points_render(&p, sc, &g, &err), T74_OK);
  struct xr_ref ref;
  assert_int_equal(xr_prepare(x, cell, &ref), 0);
  long bad = 0;
  for (int j = 0; j < H; j++)
    for (int i = 0; i < W; i++) {
      int32_t f = p.face[(size_t)j * (size_t)W + (size_t)i];
      unsigned got = f < 0 ? 0u : p.map.f[f].id, want;
      int v = xr_judge(&ref, i, j, got, &want);
      if (v > 0) (*band)++;
      if (got == ik) (*seen_k)++;
      if (v < 0 && bad++ < 4)
        print_message("%s cell %d order %d: point (%d, %d) shows %u, the reference %u\n",
                      name, cell, order, i, j, got, want);
    }
  xr_ref_free(&ref);
  points_free(&p);
  scene_free(sc);
  return bad;
}

static void test_crossing_decided_point_by_point(void **state)
{
  (void)state;
  static const char *const names[] = { "crossing", "crossing-swapped", "crossing-pattern" };
  for (int which = 0; which < 3; which++) {
    struct xr_scene x;
    build(&x, which);
    unsigned ik = which == 1 ? 1 : 2;
    for (int cell = 3; cell <= 4; cell++)
      for (int order = 0; order < 4; order++) {
        long band = 0, seen_k = 0;
        long bad = judge(&x, cell, order, names[which], &band, &seen_k, ik);
        assert_int_equal(bad, 0);
        /* k is seen on its side of the line only, over many points; o on the other */
        int W = 400 / cell, H = 300 / cell;
        assert_true(seen_k > (long)W * H / 8);
        assert_true(seen_k < (long)W * H * 7 / 8);
        assert_true(band <= H);       /* the band: at most the points on the line */
      }
    xr_scene_free(&x);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_crossing_decided_point_by_point),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
