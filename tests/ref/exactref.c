/*
** exactref.c — the exact reference of the differential tests (see exactref.h).
**
** This file contains an independent, deliberately plain answer to the visible face at
** each point centre: it projects and rounds by the contract's formula, inserts T-junction
** vertices, tests every face with an even-odd ray cast under the documented tie rule and
** compares exact plane depths. Nothing here is shared with render/; it is a test
** reference, not part of the pipeline.
*/
#include "tests/ref/exactref.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

__extension__ typedef __int128 i128;
__extension__ typedef unsigned __int128 u128;

/* ---- building ----------------------------------------------------------------------- */

int xr_vertex(struct xr_scene *s, int32_t x, int32_t y, int32_t z)
{
  if (s->nv == s->capv) {
    int c = s->capv ? 2 * s->capv : 32;
    void *n = realloc(s->v, (size_t)c * sizeof *s->v);
    if (!n) return -1;
    s->v = n;
    s->capv = c;
  }
  s->v[s->nv][0] = x; s->v[s->nv][1] = y; s->v[s->nv][2] = z;
  return s->nv++;
}

int xr_face(struct xr_scene *s, unsigned id, int nv, const int *vi)
{
  if (s->nf == s->capf) {
    int c = s->capf ? 2 * s->capf : 16;
    void *n = realloc(s->f, (size_t)c * sizeof *s->f);
    if (!n) return -1;
    s->f = n;
    s->capf = c;
  }
  struct xr_face *f = &s->f[s->nf];
  memset(f, 0, sizeof *f);
  f->id = id;
  f->grey = -1;
  f->nring = 1;
  f->rs = malloc(2 * sizeof *f->rs);
  f->vi = malloc((size_t)(nv ? nv : 1) * sizeof *f->vi);
  if (!f->rs || !f->vi) { free(f->rs); free(f->vi); return -1; }
  f->rs[0] = 0; f->rs[1] = nv;
  memcpy(f->vi, vi, (size_t)nv * sizeof *vi);
  return s->nf++;
}

int xr_hole(struct xr_scene *s, int face, int nv, const int *vi)
{
  struct xr_face *f = &s->f[face];
  int tot = f->rs[f->nring];
  int *rs = realloc(f->rs, (size_t)(f->nring + 2) * sizeof *rs);
  if (!rs) return -1;
  f->rs = rs;
  int *v = realloc(f->vi, (size_t)(tot + nv) * sizeof *v);
  if (!v) return -1;
  f->vi = v;
  memcpy(f->vi + tot, vi, (size_t)nv * sizeof *vi);
  f->nring++;
  f->rs[f->nring] = tot + nv;
  return 0;
}

void xr_scene_free(struct xr_scene *s)
{
  for (int k = 0; k < s->nf; k++) { free(s->f[k].rs); free(s->f[k].vi); }
  free(s->f);
  free(s->v);
  memset(s, 0, sizeof *s);
}

int xr_write(struct xr_scene *s, FILE *o)
{
  int line = 1;
  fprintf(o, "# exact-reference scene (tests/ref)\n"); line++;
  fprintf(o, "view %d %d %d\n", s->eye[0], s->eye[1], s->eye[2]); line++;
  fprintf(o, "window %d %d %d %d\n", s->win[0], s->win[1], s->win[2], s->win[3]); line++;
  for (int k = 0; k < s->nv; k++, line++)
    fprintf(o, "vertex %d %d %d %d\n", k + 1, s->v[k][0], s->v[k][1], s->v[k][2]);
  for (int k = 0; k < s->nf; k++, line++) {
    struct xr_face *f = &s->f[k];
    f->line = line;
    fprintf(o, "face %u", f->id);
    for (int r = 0; r < f->nring; r++) {
      if (r) fprintf(o, " *");
      for (int q = f->rs[r]; q < f->rs[r + 1]; q++) fprintf(o, " %d", f->vi[q] + 1);
    }
    if (f->on) fprintf(o, " on %u", f->on);
    if (f->grey >= 0) fprintf(o, " grey %d", f->grey);
    fprintf(o, "\n");
  }
  return ferror(o) ? -1 : 0;
}

