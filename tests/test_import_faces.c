/*
** test_import_faces.c — .obj faces that the grid cannot take whole are drawn, not refused
** (issue 20, "Everyday use"; render/import.c, file_split).
**
** This file contains code to write three .obj files shaped like well-known test models
** (assimp's test/models/OBJ box_longline.obj, concave_polygon.obj and
** space_in_material_name.obj; these are generated here, none of their bytes is copied) and
** to check that each renders at the default three-quarter view and at many other turns:
**   longline   a unit cube whose first face lists its outline 250 times over on one line
**              of over 2,000 bytes: taken once (with a warning), drawn as the cube;
**   keyhole    a ring in the plane x = -1.146, written as LightWave writes a face with a
**              hole: one outline running round the outside, along a bridge to the hole,
**              round the hole the other way and back along the bridge; it passes the
**              bridge's two points twice, so it is no simple face on any grid: it is cut
**              into triangles in the file's coordinates and drawn as the ring, its hole
**              empty (seen face-on, --turn 90,0: the centre shows no face, the band does);
**   material   the keyhole again with a material name full of blanks (`usemtl  Hard Shiny
**              Plastic White `), `g`, `s 1`, `vn` and `v//vn` references.
** Each: exit 0, points lit, no "finer than the grid" and no error on stderr.
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

#include <cmocka.h>

#include "tests/ref/testkit.h"

#define PI 3.14159265358979323846

static char scratch[64];

static void path(char *out, size_t cap, const char *name)
{
  snprintf(out, cap, "%s/%s", scratch, name);
}

static void write_longline(const char *p)
{
  FILE *f = fopen(p, "w");
  assert_non_null(f);
  fprintf(f, "# a cube whose first face repeats its outline\no 1\n");
  static const char *const v[8] = { "-0.5 -0.5 0.5", "-0.5 -0.5 -0.5", "-0.5 0.5 -0.5",
                                    "-0.5 0.5 0.5", "0.5 -0.5 0.5", "0.5 -0.5 -0.5",
                                    "0.5 0.5 -0.5", "0.5 0.5 0.5" };
  for (int k = 0; k < 8; k++) fprintf(f, "v %s\n", v[k]);
  fprintf(f, "usemtl Default\nf");
  for (int k = 0; k < 250; k++) fprintf(f, " 1 2 3 4");
  fprintf(f, "\nf 2 6 5 1\nf 3 7 6 2\nf 8 7 3 4\nf 5 8 4 1\nf 6 7 8 5\n");
  assert_int_equal(fclose(f), 0);
}

/* A ring (outer radius 0.74, inner 0.69, 32 points each) about (y, z) = (2.4, 2.348) in the
   plane x = -1.146, as one keyhole outline: outer 0..31 counter-clockwise from the bridge
   point, back to it, across to inner 0, inner clockwise, back to inner 0, across again. */
static void write_keyhole(const char *p, const char *material)
{
  FILE *f = fopen(p, "w");
  assert_non_null(f);
  fprintf(f, "# a face with a hole, written as one outline with a bridge\n"
             "o keyhole\nmtllib keyhole.mtl\ng default\n");
  for (int r = 0; r < 2; r++)
    for (int k = 0; k < 32; k++) {
      double a = 2 * PI * k / 32, rad = r == 0 ? 0.74 : 0.69;
      fprintf(f, "v -1.146 %.5f %.5f\n", 2.4 + rad * cos(a), 2.348 + rad * sin(a));
    }
  fprintf(f, "vn 1 0 -0\nusemtl %s\ns 1\nf", material);
  for (int k = 0; k <= 32; k++) fprintf(f, " %d//1", 1 + k % 32);          /* outer, closed */
  for (int k = 0; k <= 32; k++) fprintf(f, " %d//1", 33 + (32 - k) % 32);  /* inner, other way */
  fprintf(f, "\n");
  assert_int_equal(fclose(f), 0);
}

static long points_lit(const char *json)
{
  double v;
  assert_int_equal(tk_stat(json, "points_lit", &v), 0);
  return (long)v;
}

