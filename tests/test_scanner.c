/*
** test_scanner.c — tests of the drum scanner and disk model (patterns/scanner.h; paper 003
** §2, §4 and appendix).
**
** This file contains code to check each step of the 1974 input path with numbers worked
** out by hand from the appendix's figures:
**   density        a 100 mm print: 587 samples a line (5.87/mm), 555 lines for 75 mm
**                  (7.4/mm); a tall print is scaled to the drum's 250 mm;
**   A-D            0..+10 V onto 0..255 (8 bits: the grey comes back exactly; 4 bits:
**                  the rounding of 15 steps);
**   packing        4 levels a word, first in bits 15..12, every word round trips;
**   levels         4x4's level 16 is stored as 15; 3x3's 0..9 unchanged;
**   disk timing    mean seek + rotational delay + transfer, track-to-track moves, the whole
**                  picture read back row by row for 4x4 (one track) and 3x3 (two tracks);
**   a flat grey    picture gives the expected level at every point;
**   the pipeline   `render` of a scene with a background reports the scanner stage.
** A standalone cmocka program, run from the repository root.
*/
#include <fcntl.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "emu/cost.h"
#include "emu/status.h"
#include "patterns/halftone.h"
#include "patterns/picture.h"
#include "patterns/scanner.h"

#define MS 1e-3

static void defaults(struct cost_params *p)
{
  cost_params_default(p);
}

/* A w x h picture of one grey. */
static struct pic *flat(int w, int h, int g)
{
  uint8_t *px = malloc((size_t)w * (size_t)h);
  assert_non_null(px);
  memset(px, g, (size_t)w * (size_t)h);
  struct pic *p = pic_new(w, h, px);
  free(px);
  assert_non_null(p);
  return p;
}

static void test_density(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  int s, l;
  scan_geometry(&prm, 200, 150, &s, &l);   /* 100 x 75 mm */
  assert_int_equal(s, 587);                /* floor(100 x 5.87) */
  assert_int_equal(l, 555);                /* floor(75 x 7.4) */
  scan_geometry(&prm, 400, 300, &s, &l);   /* the print size, not the pixels, decides */
  assert_int_equal(s, 587);
  assert_int_equal(l, 555);
  scan_geometry(&prm, 100, 400, &s, &l);   /* 100 x 400 mm: scaled to 62.5 x 250 mm */
  assert_int_equal(s, 366);                /* floor(62.5 x 5.87) = floor(366.875) */
  assert_int_equal(l, 1850);               /* 250 x 7.4 */
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(cost_params_set(&prm, "drum_pts_mm=2", &err), T74_OK);
  scan_geometry(&prm, 200, 150, &s, &l);
  assert_int_equal(s, 200);
  /* the report of a whole scan says the same */
  defaults(&prm);
  struct pic *p = flat(200, 150, 128);
  struct scan_image *si;
  assert_int_equal(scan_photo(p, 4, &prm, &si, &err), T74_OK);
  struct scan_stats st;
  scan_report(si, &st);
  assert_int_equal(st.samples, 587);
  assert_int_equal(st.lines, 555);
  assert_true(fabs(st.photo_w_mm - 100) < 1e-9);
  assert_true(fabs(st.photo_h_mm - 75) < 1e-9);
  assert_true(fabs(st.drum_seconds - 555 * 0.75) < 1e-9);   /* one line a revolution */
  scan_free(si);
  /* a conversion time that outlasts a revolution: two revolutions a line */
  assert_int_equal(cost_params_set(&prm, "adc_us=2000", &err), T74_OK);   /* 587 x 2 ms */
  assert_int_equal(scan_photo(p, 4, &prm, &si, &err), T74_OK);
  scan_report(si, &st);
  assert_true(fabs(st.drum_seconds - 555 * 2 * 0.75) < 1e-9);
  scan_free(si);
  pic_free(p);
}

static void test_adc(void **state)
{
  (void)state;
  assert_int_equal(scan_photo_mv(0), 0);
  assert_int_equal(scan_photo_mv(255), 10000);
  assert_int_equal(scan_photo_mv(128), 5020);      /* 128 x 10000 / 255 = 5019.6 */
  assert_int_equal(scan_photo_mv(-5), 0);
  assert_int_equal(scan_photo_mv(300), 10000);
  for (int g = 0; g < 256; g++) {                  /* 8 bits lose nothing */
    int code = scan_adc(scan_photo_mv(g), 8);
    assert_int_equal(code, g);
    assert_int_equal(scan_code_grey(code, 8), g);
  }
  assert_int_equal(scan_adc(-1, 8), 0);
  assert_int_equal(scan_adc(10001, 8), 255);
  assert_int_equal(scan_adc(5000, 4), 8);          /* 7.5 steps, rounded up */
  assert_int_equal(scan_adc(4999, 4), 7);
  assert_int_equal(scan_adc(10000, 4), 15);
  assert_int_equal(scan_code_grey(8, 4), 136);     /* 8 x 255 / 15 */
  assert_int_equal(scan_code_grey(15, 4), 255);
  assert_int_equal(scan_adc(10000, 1), 1);
  assert_int_equal(scan_adc(4999, 1), 0);
}

