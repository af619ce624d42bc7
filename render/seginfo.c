/*
** seginfo.c — Segment Information: the table of convex pieces (003 §3.2, Fig. 8).
**
** This file contains code to keep the convex pieces the Segment Generator and the
** intersection splits produce, and the three exact operations the Priority Matrix and the
** Visible Surface Procedure need on them: clipping by a line (to cut a piece along an
** intersection line, eq. (5)), the overlap test of two pieces (separating line: two convex
** regions have disjoint interiors exactly when one of their sides separates them), and the
** span of a piece on a horizontal line (the D-block's xb, xe: the largest x of its left
** sides and the smallest x of its right sides).
**
** All vertices are meets of two grid lines, never of derived lines, so their size stays
** bounded (geom.h) however often pieces are cut.
*/
#include "render/seginfo.h"
#include "render/pool.h"
#include "render/segment.h"

#include <stdlib.h>
#include <string.h>

/* Fig. 8 (b), in the 1974 program's words (docs/machine.md). B block: piece number,
   y-min, y-max, pointers to the C block, the D chain and the next B block (6 words).
   C block: k and the k vertex numbers (1 + k words), and with it each side's share of
   the edge table of §2.1-2.2 (an edge: its two vertex numbers, a and b one word each, c a
   double word = 6 words, shared by the two pieces that meet on it: 3 words a side). */
#define BBLOCK_ROW_WORDS 6
#define CBLOCK_HEAD_WORDS 1
#define CBLOCK_SIDE_WORDS 4

_Static_assert(sizeof(struct piece) == 48, "struct piece: 48 bytes");

void seginfo_init(struct seginfo *t, struct core *core, struct cost *cost)
{
  memset(t, 0, sizeof *t);
  t->core = core;
  t->bname.name = "B-BLOCK";
  t->cname.name = "C-BLOCK";
  t->yname.name = CORE_T_YSORT;
  t->cost = cost;
}

void seginfo_free(struct seginfo *t)
{
  pool_free(&t->pool);
  free(t->p);
  memset(t, 0, sizeof *t);
}

void cpoly_free(struct cpoly *c)
{
  free(c->line);
  free(c->v);
  memset(c, 0, sizeof *c);
}

static int cmp_hy(struct hpoint a, struct hpoint b)
{
  /* a.Y/a.W vs b.Y/b.W: products reach 2^147, so in 256 bits */
  return geom_cross_sign(a.Y, b.W, b.Y, a.W);
}

/* Two consecutive lines that are parallel share a vertex, so they are one line. */
static bool same_direction(struct gline p, struct gline q)
{
  return (wide)p.a * q.b == (wide)q.a * p.b && ((wide)p.a * q.a + (wide)p.b * q.b) > 0;
}

/* Merge consecutive sides on one line; returns the new count. */
static int merge_sides(struct gline *l, int n)
{
  int changed = 1;
  while (changed && n >= 3) {
    changed = 0;
    for (int k = 0; k < n; k++) {
      int nx = k + 1 < n ? k + 1 : 0;
      if (same_direction(l[k], l[nx])) {
        memmove(&l[nx], &l[nx + 1], (size_t)(n - nx - 1) * sizeof *l);
        n--;
        changed = 1;
        break;
      }
    }
  }
  return n;
}

/* Y / W / GRID_ONE, truncated: in 64 bits where Y fits them (W does: geom_meet), the
   same quotients as in 128 (both truncate toward zero; W > 0), without a 128-bit
   division (issue 19: two a piece). */
static wide grid_y(struct hpoint v)
{
  if (v.Y == (int64_t)v.Y && v.W == (int64_t)v.W) return (int64_t)v.Y / (int64_t)v.W / GRID_ONE;
  return v.Y / v.W / GRID_ONE;
}

bool seginfo_reserve(struct seginfo *t, int n)
{
  if (n <= t->cap) return true;
  struct piece *np = realloc(t->p, (size_t)n * sizeof *np);
  if (!np) return false;
  t->p = np;
  t->cap = n;
  return true;
}

