/*
** test_output.c — tests of the halftone and output side (paper 003 §4; CONTRACT.md).
**
** This file contains code to check, one module at a time, that:
**   patterns/halftone  the grey -> level table follows its formula (Weber-Fechner, 003 §4),
**                      every family is a nested threshold matrix, and points land in the
**                      tube cells the contract fixes;
**   display/tube       stores each dot once and remembers the first-write order;
**   display/sink.h     the tee forwards, stops on the first failure and aborts the rest;
**   display/image      PBM / PGM / points files are exactly the expected bytes, the PNG
**                      reads back as the expected pixels;
**   display/outfile    no file appears on abort or failure, an existing file is kept;
**   patterns/picture   PGM P2/P5 (maxval 1..65535) and PNG load, malformed files are
**                      T74_EINPUT, box sampling gives the exact integer means.
** A standalone cmocka program, run from the repository root (it reads scenes/harbour.pgm).
** Scratch files go to a fresh folder under /tmp, removed at the end.
*/
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>
#include <png.h>

#include "display/image.h"
#include "display/outfile.h"
#include "display/sink.h"
#include "display/tube.h"
#include "emu/status.h"
#include "patterns/halftone.h"
#include "patterns/picture.h"

/* ---- scratch folder and file helpers ---------------------------------------------- */

struct scratch {
  char dir[64];                 /* mkdtemp folder for this run */
  char path[256];               /* last path built by in_dir */
};

static int group_setup(void **state)
{
  struct scratch *s = calloc(1, sizeof *s);
  if (!s) return -1;
  strcpy(s->dir, "/tmp/t74out.XXXXXX");
  if (!mkdtemp(s->dir)) { free(s); return -1; }
  *state = s;
  return 0;
}

/* Remove every entry of dir (one level; sub-folders are removed if empty). */
static void empty_dir(const char *dir)
{
  DIR *d = opendir(dir);
  if (!d) return;
  struct dirent *e;
  char p[512];
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
    if (unlink(p) != 0) rmdir(p);
  }
  closedir(d);
}

static int group_teardown(void **state)
{
  struct scratch *s = *state;
  empty_dir(s->dir);
  rmdir(s->dir);
  free(s);
  return 0;
}

/* Each test starts with an empty scratch folder. */
static int test_setup(void **state)
{
  empty_dir(((struct scratch *)*state)->dir);
  return 0;
}

static const char *in_dir(void **state, const char *name)
{
  struct scratch *s = *state;
  snprintf(s->path, sizeof s->path, "%s/%s", s->dir, name);
  return s->path;
}

static int dir_entries(void **state)
{
  struct scratch *s = *state;
  DIR *d = opendir(s->dir);
  assert_non_null(d);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) n++;
  closedir(d);
  return n;
}

static void put_file(const char *path, const void *bytes, size_t n)
{
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(bytes, 1, n, f), n);
  assert_int_equal(fclose(f), 0);
}

/* The whole file, malloc'd, with a NUL after it; *n its length. */
static uint8_t *get_file(const char *path, size_t *n)
{
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  size_t cap = 1 << 20;
  uint8_t *b = malloc(cap + 1);
  assert_non_null(b);
  *n = fread(b, 1, cap, f);
  assert_true(*n < cap);
  fclose(f);
  b[*n] = 0;
  return b;
}

static int file_exists(const char *path)
{
  struct stat st;
  return stat(path, &st) == 0;
}

static int popcount16(uint16_t m)
{
  int n = 0;
  for (; m; m &= (uint16_t)(m - 1)) n++;
  return n;
}

/* ---- a recording sink -------------------------------------------------------------- */

struct rec {
  int n;                        /* points received */
  int x[64], y[64];             /* the first 64 of them */
  int fail_at;                  /* point number that fails with T74_EIO, or -1 */
  int ended, aborted;           /* end / abort calls */
  int end_status;               /* what end returns */
};

static int rec_point(void *ctx, int x, int y)
{
  struct rec *r = ctx;
  if (r->n == r->fail_at) return T74_EIO;
  if (r->n < 64) { r->x[r->n] = x; r->y[r->n] = y; }
  r->n++;
  return T74_OK;
}

static int rec_end(void *ctx, struct t74_error *err)
{
  struct rec *r = ctx;
  r->ended++;
  if (r->end_status != T74_OK) return t74_fail(err, r->end_status, "rec: end failed");
  return T74_OK;
}

static void rec_abort(void *ctx)
{
  ((struct rec *)ctx)->aborted++;
}

static struct sink rec_sink(struct rec *r)
{
  memset(r, 0, sizeof *r);
  r->fail_at = -1;
  struct sink s = { r, rec_point, rec_end, rec_abort };
  return s;
}

/* ---- halftone: grey -> level ----------------------------------------------------- */

static void test_level_monotone_and_ends(void **state)
{
  (void)state;
  for (int cell = 3; cell <= 4; cell++) {
    int L = cell * cell;
    assert_int_equal(pat_levels(cell), L + 1);
    assert_int_equal(pat_level(cell, 0), 0);
    assert_int_equal(pat_level(cell, 255), L);
    int seen[17] = { 0 };
    for (int g = 1; g <= 255; g++) {
      assert_true(pat_level(cell, g) >= pat_level(cell, g - 1));
      seen[pat_level(cell, g)] = 1;
    }
    for (int l = 1; l <= L; l++) assert_true(seen[l]);     /* every level is reachable */
    assert_int_equal(pat_level(cell, -7), 0);              /* clamped */
    assert_int_equal(pat_level(cell, 300), L);
  }
  assert_int_equal(pat_levels(5), 0);
  assert_int_equal(pat_level(5, 200), 0);
}

