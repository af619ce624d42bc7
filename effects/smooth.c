/*
** smooth.c — smooth shading and partial smoothing (paper 004 §2-4), see smooth.h.
**
** Procedure (A) as built here, for a triangle V0 V1 V2 with barycentric coordinates
** l0 l1 l2 (side k is l[k] = 0) and insets t0 t1 t2 (side k's smoothing boundary line is
** l[k] = t[k]):
**   (1) the smoothing boundary lines l[k] = t[k], parallel to the sides, inside;
**   (2) where two boundary lines meet (the inner triangle's corners): the face normal;
**   (3) where a boundary line meets a side: the side's two vertex normals interpolated
**       linearly at that position;
**   (4) at the vertices: the mean of the unit normals of the object's triangles there;
**   (5) [the paper's text is cut here] taken as: the corner quadrilaterals (at Vc, between
**       the two boundary lines of the sides through Vc) have corners Vc, the two points
**       of (3) on those sides and the inner corner of (2); the edge quadrilaterals
**       (trapezoids along a side, between the side and its boundary line) have the two
**       points of (3) on the side and the two inner corners of (2);
**   (6) inside a quadrilateral the normal is its corners' normals shared out in proportion:
**       bilinear in (l_a/t_a, l_b/t_b) in a corner parallelogram; in a trapezoid along
**       side k, linear across (v = l_k/t_k) between the side and the face normal, and
**       linear along each line parallel to the side between the trapezoid's two slanted
**       edges;
**   (7) the inner triangle (every l[k] >= t[k]) keeps the face's flat intensity exactly;
**   (8) intensity by Lambert's law per point (Phong).
** On every side the normal is then exactly the linear interpolation of the side's two
** vertex normals (as in Phong's method), whatever the insets; the two triangles sharing
** a side share those vertex normals, so the normal is continuous across every shared
** side (no seams), and across the quadrilaterals' own borders inside the triangle.
**
** Units (004 Def. 3 and 5). prop:C: every boundary line cuts the two other sides at the
** fraction C of their lengths (m_i / l_i = C), so side k's band is C times the height on
** side k, t[k] = C, and the flat inner triangle is similar to the patch with ratio 1-3C:
** its share is (1-3C)^2. fixed:C: a band of one width w in space on every side, with
** w = C times the object's mean triangle height (the mean over all triangles and sides
** of 2 area / side); t[k] = w / height_k. On a mesh of equal triangles fixed:C and
** prop:C are then the same picture, so the paper's 0.05 and 0.15 cut the same share in
** both. Insets summing past 1 are scaled down to sum 1: the whole patch is smoothed and
** the inner triangle is a point (prop:C beyond 1/3).
**
** Cost per shaded point, as a 16-bit program would do it in fixed point: the ray back
** onto the plane (3 multiply-adds of the plane with the ray, 1 divide, 3 multiply-adds
** for the space point), barycentric coordinates (2 cross products, 2 divides), region
** tests (3 compares), normal interpolation (up to 4 corners x 3 components: 12 multiply-
** adds), normalisation (3 squares, a 12-step square root, 3 divides), Lambert (3
** multiply-adds, 1 multiply, 1 add) and the table loads. Gouraud stops after the
** barycentric coordinates and interpolates 3 intensities.
*/
#include "effects/smooth.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/shade.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
/* smooth_phong_row four points an instruction where the processor has AVX (a run-time
   test; the build itself assumes SSE2 at most: see phong_rows4) */
#if defined(__SSE2__) && (defined(__x86_64__) || defined(__i386__)) && \
    (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define PHONG_AVX 1
#endif

#define SMOOTH_TABLE_NORMALS "SMOOTH VERTEX NORMALS"
#define SMOOTH_TABLE_BANDS   "SMOOTH BAND TABLE"

int smooth_lambert(const double n[3], const double l[3])
{
  double d = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
  if (!(d > 0)) return SHADE_AMBIENT;
  double g = SHADE_AMBIENT + floor((255 - SHADE_AMBIENT) * d + 0.5);
  return g > 255 ? 255 : (int)g;
}

static void unit(double v[3])
{
  double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n > 0) { v[0] /= n; v[1] /= n; v[2] /= n; }
}

void smooth_insets(enum effects_smooth kind, double c, double w, const double len[3],
                   double area2, double t[3])
{
  for (int k = 0; k < 3; k++) {
    switch (kind) {
    case EFFECTS_SMOOTH_PROP:  t[k] = c; break;
    case EFFECTS_SMOOTH_FIXED: t[k] = area2 > 0 ? w * len[k] / area2 : 0; break;
    default:                   t[k] = 0.5; break;
    }
    if (!(t[k] >= 0)) t[k] = 0;
  }
  if (kind != EFFECTS_SMOOTH_PROP && kind != EFFECTS_SMOOTH_FIXED) return;
  double sum = t[0] + t[1] + t[2];
  if (sum > 1) for (int k = 0; k < 3; k++) t[k] /= sum;
}

static const int next3[3] = { 1, 2, 0 }, prev3[3] = { 2, 0, 1 };

/* The inner triangle's filter's scaled inset of t_k (smooth.c, "The inner triangle's
   filter"): max(fl(t_k (1 + 2^-40)), 2^-898). */
static double inner_tc(double tk)
{
  const double v = tk * (1 + 0x1p-40);
  return v > 0x1p-898 ? v : 0x1p-898;
}

/* A triangle's shading pass's constants, each the same double twice (two points an SSE2
   instruction), made with its insets (tri_lanes): for side k, the corner its barycentric
   area starts from (bV[(k + 1) % 3]) in xa[k], bE[k] times tot's sign in xsd[k] (u then w
   axis; exact), the vertex normals in xcn[k][c], the inner triangle's filter's scaled
   insets in xtc[k]; tot's sign in xst; the insets t[k] in xt[k], the face normal's
   components in xn[c], side k's band ends ends[k][j][c] in xends[k][j][c], corner k's
   ends[3 + k][j][c] in xcends[k][j][c]; and the rest below. Kept apart from smooth_tri (864 bytes a triangle): only the model's triangles
   have them, not the scene's part kept between frames. */
struct smooth_lanes {
  _Alignas(16) double xa[3][2][2];
  _Alignas(16) double xcn[3][3][2];
  _Alignas(16) double xtc[3][2];
  _Alignas(16) double xst[2];
  _Alignas(16) double xt[3][2];
  _Alignas(16) double xn[3][2];
  _Alignas(16) double xends[3][2][3][2];
  _Alignas(16) double xcends[3][2][3][2];  /* corner k's band ends ends[3 + k][j][c] */
  _Alignas(16) double xsd[3][2][2];
  _Alignas(16) double xlo[2], xhi[2];  /* |tot| 2^-1000, |tot| 2^1000 (the Phong filter's) */
  _Alignas(16) double xilo[2], xihi[2];  /* |tot| / 2, 2 |tot| (the inner filter's) */
  bool inner_ok;            /* 2^-100 <= |tot| <= 2^100: the inner filter may be used */
};

/* The shading pass's constants of triangle tr (struct smooth_lanes) into *x, from its
   fields: copies of them, inner_tc's values, tot's sign (and the sides' constants times
   it, exactly), the Phong filter's bounds |tot| 2^-1000 and |tot| 2^1000, and the inner
   filter's: |tot| / 2, 2 |tot| and whether 2^-100 <= |tot| <= 2^100. */
static void tri_lanes(const struct smooth_tri *tr, struct smooth_lanes *x)
{
  for (int k = 0; k < 3; k++) {
    const double *a = tr->bV[k == 2 ? 0 : k + 1], *d = tr->bE[k];   /* as bary_areas */
    const double tc = inner_tc(tr->t[k]);
    for (int h = 0; h < 2; h++) {
      for (int c = 0; c < 2; c++) {
        x->xa[k][c][h] = a[c];
        x->xsd[k][c][h] = (tr->btot > 0 ? 1 : -1) * d[c];
      }
      for (int c = 0; c < 3; c++) x->xcn[k][c][h] = tr->cn[k][c];
      x->xtc[k][h] = tc;
      x->xt[k][h] = tr->t[k];
      x->xn[k][h] = tr->n[k];
      for (int j = 0; j < 2; j++)
        for (int c = 0; c < 3; c++) {
          x->xends[k][j][c][h] = tr->ends[k][j][c];
          x->xcends[k][j][c][h] = tr->ends[3 + k][j][c];
        }
    }
  }
  x->xst[0] = x->xst[1] = tr->btot > 0 ? 1 : -1;
  x->xlo[0] = x->xlo[1] = fabs(tr->btot) * 0x1p-1000;
  x->xhi[0] = x->xhi[1] = fabs(tr->btot) * 0x1p1000;
  const double at = fabs(tr->btot);
  x->xilo[0] = x->xilo[1] = 0.5 * at;
  x->xihi[0] = x->xihi[1] = 2 * at;
  x->inner_ok = at >= 0x1p-100 && at <= 0x1p100;
}

/* The triangle's band ends (smooth_tri.ends) for its insets and vertex normals: the
   products smooth_partial_normal takes for every point, made once. */
static void band_ends(struct smooth_tri *tr)
{
  const double *t = tr->t;
  for (int k = 0; k < 3; k++) {
    const int a = next3[k], b = prev3[k];
    for (int c = 0; c < 3; c++) {
      tr->ends[k][0][c] = t[a] * tr->cn[a][c] + (1 - t[a]) * tr->cn[b][c];
      tr->ends[k][1][c] = (1 - t[b]) * tr->cn[a][c] + t[b] * tr->cn[b][c];
      tr->ends[3 + k][0][c] = (1 - t[a]) * tr->cn[k][c] + t[a] * tr->cn[a][c];
      tr->ends[3 + k][1][c] = (1 - t[b]) * tr->cn[k][c] + t[b] * tr->cn[b][c];
    }
  }
}

/* smooth_partial_normal's body, inline for the shading pass's run of band points */
static inline __attribute__((always_inline))
int partial_normal(const struct smooth_tri *tr, const double l[3], double out[3])
{
  const double *t = tr->t;
  bool in[3];
  int nb = 0;
  for (int k = 0; k < 3; k++) { in[k] = l[k] < t[k]; nb += in[k]; }
  if (nb == 0) { memcpy(out, tr->n, sizeof tr->n); return 0; }
  if (nb == 1) {
    int k = in[0] ? 0 : in[1] ? 1 : 2, a = next3[k], b = prev3[k];
    double v = l[k] / t[k];
    double den = 1 - l[k] - t[a] - t[b];
    double s = den > 1e-12 ? (l[a] - t[a]) / den : 0.5;
    if (s < 0) s = 0;
    if (s > 1) s = 1;
    const double (*e)[3] = tr->ends[k];     /* at l_a = t_a and l_b = t_b on side k */
    for (int c = 0; c < 3; c++)
      out[c] = (1 - v) * ((1 - s) * e[0][c] + s * e[1][c]) + v * tr->n[c];
    return 1;
  }
  if (nb == 2) {
    int cv = !in[0] ? 0 : !in[1] ? 1 : 2, a = next3[cv], b = prev3[cv];
    double u = l[a] / t[a], w = l[b] / t[b];
    const double (*e)[3] = tr->ends[3 + cv];
    for (int c = 0; c < 3; c++)
      out[c] = (1 - u) * (1 - w) * tr->cn[cv][c] + u * (1 - w) * e[0][c] +
               (1 - u) * w * e[1][c] + u * w * tr->n[c];
    return 2;
  }
  /* every coordinate inside a band: only when the insets sum to 1 and the point is the
     inner point itself (rounding); Phong there */
  for (int c = 0; c < 3; c++)
    out[c] = l[0] * tr->cn[0][c] + l[1] * tr->cn[1][c] + l[2] * tr->cn[2][c];
  return 1;
}

#ifdef __SSE2__
/* partial_normal's nb == 1 at two points of one edge band k (coordinates l[k], a point a
   lane), their normals into n[c]. Each lane partial_normal's operations on its values in
   their order (correctly rounded, as the scalar ones are; the compares the scalar ones;
   the divide by den made in both lanes and kept only where den > 1e-12, else 0.5; the
   clamps of s as selections where s < 0 and where s > 1, as the scalar ifs: -0 and a NaN
   stay as they are). */
static inline __attribute__((always_inline))
void edge_lanes(const struct smooth_lanes *x, const __m128d *l, int k, __m128d *n)
{
  const int a = next3[k], b = prev3[k];
  const __m128d one = _mm_set1_pd(1), zero = _mm_setzero_pd();
  const __m128d tk = _mm_load_pd(x->xt[k]), ta = _mm_load_pd(x->xt[a]);
  const __m128d v = _mm_div_pd(l[k], tk);
  const __m128d den = _mm_sub_pd(_mm_sub_pd(_mm_sub_pd(one, l[k]), ta), _mm_load_pd(x->xt[b]));
  const __m128d big = _mm_cmpgt_pd(den, _mm_set1_pd(1e-12));
  __m128d s = _mm_or_pd(_mm_and_pd(big, _mm_div_pd(_mm_sub_pd(l[a], ta), den)),
                        _mm_andnot_pd(big, _mm_set1_pd(0.5)));
  /* maxpd (a, b) is a > b ? a : b and minpd (a, b) a < b ? a : b, lane by lane (the
     instructions' definition, which GCC and clang keep for the intrinsics): 0 > s ? +0 : s
     is the scalar s < 0's +0, and keeps -0 and a NaN; 1 < s ? 1 : s is s > 1's 1 */
  s = _mm_max_pd(zero, s);                                      /* s < 0: +0 */
  s = _mm_min_pd(one, s);                                       /* s > 1: 1 */
  const __m128d omv = _mm_sub_pd(one, v), oms = _mm_sub_pd(one, s);
  const double (*e)[3][2] = x->xends[k];   /* at l_a = t_a and l_b = t_b on side k */
  for (int c = 0; c < 3; c++)
    n[c] = _mm_add_pd(_mm_mul_pd(omv, _mm_add_pd(_mm_mul_pd(oms, _mm_load_pd(e[0][c])),
                                                 _mm_mul_pd(s, _mm_load_pd(e[1][c])))),
                      _mm_mul_pd(v, _mm_load_pd(x->xn[c])));
}

/* partial_normal's nb == 2 at two points of one corner band cv (as edge_lanes). Each lane
   partial_normal's operations on its values in their order (correctly rounded, as the
   scalar ones are; the products and sums as C groups them: ((1 - u)(1 - w)) cn +
   (u (1 - w)) e_0 + ((1 - u) w) e_1 + (u w) n, added left to right). */
static inline __attribute__((always_inline))
void corner_lanes(const struct smooth_lanes *x, const __m128d *l, int cv, __m128d *n)
{
  const int a = next3[cv], b = prev3[cv];
  const __m128d one = _mm_set1_pd(1);
  const __m128d u = _mm_div_pd(l[a], _mm_load_pd(x->xt[a]));
  const __m128d w = _mm_div_pd(l[b], _mm_load_pd(x->xt[b]));
  const __m128d omu = _mm_sub_pd(one, u), omw = _mm_sub_pd(one, w);
  const __m128d c0 = _mm_mul_pd(omu, omw), c1 = _mm_mul_pd(u, omw), c2 = _mm_mul_pd(omu, w),
                c3 = _mm_mul_pd(u, w);
  const double (*e)[3][2] = x->xcends[cv];
  for (int c = 0; c < 3; c++)
    n[c] = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, _mm_load_pd(x->xcn[cv][c])),
                                            _mm_mul_pd(c1, _mm_load_pd(e[0][c]))),
                                 _mm_mul_pd(c2, _mm_load_pd(e[1][c]))),
                      _mm_mul_pd(c3, _mm_load_pd(x->xn[c])));
}

/* partial_normal at two points of one triangle (coordinates l[k], a point a lane) when
   both are in the same edge band (one coordinate, the same one, below its inset:
   partial_normal's nb == 1 with the same k; returns 1) or the same corner band (two, the
   same two: nb == 2 with the same cv; returns 2), their normals into n[c]; else 0 and
   nothing written. The compares partial_normal's (l[k] < t[k]). */
static inline __attribute__((always_inline))
int band_lanes(const struct smooth_lanes *x, const __m128d *l, __m128d *n)
{
  int in[3];
  for (int k = 0; k < 3; k++) in[k] = _mm_movemask_pd(_mm_cmplt_pd(l[k], _mm_load_pd(x->xt[k])));
  const int all = in[0] | in[1] << 2 | in[2] << 4;   /* each lane's below-inset bits */
  if (all == 0x03) { edge_lanes(x, l, 0, n); return 1; }
  if (all == 0x0c) { edge_lanes(x, l, 1, n); return 1; }
  if (all == 0x30) { edge_lanes(x, l, 2, n); return 1; }
  if (all == 0x3c) { corner_lanes(x, l, 0, n); return 2; }
  if (all == 0x33) { corner_lanes(x, l, 1, n); return 2; }
  if (all == 0x0f) { corner_lanes(x, l, 2, n); return 2; }
  return 0;
}

/* Lane 0 from a, lane 1 from b, by two 8-byte loads: each is forwarded whole from a store
   of 8 or 16 bytes still on its way to the cache, where a 16-byte load over two stores
   would wait for both to reach it. */
static inline __attribute__((always_inline)) __m128d pick2(const double *a, const double *b)
{
  return _mm_loadh_pd(_mm_load_sd(a), b);
}

/* partial_normal at band points q and q + 1 (coordinates lv[k][q]: bary_pairs' or
   inner_split's row's, stored one by one: pick2) when both are in the same edge band (1)
   or the same corner band (2) (band_lanes), their normals into nv[c][ns] and nv[c][ns +
   1]; 0 (nothing written) when neither. */
static inline __attribute__((always_inline))
int band_pair_normals(const struct smooth_lanes *x, double (*lv)[SMOOTH_ROW], int q,
                      double (*nv)[SMOOTH_ROW], int ns)
{
  __m128d l[3], n[3];
  for (int k = 0; k < 3; k++) l[k] = pick2(&lv[k][q], &lv[k][q + 1]);
  const int r = band_lanes(x, l, n);
  if (r)
    for (int c = 0; c < 3; c++) _mm_storeu_pd(&nv[c][ns], n[c]);
  return r;
}
#endif

int smooth_partial_normal(const struct smooth_tri *tr, const double l[3], double out[3])
{
  return partial_normal(tr, l, out);
}

/* ---- the model -------------------------------------------------------------------- */

struct edge_rec { int lo, hi, tri; bool fwd; };

static int edge_cmp(const void *pa, const void *pb)
{
  const struct edge_rec *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return a->tri < b->tri ? -1 : a->tri > b->tri;
}

static void smooth_scene_return(struct smooth_scene *ss);

void smooth_model_free(struct smooth_model *m)
{
  if (m->lent) smooth_scene_return(m->lent);
  else {
    free(m->tri);
    free(m->lanes);
    free(m->edge_group);
  }
  free(m->tri_of_mface);
  memset(m, 0, sizeof *m);
}

static wide det3(const struct scene_vertex *a, const struct scene_vertex *b,
                 const struct scene_vertex *c)
{
  return (wide)a->x * ((wide)b->y * c->z - (wide)b->z * c->y) -
         (wide)a->y * ((wide)b->x * c->z - (wide)b->z * c->x) +
         (wide)a->z * ((wide)b->x * c->y - (wide)b->y * c->x);
}

static void cross_int(const struct scene *s, const int v[3], int64_t o[3])
{
  const struct scene_vertex *a = &s->v[v[0]], *b = &s->v[v[1]], *c = &s->v[v[2]];
  int64_t u[3] = { b->x - a->x, b->y - a->y, b->z - a->z };
  int64_t w[3] = { c->x - a->x, c->y - a->y, c->z - a->z };
  o[0] = u[1] * w[2] - u[2] * w[1];
  o[1] = u[2] * w[0] - u[0] * w[2];
  o[2] = u[0] * w[1] - u[1] * w[0];
}

/* Orient the triangles [from, to) of one object (tri[] already filled with vertices):
   breadth first across shared edges; then outward by volume when closed (*closed set).
   An open surface is turned towards the eye afterwards, a frame at a time (face_eye). */