static int add_blocks(struct seginfo *t, struct piece *p, int n, const struct gline *pl,
                      const struct hpoint *v, int lo, int hi, struct t74_error *err);

/* The rest of seginfo_add for piece p (t->p[t->n]) of n sides, merged, on lines pl (its
   own or its face's): its vertices (into keep when it keeps them, else made here and
   dropped), lowest and highest, B and C blocks, charges. */
static int add_rest(struct seginfo *t, struct piece *p, int face, int n, const struct gline *pl,
                    struct hpoint *keep, struct t74_error *err)
{
  if (n < 3) {
    t74_fail(err, T74_EINPUT, "internal: a piece of face %d has fewer than 3 sides", face);
    return -1;
  }
  p->n = n;
  p->face = face;
  p->alive = true;
  p->parent = -1;
  struct hpoint vb[PIECE_VBUF];
  struct hpoint *v = keep ? keep : vb;
  if (p->onface && !keep) {
    /* A piece that is its face (seginfo_add_face): side k runs from pt[k] to pt[k + 1],
       so where sides k - 1 and k meet, when they are not parallel, is pt[k] itself, and
       its height Y / W there is pt[k].y exactly. The lowest and highest vertex are found
       by comparing the pt[k].y (the same strict compares, in the same order, as on Y / W:
       the same lo and hi), and their heights are kept as (y, 1), which is the same
       height: what reads them (the kept lowest height, compared as a fraction by the
       Visible Surface Procedure, and grid_y, a quotient truncated as a whole) reads only
       that (as dblock_open does for such a piece). Parallel sides are refused as below,
       tested on a and b alone (W = a b' - a' b, |a|, |b| < 2^29: in 64 bits). Nothing
       decided or charged changes; the host is spared n meets and 2 n - 2 compares of
       147-bit products, and the sweep's order by lowest height compares (y, 1) with
       (y', 1) as two integers. */
    for (int k = 0, k0 = n - 1; k < n; k0 = k++)
      if (pl[k0].a * pl[k].b == pl[k].a * pl[k0].b) {
        t74_fail(err, T74_EINPUT, "internal: sides of a piece of face %d do not meet", face);
        return -1;
      }
    int lo = 0, hi = 0;
    for (int k = 1; k < n; k++) {
      if (p->pt[k].y < p->pt[lo].y) lo = k;
      if (p->pt[k].y > p->pt[hi].y) hi = k;
    }
    v[lo] = (struct hpoint){ 0, p->pt[lo].y, 1 };
    v[hi] = (struct hpoint){ 0, p->pt[hi].y, 1 };
    cost_mw_mul_n(t->cost, 58, 29, 2 * (uint64_t)n);     /* two products a vertex */
    return add_blocks(t, p, n, pl, v, lo, hi, err);
  }
  for (int k = 0, k0 = n - 1; k < n; k0 = k++) {
    if (!geom_meet(pl[k0], pl[k], &v[k])) {
      t74_fail(err, T74_EINPUT, "internal: sides of a piece of face %d do not meet", face);
      return -1;
    }
  }
  cost_mw_mul_n(t->cost, 58, 29, 2 * (uint64_t)n);     /* two products a vertex */
  int lo = 0, hi = 0;
  for (int k = 1; k < n; k++) {
    if (cmp_hy(v[k], v[lo]) < 0) lo = k;
    if (cmp_hy(v[k], v[hi]) > 0) hi = k;
  }
  return add_blocks(t, p, n, pl, v, lo, hi, err);
}

/* The rest of add_rest, its lowest and highest vertex v[lo] and v[hi] found: their
   compares charged, the piece's height kept, B and C blocks, charges. */
