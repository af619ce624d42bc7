/*
** segment.c — the Segment Generator: concave faces and faces with holes cut into convex
** pieces by horizontal lines through concave vertices.
** Stage: Segment Generator, 003 §3.1 eq. (3), Fig. 5, Fig. 6 (tables YSORT, XSORT of §2.2,
** Fig. 3, Fig. 4; PBS, IPL, LWS, UPS of Fig. 6).
**
** INVARIANTS
**   - Every working piece keeps the face on the LEFT of each of its sides; ring 0 is its
**     outer boundary (counter-clockwise), the others are holes (clockwise).
**   - A piece is cut at the y of its LOWEST concave vertex, and one cut handles every
**     concave vertex of the piece on that line; the pieces below the cut have no concave
**     vertex (they are the convex LWS pieces), the pieces above only concave vertices
**     strictly above the cut (they are the UPS pieces, cut again): the work ends.
**   - No point is ever rounded: a crossing point is (side's line) meet (y = c) exactly,
**     and each output side lies on an input edge's line or on a cut line y = c.
**
** THE METHOD. Paper 003 cuts a concave face from the bottom up, each time along the
** horizontal line through the lowest concave vertex (a vertex whose inner angle exceeds
** 180 degrees; here: the turn from the arriving to the leaving side is to the right, an
** exact sign of a 2x2 determinant of line coefficients; straight is not concave). The
** crossing points of the line are inserted into the boundary (table PBS, rings separated
** by '*'), listed in x order (IPL), and the rewrite rules of eq. (3) turn the boundary
** into the pieces below the line (LWS) and above it (UPS):
**     (a)  XaAb     -> aAb, abX             one piece below, one above
**     (b)  XaAcBb   -> aAc, cBb, abX        a concave vertex c touching the line from below
**     (b') XaAbYd   -> aAb, abX, dbY        a concave vertex touching it from above
**     (c)  XaAb*Ye  -> aAb, aeYebX          a hole's lowest vertex e: the hole ring is
**                                           joined to the outer ring through e
** The paper reads the pieces off PBS by jumping between paired IPL entries (Fig. 6 (b),
** (c)); tube74 does the same walk, the pairs decided by the rules matched on the types:
**   Lower pieces = piece and {y < c}. A run is a maximal chain of ring vertices with
**   y < c. Its crossings are the sides with exactly one endpoint y < c, at their point on
**   y = c (when that endpoint is ON the line, the crossing is that vertex), sorted by x
**   at c, ties by x at c - e (xsort_half). They must alternate: where the counter-
**   clockwise boundary goes down into y < c, then where it comes back up; otherwise the
**   ring was not simple and the face is refused (T74_EINPUT). The rules of eq. (3) on
**   the typed crossing points (rule_pairs, below) then say which two crossings bound one
**   cut interval. Walk: leave a run at its crossing, go along the cut interval to the
**   crossing the rules pair with it, continue along that ring (which may be a hole: that
**   is how rings are joined), until back at the start.
**   Upper pieces = piece and {y > c}, the same with y > c and ties at c + e.
** Vertices on the line and horizontal edges along it thus vanish into cut intervals
** unless they are crossing points; a vertex touching the line from below gives two lower
** crossings at one x (rule (b)), one touching from above two upper crossings (rules (b')
** and (c)). A ring with no crossing lies wholly on one side and goes, as a hole, to the
** piece of that side that contains it (exact point-in-polygon of one of its vertices).
** THE TYPES AND THE MATCH. Every crossing point of the line (an IPL entry) gets its type
** of Fig. 4, 5, exactly, from the ring alone (type_crossings, touch_concave: the direction
** a side passes the line; the turn at a touching vertex; the direction a touching chain
** runs):
** a the boundary passes down through the line, b up; c a concave vertex (or horizontal
** chain) touching it from below, d from above on the outer ring, e from above on a hole
** ring; t a convex vertex or chain touching it (the paper names no type: it cuts only
** through concave vertices). A point whose type cannot be decided means the boundary was
** not simple (T74_EINPUT). The cut intervals are matched from the types (rule_pairs):
** left to right on each side, a opens and b closes (rule (a)), c closes aAc and opens cBb
** (rule (b)), d and e close one upper interval and open the next (rules (b'), (c)), t
** opens and closes a side of zero width. The rules are named in the trace
** (trace_rules): each c is one (b), each d one (b'), the first e of a hole ring (x order)
** one (c) and each further e of that ring, on the outer ring once joined, one (b') as its
** d; each application takes one lower piece aAb, and the lower pieces left over are (a).
** The trace names the rules from this match, e.g. Fig. 6's first cut "(c) (b')".
** TIES where the paper is silent: crossing points at one x are ordered by the slopes of
** their sides (xsort_half, below), the two crossings of one point by its type (unless
** another point's crossing lies between them: points nested at one x keep the slope
** order); a horizontal edge on the line belongs to a chain, typed by its direction, and
** its inner vertices to no piece; IPL merges the two halves' lists in exact x order, the lower
** half's entry first on equal x; a crossing number is deleted from IPL after as many uses
** as it has half-crossings (two for a point: the paper's "used twice"; one for each end
** of a horizontal chain along the line).
** THE TABLES OF FIG. 6. With a trace, every cut also prints the states (a)-(d) of Fig. 6
** (trace_fig6): (a) PBS and IPL with the types under them; (b) after the lower pieces,
** PBS with their vertices zeroed and IPL with the crossing numbers used up zeroed, and
** LWS; (c) after each upper piece but the last; (d) after the last, "All Zero". Pieces
** are listed from their vertex that comes first in PBS, as the paper lists them.
**
** THE CHECK. For a simple boundary the rules' intervals are exactly the neighbours
** (1,2), (3,4), ... of the slope-ordered crossings of each half (tube74's cut before the
** rules decided it): that pairing is kept only as a check in cut_piece, and a face where
** the two differ is refused (T74_EINPUT) rather than cut a new way.
** Departures from the paper: crossing points at a vertex keep the vertex's
** number (as Fig. 6, where IPL holds vertices 10 and 8); new crossing points are numbered
** from max(10, largest vertex id) + 1 so they never collide with a vertex id (11, 12, ..
** as Fig. 6 for faces with ids up to 10), past 65534 wrapping onto the numbers the face's
** vertices leave free (a face of an import with vertex ids above 65535 numbers on in 32
** bits, docs/scale.md); nothing per face is kept for this but its largest id. The output
** drops a vertex where the two sides around it lie on the same oriented line or where a
** side has zero length; every output piece is checked strictly convex, turning once
** (T74_EINPUT otherwise).
**
** Tables in core (emu/core.h), words on the 16-bit machine: YSORT 3 words a row (y 2,
** id 1); XSORT 9 a row (xsort.h); PBS 1 word per vertex or crossing number plus 1 per
** '*'; IPL 1 word per crossing number; LWS and UPS 1 word per vertex plus 1 separator per
** piece (an id above 65535 still counted as one word). All are released when the face
** is done. Operations are counted in `cost`.
*/
#include "render/segment.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "render/xsort.h"
#include "render/ysort.h"

_Static_assert(XS_ORIG == SEGV_ORIG && XS_CROSS == SEGV_CROSS, "vertex kinds agree");

#define PBS_STAR 0xFFFFu                 /* '*' in PBS, and the piece separator in LWS/UPS */
#define SEG_INLINE 4                     /* queue and finished rings held in the context */

/* ---- scratch: what lives only while one face, or one cut of it, is made ---------------
   A stack of bump-allocated chunks: a face marks it when it starts and releases it when
   done, a cut the same for its own tables, so the tables of one cut are gone before the
   next (memory stays what one cut needs, never the sum over the cuts). The chunks are
   kept for the next face (issue 19: seg_check's caller keeps one between frames). The
   rings of the working pieces (and the queue and the finished rings, past the first few)
   outlive their cut in queue order, not stack order: they come from the pool below. */

struct scr_chunk {
  struct scr_chunk *next;
  size_t cap, used;                      /* bytes of data[] */
  max_align_t data[];
};

/* A block of the pool: its size class (64 << cls bytes) before it, the free list's link
   while it is free. */
union scr_block {
  struct { union scr_block *next; int cls; } h;
  max_align_t align;
};

#define SCR_CLASSES 48

struct seg_scratch {
  struct scr_chunk *first, *cur;         /* cur: the chunk allocated from (NULL: none yet) */
  union scr_block *free[SCR_CLASSES];    /* the pool: free blocks of each size class */
};

struct scr_mark {
  struct scr_chunk *c;
  size_t used;
};

static struct scr_mark scr_mark(const struct seg_scratch *s)
{
  return (struct scr_mark){ s->cur, s->cur ? s->cur->used : 0 };
}

static void scr_release(struct seg_scratch *s, struct scr_mark m)
{
  s->cur = m.c;
  if (m.c) m.c->used = m.used;
}

static void *scr_alloc(struct seg_scratch *s, size_t n)
{
  n = (n + sizeof(max_align_t) - 1) / sizeof(max_align_t) * sizeof(max_align_t);
  struct scr_chunk *c = s->cur;
  if (!c || c->cap - c->used < n) {
    struct scr_chunk *next = c ? c->next : s->first;
    if (!next || next->cap < n) {        /* the chunks after cur go: one big enough comes */
      while (next) { struct scr_chunk *t = next->next; free(next); next = t; }
      size_t cap = c && 2 * c->cap > n ? 2 * c->cap : n;
      if (cap < 4096) cap = 4096;
      next = malloc(offsetof(struct scr_chunk, data) + cap);
      if (!next) {
        if (c) c->next = NULL; else s->first = NULL;
        return NULL;
      }
      next->next = NULL;
      next->cap = cap;
      if (c) c->next = next; else s->first = next;
    }
    next->used = 0;
    s->cur = c = next;
  }
  void *p = (unsigned char *)c->data + c->used;
  c->used += n;
  return p;
}

static void *scr_zalloc(struct seg_scratch *s, size_t n)
{
  void *p = scr_alloc(s, n);
  if (p) memset(p, 0, n);
  return p;
}

/* The rings of the working pieces come from a pool of blocks kept in the scratch, by size
   class (a power of two): a piece's ring goes back to it when the piece is cut or done,
   and the next ring of that size takes it, without the host allocator. */
static void *pool_get(struct seg_scratch *s, size_t n)
{
  int k = 0;
  while (((size_t)64 << k) < n) k++;
  union scr_block *b = s->free[k];
  if (b) s->free[k] = b->h.next;
  else {
    b = malloc(sizeof *b + ((size_t)64 << k));
    if (!b) return NULL;
    b->h.cls = k;
  }
  return b + 1;
}

static void *pool_zget(struct seg_scratch *s, size_t n)
{
  void *p = pool_get(s, n);
  if (p) memset(p, 0, n);
  return p;
}

static void pool_put(struct seg_scratch *s, void *p)
{
  if (!p) return;
  union scr_block *b = (union scr_block *)p - 1;
  b->h.next = s->free[b->h.cls];
  s->free[b->h.cls] = b;
}

struct seg_scratch *seg_scratch_new(void)
{
  return calloc(1, sizeof(struct seg_scratch));
}

static void scr_free_chunks(struct seg_scratch *s)
{
  while (s->first) { struct scr_chunk *t = s->first->next; free(s->first); s->first = t; }
  s->cur = NULL;
  for (int k = 0; k < SCR_CLASSES; k++)
    while (s->free[k]) { union scr_block *t = s->free[k]->h.next; free(s->free[k]); s->free[k] = t; }
}

