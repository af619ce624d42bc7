/*
** test_turn.c — views of imported models (render/turn.h; CONTRACT.md `--turn AZ,EL`).
**
** This file contains code to check that:
**   the turn      moves the eye's bearing to the front: with AZ = 90 the model's +x side
**                 faces the viewer, with EL = 90 its top; AZ = EL = 0 changes nothing; the
**                 centre of the bounding box stays put; lengths are kept;
**   the parser    takes "AZ,EL" and refuses anything else (and the command exits 2);
**   the command   draws a cube .obj as a solid by default (three faces seen in --dump ids)
**                 and as a square with --turn 0,0 (one face); .off the same; the fitted
**                 window follows the turn (for several turns the lit dots stay inside the
**                 tube with a margin and fill a good part of it).
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "render/turn.h"
#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */

/* ---- the turn itself --------------------------------------------------------------- */

static void test_turn_axes(void **state)
{
  (void)state;
  /* a diamond about the origin: +-x, +-y, +-z */
  const double d0[18] = { 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1 };
  double d[18];
  memcpy(d, d0, sizeof d);
  turn_apply(d, 6, 90, 0);                      /* eye round to the right: +x in front */
  assert_true(fabs(d[0]) < 1e-12 && fabs(d[1]) < 1e-12 && fabs(d[2] - 1) < 1e-12);
  assert_true(fabs(d[12] + 1) < 1e-12 && fabs(d[14]) < 1e-12);   /* old front goes left */
  memcpy(d, d0, sizeof d);
  turn_apply(d, 6, 0, 90);                      /* eye up: the top in front */
  assert_true(fabs(d[6]) < 1e-12 && fabs(d[7]) < 1e-12 && fabs(d[8] - 1) < 1e-12);
  memcpy(d, d0, sizeof d);
  turn_apply(d, 6, 0, 0);
  assert_memory_equal(d, d0, sizeof d);         /* no turn: as written */
  /* about the centre, lengths kept */
  double q[6] = { 10, 20, 30, 14, 26, 38 };     /* centre (12, 23, 34), half-diagonal 5.39 */
  turn_apply(q, 2, 37, -52);
  for (int a = 0; a < 3; a++) assert_true(fabs((q[a] + q[3 + a]) / 2 - (a == 0 ? 12 : a == 1 ? 23 : 34)) < 1e-9);
  double l = sqrt(pow(q[3] - q[0], 2) + pow(q[4] - q[1], 2) + pow(q[5] - q[2], 2));
  assert_true(fabs(l - sqrt(16 + 36 + 64)) < 1e-9);
}

static void test_turn_parse(void **state)
{
  (void)state;
  double a = 0, e = 0;
  assert_int_equal(turn_parse("30,20", &a, &e), 0);
  assert_true(a == 30 && e == 20);
  assert_int_equal(turn_parse("-12.5,0.25", &a, &e), 0);
  assert_true(a == -12.5 && e == 0.25);
  const char *bad[] = { "", "30", "30,", ",20", "30;20", "30,20,10", "a,b", "30,20x",
                        "1e9,0", "nan,0", "0,inf" };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
    assert_int_not_equal(turn_parse(bad[k], &a, &e), 0);
}

/* ---- the command ------------------------------------------------------------------- */

static const char cube_obj[] =
  "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
  "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

static const char cube_off[] =
  "OFF\n8 6 0\n-1 -1 -1\n1 -1 -1\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n"
  "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

static void put(const char *name, const char *text)
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  assert_int_equal(tk_put(p, text, strlen(text)), 0);
}

/* Faces seen: distinct non-zero ids in a --dump ids PGM (16-bit, big-endian). */
static int faces_seen(const char *name)
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  FILE *f = fopen(p, "rb");
  assert_non_null(f);
  int w, h, mx;
  assert_int_equal(fscanf(f, "P5 %d %d %d", &w, &h, &mx), 3);
  fgetc(f);
  int seen[65536] = { 0 }, n = 0;
  for (int k = 0; k < w * h; k++) {
    int hi = fgetc(f), lo = fgetc(f);
    assert_true(hi >= 0 && lo >= 0);
    int id = hi << 8 | lo;
    if (id && !seen[id]++) n++;
  }
  fclose(f);
  return n;
}

/* Bounding box of the lit dots of a --dump tube PBM (x0, y0, x1, y1 in dots, row 0 top). */
static void lit_box(const char *name, int box[4])
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  FILE *f = fopen(p, "rb");
  assert_non_null(f);
  int w, h;
  assert_int_equal(fscanf(f, "P4 %d %d", &w, &h), 2);
  fgetc(f);
  box[0] = w; box[1] = h; box[2] = -1; box[3] = -1;
  int rowbytes = (w + 7) / 8;
  for (int y = 0; y < h; y++)
    for (int b = 0; b < rowbytes; b++) {
      int c = fgetc(f);
      assert_true(c >= 0);
      for (int i = 0; i < 8; i++) {
        int x = 8 * b + i;
        if (x >= w || !(c & (0x80 >> i))) continue;
        if (x < box[0]) box[0] = x;
        if (y < box[1]) box[1] = y;
        if (x > box[2]) box[2] = x;
        if (y > box[3]) box[3] = y;
      }
    }
  fclose(f);
}

static void test_cube_solid_by_default(void **state)
{
  (void)state;
  put("cube.obj", cube_obj);
  put("cube.off", cube_off);
  const char *files[] = { "cube.obj", "cube.off" };
  for (int k = 0; k < 2; k++) {
    assert_int_equal(sh("%s render %s --dump ids=a.pgm 2>/dev/null", exe, files[k]), 0);
    assert_int_equal(faces_seen("a.pgm"), 3);            /* front, side and top */
    assert_int_equal(sh("%s render %s --turn 0,0 --dump ids=b.pgm 2>/dev/null", exe, files[k]), 0);
    assert_int_equal(faces_seen("b.pgm"), 1);            /* a square */
    assert_int_equal(sh("%s render %s --turn 30,20 --dump ids=c.pgm 2>/dev/null", exe, files[k]), 0);
    assert_int_equal(sh("cmp -s a.pgm c.pgm"), 0);       /* the default is 30,20 */
  }
  /* the bad option: usage, exit 2, nothing written */
  assert_int_equal(sh("%s render cube.obj --turn 30 -o bad.png 2>/dev/null", exe), 2);
  assert_int_equal(sh("%s render cube.obj --turn x,y -o bad.png 2>/dev/null", exe), 2);
  assert_int_equal(sh("test -e bad.png"), 1);
}

static void test_window_follows_turn(void **state)
{
  (void)state;
  put("cube.obj", cube_obj);
  const char *turns[] = { "0,0", "30,20", "90,0", "45,60", "-130,-35", "200,80" };
  for (size_t k = 0; k < sizeof turns / sizeof *turns; k++) {
    assert_int_equal(sh("%s render cube.obj --turn %s --dump tube=t.pbm 2>/dev/null", exe, turns[k]), 0);
    int b[4];
    lit_box("t.pbm", b);
    /* inside, with a margin: nothing cut off by the window */
    assert_true(b[0] > 2 && b[1] > 2 && b[2] < 397 && b[3] < 297);
    /* and filling it: the larger side at least 60% of the tube's */
    assert_true((b[2] - b[0]) > 240 || (b[3] - b[1]) > 180);
  }
}

int main(void)
{
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74turn.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_turn_axes),
    cmocka_unit_test(test_turn_parse),
    cmocka_unit_test(test_cube_solid_by_default),
    cmocka_unit_test(test_window_follows_turn),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
