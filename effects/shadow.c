/*
** shadow.c — the shadow polygons of paper 000 §3 (see shadow.h).
**
** Clipping (Sutherland-Hodgman, ring by ring) is done in space, on the occluder A, by
** half-spaces h(X) <= 0 that are affine in X: R's plane (A's part on the light's side),
** for a point light the plane through the light parallel to R (the part beyond the light
** casts nothing on R), and the six sides of R's box as they are seen through the
** projection Y(X) (Y is a projective map of X: Y = N(X) / w(X), N and w affine, w > 0 on
** the light's side, so "Y_c <= B" is the affine "N_c(X) - B w(X) <= 0"). Clipping each ring
** of an even-odd region by a half-space clips the region. The projection of a clipped
** ring's vertices onto R's plane and then onto the perspective plane is done in long double
** and rounded once onto the grid.
*/
#include "effects/shadow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef long double ld;

struct proj {
  bool point;
  ld P[3];                  /* the light: position, or direction towards it */
  ld pl[4];                 /* R's plane a, b, c, d (a X + d, plane(eye) < 0) */
  ld pP;                    /* point light: plane(P) */
  ld nL;                    /* parallel light: n . L (< 0: the light reaches R's seen side) */
};

static ld plane_at(const struct proj *q, const ld X[3])
{
  return q->pl[0] * X[0] + q->pl[1] * X[1] + q->pl[2] * X[2] + q->pl[3];
}

/* Component c of N(X) and w(X), with pX = plane_at(q, X): the shadow of X on R's plane
   is N / w. */
static ld image_n(const struct proj *q, const ld X[3], ld pX, int c)
{
  return q->P[c] * pX - X[c] * (q->point ? q->pP : q->nL);
}

static ld image_w(const struct proj *q, ld pX)
{
  return q->point ? pX - q->pP : -q->nL;
}

static void image(const struct proj *q, const ld X[3], ld pX, ld N[3], ld *w)
{
  for (int c = 0; c < 3; c++) N[c] = image_n(q, X, pX, c);
  *w = image_w(q, pX);
}

/* The clipping functionals at X, pX = plane_at(q, X): 0 R's plane, 1 beyond the point
   light, 2..7 the box (of the image, the one component the side needs). */
static ld h_at(const struct proj *q, const ld box[2][3], int k, const ld X[3], ld pX)
{
  if (k == 0) return pX;
  if (k == 1) return q->point ? q->pP - pX : -1;
  const int c = (k - 2) / 2;
  const ld Nc = image_n(q, X, pX, c), w = image_w(q, pX);
  return (k - 2) % 2 == 0 ? Nc - box[1][c] * w : box[0][c] * w - Nc;
}

/* Clip ring in[0..n) (pin: each vertex's plane_at) by h_k <= 0 into out (pout: theirs);
   returns the count, or -1 when the ring lies wholly in the half-space (h_k <= 0 at every
   vertex: the clipped ring is in itself, out not written). h: room for n values (each
   vertex's h_k, found once). */
static int clip(const struct proj *q, const ld box[2][3], int k, const ld (*in)[3],
                const ld *pin, int n, ld (*out)[3], ld *pout, ld *h)
{
  int m = 0;
  bool inside = true;
  for (int i = 0; i < n; i++) {
    h[i] = h_at(q, box, k, in[i], pin[i]);
    inside &= h[i] <= 0;
  }
  if (inside) return -1;
  for (int i = 0; i < n; i++) {
    const int j = i + 1 == n ? 0 : i + 1;
    const ld *a = in[i], *b = in[j];
    ld ha = h[i], hb = h[j];
    if (ha <= 0) { memcpy(out[m], a, sizeof out[0]); pout[m++] = pin[i]; }
    if ((ha < 0 && hb > 0) || (ha > 0 && hb < 0)) {
      ld t = ha / (ha - hb);
      for (int c = 0; c < 3; c++) out[m][c] = a[c] + t * (b[c] - a[c]);
      pout[m] = plane_at(q, out[m]);
      m++;
    }
  }
  return m;
}