void seg_scratch_free(struct seg_scratch *s)
{
  if (!s) return;
  scr_free_chunks(s);
  free(s);
}

/* ---- working pieces ------------------------------------------------------------------ */

struct wpiece {                          /* a piece being cut: ring 0 outer, others holes */
  int id;                                /* 1 = the face itself, then in order of making */
  int nring;
  struct xs_ring *ring;
};

struct cyc {                             /* a growable ring (a piece boundary being walked) */
  int n, cap;
  struct xs_vertex *v;
  struct xs_side *s;
};

struct seg_ctx {
  const struct seg_input *in;
  struct core_name *ysort;     /* seg_convex's: CORE_T_YSORT as its caller keeps it, or NULL */
  FILE *trace;
  struct core *core;
  struct cost *cost;
  struct t74_error *err;
  struct seg_scratch *scr;               /* the face's and each cut's own tables */
  int check;                             /* seg_check: decide only; nothing written to
                                            core, no output pieces (cost, trace NULL) */
  int nvert;                             /* vertices of the face */
  uint32_t next_num;                     /* next crossing number */
  uint32_t numbered;                     /* crossing numbers given so far */
  uint32_t num_end;                      /* numbers stay below: 0xFFFF (PBS's '*', one word a
                                            number) while every vertex id fits a word, else
                                            UINT32_MAX (docs/scale.md) */
  uint32_t *ids;                         /* the face's vertex ids, ascending, no repeats:
                                            made only once the numbers wrap (next_used) */
  int nids, idcur;                       /* ids[idcur] is the first id >= next_num */
  uint32_t maxid;                        /* the largest vertex id of the face (at least 10) */
  struct ysort_row *ys;                  /* YSORT */
  int *conc;                             /* conc[i] == stamp: input vertex i concave in piece */
  int stamp;
  int ncut;
  int next_id;                           /* next piece id */
  /* the queue of pieces still to examine (FIFO: bottom pieces first, as the paper) */
  struct wpiece *q;
  int qhead, qn, qcap;
  /* finished convex rings */
  struct xs_ring *fin;
  int nfin, fincap;
  /* the first entries of both in the context itself: a convex face (most faces) then
     takes no host allocation for them */
  struct wpiece q0[SEG_INLINE];
  struct xs_ring fin0[SEG_INLINE];
};

static int oom(struct seg_ctx *x)
{
  return t74_fail(x->err, T74_ECORE, "face %u: host memory exhausted in the Segment Generator",
                  (unsigned)x->in->face_id);
}

static void ring_free(struct seg_scratch *scr, struct xs_ring *r)
{
  pool_put(scr, r->v);
  pool_put(scr, r->s);
  r->v = NULL;
  r->s = NULL;
  r->n = 0;
}

static void wpiece_free(struct seg_scratch *scr, struct wpiece *p)
{
  for (int r = 0; r < p->nring; r++) ring_free(scr, &p->ring[r]);
  pool_put(scr, p->ring);
  p->ring = NULL;
  p->nring = 0;
}

static int cyc_push(struct seg_scratch *scr, struct cyc *c, const struct xs_vertex *v,
                    const struct xs_side *s)
{
  if (c->n == c->cap) {
    int cap = c->cap ? 2 * c->cap : 16;
    struct xs_vertex *nv = pool_get(scr, (size_t)cap * sizeof *nv);
    struct xs_side *ns = pool_get(scr, (size_t)cap * sizeof *ns);
    if (!nv || !ns) { pool_put(scr, nv); pool_put(scr, ns); return -1; }
    if (c->n) {
      memcpy(nv, c->v, (size_t)c->n * sizeof *nv);
      memcpy(ns, c->s, (size_t)c->n * sizeof *ns);
    }
    pool_put(scr, c->v);
    pool_put(scr, c->s);
    c->v = nv;
    c->s = ns;
    c->cap = cap;
  }
  c->v[c->n] = *v;
  c->s[c->n] = *s;
  c->n++;
  return 0;
}

static void cyc_free(struct seg_scratch *scr, struct cyc *c)
{
  pool_put(scr, c->v);
  pool_put(scr, c->s);
  memset(c, 0, sizeof *c);
}

/* ---- counting ----------------------------------------------------------------------- */

static void count_mem(struct cost *k, uint64_t words)
{
  if (k) COST_ADD_N(k, COST_MEM, words);
}

static void count_branch(struct cost *k)
{
  if (k) COST_ADD_N(k, COST_BRANCH, 1);
}

/* The turn at a vertex: sign of a1*b2 - a2*b1, two 30 x 30-bit products and a compare. */
static void count_turns(struct cost *k, uint64_t n)
{
  if (!k) return;
  cost_mw_mul_n(k, 30, 30, 2 * n);
  cost_mw_add_n(k, 60, n);
}

static void count_turn(struct cost *k) { count_turns(k, 1); }

/* A compare of two crossings' x: two 64 x 32-bit products and a compare. */
static void count_xcmps(struct cost *k, uint64_t n)
{
  if (!k) return;
  cost_mw_mul_n(k, 64, 32, 2 * n);
  cost_mw_add_n(k, 96, n);
}

static void count_xcmp(struct cost *k) { count_xcmps(k, 1); }

/* ---- exact predicates on lines and vertices ------------------------------------------- */

/* Turn from a side on l1 to the next on l2: > 0 left (convex), < 0 right (concave).
   A line's direction is (b, -a), so the cross product is a1*b2 - a2*b1. */
static int turn(struct gline l1, struct gline l2)
{
  wide t = (wide)l1.a * l2.b - (wide)l2.a * l1.b;
  return (t > 0) - (t < 0);
}

/* Do the two sides run in the same direction (dot product of directions > 0)? */
static int same_dir(struct gline l1, struct gline l2)
{
  return (wide)l1.a * l2.a + (wide)l1.b * l2.b > 0;
}

/* The same oriented line: coefficients proportional with a positive factor. */
static int same_line(struct gline l1, struct gline l2)
{
  return (wide)l1.a * l2.b == (wide)l2.a * l1.b && (wide)l1.a * l2.c == (wide)l2.a * l1.c &&
         (wide)l1.b * l2.c == (wide)l2.b * l1.c && same_dir(l1, l2);
}

static int same_point(const struct xs_vertex *p, const struct xs_vertex *q)
{
  return p->y == q->y && geom_rat_cmp(p->x, q->x) == 0;
}

/* ---- trace helpers ------------------------------------------------------------------- */

static void put_wide(FILE *f, wide v)
{
  char buf[48];
  int n = 0;
  uwide u = v < 0 ? (uwide)0 - (uwide)v : (uwide)v;
  do { buf[n++] = (char)('0' + (int)(u % 10)); u /= 10; } while (u);
  if (v < 0) fputc('-', f);
  while (n) fputc(buf[--n], f);
}

static wide gcd_wide(wide a, wide b)
{
  if (a < 0) a = -a;
  if (b < 0) b = -b;
  while (b) { wide t = a % b; a = b; b = t; }
  return a;
}

/* x as an integer or a reduced fraction num/den. */
static void put_rat(FILE *f, struct grat x)
{
  wide g = gcd_wide(x.num, x.den);
  if (g == 0) g = 1;
  put_wide(f, x.num / g);
  if (x.den / g != 1) { fputc('/', f); put_wide(f, x.den / g); }
}

/* ---- input check and the first piece -------------------------------------------------- */

/* Whether p lies outside the plane grid (check_input refuses such a vertex). */
static inline bool off_grid(struct gpoint p)
{
  return p.x > GRID_LIMIT || p.x < -GRID_LIMIT || p.y > GRID_LIMIT || p.y < -GRID_LIMIT;
}

static int check_input(struct seg_ctx *x)
{
  const struct seg_input *in = x->in;
  unsigned fid = in->face_id;
  if (in->nring < 1 || !in->ring_start || !in->pt || !in->vid || in->ring_start[0] != 0)
    return t74_fail(x->err, T74_EINPUT, "face %u: no boundary rings", fid);
  for (int r = 0; r < in->nring; r++) {
    int lo = in->ring_start[r], hi = in->ring_start[r + 1], n = hi - lo;
    if (n < 3)
      return t74_fail(x->err, T74_EINPUT, "face %u: ring %d has %d vertices (at least 3)",
                      fid, r, n);
    wide area2 = 0;
    for (int k = 0, k1 = 1, k2 = 2 % n; k < n; k++, k1 = k2, k2 = k2 + 1 < n ? k2 + 1 : 0) {
      struct gpoint p = in->pt[lo + k], q = in->pt[lo + k1], s = in->pt[lo + k2];
      if (off_grid(p))
        return t74_fail(x->err, T74_EINPUT, "face %u: vertex %u outside the plane grid",
                        fid, (unsigned)in->vid[lo + k]);
      if (p.x == q.x && p.y == q.y)
        return t74_fail(x->err, T74_EINPUT, "face %u: vertices %u and %u coincide", fid,
                        (unsigned)in->vid[lo + k], (unsigned)in->vid[lo + k1]);
      if (!(q.x == s.x && q.y == s.y) && geom_orient(p, q, s) == 0 &&
          (wide)(q.x - p.x) * (s.x - q.x) + (wide)(q.y - p.y) * (s.y - q.y) < 0)
        return t74_fail(x->err, T74_EINPUT, "face %u: the boundary doubles back at vertex %u",
                        fid, (unsigned)in->vid[lo + k1]);
      area2 += (wide)p.x * q.y - (wide)q.x * p.y;
    }
    if (r == 0 && area2 <= 0)
      return t74_fail(x->err, T74_EINPUT,
                      "face %u: outer ring is not counter-clockwise (twice its area %s 0)",
                      fid, area2 == 0 ? "=" : "<");
    if (r > 0 && area2 >= 0)
      return t74_fail(x->err, T74_EINPUT, "face %u: hole ring %d is not clockwise", fid, r);
  }
  return T74_OK;
}

static struct xs_vertex orig_vertex(const struct seg_input *in, int i)
{
  struct xs_vertex v;
  memset(&v, 0, sizeof v);
  v.kind = XS_ORIG;
  v.num = in->vid[i];
  v.src = i;
  v.y = in->pt[i].y;
  v.x.num = in->pt[i].x;
  v.x.den = 1;
  v.p.X = in->pt[i].x;
  v.p.Y = in->pt[i].y;
  v.p.W = 1;
  return v;
}

/* Ring r of the input as a working ring (g->v, g->s: room for its vertices). */
static void input_ring(const struct seg_input *in, int r, struct xs_ring *g)
{
  int lo = in->ring_start[r], n = in->ring_start[r + 1] - lo;
  g->n = n;
  for (int k = 0; k < n; k++) {
    int i = lo + k, j = k + 1 < n ? i + 1 : lo;
    g->v[k] = orig_vertex(in, i);
    memset(&g->s[k], 0, sizeof g->s[k]);
    g->s[k].line = geom_line(in->pt[i], in->pt[j]);
    g->s[k].ea = in->vid[i];
    g->s[k].eb = in->vid[j];
  }
}

