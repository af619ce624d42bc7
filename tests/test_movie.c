/*
** test_movie.c — `tube74 play --movie FILE.gif`: the animated GIF (display/gif.h,
** cli/cmd_play.c).
**
** This file contains code to check, decoding the GIF with giflib's own reader (DGifSlurp),
** that: the file is a looping GIF89a of 400*scale x 300*scale pixels with as many frames
** as play reports; the frames, composed as a viewer composes them (each a rectangle drawn
** over the picture so far), end on a picture whose lit pixels are exactly the dots of
** `--dump tube` of the same run (a pixel is lit when its palette colour is brighter than
** the look's colour halfway between the glow and a stored dot); the picture builds up
** (an early frame has fewer lit pixels than the last); the palette is a ramp of the look's
** green; a name without .gif still gives the PNG sequence; and a GIF that cannot be
** written fails with exit status 4 and leaves no file.
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <gif_lib.h>
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

#include "display/look.h"
#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */

/* The tube dots of a --dump tube PBM: lit[y][x], y up. */
static void read_pbm(const char *name, uint8_t lit[300][400])
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  FILE *f = fopen(p, "rb");
  assert_non_null(f);
  int w, h;
  assert_int_equal(fscanf(f, "P4 %d %d", &w, &h), 2);
  assert_true(w == 400 && h == 300);
  fgetc(f);
  for (int r = 0; r < 300; r++)
    for (int b = 0; b < 50; b++) {
      int c = fgetc(f);
      assert_true(c >= 0);
      for (int i = 0; i < 8; i++) lit[299 - r][8 * b + i] = (c & (0x80 >> i)) != 0;
    }
  fclose(f);
}

/* Frames reported by play ("... N frames ..."). */
static long reported_frames(const char *log)
{
  char p[256], line[512];
  snprintf(p, sizeof p, "%s/%s", scratch, log);
  FILE *f = fopen(p, "r");
  assert_non_null(f);
  long n = -1;
  while (fgets(line, sizeof line, f)) {
    char *q = strstr(line, " frames");
    if (!q) continue;
    while (q > line && q[-1] >= '0' && q[-1] <= '9') q--;
    n = strtol(q, NULL, 10);
  }
  fclose(f);
  return n;
}

static void test_gif_last_frame_is_the_tube(void **state)
{
  (void)state;
  assert_int_equal(sh("%s play scenes/fig5.s74 --movie fig5.gif --scale 1 --look glow "
                      "--dump tube=t.pbm > log.txt 2>/dev/null", exe), 0);
  long frames = reported_frames("log.txt");
  assert_true(frames >= 10);
  char p[256];
  snprintf(p, sizeof p, "%s/fig5.gif", scratch);
  int e = 0;
  GifFileType *g = DGifOpenFileName(p, &e);
  assert_non_null(g);
  assert_int_equal(DGifSlurp(g), GIF_OK);
  assert_int_equal(g->SWidth, 400);
  assert_int_equal(g->SHeight, 300);
  assert_int_equal(g->ImageCount, frames);
  assert_non_null(g->SColorMap);
  assert_int_equal(g->SColorMap->ColorCount, 256);
  /* looping: a NETSCAPE2.0 block before the first frame */
  int loops = 0;
  for (int k = 0; k < g->ImageCount && !loops; k++)
    for (int x = 0; x < g->SavedImages[k].ExtensionBlockCount; x++) {
      ExtensionBlock *b = &g->SavedImages[k].ExtensionBlocks[x];
      if (b->Function == APPLICATION_EXT_FUNC_CODE && b->ByteCount == 11 &&
          !memcmp(b->Bytes, "NETSCAPE2.0", 11)) loops = 1;
    }
  assert_true(loops);
  /* the palette: a ramp of the look's green, darkest first */
  GifColorType *pal = g->SColorMap->Colors;
  for (int k = 1; k < 256; k++) assert_true(pal[k].Green >= pal[k - 1].Green);
  assert_true(pal[255].Green > pal[0].Green);
  /* what a stored dot looks like against the glow */
  struct look_params lp;
  look_params_default(&lp);
  uint8_t mid[4];
  look_colour(&lp, (float)(lp.v[LP_GLOW] + lp.v[LP_STORED] / 2), mid);
  /* compose the frames */
  static uint8_t canvas[300][400];
  memset(canvas, g->SBackGroundColor, sizeof canvas);
  long lit_early = -1;
  for (int k = 0; k < g->ImageCount; k++) {
    SavedImage *s = &g->SavedImages[k];
    GifImageDesc *d = &s->ImageDesc;
    assert_true(d->Left >= 0 && d->Top >= 0 && d->Left + d->Width <= 400 && d->Top + d->Height <= 300);
    for (int y = 0; y < d->Height; y++)
      memcpy(&canvas[d->Top + y][d->Left], s->RasterBits + (size_t)y * d->Width, (size_t)d->Width);
    if (k == g->ImageCount / 4) {
      lit_early = 0;
      for (int y = 0; y < 300; y++)
        for (int x = 0; x < 400; x++) lit_early += pal[canvas[y][x]].Green > mid[1];
    }
  }
  static uint8_t tube[300][400];
  read_pbm("t.pbm", tube);
  long lit = 0, wrong = 0;
  for (int y = 0; y < 300; y++)
    for (int x = 0; x < 400; x++) {
      int on = pal[canvas[299 - y][x]].Green > mid[1];   /* GIF row 0 is the top */
      lit += on;
      wrong += on != tube[y][x];
    }
  assert_int_equal(wrong, 0);
  assert_true(lit > 10000);
  assert_true(lit_early >= 0 && lit_early < lit);       /* it builds up */
  DGifCloseFile(g, &e);
}

static void test_png_sequence_stays(void **state)
{
  (void)state;
  assert_int_equal(sh("mkdir -p seq && %s play scenes/fig5.s74 --movie seq/f --max-frames 3 "
                      "> /dev/null 2>&1", exe), 0);
  assert_int_equal(sh("test -s seq/f-0001.png && test -s seq/f-0003.png && ! test -e seq/f-0004.png"), 0);
  assert_int_equal(sh("! test -e seq/f.gif"), 0);
  /* upper-case extension: still a GIF */
  assert_int_equal(sh("%s play scenes/fig5.s74 --movie UP.GIF --max-frames 2 > /dev/null 2>&1", exe), 0);
  assert_int_equal(sh("head -c 6 UP.GIF | grep -q GIF89a"), 0);
}

static void test_gif_cannot_be_written(void **state)
{
  (void)state;
  assert_int_equal(sh("%s play scenes/fig5.s74 --movie no/such/dir/x.gif > /dev/null 2>&1", exe), 4);
  assert_int_equal(sh("! test -e no"), 0);
}

int main(void)
{
  char cwd[256];
  if (!getcwd(cwd, sizeof cwd)) return 1;
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74movie.XXXXXX") != 0) return 1;
  char link[128];
  snprintf(link, sizeof link, "%s/scenes", scratch);
  char target[300];
  snprintf(target, sizeof target, "%s/scenes", cwd);
  if (symlink(target, link) != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_gif_last_frame_is_the_tube),
    cmocka_unit_test(test_png_sequence_stays),
    cmocka_unit_test(test_gif_cannot_be_written),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