static int add_blocks(struct seginfo *t, struct piece *p, int n, const struct gline *pl,
                      const struct hpoint *v, int lo, int hi, struct t74_error *err)
{
  p->lo = lo;
  p->hi = hi;
  cost_mw_mul_n(t->cost, 88, 59, (uint64_t)n - 1);      /* a compare a vertex but the first */
  p->ylo_yh = (int32_t)(v[lo].Y >> 64);                  /* |Y| < 2^88: geom.h */
  p->ylo_yl = (uint64_t)(uwide)v[lo].Y;
  p->ylo_w = (int64_t)v[lo].W;                            /* W < 2^59: geom.h */

  /* B and C blocks in core: the piece's row, and its sides */
  uint32_t b, c;
  if (core_alloc_named(t->core, &t->bname, BBLOCK_ROW_WORDS, &b, err) != T74_OK ||
      core_alloc_named(t->core, &t->cname, CBLOCK_HEAD_WORDS + (uint32_t)n * CBLOCK_SIDE_WORDS, &c,
                       err) != T74_OK)
    return -1;
  /* written a block at once (issue 19); a C block's fourth word of a side stays 0, as
     core_alloc made it */
  const uint16_t brow[4] = { (uint16_t)t->n, (uint16_t)grid_y(v[lo]), (uint16_t)grid_y(v[hi]),
                             (uint16_t)c };
  core_write_n(t->core, b, brow, 4);
  uint16_t cb[CBLOCK_HEAD_WORDS + CBLOCK_SIDE_WORDS * PIECE_VBUF];
  if (n <= PIECE_VBUF) {
    cb[0] = (uint16_t)n;
    for (int k = 0; k < n; k++) {           /* vertex number, then the side's edge share */
      uint16_t *w = cb + 1 + 4 * k;
      w[0] = (uint16_t)k;
      w[1] = (uint16_t)pl[k].a;
      w[2] = (uint16_t)pl[k].b;
      w[3] = 0;
    }
    core_write_n(t->core, c, cb, CBLOCK_HEAD_WORDS + (uint32_t)n * CBLOCK_SIDE_WORDS);
  } else {
    core_write(t->core, c, (uint16_t)n);
    for (int k = 0; k < n; k++) {
      core_write(t->core, c + 1 + 4 * (uint32_t)k, (uint16_t)k);
      core_write(t->core, c + 2 + 4 * (uint32_t)k, (uint16_t)pl[k].a);
      core_write(t->core, c + 3 + 4 * (uint32_t)k, (uint16_t)pl[k].b);
    }
  }
  COST_ADD_N(t->cost, COST_MEM, BBLOCK_ROW_WORDS + CBLOCK_HEAD_WORDS + (uint64_t)n * CBLOCK_SIDE_WORDS);
  return t->n++;
}

int seginfo_add(struct seginfo *t, int face, int n, const struct gline *line,
                struct t74_error *err)
{
  if (n >= (1 << 29)) {                      /* struct piece's hi: 30 bits */
    t74_fail(err, T74_EINPUT, "a piece of face %d has %d sides, more than %d", face, n,
             (1 << 29) - 1);
    return -1;
  }
  if (t->n == t->cap && !seginfo_reserve(t, t->cap ? 2 * t->cap : 64)) {
    t74_fail(err, T74_EIO, "out of host memory");
    return -1;
  }
  struct piece *p = &t->p[t->n];
  memset(p, 0, sizeof *p);
  /* its lines and its vertices, in one piece of the pool (issue 19: no allocation a
     piece; a piece is never freed before the others) */
  _Static_assert(_Alignof(struct hpoint) >= _Alignof(struct gline), "piece block layout");
  struct hpoint *v = pool_alloc(&t->pool, (size_t)n * (sizeof *v + sizeof *p->ln),
                                _Alignof(struct hpoint));
  p->ln = v ? (struct gline *)(v + n) : NULL;
  if (!p->ln) {
    t74_fail(err, T74_EIO, "out of host memory");
    return -1;
  }
  memcpy(p->ln, line, (size_t)n * sizeof *line);
  n = merge_sides(p->ln, n);
  /* its vertices just before its lines, within the block (piece_kept) */
  return add_rest(t, p, face, n, p->ln, (struct hpoint *)(void *)p->ln - n, err);
}

