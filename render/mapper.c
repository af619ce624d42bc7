/*
** mapper.c — the Mapper (paper 003 §2.2, eq. (1) and (2), Fig. 1, Fig. 2).
**
** This file contains code to take a checked scene to the perspective plane. The paper's
** three coordinate systems coincide (Fig. 2), so a point (x, y, z) seen from the eye
** (X0, Y0, Z0) lands on the plane z = 0 at
**     X' = X0 + (-Z0)/(z - Z0) * (x - X0),   Y' = Y0 + (-Z0)/(z - Z0) * (y - Y0)   (1)
** computed here exactly as a fraction and rounded once, half up, to the plane grid of
** geom.h (1/256 world unit). That rounding is the only approximation of the projection:
** every later decision is exact on the grid polygon. Depth never uses the rounded points:
** it comes from the exact plane of eq. (2), a x + b y + c z + d = 0 through three
** vertices, kept in integers (|a|,|b|,|c| < 2^34, |d| < 2^51) and signed so the eye lies
** on its negative side.
**
** The tables of Fig. 1 / Fig. 8 made here and stored in core:
**   VERTEX  one row per vertex: id, x, y, z, X', Y'            (1 + 3 + 1 + 1 = 6 words)
**   A-BLOCK one row per face: id, grey, y-min, y-max, the plane's a, b, c (one word each),
**           d (a double word) and the B-chain pointer               (4 + 3 + 2 + 1 = 10 words)
** in the paper's formats (Fig. 8 (b); docs/machine.md says which quantity is held in what
** word). tube74 decides on exact values held by the host (|a| < 2^34 ...); the words
** written here are those values as the 1974 program held them (truncated), so that the
** core is charged what the 1974 program needed.
** Departure from the paper: faces are also given a uniform intensity here (grey, or
** Lambert's law from `light`), which the paper reads from its input data. And a face
** that the rounding folds (simple in space, not on the grid: seen almost edge-on or from
** far away) is split on request of the Segment Generator's caller into triangles by
** exact ear clipping in its plane, holes bridged first (mapper_split_face).
*/
#include "render/mapper.h"
#include "render/pool.h"
#include "render/rsort.h"
#include "render/shade.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define VERTEX_ROW_WORDS 6
#define ABLOCK_ROW_WORDS 10
#define DEFAULT_GREY     255    /* a face with neither `grey` nor `light` */

/* floor(n / d) for d > 0: C's quotient rounds toward zero and its remainder takes n's
   sign, so the quotient is one too high exactly when the remainder is negative; that
   compare is subtracted, without a branch */
static int64_t floordiv(int64_t n, int64_t d)
{
  const int64_t q = n / d, r = n % d;
  return q - (r < 0);
}

/* eq. (1) on the grid: round(GRID_ONE * (e + f*(p - e)/w)), half up; w > 0. */
static int64_t project(int64_t p, int64_t e, int64_t f, int64_t w)
{
  /* |num| < 2^8 * (2^15 * 2^17 + 2^16 * 2^16) < 2^42 */
  int64_t num = GRID_ONE * (e * w + f * (p - e));
  return floordiv(2 * num + w, 2 * w);
}

/* floor(sqrt(v)), exactly: the double's square root as the guess (within a step or two
   for v < 2^104: |n|^2 |L|^2 below), then corrected in integers. The root is below 2^64,
   so it is held in 64 bits (x * x in 128: it does not wrap); the double is made from v's
   two halves (a guess: rounding only moves it). */
static uint64_t isqrt_u(uwide v)
{
  const uint64_t top = UINT64_MAX;               /* floor(sqrt(v)) <= top for any v */
  double d = sqrt((double)(uint64_t)(v >> 64) * 0x1p64 + (double)(uint64_t)v);
  uint64_t x = d >= 0x1p64 ? top : (uint64_t)d;
  while ((uwide)x * x > v) x--;
  while (x < top && (uwide)(x + 1) * (x + 1) <= v) x++;
  return x;
}

/* |L|^2 of a light direction, for lambert (made once a run: it depends on the light
   alone) */
static uwide light_ll(const int32_t light[3])
{
  return (uwide)((wide)light[0] * light[0] + (wide)light[1] * light[1] +
                 (wide)light[2] * light[2]);
}

/* Lambert's law's denominator floor(|n| |L|) = isqrt(|n|^2 |L|^2), ll = light_ll(light):
   of the plane's normal (either sign) and the light alone (the greys of both signs are
   kept with the planes from run to run: struct mapper_keep's lgrey). */
static uint64_t lambert_den(const int64_t n[3], uwide ll)
{
  uwide nn = (uwide)((wide)n[0] * n[0] + (wide)n[1] * n[1] + (wide)n[2] * n[2]);
  /* |n|^2 < 2^70, |L|^2 < 2^32: the product fits, and so does its square root */
  return isqrt_u(nn * ll);
}

/* Lambert's law with an ambient floor; n points away from the eye (plane(eye) < 0); den is
   lambert_den(n, light_ll(light)). The dot product in 64 bits: |n_i| < 2^34 and |L_i| <=
   2^15 (a light is given in scene coordinates, SCENE_COORD_MIN .. MAX), so each product
   is below 2^49 in size and the sum below 2^51 (the same integer as in 128 bits). */
static int lambert(const int64_t n[3], const int32_t light[3], uint64_t den)
{
  int64_t dot = -(n[0] * light[0] + n[1] * light[1] + n[2] * light[2]);
  if (dot <= 0) return SHADE_AMBIENT;
  if (den == 0) return DEFAULT_GREY;
  /* 0 < dot <= |n| |L| < 2^51 (Cauchy-Schwarz) and den <= |n| |L|: the rounded quotient
     in 64 bits, (255 - SHADE_AMBIENT) dot + den / 2 < 2^59 + 2^50 (no 128-bit division) */
  uint64_t g = SHADE_AMBIENT + ((uint64_t)(255 - SHADE_AMBIENT) * (uint64_t)dot + den / 2) / den;
  return g > 255 ? 255 : (int)g;
}

/* The flat grey of a face shaded from the scene's lights: one parallel light by the exact
   integer law above (the 1974 figures; ll: light_ll of that light); several lights or
   point lights by shade_grey at the mean of the face's outer vertices (render/shade.h). */
static int face_grey(const struct scene *s, const struct mface *m, const int64_t pl[4],
                     uwide ll)
{
  if (!s->has_light) return DEFAULT_GREY;
  if (s->nlight == 1 && !s->light[0].point)
    return lambert(pl, s->light[0].v, lambert_den(pl, ll));
  double n[3] = { -(double)pl[0], -(double)pl[1], -(double)pl[2] }, c[3] = { 0, 0, 0 };
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int k = 0; k < 3; k++) n[k] /= len;
  int nv = m->ring_start[1];
  for (int v = 0; v < nv; v++) {
    const struct scene_vertex *p = &s->v[m->vix[v]];
    c[0] += p->x; c[1] += p->y; c[2] += p->z;
  }
  for (int k = 0; k < 3; k++) c[k] /= nv;
  return shade_grey(s, n, c, 1.0, 0);
}

/* Twice the ring's signed area, exactly: |gcoord| <= GRID_LIMIT = 2^28 (the vertices were
   checked), so each edge's cross product is below 2^57 in 64 bits; the sum is kept in 64
   bits for a ring of fewer than 64 points, in 128 for a longer one. */
