/*
** edges.c — enhanced edges (paper 002 §3): classify the edges of the input faces and draw
** them as strips over the frame, hidden exactly like the faces.
**
** This file contains code for the last slot of the effects stage (effects/fx.h). Paper 002
** draws each edge as a strip stuck to its polygon inside a z-buffer scan; tube74 has no
** z-buffer, so the same picture is made from the frame of the priority renderer (the face
** seen at every point centre) and the faces' exact planes.
**
** 1. Which edges (§3.2). The rings of every input face, with T-junction vertices inserted
**    exactly as the Mapper inserts them (a vertex strictly inside a segment in space, an
**    exact integer test), give edge uses u->v. Uses are grouped by vertex pair and part:
**    an object, or, for a face in no object, the face itself (the triangles an import
**    splits one face into share its number and so one part; the edges between them are
**    not edges). Cuts of the Segment Generator never enter: they are not in the rings.
**    Intersection lines between faces are the lines L~ along which render/priority.c cut
**    crossing faces (struct prio_cut), clipped to where both faces are (class e4).
** 2. Orientation. Within a part, faces joined by an edge of exactly two uses are oriented
**    alike (opposite directions along the edge; a union-find with parity). A component is
**    closed when every edge of it has exactly two uses, the orientation is consistent and
**    its signed volume is not zero; its outward side is the one of positive volume (sum
**    of q.N over faces, N the exact Newell vector of the rings, holes reversed). A face of
**    a closed component is seen ("visible", §3.1) when its outward normal points to the
**    eye, exactly: (E - q).N > 0; seen edge-on (= 0) counts as turned away.
**    Open components (and single faces) are two-sided: each face shows one side to the eye
**    unless seen exactly edge-on.
** 3. Classes. Closed: both turned away e1; both seen: e1 in a smooth group (e'1), else e3;
**    one seen: e2 (silhouettes, e'2). Open: the two faces show the same side of the
**    surface: e3 (e1 if smooth); different sides, the surface folds away there: e2; an
**    edge of one face only (open boundary, single face): e2; a face seen edge-on shows
**    nothing. An edge of three or more faces of one part: each use alone, as e2.
**    e4: within one object inner (e3's width and grey), else outline (e2's).
** 4. Drawing (§3.3). Widths w in points, taken to 1/1024 point. In scaled integer
**    coordinates X = 2W x, Y = 2H y (x, y in plane-grid units), where point centres are
**    integers, an edge's line is K(X, Y) = A X + B Y + C = 0 and a centre is within
**    perpendicular distance w/2 (in points) exactly when
**        K^2 <= w^2 ((A sx)^2 + (B sy)^2)            (sx, sy: the window in grid units)
**    which is eq. (4)-(5) with l = w sqrt(dx^2+dy^2)/|dy| of eq. (3) on a row (|dx| on a
**    column), in 256-bit integers. The row pass takes edges with 10|dy| >= 9|dx| (tangent
**    against the row >= 0.9, in point units) and, on each row whose centre line lies
**    within the edge's extent, the centres of that strip; the column pass the same with
**    x and y exchanged. Points given a line by the row pass are left alone by the column
**    pass (§3.3.1). The test is made cheap and still exact by taking, once an edge, the
**    integer bound kline = the largest k with (WQ k)^2 <= wq^2 M (a floating-point square
**    root brackets it, exact 256-bit squares decide): a centre is on the line exactly when
**    |K| <= kline. Along a row the strip is
**    an interval of centres; a floating-point estimate says where to look, the exact
**    test finds both ends from the outside in, and the centres between are filled.
** 5. Hidden exactly. A strip point is kept only where the frame's face there is one of
**    the edge's own faces (by input number), the background, or a face lying behind the
**    edge: not nearer the eye, along the ray through the centre, than the planes of the
**    faces that draw the edge (the seen ones: §3.3's strip stuck to its polygon; planes
**    the ray does not meet ahead are left out, and with none left the point is hidden).
**    Depth is compared exactly as in priority.c: face F is hit at t = |D_F| / n_F.(r - E),
**    so F is behind G at r when |D_F| n_G.(r-E) >= |D_G| n_F.(r-E) (256-bit products).
**    Before the planes, F is held against the depths of the edge's two ends (t is the
**    same for every ray at one z: t = (z - Z0) / -Z0): nearer than both ends, F hides the
**    edge; behind both, the edge shows; only in between do the planes decide. So a face
**    in front of the whole edge always hides it, whatever the planes' slopes.
** 6. Rule 3, the halo. Beside an outline whose drawing faces all lie on one side of it,
**    centres on the other side between w/2 and w/2 + halo_w from the line get the halo's
**    grey, but only where another face (not the background, not the edge's own) shows
**    behind the edge, strictly farther (a window lying on its wall gets no halo). Lines always win over halos; outline over inner where strips meet.
** 7. With contour smoothing (paper 004) the outline follows the rounded contour: see
**    "the outline along the contour curve" below.
**
** The machine model: the edge table (5 words an edge: vertex ids, faces, class), the
** intersection lines (11 words each), the contour's corners (22 words each) and the
** registered points of the first pass (1 bit a point) are allocated in core for the stage
** and released after it; every exact test is counted with the multi-word costs of
** emu/cost.h.
*/
#include "effects/edges.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "effects/contour.h"
#include "effects/model.h"

#define WQ 1024                 /* widths in 1/WQ point */
#define EDGE_ROW_WORDS 5        /* EDGE TABLE: vertex ids 2, faces 2, class 1 */
#define E4_ROW_WORDS 11         /* INTERSECTION LINES: faces 2, class 1, a 2, b 2, c 4 */
#define MAX_OWN 2

enum { MK_NONE = 0, MK_HALO = 1, MK_INNER = 2, MK_OUTLINE = 3, MK_ROW = 4 };

/* One use of an edge by a face: the ring step u -> v in the face's own orientation. */
struct use {
  int lo, hi;             /* vertex indices, lo < hi */
  int64_t part;           /* object id, or 65536 + face id for a face in no object */
  int face;               /* scene face index */
  int dir;                /* +1: u = lo, v = hi; -1: the other way */
};

/* A drawable edge: a line, its extent and its faces. */
struct edge {
  int cls;                /* enum edge_class */
  const char *why;
  int va, vb;             /* scene vertex indices (-1, -1 for an intersection line) */
  int nown; uint32_t own[MAX_OWN];      /* input numbers of its faces */
  int ndraw; int draw[MAX_OWN];         /* mapped faces whose planes the strip lies in */
  int halo;               /* +1/-1: the side of K the halo goes on; 0: no halo */
  wide A, B, C;           /* K = A X + B Y + C, scaled coordinates, left of the edge > 0 */
  wide kline, khalo;      /* a centre is on the line when |K| <= kline, in the halo when
                             kline < |K| <= khalo on the halo's side (see kbound) */
  bool bounds;            /* kline and khalo are known */
  bool trange;            /* the depths of its ends are known: */
  wide tnear_n, tnear_d, tfar_n, tfar_d;   /* t (along the ray, as in priority.c) of its
                             nearer and farther end, as fractions with positive denominator */
  struct gpoint p, q;     /* the extent's ends on the grid */
  int sface[2];           /* scene faces (for the dump), -1 when none */
  int curve;              /* a segment of contour corner curve - 1 (0: an edge of the
                             faces or an intersection line) */
  bool gone;              /* a contour cut took the whole of it away: not drawn */
};

struct ectx {
  struct render *r;
  const struct scene *s;
  const struct vis_grid *g;
  struct fx_frame *f;
  struct cost *cost;
  int W, H;
  wide sx, sy;            /* window in grid units */
  wide S, T;              /* 512 W XL and 512 H YT: X of centre i is S + (2i+1) sx,
                             Y of centre j is T - (2j+1) sy */
  uint8_t *mark;          /* per point: MK_* class | MK_ROW */
  uint64_t pts_row, pts_col, pts_halo;
  int run_face;                 /* the face and edge of the last depth test (for its cost) */
  const struct edge *run_edge;
};

/* ---- small exact helpers ---------------------------------------------------------- */

static wide wabs(wide v) { return v < 0 ? -v : v; }
static int wsign(wide v) { return (v > 0) - (v < 0); }

static wide floor_div(wide n, wide d)            /* d > 0 */
{
  wide q = n / d;
  if (n % d != 0 && n < 0) q -= 1;
  return q;
}

static wide ceil_div(wide n, wide d) { return -floor_div(-n, d); }

/* compare n1/d1 with n2/d2 (d > 0) */
static int rat_cmp(wide n1, wide d1, wide n2, wide d2)
{
  return i256_sign(i256_add(i256_mul(n1, d2), i256_mul(-n2, d1)));
}

static int cmp_use(const void *a, const void *b)
{
  const struct use *x = a, *y = b;
  if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
  if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
  if (x->part != y->part) return x->part < y->part ? -1 : 1;
  return (x->face > y->face) - (x->face < y->face);
}

/* ---- T-junction rings ------------------------------------------------------------- */

struct rings {
  int *v;                 /* all rings' vertices */
  int *start;             /* per face: first ring offset into rs */
  int *rs;                /* ring starts into v; ring k is v[rs[k] .. rs[k+1]) */
  int nv, cap, nrs, rscap;
};

