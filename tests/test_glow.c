/*
** test_glow.c — `render FILE.tek -o FILE.png --look glow` shows the stored dots once the
** stream's erase is over (issue 20: the README's gnuplot example wrote a solid green face).
**
** This file contains code to check that a Tek stream beginning with ESC FF (as gnuplot's
** tek40xx terminal and `tube74 tek` write it) is drawn by the look after the erase flash
** has died, as a viewer saw it:
**   - a small hand-made stream (ESC FF, isolated points in point plot, one vector): the
**     picture at scale 1 is not uniform, and the pixels brighter than halfway between the
**     bare face and a lone stored dot are exactly the dots of `--dump tube`;
**   - total_1974_seconds counts the erase (0.45 s, the look's erase_s) and tube_seconds
**     does not (the beam is idle while the tube erases);
**   - `--look-at` inside the erase still shows the flash: the whole face lit evenly;
**   - a scene through `tube74 tek` and back: every stored dot lit on the glow picture and
**     every pixel two dots or more from any stored dot at the bare face's level;
**   - the README's example as written (gnuplot `plot sin(x)`), when gnuplot is installed:
**     the same two checks.
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <png.h>

#include "tests/ref/testkit.h"

#define W 400
#define H 300

static char scratch[64];

static void path(char *out, size_t cap, const char *name)
{
  snprintf(out, cap, "%s/%s", scratch, name);
}

/* The green channel of an RGB PNG of W x H, row 0 at the top; NULL if unreadable. */
static uint8_t *read_green(const char *p)
{
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, p)) return NULL;
  img.format = PNG_FORMAT_RGB;
  uint8_t *rgb = malloc(PNG_IMAGE_SIZE(img));
  if (!rgb || !png_image_finish_read(&img, NULL, rgb, 0, NULL)) { free(rgb); return NULL; }
  assert_int_equal(img.width, W);
  assert_int_equal(img.height, H);
  uint8_t *g = malloc((size_t)W * H);
  assert_non_null(g);
  for (size_t k = 0; k < (size_t)W * H; k++) g[k] = rgb[3 * k + 1];
  free(rgb);
  return g;
}

/* --dump tube's PBM as lit[y][x] with y counted from the top (as the PNG's rows). */
static uint8_t *read_pbm(const char *p)
{
  size_t n;
  char *b = tk_slurp(p, &n);
  assert_non_null(b);
  int w, h, off = 0;
  assert_int_equal(sscanf(b, "P4 %d %d%n", &w, &h, &off), 2);
  assert_int_equal(w, W);
  assert_int_equal(h, H);
  off++;                                     /* the one blank after the height */
  assert_true((size_t)off + (size_t)H * (W / 8) <= n);
  uint8_t *lit = malloc((size_t)W * H);
  assert_non_null(lit);
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++)
      lit[(size_t)y * W + (size_t)x] =
        ((unsigned char)b[(size_t)off + (size_t)y * (W / 8) + (size_t)(x / 8)] >> (7 - x % 8)) & 1;
  free(b);
  return lit;
}

static double stat_field(const char *json, const char *key)
{
  double v;
  assert_int_equal(tk_stat(json, key, &v), 0);
  return v;
}

/* A 10-bit Tek address: HiY LoY HiX LoX. */
static size_t addr(uint8_t *b, int x, int y)
{
  b[0] = (uint8_t)(0x20 | (y >> 5));
  b[1] = (uint8_t)(0x60 | (y & 31));
  b[2] = (uint8_t)(0x20 | (x >> 5));
  b[3] = (uint8_t)(0x40 | (x & 31));
  return 4;
}

/* The small stream: erase, 24 points 40 address units (about 16 dots) apart, a vector. */
static void small_stream(const char *p)
{
  uint8_t b[512];
  size_t n = 0;
  b[n++] = 0x1b;                              /* ESC FF: erase */
  b[n++] = 0x0c;
  b[n++] = 0x1c;                              /* FS: point plot */
  for (int k = 0; k < 24; k++) n += addr(b + n, 100 + 40 * (k % 6), 150 + 60 * (k / 6));
  b[n++] = 0x1d;                              /* GS: a dark move, then a drawn vector */
  n += addr(b + n, 120, 100);
  n += addr(b + n, 700, 100);
  b[n++] = 0x1f;                              /* US: back to alpha */
  assert_int_equal(tk_put(p, b, n), 0);
}

/* Every stored dot lit on the picture, and every pixel 2 dots or more away from all of
** them at the bare face's level (the glow alone). Returns the number of stored dots. */
static int dots_and_bare_face(const uint8_t *g, const uint8_t *lit)
{
  int dots = 0, lo = 255, hi = 0, bare = -1;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      int v = g[(size_t)y * W + (size_t)x];
      if (v < lo) lo = v;
      if (v > hi) hi = v;
      int near = 0;
      for (int dy = -1; dy <= 1 && !near; dy++)
        for (int dx = -1; dx <= 1 && !near; dx++) {
          int xx = x + dx, yy = y + dy;
          near = xx >= 0 && xx < W && yy >= 0 && yy < H && lit[(size_t)yy * W + (size_t)xx];
        }
      if (lit[(size_t)y * W + (size_t)x]) dots++;
      if (near) continue;
      if (bare < 0) bare = v;
      if (abs(v - bare) > 1) fprintf(stderr, "pixel (%d, %d) %d, the bare face %d\n", x, y, v, bare);
      assert_true(abs(v - bare) <= 1);
    }
  assert_true(hi - lo > 60);                  /* not uniform */
  assert_true(bare >= 0 && bare < 40);        /* a dark face: the glow, no erase flash */
  for (size_t k = 0; k < (size_t)W * H; k++)
    if (lit[k]) assert_true(g[k] > bare + 60);
  return dots;
}

