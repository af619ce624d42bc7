/*
** model.c — the frame model (see model.h): building it, shading, lines, the point frame.
*/
#include "effects/model.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "effects/contour.h"
#include "effects/shadow.h"
#include "emu/grow.h"
#include "patterns/picture.h"
#include "render/face_run.h"
#include "render/shade.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
/* a row's smoothed space points eight an instruction where the processor has AVX-512 (a
   run-time test, uv_avx512; the build itself assumes SSE2 at most) */
#if defined(__SSE2__) && (defined(__x86_64__) || defined(__i386__)) && \
    (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define UV_AVX512 1
#endif
#if defined(__SSE2__) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FLAT_AVX512 1             /* flat_rowt8 built, taken where the processor has it */
#endif

/* A texture: the picture and its frame on the face (V0 + a U + b T, a, b in [0, 1) over
   the picture; repeated beyond). */
struct fx_tex {
  struct pic *pic;
  double o[3], U[3], T[3];
  int du, dv;               /* the coordinate plane the face is solved on */
  double det;
  int w, h;                 /* the picture's size */
  const uint8_t *px;        /* its pixels (pic_rows) */
};

/* ---- building ---------------------------------------------------------------------- */

static int by_owner(const void *pa, const void *pb)
{
  const struct fx_poly *a = pa, *b = pb;
  if (a->owner != b->owner) return a->owner < b->owner ? -1 : 1;
  return (a->light > b->light) - (a->light < b->light);
}

/* A scene's textures kept between frames (effects/see.h, fx_engine's tex_keep): they
   depend on the scene alone, so a later frame of the same scene takes them as they are
   instead of reading the pictures again. */
struct fx_textures {
  const struct scene *s;
  struct fx_tex *tex;
  int ntex;
};

/* A table of textures, one entry a scene face (NULL: none). */
static void tex_free(struct fx_tex *tex, int nf)
{
  for (int k = 0; tex && k < nf; k++) pic_free(tex[k].pic);
  free(tex);
}

void fx_textures_free(struct fx_textures *t)
{
  if (!t) return;
  tex_free(t->tex, t->s->nf);
  free(t);
}

static int load_textures(struct fx_model *m, struct fx_stats *st, struct cost *cost,
                         struct t74_error *err)
{
  const struct scene *s = m->s;
  struct fx_textures **keep = m->eng->tex_keep;
  if (keep && *keep && (*keep)->s == s) {   /* read by an earlier frame: its charges */
    m->tex = (*keep)->tex;
    m->ntex = (*keep)->ntex;
    m->tex_kept = true;
    COST_ADD_N(cost, COST_MEM, 9 * (uint64_t)m->ntex);
    if (m->ntex) fx_count(st, "texture_faces", m->ntex, true);
    return T74_OK;
  }
  for (int k = 0; k < s->nf; k++) {
    const struct scene_face *f = &s->f[k];
    if (!f->texture) continue;
    if (!m->tex && !(m->tex = calloc((size_t)s->nf, sizeof *m->tex)))
      return t74_fail(err, T74_EIO, "out of host memory");
    struct fx_tex *t = &m->tex[k];
    struct t74_error e2;
    memset(&e2, 0, sizeof e2);
    int rc = pic_load(f->texture, &t->pic, &e2);
    if (rc != T74_OK)
      return t74_fail_at(err, rc, s->file, f->texture_line, "texture: %s", e2.msg);
    t->w = pic_width(t->pic);
    t->h = pic_height(t->pic);
    t->px = pic_rows(t->pic);
    int n = f->ring_start[1];
    const struct scene_vertex *a = &s->v[f->vidx[0]], *b = &s->v[f->vidx[1]], *c = &s->v[f->vidx[n - 1]];
    double A[3] = { a->x, a->y, a->z }, B[3] = { b->x, b->y, b->z }, C[3] = { c->x, c->y, c->z };
    for (int q = 0; q < 3; q++) { t->o[q] = A[q]; t->U[q] = B[q] - A[q]; t->T[q] = C[q] - A[q]; }
    double nr[3] = { t->U[1] * t->T[2] - t->U[2] * t->T[1], t->U[2] * t->T[0] - t->U[0] * t->T[2],
                     t->U[0] * t->T[1] - t->U[1] * t->T[0] };
    int ax = 0;
    for (int q = 1; q < 3; q++) if (fabs(nr[q]) > fabs(nr[ax])) ax = q;
    t->du = (ax + 1) % 3;
    t->dv = (ax + 2) % 3;
    t->det = t->U[t->du] * t->T[t->dv] - t->U[t->dv] * t->T[t->du];
    if (t->det == 0)
      return t74_fail_at(err, T74_EINPUT, s->file, f->texture_line, "texture: face %d's first, "
                         "second and last vertices are in a line: no frame for the picture", f->id);
    m->ntex++;
    COST_ADD_N(cost, COST_MEM, 9);
  }
  if (m->ntex) fx_count(st, "texture_faces", m->ntex, true);
  if (keep && m->tex) {                     /* the caller keeps them for the next frame */
    struct fx_textures *t = malloc(sizeof *t);
    if (!t) return t74_fail(err, T74_EIO, "out of host memory");
    fx_textures_free(*keep);
    t->s = s; t->tex = m->tex; t->ntex = m->ntex;
    *keep = t;
    m->tex_kept = true;
  }
  return T74_OK;
}

/* What the shading of every point shares, made once a frame: the lights, the eye and
   each face's ray set-up (space_point). */
static int shade_setup(struct fx_model *m, struct t74_error *err)
{
  const struct mapped *map = m->map;
  shade_lights_init(&m->lights, m->s);
  for (int c = 0; c < 3; c++) m->eye[c] = (double)map->eye[c];
  const double *E = m->eye;
  m->ray = malloc(((size_t)map->nface + 1) * sizeof *m->ray);
  if (!m->ray) return t74_fail(err, T74_EIO, "out of host memory");
  for (int f = 0; f < map->nface; f++) {
    const int64_t *pl = map->f[f].plane;
    double *r = m->ray[f];
    for (int c = 0; c < 3; c++) r[c] = (double)pl[c];
    r[3] = -((double)pl[0] * E[0] + (double)pl[1] * E[1] + (double)pl[2] * E[2] + (double)pl[3]);
  }
  return T74_OK;
}

int fx_model_build(struct fx_model *m, const struct fx_engine *eng, const struct scene *s,
                   const struct effects *e, const uint8_t *bg,
                   struct fx_stats *st, struct cost *cost, struct t74_error *err)
{
  memset(m, 0, sizeof *m);
  const struct mapped *map = eng->map;
  const struct vis_grid *g = eng->g;
  m->eng = eng; m->map = map; m->s = s; m->e = e; m->g = g; m->bg = bg;
  m->count = eng->r != NULL;
  struct cost *counted = m->count ? cost : NULL;   /* the machine's work: the 1974 engine's */
  m->W = g->W; m->H = g->H;
  int rc = T74_OK;
  if (e->smooth != EFFECTS_SMOOTH_NONE || e->contour_on) {
    if ((rc = smooth_model_build_kept(&m->sm, map, s, e, eng->smooth_keep, err)) != T74_OK)
      return rc;
    m->smooth = true;
    if (m->sm.ntri == 0)
      fprintf(stderr, "%s:%d: warning: smooth=/contour=: no face is a triangle of an object "
              "shaded from `light`; the picture stays flat\n", s->file ? s->file : "scene",
              s->effects_line);
    if ((rc = smooth_tables(eng->core, &m->sm, counted, err)) != T74_OK) return rc;
    smooth_count(&m->sm, st);
  }
  if (e->contour_on && m->smooth) {
    rc = contour_build(map, eng->core, s, e, &m->sm, &m->cuts, &m->corners, st, counted, err);
    if (rc != T74_OK) return rc;
    for (int k = 0; k < m->cuts.n; k++) {
      int o = m->cuts.p[k].owner, seen = 0;
      for (int q = 0; q < m->ncut; q++) seen |= m->cut_obj[q] == o;
      if (seen) continue;
      int *no = realloc(m->cut_obj, (size_t)(m->ncut + 1) * sizeof *no);
      uint8_t **ns = no ? realloc(m->cut_skip, (size_t)(m->ncut + 1) * sizeof *ns) : NULL;
      if (no) m->cut_obj = no;
      if (ns) m->cut_skip = ns;
      uint8_t *sk = ns ? calloc((size_t)map->nface + 1, 1) : NULL;
      if (!sk) return t74_fail(err, T74_EIO, "out of host memory");
      for (int f = 0; f < map->nface; f++) sk[f] = s->f[map->f[f].sface].object == o;
      m->cut_obj[m->ncut] = o;
      m->cut_skip[m->ncut++] = sk;
    }
  }
  if (e->shadows && s->has_light) {
    if ((rc = shadow_build(map, s, eng->shadow_keep, &m->shadows, st, counted, err)) != T74_OK) return rc;
    /* by owner and light: shadow_build gives them so (face by face, light by light), and
       they are left as they come, ties in shadow_build's order (glibc's qsort, a merge
       sort, leaves an ordered array as it is too; none cast: p may be NULL, which qsort
       may not take) */
    bool sorted = true;
    for (int k = 1; k < m->shadows.n && sorted; k++)
      sorted = by_owner(&m->shadows.p[k - 1], &m->shadows.p[k]) <= 0;
    if (!sorted) qsort(m->shadows.p, (size_t)m->shadows.n, sizeof *m->shadows.p, by_owner);
    m->shadow_first = calloc((size_t)map->nface + 1, sizeof *m->shadow_first);
    if (!m->shadow_first) return t74_fail(err, T74_EIO, "out of host memory");
    for (int f = 0, k = 0; f <= map->nface; f++) {
      while (k < m->shadows.n && m->shadows.p[k].owner < f) k++;
      m->shadow_first[f] = k;
    }
  }
  if ((rc = load_textures(m, st, cost, err)) != T74_OK) return rc;
  return fx_model_shades(m) ? shade_setup(m, err) : T74_OK;
}

void fx_model_free(struct fx_model *m)
{
  if (m->smooth) smooth_model_free(&m->sm);
  if (m->tex && !m->tex_kept) tex_free(m->tex, m->s->nf);   /* else the caller's (tex_keep) */
  fx_polys_free(&m->cuts);
  contour_corners_free(&m->corners);
  fx_polys_free(&m->shadows);
  for (int q = 0; q < m->ncut; q++) free(m->cut_skip[q]);
  free(m->cut_skip);
  free(m->cut_obj);
  free(m->shadow_first);
  free(m->ray);
  memset(m, 0, sizeof *m);
}

bool fx_model_regions(const struct fx_model *m) { return m->cuts.n > 0 || m->shadows.n > 0; }

bool fx_model_shades(const struct fx_model *m)
{
  return (m->smooth && m->e->smooth != EFFECTS_SMOOTH_NONE) || m->ntex > 0 || m->shadows.n > 0;
}

/* ---- shading ----------------------------------------------------------------------- */

/* The space point of face f seen through plane position (px, py, 0): the ray from the eye
   onto the face's exact plane (eq. (2)). */
static inline void space_point(const struct fx_model *m, int f, double px, double py, double X[3])
{
  const double *E = m->eye, *r = m->ray[f];
  const double E0 = E[0], E1 = E[1], E2 = E[2];   /* held: a store to X might be to E */
  double D[3] = { px - E0, py - E1, -E2 };
  double den = r[0] * D[0] + r[1] * D[1] + r[2] * D[2];
  double t = den != 0 ? r[3] / den : 1;
  X[0] = E0 + t * D[0];
  X[1] = E1 + t * D[1];
  X[2] = E2 + t * D[2];
}

#ifdef __SSE2__
/* A row's space_point in two lanes: its constants (space_lanes_init: the eye, face f's ray
   r, D1 = py - E1, D2 = -E2 and the products r[1] D1, r[2] D2, each the one double
   space_point makes for the row), then two points' space positions (space_lanes_at). */
struct space_lanes {
  __m128d e0, e1, e2, r0, r3, c1, c2, d1, d2;
};

static inline void space_lanes_init(const struct fx_model *m, int f, double py,
                                    struct space_lanes *L)
{
  const double *E = m->eye, *r = m->ray[f];
  const double E0 = E[0], E1 = E[1], E2 = E[2];
  const double D1 = py - E1, D2 = -E2;
  L->e0 = _mm_set1_pd(E0); L->e1 = _mm_set1_pd(E1); L->e2 = _mm_set1_pd(E2);
  L->r0 = _mm_set1_pd(r[0]); L->r3 = _mm_set1_pd(r[3]);
  L->c1 = _mm_set1_pd(r[1] * D1); L->c2 = _mm_set1_pd(r[2] * D2);
  L->d1 = _mm_set1_pd(D1); L->d2 = _mm_set1_pd(D2);
}

/* L's face constants for two faces of its row, lane 0 face fa's and lane 1 face fb's (fb
   may be fa): r[0], r[3], and r[1] D1 and r[2] D2 as the products space_lanes_init makes,
   lane by lane. */
static inline void space_lanes_faces(const struct fx_model *m, int fa, int fb,
                                     struct space_lanes *L)
{
  const double *r = m->ray[fa], *rb = m->ray[fb];
  L->r0 = _mm_set_pd(rb[0], r[0]);
  L->r3 = _mm_set_pd(rb[3], r[3]);
  L->c1 = _mm_mul_pd(_mm_set_pd(rb[1], r[1]), L->d1);
  L->c2 = _mm_mul_pd(_mm_set_pd(rb[2], r[2]), L->d2);
}

/* The ray's denominator at two points, d0 their plane positions less E0: r[0] d0 + r[1] D1
   + r[2] D2, space_point's operations in its order. */
static inline __m128d space_lanes_den(const struct space_lanes *L, __m128d d0)
{
  return _mm_add_pd(_mm_add_pd(_mm_mul_pd(L->r0, d0), L->c1), L->c2);
}

/* The space positions X[0..2] (x, y, z lanes) of the row's points px2 (two x's). */
static inline void space_lanes_at(const struct space_lanes *L, __m128d px2, __m128d X[3])
{
  const __m128d d0 = _mm_sub_pd(px2, L->e0);
  const __m128d den = space_lanes_den(L, d0);
  const __m128d nz = _mm_cmpneq_pd(den, _mm_setzero_pd());   /* den != 0 ? r[3] / den : 1 */
  const __m128d t = _mm_or_pd(_mm_and_pd(nz, _mm_div_pd(L->r3, den)),
                              _mm_andnot_pd(nz, _mm_set1_pd(1)));
  X[0] = _mm_add_pd(L->e0, _mm_mul_pd(t, d0));
  X[1] = _mm_add_pd(L->e1, _mm_mul_pd(t, L->d1));
  X[2] = _mm_add_pd(L->e2, _mm_mul_pd(t, L->d2));
}
#endif

/* space_point at n points (px[p], py) of one row into X[p]: the same doubles, two points
   an instruction where the processor has SSE2 (its adds, multiplies and divides are
   correctly rounded, as the scalar ones are: each lane's operations are space_point's on
   its values, in its order; r[1] D[1] and r[2] D[2], the same for every point of the row,
   are each the one double space_point makes), the rest one by one. */
static inline void space_points(const struct fx_model *m, int f, int n, const double *px,
                                double py, double (*X)[3])
{
  int p = 0;
#ifdef __SSE2__
  struct space_lanes L;
  space_lanes_init(m, f, py, &L);
  for (; p + 2 <= n; p += 2) {
    __m128d x[3];
    space_lanes_at(&L, _mm_loadu_pd(px + p), x);
    _mm_storel_pd(&X[p][0], x[0]); _mm_storeh_pd(&X[p + 1][0], x[0]);
    _mm_storel_pd(&X[p][1], x[1]); _mm_storeh_pd(&X[p + 1][1], x[1]);
    _mm_storel_pd(&X[p][2], x[2]); _mm_storeh_pd(&X[p + 1][2], x[2]);
  }
#endif
  for (; p < n; p++) space_point(m, f, px[p], py, X[p]);
}

void fx_space_points(const struct fx_model *m, int f, int n, const double *px, double py,
                     double (*X)[3])
{
  space_points(m, f, n, px, py, X);
}

/* The picture's pixel at the face's coordinates (a, b) (reflectance's last step). */
static inline int tex_pixel(const struct fx_tex *t, double a, double b)
{
  a -= floor(a);
  b -= floor(b);
  const int w = t->w, h = t->h;
  int x = (int)(a * w), y = (int)((1 - b) * h);
  if (x >= w) x = w - 1;
  if (y >= h) y = h - 1;
  if (y < 0) y = 0;
  /* pic_pixel's answer, without the call (y and x's top are in the picture by now) */
  if (x < 0) return -1;
  return t->px[(size_t)y * (size_t)w + (size_t)x];
}

static inline double reflectance(const struct fx_tex *t, const double X[3], struct cost *cost)
{
  double du = X[t->du] - t->o[t->du], dv = X[t->dv] - t->o[t->dv];
  double a = (du * t->T[t->dv] - dv * t->T[t->du]) / t->det;
  double b = (t->U[t->du] * dv - t->U[t->dv] * du) / t->det;
  if (cost) {
    for (int k = 0; k < 4; k++) cost_mw_mul(cost, 32, 16);
    cost_mw_div(cost, 32, 16); cost_mw_div(cost, 32, 16);
    COST_ADD_N(cost, COST_MEM, 2);
  }
  return tex_pixel(t, a, b) / 255.0;
}

/* k / 255.0 for the pixels k = -1 .. 255 (pic_pixel's answers), at index k + 1: the
   doubles reflectance divides out (an initialiser is worked out at translation time as
   at execution time, C11 F.8.2 and F.8.5: the same correctly rounded quotients). */
#define UNIT1(k) (k) / 255.0
#define UNIT4(k) UNIT1(k), UNIT1((k) + 1), UNIT1((k) + 2), UNIT1((k) + 3)
#define UNIT16(k) UNIT4(k), UNIT4((k) + 4), UNIT4((k) + 8), UNIT4((k) + 12)
#define UNIT64(k) UNIT16(k), UNIT16((k) + 16), UNIT16((k) + 32), UNIT16((k) + 48)
static const double unit_pixel[257] = { UNIT1(-1), UNIT64(0), UNIT64(64), UNIT64(128), UNIT64(192) };

/* reflectance, uncounted, at n <= SHADE_RUN points X[p] of a textured face into r[p]: the
   same doubles, its two divides two points an instruction where the processor has SSE2
   (correctly rounded, as the scalar ones are; each lane's operations are reflectance's on
   its values, in its order) and the pixel's k / 255.0 from unit_pixel. */
static void reflectances(const struct fx_tex *t, int n, const double (*X)[3], double *r)
{
  const int du = t->du, dv = t->dv;
  double a[SHADE_RUN], b[SHADE_RUN];
  int p = 0;
#ifdef __SSE2__
  const __m128d odu = _mm_set1_pd(t->o[du]), odv = _mm_set1_pd(t->o[dv]);
  const __m128d Tdv = _mm_set1_pd(t->T[dv]), Tdu = _mm_set1_pd(t->T[du]);
  const __m128d Udu = _mm_set1_pd(t->U[du]), Udv = _mm_set1_pd(t->U[dv]);
  const __m128d det = _mm_set1_pd(t->det);
  for (; p + 2 <= n; p += 2) {
    const __m128d u = _mm_sub_pd(_mm_set_pd(X[p + 1][du], X[p][du]), odu);
    const __m128d v = _mm_sub_pd(_mm_set_pd(X[p + 1][dv], X[p][dv]), odv);
    _mm_storeu_pd(a + p, _mm_div_pd(_mm_sub_pd(_mm_mul_pd(u, Tdv), _mm_mul_pd(v, Tdu)), det));
    _mm_storeu_pd(b + p, _mm_div_pd(_mm_sub_pd(_mm_mul_pd(Udu, v), _mm_mul_pd(Udv, u)), det));
  }
#endif
  for (; p < n; p++) {
    const double u = X[p][du] - t->o[du], v = X[p][dv] - t->o[dv];
    a[p] = (u * t->T[dv] - v * t->T[du]) / t->det;
    b[p] = (t->U[du] * v - t->U[dv] * u) / t->det;
  }
  for (p = 0; p < n; p++) r[p] = unit_pixel[tex_pixel(t, a[p], b[p]) + 1];
}

#ifdef __SSE2__
/* floor(a) lane by lane where |a| < 2^30, as the truncation less 1 where it lies above a
   would give it (and so at a = -0 +0, where floor gives -0: a less either is a zero, which
   tex_pair's multiply and truncation make 0 alike), in five operations: r = (a + M) - M
   with M = 1.5 2^52 is a rounded to the nearest integer (a + M lies in [2^52, 2^53), where
   the doubles are the integers: the add rounds it to the one nearest a + M, ties to even,
   as the program never leaves round to nearest; taking M off again is exact; a zero r is
   +0), which is within 1/2 of a; so floor(a) is r where r is at or below a, else r - 1. */
static inline __m128d floor_pair(__m128d a)
{
  const __m128d M = _mm_set1_pd(0x1.8p52);
  const __m128d r = _mm_sub_pd(_mm_add_pd(a, M), M);
  return _mm_sub_pd(r, _mm_and_pd(_mm_cmpgt_pd(r, a), _mm_set1_pd(1)));
}

/* tex_pair's values of texture t, made once for a run of its face's points: each double
   broadcast to both lanes (the same doubles), the picture's tops as four lanes. */
struct tex_lanes {
  const struct fx_tex *t;
  int du, dv, w;
  const uint8_t *px;
  __m128d odu, odv, Tdv, Tdu, Udu, Udv, det, wd, hd;
  __m128d wtop, htop;       /* w - 1, h - 1 */
  __m128i wv;               /* w in the low 32 bits of each 64-bit half */
};

static inline void tex_lanes_init(struct tex_lanes *T, const struct fx_tex *t)
{
  const int du = t->du, dv = t->dv;
  T->t = t;
  T->du = du; T->dv = dv; T->w = t->w;
  T->px = t->px;
  T->odu = _mm_set1_pd(t->o[du]); T->odv = _mm_set1_pd(t->o[dv]);
  T->Tdv = _mm_set1_pd(t->T[dv]); T->Tdu = _mm_set1_pd(t->T[du]);
  T->Udu = _mm_set1_pd(t->U[du]); T->Udv = _mm_set1_pd(t->U[dv]);
  T->det = _mm_set1_pd(t->det);
  T->wd = _mm_set1_pd(t->w); T->hd = _mm_set1_pd(t->h);
  T->wtop = _mm_set1_pd(t->w - 1); T->htop = _mm_set1_pd(t->h - 1);
  T->wv = _mm_set_epi32(0, t->w, 0, t->w);
}

/* reflectance, uncounted, at two space points X (lane 0, lane 1) of a textured face (T:
   tex_lanes_init's for its texture): the same doubles, lane by lane. a and b are
   reflectance's (each lane's operations its, in its order, correctly rounded as the scalar
   ones are). Where every |a|, |b| < 2^30 (no NaN) tex_pixel's steps two at a time:
   floor_pair is floor there, so a - floor(a) is in [0, 1] (a at or above its floor, and
   rounding keeps a difference at or above 0; at most 1 as a - floor(a) < 1),
   x = (int)(a w) in [0, w] and y = (int)((1 - b) h) in [0, h]: tex_pixel's tests y < 0 and
   x < 0 never hold, and the two tops are taken before the truncations; the pixel's
   k / 255.0 from unit_pixel. Else tex_pixel lane by lane. */
static inline __m128d tex_pair(const struct tex_lanes *T, const __m128d X[3])
{
  const __m128d u = _mm_sub_pd(X[T->du], T->odu);
  const __m128d v = _mm_sub_pd(X[T->dv], T->odv);
  __m128d a = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(u, T->Tdv), _mm_mul_pd(v, T->Tdu)), T->det);
  __m128d b = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(T->Udu, v), _mm_mul_pd(T->Udv, u)), T->det);
  const __m128d mag = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)), lim = _mm_set1_pd(0x1p30);
  if (_mm_movemask_pd(_mm_and_pd(_mm_cmplt_pd(_mm_and_pd(a, mag), lim),
                                 _mm_cmplt_pd(_mm_and_pd(b, mag), lim))) != 3) {
    double aa[2], bb[2];
    _mm_storeu_pd(aa, a);
    _mm_storeu_pd(bb, b);
    return _mm_set_pd(unit_pixel[tex_pixel(T->t, aa[1], bb[1]) + 1],
                      unit_pixel[tex_pixel(T->t, aa[0], bb[0]) + 1]);
  }
  a = _mm_sub_pd(a, floor_pair(a));
  b = _mm_sub_pd(b, floor_pair(b));
  /* the tops before the truncations: a w and (1 - b) h are at or above 0, where the
     truncation of min(v, top) is min(truncation of v, top) (top an integer) */
  const __m128i x = _mm_cvttpd_epi32(_mm_min_pd(_mm_mul_pd(a, T->wd), T->wtop));
  const __m128i y = _mm_cvttpd_epi32(_mm_min_pd(_mm_mul_pd(_mm_sub_pd(_mm_set1_pd(1), b), T->hd),
                                                T->htop));
  const __m128i xy = _mm_unpacklo_epi64(x, y);   /* x0, x1, y0, y1 */
  /* the pixels' indices y w + x, both lanes' at once: x and y in [0, 2^31), so y w (below
     2^62) is the unsigned 32 by 32 bit product, and the sum the 64-bit one */
  const __m128i yw = _mm_mul_epu32(_mm_shuffle_epi32(xy, _MM_SHUFFLE(3, 3, 2, 2)), T->wv);
  const __m128i at = _mm_add_epi64(yw, _mm_unpacklo_epi32(xy, _mm_setzero_si128()));
