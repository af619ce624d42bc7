/*
** aa_area.c — adaptive area sampling after paper 001 (Kumamoto): aa=area depth=D.
**
** This file contains code to find, for each point, how much of it each visible fragment
** covers, by the paper's classification of a fragment in a pixel area: it covers the
** whole area (1), none of it (0), or one edge crosses the area, and then the share comes
** from a table indexed by the horizontal and vertical distances from the area's centre
** to the edge; in every other case the area is divided 2 x 2 and each part classified
** again, down to depth D, where what is left is taken by the trapezoid rule from the
** part's top and bottom borders. --stats counts the divisions (aa_subdivisions): the
** paper's time grows with them.
**
** What is known of an area: the visible stretches on its top and bottom borders. These
** are sub-scanlines of the exact visible-span procedure (vis_spans), 2^D + 1 a point row
** (the row's bottom border shared with the row below), so visibility is never decided
** here. An edge is "one edge" when both borders together show exactly two fragments, at
** most one boundary on each, and the boundary lies on one straight side of one of the two
** pieces (found exactly: the side's x on the border line equals the stretch's end, as
** exact rationals), on both borders when both have a boundary, or, with only one, the
** side leaves the area through its left or right side on the way to the other border;
** and no vertex of the two pieces lies inside the area. Neither case holds when another
** piece enters the area (meets it at all, seen or not: the paper's entry table), which is
** then divided. At depth D an area is taken from its two borders alone, so a piece lying
** between the borders of a smallest area is missed there (the blind spot each level of
** depth halves).
**
** THE TABLE. Coverage c(h, v) of the side of the edge holding the area's centre, for an
** edge crossing the horizontal through the centre at distance h and the vertical at
** distance v (area side = 1); by symmetry only h, v >= 0 are needed, and c >= 1/2.
** Distances from 0 to "never" are indexed through s = h/(1+h), w = v/(1+v) at 1/32
** steps: 33 x 33 = 1089 one-word entries (32768 = 1) in core, read bilinearly; h or v
** beyond the last finite step (s > 31/32, i.e. h > 31) runs between that step and the
** "never" column (a horizontal or vertical edge), which is where the coverage tends.
** The table's error against exact clipping, over all edges: at most 0.0151 of the area
** (measured by tests/test_aa.c, which holds it to 1/64).
*/
#include "effects/aa_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the table ------------------------------------------------------------------------ */

double aa_area_cover_exact(double h, double v)
{
  /* the half-plane p x + q y <= 1 (the centre's side), p = 1/h, q = 1/v */
  if (h <= 0 || v <= 0) return 0.5;               /* an edge through the centre halves it */
  double p = h > 1e30 ? 0 : 1 / h, q = v > 1e30 ? 0 : 1 / v;
  double px[8], py[8], ox[12], oy[12];
  int n = 4;
  px[0] = -0.5; py[0] = -0.5; px[1] = 0.5; py[1] = -0.5;
  px[2] = 0.5;  py[2] = 0.5;  px[3] = -0.5; py[3] = 0.5;
  int m = 0;
  for (int k = 0; k < n; k++) {
    double ax = px[k], ay = py[k], bx = px[(k + 1) % n], by = py[(k + 1) % n];
    double fa = 1 - p * ax - q * ay, fb = 1 - p * bx - q * by;
    if (fa >= 0) { ox[m] = ax; oy[m] = ay; m++; }
    if ((fa >= 0) != (fb >= 0)) {
      double t = fa / (fa - fb);
      ox[m] = ax + t * (bx - ax); oy[m] = ay + t * (by - ay); m++;
    }
  }
  double area = 0;
  for (int k = 0; k < m; k++) area += ox[k] * oy[(k + 1) % m] - ox[(k + 1) % m] * oy[k];
  return fabs(area) / 2;
}

