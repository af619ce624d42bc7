/*
** test_emu.c — unit tests of the machine model: core (emu/core.h), cost model
** (emu/cost.h), parameter table (emu/params.c) and instruction format (emu/hitac10.h).
** Where described: emu/core.h, emu/cost.h; CONTRACT.md (exit status 3 message).
**
** This file contains code to check the machine model against hand computations: the
** low region is a stack and the high region meets it exactly at the boundary; "does not
** fit" is T74_ECORE with the words needed and available; the Priority Matrix's 2-bit
** fields do not disturb their neighbours; multi-word integers round-trip; the cost of
** known counts equals the sum worked out from the table's rows.  Standalone cmocka
** program.
*/
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emu/core.h"
#include "emu/grow.h"
#include "emu/cost.h"
#include "emu/param.h"
#include "emu/hitac10.h"

/* ---------------------------------------------------------------- core: low region */

static void test_new_bounds(void **state)
{
  (void)state;
  assert_null(core_new(0));
  struct core *c = core_new(1);
  assert_non_null(c);
  assert_int_equal(core_words(c), 1);
  assert_int_equal(core_read(c, 0), 0);
  core_free(c);
  c = core_new(H10_CORE_PAPER);
  assert_non_null(c);
  for (uint32_t a = 0; a < H10_CORE_PAPER; a++) assert_int_equal(core_read(c, a), 0);
  assert_int_equal(core_used(c), 0);
  core_free(c);
}

static void test_alloc_release_stack(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(1000);
  uint32_t a, b, d, e;
  assert_int_equal(core_alloc(c, CORE_T_VERTICES, 10, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, CORE_T_FACES, 20, &b, &err), T74_OK);
  assert_int_equal(a, 0);
  assert_int_equal(b, 10);
  uint32_t m = core_mark(c);
  assert_int_equal(m, 30);
  assert_int_equal(core_alloc(c, CORE_T_PBS, 5, &d, &err), T74_OK);
  assert_int_equal(d, 30);
  core_write(c, d, 0xBEEF);
  assert_int_equal(core_alloc(c, CORE_T_IPL, 7, &e, &err), T74_OK);
  assert_int_equal(e, 35);
  assert_int_equal(core_used(c), 42);
  core_release(c, m);                                    /* PBS and IPL go */
  assert_int_equal(core_mark(c), 30);
  assert_int_equal(core_used(c), 30);
  assert_int_equal(core_alloc(c, CORE_T_LWS, 3, &d, &err), T74_OK);
  assert_int_equal(d, 30);                               /* same place again ... */
  assert_int_equal(core_read(c, d), 0);                  /* ... and zeroed */
  core_release(c, 0);
  assert_int_equal(core_used(c), 0);
  assert_int_equal(core_peak(c), 42);
  assert_int_equal(err.status, T74_OK);
  core_release(c, 500);                                  /* above the top: nothing */
  assert_int_equal(core_mark(c), 0);
  core_free(c);
}

static void test_fill_exactly(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(100);
  uint32_t a;
  assert_int_equal(core_alloc(c, "XSORT", 100, &a, &err), T74_OK);
  assert_int_equal(core_used(c), 100);
  assert_int_equal(core_alloc(c, "IPL", 1, &a, &err), T74_ECORE);
  assert_int_equal(err.status, T74_ECORE);
  assert_string_equal(err.msg, "scene does not fit the core: needs 101 words, 100 available "
                               "(table IPL could not take 1 words)");
  assert_int_equal(core_used(c), 100);                   /* nothing allocated */
  assert_int_equal(core_mark(c), 100);
  /* zero words fit even in a full core */
  struct t74_error e2 = { 0 };
  assert_int_equal(core_alloc(c, "EMPTY", 0, &a, &e2), T74_OK);
  assert_int_equal(a, 100);
  /* huge requests do not overflow the arithmetic of the message */
  struct t74_error e3 = { 0 };
  assert_int_equal(core_alloc(c, "HUGE", UINT32_MAX, &a, &e3), T74_ECORE);
  assert_non_null(strstr(e3.msg, "needs 4294967395 words, 100 available"));
  core_free(c);
}

/* ---------------------------------------------------------------- core: high region */

static void test_high_keeps_contents(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(64);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 4, &err), T74_OK);
  for (uint32_t k = 0; k < 4; k++) core_high_set(c, k, (uint16_t)(0x1000 + k));
  for (uint32_t k = 0; k < 4; k++) assert_int_equal(core_read(c, 63 - k), 0x1000 + k);
  /* a stale word where the region will grow to is cleared on growth */
  core_write(c, 64 - 6, 0xDEAD);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 10, &err), T74_OK);
  assert_int_equal(core_high_words(c), 10);
  for (uint32_t k = 0; k < 4; k++) assert_int_equal(core_high_get(c, k), 0x1000 + k);
  for (uint32_t k = 4; k < 10; k++) assert_int_equal(core_high_get(c, k), 0);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 3, &err), T74_OK);  /* no shrink */
  assert_int_equal(core_high_words(c), 10);
  core_high_free(c);
  assert_int_equal(core_high_words(c), 0);
  assert_int_equal(core_used(c), 0);
  assert_int_equal(err.status, T74_OK);
  core_free(c);
}

/* core_high_top_w: word k of the high region at p[-k], written through it and read back
   by core_high_get and core_read (the word at address size - 1 - k), as core_high_top
   reads it; a word beyond those written stays as it was. */
static void test_high_top_write(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(64);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 8, &err), T74_OK);
  uint16_t *w = core_high_top_w(c);
  assert_ptr_equal(w, core_high_top(c));
  const uint16_t four[4] = { 0x1111, 0x2222, 0x3333, 0x4444 };
  memcpy(w - 4 - 3, four, sizeof four);               /* words 7, 6, 5, 4 (a slot's) */
  assert_int_equal(core_high_get(c, 7), 0x1111);
  assert_int_equal(core_high_get(c, 6), 0x2222);
  assert_int_equal(core_high_get(c, 5), 0x3333);
  assert_int_equal(core_high_get(c, 4), 0x4444);
  assert_int_equal(core_read(c, 63 - 4), 0x4444);
  assert_int_equal(core_high_get(c, 3), 0);
  w[0] = 0xBEEF;
  assert_int_equal(core_read(c, 63), 0xBEEF);
  assert_int_equal(core_high_top(c)[-5], 0x3333);
  core_free(c);
}

static void test_high_meets_low(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(64);
  uint32_t a;
  assert_int_equal(core_alloc(c, "LOW", 40, &a, &err), T74_OK);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 24, &err), T74_OK);
  assert_int_equal(core_used(c), 64);                    /* exactly meet */
  core_high_set(c, 23, 0x5555);
  assert_int_equal(core_read(c, 40), 0x5555);            /* the lowest high word */
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 25, &err), T74_ECORE);
  assert_string_equal(err.msg, "scene does not fit the core: needs 65 words, 64 available "
                               "(table PRIORITY MATRIX could not grow by 1 words)");
  assert_int_equal(core_high_words(c), 24);
  struct t74_error e2 = { 0 };
  assert_int_equal(core_alloc(c, "LOW2", 1, &a, &e2), T74_ECORE);  /* low cannot pass */
  core_release(c, 39);
  struct t74_error e3 = { 0 };
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 25, &e3), T74_OK);
  assert_int_equal(core_high_get(c, 23), 0x5555);
  assert_int_equal(core_high_get(c, 24), 0);
  assert_int_equal(core_used(c), 64);
  core_free(c);
}

