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
#include "emu/grow.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__SSE2__) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CASTS_AVX512 1            /* grid_all4 built, taken where the processor has it */
#endif

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

/* Shadows in space: the rings a face R receives, cast by cast (one occluder A from one
   light), each vertex the image Y = N / w (w > 0) of a clipped vertex of A on R's plane.
   They depend on the scene, its lights and R's plane and box in space alone: the view's
   part (onto the perspective plane, rounded onto the grid) is draw_casts'. Each array
   grows by doubling; cast c's rings are ring[c.r0 .. c.r1), ring r's vertices
   y[r ? yend[r - 1] : 0 .. yend[r]). */
struct cast { int light, r0, r1; };
struct casts {
  struct cast *c;
  int n, nring;
  size_t cap, capring;
  size_t *yend;
  ld (*y)[3];
  double (*yd)[3];          /* each y's nearest doubles (shadow_near) */
  size_t ny, capy, capyd;
};

static void casts_free(struct casts *cs)
{
  free(cs->c); free(cs->yend); free(cs->y); free(cs->yd);
  memset(cs, 0, sizeof *cs);
}

/* The scratch of the clipping: two rings and their plane_at values, and h values; room
   for cap vertices each (a ring clipped by 8 half-spaces gains at most one vertex per
   half-space). rs: room for a polygon's ring offsets. */
struct work {
  ld (*b0)[3], (*b1)[3];
  ld *hv, *p0, *p1;
  size_t cap;
  int *rs;
  struct gpoint *g;         /* draw_casts: its casts' vertices on the grid (grid_all) */
  size_t gcap;
};

/* R's box in space (outer ring), exactly, in integers: lo[c], hi[c]. */
static void space_box(const struct mapped *map, const struct mface *mf, int32_t lo[3], int32_t hi[3])
{
  for (int c = 0; c < 3; c++) lo[c] = hi[c] = mface_coord(map, mf, 0, c);
  for (int v = 1; v < mf->ring_start[1]; v++)
    for (int c = 0; c < 3; c++) {
      const int32_t x = mface_coord(map, mf, v, c);
      if (x < lo[c]) lo[c] = x;
      if (x > hi[c]) hi[c] = x;
    }
}

/* The casts on face R (mf) of scene s, its box in space one unit wider (box), appended to
   cs; false when out of host memory. Counted in cost (NULL: not counted). */
static bool cast_face(const struct mface *mf, const struct scene *s, const ld box[2][3],
                      struct work *wk, struct casts *cs, struct cost *cost)
{
  for (int k = 0; k < s->nlight; k++) {
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
    for (int a = 0; a < s->nf; a++) {
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
      const int r0 = cs->nring;
      for (int ring = 0; ring < fa->nring; ring++) {
        int lo = fa->ring_start[ring], n = fa->ring_start[ring + 1] - lo;
        for (int v = 0; v < n; v++) {
          const struct scene_vertex *x = &s->v[fa->vidx[lo + v]];
          wk->b0[v][0] = x->x; wk->b0[v][1] = x->y; wk->b0[v][2] = x->z;
          wk->p0[v] = plane_at(&q, wk->b0[v]);
        }
        /* the ring and each vertex's plane_at, found once (the same value each use) */
        ld (*in)[3] = wk->b0, (*o)[3] = wk->b1, *pin = wk->p0, *po = wk->p1;
        for (int h = 0; h < 8 && n >= 3; h++) {
          const int nc = clip(&q, box, h, (const ld (*)[3])in, pin, n, o, po, wk->hv);
          if (nc >= 0) {                  /* else the ring as it is */
            n = nc;
            ld (*t)[3] = in; in = o; o = t;
            ld *tp = pin; pin = po; po = tp;
          }
          for (int v = 0; cost && v < n; v++) { cost_mw_mul(cost, 32, 32); cost_mw_mul(cost, 32, 32); }
        }
        if (n < 3) continue;
        if (!t74_grow((void **)&cs->y, &cs->capy, cs->ny + (size_t)n, sizeof *cs->y) ||
            !t74_grow((void **)&cs->yd, &cs->capyd, cs->ny + (size_t)n, sizeof *cs->yd))
          return false;
        size_t m = cs->ny;
        for (int v = 0; v < n; v++) {
          ld N[3], w;
          image(&q, in[v], pin[v], N, &w);
          if (!(w > 0)) continue;
          for (int c = 0; c < 3; c++) cs->y[m][c] = N[c] / w;
          shadow_near(cs->y[m], cs->yd[m]);
          m++;
        }
        if (m - cs->ny < 3) continue;     /* fewer than 3 points on the grid, whatever the view */
        if (!t74_grow((void **)&cs->yend, &cs->capring, (size_t)cs->nring + 1, sizeof *cs->yend)) return false;
        cs->ny = m;
        cs->yend[cs->nring++] = m;
      }
      if (cs->nring == r0) continue;
      if (!t74_grow((void **)&cs->c, &cs->cap, (size_t)cs->n + 1, sizeof *cs->c)) return false;
      cs->c[cs->n++] = (struct cast){ k, r0, cs->nring };
    }
  }
  return true;
}

void shadow_eye_set(struct shadow_eye *v, const int64_t E[3])
{
  v->near = true;
  for (int c = 0; c < 3; c++) {
    v->E[c] = (ld)E[c];
    v->e[c] = (double)E[c];
    v->near &= E[c] > -((int64_t)1 << 40) && E[c] < (int64_t)1 << 40;
  }
}