static wide ring_area2(const struct gpoint *p, int n)
{
  /* a triangle or a quadrilateral, the common rings: the same integer as the sum below,
     as one cross product of differences, (p1 - p0) x (p2 - p0) or of the diagonals
     (p2 - p0) x (p3 - p1) (each below 2^29 in size: the products below 2^58, their
     difference below 2^59) */
  if (n == 3)
    return (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
  if (n == 4)
    return (p[2].x - p[0].x) * (p[3].y - p[1].y) - (p[2].y - p[0].y) * (p[3].x - p[1].x);
  if (n < 64) {              /* below 64 * 2^57 = 2^63: the same integer */
    int64_t a = 0;
    for (int j = n - 1, k = 0; k < n; j = k++)
      a += p[j].x * p[k].y - p[k].x * p[j].y;
    return a;
  }
  wide a = 0;
  for (int j = n - 1, k = 0; k < n; j = k++)
    a += p[j].x * p[k].y - p[k].x * p[j].y;
  return a;
}

/* ring_reverse of a ring of three points where rev, else nothing, without a branch: the
   first and last points swapped (the middle one stays), by masks (all ones where rev). */
static inline void swap3(struct gpoint *p, uint32_t *id, int32_t *vix, bool rev)
{
  const uint64_t m = -(uint64_t)rev;
  const uint32_t m32 = (uint32_t)m;
  const uint64_t x = ((uint64_t)p[0].x ^ (uint64_t)p[2].x) & m,
                 y = ((uint64_t)p[0].y ^ (uint64_t)p[2].y) & m;
  p[0].x = (gcoord)((uint64_t)p[0].x ^ x);
  p[2].x = (gcoord)((uint64_t)p[2].x ^ x);
  p[0].y = (gcoord)((uint64_t)p[0].y ^ y);
  p[2].y = (gcoord)((uint64_t)p[2].y ^ y);
  const uint32_t i = (id[0] ^ id[2]) & m32, v = ((uint32_t)vix[0] ^ (uint32_t)vix[2]) & m32;
  id[0] ^= i;
  id[2] ^= i;
  vix[0] = (int32_t)((uint32_t)vix[0] ^ v);
  vix[2] = (int32_t)((uint32_t)vix[2] ^ v);
}

static void ring_reverse(struct gpoint *p, uint32_t *id, int32_t *vix, int n)
{
  for (int a = 0, b = n - 1; a < b; a++, b--) {
    struct gpoint tp = p[a]; p[a] = p[b]; p[b] = tp;
    uint32_t ti = id[a]; id[a] = id[b]; id[b] = ti;
    int32_t tv = vix[a]; vix[a] = vix[b]; vix[b] = tv;
  }
}

/* ring_three's and ring_four's ends: the n kept scene vertices w[0 .. n) in ring order into
   vid (their ids) and vix (their indices), and with a cost what the ring loop charges for
   a ring of n points it keeps (2 n words, one product). */
static inline void ring_ids(const struct scene *s, const int *w, int n, uint32_t *vid,
                            int32_t *vix, struct cost *cost)
{
  for (int k = 0; k < n; k++) {
    vid[k] = s->v[w[k]].id;
    vix[k] = w[k];
  }
  if (cost) {
    COST_ADD_N(cost, COST_MEM, 2 * (uint64_t)n);
    cost_mw_mul(cost, 29, 29);
  }
}

/* A face's one ring of three scene vertices r[0 .. 3) (a triangle, the common face) into
   pt, vid, vix as mapper_run_kept's ring loop puts it, without the loop's steps, where its
   three grid points are apart and not on one line, i.e. where the cross product below is
   not 0 (two points at one make it 0): the loop then keeps all three in order, its twice
   area is this cross product (ring_area2's for three points, in 64 bits), and it is swapped
   end for end (swap3) where that is negative; the loop's charges with a cost. False
   (nothing charged): the loop's to do (it drops a point or the face). */
static inline bool ring_three(const struct scene *s, const struct gpoint *proj, const int *r,
                              struct gpoint *pt, uint32_t *vid, int32_t *vix, struct cost *cost)
{
  const int v0 = r[0], v1 = r[1], v2 = r[2];
  const struct gpoint p0 = proj[v0], p1 = proj[v1], p2 = proj[v2];
  const int64_t area = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
  if (area == 0) return false;                  /* (so too where two are one point) */
  const bool rev = area < 0;
  const int w0 = rev ? v2 : v0, w2 = rev ? v0 : v2;
  pt[0] = rev ? p2 : p0;
  pt[1] = p1;
  pt[2] = rev ? p0 : p2;
  const int w[3] = { w0, v1, w2 };
  ring_ids(s, w, 3, vid, vix, cost);
  return true;
}

/* ring_three for a ring of four scene vertices r[0 .. 4) (a quadrilateral): where no two
   consecutive grid points (the last and the first too) are one point, the loop keeps all
   four in order (two points apart in the ring may be one: the loop drops only a point
   equal to the one before it), its twice area is ring_area2's for four points (the
   diagonals' cross product), and it is reversed (ring_reverse) where that is negative;
   where the area is 0 the loop drops the face. False (nothing charged): the loop's. */
static inline bool ring_four(const struct scene *s, const struct gpoint *proj, const int *r,
                             struct gpoint *pt, uint32_t *vid, int32_t *vix, struct cost *cost)
{
  const struct gpoint p0 = proj[r[0]], p1 = proj[r[1]], p2 = proj[r[2]], p3 = proj[r[3]];
  const int64_t area = (p2.x - p0.x) * (p3.y - p1.y) - (p2.y - p0.y) * (p3.x - p1.x);
  const bool same = (p0.x == p1.x && p0.y == p1.y) || (p1.x == p2.x && p1.y == p2.y) ||
                    (p2.x == p3.x && p2.y == p3.y) || (p3.x == p0.x && p3.y == p0.y);
  if (same || area == 0) return false;
  const bool rev = area < 0;
  const int w0 = rev ? r[3] : r[0], w1 = rev ? r[2] : r[1], w2 = rev ? r[1] : r[2],
            w3 = rev ? r[0] : r[3];
  pt[0] = rev ? p3 : p0;
  pt[1] = rev ? p2 : p1;
  pt[2] = rev ? p1 : p2;
  pt[3] = rev ? p0 : p3;
  const int w[4] = { w0, w1, w2, w3 };
  ring_ids(s, w, 4, vid, vix, cost);
  return true;
}

/* A face's ring_start, pt, vid, vix: in the pool (mapper_run), or four allocations (the
   triangles of a split face). */
static void mface_arrays_free(struct mface *m)
{
  if (!m->pooled) { free(m->ring_start); free(m->pt); free(m->vid); free(m->vix); }
  m->pooled = false;
  m->ring_start = NULL; m->pt = NULL; m->vid = NULL; m->vix = NULL;
}

/* ---- T-junctions ---------------------------------------------------------------------
   A vertex that lies exactly on another face's edge in space (a T-junction) is inserted
   into that edge before anything else is done with the face. Projection and rounding then
   give both faces the very same grid point there, so the faces still meet exactly on the
   plane grid: rounding each vertex on its own would otherwise leave a crack or an overlap
   up to half a grid unit wide along the edge. */

struct tjunc {
  const struct scene *s;
  const struct gpoint *proj;
  int *used_v;                   /* vertices used by faces, by index (their x order is
                                    only counted: lb, ub) */
  int n;
  /* the host's index (issue 12): the same vertices bucketed by projected (x, y) on a
     gw x gh grid of cells 2^sx x 2^sy wide from (gx0, gy0) (shifts, not divisions:
     four a T-junction search); cell c holds
     cell_v[cell_start[c] .. cell_start[c+1]). Only where to look: every candidate is
     still tested exactly, and the 1974 cost counts the x-slab the program scanned. */
  gcoord gx0, gy0;
  int sx, sy;
  int gw, gh;
  int *cell_start, *cell_v;
  struct gpoint *cell_p;         /* proj[cell_v[k]], kept beside it (no indirection) */
  int *lb, *ub;                  /* by vertex: the first place in the x order (by
                                    projected x, then index) with its x, and the first with
                                    a larger x (the x-slab's ends) */
  bool whole_boxes;              /* every cell of an edge's box (mapper_keep.whole_boxes) */
  bool counted;                  /* the 1974 charges wanted (the 1974 engine): the x-slab
                                    (lb, ub) and the box's vertices counted; else (the
                                    points engine) only the vertices found matter, and
                                    lb, ub are not made */
};


static void tj_free(struct tjunc *t)
{
  free(t->used_v);
  free(t->cell_start);
  free(t->cell_v);
  free(t->lb);
  free(t->ub);
  free(t->cell_p);
  t->used_v = t->cell_start = t->cell_v = t->lb = t->ub = NULL;
  t->cell_p = NULL;
}

static int tj_init(struct tjunc *t, const struct scene *s, const struct gpoint *proj,
                   bool counted)
{
  memset(t, 0, sizeof *t);
  t->s = s;
  t->proj = proj;
  t->counted = counted;
  char *used = calloc((size_t)(s->nv ? s->nv : 1), 1);
  t->used_v = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *t->used_v);
  if (!used || !t->used_v) { free(used); free(t->used_v); t->used_v = NULL; return 0; }
  for (int f = 0; f < s->nf; f++) {         /* (the face's count and array held: the
                                               stores into used could alias them) */
    const int *vi = s->f[f].vidx;
    for (int k = 0, nk = s->f[f].ring_start[s->f[f].nring]; k < nk; k++) used[vi[k]] = 1;
  }
  /* the used vertices in index order, and the box of their points (for the cells below) */
  gcoord x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (int v = 0; v < s->nv; v++) {
    if (!used[v]) continue;
    struct gpoint p = proj[v];
    if (t->n == 0 || p.x < x0) x0 = p.x;
    if (t->n == 0 || p.x > x1) x1 = p.x;
    if (t->n == 0 || p.y < y0) y0 = p.y;
    if (t->n == 0 || p.y > y1) y1 = p.y;
    t->used_v[t->n++] = v;
  }
  free(used);
  /* sorted once by projected x, then by index (a radix sort of (x, index) pairs,
     render/rsort.h: the same total order), with each vertex's slab bounds for the cost
     count (not wanted under the points engine) */
  if (counted) {
    struct rs_pair *key = malloc((size_t)(t->n ? 2 * t->n : 1) * sizeof *key);
    t->lb = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *t->lb);
    t->ub = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *t->ub);
    if (!key || !t->lb || !t->ub) { free(key); tj_free(t); return 0; }
    for (int k = 0; k < t->n; k++) {
      key[k].key = proj[t->used_v[k]].x;
      key[k].idx = t->used_v[k];
    }
    rsort_pairs(key, key + t->n, t->n);
    for (int k = 0; k < t->n;) {               /* a run of equal x: [k, e) */
      int e = k;
      while (e < t->n && key[e].key == key[k].key) e++;
      for (int q = k; q < e; q++) { t->lb[key[q].idx] = k; t->ub[key[q].idx] = e; }
      k = e;
    }
    free(key);
  }
  /* the cells: about two a vertex (at 100,000 boxes the Mapper took some 8% less time
     than with two vertices a cell; the order of the vertices found does not depend on
     the cells) */
  int side = 1;
  while ((int64_t)side * side < 2 * (int64_t)t->n && side < 4096) side++;
  t->gx0 = x0;
  t->gy0 = y0;
  while ((x1 - x0) >> t->sx >= side) t->sx++;     /* the narrowest cells that make at */
  while ((y1 - y0) >> t->sy >= side) t->sy++;     /* most side x side of them */
  t->gw = (int)((x1 - x0) >> t->sx) + 1;
  t->gh = (int)((y1 - y0) >> t->sy) + 1;
  size_t ncell = (size_t)t->gw * (size_t)t->gh;
  t->cell_start = calloc(ncell + 1, sizeof *t->cell_start);
  t->cell_v = malloc((size_t)(t->n ? t->n : 1) * sizeof *t->cell_v);
  t->cell_p = malloc((size_t)(t->n ? t->n : 1) * sizeof *t->cell_p);
  if (!t->cell_start || !t->cell_v || !t->cell_p) { tj_free(t); return 0; }
  for (int k = 0; k < t->n; k++) {
    struct gpoint p = proj[t->used_v[k]];
    t->cell_start[(size_t)((p.y - y0) >> t->sy) * (size_t)t->gw + (size_t)((p.x - x0) >> t->sx) + 1]++;
  }
  for (size_t c = 0; c < ncell; c++) t->cell_start[c + 1] += t->cell_start[c];
  int *fill = malloc((ncell ? ncell : 1) * sizeof *fill);
  if (!fill) { tj_free(t); return 0; }
  memcpy(fill, t->cell_start, ncell * sizeof *fill);
  for (int k = 0; k < t->n; k++) {
    struct gpoint p = proj[t->used_v[k]];
    size_t c = (size_t)((p.y - y0) >> t->sy) * (size_t)t->gw + (size_t)((p.x - x0) >> t->sx);
    t->cell_p[fill[c]] = p;
    t->cell_v[fill[c]++] = t->used_v[k];
  }
  free(fill);
  return 1;
}