static int first_piece(struct seg_ctx *x, struct wpiece *p)
{
  const struct seg_input *in = x->in;
  p->id = x->next_id++;
  p->nring = in->nring;
  p->ring = pool_zget(x->scr, (size_t)in->nring * sizeof *p->ring);
  if (!p->ring) return oom(x);
  for (int r = 0; r < in->nring; r++) {
    int n = in->ring_start[r + 1] - in->ring_start[r];
    struct xs_ring *g = &p->ring[r];
    g->v = pool_get(x->scr, (size_t)n * sizeof *g->v);
    g->s = pool_get(x->scr, (size_t)n * sizeof *g->s);
    if (!g->v || !g->s) return oom(x);
    input_ring(in, r, g);
  }
  return T74_OK;
}

/* ---- the queue and the finished rings ------------------------------------------------ */

static int q_push(struct seg_ctx *x, struct wpiece *p)
{
  if (x->qn == x->qcap) {
    int cap = 2 * x->qcap;
    struct wpiece *nq = pool_get(x->scr, (size_t)cap * sizeof *nq);
    if (!nq) return oom(x);
    for (int i = 0; i < x->qn; i++) nq[i] = x->q[(x->qhead + i) % x->qcap];
    if (x->q != x->q0) pool_put(x->scr, x->q);
    x->q = nq;
    x->qhead = 0;
    x->qcap = cap;
  }
  x->q[(x->qhead + x->qn) % x->qcap] = *p;
  x->qn++;
  memset(p, 0, sizeof *p);
  return T74_OK;
}

static int fin_push(struct seg_ctx *x, struct xs_ring *r)
{
  if (x->nfin == x->fincap) {
    int cap = 2 * x->fincap;
    struct xs_ring *nf = pool_get(x->scr, (size_t)cap * sizeof *nf);
    if (!nf) return oom(x);
    memcpy(nf, x->fin, (size_t)x->nfin * sizeof *nf);
    if (x->fin != x->fin0) pool_put(x->scr, x->fin);
    x->fin = nf;
    x->fincap = cap;
  }
  x->fin[x->nfin++] = *r;
  memset(r, 0, sizeof *r);
  return T74_OK;
}

/* ---- core tables ---------------------------------------------------------------------- */

static int table(struct seg_ctx *x, const char *name, uint32_t words, uint32_t *addr)
{
  *addr = 0;
  if (!x->core || words == 0) return T74_OK;
  return core_alloc(x->core, name, words, addr, x->err);
}

/* One word of a table. A number wider than a word (an import's vertex id above 65535,
   docs/scale.md) is counted as one word and keeps its low 16 bits in the model: the
   tables are laid out as the 1974 program's; decisions never read them back. */
static void put_word(struct seg_ctx *x, uint32_t addr, uint32_t w)
{
  count_mem(x->cost, 1);
  if (x->core) core_write(x->core, addr, (uint16_t)w);
}

/* ---- point in a walked cycle (to place an untouched hole) ------------------------------ */

/* Where is the point (tn/td, yn/td) (td 1 or 2) for the closed cycle c: 1 inside, 0
   outside, -1 on its boundary. Crossing number with the half-open rule, exact. */
static int point_in_cycle(const struct cyc *c, wide tn, int64_t yn, int64_t td,
                          struct cost *cost)
{
  int inside = 0;
  for (int k = 0; k < c->n; k++) {
    const struct xs_vertex *p = &c->v[k], *q = &c->v[(k + 1) % c->n];
    count_xcmp(cost);
    wide py = (wide)p->y * td, qy = (wide)q->y * td;
    struct grat t = { tn, td };
    if (py == yn && geom_rat_cmp(p->x, t) == 0) return -1;
    if (py == qy) {                              /* horizontal: on it, or no crossing */
      if (py == yn) {
        int a = geom_rat_cmp(p->x, t), b = geom_rat_cmp(q->x, t);
        if (a * b < 0) return -1;
      }
      continue;
    }
    if ((py > yn) != (qy > yn)) {
      struct grat xs = geom_x_at(c->s[k].line, yn, td);
      int s = geom_rat_cmp(xs, t);
      if (s == 0) return -1;
      if (s > 0) inside = !inside;
    }
  }
  return inside;
}

/* Which of the cycles contains the (untouched) ring g: its index, or -1. */
static int place_ring(const struct xs_ring *g, const struct cyc *cy, int ncy, struct cost *cost)
{
  /* Try each vertex, then each edge midpoint (doubled coordinates), until one is not on
     any cycle's boundary: a hole may touch a piece boundary at a vertex. The ring's
     vertices are input grid points (an untouched ring was never cut). */
  for (int pass = 0; pass < 2; pass++) {
    for (int k = 0; k < g->n; k++) {
      const struct xs_vertex *p = &g->v[k], *q = &g->v[(k + 1) % g->n];
      wide tn;
      int64_t yn, td;
      if (pass == 0) { tn = p->x.num; yn = p->y; td = 1; }          /* the vertex */
      else { tn = p->x.num + q->x.num; yn = p->y + q->y; td = 2; }  /* the midpoint */
      int found = -1, boundary = 0;
      for (int i = 0; i < ncy && !boundary; i++) {
        int w = point_in_cycle(&cy[i], tn, yn, td, cost);
        if (w < 0) boundary = 1;
        else if (w > 0 && found < 0) found = i;
      }
      if (!boundary) return found;
    }
  }
  return -1;
}

/* ---- one cut ------------------------------------------------------------------------- */

struct halfcut {                          /* the crossings and pieces of one side of a cut */
  int m;                                  /* crossings */
  struct xsort_cross *x;
  int ncy;                                /* pieces walked */
  struct cyc *cy;
  int *holes;                             /* untouched ring r -> cycle index, or -1 */
  int *pair;                              /* crossing j -> the other end of its cut interval,
                                             as the rules of eq. (3) decide (rule_pairs) */
};

/* Number a crossing shows in IPL: the vertex's number at an endpoint, else its own. */
static uint32_t cross_num(const struct wpiece *P, uint32_t *const *mid, const struct xsort_cross *c)
{
  const struct xs_ring *g = &P->ring[c->ring];
  if (c->at == 1) return g->v[c->side].num;
  if (c->at == 2) return g->v[(c->side + 1) % g->n].num;
  return mid[c->ring][c->side];
}

/* The point of crossing c as a ring vertex; its homogeneous point (the output's) only
   when out. */
static struct xs_vertex cross_point(const struct wpiece *P, uint32_t *const *mid,
                                    const struct xsort_cross *c, gcoord y0, int out)
{
  const struct xs_ring *g = &P->ring[c->ring];
  if (c->at == 1) return g->v[c->side];
  if (c->at == 2) return g->v[(c->side + 1) % g->n];
  struct xs_vertex v;
  memset(&v, 0, sizeof v);
  v.kind = XS_CROSS;
  v.num = mid[c->ring][c->side];
  v.src = -1;
  v.y = y0;
  v.x = c->x;
  if (out && !geom_meet(g->s[c->side].line, geom_hline(y0, true), &v.p)) {
    /* never: a side crossing the line has one end strictly off it, so it is not
       horizontal; keep the exact point from x anyway */
    v.p.X = c->x.num; v.p.Y = (wide)y0 * c->x.den; v.p.W = c->x.den;
  }
  return v;
}

/* The crossings of one half, in x order, must alternate: below (enter, exit), above
   (exit, enter); otherwise the boundary is not simple. Returns T74_OK or an error. */
static int check_alternate(struct seg_ctx *x, gcoord c, int half, const struct halfcut *h)
{
  unsigned fid = x->in->face_id;
  int m = h->m;
  if (m % 2)
    return t74_fail(x->err, T74_EINPUT, "face %u: odd number of crossings at y = %lld "
                    "(boundary not simple?)", fid, (long long)c);
  for (int j = 0; j < m; j++) {
    int want_enter = half == XS_BELOW ? (j % 2 == 0) : (j % 2 == 1);
    count_branch(x->cost);
    if (h->x[j].enter != want_enter)
      return t74_fail(x->err, T74_EINPUT,
                      "face %u: crossings at y = %lld do not alternate (crossing %d of %d "
                      "on the %s side): the boundary is not simple", fid, (long long)c,
                      j + 1, m, half == XS_BELOW ? "lower" : "upper");
  }
  return T74_OK;
}

/* Walk the pieces of one half: leave a run of the ring at an exit crossing, go along the
   cut interval to the crossing h->pair names (decided by the rules of eq. (3)), follow
   that ring to its next exit, until back at the start. Returns T74_OK or an error. */
static int walk_half(struct seg_ctx *x, const struct wpiece *P, uint32_t *const *mid,
                     gcoord c, int half, struct halfcut *h, int *const *idx)
{
  unsigned fid = x->in->face_id;
  int m = h->m;
  for (int j = 0; j < m; j++) idx[h->x[j].ring][h->x[j].side] = j;

  char *seen = scr_zalloc(x->scr, (size_t)m + 1);
  h->cy = scr_zalloc(x->scr, ((size_t)m / 2 + 1) * sizeof *h->cy);
  if (!seen || !h->cy) return oom(x);
  int total = 0;
  for (int r = 0; r < P->nring; r++) total += P->ring[r].n;

  struct xs_side cutside;
  memset(&cutside, 0, sizeof cutside);
  cutside.line = geom_hline(c, half == XS_ABOVE);   /* the piece's bottom above, top below */
  cutside.cut = 1;

  int rc = T74_OK;
  for (int j0 = 0; j0 < m && rc == T74_OK; j0++) {
    if (h->x[j0].enter || seen[j0]) continue;
    struct cyc *cy = &h->cy[h->ncy++];
    int j = j0, steps = 0;
    do {
      seen[j] = 1;
      struct xs_vertex pe = cross_point(P, mid, &h->x[j], c, !x->check);
      if (cyc_push(x->scr, cy, &pe, &cutside)) { rc = oom(x); break; }
      int e = h->pair[j];                            /* the partner: an entry */
      if (e < 0 || e >= m || !h->x[e].enter) {
        rc = t74_fail(x->err, T74_EINPUT, "face %u: cannot close a piece at y = %lld "
                      "(boundary not simple?)", fid, (long long)c);
        break;
      }
      const struct xsort_cross *en = &h->x[e];
      const struct xs_ring *g = &P->ring[en->ring];
      struct xs_vertex pn = cross_point(P, mid, en, c, !x->check);
      if (cyc_push(x->scr, cy, &pn, &g->s[en->side])) { rc = oom(x); break; }
      count_mem(x->cost, 4);
      int k = (en->side + 1) % g->n;
      for (;;) {
        if (cyc_push(x->scr, cy, &g->v[k], &g->s[k])) { rc = oom(x); break; }
        count_mem(x->cost, 1);
        int k1 = (k + 1) % g->n;
        if (!xsort_in_half(g->v[k1].y, c, half)) break;
        k = k1;
        if (++steps > total + 2 * m) break;
      }
      if (rc) break;
      j = idx[en->ring][k];
      if (j < 0 || h->x[j].enter || ++steps > total + 2 * m) {
        rc = t74_fail(x->err, T74_EINPUT, "face %u: cannot close a piece at y = %lld "
                      "(boundary not simple?)", fid, (long long)c);
        break;
      }
    } while (j != j0);
    if (rc == T74_OK && cy->n > 1) {
      /* Start the piece at the entry point after its first cut interval, as the
         paper lists LWS pieces ("11 2 12"): rotate the first vertex to the end. */
      struct xs_vertex v0 = cy->v[0];
      struct xs_side s0 = cy->s[0];
      memmove(&cy->v[0], &cy->v[1], (size_t)(cy->n - 1) * sizeof cy->v[0]);
      memmove(&cy->s[0], &cy->s[1], (size_t)(cy->n - 1) * sizeof cy->s[0]);
      cy->v[cy->n - 1] = v0;
      cy->s[cy->n - 1] = s0;
    }
  }
  return rc;
}