bool shadow_grid_ld(const struct shadow_eye *v, const ld Y[3], struct gpoint *g)
{
  const ld *E = v->E;
  ld f = -E[2], dz = Y[2] - E[2];
  if (!(dz > 0)) return false;
  ld gx = (ld)GRID_ONE * (E[0] + f * (Y[0] - E[0]) / dz);
  ld gy = (ld)GRID_ONE * (E[1] + f * (Y[1] - E[1]) / dz);
  if (fabsl(gx) > (ld)GRID_LIMIT || fabsl(gy) > (ld)GRID_LIMIT) return false;
  g->x = fx_round_ld(gx);
  g->y = fx_round_ld(gy);
  return true;
}

void shadow_near(const ld Y[3], double yd[3])
{
  bool normal = true;
  for (int c = 0; c < 3; c++)
    normal &= Y[c] == 0 || (fabsl(Y[c]) >= 0x1p-1000L && fabsl(Y[c]) < 0x1p1000L);
  for (int c = 0; c < 3; c++) yd[c] = normal ? (double)Y[c] : NAN;
}

/* The filter. u = 2^-53 (a double's rounding, |fl(x) - x| <= u |fl(x)| and <= u |x|),
   u' = 2^-64 (a long double's), G = GRID_ONE (a power of two: products by it exact). Y
   the long doubles, y = yd their nearest doubles: |y_c - Y_c| <= u |Y_c|, Y_c 0 or normal
   (shadow_near), and E's components exact in doubles (|E| < 2^40). For a coordinate c
   (x or y) let A = Y_c - E_c, D = Y_z - E_z, q = -E_z A / D (real numbers), and in doubles
   a = fl(y_c - E_c), dz = fl(y_z - E_z), r = fl(1 / dz), q' = fl(fl(-E_z a) r),
   s = fl(E_c + q'), gx' = G s.
   - |a - A| <= u |a| + u |Y_c| <= ea (1 + 2u), ea = u (|a| + |y_c|); likewise
     |dz - D| <= ed (1 + 2u), ed = u (|dz| + |y_z|). Accepted only when
     fl(ed) < fl(dz 2^-20): then D > dz (1 - 2^-19) > 0, so the long way's dz (Y_z - E_z
     rounded, of D's sign) is positive: the vertex is before the eye.
   - |q' - q| <= |q' - (-E_z a / dz)| + |E_z| |a D - A dz| / (dz D)
              <= 3.02 u |q'| + |E_z| (|a| |D - dz| + dz |a - A|) / (dz D)
              <= 3.02 u |q'| + 1.0001 T, T = |E_z| (|a| ed + dz ea) r^2
     (1 / (dz D) <= r^2 (1 + u)^2 / (1 - 2^-19)), and |s - (E_c + q')| <= u (|E_c| + |q'|):
     |gx' - G (E_c + q)| <= G (1.0001 T + 4.02 u |q'| + u |E_c|).
   - The long way, s1 = A (1 + a1), s2 = -E_z s1 (1 + a2), its dz = D (1 + a4),
     s3 = s2 / dz (1 + a3) = q (1 + t), |t| <= 4.01 u', s4 = (E_c + s3)(1 + a5), gx = G s4:
     |gx - G (E_c + q)| <= G u' (5.02 |q| + |E_c|) <= G 6 u' (|q'| + 1 + |E_c|) where
     G |q - q'| < 1/2 (as below), and 6 u' < 0.003 u.
   So |gx - gx'| <= G 1.0001 (T + 5 u (|q'| + |E_c| + 1)), and B, that times 1.01/1.0001
   found in doubles (a dozen roundings, each within 1 + u: B is not below the bound). With
   k an integer, fl(|gx' - k| + B) < 1/2 (a rounding cannot take a sum of 1/2 or more below
   1/2) gives |gx - k| < 1/2: the long way rounds gx to k, whichever way it breaks ties,
   and with |k| < 2^28, |gx| < GRID_LIMIT: the vertex is not dropped for its size either.
   (gx' - k is exact when it is below 1/2: Sterbenz, or k = 0.) */