/* ---- reading (the subset written above) --------------------------------------------- */

static int next_tok(const char **p, char *tok, size_t n)
{
  const char *q = *p;
  while (*q == ' ' || *q == '\t' || *q == '\r') q++;
  if (*q == '\0' || *q == '\n' || *q == '#') { *p = q; return 0; }
  size_t k = 0;
  while (*q && !isspace((unsigned char)*q)) { if (k + 1 < n) tok[k++] = *q; q++; }
  tok[k] = '\0';
  *p = q;
  return 1;
}

int xr_read(const char *text, struct xr_scene *s, char *err, size_t errlen)
{
  memset(s, 0, sizeof *s);
  int *map = calloc(65536, sizeof *map);          /* vertex id -> index + 1 */
  if (!map) { snprintf(err, errlen, "out of memory"); return -1; }
  const char *p = text;
  int line = 0;
  char tok[64];
  while (*p) {
    line++;
    const char *q = p;
    if (next_tok(&q, tok, sizeof tok)) {
      long a[4];
      if (!strcmp(tok, "view") || !strcmp(tok, "window") || !strcmp(tok, "vertex")) {
        int n = !strcmp(tok, "view") ? 3 : 4;
        char kind = !strcmp(tok, "view") ? 'e' : !strcmp(tok, "window") ? 'w' : 'v';
        for (int k = 0; k < n; k++) {
          if (!next_tok(&q, tok, sizeof tok)) goto bad;
          a[k] = strtol(tok, NULL, 10);
        }
        if (kind == 'e') for (int k = 0; k < 3; k++) s->eye[k] = (int32_t)a[k];
        else if (kind == 'w') for (int k = 0; k < 4; k++) s->win[k] = (int32_t)a[k];
        else {
          if (a[0] < 1 || a[0] > 65535 || map[a[0]]) goto bad;
          int v = xr_vertex(s, (int32_t)a[1], (int32_t)a[2], (int32_t)a[3]);
          if (v < 0) goto bad;
          map[a[0]] = v + 1;
        }
      } else if (!strcmp(tok, "face")) {
        if (!next_tok(&q, tok, sizeof tok)) goto bad;
        unsigned id = (unsigned)strtoul(tok, NULL, 10);
        int vi[1024], nvi = 0, rs[64], nr = 1, grey = -1;
        unsigned on = 0;
        rs[0] = 0;
        while (next_tok(&q, tok, sizeof tok)) {
          if (!strcmp(tok, "*")) { if (nr == 63) goto bad; rs[nr++] = nvi; continue; }
          if (!strcmp(tok, "grey")) {
            if (!next_tok(&q, tok, sizeof tok)) goto bad;
            grey = atoi(tok);
            continue;
          }
          if (!strcmp(tok, "on")) {
            if (!next_tok(&q, tok, sizeof tok)) goto bad;
            on = (unsigned)strtoul(tok, NULL, 10);
            continue;
          }
          long v = strtol(tok, NULL, 10);
          if (v < 1 || v > 65535 || !map[v] || nvi == 1024) goto bad;
          vi[nvi++] = map[v] - 1;
        }
        rs[nr] = nvi;
        int f = xr_face(s, id, rs[1], vi);
        if (f < 0) goto bad;
        for (int r = 1; r < nr; r++)
          if (xr_hole(s, f, rs[r + 1] - rs[r], vi + rs[r]) < 0) goto bad;
        s->f[f].grey = grey;
        s->f[f].on = on;
        s->f[f].line = line;
      } else if (strcmp(tok, "light") && strcmp(tok, "effects") && strcmp(tok, "object") &&
                 strcmp(tok, "background")) {
        goto bad;
      }
    }
    while (*p && *p != '\n') p++;
    if (*p) p++;
  }
  free(map);
  return 0;
bad:
  snprintf(err, errlen, "line %d: not understood by the exact reference", line);
  free(map);
  xr_scene_free(s);
  return -1;
}