static void test_pack_unpack(void **state)
{
  (void)state;
  const uint8_t v[4] = { 1, 2, 3, 4 };
  assert_int_equal(scan_pack(v), 0x1234);          /* first sample in bits 15..12 */
  for (unsigned w = 0; w <= 0xFFFF; w++) {
    uint8_t u[4];
    scan_unpack((uint16_t)w, u);
    for (int k = 0; k < 4; k++) assert_true(u[k] <= 15);
    assert_int_equal(scan_pack(u), w);
  }
  const uint8_t big[4] = { 16, 17, 0xFF, 0 };      /* masked to 4 bits */
  assert_int_equal(scan_pack(big), 0x01F0);
}

static void test_levels(void **state)
{
  (void)state;
  assert_int_equal(scan_code_of_level(16), 15);
  assert_int_equal(scan_code_of_level(15), 15);
  assert_int_equal(scan_code_of_level(9), 9);
  assert_int_equal(scan_code_of_level(0), 0);
  assert_int_equal(scan_code_of_level(-3), 0);
  for (int g = 0; g < 256; g++) assert_true(scan_code_of_level(pat_level(3, g)) == pat_level(3, g));
}

static void test_disk_timing(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  struct scan_disk d;
  scan_disk_init(&d, &prm);
  assert_int_equal(d.track_words, 3072);
  assert_int_equal(d.tracks, 203);                 /* floor(10e6 / 49152) */
  double word_ms = 40.0 / 3072;                     /* a track a revolution of 2 x 20 ms */
  /* first access: mean seek + mean rotational delay + 25 words */
  double t = scan_disk_access(&d, 0, 25);
  assert_true(fabs(t - (60 + 20 + 25 * word_ms) * MS) < 1e-12);
  /* the same track again: rotational delay + transfer */
  t = scan_disk_access(&d, 25, 25);
  assert_true(fabs(t - (20 + 25 * word_ms) * MS) < 1e-12);
  /* the next track: track-to-track move */
  t = scan_disk_access(&d, 3072 + 10, 25);
  assert_true(fabs(t - (30 + 20 + 25 * word_ms) * MS) < 1e-12);
  /* far away: a mean seek */
  t = scan_disk_access(&d, 3072 * 100, 1);
  assert_true(fabs(t - (60 + 20 + word_ms) * MS) < 1e-12);
  /* straddling two tracks: 2 words, a move, a new rotational delay, 2 words */
  scan_disk_init(&d, &prm);
  scan_disk_access(&d, 0, 1);
  t = scan_disk_access(&d, 3070, 4);
  assert_true(fabs(t - (20 + 2 * word_ms + 30 + 20 + 2 * word_ms) * MS) < 1e-12);
  assert_int_equal(d.track_moves, 1);
  assert_int_equal(d.accesses, 2);
  assert_int_equal(d.words, 5);
}

/* Read the whole picture back row by row in scan order (bottom row first). */
static void read_all(struct scan_image *si, int W, int H, struct cost *c)
{
  for (int j = H - 1; j >= 0; j--)
    for (int i = 0; i < W; i++) assert_true(scan_level(si, i, j, c) >= 0);
}