static inline int grid_near(const struct shadow_eye *v, const double yd[3], struct gpoint *g)
{
  const double u = 0x1p-53, G = (double)GRID_ONE;
  const double dz = yd[2] - v->e[2], ed = u * (fabs(dz) + fabs(yd[2]));
  if (!v->near || !(ed < dz * 0x1p-20)) return -1;        /* also dz <= 0, and NaN */
  const double r = 1 / dz, fz = -v->e[2], r2 = r * r;
#ifdef __SSE2__
  /* x in lane 0, y in lane 1: each lane's operations the loop's below on its values, in
     their order (correctly rounded, as the scalar ones are), the rounding half away from
     zero a truncation (CVTTPD2DQ: |gx| < 2^28) of gx plus 0.5 of gx's sign (at gx = -0,
     -0.5: 0 as the loop's 0.5) */
  const __m128d mag = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX));
  const __m128d half = _mm_set1_pd(0.5), lim = _mm_set1_pd(0x1p28);
  const __m128d Y = _mm_loadu_pd(yd), Ev = _mm_loadu_pd(v->e);
  const __m128d a = _mm_sub_pd(Y, Ev), aa = _mm_and_pd(a, mag);
  const __m128d ea = _mm_mul_pd(_mm_set1_pd(u), _mm_add_pd(aa, _mm_and_pd(Y, mag)));
  const __m128d q = _mm_mul_pd(_mm_mul_pd(_mm_set1_pd(fz), a), _mm_set1_pd(r));
  const __m128d gx = _mm_mul_pd(_mm_set1_pd(G), _mm_add_pd(Ev, q));
  const __m128d t1 = _mm_mul_pd(_mm_mul_pd(_mm_set1_pd(fabs(fz)),
                                           _mm_add_pd(_mm_mul_pd(aa, _mm_set1_pd(ed)),
                                                      _mm_mul_pd(_mm_set1_pd(dz), ea))),
                                _mm_set1_pd(r2));
  const __m128d t2 = _mm_mul_pd(_mm_set1_pd(5 * u),
                                _mm_add_pd(_mm_add_pd(_mm_and_pd(q, mag), _mm_and_pd(Ev, mag)),
                                           _mm_set1_pd(1)));
  const __m128d B = _mm_mul_pd(_mm_set1_pd(1.01 * G), _mm_add_pd(t1, t2));
  if (_mm_movemask_pd(_mm_cmplt_pd(_mm_and_pd(gx, mag), lim)) != 3) return -1;
  const __m128d sign = _mm_andnot_pd(mag, gx);
  const __m128i k = _mm_cvttpd_epi32(_mm_add_pd(gx, _mm_or_pd(sign, half)));
  const __m128d kd = _mm_cvtepi32_pd(k);
  if (_mm_movemask_pd(_mm_and_pd(_mm_cmplt_pd(_mm_and_pd(kd, mag), lim),
                                 _mm_cmplt_pd(_mm_add_pd(_mm_and_pd(_mm_sub_pd(gx, kd), mag), B),
                                              half))) != 3)
    return -1;
  g->x = (gcoord)_mm_cvtsi128_si32(k);
  g->y = (gcoord)_mm_cvtsi128_si32(_mm_shuffle_epi32(k, 1));
  return 1;
#else
  int64_t k[2];
  for (int c = 0; c < 2; c++) {
    const double a = yd[c] - v->e[c], ea = u * (fabs(a) + fabs(yd[c]));
    const double q = fz * a * r, gx = G * (v->e[c] + q);
    const double B = 1.01 * G * (fabs(fz) * (fabs(a) * ed + dz * ea) * r2 +
                                 5 * u * (fabs(q) + fabs(v->e[c]) + 1));
    if (!(fabs(gx) < 0x1p28)) return -1;
    k[c] = (int64_t)(gx >= 0 ? gx + 0.5 : gx - 0.5);
    if (!(k[c] > -GRID_LIMIT && k[c] < GRID_LIMIT && fabs(gx - (double)k[c]) + B < 0.5))
      return -1;
  }
  g->x = (gcoord)k[0];
  g->y = (gcoord)k[1];
  return 1;
#endif
}

int shadow_grid_near(const struct shadow_eye *v, const double yd[3], struct gpoint *g)
{
  return grid_near(v, yd, g);
}

/* The filter with one bound for many vertices. Every operation that makes grid_near's
   bound B (in the lanes and in the loop alike: ed, r = fl(1 / dz), r2, |a|, ea, |q|,
   t1, t2, B) is a rounded sum, product or quotient of values that are not negative, and
   rounding to nearest is monotone: B does not decrease when an operand that is summed or
   multiplied grows, or when dz, which it divides, shrinks. For a vertex yd within span sp
   (|yd[c]| <= ax[c], zlo <= yd[2] <= zhi) and dzlo = fl(zlo - e_z) > 0:
   dz = fl(yd_z - e_z) lies in [dzlo, dzhi], dzhi = fl(zhi - e_z), so |dz| = dz <= dzhi and
   r <= rm = fl(1 / dzlo); |yd_z| <= zm = max(|zlo|, |zhi|), so ed <= edm =
   fl(u fl(dzhi + zm)); |a| = fl(|yd_c - e_c|) <= am = fl(ax[c] + |e_c|) (|yd_c - e_c| <=
   ax[c] + |e_c|); |q| = fl(fl(|e_z| |a|) r) <= fl(fl(|e_z| am) rm) (rounding is
   symmetric). So shadow_bound_set's B[c], grid_near's own operations on those bounds in
   the same order, is not below grid_near's B for any vertex of sp, and when
   edm < fl(dzlo 2^-20), each vertex's ed < fl(dz 2^-20) too: grid_near's first test
   passes at every vertex. spanned_point makes grid_near's gx and k by the same
   operations (with SSE2 k is the integer nearest gx instead: see spanned_lanes);
   when fl(|gx - k| + B[c]) < 1/2 (and the tests on |gx| and |k|, the same),
   fl(|gx - k| + grid_near's B) is not above it: grid_near's test passes with that k too,
   and its proof (for any integer k) gives shadow_grid_ld's point. */
void shadow_span_init(struct shadow_span *sp)
{
  sp->ax[0] = sp->ax[1] = 0;
  sp->zlo = INFINITY;
  sp->zhi = -INFINITY;
  sp->ok = true;
}

/* (Plain compares, no library calls: where a coordinate is NaN the span is not ok, and
   what its extents hold then does not matter.) */
static inline void span_add(struct shadow_span *sp, const double yd[3])
{
  const double x = fabs(yd[0]), y = fabs(yd[1]), z = yd[2];
  sp->ok &= x == x && y == y && z == z;
  sp->ax[0] = x > sp->ax[0] ? x : sp->ax[0];
  sp->ax[1] = y > sp->ax[1] ? y : sp->ax[1];
  sp->zlo = z < sp->zlo ? z : sp->zlo;
  sp->zhi = z > sp->zhi ? z : sp->zhi;
}

