/*
** points_at.c — the points engine at any sample (see points_at.h): one row of a lattice K
** times finer than the points, every face met on it in exact integers.
**
** Numbers (the scene reader keeps coordinates in 16 bits; the Mapper keeps |gcoord| <= 2^28,
** |a|, |b|, |c| < 2^34 and |D| = deye < 2^52, render/mapper.c):
**
** The lattice.  xd = 2 K W, yd = 2 K H; points_at_row refuses xd or yd above 2^13 (the
** contract's grid at K = 16 is 4256 x 3200). Sample k lies at x = XN(k) / xd grid units,
** XN(k) = GRID_ONE (xd XL + (2k + 1)(XR - XL)); row m at y = yn / yd,
** yn = GRID_ONE (yd YT - (2m + 1)(YT - YB)), |yn| < 2^8 (2^13 2^15 + 2^14 2^16) < 2^39.
**
** Crossings.  An edge from (x0, y0) up to (x1, y1) meets the row when y0 yd <= yn < y1 yd
** (the sample shifted up by e^2: geom.h's tie rule). Its crossing lies at or left of sample
** k (the sample then belongs to the side right of the edge) when (2k + 1) D >= R with
** D = S dy yd, S = GRID_ONE (XR - XL), R = xd (x0 dy yd + (yn - y0 yd) dx) - GRID_ONE xd
** XL dy yd: D < 2^24 2^29 2^13 = 2^66, |yn - y0 yd| < 2^42, |R| < 2^13 (2^70 + 2^42 2^29)
** + 2^78 < 2^86, in 128 bits. The first such k is floor(ceil(R / D) / 2), one division a
** crossing.
**
** Depth.  With Xc = xd (x - Ex) = xd (XL - Ex) + (2k + 1)(XR - XL) and Yc = yd (y - Ey), in
** world units, P = xd yd n.u = a yd Xc + b xd Yc - c xd yd Ez, linear in k. Samples lie at
** most one point beyond the window (W, H >= 2): |x - Ex| < 2^17, so |Xc| < 2^30,
** |Yc| < 2^30 and |P| < 2^34 (2 2^13 2^30 + 2^26 2^15) < 2^79; alpha = 2 a yd (XR - XL)
** < 2^64. A is in front of B when |D_B| P_A > |D_A| P_B; the products reach 2^131, so they
** are taken in 128 bits while both P are below 2^74 (products below 2^126) and in 256 bits
** (geom_cross_sign) beyond. Equal depth: mface_tie_front (render/mapper.h), the rule
** points.c follows too.
*/
#include "render/points_at.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "render/geom.h"

/* Room for n elements of size sz in *buf (capacity *cap); false when the host has none. */
static bool room(void **buf, int *cap, int n, size_t sz)
{
  if (n <= *cap) return true;
  void *nb = realloc(*buf, (size_t)n * 2 * sz);
  if (!nb) return false;
  *buf = nb;
  *cap = n * 2;
  return true;
}

/* Each face's extent in y, once a frame. */
static int extents(struct points_at *q, const struct points *p, struct t74_error *err)
{
  if (q->of == p && q->nface == p->map.nface) return T74_OK;
  q->of = NULL;
  free(q->ylo);
  free(q->yhi);
  int n = p->map.nface;
  q->ylo = malloc(((size_t)n + 1) * sizeof *q->ylo);
  q->yhi = malloc(((size_t)n + 1) * sizeof *q->yhi);
  if (!q->ylo || !q->yhi) return t74_fail(err, T74_EIO, "out of host memory");
  for (int k = 0; k < n; k++) {
    const struct mface *f = &p->map.f[k];
    int64_t lo = f->pt[0].y, hi = lo;
    for (int v = 1; v < f->ring_start[f->nring]; v++) {
      if (f->pt[v].y < lo) lo = f->pt[v].y;
      if (f->pt[v].y > hi) hi = f->pt[v].y;
    }
    q->ylo[k] = lo;
    q->yhi[k] = hi;
  }
  q->of = p;
  q->nface = n;
  return T74_OK;
}

/* Is face k (P_k) in front of face o (P_o) at the sample? points.c's in_front, at the
   lattice's scale. */
static bool front(wide Pk, const struct mface *fk, wide Po, const struct mface *fo)
{
  int s;
  if (Pk <= 0 || Po <= 0) s = (Pk > 0) - (Po > 0);
  else {
    const wide lim = (wide)1 << 74;
    if (Pk < lim && Po < lim) {
      wide l = (wide)fo->deye * Pk, r = (wide)fk->deye * Po;
      s = (l > r) - (l < r);
    } else {
      s = geom_cross_sign(fo->deye, Pk, fk->deye, Po);
    }
    if (s == 0) return mface_tie_front(fk, fo); /* on the two planes' intersection line */
  }
  if (s == 0) return mface_coplanar_front(fk, fo);
  return s > 0;
}

