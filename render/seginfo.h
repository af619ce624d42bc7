/*
** seginfo.h — Segment Information (paper 003 §2.2, §3.2, Fig. 8): the convex pieces.
**
** After the Segment Generator every face is a set of convex pieces (the paper's divided
** faces S_i). A piece is the intersection of the half-planes left of its oriented lines
** (geom.h), listed counter-clockwise; its vertices are where consecutive lines meet,
** exactly, as homogeneous points. Pieces are only ever added: a piece cut along an
** intersection line (priority.c) is marked dead and its two halves are appended, so a
** piece number, once given, always means the same region.
**
** In core (Fig. 8): B-BLOCK, one row per piece: piece number (2 words), face (1), y-min and
** y-max floored/ceiled to the grid (2 + 2), sides k (1), C-block address (2) = 10 words;
** C-BLOCK, per piece k sides of a, b (2 words each) and c (4 words) = 8k words.
*/
#ifndef T74_SEGINFO_H
#define T74_SEGINFO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"
#include "render/pool.h"

struct piece {
  union {                  /* its n oriented lines, counter-clockwise (piece_line): */
    struct gline *ln;      /* kept, the piece's own (with its n vertices just before
                              them: piece_kept), */
    const struct gpoint *pt;   /* or, `onface`, side k runs from pt[k] to pt[k + 1 mod n]:
                              a whole convex face's points in the Mapper's table (issue 19:
                              no copy of the lines of most pieces, 10 MB at 100,000 boxes) */
  };
  uint64_t ylo_yl;         /* its lowest vertex's Y (the low 64 bits; the high ones in
                              ylo_yh: |Y| < 2^88, geom.h) and W (< 2^59): the height the
                              Visible Surface Procedure orders pieces by, read only as the
                              fraction Y / W (a piece `onface` keeps it as (y, 1), */
  int64_t  ylo_w;          /* its lowest point's y over 1: seginfo.c add_rest) */
  int32_t  ylo_yh;
  int      face;           /* index in mapped.f */
  int      n;              /* number of sides, >= 3 */
  int      parent;         /* the piece it is a half of (cut by priority.c), else -1 */
  int      lo;             /* its lowest and highest vertex: piece_v(p, lo), piece_v(p, hi) */
  signed int hi : 30;
  bool     alive : 1;      /* false once cut in two */
  bool     onface : 1;     /* its lines are its face's sides (pt), not kept (ln) */
};                         /* 48 bytes, and 72 a side of its own lines and vertices (issue
                              19: a quadrilateral took 328 bytes before, 48 now on its face) */

/* Side k's line. */
static inline struct gline piece_line(const struct piece *p, int k)
{
  if (p->onface) return geom_line(p->pt[k], p->pt[k + 1 < p->n ? k + 1 : 0]);
  return p->ln[k];
}

/* All of p's lines: its own, or made into buf (room for PIECE_VBUF: a piece on its face's
   points has at most SEG_CONVEX_MAX sides). */
static inline const struct gline *piece_lines(const struct piece *p, struct gline *buf)
{
  if (!p->onface) return p->ln;
  for (int k = 0; k < p->n; k++) buf[k] = geom_line(p->pt[k], p->pt[k + 1 < p->n ? k + 1 : 0]);
  return buf;
}

/* A piece's vertex k is where line[k-1] meets line[k] (geom_meet; the lines of a piece
   always meet: seginfo_add). A piece of its own lines (seginfo_add: the halves of a cut,
   the pieces the Segment Generator cut a face into) keeps its vertices, as geom_meet
   gives them, which seginfo_add makes anyway; a piece on its face's points (most pieces:
   48 bytes a vertex were 19 MB of the 29 MB of sides at 100,000 boxes when every piece
   kept them, issue 19) has them made again where they are read, always the same exact
   values. PIECE_VBUF: the room a caller gives for the sides and vertices of a piece on
   its face's points (SEG_CONVEX_MAX at most). */
#define PIECE_VBUF 64

/* The vertices a piece of its own lines keeps, else (onface) NULL. */
static inline const struct hpoint *piece_kept(const struct piece *p)
{
  return p->onface ? NULL : (const struct hpoint *)(const void *)p->ln - p->n;
}

static inline struct hpoint piece_v(const struct piece *p, int k)
{
  if (!p->onface) return piece_kept(p)[k];
  struct hpoint v;
  (void)geom_meet(piece_line(p, k ? k - 1 : p->n - 1), piece_line(p, k), &v);
  return v;
}

/* piece_v(p, k) where only its height is read: Y and W as piece_v gives them; X is 0
   unless the vertex is kept (two products of geom_meet's six spared). piece_vy_at: that
   of the meet of lines l1 and l2. */
static inline struct hpoint piece_vy_at(struct gline l1, struct gline l2)
{
  wide W = (wide)l1.a * l2.b - (wide)l2.a * l1.b;
  wide Y = (wide)l1.c * l2.a - (wide)l2.c * l1.a;
  if (W < 0) { W = -W; Y = -Y; }                 /* as geom_meet */
  return (struct hpoint){ 0, Y, W };
}
static inline struct hpoint piece_vy(const struct piece *p, int k)
{
  if (!p->onface) return piece_kept(p)[k];
  return piece_vy_at(piece_line(p, k ? k - 1 : p->n - 1), piece_line(p, k));
}

/* All of p's vertices, v[k] = piece_v(p, k): the piece's own (kept), or made into buf
   (room for PIECE_VBUF) from its lines pl (piece_lines) for a piece on its face's
   points. */
