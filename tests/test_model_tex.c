/*
** test_model_tex.c — cmocka tests of the points engine's lit flat faces (effects/model.c:
** flat_lit_pairs and the textures' tex_pair), against fx_shade point by point, and of a
** smoothed run's space points against the one-point path.
**
** fx_points shades a lit face that is not smoothed two points a pair of lanes and in
** stages (space points, reflectances, the lights light by light, greys), a light blocked
** at both lanes of a pair passed over, a texture's pixel found by floor_pair and the tops
** taken before the truncations. Each point's grey must be fx_shade's, the one-point path.
** tests/data/scene/tex-repeat.s74 has its picture repeated over a face whose first vertex
** is a reflex corner (coordinates below 0 and past 1, whole numbers among them on the
** face), three lights (two of them point lights) and a card casting their shadows, so that
** a pair has a point light blocked at both lanes, at one, or at none; the grids are wide
** enough that a run of a face's points goes through more than one stage's batch.
** Each frame is made twice: with the flat lit rows' SSE2 code (fx_model's flat_sse2) and
** as the processor takes them (eight points an instruction in AVX-512's registers where it
** has them: flat_rowt8, on rows whose t is fixed on faces square to the y or z axis); both
** must give fx_shade's grey at every point.
**
** And the space points fx_points takes for a run of a smoothed face's points (uv_pairs,
** through fx_space_uv): a face's run of two pairs or more is taken without space_point's
** select of t = 1 where the ray's denominator den is 0, where den is > 0 at the run's first
** and last points or < 0 at both (den_not_zero; the proof beside it needs the run's plane
** positions in order). Each point's two coordinates must be the one-point path's
** (fx_space_points with n = 1) bit for bit: on the shipped smoothed scenes' faces along
** every row, and on a face built by hand whose den is exactly 0 at a point of the run, at
** its ends and next to them (there the one-point path's t is 1, a quotient by 0 would give
** infinities). Both ways where the processor has AVX-512F: eight points an instruction
** (model.c, uv_row512) and SSE2's two (the model's uv_sse2); and fx_points' smoothed rows
** both ways, greys byte for byte.
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
#include "effects/see.h"
#include "render/effects.h"
#include "render/points.h"
#include "render/scene.h"

struct tally {
  long points, textured, shadowed, both, one, outside, differ;
  /* on faces whose ray has no x term (one t a row): textured points where the picture's
     row is the row's (solved on x and y or z, its frame's U along x), other textured
     points, untextured points with a light blocked but a point light not; textured points
     elsewhere */
  long row_tex_fixed, row_tex, row_masked, tex_other;
  int greys[256];
};

/* A shipped scene's points frame at a W x H grid and its effects' model, as the points
   engine makes them (the scene read quietly, its own effects). */
struct rig {
  struct scene *sc;
  struct effects e;
  struct vis_grid g;
  struct points p;
  struct fx_engine eng;
  struct fx_stats st;
  struct cost cost;
  struct fx_model m;
};