static void test_small_stream_after_erase(void **state)
{
  (void)state;
  char tek[128], png[128], pbm[128], js[128], dump[140];
  path(tek, sizeof tek, "small.tek");
  path(png, sizeof png, "small.png");
  path(pbm, sizeof pbm, "small.pbm");
  path(js, sizeof js, "small.json");
  snprintf(dump, sizeof dump, "tube=%s", pbm);
  small_stream(tek);
  assert_int_equal(tk_runl(NULL, NULL, "render", tek, "-o", png, "--look", "glow",
                           "--dump", dump, "--stats", js, (char *)NULL), 0);
  uint8_t *g = read_green(png), *lit = read_pbm(pbm);
  assert_non_null(g);
  int dots = 0, lo = 255, hi = 0;
  for (size_t k = 0; k < (size_t)W * H; k++) {
    dots += lit[k];
    if (g[k] < lo) lo = g[k];
    if (g[k] > hi) hi = g[k];
  }
  assert_true(dots > 24 + 100);               /* the points and the vector's dots */
  assert_true(hi - lo > 60);                  /* not a uniform face */
  int thr = (lo + hi) / 2, mismatch = 0;
  for (size_t k = 0; k < (size_t)W * H; k++)
    if ((g[k] > thr) != (lit[k] != 0)) mismatch++;
  assert_int_equal(mismatch, 0);
  /* the erase is part of the 1974 time, not of the beam's */
  double total = stat_field(js, "total_1974_seconds"), beam = stat_field(js, "tube_seconds");
  assert_true(total >= 0.45 + beam - 1e-6);
  assert_true(beam < 0.1);
  free(g);
  free(lit);
}

static void test_flash_inside_the_erase(void **state)
{
  (void)state;
  char tek[128], png[128], js[128];
  path(tek, sizeof tek, "small.tek");
  path(png, sizeof png, "flash.png");
  path(js, sizeof js, "flash.json");
  small_stream(tek);
  assert_int_equal(tk_runl(NULL, NULL, "render", tek, "--stats", js, (char *)NULL), 0);
  /* 0.2 s after the erase began (at 0): --look-at counts from the picture's completion */
  char at[32];
  snprintf(at, sizeof at, "%.6f", 0.2 - stat_field(js, "total_1974_seconds"));
  assert_int_equal(tk_runl(NULL, NULL, "render", tek, "-o", png, "--look", "glow",
                           "--look-at", at, (char *)NULL), 0);
  uint8_t *g = read_green(png);
  assert_non_null(g);
  int corner = g[0], middle = g[(size_t)150 * W + 200];
  assert_true(corner > 60);                   /* the flash lights the bare corner too */
  assert_true(abs(corner - middle) < 30);
  free(g);
}

static void test_scene_through_tek(void **state)
{
  (void)state;
  char tek[128], png[128], pbm[128], dump[140];
  path(tek, sizeof tek, "fig6.tek");
  path(png, sizeof png, "fig6.png");
  path(pbm, sizeof pbm, "fig6.pbm");
  snprintf(dump, sizeof dump, "tube=%s", pbm);
  assert_int_equal(tk_runl(NULL, NULL, "tek", "scenes/fig6.s74", "-o", tek, (char *)NULL), 0);
  char *b = tk_slurp(tek, NULL);
  assert_non_null(b);
  assert_true(b[0] == 0x1b && b[1] == 0x0c);  /* it begins with an erase */
  free(b);
  assert_int_equal(tk_runl(NULL, NULL, "render", tek, "-o", png, "--look", "glow",
                           "--dump", dump, (char *)NULL), 0);
  uint8_t *g = read_green(png), *lit = read_pbm(pbm);
  assert_non_null(g);
  assert_true(dots_and_bare_face(g, lit) > 1000);
  free(g);
  free(lit);
}

static void test_readme_gnuplot(void **state)
{
  (void)state;
  if (tk_sh(scratch, "command -v gnuplot > /dev/null 2>&1") != 0) { skip(); return; }
  /* README, "tek": exactly as written there */
  assert_int_equal(tk_sh(scratch, "gnuplot -e 'set terminal tek40xx; set output \"plot.tek\"; "
                                  "plot sin(x)'"), 0);
  char exe[512];
  assert_int_equal(tk_exe(exe, sizeof exe), 0);
  assert_int_equal(tk_sh(scratch, "%s render plot.tek -o plot.png --look glow "
                                  "--dump tube=plot.pbm", exe), 0);
  char png[128], pbm[128];
  path(png, sizeof png, "plot.png");
  path(pbm, sizeof pbm, "plot.pbm");
  uint8_t *g = read_green(png), *lit = read_pbm(pbm);
  assert_non_null(g);
  assert_true(dots_and_bare_face(g, lit) > 1000);
  free(g);
  free(lit);
}

int main(void)
{
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74glow.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_small_stream_after_erase),
    cmocka_unit_test(test_flash_inside_the_erase),
    cmocka_unit_test(test_scene_through_tek),
    cmocka_unit_test(test_readme_gnuplot),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
