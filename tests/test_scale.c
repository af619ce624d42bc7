/*
** test_scale.c — scenes beyond 16-bit ids (issue 12, docs/scale.md): an import of more
** than 65,535 faces and vertices renders, and right; where a 16-bit output cannot hold
** the answer it is refused with a clear message and no output; .s74 keeps ids 1..65535.
**
** This file contains code to write .obj scenes of many small quads (faces and vertices
** numbered past 65535) in a scratch folder under /tmp, run $TUBE74 (default ./tube74) on
** them as a user would, and check:
**   - the picture of the whole scene is the picture of its two halves put together: a
**     big face at the back (face 1 of every file) and 70,200 small tilted quads in front
**     of it; every point of the whole shows the grey one of the halves shows in front of
**     the back face (the halves, each under 65,536 faces, can be dumped as ids too), and
**     each half shows some of its quads (so the check cannot pass on an empty picture);
**   - `--dump ids` of the whole scene is refused (exit 2, "FILE:LINE:" naming a face
**     above 65535), and neither the dump nor the PNG asked for with it is created, while a
**     half's ids dump holds the face numbers the half's file gives;
**   - a .s74 with vertex id or face id 65536 is refused at its line;
**   - an .off header counting more than the importer's limit is refused at its line;
**   - the Segment Generator on a concave face whose vertex ids are above 65535 keeps
**     those ids and numbers its crossing points above them (no 16-bit wrap), and on a
**     face with ids near 65535 wraps past PBS's '*' onto numbers the face leaves free.
** One render of 70,201 faces takes well under a second; the file has three.
** A standalone cmocka program, run from the repository root.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>

#include "emu/cost.h"
#include "render/geom.h"
#include "render/segment.h"
#include "tests/ref/testkit.h"

static char scratch[64];

static int group_setup(void **state)
{
  (void)state;
  return tk_mkscratch(scratch, sizeof scratch, "/tmp/t74scale.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(scratch);
}

static void path_of(char *buf, size_t n, const char *name)
{
  snprintf(buf, n, "%s/%s", scratch, name);
}

static bool exists(const char *p)
{
  struct stat st;
  return stat(p, &st) == 0;
}

/* ---- the quads scene -------------------------------------------------------------------
   File coordinates are the grid's exactly: two vertices no face uses, (-6400, -6400, 0)
   and (6400, 6400, -12800), make the bounding box 12,800 a side centred on x = y = 0, so
   the importer's scale is 1 and its z is the file's -z (render/import.h). The camera is
   given: --view 0 0 -20000 --window -5000 -3750 5000 3750 --turn 0,0. */

#define QX 300                     /* quads a row */
#define QY 234                     /* rows: 70,200 quads */
#define QPITCH 32
#define QSIZE 20

/* part 0: all quads; part 1: the first half (rows < QY/2); part 2: the rest. */
static void write_quads(const char *path, int part)
{
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "# test_scale: part %d\nv -6400 -6400 0\nv 6400 6400 -12800\n", part);
  /* face 1: the back, flat at z = 2000, covering the window */
  fprintf(f, "v -6000 -6000 -2000\nv 6000 -6000 -2000\nv 6000 6000 -2000\nv -6000 6000 -2000\n");
  int nv = 6;
  fprintf(f, "f 3 4 5 6\n");
  for (int j = 0; j < QY; j++) {
    if ((part == 1 && j >= QY / 2) || (part == 2 && j < QY / 2)) continue;
    for (int i = 0; i < QX; i++) {
      int x0 = -4800 + QPITCH * i, y0 = -3744 + QPITCH * j, z0 = 400 + 10 * ((i + j) % 7);
      /* tilted in x (z grows with x): its own grey, not the back's */
      fprintf(f, "v %d %d %d\nv %d %d %d\nv %d %d %d\nv %d %d %d\n", x0, y0, -z0,
              x0 + QSIZE, y0, -(z0 + QSIZE), x0 + QSIZE, y0 + QSIZE, -(z0 + QSIZE),
              x0, y0 + QSIZE, -z0);
      fprintf(f, "f %d %d %d %d\n", nv + 1, nv + 2, nv + 3, nv + 4);
      nv += 4;
    }
  }
  assert_int_equal(fclose(f), 0);
}

