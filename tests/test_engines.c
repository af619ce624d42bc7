/*
** test_engines.c — the two engines point by point (issue 19): the points engine
** (render/points.h) against the 1974 program (render/render.h), and both against the exact
** reference (tests/ref/exactref.h, which shares no code with render/).
**
** Scenes: the hard generators (tests/ref/hardgen.c, every family), the cross-check's
** families (tests/ref/scenegen.c) and every shipped scene (the .s74 files of scenes/, visibility only:
** the ids a render dumps do not depend on the effects), each in both cell sizes. For
** every point of every scene:
**   - the points engine is exact: it agrees with the reference, except at a centre lying
**     exactly on two faces' intersection line, where the reference takes the larger face
**     number and the points engine the tie rule of the edges (the centre shifted by
**     (e, e^2), as the 1974 program's cut lines do); such a point must still be judged in
**     the band by the reference, and they are counted;
**   - where the engines differ, the 1974 answer lies in the reference's tolerance band
**     (the carrier line of an interpenetration, XR_BAND grid units; or a folded face's
**     chords): nowhere else may they differ.
** The figures (points, differing points) are printed; a scene that fails is saved as
** build/tests/engines-fail-NAME.s74. T74_DIFF_SEEDS (default 400) sets the seeds per hard
** family.
*/
#include <dirent.h>
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

#include "render/points.h"
#include "render/render.h"
#include "render/scene.h"
#include "tests/ref/exactref.h"
#include "tests/ref/hardgen.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/xdiff.h"

struct tally {
  long scenes, points, same, differ, points_tie, skipped;
};

struct grab { unsigned *ids; int W; const struct mapped *map; };

static int on_point(void *ctx, int i, int j, int face)
{
  struct grab *g = ctx;
  g->ids[(size_t)j * (size_t)g->W + (size_t)i] = face < 0 ? 0u : g->map->f[face].id;
  return 0;
}

/* Both engines' ids of scene sc on the grid of cell; 0, or the first engine's refusal. */
static int both(const struct scene *sc, int cell, unsigned *a, unsigned *b, char *msg, size_t n)
{
  int W = 400 / cell, H = 300 / cell;
  struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  struct t74_error err = { 0, "" };
  struct render r;
  struct render_opts ro = { 1u << 24, 0, PRIO_AUTO, NULL, 0, NULL };
  int st = render_prepare_lazy(&r, sc, &ro, &err);
  struct grab gr = { a, W, &r.map };
  if (st == T74_OK) st = render_scan(&r, &g, on_point, &gr, &err);
  render_free(&r);
  if (st != T74_OK) { snprintf(msg, n, "1974: %.900s", err.msg); return st; }
  struct points p;
  memset(&p, 0, sizeof p);
  st = points_render(&p, sc, &g, &err);
  if (st == T74_OK)
    for (int k = 0; k < W * H; k++) b[k] = p.face[k] < 0 ? 0u : p.map.f[p.face[k]].id;
  points_free(&p);
  if (st != T74_OK) snprintf(msg, n, "points: %.900s", err.msg);
  return st;
}

/* The scene as the reference reads it. */
static int to_ref(const struct scene *sc, struct xr_scene *x)
{
  memset(x, 0, sizeof *x);
  for (int c = 0; c < 3; c++) x->eye[c] = sc->view[c];
  for (int c = 0; c < 4; c++) x->win[c] = sc->window[c];
  for (int k = 0; k < sc->nv; k++)
    if (xr_vertex(x, sc->v[k].x, sc->v[k].y, sc->v[k].z) < 0) return -1;
  for (int k = 0; k < sc->nf; k++) {
    const struct scene_face *f = &sc->f[k];
    int fi = xr_face(x, f->id, f->ring_start[1] - f->ring_start[0], f->vidx);
    if (fi < 0) return -1;
    x->f[fi].grey = f->grey;
    x->f[fi].on = f->on_id;
    for (int h = 1; h < f->nring; h++)
      if (xr_hole(x, fi, f->ring_start[h + 1] - f->ring_start[h], f->vidx + f->ring_start[h]) < 0)
        return -1;
  }
  return 0;
}