/* The band of cell row cy: the columns that can hold a vertex lying inside the segment
   a-b in space, for a slanted edge (pa.y != pb.y).
   Such a vertex V projects exactly onto the segment between the exact projections A*, B*
   of a and b (a perspective takes segments to segments): V* = t A* + (1 - t) B*. Each
   grid point is its exact projection rounded half up, off by e in (-1/2, 1/2] in x and
   in y, so Q = t pa + (1 - t) pb is off V* by such an e too (a blend of A*'s and B*'s),
   and V's grid point pv off Q by less than 1: |pv.x - Q.x| < 1, |pv.y - Q.y| < 1, Q a
   point of the segment pa-pb. So with pv in the row's band [r0, r1] (r0 = max(B(cy) - 1,
   lo.y), r1 = min(B(cy + 1), hi.y), B(c) = gy0 + c 2^sy the first y of row c, lo and hi
   the ends with the smaller and larger y), Q.y lies in [r0 - 1, r1 + 1], where the
   segment's x lies in [xlo, xhi], its values at the band's ends (x is linear in y along
   it), and the integer pv.x in (xlo - 1, xhi + 1): from floor(xlo) to floor(xhi) + 1
   (the y margin and these x ends are tight: test_mapper's one-unit cells fail with either
   y end a unit nearer or either x end). A superset of the cells, never fewer: every
   vertex in them is still tested exactly, and which are found (and their order) does not
   depend on the cells. tj_edge and tj_edge_near both step the x ends from row to row
   (floor((r - lo.y) dx / dy) kept as quotient and remainder), with no divide a row. */

/* One edge's search: a-b in space, its grid box, and where the vertices found go. */
struct tj_seg {
  int a, b;
  const struct scene_vertex *A;
  int64_t dx, dy, dz, dd;        /* b - a, |b - a|^2 */
  gcoord x0, x1, y0, y1;         /* the box of a' and b' */
  int64_t px, py;                /* b' - a' */
  int64_t c0;                    /* px a'.y - py a'.x - (wband - 1) (tj_near) */
  uint64_t wlim;                 /* 2 (wband - 1), wband = |px| + |py| or 1 when a' = b' */
  int **buf, *n, *cap;
  int first;                     /* the edge's first entry of buf */
};

/* Vertex v, found at parameter tt strictly inside a-b (tj_take), inserted in order. 0
   when out of host memory. (Out of line: few vertices get here.) */
static __attribute__((noinline)) int tj_insert(const struct tjunc *t, int v, int64_t tt,
                                               const struct tj_seg *e)
{
  const struct scene_vertex *A = e->A;
  if (*e->n == *e->cap) {
    int cp = *e->cap ? 2 * *e->cap : 64;
    int *nb = realloc(*e->buf, (size_t)cp * sizeof *nb);
    if (!nb) return 0;
    *e->buf = nb;
    *e->cap = cp;
  }
  /* insertion by the parameter along a-b, then the index (few vertices per edge) */
  int *buf = *e->buf, j = (*e->n)++;
  while (j > e->first) {
    int w = buf[j - 1];
    const struct scene_vertex *W = &t->s->v[w];
    int64_t tw = (W->x - A->x) * e->dx + (W->y - A->y) * e->dy + (W->z - A->z) * e->dz;
    if (tw < tt || (tw == tt && w < v)) break;
    buf[j] = w;
    j--;
  }
  buf[j] = v;
  return 1;
}

/* tj_near: whether a vertex at grid point pv can lie on a-b, a test on the grid that only
   rejects vertices that cannot (so it changes nothing found; it spares most of them the
   scene's vertex and tj_take's three products in space). As the band's comment above
   says, such a vertex's point pv lies off some point Q of the segment a'-b' by less than
   one unit in x and in y. With d = b' - a' = (px, py), Q on the line: px (Q.y - a'.y) -
   py (Q.x - a'.x) = 0, so c = px (pv.y - a'.y) - py (pv.x - a'.x) = px (pv.y - Q.y) -
   py (pv.x - Q.x), and |c| < |px| + |py| when d is not zero (each difference below 1 in
   size, one of |px|, |py| at least 1). Rejected: |c| >= wband = |px| + |py|, as the one
   unsigned compare c + wband - 1 > 2 (wband - 1), c + wband - 1 taken as
   px pv.y - py pv.x - c0 with c0 = px a'.y - py a'.x - (wband - 1) made once an edge.
   When a' = b', c is 0 and wband is 1: nothing rejected. |px|, |py| <= 2^29 and |pv.x|,
   |pv.y|, |a'.x|, |a'.y| <= 2^28 (|gcoord| <= 2^28), so each product is below 2^57 in
   size, c0 below 2^59 and the sum below 2^60: no overflow.
   tj_take: vertex v (not a or b) tested exactly: when it lies strictly inside a-b in
   space, it is inserted in order. 0 when out of host memory. (Both inlined in the cells'
   loops: at 30,000 boxes 139,000 calls a search.) */
static inline __attribute__((always_inline)) bool tj_near(struct gpoint pv,
                                                          const struct tj_seg *e)
{
  return (uint64_t)(e->px * pv.y - e->py * pv.x - e->c0) <= e->wlim;
}

/* e's line for tj_near (px, py, c0, wlim), of a' = pa and b' = pb. */
static inline void tj_seg_line(struct tj_seg *e, struct gpoint pa, struct gpoint pb)
{
  e->px = pb.x - pa.x;
  e->py = pb.y - pa.y;
  int64_t wband = (e->px < 0 ? -e->px : e->px) + (e->py < 0 ? -e->py : e->py);
  if (wband == 0) wband = 1;
  e->c0 = e->px * pa.y - e->py * pa.x - (wband - 1);
  e->wlim = 2 * (uint64_t)(wband - 1);
}

static inline __attribute__((always_inline)) int tj_take(const struct tjunc *t, int v,
                                                         const struct tj_seg *e)
{
  const struct scene_vertex *V = &t->s->v[v], *A = e->A;
  int64_t ex = V->x - A->x, ey = V->y - A->y, ez = V->z - A->z;
  if (e->dy * ez - e->dz * ey || e->dz * ex - e->dx * ez || e->dx * ey - e->dy * ex) return 1;
  int64_t tt = ex * e->dx + ey * e->dy + ez * e->dz;
  if (tt <= 0 || tt >= e->dd) return 1;
  return tj_insert(t, v, tt, e);
}

/* The fields of e that tj_take and tj_insert use (A, b - a and its square), set when
   tj_cells or tj_cells_near first needs them: most edges meet no vertex but a and b in
   their box or on the grid (at 100,000 boxes, tj_near passes some four vertices an edge,
   a and b among them), so most never load the scene's vertices. (Out of line: few edges
   get here.) */
static __attribute__((noinline)) void tj_seg_space(const struct tjunc *t, struct tj_seg *e)
{
  const struct scene_vertex *A = &t->s->v[e->a], *B = &t->s->v[e->b];
  e->A = A;
  e->dx = B->x - A->x; e->dy = B->y - A->y; e->dz = B->z - A->z;
  e->dd = e->dx * e->dx + e->dy * e->dy + e->dz * e->dz;
}

/* The vertex of cell entry k, but a and b, tested in space (tj_take; e's fields in space
   set first, tj_seg_space, when the edge has none yet): 0 when out of host memory. */
static inline __attribute__((always_inline)) int tj_try(const struct tjunc *t, int k,
                                                        struct tj_seg *e)
{
  int v = t->cell_v[k];
  if (v == e->a || v == e->b) return 1;
  if (!e->A) tj_seg_space(t, e);
  return tj_take(t, v, e);
}

/* The vertices of cells c0 .. c1 (of one row: their vertices are one run of cell_v)
   inside e's box, each but a and b that the grid test lets through (tj_near: it rejects
   only vertices that cannot lie on a-b) given to tj_take. Returns how many lay in the box
   (a and b too), -1 when out of host memory. (Inlined: the loop of tj_edge, where most
   vertices fail the box. Both tests are made without a branch, the box's outcome added
   to the count: which vertices lie in the box follows no pattern a branch predictor
   learns, while a vertex in the box and near the line other than a and b, the one branch
   taken, is rare. Without the grid test, 1,280 interpenetrating triangles, whose long
   edges' boxes hold many vertices, gave 235,000 vertices to tj_take, each a scene vertex
   loaded and three products, behind a branch taken at random: tj_edge was 26.2 M
   instructions of the whole process's 383.6 M, 19.1 M with it, and some 6% of the
   samples, 3.5% with it.) */
static inline __attribute__((always_inline)) int tj_cells(const struct tjunc *t, size_t c0,
                                                          size_t c1, struct tj_seg *e)
{
  const struct gpoint *cp = t->cell_p;
  const int *cv = t->cell_v;
  const gcoord x0 = e->x0, x1 = e->x1, y0 = e->y0, y1 = e->y1;
  const int a = e->a, b = e->b;
  int inbox = 0;
  for (int k = t->cell_start[c0], end = t->cell_start[c1 + 1]; k < end; k++) {
    struct gpoint pv = cp[k];
    int v = cv[k];
    int in = (pv.x >= x0) & (pv.x <= x1) & (pv.y >= y0) & (pv.y <= y1);
    inbox += in;
    if (in & (v != a) & (v != b) & tj_near(pv, e)) {
      if (!e->A) tj_seg_space(t, e);
      if (!tj_take(t, v, e)) return -1;
    }
  }
  return inbox;
}

/* As tj_cells, with no count (the points engine): a vertex is tested on the grid first
   (tj_near: most in the cells a slanted edge's line reaches lie off it), then in space
   (tj_take, which also rejects one beyond a or b: no box test; e's space fields set
   first, tj_seg_space, when the edge has none yet). 0, or -1 when out of host memory. */
static inline __attribute__((always_inline)) int tj_cells_near(const struct tjunc *t,
                                                               size_t c0, size_t c1,
                                                               struct tj_seg *e)
{
  for (int k = t->cell_start[c0], end = t->cell_start[c1 + 1]; k < end; k++) {
    struct gpoint pv = t->cell_p[k];
    if (!tj_near(pv, e)) continue;
    if (!tj_try(t, k, e)) return -1;
  }
  return 0;
}

