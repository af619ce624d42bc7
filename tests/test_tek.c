/*
** test_tek.c — tests of the Tektronix 4010/4014 streams (display/tek.h; CONTRACT.md `tek`
** and `render FILE.tek`).
**
** This file contains code to check, code by code, that:
**   the mapping    every tube dot goes to an address on the tube's 4096 x 3072 area and
**                  comes back as the same dot;
**   the encoder    writes the header (ESC FF, ESC `, GS, FS), one point-plot address a dot
**                  with unchanged HiY / Extra / LoY / HiX omitted, and US at the end; leaves
**                  no file on abort;
**   the decoder    GS (dark first vector, then stored lines), FS, RS (pen up / down, the 8
**                  steps), US and CR (alpha text with the stroke font), ESC FF (erase
**                  callback), ESC p..w (write-through: callback, nothing stored), ESC ` (back
**                  to stored), the 4014 Extra byte, omitted bytes, ESC SUB / ESC ENQ (no
**                  warning), garbage and truncated streams (warnings with their offsets), and
**                  every file of tests/fuzz/corpus_tek/ (no crash);
**   the command    `tube74 tek SCENE` stores, read back by `tube74 render FILE.tek`, exactly
**                  the points (and their order) `tube74 render SCENE` stores: on every
**                  shipped scene (every .s74 under scenes/) and on random scenes of triangles and quads
**                  written here; stdout and -o give the same bytes; failures leave no file.
** A standalone cmocka program, run from the repository root; it runs $TUBE74 (default
** ./tube74) with fork/exec. Scratch files go to a fresh folder under /tmp, removed at the end.
*/
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "display/sink.h"
#include "display/tek.h"
#include "display/tube.h"
#include "emu/status.h"
#include "tests/ref/testkit.h"

#define CORPUS "tests/fuzz/corpus_tek"
#define N_RANDOM_SCENES 8

/* ---- scratch folder ---------------------------------------------------------------- */

static char scratch[64];

static const char *in_dir(char *buf, size_t n, const char *name)
{
  snprintf(buf, n, "%s/%s", scratch, name);
  return buf;
}

static int group_setup(void **state)
{
  (void)state;
  strcpy(scratch, "/tmp/t74tek.XXXXXX");
  return mkdtemp(scratch) ? 0 : -1;
}

static int group_teardown(void **state)
{
  (void)state;
  DIR *d = opendir(scratch);
  if (d) {
    struct dirent *e;
    char p[512];
    while ((e = readdir(d)) != NULL) {
      if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
      snprintf(p, sizeof p, "%s/%s", scratch, e->d_name);
      unlink(p);
    }
    closedir(d);
  }
  rmdir(scratch);
  return 0;
}

static uint8_t *slurp(const char *path, size_t *n)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, len = 0;
  uint8_t *b = malloc(cap);
  size_t got;
  while (b && (got = fread(b + len, 1, cap - len, f)) > 0) {
    len += got;
    if (len == cap) { uint8_t *nb = realloc(b, cap *= 2); if (!nb) { free(b); b = NULL; } else b = nb; }
  }
  fclose(f);
  if (b) *n = len;
  return b;
}

static int file_exists(const char *path)
{
  struct stat st;
  return stat(path, &st) == 0;
}

/* ---- decoding helpers -------------------------------------------------------------- */

struct calls {
  int erases;                   /* erase callbacks */
  int wt;                       /* write-through callbacks */
  int wt_x0, wt_y0, wt_x1, wt_y1;   /* the last one */
  struct tube *tube;            /* erased on ESC FF when set */
};

static void cb_erase(void *ctx)
{
  struct calls *c = ctx;
  c->erases++;
  if (c->tube) tube_erase(c->tube);
}

static void cb_wt(void *ctx, int x0, int y0, int x1, int y1)
{
  struct calls *c = ctx;
  c->wt++;
  c->wt_x0 = x0; c->wt_y0 = y0; c->wt_x1 = x1; c->wt_y1 = y1;
}

/* Decode bytes into a fresh tube; the tube is returned (caller frees). */
static struct tube *decode(const uint8_t *b, size_t n, struct tek_report *rep, struct calls *c)
{
  struct tube *t = tube_new();
  assert_non_null(t);
  struct sink s = tube_sink(t);
  memset(rep, 0, sizeof *rep);
  if (c) {
    memset(c, 0, sizeof *c);
    c->tube = t;
    rep->erase = cb_erase;
    rep->write_through = cb_wt;
    rep->ctx = c;
  }
  assert_int_equal(tek_decode(b, n, &s, rep), T74_OK);
  return t;
}

/* Append the 4014 address of (X, Y), all five bytes. */
static size_t put_addr(uint8_t *b, size_t k, int X, int Y)
{
  b[k++] = (uint8_t)(0x20 | ((Y >> 7) & 0x1F));
  b[k++] = (uint8_t)(0x60 | ((Y & 3) << 2) | (X & 3));
  b[k++] = (uint8_t)(0x60 | ((Y >> 2) & 0x1F));
  b[k++] = (uint8_t)(0x20 | ((X >> 7) & 0x1F));
  b[k++] = (uint8_t)(0x40 | ((X >> 2) & 0x1F));
  return k;
}

/* Append the address of the centre of tube dot (x, y). */
static size_t put_dot(uint8_t *b, size_t k, int x, int y)
{
  return put_addr(b, k, tek_addr_of_dot(x), tek_addr_of_dot(y));
}