/* ---- projection and the grid polygon ------------------------------------------------ */

static int64_t fdiv(int64_t n, int64_t d)           /* floor(n / d), d > 0 */
{
  int64_t q = n / d;
  return (n % d != 0 && n < 0) ? q - 1 : q;
}

/* 256 * (e + (-ez) (p - e) / (z - ez)), rounded half up: floor((2 * 256 * num + w) / 2w) */
static int64_t proj1(int64_t p, int64_t z, int64_t e, int64_t ez)
{
  int64_t w = z - ez;
  int64_t num = 256 * (e * w + (-ez) * (p - e));
  return fdiv(2 * num + w, 2 * w);
}

/* v strictly inside segment a-b in space */
static int inside_seg(const int32_t *a, const int32_t *b, const int32_t *v)
{
  int64_t d[3], e[3];
  for (int c = 0; c < 3; c++) { d[c] = (int64_t)b[c] - a[c]; e[c] = (int64_t)v[c] - a[c]; }
  if (d[1] * e[2] != d[2] * e[1] || d[2] * e[0] != d[0] * e[2] || d[0] * e[1] != d[1] * e[0])
    return 0;
  int64_t t = d[0] * e[0] + d[1] * e[1] + d[2] * e[2];
  int64_t dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  return t > 0 && t < dd;
}

static int64_t seg_param(const int32_t *a, const int32_t *b, const int32_t *v)
{
  int64_t t = 0;
  for (int c = 0; c < 3; c++) t += ((int64_t)b[c] - a[c]) * ((int64_t)v[c] - a[c]);
  return t;
}

/* ---- is the grid polygon simple? (exact; edges of all rings pairwise) --------------- */

static int sgn128(i128 v) { return (v > 0) - (v < 0); }

static i128 orient3(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx, int64_t cy)
{
  return (i128)(bx - ax) * (cy - ay) - (i128)(by - ay) * (cx - ax);
}

static int between(int64_t a, int64_t b, int64_t p)
{
  return p >= (a < b ? a : b) && p <= (a < b ? b : a);
}

/* closed segments ab and cd meet */
static int segs_meet(int64_t ax, int64_t ay, int64_t bx, int64_t by,
                     int64_t cx, int64_t cy, int64_t dx, int64_t dy)
{
  int d1 = sgn128(orient3(cx, cy, dx, dy, ax, ay)), d2 = sgn128(orient3(cx, cy, dx, dy, bx, by));
  int d3 = sgn128(orient3(ax, ay, bx, by, cx, cy)), d4 = sgn128(orient3(ax, ay, bx, by, dx, dy));
  if (d1 * d2 < 0 && d3 * d4 < 0) return 1;
  if (!d1 && between(cx, dx, ax) && between(cy, dy, ay)) return 1;
  if (!d2 && between(cx, dx, bx) && between(cy, dy, by)) return 1;
  if (!d3 && between(ax, bx, cx) && between(ay, by, cy)) return 1;
  if (!d4 && between(ax, bx, dx) && between(ay, by, dy)) return 1;
  return 0;
}

/* Simple: after dropping repeated consecutive points, no two edges meet except
   neighbours at their shared point (and those do not overlap). Conservative: a hole
   touching the boundary counts as not simple (that only widens the band). */
