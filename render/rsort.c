/*
** rsort.c — the renderer's general sorts (rsort.h): (key, index) pairs by key for the
** Mapper's T-junction search and the lazy cut order, and a stable merge sort for XSORT
** and the Visible Surface Procedure; no 1974 work is counted here (callers charge their
** own compares).
**
** This file contains a least significant digit radix sort: the keys taken less the
** least (so signed keys sort as unsigned, and only the bytes of the keys' range count),
** one histogram pass over those bytes, then one stable scatter pass for each byte in
** which the keys differ. Stable, so pairs of equal
** key keep the (ascending) order of their indices.
*/
#include "render/rsort.h"

#include <string.h>

void rsort_pairs(struct rs_pair *a, struct rs_pair *tmp, int n)
{
  if (n < 2) return;
  /* the keys taken less the least, as unsigned (key - lo, exact modulo 2^64 and below
     2^64 for any two int64 keys): the same order as the keys', and only the bytes of
     hi - lo can differ, where the sign bit flipped kept all eight for keys of both signs
     (grid coordinates about 0: eight scatter passes instead of three or four) */
  int64_t lo = a[0].key, hi = a[0].key;
  for (int i = 1; i < n; i++) {
    if (a[i].key < lo) lo = a[i].key;
    if (a[i].key > hi) hi = a[i].key;
  }
  const uint64_t base = (uint64_t)lo, range = (uint64_t)hi - base;
  int nb = 0;
  while (nb < 8 && range >> (8 * nb)) nb++;
  if (nb == 0) return;                       /* every key alike: already in index order */
  uint32_t count[8][256];
  memset(count, 0, (size_t)nb * sizeof count[0]);
  for (int i = 0; i < n; i++) {
    uint64_t u = (uint64_t)a[i].key - base;
    for (int b = 0; b < nb; b++) count[b][(u >> (8 * b)) & 0xff]++;
  }
  struct rs_pair *src = a, *dst = tmp;
  for (int b = 0; b < nb; b++) {
    uint32_t first = (uint32_t)(((uint64_t)src[0].key - base) >> (8 * b)) & 0xff;
    if (count[b][first] == (uint32_t)n) continue;      /* every key has this byte */
    uint32_t at[256], sum = 0;
    for (int d = 0; d < 256; d++) { at[d] = sum; sum += count[b][d]; }
    for (int i = 0; i < n; i++) {
      uint32_t d = (uint32_t)(((uint64_t)src[i].key - base) >> (8 * b)) & 0xff;
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