void shadow_span_add(struct shadow_span *sp, const double yd[3])
{
  span_add(sp, yd);
}

bool shadow_bound_set(struct shadow_bound *b, const struct shadow_eye *v,
                      const struct shadow_span *sp)
{
  const double u = 0x1p-53, G = (double)GRID_ONE;
  if (!v->near || !sp->ok || !(sp->zlo <= sp->zhi)) return false;
  const double dzlo = sp->zlo - v->e[2], dzhi = sp->zhi - v->e[2];
  const double zm = fmax(fabs(sp->zlo), fabs(sp->zhi)), edm = u * (dzhi + zm);
  if (!(dzlo > 0) || !(edm < dzlo * 0x1p-20)) return false;
  const double rm = 1 / dzlo, fz = fabs(v->e[2]), r2 = rm * rm;
  for (int c = 0; c < 2; c++) {
    const double am = sp->ax[c] + fabs(v->e[c]), ea = u * (am + sp->ax[c]);
    const double q = fz * am * rm;
    const double t1 = fz * (am * edm + dzhi * ea) * r2;
    const double t2 = 5 * u * (q + fabs(v->e[c]) + 1);
    b->B[c] = 1.01 * G * (t1 + t2);
  }
  return true;
}

/* grid_near's point and its accepting tests, with b's bound (see above), the constants
   made once (spanned_set) for many vertices (spanned_point). The test on |gx| is
   |gx| < 2^28 - 1, stricter than grid_near's |gx| < 2^28, and it makes grid_near's test
   on k true (|k| <= |gx| + 1/2 < 2^28), so it is not made. */
struct spanned {
#ifdef __SSE2__
  __m128d Ev, fz, G, B, mag, half, lim;
#else
  double e[2], fz, B[2];
#endif
  double ez;
};

static inline void spanned_set(struct spanned *sp, const struct shadow_eye *v,
                               const struct shadow_bound *b)
{
  const double G = (double)GRID_ONE;
#ifdef __SSE2__
  sp->Ev = _mm_loadu_pd(v->e);
  sp->fz = _mm_set1_pd(-v->e[2]);
  sp->G = _mm_set1_pd(G);
  sp->B = _mm_loadu_pd(b->B);
  sp->mag = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX));
  sp->half = _mm_set1_pd(0.5);
  sp->lim = _mm_set1_pd(0x1p28 - 1);
#else
  (void)G;
  sp->e[0] = v->e[0];
  sp->e[1] = v->e[1];
  sp->fz = -v->e[2];
  sp->B[0] = b->B[0];
  sp->B[1] = b->B[1];
#endif
  sp->ez = v->e[2];
}

#ifdef __SSE2__
/* spanned_point's point as x, y in the two 64-bit lanes of *g, by the same tests with
   another integer k: the nearest to gx (ties to even), from t = fl(gx + C), C = 1.5 2^52.
   Where |gx| < 2^28 the exact sum lies in [2^52, 2^53), where the doubles are the
   integers, so t = C + k exactly, kd = t - C = k exactly (a difference of two doubles of
   one binade that is itself a double), and t's bits less C's, as 64-bit integers, are k
   (the doubles of one binade follow one another as their bits do). grid_near's proof
   holds for any integer k: where fl(|gx - k| + B) < 1/2 and |gx| < 2^28 - 1 the long way
   (shadow_grid_ld) rounds onto k, so where both are accepted this k is spanned_point's.
   Where the test on |gx| fails (also NaN) t is not looked at. Three operations for the
   rounding to an integer and back and the widening to 64 bits, where spanned_point's
   truncation (CVTTPD2DQ and CVTDQ2PD, two each on this processor, and four for the sign
   and the widening) takes nine, in a loop of about thirty a vertex (grid_all's). */
static inline bool spanned_lanes(const struct spanned *sp, const double yd[3], __m128i *g)
{
  const __m128d C = _mm_set1_pd(0x1.8p52);
  const double r = 1 / (yd[2] - sp->ez);
  const __m128d a = _mm_sub_pd(_mm_loadu_pd(yd), sp->Ev);
  const __m128d q = _mm_mul_pd(_mm_mul_pd(sp->fz, a), _mm_set1_pd(r));
  const __m128d gx = _mm_mul_pd(sp->G, _mm_add_pd(sp->Ev, q));
  const __m128d t = _mm_add_pd(gx, C), kd = _mm_sub_pd(t, C);
  const __m128d in = _mm_cmplt_pd(_mm_and_pd(gx, sp->mag), sp->lim);
  const __m128d near = _mm_cmplt_pd(_mm_add_pd(_mm_and_pd(_mm_sub_pd(gx, kd), sp->mag), sp->B),
                                    sp->half);
  if (_mm_movemask_pd(_mm_and_pd(in, near)) != 3) return false;
  *g = _mm_sub_epi64(_mm_castpd_si128(t), _mm_castpd_si128(C));
  return true;
}
#endif

static inline bool spanned_point(const struct spanned *sp, const double yd[3], struct gpoint *g)
{
#ifdef __SSE2__
  __m128i k;
  if (!spanned_lanes(sp, yd, &k)) return false;
  _mm_storeu_si128((__m128i *)g, k);
  return true;
#else
  const double r = 1 / (yd[2] - sp->ez);
  const double G = (double)GRID_ONE;
  int64_t k[2];
  for (int c = 0; c < 2; c++) {
    const double a = yd[c] - sp->e[c], q = sp->fz * a * r, gx = G * (sp->e[c] + q);
    if (!(fabs(gx) < 0x1p28 - 1)) return false;
    k[c] = (int64_t)(gx >= 0 ? gx + 0.5 : gx - 0.5);
    if (!(fabs(gx - (double)k[c]) + sp->B[c] < 0.5)) return false;
  }
  g->x = (gcoord)k[0];
  g->y = (gcoord)k[1];
  return true;
#endif
}