void aa_area_table(uint16_t *t)
{
  for (int a = 0; a <= AA_AREA_STEPS; a++)
    for (int b = 0; b <= AA_AREA_STEPS; b++) {
      double s = (double)a / AA_AREA_STEPS, w = (double)b / AA_AREA_STEPS;
      double h = a == AA_AREA_STEPS ? HUGE_VAL : s / (1 - s);
      double v = b == AA_AREA_STEPS ? HUGE_VAL : w / (1 - w);
      long x = lround(aa_area_cover_exact(h, v) * AA_LIGHT_ONE);
      t[a * (AA_AREA_STEPS + 1) + b] = (uint16_t)(x > 65535 ? 65535 : x);
    }
}

double aa_area_lookup(const uint16_t *t, double h, double v)
{
  h = fabs(h);
  v = fabs(v);
  double s = (h > 1e30 ? 1 : h / (1 + h)) * AA_AREA_STEPS;
  double w = (v > 1e30 ? 1 : v / (1 + v)) * AA_AREA_STEPS;
  int a = (int)s, b = (int)w;
  if (a >= AA_AREA_STEPS) a = AA_AREA_STEPS - 1;
  if (b >= AA_AREA_STEPS) b = AA_AREA_STEPS - 1;
  double fs = s - a, fw = w - b;
  const int R = AA_AREA_STEPS + 1;
  double c00 = t[a * R + b], c01 = t[a * R + b + 1], c10 = t[(a + 1) * R + b], c11 = t[(a + 1) * R + b + 1];
  return ((c00 * (1 - fw) + c01 * fw) * (1 - fs) + (c10 * (1 - fw) + c11 * fw) * fs) / AA_LIGHT_ONE;
}

/* ---- the classification ------------------------------------------------------------------ */

#define AA_FRAG_MAX 64          /* fragments of one border within one area, at most */

struct frag { int piece, face; double u0, u1; struct grat x0, x1; bool x0_exact, x1_exact; unsigned blocked; };

struct area_run {
  struct aa_ctx *c;
  uint32_t table;           /* the area table's address in core */
  struct aa_line *ln;       /* the 2^D + 1 border lines of the row, ln[0] at the top */
  int D, j;
  uint64_t divisions, one_edge, whole, leaves;
  double (*bb)[4];          /* each piece's bounding box, u0 u1 v0 v1 (point units) */
  int nbb, bbcap;
  int *entry, nentry;       /* the row's entries: alive pieces whose box meets the row */
};

/* Does a piece other than X and Y enter the area (meet its inside)? The
   paper's entry table: every pixel a polygon's edge touches at all is entered, seen or
   not; such an area is neither whole nor one-edge, and is divided. */
static bool others_enter(struct area_run *ar, int X, int Y, double a, double b, double vt, double vb)
{
  for (int k = 0; k < ar->nentry; k++) {
    int p = ar->entry[k];
    COST_ADD_N(ar->c->cost, COST_MEM, 4);
    COST_ADD_N(ar->c->cost, COST_ADD, 4);
    if (p == X || p == Y) continue;
    const double *q = ar->bb[p];
    if (!(q[0] < b && q[1] > a && q[2] < vb && q[3] > vt)) continue;
    /* the box meets the area; so does the (convex) piece unless one of its sides has
       the whole area outside (separating sides: the area's and the piece's) */
    const struct piece *pc = &ar->c->r->seg.p[p];
    double xs[2] = { ar->c->xl + a * ar->c->pw, ar->c->xl + b * ar->c->pw };
    double ys[2] = { ar->c->yt - vb * ar->c->ph, ar->c->yt - vt * ar->c->ph };
    bool apart = false;
    for (int e = 0; e < pc->n && !apart; e++) {
      const struct gline side = piece_line(pc, e), *l = &side;
      bool in = false;
      for (int m = 0; m < 4 && !in; m++)
        in = (double)l->a * xs[m & 1] + (double)l->b * ys[m >> 1] + (double)l->c > 0;
      apart = !in;
      COST_ADD_N(ar->c->cost, COST_MUL, 8);
      COST_ADD_N(ar->c->cost, COST_ADD, 8);
    }
    if (!apart) return true;
  }
  /* a region of the frame model (a contour cut, a shadow) whose box meets the area
     enters it too: its boundary is no piece's side */
  const struct fx_model *m = ar->c->model;
  if (m && fx_model_regions(m)) {
    double x0 = ar->c->xl + a * ar->c->pw, x1 = ar->c->xl + b * ar->c->pw;
    double y0 = ar->c->yt - vb * ar->c->ph, y1 = ar->c->yt - vt * ar->c->ph;
    const struct fx_polys *sets[2] = { &m->cuts, &m->shadows };
    for (int q = 0; q < 2; q++)
      for (int k = 0; k < sets[q]->n; k++) {
        const struct fx_poly *p = &sets[q]->p[k];
        COST_ADD_N(ar->c->cost, COST_ADD, 4);
        if ((double)p->xlo < x1 && (double)p->xhi > x0 && (double)p->ylo < y1 && (double)p->yhi > y0)
          return true;
      }
  }
  return false;
}

