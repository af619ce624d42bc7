/*
** scene.c — read and check a scene: the .s74 parser and the exact face checks
** (paper 003 §2.1 for the input data; shared/CONTRACT.md "Scene files").
**
** This file contains code to turn a .s74 scene file into a struct scene and to prove,
** before any rendering stage runs, that it keeps every promise the renderer relies on.
** Parsing is strict: one statement a line, every token a whole integer inside its range,
** `*` only between vertex ids, `grey G` only at the end of a face line, the once-only
** statements (view, window, light, background, effects) at most once. Ids are resolved
** after the whole file is read, so a face may name a vertex defined further down; an
** unknown id is still reported at the line that uses it. The text may start with a UTF-8
** byte-order mark and end its lines with LF, CR LF or a lone CR (the line reader of
** render/import.h); UTF-16 is refused by name (the reader, import_open).
**
** The geometric checks are exact, in integers, never in floating point:
**  - each ring (outer boundary, then one ring per hole) has >= 3 distinct vertices, no
**    vertex twice and no two vertices at one position;
**  - the outer boundary is not a line (non-zero area);
**  - all vertices of all rings satisfy the plane equation N.(p - p0) = 0 exactly, with N
**    the cross product of the outer ring's first non-collinear triple (any such triple of
**    a planar face spans its plane, so this equals the Newell normal up to scale);
**  - projected onto the coordinate plane that drops N's largest component (a one-to-one
**    map of the face's plane), no two edges of the face intersect, except that edges
**    meeting at a common end point (adjacent edges of a ring, or rings touching at a
**    shared vertex POSITION) may meet there and only there;
**  - every hole lies inside the outer boundary and outside every other hole, tested with
**    the exact midpoint of each hole edge (given the previous check, an edge's interior is
**    wholly inside or wholly outside any other ring, so its midpoint decides).
** Bounds: coordinates are in -32768..32767, so a difference is below 2^16 in magnitude,
** a normal component (sum of two products of differences) below 2^33, and a plane test
** N.(p - p0) below 3 * 2^33 * 2^16 < 2^51; 2D orientations on doubled coordinates stay
** below 2 * 2^17 * 2^17 = 2^35. All fit int64_t; no 128-bit arithmetic is needed.
*/
#include "render/scene.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/effects.h"
#include "render/import.h"
#include "render/plane.h"
#include "render/pool.h"

#define NIDS (SCENE_ID_MAX + 1)   /* id tables are indexed by id 0..65535 */

/* ---- freeing ------------------------------------------------------------------------- */

int *scene_pool_ints(struct scene *s, size_t n)
{
  if (n > SIZE_MAX / sizeof(int)) return NULL;
  return pool_alloc(&s->pool, n * sizeof(int), _Alignof(int));
}

void scene_free(struct scene *s)
{
  if (!s) return;
  for (int i = 0; i < s->nf; i++) {
    free(s->f[i].texture);
    if (s->f[i].pooled) continue;
    free(s->f[i].ring_start);
    free(s->f[i].vidx);
  }
  pool_free(&s->pool);
  for (int i = 0; i < s->nobj; i++) free(s->obj[i].face);
  free(s->f);
  free(s->obj);
  free(s->v);
  free(s->file);
  free(s->background);
  free(s->effects);
  free(s);
}

/* ---- exact face geometry ----------------------------------------------------------- */

/* Where point t lies against the ring pts[0..n): 1 inside, 0 on the boundary, -1 outside.
   Winding number with exact orientation tests (Sunday's crossing rules). */
static int in_ring(struct pl_pt t, const struct pl_pt *pts, int n)
{
  int wn = 0;
  for (int i = 0; i < n; i++) {
    struct pl_pt a = pts[i], b = pts[(i + 1) % n];
    int64_t o = pl_orient(a, b, t);
    if (o == 0 && pl_on_seg(a, b, t)) return 0;
    if (a.v <= t.v) {
      if (b.v > t.v && o > 0) wn++;
    } else {
      if (b.v <= t.v && o < 0) wn--;
    }
  }
  return wn != 0 ? 1 : -1;
}

static const char *ring_name(int r, char *buf, size_t n)
{
  if (r == 0) snprintf(buf, n, "outer boundary");
  else snprintf(buf, n, "hole %d", r);
  return buf;
}

struct vkey { int32_t x, y, z; int pos; };

static int vkey_cmp(const void *pa, const void *pb)
{
  const struct vkey *a = pa, *b = pb;
  if (a->x != b->x) return a->x < b->x ? -1 : 1;
  if (a->y != b->y) return a->y < b->y ? -1 : 1;
  if (a->z != b->z) return a->z < b->z ? -1 : 1;
  return (a->pos > b->pos) - (a->pos < b->pos);
}

struct edge {
  int ring, a, b;         /* positions in vidx of the two ends */
  int64_t umin, umax, vmin, vmax;
  int order;              /* index before sorting: a stable tie-break */
};

static int edge_cmp(const void *pa, const void *pb)
{
  const struct edge *a = pa, *b = pb;
  if (a->umin != b->umin) return a->umin < b->umin ? -1 : 1;
  return (a->order > b->order) - (a->order < b->order);
}

/* The sorts of a face's few keys and edges: insertion sorts with the comparison inlined
   (issue 12), qsort beyond 16; both comparisons are total orders (ties broken by a unique
   index), so the order is the one qsort or import_sort gives. */
static void sort_vkeys(struct vkey *k, size_t n)
{
  if (n > 16) { qsort(k, n, sizeof *k, vkey_cmp); return; }
  for (size_t i = 1; i < n; i++) {
    struct vkey t = k[i];
    size_t j = i;
    for (; j > 0 && vkey_cmp(&k[j - 1], &t) > 0; j--) k[j] = k[j - 1];
    k[j] = t;
  }
}

