/*
** test_points_coarse.c — the points engine's coarse coverage (render/points.c, "Tiles" and
** "Order", issue 19): the tiles that skip the parts of a face proven behind, and the
** nearest-first drawing order, change nothing but the work done.
**
** For every scene: the frame (the face index at every point, and the faces culled) of the
** engine as it runs equals the frame without coarse coverage (struct points' `plain`:
** no tiles, the Mapper's order), and the frame drawn with tiles in shuffled orders
** (`shuffle`). Scenes: every hard family (tests/ref/hardgen.c: coplanar faces, shared
** vertices, T-junctions, crowds of crossing triangles, folded faces...), the cross-check's
** families (tests/ref/scenegen.c), boxes with heavy overlap and interpenetrations, a crowd
** of large crossing triangles, every shipped scene and cube.obj, in both cell sizes.
** A layered scene (parallel plates drawn back to front) shows the tiles at work: span
** parts skipped, and fewer point visits than without them (counts, not times). The tests
** of a face's first bands made before it is drawn and taken where it is drawn give the
** frame and the work counts (tiles skipped, point visits) of testing each band there
** (`retest_bands`), in the engine's order and a shuffled one. One struct points kept from
** render to render across scenes, with tiles and without, gives each a fresh one's frame.
** T74_DIFF_SEEDS (default 400) sets the seeds per hard family.
*/
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "render/points.h"
#include "render/scene.h"
#include "tests/ref/exactref.h"
#include "tests/ref/hardgen.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/xdiff.h"

struct tally {
  long scenes, points, skipped, visited, visited_plain, refused;
};

/* One render of sc on grid g with the given knobs; the frame copied to out (W x H). */
static int render_knobs(const struct scene *sc, const struct vis_grid *g, bool no_tiles,
                        uint64_t shuffle, bool retest, int32_t *out, int *culled,
                        long *skipped, long *visited)
{
  struct points p;
  memset(&p, 0, sizeof p);
  p.no_tiles = no_tiles;
  p.shuffle = shuffle;
  p.retest_bands = retest;
  struct t74_error err = { 0, "" };
  int st = points_render(&p, sc, g, &err);
  if (st == T74_OK) {
    memcpy(out, p.face, (size_t)g->W * (size_t)g->H * sizeof *out);
    *culled = p.faces_culled;
    *skipped = p.tiles_skipped;
    *visited = p.points_visited;
  }
  points_free(&p);
  return st;
}

static int render_with(const struct scene *sc, const struct vis_grid *g, bool no_tiles,
                       uint64_t shuffle, int32_t *out, int *culled, long *skipped,
                       long *visited)
{
  return render_knobs(sc, g, no_tiles, shuffle, false, out, culled, skipped, visited);
}

/* Scene sc in one cell size: plain, coarse and two shuffled orders give one frame.
   Returns the points that differ. */
static long judge(const struct scene *sc, int cell, const char *name, uint64_t seed,
                  struct tally *t)
{
  int W = 400 / cell, H = 300 / cell;
  struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  size_t n = (size_t)W * (size_t)H;
  int32_t *want = calloc(n, sizeof *want), *got = calloc(n, sizeof *got);
  assert_non_null(want);
  assert_non_null(got);
  int c0 = 0, c1 = 0;
  long s0 = 0, v0 = 0, s1 = 0, v1 = 0;
  int st = render_with(sc, &g, true, 0, want, &c0, &s0, &v0);
  long bad = 0;
  if (st != T74_OK) {
    t->refused++;
    /* the engine with coarse coverage refuses it as well */
    assert_int_equal(render_with(sc, &g, false, 0, got, &c1, &s1, &v1), st);
    goto done;
  }
  assert_int_equal(s0, 0);                      /* plain: no tiles */
  t->scenes++;
  t->points += (long)n;
  t->visited_plain += v0;
  for (int run = 0; run < 3; run++) {
    uint64_t sh = run ? seed * 4 + (uint64_t)run : 0;
    assert_int_equal(render_with(sc, &g, false, sh, got, &c1, &s1, &v1), T74_OK);
    assert_int_equal(c1, c0);
    if (run == 0) t->visited += v1;
    if (run == 1) t->skipped += s1;
    if (run < 2) {                              /* every band tested where it is drawn: */
      int c2 = 0;                               /* the same frame and the same work */
      long s2 = 0, v2 = 0;
      int32_t *again = calloc(n, sizeof *again);
      assert_non_null(again);
      assert_int_equal(render_knobs(sc, &g, false, sh, true, again, &c2, &s2, &v2), T74_OK);
      assert_memory_equal(again, got, n * sizeof *got);
      assert_int_equal(c2, c1);
      assert_int_equal(s2, s1);
      assert_int_equal(v2, v1);
      free(again);
    }
    for (size_t k = 0; k < n; k++)
      if (got[k] != want[k] && bad++ < 4)
        print_message("%s cell %d order %d: point (%d, %d) face %d, without coarse "
                      "coverage %d\n", name, cell, run, (int)(k % (size_t)W), (int)(k / (size_t)W),
                      got[k], want[k]);
  }
done:
  free(want);
  free(got);
  return bad;
}

