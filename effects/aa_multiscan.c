/*
** aa_multiscan.c — multi-scanning anti-aliasing of paper 000 (Nishita & Nakamae):
** aa=multiscan filter=box (§2.2.1) and filter=gauss (§2.2.2, §3.3).
**
** This file contains code to colour each point from n + 1 (box) or 2n - 1 (gauss)
** sub-scanlines, each sampled continuously along x: the visible stretches of a line come
** from vis_spans, the renderer's exact visible-span procedure, whose covering set with
** the front piece from the Priority Matrix is the paper's NEXT stack (§3.2): at the
** current polygon's right end the frontmost remaining one becomes current. A hidden face
** never contributes, since only visible stretches are used.
**
** BOX (eq. (1)-(3)). Lines l = 0 .. n divide a point row into n intervals, both borders
** included. On each line the visible length L_{f,l} of every face within each point is
** taken exactly, and the line's colour C'_{i,l} = sum_f L_{f,l} I_f (the background
** fills the rest) is added with weight d_l = 1/(2n) on the borders and 1/n inside. A
** border line is computed once: as line n of the row below (the walk is bottom row
** first, since lines must come in rising y) and as line 0 of the row above. Core: two
** rows of accumulators and the shared line, 2 words a point each.
**
** GAUSS (eq. (4), (5)). Lines divide the distance between two rows of point centres
** into n parts: line l of band b lies l/n below centre row b. The region R_ij between
** the four centres (i, j), (i+1, j), (i+1, j+1), (i, j+1) contributes to all four, by
** W_{l,0..3} of eq. (4) from the table F_l(x') (the integral from 0 to x' of the
** filter's section on line l, x' across R_ij from its left edge): F_l for the two upper
** corners, F_{n-l} for the two lower ones. The line l = n (F_n: the section one radius
** away) is ignored as in the paper, so each point sees 2n - 1 lines. The filter: a
** Gaussian exp(-r^2 / 2 sigma^2) truncated at one point's radius (the paper names no
** profile; sigma= defaults to 0.5 point), normalised so that the discrete volume the
** 2n - 1 lines see is exactly 1 (a flat field gives its own grey). F_l is tabulated at
** 64 steps of x' (the paper's table) as one-word fractions and read with linear
** interpolation between steps; x' is a 16-bit fraction (6 bits of step, 10 of
** interpolation). Along a line, R_ij is swept left to right in the paper's modes: 0 no
** crossing in R_ij (x'_1 = 0, x'_2 = 1), 1 from R's left end to the first visible
** crossing, 2 between two crossings, 3 from the last crossing to R's right end; the
** intensity of each segment is taken at its midpoint (the background picture's point
** there). Accumulation by eq. (5) into two rows of accumulators, C_{i,j} and C_{i,j+1}
** (32-bit, 2 words each), as the paper says; row j+1 is finished when band j is done.
*/
#include "effects/aa_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- box ------------------------------------------------------------------------------- */

/* The line's covered light and covered length within each point (row j's intensities). */
static void line_cover(struct aa_ctx *c, const struct aa_line *l, int j, double *lc, double *ll)
{
  for (int i = 0; i < c->W; i++) lc[i] = ll[i] = 0;
  for (int k = 0; k < l->n; k++) {
    const struct aa_seg *s = &l->s[k];
    if (s->u1 <= 0 || s->u0 >= c->W) continue;
    int i0 = (int)floor(fmax(s->u0, 0)), i1 = (int)floor(fmin(s->u1, c->W - 1e-9));
    /* flat shading: one light a stretch */
    bool one = c->model ? !fx_model_shades(c->model) : c->flat && !c->grey_at;
    double flat = one ? aa_frag_light(c, s->face, s->blocked, aa_mid(s->u0, s->u1, i0), l->v, i0, j) : 0;
    for (int i = i0; i <= i1; i++) {
      double len = fmin(s->u1, i + 1.0) - fmax(s->u0, (double)i);
      if (len <= 0) continue;
      lc[i] += len * (one ? flat : aa_frag_light(c, s->face, s->blocked, aa_mid(s->u0, s->u1, i), l->v, i, j));
      ll[i] += len;
      COST_ADD_N(c->cost, COST_MUL, 1);     /* L_{f,l} I_f, one word by one word */
      COST_ADD_N(c->cost, COST_ADD, 4);
      COST_ADD_N(c->cost, COST_MEM, 4);
    }
  }
}