static void test_contract_message(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(H10_CORE_PAPER);
  uint32_t a;
  assert_int_equal(core_alloc(c, "FACE DATA", 16373, &a, &err), T74_OK);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 12, &err), T74_ECORE);
  assert_int_equal(err.status, 3);
  assert_string_equal(err.msg, "scene does not fit the core: needs 16385 words, 16384 available "
                               "(table PRIORITY MATRIX could not grow by 12 words)");
  core_free(c);
}

static void test_2bit_fields(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(32);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 3, &err), T74_OK);
  for (uint64_t i = 8; i < 16; i++)                     /* word 1: every position */
    for (unsigned v = 0; v < 4; v++) {
      for (uint64_t j = 0; j < 24; j++) core_high_set2(c, j, (unsigned)((j * 7 + 1) % 4));
      core_high_set2(c, i, v);
      assert_int_equal(core_high_get2(c, i), v);
      for (uint64_t j = 0; j < 24; j++)
        if (j != i) assert_int_equal(core_high_get2(c, j), (j * 7 + 1) % 4);
      /* the layout: field i in word i/8, bits 2*(i%8)..+1 (8 pairs a word, Fig. 9) */
      uint16_t w = core_high_get(c, 1);
      assert_int_equal((w >> (2 * (i % 8))) & 3u, v);
    }
  /* all ones then clear one field */
  for (uint64_t j = 0; j < 24; j++) core_high_set2(c, j, 3);
  assert_int_equal(core_high_get(c, 0), 0xFFFF);
  assert_int_equal(core_high_get(c, 2), 0xFFFF);
  core_high_set2(c, 17, 0);
  assert_int_equal(core_high_get(c, 2), 0xFFF3);
  core_high_set2(c, 19, 2);
  assert_int_equal(core_high_get(c, 2), 0xFFB3);
  core_free(c);
}

/* ---------------------------------------------------------------- multi-word integers */

static void test_multiword_int(void **state)
{
  (void)state;
  struct core *c = core_new(64);
  core_put_int(c, 0, 2, 0x12345678);
  assert_int_equal(core_read(c, 0), 0x1234);             /* most significant first */
  assert_int_equal(core_read(c, 1), 0x5678);
  assert_int_equal(core_get_int(c, 0, 2), 0x12345678);
  static const struct { int n; int64_t v; } cases[] = {
    { 1, 0 }, { 1, 1 }, { 1, -1 }, { 1, INT16_MAX }, { 1, INT16_MIN },
    { 2, -32769 }, { 2, INT32_MIN }, { 2, INT32_MAX }, { 2, -1 },
    { 3, -((int64_t)1 << 47) }, { 3, ((int64_t)1 << 47) - 1 }, { 3, -123456789012LL },
    { 4, INT64_MIN }, { 4, INT64_MAX }, { 4, -1 }, { 4, 0x0123456789ABCDEFLL },
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    core_put_int(c, 10, cases[i].n, cases[i].v);
    assert_true(core_get_int(c, 10, cases[i].n) == cases[i].v);
  }
  core_put_int(c, 20, 1, -2);
  assert_int_equal(core_read(c, 20), 0xFFFE);
  core_put_int(c, 20, 1, 0x12345);                       /* low 16 bits kept */
  assert_int_equal(core_get_int(c, 20, 1), 0x2345);
  core_put_int(c, 20, 4, -2);
  assert_int_equal(core_read(c, 20), 0xFFFF);
  assert_int_equal(core_read(c, 23), 0xFFFE);
  core_free(c);
}

static void test_multiword_wide(void **state)
{
  (void)state;
  struct core *c = core_new(64);
  core_wide one = 1;
  core_wide max = (core_wide)(((core_uwide)1 << 127) - 1);
  core_wide min = -max - 1;
  core_wide cases8[] = { 0, 1, -1, max, min, -(one << 100) - 7, (one << 90) + 12345,
                         (core_wide)INT64_MIN * 3 };
  for (size_t i = 0; i < sizeof cases8 / sizeof cases8[0]; i++) {
    core_put_wide(c, 5, 8, cases8[i]);
    assert_true(core_get_wide(c, 5, 8) == cases8[i]);
  }
  core_put_wide(c, 5, 8, min);
  assert_int_equal(core_read(c, 5), 0x8000);
  for (int k = 1; k < 8; k++) assert_int_equal(core_read(c, 5 + (uint32_t)k), 0);
  /* 5 words (80 bits), negative and positive */
  core_wide v80 = -(one << 70) + 99;
  core_put_wide(c, 30, 5, v80);
  assert_true(core_get_wide(c, 30, 5) == v80);
  core_put_wide(c, 30, 5, (one << 79) - 1);
  assert_true(core_get_wide(c, 30, 5) == (one << 79) - 1);
  assert_int_equal(core_read(c, 30), 0x7FFF);
  /* narrow values agree with core_get_int */
  core_put_wide(c, 40, 3, -5);
  assert_true(core_get_int(c, 40, 3) == -5);
  core_free(c);
}

/* ---------------------------------------------------------------- core: statistics */

static void test_peak_and_tables(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(200);
  uint32_t a;
  assert_int_equal(core_alloc(c, "A", 50, &a, &err), T74_OK);
  core_release(c, 0);
  assert_int_equal(core_alloc(c, "B", 30, &a, &err), T74_OK);
  assert_int_equal(core_peak(c), 50);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 20, &err), T74_OK);
  assert_int_equal(core_peak(c), 50);                    /* 30 + 20: not more */
  assert_int_equal(core_alloc(c, "PBS", 10, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, "PBS", 15, &a, &err), T74_OK);  /* same name, both live */
  assert_int_equal(core_peak(c), 75);
  core_release(c, 30);
  assert_int_equal(core_alloc(c, "PBS", 5, &a, &err), T74_OK);
  assert_int_equal(core_used(c), 55);
  assert_int_equal(core_peak(c), 75);
  const char *names[8];
  uint32_t peaks[8];
  int n = core_tables(c, names, peaks, 8);
  assert_int_equal(n, 4);
  assert_string_equal(names[0], "A");               assert_int_equal(peaks[0], 50);
  assert_string_equal(names[1], "B");               assert_int_equal(peaks[1], 30);
  assert_string_equal(names[2], CORE_T_PRIORITY);   assert_int_equal(peaks[2], 20);
  assert_string_equal(names[3], "PBS");             assert_int_equal(peaks[3], 25);
  assert_int_equal(core_tables(c, names, peaks, 2), 4);   /* count even when max is short */

  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  assert_int_equal(core_layout_dump(c, f), 0);
  fclose(f);
  assert_non_null(strstr(buf, "peak 75"));
  assert_non_null(strstr(buf, "PRIORITY MATRIX (high region"));
  assert_non_null(strstr(buf, "(free)"));
  assert_non_null(strstr(buf, "PBS"));
  free(buf);
  core_free(c);
}