static int push_int(int **a, int *n, int *cap, int x)
{
  if (*n == *cap) {
    int c = *cap ? 2 * *cap : 256;
    int *b = realloc(*a, (size_t)c * sizeof *b);
    if (!b) return 0;
    *a = b;
    *cap = c;
  }
  (*a)[(*n)++] = x;
  return 1;
}

/* vertices used by faces, sorted by x then index (Shell sort, no context needed) */
static int *by_x(const struct scene *s, int *n)
{
  char *used = calloc((size_t)(s->nv ? s->nv : 1), 1);
  int *o = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *o);
  *n = 0;
  if (!used || !o) { free(used); free(o); return NULL; }
  for (int f = 0; f < s->nf; f++)
    for (int k = 0; k < s->f[f].ring_start[s->f[f].nring]; k++) used[s->f[f].vidx[k]] = 1;
  for (int v = 0; v < s->nv; v++) if (used[v]) o[(*n)++] = v;
  free(used);
  for (int gap = *n / 2; gap > 0; gap /= 2)
    for (int i = gap; i < *n; i++) {
      int v = o[i], j = i;
      while (j >= gap && (s->v[o[j - gap]].x > s->v[v].x ||
                          (s->v[o[j - gap]].x == s->v[v].x && o[j - gap] > v))) {
        o[j] = o[j - gap];
        j -= gap;
      }
      o[j] = v;
    }
  return o;
}

/* Append the vertices strictly inside segment a-b in space, from a to b (as the Mapper). */
static int tj_insert(const struct scene *s, const int *byx, int n, int a, int b,
                     struct rings *R, struct cost *cost)
{
  const struct scene_vertex *P = &s->v[a], *Q = &s->v[b];
  int32_t x0 = P->x < Q->x ? P->x : Q->x, x1 = P->x < Q->x ? Q->x : P->x;
  int64_t dx = Q->x - P->x, dy = Q->y - P->y, dz = Q->z - P->z;
  int64_t dd = dx * dx + dy * dy + dz * dz;
  int lo = 0, hi = n;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    COST_ADD_N(cost, COST_MEM, 2);
    if (s->v[byx[mid]].x < x0) lo = mid + 1; else hi = mid;
  }
  int first = R->nv;
  for (int k = lo; k < n && s->v[byx[k]].x <= x1; k++) {
    int v = byx[k];
    COST_ADD_N(cost, COST_MEM, 2);
    if (v == a || v == b) continue;
    const struct scene_vertex *V = &s->v[v];
    COST_ADD_N(cost, COST_ADD, 4);
    if ((V->y < P->y && V->y < Q->y) || (V->y > P->y && V->y > Q->y) ||
        (V->z < P->z && V->z < Q->z) || (V->z > P->z && V->z > Q->z)) continue;
    int64_t ex = V->x - P->x, ey = V->y - P->y, ez = V->z - P->z;
    cost_mw_mul(cost, 17, 17);
    if (dy * ez - dz * ey || dz * ex - dx * ez || dx * ey - dy * ex) continue;
    int64_t tt = ex * dx + ey * dy + ez * dz;
    if (tt <= 0 || tt >= dd) continue;
    if (!push_int(&R->v, &R->nv, &R->cap, v)) return 0;
    int j = R->nv - 1;
    while (j > first) {
      const struct scene_vertex *U = &s->v[R->v[j - 1]];
      int64_t tu = (U->x - P->x) * dx + (U->y - P->y) * dy + (U->z - P->z) * dz;
      if (tu <= tt) break;
      R->v[j] = R->v[j - 1];
      j--;
    }
    R->v[j] = v;
  }
  return 1;
}

static int build_rings(const struct scene *s, struct rings *R, struct cost *cost)
{
  memset(R, 0, sizeof *R);
  int n;
  int *byx = by_x(s, &n);
  R->start = malloc((size_t)(s->nf + 1) * sizeof *R->start);
  if (!byx || !R->start) { free(byx); return 0; }
  for (int fi = 0; fi < s->nf; fi++) {
    const struct scene_face *sf = &s->f[fi];
    R->start[fi] = R->nrs;
    for (int r = 0; r < sf->nring; r++) {
      if (!push_int(&R->rs, &R->nrs, &R->rscap, R->nv)) { free(byx); return 0; }
      int b = sf->ring_start[r], e = sf->ring_start[r + 1];
      for (int k = b; k < e; k++) {
        if (!push_int(&R->v, &R->nv, &R->cap, sf->vidx[k])) { free(byx); return 0; }
        if (!tj_insert(s, byx, n, sf->vidx[k], sf->vidx[k + 1 < e ? k + 1 : b], R, cost)) {
          free(byx);
          return 0;
        }
      }
    }
  }
  R->start[s->nf] = R->nrs;
  free(byx);
  return push_int(&R->rs, &R->nrs, &R->rscap, R->nv);
}

static void free_rings(struct rings *R) { free(R->v); free(R->start); free(R->rs); }

/* Newell vector of ring k: twice its vector area (exact for a planar ring). */
static void newell(const struct scene *s, const struct rings *R, int k, int64_t n[3],
                   struct cost *cost)
{
  n[0] = n[1] = n[2] = 0;
  int b = R->rs[k], e = R->rs[k + 1];
  for (int i = b; i < e; i++) {
    const struct scene_vertex *p = &s->v[R->v[i]], *q = &s->v[R->v[i + 1 < e ? i + 1 : b]];
    n[0] += ((int64_t)p->y - q->y) * ((int64_t)p->z + q->z);
    n[1] += ((int64_t)p->z - q->z) * ((int64_t)p->x + q->x);
    n[2] += ((int64_t)p->x - q->x) * ((int64_t)p->y + q->y);
    cost_mw_mul(cost, 17, 17); cost_mw_mul(cost, 17, 17); cost_mw_mul(cost, 17, 17);
  }
}

/* ---- union-find with parity (orientation within a part) --------------------------- */

static int uf_find(int *par, int8_t *flip, int x, int *parity)
{
  int p = 0, r = x;
  while (par[r] != r) { p ^= flip[r]; r = par[r]; }
  /* compress: point every node on the path at the root with its parity to it */
  int q = x, pq = p;
  while (par[q] != q) {
    int nx = par[q], fq = flip[q];
    par[q] = r;
    flip[q] = (int8_t)pq;
    pq ^= fq;
    q = nx;
  }
  *parity = p;
  return r;
}

/* ---- the strip of one edge in one pass -------------------------------------------- */

/* n.(r - E) for the centre (X, Y) scaled by 512W * 512H (|value| < 2^88). */
static wide plane_at(const struct ectx *c, const struct mface *m, wide X, wide Y)
{
  const int64_t *e = c->r->map.eye;
  wide SW = 512 * (wide)c->W, SH = 512 * (wide)c->H;
  return (wide)m->plane[0] * (X * SH - (wide)e[0] * SW * SH) +
         (wide)m->plane[1] * (Y * SW - (wide)e[1] * SW * SH) -
         (wide)m->plane[2] * (wide)e[2] * SW * SH;
}

/* Is the face F seen at the centre (X, Y) behind the edge? Nearer than both of the edge's
   ends: no; behind both (strict: farther): yes; else when it is not nearer the eye
   (strict: farther), along the ray, than any of the edge's drawing planes that the ray
   meets ahead (and there is one). */
static bool behind(struct ectx *c, const struct edge *ed, int F, wide X, wide Y, bool strict)
{
  const struct mface *mf = &c->r->map.f[F];
  wide dF = plane_at(c, mf, X, Y);
  /* Counted: the difference |D_F| n_G.(r-E) - |D_G| n_F.(r-E) is linear along a row (it is
     the priority module's G), so beside the point before, with the same faces, the 1974
     program steps it by one multi-word add; otherwise it evaluates it afresh. */
  bool step = c->run_face == F && c->run_edge == ed;
  c->run_face = F;
  c->run_edge = ed;
  if (step) {
    for (int k = 0; k < ed->ndraw; k++) { cost_mw_add(c->cost, 140); COST_ADD_N(c->cost, COST_BRANCH, 1); }
  } else {
    cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50);
  }
  if (dF <= 0) return false;              /* cannot happen for a face seen there */
  if (ed->trange) {
    /* First against the depths of the edge's two ends: nearer than both, F hides it;
       behind both, the edge is in front of F. t_F = |D_F| SW SH / dF. */
    wide SWH = 512 * (wide)c->W * 512 * (wide)c->H;
    wide tn = (wide)mf->deye * SWH;
    if (step) { cost_mw_add(c->cost, 190); cost_mw_add(c->cost, 190); }   /* stepped, as G */
    else { cost_mw_mul(c->cost, 52, 32); cost_mw_mul(c->cost, 100, 90); cost_mw_mul(c->cost, 100, 90); }
    if (rat_cmp(tn, dF, ed->tnear_n, ed->tnear_d) < 0) return false;
    int far = rat_cmp(tn, dF, ed->tfar_n, ed->tfar_d);
    if (far > 0 || (far == 0 && !strict)) return true;
  }
  int met = 0;
  for (int k = 0; k < ed->ndraw; k++) {
    const struct mface *mg = &c->r->map.f[ed->draw[k]];
    wide dG = plane_at(c, mg, X, Y);
    if (!step) {
      cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50);
      cost_mw_mul(c->cost, 52, 88); cost_mw_mul(c->cost, 52, 88);
    }
    if (dG <= 0) continue;                /* this plane does not meet the ray ahead */
    met++;
    /* t_F >= t_G:  |D_F| n_G.(r-E) >= |D_G| n_F.(r-E) */
    int sg = i256_sign(i256_add(i256_mul(mf->deye, dG), i256_mul(-(wide)mg->deye, dF)));
    if (sg < 0 || (strict && sg == 0)) return false;
  }
  return met > 0;
}