/* The boxes of pieces made since last time, and the row's entries. */
static int row_entries(struct area_run *ar, int j)
{
  struct aa_ctx *c = ar->c;
  const struct seginfo *s = &c->r->seg;
  if (s->n > ar->bbcap) {
    int cap = ar->bbcap ? ar->bbcap : 64;
    while (cap < s->n) cap *= 2;
    double (*n)[4] = realloc(ar->bb, (size_t)cap * sizeof *n);
    int *e = realloc(ar->entry, (size_t)cap * sizeof *e);
    if (n) ar->bb = n;
    if (e) ar->entry = e;
    if (!n || !e) return t74_fail(c->err, T74_EIO, "out of host memory");
    ar->bbcap = cap;
  }
  for (; ar->nbb < s->n; ar->nbb++) {
    const struct piece *pc = &s->p[ar->nbb];
    double *q = ar->bb[ar->nbb];
    q[0] = q[2] = HUGE_VAL;
    q[1] = q[3] = -HUGE_VAL;
    struct hpoint vb[PIECE_VBUF];
    const struct hpoint *pv = piece_verts(pc, vb);
    for (int k = 0; k < pc->n; k++) {
      double u = ((double)pv[k].X / (double)pv[k].W - c->xl) / c->pw;
      double v = (c->yt - (double)pv[k].Y / (double)pv[k].W) / c->ph;
      q[0] = fmin(q[0], u); q[1] = fmax(q[1], u); q[2] = fmin(q[2], v); q[3] = fmax(q[3], v);
    }
    COST_ADD_N(c->cost, COST_DIV, 2 * pc->n);
  }
  ar->nentry = 0;
  for (int p = 0; p < s->n; p++) {
    COST_ADD_N(c->cost, COST_MEM, 2);
    if (s->p[p].alive && ar->bb[p][2] < j + 1 && ar->bb[p][3] > j) ar->entry[ar->nentry++] = p;
  }
  return T74_OK;
}

/* The fragments of line l within [a, b], background gaps included (piece -1). */
static int frags(const struct aa_line *l, double a, double b, struct frag *out, int max)
{
  int n = 0;
  double x = a;
  for (int k = 0; k < l->n && n < max; k++) {
    const struct aa_seg *s = &l->s[k];
    if (s->u1 <= a) continue;
    if (s->u0 >= b) break;
    double u0 = fmax(s->u0, a), u1 = fmin(s->u1, b);
    if (u1 <= u0) continue;
    if (u0 > x && n < max) out[n++] = (struct frag){ -1, -1, x, u0, { 0, 1 }, s->x0, false, true, 0 };
    if (n < max) out[n++] = (struct frag){ s->piece, s->face, u0, u1, s->x0, s->x1, s->u0 > a, s->u1 < b, s->blocked };
    x = u1;
  }
  if (x < b && n < max) out[n++] = (struct frag){ -1, -1, x, b, { 0, 1 }, { 0, 1 }, false, false, 0 };
  /* a gap's right end is the next stretch's left end (exact); mark a gap's left end */
  for (int k = 1; k < n; k++)
    if (out[k].piece < 0 && out[k - 1].piece >= 0) { out[k].x0 = out[k - 1].x1; out[k].x0_exact = true; }
  return n;
}

