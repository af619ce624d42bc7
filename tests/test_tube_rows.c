/*
** test_tube_rows.c — display/tube's rows of cells over a tube being drawn (issue 19).
**
** tube_write_cells takes a row of cells whose lowest dot is at or past the tube's bound on
** its lit dots (lit_end, raised by every write) as a row over unlit dots: it puts the
** cells' dots into lit[] without asking which are new. These tests draw tubes bottom row
** first, as the pipeline does, with single dots, single cells and rows written between the
** rows (just under a row, in it, just above it, at the tube's last dot), and check that
** every tube keeps the dots, count and order of the same writes made a cell at a time
** (tube_write_dots), and the same status. A bound not raised by one kind of write would
** let a row take a lit dot as new: a dot twice in the order, a count too large.
** A standalone cmocka program.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "display/tube.h"
#include "emu/status.h"

static void tubes_same(const struct tube *a, const struct tube *b)
{
  assert_int_equal(tube_count(a), tube_count(b));
  for (int k = 0; k < tube_count(a); k++) {
    int xa, ya, xb, yb;
    assert_int_equal(tube_order(a, k, &xa, &ya), T74_OK);
    assert_int_equal(tube_order(b, k, &xb, &yb), T74_OK);
    assert_int_equal(xa, xb);
    assert_int_equal(ya, yb);
  }
}

/* tubes_same with one assert for the order (the first dot where it differs, -1 if none):
   for tubes of many dots */
static void orders_same(const struct tube *a, const struct tube *b)
{
  const int n = tube_count(a);
  assert_int_equal(n, tube_count(b));
  int differ = -1;
  for (int k = 0; k < n && differ < 0; k++) {
    int xa, ya, xb, yb;
    if (tube_order(a, k, &xa, &ya) != T74_OK || tube_order(b, k, &xb, &yb) != T74_OK ||
        xa != xb || ya != yb)
      differ = k;
  }
  assert_int_equal(differ, -1);
}

/* A row of n 3x3 cells from (x0, y0), keys[0 .. n) (n <= 133) under tk (made from mask_of),
   to three tubes: a a cell at a time by its mask, b as one keyed row, c as one row of
   masks; the same number of dots lit in each. */
static void write_three(struct tube *a, struct tube *b, struct tube *c, int x0, int y0,
                        const struct tube_keys *tk, const uint8_t *keys,
                        const uint16_t *mask_of, int n)
{
  uint16_t masks[133];
  for (int k = 0; k < n; k++) {
    masks[k] = mask_of[keys[k]];
    assert_int_equal(tube_write_dots(a, x0 + 3 * k, y0, 3, masks[k]), T74_OK);
  }
  assert_int_equal(tube_write_cells_keyed(b, x0, y0, tk, keys, n), T74_OK);
  assert_int_equal(tube_write_cells(c, x0, y0, 3, masks, n), T74_OK);
  assert_int_equal(tube_count(b), tube_count(a));
  assert_int_equal(tube_count(c), tube_count(a));
}

/* b and c hold a's dots, row by row, in a's order */
static void three_same(const struct tube *a, const struct tube *b, const struct tube *c)
{
  for (int y = 0; y < 300; y++) {
    uint8_t ra[TUBE_ROW_BYTES], rb[TUBE_ROW_BYTES], rc[TUBE_ROW_BYTES];
    tube_row_packed(a, y, ra);
    tube_row_packed(b, y, rb);
    tube_row_packed(c, y, rc);
    assert_memory_equal(rb, ra, TUBE_ROW_BYTES);
    assert_memory_equal(rc, ra, TUBE_ROW_BYTES);
  }
  orders_same(a, b);
  orders_same(a, c);
}

static uint32_t next_rand(uint32_t *x)
{
  *x = *x * 1103515245u + 12345u;
  return *x >> 8;
}

/* A row of count cells from (x0, y0) to both tubes: b as one tube_write_cells, a a cell
   at a time; the same status. */