static void sort_edges(struct edge *e, size_t n)
{
  if (n > 16) { qsort(e, n, sizeof *e, edge_cmp); return; }
  for (size_t i = 1; i < n; i++) {
    struct edge t = e[i];
    size_t j = i;
    for (; j > 0 && edge_cmp(&e[j - 1], &t) > 0; j--) e[j] = e[j - 1];
    e[j] = t;
  }
}

/* Positions in ring r: is any position repeated? Sorting makes this O(n log n). */
static int check_distinct(const struct scene *s, const struct scene_face *f, int r,
                          struct vkey *keys, struct t74_error *err)
{
  int lo = f->ring_start[r], hi = f->ring_start[r + 1], n = hi - lo;
  char rn[32];
  for (int k = 0; k < n; k++) {
    const struct scene_vertex *v = &s->v[f->vidx[lo + k]];
    keys[k] = (struct vkey){ v->x, v->y, v->z, k };
  }
  sort_vkeys(keys, (size_t)n);
  for (int k = 0; k + 1 < n; k++) {
    if (keys[k].x != keys[k + 1].x || keys[k].y != keys[k + 1].y ||
        keys[k].z != keys[k + 1].z)
      continue;
    int i = keys[k].pos, j = keys[k + 1].pos;     /* i < j */
    const struct scene_vertex *a = &s->v[f->vidx[lo + i]], *b = &s->v[f->vidx[lo + j]];
    ring_name(r, rn, sizeof rn);
    if (a == b) {
      t74_fail_at(err, T74_EINPUT, s->file, f->line,
                  "face %d: vertex %d appears twice in its %s (not a simple boundary)",
                  f->id, a->id, rn);
      return SCENE_FACE_NONSIMPLE;
    }
    bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
    t74_fail_at(err, T74_EINPUT, s->file, f->line,
                "face %d: vertices %d and %d of its %s are at the same point (%d, %d, %d)%s",
                f->id, a->id, b->id, rn, a->x, a->y, a->z,
                adjacent ? " (zero-length edge)" : " (not a simple boundary)");
    return adjacent ? SCENE_FACE_DEGENERATE : SCENE_FACE_NONSIMPLE;
  }
  return SCENE_FACE_OK;
}

static int face_check(const struct scene *s, const struct scene_face *f, struct pl_pt *pt,
                      struct edge *e, struct vkey *keys, struct t74_error *err)
{
  const int *rs = f->ring_start;
  const int nall = rs[f->nring];
  char rn[32], rn2[32];

  for (int r = 0; r < f->nring; r++) {
    if (rs[r + 1] - rs[r] < 3) {
      t74_fail_at(err, T74_EINPUT, s->file, f->line,
                  "face %d has fewer than 3 distinct vertices in its %s", f->id,
                  ring_name(r, rn, sizeof rn));
      return SCENE_FACE_DEGENERATE;
    }
    int d = check_distinct(s, f, r, keys, err);
    if (d) return d;
  }

  /* Normal from the first non-collinear triple p0, p1, pk of the outer ring. */
  const struct scene_vertex *p0 = &s->v[f->vidx[0]], *p1 = &s->v[f->vidx[1]];
  int64_t ax = p1->x - p0->x, ay = p1->y - p0->y, az = p1->z - p0->z;
  int64_t nx = 0, ny = 0, nz = 0;
  int k = 2;
  for (; k < rs[1]; k++) {
    const struct scene_vertex *pk = &s->v[f->vidx[k]];
    int64_t bx = pk->x - p0->x, by = pk->y - p0->y, bz = pk->z - p0->z;
    nx = ay * bz - az * by;
    ny = az * bx - ax * bz;
    nz = ax * by - ay * bx;
    if (nx || ny || nz) break;
  }
  if (k == rs[1]) {
    t74_fail_at(err, T74_EINPUT, s->file, f->line,
                "face %d has zero area: its outer boundary is a straight line", f->id);
    return SCENE_FACE_DEGENERATE;
  }
  for (int q = 0; q < nall; q++) {
    const struct scene_vertex *p = &s->v[f->vidx[q]];
    if (nx * (p->x - p0->x) + ny * (p->y - p0->y) + nz * (p->z - p0->z) != 0) {
      t74_fail_at(err, T74_EINPUT, s->file, f->line,
                  "face %d is not planar: vertex %d is off the plane of vertices %d, %d, %d",
                  f->id, p->id, p0->id, p1->id, s->v[f->vidx[k]].id);
      return SCENE_FACE_NONPLANAR;
    }
  }

  /* Project: drop the axis of N's largest component (one-to-one on the plane). Doubled,
     so that edge midpoints are grid points too. */
  int64_t anx = nx < 0 ? -nx : nx, any = ny < 0 ? -ny : ny, anz = nz < 0 ? -nz : nz;
  for (int q = 0; q < nall; q++) {
    const struct scene_vertex *p = &s->v[f->vidx[q]];
    if (anz >= anx && anz >= any) pt[q] = (struct pl_pt){ 2 * (int64_t)p->x, 2 * (int64_t)p->y };
    else if (anx >= any) pt[q] = (struct pl_pt){ 2 * (int64_t)p->y, 2 * (int64_t)p->z };
    else pt[q] = (struct pl_pt){ 2 * (int64_t)p->z, 2 * (int64_t)p->x };
  }