int seginfo_add_face(struct seginfo *t, int face, int n, const struct gpoint *pt,
                     const struct gline *line, struct t74_error *err)
{
  if (n < 3 || n > SEG_CONVEX_MAX) return seginfo_add(t, face, n, line, err);
  for (int k = 0; k < n; k++) {
    if (pt[k].x < -GRID_LIMIT || pt[k].x > GRID_LIMIT || pt[k].y < -GRID_LIMIT ||
        pt[k].y > GRID_LIMIT)
      return seginfo_add(t, face, n, line, err);           /* off the grid (geom.h) */
    struct gline l = geom_line(pt[k], pt[k + 1 < n ? k + 1 : 0]);
    if (l.a != line[k].a || l.b != line[k].b || l.c != line[k].c)
      return seginfo_add(t, face, n, line, err);
  }
  /* merge_sides would merge nothing: no two consecutive sides in one direction
     (same_direction; the sides join grid points, so |a|, |b| <= 2^29 and the products
     and the sum of two stay below 2^59, in 64 bits) */
  for (int k = 0, k0 = n - 1; k < n; k0 = k++) {
    const struct gline *p = &line[k0], *q = &line[k];
    if (p->a * q->b == q->a * p->b && p->a * q->a + p->b * q->b > 0)
      return seginfo_add(t, face, n, line, err);
  }
  const struct gline *l = line;
  if (t->n == t->cap && !seginfo_reserve(t, t->cap ? 2 * t->cap : 64)) {
    t74_fail(err, T74_EIO, "out of host memory");
    return -1;
  }
  struct piece *p = &t->p[t->n];
  memset(p, 0, sizeof *p);
  p->pt = pt;
  p->onface = true;
  return add_rest(t, p, face, n, l, NULL, err);
}

/* Room for n entries in c. */
static bool cpoly_room(struct cpoly *c, int n)
{
  if (n > c->cap) {
    int cap = c->cap ? c->cap : 16;
    while (cap < n) cap *= 2;
    struct gline *nl = realloc(c->line, (size_t)cap * sizeof *nl);
    if (!nl) return false;
    c->line = nl;
    struct hpoint *nv = realloc(c->v, (size_t)cap * sizeof *nv);
    if (!nv) return false;
    c->v = nv;
    c->cap = cap;
  }
  return true;
}

/* Append a side and its vertex (room made by cpoly_room). */
static inline void cpoly_push(struct cpoly *c, struct gline l, struct hpoint v)
{
  c->line[c->n] = l;
  c->v[c->n] = v;
  c->n++;
}

/* Some vertex strictly left of some side. Side k's own ends, vertices k and k + 1, lie on
   its line, so each side's vertices are tried from k + 2 on (every vertex is still tried:
   the answer is the same in any order; nothing is charged here), and the first side
   finds the vertex of a piece with an interior at once. */
static bool has_interior(int n, const struct gline *l, const struct hpoint *v)
{
  if (n < 3) return false;
  for (int k = 0; k < n; k++)
    for (int i = 0, j = k + 2 < n ? k + 2 : k + 2 - n; i < n; i++, j = j + 1 < n ? j + 1 : 0)
      if (geom_side_hw(l[k], v[j]) > 0) return true;
  return false;
}

/* Sutherland-Hodgman on lines: each kept vertex carries the line of the side leaving it.
   Vertex k of the result starts side k; a new vertex is the meet of the side it lies on
   and h, so it stays a meet of two grid lines. side[k] is the side of p's vertex k of h
   (geom_side_h), or side is NULL and it is found here. */