static void row_both(struct tube *a, struct tube *b, int x0, int y0, int cell,
                     const uint16_t *masks, int count)
{
  int want = T74_OK;
  for (int c = 0; c < count && want == T74_OK; c++)
    want = tube_write_dots(a, x0 + c * cell, y0, cell, masks[c]);
  assert_int_equal(tube_write_cells(b, x0, y0, cell, masks, count), want);
}

/* Rows of 3x3 and 4x4 cells drawn bottom row first (the grid's rows), each full row or a
   part of one; before some rows a dot (tube_write), a cell (tube_write_dots) or a short
   row (tube_write_cells) written where the next row goes, just under it, or just over it;
   masks with every dot, none, and some; the same tube as cell by cell, compared after
   every row. */
static void test_rows_bottom_first(void **state)
{
  (void)state;
  uint32_t x = 1974;
  for (int cell = 3; cell <= 4; cell++)
    for (int pass = 0; pass < 12; pass++) {
      struct tube *a = tube_new(), *b = tube_new();
      assert_non_null(a);
      assert_non_null(b);
      const int W = cell == 3 ? 133 : 100, H = cell == 3 ? 100 : 75;
      for (int j = H - 1; j >= 0; j--) {
        const int y0 = (H - 1 - j) * cell + cell - 1;   /* row j's cells' top dot row */
        uint16_t masks[133];
        for (int c = 0; c < W; c++) {
          const uint32_t r = next_rand(&x);
          const unsigned full = (1u << (cell * cell)) - 1;
          masks[c] = (uint16_t)((pass % 3 == 0 && c % 11 < 4) ? 0
                                : (pass % 3 == 1) ? full : r & full);
        }
        /* something written before the row, now and then */
        const uint32_t what = next_rand(&x) % 8;
        const int wx = (int)(next_rand(&x) % (uint32_t)(W * cell));
        const int wy = y0 - (int)(next_rand(&x) % (uint32_t)(cell + 2)) + 1;   /* under .. over */
        if (wy >= 0 && wy < 300) {
          if (what == 1) {
            assert_int_equal(tube_write(a, wx, wy), T74_OK);
            assert_int_equal(tube_write(b, wx, wy), T74_OK);
          } else if (what == 2 && wx <= 400 - cell && wy >= cell - 1) {
            const unsigned m = next_rand(&x) & ((1u << (cell * cell)) - 1);
            assert_int_equal(tube_write_dots(a, wx, wy, cell, m), T74_OK);
            assert_int_equal(tube_write_dots(b, wx, wy, cell, m), T74_OK);
          } else if (what == 3 && wy >= cell - 1) {
            const int x1 = cell * (wx / cell), n = (400 - x1) / cell < 5 ? (400 - x1) / cell : 5;
            row_both(a, b, x1, wy, cell, masks, n);
          }
        }
        if (pass >= 6) {                    /* a part of the row, from a cell not the first */
          const int c0 = (int)(next_rand(&x) % (uint32_t)W);
          row_both(a, b, c0 * cell, y0, cell, masks + c0, W - c0);
        } else {
          row_both(a, b, 0, y0, cell, masks, W);
        }
        assert_int_equal(tube_count(a), tube_count(b));
      }
      /* and the tube's last dot, lit before a row written over it */
      assert_int_equal(tube_write(a, 399, 299), T74_OK);
      assert_int_equal(tube_write(b, 399, 299), T74_OK);
      uint16_t top[2] = { (uint16_t)((1u << (cell * cell)) - 1), 1 };
      row_both(a, b, 400 - 2 * cell, 299, cell, top, 2);
      tubes_same(a, b);
      tube_free(a);
      tube_free(b);
    }
}

/* After tube_erase the bound starts again: rows drawn on an erased tube, bottom row
   first, over what was lit before the erase, keep the dots and order of a new tube. */