static bool own(const struct ectx *c, const struct edge *ed, int F)
{
  uint32_t id = c->r->map.f[F].id;
  for (int k = 0; k < ed->nown; k++) if (ed->own[k] == id) return true;
  return false;
}

/* bits of |v| plus a sign bit: the words a 16-bit machine needs for it (cost_words) */
static int wbits(wide v)
{
  uwide a = (uwide)(v < 0 ? -v : v);
  int n = 1;
  while (a) { n++; a >>= 1; }
  return n;
}

static bool kfits(struct i256 r, wide k, struct cost *cost)
{
  int b = wbits(WQ * k);
  cost_mw_mul(cost, b, b); cost_mw_add(cost, 2 * b); COST_ADD_N(cost, COST_BRANCH, 2);
  return i256_sign(i256_add(r, i256_mul(-WQ * k, WQ * k))) >= 0;
}

/* The largest K >= 0 with (WQ K)^2 <= r, where r = wq^2 M = (wq A sx)^2 + (wq B sy)^2, so
   that a centre is in the band exactly when |K| <= it (K is an integer). A floating-point
   square root brackets it; exact 256-bit squares decide it (a few steps of bisection). */
static wide kbound(struct i256 r, double u, double v, struct cost *cost)
{
  double est = sqrt(u * u + v * v) / WQ;
  cost_mw_div(cost, 2 * wbits((wide)est * WQ), wbits((wide)est * WQ));   /* the square root's estimate */
  wide k0 = (wide)est;
  if (kfits(r, k0, cost) && !kfits(r, k0 + 1, cost)) return k0;           /* the usual case */
  wide lo = (wide)(est * (1 - 1e-12)) - 2, hi = (wide)(est * (1 + 1e-12)) + 2;
  if (lo < 0) lo = 0;
  while (!kfits(r, lo, cost)) lo /= 2;        /* never taken unless the estimate is off */
  while (kfits(r, hi, cost)) hi *= 2;
  while (hi - lo > 1) {                       /* invariant: lo fits, hi does not */
    wide mid = lo + (hi - lo) / 2;
    if (kfits(r, mid, cost)) lo = mid; else hi = mid;
  }
  return lo;
}

/* Which band of the strip holds the centre (i, j): 2 the line (|d| <= w/2), 1 the halo
   (on the halo's side, w/2 < |d| <= w/2 + halo), 0 neither. Exact: |K| against the
   edge's bounds. Counted as the 1974 program would run it, K stepped along the row or
   column by one multi-word add from the centre before. */
static int band(struct ectx *c, const struct edge *ed, int i, int j)
{
  wide X = c->S + (2 * (wide)i + 1) * c->sx, Y = c->T - (2 * (wide)j + 1) * c->sy;
  wide K = ed->A * X + ed->B * Y + ed->C;
  int b = wbits(K);
  cost_mw_add(c->cost, b); cost_mw_add(c->cost, b);
  COST_ADD_N(c->cost, COST_BRANCH, 2);
  wide aK = wabs(K);
  if (aK <= ed->kline) return 2;
  if (!ed->halo || wsign(K) != ed->halo) return 0;
  cost_mw_add(c->cost, b);
  return aK <= ed->khalo ? 1 : 0;
}

/* Mark the centre (i, j) as kind (MK_INNER / MK_OUTLINE / MK_HALO) where what is seen
   there lets the edge show (§3.3.1: line points of the row pass are left alone). */
static void put_point(struct ectx *c, const struct edge *ed, int i, int j, int kind,
                      bool row_pass)
{
  size_t at = (size_t)j * (size_t)c->W + (size_t)i;
  uint8_t m = c->mark[at];
  COST_ADD_N(c->cost, COST_MEM, 2);
  COST_ADD_N(c->cost, COST_BRANCH, 3);
  if (!row_pass && (m & MK_ROW) && (m & 3) >= MK_INNER) return;   /* registered */
  if ((m & 3) >= kind) return;                                      /* a stronger mark */
  int F = c->f->face[at];
  bool ownf = F >= 0 && own(c, ed, F);
  COST_ADD_N(c->cost, COST_MEM, 1 + ed->nown);
  if (kind == MK_HALO) {
    if (F < 0 || ownf) return;
  } else if (F < 0 || ownf) goto keep;
  {
    wide X = c->S + (2 * (wide)i + 1) * c->sx, Y = c->T - (2 * (wide)j + 1) * c->sy;
    if (!behind(c, ed, F, X, Y, kind == MK_HALO)) return;
  }
keep:
  COST_ADD_N(c->cost, COST_MEM, 1);
  c->mark[at] = (uint8_t)(kind | (row_pass && kind >= MK_INNER ? MK_ROW : (m & MK_ROW)));
}

/* rows (row pass) or columns of centres within the extent [lo, hi] of the edge */
static void extent(const struct ectx *c, const struct edge *ed, bool rows, int *first,
                   int *last)
{
  wide lo, hi, w;
  if (rows) {
    lo = ed->p.y < ed->q.y ? ed->p.y : ed->q.y;
    hi = ed->p.y < ed->q.y ? ed->q.y : ed->p.y;
    /* lo <= T/2H - (2j+1) sy / 2H <= hi */
    wide a = ceil_div(c->T - 2 * (wide)c->H * hi - c->sy, 2 * c->sy);
    wide b = floor_div(c->T - 2 * (wide)c->H * lo - c->sy, 2 * c->sy);
    w = c->H;
    *first = a < 0 ? 0 : a > w ? (int)w : (int)a;
    *last = b >= w ? (int)w - 1 : b < -1 ? -1 : (int)b;
  } else {
    lo = ed->p.x < ed->q.x ? ed->p.x : ed->q.x;
    hi = ed->p.x < ed->q.x ? ed->q.x : ed->p.x;
    wide a = ceil_div(2 * (wide)c->W * lo - c->S - c->sx, 2 * c->sx);
    wide b = floor_div(2 * (wide)c->W * hi - c->S - c->sx, 2 * c->sx);
    w = c->W;
    *first = a < 0 ? 0 : a > w ? (int)w : (int)a;
    *last = b >= w ? (int)w - 1 : b < -1 ? -1 : (int)b;
  }
}

/* wq^2 M = (wq A sx)^2 + (wq B sy)^2: |wq A sx| < 2^16 2^38 2^25 (256-bit square) */
static struct i256 width2(const struct edge *ed, wide sx, wide sy, int64_t wq)
{
  wide u = wq * ed->A * sx, v = wq * ed->B * sy;
  return i256_add(i256_mul(u, u), i256_mul(v, v));
}

/* The edge's exact bounds kline and khalo (once an edge, when it is first drawn). */
static void edge_bounds(struct ectx *c, struct edge *ed, int64_t wline, int64_t whalo)
{
  double du = (double)ed->A * (double)c->sx, dv = (double)ed->B * (double)c->sy;
  ed->kline = kbound(width2(ed, c->sx, c->sy, wline), du * (double)wline,
                     dv * (double)wline, c->cost);
  ed->khalo = ed->halo ? kbound(width2(ed, c->sx, c->sy, wline + 2 * whalo),
                                du * (double)(wline + 2 * whalo), dv * (double)(wline + 2 * whalo),
                                c->cost) : 0;
  int b = wbits((wide)(wline + 2 * whalo) * (wabs(ed->A) * c->sx > wabs(ed->B) * c->sy
                                             ? wabs(ed->A) * c->sx : wabs(ed->B) * c->sy));
  cost_mw_mul(c->cost, b, b); cost_mw_mul(c->cost, b, b); cost_mw_add(c->cost, 2 * b);
}

