/*
** aa.c — anti-aliasing (papers 000, 001): the run, light mixing, sub-scanlines, and the
** exact reference (aa=exact), the yardstick of all the other methods.
**
** This file contains code to set up one anti-aliasing run over the effects frame (a
** fresh Visible Surface Procedure over the renderer's pieces and Priority Matrix, the
** light table in core), hand it to the method asked for (aa_multiscan.c, aa_area.c,
** aa_super.c, or aa_exact below), and write the result back as greys.
**
** LIGHT. Grey G is perceived brightness; a cell of L dots shows it with
** round((L+1)^(G/255) - 1) dots (patterns/halftone.c). What mixes on the tube is light,
** so a point's fragments are mixed as dot fractions ((L+1)^(G/255) - 1) / L, and the mix
** is turned back into the grey of nearest light: averaging greys would draw a
** half-covered edge between 0 and 255 with about a fifth of the cell's dots, not half.
** The table (256 words, 32768 = all dots) lives in core; the way back is a search by
** halving (8 steps) in the same table, as the 1974 program would have done it.
**
** EXACT (a reference path: floating point, host only; its operations are counted but it
** was never a 1974 method). The visible picture changes its structure along y only where
** a piece has a vertex or two piece boundaries cross, and, with the frame model
** (effects/model.h), where a polygon of it (a contour cut's region, a shadow) has a vertex
** or its sides cross each other or a piece's; between two such heights every visible
** stretch on every line has ends moving linearly in y. So each point row is cut at all
** such heights (computed from the exact lines), and in each band the lines (vis_spans, or
** the model's fx_lines_get) are asked at two heights inside it (1/4 and 3/4 of the way,
** rounded to 1/65536 of a grid unit); the stretches are matched one to one (the same
** piece and the same lights blocked) and their ends extended linearly to the band's
** edges. So the cut's curve (its polygon) and a shadow's edges are integrated exactly,
** like a face's sides. Then:
**   filter=box    the area of each stretch within each point is integrated in closed
**                 form (the mean of a clamped linear function, aa_mean_clamp);
**   filter=gauss  the Gaussian of radius one point (sigma=) is integrated: across x in
**                 closed form (erf), down y by 3-point Gauss-Legendre on pieces of at
**                 most 1/32 point of each band, band edges also at every row's centre
**                 line (where the filter disk's top and bottom lie).
** A band whose two lines do not match (a piece cut by the Priority Matrix between them)
** is counted in aa_exact_unmatched and taken as two halves with constant stretches; with
** every height above taken, none is expected (the tests hold it to 0 with cuts and
** shadows, tests/test_aa.c and test_compose.c).
*/
#include "effects/aa_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- light <-> grey ------------------------------------------------------------------ */

int aa_light(int cell, int g)
{
  if (g < 0) g = 0;
  if (g > 255) g = 255;
  double L = (double)cell * cell;
  return (int)floor(AA_LIGHT_ONE * (pow(L + 1, g / 255.0) - 1) / L + 0.5);
}

int aa_grey(int cell, double light)
{
  double q = light * AA_LIGHT_ONE;
  int lo = 0, hi = 255;                     /* the last grey with light <= q, by halving */
  if (q <= 0) return 0;
  while (lo < hi) {
    int mid = (lo + hi + 1) / 2;
    if (aa_light(cell, mid) <= q) lo = mid; else hi = mid - 1;
  }
  if (lo < 255 && aa_light(cell, lo + 1) - q < q - aa_light(cell, lo)) lo++;
  return lo;
}

/* ---- the context's helpers ------------------------------------------------------------ */

void *aa_calloc(struct aa_ctx *c, size_t n, size_t sz)
{
  void *p = calloc(n ? n : 1, sz);
  if (!p) t74_fail(c->err, T74_EIO, "out of host memory");
  return p;
}