static void test_rows_after_erase(void **state)
{
  (void)state;
  struct tube *a = tube_new(), *b = tube_new();
  assert_non_null(a);
  assert_non_null(b);
  uint16_t masks[133];
  for (int c = 0; c < 133; c++) masks[c] = (uint16_t)(c % 5 ? 0x1ffu : 0x0a5u);
  for (int y0 = 2; y0 < 300; y0 += 3) row_both(a, b, 0, y0, 3, masks, 133);
  tubes_same(a, b);
  tube_erase(b);
  struct tube *c = tube_new();
  assert_non_null(c);
  for (int y0 = 2; y0 < 300; y0 += 3) {
    assert_int_equal(tube_write_cells(b, 0, y0, 3, masks, 133), T74_OK);
    for (int k = 0; k < 133; k++) assert_int_equal(tube_write_dots(c, 3 * k, y0, 3, masks[k]), T74_OK);
  }
  tubes_same(b, c);
  assert_int_equal(tube_count(b), tube_count(a));
  tube_free(a);
  tube_free(b);
  tube_free(c);
}

/* A row of cells written over unlit dots is one write that keeps no masks: its cells' new
   dots are read back from lit[] when the order is spelled out, after the later writes'
   own new dots are taken out. Here rows of 3x3 and 4x4 cells with gaps (cells of no dot,
   cells with some dots) are written bottom row first, and after each row single dots,
   cells and a short row are written into the gaps of the rows already drawn (new dots
   inside an earlier row's cells, and some lit already); the order is read now and then
   between writes (spelled out, then written on). The same dots, count and order as a
   cell at a time. */
static void test_rows_then_gaps(void **state)
{
  (void)state;
  uint32_t x = 74;
  for (int cell = 3; cell <= 4; cell++) {
    struct tube *a = tube_new(), *b = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    const int W = cell == 3 ? 133 : 100, H = cell == 3 ? 100 : 75;
    const unsigned full = (1u << (cell * cell)) - 1;
    for (int j = H - 1; j >= 0; j--) {
      const int y0 = (H - 1 - j) * cell + cell - 1;
      uint16_t masks[133];
      for (int c = 0; c < W; c++)
        masks[c] = (uint16_t)(c % 3 == 0 ? 0 : next_rand(&x) & full);
      row_both(a, b, 0, y0, cell, masks, W);
      for (int k = 0; k < 6; k++) {         /* into the rows drawn: gaps and lit dots */
        const int wx = (int)(next_rand(&x) % 400), wy = (int)(next_rand(&x) % (unsigned)(y0 + 1));
        assert_int_equal(tube_write(a, wx, wy), T74_OK);
        assert_int_equal(tube_write(b, wx, wy), T74_OK);
      }
      const int cx = cell * (int)(next_rand(&x) % (unsigned)(W - 4));
      const int cy = y0 - cell * (int)(next_rand(&x) % (unsigned)(H - j));
      const unsigned m = next_rand(&x) & full;
      assert_int_equal(tube_write_dots(a, cx, cy, cell, m), T74_OK);
      assert_int_equal(tube_write_dots(b, cx, cy, cell, m), T74_OK);
      row_both(a, b, cx, cy, cell, masks + 1, 4);   /* over lit dots: not a run */
      assert_int_equal(tube_count(a), tube_count(b));
      if (j % 17 == 5) tubes_same(a, b);    /* spelled out, then written on */
    }
    tubes_same(a, b);
    for (int y = 0; y < 300; y++)
      for (int xx = 0; xx < 400; xx++) assert_int_equal(tube_lit(a, xx, y), tube_lit(b, xx, y));
    tube_free(a);
    tube_free(b);
  }
}

/* tube_erase clears the dots below the tube's bound on its lit dots (lit_end), which every
   write raises: dots lit anywhere, the tube's first and last ones too, by single dots,
   cells and rows, are all unlit after it, in lit[] (tube_lit, the packed rows) and in the
   count, and a tube drawn after it is a new tube's. */
