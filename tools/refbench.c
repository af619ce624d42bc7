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
** `refbench --warm K [--size grid|tube] SCENE` is the fair peer of `tube74 bench speed`
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
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glu.h>

#include "render/effects.h"
#include "render/scene.h"
#include "render/turn.h"
#include "tests/ref/osmesa_ref.h"

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- the warm peer ------------------------------------------------------------------ */

struct tri_array {
  GLfloat *xyz;                 /* 3 per vertex, eye space */
  GLubyte *rgb;                 /* 3 per vertex: the face number */
  size_t n, cap;                /* vertices */
  GLubyte col[3];               /* the face being tessellated */
  GLdouble *extra[64];          /* combine vertices (blocks of 256, kept to the end) */
  int nextra, used;
  int failed;
};

static void GLAPIENTRY ta_vertex(void *v, void *data)
{
  struct tri_array *a = data;
  const GLdouble *p = v;
  if (a->n == a->cap) {
    size_t cap = a->cap ? 2 * a->cap : 3 * 4096;
    GLfloat *x = realloc(a->xyz, cap * 3 * sizeof *x);
    if (x) a->xyz = x;
    GLubyte *c = realloc(a->rgb, cap * 3);
    if (c) a->rgb = c;
    if (!x || !c) { a->failed = 1; return; }
    a->cap = cap;
  }
  for (int k = 0; k < 3; k++) {
    a->xyz[3 * a->n + (size_t)k] = (GLfloat)p[k];
    a->rgb[3 * a->n + (size_t)k] = a->col[k];
  }
  a->n++;
}

static void GLAPIENTRY ta_begin(GLenum mode, void *data) { (void)mode; (void)data; }
static void GLAPIENTRY ta_end(void *data) { (void)data; }
/* an edge-flag callback makes GLU give plain GL_TRIANGLES */
static void GLAPIENTRY ta_edge(GLboolean flag, void *data) { (void)flag; (void)data; }

static void GLAPIENTRY ta_combine(GLdouble c[3], void *vd[4], GLfloat w[4], void **out, void *data)
{
  struct tri_array *a = data;
  (void)vd;
  (void)w;
  if (a->nextra == 0 || a->used == 256) {
    if (a->nextra == 64 || !(a->extra[a->nextra] = malloc(256 * 3 * sizeof(GLdouble)))) {
      a->failed = 1;
      *out = NULL;
      return;
    }
    a->nextra++;
    a->used = 0;
  }
  GLdouble *p = a->extra[a->nextra - 1] + 3 * a->used++;
  p[0] = c[0]; p[1] = c[1]; p[2] = c[2];
  *out = p;
}

static void GLAPIENTRY ta_error(GLenum e, void *data) { (void)e; ((struct tri_array *)data)->failed = 1; }

