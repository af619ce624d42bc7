/*
** test_import.c — Wavefront .obj / .off import (render/import.c): bad input, line ends, the
** split of faces that rounding made non-planar, and order independence; and the replay of
** the fuzz corpora of the scene readers and the background loader.
**
** This file contains the checks that an import is a function of the mesh, not of how it
** is written down, and that the region a face covers survives its split:
**   bad input   `f` with 0-2 references, an .off face with 0-2 vertices, a bow-tie (edges
**               crossing in the file: planar, bent, in a vertical plane), a coordinate
**               outside the exact range: each refused with FILE:LINE and status 2 (and
**               exit 2 from the command, no output file);
**   the pinch   a face that rounding pinches (two vertices onto one grid point) is split
**               into triangles in the file's coordinates, not refused: it covers what its
**               two lobes written as two faces cover;
**   line ends   a UTF-8 byte order mark, CR LF and lone CR line ends are read like LF, in
**               .obj, .off and .s74, with the same line numbers in messages;
**   the notch   a concave face made non-planar by rounding is split by ear clipping into
**               triangles that cover exactly its outline: the picture equals that of the
**               same outline kept planar, and the notch stays empty; the triangles are the
**               same for every way of writing the ring (8 rotations and orientations);
**               straight vertices stay corners of the triangles;
**   order       generated meshes (tori, spheres, boxes, terrains with non-planar quads, and
**               the scenegen families, concave combs and stars among them, scaled off the
**               grid), written as .obj and .off in four ways — as generated, faces
**               reversed, every ring reversed, faces shuffled with every ring rotated —
**               must give the same `ids` picture at both cell sizes, face numbers mapped
**               through the permutation; where no face was split (so every number is one
**               face), the imported scene written as .s74 must give the same picture too;
**               and once through the command (`--dump ids` of a mesh and of its reversal);
**   finds       the fuzzers' finds, each with the exact answer (a cube's corner pierced by
**               a face: the front must be the face the plane equations put in front);
**   corpora     every file of tests/fuzz/corpus_{s74,obj,off}/ read, rendered and rendered
**               reversed (tests/ref/memrender.c: what the fuzz targets check; for .obj and
**               .off also every face line reversed in the text), and every file of
**               tests/fuzz/corpus_pic/ through pic_load: no crash, only status 2 or 4
**               refusals naming the file.
*/
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "patterns/halftone.h"
#include "patterns/picture.h"
#include "render/import.h"
#include "render/scene.h"
#include "tests/ref/memrender.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/testkit.h"
#include "tests/ref/tuberun.h"

#define PI 3.14159265358979323846

struct fx { char dir[64]; char path[256]; };


/* The tests here are about the file as written, seen on the paper's axis: no --turn
   (the three-quarter default of imports, render/turn.h, is tested in tests/test_turn.c). */
static const struct scene_opts on_axis = { .has_turn = true, .turn = { 0.0, 0.0 } };
static int group_setup(void **state)
{
  struct fx *f = calloc(1, sizeof *f);
  if (!f) return -1;
  if (tk_mkscratch(f->dir, sizeof f->dir, "/tmp/tube74-import-XXXXXX") != 0) {
    free(f);
    return -1;
  }
  *state = f;
  return 0;
}

static int group_teardown(void **state)
{
  struct fx *f = *state;
  int rc = tk_rmscratch(f->dir);
  free(f);
  return rc;
}

static void write_file(struct fx *f, const char *name, const char *text, size_t len)
{
  snprintf(f->path, sizeof f->path, "%s/%s", f->dir, name);
  FILE *fp = fopen(f->path, "wb");
  assert_non_null(fp);
  if (len) assert_int_equal(fwrite(text, 1, len, fp), len);
  assert_int_equal(fclose(fp), 0);
}

/* A growing text buffer. */
struct text { char *s; size_t n, cap; };

static void tprintf(struct text *t, const char *fmt, ...)
{
  va_list ap;
  for (;;) {
    va_start(ap, fmt);
    int k = vsnprintf(t->s ? t->s + t->n : NULL, t->s ? t->cap - t->n : 0, fmt, ap);
    va_end(ap);
    assert_true(k >= 0);
    if (t->s && t->n + (size_t)k < t->cap) { t->n += (size_t)k; return; }
    size_t nc = (t->cap + (size_t)k + 1) * 2;
    char *ns = realloc(t->s, nc);
    assert_non_null(ns);
    t->s = ns;
    t->cap = nc;
  }
}

/* ---- bad input ------------------------------------------------------------------------- */

