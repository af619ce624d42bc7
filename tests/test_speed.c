/*
** test_speed.c — what the speed work (issue 12) must not change: `render --frames K`
** renders the loaded scene K times and writes the outputs once, the same bytes as one
** frame; --stats gains frame_seconds and frames; a bad K is refused before any output.
**
** This file contains code to run $TUBE74 (default ./tube74) as a user would (system(3))
** on shipped scenes — one with a background photograph (the disk's display-time state must
** come out as after one frame), one with the effects stage, one plain — and compare every
** output byte for byte, and the statistics line by line but for the host times. No timing
** is asserted (speed is a benchmark: `tube74 bench speed`). Also: pic_sample_grid (the
** scanner's fast sampling) gives exactly pic_sample's value at every point, on pictures
** and grids of awkward sizes (larger and smaller than the picture, primes, 1), also at the
** largest sums and sampled twice as the scanner does (pic_sample_twice); and `render`
** reads the scene once (through a FIFO whose later readers get no scene). (What the
** program loads at start-up: tests/test_dynlib.c.) A standalone cmocka program,
** run from the repository root; scratch files go to a fresh folder under /tmp.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "patterns/picture.h"
#include "tests/ref/testkit.h"

static char scratch[64];

static int group_setup(void **state)
{
  (void)state;
  return tk_mkscratch(scratch, sizeof scratch, "/tmp/t74speed.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(scratch);
}

/* Run a shell command from the working folder; its exit status. */
#define run(...) tk_sh(".", __VA_ARGS__)

static void same_file(const char *a, const char *b)
{
  size_t na = 0, nb = 0;
  char *x = tk_slurp(a, &na), *y = tk_slurp(b, &nb);
  assert_non_null(x);
  assert_non_null(y);
  assert_true(na > 0);
  assert_int_equal(na, nb);
  assert_memory_equal(x, y, na);
  free(x);
  free(y);
}

/* The statistics of two runs agree line by line except the host's clock and the frame
   count; returns frame_seconds of b (which must be there, >= 0, <= its host_seconds). */
static double same_stats(const char *a, const char *b, int frames_b)
{
  char *x = tk_slurp(a, NULL), *y = tk_slurp(b, NULL);
  assert_non_null(x);
  assert_non_null(y);
  char *sx = NULL, *sy = NULL;
  char *lx = strtok_r(x, "\n", &sx), *ly = strtok_r(y, "\n", &sy);
  double frame = -1, host = -1;
  int frames = 0, lines = 0;
  while (lx && ly) {
    if (strstr(ly, "\"host_seconds\"")) host = atof(strchr(ly, ':') + 1);
    if (strstr(ly, "\"frame_seconds\"")) frame = atof(strchr(ly, ':') + 1);
    if (strstr(ly, "\"frames\"")) frames = atoi(strchr(ly, ':') + 1);
    if (!strstr(lx, "host_seconds") && !strstr(lx, "frame_seconds") && !strstr(lx, "\"frames\""))
      assert_string_equal(lx, ly);
    lx = strtok_r(NULL, "\n", &sx);
    ly = strtok_r(NULL, "\n", &sy);
    lines++;
  }
  assert_null(lx);
  assert_null(ly);
  assert_true(lines > 10);
  assert_int_equal(frames, frames_b);
  assert_true(frame >= 0);
  assert_true(host >= frame);
  free(x);
  free(y);
  return frame;
}

static void frames_same(const char *scene, const char *extra)
{
  const bool points = strstr(extra, "--engine points") != NULL;   /* no 1974 tables */
  for (int k = 1; k <= 4; k += 3) {
    char tables[300] = "";
    if (!points) snprintf(tables, sizeof tables, "--dump tables=%s/t%d.txt", scratch, k);
    int st = run("%s render %s %s --frames %d -o %s/p%d.png --stats %s/s%d.json "
                 "--dump ids=%s/i%d.pgm --dump grey=%s/g%d.pgm %s "
                 "--dump points=%s/d%d.txt", tk_prog(), scene, extra, k, scratch, k, scratch, k,
                 scratch, k, scratch, k, tables, scratch, k);
    assert_int_equal(st, 0);
  }
  const char *kinds[] = { "p%d.png", "i%d.pgm", "g%d.pgm", "d%d.txt", "t%d.txt" };
  for (size_t q = 0; q < sizeof kinds / sizeof *kinds - points; q++) {
    char a[256], b[256], na[32], nb[32];
    snprintf(na, sizeof na, kinds[q], 1);
    snprintf(nb, sizeof nb, kinds[q], 4);
    snprintf(a, sizeof a, "%s/%s", scratch, na);
    snprintf(b, sizeof b, "%s/%s", scratch, nb);
    same_file(a, b);
  }
  char a[256], b[256];
  snprintf(a, sizeof a, "%s/s1.json", scratch);
  snprintf(b, sizeof b, "%s/s4.json", scratch);
  same_stats(a, b, 4);
}