static void draw_edge(struct ectx *c, struct edge *ed, bool row_pass, int64_t wline,
                      int64_t whalo, int line_mk)
{
  wide aA = wabs(ed->A) * c->sx, aB = wabs(ed->B) * c->sy;   /* 2 sy |dy|, 2 sx |dx| */
  if (aA == 0 && aB == 0) return;
  cost_mw_mul(c->cost, 40, 25); cost_mw_mul(c->cost, 40, 25); cost_mw_add(c->cost, 64);
  /* tangent of the edge against the row (in points) = |dy|/|dx| = (|A| sx)/(|B| sy) */
  if (row_pass ? 10 * aA < 9 * aB : 10 * aB < 9 * aA) return;
  double len = sqrt((double)aA * (double)aA + (double)aB * (double)aB);
  double half = (double)(wline + 2 * (ed->halo ? whalo : 0)) / (2.0 * WQ);
  int first, last;
  extent(c, ed, row_pass, &first, &last);
  COST_ADD_N(c->cost, COST_ADD, 4);
  if (first > last) return;                 /* no row (column) of the grid meets it */
  {                                          /* nor when its box, widened, misses the grid */
    wide m = ((wide)ceil(half) + 1) * 2;
    wide xa = 2 * (wide)c->W * ed->p.x, xb = 2 * (wide)c->W * ed->q.x;
    wide ya = 2 * (wide)c->H * ed->p.y, yb = 2 * (wide)c->H * ed->q.y;
    wide xlo = xa < xb ? xa : xb, xhi = xa < xb ? xb : xa;
    wide ylo = ya < yb ? ya : yb, yhi = ya < yb ? yb : ya;
    COST_ADD_N(c->cost, COST_ADD, 8);
    if (xhi < c->S + c->sx - m * c->sx || xlo > c->S + (2 * (wide)c->W - 1) * c->sx + m * c->sx ||
        yhi < c->T - (2 * (wide)c->H - 1) * c->sy - m * c->sy || ylo > c->T - c->sy + m * c->sy)
      return;
  }
  if (!ed->bounds) { edge_bounds(c, ed, wline, whalo); ed->bounds = true; }
  for (int k = first; k <= last; k++) {
    double ic, hl;
    int n;
    /* the crossing steps from row to row (a DDA: one multi-word add), the ends of the
       strip from it by l/2 of eq. (3)-(5) (two adds) */
    cost_mw_add(c->cost, 80); cost_mw_add(c->cost, 80); cost_mw_add(c->cost, 80);
    if (row_pass) {
      wide Y = c->T - (2 * (wide)k + 1) * c->sy;
      double X = -((double)ed->B * (double)Y + (double)ed->C) / (double)ed->A;
      ic = (X - (double)c->S) / (2.0 * (double)c->sx) - 0.5;
      hl = half * len / (double)aA;
      n = c->W;
    } else {
      wide X = c->S + (2 * (wide)k + 1) * c->sx;
      double Y = -((double)ed->A * (double)X + (double)ed->C) / (double)ed->B;
      ic = ((double)c->T - Y) / (2.0 * (double)c->sy) - 0.5;
      hl = half * len / (double)aB;
      n = c->H;
    }
    double lo = floor(ic - hl) - 1, hi = ceil(ic + hl) + 1;
    if (hi < 0 || lo >= n) continue;
    int a = lo < 0 ? 0 : (int)lo, b = hi >= n ? n - 1 : (int)hi;
    /* Along a row (column) each band is an interval of centres: find the line's ends
       exactly from the outside in, then the halo's beyond them; fill between. */
#define BAND(t) (row_pass ? band(c, ed, (t), k) : band(c, ed, k, (t)))
#define PUT(t, kind) (row_pass ? put_point(c, ed, (t), k, (kind), true) \
                               : put_point(c, ed, k, (t), (kind), false))
    int l0 = a, l1 = b, bl, bh = 0;
    while (l0 <= b && (bl = BAND(l0)) != 2) {
      if (bl == 1) PUT(l0, MK_HALO);
      l0++;
    }
    if (l0 > b) continue;
    c->run_face = -2;             /* a new row: depth differences are evaluated afresh */
    while (l1 > l0 && (bh = BAND(l1)) != 2) {
      if (bh == 1) PUT(l1, MK_HALO);
      l1--;
    }
    COST_ADD_N(c->cost, COST_ADD, 2);
    for (int t = l0; t <= l1; t++) PUT(t, line_mk);
#undef BAND
#undef PUT
  }
}

/* ---- intersection lines (e4) ------------------------------------------------------ */

struct ival { wide n0, d0, n1, d1; };   /* [n0/d0, n1/d1] along the parameter */

/* Clip the line l to piece P: the closed interval of the parameter (x when |b| >= |a|,
   else y) where l lies in P. False when it misses. */
static bool clip_piece(const struct piece *P, struct gline l, bool byx, struct ival *out,
                       struct cost *cost)
{
  bool has_lo = false, has_hi = false;
  wide ln = 0, ld = 1, hn = 0, hd = 1;
  for (int k = 0; k < P->n; k++) {
    struct gline h = piece_line(P, k);
    wide al, be;
    cost_mw_mul(cost, 30, 30); cost_mw_mul(cost, 30, 60); cost_mw_add(cost, 90);
    if (byx) {       /* y = -(a x + c)/b */
      int sb = l.b > 0 ? 1 : -1;
      al = ((wide)h.a * l.b - (wide)h.b * l.a) * sb;
      be = ((wide)h.c * l.b - (wide)h.b * l.c) * sb;
    } else {         /* x = -(b y + c)/a */
      int sa = l.a > 0 ? 1 : -1;
      al = ((wide)h.b * l.a - (wide)h.a * l.b) * sa;
      be = ((wide)h.c * l.a - (wide)h.a * l.c) * sa;
    }
    /* al t + be >= 0 */
    if (al == 0) { if (be < 0) return false; continue; }
    wide n = -be, d = al;
    if (d < 0) { n = -n; d = -d; }
    if (al > 0) {                     /* t >= n/d */
      if (!has_lo || rat_cmp(n, d, ln, ld) > 0) { ln = n; ld = d; has_lo = true; }
    } else {                          /* t <= n/d */
      if (!has_hi || rat_cmp(n, d, hn, hd) < 0) { hn = n; hd = d; has_hi = true; }
    }
  }
  if (!has_lo || !has_hi || rat_cmp(ln, ld, hn, hd) >= 0) return false;
  out->n0 = ln; out->d0 = ld; out->n1 = hn; out->d1 = hd;
  return true;
}

static int cmp_ival(const struct ival *a, const struct ival *b)
{
  return rat_cmp(a->n0, a->d0, b->n0, b->d0);
}

/* The merged intervals of l inside face `face` (its live pieces), sorted. */
static int face_ivals(const struct seginfo *sg, int face, struct gline l, bool byx,
                      struct ival **out, struct cost *cost)
{
  int n = 0, cap = 0;
  struct ival *v = NULL;
  for (int k = 0; k < sg->n; k++) {
    if (!sg->p[k].alive || sg->p[k].face != face) continue;
    struct ival iv;
    if (!clip_piece(&sg->p[k], l, byx, &iv, cost)) continue;
    if (n == cap) {
      cap = cap ? 2 * cap : 8;
      struct ival *nv = realloc(v, (size_t)cap * sizeof *nv);
      if (!nv) { free(v); return -1; }
      v = nv;
    }
    /* insertion, by start */
    int j = n++;
    while (j > 0 && cmp_ival(&v[j - 1], &iv) > 0) { v[j] = v[j - 1]; j--; }
    v[j] = iv;
  }
  int m = 0;
  for (int k = 0; k < n; k++) {
    if (m && rat_cmp(v[k].n0, v[k].d0, v[m - 1].n1, v[m - 1].d1) <= 0) {
      if (rat_cmp(v[k].n1, v[k].d1, v[m - 1].n1, v[m - 1].d1) > 0) {
        v[m - 1].n1 = v[k].n1; v[m - 1].d1 = v[k].d1;
      }
    } else v[m++] = v[k];
  }
  *out = v;
  return m;
}

/* round(n/d) half up, d > 0 */
static wide round_rat(wide n, wide d) { return floor_div(2 * n + d, 2 * d); }

/* the grid point of l at parameter n/d */
static struct gpoint on_line(struct gline l, bool byx, wide n, wide d)
{
  struct gpoint p;
  if (byx) {
    p.x = (gcoord)round_rat(n, d);
    wide num = -((wide)l.a * n + (wide)l.c * d), den = (wide)l.b * d;
    if (den < 0) { num = -num; den = -den; }
    p.y = (gcoord)round_rat(num, den);
  } else {
    p.y = (gcoord)round_rat(n, d);
    wide num = -((wide)l.b * n + (wide)l.c * d), den = (wide)l.a * d;
    if (den < 0) { num = -num; den = -den; }
    p.x = (gcoord)round_rat(num, den);
  }
  return p;
}

/* ---- the run ------------------------------------------------------------------------ */

struct elist { struct edge *e; int n, cap; };

static struct edge *add_edge(struct elist *L)
{
  if (L->n == L->cap) {
    int c = L->cap ? 2 * L->cap : 64;
    struct edge *n = realloc(L->e, (size_t)c * sizeof *n);
    if (!n) return NULL;
    L->e = n;
    L->cap = c;
  }
  struct edge *e = &L->e[L->n++];
  memset(e, 0, sizeof *e);
  e->va = e->vb = -1;
  e->sface[0] = e->sface[1] = -1;
  return e;
}

/* Side (+1 left, -1 right, 0 unknown) of mapped face m relative to the line u -> v. */
static int face_side(const struct mface *m, uint32_t u, uint32_t v)
{
  for (int r = 0; r < m->nring; r++) {
    int b = m->ring_start[r], e = m->ring_start[r + 1];
    for (int k = b; k < e; k++) {
      uint32_t a = m->vid[k], z = m->vid[k + 1 < e ? k + 1 : b];
      if (a == u && z == v) return 1;
      if (a == v && z == u) return -1;
    }
  }
  return 0;
}

/* ---- the outline along the contour curve (papers 004 and 002) ---------------------- */