  /* Every pair of edges whose boxes overlap, found by a sweep over u. */
  for (int r = 0; r < f->nring; r++)
    for (int q = rs[r]; q < rs[r + 1]; q++) {
      int q2 = q + 1 < rs[r + 1] ? q + 1 : rs[r];
      struct pl_pt a = pt[q], b = pt[q2];
      e[q] = (struct edge){ r, q, q2, a.u < b.u ? a.u : b.u, a.u > b.u ? a.u : b.u,
                            a.v < b.v ? a.v : b.v, a.v > b.v ? a.v : b.v, q };
    }
  sort_edges(e, (size_t)nall);
  for (int i = 0; i < nall; i++)
    for (int j = i + 1; j < nall && e[j].umin <= e[i].umax; j++) {
      if (e[j].vmin > e[i].vmax || e[j].vmax < e[i].vmin) continue;
      struct pl_pt a = pt[e[i].a], b = pt[e[i].b], c = pt[e[j].a], d = pt[e[j].b];
      bool bad;
      if ((pl_eq(a, c) && pl_eq(b, d)) || (pl_eq(a, d) && pl_eq(b, c))) bad = true;
      else if (pl_eq(a, c)) bad = pl_fold(a, b, d);
      else if (pl_eq(a, d)) bad = pl_fold(a, b, c);
      else if (pl_eq(b, c)) bad = pl_fold(b, a, d);
      else if (pl_eq(b, d)) bad = pl_fold(b, a, c);
      else bad = pl_meet(a, b, c, d);
      if (bad) {
        const struct edge *x = e[i].order < e[j].order ? &e[i] : &e[j];
        const struct edge *y = x == &e[i] ? &e[j] : &e[i];
        t74_fail_at(err, T74_EINPUT, s->file, f->line,
                    "face %d is not simple: edge %d-%d of its %s and edge %d-%d of its %s "
                    "intersect", f->id, s->v[f->vidx[x->a]].id, s->v[f->vidx[x->b]].id,
                    ring_name(x->ring, rn, sizeof rn), s->v[f->vidx[y->a]].id,
                    s->v[f->vidx[y->b]].id, ring_name(y->ring, rn2, sizeof rn2));
        return SCENE_FACE_NONSIMPLE;
      }
    }

  /* Holes: inside the outer boundary, outside each other. box[r] bounds ring r (it
     reuses the edge array: one entry per ring is needed and nring <= nall). */
  struct edge *box = e;
  for (int r = 0; r < f->nring; r++) {
    box[r] = (struct edge){ .umin = pt[rs[r]].u, .umax = pt[rs[r]].u, .vmin = pt[rs[r]].v,
                            .vmax = pt[rs[r]].v };
    for (int q = rs[r]; q < rs[r + 1]; q++) {
      if (pt[q].u < box[r].umin) box[r].umin = pt[q].u;
      if (pt[q].u > box[r].umax) box[r].umax = pt[q].u;
      if (pt[q].v < box[r].vmin) box[r].vmin = pt[q].v;
      if (pt[q].v > box[r].vmax) box[r].vmax = pt[q].v;
    }
  }
  for (int h = 1; h < f->nring; h++) {
    for (int q = rs[h]; q < rs[h + 1]; q++)
      if (in_ring(pt[q], pt, rs[1]) < 0) {
        t74_fail_at(err, T74_EINPUT, s->file, f->line,
                    "face %d: hole %d is outside the face (vertex %d)", f->id, h,
                    s->v[f->vidx[q]].id);
        return SCENE_FACE_HOLE;
      }
    for (int q = rs[h]; q < rs[h + 1]; q++) {
      int q2 = q + 1 < rs[h + 1] ? q + 1 : rs[h];
      struct pl_pt m = { (pt[q].u + pt[q2].u) / 2, (pt[q].v + pt[q2].v) / 2 };  /* exact */
      if (in_ring(m, pt, rs[1]) <= 0) {
        t74_fail_at(err, T74_EINPUT, s->file, f->line,
                    "face %d: hole %d leaves the face along edge %d-%d", f->id, h,
                    s->v[f->vidx[q]].id, s->v[f->vidx[q2]].id);
        return SCENE_FACE_HOLE;
      }
      for (int g = 1; g < f->nring; g++) {
        if (g == h || m.u < box[g].umin || m.u > box[g].umax || m.v < box[g].vmin ||
            m.v > box[g].vmax)
          continue;                     /* outside g's box: outside g */
        if (in_ring(m, pt + rs[g], rs[g + 1] - rs[g]) >= 0) {
          t74_fail_at(err, T74_EINPUT, s->file, f->line,
                      "face %d: hole %d overlaps hole %d (edge %d-%d is inside it)", f->id,
                      h, g, s->v[f->vidx[q]].id, s->v[f->vidx[q2]].id);
          return SCENE_FACE_HOLE;
        }
      }
    }
  }
  return SCENE_FACE_OK;
}

/* The common case first (issue 12: the box faces of a large scene): a quadrilateral
   without holes, exactly planar, whose projection along its normal's largest component
   turns strictly the same way at all four corners. Four strict turns of one sense add up
   to one full turn (each less than a half turn, the sum a multiple of a full one), so the
   quadrilateral is convex and simple: its vertices are distinct, no two edges meet but
   neighbours at their common end, and face_check would pass it. Exact, in the integers
   face_check uses; false sends the face the whole way. */