static void test_level_exact_values(void **state)
{
  (void)state;
  /* step points of round((L+1)^(G/255) - 1) (derived in halftone.c) */
  assert_int_equal(pat_level(3, 44), 0);
  assert_int_equal(pat_level(3, 45), 1);
  assert_int_equal(pat_level(3, 101), 1);
  assert_int_equal(pat_level(3, 102), 2);
  assert_int_equal(pat_level(3, 128), 2);
  assert_int_equal(pat_level(3, 237), 7);   /* 7.49986: the closest call */
  assert_int_equal(pat_level(3, 238), 8);
  assert_int_equal(pat_level(3, 249), 8);
  assert_int_equal(pat_level(3, 250), 9);
  assert_int_equal(pat_level(4, 36), 0);
  assert_int_equal(pat_level(4, 37), 1);
  assert_int_equal(pat_level(4, 112), 2);
  assert_int_equal(pat_level(4, 113), 3);
  assert_int_equal(pat_level(4, 128), 3);
  assert_int_equal(pat_level(4, 252), 15);
  assert_int_equal(pat_level(4, 253), 16);
  /* the whole table against its formula: within half a level everywhere */
  for (int cell = 3; cell <= 4; cell++) {
    double L = cell * cell;
    for (int g = 0; g <= 255; g++) {
      double want = pow(L + 1, g / 255.0) - 1;
      assert_true(fabs(pat_level(cell, g) - want) <= 0.5);
    }
  }
}

/* ---- halftone: families ---------------------------------------------------------- */

static void test_families_are_nested(void **state)
{
  (void)state;
  int nfam = 0;
  for (int k = 0; pat_family(k) != NULL; k++, nfam++)
    for (int cell = 3; cell <= 4; cell++) {
      const struct pat_cell *p = NULL;
      assert_int_equal(pat_find(pat_family(k), cell, &p), T74_OK);
      assert_int_equal(pat_cell_size(p), cell);
      assert_string_equal(pat_cell_name(p), pat_family(k));
      int L = cell * cell, used[16] = { 0 };
      for (int cy = 0; cy < cell; cy++)    /* ranks: a permutation of 0..L-1 */
        for (int cx = 0; cx < cell; cx++) {
          int r = pat_rank(p, cx, cy);
          assert_in_range(r, 0, L - 1);
          assert_false(used[r]);
          used[r] = 1;
        }
      uint16_t prev = 0, m;
      for (int level = 0; level <= L; level++) {
        pat_cell_dots(p, level, &m);
        assert_int_equal(popcount16(m), level);            /* level n lights n dots */
        assert_int_equal(m & prev, prev);                  /* nested: only adds dots */
        assert_int_equal(m >> L, 0);                       /* nothing outside the cell */
        prev = m;
      }
    }
  assert_true(nfam >= 2);
}

static void test_find(void **state)
{
  (void)state;
  const struct pat_cell *p = NULL, *q = NULL;
  assert_int_equal(pat_find(NULL, 4, &p), T74_OK);
  assert_string_equal(pat_cell_name(p), "dispersed");
  assert_int_equal(pat_find("", 3, &q), T74_OK);
  assert_string_equal(pat_cell_name(q), "dispersed");
  assert_int_equal(pat_cell_size(q), 3);
  assert_int_equal(pat_find("clustered", 3, &p), T74_OK);
  assert_int_equal(pat_rank(p, 1, 1), 0);                   /* grows from the centre */
  assert_int_equal(pat_find("clustered", 4, &p), T74_OK);
  assert_true(pat_rank(p, 1, 1) < 4 && pat_rank(p, 2, 2) < 4);
  assert_true(pat_rank(p, 0, 0) >= 12);                     /* corners last */
  q = NULL;
  assert_int_equal(pat_find("nosuch", 4, &q), T74_EINPUT);
  assert_null(q);
  assert_int_equal(pat_find("dispersed", 5, &q), T74_EINPUT);
  assert_null(q);
  /* dispersed 4x4 at level 2: the two dots are far apart (not neighbours) */
  assert_int_equal(pat_find("dispersed", 4, &p), T74_OK);
  uint16_t m;
  pat_cell_dots(p, 2, &m);
  assert_int_equal(m, (1u << 0) | (1u << (2 * 4 + 2)));
}

/* ---- halftone: placement on the tube ----------------------------------------------- */

static void check_point(int cell, int i, int j)
{
  const struct pat_cell *p;
  assert_int_equal(pat_find(NULL, cell, &p), T74_OK);
  struct rec r;
  struct sink s = rec_sink(&r);
  assert_int_equal(pat_emit_point(p, i, j, cell * cell, &s), T74_OK);
  assert_int_equal(r.n, cell * cell);
  int llx = cell * i, lly = 299 - cell * (j + 1) + 1;      /* CONTRACT.md, lower-left dot */
  for (int k = 0; k < r.n; k++) {
    int cx = k % cell, cy = k / cell;                        /* scan order: top row first */
    assert_int_equal(r.x[k], llx + cx);
    assert_int_equal(r.y[k], lly + cell - 1 - cy);
  }
  assert_int_equal(r.x[cell * (cell - 1)], llx);             /* first dot of the last row */
  assert_int_equal(r.y[cell * (cell - 1)], lly);             /* is the lower-left dot */
}

static void test_cell_placement(void **state)
{
  (void)state;
  assert_int_equal(pat_grid_w(3), 133);
  assert_int_equal(pat_grid_h(3), 100);
  assert_int_equal(pat_grid_w(4), 100);
  assert_int_equal(pat_grid_h(4), 75);
  check_point(3, 0, 0);
  check_point(3, 132, 99);
  check_point(4, 0, 0);
  check_point(4, 99, 74);
  check_point(4, 7, 30);
  /* concrete corners: top-left dot of (0,0) is (0, 299); bottom-right of (W-1,H-1) */
  int x, y;
  pat_dot_xy(3, 0, 0, 0, 0, &x, &y);
  assert_int_equal(x, 0); assert_int_equal(y, 299);
  pat_dot_xy(3, 132, 99, 2, 2, &x, &y);
  assert_int_equal(x, 398); assert_int_equal(y, 0);
  pat_dot_xy(4, 99, 74, 3, 3, &x, &y);
  assert_int_equal(x, 399); assert_int_equal(y, 0);
  /* outside the grid */
  const struct pat_cell *p;
  struct rec r;
  struct sink s = rec_sink(&r);
  assert_int_equal(pat_find(NULL, 3, &p), T74_OK);
  assert_int_equal(pat_emit_point(p, 133, 0, 9, &s), T74_EINPUT);
  assert_int_equal(pat_emit_point(p, 0, 100, 9, &s), T74_EINPUT);
  assert_int_equal(pat_emit_point(p, -1, 0, 9, &s), T74_EINPUT);
  assert_int_equal(r.n, 0);
}