/* Where contour smoothing (effects/contour.h) rounds a convex corner Q2 of an object, the
   object ends at the curve, not at the corner: the outline goes along the curve.
   - The corner's two sides stop where the curve begins and ends: the side a-b at Q0, the
     side b-c at Q4 (their lines stay the sides' own; only the extents end there). A side
     both of whose ends are rounded away and nothing left between is not drawn.
   - Every other drawn edge of the object that leaves the corner vertex into the corner
     (inside the angle Q0 Q2 Q4) stops where it crosses the curve (the crossing, exact in
     integers, rounded once onto the grid), or is not drawn when it ends inside the cut.
   - The curve's CONTOUR_STEPS segments, the very points the cut is made with
     (contour_region), are outlines (e2), drawn like every edge: their faces are the
     patches A and B, their planes hide and are hidden as an edge's faces are; the halo
     goes on their right, away from the object (the contour runs counter-clockwise).
   The machine model: each corner's row in CONTOUR OUTLINE (Q0..Q4, 4 words each, and the
   two faces); the curve's points are made again from them into one buffer of
   CONTOUR_STEPS + 1 points for each pass, counted as contour.c counts them. */

#define CORNER_ROW_WORDS 22     /* CONTOUR OUTLINE: Q0..Q4 (x, y: 2 words each), faces 2 */

struct ccount { long curve, sides, inner, gone; };

/* End `at` (a scene vertex) of regular edge ed moves to point t; gone when nothing is left
   of it along its own direction. */
static void cut_end(const struct scene *s, struct edge *ed, int at, struct gpoint t,
                    struct cost *cost)
{
  struct gpoint P = mapper_point(s, ed->va), Q = mapper_point(s, ed->vb);
  if (ed->va == at) ed->p = t; else ed->q = t;
  wide dot = (wide)(ed->q.x - ed->p.x) * (Q.x - P.x) + (wide)(ed->q.y - ed->p.y) * (Q.y - P.y);
  cost_mw_mul(cost, 30, 30); cost_mw_mul(cost, 30, 30); cost_mw_add(cost, 60);
  if (dot <= 0) ed->gone = true;
}

/* Where the segment b -> o first leaves the corner's region across the curve pts[0..n]:
   the crossing farthest from b along it, rounded onto the grid. False when it does not
   cross (it ends inside). */
static bool leave_curve(struct gpoint b, struct gpoint o, const struct gpoint *pts, int n,
                        struct gpoint *out, struct cost *cost)
{
  bool found = false;
  wide bn = 0, bd = 1;                  /* the parameter along b -> o, bn / bd */
  for (int m = 0; m < n; m++) {
    struct gpoint u = pts[m], v = pts[m + 1];
    wide su = geom_orient(b, o, u), sv = geom_orient(b, o, v);
    wide tb = geom_orient(u, v, b), to = geom_orient(u, v, o);
    for (int k = 0; k < 4; k++) cost_mw_mul(cost, 30, 30);
    COST_ADD_N(cost, COST_BRANCH, 4);
    if ((su > 0 && sv > 0) || (su < 0 && sv < 0)) continue;
    if ((tb > 0 && to > 0) || (tb < 0 && to < 0) || tb == to) continue;
    wide n_ = tb, d_ = tb - to;          /* t = tb / (tb - to), in [0, 1] */
    if (d_ < 0) { n_ = -n_; d_ = -d_; }
    if (!found || rat_cmp(n_, d_, bn, bd) > 0) { bn = n_; bd = d_; found = true; }
  }
  if (!found) return false;
  /* exact: |bn|, bd < 2^61 (orientations of 2^29 coordinates), |o - b| < 2^30 */
  out->x = b.x + (gcoord)round_rat(bn * (wide)(o.x - b.x), bd);
  out->y = b.y + (gcoord)round_rat(bn * (wide)(o.y - b.y), bd);
  cost_mw_mul(cost, 60, 30); cost_mw_div(cost, 90, 60);
  cost_mw_mul(cost, 60, 30); cost_mw_div(cost, 90, 60);
  return true;
}

static int face_object(const struct scene *s, const struct edge *ed)
{
  return ed->sface[0] >= 0 ? s->f[ed->sface[0]].object : 0;
}

/* The contour's corners into the edges (see above): sides and edges from the corners cut
   back, the curves' segments appended to L. */
static int contour_outline(struct ectx *c, const struct effects *e,
                           const struct contour_corners *cc, struct elist *L, int nregular,
                           struct ccount *n, struct t74_error *err)
{
  const struct scene *s = c->s;
  struct render *r = c->r;
  uint32_t rows, buf;
  int rc = core_alloc(r->core, "CONTOUR OUTLINE", (uint32_t)cc->n * CORNER_ROW_WORDS, &rows, err);
  if (rc == T74_OK)
    rc = core_alloc(r->core, "CONTOUR OUTLINE CURVE", (CONTOUR_STEPS + 1) * 4, &buf, err);
  if (rc != T74_OK) return rc;
  for (int k = 0; k < cc->n; k++) {
    const struct contour_corner *q = &cc->c[k];
    uint32_t at = rows + (uint32_t)k * CORNER_ROW_WORDS;
    for (int i = 0; i < 5; i++) {
      core_put_int(r->core, at + 4 * (uint32_t)i, 2, q->q[i].x);
      core_put_int(r->core, at + 4 * (uint32_t)i + 2, 2, q->q[i].y);
    }
    core_write(r->core, at + 20, (uint16_t)r->map.f[q->mface_a].id);
    core_write(r->core, at + 21, (uint16_t)r->map.f[q->mface_b].id);
    COST_ADD_N(c->cost, COST_MEM, CORNER_ROW_WORDS);
  }
  /* the edges from each corner vertex, cut back to the curve */
  for (int k = 0; k < cc->n; k++) {
    const struct contour_corner *q = &cc->c[k];
    struct gpoint poly[CONTOUR_STEPS + 2], pts[CONTOUR_STEPS + 1];
    contour_region(q->q, poly);
    for (int m = 0; m <= CONTOUR_STEPS; m++) pts[m] = poly[CONTOUR_STEPS + 1 - m];
    struct gpoint b = q->q[2], pa = mapper_point(s, q->va), pc = mapper_point(s, q->vc);
    for (int i = 0; i < nregular; i++) {
      struct edge *ed = &L->e[i];
      COST_ADD_N(c->cost, COST_MEM, 3); COST_ADD_N(c->cost, COST_BRANCH, 3);
      if (ed->gone || (ed->va != q->vb && ed->vb != q->vb) || face_object(s, ed) != q->object)
        continue;
      int o = ed->va == q->vb ? ed->vb : ed->va;
      if (o == q->va || o == q->vc) {               /* a side: to Q0 or Q4 */
        cut_end(s, ed, q->vb, o == q->va ? q->q[0] : q->q[4], c->cost);
        n->sides++;
        continue;
      }
      if (ed->cls == EDGE_E1) continue;
      struct gpoint po = mapper_point(s, o), t;
      cost_mw_mul(c->cost, 30, 30); cost_mw_mul(c->cost, 30, 30);
      if (geom_orient(b, pc, po) <= 0 || geom_orient(b, po, pa) <= 0) continue;  /* not into it */
      n->inner++;
      if (leave_curve(b, po, pts, CONTOUR_STEPS, &t, c->cost)) cut_end(s, ed, q->vb, t, c->cost);
      else ed->gone = true;
    }
  }
  /* the curves' segments */
  wide SWH = 512 * (wide)c->W * 512 * (wide)c->H;
  for (int k = 0; k < cc->n; k++) {
    const struct contour_corner *q = &cc->c[k];
    struct gpoint poly[CONTOUR_STEPS + 2];
    contour_region(q->q, poly);
    int mf[2] = { q->mface_a, q->mface_b };
    for (int m = 0; m < CONTOUR_STEPS; m++) {
      struct edge *ed = add_edge(L);
      if (!ed) return t74_fail(err, T74_EIO, "out of host memory");
      ed->cls = EDGE_E2;
      ed->why = "contour curve (paper 004 Def. 9)";
      ed->curve = k + 1;
      ed->p = poly[CONTOUR_STEPS + 1 - m];         /* from Q0 towards Q4 */
      ed->q = poly[CONTOUR_STEPS - m];
      for (int h = 0; h < 2 && (h == 0 || mf[1] != mf[0]); h++) {
        ed->own[ed->nown++] = r->map.f[mf[h]].id;
        ed->draw[ed->ndraw++] = mf[h];
        ed->sface[h] = r->map.f[mf[h]].sface;
      }
      wide DX = 2 * (wide)c->W * (ed->q.x - ed->p.x), DY = 2 * (wide)c->H * (ed->q.y - ed->p.y);
      wide XP = 2 * (wide)c->W * ed->p.x, YP = 2 * (wide)c->H * ed->p.y;
      ed->A = -DY;
      ed->B = DX;
      ed->C = DY * XP - DX * YP;
      cost_mw_mul(c->cost, 40, 40); cost_mw_mul(c->cost, 40, 40);
      ed->halo = e->halo_w > 0 ? -1 : 0;       /* right of Q0 -> Q4: away from the object */
      /* the ends' depths on the planes of A and B: the nearest and the farthest */
      for (int h = 0; h < ed->ndraw; h++) {
        const struct mface *F = &r->map.f[ed->draw[h]];
        wide tn = (wide)F->deye * SWH;
        struct gpoint ends[2] = { ed->p, ed->q };
        for (int z = 0; z < 2; z++) {
          wide d = plane_at(c, F, 2 * (wide)c->W * ends[z].x, 2 * (wide)c->H * ends[z].y);
          cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50); cost_mw_mul(c->cost, 34, 50);
          if (d <= 0) continue;
          if (!ed->trange || rat_cmp(tn, d, ed->tnear_n, ed->tnear_d) < 0) { ed->tnear_n = tn; ed->tnear_d = d; }
          if (!ed->trange || rat_cmp(tn, d, ed->tfar_n, ed->tfar_d) > 0) { ed->tfar_n = tn; ed->tfar_d = d; }
          ed->trange = true;
        }
      }
      n->curve++;
    }
  }
  return T74_OK;
}