/* ---- the mapping ------------------------------------------------------------------- */

static void test_mapping_round_trip(void **state)
{
  (void)state;
  for (int x = 0; x < TUBE_W; x++) {
    int X = tek_addr_of_dot(x);
    assert_true(X >= 0 && X < TEK_TUBE_W);
    assert_int_equal(tek_dot_of_addr(X), x);
  }
  for (int y = 0; y < TUBE_H; y++) {
    int Y = tek_addr_of_dot(y);
    assert_true(Y >= 0 && Y < TEK_TUBE_H);
    assert_int_equal(tek_dot_of_addr(Y), y);
  }
  /* every address lands on a dot; the whole 0..4095 row covers 0..399 once each */
  int prev = 0;
  for (int a = 0; a < TEK_ADDR_MAX; a++) {
    int d = tek_dot_of_addr(a);
    assert_true(d == prev || d == prev + 1);
    prev = d;
  }
  assert_int_equal(prev, TUBE_W - 1);
  assert_int_equal(tek_dot_of_addr(TEK_TUBE_H - 1), TUBE_H - 1);
  assert_int_equal(tek_dot_of_addr(TEK_TUBE_H), TUBE_H);    /* above the tube */
  assert_int_equal(tek_dot_of_addr(-1), -1);                  /* floor, not truncation */
}

static void test_sniff(void **state)
{
  (void)state;
  const uint8_t codes[] = { TEK_ESC, TEK_GS, TEK_FS, TEK_RS, TEK_US };
  for (size_t k = 0; k < sizeof codes; k++) assert_true(tek_sniff(&codes[k], 1));
  const uint8_t no[] = { '#', 'v', 0x00, TEK_CR, 0x20, 0x80 };
  for (size_t k = 0; k < sizeof no; k++) assert_false(tek_sniff(&no[k], 1));
  assert_false(tek_sniff(codes, 0));
}

/* ---- encoder ----------------------------------------------------------------------- */

/* Encode dots (x, y pairs) to a file; returns its bytes. */
static uint8_t *encode(const int *xy, int n, size_t *len)
{
  char path[128];
  in_dir(path, sizeof path, "enc.tek");
  struct t74_error err = { T74_OK, "" };
  struct tek_enc *e;
  assert_int_equal(tek_enc_open(&e, path, &err), T74_OK);
  struct sink s = tek_enc_sink(e);
  for (int k = 0; k < n; k++) assert_int_equal(sink_point(&s, xy[2 * k], xy[2 * k + 1]), T74_OK);
  assert_int_equal(sink_end(&s, &err), T74_OK);
  assert_int_equal(tek_enc_points(e), (uint64_t)n);
  size_t bytes = (size_t)tek_enc_bytes(e);
  tek_enc_free(e);
  uint8_t *b = slurp(path, len);
  assert_non_null(b);
  assert_int_equal(*len, bytes);
  unlink(path);
  return b;
}

static void test_encoder_header_trailer(void **state)
{
  (void)state;
  size_t n;
  uint8_t *b = encode(NULL, 0, &n);
  const uint8_t empty[] = { TEK_ESC, TEK_FF, TEK_ESC, 0x60, TEK_GS, TEK_FS, TEK_US };
  assert_int_equal(n, sizeof empty);
  assert_memory_equal(b, empty, sizeof empty);
  free(b);

  int one[] = { 0, 0 };
  b = encode(one, 1, &n);
  /* header, then the whole address of (5, 5): HiY 0x20, Extra 0x60|(1<<2)|1, LoY 0x61,
     HiX 0x20, LoX 0x41, then US */
  const uint8_t want[] = { TEK_ESC, TEK_FF, TEK_ESC, 0x60, TEK_GS, TEK_FS,
                           0x20, 0x65, 0x61, 0x20, 0x41, TEK_US };
  assert_int_equal(tek_addr_of_dot(0), 5);
  assert_int_equal(n, sizeof want);
  assert_memory_equal(b, want, sizeof want);
  free(b);
}