static void test_injected_exhaustion(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(1000);
  uint32_t a;
  assert_int_equal(core_alloc(c, "A", 100, &a, &err), T74_OK);
  core_inject_exhaustion(c, 10);
  assert_int_equal(core_alloc(c, "B", 6, &a, &err), T74_OK);
  core_release(c, 100);                                  /* released words do not count back */
  assert_int_equal(core_alloc(c, "C", 4, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, "D", 1, &a, &err), T74_ECORE);
  assert_string_equal(err.msg, "scene does not fit the core: needs 105 words, 104 available "
                               "(table D could not take 1 words; injected exhaustion)");
  struct t74_error e2 = { 0 };
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 1, &e2), T74_ECORE);  /* sticky */
  assert_int_equal(e2.status, T74_ECORE);
  assert_int_equal(core_used(c), 104);
  core_inject_exhaustion(c, UINT32_MAX);                 /* disarm */
  struct t74_error e3 = { 0 };
  assert_int_equal(core_alloc(c, "D", 800, &a, &e3), T74_OK);
  assert_int_equal(e3.status, T74_OK);
  /* budget 0: the very next allocation fails, a zero-word one does not */
  core_inject_exhaustion(c, 0);
  assert_int_equal(core_alloc(c, "Z", 0, &a, &e3), T74_OK);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 2, &e3), T74_ECORE);
  core_free(c);
}

/* The layout dump of a core, as a string (caller frees). */
static char *layout_of(const struct core *c)
{
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  assert_non_null(f);
  assert_int_equal(core_layout_dump(c, f), 0);
  fclose(f);
  return buf;
}

/* core_reset (issue 19: one core for every frame of --frames) leaves a core that cannot be
   told from a new one: no tables, no names, no peak, no growth, no injected budget, every
   table's words zero when allocated, the same refusals. */
static void test_reset_as_new(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *fresh = core_new(300), *c = core_new(300);
  uint32_t a, b;
  assert_int_equal(core_alloc(c, "A", 120, &a, &err), T74_OK);
  for (uint32_t k = 0; k < 120; k++) core_write(c, a + k, 0xBEEF);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 100, &err), T74_OK);
  for (uint32_t k = 0; k < 100; k++) core_high_set(c, k, 0xF00D);
  core_inject_exhaustion(c, 5);
  core_set_growth(c, 1000);
  core_reset(c);
  assert_int_equal(core_used(c), 0);
  assert_int_equal(core_peak(c), 0);
  assert_int_equal(core_high_words(c), 0);
  assert_int_equal(core_tables(c, NULL, NULL, 0), 0);
  assert_int_equal(core_words(c), 300);
  assert_int_equal(core_first_words(c), 300);
  char *x = layout_of(fresh), *y = layout_of(c);
  assert_string_equal(x, y);
  free(x);
  free(y);
  /* the same tables on both: the same addresses, zero words, the same figures */
  assert_int_equal(core_alloc(fresh, "B", 200, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, "B", 200, &b, &err), T74_OK);   /* past the old budget */
  assert_int_equal(a, b);
  for (uint32_t k = 0; k < 200; k++) assert_int_equal(core_read(c, b + k), 0);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 100, &err), T74_OK);
  for (uint32_t k = 0; k < 100; k++) assert_int_equal(core_high_get(c, k), 0);
  /* no growth any more: one more word than the core has is refused */
  assert_int_equal(core_alloc(c, "C", 1, &b, &err), T74_ECORE);
  assert_int_equal(core_words(c), 300);
  core_free(fresh);
  core_free(c);
}

/* core_renew (issue 19: a core that grew in one frame serves the next): a core renewed
   to any size cannot be told from core_new of that size, grows the same way to the same
   sizes with every new table's words zero, and its high region keeps its words' numbering
   across a growth that needs no new host block. */
static void test_renew_as_new(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *fresh = core_new(100), *c = core_new(100);
  uint32_t a, b;
  core_set_growth(c, 4096);
  assert_int_equal(core_alloc(c, "A", 700, &a, &err), T74_OK);        /* grows to 800 */
  for (uint32_t k = 0; k < 700; k++) core_write(c, a + k, 0xBEEF);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 90, &err), T74_OK);
  for (uint32_t k = 0; k < 90; k++) core_high_set(c, k, 0xF00D);
  assert_int_equal(core_words(c), 800);
  assert_int_equal(core_renew(c, 100), 0);
  assert_int_equal(core_words(c), 100);
  assert_int_equal(core_first_words(c), 100);
  assert_int_equal(core_peak(c), 0);
  assert_int_equal(core_tables(c, NULL, NULL, 0), 0);
  char *x = layout_of(fresh), *y = layout_of(c);
  assert_string_equal(x, y);
  free(x);
  free(y);
  /* no growth unless asked: one word more than 100 is refused */
  assert_int_equal(core_alloc(c, "B", 101, &b, &err), T74_ECORE);
  /* asked on both: the same growth, addresses, zero words and high region */
  core_set_growth(fresh, 4096);
  core_set_growth(c, 4096);
  assert_int_equal(core_high_grow(fresh, CORE_T_PRIORITY, 30, &err), T74_OK);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 30, &err), T74_OK);
  for (uint32_t k = 0; k < 30; k++) {
    assert_int_equal(core_high_get(c, k), 0);
    core_high_set(fresh, k, (uint16_t)(k + 1));
    core_high_set(c, k, (uint16_t)(k + 1));
  }
  assert_int_equal(core_alloc(fresh, "B", 300, &a, &err), T74_OK);    /* 100 -> 400 */
  assert_int_equal(core_alloc(c, "B", 300, &b, &err), T74_OK);
  assert_int_equal(a, b);
  assert_int_equal(core_words(c), 400);
  assert_int_equal(core_words(fresh), 400);
  for (uint32_t k = 0; k < 300; k++) assert_int_equal(core_read(c, b + k), 0);
  for (uint32_t k = 0; k < 30; k++) assert_int_equal(core_high_get(c, k), k + 1);
  assert_int_equal(core_read(c, 399), 1);                  /* word 0 of it at the top */
  x = layout_of(fresh);
  y = layout_of(c);
  assert_string_equal(x, y);
  free(x);
  free(y);
  assert_int_equal(core_renew(c, 0), -1);                  /* out of range: unchanged */
  assert_int_equal(core_words(c), 400);
  core_free(fresh);
  core_free(c);
}

/* A core of 64 MB or more is a host mapping of its own (emu/core.c, "the host block"),
   given huge pages once a region reaches 2^16 words, the stretches in use collapsed into
   them: its words behave as any core's. Tables written before that keep their words,
   every new table's words are zero, and a core that grows into (or within) such a
   mapping keeps its low tables and its high region. */