static void test_erase_clears(void **state)
{
  (void)state;
  uint32_t x = 19;
  struct tube *t = tube_new();
  assert_non_null(t);
  for (int round = 0; round < 6; round++) {
    const int top = round % 2 ? 299 : 40 + 40 * round;   /* the highest row written */
    assert_int_equal(tube_write(t, 0, 0), T74_OK);
    assert_int_equal(tube_write(t, 399, top), T74_OK);
    for (int k = 0; k < 50; k++) {
      const int wx = (int)(next_rand(&x) % 400), wy = (int)(next_rand(&x) % (unsigned)(top + 1));
      assert_int_equal(tube_write(t, wx, wy), T74_OK);
    }
    uint16_t masks[100];
    for (int c = 0; c < 100; c++) masks[c] = (uint16_t)next_rand(&x);
    assert_int_equal(tube_write_cells(t, 0, top, 4, masks, 100), T74_OK);
    assert_int_equal(tube_write_dots(t, 396, top, 4, 0xffffu), T74_OK);
    assert_true(tube_count(t) > 100);
    tube_erase(t);
    assert_int_equal(tube_count(t), 0);
    for (int y = 0; y < 300; y++) {
      uint8_t row[TUBE_ROW_BYTES];
      tube_row_packed(t, y, row);
      for (int k = 0; k < TUBE_ROW_BYTES; k++) assert_int_equal(row[k], 0);
      for (int xx = 0; xx < 400; xx++) assert_int_equal(tube_lit(t, xx, y), 0);
    }
  }
  struct tube *n = tube_new();               /* drawn after the erase: a new tube's */
  assert_non_null(n);
  uint16_t masks[133];
  for (int c = 0; c < 133; c++) masks[c] = (uint16_t)(next_rand(&x) & 0x1ffu);
  for (int y0 = 2; y0 < 300; y0 += 3) row_both(n, t, 0, y0, 3, masks, 133);
  tubes_same(n, t);
  tube_free(n);
  tube_free(t);
}

/* tube_write_cells_keyed stores exactly what tube_write_cells of the keys' masks would:
   rows of 3x3 cells drawn bottom row first (the fused run over unlit rows), parts of rows
   (counts not a multiple of seven), rows over lit dots and partly off the tube, tables
   with masks past the cell, 4x4 cells, keys of no dot; the same status, dots and order. */
static void test_rows_keyed(void **state)
{
  (void)state;
  uint32_t x = 1919;
  for (int pass = 0; pass < 8; pass++) {
    const int cell = pass == 7 ? 4 : 3;
    const unsigned full = (1u << (cell * cell)) - 1;
    uint16_t mask_of[256];
    for (int k = 0; k < 256; k++)
      mask_of[k] = (uint16_t)(k % 5 == 0 ? 0 : (pass == 6 && k == 77) ? 0x3ffu
                              : next_rand(&x) & full);
    struct tube_keys tk;
    tube_keys_init(&tk, cell, mask_of);
    struct tube *a = tube_new(), *b = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    const int W = cell == 3 ? 133 : 100, H = cell == 3 ? 100 : 75;
    for (int j = H - 1; j >= 0; j--) {
      const int y0 = (H - 1 - j) * cell + cell - 1;
      uint8_t keys[140];
      uint16_t masks[140];
      const int n = pass % 3 == 1 ? 1 + (int)(next_rand(&x) % (uint32_t)W) : W;
      const int x0 = cell * (W - n) * (pass % 2);
      for (int c = 0; c < n; c++) {
        keys[c] = (uint8_t)(pass == 2 && j % 4 == 0 ? 5u * (uint32_t)(c % 3) : next_rand(&x));
        masks[c] = mask_of[keys[c]];
      }
      if (pass >= 4 && j % 3 == 0) {        /* a dot lit where the row goes */
        const int wx = (int)(next_rand(&x) % 400), wy = y0 - (int)(next_rand(&x) % (uint32_t)cell);
        assert_int_equal(tube_write(a, wx, wy), T74_OK);
        assert_int_equal(tube_write(b, wx, wy), T74_OK);
      }
      assert_int_equal(tube_write_cells_keyed(b, x0, y0, &tk, keys, n),
                       tube_write_cells(a, x0, y0, cell, masks, n));
      assert_int_equal(tube_count(a), tube_count(b));
    }
    uint8_t keys[140];                      /* partly off the tube: the same first failure */
    uint16_t masks[140];
    for (int c = 0; c < 140; c++) masks[c] = mask_of[keys[c] = (uint8_t)(1 + c)];
    assert_int_equal(tube_write_cells_keyed(b, 390, 299, &tk, keys, 140),
                     tube_write_cells(a, 390, 299, cell, masks, 140));
    tubes_same(a, b);
    tube_free(a);
    tube_free(b);
  }
}

