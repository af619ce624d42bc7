/*
** visible.c — the Visible Surface Procedure (paper 003 §2.2, §4, Fig. 8 D-blocks).
**
** This file contains code to find, along a horizontal line of the perspective plane, which
** piece is seen where. The paper scans the whole plane and, at each point, takes the piece
** of highest priority among those containing it, using area coherence: near a point the
** front piece rarely changes. Here the line is cut exactly into stretches:
**
**   1. active pieces: those whose lowest vertex is at or below the line (YSORT order,
**      kept as `order`) and whose highest is above it;
**   2. each active piece's span [xb, xe) on the line, from its D-block (Fig. 8): the
**      stretch between two vertex heights where the piece's left and right sides stay the
**      same. Within a D-block, xb and xe move by fixed exact increments dxb, dxe from one
**      line to the next (one multi-word add each, as in 1974); a new D-block is opened at
**      y-max, or when the step between lines changes (sub-scanlines);
**   3. a sweep over span ends, left to right; between two ends the covering set is fixed,
**      and its front piece is found through the Priority Matrix. Coherence: when a piece
**      joins the set only it is compared with the current front; the whole set is looked
**      at again only when the front piece leaves. Pieces are kept in x order from line to
**      line, so re-sorting is an insertion sort over a nearly sorted list.
**
** A pair's priority is asked for only when both pieces cover a stretch of positive length,
** so the matrix is filled lazily with pairs that really overlap on the plane. When a pair
** turns out to interpenetrate, both pieces are cut (priority.c) and the line is done again.
**
** Invariant: after vis_spans, the stretches are disjoint, ordered, and each lies inside the
** span of its piece; a point of the line lies in a stretch exactly when some alive piece
** owns it under the tie rule of geom.h.
*/
#include "render/visible.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int grow(void **p, int *cap, int need, size_t size)
{
  if (need <= *cap) return 1;
  int c = *cap ? *cap : 64;
  while (c < need) c *= 2;
  void *n = realloc(*p, (size_t)c * size);
  if (!n) return 0;
  *p = n;
  *cap = c;
  return 1;
}

static int cmp_hy_frac(struct hpoint p, int64_t n, int64_t d)
{
  return geom_hy_cmp(p, n, d);
}

static int cmp_ylo(const struct seginfo *s, int a, int b)
{
  struct hpoint p = s->p[a].ylo, q = s->p[b].ylo;
  int c = geom_cross_sign(p.Y, q.W, q.Y, p.W);     /* p.Y/p.W vs q.Y/q.W, exactly */
  return c ? c : (a > b) - (a < b);
}

/* place pieces added to seg since last time into `order` (after `next`, by lowest y) */
static int take_new_pieces(struct vis *v)
{
  struct seginfo *s = v->seg;
  if (!grow((void **)&v->order, &v->ordcap, s->n, sizeof *v->order)) return 0;
  for (; v->seen < s->n; v->seen++) {
    int p = v->seen;
    if (!s->p[p].alive) continue;
    int lo = v->next, hi = v->norder;
    while (lo < hi) {
      int mid = (lo + hi) / 2;
      if (cmp_ylo(s, v->order[mid], p) < 0) lo = mid + 1; else hi = mid;
      cost_mw_mul(v->cost, 88, 59);
    }
    memmove(&v->order[lo + 1], &v->order[lo], (size_t)(v->norder - lo) * sizeof *v->order);
    v->order[lo] = p;
    v->norder++;
  }
  return 1;
}

int vis_init(struct vis *v, struct seginfo *seg, struct prio *prio, struct cost *cost,
             struct t74_error *err)
{
  memset(v, 0, sizeof *v);
  v->seg = seg;
  v->prio = prio;
  v->cost = cost;
  v->yd = 0;
  if (!take_new_pieces(v)) return t74_fail(err, T74_EIO, "out of host memory");
  return T74_OK;
}

void vis_free(struct vis *v)
{
  free(v->dfree);
  free(v->order);
  free(v->act);
  free(v->byxr);
  free(v->set);
  free(v->span);
  memset(v, 0, sizeof *v);
}