int aa_core(struct aa_ctx *c, const char *table, uint32_t words, uint32_t *addr)
{
  return core_alloc(c->eng->core, table, words, addr, c->err);
}

void aa_line_free(struct aa_line *l)
{
  free(l->s);
  memset(l, 0, sizeof *l);
}

static double rat_d(struct grat x) { return (double)x.num / (double)x.den; }

double aa_frag_light(struct aa_ctx *c, int face, unsigned blocked, double u, double v, int i, int j)
{
  int g;
  if (c->model) g = fx_shade(c->model, face, blocked, u, v, i, j, c->cost, NULL);
  else if (c->grey_at) g = c->grey_at(c->grey_ctx, face, i, j);
  else if (face >= 0 && c->flat) g = c->eng->map->f[face].grey;
  else if (face < 0 && !c->f->bg) g = 0;
  else {
    i = i < 0 ? 0 : i >= c->W ? c->W - 1 : i;
    j = j < 0 ? 0 : j >= c->H ? c->H - 1 : j;
    size_t at = (size_t)j * (size_t)c->W + (size_t)i;
    if (face < 0) g = c->f->bg[at];
    else g = c->f->face[at] == face ? c->f->grey[at] : c->eng->map->f[face].grey;
  }
  COST_ADD_N(c->cost, COST_MEM, 3);
  COST_ADD_N(c->cost, COST_ADD, 1);
  return c->ltab[g];
}

int aa_line_y(struct aa_ctx *c, int64_t yn, int64_t yd, struct aa_line *l)
{
  const struct vis_span *vsp = NULL;
  const struct fx_span *fsp = NULL;
  int ns;
  int st = c->lines ? fx_lines_get(c->lines, yn, yd, &fsp, &ns, c->err)
                    : fx_see_spans(c->see, yn, yd, &vsp, &ns, c->err);
  if (st != T74_OK) return st;
  c->nlines++;
  if (ns > l->cap) {
    int cap = l->cap ? l->cap : 16;
    while (cap < ns) cap *= 2;
    struct aa_seg *n = realloc(l->s, (size_t)cap * sizeof *n);
    if (!n) return t74_fail(c->err, T74_EIO, "out of host memory");
    l->s = n;
    l->cap = cap;
  }
  l->n = ns;
  l->yn = yn;
  l->yd = yd;
  l->v = aa_v_at(c, yn, yd);
  for (int k = 0; k < ns; k++) {
    struct aa_seg *s = &l->s[k];
    if (fsp) {
      s->x0 = fsp[k].x0; s->x1 = fsp[k].x1;
      s->piece = fsp[k].piece; s->face = fsp[k].face; s->blocked = fsp[k].blocked;
    } else {
      s->x0 = vsp[k].x0; s->x1 = vsp[k].x1;
      s->piece = vsp[k].piece; s->face = vsp[k].face; s->blocked = 0;
    }
    s->u0 = (rat_d(s->x0) - c->xl) / c->pw;
    s->u1 = (rat_d(s->x1) - c->xl) / c->pw;
    /* each end to a one-word fraction of a point: a divide of the exact rational */
    cost_mw_div(c->cost, 75, 46);
    cost_mw_div(c->cost, 75, 46);
  }
  return T74_OK;
}

double aa_v_at(const struct aa_ctx *c, int64_t yn, int64_t yd)
{
  return (c->yt - (double)yn / (double)yd) / c->ph;
}

void aa_y_of_v(const struct aa_ctx *c, int64_t vn, int64_t vd, int64_t *yn, int64_t *yd)
{
  const int32_t *w = c->g->window;
  *yd = vd * (int64_t)c->H;
  *yn = GRID_ONE * (*yd * (int64_t)w[3] - vn * ((int64_t)w[3] - w[1]));
}

int aa_line_v(struct aa_ctx *c, int64_t vn, int64_t vd, struct aa_line *l)
{
  int64_t yn, yd;
  aa_y_of_v(c, vn, vd, &yn, &yd);
  return aa_line_y(c, yn, yd, l);
}

