/*
** shade.c — Lambert's law over the scene's lights (see shade.h).
*/
#include "render/shade.h"

#include <math.h>
#include <stdint.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* Normalise l (shade_dir's last step). */
static void unit_dir(double l[3])
{
  double n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  if (n > 0) for (int c = 0; c < 3; c++) l[c] /= n;
}

void shade_dir(const struct scene *s, int k, const double at[3], double l[3])
{
  const struct scene_light *L = &s->light[k];
  for (int c = 0; c < 3; c++) l[c] = L->point ? L->v[c] - at[c] : L->v[c];
  unit_dir(l);
}

void shade_lights_init(struct shade_lights *L, const struct scene *s)
{
  L->n = s->nlight;
  for (int k = 0; k < s->nlight; k++) {
    L->point[k] = s->light[k].point;
    for (int c = 0; c < 3; c++) L->v[k][c] = s->light[k].v[c];
    if (!L->point[k]) unit_dir(L->v[k]);
  }
}

void shade_point_dir(const double v[3], const double at[3], double l[3])
{
  for (int c = 0; c < 3; c++) l[c] = v[c] - at[c];
  unit_dir(l);
}

int shade_grey(const struct scene *s, const double n[3], const double at[3], double r,
               unsigned blocked)
{
  struct shade_lights L;
  shade_lights_init(&L, s);
  return shade_grey_lit(&L, n, at, r, blocked);
}

void shade_grey_lit_run(const struct shade_lights *L, const double n[3], int np,
                        const double (*at)[3], const double *r, const unsigned *blocked,
                        int *grey)
{
  double sum[SHADE_RUN];
  for (int p = 0; p < np; p++) sum[p] = 0;
  for (int k = 0; k < L->n; k++) {
    const double *v = L->v[k];
    if (!L->point[k]) {                     /* the same n.l at every point */
      const double d = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
      if (d > 0)
        for (int p = 0; p < np; p++) if (!(blocked[p] >> k & 1u)) sum[p] += d;
      continue;
    }
    /* unit_dir's steps, a step for all the points at a time; a length that is not
       positive divides nothing (x / 1 is x) */
    double l[3][SHADE_RUN], len[SHADE_RUN];
    for (int p = 0; p < np; p++) {
      for (int c = 0; c < 3; c++) l[c][p] = v[c] - at[p][c];
      len[p] = l[0][p] * l[0][p] + l[1][p] * l[1][p] + l[2][p] * l[2][p];
    }
    int q = 0;
#ifdef __SSE2__
    for (const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1); q + 2 <= np; q += 2) {
      const __m128d s = _mm_sqrt_pd(_mm_loadu_pd(len + q));
      const __m128d pos = _mm_cmpgt_pd(s, zero);
      const __m128d div = _mm_or_pd(_mm_and_pd(pos, s), _mm_andnot_pd(pos, one));
      for (int c = 0; c < 3; c++) _mm_storeu_pd(l[c] + q, _mm_div_pd(_mm_loadu_pd(l[c] + q), div));
    }
#endif
    for (; q < np; q++) {
      const double s = sqrt(len[q]);
      if (s > 0) for (int c = 0; c < 3; c++) l[c][q] /= s;
    }
    for (int p = 0; p < np; p++) {
      if (blocked[p] >> k & 1u) continue;
      const double d = n[0] * l[0][p] + n[1] * l[1][p] + n[2] * l[2][p];
      if (d > 0) sum[p] += d;
    }
  }
  for (int p = 0; p < np; p++) grey[p] = shade_grey_of_sum(r[p], sum[p]);
}

#ifdef __SSE2__
void shade_pair_init(struct shade_pair *P, const struct shade_lights *L, const double n[3])
{
  P->n = L->n;
  for (int c = 0; c < 3; c++) P->nv[c] = _mm_set1_pd(n[c]);
  const int nz = (n[0] != 0) + (n[1] != 0) + (n[2] != 0);
  P->axis = nz != 1 ? -1 : n[0] != 0 ? 0 : n[1] != 0 ? 1 : 2;
  for (int k = 0; k < L->n; k++) {
    const double *v = L->v[k];
    struct shade_pair_light *l = &P->l[k];
    l->point = L->point[k];
    l->bit = _mm_set1_epi32((int)(1u << k));
    if (L->point[k]) {
      for (int c = 0; c < 3; c++) l->v[c] = _mm_set1_pd(v[c]);
      continue;
    }
    const double d = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];   /* shade_grey_lit's */
    l->v[0] = _mm_set1_pd(d > 0 ? d : 0);
  }
}
#endif