/* Judge one loaded scene in one cell size; returns the points that break the rules. */
static long judge_scene(const struct scene *sc, int cell, const char *name, struct tally *t)
{
  int W = 400 / cell, H = 300 / cell;
  unsigned *a = calloc((size_t)W * H, sizeof *a), *b = calloc((size_t)W * H, sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  char msg[1024];
  long bad = 0;
  if (both(sc, cell, a, b, msg, sizeof msg) != T74_OK) {
    print_message("%s cell %d: refused: %s\n", name, cell, msg);
    free(a);
    free(b);
    return 1;
  }
  struct xr_scene xs;
  struct xr_ref ref;
  assert_int_equal(to_ref(sc, &xs), 0);
  assert_int_equal(xr_prepare(&xs, cell, &ref), 0);
  t->scenes++;
  for (int j = 0; j < H; j++)
    for (int i = 0; i < W; i++) {
      unsigned ga = a[j * W + i], gb = b[j * W + i], want;
      t->points++;
      int vb = xr_judge(&ref, i, j, gb, &want);
      if (vb != 0) {
        t->points_tie++;
        if (vb < 0) {
          if (bad++ < 4)
            print_message("%s cell %d (%d, %d): points engine shows %u, the reference %u\n",
                          name, cell, i, j, gb, want);
        }
      }
      if (ga == gb) { t->same++; continue; }
      t->differ++;
      if (xr_judge(&ref, i, j, ga, &want) < 0) {
        if (bad++ < 4)
          print_message("%s cell %d (%d, %d): 1974 %u, points %u, reference %u: outside "
                        "the band\n", name, cell, i, j, ga, gb, want);
      }
    }
  xr_ref_free(&ref);
  if (bad) {
    char path[512];
    snprintf(path, sizeof path, "build/tests/engines-fail-%s.s74", name);
    xd_save(&xs, path);
    print_message("%s: %ld points break the rules (scene kept in %s)\n", name, bad, path);
  }
  xr_scene_free(&xs);
  free(a);
  free(b);
  return bad;
}

/* Write x to a temporary .s74 and load it as a user's file would be. */
static long judge_xr(struct xr_scene *x, int cell, const char *name, struct tally *t)
{
  char path[] = "/tmp/tube74-engines-XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  assert_int_equal(xd_save(x, path), 0);
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.input = "s74";
  int st = scene_load(path, &so, &sc, &err);
  unlink(path);
  if (st != T74_OK) { t->skipped++; return 0; }   /* the reader refused it: not a scene */
  long bad = judge_scene(sc, cell, name, t);
  scene_free(sc);
  return bad;
}

static void report(const char *what, const struct tally *t)
{
  print_message("%s: %ld scenes, %ld points, %ld the same in both engines, %ld differ (each "
                "in the 1974 program's band), %ld points-engine answers on an exact depth tie; "
                "%ld scenes refused by the reader\n", what, t->scenes, t->points, t->same,
                t->differ, t->points_tie, t->skipped);
}

static int seeds(void)
{
  const char *e = getenv("T74_DIFF_SEEDS");
  int n = e ? atoi(e) : 400;
  return n > 0 ? n : 400;
}

static void test_hard_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  int n = seeds();
  for (int fam = 0; fam < HG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(hg_generate(fam, (uint64_t)seed, &s), 0);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", hg_family_name(fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, &t);
      xr_scene_free(&s);
    }
  report("hard families", &t);
  assert_int_equal(bad, 0);
  assert_int_equal(t.scenes + t.skipped, (long)n * HG_NFAMILIES);
  assert_true(t.scenes > (long)n * HG_NFAMILIES / 2);
  assert_true(t.same > 0);
  /* the engines are compared where they can differ: the hard families cross faces */
  assert_true(t.differ > 0);
  /* and agree nearly everywhere */
  assert_true(t.differ * 1000 < t.points);
}

static int from_sg(const ref_scene *r, struct xr_scene *s)
{
  memset(s, 0, sizeof *s);
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

static void test_scenegen_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  int n = seeds() / 8 > 0 ? seeds() / 8 : 1;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      ref_scene r;
      memset(&r, 0, sizeof r);
      char err[256];
      assert_int_equal(sg_generate((sg_family)fam, (uint64_t)seed, &r, err, sizeof err), 0);
      struct xr_scene s;
      assert_int_equal(from_sg(&r, &s), 0);
      sg_free(&r);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", sg_family_name((sg_family)fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, &t);
      xr_scene_free(&s);
    }
  report("cross-check families", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= SG_NFAMILIES);
  assert_true(t.same > 0);
}

static int cmp_str(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* every shipped scene; the ones without interpenetrations must agree exactly */
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
    if (l > 4 && !strcmp(e->d_name + l - 4, ".s74")) names[nn++] = strdup(e->d_name);
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
    for (int cell = 3; cell <= 4; cell++) {
      long before = t.differ;
      bad += judge_scene(sc, cell, names[k], &t);
      /* these scenes have no face crossing another: every point the same */
      if (!strcmp(names[k], "fig6.s74") || !strcmp(names[k], "fig5.s74") ||
          !strcmp(names[k], "fig10c.s74"))
        assert_int_equal(t.differ, before);
    }
    scene_free(sc);
    free(names[k]);
  }
  report("shipped scenes", &t);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= 2 * 20);
  /* nearly every point agrees */
  assert_true(t.differ * 10000 < t.points);
}

/* ---- the command line: --engine, --stats, the refusals ---------------------------- */

