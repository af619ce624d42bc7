/*
** test_differential.c — the renderer against the exact reference on a fixed seed set.
**
** This file contains the differential test of issue 7: scenes of the hard configurations
** (tests/ref/hardgen.c: walls with touching windows and piercing faces, pierced coplanar
** faces, faces sharing one vertex, T-junctions, slivers, far and edge-on faces, vertices
** snapped into other planes) and the cross-check's scene families (tests/ref/scenegen.c)
** are rendered through the library exactly as `tube74 render --dump ids` renders them
** (tests/ref/xdiff.c) and every point is judged by tests/ref/exactref.c, which shares no
** code with render/. Required: every scene rendered (none refused), and 0 points wrong
** outside the reference's tolerance band (exactref.h: within XR_BAND grid units of the
** intersection line of the two faces in question). Both cell sizes and both priority
** stores (dense, sparse) are used, alternating by seed.
** T74_DIFF_SEEDS (default 400) sets the seeds per hard family; a failing scene is saved
** as build/tests/diff-fail-FAMILY-SEED.s74 and named.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "tests/ref/exactref.h"
#include "tests/ref/hardgen.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/xdiff.h"

struct tally { long scenes, points, band, wrong, refused, split; };

static void judge(struct xr_scene *s, const char *fam, unsigned long long seed, int cell,
                  int store, struct tally *t)
{
  struct xd_result r;
  assert_int_equal(xd_check(s, cell, store, &r), 0);
  t->scenes++;
  t->points += r.points;
  t->band += r.band;
  t->wrong += r.wrong;
  if (r.status) t->refused++;
  t->split += r.faces_split;
  if (r.status || r.wrong) {
    char path[256];
    snprintf(path, sizeof path, "build/tests/diff-fail-%s-%llu.s74", fam, seed);
    xd_save(s, path);
    if (r.status)
      print_message("%s seed %llu cell %d: refused: %s (scene kept in %s)\n", fam, seed,
                    cell, r.msg, path);
    else
      print_message("%s seed %llu cell %d %s: %ld points wrong, first (%d, %d): got face "
                    "%u, want %u (scene kept in %s)\n", fam, seed, cell,
                    store == 1 ? "dense" : "sparse", r.wrong, r.first_i, r.first_j,
                    r.first_got, r.first_want, path);
  }
}

static void report(const char *what, const struct tally *t)
{
  print_message("%s: %ld scenes, %ld points checked, %ld in the tolerance band, %ld wrong, "
                "%ld refused; %ld faces folded by rounding, rendered as triangles\n", what, t->scenes,
                t->points, t->band, t->wrong, t->refused, t->split);
}

static void test_hard(void **state)
{
  (void)state;
  struct tally t = { 0, 0, 0, 0, 0, 0 };
  int n = xd_seeds();
  for (int fam = 0; fam < HG_NFAMILIES; fam++) {
    struct tally f = { 0, 0, 0, 0, 0, 0 };
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(hg_generate(fam, (uint64_t)seed, &s), 0);
      judge(&s, hg_family_name(fam), (unsigned long long)seed, seed % 2 ? 3 : 4,
            (seed / 2) % 2 ? 2 : 1, &f);
      xr_scene_free(&s);
    }
    report(hg_family_name(fam), &f);
    t.scenes += f.scenes; t.points += f.points; t.band += f.band;
    t.wrong += f.wrong; t.refused += f.refused; t.split += f.split;
  }
  report("hard configurations", &t);
  assert_int_equal(t.refused, 0);
  assert_int_equal(t.wrong, 0);
  /* the test must have judged something: points of every family, and faces that the
     rounding folded (the far and edge-on families are built to make them) */
  assert_true(t.points > 1000L * HG_NFAMILIES);
  assert_true(t.split > 0);
}

/* the cross-check's families, judged exactly (OSMesa cannot judge ties; this can) */

static void test_scenegen(void **state)
{
  (void)state;
  struct tally t = { 0, 0, 0, 0, 0, 0 };
  int n = xd_seeds() / 8 > 0 ? xd_seeds() / 8 : 1;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(xd_scenegen((sg_family)fam, (uint64_t)seed, &s), 0);
      judge(&s, sg_family_name((sg_family)fam), (unsigned long long)seed, seed % 2 ? 3 : 4,
            (seed / 2) % 2 ? 2 : 1, &t);
      xr_scene_free(&s);
    }
  report("cross-check families", &t);
  assert_int_equal(t.refused, 0);
  assert_int_equal(t.wrong, 0);
  assert_true(t.points > 0);
}

/* the reference itself: a square on z = 0 seen from straight ahead, where the answer at
   every point follows from the tie rule by hand (so the reference can fail) */
static void test_reference_by_hand(void **state)
{
  (void)state;
  struct xr_scene s;
  memset(&s, 0, sizeof s);
  s.eye[2] = -1000;
  s.win[0] = -200; s.win[1] = -150; s.win[2] = 200; s.win[3] = 150;
  /* cell 4: 100 x 75 points, centres x = -198 + 4i, y = 148 - 4j; square -2..10 in x
     and -2..6 in y: its left edge x = -2 passes through centres of column i = 49 */
  int v[4] = { xr_vertex(&s, -2, -2, 0), xr_vertex(&s, 10, -2, 0), xr_vertex(&s, 10, 6, 0),
               xr_vertex(&s, -2, 6, 0) };
  assert_true(xr_face(&s, 7, 4, v) >= 0);
  /* a coplanar window with a larger number, and a face in front of part of it */
  int w[4] = { xr_vertex(&s, -2, -2, 0), xr_vertex(&s, 2, -2, 0), xr_vertex(&s, 2, 2, 0),
               xr_vertex(&s, -2, 2, 0) };
  assert_true(xr_face(&s, 9, 4, w) >= 0);
  struct xr_ref r;
  assert_int_equal(xr_prepare(&s, 4, &r), 0);
  for (int j = 0; j < r.H; j++)
    for (int i = 0; i < r.W; i++) {
      long x = -198 + 4 * i, y = 148 - 4 * j;
      unsigned want = 0;
      if (x >= -2 && x < 10 && y >= -2 && y < 6) want = 7;
      if (x >= -2 && x < 2 && y >= -2 && y < 2) want = 9;
      assert_int_equal(xr_visible(&r, i, j), want);
    }
  /* a wrong answer is judged wrong, the right one right */
  unsigned want;
  assert_int_equal(xr_judge(&r, 49, 37, 9, &want), 0);       /* (-2, 0): window */
  assert_int_equal(want, 9);
  assert_int_equal(xr_judge(&r, 49, 37, 7, &want), -1);
  assert_int_equal(xr_judge(&r, 0, 0, 7, &want), -1);
  xr_ref_free(&r);
  xr_scene_free(&s);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_reference_by_hand),
    cmocka_unit_test(test_hard),
    cmocka_unit_test(test_scenegen),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