static void test_emit_partial_and_failure(void **state)
{
  (void)state;
  const struct pat_cell *p;
  assert_int_equal(pat_find("clustered", 3, &p), T74_OK);
  struct rec r;
  struct sink s = rec_sink(&r);
  assert_int_equal(pat_emit_point(p, 10, 20, 1, &s), T74_OK);  /* level 1: the centre */
  assert_int_equal(r.n, 1);
  assert_int_equal(r.x[0], 31);
  assert_int_equal(r.y[0], 299 - 60 - 1);
  s = rec_sink(&r);
  assert_int_equal(pat_emit_point(p, 0, 0, 0, &s), T74_OK);    /* level 0: no dot */
  assert_int_equal(r.n, 0);
  s = rec_sink(&r);
  r.fail_at = 2;
  assert_int_equal(pat_emit_point(p, 0, 0, 9, &s), T74_EIO);   /* stops at the failure */
  assert_int_equal(r.n, 2);
}

/* ---- tube and tee ------------------------------------------------------------------ */

/* Tubes a and b hold the same dots in the same order from the k-th on. */
static void tubes_same_from(const struct tube *a, const struct tube *b, int from)
{
  assert_int_equal(tube_count(a), tube_count(b));
  for (int k = from; k < tube_count(a); k++) {
    int xa, ya, xb, yb;
    assert_int_equal(tube_order(a, k, &xa, &ya), T74_OK);
    assert_int_equal(tube_order(b, k, &xb, &yb), T74_OK);
    assert_int_equal(xa, xb);
    assert_int_equal(ya, yb);
  }
}

/* tube_write_dots stores exactly what tube_write of each set bit would, in rising bit
   order: the same dots, order, count and first failure, for cells of 1 to 4 at every
   offset (a 4x4 cell at x0 not a multiple of 4 too), cells partly off the tube, masks
   with bits beyond the cell, and dots already lit; b's order read now and then between
   writes (it is spelled out when read: writes after a read go on from there). */
static void test_tube_write_dots(void **state)
{
  (void)state;
  struct tube *a = tube_new(), *b = tube_new();
  assert_non_null(a);
  assert_non_null(b);
  uint32_t x = 12345;
  for (int round = 0; round < 4000; round++) {
    x = x * 1103515245u + 12345u;
    int cell = 1 + (int)((x >> 8) % 4);
    x = x * 1103515245u + 12345u;
    int x0 = (int)((x >> 8) % 404) - 2;
    x = x * 1103515245u + 12345u;
    int y0 = (int)((x >> 8) % 304) - 2;
    x = x * 1103515245u + 12345u;
    unsigned mask = (x >> 4) & ((round % 7 == 0) ? 0x3ffffu : (1u << (cell * cell)) - 1u);
    int want = T74_OK;
    for (unsigned m = mask; m; m &= m - 1) {
      int k = __builtin_ctz(m);
      want = tube_write(a, x0 + k % cell, y0 - k / cell);
      if (want != T74_OK) break;
    }
    assert_int_equal(tube_write_dots(b, x0, y0, cell, mask), want);
    assert_int_equal(tube_count(a), tube_count(b));
    if (round % 61 == 7 && tube_count(b) > 0) {
      int xb, yb;
      assert_int_equal(tube_order(b, tube_count(b) - 1, &xb, &yb), T74_OK);
      assert_int_equal(tube_lit(b, xb, yb), 1);
    }
    if (round % 500 != 499) continue;
    assert_true(tube_count(a) > 1000);
    tubes_same_from(a, b, 0);
    tube_erase(a);
    tube_erase(b);
  }
  tube_free(a);
  tube_free(b);
}

/* tube_write_cells stores exactly what tube_write_dots of each cell in turn would: rows of
   3x3 and 4x4 cells (aligned or not, partly off the tube, masks with bits beyond the
   cell, empty masks, runs of one mask) over dots already lit, the same status, dots,
   count and order. */
static void test_tube_write_cells(void **state)
{
  (void)state;
  struct tube *a = tube_new(), *b = tube_new();
  assert_non_null(a);
  assert_non_null(b);
  uint32_t x = 777;
  int fails = 0;
  for (int round = 0; round < 3000; round++) {
    uint16_t masks[140];
    x = x * 1103515245u + 12345u;
    int cell = 3 + (int)((x >> 8) % 2);
    x = x * 1103515245u + 12345u;
    int count = (int)((x >> 8) % 140);
    x = x * 1103515245u + 12345u;
    int x0 = round % 5 == 0 ? (int)((x >> 8) % 420) - 10 : cell * (int)((x >> 8) % 40);
    x = x * 1103515245u + 12345u;
    int y0 = round % 11 == 0 ? (int)((x >> 12) % 310) - 5 : (int)((x >> 12) % 300);
    for (int c = 0; c < count; c++) {
      x = x * 1103515245u + 12345u;
      unsigned m = (x >> 8) & 0xffffu;
      masks[c] = (uint16_t)(c % 9 == 4 ? 0 : round % 13 == 0 ? m : m & ((1u << (cell * cell)) - 1u));
    }
    if (round % 4 == 1)                     /* runs of ten cells of one mask */
      for (int c = 0; c < count; c++) masks[c] = masks[c - c % 10];
    int want = T74_OK;
    for (int c = 0; c < count && want == T74_OK; c++)
      want = tube_write_dots(a, x0 + c * cell, y0, cell, masks[c]);
    int got = tube_write_cells(b, x0, y0, cell, masks, count);
    assert_int_equal(got, want);
    fails += got != T74_OK;
    assert_int_equal(tube_count(a), tube_count(b));
    if (round % 300 != 299) continue;
    assert_true(tube_count(a) > 1000);
    tubes_same_from(a, b, 0);
    tube_erase(a);
    tube_erase(b);
  }
  assert_true(fails > 0);
  tube_free(a);
  tube_free(b);
}