/* The curve's points made again for one pass (the host keeps the segments; the 1974
   program would make each corner's points into CONTOUR OUTLINE CURVE again): counted. */
static void curve_pass_cost(const struct contour_corners *cc, struct cost *cost)
{
  for (int k = 0; k < cc->n; k++) {
    COST_ADD_N(cost, COST_MEM, CORNER_ROW_WORDS + 4 * (CONTOUR_STEPS + 1));
    for (int m = 0; m < 2 * (CONTOUR_STEPS + 1); m++) {
      for (int h = 0; h < 4; h++) cost_mw_mul(cost, 32, 16);
      COST_ADD_N(cost, COST_ADD, 4);
    }
  }
}

static const char *const class_name[] = { "e1 not drawn", "e2 outline", "e3 inner",
                                          "e4 intersection (inner)",
                                          "e4 intersection (outline)" };

int edge_run(struct render *r, const struct scene *s, const struct effects *e,
             const struct vis_grid *g, struct fx_frame *f, unsigned passes,
             struct fx_stats *st, struct cost *cost, struct t74_error *err)
{
  int status = T74_OK;
  struct rings R;
  struct use *u = NULL;
  int nu = 0;
  int *par = NULL; int64_t *part = NULL; int *sf2m = NULL, *sigma = NULL, *outw = NULL, *bad = NULL;
  int8_t *flip = NULL;
  bool *smooth = NULL;
  wide *vol = NULL;
  struct elist L = { NULL, 0, 0 };
  struct ectx c;
  memset(&c, 0, sizeof c);
  uint32_t mark0 = core_mark(r->core);
  const int nf = s->nf;

  if (!build_rings(s, &R, cost)) goto oom;
  int nuse = R.nv;
  u = malloc((size_t)(nuse ? nuse : 1) * sizeof *u);
  par = malloc((size_t)(nf ? nf : 1) * sizeof *par);
  flip = calloc((size_t)(nf ? nf : 1), sizeof *flip);
  part = malloc((size_t)(nf ? nf : 1) * sizeof *part);
  sf2m = malloc((size_t)(nf ? nf : 1) * sizeof *sf2m);
  sigma = calloc((size_t)(nf ? nf : 1), sizeof *sigma);
  outw = calloc((size_t)(nf ? nf : 1), sizeof *outw);
  bad = calloc((size_t)(nf ? nf : 1), sizeof *bad);
  smooth = calloc((size_t)(nf ? nf : 1), sizeof *smooth);
  vol = calloc((size_t)(nf ? nf : 1), sizeof *vol);
  if (!u || !par || !flip || !part || !sf2m || !sigma || !outw || !bad || !smooth || !vol)
    goto oom;
  for (int k = 0; k < nf; k++) { par[k] = k; sf2m[k] = -1; }
  for (int k = 0; k < r->map.nface; k++) sf2m[r->map.f[k].sface] = k;
  for (int o = 0; o < s->nobj; o++)
    for (int k = 0; k < s->obj[o].nface; k++) smooth[s->obj[o].face[k]] = s->obj[o].smooth;
  /* smooth= (paper 004) smooths every patch of an object (a triangle shaded from the
     lights, effects/smooth.h): the edges two patches of one object share are no creases
     any more, so they are not drawn, like a smooth group's (e'1) */
  if (e->smooth != EFFECTS_SMOOTH_NONE)
    for (int k = 0; k < nf; k++) {
      const struct scene_face *sf_ = &s->f[k];
      if (sf_->object && sf_->nring == 1 && sf_->ring_start[1] == 3 && sf_->grey < 0 && s->has_light)
        smooth[k] = true;
    }

  /* faces: which way each ring turns, which side the eye sees, the uses of its edges */
  const int64_t *E = r->map.eye;
  for (int fi = 0; fi < nf; fi++) {
    const struct scene_face *sf = &s->f[fi];
    part[fi] = sf->object ? (int64_t)sf->object : 65536 + (int64_t)sf->id;
    int64_t n0[3], N[3];
    newell(s, &R, R.start[fi], n0, cost);
    memcpy(N, n0, sizeof N);
    const struct scene_vertex *q = &s->v[R.v[R.rs[R.start[fi]]]];
    wide facing = ((wide)E[0] - q->x) * n0[0] + ((wide)E[1] - q->y) * n0[1] +
                  ((wide)E[2] - q->z) * n0[2];
    cost_mw_mul(cost, 34, 17); cost_mw_mul(cost, 34, 17); cost_mw_mul(cost, 34, 17);
    sigma[fi] = wsign(facing);
    for (int rk = R.start[fi]; rk < R.start[fi + 1]; rk++) {
      int rev = 0;
      if (rk != R.start[fi]) {          /* a hole runs against its outer ring */
        int64_t nh[3];
        newell(s, &R, rk, nh, cost);
        wide dot = (wide)nh[0] * n0[0] + (wide)nh[1] * n0[1] + (wide)nh[2] * n0[2];
        rev = dot > 0;
        for (int a = 0; a < 3; a++) N[a] += rev ? -nh[a] : nh[a];
      }
      int b = R.rs[rk], en = R.rs[rk + 1];
      for (int k = b; k < en; k++) {
        int p = R.v[k], qq = R.v[k + 1 < en ? k + 1 : b];
        if (rev) { int t = p; p = qq; qq = t; }
        struct use *w = &u[nu++];
        w->lo = p < qq ? p : qq;
        w->hi = p < qq ? qq : p;
        w->dir = p < qq ? 1 : -1;
        w->part = part[fi];
        w->face = fi;
      }
    }
    vol[fi] = (wide)q->x * N[0] + (wide)q->y * N[1] + (wide)q->z * N[2];
  }
  qsort(u, (size_t)nu, sizeof *u, cmp_use);
  {
    double lg = nu > 1 ? log2((double)nu) : 1;
    uint64_t cmps = (uint64_t)((double)nu * lg);
    COST_ADD_N(cost, COST_MEM, 4 * cmps);
    COST_ADD_N(cost, COST_ADD, 2 * cmps);
    COST_ADD_N(cost, COST_BRANCH, 2 * cmps);
  }

  /* orientation: join faces across edges of two uses; flag faces on open, non-manifold
     or contradictory edges (their component is not closed) */
  for (int a = 0; a < nu;) {
    int b = a + 1;
    while (b < nu && u[b].lo == u[a].lo && u[b].hi == u[a].hi && u[b].part == u[a].part) b++;
    COST_ADD_N(cost, COST_MEM, 3 * (b - a));
    if (b - a == 2) {
      int pa, pb;
      int ra = uf_find(par, flip, u[a].face, &pa), rb = uf_find(par, flip, u[a + 1].face, &pb);
      int want = u[a].dir == u[a + 1].dir;          /* 1: their orientations differ */
      if (ra != rb) { par[rb] = ra; flip[rb] = (int8_t)(pa ^ pb ^ want); }
      else if ((pa ^ pb) != want) bad[u[a].face] = 1;   /* cannot be oriented */
    } else {
      for (int k = a; k < b; k++) bad[u[k].face] = 1;
    }
    a = b;
  }
  /* per component: broken? its signed volume 6V, oriented as its root face */
  wide *cv = calloc((size_t)(nf ? nf : 1), sizeof *cv);
  int *badc = calloc((size_t)(nf ? nf : 1), sizeof *badc);
  if (!cv || !badc) { free(cv); free(badc); goto oom; }
  for (int fi = 0; fi < nf; fi++) {
    int p;
    int rt = uf_find(par, flip, fi, &p);
    cv[rt] += p ? -vol[fi] : vol[fi];
    badc[rt] |= bad[fi];
    cost_mw_add(cost, 100);
  }
  for (int fi = 0; fi < nf; fi++) {
    int p;
    int rt = uf_find(par, flip, fi, &p);
    bool closed = !badc[rt] && cv[rt] != 0 && part[fi] < 65536;
    /* outw: +1/-1 the outward side relative to the face's own ring (closed), 0 open */
    outw[fi] = closed ? (p ? -1 : 1) * (cv[rt] > 0 ? 1 : -1) : 0;
  }
  free(cv);
  free(badc);

