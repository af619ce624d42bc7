/*
** see.c — the engine as the effects see it (see see.h): the two engines' answers behind
** one question.
**
** The 1974 engine answers with a Visible Surface Procedure of its own for each question
** (vis_init, or vis_init_without for faces taken away), over the pieces and the Priority
** Matrix the scan left (render/visible.h); a row of samples is the stretches of the row's
** line, each sample placed in its stretch exactly (a stretch owns its left end). The
** points engine answers with points_at_row (render/points_at.h); at the centres, with no
** face taken away, that is the frame points_render made, which is read back as it is.
*/
#include "effects/see.h"

#include <stdlib.h>
#include <string.h>

#include "render/points.h"
#include "render/points_at.h"
#include "render/render.h"

struct fx_see {
  const struct fx_engine *e;
  const uint8_t *skip;
  struct vis vis;                   /* the 1974 engine */
  bool vis_open;
  struct points_at at;              /* the points engine */
  bool none;                        /* the points engine with every face taken away or left
                                       out (p->skip): no face is seen anywhere */
};

void fx_engine_1974(struct fx_engine *e, struct render *r, const struct vis_grid *g)
{
  memset(e, 0, sizeof *e);
  e->map = &r->map;
  e->core = r->core;
  e->g = g;
  e->r = r;
}

/* The effects' core under the points engine: as large as they ask (host memory only). */
#define FX_POINTS_CORE_FIRST (UINT32_C(1) << 16)
#define FX_POINTS_CORE_MAX   (UINT32_C(1) << 31)

int fx_engine_points(struct fx_engine *e, const struct points *p, const struct vis_grid *g,
                     struct core **keep, struct t74_error *err)
{
  memset(e, 0, sizeof *e);
  if (keep && *keep) {
    e->core = *keep;                        /* its first size: as core_new makes one */
    *keep = NULL;
    core_reset(e->core);
  } else {
    e->core = core_new(FX_POINTS_CORE_FIRST);
  }
  if (!e->core) return t74_fail(err, T74_EIO, "out of host memory");
  core_set_growth(e->core, FX_POINTS_CORE_MAX);
  e->own_core = true;
  e->keep = keep;
  e->map = &p->map;
  e->g = g;
  e->pts = p;
  return T74_OK;
}

void fx_engine_free(struct fx_engine *e)
{
  if (e->own_core && e->keep && core_words(e->core) == FX_POINTS_CORE_FIRST)
    *e->keep = e->core;
  else if (e->own_core)
    core_free(e->core);
  memset(e, 0, sizeof *e);
}

const char *fx_needs_1974(const struct effects *e)
{
  switch (e->aa) {
  case EFFECTS_AA_MULTISCAN:
    return "aa=multiscan integrates coverage along the visible stretches of the 1974 "
           "program's sub-scanlines, which the points engine does not make (it decides "
           "samples: aa=super runs on it)";
  case EFFECTS_AA_AREA:
    return "aa=area integrates coverage along the visible stretches of the 1974 program's "
           "sub-scanlines, which the points engine does not make (it decides samples: "
           "aa=super runs on it)";
  case EFFECTS_AA_EXACT:
    return "aa=exact integrates the 1974 program's visible stretches between the heights "
           "of its pieces, which the points engine does not make (it decides samples: "
           "aa=super runs on it)";
  default:
    break;
  }
  if (e->edges)
    return "edges= draws the intersection lines along which the 1974 program's Priority "
           "Matrix cut crossing faces (paper 002's class e4), which the points engine "
           "does not make";
  return NULL;
}

/* ---- which face is seen ------------------------------------------------------------ */