#if defined(__x86_64__)
  const size_t i0 = (size_t)_mm_cvtsi128_si64(at);
  const size_t i1 = (size_t)_mm_cvtsi128_si64(_mm_unpackhi_epi64(at, at));
#else                                       /* (no 64-bit moves from a vector) */
  uint64_t a64[2];
  _mm_storeu_si128((__m128i *)(void *)a64, at);
  const size_t i0 = (size_t)a64[0], i1 = (size_t)a64[1];
#endif
  return _mm_set_pd(unit_pixel[T->px[i1] + 1], unit_pixel[T->px[i0] + 1]);
}

/* The blocked-mask bits of P's point lights (flat_lit_pairs, flat_lit_masked). */
static inline unsigned point_bits(const struct shade_pair *P)
{
  unsigned pm = 0;
  for (int k = 0; k < P->n; k++) if (P->l[k].point) pm |= 1u << k;
  return pm;
}

/* A row of face f where space_point's t is the same at every point: where the face's ray
   has r[0] = 0 (its plane has no x term: a face square to the y or the z axis, or slanted
   about the x axis only). space_point's den is (r[0] D0 + r[1] D1) + r[2] D2 with D0 =
   px - E0 the only term that changes along the row. px is finite (plane_x's: the window's
   whole numbers and a point's u in [0, W]) and so is E0 (the Mapper's eye, whole numbers),
   so D0 is finite and r[0] D0 is a zero (+0 or -0). Then, with c1 = r[1] D1 and c2 =
   r[2] D2 (space_lanes_init's):
   - c1 not a zero: z + c1 is c1 for either zero z (also where c1 is infinite or NaN: a NaN
     operand is passed on as it is), so den = c1 + c2 at every point;
   - c1 a zero: z + c1 is a zero, and a zero plus c2 is c2 where c2 is not a zero, and a
     zero where it is.
   So den is the same double at every point of the row where it is not a zero, and a zero
   at every point where it is (only its sign may differ), where t is 1: t = den != 0 ?
   r[3] / den : 1 is the same double at every point, row_lanes_init's (den made at D0 =
   +0).
   The space point's X[1] = E1 + t D1 and X[2] = E2 + t D2 are then the same at every
   point of the row too, and only X[0] = E0 + t D0 changes: space_lanes_at's operations
   on the same values, in its order. */
struct row_lanes {
  __m128d t, x1, x2;        /* t, X[1], X[2]: the row's, in both lanes */
};

static inline bool row_t_fixed(const struct fx_model *m, int face)
{
  return m->ray[face][0] == 0;
}

static inline void row_lanes_init(const struct space_lanes *L, struct row_lanes *R)
{
  const __m128d zero = _mm_setzero_pd();
  const __m128d den = _mm_add_pd(_mm_add_pd(_mm_mul_pd(L->r0, zero), L->c1), L->c2);
  const __m128d nz = _mm_cmpneq_pd(den, zero);
  R->t = _mm_or_pd(_mm_and_pd(nz, _mm_div_pd(L->r3, den)), _mm_andnot_pd(nz, _mm_set1_pd(1)));
  R->x1 = _mm_add_pd(L->e1, _mm_mul_pd(R->t, L->d1));
  R->x2 = _mm_add_pd(L->e2, _mm_mul_pd(R->t, L->d2));
}

/* A row of a flat face made ready for flat_lit_pairs, once for all its calls on the row:
   space_lanes_init's lanes, and where the row's t is fixed (row_t_fixed), row_lanes_init's. */
struct flat_row {
  struct space_lanes L;
  struct row_lanes R;
  bool rowt;
};

static inline void flat_row_init(const struct fx_model *m, int face, double py, struct flat_row *F)
{
  space_lanes_init(m, face, py, &F->L);
  F->rowt = row_t_fixed(m, face);
  if (F->rowt) row_lanes_init(&F->L, &F->R);
}

/* shade_pair_dot_axis of point light l on such a row (R: row_lanes_init's; the face's
   axis c is 1 or 2, nc its normal's coordinate) at the two points whose X[0] is x0: the
   same operations on the same values in the same order, the row's terms made once (K:
   row_light_init's): ly = l1 - X[1] and lz = l2 - X[2], their squares, and lc - X[c],
   which is ly or lz. */
struct row_light {
  __m128d l0, yy, zz, num;  /* l's x; ly ly, lz lz; lc - X[c] */
};

static inline void row_light_init(const struct shade_pair_light *l, const struct row_lanes *R,
                                  int c, struct row_light *K)
{
  const __m128d ly = _mm_sub_pd(l->v[1], R->x1), lz = _mm_sub_pd(l->v[2], R->x2);
  K->l0 = l->v[0];
  K->yy = _mm_mul_pd(ly, ly);
  K->zz = _mm_mul_pd(lz, lz);
  K->num = c == 1 ? ly : lz;
}

static inline __m128d row_dot_axis(const struct row_light *K, __m128d nc, __m128d x0)
{
  const __m128d zero = _mm_setzero_pd();
  const __m128d lx = _mm_sub_pd(K->l0, x0);
  const __m128d s = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(lx, lx), K->yy), K->zz));
  const __m128d keep = _mm_cmpneq_pd(s, zero);
  const __m128d div = _mm_or_pd(_mm_and_pd(keep, s), _mm_andnot_pd(keep, _mm_set1_pd(1)));
  const __m128d d = _mm_mul_pd(nc, _mm_div_pd(K->num, div));
  return _mm_and_pd(_mm_cmpgt_pd(d, zero), d);
}

/* tex_pair on such a row where the texture is solved on x and one of y, z (du = 0: only
   u = X[0] - o[0] changes along the row; v = X[dv] - o[dv] is the row's) and its frame's U
   has no dv term (U[dv] = 0: a picture's rows along the x axis), made once for the row
   (row_tex_init; ok false where this does not hold or the row's b is off |b| < 2^30).
   tex_pair's a = (u T[dv] - v T[du]) / det, v T[du] the row's product; its b = (U[du] v -
   U[dv] u) / det: where a lane's a is finite, so is its u (an infinite u makes u T[dv]
   infinite or NaN: NaN where T[dv] is 0; and so a infinite or NaN; a NaN u makes a NaN),
   so U[dv] u is a zero and U[du] v less it is U[du] v where that is not a zero, a zero
   where it is: b is the row's b0 (made at u = +0) or a zero where b0 is a zero. The
   picture's row y = (int)((1 - (b - floor b)) h), topped at h - 1, comes from b alone,
   and is the same for +0 and -0 (b - floor(b) is +0 for +0 and -0 for -0 by floor_pair's
   steps, 1 less either is 1): the row's y w is made once (tex_pair's steps on b0). The
   fast path is taken where both lanes' |a| < 2^30 (then a is finite: the above holds) and
   the row's |b0| < 2^30, tex_pair's condition; else tex_pair itself, on the space point
   as space_lanes_at makes it. */
struct row_tex {
  bool ok;
  __m128d vTdu;             /* v T[du] */
  __m128i yw;               /* the pixels' row start y w, in each 64-bit half */
};

static inline void row_tex_init(const struct tex_lanes *T, const struct row_lanes *R,
                                struct row_tex *Q)
{
  Q->ok = false;
  Q->vTdu = _mm_setzero_pd();               /* (read only where ok) */
  Q->yw = _mm_setzero_si128();
  if (T->du != 0 || T->t->U[T->dv] != 0) return;
  const __m128d v = _mm_sub_pd(T->dv == 1 ? R->x1 : R->x2, T->odv);
  const __m128d u0 = _mm_setzero_pd();
  const __m128d b = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(T->Udu, v), _mm_mul_pd(T->Udv, u0)), T->det);
  const __m128d mag = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)), lim = _mm_set1_pd(0x1p30);
  if (!(_mm_movemask_pd(_mm_cmplt_pd(_mm_and_pd(b, mag), lim)) & 1)) return;
  const __m128d f = _mm_sub_pd(b, floor_pair(b));
  const __m128i y = _mm_cvttpd_epi32(_mm_min_pd(_mm_mul_pd(_mm_sub_pd(_mm_set1_pd(1), f), T->hd),
                                                T->htop));
  Q->yw = _mm_mul_epu32(_mm_shuffle_epi32(y, _MM_SHUFFLE(0, 0, 0, 0)), T->wv);
  Q->vTdu = _mm_mul_pd(v, T->Tdu);
  Q->ok = true;
}

static inline __m128d row_tex_pair(const struct tex_lanes *T, const struct row_tex *Q,
                                   const struct row_lanes *R, __m128d x0)
{
  const __m128d u = _mm_sub_pd(x0, T->odu);
  __m128d a = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(u, T->Tdv), Q->vTdu), T->det);
  const __m128d mag = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)), lim = _mm_set1_pd(0x1p30);
  if (_mm_movemask_pd(_mm_cmplt_pd(_mm_and_pd(a, mag), lim)) != 3) {
    const __m128d X[3] = { x0, R->x1, R->x2 };
    return tex_pair(T, X);
  }
  a = _mm_sub_pd(a, floor_pair(a));
  const __m128i x = _mm_cvttpd_epi32(_mm_min_pd(_mm_mul_pd(a, T->wd), T->wtop));
  /* y w + x, both lanes: x in [0, 2^31) */
  const __m128i at = _mm_add_epi64(Q->yw, _mm_unpacklo_epi32(x, _mm_setzero_si128()));
#if defined(__x86_64__)
  const size_t i0 = (size_t)_mm_cvtsi128_si64(at);
  const size_t i1 = (size_t)_mm_cvtsi128_si64(_mm_unpackhi_epi64(at, at));
#else
  uint64_t a64[2];
  _mm_storeu_si128((__m128i *)(void *)a64, at);
  const size_t i0 = (size_t)a64[0], i1 = (size_t)a64[1];
#endif
  return _mm_set_pd(unit_pixel[T->px[i1] + 1], unit_pixel[T->px[i0] + 1]);
}

/* shade_face_at, uncounted, at the n points px[0 .. n) of a row (py) on a lit face that is
   not smoothed, T its texture's tex_lanes or NULL (P: shade_pair_init's for the face's unit
   normal, face_normal's), two points a pair of lanes: points p and p + 1 (an odd last point
   in both lanes); each lane's space point is space_point's (space_lanes_at), its
   reflectance reflectance's (tex_pair) or 1, its grey shade_grey_lit's (shade_pair_greys of
   shade_pair_sum's sums). The lights blocked at point p are blocked[p], or b at every point
   where blocked is NULL.
   The work goes in stages over up to LIT_PAIRS pairs at a time: every pair's space point,
   then every pair's reflectance, then light by light (the scene's order) every pair's term
   added to its sum, then every pair's grey. One pair from space point to grey is a long
   chain (a divide, a square root and divides on it, the texture's divides, its pixel's
   two loads, the grey); a stage's pairs do not wait on each other, so the processor has
   many of them under way at once (perf on fig6-room: the flat_ functions' share of the
   frame 51% -> 44%). Each lane's operations are those of a pair alone, on the same
   values, in the same order: its sum starts at +0 and adds the lights' terms in the
   scene's order. A light blocked at both lanes of a pair adds +0 there in shade_pair_sum
   (the AND of an all-zero mask), which leaves the sum as it is (a sum is +0 or positive:
   each term is +0 or a positive n.l, never -0 or NaN), so its term is not made: with
   blocked NULL such a light is passed over for the whole run; with blocked[] a point
   light's terms are made at the pairs where it is not blocked at both lanes only (a list
   of them, made without a branch a pair). Where a lane's light is not blocked the mask is
   all ones and the AND gives the term as shade_pair_sum's sum of unblocked lights adds
   it. (Without blocked[] where the kept sums of the one-pair loop were used, at pairs
   with every point light blocked at both lanes, the sums come out the same: a parallel
   light's term does not depend on the point.)
   F is the row's (flat_row_init). With rowt (F->rowt, a constant where it is inlined, so
   that each way is its own code) the row's t is fixed (row_lanes_init's proof): each
   pair's X[0] alone is made (space_lanes_at's steps for it), X[1] and X[2] are the row's;
   a point light's term on a face square to the y or z axis is row_dot_axis's, the row's
   parts of it made once a light a stage; a texture's pixels row_tex_pair's where
   row_tex_init holds (then made in the first point light's loop, as said there), else
   tex_pair's on the space points. */
/* shade_pair_greys of four pairs at once: pair q's reflectances r[q] (r NULL: 1 in every
   lane) and sums sum[q], its two greys to g[2q] (lane 0's) and g[2q + 1], where every
   lane's f lies in [0, 2^30) (shade_pair_greys_fast's condition, the AND of the four
   pairs' tests): true, the eight greys in one 8-byte store. Each lane's f and its
   truncation t are shade_pair_greys_fast's operations on the same values, without its top
   of 512: with f in [0, 2^30), 48 + t lies in [48, 2^30 + 48), below 2^31, and the two
   saturating packs of shade_pair_pack (the four pairs' t side by side, two pairs a
   register, element by element as there) give min(48 + t, 255) whether t was topped at
   512 or not (48 + 512 > 255): each byte is the one shade_pair_greys gives. Else false
   and nothing stored (the caller takes the pairs one at a time). */
static inline bool greys_quad(const __m128d *r, const __m128d *sum, uint8_t *g)
{
  const __m128d k = _mm_set1_pd(255 - SHADE_AMBIENT), half = _mm_set1_pd(0.5);
  const __m128d zero = _mm_setzero_pd(), lim = _mm_set1_pd(0x1p30);
  __m128d f[4], ok = _mm_castsi128_pd(_mm_set1_epi32(-1));
  for (int q = 0; q < 4; q++) {
    f[q] = _mm_add_pd(_mm_mul_pd(_mm_mul_pd(k, r ? r[q] : _mm_set1_pd(1)), sum[q]), half);
    ok = _mm_and_pd(ok, _mm_and_pd(_mm_cmpge_pd(f[q], zero), _mm_cmplt_pd(f[q], lim)));
  }
  if (_mm_movemask_pd(ok) != 3) return false;
  const __m128i t01 = _mm_unpacklo_epi64(_mm_cvttpd_epi32(f[0]), _mm_cvttpd_epi32(f[1]));
  const __m128i t23 = _mm_unpacklo_epi64(_mm_cvttpd_epi32(f[2]), _mm_cvttpd_epi32(f[3]));
  const __m128i amb = _mm_set1_epi32(SHADE_AMBIENT);
  const __m128i b = _mm_packus_epi16(_mm_packs_epi32(_mm_add_epi32(t01, amb),
                                                     _mm_add_epi32(t23, amb)),
                                     _mm_setzero_si128());
  _mm_storel_epi64((__m128i *)(void *)g, b);
  return true;
}

enum { LIT_PAIRS = 16 };

static inline __attribute__((always_inline))
void flat_lit_pairs(const struct flat_row *F, const struct shade_pair *P,
                    const struct tex_lanes *T, int n, const unsigned *blocked, unsigned b,
                    const double *px, uint8_t *grey, bool rowt)
{
  const struct space_lanes *const L = &F->L;
  const __m128d one = _mm_set1_pd(1), zero = _mm_setzero_pd();
  const int ax = P->axis;                   /* a face square to an axis: */
  const __m128d nax = P->nv[ax >= 0 ? ax : 0];   /* shade_pair_dot_axis */
  struct row_lanes R;                       /* rowt: t the row's (row_lanes_init) */
  struct row_tex Q;
  Q.ok = false;
  Q.vTdu = _mm_setzero_pd();                /* (read only where ok) */
  Q.yw = _mm_setzero_si128();
  if (rowt) {
    R = F->R;
    if (T) row_tex_init(T, &R, &Q);
  }
  for (int p0 = 0; p0 < n; p0 += 2 * LIT_PAIRS) {
    const int c = n - p0 < 2 * LIT_PAIRS ? n - p0 : 2 * LIT_PAIRS;
    const int nf = c / 2, np = (c + 1) / 2;   /* pairs of two points; with an odd last one */
    const double *pxc = px + p0;
    const unsigned *bc = blocked ? blocked + p0 : NULL;
    uint8_t *gc = grey + p0;
    __m128d X[LIT_PAIRS][3], sum[LIT_PAIRS], refl[LIT_PAIRS];
    __m128i bm[LIT_PAIRS];                  /* blocked[]: lane 0's mask twice, lane 1's twice */
    unsigned both[LIT_PAIRS];               /* blocked[]: the lights blocked at both lanes */
    if (rowt) {                             /* the space points: X[0] alone changes */
      for (int k = 0; k < nf; k++)
        X[k][0] = _mm_add_pd(L->e0, _mm_mul_pd(R.t, _mm_sub_pd(_mm_loadu_pd(pxc + 2 * k), L->e0)));
      if (nf < np)
        X[nf][0] = _mm_add_pd(L->e0, _mm_mul_pd(R.t, _mm_sub_pd(_mm_set1_pd(pxc[2 * nf]), L->e0)));
    } else {
      for (int k = 0; k < nf; k++)
        space_lanes_at(L, _mm_loadu_pd(pxc + 2 * k), X[k]);
      if (nf < np) space_lanes_at(L, _mm_set1_pd(pxc[2 * nf]), X[nf]);
    }
    /* the reflectances; where the row's t is fixed, the picture's row the row's and the
       face square to the y or z axis (fuse), in the loop of the first point light whose
       terms are made (below), else after the lights: the texture's divide and the
       light's square root and divide in one loop, so that the divider and the other
       units work at once */
    const bool fuse = T && rowt && Q.ok && ax > 0;
    bool texed = false;                     /* fuse: refl[] made */
    if (T && !fuse) {
      if (rowt)
        for (int k = 0; k < np; k++) {
          const __m128d Xk[3] = { X[k][0], R.x1, R.x2 };
          refl[k] = tex_pair(T, Xk);
        }
      else
        for (int k = 0; k < np; k++) refl[k] = tex_pair(T, X[k]);
    }
    /* every sum starts at +0 and adds the lights' terms in the scene's order: without
       blocked[] the leading parallel lights' terms are the same at every pair (their
       n.l), so their sum is made once and each pair's sum starts from it (the same
       doubles: the same adds in the same order); the start set for every one of the
       LIT_PAIRS sums (a loop of a fixed count, no exit to mispredict) */
    const struct shade_pair_light *l = P->l, *const end = P->l + P->n;
    unsigned bit = 1;                       /* l's bit in a blocked mask, 1 << (l - P->l) */
    __m128d start = zero;
    if (!bc)
      for (; l < end && !l->point; l++, bit <<= 1)
        if (!(b & bit)) start = _mm_add_pd(start, l->v[0]);
    for (int k = 0; k < LIT_PAIRS; k++) sum[k] = start;
    if (bc) {
      for (int k = 0; k < np; k++) {
        const unsigned b0 = bc[2 * k], b1 = bc[2 * k + 1 < c ? 2 * k + 1 : 2 * k];
        bm[k] = _mm_shuffle_epi32(_mm_unpacklo_epi32(_mm_cvtsi32_si128((int)b0),
                                                     _mm_cvtsi32_si128((int)b1)),
                                  _MM_SHUFFLE(1, 1, 0, 0));
        both[k] = b0 & b1;
      }
    }
    for (; l < end; l++, bit <<= 1) {
      if (!bc) {                            /* b at every point */
        if (b & bit) continue;              /* +0 at every lane */
        if (!l->point)
          for (int k = 0; k < np; k++) sum[k] = _mm_add_pd(sum[k], l->v[0]);
        else if (rowt && ax > 0) {
          struct row_light K;
          row_light_init(l, &R, ax, &K);
          if (fuse && !texed) {
            for (int k = 0; k < np; k++) {
              refl[k] = row_tex_pair(T, &Q, &R, X[k][0]);
              sum[k] = _mm_add_pd(sum[k], row_dot_axis(&K, nax, X[k][0]));
            }
            texed = true;
          } else {
            for (int k = 0; k < np; k++) sum[k] = _mm_add_pd(sum[k], row_dot_axis(&K, nax, X[k][0]));
          }
        } else if (rowt)
          for (int k = 0; k < np; k++)
            sum[k] = _mm_add_pd(sum[k], shade_pair_dot(l, P->nv, X[k][0], R.x1, R.x2));
        else if (ax >= 0)
          for (int k = 0; k < np; k++)
            sum[k] = _mm_add_pd(sum[k], shade_pair_dot_axis(l, nax, ax, X[k]));
        else
          for (int k = 0; k < np; k++)
            sum[k] = _mm_add_pd(sum[k], shade_pair_dot(l, P->nv, X[k][0], X[k][1], X[k][2]));
        continue;
      }
      if (!l->point) {
        for (int k = 0; k < np; k++) {
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit), l->v[0]));
        }
        continue;
      }
      int at[LIT_PAIRS], na = 0;            /* the pairs where it is not blocked at both */
      for (int k = 0; k < np; k++) {
        at[na] = k;
        na += !(both[k] & bit);
      }
      if (rowt && ax > 0 && fuse && !texed) {
        /* every pair's: at a pair where it is blocked at both lanes the mask's AND
           makes its term +0, which leaves the sum */
        struct row_light K;
        row_light_init(l, &R, ax, &K);
        for (int k = 0; k < np; k++) {
          refl[k] = row_tex_pair(T, &Q, &R, X[k][0]);
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit),
                                                 row_dot_axis(&K, nax, X[k][0])));
        }
        texed = true;
      } else if (rowt && ax > 0) {
        struct row_light K;
        row_light_init(l, &R, ax, &K);
        for (int h = 0; h < na; h++) {
          const int k = at[h];
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit),
                                                 row_dot_axis(&K, nax, X[k][0])));
        }
      } else if (rowt)
        for (int h = 0; h < na; h++) {
          const int k = at[h];
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit),
                                                 shade_pair_dot(l, P->nv, X[k][0], R.x1, R.x2)));
        }
      else if (ax >= 0)
        for (int h = 0; h < na; h++) {
          const int k = at[h];
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit),
                                                 shade_pair_dot_axis(l, nax, ax, X[k])));
        }
      else
        for (int h = 0; h < na; h++) {
          const int k = at[h];
          const __m128i lit = _mm_cmpeq_epi32(_mm_and_si128(bm[k], l->bit), _mm_setzero_si128());
          sum[k] = _mm_add_pd(sum[k], _mm_and_pd(_mm_castsi128_pd(lit),
                                                 shade_pair_dot(l, P->nv, X[k][0], X[k][1], X[k][2])));
        }
    }
    if (fuse && !texed)                     /* no point light's terms made */
      for (int k = 0; k < np; k++) refl[k] = row_tex_pair(T, &Q, &R, X[k][0]);
    int k = 0;                              /* the greys: four pairs' eight bytes in one */
    for (; k + 4 <= nf; k += 4)             /* store (greys_quad), else pair by pair */
      if (!greys_quad(T ? refl + k : NULL, sum + k, gc + 2 * k)) break;
    for (; k < nf; k++) {                   /* a pair's two bytes in one store (lane 0's */
                                            /* the low byte: x86 is little-endian) */
      const uint16_t g = (uint16_t)shade_pair_greys(T ? refl[k] : one, sum[k]);
      memcpy(gc + 2 * k, &g, 2);
    }
    if (nf < np) gc[2 * nf] = (uint8_t)shade_pair_greys(T ? refl[nf] : one, sum[nf]);
  }
}
#endif