/* Rows of 4x4 cells written again over a row already written as a run (tube_write_cells
   takes a row of 4x4 cells as a run wherever the bytes under it are unlit, blank_cells),
   where that run's cells had no dot: a later run over an earlier run's empty cells, a run
   over those of two earlier ones, and rows over lit dots between. settle spells a run's
   dots from lit[] with the later writes' dots taken out, so each of the later runs' dots
   must be taken out before an earlier run that covers the same cells is reached: the same
   dots, count and order as cell by cell. */
static void test_runs_over_runs(void **state)
{
  (void)state;
  uint32_t x = 2024;
  for (int trial = 0; trial < 200; trial++) {
    struct tube *a = tube_new(), *b = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    const int y0 = 3 + (int)(next_rand(&x) % 290u);
    for (int k = 0; k < 6; k++) {
      /* a row of up to 100 cells from an even cell, its cells empty in blocks */
      const int c0 = 2 * (int)(next_rand(&x) % 40u), n = 1 + (int)(next_rand(&x) % (uint32_t)(100 - c0));
      const int z0 = (int)(next_rand(&x) % 100u), z1 = z0 + (int)(next_rand(&x) % 60u);
      uint16_t masks[100];
      for (int c = 0; c < n; c++) {
        const int at = c0 + c;
        masks[c] = (uint16_t)(at >= z0 && at < z1 && k < 5 ? 0 : next_rand(&x) & 0xffffu);
        if (masks[c] && next_rand(&x) % 4u == 0) masks[c] = 0;
      }
      row_both(a, b, 4 * c0, y0, 4, masks, n);
      if (k == 3 && trial % 3 == 0) {       /* a dot lit on the row: later rows over it */
        const int wx = (int)(next_rand(&x) % 400u), wy = y0 - (int)(next_rand(&x) % 4u);
        assert_int_equal(tube_write(a, wx, wy), T74_OK);
        assert_int_equal(tube_write(b, wx, wy), T74_OK);
      }
      assert_int_equal(tube_count(a), tube_count(b));
    }
    tubes_same(a, b);
    tube_free(a);
    tube_free(b);
  }
}

/* tube_write_cells_keyed of 4x4 cells stores exactly what tube_write_cells of the keys'
   masks would: rows drawn bottom row first (the fused path over unlit rows: sixteen cells
   by vectors, the rest two by two), from a byte's start and not, whole rows and parts
   (an odd count: a lone last cell), sixteen keys alike of a dot and of none, keys of no
   dot, a dot lit where the next row goes (then the cells one by one); the same status,
   dots and order. */