static int cmp_d(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static int warm(const char *path, const struct scene_opts *so, int frames, int tube_size)
{
  double t0 = now();
  struct t74_error err = { T74_OK, "" };
  struct scene *s = NULL;
  if (scene_load(path, so, &s, &err) != T74_OK) { fprintf(stderr, "%s\n", err.msg); return err.status; }
  struct effects eff;
  effects_default(&eff);
  if (s->effects) effects_parse(s->effects, &eff, s->file, s->effects_line, &err);
  int w = tube_size ? 400 : 400 / eff.halftone, h = tube_size ? 300 : 300 / eff.halftone;
  const double x0 = s->view[0], y0 = s->view[1], z0 = s->view[2];
  double dmin = 1, dmax = 1;
  for (int k = 0; k < s->nv; k++) {
    double d = (double)s->v[k].z - z0;
    if (k == 0 || d < dmin) dmin = d;
    if (k == 0 || d > dmax) dmax = d;
  }
  if (z0 >= 0 || dmin <= 0) { fprintf(stderr, "refbench: the eye must be in front of every vertex\n"); scene_free(s); return 2; }

  /* GLU tessellation into one triangle array, before the clock */
  struct tri_array ta;
  memset(&ta, 0, sizeof ta);
  GLUtesselator *tess = gluNewTess();
  gluTessCallback(tess, GLU_TESS_BEGIN_DATA, (_GLUfuncptr)ta_begin);
  gluTessCallback(tess, GLU_TESS_VERTEX_DATA, (_GLUfuncptr)ta_vertex);
  gluTessCallback(tess, GLU_TESS_END_DATA, (_GLUfuncptr)ta_end);
  gluTessCallback(tess, GLU_TESS_EDGE_FLAG_DATA, (_GLUfuncptr)ta_edge);
  gluTessCallback(tess, GLU_TESS_COMBINE_DATA, (_GLUfuncptr)ta_combine);
  gluTessCallback(tess, GLU_TESS_ERROR_DATA, (_GLUfuncptr)ta_error);
  gluTessProperty(tess, GLU_TESS_WINDING_RULE, GLU_TESS_WINDING_ODD);
  size_t cap = 0;
  GLdouble *xyz = NULL;
  for (int k = 0; k < s->nf && !ta.failed; k++) {
    const struct scene_face *f = &s->f[k];
    size_t total = (size_t)f->ring_start[f->nring];
    if (total > cap) { free(xyz); cap = total; xyz = malloc(cap * 3 * sizeof *xyz); if (!xyz) { ta.failed = 1; break; } }
    for (size_t q = 0; q < total; q++) {
      const struct scene_vertex *v = &s->v[f->vidx[q]];
      xyz[3 * q] = v->x - x0; xyz[3 * q + 1] = v->y - y0; xyz[3 * q + 2] = -(v->z - z0);
    }
    int n0 = f->ring_start[1] - f->ring_start[0];
    double nn[3] = { 0, 0, 0 };
    for (int q = 0; q < n0; q++) {
      const GLdouble *a = &xyz[3 * q], *b = &xyz[3 * ((q + 1) % n0)];
      nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
      nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
      nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    if (nn[0] == 0 && nn[1] == 0 && nn[2] == 0) continue;
    ta.col[0] = (GLubyte)(f->id & 0xff); ta.col[1] = (GLubyte)(f->id >> 8 & 0xff); ta.col[2] = (GLubyte)(f->id >> 16 & 0xff);
    gluTessNormal(tess, nn[0], nn[1], nn[2]);
    gluTessBeginPolygon(tess, &ta);
    for (int r = 0; r < f->nring; r++) {
      gluTessBeginContour(tess);
      for (int q = f->ring_start[r]; q < f->ring_start[r + 1]; q++) gluTessVertex(tess, &xyz[3 * q], &xyz[3 * q]);
      gluTessEndContour(tess);
    }
    gluTessEndPolygon(tess);
  }
  gluDeleteTess(tess);
  free(xyz);
  for (int k = 0; k < ta.nextra; k++) free(ta.extra[k]);
  const double plane = -z0, nearz = 0.9 * dmin, farz = 1.1 * dmax;
  const double l = (s->window[0] - x0) * nearz / plane, r = (s->window[2] - x0) * nearz / plane;
  const double b = (s->window[1] - y0) * nearz / plane, t = (s->window[3] - y0) * nearz / plane;
  scene_free(s);
  if (ta.failed) { fprintf(stderr, "refbench: tessellation failed\n"); free(ta.xyz); free(ta.rgb); return 4; }

  OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
  GLubyte *buf = malloc((size_t)w * (size_t)h * 4);
  uint32_t *ids = malloc((size_t)w * (size_t)h * sizeof *ids);
  double *ft = malloc((size_t)frames * sizeof *ft);
  if (!ctx || !buf || !ids || !ft || !OSMesaMakeCurrent(ctx, buf, GL_UNSIGNED_BYTE, w, h)) {
    fprintf(stderr, "refbench: no OSMesa context\n");
    return 4;
  }
  glViewport(0, 0, w, h);
  glDisable(GL_DITHER);
  glShadeModel(GL_FLAT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(0, 0, 0, 0);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum(l, r, b, t, nearz, farz);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, ta.xyz);
  glColorPointer(3, GL_UNSIGNED_BYTE, 0, ta.rgb);
  unsigned long check = 0;
  double setup = 0;
  for (int k = -1; k < frames; k++) {          /* frame -1: the warm-up */
    double f0 = now();
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)ta.n);
    glFinish();
    for (int j = 0; j < h; j++) {
      const GLubyte *row = buf + (size_t)(h - 1 - j) * (size_t)w * 4;
      for (int i = 0; i < w; i++) ids[(size_t)j * (size_t)w + (size_t)i] = (uint32_t)row[4 * i] | (uint32_t)row[4 * i + 1] << 8 | (uint32_t)row[4 * i + 2] << 16;
    }
    if (k < 0) {
      setup = now() - t0;
      for (size_t q = 0; q < (size_t)w * (size_t)h; q++) check += ids[q] != 0;
    }
    else ft[k] = now() - f0;
  }
  qsort(ft, (size_t)frames, sizeof *ft, cmp_d);
  printf("%.9f %.6f %zu\n", ft[frames / 2], setup, ta.n / 3);
  fprintf(stderr, "refbench: %lu of %d points covered\n", check, w * h);
  free(ft);
  free(ids);
  free(buf);
  free(ta.xyz);
  free(ta.rgb);
  OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
  OSMesaDestroyContext(ctx);
  return glGetError() == GL_NO_ERROR ? 0 : 4;
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
    int frames = atoi(argv[2]), tube_size = 0, a = 3;
    if (argc == 6 && !strcmp(argv[3], "--size")) { tube_size = !strcmp(argv[4], "tube"); a = 5; }
    if (frames < 1 || a != argc - 1) { fprintf(stderr, "usage: refbench [--turn AZ,EL] --warm K [--size grid|tube] SCENE\n"); return 2; }
    return warm(argv[a], &so, frames, tube_size);
  }
  if (argc != 2) { fprintf(stderr, "usage: refbench [--turn AZ,EL] SCENE | --warm K [--size grid|tube] SCENE\n"); return 2; }
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