static void test_core_large_block(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  const uint32_t big = UINT32_C(1) << 25;                   /* 64 MB of words */
  struct core *c = core_new(big);
  assert_non_null(c);
  uint32_t a, b;
  assert_int_equal(core_alloc(c, "A", 1000, &a, &err), T74_OK);
  for (uint32_t k = 0; k < 1000; k++) core_write(c, a + k, (uint16_t)(k * 7 + 1));
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 1000, &err), T74_OK);
  for (uint32_t k = 0; k < 1000; k++) core_high_set(c, k, (uint16_t)(k * 5 + 3));
  assert_int_equal(core_alloc(c, "B", UINT32_C(1) << 16, &b, &err), T74_OK);   /* huge now */
  for (uint32_t k = 0; k < 1000; k++) assert_int_equal(core_read(c, a + k), (uint16_t)(k * 7 + 1));
  for (uint32_t k = 0; k < 1000; k++) assert_int_equal(core_high_get(c, k), (uint16_t)(k * 5 + 3));
  for (uint32_t k = 0; k < UINT32_C(1) << 16; k++) assert_int_equal(core_read(c, b + k), 0);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 300000, &err), T74_OK);
  for (uint32_t k = 1000; k < 300000; k++) assert_int_equal(core_high_get(c, k), 0);
  for (uint32_t k = 0; k < 1000; k++) assert_int_equal(core_high_get(c, k), (uint16_t)(k * 5 + 3));
  /* renewed larger: a new mapping, made as new */
  assert_int_equal(core_renew(c, big * 2), 0);
  assert_int_equal(core_words(c), big * 2);
  assert_int_equal(core_alloc(c, "C", 200000, &a, &err), T74_OK);
  for (uint32_t k = 0; k < 200000; k++) assert_int_equal(core_read(c, a + k), 0);
  core_free(c);
  /* a small core (from malloc) that grows into a mapping, and within mappings */
  c = core_new(1024);
  core_set_growth(c, big * 4);
  assert_int_equal(core_alloc(c, "A", 900, &a, &err), T74_OK);
  for (uint32_t k = 0; k < 900; k++) core_write(c, a + k, (uint16_t)(k + 11));
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, 50, &err), T74_OK);
  for (uint32_t k = 0; k < 50; k++) core_high_set(c, k, (uint16_t)(k + 101));
  for (int round = 0; round < 2; round++) {
    uint32_t words = round ? core_words(c) : big - 1000;
    /* reserved, not zeroed by the table: the growth's words are zero */
    assert_int_equal(core_reserve(c, "B", words, &b, &err), T74_OK);
    assert_int_equal(core_words(c), round ? 2 * big : big);
    for (uint32_t k = 0; k < 900; k++) assert_int_equal(core_read(c, a + k), (uint16_t)(k + 11));
    for (uint32_t k = 0; k < 50; k++) assert_int_equal(core_high_get(c, k), (uint16_t)(k + 101));
    for (uint32_t k = 0; k < words; k += k < 4096 ? 1 : 997)   /* (where the high region was) */
      assert_int_equal(core_read(c, b + k), 0);
    assert_int_equal(core_read(c, b + words - 1), 0);
  }
  assert_true(core_words(c) >= big);
  core_free(c);
  /* a growth capped at grow_max into a new mapping, with a high region longer than the
     growth: the old and new places of the high region overlap, and it is kept whole */
  const uint32_t old = 3 * (big / 4), top = old + old / 2, hl = old / 2 + 4096;
  c = core_new(old);
  core_set_growth(c, top);
  assert_int_equal(core_high_grow(c, CORE_T_PRIORITY, hl, &err), T74_OK);
  for (uint32_t k = 0; k < hl; k += 61) core_high_set(c, k, (uint16_t)(k % 65521 + 1));
  assert_int_equal(core_reserve(c, "B", old - hl + 1, &b, &err), T74_OK);
  assert_int_equal(core_words(c), top);
  for (uint32_t k = 0; k < hl; k += 61) assert_int_equal(core_high_get(c, k), (uint16_t)(k % 65521 + 1));
  for (uint32_t k = 0; k < old - hl + 1; k += 997) assert_int_equal(core_read(c, b + k), 0);
  core_free(c);
}

/* core_new_lazy: the same core as core_new: zero words, the same places, refusals and
   growth, the words written kept. (What it saves, host memory never touched, is a
   benchmark's figure: `tube74 bench speed`'s max RSS column, points engine.) */
static void test_lazy_core(void **state)
{
  (void)state;
  struct t74_error e0 = { 0 }, e1 = { 0 };
  struct core *c[2] = { core_new(600000), core_new_lazy(600000) };   /* 1.2 MB: mapped */
  assert_non_null(c[0]);
  assert_non_null(c[1]);
  uint32_t a[2], b[2];
  for (int k = 0; k < 2; k++) {
    assert_int_equal(core_alloc(c[k], "A", 3000, &a[k], k ? &e1 : &e0), T74_OK);
    for (uint32_t q = 0; q < 3000; q++) assert_int_equal(core_read(c[k], a[k] + q), 0);
    for (uint32_t q = 0; q < 3000; q += 7) core_write(c[k], a[k] + q, (uint16_t)(q + 1));
    assert_int_equal(core_high_grow(c[k], CORE_T_PRIORITY, 1500, k ? &e1 : &e0), T74_OK);
    assert_int_equal(core_reserve(c[k], "B", 596000, &b[k], k ? &e1 : &e0), T74_ECORE);
    core_set_growth(c[k], UINT32_C(1) << 21);                 /* grown: kept */
    assert_int_equal(core_reserve(c[k], "B", 1u << 20, &b[k], k ? &e1 : &e0), T74_OK);
    for (uint32_t q = 0; q < 1500; q++) assert_int_equal(core_high_get(c[k], q), 0);
  }
  assert_int_equal(a[0], a[1]);
  assert_int_equal(b[0], b[1]);
  assert_int_equal(core_words(c[0]), core_words(c[1]));
  for (uint32_t q = 0; q < 3000; q++)
    assert_int_equal(core_read(c[0], a[0] + q), core_read(c[1], a[1] + q));
  core_free(c[0]);
  core_free(c[1]);
}

/* The layout dump's addresses (each table's first word is the length of those below it):
   after a release that cuts a table short, the tables above the mark are gone and the one
   it cuts keeps its first words. */
static void test_layout_after_release(void **state)
{
  (void)state;
  struct t74_error err = { 0 };
  struct core *c = core_new(100);
  uint32_t a;
  assert_int_equal(core_alloc(c, "A", 10, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, "B", 20, &a, &err), T74_OK);
  assert_int_equal(core_alloc(c, "C", 5, &a, &err), T74_OK);
  core_release(c, 15);
  assert_int_equal(core_alloc(c, "D", 7, &a, &err), T74_OK);
  assert_int_equal(a, 15);
  char *x = layout_of(c);
  assert_non_null(strstr(x, "           0 00000000         10  A\n"
                            "          10 0000000A          5  B\n"
                            "          15 0000000F          7  D\n"
                            "          22 00000016         78  (free)\n"));
  assert_null(strstr(x, "  C\n"));
  free(x);
  core_release(c, 12);                                     /* D goes, B keeps 2 words */
  x = layout_of(c);
  assert_non_null(strstr(x, "          10 0000000A          2  B\n"
                            "          12 0000000C         88  (free)\n"));
  free(x);
  core_free(c);
}

/* ---------------------------------------------------------------- cost model */