static int orient_object(struct smooth_model *m, const struct scene *s, int from, int to,
                         bool *closed_out, int *group, int *ngroup, struct t74_error *err)
{
  *closed_out = false;
  if (to <= from) return T74_OK;
  size_t n = (size_t)(to - from), ne = 3 * n;
  struct edge_rec *e = malloc(ne * sizeof *e);
  int *flip = malloc(n * sizeof *flip), *queue = malloc(n * sizeof *queue);
  int *first = malloc((n + 1) * sizeof *first);
  if (!e || !flip || !queue || !first) {
    free(e); free(flip); free(queue); free(first);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  for (size_t t = 0; t < n; t++) {
    const int *v = m->tri[from + (int)t].v;
    for (int k = 0; k < 3; k++) {
      int a = v[k], b = v[(k + 1) % 3];
      e[3 * t + (size_t)k] = (struct edge_rec){ a < b ? a : b, a < b ? b : a, (int)t, a < b };
    }
    flip[t] = -1;
  }
  qsort(e, ne, sizeof *e, edge_cmp);
  /* per triangle, its edge records: an index list sorted by triangle */
  int *bytri = malloc(ne * sizeof *bytri);
  if (!bytri) {
    free(e); free(flip); free(queue); free(first);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  memset(first, 0, (n + 1) * sizeof *first);
  for (size_t k = 0; k < ne; k++) first[e[k].tri + 1]++;
  for (size_t t = 0; t < n; t++) first[t + 1] += first[t];
  int *fill = queue;                      /* reused as a cursor before the search */
  for (size_t t = 0; t < n; t++) fill[t] = first[t];
  for (size_t k = 0; k < ne; k++) bytri[fill[e[k].tri]++] = (int)k;
  bool closed = true;
  for (size_t k = 0; k < ne;) {
    size_t j = k;
    while (j < ne && e[j].lo == e[k].lo && e[j].hi == e[k].hi) j++;
    if (j - k != 2) closed = false;
    if (j - k > 2) m->conflicts++;
    k = j;
  }
  for (size_t seed = 0; seed < n; seed++) {
    if (flip[seed] >= 0) continue;
    size_t head = 0, tail = 0;
    flip[seed] = 0;
    queue[tail++] = (int)seed;
    while (head < tail) {
      int t = queue[head++];
      for (int q = first[t]; q < first[t + 1]; q++) {
        size_t k = (size_t)bytri[q];
        size_t lo = k, hi = k;
        while (lo > 0 && e[lo - 1].lo == e[k].lo && e[lo - 1].hi == e[k].hi) lo--;
        while (hi + 1 < ne && e[hi + 1].lo == e[k].lo && e[hi + 1].hi == e[k].hi) hi++;
        if (hi - lo != 1) continue;       /* a border or a non-manifold edge */
        size_t o = lo == k ? hi : lo;
        int u = e[o].tri;
        /* consistent when the two run the edge in opposite directions */
        int want = flip[t] ^ (e[o].fwd == e[k].fwd);
        if (flip[u] < 0) { flip[u] = want; queue[tail++] = u; }
        else if (flip[u] != want) m->conflicts++;
      }
    }
  }
  for (size_t t = 0; t < n; t++)
    if (flip[t]) {
      int *v = m->tri[from + (int)t].v, x = v[1];
      v[1] = v[2]; v[2] = x;
      m->flips++;
    }
  *closed_out = closed;
  if (closed) {
    /* outward: the volume sum of det(v0, v1, v2) / 6 is positive */
    wide vol = 0;
    for (size_t t = 0; t < n; t++) {
      const int *v = m->tri[from + (int)t].v;
      vol += det3(&s->v[v[0]], &s->v[v[1]], &s->v[v[2]]);
    }
    if (vol < 0)
      for (size_t t = 0; t < n; t++) {
        int *v = m->tri[from + (int)t].v, x = v[1];
        v[1] = v[2]; v[2] = x;
      }
  }
  /* the sides' groups (edge_groups in smooth.h), on the triangles as now oriented */
  for (size_t k = 0; k < 3 * n; k++) group[k] = -1;
  for (size_t k = 0; k < ne; k++) {
    if (k == 0 || e[k].lo != e[k - 1].lo || e[k].hi != e[k - 1].hi) (*ngroup)++;
    const int *v = m->tri[from + e[k].tri].v;
    int *g = group + 3 * (size_t)e[k].tri;
    for (int q = 0; q < 3; q++) {
      int a = v[q], b = v[q == 2 ? 0 : q + 1];
      if (g[q] < 0 && (a < b ? a : b) == e[k].lo && (a < b ? b : a) == e[k].hi) {
        g[q] = *ngroup - 1;
        break;
      }
    }
  }
  free(e); free(flip); free(queue); free(first); free(bytri);
  return T74_OK;
}

/* o . (eye - v0) for a triangle with corner v0 and integer normal o, exact: positive when
   its side o points to faces the eye. */
static wide toward_eye(const struct scene *s, int v0, const int64_t o[3], const int64_t eye[3])
{
  const struct scene_vertex *p = &s->v[v0];
  return (wide)o[0] * (eye[0] - p->x) + (wide)o[1] * (eye[1] - p->y) + (wide)o[2] * (eye[2] - p->z);
}

static double mean_height(const struct smooth_tri *tri, int from, int to)
{
  double sum = 0;
  int cnt = 0;
  for (int t = from; t < to; t++)
    for (int k = 0; k < 3; k++)
      if (tri[t].len[k] > 0) { sum += tri[t].area2 / tri[t].len[k]; cnt++; }
  return cnt ? sum / cnt : 0;
}

/* The barycentric set-up of a triangle (its unit normal n found), once a triangle: the
   sub-triangles' areas are taken on the plane's dominant axis. */
static void bary_setup(const struct scene *s, struct smooth_tri *tr)
{
  int ax = 0;
  for (int c = 1; c < 3; c++) if (fabs(tr->n[c]) > fabs(tr->n[ax])) ax = c;
  int u = (ax + 1) % 3, w = (ax + 2) % 3;
  double (*V)[2] = tr->bV;
  for (int k = 0; k < 3; k++) {
    const struct scene_vertex *v = &s->v[tr->v[k]];
    double q[3] = { (double)v->x, (double)v->y, (double)v->z };
    V[k][0] = q[u]; V[k][1] = q[w];
  }
  static const int next[3][2] = { { 1, 2 }, { 2, 0 }, { 0, 1 } };   /* (k + 1, k + 2) % 3 */
  for (int k = 0; k < 3; k++)
    for (int c = 0; c < 2; c++) tr->bE[k][c] = V[next[k][1]][c] - V[next[k][0]][c];
  tr->bu = u;
  tr->bw = w;
  tr->btot = (V[1][0] - V[0][0]) * (V[2][1] - V[0][1]) - (V[2][0] - V[0][0]) * (V[1][1] - V[0][1]);
}

/* A triangle's geometry from its corners as they are ordered: its integer normal o3, unit
   normal, twice its area, the barycentric set-up and its sides' lengths. */
static void tri_shape(const struct scene *s, struct smooth_tri *tr, int64_t o3[3])
{
  cross_int(s, tr->v, o3);
  for (int c = 0; c < 3; c++) tr->n[c] = (double)o3[c];
  tr->area2 = sqrt(tr->n[0] * tr->n[0] + tr->n[1] * tr->n[1] + tr->n[2] * tr->n[2]);
  unit(tr->n);
  bary_setup(s, tr);
  for (int k = 0; k < 3; k++) {
    const struct scene_vertex *a = &s->v[tr->v[(k + 1) % 3]], *b = &s->v[tr->v[(k + 2) % 3]];
    double dx = b->x - a->x, dy = b->y - a->y, dz = b->z - a->z;
    tr->len[k] = sqrt(dx * dx + dy * dy + dz * dz);
  }
}

/* A triangle as the scene's part keeps it (smooth_scene): smooth_tri's fields that depend
   on the scene alone (its corners, their geometry and vertex normals), not the frame's
   (mface, front, ni, t, ends; 264 bytes, not 600). */
struct smooth_kept {
  int    sface, object, v[3];
  double n[3], area2, len[3], cn[3][3];
  int    bu, bw;
  double bV[3][2], bE[3][2], btot;
};

/* struct smooth_kept's fields, which smooth_tri has too (the same names and types): one
   list for the two copies below. */
#define KEPT_FIELDS(F) F(sface) F(object) F(v) F(n) F(area2) F(len) F(cn) F(bu) F(bw) \
                       F(bV) F(bE) F(btot)
#define KEPT_COPY(f)                                                                  \
  _Static_assert(sizeof to->f == sizeof from->f, "smooth_kept and smooth_tri: " #f);   \
  memcpy(&to->f, &from->f, sizeof to->f);

/* Triangle from's fields that depend on the scene alone into to (smooth_kept). */
static void tri_keep(const struct smooth_tri *from, struct smooth_kept *to)
{
  KEPT_FIELDS(KEPT_COPY)
}

/* Kept triangle from as it is into to (the frame's fields are left to the frame). */
static void tri_kept(const struct smooth_kept *from, struct smooth_tri *to)
{
  KEPT_FIELDS(KEPT_COPY)
}
#undef KEPT_COPY
#undef KEPT_FIELDS

/* Kept triangle a turned (corners v1 and v2 swapped) into b: what tri_shape and the vertex
   normals give for the turned corners, without working them out again. Every value is
   a's or its negation, exactly: the normals' and the sides' differences change sign and
   nothing else (0 - x: a zero stays +0, as the turned triangle's own arithmetic makes
   it). Corner k of b is corner turn[k] of a; side k of b (opposite corner k) is a's side
   turn[k]. */
static void tri_turned(const struct smooth_kept *a, struct smooth_tri *b)
{
  static const int turn[3] = { 0, 2, 1 };
  b->sface = a->sface;
  b->object = a->object;
  for (int k = 0; k < 3; k++) {
    int q = turn[k];
    b->v[k] = a->v[q];
    b->n[k] = 0 - a->n[k];
    b->len[k] = a->len[q];
    for (int c = 0; c < 3; c++) b->cn[k][c] = 0 - a->cn[q][c];
    for (int c = 0; c < 2; c++) {
      b->bV[k][c] = a->bV[q][c];
      b->bE[k][c] = 0 - a->bE[q][c];
    }
  }
  b->area2 = a->area2;
  b->bu = a->bu;
  b->bw = a->bw;
  b->btot = 0 - a->btot;
}

/* What of the model depends on the scene alone, kept between frames (smooth.h): the
   triangles of each object, oriented consistently (closed objects outward). */
struct smooth_scene {
  const struct scene *s;    /* the scene it was made for */
  int ntri;
  struct smooth_kept *tri;  /* each triangle as oriented here: its corners and their
                               geometry (normal, sides, barycentric set-up, vertex normals) */
  int64_t (*o3)[3];         /* each one's integer normal (cross_int) */
  int nobj;                 /* objects with a triangle */
  struct smooth_part { int from, to; bool closed; } *obj;
  int flips, conflicts;
  int *group, ngroup;       /* edge_group (smooth.h), on the triangles as oriented here */
  /* the model's triangles and edge groups as the last frame turned them (lent to its
     model): valid when view_made, for smooth= view_kind (view_c), each object turned
     (view_turned[o]) as then, with view_normals vertex normals */
  struct smooth_tri *view;
  struct smooth_lanes *view_lanes;
  int *view_group;
  bool *view_turned;
  bool view_made, view_lent;
  enum effects_smooth view_kind;
  double view_c;
  int view_normals;
};

/* The model's triangles given back to their kept part (smooth_model_free). */
static void smooth_scene_return(struct smooth_scene *ss) { ss->view_lent = false; }

void smooth_scene_free(struct smooth_scene *ss)
{
  if (!ss) return;
  free(ss->view);
  free(ss->view_lanes);
  free(ss->view_group);
  free(ss->view_turned);
  free(ss->tri);
  free(ss->o3);
  free(ss->obj);
  free(ss->group);
  free(ss);
}

/* Face fi of s is a patch: a triangle (no holes) shaded from the light (no grey of its
   own), when it is an object's. */
static bool smoothed_face(const struct scene *s, int fi)
{
  const struct scene_face *sf = &s->f[fi];
  return sf->nring == 1 && sf->ring_start[1] == 3 && sf->grey < 0 && s->has_light;
}

/* The scene's part of the model (smooth_scene) into *out. */
static int scene_part(const struct scene *s, struct smooth_scene **out, struct t74_error *err)
{
  struct smooth_scene *ss = calloc(1, sizeof *ss);
  struct smooth_model m;                    /* orient_object's view of the triangles */
  memset(&m, 0, sizeof m);
  /* the triangles: an object's faces that are triangles, shaded from the light */
  size_t ntri = 0;
  for (int o = 0; o < s->nobj; o++)
    for (int q = 0; q < s->obj[o].nface; q++) ntri += smoothed_face(s, s->obj[o].face[q]);
  if (ss) {
    ss->s = s;
    m.tri = malloc((ntri + 1) * sizeof *m.tri);
    ss->obj = malloc(((size_t)s->nobj + 1) * sizeof *ss->obj);
    ss->group = malloc((3 * (size_t)s->nf + 1) * sizeof *ss->group);
  }
  if (!ss || !m.tri || !ss->obj || !ss->group) {
    free(m.tri);
    smooth_scene_free(ss);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  for (int o = 0; o < s->nobj; o++) {
    const struct scene_object *ob = &s->obj[o];
    int from = m.ntri;
    for (int q = 0; q < ob->nface; q++) {
      int fi = ob->face[q];
      const struct scene_face *sf = &s->f[fi];
      if (!smoothed_face(s, fi)) continue;
      struct smooth_tri *tr = &m.tri[m.ntri++];
      memset(tr, 0, sizeof *tr);
      tr->sface = fi;
      tr->object = ob->id;
      for (int k = 0; k < 3; k++) tr->v[k] = sf->vidx[k];
    }
    int to = m.ntri;
    if (to == from) continue;
    struct smooth_part *pt = &ss->obj[ss->nobj++];
    pt->from = from;
    pt->to = to;
    if (orient_object(&m, s, from, to, &pt->closed, ss->group + 3 * (size_t)from, &ss->ngroup,
                      err) != T74_OK) {
      free(m.tri);
      smooth_scene_free(ss);
      return err->status;
    }
  }
  ss->tri = malloc(((size_t)m.ntri + 1) * sizeof *ss->tri);
  ss->o3 = malloc(((size_t)m.ntri + 1) * sizeof *ss->o3);
  double (*acc)[3] = malloc(((size_t)s->nv + 1) * sizeof *acc);
  if (!ss->tri || !ss->o3 || !acc) {
    free(acc);
    free(m.tri);
    smooth_scene_free(ss);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  /* each triangle's geometry, and each object's vertex normals (the mean of the unit
     normals of its triangles at the vertex) */
  for (int o = 0; o < ss->nobj; o++) {
    int from = ss->obj[o].from, to = ss->obj[o].to;
    for (int t = from; t < to; t++)
      for (int k = 0; k < 3; k++) acc[m.tri[t].v[k]][0] = acc[m.tri[t].v[k]][1] = acc[m.tri[t].v[k]][2] = 0;
    for (int t = from; t < to; t++) {
      struct smooth_tri *tr = &m.tri[t];
      tri_shape(s, tr, ss->o3[t]);
      for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++) acc[tr->v[k]][c] += tr->n[c];
    }
    for (int t = from; t < to; t++)
      for (int k = 0; k < 3; k++) {
        memcpy(m.tri[t].cn[k], acc[m.tri[t].v[k]], sizeof m.tri[t].cn[k]);
        unit(m.tri[t].cn[k]);
      }
  }
  free(acc);
  for (int t = 0; t < m.ntri; t++) tri_keep(&m.tri[t], &ss->tri[t]);
  free(m.tri);
  ss->ntri = m.ntri;
  ss->flips = m.flips;
  ss->conflicts = m.conflicts;
  *out = ss;
  return T74_OK;
}

int smooth_model_build(struct smooth_model *m, const struct mapped *map,
                       const struct scene *s, const struct effects *e,
                       struct t74_error *err)
{
  return smooth_model_build_kept(m, map, s, e, NULL, err);
}

/* The model's triangles (and edge groups) as the frame turns each object (turned[o]),
   their vertex normals' rows and their insets for e's smooth=, into tri and group, and
   their shading constants into lanes; the count of vertex normals returned. seen, row: s->nv + 1 ints of scratch. */
static int orient_view(const struct smooth_scene *ss, const struct scene *s,
                       const struct effects *e, const bool *turned, struct smooth_tri *tri,
                       struct smooth_lanes *lanes, int *group, int *seen, int *row)
{
  int normals = 0;
  if (ss->ntri) memcpy(group, ss->group, 3 * (size_t)ss->ntri * sizeof *group);
  for (int k = 0; k < s->nv; k++) seen[k] = -1;
  for (int o = 0; o < ss->nobj; o++) {
    int from = ss->obj[o].from, to = ss->obj[o].to;
    for (int t = from; t < to; t++) {
      struct smooth_tri *tr = &tri[t];
      if (turned[o]) {
        tri_turned(&ss->tri[t], tr);
        int *g = group + 3 * t, x = g[0];   /* side 0 is a's side 2 and back */
        g[0] = g[2]; g[2] = x;
      } else {
        tri_kept(&ss->tri[t], tr);
      }
      for (int k = 0; k < 3; k++) {
        int v = tr->v[k];
        if (seen[v] != o) {
          seen[v] = o;
          row[v] = normals++;
        }
        tr->ni[k] = row[v];
      }
    }
    double w = e->smooth == EFFECTS_SMOOTH_FIXED ? e->smooth_c * mean_height(tri, from, to) : 0;
    for (int t = from; t < to; t++) {
      smooth_insets(e->smooth, e->smooth_c, w, tri[t].len, tri[t].area2, tri[t].t);
      band_ends(&tri[t]);
      tri_lanes(&tri[t], &lanes[t]);
    }
  }
  return normals;
}

int smooth_model_build_kept(struct smooth_model *m, const struct mapped *map,
                            const struct scene *s, const struct effects *e,
                            struct smooth_scene **keep, struct t74_error *err)
{
  memset(m, 0, sizeof *m);
  if (keep && *keep && (*keep)->s != s && (*keep)->view_lent)
    keep = NULL;                            /* a live model holds it: made for this one alone */
  struct smooth_scene *ss = keep && *keep && (*keep)->s == s ? *keep : NULL;
  if (!ss) {
    int rc = scene_part(s, &ss, err);
    if (rc != T74_OK) return rc;
    if (keep) {
      smooth_scene_free(*keep);
      *keep = ss;
    }
  }
  /* the kept part's triangles serve this model unless another holds them */
  const bool lend = keep && !ss->view_lent;
  if (lend && !ss->view) {
    ss->view = malloc(((size_t)ss->ntri + 1) * sizeof *ss->view);
    ss->view_lanes = malloc(((size_t)ss->ntri + 1) * sizeof *ss->view_lanes);
    ss->view_group = malloc((3 * (size_t)ss->ntri + 1) * sizeof *ss->view_group);
    ss->view_turned = malloc(((size_t)ss->nobj + 1) * sizeof *ss->view_turned);
    if (!ss->view || !ss->view_lanes || !ss->view_group || !ss->view_turned) {
      free(ss->view); free(ss->view_lanes); free(ss->view_group); free(ss->view_turned);
      ss->view = NULL; ss->view_lanes = NULL; ss->view_group = NULL; ss->view_turned = NULL;
      return t74_fail(err, T74_EIO, "out of host memory");
    }
    ss->view_made = false;
  }
  int nm = map->nface;
  m->tri_of_mface = malloc(((size_t)nm + 1) * sizeof *m->tri_of_mface);
  int *mof = malloc(((size_t)s->nf + 1) * sizeof *mof);
  bool *turned = malloc(((size_t)ss->nobj + 1) * sizeof *turned);
  /* each triangle's toward_eye, made once: an open surface's sum and every front test */
  wide *dt = malloc(((size_t)ss->ntri + 1) * sizeof *dt);
  if (lend) {
    m->tri = ss->view;
    m->lanes = ss->view_lanes;
    m->edge_group = ss->view_group;
    m->lent = ss;
    ss->view_lent = true;
  } else {
    m->tri = malloc(((size_t)ss->ntri + 1) * sizeof *m->tri);
    m->lanes = malloc(((size_t)ss->ntri + 1) * sizeof *m->lanes);
    m->edge_group = malloc((3 * (size_t)ss->ntri + 1) * sizeof *m->edge_group);
  }
  if (!m->tri_of_mface || !mof || !turned || !dt || !m->tri || !m->lanes || !m->edge_group) {
    free(mof); free(turned); free(dt); smooth_model_free(m);
    if (!keep) smooth_scene_free(ss);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  m->ngroup = ss->ngroup;
  m->ntri = ss->ntri;
  m->flips = ss->flips;
  m->conflicts = ss->conflicts;
  m->objects = ss->nobj;
  const int64_t *eye = map->eye;
  /* an open surface has no outside: its front is the side most of it turns to the eye
     (the sum of o . (eye - v0) over its triangles, exact, positive) */
  bool same = lend && ss->view_made && ss->view_kind == e->smooth && ss->view_c == e->smooth_c;
  for (int t = 0; t < ss->ntri; t++) dt[t] = toward_eye(s, ss->tri[t].v[0], ss->o3[t], eye);
  for (int o = 0; o < ss->nobj; o++) {
    wide toward = 0;
    for (int t = ss->obj[o].from; t < ss->obj[o].to && !ss->obj[o].closed; t++)
      toward += dt[t];
    turned[o] = toward < 0;
    same = same && ss->view_turned[o] == turned[o];
  }
  if (same) {
    m->vertex_normals = ss->view_normals;
  } else {
    int *seen = malloc(((size_t)s->nv + 1) * sizeof *seen);
    int *row = malloc(((size_t)s->nv + 1) * sizeof *row);
    if (!seen || !row) {
      free(seen); free(row); free(mof); free(turned); free(dt);
      if (lend) ss->view_made = false;
      smooth_model_free(m);
      if (!keep) smooth_scene_free(ss);
      return t74_fail(err, T74_EIO, "out of host memory");
    }
    m->vertex_normals = orient_view(ss, s, e, turned, m->tri, m->lanes, m->edge_group, seen, row);
    free(seen); free(row);
    if (lend) {
      memcpy(ss->view_turned, turned, (size_t)ss->nobj * sizeof *turned);
      ss->view_kind = e->smooth;
      ss->view_c = e->smooth_c;
      ss->view_normals = m->vertex_normals;
      ss->view_made = true;
    }
  }
  /* the view's fields: which face the Mapper kept, and whether it faces the eye */
  for (int k = 0; k < s->nf; k++) mof[k] = -1;
  for (int k = 0; k < nm; k++) { mof[map->f[k].sface] = k; m->tri_of_mface[k] = -1; }
  for (int o = 0; o < ss->nobj; o++)
    for (int t = ss->obj[o].from; t < ss->obj[o].to; t++) {
      struct smooth_tri *tr = &m->tri[t];
      tr->mface = mof[tr->sface];
      /* front: the outward side faces the eye, o . (eye - v0) > 0, exactly (v0 stays: the
         kept triangle's v[0] is tr's, dt[t]) */
      const wide d = dt[t];
      tr->front = tr->mface >= 0 && (turned[o] ? d < 0 : d > 0);
      if (tr->mface >= 0) m->tri_of_mface[tr->mface] = t;
    }
  free(mof); free(turned); free(dt);
  if (!keep) smooth_scene_free(ss);
  return T74_OK;
}

/* ---- the shading pass ------------------------------------------------------------- */

static void cost_point(struct cost *c, bool gouraud, int region)
{
  COST_ADD_N(c, COST_MEM, 8);                /* face, triangle row, plane, eye */
  for (int k = 0; k < 6; k++) cost_mw_mul(c, 32, 16);   /* ray onto the plane */
  cost_mw_div(c, 48, 32);
  for (int k = 0; k < 4; k++) cost_mw_mul(c, 32, 32);   /* barycentric coordinates */
  cost_mw_div(c, 64, 32); cost_mw_div(c, 64, 32);
  COST_ADD_N(c, COST_ADD, 3); COST_ADD_N(c, COST_BRANCH, 3);   /* region tests */
  if (gouraud) {
    for (int k = 0; k < 3; k++) cost_mw_mul(c, 16, 16);
    COST_ADD_N(c, COST_ADD, 2);
    return;
  }
  if (region == 0) return;                   /* the inner triangle: the face's grey */
  int corners = 4;
  COST_ADD_N(c, COST_MEM, 3 * corners);
  for (int k = 0; k < 3 * corners; k++) cost_mw_mul(c, 16, 16);
  COST_ADD_N(c, COST_ADD, 3 * corners);
  for (int k = 0; k < 3; k++) cost_mw_mul(c, 16, 16);   /* |n|^2 */
  COST_ADD_N(c, COST_DIV, 12); COST_ADD_N(c, COST_ADD, 24);   /* square root */
  for (int k = 0; k < 3; k++) cost_mw_div(c, 32, 16);
  for (int k = 0; k < 4; k++) cost_mw_mul(c, 16, 16);   /* Lambert */
  COST_ADD_N(c, COST_ADD, 4);
}

/* The areas behind a triangle's barycentric coordinates at space point X (on its plane):
   ar[k] is twice the signed area of side k's triangle with the point on the projection
   axes bu, bw, so that l[k] = ar[k] / btot. They read only the point's coordinates on those
   two axes, x = X[bu] and y = X[bw] (bary_areas_uw takes them alone). */
static inline void bary_areas_uw(const struct smooth_tri *tr, double x, double y, double ar[3])
{
  for (int k = 0; k < 3; k++) {
    const double *a = tr->bV[k == 2 ? 0 : k + 1], *d = tr->bE[k];   /* d: b - a, made once */
    ar[k] = d[0] * (y - a[1]) - (x - a[0]) * d[1];
  }
}

static inline void bary_areas(const struct smooth_tri *tr, const double X[3], double ar[3])
{
  bary_areas_uw(tr, X[tr->bu], X[tr->bw], ar);
}

#ifdef __SSE2__
/* bary_areas' ar[k] at two points, a point a lane (x, y: their coordinates on the axes bu,
   bw), from side k's constants as smooth_lanes keeps them twice: a = xa[k], d = xsd[k] (d
   times tot's sign: the area times the sign but for the sign of a zero, phong_pairs and
   inner_split); bary_areas' operations in its order. */
static inline __m128d area_lanes(const double (*a)[2], const double (*d)[2], __m128d x,
                                 __m128d y)
{
  return _mm_sub_pd(_mm_mul_pd(_mm_load_pd(d[0]), _mm_sub_pd(y, _mm_load_pd(a[1]))),
                    _mm_mul_pd(_mm_sub_pd(x, _mm_load_pd(a[0])), _mm_load_pd(d[1])));
}
#endif

/* Barycentric coordinates from bary_areas' areas, clamped into the triangle, for points
   p < n <= SMOOTH_RUN: several points side by side only let their chains of divides
   overlap in the processor. */
static inline void bary_of_areas(const struct smooth_tri *tr, int n, const double (*ar)[3],
                                 double (*l)[3])
{
  const double tot = tr->btot;
  /* sum[p] starts at the first coordinate, not at 0 + it: the same double, as a clamped
     coordinate is never -0 (and no array to clear a run) */
  double sum[SMOOTH_RUN];
  for (int k = 0; k < 3; k++)
    for (int p = 0; p < n; p++) {
      l[p][k] = tot != 0 ? ar[p][k] / tot : 1.0 / 3;
      if (!(l[p][k] > 0)) l[p][k] = 0;
      sum[p] = k ? sum[p] + l[p][k] : l[p][k];
    }
  for (int p = 0; p < n; p++) {
    if (!(sum[p] > 0)) l[p][0] = l[p][1] = l[p][2] = 1.0 / 3;
    else if (sum[p] != 1)                 /* x / 1 is x: the divides only when they change it */
      for (int k = 0; k < 3; k++) l[p][k] /= sum[p];
  }
}

/* bary_of_areas at points q < n whose areas are given a component an array (a[k][q]),
   the coordinates likewise (l[k][q]): two points an instruction where the processor has
   SSE2, the same correctly rounded divides and adds on the same values in the same order
   (the sum l_0 + l_1, then + l_2); max(x, 0) is x when x > 0, else +0 (a NaN too: MAXPD
   gives its second operand), the scalar clamp's; l / sum is l itself where sum is 1, so
   each lane divides whenever sum > 0, as the scalar code does when sum is not 1; the rest
   one by one through bary_of_areas itself. */
static inline void bary_pairs(const struct smooth_tri *tr, int n, const double (*a)[SMOOTH_ROW],
                              double (*l)[SMOOTH_ROW])
{
  int q = 0;
#ifdef __SSE2__
  const double tot = tr->btot;
  if (tot != 0) {
    const __m128d tv = _mm_set1_pd(tot), zero = _mm_setzero_pd(), third = _mm_set1_pd(1.0 / 3);
    for (; q + 2 <= n; q += 2) {
      __m128d lk[3];
      for (int k = 0; k < 3; k++) lk[k] = _mm_max_pd(_mm_div_pd(_mm_loadu_pd(a[k] + q), tv), zero);
      const __m128d sum = _mm_add_pd(_mm_add_pd(lk[0], lk[1]), lk[2]);
      const __m128d pos = _mm_cmpgt_pd(sum, zero);
      for (int k = 0; k < 3; k++)
        _mm_storeu_pd(l[k] + q, _mm_or_pd(_mm_and_pd(pos, _mm_div_pd(lk[k], sum)),
                                          _mm_andnot_pd(pos, third)));
    }
  }
#endif
  for (; q < n; q++) {
    const double one[1][3] = { { a[0][q], a[1][q], a[2][q] } };
    double lo[1][3];
    bary_of_areas(tr, 1, one, lo);
    for (int k = 0; k < 3; k++) l[k][q] = lo[0][k];
  }
}

/* The Phong grey at space point X of the triangle from its areas ar (bary_areas): the
   exact chain, the one that defines a Phong grey. */
static void grey_phong_exact(const struct smooth_tri *tr, const double ar[3], const double X[3],
                             double refl, unsigned blocked, const struct shade_lights *lights,
                             int *grey)
{
  double l[1][3], nrm[3];
  bary_of_areas(tr, 1, (const double (*)[3])ar, l);
  for (int c = 0; c < 3; c++)
    nrm[c] = l[0][0] * tr->cn[0][c] + l[0][1] * tr->cn[1][c] + l[0][2] * tr->cn[2][c];
  unit(nrm);
  const double sgn = tr->front ? 1 : -1;     /* seen from inside: the eye's side */
  for (int c = 0; c < 3; c++) nrm[c] *= sgn;
  int g = shade_grey_lit(lights, nrm, X, refl, blocked);
  *grey = g < 0 ? 0 : g > 255 ? 255 : g;
}

/* The Phong grey's filter.
**
** The exact chain above spends up to nine divides and a square root on a point: each
** barycentric coordinate divided by the triangle's area, by their sum, each component of
** the normal by its length. The filter finds the same grey with one divide and one square
** root, or says it cannot, and then the exact chain runs; the grey is the exact chain's,
** bit for bit, either way.
**
** Both chains start from the same doubles ar_k (bary_areas). In real numbers, let
** w_k = max(0, ar_k / tot) (tot = btot != 0), lam_k = w_k / sum w, N = sum lam_k cn_k,
** U = N / |N| and D = sum over the lights not blocked of max(0, s U . l_j) (s = +-1, the
** eye's side): the grey is A + floor(F) with F = (255 - A) r D + 1/2 (render/shade.h).
** Scaling the w_k scales N and leaves U as it is, so the filter takes w_k = max(0, +-ar_k)
** (the sign of tot: exact) and never divides by tot or by sum w; it normalises once, by
** 1 / |N'| with N' = sum w_k cn_k.
**
** Error of the exact chain against F (u = 2^-53, |cn_k| <= 1 + 4u, |l_j| <= 1 + 4u, as
** each is a unit vector rounded; r <= 1; at most SCENE_LIGHT_MAX = 16 lights): each
** clamped coordinate is lam_k (1 + e), |e| <= 7u (a divide, a sum of three positive terms
** and a second divide, or none when the sum is 1), provided none underflows to 0 or
** overflows (the filter declines when a positive w_k is below |tot| 2^-1000 or above
** |tot| 2^1000, or when all are 0: the exact chain's 1/3 each); so each normal component is off by at most
** 11u sum lam_k = 11u, the vector by E = 11 sqrt(3) u < 20u, and its unit vector from U by
** at most 2E / |N| + 5u (|a/|a| - b/|b|| <= 2 |a - b| / |b|, then the length's and the
** divides' roundings). Each light's dot is then within 41u / |N| + 8u of s U . l_j, max(0,
** .) does not widen that, a sum of 16 adds at most 17u a light, and F's two roundings
** (207 r times the sum, then + 1/2; 207 r is the same double in both chains) at most
** 2u |F| <= 2u 3,313: |F_exact - F| <= 207 * 16 * (41u / |N| + 25u) + 6,626u
** < 2^-35 (1 + 1/|N|). The filter's
** own chain is nearer (no divides before the normal: its vector is off by 6u sum w, 6u
** |N'| / |N|, its unit vector by 12u / |N| + 4u), so |F_filter - F_exact| < 2^-34 (1 +
** 1/|N|). The filter declines when r is not in [0, 1], when the computed sum s of the
** w_k is below 2^-500 (so that fl(fl(s s) 2^-20) >= 2^-1020 is a normal number, rounded
** within a relative u), or when nn = fl(|N'|^2) < fl(fl(s s) 2^-20): the vertex normals
** nearly cancel, and the exact chain's own length test is then left to it. Where it
** passes, |N| >= 2^-10 (1 - 2^-39): nn is within a relative 6u of the square of the
** computed N' (three products and two sums of non-negative terms, 4u; a product that
** falls below 2^-1022 is off by at most 2^-1075 absolutely, three of them under 2^-53 of
** nn >= 2^-1020), and fl(fl(s s) 2^-20) >= s^2 2^-20 (1 - 2u), so the computed N' has
** length at least s 2^-10 (1 - 4u); s >= (sum w)(1 - 2u) (two roundings of positive
** terms); the computed N' is within 12u sum w of the real one (each component's 6u sum
** w, 11u for the vector, plus at most 3 2^-1075 a component from products below 2^-1022,
** less than 2^-570 sum w as sum w > 2^-501); so |N| = |N'| / sum w >= 2^-10 (1 - 6u) -
** 12u >= 2^-10 (1 - 2^-39). Then 1/|N| < 2^10 (1 + 2^-38) and |F_filter - F_exact| <
** 2^-34 (1 + 2^10 (1 + 2^-38)) < 2^-24 (1 + 2^-9): the filter takes the margin delta =
** 2^-23, the same for every point, and gives A + floor(F_filter) only when fl(F_filter
** - delta) and fl(F_filter + delta) truncate to the same integer. F_filter is below 2^12 (at most 16 lights, r <= 1: F <= 207 16
** (1 + 2^-40) + 1/2 < 3,313), so each of the two sums is within 2^-42 of F_filter -+
** delta (a rounding to nearest never crosses an integer, which is a double); both lie in
** [k, k + 1) for the one integer k, so [F_filter - delta + 2^-42, F_filter + delta -
** 2^-42], which holds F_exact (2^-24 (1 + 2^-9) < 2^-23 - 2^-42), lies in [k, k + 1)
** too: F_exact's floor is k, and the grey A + k is the exact chain's. (The margin was 2^-24 (1 + 2 sum
** w / |N'|) before, a point's own: above 2^-23 at every point, as sum w >= |N'| (1 -
** 8u), so the constant 2^-23 declines no more points, and needs no multiplies.) A point
** is declined with odds of about 2 delta, a few in ten million. The filter works on a run
** of points in steps (their normals, then their square roots and divides, then their
** lights), so that the processor overlaps the points' square roots and divides instead
** of waiting on each. test_smooth (test_phong_filter_is_exact) holds it to the exact
** chain on a grid of points in and around every triangle of the globe under several
** lights, and on points bisected onto the borders between two greys, where it must
** decline (and does, at each). */
static inline void phong_filter(const struct smooth_tri *tr, int n, const double (*ar)[3],
                                const double (*X)[3], double refl, const unsigned *blocked,
                                const struct shade_lights *L, int *grey, bool *ok)
{
  const double tot = tr->btot;
  const double at = fabs(tot), lo = at * 0x1p-1000, hi = at * 0x1p1000;
  const double sgn = tr->front ? 1 : -1, st = tot > 0 ? 1 : -1;
  const bool usable = tot != 0 && refl >= 0 && refl <= 1;
  double N[SMOOTH_RUN][3], inv[SMOOTH_RUN];
  /* in steps over the n points, so that their square roots and divides overlap; the
     clamps and tests without branches (a point near a side goes either way) */
  for (int p = 0; p < n; p++) {
    double w[3], s = 0;
    bool good = usable;
    for (int k = 0; k < 3; k++) {
      const double v = st * ar[p][k];       /* exact */
      w[k] = v > 0 ? v : 0;
      good &= (w[k] == 0) | ((w[k] >= lo) & (w[k] <= hi));
      s += w[k];
    }
    for (int c = 0; c < 3; c++)
      N[p][c] = w[0] * tr->cn[0][c] + w[1] * tr->cn[1][c] + w[2] * tr->cn[2][c];
    double nn = N[p][0] * N[p][0] + N[p][1] * N[p][1] + N[p][2] * N[p][2];
    /* |N| at least about 2^-10; s >= 2^-500 keeps s * s * 2^-20 a normal number */
    ok[p] = good && s >= 0x1p-500 && nn >= s * s * 0x1p-20;
    inv[p] = ok[p] ? nn : 1;
  }
  int q = 0;
#ifdef __SSE2__
  /* two points an instruction: the same correctly rounded square roots and divides */
  for (const __m128d sg = _mm_set1_pd(sgn); q + 2 <= n; q += 2)
    _mm_storeu_pd(inv + q, _mm_div_pd(sg, _mm_sqrt_pd(_mm_loadu_pd(inv + q))));
#endif
  for (; q < n; q++) inv[q] = sgn / sqrt(inv[q]);
  for (int p = 0; p < n; p++) {
    if (!ok[p]) continue;
    double sum = 0;
    for (int k = 0; k < L->n; k++) {
      if (blocked[p] >> k & 1u) continue;
      const double *l = L->v[k];
      double pl[3];
      if (L->point[k]) {
        shade_point_dir(l, X[p], pl);
        l = pl;
      }
      double d = (N[p][0] * l[0] + N[p][1] * l[1] + N[p][2] * l[2]) * inv[p];
      sum += d > 0 ? d : 0;
    }
    const double f = (255 - SHADE_AMBIENT) * refl * sum + 0.5;
    const double f0 = f - 0x1p-23, f1 = f + 0x1p-23;
    ok[p] = f0 >= 0 && f1 < 0x1p62 && (int64_t)f0 == (int64_t)f1;
    const int g = SHADE_AMBIENT + (int)(f0 >= 0 && f0 < 0x1p62 ? (int64_t)f0 : 0);
    grey[p] = g > 255 ? 255 : g;
  }
}

/* The inner triangle's filter.
**
** A point of the partial smoothing is in region 0 (the flat inner triangle) when every
** clamped barycentric coordinate l_k of the exact chain (bary_of_areas) is at least the
** inset t_k (smooth_partial_normal); there its normal is the face's, whatever l is. The
** filter proves that from the areas ar_k (bary_areas, the same doubles) with three
** multiplies and compares a coordinate, no divide, or declines and leaves the point to
** the chain (which decides it the same way it always did).
**
** Let at = |tot| (tot = btot), w_k = +-ar_k (tot's sign: exact), W = w_0 + w_1 + w_2 in
** real numbers, u = 2^-53, c = 1 + 2^-40, tc_k = max(fl(t_k c), 2^-898) (a triangle's
** three, made with its insets: inner_tc). The filter declines unless 2^-100 <= at <= 2^100,
** S = fl(fl(w_0 + w_1) + w_2) is in [at / 2, 2 at] (at / 2 and 2 at are exact, and the
** range test is made once a triangle: tri_lanes) and every w_k >= R_k = fl(tc_k S). Then
** tc_k S >= 2^-999 (so R_k is a normal number, rounded within a relative u) and every
** w_k >= R_k >= at 2^-900 > 0; W <= S / (1 - u)^2, so each a_k = ar_k / tot = w_k / at lies
** in [2^-900, 2 + 8u] and no step of the chain below underflows or overflows. The chain:
** l'_k = fl(ar_k / tot) = a_k (1 + d), |d| <= u, positive (no clamp); their sum s' (two
** adds of positive terms) = (sum a)(1 + e), |e| < 3.01u; l_k = l'_k when s' is 1, else
** fl(l'_k / s'): either way l_k >= (w_k / W)(1 - 5.03u) (a_k / sum a is w_k / W). When
** t_k > 0: R_k >= tc_k S (1 - u) >= t_k c (1 - u)^2 S >= t_k c (1 - u)^4 W (S: two
** roundings down at most), so w_k / W >= t_k (1 - u)^4 (1 + 2^-40) and l_k >= t_k (1 +
** 2^-40 - 10u) > t_k; when t_k = 0, l_k > 0 = t_k. So no l_k is below its t_k: the chain
** says region 0. The filter declines only points within a relative 2^-40 of the inner
** triangle's border (none in practice), and those outside it. test_smooth
** (test_inner_filter_is_exact) holds it to the chain on a grid in and around every triangle
** of the globe under several insets, and on points bisected onto the inner triangle's
** border, where it must decline. */
/* The filter at one point from its areas ar (bary_areas): true when it proves the point
   inner. x: the triangle's constants (tot's sign, the bounds on S, the scaled insets). */
static inline bool inner_one(const double ar[3], const struct smooth_lanes *x)
{
  const double st = x->xst[0];
  const double w0 = st * ar[0], w1 = st * ar[1], w2 = st * ar[2];
  const double S = w0 + w1 + w2;
  return S >= x->xilo[0] && S <= x->xihi[0] && w0 >= x->xtc[0][0] * S &&
         w1 >= x->xtc[1][0] * S && w2 >= x->xtc[2][0] * S;
}

/* The partial smoothing's points in a run, split by the inner triangle's filter: what the
   partial smoothing's first step needs, without arrays in between. */
struct split {
  int nl;                   /* points left to the chain: */
  int at[SMOOTH_ROW];       /*   their indices in the run */
  double la[3][SMOOTH_ROW]; /*   a component an array: their areas (bary_areas; a run's, for
                                 bary_pairs), or their barycentric coordinates (a row's
                                 stretch: inner_split's row) */
  int tri[SMOOTH_ROW];      /*   their triangles (a row's stretch) */
  int ni;                   /* points the filter proved inner whose grey is lit (not the
                               flat picture's): */
  int lit_in[SMOOTH_ROW];   /*   their indices */
  int lit_tri[SMOOTH_ROW];  /*   their triangles (likewise) */
};

/* bary_of_areas at one point from its areas a, for a triangle whose btot is tot: the same
   operations in the same order. */
static inline void bary_one(double tot, const double a[3], double l[3])
{
  double sum = 0;
  for (int k = 0; k < 3; k++) {
    l[k] = tot != 0 ? a[k] / tot : 1.0 / 3;
    if (!(l[k] > 0)) l[k] = 0;
    sum = k ? sum + l[k] : l[k];
  }
  if (!(sum > 0)) l[0] = l[1] = l[2] = 1.0 / 3;
  else if (sum != 1)
    for (int k = 0; k < 3; k++) l[k] /= sum;
}

/* Point p of the run proved inner (region 0, the face's normal): given the flat picture's
   grey fg where that is exactly its grey (reflectance 1, no light blocked), else put aside
   to be lit with the face's normal (as point base + p of triangle t). row (a constant
   where it is inlined): a row's stretch (smooth_row), whose regions are counted, not
   written, and whose points are of several triangles (lit_tri); else a run's. */
static inline __attribute__((always_inline))
void inner_point(struct split *sp, int p, bool flat, const unsigned *blocked, int fg,
                 int *grey, int *region, int base, int t, bool row)
{
  if (!row) region[p] = 0;
  if (flat && !blocked[p]) grey[p] = fg;
  else {
    if (row) sp->lit_tri[sp->ni] = t;
    sp->lit_in[sp->ni++] = base + p;
  }
}

/* bary_areas at points X[p], p < n (X NULL: at the points whose coordinates on tr's axes
   bu and bw are xu[p] and xw[p], all bary_areas reads), and the filter's answer for each:
   a point it proves inner handled at once (inner_point), the others' areas and indices
   into sp for the chain. Two points an instruction where the processor has SSE2 (the same correctly
   rounded operations on the same values, and the same tests), the rest one by one.
   flat: reflectance 1 (refl == 1). The points are triangle t's (tr, lx), put into sp
   after those there as base + p. row (a constant where it is inlined, as inner_point's):
   the regions not written (the points proved inner are the n less those put to the
   chain), each chain point's triangle put with it (sp->tri), and its barycentric
   coordinates in place of its areas, made at once (bary_one's operations on the same
   values: see below), so that their divides overlap the filter's work on the points after
   it; nothing waits on them before partial_row's next step. */
static inline __attribute__((always_inline))
void inner_split(const struct smooth_model *m, const struct smooth_tri *tr,
                               const struct smooth_lanes *lx, int n, const double (*X)[3],
                               const double *xu, const double *xw, bool flat, const unsigned *blocked,
                               int fg, int *grey, int *region, struct split *sp, int base, int t,
                               bool row)
{
  const bool usable = lx->inner_ok && !m->inner_exact;
  long declines = 0;
  int p = 0;
#ifdef __SSE2__
  if (usable) {
    const int bu = tr->bu, bw = tr->bw;
    const __m128d sv = _mm_load_pd(lx->xst), lov = _mm_load_pd(lx->xilo), hiv = _mm_load_pd(lx->xihi);
    const __m128d atv = _mm_set1_pd(fabs(tr->btot));
    for (; p + 2 <= n; p += 2) {
      /* (xu, xw: 16 bytes a load, as smooth_partial_row's callers store them) */
      const __m128d x = X ? _mm_set_pd(X[p + 1][bu], X[p][bu]) : _mm_loadu_pd(xu + p);
      const __m128d y = X ? _mm_set_pd(X[p + 1][bw], X[p][bw]) : _mm_loadu_pd(xw + p);
      /* w_k = +-ar_k (tot's sign) from the sides' constants times the sign (xsd), as in
         phong_pairs: (-d_u) (y - a_w) - (x - a_u) (-d_w) is -(d_u (y - a_w) - (x - a_u) d_w)
         exactly (rounding to nearest is symmetric under negation), but where the area is a
         zero: then w_k is a zero too, maybe of the other sign. No test below tells the
         zeros apart (an S of 0 is below at / 2 > 0 either way, and w_k >= tc_k S compares
         zeros as equal), and the areas given back to the chain (v_k = sign times w_k: ar_k,
         or a zero where it is a zero) make the same coordinates: the chain's clamp (bary_pairs'
         max with +0, bary_of_areas' test) makes +0 of a zero of either sign over tot. */
      __m128d w[3];
      for (int k = 0; k < 3; k++) w[k] = area_lanes(lx->xa[k], lx->xsd[k], x, y);
      const __m128d S = _mm_add_pd(_mm_add_pd(w[0], w[1]), w[2]);
      __m128d ok = _mm_and_pd(_mm_cmpge_pd(S, lov), _mm_cmple_pd(S, hiv));
      for (int k = 0; k < 3; k++)
        ok = _mm_and_pd(ok, _mm_cmpge_pd(w[k], _mm_mul_pd(_mm_load_pd(lx->xtc[k]), S)));
      const int bits = _mm_movemask_pd(ok);
      if (bits == 3 && flat && !(blocked[p] | blocked[p + 1])) {   /* the common case */
        if (!row) region[p] = region[p + 1] = 0;
        grey[p] = grey[p + 1] = fg;
        continue;
      }
      __m128d v[3];
      if (row) {
        /* the coordinates, each lane bary_one's operations with tot (not 0: |tot| >=
           2^-100 where the filter is used) on v_k = s w_k (s = +-1, tot's sign: the areas
           given back to the chain, which make the same coordinates as ar_k, above):
           l'_k = max(v_k / tot, +0) (+0 where the quotient is not > 0, a NaN too: MAXPD
           gives its second operand), their sum (l'_0 + l'_1) + l'_2, and l'_k / sum where
           sum > 0 (l' / 1 is l' itself, so the divide where bary_one skips it gives the
           same), else 1/3: selections, no branch. v_k / tot is (s w_k) / (s |tot|), and a
           quotient (IEEE 754: its magnitude |a| / |b| correctly rounded, its sign the
           exclusive or of theirs) is the same double when both operands are negated:
           w_k / |tot|, bit for bit, zeros included (a NaN is a NaN either way, and the
           max makes +0 of it); so the divides take w_k itself, without the multiplies by
           s in front of them on the chain */
        const __m128d zero = _mm_setzero_pd();
        __m128d lk[3];
        for (int k = 0; k < 3; k++) lk[k] = _mm_max_pd(_mm_div_pd(w[k], atv), zero);
        const __m128d sum = _mm_add_pd(_mm_add_pd(lk[0], lk[1]), lk[2]);
        const __m128d pos = _mm_cmpgt_pd(sum, zero);
        if (_mm_movemask_pd(pos) == 3)      /* both sums positive: the selection's value */
          for (int k = 0; k < 3; k++) v[k] = _mm_div_pd(lk[k], sum);
        else
          for (int k = 0; k < 3; k++)
            v[k] = _mm_or_pd(_mm_and_pd(pos, _mm_div_pd(lk[k], sum)),
                             _mm_andnot_pd(pos, _mm_set1_pd(1.0 / 3)));
      } else {
        for (int k = 0; k < 3; k++) v[k] = _mm_mul_pd(sv, w[k]);
      }
      for (int h = 0; h < 2; h++) {
        if (bits >> h & 1) {
          inner_point(sp, p + h, flat, blocked, fg, grey, region, base, t, row);
          continue;
        }
        declines++;
        for (int k = 0; k < 3; k++)
          if (h) _mm_storeh_pd(&sp->la[k][sp->nl], v[k]);
          else _mm_storel_pd(&sp->la[k][sp->nl], v[k]);
        if (row) sp->tri[sp->nl] = t;
        sp->at[sp->nl++] = base + p + h;
      }
    }
  }
#endif
  for (; p < n; p++) {
    double ar[3];
    if (X) bary_areas(tr, X[p], ar);
    else bary_areas_uw(tr, xu[p], xw[p], ar);
    if (usable && inner_one(ar, lx)) {
      inner_point(sp, p, flat, blocked, fg, grey, region, base, t, row);
      continue;
    }
    declines += usable;
    if (row) {
      double l[3];
      bary_one(tr->btot, ar, l);
      for (int k = 0; k < 3; k++) sp->la[k][sp->nl] = l[k];
      sp->tri[sp->nl] = t;
    } else
      for (int k = 0; k < 3; k++) sp->la[k][sp->nl] = ar[k];
    sp->at[sp->nl++] = base + p;
  }
  if (m->inner_declines) *m->inner_declines += declines;
}

/* The Phong grey at points p < n <= SMOOTH_RUN from their areas: the filter, and the
   exact chain for a point it declines. */
static inline void phong_lanes(const struct smooth_model *m, const struct smooth_tri *tr, int n,
                               const double (*ar)[3], const double (*X)[3], double refl,
                               const unsigned *blocked, const struct shade_lights *lights,
                               int *grey)
{
  bool ok[SMOOTH_RUN];
  if (!m->phong_exact) phong_filter(tr, n, ar, X, refl, blocked, lights, grey, ok);
  for (int p = 0; p < n; p++) {
    if (!m->phong_exact) {
      if (ok[p]) continue;
      if (m->phong_declines) ++*m->phong_declines;
    }
    grey_phong_exact(tr, ar[p], X[p], refl, blocked[p], lights, &grey[p]);
  }
}

static inline int clamp_grey(int g) { return g < 0 ? 0 : g > 255 ? 255 : g; }

static inline __attribute__((always_inline))
void lit_row(const struct smooth_model *m, int q, int ns, double (*nv)[SMOOTH_ROW],
             const double *sg, double refl, const int *slot_p, const double (*X)[3],
             const unsigned *blocked, const struct shade_lights *L, int *grey);

/* lit_row with one side sgn for every slot (a run's: one triangle). */
static inline void lit_slots(const struct smooth_model *m, double sgn, int ns,
                             double (*nv)[SMOOTH_ROW], const int *slot_p, const double (*X)[3],
                             double refl, const unsigned *blocked, const struct shade_lights *L,
                             int *grey)
{
  double sg[SMOOTH_ROW];
  for (int q = 0; q < ns; q++) sg[q] = sgn;
  lit_row(m, 0, ns, nv, sg, refl, slot_p, X, blocked, L, grey);
}

#ifdef __SSE2__
/* The parallel lights' directions of L for phong_tail, each component in both lanes. */
static inline void phong_lights(const struct shade_lights *L, __m128d (*lv)[3])
{
  for (int k = 0; k < L->n; k++)
    for (int c = 0; c < 3; c++) lv[k][c] = _mm_set1_pd(L->v[k][c]);
}

/* The eye's sides of triangles ta and tb (lanes 0 and 1): +1 where it is front, else -1. */
static inline __m128d phong_side(const struct smooth_tri *ta, const struct smooth_tri *tb)
{
  return _mm_set_pd(tb->front ? 1 : -1, ta->front ? 1 : -1);
}

/* Two doubles into lanes 0 and 1: one aligned load of a smooth_lanes pair when both lanes
   take the same triangle's constants (same: a constant where phong_head is inlined), else
   lane 0 from a, lane 1 from b (pick2). */
static inline __attribute__((always_inline)) __m128d lanes2(const double *a, const double *b,
                                                             bool same)
{
  return same ? _mm_load_pd(a) : pick2(a, b);
}

#endif

/* Point p's space point where phong_tri_at's triangle tr needs it (bary_areas, and
   grey_phong_exact under parallel lights, which reads only its coordinates on tr's axes bu
   and bw): X[p] itself, or (X NULL: smooth_phong_row's points) xu[p] and xw[p] put on those
   axes in *buf, the third coordinate 0. */
static inline const double *phong_point(const double (*X)[3], const double *xu,
                                        const double *xw, const struct smooth_tri *tr, int p,
                                        double buf[3])
{
  if (X) return X[p];
  buf[0] = buf[1] = buf[2] = 0;
  buf[tr->bu] = xu[p];
  buf[tr->bw] = xw[p];
  return buf;
}

/* The Phong rows' last test and grey for one point p of triangle tr, whatever the width of
   their step: the grey from the filter's two values f0, f1 (phong_filter's) where the lane
   passed the step's tests (ok) and both give one integer, else (counted as a decline) the
   exact chain at p's space point (phong_point). */
static inline void phong_lane_grey(const struct smooth_model *m, const struct smooth_tri *tr,
                                   const double (*X)[3], const double *xu, const double *xw,
                                   int p, bool ok, double f0, double f1, double refl,
                                   unsigned blocked, const struct shade_lights *L, int *g)
{
  if (ok && f0 >= 0 && f1 < 0x1p62 && (int64_t)f0 == (int64_t)f1) {
    const int gv = SHADE_AMBIENT + (int)(int64_t)f0;
    *g = gv > 255 ? 255 : gv;
    return;
  }
  if (m->phong_declines) ++*m->phong_declines;
  double buf[3], ar[3];
  const double *Xp = phong_point(X, xu, xw, tr, p, buf);
  bary_areas(tr, Xp, ar);
  grey_phong_exact(tr, ar, Xp, refl, blocked, L, g);
}

/* smooth_grey_run's Phong grey of one point X of triangle tr (reflectance 1) where
   phong_pairs declines the triangle: its areas, then phong_lanes. */
static void phong_alone(const struct smooth_model *m, const struct smooth_tri *tr,
                        const double X[3], unsigned blocked, const struct shade_lights *L,
                        int *grey)
{
  double ar[1][3];
  bary_areas(tr, X, ar[0]);
  phong_lanes(m, tr, 1, (const double (*)[3])ar, (const double (*)[3])X, 1.0, &blocked, L,
              grey);
}

#ifdef __SSE2__
/* A row's steps (phong_row_lights), kept between its two passes: step j's points pa[j]
   (lane 0) and pa[j] + two[j] (lane 1: the next point, or pa[j] again for a lone point,
   two[j] 0), the normals' sums n[c][j], the operand of the square root r[j] (nn), the
   eye's sides sg[j] and okb[j], ok's lanes (the areas' sums are not kept: the filter's
   margin is a constant). A point's triangle is not kept: only a point the filter declines needs it, and
   it is found there (phong_tri_at). */
#define PHONG_STEPS SMOOTH_ROW
struct phong_steps {
  _Alignas(16) double n[3][PHONG_STEPS][2];
  _Alignas(16) double r[PHONG_STEPS][2];
  _Alignas(16) double sg[PHONG_STEPS][2];
  int pa[PHONG_STEPS], two[PHONG_STEPS], okb[PHONG_STEPS];
};

/* The triangle of point p of a stretch of nseg runs (point at[k] <= p < at[k + 1] is
   triangle tri[k]'s). */
static inline int phong_tri_at(int nseg, const int *tri, const int *at, int p)
{
  int k = 0;
  while (k + 1 < nseg && at[k + 1] <= p) k++;
  return tri[k];
}
_Static_assert((SMOOTH_RUN + 1) / 2 <= PHONG_STEPS, "a run's steps fit in struct phong_steps");

/* The first half of a step of phong_pairs and phong_row_lights at two points: Xa of
   triangle ta (constants xa) in lane 0 and Xb of triangle tb (xb) in lane 1 (the same
   point twice for a lone one; same: ta is tb), each lane with its own triangle's
   constants, given by their coordinates on their triangles' axes bu and bw (x: Xa[ta->bu]
   in lane 0, Xb[tb->bu] in lane 1; y likewise on bw), all the step needs of them; the
   operations up to the square root's operand, into step j of *S (N into
   n, the operand into r, sg, ok's lanes). Each lane's operations are phong_filter's
   for its point alone, in their order (see phong_lanes): the lanes never mix. Both
   triangles' btot is not 0; sg the eye's sides, +-1 by front (phong_side). */
static inline __attribute__((always_inline))
void phong_head(const struct smooth_lanes *xa, const struct smooth_lanes *xb, bool same,
                __m128d x, __m128d y, __m128d sg, struct phong_steps *S, int j)
{
  const __m128d lo = lanes2(xa->xlo, xb->xlo, same), hi = lanes2(xa->xhi, xb->xhi, same);
  const __m128d zero = _mm_setzero_pd(), scale = _mm_set1_pd(0x1p-20);
  const __m128d tiny = _mm_set1_pd(0x1p-500);
  __m128d w[3], s = zero;
  for (int k = 0; k < 3; k++) {
    /* max(+-ar_k, 0) (tot's sign) with the sign in the sides' constants (xsd: d times
       the sign): where tot < 0, (-d_u) (y - a_w) - (x - a_u) (-d_w) is -(d_u (y - a_w) -
       (x - a_u) d_w) exactly (rounding to nearest is symmetric under negation), but where
       that difference is 0: +0 here against -0 there, and the max with +0 makes either
       +0 (MAXPD gives its second operand when the two are equal); area_lanes' operations */
    const __m128d ar = _mm_sub_pd(
        _mm_mul_pd(lanes2(xa->xsd[k][0], xb->xsd[k][0], same),
                   _mm_sub_pd(y, lanes2(xa->xa[k][1], xb->xa[k][1], same))),
        _mm_mul_pd(_mm_sub_pd(x, lanes2(xa->xa[k][0], xb->xa[k][0], same)),
                   lanes2(xa->xsd[k][1], xb->xsd[k][1], same)));
    w[k] = _mm_max_pd(ar, zero);
    /* phong_filter's s = 0 + w_0 is w_0 itself: w_0 is +0 or above (MAXPD with +0 never
       gives -0 nor a NaN), and +0 + w_0 is w_0 then */
    s = k ? _mm_add_pd(s, w[k]) : w[k];
  }
  /* a narrower test than phong_filter's (it declines more: a point with a w_k of 0 too,
     and one whose sum is above hi), in five instructions: every w_k >= min >= lo, and
     w_k <= s <= hi (s a sum of non-negative terms, each rounding monotone) */
  const __m128d good = _mm_and_pd(_mm_cmpge_pd(_mm_min_pd(_mm_min_pd(w[0], w[1]), w[2]), lo),
                                  _mm_cmple_pd(s, hi));
  __m128d N[3];
  for (int c = 0; c < 3; c++) {
    N[c] = _mm_add_pd(_mm_add_pd(_mm_mul_pd(w[0], lanes2(xa->xcn[0][c], xb->xcn[0][c], same)),
                                 _mm_mul_pd(w[1], lanes2(xa->xcn[1][c], xb->xcn[1][c], same))),
                      _mm_mul_pd(w[2], lanes2(xa->xcn[2][c], xb->xcn[2][c], same)));
    _mm_store_pd(S->n[c][j], N[c]);
  }
  const __m128d nn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(N[0], N[0]), _mm_mul_pd(N[1], N[1])),
                                _mm_mul_pd(N[2], N[2]));
  const __m128d ok = _mm_and_pd(_mm_and_pd(good, _mm_cmpge_pd(s, tiny)),
                                _mm_cmpge_pd(nn, _mm_mul_pd(_mm_mul_pd(s, s), scale)));
  /* the square root's operand nn: where not ok (okb) the lane is declined whatever its
     square root, divide and grey come to (0, an infinity or a NaN among them) */
  _mm_store_pd(S->r[j], nn);
  _mm_store_pd(S->sg[j], sg);
  S->okb[j] = _mm_movemask_pd(ok);
}

/* The second half of step j of *S (phong_head made the first): from the square root on,
   phong_filter's operations in their order: inv, each parallel light's term (a light
   blocked or a dot not > 0 adds +0), the grey under reflectance refl in [0, 1] by
   phong_filter's last test, and the exact chain where that declines (counted in
   phong_declines; the point's triangle from the stretch's runs nseg, tri, at: see
   phong_tri_at; its space point from X, or xu and xw: phong_point). nlight is L->n (a
   constant where the caller can make it one), lv the
   lights' directions in both lanes (phong_lights). shadow false (a constant where the
   caller makes it one): every blocked[] of the steps' points is 0, and is not read. */
static inline __attribute__((always_inline))
void phong_tail(const struct smooth_model *m, const struct phong_steps *S, int j,
                const double (*X)[3], const double *xu, const double *xw, double refl,
                const unsigned *blocked, bool shadow,
                const struct shade_lights *L, const __m128d (*lv)[3], int nlight,
                int nseg, const int *tri, const int *at, int *grey)
{
  const __m128d zero = _mm_setzero_pd();
  const __m128d half = _mm_set1_pd(0.5), fr = _mm_set1_pd((255 - SHADE_AMBIENT) * refl);
  const __m128d delta = _mm_set1_pd(0x1p-23), two30 = _mm_set1_pd(0x1p30);
  const int pa = S->pa[j], pb = pa + S->two[j];
  const unsigned b0 = shadow ? blocked[pa] : 0, b1 = shadow ? blocked[pb] : 0;
  const __m128d N0 = _mm_load_pd(S->n[0][j]), N1 = _mm_load_pd(S->n[1][j]);
  const __m128d N2 = _mm_load_pd(S->n[2][j]);
  const __m128d inv = _mm_div_pd(_mm_load_pd(S->sg[j]), _mm_sqrt_pd(_mm_load_pd(S->r[j])));
  __m128d sum = zero;
  for (int k = 0; k < nlight; k++) {
    const __m128d d = _mm_mul_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(N0, lv[k][0]),
                                                       _mm_mul_pd(N1, lv[k][1])),
                                            _mm_mul_pd(N2, lv[k][2])), inv);
    __m128d lit = _mm_cmpgt_pd(d, zero);
    if (shadow && ((b0 | b1) >> k & 1u))
      lit = _mm_and_pd(lit, _mm_castsi128_pd(_mm_set_epi64x((b1 >> k & 1u) - 1ull,
                                                            (b0 >> k & 1u) - 1ull)));
    sum = k ? _mm_add_pd(sum, _mm_and_pd(lit, d)) : _mm_and_pd(lit, d);
  }
  const __m128d f = _mm_add_pd(_mm_mul_pd(fr, sum), half);
  const __m128d f0v = _mm_sub_pd(f, delta), f1v = _mm_add_pd(f, delta);
  const __m128i t0 = _mm_cvttpd_epi32(f0v);
  const int okb = S->okb[j];
  /* phong_filter's f0 >= 0 && f1 < 2^62 && (int64_t)f0 == (int64_t)f1, lane by lane, as
     f1 < 2^30 and the two truncations to 32 bits equal: f is 1/2 or above, or NaN (the sum
     is +0 or above or NaN, 207 refl >= 0), so f0 = fl(f - 2^-23) is above 0 or NaN, and
     f0 >= 0 needs no test of its own; where f1 < 2^30, f0 < 2^30 too and both truncate
     in range. A NaN fails f1 < 2^30. */
  const int fine = okb & _mm_movemask_pd(_mm_cmplt_pd(f1v, two30)) &
                   _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(t0, _mm_cvttpd_epi32(f1v))));
  const bool two = S->two[j] != 0;
  const int lanes = two ? 3 : 1;
  if ((fine & lanes) == lanes) {
    if (nlight == 1 && two) {
      /* both greys in one store (pb is pa + 1), without the clamp: under one light, with
         reflectance refl <= 1, no grey is above 255. Its sum is max(0, d), d the dot of
         two vectors whose lengths' product inv makes at most 1 but for a few roundings
         (the light's direction a unit vector rounded; inv 1 / |N| with the rounding of
         nn, its square root and the divide), so d < 1 + 2^-40, f = (255 - SHADE_AMBIENT)
         refl d + 1/2 < 256 - SHADE_AMBIENT, and a lane's truncation of f0 = f - delta
         (f0 >= 0 where fine) is at most 255 - SHADE_AMBIENT */
      _mm_storel_epi64((__m128i *)(void *)&grey[pa],
                       _mm_add_epi32(t0, _mm_set1_epi32(SHADE_AMBIENT)));
      return;
    }
    const int g0 = SHADE_AMBIENT + _mm_cvtsi128_si32(t0);
    grey[pa] = g0 > 255 ? 255 : g0;
    if (two) {
      const int g1 = SHADE_AMBIENT + _mm_cvtsi128_si32(_mm_srli_si128(t0, 4));
      grey[pb] = g1 > 255 ? 255 : g1;
    }
    return;
  }
  double f0[2], f1[2];
  _mm_storeu_pd(f0, f0v);
  _mm_storeu_pd(f1, f1v);
  for (int h = 0; h <= (int)two; h++) {       /* phong_filter's last test and grey */
    const int p = h ? pb : pa;
    phong_lane_grey(m, &m->tri[phong_tri_at(nseg, tri, at, p)], X, xu, xw, p, okb >> h & 1,
                    f0[h], f1[h], refl, h ? b1 : b0, L, &grey[p]);
  }
}

