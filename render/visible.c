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
**      at again only when the front piece itself leaves. The pieces' order by xb and their
**      order by xe are both kept from line to line, so each line re-sorts a nearly sorted
**      list (an insertion sort), and pieces new on the line are sorted apart and merged in.
**
** A pair's priority is asked for only when both pieces cover a stretch of positive length,
** so the matrix is filled lazily with pairs that really overlap on the plane. When a pair
** turns out to interpenetrate, both pieces are cut (priority.c); the sweep takes the
** halves in where it stands and goes on from there (resume below): the stretches already
** found to its left stay as they are, and are given to the halves at the line's end. A
** pair of halves takes the order of a decided pair of the pieces they were cut from
** (order_of), and a large set's front is looked for first at the piece nearest the eye
** by an estimate (front_guess): both only spare pairs from being decided.
**
** Invariant: after vis_spans, the stretches are disjoint, ordered, and each lies inside the
** span of its piece, an alive one; a point of the line lies in a stretch exactly when some
** alive piece owns it under the tie rule of geom.h.
*/
#include "render/visible.h"
#include "render/vis_x.h"
#include "emu/grow.h"

#include <assert.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static int cmp_hy_frac(struct hpoint p, int64_t n, int64_t d)
{
  return geom_hy_cmp(p, n, d);
}

/* cmp_hy_frac of piece p's lowest vertex, from its kept height. */
static int ylo_cmp_frac(const struct piece *p, int64_t n, int64_t d)
{
  wide l = piece_ylo_y(p) * d, r = (wide)n * (wide)(uint64_t)p->ylo_w;
  return (l > r) - (l < r);
}

static int cmp_ylo(const struct seginfo *s, int a, int b)
{
  const struct piece *p = &s->p[a], *q = &s->p[b];
  int c = geom_cross_sign(piece_ylo_y(p), q->ylo_w, piece_ylo_y(q), p->ylo_w);   /* exactly */
  return c ? c : (a > b) - (a < b);
}

/* ---- orders of indices -----------------------------------------------------------------
   Comparisons of two pieces (by lowest y) or of two active items (by xb or by xe, pieces
   the line meets before those it misses); each compare made is charged as the 1974
   program would make it: a lowest y a product of 88 x 59 bits, an x one of 75 x 46,
   counted as it is made and charged at the end of the line (charge_compares). */
typedef int (*vis_cmp)(struct vis *v, int a, int b);

static inline int by_ylo(struct vis *v, int a, int b)
{
  v->pend_ycmp++;
  return cmp_ylo(v->seg, a, b);
}

/* by_xl inline (the insertion sort of every line, sort_kept, makes its compares itself);
   not always_inline: a -O1 build (make asan) cannot inline it where it is passed as a
   pointer, and must still build */
static inline int by_xl(struct vis *v, int i, int j)
{
  const struct vis_key *a = &v->key[i], *b = &v->key[j];
  if (a->on != b->on) return a->on ? -1 : 1;
  if (!a->on) return 0;
  v->pend_xcmp++;
  return kx_cmp(a->l, b->l, &v->act[i].xl, &v->act[j].xl);
}

static inline int by_xr(struct vis *v, int i, int j)
{
  v->pend_xcmp++;
  return kx_cmp(v->key[i].r, v->key[j].r, &v->act[i].xr, &v->act[j].xr);
}

/* The compares the orders counted, and the looks prio_order_lineage counted, charged
   (before anything reads the counters: at the end of vis_init and of each line). */
static void charge_compares(struct vis *v)
{
  cost_mw_mul_n(v->cost, 88, 59, v->pend_ycmp);
  cost_mw_mul_n(v->cost, 75, 46, v->pend_xcmp);
  cost_mw_add_n(v->cost, 75, v->pend_xadd);
  cost_mw_mul_n(v->cost, 88, 17, v->pend_side);
  v->pend_ycmp = v->pend_xcmp = v->pend_xadd = v->pend_side = 0;
  prio_charge_pending(v->prio);             /* and the Priority Matrix's looks */
}

/* Merge the sorted runs a[0..na) and b[0..nb) into out (stable: a first on ties). */
static void merge_runs(struct vis *v, const int *a, int na, const int *b, int nb,
                       int *out, vis_cmp cmp)
{
  int i = 0, j = 0, k = 0;
  while (i < na && j < nb) out[k++] = cmp(v, b[j], a[i]) < 0 ? b[j++] : a[i++];
  while (i < na) out[k++] = a[i++];
  while (j < nb) out[k++] = b[j++];
}

/* A batch of new pieces sorted stably, scratch tmp[0..n): rsort_merge's merge sort
   (rsort.h) written out for the item indices, with cmp a constant at each call (inlined:
   the sort's compares were indirect calls through a context, about 60 instructions each,
   17 M of a frame at 10,000 boxes). The same passes, the same compares in the same order
   (runs of 1, 2, 4, ... merged left to right, the right item taken only when strictly
   less), so the same order and the same compares counted. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
static inline void sort_batch(struct vis *v, int *a, int n, int *tmp, vis_cmp cmp)
{
  int *src = a, *dst = tmp;
  for (int width = 1; width < n; width *= 2) {
    for (int lo = 0; lo < n; lo += 2 * width) {
      int mid = lo + width < n ? lo + width : n;
      int hi = lo + 2 * width < n ? lo + 2 * width : n;
      int i = lo, j = mid, k = lo;
      while (i < mid && j < hi) dst[k++] = cmp(v, src[j], src[i]) < 0 ? src[j++] : src[i++];
      while (i < mid) dst[k++] = src[i++];
      while (j < hi) dst[k++] = src[j++];
    }
    int *t = src; src = dst; dst = t;
  }
  if (src != a) memcpy(a, src, (size_t)n * sizeof *a);
}

/* A stable insertion sort of a[0..n) by by_xl (xr false) or by_xr (true): for the order
   kept from the last line, which moves only where two ends pass each other between the
   lines. The item inserted is read once, and the compares are counted at the end: the
   same compares, the same count, as cmp(v, a[j], t) > 0 would make. */