#ifdef FLAT_AVX512
/* flat_lit_pairs where the row's t is fixed (rowt) and the face is square to the y or the
   z axis (P->axis 1 or 2), its texture T (or NULL) with its picture's row the row's
   (row_tex_init's Q->ok), eight points an instruction in AVX-512's registers, chosen at
   run time where the processor has AVX-512F and VL (flat_wide). Why: on fig6-room every
   point the flat lit functions shade comes this way (1,277 points a frame of untextured
   stretches under a fixed mask, 999 textured points with no light blocked, 730 textured
   with blocked[]), and each pair of SSE2 lanes waits on a square root and a divide (two
   with a texture); this host's divider takes a 512-bit square root or divide about as
   often as a 128-bit one (independent chains: DIVPD 1.3 ns an instruction, VDIVPD zmm
   1.7; SQRTPD 2.9, VSQRTPD zmm 2.4), so eight points go through it in the time of two
   (round 41: the flat functions' share of fig6-room 38% -> 27%, its whole process's CPU
   time 0.85 to 0.88 of before).
   Each lane's operations are flat_lit_pairs' for its point on the same doubles in the
   same order, each the same IEEE operation (EVEX-encoded; no fused multiply-add: the
   build's -ffp-contract=off), a compare by the predicate of the SSE2 one (CMPPD's LT, GT
   and GE are LT_OS, GT_OS and GE_OS, its NEQ is NEQ_UQ), a select as a blend or a zeroing
   move in place of an AND/ANDN/OR of a compare's mask (the same double chosen):
   - X[0] = E0 + t (px - E0), the row's t (rowt); X[1], X[2] are the row's;
   - the texture (row_tex_pair): u = X[0] - o[du], a = (u T[dv] - v T[du]) / det, where
     every lane's |a| < 2^30 its floor as floor_pair makes it, x = (int)min(a w, w - 1),
     the pixel at y w + x (Q's y w), its k / 255.0 from unit_pixel (loaded lane by lane);
     where a lane's |a| is not below 2^30 the step's points go to flat_lit_pairs itself
     (flat_rowt_pairs: each point's grey depends on its own px and mask alone);
   - the lights in the scene's order from a sum of +0: a parallel light's n.l (P's), a
     point light's row_dot_axis (row_light_init's row terms, the same doubles), added
     where the light is not blocked at the lane (blocked[p], or b at every point: a light
     in b is passed over, as there). flat_lit_pairs adds +0 (an AND with an all-zero mask)
     where a light is blocked at a lane, or passes a light blocked at both lanes of a
     pair over; here the lane's sum is kept (a masked add), the same double: a sum is +0
     or positive (each term is +0 or a positive n.l, never -0 or NaN), and x + (+0) is x
     for every such x;
   - the grey: f = (207 r) s + 0.5 (r 1 without a texture: 207 1 is 207, as there), where
     every lane's f lies in [0, 2^30) shade_pair_greys_fast's truncation of min(f, 512)
     and min(48 + t, 255) (the packs' clamp: 48 + t lies in [48, 560]); else
     shade_grey_of_sum lane by lane (what shade_pair_greys gives both ways).
   A step's lanes past the run's end read px +0 and mask 0 and take the picture's first
   pixel; their greys are not stored. test_model_tex's pointwise tests run fx_points both
   ways (fx_model's flat_sse2) against fx_shade at every point. */
#define FLAT512_ATTR __attribute__((target("avx512f,avx512vl")))

__attribute__((noinline))
static void flat_rowt_pairs(const struct flat_row *F, const struct shade_pair *P,
                            const struct tex_lanes *T, int n, const unsigned *blocked,
                            unsigned b, const double *px, uint8_t *grey)
{
  flat_lit_pairs(F, P, T, n, blocked, b, px, grey, true);
}

static FLAT512_ATTR void flat_rowt8(const struct flat_row *F, const struct shade_pair *P,
                                    const struct tex_lanes *T, const struct row_tex *Q, int n,
                                    const unsigned *blocked, unsigned b, const double *px,
                                    uint8_t *grey)
{
  const int ax = P->axis;                   /* 1 or 2 */
  const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1);
  const __m512d e0 = _mm512_set1_pd(_mm_cvtsd_f64(F->L.e0));
  const __m512d tr = _mm512_set1_pd(_mm_cvtsd_f64(F->R.t));
  const __m512d nc = _mm512_set1_pd(_mm_cvtsd_f64(P->nv[ax]));
  /* the lights whose terms are made, in the scene's order: a point light's row terms
     (row_light_init's), a parallel light's n.l */
  double l0[SCENE_LIGHT_MAX], yy[SCENE_LIGHT_MAX], zz[SCENE_LIGHT_MAX], num[SCENE_LIGHT_MAX];
  unsigned bits[SCENE_LIGHT_MAX];
  bool point[SCENE_LIGHT_MAX];
  int nl = 0;
  for (int k = 0; k < P->n; k++) {
    const struct shade_pair_light *l = &P->l[k];
    if (!blocked && (b >> k & 1u)) continue;
    bits[nl] = 1u << k;
    point[nl] = l->point;
    if (l->point) {
      struct row_light K;
      row_light_init(l, &F->R, ax, &K);
      l0[nl] = _mm_cvtsd_f64(K.l0);
      yy[nl] = _mm_cvtsd_f64(K.yy);
      zz[nl] = _mm_cvtsd_f64(K.zz);
      num[nl] = _mm_cvtsd_f64(K.num);
    } else {
      l0[nl] = _mm_cvtsd_f64(l->v[0]);
      yy[nl] = zz[nl] = num[nl] = 0;
    }
    nl++;
  }
  const __m512d k207 = _mm512_set1_pd(255 - SHADE_AMBIENT), half = _mm512_set1_pd(0.5);
  const __m512d lim = _mm512_set1_pd(0x1p30), top = _mm512_set1_pd(512);
  for (int p = 0; p < n; p += 8) {
    const int c = n - p < 8 ? n - p : 8;
    const __mmask8 km = (__mmask8)((1u << c) - 1);
    const __m512d x0 = _mm512_add_pd(e0, _mm512_mul_pd(tr, _mm512_sub_pd(
                                       _mm512_maskz_loadu_pd(km, px + p), e0)));
    __m512d refl = one;
    if (T) {
      const __m512d u = _mm512_sub_pd(x0, _mm512_set1_pd(_mm_cvtsd_f64(T->odu)));
      __m512d a = _mm512_div_pd(_mm512_sub_pd(_mm512_mul_pd(u, _mm512_set1_pd(_mm_cvtsd_f64(T->Tdv))),
                                              _mm512_set1_pd(_mm_cvtsd_f64(Q->vTdu))),
                                _mm512_set1_pd(_mm_cvtsd_f64(T->det)));
      if (_mm512_mask_cmp_pd_mask(km, _mm512_abs_pd(a), lim, _CMP_LT_OS) != km) {
        flat_rowt_pairs(F, P, T, c, blocked ? blocked + p : NULL, b, px + p, grey + p);
        continue;
      }
      const __m512d M = _mm512_set1_pd(0x1.8p52);  /* floor_pair's steps */
      const __m512d r = _mm512_sub_pd(_mm512_add_pd(a, M), M);
      a = _mm512_sub_pd(a, _mm512_sub_pd(r, _mm512_maskz_mov_pd(
                                           _mm512_cmp_pd_mask(r, a, _CMP_GT_OS), one)));
      const __m256i x = _mm512_cvttpd_epi32(_mm512_min_pd(
        _mm512_mul_pd(a, _mm512_set1_pd(_mm_cvtsd_f64(T->wd))),
        _mm512_set1_pd(_mm_cvtsd_f64(T->wtop))));
      const __m512i at = _mm512_maskz_add_epi64(km, _mm512_set1_epi64(_mm_cvtsi128_si64(Q->yw)),
                                                _mm512_cvtepu32_epi64(x));
      /* (lane by lane: two gathers in their place, the pixel as a byte of a 32-bit
         gather and its k / 255.0 from unit_pixel, were slower on fig6-room, 1.03 to 1.04
         of this in turn) */
      _Alignas(64) int64_t ix[8];
      _Alignas(64) double rv[8];
      _mm512_store_si512((void *)ix, at);
      for (int h = 0; h < 8; h++) rv[h] = unit_pixel[T->px[ix[h]] + 1];
      refl = _mm512_load_pd(rv);
    }
    const __m256i bm = blocked ? _mm256_maskz_loadu_epi32(km, blocked + p) : _mm256_setzero_si256();
    __m512d sum = zero;
    for (int h = 0; h < nl; h++) {
      const __mmask8 lit = _mm256_testn_epi32_mask(bm, _mm256_set1_epi32((int)bits[h]));
      __m512d term;
      if (!point[h]) {
        term = _mm512_set1_pd(l0[h]);
      } else {
        const __m512d lx = _mm512_sub_pd(_mm512_set1_pd(l0[h]), x0);
        const __m512d s = _mm512_sqrt_pd(_mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(lx, lx),
                                                                     _mm512_set1_pd(yy[h])),
                                                       _mm512_set1_pd(zz[h])));
        const __m512d div = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(s, zero, _CMP_NEQ_UQ), one, s);
        const __m512d d = _mm512_mul_pd(nc, _mm512_div_pd(_mm512_set1_pd(num[h]), div));
        term = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(d, zero, _CMP_GT_OS), d);
      }
      sum = _mm512_mask_add_pd(sum, lit, sum, term);
    }
    const __m512d f = _mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(k207, refl), sum), half);
    const __mmask8 fine = _mm512_mask_cmp_pd_mask(_mm512_mask_cmp_pd_mask(km, f, zero, _CMP_GE_OS),
                                                  f, lim, _CMP_LT_OS);
    if (fine == km) {
      const __m256i t = _mm512_cvttpd_epi32(_mm512_min_pd(f, top));
      _mm256_mask_cvtepi32_storeu_epi8(grey + p, km,
                                       _mm256_min_epi32(_mm256_add_epi32(t, _mm256_set1_epi32(SHADE_AMBIENT)),
                                                        _mm256_set1_epi32(255)));
    } else {
      _Alignas(64) double rr[8], ss[8];
      _mm512_store_pd(rr, refl);
      _mm512_store_pd(ss, sum);
      for (int h = 0; h < c; h++) grey[p + h] = (uint8_t)shade_grey_of_sum(rr[h], ss[h]);
    }
  }
}

/* Whether a flat lit row takes flat_rowt8: where the processor has AVX-512F and VL (and
   the system saves their registers: __builtin_cpu_supports) and m's flat_sse2 (tests
   only) is not set. */
static inline bool flat_wide(const struct fx_model *m)
{
  return !m->flat_sse2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
}

/* A textured face's n points of a row (F: flat_row_init's) by flat_rowt8 where it takes
   them (the row's t fixed, the face square to the y or z axis, the picture's row the
   row's: row_tex_init's Q made as flat_lit_pairs makes it): true, the greys made; else
   false, nothing done. */
static inline bool flat_tex_wide(const struct fx_model *m, const struct shade_pair *P,
                                 const struct tex_lanes *T, const struct flat_row *F, int n,
                                 const unsigned *blocked, const double *px, uint8_t *grey)
{
  if (!F->rowt || P->axis <= 0 || !flat_wide(m)) return false;
  struct row_tex Q;
  row_tex_init(T, &F->R, &Q);
  if (!Q.ok) return false;
  flat_rowt8(F, P, T, &Q, n, blocked, 0, px, grey);
  return true;
}
#endif

/* The plane position of point coordinates (u, v) (fx_shade's px, py). */
static double plane_x(const struct vis_grid *g, double u)
{
  return g->window[0] + u * (double)(g->window[2] - g->window[0]) / g->W;
}

static double plane_y(const struct vis_grid *g, double v)
{
  return g->window[3] - v * (double)(g->window[3] - g->window[1]) / g->H;
}

/* What the shading needs of a face, found once for a run of points on it. */
struct face_shade {
  const struct mface *mf;
  const struct fx_tex *t;   /* its texture, or NULL */
  int tri;                  /* its smoothing triangle, or -1 */
  bool lit;                 /* shaded from the lights (no grey of its own) */
};

static void face_shade_of(const struct fx_model *m, int face, struct face_shade *fs)
{
  const struct mface *mf = &m->map->f[face];
  fs->mf = mf;
  fs->t = m->tex && m->tex[mf->sface].pic ? &m->tex[mf->sface] : NULL;
  fs->tri = m->smooth && m->e->smooth != EFFECTS_SMOOTH_NONE ? m->sm.tri_of_mface[face] : -1;
  fs->lit = m->s->f[mf->sface].grey < 0 && m->s->has_light;
}

/* fx_shade of face (fs: face_shade_of's) at plane position (px, py); cost NULL: not
   counted. */
/* A flat face's unit normal towards the eye's side, as it is lit. */
static void face_normal(const struct mface *mf, double n[3])
{
  for (int c = 0; c < 3; c++) n[c] = -(double)mf->plane[c];
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int c = 0; c < 3; c++) n[c] /= len;
}

static int shade_face_at(const struct fx_model *m, int face, const struct face_shade *fs,
                         unsigned blocked, double px, double py, struct cost *cost, int *region)
{
  if (region) *region = -1;
  const struct mface *mf = fs->mf;
  const struct fx_tex *t = fs->t;
  const int tri = fs->tri;
  const bool lit = fs->lit;
  if (cost) { COST_ADD_N(cost, COST_MEM, 2); COST_ADD_N(cost, COST_BRANCH, 2); }
  if (!lit) blocked = 0;                     /* a face of its own grey is not lit */
  if (tri < 0 && !t && !blocked) return mf->grey;
  double X[3];
  space_point(m, face, px, py, X);
  if (cost) {
    for (int k = 0; k < 6; k++) cost_mw_mul(cost, 32, 16);
    cost_mw_div(cost, 48, 32);
  }
  double refl = t ? reflectance(t, X, cost) : 1.0;
  if (tri >= 0)
    return smooth_grey_at(&m->sm, m->map, m->s, m->e, tri, X, refl, blocked, &m->lights, cost,
                          region);
  if (!lit) return (int)floor(mf->grey * refl + 0.5);
  double n[3];
  face_normal(mf, n);
  if (cost)
    for (int k = 0; k < m->s->nlight; k++) { cost_mw_mul(cost, 16, 16); cost_mw_mul(cost, 16, 16); }
  return shade_grey_lit(&m->lights, n, X, refl, blocked);
}

/* shade_face_at, uncounted, at n <= SMOOTH_RUN neighbouring points (px[p], py) of a
   smoothed face without a texture (fs: face_shade_of's): the same greys and regions,
   worked out together (smooth_grey_run). */
static void shade_run(const struct fx_model *m, int face, const struct face_shade *fs, int n,
                      const unsigned *blocked, const double *px, double py, uint8_t *grey,
                      int *region)
{
  static const unsigned none[SMOOTH_RUN];  /* a face of its own grey is not lit */
  double X[SMOOTH_RUN][3];
  int g[SMOOTH_RUN];
  space_points(m, face, n, px, py, X);
  smooth_grey_run(&m->sm, m->map, m->s, m->e, fs->tri, n, (const double (*)[3])X, 1.0,
                  fs->lit ? blocked : none, &m->lights, g, region);
  for (int p = 0; p < n; p++) grey[p] = (uint8_t)g[p];
}

/* shade_row's greys g[0 .. n) (each 0 .. 255) into gr[] as bytes. */
static inline void shade_row_greys(const int *g, int n, uint8_t *gr)
{
  int h = 0;
#ifdef __SSE2__
  for (; h + 8 <= n; h += 8) {              /* greys 0 .. 255: the packs keep them */
    const __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(g + h));
    const __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(g + h + 4));
    _mm_storel_epi64((__m128i *)(void *)(gr + h),
                     _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_setzero_si128()));
  }
#endif
  for (; h < n; h++) gr[h] = (uint8_t)g[h];
}

#ifdef __SSE2__
/* Whether space_lanes_at's den (L's constants one face's in both lanes) is not 0 at any
   point of a row from plane position a to b (a <= b): true where den is > 0 at both a and
   b, or < 0 at both. Proof: each step from px to den (D0 = px - E0, r[0] D0, + c1, + c2) is one
   correctly rounded operation of one variable operand and a constant; where it gives no
   NaN it is monotone in that operand (rounding is monotone: non-decreasing, or
   non-increasing for the product where r[0] < 0), and so is the chain of them. The row's
   px[] are plane_x's, non-decreasing in the point's column (u (W_R - W_L) / W, W_R > W_L and
   W > 0, plus W_L), so a point's px lies in [a, b]. At a and at b the chain gives no NaN
   (its den is > 0 or < 0, not NaN); at a point between, either some step gives a NaN, and
   then den is NaN (NaN is passed on), not 0; or none does, and then each step's value lies
   between its values at a and at b, den too: > 0 or < 0, not 0. Where den is not 0,
   space_lanes_at's select gives r[3] / den (and a NaN den makes that quotient NaN, both
   ways). */
static inline bool den_not_zero(const struct space_lanes *L, double a, double b)
{
  const __m128d d0 = _mm_sub_pd(_mm_set_pd(b, a), L->e0);
  const __m128d den = space_lanes_den(L, d0);
  /* (the rounded product of the two is > 0 only where the exact one is: rounding is
     monotone and keeps 0; so both are > 0 or both < 0, neither a NaN) */
  return _mm_comigt_sd(_mm_mul_sd(den, _mm_unpackhi_pd(den, den)), _mm_setzero_pd());
}

/* shade_row's space points p .. q - 1 (q - p even) of one face (L its constants) two an
   instruction, space_lanes_at's, of which only the coordinates on the face's triangle's
   axes u and w (constants where inlined: the third is not made) are kept, into xu[] and
   xw[] (smooth_phong_row's and smooth_partial_row's). Where den_not_zero holds from the
   first point to the last (a face's run of two pairs or more: fx_points' px[] are
   non-decreasing), t is r[3] / den without space_lanes_at's select of 1 where den is 0
   (its value at every point there; four instructions and two copies a pair fewer on a
   loop the divider holds: issue 19, round 40). */
static inline __attribute__((always_inline))
void uv_pairs(const struct space_lanes *L, const double *px, int p, int q, int u, int w,
              double *xu, double *xw)
{
  if (q - p >= 4 && den_not_zero(L, px[p], px[q - 1])) {
    for (; p < q; p += 2) {                 /* den not 0: t = r[3] / den, no select */
      const __m128d d0 = _mm_sub_pd(_mm_loadu_pd(px + p), L->e0);
      const __m128d den = space_lanes_den(L, d0);
      const __m128d t = _mm_div_pd(L->r3, den);
      const __m128d d[3] = { d0, L->d1, L->d2 }, e[3] = { L->e0, L->e1, L->e2 };
      _mm_storeu_pd(xu + p, _mm_add_pd(e[u], _mm_mul_pd(t, d[u])));
      _mm_storeu_pd(xw + p, _mm_add_pd(e[w], _mm_mul_pd(t, d[w])));
    }
    return;
  }
  for (; p < q; p += 2) {
    __m128d x[3];
    space_lanes_at(L, _mm_loadu_pd(px + p), x);
    _mm_storeu_pd(xu + p, x[u]);
    _mm_storeu_pd(xw + p, x[w]);
  }
}

/* shade_row's space points p .. q - 1 (q - p even) of face f (triangle ta), L's face
   constants set to f's first (space_lanes_faces), two by two (uv_pairs, ta's axes
   constants there). */
static inline __attribute__((always_inline))
void uv_face(const struct fx_model *m, struct space_lanes *L, int f, const struct smooth_tri *ta,
             const double *px, int p, int q, double *xu, double *xw)
{
  space_lanes_faces(m, f, f, L);
  switch (3 - ta->bu - ta->bw) {            /* (bu, bw) is (ax + 1, ax + 2) mod 3 */
  case 0: uv_pairs(L, px, p, q, 1, 2, xu, xw); break;
  case 1: uv_pairs(L, px, p, q, 2, 0, xu, xw); break;
  default: uv_pairs(L, px, p, q, 0, 1, xu, xw); break;
  }
}

/* shade_row's space points pa of face fa (triangle ta) and pb of face fb (tb) in one
   step, each lane with its own face's constants (L's row constants; its face constants
   set here, space_lanes_faces), each lane's operations space_point's on its values; each
   point's coordinates on its triangle's axes into xu[] and xw[] (pb may be pa: a point
   alone, in both lanes). */
static inline __attribute__((always_inline))
void uv_two(const struct fx_model *m, struct space_lanes *L, int fa, int fb,
            const struct smooth_tri *ta, const struct smooth_tri *tb, const double *px, int pa,
            int pb, double *xu, double *xw)
{
  space_lanes_faces(m, fa, fb, L);
  __m128d x[3];
  space_lanes_at(L, _mm_set_pd(px[pb], px[pa]), x);
  _mm_storel_pd(&xu[pa], x[ta->bu]); _mm_storel_pd(&xw[pa], x[ta->bw]);
  _mm_storeh_pd(&xu[pb], x[tb->bu]); _mm_storeh_pd(&xw[pb], x[tb->bw]);
}
#endif