int shadow_grid_spanned(const struct shadow_eye *v, const struct shadow_bound *b,
                        const double yd[3], struct gpoint *g)
{
  struct spanned sp;
  spanned_set(&sp, v, b);
  return spanned_point(&sp, yd, g) ? 1 : -1;
}

/* shadow_grid_ld's answer, from the filter when it decides. */
static inline bool grid_point(const struct shadow_eye *v, const ld Y[3], const double yd[3],
                              struct gpoint *g)
{
  const int r = grid_near(v, yd, g);
  return r >= 0 ? r : shadow_grid_ld(v, Y, g);
}

/* Ring r of cs onto the grid at poly (room for its vertices), seen from eye v: the
   points that land, a repeat of the one before dropped (the last and the first not
   compared); their count. With sp (spanned_set for a bound on its vertices; not
   counted): spanned_point where it decides, else grid_point; where the processor has
   SSE2, draw_casts takes that case through grid_all and ring_from, and sp is not read. */
__attribute__((noinline))
static int draw_ring(const struct casts *cs, int r, const struct shadow_eye *eye,
                     const struct spanned *sp, struct gpoint *poly, struct cost *cost)
{
  const size_t y0 = r ? cs->yend[r - 1] : 0, n = cs->yend[r] - y0;
  const ld (*y)[3] = (const ld (*)[3])cs->y + y0;
  const double (*yd)[3] = (const double (*)[3])cs->yd + y0;
  int m = 0;
#ifndef __SSE2__
  if (sp && !cost) {
    for (size_t v = 0; v < n; v++) {
      struct gpoint *g = &poly[m];         /* written in place: read back a word at a time */
      if (!spanned_point(sp, yd[v], g) && !grid_point(eye, y[v], yd[v], g)) continue;
      m += m == 0 || poly[m - 1].x != g->x || poly[m - 1].y != g->y;
    }
    return m;
  }
#else
  (void)sp;
#endif
  for (size_t v = 0; v < n; v++) {
    struct gpoint *g = &poly[m];
    if (!grid_point(eye, y[v], yd[v], g)) continue;
    if (m > 0 && poly[m - 1].x == g->x && poly[m - 1].y == g->y) continue;
    m++;
    if (cost) {
      for (int k = 0; k < 4; k++) cost_mw_mul(cost, 32, 32);
      cost_mw_div(cost, 64, 32); cost_mw_div(cost, 64, 32);
    }
  }
  return m;
}

#ifdef __SSE2__
/* Vertices y0 .. y1 - 1 of cs onto the grid at g[0 ..] (sp: spanned_set for a bound on
   them), each as draw_ring takes it: spanned_lanes where it decides, else grid_point; a
   vertex that does not land has x = INT64_MIN (no grid point has: |x| < 2^28). One loop
   over every vertex of a face's casts: each vertex's chain (a divide, then some twelve
   dependent operations) overlaps the next ones', where draw_ring's loop over a ring of
   three to five ended before the next ring's began (a mispredicted exit a ring). */
static void grid_all(const struct casts *cs, size_t y0, size_t y1, const struct shadow_eye *eye,
                     const struct spanned *sp, struct gpoint *g)
{
  const ld (*y)[3] = (const ld (*)[3])cs->y;
  const double (*yd)[3] = (const double (*)[3])cs->yd;
  for (size_t v = y0; v < y1; v++) {
    __m128i k;
    if (!spanned_lanes(sp, yd[v], &k)) {
      struct gpoint p;
      if (!grid_point(eye, y[v], yd[v], &p)) p.x = INT64_MIN;
      k = _mm_loadu_si128((const __m128i *)&p);
    }
    _mm_storeu_si128((__m128i *)&g[v - y0], k);
  }
}

#ifdef CASTS_AVX512
/* grid_all four vertices an instruction in AVX-512's registers (lanes x, y of vertex v,
   then of v + 1, ..), chosen at run time where the processor has AVX-512F (casts_wide).
   Each lane's operations are spanned_lanes' for its coordinate on the same doubles in the
   same order, each the same IEEE operation (EVEX-encoded; no fused multiply-add: the
   build's -ffp-contract=off): r = 1 / (Y_z - E_z) (made in both lanes of its vertex, the
   same quotient twice), q = (fz a) r, gx = G (E + q), t = gx + C, kd = t - C, the tests
   |gx| < 2^28 - 1 and |gx - kd| + B < 1/2 by CMPPD's predicate (LT_OS), |x| as the AND
   with INT64_MAX's bits (what _mm512_abs_pd makes), and t's bits less C's as 64-bit
   integers. A vertex whose two lanes pass both tests takes that point (spanned_lanes'
   answer), another grid_point's as grid_all takes it; the last 0 .. 3 vertices grid_all's
   own way. Why: a vertex's chain (a divide, then some twelve dependent operations, some
   thirty instructions a vertex) is about the whole of grid_all, and grid_all about
   two thirds of draw_casts (fig6-building: 157 casts a frame); four vertices share one
   divide and one chain here. test_shadow's test_kept_is_long_way builds each frame this
   way and with SSE2's (shadow_keep_sse2) against the counted long way. */
