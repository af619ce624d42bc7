/*
** refbench.c — the peer of `make bench`: the OSMesa z-buffer (tests/ref) drawing the same
** scene file, timed the way tube74 times itself (reading the scene included).
**
** This file contains code to read a .s74 scene with tube74's own reader, hand it to the
** independent reference renderer of the tests (OSMesa, GLU tessellation for concave
** faces and holes) at the scene's cell size, and print the host seconds the read and the
** render took. The context is created before the clock starts: like tube74's, the time
** is that of one frame, not of starting a GL driver.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/effects.h"
#include "render/scene.h"
#include "tests/ref/osmesa_ref.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
  if (argc != 2) { fprintf(stderr, "usage: refbench SCENE.s74\n"); return 2; }
  char msg[256];
  ref_renderer *rr = ref_open(msg, sizeof msg);
  if (!rr) { fprintf(stderr, "refbench: %s\n", msg); return 4; }

  double t0 = now();
  struct t74_error err = { T74_OK, "" };
  struct scene *s = NULL;
  if (scene_load(argv[1], NULL, &s, &err) != T74_OK) {
    fprintf(stderr, "%s\n", err.msg);
    ref_close(rr);
    return err.status;
  }
  struct effects eff;
  effects_default(&eff);
  if (s->effects) effects_parse(s->effects, &eff, s->file, s->effects_line, &err);
  int cell = eff.halftone;

  ref_scene rs;
  memset(&rs, 0, sizeof rs);
  rs.x0 = s->view[0]; rs.y0 = s->view[1]; rs.z0 = s->view[2];
  rs.xl = s->window[0]; rs.yb = s->window[1]; rs.xr = s->window[2]; rs.yt = s->window[3];
  rs.nv = s->nv;
  rs.v = calloc((size_t)(s->nv ? s->nv : 1), sizeof *rs.v);
  rs.nf = s->nf;
  rs.f = calloc((size_t)(s->nf ? s->nf : 1), sizeof *rs.f);
  for (int k = 0; k < s->nv; k++) {
    rs.v[k].id = s->v[k].id;
    rs.v[k].x = s->v[k].x; rs.v[k].y = s->v[k].y; rs.v[k].z = s->v[k].z;
  }
  for (int k = 0; k < s->nf; k++) {
    const struct scene_face *f = &s->f[k];
    rs.f[k].id = f->id;
    rs.f[k].grey = f->grey;
    rs.f[k].nring = f->nring;
    rs.f[k].ring_len = malloc((size_t)f->nring * sizeof(int));
    for (int r = 0; r < f->nring; r++) rs.f[k].ring_len[r] = f->ring_start[r + 1] - f->ring_start[r];
    rs.f[k].vi = f->vidx;                 /* indices into the same vertex order */
  }
  int w = ref_grid_w(cell), h = ref_grid_h(cell);
  uint16_t *ids = malloc((size_t)w * (size_t)h * sizeof *ids);
  int st = ref_render_ids(rr, &rs, cell, ids, msg, sizeof msg);
  double t = now() - t0;
  if (st != 0) fprintf(stderr, "refbench: %s\n", msg);
  else printf("%.6f\n", t);

  for (int k = 0; k < s->nf; k++) free(rs.f[k].ring_len);
  free(rs.f);
  free(rs.v);
  free(ids);
  scene_free(s);
  ref_close(rr);
  return st ? 4 : 0;
}