static void test_cost_seconds_by_hand(void **state)
{
  (void)state;
  struct cost_params p;
  cost_params_default(&p);
  struct cost c = { { 0 } };
  COST_ADD_N(&c, COST_MEM, 1000);
  COST_ADD_N(&c, COST_ADD, 500);
  COST_ADD_N(&c, COST_LOGIC, 40);
  COST_ADD_N(&c, COST_SHIFT, 30);
  COST_ADD_N(&c, COST_BRANCH, 200);
  COST_ADD_N(&c, COST_MUL, 10);
  COST_ADD_N(&c, COST_DIV, 5);
  COST_ADD_N(&c, COST_IO, 7);
  COST_ADD_N(&c, COST_IND, 11);
  /* By hand from the table: 233.33 ns a state; MEM, ADD, LOGIC, BRANCH, IO 6 states;
     SHIFT 6 + (4-1)*1 = 9; MUL (hw) 22; DIV (hw) 38; IND 3. */
  double states = 1000 * 6 + 500 * 6 + 40 * 6 + 30 * 9 + 200 * 6 + 10 * 22 + 5 * 38 + 7 * 6 + 11 * 3;
  double want = states * 233.33e-9;
  assert_true(fabs(cost_seconds(&c, &p) - want) < 1e-12);
  assert_true(fabs(cost_class_us(&p, COST_MEM) - 1.39998) < 1e-9);   /* "about 1.4 us" */
  /* software multiply/divide: trap 6 + routine instructions x 6 states */
  assert_int_equal(cost_params_set(&p, "muldiv=sw", NULL), T74_OK);
  double sw = states - 10 * 22 - 5 * 38 + 10 * (6 + 138 * 6) + 5 * (6 + 172 * 6);
  assert_true(fabs(cost_seconds(&c, &p) - sw * 233.33e-9) < 1e-12);
  assert_true(cost_class_us(&p, COST_MUL) > 30 * cost_class_us(&p, COST_MEM));
  /* merge and total */
  struct cost d = { { 0 } };
  cost_merge(&d, &c);
  cost_merge(&d, &c);
  assert_int_equal(d.n[COST_MEM], 2000);
  assert_int_equal(cost_total(&d), 2 * (1000 + 500 + 40 + 30 + 200 + 10 + 5 + 7 + 11));
  struct cost zero = { { 0 } };
  assert_true(cost_seconds(&zero, &p) == 0.0);
}

static void test_params_set(void **state)
{
  (void)state;
  struct cost_params p;
  cost_params_default(&p);
  struct t74_error err = { 0 };
  double v;
  assert_int_equal(cost_params_set(&p, "mem_states=7", &err), T74_OK);
  assert_int_equal(cost_params_get(&p, "mem_states", &v), T74_OK);
  assert_true(v == 7);
  assert_int_equal(cost_params_set(&p, "state_ns=250", &err), T74_OK);
  assert_true(fabs(cost_class_us(&p, COST_MEM) - 1.75) < 1e-12);
  assert_int_equal(cost_params_set(&p, "mem_us=1.6", &err), T74_OK);  /* via states */
  assert_true(fabs(cost_class_us(&p, COST_MEM) - 1.6) < 1e-12);
  assert_true(fabs(p.v[CP_MEM_STATES] - 6.4) < 1e-12);
  assert_int_equal(cost_params_set(&p, "muldiv=sw", &err), T74_OK);
  assert_true(p.v[CP_MULDIV] == 1);
  assert_int_equal(cost_params_set(&p, "muldiv=hw", &err), T74_OK);
  assert_true(p.v[CP_MULDIV] == 0);
  assert_int_equal(err.status, T74_OK);

  struct cost_params before = p;
  struct t74_error e1 = { 0 };
  assert_int_equal(cost_params_set(&p, "bogus=1", &e1), T74_EINPUT);
  assert_int_equal(e1.status, T74_EINPUT);
  assert_non_null(strstr(e1.msg, "unknown machine parameter 'bogus'"));
  struct t74_error e2 = { 0 };
  assert_int_equal(cost_params_set(&p, "mem_states=fast", &e2), T74_EINPUT);
  assert_non_null(strstr(e2.msg, "not a number"));
  assert_int_equal(cost_params_set(&p, "mem_states=", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "mem_states=6x", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "mem_states=-1", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "mem_states=nan", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "core_words=1000.5", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "muldiv=maybe", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "mem_states", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "=3", NULL), T74_EINPUT);
  assert_int_equal(cost_params_set(&p, "disk_us=3", NULL), T74_EINPUT);   /* not a states row */
  assert_memory_equal(&before, &p, sizeof p);           /* nothing changed */
  assert_int_equal(cost_params_get(&p, "nope", &v), T74_EINPUT);
}

static void test_params_table(void **state)
{
  (void)state;
  struct cost_params p;
  cost_params_default(&p);
  int inferred = 0;
  for (int i = 0; i < CP_NPARAM; i++) {
    const struct param_row *r = &cost_param_rows[i];
    assert_non_null(r->name);                           /* every row filled in */
    assert_non_null(r->unit);
    assert_non_null(r->source);
    assert_true(strlen(r->source) > 10);
    assert_true(r->def >= r->min && r->def <= r->max);
    inferred += strstr(r->source, "inferred") != NULL;
    for (int j = 0; j < i; j++) assert_true(strcmp(r->name, cost_param_rows[j].name) != 0);
  }
  assert_true(inferred >= 8);
  assert_true(p.v[CP_CORE_WORDS] == 16384);
  assert_true(p.v[CP_DISK_SEEK_MS] == 60 && p.v[CP_DISK_TRACK_MS] == 30);
  assert_true(p.v[CP_DISK_ROT_MS] == 20 && p.v[CP_DISK_MBIT] == 10);
  assert_true(p.v[CP_DRUM_REV_S] == 0.75 && p.v[CP_ADC_US] == 50);
  assert_true(p.v[CP_MULDIV] == 0);                      /* hw, the stated assumption */

  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  assert_int_equal(cost_params_list(&p, f), 0);
  assert_int_equal(h10_list(f), 0);
  fclose(f);
  for (int i = 0; i < CP_NPARAM; i++) assert_non_null(strstr(buf, cost_param_rows[i].name));
  assert_non_null(strstr(buf, "hw|sw"));
  assert_non_null(strstr(buf, "EC"));
  free(buf);
}

/* Operations of an exact-width operation: the 1974 program's share plus the rest. */
static uint64_t X_(const struct cost *c, int cls) { return c->n[cls] + COST_X(c, cls); }

static void expect(const struct cost *c, uint64_t mem, uint64_t add, uint64_t logic,
                   uint64_t shift, uint64_t branch, uint64_t mul, uint64_t div)
{
  assert_int_equal(X_(c, COST_MEM), mem);
  assert_int_equal(X_(c, COST_ADD), add);
  assert_int_equal(X_(c, COST_LOGIC), logic);
  assert_int_equal(X_(c, COST_SHIFT), shift);
  assert_int_equal(X_(c, COST_BRANCH), branch);
  assert_int_equal(X_(c, COST_MUL), mul);
  assert_int_equal(X_(c, COST_DIV), div);
  assert_int_equal(X_(c, COST_IO), 0);
}

static void test_mw_add(void **state)
{
  (void)state;
  struct cost c;
  static const struct { int bits; uint64_t w; } t[] = {
    { 1, 1 }, { 16, 1 }, { 17, 2 }, { 32, 2 }, { 64, 4 }, { 128, 8 } };
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
    memset(&c, 0, sizeof c);
    cost_mw_add(&c, t[i].bits);
    uint64_t w = t[i].w;
    /* 2w memory references, w adds plus w-1 carry adds, w-1 carry skips */
    expect(&c, 2 * w, 2 * w - 1, 0, 0, w - 1, 0, 0);
  }
}