double aa_mean_clamp(double p, double q, double a, double b)
{
  double w = b - a, P = p - a, Q = q - a;
  if (fabs(Q - P) < 1e-12) {
    double m = (P + Q) / 2;
    return a + (m < 0 ? 0 : m > w ? w : m);
  }
  /* Phi(s) = integral of clamp(t, 0, w) dt from 0 to s */
#define PHI(s) ((s) <= 0 ? 0.0 : (s) <= w ? (s) * (s) / 2 : w * w / 2 + w * ((s) - w))
  return a + (PHI(Q) - PHI(P)) / (Q - P);
#undef PHI
}

/* ---- exact: the bands ------------------------------------------------------------------ */

struct xline {
  int64_t a, b, c;          /* the side's line */
  double ylo, yhi, xlo, xhi;   /* its extent */
  int piece;                /* a piece's index, or a polygon's id (>= the pieces' count) */
};

static int cmp_double(const void *p, const void *q)
{
  double a = *(const double *)p, b = *(const double *)q;
  return (a > b) - (a < b);
}

struct evlist { double *y; int n, cap; struct xline *ln; int nl, lcap; };

static int ev_push(struct evlist *e, double y)
{
  if (e->n == e->cap) {
    int cap = e->cap ? 2 * e->cap : 256;
    double *n = realloc(e->y, (size_t)cap * sizeof *n);
    if (!n) return 0;
    e->y = n;
    e->cap = cap;
  }
  e->y[e->n++] = y;
  return 1;
}

static int ln_push(struct evlist *e, struct xline l)
{
  if (e->nl == e->lcap) {
    int cap = e->lcap ? 2 * e->lcap : 64;
    struct xline *n = realloc(e->ln, (size_t)cap * sizeof *n);
    if (!n) return 0;
    e->ln = n;
    e->lcap = cap;
  }
  e->ln[e->nl++] = l;
  return 1;
}

/* The vertices and sides of the frame model's polygons ps (a contour cut's regions, the
   shadows) that reach into (ya, yb): where a stretch is cut or split, its end follows a
   side of the polygon. Their lines carry id, id + 1, ... (one a polygon) in `piece`. */
static int poly_events(struct aa_ctx *c, const struct fx_polys *ps, int id, double ya,
                       double yb, struct evlist *e)
{
  for (int k = 0; k < ps->n; k++) {
    const struct fx_poly *p = &ps->p[k];
    COST_ADD_N(c->cost, COST_MEM, 2);
    if ((double)p->ylo >= yb || (double)p->yhi <= ya) continue;
    for (int r = 0; r < p->nring; r++) {
      int a = p->rs[r], n = p->rs[r + 1] - a;
      for (int v = 0; v < n; v++) {
        struct gpoint p0 = p->pt[a + v], p1 = p->pt[a + (v + 1) % n];
        double y0 = (double)p0.y, y1 = (double)p1.y;
        COST_ADD_N(c->cost, COST_MEM, 4);
        if (y0 > ya && y0 < yb && !ev_push(e, y0)) return 0;
        if (p0.y == p1.y) continue;
        double l = y0 < y1 ? y0 : y1, h = y0 < y1 ? y1 : y0;
        if (l >= yb || h <= ya) continue;
        struct gline g = geom_line(p0, p1);
        double x0 = (double)p0.x, x1 = (double)p1.x;
        if (!ln_push(e, (struct xline){ g.a, g.b, g.c, l, h, x0 < x1 ? x0 : x1, x0 < x1 ? x1 : x0,
                                        id + k }))
          return 0;
      }
    }
  }
  return 1;
}

/* Heights in (ya, yb) where the visible structure can change: vertices of alive pieces
   and crossings of their sides, and with a frame model the same of its polygons (a cut
   or a shadow begins, ends or turns there); sorted, with ya and yb at the ends. */