/* Find the lowest concave vertex of P: returns 1 and *c when there is one. */
static int lowest_concave(struct seg_ctx *x, const struct wpiece *P, gcoord *c, int *nconc)
{
  x->stamp++;
  int any = 0;
  *nconc = 0;
  for (int r = 0; r < P->nring; r++) {
    const struct xs_ring *g = &P->ring[r];
    for (int k = 0; k < g->n; k++) {
      count_turn(x->cost);
      if (turn(g->s[(k + g->n - 1) % g->n].line, g->s[k].line) >= 0) continue;
      if (g->v[k].kind != XS_ORIG) {
        /* A crossing point lies on a cut and the piece is on one side of it: its
           angle is at most 180 degrees. Reaching here means the ring was not simple. */
        return -t74_fail(x->err, T74_EINPUT, "face %u: crossing point %u is concave "
                         "(boundary not simple?)", (unsigned)x->in->face_id,
                         (unsigned)g->v[k].num);
      }
      x->conc[g->v[k].src] = x->stamp;
      any = 1;
      (*nconc)++;
    }
  }
  if (!any) return 0;
  for (int i = 0; i < x->nvert; i++) {               /* YSORT from the bottom */
    count_mem(x->cost, YSORT_ROW_WORDS);
    count_branch(x->cost);
    if (x->conc[x->ys[i].index] == x->stamp) { *c = x->ys[i].y; return 1; }
  }
  return 0;
}

static void trace_cycle_list(FILE *f, const char *name, const struct halfcut *h,
                             const struct wpiece *P)
{
  fprintf(f, "%-6s ", name);
  if (h->ncy == 0) fputs("(none)", f);
  for (int i = 0; i < h->ncy; i++) {
    if (i) fputs(" ; ", f);
    for (int k = 0; k < h->cy[i].n; k++)
      fprintf(f, "%s%u", k ? " " : "", (unsigned)h->cy[i].v[k].num);
    for (int r = 0; r < P->nring; r++) {
      if (h->holes[r] != i) continue;
      const struct xs_ring *g = &P->ring[r];
      fputs(" *", f);
      for (int k = 0; k < g->n; k++) fprintf(f, " %u", (unsigned)g->v[k].num);
    }
  }
  fputc('\n', f);
}

static void trace_ipl(FILE *f, const char *label, const struct halfcut *h,
                      const struct wpiece *P, uint32_t *const *mid)
{
  fprintf(f, "%s:", label);
  if (h->m == 0) fputs(" (none)", f);
  for (int j = 0; j < h->m; j++)
    fprintf(f, "%s %u", j && j % 2 == 0 ? " |" : "", (unsigned)cross_num(P, mid, &h->x[j]));
}

/* ---- typed crossings (Fig. 4, Fig. 5) and the rule match of eq. (3) ------------------- */

/* One crossing point of the cut line: one entry of the paper's IPL. A middle crossing of
   a side, or a ring vertex on the line; a horizontal chain of sides along the line is two
   entries (its ends), typed alike. */
struct tcross {
  int ring, key;                          /* key: vertex index k, or -1 - side (middle) */
  uint32_t num;                           /* its number in PBS and IPL */
  char type;                              /* 'a'..'e' (Fig. 5), 't' (see below) */
  int nhalf;                              /* half-crossings it stands for: uses before deletion */
  int at[2][2];                           /* per half: indices into hc[s].x (or -1) */
  int partner;                            /* a chain's other end (IPL index), else -1 */
  int uses;                               /* tables only: times used by a piece so far */
};

static int tc_find(const struct tcross *tc, int n, int ring, int key)
{
  for (int i = 0; i < n; i++) if (tc[i].ring == ring && tc[i].key == key) return i;
  return -1;
}

static int tc_key(const struct wpiece *P, const struct xsort_cross *h)
{
  if (h->at == 1) return h->side;
  if (h->at == 2) return (h->side + 1) % P->ring[h->ring].n;
  return -1 - h->side;
}

/* The other end of the horizontal chain along y = c that starts at vertex k of ring g and
   runs against (dir -1) or with (dir +1) the ring's order. */
static int chain_end(const struct xs_ring *g, int k, int dir, gcoord c)
{
  for (int steps = 0; steps < g->n; steps++) {
    int k1 = (k + dir + g->n) % g->n;
    if (g->v[k1].y != c) return k;
    k = k1;
  }
  return k;
}

/* Does the boundary touching the line from half s at IPL entry e (its half-crossings
   j0, j1 in hc[s]) make a concave touch (the face on both sides of the touch, the outside
   wedge between its two sides) rather than a convex one? Decided from the ring alone,
   exactly: for a single vertex k by the turn at it (right: concave); for a chain of sides
   along the line by the direction it runs (the face is on its left): from below, running
   to +x (face above it) is concave; from above, running to -x (face below it). A chain of
   zero length falls back to the turn from the side arriving at it to the side leaving.
   1 concave, 0 convex, -1 undecidable (the boundary doubles back: not simple). */
static int touch_concave(const struct wpiece *P, const struct halfcut *hc, int s,
                         const struct tcross *e, int j0, int j1, struct cost *cost)
{
  const struct xs_ring *g = &P->ring[e->ring];
  const struct xsort_cross *h0 = &hc[s].x[j0], *h1 = &hc[s].x[j1];
  /* the side arriving at the touch (it leaves half s) and the side leaving it */
  const struct xsort_cross *in = h0->enter ? h1 : h0, *out = h0->enter ? h0 : h1;
  if (in->enter || !out->enter) return -1;
  int kin = (in->side + 1) % g->n, kout = out->side;   /* first and last vertex on the line */
  count_turn(cost);
  if (kin != kout) {
    count_xcmp(cost);
    int dir = geom_rat_cmp(g->v[kout].x, g->v[kin].x);
    if (dir != 0) return s == XS_BELOW ? dir > 0 : dir < 0;
  }
  int t = turn(g->s[in->side].line, g->s[out->side].line);
  if (t == 0) return -1;
  return t < 0;
}

/* Build IPL: the crossing points of both halves, merged in exact x order (on equal x,
   the lower half's first, each half in its own order), each typed. Types, decided from
   the half-crossings alone (integers and exact rationals only):
     a  the boundary passes down through the line (the left end of a piece below and of
        one above), b  it passes up (the right ends);
     c  a concave vertex (or horizontal chain) touching the line from below: the end of
        one interval below and the start of the next (rule (b));
     d  the same from above on the piece's outer ring (rule (b'));
     e  the same from above on a hole ring (rule (c): the hole is joined there);
     t  a convex vertex or chain touching the line: it closes a piece at a point or along
        a side and cuts nothing (the paper cuts only at concave vertices and names no type
        for it).
   "Touching, concave" is decided from the ring (touch_concave), not from any pairing of
   the half-crossings: the pairing is what the rules then make from the types.
   Returns the count (at most the half-crossings of both halves). */
static int type_crossings(const struct wpiece *P, uint32_t *const *mid, gcoord c,
                          const struct halfcut *hc, struct tcross *tc, struct cost *cost)
{
  int n = 0;
  int i[2] = { 0, 0 };
  while (i[0] < hc[0].m || i[1] < hc[1].m) {
    int s;
    if (i[0] >= hc[0].m) s = 1;
    else if (i[1] >= hc[1].m) s = 0;
    else s = geom_rat_cmp(hc[0].x[i[0]].x, hc[1].x[i[1]].x) <= 0 ? 0 : 1;
    count_xcmp(cost);
    const struct xsort_cross *h = &hc[s].x[i[s]];
    int key = tc_key(P, h), t = tc_find(tc, n, h->ring, key);
    if (t < 0) {
      t = n++;
      memset(&tc[t], 0, sizeof tc[t]);
      tc[t].ring = h->ring;
      tc[t].key = key;
      tc[t].num = cross_num(P, mid, h);
      tc[t].partner = -1;
      for (int a = 0; a < 2; a++) tc[t].at[a][0] = tc[t].at[a][1] = -1;
    }
    struct tcross *e = &tc[t];
    if (e->at[s][0] < 0) e->at[s][0] = i[s];
    else e->at[s][1] = i[s];
    e->nhalf++;
    i[s]++;
  }
  for (int t = 0; t < n; t++) {
    struct tcross *e = &tc[t];
    count_branch(cost);
    int nl = (e->at[0][0] >= 0) + (e->at[0][1] >= 0), nu = (e->at[1][0] >= 0) + (e->at[1][1] >= 0);
    if (nl == 1 && nu == 1) {                      /* through the line */
      e->type = hc[0].x[e->at[0][0]].enter ? 'a' : 'b';
      continue;
    }
    int s = nl ? 0 : 1;
    int j0 = e->at[s][0], j1 = e->at[s][1];
    if (j1 < 0 && e->key >= 0) {                    /* one end of a chain along the line */
      const struct xsort_cross *h = &hc[s].x[j0];
      const struct xs_ring *g = &P->ring[e->ring];
      int other = chain_end(g, e->key, h->at == 2 ? 1 : -1, c);
      int u = other == e->key ? -1 : tc_find(tc, n, e->ring, other);
      if (u >= 0 && tc[u].at[s][0] >= 0 && tc[u].at[s][1] < 0 && tc[u].at[1 - s][0] < 0) {
        j1 = tc[u].at[s][0];
        e->partner = u;
      } else if (u >= 0 && tc[u].at[1 - s][0] >= 0 && tc[u].at[1 - s][1] < 0 &&
                 tc[u].at[s][0] < 0) {
        /* the chain comes from one side and leaves to the other: through the line */
        const struct xsort_cross *lo = s == XS_BELOW ? h : &hc[XS_BELOW].x[tc[u].at[0][0]];
        e->type = lo->enter ? 'a' : 'b';
        e->partner = u;
        continue;
      }
    }
    if (j1 < 0) { e->type = '?'; continue; }       /* never for a simple boundary */
    int concave = touch_concave(P, hc, s, e, j0, j1, cost);
    if (concave < 0) { e->type = '?'; continue; }  /* never for a simple boundary */
    if (!concave) e->type = 't';
    else e->type = s == XS_BELOW ? 'c' : (e->ring == 0 ? 'd' : 'e');
  }
  return n;
}

/* The cut: which crossings of half s bound one cut interval (the side of a piece along
   the line), decided by matching the rules of eq. (3) on the typed IPL. Reading the
   half's crossing points from left to right, a piece's side along the line opens at
   the left end of a piece and closes at its right end:
     a, b   rule (a) XaAb -> aAb, abX: one crossing each; a opens (the boundary passes
            down: the left end of aAb below and of abX above), b closes (it passes up).
     c      rule (b) XaAcBb -> aAc, cBb: below, c closes the piece aAc and opens cBb
            (its arriving side first, then its leaving side);
     d, e   rules (b') and (c): above, d or e closes the interval ab of abX and opens
            the next one (dbY, or aeYebX: the walk then follows the hole ring from e,
            which is the join);
     t      a convex touch: it opens and closes a side of zero width (leaving side first
            below, arriving side first above).
   Ties where the paper is silent: several crossing points at one x are taken in the
   order of xsort_half (by the x an infinitesimal step into the half: the slopes of their
   sides); the two crossings of one point, when no other point's crossing lies between
   them in that order, are ordered by its type as above (when one does, the points are
   nested at one x and that order stands); a chain of
   sides along the line is two points (its ends), each one crossing. In h->pair each
   crossing gets the other end of its interval. Returns 0, or -1 when the openings and
   closings do not alternate (the boundary is not simple). */