static void test_encoder_omits_unchanged(void **state)
{
  (void)state;
  /* find two dots on one row whose X share Extra bits and HiX: only LoX is sent (dots
     next to each other never do: 10.24 units apart, their low bits differ) */
  int xa = -1, xb = -1;
  for (int x = 0; x + 2 < TUBE_W && xa < 0; x++) {
    int A = tek_addr_of_dot(x), B = tek_addr_of_dot(x + 2);
    if ((A & 3) == (B & 3) && (A >> 7) == (B >> 7)) { xa = x; xb = x + 2; }
  }
  assert_true(xa >= 0);
  int dots[] = { xa, 10, xb, 10 };
  size_t n;
  uint8_t *b = encode(dots, 2, &n);
  assert_int_equal(n, 6 + 5 + 1 + 1);     /* header, full address, LoX alone, US */
  assert_int_equal(b[11], 0x40 | ((tek_addr_of_dot(xb) >> 2) & 0x1F));
  free(b);

  /* X whose HiX changes: LoY must come again before HiX (it tells HiX from HiY) */
  int xc = -1, xd = -1;
  for (int x = 0; x + 8 < TUBE_W && xc < 0; x++)
    for (int k = 2; k <= 8 && xc < 0; k++) {
      int A = tek_addr_of_dot(x), B = tek_addr_of_dot(x + k);
      if ((A & 3) == (B & 3) && (A >> 7) != (B >> 7)) { xc = x; xd = x + k; }
    }
  assert_true(xc >= 0);
  int dots2[] = { xc, 10, xd, 10 };
  b = encode(dots2, 2, &n);
  int Y = tek_addr_of_dot(10), X = tek_addr_of_dot(xd);
  assert_int_equal(n, 6 + 5 + 3 + 1);
  assert_int_equal(b[11], 0x60 | ((Y >> 2) & 0x1F));
  assert_int_equal(b[12], 0x20 | ((X >> 7) & 0x1F));
  assert_int_equal(b[13], 0x40 | ((X >> 2) & 0x1F));
  free(b);

  /* a new row in the same HiY band with the same Extra: LoY and LoX only */
  int ya = -1;
  for (int y = 0; y + 2 < TUBE_H; y++) {
    int A = tek_addr_of_dot(y), B = tek_addr_of_dot(y + 2);
    if ((A & 3) == (B & 3) && (A >> 7) == (B >> 7)) { ya = y; break; }
  }
  assert_true(ya >= 0);
  int dots3[] = { 7, ya, 7, ya + 2 };
  b = encode(dots3, 2, &n);
  assert_int_equal(n, 6 + 5 + 2 + 1);
  free(b);
}

static void test_encoder_extra_byte(void **state)
{
  (void)state;
  /* dots whose address has low bits: the Extra byte carries them, and changes of them
     alone send Extra + LoY + LoX */
  int x = 1, y = 2;                       /* X = 15, Y = 25: low bits 3 and 1 */
  int X = tek_addr_of_dot(x), Y = tek_addr_of_dot(y);
  assert_int_equal(X, 15);
  assert_int_equal(Y, 25);
  int dots[] = { x, y };
  size_t n;
  uint8_t *b = encode(dots, 1, &n);
  assert_int_equal(b[7], 0x60 | ((Y & 3) << 2) | (X & 3));
  free(b);
  /* decode the stream back: the dot is the same */
  b = encode(dots, 1, &n);
  struct tek_report rep;
  struct tube *t = decode(b, n, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(tube_count(t), 1);
  assert_true(tube_lit(t, x, y));
  tube_free(t);
  free(b);
}

static void test_encoder_rejects_and_aborts(void **state)
{
  (void)state;
  char path[128];
  in_dir(path, sizeof path, "abort.tek");
  struct t74_error err = { T74_OK, "" };
  struct tek_enc *e;
  assert_int_equal(tek_enc_open(&e, path, &err), T74_OK);
  struct sink s = tek_enc_sink(e);
  assert_int_equal(sink_point(&s, 3, 3), T74_OK);
  assert_int_equal(sink_point(&s, TUBE_W, 0), T74_EINPUT);
  assert_int_equal(sink_end(&s, &err), T74_EINPUT);
  tek_enc_free(e);
  assert_false(file_exists(path));        /* failed: nothing left behind */

  /* freed without end or abort (the job failed early): no file either */
  assert_int_equal(tek_enc_open(&e, path, &err), T74_OK);
  s = tek_enc_sink(e);
  assert_int_equal(sink_point(&s, 3, 3), T74_OK);
  tek_enc_free(e);
  assert_false(file_exists(path));

  /* a folder that does not exist: T74_EIO */
  struct t74_error err2 = { T74_OK, "" };
  assert_int_equal(tek_enc_open(&e, "/nonexistent-t74/x.tek", &err2), T74_EIO);
}

static uint64_t rng_next(uint64_t *s)
{
  uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

static void test_encoder_decoder_order(void **state)
{
  (void)state;
  /* 3000 distinct dots in a random order come back in that order */
  enum { N = 3000 };
  static int xy[2 * N];
  static uint8_t used[TUBE_W * TUBE_H];
  memset(used, 0, sizeof used);
  uint64_t seed = 74;
  for (int k = 0; k < N;) {
    int x = (int)(rng_next(&seed) % TUBE_W), y = (int)(rng_next(&seed) % TUBE_H);
    if (used[y * TUBE_W + x]) continue;
    used[y * TUBE_W + x] = 1;
    xy[2 * k] = x; xy[2 * k + 1] = y;
    k++;
  }
  size_t n;
  uint8_t *b = encode(xy, N, &n);
  struct tek_report rep;
  struct tube *t = decode(b, n, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.points, N);
  assert_int_equal(tube_count(t), N);
  for (int k = 0; k < N; k++) {
    int x, y;
    assert_int_equal(tube_order(t, k, &x, &y), T74_OK);
    assert_int_equal(x, xy[2 * k]);
    assert_int_equal(y, xy[2 * k + 1]);
  }
  tube_free(t);
  free(b);
}

/* ---- decoder, code by code --------------------------------------------------------- */

static void test_decode_fs_points(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  k = put_dot(b, k, 0, 0);
  k = put_dot(b, k, 399, 299);
  k = put_dot(b, k, 200, 150);
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.points, 3);
  assert_int_equal(tube_count(t), 3);
  int x, y;
  tube_order(t, 1, &x, &y);
  assert_int_equal(x, 399);
  assert_int_equal(y, 299);
  tube_free(t);
}

static void test_decode_gs_vectors(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_GS;
  k = put_dot(b, k, 10, 10);              /* dark move */
  k = put_dot(b, k, 30, 20);              /* stored vector */
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.moves, 1);
  assert_int_equal(rep.vectors, 1);
  assert_int_equal(tube_count(t), 21);    /* max(|dx|, |dy|) + 1 dots */
  assert_true(tube_lit(t, 10, 10));
  assert_true(tube_lit(t, 30, 20));
  assert_true(tube_lit(t, 20, 15));       /* the exact midpoint */
  tube_free(t);

  /* GS again: the next address is a move again, nothing drawn */
  k = 0;
  b[k++] = TEK_GS;
  k = put_dot(b, k, 10, 10);
  b[k++] = TEK_GS;
  k = put_dot(b, k, 50, 50);
  t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.moves, 2);
  assert_int_equal(tube_count(t), 0);
  tube_free(t);
}