static __attribute__((target("avx512f"))) void
grid_all4(const struct casts *cs, size_t y0, size_t y1, const struct shadow_eye *eye,
          const struct spanned *sp, struct gpoint *g)
{
  const ld (*y)[3] = (const ld (*)[3])cs->y;
  const double (*yd)[3] = (const double (*)[3])cs->yd;
  double e2[2], b2[2];
  _mm_storeu_pd(e2, sp->Ev);
  _mm_storeu_pd(b2, sp->B);
  const __m512d E = _mm512_setr_pd(e2[0], e2[1], e2[0], e2[1], e2[0], e2[1], e2[0], e2[1]);
  const __m512d B = _mm512_setr_pd(b2[0], b2[1], b2[0], b2[1], b2[0], b2[1], b2[0], b2[1]);
  const __m512d fz = _mm512_set1_pd(_mm_cvtsd_f64(sp->fz)), G = _mm512_set1_pd(_mm_cvtsd_f64(sp->G));
  const __m512d ez = _mm512_set1_pd(sp->ez), one = _mm512_set1_pd(1);
  const __m512d C = _mm512_set1_pd(0x1.8p52), half = _mm512_set1_pd(0.5);
  const __m512d lim = _mm512_set1_pd(0x1p28 - 1);
  /* from the twelve doubles of four vertices (eight, then four): their x, y pairs and
     each one's z twice */
  const __m512i ixy = _mm512_setr_epi64(0, 1, 3, 4, 6, 7, 9, 10);
  const __m512i iz = _mm512_setr_epi64(2, 2, 5, 5, 8, 8, 11, 11);
  size_t v = y0;
  for (; v + 4 <= y1; v += 4) {
    const double *const a = yd[v];
    const __m512d lo = _mm512_loadu_pd(a);
    const __m512d hi = _mm512_castpd256_pd512(_mm256_loadu_pd(a + 8));
    const __m512d xy = _mm512_permutex2var_pd(lo, ixy, hi);
    const __m512d z = _mm512_permutex2var_pd(lo, iz, hi);
    const __m512d r = _mm512_div_pd(one, _mm512_sub_pd(z, ez));
    const __m512d q = _mm512_mul_pd(_mm512_mul_pd(fz, _mm512_sub_pd(xy, E)), r);
    const __m512d gx = _mm512_mul_pd(G, _mm512_add_pd(E, q));
    const __m512d t = _mm512_add_pd(gx, C), kd = _mm512_sub_pd(t, C);
    const __mmask8 in = _mm512_cmp_pd_mask(_mm512_abs_pd(gx), lim, _CMP_LT_OS);
    const __mmask8 ok = _mm512_mask_cmp_pd_mask(
      in, _mm512_add_pd(_mm512_abs_pd(_mm512_sub_pd(gx, kd)), B), half, _CMP_LT_OS);
    _mm512_storeu_si512((void *)&g[v - y0],
                        _mm512_sub_epi64(_mm512_castpd_si512(t), _mm512_castpd_si512(C)));
    if (ok != 0xff)
      for (int h = 0; h < 4; h++) {
        if ((ok >> 2 * h & 3) == 3) continue;
        struct gpoint p;
        if (!grid_point(eye, y[v + h], yd[v + h], &p)) p.x = INT64_MIN;
        g[v - y0 + h] = p;
      }
  }
  if (v < y1) grid_all(cs, v, y1, eye, sp, g + (v - y0));
}
#endif

/* Ring r of cs from its vertices on the grid, g (grid_all's, from the ring's first) to
   poly: draw_ring's points (those that land, a repeat of the one before dropped, the last
   and the first not compared); their count. */
static inline int ring_from(const struct casts *cs, int r, const struct gpoint *g,
                            struct gpoint *poly)
{
  const size_t n = cs->yend[r] - (r ? cs->yend[r - 1] : 0);
  __m128i prev = _mm_set1_epi64x(INT64_MIN);   /* (none at first: no point has that x) */
  int m = 0;
  for (size_t v = 0; v < n; v++) {
    if (g[v].x == INT64_MIN) continue;       /* (it did not land) */
    const __m128i k = _mm_loadu_si128((const __m128i *)&g[v]);
    _mm_storeu_si128((__m128i *)&poly[m], k);
    m += _mm_movemask_epi8(_mm_cmpeq_epi32(k, prev)) != 0xffff;
    prev = k;
  }
  return m;
}
#endif

/* The view's part of casts [c0, c1) of cs on face R (map index; its box on the grid gb:
   x lo, x hi, y lo, y hi), seen from the eye v (sp: the span of their vertices): each ring's vertices onto the perspective
   plane by eq. (1), rounded onto the grid, repeats dropped; a polygon that misses gb is
   dropped, the others go to out. *any: set when one is added. false when out of host
   memory. */