static int rule_pairs(const struct tcross *tc, int ntc, struct halfcut *hc, int s,
                      struct seg_scratch *scr, struct cost *cost)
{
  struct halfcut *h = &hc[s];
  int m = h->m, rc = 0;
  int *tix = scr_alloc(scr, ((size_t)m + 1) * sizeof *tix);
  int *seq = scr_alloc(scr, ((size_t)m + 1) * sizeof *seq);
  char *done = scr_zalloc(scr, (size_t)ntc + 1);
  if (!tix || !seq || !done) return -2;
  for (int j = 0; j < m; j++) tix[j] = -1;
  for (int t = 0; t < ntc; t++)
    for (int a = 0; a < 2; a++) if (tc[t].at[s][a] >= 0) tix[tc[t].at[s][a]] = t;
  int n = 0;
  for (int j = 0; j < m; j++) {
    int t = tix[j];
    if (t < 0) { rc = -1; break; }
    if (done[t]) continue;
    int j0 = tc[t].at[s][0], j1 = tc[t].at[s][1];
    count_branch(cost);
    if (j1 < 0 || (j0 - j1 != 1 && j1 - j0 != 1)) {
      /* one crossing of this point, or several points at this x nested one inside the
         other (a hole touching the outer ring from inside its corner): x order decides */
      seq[n++] = j;
      continue;
    }
    done[t] = 1;
    /* a point touching the line: closing crossing first when concave (c, d, e: the end
       of one piece's side, then the start of the next), opening first when convex (t) */
    int open0 = s == XS_BELOW ? h->x[j0].enter : !h->x[j0].enter;
    int close_first = tc[t].type != 't';
    if (open0 == close_first) { int tmp = j0; j0 = j1; j1 = tmp; }
    seq[n++] = j0;
    seq[n++] = j1;
  }
  for (int i = 0; rc == 0 && i < n; i++) {
    const struct xsort_cross *q = &h->x[seq[i]];
    int opening = s == XS_BELOW ? q->enter : !q->enter;
    count_branch(cost);
    if (opening != (i % 2 == 0)) { rc = -1; break; }
    if (i % 2) { h->pair[seq[i]] = seq[i - 1]; h->pair[seq[i - 1]] = seq[i]; }
  }
  if (rc == 0 && n != m) rc = -1;
  return rc;
}

/* The rules of eq. (3) matched on the typed crossings, written to f: each c is an
   application of (b) XaAcBb -> aAc, cBb, abX; each d of (b') XaAbYd -> aAb, abX, dbY;
   the first e of a hole ring (in x order) of (c) XaAb*Ye -> aAb, aeYebX, and every
   further e of that ring, which after the join lies on the outer ring, of (b') as its d.
   Each application takes one lower piece aAb (two for (b)); the lower pieces left over
   are (a) XaAb -> aAb, abX. A chain along the line (two IPL entries) is one application.
   Returns the number of applications. */
static int trace_rules(FILE *f, const struct tcross *tc, int n, const struct halfcut *hc,
                       int nring)
{
  int apps = 0, groups = hc[XS_BELOW].m / 2;      /* lower pieces, then lower groups */
  char *joined = calloc((size_t)nring + 1, 1);
  for (int t = 0; t < n; t++) {
    const struct tcross *e = &tc[t];
    if (e->type != 'c' && e->type != 'd' && e->type != 'e') continue;
    if (e->partner >= 0 && e->partner < t) continue; /* a chain: named at its first end */
    if (e->type == 'c') { fputs(" (b)", f); groups--; }
    else if (e->type == 'e' && joined && !joined[e->ring]) { fputs(" (c)", f); joined[e->ring] = 1; }
    else fputs(" (b')", f);
    apps++;
  }
  for (int g = apps; g < groups; g++) { fputs(" (a)", f); }
  free(joined);
  return apps > groups ? apps : groups;
}

/* ---- the tables of Fig. 6, state by state ---------------------------------------------- */

/* PBS as the paper keeps it while pieces are taken: one word per vertex or crossing
   number, '*' between rings; an entry becomes 0 once used (a crossing number once it
   has been used as often as it has half-crossings: twice for a point, the paper's rule). */
struct pbs_entry {
  uint32_t num, now;                      /* number; now: the number, or 0 once deleted */
  int star;                               /* 1: the '*' between rings */
  int tc;                                 /* IPL index when a crossing number, else -1 */
  int inner;                              /* a vertex inside a chain of sides along the line */
};

struct fig6 {
  FILE *f;
  int npbs, ntc;
  struct pbs_entry *pbs;
  struct tcross *tc;
  uint32_t *ipl;                          /* IPL now: the number, or 0 once deleted */
};

static void f6_width_row(FILE *f, const char *name, const struct pbs_entry *e, int n,
                         int types, const struct tcross *tc)
{
  fprintf(f, "  %-5s", name);
  for (int i = 0; i < n; i++) {
    char num[12];
    snprintf(num, sizeof num, "%u", (unsigned)e[i].num);
    int w = (int)strlen(num);
    if (e[i].star) fputs(" *", f);
    else if (types) fprintf(f, " %*c", w, e[i].tc >= 0 ? tc[e[i].tc].type : ' ');
    else fprintf(f, " %*u", w, (unsigned)e[i].now);
  }
  fputc('\n', f);
}

static void f6_pbs(struct fig6 *g, int types)
{
  int zero = 1;
  for (int i = 0; i < g->npbs; i++) zero &= g->pbs[i].star || g->pbs[i].now == 0;
  if (zero && !types) { fprintf(g->f, "  %-5s All Zero\n", "PBS"); return; }
  f6_width_row(g->f, types ? "" : "PBS", g->pbs, g->npbs, types, g->tc);
}

static void f6_ipl(struct fig6 *g, int types)
{
  int zero = 1;
  for (int i = 0; i < g->ntc; i++) zero &= g->ipl[i] == 0;
  if (zero && !types) { fprintf(g->f, "  %-5s All Zero\n", "IPL"); return; }
  fprintf(g->f, "  %-5s", types ? "" : "IPL");
  for (int i = 0; i < g->ntc; i++) {
    char num[12];
    snprintf(num, sizeof num, "%u", (unsigned)g->tc[i].num);
    int w = (int)strlen(num);
    if (types) fprintf(g->f, " %*c", w, g->tc[i].type);
    else fprintf(g->f, " %*u", w, (unsigned)g->ipl[i]);
  }
  fputc('\n', g->f);
}

/* Position of number v in PBS as it was first written (the order the paper lists a
   piece in: from its vertex that comes first in PBS). */
static int f6_pos(const struct fig6 *g, uint32_t v)
{
  for (int i = 0; i < g->npbs; i++) if (!g->pbs[i].star && g->pbs[i].num == v) return i;
  return g->npbs;
}

/* Use one vertex of a piece: zero it in PBS, or count a use of a crossing number. */
static void f6_use(struct fig6 *g, uint32_t v)
{
  for (int t = 0; t < g->ntc; t++) {
    if (g->ipl[t] != v) continue;
    if (++g->tc[t].uses >= g->tc[t].nhalf) {
      g->ipl[t] = 0;
      for (int i = 0; i < g->npbs; i++) if (g->pbs[i].tc == t) g->pbs[i].now = 0;
    }
    return;
  }
  for (int i = 0; i < g->npbs; i++)
    if (!g->pbs[i].star && g->pbs[i].tc < 0 && g->pbs[i].now == v) { g->pbs[i].now = 0; return; }
}

/* One list of pieces (LWS or UPS) up to piece upto (exclusive), as the paper prints it:
   pieces separated by ',', each from its vertex first in PBS, a hole after '*'. */
static void f6_list(struct fig6 *g, const char *name, const struct halfcut *h, int upto,
                    const struct wpiece *P)
{
  fprintf(g->f, "  %-5s", name);
  for (int i = 0; i < upto; i++) {
    const struct cyc *cy = &h->cy[i];
    int k0 = 0;
    for (int k = 1; k < cy->n; k++) if (f6_pos(g, cy->v[k].num) < f6_pos(g, cy->v[k0].num)) k0 = k;
    fputs(i ? ", " : " ", g->f);
    for (int k = 0; k < cy->n; k++)
      fprintf(g->f, "%s%u", k ? " " : "", (unsigned)cy->v[(k0 + k) % cy->n].num);
    for (int r = 0; r < P->nring; r++) {
      if (h->holes[r] != i) continue;
      fputs(" *", g->f);
      for (int k = 0; k < P->ring[r].n; k++) fprintf(g->f, " %u", (unsigned)P->ring[r].v[k].num);
    }
  }
  if (upto == 0) fputs(" (none)", g->f);
  fputc('\n', g->f);
}

static void f6_take(struct fig6 *g, const struct halfcut *h, int i, const struct wpiece *P)
{
  const struct cyc *cy = &h->cy[i];
  for (int k = 0; k < cy->n; k++) f6_use(g, cy->v[k].num);
  for (int r = 0; r < P->nring; r++)
    if (h->holes[r] == i)
      for (int k = 0; k < P->ring[r].n; k++) f6_use(g, P->ring[r].v[k].num);
}

/* The states (a)-(d) of Fig. 6 for one cut: (a) PBS and IPL as written, with the type
   of every crossing under it; (b) after the lower pieces are taken (LWS); (c) after each
   upper piece but the last (UPS so far); (d) after the last. Vertices inside a chain of
   sides along the cut line belong to no piece and are zeroed with the lower pieces. */
static void trace_fig6(FILE *f, const struct wpiece *P, uint32_t *const *mid, gcoord c,
                       struct tcross *tc, int ntc, const struct halfcut *hc)
{
  struct fig6 g;
  memset(&g, 0, sizeof g);
  g.f = f;
  g.tc = tc;
  g.ntc = ntc;
  int total = 0;
  for (int r = 0; r < P->nring; r++) total += 2 * P->ring[r].n + 1;
  g.pbs = calloc((size_t)total, sizeof *g.pbs);
  g.ipl = calloc((size_t)ntc + 1, sizeof *g.ipl);
  if (!g.pbs || !g.ipl) { free(g.pbs); free(g.ipl); return; }
  for (int r = 0; r < P->nring; r++) {
    if (r) { g.pbs[g.npbs].star = 1; g.pbs[g.npbs++].tc = -1; }
    for (int k = 0; k < P->ring[r].n; k++) {
      struct pbs_entry *e = &g.pbs[g.npbs++];
      e->num = e->now = P->ring[r].v[k].num;
      e->tc = tc_find(tc, ntc, r, k);
      e->inner = e->tc < 0 && P->ring[r].v[k].y == c;
      if (mid[r][k]) {
        e = &g.pbs[g.npbs++];
        e->num = e->now = mid[r][k];
        e->tc = tc_find(tc, ntc, r, -1 - k);
      }
    }
  }
  for (int t = 0; t < ntc; t++) { g.ipl[t] = tc[t].num; tc[t].uses = 0; }
  fputs("Fig. 6 (a)\n", f);
  f6_pbs(&g, 0);
  f6_pbs(&g, 1);
  f6_ipl(&g, 0);
  f6_ipl(&g, 1);
  for (int i = 0; i < hc[XS_BELOW].ncy; i++) f6_take(&g, &hc[XS_BELOW], i, P);
  /* a vertex inside a chain of sides along the line is in no piece: the cut line takes
     the chain's place (the paper's example has none); it goes with the lower pieces */
  for (int i = 0; i < g.npbs; i++) if (g.pbs[i].inner) g.pbs[i].now = 0;
  fputs("Fig. 6 (b)\n", f);
  f6_pbs(&g, 0);
  f6_ipl(&g, 0);
  f6_list(&g, "LWS", &hc[XS_BELOW], hc[XS_BELOW].ncy, P);
  int nu = hc[XS_ABOVE].ncy;
  for (int i = 0; i < nu; i++) {
    f6_take(&g, &hc[XS_ABOVE], i, P);
    fprintf(f, "Fig. 6 (%c)\n", i + 1 < nu ? 'c' : 'd');
    f6_pbs(&g, 0);
    f6_ipl(&g, 0);
    f6_list(&g, "UPS", &hc[XS_ABOVE], i + 1, P);
    f6_list(&g, "LWS", &hc[XS_BELOW], hc[XS_BELOW].ncy, P);
  }
  free(g.pbs);
  free(g.ipl);
}