static void test_mw_mul(void **state)
{
  (void)state;
  struct cost c;
  memset(&c, 0, sizeof c);
  cost_mw_mul(&c, 16, 16);                               /* L, M, ST, EC->AC, ST */
  expect(&c, 3, 0, 1, 0, 0, 1, 0);
  static const struct { int a, b; uint64_t wa, wb; } t[] = {
    { 32, 32, 2, 2 }, { 64, 64, 4, 4 }, { 128, 128, 8, 8 }, { 32, 16, 2, 1 }, { 64, 128, 4, 8 } };
  for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
    memset(&c, 0, sizeof c);
    cost_mw_mul(&c, t[i].a, t[i].b);
    uint64_t wa = t[i].wa, wb = t[i].wb, pp = wa * wb, wr = wa + wb;
    assert_int_equal(X_(&c, COST_MUL), pp);                /* wa*wb single-word multiplies */
    /* clear + partials + row carries + sign fix-up (an add of the product width) */
    expect(&c, wr + 3 * pp + 2 * wa + 2 * wr, 3 * pp + wa + (2 * wr - 1), pp, 0,
           pp + wa + 2 + (wr - 1), pp, 0);
  }
  memset(&c, 0, sizeof c);
  cost_mw_mul(&c, 32, 32);                               /* spelled out once */
  expect(&c, 28, 21, 4, 0, 11, 4, 0);
  memset(&c, 0, sizeof c);
  cost_mw_mul(&c, 128, 128);
  assert_int_equal(X_(&c, COST_MUL), 64);
}

static void test_mw_div(void **state)
{
  (void)state;
  struct cost c;
  memset(&c, 0, sizeof c);
  cost_mw_div(&c, 16, 16);
  expect(&c, 2, 0, 1, 0, 0, 0, 1);
  memset(&c, 0, sizeof c);
  cost_mw_div(&c, 64, 16);                               /* one divide per dividend word */
  expect(&c, 8, 0, 4, 0, 0, 0, 4);
  memset(&c, 0, sizeof c);
  cost_mw_div(&c, 128, 64);                              /* wn 8, wd 4: 5 quotient words */
  assert_int_equal(X_(&c, COST_DIV), 5);
  assert_int_equal(X_(&c, COST_MUL), 20);
  assert_int_equal(X_(&c, COST_SHIFT), 24);
  expect(&c, 24 + 5 * 15 + 10, 5 * 9 + 9, 20, 24, 5 * 5 + 2 + 4, 20, 5);
}

/* Issue 19: cost_mw_*_n(c, ..., k) charges exactly what k single calls charge, in both
   sets of counters (x[] below zero included), for k = 0, 1 and more, at widths within and
   beyond the 1974 program's. */
static void test_mw_n(void **state)
{
  (void)state;
  static const int bits[][2] = { { 16, 16 }, { 17, 17 }, { 30, 30 }, { 64, 32 }, { 88, 58 },
                                 { 86, 48 }, { 128, 128 }, { 1, 200 } };
  static const uint64_t ks[] = { 0, 1, 2, 7, 1000 };
  for (size_t b = 0; b < sizeof bits / sizeof bits[0]; b++)
    for (size_t q = 0; q < sizeof ks / sizeof ks[0]; q++) {
      struct cost one = { { 0 } }, many = { { 0 } };
      for (uint64_t i = 0; i < ks[q]; i++) {
        cost_mw_add(&one, bits[b][0]);
        cost_mw_mul(&one, bits[b][0], bits[b][1]);
        cost_mw_div(&one, bits[b][0], bits[b][1]);
      }
      cost_mw_add_n(&many, bits[b][0], ks[q]);
      cost_mw_mul_n(&many, bits[b][0], bits[b][1], ks[q]);
      cost_mw_div_n(&many, bits[b][0], bits[b][1], ks[q]);
      assert_memory_equal(&one, &many, sizeof one);
      if (ks[q] == 2 && bits[b][0] > 32) assert_true(cost_total(&many) > 0);
    }
}

/* The 1974 program's share: adds on at most a double word, multiplies one word by one
   word, divides a double word by a word (docs/machine.md); the rest goes to x[]. */
static void test_mw_1974_share(void **state)
{
  (void)state;
  struct cost c;
  memset(&c, 0, sizeof c);
  cost_mw_add(&c, 128);                         /* 8 words exact, 2 in 1974 */
  assert_int_equal(c.n[COST_MEM], 4); assert_int_equal(c.n[COST_ADD], 3);
  assert_int_equal(c.n[COST_BRANCH], 1);
  assert_int_equal(COST_X(&c, COST_MEM), 12); assert_int_equal(COST_X(&c, COST_ADD), 12);
  memset(&c, 0, sizeof c);
  cost_mw_mul(&c, 88, 59);                      /* 6 x 4 words exact: 24 multiplies */
  assert_int_equal(c.n[COST_MUL], 1);           /* 1974: one 16 x 16 multiply */
  assert_int_equal(c.n[COST_MEM], 3);
  assert_int_equal(COST_X(&c, COST_MUL), 23);
  memset(&c, 0, sizeof c);
  cost_mw_mul(&c, 16, 16);                      /* one word each: nothing extra */
  for (int k = 0; k < COST_NCLASS; k++) assert_int_equal(COST_X(&c, k), 0);
  memset(&c, 0, sizeof c);
  cost_mw_div(&c, 128, 64);                     /* 1974: a double word by a word */
  assert_int_equal(c.n[COST_DIV], 2); assert_int_equal(c.n[COST_MUL], 0);
  assert_int_equal(COST_X(&c, COST_DIV), 3); assert_int_equal(COST_X(&c, COST_MUL), 20);
  struct cost_params p;
  cost_params_default(&p);
  assert_true(cost_seconds_exact(&c, &p) > cost_seconds(&c, &p));
  struct cost m;
  memset(&m, 0, sizeof m);
  cost_merge(&m, &c);
  cost_merge(&m, &c);
  assert_int_equal(COST_X(&m, COST_MUL), 40);
}

/* ---------------------------------------------------------------- instruction format */