#ifdef UV_AVX512
/* shade_row's space points eight an instruction (AVX-512's registers), chosen at run time
   where the processor has AVX-512F (uv_avx512): each face's run of points from its first,
   eight a step, the last step's lanes past the run's end masked off (not loaded, divided
   or stored). Each lane's operations are space_lanes_at's (space_point's) on its point,
   in their order, each the same IEEE operation on the same doubles (EVEX-encoded, 512 bits
   wide; no fused multiply-add: the build's -ffp-contract=off), r[1] D1 and r[2] D2 the one
   double space_lanes_init makes; the select of t = 1 where den is 0 (C's den != 0 is
   _CMP_NEQ_UQ, true for a NaN, as CMPNEQPD's) made by the divide's mask: lanes where den
   is 0 keep 1 and are not divided. So the same two coordinates bit for bit, whatever
   faces share a step in the SSE2 way (a lane's value is its point's alone); no pairing of
   a face's odd last point with the next face's, no den_not_zero. Where it pays: the SSE2
   way's loop is held by its divides (issue 19, round 40: about 6.5 cycles a pair of
   points, the divider's throughput 4), and here a VDIVPD of eight lanes takes about what a
   DIVPD of two does (a Zen 5 machine: 1.27 against 1.13 ns an instruction with eight
   chains in flight). What is left of it waits on a stretch's first divide (perf: most of
   uv_row512's samples on the product after VDIVPD; t1-g has one stretch a row or two).
   Tried, the same greys, and not faster (median frames in turn, round 41): the whole
   stretch eight points a step whatever faces they are on, each lane's constants by
   VPERMT2PD from tables of the stretch's faces and its axes by masks (t1-g 1.036, t1-e
   1.017); each face's three coordinates made and two picked by masks, no branch on the
   axes (t1-g 1.027, the sphere 1.019); the stretch's first eight points made as its first
   face's before its runs are found, so that the divide's wait overlaps the search (level:
   fx_points' and the space points' samples t1-g 16.7 -> 16.6%, the sphere 13.1 -> 13.5%). */
#define UV512_ATTR __attribute__((target("avx512f")))

/* The constants of a row (eye E, D1 = py - E1, D2 = -E2) in eight lanes. */
struct uv512_row {
  __m512d e0, e1, e2, d1, d2;
  double D1, D2;
};

/* Points p .. q - 1 of the row (px[]) on the face of ray r: their coordinates u and
   (u + 1) % 3 (u a constant where inlined) into xu[] and xw[]. */
static inline __attribute__((always_inline)) UV512_ATTR
void uv_run512(const struct uv512_row *R, const double *r, int u, const double *px, int p, int q,
               double *xu, double *xw)
{
  const __m512d r0 = _mm512_set1_pd(r[0]), r3 = _mm512_set1_pd(r[3]);
  const __m512d c1 = _mm512_set1_pd(r[1] * R->D1), c2 = _mm512_set1_pd(r[2] * R->D2);
  const __m512d one = _mm512_set1_pd(1), zero = _mm512_setzero_pd();
  for (; p < q; p += 8) {
    const __mmask8 in = q - p >= 8 ? (__mmask8)0xff : (__mmask8)((1u << (q - p)) - 1);
    const __m512d d0 = _mm512_sub_pd(_mm512_maskz_loadu_pd(in, px + p), R->e0);
    const __m512d den = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(r0, d0), c1), c2);
    const __mmask8 nz = _mm512_mask_cmp_pd_mask(in, den, zero, _CMP_NEQ_UQ);
    const __m512d t = _mm512_mask_div_pd(one, nz, r3, den);   /* den != 0 ? r[3] / den : 1 */
    const __m512d x0 = u != 1 ? _mm512_add_pd(R->e0, _mm512_mul_pd(t, d0)) : zero;
    const __m512d x1 = u != 2 ? _mm512_add_pd(R->e1, _mm512_mul_pd(t, R->d1)) : zero;
    const __m512d x2 = u != 0 ? _mm512_add_pd(R->e2, _mm512_mul_pd(t, R->d2)) : zero;
    _mm512_mask_storeu_pd(xu + p, in, u == 0 ? x0 : u == 1 ? x1 : x2);
    _mm512_mask_storeu_pd(xw + p, in, u == 0 ? x1 : u == 1 ? x2 : x0);
  }
}

static inline __attribute__((always_inline)) UV512_ATTR
void uv_row512_init(const struct fx_model *m, double py, struct uv512_row *R)
{
  const double *E = m->eye;
  const double E0 = E[0], E1 = E[1], E2 = E[2];
  R->D1 = py - E1;
  R->D2 = -E2;
  R->e0 = _mm512_set1_pd(E0); R->e1 = _mm512_set1_pd(E1); R->e2 = _mm512_set1_pd(E2);
  R->d1 = _mm512_set1_pd(R->D1); R->d2 = _mm512_set1_pd(R->D2);
}

/* Points p .. q - 1 of face f: uv_run512 on its axes u, (u + 1) % 3. */
static inline __attribute__((always_inline)) UV512_ATTR
void uv_face512(const struct fx_model *m, const struct uv512_row *R, int f, int u,
                const double *px, int p, int q, double *xu, double *xw)
{
  const double *r = m->ray[f];
  switch (u) {
  case 1: uv_run512(R, r, 1, px, p, q, xu, xw); break;
  case 2: uv_run512(R, r, 2, px, p, q, xu, xw); break;
  default: uv_run512(R, r, 0, px, p, q, xu, xw); break;
  }
}

/* shade_row's coordinates of its stretch (faces sf[k], triangles tri[k], at points at[k] ..
   at[k + 1] - 1) on each point's triangle's axes bu, bw (bw = (bu + 1) % 3: uv_face). */
static UV512_ATTR void uv_row512(const struct fx_model *m, double py, int ns, const int *sf,
                                 const int *tri, const int *at, const double *px, double *xu,
                                 double *xw)
{
  struct uv512_row R;
  uv_row512_init(m, py, &R);
  for (int k = 0; k < ns; k++)
    uv_face512(m, &R, sf[k], m->sm.tri[tri[k]].bu, px, at[k], at[k + 1], xu, xw);
}

/* fx_space_uv's way on AVX-512 (any n). */
static UV512_ATTR void space_uv512(const struct fx_model *m, int f, int n, const double *px,
                                   double py, int u, double *xu, double *xw)
{
  struct uv512_row R;
  uv_row512_init(m, py, &R);
  uv_face512(m, &R, f, u, px, 0, n, xu, xw);
}

/* Whether shade_row's space points take uv_row512: where the processor has AVX-512F (and
   the system saves its registers: __builtin_cpu_supports) and m's uv_sse2 (tests only) is
   not set. */
static inline bool uv_avx512(const struct fx_model *m)
{
  return !m->uv_sse2 && __builtin_cpu_supports("avx512f");
}
#endif

void fx_space_uv(const struct fx_model *m, int f, int n, const double *px, double py, int u,
                 double *xu, double *xw)
{
#ifdef UV_AVX512
  if (uv_avx512(m)) {
    space_uv512(m, f, n, px, py, u, xu, xw);
    return;
  }
#endif
#ifdef __SSE2__
  struct space_lanes L;
  space_lanes_init(m, f, py, &L);
  switch (u) {                              /* uv_face's three ways */
  case 1: uv_pairs(&L, px, 0, n, 1, 2, xu, xw); break;
  case 2: uv_pairs(&L, px, 0, n, 2, 0, xu, xw); break;
  default: uv_pairs(&L, px, 0, n, 0, 1, xu, xw); break;
  }
#else
  for (int p = 0; p < n; p++) {
    double X[3];
    space_point(m, f, px[p], py, X);
    xu[p] = X[u];
    xw[p] = X[(u + 1) % 3];
  }
#endif
}

/* Where smooth_rows says so: the points i, i + 1, .. of a row (faces fr[], px[],
   blocked[]) while they are on smoothed faces without a texture, of one triangle or
   several, at most SMOOTH_ROW of them, from the first (face fr[i], fs its face_shade_of's:
   a smoothed face without a texture) on: their greys into gr[] as shade_run gives them,
   shaded together (smooth_row), their regions counted up in runs[]; returns the end of the
   stretch. The space points two an instruction (space_lanes_at), a face's
   two by two and an odd one left over with the next face's first (smooth=phong) or with
   the next face's left over (the partial smoothing; see uv below): each lane's
   operations are space_point's on its values in its order, with its own face's constants
   (r[1] D1 and r[2] D2 lane by lane, the same products space_lanes_init makes); a lone
   last point in both lanes. Where the lights are all parallel (uv; smooth=phong is served
   only so) only the two coordinates of each point on its triangle's axes (smooth_tri's bu,
   bw) are kept, in two arrays (smooth_phong_row's and smooth_partial_row's greys and
   regions depend on nothing else of it): two stores a pair of points, not six; and, under
   smooth=phong, two loads there, not four and two shuffles. There, where the processor
   has AVX-512F (uv512: uv_avx512), eight points an instruction, a face at a time
   (uv_row512): the same doubles. */
static int shade_row(const struct fx_model *m, const int *fr, int i, int W,
                     const struct face_shade *fs, const unsigned *blocked, const double *px,
                     double py, uint8_t *gr, long runs[3], bool uv, bool uv512)
{
  /* the faces one after another: face sf[k] (triangle tri[k]) at points at[k] .. at[k + 1] - 1
     of the stretch */
  int tri[SMOOTH_ROW], sf[SMOOTH_ROW], at[SMOOTH_ROW + 1], ns = 0;
  sf[0] = fr[i];
  tri[0] = fs->tri;
  at[0] = 0;
  const int len = W - i < SMOOTH_ROW ? W - i : SMOOTH_ROW;
  /* the runs' ends: the points q (0 < q < len) where fr[i + q] != fr[i + q - 1], as bits
     of cut, made four points a compare (independent of one another), then taken in order;
     found run after run (face_run_end from the last run's end) each run waited on its
     last one's loads and compares (issue 19) */
  uint64_t cut = 0;
  {
    int q = 1;
#ifdef __SSE2__
    if (len >= 17) {
      /* sixteen points a step: the four compares' masks packed to bytes (packs with
         signed saturation keep -1 and 0), one movemask; the last 1 .. 15 the stretch's
         last sixteen again (a point's bit the same, made twice) */
      for (;;) {
        const int *a = fr + i + q;
        __m128i eq[4];
        for (int h = 0; h < 4; h++)
          eq[h] = _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(a + 4 * h)),
                                  _mm_loadu_si128((const __m128i *)(const void *)(a + 4 * h - 1)));
        const unsigned same = (unsigned)_mm_movemask_epi8(
          _mm_packs_epi16(_mm_packs_epi32(eq[0], eq[1]), _mm_packs_epi32(eq[2], eq[3])));
        cut |= (uint64_t)(~same & 0xffffu) << q;
        if (q + 16 == len) break;
        q = q + 32 <= len ? q + 16 : len - 16;
      }
      q = len;
    }
    for (; q + 4 <= len; q += 4) {
      const __m128i x = _mm_loadu_si128((const __m128i *)(const void *)(fr + i + q));
      const __m128i y = _mm_loadu_si128((const __m128i *)(const void *)(fr + i + q - 1));
      cut |= (uint64_t)(~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(x, y))) & 15) << q;
    }
    if (q < len && len >= 5) {              /* the last 1 .. 3: the last four, again */
      q = len - 4;                          /* (a point's bit the same, made twice) */
      const __m128i x = _mm_loadu_si128((const __m128i *)(const void *)(fr + i + q));
      const __m128i y = _mm_loadu_si128((const __m128i *)(const void *)(fr + i + q - 1));
      cut |= (uint64_t)(~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(x, y))) & 15) << q;
      q = len;
    }
#endif
    for (; q < len; q++) cut |= (uint64_t)(fr[i + q] != fr[i + q - 1]) << q;
  }
  int e = len;                              /* the stretch's end, from i */
  for (; cut; cut &= cut - 1) {
    const int c = __builtin_ctzll(cut), f = fr[i + c];
    /* a smoothed face without a texture (face_shade_of's tri >= 0 and t NULL): lit, as
       only a face of no grey of its own under a light is smoothed (smooth.h) */
    const int t = f < 0 ? -1 : m->sm.tri_of_mface[f];
    if (t < 0 || (m->tex && m->tex[m->map->f[f].sface].pic)) {
      e = c;
      break;
    }
    at[++ns] = c;
    sf[ns] = f;
    tri[ns] = t;
  }
  at[++ns] = e;
  e += i;
  double X[SMOOTH_ROW][3];
  int g[SMOOTH_ROW];
#ifdef __SSE2__
  if (uv) {
    _Alignas(16) double xu[SMOOTH_ROW], xw[SMOOTH_ROW];
    const bool phong = m->e->smooth == EFFECTS_SMOOTH_PHONG;
#ifdef UV_AVX512
    if (uv512)
      uv_row512(m, py, ns, sf, tri, at, px, xu, xw);
    else
#else
    (void)uv512;
#endif
    {
      struct space_lanes L;
      space_lanes_init(m, sf[0], py, &L);
      /* smooth=phong: a face's odd last point with the next face's first (phong_row_lights
         pairs them so); the partial smoothing: each face's pairs from its first point (as
         inner_split reads them, 16 bytes a load: each the very 16 bytes stored), its odd
         last point left over (left[]: its face's index k) and put with the next one left
         over after the faces */
      int p = 0;
      if (phong) {
        for (int k = 0; k < ns; k++) {
          const int q = at[k + 1], qe = p + ((q - p) & ~1);
          const struct smooth_tri *ta = &m->sm.tri[tri[k]];
          uv_face(m, &L, sf[k], ta, px, p, qe, xu, xw);
          p = qe;
          if (p == q) continue;
          const int kb = k + 1 < ns ? k + 1 : k;  /* with the next face's first, or alone */
          const int p1 = k + 1 < ns ? q : p;
          uv_two(m, &L, sf[k], sf[kb], ta, &m->sm.tri[tri[kb]], px, p, p1, xu, xw);
          p = p1 + 1;
        }
      } else {
        int left[SMOOTH_ROW], nleft = 0;
        for (int k = 0; k < ns; k++) {
          const int q = at[k + 1], qe = p + ((q - p) & ~1);
          uv_face(m, &L, sf[k], &m->sm.tri[tri[k]], px, p, qe, xu, xw);
          if (qe < q) left[nleft++] = k;
          p = q;
        }
        for (int j = 0; j < nleft; j += 2) {  /* the left-over points, two a step */
          const int ka = left[j], kb = left[j + 1 < nleft ? j + 1 : j];   /* a last one alone */
          uv_two(m, &L, sf[ka], sf[kb], &m->sm.tri[tri[ka]], &m->sm.tri[tri[kb]], px,
                 at[ka + 1] - 1, at[kb + 1] - 1, xu, xw);
        }
      }
    }
    if (phong) {
      smooth_phong_row(&m->sm, ns, tri, at, xu, xw, blocked, &m->lights, g);
      runs[1] += at[ns];                    /* smooth_row's regions under smooth=phong */
    } else {
      smooth_partial_row(&m->sm, m->map, ns, tri, at, xu, xw, blocked, &m->lights, g, runs);
    }
    shade_row_greys(g, e - i, gr);
    return e;
  }
  struct space_lanes L;
  space_lanes_init(m, sf[0], py, &L);        /* the row's constants; the faces' below */
  int p = 0;
  for (int k = 0; k < ns; k++) {
    const int q = at[k + 1];
    space_lanes_faces(m, sf[k], sf[k], &L);
    __m128d x[3];
    for (; p + 2 <= q; p += 2) {
      space_lanes_at(&L, _mm_loadu_pd(px + p), x);
      _mm_storel_pd(&X[p][0], x[0]); _mm_storeh_pd(&X[p + 1][0], x[0]);
      _mm_storel_pd(&X[p][1], x[1]); _mm_storeh_pd(&X[p + 1][1], x[1]);
      _mm_storel_pd(&X[p][2], x[2]); _mm_storeh_pd(&X[p + 1][2], x[2]);
    }
    if (p == q) continue;
    const int p1 = k + 1 < ns ? q : p;       /* with the next face's first, or alone */
    space_lanes_faces(m, sf[k], sf[k + 1 < ns ? k + 1 : k], &L);
    space_lanes_at(&L, _mm_set_pd(px[p1], px[p]), x);
    _mm_storel_pd(&X[p][0], x[0]); _mm_storeh_pd(&X[p1][0], x[0]);
    _mm_storel_pd(&X[p][1], x[1]); _mm_storeh_pd(&X[p1][1], x[1]);
    _mm_storel_pd(&X[p][2], x[2]); _mm_storeh_pd(&X[p1][2], x[2]);
    p = p1 + 1;
  }
#else
  (void)uv; (void)uv512;                    /* (smooth_rows serves nothing without SSE2) */
  for (int k = 0; k < ns; k++)
    for (int p = at[k]; p < at[k + 1]; p++) space_point(m, sf[k], px[p], py, X[p]);
#endif
  smooth_row(&m->sm, m->map, m->e, ns, tri, at, (const double (*)[3])X, blocked, &m->lights,
             g, runs);
  shade_row_greys(g, e - i, gr);
  return e;
}

/* grey[0 .. len) set to v (len >= 1): up to 16 by two stores that may overlap (of 8, 4 or
   1 bytes, each byte of the stretch written v), longer by memset. */
static inline void fill_grey(uint8_t *grey, uint8_t v, int len)
{
  if (len > 16) {
    memset(grey, v, (size_t)len);
    return;
  }
  const uint64_t w = v * UINT64_C(0x0101010101010101);
  if (len >= 8) {
    memcpy(grey, &w, 8);
    memcpy(grey + len - 8, &w, 8);
  } else if (len >= 4) {
    memcpy(grey, &w, 4);
    memcpy(grey + len - 4, &w, 4);
  } else {
    grey[0] = v;
    grey[len / 2] = v;
    grey[len - 1] = v;
  }
}

#ifdef __SSE2__
/* The end of the stretch of points from e on (e <= n) whose blocked mask is b (0: no light
   blocked): the first point at or after e where blocked[] is not b, or n; four compares an
   instruction. */
static inline int same_end(const unsigned *blocked, int e, int n, unsigned b)
{
  const __m128i bv = _mm_set1_epi32((int)b);
  for (; e + 4 <= n; e += 4) {
    const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(blocked + e));
    const unsigned eq = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(v, bv)));
    if (eq != 0xf) return e + __builtin_ctz(~eq);
  }
  while (e < n && blocked[e] == b) e++;
  return e;
}
#endif

#ifdef __SSE2__
/* flat_lit_pairs' greys for n points of a lit face without a texture where the same lights
   b are blocked at each: its operations on the same values with both lanes' masks b, not
   read from blocked[]. Where b holds every point light the sum does not depend on the
   point (flat_lit_pairs' kept sums): one grey for all n, made once.
   A point light's term here (row_dot_axis) takes one square root and one divide a pair.
   A filter in the manner of smooth.c's lit_pair_filter does not pay here (round 38, perf
   under load, three runs each way): with the square root and the divide left out
   altogether (wrong greys; the most any filter could save) this function's share of
   fig6-room's frame fell only from about 11.1% to 10.0% and of fig6-building's from 5.3%
   to 4.8%, and with them made from RSQRTPS and two Newton steps (what a filter without
   the square root needs before its check) it did not fall at all. On fig6-room a call
   has 16 points on average (91 calls, 1,493 points a frame), so the row's set-up
   (flat_row_init) and each call's own steps weigh as much as the pairs' divider work. */
__attribute__((noinline))
static void flat_lit_masked(const struct fx_model *m, int face, const struct shade_pair *P,
                            unsigned b, int n, const double *px, double py,
                            struct flat_row *F, bool *ready, uint8_t *grey)
{
  const __m128d one = _mm_set1_pd(1), zero = _mm_setzero_pd();
  const unsigned pm = point_bits(P);        /* the point lights' bits */
  if ((b & pm) == pm) {
    const unsigned g = shade_pair_greys(one, shade_pair_sum(P, zero, zero, zero, b, b));
    fill_grey(grey, (uint8_t)g, n);         /* (both lanes the same grey) */
    return;
  }
  if (!*ready) {                            /* the row's lanes, once for its stretches */
    flat_row_init(m, face, py, F);
    *ready = true;
  }
#ifdef FLAT_AVX512
  if (F->rowt && P->axis > 0 && flat_wide(m)) {
    flat_rowt8(F, P, NULL, NULL, n, NULL, b, px, grey);
    return;
  }
#endif
  if (F->rowt)
    flat_lit_pairs(F, P, NULL, n, NULL, b, px, grey, true);
  else
    flat_lit_pairs(F, P, NULL, n, NULL, b, px, grey, false);
}
#endif

#ifdef __SSE2__
/* What flat_lit_rest and flat_tex_clear make of a lit face that does not depend on the
   row: its lights made ready for its unit normal (shade_pair_init of face_normal's), and
   its texture's tex_lanes (where it has one). Made the same way at each call before
   (about 135 calls a frame on fig6-room, many on the same face), so made once a face a
   frame (flat_face_of) and read from there: the same doubles. */
struct flat_face {
  struct shade_pair P;
  struct tex_lanes T;       /* (set where the face has a texture) */
};

static void flat_face_init(const struct fx_model *m, const struct face_shade *fs,
                           struct flat_face *ff)
{
  double nrm[3];
  face_normal(fs->mf, nrm);                 /* shade_face_at's normal */
  shade_pair_init(&ff->P, &m->lights, nrm);
  if (fs->t) tex_lanes_init(&ff->T, fs->t);
}

/* fx_points' flat_face of each face it has made one for this frame: at[face] its place in
   kept plus 1, 0 none yet. At most FLAT_KEEP are kept (a flat_face holds up to
   SCENE_LIGHT_MAX lights' lanes, over a kilobyte); beyond them a face's is made again at
   each call, in one spare (spare), as before. at and kept are made at the first call and
   kept grows as faces come, so that a frame without lit flat faces holds none; where an
   allocation fails the spare is used (the same doubles). */
enum { FLAT_KEEP = 512 };

struct flat_cache {
  size_t nface;             /* the map's faces, + 1 */
  int *at;                  /* nface entries, or NULL: none kept */
  bool tried;               /* at's allocation made (or failed) */
  struct flat_face *kept;
  int n, cap;
  struct flat_face spare;
};

static const struct flat_face *flat_face_of(const struct fx_model *m, int face,
                                            const struct face_shade *fs, struct flat_cache *C)
{
  if (C->at && C->at[face]) return &C->kept[C->at[face] - 1];
  if (!C->tried) {
    C->tried = true;
    C->at = calloc(C->nface, sizeof *C->at);
  }
  if (C->at && C->n == C->cap && C->cap < FLAT_KEEP) {
    const int cap = C->cap ? 2 * C->cap : 16;
    struct flat_face *k = realloc(C->kept, (size_t)cap * sizeof *k);
    if (k) {
      C->kept = k;
      C->cap = cap;
    }
  }
  if (!C->at || C->n == C->cap) {           /* not kept: the spare's, made again */
    flat_face_init(m, fs, &C->spare);
    return &C->spare;
  }
  struct flat_face *ff = &C->kept[C->n++];
  flat_face_init(m, fs, ff);
  C->at[face] = C->n;
  return ff;
}
#endif

#ifdef __SSE2__
/* shade_flat_run's lit face from point p on, where p needs shading (a texture, or a light
   blocked at p): the face's normal and its lights made ready (shade_pair_init), then the
   points that need shading two at a time (flat_lit_pairs: all of a textured face's;
   flat_lit_masked: else the stretches where a light is blocked, a stretch of the same
   lights at a time), the others the face's grey. Not inlined:
   shade_flat_run's own path, a run no light is blocked at, stays small. The face's
   lights and texture lanes are C's (flat_face_of). */