/* tj_edge without a count (the points engine): only the vertices found matter. Of a
   slanted edge's box with three columns or more, in every row, first and last too, only
   the cells its line can reach (the band above, whose argument holds in any row of
   the box); else the box's cells. In those cells a vertex is tested on the grid first
   (tj_near), then in space (tj_take); no box test: tj_take rejects what lies beyond a or
   b. The same vertices are found as when every cell of the box is looked at, in the same
   order: a vertex outside those cells cannot lie on a-b, and tj_insert orders the
   vertices found by their parameter along a-b and their index, whatever order the cells
   give them in. 0 when out of host memory.
   The band of row cy is from the line's x at r0 = max(B(cy) - 1, lo.y) and
   r1 = min(B(cy + 1), hi.y), B(c) = gy0 + c 2^sy the first y of row c, lo and hi the ends
   with the smaller and larger y. In the first row r0 = lo.y (lo lies in it: the x is
   lo.x), in the last r1 = hi.y (the x is hi.x); between, B(cy) - 1 and B(cy + 1) lie in
   [lo.y, hi.y] and step by 2^sy a row: each x, lo.x + floor((r - lo.y) dx / dy), is kept
   as quotient and remainder and stepped by the quotient and remainder of 2^sy dx by dy,
   exactly (as floordiv would give it). |dx| < 2^30, 2^sy <= 2^29 (the cells split the
   vertices' range): the products stay below 2^59. */
static int tj_edge_near(const struct tjunc *t, int a, int b, int **buf, int *n, int *cap)
{
  if (t->n == 0) return 1;
  struct gpoint pa = t->proj[a], pb = t->proj[b];
  struct tj_seg es, *e = &es;               /* the fields used here, set one by one (an
                                               initializer would zero the box too); those
                                               in space when needed (A NULL: not yet) */
  e->a = a; e->b = b; e->A = NULL; e->buf = buf; e->n = n; e->cap = cap; e->first = *n;
  tj_seg_line(e, pa, pb);
  /* the box's cells (the grid holds a' and b': no clamping) */
  gcoord cx0 = ((pa.x < pb.x ? pa.x : pb.x) - t->gx0) >> t->sx;
  gcoord cx1 = ((pa.x < pb.x ? pb.x : pa.x) - t->gx0) >> t->sx;
  gcoord cy0 = ((pa.y < pb.y ? pa.y : pb.y) - t->gy0) >> t->sy;
  gcoord cy1 = ((pa.y < pb.y ? pb.y : pa.y) - t->gy0) >> t->sy;
  size_t gw = (size_t)t->gw;
  if (t->whole_boxes || pa.y == pb.y || cx1 - cx0 < 2) {
    for (gcoord cy = cy0; cy <= cy1; cy++)
      if (tj_cells_near(t, (size_t)cy * gw + (size_t)cx0, (size_t)cy * gw + (size_t)cx1, e) < 0)
        return 0;
    return 1;
  }
  struct gpoint lo = pa.y < pb.y ? pa : pb, hi = pa.y < pb.y ? pb : pa;
  int64_t dx = hi.x - lo.x, dy = hi.y - lo.y;           /* dy > 0 */
  int64_t step = dx * ((int64_t)1 << t->sy);
  int64_t sq = floordiv(step, dy), sr = step - sq * dy;  /* 0 <= sr < dy */
  gcoord b1 = t->gy0 + ((cy0 + 1) << t->sy);             /* B(cy0 + 1) */
  int64_t qa = floordiv((b1 - 1 - lo.y) * dx, dy), ra = (b1 - 1 - lo.y) * dx - qa * dy;
  int64_t qb = floordiv((b1 - lo.y) * dx, dy), rb = (b1 - lo.y) * dx - qb * dy;
  for (gcoord cy = cy0; cy <= cy1; cy++) {
    int64_t xa = lo.x, xb = hi.x;           /* the first row's r0, the last row's r1 */
    if (cy > cy0) {                         /* r0 = B(cy) - 1 */
      xa = lo.x + qa;
      qa += sq; ra += sr;
      if (ra >= dy) { ra -= dy; qa++; }
    }
    if (cy < cy1) {                         /* r1 = B(cy + 1) */
      xb = lo.x + qb;
      qb += sq; rb += sr;
      if (rb >= dy) { rb -= dy; qb++; }
    }
    int64_t x0 = xa < xb ? xa : xb, x1 = (xa < xb ? xb : xa) + 1;   /* (x - 1, x + 1) */
    gcoord ca = (x0 - t->gx0) >> t->sx, cb = (x1 - t->gx0) >> t->sx;  /* x0 >= the box's */
    if (ca < cx0) ca = cx0;
    if (cb > cx1) cb = cx1;
    size_t row = (size_t)cy * gw;
    if (ca <= cb && tj_cells_near(t, row + (size_t)ca, row + (size_t)cb, e) < 0) return 0;
  }
  return 1;
}

/* Append to (*buf, *n) the vertices lying strictly inside the segment a-b in space,
   ordered from a to b (two at one point of space: by vertex index, as the x-ordered scan
   of the 1974 program meets them). Rounding is monotone, so such a vertex projects inside
   the grid box of a' and b': only those are tested, exactly. The 1974 program scans the
   x-slab of the box (2 loads a vertex) and tests each vertex inside the box in space (a
   product of 17-bit operands); the host finds the same vertices through the cells that
   meet the box, and of a slanted edge's box, in the rows between its first and last,
   only through the cells its line can reach (the band above) and the first and last
   column: the box's vertices in the other cells, which lie wholly inside it, are counted
   from the cells' starts, not looked at; of those looked at, only the ones that pass the
   grid test (tj_near) are tested in space, as tj_edge_near does: the same vertices
   found, the same count charged. (The 1974 engine's search, which counts; the
   points engine's, which does not, is tj_edge_near.)
   A row between the first and last, cy0 < cy < cy1, has r0 = B(cy) - 1 and r1 = B(cy + 1)
   (lo lies in row cy0, hi in row cy1: B(cy0 + 1) - 1 >= lo.y, B(cy1) <= hi.y): each x
   end, lo.x + floor((r - lo.y) dx / dy), is kept as quotient and remainder and stepped by
   the quotient and remainder of 2^sy dx by dy, exactly (as floordiv would give it), as
   tj_edge_near does. |dx| < 2^30, r - lo.y <= 2^(sy + 1) <= 2^30: the products stay
   below 2^60. */
static int tj_edge(const struct tjunc *t, int a, int b, int **buf, int *n, int *cap,
                   struct cost *cost, uint64_t *tests)
{
  struct gpoint pa = t->proj[a], pb = t->proj[b];
  struct tj_seg e;              /* the fields used here, set one by one (an initializer
                                   would zero the whole struct: a string store, slow to
                                   start, on every edge); those in space when needed (A
                                   NULL: not yet) */
  e.a = a; e.b = b; e.A = NULL; e.buf = buf; e.n = n; e.cap = cap; e.first = *n;
  tj_seg_line(&e, pa, pb);
  e.x0 = pa.x < pb.x ? pa.x : pb.x; e.x1 = pa.x < pb.x ? pb.x : pa.x;
  e.y0 = pa.y < pb.y ? pa.y : pb.y; e.y1 = pa.y < pb.y ? pb.y : pa.y;
  /* the slab [x0, x1] of the x order: from the first vertex with a's or b's smaller x to
     the last with the larger */
  int lo_v = pa.x < pb.x ? a : b, hi_v = pa.x < pb.x ? b : a;
  COST_ADD_N(cost, COST_MEM, 2 * (t->ub[hi_v] - t->lb[lo_v]));
  if (t->n == 0) return 1;
  gcoord cx0 = e.x0 < t->gx0 ? 0 : (e.x0 - t->gx0) >> t->sx, cx1 = (e.x1 - t->gx0) >> t->sx;
  gcoord cy0 = e.y0 < t->gy0 ? 0 : (e.y0 - t->gy0) >> t->sy, cy1 = (e.y1 - t->gy0) >> t->sy;
  if (cx1 >= t->gw) cx1 = t->gw - 1;
  if (cy1 >= t->gh) cy1 = t->gh - 1;
  size_t gw = (size_t)t->gw;
  int64_t inbox = 0;                        /* the box's vertices, a and b among them */
  int got;
  if (t->whole_boxes || cy1 - cy0 < 2 || cx1 - cx0 < 2 || pa.y == pb.y) {
    for (gcoord cy = cy0; cy <= cy1; cy++) {         /* every cell */
      size_t row = (size_t)cy * gw;
      if ((got = tj_cells(t, row + (size_t)cx0, row + (size_t)cx1, &e)) < 0) return 0;
      inbox += got;
    }
    *tests += (uint64_t)(inbox - (a == b ? 1 : 2));   /* but a and b */
    return 1;
  }
  /* the first row: every cell */
  size_t first = (size_t)cy0 * gw, last = (size_t)cy1 * gw;
  if ((got = tj_cells(t, first + (size_t)cx0, first + (size_t)cx1, &e)) < 0) return 0;
  inbox += got;
  struct gpoint lo = pa.y < pb.y ? pa : pb, hi = pa.y < pb.y ? pb : pa;
  int64_t dx = hi.x - lo.x, dy = hi.y - lo.y;           /* dy > 0 */
  int64_t step = dx * ((int64_t)1 << t->sy);
  int64_t sq = floordiv(step, dy), sr = step - sq * dy;  /* 0 <= sr < dy */
  int64_t ya = t->gy0 + ((cy0 + 1) << t->sy) - 1 - lo.y;  /* B(cy0 + 1) - 1 - lo.y */
  int64_t yb = ya + 1 + ((int64_t)1 << t->sy);           /* B(cy0 + 2) - lo.y */
  int64_t qa = floordiv(ya * dx, dy), ra = ya * dx - qa * dy;
  int64_t qb = floordiv(yb * dx, dy), rb = yb * dx - qb * dy;
  for (gcoord cy = cy0 + 1; cy < cy1; cy++) {
    /* a row between: the first and last column looked at, the others' vertices counted
       (they lie in the box), and of those only the cells the line can reach looked at */
    size_t row = (size_t)cy * gw;
    inbox += t->cell_start[row + (size_t)cx1] - t->cell_start[row + (size_t)cx0 + 1];
    if ((got = tj_cells(t, row + (size_t)cx0, row + (size_t)cx0, &e)) < 0) return 0;
    inbox += got;
    if ((got = tj_cells(t, row + (size_t)cx1, row + (size_t)cx1, &e)) < 0) return 0;
    inbox += got;
    int64_t xa = lo.x + qa, xb = lo.x + qb;
    qa += sq; ra += sr;
    if (ra >= dy) { ra -= dy; qa++; }
    qb += sq; rb += sr;
    if (rb >= dy) { rb -= dy; qb++; }
    int64_t x0 = xa < xb ? xa : xb, x1 = (xa < xb ? xb : xa) + 1;   /* (x - 1, x + 1) */
    gcoord ca = (x0 - t->gx0) >> t->sx, cb = (x1 - t->gx0) >> t->sx;  /* x0 >= the box's */
    if (ca < cx0 + 1) ca = cx0 + 1;
    if (cb > cx1 - 1) cb = cx1 - 1;
    if (ca <= cb && tj_cells(t, row + (size_t)ca, row + (size_t)cb, &e) < 0) return 0;
  }
  /* the last row: every cell */
  if ((got = tj_cells(t, last + (size_t)cx0, last + (size_t)cx1, &e)) < 0) return 0;
  inbox += got;
  *tests += (uint64_t)(inbox - (a == b ? 1 : 2));   /* but a and b */
  return 1;
}