static void test_disk_picture(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  struct t74_error err = { T74_OK, "" };
  struct pic *p = flat(200, 150, 200);
  double word_ms = 40.0 / 3072;
  /* 4x4: 100 x 75 points, 25 words a row, 1875 words on one track */
  struct scan_image *si;
  assert_int_equal(scan_photo(p, 4, &prm, &si, &err), T74_OK);
  struct scan_stats st;
  scan_report(si, &st);
  assert_int_equal(st.row_words, 25);
  assert_int_equal(st.words, 1875);
  assert_int_equal(st.tracks, 1);
  double want = (60 + 75 * 20 + 1875 * word_ms) * MS;
  assert_true(fabs(st.input_disk_seconds - want) < 1e-9);   /* written once at input */
  assert_true(fabs(st.scanner_seconds - (st.drum_seconds + (20 + 25 * word_ms) * MS)) < 1e-9);
  struct cost c = { { 0 } };
  read_all(si, 100, 75, &c);
  scan_report(si, &st);
  assert_int_equal(st.disk_reads, 75);             /* one read a row */
  assert_true(fabs(st.disk_seconds - want) < 1e-9);
  assert_int_equal(c.n[COST_IO], 1875);            /* each word moved once */
  assert_int_equal(c.n[COST_SHIFT], 7500);         /* each point unpacked once */
  read_all(si, 100, 1, NULL);                       /* row 0 again: the buffered row */
  scan_report(si, &st);
  assert_int_equal(st.disk_reads, 75);              /* no new read */
  int l1 = scan_level(si, 0, 1, NULL);
  int l0 = scan_level(si, 0, 0, NULL);
  assert_int_equal(l1, l0);
  scan_report(si, &st);
  assert_int_equal(st.disk_reads, 77);              /* row 1, then row 0 again */
  scan_free(si);
  /* 3x3: 133 x 100 points, 34 words a row, 3400 words on two tracks; row 90 straddles */
  assert_int_equal(scan_photo(p, 3, &prm, &si, &err), T74_OK);
  scan_report(si, &st);
  assert_int_equal(st.row_words, 34);
  assert_int_equal(st.words, 3400);
  assert_int_equal(st.tracks, 2);
  read_all(si, 133, 100, NULL);
  scan_report(si, &st);
  want = (60 + 100 * 20 + 30 + 20 + 3400 * word_ms) * MS;
  assert_true(fabs(st.disk_seconds - want) < 1e-9);
  scan_free(si);
  pic_free(p);
}

/* scan_row gives every point of a row what scan_level and scan_grey give it, and the
   level its grey's level is stored as, on a picture
   of varied greys, both cells, every row, out of the display's order (rows again, the
   buffered row); and it reads nothing from the disk (the points engine has no 1974 time):
   no read, no disk time. */
static void test_row(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  struct t74_error err = { T74_OK, "" };
  uint8_t *px = malloc(171 * 113);
  assert_non_null(px);
  for (int k = 0; k < 171 * 113; k++) px[k] = (uint8_t)((k * 37 + k / 171 * 11) % 256);
  struct pic *p = pic_new(171, 113, px);
  free(px);
  assert_non_null(p);
  for (int cell = 3; cell <= 4; cell++) {
    struct scan_image *a, *b;               /* a: looked up point by point */
    assert_int_equal(scan_photo(p, cell, &prm, &a, &err), T74_OK);
    assert_int_equal(scan_photo(p, cell, &prm, &b, &err), T74_OK);
    const int W = pat_grid_w(cell), H = pat_grid_h(cell);
    uint8_t level[TUBE_W], grey[TUBE_W];
    int varied = 0;
    const int rows[] = { 5, 5, 4, H - 1, 3, 3, 0 };   /* then each row, bottom first */
    for (int q = 0; q < 7 + H; q++) {
      int j = q < 7 ? rows[q] : H - 1 - (q - 7);
      memset(level, 200, sizeof level);
      memset(grey, 200, sizeof grey);
      scan_row(b, j, level, grey);
      for (int i = 0; i < W; i++) {
        assert_int_equal(level[i], scan_level(a, i, j, NULL));
        assert_int_equal(grey[i], scan_grey(a, i, j));
        assert_int_equal(level[i], scan_code_of_level(pat_level(cell, grey[i])));
        varied += level[i] != level[0];
      }
      assert_int_equal(level[W], 200);       /* nothing past the row */
    }
    struct scan_stats sb;
    scan_report(b, &sb);
    assert_int_equal(sb.disk_reads, 0);
    assert_true(sb.disk_seconds == 0);
    assert_true(varied > 100);
    scan_free(a);
    scan_free(b);
  }
  pic_free(p);
}

static void test_flat_grey(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  struct t74_error err = { T74_OK, "" };
  const int greys[] = { 0, 37, 100, 128, 200, 252, 253, 255 };
  for (size_t g = 0; g < sizeof greys / sizeof *greys; g++)
    for (int cell = 3; cell <= 4; cell++) {
      struct pic *p = flat(57, 43, greys[g]);      /* odd sizes: footprints share pixels */
      struct scan_image *si;
      assert_int_equal(scan_photo(p, cell, &prm, &si, &err), T74_OK);
      int W = pat_grid_w(cell), H = pat_grid_h(cell);
      int want = scan_code_of_level(pat_level(cell, greys[g]));
      for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) {
          assert_int_equal(scan_grey(si, i, j), greys[g]);
          assert_int_equal(scan_level(si, i, j, NULL), want);
        }
      assert_int_equal(scan_level(si, W, 0, NULL), -1);
      assert_int_equal(scan_grey(si, 0, H), -1);
      scan_free(si);
      pic_free(p);
    }
}