static bool clip_sides(const struct piece *p, const struct gline *pl, const struct hpoint *pv,
                       struct gline h, const signed char *side, struct cpoly *out, uint64_t *prod)
{
  out->n = 0;
  int n = p->n;
  if (!cpoly_room(out, n + 2)) return false;   /* a convex piece crosses a line twice at most */
  int s0 = side ? side[0] : geom_side_hw(h, pv[0]), sk = s0;
  *prod += (uint64_t)n;                          /* a product a vertex */
  for (int k = 0; k < n; k++) {
    int nx = k + 1 < n ? k + 1 : 0;        /* (k + 1) % n, without a divide */
    int sn = nx == 0 ? s0 : side ? side[nx] : geom_side_hw(h, pv[nx]);
    struct gline lk = pl[k];
    struct hpoint x;
    if (sk > 0 || (sk == 0 && sn >= 0)) {
      cpoly_push(out, lk, pv[k]);
      if (sk > 0 && sn < 0) {            /* leaves through h */
        if (!geom_meet(lk, h, &x)) return false;
        cpoly_push(out, h, x);
      }
    } else if (sk == 0) {                /* on h, and the side goes outside */
      cpoly_push(out, h, pv[k]);
    } else if (sn > 0) {                 /* enters through h */
      if (!geom_meet(lk, h, &x)) return false;
      cpoly_push(out, lk, x);
    }
    sk = sn;
  }
  /* merge consecutive sides that lie on one line (keep the first vertex) */
  for (int k = 0; out->n >= 3 && k < out->n; ) {
    int nx = k + 1 < out->n ? k + 1 : 0;   /* (k + 1) % out->n, without a divide */
    if (same_direction(out->line[k], out->line[nx])) {
      memmove(&out->line[nx], &out->line[nx + 1], (size_t)(out->n - nx - 1) * sizeof *out->line);
      memmove(&out->v[nx], &out->v[nx + 1], (size_t)(out->n - nx - 1) * sizeof *out->v);
      out->n--;
      if (nx < k) k--;
      continue;
    }
    k++;
  }
  return has_interior(out->n, out->line, out->v);
}

/* The products (88 x 58 bits) counted in prod, charged. */
static void charge_products(struct cost *cost, uint64_t prod)
{
  cost_mw_mul_n(cost, 88, 58, prod);
}

bool seginfo_clip(const struct piece *p, struct gline h, struct cpoly *out, struct cost *cost)
{
  uint64_t prod = 0;
  struct gline lb[PIECE_VBUF];
  struct hpoint vb[PIECE_VBUF];
  const struct gline *pl = p->n > PIECE_VBUF ? p->ln : piece_lines(p, lb);
  bool r = clip_sides(p, pl, piece_verts_of(p, pl, vb), h, NULL, out, &prod);
  charge_products(cost, prod);
  return r;
}

#define CLIP_SIDES_MAX 64                  /* pieces with more sides: seginfo_clip twice */

/* The number of sides clip_sides leaves (side[]: as for clip_sides), found from the sides'
   lines alone: the same lines pushed in the same order, the same merges. A side that
   clip_sides meets with h runs from a vertex strictly on one side of h to one strictly
   on the other, so it is not parallel to h and the meet is made: it never ends the clip
   early. Host only: nothing charged. */
static int clip_count(const struct piece *p, const struct gline *pl, struct gline h,
                      const signed char *side)
{
  struct gline l[CLIP_SIDES_MAX + 2];
  int n = p->n, m = 0, s0 = side[0], sk = s0;
  for (int k = 0; k < n; k++) {
    int sn = k + 1 == n ? s0 : side[k + 1];
    if (sk > 0 || (sk == 0 && sn >= 0)) {
      l[m++] = pl[k];
      if (sk > 0 && sn < 0) l[m++] = h;
    } else if (sk == 0)
      l[m++] = h;
    else if (sn > 0)
      l[m++] = pl[k];
    sk = sn;
  }
  for (int k = 0; m >= 3 && k < m; ) {
    int nx = k + 1 < m ? k + 1 : 0;        /* (k + 1) % m, without a divide */
    if (same_direction(l[k], l[nx])) {
      memmove(&l[nx], &l[nx + 1], (size_t)(m - nx - 1) * sizeof *l);
      m--;
      if (nx < k) k--;
      continue;
    }
    k++;
  }
  return m;
}

void seginfo_clip_both(const struct piece *p, struct gline h, struct cpoly *left, bool *hasl,
                       struct cpoly *right, bool *hasr, struct cost *cost)
{
  uint64_t prod = 0;
  seginfo_clip_both_known(p, NULL, NULL, h, NULL, 0, left, hasl, right, hasr, &prod);
  charge_products(cost, prod);
}