static void test_decode_omitted_bytes(void **state)
{
  (void)state;
  /* a full address, then addresses that send only LoX, only LoY + LoX, only HiY + LoX, and
     LoY + HiX + LoX: the registers keep what is not sent (the Extra bits included) */
  int X = 1000 + 3, Y = 600 + 2;          /* low bits 3 and 2 */
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  k = put_addr(b, k, X, Y);
  b[k++] = (uint8_t)(0x40 | (((X + 8) >> 2) & 0x1F));                 /* LoX: X + 8 */
  b[k++] = (uint8_t)(0x60 | (((Y + 12) >> 2) & 0x1F));                /* LoY: Y + 12 */
  b[k++] = (uint8_t)(0x40 | ((X >> 2) & 0x1F));
  b[k++] = (uint8_t)(0x20 | (((Y + 128) >> 7) & 0x1F));               /* HiY: Y + 128 */
  b[k++] = (uint8_t)(0x40 | ((X >> 2) & 0x1F));
  b[k++] = (uint8_t)(0x60 | (((Y + 128) >> 2) & 0x1F));               /* LoY (same) */
  b[k++] = (uint8_t)(0x20 | (((X + 256) >> 7) & 0x1F));               /* HiX: X + 256 */
  b[k++] = (uint8_t)(0x40 | ((X >> 2) & 0x1F));
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(tube_count(t), 5);
  /* the HiY-only address keeps the LoY of the one before: Y + 128 + 12 */
  int want[5][2] = { { X, Y }, { X + 8, Y }, { X, Y + 12 }, { X, Y + 140 }, { X + 256, Y + 128 } };
  for (int p = 0; p < 5; p++) {
    int x, y;
    tube_order(t, p, &x, &y);
    assert_int_equal(x, tek_dot_of_addr(want[p][0]));
    assert_int_equal(y, tek_dot_of_addr(want[p][1]));
  }
  tube_free(t);
}

static void test_decode_extra_byte(void **state)
{
  (void)state;
  /* two addresses that differ only in the Extra byte's bits land on different dots when
     the low bits cross a dot boundary: X 10 -> dot 0, X 11 -> dot 1 (10.24 per dot) */
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  k = put_addr(b, k, 10, 0);
  k = put_addr(b, k, 11, 0);
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(tube_count(t), 2);
  assert_true(tube_lit(t, 0, 0));
  assert_true(tube_lit(t, 1, 0));
  tube_free(t);
  /* without the Extra byte (a 4010 address), the low bits stay as the last Extra left them */
  k = 0;
  b[k++] = TEK_FS;
  k = put_addr(b, k, 11, 0);              /* low X bits 3 */
  b[k++] = 0x20; b[k++] = 0x60; b[k++] = 0x20; b[k++] = 0x42;   /* 4010 address X = 8 (+3) */
  t = decode(b, k, &rep, NULL);
  assert_int_equal(tube_count(t), 1);     /* X = 11 again: the same dot */
  tube_free(t);
}

static void test_decode_rs_incremental(void **state)
{
  (void)state;
  uint8_t b[128];
  size_t k = 0;
  b[k++] = TEK_GS;
  k = put_dot(b, k, 100, 100);            /* move there */
  b[k++] = TEK_RS;
  b[k++] = 'P';                           /* pen down */
  for (int s = 0; s < 40; s++) b[k++] = 'A';   /* 40 steps east: 4 dots' worth */
  b[k++] = ' ';                           /* pen up */
  for (int s = 0; s < 40; s++) b[k++] = 'D';   /* north, not drawn */
  b[k++] = 'P';
  const char *all = "AEDFBJHI";           /* every direction once, pen down */
  for (const char *c = all; *c; c++) b[k++] = (uint8_t)*c;
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.points, 48);
  int X = tek_addr_of_dot(100);
  assert_true(tube_lit(t, tek_dot_of_addr(X + 40), 100));
  assert_false(tube_lit(t, 100, 103));    /* pen up going north */
  assert_true(tube_count(t) >= 4 && tube_count(t) <= 8);
  tube_free(t);
}

