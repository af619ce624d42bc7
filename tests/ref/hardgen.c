/*
** hardgen.c — generator of hard configurations for the differential tests (hardgen.h).
**
** This file contains test code: each family builds faces as 2-D integer outlines (a, b)
** placed in space as O + a U + b V, so every face is exactly planar; outlines are
** rectangles, triangles and star-shaped polygons over a fixed table of integer
** directions (no libm), checked simple exactly. Special coincidences (a vertex in another
** face's plane, on another face's edge, at another face's vertex) are made by building
** both faces from one plane or one edge.
*/
#include "tests/ref/hardgen.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

__extension__ typedef __int128 i128;

struct rng { uint64_t s; };

static uint64_t next(struct rng *r)
{
  uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

static long rnd(struct rng *r, long lo, long hi)   /* lo..hi inclusive */
{
  return lo + (long)(next(r) % (uint64_t)(hi - lo + 1));
}

const char *hg_family_name(int fam)
{
  static const char *const n[HG_NFAMILIES] = {
    "wall", "coplanar", "vshare", "tjunc", "sliver", "far", "edgeon", "snapped", "fold",
    "holes", "mix", "crowd"
  };
  return fam >= 0 && fam < HG_NFAMILIES ? n[fam] : "?";
}

/* ---- planes and outlines ------------------------------------------------------------ */

struct plane { int64_t O[3], U[3], V[3]; };

struct gen {
  struct rng r;
  struct xr_scene *s;
  unsigned next_id;
  int bad;                       /* a vertex out of range or behind the eye */
};

static int put(struct gen *g, const int64_t p[3])
{
  for (int c = 0; c < 3; c++)
    if (p[c] < -32768 || p[c] > 32767) { g->bad = 1; return 0; }
  if (p[2] <= g->s->eye[2]) { g->bad = 1; return 0; }
  /* now and then reuse a vertex at the same position (else a new id at that position) */
  if (next(&g->r) & 1)
    for (int k = 0; k < g->s->nv; k++)
      if (g->s->v[k][0] == p[0] && g->s->v[k][1] == p[1] && g->s->v[k][2] == p[2]) return k;
  int v = xr_vertex(g->s, (int32_t)p[0], (int32_t)p[1], (int32_t)p[2]);
  if (v < 0) g->bad = 2;
  return v < 0 ? 0 : v;
}

static void at(const struct plane *pl, int64_t a, int64_t b, int64_t out[3])
{
  for (int c = 0; c < 3; c++) out[c] = pl->O[c] + a * pl->U[c] + b * pl->V[c];
}

static i128 cross2(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx, int64_t cy)
{
  return (i128)(bx - ax) * (cy - ay) - (i128)(by - ay) * (cx - ax);
}

static int sgn(i128 v) { return (v > 0) - (v < 0); }

static int on_seg(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py)
{
  return (px >= (ax < bx ? ax : bx)) && (px <= (ax < bx ? bx : ax)) &&
         (py >= (ay < by ? ay : by)) && (py <= (ay < by ? by : ay));
}

static int seg_meet(const int64_t *a, const int64_t *b, const int64_t *c, const int64_t *d)
{
  int d1 = sgn(cross2(c[0], c[1], d[0], d[1], a[0], a[1]));
  int d2 = sgn(cross2(c[0], c[1], d[0], d[1], b[0], b[1]));
  int d3 = sgn(cross2(a[0], a[1], b[0], b[1], c[0], c[1]));
  int d4 = sgn(cross2(a[0], a[1], b[0], b[1], d[0], d[1]));
  if (d1 * d2 < 0 && d3 * d4 < 0) return 1;
  if (!d1 && on_seg(c[0], c[1], d[0], d[1], a[0], a[1])) return 1;
  if (!d2 && on_seg(c[0], c[1], d[0], d[1], b[0], b[1])) return 1;
  if (!d3 && on_seg(a[0], a[1], b[0], b[1], c[0], c[1])) return 1;
  if (!d4 && on_seg(a[0], a[1], b[0], b[1], d[0], d[1])) return 1;
  return 0;
}

/* exact: the outline (n >= 3 points) is simple and has non-zero area */
static int simple2(int n, const int64_t (*p)[2])
{
  i128 area = 0;
  for (int i = 0; i < n; i++) {
    const int64_t *a = p[i], *b = p[(i + 1) % n];
    area += (i128)a[0] * b[1] - (i128)b[0] * a[1];
    if (a[0] == b[0] && a[1] == b[1]) return 0;
  }
  if (area == 0) return 0;
  for (int i = 0; i < n; i++)
    for (int j = i + 1; j < n; j++) {
      const int64_t *a = p[i], *b = p[(i + 1) % n], *c = p[j], *d = p[(j + 1) % n];
      if (j == i + 1 || (i == 0 && j == n - 1)) {
        /* neighbours share one vertex: they must not overlap (fold back) */
        const int64_t *sh = j == i + 1 ? b : a, *x = j == i + 1 ? a : b, *y = j == i + 1 ? d : c;
        if (sgn(cross2(sh[0], sh[1], x[0], x[1], y[0], y[1])) == 0 &&
            ((x[0] - sh[0]) * (y[0] - sh[0]) + (x[1] - sh[1]) * (y[1] - sh[1])) > 0)
          return 0;
        continue;
      }
      if (seg_meet(a, b, c, d)) return 0;
    }
  return 1;
}

/* a face from an outline in plane pl; returns its index or -1 when not simple */
static int face2(struct gen *g, const struct plane *pl, int n, const int64_t (*ab)[2])
{
  if (n < 3 || n > 64 || !simple2(n, ab)) return -1;
  int vi[64];
  for (int k = 0; k < n; k++) {
    int64_t p[3];
    at(pl, ab[k][0], ab[k][1], p);
    vi[k] = put(g, p);
  }
  if (g->bad) return -1;
  int f = xr_face(g->s, g->next_id++, n, vi);
  if (f < 0) g->bad = 2;
  return f;
}

/* a triangle from three points in space (not collinear), or -1 */
static int tri3(struct gen *g, const int64_t *p, const int64_t *q, const int64_t *r)
{
  int64_t u[3], v[3];
  for (int c = 0; c < 3; c++) { u[c] = q[c] - p[c]; v[c] = r[c] - p[c]; }
  if (u[1] * v[2] - u[2] * v[1] == 0 && u[2] * v[0] - u[0] * v[2] == 0 &&
      u[0] * v[1] - u[1] * v[0] == 0)
    return -1;
  int vi[3] = { put(g, p), put(g, q), put(g, r) };
  if (g->bad) return -1;
  int f = xr_face(g->s, g->next_id++, 3, vi);
  if (f < 0) g->bad = 2;
  return f;
}

/* sixteen integer directions around the circle (x 1000) */
static const int DIR[16][2] = {
  { 1000, 0 }, { 924, 383 }, { 707, 707 }, { 383, 924 }, { 0, 1000 }, { -383, 924 },
  { -707, 707 }, { -924, 383 }, { -1000, 0 }, { -924, -383 }, { -707, -707 },
  { -383, -924 }, { 0, -1000 }, { 383, -924 }, { 707, -707 }, { 924, -383 }
};

/* a star-shaped outline around (cx, cy), radius up to R: n points, gaps < 180 degrees */
static int star(struct gen *g, int64_t cx, int64_t cy, int64_t R, int64_t (*out)[2])
{
  int idx[16], n = 0;
  for (int k = 0; k < 16; k++)
    if (rnd(&g->r, 0, 2)) idx[n++] = k;
  if (n < 3) { idx[0] = 0; idx[1] = 5; idx[2] = 10; n = 3; }
  for (int k = 0; k < n; k++) {
    int gap = (k + 1 < n ? idx[k + 1] : idx[0] + 16) - idx[k];
    if (gap >= 8) { n = 0; break; }
  }
  if (n == 0) { for (int k = 0; k < 8; k++) idx[k] = 2 * k; n = 8; }
  for (int k = 0; k < n; k++) {
    int64_t rr = rnd(&g->r, R / 4 > 1 ? R / 4 : 1, R > 1 ? R : 1);
    out[k][0] = cx + DIR[idx[k]][0] * rr / 1000;
    out[k][1] = cy + DIR[idx[k]][1] * rr / 1000;
  }
  return n;
}

static void rvec(struct gen *g, int64_t v[3], long m)
{
  for (int c = 0; c < 3; c++) v[c] = rnd(&g->r, -m, m);
}

static int plane_ok(const struct plane *pl)
{
  const int64_t *u = pl->U, *v = pl->V;
  return (u[1] * v[2] - u[2] * v[1]) || (u[2] * v[0] - u[0] * v[2]) || (u[0] * v[1] - u[1] * v[0]);
}

/* a random plane near the middle of the scene, spanned by short vectors of scale m */
static void rplane(struct gen *g, struct plane *pl, long m)
{
  do {
    pl->O[0] = rnd(&g->r, -60, 60);
    pl->O[1] = rnd(&g->r, -60, 60);
    pl->O[2] = rnd(&g->r, 0, 300);
    rvec(g, pl->U, m);
    rvec(g, pl->V, m);
    if (rnd(&g->r, 0, 2) == 0) { pl->U[2] = 0; pl->V[2] = rnd(&g->r, -1, 1); }
  } while (!plane_ok(pl));
}

static void rect(int64_t a0, int64_t b0, int64_t a1, int64_t b1, int64_t (*o)[2])
{
  o[0][0] = a0; o[0][1] = b0; o[1][0] = a1; o[1][1] = b0;
  o[2][0] = a1; o[2][1] = b1; o[3][0] = a0; o[3][1] = b1;
}

/* side of point p of plane pl: sign of n.(p - O) */
static int64_t pside(const struct plane *pl, const int64_t *p)
{
  const int64_t *u = pl->U, *v = pl->V;
  int64_t n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
  return n[0] * (p[0] - pl->O[0]) + n[1] * (p[1] - pl->O[1]) + n[2] * (p[2] - pl->O[2]);
}

/* a triangle through p (exactly in pl) that pierces pl (pierce) or only touches it */
static int piercer(struct gen *g, const struct plane *pl, const int64_t *p, int pierce)
{
  for (int tries = 0; tries < 20; tries++) {
    int64_t q[3], r[3], d[3], e[3];
    rvec(g, d, 60);
    rvec(g, e, 60);
    for (int c = 0; c < 3; c++) { q[c] = p[c] + d[c]; r[c] = p[c] + e[c]; }
    int64_t sq = pside(pl, q), sr = pside(pl, r);
    if (!sq || !sr) continue;
    if (pierce != ((sq > 0) != (sr > 0))) continue;
    int f = tri3(g, p, q, r);
    if (f >= 0 || g->bad) return f;
  }
  return -1;
}

/* ---- families ----------------------------------------------------------------------- */

static void fam_wall(struct gen *g)
{
  struct plane pl;
  rplane(g, &pl, 12);
  int64_t A = rnd(&g->r, 3, 14), B = rnd(&g->r, 3, 14), o[4][2];
  rect(0, 0, A, B, o);
  face2(g, &pl, 4, (const int64_t (*)[2])o);
  /* the window: touching the outline on one side or at a corner */
  int64_t a0 = rnd(&g->r, 0, A - 1), a1 = rnd(&g->r, a0 + 1, A);
  int64_t b0 = rnd(&g->r, 0, B - 1), b1 = rnd(&g->r, b0 + 1, B);
  switch (rnd(&g->r, 0, 4)) {
  case 0: a0 = 0; break;
  case 1: a1 = A; break;
  case 2: b0 = 0; break;
  case 3: b1 = B; break;
  default: a0 = 0; b0 = 0; break;
  }
  rect(a0, b0, a1, b1, o);
  face2(g, &pl, 4, (const int64_t (*)[2])o);
  int np = (int)rnd(&g->r, 1, 2);
  for (int k = 0; k < np; k++) {
    int64_t p[3];
    long a = rnd(&g->r, 0, A), b = rnd(&g->r, 0, B);
    if (rnd(&g->r, 0, 1)) { a = rnd(&g->r, 0, 1) ? a0 : a1; b = rnd(&g->r, b0, b1); }
    at(&pl, a, b, p);
    piercer(g, &pl, p, rnd(&g->r, 0, 3) != 0);
  }
}

static void fam_coplanar(struct gen *g)
{
  struct plane pl;
  rplane(g, &pl, 12);
  int64_t o[4][2];
  int n = (int)rnd(&g->r, 2, 3);
  for (int k = 0; k < n; k++) {
    int64_t a0 = rnd(&g->r, 0, 8), b0 = rnd(&g->r, 0, 8);
    rect(a0, b0, a0 + rnd(&g->r, 1, 8), b0 + rnd(&g->r, 1, 8), o);
    face2(g, &pl, 4, (const int64_t (*)[2])o);
  }
  int np = (int)rnd(&g->r, 1, 2);
  for (int k = 0; k < np; k++) {
    int64_t p[3];
    at(&pl, rnd(&g->r, 0, 16), rnd(&g->r, 0, 16), p);
    piercer(g, &pl, p, 1);
  }
}

/* faces of one edge P -> P + m u: planes P + a u + b V for random V */
static void fam_vshare(struct gen *g)
{
  int64_t P[3] = { rnd(&g->r, -50, 50), rnd(&g->r, -50, 50), rnd(&g->r, 0, 300) }, u[3];
  do rvec(g, u, 20); while (!u[0] && !u[1] && !u[2]);
  long m = rnd(&g->r, 1, 4);
  int nf = (int)rnd(&g->r, 2, 3);
  for (int k = 0; k < nf; k++) {
    struct plane pl;
    memcpy(pl.O, P, sizeof P);
    memcpy(pl.U, u, sizeof u);
    do rvec(g, pl.V, 40); while (!plane_ok(&pl));
    long side = k % 2 ? -1 : 1;
    int64_t o[4][2] = { { 0, 0 }, { m, 0 }, { m + rnd(&g->r, -2, 2), side * rnd(&g->r, 1, 3) },
                        { rnd(&g->r, -2, 2), side * rnd(&g->r, 1, 3) } };
    int n = rnd(&g->r, 0, 1) ? 3 : 4;
    if (side < 0) {                      /* keep the outline counter-clockwise */
      for (int q = 0; q < 2; q++) { int64_t t = o[q][0]; o[q][0] = o[3 - q][0]; o[3 - q][0] = t;
        t = o[q][1]; o[q][1] = o[3 - q][1]; o[3 - q][1] = t; }
      if (n == 3) { o[0][0] = o[1][0]; o[0][1] = o[1][1]; o[1][0] = o[2][0]; o[1][1] = o[2][1];
                    o[2][0] = o[3][0]; o[2][1] = o[3][1]; }
    }
    face2(g, &pl, n, (const int64_t (*)[2])o);
  }
  /* faces sharing only one vertex position with them */
  int nt = (int)rnd(&g->r, 1, 2);
  for (int k = 0; k < nt; k++) {
    int64_t V[3], q[3], r[3], d[3], e[3];
    for (int c = 0; c < 3; c++) V[c] = P[c] + (rnd(&g->r, 0, 1) ? m * u[c] : 0);
    rvec(g, d, 60);
    rvec(g, e, 60);
    for (int c = 0; c < 3; c++) { q[c] = V[c] + d[c]; r[c] = V[c] + e[c]; }
    tri3(g, V, q, r);
  }
}

static void fam_tjunc(struct gen *g)
{
  int64_t P[3] = { rnd(&g->r, -50, 50), rnd(&g->r, -50, 50), rnd(&g->r, 0, 300) }, u[3];
  do rvec(g, u, 12); while (!u[0] && !u[1] && !u[2]);
  long m = rnd(&g->r, 2, 8);
  struct plane pa;
  memcpy(pa.O, P, sizeof P);
  memcpy(pa.U, u, sizeof u);
  do rvec(g, pa.V, 40); while (!plane_ok(&pa));
  int64_t o[4][2] = { { 0, 0 }, { m, 0 }, { m, rnd(&g->r, 1, 4) }, { 0, rnd(&g->r, 1, 4) } };
  face2(g, &pa, 4, (const int64_t (*)[2])o);
  int nb = (int)rnd(&g->r, 1, 3);
  for (int k = 0; k < nb; k++) {
    struct plane pb;
    memcpy(pb.O, P, sizeof P);
    memcpy(pb.U, u, sizeof u);
    if (rnd(&g->r, 0, 3) == 0) memcpy(pb.V, pa.V, sizeof pb.V);   /* coplanar neighbour */
    else do rvec(g, pb.V, 40); while (!plane_ok(&pb));
    long k1 = rnd(&g->r, -2, m - 1), k2 = rnd(&g->r, k1 + 1, m + 2);
    if (rnd(&g->r, 0, 1)) k2 = k1 + 1 + rnd(&g->r, 0, 1) * (m - k1 - 1 > 0 ? m - k1 - 1 : 0);
    int64_t h = rnd(&g->r, 1, 4);
    /* on the other side of the edge line from A (b < 0), sharing [k1, k2] of it */
    int64_t t[4][2] = { { k1, 0 }, { k1 + rnd(&g->r, -2, 2), -h }, { k2 + rnd(&g->r, -2, 2), -h }, { k2, 0 } };
    int n = 4;
    if (rnd(&g->r, 0, 2) == 0) { t[1][0] = (k1 + k2) / 2; t[1][1] = -h; t[2][0] = k2; t[2][1] = 0; n = 3; }
    face2(g, &pb, n, (const int64_t (*)[2])t);
  }
}

static void fam_sliver(struct gen *g)
{
  int n = (int)rnd(&g->r, 2, 5);
  for (int k = 0; k < n; k++) {
    struct plane pl;
    if (rnd(&g->r, 0, 1)) {               /* on z = 0: vertices on point centres */
      int64_t O[3] = { rnd(&g->r, -40, 40) * 2 + 1, rnd(&g->r, -30, 30) * 2 + 1, 0 };
      int64_t U[3] = { 2, 0, 0 }, V[3] = { 0, 2, 0 };
      memcpy(pl.O, O, sizeof O); memcpy(pl.U, U, sizeof U); memcpy(pl.V, V, sizeof V);
      if (rnd(&g->r, 0, 1)) { pl.V[2] = rnd(&g->r, -1, 1); pl.O[2] = rnd(&g->r, 0, 3); }
    } else {
      rplane(g, &pl, 6);
    }
    long L = rnd(&g->r, 5, 40);
    int64_t o[3][2] = { { 0, 0 }, { L, rnd(&g->r, 1, 2) }, { 2 * L + rnd(&g->r, -1, 1), rnd(&g->r, 1, 4) } };
    if (rnd(&g->r, 0, 1)) { o[1][1] = 1; o[2][0] = L + 1; o[2][1] = 1; o[1][0] = L; o[1][1] = 0; }
    face2(g, &pl, 3, (const int64_t (*)[2])o);
  }
}

static void fam_far(struct gen *g)
{
  /* an eye close to the plane and faces far behind it: a star of radius R at depth z
     projects to about 256 R |Z0| / z grid units, a few units only, so rounding each
     vertex by up to half a unit can fold the outline */
  g->s->eye[2] = (int32_t)rnd(&g->r, -12, -1);
  int n = (int)rnd(&g->r, 1, 6);
  for (int k = 0; k < n; k++) {
    struct plane pl;
    int64_t O[3] = { rnd(&g->r, -400, 400), rnd(&g->r, -400, 400), rnd(&g->r, 12000, 30000) };
    int64_t U[3] = { 1, 0, 0 }, V[3] = { 0, 1, 0 };
    if (rnd(&g->r, 0, 1)) { U[2] = rnd(&g->r, -1, 1); V[2] = rnd(&g->r, -1, 1); }
    memcpy(pl.O, O, sizeof O); memcpy(pl.U, U, sizeof U); memcpy(pl.V, V, sizeof V);
    int64_t o[16][2];
    int m = star(g, 0, 0, rnd(&g->r, 100, 3000), o);
    face2(g, &pl, m, (const int64_t (*)[2])o);
  }
}

static void fam_edgeon(struct gen *g)
{
  const int32_t *E = g->s->eye;
  int n = (int)rnd(&g->r, 1, 3);
  for (int k = 0; k < n; k++) {
    struct plane pl;
    pl.O[0] = E[0] + rnd(&g->r, -3, 3);
    pl.O[1] = E[1] + rnd(&g->r, -3, 3);
    pl.O[2] = E[2] + rnd(&g->r, 0, 2);
    do {
      pl.U[0] = rnd(&g->r, -3, 3); pl.U[1] = rnd(&g->r, -3, 3); pl.U[2] = rnd(&g->r, 4, 12);
      pl.V[0] = rnd(&g->r, -12, 12); pl.V[1] = rnd(&g->r, -12, 12); pl.V[2] = rnd(&g->r, 0, 3);
    } while (!plane_ok(&pl));
    int64_t o[16][2];
    long R = rnd(&g->r, 20, 80);
    int m = star(g, R + 40, 0, R, o);
    face2(g, &pl, m, (const int64_t (*)[2])o);
  }
  /* and an ordinary face or two behind and across */
  struct plane pl;
  rplane(g, &pl, 12);
  int64_t o[4][2];
  rect(-5, -5, 5, 5, o);
  face2(g, &pl, 4, (const int64_t (*)[2])o);
}

static void fam_snapped(struct gen *g)
{
  struct plane pl[4];
  int np = (int)rnd(&g->r, 2, 4);
  for (int k = 0; k < np; k++) {
    rplane(g, &pl[k], 10);
    int64_t o[16][2];
    int m = rnd(&g->r, 0, 2) ? 4 : star(g, 0, 0, 8, o);
    if (m == 4) rect(-rnd(&g->r, 1, 6), -rnd(&g->r, 1, 6), rnd(&g->r, 1, 6), rnd(&g->r, 1, 6), o);
    face2(g, &pl[k], m, (const int64_t (*)[2])o);
  }
  int nt = (int)rnd(&g->r, 1, 3);
  for (int k = 0; k < nt; k++) {
    int64_t p[3], q[3], r[3];
    const struct plane *a = &pl[rnd(&g->r, 0, np - 1)], *b = &pl[rnd(&g->r, 0, np - 1)];
    at(a, rnd(&g->r, -6, 6), rnd(&g->r, -6, 6), p);
    at(b, rnd(&g->r, -6, 6), rnd(&g->r, -6, 6), q);
    int64_t d[3];
    rvec(g, d, 60);
    for (int c = 0; c < 3; c++) r[c] = p[c] + d[c];
    tri3(g, p, q, r);
  }
}

/* combs on z = z0 seen from an eye close to the plane: one world unit is 256 f / (z0 + f)
   grid units (about 0.1 to 3), and the notches end 1..3 world units from the bottom edge,
   which is tilted by a unit or two: after rounding, tips touch or cross it */
static void fam_fold(struct gen *g)
{
  g->s->eye[2] = (int32_t)rnd(&g->r, -3, -1);
  int n = (int)rnd(&g->r, 1, 3);
  for (int k = 0; k < n; k++) {
    struct plane pl;
    int64_t O[3] = { rnd(&g->r, -100, 100), rnd(&g->r, -100, 100), rnd(&g->r, 150, 2500) };
    int64_t U[3] = { 1, 0, 0 }, V[3] = { 0, 1, 0 };
    if (rnd(&g->r, 0, 2) == 0) V[2] = rnd(&g->r, -1, 1);
    memcpy(pl.O, O, sizeof O); memcpy(pl.U, U, sizeof U); memcpy(pl.V, V, sizeof V);
    int teeth = (int)rnd(&g->r, 1, 5);
    int64_t gap = rnd(&g->r, 4, 30), Wd = gap * (2 * teeth + 1), H = rnd(&g->r, 8, 60);
    int64_t s = rnd(&g->r, -2, 2);              /* the bottom edge rises by s */
    int64_t o[64][2];
    int m = 0;
    o[m][0] = 0; o[m][1] = s < 0 ? -s : 0; m++;
    o[m][0] = Wd; o[m][1] = s > 0 ? s : 0; m++;
    o[m][0] = Wd; o[m][1] = H; m++;
    for (int t = teeth; t >= 1; t--) {
      int64_t x = gap * 2 * t;
      /* bottom edge height at x, rounded up, plus 1..3 */
      int64_t y0 = o[0][1], y1 = o[1][1];
      int64_t yb = y0 + ((y1 - y0) * x + (Wd - 1)) / Wd;
      int64_t w = rnd(&g->r, 1, gap / 2 > 1 ? gap / 2 : 1);
      o[m][0] = x + w; o[m][1] = H; m++;
      o[m][0] = x + rnd(&g->r, -1, 1); o[m][1] = yb + rnd(&g->r, 1, 3); m++;
      o[m][0] = x - w; o[m][1] = H; m++;
    }
    o[m][0] = 0; o[m][1] = H; m++;
    face2(g, &pl, m, (const int64_t (*)[2])o);
  }
  /* something in front now and then */
  if (rnd(&g->r, 0, 1)) {
    struct plane pl;
    int64_t O[3] = { rnd(&g->r, -100, 100), rnd(&g->r, -100, 100), rnd(&g->r, 100, 140) };
    int64_t U[3] = { 1, 0, rnd(&g->r, -1, 1) }, V[3] = { 0, 1, 0 };
    memcpy(pl.O, O, sizeof O); memcpy(pl.U, U, sizeof U); memcpy(pl.V, V, sizeof V);
    int64_t o[4][2];
    rect(0, 0, rnd(&g->r, 2, 20), rnd(&g->r, 2, 20), o);
    face2(g, &pl, 4, (const int64_t (*)[2])o);
  }
}

static int hole2(struct gen *g, const struct plane *pl, int face, int n, const int64_t (*ab)[2])
{
  if (face < 0 || n < 3 || n > 64 || !simple2(n, ab)) return -1;
  int vi[64];
  for (int k = 0; k < n; k++) {
    int64_t p[3];
    at(pl, ab[k][0], ab[k][1], p);
    vi[k] = put(g, p);
  }
  if (g->bad) return -1;
  if (xr_hole(g->s, face, n, vi) != 0) { g->bad = 2; return -1; }
  return 0;
}

static void fam_holes(struct gen *g)
{
  struct plane pl;
  rplane(g, &pl, 10);
  int64_t A = rnd(&g->r, 8, 20), B = rnd(&g->r, 8, 20), o[4][2];
  rect(0, 0, A, B, o);
  int f = face2(g, &pl, 4, (const int64_t (*)[2])o);
  /* one or two holes, apart, strictly inside */
  int64_t a0 = rnd(&g->r, 1, A / 2 - 1), a1 = rnd(&g->r, a0 + 1, A / 2);
  int64_t b0 = rnd(&g->r, 1, B - 3), b1 = rnd(&g->r, b0 + 1, B - 1);
  int64_t h[4][2];
  rect(a0, b0, a1, b1, h);
  hole2(g, &pl, f, 4, (const int64_t (*)[2])h);
  int64_t c0 = A / 2 + 1, c1 = rnd(&g->r, c0 + 1, A - 1);
  int64_t d0 = rnd(&g->r, 1, B - 3), d1 = rnd(&g->r, d0 + 1, B - 1);
  bool two = c1 > c0 && rnd(&g->r, 0, 1);
  if (two) {
    int64_t t[4][2] = { { c0, d0 }, { c1, (d0 + d1) / 2 }, { c0, d1 }, { c0, d1 } };
    hole2(g, &pl, f, 3, (const int64_t (*)[2])t);
  }
  /* a coplanar face filling the first hole, or overlapping its edge */
  if (rnd(&g->r, 0, 1)) {
    face2(g, &pl, 4, (const int64_t (*)[2])h);
  } else {
    int64_t w[4][2];
    rect(a0 - rnd(&g->r, 0, 1), b0, a1 + rnd(&g->r, 0, 1), b1 + rnd(&g->r, 0, 1), w);
    face2(g, &pl, 4, (const int64_t (*)[2])w);
  }
  /* faces piercing the plate at a hole's corner or through the hole */
  int np = (int)rnd(&g->r, 1, 2);
  for (int k = 0; k < np; k++) {
    int64_t p[3];
    int c = (int)rnd(&g->r, 0, 3);
    if (rnd(&g->r, 0, 2)) at(&pl, h[c][0], h[c][1], p);
    else at(&pl, rnd(&g->r, 0, A), rnd(&g->r, 0, B), p);
    piercer(g, &pl, p, rnd(&g->r, 0, 3) != 0);
  }
}

static void fam_one(struct gen *g, int fam);

static void fam_crowd(struct gen *g)
{
  struct plane pl[3];
  int np = (int)rnd(&g->r, 1, 3);
  for (int k = 0; k < np; k++) rplane(g, &pl[k], 10);
  int64_t hub[3][3];
  for (int k = 0; k < 3; k++) at(&pl[k % np], rnd(&g->r, -4, 4), rnd(&g->r, -4, 4), hub[k]);
  int n = (int)rnd(&g->r, 10, 24);
  for (int k = 0; k < n; k++) {
    int64_t p[3][3];
    for (int c = 0; c < 3; c++) {
      switch (rnd(&g->r, 0, 3)) {
      case 0: memcpy(p[c], hub[rnd(&g->r, 0, 2)], sizeof p[c]); break;     /* a shared point */
      case 1: at(&pl[rnd(&g->r, 0, np - 1)], rnd(&g->r, -8, 8), rnd(&g->r, -8, 8), p[c]); break;
      default:
        for (int q = 0; q < 3; q++) p[c][q] = hub[0][q] + rnd(&g->r, -90, 90);
        break;
      }
    }
    tri3(g, p[0], p[1], p[2]);
  }
}

static void fam_mix(struct gen *g)
{
  static const int pick[] = { HG_WALL, HG_COPLANAR, HG_VSHARE, HG_TJUNC, HG_SNAPPED, HG_HOLES,
                              HG_SLIVER };
  int n = (int)rnd(&g->r, 2, 3);
  for (int k = 0; k < n && !g->bad; k++)
    fam_one(g, pick[rnd(&g->r, 0, (long)(sizeof pick / sizeof pick[0]) - 1)]);
}

static void fam_one(struct gen *g, int fam)
{
  switch (fam) {
  case HG_WALL: fam_wall(g); break;
  case HG_COPLANAR: fam_coplanar(g); break;
  case HG_VSHARE: fam_vshare(g); break;
  case HG_TJUNC: fam_tjunc(g); break;
  case HG_SLIVER: fam_sliver(g); break;
  case HG_FAR: fam_far(g); break;
  case HG_EDGEON: fam_edgeon(g); break;
  case HG_FOLD: fam_fold(g); break;
  case HG_HOLES: fam_holes(g); break;
  case HG_MIX: fam_mix(g); break;
  case HG_CROWD: fam_crowd(g); break;
  default: fam_snapped(g); break;
  }
}

/* ---- the camera --------------------------------------------------------------------- */

static void window_fit(struct gen *g)
{
  struct xr_scene *s = g->s;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  double ex = s->eye[0], ey = s->eye[1], ez = s->eye[2];
  for (int k = 0; k < s->nv; k++) {
    double w = s->v[k][2] - ez;
    double x = ex + (-ez) * (s->v[k][0] - ex) / w, y = ey + (-ez) * (s->v[k][1] - ey) / w;
    if (x < x0) x0 = x;
    if (x > x1) x1 = x;
    if (y < y0) y0 = y;
    if (y > y1) y1 = y;
  }
  if (s->nv == 0) { x0 = y0 = -10; x1 = y1 = 10; }
  /* now and then zoom onto a vertex: many point centres near a coincidence */
  if (s->nv > 0 && rnd(&g->r, 0, 2) == 0) {
    int k = (int)rnd(&g->r, 0, s->nv - 1);
    double w = s->v[k][2] - ez;
    double x = ex + (-ez) * (s->v[k][0] - ex) / w, y = ey + (-ez) * (s->v[k][1] - ey) / w;
    double h = (x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0) / (double)rnd(&g->r, 3, 12);
    x0 = x - h; x1 = x + h; y0 = y - h; y1 = y + h;
  }
  long xl = (long)(x0 >= 0 ? x0 : x0 - 1) - 1, xr = (long)(x1 >= 0 ? x1 + 1 : x1) + 1;
  long yb = (long)(y0 >= 0 ? y0 : y0 - 1) - 1, yt = (long)(y1 >= 0 ? y1 + 1 : y1) + 1;
  if (rnd(&g->r, 0, 1)) {                /* keep 4:3, like the tube */
    long w = xr - xl, h = yt - yb;
    if (3 * w > 4 * h) { long nh = (3 * w + 3) / 4; yb -= (nh - h) / 2; yt = yb + nh; }
    else { long nw = (4 * h + 2) / 3; xl -= (nw - w) / 2; xr = xl + nw; }
  }
  if (xl < -32768) xl = -32768;
  if (yb < -32768) yb = -32768;
  if (xr > 32767) xr = 32767;
  if (yt > 32767) yt = 32767;
  s->win[0] = (int32_t)xl; s->win[1] = (int32_t)yb; s->win[2] = (int32_t)xr; s->win[3] = (int32_t)yt;
}

int hg_generate(int fam, uint64_t seed, struct xr_scene *s)
{
  for (uint64_t attempt = 0;; attempt++) {
    memset(s, 0, sizeof *s);
    struct gen g;
    g.r.s = seed * 0x2545F4914F6CDD1Dull + (uint64_t)fam * 0x9E3779B97F4A7C15ull + attempt * 7919;
    g.s = s;
    g.next_id = 1;
    g.bad = 0;
    s->eye[0] = (int32_t)rnd(&g.r, -30, 30);
    s->eye[1] = (int32_t)rnd(&g.r, -30, 30);
    s->eye[2] = (int32_t)rnd(&g.r, -2000, -150);
    fam_one(&g, fam);
    if (g.bad == 2) { xr_scene_free(s); return -1; }
    if (!g.bad && s->nf >= 1) {
      /* shuffle the face numbers now and then: the tie rules must hold either way */
      if (rnd(&g.r, 0, 1))
        for (int k = s->nf - 1; k > 0; k--) {
          int j = (int)rnd(&g.r, 0, k);
          unsigned t = s->f[k].id; s->f[k].id = s->f[j].id; s->f[j].id = t;
        }
      window_fit(&g);
      return 0;
    }
    xr_scene_free(s);
    if (attempt > 1000) return -1;
  }
}