static void test_instruction_format(void **state)
{
  (void)state;
  /* words of the IPL that H10.v loads, with its comments */
  assert_int_equal(H10_OPCODE(0x3C01), H10_ST);          /* ST ,I 1 */
  assert_int_equal(H10_IND(0x3C01), 1);
  assert_int_equal(H10_PAGE(0x3C01), 0);
  assert_int_equal(H10_ADDR(0x3C01), 1);
  assert_int_equal(H10_OPCODE(0x4005), H10_B);           /* B 5 */
  assert_int_equal(H10_OPCODE(0x8804), H10_SLL);         /* SLL 4 */
  assert_int_equal(0x8804 & H10_M_SHCNT, 4);
  assert_int_equal(H10_OPCODE(0x5001), H10_KCT);         /* KCT 1 */
  assert_int_equal(H10_OPCODE(0x6841), H10_K);           /* KNC */
  assert_int_equal(H10_OPCODE(0x7024), H10_IOC);
  assert_int_equal(H10_INSTR(H10_ST, 1, 0, 1), 0x3C01);
  assert_int_equal(H10_INSTR(H10_L, 0, 1, 0x1FF), 0x0BFF);
  for (unsigned w = 0; w <= 0xFFFF; w += 37)
    assert_int_equal(H10_INSTR(H10_OPCODE(w), H10_IND(w), H10_PAGE(w), H10_ADDR(w)), w);
  assert_int_equal(H10_EA(H10_INSTR(H10_L, 0, 1, 5), 0x1234), 0x1205);  /* current page */
  assert_int_equal(H10_EA(H10_INSTR(H10_L, 0, 0, 5), 0x1234), 5);       /* page 0 */
  assert_int_equal(H10_PAGE_WORDS, 1u << H10_PAGE_BITS);
  assert_int_equal(H10_CORE_MAX, 1u << H10_PC_BITS);
  assert_int_equal(H10_CORE_PAPER % H10_CORE_UNIT, 0);
  for (int i = 0; i < h10_nops; i++) assert_true(h10_ops[i].cls >= 0 && h10_ops[i].cls < COST_NCLASS);
  assert_true(h10_nregs >= 3);
  assert_string_equal(h10_regs[0].name, "AC");
  assert_int_equal(h10_regs[0].width, H10_WORD_BITS);
}

/* emu/param: lookup by a name prefix, exact range and whole-number checks, defaults. */
static void test_param_table(void **state)
{
  (void)state;
  static const struct param_row rows[] = {
    { "dwell_us", "us", 10, 0, 1e6, 0, "inferred" },
    { "home_x", "point", 0, 0, 399, 1, "inferred" },
  };
  assert_int_equal(param_find(rows, 2, "home_x=3", 6), 1);
  assert_int_equal(param_find(rows, 2, "home", 4), -1);         /* whole names only */
  double v = -1;
  assert_int_equal(param_parse(&rows[0], "12.5", &v), PARAM_OK);
  assert_true(v == 12.5);
  assert_int_equal(param_parse(&rows[0], "12.5x", &v), PARAM_NOT_NUMBER);
  assert_int_equal(param_parse(&rows[0], "", &v), PARAM_NOT_NUMBER);
  assert_int_equal(param_parse(&rows[0], "inf", &v), PARAM_NOT_NUMBER);
  assert_int_equal(param_parse(&rows[0], "-0.001", &v), PARAM_OUT_OF_RANGE);
  assert_int_equal(param_parse(&rows[1], "399", &v), PARAM_OK);
  assert_int_equal(param_parse(&rows[1], "1.5", &v), PARAM_OUT_OF_RANGE);
  assert_int_equal(param_parse(&rows[1], "400", &v), PARAM_OUT_OF_RANGE);
  assert_true(v == 399);                                          /* untouched on failure */
  double d[2] = { -1, -1 };
  param_defaults(rows, 2, d);
  assert_true(d[0] == 10 && d[1] == 0);
}

/* core_reserve is core_alloc but for the zeroing: on two cores the same random sequence
   of tables (some too large, refused), releases and a high region, one core taking every
   other table by core_reserve, gives the same addresses, results, messages, use, peak,
   tables and layout; the reserved words keep what was there, the allocated ones are 0. */
/* Issue 19: core_write_n is core_write a word at a time, to the core's last word. */
static void test_write_n(void **state)
{
  (void)state;
  struct core *c[2] = { core_new(64), core_new(64) };
  const uint32_t at[][2] = { { 0, 0 }, { 0, 5 }, { 7, 13 }, { 40, 24 }, { 63, 1 }, { 0, 64 } };
  enum { NAT = sizeof at / sizeof at[0] };
  uint16_t w[64 + NAT];                   /* case t reads w[t .. t + n) */
  for (int k = 0; k < 64 + NAT; k++) w[k] = (uint16_t)(0x9E37u * (unsigned)(k + 1));
  for (size_t t = 0; t < sizeof at / sizeof at[0]; t++) {
    core_write_n(c[0], at[t][0], w + t, at[t][1]);
    for (uint32_t k = 0; k < at[t][1]; k++) core_write(c[1], at[t][0] + k, w[t + k]);
    for (uint32_t k = 0; k < 64; k++) assert_int_equal(core_read(c[0], k), core_read(c[1], k));
  }
  core_free(c[0]);
  core_free(c[1]);
}

/* The two cores' tables and layouts are the same. */
static void same_tables(struct core *a, struct core *b)
{
  const char *n0[8], *n1[8];
  uint32_t p0[8], p1[8];
  int nt = core_tables(a, n0, p0, 8);
  assert_int_equal(nt, core_tables(b, n1, p1, 8));
  for (int k = 0; k < nt && k < 8; k++) {
    assert_string_equal(n0[k], n1[k]);
    assert_int_equal(p0[k], p1[k]);
  }
  char *buf[2] = { NULL, NULL };
  size_t len[2] = { 0, 0 };
  struct core *c[2] = { a, b };
  for (int k = 0; k < 2; k++) {
    FILE *f = open_memstream(&buf[k], &len[k]);
    assert_int_equal(core_layout_dump(c[k], f), 0);
    fclose(f);
  }
  assert_int_equal(len[0], len[1]);
  assert_memory_equal(buf[0], buf[1], len[0]);
  free(buf[0]);
  free(buf[1]);
}

/* Issue 19: core_alloc_named is core_alloc: the same addresses, refusals, statistics and
   layout, with the names' rows found once; after core_reset (the rows made again, in
   another order) and on another core each handle finds its row again. */
static void test_alloc_named(void **state)
{
  (void)state;
  struct core *c[3] = { core_new(4000), core_new(4000), core_new(4000) };
  for (int k = 0; k < 3; k++) assert_non_null(c[k]);
  const char *names[] = { "VERTEX", "A-BLOCK", "PBS", "X" };
  struct core_name h[4];
  memset(h, 0, sizeof h);
  for (int k = 0; k < 4; k++) h[k].name = names[k];
  uint32_t rnd = 777;
  for (int step = 0; step < 600; step++) {
    rnd = rnd * 1103515245u + 12345u;
    uint32_t r = rnd >> 8, words = 1 + r % 900;
    int ni = (int)((r >> 12) % 4);
    if (step % 97 == 96) {                    /* both made anew: rows in another order */
      same_tables(c[0], c[1]);
      for (int k = 0; k < 2; k++) core_reset(c[k]);
      continue;
    }
    if (r % 7 == 0) {
      uint32_t mark = core_mark(c[0]) / 2;
      for (int k = 0; k < 2; k++) core_release(c[k], mark);
      continue;
    }
    uint32_t a[3] = { 0, 0, 0 };
    struct t74_error e[3] = { { 0 }, { 0 }, { 0 } };
    int st0 = core_alloc(c[0], names[ni], words, &a[0], &e[0]);
    int st1 = core_alloc_named(c[1], &h[ni], words, &a[1], &e[1]);
    assert_int_equal(st0, st1);
    assert_string_equal(e[0].msg, e[1].msg);
    assert_int_equal(core_used(c[0]), core_used(c[1]));
    if (st0 == T74_OK) assert_int_equal(a[0], a[1]);
    if (step % 5 == 0) {                      /* the same handles on a third core */
      core_release(c[2], 0);
      assert_int_equal(core_alloc_named(c[2], &h[(ni + 1) % 4], 3, &a[2], &e[2]), T74_OK);
      const char *n2[8];
      uint32_t p2[8];
      int nt = core_tables(c[2], n2, p2, 8), found = 0;
      for (int k = 0; k < nt && k < 8; k++) found += strcmp(n2[k], names[(ni + 1) % 4]) == 0;
      assert_int_equal(found, 1);
    }
  }
  same_tables(c[0], c[1]);
  for (int k = 0; k < 3; k++) core_free(c[k]);
}

