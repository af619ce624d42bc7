/*
** osmesa_ref.c — the reference renderer of the cross-checks: OSMesa + GLU, nothing of tube74.
**
** This file contains every GL call of the tests. It renders a ref_scene the ordinary
** z-buffer way and reads back, at every perspective-plane point centre, which face is in
** front. Nothing here shares code or ideas with render/: no priority matrix, no segments,
** no integer plane grid; so agreement between the two is evidence, not an echo.
**
** Method.
**   - The viewport is exactly the point grid (W x H pixels for cell 3 or 4), so GL's pixel
**     centres ARE the contract's point centres: pixel (i, H-1-j) samples
**     x = XL + (i + 0.5)(XR - XL)/W, y = YT - (j + 0.5)(YT - YB)/H on the plane z = 0.
**   - Eye space: every vertex is translated by -eye on the CPU in double precision and z is
**     flipped (GL looks down -z; the 1974 eye looks down +z). The plane z = 0 is then at
**     eye-space depth -Z0 > 0, and glFrustum(l, r, b, t, n, f) with
**     l = (XL - X0) n / (-Z0) (and r, b, t likewise) maps the window to the viewport.
**   - Depth: GL_LESS on a 24-bit buffer; n = 0.9 min(z - Z0) and f = 1.1 max(z - Z0) over
**     all vertices, as tight as the scene allows, to keep depth resolution where it is used.
**   - Colour: face number N is drawn as RGB (N & 0xff, N >> 8, 0) with flat shading, no
**     lighting, no dithering, no blending, no multisampling; the clear colour 0 is "none".
**   - Faces go through GLU's tessellator with GLU_TESS_WINDING_ODD and the face's Newell
**     normal, so concave boundaries and holes (in either orientation) come out right.
**
** What is not exact: GL's own rasterisation rule at edges (top-left rule, float snapping)
** and depth quantisation where two faces are within a few depth steps of each other (along
** interpenetration lines). Both only matter next to a change of visible face, which is why
** the cross-checks compare only points whose 3 x 3 neighbourhood is uniform here, and not
** points whose centre is within REF_EDGE_MARGIN_PX of a projected edge (ref_edge_points:
** sub-point slivers, where no neighbour reveals the boundary).
*/
#include "tests/ref/osmesa_ref.h"

#include <math.h>
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glu.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Vertices the tessellator invents (combine callback) live in blocks that never move,
   because GLU keeps the pointers we hand back. */
#define REF_BLOCK_VERTS 256

typedef struct ref_block {
  struct ref_block *next;
  int used;
  GLdouble xyz[REF_BLOCK_VERTS][3];
} ref_block;

/* Per-polygon data given to the GLU callbacks (GLU_TESS_*_DATA): no globals. */
typedef struct ref_tess_ctx {
  ref_block *blocks;      /* combine vertices of the face being tessellated */
  int failed;             /* sticky: out of memory in combine */
  GLenum glu_error;       /* first GLU error reported, 0 if none */
} ref_tess_ctx;

struct ref_renderer {
  OSMesaContext ctx;
  GLubyte *buf;           /* RGBA colour buffer, bottom row first (OSMesa's Y_UP default) */
  size_t buf_cap;         /* in pixels */
  GLUtesselator *tess;
  GLdouble *xyz;          /* eye-space copy of one face's vertices (stable during a polygon) */
  size_t xyz_cap;         /* in vertices */
};

/* Under `make asan`, LeakSanitizer would fail every program that links this file: Mesa 22's
   OSMesa keeps the framebuffers OSMesaMakeCurrent creates in a private list it never frees.
   The sanitizer runtime asks this hook for default suppressions; naming only libOSMesa keeps
   leaks of our own code (and of tube74's library) reported. Unused without sanitizers. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libOSMesa.so\n"; }

int ref_grid_w(int cell) { return 400 / cell; }
int ref_grid_h(int cell) { return 300 / cell; }

static void set_err(char *err, size_t errlen, const char *msg)
{
  if (err && errlen) snprintf(err, errlen, "%s", msg);
}

/* --- GLU callbacks ------------------------------------------------------------------ */

