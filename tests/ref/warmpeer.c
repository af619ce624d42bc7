/*
** warmpeer.c — the warm OSMesa peer of the speed bench, ids or Phong-shaded (warmpeer.h).
**
** This file contains code to tessellate a ref_scene with GLU (odd winding, the Newell
** normal of the outer ring, as osmesa_ref.c does) into one vertex array of triangles,
** each vertex with the face number as its colour and, in the shaded mode, a normal;
** to make an OSMesa context at the scene's viewport with the same frustum as the
** cross-check reference; and to draw a frame of it. Everything but the frame is done in
** ref_peer_new, before the bench's clock.
**
** The shaded mode's program (GLSL 1.30, the compatibility built-ins gl_Vertex, gl_Normal,
** gl_Color): the vertex stage passes the eye-space position, the normal and the face
** colour (flat); the fragment stage normalises the interpolated normal, sums
** max(0, n.l) over the lights (a point light's direction from the fragment's position),
** and writes grey = min(255, 48 + floor(207 sum + 0.5)) / 255 into alpha, the face
** colour into R, G, B. The lights are constants in the program's text, in eye space.
**
** Eye space: every vertex moved by -eye on the CPU and z flipped (GL looks down -z);
** normals and lights go through the same map, so every dot product is the scene's.
*/
#include "tests/ref/warmpeer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glu.h>

#define PEER_AMBIENT 48          /* render/shade.h SHADE_AMBIENT: the grey no light reaches */

/* a vertex as GLU hands it around: eye-space position and (shaded mode) normal */
typedef struct pv {
  GLdouble xyz[3];
  double n[3];
} pv;

typedef struct pv_block {
  struct pv_block *next;
  int used;
  pv v[256];
} pv_block;

/* the GL 2.0 entry points, from OSMesaGetProcAddress (OSMesa's own, whatever else is
   linked) */
typedef struct gl2 {
  PFNGLCREATESHADERPROC CreateShader;
  PFNGLSHADERSOURCEPROC ShaderSource;
  PFNGLCOMPILESHADERPROC CompileShader;
  PFNGLGETSHADERIVPROC GetShaderiv;
  PFNGLGETSHADERINFOLOGPROC GetShaderInfoLog;
  PFNGLCREATEPROGRAMPROC CreateProgram;
  PFNGLATTACHSHADERPROC AttachShader;
  PFNGLLINKPROGRAMPROC LinkProgram;
  PFNGLGETPROGRAMIVPROC GetProgramiv;
  PFNGLGETPROGRAMINFOLOGPROC GetProgramInfoLog;
  PFNGLUSEPROGRAMPROC UseProgram;
  PFNGLDELETESHADERPROC DeleteShader;
  PFNGLDELETEPROGRAMPROC DeleteProgram;
} gl2;

/* the triangle array being built by the tessellator's callbacks */
typedef struct tri_out {
  GLfloat *xyz, *nrm;           /* 3 per vertex; nrm only in the shaded mode */
  GLubyte *rgb;                 /* 3 per vertex: the face number */
  size_t n, cap;
  GLubyte col[3];               /* the face being tessellated */
  int shade;
  pv_block *extra;              /* combine vertices, kept to the end of the polygon */
  int failed;
} tri_out;

struct ref_peer {
  OSMesaContext ctx;
  int w, h, shade;
  GLubyte *buf;                 /* RGBA, bottom row first */
  tri_out t;
  gl2 gl;
  GLuint prog;
};

static void set_err(char *err, size_t errlen, const char *msg)
{
  if (err && errlen) snprintf(err, errlen, "%s", msg);
}

/* ---- GLU callbacks ------------------------------------------------------------------ */

static void GLAPIENTRY to_vertex(void *v, void *data)
{
  tri_out *a = data;
  const pv *p = v;
  if (a->failed) return;
  if (a->n == a->cap) {
    size_t cap = a->cap ? 2 * a->cap : 3 * 4096;
    GLfloat *x = realloc(a->xyz, cap * 3 * sizeof *x);
    if (x) a->xyz = x;
    GLubyte *c = realloc(a->rgb, cap * 3);
    if (c) a->rgb = c;
    GLfloat *nn = a->shade ? realloc(a->nrm, cap * 3 * sizeof *nn) : NULL;
    if (nn) a->nrm = nn;
    if (!x || !c || (a->shade && !nn)) { a->failed = 1; return; }
    a->cap = cap;
  }
  for (size_t k = 0; k < 3; k++) {
    a->xyz[3 * a->n + k] = (GLfloat)p->xyz[k];
    a->rgb[3 * a->n + k] = a->col[k];
    if (a->shade) a->nrm[3 * a->n + k] = (GLfloat)p->n[k];
  }
  a->n++;
}