static void add_line(struct aa_ctx *c, double *acc, const double *lc, const double *ll,
                     double d, int j)
{
  for (int i = 0; i < c->W; i++) {
    double rest = 1 - ll[i];
    double v = lc[i] + (rest > 1e-12 && (c->f->bg || c->grey_at || (c->model && c->model->bg)) ? rest * aa_frag_light(c, -1, 0, i + 0.5, j + 0.5, i, j) : 0);
    acc[i] += d * v;
    COST_ADD_N(c->cost, COST_MUL, 2);
    COST_ADD_N(c->cost, COST_ADD, 3);
    COST_ADD_N(c->cost, COST_MEM, 4);
  }
}

int aa_multiscan_box(struct aa_ctx *c)
{
  const int n = c->e->n, W = c->W;
  uint32_t rows;
  int st = aa_core(c, "AA MULTISCAN ROWS", (uint32_t)(4 * 2 * W), &rows);
  if (st != T74_OK) return st;
  double *buf = aa_calloc(c, (size_t)6 * (size_t)W, sizeof(double));
  if (!buf) return c->err->status;
  double *acc = buf, *lc = buf + W, *ll = buf + 2 * W, *sc = buf + 3 * W, *sl = buf + 4 * W,
         *up = buf + 5 * W;
  struct aa_line line = { 0 };
  for (int j = c->H - 1; st == T74_OK && j >= 0; j--) {
    memcpy(acc, up, (size_t)W * sizeof *acc);    /* row j's share of its bottom border */
    if (j == c->H - 1) {
      if ((st = aa_line_v(c, (int64_t)n * (j + 1), n, &line)) != T74_OK) break;
      line_cover(c, &line, j, sc, sl);
      memset(acc, 0, (size_t)W * sizeof *acc);
      add_line(c, acc, sc, sl, 1.0 / (2 * n), j);
    }
    for (int l = n - 1; st == T74_OK && l >= 0; l--) {
      if ((st = aa_line_v(c, (int64_t)n * j + l, n, &line)) != T74_OK) break;
      line_cover(c, &line, j, lc, ll);
      add_line(c, acc, lc, ll, l == 0 ? 1.0 / (2 * n) : 1.0 / n, j);
      if (l == 0 && j > 0) {                     /* the shared border: row j-1's line n */
        memset(up, 0, (size_t)W * sizeof *up);
        add_line(c, up, lc, ll, 1.0 / (2 * n), j - 1);
      }
    }
    for (int i = 0; i < W; i++) {
      c->out[(size_t)j * (size_t)W + (size_t)i] = acc[i];
      core_put_int(c->eng->core, rows + (uint32_t)(2 * i), 2, (int64_t)(acc[i] * AA_LIGHT_ONE));
    }
    COST_ADD_N(c->cost, COST_MEM, 2 * W);
  }
  aa_line_free(&line);
  free(buf);
  return st;
}

/* ---- gauss: the F table ------------------------------------------------------------------ */

void aa_ftable(int n, double sigma, uint16_t *t)
{
  double *F = malloc((size_t)n * (AA_FSTEPS + 1) * sizeof *F);
  if (!F) { memset(t, 0, (size_t)n * (AA_FSTEPS + 1) * sizeof *t); return; }
  double k2 = sigma * sqrt(2.0);
  for (int l = 0; l < n; l++) {
    double d = (double)l / n, hw = sqrt(1 - d * d), ey = exp(-d * d / (2 * sigma * sigma));
    for (int k = 0; k <= AA_FSTEPS; k++) {
      double x = fmin((double)k / AA_FSTEPS, hw);
      /* (1/n) * integral_0^x exp(-(x^2 + d^2) / 2 sigma^2) dx */
      F[l * (AA_FSTEPS + 1) + k] = ey * sigma * sqrt(AA_PI / 2) * erf(x / k2) / n;
    }
  }
  double vol = 2 * F[AA_FSTEPS];
  for (int l = 1; l < n; l++) vol += 4 * F[l * (AA_FSTEPS + 1) + AA_FSTEPS];
  long sum = 0;
  for (int l = 0; l < n; l++)
    for (int k = 0; k <= AA_FSTEPS; k++) {
      long v = lround(AA_FONE * F[l * (AA_FSTEPS + 1) + k] / vol);
      t[l * (AA_FSTEPS + 1) + k] = (uint16_t)v;
      if (k == AA_FSTEPS) sum += (l == 0 ? 2 : 4) * v;
    }
  /* the rounding's rest goes to F_0(1): the volume is then exactly AA_FONE (even: 2 | rest) */
  t[AA_FSTEPS] = (uint16_t)(t[AA_FSTEPS] + (AA_FONE - sum) / 2);
  free(F);
}