/* ---- crossing numbers ------------------------------------------------------------------
   Numbers above the face's largest vertex id first (11, 12, ... as Fig. 6), then, past
   the last number a word holds, wrapping onto 1, 2, ... skipping the numbers the face's
   vertices use. Until the wrap no vertex id can be met, so nothing is kept per face; at
   the wrap (rare: tens of thousands of crossings in one face) the face's ids are sorted
   once, and a cursor walks them as the numbers grow again. */

static int cmp_u32(const void *a, const void *b)
{
  uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
  return (x > y) - (x < y);
}

/* The numbers run past num_end - 1: start again from 0 (never given: 0 is "deleted"). */
static void wrap_numbers(struct seg_ctx *x)
{
  x->next_num = 0;
  x->idcur = 0;
}

/* 1 when next_num cannot be given (0, PBS's '*', a vertex id of the face), 0 when it can,
   -1 out of memory. */
static int next_used(struct seg_ctx *x)
{
  uint32_t v = x->next_num;
  if (v == 0 || v == PBS_STAR) return 1;
  if (v > x->maxid) return 0;                   /* above every id: before the wrap */
  if (!x->ids) {
    x->ids = malloc((size_t)x->nvert * sizeof *x->ids);
    if (!x->ids) return -1;
    for (int i = 0; i < x->nvert; i++) x->ids[i] = x->in->vid[i];
    qsort(x->ids, (size_t)x->nvert, sizeof *x->ids, cmp_u32);
    int n = 0;
    for (int i = 0; i < x->nvert; i++) if (!n || x->ids[i] != x->ids[n - 1]) x->ids[n++] = x->ids[i];
    x->nids = n;
    x->idcur = 0;
  }
  while (x->idcur < x->nids && x->ids[x->idcur] < v) x->idcur++;
  return x->idcur < x->nids && x->ids[x->idcur] == v;
}

/* Cut piece P at y = c; its pieces go to the queue. P is consumed. */
static int cut_piece(struct seg_ctx *x, struct wpiece *P, gcoord c)
{
  int rc = T74_OK;
  int total = 0;
  for (int r = 0; r < P->nring; r++) total += P->ring[r].n;
  x->ncut++;

  struct scr_mark mark = scr_mark(x->scr);
  uint32_t **mid = scr_zalloc(x->scr, (size_t)P->nring * sizeof *mid);
  int **idx = scr_zalloc(x->scr, (size_t)P->nring * sizeof *idx);
  struct xsort_row *rows = x->check ? NULL : scr_alloc(x->scr, (size_t)(2 * total) * sizeof *rows);
  struct halfcut hc[2];
  struct tcross *tc = NULL;
  memset(hc, 0, sizeof hc);
  for (int s = 0; s < 2; s++) {
    hc[s].x = scr_alloc(x->scr, (size_t)(2 * total) * sizeof *hc[s].x);
    hc[s].holes = scr_alloc(x->scr, (size_t)P->nring * sizeof *hc[s].holes);
  }
  if (!mid || !idx || (!rows && !x->check) || !hc[0].x || !hc[1].x || !hc[0].holes ||
      !hc[1].holes) {
    rc = oom(x);
    goto done;
  }
  for (int r = 0; r < P->nring; r++) {
    mid[r] = scr_zalloc(x->scr, (size_t)P->ring[r].n * sizeof *mid[r]);
    idx[r] = scr_alloc(x->scr, (size_t)P->ring[r].n * sizeof *idx[r]);
    if (!mid[r] || !idx[r]) { rc = oom(x); goto done; }
  }

  /* XSORT for the line: seg_check only takes its room in core (its rows are written,
     never read back). */
  int nx = x->check ? xsort_rows(P->ring, P->nring, c)
                    : xsort_build(P->ring, P->nring, c, rows, rows + total, x->cost);
  uint32_t a;
  if ((rc = table(x, CORE_T_XSORT, (uint32_t)nx * XSORT_ROW_WORDS, &a))) goto done;
  for (int i = 0; i < nx && x->core && !x->check; i++) {
    const struct xs_side *sd = &P->ring[rows[i].ring].s[rows[i].side];
    uint32_t w = a + (uint32_t)i * XSORT_ROW_WORDS;
    core_put_int(x->core, w, 4, (int64_t)rows[i].x.num);
    core_put_int(x->core, w + 4, 2, (int64_t)rows[i].x.den);
    core_write(x->core, w + 6, (uint16_t)sd->ea);   /* ids above 65535: low word (put_word) */
    core_write(x->core, w + 7, (uint16_t)sd->eb);
    core_write(x->core, w + 8, rows[i].code);
  }

  /* Number the crossing points through the middle of a side, in ring order (PBS). */
  uint32_t npbs = 0;
  for (int r = 0; r < P->nring; r++) {
    const struct xs_ring *g = &P->ring[r];
    for (int k = 0; k < g->n; k++) {
      gcoord y0 = g->v[k].y, y1 = g->v[(k + 1) % g->n].y;
      npbs++;
      if ((y0 < c && y1 > c) || (y0 > c && y1 < c)) {
        /* numbers above the face's largest vertex id first (11, 12, ... as Fig. 6), then
           wrapping onto numbers no vertex of the face uses: one word a number, 0xFFFF
           being PBS's '*' */
        int u;
        while ((u = next_used(x)) != 0) {
          if (u < 0) { rc = oom(x); goto done; }
          if (x->numbered >= x->num_end - 1) {
            rc = t74_fail(x->err, T74_EINPUT, "face %u: more crossing points than a "
                          "%s number can tell apart", (unsigned)x->in->face_id,
                          x->num_end == PBS_STAR ? "16-bit" : "32-bit");
            goto done;
          }
          x->next_num++;
          if (x->next_num > x->num_end) wrap_numbers(x);
        }
        mid[r][k] = x->next_num++;
        if (x->next_num > x->num_end) wrap_numbers(x);
        x->numbered++;
        npbs++;
      }
    }
  }
  npbs += (uint32_t)P->nring - 1;
  if ((rc = table(x, CORE_T_PBS, npbs, &a))) goto done;
  if (!x->check) {
    uint32_t w = a;
    for (int r = 0; r < P->nring; r++) {
      if (r) put_word(x, w++, PBS_STAR);
      for (int k = 0; k < P->ring[r].n; k++) {
        put_word(x, w++, P->ring[r].v[k].num);
        if (mid[r][k]) put_word(x, w++, mid[r][k]);
      }
    }
  }

  /* The two halves' crossings in x order; IPL with each crossing point typed (Fig. 4,
     5); the cut intervals decided by the rules of eq. (3) on the types; the walk. */
  for (int s = 0; s < 2; s++) {
    hc[s].m = xsort_half(P->ring, P->nring, c, s, hc[s].x, hc[s].x + total, x->cost);
    if ((rc = check_alternate(x, c, s, &hc[s]))) goto done;
  }
  tc = scr_alloc(x->scr, (size_t)(hc[0].m + hc[1].m + 1) * sizeof *tc);
  if (!tc) { rc = oom(x); goto done; }
  int ntc = type_crossings(P, mid, c, hc, tc, x->cost);
  for (int t = 0; t < ntc; t++)
    if (tc[t].type == '?') {
      rc = t74_fail(x->err, T74_EINPUT, "face %u: crossing %u at y = %lld has no type "
                    "(boundary not simple?)", (unsigned)x->in->face_id, (unsigned)tc[t].num,
                    (long long)c);
      goto done;
    }
  for (int s = 0; s < 2; s++) {
    hc[s].pair = scr_alloc(x->scr, ((size_t)hc[s].m + 1) * sizeof *hc[s].pair);
    if (!hc[s].pair) { rc = oom(x); goto done; }
    for (int j = 0; j < hc[s].m; j++) hc[s].pair[j] = -1;
    int pr = rule_pairs(tc, ntc, hc, s, x->scr, x->cost);
    if (pr == -2) { rc = oom(x); goto done; }
    if (pr < 0) {
      rc = t74_fail(x->err, T74_EINPUT, "face %u: the typed crossings at y = %lld match no "
                    "rule of eq. (3) (boundary not simple?)", (unsigned)x->in->face_id,
                    (long long)c);
      goto done;
    }
    /* The check that keeps every picture as it was: the intervals the rules make are
       the neighbours (1,2), (3,4), ... of the x order with the slope tie rule, the
       pairing tube74 cut with before; a face where they differ is refused, not cut
       differently (none of the test suite's faces or shipped scenes does). */
    for (int j = 0; j < hc[s].m; j++)
      if (hc[s].pair[j] != (j ^ 1)) {
        rc = t74_fail(x->err, T74_EINPUT, "face %u: at y = %lld the rules of eq. (3) join "
                      "crossing %d of the %s side to %d, the slope order to %d (a tie the "
                      "rules do not settle)", (unsigned)x->in->face_id, (long long)c, j + 1,
                      s == XS_BELOW ? "lower" : "upper", hc[s].pair[j] + 1, (j ^ 1) + 1);
        goto done;
      }
  }
  for (int s = 0; s < 2; s++) {
    for (int r = 0; r < P->nring; r++)
      for (int k = 0; k < P->ring[r].n; k++) idx[r][k] = -1;
    if ((rc = walk_half(x, P, mid, c, s, &hc[s], idx))) goto done;
  }
  if ((rc = table(x, CORE_T_IPL, (uint32_t)(hc[0].m + hc[1].m), &a))) goto done;
  for (int s = 0, w = 0; s < 2 && !x->check; s++)
    for (int j = 0; j < hc[s].m; j++)
      put_word(x, a + (uint32_t)w++, cross_num(P, mid, &hc[s].x[j]));

  /* Rings without crossings go, as holes, to the piece of their side containing them. */

  for (int r = 0; r < P->nring; r++) {
    hc[0].holes[r] = hc[1].holes[r] = -1;
    int touched = 0;
    for (int s = 0; s < 2; s++)
      for (int j = 0; j < hc[s].m; j++) touched |= hc[s].x[j].ring == r;
    if (touched) continue;
    int s = P->ring[r].v[0].y > c ? XS_ABOVE : XS_BELOW;
    int i = r > 0 ? place_ring(&P->ring[r], hc[s].cy, hc[s].ncy, x->cost) : -1;
    if (i < 0) {
      rc = t74_fail(x->err, T74_EINPUT, "face %u: ring %d lies in no piece at y = %lld "
                    "(rings not nested?)", (unsigned)x->in->face_id, r, (long long)c);
      goto done;
    }
    hc[s].holes[r] = i;
  }

  /* LWS and UPS. */
  for (int s = 0; s < 2; s++) {
    uint32_t words = 0;
    for (int i = 0; i < hc[s].ncy; i++) {
      words += (uint32_t)hc[s].cy[i].n + 1;
      for (int r = 0; r < P->nring; r++)
        if (hc[s].holes[r] == i) words += (uint32_t)P->ring[r].n + 1;
    }
    if ((rc = table(x, s == XS_BELOW ? CORE_T_LWS : CORE_T_UPS, words, &a))) goto done;
    uint32_t w = a;
    for (int i = 0; i < hc[s].ncy && !x->check; i++) {
      for (int k = 0; k < hc[s].cy[i].n; k++) put_word(x, w++, hc[s].cy[i].v[k].num);
      for (int r = 0; r < P->nring; r++) {
        if (hc[s].holes[r] != i) continue;
        put_word(x, w++, PBS_STAR);
        for (int k = 0; k < P->ring[r].n; k++) put_word(x, w++, P->ring[r].v[k].num);
      }
      put_word(x, w++, PBS_STAR);
    }
  }

  if (x->trace) {
    FILE *f = x->trace;
    int nl = hc[XS_BELOW].ncy, nu = hc[XS_ABOVE].ncy;
    fprintf(f, "cut %d at y = %lld in part %d (through concave vertex", x->ncut,
            (long long)c, P->id);
    int cnt = 0;
    for (int r = 0; r < P->nring; r++) {
      const struct xs_ring *g = &P->ring[r];
      for (int k = 0; k < g->n; k++)
        if (g->v[k].kind == XS_ORIG && g->v[k].y == c && x->conc[g->v[k].src] == x->stamp)
          fprintf(f, "%s v%u", cnt++ ? "," : "", (unsigned)g->v[k].num);
    }
    fputs("): rule", f);
    trace_rules(f, tc, ntc, hc, P->nring);
    fprintf(f, "; %d below, %d above\n", nl, nu);
    fputs("XSORT ", f);
    for (int i = 0; i < nx; i++) {
      const struct xs_side *sd = &P->ring[rows[i].ring].s[rows[i].side];
      fputs(i ? " | x=" : " x=", f);
      put_rat(f, rows[i].x);
      if (sd->cut) fputs(" cut", f);
      else fprintf(f, " edge v%u-v%u", (unsigned)sd->ea, (unsigned)sd->eb);
      fprintf(f, " %s", xsort_code_name(rows[i].code));
      const struct xs_ring *g = &P->ring[rows[i].ring];
      int k = rows[i].side, k1 = (k + 1) % g->n, t = -1;
      if (rows[i].code == XS_MIDDLE) t = tc_find(tc, ntc, rows[i].ring, -1 - k);
      else {
        if (g->v[k].y == c) t = tc_find(tc, ntc, rows[i].ring, k);
        if (t < 0 && g->v[k1].y == c) t = tc_find(tc, ntc, rows[i].ring, k1);
      }
      fprintf(f, " (%c)", t >= 0 ? tc[t].type : '-');
    }
    fputs("\nPBS   ", f);
    for (int r = 0; r < P->nring; r++) {
      if (r) fputs(" *", f);
      for (int k = 0; k < P->ring[r].n; k++) {
        fprintf(f, " %u", (unsigned)P->ring[r].v[k].num);
        if (mid[r][k]) fprintf(f, " %u", (unsigned)mid[r][k]);
      }
    }
    fputs("\nIPL    ", f);
    trace_ipl(f, "below", &hc[XS_BELOW], P, mid);
    fputc('\n', f);
    fputs("       ", f);
    trace_ipl(f, "above", &hc[XS_ABOVE], P, mid);
    fputc('\n', f);
    trace_cycle_list(f, "LWS", &hc[XS_BELOW], P);
    trace_cycle_list(f, "UPS", &hc[XS_ABOVE], P);
    trace_fig6(f, P, mid, c, tc, ntc, hc);
  }

  /* The new pieces, lower ones first, go to the queue. */
  for (int s = 0; s < 2 && rc == T74_OK; s++) {
    for (int i = 0; i < hc[s].ncy && rc == T74_OK; i++) {
      struct wpiece np;
      memset(&np, 0, sizeof np);
      np.id = x->next_id++;
      int nr = 1;
      for (int r = 0; r < P->nring; r++) nr += hc[s].holes[r] == i;
      np.ring = pool_zget(x->scr, (size_t)nr * sizeof *np.ring);
      if (!np.ring) { rc = oom(x); break; }
      np.nring = nr;
      struct cyc *cy = &hc[s].cy[i];
      np.ring[0].n = cy->n;
      np.ring[0].v = cy->v;
      np.ring[0].s = cy->s;
      memset(cy, 0, sizeof *cy);
      for (int r = 0, t = 1; r < P->nring; r++) {
        if (hc[s].holes[r] != i) continue;
        np.ring[t++] = P->ring[r];                 /* moved, not copied */
        memset(&P->ring[r], 0, sizeof P->ring[r]);
      }
      rc = q_push(x, &np);
      if (rc) wpiece_free(x->scr, &np);
    }
  }

done:
  for (int s = 0; s < 2; s++)
    for (int i = 0; i < hc[s].ncy; i++) cyc_free(x->scr, &hc[s].cy[i]);
  scr_release(x->scr, mark);
  wpiece_free(x->scr, P);
  return rc;
}