/* phong_row's pairs, under nlight = L->n parallel lights whose directions are lv: a
   triangle's points two a step (phong_pairs' steps), and an odd one left over with the
   next triangle's first (each lane its own triangle's constants); a point of a triangle
   whose btot is 0 alone (smooth_grey_run's way). Each step is phong_filter's operations on
   its lanes, in two passes over the row's steps: up to the square root's operand
   (phong_head) for every step, then the rest (phong_tail) for every step. Done step after
   step in one pass, a step's chain from its loads through its square root and divide to
   its grey is some 150 cycles long and the processor kept only two or three steps in
   flight, waiting on the chains (issue 19); a pass's chain is about half as long, and the
   square roots and divides of the second pass are fed with no wait on the areas. */
static inline __attribute__((always_inline))
void phong_row_lights(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                      const double (*X)[3], const double *xu, const double *xw,
                      const unsigned *blocked, bool shadow,
                      const struct shade_lights *L, const __m128d (*lv)[3], int nlight,
                      int *grey)
{
  struct phong_steps S;
  int p = 0, j = 0;
  for (int k = 0; k < nseg; k++) {
    const int q = at[k + 1];
    const struct smooth_tri *tr = &m->tri[tri[k]];
    if (tr->btot == 0) {
      for (; p < q; p++) {
        double buf[3];
        phong_alone(m, tr, phong_point(X, xu, xw, tr, p, buf), blocked[p], L, &grey[p]);
      }
      continue;
    }
    const struct smooth_lanes *lx = &m->lanes[tri[k]];
    const __m128d sg = phong_side(tr, tr);
    for (; p + 2 <= q; p += 2, j++) {
      S.pa[j] = p; S.two[j] = 1;
      if (X)
        phong_head(lx, lx, true, _mm_set_pd(X[p + 1][tr->bu], X[p][tr->bu]),
                   _mm_set_pd(X[p + 1][tr->bw], X[p][tr->bw]), sg, &S, j);
      else
        phong_head(lx, lx, true, _mm_loadu_pd(xu + p), _mm_loadu_pd(xw + p), sg, &S, j);
    }
    if (p == q) continue;
    const int tn = k + 1 < nseg ? tri[k + 1] : -1;
    S.pa[j] = p;
    if (tn >= 0 && m->tri[tn].btot != 0) {     /* p = q - 1 and the next one, q */
      S.two[j] = 1;
      const struct smooth_tri *tb = &m->tri[tn];
      phong_head(lx, &m->lanes[tn], false,
                 X ? _mm_set_pd(X[q][tb->bu], X[p][tr->bu]) : _mm_set_pd(xu[q], xu[p]),
                 X ? _mm_set_pd(X[q][tb->bw], X[p][tr->bw]) : _mm_set_pd(xw[q], xw[p]),
                 phong_side(tr, tb), &S, j++);
      p = q + 1;
    } else {                                   /* alone: in both lanes */
      S.two[j] = 0;
      phong_head(lx, lx, true, _mm_set1_pd(X ? X[p][tr->bu] : xu[p]),
                 _mm_set1_pd(X ? X[p][tr->bw] : xw[p]), sg, &S, j++);
      p = q;
    }
  }
  for (int i = 0; i < j; i++)
    phong_tail(m, &S, i, X, xu, xw, 1.0, blocked, shadow, L, lv, nlight, nseg, tri, at, grey);
}
#endif