/* The side of piece p through the point (x, y = yn/yd) exactly: the index of its one
   left (left=true: a > 0) or right side there, -1 when none or more than one. */
static int side_at(struct aa_ctx *c, int p, bool left, struct grat x, int64_t yn, int64_t yd)
{
  const struct piece *pc = &c->r->seg.p[p];
  int found = -1;
  for (int k = 0; k < pc->n; k++) {
    const struct gline side = piece_line(pc, k), *l = &side;
    if (l->a == 0 || (l->a > 0) != left) continue;
    cost_mw_mul(c->cost, 58, 17);
    if (geom_rat_cmp(geom_x_at(*l, yn, yd), x) != 0) continue;
    if (found >= 0) return -1;                      /* a vertex on the border */
    found = k;
  }
  return found;
}

static bool vertex_inside(struct aa_ctx *c, int p, double a, double b, double vt, double vb)
{
  if (p < 0) return false;
  const struct piece *pc = &c->r->seg.p[p];
  struct hpoint pvb[PIECE_VBUF];
  const struct hpoint *pv = piece_verts(pc, pvb);
  for (int k = 0; k < pc->n; k++) {
    double x = ((double)pv[k].X / (double)pv[k].W - c->xl) / c->pw;
    double y = (c->yt - (double)pv[k].Y / (double)pv[k].W) / c->ph;
    COST_ADD_N(c->cost, COST_ADD, 4);
    if (x > a && x < b && y > vt && y < vb) return true;
  }
  return false;
}

static void add(struct area_run *ar, int face, unsigned blocked, double u, double v, int i,
                double share)
{
  struct aa_ctx *c = ar->c;
  if (share <= 0) return;
  c->out[(size_t)ar->j * (size_t)c->W + (size_t)i] += share * aa_frag_light(c, face, blocked, u, v, i, ar->j);
  COST_ADD_N(c->cost, COST_MUL, 1);
  COST_ADD_N(c->cost, COST_ADD, 2);
}

/* The one side of piece p (p >= 0) that crosses the area's left and right sides between
   its borders with the piece's interior above it (above=true) or below: -1 when none or
   more than one (the near-horizontal edge no border shows). */
static int side_across(struct aa_ctx *c, int p, bool above, double a, double b, double vt, double vb)
{
  if (p < 0) return -1;
  const struct piece *pc = &c->r->seg.p[p];
  int found = -1;
  double xa = c->xl + a * c->pw, xb = c->xl + b * c->pw;
  double ylo = c->yt - vb * c->ph, yhi = c->yt - vt * c->ph, ym = (ylo + yhi) / 2;
  for (int k = 0; k < pc->n; k++) {
    const struct gline side = piece_line(pc, k), *l = &side;
    COST_ADD_N(c->cost, COST_MUL, 4);
    COST_ADD_N(c->cost, COST_ADD, 6);
    if (l->b == 0) continue;
    double y1 = -((double)l->a * xa + (double)l->c) / (double)l->b;
    double y2 = -((double)l->a * xb + (double)l->c) / (double)l->b;
    if (y1 <= ylo || y1 >= yhi || y2 <= ylo || y2 >= yhi) continue;
    /* the interior is where L > 0: above the line when L grows with y (b > 0) */
    double xm = (xa + xb) / 2, lm = (double)l->a * xm + (double)l->b * (ym + (yhi - ylo)) + (double)l->c;
    if ((lm > 0) != above) continue;
    if (found >= 0) return -1;
    found = k;
  }
  return found;
}

/* Do the row's lines inside the area (those of the deeper levels, already at hand) show
   what the edge L says: the owner on L's inner side, the other piece beyond, the one
   boundary where L crosses? A piece hidden between the borders (a piece of the same face
   beyond a cut, say) shows here and sends the area on to be divided. */
