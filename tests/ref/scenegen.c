/*
** scenegen.c — deterministic scene generators for the cross-check and invariance tests.
**
** This file contains code to make .s74 scenes that are hard for a hidden-surface
** algorithm and easy to trust: many overlapping, interpenetrating and concave faces, each
** exactly planar on the integer grid. A generator draws a view and a window, then adds
** "pieces" (a box, a comb, a plate with holes, ...) near a common centre so that they
** overlap on the screen and pass through one another in depth. A piece that would put
** two faces on one plane (visibility undefined there), or a vertex too close to the eye
** plane, is rolled back and drawn again. The finished scene is checked by sg_validate
** (exact integer predicates) and, if it fails, the whole scene is drawn again from a
** derived seed — deterministically.
**
** Planarity by construction:
**   - triangles are planar;
**   - a planar outline (comb, star, plate, hole) is drawn in integer 2-D coordinates
**     (a, b) and placed at O + a U + b V with integer O, U, V: exactly coplanar;
**   - a box is O + {0,1}U + {0,1}V + {0,1}W with integer U, V, W (axis-aligned or
**     rotated: U a small integer vector, V = U x R, W = U x V, each scaled by an integer):
**     each face O + sU + tV (etc.) is exactly planar.
**
** Sizes are chosen in "plane units" (units of the window on z = 0) and scaled by the
** perspective factor k(z) = (z - Z0) / (-Z0) of the depth they sit at, so a piece covers
** a sensible part of the picture wherever it is.
*/
#include "tests/ref/scenegen.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SG_ID_MAX 65535
#define SG_COORD_MIN (-32768L)
#define SG_COORD_MAX 32767L
#define SG_PI 3.14159265358979323846

/* --- random stream (splitmix64) --------------------------------------------------- */

uint64_t sg_next(sg_rng *r)
{
  uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

long sg_range(sg_rng *r, long lo, long hi)
{
  uint64_t span = (uint64_t)(hi - lo) + 1;
  return lo + (long)(sg_next(r) % span); /* bias < 2^-40 for our spans: irrelevant */
}

/* Uniform double in [0, 1). */
static double sg_unit(sg_rng *r) { return (double)(sg_next(r) >> 11) * (1.0 / 9007199254740992.0); }

static double sg_uniform(sg_rng *r, double lo, double hi) { return lo + (hi - lo) * sg_unit(r); }

/* cos and sin of an angle given in turns, by Taylor series in plain IEEE arithmetic, so the
   rounded outlines are the same on every machine (libm's last bits may differ). */
static void sg_cossin(double turns, double *c, double *s)
{
  double t = turns - floor(turns); /* 0..1 */
  if (t > 0.5) t -= 1.0;           /* -0.5..0.5 */
  const double x = 2.0 * SG_PI * t;
  double term = 1.0, cs = 1.0, sn = x, st = x;
  for (int n = 1; n < 30; n++) {
    term *= -x * x / ((2.0 * n - 1.0) * (2.0 * n));
    cs += term;
    st *= -x * x / ((2.0 * n) * (2.0 * n + 1.0));
    sn += st;
  }
  *c = cs;
  *s = sn;
}

static long sg_round(double v) { return (long)floor(v + 0.5); }

const char *sg_family_name(sg_family fam)
{
  static const char *const names[SG_NFAMILIES] = {"boxes", "triangles", "combs",
                                                  "stars", "plates",    "pierced"};
  return (unsigned)fam < SG_NFAMILIES ? names[fam] : "?";
}

/* --- scene building --------------------------------------------------------------- */

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static int set_err(char *err, size_t errlen, const char *fmt, ...)
{
  if (err && errlen) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
  }
  return -1;
}

int sg_add_vertex(ref_scene *s, unsigned id, long x, long y, long z)
{
  if (s->nv == s->cap_v) {
    int cap = s->cap_v ? 2 * s->cap_v : 64;
    ref_vertex *v = realloc(s->v, (size_t)cap * sizeof *v);
    if (!v) return -1;
    s->v = v;
    s->cap_v = cap;
  }
  s->v[s->nv] = (ref_vertex){id, x, y, z};
  return s->nv++;
}

int sg_add_face(ref_scene *s, unsigned id, int grey, int nring, const int *ring_len,
                const int *vi)
{
  if (s->nf == s->cap_f) {
    int cap = s->cap_f ? 2 * s->cap_f : 32;
    ref_face *f = realloc(s->f, (size_t)cap * sizeof *f);
    if (!f) return -1;
    s->f = f;
    s->cap_f = cap;
  }
  int total = 0;
  for (int k = 0; k < nring; k++) total += ring_len[k];
  ref_face *f = &s->f[s->nf];
  f->id = id;
  f->grey = grey;
  f->nring = nring;
  f->ring_len = malloc((size_t)nring * sizeof *f->ring_len);
  f->vi = malloc((size_t)total * sizeof *f->vi);
  if (!f->ring_len || !f->vi) {
    free(f->ring_len);
    free(f->vi);
    return -1;
  }
  memcpy(f->ring_len, ring_len, (size_t)nring * sizeof *ring_len);
  memcpy(f->vi, vi, (size_t)total * sizeof *vi);
  return s->nf++;
}

/* Drop faces and vertices added after (nv, nf): rolls back a rejected piece. */
static void truncate_scene(ref_scene *s, int nv, int nf)
{
  for (int k = nf; k < s->nf; k++) {
    free(s->f[k].ring_len);
    free(s->f[k].vi);
  }
  s->nf = nf;
  s->nv = nv;
}

void sg_free(ref_scene *s)
{
  truncate_scene(s, 0, 0);
  free(s->v);
  free(s->f);
  memset(s, 0, sizeof *s);
}

/* --- exact plane of a face -------------------------------------------------------- */

static int64_t gcd64(int64_t a, int64_t b)
{
  if (a < 0) a = -a;
  if (b < 0) b = -b;
  while (b) {
    int64_t t = a % b;
    a = b;
    b = t;
  }
  return a;
}