__attribute__((noinline))
static void flat_lit_rest(const struct fx_model *m, int face, const struct face_shade *fs,
                          int p, int n, const unsigned *blocked, const double *px, double py,
                          uint8_t *grey, struct flat_cache *C)
{
  const struct mface *mf = fs->mf;
  const struct fx_tex *t = fs->t;
  const struct flat_face *ff = flat_face_of(m, face, fs, C);
  const struct shade_pair *P = &ff->P;
  struct flat_row F;
  bool ready = false;                       /* F made */
  while (p < n) {
    int e = p + 1;
    if (!t && !blocked[p]) {                /* a stretch no light is blocked at: the face's */
      e = same_end(blocked, e, n, 0);       /* grey */
      fill_grey(grey + p, (uint8_t)mf->grey, e - p);
      p = e;
      continue;
    }
    if (t) {                                /* a texture: every point */
      flat_row_init(m, face, py, &F);
#ifdef FLAT_AVX512
      if (flat_tex_wide(m, P, &ff->T, &F, n - p, blocked + p, px + p, grey + p)) return;
#endif
      if (F.rowt)
        flat_lit_pairs(&F, P, &ff->T, n - p, blocked + p, 0, px + p, grey + p, true);
      else
        flat_lit_pairs(&F, P, &ff->T, n - p, blocked + p, 0, px + p, grey + p, false);
      return;
    }
    const unsigned b = blocked[p];          /* a stretch of the same lights blocked */
    e = same_end(blocked, e, n, b);
    flat_lit_masked(m, face, P, b, e - p, px + p, py, &F, &ready, grey + p);
    p = e;
  }
}
#endif

#ifdef __SSE2__
/* flat_lit_rest's greys for a run of n points of a lit textured face (fs) where no light is
   blocked at any point (fx_points knows it from shadow_ranges): flat_lit_pairs' with every
   mask 0, its operations on the same values (where there is no point light its sums at
   X = 0 are those at any X: a parallel light's term is its n.l), without the masks. The
   face's lights and texture lanes are C's (flat_face_of). */
__attribute__((noinline))
static void flat_tex_clear(const struct fx_model *m, int face, const struct face_shade *fs,
                           int n, const double *px, double py, uint8_t *grey,
                           struct flat_cache *C)
{
  const struct flat_face *ff = flat_face_of(m, face, fs, C);
  struct flat_row F;
  flat_row_init(m, face, py, &F);
#ifdef FLAT_AVX512
  if (flat_tex_wide(m, &ff->P, &ff->T, &F, n, NULL, px, grey)) return;
#endif
  if (F.rowt)
    flat_lit_pairs(&F, &ff->P, &ff->T, n, NULL, 0, px, grey, true);
  else
    flat_lit_pairs(&F, &ff->P, &ff->T, n, NULL, 0, px, grey, false);
}
#endif

static void flat_run_rest(const struct fx_model *m, int face, const struct face_shade *fs,
                          int n, const unsigned *blocked, const double *px, double py,
                          uint8_t *grey);

#ifndef __SSE2__
struct flat_cache {         /* (flat_lit_rest's, which is SSE2's) */
  size_t nface;
};
#endif

/* shade_face_at, uncounted, at n >= 1 neighbouring points (px[p], py) of a face that is not
   smoothed (fs: face_shade_of's, fs->tri < 0; n >= 1: fill_grey writes its stretch's last
   byte, grey[n - 1]): the same greys, the face's unit normal
   found once for the run (the same operations on the same values as each point's). Where
   the processor has SSE2 a lit face's points that need shading (all of a textured face's,
   else those where a light is blocked) go two at a time from the space point to the grey
   (flat_lit_rest; flat_lit_pairs, flat_lit_masked), the stretches before the first of them
   the face's grey here; else (flat_run_rest) the lit points' greys SHADE_RUN at a time
   (shade_grey_lit_run), and a textured face that is not lit: its space points and
   reflectances SHADE_RUN at a time (space_points, reflectances). */
static void shade_flat_run(const struct fx_model *m, int face, const struct face_shade *fs,
                           int n, const unsigned *blocked, const double *px, double py,
                           uint8_t *grey, struct flat_cache *C)
{
#ifdef __SSE2__
  if (fs->lit) {
    for (int p = 0; p < n;) {
      if (fs->t || blocked[p]) {
        flat_lit_rest(m, face, fs, p, n, blocked, px, py, grey, C);
        return;
      }
      const int e = same_end(blocked, p + 1, n, 0);          /* no light blocked: the */
      fill_grey(grey + p, (uint8_t)fs->mf->grey, e - p);     /* face's grey */
      p = e;
    }
    return;
  }
#endif
  if (!fs->t && !fs->lit) {                 /* a face of its own grey is not lit */
    fill_grey(grey, (uint8_t)fs->mf->grey, n);
    return;
  }
  flat_run_rest(m, face, fs, n, blocked, px, py, grey);
}

/* shade_flat_run's greys where flat_lit_rest does not make them (see there). */
__attribute__((noinline))
static void flat_run_rest(const struct fx_model *m, int face, const struct face_shade *fs,
                          int n, const unsigned *blocked, const double *px, double py,
                          uint8_t *grey)
{
  const struct mface *mf = fs->mf;
  const struct fx_tex *t = fs->t;
  double X[SHADE_RUN][3], refl[SHADE_RUN], nrm[3];
  unsigned b[SHADE_RUN];
  int at[SHADE_RUN], g[SHADE_RUN], nl = 0;
  bool unit = false;
  if (t) {                                  /* every point's space point and reflectance */
    for (int p = 0; p < n; p += SHADE_RUN) {
      const int c = n - p < SHADE_RUN ? n - p : SHADE_RUN;
      space_points(m, face, c, px + p, py, X);
      reflectances(t, c, (const double (*)[3])X, refl);
      if (!fs->lit) {
        for (int q = 0; q < c; q++) grey[p + q] = (uint8_t)(int)floor(mf->grey * refl[q] + 0.5);
        continue;
      }
      if (!unit) {                          /* shade_face_at's normal */
        face_normal(mf, nrm);
        unit = true;
      }
      shade_grey_lit_run(&m->lights, nrm, c, (const double (*)[3])X, refl, blocked + p, g);
      for (int q = 0; q < c; q++) grey[p + q] = (uint8_t)g[q];
    }
    return;
  }
  if (!fs->lit) {                           /* a face of its own grey is not lit */
    memset(grey, (uint8_t)mf->grey, (size_t)n);
    return;
  }
  for (int p = 0; p < n || nl > 0; p++) {
    if (p < n) {
      const unsigned bp = blocked[p];
      if (!bp) {                            /* a stretch no light is blocked at: the face's */
        int e = p + 1;                      /* grey (four a test: none when their OR is 0) */
        while (e + 4 <= n && !(blocked[e] | blocked[e + 1] | blocked[e + 2] | blocked[e + 3]))
          e += 4;
        while (e < n && !blocked[e]) e++;
        memset(grey + p, (uint8_t)mf->grey, (size_t)(e - p));
        p = e - 1;
        continue;
      }
      space_point(m, face, px[p], py, X[nl]);
      refl[nl] = 1.0;
      b[nl] = bp;
      at[nl++] = p;
      if (nl < SHADE_RUN) continue;
    }
    /* SHADE_RUN lit points, or the last few */
    if (!unit) {                            /* shade_face_at's normal */
      face_normal(mf, nrm);
      unit = true;
    }
    shade_grey_lit_run(&m->lights, nrm, nl, (const double (*)[3])X, refl, b, g);
    for (int q = 0; q < nl; q++) grey[at[q]] = (uint8_t)g[q];
    nl = 0;
  }
}

/* The background's grey at point (i, j) (fx_shade of no face). */
static int shade_none(const struct fx_model *m, int i, int j)
{
  if (!m->bg) return 0;
  i = i < 0 ? 0 : i >= m->W ? m->W - 1 : i;
  j = j < 0 ? 0 : j >= m->H ? m->H - 1 : j;
  return m->bg[(size_t)j * (size_t)m->W + (size_t)i];
}

int fx_shade(const struct fx_model *m, int face, unsigned blocked, double u, double v,
             int i, int j, struct cost *cost, int *region)
{
  if (face < 0) {
    if (region) *region = -1;
    return shade_none(m, i, j);
  }
  struct face_shade fs;
  face_shade_of(m, face, &fs);
  return shade_face_at(m, face, &fs, blocked, plane_x(m->g, u), plane_y(m->g, v),
                       m->count ? cost : NULL, region);
}

/* ---- lines --------------------------------------------------------------------------- */

/* A chain of a cut polygon's ring (cut_chains): m edges, from points pt[0 .. m] (ring
   order) whose y never falls (up) or never rises; [ylo, yhi) the rows whose line it
   crosses (then at one edge, j: the last one found). */
struct cut_chain { const struct gpoint *pt; int m, j; bool up; gcoord ylo, yhi; };

struct fx_lines {
  const struct fx_model *m;
  struct cost *cost;
  bool spans;               /* by the engine's stretches (else sample by sample) */
  struct fx_see *see;       /* the engine's answers */
  struct fx_see **behind;   /* per cut object: the same with the object's faces taken away */
  struct cut_range { int k0, k1; int64_t ylo, yhi; } *cr;   /* per cut object: its regions,
                              m->cuts.p[k0 .. k1), and the rows [ylo, yhi) they span */
  struct fx_span *a, *b;    /* the line's stretches, and scratch */
  int na, cap;              /* na: a's stretches; cap: a's and b's room */
  struct grat *x;           /* crossings */
  int xcap;
  struct ev { struct grat x; double k; int light, d; } *ev, *evt;   /* events (k: ev_key's),
                                                                       and ev_sort's room */
  int evcap;
  int *brow; size_t browcap;   /* samples: the row behind a cut object */
  int *bnd; size_t bndcap;     /* samples: per event, the first sample at or right of it */
  uint64_t *cutbit; size_t cutbitcap;   /* cut_bits: a row's samples a cut object's regions
                               hold, a bit each */
  struct cut_chain *cc;     /* cut_bits: the cut polygons' rings in chains (cut_chains) */
  bool track;               /* cut_samples notes each sample it writes (cut_note): */
  uint64_t *touch; size_t touchcap;   /* a bit a sample written on the row, */
  int *orig; size_t origcap;          /* and its face before the first write */
  int *ccf;                 /* per cut polygon its first chain (cuts.n + 1 of them) */
  struct gpoint *cpt;       /* the points of the chains that hold a ring's last edge */
  /* samples on a rising window (shadow_samples): the row's stretches of each face's shadows
     as ranges of samples [b0, b1), found at the face's first run on the row (row: the
     row's number, counted from 1, when found) */
  struct brange { int b0, b1, light; } *rng;
  int nrng;
  size_t rngcap;
  struct { long row; int at, n; bool ext; gcoord ylo, yhi; } *fr;   /* per mapped face: its
                               ranges on the row (row, at, n; shadow_ranges) and its shadow
                               polygons' rows, ylo <= fy < yhi for any (ext: found) */
  long row;
  struct poly_step *ps;     /* per shadow polygon: its two stretch ends stepped from row to
                               row (face_ranges), or NULL (none kept) */
  struct edge_wide *psw;    /* per shadow polygon two: its steps' edges' 128-bit values */
  int *rend, rendn;         /* the last row's runs of one face (shadow_ranges): at each
                               run's first sample its end e, or -e where a light is blocked
                               at a sample of the run; rendn samples, 0 when not found */
  size_t rendcap;
  uint64_t *runbit; size_t runbitcap;   /* shadow_ranges: a row's run ends (run_bits) */
  int nblk;                 /* the last row's samples with a light blocked (shadow_ranges),
                               or -1 when not counted */
  struct fx_sample_row sr;  /* shadow_ranges' row of samples, kept while its xd, k0 and n
                               are asked again (srn: its n, or -1 when none kept) */
  int srn;
  int64_t sryd;             /* the yd of the last line shadow_ranges was asked */
  unsigned sgen;            /* counts the changes of sr or sryd: a step made for one (sgen
                               then) holds for the rows of samples asked until the next */
};

static bool room(struct fx_lines *L, int n)
{
  if (n <= L->cap) return true;
  int cap = L->cap ? L->cap : 64;
  while (cap < n) cap *= 2;
  struct fx_span *na = realloc(L->a, (size_t)cap * sizeof *na);
  if (!na) return false;
  L->a = na;
  struct fx_span *nb = realloc(L->b, (size_t)cap * sizeof *nb);
  if (!nb) return false;
  L->b = nb;
  L->cap = cap;
  return true;
}

int fx_lines_open(struct fx_lines **out, const struct fx_model *m, bool by_samples,
                  struct cost *cost, struct t74_error *err)
{
  struct fx_lines *L = calloc(1, sizeof *L);
  if (!L) return t74_fail(err, T74_EIO, "out of host memory");
  L->m = m;
  L->cost = cost;
  int rc = fx_see_open(&L->see, m->eng, NULL, cost, err);
  if (rc == T74_OK && m->ncut) {
    L->behind = calloc((size_t)m->ncut, sizeof *L->behind);
    if (!L->behind) rc = t74_fail(err, T74_EIO, "out of host memory");
    for (int q = 0; rc == T74_OK && q < m->ncut; q++)
      rc = fx_see_open(&L->behind[q], m->eng, m->cut_skip[q], cost, err);
    L->cr = rc == T74_OK ? malloc((size_t)m->ncut * sizeof *L->cr) : NULL;
    if (rc == T74_OK && !L->cr) rc = t74_fail(err, T74_EIO, "out of host memory");
    for (int q = 0; rc == T74_OK && q < m->ncut; q++) {
      struct cut_range *c = &L->cr[q];
      *c = (struct cut_range){ -1, -1, INT64_MAX, INT64_MIN };
      for (int k = 0; k < m->cuts.n; k++) {
        const struct fx_poly *p = &m->cuts.p[k];
        if (p->owner != m->cut_obj[q]) continue;
        if (c->k0 < 0) c->k0 = k;
        c->k1 = k + 1;
        if (p->ylo < c->ylo) c->ylo = p->ylo;
        if (p->yhi > c->yhi) c->yhi = p->yhi;
      }
    }
  }
  if (rc != T74_OK) { fx_lines_close(L); return rc; }
  L->spans = !by_samples && fx_see_has_spans(L->see);
  L->srn = -1;
  L->nblk = -1;
  *out = L;
  return T74_OK;
}

bool fx_lines_have_spans(const struct fx_lines *L) { return L->spans; }

void fx_lines_close(struct fx_lines *L)
{
  if (!L) return;
  fx_see_close(L->see);
  if (L->behind)
    for (int q = 0; q < L->m->ncut; q++) fx_see_close(L->behind[q]);
  free(L->behind);
  free(L->cr);
  free(L->a); free(L->b); free(L->x); free(L->ev); free(L->evt); free(L->brow); free(L->bnd);
  free(L->cutbit); free(L->cc); free(L->ccf); free(L->cpt); free(L->touch); free(L->orig);
  free(L->rng); free(L->fr); free(L->ps); free(L->psw); free(L->rend); free(L->runbit);
  free(L);
}

static struct grat rmax(struct grat p, struct grat q) { return geom_rat_cmp(p, q) >= 0 ? p : q; }
static struct grat rmin(struct grat p, struct grat q) { return geom_rat_cmp(p, q) <= 0 ? p : q; }

/* An event's x in a double (geom_rat_key), and the order of two events' x from them
   (fx_x_cmp: exact). */
static inline double ev_key(struct grat x) { return geom_rat_key(x); }

static inline int ev_cmp(const struct ev *a, const struct ev *b)
{
  return fx_x_cmp(&a->x, a->k, &b->x, b->k);
}

/* Room in L->x for polygon p's crossings with a line (one at most a point); false when
   out of host memory. */
static bool cross_room(struct fx_lines *L, const struct fx_poly *p)
{
  const int need = p->rs[p->nring];
  if (need <= L->xcap) return true;
  struct grat *nx = realloc(L->x, (size_t)need * sizeof *nx);
  if (!nx) return false;
  L->x = nx;
  L->xcap = need;
  return true;
}

/* The crossings of every polygon in [k0, k1) of ps with the line, as stretches appended
   to L->ev (d = +1 at a start, -1 at an end; light from the polygon). */
static int stretches(struct fx_lines *L, const struct fx_polys *ps, int k0, int k1, int64_t yn,
                     int64_t yd, int *nev, struct t74_error *err)
{
  const int64_t fy = fx_line_row(yn, yd);
  for (int k = k0; k < k1; k++) {
    const struct fx_poly *p = &ps->p[k];
    if (!fx_poly_on_row(p, fy)) continue;   /* the line misses its box */
    if (!cross_room(L, p)) return t74_fail(err, T74_EIO, "out of host memory");
    int nx = fx_poly_cross(p, yn, yd, L->x, L->xcap, L->m->count ? L->cost : NULL);
    if (*nev + nx > L->evcap) {
      int cap = L->evcap ? L->evcap : 64;
      while (cap < *nev + nx) cap *= 2;
      struct ev *ne = realloc(L->ev, (size_t)cap * sizeof *ne);
      if (!ne) return t74_fail(err, T74_EIO, "out of host memory");
      L->ev = ne;
      if (!(ne = realloc(L->evt, (size_t)cap * sizeof *ne)))
        return t74_fail(err, T74_EIO, "out of host memory");
      L->evt = ne;
      L->evcap = cap;
    }
    for (int h = 0; h + 1 < nx; h += 2) {
      if (geom_rat_cmp(L->x[h], L->x[h + 1]) >= 0) continue;
      L->ev[(*nev)++] = (struct ev){ L->x[h], ev_key(L->x[h]), p->light, +1 };
      L->ev[(*nev)++] = (struct ev){ L->x[h + 1], ev_key(L->x[h + 1]), p->light, -1 };
    }
  }
  return T74_OK;
}

/* Sort ev[0..n) by x, stable (events of one x keep their order): a few in place, more
   by merging sorted halves through tmp (room for n). */
static void ev_sort(struct ev *ev, struct ev *tmp, int n)
{
  if (n > 32) {
    const int h = n / 2;
    ev_sort(ev, tmp, h);
    ev_sort(ev + h, tmp, n - h);
    if (ev_cmp(&ev[h - 1], &ev[h]) <= 0) return;   /* already in order */
    int a = 0, b = h, k = 0;
    while (a < h && b < n) tmp[k++] = ev_cmp(&ev[b], &ev[a]) < 0 ? ev[b++] : ev[a++];
    while (a < h) tmp[k++] = ev[a++];
    memcpy(ev, tmp, (size_t)k * sizeof *ev);   /* the rest of the right half is in place */
    return;
  }
  for (int k = 1; k < n; k++) {
    struct ev e = ev[k];
    int h = k;
    while (h > 0 && ev_cmp(&ev[h - 1], &e) > 0) { ev[h] = ev[h - 1]; h--; }
    ev[h] = e;
  }
}

/* The stretches of cut object q's regions on the line, sorted, into L->ev[0..*nev) (they
   do not overlap: each region lies at its own corner). */
static int cut_stretches(struct fx_lines *L, int q, int64_t yn, int64_t yd, int *nev,
                         struct t74_error *err)
{
  const struct fx_model *m = L->m;
  const int k0 = L->cr[q].k0, k1 = L->cr[q].k1;   /* (fx_lines_open's) */
  *nev = 0;
  if (k0 < 0) return T74_OK;
  int rc = stretches(L, &m->cuts, k0, k1, yn, yd, nev, err);
  if (rc == T74_OK) ev_sort(L->ev, L->evt, *nev);
  return rc;
}

/* Cut object q's regions out of its stretches on the line. */
static int cut_line(struct fx_lines *L, int q, int64_t yn, int64_t yd, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  int nev;
  int rc = cut_stretches(L, q, yn, yd, &nev, err);
  if (rc != T74_OK || nev == 0) return rc;
  const uint8_t *skip = m->cut_skip[q];
  bool hit = false;
  for (int s = 0; s < L->na && !hit; s++) hit = skip[L->a[s].face] != 0;
  if (!hit) return T74_OK;
  const struct vis_span *bs;
  int nbs;
  if ((rc = fx_see_spans(L->behind[q], yn, yd, &bs, &nbs, err)) != T74_OK) return rc;
  int nb = 0;
  for (int s = 0; s < L->na; s++) {
    struct fx_span sp = L->a[s];
    if (!skip[sp.face]) {
      if (!room(L, nb + 1)) return t74_fail(err, T74_EIO, "out of host memory");
      L->b[nb++] = sp;
      continue;
    }
    /* walk the cut stretches across sp: outside them sp stays, inside the line behind */
    struct grat at = sp.x0;
    for (int h = 0; h + 1 < nev && geom_rat_cmp(at, sp.x1) < 0; h += 2) {
      struct grat c0 = rmax(L->ev[h].x, at), c1 = rmin(L->ev[h + 1].x, sp.x1);
      if (geom_rat_cmp(c0, c1) >= 0) continue;
      if (!room(L, nb + 2 + nbs)) return t74_fail(err, T74_EIO, "out of host memory");
      if (geom_rat_cmp(at, c0) < 0) { L->b[nb] = sp; L->b[nb].x0 = at; L->b[nb++].x1 = c0; }
      for (int k = 0; k < nbs; k++) {
        struct grat b0 = rmax(bs[k].x0, c0), b1 = rmin(bs[k].x1, c1);
        if (geom_rat_cmp(b0, b1) >= 0) continue;
        L->b[nb++] = (struct fx_span){ b0, b1, bs[k].piece, bs[k].face, 0 };
      }
      at = c1;
    }
    if (geom_rat_cmp(at, sp.x1) < 0) {
      if (!room(L, nb + 1)) return t74_fail(err, T74_EIO, "out of host memory");
      L->b[nb] = sp; L->b[nb++].x0 = at;
    }
    COST_ADD_N(L->cost, COST_ADD, (uint64_t)nev); COST_ADD_N(L->cost, COST_BRANCH, (uint64_t)nev);
  }
  struct fx_span *t = L->a; L->a = L->b; L->b = t;
  L->na = nb;
  return T74_OK;
}

/* Split the stretches where shadows begin and end. */
static int shadow_line(struct fx_lines *L, int64_t yn, int64_t yd, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  int nb = 0;
  for (int s = 0; s < L->na; s++) {
    struct fx_span sp = L->a[s];
    int nev = 0;
    int rc = stretches(L, &m->shadows, m->shadow_first[sp.face], m->shadow_first[sp.face + 1],
                       yn, yd, &nev, err);
    if (rc != T74_OK) return rc;
    if (!room(L, nb + 2 * nev + 1)) return t74_fail(err, T74_EIO, "out of host memory");
    if (nev == 0) { L->b[nb++] = sp; continue; }
    ev_sort(L->ev, L->evt, nev);
    int cnt[SCENE_LIGHT_MAX] = { 0 };
    unsigned mask = 0;
    struct grat at = sp.x0;
    int h = 0;
    /* the events at or left of the stretch's start set its first mask */
    while (h < nev && geom_rat_cmp(L->ev[h].x, at) <= 0) {
      cnt[L->ev[h].light] += L->ev[h].d;
      h++;
    }
    for (int k = 0; k < SCENE_LIGHT_MAX; k++) if (cnt[k] > 0) mask |= 1u << k;
    while (geom_rat_cmp(at, sp.x1) < 0) {
      struct grat nx = h < nev ? rmin(L->ev[h].x, sp.x1) : sp.x1;
      if (geom_rat_cmp(at, nx) < 0) {
        if (nb > 0 && L->b[nb - 1].face == sp.face && L->b[nb - 1].piece == sp.piece &&
            L->b[nb - 1].blocked == mask && geom_rat_cmp(L->b[nb - 1].x1, at) == 0)
          L->b[nb - 1].x1 = nx;
        else
          L->b[nb++] = (struct fx_span){ at, nx, sp.piece, sp.face, mask };
      }
      at = nx;
      if (h >= nev) break;
      while (h < nev && geom_rat_cmp(L->ev[h].x, at) <= 0) {
        cnt[L->ev[h].light] += L->ev[h].d;
        h++;
      }
      mask = 0;
      for (int k = 0; k < SCENE_LIGHT_MAX; k++) if (cnt[k] > 0) mask |= 1u << k;
      COST_ADD_N(L->cost, COST_ADD, 2); COST_ADD_N(L->cost, COST_BRANCH, 2);
    }
  }
  struct fx_span *t = L->a; L->a = L->b; L->b = t;
  L->na = nb;
  return T74_OK;
}