static bool draw_casts(const struct casts *cs, int c0, int c1, const struct shadow_eye *eye,
                       const struct shadow_span *sp, const gcoord gb[4], int R,
                       struct work *wk, struct fx_polys *out, bool *any, struct cost *cost,
                       bool wide4)
{
  struct shadow_bound bd;
  struct spanned sd;
  const bool bounded = shadow_bound_set(&bd, eye, sp);
  if (bounded) spanned_set(&sd, eye, &bd);
#ifdef __SSE2__
  /* every vertex of the casts onto the grid first (grid_all), then their rings */
  const bool flat = bounded && !cost && c0 < c1;
  size_t gy0 = 0;                           /* the first vertex's index in cs */
  if (flat) {
    const int r0 = cs->c[c0].r0, r1 = cs->c[c1 - 1].r1;
    gy0 = r0 ? cs->yend[r0 - 1] : 0;
    const size_t gy1 = cs->yend[r1 - 1];
    if (!t74_grow((void **)&wk->g, &wk->gcap, gy1 - gy0 + 1, sizeof *wk->g)) return false;
#ifdef CASTS_AVX512
    if (wide4) grid_all4(cs, gy0, gy1, eye, &sd, wk->g);
    else
#endif
      grid_all(cs, gy0, gy1, eye, &sd, wk->g);
  }
#endif
  for (int c = c0; c < c1; c++) {
    size_t need = 0;
    int nring = 0;
    wk->rs[0] = 0;
    const int r0 = cs->c[c].r0, r1 = cs->c[c].r1;
    const size_t nv = cs->yend[r1 - 1] - (r0 ? cs->yend[r0 - 1] : 0);
    struct gpoint *room = fx_polys_room(out, (int)nv);   /* the rings written in place */
    if (!room) return false;
#ifdef __SSE2__
    if (flat && r1 - r0 == 1 && nv <= FX_POLY_BLOCK) {
      /* one ring of at most FX_POLY_BLOCK points (every cast of fig6-building, 157 a
         frame, and of fig6-room, 50): its box made here in one loop over its points, and
         its one block, whose points are all the ring's, from the box's y range:
         fx_ring_blocks' values (the block's lo and hi over its points and the ring's first
         again, one of them; the box from INT64_MAX and INT64_MIN over the same points),
         without fx_polys_close's loops over rings and blocks (about 120 of the some 540
         instructions a cast took; test_kept_is_long_way checks every box and block) */
      int m = ring_from(cs, r0, wk->g + ((r0 ? cs->yend[r0 - 1] : 0) - gy0), room);
      if (m > 1 && room[0].x == room[m - 1].x && room[0].y == room[m - 1].y) m--;
      if (m < 3) continue;
      gcoord box[4] = { room[0].x, room[0].x, room[0].y, room[0].y };
      for (int v = 1; v < m; v++) {
        const gcoord x = room[v].x, y = room[v].y;
        box[0] = x < box[0] ? x : box[0];
        box[1] = x > box[1] ? x : box[1];
        box[2] = y < box[2] ? y : box[2];
        box[3] = y > box[3] ? y : box[3];
      }
      gcoord (*blk)[2] = fx_polys_blocks_at(room, m);
      blk[0][0] = box[2];
      blk[0][1] = box[3];
      wk->rs[1] = m;
      if (!fx_polys_close_made(out, 1, wk->rs, R, cs->c[c].light, gb, any, 1, box)) return false;
      continue;
    }
#endif
    for (int r = r0; r < r1; r++) {
      struct gpoint *poly = room + need;
#ifdef __SSE2__
      int m = flat ? ring_from(cs, r, wk->g + ((r ? cs->yend[r - 1] : 0) - gy0), poly)
                   : draw_ring(cs, r, eye, bounded ? &sd : NULL, poly, cost);
#else
      int m = draw_ring(cs, r, eye, bounded ? &sd : NULL, poly, cost);
#endif
      if (m > 1 && poly[0].x == poly[m - 1].x && poly[0].y == poly[m - 1].y) m--;
      if (m < 3) continue;
      need += (size_t)m;
      wk->rs[++nring] = (int)need;
    }
    /* (a shadow that misses R's box on the grid is dropped) */
    if (nring > 0 && !fx_polys_close(out, nring, wk->rs, R, cs->c[c].light, gb, any))
      return false;
  }
  return true;
}

/* A scene face's casts as kept: for its plane and box in space (the key), casts
   [c0, c1) of the keep's. */
struct kept_face {
  bool set;
  int64_t plane[4];
  int32_t lo[3], hi[3];
  int c0, c1;
  struct shadow_span sp;    /* of the casts' vertices */
};

struct shadow_keep {
  const struct scene *s;
  int nf;
  struct kept_face *face;   /* one a scene face */
  struct casts cs;
  bool sse2;                /* tests only: grid_all, not grid_all4 (shadow_keep_sse2) */
};

void shadow_keep_sse2(struct shadow_keep *k, bool on)
{
  if (k) k->sse2 = on;
}

void shadow_keep_free(struct shadow_keep *k)
{
  if (!k) return;
  casts_free(&k->cs);
  free(k->face);
  free(k);
}

/* The keep for scene s: *keep as it is when it is s's, else a new one (NULL when out of
   host memory). */
/* The span of cs's vertices from y0 on. */
static void span_from(const struct casts *cs, size_t y0, struct shadow_span *sp)
{
  shadow_span_init(sp);
  for (size_t v = y0; v < cs->ny; v++) span_add(sp, cs->yd[v]);
}

static struct shadow_keep *keep_for(struct shadow_keep **keep, const struct scene *s)
{
  if (*keep && (*keep)->s == s && (*keep)->nf == s->nf) return *keep;
  shadow_keep_free(*keep);
  *keep = calloc(1, sizeof **keep);
  if (*keep && !((*keep)->face = calloc((size_t)s->nf + 1, sizeof *(*keep)->face))) {
    free(*keep);
    *keep = NULL;
  }
  if (*keep) { (*keep)->s = s; (*keep)->nf = s->nf; }
  return *keep;
}