int aa_ftable_at(const uint16_t *t, int l, int32_t xq)
{
  const uint16_t *r = t + l * (AA_FSTEPS + 1);
  if (xq <= 0) return r[0];
  int k = xq >> 10, fr = xq & 1023;
  if (k >= AA_FSTEPS) return r[AA_FSTEPS];
  return r[k] + (((int)r[k + 1] - (int)r[k]) * fr >> 10);
}

/* F_l(xq) read from the table in core (counted: two loads, a multiply, a shift, adds). */
static int fcore(struct aa_ctx *c, uint32_t base, int l, int32_t xq)
{
  COST_ADD_N(c->cost, COST_MEM, 3);
  COST_ADD_N(c->cost, COST_MUL, 1);
  COST_ADD_N(c->cost, COST_SHIFT, 2);
  COST_ADD_N(c->cost, COST_ADD, 3);
  uint32_t row = base + (uint32_t)(l * (AA_FSTEPS + 1));
  if (xq <= 0) return core_read(c->eng->core, row);
  int k = xq >> 10, fr = xq & 1023;
  if (k >= AA_FSTEPS) return core_read(c->eng->core, row + AA_FSTEPS);
  int a = core_read(c->eng->core, row + (uint32_t)k), b = core_read(c->eng->core, row + (uint32_t)k + 1);
  return a + ((b - a) * fr >> 10);
}

/* ---- gauss: the sweep ---------------------------------------------------------------------- */

struct gseg { double u0, u1; int face; unsigned blocked; };