static void test_decode_alpha_us_cr(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_GS;
  k = put_dot(b, k, 50, 200);
  b[k++] = TEK_US;                        /* alpha at the beam */
  b[k++] = 'H'; b[k++] = 'i';
  b[k++] = TEK_CR;                        /* margin, still alpha */
  b[k++] = TEK_LF;
  b[k++] = '!';
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.chars, 3);
  assert_true(tube_count(t) > 10);
  /* 'H' at (50, 200): its left stem is there */
  assert_true(tube_lit(t, 50, 200));
  /* '!' at the left margin, a line (88 units, 8.6 dots) lower */
  int any = 0;
  for (int y = 185; y < 200; y++)
    for (int x = 0; x < 4; x++) any |= tube_lit(t, x, y);
  assert_true(any);
  tube_free(t);

  /* CR in graph mode ends it: what follows is text, not an address */
  k = 0;
  b[k++] = TEK_GS;
  b[k++] = TEK_CR;
  b[k++] = 'A'; b[k++] = 'B';
  t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.chars, 2);
  assert_int_equal(rep.vectors + rep.moves, 0);
  tube_free(t);
}

static void test_decode_esc_ff_erase(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  k = put_dot(b, k, 5, 5);
  b[k++] = TEK_ESC; b[k++] = TEK_FF;      /* erase: alpha mode */
  b[k++] = TEK_FS;
  k = put_dot(b, k, 6, 6);
  struct tek_report rep;
  struct calls c;
  struct tube *t = decode(b, k, &rep, &c);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.erases, 1);
  assert_int_equal(c.erases, 1);
  assert_int_equal(tube_count(t), 1);     /* the dot before the erase is gone */
  assert_true(tube_lit(t, 6, 6));
  tube_free(t);
}

static void test_decode_write_through(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_ESC; b[k++] = 'p';         /* write-through */
  b[k++] = TEK_GS;
  k = put_dot(b, k, 10, 10);
  k = put_dot(b, k, 20, 10);              /* a dim vector: not stored */
  b[k++] = TEK_FS;
  k = put_dot(b, k, 30, 30);              /* a dim point */
  b[k++] = TEK_ESC; b[k++] = 'w';         /* still write-through (line style 7) */
  k = put_dot(b, k, 31, 30);
  b[k++] = TEK_ESC; b[k++] = '`';         /* stored again */
  k = put_dot(b, k, 40, 40);
  b[k++] = TEK_ESC; b[k++] = 'h';         /* defocused: stored too */
  k = put_dot(b, k, 41, 40);
  struct tek_report rep;
  struct calls c;
  struct tube *t = decode(b, k, &rep, &c);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(rep.wt_traces, 3);
  assert_int_equal(c.wt, 3);
  assert_int_equal(c.wt_x0, 31);
  assert_int_equal(c.wt_x1, 31);
  assert_int_equal(tube_count(t), 2);
  assert_true(tube_lit(t, 40, 40));
  assert_true(tube_lit(t, 41, 40));
  tube_free(t);
  /* the vector's callback had both ends */
  k = 0;
  b[k++] = TEK_ESC; b[k++] = 's';
  b[k++] = TEK_GS;
  k = put_dot(b, k, 10, 10);
  k = put_dot(b, k, 20, 12);
  t = decode(b, k, &rep, &c);
  assert_int_equal(c.wt, 1);
  assert_int_equal(c.wt_x0, 10); assert_int_equal(c.wt_y0, 10);
  assert_int_equal(c.wt_x1, 20); assert_int_equal(c.wt_y1, 12);
  assert_int_equal(tube_count(t), 0);
  tube_free(t);
}

static void test_decode_ignored_escapes(void **state)
{
  (void)state;
  const uint8_t b[] = { TEK_ESC, 0x1A, TEK_ESC, 0x05, TEK_ESC, 0x17, TEK_ESC, 0x0E,
                        TEK_ESC, 0x0F, TEK_ESC, '8', TEK_ESC, ';', TEK_ESC, '9', TEK_ESC, ':',
                        0x00, 0x16, TEK_BEL, 0x7F, TEK_GS, TEK_LF, 0x00, TEK_US };
  struct tek_report rep;
  struct tube *t = decode(b, sizeof b, &rep, NULL);
  assert_int_equal(rep.warnings, 0);
  assert_int_equal(tube_count(t), 0);
  tube_free(t);
}

static void test_decode_garbage_offsets(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;                        /* 0 */
  b[k++] = 0x85;                          /* 1: not 7-bit */
  b[k++] = TEK_ESC; b[k++] = '?';         /* 2, 3: unknown escape (warned at its ESC, 2) */
  b[k++] = 0x02;                          /* 4: STX means nothing in point plot */
  k = put_dot(b, k, 1, 1);                /* 5..9: fine */
  b[k++] = 0x3F; b[k++] = 0x7F;           /* 10, 11: HiY, LoY ... */
  b[k++] = TEK_GS;                        /* 12: interrupts the address begun at 10 */
  b[k++] = TEK_FS;                        /* 13 */
  b[k++] = 0x3F; b[k++] = 0x60; b[k++] = 0x20; b[k++] = 0x40;  /* 14..17: Y = 3968: above */
  b[k++] = TEK_RS; b[k++] = 'Z';          /* 18, 19: nonsense in incremental mode */
  struct tek_report rep;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(rep.warnings, 6);
  const size_t want[] = { 1, 2, 4, 12, 14, 19 };
  for (int w = 0; w < 6; w++) assert_int_equal(rep.warn_offset[w], want[w]);
  assert_int_equal(tube_count(t), 1);     /* the one good point */
  assert_int_equal(rep.bytes, k);
  tube_free(t);
}