#define CAMERA "--view", "0", "0", "-20000", "--window", "-5000", "-3750", "5000", "3750", "--turn", "0,0"

/* A binary PGM (P5) of W x H samples of 1 or 2 bytes; returns the samples (malloc'd). */
static unsigned *read_pgm(const char *path, int *w, int *h)
{
  size_t n = 0;
  char *b = tk_slurp(path, &n);
  assert_non_null(b);
  int maxval = 0, off = 0;
  assert_int_equal(sscanf(b, "P5 %d %d %d%n", w, h, &maxval, &off), 3);
  off++;                                             /* the one blank after maxval */
  int bytes = maxval > 255 ? 2 : 1;
  size_t cnt = (size_t)*w * (size_t)*h;
  assert_int_equal(n, (size_t)off + cnt * (size_t)bytes);
  unsigned *v = malloc(cnt * sizeof *v);
  assert_non_null(v);
  const unsigned char *p = (const unsigned char *)b + off;
  for (size_t k = 0; k < cnt; k++)
    v[k] = bytes == 2 ? (unsigned)p[2 * k] << 8 | p[2 * k + 1] : p[k];
  free(b);
  return v;
}

static void test_big_import_renders(void **state)
{
  (void)state;
  char whole[128], half[3][128], grey[3][128], ids[3][128], png[128], err[128];
  path_of(whole, sizeof whole, "whole.obj");
  write_quads(whole, 0);
  for (int p = 1; p <= 2; p++) {
    char name[32];
    snprintf(name, sizeof name, "half%d.obj", p);
    path_of(half[p], sizeof half[p], name);
    write_quads(half[p], p);
  }
  for (int p = 0; p <= 2; p++) {
    char name[32];
    snprintf(name, sizeof name, "grey%d.pgm", p);
    path_of(grey[p], sizeof grey[p], name);
    snprintf(name, sizeof name, "ids%d.pgm", p);
    path_of(ids[p], sizeof ids[p], name);
  }
  path_of(png, sizeof png, "whole.png");
  path_of(err, sizeof err, "err.txt");
  char dg[160], di[160];
  snprintf(dg, sizeof dg, "grey=%s", grey[0]);
  assert_int_equal(tk_runl(NULL, err, "render", whole, CAMERA, "--core", "268435456",
                           "--dump", dg, "-o", png, (char *)NULL), 0);
  assert_true(exists(png));
  for (int p = 1; p <= 2; p++) {
    snprintf(dg, sizeof dg, "grey=%s", grey[p]);
    snprintf(di, sizeof di, "ids=%s", ids[p]);
    assert_int_equal(tk_runl(NULL, err, "render", half[p], CAMERA, "--core", "268435456",
                             "--dump", dg, "--dump", di, (char *)NULL), 0);
  }
  int w[3], h[3];
  unsigned *g[3], *id[3];
  for (int p = 0; p <= 2; p++) g[p] = read_pgm(grey[p], &w[p], &h[p]);
  for (int p = 1; p <= 2; p++) {
    int iw, ih;
    id[p] = read_pgm(ids[p], &iw, &ih);
    assert_int_equal(iw, w[p]);
    assert_int_equal(ih, h[p]);
  }
  assert_int_equal(w[0], w[1]); assert_int_equal(w[0], w[2]);
  assert_int_equal(h[0], h[1]); assert_int_equal(h[0], h[2]);
  size_t n = (size_t)w[0] * (size_t)h[0];
  long shown[3] = { 0, 0, 0 };
  unsigned back = 0, quad = 0;
  for (size_t k = 0; k < n; k++) {
    /* the back face (1 in every file) is what a half shows where none of its quads is */
    for (int p = 1; p <= 2; p++) {
      assert_true(id[p][k] >= 1);                    /* the back covers the window */
      if (id[p][k] == 1) { if (!back) back = g[p][k]; assert_int_equal(g[p][k], back); }
      else { if (!quad) quad = g[p][k]; assert_int_equal(g[p][k], quad); shown[p]++; }
    }
    assert_false(id[1][k] > 1 && id[2][k] > 1);      /* the halves do not overlap */
    unsigned want = id[1][k] > 1 ? g[1][k] : g[2][k];
    if (g[0][k] != want)
      fail_msg("point (%zu, %zu): the whole shows grey %u, its halves %u", k % (size_t)w[0],
               k / (size_t)w[0], g[0][k], want);
    shown[0] += id[1][k] > 1 || id[2][k] > 1;
  }
  assert_true(back != quad);                         /* the check can tell them apart */
  assert_true(shown[1] > 500 && shown[2] > 500);     /* each half shows many quads */
  /* the half's ids are its file's face numbers: the second half's quads are 2.. again */
  bool high = false;
  for (size_t k = 0; k < n; k++) high |= id[2][k] > 30000;
  assert_true(high);
  for (int p = 0; p <= 2; p++) free(g[p]);
  for (int p = 1; p <= 2; p++) free(id[p]);
}