static inline void sort_kept(struct vis *v, int *a, int n, bool xr)
{
  uint64_t cmps = 0;
  const struct vis_key *key = v->key;
  for (int i = 1; i < n; i++) {
    int t = a[i], j = i - 1;
    const struct vis_key *ti = &key[t];
    double lo, hi;
    key_band(xr ? ti->r : ti->l, &lo, &hi);
    const int ton = ti->on;
    for (; j >= 0; j--) {
      const struct vis_key *aj = &key[a[j]];
      if (!xr) {                         /* by_xl: the pieces the line meets first */
        if (aj->on != ton) {
          if (aj->on) break;             /* -1 */
          a[j + 1] = a[j];               /* 1 */
          continue;
        }
        if (!ton) break;                 /* 0 */
      }
      cmps++;
      const struct vis_item *ij = &v->act[a[j]], *it = &v->act[t];
      if (band_cmp(xr ? aj->r : aj->l, lo, hi, xr ? &ij->xr : &ij->xl,
                   xr ? &it->xr : &it->xl) <= 0) break;
      a[j + 1] = a[j];
    }
    a[j + 1] = t;
  }
  v->pend_xcmp += cmps;
}

/* Take item `it` out of the sorted ord[0..*n) (found by a binary search, then among
   equal keys). The searches' steps choose the half by conditional moves, not a branch a
   step: which half comes as a coin toss, and a mispredicted branch cost more than the
   compare (issue 19); the same compares, in the same order, charged as before. */
/* cmp(v, o, it) for cmp by_xl (xr false) or by_xr (true), with it's on and its end's key
   band (key_band) worked out once: the same answer, counted alike; an item against
   itself is 0 (x_cmp of a number with itself). */
static inline int ord_cmp(struct vis *v, int o, int it, bool xr, int ton, double lo,
                          double hi)
{
  const struct vis_key *k = &v->key[o];
  if (!xr) {
    if (k->on != ton) return k->on ? -1 : 1;
    if (!ton) return 0;
  }
  v->pend_xcmp++;
  if (o == it) return 0;
  return xr ? band_cmp(k->r, lo, hi, &v->act[o].xr, &v->act[it].xr)
            : band_cmp(k->l, lo, hi, &v->act[o].xl, &v->act[it].xl);
}

static void ord_remove(struct vis *v, int *ord, int *n, int it, bool xr)
{
  int lo = 0, hi = *n;
  const int ton = v->key[it].on;
  double klo, khi;
  key_band(xr ? v->key[it].r : v->key[it].l, &klo, &khi);
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    int before = ord_cmp(v, ord[mid], it, xr, ton, klo, khi) < 0;
    lo = before ? mid + 1 : lo;            /* conditional moves: no branch a step */
    hi = before ? hi : mid;
  }
  while (lo < *n && ord[lo] != it) lo++;
  if (lo == *n) return;
  memmove(&ord[lo], &ord[lo + 1], (size_t)(*n - lo - 1) * sizeof *ord);
  (*n)--;
}

/* Put item `it` into the sorted ord[0..*n), after the equal keys (room for one more). */
static void ord_insert(struct vis *v, int *ord, int *n, int it, bool xr)
{
  int lo = 0, hi = *n;
  const int ton = v->key[it].on;
  double klo, khi;
  key_band(xr ? v->key[it].r : v->key[it].l, &klo, &khi);
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    int before = ord_cmp(v, ord[mid], it, xr, ton, klo, khi) <= 0;
    lo = before ? mid + 1 : lo;
    hi = before ? hi : mid;
  }
  memmove(&ord[lo + 1], &ord[lo], (size_t)(*n - lo) * sizeof *ord);
  ord[lo] = it;
  (*n)++;
}

/* Place pieces added to seg since last time into `order` (after `next`, by lowest y):
   the new ones sorted apart, then merged in from the back, each placed by a binary
   search over the pieces not yet passed (as one piece alone is placed), so every piece
   already in order moves at most once however many arrive together. */
static int take_new_pieces(struct vis *v)
{
  struct seginfo *s = v->seg;
  int room = s->n - v->seen;
  if (room <= 0) return 1;
  if (!t74_grow((void **)&v->order, &v->ordcap, s->n, sizeof *v->order) ||
      !t74_grow((void **)&v->tmp, &v->tmpcap, room, sizeof *v->tmp) ||
      !t74_grow((void **)&v->tmp2, &v->tmp2cap, room, sizeof *v->tmp2))
    return 0;
  int k = 0;
  for (; v->seen < s->n; v->seen++)
    if (s->p[v->seen].alive && !(v->skip_face && v->skip_face[s->p[v->seen].face]))
      v->tmp[k++] = v->seen;
  sort_batch(v, v->tmp, k, v->tmp2, by_ylo);
  int hi = v->norder, dst = v->norder + k;  /* order[next..hi): not yet moved */
  for (int j = k - 1; j >= 0; j--) {
    int p = v->tmp[j], lo = v->next, h = hi;
    while (lo < h) {
      int mid = (lo + h) / 2;
      if (by_ylo(v, v->order[mid], p) < 0) lo = mid + 1; else h = mid;
    }
    dst -= hi - lo;
    memmove(&v->order[dst], &v->order[lo], (size_t)(hi - lo) * sizeof *v->order);
    v->order[--dst] = p;
    hi = lo;
  }
  v->norder += k;
  return 1;
}

int vis_init(struct vis *v, struct seginfo *seg, struct prio *prio, struct cost *cost,
             struct t74_error *err)
{
  return vis_init_without(v, seg, prio, cost, NULL, err);
}

int vis_init_without(struct vis *v, struct seginfo *seg, struct prio *prio, struct cost *cost,
                     const uint8_t *skip_face, struct t74_error *err)
{
  memset(v, 0, sizeof *v);
  v->seg = seg;
  v->prio = prio;
  v->cost = cost;
  v->skip_face = skip_face;
  v->yd = 0;
  int ok = take_new_pieces(v);
  charge_compares(v);
  if (!ok) return t74_fail(err, T74_EIO, "out of host memory");
  return T74_OK;
}

void vis_free(struct vis *v)
{
  free(v->dfree);
  free(v->order);
  free(v->act);
  free(v->key);
  free(v->byxl);
  free(v->byxr);
  free(v->set);
  free(v->seti);
  free(v->setpos);
  free(v->span);
  free(v->span2);
  free(v->tmp);
  free(v->tmp2);
  free(v->tmp3);
  memset(v, 0, sizeof *v);
}