/* Whole rows of 3x3 cells written where nothing is lit yet (a tube being drawn: the cells'
   rows stored seven cells at a time), at the tube's corners and edges (the top row, the
   bottom row, the last dot of a row; seven cells of no dot among them, and six before
   one that has), and again over
   them with a dot lit under one cell, and with a dot in every cell (seven cells' writes
   stored four at a time), and in runs of 17 cells of one mask (seven cells of one mask
   taken at once), with and without a dot lit under one: the same dots, count and order
   as tube_write_dots of each cell in turn. */
static void test_tube_write_cells3_rows(void **state)
{
  (void)state;
  static const int at[][3] = { { 0, 299, 133 }, { 1, 299, 133 }, { 0, 2, 133 }, { 1, 2, 133 },
                               { 397, 150, 1 }, { 394, 2, 2 }, { 200, 299, 66 }, { 5, 100, 20 } };
  uint32_t x = 4242;
  for (int pass = 0; pass < 5; pass++)
    for (size_t k = 0; k < sizeof at / sizeof at[0]; k++) {
      struct tube *a = tube_new(), *b = tube_new();
      assert_non_null(a);
      assert_non_null(b);
      const int x0 = at[k][0], y0 = at[k][1], count = at[k][2];
      uint16_t masks[133];
      for (int c = 0; c < count; c++) {
        x = x * 1103515245u + 12345u;
        const int none = pass < 2 && (c % 7 == 3 || c / 7 == 2 || (c / 7 == 4 && c % 7 < 6));
        masks[c] = (uint16_t)(none ? 0 : c % 5 == 1 ? 0x1ffu : 1u | ((x >> 8) & 0x1ffu));
        if (pass >= 3 && c % 17 != 0) masks[c] = masks[c - 1];   /* runs of one mask */
      }
      if (pass % 3 == 1) {                      /* a dot lit already under the last cell */
        const int dx = x0 + 3 * (count - 1) + 2, dy = y0 - 1;
        assert_int_equal(tube_write(a, dx, dy), T74_OK);
        assert_int_equal(tube_write(b, dx, dy), T74_OK);
      }
      for (int c = 0; c < count; c++)
        assert_int_equal(tube_write_dots(a, x0 + 3 * c, y0, 3, masks[c]), T74_OK);
      assert_int_equal(tube_write_cells(b, x0, y0, 3, masks, count), T74_OK);
      assert_true(tube_count(b) > 2 * count);
      tubes_same_from(a, b, 0);
      for (int yy = 0; yy < 300; yy++)
        for (int xx = 0; xx < 400; xx++) assert_int_equal(tube_lit(a, xx, yy), tube_lit(b, xx, yy));
      tube_free(a);
      tube_free(b);
    }
}

/* The same on a tube lit all but a few dots (order[] nearly full): 4x4 cells over the
   last unlit dots store exactly what tube_write would, and the tube ends full. */
static void test_tube_write_dots_full(void **state)
{
  (void)state;
  struct tube *a = tube_new(), *b = tube_new();
  assert_non_null(a);
  assert_non_null(b);
  /* unlit: a few dots in the cells at x0 = 0, 4, 8 of the top rows */
  static const int hole[][2] = { { 1, 299 }, { 2, 298 }, { 3, 297 }, { 4, 299 }, { 7, 296 },
                                 { 8, 299 }, { 9, 299 }, { 10, 299 }, { 11, 299 } };
  const int nh = (int)(sizeof hole / sizeof hole[0]);
  for (int y = 0; y < 300; y++)
    for (int x = 0; x < 400; x++) {
      int skip = 0;
      for (int h = 0; h < nh; h++) skip |= hole[h][0] == x && hole[h][1] == y;
      if (skip) continue;
      assert_int_equal(tube_write(a, x, y), T74_OK);
      assert_int_equal(tube_write(b, x, y), T74_OK);
    }
  assert_int_equal(tube_count(b), 400 * 300 - nh);
  for (int x0 = 0; x0 <= 8; x0 += 4) {
    for (int k = 0; k < 16; k++) assert_int_equal(tube_write(a, x0 + k % 4, 299 - k / 4), T74_OK);
    assert_int_equal(tube_write_dots(b, x0, 299, 4, 0xffffu), T74_OK);
    assert_int_equal(tube_count(a), tube_count(b));
  }
  assert_int_equal(tube_count(b), 400 * 300);
  struct t74_error err = { T74_OK, "" };         /* nothing written past the tube's store */
  struct sink sb = tube_sink(b);
  assert_int_equal(sink_end(&sb, &err), T74_OK);
  tubes_same_from(a, b, 400 * 300 - nh);
  tube_free(a);
  tube_free(b);
}

static void test_tube_once_in_order(void **state)
{
  (void)state;
  struct tube *t = tube_new();
  assert_non_null(t);
  struct sink s = tube_sink(t);
  int in[][2] = { { 5, 6 }, { 1, 2 }, { 5, 6 }, { 399, 299 }, { 0, 0 }, { 1, 2 } };
  for (size_t k = 0; k < sizeof in / sizeof in[0]; k++)
    assert_int_equal(sink_point(&s, in[k][0], in[k][1]), T74_OK);
  assert_int_equal(tube_count(t), 4);
  int want[][2] = { { 5, 6 }, { 1, 2 }, { 399, 299 }, { 0, 0 } };
  for (int k = 0; k < 4; k++) {
    int x, y;
    assert_int_equal(tube_order(t, k, &x, &y), T74_OK);
    assert_int_equal(x, want[k][0]);
    assert_int_equal(y, want[k][1]);
    assert_int_equal(tube_lit(t, x, y), 1);
  }
  int x, y;
  assert_int_equal(tube_order(t, 4, &x, &y), T74_EINPUT);
  assert_int_equal(tube_lit(t, 6, 5), 0);
  assert_int_equal(tube_lit(t, 400, 0), 0);
  struct t74_error err = { 0 };
  assert_int_equal(sink_end(&s, &err), T74_OK);
  /* a dot outside the tube: refused, remembered, reported by end */
  assert_int_equal(tube_write(t, 400, 10), T74_EINPUT);
  assert_int_equal(tube_write(t, 3, -1), T74_EINPUT);
  assert_int_equal(tube_count(t), 4);
  assert_int_equal(sink_end(&s, &err), T74_EINPUT);
  assert_non_null(strstr(err.msg, "(400, 10)"));
  tube_erase(t);
  assert_int_equal(tube_count(t), 0);
  assert_int_equal(tube_lit(t, 5, 6), 0);
  tube_free(t);
}