static void test_halves(void **state)
{
  (void)state;
  /* left half black, right half white: away from the edge the levels are exact; at the
     edge the scanner's sample straddling it (aperture blur) mixes the two */
  uint8_t px[40 * 30];
  for (int y = 0; y < 30; y++)
    for (int x = 0; x < 40; x++) px[y * 40 + x] = x < 20 ? 0 : 255;
  struct pic *p = pic_new(40, 30, px);
  struct cost_params prm;
  defaults(&prm);
  struct t74_error err = { T74_OK, "" };
  struct scan_image *si;
  assert_int_equal(scan_photo(p, 4, &prm, &si, &err), T74_OK);
  for (int j = 0; j < 75; j++) {
    assert_int_equal(scan_level(si, 0, j, NULL), 0);
    assert_int_equal(scan_level(si, 48, j, NULL), 0);
    assert_int_equal(scan_level(si, 51, j, NULL), 15);   /* level 16, stored as 15 */
    int e = scan_level(si, 50, j, NULL);
    assert_true(e >= 10 && e <= 15);
    assert_int_equal(scan_level(si, 99, j, NULL), 15);
  }
  scan_free(si);
  pic_free(p);
}

static void test_errors(void **state)
{
  (void)state;
  struct cost_params prm;
  defaults(&prm);
  struct t74_error err = { T74_OK, "" };
  struct pic *p = flat(8, 6, 10);
  struct scan_image *si = NULL;
  assert_int_equal(scan_photo(p, 5, &prm, &si, &err), T74_EINPUT);
  struct t74_error err2 = { T74_OK, "" };
  assert_int_equal(cost_params_set(&prm, "disk_mbit=0.01", &err2), T74_OK);   /* 0 tracks */
  assert_int_equal(scan_photo(p, 4, &prm, &si, &err2), T74_EINPUT);
  assert_non_null(strstr(err2.msg, "1875 disk words"));
  pic_free(p);
}

/* Run $TUBE74 with args; stdout and stderr to /dev/null. The exit status, or -1. */
static int run(const char *const *args)
{
  const char *prog = getenv("TUBE74");
  if (!prog || !*prog) prog = "./tube74";
  const char *argv[16];
  int n = 0;
  argv[n++] = prog;
  for (; *args && n < 15; args++) argv[n++] = *args;
  argv[n] = NULL;
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    int fd = open("/dev/null", O_WRONLY);
    dup2(fd, 1);
    dup2(fd, 2);
    execv(argv[0], (char *const *)argv);
    _exit(127);
  }
  int st;
  if (waitpid(pid, &st, 0) != pid) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void test_pipeline_stats(void **state)
{
  (void)state;
  char dir[] = "/tmp/t74scan.XXXXXX";
  assert_non_null(mkdtemp(dir));
  char stats[64];
  snprintf(stats, sizeof stats, "%s/s.json", dir);
  const char *args[] = { "render", "scenes/street.s74", "--stats", stats, NULL };
  assert_int_equal(run(args), 0);
  FILE *f = fopen(stats, "r");
  assert_non_null(f);
  char buf[8192];
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = 0;
  fclose(f);
  unlink(stats);
  rmdir(dir);
  assert_non_null(strstr(buf, "\"scanner_seconds\": 416.2"));   /* 555 lines x 0.75 s + a write */
  assert_non_null(strstr(buf, "\"disk_seconds\": "));
  assert_non_null(strstr(buf, "\"stages\": [\"scanner\""));
  const char *h = strstr(buf, "\"hitac10_seconds\": ");
  assert_non_null(h);
  assert_true(atof(h + 19) > 1.3);                  /* includes the disk reads */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_density),
    cmocka_unit_test(test_row),
    cmocka_unit_test(test_adc),
    cmocka_unit_test(test_pack_unpack),
    cmocka_unit_test(test_levels),
    cmocka_unit_test(test_disk_timing),
    cmocka_unit_test(test_disk_picture),
    cmocka_unit_test(test_flat_grey),
    cmocka_unit_test(test_halves),
    cmocka_unit_test(test_errors),
    cmocka_unit_test(test_pipeline_stats),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
