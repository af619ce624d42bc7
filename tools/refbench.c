/*
** refbench.c — the peer of `make bench`: the OSMesa z-buffer (tests/ref) drawing the same
** scene file, timed the way tube74 times itself (reading the scene included).
**
** This file contains code to read a .s74 scene with tube74's own reader, hand it to the
** independent reference renderer of the tests (OSMesa, GLU tessellation for concave
** faces and holes) at the scene's cell size, and print the host seconds the read and the
** render took. The context is created before the clock starts: like tube74's, the time
** is that of one frame, not of starting a GL driver.
**
** `refbench --warm K [--shade] [--size grid|tube] SCENE` is the fair peer of `tube74 bench speed`
** (issue 12): the scene is read and tessellated by GLU (odd winding, Newell normal, as
** tests/ref/osmesa_ref.c does) into one vertex array of triangles with a colour per
** vertex (the face number), the context is made and one warm-up frame drawn, all before
** the clock; then K frames are timed, each: clear, glDrawArrays, glFinish, and the face
** numbers read back into a 16-bit grid. The viewport is the scene's point grid (`grid`,
** 100 x 75 or 133 x 100) or the whole tube (`tube`, 400 x 300). It prints
**     frame_median_seconds setup_seconds triangles
** (setup: read + tessellation + context + warm-up frame). The driver is Mesa's choice of
** GALLIUM_DRIVER (llvmpipe or softpipe; LP_NUM_THREADS sets llvmpipe's threads).
** `--turn AZ,EL` first (either form) turns an .obj/.off import as tube74's --turn does
** (bench speed's box scenes beyond what .s74 holds are .obj read with --turn 0,0); the
** warm frames read face numbers back in 24 bits (the colour holds 24).
** `--warm K --shade` (issue 19) is the peer of the scenes whose `effects` ask smooth=:
** each fragment computes a Phong grey (vertex normals interpolated, normalised, lit by the
** scene's lights with tube74's law) and the frame reads the greys back with the ids. The
** warm peer itself is tests/ref/warmpeer.c (its header says what the shaded mode
** computes and where it differs from tube74's smoothing); setup now also includes the
** scene's copy into the reference's form and, shaded, the shader's compilation.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/effects.h"
#include "render/scene.h"
#include "render/turn.h"
#include "tests/ref/osmesa_ref.h"
#include "tests/ref/warmpeer.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int cmp_d(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* ---- the warm peer ------------------------------------------------------------------ */

/* The scene as the reference holds it: the same vertex order, ring lengths, ids. */
static int to_ref(const struct scene *s, ref_scene *rs)
{
  memset(rs, 0, sizeof *rs);
  rs->x0 = s->view[0]; rs->y0 = s->view[1]; rs->z0 = s->view[2];
  rs->xl = s->window[0]; rs->yb = s->window[1]; rs->xr = s->window[2]; rs->yt = s->window[3];
  rs->nv = s->nv;
  rs->v = calloc((size_t)(s->nv ? s->nv : 1), sizeof *rs->v);
  rs->nf = s->nf;
  rs->f = calloc((size_t)(s->nf ? s->nf : 1), sizeof *rs->f);
  if (!rs->v || !rs->f) return -1;
  for (int k = 0; k < s->nv; k++) {
    rs->v[k].id = s->v[k].id;
    rs->v[k].x = s->v[k].x; rs->v[k].y = s->v[k].y; rs->v[k].z = s->v[k].z;
  }
  for (int k = 0; k < s->nf; k++) {
    const struct scene_face *f = &s->f[k];
    rs->f[k].id = f->id;
    rs->f[k].grey = f->grey;
    rs->f[k].nring = f->nring;
    rs->f[k].ring_len = malloc((size_t)f->nring * sizeof(int));
    if (!rs->f[k].ring_len) return -1;
    for (int r = 0; r < f->nring; r++) rs->f[k].ring_len[r] = f->ring_start[r + 1] - f->ring_start[r];
    rs->f[k].vi = f->vidx;                /* indices into the same vertex order */
  }
  return 0;
}

static void ref_free(ref_scene *rs)
{
  for (int k = 0; rs->f && k < rs->nf; k++) free(rs->f[k].ring_len);
  free(rs->f);
  free(rs->v);
}