static bool consistent(struct area_run *ar, struct gline L, int owner, int other, double a,
                       double b, int lt, int lb)
{
  struct aa_ctx *c = ar->c;
  struct frag F[AA_FRAG_MAX];
  for (int l = lt + 1; l < lb; l++) {
    int n = frags(&ar->ln[l], a, b, F, AA_FRAG_MAX);
    double y = c->yt - ar->ln[l].v * c->ph;
    double xl = L.a ? -((double)L.b * y + (double)L.c) / (double)L.a : 0;
    double ul = (xl - c->xl) / c->pw;
    COST_ADD_N(c->cost, COST_MEM, 4 * n);
    COST_ADD_N(c->cost, COST_MUL, 2 * n);
    for (int k = 0; k < n; k++) {
      double um = (F[k].u0 + F[k].u1) / 2, xm = c->xl + um * c->pw;
      bool in = (double)L.a * xm + (double)L.b * y + (double)L.c > 0;
      if (F[k].piece != (in ? owner : other)) return false;
      if (k > 0 && (!L.a || fabs(F[k].u0 - ul) > 1e-6)) return false;
    }
  }
  return true;
}

/* Try the one-edge case; true when the area was accounted for. */
static bool one_edge(struct area_run *ar, int i, double a, double b, int lt, int lb,
                     const struct frag *T, int nt, const struct frag *B, int nb, double area)
{
  struct aa_ctx *c = ar->c;
  if (nt > 2 || nb > 2) return false;
  int X, Y, owner = -1, side = -1;
  const double vt = ar->ln[lt].v, vb = ar->ln[lb].v;
  if (nt == 1 && nb == 1) {
    /* top all X, bottom all Y: an edge across the area from its left to its right side */
    X = T[0].piece;
    Y = B[0].piece;
    if (X == Y) return false;
    int sx = side_across(c, X, true, a, b, vt, vb), sy = side_across(c, Y, false, a, b, vt, vb);
    if ((sx >= 0) == (sy >= 0)) return false;      /* none, or both: which is in front? */
    owner = sx >= 0 ? X : Y;
    side = sx >= 0 ? sx : sy;
  } else {
    /* the two fragments, left X and right Y, from a border with a boundary */
    const struct frag *F = nt == 2 ? T : B;
    const struct aa_line *Lf = nt == 2 ? &ar->ln[lt] : &ar->ln[lb];
    const struct aa_line *Lo = nt == 2 ? &ar->ln[lb] : &ar->ln[lt];
    const struct frag *O = nt == 2 ? B : T;
    int no = nt == 2 ? nb : nt;
    X = F[0].piece;
    Y = F[1].piece;
    if (X == Y) return false;
    if (no == 2 && (O[0].piece != X || O[1].piece != Y)) return false;
    if (no == 1 && O[0].piece != X && O[0].piece != Y) return false;
    /* the boundary: Y's left side or X's right side through it */
    if (Y >= 0 && F[1].x0_exact) { side = side_at(c, Y, true, F[1].x0, Lf->yn, Lf->yd); owner = Y; }
    if (side < 0 && X >= 0 && F[0].x1_exact) { side = side_at(c, X, false, F[0].x1, Lf->yn, Lf->yd); owner = X; }
    if (side < 0) return false;
    const struct gline L = piece_line(&c->r->seg.p[owner], side);
    /* where the side meets the other border, and whether that agrees */
    struct grat xo = geom_x_at(L, Lo->yn, Lo->yd);
    cost_mw_mul(c->cost, 58, 17);
    if (no == 2) {
      if (!(O[1].x0_exact && geom_rat_cmp(xo, O[1].x0) == 0) &&
          !(O[0].x1_exact && geom_rat_cmp(xo, O[0].x1) == 0)) return false;
    } else {
      double uo = ((double)xo.num / (double)xo.den - c->xl) / c->pw;
      if (O[0].piece == X && uo < b) return false;    /* the side must leave by the right */
      if (O[0].piece == Y && uo > a) return false;    /* ... or by the left */
    }
  }
  const struct gline L = piece_line(&c->r->seg.p[owner], side);
  if (vertex_inside(c, X, a, b, vt, vb) || vertex_inside(c, Y, a, b, vt, vb)) return false;
  if (others_enter(ar, X, Y, a, b, vt, vb)) return false;
  if (!consistent(ar, L, owner, owner == X ? Y : X, a, b, lt, lb)) return false;
  /* the edge in the area's own units: centre 0, side 1, y up */
  double xc = c->xl + (a + b) / 2 * c->pw, yc = c->yt - (vt + vb) / 2 * c->ph;
  double sw = (b - a) * c->pw, sh = (vb - vt) * c->ph;
  double A = (double)L.a * sw, Bc = (double)L.b * sh, C = (double)L.a * xc + (double)L.b * yc + (double)L.c;
  double h = A != 0 ? fabs(C / A) : HUGE_VAL, v = Bc != 0 ? fabs(C / Bc) : HUGE_VAL;
  /* the table lookup: bilinear, 4 loads, 3 multiplies (and h, v: 2 divides) */
  double cov;
  {
    const int R = AA_AREA_STEPS + 1;
    double s = (h > 1e30 ? 1 : h / (1 + h)) * AA_AREA_STEPS, w = (v > 1e30 ? 1 : v / (1 + v)) * AA_AREA_STEPS;
    int ia = (int)s, ib = (int)w;
    if (ia >= AA_AREA_STEPS) ia = AA_AREA_STEPS - 1;
    if (ib >= AA_AREA_STEPS) ib = AA_AREA_STEPS - 1;
    double fs = s - ia, fw = w - ib;
    struct core *k = c->eng->core;
    double c00 = core_read(k, ar->table + (uint32_t)(ia * R + ib)), c01 = core_read(k, ar->table + (uint32_t)(ia * R + ib + 1));
    double c10 = core_read(k, ar->table + (uint32_t)((ia + 1) * R + ib)), c11 = core_read(k, ar->table + (uint32_t)((ia + 1) * R + ib + 1));
    cov = ((c00 * (1 - fw) + c01 * fw) * (1 - fs) + (c10 * (1 - fw) + c11 * fw) * fs) / AA_LIGHT_ONE;
    COST_ADD_N(c->cost, COST_MEM, 8);
    COST_ADD_N(c->cost, COST_MUL, 5);
    COST_ADD_N(c->cost, COST_DIV, 4);
    COST_ADD_N(c->cost, COST_ADD, 8);
  }
  /* the owner's interior is left of its side: L > 0 there */
  bool centre_owner = C > 0;
  int other = owner == X ? Y : X;
  int fo = owner >= 0 ? c->r->seg.p[owner].face : -1, fx = other >= 0 ? c->r->seg.p[other].face : -1;
  if (C == 0) cov = 0.5;
  unsigned bo = 0, bx = 0;                 /* no region enters: one mask a piece here */
  for (int k = 0; k < nt; k++) {
    if (T[k].piece == owner) bo = T[k].blocked;
    if (T[k].piece == other) bx = T[k].blocked;
  }
  double um = (a + b) / 2, vm = (vt + vb) / 2;
  add(ar, fo, bo, um, vm, i, area * (centre_owner ? cov : 1 - cov));
  add(ar, fx, bx, um, vm, i, area * (centre_owner ? 1 - cov : cov));
  ar->one_edge++;
  return true;
}