static int grid_simple(const struct xr_pface *f)
{
  int tot = 0;
  for (int g = 0; g < f->nring; g++) tot += f->ring[g].n;
  int64_t (*e)[4] = malloc((size_t)(tot ? tot : 1) * sizeof *e);
  int *ring = malloc((size_t)(tot ? tot : 1) * sizeof *ring);
  if (!e || !ring) { free(e); free(ring); return 0; }
  int ne = 0;
  for (int g = 0; g < f->nring; g++) {
    const struct xr_ring *R = &f->ring[g];
    for (int k = 0; k < R->n; k++) {
      int64_t ax = R->x[k], ay = R->y[k], bx = R->x[(k + 1) % R->n], by = R->y[(k + 1) % R->n];
      if (ax == bx && ay == by) continue;
      e[ne][0] = ax; e[ne][1] = ay; e[ne][2] = bx; e[ne][3] = by;
      ring[ne++] = g;
    }
  }
  int ok = 1;
  for (int i = 0; i < ne && ok; i++)
    for (int j = i + 1; j < ne && ok; j++) {
      const int64_t *a = e[i], *b = e[j];
      int next = ring[i] == ring[j] && (a[2] == b[0] && a[3] == b[1]);
      int prev = ring[i] == ring[j] && (b[2] == a[0] && b[3] == a[1]);
      if (next || prev) {
        /* neighbours: they must not fold back over each other */
        const int64_t *p = next ? a : b, *q = next ? b : a;    /* p ends where q starts */
        if (sgn128(orient3(p[0], p[1], p[2], p[3], q[2], q[3])) == 0 &&
            (i128)(p[2] - p[0]) * (q[2] - q[0]) + (i128)(p[3] - p[1]) * (q[3] - q[1]) < 0)
          ok = 0;
        if (next && prev) ok = 0;                 /* a ring of two edges */
        continue;
      }
      if (segs_meet(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3])) ok = 0;
    }
  free(e);
  free(ring);
  return ok;
}

/* distance from (x, y) to the closest chord between two grid vertices of f */
static long double chord_dist(const struct xr_pface *f, long double x, long double y)
{
  long double best = 1e30L;
  for (int g = 0; g < f->nring; g++)
    for (int h = g; h < f->nring; h++) {
      const struct xr_ring *A = &f->ring[g], *B = &f->ring[h];
      for (int i = 0; i < A->n; i++)
        for (int j = g == h ? i + 1 : 0; j < B->n; j++) {
          long double ax = (long double)A->x[i], ay = (long double)A->y[i];
          long double dx = (long double)B->x[j] - ax, dy = (long double)B->y[j] - ay;
          long double l2 = dx * dx + dy * dy, t = 0;
          if (l2 > 0) t = ((x - ax) * dx + (y - ay) * dy) / l2;
          if (t < 0) t = 0;
          if (t > 1) t = 1;
          long double ex = ax + t * dx - x, ey = ay + t * dy - y;
          long double d = sqrtl(ex * ex + ey * ey);
          if (d < best) best = d;
        }
    }
  return best;
}