static void test_rows_keyed4(void **state)
{
  (void)state;
  uint32_t x = 2718;
  for (int pass = 0; pass < 6; pass++) {
    uint16_t mask_of[256];
    for (int k = 0; k < 256; k++)
      mask_of[k] = (uint16_t)(k % 7 == 0 ? 0 : k == 3 ? 0xffffu : next_rand(&x) & 0xffffu);
    struct tube_keys tk;
    tube_keys_init(&tk, 4, mask_of);
    struct tube *a = tube_new(), *b = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    for (int j = 74; j >= 0; j--) {
      const int y0 = (74 - j) * 4 + 3;
      uint8_t keys[100];
      uint16_t masks[100];
      const int n = pass % 2 ? 1 + (int)(next_rand(&x) % 100u) : 100;
      const int x0 = pass >= 2 ? 4 * (int)(next_rand(&x) % (uint32_t)(101 - n)) : 0;
      for (int c = 0; c < n; c++) {
        const uint32_t r = next_rand(&x);
        /* runs of one key (sixteen alike, of a dot or of none), else keys at random */
        keys[c] = (uint8_t)(j % 3 == 0 ? (c / 20 % 2 ? 7u : 3u) : j % 3 == 1 ? r % 6 : r);
        masks[c] = mask_of[keys[c]];
      }
      if (pass >= 4 && j % 5 == 0) {        /* a dot lit where the row goes */
        const int wx = (int)(next_rand(&x) % 400), wy = y0 - (int)(next_rand(&x) % 4u);
        assert_int_equal(tube_write(a, wx, wy), T74_OK);
        assert_int_equal(tube_write(b, wx, wy), T74_OK);
      }
      assert_int_equal(tube_write_cells_keyed(b, x0, y0, &tk, keys, n),
                       tube_write_cells(a, x0, y0, 4, masks, n));
      assert_int_equal(tube_count(a), tube_count(b));
    }
    tubes_same(a, b);
    tube_free(a);
    tube_free(b);
  }
}

/* The 3x3 rows over unlit rows (tube_write_cells_keyed's and tube_write_cells' run) store
   each row of the cells as whole aligned 64-bit words of lit[], reading only the row's
   first word: the dots below the row's first dot in that word are kept, the words after
   it are stored whole. Here rows of 3x3 cells are drawn bottom row first, each three
   ways: a cell at a time (tube_write_dots, a), by keys (b) and by masks (c). The rows
   start anywhere in a word (x0 0 .. 399, rows 3 or 4 apart), most end at the tube's
   right edge (x0 = 400 - 3 * count: the bottom row's last word is the next row's first
   when the next row starts within it, and a row's first word may hold the last dots of
   the row written before), some on the tube's last row (y0 299: its last dot is the
   last of lit[]); before many rows dots are lit just left of the row in its bottom row
   (in its first word); some rows have no dot, every dot, one key or runs of one key (seven
   cells of one key are taken at once). A word stored over dots it
   should have kept loses them: the packed rows, the count and the order would differ. */
static void test_rows_keyed_words(void **state)
{
  (void)state;
  uint32_t x = 4019;
  uint16_t mask_of[256];
  for (int k = 0; k < 256; k++)
    mask_of[k] = (uint16_t)(k % 9 == 0 ? 0 : k == 1 ? 0x1ffu : next_rand(&x) & 0x1ffu);
  struct tube_keys tk;
  tube_keys_init(&tk, 3, mask_of);
  for (int pass = 0; pass < 48; pass++) {
    struct tube *a = tube_new(), *b = tube_new(), *c = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(c);
    /* every 3 rows from y0 2 to the tube's last row, or 3 or 4 apart, or the last row alone */
    const int y1 = pass % 6 == 5 ? 299 : 2 + (pass % 3 == 2 ? (int)(next_rand(&x) % 3u) : 0);
    for (int y0 = y1; y0 < 300; y0 += pass % 3 == 2 ? 3 + (int)(next_rand(&x) % 2u) : 3) {
      const uint32_t how = next_rand(&x) % 8u;
      const int n = how == 7 ? 133 : 1 + (int)(next_rand(&x) % 133u);
      const int x0 = how < 5 ? 400 - 3 * n : (int)(next_rand(&x) % (uint32_t)(401 - 3 * n));
      if (next_rand(&x) % 3u) {             /* dots lit just left of the row, bottom row */
        const int k1 = (int)(next_rand(&x) % 12u);
        for (int k = 1; k <= k1 && k <= x0; k++)
          if (next_rand(&x) % 3u) {
            assert_int_equal(tube_write(a, x0 - k, y0 - 2), T74_OK);
            assert_int_equal(tube_write(b, x0 - k, y0 - 2), T74_OK);
            assert_int_equal(tube_write(c, x0 - k, y0 - 2), T74_OK);
          }
      }
      uint8_t keys[133];
      /* 0: no dot, 1: every dot, 2: one key, 3: runs of one key, else any */
      const uint32_t fill = next_rand(&x) % 7u, one = next_rand(&x) % 256u;
      for (int k = 0; k < n; k++) {
        keys[k] = (uint8_t)(fill == 0 ? 9u * (next_rand(&x) % 4u) : fill == 1 ? 1u
                            : fill == 2 ? one : fill == 3 ? one + (uint32_t)k / 9u
                            : next_rand(&x));
      }
      write_three(a, b, c, x0, y0, &tk, keys, mask_of, n);
    }
    three_same(a, b, c);
    tube_free(a);
    tube_free(b);
    tube_free(c);
  }
}