static int events(struct aa_ctx *c, double ya, double yb, struct evlist *e)
{
  const struct seginfo *s = &c->r->seg;
  e->n = 0;
  e->nl = 0;
  if (!ev_push(e, ya) || !ev_push(e, yb)) return 0;
  for (int p = 0; p < s->n; p++) {
    const struct piece *pc = &s->p[p];
    if (!pc->alive) continue;
    struct hpoint vb[PIECE_VBUF];
    struct gline lb[PIECE_VBUF];
    const struct gline *pl = piece_lines(pc, lb);
    const struct hpoint *pv = piece_verts_of(pc, pl, vb);
    double lo = (double)pv[pc->lo].Y / (double)pv[pc->lo].W,
           hi = (double)pv[pc->hi].Y / (double)pv[pc->hi].W;
    COST_ADD_N(c->cost, COST_MEM, 4);
    if (lo >= yb || hi <= ya) continue;
    for (int k = 0; k < pc->n; k++) {
      double y0 = (double)pv[k].Y / (double)pv[k].W;
      double y1 = (double)pv[(k + 1) % pc->n].Y / (double)pv[(k + 1) % pc->n].W;
      cost_mw_div(c->cost, 88, 59);
      if (y0 > ya && y0 < yb && !ev_push(e, y0)) return 0;
      if (pl[k].a == 0) continue;
      double l = y0 < y1 ? y0 : y1, h = y0 < y1 ? y1 : y0;
      if (l >= yb || h <= ya) continue;
      double x0 = (double)pv[k].X / (double)pv[k].W;
      double x1 = (double)pv[(k + 1) % pc->n].X / (double)pv[(k + 1) % pc->n].W;
      if (!ln_push(e, (struct xline){ pl[k].a, pl[k].b, pl[k].c, l, h,
                                      x0 < x1 ? x0 : x1, x0 < x1 ? x1 : x0, p }))
        return 0;
    }
  }
  if (c->model) {
    const struct fx_model *m = c->model;
    if (!poly_events(c, &m->cuts, s->n, ya, yb, e) ||
        !poly_events(c, &m->shadows, s->n + m->cuts.n, ya, yb, e))
      return 0;
  }
  for (int m = 0; m < e->nl; m++)
    for (int q = m + 1; q < e->nl; q++) {
      const struct xline *A = &e->ln[m], *B = &e->ln[q];
      if (A->piece == B->piece) continue;
      /* a polygon's side against anything: sides whose x extents lie a grid unit or more
         apart do not meet (two pieces' sides are taken as they always were) */
      if ((A->piece >= s->n || B->piece >= s->n) &&
          (A->xhi + 1 < B->xlo || B->xhi + 1 < A->xlo)) {
        COST_ADD_N(c->cost, COST_ADD, 2); COST_ADD_N(c->cost, COST_BRANCH, 2);
        continue;
      }
      wide den = (wide)A->a * B->b - (wide)B->a * A->b;
      cost_mw_mul(c->cost, 29, 29);
      if (den == 0) continue;
      wide num = (wide)B->a * A->c - (wide)A->a * B->c;
      cost_mw_mul(c->cost, 29, 58);
      double y = (double)num / (double)den;
      if (y <= ya || y >= yb || y < A->ylo || y > A->yhi || y < B->ylo || y > B->yhi) continue;
      if (!ev_push(e, y)) return 0;
    }
  qsort(e->y, (size_t)e->n, sizeof *e->y, cmp_double);
  int k = 0;
  for (int m = 0; m < e->n; m++)
    if (k == 0 || e->y[m] > e->y[k - 1]) e->y[k++] = e->y[m];
  e->n = k;
  return 1;
}

/* What the exact integration of one band hands on: stretch k runs from (a0, a1) at the
   band's top-of-v edge va to (b0, b1) at vb (va < vb in v). */
struct band_fn {
  void (*run)(struct aa_ctx *c, double va, double vb, const struct aa_line *A,
              const struct aa_line *B, double ta, double tb, void *ctx);
  void *ctx;
};