static void GLAPIENTRY to_begin(GLenum mode, void *data) { (void)mode; (void)data; }
static void GLAPIENTRY to_end(void *data) { (void)data; }
/* an edge-flag callback makes GLU give plain GL_TRIANGLES */
static void GLAPIENTRY to_edge(GLboolean flag, void *data) { (void)flag; (void)data; }

static void GLAPIENTRY to_combine(GLdouble c[3], void *vd[4], GLfloat w[4], void **out, void *data)
{
  tri_out *a = data;
  if (!a->extra || a->extra->used == 256) {
    pv_block *b = malloc(sizeof *b);
    if (!b) { a->failed = 1; *out = NULL; return; }
    b->next = a->extra;
    b->used = 0;
    a->extra = b;
  }
  pv *p = &a->extra->v[a->extra->used++];
  memcpy(p->xyz, c, sizeof p->xyz);
  memset(p->n, 0, sizeof p->n);
  for (int k = 0; k < 4; k++) {
    const pv *q = vd[k];
    if (q) for (int m = 0; m < 3; m++) p->n[m] += w[k] * q->n[m];
  }
  *out = p;
}

static void GLAPIENTRY to_error(GLenum e, void *data) { (void)e; ((tri_out *)data)->failed = 1; }

/* ---- normals ------------------------------------------------------------------------ */

static void unit(double v[3])
{
  double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (n > 0) { v[0] /= n; v[1] /= n; v[2] /= n; }
}

static void eye_xyz(const ref_scene *s, int vi, double out[3])
{
  const ref_vertex *v = &s->v[vi];
  out[0] = (double)(v->x - s->x0);
  out[1] = (double)(v->y - s->y0);
  out[2] = -(double)(v->z - s->z0);
}