int xr_prepare(const struct xr_scene *s, int cell, struct xr_ref *r)
{
  memset(r, 0, sizeof *r);
  r->W = 400 / cell;
  r->H = 300 / cell;
  for (int c = 0; c < 3; c++) r->eye[c] = s->eye[c];
  memcpy(r->win, s->win, sizeof r->win);
  r->nf = s->nf;
  r->f = calloc((size_t)(s->nf ? s->nf : 1), sizeof *r->f);
  char *used = calloc((size_t)(s->nv ? s->nv : 1), 1);
  int *ins = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *ins);
  if (!r->f || !used || !ins) { free(used); free(ins); xr_ref_free(r); return -1; }
  for (int k = 0; k < s->nf; k++)
    for (int q = 0; q < s->f[k].rs[s->f[k].nring]; q++) used[s->f[k].vi[q]] = 1;
  const int64_t E[3] = { s->eye[0], s->eye[1], s->eye[2] };
  for (int k = 0; k < s->nf; k++) {
    const struct xr_face *f = &s->f[k];
    struct xr_pface *pf = &r->f[k];
    pf->id = f->id;
    pf->on = f->on;
    /* plane from the first non-collinear triple of the outer ring */
    int n0 = f->rs[1];
    const int32_t *p0 = s->v[f->vi[0]];
    i128 nn[3] = { 0, 0, 0 };
    for (int a = 1; a < n0 && !(nn[0] || nn[1] || nn[2]); a++)
      for (int b = a + 1; b < n0 && !(nn[0] || nn[1] || nn[2]); b++) {
        const int32_t *p1 = s->v[f->vi[a]], *p2 = s->v[f->vi[b]];
        i128 u[3], w[3];
        for (int c = 0; c < 3; c++) { u[c] = p1[c] - p0[c]; w[c] = p2[c] - p0[c]; }
        nn[0] = u[1] * w[2] - u[2] * w[1];
        nn[1] = u[2] * w[0] - u[0] * w[2];
        nn[2] = u[0] * w[1] - u[1] * w[0];
      }
    i128 d = -(nn[0] * p0[0] + nn[1] * p0[1] + nn[2] * p0[2]);
    i128 D = nn[0] * E[0] + nn[1] * E[1] + nn[2] * E[2] + d;
    if (D > 0) { for (int c = 0; c < 3; c++) nn[c] = -nn[c]; D = -D; }
    for (int c = 0; c < 3; c++) pf->n[c] = nn[c];
    pf->D = D;
    pf->used = D != 0;
    pf->nring = f->nring;
    pf->ring = calloc((size_t)f->nring, sizeof *pf->ring);
    if (!pf->ring) goto oom;
    pf->bx0 = pf->by0 = INT64_MAX;
    pf->bx1 = pf->by1 = INT64_MIN;
    for (int rg = 0; rg < f->nring; rg++) {
      int b = f->rs[rg], e = f->rs[rg + 1], n = e - b;
      /* count first, then fill: each edge plus the vertices strictly inside it */
      struct xr_ring *R = &pf->ring[rg];
      int cap = n;
      for (int q = 0; q < n; q++) {
        const int32_t *A = s->v[f->vi[b + q]], *B = s->v[f->vi[b + (q + 1) % n]];
        for (int v = 0; v < s->nv; v++)
          if (used[v] && inside_seg(A, B, s->v[v])) cap++;
      }
      R->x = malloc((size_t)cap * sizeof *R->x);
      R->y = malloc((size_t)cap * sizeof *R->y);
      if (!R->x || !R->y) goto oom;
      for (int q = 0; q < n; q++) {
        const int32_t *A = s->v[f->vi[b + q]], *B = s->v[f->vi[b + (q + 1) % n]];
        int ni = 0;
        for (int v = 0; v < s->nv; v++)
          if (used[v] && inside_seg(A, B, s->v[v])) {
            int j = ni++;
            int64_t t = seg_param(A, B, s->v[v]);
            while (j > 0 && seg_param(A, B, s->v[ins[j - 1]]) > t) { ins[j] = ins[j - 1]; j--; }
            ins[j] = v;
          }
        for (int m = -1; m < ni; m++) {
          const int32_t *P = m < 0 ? A : s->v[ins[m]];
          int64_t x = proj1(P[0], P[2], E[0], E[2]), y = proj1(P[1], P[2], E[1], E[2]);
          R->x[R->n] = x; R->y[R->n] = y; R->n++;
          if (x < pf->bx0) pf->bx0 = x;
          if (x > pf->bx1) pf->bx1 = x;
          if (y < pf->by0) pf->by0 = y;
          if (y > pf->by1) pf->by1 = y;
        }
      }
    }
  }
  for (int k = 0; k < r->nf; k++) r->f[k].folded = !grid_simple(&r->f[k]);
  free(used);
  free(ins);
  return 0;
oom:
  free(used);
  free(ins);
  xr_ref_free(r);
  return -1;
}

void xr_ref_free(struct xr_ref *r)
{
  if (r->f)
    for (int k = 0; k < r->nf; k++) {
      for (int g = 0; g < r->f[k].nring && r->f[k].ring; g++) {
        free(r->f[k].ring[g].x);
        free(r->f[k].ring[g].y);
      }
      free(r->f[k].ring);
    }
  free(r->f);
  memset(r, 0, sizeof *r);
}

/* ---- one point ---------------------------------------------------------------------- */

/* The centre of (i, j) in grid units: (xn / xd, yn / yd). */
struct centre { int64_t xn, xd, yn, yd; };