/* Without --stats (nor a look or a scaled picture) `render` does not time the beam
   (issue 19: nothing would show it): the pictures and dumps must be those of a run that
   does, on a scene with a background photograph, one with the effects stage and a Tek
   stream with an erase, under both engines. */
static void untimed_same(const char *scene, const char *extra)
{
  const char *dump = strstr(scene, ".tek") ? "points" : "ids";   /* a stream has no ids */
  int st = run("%s render %s %s -o %s/u1.png --dump %s=%s/v1.pgm --stats %s/w1.json",
               tk_prog(), scene, extra, scratch, dump, scratch, scratch);
  assert_int_equal(st, 0);
  st = run("%s render %s %s -o %s/u2.png --dump %s=%s/v2.pgm", tk_prog(), scene, extra,
           scratch, dump, scratch);
  assert_int_equal(st, 0);
  char a[256], b[256];
  snprintf(a, sizeof a, "%s/u1.png", scratch);
  snprintf(b, sizeof b, "%s/u2.png", scratch);
  same_file(a, b);
  snprintf(a, sizeof a, "%s/v1.pgm", scratch);
  snprintf(b, sizeof b, "%s/v2.pgm", scratch);
  same_file(a, b);
}

static void test_untimed_same_picture(void **state)
{
  (void)state;
  untimed_same("scenes/street.s74", "");
  untimed_same("scenes/street.s74", "--engine points");
  untimed_same("scenes/fig5.s74", "--effects 'halftone=4x4 edges=on'");
  untimed_same("scenes/sphere.s74", "--engine points");
  untimed_same("tests/fuzz/corpus_tek/erase_mid.tek", "");
  untimed_same("tests/fuzz/corpus_tek/gs_box.tek", "");
}

/* The street has a background photograph: its disk reads and times are those of one frame. */
static void test_frames_background(void **state) { (void)state; frames_same("scenes/street.s74", ""); }

/* The effects stage runs in every frame; its statistics stay one frame's. */
static void test_frames_effects(void **state)
{
  (void)state;
  frames_same("scenes/fig5.s74", "--effects 'halftone=4x4 edges=on'");
}

static void test_frames_plain(void **state) { (void)state; frames_same("scenes/crossing.s74", ""); }

/* A textured scene's pictures are read by the first frame and kept for the later ones
   (effects/model.c, fx_textures): the same picture, dumps and figures, under both engines. */
static void test_frames_textures(void **state)
{
  (void)state;
  frames_same("scenes/fig6-room.s74", "--engine 1974");
  frames_same("scenes/fig6-room.s74", "--engine points");
}

/* ---- the scene is read once (issue 12: one parse) ---- */

/* Wait until no reader has the FIFO open (a writer's non-blocking open fails with ENXIO).
   Each probe opens and closes the write end without writing: a reader at that moment
   waits, then sees the end of the stream as before. */
static void fifo_wait_unread(const char *path)
{
  for (;;) {
    int fd = open(path, O_WRONLY | O_NONBLOCK);
    if (fd < 0) return;
    close(fd);
    struct timespec ms = { 0, 1000000 };
    nanosleep(&ms, NULL);
  }
}

/* A writer for the FIFO `path`: gives `text` to the first reader that opens it and, once
   that reader has closed it, a line that is not a scene (`bogus`) to each later reader,
   so that a second reading of the scene cannot give the first one's picture or message
   (a reader that opens it between two probes of fifo_wait_unread gets an empty stream,
   no scene either). Runs until killed. */
static pid_t fifo_writer(const char *path, const char *text)
{
  pid_t pid = fork();
  if (pid != 0) return pid;
  signal(SIGPIPE, SIG_IGN);
  for (int k = 0;; k++) {
    int fd = open(path, O_WRONLY);          /* waits for a reader */
    if (fd < 0) _exit(1);
    const char *t = k == 0 ? text : "bogus\n";
    size_t n = strlen(t), off = 0;
    while (off < n) {
      ssize_t w = write(fd, t + off, n - off);
      if (w <= 0) break;
      off += (size_t)w;
    }
    close(fd);
    fifo_wait_unread(path);
  }
}

/* Render the scene text given through a FIFO (with extra arguments); the exit status. */
static int render_fifo(const char *text, const char *extra, const char *out)
{
  char fifo[256];
  snprintf(fifo, sizeof fifo, "%s/once.s74", scratch);
  unlink(fifo);
  assert_int_equal(mkfifo(fifo, 0600), 0);
  pid_t w = fifo_writer(fifo, text);
  assert_true(w > 0);
  int st = run("%s render %s %s -o %s 2>%s/once.err", tk_prog(), fifo, extra, out, scratch);
  kill(w, SIGKILL);
  int ws;
  waitpid(w, &ws, 0);
  unlink(fifo);
  return st;
}