#define BAD_IMPORTS(X)                                                                     \
  X(obj_f_none, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n", 4,                                  \
    "`f` needs at least 3 vertices, has 0")                                                \
  X(obj_f_one, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1\n", 4,                                \
    "`f` needs at least 3 vertices, has 1")                                                \
  X(obj_f_two, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 # a line\n", 5,                  \
    "`f` needs at least 3 vertices, has 2")                                                \
  X(obj_fo_two, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nfo 1 2\n", 4, "`fo` needs at least 3")  \
  X(off_face_none, "off", "OFF\n3 2\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n", 7,                 \
    "a face needs at least 3 vertices, this one has 0")                                    \
  X(off_face_two, "off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 6,                       \
    "a face needs at least 3 vertices, this one has 2")                                    \
  X(obj_bowtie, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n", 5,               \
    "face 1 is not simple in the file: its edges 2-3 and 4-1")                             \
  X(obj_index_24_bytes, "obj",                                                            \
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 000000000000000000000003\n", 4,                      \
    "bad face vertex `000000000000000000000003`")                                          \
  X(obj_bowtie_first_pair, "obj", "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n", 5,      \
    "face 1 is not simple in the file: its edges 1-2 and 3-4")                             \
  X(obj_bowtie_five, "obj", "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nv 1 -1 0\nf 1 2 3 4 5\n", 6, \
    "face 1 is not simple in the file")                                                    \
  X(obj_bowtie_nonplanar, "obj",                                                           \
    "v 0 0 0\nv 3 0 0.01\nv 0 1 0.02\nv 1 1 0\nv 5 5 5\nf 5 1 2\nf 1 2 3 4\n", 7,        \
    "face 2 is not simple in the file: its edges 2-3 and 4-1")                            \
  X(obj_bowtie_by_an_ulp, "obj", /* vertex 4 is above line 1-2 by less than the float      \
    filter's bound: the expansion decides (orient_d) */                                    \
    "v 0.1 0.3 0\nv 2.9 8.7 0\nv 1.9 0 0\nv 1.9 5.7 0\nf 1 2 3 4\n", 5,                   \
    "face 1 is not simple in the file: its edges 1-2 and 3-4")                             \
  X(obj_bowtie_vertical, "obj", "v 0 0 0\nv 0 1 0\nv 0 0 1\nv 0 1 1\nf 1 2 3 4\n", 5,     \
    "face 1 is not simple in the file: its edges 2-3 and 4-1")                             \
  X(obj_bowtie_second, "obj",                                                              \
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 2 4\n", 6,                      \
    "face 2 is not simple in the file")                                                    \
  X(off_bowtie, "off", "OFF\n4 1\n0 0 0\n2 0 0\n0 2 0\n2 2 0\n4 0 1 2 3\n", 7,              \
    "face 1 is not simple in the file")                                                    \
  X(obj_tiny_coordinate, "obj", "v 0 0 1e-200\n", 1, "coordinate `1e-200` out of range")   \
  X(off_huge_coordinate, "off", "OFF\n3 1\n0 0 1e300\n1 0 0\n0 1 0\n3 0 1 2\n", 3,          \
    "coordinate `1e300` out of range")                                                     \
  X(obj_cr_error_line, "obj", "v 0 0 0\rv 1 0 0\r\rv 0 1 0\rf 1 2\r", 5, "needs at least 3") \
  X(obj_crlf_error_line, "obj", "v 0 0 0\r\nv 1 0 0\r\n\r\nv 0 1 0\r\nf 1 2\r\n", 5,        \
    "needs at least 3")                                                                    \
  X(obj_bom_error_line, "obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nf 1 2\n", 3, "needs at least 3") \
  X(obj_bom_inside, "obj", "v 0 0 0\n\xEF\xBB\xBFv 1 0 0\n", 2, "unknown statement `???v`")

static void expect_refused(void **state, const char *name, const char *kind,
                           const char *text, size_t len, int line, const char *what)
{
  struct fx *f = *state;
  char file[64];
  snprintf(file, sizeof file, "%s.%s", name, kind);
  write_file(f, file, text, len);
  struct scene *s = (struct scene *)1;
  struct t74_error err = { 0 };
  int st = scene_load(f->path, &on_axis, &s, &err);
  char prefix[300];
  snprintf(prefix, sizeof prefix, "%s:%d: ", f->path, line);
  if (st != T74_EINPUT || strncmp(err.msg, prefix, strlen(prefix)) != 0 ||
      !strstr(err.msg, what))
    fail_msg("%s: status %d, message \"%s\"; wanted 2, \"%s...%s\"", name, st, err.msg,
             prefix, what);
  assert_null(s);
}

#define DEFINE_BAD(name, kind, text, line, what)                                         \
  static void bad_##name(void **state)                                                   \
  {                                                                                      \
    static const char t[] = text;                                                        \
    expect_refused(state, #name, kind, t, sizeof t - 1, line, what);                     \
  }
BAD_IMPORTS(DEFINE_BAD)

/* Vertex 4 is below line 1-2 in binary (0.1 0.3, 2.9 8.7, 1.3 3.9 are not collinear as
   doubles), by less than orient_d's float filter can tell: the face touches nothing in
   the file and is kept. A filter that trusted the rounded determinant (its sign is the
   wrong one here) would refuse it as a bow-tie. */
static void no_bowtie_below_an_ulp(void **state)
{
  struct fx *f = *state;
  static const char t[] = "v 0.1 0.3 0\nv 2.9 8.7 0\nv 1.3 0 0\nv 1.3 3.9 0\nf 1 2 3 4\n";
  write_file(f, "below.obj", t, sizeof t - 1);
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  int st = scene_load(f->path, &on_axis, &s, &err);
  if (st != T74_OK) fail_msg("status %d, message \"%s\"", st, err.msg);
  assert_non_null(s);
  assert_true(s->nf >= 1);
  scene_free(s);
}

/* A quad on a random plane (or flat, convex or not), rounded onto the grid: the import
   keeps it whole exactly when scene_check_face passes the rounded quad, and warns (split
   or dropped) exactly when it says not planar; the import tells most such quads without
   scene_check_face (quad_off_plane), and this holds it to the same verdict. */
static void quad_verdicts_as_scene_check(void **state)
{
  struct fx *f = *state;
  struct scene_opts quiet = on_axis;
  quiet.quiet = true;
  uint32_t seed = 12345;
  int seen[2] = { 0, 0 };
  for (int t = 0; t < 400; t++) {
    double q[4][3];
    for (int k = 0; k < 4; k++) {
      double x, y;
      seed = seed * 1103515245u + 12345u; x = (double)(seed >> 8) / (1 << 24);
      seed = seed * 1103515245u + 12345u; y = (double)(seed >> 8) / (1 << 24);
      if (t % 4 == 0) { x = k == 1 || k == 2 ? 1 : 0; y = k >= 2 ? 1 : 0; x += y * 0.3 * (k & 1); }
      q[k][0] = x;
      q[k][1] = y;
      q[k][2] = t % 3 == 0 ? 0.25 : 0.1 + 0.37 * x + 0.21 * y;   /* a plane, in decimals */
    }
    char text[512];
    int len = snprintf(text, sizeof text,
                       "v %.9f %.9f %.9f\nv %.9f %.9f %.9f\nv %.9f %.9f %.9f\nv %.9f %.9f %.9f\n"
                       "v -1 -1 -1\nv 2 2 2\nf 1 2 3 4\n", q[0][0], q[0][1], q[0][2], q[1][0],
                       q[1][1], q[1][2], q[2][0], q[2][1], q[2][2], q[3][0], q[3][1], q[3][2]);
    write_file(f, "quad.obj", text, (size_t)len);
    struct scene *sc = NULL;
    struct t74_error err = { 0 };
    if (scene_load(f->path, &quiet, &sc, &err) != T74_OK) continue;   /* a bow-tie */
    int vi[4] = { 0, 1, 2, 3 }, rs[2] = { 0, 4 };
    struct scene_face face = { .id = 1, .line = 7, .grey = -1, .nring = 1, .ring_start = rs,
                               .vidx = vi };
    int d = scene_check_face(sc, &face, NULL);
    if (d == SCENE_FACE_OK) {
      assert_int_equal(sc->nf, 1);
      assert_int_equal(sc->warnings, 0);
      seen[0]++;
    } else if (d == SCENE_FACE_NONPLANAR) {
      assert_true(sc->warnings >= 1);
      seen[1]++;
    }
    scene_free(sc);
  }
  if (seen[0] < 20 || seen[1] < 20) fail_msg("kept %d, not planar %d: too few", seen[0], seen[1]);
}

/* `tube74 render` of f's file (f->path, *scene) refused: exit 2, no output written; its
   stderr kept in errp (dir/stem.err) and opened for reading. */
static FILE *render_refused(struct fx *f, const char *stem, char scene[300], char errp[300])
{
  char out[300], cmd[1200];
  snprintf(scene, 300, "%s", f->path);
  snprintf(out, sizeof out, "%s/%s.png", f->dir, stem);
  snprintf(errp, 300, "%s/%s.err", f->dir, stem);
  unlink(out);
  snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' 2>'%s'", tk_prog(), scene, out, errp);
  int rc = system(cmd);
  assert_true(WIFEXITED(rc));
  assert_int_equal(WEXITSTATUS(rc), 2);
  assert_int_equal(access(out, F_OK), -1);
  FILE *e = fopen(errp, "r");
  assert_non_null(e);
  return e;
}

/* The command refuses such a file with exit 2, the message on stderr, no output. */
static void command_exit_2(void **state)
{
  struct fx *f = *state;
  if (access(tk_prog(), X_OK) != 0) skip();
  static const char *const texts[] = {
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n",
  };
  for (size_t k = 0; k < sizeof texts / sizeof *texts; k++) {
    write_file(f, "cmd.obj", texts[k], strlen(texts[k]));
    char scene[300], errp[300];
    FILE *e = render_refused(f, "cmd", scene, errp);
    char line[600] = "";
    assert_non_null(fgets(line, sizeof line, e));
    fclose(e);
    char prefix[320];
    snprintf(prefix, sizeof prefix, "%s:%d: ", scene, k == 0 ? 4 : 5);
    if (strncmp(line, prefix, strlen(prefix)) != 0) fail_msg("stderr: %s", line);
    unlink(errp);
  }
}

/* The warnings an import prints, gathered a buffer at a time: 300 faces rounded away (some
   18 kB of warnings, more than one buffer), every line whole and in the file's order,
   then the error of a face refused after them, last; exit 2, no output. */
static void command_warnings_in_order(void **state)
{
  struct fx *f = *state;
  if (access(tk_prog(), X_OK) != 0) skip();
  size_t cap = 64 * 1024, n = 0;
  char *t = malloc(cap);
  assert_non_null(t);
  n += (size_t)snprintf(t + n, cap - n, "v 0 0 0\nv 1000 1000 1000\n");
  for (int k = 0; k < 300; k++)                 /* 1e-6 across: one grid point once rounded */
    n += (size_t)snprintf(t + n, cap - n, "v %d 0 0\nv %d.000001 0 0\nv %d 0.000001 0\n",
                          3 * k, 3 * k, 3 * k);
  for (int k = 0; k < 300; k++)                 /* lines 903 .. 1202 */
    n += (size_t)snprintf(t + n, cap - n, "f %d %d %d\n", 3 + 3 * k, 4 + 3 * k, 5 + 3 * k);
  n += (size_t)snprintf(t + n, cap - n, "v 0 0 5\nv 10 10 5\nv 10 0 5\nv 0 10 5\n"
                                        "f 903 904 905 906\n");     /* a bow-tie: line 1207 */
  write_file(f, "warn.obj", t, n);
  free(t);
  char scene[300], errp[300];
  FILE *e = render_refused(f, "warn", scene, errp);
  char line[600], want[600];
  for (int k = 0; k < 300; k++) {
    assert_non_null(fgets(line, sizeof line, e));
    snprintf(want, sizeof want, "%s:%d: warning: face %d degenerate after rounding; dropped\n",
             scene, 903 + k, k + 1);
    if (strcmp(line, want) != 0) fail_msg("warning %d: %s", k + 1, line);
  }
  assert_non_null(fgets(line, sizeof line, e));
  snprintf(want, sizeof want, "%s:1207: face 301 is not simple in the file", scene);
  if (strncmp(line, want, strlen(want)) != 0) fail_msg("error: %s", line);
  assert_null(fgets(line, sizeof line, e));
  fclose(e);
  unlink(errp);
}

/* ---- line ends and the byte order mark --------------------------------------------------- */

static void same_scene(const struct scene *a, const struct scene *b)
{
  assert_int_equal(a->nv, b->nv);
  assert_int_equal(a->nf, b->nf);
  for (int i = 0; i < a->nv; i++) {
    assert_int_equal(a->v[i].x, b->v[i].x);
    assert_int_equal(a->v[i].y, b->v[i].y);
    assert_int_equal(a->v[i].z, b->v[i].z);
    assert_int_equal(a->v[i].line, b->v[i].line);
  }
  for (int k = 0; k < a->nf; k++) {
    assert_int_equal(a->f[k].id, b->f[k].id);
    assert_int_equal(a->f[k].line, b->f[k].line);
    assert_int_equal(a->f[k].ring_start[a->f[k].nring], b->f[k].ring_start[b->f[k].nring]);
    for (int q = 0; q < a->f[k].ring_start[a->f[k].nring]; q++)
      assert_int_equal(a->f[k].vidx[q], b->f[k].vidx[q]);
  }
}

/* Replace every "\n" of text by `nl` (and prefix `head`). */
static char *rewrite(const char *text, const char *head, const char *nl, size_t *len)
{
  struct text t = { 0 };
  tprintf(&t, "%s", head);
  for (const char *p = text; *p; p++) {
    if (*p == '\n') tprintf(&t, "%s", nl);
    else tprintf(&t, "%c", *p);
  }
  *len = t.n;
  return t.s;
}

static void line_ends(void **state)
{
  struct fx *f = *state;
  static const char *const base[3] = {
    "# a cube's three faces\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
    "v 1 1 1\nv 0 1 1\n\nf 1 2 3 4\nf 1 2 6 5 # the bottom\nf 2 3 7 6\n",
    "OFF\n# comment\n8 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 1 2 3\n4 0 1 5 4\n\n4 1 2 6 5\n",
    "# the same reader serves .s74\nview 0 0 -100\nwindow -10 -10 10 10\nvertex 1 0 0 0\n"
    "vertex 2 5 0 0\nvertex 3 0 5 0\nvertex 4 5 5 9\nface 1 1 2 3\n\nface 2 2 3 4 # x\n"
    "face 3 1 2 4\n",
  };
  static const char *const kind[3] = { "obj", "off", "s74" };
  static const char *const nl[3] = { "\r\n", "\r", "\n" };
  for (int k = 0; k < 3; k++) {
    char name[32];
    snprintf(name, sizeof name, "lf.%s", kind[k]);
    write_file(f, name, base[k], strlen(base[k]));
    struct scene *ref = NULL;
    struct t74_error err = { 0 };
    if (scene_load(f->path, &on_axis, &ref, &err)) fail_msg("%s", err.msg);
    assert_int_equal(ref->nf, 3);
    assert_int_equal(ref->warnings, 0);
    for (int bom = 0; bom < 2; bom++)
      for (int e = 0; e < 3; e++) {
        size_t len;
        char *t = rewrite(base[k], bom ? "\xEF\xBB\xBF" : "", nl[e], &len);
        snprintf(name, sizeof name, "v%d%d.%s", bom, e, kind[k]);
        write_file(f, name, t, len);
        free(t);
        struct scene *s = NULL;
        memset(&err, 0, sizeof err);
        if (scene_load(f->path, &on_axis, &s, &err))
          fail_msg("%s, bom %d, line end %d: %s", kind[k], bom, e, err.msg);
        same_scene(ref, s);
        scene_free(s);
      }
    scene_free(ref);
  }
}

/* ---- the split of a face made non-planar by rounding ------------------------------------ */

/* A comb: the outline of a U (the notch from above), x 0..3, y 0..3, notch x 1..2, y 1..3.
   z_bump moves vertex 3 off the plane by that much in the file. */
static char *comb_obj(double z_bump, int rot, int rev, size_t *len)
{
  static const double xy[8][2] = { { 0, 0 }, { 3, 0 }, { 3, 3 }, { 2, 3 },
                                   { 2, 1 }, { 1, 1 }, { 1, 3 }, { 0, 3 } };
  struct text t = { 0 };
  for (int k = 0; k < 8; k++)
    tprintf(&t, "v %g %g %.9g\n", xy[k][0], xy[k][1], k == 3 ? z_bump : 0.0);
  tprintf(&t, "v -1 -1 -1.5\nv 4 4 0.5\n");     /* unused: fix the box and the scale */
  tprintf(&t, "f");
  for (int k = 0; k < 8; k++) {
    int at = rev ? (rot - k + 16) % 8 : (rot + k) % 8;
    tprintf(&t, " %d", at + 1);
  }
  tprintf(&t, "\n");
  *len = t.n;
  return t.s;
}

static struct scene *load_or_fail(struct fx *f, const char *name, const char *text, size_t len)
{
  write_file(f, name, text, len);
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  if (scene_load(f->path, &on_axis, &s, &err)) fail_msg("%s: %s", name, err.msg);
  return s;
}

static int int_cmp(const void *a, const void *b)
{
  int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

static int tri_cmp(const void *a, const void *b)
{
  const int *x = a, *y = b;
  for (int k = 0; k < 3; k++) if (x[k] != y[k]) return x[k] < y[k] ? -1 : 1;
  return 0;
}

/* The triangles of s (sorted corners, sorted list), n of them at most 16. */
static int triangles(const struct scene *s, int out[16][3])
{
  assert_true(s->nf <= 16);
  for (int k = 0; k < s->nf; k++) {
    assert_int_equal(s->f[k].ring_start[1], 3);
    for (int q = 0; q < 3; q++) out[k][q] = s->f[k].vidx[q];
    qsort(out[k], 3, sizeof out[k][0], int_cmp);
  }
  qsort(out, (size_t)s->nf, sizeof out[0], tri_cmp);
  return s->nf;
}

static void concave_nonplanar_keeps_notch(void **state)
{
  struct fx *f = *state;
  size_t len;
  char *t = comb_obj(0, 0, 0, &len);
  struct scene *flat = load_or_fail(f, "flat.obj", t, len);
  free(t);
  assert_int_equal(flat->nf, 1);                 /* planar: one concave face */
  assert_int_equal(flat->warnings, 0);
  /* 0.001 of 5 is 2.6 grid units: vertex 4 leaves the plane once rounded */
  t = comb_obj(0.001, 0, 0, &len);
  struct scene *bent = load_or_fail(f, "bent.obj", t, len);
  free(t);
  assert_int_equal(bent->warnings, 1);           /* "not planar after rounding; split" */
  assert_int_equal(bent->nf, 6);                 /* 8 corners: 6 triangles */
  for (int k = 0; k < bent->nf; k++) assert_int_equal(bent->f[k].id, 1);
  int ref[16][3];
  int nref = triangles(bent, ref);
  for (int cell = 3; cell <= 4; cell++) {
    size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
    uint16_t *a = calloc(n, sizeof *a), *b = calloc(n, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    struct t74_error err = { 0 };
    assert_int_equal(mr_render_ids(flat, cell, a, &err), T74_OK);
    assert_int_equal(mr_render_ids(bent, cell, b, &err), T74_OK);
    long lit = 0;
    for (size_t k = 0; k < n; k++) lit += a[k] != 0;
    assert_true(lit > (long)n / 10);
    if (mr_diff(a, b, n)) fail_msg("cell %d: %ld of %ld points differ from the planar face",
                                   cell, mr_diff(a, b, n), lit);
    /* the notch's middle (file x 1.5, y 2.5) is empty, the arms beside it are not; the
       box is x, y -1..4 (scale 2560, centre 1.5), z' = 1280 (projected by 32000/33280) */
    int W = pat_grid_w(cell), H = pat_grid_h(cell);
    static const double fxs[3] = { 1.5, 0.5, 2.5 };
    for (int q = 0; q < 3; q++) {
      double px = (fxs[q] - 1.5) * 2560 * 32000 / 33280, py = (2.5 - 1.5) * 2560 * 32000 / 33280;
      int i = (int)floor((px - flat->window[0]) / (flat->window[2] - flat->window[0]) * W);
      int j = (int)floor((flat->window[3] - py) / (flat->window[3] - flat->window[1]) * H);
      assert_in_range(i, 0, W - 1);
      assert_in_range(j, 0, H - 1);
      assert_int_equal(b[(size_t)j * (size_t)W + (size_t)i], q == 0 ? 0 : 1);
    }
    free(a);
    free(b);
  }
  /* the same triangles for every way the ring is written */
  for (int rot = 0; rot < 8; rot++)
    for (int rev = 0; rev < 2; rev++) {
      t = comb_obj(0.001, rot, rev, &len);
      struct scene *s = load_or_fail(f, "ring.obj", t, len);
      free(t);
      int got[16][3];
      assert_int_equal(triangles(s, got), nref);
      if (memcmp(got, ref, sizeof got[0] * (size_t)nref) != 0)
        fail_msg("ring rotated by %d%s: other triangles", rot, rev ? ", reversed" : "");
      scene_free(s);
    }
  scene_free(flat);
  scene_free(bent);
}

/* An hourglass whose waist (vertices 3 and 6, 0.00004 apart) rounds onto one grid point:
   the face is no longer simple on the grid, so it is split into triangles in the file's
   coordinates (warning), every one numbered 1, covering what its two lobes cover. */
static void rounding_pinch_split(void **state)
{
  struct fx *f = *state;
  static const char pinch[] =
    "v 0 0 0\nv 1 0 0\nv 0.50002 0.5 0\nv 1 1 0\nv 0 1 0\nv 0.49998 0.5 0\nv 0 0 1\n"
    "f 1 2 3 4 5 6\n";
  static const char lobes[] =
    "v 0 0 0\nv 1 0 0\nv 0.50002 0.5 0\nv 1 1 0\nv 0 1 0\nv 0.49998 0.5 0\nv 0 0 1\n"
    "f 1 2 3 6\nf 6 3 4 5\n";
  struct scene *a = load_or_fail(f, "pinch.obj", pinch, sizeof pinch - 1);
  struct scene *b = load_or_fail(f, "lobes.obj", lobes, sizeof lobes - 1);
  assert_true(a->warnings >= 1);
  assert_true(a->nf >= 2);
  for (int k = 0; k < a->nf; k++) assert_int_equal(a->f[k].id, 1);
  for (int cell = 3; cell <= 4; cell++) {
    size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
    uint16_t *ia = calloc(n, sizeof *ia), *ib = calloc(n, sizeof *ib);
    assert_non_null(ia);
    assert_non_null(ib);
    struct t74_error err = { 0 };
    assert_int_equal(mr_render_ids(a, cell, ia, &err), T74_OK);
    assert_int_equal(mr_render_ids(b, cell, ib, &err), T74_OK);
    long lit = 0, differ = 0;
    for (size_t k = 0; k < n; k++) {
      lit += ib[k] != 0;
      differ += (ia[k] != 0) != (ib[k] != 0);
    }
    assert_true(lit > (long)n / 20);
    if (differ > 0) fail_msg("cell %d: %ld of %ld points differ from the two lobes", cell, differ, lit);
    free(ia);
    free(ib);
  }
  scene_free(a);
  scene_free(b);
}

/* A square with a vertex in the middle of every side, bent off its plane: the straight
   vertices stay corners of the triangles (no vertex lost, no crack for a neighbour that
   shares it), and the picture is that of the flat square. */
static void straight_vertices_kept(void **state)
{
  struct fx *f = *state;
  static const char flat[] =
    "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 2 2 0\nv 1 2 0\nv 0 2 0\nv 0 1 0\n"
    "v -1 -1 -2\nv 3 3 1\nf 1 2 3 4 5 6 7 8\n";
  static const char bent[] =
    "v 0 0 0\nv 1 0 0\nv 2 0 0.001\nv 2 1 0\nv 2 2 0\nv 1 2 0\nv 0 2 0.0007\nv 0 1 0\n"
    "v -1 -1 -2\nv 3 3 1\nf 8 1 2 3 4 5 6 7\n";
  struct scene *a = load_or_fail(f, "sq.obj", flat, sizeof flat - 1);
  struct scene *b = load_or_fail(f, "sqb.obj", bent, sizeof bent - 1);
  assert_int_equal(a->nf, 1);
  assert_int_equal(b->warnings, 1);
  assert_int_equal(b->nf, 6);                    /* 8 corners, 6 triangles, none empty */
  int used[8] = { 0 };
  for (int k = 0; k < b->nf; k++)
    for (int q = 0; q < 3; q++) {
      assert_in_range(b->f[k].vidx[q], 0, 7);
      used[b->f[k].vidx[q]]++;
    }
  for (int v = 0; v < 8; v++) assert_true(used[v] > 0);
  for (int cell = 3; cell <= 4; cell++) {
    size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
    uint16_t *x = calloc(n, sizeof *x), *y = calloc(n, sizeof *y);
    assert_non_null(x);
    assert_non_null(y);
    struct t74_error err = { 0 };
    assert_int_equal(mr_render_ids(a, cell, x, &err), T74_OK);
    assert_int_equal(mr_render_ids(b, cell, y, &err), T74_OK);
    assert_int_equal(mr_diff(x, y, n), 0);
    free(x);
    free(y);
  }
  scene_free(a);
  scene_free(b);
}

/* Found by fuzz_obj: three faces of a cube's corner pierced by a fourth. Face 10 is in
   front of face 6 at points (46..48, 53) of the cell-4 grid (exact plane depths: 1.0322
   against 1.0334 .. 1.0381 of the way to the plane z = 0); written in file order the
   Visible Surface Procedure kept face 6 in front there, because face 9, through which it
   had been compared with face 10, had left the covering set. Both orders must show 10. */
static void pierced_corner_front(void **state)
{
  (void)state;
  for (int rev = 0; rev < 2; rev++) {
    struct scene *s = NULL;
    struct t74_error err = { 0 };
    if (scene_load("tests/data/import/pierced_corner.s74", NULL, &s, &err)) fail_msg("%s", err.msg);
    if (rev) mr_reverse(s);
    size_t n = (size_t)pat_grid_w(4) * (size_t)pat_grid_h(4);
    uint16_t *ids = calloc(n, sizeof *ids);
    assert_non_null(ids);
    assert_int_equal(mr_render_ids(s, 4, ids, &err), T74_OK);
    for (int i = 46; i <= 48; i++)
      assert_int_equal(ids[53 * (size_t)pat_grid_w(4) + (size_t)i], 10);
    free(ids);
    scene_free(s);
  }
}

/* ---- order independence ---------------------------------------------------------------- */

struct mesh { double *v; int nv, capv; int *idx, nidx, capidx; int *fs; int nf, capf; };

static void m_vertex(struct mesh *m, double x, double y, double z)
{
  if (m->nv == m->capv) {
    m->capv = m->capv ? 2 * m->capv : 256;
    m->v = realloc(m->v, (size_t)m->capv * 3 * sizeof *m->v);
    assert_non_null(m->v);
  }
  m->v[3 * m->nv] = x; m->v[3 * m->nv + 1] = y; m->v[3 * m->nv + 2] = z;
  m->nv++;
}

static void m_face(struct mesh *m, int n, const int *vi)
{
  if (m->nf + 2 > m->capf) {
    m->capf = m->capf ? 2 * m->capf : 256;
    m->fs = realloc(m->fs, (size_t)m->capf * sizeof *m->fs);
    assert_non_null(m->fs);
  }
  if (m->nidx + n > m->capidx) {
    m->capidx = (m->capidx + n) * 2;
    m->idx = realloc(m->idx, (size_t)m->capidx * sizeof *m->idx);
    assert_non_null(m->idx);
  }
  if (m->nf == 0) m->fs[0] = 0;
  memcpy(m->idx + m->nidx, vi, (size_t)n * sizeof *vi);
  m->nidx += n;
  m->fs[++m->nf] = m->nidx;
}

static void m_free(struct mesh *m) { free(m->v); free(m->idx); free(m->fs); }

static double unit(sg_rng *r) { return (double)(sg_next(r) >> 11) / 9007199254740992.0; }

/* Turn p by angles a (about x) and b (about y), scale by s, move to c. */
static void place(double p[3], double a, double b, double s, const double c[3])
{
  double y = p[1] * cos(a) - p[2] * sin(a), z = p[1] * sin(a) + p[2] * cos(a);
  double x = p[0] * cos(b) - z * sin(b);
  z = p[0] * sin(b) + z * cos(b);
  p[0] = c[0] + s * x; p[1] = c[1] + s * y; p[2] = c[2] + s * z;
}

/* One object of a generated mesh: a torus, a sphere, a box or a terrain (quads that are
   not planar), turned and placed at random. */
static void m_object(struct mesh *m, sg_rng *r)
{
  int kind = (int)(sg_next(r) % 4), base = m->nv;
  double a = unit(r) * 6.3, b = unit(r) * 6.3, s = 0.6 + 1.4 * unit(r);
  double c[3] = { unit(r) * 8 - 4, unit(r) * 8 - 4, unit(r) * 8 - 4 };
  if (kind == 0) {
    for (int i = 0; i < 8; i++) {
      double p[3] = { (i & 1) * 2 - 1, (i >> 1 & 1) * 2 - 1, (i >> 2 & 1) * 2 - 1 };
      place(p, a, b, s, c);
      m_vertex(m, p[0], p[1], p[2]);
    }
    static const int q[6][4] = { { 0, 1, 3, 2 }, { 4, 6, 7, 5 }, { 0, 4, 5, 1 },
                                 { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 5, 7, 3 } };
    for (int k = 0; k < 6; k++) {
      int vi[4] = { base + q[k][0], base + q[k][1], base + q[k][2], base + q[k][3] };
      m_face(m, 4, vi);
    }
  } else if (kind == 3) {
    int n = 3 + (int)(sg_next(r) % 6);
    for (int i = 0; i <= n; i++)
      for (int j = 0; j <= n; j++) {
        double p[3] = { 2.0 * i / n - 1, 0.6 * unit(r) - 0.3, 2.0 * j / n - 1 };
        place(p, a, b, s, c);
        m_vertex(m, p[0], p[1], p[2]);
      }
    for (int i = 0; i < n; i++)
      for (int j = 0; j < n; j++) {
        int A = base + i * (n + 1) + j, B = A + n + 1, C = B + 1, D = A + 1;
        int vi[4] = { A, B, C, D };
        if (sg_next(r) % 3) m_face(m, 4, vi);
        else { int t1[3] = { A, B, C }, t2[3] = { A, C, D }; m_face(m, 3, t1); m_face(m, 3, t2); }
      }
  } else {
    int nu = 4 + (int)(sg_next(r) % 7), nv = 4 + (int)(sg_next(r) % 5);
    for (int i = 0; i < nu; i++)
      for (int j = 0; j < nv; j++) {
        double u = 2 * PI * i / nu, v = 2 * PI * j / nv, p[3];
        if (kind == 1) {
          p[0] = (2 + cos(v)) * cos(u); p[1] = (2 + cos(v)) * sin(u); p[2] = sin(v);
        } else {
          double th = PI * (j + 0.5) / nv;
          p[0] = sin(th) * cos(u); p[1] = sin(th) * sin(u); p[2] = cos(th);
        }
        place(p, a, b, s, c);
        m_vertex(m, p[0], p[1], p[2]);
      }
    for (int i = 0; i < nu; i++)
      for (int j = 0; j < (kind == 1 ? nv : nv - 1); j++) {
        int vi[4] = { base + i * nv + j, base + ((i + 1) % nu) * nv + j,
                      base + ((i + 1) % nu) * nv + (j + 1) % nv, base + i * nv + (j + 1) % nv };
        m_face(m, 4, vi);
      }
  }
}

/* A scenegen scene's faces without holes, moved off the integer grid (scaled by 1.37). */
static int m_from_scenegen(struct mesh *m, sg_family fam, uint64_t seed)
{
  ref_scene rs;
  memset(&rs, 0, sizeof rs);
  char e[200];
  if (sg_generate(fam, seed, &rs, e, sizeof e)) return 0;
  for (int v = 0; v < rs.nv; v++)
    m_vertex(m, 1.37 * (double)rs.v[v].x + 0.3, 1.37 * (double)rs.v[v].y,
             -1.37 * (double)rs.v[v].z);
  for (int k = 0; k < rs.nf; k++)
    if (rs.f[k].nring == 1) m_face(m, rs.f[k].ring_len[0], rs.f[k].vi);
  sg_free(&rs);
  return m->nf > 0;
}

/* Write m: faces in the order perm (file position -> face), each ring rotated by rot and
   reversed when rev (1 for all, 0 for none, 2 for every other face). */
static char *m_write(const struct mesh *m, const char *kind, const int *perm, int rot, int rev,
                     size_t *len)
{
  struct text t = { 0 };
  bool off = strcmp(kind, "off") == 0;
  if (off) tprintf(&t, "OFF\n%d %d 0\n", m->nv, m->nf);
  for (int v = 0; v < m->nv; v++)
    tprintf(&t, "%s%.17g %.17g %.17g\n", off ? "" : "v ", m->v[3 * v], m->v[3 * v + 1],
            m->v[3 * v + 2]);
  for (int q = 0; q < m->nf; q++) {
    int k = perm[q], b = m->fs[k], n = m->fs[k + 1] - b;
    bool back = rev == 1 || (rev == 2 && q % 2);
    int start = (rot * (k + 1)) % n;
    if (off) tprintf(&t, "%d", n); else tprintf(&t, "f");
    for (int i = 0; i < n; i++) {
      int at = back ? (start - i + 2 * n) % n : (start + i) % n;
      tprintf(&t, " %d", m->idx[b + at] + (off ? 0 : 1));
    }
    tprintf(&t, "\n");
  }
  *len = t.n;
  return t.s;
}

/* The imported scene s written as .s74 (its grid coordinates, ids, camera). NULL when a
   face number is used by more than one face (a face was split). */
static char *scene_as_s74(const struct scene *s, size_t *len)
{
  for (int a = 0; a < s->nf; a++)
    for (int b = a + 1; b < s->nf; b++)
      if (s->f[a].id == s->f[b].id) return NULL;
  struct text t = { 0 };
  tprintf(&t, "view %d %d %d\nwindow %d %d %d %d\n", s->view[0], s->view[1], s->view[2],
          s->window[0], s->window[1], s->window[2], s->window[3]);
  if (s->has_light) tprintf(&t, "light %d %d %d\n", s->light[0].v[0], s->light[0].v[1], s->light[0].v[2]);
  for (int v = 0; v < s->nv; v++)
    tprintf(&t, "vertex %d %d %d %d\n", v + 1, s->v[v].x, s->v[v].y, s->v[v].z);
  for (int k = s->nf - 1; k >= 0; k--) {          /* listed backwards, too */
    tprintf(&t, "face %d", s->f[k].id);
    for (int q = 0; q < s->f[k].ring_start[1]; q++) tprintf(&t, " %d", s->f[k].vidx[q] + 1);
    tprintf(&t, "\n");
  }
  *len = t.n;
  return t.s;
}

struct order_totals { long scenes, renders, points, s74, split_faces; };

/* Render m in every writing and compare; fails at the first difference. */
static void check_orders(struct fx *f, const struct mesh *m, const char *what,
                         struct order_totals *tot)
{
  static const char *const kinds[2] = { "obj", "off" };
  int *perm = malloc((size_t)m->nf * sizeof *perm);
  int *inv = malloc((size_t)(m->nf + 1) * sizeof *inv);
  assert_non_null(perm);
  assert_non_null(inv);
  for (int ki = 0; ki < 2; ki++)
    for (int cell = 3; cell <= 4; cell++) {
      size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
      uint16_t *ref = calloc(n, sizeof *ref), *got = calloc(n, sizeof *got);
      assert_non_null(ref);
      assert_non_null(got);
      struct scene *base = NULL;
      for (int var = 0; var < 4; var++) {
        sg_rng r = { 991 + (uint64_t)var };
        for (int q = 0; q < m->nf; q++) perm[q] = var == 1 ? m->nf - 1 - q : q;
        if (var == 3)
          for (int q = m->nf - 1; q > 0; q--) {
            int j = (int)(sg_next(&r) % (uint64_t)(q + 1)), tmp = perm[q];
            perm[q] = perm[j];
            perm[j] = tmp;
          }
        size_t len;
        char *text = m_write(m, kinds[ki], perm, var == 3 ? 1 : 0, var == 2 ? 1 : var == 3 ? 2 : 0,
                             &len);
        char name[32];
        snprintf(name, sizeof name, "order.%s", kinds[ki]);
        write_file(f, name, text, len);
        free(text);
        struct scene *s = NULL;
        struct t74_error err = { 0 };
        int st = scene_load(f->path, &on_axis, &s, &err);
        if (st) fail_msg("%s, %s writing %d: %s", what, kinds[ki], var, err.msg);
        uint16_t *ids = var == 0 ? ref : got;
        memset(&err, 0, sizeof err);
        st = mr_render_ids(s, cell, ids, &err);
        if (st) fail_msg("%s, %s writing %d, cell %d: render status %d: %s", what, kinds[ki],
                         var, cell, st, err.msg);
        tot->renders++;
        if (var > 0) {
          for (int q = 0; q < m->nf; q++) inv[q + 1] = perm[q] + 1;   /* file number -> face */
          for (size_t k = 0; k < n; k++) if (got[k]) got[k] = (uint16_t)inv[got[k]];
          long d = mr_diff(ref, got, n);
          tot->points += (long)n;
          if (d) fail_msg("%s, %s, cell %d: %ld points differ when written in way %d "
                          "(1 faces reversed, 2 rings reversed, 3 shuffled and rotated)",
                          what, kinds[ki], cell, d, var);
          scene_free(s);
        } else {
          base = s;
          uint32_t last = 0;
          for (int a = 0; ki == 0 && cell == 3 && a < s->nf; a++) {
            if (a > 0 && s->f[a].id == s->f[a - 1].id && s->f[a].id != last) {
              tot->split_faces++;
              last = s->f[a].id;
            }
          }
        }
      }
      /* the same grid geometry as .s74, where every number is one face */
      size_t len;
      char *text = scene_as_s74(base, &len);
      if (text) {
        write_file(f, "order.s74", text, len);
        free(text);
        struct scene *s = NULL;
        struct t74_error err = { 0 };
        if (scene_load(f->path, &on_axis, &s, &err)) fail_msg("%s as .s74: %s", what, err.msg);
        assert_int_equal(mr_render_ids(s, cell, got, &err), T74_OK);
        long d = mr_diff(ref, got, n);
        if (d) fail_msg("%s, cell %d: %ld points differ from the same geometry as .s74", what,
                        cell, d);
        tot->s74++;
        tot->points += (long)n;
        scene_free(s);
      }
      scene_free(base);
      free(ref);
      free(got);
    }
  tot->scenes++;
  free(perm);
  free(inv);
}

static void order_independent(void **state)
{
  struct fx *f = *state;
  struct order_totals tot = { 0 };
  for (uint64_t seed = 1; seed <= 24; seed++) {
    struct mesh m = { 0 };
    sg_rng r = { seed * 7919 };
    int objects = 1 + (int)(seed % 4);
    for (int o = 0; o < objects; o++) m_object(&m, &r);
    char what[64];
    snprintf(what, sizeof what, "mesh seed %llu", (unsigned long long)seed);
    check_orders(f, &m, what, &tot);
    m_free(&m);
  }
  static const sg_family fams[] = { SG_BOXES, SG_TRIANGLES, SG_COMBS, SG_STARS, SG_PIERCED };
  for (size_t fi = 0; fi < sizeof fams / sizeof *fams; fi++)
    for (uint64_t seed = 1; seed <= 6; seed++) {
      struct mesh m = { 0 };
      if (!m_from_scenegen(&m, fams[fi], seed)) { m_free(&m); continue; }
      char what[64];
      snprintf(what, sizeof what, "%s seed %llu", sg_family_name(fams[fi]),
               (unsigned long long)seed);
      check_orders(f, &m, what, &tot);
      m_free(&m);
    }
  printf("order: %ld meshes, %ld renders, %ld points compared, %ld compared with .s74, "
         "%ld faces split\n", tot.scenes, tot.renders, tot.points, tot.s74, tot.split_faces);
  assert_true(tot.scenes >= 50);
  assert_true(tot.s74 > 0);
  assert_true(tot.split_faces > 0);
}

/* The same through the command: `--dump ids` of a mesh and of the mesh written with its
   faces and rings reversed agree point for point, face numbers mapped (an outside check:
   the file is what a user would give, the picture what a user would get). */
static void command_dump_ids_reversed(void **state)
{
  struct fx *f = *state;
  if (access(tk_prog(), X_OK) != 0) skip();
  struct mesh m = { 0 };
  sg_rng r = { 4242 };
  for (int o = 0; o < 3; o++) m_object(&m, &r);
  int *perm = malloc((size_t)m.nf * sizeof *perm);
  assert_non_null(perm);
  uint16_t *ids[2] = { NULL, NULL };
  int w = 0, h = 0;
  for (int var = 0; var < 2; var++) {
    for (int q = 0; q < m.nf; q++) perm[q] = var ? m.nf - 1 - q : q;
    size_t len;
    char *text = m_write(&m, "obj", perm, 0, var, &len);
    char name[32], scene[300], dump[300], log[300], cmd[1400], e[200];
    snprintf(name, sizeof name, "cmd%d.obj", var);
    write_file(f, name, text, len);
    free(text);
    snprintf(scene, sizeof scene, "%s", f->path);
    snprintf(dump, sizeof dump, "%s/ids%d.pgm", f->dir, var);
    snprintf(log, sizeof log, "%s/cmd%d.log", f->dir, var);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' --turn 0,0 --cell 3 --core 1000000 --dump ids='%s' 2>'%s'",
             tk_prog(), scene, dump, log);
    int rc = system(cmd);
    assert_true(WIFEXITED(rc));
    if (WEXITSTATUS(rc) != 0) fail_msg("exit %d (see %s)", WEXITSTATUS(rc), log);
    ids[var] = tr_read_pgm16(dump, &w, &h, e, sizeof e);
    if (!ids[var]) fail_msg("%s: %s", dump, e);
    unlink(dump);
    unlink(log);
  }
  assert_int_equal(w, pat_grid_w(3));
  long lit = 0, d = 0;
  for (long k = 0; k < (long)w * h; k++) {
    uint16_t b = ids[1][k] ? (uint16_t)(m.nf + 1 - ids[1][k]) : 0;
    lit += ids[0][k] != 0;
    d += ids[0][k] != b;
  }
  assert_true(lit > 100);
  assert_int_equal(d, 0);
  free(ids[0]);
  free(ids[1]);
  free(perm);
  m_free(&m);
}

/* ---- the fuzz corpora ---------------------------------------------------------------------- */

static int replay_dir(const char *dir, const char *kind, int *rendered)
{
  DIR *d = opendir(dir);
  if (!d) fail_msg("%s: cannot open: %s", dir, strerror(errno));
  struct dirent *e;
  int files = 0;
  *rendered = 0;
  while ((e = readdir(d)) != NULL) {
    if (e->d_name[0] == '.') continue;
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
    FILE *fp = fopen(p, "rb");
    if (!fp) fail_msg("%s: cannot read", p);
    static uint8_t buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf, fp);
    fclose(fp);
    if (strcmp(kind, "pic") == 0) {
      char *path = mr_temp_file(buf, n, "pic");
      assert_non_null(path);
      struct pic *pic = NULL;
      struct t74_error err = { 0 };
      int st = pic_load(path, &pic, &err);
      if (st == T74_OK) {
        assert_in_range(pic_width(pic), 1, PIC_MAX_SIDE);
        assert_in_range(pic_height(pic), 1, PIC_MAX_SIDE);
        assert_in_range(pic_sample(pic, 0, 0, 100, 75), 0, 255);
        pic_free(pic);
        (*rendered)++;
      } else if ((st != T74_EINPUT && st != T74_EIO) || strncmp(err.msg, path, strlen(path)))
        fail_msg("%s: status %d: %s", p, st, err.msg);
      mr_temp_remove(path);
    } else {
      char why[600];
      int r = 0;
      for (int cell = 3; cell <= 4; cell++) {
        if (mr_check(buf, n, kind, cell, &r, why, sizeof why)) fail_msg("%s: %s", p, why);
      }
      *rendered += r;
      if (strcmp(kind, "obj") == 0 || strcmp(kind, "off") == 0) {
        size_t rn;
        uint8_t *rev = strcmp(kind, "obj") == 0 ? mr_obj_reverse_rings(buf, n, &rn)
                                               : mr_off_reverse_rings(buf, n, &rn);
        assert_non_null(rev);
        struct scene *a = NULL, *b = NULL;
        int s1 = mr_load_bytes(buf, n, kind, &a), s2 = mr_load_bytes(rev, rn, kind, &b);
        if ((s1 == 0) != (s2 == 0)) fail_msg("%s: status %d, rings reversed %d", p, s1, s2);
        if (s1 == 0 && !mr_same_picture(a, b, 4)) fail_msg("%s: rings reversed: other picture", p);
        scene_free(a);
        scene_free(b);
        free(rev);
      }
    }
    files++;
  }
  closedir(d);
  return files;
}

/* The text reversals the fuzz targets and the replay use do reverse (and only faces). */
static void text_reversals(void **state)
{
  (void)state;
  static const char obj[] = "v 1 2 3\r\n  f 1 2/5 -1 # c\rfo 4 5 6\nvt 1 2\n";
  static const char off[] = "OFF # x\n3 2 0\n0 0 0\n\n1 0 0\n0 1 0\n3 0 1 2 9 9\r\n4 2 1 0 1\n";
  size_t n;
  uint8_t *r = mr_obj_reverse_rings((const uint8_t *)obj, sizeof obj - 1, &n);
  assert_non_null(r);
  static const char obj_rev[] = "v 1 2 3\r\nf -1 2/5 1\rfo 6 5 4\nvt 1 2\n";
  assert_int_equal(n, sizeof obj_rev - 1);
  assert_memory_equal(r, obj_rev, n);
  free(r);
  r = mr_off_reverse_rings((const uint8_t *)off, sizeof off - 1, &n);
  assert_non_null(r);
  static const char off_rev[] = "OFF # x\n3 2 0\n0 0 0\n\n1 0 0\n0 1 0\n3 2 1 0 9 9\r\n4 1 0 1 2\n";
  assert_int_equal(n, sizeof off_rev - 1);
  assert_memory_equal(r, off_rev, n);
  free(r);
}

/* The line reader's long way: import_next as it was before the one-pass scan (issue 19),
   the line's end found first, then its tokens split. */
enum { RB_END = 1, RB_BLANK = 2, RB_STOP = 4 };
static unsigned char ref_class(char c)
{
  switch (c) {
  case '\0': return RB_END | RB_STOP;
  case '\n': return RB_END;
  case '\r': return RB_END | RB_BLANK;
  case ' ': case '\t': case '\f': case '\v': return RB_BLANK;
  case '#': return RB_STOP;
  default: return 0;
  }
}

static int ref_next(struct import_reader *r)
{
  while (r->pos < r->len) {
    char *start = r->buf + r->pos, *last = r->buf + r->len;
    char *end = start;
    while (!(ref_class(*end) & RB_END)) end++;
    bool nul = end < last && *end == '\0';
    r->pos = (size_t)(end - r->buf) + 1;
    if (end < last && *end == '\r' && end + 1 < last && end[1] == '\n') r->pos++;
    r->line = ++r->nlines;
    if (nul) return T74_EINPUT;
    *end = '\0';
    r->ntok = 0;
    char *p = start;
    for (;;) {
      while (ref_class(*p) & RB_BLANK) p++;
      if (ref_class(*p) & RB_STOP) { *p = '\0'; break; }
      if (r->ntok == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 16;
        r->tok = realloc(r->tok, (size_t)r->cap * sizeof *r->tok);
        assert_non_null(r->tok);
      }
      r->tok[r->ntok++] = p;
      while (!(ref_class(*p) & (RB_BLANK | RB_STOP))) p++;
      if (ref_class(*p) & RB_STOP) { *p = '\0'; break; }
      *p++ = '\0';
    }
    if (r->ntok > 0) return 1;
  }
  r->ntok = 0;
  return 0;
}

/* A reader over text[0..len) as import_open makes one (NUL after the last byte). */
static void reader_on(struct import_reader *r, const char *text, size_t len)
{
  memset(r, 0, sizeof *r);
  r->file = "t.obj";
  r->buf = malloc(len + 1);
  assert_non_null(r->buf);
  memcpy(r->buf, text, len);
  r->buf[len] = '\0';
  r->len = len;
}

/* import_next gives, line by line, the tokens, line numbers and refusals (a NUL in a
   line) of the long way, on random text of blanks, line ends (LF, CR, CR LF), NULs,
   comments and words, and on a few written out. */
static void line_reader_as_long_way(void **state)
{
  (void)state;
  static const char alpha[] = { ' ', '\t', '\r', '\n', '\0', '#', 'v', '1', '-', '\f', '\v', 'f' };
  static const char *const fixed[] = { "", "\n", "v 1 2 3\r\n  f 1 2/5 -1 # c\rfo 4 5 6\nvt 1 2\n",
                                       "#\n# a b\n  \t\n a#b c\n", "a\r\r\nb\n\rc", "x y\0z\nw" };
  uint32_t seed = 7;
  for (int trial = 0; trial < 3000; trial++) {
    char text[160];
    size_t len;
    if (trial < 6) {
      len = strlen(fixed[trial]) + (trial == 5 ? 4 : 0);
      memcpy(text, fixed[trial], len);
    } else {
      len = (size_t)(trial % 150);
      for (size_t k = 0; k < len; k++) {
        seed = seed * 1103515245u + 12345u;
        uint32_t u = (seed >> 8) % 40;
        text[k] = u < sizeof alpha ? alpha[u] : (char)('a' + u % 5);   /* words mostly */
      }
    }
    struct import_reader a, b;
    reader_on(&a, text, len);
    reader_on(&b, text, len);
    for (;;) {
      struct t74_error err = { 0, "" };
      int sa = import_next(&a, &err), sb = ref_next(&b);
      assert_int_equal(sa, sb);
      assert_int_equal(a.nlines, b.nlines);
      assert_true(a.pos == b.pos);
      if (sa != 1) {
        if (sa) assert_non_null(strstr(err.msg, "NUL byte in the line"));
        break;
      }
      assert_int_equal(a.line, b.line);
      assert_int_equal(a.ntok, b.ntok);
      for (int k = 0; k < a.ntok; k++) assert_string_equal(a.tok[k], b.tok[k]);
    }
    import_close(&a);
    free(b.buf);
    free(b.tok);
  }
}

#define CORPUS(name)                                                                      \
  static void corpus_##name(void **state)                                                 \
  {                                                                                       \
    (void)state;                                                                          \
    int rendered;                                                                         \
    int files = replay_dir("tests/fuzz/corpus_" #name, #name, &rendered);                 \
    printf("corpus_%s: %d files, %d accepted\n", #name, files, rendered);                 \
    assert_true(files > 0);                                                               \
    assert_true(rendered > 0);                                                            \
  }
CORPUS(s74)
CORPUS(obj)
CORPUS(off)
CORPUS(pic)


/* import_real reads plain decimals without strtod (Clinger's fast path): every token must
   give the very double strtod gives, bit for bit, and the same refusals. Tokens at the
   path's edges (15/16 significant digits, 22/23 after the point, leading zeros, signs,
   a bare point) and random ones, where a division rounded differently would show. */
static void real_tokens_as_strtod(void **state)
{
  (void)state;
  static const char *const fixed[] = {
    "0", "-0", "+0", "0.0", "-0.000", "1", "-1", "+17", "1.", ".5", "-.5", "+.25", ".",
    "-", "+", "", "1.2.3", "1e3", "1E-3", "0x1p3", "inf", "-nan", "1,5", "12a", " 1",
    "0.1", "0.2", "0.3", "2.675", "1.0000000000000002", "123456789012345",
    "1234567890123456", "12345678901234.5", "999999999999999", "9999999999999999",
    "0.0000000000000000000001", "0.00000000000000000000001", "00000000000000000000123.5",
    "3.14159265358979", "-2.71828182845904", "0.000000000000000000000", "7.0e0",
    "1.7976931348623157", "4.9406564584124654", "0.1234567890123456789012",
  };
  char *end;
  for (size_t k = 0; k < sizeof fixed / sizeof fixed[0]; k++) {
    double a = 0, b = strtod(fixed[k], &end);
    bool want = end != fixed[k] && *end == '\0' && isfinite(b);
    bool got = import_real(fixed[k], &a);
    if (got != want) fail_msg("token `%s`: import_real says %d, strtod %d", fixed[k], got, want);
    if (want && memcmp(&a, &b, sizeof a) != 0)
      fail_msg("token `%s`: %a, strtod %a", fixed[k], a, b);
  }
  uint64_t x = 0x9e3779b97f4a7c15u;
  char tok[40];
  for (int k = 0; k < 200000; k++) {
    x ^= x << 13; x ^= x >> 7; x ^= x << 17;
    int nd = 1 + (int)(x % 18), point = (int)((x >> 8) % (uint64_t)(nd + 2)) - 1, n = 0;
    if ((x >> 16) & 1) tok[n++] = '-';
    uint64_t y = x;
    for (int d = 0; d < nd; d++) {
      if (d == point) tok[n++] = '.';
      y = y * 6364136223846793005u + 1442695040888963407u;
      tok[n++] = (char)('0' + (y >> 60) % 10);
    }
    tok[n] = '\0';
    double a = 0, b = strtod(tok, &end);
    bool want = end != tok && *end == '\0' && isfinite(b);
    bool got = import_real(tok, &a);
    if (got != want) fail_msg("token `%s`: import_real says %d, strtod %d", tok, got, want);
    if (want && memcmp(&a, &b, sizeof a) != 0) fail_msg("token `%s`: %a, strtod %a", tok, a, b);
  }
}

/* The parts of a face reference are read in place: the forms i, i/t, i//n, i/t/n, a sign,
   and parts of up to 23 bytes (leading zeros) are taken as before (24 bytes are refused:
   BAD_IMPORTS); the indices found are the ones written. */
static void obj_refs_in_place(void **state)
{
  struct fx *f = *state;
  static const char text[] =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\n"
    "f 1/7/9 +2//3 00000000000000000000003/00000000000000000000001/-0000000000000000000001\n"
    "f -3 4/2 -2/-1/+0\n";
  struct scene *s = load_or_fail(f, "refs.obj", text, sizeof text - 1);
  assert_int_equal(s->nf, 2);
  assert_int_equal(s->f[0].ring_start[1], 3);
  assert_int_equal(s->f[0].vidx[0], 0);
  assert_int_equal(s->f[0].vidx[1], 1);
  assert_int_equal(s->f[0].vidx[2], 2);
  assert_int_equal(s->f[1].vidx[0], 1);
  assert_int_equal(s->f[1].vidx[1], 3);
  assert_int_equal(s->f[1].vidx[2], 2);
  scene_free(s);
}

/* The common `v` and `f` lines are read in one pass (obj_fast) when written with single
   blanks; written with tabs the same lines go the general way (tokens, read_xyz,
   obj_ref). Both must give the same scene, or the same refusal with the same line:
   lines at the fast path's edges (runs of blanks and trailing ones, 15 and 16 significant
   digits, leading zeros, signs, a bare point, 9- and 10-digit indices, 32 and 33
   references, a last line without LF, comments, CR LF, slashes, negative indices) and
   bad ones (index 0, too few references, an index past the vertices, a bad number). */
static void obj_fast_as_general(void **state)
{
  struct fx *f = *state;
  static const char *const good[] = {
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n",
    "# c\nv  0.5   -0   +.25  \nv 1. 0 0\nv 0 1 0 \nf  1 2  3  \nf 1 2 3",
    ("v 0.123456789012345 0 0\nv 1.234567890123456 0 0\nv 0 1.0000000000000002 0\n"
     "v 0 0 000000000000000000001\nf 000000001 2 3 4\nf 0000000001 2 3\n"),
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\r\nf 1/1/1 2//2 3\nf -3 -2 -1\nf 1 2 3 # c\n",
    "v 0 0 1e0\nv 1 0 0 1\nv 0 1 0\nv 0 0 0\nf 1 2 3\nf 2 3 4\n",
    /* indices read 8 bytes at a time (digits8): leading zeros, runs of 1 to 7 digits
       with 8 bytes after them, and one of 8 (the loop) */
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 0000001 02 0004 003\n"
     "f 4 2 00000001 3\nf 5 0000004 2\n# eight bytes and more\n"),
  };
  static const char *const bad[] = {
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0.1.2\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0 0 0 0 0 0\nf 1 2 3\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 1234567890\n",
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 -4\n",
  };
  for (int g = 0; g < 2; g++) {
    int n = g == 0 ? (int)(sizeof good / sizeof *good) + 2 : (int)(sizeof bad / sizeof *bad);
    for (int k = 0; k < n; k++) {
      struct text t = { 0 };
      if (g == 0 && k >= (int)(sizeof good / sizeof *good)) {
        /* a face of 32 references (the fast path's most) and one of 33 (the general's) */
        int refs = k == (int)(sizeof good / sizeof *good) ? 32 : 33;
        for (int v = 0; v < refs; v++)
          tprintf(&t, "v %d %d 0\n", (int)lround(1000 * cos(2 * PI * v / refs)),
                  (int)lround(1000 * sin(2 * PI * v / refs)));
        tprintf(&t, "f");
        for (int v = 0; v < refs; v++) tprintf(&t, " %d", v + 1);
        tprintf(&t, "\n");
      } else {
        tprintf(&t, "%s", g == 0 ? good[k] : bad[k]);
      }
      char *tab = malloc(t.n + 1);
      assert_non_null(tab);
      memcpy(tab, t.s, t.n + 1);
      for (size_t q = 0; q < t.n; q++)
        if (tab[q] == ' ') tab[q] = '\t';
      struct scene *s[2] = { NULL, NULL };
      struct t74_error err[2] = { { 0 }, { 0 } };
      int st[2];
      for (int w = 0; w < 2; w++) {
        write_file(f, "fast.obj", w == 0 ? t.s : tab, t.n);
        st[w] = scene_load(f->path, &on_axis, &s[w], &err[w]);
      }
      if (st[0] != st[1] || strcmp(err[0].msg, err[1].msg) != 0 || (g == 0) != (st[0] == 0))
        fail_msg("%s text %d: %d \"%s\" with blanks, %d \"%s\" with tabs", g ? "bad" : "good",
                 k, st[0], err[0].msg, st[1], err[1].msg);
      if (st[0] == 0) same_scene(s[0], s[1]);
      scene_free(s[0]);
      scene_free(s[1]);
      free(tab);
      free(t.s);
    }
  }
}

/* import_round is (double)lround bit for bit: halves (both signs), values beside them,
   signed zeros, the 2^52 edge, and random values at several magnitudes. */
static void round_as_lround(void **state)
{
  (void)state;
  static const double fixed[] = {
    0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
    0.5000000000000001, -0.5000000000000001, 6399.5, -6399.5, 12800.5, 1e-300, -1e-300,
    0x1p52 - 0.5, -(0x1p52 - 0.5), 0x1p52 - 1, 0x1p52, -0x1p52, 0x1p52 + 1, 1e18, -1e18,
    4503599627370495.5, -4503599627370495.5, 0.3, -0.3, 0.7, -0.7,
  };
  for (size_t k = 0; k < sizeof fixed / sizeof *fixed; k++) {
    double a = import_round(fixed[k]), b = (double)lround(fixed[k]);
    if (memcmp(&a, &b, sizeof a) != 0) fail_msg("%a: %a, lround %a", fixed[k], a, b);
  }
  uint64_t x = 0x2545f4914f6cdd1du;
  for (int k = 0; k < 1000000; k++) {
    x ^= x << 13; x ^= x >> 7; x ^= x << 17;
    double v = ldexp((double)(x >> 11) / 9007199254740992.0, (int)(x % 60) - 4);
    if (x & (1u << 5)) v = -v;
    if ((x & 0xc0) == 0) v = floor(v) + 0.5;          /* a half */
    double a = import_round(v), b = (double)lround(v);
    if (memcmp(&a, &b, sizeof a) != 0) fail_msg("%a: %a, lround %a", v, a, b);
  }
}

int main(void)
{
#define LIST_BAD(name, kind, text, line, what) cmocka_unit_test(bad_##name),
  const struct CMUnitTest tests[] = {
    BAD_IMPORTS(LIST_BAD)
    cmocka_unit_test(no_bowtie_below_an_ulp),
    cmocka_unit_test(quad_verdicts_as_scene_check),
    cmocka_unit_test(command_exit_2),
    cmocka_unit_test(command_warnings_in_order),
    cmocka_unit_test(real_tokens_as_strtod),
    cmocka_unit_test(obj_refs_in_place),
    cmocka_unit_test(obj_fast_as_general),
    cmocka_unit_test(round_as_lround),
    cmocka_unit_test(line_ends),
    cmocka_unit_test(concave_nonplanar_keeps_notch),
    cmocka_unit_test(straight_vertices_kept),
    cmocka_unit_test(rounding_pinch_split),
    cmocka_unit_test(pierced_corner_front),
    cmocka_unit_test(order_independent),
    cmocka_unit_test(command_dump_ids_reversed),
    cmocka_unit_test(text_reversals),
    cmocka_unit_test(line_reader_as_long_way),
    cmocka_unit_test(corpus_s74),
    cmocka_unit_test(corpus_obj),
    cmocka_unit_test(corpus_off),
    cmocka_unit_test(corpus_pic),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