static int push_span(struct vis *v, struct grat x0, struct grat x1, int piece)
{
  if (v->nspan > 0) {
    struct vis_span *last = &v->span[v->nspan - 1];
    if (last->piece == piece && geom_rat_cmp(last->x1, x0) == 0) {
      last->x1 = x1;
      return 1;
    }
  }
  if (!grow((void **)&v->span, &v->spancap, v->nspan + 1, sizeof *v->span)) return 0;
  struct vis_span *s = &v->span[v->nspan++];
  s->x0 = x0;
  s->x1 = x1;
  s->piece = piece;
  s->face = v->seg->p[piece].face;
  return 1;
}

/* ---- D-blocks ------------------------------------------------------------------------
   A D-block row in core, in the paper's format (Fig. 8 (b)): xb and xe, dxb and dxe (a
   double word each, 16.16 fixed point in world units as the 1974 program held them,
   docs/machine.md), y-max (one word) and the chain pointer (one word) = 10 words. The
   exact values tube74 decides on (rationals of up to 8 words) are held by the host; what
   holding them in core would add is reported as exactness's cost, not charged here.
   Rows are taken from a free list, in chunks of DBLOCK_CHUNK, and given back when a piece
   leaves the line: only the pieces on the current line hold one, as the paper's display
   did. */
#define DBLOCK_WORDS 10
#define DBLOCK_CHUNK 16

static int dblock_take(struct vis *v, uint32_t *addr, struct t74_error *err)
{
  if (v->ndfree == 0) {
    uint32_t a;
    if (core_alloc(v->seg->core, "D-BLOCK", DBLOCK_WORDS * DBLOCK_CHUNK, &a, err) != T74_OK)
      return err->status;
    if (!grow((void **)&v->dfree, &v->dfreecap, DBLOCK_CHUNK, sizeof *v->dfree))
      return t74_fail(err, T74_EIO, "out of host memory");
    for (int k = DBLOCK_CHUNK - 1; k >= 0; k--) v->dfree[v->ndfree++] = a + (uint32_t)k * DBLOCK_WORDS;
  }
  *addr = v->dfree[--v->ndfree];
  return T74_OK;
}

static void dblock_give(struct vis *v, uint32_t addr)
{
  /* the free list never outgrows the rows taken: room was made when they were */
  if (grow((void **)&v->dfree, &v->dfreecap, v->ndfree + 1, sizeof *v->dfree))
    v->dfree[v->ndfree++] = addr;
}

/* n/d grid units as a 16.16 double word (world units), truncated; a 64-bit divide when
   the operands allow (the common case), for the host's speed. */
static int64_t fix16(wide n, wide d)
{
  wide m = n * GEOM_H10_XONE;
  if (m >= INT64_MIN && m <= INT64_MAX && d <= INT64_MAX) return (int64_t)m / (int64_t)d;
  return (int64_t)(m / d);
}

static void dblock_store(struct vis *v, const struct vis_item *it)
{
  struct core *c = v->seg->core;
  core_put_int(c, it->core, 2, fix16(it->xl.num, it->xl.den));
  core_put_int(c, it->core + 2, 2, fix16(it->xr.num, it->xr.den));
  core_put_int(c, it->core + 4, 2, fix16(it->dxl, it->xl.den));
  core_put_int(c, it->core + 6, 2, fix16(it->dxr, it->xr.den));
  core_write(c, it->core + 8, (uint16_t)(it->ymax.Y / it->ymax.W / GRID_ONE));
  core_write(c, it->core + 9, 0);
}

/* The lower of two heights. */
static struct hpoint lower(struct hpoint p, struct hpoint q)
{
  struct i256 d = i256_add(i256_mul(p.Y, q.W), i256_mul(-q.Y, p.W));
  return i256_sign(d) <= 0 ? p : q;
}

/* Open the D-block of piece p that holds the line y = yn/yd: its left side runs down
   (a > 0) from v[k] to v[k+1], its right side up (a < 0) from v[k] to v[k+1]; each is
   the one whose y-range [bottom, top) holds the line. False when none does: the line is
   at or above the piece's top. */