static void test_tee(void **state)
{
  (void)state;
  struct tube *a = tube_new(), *b = tube_new();
  assert_non_null(a);
  assert_non_null(b);
  struct sink_tee tee;
  sink_tee_init(&tee);
  assert_int_equal(sink_tee_add(&tee, tube_sink(a)), T74_OK);
  assert_int_equal(sink_tee_add(&tee, tube_sink(b)), T74_OK);
  struct sink s = sink_tee_sink(&tee);
  const struct pat_cell *p;
  assert_int_equal(pat_find(NULL, 4, &p), T74_OK);
  assert_int_equal(pat_emit_point(p, 1, 1, 5, &s), T74_OK);
  assert_int_equal(tube_count(a), 5);
  assert_int_equal(tube_count(b), 5);
  for (int k = 0; k < 5; k++) {
    int xa, ya, xb, yb;
    tube_order(a, k, &xa, &ya);
    tube_order(b, k, &xb, &yb);
    assert_int_equal(xa, xb);
    assert_int_equal(ya, yb);
  }
  struct t74_error err = { 0 };
  assert_int_equal(sink_end(&s, &err), T74_OK);
  tube_free(a);
  tube_free(b);

  /* a failing point: sticky, later points not forwarded */
  struct rec r1, r2;
  sink_tee_init(&tee);
  sink_tee_add(&tee, rec_sink(&r1));
  sink_tee_add(&tee, rec_sink(&r2));
  r2.fail_at = 1;
  s = sink_tee_sink(&tee);
  assert_int_equal(sink_point(&s, 1, 1), T74_OK);
  assert_int_equal(sink_point(&s, 2, 2), T74_EIO);
  assert_int_equal(sink_point(&s, 3, 3), T74_EIO);
  assert_int_equal(r1.n, 2);
  assert_int_equal(r2.n, 1);
  sink_abort(&s);
  assert_int_equal(r1.aborted, 1);
  assert_int_equal(r2.aborted, 1);

  /* a failing end: the sinks after it are aborted, not ended */
  struct rec r3;
  sink_tee_init(&tee);
  sink_tee_add(&tee, rec_sink(&r1));
  sink_tee_add(&tee, rec_sink(&r2));
  sink_tee_add(&tee, rec_sink(&r3));
  r2.end_status = T74_EIO;
  s = sink_tee_sink(&tee);
  memset(&err, 0, sizeof err);
  assert_int_equal(sink_end(&s, &err), T74_EIO);
  assert_int_equal(r1.ended, 1);
  assert_int_equal(r2.ended, 1);
  assert_int_equal(r3.ended, 0);
  assert_int_equal(r3.aborted, 1);

  /* full */
  sink_tee_init(&tee);
  for (int k = 0; k < SINK_TEE_MAX; k++) assert_int_equal(sink_tee_add(&tee, s), T74_OK);
  assert_int_equal(sink_tee_add(&tee, s), T74_EINPUT);
}

/* ---- writers ------------------------------------------------------------------------ */

/* A tiny picture: four dots that pin down orientation and bit order. */
static struct tube *tiny_tube(void)
{
  struct tube *t = tube_new();
  assert_non_null(t);
  tube_write(t, 0, 299);        /* top-left corner */
  tube_write(t, 9, 150);
  tube_write(t, 399, 0);        /* bottom-right corner */
  tube_write(t, 8, 150);
  return t;
}

static void test_pbm_bytes(void **state)
{
  struct tube *t = tiny_tube();
  const char *path = in_dir(state, "tube.pbm");
  struct t74_error err = { 0 };
  assert_int_equal(image_write_pbm(t, path, &err), T74_OK);
  static uint8_t want[11 + 300 * 50];
  memcpy(want, "P4\n400 300\n", 11);
  memset(want + 11, 0, 300 * 50);
  want[11 + 0 * 50 + 0] = 0x80;             /* file row 0 = tube y 299, x 0 = MSB */
  want[11 + 149 * 50 + 1] = 0xC0;           /* tube y 150: x 8 and 9 */
  want[11 + 299 * 50 + 49] = 0x01;          /* file row 299 = tube y 0, x 399 = LSB */
  size_t n;
  uint8_t *got = get_file(path, &n);
  assert_int_equal(n, sizeof want);
  assert_memory_equal(got, want, sizeof want);
  free(got);
  assert_int_equal(dir_entries(state), 1);  /* no temporary left beside it */
  tube_free(t);
}

static void test_points_bytes(void **state)
{
  struct tube *t = tiny_tube();
  tube_write(t, 9, 150);                    /* again: not listed twice */
  const char *path = in_dir(state, "tube.txt");
  struct t74_error err = { 0 };
  assert_int_equal(image_write_points(t, path, &err), T74_OK);
  size_t n;
  uint8_t *got = get_file(path, &n);
  assert_string_equal((char *)got, "0 299\n9 150\n399 0\n8 150\n");
  free(got);
  tube_free(t);
}