/* `render` reads the scene once: from a FIFO whose later readers get a line that is not
   a scene, the picture is that of the same scene read from a file, with the effects from
   --effects or from the scene's own effects line (read from the same parse). A scene that
   fails to load is reported from that one reading too (its FILE:LINE, exit 2, no output). */
static void test_scene_read_once(void **state)
{
  (void)state;
  const char *const scenes[] = { "scenes/fig5.s74", "scenes/street.s74" };
  for (size_t k = 0; k < sizeof scenes / sizeof *scenes; k++) {
    char *text = tk_slurp(scenes[k], NULL);
    assert_non_null(text);
    char a[256], b[256];
    snprintf(a, sizeof a, "%s/once_file.png", scratch);
    snprintf(b, sizeof b, "%s/once_fifo.png", scratch);
    /* the street's background photograph is named relative to the scene: beside the
       FIFO, a copy */
    assert_int_equal(run("cp scenes/harbour.pgm %s/", scratch), 0);
    assert_int_equal(run("%s render %s --effects 'halftone=4x4 edges=on' -o %s", tk_prog(),
                         scenes[k], a), 0);
    assert_int_equal(render_fifo(text, "--effects 'halftone=4x4 edges=on'", b), 0);
    same_file(a, b);
    /* the scene's own effects line, read from that one parse */
    assert_int_equal(run("%s render %s -o %s", tk_prog(), scenes[k], a), 0);
    assert_int_equal(render_fifo(text, "", b), 0);
    same_file(a, b);
    free(text);
  }
  char b[256], e[256];
  snprintf(b, sizeof b, "%s/once_bad.png", scratch);
  assert_int_equal(render_fifo("view 0 0 -100\nview 0 0 -100 7\n", "", b), 2);
  struct stat sb;
  assert_int_not_equal(stat(b, &sb), 0);
  snprintf(e, sizeof e, "%s/once.err", scratch);
  char *msg = tk_slurp(e, NULL);
  assert_non_null(msg);
  assert_non_null(strstr(msg, "once.s74:2: `view` given twice"));
  free(msg);
}

/* A bad K: exit 2 and no output created. */
static void test_frames_refused(void **state)
{
  (void)state;
  const char *bad[] = { "0", "-1", "x", "2.5", "1000001" };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    assert_int_equal(run("%s render scenes/fig6.s74 --frames %s -o %s/bad.png 2>/dev/null", tk_prog(),
                         bad[k], scratch), 2);
    char p[256];
    snprintf(p, sizeof p, "%s/bad.png", scratch);
    struct stat sb;
    assert_int_not_equal(stat(p, &sb), 0);
  }
  assert_int_equal(run("%s render scenes/fig6.s74 --frames 2>/dev/null", tk_prog()), 2);
}

/* A pw x ph picture of noise from *seed (every third pixel white when extremes). */
static struct pic *noise_pic(int pw, int ph, uint32_t *seed, bool extremes)
{
  uint8_t *px = malloc((size_t)pw * (size_t)ph);
  assert_non_null(px);
  for (int k = 0; k < pw * ph; k++) {
    *seed = *seed * 1103515245u + 12345u;
    px[k] = (uint8_t)(extremes && k % 3 == 0 ? 255 : *seed >> 24);
  }
  struct pic *p = pic_new(pw, ph, px);
  assert_non_null(p);
  free(px);
  return p;
}

static void test_sample_grid_exact(void **state)
{
  (void)state;
  static const int pics[][2] = { { 1, 1 }, { 7, 3 }, { 200, 150 }, { 13, 200 }, { 401, 2 } };
  static const int grids[][2] = { { 1, 1 }, { 3, 5 }, { 100, 75 }, { 587, 555 }, { 400, 1 },
                                  { 133, 100 } };
  uint32_t seed = 12345;
  for (size_t a = 0; a < sizeof pics / sizeof *pics; a++) {
    int pw = pics[a][0], ph = pics[a][1];
    struct pic *p = noise_pic(pw, ph, &seed, true);     /* extremes and noise */
    uint8_t spare[4];
    for (size_t b = 0; b < sizeof grids / sizeof *grids; b++) {
      int W = grids[b][0], H = grids[b][1];
      uint8_t *out = malloc((size_t)W * (size_t)H);
      assert_non_null(out);
      assert_int_equal(pic_sample_grid(p, W, H, out), 0);
      for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
          if (out[(size_t)j * (size_t)W + (size_t)i] != pic_sample(p, i, j, W, H))
            fail_msg("%dx%d picture on a %dx%d grid: point (%d, %d) is %d, pic_sample %d", pw, ph,
                     W, H, i, j, out[(size_t)j * (size_t)W + (size_t)i], pic_sample(p, i, j, W, H));
      free(out);
    }
    assert_int_equal(pic_sample_grid(p, 0, 5, spare), -1);
    pic_free(p);
  }
}