  /* the edge table */
  int nsplit = 0;
  for (int a = 0; a < nu;) {
    int b = a + 1;
    while (b < nu && u[b].lo == u[a].lo && u[b].hi == u[a].hi && u[b].part == u[a].part) b++;
    int n = b - a;
    if (n == 2 && s->f[u[a].face].id == s->f[u[a + 1].face].id) {
      u[nsplit++] = u[a];              /* not an edge: listed in the dump (u[0..a) is done) */
      a = b;
      continue;
    }
    int groups = n == 2 ? 1 : n;
    for (int gk = 0; gk < groups; gk++) {
      struct edge *ed = add_edge(&L);
      if (!ed) goto oom;
      ed->va = u[a].lo;
      ed->vb = u[a].hi;
      int fa = u[a + gk].face;
      ed->sface[0] = fa;
      ed->own[ed->nown++] = s->f[fa].id;
      bool seen_a, seen_b = false;
      if (n == 2) {
        int fb = u[a + 1].face;
        ed->sface[1] = fb;
        ed->own[ed->nown++] = s->f[fb].id;
        if (outw[fa] && outw[fb]) {
          seen_a = sigma[fa] * outw[fa] > 0;
          seen_b = sigma[fb] * outw[fb] > 0;
          if (!seen_a && !seen_b) { ed->cls = EDGE_E1; ed->why = "both faces turned away"; }
          else if (seen_a && seen_b) {
            bool sm = smooth[fa] && smooth[fb] && s->f[fa].object == s->f[fb].object;
            ed->cls = sm ? EDGE_E1 : EDGE_E3;
            ed->why = sm ? "both faces seen, smooth group or smoothed patches (e'1)" : "both faces seen";
          } else { ed->cls = EDGE_E2; ed->why = "one face seen (silhouette)"; }
        } else {
          seen_a = sigma[fa] != 0;
          seen_b = sigma[fb] != 0;
          int same = (u[a].dir != u[a + 1].dir) ? sigma[fa] == sigma[fb] : sigma[fa] == -sigma[fb];
          if (!seen_a && !seen_b) { ed->cls = EDGE_E1; ed->why = "open surface, both faces edge-on"; }
          else if (!seen_a || !seen_b) { ed->cls = EDGE_E2; ed->why = "open surface, one face edge-on"; }
          else if (same) {
            bool sm = smooth[fa] && smooth[fb] && s->f[fa].object == s->f[fb].object;
            ed->cls = sm ? EDGE_E1 : EDGE_E3;
            ed->why = sm ? "open surface, same side seen, smooth group or smoothed patches"
                         : "open surface, same side of both faces seen";
          } else { ed->cls = EDGE_E2; ed->why = "open surface folds away (one side each)"; }
        }
      } else {
        seen_a = sigma[fa] != 0;
        ed->cls = seen_a ? EDGE_E2 : EDGE_E1;
        ed->why = !seen_a ? "its only face is seen edge-on"
                  : n == 1 ? "edge of one face only" : "edge of three or more faces: each alone";
      }
      COST_ADD_N(cost, COST_MEM, 8);
      COST_ADD_N(cost, COST_BRANCH, 6);
      /* drawing faces: the seen ones the Mapper kept */
      bool sa[2] = { seen_a, seen_b };
      for (int k = 0; k < ed->nown; k++) {
        int m = sf2m[ed->sface[k]];
        if (sa[k] && m >= 0) ed->draw[ed->ndraw++] = m;
      }
    }
    a = b;
  }
  int nregular = L.n;

  /* intersection lines: L~ of each cut pair, where both faces are */
  for (int k = 0; k < r->prio.ncut; k++) {
    const struct prio_cut *ct = &r->prio.cut[k];
    struct gline l = ct->line;
    bool byx = (l.b < 0 ? -l.b : l.b) >= (l.a < 0 ? -l.a : l.a);
    struct ival *ia = NULL, *ib = NULL;
    int na = face_ivals(&r->seg, ct->fa, l, byx, &ia, cost);
    int nb = face_ivals(&r->seg, ct->fb, l, byx, &ib, cost);
    if (na < 0 || nb < 0) { free(ia); free(ib); goto oom; }
    for (int x = 0, y = 0; x < na && y < nb;) {
      struct ival v;
      bool lo_a = rat_cmp(ia[x].n0, ia[x].d0, ib[y].n0, ib[y].d0) >= 0;
      v.n0 = lo_a ? ia[x].n0 : ib[y].n0; v.d0 = lo_a ? ia[x].d0 : ib[y].d0;
      bool hi_a = rat_cmp(ia[x].n1, ia[x].d1, ib[y].n1, ib[y].d1) <= 0;
      v.n1 = hi_a ? ia[x].n1 : ib[y].n1; v.d1 = hi_a ? ia[x].d1 : ib[y].d1;
      if (rat_cmp(v.n0, v.d0, v.n1, v.d1) < 0) {
        struct edge *ed = add_edge(&L);
        if (!ed) { free(ia); free(ib); goto oom; }
        const struct mface *A = &r->map.f[ct->fa], *B = &r->map.f[ct->fb];
        int oa = s->f[A->sface].object, ob = s->f[B->sface].object;
        ed->cls = oa && oa == ob ? EDGE_E4_INNER : EDGE_E4_OUTLINE;
        ed->why = oa && oa == ob ? "faces of one object cross" : "faces of different parts cross";
        ed->own[0] = A->id; ed->own[1] = B->id; ed->nown = 2;
        ed->draw[0] = ct->fa; ed->draw[1] = ct->fb; ed->ndraw = 2;
        ed->sface[0] = A->sface; ed->sface[1] = B->sface;
        ed->p = on_line(l, byx, v.n0, v.d0);
        ed->q = on_line(l, byx, v.n1, v.d1);
        /* K in scaled coordinates: 4WH L(X/2W, Y/2H) */
        ed->A = 2 * (wide)g->H * l.a;
        ed->B = 2 * (wide)g->W * l.b;
        ed->C = 4 * (wide)g->W * g->H * l.c;
      }
      if (hi_a) x++; else y++;
    }
    free(ia);
    free(ib);
  }

  /* the tables in core */
  uint32_t et, lt, mt;
  size_t npts = (size_t)f->W * (size_t)f->H;
  if (core_alloc(r->core, "EDGE TABLE", (uint32_t)nregular * EDGE_ROW_WORDS, &et, err) != T74_OK ||
      core_alloc(r->core, "INTERSECTION LINES", (uint32_t)(L.n - nregular) * E4_ROW_WORDS, &lt, err) != T74_OK ||
      core_alloc(r->core, "EDGE MARKS", (uint32_t)((npts + 15) / 16), &mt, err) != T74_OK) {
    status = err->status;
    goto done;
  }
  for (int k = 0; k < L.n; k++) {
    struct edge *ed = &L.e[k];
    if (k < nregular) {
      uint32_t a = et + (uint32_t)k * EDGE_ROW_WORDS;
      /* ids above 65535 (imports, docs/scale.md): their low word, the 1974 layout */
      core_write(r->core, a, (uint16_t)s->v[ed->va].id);
      core_write(r->core, a + 1, (uint16_t)s->v[ed->vb].id);
      core_write(r->core, a + 2, (uint16_t)ed->own[0]);
      core_write(r->core, a + 3, (uint16_t)(ed->nown > 1 ? ed->own[1] : 0));
      core_write(r->core, a + 4, (uint16_t)ed->cls);
      COST_ADD_N(cost, COST_MEM, EDGE_ROW_WORDS);
    } else {
      uint32_t a = lt + (uint32_t)(k - nregular) * E4_ROW_WORDS;
      core_write(r->core, a, (uint16_t)ed->own[0]);
      core_write(r->core, a + 1, (uint16_t)ed->own[1]);
      core_write(r->core, a + 2, (uint16_t)ed->cls);
      COST_ADD_N(cost, COST_MEM, E4_ROW_WORDS);
    }
  }

  /* lines and halo sides in scaled coordinates */
  for (int k = 0; k < nregular; k++) {
    struct edge *ed = &L.e[k];
    ed->p = mapper_point(s, ed->va);
    ed->q = mapper_point(s, ed->vb);
    wide DX = 2 * (wide)g->W * (ed->q.x - ed->p.x), DY = 2 * (wide)g->H * (ed->q.y - ed->p.y);
    wide XP = 2 * (wide)g->W * ed->p.x, YP = 2 * (wide)g->H * ed->p.y;
    ed->A = -DY;
    ed->B = DX;
    ed->C = DY * XP - DX * YP;
    cost_mw_mul(cost, 40, 40); cost_mw_mul(cost, 40, 40);
    /* the ends' depths: t = (z - Z0) / -Z0 along the ray through each */
    int32_t za = s->v[ed->va].z, zb = s->v[ed->vb].z;
    ed->tnear_n = (wide)(za < zb ? za : zb) - r->map.eye[2];
    ed->tfar_n = (wide)(za < zb ? zb : za) - r->map.eye[2];
    ed->tnear_d = ed->tfar_d = -(wide)r->map.eye[2];
    ed->trange = true;
    COST_ADD_N(cost, COST_ADD, 3);
    if (ed->cls == EDGE_E2 && e->halo_w > 0 && ed->ndraw > 0) {
      int side = 0;
      for (int d = 0; d < ed->ndraw; d++) {
        int sd = face_side(&r->map.f[ed->draw[d]], s->v[ed->va].id, s->v[ed->vb].id);
        if (!sd || (side && sd != side)) { side = 0; break; }
        side = sd;
        COST_ADD_N(cost, COST_MEM, 2 * r->map.f[ed->draw[d]].ring_start[r->map.f[ed->draw[d]].nring]);
      }
      ed->halo = -side;
    }
  }