/* Edges met the other way (issue 19): most edges of a closed surface are the edges of
   two faces, a-b of one and b-a of the other, and the search finds the same vertices for
   both: those lying strictly inside the segment in space, with the same box, cells and
   exact tests, so the same count of tests and the same x-slab charge (lb and ub are one
   run's where a' and b' have one x). Of an edge searched, where its vertices went in the
   kept rings and its tests are noted in a small table the unordered pair hashes into (the
   newest kept); an edge found there is not searched again: its vertices are copied, in
   the other order when it is met the other way, those at one point of space (equal
   parameters along the edge) still by index (tj_insert's order both ways). The faces of
   one box come one after another in a file, so the edge's other face follows within a
   few edges. */
#define TJ_MEMO_BITS 10u
struct tj_memo {
  int a, b;                      /* the edge as searched (a < 0: empty) */
  int start, n;                  /* its vertices: ring[start .. start + n) */
  uint64_t tests;                /* the exact tests it charged */
};

static bool same_point(const struct scene *s, int v, int w)
{
  return s->v[v].x == s->v[w].x && s->v[v].y == s->v[w].y && s->v[v].z == s->v[w].z;
}

/* One edge searched: with the count (tj_edge) or without (tj_edge_near). */
static inline int tj_search(const struct tjunc *t, int a, int b, int **buf, int *n, int *cap,
                            struct cost *cost, uint64_t *tests)
{
  return t->counted ? tj_edge(t, a, b, buf, n, cap, cost, tests)
                    : tj_edge_near(t, a, b, buf, n, cap);
}

/* tj_search through the table memo (NULL: every edge searched, the long way). 0 when out
   of host memory. */
static int tj_edge_memo(const struct tjunc *t, struct tj_memo *memo, int a, int b, int **buf,
                        int *n, int *cap, struct cost *cost, uint64_t *tests, int *replayed)
{
  if (!memo) return tj_search(t, a, b, buf, n, cap, cost, tests);
  uint32_t lo = (uint32_t)(a < b ? a : b), hi = (uint32_t)(a < b ? b : a);
  struct tj_memo *m = &memo[(lo * 0x9E3779B1u ^ hi * 0x85EBCA77u) >> (32 - TJ_MEMO_BITS)];
  bool same = m->a == a && m->b == b;
  if (!same && !(m->a == b && m->b == a)) {
    int first = *n;
    uint64_t before = *tests;
    if (!tj_search(t, a, b, buf, n, cap, cost, tests)) return 0;
    *m = (struct tj_memo){ a, b, first, *n - first, *tests - before };
    return 1;
  }
  if (t->counted) {                                         /* tj_edge's charges */
    struct gpoint pa = t->proj[a], pb = t->proj[b];
    int lo_v = pa.x < pb.x ? a : b, hi_v = pa.x < pb.x ? b : a;
    COST_ADD_N(cost, COST_MEM, 2 * (t->ub[hi_v] - t->lb[lo_v]));
  }
  *tests += m->tests;
  (*replayed)++;
  if (*n + m->n > *cap) {
    int c = *cap ? *cap : 64;
    while (c < *n + m->n) c *= 2;
    int *nb = realloc(*buf, (size_t)c * sizeof *nb);
    if (!nb) return 0;
    *buf = nb;
    *cap = c;
  }
  int *r = *buf;
  if (same) {
    memcpy(r + *n, r + m->start, (size_t)m->n * sizeof *r);
    *n += m->n;
    return 1;
  }
  for (int e = m->start + m->n; e > m->start;) {        /* from b's end: runs at one point */
    int q = e - 1;
    while (q > m->start && same_point(t->s, r[q - 1], r[e - 1])) q--;
    for (int k = q; k < e; k++) r[(*n)++] = r[k];
    e = q;
  }
  return 1;
}

/* eq. (2): the plane through three vertices of the outer ring that are not collinear. */
static int face_plane(const struct scene *s, const struct scene_face *f, int64_t pl[4])
{
  const int *r = f->vidx;
  int n = f->ring_start[1] - f->ring_start[0];
  const struct scene_vertex *p0 = &s->v[r[0]];
  for (int i = 1; i < n; i++) {
    const struct scene_vertex *p1 = &s->v[r[i]];
    int64_t ux = p1->x - p0->x, uy = p1->y - p0->y, uz = p1->z - p0->z;
    for (int k = i + 1; k < n; k++) {
      const struct scene_vertex *p2 = &s->v[r[k]];
      int64_t vx = p2->x - p0->x, vy = p2->y - p0->y, vz = p2->z - p0->z;
      int64_t a = uy * vz - uz * vy, b = uz * vx - ux * vz, c = ux * vy - uy * vx;
      if (a | b | c) {
        pl[0] = a; pl[1] = b; pl[2] = c;
        pl[3] = -(a * p0->x + b * p0->y + c * p0->z);
        return 1;
      }
    }
  }
  return 0;
}

/* Forget the T-junctions (the blocks stay). */
static void tj_forget(struct mapper_keep *k)
{
  free(k->ring);
  free(k->start);
  free(k->plane);
  free(k->lgrey);
  k->s = NULL;
  k->ring = k->start = NULL;
  k->plane = NULL;
  k->lgrey = NULL;
  k->n = k->cap = 0;
  memset(&k->cost, 0, sizeof k->cost);
}

void mapper_keep_free(struct mapper_keep *k)
{
  tj_forget(k);
  pool_free(&k->pool);
  free(k->f);
  k->f = NULL;
  k->fcap = 0;
}

void mapper_keep_faces(struct mapped *m, struct mapper_keep *k)
{
  pool_reset(&m->pool);
  pool_free(&k->pool);
  k->pool = m->pool;
  memset(&m->pool, 0, sizeof m->pool);
  if (m->f) {                               /* the table, its split triangles' arrays freed */
    for (int n = 0; n < m->nface; n++) mface_arrays_free(&m->f[n]);
    free(k->f);
    k->f = m->f;
    k->fcap = m->cap;
    m->f = NULL;
    m->nface = m->cap = 0;
  }
}

int mapper_run(const struct scene *s, struct mapped *out, struct core *core,
               struct cost *cost, struct t74_error *err)
{
  return mapper_run_kept(s, out, core, cost, NULL, err);
}

int mapper_run_kept(const struct scene *s, struct mapped *out, struct core *core,
                    struct cost *cost, struct mapper_keep *kt, struct t74_error *err)
{
  memset(out, 0, sizeof *out);
  if (kt) {                                 /* the last run's blocks */
    out->pool = kt->pool;
    memset(&kt->pool, 0, sizeof kt->pool);
  }
  const int64_t X0 = s->view[0], Y0 = s->view[1], Z0 = s->view[2];
  const int64_t f = -Z0;                    /* distance from the eye to the plane, > 0 */
  out->eye[0] = X0; out->eye[1] = Y0; out->eye[2] = Z0;

  out->sv = s->v;
  struct gpoint *proj = malloc((size_t)(s->nv ? s->nv : 1) * sizeof *proj);
  if (kt && kt->f && kt->fcap >= s->nf) {   /* the last run's table (issue 19: no calloc a
                                               frame); each face kept is written whole */
    out->f = kt->f;
    out->cap = kt->fcap;
    kt->f = NULL;
    kt->fcap = 0;
  } else {
    out->f = malloc((size_t)(s->nf ? s->nf : 1) * sizeof *out->f);
    out->cap = s->nf ? s->nf : 1;
  }
  if (!proj || !out->f) {
    free(proj);
    return t74_fail(err, T74_EIO, "out of host memory");
  }