static inline const struct hpoint *piece_verts_of(const struct piece *p, const struct gline *pl,
                                                  struct hpoint *buf)
{
  if (!p->onface) return piece_kept(p);
  for (int k = 0, k0 = p->n - 1; k < p->n; k0 = k++) (void)geom_meet(pl[k0], pl[k], &buf[k]);
  return buf;
}

/* All of p's vertices (piece_verts_of its lines). */
static inline const struct hpoint *piece_verts(const struct piece *p, struct hpoint *buf)
{
  struct gline lb[PIECE_VBUF];
  return piece_verts_of(p, p->onface ? piece_lines(p, lb) : NULL, buf);
}

/* Piece p's lowest vertex's Y, over W = p->ylo_w (piece_v(p, p->lo)'s height Y / W;
   for a piece `onface`, Y = its y and W = 1). */
static inline wide piece_ylo_y(const struct piece *p)
{
  return (wide)(((uwide)(uint64_t)(int64_t)p->ylo_yh << 64) | p->ylo_yl);
}

/* Piece p's lowest and highest vertex (the first of equal y in p's order). */
static inline struct hpoint piece_ylo(const struct piece *p) { return piece_v(p, p->lo); }
static inline struct hpoint piece_yhi(const struct piece *p) { return piece_v(p, p->hi); }
/* The height of p's highest vertex (piece_vy). */
static inline struct hpoint piece_yhi_y(const struct piece *p) { return piece_vy(p, p->hi); }

struct seginfo {
  int    n, cap;
  struct piece *p;
  struct core *core;
  struct core_name bname, cname, yname;   /* B-BLOCK, C-BLOCK, and the Segment Generator's
                                             YSORT (seg_input.ysort): their rows found once */
  struct cost *cost;
  struct pool pool;        /* host blocks of the pieces' lines and vertices */
};

void seginfo_init(struct seginfo *t, struct core *core, struct cost *cost);
void seginfo_free(struct seginfo *t);

/* Room for n pieces in all, taken now (issue 19: the table sized from an estimate of the
   pieces, not by doubling from 64, which leaves it up to twice as large as it needs and
   its smaller copies freed behind it). false when the host is out of memory. */
bool seginfo_reserve(struct seginfo *t, int n);

/* seginfo_add of a convex face's one piece whose sides are the face's: n points pt (at
   most SEG_CONVEX_MAX, the face's own array in the Mapper's table, which outlives the
   pieces), side k from pt[k] to pt[k + 1 mod n], its lines `line` as seginfo_add is
   given them. The same piece, blocks and charges as seginfo_add; its lines are not copied
   (issue 19) unless a point is off the grid (geom.h), the lines are not exactly those of
   the points, in order, or two consecutive ones run on one line (then seginfo_add). */
int seginfo_add_face(struct seginfo *t, int face, int n, const struct gpoint *pt,
                     const struct gline *line, struct t74_error *err);

/* Append a piece given by its lines (consecutive lines must meet). Returns the piece's
   number, or -1 with err set (T74_ECORE when its blocks do not fit the core). */
int seginfo_add(struct seginfo *t, int face, int n, const struct gline *line,
                struct t74_error *err);

/* A convex polygon under construction (for clipping). */
struct cpoly {
  int n, cap;
  struct gline  *line;
  struct hpoint *v;
};

void cpoly_free(struct cpoly *c);

/* Clip piece p by the half-plane left of h (closed). Returns true when what remains has
   a non-empty interior, and then fills out (lines only; vertices computed too). */
bool seginfo_clip(const struct piece *p, struct gline h, struct cpoly *out, struct cost *cost);

/* seginfo_clip by h into left and by the reversed h (-a, -b, -c) into right, each of p's
   vertices placed once: the same halves, results and charges as the two calls. */
void seginfo_clip_both(const struct piece *p, struct gline h, struct cpoly *left, bool *hasl,
                       struct cpoly *right, bool *hasr, struct cost *cost);

/* seginfo_clip_both where the caller knows that the half on side `known` of h (1 the left,
   2 the right; 0 neither) has an interior: that half is only counted, its number of sides
   (out->n) and *has (true) what seginfo_clip_both gives, its sides and vertices not made;
   the same charges, counted: the products (88 x 58 bits) seginfo_clip_both charges are
   added to *prod instead. sides: NULL, or the side of h of each of p's vertices as
   geom_side_h gives it, found already (p->n entries). pl, pv: NULL, or p's lines and
   vertices as piece_lines and piece_verts give them, made already. */
void seginfo_clip_both_known(const struct piece *p, const struct gline *pl,
                             const struct hpoint *pv, struct gline h, const signed char *sides,
                             int known, struct cpoly *left, bool *hasl, struct cpoly *right,
                             bool *hasr, uint64_t *prod);

/* Do the interiors of two convex polygons overlap? (exact separating-line test) */
bool seginfo_overlap(int n1, const struct gline *l1, const struct hpoint *v1,
                     int n2, const struct gline *l2, const struct hpoint *v2,
                     struct cost *cost);

/* seginfo_overlap with the products it charges (88 x 58 bits) added to *prod instead. */
bool seginfo_overlap_n(int n1, const struct gline *l1, const struct hpoint *v1,
                       int n2, const struct gline *l2, const struct hpoint *v2,
                       uint64_t *prod);

/* The x-span of piece p on the horizontal line y = yn/yd: [xl, xr) by the tie rule of
   geom.h, by definition (the largest x of its left sides, the smallest of its right
   ones). Returns false when the line misses the piece (or meets only its boundary in a
   way the piece does not own). The scan itself gets the same spans incrementally from
   D-blocks (visible.c); the tests hold the two to each other. */
bool seginfo_span(const struct piece *p, int64_t yn, int64_t yd, struct grat *xl,
                  struct grat *xr, struct cost *cost);

#endif
