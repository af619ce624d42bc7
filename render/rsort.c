/*
** rsort.c — the renderer's general sorts (rsort.h): (key, index) pairs by key for the
** Mapper's T-junction search and the lazy cut order, and a stable merge sort for XSORT
** and the Visible Surface Procedure; no 1974 work is counted here (callers charge their
** own compares).
**
** This file contains a least significant digit radix sort: one histogram pass over the
** eight key bytes (the sign bit flipped, so signed keys sort as unsigned), then one
** stable scatter pass for each byte in which the keys differ. Stable, so pairs of equal
** key keep the (ascending) order of their indices.
*/
#include "render/rsort.h"

#include <string.h>

void rsort_pairs(struct rs_pair *a, struct rs_pair *tmp, int n)
{
  if (n < 2) return;
  static const uint64_t flip = (uint64_t)1 << 63;
  uint32_t count[8][256];
  memset(count, 0, sizeof count);
  for (int i = 0; i < n; i++) {
    uint64_t u = (uint64_t)a[i].key ^ flip;
    for (int b = 0; b < 8; b++) count[b][(u >> (8 * b)) & 0xff]++;
  }
  struct rs_pair *src = a, *dst = tmp;
  for (int b = 0; b < 8; b++) {
    uint32_t first = (uint32_t)(((uint64_t)src[0].key ^ flip) >> (8 * b)) & 0xff;
    if (count[b][first] == (uint32_t)n) continue;      /* every key has this byte */
    uint32_t at[256], sum = 0;
    for (int d = 0; d < 256; d++) { at[d] = sum; sum += count[b][d]; }
    for (int i = 0; i < n; i++) {
      uint32_t d = (uint32_t)(((uint64_t)src[i].key ^ flip) >> (8 * b)) & 0xff;
      dst[at[d]++] = src[i];
    }
    struct rs_pair *t = src; src = dst; dst = t;
  }
  if (src != a) memcpy(a, src, (size_t)n * sizeof *a);
}

/* One pass of the merge: runs of width merged pairwise from src to dst, elements of SZ
   bytes (a constant where the size is known: the copies are then moves, not calls). The
   compares are those of the plain loop, in its order; a run's rest goes in one copy. */
#define MERGE_PASS(SZ)                                                                  \
  for (int lo = 0; lo < n; lo += 2 * width) {                                           \
    int mid = lo + width < n ? lo + width : n;                                          \
    int hi = lo + 2 * width < n ? lo + 2 * width : n;                                   \
    int i = lo, j = mid, k = lo;                                                        \
    while (i < mid && j < hi) {                                                         \
      if (cmp(src + (size_t)j * (SZ), src + (size_t)i * (SZ), ctx) < 0)                 \
        memcpy(dst + (size_t)k++ * (SZ), src + (size_t)j++ * (SZ), (SZ));               \
      else                                                                              \
        memcpy(dst + (size_t)k++ * (SZ), src + (size_t)i++ * (SZ), (SZ));               \
    }                                                                                   \
    int from = i < mid ? i : j, rest = i < mid ? mid - i : hi - j;                      \
    if (rest > 0)                                                                       \
      memcpy(dst + (size_t)k * (SZ), src + (size_t)from * (SZ), (size_t)rest * (SZ));   \
  }

void rsort_merge(void *base, int n, size_t sz, void *tmp, rs_cmp cmp, void *ctx)
{
  char *src = base, *dst = tmp;
  for (int width = 1; width < n; width *= 2) {
    if (sz == sizeof(int)) {                 /* the Visible Surface Procedure's indices */
      MERGE_PASS(sizeof(int))
    } else {
      MERGE_PASS(sz)
    }
    char *t = src; src = dst; dst = t;
  }
  if (src != (char *)base) memcpy(base, src, (size_t)n * sz);
}