/* Append [*x0, *x1) of piece to a list of stretches, joined to the last when it goes on.
   The ends by address: passed by value, the sweep's were copied to the stack in 8-byte
   stores and read back at once in 16-byte loads, which waited for the stores (a
   store-forwarding stall, issue 19). */
static int put_span(struct vis_span **sp, int *n, size_t *cap, const struct grat *x0,
                    const struct grat *x1, int piece, int face)
{
  if (*n > 0) {
    struct vis_span *last = &(*sp)[*n - 1];
    if (last->piece == piece && x_cmp(last->x1, *x0) == 0) {
      last->x1 = *x1;
      return 1;
    }
  }
  if (!t74_grow((void **)sp, cap, *n + 1, sizeof **sp)) return 0;
  struct vis_span *s = &(*sp)[(*n)++];
  s->x0 = *x0;
  s->x1 = *x1;
  s->piece = piece;
  s->face = face;
  return 1;
}

static int push_span(struct vis *v, const struct grat *x0, const struct grat *x1, int piece)
{
  return put_span(&v->span, &v->nspan, &v->spancap, x0, x1, piece, v->seg->p[piece].face);
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
    if (!t74_grow((void **)&v->dfree, &v->dfreecap, DBLOCK_CHUNK, sizeof *v->dfree))
      return t74_fail(err, T74_EIO, "out of host memory");
    for (int k = DBLOCK_CHUNK - 1; k >= 0; k--) v->dfree[v->ndfree++] = a + (uint32_t)k * DBLOCK_WORDS;
  }
  *addr = v->dfree[--v->ndfree];
  return T74_OK;
}