/* ---- exact, box filter ---------------------------------------------------------------- */

struct box_acc { double *cov; };          /* W * H covered fraction (the rest: background) */

/* End k of stretch s at parameter t (0: line A, 1: line B), extended linearly. */
static inline double lerp(double p, double q, double t) { return p + (q - p) * t; }

static void box_band(struct aa_ctx *c, double va, double vb, const struct aa_line *A,
                     const struct aa_line *B, double ta, double tb, void *ctx)
{
  struct box_acc *b = ctx;
  int j = (int)floor((va + vb) / 2);
  if (j < 0 || j >= c->H) return;
  double hv = vb - va;
  for (int k = 0; k < A->n; k++) {
    const struct aa_seg *p = &A->s[k], *q = &B->s[k];
    double u0a = lerp(p->u0, q->u0, ta), u0b = lerp(p->u0, q->u0, tb);
    double u1a = lerp(p->u1, q->u1, ta), u1b = lerp(p->u1, q->u1, tb);
    int i0 = (int)floor(fmin(u0a, u0b)), i1 = (int)floor(fmax(u1a, u1b));
    if (i0 < 0) i0 = 0;
    if (i1 > c->W - 1) i1 = c->W - 1;
    for (int i = i0; i <= i1; i++) {
      double cov = hv * (aa_mean_clamp(u1a, u1b, i, i + 1) - aa_mean_clamp(u0a, u0b, i, i + 1));
      COST_ADD_N(c->cost, COST_MUL, 2);
      COST_ADD_N(c->cost, COST_ADD, 6);
      if (cov <= 0) continue;
      size_t at = (size_t)j * (size_t)c->W + (size_t)i;
      double tm = (ta + tb) / 2;
      c->out[at] += cov * aa_frag_light(c, p->face, p->blocked,
                                        aa_mid(lerp(p->u0, q->u0, tm), lerp(p->u1, q->u1, tm), i),
                                        (va + vb) / 2, i, j);
      b->cov[at] += cov;
    }
  }
}

/* ---- exact, Gaussian filter ----------------------------------------------------------- */

struct gauss_acc { double sigma, vol; };

/* Integral of exp(-x^2 / (2 s^2)) from a to b. */
static double gint(double a, double b, double s)
{
  double k = s * sqrt(2.0);
  return s * sqrt(AA_PI / 2) * (erf(b / k) - erf(a / k));
}

/* The Gaussian's share of [s0, s1) on the line v for the points whose filter reaches it,
   times wgt * light (the fragment's intensity taken in each column it crosses). */
static void gauss_stretch(struct aa_ctx *c, const struct gauss_acc *g, double v, double s0,
                          double s1, int face, unsigned blocked, double wgt)
{
  int jr = (int)floor(v);                     /* the row the line lies in (intensity) */
  int ja = (int)floor(v - 0.5);               /* rows whose centres lie within 1 of v */
  for (int col = (int)floor(s0); col < s1; col++) {
    double a = fmax(s0, col), b = fmin(s1, col + 1.0);
    if (b <= a) continue;
    double light = aa_frag_light(c, face, blocked, (a + b) / 2, v, col, jr);
    for (int jj = ja; jj <= ja + 1; jj++) {
      if (jj < 0 || jj >= c->H) continue;
      double dy = v - (jj + 0.5);
      if (fabs(dy) >= 1) continue;
      double hw = sqrt(1 - dy * dy), ey = exp(-dy * dy / (2 * g->sigma * g->sigma));
      for (int i = col - 1; i <= col + 1; i++) {
        if (i < 0 || i >= c->W) continue;
        double cx = i + 0.5, lo = fmax(a, cx - hw) - cx, hi = fmin(b, cx + hw) - cx;
        if (hi <= lo) continue;
        c->out[(size_t)jj * (size_t)c->W + (size_t)i] += wgt * ey * gint(lo, hi, g->sigma) / g->vol * light;
        COST_ADD_N(c->cost, COST_MUL, 4);
        COST_ADD_N(c->cost, COST_ADD, 6);
      }
    }
  }
}