/* Rows of 3x3 cells by keys over unlit rows whose keys are all one key of no dot but at
   most one (tube_write_cells_keyed takes a row of one key of no dot as blank: nothing
   stored, sixteen keys a compare, the last sixteen possibly overlapping): the other key
   at every place of rows of 1 to 133 cells (the first, at and around multiples of
   sixteen, in the last sixteen), and rows of no other; each row also a cell at a time
   (tube_write_dots). A row taken as blank when one key has dots loses that key's dots:
   the count, the packed rows and the order would differ. */
static void test_rows_keyed_blank(void **state)
{
  (void)state;
  uint16_t mask_of[256];
  for (int k = 0; k < 256; k++)                 /* (within the cell: 1 .. 0x1ff) */
    mask_of[k] = (uint16_t)(k == 0 || k == 200 ? 0 : 1 + (37 * k) % 511);
  struct tube_keys tk;
  tube_keys_init(&tk, 3, mask_of);
  const int counts[] = { 1, 15, 16, 17, 31, 32, 33, 47, 100, 112, 128, 132, 133 };
  for (int ci = 0; ci < (int)(sizeof counts / sizeof *counts); ci++) {
    const int n = counts[ci];
    for (int blank = 0; blank < 256; blank += 200) {  /* keys 0 and 200: no dot */
      struct tube *a = tube_new(), *b = tube_new();
      assert_non_null(a);
      assert_non_null(b);
      int y0 = 2;
      for (int at = -1; at < n; at++, y0 += 3) {      /* -1: no other key */
        if (y0 >= 300) {                              /* (a fresh pair of tubes) */
          tube_free(a);
          tube_free(b);
          a = tube_new();
          b = tube_new();
          assert_non_null(a);
          assert_non_null(b);
          y0 = 2;
        }
        const int x0 = 400 - 3 * n - (3 * n + 3 <= 400 ? at & 3 : 0);   /* (on the tube) */
        uint8_t keys[133];
        for (int k = 0; k < n; k++) {
          keys[k] = (uint8_t)(k == at ? 1 + (at % 199) : blank);
          assert_int_equal(tube_write_dots(a, x0 + 3 * k, y0, 3, mask_of[keys[k]]), T74_OK);
        }
        assert_int_equal(tube_write_cells_keyed(b, x0, y0, &tk, keys, n), T74_OK);
        assert_int_equal(tube_count(b), tube_count(a));
      }
      for (int y = 0; y < 300; y++) {
        uint8_t ra[TUBE_ROW_BYTES], rb[TUBE_ROW_BYTES];
        tube_row_packed(a, y, ra);
        tube_row_packed(b, y, rb);
        assert_memory_equal(rb, ra, TUBE_ROW_BYTES);
      }
      orders_same(a, b);
      tube_free(a);
      tube_free(b);
    }
  }
}