static void classify(struct area_run *ar, int i, double a, double b, int lt, int lb, int d)
{
  struct aa_ctx *c = ar->c;
  struct frag T[AA_FRAG_MAX], B[AA_FRAG_MAX];
  int nt = frags(&ar->ln[lt], a, b, T, AA_FRAG_MAX), nb = frags(&ar->ln[lb], a, b, B, AA_FRAG_MAX);
  COST_ADD_N(c->cost, COST_MEM, 4 * (nt + nb));
  COST_ADD_N(c->cost, COST_ADD, 2 * (nt + nb));
  double area = (b - a) * (ar->ln[lb].v - ar->ln[lt].v);
  if (nt == 1 && nb == 1 && T[0].piece == B[0].piece && T[0].blocked == B[0].blocked &&
      (d == ar->D || !others_enter(ar, T[0].piece, T[0].piece, a, b, ar->ln[lt].v, ar->ln[lb].v))) {
    add(ar, T[0].face, T[0].blocked, (a + b) / 2, (ar->ln[lt].v + ar->ln[lb].v) / 2, i, area);   /* whole */
    ar->whole++;
    return;
  }
  if (one_edge(ar, i, a, b, lt, lb, T, nt, B, nb, area)) return;
  if (d < ar->D) {
    int lm = (lt + lb) / 2;
    double m = (a + b) / 2;
    ar->divisions++;
    COST_ADD_N(c->cost, COST_BRANCH, 4);
    classify(ar, i, a, m, lt, lm, d + 1);
    classify(ar, i, m, b, lt, lm, d + 1);
    classify(ar, i, a, m, lm, lb, d + 1);
    classify(ar, i, m, b, lm, lb, d + 1);
    return;
  }
  /* depth D: the trapezoid rule on the two borders */
  ar->leaves++;
  for (int k = 0; k < nt; k++)
    add(ar, T[k].face, T[k].blocked, (T[k].u0 + T[k].u1) / 2, ar->ln[lt].v, i, area * (T[k].u1 - T[k].u0) / (2 * (b - a)));
  for (int k = 0; k < nb; k++)
    add(ar, B[k].face, B[k].blocked, (B[k].u0 + B[k].u1) / 2, ar->ln[lb].v, i, area * (B[k].u1 - B[k].u0) / (2 * (b - a)));
}