static char *slurp_file(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = malloc(1 << 20);
  size_t n = buf ? fread(buf, 1, (1 << 20) - 1, f) : 0;
  fclose(f);
  if (buf) buf[n] = 0;
  return buf;
}

/* Run `$TUBE74 ARGS` (a shell line); the exit status. */
static int run(const char *args)
{
  const char *bin = getenv("TUBE74");
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "%s %s >/dev/null 2>&1", bin ? bin : "./tube74", args);
  int ws = system(cmd);
  return WIFEXITED(ws) ? WEXITSTATUS(ws) : 128;
}

static void test_cli(void **state)
{
  (void)state;
  char dir[] = "/tmp/tube74-engines-cli-XXXXXX";
  assert_non_null(mkdtemp(dir));
  char a[2048], path[512], path2[512];
  /* auto: an import takes the points engine, its 1974 figures null */
  snprintf(path, sizeof path, "%s/a.json", dir);
  snprintf(a, sizeof a, "render tests/data/scene/cube.off --stats %s --dump ids=%s/a.pgm", path, dir);
  assert_int_equal(run(a), 0);
  char *js = slurp_file(path);
  assert_non_null(js);
  assert_non_null(strstr(js, "\"engine\": \"points\""));
  assert_non_null(strstr(js, "\"hitac10_seconds\": null"));
  assert_non_null(strstr(js, "\"first_dot_1974_seconds\": null"));
  assert_non_null(strstr(js, "\"core_words_used\": null"));
  assert_non_null(strstr(js, "\"priority_pairs_computed\": null"));
  assert_non_null(strstr(js, "\"total_1974_seconds\": null"));
  assert_non_null(strstr(js, "\"faces_in\": 6"));
  free(js);
  /* --engine 1974 on the same: the figures, and the same ids byte for byte */
  snprintf(a, sizeof a, "render tests/data/scene/cube.off --engine 1974 --stats %s --dump ids=%s/b.pgm",
           path, dir);
  assert_int_equal(run(a), 0);
  js = slurp_file(path);
  assert_non_null(js);
  assert_non_null(strstr(js, "\"engine\": \"1974\""));
  assert_null(strstr(js, "\"hitac10_seconds\": null"));
  free(js);
  snprintf(path, sizeof path, "%s/a.pgm", dir);
  snprintf(path2, sizeof path2, "%s/b.pgm", dir);
  char *ia = slurp_file(path), *ib = slurp_file(path2);
  assert_non_null(ia);
  assert_non_null(ib);
  assert_memory_equal(ia, ib, 15 + 2 * 100 * 75);
  free(ia);
  free(ib);
  /* auto: a .s74 scene takes the 1974 program; an import with an effect too */
  snprintf(path, sizeof path, "%s/c.json", dir);
  snprintf(a, sizeof a, "render scenes/fig6.s74 --stats %s", path);
  assert_int_equal(run(a), 0);
  js = slurp_file(path);
  assert_non_null(strstr(js, "\"engine\": \"1974\""));
  free(js);
  snprintf(a, sizeof a, "render tests/data/scene/cube.off --effects edges=on --stats %s", path);
  assert_int_equal(run(a), 0);
  js = slurp_file(path);
  assert_non_null(strstr(js, "\"engine\": \"1974\""));
  free(js);
  /* --engine points on a .s74 scene, with --frames */
  snprintf(a, sizeof a, "render scenes/fig7b.s74 --engine points --frames 3 --stats %s", path);
  assert_int_equal(run(a), 0);
  js = slurp_file(path);
  assert_non_null(strstr(js, "\"engine\": \"points\""));
  assert_non_null(strstr(js, "\"frames\": 3"));
  free(js);
  /* what only the 1974 program does is refused under --engine points, exit 2, no output */
  snprintf(path, sizeof path, "%s/never.png", dir);
  snprintf(a, sizeof a, "render scenes/sphere.s74 --engine points -o %s", path);
  assert_int_equal(run(a), 2);
  assert_int_equal(access(path, F_OK), -1);
  snprintf(a, sizeof a, "render scenes/fig6.s74 --engine points --arith hitac -o %s", path);
  assert_int_equal(run(a), 2);
  snprintf(a, sizeof a, "render scenes/fig6.s74 --engine points --dump tables=%s", path);
  assert_int_equal(run(a), 2);
  assert_int_equal(access(path, F_OK), -1);
  assert_int_equal(run("render scenes/fig6.s74 --engine fast"), 2);
  snprintf(a, sizeof a, "tek scenes/fig6.s74 --engine points -o %s/f.tek", dir);
  assert_int_equal(run(a), 0);
  snprintf(a, sizeof a, "rm -rf %s", dir);
  assert_int_equal(system(a), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_cli),
    cmocka_unit_test(test_shipped),
    cmocka_unit_test(test_scenegen_families),
    cmocka_unit_test(test_hard_families),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