static void gauss_band(struct aa_ctx *c, double va, double vb, const struct aa_line *A,
                       const struct aa_line *B, double ta, double tb, void *ctx)
{
  const struct gauss_acc *g = ctx;
  static const double gx[3] = { -0.7745966692414834, 0.0, 0.7745966692414834 };
  static const double gw[3] = { 5.0 / 9, 8.0 / 9, 5.0 / 9 };
  int m = (int)ceil((vb - va) * 32);
  if (m < 1) m = 1;
  double lo = -1.5, hi = c->W + 1.5;          /* the filters of the edge points reach here */
  for (int s = 0; s < m; s++) {
    double a = va + (vb - va) * s / m, b = va + (vb - va) * (s + 1) / m;
    for (int q = 0; q < 3; q++) {
      double v = (a + b) / 2 + gx[q] * (b - a) / 2, wgt = gw[q] * (b - a) / 2;
      double t = ta + (tb - ta) * (v - va) / (vb - va);
      double x = lo;
      for (int k = 0; k < A->n; k++) {
        double u0 = lerp(A->s[k].u0, B->s[k].u0, t), u1 = lerp(A->s[k].u1, B->s[k].u1, t);
        if (u0 > x) gauss_stretch(c, g, v, x, fmin(u0, hi), -1, 0, wgt);
        gauss_stretch(c, g, v, fmax(u0, lo), fmin(u1, hi), A->s[k].face, A->s[k].blocked, wgt);
        if (u1 > x) x = u1;
      }
      if (x < hi) gauss_stretch(c, g, v, x, hi, -1, 0, wgt);
    }
  }
}

/* Walk [v_top, v_bot] (v_top < v_bot) bottom first, band by band (see the file head). */
static int exact_rows(struct aa_ctx *c, double vtop, double vbot, bool centres,
                      const struct band_fn *fn)
{
  struct evlist e = { 0 };
  struct aa_line A = { 0 }, B = { 0 };
  const double YQ = (double)GRID_YDEN_MAX;     /* sample lines at 1/65536 grid unit */
  int st = T74_OK;
  uint64_t unmatched = 0;
  for (int j = (int)ceil(vbot) - 1; st == T74_OK && j >= (int)floor(vtop); j--) {
    double v0 = fmax(j, vtop), v1 = fmin(j + 1.0, vbot);
    if (v1 <= v0) continue;
    double ya = c->yt - v1 * c->ph, yb = c->yt - v0 * c->ph;   /* ya < yb: grid y */
    int pieces = c->r->seg.n;
    if (!events(c, ya, yb, &e)) { st = t74_fail(c->err, T74_EIO, "out of host memory"); break; }
    if (centres && j + 0.5 > v0 && j + 0.5 < v1) {
      if (!ev_push(&e, c->yt - (j + 0.5) * c->ph)) { st = t74_fail(c->err, T74_EIO, "out of host memory"); break; }
      qsort(e.y, (size_t)e.n, sizeof *e.y, cmp_double);
    }
    for (int k = 0; st == T74_OK && k + 1 < e.n; k++) {
      double y0 = e.y[k], y1 = e.y[k + 1];
      double s0 = ceil((y0 + (y1 - y0) / 4) * YQ), s1 = floor((y0 + 3 * (y1 - y0) / 4) * YQ);
      if (s1 <= s0) continue;                  /* thinner than 4/65536 grid unit: nothing */
      if ((st = aa_line_y(c, (int64_t)s0, GRID_YDEN_MAX, &A)) != T74_OK) break;
      if ((st = aa_line_y(c, (int64_t)s1, GRID_YDEN_MAX, &B)) != T74_OK) break;
      double ys0 = s0 / YQ, ys1 = s1 / YQ;
      /* t(y): 0 on line A, 1 on line B; v runs the other way from y */
      double ta = (y1 - ys0) / (ys1 - ys0), tb = (y0 - ys0) / (ys1 - ys0);
      double va = (c->yt - y1) / c->ph, vb = (c->yt - y0) / c->ph;
      bool match = A.n == B.n;
      for (int m = 0; match && m < A.n; m++)
        match = A.s[m].piece == B.s[m].piece && A.s[m].blocked == B.s[m].blocked;
      if (match) {
        fn->run(c, va, vb, &A, &B, ta, tb, fn->ctx);
      } else {
        unmatched++;
        double vm = (va + vb) / 2;
        fn->run(c, vm, vb, &A, &A, 0, 0, fn->ctx);
        fn->run(c, va, vm, &B, &B, 0, 0, fn->ctx);
      }
      if (c->r->seg.n != pieces) {              /* a piece was cut: heights anew */
        pieces = c->r->seg.n;
        double from = y1, to = yb;
        if (!events(c, from, to, &e)) { st = t74_fail(c->err, T74_EIO, "out of host memory"); break; }
        if (centres && j + 0.5 > v0 && j + 0.5 < v1) {
          double yc = c->yt - (j + 0.5) * c->ph;
          if (yc > from && yc < to && !ev_push(&e, yc)) { st = t74_fail(c->err, T74_EIO, "out of host memory"); break; }
          qsort(e.y, (size_t)e.n, sizeof *e.y, cmp_double);
        }
        k = -1;
      }
    }
  }
  fx_count(c->st, "aa_exact_unmatched", (double)unmatched, true);
  free(e.y);
  free(e.ln);
  aa_line_free(&A);
  aa_line_free(&B);
  return st;
}