static void GLAPIENTRY tess_combine(GLdouble coords[3], void *vertex_data[4],
                                    GLfloat weight[4], void **out, void *polygon_data)
{
  ref_tess_ctx *tc = polygon_data;
  (void)vertex_data;
  (void)weight;
  if (!tc->blocks || tc->blocks->used == REF_BLOCK_VERTS) {
    ref_block *b = malloc(sizeof *b);
    if (!b) {
      tc->failed = 1;
      *out = NULL;
      return;
    }
    b->next = tc->blocks;
    b->used = 0;
    tc->blocks = b;
  }
  GLdouble *p = tc->blocks->xyz[tc->blocks->used++];
  p[0] = coords[0];
  p[1] = coords[1];
  p[2] = coords[2];
  *out = p;
}

static void GLAPIENTRY tess_error(GLenum code, void *polygon_data)
{
  ref_tess_ctx *tc = polygon_data;
  if (!tc->glu_error) tc->glu_error = code;
}

static void free_blocks(ref_tess_ctx *tc)
{
  while (tc->blocks) {
    ref_block *n = tc->blocks->next;
    free(tc->blocks);
    tc->blocks = n;
  }
}

/* --- context ------------------------------------------------------------------------ */

ref_renderer *ref_open(char *err, size_t errlen)
{
  /* An unknown GALLIUM_DRIVER crashes inside OSMesaCreateContextExt: pin a known one. */
  const char *drv = getenv("GALLIUM_DRIVER");
  if (!drv || (strcmp(drv, "llvmpipe") != 0 && strcmp(drv, "softpipe") != 0))
    setenv("GALLIUM_DRIVER", "llvmpipe", 1);

  ref_renderer *r = calloc(1, sizeof *r);
  if (!r) {
    set_err(err, errlen, "out of memory");
    return NULL;
  }
  r->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
  if (!r->ctx) {
    set_err(err, errlen, "OSMesaCreateContextExt(OSMESA_RGBA, 24-bit depth) failed");
    free(r);
    return NULL;
  }
  r->tess = gluNewTess();
  if (!r->tess) {
    set_err(err, errlen, "gluNewTess failed");
    OSMesaDestroyContext(r->ctx);
    free(r);
    return NULL;
  }
  /* Casts to _GLUfuncptr (void (*)(void)) are how GLU takes callbacks of any type. */
  gluTessCallback(r->tess, GLU_TESS_BEGIN, (_GLUfuncptr)glBegin);
  gluTessCallback(r->tess, GLU_TESS_VERTEX, (_GLUfuncptr)glVertex3dv);
  gluTessCallback(r->tess, GLU_TESS_END, (_GLUfuncptr)glEnd);
  gluTessCallback(r->tess, GLU_TESS_COMBINE_DATA, (_GLUfuncptr)tess_combine);
  gluTessCallback(r->tess, GLU_TESS_ERROR_DATA, (_GLUfuncptr)tess_error);
  gluTessProperty(r->tess, GLU_TESS_WINDING_RULE, GLU_TESS_WINDING_ODD);
  gluTessProperty(r->tess, GLU_TESS_BOUNDARY_ONLY, GL_FALSE);
  return r;
}

void ref_close(ref_renderer *r)
{
  if (!r) return;
  if (r->tess) gluDeleteTess(r->tess);
  if (r->ctx) {
    OSMesaMakeCurrent(NULL, NULL, 0, 0, 0); /* release before destroying */
    OSMesaDestroyContext(r->ctx);
  }
  free(r->buf);
  free(r->xyz);
  free(r);
}

/* --- rendering ---------------------------------------------------------------------- */