int aa_multiscan_gauss(struct aa_ctx *c)
{
  const int n = c->e->n, W = c->W, H = c->H;
  uint32_t ft, rows;
  int st = aa_core(c, "AA F TABLE", (uint32_t)(n * (AA_FSTEPS + 1)), &ft);
  if (st == T74_OK) st = aa_core(c, "AA MULTISCAN ROWS", (uint32_t)(2 * 2 * (W + 2)), &rows);
  if (st != T74_OK) return st;
  uint16_t *tab = malloc((size_t)n * (AA_FSTEPS + 1) * sizeof *tab);
  int64_t *acc = aa_calloc(c, (size_t)2 * (size_t)(W + 2), sizeof *acc);
  if (!tab || !acc) { free(tab); free(acc); return t74_fail(c->err, T74_EIO, "out of host memory"); }
  aa_ftable(n, c->e->sigma, tab);
  for (int k = 0; k < n * (AA_FSTEPS + 1); k++) core_write(c->eng->core, ft + (uint32_t)k, tab[k]);
  free(tab);
  int64_t *top = acc, *bot = acc + (W + 2);      /* C_{., b} and C_{., b+1}, index i + 1 */
  struct aa_line line = { 0 };
  struct gseg *seg = NULL;
  int segcap = 0;
  uint64_t modes[4] = { 0 };
  const double ulo = -0.5, uhi = W + 0.5;
  for (int b = H - 1; st == T74_OK && b >= -1; b--) {
    for (int l = n - 1; st == T74_OK && l >= 0; l--) {
      /* line l of band b: v = b + 1/2 + l/n */
      if ((st = aa_line_v(c, (int64_t)(2 * b + 1) * n + 2 * l, 2 * n, &line)) != T74_OK) break;
      int jr = (int)floor(line.v);
      /* the line as segments over [ulo, uhi): visible stretches and background gaps */
      if (segcap < 2 * line.n + 2) {
        segcap = 2 * line.n + 2;
        struct gseg *ns = realloc(seg, (size_t)segcap * sizeof *ns);
        if (!ns) { st = t74_fail(c->err, T74_EIO, "out of host memory"); break; }
        seg = ns;
      }
      int ns = 0;
      double x = ulo;
      for (int k = 0; k < line.n; k++) {
        double u0 = fmax(line.s[k].u0, ulo), u1 = fmin(line.s[k].u1, uhi);
        if (u1 <= u0) continue;
        if (u0 > x) seg[ns++] = (struct gseg){ x, u0, -1, 0 };
        seg[ns++] = (struct gseg){ u0, u1, line.s[k].face, line.s[k].blocked };
        x = u1;
      }
      if (x < uhi) seg[ns++] = (struct gseg){ x, uhi, -1, 0 };
      int s = 0;
      for (int i = -1; i < W; i++) {               /* region R_{i,b}: u in [i+1/2, i+3/2] */
        double r0 = i + 0.5;
        while (s < ns && seg[s].u1 <= r0) s++;
        int inside = 0;
        for (int q = s; q < ns && seg[q].u0 < r0 + 1; q++) {
          double a = fmax(seg[q].u0, r0), e = fmin(seg[q].u1, r0 + 1);
          if (e <= a) continue;
          int32_t x1 = (int32_t)lround((a - r0) * 65536), x2 = (int32_t)lround((e - r0) * 65536);
          if (x1 < 0) x1 = 0;
          if (x2 > 65536) x2 = 65536;
          double mid = (a + e) / 2;
          int64_t I = lround(aa_frag_light(c, seg[q].face, seg[q].blocked, mid, line.v, (int)floor(mid), jr) * AA_LIGHT_ONE);
          int64_t w0 = fcore(c, ft, l, x2) - fcore(c, ft, l, x1);
          int64_t w1 = fcore(c, ft, l, 65536 - x1) - fcore(c, ft, l, 65536 - x2);
          top[i + 1] += w0 * I;                   /* eq. (5): C_{i,j}, C_{i+1,j} */
          top[i + 2] += w1 * I;
          if (l > 0) {                            /* F_n: the outermost line, ignored */
            int64_t w2 = fcore(c, ft, n - l, 65536 - x1) - fcore(c, ft, n - l, 65536 - x2);
            int64_t w3 = fcore(c, ft, n - l, x2) - fcore(c, ft, n - l, x1);
            bot[i + 2] += w2 * I;                 /* C_{i+1,j+1}, C_{i,j+1} */
            bot[i + 1] += w3 * I;
          }
          COST_ADD_N(c->cost, COST_MUL, 4);
          COST_ADD_N(c->cost, COST_ADD, 16);
          COST_ADD_N(c->cost, COST_MEM, 16);
          inside++;
        }
        if (inside == 1) modes[0]++;
        else if (inside > 1) { modes[1]++; modes[3]++; modes[2] += (uint64_t)(inside - 2); }
      }
    }
    if (st != T74_OK) break;
    if (b + 1 < H) {                               /* row b+1 is done */
      for (int i = 0; i < W; i++) {
        c->out[(size_t)(b + 1) * (size_t)W + (size_t)i] =
            (double)bot[i + 1] / ((double)AA_FONE * AA_LIGHT_ONE);
        core_put_int(c->eng->core, rows + (uint32_t)(2 * i), 2, bot[i + 1]);
      }
      COST_ADD_N(c->cost, COST_MEM, 2 * W);
    }
    int64_t *t = bot;
    bot = top;
    top = t;
    memset(top, 0, (size_t)(W + 2) * sizeof *top);
  }
  fx_count(c->st, "aa_mode0", (double)modes[0], true);
  fx_count(c->st, "aa_mode1", (double)modes[1], true);
  fx_count(c->st, "aa_mode2", (double)modes[2], true);
  fx_count(c->st, "aa_mode3", (double)modes[3], true);
  free(seg);
  free(acc);
  aa_line_free(&line);
  return st;
}