int aa_exact(struct aa_ctx *c)
{
  size_t n = (size_t)c->W * (size_t)c->H;
  int st;
  if (c->e->filter == EFFECTS_FILTER_GAUSS) {
    double s = c->e->sigma;
    struct gauss_acc g = { s, 2 * AA_PI * s * s * (1 - exp(-1 / (2 * s * s))) };
    struct band_fn fn = { gauss_band, &g };
    st = exact_rows(c, -0.5, c->H + 0.5, true, &fn);
    /* the filter's volume inside the disk is 1 by construction; what a point's disk
       reaches beyond -1.5 .. W+1.5 is nothing, so no further normalisation */
    return st;
  }
  struct box_acc b = { aa_calloc(c, n, sizeof(double)) };
  if (!b.cov) return c->err->status;
  struct band_fn fn = { box_band, &b };
  st = exact_rows(c, 0.0, (double)c->H, false, &fn);
  for (int j = 0; st == T74_OK && j < c->H; j++)
    for (int i = 0; i < c->W; i++) {
      size_t at = (size_t)j * (size_t)c->W + (size_t)i;
      double rest = 1 - b.cov[at];
      if (rest > 1e-12) c->out[at] += rest * aa_frag_light(c, -1, 0, i + 0.5, j + 0.5, i, j);
    }
  free(b.cov);
  return st;
}

/* ---- the run ---------------------------------------------------------------------------- */

