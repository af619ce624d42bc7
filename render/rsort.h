/*
** rsort.h — sorting (key, index) pairs by key, ties by index: a host helper of the
** Mapper (its T-junction search's x order) and the lazy cut order (render.c), not a
** stage of paper 003 and not counted as 1974 work.
**
** Both sorted with qsort of (key, index) pairs before (issue 12: 8% of a 100,000-face
** render went to qsort's merge sort and its comparison calls). A least significant digit
** radix sort on the keys' bytes gives the same total order, exactly: it is stable, and the
** pairs arrive in ascending index, so equal keys stay in index order. Bytes in which all
** keys agree are skipped (grid coordinates use 4 of the 8).
*/
#ifndef T74_RSORT_H
#define T74_RSORT_H

#include <stdint.h>

struct rs_pair { int64_t key; int idx; };

/* Sort a[0..n) by key, ties by idx, given that the idx of equal keys already ascend in
   a's order (for instance a[k].idx == k, or any idx ascending along a). Uses scratch
   tmp[0..n). */
void rsort_pairs(struct rs_pair *a, struct rs_pair *tmp, int n);

#endif
