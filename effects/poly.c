/*
** poly.c — the effects' grid polygons (see poly.h).
*/
#include "effects/poly.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

enum { CHUNK_BYTES = 1 << 15 };

/* Room for size bytes (aligned as malloc's) at the end of ps->mem, not yet taken; NULL
   when out of host memory. */
static void *room(struct fx_polys *ps, size_t size)
{
  size = fx_piece(size);
  struct fx_chunk *c = ps->mem;
  if (!c || c->cap - c->used < size) {
    const size_t cap = size > CHUNK_BYTES ? size : CHUNK_BYTES;
    if (!(c = malloc(sizeof *c + cap))) return NULL;
    c->used = 0;
    c->cap = cap;
    c->next = ps->mem;
    ps->mem = c;
  }
  return (char *)c->data + c->used;
}

/* size bytes from ps's chunks (room's, taken); NULL when out of host memory. */
static void *take(struct fx_polys *ps, size_t size)
{
  void *at = room(ps, size);
  if (at) ps->mem->used += fx_piece(size);
  return at;
}

bool fx_polys_reserve(struct fx_polys *ps, int n)
{
  if (n <= ps->cap) return true;
  struct fx_poly *np = realloc(ps->p, (size_t)n * sizeof *np);
  if (!np) return false;
  ps->p = np;
  ps->cap = n;
  return true;
}

/* (The layout fx_polys_close_at makes, each ring copied and its blocks made in one go:
   a contour's long rings take no second pass and no room for the worst case.) */
bool fx_polys_add(struct fx_polys *ps, int nring, const int *rs, const struct gpoint *pt,
                  int owner, int light)
{
  int keep = 0, npt = 0;
  for (int r = 0; r < nring; r++)
    if (rs[r + 1] - rs[r] >= 3) { keep++; npt += rs[r + 1] - rs[r]; }
  if (!keep) return true;
  if (ps->n == ps->cap) {
    int cap = ps->cap ? 2 * ps->cap : 16;
    struct fx_poly *np = realloc(ps->p, (size_t)cap * sizeof *np);
    if (!np) return false;
    ps->p = np;
    ps->cap = cap;
  }
  struct fx_poly *p = &ps->p[ps->n];
  /* one piece of the list's memory: the points, then the blocks' y ranges, then the offsets */
  size_t nblk = 0;
  for (int r = 0; r < nring; r++) {
    int n = rs[r + 1] - rs[r];
    if (n >= 3) nblk += (size_t)(n + FX_POLY_BLOCK - 1) / FX_POLY_BLOCK;
  }
  char *mem = take(ps, (size_t)npt * sizeof *p->pt + nblk * sizeof *p->blk +
                     (size_t)(keep + 1) * sizeof *p->rs);
  if (!mem) return false;
  p->pt = (struct gpoint *)mem;
  p->blk = (gcoord (*)[2])(mem + (size_t)npt * sizeof *p->pt);
  p->rs = (int *)(mem + (size_t)npt * sizeof *p->pt + nblk * sizeof *p->blk);
  p->nring = 0;
  int at = 0;
  size_t b = 0;
  gcoord box[4] = { INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN };   /* xlo, xhi, ylo, yhi */
  for (int r = 0; r < nring; r++) {
    int n = rs[r + 1] - rs[r];
    if (n < 3) continue;
    p->rs[p->nring++] = at;
    memcpy(p->pt + at, pt + rs[r], (size_t)n * sizeof *pt);
    b = fx_ring_blocks(p->pt + at, n, p->blk, b, box);
    at += n;
  }
  p->rs[p->nring] = at;
  p->xlo = box[0]; p->xhi = box[1]; p->ylo = box[2]; p->yhi = box[3];
  p->owner = owner;
  p->light = light;
  ps->n++;
  return true;
}

struct gpoint *fx_polys_room_made(struct fx_polys *ps, int npt)
{
  if (ps->n == ps->cap && !fx_polys_reserve(ps, ps->cap ? 2 * ps->cap : 16)) return NULL;
  return room(ps, fx_room_bytes(npt));
}

void fx_polys_free(struct fx_polys *ps)
{
  for (struct fx_chunk *c = ps->mem, *next; c; c = next) {
    next = c->next;
    free(c);
  }
  free(ps->p);
  memset(ps, 0, sizeof *ps);
}

/* The crossing of the edge p0 -> p1 (p0.y != p1.y: its ends on either side of the line)
   with the line y = yn / yd put into x[0 .. nx) in order: nx + 1 returned. */
static inline int cross_edge(struct gpoint p0, struct gpoint p1, int64_t yn, int64_t yd,
                             struct grat *x, int nx, struct cost *cost)
{
  /* geom_x_at(geom_line(p0, p1), yn, yd): the same rational, without the two calls */
  const int64_t la = p0.y - p1.y, lb = p1.x - p0.x, lc = -(la * p0.x + lb * p0.y);
  struct grat xc = { -((wide)lb * yn + (wide)lc * yd), (wide)la * yd };
  if (xc.den < 0) { xc.den = -xc.den; xc.num = -xc.num; }
  if (cost) { cost_mw_mul(cost, 58, 17); cost_mw_div(cost, 75, 46); }
  int h = nx;
  while (h > 0 && geom_rat_cmp(x[h - 1], xc) > 0) { x[h] = x[h - 1]; h--; }
  x[h] = xc;
  return nx + 1;
}

/* fx_poly_cross, made twice: counted and not (the points engine's: none of the counts'
   work in its loop). */
static inline int poly_cross(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x,
                             int max, struct cost *cost)
{
  int nx = 0;
  const int64_t fy = fx_line_row(yn, yd);   /* a point on or below the line: y <= fy */
  if (!fx_poly_on_row(p, fy)) return 0;
  const gcoord (*blk)[2] = (const gcoord (*)[2])p->blk;   /* the ring's first block */
  for (int r = 0; r < p->nring; r++) {
    int a = p->rs[r], n = p->rs[r + 1] - a;
    if (n <= 0) continue;
    /* an edge crosses the line when its ends lie on either side, a point on the line
       counting as above it (half-open: each crossing counted once); each vertex's side
       found once, for the edge it ends and the one it starts */
    const struct gpoint *pt = p->pt + a;
    bool c0 = pt[0].y <= fy;
    for (int v0 = 0; v0 < n; v0 += FX_POLY_BLOCK, blk++) {
      /* a block of edges whose points all lie on one side (c0's, its first point's)
         crosses nowhere: on to the next, c0 still its first point's */
      if ((*blk)[1] <= fy || (*blk)[0] > fy) continue;
      /* the edges from points v0 .. v1 - 1 to the next (the last back to the first) */
      const int v1 = v0 + FX_POLY_BLOCK < n ? v0 + FX_POLY_BLOCK : n;
      for (int v = v0; v < v1; v++) {
        const int w = v + 1 < n ? v + 1 : 0;
        const bool c1 = pt[w].y <= fy;
        if (c0 != c1) {
          if (nx == max) {
            if (cost) {
              COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)(v + 1)); COST_ADD_N(cost, COST_BRANCH, v + 1);
            }
            return -1;
          }
          nx = cross_edge(pt[v], pt[w], yn, yd, x, nx, cost);
        }
        c0 = c1;
      }
    }
    if (cost) {                             /* an edge's */
      COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)n);
      COST_ADD_N(cost, COST_BRANCH, n);
    }
  }
  return nx;
}

int fx_poly_cross(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x, int max,
                  struct cost *cost)
{
  return cost ? poly_cross(p, yn, yd, x, max, cost) : poly_cross(p, yn, yd, x, max, NULL);
}