static bool convex_quad(const struct scene *s, const struct scene_face *f)
{
  if (f->nring != 1 || f->ring_start[1] - f->ring_start[0] != 4) return false;
  const int *r = f->vidx + f->ring_start[0];
  const struct scene_vertex *p[4] = { &s->v[r[0]], &s->v[r[1]], &s->v[r[2]], &s->v[r[3]] };
  int64_t ax = p[1]->x - p[0]->x, ay = p[1]->y - p[0]->y, az = p[1]->z - p[0]->z;
  int64_t bx = p[2]->x - p[0]->x, by = p[2]->y - p[0]->y, bz = p[2]->z - p[0]->z;
  int64_t nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
  if (!(nx || ny || nz)) return false;
  if (nx * (p[3]->x - p[0]->x) + ny * (p[3]->y - p[0]->y) + nz * (p[3]->z - p[0]->z) != 0)
    return false;
  int64_t anx = nx < 0 ? -nx : nx, any = ny < 0 ? -ny : ny, anz = nz < 0 ? -nz : nz;
  struct pl_pt q[4];
  for (int k = 0; k < 4; k++) {
    if (anz >= anx && anz >= any) q[k] = (struct pl_pt){ p[k]->x, p[k]->y };
    else if (anx >= any) q[k] = (struct pl_pt){ p[k]->y, p[k]->z };
    else q[k] = (struct pl_pt){ p[k]->z, p[k]->x };
  }
  int pos = 0, neg = 0;
  for (int k = 0; k < 4; k++) {
    int64_t o = pl_orient(q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
    pos += o > 0;
    neg += o < 0;
  }
  return pos == 4 || neg == 4;
}

int scene_check_face(const struct scene *s, const struct scene_face *f,
                     struct t74_error *err)
{
  if (convex_quad(s, f)) return SCENE_FACE_OK;
  if (f->nring < 1) {
    t74_fail_at(err, T74_EINPUT, s->file, f->line, "face %d has no vertices", f->id);
    return SCENE_FACE_DEGENERATE;
  }
  size_t n = (size_t)f->ring_start[f->nring] + 1;
  /* most faces are small: their scratch on the stack (issue 12: three mallocs a face) */
  enum { SMALL = 32 };
  struct pl_pt spt[SMALL];
  struct edge se[SMALL];
  struct vkey skeys[SMALL];
  bool small = n <= SMALL;
  struct pl_pt *pt = small ? spt : malloc(n * sizeof *pt);
  struct edge *e = small ? se : malloc(n * sizeof *e);
  struct vkey *keys = small ? skeys : malloc(n * sizeof *keys);
  int d;
  if (!pt || !e || !keys) {
    t74_fail(err, T74_EIO, "%s: out of memory", s->file);
    d = -1;
  } else {
    d = face_check(s, f, pt, e, keys, err);
  }
  if (!small) {
    free(pt);
    free(e);
    free(keys);
  }
  return d;
}

int scene_check_camera(const struct scene *s, int view_line, int window_line,
                       struct t74_error *err)
{
  const int32_t *w = s->window, *v = s->view;
  for (int k = 0; k < 3; k++)
    if (v[k] < SCENE_COORD_MIN || v[k] > SCENE_COORD_MAX) {
      if (view_line) break;   /* a .s74 value was range-checked when read */
      return t74_fail(err, T74_EINPUT, "--view: %d is out of range %d..%d", (int)v[k],
                      SCENE_COORD_MIN, SCENE_COORD_MAX);
    }
  for (int k = 0; k < 4; k++)
    if (w[k] < SCENE_COORD_MIN || w[k] > SCENE_COORD_MAX) {
      if (window_line) break;
      return t74_fail(err, T74_EINPUT, "--window: %d is out of range %d..%d", (int)w[k],
                      SCENE_COORD_MIN, SCENE_COORD_MAX);
    }
  if (v[2] >= 0) {
    if (view_line)
      return t74_fail_at(err, T74_EINPUT, s->file, view_line,
                         "the eye must be on the negative side: view Z0 = %d must be < 0",
                         (int)v[2]);
    return t74_fail(err, T74_EINPUT,
                    "--view: the eye must be on the negative side: Z0 = %d must be < 0",
                    (int)v[2]);
  }
  if (w[0] >= w[2] || w[1] >= w[3]) {
    const char *what = w[0] >= w[2] ? "XL must be < XR" : "YB must be < YT";
    if (window_line)
      return t74_fail_at(err, T74_EINPUT, s->file, window_line,
                         "window %d %d %d %d: %s", (int)w[0], (int)w[1], (int)w[2],
                         (int)w[3], what);
    return t74_fail(err, T74_EINPUT, "--window %d %d %d %d: %s", (int)w[0], (int)w[1],
                    (int)w[2], (int)w[3], what);
  }
  bool *used = calloc((size_t)s->nv + 1, sizeof *used);
  if (!used) return t74_fail(err, T74_EIO, "%s: out of memory", s->file);
  for (int i = 0; i < s->nf; i++)
    for (int q = 0; q < s->f[i].ring_start[s->f[i].nring]; q++) used[s->f[i].vidx[q]] = true;
  for (int i = 0; i < s->nv; i++)
    if (used[i] && s->v[i].z <= v[2]) {
      free(used);
      return t74_fail_at(err, T74_EINPUT, s->file, s->v[i].line,
                         "vertex %d (z = %d) is not in front of the eye: every vertex of a "
                         "face needs z > Z0 = %d", s->v[i].id, (int)s->v[i].z, (int)v[2]);
    }
  free(used);
  return T74_OK;
}

/* ---- the .s74 parser --------------------------------------------------------------- */

/* An id table: ids 0 .. SCENE_ID_MAX in blocks of IDMAP_BLOCK, a block made (zeroed) when
** an id in it is first defined; an entry holds the index + 1, 0 when the id is not
** defined. A scene's ids are few and mostly small, so the table stays a few kB (issue
** 19: three flat tables of 64 k ids set to -1 were 192 of a small scene's 440 page
** faults, each page touched costing about 10 us). */
#define IDMAP_BLOCK 256
struct idmap { int *block[NIDS / IDMAP_BLOCK]; };

struct parse {
  struct scene *s;
  struct import_reader r;
  struct t74_error *err;
  int capv, capf, capo;
  struct idmap vmap, fmap, omap;    /* id -> index (map_get) */
  int view_line, window_line, background_line;
  struct tex_line { int face, line; char *path; } *tex;   /* `texture` lines, resolved */
  int ntex, captex;                                        /* after the faces */
};

static int oom(struct parse *p)
{
  return t74_fail(p->err, T74_EIO, "%s: out of memory", p->s->file);
}

static int at(struct parse *p, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;

/* Record "FILE:LINE: message" at the current line. */
static int at(struct parse *p, const char *fmt, ...)
{
  char msg[900];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return t74_fail_at(p->err, T74_EINPUT, p->s->file, p->r.line, "%s", msg);
}

/* Token t of the current line as an integer in lo..hi; what names it in messages. */
static int number(struct parse *p, int t, long lo, long hi, const char *what, long *out)
{
  char b[48];
  int e = import_int(p->r.tok[t], lo, hi, out);
  if (e == 1) return at(p, "bad number `%s` (%s)", import_show(p->r.tok[t], b, sizeof b), what);
  if (e == 2)
    return at(p, "%s `%s` out of range %ld..%ld", what,
              import_show(p->r.tok[t], b, sizeof b), lo, hi);
  return T74_OK;
}

static int coords(struct parse *p, int t0, int n, int32_t *out, const char *what)
{
  for (int k = 0; k < n; k++) {
    long v;
    int st = number(p, t0 + k, SCENE_COORD_MIN, SCENE_COORD_MAX, what, &v);
    if (st) return st;
    out[k] = (int32_t)v;
  }
  return T74_OK;
}

static int once(struct parse *p, int *line, const char *name)
{
  if (*line) return at(p, "`%s` given twice (first at line %d)", name, *line);
  *line = p->r.line;
  return T74_OK;
}

static int count(struct parse *p, int want, const char *usage)
{
  if (p->r.ntok != want) return at(p, "wrong number of values: expected `%s`", usage);
  return T74_OK;
}

/* An id table's entry for id: the index, or -1 when the id is not defined. */
static int map_get(const struct idmap *m, long id)
{
  const int *b = m->block[id / IDMAP_BLOCK];
  return b ? b[id % IDMAP_BLOCK] - 1 : -1;
}

/* Define id as index idx: 0, or -1 when out of memory. */
static int map_set(struct idmap *m, long id, int idx)
{
  int **b = &m->block[id / IDMAP_BLOCK];
  if (!*b && !(*b = calloc(IDMAP_BLOCK, sizeof **b))) return -1;
  (*b)[id % IDMAP_BLOCK] = idx + 1;
  return 0;
}

static void map_free(struct idmap *m)
{
  for (int k = 0; k < NIDS / IDMAP_BLOCK; k++) free(m->block[k]);
}

static int st_vertex(struct parse *p)
{
  struct scene *s = p->s;
  long id;
  int st;
  if ((st = count(p, 5, "vertex N X Y Z"))) return st;
  if ((st = number(p, 1, 1, SCENE_ID_MAX, "vertex id", &id))) return st;
  if (map_get(&p->vmap, id) >= 0)
    return at(p, "vertex %ld already defined at line %d", id, s->v[map_get(&p->vmap, id)].line);
  if (s->nv == p->capv) {
    int nc = p->capv ? p->capv * 2 : 256;
    struct scene_vertex *nv = realloc(s->v, (size_t)nc * sizeof *nv);
    if (!nv) return oom(p);
    s->v = nv;
    p->capv = nc;
  }
  struct scene_vertex *v = &s->v[s->nv];
  int32_t c[3];
  if ((st = coords(p, 2, 3, c, "coordinate"))) return st;
  v->id = (uint16_t)id;
  v->x = c[0];
  v->y = c[1];
  v->z = c[2];
  v->line = p->r.line;
  if (map_set(&p->vmap, id, s->nv)) return oom(p);
  s->nv++;
  return T74_OK;
}

static int st_face(struct parse *p)
{
  struct scene *s = p->s;
  char **tok = p->r.tok;
  int ntok = p->r.ntok, st;
  long id, g = -1;
  if (ntok < 2) return at(p, "wrong number of values: expected `face N V1 V2 V3 ...`");
  if ((st = number(p, 1, 1, SCENE_ID_MAX, "face id", &id))) return st;
  if (map_get(&p->fmap, id) >= 0)
    return at(p, "face %ld already defined at line %d", id, s->f[map_get(&p->fmap, id)].line);
  int end = ntok;                       /* ring tokens are tok[2..end) */
  long on = 0;
  /* the trailing keywords, `on F` and `grey G`, in either order, each at most once */
  for (int round = 0; round < 2 && end >= 4; round++) {
    if (strcmp(tok[end - 2], "grey") == 0 && g < 0) {
      if ((st = number(p, end - 1, 0, 255, "grey", &g))) return st;
      end -= 2;
    } else if (strcmp(tok[end - 2], "on") == 0 && on == 0) {
      if ((st = number(p, end - 1, 1, SCENE_ID_MAX, "face id after `on`", &on))) return st;
      if (on == id) return at(p, "face %ld cannot lie on itself", id);
      end -= 2;
    }
  }
  for (int t = 2; t < end; t++) {
    if (strcmp(tok[t], "grey") == 0)
      return at(p, "`grey` must be followed by exactly one intensity 0..255 at the end "
                   "of the line");
    if (strcmp(tok[t], "on") == 0)
      return at(p, "`on` must be followed by exactly one face id at the end of the line "
                   "(`face N V1 V2 ... on F [grey G]`)");
  }
  int nstar = 0;
  for (int t = 2; t < end; t++) {
    if (strcmp(tok[t], "*") != 0) continue;
    if (t == 2) return at(p, "`*` must come between vertex ids, not first");
    if (strcmp(tok[t - 1], "*") == 0) return at(p, "`*` must come between vertex ids: `* *`");
    if (t == end - 1) return at(p, "`*` must come between vertex ids, not last");
    nstar++;
  }
  if (s->nf == p->capf) {
    int nc = p->capf ? p->capf * 2 : 64;
    struct scene_face *nf = realloc(s->f, (size_t)nc * sizeof *nf);
    if (!nf) return oom(p);
    s->f = nf;
    p->capf = nc;
  }
  struct scene_face *f = &s->f[s->nf];
  memset(f, 0, sizeof *f);
  f->ring_start = malloc((size_t)(nstar + 2) * sizeof *f->ring_start);
  f->vidx = malloc((size_t)(end - 2 + 1) * sizeof *f->vidx);
  if (!f->ring_start || !f->vidx) {
    free(f->ring_start);
    free(f->vidx);
    return oom(p);
  }
  s->nf++;                              /* from here scene_free owns the arrays */
  f->id = (uint16_t)id;
  f->line = p->r.line;
  f->grey = (int16_t)g;               /* 0..255, or -1 */
  f->on_id = (uint32_t)on;
  f->nring = nstar + 1;
  int n = 0, r = 0;
  f->ring_start[0] = 0;
  for (int t = 2; t < end; t++) {
    if (strcmp(tok[t], "*") == 0) {
      f->ring_start[++r] = n;
      continue;
    }
    long vid;
    if ((st = number(p, t, 1, SCENE_ID_MAX, "vertex id", &vid))) return st;
    f->vidx[n++] = (int)vid;          /* an id until resolve() */
  }
  f->ring_start[f->nring] = n;
  if (map_set(&p->fmap, id, s->nf - 1)) return oom(p);
  return T74_OK;
}

static int st_object(struct parse *p)
{
  struct scene *s = p->s;
  long id;
  int st;
  int ntok = p->r.ntok;
  bool smooth = ntok >= 3 && strcmp(p->r.tok[ntok - 1], "smooth") == 0;
  if (smooth) ntok--;
  if (ntok < 3) return at(p, "wrong number of values: expected `object N F1 F2 ... [smooth]`");
  if ((st = number(p, 1, 1, SCENE_ID_MAX, "object id", &id))) return st;
  if (map_get(&p->omap, id) >= 0)
    return at(p, "object %ld already defined at line %d", id, s->obj[map_get(&p->omap, id)].line);
  if (s->nobj == p->capo) {
    int nc = p->capo ? p->capo * 2 : 16;
    struct scene_object *no = realloc(s->obj, (size_t)nc * sizeof *no);
    if (!no) return oom(p);
    s->obj = no;
    p->capo = nc;
  }
  struct scene_object *o = &s->obj[s->nobj];
  memset(o, 0, sizeof *o);
  o->face = malloc((size_t)(ntok - 2) * sizeof *o->face);
  if (!o->face) return oom(p);
  s->nobj++;
  o->id = (uint16_t)id;
  o->line = p->r.line;
  o->smooth = smooth;
  for (int t = 2; t < ntok; t++) {
    long fid;
    if ((st = number(p, t, 1, SCENE_ID_MAX, "face id", &fid))) return st;
    o->face[o->nface++] = (int)fid;   /* an id until resolve() */
  }
  if (map_set(&p->omap, id, s->nobj - 1)) return oom(p);
  return T74_OK;
}

/* "a/b/scene.s74" + "pic.pgm" -> "a/b/pic.pgm"; absolute paths are kept. */
static char *resolve_path(const char *scene_file, const char *name)
{
  const char *slash = strrchr(scene_file, '/');
  size_t dir = (name[0] == '/' || !slash) ? 0 : (size_t)(slash - scene_file) + 1;
  char *out = malloc(dir + strlen(name) + 1);
  if (!out) return NULL;
  memcpy(out, scene_file, dir);
  strcpy(out + dir, name);
  return out;
}

static int statement(struct parse *p)
{
  struct scene *s = p->s;
  const char *k = p->r.tok[0];
  int st;
  char b[48];
  if (strcmp(k, "vertex") == 0) return st_vertex(p);
  if (strcmp(k, "face") == 0) return st_face(p);
  if (strcmp(k, "object") == 0) return st_object(p);
  if (strcmp(k, "view") == 0) {
    if ((st = once(p, &p->view_line, "view")) || (st = count(p, 4, "view X0 Y0 Z0")) ||
        (st = coords(p, 1, 3, s->view, "view value")))
      return st;
    s->has_view = true;
    return T74_OK;
  }
  if (strcmp(k, "window") == 0) {
    if ((st = once(p, &p->window_line, "window")) ||
        (st = count(p, 5, "window XL YB XR YT")) ||
        (st = coords(p, 1, 4, s->window, "window value")))
      return st;
    s->has_window = true;
    if (s->window[0] >= s->window[2]) return at(p, "window: XL must be < XR");
    if (s->window[1] >= s->window[3]) return at(p, "window: YB must be < YT");
    return T74_OK;
  }
  if (strcmp(k, "light") == 0) {
    bool point = p->r.ntok >= 2 && strcmp(p->r.tok[1], "point") == 0;
    if (s->nlight == SCENE_LIGHT_MAX)
      return at(p, "more than %d lights", SCENE_LIGHT_MAX);
    struct scene_light *l = &s->light[s->nlight];
    if (point) {
      if ((st = count(p, 5, "light point X Y Z")) ||
          (st = coords(p, 2, 3, l->v, "light position")))
        return st;
    } else {
      if ((st = count(p, 4, "light DX DY DZ` or `light point X Y Z")) ||
          (st = coords(p, 1, 3, l->v, "light value")))
        return st;
      if (!l->v[0] && !l->v[1] && !l->v[2])
        return at(p, "light direction (0, 0, 0) has no direction");
    }
    l->point = point;
    l->line = p->r.line;
    s->nlight++;
    s->has_light = true;
    return T74_OK;
  }
  if (strcmp(k, "texture") == 0) {
    long fid;
    if ((st = count(p, 3, "texture F FILE")) ||
        (st = number(p, 1, 1, SCENE_ID_MAX, "face id", &fid)))
      return st;
    if (p->ntex == p->captex) {
      int nc = p->captex ? 2 * p->captex : 8;
      struct tex_line *nt = realloc(p->tex, (size_t)nc * sizeof *nt);
      if (!nt) return oom(p);
      p->tex = nt;
      p->captex = nc;
    }
    char *path = resolve_path(s->file, p->r.tok[2]);
    if (!path) return oom(p);
    p->tex[p->ntex++] = (struct tex_line){ (int)fid, p->r.line, path };
    return T74_OK;
  }
  if (strcmp(k, "background") == 0) {
    if ((st = once(p, &p->background_line, "background")) ||
        (st = count(p, 2, "background FILE")))
      return st;
    s->background = resolve_path(s->file, p->r.tok[1]);
    s->background_line = p->r.line;
    return s->background ? T74_OK : oom(p);
  }
  if (strcmp(k, "effects") == 0) {
    if (s->effects_line) return at(p, "`effects` given twice (first at line %d)", s->effects_line);
    s->effects_line = p->r.line;
    size_t len = 1;
    for (int t = 1; t < p->r.ntok; t++) len += strlen(p->r.tok[t]) + 1;
    s->effects = malloc(len);
    if (!s->effects) return oom(p);
    s->effects[0] = '\0';
    for (int t = 1; t < p->r.ntok; t++) {   /* tokens joined by one blank */
      if (t > 1) strcat(s->effects, " ");
      strcat(s->effects, p->r.tok[t]);
    }
    struct effects fx;
    return effects_parse(s->effects, &fx, s->file, p->r.line, p->err);
  }
  return at(p, "unknown statement `%s`", import_show(k, b, sizeof b));
}

/* Ids -> indices, clean the rings, then every check needing the whole file. */
static int resolve(struct parse *p)
{
  struct scene *s = p->s;
  struct t74_error *err = p->err;
  char rn[32];
  int *mark = calloc((size_t)s->nv + 1, sizeof *mark);   /* stamp per vertex index */
  if (!mark) return oom(p);
  int stamp = 0, st = T74_OK;
  for (int i = 0; i < s->nf && !st; i++) {
    struct scene_face *f = &s->f[i];
    int n = f->ring_start[f->nring];
    for (int q = 0; q < n; q++) {
      int idx = map_get(&p->vmap, f->vidx[q]);
      if (idx < 0) {
        st = t74_fail_at(err, T74_EINPUT, s->file, f->line, "face %d: unknown vertex %d",
                         f->id, f->vidx[q]);
        break;
      }
      f->vidx[q] = idx;
    }
    /* Remove consecutive duplicates and closing repeats of the first vertex. */
    int w = 0;
    for (int r = 0; r < f->nring && !st; r++) {
      int lo = f->ring_start[r], hi = f->ring_start[r + 1], start = w;   /* w <= lo */
      for (int q = lo; q < hi; q++)
        if (w == start || f->vidx[w - 1] != f->vidx[q]) f->vidx[w++] = f->vidx[q];
      while (w - start > 1 && f->vidx[w - 1] == f->vidx[start]) w--;
      f->ring_start[r] = start;
      if (w - start < 3) {
        st = t74_fail_at(err, T74_EINPUT, s->file, f->line,
                         "face %d has fewer than 3 distinct vertices in its %s", f->id,
                         ring_name(r, rn, sizeof rn));
        break;
      }
      stamp++;
      for (int q = start; q < w; q++) {
        if (mark[f->vidx[q]] == stamp) {
          st = t74_fail_at(err, T74_EINPUT, s->file, f->line,
                           "face %d: vertex %d appears twice in its %s (not a simple "
                           "boundary)", f->id, s->v[f->vidx[q]].id, ring_name(r, rn, sizeof rn));
          break;
        }
        mark[f->vidx[q]] = stamp;
      }
      /* ring_start[r + 1] still holds the next ring's old start (read next round) */
      if (r + 1 == f->nring) f->ring_start[r + 1] = w;
    }
    if (st) break;
    int d = scene_check_face(s, f, err);
    if (d) st = err->status ? err->status : T74_EINPUT;
  }
  free(mark);
  if (st) return st;

  for (int i = 0; i < s->nobj; i++) {
    struct scene_object *o = &s->obj[i];
    for (int k = 0; k < o->nface; k++) {
      int fid = o->face[k], idx = map_get(&p->fmap, fid);
      if (idx < 0)
        return t74_fail_at(err, T74_EINPUT, s->file, o->line, "object %d: unknown face %d",
                           o->id, fid);
      struct scene_face *f = &s->f[idx];
      if (f->object == (int)o->id)
        return t74_fail_at(err, T74_EINPUT, s->file, o->line,
                           "object %d: face %d is listed twice", o->id, fid);
      if (f->object)
        return t74_fail_at(err, T74_EINPUT, s->file, o->line,
                           "face %d is already in object %d (line %d)", fid, f->object,
                           s->obj[map_get(&p->omap, f->object)].line);
      f->object = (int)o->id;
      o->face[k] = idx;
    }
  }
  return T74_OK;
}

/* Pattern face pf (`on F`) against its face F: coplanar exactly, and every vertex of it
   inside F or on F's boundary, not inside one of F's holes (exact, on the coordinate
   plane the face's normal is largest across). */
static int check_pattern(const struct scene *s, const struct scene_face *pf,
                         const struct scene_face *F, struct t74_error *err)
{
  const struct scene_vertex *a = &s->v[F->vidx[0]];
  int64_t n[3] = { 0, 0, 0 };
  int nr = F->ring_start[1];
  for (int k = 1; k + 1 < nr && !n[0] && !n[1] && !n[2]; k++) {
    const struct scene_vertex *b = &s->v[F->vidx[k]], *c = &s->v[F->vidx[k + 1]];
    int64_t u[3] = { b->x - a->x, b->y - a->y, b->z - a->z };
    int64_t w[3] = { c->x - a->x, c->y - a->y, c->z - a->z };
    n[0] = u[1] * w[2] - u[2] * w[1];
    n[1] = u[2] * w[0] - u[0] * w[2];
    n[2] = u[0] * w[1] - u[1] * w[0];
  }
  int64_t ax = n[0] < 0 ? -n[0] : n[0], ay = n[1] < 0 ? -n[1] : n[1], az = n[2] < 0 ? -n[2] : n[2];
  int drop = az >= ax && az >= ay ? 2 : ax >= ay ? 0 : 1;
  int np = pf->ring_start[pf->nring], nf = F->ring_start[F->nring];
  struct pl_pt *ring = malloc((size_t)nf * sizeof *ring);
  if (!ring) return t74_fail(err, T74_EIO, "%s: out of memory", s->file);
  for (int k = 0; k < nf; k++) {
    const struct scene_vertex *v = &s->v[F->vidx[k]];
    int64_t c[3] = { v->x, v->y, v->z };
    ring[k] = (struct pl_pt){ c[(drop + 1) % 3], c[(drop + 2) % 3] };
  }
  int st = T74_OK;
  for (int q = 0; q < np && st == T74_OK; q++) {
    const struct scene_vertex *v = &s->v[pf->vidx[q]];
    int64_t d = n[0] * (v->x - a->x) + n[1] * (v->y - a->y) + n[2] * (v->z - a->z);
    if (d != 0) {
      st = t74_fail_at(err, T74_EINPUT, s->file, pf->line, "face %d is `on %d` but its vertex "
                       "%d is not in face %d's plane", pf->id, F->id, v->id, F->id);
      break;
    }
    int64_t c[3] = { v->x, v->y, v->z };
    struct pl_pt t = { c[(drop + 1) % 3], c[(drop + 2) % 3] };
    bool inside = in_ring(t, ring, F->ring_start[1]) >= 0;
    for (int h = 1; h < F->nring && inside; h++)
      if (in_ring(t, ring + F->ring_start[h], F->ring_start[h + 1] - F->ring_start[h]) > 0)
        inside = false;
    if (!inside)
      st = t74_fail_at(err, T74_EINPUT, s->file, pf->line, "face %d is `on %d` but its vertex "
                       "%d lies outside face %d", pf->id, F->id, v->id, F->id);
  }
  free(ring);
  return st;
}

/* `on F` and `texture F FILE`: face ids to indices, patterns checked against their face. */
static int resolve_layers(struct parse *p)
{
  struct scene *s = p->s;
  for (int i = 0; i < s->nf; i++) {
    struct scene_face *f = &s->f[i];
    if (!f->on_id) continue;
    int idx = map_get(&p->fmap, f->on_id);
    if (idx < 0)
      return t74_fail_at(p->err, T74_EINPUT, s->file, f->line, "face %d: `on %u`: no face %u",
                         f->id, f->on_id, f->on_id);
    f->on = idx;
    int st = check_pattern(s, f, &s->f[idx], p->err);
    if (st) return st;
  }
  for (int i = 0; i < s->nf; i++) {        /* a chain of patterns must end on a face */
    int at_ = i, steps = 0;
    while (s->f[at_].on_id && steps <= s->nf) { at_ = s->f[at_].on; steps++; }
    if (steps > s->nf)
      return t74_fail_at(p->err, T74_EINPUT, s->file, s->f[i].line, "face %d: its `on` "
                         "faces go round in a circle", s->f[i].id);
  }
  for (int k = 0; k < p->ntex; k++) {
    struct tex_line *t = &p->tex[k];
    int idx = map_get(&p->fmap, t->face);
    if (idx < 0)
      return t74_fail_at(p->err, T74_EINPUT, s->file, t->line, "texture: no face %d", t->face);
    struct scene_face *f = &s->f[idx];
    if (f->texture)
      return t74_fail_at(p->err, T74_EINPUT, s->file, t->line, "texture: face %d already has "
                         "one (line %d)", t->face, f->texture_line);
    f->texture = t->path;
    f->texture_line = t->line;
    t->path = NULL;
  }
  return T74_OK;
}

static int load_s74(const char *path, const struct scene_opts *opts, struct scene **out,
                    struct t74_error *err)
{
  struct parse p;
  memset(&p, 0, sizeof p);
  p.err = err;
  p.s = calloc(1, sizeof *p.s);
  int st = T74_OK;
  if (!p.s) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  p.s->file = malloc(strlen(path) + 1);
  if (!p.s->file) {
    free(p.s->file);
    p.s->file = NULL;
    st = t74_fail(err, T74_EIO, "%s: out of memory", path);
    goto done;
  }
  strcpy(p.s->file, path);
  if ((st = import_open(&p.r, path, err))) goto done;
  while ((st = import_next(&p.r, err)) == 1)
    if ((st = statement(&p))) break;
  if (st) goto done;
  if ((st = resolve(&p))) goto done;
  if ((st = resolve_layers(&p))) goto done;
  int last = p.r.nlines > 0 ? p.r.nlines : 1;
  if (opts && opts->has_view) {
    memcpy(p.s->view, opts->view, sizeof p.s->view);
    p.s->has_view = true;
    p.view_line = 0;
  }
  if (opts && opts->has_window) {
    memcpy(p.s->window, opts->window, sizeof p.s->window);
    p.s->has_window = true;
    p.window_line = 0;
  }
  if (!p.s->has_view) {
    st = t74_fail_at(err, T74_EINPUT, path, last, "missing `view` statement");
    goto done;
  }
  if (!p.s->has_window) {
    st = t74_fail_at(err, T74_EINPUT, path, last, "missing `window` statement");
    goto done;
  }
  st = scene_check_camera(p.s, p.view_line, p.window_line, err);
done:
  import_close(&p.r);
  map_free(&p.vmap);
  map_free(&p.fmap);
  map_free(&p.omap);
  for (int k = 0; k < p.ntex; k++) free(p.tex[k].path);
  free(p.tex);
  if (st) {
    scene_free(p.s);
    return st;
  }
  *out = p.s;
  return T74_OK;
}

/* Does path end in ext (".obj"), ignoring case? */
static bool ends_with(const char *path, const char *ext)
{
  size_t n = strlen(path), m = strlen(ext);
  if (n < m) return false;
  for (size_t i = 0; i < m; i++) {
    char c = path[n - m + i];
    if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
    if (c != ext[i]) return false;
  }
  return true;
}

const char *scene_kind(const char *path, const struct scene_opts *opts)
{
  return opts && opts->input ? opts->input
         : ends_with(path, ".obj") ? "obj"
         : ends_with(path, ".off") ? "off" : "s74";
}

int scene_load(const char *path, const struct scene_opts *opts, struct scene **out,
               struct t74_error *err)
{
  *out = NULL;
  const char *kind = scene_kind(path, opts);
  if (strcmp(kind, "obj") == 0 || strcmp(kind, "off") == 0)
    return import_load(path, kind, opts, out, err);
  if (strcmp(kind, "s74") == 0) return load_s74(path, opts, out, err);
  return t74_fail(err, T74_EINPUT, "%s: unknown input kind `%s` (s74, obj or off)", path,
                  kind);
}