  uint32_t vt;
  /* the rows reserved as the 1974 program holds them; under the points engine (cost
     NULL) never written, so not zeroed either */
  int (*reserve)(struct core *, const char *, uint32_t, uint32_t *, struct t74_error *) =
      cost ? core_alloc : core_reserve;
  if (reserve(core, "VERTEX", (uint32_t)s->nv * VERTEX_ROW_WORDS, &vt, err) != T74_OK)
    goto fail;
  for (int k = 0; k < s->nv; k++) {
    const struct scene_vertex *v = &s->v[k];
    int64_t w = v->z - Z0;                  /* > 0: the scene reader checked z > Z0 */
    proj[k].x = project(v->x, X0, f, w);
    proj[k].y = project(v->y, Y0, f, w);
    if (cost) {                             /* NULL: not counted (the points engine) */
      COST_ADD_N(cost, COST_MEM, 6);
      cost_mw_mul(cost, 32, 32);
      cost_mw_mul(cost, 32, 32);
      cost_mw_div(cost, 48, 32);
      cost_mw_div(cost, 48, 32);
    }
    if (proj[k].x < -GRID_LIMIT || proj[k].x > GRID_LIMIT ||
        proj[k].y < -GRID_LIMIT || proj[k].y > GRID_LIMIT) {
      t74_fail_at(err, T74_EINPUT, s->file, v->line,
                  "vertex %u projects to (%.1f, %.1f), outside the perspective plane's "
                  "range of +-%lld units; move the eye back or the vertex away from it",
                  (unsigned)v->id, (double)proj[k].x / GRID_ONE, (double)proj[k].y / GRID_ONE,
                  (long long)(GRID_LIMIT / GRID_ONE));
      goto fail;
    }
    if (!cost) continue;                    /* the points engine: the rows unwritten */
    /* the row in one write (issue 19); an import's id above 65535: its low word (the 1974
       layout; never read back) */
    const uint16_t row[VERTEX_ROW_WORDS] = {
      (uint16_t)v->id, (uint16_t)v->x, (uint16_t)v->y, (uint16_t)v->z,
      (uint16_t)(proj[k].x / GRID_ONE), (uint16_t)(proj[k].y / GRID_ONE) };
    core_write_n(core, vt + (uint32_t)k * VERTEX_ROW_WORDS, row, VERTEX_ROW_WORDS);
  }

  /* The T-junctions: taken from kt when it holds this scene's (replay), else searched for
     (tj), the rings built in the scratch ring[] or, to be kept, in kt's own array. The
     search's charges go to tjc, added to cost at the end either way. */
  /* (a keep searched without a cost holds no charges: a run with one searches again) */
  bool replay = kt && kt->s == s && (kt->counted || !cost);
  struct tjunc tj;
  memset(&tj, 0, sizeof tj);
  struct cost tjc = { { 0 } };
  uint64_t tjtests = 0;                     /* the search's exact tests, charged at the end */
  int *ring = NULL, nring_v = 0, capring = 0;
  int **rbuf = &ring, *rn = &nring_v, *rcap = &capring;
  struct tj_memo *memo = NULL;
  int replayed = 0;                         /* edges taken from memo */
  if (!replay) {
    if (kt) {
      tj_forget(kt);
      int nrings = 0;
      for (int fi = 0; fi < s->nf; fi++) nrings += s->f[fi].nring;
      if (!kt->once) {                      /* what a next run replays */
        kt->start = malloc(((size_t)nrings + 1) * sizeof *kt->start);
        kt->plane = malloc((size_t)(s->nf ? s->nf : 1) * sizeof *kt->plane);
        kt->lgrey = malloc((size_t)(s->nf ? s->nf : 1) * sizeof *kt->lgrey);
        if (!kt->start || !kt->plane || !kt->lgrey) {
          t74_fail(err, T74_EIO, "out of host memory");
          goto fail;
        }
      }
      rbuf = &kt->ring; rn = &kt->n; rcap = &kt->cap;   /* the memo points into them */
    }
    if (!tj_init(&tj, s, proj, cost != NULL)) {   /* no cost: no count (points engine) */
      t74_fail(err, T74_EIO, "out of host memory");
      goto fail_tj;
    }
    tj.whole_boxes = kt && kt->whole_boxes;
    /* the edges met the other way: where the rings are kept (their places stay) */
    if (kt && !kt->whole_boxes && (memo = malloc(sizeof *memo << TJ_MEMO_BITS)) != NULL)
      for (size_t q = 0; q < (size_t)1 << TJ_MEMO_BITS; q++) memo[q].a = -1;
  }
  int g0 = 0;                               /* the scene's first ring of face fi */
  const uwide ll = s->nlight > 0 ? light_ll(s->light[0].v) : 0;   /* face_grey's lambert */
  const bool lamb = s->has_light && s->nlight == 1 && !s->light[0].point;   /* (its case) */

  uint32_t at;
  if (reserve(core, "A-BLOCK", (uint32_t)s->nf * ABLOCK_ROW_WORDS, &at, err) != T74_OK)
    goto fail_tj;
  for (int fi = 0; fi < s->nf; fi++) {
    const struct scene_face *sf = &s->f[fi];
    struct mface *m = &out->f[out->nface];
    int g = g0;
    g0 += sf->nring;
    int64_t pl[4];
    if (replay) {
      memcpy(pl, kt->plane[fi], sizeof pl);
    } else {
      if (!face_plane(s, sf, pl)) memset(pl, 0, sizeof pl);
      if (kt && kt->plane) memcpy(kt->plane[fi], pl, sizeof pl);
      if (kt && kt->lgrey && lamb) {        /* the grey of either sign of the plane */
        const uint64_t den = lambert_den(pl, ll);
        const int64_t turned[3] = { -pl[0], -pl[1], -pl[2] };
        kt->lgrey[fi][0] = (uint8_t)lambert(pl, s->light[0].v, den);
        kt->lgrey[fi][1] = (uint8_t)lambert(turned, s->light[0].v, den);
      }
    }
    if (!(pl[0] | pl[1] | pl[2])) { out->dropped++; continue; }   /* face_plane found none */
    if (cost) {
      cost_mw_mul(cost, 17, 17);
      COST_ADD_N(cost, COST_MEM, 9);
    }
    wide pe = (wide)pl[0] * X0 + (wide)pl[1] * Y0 + (wide)pl[2] * Z0 + pl[3];
    if (pe == 0) { out->dropped++; continue; }     /* edge-on: the plane holds the eye */
    /* the plane turned to face away from the eye where pe > 0, without a branch (the
       side the eye is on has no pattern the predictor learns among crossing triangles):
       (v ^ t) - t is v for t = 0 and -v for t = -1 (all ones), in two's complement;
       |pl[k]| < 2^63 and |pe| < 2^127, so -v fits */
    const bool turn = pe > 0;                /* (lgrey's second) */
    const int64_t t64 = -(int64_t)turn;
    /* into the face's own row at once (no copy of pl later: a 16-byte load of two
       8-byte stores, which cannot be forwarded from them) */
    for (int k = 0; k < 4; k++)
      m->plane[k] = (int64_t)(((uint64_t)pl[k] ^ (uint64_t)t64) - (uint64_t)t64);
    /* deye = |pe|: the low 64 bits of pe turned as the plane is and negated, made from
       pe's low 64 bits alone (in two's complement the low bits of an xor, a difference or
       a negation depend on the operands' low bits only); the same number as the 128-bit
       turn and the truncation of its negation */
    const int64_t deye = (int64_t)(((uint64_t)pe ^ (uint64_t)~t64) - (uint64_t)~t64);

    /* the rings with T-junction vertices inserted: ring r is rv[rs[r] .. rs[r+1]) */
    int rs_new[sf->nring + 1];
    const int *rs = replay ? kt->start + g : rs_new;
    if (!replay) {
      if (!kt) nring_v = 0;
      for (int r = 0; r < sf->nring; r++) {
        rs_new[r] = *rn;
        int b = sf->ring_start[r], e = sf->ring_start[r + 1];
        for (int k = b; k < e; k++) {
          if (*rn == *rcap) {
            int c = *rcap ? 2 * *rcap : 64;
            int *nb = realloc(*rbuf, (size_t)c * sizeof *nb);
            if (!nb) { t74_fail(err, T74_EIO, "out of host memory"); goto fail_tj; }
            *rbuf = nb;
            *rcap = c;
          }
          (*rbuf)[(*rn)++] = sf->vidx[k];
          int nx = k + 1 < e ? k + 1 : b;
          if (!tj_edge_memo(&tj, memo, sf->vidx[k], sf->vidx[nx], rbuf, rn, rcap, &tjc,
                            &tjtests, &replayed)) {
            t74_fail(err, T74_EIO, "out of host memory");
            goto fail_tj;
          }
        }
      }
      rs_new[sf->nring] = *rn;
      if (kt && kt->start) for (int r = 0; r <= sf->nring; r++) kt->start[g + r] = rs_new[r];
    }
    const int *rv = replay ? kt->ring : *rbuf;
    int nv = rs[sf->nring] - rs[0];
    /* the face's arrays in one piece of the pool (100,000 faces: 400,000 fewer mallocs
       a frame), the widest elements first so each array stays aligned */
    size_t bytes = (size_t)nv * (sizeof *m->pt + sizeof *m->vid + sizeof *m->vix) +
                   (size_t)(sf->nring + 1) * sizeof *m->ring_start;
    _Static_assert(_Alignof(struct gpoint) >= _Alignof(uint32_t) &&
                   _Alignof(uint32_t) >= _Alignof(int32_t) &&
                   _Alignof(int32_t) >= _Alignof(int), "mface block layout");
    m->pt = pool_alloc(&out->pool, bytes, _Alignof(struct gpoint));
    if (!m->pt) {
      t74_fail(err, T74_EIO, "out of host memory");
      goto fail_tj;
    }
    m->pooled = true;
    m->vid = (uint32_t *)(m->pt + nv);
    m->vix = (int32_t *)(m->vid + nv);
    m->ring_start = (int *)(m->vix + nv);
    /* copy rings, dropping points that rounding made equal to their predecessor, and
       rings that rounding collapsed; orient outer CCW, holes CW */
    int nr = 0, np = 0;
    bool keep = true;
    if (sf->nring == 1 &&
        (nv == 3 ? ring_three(s, proj, rv + rs[0], m->pt, m->vid, m->vix, cost)
                 : nv == 4 && ring_four(s, proj, rv + rs[0], m->pt, m->vid, m->vix, cost))) {
      m->ring_start[0] = 0;
      nr = 1;
      np = nv;
    } else {                                    /* any other: point by point */
      for (int r = 0; r < sf->nring && keep; r++) {
        int start = np;
        for (int k = rs[r]; k < rs[r + 1]; k++) {
          struct gpoint p = proj[rv[k]];
          if (np > start && p.x == m->pt[np - 1].x && p.y == m->pt[np - 1].y) continue;
          const struct scene_vertex *sv = &s->v[rv[k]];
          m->pt[np] = p;
          m->vid[np] = sv->id;
          m->vix[np] = rv[k];
          np++;
        }
        while (np - start > 1 && m->pt[np - 1].x == m->pt[start].x &&
               m->pt[np - 1].y == m->pt[start].y)
          np--;
        wide area = np - start >= 3 ? ring_area2(m->pt + start, np - start) : 0;
        if (cost) {
          COST_ADD_N(cost, COST_MEM, 2 * (np - start));
          cost_mw_mul(cost, 29, 29);
        }
        if (area == 0) {                    /* covers no point of the plane */
          np = start;
          if (r == 0) keep = false;
          continue;
        }
        const bool rev = (r == 0) != (area > 0);
        if (np - start == 3) {              /* a triangle: its first and last swapped where it
                                               turns the wrong way, by selects (which way a
                                               crossing triangle turns is anyone's guess) */
          swap3(m->pt + start, m->vid + start, m->vix + start, rev);
        } else if (rev) {
          ring_reverse(m->pt + start, m->vid + start, m->vix + start, np - start);
        }
        m->ring_start[nr++] = start;
      }
    }
    if (!keep) {
      mface_arrays_free(m);
      memset(m, 0, sizeof *m);
      out->dropped++;
      continue;
    }
    m->ring_start[nr] = np;
    m->nring = nr;
    m->id = sf->id;
    m->on = sf->on_id;
    m->sface = fi;
    m->sline = sf->line;
    m->deye = deye;
    m->grey = (uint8_t)(sf->grey >= 0              ? sf->grey
                        : lamb && kt && kt->lgrey ? kt->lgrey[fi][turn]   /* (kept) */
                                                  : face_grey(s, m, m->plane, ll));

    if (!cost) { out->nface++; continue; }  /* the points engine: the row unwritten */
    gcoord ymin = m->pt[0].y, ymax = m->pt[0].y;
    for (int k = 1; k < m->ring_start[1]; k++) {
      if (m->pt[k].y < ymin) ymin = m->pt[k].y;
      if (m->pt[k].y > ymax) ymax = m->pt[k].y;
    }
    int64_t h[4];
    geom_h10_plane(m->plane, h);
    /* the row's first 9 words in one write (issue 19): id, grey, y-min, y-max, a, b, c
       one word each, d two words (the high one first, as core_put_int); the tenth stays
       as core_alloc left it */
    const uint16_t row[9] = {
      (uint16_t)m->id, (uint16_t)m->grey, (uint16_t)(ymin / GRID_ONE),
      (uint16_t)(ymax / GRID_ONE), (uint16_t)h[0], (uint16_t)h[1], (uint16_t)h[2],
      (uint16_t)((uint64_t)h[3] >> 16), (uint16_t)(uint64_t)h[3] };
    core_write_n(core, at + (uint32_t)out->nface * ABLOCK_ROW_WORDS, row, 9);
    out->nface++;
  }
  free(ring);
  free(memo);
  tj_free(&tj);
  if (cost) free(proj);
  else out->proj = proj;                    /* (the points engine's vertices) */
  cost_mw_mul_n(&tjc, 17, 17, tjtests);    /* each a product of 17-bit operands */
  if (kt && !replay && kt->once) {          /* no next run: nothing kept (the charges and
                                               the host statistic stay readable) */
    tj_forget(kt);
    kt->cost = tjc;
    kt->replayed = replayed;
  } else if (kt && !replay) {
    if (kt->n > 0 && kt->n < kt->cap) {   /* kept for the whole run: to its size (it
                                             doubled; 100,000 boxes: 4 MB for 2.3) */
      int *fit = realloc(kt->ring, (size_t)kt->n * sizeof *fit);
      if (fit) { kt->ring = fit; kt->cap = kt->n; }
    }
    kt->s = s;
    kt->counted = cost != NULL;
    kt->cost = tjc;
    kt->replayed = replayed;
  }
  if (cost) cost_merge(cost, replay ? &kt->cost : &tjc);
  return T74_OK;

fail_tj:
  free(ring);
  free(memo);
  tj_free(&tj);
  if (kt && !replay) tj_forget(kt);
fail:
  free(proj);
  mapper_free(out);
  return err->status;
}