static bool dblock_open(struct vis *v, struct vis_item *it, int64_t yn, int64_t yd)
{
  const struct piece *p = &v->seg->p[it->piece];
  int kl = -1, kr = -1;
  for (int k = 0; k < p->n && (kl < 0 || kr < 0); k++) {
    const struct gline *l = &p->line[k];
    if (l->a == 0) continue;
    struct hpoint lo = l->a > 0 ? p->v[(k + 1) % p->n] : p->v[k];
    struct hpoint hi = l->a > 0 ? p->v[k] : p->v[(k + 1) % p->n];
    cost_mw_mul(v->cost, 88, 17);
    if (geom_hy_cmp(lo, yn, yd) > 0 || geom_hy_cmp(hi, yn, yd) <= 0) continue;
    if (l->a > 0) kl = k; else kr = k;
  }
  if (kl < 0 || kr < 0) return false;
  it->kl = kl;
  it->kr = kr;
  it->xl = geom_x_at(p->line[kl], yn, yd);
  it->xr = geom_x_at(p->line[kr], yn, yd);
  /* geom_x_at: num = -(b yn + c yd), negated with the denominator when a < 0 */
  it->sl = p->line[kl].a > 0 ? -(wide)p->line[kl].b : (wide)p->line[kl].b;
  it->sr = p->line[kr].a > 0 ? -(wide)p->line[kr].b : (wide)p->line[kr].b;
  if (v->arith == GEOM_HITAC) {         /* --arith hitac: xb, xe as double words */
    it->hdl = it->xl.den;
    it->hdr = it->xr.den;
    it->xl = geom_h10_x(it->xl);
    it->xr = geom_h10_x(it->xr);
  }
  it->dyn = 0;
  it->dxl = it->dxr = 0;
  it->ymax = lower(p->v[kl], p->v[(kr + 1) % p->n]);
  cost_mw_mul(v->cost, 58, 17);
  cost_mw_mul(v->cost, 58, 17);
  it->open = true;
  return true;
}

/* The span [xb, xe) of an active piece on the line y = yn/yd (y never decreasing):
   by its D-block's increments while the line stays below y-max with the same
   denominator, else from a newly opened D-block. */
static int dblock_span(struct vis *v, struct vis_item *it, int64_t yn, int64_t yd,
                       struct t74_error *err)
{
  bool same = it->open && yd == it->yd && geom_hy_cmp(it->ymax, yn, yd) > 0;
  if (same && yn != it->yn) {
    int64_t dyn = yn - it->yn;
    if (dyn != it->dyn) {                /* a new step: dxb = (d xb / d yn) * step */
      it->dxl = v->arith == GEOM_HITAC ? geom_h10_dx(it->sl, dyn, it->hdl) : it->sl * dyn;
      it->dxr = v->arith == GEOM_HITAC ? geom_h10_dx(it->sr, dyn, it->hdr) : it->sr * dyn;
      it->dyn = dyn;
      cost_mw_mul(v->cost, 29, 44);
      cost_mw_mul(v->cost, 29, 44);
    }
    it->xl.num += it->dxl;               /* xb += dxb, xe += dxe */
    it->xr.num += it->dxr;
    cost_mw_add(v->cost, 75);
    cost_mw_add(v->cost, 75);
  } else if (!same) {
    if (!dblock_open(v, it, yn, yd)) {
      it->open = false;
      it->on = false;
      it->yn = yn;
      it->yd = yd;
      return T74_OK;
    }
    if (!it->core && dblock_take(v, &it->core, err) != T74_OK) return err->status;
  }
  it->yn = yn;
  it->yd = yd;
  dblock_store(v, it);
  COST_ADD_N(v->cost, COST_MEM, DBLOCK_WORDS);
  it->on = geom_rat_cmp(it->xl, it->xr) < 0;
  cost_mw_mul(v->cost, 75, 46);
  return T74_OK;
}