static void test_decode_truncated(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  k = put_dot(b, k, 3, 4);
  size_t cut = k;
  k = put_dot(b, k, 8, 9);
  struct tek_report rep;
  /* every cut inside the second address: the first dot shows, one warning at its start */
  for (size_t n = cut + 1; n < k; n++) {
    struct tube *t = decode(b, n, &rep, NULL);
    assert_int_equal(tube_count(t), 1);
    assert_int_equal(rep.warnings, 1);
    assert_int_equal(rep.warn_offset[0], cut);
    tube_free(t);
  }
  /* ends after ESC */
  b[k++] = TEK_ESC;
  struct tube *t = decode(b, k, &rep, NULL);
  assert_int_equal(tube_count(t), 2);
  assert_int_equal(rep.warnings, 1);
  assert_int_equal(rep.warn_offset[0], k - 1);
  tube_free(t);
  /* nothing at all, and a NULL sink */
  assert_int_equal(tek_decode(NULL, 0, NULL, &rep), T74_OK);
  assert_int_equal(tek_decode(b, k, NULL, &rep), T74_OK);
  assert_int_equal(rep.points, 2);
}

/* A sink that fails on its third dot. */
static int fail3(void *ctx, int x, int y)
{
  (void)x; (void)y;
  int *n = ctx;
  return ++*n >= 3 ? T74_EIO : T74_OK;
}

static void test_decode_sink_failure(void **state)
{
  (void)state;
  uint8_t b[64];
  size_t k = 0;
  b[k++] = TEK_FS;
  for (int p = 0; p < 5; p++) k = put_dot(b, k, p, p);
  int n = 0;
  struct sink s = { &n, fail3, NULL, NULL };
  struct tek_report rep;
  memset(&rep, 0, sizeof rep);
  assert_int_equal(tek_decode(b, k, &s, &rep), T74_EIO);
  assert_int_equal(n, 3);
  assert_true(rep.bytes < k);
}

static void test_font_every_char(void **state)
{
  (void)state;
  for (int c = 0x20; c <= 0x7E; c++) {
    /* the glyph string is well formed */
    const char *g = tek_glyph(c);
    for (const char *p = g; *p;) {
      if (*p == ' ') { p++; continue; }
      assert_true(p[0] >= '0' && p[0] <= '4');
      assert_true(p[1] >= '0' && p[1] <= '8');
      p += 2;
    }
    /* and draws something (the blank nothing), at every character size */
    for (int size = 0; size < 4; size++) {
      uint8_t b[8];
      size_t k = 0;
      b[k++] = TEK_ESC; b[k++] = (uint8_t)('8' + size);
      b[k++] = TEK_US; b[k++] = (uint8_t)c;
      struct tek_report rep;
      struct tube *t = decode(b, k, &rep, NULL);
      assert_int_equal(rep.warnings, 0);
      assert_int_equal(rep.chars, 1);
      if (c == ' ') assert_int_equal(tube_count(t), 0);
      else if (tube_count(t) == 0) fail_msg("character 0x%02X '%c' (size %d) draws nothing", c, c, size + 1);
      tube_free(t);
    }
  }
  assert_string_equal(tek_glyph(0x7F), "");
  assert_string_equal(tek_glyph('\n'), "");
}

static void test_corpus_replay(void **state)
{
  (void)state;
  DIR *d = opendir(CORPUS);
  if (!d) fail_msg("%s: cannot open: %s", CORPUS, strerror(errno));
  struct dirent *e;
  int files = 0;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') continue;
    char p[512];
    snprintf(p, sizeof p, "%s/%s", CORPUS, e->d_name);
    size_t n = 0;
    uint8_t *b = slurp(p, &n);
    if (!b) fail_msg("%s: cannot read", p);
    struct tube *t = tube_new();
    struct sink s = tube_sink(t);
    struct calls c;
    memset(&c, 0, sizeof c);
    c.tube = t;
    struct tek_report rep;
    memset(&rep, 0, sizeof rep);
    rep.erase = cb_erase;
    rep.write_through = cb_wt;
    rep.ctx = &c;
    assert_int_equal(tek_decode(b, n, &s, &rep), T74_OK);
    assert_int_equal(rep.bytes, n);
    assert_true(tube_count(t) <= TUBE_W * TUBE_H);
    tube_free(t);
    free(b);
    files++;
  }
  closedir(d);
  assert_true(files > 0);
}

/* ---- the command: round trips through $TUBE74 --------------------------------------- */

/* run(OUT, ERR, ARG..., NULL): $TUBE74 ARG... with stdout to OUT and stderr to ERR (each
** NULL for /dev/null); the exit status, or -1. */
#define run tk_runl