static void rig_open(struct rig *r, const char *path, int W, int H)
{
  memset(r, 0, sizeof *r);
  struct t74_error err = { 0, "" };
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.quiet = true;
  assert_int_equal(scene_load(path, &so, &r->sc, &err), T74_OK);
  const struct scene *sc = r->sc;
  if (effects_parse(sc->effects ? sc->effects : "", &r->e, "test", 1, &err) != T74_OK)
    fail_msg("%s", err.msg);
  r->g = (struct vis_grid){ W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  assert_int_equal(points_render(&r->p, sc, &r->g, &err), T74_OK);
  assert_int_equal(fx_engine_points(&r->eng, &r->p, &r->g, NULL, &err), T74_OK);
  assert_int_equal(fx_model_build(&r->m, &r->eng, sc, &r->e, NULL, &r->st, &r->cost, &err),
                   T74_OK);
}

static void rig_close(struct rig *r)
{
  fx_model_free(&r->m);
  fx_engine_free(&r->eng);
  points_free(&r->p);
  scene_free(r->sc);
}

/* fx_points against fx_shade on scene path, its own effects, a W x H grid. */
static void frame_is_pointwise(const char *path, int W, int H, struct tally *t)
{
  struct rig r;
  rig_open(&r, path, W, H);
  const struct scene *sc = r.sc;
  struct t74_error err = { 0, "" };
  assert_false(r.m.count);                  /* the points engine: greys in runs */
  const size_t np = (size_t)W * (size_t)H;
  struct fx_frame f;
  memset(&f, 0, sizeof f);
  f.W = W; f.H = H; f.cell = 1;
  assert_non_null(f.face = malloc(np * sizeof *f.face));
  assert_non_null(f.grey = calloc(np, 1));
  memcpy(f.face, r.p.face, np * sizeof *f.face);
  /* the frame with the flat lit rows' SSE2 code (flat_sse2) first, then as the processor
     takes them (AVX-512's flat_rowt8 where it has it): each grey fx_shade's both ways */
  uint8_t *sse2 = malloc(np);
  assert_non_null(sse2);
  r.m.flat_sse2 = true;
  assert_int_equal(fx_points(&r.m, &f, &r.st, &r.cost, &err), T74_OK);
  memcpy(sse2, f.grey, np);
  memcpy(f.face, r.p.face, np * sizeof *f.face);
  memset(f.grey, 0, np);
  r.m.flat_sse2 = false;
  assert_int_equal(fx_points(&r.m, &f, &r.st, &r.cost, &err), T74_OK);
  struct fx_lines *L = NULL;
  int *row = malloc((size_t)W * sizeof *row);
  unsigned *blocked = calloc((size_t)W, sizeof *blocked);
  double *px = malloc((size_t)W * sizeof *px), (*X)[3] = malloc((size_t)W * sizeof *X);
  assert_true(row && blocked && px && X);
  assert_true(fx_model_regions(&r.m));
  assert_int_equal(fx_lines_open(&L, &r.m, false, &r.cost, &err), T74_OK);
  unsigned pm = 0;                          /* the point lights' bits */
  for (int k = 0; k < sc->nlight; k++) if (sc->light[k].point) pm |= 1u << k;
  for (int j = H - 1; j >= 0; j--) {
    assert_int_equal(fx_lines_samples(L, 1, j, 0, W, row, blocked, &err), T74_OK);
    const double py = sc->window[3] - (j + 0.5) * (double)(sc->window[3] - sc->window[1]) / H;
    for (int i = 0; i < W; i++)
      px[i] = sc->window[0] + (i + 0.5) * (double)(sc->window[2] - sc->window[0]) / W;
    for (int i = 0; i < W; i++) {
      const size_t at = (size_t)j * (size_t)W + (size_t)i;
      assert_int_equal(f.face[at], row[i]);
      const int face = row[i];
      const int gs = fx_shade(&r.m, face, blocked[i], i + 0.5, j + 0.5, i, j, NULL, NULL);
      if ((gs != f.grey[at] || gs != sse2[at]) && t->differ++ < 4)
        print_message("%s %dx%d point (%d, %d) face %d blocked %u: frame %d (SSE2 %d), "
                      "fx_shade %d\n", path, W, H, i, j, face, blocked[i], f.grey[at],
                      sse2[at], gs);
      t->points++;
      t->greys[f.grey[at]] = 1;
      if (face < 0) continue;
      const struct scene_face *sf = &sc->f[r.m.map->f[face].sface];
      const bool rowt = r.m.ray[face][0] == 0;
      if (!sf->texture) {
        t->row_masked += rowt && blocked[i] != 0 && (blocked[i] & pm) != pm && sf->grey < 0;
        continue;
      }
      if (rowt) {
        const struct scene_vertex *a = &sc->v[sf->vidx[0]], *b = &sc->v[sf->vidx[1]];
        const bool on_z = r.m.map->f[face].plane[1] == 0;   /* solved on x and y */
        if (on_z && b->y == a->y) t->row_tex_fixed++;
        else t->row_tex++;
      } else {
        t->tex_other++;
      }
      t->textured++;
      t->shadowed += blocked[i] != 0;
      /* a neighbour in the same pair of lanes, or not: both ways with a point light
         blocked at the two or at one */
      if (i + 1 < W && row[i + 1] == face) {
        const unsigned both = blocked[i] & blocked[i + 1] & pm, any = (blocked[i] | blocked[i + 1]) & pm;
        t->both += both != 0;
        t->one += any != both;
      }
      /* the picture's coordinates off [0, 1) here: the face's frame solved as
         reflectance does it (effects/model.c), from the point's space point */
      fx_space_points(&r.m, face, 1, &px[i], py, &X[i]);
      const struct scene_vertex *a = &sc->v[sf->vidx[0]], *b = &sc->v[sf->vidx[1]];
      const struct scene_vertex *c = &sc->v[sf->vidx[sf->ring_start[1] - 1]];
      const double U[2] = { b->x - a->x, b->y - a->y }, T[2] = { c->x - a->x, c->y - a->y };
      const double du = X[i][0] - a->x, dv = X[i][1] - a->y, det = U[0] * T[1] - U[1] * T[0];
      const double ua = (du * T[1] - dv * T[0]) / det, ub = (U[0] * dv - U[1] * du) / det;
      t->outside += ua < 0 || ua >= 1 || ub < 0 || ub >= 1;
    }
  }
  fx_lines_close(L);
  free(row); free(blocked); free(px); free(X);
  free(f.face); free(f.grey); free(sse2);
  rig_close(&r);
}

static void test_tex_repeat_pointwise(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  static const int grids[][2] = { { 100, 75 }, { 400, 300 }, { 333, 217 } };
  for (size_t k = 0; k < sizeof grids / sizeof grids[0]; k++)
    frame_is_pointwise("tests/data/scene/tex-repeat.s74", grids[k][0], grids[k][1], &t);
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += t.greys[g];
  print_message("tex-repeat: %ld points, %ld textured (%ld in shadow, %ld off the picture's "
                "frame), pairs of neighbours with a point light blocked at both %ld, at one "
                "%ld; %d greys, %ld differ\n", t.points, t.textured, t.shadowed, t.outside,
                t.both, t.one, distinct, t.differ);
  assert_int_equal(t.differ, 0);
  assert_true(t.textured > 10000 && t.shadowed > 1000 && t.outside > 5000);
  assert_true(t.both > 500 && t.one > 20 && distinct > 40);
}

/* Faces square to an axis (tests/data/scene/tex-axis.s74, and tex-axis-sun.s74: the same
   faces without point lights): a row's one t, the picture's row made once where its
   frame's U is along x, the pixels in the first point light's loop or after the lights,
   the point lights' terms from the row's y and z, in shadow and out of it: fx_points'
   greys against fx_shade's at every point. */
static void test_tex_axis_pointwise(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  static const int grids[][2] = { { 100, 75 }, { 400, 300 }, { 333, 217 } };
  for (size_t k = 0; k < sizeof grids / sizeof grids[0]; k++) {
    frame_is_pointwise("tests/data/scene/tex-axis.s74", grids[k][0], grids[k][1], &t);
    frame_is_pointwise("tests/data/scene/tex-axis-sun.s74", grids[k][0], grids[k][1], &t);
  }
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += t.greys[g];
  print_message("tex-axis: %ld points, %ld textured (%ld in shadow, %ld off the picture's "
                "frame); one t a row: %ld with the picture's row fixed, %ld other textured, "
                "%ld untextured with a point light lit and a light blocked; %ld textured "
                "elsewhere; %d greys, %ld differ\n", t.points, t.textured, t.shadowed,
                t.outside, t.row_tex_fixed, t.row_tex, t.row_masked, t.tex_other, distinct,
                t.differ);
  assert_int_equal(t.differ, 0);
  assert_true(t.row_tex_fixed > 20000 && t.row_tex > 5000 && t.row_masked > 400);
  assert_true(t.tex_other > 1000 && t.shadowed > 1000 && t.outside > 5000 && distinct > 40);
}

/* scenes/fig6-room.s74: a textured wall and a floor in a table's shadow under a parallel
   and a point light, every point of a lit face's run past the first blocked one shaded in
   stages whose greys go four pairs a store (greys_quad), with clamped greys (255) among
   them: fx_points' greys against fx_shade's at every point. */
static void test_fig6_room_pointwise(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  static const int grids[][2] = { { 320, 240 }, { 333, 217 }, { 101, 77 } };
  for (size_t k = 0; k < sizeof grids / sizeof grids[0]; k++)
    frame_is_pointwise("scenes/fig6-room.s74", grids[k][0], grids[k][1], &t);
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += t.greys[g];
  print_message("fig6-room: %ld points, %ld textured (%ld in shadow), %ld untextured with a "
                "point light lit and a light blocked; %d greys (255: %d), %ld differ\n",
                t.points, t.textured, t.shadowed, t.row_masked, distinct, t.greys[255],
                t.differ);
  assert_int_equal(t.differ, 0);
  assert_true(t.textured > 10000 && t.row_masked > 1000 && distinct > 40 && t.greys[255]);
}

/* fx_space_uv over px[0 .. n) of face f, each of the three axis pairs, both ways (eight
   points an instruction where the processor has AVX-512F, and SSE2's two: uv_sse2),
   against the one-point path; returns the points that differ (the first few printed). */
static long uv_against_single(const struct fx_model *m, int f, int n, const double *px,
                              double py, const char *what)
{
  double xu[512], xw[512];
  long bad = 0;
  assert_true(n % 2 == 0 && n <= 512);
  struct fx_model *mw = (struct fx_model *)m;   /* (its uv_sse2 set for each way, then reset) */
  for (int way = 0; way < 2; way++)
  for (int u = 0; u < 3; u++) {
    mw->uv_sse2 = way == 1;
    fx_space_uv(m, f, n, px, py, u, xu, xw);
    mw->uv_sse2 = false;
    for (int p = 0; p < n; p++) {
      double one[1][3];
      fx_space_points(m, f, 1, px + p, py, one);
      if (!memcmp(&xu[p], &one[0][u], sizeof xu[p]) &&
          !memcmp(&xw[p], &one[0][(u + 1) % 3], sizeof xw[p]))
        continue;
      if (bad++ < 4)
        print_message("%s face %d py %.17g px %.17g axis %d (%s): %.17g %.17g, alone %.17g "
                      "%.17g\n", what, f, py, px[p], u, way ? "SSE2" : "AVX-512 where there",
                      xu[p], xw[p], one[0][u], one[0][(u + 1) % 3]);
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
      const int W = grids[gi][0], H = grids[gi][1];
      struct rig r;
      rig_open(&r, path, W, H);
      const struct scene *sc = r.sc;
      const struct fx_model *m = &r.m;
      double px[512];
      assert_true(W <= 512);
      for (int i = 0; i < W; i++)             /* plane_x's: non-decreasing */
        px[i] = sc->window[0] + (i + 0.5) * (double)(sc->window[2] - sc->window[0]) / W;
      for (int j = 0; j < H; j++) {
        const double py = sc->window[3] - (j + 0.5) * (double)(sc->window[3] - sc->window[1]) / H;
        const int *row = r.p.face + (size_t)j * (size_t)W;
        for (int i = 0; i < W;) {             /* the row's runs of one face */
          int e2 = i + 1;
          while (e2 < W && row[e2] == row[i]) e2++;
          const int n = (e2 - i) & ~1;
          if (row[i] >= 0 && n) {
            bad += uv_against_single(m, row[i], n, px + i, py, names[k]);
            runs++;
            long_runs += n >= 4;
          }
          i = e2;
        }
        for (int f = 0; f < m->map->nface; f++, rows++)
          bad += uv_against_single(m, f, W & ~1, px, py, names[k]);
      }
      rig_close(&r);
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

/* fx_points' smoothed rows both ways: their space points eight an instruction where the
   processor has AVX-512F (uv_row512: each face's run from its first point, a step's lanes
   past the run's end masked off) and SSE2's two (uv_sse2: a face's odd last point with the
   next face's first under smooth=phong, the odd points left over paired under the partial
   smoothing). The same greys, byte for byte, on the smoothed shipped scenes (smooth=phong,
   prop: and fixed:, with their contours) on grids whose rows hold stretches of many
   faces, short runs and long ones; and the same as fx_shade's at every point (t1-g, the
   sphere and t1-e on one grid). */
static void test_uv_rows_both_ways(void **state)
{
  (void)state;
  static const char *const names[] = { "t1-g", "sphere", "t1-e", "t1-j", "t1-a", "lprism" };
  static const int grids[][2] = { { 133, 100 }, { 200, 150 }, { 97, 61 }, { 311, 203 } };
  long points = 0, smoothed = 0, differ = 0, pointwise = 0;
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
    for (size_t gi = 0; gi < sizeof grids / sizeof grids[0]; gi++) {
      char path[64];
      snprintf(path, sizeof path, "scenes/%s.s74", names[k]);
      const int W = grids[gi][0], H = grids[gi][1];
      struct rig r;
      rig_open(&r, path, W, H);
      struct t74_error err = { 0, "" };
      const size_t np = (size_t)W * (size_t)H;
      uint8_t *grey[2];
      int *faces[2];
      for (int way = 0; way < 2; way++) {
        struct fx_frame f;
        memset(&f, 0, sizeof f);
        f.W = W; f.H = H; f.cell = 1;
        assert_non_null(f.face = malloc(np * sizeof *f.face));
        assert_non_null(f.grey = calloc(np, 1));
        memcpy(f.face, r.p.face, np * sizeof *f.face);
        r.m.uv_sse2 = way == 1;
        assert_int_equal(fx_points(&r.m, &f, &r.st, &r.cost, &err), T74_OK);
        r.m.uv_sse2 = false;
        grey[way] = f.grey;
        faces[way] = f.face;
      }
      for (size_t at = 0; at < np; at++) {
        const int face = faces[0][at];
        assert_int_equal(face, faces[1][at]);
        points++;
        smoothed += face >= 0 && r.m.sm.tri_of_mface[face] >= 0;
        if (grey[0][at] != grey[1][at] && differ++ < 4)
          print_message("%s %dx%d point %zu face %d: %d eight a step, %d two\n", path, W, H,
                        at, face, grey[0][at], grey[1][at]);
      }
      for (int way = 0; way < 2; way++) { free(grey[way]); free(faces[way]); }
      rig_close(&r);
    }
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
    if (k >= 3) continue;                   /* (phong and prop: with contours, t1-g, the sphere, t1-e) */
    struct tally t;
    memset(&t, 0, sizeof t);
    char path[64];
    snprintf(path, sizeof path, "scenes/%s.s74", names[k]);
    frame_is_pointwise(path, 97, 61, &t);
    pointwise += t.differ;
  }
  print_message("smoothed rows: %ld points (%ld smoothed), %ld differ between the ways, %ld "
                "from fx_shade (AVX-512F here: %s)\n", points, smoothed, differ, pointwise,
                __builtin_cpu_supports("avx512f") ? "yes" : "no");
  assert_int_equal(differ, 0);
  assert_int_equal(pointwise, 0);
  assert_true(smoothed > 100000);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_tex_repeat_pointwise),
    cmocka_unit_test(test_tex_axis_pointwise),
    cmocka_unit_test(test_fig6_room_pointwise),
    cmocka_unit_test(test_uv_runs_are_single),
    cmocka_unit_test(test_uv_den_zero),
    cmocka_unit_test(test_uv_rows_both_ways),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
