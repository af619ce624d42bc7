/*
** poly.c — the effects' grid polygons (see poly.h).
*/
#include "effects/poly.h"

#include <stdlib.h>
#include <string.h>

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
  p->rs = malloc((size_t)(keep + 1) * sizeof *p->rs);
  p->pt = malloc((size_t)npt * sizeof *p->pt);
  if (!p->rs || !p->pt) { free(p->rs); free(p->pt); return false; }
  p->nring = 0;
  int at = 0;
  for (int r = 0; r < nring; r++) {
    int n = rs[r + 1] - rs[r];
    if (n < 3) continue;
    p->rs[p->nring++] = at;
    memcpy(p->pt + at, pt + rs[r], (size_t)n * sizeof *pt);
    at += n;
  }
  p->rs[p->nring] = at;
  p->xlo = p->xhi = p->pt[0].x;
  p->ylo = p->yhi = p->pt[0].y;
  for (int k = 1; k < at; k++) {
    if (p->pt[k].x < p->xlo) p->xlo = p->pt[k].x;
    if (p->pt[k].x > p->xhi) p->xhi = p->pt[k].x;
    if (p->pt[k].y < p->ylo) p->ylo = p->pt[k].y;
    if (p->pt[k].y > p->yhi) p->yhi = p->pt[k].y;
  }
  p->owner = owner;
  p->light = light;
  ps->n++;
  return true;
}

void fx_polys_free(struct fx_polys *ps)
{
  for (int k = 0; k < ps->n; k++) { free(ps->p[k].rs); free(ps->p[k].pt); }
  free(ps->p);
  memset(ps, 0, sizeof *ps);
}

int fx_poly_cross(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x, int max,
                  struct cost *cost)
{
  int nx = 0;
  const int64_t fy = fx_line_row(yn, yd);   /* a point on or below the line: y <= fy */
  if (!fx_poly_on_row(p, fy)) return 0;
  for (int r = 0; r < p->nring; r++) {
    int a = p->rs[r], n = p->rs[r + 1] - a;
    if (n <= 0) continue;
    /* an edge crosses the line when its ends lie on either side, a point on the line
       counting as above it (half-open: each crossing counted once); each vertex's side
       found once, for the edge it ends and the one it starts */
    const struct gpoint *pt = p->pt + a;
    bool c0 = pt[0].y <= fy;
    for (int v = 0; v < n; v++) {
      /* the edge from point v to the next, w (the last back to the first) */
      const int w = v + 1 == n ? 0 : v + 1;
      const bool c1 = pt[w].y <= fy;
      if (c0 != c1) {
        struct gpoint p0 = pt[v], p1 = pt[w];
        if (nx == max) {
          COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)(v + 1)); COST_ADD_N(cost, COST_BRANCH, v + 1);
          return -1;
        }
        struct grat xc = geom_x_at(geom_line(p0, p1), yn, yd);
        cost_mw_mul(cost, 58, 17); cost_mw_div(cost, 75, 46);
        int h = nx++;
        while (h > 0 && geom_rat_cmp(x[h - 1], xc) > 0) { x[h] = x[h - 1]; h--; }
        x[h] = xc;
      }
      c0 = c1;
    }
    COST_ADD_N(cost, COST_ADD, 2 * (uint64_t)n); COST_ADD_N(cost, COST_BRANCH, n);  /* an edge's */
  }
  return nx;
}