static void dblock_give(struct vis *v, uint32_t addr)
{
  /* the free list never outgrows the rows taken: room was made when they were */
  if (t74_grow((void **)&v->dfree, &v->dfreecap, v->ndfree + 1, sizeof *v->dfree))
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

/* The D-block's words that stay while it does: fix16 of dxb and dxe (each denominator is
   fixed within the D-block, and the increments change only with the line step) and y-max
   in whole grid units; made where those change (dblock_open, a new step in dblock_span),
   not with every line's store. */
static void dblock_fixed(struct vis_item *it)
{
  it->fdxl = fix16(it->dxl, it->xl.den);
  it->fdxr = fix16(it->dxr, it->xr.den);
  it->fymax = (uint16_t)(it->ymax.Y / it->ymax.W / GRID_ONE);
}

static void dblock_store(struct vis *v, const struct vis_item *it)
{
  struct core *c = v->seg->core;
  core_put_int(c, it->core, 2, fix16(it->xl.num, it->xl.den));
  core_put_int(c, it->core + 2, 2, fix16(it->xr.num, it->xr.den));
  core_put_int(c, it->core + 4, 2, it->fdxl);
  core_put_int(c, it->core + 6, 2, it->fdxr);
  core_write(c, it->core + 8, it->fymax);
  core_write(c, it->core + 9, 0);
}

/* The lower of two heights. */
static struct hpoint lower(struct hpoint p, struct hpoint q)
{
  return geom_cross_sign(p.Y, q.W, q.Y, p.W) <= 0 ? p : q;
}

/* The height of p's vertex k (piece_vy; pl: its lines): a piece's own kept vertex, or
   made into vb[k] the first time (bit k of *made; a piece whose vertices are not kept,
   one on its face's points, has at most PIECE_VBUF <= 64 sides). */
static inline struct hpoint vy_at(const struct piece *p, const struct gline *pl,
                                  struct hpoint *vb, uint64_t *made, int k)
{
  if (!p->onface) return piece_kept(p)[k];
  if (!(*made >> k & 1)) {
    *made |= (uint64_t)1 << k;
    vb[k] = piece_vy_at(pl[k ? k - 1 : p->n - 1], pl[k]);
  }
  return vb[k];
}

/* Open the D-block of piece p that holds the line y = yn/yd: its left side runs down
   (a > 0) from v[k] to v[k+1], its right side up (a < 0) from v[k] to v[k+1]; each is
   the one whose y-range [bottom, top) holds the line. False when none does: the line is
   at or above the piece's top. */
static bool dblock_open(struct vis *v, struct vis_item *it, int64_t yn, int64_t yd)
{
  const struct piece *p = &v->seg->p[it->piece];
  /* the heights of the vertices (piece_vy), each made once, as the sides reach them */
  struct hpoint vb[PIECE_VBUF];
  uint64_t made = 0;
  struct gline lb[PIECE_VBUF];
  const struct gline *pl;
  int kl = -1, kr = -1;
  if (p->onface) {
    /* A piece on its face's points (struct piece: onface): side k runs from pt[k] to
       pt[k+1], so its line's a is pt[k].y - pt[k+1].y (geom_line), and vertex k, the meet
       of sides k-1 and k, both through pt[k] and not parallel (seginfo_add_face), is
       pt[k] exactly: piece_vy gives (0, W y, W), W > 0, and (0, y, 1) has the same height
       Y/W. Everything below reads only that height (geom_hy_cmp, lower, dblock_store's
       Y / W, exact as Y = W y): the same decisions and values, without the lines of the
       sides passed over and the vertices' products (issue 19). */
    const struct gpoint *pt = p->pt;
    for (int k = 0; k < p->n && (kl < 0 || kr < 0); k++) {
      int k1 = k + 1 < p->n ? k + 1 : 0;
      int64_t a = pt[k].y - pt[k1].y;
      if (a == 0) continue;
      struct hpoint lo = { 0, a > 0 ? pt[k1].y : pt[k].y, 1 };
      struct hpoint hi = { 0, a > 0 ? pt[k].y : pt[k1].y, 1 };
      v->pend_side++;                    /* charged by charge_compares */
      if (geom_hy_cmp(lo, yn, yd) > 0 || geom_hy_cmp(hi, yn, yd) <= 0) continue;
      if (a > 0) kl = k; else kr = k;
    }
    if (kl < 0 || kr < 0) return false;
    int kl1 = kl + 1 < p->n ? kl + 1 : 0, kr1 = kr + 1 < p->n ? kr + 1 : 0;
    lb[kl] = geom_line(pt[kl], pt[kl1]);
    lb[kr] = geom_line(pt[kr], pt[kr1]);
    pl = lb;                             /* (only lb[kl] and lb[kr] are read below) */
    vb[kl] = (struct hpoint){ 0, pt[kl].y, 1 };
    vb[kr1] = (struct hpoint){ 0, pt[kr1].y, 1 };
    made = (uint64_t)1 << kl | (uint64_t)1 << kr1;
  } else {
    pl = piece_lines(p, lb);
    for (int k = 0; k < p->n && (kl < 0 || kr < 0); k++) {
      const struct gline *l = &pl[k];
      if (l->a == 0) continue;
      int k1 = k + 1 < p->n ? k + 1 : 0;
      struct hpoint lo = l->a > 0 ? vy_at(p, pl, vb, &made, k1) : vy_at(p, pl, vb, &made, k);
      struct hpoint hi = l->a > 0 ? vy_at(p, pl, vb, &made, k) : vy_at(p, pl, vb, &made, k1);
      v->pend_side++;                    /* charged by charge_compares */
      if (geom_hy_cmp(lo, yn, yd) > 0 || geom_hy_cmp(hi, yn, yd) <= 0) continue;
      if (l->a > 0) kl = k; else kr = k;
    }
  }
  if (kl < 0 || kr < 0) return false;
  it->kl = kl;
  it->kr = kr;
  it->xl = geom_x_at(pl[kl], yn, yd);
  it->xr = geom_x_at(pl[kr], yn, yd);
  /* geom_x_at: num = -(b yn + c yd), negated with the denominator when a < 0 */
  it->sl = pl[kl].a > 0 ? -(wide)pl[kl].b : (wide)pl[kl].b;
  it->sr = pl[kr].a > 0 ? -(wide)pl[kr].b : (wide)pl[kr].b;
  if (v->arith == GEOM_HITAC) {         /* --arith hitac: xb, xe as double words */
    it->hdl = it->xl.den;
    it->hdr = it->xr.den;
    it->xl = geom_h10_x(it->xl);
    it->xr = geom_h10_x(it->xr);
  }
  it->dyn = 0;
  it->dxl = it->dxr = 0;
  it->ymax = lower(vy_at(p, pl, vb, &made, kl),             /* (only its height is read) */
                   vy_at(p, pl, vb, &made, kr + 1 < p->n ? kr + 1 : 0));
  cost_mw_mul(v->cost, 58, 17);
  cost_mw_mul(v->cost, 58, 17);
  dblock_fixed(it);
  it->open = true;
  return true;
}

/* The span [xb, xe) of an active piece on the line y = yn/yd (y never decreasing):
   by its D-block's increments while the line stays below y-max with the same
   denominator, else from a newly opened D-block. */
static int dblock_span(struct vis *v, int a, int64_t yn, int64_t yd, struct t74_error *err)
{
  struct vis_item *it = &v->act[a];
  bool same = it->open && yd == it->yd && geom_hy_cmp(it->ymax, yn, yd) > 0;
  if (same && yn != it->yn) {
    int64_t dyn = yn - it->yn;
    if (dyn != it->dyn) {                /* a new step: dxb = (d xb / d yn) * step */
      it->dxl = v->arith == GEOM_HITAC ? geom_h10_dx(it->sl, dyn, it->hdl) : it->sl * dyn;
      it->dxr = v->arith == GEOM_HITAC ? geom_h10_dx(it->sr, dyn, it->hdr) : it->sr * dyn;
      it->dyn = dyn;
      it->fdxl = fix16(it->dxl, it->xl.den);   /* (dblock_fixed's, y-max unchanged) */
      it->fdxr = fix16(it->dxr, it->xr.den);
      cost_mw_mul(v->cost, 29, 44);
      cost_mw_mul(v->cost, 29, 44);
    }
    it->xl.num += it->dxl;               /* xb += dxb, xe += dxe */
    it->xr.num += it->dxr;
    v->pend_xadd += 2;                   /* charged by charge_compares */
  } else if (!same) {
    if (!dblock_open(v, it, yn, yd)) {
      it->open = false;
      it->on = false;
      v->key[a].on = 0;
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
  struct vis_key *k = &v->key[a];
  k->l = geom_rat_key(it->xl);
  k->r = geom_rat_key(it->xr);
  it->on = kx_cmp(k->l, k->r, &it->xl, &it->xr) < 0;
  k->on = it->on;
  v->pend_xcmp++;                        /* an x compare (charge_compares) */
  return T74_OK;
}


/* The piece p was cut from (priority.c), or -1. */
static int parent_of(const struct vis *v, int p)
{
  COST_ADD_N(v->cost, COST_MEM, 1);
  return v->seg->p[p].parent;
}

/* Ancestors looked at on each side before a pair is decided afresh. */
#define ANC_MAX 16

/* The order of pieces b and c. A decided pair's order holds over the pair's whole
   overlap, and a half is part of the piece it was cut from: so when b and c are not
   decided themselves, a decided pair of b (or an ancestor of b) with c (or an ancestor
   of c) gives their order over their overlap, exactly, as their own deciding would
   (they do not cross there: the ancestors did not). Looked at: b's ancestors against c,
   b against c's ancestors, the two parents; else prio_order decides (and may cut). Both
   cover the stretch st, each within its span (the sweep's covering set): in exact
   arithmetic that answers some of the deciding's overlap tests (priority.h, struct
   prio_meet); under --arith hitac the spans are the 1974 program's rounded ones, and
   every test is made. Always inlined into front_of, which asks it for every pair. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((always_inline))
#endif
static inline int order_of(struct vis *v, int b, int c, const struct prio_meet *st,
                    struct t74_error *err)
{
  int pb = parent_of(v, b), pc = parent_of(v, c);
  return prio_order_lineage(v->prio, b, c, pb, pc, ANC_MAX, v->cost,
                            v->arith == GEOM_EXACT ? st : NULL, err);
}

/* The front piece of the covering set of the stretch st; PRIO_SPLIT/PRIO_ERROR pass
   through as negative.
   A pair's priority holds over the pair's whole overlap only once the pair itself has
   been decided: deciding is also where crossing pieces are found and cut (priority.c).
   So the winner of the elimination below is then compared DIRECTLY with every other
   piece of the set — never by transitivity through a third piece, which would take the
   order of two pieces that cross as settled (issue 7: three faces meeting at one vertex
   showed a face behind the visible one, with one of the three pairs never decided).
   On return with *sure, *best has met every piece of the set in a decided pair and won
   it: either it was kept from the last stretch, had so met every piece it still shares
   the set with, and won against each piece from `from` on (the pieces that joined), or
   it is new and won the whole checking round below. The sweep relies on exactly this. */
static int front_guess(struct vis *v, struct grat x0, struct grat x1, int64_t yn, int64_t yd);

static int front_of(struct vis *v, int start_best, int from, int *best, bool *sure,
                    const struct prio_meet *st, struct t74_error *err)
{
  int b = start_best;
  bool changed = start_best < 0;
  *sure = true;
  for (int k = from; k < v->nset; k++) {
    int c = v->set[k];
    if (c == b) continue;
    if (b < 0) { b = c; continue; }
    int r = order_of(v, b, c, st, err);
    if (r == PRIO_ERROR) return PRIO_ERROR;
    if (r == PRIO_SPLIT) return PRIO_SPLIT;
    if (r == PRIO_SECOND) { b = c; changed = true; }
  }
  /* a new front: check it against the whole set. With exact pairwise orders it wins every
     pair on the first round; a later round runs only if three orders are cyclic (possible
     only where pieces overlap within rounding of an intersection line's carrier), and
     nset rounds bound that. A front left unproven so is not kept for the next stretch,
     and it is the piece whose plane is nearest the eye in the stretch (front_guess), not
     whichever piece the rounds stopped at. */
  for (int round = 0; changed && b >= 0; round++) {
    if (round == v->nset) {            /* cyclic: the tie rule of front_guess */
      *sure = false;
      b = front_guess(v, st->x0, st->x1, st->yn, st->yd);
      break;
    }
    changed = false;
    for (int k = 0; k < v->nset && !changed; k++) {
      int c = v->set[k];
      if (c == b) continue;
      int r = order_of(v, b, c, st, err);
      if (r == PRIO_ERROR) return PRIO_ERROR;
      if (r == PRIO_SPLIT) return PRIO_SPLIT;
      if (r == PRIO_SECOND) { b = c; changed = true; }
    }
  }
  *best = b;
  return PRIO_FIRST;
}

/* Sets from this size on start their front's election from front_guess: below it the
   pairs an estimate can save do not pay for the planes evaluated (1974 seconds). */
#define GUESS_MIN 8

/* A first candidate for the front of the covering set on the stretch [x0, x1) of the
   line y: the piece whose face's plane is nearest the eye at the stretch's middle, by
   an estimate — the depth form of priority.c (G = deye_B plane_A(r) - deye_A plane_B(r)
   > 0: face A in front), per face plane_A(r) / deye_A, at x and y cut to whole grid
   units, the quotient scaled by 2^32 and truncated. With exact pairwise orders it only
   orders front_of's pairs: the front is still the piece that won a decided pair against
   every other (a poor guess costs pairs decided, never a wrong picture). Where pairwise
   orders turn cyclic (pieces within rounding of an intersection line's carrier, where no
   order of the pairs is right everywhere), it is the tie rule: the piece nearest the eye
   there. Charged as the 1974 program would evaluate a plane: two products and a sum, a
   quotient, a compare. */
static int front_guess(struct vis *v, struct grat x0, struct grat x1, int64_t yn, int64_t yd)
{
  const struct mapped *m = v->prio->map;
  const int64_t *e = m->eye;
  wide xi = (x0.num / x0.den + x1.num / x1.den) / 2, yi = yn / yd;
  wide rx = xi - GRID_ONE * (wide)e[0], ry = yi - GRID_ONE * (wide)e[1];
  wide rz = -GRID_ONE * (wide)e[2];
  int best = -1;
  wide bq = 0;
  if (v->nset <= 2) return v->set[0];     /* one pair at most: nothing to gain */
  for (int k = 0; k < v->nset; k++) {
    const struct mface *f = &m->f[v->seg->p[v->set[k]].face];
    wide n = (wide)f->plane[0] * rx + (wide)f->plane[1] * ry + (wide)f->plane[2] * rz;
    wide an = n < 0 ? -n : n;
    wide q = an < ((wide)1 << 94) ? n * ((wide)1 << 32) / f->deye
                                  : n / f->deye * ((wide)1 << 32);
    if (best < 0 || q > bq) { best = v->set[k]; bq = q; }
  }
  uint64_t k = (uint64_t)v->nset;         /* each plane: two products and a sum, a quotient, */
  cost_mw_mul_n(v->cost, 51, 34, 2 * k);  /* a compare */
  cost_mw_add_n(v->cost, 86, k);
  cost_mw_div_n(v->cost, 86, 48, k);
  cost_mw_add_n(v->cost, 64, k);
  return best;
}

/* Activate the pieces of `order` that begin at or below the line (appended to act). */
static int activate(struct vis *v, int64_t yn, int64_t yd, struct t74_error *err)
{
  struct seginfo *s = v->seg;
  while (v->next < v->norder && ylo_cmp_frac(&s->p[v->order[v->next]], yn, yd) <= 0) {
    int p = v->order[v->next++];
    cost_mw_mul(v->cost, 88, 17);
    if (!s->p[p].alive) continue;
    struct hpoint yhi = piece_yhi_y(&s->p[p]);
    if (cmp_hy_frac(yhi, yn, yd) <= 0) continue;
    if (!t74_grow((void **)&v->act, &v->actcap, v->nact + 1, sizeof *v->act))
      return t74_fail(err, T74_EIO, "out of host memory");
    memset(&v->act[v->nact], 0, sizeof v->act[v->nact]);
    v->act[v->nact].piece = p;
    v->act[v->nact].yhi_y = yhi.Y;
    v->act[v->nact].yhi_w = (int64_t)yhi.W;
    v->nact++;
  }
  return T74_OK;
}

/* Room for n active items in the orders and the scratch arrays (at least one: every
   array then exists, as memcpy wants even for no bytes). */
static int room(struct vis *v, int n)
{
  n++;
  return t74_grow((void **)&v->byxl, &v->byxlcap, n, sizeof *v->byxl) &&
         t74_grow((void **)&v->byxr, &v->byxrcap, n, sizeof *v->byxr) &&
         t74_grow((void **)&v->set, &v->setcap, n, sizeof *v->set) &&
         t74_grow((void **)&v->seti, &v->seticap, n, sizeof *v->seti) &&
         t74_grow((void **)&v->setpos, &v->setposcap, n, sizeof *v->setpos) &&
         t74_grow((void **)&v->tmp, &v->tmpcap, n, sizeof *v->tmp) &&
         t74_grow((void **)&v->tmp2, &v->tmp2cap, n, sizeof *v->tmp2) &&
         t74_grow((void **)&v->tmp3, &v->tmp3cap, n, sizeof *v->tmp3);
}

/* Items on the line at the head of byxl (the pieces the line meets come first). */
static int count_on(const struct vis *v)
{
  int non = 0;
  while (non < v->nbyxl && v->act[v->byxl[non]].on) non++;
  return non;
}

/* The line's active set, spans and both x orders, before the sweep. */
static int line_begin(struct vis *v, int64_t yn, int64_t yd, struct t74_error *err)
{
  struct seginfo *s = v->seg;
  v->nspan = 0;
  if (v->feed && v->feed(v->feed_ctx, yn, yd, err) != T74_OK) return err->status;
  if (!take_new_pieces(v)) return t74_fail(err, T74_EIO, "out of host memory");
  v->born = s->n;

  /* 1. retire dead and finished pieces (tmp: where each item moves, -1 gone), activate
     those that begin at or below the line. The dead are the pieces cut on the last line
     (they left both orders there, in resume); they are dropped here, uncharged, as the
     last line's end once dropped them (line_end); the rest are looked at and charged. */
  if (!room(v, v->nact)) return t74_fail(err, T74_EIO, "out of host memory");
  int k = 0;
  for (int a = 0; a < v->nact; a++) {
    const struct piece *p = &s->p[v->act[a].piece];
    if (p->alive) COST_ADD_N(v->cost, COST_MEM, 2);
    if (!p->alive || cmp_hy_frac((struct hpoint){ 0, v->act[a].yhi_y, v->act[a].yhi_w },
                                 yn, yd) <= 0) {
      if (v->act[a].core) dblock_give(v, v->act[a].core);
      v->tmp[a] = -1;
      continue;
    }
    v->tmp[a] = k;
    if (k != a) v->act[k] = v->act[a];
    k++;
  }
  int m = 0;
  for (int i = 0; i < v->nbyxr; i++)
    if (v->tmp[v->byxr[i]] >= 0) v->byxr[m++] = v->tmp[v->byxr[i]];
  v->nbyxr = m;
  m = 0;                                   /* byxl likewise: the kept, in the last line's */
  for (int i = 0; i < v->nbyxl; i++)       /* order (each item is in byxl once) */
    if (v->tmp[v->byxl[i]] >= 0) v->byxl[m++] = v->tmp[v->byxl[i]];
  assert(m == k);
  v->nact = k;
  int kept = k;
  if (activate(v, yn, yd, err) != T74_OK) return err->status;

  /* 2. the D-blocks: spans on this line */
  if (!t74_grow((void **)&v->key, &v->keycap, v->nact + 1, sizeof *v->key))
    return t74_fail(err, T74_EIO, "out of host memory");
  for (int a = 0; a < v->nact; a++)
    if (dblock_span(v, a, yn, yd, err) != T74_OK) return err->status;
  if (!room(v, v->nact)) return t74_fail(err, T74_EIO, "out of host memory");

  /* 3. the order by xb: the pieces kept are in the last line's order (byxl[0..kept), as
     step 1 left it), the new ones are sorted apart and merged in */
  for (int a = kept; a < v->nact; a++) v->byxl[a] = a;
  sort_kept(v, v->byxl, kept, false);
  sort_batch(v, v->byxl + kept, v->nact - kept, v->tmp, by_xl);
  merge_runs(v, v->byxl, kept, v->byxl + kept, v->nact - kept, v->tmp, by_xl);
  memcpy(v->byxl, v->tmp, (size_t)v->nact * sizeof *v->byxl);
  v->nbyxl = v->nact;

  /* 4. the order by xe, kept from the last line likewise (tmp3 marks the items in it) */
  for (int a = 0; a < v->nact; a++) v->tmp3[a] = 0;
  m = 0;
  for (int i = 0; i < v->nbyxr; i++)
    if (v->act[v->byxr[i]].on) { v->tmp3[v->byxr[i]] = 1; v->byxr[m++] = v->byxr[i]; }
  sort_kept(v, v->byxr, m, true);
  int nb = 0;
  for (int a = 0; a < v->nact; a++)
    if (v->act[a].on && !v->tmp3[a]) v->tmp[nb++] = a;
  sort_batch(v, v->tmp, nb, v->tmp2, by_xr);
  merge_runs(v, v->byxr, m, v->tmp, nb, v->tmp2, by_xr);
  memcpy(v->byxr, v->tmp2, (size_t)(m + nb) * sizeof *v->byxr);
  v->nbyxr = m + nb;
  return T74_OK;
}

/* The first of the n items of ord whose xb (xe when xr) lies right of x. */
static int after_x(struct vis *v, const int *ord, int n, const struct grat *x, double kx,
                   bool xr)
{
  int lo = 0, hi = n;
  double klo, khi;
  key_band(kx, &klo, &khi);
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    const int a = ord[mid];
    v->pend_xcmp++;
    if ((xr ? band_cmp(v->key[a].r, klo, khi, &v->act[a].xr, x)
            : band_cmp(v->key[a].l, klo, khi, &v->act[a].xl, x)) <= 0) lo = mid + 1; else hi = mid;
  }
  return lo;
}

/* A pair of the covering set at x crossed and was cut (priority.c: the dead pieces have
   alive == false, their halves were appended to seg). Take the halves in on this line,
   where the sweep stands, instead of doing the line again:
   - the halves join `order`; those the line meets get their D-blocks now (appended to
     act, so every index the sweep holds stays valid) and join both x orders;
   - the dead leave both orders and the set; ia, ir are found again for x;
   - the set gains the halves that cover x (xb <= x < xe); the set keeps its order, so
     the pieces the front had already met stay before *joined, and the halves come after.
   Why the stretches left of x stay right: each was given to a piece that had won, in a
   decided pair, against every piece then covering it, and a decided pair's order holds
   over the pair's whole overlap. A half is part of its dead piece (the two halves' union
   is the old piece, and they do not overlap), in the same plane, so every order with it
   that was decided there still holds for the half at the same points; left of x nothing
   else changed. Only the name of a stretch's piece is out of date where that piece died:
   line_end gives such stretches to the halves. */
static int resume(struct vis *v, struct grat x, double kx, int64_t yn, int64_t yd, int *ia,
                  int *ir, int *non, int *joined, struct t74_error *err)
{
  struct seginfo *s = v->seg;
  v->resumes++;
  if (!take_new_pieces(v)) return t74_fail(err, T74_EIO, "out of host memory");
  int first = v->nact;
  if (activate(v, yn, yd, err) != T74_OK) return err->status;
  if (!t74_grow((void **)&v->key, &v->keycap, v->nact + 1, sizeof *v->key))
    return t74_fail(err, T74_EIO, "out of host memory");
  for (int a = first; a < v->nact; a++)
    if (dblock_span(v, a, yn, yd, err) != T74_OK) return err->status;
  if (!room(v, v->nact)) return t74_fail(err, T74_EIO, "out of host memory");

  /* both x orders: the dead out (they are pieces of the set: the pair just decided),
     the halves in, each by a binary search */
  for (int i = 0; i < v->nset; i++)
    if (!s->p[v->set[i]].alive) {
      ord_remove(v, v->byxl, &v->nbyxl, v->seti[i], false);
      ord_remove(v, v->byxr, &v->nbyxr, v->seti[i], true);
    }
  for (int a = first; a < v->nact; a++) {
    ord_insert(v, v->byxl, &v->nbyxl, a, false);
    if (v->act[a].on) ord_insert(v, v->byxr, &v->nbyxr, a, true);
  }
  *non = v->nbyxr;                        /* the items on the line, at the head of byxl */

  *ia = after_x(v, v->byxl, *non, &x, kx, false);
  *ir = after_x(v, v->byxr, v->nbyxr, &x, kx, true);

  /* the covering set */
  for (int a = first; a < v->nact; a++) v->setpos[a] = -1;
  int k = 0, j = 0;
  for (int i = 0; i < v->nset; i++) {
    if (!s->p[v->set[i]].alive) continue;
    if (i < *joined) j++;
    v->seti[k] = v->seti[i];
    v->set[k++] = v->set[i];
  }
  *joined = j;
  for (int a = first; a < v->nact; a++) {
    const struct vis_item *it = &v->act[a];
    if (!it->on) continue;
    v->pend_xcmp += 2;                   /* two x compares (charge_compares) */
    if (kx_cmp(v->key[a].l, kx, &it->xl, &x) <= 0 && kx_cmp(kx, v->key[a].r, &x, &it->xr) < 0) {
      v->seti[k] = a;
      v->set[k++] = it->piece;
      COST_ADD_N(v->cost, COST_MEM, 2);
    }
  }
  v->nset = k;
  for (int i = 0; i < k; i++) v->setpos[v->seti[i]] = i;
  return T74_OK;
}

/* The sweep over the span ends of the line; PRIO_FIRST when done. */
static int sweep(struct vis *v, int64_t yn, int64_t yd, struct t74_error *err)
{
#define XL(i) (v->act[v->byxl[i]].xl)
#define XR(i) (v->act[v->byxr[i]].xr)
#define KL(i) (v->key[v->byxl[i]].l)
#define KR(i) (v->key[v->byxr[i]].r)
  int non = count_on(v);
  int ia = 0, ir = 0, front = -1;
  /* This merge of the two orders is the host's (no 1974 work is counted in it), and some
     of its compares have answers it holds: x_cmp(XL(ia), XR(ir)) made for the end of a
     stretch is the next x's when ia and ir are still the same (cmp_ia, cmp_ir, cmp_lr;
     cmp_ia = -1: none held; resume changes both orders and forgets it), and x against
     the end it was taken from, or the other end when that compare was made, is known:
     those are not made again. */
  int cmp_ia = -1, cmp_ir = -1, cmp_lr = 0;
  v->nset = 0;
  for (int a = 0; a < v->nact; a++) v->setpos[a] = -1;
  while (ia < non || ir < v->nbyxr) {
    struct grat x;
    const bool both = ia < non && ir < v->nbyxr;
    const int lr = !both ? 0 : ia == cmp_ia && ir == cmp_ir ? cmp_lr
                   : kx_cmp(KL(ia), KR(ir), &XL(ia), &XR(ir));
    const bool from_l = ia < non && (ir >= v->nbyxr || lr <= 0);
    x = from_l ? XL(ia) : XR(ir);
    const double kx = from_l ? KL(ia) : KR(ir);
    /* leave: spans ending at x. The first XR(ir) is x when x was taken from it or
       lr == 0, and right of x when x = XL(ia) and lr < 0: 1 equal, -1 not, 0 ask. */
    int first = !from_l ? 1 : !both ? 0 : lr == 0 ? 1 : -1;
    while (ir < v->nbyxr && (first ? first > 0 : kx_cmp(KR(ir), kx, &XR(ir), &x) == 0)) {
      first = 0;
      int a = v->byxr[ir++], p = v->act[a].piece, m = v->setpos[a];
      if (m >= 0 && m < v->nset && v->seti[m] == a) {   /* out of the set, the last in */
        v->nset--;                                      /* its place */
        v->set[m] = v->set[v->nset];
        v->seti[m] = v->seti[v->nset];
        v->setpos[v->seti[m]] = m;
      }
      /* Only the front's own leaving calls for a new choice. A front kept (front_of
         returned it sure) has met every other piece of the set in a pair decided
         directly, and won each: not by transitivity through a third piece (issue 7,
         three faces at one vertex, tests/data/import/pierced_corner.s74), which is what
         once made any leave reset the front, when front_of still chained its choice.
         The pieces still here after another one leaves are a subset of those it beat,
         on a stretch inside each such pair's overlap, where a decided order holds
         point by point: the front is still in front of every one of them. */
      if (p == front) front = -1;
      COST_ADD_N(v->cost, COST_MEM, 2);
    }
    /* join: spans starting at x. The first XL(ia) is x when x was taken from it, and
       right of it when x = XR(ir) was taken because lr > 0. */
    int joined = v->nset;
    first = from_l ? 1 : both ? -1 : 0;
    while (ia < non && (first ? first > 0 : kx_cmp(KL(ia), kx, &XL(ia), &x) == 0)) {
      first = 0;
      v->setpos[v->byxl[ia]] = v->nset;
      v->seti[v->nset] = v->byxl[ia];
      v->set[v->nset++] = v->act[v->byxl[ia++]].piece;
      COST_ADD_N(v->cost, COST_MEM, 2);
    }
    while (v->nset > 0) {
      /* the stretch [x, xn) has a fixed covering set: find its front piece (ir < nbyxr:
         a piece of the set has not left yet) */
      if (ia < non) {
        cmp_lr = kx_cmp(KL(ia), KR(ir), &XL(ia), &XR(ir));
        cmp_ia = ia;
        cmp_ir = ir;
      }
      struct grat xn = ia < non && cmp_lr < 0 ? XL(ia) : XR(ir);
      bool sure;
      struct prio_meet st = { x, xn, yn, yd };
      int r = front >= 0 ? front_of(v, front, joined, &front, &sure, &st, err)
              : front_of(v, v->nset >= GUESS_MIN ? front_guess(v, x, xn, yn, yd) : -1, 0,
                         &front, &sure, &st, err);
      if (r == PRIO_SPLIT) {
        cmp_ia = -1;                      /* the orders change */
        if (resume(v, x, kx, yn, yd, &ia, &ir, &non, &joined, err) != T74_OK) return PRIO_ERROR;
        if (front >= 0 && !v->seg->p[front].alive) front = -1;
        continue;
      }
      if (r != PRIO_FIRST) return r;
      if (!push_span(v, &st.x0, &st.x1, front))
        return t74_fail(err, T74_EIO, "out of host memory"), PRIO_ERROR;
      if (!sure) front = -1;
      break;
    }
  }
#undef XL
#undef XR
#undef KL
#undef KR
  return PRIO_FIRST;
}

/* After the sweep: stretches given to a piece that was cut during it go to its halves
   (host bookkeeping, not the 1974 program's: it showed the face, which is the same).
   A dead piece's halves, and theirs, were all made on this line (pieces >= born), are in
   act with the dead piece's face, and partition its span on the line; no other piece of
   that face overlaps it. So the stretch is cut where those pieces' spans meet: at their
   xb, in order. In exact arithmetic each part must then lie in its piece's span (checked:
   an internal error if not); under --arith hitac xb and xe are rounded as in 1974 and the
   halves' spans may part or overlap by a rounding, so a part goes to the half whose xb
   is last at or before it (the first half when none is), and a stretch with no half on
   the line at all keeps the dead piece's number (its face is the same). */
static int rename_spans(struct vis *v, struct t74_error *err)
{
  const struct seginfo *s = v->seg;
  int non = count_on(v), nc = 0;
  for (int i = 0; i < non; i++)                     /* candidates, in order of xb */
    if (v->act[v->byxl[i]].piece >= v->born) v->tmp[nc++] = v->byxl[i];
  v->nspan2 = 0;
  for (int k = 0; k < v->nspan; k++) {
    const struct vis_span *sp = &v->span[k];
    int c = -1;                                     /* the half of the first part */
    if (!s->p[sp->piece].alive)
      for (int i = 0; i < nc; i++) {
        const struct vis_item *it = &v->act[v->tmp[i]];
        if (s->p[it->piece].face != sp->face) continue;
        if (c >= 0 && x_cmp(it->xl, sp->x0) > 0) break;
        c = i;
      }
    if (c < 0) {
      if (!s->p[sp->piece].alive && v->arith == GEOM_EXACT)
        return t74_fail(err, T74_EINPUT, "internal: cut piece %d has no half on the line",
                        sp->piece);
      if (!put_span(&v->span2, &v->nspan2, &v->span2cap, &sp->x0, &sp->x1, sp->piece, sp->face))
        return t74_fail(err, T74_EIO, "out of host memory");
      continue;
    }
    struct grat at = sp->x0;
    while (x_cmp(at, sp->x1) < 0) {
      int nx = c + 1;                               /* the next half of the face */
      while (nx < nc && s->p[v->act[v->tmp[nx]].piece].face != sp->face) nx++;
      const struct vis_item *it = &v->act[v->tmp[c]];
      struct grat to = sp->x1;
      if (nx < nc && x_cmp(v->act[v->tmp[nx]].xl, to) < 0) to = v->act[v->tmp[nx]].xl;
      if (v->arith == GEOM_EXACT &&
          (x_cmp(it->xl, at) > 0 || x_cmp(to, it->xr) > 0))
        return t74_fail(err, T74_EINPUT, "internal: the halves of cut piece %d do not "
                        "cover its stretch", sp->piece);
      if (x_cmp(at, to) < 0 &&
          !put_span(&v->span2, &v->nspan2, &v->span2cap, &at, &to, it->piece, sp->face))
        return t74_fail(err, T74_EIO, "out of host memory");
      if (x_cmp(to, at) > 0) at = to;
      if (nx >= nc) break;
      c = nx;
    }
  }
  struct vis_span *t = v->span; v->span = v->span2; v->span2 = t;
  size_t cp = v->spancap; v->spancap = v->span2cap; v->span2cap = cp;
  v->nspan = v->nspan2;
  return T74_OK;
}

/* After the sweep: stretches of cut pieces to their halves. The items stay where they
   are in act (the dead among them until the next line's step 1), and both x orders are
   kept as indices: the next line's insertion sorts start from them. (act was once put in
   order of xb here, 288 bytes an item moved every line: the same orders, the same
   compares.) */
static int line_end(struct vis *v, struct t74_error *err)
{
  const struct seginfo *s = v->seg;
  if (s->n > v->born && rename_spans(v, err) != T74_OK) return err->status;
  return T74_OK;
}

int vis_spans(struct vis *v, int64_t yn, int64_t yd, const struct vis_span **span,
              int *nspan, struct t74_error *err)
{
  assert(yd > 0 && yd < ((int64_t)1 << 34));   /* x_cmp: each denominator below 2^63 */
  v->yn = yn;
  v->yd = yd;
  v->lines++;
  int st = line_begin(v, yn, yd, err);
  if (st == T74_OK && sweep(v, yn, yd, err) != PRIO_FIRST) st = err->status ? err->status : T74_EINPUT;
  if (st == T74_OK) st = line_end(v, err);
  charge_compares(v);
  if (st != T74_OK) return st;
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