/* x written to a temporary .s74 and loaded as a user's file would be. */
static long judge_xr(struct xr_scene *x, int cell, const char *name, uint64_t seed,
                     struct tally *t)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  int st = xd_load(x, &sc, &err);
  assert_true(st >= 0);
  long bad = 0;
  if (st == T74_OK) {
    bad = judge(sc, cell, name, seed, t);
    scene_free(sc);
  }
  if (bad) {
    char keep[256];
    snprintf(keep, sizeof keep, "build/tests/coarse-fail-%s.s74", name);
    xd_save(x, keep);
    print_message("%s: %ld points differ (scene kept in %s)\n", name, bad, keep);
  }
  return bad;
}

static void report(const char *what, const struct tally *t)
{
  print_message("%s: %ld scenes (%ld refused by the engine), %ld points, the same in every "
                "order; %ld tiles skipped, %ld point visits (%ld without tiles)\n",
                what, t->scenes, t->refused, t->points, t->skipped, t->visited,
                t->visited_plain);
}

static void test_hard_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  int n = xd_seeds();
  for (int fam = 0; fam < HG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(hg_generate(fam, (uint64_t)seed, &s), 0);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", hg_family_name(fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, (uint64_t)seed, &t);
      xr_scene_free(&s);
    }
  report("hard families", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes > (long)n * HG_NFAMILIES / 2);
}


static void test_scenegen_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  int n = xd_seeds() / 2 > 0 ? xd_seeds() / 2 : 1;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(xd_scenegen((sg_family)fam, (uint64_t)seed, &s), 0);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", sg_family_name((sg_family)fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, (uint64_t)seed, &t);
      xr_scene_free(&s);
    }
  report("cross-check families", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= SG_NFAMILIES);
}

/* A whole number in lo .. hi from the generators' random stream (scenegen.h's splitmix64). */
static int32_t rnd(sg_rng *x, int32_t lo, int32_t hi) { return (int32_t)sg_range(x, lo, hi); }

/* An axis-aligned box as six faces, numbered from *id. */
static void add_box(struct xr_scene *s, const int32_t lo[3], const int32_t hi[3], unsigned *id)
{
  int v[8];
  for (int c = 0; c < 8; c++) {
    v[c] = xr_vertex(s, c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]);
    assert_true(v[c] >= 0);
  }
  static const int q[6][4] = { { 0, 1, 3, 2 }, { 4, 6, 7, 5 }, { 0, 4, 5, 1 },
                               { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 5, 7, 3 } };
  for (int f = 0; f < 6; f++) {
    int vi[4] = { v[q[f][0]], v[q[f][1]], v[q[f][2]], v[q[f][3]] };
    assert_true(xr_face(s, (*id)++, 4, vi) >= 0);
  }
}

/* nbox boxes at random depths over the window, overlapping heavily (many interpenetrate),
   some sharing faces' planes exactly (coordinates on a coarse lattice). */
static void boxes(struct xr_scene *s, uint64_t seed, int nbox)
{
  memset(s, 0, sizeof *s);
  s->eye[0] = 0; s->eye[1] = 0; s->eye[2] = -1000;
  s->win[0] = -200; s->win[1] = -150; s->win[2] = 200; s->win[3] = 150;
  sg_rng x = { seed };
  unsigned id = 1;
  for (int b = 0; b < nbox; b++) {
    int32_t lo[3], hi[3];
    lo[0] = 10 * rnd(&x, -30, 25); hi[0] = lo[0] + 10 * rnd(&x, 1, 12);
    lo[1] = 10 * rnd(&x, -22, 18); hi[1] = lo[1] + 10 * rnd(&x, 1, 10);
    lo[2] = 10 * rnd(&x, 0, 60);   hi[2] = lo[2] + 10 * rnd(&x, 1, 20);
    add_box(s, lo, hi, &id);
  }
}