/* The 3x3 rows over unlit rows store only the groups of 21 cells (63 dots a row) from the
   first with a dot to the last with one: the groups before and after hold unlit dots, 0
   in lit[] already. Here rows of 1 to 133 cells by keys over unlit rows (bottom row
   first, 3 rows apart, from any column or ending at the right edge) whose cells have no
   dot (keys of no dot) but in some groups: one cell with a dot at the first or last place
   of a group, whole groups of dots, two groups with blank groups between, the row's last
   group (cut short by the count) alone, no group; dots lit just left of the row in its
   bottom row; each row also a cell at a time (tube_write_dots, a) and by masks
   (tube_write_cells, c). A group with a dot left out, or the groups stored from the wrong
   place, loses dots or lights others: the count, the packed rows and the order differ. */
static void test_rows_keyed_groups(void **state)
{
  (void)state;
  uint32_t x = 5077;
  uint16_t mask_of[256];
  for (int k = 0; k < 256; k++)
    mask_of[k] = (uint16_t)(k % 4 == 0 ? 0 : 1 + next_rand(&x) % 511u);
  struct tube_keys tk;
  tube_keys_init(&tk, 3, mask_of);
  long rows = 0, dots = 0;
  for (int pass = 0; pass < 24; pass++) {
    struct tube *a = tube_new(), *b = tube_new(), *c = tube_new();
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(c);
    for (int y0 = 2 + pass % 3; y0 < 300; y0 += 3) {
      const int n = pass % 4 == 0 ? 133 : 1 + (int)(next_rand(&x) % 133u);
      const int x0 = pass % 2 ? 400 - 3 * n : (int)(next_rand(&x) % (uint32_t)(401 - 3 * n));
      if (next_rand(&x) % 2u && x0 > 0) {   /* a dot lit just left of the row, bottom row */
        assert_int_equal(tube_write(a, x0 - 1, y0 - 2), T74_OK);
        assert_int_equal(tube_write(b, x0 - 1, y0 - 2), T74_OK);
        assert_int_equal(tube_write(c, x0 - 1, y0 - 2), T74_OK);
      }
      const int ng = (n + 20) / 21;
      const uint32_t how = next_rand(&x) % 6u;
      const int g = (int)(next_rand(&x) % (uint32_t)ng), h = (int)(next_rand(&x) % (uint32_t)ng);
      uint8_t keys[133];
      for (int k = 0; k < n; k++) {
        const int gk = k / 21, at = k % 21, last = k == n - 1 || at == 20;
        const bool dot =
          how == 0 ? gk == g && at == 0                 /* a group's first cell */
          : how == 1 ? gk == g && last                  /* its last */
          : how == 2 ? gk == g                          /* a whole group */
          : how == 3 ? (gk == g || gk == h) && next_rand(&x) % 3u == 0   /* two groups */
          : how == 4 ? gk == ng - 1 && last             /* the row's last cell */
          : false;                                      /* no dot */
        keys[k] = (uint8_t)(dot ? 1u + 4u * (next_rand(&x) % 63u) + next_rand(&x) % 3u
                                : 4u * (next_rand(&x) % 64u));
      }
      write_three(a, b, c, x0, y0, &tk, keys, mask_of, n);
      rows++;
    }
    three_same(a, b, c);
    dots += tube_count(a);
    tube_free(a);
    tube_free(b);
    tube_free(c);
  }
  print_message("rows keyed by groups: %ld rows, %ld dots\n", rows, dots);
  assert_true(dots > 1000);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_rows_bottom_first),
    cmocka_unit_test(test_rows_after_erase),
    cmocka_unit_test(test_rows_then_gaps),
    cmocka_unit_test(test_erase_clears),
    cmocka_unit_test(test_rows_keyed),
    cmocka_unit_test(test_runs_over_runs),
    cmocka_unit_test(test_rows_keyed4),
    cmocka_unit_test(test_rows_keyed_words),
    cmocka_unit_test(test_rows_keyed_blank),
    cmocka_unit_test(test_rows_keyed_groups),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