static void test_pgm_writers_bytes(void **state)
{
  const uint16_t ids[6] = { 1, 256, 65535, 0, 2, 513 };
  struct t74_error err = { 0 };
  const char *path = in_dir(state, "ids.pgm");
  assert_int_equal(image_write_ids(ids, 3, 2, path, &err), T74_OK);
  size_t n;
  uint8_t *got = get_file(path, &n);
  static const uint8_t want_ids[] = "P5\n3 2\n65535\n"
      "\x00\x01" "\x01\x00" "\xff\xff" "\x00\x00" "\x00\x02" "\x02\x01";
  assert_int_equal(n, sizeof want_ids - 1);
  assert_memory_equal(got, want_ids, n);
  free(got);

  const uint8_t grey[6] = { 0, 10, 255, 128, 7, 9 };
  path = in_dir(state, "grey.pgm");
  assert_int_equal(image_write_grey(grey, 2, 3, path, &err), T74_OK);
  got = get_file(path, &n);
  static const uint8_t want_grey[] = "P5\n2 3\n255\n" "\x00\x0a\xff\x80\x07\x09";
  assert_int_equal(n, sizeof want_grey - 1);
  assert_memory_equal(got, want_grey, n);
  free(got);
}

static void test_png_readback(void **state)
{
  struct tube *t = tiny_tube();
  const char *path = in_dir(state, "tube.png");
  struct t74_error err = { 0 };
  assert_int_equal(image_write_png(t, path, &err), T74_OK);

  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info = png_create_info_struct(png);
  assert_non_null(info);
  static uint8_t pix[300][1200];
  png_bytep rows[300];
  for (int r = 0; r < 300; r++) rows[r] = pix[r];
  if (setjmp(png_jmpbuf(png))) fail_msg("libpng could not read back %s", path);
  png_init_io(png, f);
  png_read_info(png, info);
  assert_int_equal(png_get_image_width(png, info), 400);
  assert_int_equal(png_get_image_height(png, info), 300);
  /* two colours: a 1-bit palette file; expanded it must give the RGB pixels below */
  assert_int_equal(png_get_color_type(png, info), PNG_COLOR_TYPE_PALETTE);
  assert_int_equal(png_get_bit_depth(png, info), 1);
  png_colorp pal = NULL;
  int npal = 0;
  assert_int_equal(png_get_PLTE(png, info, &pal, &npal), PNG_INFO_PLTE);
  assert_int_equal(npal, 2);
  png_set_packing(png);
  png_set_palette_to_rgb(png);
  png_read_update_info(png, info);
  assert_int_equal(png_get_rowbytes(png, info), 1200);
  png_read_image(png, rows);
  png_destroy_read_struct(&png, &info, NULL);
  fclose(f);

  static const uint8_t dot[3] = { 80, 255, 120 }, face[3] = { 8, 20, 12 };
  int lit = 0;
  for (int r = 0; r < 300; r++)
    for (int x = 0; x < 400; x++) {
      int on = tube_lit(t, x, 299 - r);
      assert_memory_equal(&pix[r][3 * x], on ? dot : face, 3);
      lit += on;
    }
  assert_int_equal(lit, 4);
  assert_memory_equal(&pix[0][0], dot, 3);            /* top-left is tube (0, 299) */
  assert_memory_equal(&pix[299][3 * 399], dot, 3);    /* bottom-right is tube (399, 0) */
  tube_free(t);
}

/* ---- atomic output ----------------------------------------------------------------- */

static void test_outfile_abort_leaves_nothing(void **state)
{
  const char *path = in_dir(state, "new.txt");
  struct outfile *o;
  struct t74_error err = { 0 };
  assert_int_equal(outfile_open(&o, path, &err), T74_OK);
  assert_int_equal(outfile_printf(o, "half a picture\n"), T74_OK);
  assert_int_equal(dir_entries(state), 1);            /* the temporary, hidden */
  assert_false(file_exists(path));                    /* not under the final name yet */
  outfile_abort(o);
  assert_false(file_exists(path));
  assert_int_equal(dir_entries(state), 0);
}

static void test_outfile_keeps_existing(void **state)
{
  const char *path = in_dir(state, "old.txt");
  put_file(path, "old\n", 4);
  struct outfile *o;
  struct t74_error err = { 0 };
  assert_int_equal(outfile_open(&o, path, &err), T74_OK);
  assert_int_equal(outfile_write(o, "new!\n", 5), T74_OK);
  outfile_abort(o);                                   /* a failed run */
  size_t n;
  uint8_t *got = get_file(path, &n);
  assert_string_equal((char *)got, "old\n");
  free(got);
  assert_int_equal(dir_entries(state), 1);

  assert_int_equal(outfile_open(&o, path, &err), T74_OK);   /* a good run replaces it */
  assert_int_equal(outfile_write(o, "new!\n", 5), T74_OK);
  assert_int_equal(outfile_commit(o, &err), T74_OK);
  got = get_file(path, &n);
  assert_string_equal((char *)got, "new!\n");
  free(got);
  assert_int_equal(dir_entries(state), 1);
}

static void test_writer_failures(void **state)
{
  struct tube *t = tiny_tube();
  struct t74_error err = { 0 };
  /* folder does not exist: T74_EIO naming the file, nothing created */
  const char *path = in_dir(state, "nodir/tube.pbm");
  assert_int_equal(image_write_pbm(t, path, &err), T74_EIO);
  assert_int_equal(err.status, T74_EIO);
  assert_non_null(strstr(err.msg, path));
  assert_int_equal(dir_entries(state), 0);
  /* the final name is a folder: refused when opened (nothing is written); the folder and
  ** its content are untouched and no temporary is left */
  path = in_dir(state, "taken");
  assert_int_equal(mkdir(path, 0777), 0);
  char inner[300];
  snprintf(inner, sizeof inner, "%s/keep", path);
  put_file(inner, "k", 1);
  memset(&err, 0, sizeof err);
  path = in_dir(state, "taken");
  assert_int_equal(image_write_png(t, path, &err), T74_EIO);
  assert_non_null(strstr(err.msg, "taken"));
  assert_int_equal(dir_entries(state), 1);
  assert_true(file_exists(inner));
  unlink(inner);
  rmdir(in_dir(state, "taken"));
  tube_free(t);
}

/* ---- picture loading ---------------------------------------------------------------- */