int aa_area(struct aa_ctx *c)
{
  const int D = c->e->depth, NL = (1 << D) + 1;
  struct area_run ar;
  memset(&ar, 0, sizeof ar);
  ar.c = c;
  ar.D = D;
  int st = aa_core(c, "AA AREA TABLE", AA_AREA_WORDS, &ar.table);
  if (st != T74_OK) return st;
  uint16_t tab[AA_AREA_WORDS];
  aa_area_table(tab);
  for (int k = 0; k < AA_AREA_WORDS; k++) core_write(c->eng->core, ar.table + (uint32_t)k, tab[k]);
  uint32_t rowbuf;
  if ((st = aa_core(c, "AA AREA ROW", (uint32_t)(2 * c->W), &rowbuf)) != T74_OK) return st;
  ar.ln = aa_calloc(c, (size_t)NL, sizeof *ar.ln);
  if (!ar.ln) return c->err->status;
  for (int j = c->H - 1; st == T74_OK && j >= 0; j--) {
    ar.j = j;
    /* the border lines, bottom first; line NL-1 is the row below's line 0 */
    uint32_t mark = core_mark(c->eng->core);
    if (j < c->H - 1) {
      struct aa_line t = ar.ln[NL - 1];
      ar.ln[NL - 1] = ar.ln[0];
      ar.ln[0] = t;
    }
    for (int l = (j == c->H - 1 ? NL - 1 : NL - 2); st == T74_OK && l >= 0; l--)
      st = aa_line_v(c, (int64_t)(NL - 1) * j + l, NL - 1, &ar.ln[l]);
    if (st != T74_OK) break;
    if ((st = row_entries(&ar, j)) != T74_OK) break;
    /* the row's lines in core while it is classified: 3 words a stretch */
    uint32_t words = 0, at;
    for (int l = 0; l < NL; l++) words += (uint32_t)(3 * ar.ln[l].n + 1);
    if ((st = aa_core(c, "AA AREA LINES", words, &at)) != T74_OK) break;
    for (int i = 0; i < c->W; i++) classify(&ar, i, i, i + 1.0, 0, NL - 1, 0);
    core_release(c->eng->core, mark);
  }
  fx_count(c->st, "aa_subdivisions", (double)ar.divisions, true);
  fx_count(c->st, "aa_one_edge", (double)ar.one_edge, true);
  fx_count(c->st, "aa_whole", (double)ar.whole, true);
  fx_count(c->st, "aa_depth_leaves", (double)ar.leaves, true);
  for (int l = 0; l < NL; l++) aa_line_free(&ar.ln[l]);
  free(ar.ln);
  free(ar.bb);
  free(ar.entry);
  return st;
}