/* The front piece of the covering set; PRIO_SPLIT/PRIO_ERROR pass through as negative.
   A pair's priority holds over the pair's whole overlap only once the pair itself has
   been decided: deciding is also where crossing pieces are found and cut (priority.c).
   So the winner of the elimination below is then compared DIRECTLY with every other
   piece of the set — never by transitivity through a third piece, which would take the
   order of two pieces that cross as settled (issue 7: three faces meeting at one vertex
   showed a face behind the visible one, with one of the three pairs never decided). A
   front kept from the last stretch was compared with every piece it still shares the set
   with; only the pieces that joined are new to it. */
static int front_of(struct vis *v, int start_best, int from, int *best, bool *sure,
                    struct t74_error *err)
{
  int b = start_best;
  bool changed = start_best < 0;
  *sure = true;
  for (int k = from; k < v->nset; k++) {
    int c = v->set[k];
    if (c == b) continue;
    if (b < 0) { b = c; continue; }
    int r = prio_order(v->prio, b, c, err);
    if (r == PRIO_ERROR) return PRIO_ERROR;
    if (r == PRIO_SPLIT) return PRIO_SPLIT;
    if (r == PRIO_SECOND) { b = c; changed = true; }
  }
  /* a new front: check it against the whole set. With exact pairwise orders it wins every
     pair on the first round; a later round runs only if three orders are cyclic (possible
     only where pieces overlap within rounding of an intersection line's carrier), and
     nset rounds bound that. A front left unproven so is not kept for the next stretch. */
  for (int round = 0; changed && b >= 0; round++) {
    if (round == v->nset) { *sure = false; break; }
    changed = false;
    for (int k = 0; k < v->nset && !changed; k++) {
      int c = v->set[k];
      if (c == b) continue;
      int r = prio_order(v->prio, b, c, err);
      if (r == PRIO_ERROR) return PRIO_ERROR;
      if (r == PRIO_SPLIT) return PRIO_SPLIT;
      if (r == PRIO_SECOND) { b = c; changed = true; }
    }
  }
  *best = b;
  return PRIO_FIRST;
}