/* Round trip of one scene: the points of `render SCENE` and of `render (tek SCENE)` are
** the same, in the same order. */
static void round_trip(const char *scene)
{
  char tek[128], a[128], b[128], log[128];
  in_dir(tek, sizeof tek, "rt.tek");
  in_dir(a, sizeof a, "rt_a.txt");
  in_dir(b, sizeof b, "rt_b.txt");
  in_dir(log, sizeof log, "rt.log");
  int st = run(NULL, log, "tek", scene, "-o", tek, (char *)NULL);
  if (st != 0) fail_msg("%s: tube74 tek exited %d", scene, st);
  char dump_a[160], dump_b[160];
  snprintf(dump_a, sizeof dump_a, "points=%s", a);
  snprintf(dump_b, sizeof dump_b, "points=%s", b);
  st = run(NULL, log, "render", scene, "--dump", dump_a, (char *)NULL);
  if (st != 0) fail_msg("%s: tube74 render exited %d", scene, st);
  st = run(NULL, log, "render", tek, "--dump", dump_b, (char *)NULL);
  if (st != 0) fail_msg("%s: tube74 render of its Tek stream exited %d", scene, st);
  size_t na, nb, nl;
  uint8_t *pa = slurp(a, &na), *pb = slurp(b, &nb), *pl = slurp(log, &nl);
  assert_non_null(pa);
  assert_non_null(pb);
  assert_non_null(pl);
  if (nl != 0) fail_msg("%s: reading the Tek stream back warned: %.*s", scene, (int)nl, (char *)pl);
  if (na != nb || memcmp(pa, pb, na) != 0)
    fail_msg("%s: the Tek stream stores other points (%zu vs %zu bytes of points)", scene, na, nb);
  assert_true(na > 0);
  free(pa); free(pb); free(pl);
}

static void test_round_trip_shipped_scenes(void **state)
{
  (void)state;
  DIR *d = opendir("scenes");
  assert_non_null(d);
  struct dirent *e;
  int n = 0;
  while ((e = readdir(d)) != NULL) {
    size_t len = strlen(e->d_name);
    if (len < 5 || strcmp(e->d_name + len - 4, ".s74") != 0) continue;
    char p[512];
    snprintf(p, sizeof p, "scenes/%s", e->d_name);
    round_trip(p);
    n++;
  }
  closedir(d);
  assert_true(n >= 1);
}

/* Write a random scene of triangles and quads, each planar by construction: a triangle is
** any three points that are not collinear; a quad is O, O + wU, O + wU + hV, O + hV with
** integer O, U, V (U, V not parallel), so its four corners lie on one plane exactly. */
static void write_random_scene(const char *path, uint64_t seed)
{
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "# random scene %llu (test_tek.c)\nview 0 0 -1000\nwindow -200 -150 200 150\n",
          (unsigned long long)seed);
  uint64_t s = seed;
#define R(lo, hi) ((long)(rng_next(&s) % (uint64_t)((hi) - (lo) + 1)) + (lo))
  int faces = (int)R(2, 7), v = 1;
  for (int fc = 1; fc <= faces; fc++) {
    if (R(0, 1)) {                        /* triangle */
      long p[3][3];
      for (;;) {
        for (int k = 0; k < 3; k++) { p[k][0] = R(-250, 250); p[k][1] = R(-200, 200); p[k][2] = R(0, 600); }
        long ux = p[1][0] - p[0][0], uy = p[1][1] - p[0][1], uz = p[1][2] - p[0][2];
        long wx = p[2][0] - p[0][0], wy = p[2][1] - p[0][1], wz = p[2][2] - p[0][2];
        long cx = uy * wz - uz * wy, cy = uz * wx - ux * wz, cz = ux * wy - uy * wx;
        if (cz != 0 && (cx != 0 || cy != 0 || cz != 0)) break;   /* not collinear, not edge-on */
      }
      for (int k = 0; k < 3; k++) fprintf(f, "vertex %d %ld %ld %ld\n", v + k, p[k][0], p[k][1], p[k][2]);
      fprintf(f, "face %d %d %d %d grey %ld\n", fc, v, v + 1, v + 2, R(0, 255));
      v += 3;
    } else {                              /* quad on O + aU + bV */
      long O[3] = { R(-200, 100), R(-150, 80), R(0, 500) }, U[3], V[3];
      for (;;) {
        for (int k = 0; k < 3; k++) { U[k] = R(-3, 3); V[k] = R(-3, 3); }
        long cz = U[0] * V[1] - U[1] * V[0];
        if (cz != 0) break;               /* not parallel, and not seen edge-on */
      }
      long w = R(10, 40), h = R(10, 40);
      long c[4][3];
      for (int k = 0; k < 3; k++) {
        c[0][k] = O[k];
        c[1][k] = O[k] + w * U[k];
        c[2][k] = O[k] + w * U[k] + h * V[k];
        c[3][k] = O[k] + h * V[k];
      }
      for (int k = 0; k < 4; k++) fprintf(f, "vertex %d %ld %ld %ld\n", v + k, c[k][0], c[k][1], c[k][2]);
      fprintf(f, "face %d %d %d %d %d grey %ld\n", fc, v, v + 1, v + 2, v + 3, R(0, 255));
      v += 4;
    }
  }
  if (R(0, 1)) fprintf(f, "effects halftone=3x3\n");
#undef R
  assert_int_equal(fclose(f), 0);
}

static void test_round_trip_random_scenes(void **state)
{
  (void)state;
  for (uint64_t seed = 1; seed <= N_RANDOM_SCENES; seed++) {
    char p[128];
    in_dir(p, sizeof p, "random.s74");
    write_random_scene(p, seed * 7919);
    round_trip(p);
  }
}