/* ---- output --------------------------------------------------------------------------- */

/* Remove vertex i and the side leaving it. */
static void ring_remove(struct xs_ring *g, int i)
{
  memmove(&g->v[i], &g->v[i + 1], (size_t)(g->n - i - 1) * sizeof g->v[0]);
  memmove(&g->s[i], &g->s[i + 1], (size_t)(g->n - i - 1) * sizeof g->s[0]);
  g->n--;
}

/* A ring whose sides each turn left into the next goes round once when its sides'
   directions (b, -a), in angular order, wrap around once (else it is a star): whether the
   order wraps from side l1 to the next, l2; and the refusal of a ring that wrapped
   `wraps` times. */
static int wraps_from(struct gline l1, struct gline l2)
{
  int h1 = -l1.a > 0 || (l1.a == 0 && l1.b > 0), h2 = -l2.a > 0 || (l2.a == 0 && l2.b > 0);
  return h1 == 0 && h2 == 1;                    /* from the lower half back to the upper */
}

static int winds_once(struct seg_ctx *x, int wraps)
{
  if (wraps != 1)
    return t74_fail(x->err, T74_EINPUT, "face %u: piece winds %d times (boundary not simple?)",
                    (unsigned)x->in->face_id, wraps);
  return T74_OK;
}

/* Drop zero-length sides and vertices between two sides on one line; check the ring is
   strictly convex and turns once. */
static int tidy_ring(struct seg_ctx *x, struct xs_ring *g)
{
  unsigned fid = x->in->face_id;
  int changed = 1;
  uint64_t xcmps = 0, turns = 0;         /* the compares made, charged once */
  while (changed && g->n >= 3) {
    changed = 0;
    for (int k = 0; k < g->n && g->n >= 3; k++) {
      int k1 = (k + 1) % g->n;
      xcmps++;
      if (same_point(&g->v[k], &g->v[k1])) {
        /* Side k has zero length: side k takes over side k1's line, vertex k1 goes. */
        g->s[k] = g->s[k1];
        ring_remove(g, k1);
        changed = 1;
        break;
      }
      turns++;
      if (same_line(g->s[k].line, g->s[k1].line)) {
        /* Vertex k1 lies inside one line: side k runs on over it, vertex k1 goes. */
        ring_remove(g, k1);
        changed = 1;
        break;
      }
    }
  }
  count_xcmps(x->cost, xcmps);
  count_turns(x->cost, turns);
  if (g->n < 3)
    return t74_fail(x->err, T74_EINPUT, "face %u: a piece degenerated to %d sides "
                    "(boundary not simple?)", fid, g->n);
  int wraps = 0;
  for (int k = 0; k < g->n; k++) {
    struct gline l1 = g->s[k].line, l2 = g->s[(k + 1) % g->n].line;
    if (turn(l1, l2) <= 0)
      return t74_fail(x->err, T74_EINPUT, "face %u: piece not convex at vertex %u "
                      "(boundary not simple?)", fid, (unsigned)g->v[(k + 1) % g->n].num);
    wraps += wraps_from(l1, l2);
  }
  return winds_once(x, wraps);
}

/* tidy_ring, then the output piece. */
static int finish_ring(struct seg_ctx *x, struct xs_ring *g, struct seg_piece *out)
{
  int rc = tidy_ring(x, g);
  if (rc) return rc;
  out->n = g->n;
  out->line = malloc((size_t)g->n * sizeof *out->line);
  out->v = malloc((size_t)g->n * sizeof *out->v);
  if (!out->line || !out->v) {
    free(out->line);
    free(out->v);
    out->line = NULL;
    out->v = NULL;
    return oom(x);
  }
  for (int k = 0; k < g->n; k++) {
    out->line[k] = g->s[k].line;
    out->v[k].kind = g->v[k].kind == XS_ORIG ? SEGV_ORIG : SEGV_CROSS;
    out->v[k].num = g->v[k].num;
    out->v[k].p = g->v[k].p;
  }
  return T74_OK;
}

/* ---- the entry point ------------------------------------------------------------------ */

static void ctx_free(struct seg_ctx *x)
{
  free(x->ids);
  while (x->qn) {
    wpiece_free(x->scr, &x->q[x->qhead]);
    x->qhead = (x->qhead + 1) % x->qcap;
    x->qn--;
  }
  if (x->q != x->q0) pool_put(x->scr, x->q);
  for (int i = 0; i < x->nfin; i++) ring_free(x->scr, &x->fin[i]);
  if (x->fin != x->fin0) pool_put(x->scr, x->fin);
}

static void ctx_init(struct seg_ctx *x, const struct seg_input *in, FILE *trace,
                     struct core *core, struct cost *cost, struct t74_error *err)
{
  memset(x, 0, sizeof *x);
  x->scr = NULL;
  x->in = in;
  x->trace = trace;
  x->core = core;
  x->cost = cost;
  x->err = err;
  x->next_id = 1;
  x->q = x->q0;
  x->qcap = SEG_INLINE;
  x->fin = x->fin0;
  x->fincap = SEG_INLINE;
}