/* render FILE [--turn T] --stats: exit 0, points lit, nothing but warnings on stderr. */
static long render_ok(const char *file, const char *turn)
{
  char png[128], js[128], err[128];
  path(png, sizeof png, "x.png");
  path(js, sizeof js, "x.json");
  path(err, sizeof err, "x.err");
  int rc = turn ? tk_runl(NULL, err, "render", file, "--turn", turn, "-o", png, "--stats", js,
                          (char *)NULL)
                : tk_runl(NULL, err, "render", file, "-o", png, "--stats", js, (char *)NULL);
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  if (rc != 0) fprintf(stderr, "%s --turn %s: exit %d: %s", file, turn ? turn : "(default)", rc, e);
  assert_int_equal(rc, 0);
  assert_null(strstr(e, "finer than the grid"));
  for (const char *l = e; *l; ) {                 /* every line a warning */
    const char *nl = strchr(l, '\n');
    size_t n = nl ? (size_t)(nl - l) : strlen(l);
    char line[512];
    snprintf(line, sizeof line, "%.*s", (int)(n < 500 ? n : 500), l);
    if (!strstr(line, ": warning: ")) fail_msg("not a warning: %s", line);
    l += n + (nl != NULL);
  }
  free(e);
  return points_lit(js);
}

static void every_turn(const char *file)
{
  assert_true(render_ok(file, NULL) > 0);          /* the default three-quarter view */
  static const char *const turns[] = { "0,0", "30,20", "45,45", "90,0", "120,-30",
                                       "200,-30", "270,10", "315,60", "10,85" };
  long lit = 0;
  for (size_t k = 0; k < sizeof turns / sizeof *turns; k++) lit += render_ok(file, turns[k]);
  assert_true(lit > 0);
}

static void test_longline(void **state)
{
  (void)state;
  char p[128];
  path(p, sizeof p, "box_longline.obj");
  write_longline(p);
  long lit = render_ok(p, NULL);
  assert_true(lit > 1000);                        /* a cube's three faces */
  char err[128];
  path(err, sizeof err, "x.err");
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_non_null(strstr(e, "face 1 traces its outline 250 times; taken once"));
  free(e);
  every_turn(p);
}

/* The ring's hole: the window's centre shows no face, a point of the band face 1. */
static void hole_stays_empty(const char *file)
{
  char ids[128], arg[140];
  path(ids, sizeof ids, "ids.pgm");
  snprintf(arg, sizeof arg, "ids=%s", ids);
  assert_int_equal(tk_runl(NULL, NULL, "render", file, "--turn", "90,0", "--cell", "3", "--dump",
                           arg, (char *)NULL), 0);
  size_t n;
  char *b = tk_slurp(ids, &n);
  assert_non_null(b);
  int w, h, mx, off = 0;
  assert_int_equal(sscanf(b, "P5 %d %d %d%n", &w, &h, &mx, &off), 3);
  off++;
  assert_true((size_t)off + (size_t)w * (size_t)h * 2 <= n);
  const unsigned char *px = (const unsigned char *)b + off;
#define ID(i, j) (px[2 * ((size_t)(j) * (size_t)w + (size_t)(i))] << 8 | \
                  px[2 * ((size_t)(j) * (size_t)w + (size_t)(i)) + 1])
  assert_int_equal(ID(w / 2, h / 2), 0);          /* the hole */
  long band = 0, other = 0;
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      band += ID(i, j) == 1;
      other += ID(i, j) > 1;
    }
#undef ID
  assert_true(band > 100);
  assert_int_equal(other, 0);
  /* the band is thin: far from filling the picture, as the disc would */
  assert_true(band < (long)w * h / 4);
  free(b);
}

static void test_keyhole(void **state)
{
  (void)state;
  char p[128];
  path(p, sizeof p, "concave_polygon.obj");
  write_keyhole(p, "test");
  every_turn(p);
  hole_stays_empty(p);
}

static void test_material_name_with_blanks(void **state)
{
  (void)state;
  char p[128];
  path(p, sizeof p, "space_in_material_name.obj");
  write_keyhole(p, " Hard Shiny Plastic White ");
  every_turn(p);
  hole_stays_empty(p);
}

int main(void)
{
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74faces.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_longline),
    cmocka_unit_test(test_keyhole),
    cmocka_unit_test(test_material_name_with_blanks),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