/* phong_lanes at points p < n under parallel lights alone, two points an instruction
   where the processor has SSE2, from their space points: bary_areas' areas (inner_split's
   operations), then phong_filter's steps, each lane's the scalar ones on its values in
   their order (correctly rounded, as the scalar ones are; max(v, 0) is v when v > 0, else
   +0, phong_filter's clamp; 0 + w_0 is kept; a light blocked or a dot not > 0 adds +0,
   which leaves a sum never below +0 as it is; |inv| by clearing the sign bit); a lane's
   last test and its grey as phong_filter makes them, and the exact chain where it
   declines (an odd run's last point in both lanes of its pair, a run of one point too).
   Its range test on the w_k is narrower than phong_filter's: it passes only points that
   phong_filter's passes (below), whose greys it then makes as phong_filter does; it
   declines also a point on a side or outside (a w_k of 0), left to the exact chain like
   every point declined. The points done (their greys, and their regions, 1): all n, or
   none when the filter is off or cannot be used for the triangle, or some light is a
   point light (phong_lanes does them). The steps at a pair of points: phong_head, then
   phong_tail (phong_row_lights' two passes). */
static inline int phong_pairs(const struct smooth_model *m, const struct smooth_tri *tr,
                              const struct smooth_lanes *lx, int n,
                              const double (*X)[3], double refl, const unsigned *blocked,
                              const struct shade_lights *L, int *grey, int *region)
{
#ifdef __SSE2__
  if (m->phong_exact || !(tr->btot != 0 && refl >= 0 && refl <= 1)) return 0;
  for (int k = 0; k < L->n; k++)
    if (L->point[k]) return 0;
  __m128d lv[SCENE_LIGHT_MAX][3];
  phong_lights(L, lv);
  const __m128d sg = phong_side(tr, tr);
  const int t = (int)(tr - m->tri), ats[2] = { 0, n };
  struct phong_steps S;
  int j = 0;
  for (int p = 0; p < n; p += 2, j++) {
    const bool two = p + 1 < n;
    const int p1 = two ? p + 1 : p;         /* the last of an odd run: itself in both lanes */
    region[p] = region[p1] = 1;
    S.pa[j] = p; S.two[j] = two;
    phong_head(lx, lx, true, _mm_set_pd(X[p1][tr->bu], X[p][tr->bu]),
               _mm_set_pd(X[p1][tr->bw], X[p][tr->bw]), sg, &S, j);
  }
  for (int i = 0; i < j; i++)
    phong_tail(m, &S, i, X, NULL, NULL, refl, blocked, true, L, (const __m128d (*)[3])lv, L->n,
               1, &t, ats, grey);
  return n;
#else
  (void)m; (void)tr; (void)lx; (void)n; (void)X; (void)refl; (void)blocked; (void)L; (void)grey; (void)region;
  return 0;
#endif
}

/* smooth_row under smooth=phong (the regions left to the caller: all 1): phong_row_lights,
   made for one light apart (the scenes' usual case: its loop unrolled), and for a stretch
   where no light is blocked at any point apart (no shadows: blocked[] not read a step).
   The points' space points X, or (X NULL) their coordinates on their triangles' axes in
   xu and xw (smooth_phong_row). */
static inline __attribute__((always_inline))
void phong_rows(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                const double (*X)[3], const double *xu, const double *xw,
                const unsigned *blocked, const struct shade_lights *L, int *grey)
{
#ifdef __SSE2__
  __m128d lv[SCENE_LIGHT_MAX][3];
  phong_lights(L, lv);
  /* whether a light is blocked at any point of the stretch (four points an OR) */
  const int n = at[nseg];
  __m128i any = _mm_setzero_si128();
  int p = 0;
  for (; p + 4 <= n; p += 4)
    any = _mm_or_si128(any, _mm_loadu_si128((const __m128i *)(const void *)(blocked + p)));
  unsigned bl = 0;
  for (; p < n; p++) bl |= blocked[p];
  const bool shadow =
      bl || _mm_movemask_epi8(_mm_cmpeq_epi32(any, _mm_setzero_si128())) != 0xffff;
  const __m128d (*lc)[3] = (const __m128d (*)[3])lv;
  if (L->n == 1 && !shadow)
    phong_row_lights(m, nseg, tri, at, X, xu, xw, blocked, false, L, lc, 1, grey);
  else if (L->n == 1)
    phong_row_lights(m, nseg, tri, at, X, xu, xw, blocked, true, L, lc, 1, grey);
  else
    phong_row_lights(m, nseg, tri, at, X, xu, xw, blocked, true, L, lc, L->n, grey);
#else
  for (int k = 0, p = 0; k < nseg; k++)
    for (; p < at[k + 1]; p++) {
      double buf[3];
      const struct smooth_tri *tr = &m->tri[tri[k]];
      phong_alone(m, tr, phong_point(X, xu, xw, tr, p, buf), blocked[p], L, &grey[p]);
    }
#endif
}

#ifdef PHONG_AVX
/* Whether the rows built twice take their AVX build: where the processor has AVX
   (__builtin_cpu_supports, which asks the processor and whether the system saves the
   256-bit registers) and m's rows_sse2 (tests only) is not set. */
static inline bool rows_avx(const struct smooth_model *m)
{
  return !m->rows_sse2 && __builtin_cpu_supports("avx");
}