/* One attempt at the line; PRIO_SPLIT asks for another. */
static int line_once(struct vis *v, int64_t yn, int64_t yd, struct t74_error *err)
{
  struct seginfo *s = v->seg;
  v->nspan = 0;
  if (v->feed && v->feed(v->feed_ctx, yn, yd, err) != T74_OK) return PRIO_ERROR;
  if (!take_new_pieces(v)) return t74_fail(err, T74_EIO, "out of host memory"), PRIO_ERROR;

  /* 1. retire dead and finished pieces, activate those that begin at or below the line */
  int k = 0;
  for (int a = 0; a < v->nact; a++) {
    const struct piece *p = &s->p[v->act[a].piece];
    COST_ADD_N(v->cost, COST_MEM, 2);
    if (!p->alive || cmp_hy_frac(p->yhi, yn, yd) <= 0) {
      if (v->act[a].core) dblock_give(v, v->act[a].core);
      continue;
    }
    v->act[k++] = v->act[a];
  }
  v->nact = k;
  while (v->next < v->norder && cmp_hy_frac(s->p[v->order[v->next]].ylo, yn, yd) <= 0) {
    int p = v->order[v->next++];
    cost_mw_mul(v->cost, 88, 17);
    if (!s->p[p].alive || cmp_hy_frac(s->p[p].yhi, yn, yd) <= 0) continue;
    if (!grow((void **)&v->act, &v->actcap, v->nact + 1, sizeof *v->act))
      return t74_fail(err, T74_EIO, "out of host memory"), PRIO_ERROR;
    memset(&v->act[v->nact], 0, sizeof v->act[v->nact]);
    v->act[v->nact].piece = p;
    v->nact++;
  }

  /* 2. the D-blocks: spans on this line */
  for (int a = 0; a < v->nact; a++)
    if (dblock_span(v, &v->act[a], yn, yd, err) != T74_OK) return PRIO_ERROR;
  /* keep the x order of the last line: a stable insertion sort, pieces on the line by
     xl first, pieces the line misses after them */
  for (int a = 1; a < v->nact; a++) {
    struct vis_item t = v->act[a];
    int b = a - 1;
    while (b >= 0 && t.on &&
           (!v->act[b].on || geom_rat_cmp(v->act[b].xl, t.xl) > 0)) {
      v->act[b + 1] = v->act[b];
      b--;
      cost_mw_mul(v->cost, 75, 46);
    }
    v->act[b + 1] = t;
  }
  int non = 0;
  while (non < v->nact && v->act[non].on) non++;
  if (!grow((void **)&v->byxr, &v->byxrcap, v->nact, sizeof *v->byxr) ||
      !grow((void **)&v->set, &v->setcap, v->nact, sizeof *v->set))
    return t74_fail(err, T74_EIO, "out of host memory"), PRIO_ERROR;
  for (int a = 0; a < non; a++) {
    int b = a - 1;
    while (b >= 0 && geom_rat_cmp(v->act[v->byxr[b]].xr, v->act[a].xr) > 0) {
      v->byxr[b + 1] = v->byxr[b];
      b--;
      cost_mw_mul(v->cost, 75, 46);
    }
    v->byxr[b + 1] = a;
  }

  /* 3. sweep the span ends */
  int ia = 0, ir = 0, front = -1;
  v->nset = 0;
  while (ia < non || ir < non) {
    struct grat x;
    if (ia < non && (ir >= non || geom_rat_cmp(v->act[ia].xl, v->act[v->byxr[ir]].xr) <= 0))
      x = v->act[ia].xl;
    else
      x = v->act[v->byxr[ir]].xr;
    /* leave: spans ending at x */
    while (ir < non && geom_rat_cmp(v->act[v->byxr[ir]].xr, x) == 0) {
      int p = v->act[v->byxr[ir++]].piece;
      for (int m = 0; m < v->nset; m++)
        if (v->set[m] == p) { v->set[m] = v->set[--v->nset]; break; }
      /* Any piece leaving may take the front's title with it: front_of leans on
         transitivity (b before c, c before d), which holds point by point only where c
         is there too. Once c has left, front and d may never have been compared, and
         may cross (an intersection not yet cut) right here: choose afresh among the
         pieces present, so every step of the chain is a pair met on this stretch. */
      front = -1;
      COST_ADD_N(v->cost, COST_MEM, 2);
    }
    /* join: spans starting at x */
    int joined = v->nset;
    while (ia < non && geom_rat_cmp(v->act[ia].xl, x) == 0) {
      v->set[v->nset++] = v->act[ia++].piece;
      COST_ADD_N(v->cost, COST_MEM, 2);
    }
    if (v->nset == 0) continue;
    struct grat xn;
    if (ia < non && geom_rat_cmp(v->act[ia].xl, v->act[v->byxr[ir]].xr) < 0) xn = v->act[ia].xl;
    else xn = v->act[v->byxr[ir]].xr;
    /* the stretch [x, xn) has a fixed covering set: find its front piece */
    bool sure;
    int r = front < 0 ? front_of(v, -1, 0, &front, &sure, err)
                      : front_of(v, front, joined, &front, &sure, err);
    if (r != PRIO_FIRST) return r;
    if (!push_span(v, x, xn, front))
      return t74_fail(err, T74_EIO, "out of host memory"), PRIO_ERROR;
    if (!sure) front = -1;
  }
  return PRIO_FIRST;
}

int vis_spans(struct vis *v, int64_t yn, int64_t yd, const struct vis_span **span,
              int *nspan, struct t74_error *err)
{
  v->yn = yn;
  v->yd = yd;
  v->lines++;
  for (;;) {
    int r = line_once(v, yn, yd, err);
    if (r == PRIO_ERROR) return err->status ? err->status : T74_EINPUT;
    if (r != PRIO_SPLIT) break;
  }
  *span = v->span;
  *nspan = v->nspan;
  return T74_OK;
}