static int warm(const char *path, const struct scene_opts *so, int frames, int tube_size, int shade)
{
  double t0 = now();
  struct t74_error err = { T74_OK, "" };
  struct scene *s = NULL;
  if (scene_load(path, so, &s, &err) != T74_OK) { fprintf(stderr, "%s\n", err.msg); return err.status; }
  struct effects eff;
  effects_default(&eff);
  if (s->effects) effects_parse(s->effects, &eff, s->file, s->effects_line, &err);
  int w = tube_size ? 400 : 400 / eff.halftone, h = tube_size ? 300 : 300 / eff.halftone;

  /* the scene into the peer: tessellated, context made, shader compiled, before the clock */
  ref_scene rs;
  int *object = malloc((size_t)(s->nf ? s->nf : 1) * sizeof *object);
  ref_light light[SCENE_LIGHT_MAX];
  int rc = to_ref(s, &rs);
  for (int k = 0; object && k < s->nf; k++) object[k] = s->f[k].object;
  for (int k = 0; k < s->nlight; k++) {
    light[k].point = s->light[k].point;
    for (int c = 0; c < 3; c++) light[k].v[c] = s->light[k].v[c];
  }
  char msg[600] = "out of memory";
  ref_peer_input in = { &rs, object, s->nlight, light, shade, w, h };
  ref_peer *p = rc == 0 && object ? ref_peer_new(&in, msg, sizeof msg) : NULL;
  ref_free(&rs);
  free(object);
  scene_free(s);
  uint32_t *ids = malloc((size_t)w * (size_t)h * sizeof *ids);
  uint8_t *grey = malloc((size_t)w * (size_t)h);
  double *ft = malloc((size_t)frames * sizeof *ft);
  if (!p || !ids || !grey || !ft) {
    fprintf(stderr, "refbench: %s\n", msg);
    ref_peer_free(p);
    free(ids); free(grey); free(ft);
    return 4;
  }
  unsigned long check = 0;
  double setup = 0;
  int st = 0;
  for (int k = -1; k < frames && st == 0; k++) {          /* frame -1: the warm-up */
    double f0 = now();
    st = ref_peer_frame(p, ids, grey);
    if (k < 0) {
      setup = now() - t0;
      for (size_t q = 0; q < (size_t)w * (size_t)h; q++) check += ids[q] != 0;
    }
    else ft[k] = now() - f0;
  }
  if (st == 0) {
    qsort(ft, (size_t)frames, sizeof *ft, cmp_d);
    printf("%.9f %.6f %zu\n", ft[frames / 2], setup, ref_peer_triangles(p));
    fprintf(stderr, "refbench: %lu of %d points covered%s\n", check, w * h, shade ? " (shaded)" : "");
  } else {
    fprintf(stderr, "refbench: GL error in a frame\n");
  }
  free(ft);
  free(ids);
  free(grey);
  ref_peer_free(p);
  return st == 0 ? 0 : 4;
}

int main(int argc, char **argv)
{
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  if (argc >= 3 && !strcmp(argv[1], "--turn")) {
    if (turn_parse(argv[2], &so.turn[0], &so.turn[1]) != 0) {
      fprintf(stderr, "refbench: --turn takes AZ,EL\n");
      return 2;
    }
    so.has_turn = true;
    argv[2] = argv[0];
    argv += 2;
    argc -= 2;
  }
  if (argc >= 4 && !strcmp(argv[1], "--warm")) {
    int frames = atoi(argv[2]), tube_size = 0, shade = 0, a = 3;
    if (a < argc - 1 && !strcmp(argv[a], "--shade")) { shade = 1; a++; }
    if (a + 1 < argc - 1 && !strcmp(argv[a], "--size")) { tube_size = !strcmp(argv[a + 1], "tube"); a += 2; }
    if (frames < 1 || a != argc - 1) { fprintf(stderr, "usage: refbench [--turn AZ,EL] --warm K [--shade] [--size grid|tube] SCENE\n"); return 2; }
    return warm(argv[a], &so, frames, tube_size, shade);
  }
  if (argc != 2) { fprintf(stderr, "usage: refbench [--turn AZ,EL] SCENE | --warm K [--shade] [--size grid|tube] SCENE\n"); return 2; }
  char msg[256];
  ref_renderer *rr = ref_open(msg, sizeof msg);
  if (!rr) { fprintf(stderr, "refbench: %s\n", msg); return 4; }

  double t0 = now();
  struct t74_error err = { T74_OK, "" };
  struct scene *s = NULL;
  if (scene_load(argv[1], &so, &s, &err) != T74_OK) {
    fprintf(stderr, "%s\n", err.msg);
    ref_close(rr);
    return err.status;
  }
  struct effects eff;
  effects_default(&eff);
  if (s->effects) effects_parse(s->effects, &eff, s->file, s->effects_line, &err);
  int cell = eff.halftone;

  ref_scene rs;
  if (to_ref(s, &rs) != 0) {
    fprintf(stderr, "refbench: out of memory\n");
    ref_free(&rs);
    scene_free(s);
    ref_close(rr);
    return 4;
  }
  int w = ref_grid_w(cell), h = ref_grid_h(cell);
  uint16_t *ids = malloc((size_t)w * (size_t)h * sizeof *ids);
  int st = ref_render_ids(rr, &rs, cell, ids, msg, sizeof msg);
  double t = now() - t0;
  if (st != 0) fprintf(stderr, "refbench: %s\n", msg);
  else printf("%.6f\n", t);

  ref_free(&rs);
  free(ids);
  scene_free(s);
  ref_close(rr);
  return st ? 4 : 0;
}