/* smooth_phong_row four points an instruction (AVX's 256-bit registers), chosen at run
   time where the processor has AVX (rows_avx): phong_row_lights' two passes, the
   first with steps of up to four points of one triangle (a run's points four a step from
   its first; the last step's lanes past the run's end hold its last point again), the
   second four points a step in the row's order (phong_row4_lights). Each lane's
   operations are phong_head's and phong_tail's for its
   point, in their order, each the same IEEE operation on the same doubles as the SSE2
   path's (VEX-encoded, 256 bits wide; no fused multiply-add: AVX alone, and the build's
   -ffp-contract=off), and a compare by the predicate of the SSE2 one (GE_OS, LE_OS,
   GT_OS, LT_OS: false for a NaN, as CMPPD's GE, LE, GT and LT): the same greys and the
   same points declined, bit for bit, as phong_rows (test_smooth test_row_is_single runs
   the rows both ways, m->rows_sse2). Where it pays: the SSE2 rows' time went to their
   arithmetic (about 77 vector operations a step of two points) and to the steps across
   two runs (some 25 shuffles each, a run holding 3.4 points on average on the sphere);
   four lanes a step take a run's points with about half the operations, and the second
   pass's square roots and divides, four a step, are not spent on spare lanes.
   What does not pay here (round 39, perf's sampling clock under load, phong_rows4's
   samples in runs of 10,000 frames, three or four runs each way). A frame of t1-g has
   105 rows, 4,097 points in 288 runs (14 a run) and 1,126 first-pass steps; the sphere's
   56 rows, 2,343 points in 695 runs (3.4 a run: 187 of one point, 134 of two) and 907
   steps; the filter declines none, under one light blocked nowhere. The first pass took
   about half of the function's samples, the second the rest. Leaving the square root and
   the divide out altogether (a float reciprocal square root in their place: wrong greys,
   the most any other normalisation could save) took 16% of the function's samples on
   t1-g and 10% on the sphere; so the function is held by its vector operations (then
   about 52 a first-pass step, 30 a second-pass step besides the square root and divide)
   more than by the divider (what paid: see phong_row4_lights). Tried, each exact (the
   same greys on t1-g, t1-h, t1-i, lprism and the sphere) and not faster: the grey
   decided without the square root and divide, by comparing (207 max(0, s N'.l))^2 with
   (k -+ (1/2 - 2^-23))^2 nn for a candidate k made by RSQRTPS's reciprocal square root
   and a Newton step (+10% on t1-g, +7% on the sphere: the conversions and products cost
   more than the divider's wait; branch r39-phong5-squares); the constants folded
   into the products as AVX-512VL broadcasts (level); the second pass eight points a step
   on AVX-512's registers (the function's share of t1-g 28.4 -> 31.8%, of the sphere 16.1
   -> 17.2%); the second pass over the first pass's own steps, so that each load reads
   one store (29.9% against 28.2% of t1-g); full loads of xu and xw for a run's last step
   (level; 0.2 to 0.5% fewer instructions a frame). */
#define PHONG_AVX_ATTR __attribute__((target("avx")))
/* A row's points between phong_row4_lights' two passes, point p's values at [p]: the
   normal's sums N, the eye's side (+-1), the least of the clamped areas w_k (mn), their
   sum s, the triangle's |tot| and the triangle; 4 spare places past the row's last
   point. phong_head's tests on them (its ok) and its square root's operand nn (from N)
   are made in the second pass (phong_tail4), not the first: see phong_row4_lights. */
#define PHONG_PTS (SMOOTH_ROW + 4)
struct phong_pts4 {
  _Alignas(32) double n[3][PHONG_PTS];
  _Alignas(32) double sg[PHONG_PTS];
  _Alignas(32) double mn[PHONG_PTS];
  _Alignas(32) double s[PHONG_PTS];
  _Alignas(32) double tot[PHONG_PTS];
  int tri[PHONG_PTS];
};

/* A pair's double (struct smooth_lanes: the same double twice) in all four lanes */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR __m256d lanes4(const double *a)
{
  return _mm256_broadcast_sd(a);
}

/* phong_head at four points p .. p + 3 of triangle x (lanes 0 .. 3: coordinates x, y on
   its axes bu, bw; at: the triangle's |tot|) into *P at [p] .. [p + 3]: the same
   operations, lane by lane, up to N, the sum s and the least w_k; the rest of phong_head
   (its tests and nn) is phong_tail4's. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void phong_head4(const struct smooth_lanes *x, __m256d px, __m256d py, __m256d sg,
                 __m256d at, struct phong_pts4 *P, int p)
{
  const __m256d zero = _mm256_setzero_pd();
  __m256d w[3], s = zero;
  for (int k = 0; k < 3; k++) {
    const __m256d ar = _mm256_sub_pd(
        _mm256_mul_pd(lanes4(x->xsd[k][0]), _mm256_sub_pd(py, lanes4(x->xa[k][1]))),
        _mm256_mul_pd(_mm256_sub_pd(px, lanes4(x->xa[k][0])), lanes4(x->xsd[k][1])));
    w[k] = _mm256_max_pd(ar, zero);         /* MAXPD's: the second operand where equal */
    s = k ? _mm256_add_pd(s, w[k]) : w[k];
  }
  const __m256d mn = _mm256_min_pd(_mm256_min_pd(w[0], w[1]), w[2]);
  __m256d N[3];
  for (int c = 0; c < 3; c++) {
    N[c] = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(w[0], lanes4(x->xcn[0][c])),
                                       _mm256_mul_pd(w[1], lanes4(x->xcn[1][c]))),
                         _mm256_mul_pd(w[2], lanes4(x->xcn[2][c])));
    _mm256_storeu_pd(P->n[c] + p, N[c]);
  }
  _mm256_storeu_pd(P->sg + p, sg);
  _mm256_storeu_pd(P->mn + p, mn);
  _mm256_storeu_pd(P->s + p, s);
  _mm256_storeu_pd(P->tot + p, at);
}

/* The AVX-512 rows' short chain (phong_tail4 with r14, where rows_r14 says so).
**
** The AVX rows' second pass is held less by the divider than by the length of each step's
** chain from the normal's sums to the test of the grey (nn, square root, divide, each
** light's product and compare, 207 r, + 1/2, -+ delta, the conversions: some 80 cycles),
** whose later operations wait in the scheduler and keep it from taking the next steps
** (round 40, perf: leaving out the divider alone, a reciprocal square root with a Newton
** step in the same place in the chain, changed nothing). The short chain reorders it:
** each light's term S_k = max(0, sg fl(N'.l_k)) (the sum as before; sg = +-1, exact) and
** their sum S, A = fl(207 S), off the chain; on it, y0 = VRSQRT14PD(nn), c = fl(1.5 -
** fl(fl(nn / 2) fl(y0 y0))) (one Newton step) and F' = fl(fl(fl(A y0) c) + 1/2): about
** 55 cycles from the loads.
**
** Bound on |F' - F_exact| where the filter's tests pass (phong_filter: nn is a normal
** number >= 2^-1020 and |N| >= 2^-10 (1 - 2^-39)); u = 2^-53, e0 = y0 sqrt(nn) - 1 with
** |e0| < 2^-14 (the instruction's documented bound). In real numbers y0 (3/2 - nn y0^2 /
** 2) sqrt(nn) = 1 - 3 e0^2 / 2 - e0^3 / 2, within 1.5001 2^-28 of 1; nn / 2 is exact (a
** normal number halved); fl(y0 y0) and the product by nn / 2 add a relative 2u to a term
** within 2^-12 of 1/2, and the difference from 1.5 (in [1 - 2^-12, 1 + 2^-12]) a
** rounding of at most u: c is within 2.001u of its real value (about 1). nn is within a
** relative 4u of |N'|^2 (phong_filter), so 1 / sqrt(nn) within 2.001u of 1 / |N'|. So
** fl(fl(A y0) c) = A (1 + eps) / |N'| with |eps| <= 1.5001 2^-28 + 7u < 2^-27.41. Each
** fl(N'.l_k) is within 3.001u |N'| |l_k| of N'.l_k and |l_k| <= 1 + 4u, max(0, .) does
** not widen that, S's at most 15 adds of non-negative terms a relative 15.001u, 207 S
** one more u; so with T = sum_k max(0, sg N'.l_k / |N'|) <= 16 (1 + 4u) (the real
** unit vector of the computed N' against each light), |fl(fl(A y0) c) - 207 T| <= 207
** (16 (3.002u) + 16.001 (17.002u + 2^-27.41)) < 2^-15.69, and the + 1/2 a rounding of at
** most 2^-41 (F' < 2^12). 207 T + 1/2 is the real F of phong_filter's unit vector before
** its own roundings, which that proof puts within 12u / |N| + 4u of the true U a light:
** |207 T + 1/2 - F| <= 207 16 (12u 2^10 (1 + 2^-38) + 4u) (1 + 4u) < 2^-27.6, and
** |F_exact - F| < 2^-35 (1 + 1 / |N|) < 2^-24.9 (phong_filter). So |F' - F_exact| <
** 2^-15.69 + 2^-41 + 2^-27.6 + 2^-24.9 < 2^-15.68, and the margin delta = 2^-15 leaves
** more than 2^-17 for fl(F' -+ delta) (each within 2^-41 of F' -+ delta: a rounding to
** nearest never crosses an integer): where both truncate to the one integer k, F_exact
** lies in [k, k + 1) and the grey A + k is the exact chain's (phong_filter's argument
** with 2^-15 for 2^-23). Where nn is +inf (or NaN), y0 is +0 (NaN), c and F' NaN, and
** the lane is declined (F' -+ delta < 2^30 fails). A point is declined with odds of
** about 2^-14 (under one light about 2 2^-15 of the greys' borders), a few a frame at
** most; its grey is the exact chain's. test_smooth test_phong_rows_borders holds the
** rows both ways (phong_sqrt) to the exact chain on points bisected onto the borders
** between two greys, where the short chain must decline, and fails with the margin cut
** to 2^-30. Measured (round 40, perf's sampling clock, phong_rows4's share of the
** frame's samples, medians of 4 runs in turn, 6,000 frames each, under load): t1-g 29.0
** -> 27.1%, the sphere 16.9 -> 14.7%, lprism 19.0 -> 17.5%. */
/* AVX-512VL's VRSQRT14PD: an approximation of 1 / sqrt(x) in each lane, within a relative
   2^-14 of it (Intel's manual) for x a positive normal number; +0 for +inf, NaN for NaN.
   Written as an instruction (EVEX-encoded, on ymm0 .. ymm15) so that the function around
   it needs no AVX-512 target of its own; run only where rows_r14 says the processor has
   it. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR __m256d rsqrt14(__m256d x)
{
  __m256d y;
  __asm__("vrsqrt14pd %1, %0" : "=x"(y) : "x"(x));
  return y;
}

/* Four points' N . l, fl(fl(fl(N0 l0) + fl(N1 l1)) + fl(N2 l2)) lane by lane. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR __m256d dot4(__m256d N0, __m256d N1,
                                                                        __m256d N2,
                                                                        const __m256d l[3])
{
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(N0, l[0]), _mm256_mul_pd(N1, l[1])),
                       _mm256_mul_pd(N2, l[2]));
}

/* The lanes of four points whose light k is not blocked (b[h]'s bit k clear): all ones
   there, zero where it is blocked. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR __m256d unblocked4(const unsigned b[4],
                                                                              int k)
{
  return _mm256_castsi256_pd(_mm256_set_epi64x((long long)((b[3] >> k & 1u) - 1ull),
                                               (long long)((b[2] >> k & 1u) - 1ull),
                                               (long long)((b[1] >> k & 1u) - 1ull),
                                               (long long)((b[0] >> k & 1u) - 1ull)));
}

/* The end of phong_head and phong_tail at points q .. q + cnt - 1 of *P (cnt 1 .. 4; the
   lanes past them hold other values, never stored nor counted): the same operations lane
   by lane (phong_head's nn from N, and its tests: the least w_k >= |tot| 2^-1000 and s <=
   |tot| 2^1000, the very products tri_lanes makes for xlo and xhi, s >= 2^-500 and nn >=
   s s 2^-20), the same last test, greys and declines (the exact chain, counted in
   phong_declines); the greys to grey[q + h], under one light four in one store. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void phong_tail4(const struct smooth_model *m, const struct phong_pts4 *P, int q, int cnt,
                 const double *xu, const double *xw, const unsigned *blocked, bool shadow,
                 const struct shade_lights *L, const __m256d (*lv)[3], int nlight, bool r14,
                 int *grey)
{
  const __m256d zero = _mm256_setzero_pd();
  const __m256d half = _mm256_set1_pd(0.5), fr = _mm256_set1_pd((255 - SHADE_AMBIENT) * 1.0);
  const __m256d two30 = _mm256_set1_pd(0x1p30);
  unsigned b[4] = { 0, 0, 0, 0 }, bor = 0;
  if (shadow)
    for (int h = 0; h < cnt; h++) bor |= b[h] = blocked[q + h];
  const __m256d N0 = _mm256_load_pd(P->n[0] + q), N1 = _mm256_load_pd(P->n[1] + q);
  const __m256d N2 = _mm256_load_pd(P->n[2] + q);
  const __m256d nn = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(N0, N0), _mm256_mul_pd(N1, N1)),
                                   _mm256_mul_pd(N2, N2));
  const __m256d sv = _mm256_load_pd(P->s + q);
  const __m256d at = _mm256_load_pd(P->tot + q);
  const __m256d okv = _mm256_and_pd(
      _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(_mm256_load_pd(P->mn + q),
                                                _mm256_mul_pd(at, _mm256_set1_pd(0x1p-1000)),
                                                _CMP_GE_OS),
                                  _mm256_cmp_pd(sv, _mm256_mul_pd(at, _mm256_set1_pd(0x1p1000)),
                                                _CMP_LE_OS)),
                    _mm256_cmp_pd(sv, _mm256_set1_pd(0x1p-500), _CMP_GE_OS)),
      _mm256_cmp_pd(nn, _mm256_mul_pd(_mm256_mul_pd(sv, sv), _mm256_set1_pd(0x1p-20)),
                    _CMP_GE_OS));
  __m256d sum = zero, f, delta;
  if (r14) {                                /* "The AVX-512 rows' short chain" (above) */
    const __m256d sg = _mm256_load_pd(P->sg + q);
    const __m256d y0 = rsqrt14(nn);
    const __m256d c = _mm256_sub_pd(_mm256_set1_pd(1.5),
                                    _mm256_mul_pd(_mm256_mul_pd(nn, _mm256_set1_pd(0.5)),
                                                  _mm256_mul_pd(y0, y0)));
    for (int k = 0; k < nlight; k++) {
      __m256d d = _mm256_max_pd(_mm256_mul_pd(sg, dot4(N0, N1, N2, lv[k])), zero);
      if (shadow && (bor >> k & 1u))
        d = _mm256_and_pd(d, unblocked4(b, k));
      sum = k ? _mm256_add_pd(sum, d) : d;
    }
    f = _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(fr, sum), y0), c), half);
    delta = _mm256_set1_pd(0x1p-15);
  } else {
    const __m256d inv = _mm256_div_pd(_mm256_load_pd(P->sg + q), _mm256_sqrt_pd(nn));
    for (int k = 0; k < nlight; k++) {
      const __m256d d = _mm256_mul_pd(dot4(N0, N1, N2, lv[k]), inv);
      __m256d lit = _mm256_cmp_pd(d, zero, _CMP_GT_OS);
      if (shadow && (bor >> k & 1u))
        lit = _mm256_and_pd(lit, unblocked4(b, k));
      sum = k ? _mm256_add_pd(sum, _mm256_and_pd(lit, d)) : _mm256_and_pd(lit, d);
    }
    f = _mm256_add_pd(_mm256_mul_pd(fr, sum), half);
    delta = _mm256_set1_pd(0x1p-23);
  }
  const __m256d f0v = _mm256_sub_pd(f, delta), f1v = _mm256_add_pd(f, delta);
  const __m128i t0 = _mm256_cvttpd_epi32(f0v);
  /* phong_tail's test, lane by lane */
  const int okb = _mm256_movemask_pd(okv), lanes = (1 << cnt) - 1;
  const int fine = okb & _mm256_movemask_pd(_mm256_cmp_pd(f1v, two30, _CMP_LT_OS)) &
                   _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(t0, _mm256_cvttpd_epi32(f1v))));
  if ((fine & lanes) == lanes) {
    if (nlight == 1 && cnt == 4) {          /* no clamp under one light: phong_tail */
      _mm_storeu_si128((__m128i *)(void *)&grey[q],
                       _mm_add_epi32(t0, _mm_set1_epi32(SHADE_AMBIENT)));
      return;
    }
    _Alignas(16) int g[4];
    _mm_store_si128((__m128i *)(void *)g, _mm_add_epi32(t0, _mm_set1_epi32(SHADE_AMBIENT)));
    for (int h = 0; h < cnt; h++) grey[q + h] = g[h] > 255 ? 255 : g[h];
    return;
  }
  _Alignas(32) double f0[4], f1[4];
  _mm256_store_pd(f0, f0v);
  _mm256_store_pd(f1, f1v);
  for (int h = 0; h < cnt; h++)            /* phong_filter's last test and grey */
    phong_lane_grey(m, &m->tri[P->tri[q + h]], NULL, xu, xw, q + h, okb >> h & 1, f0[h],
                    f1[h], 1.0, b[h], L, &grey[q + h]);
}

/* Four doubles v[p + min(h, c - 1)], h = 0 .. 3 (c >= 1): a step's points, the last
   again past them */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
__m256d step4(const double *v, int p, int c)
{
  if (c >= 4) return _mm256_loadu_pd(v + p);
  const double a = v[p], b = v[p + (c > 1)], d = v[p + (c > 2 ? 2 : c - 1)];
  return _mm256_set_pd(d, d, b, a);
}

/* phong_row_lights four points a step (phong_rows4): the first pass a run's points four
   a step from its first, with its triangle's constants (the last step's lanes past the
   run write their values at the next run's first points, which its first step then
   writes over, or past the row's last point); the second pass the row's points four a
   step whatever their triangles (it needs none of a triangle's constants but |tot|, kept
   a point), so that no lane of its square roots and divides is spare but in the last
   step. The first pass is bound by its vector operations (about 52 a step); the second
   waits on the divider (a square root and a divide a step, 16% of the function's samples
   on t1-g, round 39) with ports to spare: so phong_head's tests (9 operations) and nn (5)
   are made in the second pass, each on the same doubles as before (phong_rows4's share
   of the frame's samples, medians of 4 to 14 runs each way under load: t1-g 29.0 ->
   27.3%, t1-h 28.2 -> 26.6%, t1-i 29.9 -> 28.6%, the sphere 16.9 -> 16.2%, lprism 19.8
   -> 18.9%; about 0.5% more instructions a frame). A point of a triangle whose btot is
   0 is declined (its least w_k kept as 0, below |tot| 2^-1000 = 2^-1000 with |tot| kept
   as 1), and so takes the exact chain with its areas (bary_areas), counted, as
   phong_alone takes it in phong_rows (whose filter declines a triangle whose btot is 0). */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void phong_row4_lights(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                       const double *xu, const double *xw, const unsigned *blocked,
                       bool shadow, const struct shade_lights *L, const __m256d (*lv)[3],
                       int nlight, bool r14, int *grey)
{
  struct phong_pts4 P;
  const int n = at[nseg];
  const __m256d pad = _mm256_set1_pd(1);    /* values of no use, in lanes not ok */
  for (int k = 0; k < nseg; k++) {
    const struct smooth_tri *tr = &m->tri[tri[k]];
    const int q = at[k + 1];
    const __m128i t = _mm_set1_epi32(tri[k]);
    if (tr->btot == 0) {                    /* declined: the exact chain, as phong_alone */
      for (int p = at[k]; p < q; p += 4) {
        _mm_storeu_si128((__m128i *)(void *)(P.tri + p), t);
        for (int c = 0; c < 3; c++) _mm256_storeu_pd(P.n[c] + p, pad);
        _mm256_storeu_pd(P.sg + p, pad);
        _mm256_storeu_pd(P.mn + p, _mm256_setzero_pd());   /* 0 < |tot| 2^-1000 */
        _mm256_storeu_pd(P.s + p, pad);
        _mm256_storeu_pd(P.tot + p, pad);
      }
      continue;
    }
    const struct smooth_lanes *lx = &m->lanes[tri[k]];
    const __m256d sg = _mm256_set1_pd(tr->front ? 1 : -1);
    const __m256d av = _mm256_set1_pd(fabs(tr->btot));
    for (int p = at[k]; p < q; p += 4) {
      const int c = q - p;
      /* lx's constants read at each step from their addresses in lx (memory operands),
         not their 22 addresses made and kept on the stack once a run */
      __asm__("" : "+r"(lx));
      _mm_storeu_si128((__m128i *)(void *)(P.tri + p), t);
      phong_head4(lx, step4(xu, p, c), step4(xw, p, c), sg, av, &P, p);
    }
  }
  for (int c = 0; c < 3; c++)               /* past the last point: set (no lane of a */
    _mm256_storeu_pd(P.n[c] + n, pad);      /* step reads memory never written) */
  _mm256_storeu_pd(P.sg + n, pad);
  _mm256_storeu_pd(P.mn + n, _mm256_setzero_pd());
  _mm256_storeu_pd(P.s + n, pad);
  _mm256_storeu_pd(P.tot + n, pad);
  for (int q = 0; q < n; q += 4)
    phong_tail4(m, &P, q, n - q < 4 ? n - q : 4, xu, xw, blocked, shadow, L, lv, nlight, r14,
                grey);
}

/* phong_rows for smooth_phong_row, four points a step (AVX); r14: the second pass's
   short chain (AVX-512's VRSQRT14PD) */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void phong_rows4_as(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                    const double *xu, const double *xw, const unsigned *blocked,
                    const struct shade_lights *L, bool r14, int *grey)
{
  __m256d lv[SCENE_LIGHT_MAX][3];
  for (int k = 0; k < L->n; k++)
    for (int c = 0; c < 3; c++) lv[k][c] = _mm256_set1_pd(L->v[k][c]);
  const int n = at[nseg];
  unsigned bl = 0;
  for (int p = 0; p < n; p++) bl |= blocked[p];
  const __m256d (*lc)[3] = (const __m256d (*)[3])lv;
  if (L->n == 1 && !bl)
    phong_row4_lights(m, nseg, tri, at, xu, xw, blocked, false, L, lc, 1, r14, grey);
  else if (L->n == 1)
    phong_row4_lights(m, nseg, tri, at, xu, xw, blocked, true, L, lc, 1, r14, grey);
  else
    phong_row4_lights(m, nseg, tri, at, xu, xw, blocked, true, L, lc, L->n, r14, grey);
}

static PHONG_AVX_ATTR void phong_rows4(const struct smooth_model *m, int nseg, const int *tri,
                                       const int *at, const double *xu, const double *xw,
                                       const unsigned *blocked, const struct shade_lights *L,
                                       int *grey)
{
  phong_rows4_as(m, nseg, tri, at, xu, xw, blocked, L, false, grey);
}

static PHONG_AVX_ATTR void phong_rows4_r14(const struct smooth_model *m, int nseg,
                                           const int *tri, const int *at, const double *xu,
                                           const double *xw, const unsigned *blocked,
                                           const struct shade_lights *L, int *grey)
{
  phong_rows4_as(m, nseg, tri, at, xu, xw, blocked, L, true, grey);
}

/* Whether the AVX rows take the short chain: where the processor has AVX-512VL (and the
   system saves its registers: __builtin_cpu_supports) and m's phong_sqrt (tests only) is
   not set. */
static inline bool rows_r14(const struct smooth_model *m)
{
  return !m->phong_sqrt && __builtin_cpu_supports("avx512vl");
}