/* --dump ids of a picture showing faces above 65535: refused, nothing written. */
static void test_ids_dump_refused(void **state)
{
  (void)state;
  char whole[128], ids[128], png[128], stats[128], err[128];
  path_of(whole, sizeof whole, "whole.obj");
  if (!exists(whole)) write_quads(whole, 0);
  path_of(ids, sizeof ids, "refused.pgm");
  path_of(png, sizeof png, "refused.png");
  path_of(stats, sizeof stats, "refused.json");
  path_of(err, sizeof err, "err2.txt");
  char di[160];
  snprintf(di, sizeof di, "ids=%s", ids);
  assert_int_equal(tk_runl(NULL, err, "render", whole, CAMERA, "--core", "268435456",
                           "--dump", di, "-o", png, "--stats", stats, (char *)NULL), 2);
  assert_false(exists(ids));
  assert_false(exists(png));
  assert_false(exists(stats));
  char *msg = tk_slurp(err, NULL);
  assert_non_null(msg);
  char want[160];
  snprintf(want, sizeof want, "%s:", whole);
  assert_non_null(strstr(msg, want));                /* FILE:LINE: */
  assert_non_null(strstr(msg, "--dump ids"));
  assert_non_null(strstr(msg, "65535"));
  /* the face it names is above 65535 and sits at the line the message gives */
  const char *f = strstr(msg, "face ");
  assert_non_null(f);
  long face = atol(f + 5), line = atol(msg + strlen(want));
  assert_true(face > 65535);
  assert_int_equal(line, 8 + 5 * (face - 1));       /* write_quads: 5 lines a quad */
  free(msg);
}

/* .s74 keeps its ids 1..65535 (CONTRACT.md). */
static void test_s74_ids_stay_16_bit(void **state)
{
  (void)state;
  static const char *const bad[] = {
    "view 0 0 -1000\nwindow -10 -10 10 10\nvertex 65536 0 0 10\n",
    "view 0 0 -1000\nwindow -10 -10 10 10\nvertex 1 0 0 10\nvertex 2 5 0 10\n"
    "vertex 3 0 5 10\nface 65536 1 2 3\n",
  };
  static const int line[] = { 3, 6 };
  for (int k = 0; k < 2; k++) {
    char s74[128], err[128], png[128], want[200];
    path_of(s74, sizeof s74, "big.s74");
    path_of(err, sizeof err, "err3.txt");
    path_of(png, sizeof png, "big.png");
    assert_int_equal(tk_put(s74, bad[k], strlen(bad[k])), 0);
    assert_int_equal(tk_runl(NULL, err, "render", s74, "-o", png, (char *)NULL), 2);
    assert_false(exists(png));
    char *msg = tk_slurp(err, NULL);
    assert_non_null(msg);
    snprintf(want, sizeof want, "%s:%d:", s74, line[k]);
    assert_non_null(strstr(msg, want));
    assert_non_null(strstr(msg, "65535"));
    free(msg);
  }
}