/* YSORT into core: the table of the face's ys[0..nvert) rows. */
static int ysort_table(struct seg_ctx *x, const struct ysort_row *ys)
{
  uint32_t a = 0;
  uint32_t words = (uint32_t)x->nvert * YSORT_ROW_WORDS;
  int rc = x->ysort && x->core && words ? core_alloc_named(x->core, x->ysort, words, &a, x->err)
                                        : table(x, CORE_T_YSORT, words, &a);
  if (rc != T74_OK || !x->core || x->check) return rc;
  /* the rows as core_put_int (y, two words, the high one first) and core_write (the
     vertex) make them, SEG_CONVEX_MAX rows at a time in one write (issue 19) */
  uint16_t w[3 * SEG_CONVEX_MAX];
  for (int i0 = 0; i0 < x->nvert; i0 += SEG_CONVEX_MAX) {
    int m = x->nvert - i0 < SEG_CONVEX_MAX ? x->nvert - i0 : SEG_CONVEX_MAX;
    for (int i = 0; i < m; i++) {
      uint64_t u = (uint64_t)(int64_t)ys[i0 + i].y;
      w[3 * i] = (uint16_t)(u >> 16);
      w[3 * i + 1] = (uint16_t)u;
      w[3 * i + 2] = (uint16_t)ys[i0 + i].vid;
    }
    core_write_n(x->core, a + 3 * (uint32_t)i0, w, 3 * (uint32_t)m);
  }
  return rc;
}

/* The fast path (issue 19): a face of one ring that turns nowhere to the right is its own
   one piece. What seg_generate does for it, in its order: YSORT built and put in core,
   the turn at every vertex charged as the look for the lowest concave vertex is, the
   ring tidied and checked as a finished piece, the core released; without the queue, the
   working pieces and their host allocations. */
int seg_convex(const struct seg_input *in, struct core_name *ysort, struct gline *line, int *n,
               FILE *trace, struct core *core, struct cost *cost, struct t74_error *err)
{
  *n = 0;
  if (trace || in->nring != 1 || !in->ring_start || in->ring_start[0] != 0) return T74_OK;
  int nv = in->ring_start[1];
  if (nv < 3 || nv > SEG_CONVEX_MAX) return T74_OK;
  /* A face check_input refuses is left to seg_generate, which refuses it. Its tests, made
     here with the turns (issue 19: a face's vertices looked at once, not twice): a vertex
     outside the grid, two consecutive ones at one point, and, for a ring that turns
     left or straight at every vertex (another is declined as concave anyway), a
     boundary doubling back and a ring not counter-clockwise. check_input's orientation
     of vertices p, q, s is the turn from side p q to side q s (the same difference of
     products: geom_line's a = -dy, b = dx), and its doubling back, where that is 0,
     (q - p).(s - q) < 0, the two sides' a a' + b b'. */
  const struct gpoint *pt = in->pt;
  if (!pt || !in->vid) return T74_OK;
  for (int k = 0; k < nv; k++) {
    struct gpoint p = pt[k], q = pt[k + 1 < nv ? k + 1 : 0];
    if (off_grid(p) || (p.x == q.x && p.y == q.y)) return T74_OK;
  }
  struct gline ln[SEG_CONVEX_MAX];      /* side k: from vertex k to k + 1 */
  for (int k = 0; k < nv; k++) ln[k] = geom_line(pt[k], pt[k + 1 < nv ? k + 1 : 0]);
  bool strict = true;                   /* every vertex a strict left turn */
  wide area2 = 0;                       /* twice the ring's signed area */
  for (int k = 0, k0 = nv - 1; k < nv; k0 = k++) {
    int t = turn(ln[k0], ln[k]);
    if (t < 0) return T74_OK;           /* concave */
    if (t == 0 && (wide)ln[k0].a * ln[k].a + (wide)ln[k0].b * ln[k].b < 0)
      return T74_OK;                    /* doubling back */
    strict &= t > 0;
    area2 += (wide)pt[k0].x * pt[k].y - (wide)pt[k].x * pt[k0].y;
  }
  if (area2 <= 0) return T74_OK;        /* clockwise */
  struct seg_ctx xc;
  struct seg_ctx *x = &xc;
  ctx_init(x, in, NULL, core, cost, err);
  x->ysort = ysort;

  x->nvert = nv;
  uint32_t mark = core ? core_mark(core) : 0;
  struct ysort_row ys[2 * SEG_CONVEX_MAX];
  ysort_build(in->pt, in->vid, nv, ys, ys + nv, cost);
  int rc = ysort_table(x, ys);
  if (rc == T74_OK) {
    count_turns(cost, (uint64_t)nv);                   /* lowest_concave: none */
    if (strict) {
      /* tidy_ring as it goes on such a ring: no two vertices coincide (check_input), no
         two sides run on one line (they turn), so one pass drops nothing, a compare and a
         turn a vertex; and each turn is left. The piece's sides are the ring's. */
      count_xcmps(cost, (uint64_t)nv);
      count_turns(cost, (uint64_t)nv);
      int wraps = 0;
      for (int k = 0; k < nv; k++) wraps += wraps_from(ln[k], ln[k + 1 < nv ? k + 1 : 0]);
      rc = winds_once(x, wraps);
      if (rc == T74_OK) {
        memcpy(line, ln, (size_t)nv * sizeof *line);
        *n = nv;
      }
    } else {                            /* a vertex inside a side: tidy_ring drops it */
      struct xs_vertex v[SEG_CONVEX_MAX];
      struct xs_side sd[SEG_CONVEX_MAX];
      struct xs_ring g = { 0, v, sd };
      input_ring(in, 0, &g);
      rc = tidy_ring(x, &g);
      if (rc == T74_OK) {
        for (int k = 0; k < g.n; k++) line[k] = g.s[k].line;
        *n = g.n;
      }
    }
  }
  if (core) core_release(core, mark);
  return rc;
}

/* seg_generate's work on the context x (x->check: seg_check's, out unused). */
static int generate(struct seg_ctx *x, struct seg_result *out)
{
  const struct seg_input *in = x->in;
  FILE *trace = x->trace;
  struct cost *cost = x->cost;
  struct t74_error *err = x->err;
  int rc = check_input(x);
  if (rc) return rc;
  uint32_t mark = x->core ? core_mark(x->core) : 0;
  struct scr_mark smark = scr_mark(x->scr);

  x->nvert = in->ring_start[in->nring];
  uint32_t maxid = 10;
  for (int i = 0; i < x->nvert; i++) if (in->vid[i] > maxid) maxid = in->vid[i];
  x->maxid = maxid;
  x->num_end = maxid <= 0xFFFFu ? PBS_STAR : UINT32_MAX;
  x->next_num = maxid + 1;
  if (x->next_num > x->num_end) wrap_numbers(x);

  /* YSORT */
  x->ys = scr_alloc(x->scr, (size_t)x->nvert * 2 * sizeof *x->ys);
  x->conc = scr_zalloc(x->scr, (size_t)x->nvert * sizeof *x->conc);
  if (!x->ys || !x->conc) { rc = oom(x); goto fail; }
  ysort_build(in->pt, in->vid, x->nvert, x->ys, x->ys + x->nvert, cost);
  if ((rc = ysort_table(x, x->ys))) goto fail;

  struct wpiece P;
  memset(&P, 0, sizeof P);
  if ((rc = first_piece(x, &P))) { wpiece_free(x->scr, &P); goto fail; }
  if (trace) {
    int nconc;
    x->cost = NULL;                       /* the trace's own look is not the machine's work */
    rc = lowest_concave(x, &P, &(gcoord){0}, &nconc);
    x->cost = cost;
    if (rc < 0) { wpiece_free(x->scr, &P); rc = -rc; goto fail; }
    fprintf(trace, "face %u: %d ring%s, %d vertices, %d concave vertices\nYSORT  y:",
            (unsigned)in->face_id, in->nring, in->nring == 1 ? "" : "s", x->nvert, nconc);
    for (int i = 0; i < x->nvert; i++)
      fprintf(trace, " %lld (v%u)", (long long)x->ys[i].y, (unsigned)x->ys[i].vid);
    fputc('\n', trace);
  }
  if ((rc = q_push(x, &P))) { wpiece_free(x->scr, &P); goto fail; }

  while (x->qn) {
    struct wpiece cur = x->q[x->qhead];
    x->qhead = (x->qhead + 1) % x->qcap;
    x->qn--;
    gcoord c = 0;
    int nconc;
    int has = lowest_concave(x, &cur, &c, &nconc);
    if (has < 0) { wpiece_free(x->scr, &cur); rc = -has; goto fail; }
    if (!has) {
      if (cur.nring != 1) {
        wpiece_free(x->scr, &cur);
        rc = t74_fail(err, T74_EINPUT, "face %u: a piece with a hole has no concave vertex "
                      "(rings not simple?)", (unsigned)in->face_id);
        goto fail;
      }
      rc = fin_push(x, &cur.ring[0]);
      wpiece_free(x->scr, &cur);
      if (rc) goto fail;
      continue;
    }
    if (x->ncut > 4 * x->nvert + 16) {
      wpiece_free(x->scr, &cur);
      rc = t74_fail(err, T74_EINPUT, "face %u: too many cuts (boundary not simple?)",
                    (unsigned)in->face_id);
      goto fail;
    }
    if ((rc = cut_piece(x, &cur, c))) goto fail;
  }

  if (x->check) {                          /* the convex pieces, checked as they would be */
    for (int i = 0; i < x->nfin; i++)
      if ((rc = tidy_ring(x, &x->fin[i]))) goto fail;
    goto done;
  }

  /* The convex pieces. */
  struct seg_result res;
  memset(&res, 0, sizeof res);
  res.piece = calloc((size_t)x->nfin + 1, sizeof *res.piece);
  if (!res.piece) { rc = oom(x); goto fail; }
  res.ncut = x->ncut;
  for (int i = 0; i < x->nfin; i++) {
    if ((rc = finish_ring(x, &x->fin[i], &res.piece[i]))) { seg_result_free(&res); goto fail; }
    res.npiece++;
  }
  if (trace) {
    fprintf(trace, "face %u: %d convex piece%s after %d cut%s\n", (unsigned)in->face_id,
            res.npiece, res.npiece == 1 ? "" : "s", res.ncut, res.ncut == 1 ? "" : "s");
    for (int i = 0; i < res.npiece; i++) {
      fprintf(trace, "  piece %d:", (in->first_piece > 0 ? in->first_piece : 1) + i);
      for (int k = 0; k < res.piece[i].n; k++)
        fprintf(trace, " %u", (unsigned)res.piece[i].v[k].num);
      fputc('\n', trace);
    }
  }
  *out = res;
  goto done;

fail:
  if (!rc) rc = T74_EINPUT;
done:
  ctx_free(x);
  scr_release(x->scr, smark);
  if (x->core) core_release(x->core, mark);
  return rc;
}

int seg_generate(const struct seg_input *in, struct seg_result *out, FILE *trace,
                 struct core *core, struct cost *cost, struct t74_error *err)
{
  struct seg_ctx xc;
  struct seg_scratch scr;
  memset(&scr, 0, sizeof scr);
  ctx_init(&xc, in, trace, core, cost, err);
  xc.scr = &scr;
  int rc = generate(&xc, out);
  scr_free_chunks(&scr);
  return rc;
}

int seg_check(const struct seg_input *in, struct seg_scratch *scr, struct core *core,
              struct t74_error *err)
{
  struct seg_ctx xc;
  ctx_init(&xc, in, NULL, core, NULL, err);
  xc.scr = scr;
  xc.check = 1;
  return generate(&xc, NULL);
}

void seg_result_free(struct seg_result *r)
{
  if (!r) return;
  for (int i = 0; i < r->npiece; i++) {
    free(r->piece[i].line);
    free(r->piece[i].v);
  }
  free(r->piece);
  r->piece = NULL;
  r->npiece = 0;
  r->ncut = 0;
}
