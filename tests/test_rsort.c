/*
** test_rsort.c — tests of the renderer's sorts (render/rsort.c).
**
** rsort_merge: against the plain bottom-up merge sort written out here (the long way:
** every element moved by its own copy), on elements of 4 bytes (the Visible Surface
** Procedure's indices, which take their own copy loop), 8, 12 and 40 bytes, with many
** equal keys: the same result, and the very same compares in the same order (callers
** charge each as 1974 work). rsort_pairs: against qsort by (key, index). Run from the
** repository root.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/rsort.h"

/* An element: its key first (as an int), then an identity, then padding to its size. */
struct log { int n, cap; int (*pair)[2]; };

/* The compare of the elements identified by ia and ib logged. */
static void logged(struct log *l, int ia, int ib)
{
  if (l->n == l->cap) {
    l->cap = l->cap ? 2 * l->cap : 256;
    l->pair = realloc(l->pair, (size_t)l->cap * sizeof *l->pair);
    assert_non_null(l->pair);
  }
  l->pair[l->n][0] = ia;
  l->pair[l->n][1] = ib;
  l->n++;
}

static int by_key(const void *x, const void *y, void *ctx)
{
  int a, b, ia, ib;
  memcpy(&a, x, sizeof a);
  memcpy(&b, y, sizeof b);
  memcpy(&ia, (const char *)x + sizeof(int), sizeof ia);
  memcpy(&ib, (const char *)y + sizeof(int), sizeof ib);
  logged(ctx, ia, ib);
  return (a > b) - (a < b);
}

/* 4-byte elements: the key alone, which then names the element in the log; compared
   without its low 4 bits, so that equal keys abound. */
static int by_int(const void *x, const void *y, void *ctx)
{
  int a, b;
  memcpy(&a, x, sizeof a);
  memcpy(&b, y, sizeof b);
  logged(ctx, a, b);
  return (a >> 4) < (b >> 4) ? -1 : (a >> 4) > (b >> 4);
}

/* The long way: rsort_merge as it was first written. */
static void merge_ref(void *base, int n, size_t sz, void *tmp, rs_cmp cmp, void *ctx)
{
  char *src = base, *dst = tmp;
  for (int width = 1; width < n; width *= 2) {
    for (int lo = 0; lo < n; lo += 2 * width) {
      int mid = lo + width < n ? lo + width : n;
      int hi = lo + 2 * width < n ? lo + 2 * width : n;
      int i = lo, j = mid, k = lo;
      while (i < mid && j < hi) {
        if (cmp(src + (size_t)j * sz, src + (size_t)i * sz, ctx) < 0)
          memcpy(dst + (size_t)k++ * sz, src + (size_t)j++ * sz, sz);
        else
          memcpy(dst + (size_t)k++ * sz, src + (size_t)i++ * sz, sz);
      }
      while (i < mid) memcpy(dst + (size_t)k++ * sz, src + (size_t)i++ * sz, sz);
      while (j < hi) memcpy(dst + (size_t)k++ * sz, src + (size_t)j++ * sz, sz);
    }
    char *t = src; src = dst; dst = t;
  }
  if (src != (char *)base) memcpy(base, src, (size_t)n * sz);
}

static uint32_t seed;
static int rnd(int m)
{
  seed = seed * 1103515245u + 12345u;
  return (int)((seed >> 8) % (uint32_t)m);
}

static void test_merge_as_long_way(void **state)
{
  (void)state;
  const size_t sizes[] = { 4, 8, 12, 40 };
  seed = 74;
  for (int s = 0; s < 4; s++) {
    size_t sz = sizes[s];
    for (int trial = 0; trial < 60; trial++) {
      int n = trial < 20 ? trial : rnd(3000) + 1;
      int keys = 1 + rnd(trial % 3 == 0 ? 4 : 500);         /* few keys: many ties */
      char *a = calloc((size_t)n + 1, sz), *b = calloc((size_t)n + 1, sz);
      char *ta = calloc((size_t)n + 1, sz), *tb = calloc((size_t)n + 1, sz);
      assert_true(a && b && ta && tb);
      for (int k = 0; k < n; k++) {
        int key = sz == 4 ? rnd(keys) * 16 + rnd(16) : rnd(keys);
        memcpy(a + (size_t)k * sz, &key, sizeof key);
        if (sz > 4) memcpy(a + (size_t)k * sz + sizeof(int), &k, sizeof k);
        for (size_t c = 2 * sizeof(int); c < sz; c++) a[(size_t)k * sz + c] = (char)rnd(256);
      }
      memcpy(b, a, (size_t)n * sz);
      struct log la = { 0, 0, NULL }, lb = { 0, 0, NULL };
      rs_cmp cmp = sz == 4 ? by_int : by_key;
      rsort_merge(a, n, sz, ta, cmp, &la);
      merge_ref(b, n, sz, tb, cmp, &lb);
      if (n > 0) assert_memory_equal(a, b, (size_t)n * sz);
      assert_int_equal(la.n, lb.n);
      if (la.n) assert_memory_equal(la.pair, lb.pair, (size_t)la.n * sizeof *la.pair);
      free(la.pair); free(lb.pair);
      free(a); free(b); free(ta); free(tb);
    }
  }
}

static int pair_cmp(const void *x, const void *y)
{
  const struct rs_pair *a = x, *b = y;
  if (a->key != b->key) return a->key < b->key ? -1 : 1;
  return (a->idx > b->idx) - (a->idx < b->idx);
}

static void test_pairs_as_qsort(void **state)
{
  (void)state;
  seed = 19;
  for (int trial = 0; trial < 40; trial++) {
    int n = rnd(5000) + 1;
    struct rs_pair *a = malloc(2 * (size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b);
    assert_true(a && b);
    for (int k = 0; k < n; k++) {
      int64_t key = (int64_t)rnd(1 << 20) - (1 << 19);
      if (trial % 2) key *= (int64_t)1 << 30;                /* high bytes differ */
      if (trial % 5 == 0) key = rnd(3);                      /* ties */
      if (trial % 8 == 3 && k % 7 == 0)                      /* the ends of the range */
        key = k % 2 ? INT64_MAX - rnd(3) : INT64_MIN + rnd(3);
      a[k].key = key;
      a[k].idx = k;
    }
    memcpy(b, a, (size_t)n * sizeof *b);
    rsort_pairs(a, a + n, n);
    qsort(b, (size_t)n, sizeof *b, pair_cmp);
    for (int k = 0; k < n; k++) {
      assert_true(a[k].key == b[k].key);
      assert_int_equal(a[k].idx, b[k].idx);
    }
    free(a);
    free(b);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_merge_as_long_way),
    cmocka_unit_test(test_pairs_as_qsort),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
