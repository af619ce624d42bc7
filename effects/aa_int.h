/*
** aa_int.h — what the anti-aliasing methods (effects/aa*.c) share: the context of one
** run, sub-scanlines from the exact visible-span procedure, fragment light, the result.
**
** This file contains the internal interface of the aa_ module (effects/aa.h is the public
** one). Coordinates: a point (i, j) is the unit square [i, i+1] x [j, j+1] in point units
** u (across, from the window's left) and v (down, from the window's top), as the contract
** places point centres at (i + 1/2, j + 1/2). A sub-scanline v = vn / vd is the plane's
** line y = YT - v (YT - YB) / H, handed to vis_spans exactly; lines must come in
** non-decreasing y, i.e. non-increasing v: every method walks the frame bottom row first.
*/
#ifndef T74_AA_INT_H
#define T74_AA_INT_H

#include <stdbool.h>
#include <stdint.h>
#include "effects/aa.h"
#include "effects/model.h"
#include "render/render.h"
#include "render/visible.h"

#define AA_PI 3.14159265358979323846

/* The intensity source: the grey of face `face` (-1: the background) for a fragment
   lying in point (i, j) (clamped to the grid). Flat shading (no smooth effect before
   aa): the face's grey, or the background picture's. When an effect before aa (smooth,
   paper 004) has put a per-point intensity into the frame, a fragment of the face seen
   at the point's centre takes that point's grey, any other face its flat grey; a later
   shading that knows more can give its own function (grey_at). */
typedef int (*aa_grey_fn)(void *ctx, int face, int i, int j);

/* One visible stretch of a sub-scanline, in point units, with its exact ends. */
struct aa_seg {
  double u0, u1;            /* [u0, u1) across, point units */
  struct grat x0, x1;       /* the same, exact, grid units (from vis_spans) */
  int piece, face;
  unsigned blocked;         /* lights in shadow there (effects/model.h) */
};

struct aa_line {
  struct aa_seg *s;
  int n, cap;
  int64_t yn, yd;           /* the line y = yn / yd, grid units */
  double v;                 /* the same, point units down */
};

struct aa_ctx {
  const struct fx_engine *eng;    /* the engine that drew the frame (effects/see.h) */
  struct render *r;               /* the 1974 engine (eng->r): the pieces the methods that
                                     work on its stretches read; NULL under points */
  const struct effects *e;
  const struct vis_grid *g;
  const struct fx_frame *f;
  struct fx_stats *st;
  struct cost *cost;
  struct t74_error *err;
  struct fx_see *see;       /* the engine's answers (no frame model) */
  const struct fx_model *model;   /* the frame model (f->model), or NULL */
  struct fx_lines *lines;   /* its lines (with a model) */
  int W, H, cell;
  double xl, yt;            /* XL and YT in grid units */
  double pw, ph;            /* grid units per point across and down */
  uint32_t light_at;        /* core address of the 256-word light table */
  double *out;              /* W * H: the light (0..1) each point shows, the result */
  aa_grey_fn grey_at;       /* NULL: the frame's own intensities (see aa_grey_fn) */
  bool flat;                /* no effect before aa changed the greys: one per face */
  void *grey_ctx;
  double ltab[256];         /* the light table as read from core, 0..1 */
  uint64_t nlines;          /* sub-scanlines asked for */
};

/* The visible stretches of the line v = vn / vd (vd * H <= GRID_YDEN_MAX). */
int aa_line_v(struct aa_ctx *c, int64_t vn, int64_t vd, struct aa_line *l);

/* The same for the line y = yn / yd in grid units. */
int aa_line_y(struct aa_ctx *c, int64_t yn, int64_t yd, struct aa_line *l);

/* The line v = vn / vd as y = yn / yd in grid units, and back to v (point units down). */
void aa_y_of_v(const struct aa_ctx *c, int64_t vn, int64_t vd, int64_t *yn, int64_t *yd);
double aa_v_at(const struct aa_ctx *c, int64_t yn, int64_t yd);

void aa_line_free(struct aa_line *l);

/* Light 0..1 of a fragment of face (-1: background) lying in point (i, j), at position
   (u, v) of the plane (point units) with the lights in blocked in shadow, through the
   light table in core (counted: the grey, then its light from the table). With a frame
   model the grey is the model's shading at (u, v) (000 §3.3 (1): a fragment's intensity
   at the midpoint of its stretch within the point); without one, the frame's own. */
double aa_frag_light(struct aa_ctx *c, int face, unsigned blocked, double u, double v, int i, int j);

/* The midpoint of [u0, u1] within point column i ([i, i + 1]); i + 1/2 when they miss. */
static inline double aa_mid(double u0, double u1, int i)
{
  double a = u0 > i ? u0 : i, b = u1 < i + 1 ? u1 : i + 1;
  return b > a ? (a + b) / 2 : i + 0.5;
}

/* Mean over t in [0, 1] of clamp(p + t (q - p), a, b): the length a straight boundary
   moving linearly from p to q leaves of [a, b], averaged (exact, for linear motion). */
double aa_mean_clamp(double p, double q, double a, double b);

/* The methods. Each fills c->out. */
int aa_exact(struct aa_ctx *c);
int aa_multiscan_box(struct aa_ctx *c);
int aa_multiscan_gauss(struct aa_ctx *c);
int aa_area(struct aa_ctx *c);
int aa_super(struct aa_ctx *c);

/* Allocate `words` of core for `table` (T74_ECORE when they do not fit). */
int aa_core(struct aa_ctx *c, const char *table, uint32_t words, uint32_t *addr);

/* Host memory for n elements of size sz, zeroed; NULL with T74_EIO in c->err. */
void *aa_calloc(struct aa_ctx *c, size_t n, size_t sz);

#endif