/* smooth_phong_row eight points a step (AVX-512F's 512-bit registers), chosen at run time
   where the processor has AVX-512F and AVX-512VL (rows_zmm), always with the short chain
   ("The AVX-512 rows' short chain": VRSQRT14PD's bound is the same on 512 bits, and so
   the proof). Each lane's operations are phong_head4's and phong_tail4's (r14) for its
   point, in their order, each the same IEEE operation on the same doubles (EVEX-encoded;
   no fused multiply-add: the build's -ffp-contract=off, and no FMA target), a compare by
   the same predicate into a mask register (a compare under a mask is the AND of the two
   tests, as VANDPD of the two compares' lanes), a light's blocked lanes made +0 by a
   zeroing move (as VANDPD with zero): the same greys and the same points declined, bit for
   bit, as phong_rows4_r14 (test_smooth's test_phong_rows_borders, test_phong_rows_long,
   test_row_is_single and the others run the rows each way: phong_row_way, m->phong_ymm).
   Unlike phong_row4_lights, one pass: each step makes its points' greys from its own
   registers (phong_head8, then phong_tail8), nothing stored between two passes.
   A step holds up to eight points of a run, from its first; where fewer than eight of the
   run are left (a run of 1 .. 7 points, or the last 1 .. 7 of a longer one) the step
   holds them in its low lanes with their triangle's constants and the next run's first
   points in the others with that run's (each constant's vector blended under the step's
   mask: a masked broadcast), where the next run's btot is not 0; the next step then
   starts at the first of the next run's points this one did not hold. Lanes past the
   step's points hold +0 (masked loads), and are neither stored nor counted.
   Measured on a Zen 5 host (full-width AVX-512; perf's sampling clock, the rows' share of
   the frame's samples, 3 runs each way in turn, under load): eight points a step in the
   AVX rows' two passes against phong_rows4_r14, t1-g 27.4 -> 22.8%; then the steps
   across two runs, t1-g 25.7 -> 24.2%, lprism 17.7 -> 16.4%, the sphere 15.3 -> 14.1%
   (its runs hold 3.4 points on average); then one pass, t1-g 23.1 -> 21.3%, the sphere
   14.1 -> 13.6%: the processor's window holds several steps' chains (round 39's host
   did not: there the second pass eight points a step lost). Altogether, against
   phong_rows4_r14 (3 runs each way in turn): t1-g 25.9 -> 21.4%, t1-h 24.8 -> 19.5%,
   t1-i 28.0 -> 22.8%, the sphere 15.3 -> 13.3%, lprism 17.9 -> 15.6%. Tried and not
   kept (the same greys): every step blended, so that the step has no branch on the run's
   length (t1-g 23.3 -> 26.4%, the sphere level); the 21 constants a step reads
   (phong_head8's) and |btot| kept together in the triangle's lanes, about 3 cache lines
   a run instead of about 9 (the sphere level). */
#define PHONG_ZMM_ATTR __attribute__((target("avx512f,avx512vl")))

/* A pair's double (struct smooth_lanes) in all eight lanes: x's double at a where two is
   false, else in the lanes of ka, and in the others y's double at the same place in y */
static inline __attribute__((always_inline)) PHONG_ZMM_ATTR
__m512d lanes8(const struct smooth_lanes *x, const struct smooth_lanes *y, const double *a,
               bool two, __mmask8 ka)
{
  if (!two) return _mm512_set1_pd(*a);
  const double *b = (const double *)(const void *)((const char *)y +
                                                   ((const char *)a - (const char *)x));
  return _mm512_mask_blend_pd(ka, _mm512_set1_pd(*b), _mm512_set1_pd(*a));
}

/* Eight points' values between phong_head8 and phong_tail8, as phong_pts4's: the normal's
   sums N, the least clamped area mn, their sum s, the triangle's |tot|, the eye's side */
struct phong_v8 {
  __m512d n[3], mn, s, at, sg;
};

/* phong_head4 at eight points (coordinates px, py on their triangles' axes), triangle x's
   constants in the lanes of ka and (two) triangle y's in the others: the same operations
   lane by lane, into *V (with sg and at, the lanes' sides and |tot|) */
static inline __attribute__((always_inline)) PHONG_ZMM_ATTR
void phong_head8(const struct smooth_lanes *x, const struct smooth_lanes *y, bool two,
                 __mmask8 ka, __m512d px, __m512d py, __m512d sg, __m512d at,
                 struct phong_v8 *V)
{
  const __m512d zero = _mm512_setzero_pd();
  __m512d w[3], s = zero;
#define LANES8(a) lanes8(x, y, a, two, ka)
  for (int k = 0; k < 3; k++) {
    const __m512d ar = _mm512_sub_pd(
        _mm512_mul_pd(LANES8(x->xsd[k][0]), _mm512_sub_pd(py, LANES8(x->xa[k][1]))),
        _mm512_mul_pd(_mm512_sub_pd(px, LANES8(x->xa[k][0])), LANES8(x->xsd[k][1])));
    w[k] = _mm512_max_pd(ar, zero);         /* MAXPD's: the second operand where equal */
    s = k ? _mm512_add_pd(s, w[k]) : w[k];
  }
  V->mn = _mm512_min_pd(_mm512_min_pd(w[0], w[1]), w[2]);
  for (int c = 0; c < 3; c++)
    V->n[c] = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(w[0], LANES8(x->xcn[0][c])),
                                          _mm512_mul_pd(w[1], LANES8(x->xcn[1][c]))),
                            _mm512_mul_pd(w[2], LANES8(x->xcn[2][c])));
#undef LANES8
  V->s = s;
  V->at = at;
  V->sg = sg;
}

/* phong_tail4 (r14) at points q .. q + cnt - 1 (cnt 1 .. 8; lanes past them neither
   stored nor counted) from *V: the same operations lane by lane, the same tests, greys
   and declines (the exact chain, counted in phong_declines; lane h's triangle ta in the
   lanes of ka, else tb); the greys to grey[q + h], under one light eight in one store,
   else clamped to 255 (VPMINSD: g > 255 ? 255 : g) and stored under the step's mask */
static inline __attribute__((always_inline)) PHONG_ZMM_ATTR
void phong_tail8(const struct smooth_model *m, const struct phong_v8 *V, int ta, int tb,
                 __mmask8 ka, int q, int cnt, const double *xu, const double *xw,
                 const unsigned *blocked, bool shadow, const struct shade_lights *L,
                 const __m512d (*lv)[3], int nlight, int *grey)
{
  const __m512d zero = _mm512_setzero_pd();
  const __mmask8 lanes = (__mmask8)((1u << cnt) - 1);
  __m256i bv = _mm256_setzero_si256();
  unsigned bor = 0;
  if (shadow) {
    bv = _mm256_maskz_loadu_epi32(lanes, blocked + q);
    for (int h = 0; h < cnt; h++) bor |= blocked[q + h];
  }
  const __m512d N0 = V->n[0], N1 = V->n[1], N2 = V->n[2], sv = V->s, at = V->at;
  const __m512d nn = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(N0, N0), _mm512_mul_pd(N1, N1)),
                                   _mm512_mul_pd(N2, N2));
  __mmask8 ok = _mm512_cmp_pd_mask(V->mn, _mm512_mul_pd(at, _mm512_set1_pd(0x1p-1000)),
                                   _CMP_GE_OS);
  ok = _mm512_mask_cmp_pd_mask(ok, sv, _mm512_mul_pd(at, _mm512_set1_pd(0x1p1000)), _CMP_LE_OS);
  ok = _mm512_mask_cmp_pd_mask(ok, sv, _mm512_set1_pd(0x1p-500), _CMP_GE_OS);
  ok = _mm512_mask_cmp_pd_mask(ok, nn,
                               _mm512_mul_pd(_mm512_mul_pd(sv, sv), _mm512_set1_pd(0x1p-20)),
                               _CMP_GE_OS);
  const __m512d y0 = _mm512_rsqrt14_pd(nn);
  const __m512d c = _mm512_sub_pd(_mm512_set1_pd(1.5),
                                  _mm512_mul_pd(_mm512_mul_pd(nn, _mm512_set1_pd(0.5)),
                                                _mm512_mul_pd(y0, y0)));
  __m512d sum = zero;
  for (int k = 0; k < nlight; k++) {
    const __m512d dot = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(N0, lv[k][0]),
                                                    _mm512_mul_pd(N1, lv[k][1])),
                                      _mm512_mul_pd(N2, lv[k][2]));
    __m512d d = _mm512_max_pd(_mm512_mul_pd(V->sg, dot), zero);
    if (shadow && (bor >> k & 1u))          /* +0 where light k is blocked */
      d = _mm512_maskz_mov_pd(_mm256_testn_epi32_mask(bv, _mm256_set1_epi32((int)(1u << k))), d);
    sum = k ? _mm512_add_pd(sum, d) : d;
  }
  const __m512d fr = _mm512_set1_pd((255 - SHADE_AMBIENT) * 1.0);
  const __m512d f = _mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(fr, sum), y0), c),
                                  _mm512_set1_pd(0.5));
  const __m512d delta = _mm512_set1_pd(0x1p-15);
  const __m512d f0v = _mm512_sub_pd(f, delta), f1v = _mm512_add_pd(f, delta);
  const __m256i t0 = _mm512_cvttpd_epi32(f0v);
  /* phong_tail's test, lane by lane */
  const __mmask8 fine = _mm256_mask_cmpeq_epi32_mask(
      _mm512_mask_cmp_pd_mask(ok, f1v, _mm512_set1_pd(0x1p30), _CMP_LT_OS), t0,
      _mm512_cvttpd_epi32(f1v));
  if ((fine & lanes) == lanes) {
    const __m256i g = _mm256_add_epi32(t0, _mm256_set1_epi32(SHADE_AMBIENT));
    if (nlight == 1 && cnt == 8)            /* no clamp under one light: phong_tail */
      _mm256_storeu_si256((__m256i *)(void *)&grey[q], g);
    else
      _mm256_mask_storeu_epi32(&grey[q], lanes, _mm256_min_epi32(g, _mm256_set1_epi32(255)));
    return;
  }
  _Alignas(64) double f0[8], f1[8];
  _mm512_store_pd(f0, f0v);
  _mm512_store_pd(f1, f1v);
  for (int h = 0; h < cnt; h++)            /* phong_filter's last test and grey */
    phong_lane_grey(m, &m->tri[ka >> h & 1 ? ta : tb], NULL, xu, xw, q + h, ok >> h & 1,
                    f0[h], f1[h], 1.0, shadow ? blocked[q + h] : 0, L, &grey[q + h]);
}

/* phong_row_lights eight points a step, in one pass (above). A run of a triangle whose
   btot is 0 is declined (its least w_k taken as 0, below |tot| 2^-1000 = 2^-1000 with
   |tot| taken as 1), and so takes the exact chain with its areas (bary_areas), counted,
   as phong_alone takes it in phong_rows. */
static inline __attribute__((always_inline)) PHONG_ZMM_ATTR
void phong_row8_lights(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                       const double *xu, const double *xw, const unsigned *blocked,
                       bool shadow, const struct shade_lights *L, const __m512d (*lv)[3],
                       int nlight, int *grey)
{
  const __m512d one = _mm512_set1_pd(1);    /* values of no use, in lanes not ok */
  int k = 0, p = 0;
  while (k < nseg) {
    const struct smooth_tri *tr = &m->tri[tri[k]];
    const int q = at[k + 1];
    if (tr->btot == 0) {                    /* declined: the exact chain, as phong_alone */
      const struct phong_v8 V = { { one, one, one }, _mm512_setzero_pd(), one, one, one };
      for (; p < q; p += 8)
        phong_tail8(m, &V, tri[k], tri[k], 0xff, p, q - p < 8 ? q - p : 8, xu, xw, blocked,
                    shadow, L, lv, nlight, grey);
      p = q;
      k++;
      continue;
    }
    const struct smooth_lanes *lx = &m->lanes[tri[k]];
    __m512d sg = _mm512_set1_pd(tr->front ? 1 : -1);
    __m512d av = _mm512_set1_pd(fabs(tr->btot));
    const int c = q - p;
    /* lx's constants read at each step from their addresses in lx (memory operands), not
       made and kept on the stack once a run (phong_row4_lights) */
    __asm__("" : "+r"(lx));
    struct phong_v8 V;
    if (c >= 8) {                           /* eight of the run's points */
      phong_head8(lx, lx, false, 0xff, _mm512_loadu_pd(xu + p), _mm512_loadu_pd(xw + p), sg,
                  av, &V);
      phong_tail8(m, &V, tri[k], tri[k], 0xff, p, 8, xu, xw, blocked, shadow, L, lv, nlight,
                  grey);
      p += 8;
      k += p == q;
      continue;
    }
    const struct smooth_tri *tb = k + 1 < nseg ? &m->tri[tri[k + 1]] : NULL;
    if (tb && tb->btot != 0) {              /* run k's last c points, then run k + 1's */
      const int q2 = at[k + 2], e = q2 - p < 8 ? q2 : p + 8;
      const __mmask8 ka = (__mmask8)((1u << c) - 1), l = (__mmask8)((1u << (e - p)) - 1);
      const struct smooth_lanes *ly = &m->lanes[tri[k + 1]];
      __asm__("" : "+r"(ly));
      sg = _mm512_mask_blend_pd(ka, _mm512_set1_pd(tb->front ? 1 : -1), sg);
      av = _mm512_mask_blend_pd(ka, _mm512_set1_pd(fabs(tb->btot)), av);
      phong_head8(lx, ly, true, ka, _mm512_maskz_loadu_pd(l, xu + p),
                  _mm512_maskz_loadu_pd(l, xw + p), sg, av, &V);
      phong_tail8(m, &V, tri[k], tri[k + 1], ka, p, e - p, xu, xw, blocked, shadow, L, lv,
                  nlight, grey);
      p = e;
      k += 1 + (e == q2);
      continue;
    }
    const __mmask8 l = (__mmask8)((1u << c) - 1);   /* the run's last c points alone */
    phong_head8(lx, lx, false, 0xff, _mm512_maskz_loadu_pd(l, xu + p),
                _mm512_maskz_loadu_pd(l, xw + p), sg, av, &V);
    phong_tail8(m, &V, tri[k], tri[k], 0xff, p, c, xu, xw, blocked, shadow, L, lv, nlight,
                grey);
    p = q;
    k++;
  }
}

/* phong_rows4_r14 eight points a step (AVX-512F, rows_zmm) */
static PHONG_ZMM_ATTR void phong_rows8(const struct smooth_model *m, int nseg, const int *tri,
                                       const int *at, const double *xu, const double *xw,
                                       const unsigned *blocked, const struct shade_lights *L,
                                       int *grey)
{
  __m512d lv[SCENE_LIGHT_MAX][3];
  for (int k = 0; k < L->n; k++)
    for (int c = 0; c < 3; c++) lv[k][c] = _mm512_set1_pd(L->v[k][c]);
  const int n = at[nseg];
  unsigned bl = 0;
  for (int p = 0; p < n; p++) bl |= blocked[p];
  const __m512d (*lc)[3] = (const __m512d (*)[3])lv;
  if (L->n == 1 && !bl)
    phong_row8_lights(m, nseg, tri, at, xu, xw, blocked, false, L, lc, 1, grey);
  else if (L->n == 1)
    phong_row8_lights(m, nseg, tri, at, xu, xw, blocked, true, L, lc, 1, grey);
  else
    phong_row8_lights(m, nseg, tri, at, xu, xw, blocked, true, L, lc, L->n, grey);
}

/* Whether smooth_phong_row takes its rows eight points a step: where the processor has
   AVX-512F and AVX-512VL (and the system saves their registers: __builtin_cpu_supports)
   and m's phong_sqrt and phong_ymm (tests only) are not set. */
static inline bool rows_zmm(const struct smooth_model *m)
{
  return !m->phong_sqrt && !m->phong_ymm && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512vl");
}
#endif

static void phong_row(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                      const double (*X)[3], const unsigned *blocked,
                      const struct shade_lights *L, int *grey)
{
  phong_rows(m, nseg, tri, at, X, NULL, NULL, blocked, L, grey);
}

void smooth_phong_row(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                      const double *xu, const double *xw, const unsigned *blocked,
                      const struct shade_lights *L, int *grey)
{
#ifdef PHONG_AVX
  if (rows_avx(m)) {
    if (rows_zmm(m)) phong_rows8(m, nseg, tri, at, xu, xw, blocked, L, grey);
    else if (rows_r14(m)) phong_rows4_r14(m, nseg, tri, at, xu, xw, blocked, L, grey);
    else phong_rows4(m, nseg, tri, at, xu, xw, blocked, L, grey);
    return;
  }
#endif
  phong_rows(m, nseg, tri, at, NULL, xu, xw, blocked, L, grey);
}

/* a run of one point, counted */
int smooth_grey_at(const struct smooth_model *m, const struct mapped *map, const struct scene *s,
                   const struct effects *e, int t, const double X[3], double refl,
                   unsigned blocked, const struct shade_lights *lights, struct cost *cost,
                   int *region_out)
{
  int grey, region;
  smooth_grey_run(m, map, s, e, t, 1, (const double (*)[3])X, refl, &blocked, lights, &grey,
                  &region);
  if (cost) cost_point(cost, e->smooth == EFFECTS_SMOOTH_GOURAUD, region);
  if (region_out) *region_out = region;
  return grey;
}

void smooth_grey_run(const struct smooth_model *m, const struct mapped *map, const struct scene *s,
                     const struct effects *e, int t, int n, const double (*X)[3], double refl,
                     const unsigned *blocked, const struct shade_lights *lights, int *grey,
                     int *region)
{
  const struct smooth_tri *tr = &m->tri[t];
  const struct smooth_lanes *lx = &m->lanes[t];
  double ar[SMOOTH_RUN][3];
  if (e->smooth == EFFECTS_SMOOTH_PHONG) {
    if (phong_pairs(m, tr, lx, n, X, refl, blocked, lights, grey, region) == n) return;
    for (int p = 0; p < n; p++) {            /* (phong_pairs did them all, or none) */
      bary_areas(tr, X[p], ar[p]);
      region[p] = 1;
    }
    phong_lanes(m, tr, n, (const double (*)[3])ar, X, refl, blocked, lights, grey);
    return;
  }
  double l[SMOOTH_RUN][3];
  const double sgn = tr->front ? 1 : -1;     /* seen from inside: the eye's side */
  if (e->smooth == EFFECTS_SMOOTH_GOURAUD) {
    for (int p = 0; p < n; p++) bary_areas(tr, X[p], ar[p]);
    bary_of_areas(tr, n, (const double (*)[3])ar, l);
    for (int p = 0; p < n; p++) {
      double gi = 0;
      for (int k = 0; k < 3; k++) {
        double nk[3] = { sgn * tr->cn[k][0], sgn * tr->cn[k][1], sgn * tr->cn[k][2] };
        const struct scene_vertex *v = &s->v[tr->v[k]];
        double at[3] = { v->x, v->y, v->z };
        gi += l[p][k] * shade_grey_lit(lights, nk, at, refl, blocked[p]);
      }
      const int g = (int)floor(gi + 0.5);
      grey[p] = g < 0 ? 0 : g > 255 ? 255 : g;
      region[p] = 1;
    }
    return;
  }
  /* the partial smoothing: the inner triangle's points the filter proves are in it
     (region 0, the face's normal) without the coordinates, each given the flat picture's
     grey at once when it is exactly that (reflectance 1, no light blocked); the others by
     the chain (each point's steps, one step for all the points at a time: a point's grey
     is the one it has alone) */
  const int fg = map->f[tr->mface].grey;
  const bool flat = refl == 1;
  struct split sp;
  sp.nl = sp.ni = 0;
  inner_split(m, tr, lx, n, X, NULL, NULL, flat, blocked, fg, grey, region, &sp, 0, t, false);
  const int nl = sp.nl;
  double lv[3][SMOOTH_ROW];
  bary_pairs(tr, nl, (const double (*)[SMOOTH_ROW])sp.la, lv);
  /* the lit points' normals in slots, a component an array (lit_slots): the band
     points' in their order, but for those the chain puts in region 0 that take the flat
     picture's grey (reflectance 1, no light blocked, as for the inner triangle's), then
     the inner triangle's that are lit */
  double nv[3][SMOOTH_ROW];
  int slot_p[SMOOTH_ROW], ns = 0;
  for (int q = 0; q < nl; q++) {
#ifdef __SSE2__
    int r2;                                 /* two points of one edge or corner band */
    if (q + 1 < nl && (r2 = band_pair_normals(lx, lv, q, nv, ns)) != 0) {
      for (int h = 0; h < 2; h++) {
        region[sp.at[q + h]] = r2;
        slot_p[ns++] = sp.at[q + h];
      }
      q++;
      continue;
    }
#endif
    const double lq[3] = { lv[0][q], lv[1][q], lv[2][q] };
    double out[3];
    const int r = partial_normal(tr, lq, out), p = sp.at[q];
    region[p] = r;
    if (r == 0 && flat && !blocked[p]) {
      grey[p] = fg;
      continue;
    }
    for (int c = 0; c < 3; c++) nv[c][ns] = out[c];
    slot_p[ns++] = p;
  }
  for (int k = 0; k < sp.ni; k++, ns++) {   /* the face's normal */
    for (int c = 0; c < 3; c++) nv[c][ns] = tr->n[c];
    slot_p[ns] = sp.lit_in[k];
  }
  if (ns) lit_slots(m, sgn, ns, nv, slot_p, X, refl, blocked, lights, grey);
}

/* ---- a row's stretch of points on several triangles (smooth_row) ------------------ */

#ifdef __SSE2__
/* The lengths of two normals (x, y, z lanes): fl(sqrt(fl(fl(x x + y y) + z z))). */
static inline __attribute__((always_inline))
__m128d pair_length(__m128d v0, __m128d v1, __m128d v2)
{
  return _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(v0, v0), _mm_mul_pd(v1, v1)),
                                _mm_mul_pd(v2, v2)));
}

/* The lights' sum at two normals v (x, y, z lanes) on their eye's sides sg (+-1): each
   parallel light k's fl(fl(v_0 (l_0 sg) + v_1 (l_1 sg)) + v_2 (l_2 sg)), taken where it is
   positive and light k is not blocked in the lane (b0, b1: lane 0's and lane 1's blocked
   lights), added in the lights' order. lit_pair's on the unit normals, lit_pair_filter's
   on the normals as they are. */
static inline __attribute__((always_inline))
__m128d lights_sum(__m128d v0, __m128d v1, __m128d v2, __m128d sg, unsigned b0, unsigned b1,
                   const struct shade_lights *L, int nlight)
{
  const __m128d zero = _mm_setzero_pd();
  __m128d sum = zero;
  for (int k = 0; k < nlight; k++) {
    const double *l = L->v[k];
    const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(v0, _mm_mul_pd(_mm_set1_pd(l[0]), sg)),
                                            _mm_mul_pd(v1, _mm_mul_pd(_mm_set1_pd(l[1]), sg))),
                                 _mm_mul_pd(v2, _mm_mul_pd(_mm_set1_pd(l[2]), sg)));
    __m128d m = _mm_cmpgt_pd(d, zero);
    if ((b0 | b1) >> k & 1u)                  /* the lanes whose light k is not blocked */
      m = _mm_and_pd(m, _mm_castsi128_pd(_mm_set_epi64x((b1 >> k & 1u) - 1ull,
                                                        (b0 >> k & 1u) - 1ull)));
    /* the first light's term is the sum: +0 + x is x for x positive or +0 */
    sum = k ? _mm_add_pd(sum, _mm_and_pd(m, d)) : _mm_and_pd(m, d);
  }
  return sum;
}

/* lit_row's step at two slots under parallel lights, reflectance refl: normals v (x, y, z
   lanes), the eye's sides sg, the lights blocked b0 and b1; their greys into *g0, *g1.
   nlight is L->n (a constant where the caller can make it one). */