int aa_light_map(const struct fx_engine *eng, const struct effects *e, const struct fx_frame *f, struct fx_stats *st, struct cost *cost,
                 double *light, struct t74_error *err)
{
  const struct vis_grid *g = eng->g;
  struct aa_ctx c;
  memset(&c, 0, sizeof c);
  c.eng = eng; c.r = eng->r; c.e = e; c.g = g; c.f = f; c.st = st; c.cost = cost; c.err = err;
  c.W = f->W; c.H = f->H; c.cell = f->cell;
  c.xl = (double)GRID_ONE * g->window[0];
  c.yt = (double)GRID_ONE * g->window[3];
  c.pw = (double)GRID_ONE * (g->window[2] - g->window[0]) / c.W;
  c.ph = (double)GRID_ONE * (g->window[3] - g->window[1]) / c.H;
  c.grey_at = NULL;                           /* the frame's intensities */
  c.flat = e->smooth == EFFECTS_SMOOTH_NONE && !e->contour_on;
  c.out = light;
  memset(light, 0, (size_t)c.W * (size_t)c.H * sizeof *light);
  const char *why = eng->r ? NULL : fx_needs_1974(e);
  if (why) return t74_fail(err, T74_EINPUT, "the points engine cannot run this: %s", why);
  int rc = aa_core(&c, "AA LIGHT TABLE", 256, &c.light_at);
  if (rc != T74_OK) return rc;
  for (int k = 0; k < 256; k++) core_write(eng->core, c.light_at + (uint32_t)k, (uint16_t)aa_light(c.cell, k));
  for (int k = 0; k < 256; k++) c.ltab[k] = core_read(eng->core, c.light_at + (uint32_t)k) / (double)AA_LIGHT_ONE;
  c.model = f->model;
  if (c.model) rc = fx_lines_open(&c.lines, c.model, false, cost, err);
  else rc = fx_see_open(&c.see, eng, NULL, cost, err);
  if (rc == T74_OK) {
    switch (e->aa) {
    case EFFECTS_AA_EXACT:     rc = aa_exact(&c); break;
    case EFFECTS_AA_MULTISCAN: rc = e->filter == EFFECTS_FILTER_GAUSS ? aa_multiscan_gauss(&c)
                                                                      : aa_multiscan_box(&c); break;
    case EFFECTS_AA_AREA:      rc = aa_area(&c); break;
    case EFFECTS_AA_SUPER:     rc = aa_super(&c); break;
    default:                   break;
    }
  }
  if (rc == T74_OK) fx_count(st, "aa_sub_scanlines", (double)c.nlines, true);
  if (c.model) fx_lines_close(c.lines);
  else fx_see_close(c.see);
  return rc;
}

int aa_run(const struct fx_engine *eng, const struct effects *e, struct fx_frame *f, struct fx_stats *st, struct cost *cost,
           struct t74_error *err)
{
  size_t n = (size_t)f->W * (size_t)f->H;
  double *light = malloc(n * sizeof *light);
  if (!light) return t74_fail(err, T74_EIO, "out of host memory");
  int rc = aa_light_map(eng, e, f, st, cost, light, err);
  if (rc == T74_OK) {
    int tab[256];                             /* the light table */
    for (int k = 0; k < 256; k++) tab[k] = aa_light(f->cell, k);
    /* the host's shortcut to the same answer: inv[q] = the last grey with light <= 8q */
    uint8_t inv[AA_LIGHT_ONE / 8 + 1];
    for (int q = 0, gg = 0; q <= AA_LIGHT_ONE / 8; q++) {
      while (gg < 255 && tab[gg + 1] <= 8 * q) gg++;
      inv[q] = (uint8_t)gg;
    }
    for (size_t k = 0; k < n; k++) {
      /* the grey of nearest light (ties to the darker), as a search by halving in the
         table finds it on the machine (8 compares, counted below) */
      double q = light[k] * AA_LIGHT_ONE;
      int lo = 0;
      if (q > 0) {
        int b = q >= AA_LIGHT_ONE ? AA_LIGHT_ONE / 8 : (int)(q / 8);
        lo = inv[b];
        while (lo < 255 && tab[lo + 1] <= q) lo++;
        if (lo < 255 && tab[lo + 1] - q < q - tab[lo]) lo++;
      }
      f->grey[k] = (uint8_t)lo;
      COST_ADD_N(cost, COST_MEM, 2 + 8 * 2);
      COST_ADD_N(cost, COST_ADD, 8);
      COST_ADD_N(cost, COST_BRANCH, 8);
    }
  }
  free(light);
  return rc;
}