static struct pic *load_ok(const char *path)
{
  struct pic *p = NULL;
  struct t74_error err = { 0 };
  int rc = pic_load(path, &p, &err);
  if (rc != T74_OK) fail_msg("%s", err.msg);
  assert_non_null(p);
  return p;
}

static void test_pgm_loader(void **state)
{
  const char *path = in_dir(state, "a.pgm");
  const char p2[] = "P2\n# a comment\n3 2 # another\n15\n0 15 7\n\n8 1 # end\n 15\n";
  put_file(path, p2, sizeof p2 - 1);
  struct pic *p = load_ok(path);
  assert_int_equal(pic_width(p), 3);
  assert_int_equal(pic_height(p), 2);
  const int want2[6] = { 0, 255, 119, 136, 17, 255 };  /* round(v * 255 / 15) */
  for (int k = 0; k < 6; k++) assert_int_equal(pic_pixel(p, k % 3, k / 3), want2[k]);
  assert_int_equal(pic_pixel(p, 3, 0), -1);
  /* the rows (pic_rows, the textures' way) hold pic_pixel's pixels, row by row */
  for (int k = 0; k < 6; k++) assert_int_equal(pic_rows(p)[k], pic_pixel(p, k % 3, k / 3));
  pic_free(p);

  const char p5[] = "P5 2 2 255\n\x00\x80\xff\x07";
  put_file(path, p5, sizeof p5 - 1);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 0);
  assert_int_equal(pic_pixel(p, 1, 0), 128);
  assert_int_equal(pic_pixel(p, 0, 1), 255);
  assert_int_equal(pic_pixel(p, 1, 1), 7);
  pic_free(p);

  const char p16[] = "P5\n2 2\n65535\n\x00\x00\xff\xff\x80\x00\x01\x01";
  put_file(path, p16, sizeof p16 - 1);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 0);
  assert_int_equal(pic_pixel(p, 1, 0), 255);
  assert_int_equal(pic_pixel(p, 0, 1), 128);            /* 32768 * 255 / 65535 = 127.5.. */
  assert_int_equal(pic_pixel(p, 1, 1), 1);              /* 257 -> exactly 1 */
  pic_free(p);

  const char p1[] = "P2 2 1 1 0 1";                     /* maxval 1, no final newline */
  put_file(path, p1, sizeof p1 - 1);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 0);
  assert_int_equal(pic_pixel(p, 1, 0), 255);
  pic_free(p);
}

static void expect_bad(const char *path, const void *bytes, size_t n)
{
  put_file(path, bytes, n);
  struct pic *p = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(pic_load(path, &p, &err), T74_EINPUT);
  assert_null(p);
  char prefix[320];
  snprintf(prefix, sizeof prefix, "%s: not a PGM/PNG picture: ", path);
  if (strncmp(err.msg, prefix, strlen(prefix)) != 0) fail_msg("message: %s", err.msg);
}

static void test_pgm_rejects(void **state)
{
  const char *path = in_dir(state, "bad.pgm");
#define BAD(s) expect_bad(path, s, sizeof s - 1)
  BAD("hello world");
  BAD("");
  BAD("P5\n2 2\n255\n\x01\x02\x03");          /* truncated raster */
  BAD("P5\n2 2\n65535\n\x01\x02\x03\x04");    /* truncated: 2 of 4 16-bit samples */
  BAD("P2\n2 2\n255\n1 2 3");                 /* truncated plain raster */
  BAD("P5\n2 2\n");                           /* truncated header */
  BAD("P2\n2 1\n10\n5 11\n");                 /* sample above maxval */
  BAD("P2\n2 1\n10\n5 x\n");                  /* not a number */
  BAD("P5\n2 2\n0\n\x00\x00\x00\x00");        /* maxval 0 */
  BAD("P5\n1 1\n70000\n\x00\x00\x00");        /* maxval too large */
  BAD("P5\n0 2\n255\n");                      /* no width */
  BAD("P6\n1 1\n255\n\x00\x00\x00");          /* colour PPM */
  BAD("P5\n1 1\n255\x00");                    /* no white space after maxval */
#undef BAD
  struct pic *p = NULL;
  struct t74_error err = { 0 };
  path = in_dir(state, "missing.pgm");
  assert_int_equal(pic_load(path, &p, &err), T74_EIO);
  assert_null(p);
  assert_non_null(strstr(err.msg, path));
}

/* Write a PNG of w x h with libpng: type/depth as given, rows of raw bytes. */
static void put_png(const char *path, int w, int h, int type, int depth, const uint8_t *raw,
                    size_t rowbytes)
{
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info = png_create_info_struct(png);
  assert_non_null(info);
  if (setjmp(png_jmpbuf(png))) fail_msg("libpng could not write %s", path);
  png_init_io(png, f);
  png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, depth, type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < h; y++) png_write_row(png, raw + rowbytes * (size_t)y);
  png_write_end(png, NULL);
  png_destroy_write_struct(&png, &info);
  assert_int_equal(fclose(f), 0);
}