/* Draw one face: eye-space copy, Newell normal, tessellate with the odd rule. */
static int draw_face(ref_renderer *r, const ref_scene *s, const ref_face *f,
                     char *err, size_t errlen)
{
  size_t total = 0;
  for (int k = 0; k < f->nring; k++) total += (size_t)f->ring_len[k];
  if (total > r->xyz_cap) {
    GLdouble *p = realloc(r->xyz, total * 3 * sizeof *p);
    if (!p) {
      set_err(err, errlen, "out of memory");
      return -1;
    }
    r->xyz = p;
    r->xyz_cap = total;
  }
  for (size_t k = 0; k < total; k++) {
    const ref_vertex *v = &s->v[f->vi[k]];
    r->xyz[3 * k + 0] = (double)(v->x - s->x0);
    r->xyz[3 * k + 1] = (double)(v->y - s->y0);
    r->xyz[3 * k + 2] = -(double)(v->z - s->z0);
  }
  /* Newell normal of the outer ring (exact in doubles for these integer inputs). */
  double n[3] = {0, 0, 0};
  for (int k = 0; k < f->ring_len[0]; k++) {
    const GLdouble *a = &r->xyz[3 * k];
    const GLdouble *b = &r->xyz[3 * ((k + 1) % f->ring_len[0])];
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  if (n[0] == 0 && n[1] == 0 && n[2] == 0) return 0; /* degenerate: covers nothing */

  ref_tess_ctx tc = {NULL, 0, 0};
  glColor3ub((GLubyte)(f->id & 0xff), (GLubyte)(f->id >> 8), 0);
  gluTessNormal(r->tess, n[0], n[1], n[2]);
  gluTessBeginPolygon(r->tess, &tc);
  size_t at = 0;
  for (int k = 0; k < f->nring; k++) {
    gluTessBeginContour(r->tess);
    for (int m = 0; m < f->ring_len[k]; m++, at++)
      gluTessVertex(r->tess, &r->xyz[3 * at], &r->xyz[3 * at]);
    gluTessEndContour(r->tess);
  }
  gluTessEndPolygon(r->tess);
  free_blocks(&tc);
  if (tc.failed || tc.glu_error) {
    if (err && errlen)
      snprintf(err, errlen, "GLU tessellation of face %u failed (%s)", f->id,
               tc.failed ? "out of memory" : (const char *)gluErrorString(tc.glu_error));
    return -1;
  }
  return 0;
}

int ref_render_ids(ref_renderer *r, const ref_scene *s, int cell, uint16_t *ids,
                   char *err, size_t errlen)
{
  if (cell != 3 && cell != 4) {
    set_err(err, errlen, "cell must be 3 or 4");
    return -1;
  }
  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  if ((size_t)w * (size_t)h > r->buf_cap) {
    GLubyte *b = realloc(r->buf, (size_t)w * (size_t)h * 4);
    if (!b) {
      set_err(err, errlen, "out of memory");
      return -1;
    }
    r->buf = b;
    r->buf_cap = (size_t)w * (size_t)h;
  }
  if (!OSMesaMakeCurrent(r->ctx, r->buf, GL_UNSIGNED_BYTE, w, h)) {
    set_err(err, errlen, "OSMesaMakeCurrent failed");
    return -1;
  }
  if (s->z0 >= 0 || s->xr <= s->xl || s->yt <= s->yb) {
    set_err(err, errlen, "scene view/window unusable (need Z0 < 0, XL < XR, YB < YT)");
    return -1;
  }

  /* Depth range as tight as the scene: every vertex has z - Z0 > 0. */
  double dmin = 0, dmax = 0;
  for (int k = 0; k < s->nv; k++) {
    double d = (double)(s->v[k].z - s->z0);
    if (d <= 0) {
      set_err(err, errlen, "a vertex is not in front of the eye (z <= Z0)");
      return -1;
    }
    if (k == 0 || d < dmin) dmin = d;
    if (k == 0 || d > dmax) dmax = d;
  }
  if (s->nv == 0) dmin = dmax = 1;
  const double nearz = 0.9 * dmin, farz = 1.1 * dmax;
  const double plane = (double)(-s->z0); /* eye-space distance of the plane z = 0 */

  glViewport(0, 0, w, h);
  glDisable(GL_DITHER);
  glDisable(GL_LIGHTING);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_MULTISAMPLE);
  glDisable(GL_POLYGON_SMOOTH);
  glDisable(GL_TEXTURE_2D);
  glDisable(GL_FOG);
  glDisable(GL_ALPHA_TEST);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_SCISSOR_TEST);
  glShadeModel(GL_FLAT);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDepthRange(0.0, 1.0);
  glClearColor(0, 0, 0, 0);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum((double)(s->xl - s->x0) * nearz / plane, (double)(s->xr - s->x0) * nearz / plane,
            (double)(s->yb - s->y0) * nearz / plane, (double)(s->yt - s->y0) * nearz / plane,
            nearz, farz);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();

  for (int k = 0; k < s->nf; k++)
    if (draw_face(r, s, &s->f[k], err, errlen) != 0) return -1;
  glFinish();
  GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    if (err && errlen) snprintf(err, errlen, "GL error 0x%x", (unsigned)e);
    return -1;
  }

  for (int j = 0; j < h; j++) {
    const GLubyte *row = r->buf + (size_t)(h - 1 - j) * (size_t)w * 4; /* row 0 = bottom */
    for (int i = 0; i < w; i++)
      ids[(size_t)j * (size_t)w + (size_t)i] =
          (uint16_t)(row[4 * i] | (row[4 * i + 1] << 8));
  }
  return 0;
}

