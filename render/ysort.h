/*
** ysort.h — YSORT: a face's vertices in ascending y (Segment Generator, 003 §2.2;
** used by §3.1 eq. (3), Fig. 6).
**
** INVARIANT: rows are in ascending exact y; vertices of equal y keep their input order
** (ring by ring, counter-clockwise), so the table does not depend on the sort.
**
** This file contains the table the Segment Generator reads its cut lines from: the paper
** "takes the y values from this table and finds the crossing points of the line parallel
** to the x axis with each edge" (003 §2.2). tube74 scans it from the bottom for the first
** vertex that is concave in the piece being cut; that vertex's y is the next cut line.
*/
#ifndef T74_YSORT_H
#define T74_YSORT_H

#include <stdint.h>
#include "emu/cost.h"
#include "render/geom.h"

/* One row: 3 words on the 16-bit machine: y (2 words: |y| <= 2^28 needs 30 bits),
   vertex id (1 word). */
#define YSORT_ROW_WORDS 3

struct ysort_row {
  gcoord   y;                      /* the vertex's y */
  uint32_t vid;                    /* its id as typed */
  int      index;                  /* its index in the face's point array */
};

/* Fill rows[0..n-1] with the n points in ascending y, ties in input order (stable merge
   sort on scratch, n rows). cost may be NULL. */
void ysort_build(const struct gpoint *pt, const uint32_t *vid, int n,
                 struct ysort_row *rows, struct ysort_row *scratch, struct cost *cost);

#endif