static void test_reserve_as_alloc(void **state)
{
  (void)state;
  struct core *c[2] = { core_new(4000), core_new(4000) };
  assert_non_null(c[0]);
  assert_non_null(c[1]);
  const char *names[] = { "VERTEX", "A-BLOCK", "PBS", "X" };
  uint32_t rnd = 12345;
  for (int step = 0; step < 400; step++) {
    rnd = rnd * 1103515245u + 12345u;
    uint32_t r = rnd >> 8, words = 1 + r % 900;
    const char *name = names[(r >> 12) % 4];
    if (r % 7 == 0) {                         /* a release to a mark below the top */
      uint32_t mark = core_mark(c[0]) / 2;
      for (int k = 0; k < 2; k++) core_release(c[k], mark);
      continue;
    }
    if (r % 11 == 0) {
      for (int k = 0; k < 2; k++) core_high_free(c[k]);
      continue;
    }
    if (r % 13 == 0) {
      struct t74_error e0 = { 0 }, e1 = { 0 };
      assert_int_equal(core_high_grow(c[0], CORE_T_PRIORITY, words / 4, &e0),
                       core_high_grow(c[1], CORE_T_PRIORITY, words / 4, &e1));
      continue;
    }
    uint32_t a[2] = { 0, 0 };
    struct t74_error e[2] = { { 0 }, { 0 } };
    int st0 = core_alloc(c[0], name, words, &a[0], &e[0]);
    int st1 = step % 2 ? core_reserve(c[1], name, words, &a[1], &e[1])
                       : core_alloc(c[1], name, words, &a[1], &e[1]);
    assert_int_equal(st0, st1);
    assert_string_equal(e[0].msg, e[1].msg);
    assert_int_equal(core_used(c[0]), core_used(c[1]));
    assert_int_equal(core_peak(c[0]), core_peak(c[1]));
    if (st0 != T74_OK) continue;
    assert_int_equal(a[0], a[1]);
    for (uint32_t k = 0; k < words; k++) {
      assert_int_equal(core_read(c[0], a[0] + k), 0);
      if (step % 2 == 0) assert_int_equal(core_read(c[1], a[1] + k), 0);
      core_write(c[0], a[0] + k, (uint16_t)(step + 1));   /* left for the next tables */
      core_write(c[1], a[1] + k, (uint16_t)(step + 1));
    }
  }
  const char *n0[8], *n1[8];
  uint32_t p0[8], p1[8];
  int nt = core_tables(c[0], n0, p0, 8);
  assert_int_equal(nt, core_tables(c[1], n1, p1, 8));
  for (int k = 0; k < nt && k < 8; k++) {
    assert_string_equal(n0[k], n1[k]);
    assert_int_equal(p0[k], p1[k]);
  }
  char *buf[2] = { NULL, NULL };
  size_t len[2] = { 0, 0 };
  for (int k = 0; k < 2; k++) {
    FILE *f = open_memstream(&buf[k], &len[k]);
    assert_int_equal(core_layout_dump(c[k], f), 0);
    fclose(f);
  }
  assert_string_equal(buf[0], buf[1]);
  free(buf[0]);
  free(buf[1]);
  /* a reserved table over words a released one wrote keeps them */
  uint32_t a, b;
  struct t74_error err = { 0 };
  core_release(c[1], 0);
  core_high_free(c[1]);
  assert_int_equal(core_alloc(c[1], "A", 4, &a, &err), T74_OK);
  core_write(c[1], a + 2, 77);
  core_release(c[1], 0);
  assert_int_equal(core_reserve(c[1], "B", 4, &b, &err), T74_OK);
  assert_int_equal(b, a);
  assert_int_equal(core_read(c[1], b + 2), 77);
  core_free(c[0]);
  core_free(c[1]);
}

/* t74_grow: room from 64, doubled until it holds what is asked, the contents kept; a
   size whose bytes overflow a size_t refused with the array as it was. */
static void test_grow(void **state)
{
  (void)state;
  int *a = NULL;
  size_t cap = 0;
  assert_true(t74_grow((void **)&a, &cap, 0, sizeof *a));     /* nothing asked: nothing made */
  assert_null(a);
  assert_int_equal(cap, 0);
  assert_true(t74_grow((void **)&a, &cap, 1, sizeof *a));
  assert_int_equal(cap, 64);
  for (int k = 0; k < 64; k++) a[k] = 3 * k + 1;
  int *before = a;
  assert_true(t74_grow((void **)&a, &cap, 64, sizeof *a));    /* held already: untouched */
  assert_ptr_equal(a, before);
  assert_int_equal(cap, 64);
  assert_true(t74_grow((void **)&a, &cap, 300, sizeof *a));
  assert_int_equal(cap, 512);                                /* 64 doubled to hold 300 */
  for (int k = 0; k < 64; k++) assert_int_equal(a[k], 3 * k + 1);
  a[299] = 7;                                                /* (ASan: the room is there) */
  int *kept = a;
  assert_false(t74_grow((void **)&a, &cap, SIZE_MAX / 2, sizeof *a));
  assert_ptr_equal(a, kept);
  assert_int_equal(cap, 512);
  assert_int_equal(a[299], 7);
  free(a);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_param_table),
    cmocka_unit_test(test_grow),
    cmocka_unit_test(test_new_bounds),
    cmocka_unit_test(test_alloc_release_stack),
    cmocka_unit_test(test_fill_exactly),
    cmocka_unit_test(test_high_keeps_contents),
    cmocka_unit_test(test_high_top_write),
    cmocka_unit_test(test_high_meets_low),
    cmocka_unit_test(test_contract_message),
    cmocka_unit_test(test_2bit_fields),
    cmocka_unit_test(test_multiword_int),
    cmocka_unit_test(test_multiword_wide),
    cmocka_unit_test(test_peak_and_tables),
    cmocka_unit_test(test_reserve_as_alloc),
    cmocka_unit_test(test_injected_exhaustion),
    cmocka_unit_test(test_reset_as_new),
    cmocka_unit_test(test_renew_as_new),
    cmocka_unit_test(test_core_large_block),
    cmocka_unit_test(test_lazy_core),
    cmocka_unit_test(test_layout_after_release),
    cmocka_unit_test(test_cost_seconds_by_hand),
    cmocka_unit_test(test_params_set),
    cmocka_unit_test(test_params_table),
    cmocka_unit_test(test_mw_add),
    cmocka_unit_test(test_mw_mul),
    cmocka_unit_test(test_mw_div),
    cmocka_unit_test(test_mw_1974_share),
    cmocka_unit_test(test_mw_n),
    cmocka_unit_test(test_instruction_format),
    cmocka_unit_test(test_alloc_named),
    cmocka_unit_test(test_write_n),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