static struct centre centre_of(const struct xr_ref *r, int i, int j)
{
  struct centre c;
  int64_t XL = r->win[0], YB = r->win[1], XR = r->win[2], YT = r->win[3];
  c.xd = 2 * (int64_t)r->W;
  c.xn = 256 * (c.xd * XL + (2 * (int64_t)i + 1) * (XR - XL));
  c.yd = 2 * (int64_t)r->H;
  c.yn = 256 * (c.yd * YT - (2 * (int64_t)j + 1) * (YT - YB));
  return c;
}

/* Even-odd with the centre shifted by (e, e^2): an edge counts when it straddles the
   centre's y (an endpoint at that y counts as below) and the centre is strictly left of
   it. */
static int covers(const struct xr_pface *f, struct centre c)
{
  if (!f->used) return 0;
  /* bounding box (x0 <= x < x1 ... generous: a centre outside the closed box is out) */
  if ((i128)c.xn < (i128)f->bx0 * c.xd || (i128)c.xn > (i128)f->bx1 * c.xd) return 0;
  if ((i128)c.yn < (i128)f->by0 * c.yd || (i128)c.yn > (i128)f->by1 * c.yd) return 0;
  int in = 0;
  for (int g = 0; g < f->nring; g++) {
    const struct xr_ring *R = &f->ring[g];
    for (int k = 0; k < R->n; k++) {
      int64_t ax = R->x[k], ay = R->y[k];
      int64_t bx = R->x[(k + 1) % R->n], by = R->y[(k + 1) % R->n];
      int abelow = (i128)ay * c.yd <= c.yn, bbelow = (i128)by * c.yd <= c.yn;
      if (abelow == bbelow) continue;
      if (!abelow) { int64_t t = ax; ax = bx; bx = t; t = ay; ay = by; by = t; }
      /* a below, b above: centre strictly left of a->b */
      i128 o = (i128)(bx - ax) * ((i128)c.yn - (i128)ay * c.yd) * c.xd -
               (i128)(by - ay) * ((i128)c.xn - (i128)ax * c.xd) * c.yd;
      if (o > 0) in ^= 1;
    }
  }
  return in;
}

/* n.u scaled by 256 xd yd > 0, u = centre - eye in world units */
static i128 n_dot_u(const struct xr_pface *f, const struct xr_ref *r, struct centre c)
{
  i128 s = (i128)256 * c.xd * c.yd;
  i128 ux = (i128)c.xn * c.yd - s * r->eye[0];
  i128 uy = (i128)c.yn * c.xd - s * r->eye[1];
  i128 uz = -s * r->eye[2];
  return f->n[0] * ux + f->n[1] * uy + f->n[2] * uz;
}

/* sign of a*b - c*d for |a|, |b|, |c|, |d| < 2^127 */
static void umul(u128 a, u128 b, u128 *hi, u128 *lo)
{
  u128 m = ((u128)1 << 64) - 1;
  u128 a0 = a & m, a1 = a >> 64, b0 = b & m, b1 = b >> 64;
  u128 p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
  u128 mid = (p00 >> 64) + (p01 & m) + (p10 & m);
  *lo = (p00 & m) | (mid << 64);
  *hi = p11 + (p01 >> 64) + (p10 >> 64) + (mid >> 64);
}

static int cmp_prod(i128 a, i128 b, i128 c, i128 d)
{
  int s1 = (a > 0) - (a < 0), s2 = (b > 0) - (b < 0);
  int t1 = (c > 0) - (c < 0), t2 = (d > 0) - (d < 0);
  int sl = s1 * s2, sr = t1 * t2;
  if (sl != sr) return sl > sr ? 1 : -1;
  if (sl == 0) return 0;
  u128 h1, l1, h2, l2;
  umul((u128)(a < 0 ? -a : a), (u128)(b < 0 ? -b : b), &h1, &l1);
  umul((u128)(c < 0 ? -c : c), (u128)(d < 0 ? -d : d), &h2, &l2);
  int m = h1 != h2 ? (h1 > h2 ? 1 : -1) : l1 != l2 ? (l1 > l2 ? 1 : -1) : 0;
  return sl > 0 ? m : -m;
}