static inline __attribute__((always_inline))
void lit_pair(__m128d v0, __m128d v1, __m128d v2, __m128d sg, unsigned b0, unsigned b1,
              const struct shade_lights *L, int nlight, double refl, int *g0, int *g1)
{
  const __m128d zero = _mm_setzero_pd(), rv = _mm_set1_pd(refl);
  __m128d v[3] = { v0, v1, v2 };
  const __m128d ln = pair_length(v0, v1, v2);
  const __m128d pos = _mm_cmpgt_pd(ln, zero);
  /* the unit vector u (v / ln where ln > 0, else v), not yet turned to its side: the
     scalar steps multiply it by sg (+-1) and then by the light, (u_c sg) l_c; here sg
     goes to the light, u_c (l_c sg), off the chain of the square root and the divides.
     The same double: both products are u_c l_c or its negation, exactly (a product's
     sign is the exclusive or of its operands', its magnitude |u_c| |l_c| correctly
     rounded, and times +-1 is exact), zeros and their signs included */
  if (_mm_movemask_pd(pos) == 3)            /* both lengths positive: the selection's value */
    for (int c = 0; c < 3; c++) v[c] = _mm_div_pd(v[c], ln);
  else
    for (int c = 0; c < 3; c++)
      v[c] = _mm_or_pd(_mm_and_pd(pos, _mm_div_pd(v[c], ln)), _mm_andnot_pd(pos, v[c]));
  const __m128d sum = lights_sum(v[0], v[1], v[2], sg, b0, b1, L, nlight);
  unsigned g;                                 /* both lanes' greys at once where it can */
  if (shade_pair_greys_fast(rv, sum, &g)) {
    *g0 = (int)(g & 0xffu);
    *g1 = (int)(g >> 8);
    return;
  }
  double sm[2];
  _mm_storeu_pd(sm, sum);
  *g0 = clamp_grey(shade_grey_of_sum(refl, sm[0]));
  *g1 = clamp_grey(shade_grey_of_sum(refl, sm[1]));
}
#endif

/* The lit pairs' filter.
**
** lit_pair's chain makes each normal v a unit vector, u_c = fl(v_c / l) with l =
** fl(sqrt(fl(v.v))) (three divides after the square root, each waiting on it), then each
** light's d = fl(fl(u_0 m_0 + u_1 m_1) + u_2 m_2) with m_c = fl(l_c sg) = +-l_c (exact),
** the sum s of the terms max(d, 0) of the lights not blocked (d > 0 taken, else +0) in the
** lights' order, and the grey from f = fl(fl(c s) + 0.5), c = fl(207 refl)
** (shade_pair_greys_fast, where f is in [0, 2^30)). The filter finds the same grey with one
** divide: the same l, e = fl(fl(v_0 m_0 + v_1 m_1) + v_2 m_2) a light (made beside the
** square root, not after it), S' the sum of the terms max(e, 0) of the lights not blocked,
** D = fl(S' / l) and f' = fl(fl(c D) + 0.5); it gives 48 + floor(f') (clamped to 255, as
** the chain's) when 2^-400 <= l <= 2^400, f' - 2^-29 >= 0, f' + 2^-29 < 2^10 and the two
** have one floor, else it declines and the chain runs.
**
** Proof that f is within 2^-30 of f' then (so in [f' - 2^-29, f' + 2^-29] with room for
** those two roundings, each below 2^-43 at f' < 2^10: f has that floor too, rounding
** being monotonic, and f is in [0, 2^30): the chain's grey is 48 + floor(f)). u = 2^-53.
** In real numbers let w_c = v_c / l and A_k = sum_c |w_c m_kc| for light k. Where l >=
** 2^-400, fl(v.v) >= 2^-801 and its squares' underflows (below 2^-1074 each) are far
** below u of it, so |v| <= l (1 + 3u) and every |w_c| <= 1 + 3u: A_k <= (1 + 3u) Lam_k,
** Lam_k = sum_c |l_kc| (|m_kc| = |l_kc|). A rounding is x (1 + a) + b with |a| <= u and
** |b| <= 2^-1075 (b only where the result is subnormal; sums of doubles are exact there).
** The chain: u_c =
** w_c (1 + a) + b, its products and two adds, so |d - sum_c w_c m_c| <= 4.01u A_k +
** 2^-1070 (|m_c| <= 2^8: below). The filter: |e / l - sum_c w_c m_c| <= 3.01u A_k +
** 2^-1071 / l <= 3.01u A_k + 2^-670. Then max(., 0) moves neither apart (|max(x, 0) -
** max(y, 0)| <= |x - y|; max(e, 0) / l = max(e / l, 0), l > 0), and with T the sum of
** max(sum_c w_c m_kc, 0) over the lights not blocked, the at most 16 terms' at most 15 adds
** (of terms >= 0) and D's divide: |s - T| <= (4.01 + 15.2) u A + 2^-1066 and |D - T| <=
** (3.01 + 15.2 + 1.01) u A + 2^-666, A = sum_k A_k <= (1 + 3u) Lam, Lam = sum_k Lam_k:
** |s - D| <= 38.5u Lam + 2^-665. f and f' are c s and c D each rounded twice, within 2.01u
** |f| < 2^-42 (f' < 2^10 and f near it): |f - f'| <= c (38.5u Lam + 2^-665) + 2^-41. lit_row
** takes the filter only where c and Lam are each at most 2^8 (one test a row; refl 1 and
** one unit light: c = 207, Lam <= sqrt 3): then c Lam <= 2^16 and |f - f'| <= 2^16 38.5
** 2^-53 + 2^-41 + 2^-640 < 2^-31.7 + 2^-41 < 2^-30. (Every |m_c| is then at most 2^8, and
** no step overflows where l <= 2^400: |v_c m_c| <= 2^410.) test_smooth
** (test_lit_filter_is_exact) holds the filter to the chain on a grid of points in and
** around every triangle of the globe and of the t1 objects (their band normals, and the
** face's where lit) and on points bisected onto the borders between two of the chain's
** greys, where it must decline. */
#ifdef __SSE2__
/* The filter at two slots (lit_pair's arguments; refl's c = fl(207 refl) in cv): true and
   their greys into *g0, *g1; false (nothing written) when it declines. */
static inline __attribute__((always_inline))
bool lit_pair_filter(__m128d v0, __m128d v1, __m128d v2, __m128d sg, unsigned b0, unsigned b1,
                     const struct shade_lights *L, int nlight, __m128d cv, int *g0, int *g1)
{
  const __m128d zero = _mm_setzero_pd();
  const __m128d ln = pair_length(v0, v1, v2);
  const __m128d sum = lights_sum(v0, v1, v2, sg, b0, b1, L, nlight);   /* S', on v as it is */
  const __m128d f = _mm_add_pd(_mm_mul_pd(cv, _mm_div_pd(sum, ln)), _mm_set1_pd(0.5));
  const __m128d dl = _mm_set1_pd(0x1p-29);
  const __m128d f0 = _mm_sub_pd(f, dl), f1 = _mm_add_pd(f, dl);
  const __m128d ok = _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(ln, _mm_set1_pd(0x1p-400)),
                                           _mm_cmple_pd(ln, _mm_set1_pd(0x1p400))),
                                _mm_and_pd(_mm_cmpge_pd(f0, zero),
                                           _mm_cmplt_pd(f1, _mm_set1_pd(0x1p10))));
  const __m128i t0 = _mm_cvttpd_epi32(f0), t1 = _mm_cvttpd_epi32(f1);
  if (_mm_movemask_pd(ok) != 3 || (_mm_movemask_epi8(_mm_cmpeq_epi32(t0, t1)) & 0xff) != 0xff)
    return false;
  const unsigned g = shade_pair_pack(t0);   /* (0 <= t0 < 2^10) */
  *g0 = (int)(g & 0xffu);
  *g1 = (int)(g >> 8);
  return true;
}

/* lit_pair through the filter where lit_row takes it (filt), else (or where it declines)
   lit_pair itself. */
static inline __attribute__((always_inline))
void lit_pair_as(bool filt, __m128d v0, __m128d v1, __m128d v2, __m128d sg, unsigned b0,
                 unsigned b1, const struct shade_lights *L, int nlight, double refl, __m128d cv,
                 int *g0, int *g1, long *declines)
{
  if (filt) {
    if (lit_pair_filter(v0, v1, v2, sg, b0, b1, L, nlight, cv, g0, g1)) return;
    ++*declines;
  }
  lit_pair(v0, v1, v2, sg, b0, b1, L, nlight, refl, g0, g1);
}
#endif

/* The greys of slots q .. ns - 1 (q: the first, 0 but after lit_quads): the normal (nv[0][q], nv[1][q], nv[2][q]) made a unit vector
   (unit()'s steps), turned to its eye's side (times sg[q]) and lit (shade_grey_lit, at
   reflectance refl) at point slot_p[q] (X, blocked), into grey[slot_p[q]] clamped to
   0..255. Under parallel lights two slots an instruction where the processor has SSE2
   (lit_pair: each lane's operations the scalar ones on its values in their order,
   correctly rounded as the scalar ones are; a lone last slot in both lanes), through the
   lit pairs' filter (lit_pair_filter: one divide a pair, not three) where fl(207 refl) and
   the lights' sum of |l_c| are at most 2^8 each (and not m's lit_exact). */
static inline __attribute__((always_inline))
void lit_row(const struct smooth_model *m, int q, int ns, double (*nv)[SMOOTH_ROW],
             const double *sg, double refl, const int *slot_p, const double (*X)[3],
             const unsigned *blocked, const struct shade_lights *L, int *grey)
{
#ifdef __SSE2__
  bool parallel = true;
  double lam = 0;
  for (int k = 0; k < L->n; k++) {
    parallel &= !L->point[k];
    lam += fabs(L->v[k][0]) + fabs(L->v[k][1]) + fabs(L->v[k][2]);
  }
  if (parallel) {
    const int nlight = L->n;
    const double c = (255 - SHADE_AMBIENT) * refl;
    /* (the sum of |l_c| rounded: at most 47 roundings up of a relative 2^-53 below the
       proof's Lam's bound, far inside 2^8's room) */
    const bool filt = !m->lit_exact && c >= 0 && c <= 0x1p8 && lam <= 0x1p8;
    const __m128d cv = _mm_set1_pd(c);
    long declines = 0;
    /* (pick2: the slots were just written, a pair or one at a time) */
    if (nlight == 1)                          /* the usual case: the light loop unrolled */
      for (; q + 2 <= ns; q += 2)
        lit_pair_as(filt, pick2(nv[0] + q, nv[0] + q + 1), pick2(nv[1] + q, nv[1] + q + 1),
                    pick2(nv[2] + q, nv[2] + q + 1), pick2(sg + q, sg + q + 1),
                    blocked[slot_p[q]], blocked[slot_p[q + 1]], L, 1, refl, cv,
                    &grey[slot_p[q]], &grey[slot_p[q + 1]], &declines);
    for (; q + 2 <= ns; q += 2)
      lit_pair_as(filt, pick2(nv[0] + q, nv[0] + q + 1), pick2(nv[1] + q, nv[1] + q + 1),
                  pick2(nv[2] + q, nv[2] + q + 1), pick2(sg + q, sg + q + 1),
                  blocked[slot_p[q]], blocked[slot_p[q + 1]], L, nlight, refl, cv,
                  &grey[slot_p[q]], &grey[slot_p[q + 1]], &declines);
    if (q < ns) {
      int dummy;
      lit_pair_as(filt, _mm_set1_pd(nv[0][q]), _mm_set1_pd(nv[1][q]), _mm_set1_pd(nv[2][q]),
                  _mm_set1_pd(sg[q]), blocked[slot_p[q]], blocked[slot_p[q]], L, nlight,
                  refl, cv, &grey[slot_p[q]], &dummy, &declines);
      q++;
    }
    if (m->lit_declines) *m->lit_declines += declines;
  }
#else
  (void)m;
#endif
  for (; q < ns; q++) {
    double v[3] = { nv[0][q], nv[1][q], nv[2][q] };
    unit(v);
    for (int c = 0; c < 3; c++) v[c] *= sg[q];
    grey[slot_p[q]] = clamp_grey(shade_grey_lit(L, v, X[slot_p[q]], refl, blocked[slot_p[q]]));
  }
}

#ifdef PHONG_AVX
/* lit_pair_filter at four slots q .. q + 3 (lanes 0 .. 3: normals nv[c][q + h], sides
   sg[q + h], the lights blocked b[h]; c = fl(207 refl) in cv): each lane's operations
   lit_pair_filter's on its values in their order (VEX-encoded, 256 bits wide, the same
   IEEE operations: no fused multiply-add, the build's -ffp-contract=off; the compares by
   the predicates of SSE2's CMPPD: GT_OS, GE_OS, LE_OS, LT_OS, false for a NaN as theirs),
   so where it takes all four lanes each lane's grey is the pair filter's, and that the
   chain's (the lit pairs' filter's proof). True and the greys into g[h] when every lane
   passes the filter's tests; false (nothing written) when any lane declines. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
bool lit_quad_filter(double (*nv)[SMOOTH_ROW], const double *sg, int q, const unsigned b[4],
                     const struct shade_lights *L, int nlight, __m256d cv, int g[4])
{
  const __m256d zero = _mm256_setzero_pd();
  const __m256d v0 = _mm256_loadu_pd(nv[0] + q), v1 = _mm256_loadu_pd(nv[1] + q),
                v2 = _mm256_loadu_pd(nv[2] + q), sgv = _mm256_loadu_pd(sg + q);
  const __m256d ln = _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v0, v0),
                                                                _mm256_mul_pd(v1, v1)),
                                                  _mm256_mul_pd(v2, v2)));
  __m256d sum = zero;                         /* lights_sum's, lane by lane */
  for (int k = 0; k < nlight; k++) {
    const double *l = L->v[k];
    const __m256d d =
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v0, _mm256_mul_pd(_mm256_set1_pd(l[0]), sgv)),
                                    _mm256_mul_pd(v1, _mm256_mul_pd(_mm256_set1_pd(l[1]), sgv))),
                      _mm256_mul_pd(v2, _mm256_mul_pd(_mm256_set1_pd(l[2]), sgv)));
    __m256d mk = _mm256_cmp_pd(d, zero, _CMP_GT_OS);
    if ((b[0] | b[1] | b[2] | b[3]) >> k & 1u) mk = _mm256_and_pd(mk, unblocked4(b, k));
    sum = k ? _mm256_add_pd(sum, _mm256_and_pd(mk, d)) : _mm256_and_pd(mk, d);
  }
  const __m256d f = _mm256_add_pd(_mm256_mul_pd(cv, _mm256_div_pd(sum, ln)),
                                  _mm256_set1_pd(0.5));
  const __m256d dl = _mm256_set1_pd(0x1p-29);
  const __m256d f0 = _mm256_sub_pd(f, dl), f1 = _mm256_add_pd(f, dl);
  const __m256d ok =
      _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(ln, _mm256_set1_pd(0x1p-400), _CMP_GE_OS),
                                  _mm256_cmp_pd(ln, _mm256_set1_pd(0x1p400), _CMP_LE_OS)),
                    _mm256_and_pd(_mm256_cmp_pd(f0, zero, _CMP_GE_OS),
                                  _mm256_cmp_pd(f1, _mm256_set1_pd(0x1p10), _CMP_LT_OS)));
  const __m128i t0 = _mm256_cvttpd_epi32(f0), t1 = _mm256_cvttpd_epi32(f1);
  if (_mm256_movemask_pd(ok) != 15 || _mm_movemask_epi8(_mm_cmpeq_epi32(t0, t1)) != 0xffff)
    return false;
  /* (0 <= t0 < 2^10: 48 + t0 packed to bytes by the two saturating packs, as
     shade_pair_pack's, four lanes) */
  const __m128i a = _mm_add_epi32(t0, _mm_set1_epi32(SHADE_AMBIENT));
  const unsigned gb = (unsigned)_mm_cvtsi128_si32(
      _mm_packus_epi16(_mm_packs_epi32(a, a), _mm_setzero_si128()));
  for (int h = 0; h < 4; h++) g[h] = (int)(gb >> 8 * h & 0xffu);
  return true;
}

/* lit_row's slots four a step (lit_quad_filter) from slot 0 where lit_row would take the
   lit pairs' filter (under parallel lights, fl(207 refl) and the lights' sum of |l_c| at
   most 2^8 each, not m's lit_exact); a step any of whose lanes the filter declines is
   made as lit_row makes it, its two pairs each by lit_pair_as (so the same greys, and
   the same declines counted: lit_row's pairs are these). Returns the first slot left to
   lit_row (a multiple of 4; 0 where the filter is not taken). */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
int lit_quads(const struct smooth_model *m, int ns, double (*nv)[SMOOTH_ROW], const double *sg,
              const int *slot_p, const unsigned *blocked, const struct shade_lights *L,
              int *grey)
{
  double lam = 0;
  for (int k = 0; k < L->n; k++) {
    if (L->point[k]) return 0;
    lam += fabs(L->v[k][0]) + fabs(L->v[k][1]) + fabs(L->v[k][2]);
  }
  const double c = 255 - SHADE_AMBIENT;      /* refl 1 */
  if (m->lit_exact || !(lam <= 0x1p8)) return 0;
  const __m256d cv = _mm256_set1_pd(c);
  const __m128d cv2 = _mm_set1_pd(c);
  const int nlight = L->n;
  long declines = 0;
  int q = 0;
  for (; q + 4 <= ns; q += 4) {
    const int p0 = slot_p[q], p1 = slot_p[q + 1], p2 = slot_p[q + 2], p3 = slot_p[q + 3];
    const unsigned b[4] = { blocked[p0], blocked[p1], blocked[p2], blocked[p3] };
    int g[4];
    if (nlight == 1 ? lit_quad_filter(nv, sg, q, b, L, 1, cv, g)
                    : lit_quad_filter(nv, sg, q, b, L, nlight, cv, g)) {
      grey[p0] = g[0];
      grey[p1] = g[1];
      grey[p2] = g[2];
      grey[p3] = g[3];
      continue;
    }
    for (int h = 0; h < 4; h += 2)
      lit_pair_as(true, pick2(nv[0] + q + h, nv[0] + q + h + 1),
                  pick2(nv[1] + q + h, nv[1] + q + h + 1), pick2(nv[2] + q + h, nv[2] + q + h + 1),
                  pick2(sg + q + h, sg + q + h + 1), b[h], b[h + 1], L, nlight, 1.0, cv2,
                  &grey[slot_p[q + h]], &grey[slot_p[q + h + 1]], &declines);
  }
  if (m->lit_declines) *m->lit_declines += declines;
  return q;
}

/* inner_split for a row's stretch of triangle t's points (row, flat: partial_rows' call)
   four points a step (AVX's 256-bit registers), the rest (n mod 4) by inner_split itself.
   Each lane's operations inner_split's pair step's on its point, in their order (the
   same IEEE operations, VEX-encoded: no fused multiply-add, -ffp-contract=off; the
   compares by CMPPD's predicates GE_OS, LE_OS, GT_OS, false for a NaN as SSE2's; MAXPD's
   operand order kept, so +0 for a NaN or a zero quotient as there), the same tests, and
   the points put into sp in their order (those proved inner by inner_point, the others'
   coordinates, triangles and indices): the same split, bit for bit, and the same
   declines counted. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void inner_split4(const struct smooth_model *m, const struct smooth_tri *tr,
                  const struct smooth_lanes *lx, int n, const double *xu, const double *xw,
                  const unsigned *blocked, int fg, int *grey, struct split *sp, int base,
                  int t)
{
  if (lx->inner_ok && !m->inner_exact) {
    long declines = 0;
    int p = 0;
    const __m256d lov = _mm256_broadcast_sd(lx->xilo), hiv = _mm256_broadcast_sd(lx->xihi);
    const __m256d atv = _mm256_set1_pd(fabs(tr->btot)), zero = _mm256_setzero_pd();
    /* the triangle's constants in four lanes, once a stretch (those the registers cannot
       hold are kept on the stack, each step's operations reading them from there) */
    __m256d a0[3], a1[3], d0[3], d1[3], tc[3];
    for (int k = 0; k < 3; k++) {
      a0[k] = _mm256_broadcast_sd(&lx->xa[k][0][0]);
      a1[k] = _mm256_broadcast_sd(&lx->xa[k][1][0]);
      d0[k] = _mm256_broadcast_sd(&lx->xsd[k][0][0]);
      d1[k] = _mm256_broadcast_sd(&lx->xsd[k][1][0]);
      tc[k] = _mm256_broadcast_sd(lx->xtc[k]);
    }
    for (; p < n; p += 4) {
      const int cnt = n - p < 4 ? n - p : 4;  /* the step's points: lanes 0 .. cnt - 1 */
      __m256d x, y;
      if (cnt == 4) {
        /* (two 16-byte loads each: smooth_partial_row's callers store xu and xw 16 bytes
           a store from the triangle's first point, and a load is forwarded only from one
           store) */
        x = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(xu + p)),
                                 _mm_loadu_pd(xu + p + 2), 1);
        y = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(xw + p)),
                                 _mm_loadu_pd(xw + p + 2), 1);
      } else {                                /* the lanes past them: the last point again */
        const int i1 = cnt > 1, i2 = cnt > 2 ? 2 : i1;
        x = _mm256_set_pd(xu[p + i2], xu[p + i2], xu[p + i1], xu[p]);
        y = _mm256_set_pd(xw[p + i2], xw[p + i2], xw[p + i1], xw[p]);
      }
      __m256d w[3];
      for (int k = 0; k < 3; k++)             /* area_lanes' operations */
        w[k] = _mm256_sub_pd(_mm256_mul_pd(d0[k], _mm256_sub_pd(y, a1[k])),
                             _mm256_mul_pd(_mm256_sub_pd(x, a0[k]), d1[k]));
      const __m256d S = _mm256_add_pd(_mm256_add_pd(w[0], w[1]), w[2]);
      __m256d ok = _mm256_and_pd(_mm256_cmp_pd(S, lov, _CMP_GE_OS),
                                 _mm256_cmp_pd(S, hiv, _CMP_LE_OS));
      for (int k = 0; k < 3; k++)
        ok = _mm256_and_pd(ok, _mm256_cmp_pd(w[k], _mm256_mul_pd(tc[k], S), _CMP_GE_OS));
      const int bits = _mm256_movemask_pd(ok);
      if (cnt == 4 && bits == 15 &&
          !(blocked[p] | blocked[p + 1] | blocked[p + 2] | blocked[p + 3])) {
        grey[p] = grey[p + 1] = grey[p + 2] = grey[p + 3] = fg;
        continue;
      }
      /* the coordinates (inner_split's row step, lane by lane) */
      __m256d lk[3], v[3];
      for (int k = 0; k < 3; k++) lk[k] = _mm256_max_pd(_mm256_div_pd(w[k], atv), zero);
      const __m256d sum = _mm256_add_pd(_mm256_add_pd(lk[0], lk[1]), lk[2]);
      const __m256d pos = _mm256_cmp_pd(sum, zero, _CMP_GT_OS);
      if (_mm256_movemask_pd(pos) == 15)
        for (int k = 0; k < 3; k++) v[k] = _mm256_div_pd(lk[k], sum);
      else
        for (int k = 0; k < 3; k++)
          v[k] = _mm256_blendv_pd(_mm256_set1_pd(1.0 / 3), _mm256_div_pd(lk[k], sum), pos);
      if ((bits & ((1 << cnt) - 1)) == 0 && sp->nl + 4 <= SMOOTH_ROW) {
        /* every point of the step to the chain (the usual case): four lanes a store, the
           lanes past the step's points (held by no slot, written over by the next) inside
           sp's arrays */
        const int nl = sp->nl;
        for (int k = 0; k < 3; k++) _mm256_storeu_pd(sp->la[k] + nl, v[k]);
        _mm_storeu_si128((__m128i *)(sp->tri + nl), _mm_set1_epi32(t));
        _mm_storeu_si128((__m128i *)(sp->at + nl),
                         _mm_add_epi32(_mm_set1_epi32(base + p), _mm_set_epi32(3, 2, 1, 0)));
        sp->nl = nl + cnt;
        declines += cnt;
        continue;
      }
      double vs[3][4];
      for (int k = 0; k < 3; k++) _mm256_storeu_pd(vs[k], v[k]);
      for (int h = 0; h < cnt; h++) {
        if (bits >> h & 1) {
          inner_point(sp, p + h, true, blocked, fg, grey, NULL, base, t, true);
          continue;
        }
        declines++;
        for (int k = 0; k < 3; k++) sp->la[k][sp->nl] = vs[k][h];
        sp->tri[sp->nl] = t;
        sp->at[sp->nl++] = base + p + h;
      }
    }
    if (m->inner_declines) *m->inner_declines += declines;
    return;
  }
  inner_split(m, tr, lx, n, NULL, xu, xw, true, blocked, fg, grey, NULL, sp, base, t, true);
}
/* partial_split in the AVX build: inner_split4 a triangle at a time. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void partial_split4(const struct smooth_model *m, const struct mapped *map, int nseg,
                    const int *tri, const int *at, const double *xu, const double *xw,
                    const unsigned *blocked, int *grey, long regions[3], struct split *sp)
{
  sp->nl = sp->ni = 0;
  for (int k = 0; k < nseg; k++) {
    const int t = tri[k], b = at[k];
    const struct smooth_tri *tr = &m->tri[t];
    inner_split4(m, tr, &m->lanes[t], at[k + 1] - b, xu + b, xw + b, blocked + b,
                 map->f[tr->mface].grey, grey + b, sp, b, t);
  }
  regions[0] += at[nseg] - sp->nl;          /* the points proved inner */
}
#endif