int vis_scan(struct vis *v, const struct vis_grid *g, vis_point_fn point, void *ctx,
             struct t74_error *err)
{
  /* Point i of a line is at x_i = xn_i / xd with xn_i = GRID_ONE (xd XL + (2i + 1)(XR - XL)),
     and a point belongs to the first span k (in order) with x_i < x1_k, when x0_k <= x_i.
     With XL < XR (the scene reader's rule) x_i grows with i, so "x1_k <= x_i" and
     "x0_k <= x_i" each hold from some index on: for each span the scan enters, the index
     where it reaches x0 and the one where it leaves x1 are found once, by a galloping
     search from the current point with the same exact compare (geom_rat_cmp_frac), and
     the points between take their face without a compare of their own. The faces are
     those of comparing every point; a window with XL >= XR compares every point. */
  const int64_t XL = g->window[0], YB = g->window[1], XR = g->window[2], YT = g->window[3];
  const int64_t xd = 2 * (int64_t)g->W;          /* point centres: n / xd grid units */
  const int W = g->W;
#define XN(i) (GRID_ONE * (xd * XL + (2 * (int64_t)(i) + 1) * (XR - XL)))
  for (int j = g->H - 1; j >= 0; j--) {
    /* y = YT - (j + 1/2)(YT - YB)/H, on the grid */
    int64_t yd = 2 * (int64_t)g->H;
    int64_t yn = GRID_ONE * (yd * YT - (2 * (int64_t)j + 1) * (YT - YB));
    const struct vis_span *sp;
    int ns;
    int st = vis_spans(v, yn, yd, &sp, &ns, err);
    if (st != T74_OK) return st;
    if (XL >= XR) {
      int k = 0;
      for (int i = 0; i < W; i++) {
        int64_t xn = XN(i);
        while (k < ns && geom_rat_cmp_frac(sp[k].x1, xn, xd) <= 0) k++;
        int face = -1;
        if (k < ns && geom_rat_cmp_frac(sp[k].x0, xn, xd) <= 0) face = sp[k].face;
        cost_mw_mul(v->cost, 75, 17);
        st = point(ctx, i, j, face);
        if (st != T74_OK) return st;
      }
      continue;
    }
    int k = 0, i = 0;
    while (i < W) {
      /* the spans the point i has left */
      int leave = W;                   /* first index with x1_k <= x_i: the scan leaves k */
      for (; k < ns; k++) {
        struct grat e = sp[k].x1;
        if (geom_rat_cmp_frac(e, XN(i), xd) <= 0) continue;   /* already past it */
        /* gallop: x1_k > x_i; find the first index lo > i with x1_k <= x_lo, or W */
        int lo = i, step = 1, hi;
        for (;;) {
          hi = lo + step;
          if (hi >= W) { hi = W; break; }
          if (geom_rat_cmp_frac(e, XN(hi), xd) <= 0) break;
          lo = hi;
          step *= 2;
        }
        while (hi - lo > 1) {          /* x1_k > x_lo; x1_k <= x_hi (or hi == W) */
          int mid = lo + (hi - lo) / 2;
          if (geom_rat_cmp_frac(e, XN(mid), xd) <= 0) hi = mid;
          else lo = mid;
        }
        leave = hi;
        break;
      }
      int enter = leave;               /* first index with x0_k <= x_i (points before: none) */
      if (k < ns) {
        struct grat b = sp[k].x0;
        if (geom_rat_cmp_frac(b, XN(i), xd) <= 0) enter = i;
        else {
          int lo = i, hi = leave;      /* x0_k > x_lo; the answer is in (lo, leave] */
          int step = 1;
          for (;;) {
            int t = lo + step;
            if (t >= hi) break;
            if (geom_rat_cmp_frac(b, XN(t), xd) <= 0) { hi = t; break; }
            lo = t;
            step *= 2;
          }
          while (hi - lo > 1) {
            int mid = lo + (hi - lo) / 2;
            if (geom_rat_cmp_frac(b, XN(mid), xd) <= 0) hi = mid;
            else lo = mid;
          }
          enter = hi;
        }
      }
      for (; i < leave; i++) {
        cost_mw_mul(v->cost, 75, 17);
        st = point(ctx, i, j, i >= enter ? sp[k].face : -1);
        if (st != T74_OK) return st;
      }
      k++;                             /* left (or W reached) */
    }
  }
#undef XN
  return T74_OK;
}