int fx_lines_get(struct fx_lines *L, int64_t yn, int64_t yd, const struct fx_span **span,
                 int *nspan, struct t74_error *err)
{
  const struct vis_span *vs;
  int nv;
  int rc = fx_see_spans(L->see, yn, yd, &vs, &nv, err);
  if (rc != T74_OK) return rc;
  if (!room(L, nv + 1)) return t74_fail(err, T74_EIO, "out of host memory");
  for (int k = 0; k < nv; k++) L->a[k] = (struct fx_span){ vs[k].x0, vs[k].x1, vs[k].piece, vs[k].face, 0 };
  L->na = nv;
  for (int q = 0; q < L->m->ncut && rc == T74_OK; q++) rc = cut_line(L, q, yn, yd, err);
  if (rc == T74_OK && L->m->shadows.n) rc = shadow_line(L, yn, yd, err);
  if (rc != T74_OK) return rc;
  *span = L->a;
  *nspan = L->na;
  return T74_OK;
}

/* ---- samples ------------------------------------------------------------------------- */

/* Does the sample at xn / xd lie in one of the stretches [ev[h], ev[h + 1]) (h even)? */
static bool in_stretches(const struct ev *ev, int nev, int64_t xn, int64_t xd)
{
  for (int h = 0; h + 1 < nev; h += 2)
    if (geom_rat_cmp_frac(ev[h].x, xn, xd) <= 0 && geom_rat_cmp_frac(ev[h + 1].x, xn, xd) > 0)
      return true;
  return false;
}

/* Event e counted into its light's count cnt: the lights' mask after it (a light is in
   it while its count is positive). */
static inline unsigned ev_count(const struct ev *e, int *cnt, unsigned mask)
{
  const int k = e->light;
  cnt[k] += e->d;
  return cnt[k] > 0 ? mask | 1u << k : mask & ~(1u << k);
}

/* ---- a cut object's regions on a rising row of samples, in integers ----
   On a rising row (fx_sample_row: sample i at xn_i / xd, xn_i = G (c + 2 S i),
   c = xd XL + (2 k0 + 1) S, S > 0, G = GRID_ONE) the first sample at or right of an edge's
   crossing x = N / D with the line y = yn / yd (fx_poly_cross's rational: N = -(lb yn +
   lc yd), D = la yd, both signs changed where D < 0, so D > 0) is the least i in [0, n]
   with N xd <= D xn_i (xd > 0), that is with P <= Q i, P = N xd - D G c, Q = 2 G S D > 0:
   ceil(P / Q) put into [0, n], fx_first_at_or_right's index exactly. Here every product
   and sum is taken in 64 bits with a check for overflow, so each value is exact where
   none overflows (then the row goes the long way, cut_stretches): one divide a crossing,
   no rational made, compared or sorted.
   Which samples the regions hold: cut_samples' long way pairs the sorted ends of the
   polygons' stretches, [b_0, b_1), [b_2, b_3), ..., b_h the events' indices, in x's order
   and so not falling. A sample i lies in one of those ranges exactly when an odd number
   of the b_h are at or left of it (i in [b_2r, b_2r+1) is 2r + 1 of them). The b_h are
   the indices of every crossing of every polygon on the line but for pairs of equal
   crossings (fx_poly_cross's empty stretches, x_h = x_h+1, left out by stretches), which
   have equal indices and change no count's parity. So a sample is cut exactly when the
   count of crossings, of all the polygons, whose index is at or left of it is odd: each
   crossing's index flips a bit (cut_bits), and a prefix XOR along the row gives the
   parity at each sample. */

/* The index (above) of the crossing of edge p0 -> p1 (p0.y != p1.y: its ends on either side
   of the line) into *at; false when a value leaves 64 bits. Gc = G c and Q1 = 2 G S. */
static inline bool cut_index(struct gpoint p0, struct gpoint p1, int64_t yn, int64_t yd,
                             int64_t xd, int64_t Gc, int64_t Q1, int n, int *at)
{
  /* cross_edge's line (poly.c): la, lb, lc within 64 bits on the grid (geom.h) */
  const int64_t la = p0.y - p1.y, lb = p1.x - p0.x, lc = -(la * p0.x + lb * p0.y);
  int64_t t0, t1, M, D, P, Q;
  /* the overflow tests without branches, each its own statement: a value one writes
     another reads, and operands of | are not sequenced (a call's are indeterminately) */
  bool o = __builtin_mul_overflow(lb, yn, &t0);
  o |= __builtin_mul_overflow(lc, yd, &t1);
  o |= __builtin_add_overflow(t0, t1, &M);
  o |= __builtin_mul_overflow(la, yd, &D);
  if (o || M == INT64_MIN || D == INT64_MIN) return false;
  const int64_t N = D < 0 ? M : -M;         /* N = -M, both signs changed where D < 0 */
  D = D < 0 ? -D : D;
  o = __builtin_mul_overflow(N, xd, &t0);
  o |= __builtin_mul_overflow(D, Gc, &t1);
  o |= __builtin_sub_overflow(t0, t1, &P);
  o |= __builtin_mul_overflow(D, Q1, &Q);
  if (o) return false;
  /* ceil(P / Q), Q > 0: C's quotient truncates toward 0, the ceiling for P <= 0 and the
     floor for P > 0, one less than the ceiling there when the rest is not 0 */
  const int64_t i = P / Q + (P % Q > 0);
  *at = i <= 0 ? 0 : i >= n ? n : (int)i;
  return true;
}

/* The cut polygons' rings as chains into L->cc, L->ccf and L->cpt, made once a frame (L's):
   each ring cut, from its first point on, where an edge's y rises after one that falls or
   falls after one that rises (edges of one y go with the chain they meet), so each
   chain's y never falls or never rises. An edge crosses a line (its ends on either side,
   a point on the line counting as above it: y <= fy the other side from y > fy) exactly
   when in a chain of points y_0 <= .. <= y_m it is the edge j with y_j <= fy < y_j+1 (the
   edges before it have both ends at or below y_j, those after it both above y_j+1), there
   when y_0 <= fy < y_m; likewise y_j+1 <= fy < y_j in a chain whose y never rises, there
   when y_m <= fy < y_0. So a ring's crossing edges are its chains' one each, where the
   line lies in the chain's range, and a chain's is found from the last one it found,
   a step for each point the line passes (rows asked in order: a few points a row). A
   chain's points are the polygon's own, but for the chain holding the ring's last edge
   (from its last point back to its first), whose points are copied into L->cpt with the
   first one after them. */
static int cut_chains(struct fx_lines *L, struct t74_error *err)
{
  const struct fx_polys *ps = &L->m->cuts;
  size_t ne = 0, nr = 0;                    /* edges (a chain has one or more), rings */
  for (int k = 0; k < ps->n; k++) {
    ne += (size_t)ps->p[k].rs[ps->p[k].nring];
    nr += (size_t)ps->p[k].nring;
  }
  L->cc = malloc((ne + 1) * sizeof *L->cc);
  L->ccf = malloc(((size_t)ps->n + 1) * sizeof *L->ccf);
  L->cpt = malloc((ne + nr + 1) * sizeof *L->cpt);   /* a ring's points and its first again */
  if (!L->cc || !L->ccf || !L->cpt) return t74_fail(err, T74_EIO, "out of host memory");
  int nc = 0;
  size_t ncpt = 0;
  for (int k = 0; k < ps->n; k++) {
    const struct fx_poly *p = &ps->p[k];
    L->ccf[k] = nc;
    for (int r = 0; r < p->nring; r++) {
      const int np = p->rs[r + 1] - p->rs[r];
      const struct gpoint *pt = p->pt + p->rs[r];
      for (int v = 0; v < np;) {            /* a chain from point v */
        /* its edges e -> e + 1 (in place): those of one y, then the first whose y rises
           or falls (its direction, dir), then every one whose y does not go the other
           way (one compare an edge, where finding each edge's direction and comparing it
           with dir took several) */
        int dir = 0, e = v;
        while (e + 1 < np && pt[e + 1].y == pt[e].y) e++;
        if (e + 1 < np) {
          dir = pt[e + 1].y > pt[e].y ? 1 : -1;
          e++;
          if (dir > 0)
            while (e + 1 < np && pt[e + 1].y >= pt[e].y) e++;
          else
            while (e + 1 < np && pt[e + 1].y <= pt[e].y) e++;
        }
        bool last = false;                  /* the ring's last edge, back to its first point */
        if (e + 1 == np) {
          const int d = (pt[0].y > pt[e].y) - (pt[0].y < pt[e].y);
          last = !(d && d == -dir);
          dir = last && d ? d : dir;
        }
        struct cut_chain *c = &L->cc[nc++];
        c->m = e - v + last;
        if (last) {                         /* its points copied, the first one after them */
          struct gpoint *q = L->cpt + ncpt;
          memcpy(q, pt + v, (size_t)(np - v) * sizeof *q);
          q[np - v] = pt[0];
          ncpt += (size_t)(np - v) + 1;
          c->pt = q;
        } else {
          c->pt = pt + v;
        }
        c->up = dir >= 0;
        c->j = c->up ? 0 : c->m - 1;        /* (rows asked bottom up: each chain's lowest) */
        const gcoord ya = c->pt[0].y, yb = c->pt[c->m].y;
        c->ylo = c->up ? ya : yb;
        c->yhi = c->up ? yb : ya;
        v = last ? np : e;
      }
    }
  }
  L->ccf[ps->n] = nc;
  return T74_OK;
}

/* The samples k0 .. k0 + n - 1 of a rising row that cut object q's regions hold on the
   line yn / yd (row fy), as bits L->cutbit[0 .. (n + 63) / 64) (above); *made false when
   a value leaves 64 bits (the long way then). Every polygon of the object's range in
   cuts whose box the row meets, its crossing edges found from its chains (cut_chains:
   the edges fx_poly_cross finds, in another order, which the bits do not see). */
static int cut_bits(struct fx_lines *L, int q, int64_t yn, int64_t yd, int64_t fy, int64_t xd,
                    int64_t k0, int n, bool *made, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  const int32_t *win = m->g->window;
  const int64_t S = (int64_t)win[2] - win[0];
  *made = false;
  int64_t t0, t1, c, Gc, Q1;
  if (xd <= 0 || yd <= 0 || k0 <= -((int64_t)1 << 40) || k0 >= (int64_t)1 << 40) return T74_OK;
  bool o = __builtin_mul_overflow(xd, (int64_t)win[0], &t0);   /* each its own statement */
  o |= __builtin_mul_overflow(2 * k0 + 1, S, &t1);             /* (as cut_index's) */
  o |= __builtin_add_overflow(t0, t1, &c);
  o |= __builtin_mul_overflow(GRID_ONE, c, &Gc);
  o |= __builtin_mul_overflow(2 * GRID_ONE, S, &Q1);
  if (o) return T74_OK;
  const int nw = (n + 63) / 64;
  if (!t74_grow((void **)&L->cutbit, &L->cutbitcap, (size_t)nw, sizeof *L->cutbit))
    return t74_fail(err, T74_EIO, "out of host memory");
  if (!L->cc) {
    const int rc = cut_chains(L, err);
    if (rc != T74_OK) return rc;
  }
  uint64_t *bit = L->cutbit;
  /* a row of up to 256 samples (four words) keeps its bits in registers (b[0 .. 3]: the
     flips by masks, no branch) and stores each word once, after its prefix; else they are
     flipped in L->cutbit. (In memory a row's flips of one word followed one another
     through its loads and stores, and the prefix waited for the last.) */
  const bool small = nw <= 4;
  uint64_t b[4] = { 0, 0, 0, 0 };
  if (!small) memset(bit, 0, (size_t)nw * sizeof *bit);
  const struct fx_poly *const cp = m->cuts.p;
  for (int k = L->cr[q].k0; k < L->cr[q].k1; k++) {
    if (!fx_poly_on_row(&cp[k], fy)) continue;   /* the line misses its box */
    for (int h = L->ccf[k]; h < L->ccf[k + 1]; h++) {
      struct cut_chain *ch = &L->cc[h];
      if (fy < ch->ylo || fy >= ch->yhi) continue;   /* the line misses the chain */
      const struct gpoint *pt = ch->pt;
      int j = ch->j;
      if (ch->up) {                          /* y_j <= fy < y_j+1 */
        while (pt[j + 1].y <= fy) j++;
        while (pt[j].y > fy) j--;
      } else {                              /* y_j+1 <= fy < y_j */
        while (pt[j + 1].y > fy) j++;
        while (pt[j].y <= fy) j--;
      }
      ch->j = j;
      int i;
      if (!cut_index(pt[j], pt[j + 1], yn, yd, xd, Gc, Q1, n, &i)) return T74_OK;
      if (i >= n) continue;
      const uint64_t flip = (uint64_t)1 << (i & 63);
      if (small) {
        const int w = i >> 6;
        b[0] ^= w == 0 ? flip : 0;
        b[1] ^= w == 1 ? flip : 0;
        b[2] ^= w == 2 ? flip : 0;
        b[3] ^= w == 3 ? flip : 0;
      } else {
        bit[i >> 6] ^= flip;
      }
    }
  }
  /* the prefix XOR: bit i the parity of the flips at or left of i (within a word by
     doubling steps, then the words' carry: the last bit of the word before) */
  uint64_t carry = 0;
  for (int w = 0; w < nw; w++) {
    uint64_t x = small ? b[w] : bit[w];
    x ^= x << 1; x ^= x << 2; x ^= x << 4; x ^= x << 8; x ^= x << 16; x ^= x << 32;
    x ^= carry;
    carry = (uint64_t)0 - (x >> 63);
    bit[w] = x;
  }
  if (n & 63) bit[nw - 1] &= ((uint64_t)1 << (n & 63)) - 1;   /* (samples n .. : none) */
  *made = true;
  return T74_OK;
}

/* The row behind cut object q into L->brow (fx_see_row's, at the row's samples). */
static int behind_row(struct fx_lines *L, int q, int K, int64_t mrow, int64_t k0, int n,
                      struct t74_error *err)
{
  if (!t74_grow((void **)&L->brow, &L->browcap, (size_t)n, sizeof *L->brow))
    return t74_fail(err, T74_EIO, "out of host memory");
  return fx_see_row(L->behind[q], K, mrow, k0, n, L->brow, err);
}

/* Sample i of face about to be written by cut_samples: where L->track, its bit set in
   L->touch and its face before the row's first write kept in L->orig (fx_points then
   counts the cut from those samples alone). */
static inline void cut_note(struct fx_lines *L, const int *face, int i)
{
  if (!L->track) return;
  const uint64_t b = (uint64_t)1 << (i & 63);
  if (!(L->touch[i >> 6] & b)) {
    L->touch[i >> 6] |= b;
    L->orig[i] = face[i];
  }
}

/* Cut object q's regions out of a row of samples: a sample showing one of the object's
   faces inside a region shows what the engine sees there without the object (cut_line's
   answer, sample by sample). */
static int cut_samples(struct fx_lines *L, int q, int K, int64_t mrow, int64_t yn, int64_t yd,
                       int64_t xd, int64_t k0, int n, int *face, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  const uint8_t *skip = m->cut_skip[q];
  /* a row outside every region's height range has nothing cut: no scan for the object */
  const int64_t fy = fx_line_row(yn, yd);
  const struct cut_range *c = &L->cr[q];
  bool near = false;
  if (fy >= c->ylo && fy < c->yhi)          /* (else no region's rows hold it) */
    for (int k = c->k0; k < c->k1 && !near; k++)
      near = m->cuts.p[k].owner == m->cut_obj[q] && fx_poly_on_row(&m->cuts.p[k], fy);
  if (!near) return T74_OK;
  const int32_t *win = m->g->window;
  const bool rising = win[2] > win[0];
  int rc;
  if (rising && !m->count) {
    /* (no scan for the object's faces first: the bits are few steps, and their samples
       are the only ones looked at; the 1974 engine's machine counts fx_poly_cross's work:
       its way) */
    bool made;
    if ((rc = cut_bits(L, q, yn, yd, fy, xd, k0, n, &made, err)) != T74_OK) return rc;
    if (made) {                             /* the held samples showing the object's faces */
      /* nothing behind the object (fx_see_row_none: the row behind all -1): -1 without
         the row; else the row behind made at the first sample that needs it */
      const bool none = fx_see_row_none(L->behind[q], K, mrow, k0, n);
      bool behind = none;
      for (int w = 0; w < (n + 63) / 64; w++)
        for (uint64_t b = L->cutbit[w]; b; b &= b - 1) {
          const int i = 64 * w + __builtin_ctzll(b);
          if (face[i] < 0 || !skip[face[i]]) continue;
          if (!behind && (rc = behind_row(L, q, K, mrow, k0, n, err)) != T74_OK) return rc;
          behind = true;
          cut_note(L, face, i);
          face[i] = none ? -1 : L->brow[i];
        }
      return T74_OK;
    }
  }
  bool hit = false;
  for (int i = 0; i < n && !hit; i++) {
    /* none seen at four samples (their AND negative exactly when all four are -1) */
    if (i + 4 <= n && (face[i] & face[i + 1] & face[i + 2] & face[i + 3]) < 0) { i += 3; continue; }
    hit = face[i] >= 0 && skip[face[i]];
  }
  if (!hit) return T74_OK;
  int nev;
  rc = cut_stretches(L, q, yn, yd, &nev, err);
  if (rc != T74_OK || nev == 0) return rc;
  bool behind = false;
  /* samples left to right (xn rising): each event's first sample at or right of it found
     once (bnd, fx_first_at_or_right); a sample lies in a stretch exactly when it lies in the
     stretch's range of samples (the events are sorted, the ranges in order and apart).
     Else each sample of the row is tested. */
  const int np = rising ? nev / 2 : 1;
  if (!t74_grow((void **)&L->bnd, &L->bndcap, 2 * (size_t)np, sizeof *L->bnd))
    return t74_fail(err, T74_EIO, "out of host memory");
  if (!rising) { L->bnd[0] = 0; L->bnd[1] = n; }
  struct fx_sample_row sr;
  if (rising) fx_sample_row_set(&sr, win, xd, k0, n);
  for (int h = 0; rising && h < 2 * np; h++)
    L->bnd[h] = fx_first_at_or_right(&L->ev[h].x, L->ev[h].k, &sr);
  for (int r = 0; r < np; r++)
    for (int i = L->bnd[2 * r]; i < L->bnd[2 * r + 1]; i++) {
      if (face[i] < 0 || !skip[face[i]]) continue;
      if (!rising) {
        int64_t xn = GRID_ONE * (xd * win[0] + (2 * (k0 + i) + 1) * ((int64_t)win[2] - win[0]));
        if (!in_stretches(L->ev, nev, xn, xd)) continue;
      }
      if (!behind && (rc = behind_row(L, q, K, mrow, k0, n, err)) != T74_OK) return rc;
      behind = true;
      cut_note(L, face, i);
      face[i] = L->brow[i];
    }
  return T74_OK;
}

/* ---- a shadow's ends from row to row ----
   On a rising row of samples (fx_sample_row: sample i at xn_i / xd, xn_i = G (xd XL +
   (2 (k0 + i) + 1) S), S > 0, G = GRID_ONE) the first sample at or right of the crossing
   x = N / D of an edge with the line y = yn / yd (N = -(lb yn + lc yd), D = la yd > 0
   after a change of both signs; fx_poly_cross's rational) is the least i in [0, n] with
   N xd <= D xn_i, that is with P <= Q i, P = N xd - D G (xd XL + (2 k0 + 1) S),
   Q = 2 G S D > 0: ceil(P / Q) put into [0, n] (fx_first_at_or_right's answer, exactly).
   P is affine in yn: the next line, yn + dyn, has P + dP, dP = -lb dyn xd. With
   P = q Q + r, 0 <= r < Q, and dP = dq Q + dr, 0 <= dr < Q, the next P is
   (q + dq) Q + (r + dr), r + dr < 2 Q: one subtraction of Q at most puts it back in
   [0, Q). So a polygon whose line crosses two edges keeps their q, r from row to row
   while the row lies in the same band between its vertices' heights (the same two edges
   cross it) and the samples are the same (yd, xd, k0, n): each row's ends two additions.
   An edge's q, r hold for its own line whatever the band: where the row passes a vertex
   and one of the two edges is still crossed, that edge is stepped on and only the new
   one started (fig6-building: about a third of the restarts).
   Rows and lines outside the bounds that keep every product within 128 bits (step_bounds,
   |yn| < 2^61) go the long way (fx_poly_cross), and the quotients are guessed in doubles
   and then corrected exactly.
   An edge whose Q is below 2^62 keeps r, Q and dr in 64-bit integers (r + dr < 2 Q < 2^63:
   the step's sum does not overflow), the others in 128 bits (edge_wide, beside the steps:
   test_shadow's far polygons); the same values either way.
   The samples a polygon covers on the line are those at or right of an odd number of
   its crossings (the even-odd rule, a crossing at or left of a sample being one the
   sample is at or right of: fx_first_at_or_right's index at most the sample's), so they
   are [b0, b1) with b0 <= b1 the two crossings' indices, in whatever order the
   crossings come. */
struct edge_step {
  int64_t q, dq;            /* P's floor quotient by Q, and dP's (for dyn) */
  int64_t r, Q, dr;         /* the rests and Q, where !wide (else in edge_wide) */
  int64_t lb;               /* the edge's lb, its sign changed with N's */
  int64_t dyn;              /* the step dq, dr are for (0: none) */
  int v;                    /* the edge: from the ring's point v to the next */
  bool wide;
};
struct edge_wide { wide r, Q, dr; };
struct poly_step {
  bool set;                 /* the two edges below hold the line yn for the samples of gen */
  unsigned gen;             /* fx_lines' sgen when made: its yd and row of samples */
  int64_t yn;
  gcoord lo, hi;            /* the band of rows lo <= fy < hi with these two edges */
  struct edge_step e[2];
};

/* A guess at a wide integer's value in a double (its two halves'; within a few units in
   the last place). */
static inline double wide_guess(wide a)
{
  return (double)(int64_t)(a >> 64) * 0x1p64 + (double)(uint64_t)a;
}

/* floor(a / b) and the rest (0 <= rest < b) into *q, *rest, for |a| < 2^125 and
   0 < b < 2^88; false when the quotient is not within 2^36 (a guess in doubles, then
   corrected exactly: the guess is within a unit or so of it; four corrections allowed). */
static bool div_floor(wide a, wide b, int64_t *q, wide *rest)
{
  const double g = floor(wide_guess(a) / wide_guess(b));
  if (!(fabs(g) < 0x1p36)) return false;
  int64_t k = (int64_t)g;
  wide r = a - (wide)k * b;                 /* |k b| <= 2^124, |a - k b| < 2^126 */
  for (int t = 0; r < 0 && t < 4; t++) { k--; r += b; }
  for (int t = 0; r >= b && t < 4; t++) { k++; r -= b; }
  if (r < 0 || r >= b) return false;
  *q = k;
  *rest = r;
  return true;
}

/* The index of edge e's crossing on its line (ceil(P / Q) in [0, n]; w: its 128-bit values
   where e is wide). The rest r is never negative (div_floor's is in [0, Q), and a step
   puts it back there), so r > 0 is r != 0. */
static inline int edge_index(const struct edge_step *e, const struct edge_wide *w, int n)
{
  const bool rest = !e->wide ? e->r != 0 : ((uint64_t)w->r != 0 || (uint64_t)(w->r >> 64) != 0);
  const int64_t c = e->q + rest;
  return c <= 0 ? 0 : c >= n ? n : (int)c;
}