int fx_see_open(struct fx_see **out, const struct fx_engine *e, const uint8_t *skip,
                struct cost *cost, struct t74_error *err)
{
  struct fx_see *s = calloc(1, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "out of host memory");
  s->e = e;
  s->skip = skip;
  if (e->r) {
    int st = skip ? vis_init_without(&s->vis, &e->r->seg, &e->r->prio, cost, skip, err)
                  : vis_init(&s->vis, &e->r->seg, &e->r->prio, cost, err);
    s->vis_open = true;
    if (st != T74_OK) { fx_see_close(s); return st; }
  }
  if (e->pts && skip) {             /* (a cut object alone in its scene: nothing behind it) */
    const struct points *p = e->pts;
    s->none = true;
    for (int k = 0; k < p->map.nface && s->none; k++) s->none = p->skip[k] || skip[k];
  }
  *out = s;
  return T74_OK;
}

void fx_see_close(struct fx_see *s)
{
  if (!s) return;
  if (s->vis_open) vis_free(&s->vis);
  points_at_free(&s->at);
  free(s);
}

bool fx_see_has_spans(const struct fx_see *s) { return s->e->r != NULL; }

int fx_see_spans(struct fx_see *s, int64_t yn, int64_t yd, const struct vis_span **span,
                 int *nspan, struct t74_error *err)
{
  if (!s->e->r) return t74_fail(err, T74_EIO, "fx_see_spans: the points engine gives no stretches");
  return vis_spans(&s->vis, yn, yd, span, nspan, err);
}

int fx_see_row(struct fx_see *s, int K, int64_t m, int64_t k0, int n, int *face,
               struct t74_error *err)
{
  const int *drawn;
  return fx_see_row_drawn(s, K, m, k0, n, face, &drawn, err);
}

bool fx_see_row_none(const struct fx_see *s, int K, int64_t m, int64_t k0, int n)
{
  /* (fx_see_row_drawn's second answer: s->none is set only with a skip, so its first,
     the drawn row, is not taken) */
  return s->e->pts && s->none && s->skip && points_at_lattice_ok(s->e->g, K, m, k0, n);
}

const int *fx_see_drawn_row(const struct fx_see *s, int K, int64_t m, int64_t k0, int n)
{
  const struct vis_grid *g = s->e->g;
  if (!s->e->pts || K != 1 || s->skip || m < 0 || m >= g->H || k0 < 0 || k0 + n > g->W)
    return NULL;
  _Static_assert(sizeof *s->e->pts->face == sizeof(int), "the engine's faces are ints");
  return s->e->pts->face + m * g->W + k0;
}

int fx_see_row_drawn(struct fx_see *s, int K, int64_t m, int64_t k0, int n, int *face,
                     const int **drawn, struct t74_error *err)
{
  const struct vis_grid *g = s->e->g;
  const int64_t XL = g->window[0], YB = g->window[1], XR = g->window[2], YT = g->window[3];
  *drawn = NULL;
  if (s->e->pts) {
    const struct points *p = s->e->pts;
    if ((*drawn = fx_see_drawn_row(s, K, m, k0, n)) != NULL) {
      memcpy(face, *drawn, (size_t)n * sizeof *face);   /* the row as drawn */
      return T74_OK;
    }
    /* no face left: points_at_row's answer, every sample -1, on a lattice it takes (else
       it refuses, as it does) */
    if (s->none && points_at_lattice_ok(g, K, m, k0, n)) {
      for (int i = 0; i < n; i++) face[i] = -1;
      return T74_OK;
    }
    return points_at_row(&s->at, p, g, K, m, k0, n, s->skip, face, err);
  }
  const int64_t xd = 2 * (int64_t)K * g->W, yd = 2 * (int64_t)K * g->H;
  const struct vis_span *sp;
  int ns;
  int st = vis_spans(&s->vis, GRID_ONE * (yd * YT - (2 * m + 1) * (YT - YB)), yd, &sp, &ns, err);
  if (st != T74_OK) return st;
  int h = 0;
  for (int i = 0; i < n; i++) {
    int64_t xn = GRID_ONE * (xd * XL + (2 * (k0 + i) + 1) * (XR - XL));
    while (h < ns && geom_rat_cmp_frac(sp[h].x1, xn, xd) <= 0) h++;
    face[i] = h < ns && geom_rat_cmp_frac(sp[h].x0, xn, xd) <= 0 ? sp[h].face : -1;
  }
  return T74_OK;
}