/* > 0 when face a is in front of face b at the centre, 0 on a tie of depth */
static int in_front(const struct xr_ref *r, const struct xr_pface *a, const struct xr_pface *b,
                    struct centre c)
{
  i128 ua = n_dot_u(a, r, c), ub = n_dot_u(b, r, c);
  /* a plane met behind the eye (n.u <= 0) is never in front */
  if (ua <= 0 || ub <= 0) return (ua > 0) - (ub > 0);
  /* t_a < t_b  <=>  |D_a| ub < |D_b| ua */
  return cmp_prod(-b->D, ua, -a->D, ub);
}

/* Equal depth (coplanar faces, as the contract fixes it): a face lying `on` the other is in
   front of it (paper 000 §3.2); a face lying on some face wins over one that lies on none;
   else the larger number. Does a win over b? */
static int tie_wins(const struct xr_pface *a, const struct xr_pface *b)
{
  if (a->on && a->on == b->id) return 1;
  if (b->on && b->on == a->id) return 0;
  if (!a->on != !b->on) return a->on != 0;
  return a->id > b->id;
}

static int front_index(const struct xr_ref *r, struct centre c)
{
  int best = -1;
  for (int k = 0; k < r->nf; k++) {
    if (!covers(&r->f[k], c)) continue;
    if (best < 0) { best = k; continue; }
    int s = in_front(r, &r->f[k], &r->f[best], c);
    if (s > 0 || (s == 0 && tie_wins(&r->f[k], &r->f[best]))) best = k;
  }
  return best;
}

unsigned xr_visible(const struct xr_ref *r, int i, int j)
{
  int k = front_index(r, centre_of(r, i, j));
  return k < 0 ? 0 : r->f[k].id;
}

/* distance in grid units from the centre to the projected intersection line of faces a, b */
static long double line_dist(const struct xr_ref *r, const struct xr_pface *a,
                             const struct xr_pface *b, struct centre c)
{
  /* G(x, y) = |D_b| n_a.u - |D_a| n_b.u, u = (x/256 - X0, y/256 - Y0, -Z0) */
  long double k[3];
  for (int q = 0; q < 3; q++)
    k[q] = (long double)(-b->D) * (long double)a->n[q] - (long double)(-a->D) * (long double)b->n[q];
  long double x = (long double)c.xn / c.xd, y = (long double)c.yn / c.yd;
  long double G = k[0] * (x / 256 - r->eye[0]) + k[1] * (y / 256 - r->eye[1]) + k[2] * (-r->eye[2]);
  long double g = sqrtl(k[0] * k[0] + k[1] * k[1]) / 256;
  if (g == 0) return 1e30L;
  long double dd = G / g;
  return dd < 0 ? -dd : dd;
}

int xr_judge(const struct xr_ref *r, int i, int j, unsigned got, unsigned *want)
{
  struct centre c = centre_of(r, i, j);
  int k = front_index(r, c);
  unsigned w = k < 0 ? 0 : r->f[k].id;
  if (want) *want = w;
  if (w == got) return 0;
  /* a folded face (got or want) near one of its chords */
  long double x = (long double)c.xn / c.xd, y = (long double)c.yn / c.yd;
  for (int g = 0; g < r->nf; g++)
    if (r->f[g].folded && (r->f[g].id == got || r->f[g].id == w) &&
        chord_dist(&r->f[g], x, y) <= XR_FOLD_BAND)
      return 1;
  if (k < 0 || got == 0) return -1;
  for (int g = 0; g < r->nf; g++) {
    if (r->f[g].id != got || !covers(&r->f[g], c)) continue;
    if (line_dist(r, &r->f[g], &r->f[k], c) <= XR_BAND) return 1;
  }
  return -1;
}