static void test_png_loader(void **state)
{
  const char *path = in_dir(state, "a.png");
  const uint8_t grey[6] = { 0, 50, 100, 150, 200, 255 };
  put_png(path, 3, 2, PNG_COLOR_TYPE_GRAY, 8, grey, 3);
  struct pic *p = load_ok(path);
  assert_int_equal(pic_width(p), 3);
  assert_int_equal(pic_height(p), 2);
  for (int k = 0; k < 6; k++) assert_int_equal(pic_pixel(p, k % 3, k / 3), grey[k]);
  pic_free(p);

  const uint8_t rgb[12] = { 255, 255, 255,  0, 0, 0,  0, 255, 0,  255, 0, 0 };
  put_png(path, 2, 2, PNG_COLOR_TYPE_RGB, 8, rgb, 6);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 255);
  assert_int_equal(pic_pixel(p, 1, 0), 0);
  int g = pic_pixel(p, 0, 1), r = pic_pixel(p, 1, 1);
  assert_in_range(g, 180, 184);                          /* 0.7152 * 255 = 182.4 */
  assert_in_range(r, 52, 56);                            /* 0.2126 * 255 = 54.2 */
  pic_free(p);

  const uint8_t ga[4] = { 200, 0,  200, 255 };           /* grey + alpha: over black */
  put_png(path, 2, 1, PNG_COLOR_TYPE_GRAY_ALPHA, 8, ga, 4);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 0);
  assert_int_equal(pic_pixel(p, 1, 0), 200);
  pic_free(p);

  const uint8_t g16[4] = { 0xAB, 0xCD, 0x00, 0xFF };     /* 16-bit: the high byte */
  put_png(path, 2, 1, PNG_COLOR_TYPE_GRAY, 16, g16, 4);
  p = load_ok(path);
  assert_int_equal(pic_pixel(p, 0, 0), 0xAB);
  assert_int_equal(pic_pixel(p, 1, 0), 0x00);
  pic_free(p);

  /* truncated PNG: an input error, not a crash */
  static uint8_t big[64 * 64];
  for (size_t k = 0; k < sizeof big; k++) big[k] = (uint8_t)(k * 7 + k / 64);
  put_png(path, 64, 64, PNG_COLOR_TYPE_GRAY, 8, big, 64);
  size_t n;
  uint8_t *whole = get_file(path, &n);
  assert_true(n > 100);
  expect_bad(path, whole, n / 2);
  expect_bad(path, whole, 20);                           /* signature + part of IHDR */
  whole[20] ^= 0x55;                                     /* corrupt the IHDR (bad CRC) */
  expect_bad(path, whole, n);
  free(whole);
}

/* ---- sampling ------------------------------------------------------------------------ */

static void test_box_sampling(void **state)
{
  (void)state;
  const uint8_t px[8] = { 0, 100, 200, 40,
                          10, 20, 30, 50 };
  struct pic *p = pic_new(4, 2, px);
  assert_non_null(p);
  assert_int_equal(pic_sample(p, 0, 0, 2, 1), 33);       /* 130/4 = 32.5: halves up */
  assert_int_equal(pic_sample(p, 1, 0, 2, 1), 80);       /* 320/4 */
  assert_int_equal(pic_sample(p, 0, 0, 1, 1), 56);       /* 450/8 = 56.25 */
  /* a 3 x 2 grid: footprints of 4/3 pixel, weighted by shared area */
  assert_int_equal(pic_sample(p, 0, 0, 3, 2), 25);       /* (0*3 + 100*1) / 4 */
  assert_int_equal(pic_sample(p, 1, 0, 3, 2), 150);      /* (100*2 + 200*2) / 4 */
  assert_int_equal(pic_sample(p, 2, 0, 3, 2), 80);       /* (200*1 + 40*3) / 4 */
  assert_int_equal(pic_sample(p, 2, 1, 3, 2), 45);       /* (30 + 50*3) / 4 */
  /* identity grid: the pixels themselves */
  for (int k = 0; k < 8; k++) assert_int_equal(pic_sample(p, k % 4, k / 4, 4, 2), px[k]);
  /* outside */
  assert_int_equal(pic_sample(p, 3, 0, 3, 2), -1);
  assert_int_equal(pic_sample(p, 0, 0, 0, 2), -1);
  pic_free(p);

  const uint8_t two[2] = { 0, 255 };                     /* magnified 2 -> 3 points */
  p = pic_new(2, 1, two);
  assert_int_equal(pic_sample(p, 0, 0, 3, 5), 0);
  assert_int_equal(pic_sample(p, 1, 0, 3, 5), 128);      /* half of each: 127.5 up */
  assert_int_equal(pic_sample(p, 2, 4, 3, 5), 255);
  pic_free(p);
}

static void test_harbour_background(void **state)
{
  (void)state;
  struct pic *p = load_ok("scenes/harbour.pgm");
  assert_int_equal(pic_width(p), 200);
  assert_int_equal(pic_height(p), 150);
  int lo = 255, hi = 0;                                  /* a picture, not a flat field */
  for (int j = 0; j < pat_grid_h(4); j++)
    for (int i = 0; i < pat_grid_w(4); i++) {
      int g = pic_sample(p, i, j, pat_grid_w(4), pat_grid_h(4));
      assert_in_range(g, 0, 255);
      if (g < lo) lo = g;
      if (g > hi) hi = g;
    }
  assert_true(hi - lo > 150);
  pic_free(p);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test_setup(test_level_monotone_and_ends, test_setup),
    cmocka_unit_test_setup(test_level_exact_values, test_setup),
    cmocka_unit_test_setup(test_families_are_nested, test_setup),
    cmocka_unit_test_setup(test_find, test_setup),
    cmocka_unit_test_setup(test_cell_placement, test_setup),
    cmocka_unit_test_setup(test_emit_partial_and_failure, test_setup),
    cmocka_unit_test_setup(test_tube_once_in_order, test_setup),
    cmocka_unit_test_setup(test_tube_write_dots, test_setup),
    cmocka_unit_test_setup(test_tube_write_dots_full, test_setup),
    cmocka_unit_test_setup(test_tube_write_cells, test_setup),
    cmocka_unit_test_setup(test_tube_write_cells3_rows, test_setup),
    cmocka_unit_test_setup(test_tee, test_setup),
    cmocka_unit_test_setup(test_pbm_bytes, test_setup),
    cmocka_unit_test_setup(test_points_bytes, test_setup),
    cmocka_unit_test_setup(test_pgm_writers_bytes, test_setup),
    cmocka_unit_test_setup(test_png_readback, test_setup),
    cmocka_unit_test_setup(test_outfile_abort_leaves_nothing, test_setup),
    cmocka_unit_test_setup(test_outfile_keeps_existing, test_setup),
    cmocka_unit_test_setup(test_writer_failures, test_setup),
    cmocka_unit_test_setup(test_pgm_loader, test_setup),
    cmocka_unit_test_setup(test_pgm_rejects, test_setup),
    cmocka_unit_test_setup(test_png_loader, test_setup),
    cmocka_unit_test_setup(test_box_sampling, test_setup),
    cmocka_unit_test_setup(test_harbour_background, test_setup),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