int shadow_build(const struct mapped *map, const struct scene *s, struct fx_polys *out,
                 struct fx_stats *st, struct cost *cost, struct t74_error *err)
{
  int maxv = 3;
  for (int a = 0; a < s->nf; a++) {
    int n = s->f[a].ring_start[s->f[a].nring];
    if (n > maxv) maxv = n;
  }
  /* a ring clipped by 8 half-spaces gains at most one vertex per half-space */
  size_t cap = (size_t)maxv + 16;
  ld (*b0)[3] = malloc(cap * sizeof *b0), (*b1)[3] = malloc(cap * sizeof *b1);
  ld *hv = malloc(3 * cap * sizeof *hv), *p0 = hv ? hv + cap : NULL, *p1 = hv ? hv + 2 * cap : NULL;
  int *rs = malloc(((size_t)maxv + 2) * sizeof *rs);
  if (!b0 || !b1 || !hv || !rs) {
    free(b0); free(b1); free(hv); free(rs);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  struct gpoint *poly = NULL;
  size_t polycap = 0;
  long receivers = 0, polys0 = out->n;
  const ld E[3] = { (ld)map->eye[0], (ld)map->eye[1], (ld)map->eye[2] };
  int st_ = T74_OK;
  for (int R = 0; R < map->nface && st_ == T74_OK; R++) {
    const struct mface *mf = &map->f[R];
    const struct scene_face *sr = &s->f[mf->sface];
    if (sr->grey >= 0 || !s->has_light) continue;
    /* R's box in space (outer ring), one unit wider; and on the grid */
    ld box[2][3];
    for (int c = 0; c < 3; c++) box[0][c] = box[1][c] = mface_coord(map, mf, 0, c);
    gcoord gxlo = mf->pt[0].x, gxhi = gxlo, gylo = mf->pt[0].y, gyhi = gylo;
    for (int v = 1; v < mf->ring_start[1]; v++) {
      for (int c = 0; c < 3; c++) {
        if (mface_coord(map, mf, v, c) < box[0][c]) box[0][c] = mface_coord(map, mf, v, c);
        if (mface_coord(map, mf, v, c) > box[1][c]) box[1][c] = mface_coord(map, mf, v, c);
      }
      if (mf->pt[v].x < gxlo) gxlo = mf->pt[v].x;
      if (mf->pt[v].x > gxhi) gxhi = mf->pt[v].x;
      if (mf->pt[v].y < gylo) gylo = mf->pt[v].y;
      if (mf->pt[v].y > gyhi) gyhi = mf->pt[v].y;
    }
    for (int c = 0; c < 3; c++) { box[0][c] -= 1; box[1][c] += 1; }
    if (box[0][2] <= E[2]) box[0][2] = (E[2] + (ld)mface_coord(map, mf, 0, 2)) / 2;   /* stays before the eye */
    bool any = false;
    for (int k = 0; k < s->nlight && st_ == T74_OK; k++) {
      const struct scene_light *L = &s->light[k];
      struct proj q;
      q.point = L->point;
      q.pP = q.nL = 0;                       /* the one the light's kind uses is set below */
      for (int c = 0; c < 4; c++) q.pl[c] = (ld)mf->plane[c];
      for (int c = 0; c < 3; c++) q.P[c] = (ld)L->v[c];
      /* does the light reach R's seen side? exactly, in integers */
      if (L->point) {
        wide pv = (wide)mf->plane[0] * L->v[0] + (wide)mf->plane[1] * L->v[1] +
                  (wide)mf->plane[2] * L->v[2] + mf->plane[3];
        if (pv >= 0) continue;
        q.pP = plane_at(&q, q.P);
      } else {
        wide nl = (wide)mf->plane[0] * L->v[0] + (wide)mf->plane[1] * L->v[1] +
                  (wide)mf->plane[2] * L->v[2];
        if (nl >= 0) continue;
        q.nL = (ld)mf->plane[0] * q.P[0] + (ld)mf->plane[1] * q.P[1] + (ld)mf->plane[2] * q.P[2];
      }
      if (cost) COST_ADD_N(cost, COST_MEM, 6);
      for (int a = 0; a < s->nf && st_ == T74_OK; a++) {
        if (a == mf->sface) continue;
        const struct scene_face *fa = &s->f[a];
        int nv = fa->ring_start[fa->nring];
        /* coplanar with R, or wholly on R's far side: no shadow on R */
        bool near = false, off = false;
        for (int v = 0; v < nv; v++) {
          const struct scene_vertex *x = &s->v[fa->vidx[v]];
          wide pv = (wide)mf->plane[0] * x->x + (wide)mf->plane[1] * x->y +
                    (wide)mf->plane[2] * x->z + mf->plane[3];
          if (pv < 0) near = true;
          if (pv != 0) off = true;
        }
        for (int v = 0; cost && v < nv; v++) cost_mw_mul(cost, 34, 16);
        if (!near || !off) continue;
        size_t need = 0;
        int nring = 0;
        rs[0] = 0;
        for (int ring = 0; ring < fa->nring; ring++) {
          int lo = fa->ring_start[ring], n = fa->ring_start[ring + 1] - lo;
          for (int v = 0; v < n; v++) {
            const struct scene_vertex *x = &s->v[fa->vidx[lo + v]];
            b0[v][0] = x->x; b0[v][1] = x->y; b0[v][2] = x->z;
            p0[v] = plane_at(&q, b0[v]);
          }
          /* the ring and each vertex's plane_at, found once (the same value each use) */
          ld (*in)[3] = b0, (*o)[3] = b1, *pin = p0, *po = p1;
          for (int h = 0; h < 8 && n >= 3; h++) {
            const int nc = clip(&q, box, h, (const ld (*)[3])in, pin, n, o, po, hv);
            if (nc >= 0) {                  /* else the ring as it is */
              n = nc;
              ld (*t)[3] = in; in = o; o = t;
              ld *tp = pin; pin = po; po = tp;
            }
            for (int v = 0; cost && v < n; v++) { cost_mw_mul(cost, 32, 32); cost_mw_mul(cost, 32, 32); }
          }
          if (n < 3) continue;
          if (need + (size_t)n > polycap) {
            size_t nc = polycap ? 2 * polycap : 64;
            while (nc < need + (size_t)n) nc *= 2;
            struct gpoint *np = realloc(poly, nc * sizeof *np);
            if (!np) { st_ = t74_fail(err, T74_EIO, "out of host memory"); break; }
            poly = np;
            polycap = nc;
          }
          int m = 0;
          for (int v = 0; v < n; v++) {
            ld N[3], w;
            image(&q, in[v], pin[v], N, &w);
            if (!(w > 0)) continue;
            ld Y[3] = { N[0] / w, N[1] / w, N[2] / w };
            ld f = -E[2], dz = Y[2] - E[2];
            if (!(dz > 0)) continue;
            ld gx = (ld)GRID_ONE * (E[0] + f * (Y[0] - E[0]) / dz);
            ld gy = (ld)GRID_ONE * (E[1] + f * (Y[1] - E[1]) / dz);
            if (fabsl(gx) > (ld)GRID_LIMIT || fabsl(gy) > (ld)GRID_LIMIT) continue;
            struct gpoint g = { fx_round_ld(gx), fx_round_ld(gy) };
            if (m > 0 && poly[need + (size_t)m - 1].x == g.x && poly[need + (size_t)m - 1].y == g.y) continue;
            poly[need + (size_t)m++] = g;
            if (cost) {
              for (int c = 0; c < 4; c++) cost_mw_mul(cost, 32, 32);
              cost_mw_div(cost, 64, 32); cost_mw_div(cost, 64, 32);
            }
          }
          if (m > 1 && poly[need].x == poly[need + (size_t)m - 1].x && poly[need].y == poly[need + (size_t)m - 1].y) m--;
          if (m < 3) continue;
          need += (size_t)m;
          rs[++nring] = (int)need;
        }
        if (st_ != T74_OK || nring == 0) continue;
        /* drop shadows that miss R's box on the grid */
        gcoord sxlo = poly[0].x, sxhi = sxlo, sylo = poly[0].y, syhi = sylo;
        for (size_t v = 1; v < need; v++) {
          if (poly[v].x < sxlo) sxlo = poly[v].x;
          if (poly[v].x > sxhi) sxhi = poly[v].x;
          if (poly[v].y < sylo) sylo = poly[v].y;
          if (poly[v].y > syhi) syhi = poly[v].y;
        }
        if (sxhi <= gxlo || sxlo >= gxhi || syhi <= gylo || sylo >= gyhi) continue;
        if (!fx_polys_add(out, nring, rs, poly, R, k)) st_ = t74_fail(err, T74_EIO, "out of host memory");
        any = true;
      }
    }
    receivers += any;
  }
  free(b0); free(b1); free(hv); free(rs); free(poly);
  if (st_ == T74_OK) {
    fx_count(st, "shadow_polygons", (double)(out->n - polys0), true);
    fx_count(st, "shadow_receivers", (double)receivers, true);
  }
  return st_;
}
