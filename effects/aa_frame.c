/*
** aa_frame.c — one anti-aliased frame from a scene file, without halftone or sinks: the
** harness the tests of effects/aa and `tube74 bench accuracy` share.
**
** This file contains code to run the renderer's stages (render/render.h) and the point
** scan on a scene, build the effects frame as cli/pipeline.c does (face at each point
** centre, flat grey, background grey) and, when the effects or the scene ask for it
** (smoothing, a contour cut, shadows, textures), the frame model over it as fx_run does
** (effects/model.h), and hand it to aa_light_map, timing the whole on
** the host (CLOCK_MONOTONIC) from the Mapper to the last intensity. The grid is the
** contract's: W = floor(400 / cell), H = floor(300 / cell).
*/
#include "effects/aa.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "effects/model.h"
#include "patterns/picture.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

struct scan_ctx { struct render *r; struct aa_frame *f; const uint8_t *bg; };

static int on_point(void *ctx, int i, int j, int face)
{
  struct scan_ctx *c = ctx;
  size_t at = (size_t)j * (size_t)c->f->W + (size_t)i;
  c->f->face[at] = face;
  c->f->grey[at] = (uint8_t)(face >= 0 ? c->r->map.f[face].grey : c->bg ? c->bg[at] : 0);
  return T74_OK;
}

void aa_frame_free(struct aa_frame *f)
{
  free(f->light);
  free(f->grey);
  free(f->face);
  memset(f, 0, sizeof *f);
}

int aa_frame_render(const char *path, const char *effects, int cell, uint32_t core_words,
                    struct aa_frame *f, struct t74_error *err)
{
  memset(f, 0, sizeof *f);
  struct scene *s = NULL;
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  int st = scene_load(path, &so, &s, err);
  if (st != T74_OK) return st;
  struct effects e;
  if (effects) st = effects_parse(effects, &e, "--effects", 1, err);
  else st = effects_parse(s->effects, &e, s->file, s->effects_line, err);
  if (st != T74_OK) { scene_free(s); return st; }
  f->cell = cell ? cell : e.halftone;
  f->W = 400 / f->cell;
  f->H = 300 / f->cell;
  size_t n = (size_t)f->W * (size_t)f->H;
  uint8_t *bg = NULL;
  struct pic *pic = NULL;
  if (s->background) {
    /* the background picture's grey per point: the picture sampled at point centres */
    if ((st = pic_load(s->background, &pic, err)) != T74_OK) { scene_free(s); return st; }
    bg = malloc(n);
    if (!bg) { pic_free(pic); scene_free(s); return t74_fail(err, T74_EIO, "out of host memory"); }
    for (int j = 0; j < f->H; j++)
      for (int i = 0; i < f->W; i++)
        bg[(size_t)j * (size_t)f->W + (size_t)i] = (uint8_t)pic_sample(pic, i, j, f->W, f->H);
    pic_free(pic);
  }
  f->light = calloc(n, sizeof *f->light);
  f->grey = calloc(n, 1);
  f->face = calloc(n, sizeof *f->face);
  if (!f->light || !f->grey || !f->face) {
    free(bg); scene_free(s); aa_frame_free(f);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  double t0 = now();
  struct render r;
  struct render_opts ro = { core_words, 0, PRIO_AUTO, NULL, 0, NULL };
  st = render_prepare(&r, s, &ro, err);
  struct vis_grid g = { f->W, f->H, { s->window[0], s->window[1], s->window[2], s->window[3] } };
  struct scan_ctx sc = { &r, f, bg };
  if (st == T74_OK) st = render_scan(&r, &g, on_point, &sc, err);
  /* the frame model, as fx_run builds it, when the effects or the scene ask for what it
     holds (smoothing, a contour cut, shadows, textures): the point frame from it, and
     the anti-aliasing over it */
  struct fx_model m;
  bool built = st == T74_OK;
  struct fx_frame fr = { f->W, f->H, f->cell, f->face, f->grey, bg, NULL, NULL };
  struct fx_engine eng;
  fx_engine_1974(&eng, &r, &g);
  if (built && (st = fx_model_build(&m, &eng, s, &e, bg, &f->st, &f->fx, err)) == T74_OK &&
      (fx_model_shades(&m) || fx_model_regions(&m))) {
    st = fx_points(&m, &fr, &f->st, &f->fx, err);
    fr.model = &m;
  }
  if (st == T74_OK && e.aa != EFFECTS_AA_NONE) {
    st = aa_light_map(&eng, &e, &fr, &f->st, &f->fx, f->light, err);
    for (size_t k = 0; st == T74_OK && k < n; k++) f->grey[k] = (uint8_t)aa_grey(f->cell, f->light[k]);
  } else if (st == T74_OK) {
    for (size_t k = 0; k < n; k++) f->light[k] = aa_light(f->cell, f->grey[k]) / (double)AA_LIGHT_ONE;
  }
  if (built) fx_model_free(&m);
  f->host_seconds = now() - t0;
  if (st == T74_OK) {
    for (int k = 0; k < RS_NSTAGE; k++) cost_merge(&f->render, &r.cost[k]);
    f->core_peak = core_peak(r.core);
  }
  render_free(&r);
  free(bg);
  scene_free(s);
  if (st != T74_OK) {
    struct t74_error keep = *err;
    aa_frame_free(f);
    *err = keep;
  }
  return st;
}
