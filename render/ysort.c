/*
** ysort.c — YSORT, the face's vertex y values in ascending order.
** Stage: Segment Generator (003 §2.2; used by §3.1 eq. (3), Fig. 6).
**
** INVARIANT: rows ascending by y; equal y in input order (the sort is stable).
**
** This file contains the sort. Paper 003 registers "the coordinates of the mapped
** vertices in ascending order" in YSORT; y is an exact grid coordinate (geom.h), so the
** comparison is an integer subtract of 30 bits (two words on the HITAC-10), counted as
** such. A bottom-up merge sort on the caller's scratch rows: n log n compares, no
** allocation, stable so that equal y keep the boundary order the trace shows.
*/
#include "render/ysort.h"

void ysort_build(const struct gpoint *pt, const uint32_t *vid, int n,
                 struct ysort_row *rows, struct ysort_row *scratch, struct cost *cost)
{
  for (int i = 0; i < n; i++) {
    rows[i].y = pt[i].y;
    rows[i].vid = vid[i];
    rows[i].index = i;
    if (cost) COST_ADD_N(cost, COST_MEM, YSORT_ROW_WORDS);     /* row stored */
  }
  struct ysort_row *src = rows, *dst = scratch;
  for (int width = 1; width < n; width *= 2) {
    for (int lo = 0; lo < n; lo += 2 * width) {
      int mid = lo + width < n ? lo + width : n;
      int hi = lo + 2 * width < n ? lo + 2 * width : n;
      int i = lo, j = mid, k = lo;
      while (i < mid && j < hi) {
        if (cost) cost_mw_add(cost, 30);                     /* y_j - y_i */
        dst[k++] = src[j].y < src[i].y ? src[j++] : src[i++];
      }
      while (i < mid) dst[k++] = src[i++];
      while (j < hi) dst[k++] = src[j++];
      if (cost) COST_ADD_N(cost, COST_MEM, 2 * YSORT_ROW_WORDS * (hi - lo));
    }
    struct ysort_row *t = src; src = dst; dst = t;
  }
  if (src != rows)
    for (int i = 0; i < n; i++) rows[i] = src[i];
}