/* ---- faces that rounding made not simple ------------------------------------------------
   Ear clipping on the face's vertices in space, projected onto the coordinate plane the
   face's normal is most nearly perpendicular to (the projection of a plane polygon along
   an axis not in its plane keeps it simple). Coordinates are 16-bit, so orientations fit
   64 bits. A vertex is an ear when it turns strictly left and no other vertex of what is
   left lies in or on its triangle; a T-junction vertex (straight) is never an ear tip and
   never lies on a cut, so it stays on the boundary of a triangle that shares the edge it
   lies on. */

static int64_t orient2(const int64_t *p, const int64_t *q, const int64_t *r)
{
  return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
}

static bool same2(const int64_t *p, const int64_t *q) { return p[0] == q[0] && p[1] == q[1]; }

static bool in_tri(const int64_t *a, const int64_t *b, const int64_t *c, const int64_t *p)
{
  return orient2(a, b, p) >= 0 && orient2(b, c, p) >= 0 && orient2(c, a, p) >= 0;
}

/* The diagonal a-p leaves vertex a (neighbours ap before it, an after it, the polygon
   counter-clockwise) into the polygon's inside: O'Rourke's in-cone test, strict. Needed
   where a bridge makes one point a vertex twice: there the emptiness of an ear's triangle
   alone does not tell which of the two copies the diagonal leaves from. */
static bool in_cone(const int64_t *ap, const int64_t *a, const int64_t *an, const int64_t *p)
{
  if (orient2(ap, a, an) >= 0)                       /* convex (or straight) at a */
    return orient2(a, p, ap) > 0 && orient2(p, a, an) > 0;
  return !(orient2(a, p, an) >= 0 && orient2(p, a, ap) >= 0);
}

/* p strictly inside segment a-b (a != b) */
static bool on_open_seg(const int64_t *a, const int64_t *b, const int64_t *p)
{
  if (orient2(a, b, p) != 0 || same2(p, a) || same2(p, b)) return false;
  return (p[0] - a[0]) * (p[0] - b[0]) <= 0 && (p[1] - a[1]) * (p[1] - b[1]) <= 0;
}

