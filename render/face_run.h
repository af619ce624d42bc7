/*
** face_run.h — runs of one face along a row of points.
**
** Both engines give a frame as the face seen at each point centre, a row at a time; the
** stages after them (cli/pipeline.c's cells and greys, effects/model.c's shading and
** shadow masks) take a row a run of equal faces at a time. This is where such a run's end
** is found, four points a compare where the processor has SSE2. Static inline: it sits
** in those stages' inner loops.
*/
#ifndef T74_FACE_RUN_H
#define T74_FACE_RUN_H

#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* The end of the run of points from i (0 <= i < n) that see face[i]: the first e > i with
   face[e] != face[i], or n. */
static inline int face_run_end(const int *face, int i, int n)
{
  const int f = face[i];
  int e = i + 1;
#ifdef __SSE2__
  const __m128i fv = _mm_set1_epi32(f);
  for (; e + 4 <= n; e += 4) {              /* four points a compare */
    const __m128i x = _mm_loadu_si128((const __m128i *)(const void *)(face + e));
    const unsigned same = (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi32(x, fv));
    if (same != 0xffffu) return e + __builtin_ctz(~same) / 4;
  }
#endif
  while (e < n && face[e] == f) e++;
  return e;
}

#endif
