/*
** test_model_tex.c — cmocka tests of the points engine's lit flat faces (effects/model.c:
** flat_lit_pairs and the textures' tex_pair), against fx_shade point by point.
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

/* fx_points against fx_shade on scene path, its own effects, a W x H grid. */
static void frame_is_pointwise(const char *path, int W, int H, struct tally *t)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.quiet = true;
  assert_int_equal(scene_load(path, &so, &sc, &err), T74_OK);
  struct effects e;
  if (effects_parse(sc->effects ? sc->effects : "", &e, "test", 1, &err) != T74_OK)
    fail_msg("%s", err.msg);
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
  assert_false(m.count);                    /* the points engine: greys in runs */
  const size_t np = (size_t)W * (size_t)H;
  struct fx_frame f;
  memset(&f, 0, sizeof f);
  f.W = W; f.H = H; f.cell = 1;
  assert_non_null(f.face = malloc(np * sizeof *f.face));
  assert_non_null(f.grey = calloc(np, 1));
  memcpy(f.face, p.face, np * sizeof *f.face);
  assert_int_equal(fx_points(&m, &f, &st, &cost, &err), T74_OK);
  struct fx_lines *L = NULL;
  int *row = malloc((size_t)W * sizeof *row);
  unsigned *blocked = calloc((size_t)W, sizeof *blocked);
  double *px = malloc((size_t)W * sizeof *px), (*X)[3] = malloc((size_t)W * sizeof *X);
  assert_true(row && blocked && px && X);
  assert_true(fx_model_regions(&m));
  assert_int_equal(fx_lines_open(&L, &m, false, &cost, &err), T74_OK);
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
      const int gs = fx_shade(&m, face, blocked[i], i + 0.5, j + 0.5, i, j, NULL, NULL);
      if (gs != f.grey[at] && t->differ++ < 4)
        print_message("%s %dx%d point (%d, %d) face %d blocked %u: frame %d, fx_shade %d\n",
                      path, W, H, i, j, face, blocked[i], f.grey[at], gs);
      t->points++;
      t->greys[f.grey[at]] = 1;
      if (face < 0) continue;
      const struct scene_face *sf = &sc->f[m.map->f[face].sface];
      const bool rowt = m.ray[face][0] == 0;
      if (!sf->texture) {
        t->row_masked += rowt && blocked[i] != 0 && (blocked[i] & pm) != pm && sf->grey < 0;
        continue;
      }
      if (rowt) {
        const struct scene_vertex *a = &sc->v[sf->vidx[0]], *b = &sc->v[sf->vidx[1]];
        const bool on_z = m.map->f[face].plane[1] == 0;   /* solved on x and y */
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
      fx_space_points(&m, face, 1, &px[i], py, &X[i]);
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
  free(f.face); free(f.grey);
  fx_model_free(&m);
  fx_engine_free(&eng);
  points_free(&p);
  scene_free(sc);
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

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_tex_repeat_pointwise),
    cmocka_unit_test(test_tex_axis_pointwise),
    cmocka_unit_test(test_fig6_room_pointwise),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
