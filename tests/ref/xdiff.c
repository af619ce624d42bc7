/*
** xdiff.c — one differential check, renderer against the exact reference (xdiff.h).
**
** This file contains test code that drives the library the way cli/pipeline.c does
** (scene_load, render_prepare, render_scan) and judges every point with exactref.
*/
#include "tests/ref/xdiff.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/render.h"
#include "render/scene.h"

struct grab { unsigned *ids; int W; const struct render *r; };

static int on_point(void *ctx, int i, int j, int face)
{
  struct grab *g = ctx;
  g->ids[(size_t)j * (size_t)g->W + (size_t)i] = face < 0 ? 0u : g->r->map.f[face].id;
  return 0;
}

int xd_save(struct xr_scene *s, const char *path)
{
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  int st = xr_write(s, f);
  if (fclose(f) != 0) st = -1;
  return st;
}

int xd_check(struct xr_scene *s, int cell, int store, struct xd_result *res)
{
  return xd_check_ids(s, cell, store, res, NULL);
}

int xd_check_ids(struct xr_scene *s, int cell, int store, struct xd_result *res, unsigned **keep)
{
  memset(res, 0, sizeof *res);
  res->first_i = res->first_j = -1;
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  int st = xd_load(s, &sc, &err);
  if (st < 0) { snprintf(res->msg, sizeof res->msg, "%s", err.msg); return -1; }
  if (st != T74_OK) {
    res->status = st;
    snprintf(res->msg, sizeof res->msg, "%s", err.msg);
    return 0;
  }
  struct render r;
  struct render_opts ro = { 1u << 22, 0, store, NULL, 0, NULL };
  struct xr_ref ref;
  int W = 400 / cell, H = 300 / cell;
  unsigned *ids = calloc((size_t)W * (size_t)H, sizeof *ids);
  if (!ids || xr_prepare(s, cell, &ref) != 0) {
    free(ids);
    scene_free(sc);
    snprintf(res->msg, sizeof res->msg, "out of memory");
    return -1;
  }
  st = render_prepare(&r, sc, &ro, &err);
  res->faces_split = r.map.split;
  if (st == T74_OK) {
    struct grab g = { ids, W, &r };
    struct vis_grid vg = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
    st = render_scan(&r, &vg, on_point, &g, &err);
    res->pairs_computed = r.prio.computed;
    res->faces_split = r.map.split;
  }
  render_free(&r);
  scene_free(sc);
  if (st != T74_OK) {
    res->status = st;
    snprintf(res->msg, sizeof res->msg, "%s", err.msg);
  } else {
    for (int j = 0; j < H; j++)
      for (int i = 0; i < W; i++) {
        unsigned want, got = ids[(size_t)j * (size_t)W + (size_t)i];
        int v = xr_judge(&ref, i, j, got, &want);
        res->points++;
        if (v > 0) res->band++;
        if (v < 0) {
          if (res->wrong++ == 0) {
            res->first_i = i; res->first_j = j;
            res->first_got = got; res->first_want = want;
          }
        }
      }
  }
  xr_ref_free(&ref);
  if (keep) *keep = ids; else free(ids);
  return 0;
}

static int from_scenegen(const ref_scene *r, struct xr_scene *s)
{
  s->eye[0] = (int32_t)r->x0; s->eye[1] = (int32_t)r->y0; s->eye[2] = (int32_t)r->z0;
  s->win[0] = (int32_t)r->xl; s->win[1] = (int32_t)r->yb;
  s->win[2] = (int32_t)r->xr; s->win[3] = (int32_t)r->yt;
  for (int k = 0; k < r->nv; k++)
    if (xr_vertex(s, (int32_t)r->v[k].x, (int32_t)r->v[k].y, (int32_t)r->v[k].z) < 0) return -1;
  for (int k = 0; k < r->nf; k++) {
    const ref_face *f = &r->f[k];
    int fi = xr_face(s, f->id, f->ring_len[0], f->vi);
    if (fi < 0) return -1;
    s->f[fi].grey = f->grey;
    int off = f->ring_len[0];
    for (int g = 1; g < f->nring; g++) {
      if (xr_hole(s, fi, f->ring_len[g], f->vi + off) < 0) return -1;
      off += f->ring_len[g];
    }
  }
  return 0;
}

int xd_scenegen(sg_family fam, uint64_t seed, struct xr_scene *s)
{
  memset(s, 0, sizeof *s);
  ref_scene r;
  memset(&r, 0, sizeof r);
  char err[256];
  if (sg_generate(fam, seed, &r, err, sizeof err) != 0) return -1;
  int rc = from_scenegen(&r, s);
  sg_free(&r);
  return rc;
}

int xd_load(struct xr_scene *s, struct scene **out, struct t74_error *err)
{
  char path[] = "/tmp/tube74-xdiff-XXXXXX";
  int fd = mkstemp(path);
  if (fd < 0) { snprintf(err->msg, sizeof err->msg, "cannot make a temporary file"); return -1; }
  close(fd);
  if (xd_save(s, path) != 0) {
    unlink(path);
    snprintf(err->msg, sizeof err->msg, "cannot write %s", path);
    return -1;
  }
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.input = "s74";
  int st = scene_load(path, &so, out, err);
  unlink(path);
  return st;
}

int xd_seeds(void)
{
  const char *e = getenv("T74_DIFF_SEEDS");
  int n = e ? atoi(e) : 400;
  return n > 0 ? n : 400;
}