/* An .off header beyond any file the importer reads: refused at its line. */
static void test_absurd_off_count(void **state)
{
  (void)state;
  char off[128], err[128], want[200];
  path_of(off, sizeof off, "huge.off");
  path_of(err, sizeof err, "err4.txt");
  const char *text = "OFF\n# too many\n3 999999999999 0\n0 0 0\n1 0 0\n0 1 0\n";
  assert_int_equal(tk_put(off, text, strlen(text)), 0);
  assert_int_equal(tk_runl(NULL, err, "render", off, (char *)NULL), 2);
  char *msg = tk_slurp(err, NULL);
  assert_non_null(msg);
  snprintf(want, sizeof want, "%s:3:", off);
  assert_non_null(strstr(msg, want));
  free(msg);
}

/* ---- the Segment Generator's crossing numbers ------------------------------------------ */

/* A U, open at the top: concave at (20, 10) and (10, 10); the cut y = 10 crosses the two
   outer sides in their middle, so two new crossing numbers are made. */
static void seg_u(const uint32_t ids[8], uint32_t newnum[2])
{
  static const long long xy[8][2] = { { 0, 0 }, { 30, 0 }, { 30, 30 }, { 20, 30 },
                                      { 20, 10 }, { 10, 10 }, { 10, 30 }, { 0, 30 } };
  struct gpoint pt[8];
  for (int k = 0; k < 8; k++) { pt[k].x = xy[k][0] * GRID_ONE; pt[k].y = xy[k][1] * GRID_ONE; }
  int rs[2] = { 0, 8 };
  struct seg_input in = { 70001, 1, rs, pt, ids, 1 };
  struct seg_result r;
  struct t74_error err;
  memset(&err, 0, sizeof err);
  struct cost c;
  memset(&c, 0, sizeof c);
  assert_int_equal(seg_generate(&in, &r, NULL, NULL, &c, &err), T74_OK);
  assert_true(r.npiece >= 3);
  int nnew = 0;
  for (int i = 0; i < r.npiece; i++)
    for (int k = 0; k < r.piece[i].n; k++) {
      const struct seg_vertex *v = &r.piece[i].v[k];
      if (v->kind == SEGV_ORIG) {
        bool known = false;
        for (int q = 0; q < 8; q++) known |= v->num == ids[q];
        assert_true(known);
      } else {
        for (int q = 0; q < 8; q++) assert_true(v->num != ids[q]);
        if (nnew < 2 && (nnew == 0 || newnum[0] != v->num)) newnum[nnew++] = v->num;
        else assert_true(v->num == newnum[0] || v->num == newnum[1]);
      }
    }
  assert_int_equal(nnew, 2);
  seg_result_free(&r);
}

static void test_segment_wide_ids(void **state)
{
  (void)state;
  uint32_t wide_ids[8] = { 70001, 70002, 99999, 70004, 70005, 70006, 70007, 70008 };
  uint32_t got[2];
  seg_u(wide_ids, got);
  for (int k = 0; k < 2; k++) assert_true(got[k] == 100000 || got[k] == 100001);
  /* ids up to 65534: the numbers pass 65535 (PBS's '*') and 0, then skip 1 and 2 */
  uint32_t near[8] = { 65534, 1, 2, 65533, 4, 65532, 65531, 65530 };
  seg_u(near, got);
  for (int k = 0; k < 2; k++) assert_true(got[k] == 3 || got[k] == 5);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_big_import_renders),
    cmocka_unit_test(test_ids_dump_refused),
    cmocka_unit_test(test_s74_ids_stay_16_bit),
    cmocka_unit_test(test_absurd_off_count),
    cmocka_unit_test(test_segment_wide_ids),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