/* Reduced integer normal (gcd 1, first non-zero component positive) and offset d = n.p
   of the outer ring, by Newell's formula (exact in 64 bits for 16-bit coordinates).
   Returns 0, or -1 if the ring has zero area. */
static int face_plane(const ref_scene *s, const ref_face *f, int64_t n[3], int64_t *d)
{
  n[0] = n[1] = n[2] = 0;
  const int m = f->ring_len[0];
  for (int k = 0; k < m; k++) {
    const ref_vertex *a = &s->v[f->vi[k]], *b = &s->v[f->vi[(k + 1) % m]];
    n[0] += (int64_t)(a->y - b->y) * (a->z + b->z);
    n[1] += (int64_t)(a->z - b->z) * (a->x + b->x);
    n[2] += (int64_t)(a->x - b->x) * (a->y + b->y);
  }
  int64_t g = gcd64(gcd64(n[0], n[1]), n[2]);
  if (g == 0) return -1;
  for (int c = 0; c < 3; c++) n[c] /= g;
  int flip = n[0] < 0 || (n[0] == 0 && (n[1] < 0 || (n[1] == 0 && n[2] < 0)));
  if (flip)
    for (int c = 0; c < 3; c++) n[c] = -n[c];
  const ref_vertex *p = &s->v[f->vi[0]];
  *d = n[0] * p->x + n[1] * p->y + n[2] * p->z;
  return 0;
}

/* 1 if faces a and b lie on one plane (or either is degenerate). */
static int same_plane(const ref_scene *s, const ref_face *a, const ref_face *b)
{
  int64_t na[3], nb[3], da, db;
  if (face_plane(s, a, na, &da) || face_plane(s, b, nb, &db)) return 1;
  return na[0] == nb[0] && na[1] == nb[1] && na[2] == nb[2] && da == db;
}

/* --- exact 2-D predicates for sg_validate ----------------------------------------- */

typedef struct pt2 {
  int64_t x, y;
} pt2;