long ref_edge_points(const ref_scene *s, int cell, unsigned char *near_edge)
{
  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  memset(near_edge, 0, (size_t)w * (size_t)h);
  /* Plane point (x, y) -> point-grid coordinates (u, v): centres at u = i + 0.5, v = j + 0.5. */
  const double su = w / (double)(s->xr - s->xl), sv = h / (double)(s->yt - s->yb);
  const double m = REF_EDGE_MARGIN_PX;
  long marked = 0;
  for (int k = 0; k < s->nf; k++) {
    const ref_face *f = &s->f[k];
    int at = 0;
    for (int r = 0; r < f->nring; r++) {
      const int n = f->ring_len[r];
      for (int e = 0; e < n; e++) {
        double u[2], v[2];
        for (int q = 0; q < 2; q++) {
          const ref_vertex *p = &s->v[f->vi[at + (e + q) % n]];
          const double t = (double)(-s->z0) / (double)(p->z - s->z0); /* plane / depth */
          u[q] = ((double)s->x0 + (double)(p->x - s->x0) * t - (double)s->xl) * su;
          v[q] = ((double)s->yt - ((double)s->y0 + (double)(p->y - s->y0) * t)) * sv;
        }
        const double du = u[1] - u[0], dv = v[1] - v[0], len2 = du * du + dv * dv;
        int i0 = (int)floor((u[0] < u[1] ? u[0] : u[1]) - m - 0.5);
        int i1 = (int)ceil((u[0] > u[1] ? u[0] : u[1]) + m - 0.5);
        int j0 = (int)floor((v[0] < v[1] ? v[0] : v[1]) - m - 0.5);
        int j1 = (int)ceil((v[0] > v[1] ? v[0] : v[1]) + m - 0.5);
        if (i0 < 0) i0 = 0;
        if (j0 < 0) j0 = 0;
        if (i1 > w - 1) i1 = w - 1;
        if (j1 > h - 1) j1 = h - 1;
        for (int j = j0; j <= j1; j++)
          for (int i = i0; i <= i1; i++) {
            const double cu = i + 0.5 - u[0], cv = j + 0.5 - v[0];
            double t = len2 > 0 ? (cu * du + cv * dv) / len2 : 0;
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            const double eu = cu - t * du, ev = cv - t * dv;
            unsigned char *p = &near_edge[(size_t)j * (size_t)w + (size_t)i];
            if (eu * eu + ev * ev <= m * m && !*p) {
              *p = 1;
              marked++;
            }
          }
      }
      at += n;
    }
  }
  return marked;
}

long ref_uniform_face(const uint16_t *ids, const unsigned char *near_edge, int w, int h, int i,
                      int j)
{
  const size_t at = (size_t)j * (size_t)w + (size_t)i;
  if (near_edge && near_edge[at]) return -1;
  const uint16_t c = ids[at];
  for (int dj = -1; dj <= 1; dj++)
    for (int di = -1; di <= 1; di++) {
      int x = i + di, y = j + dj;
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      if (ids[(size_t)y * (size_t)w + (size_t)x] != c) return -1;
    }
  return c;
}