static void test_command_stdout_and_failures(void **state)
{
  (void)state;
  char tek[128], out[128], log[128], bad[128], garbage[128];
  in_dir(tek, sizeof tek, "o.tek");
  in_dir(out, sizeof out, "stdout.tek");
  in_dir(log, sizeof log, "cmd.log");
  /* stdout and -o give the same bytes */
  assert_int_equal(run(NULL, log, "tek", "scenes/fig6.s74", "-o", tek, (char *)NULL), 0);
  assert_int_equal(run(out, log, "tek", "scenes/fig6.s74", (char *)NULL), 0);
  size_t n1, n2;
  uint8_t *b1 = slurp(tek, &n1), *b2 = slurp(out, &n2);
  assert_non_null(b1);
  assert_non_null(b2);
  assert_int_equal(n1, n2);
  assert_memory_equal(b1, b2, n1);
  free(b1); free(b2);
  /* a scene that is wrong: exit 2, no Tek file, nothing on stdout */
  in_dir(bad, sizeof bad, "bad.s74");
  FILE *f = fopen(bad, "w");
  fprintf(f, "view 0 0 -1000\nwindow -200 -150 200 150\nnonsense 1 2 3\n");
  fclose(f);
  unlink(tek);
  assert_int_equal(run(out, log, "tek", bad, "-o", tek, (char *)NULL), 2);
  assert_false(file_exists(tek));
  assert_int_equal(run(out, log, "tek", bad, (char *)NULL), 2);
  size_t n;
  uint8_t *b = slurp(out, &n);
  assert_int_equal(n, 0);
  free(b);
  /* a garbage stream: shown as far as valid, warnings "FILE: warning: byte N: ..." */
  in_dir(garbage, sizeof garbage, "garbage.tek");
  f = fopen(garbage, "wb");
  const uint8_t g[] = { TEK_FS, 0x20, 0x65, 0x61, 0x20, 0x41, 0xFF, TEK_ESC, '?', 0x21 };
  fwrite(g, 1, sizeof g, f);
  fclose(f);
  char dump[160], pts[128];
  in_dir(pts, sizeof pts, "g.txt");
  snprintf(dump, sizeof dump, "points=%s", pts);
  assert_int_equal(run(NULL, log, "render", garbage, "--dump", dump, (char *)NULL), 0);
  b = slurp(log, &n);
  assert_non_null(b);
  char want[256];
  snprintf(want, sizeof want, "%s: warning: byte 6: ", garbage);
  assert_non_null(strstr((char *)b, want));
  snprintf(want, sizeof want, "%s: warning: byte 7: ", garbage);   /* ESC ?: at the ESC */
  assert_non_null(strstr((char *)b, want));
  snprintf(want, sizeof want, "%s: warning: byte 9: ", garbage);   /* truncated address */
  assert_non_null(strstr((char *)b, want));
  free(b);
  b = slurp(pts, &n);
  assert_non_null(b);
  assert_int_equal(n, 4);
  assert_memory_equal(b, "0 0\n", 4);
  free(b);
  /* --input tek on a file that does not sniff as one (starts with a printable byte) */
  f = fopen(garbage, "wb");
  fputs("AB", f);
  fclose(f);
  assert_int_equal(run(NULL, log, "render", garbage, "--input", "tek", "--dump", dump, (char *)NULL), 0);
  b = slurp(pts, &n);
  assert_true(n > 0);                     /* the text "AB" drawn as strokes */
  free(b);
  /* dumps a Tek stream cannot give: exit 2 */
  assert_int_equal(run(NULL, log, "tek", "scenes/fig6.s74", "-o", tek, (char *)NULL), 0);
  char ids[160];
  snprintf(ids, sizeof ids, "ids=%s/x.pgm", scratch);
  assert_int_equal(run(NULL, log, "render", tek, "--dump", ids, (char *)NULL), 2);
  /* tek of a Tek stream re-encodes it: the same bytes again */
  char tek2[128];
  in_dir(tek2, sizeof tek2, "o2.tek");
  assert_int_equal(run(NULL, log, "tek", tek, "-o", tek2, (char *)NULL), 0);
  b1 = slurp(tek, &n1);
  b2 = slurp(tek2, &n2);
  assert_int_equal(n1, n2);
  assert_memory_equal(b1, b2, n1);
  free(b1); free(b2);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_mapping_round_trip),
    cmocka_unit_test(test_sniff),
    cmocka_unit_test(test_encoder_header_trailer),
    cmocka_unit_test(test_encoder_omits_unchanged),
    cmocka_unit_test(test_encoder_extra_byte),
    cmocka_unit_test(test_encoder_rejects_and_aborts),
    cmocka_unit_test(test_encoder_decoder_order),
    cmocka_unit_test(test_decode_fs_points),
    cmocka_unit_test(test_decode_gs_vectors),
    cmocka_unit_test(test_decode_omitted_bytes),
    cmocka_unit_test(test_decode_extra_byte),
    cmocka_unit_test(test_decode_rs_incremental),
    cmocka_unit_test(test_decode_alpha_us_cr),
    cmocka_unit_test(test_decode_esc_ff_erase),
    cmocka_unit_test(test_decode_write_through),
    cmocka_unit_test(test_decode_ignored_escapes),
    cmocka_unit_test(test_decode_garbage_offsets),
    cmocka_unit_test(test_decode_truncated),
    cmocka_unit_test(test_decode_sink_failure),
    cmocka_unit_test(test_font_every_char),
    cmocka_unit_test(test_corpus_replay),
    cmocka_unit_test(test_round_trip_shipped_scenes),
    cmocka_unit_test(test_round_trip_random_scenes),
    cmocka_unit_test(test_command_stdout_and_failures),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