int shadow_build(const struct mapped *map, const struct scene *s, struct shadow_keep **keep,
                 struct fx_polys *out, struct fx_stats *st, struct cost *cost,
                 struct t74_error *err)
{
  int maxv = 3;
  for (int a = 0; a < s->nf; a++) {
    int n = s->f[a].ring_start[s->f[a].nring];
    if (n > maxv) maxv = n;
  }
  struct work wk;
  memset(&wk, 0, sizeof wk);
  wk.cap = (size_t)maxv + 16;
  wk.b0 = malloc(wk.cap * sizeof *wk.b0);
  wk.b1 = malloc(wk.cap * sizeof *wk.b1);
  wk.hv = malloc(3 * wk.cap * sizeof *wk.hv);
  wk.p0 = wk.hv ? wk.hv + wk.cap : NULL;
  wk.p1 = wk.hv ? wk.hv + 2 * wk.cap : NULL;
  wk.rs = malloc(((size_t)maxv + 2) * sizeof *wk.rs);
  struct shadow_keep *kp = keep && !cost && s->has_light ? keep_for(keep, s) : NULL;
  struct casts scratch;
  memset(&scratch, 0, sizeof scratch);
  bool ok = wk.b0 && wk.b1 && wk.hv && wk.rs && (kp || !keep || cost || !s->has_light);
  /* room for as many polygons as the keep has casts (from the second frame on: each of
     them at most one polygon, and few others), not grown step by step */
  ok = ok && (!kp || fx_polys_reserve(out, out->n + kp->cs.n));
  long receivers = 0, polys0 = out->n;
  struct shadow_eye eye;
  shadow_eye_set(&eye, map->eye);
  /* grid_all4 where the processor has AVX-512F (and the system saves its registers:
     __builtin_cpu_supports), unless the keep says SSE2's (tests only) */
#ifdef CASTS_AVX512
  const bool wide4 = __builtin_cpu_supports("avx512f") && !(kp && kp->sse2);
#else
  const bool wide4 = false;
#endif
  const ld *E = eye.E;
  for (int R = 0; R < map->nface && ok; R++) {
    const struct mface *mf = &map->f[R];
    const struct scene_face *sr = &s->f[mf->sface];
    if (sr->grey >= 0 || !s->has_light) continue;
    /* R's box in space (outer ring), one unit wider; and on the grid */
    int32_t lo[3], hi[3];
    space_box(map, mf, lo, hi);
    ld box[2][3];
    for (int c = 0; c < 3; c++) { box[0][c] = (ld)lo[c] - 1; box[1][c] = (ld)hi[c] + 1; }
    gcoord gb[4] = { mf->pt[0].x, mf->pt[0].x, mf->pt[0].y, mf->pt[0].y };
    for (int v = 1; v < mf->ring_start[1]; v++) {
      if (mf->pt[v].x < gb[0]) gb[0] = mf->pt[v].x;
      if (mf->pt[v].x > gb[1]) gb[1] = mf->pt[v].x;
      if (mf->pt[v].y < gb[2]) gb[2] = mf->pt[v].y;
      if (mf->pt[v].y > gb[3]) gb[3] = mf->pt[v].y;
    }
    bool any = false;
    if (box[0][2] <= E[2]) {                /* stays before the eye: the view's, a frame's */
      box[0][2] = (E[2] + (ld)mface_coord(map, mf, 0, 2)) / 2;
    } else if (kp) {                        /* the scene's: kept for the run */
      struct kept_face *kf = &kp->face[mf->sface];
      if (!kf->set) {
        kf->c0 = kp->cs.n;
        const size_t y0 = kp->cs.ny;
        ok = cast_face(mf, s, (const ld (*)[3])box, &wk, &kp->cs, NULL);
        kf->c1 = kp->cs.n;
        span_from(&kp->cs, y0, &kf->sp);
        memcpy(kf->plane, mf->plane, sizeof kf->plane);
        memcpy(kf->lo, lo, sizeof lo);
        memcpy(kf->hi, hi, sizeof hi);
        kf->set = ok;
      }
      if (kf->set && !memcmp(kf->plane, mf->plane, sizeof kf->plane) &&
          !memcmp(kf->lo, lo, sizeof lo) && !memcmp(kf->hi, hi, sizeof hi)) {
        ok = draw_casts(&kp->cs, kf->c0, kf->c1, &eye, &kf->sp, gb, R, &wk, out, &any, NULL,
                        wide4);
        receivers += any;
        continue;
      }
    }
    if (!ok) break;
    scratch.n = scratch.nring = 0;
    scratch.ny = 0;
    struct shadow_span sp;
    ok = cast_face(mf, s, (const ld (*)[3])box, &wk, &scratch, cost);
    if (!cost) span_from(&scratch, 0, &sp);
    else {                                  /* counted: each vertex by itself (draw_ring) */
      shadow_span_init(&sp);
      sp.ok = false;
    }
    ok = ok && draw_casts(&scratch, 0, scratch.n, &eye, &sp, gb, R, &wk, out, &any, cost,
                          wide4);
    receivers += any;
  }
  free(wk.b0); free(wk.b1); free(wk.hv); free(wk.rs); free(wk.g);
  casts_free(&scratch);
  if (!ok) return t74_fail(err, T74_EIO, "out of host memory");
  fx_count(st, "shadow_polygons", (double)(out->n - polys0), true);
  fx_count(st, "shadow_receivers", (double)receivers, true);
  return T74_OK;
}