static int64_t orient(pt2 a, pt2 b, pt2 c)
{
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static int sgn(int64_t v) { return (v > 0) - (v < 0); }

static int on_segment(pt2 a, pt2 b, pt2 p) /* p collinear with a-b: within the box? */
{
  return (p.x >= (a.x < b.x ? a.x : b.x)) && (p.x <= (a.x > b.x ? a.x : b.x)) &&
         (p.y >= (a.y < b.y ? a.y : b.y)) && (p.y <= (a.y > b.y ? a.y : b.y));
}

/* Closed segments ab and cd share at least one point. */
static int seg_touch(pt2 a, pt2 b, pt2 c, pt2 d)
{
  int o1 = sgn(orient(a, b, c)), o2 = sgn(orient(a, b, d));
  int o3 = sgn(orient(c, d, a)), o4 = sgn(orient(c, d, b));
  if (o1 * o2 < 0 && o3 * o4 < 0) return 1; /* proper crossing */
  if (o1 == 0 && on_segment(a, b, c)) return 1;
  if (o2 == 0 && on_segment(a, b, d)) return 1;
  if (o3 == 0 && on_segment(c, d, a)) return 1;
  if (o4 == 0 && on_segment(c, d, b)) return 1;
  return 0;
}

/* Point strictly inside ring (p known not to be on its boundary): crossing count. */
static int inside_ring(const pt2 *r, int m, pt2 p)
{
  int in = 0;
  for (int k = 0; k < m; k++) {
    pt2 a = r[k], b = r[(k + 1) % m];
    if ((a.y > p.y) != (b.y > p.y)) {
      /* x of the crossing > p.x  <=>  sign test with the edge's direction */
      int64_t o = orient(a, b, p);
      if ((b.y > a.y) ? (o > 0) : (o < 0)) in = !in;
    }
  }
  return in;
}

int sg_validate(const ref_scene *s, char *err, size_t errlen)
{
  if (s->z0 >= 0) return set_err(err, errlen, "eye Z0 = %ld is not negative", s->z0);
  if (s->xl >= s->xr || s->yb >= s->yt)
    return set_err(err, errlen, "empty window (%ld, %ld)", s->xr - s->xl, s->yt - s->yb);
  const long view[7] = {s->x0, s->y0, s->z0, s->xl, s->yb, s->xr, s->yt};
  for (int k = 0; k < 7; k++)
    if (view[k] < SG_COORD_MIN || view[k] > SG_COORD_MAX)
      return set_err(err, errlen, "view/window value %ld out of range", view[k]);

  unsigned char *seen = calloc(SG_ID_MAX + 1, 1);
  if (!seen) return set_err(err, errlen, "out of memory");
  int bad = 0;
  for (int k = 0; k < s->nv && !bad; k++) {
    const ref_vertex *v = &s->v[k];
    if (v->id < 1 || v->id > SG_ID_MAX || seen[v->id])
      bad = set_err(err, errlen, "vertex id %u bad or repeated (index %d)", v->id, k);
    else if (v->x < SG_COORD_MIN || v->x > SG_COORD_MAX || v->y < SG_COORD_MIN ||
             v->y > SG_COORD_MAX || v->z < SG_COORD_MIN || v->z > SG_COORD_MAX)
      bad = set_err(err, errlen, "vertex %u out of range", v->id);
    else if (v->z <= s->z0)
      bad = set_err(err, errlen, "vertex %u has z %ld <= Z0", v->id, v->z);
    else
      seen[v->id] = 1;
  }
  memset(seen, 0, SG_ID_MAX + 1);
  for (int k = 0; k < s->nf && !bad; k++) {
    const ref_face *f = &s->f[k];
    if (f->id < 1 || f->id > SG_ID_MAX || seen[f->id])
      bad = set_err(err, errlen, "face id %u bad or repeated (index %d)", f->id, k);
    else if (f->grey < -1 || f->grey > 255)
      bad = set_err(err, errlen, "face %u grey %d", f->id, f->grey);
    else if (f->nring < 1)
      bad = set_err(err, errlen, "face %u has %d rings", f->id, f->nring);
    else
      seen[f->id] = 1;
  }
  free(seen);
  if (bad) return -1;

  for (int k = 0; k < s->nf; k++) {
    const ref_face *f = &s->f[k];
    int total = 0;
    for (int r = 0; r < f->nring; r++) {
      if (f->ring_len[r] < 3)
        return set_err(err, errlen, "face %u ring %d has < 3 vertices", f->id, r);
      total += f->ring_len[r];
    }
    for (int m = 0; m < total; m++)
      if (f->vi[m] < 0 || f->vi[m] >= s->nv)
        return set_err(err, errlen, "face %u vertex index %d bad", f->id, f->vi[m]);
    int64_t n[3], d;
    if (face_plane(s, f, n, &d))
      return set_err(err, errlen, "face %u has zero area", f->id);
    for (int m = 0; m < total; m++) {
      const ref_vertex *v = &s->v[f->vi[m]];
      if (n[0] * v->x + n[1] * v->y + n[2] * v->z != d)
        return set_err(err, errlen, "face %u: vertex %u off its plane", f->id, v->id);
    }
    /* Drop the axis with the largest normal component: a 1-1 projection of the plane. */
    int drop = 2;
    int64_t an[3] = {n[0] < 0 ? -n[0] : n[0], n[1] < 0 ? -n[1] : n[1], n[2] < 0 ? -n[2] : n[2]};
    if (an[0] >= an[1] && an[0] >= an[2]) drop = 0;
    else if (an[1] >= an[2]) drop = 1;
    pt2 *p = malloc((size_t)total * sizeof *p);
    int *start = malloc((size_t)(f->nring + 1) * sizeof *start);
    if (!p || !start) {
      free(p);
      free(start);
      return set_err(err, errlen, "out of memory");
    }
    start[0] = 0;
    for (int r = 0; r < f->nring; r++) start[r + 1] = start[r] + f->ring_len[r];
    for (int m = 0; m < total; m++) {
      const ref_vertex *v = &s->v[f->vi[m]];
      long c[3] = {v->x, v->y, v->z};
      p[m].x = c[drop == 0 ? 1 : 0];
      p[m].y = c[drop == 2 ? 1 : 2];
    }
    const char *why = NULL;
    /* distinct points within the face */
    for (int a = 0; a < total && !why; a++)
      for (int b = a + 1; b < total && !why; b++)
        if (p[a].x == p[b].x && p[a].y == p[b].y) why = "repeated point";
    /* every ring has area; no two non-adjacent edges touch; adjacent ones do not fold */
    for (int r = 0; r < f->nring && !why; r++) {
      int64_t area = 0;
      for (int m = start[r]; m < start[r + 1]; m++) {
        int nx = m + 1 == start[r + 1] ? start[r] : m + 1;
        area += p[m].x * p[nx].y - p[nx].x * p[m].y;
      }
      if (area == 0) why = "ring of zero area";
    }
    for (int r1 = 0; r1 < f->nring && !why; r1++)
      for (int e1 = start[r1]; e1 < start[r1 + 1] && !why; e1++) {
        int e1n = e1 + 1 == start[r1 + 1] ? start[r1] : e1 + 1;
        for (int r2 = r1; r2 < f->nring && !why; r2++)
          for (int e2 = (r2 == r1 ? e1 + 1 : start[r2]); e2 < start[r2 + 1] && !why; e2++) {
            int e2n = e2 + 1 == start[r2 + 1] ? start[r2] : e2 + 1;
            if (r1 == r2 && (e1n == e2 || e2n == e1)) {
              /* adjacent: shared vertex; must not fold back over each other */
              pt2 a = p[e1n == e2 ? e1 : e2], b = p[e1n == e2 ? e1n : e1], c = p[e1n == e2 ? e2n : e1n];
              if (orient(a, b, c) == 0 &&
                  (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y) < 0)
                why = "ring folds back on itself";
              continue;
            }
            if (seg_touch(p[e1], p[e1n], p[e2], p[e2n])) why = "edges touch or cross";
          }
      }
    for (int r = 1; r < f->nring && !why; r++) {
      if (!inside_ring(p, f->ring_len[0], p[start[r]])) why = "hole not inside the boundary";
      for (int q = 1; q < f->nring && !why; q++)
        if (q != r && inside_ring(p + start[q], f->ring_len[q], p[start[r]]))
          why = "hole inside another hole";
    }
    free(p);
    free(start);
    if (why) return set_err(err, errlen, "face %u: %s", f->id, why);
  }
  for (int a = 0; a < s->nf; a++)
    for (int b = a + 1; b < s->nf; b++)
      if (same_plane(s, &s->f[a], &s->f[b]))
        return set_err(err, errlen, "faces %u and %u lie on one plane", s->f[a].id,
                       s->f[b].id);
  return 0;
}

/* --- generator context ------------------------------------------------------------ */

typedef struct gen {
  ref_scene *s;
  sg_rng rng;
  unsigned next_vid, next_fid; /* provisional ids; renumbered at the end */
  double cx, cy, cz;           /* world centre the pieces gather around */
  double spread;               /* typical piece size in plane units */
  int oom;                     /* sticky: out of memory */
} gen;

/* Perspective factor at depth z: world length per plane unit. */
static double kz(const ref_scene *s, double z) { return (z - (double)s->z0) / (double)(-s->z0); }

static int vtx(gen *g, long x, long y, long z)
{
  int k = sg_add_vertex(g->s, g->next_vid++, x, y, z);
  if (k < 0) g->oom = 1;
  return k < 0 ? 0 : k;
}

static void face(gen *g, int nring, const int *ring_len, const int *vi)
{
  int grey = (int)sg_range(&g->rng, 30, 255);
  if (sg_add_face(g->s, g->next_fid++, grey, nring, ring_len, vi) < 0) g->oom = 1;
}

/* A piece starts: remember where; ends: keep it if its faces are on planes of their own
   and its vertices are well in front of the eye (>= 1/5 of the eye's distance to z = 0,
   which keeps GL's depth range and tube74's perspective division comfortable). */
typedef struct mark {
  int nv, nf;
  unsigned vid, fid;
} mark;

static mark begin_piece(const gen *g) { return (mark){g->s->nv, g->s->nf, g->next_vid, g->next_fid}; }

static int end_piece(gen *g, mark m)
{
  ref_scene *s = g->s;
  int ok = !g->oom;
  for (int k = m.nv; k < s->nv && ok; k++) {
    const ref_vertex *v = &s->v[k];
    if (5 * (v->z - s->z0) < -s->z0) ok = 0;
    if (v->x < SG_COORD_MIN + 10 || v->x > SG_COORD_MAX - 10 || v->y < SG_COORD_MIN + 10 ||
        v->y > SG_COORD_MAX - 10 || v->z > SG_COORD_MAX - 10)
      ok = 0;
  }
  for (int a = m.nf; a < s->nf && ok; a++)
    for (int b = 0; b < a && ok; b++)
      if (same_plane(s, &s->f[a], &s->f[b])) ok = 0;
  if (!ok) {
    truncate_scene(s, m.nv, m.nf);
    g->next_vid = m.vid;
    g->next_fid = m.fid;
  }
  return ok;
}

/* A random point near the gathering centre: jitter in plane units times k(z). */
static void near_centre(gen *g, double jitter, double out[3])
{
  const double z = g->cz + sg_uniform(&g->rng, -jitter, jitter) * kz(g->s, g->cz);
  const double k = kz(g->s, z);
  out[0] = g->cx + sg_uniform(&g->rng, -jitter, jitter) * k;
  out[1] = g->cy + sg_uniform(&g->rng, -jitter, jitter) * k;
  out[2] = z;
}

/* Eye, window, and a centre for the pieces somewhere inside the view. */
static void make_view(gen *g)
{
  ref_scene *s = g->s;
  sg_rng *r = &g->rng;
  s->z0 = -sg_range(r, 800, 2500);
  s->x0 = sg_range(r, -300, 300);
  s->y0 = sg_range(r, -300, 300);
  const long ww = sg_range(r, 600, 1200);
  const long hh = ww * 3 / 4 + sg_range(r, -ww / 10, ww / 10);
  const long wx = s->x0 + sg_range(r, -150, 150), wy = s->y0 + sg_range(r, -150, 150);
  s->xl = wx - ww / 2;
  s->xr = s->xl + ww;
  s->yb = wy - hh / 2;
  s->yt = s->yb + hh;
  /* centre: depth between Z0/3 (in front of the plane) and 1500, on screen within the
     middle 60% of the window */
  g->cz = (double)sg_range(r, s->z0 / 3, 1500);
  const double k = kz(s, g->cz);
  const double px = (double)s->xl + (double)ww * sg_uniform(r, 0.2, 0.8);
  const double py = (double)s->yb + (double)hh * sg_uniform(r, 0.2, 0.8);
  g->cx = (double)s->x0 + (px - (double)s->x0) * k;
  g->cy = (double)s->y0 + (py - (double)s->y0) * k;
  g->spread = (double)ww * sg_uniform(r, 0.35, 0.7);
}

/* --- integer vectors -------------------------------------------------------------- */

static void cross(const long a[3], const long b[3], long c[3])
{
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static double len3(const long a[3])
{
  return sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
}

static void reduce3(long a[3])
{
  long g = (long)gcd64(gcd64(a[0], a[1]), a[2]);
  if (g > 1)
    for (int c = 0; c < 3; c++) a[c] /= g;
}

static void small_vec(sg_rng *r, long a[3], long lim)
{
  do {
    for (int c = 0; c < 3; c++) a[c] = sg_range(r, -lim, lim);
  } while (a[0] == 0 && a[1] == 0 && a[2] == 0);
  reduce3(a);
}

/* A frame (U, V) for a planar outline: facing the eye, axis-aligned, or tilted by small
   integer vectors at least 30 degrees apart; the plane's normal makes an angle with the
   line of sight whose cosine is at least min_cos (0: any plane, even edge-on). */
static void random_frame(sg_rng *r, long U[3], long V[3], double min_cos)
{
  const long choice = sg_range(r, 0, 9);
  if (choice < 3) { /* facing the eye (plane z = const), turned by a multiple of 90 deg */
    const long q = sg_range(r, 0, 3);
    const long cu[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    U[0] = cu[q][0], U[1] = cu[q][1], U[2] = 0;
    V[0] = -cu[q][1], V[1] = cu[q][0], V[2] = 0;
    return;
  }
  for (;;) {
    small_vec(r, U, choice < 6 ? 1 : 3);
    small_vec(r, V, choice < 6 ? 1 : 3);
    long n[3];
    cross(U, V, n);
    const double nn = len3(n), lu = len3(U), lv = len3(V);
    if (nn >= 0.5 * lu * lv && fabs((double)n[2]) >= min_cos * nn) return; /* sin >= 1/2 */
  }
}

/* Place a 2-D outline: vertex (a, b) -> O + a U + b V. Adds vertices, returns first index. */
static int place_outline(gen *g, const long O[3], const long U[3], const long V[3],
                         const long (*ab)[2], int m, int *vi)
{
  int first = -1;
  for (int k = 0; k < m; k++) {
    long x = O[0] + ab[k][0] * U[0] + ab[k][1] * V[0];
    long y = O[1] + ab[k][0] * U[1] + ab[k][1] * V[1];
    long z = O[2] + ab[k][0] * U[2] + ab[k][1] * V[2];
    vi[k] = vtx(g, x, y, z);
    if (first < 0) first = vi[k];
  }
  return first;
}

/* Origin so that the outline's box [0,A] x [0,B] is centred on c. */
static void centred_origin(const double c[3], const long U[3], const long V[3], long A, long B,
                           long O[3])
{
  for (int k = 0; k < 3; k++)
    O[k] = sg_round(c[k] - 0.5 * (double)A * (double)U[k] - 0.5 * (double)B * (double)V[k]);
}

/* --- pieces ----------------------------------------------------------------------- */

/* A box O + {0,1}U + {0,1}V + {0,1}W as 6 quads. */
static void box_faces(gen *g, const long O[3], const long U[3], const long V[3], const long W[3])
{
  int b[8];
  for (int k = 0; k < 8; k++) {
    long p[3];
    for (int c = 0; c < 3; c++)
      p[c] = O[c] + ((k & 1) ? U[c] : 0) + ((k & 2) ? V[c] : 0) + ((k & 4) ? W[c] : 0);
    b[k] = vtx(g, p[0], p[1], p[2]);
  }
  static const int quad[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                 {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  const int len = 4;
  for (int f = 0; f < 6; f++) {
    int vi[4] = {b[quad[f][0]], b[quad[f][1]], b[quad[f][2]], b[quad[f][3]]};
    face(g, 1, &len, vi);
  }
}

/* Box centred at c with edge lengths (world units) about lu, lv, lw; axis-aligned or
   rotated by small integer vectors (U, U x R, U x (U x R)), scaled by integers. */
static void add_box(gen *g, const double c[3], double lu, double lv, double lw, int rotated)
{
  long U[3] = {1, 0, 0}, V[3] = {0, 1, 0}, W[3] = {0, 0, 1};
  if (rotated) {
    long R[3];
    do {
      small_vec(&g->rng, U, 3);
      small_vec(&g->rng, R, 2);
      cross(U, R, V);
    } while (V[0] == 0 && V[1] == 0 && V[2] == 0);
    reduce3(V);
    cross(U, V, W);
    reduce3(W);
  }
  const double L[3] = {lu, lv, lw};
  long *E[3] = {U, V, W};
  for (int e = 0; e < 3; e++) {
    long kk = sg_round(L[e] / len3(E[e]));
    if (kk < 1) kk = 1;
    for (int q = 0; q < 3; q++) E[e][q] *= kk;
  }
  long O[3];
  for (int q = 0; q < 3; q++)
    O[q] = sg_round(c[q] - 0.5 * (double)(U[q] + V[q] + W[q]));
  box_faces(g, O, U, V, W);
}

/* A comb: a spine along the bottom and T teeth of random width, gap and height, in units
   of the frame; about the gathering spread long. */
static void add_comb(gen *g, const double c[3])
{
  sg_rng *r = &g->rng;
  long U[3], V[3];
  random_frame(r, U, V, 0.5);
  const int teeth = (int)sg_range(r, 4, 12);
  long (*ab)[2] = malloc((size_t)(4 * teeth + 4) * sizeof *ab);
  int *vi = malloc((size_t)(4 * teeth + 4) * sizeof *vi);
  long *s0 = malloc((size_t)teeth * sizeof *s0), *e0 = malloc((size_t)teeth * sizeof *e0),
       *t0 = malloc((size_t)teeth * sizeof *t0);
  if (!ab || !vi || !s0 || !e0 || !t0) {
    g->oom = 1;
    goto out;
  }
  /* length about the spread; teeth and gaps share it at random, >= 2 units each */
  const double len = g->spread * kz(g->s, c[2]) * sg_uniform(r, 0.4, 0.9) / len3(U);
  long unit = sg_round(len / (2 * teeth));
  if (unit < 4) unit = 4;
  long x = 0;
  const long hb = sg_range(r, unit / 2, 2 * unit);
  for (int t = 0; t < teeth; t++) {
    if (t) x += sg_range(r, unit / 2, 3 * unit / 2); /* gap */
    s0[t] = x;
    x += sg_range(r, unit / 2, 3 * unit / 2);        /* tooth */
    e0[t] = x;
    t0[t] = hb + sg_range(r, 2 * unit, 8 * unit);
  }
  const long L = x;
  long maxh = 0;
  for (int t = 0; t < teeth; t++) maxh = t0[t] > maxh ? t0[t] : maxh;
  int m = 0;
  ab[m][0] = 0, ab[m][1] = 0, m++;
  ab[m][0] = L, ab[m][1] = 0, m++;
  for (int t = teeth - 1; t >= 0; t--) {
    ab[m][0] = e0[t], ab[m][1] = t0[t], m++;
    ab[m][0] = s0[t], ab[m][1] = t0[t], m++;
    if (t > 0) {
      ab[m][0] = s0[t], ab[m][1] = hb, m++;
      ab[m][0] = e0[t - 1], ab[m][1] = hb, m++;
    }
  }
  long O[3];
  centred_origin(c, U, V, L, maxh, O);
  place_outline(g, O, U, V, (const long(*)[2])ab, m, vi);
  face(g, 1, &m, vi);
out:
  free(ab);
  free(vi);
  free(s0);
  free(e0);
  free(t0);
}

/* Star-shaped outline around (ca, cb): n points, radii R and r alternating, starting at
   angle `turn0` (turns). Radii >= 20 units keep the rounded vertices in angular order. */
static int star_outline(long ca, long cb, int n, double R, double rr, double turn0,
                        long (*ab)[2])
{
  for (int k = 0; k < 2 * n; k++) {
    double cs, sn;
    sg_cossin(turn0 + (double)k / (2.0 * n), &cs, &sn);
    const double rad = (k & 1) ? rr : R;
    ab[k][0] = ca + sg_round(rad * cs);
    ab[k][1] = cb + sg_round(rad * sn);
  }
  return 2 * n;
}

static void add_star(gen *g, const double c[3])
{
  sg_rng *r = &g->rng;
  long U[3], V[3];
  random_frame(r, U, V, 0.3);
  const double size = g->spread * sg_uniform(r, 0.5, 1.2) * kz(g->s, c[2]) / len3(U);
  const int n = (int)sg_range(r, 5, 12);
  double R = size / 2, rr = R * sg_uniform(r, 0.3, 0.7);
  if (rr < 20) rr = 20, R = R < 45 ? 45 : R;
  long ab[24][2];
  int vi[24];
  const long Rl = sg_round(R) + 1;
  const int m = star_outline(Rl, Rl, n, R, rr, sg_unit(r), ab);
  long O[3];
  centred_origin(c, U, V, 2 * Rl, 2 * Rl, O);
  place_outline(g, O, U, V, (const long(*)[2])ab, m, vi);
  face(g, 1, &m, vi);
}

/* A plate A x B (frame units) with holes in a gx x gy grid of cells: rectangles, regular
   polygons and stars, each strictly inside its cell's margin; optional chamfered corners
   smaller than the margin, so holes stay strictly inside. */
static void add_plate(gen *g, const double c[3], int facing)
{
  sg_rng *r = &g->rng;
  long U[3], V[3];
  if (facing) {
    U[0] = 1, U[1] = 0, U[2] = 0;
    V[0] = 0, V[1] = 1, V[2] = 0;
    if (sg_range(r, 0, 1)) { /* tilt a little about one axis */
      U[2] = sg_range(r, -1, 1);
      if (!U[2]) V[2] = 1;
      U[0] = U[2] ? 3 : 1;
      V[1] = V[2] ? 3 : 1;
    }
  } else {
    random_frame(r, U, V, 0.3);
  }
  const double unitw = len3(U) > len3(V) ? len3(U) : len3(V);
  const double size = g->spread * sg_uniform(r, 0.7, 1.3) * kz(g->s, c[2]) / unitw;
  const int gx = (int)sg_range(r, 2, 4), gy = (int)sg_range(r, 2, 3);
  long cw = sg_round(size / gx), ch = sg_round(size * sg_uniform(r, 0.6, 1.0) / gy);
  if (cw < 60) cw = 60;
  if (ch < 60) ch = 60;
  const long A = cw * gx, B = ch * gy;
  const long margin = (cw < ch ? cw : ch) / 6;
  enum { MAXV = 8 + 12 * 24 };
  long ab[MAXV][2];
  int vi[MAXV], ring_len[13];
  int nring = 0, m = 0;
  /* outer boundary */
  const long ch0 = sg_range(r, 0, 1) ? sg_range(r, 1, margin - 1) : 0;
  if (ch0 > 0) {
    const long o[8][2] = {{ch0, 0}, {A - ch0, 0}, {A, ch0}, {A, B - ch0},
                          {A - ch0, B}, {ch0, B}, {0, B - ch0}, {0, ch0}};
    memcpy(ab, o, sizeof o);
    m = 8;
  } else {
    const long o[4][2] = {{0, 0}, {A, 0}, {A, B}, {0, B}};
    memcpy(ab, o, sizeof o);
    m = 4;
  }
  ring_len[nring++] = m;
  int holes = 0;
  for (int i = 0; i < gx; i++)
    for (int j = 0; j < gy; j++) {
      if (holes && sg_range(r, 0, 9) < 3) continue; /* about 70% of cells get a hole */
      if (nring == 13) continue;
      const long x0 = i * cw + margin, x1 = (i + 1) * cw - margin;
      const long y0 = j * ch + margin, y1 = (j + 1) * ch - margin;
      const long mx = (x0 + x1) / 2, my = (y0 + y1) / 2;
      const long half = ((x1 - x0) < (y1 - y0) ? (x1 - x0) : (y1 - y0)) / 2;
      const long kind = half >= 24 ? sg_range(r, 0, 2) : 0;
      int k;
      if (kind == 0) { /* rectangle */
        const long a0 = sg_range(r, x0, mx - 2), a1 = sg_range(r, mx + 2, x1);
        const long b0 = sg_range(r, y0, my - 2), b1 = sg_range(r, my + 2, y1);
        const long h4[4][2] = {{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}};
        memcpy(ab[m], h4, sizeof h4);
        k = 4;
      } else if (kind == 1) { /* regular polygon, 3..8 sides */
        const int sides = (int)sg_range(r, 3, 8);
        const double rad = (double)(half - 2) * sg_uniform(r, 0.7, 1.0);
        const double t0 = sg_unit(r);
        for (k = 0; k < sides; k++) {
          double cs, sn;
          sg_cossin(t0 + (double)k / sides, &cs, &sn);
          ab[m + k][0] = mx + sg_round(rad * cs);
          ab[m + k][1] = my + sg_round(rad * sn);
        }
      } else { /* star */
        const double R = (double)(half - 2);
        double rr = R * sg_uniform(r, 0.4, 0.7);
        if (rr < 20) rr = 20;
        k = star_outline(mx, my, (int)sg_range(r, 4, 8), R, rr, sg_unit(r), ab + m);
      }
      ring_len[nring++] = k;
      m += k;
      holes++;
    }
  long O[3];
  centred_origin(c, U, V, A, B, O);
  place_outline(g, O, U, V, (const long(*)[2])ab, m, vi);
  face(g, nring, ring_len, vi);
}

/* A triangle around c with vertices within `size` world units in x, y and z. */
static void add_triangle(gen *g, const double c[3], double size)
{
  sg_rng *r = &g->rng;
  for (int tries = 0; tries < 100; tries++) {
    long p[3][3];
    for (int k = 0; k < 3; k++)
      for (int q = 0; q < 3; q++) p[k][q] = sg_round(c[q] + sg_uniform(r, -size, size));
    long e1[3], e2[3], n[3];
    for (int q = 0; q < 3; q++) e1[q] = p[1][q] - p[0][q], e2[q] = p[2][q] - p[0][q];
    cross(e1, e2, n);
    if (len3(n) < 0.2 * len3(e1) * len3(e2) || len3(e1) < size / 4 || len3(e2) < size / 4)
      continue; /* thin or small */
    int vi[3] = {vtx(g, p[0][0], p[0][1], p[0][2]), vtx(g, p[1][0], p[1][1], p[1][2]),
                 vtx(g, p[2][0], p[2][1], p[2][2])};
    const int len = 3;
    face(g, 1, &len, vi);
    return;
  }
}

/* A flat quad (no holes) through c: O + {0,A}U + {0,B}V. */
static void add_quad(gen *g, const double c[3], double world)
{
  long U[3], V[3];
  random_frame(&g->rng, U, V, 0.0);
  const long A = sg_round(world / len3(U)), B = sg_round(world * sg_uniform(&g->rng, 0.5, 1.0) / len3(V));
  const long o[4][2] = {{0, 0}, {A < 2 ? 2 : A, 0}, {A < 2 ? 2 : A, B < 2 ? 2 : B}, {0, B < 2 ? 2 : B}};
  int vi[4];
  long O[3];
  centred_origin(c, U, V, A, B, O);
  place_outline(g, O, U, V, o, 4, vi);
  const int len = 4;
  face(g, 1, &len, vi);
}

/* --- families --------------------------------------------------------------------- */

/* Run piece() until it is accepted (at most 50 draws); 0 if it never was. */
#define TRY_PIECE(g, stmt)                                                                  \
  do {                                                                                      \
    for (int try_ = 0; try_ < 50 && !(g)->oom; try_++) {                                    \
      mark m_ = begin_piece(g);                                                             \
      stmt;                                                                                 \
      if (end_piece((g), m_)) break;                                                        \
    }                                                                                       \
  } while (0)

static void fam_boxes(gen *g)
{
  const int n = (int)sg_range(&g->rng, 3, 10);
  for (int b = 0; b < n; b++) {
    double c[3];
    near_centre(g, g->spread * 0.6, c);
    const double k = kz(g->s, c[2]) * g->spread;
    const double lu = k * sg_uniform(&g->rng, 0.2, 0.8), lv = k * sg_uniform(&g->rng, 0.2, 0.8),
                 lw = k * sg_uniform(&g->rng, 0.2, 0.8);
    const int rot = (int)sg_range(&g->rng, 0, 1);
    TRY_PIECE(g, add_box(g, c, lu, lv, lw, rot));
  }
}

static void fam_triangles(gen *g)
{
  const int n = (int)sg_range(&g->rng, 8, 40);
  for (int t = 0; t < n; t++) {
    double c[3];
    near_centre(g, g->spread * 0.5, c);
    const double size = kz(g->s, c[2]) * g->spread * sg_uniform(&g->rng, 0.2, 0.6);
    TRY_PIECE(g, add_triangle(g, c, size));
  }
}

static void fam_combs(gen *g)
{
  const int n = (int)sg_range(&g->rng, 3, 6);
  for (int k = 0; k < n; k++) {
    double c[3];
    near_centre(g, g->spread * 0.25, c);
    TRY_PIECE(g, add_comb(g, c));
  }
}

static void fam_stars(gen *g)
{
  const int n = (int)sg_range(&g->rng, 3, 8);
  for (int k = 0; k < n; k++) {
    double c[3];
    near_centre(g, g->spread * 0.4, c);
    TRY_PIECE(g, add_star(g, c));
  }
}

static void fam_plates(gen *g)
{
  /* behind: a wall and a few boxes or stars; in front: 1..3 plates with holes */
  double c[3] = {g->cx, g->cy, g->cz + g->spread * kz(g->s, g->cz) * 0.8};
  TRY_PIECE(g, add_quad(g, c, 2.5 * g->spread * kz(g->s, c[2])));
  const int behind = (int)sg_range(&g->rng, 0, 3);
  for (int k = 0; k < behind; k++) {
    near_centre(g, g->spread * 0.4, c);
    c[2] += 0.4 * g->spread * kz(g->s, g->cz);
    const double s = kz(g->s, c[2]) * g->spread * 0.4;
    if (sg_range(&g->rng, 0, 1))
      TRY_PIECE(g, add_box(g, c, s, s, s, (int)sg_range(&g->rng, 0, 1)));
    else
      TRY_PIECE(g, add_star(g, c));
  }
  const int plates = (int)sg_range(&g->rng, 1, 3);
  for (int k = 0; k < plates; k++) {
    near_centre(g, g->spread * 0.2, c);
    c[2] -= 0.2 * g->spread * kz(g->s, g->cz) * k;
    const int facing = sg_range(&g->rng, 0, 2) > 0;
    TRY_PIECE(g, add_plate(g, c, facing));
  }
}

static void fam_pierced(gen *g)
{
  const int n = (int)sg_range(&g->rng, 1, 3);
  for (int b = 0; b < n; b++) {
    double c[3];
    near_centre(g, g->spread * 0.5, c);
    const double k = kz(g->s, c[2]) * g->spread;
    const double lu = k * sg_uniform(&g->rng, 0.3, 0.7), lv = k * sg_uniform(&g->rng, 0.3, 0.7),
                 lw = k * sg_uniform(&g->rng, 0.3, 0.7);
    TRY_PIECE(g, add_box(g, c, lu, lv, lw, (int)sg_range(&g->rng, 0, 1)));
    const int pierce = (int)sg_range(&g->rng, 1, 2);
    for (int p = 0; p < pierce; p++) {
      double q[3];
      for (int a = 0; a < 3; a++) q[a] = c[a] + sg_uniform(&g->rng, -0.15, 0.15) * k;
      if (sg_range(&g->rng, 0, 1)) {
        TRY_PIECE(g, add_quad(g, q, 1.6 * k));
      } else {
        const double thick = k * sg_uniform(&g->rng, 0.06, 0.2);
        TRY_PIECE(g, add_box(g, q, 1.8 * k, thick, thick * sg_uniform(&g->rng, 0.7, 1.5), 1));
      }
    }
  }
}

/* Give vertices and faces their final ids: 1..n in order, or random distinct ids across
   the whole 16-bit range (so the dump's high byte and the GL colour's green are used). */
static int assign_ids(gen *g)
{
  ref_scene *s = g->s;
  unsigned char *used = calloc(SG_ID_MAX + 1, 1);
  if (!used) return -1;
  for (int pass = 0; pass < 2; pass++) {
    const int n = pass ? s->nf : s->nv;
    const int spread = (int)sg_range(&g->rng, 0, 1);
    memset(used, 0, SG_ID_MAX + 1);
    for (int k = 0; k < n; k++) {
      unsigned id = (unsigned)k + 1;
      if (spread)
        do id = (unsigned)sg_range(&g->rng, 1, SG_ID_MAX); while (used[id]);
      used[id] = 1;
      if (pass) s->f[k].id = id;
      else s->v[k].id = id;
    }
  }
  free(used);
  return 0;
}

int sg_generate(sg_family fam, uint64_t seed, ref_scene *out, char *err, size_t errlen)
{
  if ((unsigned)fam >= SG_NFAMILIES) {
    if (err && errlen) snprintf(err, errlen, "unknown family %d", (int)fam);
    return -1;
  }
  char why[200] = "";
  for (int attempt = 0; attempt < 20; attempt++) {
    memset(out, 0, sizeof *out);
    gen g = {out, {seed * 0x2545f4914f6cdd1dULL + (uint64_t)fam * 0x9e3779b97f4a7c15ULL +
                   (uint64_t)attempt * 0xd1b54a32d192ed03ULL},
             1, 1, 0, 0, 0, 0, 0};
    sg_next(&g.rng);
    make_view(&g);
    switch (fam) {
    case SG_BOXES: fam_boxes(&g); break;
    case SG_TRIANGLES: fam_triangles(&g); break;
    case SG_COMBS: fam_combs(&g); break;
    case SG_STARS: fam_stars(&g); break;
    case SG_PLATES: fam_plates(&g); break;
    case SG_PIERCED: fam_pierced(&g); break;
    default: break;
    }
    if (g.oom || assign_ids(&g) != 0) {
      sg_free(out);
      if (err && errlen) snprintf(err, errlen, "out of memory");
      return -1;
    }
    if (out->nf > 0 && sg_validate(out, why, sizeof why) == 0) return 0;
    if (out->nf == 0) snprintf(why, sizeof why, "no faces");
    sg_free(out);
  }
  if (err && errlen)
    snprintf(err, errlen, "%s seed %llu: no valid scene (%s)", sg_family_name(fam),
             (unsigned long long)seed, why);
  return -1;
}

/* --- writing .s74 ----------------------------------------------------------------- */

static int *permutation(int n, sg_rng *r, int shuffle)
{
  int *p = malloc((size_t)(n ? n : 1) * sizeof *p);
  if (!p) return NULL;
  for (int k = 0; k < n; k++) p[k] = k;
  if (shuffle)
    for (int k = n - 1; k > 0; k--) {
      int j = (int)sg_range(r, 0, k);
      int t = p[k];
      p[k] = p[j];
      p[j] = t;
    }
  return p;
}

/* Print one ring: optionally starting at another vertex and/or reversed. */
static void write_ring(FILE *fp, const ref_scene *s, const int *vi, int m, sg_rng *r,
                       int rotate, int reverse)
{
  const int start = rotate ? (int)sg_range(r, 0, m - 1) : 0;
  const int rev = reverse ? (int)sg_range(r, 0, 1) : 0;
  for (int k = 0; k < m; k++) {
    int idx = rev ? (start - k + m) % m : (start + k) % m;
    fprintf(fp, " %u", s->v[vi[idx]].id);
  }
}

int sg_write_s74(const ref_scene *s, const char *path, const char *comment,
                 const sg_variant *var, char *err, size_t errlen)
{
  static const sg_variant canonical = {0, 0, 0, 0};
  if (!var) var = &canonical;
  sg_rng r = {var->seed ^ 0x5851f42d4c957f2dULL};
  FILE *fp = fopen(path, "w");
  if (!fp) {
    if (err && errlen) snprintf(err, errlen, "%s: %s", path, strerror(errno));
    return -1;
  }
  int *pv = permutation(s->nv, &r, var->shuffle), *pf = permutation(s->nf, &r, var->shuffle);
  int ok = pv && pf;
  if (comment) fprintf(fp, "# %s\n", comment);
  fprintf(fp, "view %ld %ld %ld\n", s->x0, s->y0, s->z0);
  fprintf(fp, "window %ld %ld %ld %ld\n", s->xl, s->yb, s->xr, s->yt);
  for (int k = 0; ok && k < s->nv; k++) {
    const ref_vertex *v = &s->v[pv[k]];
    fprintf(fp, "vertex %u %ld %ld %ld\n", v->id, v->x, v->y, v->z);
  }
  for (int k = 0; ok && k < s->nf; k++) {
    const ref_face *f = &s->f[pf[k]];
    int *start = malloc((size_t)(f->nring + 1) * sizeof *start);
    int *hp = permutation(f->nring > 1 ? f->nring - 1 : 0, &r, var->rotate);
    if (!start || !hp) {
      ok = 0;
      free(start);
      free(hp);
      break;
    }
    start[0] = 0;
    for (int q = 0; q < f->nring; q++) start[q + 1] = start[q] + f->ring_len[q];
    fprintf(fp, "face %u", f->id);
    write_ring(fp, s, f->vi, f->ring_len[0], &r, var->rotate, var->reverse);
    for (int h = 1; h < f->nring; h++) {
      const int q = 1 + hp[h - 1];
      fprintf(fp, " *");
      write_ring(fp, s, f->vi + start[q], f->ring_len[q], &r, var->rotate, var->reverse);
    }
    if (f->grey >= 0) fprintf(fp, " grey %d", f->grey);
    fprintf(fp, "\n");
    free(start);
    free(hp);
  }
  free(pv);
  free(pf);
  if (fclose(fp) != 0) ok = 0;
  if (!ok) {
    if (err && errlen) snprintf(err, errlen, "%s: write failed", path);
    return -1;
  }
  return 0;
}