/* The bridge m-w (m != w) meets edge a-b elsewhere than at its own ends. */
static bool bridge_hits(const int64_t *m, const int64_t *w, const int64_t *a, const int64_t *b)
{
  if (same2(a, b)) return on_open_seg(m, w, a);
  if (on_open_seg(m, w, a) || on_open_seg(m, w, b) || on_open_seg(a, b, m) || on_open_seg(a, b, w))
    return true;
  int64_t d1 = orient2(a, b, m), d2 = orient2(a, b, w), d3 = orient2(m, w, a), d4 = orient2(m, w, b);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Even-odd of the doubled point (px, py) / 2 against every ring (coordinates doubled);
   -1 when it lies on an edge. */
static int inside2(const int64_t (*q)[2], const int *rs, int nring, int64_t px, int64_t py)
{
  int in = 0;
  for (int r = 0; r < nring; r++)
    for (int i = rs[r]; i < rs[r + 1]; i++) {
      int j = i + 1 < rs[r + 1] ? i + 1 : rs[r];
      int64_t a[2] = { 2 * q[i][0], 2 * q[i][1] }, b[2] = { 2 * q[j][0], 2 * q[j][1] }, p[2] = { px, py };
      if (same2(a, p) || on_open_seg(a, b, p)) return -1;
      if ((a[1] > py) != (b[1] > py)) {
        int64_t o = orient2(a, b, p);
        if ((b[1] > a[1]) == (o > 0)) in ^= 1;      /* the edge passes right of p */
      }
    }
  return in;
}

/* The rings are simple in the projected plane: no two edges meet except at a shared end
   point (neighbours in a ring, or rings touching at one vertex position), and neighbours
   do not fold back. The scene reader checked this of the face as given; it is checked
   again here because the Mapper dropped vertices that rounded onto their predecessor. */
static bool rings_simple(const int64_t (*q)[2], const int *rs, int nring, struct cost *cost)
{
  int n = rs[nring];
  for (int i = 0; i < n; i++) {
    int ri = 0;
    while (i >= rs[ri + 1]) ri++;
    int i2 = i + 1 < rs[ri + 1] ? i + 1 : rs[ri];
    const int64_t *a = q[i], *b = q[i2];
    if (same2(a, b)) return false;
    for (int j = i + 1; j < n; j++) {
      int rj = ri;
      while (j >= rs[rj + 1]) rj++;
      int j2 = j + 1 < rs[rj + 1] ? j + 1 : rs[rj];
      const int64_t *c = q[j], *d = q[j2];
      cost_mw_mul(cost, 17, 17);
      if (j == i2 || j2 == i) {                /* neighbours: no folding back */
        const int64_t *sh = j == i2 ? b : a, *x = j == i2 ? a : b, *y = j == i2 ? d : c;
        if (orient2(sh, x, y) == 0 && (x[0] - sh[0]) * (y[0] - sh[0]) + (x[1] - sh[1]) * (y[1] - sh[1]) > 0)
          return false;
        continue;
      }
      if ((same2(a, c) && same2(b, d)) || (same2(a, d) && same2(b, c))) return false;
      if (on_open_seg(a, b, c) || on_open_seg(a, b, d) || on_open_seg(c, d, a) || on_open_seg(c, d, b))
        return false;
      int64_t d1 = orient2(a, b, c), d2 = orient2(a, b, d), d3 = orient2(c, d, a), d4 = orient2(c, d, b);
      if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return false;
    }
  }
  return true;
}

/* The face's rings as one counter-clockwise index list in the projected plane: each hole
   joined to what is built so far by a bridge from one of its vertices to a vertex in
   sight (crossing no edge and no bridge, its midpoint inside the face), walked around and
   back along the bridge. Returns the list's length, or -1 when no bridge was found. */
static int bridge_rings(const int64_t (*q)[2], const int *rs, int nring, int *out, int attempt,
                        struct cost *cost)
{
  int n = 0;
  int64_t area0 = 0;
  for (int i = rs[0]; i < rs[1]; i++) {
    int j = i + 1 < rs[1] ? i + 1 : rs[0];
    area0 += q[i][0] * q[j][1] - q[j][0] * q[i][1];
  }
  for (int i = rs[0]; i < rs[1]; i++) out[n++] = area0 > 0 ? i : rs[1] - 1 - (i - rs[0]);
  for (int h = 1; h < nring; h++) {
    int hb = rs[h], he = rs[h + 1], hn = he - hb;
    int64_t ah = 0;
    for (int i = hb; i < he; i++) {
      int j = i + 1 < he ? i + 1 : hb;
      ah += q[i][0] * q[j][1] - q[j][0] * q[i][1];
    }
    /* attempt 0: the shortest bridge in sight; later attempts (when the ears ran into a
       dead end): the first in sight from a rotated start */
    int bm = -1, bw = -1;
    wide best = 0;
    for (int mi0 = 0; mi0 < hn && (attempt == 0 || bm < 0); mi0++) {
      int mi = (mi0 + attempt) % hn;
      const int64_t *M = q[hb + mi];
      for (int wi0 = 0; wi0 < n && (attempt == 0 || bm < 0); wi0++) {
        int wi = (wi0 + 7 * attempt) % n;
        const int64_t *Wp = q[out[wi]];
        wide dx = Wp[0] - M[0], dy = Wp[1] - M[1], d2 = dx * dx + dy * dy;
        if (attempt == 0 && bm >= 0 && d2 >= best) continue;
        bool ok = true;
        if (!same2(M, Wp)) {
          for (int e = 0; e < n && ok; e++)
            ok = !bridge_hits(M, Wp, q[out[e]], q[out[(e + 1) % n]]);
          for (int r = h; r < nring && ok; r++)
            for (int i = rs[r]; i < rs[r + 1] && ok; i++)
              ok = !bridge_hits(M, Wp, q[i], q[i + 1 < rs[r + 1] ? i + 1 : rs[r]]);
          cost_mw_mul(cost, 17, 17);
          ok = ok && inside2(q, rs, nring, M[0] + Wp[0], M[1] + Wp[1]) == 1;
        }
        if (ok) { bm = mi; bw = wi; best = d2; }
      }
    }
    if (bm < 0) return -1;
    /* out[0..bw], then the hole clockwise from M round to M, then out[bw] again, then the
       rest; when M and out[bw] are one point (the hole touches there), the walk starts
       after M instead, so that point is passed twice but never twice in a row */
    int dup = !same2(q[hb + bm], q[out[bw]]);
    int walk = dup ? hn + 2 : hn, tail = n - bw - 1;
    memmove(out + bw + 1 + walk, out + bw + 1, (size_t)tail * sizeof *out);
    int at = bw + 1;
    for (int t = dup ? 0 : 1; t <= hn; t++) {
      int i = (bm + (ah < 0 ? t : hn - t)) % hn;          /* clockwise */
      out[at++] = hb + i;
    }
    if (dup) out[at++] = out[bw];
    n = at + tail;
  }
  return n;
}

/* Ear clipping of the counter-clockwise list left[0..*pnl) into tri; *pnl is left at 3
   when done (the last triangle not yet in tri), above 3 at a dead end. Returns the
   triangles made. */
static int ear_clip(const int64_t (*q)[2], int *left, int *pnl, int (*tri)[3], struct cost *cost)
{
  int nt = 0, nl = *pnl;
  while (nl > 3) {
    int ear = -1;
    for (int i = 0; i < nl && ear < 0; i++) {
      const int64_t *a = q[left[(i + nl - 1) % nl]], *b = q[left[i]], *c = q[left[(i + 1) % nl]];
      cost_mw_mul(cost, 17, 17);
      if (orient2(a, b, c) <= 0) continue;
      const int64_t *ap = q[left[(i + nl - 2) % nl]], *cn = q[left[(i + 2) % nl]];
      if (!in_cone(ap, a, b, c) || !in_cone(b, c, cn, a)) continue;
      /* and no edge crosses the cut a-c: an edge ending at a point the polygon passes
         twice (a bridge's end) can enter the triangle without a vertex inside it */
      bool empty = true;
      for (int j = 0; j < nl && empty; j++)
        empty = !bridge_hits(a, c, q[left[j]], q[left[(j + 1) % nl]]);
      for (int j = 0; j < nl && empty; j++) {
        const int64_t *p = q[left[j]];
        if (same2(p, a) || same2(p, b) || same2(p, c)) continue;   /* bridge ends */
        empty = !in_tri(a, b, c, p);
      }
      if (empty) ear = i;
    }
    if (ear < 0) break;                          /* not simple in space: give up */
    tri[nt][0] = left[(ear + nl - 1) % nl]; tri[nt][1] = left[ear]; tri[nt][2] = left[(ear + 1) % nl];
    nt++;
    for (int j = ear; j + 1 < nl; j++) left[j] = left[j + 1];
    nl--;
  }
  *pnl = nl;
  return nt;
}

#define SPLIT_ATTEMPTS 8     /* bridge choices tried when the ears run into a dead end */

int mapper_split_face(struct mapped *m, int k, struct core *core, struct cost *cost,
                      int *ntri, struct t74_error *err)
{
  *ntri = 0;
  struct mface *f = &m->f[k];
  int n = f->ring_start[f->nring];
  int ax = 0;
  for (int c = 1; c < 3; c++)
    if ((f->plane[c] < 0 ? -f->plane[c] : f->plane[c]) > (f->plane[ax] < 0 ? -f->plane[ax] : f->plane[ax]))
      ax = c;
  int u = ax == 0 ? 1 : 0, v = ax == 2 ? 1 : 2;
  int cap = n + 2 * f->nring + 2;
  int64_t (*q)[2] = malloc((size_t)n * sizeof *q);
  int *left = malloc((size_t)cap * sizeof *left);
  int (*tri)[3] = malloc((size_t)cap * sizeof *tri);
  if (!q || !left || !tri) {
    free(q); free(left); free(tri);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  for (int i = 0; i < n; i++) { q[i][0] = mface_coord(m, f, i, u); q[i][1] = mface_coord(m, f, i, v); }
  bool simple = rings_simple((const int64_t (*)[2])q, f->ring_start, f->nring, cost);
  int nl = -1, nt = 0;
  for (int attempt = 0; simple && attempt < SPLIT_ATTEMPTS; attempt++) {
    nl = bridge_rings((const int64_t (*)[2])q, f->ring_start, f->nring, left, attempt, cost);
    if (nl < 0) break;
    nt = ear_clip((const int64_t (*)[2])q, left, &nl, tri, cost);
    if (nl == 3 || f->nring == 1) break;      /* done, or no bridge to choose otherwise */
  }
  if (nl < 0) { free(q); free(left); free(tri); return T74_EINPUT; }
  if (nl == 3) { tri[nt][0] = left[0]; tri[nt][1] = left[1]; tri[nt][2] = left[2]; nt++; }
  free(q);
  free(left);
  if (nl > 3) { free(tri); return T74_EINPUT; }
  /* keep the triangles that cover a point of the grid, counter-clockwise on it */
  int keep = 0;
  for (int t = 0; t < nt; t++) {
    wide a2 = geom_orient(f->pt[tri[t][0]], f->pt[tri[t][1]], f->pt[tri[t][2]]);
    if (a2 == 0) continue;
    if (a2 < 0) { int x = tri[t][1]; tri[t][1] = tri[t][2]; tri[t][2] = x; }
    tri[keep][0] = tri[t][0]; tri[keep][1] = tri[t][1]; tri[keep][2] = tri[t][2];
    keep++;
  }
  if (keep == 0) { free(tri); return T74_OK; }
  if (m->nface + keep - 1 > m->cap) {
    int c = m->nface + keep - 1;
    struct mface *nf = realloc(m->f, (size_t)c * sizeof *nf);
    if (!nf) { free(tri); return t74_fail(err, T74_EIO, "out of host memory"); }
    m->f = nf;
    m->cap = c;
    f = &m->f[k];
  }
  uint32_t at;
  if (keep > 1 &&
      core_alloc(core, "A-BLOCK", (uint32_t)(keep - 1) * ABLOCK_ROW_WORDS, &at, err) != T74_OK) {
    free(tri);
    return err->status;
  }
  struct mface base = *f;
  for (int t = 0; t < keep; t++) {
    struct mface g = base;
    g.nring = 1;
    g.pooled = false;
    g.ring_start = malloc(2 * sizeof *g.ring_start);
    g.pt = malloc(3 * sizeof *g.pt);
    g.vid = malloc(3 * sizeof *g.vid);
    g.vix = malloc(3 * sizeof *g.vix);
    if (!g.ring_start || !g.pt || !g.vid || !g.vix) {
      free(g.ring_start); free(g.pt); free(g.vid); free(g.vix);
      free(tri);
      return t74_fail(err, T74_EIO, "out of host memory");
    }
    g.ring_start[0] = 0;
    g.ring_start[1] = 3;
    for (int c = 0; c < 3; c++) {
      g.pt[c] = base.pt[tri[t][c]];
      g.vid[c] = base.vid[tri[t][c]];
      g.vix[c] = base.vix[tri[t][c]];
    }
    COST_ADD_N(cost, COST_MEM, 12);
    if (t == 0) {
      m->f[k] = g;
    } else {
      uint32_t a = at + (uint32_t)(t - 1) * ABLOCK_ROW_WORDS;
      core_write(core, a, (uint16_t)g.id);
      core_write(core, a + 1, (uint16_t)g.grey);
      int64_t h[4];
      geom_h10_plane(g.plane, h);
      for (int c = 0; c < 3; c++) core_write(core, a + 4 + (uint32_t)c, (uint16_t)h[c]);
      core_put_int(core, a + 7, 2, h[3]);
      m->f[m->nface++] = g;
    }
  }
  mface_arrays_free(&base);
  free(tri);
  m->split++;
  *ntri = keep;
  return T74_OK;
}

struct gpoint mapper_point(const struct scene *s, int v)
{
  const int64_t X0 = s->view[0], Y0 = s->view[1], Z0 = s->view[2];
  int64_t w = s->v[v].z - Z0;
  struct gpoint p = { project(s->v[v].x, X0, -Z0, w), project(s->v[v].y, Y0, -Z0, w) };
  return p;
}

void mapper_free(struct mapped *m)
{
  if (m->f) {
    for (int k = 0; k < m->nface; k++) mface_arrays_free(&m->f[k]);
    free(m->f);
    m->f = NULL;
    m->nface = 0;
  }
  free(m->proj);
  m->proj = NULL;
  pool_free(&m->pool);
}