  /* the scan */
  c.r = r; c.s = s; c.g = g; c.f = f; c.cost = cost;
  c.W = f->W; c.H = f->H;
  c.sx = (wide)GRID_ONE * (g->window[2] - g->window[0]);
  c.sy = (wide)GRID_ONE * (g->window[3] - g->window[1]);
  c.S = 512 * (wide)c.W * g->window[0];
  c.T = 512 * (wide)c.H * g->window[3];
  c.mark = calloc(npts ? npts : 1, 1);
  if (!c.mark) goto oom;
  /* the ends' depths of the intersection lines: on face A's plane at each end */
  for (int k = nregular; k < L.n; k++) {
    struct edge *ed = &L.e[k];
    const struct mface *A = &r->map.f[ed->draw[0]];
    wide SWH = 512 * (wide)c.W * 512 * (wide)c.H;
    wide dp = plane_at(&c, A, 2 * (wide)c.W * ed->p.x, 2 * (wide)c.H * ed->p.y);
    wide dq = plane_at(&c, A, 2 * (wide)c.W * ed->q.x, 2 * (wide)c.H * ed->q.y);
    cost_mw_mul(cost, 34, 50); cost_mw_mul(cost, 34, 50); cost_mw_mul(cost, 34, 50);
    cost_mw_mul(cost, 34, 50); cost_mw_mul(cost, 34, 50); cost_mw_mul(cost, 34, 50);
    if (dp <= 0 || dq <= 0) continue;
    wide tn = (wide)A->deye * SWH;
    bool pnear = rat_cmp(tn, dp, tn, dq) <= 0;
    ed->tnear_n = ed->tfar_n = tn;
    ed->tnear_d = pnear ? dp : dq;
    ed->tfar_d = pnear ? dq : dp;
    ed->trange = true;
  }
  /* the outline along the contour's curve, where contour smoothing rounds corners */
  const struct contour_corners *cc = f->model && f->model->corners.n ? &f->model->corners : NULL;
  struct ccount ncc = { 0, 0, 0, 0 };
  int nedges = L.n;
  if (cc && (status = contour_outline(&c, e, cc, &L, nregular, &ncc, err)) != T74_OK) goto done;
  int64_t wo = llround(e->outline_w * WQ), wi = llround(e->inner_w * WQ);
  int64_t wh = llround(e->halo_w * WQ);
  for (int pass = 0; pass < 2; pass++) {
    bool row = pass == 0;
    if (!(passes & (row ? EDGE_PASS_ROW : EDGE_PASS_COL))) continue;
    if (cc) curve_pass_cost(cc, cost);
    for (int k = 0; k < L.n; k++) {
      struct edge *ed = &L.e[k];
      COST_ADD_N(cost, COST_MEM, 4);
      if (ed->cls == EDGE_E1 || ed->ndraw == 0 || ed->gone) continue;
      bool outl = ed->cls == EDGE_E2 || ed->cls == EDGE_E4_OUTLINE;
      int64_t w = outl ? wo : wi;
      if (w <= 0) continue;
      draw_edge(&c, ed, row, w, ed->halo ? wh : 0, outl ? MK_OUTLINE : MK_INNER);
    }
  }
  for (size_t k = 0; k < npts; k++) {
    int m = c.mark[k] & 3;
    if (m >= MK_INNER) { if (c.mark[k] & MK_ROW) c.pts_row++; else c.pts_col++; }
    if (m == MK_HALO) c.pts_halo++;
    if (m == MK_OUTLINE) f->grey[k] = (uint8_t)e->outline_g;
    else if (m == MK_INNER) f->grey[k] = (uint8_t)e->inner_g;
    else if (m == MK_HALO) f->grey[k] = (uint8_t)e->halo_g;
    if (m) COST_ADD_N(cost, COST_MEM, 2);
  }
  COST_ADD_N(cost, COST_MEM, npts);
  COST_ADD_N(cost, COST_BRANCH, npts);

  /* counts and the dump */
  {
    int cnt[5] = { 0 };
    for (int k = 0; k < nedges; k++) cnt[L.e[k].cls]++;
    fx_count(st, "edges_not_drawn", cnt[EDGE_E1], true);
    fx_count(st, "edges_outline", cnt[EDGE_E2], true);
    fx_count(st, "edges_inner", cnt[EDGE_E3], true);
    fx_count(st, "edges_intersection", cnt[EDGE_E4_INNER] + cnt[EDGE_E4_OUTLINE], true);
    fx_count(st, "edges_intersection_inner", cnt[EDGE_E4_INNER], true);
    fx_count(st, "edges_intersection_outline", cnt[EDGE_E4_OUTLINE], true);
    fx_count(st, "edge_points_row_pass", (double)c.pts_row, true);
    fx_count(st, "edge_points_column_pass", (double)c.pts_col, true);
    fx_count(st, "edge_points_halo", (double)c.pts_halo, true);
    if (cc) {
      long gone = 0;
      for (int k = 0; k < nregular; k++) gone += L.e[k].gone;
      fx_count(st, "edges_contour_curve_segments", (double)ncc.curve, true);
      fx_count(st, "edges_contour_sides_cut", (double)ncc.sides, true);
      fx_count(st, "edges_contour_inner_cut", (double)ncc.inner, true);
      fx_count(st, "edges_contour_gone", (double)gone, true);
    }
    if (r->tables) {
      fprintf(r->tables, "\nEDGES (paper 002 §3.2): %d edges, %d intersection lines; "
              "e1 %d, e2 %d, e3 %d, e4 %d\n", nregular, nedges - nregular, cnt[EDGE_E1],
              cnt[EDGE_E2], cnt[EDGE_E3], cnt[EDGE_E4_INNER] + cnt[EDGE_E4_OUTLINE]);
      if (cc)
        fprintf(r->tables, "CONTOUR OUTLINE (papers 004 and 002): %d curves of %d segments "
                "(e2)\n", cc->n, CONTOUR_STEPS);
      for (int k = 0; k < nsplit; k++)
        fprintf(r->tables, "  edge %u-%u faces %u: not an edge (inside imported face %u, split "
                "by the importer)\n", (unsigned)s->v[u[k].lo].id, (unsigned)s->v[u[k].hi].id,
                (unsigned)s->f[u[k].face].id, (unsigned)s->f[u[k].face].id);
      for (int k = 0; k < nedges; k++) {
        const struct edge *ed = &L.e[k];
        if (k < nregular)
          fprintf(r->tables, "  edge %u-%u", (unsigned)s->v[ed->va].id, (unsigned)s->v[ed->vb].id);
        else
          fprintf(r->tables, "  line (%.2f,%.2f)-(%.2f,%.2f)", (double)ed->p.x / GRID_ONE,
                  (double)ed->p.y / GRID_ONE, (double)ed->q.x / GRID_ONE, (double)ed->q.y / GRID_ONE);
        fprintf(r->tables, " faces %u", (unsigned)ed->own[0]);
        if (ed->nown > 1) fprintf(r->tables, ",%u", (unsigned)ed->own[1]);
        fprintf(r->tables, ": %s: %s%s", class_name[ed->cls], ed->why,
                ed->halo ? "; halo outside" : "");
        if (k < nregular && cc) {
          struct gpoint P = mapper_point(s, ed->va), Q = mapper_point(s, ed->vb);
          if (ed->gone) fprintf(r->tables, "; cut away by the contour");
          else if (P.x != ed->p.x || P.y != ed->p.y || Q.x != ed->q.x || Q.y != ed->q.y)
            fprintf(r->tables, "; drawn (%.2f,%.2f)-(%.2f,%.2f) (contour)",
                    (double)ed->p.x / GRID_ONE, (double)ed->p.y / GRID_ONE,
                    (double)ed->q.x / GRID_ONE, (double)ed->q.y / GRID_ONE);
        }
        fputc('\n', r->tables);
      }
      for (int k = 0; cc && k < cc->n; k++) {
        const struct contour_corner *q = &cc->c[k];
        fprintf(r->tables, "  curve at vertex %u (object %d) faces %u", (unsigned)s->v[q->vb].id,
                q->object, (unsigned)r->map.f[q->mface_a].id);
        if (q->mface_b != q->mface_a) fprintf(r->tables, ",%u", (unsigned)r->map.f[q->mface_b].id);
        fprintf(r->tables, ": %s: %d segments (%.2f,%.2f)-(%.2f,%.2f), sides %u-%u and %u-%u "
                "end there%s\n", class_name[EDGE_E2], CONTOUR_STEPS,
                (double)q->q[0].x / GRID_ONE, (double)q->q[0].y / GRID_ONE,
                (double)q->q[4].x / GRID_ONE, (double)q->q[4].y / GRID_ONE,
                (unsigned)s->v[q->va].id, (unsigned)s->v[q->vb].id, (unsigned)s->v[q->vb].id,
                (unsigned)s->v[q->vc].id, e->halo_w > 0 ? "; halo outside" : "");
      }
    }
  }
  goto done;

oom:
  status = t74_fail(err, T74_EIO, "out of host memory");
done:
  core_release(r->core, mark0);
  free(c.mark);
  free(L.e);
  free(u); free(par); free(flip); free(part); free(sf2m); free(sigma); free(outw);
  free(bad); free(smooth); free(vol);
  free_rings(&R);
  return status;
}