bool points_at_lattice_ok(const struct vis_grid *g, int K, int64_t m, int64_t k0, int n)
{
  const int64_t xd = 2 * (int64_t)K * g->W, yd = 2 * (int64_t)K * g->H;
  return K >= 1 && K <= POINTS_AT_KMAX && g->W >= 2 && g->H >= 2 && xd <= 8192 &&
         yd <= 8192 && n >= 0 && k0 >= -K && k0 + n <= (int64_t)K * (g->W + 1) && m >= -K &&
         m < (int64_t)K * (g->H + 1) && g->window[0] < g->window[2] &&
         g->window[1] < g->window[3];
}

int points_at_row(struct points_at *q, const struct points *p, const struct vis_grid *g, int K,
                  int64_t m, int64_t k0, int n, const uint8_t *skip, int *face,
                  struct t74_error *err)
{
  const int64_t XL = g->window[0], YB = g->window[1], XR = g->window[2], YT = g->window[3];
  const int64_t xd = 2 * (int64_t)K * g->W, yd = 2 * (int64_t)K * g->H;
  if (!points_at_lattice_ok(g, K, m, k0, n))
    return t74_fail(err, T74_EIO, "points_at_row: sample lattice out of range");
  int st = extents(q, p, err);
  if (st != T74_OK) return st;
  if (!room((void **)&q->depth, &q->depthcap, n + 1, sizeof *q->depth))
    return t74_fail(err, T74_EIO, "out of host memory");
  for (int i = 0; i < n; i++) face[i] = -1;
  const wide yn = (wide)GRID_ONE * (yd * YT - (2 * m + 1) * (YT - YB));
  const wide S = (wide)GRID_ONE * (XR - XL);
  const wide Xc0 = (wide)xd * (XL - p->map.eye[0]) + (XR - XL);      /* Xc at k = 0 */
  const wide Yc = (wide)yd * (YT - p->map.eye[1]) - (2 * m + 1) * (YT - YB);
  const struct mface *F = p->map.f;
  for (int k = 0; k < p->map.nface; k++) {
    if (p->skip[k] || (skip && skip[k])) continue;
    if (yn < (wide)q->ylo[k] * yd || yn >= (wide)q->yhi[k] * yd) continue;
    const struct mface *f = &F[k];
    if (!room((void **)&q->col, &q->colcap, f->ring_start[f->nring], sizeof *q->col))
      return t74_fail(err, T74_EIO, "out of host memory");
    int nc = 0;
    for (int r = 0; r < f->nring; r++) {
      int lo = f->ring_start[r], hi = f->ring_start[r + 1];
      for (int v = lo; v < hi; v++) {
        struct gpoint a = f->pt[v], b = f->pt[v + 1 < hi ? v + 1 : lo];
        if (a.y == b.y) continue;
        if (a.y > b.y) { struct gpoint t = a; a = b; b = t; }
        if (yn < (wide)a.y * yd || yn >= (wide)b.y * yd) continue;
        wide dx = b.x - a.x, dy = b.y - a.y;
        wide D = S * dy * yd;
        wide R = xd * ((wide)a.x * dy * yd + (yn - (wide)a.y * yd) * dx) -
                 (wide)GRID_ONE * xd * XL * dy * yd;
        wide c = geom_rat_ceil((struct grat){ R, D });
        c = geom_rat_floor((struct grat){ c, 2 }) - k0;
        if (c < 0) c = 0;
        if (c > n) c = n;
        q->col[nc++] = (int32_t)c;
      }
    }
    for (int x = 1; x < nc; x++) {              /* insertion sort: a row holds few */
      int32_t t = q->col[x];
      int y = x - 1;
      while (y >= 0 && q->col[y] > t) { q->col[y + 1] = q->col[y]; y--; }
      q->col[y + 1] = t;
    }
    const wide a = f->plane[0], b = f->plane[1], c = f->plane[2];
    const wide alpha = 2 * a * yd * (XR - XL);          /* P grows by this a sample right */
    const wide P0 = a * yd * Xc0 + b * xd * Yc - c * xd * yd * p->map.eye[2];
    for (int x = 0; x + 1 < nc; x += 2) {
      for (int32_t i = q->col[x]; i < q->col[x + 1]; i++) {
        wide P = P0 + alpha * (k0 + i);
        int o = face[i];
        if (o < 0 || front(P, f, q->depth[i], &F[o])) { face[i] = k; q->depth[i] = P; }
      }
    }
  }
  return T74_OK;
}

void points_at_free(struct points_at *q)
{
  free(q->ylo);
  free(q->yhi);
  free(q->col);
  free(q->depth);
  memset(q, 0, sizeof *q);
}
