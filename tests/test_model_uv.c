/*
** test_model_uv.c — cmocka tests of the space points fx_points takes for a run of a
** smoothed face's points (effects/model.c: uv_pairs, through fx_space_uv).
**
** A face's run of two pairs or more is taken without space_point's select of t = 1 where
** the ray's denominator den is 0, where den is > 0 at the run's first and last points or
** < 0 at both (den_not_zero; the proof beside it needs the run's plane positions in
** order). Each point's two coordinates must be the one-point path's (fx_space_points with
** n = 1) bit for bit: on the shipped smoothed scenes' faces along every row, and on a
** face built by hand whose den is exactly 0 at a point of the run, at its ends and next to
** them (there the one-point path's t is 1, a quotient by 0 would give infinities).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "effects/fx.h"
#include "effects/model.h"
#include "render/effects.h"
#include "render/points.h"
#include "render/scene.h"

/* fx_space_uv over px[0 .. n) of face f, each of the three axis pairs, against the
   one-point path; returns the points that differ (the first few printed). */
static long uv_against_single(const struct fx_model *m, int f, int n, const double *px,
                              double py, const char *what)
{
  double xu[512], xw[512];
  long bad = 0;
  assert_true(n % 2 == 0 && n <= 512);
  for (int u = 0; u < 3; u++) {
    fx_space_uv(m, f, n, px, py, u, xu, xw);
    for (int p = 0; p < n; p++) {
      double one[1][3];
      fx_space_points(m, f, 1, px + p, py, one);
      if (!memcmp(&xu[p], &one[0][u], sizeof xu[p]) &&
          !memcmp(&xw[p], &one[0][(u + 1) % 3], sizeof xw[p]))
        continue;
      if (bad++ < 4)
        print_message("%s face %d py %.17g px %.17g axis %d: %.17g %.17g, alone %.17g %.17g\n",
                      what, f, py, px[p], u, xu[p], xw[p], one[0][u], one[0][(u + 1) % 3]);
    }
  }
  return bad;
}

/* Every mapped face of the smoothed shipped scenes along every row of two grids, the
   point centres in order: the face's runs as the points engine sees them (each from its
   first point, an even count) and the whole row (the face's plane beyond its edges). */
static void test_uv_runs_are_single(void **state)
{
  (void)state;
  static const char *const names[] = { "t1-a", "t1-g", "lprism", "sphere" };
  static const int grids[][2] = { { 133, 100 }, { 200, 150 } };
  long runs = 0, long_runs = 0, rows = 0, bad = 0;
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
    for (size_t gi = 0; gi < sizeof grids / sizeof grids[0]; gi++) {
      char path[64];
      snprintf(path, sizeof path, "scenes/%s.s74", names[k]);
      struct scene *sc = NULL;
      struct t74_error err = { 0, "" };
      struct scene_opts so;
      memset(&so, 0, sizeof so);
      so.quiet = true;
      assert_int_equal(scene_load(path, &so, &sc, &err), T74_OK);
      struct effects e;
      if (effects_parse(sc->effects ? sc->effects : "", &e, "test", 1, &err) != T74_OK)
        fail_msg("%s", err.msg);
      const int W = grids[gi][0], H = grids[gi][1];
      struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
      struct points p;
      memset(&p, 0, sizeof p);
      assert_int_equal(points_render(&p, sc, &g, &err), T74_OK);
      struct fx_engine eng;
      assert_int_equal(fx_engine_points(&eng, &p, &g, NULL, &err), T74_OK);
      struct fx_stats st;
      memset(&st, 0, sizeof st);
      struct cost cost = { { 0 } };
      struct fx_model m;
      assert_int_equal(fx_model_build(&m, &eng, sc, &e, NULL, &st, &cost, &err), T74_OK);
      double px[512];
      assert_true(W <= 512);
      for (int i = 0; i < W; i++)             /* plane_x's: non-decreasing */
        px[i] = sc->window[0] + (i + 0.5) * (double)(sc->window[2] - sc->window[0]) / W;
      for (int j = 0; j < H; j++) {
        const double py = sc->window[3] - (j + 0.5) * (double)(sc->window[3] - sc->window[1]) / H;
        const int *row = p.face + (size_t)j * (size_t)W;
        for (int i = 0; i < W;) {             /* the row's runs of one face */
          int e2 = i + 1;
          while (e2 < W && row[e2] == row[i]) e2++;
          const int n = (e2 - i) & ~1;
          if (row[i] >= 0 && n) {
            bad += uv_against_single(&m, row[i], n, px + i, py, names[k]);
            runs++;
            long_runs += n >= 4;
          }
          i = e2;
        }
        for (int f = 0; f < m.map->nface; f++, rows++)
          bad += uv_against_single(&m, f, W & ~1, px, py, names[k]);
      }
      fx_model_free(&m);
      fx_engine_free(&eng);
      points_free(&p);
      scene_free(sc);
    }
  print_message("uv runs: %ld runs (%ld of two pairs or more), %ld whole rows; %ld differ\n",
                runs, long_runs, rows, bad);
  assert_int_equal(bad, 0);
  assert_true(long_runs > 2500 && rows > 50000);
}

/* A face built by hand (whole-number ray and eye, so that den = 3 px - 2 py + 4930 is
   exact at whole-number and half plane positions): den exactly 0 at px = z = (2 py -
   4930) / 3 on the rows where that is a whole number. Runs of 2 to 12 points in order,
   from every start around z: z inside the run, at its first or last point, just outside
   it; and runs on one side of z (den of one sign: no select). Where den is 0 the one-point
   path's t is 1 and its space point E + D; the two pairs' loop without the select would
   divide by 0. */
static void test_uv_den_zero(void **state)
{
  (void)state;
  struct fx_model m;
  memset(&m, 0, sizeof m);
  double ray[1][4] = { { 3, -2, 5, 7000 } };
  m.ray = ray;
  m.eye[0] = 10; m.eye[1] = -20; m.eye[2] = -1000;
  long runs = 0, zero_inside = 0, zero_end = 0, one_sign = 0, bad = 0;
  for (int py = -60; py <= 60; py++) {
    if ((2 * py - 4930) % 3) continue;
    const double z = (2 * py - 4930) / 3;
    for (int n = 2; n <= 12; n += 2)
      for (int s = -n - 2; s <= 2; s++)
        for (int step = 1; step <= 2; step++) {   /* whole numbers, then halves */
          double px[12];
          for (int q = 0; q < n; q++) px[q] = z + (s + q) / (double)step;
          bad += uv_against_single(&m, 0, n, px, py, "by hand");
          runs++;
          const double a = px[0], b = px[n - 1];
          zero_inside += a < z && z < b && n >= 4;
          zero_end += (a == z || b == z) && n >= 4;
          one_sign += (b < z || a > z) && n >= 4;
        }
  }
  print_message("den 0: %ld runs, %ld with it inside, %ld at an end, %ld of one sign; "
                "%ld differ\n", runs, zero_inside, zero_end, one_sign, bad);
  assert_int_equal(bad, 0);
  assert_true(zero_inside > 500 && zero_end > 200 && one_sign > 500);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_uv_runs_are_single),
    cmocka_unit_test(test_uv_den_zero),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
