/*
** rsort.h — the renderer's two general sorts, host helpers rather than stages of paper
** 003:
**
**   rsort_pairs   (key, index) pairs by key, ties by index: the Mapper's T-junction x
**                 order and the lazy cut order (render.c); no 1974 work counted.
**   rsort_merge   a stable bottom-up merge sort with a comparison context: XSORT's rows
**                 and crossings (xsort.c), the Visible Surface Procedure's batches of new
**                 pieces (visible.c). Its comparison sequence is fixed by n alone (runs of
**                 1, 2, 4, ... merged left to right, the right element taken only when it
**                 is strictly less), so a caller that charges each compare as 1974 work
**                 gets the same count for the same input.
**
** rsort_pairs:
** Both sorted with qsort of (key, index) pairs before (issue 12: 8% of a 100,000-face
** render went to qsort's merge sort and its comparison calls). A least significant digit
** radix sort on the keys' bytes gives the same total order, exactly: it is stable, and the
** pairs arrive in ascending index, so equal keys stay in index order. The keys are taken
** less the least: only the bytes of their range are passed over (grid coordinates of both
** signs: 3 or 4 of the 8), and of those, bytes in which all keys agree are skipped.
*/
#ifndef T74_RSORT_H
#define T74_RSORT_H

#include <stddef.h>
#include <stdint.h>

struct rs_pair { int64_t key; int idx; };

/* Sort a[0..n) by key, ties by idx, given that the idx of equal keys already ascend in
   a's order (for instance a[k].idx == k, or any idx ascending along a). Uses scratch
   tmp[0..n). */
void rsort_pairs(struct rs_pair *a, struct rs_pair *tmp, int n);

/* Sort the n elements of size sz at base, stably, by cmp(x, y, ctx) (< 0: x first), with
   scratch tmp of n elements. */
typedef int (*rs_cmp)(const void *x, const void *y, void *ctx);
void rsort_merge(void *base, int n, size_t sz, void *tmp, rs_cmp cmp, void *ctx);

#endif