/* Whether a row of samples and a line stay within edge_start's bounds: 0 < yd <= 2^16,
   |xd|, |k0| < 2^30, 0 < S < 2^32 (XL is a window's int32). */
static inline bool step_bounds(int64_t yd, const struct fx_sample_row *r)
{
  return yd > 0 && yd <= GRID_YDEN_MAX && r->xd > 0 && r->xd < (int64_t)1 << 30 &&
         r->k0 > -((int64_t)1 << 30) && r->k0 < (int64_t)1 << 30 && r->S > 0 &&
         r->S < (int64_t)1 << 32;
}

/* div_floor for a 64-bit a (0 < b < 2^63): floor(a / b) and the rest (0 <= rest < b) from
   the processor's divide (C's quotient truncates toward 0 and its rest has a's sign: one
   less and the rest plus b where the rest is negative); false when the quotient is not
   within 2^36 (div_floor's range). Where both succeed they give the same q and rest (the
   exact floor and rest); where either fails its caller takes the long way, whose answer
   is the same. */
static inline bool div_floor64(int64_t a, int64_t b, int64_t *q, int64_t *rest)
{
  int64_t k = a / b, r = a % b;
  if (r < 0) { k--; r += b; }
  if (k <= -((int64_t)1 << 36) || k >= (int64_t)1 << 36) return false;
  *q = k;
  *rest = r;
  return true;
}

/* edge_start's N, D, P and Q in 64-bit integers, each product and sum checked for overflow
   (the same exact values where none overflows): true and the step as edge_start makes it
   (div_floor64), or false with *done false where one overflows or Q is 2^62 or more (then
   edge_start's 128-bit way). On fig6-room and fig6-building every value fits (|P| < 2^50,
   Q < 2^44 there); test_shadow's far polygons take the 128-bit way. */
static inline bool edge_start64(struct edge_step *e, int64_t la, int64_t lb, int64_t lc,
                                int64_t yn, int64_t yd, const struct fx_sample_row *r,
                                bool *done)
{
  int64_t t0, t1, M, N, D, Dg, P, Q, c0, c1, c;
  *done = false;
  if (__builtin_mul_overflow(lb, yn, &t0) || __builtin_mul_overflow(lc, yd, &t1) ||
      __builtin_add_overflow(t0, t1, &M) || __builtin_mul_overflow(la, yd, &D) ||
      D == INT64_MIN || M == INT64_MIN)
    return false;
  int64_t elb = lb;                         /* M = lb yn + lc yd; edge_start's N = -M */
  N = -M;
  if (D < 0) { D = -D; N = M; elb = -lb; }
  if (__builtin_mul_overflow(D, GRID_ONE, &Dg) || __builtin_mul_overflow(N, r->xd, &t0) ||
      __builtin_mul_overflow(r->xd, r->XL, &c0) ||
      __builtin_mul_overflow(2 * r->k0 + 1, r->S, &c1) || __builtin_add_overflow(c0, c1, &c) ||
      __builtin_mul_overflow(Dg, c, &t1) || __builtin_sub_overflow(t0, t1, &P) ||
      __builtin_mul_overflow(Dg, 2 * r->S, &Q) || Q <= 0 || Q >= (int64_t)1 << 62)
    return false;
  *done = true;
  e->lb = elb;
  e->Q = Q;
  e->wide = false;
  return div_floor64(P, Q, &e->q, &e->r);
}

/* The step of the edge from p0 to p1 on the line yn / yd for the samples r (within
   step_bounds): its q, r, Q (in *w where they take 128 bits: e->wide); false when the
   quotient is out of div_floor's range. The sizes, with
   |p.x|, |p.y| <= 2^28 (geom.h): |la|, |lb| < 2^30, |lc| < 2^59, |yn| < 2^63:
   |N| < 2^93 + 2^75 < 2^94, |N xd| < 2^124; D < 2^46, D G < 2^54,
   |xd XL + (2 k0 + 1) S| < 2^61 + 2^63, their product < 2^118; |P| < 2^125, Q < 2^87:
   no overflow in 128 bits. Where every value fits in 64 bits, found there
   (edge_start64). */
static bool edge_start(struct edge_step *e, struct edge_wide *w, struct gpoint p0,
                       struct gpoint p1, int64_t yn, int64_t yd, const struct fx_sample_row *r)
{
  const int64_t la = p0.y - p1.y, lb = p1.x - p0.x, lc = -(la * p0.x + lb * p0.y);
  bool done;
  e->dyn = 0;
  const bool ok = edge_start64(e, la, lb, lc, yn, yd, r, &done);
  if (done) return ok;
  wide N = -((wide)lb * yn + (wide)lc * yd), D = (wide)la * yd;
  e->lb = lb;                               /* N = -(lb yn + lc yd) */
  if (D < 0) { D = -D; N = -N; e->lb = -lb; }   /* (then N = lb yn + lc yd) */
  const wide Dg = D * GRID_ONE;
  const wide P = N * r->xd - Dg * ((wide)r->xd * r->XL + (wide)(2 * r->k0 + 1) * r->S);
  e->wide = true;
  w->Q = Dg * (2 * r->S);
  return div_floor(P, w->Q, &e->q, &w->r);
}

/* Edge e's step for a change dyn of the line's yn (|dyn| < 2^62, both lines' |yn| < 2^61;
   samples' xd < 2^30: |lb dyn xd| < 2^122): dq, dr (in *w where e is wide); false when the
   quotient is out of div_floor's range. In 64 bits where -lb dyn xd and Q fit
   (div_floor64). */
static bool edge_step_set(struct edge_step *e, struct edge_wide *w, int64_t dyn, int64_t xd)
{
  int64_t t, a = 0;               /* a is read only where fits; 0 for gcc -O1's warning */
  const bool fits = !__builtin_mul_overflow(-e->lb, dyn, &t) && !__builtin_mul_overflow(t, xd, &a);
  e->dyn = dyn;
  if (!e->wide) {
    if (fits) return div_floor64(a, e->Q, &e->dq, &e->dr);
    wide dr;                                /* in [0, Q): 64 bits */
    if (!div_floor((wide)-e->lb * dyn * xd, e->Q, &e->dq, &dr)) return false;
    e->dr = (int64_t)dr;
    return true;
  }
  if (w->Q <= INT64_MAX && fits) {
    int64_t dr;
    if (!div_floor64(a, (int64_t)w->Q, &e->dq, &dr)) return false;
    w->dr = dr;
    return true;
  }
  return div_floor((wide)-e->lb * dyn * xd, w->Q, &e->dq, &w->dr);
}

/* Edge e (w: its 128-bit values where wide) moved from its line to the next, dyn further,
   with its step for dyn (edge_step_set): r + dr in [0, 2Q): over Q (t >= 0) the rest is t
   and q gains one more; a carry the predictor cannot guess, so taken without a branch
   (neg: -1 where t < 0). |q| < 2^36 + rows 2^36: no overflow. */
static inline void edge_advance(struct edge_step *e, struct edge_wide *w)
{
  if (!e->wide) {
    const int64_t t = e->r + e->dr - e->Q;  /* in [-Q, Q) */
    const int64_t neg = -(int64_t)(t < 0);
    e->r = t + (e->Q & neg);
    e->q += e->dq + 1 + neg;
    return;
  }
  const wide t = w->r + w->dr - w->Q;
  const int64_t neg = -(int64_t)(t < 0);
  w->r = t + (w->Q & (wide)neg);
  e->q += e->dq + 1 + neg;
}

/* Edge e of a step on line yn0 moved to the line yn (both within 2^61 of 0): its step for
   yn - yn0 made where it is not the one kept. false when out of div_floor's range. */
static inline bool edge_move(struct edge_step *e, struct edge_wide *w, int64_t yn0, int64_t yn,
                             int64_t xd)
{
  const int64_t dyn = yn - yn0;
  if (dyn == 0) return true;
  if (e->dyn != dyn && !edge_step_set(e, w, dyn, xd)) return false;
  edge_advance(e, w);
  return true;
}

/* Polygon p's two ends on the line yn / yd (row fy) from its step s, when s holds the
   line before it (or this one) for the same samples (gen: the caller's count of its yd
   and row of samples r): true and b[0], b[1]. w: the step's two edge_wide. */
static inline bool poly_stepped(struct poly_step *s, struct edge_wide *w, unsigned gen,
                                int64_t yn, int64_t fy, const struct fx_sample_row *r, int b[2])
{
  if (!s->set || s->gen != gen || fy < s->lo || fy >= s->hi || yn <= -((int64_t)1 << 61) ||
      yn >= (int64_t)1 << 61)
    return false;
  if (!edge_move(&s->e[0], w, s->yn, yn, r->xd) ||
      !edge_move(&s->e[1], w + 1, s->yn, yn, r->xd)) {
    s->set = false;
    return false;
  }
  s->yn = yn;
  b[0] = edge_index(&s->e[0], w, r->n);
  b[1] = edge_index(&s->e[1], w + 1, r->n);
  return true;
}

/* Polygon p's step made on the line yn / yd (row fy) when it is one ring of at most 32
   points whose line crosses two edges: true and their b[0], b[1]. An edge of s's last
   line (for the same samples, gen) that the line still crosses is moved to it
   (edge_move), the other started (edge_start). w: as poly_stepped's. */
static bool poly_step_start(struct poly_step *s, struct edge_wide *w, unsigned gen,
                            const struct fx_poly *p, int64_t yn, int64_t yd, int64_t fy,
                            const struct fx_sample_row *r, int b[2])
{
  const bool was = s->set && s->gen == gen;
  s->set = false;
  const int n = p->rs[1] - p->rs[0];
  if (p->nring != 1 || n < 3 || n > 32 || !step_bounds(yd, r) || yn <= -((int64_t)1 << 61) ||
      yn >= (int64_t)1 << 61)
    return false;
  const struct gpoint *pt = p->pt + p->rs[0];
  uint32_t below = 0;                       /* bit v: point v on or below the line */
  gcoord lo = INT64_MIN, hi = INT64_MAX;    /* the band of rows with the same sides */
  for (int v = 0; v < n; v++) {
    const gcoord y = pt[v].y;
    if (y <= fy) { below |= 1u << v; if (y > lo) lo = y; }
    else if (y < hi) hi = y;
  }
  const uint32_t cross = below ^ (below >> 1 | (below & 1u) << (n - 1));   /* v to v + 1 */
  const uint32_t rest = cross & (cross - 1);   /* two crossings: two bits set */
  if (!cross || !rest || (rest & (rest - 1))) return false;
  const int v0 = __builtin_ctz(cross), v1 = __builtin_ctz(rest);
  /* each edge of the last line still crossed kept in its place, the new ones in the
     others */
  bool keep[2] = { false, false };
  for (int c = 0; was && c < 2; c++) keep[c] = s->e[c].v == v0 || s->e[c].v == v1;
  int nv[2] = { v0, v1 };
  if (keep[0] != keep[1]) nv[keep[0] ? 1 : 0] = s->e[keep[0] ? 0 : 1].v == v0 ? v1 : v0;
  for (int c = 0; c < 2; c++) {
    struct edge_wide *wc = w + c;
    if (keep[c]) {
      if (!edge_move(&s->e[c], wc, s->yn, yn, r->xd)) return false;
      continue;
    }
    const int v = nv[c];
    if (!edge_start(&s->e[c], wc, pt[v], pt[v + 1 < n ? v + 1 : 0], yn, yd, r)) return false;
    s->e[c].v = v;
  }
  s->set = true;
  s->gen = gen;
  s->yn = yn;
  s->lo = lo; s->hi = hi;
  b[0] = edge_index(&s->e[0], w, r->n);
  b[1] = edge_index(&s->e[1], w + 1, r->n);
  return true;
}

/* Range [b0, b1) of a row's samples in light's shadow appended to L->rng; false when out
   of host memory. */
static bool range_add(struct fx_lines *L, int b0, int b1, int light)
{
  if (!t74_grow((void **)&L->rng, &L->rngcap, (size_t)L->nrng + 1, sizeof *L->rng)) return false;
  L->rng[L->nrng++] = (struct brange){ b0, b1, light };
  return true;
}

/* The first of polygons p[k .. k1) whose box row fy meets (fx_poly_on_row), or k1: a loop of
   its own over locals (inside face_ranges' loop the compiler kept its index in memory). */
__attribute__((noinline))
static int next_on_row(const struct fx_poly *p, int k, int k1, int64_t fy)
{
  while (k < k1 && !fx_poly_on_row(&p[k], fy)) k++;
  return k;
}

/* The stretches of face f's shadows on the line y = yn / yd as ranges of the samples of
   row r (rising; fy: the line's row, fx_line_row): a sample lies in a stretch [x0, x1)
   exactly when it is at or right of
   x0 and not at or right of x1, so in [fx_first_at_or_right(x0), fx_first_at_or_right(x1)).
   Appended to L->rng. A polygon of two crossings takes its ends from its step (above)
   where it can. A row outside the rows of all the face's polygons (the least ylo, the
   greatest yhi: found at its first call) meets none of them, so none is looked at
   (fig6-building: 106 of a frame's 180 calls, 854 of the 2,545 polygons they looked at). */
static int face_ranges(struct fx_lines *L, int f, int64_t yn, int64_t yd, int64_t fy,
                       const struct fx_sample_row *r, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  const struct fx_poly *const sp = m->shadows.p;
  const int k1 = m->shadow_first[f + 1];
  if (!L->fr[f].ext) {
    gcoord lo = INT64_MAX, hi = INT64_MIN;
    for (int k = m->shadow_first[f]; k < k1; k++) {
      lo = sp[k].ylo < lo ? sp[k].ylo : lo;
      hi = sp[k].yhi > hi ? sp[k].yhi : hi;
    }
    L->fr[f].ylo = lo;
    L->fr[f].yhi = hi;
    L->fr[f].ext = true;
  }
  if (fy < L->fr[f].ylo || fy >= L->fr[f].yhi) return T74_OK;
  if (!L->ps && !m->count && m->shadows.n <= 1 << 15 &&
      (L->ps = malloc((size_t)m->shadows.n * sizeof *L->ps)) != NULL) {   /* (NULL: the long way) */
    if (!(L->psw = malloc(2 * (size_t)m->shadows.n * sizeof *L->psw))) {
      free(L->ps);
      L->ps = NULL;
    }
    for (int k = 0; L->ps && k < m->shadows.n; k++) L->ps[k].set = false;
  }
  for (int k = next_on_row(sp, m->shadow_first[f], k1, fy); k < k1;
       k = next_on_row(sp, k + 1, k1, fy)) {
    const struct fx_poly *p = &sp[k];
    int b2[2];
    if (L->ps && (poly_stepped(&L->ps[k], &L->psw[2 * k], L->sgen, yn, fy, r, b2) ||
                  poly_step_start(&L->ps[k], &L->psw[2 * k], L->sgen, p, yn, yd, fy, r, b2))) {
      const int b0 = b2[0] < b2[1] ? b2[0] : b2[1], b1 = b2[0] < b2[1] ? b2[1] : b2[0];
      if (b0 == b1) continue;
      if (!range_add(L, b0, b1, p->light)) return t74_fail(err, T74_EIO, "out of host memory");
      continue;
    }
    if (!cross_room(L, p)) return t74_fail(err, T74_EIO, "out of host memory");
    const int nx = fx_poly_cross(p, yn, yd, L->x, L->xcap, L->m->count ? L->cost : NULL);
    /* (an empty stretch, x[h] = x[h + 1] (they are sorted), has b0 = b1: skipped as one;
       or b0 = n, as the stretches right of it) */
    for (int h = 0; h + 1 < nx; h += 2) {
      const int b0 = fx_first_at_or_right(&L->x[h], ev_key(L->x[h]), r);
      if (b0 == r->n) break;                /* this stretch and the rest: right of the row */
      const int b1 = fx_first_at_or_right(&L->x[h + 1], ev_key(L->x[h + 1]), r);
      if (b0 == b1) continue;
      if (!range_add(L, b0, b1, p->light)) return t74_fail(err, T74_EIO, "out of host memory");
    }
  }
  return T74_OK;
}

/* The ends of the runs of one face along face[0 .. n), as bits: bit i of bit[i / 64] set
   when a run ends after sample i (face[i + 1] != face[i], or i = n - 1). Four samples a
   compare where the processor has SSE2; one pass over the row, where finding each run's
   end on its own (face_run_end) ends each search with a branch no predictor can guess.
   settled: face was not just stored (fx_see_row_drawn's row), so its samples i + 1 .. i + 4
   are loaded as they lie (one load, where the shifted form below takes two shifts and an
   OR, all three on the processor's one shuffle port). */
static void run_bits(const int *face, int n, bool settled, uint64_t *bit)
{
  int i = 0;
  for (int w = 0; w < (n + 63) / 64; w++) {
    uint64_t acc = 0;                       /* (in a register: no store and reload a step) */
    const int end = 64 * w + 64 < n ? 64 * w + 64 : n;
#ifdef __SSE2__
    /* sixteen at a time: samples i .. i + 15 against i + 1 .. i + 16 (i + 17 <= n), their
       lanes packed to bytes in order (as below) */
    for (; settled && i + 16 <= end && i + 17 <= n; i += 16) {
      const int *const a = face + i;
      const __m128i e0 = _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)a),
                                         _mm_loadu_si128((const __m128i *)(const void *)(a + 1)));
      const __m128i e1 = _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(a + 4)),
                                         _mm_loadu_si128((const __m128i *)(const void *)(a + 5)));
      const __m128i e2 = _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(a + 8)),
                                         _mm_loadu_si128((const __m128i *)(const void *)(a + 9)));
      const __m128i e3 =
        _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(a + 12)),
                        _mm_loadu_si128((const __m128i *)(const void *)(a + 13)));
      const unsigned same = (unsigned)_mm_movemask_epi8(
        _mm_packs_epi16(_mm_packs_epi32(e0, e1), _mm_packs_epi32(e2, e3)));
      acc |= (uint64_t)(~same & 0xffffu) << (i & 63);
    }
    /* then four at a time, and at the row's end samples n - 5 .. n - 2 against n - 4 ..
       n - 1 where they lie in this word (those found already found again, the same) and
       the last sample, which ends its run */
    for (; settled && i + 4 <= end && i + 5 <= n; i += 4) {
      const unsigned same = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(
        _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(face + i)),
                        _mm_loadu_si128((const __m128i *)(const void *)(face + i + 1)))));
      acc |= (uint64_t)(~same & 0xfu) << (i & 63);   /* (i a multiple of 4) */
    }
    if (settled && i < end && end == n && n - 5 >= 64 * w) {
      const unsigned same = (unsigned)_mm_movemask_ps(_mm_castsi128_ps(
        _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(face + n - 5)),
                        _mm_loadu_si128((const __m128i *)(const void *)(face + n - 4)))));
      acc |= (uint64_t)(~same & 0xfu) << ((n - 5) & 63) | (uint64_t)1 << ((n - 1) & 63);
      i = n;
    }
    /* samples i .. i + 3 against i + 1 .. i + 4, the latter shifted in from the loads of
       i .. i + 3 and i + 4 .. i + 7: every load at a multiple of four samples from the row's
       start (the row was just copied in: a load across two of the copy's stores would wait
       for both to be written) */
    /* sixteen at a time first: four such compares, their lanes (0 or -1) packed to bytes
       in order, one mask of 16 bits (i a multiple of 16 from the word's start: i & 63 at
       most 48) */
    if (i + 16 <= end && i + 20 <= n) {
      __m128i a0 = _mm_loadu_si128((const __m128i *)(const void *)(face + i));
      for (; i + 16 <= end && i + 20 <= n; i += 16) {
        const __m128i a1 = _mm_loadu_si128((const __m128i *)(const void *)(face + i + 4));
        const __m128i a2 = _mm_loadu_si128((const __m128i *)(const void *)(face + i + 8));
        const __m128i a3 = _mm_loadu_si128((const __m128i *)(const void *)(face + i + 12));
        const __m128i a4 = _mm_loadu_si128((const __m128i *)(const void *)(face + i + 16));
        const __m128i e0 =
          _mm_cmpeq_epi32(a0, _mm_or_si128(_mm_srli_si128(a0, 4), _mm_slli_si128(a1, 12)));
        const __m128i e1 =
          _mm_cmpeq_epi32(a1, _mm_or_si128(_mm_srli_si128(a1, 4), _mm_slli_si128(a2, 12)));
        const __m128i e2 =
          _mm_cmpeq_epi32(a2, _mm_or_si128(_mm_srli_si128(a2, 4), _mm_slli_si128(a3, 12)));
        const __m128i e3 =
          _mm_cmpeq_epi32(a3, _mm_or_si128(_mm_srli_si128(a3, 4), _mm_slli_si128(a4, 12)));
        const unsigned same = (unsigned)_mm_movemask_epi8(
          _mm_packs_epi16(_mm_packs_epi32(e0, e1), _mm_packs_epi32(e2, e3)));
        acc |= (uint64_t)(~same & 0xffffu) << (i & 63);
        a0 = a4;
      }
    }
    if (i + 4 <= end && i + 8 <= n) {
      __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(face + i));
      for (; i + 4 <= end && i + 8 <= n; i += 4) {
        const __m128i nx = _mm_loadu_si128((const __m128i *)(const void *)(face + i + 4));
        const __m128i b = _mm_or_si128(_mm_srli_si128(a, 4), _mm_slli_si128(nx, 12));
        const unsigned same =
          (unsigned)_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(a, b)));
        acc |= (uint64_t)(~same & 0xfu) << (i & 63);   /* (i a multiple of 4) */
        a = nx;
      }
    }
#endif
    for (; i < end; i++)
      acc |= (uint64_t)(i + 1 == n || face[i + 1] != face[i]) << (i & 63);
    bit[w] = acc;
  }
}

/* shadow_samples on a rising window: a light is blocked at a sample when one of its
   shadows' stretches on the face seen there holds the sample (the count of them at the
   sample, starts at or left of it less ends at or left of it, is positive: shadow_line's
   rule), so the mask at each sample is the OR of the lights of the face's ranges that
   hold it. A face's ranges are found at its first run on the row and serve its others. */