/* the Newell normal of a face's outer ring, eye space (not unit; zero when degenerate) */
static void newell(const ref_scene *s, const ref_face *f, double n[3])
{
  n[0] = n[1] = n[2] = 0;
  for (int q = 0; q < f->ring_len[0]; q++) {
    double a[3], b[3];
    eye_xyz(s, f->vi[q], a);
    eye_xyz(s, f->vi[(q + 1) % f->ring_len[0]], b);
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
}

static int smooth_face(const ref_peer_input *in, int k)
{
  const ref_face *f = &in->s->f[k];
  return in->object && in->object[k] != 0 && f->nring == 1 && f->ring_len[0] == 3 && f->grey < 0;
}

/* (object, vertex) of one corner of a smoothed triangle, and where its normal goes */
typedef struct corner { int object, vi, slot; } corner;

static int cmp_corner(const void *x, const void *y)
{
  const corner *a = x, *b = y;
  if (a->object != b->object) return (a->object > b->object) - (a->object < b->object);
  return (a->vi > b->vi) - (a->vi < b->vi);
}

/* vn[3 * (3k + c)]: the unit vertex normal at corner c of smoothed face k (the mean of the
   unit normals of its object's smoothed triangles there); fn[3k]: face k's unit normal */
static int vertex_normals(const ref_peer_input *in, const double *fn, double *vn)
{
  const ref_scene *s = in->s;
  corner *c = malloc((size_t)(s->nf ? s->nf : 1) * 3 * sizeof *c);
  if (!c) return -1;
  size_t m = 0;
  for (int k = 0; k < s->nf; k++)
    if (smooth_face(in, k))
      for (int q = 0; q < 3; q++) c[m++] = (corner){ in->object[k], s->f[k].vi[q], 3 * k + q };
  qsort(c, m, sizeof *c, cmp_corner);
  for (size_t a = 0, b; a < m; a = b) {
    double sum[3] = { 0, 0, 0 };
    for (b = a; b < m && c[b].object == c[a].object && c[b].vi == c[a].vi; b++)
      for (int d = 0; d < 3; d++) sum[d] += fn[3 * (c[b].slot / 3) + d];
    unit(sum);
    for (size_t q = a; q < b; q++) memcpy(&vn[3 * c[q].slot], sum, sizeof sum);
  }
  free(c);
  return 0;
}

/* ---- tessellation ------------------------------------------------------------------- */

static int tessellate(const ref_peer_input *in, tri_out *t)
{
  const ref_scene *s = in->s;
  double *fn = malloc((size_t)(s->nf ? s->nf : 1) * 3 * sizeof *fn);
  double *vn = in->shade ? malloc((size_t)(s->nf ? s->nf : 1) * 9 * sizeof *vn) : NULL;
  pv *pts = NULL;
  size_t cap = 0;
  GLUtesselator *tess = gluNewTess();
  if (!fn || (in->shade && !vn) || !tess) { free(fn); free(vn); if (tess) gluDeleteTess(tess); return -1; }
  for (int k = 0; k < s->nf; k++) {
    newell(s, &s->f[k], &fn[3 * k]);
    unit(&fn[3 * k]);
  }
  if (in->shade && vertex_normals(in, fn, vn) != 0) t->failed = 1;
  gluTessCallback(tess, GLU_TESS_BEGIN_DATA, (_GLUfuncptr)to_begin);
  gluTessCallback(tess, GLU_TESS_VERTEX_DATA, (_GLUfuncptr)to_vertex);
  gluTessCallback(tess, GLU_TESS_END_DATA, (_GLUfuncptr)to_end);
  gluTessCallback(tess, GLU_TESS_EDGE_FLAG_DATA, (_GLUfuncptr)to_edge);
  gluTessCallback(tess, GLU_TESS_COMBINE_DATA, (_GLUfuncptr)to_combine);
  gluTessCallback(tess, GLU_TESS_ERROR_DATA, (_GLUfuncptr)to_error);
  gluTessProperty(tess, GLU_TESS_WINDING_RULE, GLU_TESS_WINDING_ODD);
  for (int k = 0; k < s->nf && !t->failed; k++) {
    const ref_face *f = &s->f[k];
    size_t total = 0;
    for (int r = 0; r < f->nring; r++) total += (size_t)f->ring_len[r];
    if (total > cap) {
      free(pts);
      cap = total;
      pts = malloc(cap * sizeof *pts);
      if (!pts) { t->failed = 1; break; }
    }
    const double *n = &fn[3 * k];
    if (n[0] == 0 && n[1] == 0 && n[2] == 0) continue;   /* degenerate: covers nothing */
    for (size_t q = 0; q < total; q++) eye_xyz(s, f->vi[q], pts[q].xyz);
    /* the eye's side of the face's plane (the eye is the origin) */
    const double side = n[0] * pts[0].xyz[0] + n[1] * pts[0].xyz[1] + n[2] * pts[0].xyz[2] < 0 ? 1 : -1;
    for (size_t q = 0; q < total; q++)
      for (int d = 0; d < 3; d++)
        pts[q].n[d] = side * (smooth_face(in, k) && in->shade ? vn[3 * (3 * (size_t)k + q) + (size_t)d] : n[d]);
    t->col[0] = (GLubyte)(f->id & 0xff);
    t->col[1] = (GLubyte)(f->id >> 8 & 0xff);
    t->col[2] = (GLubyte)(f->id >> 16 & 0xff);
    gluTessNormal(tess, n[0], n[1], n[2]);
    gluTessBeginPolygon(tess, t);
    size_t at = 0;
    for (int r = 0; r < f->nring; r++) {
      gluTessBeginContour(tess);
      for (int q = 0; q < f->ring_len[r]; q++, at++) gluTessVertex(tess, pts[at].xyz, &pts[at]);
      gluTessEndContour(tess);
    }
    gluTessEndPolygon(tess);
    while (t->extra) { pv_block *b = t->extra->next; free(t->extra); t->extra = b; }
  }
  gluDeleteTess(tess);
  free(pts);
  free(fn);
  free(vn);
  return t->failed ? -1 : 0;
}

/* ---- the shader ----------------------------------------------------------------------- */

static int load_gl2(gl2 *g)
{
#define GET(name, type) if (!(g->name = (type)(void (*)(void))OSMesaGetProcAddress("gl" #name))) return -1
  GET(CreateShader, PFNGLCREATESHADERPROC);
  GET(ShaderSource, PFNGLSHADERSOURCEPROC);
  GET(CompileShader, PFNGLCOMPILESHADERPROC);
  GET(GetShaderiv, PFNGLGETSHADERIVPROC);
  GET(GetShaderInfoLog, PFNGLGETSHADERINFOLOGPROC);
  GET(CreateProgram, PFNGLCREATEPROGRAMPROC);
  GET(AttachShader, PFNGLATTACHSHADERPROC);
  GET(LinkProgram, PFNGLLINKPROGRAMPROC);
  GET(GetProgramiv, PFNGLGETPROGRAMIVPROC);
  GET(GetProgramInfoLog, PFNGLGETPROGRAMINFOLOGPROC);
  GET(UseProgram, PFNGLUSEPROGRAMPROC);
  GET(DeleteShader, PFNGLDELETESHADERPROC);
  GET(DeleteProgram, PFNGLDELETEPROGRAMPROC);
#undef GET
  return 0;
}

static const char peer_vs[] =
  "#version 130\n"
  "out vec3 pos;\n"
  "out vec3 nrm;\n"
  "flat out vec3 face;\n"
  "void main() {\n"
  "  pos = gl_Vertex.xyz;\n"
  "  nrm = gl_Normal;\n"
  "  face = gl_Color.rgb;\n"
  "  gl_Position = gl_ModelViewProjectionMatrix * gl_Vertex;\n"
  "}\n";

/* the fragment stage with the lights written in (eye space); NULL when out of memory */
static char *fragment_source(const ref_peer_input *in)
{
  const ref_scene *s = in->s;
  size_t cap = 1024 + (size_t)in->nlight * 160;
  char *src = malloc(cap);
  if (!src) return NULL;
  size_t n = (size_t)snprintf(src, cap,
    "#version 130\n"
    "in vec3 pos;\n"
    "in vec3 nrm;\n"
    "flat in vec3 face;\n"
    "void main() {\n"
    "  vec3 n = normalize(nrm);\n"
    "  float sum = 0.0;\n");
  for (int k = 0; k < in->nlight; k++) {
    const ref_light *L = &in->light[k];
    double l[3] = { L->v[0], L->v[1], -L->v[2] };
    if (L->point) { l[0] -= (double)s->x0; l[1] -= (double)s->y0; l[2] += (double)s->z0; }
    else unit(l);
    n += (size_t)snprintf(src + n, cap - n,
                          L->point ? "  sum += max(dot(n, normalize(vec3(%.9g, %.9g, %.9g) - pos)), 0.0);\n"
                                   : "  sum += max(dot(n, vec3(%.9g, %.9g, %.9g)), 0.0);\n",
                          l[0], l[1], l[2]);
  }
  snprintf(src + n, cap - n,
           "  float g = min(%d.0 + floor(%d.0 * sum + 0.5), 255.0);\n"
           "  gl_FragColor = vec4(face, g / 255.0);\n"
           "}\n", PEER_AMBIENT, 255 - PEER_AMBIENT);
  return src;
}

static GLuint compile(const gl2 *g, GLenum kind, const char *src, char *err, size_t errlen)
{
  GLuint sh = g->CreateShader(kind);
  g->ShaderSource(sh, 1, &src, NULL);
  g->CompileShader(sh);
  GLint ok = 0;
  g->GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    g->GetShaderInfoLog(sh, sizeof log, NULL, log);
    if (err && errlen) snprintf(err, errlen, "the %s shader does not compile: %s",
                                kind == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    g->DeleteShader(sh);
    return 0;
  }
  return sh;
}

static int make_program(ref_peer *p, const ref_peer_input *in, char *err, size_t errlen)
{
  int major = 0, minor = 0;
  const char *ver = (const char *)glGetString(GL_VERSION);
  if (!ver || sscanf(ver, "%d.%d", &major, &minor) != 2 || major * 10 + minor < 30) {
    if (err && errlen) snprintf(err, errlen, "the shaded peer needs GL 3.0 (GLSL 1.30); the context gives %s",
                                ver ? ver : "no version");
    return -1;
  }
  if (load_gl2(&p->gl) != 0) { set_err(err, errlen, "OSMesaGetProcAddress has no GL 2.0 shader entry points"); return -1; }
  char *fs_src = fragment_source(in);
  if (!fs_src) { set_err(err, errlen, "out of memory"); return -1; }
  GLuint vs = compile(&p->gl, GL_VERTEX_SHADER, peer_vs, err, errlen);
  GLuint fs = vs ? compile(&p->gl, GL_FRAGMENT_SHADER, fs_src, err, errlen) : 0;
  free(fs_src);
  if (!fs) { if (vs) p->gl.DeleteShader(vs); return -1; }
  p->prog = p->gl.CreateProgram();
  p->gl.AttachShader(p->prog, vs);
  p->gl.AttachShader(p->prog, fs);
  p->gl.LinkProgram(p->prog);
  p->gl.DeleteShader(vs);
  p->gl.DeleteShader(fs);
  GLint ok = 0;
  p->gl.GetProgramiv(p->prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    p->gl.GetProgramInfoLog(p->prog, sizeof log, NULL, log);
    if (err && errlen) snprintf(err, errlen, "the shaded peer's program does not link: %s", log);
    return -1;
  }
  p->gl.UseProgram(p->prog);
  return 0;
}

/* ---- the peer ----------------------------------------------------------------------- */

ref_peer *ref_peer_new(const ref_peer_input *in, char *err, size_t errlen)
{
  const ref_scene *s = in->s;
  double dmin = 1, dmax = 1;
  for (int k = 0; k < s->nv; k++) {
    double d = (double)(s->v[k].z - s->z0);
    if (k == 0 || d < dmin) dmin = d;
    if (k == 0 || d > dmax) dmax = d;
  }
  if (s->z0 >= 0 || dmin <= 0 || in->w < 1 || in->h < 1) {
    set_err(err, errlen, "the eye must be in front of every vertex");
    return NULL;
  }
  ref_peer *p = calloc(1, sizeof *p);
  if (!p) { set_err(err, errlen, "out of memory"); return NULL; }
  p->w = in->w;
  p->h = in->h;
  p->shade = in->shade;
  p->t.shade = in->shade;
  if (tessellate(in, &p->t) != 0) {
    set_err(err, errlen, "tessellation failed");
    ref_peer_free(p);
    return NULL;
  }
  /* An unknown GALLIUM_DRIVER crashes inside OSMesaCreateContextExt (osmesa_ref.c). */
  const char *drv = getenv("GALLIUM_DRIVER");
  if (!drv || (strcmp(drv, "llvmpipe") != 0 && strcmp(drv, "softpipe") != 0))
    setenv("GALLIUM_DRIVER", "llvmpipe", 1);
  p->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
  p->buf = malloc((size_t)p->w * (size_t)p->h * 4);
  if (!p->ctx || !p->buf || !OSMesaMakeCurrent(p->ctx, p->buf, GL_UNSIGNED_BYTE, p->w, p->h)) {
    set_err(err, errlen, "no OSMesa context");
    ref_peer_free(p);
    return NULL;
  }
  if (p->shade && make_program(p, in, err, errlen) != 0) { ref_peer_free(p); return NULL; }
  const double plane = (double)-s->z0, nearz = 0.9 * dmin, farz = 1.1 * dmax;
  glViewport(0, 0, p->w, p->h);
  glDisable(GL_DITHER);
  glShadeModel(GL_FLAT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(0, 0, 0, 0);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum((double)(s->xl - s->x0) * nearz / plane, (double)(s->xr - s->x0) * nearz / plane,
            (double)(s->yb - s->y0) * nearz / plane, (double)(s->yt - s->y0) * nearz / plane,
            nearz, farz);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_COLOR_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, p->t.xyz);
  glColorPointer(3, GL_UNSIGNED_BYTE, 0, p->t.rgb);
  if (p->shade) {
    glEnableClientState(GL_NORMAL_ARRAY);
    glNormalPointer(GL_FLOAT, 0, p->t.nrm);
  }
  if (glGetError() != GL_NO_ERROR) {
    set_err(err, errlen, "GL error while setting up");
    ref_peer_free(p);
    return NULL;
  }
  return p;
}

int ref_peer_frame(ref_peer *p, uint32_t *ids, uint8_t *grey)
{
  if (OSMesaGetCurrentContext() != p->ctx && !OSMesaMakeCurrent(p->ctx, p->buf, GL_UNSIGNED_BYTE, p->w, p->h))
    return -1;
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDrawArrays(GL_TRIANGLES, 0, (GLsizei)p->t.n);
  glFinish();
  const size_t w = (size_t)p->w, h = (size_t)p->h;
  for (size_t j = 0; j < h; j++) {
    const GLubyte *row = p->buf + (h - 1 - j) * w * 4;
    for (size_t i = 0; i < w; i++)
      ids[j * w + i] = (uint32_t)row[4 * i] | (uint32_t)row[4 * i + 1] << 8 | (uint32_t)row[4 * i + 2] << 16;
    if (p->shade && grey)
      for (size_t i = 0; i < w; i++) grey[j * w + i] = row[4 * i + 3];
  }
  return glGetError() == GL_NO_ERROR ? 0 : -1;
}

size_t ref_peer_triangles(const ref_peer *p) { return p->t.n / 3; }

void ref_peer_free(ref_peer *p)
{
  if (!p) return;
  if (p->ctx) {
    if (p->prog && OSMesaGetCurrentContext() == p->ctx) p->gl.DeleteProgram(p->prog);
    OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
    OSMesaDestroyContext(p->ctx);
  }
  free(p->buf);
  free(p->t.xyz);
  free(p->t.nrm);
  free(p->t.rgb);
  free(p);
}