/* pic_sample_twice (the scanner's drum grid, mapped, sampled again without being held)
   gives what the two steps give one after the other, the first grid held whole, each
   point by pic_sample (not by the grid code pic_sample_twice shares). */
static void test_sample_twice(void **state)
{
  (void)state;
  static const int pics[][2] = { { 1, 1 }, { 7, 3 }, { 200, 150 }, { 13, 200 } };
  static const int grids[][4] = { { 587, 555, 100, 75 }, { 587, 555, 133, 100 },
                                  { 1, 1, 1, 1 }, { 3, 5, 7, 2 }, { 50, 40, 100, 75 } };
  uint32_t seed = 99;
  uint8_t map[256];
  for (int g = 0; g < 256; g++) {
    seed = seed * 1103515245u + 12345u;
    map[g] = (uint8_t)(seed >> 24);                  /* any map: not monotonic either */
  }
  for (size_t a = 0; a < sizeof pics / sizeof *pics; a++) {
    struct pic *p = noise_pic(pics[a][0], pics[a][1], &seed, false);
    uint8_t spare[4];
    for (size_t b = 0; b < sizeof grids / sizeof *grids; b++) {
      int W1 = grids[b][0], H1 = grids[b][1], W = grids[b][2], H = grids[b][3];
      uint8_t *g1 = malloc((size_t)W1 * (size_t)H1), *want = malloc((size_t)W * (size_t)H);
      uint8_t *got = malloc((size_t)W * (size_t)H);
      assert_true(g1 && want && got);
      for (int j = 0; j < H1; j++)
        for (int i = 0; i < W1; i++) g1[j * W1 + i] = map[pic_sample(p, i, j, W1, H1)];
      struct pic *q = pic_new(W1, H1, g1);
      assert_non_null(q);
      for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++) want[j * W + i] = (uint8_t)pic_sample(q, i, j, W, H);
      assert_int_equal(pic_sample_twice(p, W1, H1, map, W, H, got), 0);
      assert_memory_equal(got, want, (size_t)W * (size_t)H);
      pic_free(q);
      free(g1);
      free(want);
      free(got);
    }
    assert_int_equal(pic_sample_twice(p, 0, 5, map, 3, 3, spare), -1);
    pic_free(p);
  }
}

/* The same at the largest sums: a picture of nearly PIC_MAX_PIXELS, where the sums come
   near 255 x 2^26 (pic_sample_grid takes its quotients without a divide instruction). */
static void test_sample_grid_large(void **state)
{
  (void)state;
  const int pw = 8191, ph = 8191;
  uint8_t *px = malloc((size_t)pw * (size_t)ph);
  assert_non_null(px);
  uint32_t seed = 777;
  for (size_t k = 0; k < (size_t)pw * (size_t)ph; k++) {
    seed = seed * 1103515245u + 12345u;
    px[k] = (uint8_t)(seed >> 31 ? 255 : 254 + (seed >> 30 & 1));   /* near white */
  }
  struct pic *p = pic_new(pw, ph, px);
  assert_non_null(p);
  static const int grids[][2] = { { 1, 1 }, { 2, 3 }, { 5, 4 } };
  for (size_t b = 0; b < sizeof grids / sizeof *grids; b++) {
    int W = grids[b][0], H = grids[b][1];
    uint8_t out[20];
    assert_int_equal(pic_sample_grid(p, W, H, out), 0);
    for (int j = 0; j < H; j++)
      for (int i = 0; i < W; i++)
        assert_int_equal(out[j * W + i], pic_sample(p, i, j, W, H));
  }
  pic_free(p);
  free(px);
}

/* bench speed refuses bad options before measuring anything (exit 2). */
static void test_bench_speed_usage(void **state)
{
  (void)state;
  const char *bad[] = { "--runs 0", "--runs 32", "--runs x", "--bogus", "--boxes-max -1",
                        "--triangles-max 1x", "--out" };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
    assert_int_equal(run("%s bench speed %s --out %s/b 2>/dev/null", tk_prog(), bad[k], scratch), 2);
  assert_int_equal(run("%s bench nosuch 2>/dev/null", tk_prog()), 2);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_sample_grid_exact),
    cmocka_unit_test(test_sample_grid_large),
    cmocka_unit_test(test_sample_twice),
    cmocka_unit_test(test_bench_speed_usage),
    cmocka_unit_test(test_frames_background),
    cmocka_unit_test(test_frames_effects),
    cmocka_unit_test(test_frames_plain),
    cmocka_unit_test(test_frames_textures),
    cmocka_unit_test(test_untimed_same_picture),
    cmocka_unit_test(test_frames_refused),
    cmocka_unit_test(test_scene_read_once),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