#ifdef PHONG_AVX
/* Whether partial_row takes partial_row_zmm (AVX-512F and VL, not the tests' partial_ymm). */
static inline bool rows_partial_zmm(const struct smooth_model *m)
{
  return !m->partial_ymm && __builtin_cpu_supports("avx512f") &&
         __builtin_cpu_supports("avx512vl");
}
#endif

/* smooth_row under smooth=fixed or prop: smooth_grey_run's partial smoothing, its steps
   each over the whole stretch (reflectance 1: flat) and each point with its own
   triangle's constants: the inner triangle's filter a triangle at a time (inner_split,
   the chain's points gathered with their barycentric coordinates, whose divides the
   processor overlaps with the filter's work on the points after them), the normals (two
   points of one triangle's edge or corner band together: band_pair_normals), the
   lighting (lit_row). No step waits on a divide to choose its next branch before the
   normals. The points are given by their coordinates on their triangles' axes bu and bw,
   xu[p] and xw[p]: all that the steps read of them but the lighting under a point light,
   which takes the space points X (NULL when the lights are all parallel). Built twice
   (partial_row_sse2, partial_row_avx): the steps are partial_split or partial_split4,
   partial_normals, then lit_row (after lit_quads in the AVX build). */

/* The lit points' normals in slots (as smooth_grey_run's), each with its eye's side and
   its point. */
struct slots {
  double nv[3][SMOOTH_ROW], sg[SMOOTH_ROW];
  int slot_p[SMOOTH_ROW];
};

/* partial_rows' first step: the inner triangle's filter a triangle at a time (inner_split)
   into sp, the points proved inner counted in regions[0]. */
static inline __attribute__((always_inline))
void partial_split(const struct smooth_model *m, const struct mapped *map, int nseg,
                   const int *tri, const int *at, const double *xu, const double *xw,
                   const unsigned *blocked, int *grey, long regions[3], struct split *sp)
{
  sp->nl = sp->ni = 0;
  for (int k = 0; k < nseg; k++) {
    const int t = tri[k], b = at[k];
    const struct smooth_tri *tr = &m->tri[t];
    inner_split(m, tr, &m->lanes[t], at[k + 1] - b, NULL, xu + b, xw + b, true, blocked + b,
                map->f[tr->mface].grey, grey + b, NULL, sp, b, t, true);
  }
  regions[0] += at[nseg] - sp->nl;          /* the points proved inner */
}

/* partial_normals' step at point q of sp (its lv: sp's coordinates): two points of one
   triangle's edge or corner band (band_pair_normals), else one point (band_lanes, or
   partial_normal's chain where it is in neither: the inner triangle, or every coordinate
   below its inset), their normals into the slots S from *ns on (the inner ones not lit
   given the face's grey), their regions counted; returns the point after them. */
static inline __attribute__((always_inline))
int normals_step(const struct smooth_model *m, const struct mapped *map, struct split *sp,
                 int q, const unsigned *blocked, int *grey, long regions[3], struct slots *S,
                 int *ns)
{
  const int nl = sp->nl;
  double (*lv)[SMOOTH_ROW] = sp->la;
  double (*nv)[SMOOTH_ROW] = S->nv;
  const int t = sp->tri[q];
  const struct smooth_tri *tr = &m->tri[t];
  const double sgn = tr->front ? 1 : -1;     /* seen from inside: the eye's side */
#ifdef __SSE2__
  if (q + 1 < nl && sp->tri[q + 1] == t) {
    const int r = band_pair_normals(&m->lanes[t], lv, q, nv, *ns);
    if (r) {                                  /* two points of one edge or corner band */
      for (int h = 0; h < 2; h++) {
        S->sg[*ns] = sgn;
        S->slot_p[(*ns)++] = sp->at[q + h];
      }
      regions[r] += 2;
      return q + 2;
    }
  }
  {                                           /* one point of a band: in both lanes */
    const __m128d l[3] = { _mm_set1_pd(lv[0][q]), _mm_set1_pd(lv[1][q]), _mm_set1_pd(lv[2][q]) };
    __m128d n[3];
    const int r = band_lanes(&m->lanes[t], l, n);
    if (r) {
      for (int c = 0; c < 3; c++) _mm_storel_pd(&nv[c][*ns], n[c]);
      S->sg[*ns] = sgn;
      S->slot_p[(*ns)++] = sp->at[q];
      regions[r]++;
      return q + 1;
    }
  }
#endif
  const double lq[3] = { lv[0][q], lv[1][q], lv[2][q] };
  double out[3];
  const int r = partial_normal(tr, lq, out), p = sp->at[q];
  regions[r]++;                               /* 0, 1 or 2 */
  if (r == 0 && !blocked[p]) {
    grey[p] = map->f[tr->mface].grey;
    return q + 1;
  }
  for (int c = 0; c < 3; c++) nv[c][*ns] = out[c];
  S->sg[*ns] = sgn;
  S->slot_p[(*ns)++] = p;
  return q + 1;
}

/* The points put aside to be lit with the face's normal (sp's lit_in) into the slots S
   from ns on; returns the slots' count. */
static inline __attribute__((always_inline))
int face_slots(const struct smooth_model *m, const struct split *sp, struct slots *S, int ns)
{
  for (int k = 0; k < sp->ni; k++, ns++) {
    const struct smooth_tri *tr = &m->tri[sp->lit_tri[k]];
    for (int c = 0; c < 3; c++) S->nv[c][ns] = tr->n[c];
    S->sg[ns] = tr->front ? 1 : -1;
    S->slot_p[ns] = sp->lit_in[k];
  }
  return ns;
}

/* partial_rows' second step: the normals of the points left to the chain in sp (their
   regions counted, the inner ones not lit given the face's grey: normals_step) and of the
   points put aside to be lit with the face's normal (face_slots), into the slots S;
   returns how many. */
static inline __attribute__((always_inline))
int partial_normals(const struct smooth_model *m, const struct mapped *map, struct split *sp,
                    const unsigned *blocked, int *grey, long regions[3], struct slots *S)
{
  int ns = 0;
  for (int q = 0; q < sp->nl;) q = normals_step(m, map, sp, q, blocked, grey, regions, S, &ns);
  return face_slots(m, sp, S, ns);
}

#ifdef PHONG_AVX
/* edge_lanes at four points (lanes 0 .. 3) of one edge band k: each lane edge_lanes'
   operations (and so partial_normal's) on its values in their order, VEX-encoded, 256
   bits wide (the compare GT_OS: CMPPD's GT; VMAXPD and VMINPD as MAXPD and MINPD, the
   same operand order). */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void edge_lanes4(const struct smooth_lanes *x, const __m256d *l, int k, __m256d *n)
{
  const int a = next3[k], b = prev3[k];
  const __m256d one = _mm256_set1_pd(1), zero = _mm256_setzero_pd();
  const __m256d tk = _mm256_broadcast_sd(x->xt[k]), ta = _mm256_broadcast_sd(x->xt[a]);
  const __m256d v = _mm256_div_pd(l[k], tk);
  const __m256d den = _mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(one, l[k]), ta),
                                    _mm256_broadcast_sd(x->xt[b]));
  const __m256d big = _mm256_cmp_pd(den, _mm256_set1_pd(1e-12), _CMP_GT_OS);
  __m256d s = _mm256_blendv_pd(_mm256_set1_pd(0.5),
                               _mm256_div_pd(_mm256_sub_pd(l[a], ta), den), big);
  s = _mm256_max_pd(zero, s);                                   /* s < 0: +0 */
  s = _mm256_min_pd(one, s);                                    /* s > 1: 1 */
  const __m256d omv = _mm256_sub_pd(one, v), oms = _mm256_sub_pd(one, s);
  const double (*e)[3][2] = x->xends[k];
  for (int c = 0; c < 3; c++)
    n[c] = _mm256_add_pd(
        _mm256_mul_pd(omv, _mm256_add_pd(_mm256_mul_pd(oms, _mm256_broadcast_sd(e[0][c])),
                                         _mm256_mul_pd(s, _mm256_broadcast_sd(e[1][c])))),
        _mm256_mul_pd(v, _mm256_broadcast_sd(x->xn[c])));
}

/* corner_lanes at four points of one corner band cv (as edge_lanes4). */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void corner_lanes4(const struct smooth_lanes *x, const __m256d *l, int cv, __m256d *n)
{
  const int a = next3[cv], b = prev3[cv];
  const __m256d one = _mm256_set1_pd(1);
  const __m256d u = _mm256_div_pd(l[a], _mm256_broadcast_sd(x->xt[a]));
  const __m256d w = _mm256_div_pd(l[b], _mm256_broadcast_sd(x->xt[b]));
  const __m256d omu = _mm256_sub_pd(one, u), omw = _mm256_sub_pd(one, w);
  const __m256d c0 = _mm256_mul_pd(omu, omw), c1 = _mm256_mul_pd(u, omw),
                c2 = _mm256_mul_pd(omu, w), c3 = _mm256_mul_pd(u, w);
  const double (*e)[3][2] = x->xcends[cv];
  for (int c = 0; c < 3; c++)
    n[c] = _mm256_add_pd(
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(c0, _mm256_broadcast_sd(x->xcn[cv][c])),
                                    _mm256_mul_pd(c1, _mm256_broadcast_sd(e[0][c]))),
                      _mm256_mul_pd(c2, _mm256_broadcast_sd(e[1][c]))),
        _mm256_mul_pd(c3, _mm256_broadcast_sd(x->xn[c])));
}

/* band_lanes at four points q .. q + 3 of sp, all of triangle t: when the four are in the
   same edge band (1) or the same corner band (2) (partial_normal's compares l[k] < t[k],
   lane by lane), their normals into the slots S from *ns on and their region returned;
   else 0, nothing written. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
int band_quad(const struct smooth_model *m, struct split *sp, int q, int t, struct slots *S,
              int *ns)
{
  const struct smooth_lanes *x = &m->lanes[t];
  __m256d l[3], n[3];
  int in[3];
  for (int k = 0; k < 3; k++) {
    l[k] = _mm256_loadu_pd(sp->la[k] + q);
    in[k] = _mm256_movemask_pd(_mm256_cmp_pd(l[k], _mm256_broadcast_sd(x->xt[k]), _CMP_LT_OS));
  }
  const int all = in[0] | in[1] << 4 | in[2] << 8;   /* each lane's below-inset bits */
  int r;
  switch (all) {
  case 0x00f: edge_lanes4(x, l, 0, n); r = 1; break;
  case 0x0f0: edge_lanes4(x, l, 1, n); r = 1; break;
  case 0xf00: edge_lanes4(x, l, 2, n); r = 1; break;
  case 0xff0: corner_lanes4(x, l, 0, n); r = 2; break;
  case 0xf0f: corner_lanes4(x, l, 1, n); r = 2; break;
  case 0x0ff: corner_lanes4(x, l, 2, n); r = 2; break;
  default: return 0;
  }
  const double sgn = m->tri[t].front ? 1 : -1;
  for (int c = 0; c < 3; c++) _mm256_storeu_pd(S->nv[c] + *ns, n[c]);
  for (int h = 0; h < 4; h++) {
    S->sg[*ns] = sgn;
    S->slot_p[(*ns)++] = sp->at[q + h];
  }
  return r;
}

/* partial_normals in the AVX build: four points of one triangle's edge or corner band a
   step where they are (band_quad), else normals_step; the same slots in the same order,
   the same normals (each lane's operations partial_normal's) and regions. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
int partial_normals4(const struct smooth_model *m, const struct mapped *map, struct split *sp,
                     const unsigned *blocked, int *grey, long regions[3], struct slots *S)
{
  int ns = 0;
  for (int q = 0; q < sp->nl;) {
    const int t = sp->tri[q];
    if (q + 4 <= sp->nl && sp->tri[q + 1] == t && sp->tri[q + 2] == t && sp->tri[q + 3] == t) {
      const int r = band_quad(m, sp, q, t, S, &ns);
      if (r) {
        regions[r] += 4;
        q += 4;
        continue;
      }
    }
    q = normals_step(m, map, sp, q, blocked, grey, regions, S, &ns);
  }
  return face_slots(m, sp, S, ns);
}
#endif

/* partial_rows built twice: for SSE2 (the build's target) and for AVX (VEX, chosen at run
   time by rows_avx, as smooth_phong_row's rows are). The AVX build is the same C but for
   the filter's step (partial_split4: inner_split4, four points a step) and the lighting's
   (lit_quads, four slots a step, before lit_row), 256-bit operations whose lanes each
   make the SSE2 build's operations on the same doubles in the same order; the rest the
   same 128-bit operations; each IEEE operation the same whatever its encoding (no fused
   multiply-add: AVX alone, and the build's -ffp-contract=off; no reassociation: no
   -ffast-math), so the same greys and regions bit for bit (test_smooth
   test_row_is_single and test_row_band_pairs run the rows both ways). Round 39: VEX's
   three operands take no register copies, its operands from memory need no alignment,
   and a pair's constant is one load (VMOVDDUP), not two; partial_row's instructions about
   -15% on t1-e (a frame about 1,179 k -> 1,094 k). Round 41, four lanes a step in the
   filter, the band normals and the lighting: partial_row_avx's instructions on t1-e -15%
   (2,488 k -> 2,118 k over 5 frames; the frame 1,047 -> 973 k), t1-a level; the whole
   process's least CPU time over 15 runs in turn about -9 to -14% on t1-c, t1-d, t1-e,
   t1-j, -4% on t1-a. Its first step is held by the divider (six divides a step of four,
   VDIVPD's throughput per instruction the same at 128, 256 and 512 bits on this Zen 5);
   tried and level: the second three divides left out where every lane's sum is 1 (44%
   of t1-e's steps, 77% of the lanes: the branch mispredicts about as often). */
static void partial_row_sse2(const struct smooth_model *m, const struct mapped *map, int nseg,
                             const int *tri, const int *at, const double *xu, const double *xw,
                             const double (*X)[3], const unsigned *blocked,
                             const struct shade_lights *L, int *grey, long regions[3])
{
  struct split sp;
  struct slots S;
  partial_split(m, map, nseg, tri, at, xu, xw, blocked, grey, regions, &sp);
  const int ns = partial_normals(m, map, &sp, blocked, grey, regions, &S);
  if (ns) lit_row(m, 0, ns, S.nv, S.sg, 1.0, S.slot_p, X, blocked, L, grey);
}

#ifdef PHONG_AVX
/* The AVX build's steps, built into partial_row_avx and partial_row_zmm. */
static inline __attribute__((always_inline)) PHONG_AVX_ATTR
void partial_row_vex(const struct smooth_model *m, const struct mapped *map, int nseg,
                     const int *tri, const int *at, const double *xu, const double *xw,
                     const double (*X)[3], const unsigned *blocked,
                     const struct shade_lights *L, int *grey, long regions[3])
{
  struct split sp;
  struct slots S;
  partial_split4(m, map, nseg, tri, at, xu, xw, blocked, grey, regions, &sp);
  const int ns = partial_normals4(m, map, &sp, blocked, grey, regions, &S);
  const int q = lit_quads(m, ns, S.nv, S.sg, S.slot_p, blocked, L, grey);
  if (q < ns) lit_row(m, q, ns, S.nv, S.sg, 1.0, S.slot_p, X, blocked, L, grey);
}

static PHONG_AVX_ATTR void partial_row_avx(const struct smooth_model *m,
                                           const struct mapped *map, int nseg, const int *tri,
                                           const int *at, const double *xu, const double *xw,
                                           const double (*X)[3], const unsigned *blocked,
                                           const struct shade_lights *L, int *grey,
                                           long regions[3])
{
  partial_row_vex(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
}

/* partial_row_vex built for AVX-512F and VL (chosen at run time where the processor has
   them: rows_partial_zmm), the same C: the same 256-bit (and 128-bit and scalar) IEEE
   operations on the same doubles in the same order, so the same greys, regions and
   declines bit for bit (no fused multiply-add: the build's -ffp-contract=off; the
   compares' predicates as they are, into mask registers or vectors alike; test_smooth
   runs the rows both ways: test_row_is_single, test_row_band_pairs,
   test_partial_row_lit_borders). What it gains: EVEX's 32 vector registers (the
   triangle's 15 constants of inner_split4 and the lighting's held in registers, not
   spilled to the stack and read back each step) and the mask registers for the
   compares. Measured (round 42, this Zen 5 host, tools/ab_pairs.sh 15 pairs of 3000
   frames, the whole process, in turn, median pair ratios of three runs): t1-c 0.965 -
   0.988, t1-d 0.976 - 0.979, t1-e 0.965 - 0.991, t1-j 0.967 - 0.988 (one run 1.040, its
   least times 0.953), t1-a 0.989 - 0.998; the phong scenes level. Tried and not kept:
   inner_split4's steps without branches on the filter's answers (the lanes proved inner
   by a masked store, the others packed by VCOMPRESSPD and stored four a store):
   t1-e, t1-j, t1-c about +3% (slower). */
static PHONG_ZMM_ATTR void partial_row_zmm(const struct smooth_model *m,
                                           const struct mapped *map, int nseg, const int *tri,
                                           const int *at, const double *xu, const double *xw,
                                           const double (*X)[3], const unsigned *blocked,
                                           const struct shade_lights *L, int *grey,
                                           long regions[3])
{
  partial_row_vex(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
}
#endif

static void partial_row(const struct smooth_model *m, const struct mapped *map, int nseg,
                        const int *tri, const int *at, const double *xu, const double *xw,
                        const double (*X)[3], const unsigned *blocked,
                        const struct shade_lights *L, int *grey, long regions[3])
{
#ifdef PHONG_AVX
  if (rows_avx(m)) {
    if (rows_partial_zmm(m))
      partial_row_zmm(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
    else
      partial_row_avx(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
    return;
  }
#endif
  partial_row_sse2(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
}

bool smooth_rows(const struct smooth_model *m, const struct effects *e,
                 const struct shade_lights *L)
{
#ifdef __SSE2__
  if (e->smooth == EFFECTS_SMOOTH_FIXED || e->smooth == EFFECTS_SMOOTH_PROP) return true;
  if (e->smooth != EFFECTS_SMOOTH_PHONG || m->phong_exact) return false;
  for (int k = 0; k < L->n; k++)
    if (L->point[k]) return false;
  return true;
#else
  (void)m; (void)e; (void)L;
  return false;
#endif
}

void smooth_row(const struct smooth_model *m, const struct mapped *map,
                const struct effects *e, int nseg, const int *tri, const int *at,
                const double (*X)[3], const unsigned *blocked, const struct shade_lights *L,
                int *grey, long regions[3])
{
  if (e->smooth == EFFECTS_SMOOTH_PHONG) {
    phong_row(m, nseg, tri, at, X, blocked, L, grey);
    regions[1] += at[nseg];
    return;
  }
  double xu[SMOOTH_ROW], xw[SMOOTH_ROW];
  for (int k = 0; k < nseg; k++) {          /* (a triangle's pairs stored as partial_row */
    const struct smooth_tri *tr = &m->tri[tri[k]];   /* reads them: smooth_partial_row) */
    int p = at[k];
#ifdef __SSE2__
    for (; p + 2 <= at[k + 1]; p += 2) {
      _mm_storeu_pd(xu + p, _mm_set_pd(X[p + 1][tr->bu], X[p][tr->bu]));
      _mm_storeu_pd(xw + p, _mm_set_pd(X[p + 1][tr->bw], X[p][tr->bw]));
    }
#endif
    for (; p < at[k + 1]; p++) {
      xu[p] = X[p][tr->bu];
      xw[p] = X[p][tr->bw];
    }
  }
  partial_row(m, map, nseg, tri, at, xu, xw, X, blocked, L, grey, regions);
}

void smooth_partial_row(const struct smooth_model *m, const struct mapped *map, int nseg,
                        const int *tri, const int *at, const double *xu, const double *xw,
                        const unsigned *blocked, const struct shade_lights *L, int *grey,
                        long regions[3])
{
  partial_row(m, map, nseg, tri, at, xu, xw, NULL, blocked, L, grey, regions);
}

int smooth_tables(struct core *core, const struct smooth_model *m, struct cost *cost,
                  struct t74_error *err)
{
  uint32_t an, ab;
  int rc = core_alloc(core, SMOOTH_TABLE_NORMALS, (uint32_t)m->vertex_normals * 3, &an, err);
  if (rc == T74_OK)
    rc = core_alloc(core, SMOOTH_TABLE_BANDS, (uint32_t)m->ntri * 4, &ab, err);
  if (rc != T74_OK) return rc;
  /* the tables themselves: Q1.14 vertex normals as the triangles meet them, the
     triangle's face row and its insets in Q0.16 (not under the points engine, cost NULL) */
  for (int t = 0; cost && t < m->ntri; t++) {
    const struct smooth_tri *tr = &m->tri[t];
    core_write(core, ab + 4 * (uint32_t)t, (uint16_t)(tr->mface + 1));
    for (int k = 0; k < 3; k++) {
      double tk = tr->t[k] * 65535.0;
      core_write(core, ab + 4 * (uint32_t)t + 1 + (uint32_t)k, (uint16_t)(tk > 65535 ? 65535 : tk));
      for (int c = 0; c < 3; c++)
        core_write(core, an + 3 * (uint32_t)tr->ni[k] + (uint32_t)c,
                   (uint16_t)(int16_t)lrint(tr->cn[k][c] * 16384));
    }
    COST_ADD_N(cost, COST_MEM, 4 + 9);
  }
  return T74_OK;
}

int smooth_lanes_pair(const struct smooth_model *m, int t, const double l[2][3], double sgn,
                      const struct shade_lights *L, double n[2][3], int g[2])
{
#ifdef __SSE2__
  __m128d lv[3], nv[3];
  for (int k = 0; k < 3; k++) lv[k] = _mm_set_pd(l[1][k], l[0][k]);
  const int r = band_lanes(&m->lanes[t], lv, nv);
  if (!r) return 0;
  for (int c = 0; c < 3; c++) {
    _mm_storel_pd(&n[0][c], nv[c]);
    _mm_storeh_pd(&n[1][c], nv[c]);
  }
  lit_pair(nv[0], nv[1], nv[2], _mm_set1_pd(sgn), 0, 0, L, L->n, 1.0, g, g + 1);
  return r;
#else
  (void)m; (void)t; (void)l; (void)sgn; (void)L; (void)n; (void)g;
  return 0;
#endif
}

bool smooth_lit_pair(const double v[2][3], double sgn, const struct shade_lights *L, int g[2])
{
#ifdef __SSE2__
  lit_pair(_mm_set_pd(v[1][0], v[0][0]), _mm_set_pd(v[1][1], v[0][1]),
           _mm_set_pd(v[1][2], v[0][2]), _mm_set1_pd(sgn), 0, 0, L, L->n, 1.0, g, g + 1);
  return true;
#else
  (void)v; (void)sgn; (void)L; (void)g;
  return false;
#endif
}

void smooth_lanes_remake(struct smooth_model *m, int t) { tri_lanes(&m->tri[t], &m->lanes[t]); }

void smooth_count(const struct smooth_model *m, struct fx_stats *st)
{
  fx_count(st, "smooth_triangles", m->ntri, true);
  fx_count(st, "smooth_objects", m->objects, true);
  fx_count(st, "smooth_vertex_normals", m->vertex_normals, true);
  fx_count(st, "smooth_orient_flips", m->flips, true);
  fx_count(st, "smooth_orient_conflicts", m->conflicts, true);
}