/* ntri large triangles across the window at random slants (they cross each other). */
static void triangles(struct xr_scene *s, uint64_t seed, int ntri)
{
  memset(s, 0, sizeof *s);
  s->eye[0] = 0; s->eye[1] = 0; s->eye[2] = -1000;
  s->win[0] = -200; s->win[1] = -150; s->win[2] = 200; s->win[3] = 150;
  sg_rng x = { seed };
  for (int k = 0; k < ntri; k++) {
    int v[3];
    for (int c = 0; c < 3; c++) {
      v[c] = xr_vertex(s, rnd(&x, -260, 260), rnd(&x, -200, 200), rnd(&x, 0, 800));
      assert_true(v[c] >= 0);
    }
    if (xr_face(s, (unsigned)k + 1, 3, v) < 0) fail();
  }
}

static void test_boxes_and_triangles(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  int n = xd_seeds() / 4 > 0 ? xd_seeds() / 4 : 1;
  for (int seed = 1; seed <= n; seed++) {
    struct xr_scene s;
    char name[64];
    boxes(&s, (uint64_t)seed, 20 + seed * 37 % 400);
    snprintf(name, sizeof name, "boxes-%d", seed);
    bad += judge_xr(&s, seed % 2 ? 3 : 4, name, (uint64_t)seed, &t);
    xr_scene_free(&s);
    triangles(&s, (uint64_t)seed, 10 + seed * 13 % 200);
    snprintf(name, sizeof name, "triangles-%d", seed);
    bad += judge_xr(&s, seed % 2 ? 4 : 3, name, (uint64_t)seed, &t);
    xr_scene_free(&s);
  }
  report("boxes and triangles", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= n);
  assert_true(t.skipped > 0);                   /* the tiles were used */
}

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void test_shipped(void **state)
{
  (void)state;
  DIR *d = opendir("scenes");
  assert_non_null(d);
  char *names[256];
  int nn = 0;
  struct dirent *e;
  while ((e = readdir(d)) && nn < 256) {
    size_t l = strlen(e->d_name);
    if (l > 4 && (!strcmp(e->d_name + l - 4, ".s74") || !strcmp(e->d_name + l - 4, ".obj")))
      names[nn++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, (size_t)nn, sizeof *names, cmp_str);
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  for (int k = 0; k < nn; k++) {
    char path[512];
    snprintf(path, sizeof path, "scenes/%s", names[k]);
    struct scene *sc = NULL;
    struct t74_error err = { 0, "" };
    struct scene_opts so;
    memset(&so, 0, sizeof so);
    so.quiet = true;
    assert_int_equal(scene_load(path, &so, &sc, &err), T74_OK);
    for (int cell = 3; cell <= 4; cell++) bad += judge(sc, cell, names[k], (uint64_t)k + 1, &t);
    scene_free(sc);
    free(names[k]);
  }
  report("shipped scenes", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= 2 * 20);
}

/* Plates parallel to the picture, each covering the window, drawn back to front (the file
   gives the farthest first): without tiles every plate visits every point; with them,
   once the faces' boxes cover the grid three times over, the nearest-first order draws
   the nearest plate and the tiles skip the rest. */
static void test_layered(void **state)
{
  (void)state;
  struct xr_scene s;
  memset(&s, 0, sizeof s);
  s.eye[0] = 0; s.eye[1] = 0; s.eye[2] = -1000;
  s.win[0] = -200; s.win[1] = -150; s.win[2] = 200; s.win[3] = 150;
  const int nplate = 12;
  for (int k = 0; k < nplate; k++) {
    /* z from 1200 (the first) to 100; r reaches beyond the window's corners */
    int32_t z = 100 * (nplate - k), r = 250 * (1000 + z) / 1000 + 20;
    int v[4] = { xr_vertex(&s, -r, -r, z), xr_vertex(&s, r, -r, z), xr_vertex(&s, r, r, z),
                 xr_vertex(&s, -r, r, z) };
    assert_true(xr_face(&s, (unsigned)k + 1, 4, v) >= 0);
  }
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  assert_int_equal(xd_load(&s, &sc, &err), T74_OK);
  xr_scene_free(&s);
  struct vis_grid g = { 100, 75, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  int32_t *a = calloc(100 * 75, sizeof *a), *b = calloc(100 * 75, sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  int c0, c1;
  long s0, v0, s1, v1;
  assert_int_equal(render_with(sc, &g, true, 0, a, &c0, &s0, &v0), T74_OK);
  assert_int_equal(render_with(sc, &g, false, 0, b, &c1, &s1, &v1), T74_OK);
  print_message("layered: %d plates, %ld point visits without tiles, %ld with them (%ld tiles "
                "skipped)\n", nplate, v0, v1, s1);
  assert_memory_equal(a, b, 100 * 75 * sizeof *a);
  for (int k = 0; k < 100 * 75; k++) assert_int_equal(a[k], nplate - 1);   /* the nearest */
  assert_int_equal(v0, (long)nplate * 100 * 75);
  assert_true(s1 > 0);
  /* the first three plates drawn as they come (their boxes then cover the grid three
     times over), the others nearest first: the nearest, and no other, visited */
  assert_int_equal(v1, 4 * 100 * 75);
  /* and in the file's order (a shuffle that happens to keep it, or any): still fewer */
  assert_int_equal(render_with(sc, &g, false, 7, b, &c1, &s1, &v1), T74_OK);
  assert_memory_equal(a, b, 100 * 75 * sizeof *a);
  assert_true(v1 <= v0);
  free(a);
  free(b);
  scene_free(sc);
}

/* Patterns on patterns (`on`): face 5, pattern 3 on it, 2 on 3, 1 on 2, nested squares in
   one plane. The coplanar rule goes round in a circle there (2 before 3, 1 before 2, but
   3 before 1 by number), so the picture would depend on the order: the engine keeps the
   Mapper's order for such a scene, whatever order it is asked for. */
static void test_pattern_chain(void **state)
{
  (void)state;
  struct xr_scene s;
  memset(&s, 0, sizeof s);
  s.eye[0] = 0; s.eye[1] = 0; s.eye[2] = -1000;
  s.win[0] = -200; s.win[1] = -150; s.win[2] = 200; s.win[3] = 150;
  const unsigned id[4] = { 5, 3, 2, 1 }, on[4] = { 0, 5, 3, 2 };
  for (int k = 0; k < 4; k++) {
    int32_t r = 140 - 30 * k;
    int v[4] = { xr_vertex(&s, -r, -r, 200), xr_vertex(&s, r, -r, 200), xr_vertex(&s, r, r, 200),
                 xr_vertex(&s, -r, r, 200) };
    int fi = xr_face(&s, id[k], 4, v);
    assert_true(fi >= 0);
    s.f[fi].on = on[k];
  }
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  assert_int_equal(xd_load(&s, &sc, &err), T74_OK);
  xr_scene_free(&s);
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  for (uint64_t seed = 1; seed <= 16; seed++) bad += judge(sc, 4, "pattern-chain", seed, &t);
  assert_int_equal(bad, 0);
  assert_int_equal(t.scenes, 16);
  scene_free(sc);
}

/* One struct points kept from render to render, as `--frames` keeps it, across scenes that
   differ in what they cover, with tiles and without: each frame (faces, culled, visits,
   tiles skipped) is a fresh struct's. Where no tile is kept the buffer is not cleared for
   the frame (points.c, "Clearing"): what an earlier frame left in the columns a frame's
   spans do not make ready must never be read nor shown. */
static void test_reused(void **state)
{
  (void)state;
  const char *const files[] = { "scenes/fig6-building.s74", "scenes/crossing.s74",
                                "scenes/street.s74", "scenes/sphere.s74", "scenes/t1-a.s74",
                                "scenes/lprism.s74", "scenes/cube.obj" };
  enum { NFILE = sizeof files / sizeof *files, NGEN = 4, NS = NFILE + NGEN };
  struct scene *sc[NS];
  for (int k = 0; k < NFILE; k++) {
    struct t74_error err = { 0, "" };
    struct scene_opts so;
    memset(&so, 0, sizeof so);
    so.quiet = true;
    assert_int_equal(scene_load(files[k], &so, &sc[k], &err), T74_OK);
  }
  for (int k = 0; k < NGEN; k++) {              /* boxes (tiles kept) and triangles */
    struct xr_scene x;
    if (k % 2) triangles(&x, (uint64_t)k + 5, 30 + 40 * k);
    else boxes(&x, (uint64_t)k + 5, 60 + 90 * k);
    struct t74_error err = { 0, "" };
    assert_int_equal(xd_load(&x, &sc[NFILE + k], &err), T74_OK);
    xr_scene_free(&x);
  }
  struct points kept;
  memset(&kept, 0, sizeof kept);
  int32_t *want = calloc(100 * 75, sizeof *want);
  assert_non_null(want);
  long frames = 0, tiled = 0;
  sg_rng x = { 12345 };
  for (int round = 0; round < 4 * NS; round++) {
    const int k = round < NS ? round : (int)(sg_next(&x) % NS);   /* each once, then at random */
    const bool no_tiles = round % 3 == 2;
    const struct scene *s = sc[k];
    struct vis_grid g = { 100, 75, { s->window[0], s->window[1], s->window[2], s->window[3] } };
    int c0 = 0;
    long s0 = 0, v0 = 0;
    assert_int_equal(render_with(s, &g, no_tiles, 0, want, &c0, &s0, &v0), T74_OK);
    kept.no_tiles = no_tiles;
    struct t74_error err = { 0, "" };
    assert_int_equal(points_render(&kept, s, &g, &err), T74_OK);
    if (memcmp(kept.face, want, 100 * 75 * sizeof *want))
      for (int q = 0, shown = 0; q < 100 * 75 && shown < 4; q++)
        if (kept.face[q] != want[q] && ++shown)
          print_message("scene %d (round %d): point (%d, %d) face %d, fresh %d\n", k, round,
                        q % 100, q / 100, kept.face[q], want[q]);
    assert_memory_equal(kept.face, want, 100 * 75 * sizeof *want);
    assert_int_equal(kept.faces_culled, c0);
    assert_int_equal(kept.points_visited, v0);
    assert_int_equal(kept.tiles_skipped, s0);
    frames++;
    tiled += s0 > 0;
  }
  print_message("reused: %ld frames, each a fresh render's (%ld with tiles skipped)\n",
                frames, tiled);
  assert_true(tiled > 0);
  points_free(&kept);
  free(want);
  for (int k = 0; k < NS; k++) scene_free(sc[k]);
}

/* One struct points kept from render to render over scenes of one to three squares at
   random places and sizes (a column to half the grid wide: some frames made ready span by
   span, some cleared over the faces' boxes), each frame a fresh struct's. A frame sets -1
   only where the last frame may have drawn and this one does not (points.c, "Clearing"):
   a square's box drawn to its edges, then none there, finds a column or row left over. */
static void test_reused_squares(void **state)
{
  (void)state;
  enum { W = 100, H = 75 };
  struct points kept;
  memset(&kept, 0, sizeof kept);
  int32_t *want = calloc(W * H, sizeof *want);
  assert_non_null(want);
  sg_rng x = { 777 };
  long lazy = 0, boxed = 0;
  for (int round = 0; round < 400; round++) {
    struct xr_scene sq;
    memset(&sq, 0, sizeof sq);
    sq.eye[0] = 0; sq.eye[1] = 0; sq.eye[2] = -1000;
    sq.win[0] = -200; sq.win[1] = -150; sq.win[2] = 200; sq.win[3] = 150;
    const int nsq = 1 + (int)(sg_next(&x) % 3);
    long area = 0;
    for (int k = 0; k < nsq; k++) {
      const int32_t r = 2 + (int32_t)(sg_next(&x) % (round % 2 ? 12 : 90));
      const int32_t cx = (int32_t)(sg_next(&x) % 400) - 200, cy = (int32_t)(sg_next(&x) % 300) - 150;
      const int32_t z = 200 + 100 * k;
      int v[4] = { xr_vertex(&sq, cx - r, cy - r, z), xr_vertex(&sq, cx + r, cy - r, z),
                   xr_vertex(&sq, cx + r, cy + r, z), xr_vertex(&sq, cx - r, cy + r, z) };
      assert_true(xr_face(&sq, (unsigned)k + 1, 4, v) >= 0);
      area += (long)r * r;
    }
    struct scene *sc = NULL;
    struct t74_error err = { 0, "" };
    assert_int_equal(xd_load(&sq, &sc, &err), T74_OK);
    xr_scene_free(&sq);
    struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
    int c0 = 0;
    long s0 = 0, v0 = 0;
    assert_int_equal(render_with(sc, &g, false, 0, want, &c0, &s0, &v0), T74_OK);
    assert_int_equal(points_render(&kept, sc, &g, &err), T74_OK);
    if (memcmp(kept.face, want, W * H * sizeof *want))
      for (int q = 0, shown = 0; q < W * H && shown < 4; q++)
        if (kept.face[q] != want[q] && ++shown)
          print_message("round %d: point (%d, %d) face %d, fresh %d\n", round, q % W, q / W,
                        kept.face[q], want[q]);
    assert_memory_equal(kept.face, want, W * H * sizeof *want);
    assert_int_equal(kept.points_visited, v0);
    lazy += area / nsq >= 400;                  /* (a rough split, for the message) */
    boxed += area / nsq < 400;
    scene_free(sc);
  }
  print_message("reused squares: 400 frames (about %ld large, %ld small)\n", lazy, boxed);
  points_free(&kept);
  free(want);
}

/* The core's size kept from call to call while the keep holds the scene's rings
   (map_faces: a sum over the scene's faces, taken again only for a scene the keep does not
   hold). A small scene twice with a keep, the keep freed (as when a run moves on to
   another scene), then a large scene in the very same struct scene (its contents moved
   there: the address alone cannot tell the scenes apart) with the keep: each frame a fresh
   struct's. Fails when the small scene's sum is taken for the large one (its Mapper's
   tables do not fit the core: an error), or when a kept sum is never taken again. */
static void test_core_words_kept(void **state)
{
  (void)state;
  struct xr_scene xs, xl;
  boxes(&xs, 3, 1);                             /* 6 faces */
  boxes(&xl, 4, 300);                           /* 1,800 faces: tables beyond the small core */
  struct scene *a = NULL, *b = NULL;
  struct t74_error err = { 0, "" };
  assert_int_equal(xd_load(&xs, &a, &err), T74_OK);
  assert_int_equal(xd_load(&xl, &b, &err), T74_OK);
  xr_scene_free(&xs);
  xr_scene_free(&xl);
  struct mapper_keep keep;
  memset(&keep, 0, sizeof keep);
  struct points kept;
  memset(&kept, 0, sizeof kept);
  kept.keep = &keep;
  int32_t *want = calloc(100 * 75, sizeof *want);
  assert_non_null(want);
  for (int round = 0; round < 5; round++) {
    if (round == 2) {                           /* the keep freed, the large scene in a's place */
      mapper_keep_free(&keep);
      const struct scene t = *a;
      *a = *b;
      *b = t;
    }
    struct vis_grid g = { 100, 75, { a->window[0], a->window[1], a->window[2], a->window[3] } };
    int c0 = 0;
    long s0 = 0, v0 = 0;
    assert_int_equal(render_with(a, &g, false, 0, want, &c0, &s0, &v0), T74_OK);
    const int st = points_render(&kept, a, &g, &err);
    if (st != T74_OK) print_message("round %d: %s\n", round, err.msg);
    assert_int_equal(st, T74_OK);
    assert_true(keep.s == a);                    /* (the Mapper holds a's rings now) */
    assert_memory_equal(kept.face, want, 100 * 75 * sizeof *want);
    assert_int_equal(kept.faces_culled, c0);
    assert_int_equal(kept.points_visited, v0);
  }
  assert_true(a->nf > 1000 && b->nf < 10);
  points_free(&kept);
  mapper_keep_free(&keep);
  free(want);
  scene_free(a);
  scene_free(b);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_reused),
    cmocka_unit_test(test_reused_squares),
    cmocka_unit_test(test_core_words_kept),
    cmocka_unit_test(test_layered),
    cmocka_unit_test(test_pattern_chain),
    cmocka_unit_test(test_shipped),
    cmocka_unit_test(test_boxes_and_triangles),
    cmocka_unit_test(test_scenegen_families),
    cmocka_unit_test(test_hard_families),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