void seginfo_clip_both_known(const struct piece *p, const struct gline *pl,
                             const struct hpoint *pv, struct gline h, const signed char *sides,
                             int known, struct cpoly *left, bool *hasl, struct cpoly *right,
                             bool *hasr, uint64_t *prod)
{
  struct gline rh = { -h.a, -h.b, -h.c };
  struct gline lb[PIECE_VBUF];
  struct hpoint vb[PIECE_VBUF];
  if (!pl) pl = p->n > PIECE_VBUF ? p->ln : piece_lines(p, lb);
  if (!pv) pv = piece_verts_of(p, pl, vb);
  if (p->n > CLIP_SIDES_MAX) {
    *hasl = clip_sides(p, pl, pv, h, NULL, left, prod);
    *hasr = clip_sides(p, pl, pv, rh, NULL, right, prod);
    return;
  }
  signed char side[CLIP_SIDES_MAX], rside[CLIP_SIDES_MAX];
  for (int k = 0; k < p->n; k++) {
    side[k] = sides ? sides[k] : (signed char)geom_side_hw(h, pv[k]);
    rside[k] = (signed char)-side[k];      /* the reversed line: the negated sum, exactly */
  }
  struct cpoly *half[2] = { left, right };
  bool *has[2] = { hasl, hasr };
  const signed char *sd[2] = { side, rside };
  const struct gline hh[2] = { h, rh };
  for (int s = 0; s < 2; s++) {
    if (known != s + 1) {
      *has[s] = clip_sides(p, pl, pv, hh[s], sd[s], half[s], prod);
      continue;
    }
    /* known to have an interior: counted, charged as clip_sides charges */
    if (!cpoly_room(half[s], p->n + 2)) { *has[s] = false; continue; }
    *prod += (uint64_t)p->n;
    half[s]->n = clip_count(p, pl, hh[s], sd[s]);
    *has[s] = half[s]->n >= 3;
  }
}

bool seginfo_overlap_n(int n1, const struct gline *l1, const struct hpoint *v1,
                     int n2, const struct gline *l2, const struct hpoint *v2,
                     uint64_t *prod)
{
  /* one product charged for each side looked at (at once, when the answer is known) */
  for (int k = 0; k < n1; k++) {
    int j = 0;
    while (j < n2 && geom_side_hw(l1[k], v2[j]) <= 0) j++;
    if (j == n2) {                       /* side k of the first separates them */
      *prod += (uint64_t)k + 1;
      return false;
    }
  }
  for (int k = 0; k < n2; k++) {
    int j = 0;
    while (j < n1 && geom_side_hw(l2[k], v1[j]) <= 0) j++;
    if (j == n1) {
      *prod += (uint64_t)n1 + (uint64_t)k + 1;
      return false;
    }
  }
  *prod += (uint64_t)n1 + (uint64_t)n2;
  return true;
}

bool seginfo_overlap(int n1, const struct gline *l1, const struct hpoint *v1,
                     int n2, const struct gline *l2, const struct hpoint *v2,
                     struct cost *cost)
{
  uint64_t prod = 0;
  bool r = seginfo_overlap_n(n1, l1, v1, n2, l2, v2, &prod);
  charge_products(cost, prod);
  return r;
}

bool seginfo_span(const struct piece *p, int64_t yn, int64_t yd, struct grat *xl,
                  struct grat *xr, struct cost *cost)
{
  bool have_l = false, have_r = false;
  for (int k = 0; k < p->n; k++) {
    struct gline l = piece_line(p, k);
    if (l.a == 0) {
      /* horizontal side: a point on it belongs to the side of larger y (geom.h) */
      wide v = (wide)l.b * yn + (wide)l.c * yd;
      cost_mw_mul(cost, 58, 17);
      if (v < 0 || (v == 0 && l.b < 0)) return false;
      continue;
    }
    struct grat x = geom_x_at(l, yn, yd);
    cost_mw_mul(cost, 58, 17);
    if (l.a > 0) {                       /* interior to the right: a left side */
      if (!have_l || geom_rat_cmp(x, *xl) > 0) *xl = x;
      have_l = true;
    } else {
      if (!have_r || geom_rat_cmp(x, *xr) < 0) *xr = x;
      have_r = true;
    }
    cost_mw_mul(cost, 75, 46);
  }
  return have_l && have_r && geom_rat_cmp(*xl, *xr) < 0;
}