static int shadow_ranges(struct fx_lines *L, int64_t yn, int64_t yd, int64_t xd, int64_t k0,
                         int n, const int *face, const int *runs, bool settled,
                         unsigned *blocked, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  if (!L->fr && !(L->fr = calloc((size_t)m->map->nface + 1, sizeof *L->fr)))
    return t74_fail(err, T74_EIO, "out of host memory");
  /* the row of samples: the same for every row of one frame (fx_points'), so made once
     (its divides) while xd, k0 and n stay */
  if (L->srn != n || L->sr.xd != xd || L->sr.k0 != k0 || L->sryd != yd) {
    fx_sample_row_set(&L->sr, m->g->window, xd, k0, n);
    L->srn = n;
    L->sryd = yd;
    L->sgen++;                              /* (the polygons' steps made before: not for it) */
  }
  const struct fx_sample_row *const sr = &L->sr;
  const int64_t fy = fx_line_row(yn, yd);
  L->row++;                                 /* every face's ranges: none yet */
  L->nrng = 0;
  const int nw = (n + 63) / 64;
  if (!t74_grow((void **)&L->rend, &L->rendcap, (size_t)n, sizeof *L->rend) ||
      !t74_grow((void **)&L->runbit, &L->runbitcap, (size_t)nw, sizeof *L->runbit))
    return t74_fail(err, T74_EIO, "out of host memory");
  run_bits(runs, n, settled, L->runbit);
  memset(blocked, 0, (size_t)n * sizeof *blocked);
  int i = 0, nblk = 0;
  for (int w = 0; w < nw; w++)
    for (uint64_t mb = L->runbit[w]; mb; mb &= mb - 1) {
      const int e = 64 * w + __builtin_ctzll(mb) + 1;   /* the run [i, e) */
      const int f = face[i];
      L->rend[i] = e;                       /* (the run's end, for fx_points' greys) */
      if (f >= 0 && m->shadow_first[f] < m->shadow_first[f + 1]) {
        int any = 0;                        /* a range meets the run: a light blocked there */
        if (L->fr[f].row != L->row) {
          const int at = L->nrng;
          const int rc = face_ranges(L, f, yn, yd, fy, sr, err);
          if (rc != T74_OK) return rc;
          L->fr[f].row = L->row; L->fr[f].at = at; L->fr[f].n = L->nrng - at;
        }
        for (int k = L->fr[f].at; k < L->fr[f].at + L->fr[f].n; k++) {
          const struct brange *b = &L->rng[k];
          const unsigned bit = 1u << b->light;
          const int j0 = b->b0 > i ? b->b0 : i, hi = b->b1 < e ? b->b1 : e;
          any |= j0 < hi;
          /* (four samples an SSE2 instruction here, the zero masks counted from a compare,
             was slower: fig6-room 1.03 to 1.05, fig6-building 1.02 of this, in turn) */
          for (int j = j0; j < hi; j++) {   /* (a sample counted at its first light) */
            nblk += blocked[j] == 0;
            blocked[j] |= bit;
          }
        }
        if (any) L->rend[i] = -e;
      }
      i = e;
    }
  L->rendn = n;
  L->nblk = nblk;
  return T74_OK;
}

/* The lights blocked at each sample of a row: the shadows lying on the face seen there,
   counted up to the sample (shadow_line's answer, sample by sample). runs: the same faces
   as face, which shadow_ranges reads to find the row's runs (fx_lines_samples passes the
   engine's row where face is its copy, fx_see_row_drawn); settled: runs was not just
   stored (run_bits). */
static int shadow_samples(struct fx_lines *L, int64_t yn, int64_t yd, int64_t xd, int64_t k0,
                          int n, const int *face, const int *runs, bool settled,
                          unsigned *blocked, struct t74_error *err)
{
  const struct fx_model *m = L->m;
  const int32_t *win = m->g->window;
  if (!m->shadows.n) {                      /* none: no light blocked anywhere */
    memset(blocked, 0, (size_t)n * sizeof *blocked);
    return T74_OK;
  }
  /* samples left to right (xn rising): each stretch of a face's shadows the range of
     samples between its ends' first samples at or right of them (fx_first_at_or_right),
     found once a row (face_ranges); else each sample compared with the events */
  if (win[2] > win[0])
    return shadow_ranges(L, yn, yd, xd, k0, n, face, runs, settled, blocked, err);
  /* a face's events on the line, sorted, are kept in L->ev for the row: a face seen again
     further along (another face in between) takes them as they are; the last few faces
     are remembered */
  enum { RECENT = 8 };
  struct { int f, at, n; } recent[RECENT];
  int nrecent = 0, total = 0;
  for (int i = 0; i < n;) {
    const int f = face[i], e = face_run_end(face, i, n);
    const struct ev *ev = NULL;
    int nev = 0;
    if (f >= 0 && m->shadow_first[f] < m->shadow_first[f + 1]) {
      int r = 0;
      while (r < nrecent && r < RECENT && recent[r].f != f) r++;
      if (r == nrecent || r == RECENT) {    /* not among them: found and kept */
        const int at = total;
        int rc = stretches(L, &m->shadows, m->shadow_first[f], m->shadow_first[f + 1], yn, yd,
                           &total, err);
        if (rc != T74_OK) return rc;
        ev_sort(L->ev + at, L->evt, total - at);
        r = nrecent++ % RECENT;
        recent[r].f = f; recent[r].at = at; recent[r].n = total - at;
      }
      ev = L->ev + recent[r].at;
      nev = recent[r].n;
    }
    /* a sample's mask: the lights whose count, over the events at or left of it (in
       order), is positive; kept as each event changes its light's count */
    int cnt[SCENE_LIGHT_MAX] = { 0 }, h = 0;
    unsigned mask = 0;
    for (; i < e; i++) {
      int64_t xn = GRID_ONE * (xd * win[0] + (2 * (k0 + i) + 1) * ((int64_t)win[2] - win[0]));
      for (; h < nev && geom_rat_cmp_frac(ev[h].x, xn, xd) <= 0; h++) {
        mask = ev_count(&ev[h], cnt, mask);
      }
      blocked[i] = mask;
    }
  }
  return T74_OK;
}

/* fx_lines_samples; placed: face is the engine's row as drawn itself (fx_see_drawn_row's
   buffer, not a copy), so it is not copied, and the cuts write it in place (fx_points'
   rows: without shadows, blocked is left as it is, all 0). */
static int lines_samples(struct fx_lines *L, int K, int64_t mrow, int64_t k0, int n, int *face,
                         unsigned *blocked, bool placed, struct t74_error *err)
{
  const int32_t *win = L->m->g->window;
  const int64_t XL = win[0], YB = win[1], XR = win[2], YT = win[3];
  const int64_t xd = 2 * (int64_t)K * L->m->W, yd = 2 * (int64_t)K * L->m->H;
  const int64_t yn = GRID_ONE * (yd * YT - (2 * mrow + 1) * (YT - YB));
  int rc;
  L->nblk = -1;                             /* (shadow_ranges counts the samples in shadow) */
  if (L->spans) {
    /* the stretches of the row's line after the regions, each sample placed in its own */
    const struct fx_span *sp;
    int ns;
    if ((rc = fx_lines_get(L, yn, yd, &sp, &ns, err)) != T74_OK) return rc;
    int h = 0;
    for (int i = 0; i < n; i++) {
      int64_t xn = GRID_ONE * (xd * XL + (2 * (k0 + i) + 1) * (XR - XL));
      while (h < ns && geom_rat_cmp_frac(sp[h].x1, xn, xd) <= 0) h++;
      bool in = h < ns && geom_rat_cmp_frac(sp[h].x0, xn, xd) <= 0;
      face[i] = in ? sp[h].face : -1;
      blocked[i] = in ? sp[h].blocked : 0;
    }
    return T74_OK;
  }
  L->rendn = 0;                             /* (shadow_ranges finds the row's runs) */
  const int *drawn = face;                  /* the engine's row face copies, or NULL */
  if (!placed && (rc = fx_see_row_drawn(L->see, K, mrow, k0, n, face, &drawn, err)) != T74_OK)
    return rc;
  for (int q = 0; q < L->m->ncut && rc == T74_OK; q++)
    rc = cut_samples(L, q, K, mrow, yn, yd, xd, k0, n, face, err);
  /* the row's runs read from the engine's row where face is its copy and no cut changed
     it: the copy's stores may still be on their way when run_bits loads them sixteen
     bytes at a time, and such a load waits for them (the same values either way); in
     place, the row was not just stored where no cut wrote it */
  const int *runs = drawn && !L->m->ncut ? drawn : face;
  const bool settled = placed ? !L->m->ncut : runs != face;
  /* placed, without shadows: fx_points' masks are all 0 (its calloc; nothing it calls
     writes one but with a shadow's light), which shadow_samples would set again, a memset
     a row (0.65% of t1-g's instructions) */
  if (rc == T74_OK && (!placed || L->m->shadows.n))
    rc = shadow_samples(L, yn, yd, xd, k0, n, face, runs, settled, blocked, err);
  return rc;
}

int fx_lines_samples(struct fx_lines *L, int K, int64_t mrow, int64_t k0, int n, int *face,
                     unsigned *blocked, struct t74_error *err)
{
  return lines_samples(L, K, mrow, k0, n, face, blocked, false, err);
}

/* ---- the point frame ------------------------------------------------------------------ */

/* The number of b[0 .. n) that are not 0: four a compare where the processor has SSE2
   (n - the count of zeros; n < 2^31). */
static int count_set(const unsigned *b, int n)
{
  int i = 0, c = 0;
#ifdef __SSE2__
  const __m128i z = _mm_setzero_si128();
  __m128i zeros = z;                        /* -1 a zero, lane by lane */
  for (; i + 4 <= n; i += 4)
    zeros = _mm_add_epi32(zeros, _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)(b + i)), z));
  zeros = _mm_add_epi32(zeros, _mm_shuffle_epi32(zeros, _MM_SHUFFLE(1, 0, 3, 2)));
  zeros = _mm_add_epi32(zeros, _mm_shuffle_epi32(zeros, _MM_SHUFFLE(2, 3, 0, 1)));
  c = i + _mm_cvtsi128_si32(zeros);
#endif
  for (; i < n; i++) c += b[i] != 0;
  return c;
}

/* The faces row[0 .. n) after the regions put over fr[0 .. n) (the engine's), the points
   where they differ counted: *cut, of which *show_face now see a face and *show_none none.
   Where the processor has SSE2, sixteen points a step are compared with one branch (the
   regions change a few points of a row: most steps are left as they are, not written); a
   step where they differ is counted and copied four points a vector instruction, without
   a branch a point (where the faces differ follows no pattern a predictor learns). */
static void cut_row(const int *row, int *fr, int n, long *cut, long *show_face, long *show_none)
{
  int i = 0, c = 0, none = 0;               /* (< n: ints) */
#ifdef __SSE2__
  const __m128i ones = _mm_set1_epi32(-1);
  __m128i vc = _mm_setzero_si128(), vn = vc;   /* lane by lane: -1 a point counted */
  for (; i + 16 <= n; i += 16) {
    __m128i a[4], eq[4];
    for (int h = 0; h < 4; h++) {
      a[h] = _mm_loadu_si128((const __m128i *)(const void *)(row + i + 4 * h));
      eq[h] = _mm_cmpeq_epi32(a[h], _mm_loadu_si128((const __m128i *)(const void *)(fr + i + 4 * h)));
    }
    const __m128i all = _mm_and_si128(_mm_and_si128(eq[0], eq[1]), _mm_and_si128(eq[2], eq[3]));
    if (_mm_movemask_epi8(all) == 0xffff) continue;   /* the sixteen the same */
    for (int h = 0; h < 4; h++) {
      const __m128i ne = _mm_andnot_si128(eq[h], ones);
      vc = _mm_add_epi32(vc, ne);
      vn = _mm_add_epi32(vn, _mm_and_si128(ne, _mm_srai_epi32(a[h], 31)));   /* and a < 0 */
      _mm_storeu_si128((__m128i *)(void *)(fr + i + 4 * h), a[h]);
    }
  }
  for (; i + 4 <= n; i += 4) {
    const __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(row + i));
    const __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(fr + i));
    const __m128i ne = _mm_andnot_si128(_mm_cmpeq_epi32(a, b), ones);
    vc = _mm_add_epi32(vc, ne);
    vn = _mm_add_epi32(vn, _mm_and_si128(ne, _mm_srai_epi32(a, 31)));   /* and a < 0 */
    _mm_storeu_si128((__m128i *)(void *)(fr + i), a);
  }
  vc = _mm_add_epi32(vc, _mm_shuffle_epi32(vc, _MM_SHUFFLE(1, 0, 3, 2)));
  vc = _mm_add_epi32(vc, _mm_shuffle_epi32(vc, _MM_SHUFFLE(2, 3, 0, 1)));
  vn = _mm_add_epi32(vn, _mm_shuffle_epi32(vn, _MM_SHUFFLE(1, 0, 3, 2)));
  vn = _mm_add_epi32(vn, _mm_shuffle_epi32(vn, _MM_SHUFFLE(2, 3, 0, 1)));
  c = -_mm_cvtsi128_si32(vc);
  none = -_mm_cvtsi128_si32(vn);
#endif
  for (; i < n; i++) {
    const int face = row[i];
    c += face != fr[i];
    none += face != fr[i] && face < 0;
    fr[i] = face;
  }
  *cut += c;
  *show_none += none;
  *show_face += c - none;
}

#ifdef __SSE2__
/* The signs of the ints a[0 .. 16), bit k set where a[k] < 0 (packs with signed
   saturation keep each int's sign as an int16's, then as a byte's). */
static inline unsigned signs16(const int *a)
{
  const __m128i a0 = _mm_loadu_si128((const __m128i *)(const void *)a);
  const __m128i a1 = _mm_loadu_si128((const __m128i *)(const void *)(a + 4));
  const __m128i a2 = _mm_loadu_si128((const __m128i *)(const void *)(a + 8));
  const __m128i a3 = _mm_loadu_si128((const __m128i *)(const void *)(a + 12));
  return (unsigned)_mm_movemask_epi8(_mm_packs_epi16(_mm_packs_epi32(a0, a1),
                                                     _mm_packs_epi32(a2, a3)));
}
#endif

int fx_points(const struct fx_model *m, struct fx_frame *f, struct fx_stats *st,
              struct cost *cost, struct t74_error *err)
{
  /* a row at a time, bottom row first: its faces after the regions (the lights blocked
     along it), then its greys; px[] and py[] the plane positions of the point centres */
  const int W = f->W, H = f->H;
  const bool regions = fx_model_regions(m);
  unsigned *blocked = calloc((size_t)W + 1, sizeof *blocked);
  int *row = malloc(((size_t)W + 1) * sizeof *row);
  double *px = malloc(((size_t)W + (size_t)H + 1) * sizeof *px);
  /* each face's face_shade_of, found at its first run of the frame and kept (known): a
     run then reads it from one table, not through the face, its scene face and its
     texture one load after another */
  const size_t nface = (size_t)m->map->nface + 1;
  struct face_shade *shades = malloc(nface * sizeof *shades);
  uint8_t *known = calloc(nface, 1);
  struct flat_cache flats;                  /* the lit flat faces' flat_face (flat_face_of) */
  memset(&flats, 0, sizeof flats);
  flats.nface = nface;
  struct fx_lines *L = NULL;
  int rc = !blocked || !row || !px || !shades || !known
             ? t74_fail(err, T74_EIO, "out of host memory") : T74_OK;
  if (rc == T74_OK && regions) rc = fx_lines_open(&L, m, false, cost, err);
  if (rc != T74_OK) {
    free(blocked); free(row); free(px); free(shades); free(known);
    return rc;
  }
  double *py = px + W;
  for (int i = 0; i < W; i++) px[i] = plane_x(m->g, i + 0.5);
  for (int j = 0; j < H; j++) py[j] = plane_y(m->g, j + 0.5);
  struct cost *pc = m->count ? cost : NULL;
  long cut = 0, show_face = 0, show_none = 0, shadowed = 0;
  long pts = 0, flat = 0, band = 0, corner = 0;
  long runs[3] = { 0, 0, 0 };               /* shade_run's points by region */
  const bool bg = m->bg != NULL;
  /* smoothed points a stretch of a row at a time (shade_row), not a run a face */
  const bool rows = m->smooth && smooth_rows(&m->sm, m->e, &m->lights);
  /* and from two coordinates a point where the lights are all parallel (shade_row) */
  bool uv = rows;
  for (int k = 0; k < m->lights.n; k++) uv = uv && !m->lights.point[k];
#ifdef UV_AVX512
  const bool uv512 = uv && uv_avx512(m);   /* its space points eight an instruction */
#else
  const bool uv512 = false;
#endif
  for (int j = H - 1; j >= 0; j--) {
    size_t at0 = (size_t)j * (size_t)W;
    int *fr = f->face + at0;
    if (regions && fx_see_drawn_row(L->see, 1, j, 0, W) == fr) {
      /* fr is the engine's row itself (the frame's faces are its buffer): the cuts
         written into it in place, each sample they write noted (cut_note), and the cut
         counted at those samples alone (the others are as drawn); no row copied into
         row, compared with fr and copied back (the compare waited on the copy's stores) */
      const int nw = (W + 63) / 64;
      if (m->ncut) {
        if (!t74_grow((void **)&L->touch, &L->touchcap, (size_t)nw, sizeof *L->touch) ||
            !t74_grow((void **)&L->orig, &L->origcap, (size_t)W, sizeof *L->orig)) {
          rc = t74_fail(err, T74_EIO, "out of host memory");
          break;
        }
        memset(L->touch, 0, (size_t)nw * sizeof *L->touch);
        L->track = true;
      }
      rc = lines_samples(L, 1, j, 0, W, fr, blocked, true, err);
      L->track = false;
      if (rc != T74_OK) break;
      for (int w = 0; m->ncut && w < nw; w++)
        for (uint64_t b = L->touch[w]; b; b &= b - 1) {
          const int i = 64 * w + __builtin_ctzll(b);
          const bool changed = fr[i] != L->orig[i];
          cut += changed;
          show_none += changed && fr[i] < 0;
          show_face += changed && fr[i] >= 0;
        }
      COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)W);   /* 2 and 2 a point */
      COST_ADD_N(cost, COST_BRANCH, 2 * (uint64_t)W);
    } else if (regions) {
      if ((rc = fx_lines_samples(L, 1, j, 0, W, row, blocked, err)) != T74_OK) break;
      /* a row the regions left as it was has no cut to count (nor, without shadows,
         anything): memcmp tells so faster than cut_row's steps */
      if (memcmp(row, fr, (size_t)W * sizeof *row))
        cut_row(row, fr, W, &cut, &show_face, &show_none);
      COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)W);   /* 2 and 2 a point */
      COST_ADD_N(cost, COST_BRANCH, 2 * (uint64_t)W);
    }
    uint8_t *gr = f->grey + at0;
    /* the row's runs of one face as shadow_ranges found them (the faces fr holds now): at a
       run's first point its end, negated where a light is blocked in it; or NULL: each
       run's end is found here */
    const int *rend = L && L->rendn == W ? L->rend : NULL;
    int last = -1;                          /* the face fs holds */
    struct face_shade fs;
    bool run = false;                       /* its points go in runs (smoothed greys) */
    bool plain = false;                     /* or in runs of a face not smoothed */
    for (int i = 0; i < W; i++) {
      int region, face = fr[i];
      if (face < 0 && rend && (i == 0 || fr[i - 1] >= 0)) {   /* a run that sees no face, */
        const int e = rend[i];              /* i its first point: its end from the table */
                                            /* (no light blocked where no face is seen) */
        if (!bg) memset(gr + i, 0, (size_t)(e - i));
        else for (int q = i; q < e; q++) gr[q] = (uint8_t)shade_none(m, q, j);
        i = e - 1;
        continue;
      }
      if (face < 0) {                       /* a run of points that see no face */
        int e = i + 1;
#ifdef __SSE2__
        /* sixteen at a time, the signs of points e .. e + 15 as the bits of neg (signs16),
           the run's end at its lowest clear bit (~neg's lowest set bit: its bits 16 .. 31
           are set); where fewer than sixteen are left, the row's last sixteen, their bits
           below e taken as set (points of the run, or left of i): their lowest clear bit,
           or bit 16 (the row's end) */
        unsigned neg = 0xffffu;
        for (; e + 16 <= W; e += 16)
          if ((neg = signs16(fr + e)) != 0xffffu) break;
        if (neg != 0xffffu)
          e += __builtin_ctz(~neg);
        else if (W >= 16 && e < W)
          e = W - 16 + __builtin_ctz(~(signs16(fr + W - 16) | ((1u << (e - (W - 16))) - 1)));
#endif
        while (e < W && fr[e] < 0) e++;
        if (!bg) memset(gr + i, 0, (size_t)(e - i));
        else for (int q = i; q < e; q++) gr[q] = (uint8_t)shade_none(m, q, j);
        i = e - 1;
        continue;
      }
      if (face != last) {
        /* (at the face's first run fs made and kept field by field, not read back: a
           struct copy just after face_shade_of's stores reads them in wider loads (the
           two pointers in one of 16 bytes), which wait for the stores to be written, not
           forwarded) */
        if (!known[face]) {
          face_shade_of(m, face, &fs);
          shades[face].mf = fs.mf;
          shades[face].t = fs.t;
          shades[face].tri = fs.tri;
          shades[face].lit = fs.lit;
          known[face] = 1;
        } else {
          fs = shades[face];
        }
        last = face;
        run = !pc && fs.tri >= 0 && !fs.t;
        plain = !pc && fs.tri < 0;
      }
      if (plain) {                          /* all its points here at once */
        if (rend && (i == 0 || fr[i - 1] != face)) {   /* i its first point */
          const int e = rend[i] < 0 ? -rend[i] : rend[i];
          if (rend[i] > 0 && !fs.t)         /* no light blocked, no texture: the face's grey */
            fill_grey(gr + i, (uint8_t)fs.mf->grey, e - i);   /* (shade_flat_run's, lit or not) */
#ifdef __SSE2__
          else if (rend[i] > 0 && fs.lit)   /* no light blocked, a texture */
            flat_tex_clear(m, face, &fs, e - i, px + i, py[j], gr + i, &flats);
#endif
          else
            shade_flat_run(m, face, &fs, e - i, blocked + i, px + i, py[j], gr + i, &flats);
          i = e - 1;
          continue;
        }
        const int e = face_run_end(fr, i, W);
        shade_flat_run(m, face, &fs, e - i, blocked + i, px + i, py[j], gr + i, &flats);
        i = e - 1;
        continue;
      }
      if (run && rows) {                    /* a stretch of smoothed faces' points */
        const int e = shade_row(m, fr, i, W, &fs, blocked + i, px + i, py[j], gr + i, runs,
                                  uv, uv512);
        pts += e - i;
        i = e - 1;
        last = -1;                          /* fs is not fr[e - 1]'s, maybe */
        continue;
      }
      if (run) {                            /* up to SMOOTH_RUN points of it at once */
        int e = i + 1, rg[SMOOTH_RUN];
        while (e < W && e - i < SMOOTH_RUN && fr[e] == face) e++;
        shade_run(m, face, &fs, e - i, blocked + i, px + i, py[j], gr + i, rg);
        for (int q = 0; q < e - i; q++) runs[rg[q]]++;   /* 0, 1 or 2 there */
        pts += e - i;
        i = e - 1;
        continue;
      }
      gr[i] = (uint8_t)shade_face_at(m, face, &fs, blocked[i], px[i], py[j], pc, &region);
      if (region < 0) continue;
      pts++;
      if (region == 0) flat++; else if (region == 2) corner++; else band++;
    }
    /* the row's points in shadow: shadow_ranges' count as it set the masks, else (< W: an
       int) counted four a vector instruction; none without shadows, where shadow_samples
       leaves every mask 0 */
    if (regions && m->shadows.n) shadowed += L->nblk >= 0 ? L->nblk : count_set(blocked, W);
  }
  fx_lines_close(L);
  free(blocked); free(row); free(px); free(shades); free(known);
#ifdef __SSE2__
  free(flats.at); free(flats.kept);
#endif
  if (rc != T74_OK) return rc;
  flat += runs[0]; band += runs[1]; corner += runs[2];
  if (m->e->contour_on && m->smooth) {
    fx_count(st, "contour_points_cut", (double)cut, true);
    fx_count(st, "contour_points_show_face", (double)show_face, true);
    fx_count(st, "contour_points_show_background", (double)show_none, true);
  }
  if (m->smooth && m->e->smooth != EFFECTS_SMOOTH_NONE) {
    fx_count(st, "smooth_points", (double)pts, true);
    fx_count(st, "smooth_points_flat", (double)flat, true);
    fx_count(st, "smooth_points_edge_band", (double)band, true);
    fx_count(st, "smooth_points_corner_band", (double)corner, true);
  }
  if (m->e->shadows) fx_count(st, "shadow_points", (double)shadowed, true);
  return T74_OK;
}
