/*
** penplan.c — band buffering, the stroke rule and the nearest-first order for pen plotters
** (see penplan.h for the method; used by hpgl.c and ebb.c).
**
** This file contains code to plan one band of tube rows at a time. Hardware source: none
** beyond the pen-plotter timing model of penplan.h (its speeds and lift times are the
** profiles' parameters, each with its source). Integer dot coordinates throughout; the only
** floating point is the yes/no of the stroke rule, computed once.
*/
#include "display/usb/penplan.h"

#include <stdlib.h>
#include <string.h>

#include "display/sink.h"

struct pen_geom pen_geom_fit(double x0, double y0, double w, double h)
{
  struct pen_geom g;
  int px = (int)(w / TUBE_W), py = (int)(h / TUBE_H);
  g.pitch = px < py ? px : py;
  if (g.pitch < 1) g.pitch = 1;
  g.ox = (int)x0 + ((int)w - TUBE_W * g.pitch) / 2;
  g.oy = (int)y0 + ((int)h - TUBE_H * g.pitch) / 2;
  if (g.ox < (int)x0) g.ox = (int)x0;
  if (g.oy < (int)y0) g.oy = (int)y0;
  return g;
}

int penplan_rule(double pitch_mm, double v_up, double v_down, double lift_ms)
{
  double lift = lift_ms / 1000.0;
  return 2 * lift + pitch_mm / v_up > pitch_mm / v_down;
}

int penplan_init(struct penplan *pp, int band_rows, int runs, struct t74_error *err)
{
  memset(pp, 0, sizeof *pp);
  pp->band_rows = band_rows < 1 ? 1 : band_rows;
  pp->band = -1;
  pp->runs = runs;
  pp->capin = TUBE_W * pp->band_rows;          /* a band holds at most this many dots */
  pp->in = malloc(sizeof *pp->in * (size_t)pp->capin);
  pp->pts = malloc(sizeof *pp->pts * (size_t)pp->capin);
  pp->st = malloc(sizeof *pp->st * (size_t)pp->capin);
  if (!pp->in || !pp->pts || !pp->st) {
    penplan_free(pp);
    return t74_fail(err, T74_EIO, "pen plan: out of memory");
  }
  return T74_OK;
}

void penplan_free(struct penplan *pp)
{
  free(pp->in);
  free(pp->pts);
  free(pp->st);
  pp->in = pp->pts = NULL;
  pp->st = NULL;
}

static int band_of(const struct penplan *pp, int y)
{
  return (TUBE_H - 1 - y) / pp->band_rows;
}

int penplan_new_band(const struct penplan *pp, const struct usb_point *p)
{
  return pp->nin > 0 && band_of(pp, p->y) != pp->band;
}

int penplan_add(struct penplan *pp, const struct usb_point *p, struct t74_error *err)
{
  if (pp->nin == 0) pp->band = band_of(pp, p->y);
  if (pp->nin >= pp->capin)     /* only if a dot came twice: the stream dedupes, so never */
    return t74_fail(err, T74_EIO, "pen plan: band overflow at dot %d %d", p->x, p->y);
  pp->in[pp->nin++] = *p;
  return T74_OK;
}

/* Sort by row (top first), then x. */
static int cmp_row_x(const void *a, const void *b)
{
  const struct usb_point *p = a, *q = b;
  if (p->y != q->y) return q->y - p->y;
  return p->x - q->x;
}

static long dist2(int ax, int ay, int bx, int by)
{
  long dx = ax - bx, dy = ay - by;
  return dx * dx + dy * dy;
}

int penplan_plan(struct penplan *pp, struct t74_error *err)
{
  (void)err;
  pp->nst = 0;
  if (pp->nin == 0) return T74_OK;
  qsort(pp->in, (size_t)pp->nin, sizeof *pp->in, cmp_row_x);
  /* runs -> candidate strokes (left to right, dots in pp->in order) */
  struct pen_stroke *cand = malloc(sizeof *cand * (size_t)pp->nin);
  char *used = calloc((size_t)pp->nin, 1);
  if (!cand || !used) {
    free(cand);
    free(used);
    return t74_fail(err, T74_EIO, "pen plan: out of memory");
  }
  int nc = 0;
  for (int k = 0; k < pp->nin;) {
    int e = k + 1;
    if (pp->runs)
      while (e < pp->nin && pp->in[e].y == pp->in[k].y && pp->in[e].x == pp->in[e - 1].x + 1) e++;
    cand[nc].y = pp->in[k].y;
    cand[nc].x0 = pp->in[k].x;
    cand[nc].x1 = pp->in[e - 1].x;
    cand[nc].first = k;
    cand[nc].n = e - k;
    nc++;
    k = e;
  }
  /* nearest end first */
  int out = 0;
  for (int done = 0; done < nc; done++) {
    int best = -1, rev = 0;
    long bd = 0;
    for (int c = 0; c < nc; c++) {
      if (used[c]) continue;
      long d0 = dist2(pp->pen_x, pp->pen_y, cand[c].x0, cand[c].y);
      long d1 = dist2(pp->pen_x, pp->pen_y, cand[c].x1, cand[c].y);
      if (best < 0 || d0 < bd) { best = c; bd = d0; rev = 0; }
      if (d1 < bd) { best = c; bd = d1; rev = 1; }
    }
    used[best] = 1;
    struct pen_stroke s = cand[best];
    struct pen_stroke *o = &pp->st[pp->nst++];
    o->y = s.y;
    o->first = out;
    o->n = s.n;
    o->x0 = rev ? s.x1 : s.x0;
    o->x1 = rev ? s.x0 : s.x1;
    for (int k = 0; k < s.n; k++)
      pp->pts[out++] = pp->in[rev ? s.first + s.n - 1 - k : s.first + k];
    pp->pen_x = o->x1;
    pp->pen_y = o->y;
  }
  free(cand);
  free(used);
  pp->nin = 0;
  pp->band = -1;
  return T74_OK;
}
