/*
** aa_super.c — supersampling, paper 000's method D: aa=super super=K.
**
** This file contains code to colour each point from samples on a lattice K times finer
** than the points: sample (k, m) is at u = (k + 1/2)/K, v = (m + 1/2)/K. With the 1974
** engine each sample line is asked of vis_spans (its exact visible-span procedure) and
** each sample is placed in its visible stretch exactly, by the same rational comparison
** the point scan uses; the points engine is asked for the samples themselves
** (effects/see.h: exact visibility at each sample, the same tie rules), so supersampling
** runs with either engine. Two filters:
**   gauss (the default for super; the paper's method D): every lattice sample within
**        one point of the point's centre (|du| < 1, |dv| < 1 and r < 1), weighted by
**        exp(-r^2 / 2 sigma^2) and normalised; for K = 3 these are the paper's 5 x 5
**        samples including the neighbouring points' (all 25 lie within r < 1);
**   box  (filter=box given): the K x K samples inside the point, plain mean.
** Other K than 3 are extensions of the paper. Core: the weight table (one word each)
** and the rows of accumulators the filter spans (2 words a point).
*/
#include "effects/aa_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int aa_super(struct aa_ctx *c)
{
  const int K = c->e->super, W = c->W, H = c->H;
  const bool box = c->e->filter == EFFECTS_FILTER_BOX && (c->e->given & EFFECTS_FILTER);
  /* offsets dk = k - K i of the samples a point uses, off0 .. off0 + D - 1 */
  int off0, D;
  if (box) { off0 = 0; D = K; }
  else {
    /* du = (dk + (1 - K)/2) / K, |du| < 1 */
    off0 = (K - 1) / 2 - K + 1;
    if (K % 2 == 0) off0 = K / 2 - K;
    D = (K % 2) ? 2 * K - 1 : 2 * K;
  }
  double *w = aa_calloc(c, (size_t)D * (size_t)D, sizeof *w);
  if (!w) return c->err->status;
  double sum = 0, s2 = 2 * c->e->sigma * c->e->sigma;
  for (int a = 0; a < D; a++)
    for (int b = 0; b < D; b++) {
      double du = (off0 + a + 0.5) / K - 0.5, dv = (off0 + b + 0.5) / K - 0.5;
      double r2 = du * du + dv * dv;
      w[a * D + b] = box ? 1.0 : (r2 < 1 ? exp(-r2 / s2) : 0);
      sum += w[a * D + b];
    }
  uint32_t wt, rows;
  int st = aa_core(c, "AA SUPER WEIGHTS", (uint32_t)(D * D), &wt);
  if (st == T74_OK) st = aa_core(c, "AA SUPER ROWS", (uint32_t)(2 * W * ((D + K - 1) / K + 1)), &rows);
  if (st != T74_OK) { free(w); return st; }
  for (int k = 0; k < D * D; k++) {
    w[k] /= sum;
    core_write(c->eng->core, wt + (uint32_t)k, (uint16_t)lround(w[k] * 32767));
  }
  const int32_t *win = c->g->window;
  const int64_t xd = 2 * (int64_t)K * W;
  struct aa_line line = { 0 };
  uint64_t samples = 0;
  int mlo = off0, mhi = K * (H - 1) + off0 + D - 1;
  int klo = off0, khi = K * (W - 1) + off0 + D - 1;
  /* the engine's stretches (the 1974 engine), or its samples (the points engine) */
  const bool spans = c->lines ? fx_lines_have_spans(c->lines) : fx_see_has_spans(c->see);
  int *sface = spans ? NULL : aa_calloc(c, (size_t)(khi - klo + 1), sizeof *sface);
  unsigned *sblk = spans ? NULL : aa_calloc(c, (size_t)(khi - klo + 1), sizeof *sblk);
  if (!spans && (!sface || !sblk)) st = c->err->status;
  for (int m = mhi; st == T74_OK && m >= mlo; m--) {
    double v;
    if (spans) {
      if ((st = aa_line_v(c, 2 * (int64_t)m + 1, 2 * (int64_t)K, &line)) != T74_OK) break;
      v = line.v;
    } else {
      int64_t yn, yd;
      aa_y_of_v(c, 2 * (int64_t)m + 1, 2 * (int64_t)K, &yn, &yd);
      v = aa_v_at(c, yn, yd);
      st = c->lines ? fx_lines_samples(c->lines, K, m, klo, khi - klo + 1, sface, sblk, c->err)
                    : fx_see_row(c->see, K, m, klo, khi - klo + 1, sface, c->err);
      if (st != T74_OK) break;
      if (!c->lines) memset(sblk, 0, (size_t)(khi - klo + 1) * sizeof *sblk);
      c->nlines++;
    }
    int jr = (int)floor(v);
    int s = 0;
    for (int k = klo; k <= khi; k++) {
      int face = -1;
      unsigned blocked = 0;
      if (spans) {
        int64_t xn = GRID_ONE * (xd * win[0] + (2 * (int64_t)k + 1) * ((int64_t)win[2] - win[0]));
        while (s < line.n && geom_rat_cmp_frac(line.s[s].x1, xn, xd) <= 0) s++;
        if (s < line.n && geom_rat_cmp_frac(line.s[s].x0, xn, xd) <= 0) {
          face = line.s[s].face;
          blocked = line.s[s].blocked;
        }
      } else {
        face = sface[k - klo];
        blocked = sblk[k - klo];
      }
      cost_mw_mul(c->cost, 75, 17);
      samples++;
      double light = aa_frag_light(c, face, blocked, (k + 0.5) / K, v, (int)floor((k + 0.5) / K), jr);
      /* to every point whose filter holds the sample */
      for (int b = 0; b < D; b++) {
        int dm = off0 + b, jj = m - dm;
        if (jj % K) continue;
        jj /= K;
        if (jj < 0 || jj >= H) continue;
        for (int a = 0; a < D; a++) {
          int ii = k - (off0 + a);
          if (ii % K) continue;
          ii /= K;
          if (ii < 0 || ii >= W || w[a * D + b] == 0) continue;
          c->out[(size_t)jj * (size_t)W + (size_t)ii] += w[a * D + b] * light;
          COST_ADD_N(c->cost, COST_MEM, 4);
          COST_ADD_N(c->cost, COST_MUL, 1);
          COST_ADD_N(c->cost, COST_ADD, 3);
        }
      }
    }
  }
  fx_count(c->st, "aa_samples", (double)samples, true);
  aa_line_free(&line);
  free(sface);
  free(sblk);
  free(w);
  return st;
}
