/*
** test_engines.c — the two engines point by point (issue 19): the points engine
** (render/points.h) against the 1974 program (render/render.h), and both against the exact
** reference (tests/ref/exactref.h, which shares no code with render/).
**
** Scenes: the hard generators (tests/ref/hardgen.c, every family), the cross-check's
** families (tests/ref/scenegen.c), every shipped scene (the .s74 files of scenes/, visibility only:
** the ids a render dumps do not depend on the effects) and every file of the fuzz corpus
** the reader takes (tests/fuzz/corpus_s74, _obj, _off), each in both cell sizes. For
** every point of every scene:
**   - the points engine is exact: it agrees with the reference, except at a centre lying
**     exactly on two faces' intersection line, where the reference takes the larger face
**     number and the points engine the tie rule of the edges (the centre shifted by
**     (e, e^2), as the 1974 program's cut lines do); such a point must still be judged in
**     the band by the reference, and they are counted;
**   - where the engines differ, the 1974 answer lies in the reference's tolerance band
**     (the carrier line of an interpenetration, XR_BAND grid units; or a folded face's
**     chords): nowhere else may they differ.
**
** The effects both engines run (smoothing, contour cuts, shadows, textures, supersampling;
** effects/see.h), on the shipped scenes that use them (with supersampling and shadows
** added) and on every 8th hard scene and every 4th cross-check scene lit from a light, its
** triangles made one object: at every sample of the lattices the effects use (the centres,
** and aa=super's K x K a point, up to one point beyond the grid), the face each engine
** sees, plain and with each cut object taken away, is judged by the reference where they
** differ (the reference at the samples, without the object's faces), exactly as above; the
** regions decided sample by sample (the points engine's way) equal those decided stretch
** by stretch (the 1974 engine's) on the 1974 engine, also with polygons laid through the
** samples themselves; after the regions the engines differ only where a plain answer
** does; and the pictures fx_run makes (greys and ids) differ only at points with such a
** sample within the filter's reach. At the centres the points engine's sample query is
** its own frame, exactly.
**
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

#include "effects/fx.h"
#include "effects/model.h"
#include "effects/see.h"
#include "render/effects.h"
#include "render/points.h"
#include "render/points_at.h"
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

/* The scene as the reference reads it, without the faces of object `without` (0: all). */
static int to_ref_without(const struct scene *sc, uint32_t without, struct xr_scene *x)
{
  memset(x, 0, sizeof *x);
  for (int c = 0; c < 3; c++) x->eye[c] = sc->view[c];
  for (int c = 0; c < 4; c++) x->win[c] = sc->window[c];
  for (int k = 0; k < sc->nv; k++)
    if (xr_vertex(x, sc->v[k].x, sc->v[k].y, sc->v[k].z) < 0) return -1;
  for (int k = 0; k < sc->nf; k++) {
    const struct scene_face *f = &sc->f[k];
    if (without && (uint32_t)f->object == without) continue;
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

static int to_ref(const struct scene *sc, struct xr_scene *x) { return to_ref_without(sc, 0, x); }

/* Judge one loaded scene in one cell size; returns the points that break the rules. A
   refusal by either engine is one (refused counts it instead, when given: the fuzz
   corpus holds scenes the 1974 program may refuse, such as for its limits). */
static long judge_scene_or(const struct scene *sc, int cell, const char *name, struct tally *t,
                           long *refused)
{
  int W = 400 / cell, H = 300 / cell;
  unsigned *a = calloc((size_t)W * H, sizeof *a), *b = calloc((size_t)W * H, sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  char msg[1024];
  long bad = 0;
  if (both(sc, cell, a, b, msg, sizeof msg) != T74_OK) {
    if (!refused) print_message("%s cell %d: refused: %s\n", name, cell, msg);
    free(a);
    free(b);
    if (refused) (*refused)++;
    return refused ? 0 : 1;
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

static long judge_scene(const struct scene *sc, int cell, const char *name, struct tally *t)
{
  return judge_scene_or(sc, cell, name, t, NULL);
}

/* Write x to a temporary .s74 and load it as a user's file would be. */
static long judge_xr(struct xr_scene *x, int cell, const char *name, struct tally *t)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  int st = xd_load(x, &sc, &err);
  assert_true(st >= 0);
  if (st != T74_OK) { t->skipped++; return 0; }   /* the reader refused it: not a scene */
  long bad = judge_scene(sc, cell, name, t);
  scene_free(sc);
  return bad;
}

/* A shipped scene, read quietly as a user's file would be. */
static struct scene *load_quiet(const char *path)
{
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.quiet = true;
  assert_int_equal(scene_load(path, &so, &sc, &err), T74_OK);
  return sc;
}

/* ---- the effects under both engines ----------------------------------------------- */

/* Both engines on one scene and grid, as the effects see them (effects/see.h). */
struct duo {
  const struct scene *s;
  int W, H, cell;
  struct vis_grid g;
  struct render r;
  struct points p;
  struct fx_engine eng[2];          /* 0: the 1974 engine, 1: the points engine */
  int *face[2];                     /* each engine's frame: the face at each centre */
};

static int duo_point(void *ctx, int i, int j, int face)
{
  struct duo *d = ctx;
  d->face[0][(size_t)j * (size_t)d->W + (size_t)i] = face;
  return 0;
}

static void duo_close(struct duo *d)
{
  fx_engine_free(&d->eng[1]);
  points_free(&d->p);
  render_free(&d->r);
  free(d->face[0]);
  free(d->face[1]);
  memset(d, 0, sizeof *d);
}

static int duo_open(struct duo *d, const struct scene *s, int cell, char *msg, size_t n)
{
  memset(d, 0, sizeof *d);
  d->s = s;
  d->cell = cell;
  d->W = 400 / cell;
  d->H = 300 / cell;
  d->g = (struct vis_grid){ d->W, d->H, { s->window[0], s->window[1], s->window[2], s->window[3] } };
  d->face[0] = calloc((size_t)d->W * (size_t)d->H, sizeof *d->face[0]);
  d->face[1] = calloc((size_t)d->W * (size_t)d->H, sizeof *d->face[1]);
  assert_non_null(d->face[0]);
  assert_non_null(d->face[1]);
  struct t74_error err = { 0, "" };
  struct render_opts ro = { 1u << 24, 0, PRIO_AUTO, NULL, 0, NULL };
  int st = render_prepare_lazy(&d->r, s, &ro, &err);
  if (st == T74_OK) st = render_scan(&d->r, &d->g, duo_point, d, &err);
  if (st == T74_OK) st = points_render(&d->p, s, &d->g, &err);
  if (st == T74_OK) {
    for (int k = 0; k < d->W * d->H; k++) d->face[1][k] = d->p.face[k];
    fx_engine_1974(&d->eng[0], &d->r, &d->g);
    st = fx_engine_points(&d->eng[1], &d->p, &d->g, NULL, &err);
  }
  if (st != T74_OK) {
    snprintf(msg, n, "%.900s", err.msg);
    duo_close(d);
  }
  return st;
}

/* Scene s in both engines at cell (d, duo_open's), and the effects model e makes on engine
   eng's frame (m), its figures into *st (cleared first) and its charges into *cost. */
static void model_open(struct duo *d, struct fx_model *m, const struct scene *s,
                       const struct effects *e, int cell, int eng, struct fx_stats *st,
                       struct cost *cost)
{
  char msg[1024];
  if (duo_open(d, s, cell, msg, sizeof msg) != T74_OK) fail_msg("%s", msg);
  memset(st, 0, sizeof *st);
  struct t74_error err = { 0, "" };
  if (fx_model_build(m, &d->eng[eng], s, e, NULL, st, cost, &err) != T74_OK)
    fail_msg("%s", err.msg);
}

/* A frame for fx_points on d's grid: the points engine's faces (d->face[1]), greys 0. */
static void frame_of_points(struct fx_frame *f, const struct duo *d)
{
  const size_t np = (size_t)d->W * (size_t)d->H;
  memset(f, 0, sizeof *f);
  f->W = d->W; f->H = d->H; f->cell = d->cell;
  assert_non_null(f->face = malloc(np * sizeof *f->face));
  assert_non_null(f->grey = calloc(np, 1));
  memcpy(f->face, d->face[1], np * sizeof *f->face);
}

/* Shipped scene scenes/NAME.s74, loaded quietly, and its own effects into *e. */
static struct scene *shipped_with_effects(const char *name, struct effects *e)
{
  char path[256];
  snprintf(path, sizeof path, "scenes/%s.s74", name);
  struct scene *sc = load_quiet(path);
  struct t74_error err = { 0, "" };
  if (effects_parse(sc->effects ? sc->effects : "", e, "test", 1, &err) != T74_OK)
    fail_msg("%s", err.msg);
  return sc;
}

static unsigned id_of(const struct fx_engine *e, int face) { return face < 0 ? 0u : e->map->f[face].id; }

struct fx_tally {
  long scenes, samples, differ, explained, points, grey_differ, id_differ, bad;
  long smoothed, cut, shadowed;     /* scenes with smoothing patches, cuts, shadows */
};

/* One lattice K of a scene under effects e: at every sample (bottom row first) the face
   each engine sees, plain and with each cut object taken away, judged by the exact
   reference where the engines differ (the points engine exact, the 1974 program inside
   its band); the model's regions decided stretch by stretch and sample by sample on the
   1974 engine, which must agree everywhere; and the answers after the regions, which may
   differ between the engines only where a plain answer differs. diff[] marks those
   samples ((m + K) * nk + k + K). */
static void lattice(struct duo *d, const struct effects *e, int K, const char *name,
                    uint8_t *diff, struct fx_tally *t)
{
  struct fx_stats st;
  memset(&st, 0, sizeof st);
  struct cost cost = { { 0 } };
  struct t74_error err = { 0, "" };
  struct fx_model m[2];
  for (int k = 0; k < 2; k++)
    assert_int_equal(fx_model_build(&m[k], &d->eng[k], d->s, e, NULL, &st, &cost, &err), T74_OK);
  assert_int_equal(m[0].ncut, m[1].ncut);
  assert_int_equal(m[0].shadows.n, m[1].shadows.n);
  if (K == 1) {
    t->smoothed += m[0].smooth && m[0].sm.ntri > 0;
    t->cut += m[0].ncut > 0;
    t->shadowed += m[0].shadows.n > 0;
  }
  const int nq = m[0].ncut + 1;             /* 0: plain; q + 1: without cut object q */
  struct fx_see *see[2][16];
  struct xr_ref ref[16];
  assert_true(nq <= 16);
  for (int q = 0; q < nq; q++) {
    for (int k = 0; k < 2; k++)
      assert_int_equal(fx_see_open(&see[k][q], &d->eng[k], q ? m[k].cut_skip[q - 1] : NULL,
                                   &cost, &err), T74_OK);
    struct xr_scene xs;
    assert_int_equal(to_ref_without(d->s, q ? (uint32_t)m[0].cut_obj[q - 1] : 0, &xs), 0);
    assert_int_equal(xr_prepare(&xs, d->cell, &ref[q]), 0);
    xr_scene_free(&xs);
    ref[q].W = K * d->W;                      /* the reference at the samples */
    ref[q].H = K * d->H;
  }
  struct fx_lines *L[3];                      /* 1974 by stretches, 1974 by samples, points */
  assert_int_equal(fx_lines_open(&L[0], &m[0], false, &cost, &err), T74_OK);
  assert_int_equal(fx_lines_open(&L[1], &m[0], true, &cost, &err), T74_OK);
  assert_int_equal(fx_lines_open(&L[2], &m[1], false, &cost, &err), T74_OK);
  assert_true(fx_lines_have_spans(L[0]));
  assert_false(fx_lines_have_spans(L[1]));
  assert_false(fx_lines_have_spans(L[2]));
  const int nk = K * (d->W + 2), k0 = -K;
  int *pl[2][16], *af[3];
  unsigned *ab[3];
  for (int k = 0; k < 2; k++)
    for (int q = 0; q < nq; q++) assert_non_null(pl[k][q] = calloc((size_t)nk, sizeof(int)));
  for (int k = 0; k < 3; k++) {
    assert_non_null(af[k] = calloc((size_t)nk, sizeof(int)));
    assert_non_null(ab[k] = calloc((size_t)nk, sizeof(unsigned)));
  }
  for (int mr = K * (d->H + 1) - 1; mr >= -K; mr--) {
    for (int k = 0; k < 2; k++)
      for (int q = 0; q < nq; q++)
        assert_int_equal(fx_see_row(see[k][q], K, mr, k0, nk, pl[k][q], &err), T74_OK);
    for (int k = 0; k < 3; k++)
      assert_int_equal(fx_lines_samples(L[k], K, mr, k0, nk, af[k], ab[k], &err), T74_OK);
    for (int i = 0; i < nk; i++) {
      int kk = k0 + i;
      t->samples++;
      bool plain_differs = false;
      for (int q = 0; q < nq; q++) {
        unsigned a = id_of(&d->eng[0], pl[0][q][i]), b = id_of(&d->eng[1], pl[1][q][i]), want;
        if (a == b) continue;
        plain_differs = true;
        t->differ++;
        if (xr_judge(&ref[q], kk, mr, b, &want) < 0 || xr_judge(&ref[q], kk, mr, a, &want) < 0) {
          if (t->bad++ < 4)
            print_message("%s K=%d sample (%d, %d)%s: 1974 %u, points %u, reference %u\n", name,
                          K, kk, mr, q ? " behind a cut" : "", a, b, want);
        }
      }
      /* the regions: stretch by stretch and sample by sample, the same */
      if (af[0][i] != af[1][i] || ab[0][i] != ab[1][i]) {
        if (t->bad++ < 4)
          print_message("%s K=%d sample (%d, %d): regions by stretches %d/%u, by samples %d/%u\n",
                        name, K, kk, mr, af[0][i], ab[0][i], af[1][i], ab[1][i]);
      }
      bool after_differs = id_of(&d->eng[0], af[0][i]) != id_of(&d->eng[1], af[2][i]) ||
                           ab[0][i] != ab[2][i];
      if (after_differs && !plain_differs) {
        if (t->bad++ < 4)
          print_message("%s K=%d sample (%d, %d): after the regions 1974 %u/%u, points %u/%u, "
                        "with the same faces seen\n", name, K, kk, mr, id_of(&d->eng[0], af[0][i]),
                        ab[0][i], id_of(&d->eng[1], af[2][i]), ab[2][i]);
      }
      diff[(size_t)(mr + K) * (size_t)nk + (size_t)i] = after_differs;
    }
  }
  for (int k = 0; k < 3; k++) { fx_lines_close(L[k]); free(af[k]); free(ab[k]); }
  for (int q = 0; q < nq; q++) {
    for (int k = 0; k < 2; k++) { fx_see_close(see[k][q]); free(pl[k][q]); }
    xr_ref_free(&ref[q]);
  }
  fx_model_free(&m[0]);
  fx_model_free(&m[1]);
}

/* Is a sample near point (i, j) of lattice K marked in diff (the filter's reach)? */
static bool near_diff(const uint8_t *diff, int W, int H, int K, int i, int j)
{
  const int nk = K * (W + 2);
  for (int m = K * j - K; m < K * j + 2 * K; m++)
    for (int k = K * i - K; k < K * i + 2 * K; k++) {
      if (m < -K || m >= K * (H + 1) || k < -K || k >= K * (W + 1)) continue;
      if (diff[(size_t)(m + K) * (size_t)nk + (size_t)(k + K)]) return true;
    }
  return false;
}

/* Scene s under effects text fx (points-engine effects) in both engines: the samples
   (lattice), then the pictures through fx_run as the pipeline runs it: every point whose
   grey or face differs has a differing sample within its filter's reach. */
static void judge_fx(const struct scene *s, int cell, const char *fx, const char *name,
                     struct fx_tally *t)
{
  struct effects e;
  struct t74_error err = { 0, "" };
  assert_int_equal(effects_parse(fx, &e, "test", 1, &err), T74_OK);
  assert_null(fx_needs_1974(&e));
  struct duo d;
  char msg[1024];
  if (duo_open(&d, s, cell, msg, sizeof msg) != T74_OK) {
    print_message("%s: refused: %s\n", name, msg);
    return;
  }
  t->scenes++;
  const int K = e.aa == EFFECTS_AA_SUPER ? e.super : 1;
  uint8_t *diff1 = calloc((size_t)(d.W + 2) * (size_t)(d.H + 2), 1);
  uint8_t *diffk = calloc((size_t)(K * (d.W + 2)) * (size_t)(K * (d.H + 2)), 1);
  assert_non_null(diff1);
  assert_non_null(diffk);
  lattice(&d, &e, 1, name, diff1, t);
  if (K > 1) lattice(&d, &e, K, name, diffk, t);
  /* the pictures */
  size_t n = (size_t)d.W * (size_t)d.H;
  uint8_t *grey[2];
  for (int k = 0; k < 2; k++) {
    grey[k] = malloc(n);
    assert_non_null(grey[k]);
    for (size_t at = 0; at < n; at++)
      grey[k][at] = (uint8_t)(d.face[k][at] >= 0 ? d.eng[k].map->f[d.face[k][at]].grey : 0);
    struct fx_frame f = { d.W, d.H, e.halftone, d.face[k], grey[k], NULL, NULL, NULL };
    struct fx_stats st;
    memset(&st, 0, sizeof st);
    struct cost cost = { { 0 } };
    assert_int_equal(fx_run(&d.eng[k], s, &e, &f, &st, &cost, &err), T74_OK);
  }
  for (int j = 0; j < d.H; j++)
    for (int i = 0; i < d.W; i++) {
      size_t at = (size_t)j * (size_t)d.W + (size_t)i;
      bool gd = grey[0][at] != grey[1][at];
      bool id = id_of(&d.eng[0], d.face[0][at]) != id_of(&d.eng[1], d.face[1][at]);
      t->points++;
      t->grey_differ += gd;
      t->id_differ += id;
      if (!gd && !id) continue;
      bool why = diff1[(size_t)(j + 1) * (size_t)(d.W + 2) + (size_t)(i + 1)] ||
                 (gd && K > 1 && near_diff(diffk, d.W, d.H, K, i, j));
      if (why) { t->explained++; continue; }
      if (t->bad++ < 4)
        print_message("%s point (%d, %d): grey %d / %d, face %u / %u, with the same samples\n",
                      name, i, j, grey[0][at], grey[1][at], id_of(&d.eng[0], d.face[0][at]),
                      id_of(&d.eng[1], d.face[1][at]));
    }
  free(grey[0]);
  free(grey[1]);
  free(diff1);
  free(diffk);
  duo_close(&d);
}

/* A generated scene under the points engine's effects: its faces lit from a light instead
   of their greys, its triangles one object (smoothing, contour cuts), shadows and
   supersampling, in both engines (judge_fx). */
static void judge_fx_xr(struct xr_scene *x, int cell, const char *name, struct fx_tally *t)
{
  char path[] = "/tmp/tube74-engines-fx-XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  close(fd);
  for (int k = 0; k < x->nf; k++) x->f[k].grey = -1;
  assert_int_equal(xd_save(x, path), 0);
  FILE *f = fopen(path, "a");
  assert_non_null(f);
  fprintf(f, "light -45 60 -80\n");
  int ntri = 0;
  for (int k = 0; k < x->nf; k++)
    if (x->f[k].nring == 1 && x->f[k].rs[1] - x->f[k].rs[0] == 3) {
      fprintf(f, "%s %u", ntri++ ? "" : "object 1", x->f[k].id);
    }
  if (ntri) fprintf(f, "\n");
  fclose(f);
  struct scene *sc = NULL;
  struct t74_error err = { 0, "" };
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  so.input = "s74";
  so.quiet = true;
  int st = scene_load(path, &so, &sc, &err);
  unlink(path);
  if (st != T74_OK) return;                   /* the reader refused it: not a scene */
  judge_fx(sc, cell, ntri ? "shadows=on smooth=gouraud contour=0.5 aa=super"
                          : "shadows=on aa=super", name, t);
  scene_free(sc);
}

static void fx_report(const char *what, const struct fx_tally *t)
{
  print_message("%s: %ld scene renders (%ld smoothed, %ld with contour cuts, %ld with "
                "shadows), %ld samples, %ld answers differ (each judged), %ld points, %ld greys "
                "and %ld faces differ (each beside a differing sample); %ld break the rules\n",
                what, t->scenes, t->smoothed, t->cut, t->shadowed, t->samples, t->differ,
                t->points, t->grey_differ, t->id_differ, t->bad);
}

/* At the point centres the points engine's sample query is its frame, exactly. */
static void check_points_at(const struct scene *sc, int cell)
{
  int W = 400 / cell, H = 300 / cell;
  struct vis_grid g = { W, H, { sc->window[0], sc->window[1], sc->window[2], sc->window[3] } };
  struct points p;
  memset(&p, 0, sizeof p);
  struct t74_error err = { 0, "" };
  if (points_render(&p, sc, &g, &err) != T74_OK) { points_free(&p); return; }
  struct points_at q;
  memset(&q, 0, sizeof q);
  int *row = calloc((size_t)W, sizeof *row);
  assert_non_null(row);
  for (int j = 0; j < H; j++) {
    assert_int_equal(points_at_row(&q, &p, &g, 1, j, 0, W, NULL, row, &err), T74_OK);
    for (int i = 0; i < W; i++) assert_int_equal(row[i], p.face[j * W + i]);
  }
  /* and it refuses a lattice it cannot decide exactly */
  assert_int_equal(points_at_row(&q, &p, &g, POINTS_AT_KMAX + 1, 0, 0, 1, NULL, row, &err), T74_EIO);
  assert_int_equal(points_at_row(&q, &p, &g, 2, 0, -3, 1, NULL, row, &err), T74_EIO);
  free(row);
  points_at_free(&q);
  points_free(&p);
}

static void report(const char *what, const struct tally *t)
{
  print_message("%s: %ld scenes, %ld points, %ld the same in both engines, %ld differ (each "
                "in the 1974 program's band), %ld points-engine answers on an exact depth tie; "
                "%ld scenes refused by the reader\n", what, t->scenes, t->points, t->same,
                t->differ, t->points_tie, t->skipped);
}

static void test_hard_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  struct fx_tally ft;
  memset(&ft, 0, sizeof ft);
  long bad = 0;
  int n = xd_seeds();
  for (int fam = 0; fam < HG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(hg_generate(fam, (uint64_t)seed, &s), 0);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", hg_family_name(fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, &t);
      if (seed % 8 == 1) judge_fx_xr(&s, seed % 16 == 1 ? 4 : 3, name, &ft);   /* greys dropped */
      xr_scene_free(&s);
    }
  report("hard families", &t);
  fx_report("effects, hard families", &ft);
  assert_int_equal(ft.bad, 0);
  assert_true(ft.scenes > (long)n * HG_NFAMILIES / 16);
  assert_true(ft.smoothed > 0 && ft.cut > 0 && ft.shadowed > 0);
  if (n >= 100) assert_true(ft.differ > 0);   /* they cross faces: the engines differ */
  assert_int_equal(bad, 0);
  assert_int_equal(t.scenes + t.skipped, (long)n * HG_NFAMILIES);
  assert_true(t.scenes > (long)n * HG_NFAMILIES / 2);
  assert_true(t.same > 0);
  /* the engines are compared where they can differ: the hard families cross faces */
  assert_true(t.differ > 0);
  /* and agree nearly everywhere */
  assert_true(t.differ * 1000 < t.points);
}


/* Faces with vertices just in front of the eye's plane, projected some 2^27 grid units
   away (|gcoord| <= 2^28): the first crossings of an edge between two of them overflow 64
   bits, and the points engine works them out in 128 (render/points.c, face_edges). Judged as the shipped scenes
   are, in both cells, seen from the front and turned about the eye (every edge's slope). */
static void test_far_vertices(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0;
  static const int32_t far[][3] = { { -5000, -3000, -990 }, { 4000, 4500, -985 },
                                    { 4800, -4700, -988 }, { -4200, 3900, -992 },
                                    { -5000, -4900, -995 }, { 5000, 5000, -995 } };
  static const int32_t near[][3] = { { 100, -50, 50 }, { 0, 120, 80 }, { -150, 100, 30 },
                                     { 150, -100, 60 }, { -120, -110, 45 }, { 90, 130, 70 } };
  for (int turn = 0; turn < 4; turn++) {
    struct xr_scene x;
    memset(&x, 0, sizeof x);
    x.eye[2] = -1000;
    x.win[0] = -200; x.win[1] = -150; x.win[2] = 200; x.win[3] = 150;
    for (int k = 0; k < 6; k++) {             /* the far ones turned by turn quarters */
      int32_t fx = far[k][0], fy = far[k][1];
      for (int q = 0; q < turn; q++) { int32_t tx = fx; fx = -fy; fy = tx; }
      assert_true(xr_vertex(&x, fx, fy, far[k][2]) >= 0);
    }
    for (int k = 0; k < 6; k++) assert_true(xr_vertex(&x, near[k][0], near[k][1], near[k][2]) >= 0);
    for (int k = 0; k < 4; k++)               /* a square at z = 40 */
      assert_true(xr_vertex(&x, k == 1 || k == 2 ? 100 : -100, k >= 2 ? 100 : -100, 40) >= 0);
    /* two far vertices (an edge passing the window beside it, its crossings thousands of
       columns away; or across it, from corner to corner of the plane's range, where the
       products of a crossing inside the window overflow 64 bits) or one with near ones;
       the square across them */
    static const int tri[][3] = { { 0, 3, 6 }, { 1, 2, 9 }, { 2, 10, 11 }, { 3, 7, 10 },
                                  { 4, 5, 6 } };
    for (int k = 0; k < 5; k++) assert_true(xr_face(&x, (unsigned)k + 1, 3, tri[k]) >= 0);
    static const int quad[4] = { 12, 13, 14, 15 };
    assert_true(xr_face(&x, 6, 4, quad) >= 0);
    char name[64];
    snprintf(name, sizeof name, "far-vertices-%d", turn);
    bad += judge_xr(&x, 3, name, &t) + judge_xr(&x, 4, name, &t);
    xr_scene_free(&x);
  }
  report("far vertices", &t);
  assert_int_equal(bad, 0);
  assert_int_equal(t.scenes, 8);
  assert_true(t.points - t.same < t.points / 100);  /* the faces meet: nearly all agree */
}

static void test_scenegen_families(void **state)
{
  (void)state;
  struct tally t;
  memset(&t, 0, sizeof t);
  struct fx_tally ft;
  memset(&ft, 0, sizeof ft);
  long bad = 0;
  int n = xd_seeds() / 8 > 0 ? xd_seeds() / 8 : 1;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (int seed = 1; seed <= n; seed++) {
      struct xr_scene s;
      assert_int_equal(xd_scenegen((sg_family)fam, (uint64_t)seed, &s), 0);
      char name[64];
      snprintf(name, sizeof name, "%s-%d", sg_family_name((sg_family)fam), seed);
      bad += judge_xr(&s, seed % 2 ? 3 : 4, name, &t);
      if (seed % 4 == 1) judge_fx_xr(&s, seed % 8 == 1 ? 4 : 3, name, &ft);
      xr_scene_free(&s);
    }
  report("cross-check families", &t);
  fx_report("effects, cross-check families", &ft);
  assert_int_equal(ft.bad, 0);
  assert_true(ft.scenes >= SG_NFAMILIES);
  assert_true(ft.smoothed > 0 && ft.shadowed > 0);
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
    struct scene *sc = load_quiet(path);
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

/* The fuzz corpus (tests/fuzz/corpus_s74, _obj, _off: the inputs the fuzzers kept, most
   of them odd): every file the reader takes, in both cells, judged as the shipped scenes
   are. A file the reader refuses is no scene (counted, not judged); a scene the 1974
   program refuses (its limits) is counted, and then the points engine is not asked. */
static void test_fuzz_corpus(void **state)
{
  (void)state;
  static const char *const dirs[] = { "tests/fuzz/corpus_s74", "tests/fuzz/corpus_obj",
                                      "tests/fuzz/corpus_off" };
  static const char *const kinds[] = { "s74", "obj", "off" };
  struct tally t;
  memset(&t, 0, sizeof t);
  long bad = 0, refused = 0, files = 0;
  for (size_t q = 0; q < sizeof dirs / sizeof *dirs; q++) {
    DIR *d = opendir(dirs[q]);
    assert_non_null(d);
    char *names[1024];
    int nn = 0;
    struct dirent *e;
    while ((e = readdir(d)) && nn < 1024)
      if (e->d_name[0] != '.') names[nn++] = strdup(e->d_name);
    closedir(d);
    qsort(names, (size_t)nn, sizeof *names, cmp_str);
    for (int k = 0; k < nn; k++) {
      char path[512];
      snprintf(path, sizeof path, "%s/%s", dirs[q], names[k]);
      files++;
      struct scene *sc = NULL;
      struct t74_error err = { 0, "" };
      struct scene_opts so;
      memset(&so, 0, sizeof so);
      so.quiet = true;
      so.input = kinds[q];
      if (scene_load(path, &so, &sc, &err) != T74_OK) { t.skipped++; free(names[k]); continue; }
      for (int cell = 3; cell <= 4; cell++) bad += judge_scene_or(sc, cell, names[k], &t, &refused);
      scene_free(sc);
      free(names[k]);
    }
  }
  report("fuzz corpus", &t);
  print_message("fuzz corpus: %ld files, %ld not scenes, %ld renders refused by the 1974 "
                "program\n", files, t.skipped, refused);
  assert_int_equal(bad, 0);
  assert_true(t.scenes >= 100);          /* most of the corpus is read and judged */
  assert_true(t.differ * 1000 < t.points);
}

/* The point centre (i, j) on the plane grid (it must lie on it). */
static struct gpoint centre_pt(const struct vis_grid *g, int i, int j)
{
  int64_t xd = 2 * (int64_t)g->W, yd = 2 * (int64_t)g->H;
  int64_t xn = GRID_ONE * (xd * g->window[0] + (2 * (int64_t)i + 1) * (g->window[2] - g->window[0]));
  int64_t yn = GRID_ONE * (yd * g->window[3] - (2 * (int64_t)j + 1) * (g->window[3] - g->window[1]));
  assert_int_equal(xn % xd, 0);
  assert_int_equal(yn % yd, 0);
  return (struct gpoint){ xn / xd, yn / yd };
}

static void add_poly(struct fx_polys *ps, const struct vis_grid *g, const int (*ij)[2], int n,
                     int owner, int light)
{
  struct gpoint pt[8];
  for (int k = 0; k < n; k++) pt[k] = centre_pt(g, ij[k][0], ij[k][1]);
  int rs[2] = { 0, n };
  assert_true(fx_polys_add(ps, 1, rs, pt, owner, light));
}

/* The regions decided sample by sample against stretch by stretch where it is hardest:
   shadow and cut polygons whose vertices and edges pass through the samples themselves.
   lprism's window is 400 x 300 world units, so at cell 4 the samples of lattices K = 1 and
   2 lie on the plane grid; the model's polygons are replaced by such ones (a rectangle, a
   diamond and a triangle with edges of slope 0, 4/5 and 1 through centres). */
static void test_regions_on_samples(void **state)
{
  (void)state;
  struct scene *sc = load_quiet("scenes/lprism.s74");
  struct t74_error err = { 0, "" };
  struct effects e;
  assert_int_equal(effects_parse("halftone=4x4 smooth=phong contour=0.5 shadows=on", &e, "test", 1,
                                 &err), T74_OK);
  struct duo d;
  struct fx_model m;
  struct fx_stats st;
  struct cost cost = { { 0 } };
  model_open(&d, &m, sc, &e, 4, 0, &st, &cost);
  assert_true(m.ncut == 1 && m.shadows.n > 0);
  static const int rect[4][2] = { { 20, 20 }, { 60, 20 }, { 60, 50 }, { 20, 50 } };
  static const int diamond[4][2] = { { 10, 37 }, { 50, 5 }, { 90, 37 }, { 50, 69 } };
  static const int tri[3][2] = { { 30, 10 }, { 70, 10 }, { 50, 30 } };
  fx_polys_free(&m.shadows);
  memset(&m.shadows, 0, sizeof m.shadows);
  for (int f = 0; f < d.eng[0].map->nface; f++) {
    m.shadow_first[f] = m.shadows.n;
    add_poly(&m.shadows, &d.g, rect, 4, f, 0);
    add_poly(&m.shadows, &d.g, diamond, 4, f, 1);
  }
  m.shadow_first[d.eng[0].map->nface] = m.shadows.n;
  fx_polys_free(&m.cuts);
  memset(&m.cuts, 0, sizeof m.cuts);
  add_poly(&m.cuts, &d.g, tri, 3, m.cut_obj[0], 0);
  long on_edge = 0, blocked = 0, cut = 0;
  for (int K = 1; K <= 2; K++) {
    struct fx_lines *L[2];
    assert_int_equal(fx_lines_open(&L[0], &m, false, &cost, &err), T74_OK);
    assert_int_equal(fx_lines_open(&L[1], &m, true, &cost, &err), T74_OK);
    struct fx_see *plain;
    assert_int_equal(fx_see_open(&plain, &d.eng[0], NULL, &cost, &err), T74_OK);
    const int nk = K * (d.W + 2);
    int *fa = calloc((size_t)nk, sizeof *fa), *fb = calloc((size_t)nk, sizeof *fb);
    int *fp = calloc((size_t)nk, sizeof *fp);
    unsigned *ba = calloc((size_t)nk, sizeof *ba), *bb = calloc((size_t)nk, sizeof *bb);
    for (int mr = K * (d.H + 1) - 1; mr >= -K; mr--) {
      assert_int_equal(fx_lines_samples(L[0], K, mr, -K, nk, fa, ba, &err), T74_OK);
      assert_int_equal(fx_lines_samples(L[1], K, mr, -K, nk, fb, bb, &err), T74_OK);
      assert_int_equal(fx_see_row(plain, K, mr, -K, nk, fp, &err), T74_OK);
      for (int i = 0; i < nk; i++) {
        assert_int_equal(fa[i], fb[i]);
        assert_int_equal(ba[i], bb[i]);
        blocked += ba[i] != 0;
        cut += fa[i] != fp[i];
        /* samples on the rectangle's sides (K = 1: every centre of those columns/rows) */
        int k = i - K;
        on_edge += K == 1 && ((k == 20 || k == 60) && mr >= 20 && mr <= 50);
      }
    }
    free(fa); free(fb); free(fp); free(ba); free(bb);
    fx_see_close(plain);
    fx_lines_close(L[0]);
    fx_lines_close(L[1]);
  }
  print_message("regions on the samples: %ld samples on the rectangle's sides, %ld in shadow, "
                "%ld cut\n", on_edge, blocked, cut);
  assert_true(on_edge > 0 && blocked > 0 && cut > 0);
  fx_model_free(&m);
  duo_close(&d);
  scene_free(sc);
}

/* A sample's place in the cut polygons ps[0 .. n): the count of the crossings, of every
   ring's every edge with the line y = yn / yd (its ends on either side, a point on the
   line counting as above it), at or left of xn / xd, as exact rationals: odd when cut. */
static bool cut_by_count(const struct fx_poly *ps, int n, int64_t yn, int64_t yd, int64_t xn,
                         int64_t xd)
{
  const int64_t fy = yn / yd - (yn % yd != 0 && yn < 0);
  int count = 0;
  for (int k = 0; k < n; k++)
    for (int r = 0; r < ps[k].nring; r++) {
      const int a = ps[k].rs[r], np = ps[k].rs[r + 1] - a;
      for (int v = 0; v < np; v++) {
        const struct gpoint p0 = ps[k].pt[a + v], p1 = ps[k].pt[a + (v + 1) % np];
        if ((p0.y <= fy) == (p1.y <= fy)) continue;
        count += geom_rat_cmp_frac(geom_x_at(geom_line(p0, p1), yn, yd), xn, xd) <= 0;
      }
    }
  return count % 2;
}

/* A polygon of rings given as point centres (i + di, j + dj) each moved by (dx, dy) grid
   units. */
static void add_rings(struct fx_polys *ps, const struct vis_grid *g, int nring, const int *rs,
                      const int (*ijd)[4], int di, int dj, int owner)
{
  struct gpoint pt[64];
  assert_true(rs[nring] <= 64);
  for (int k = 0; k < rs[nring]; k++) {
    pt[k] = centre_pt(g, ijd[k][0] + di, ijd[k][1] + dj);
    pt[k].x += ijd[k][2];
    pt[k].y += ijd[k][3];
  }
  assert_true(fx_polys_add(ps, nring, rs, pt, owner, 0));
}

/* The points engine's contour cuts at the samples (cut_samples' way on a rising row: each
   crossing's first sample at or right of it in 64-bit integers, the rings walked in chains
   whose y never falls or never rises, a bit flipped a crossing) against the count of
   crossings at or left of each sample in exact rationals, with polygons made to be hard:
   vertices on the samples and a grid unit off them, edges along a row's line, chains of
   every length (a zigzag, a disc), two polygons overlapping (where both hold a sample the count is
   even: not cut, as the sorted stretches' pairs have it), a ring inside another, polygons
   past both ends of the row; rows asked from the bottom up, then in a scrambled order
   (each chain's last edge found again from anywhere); rows of 102, 204 and 306 samples
   (K = 1, 2, 3: cut_bits keeps up to 256 in registers and flips longer rows' bits in
   memory). */
static void test_cuts_on_points(void **state)
{
  (void)state;
  struct scene *sc = load_quiet("scenes/lprism.s74");
  struct t74_error err = { 0, "" };
  struct effects e;
  assert_int_equal(effects_parse("halftone=4x4 smooth=phong contour=0.5", &e, "test", 1, &err),
                   T74_OK);
  struct duo d;
  struct fx_model m;
  struct fx_stats st;
  struct cost cost = { { 0 } };
  model_open(&d, &m, sc, &e, 4, 1, &st, &cost);
  assert_true(m.ncut == 1 && m.cuts.n > 0);
  const int o = m.cut_obj[0];
  static const int zz[24][4] = {   /* a zigzag: up and down along the top, a flat bottom */
    { 10, 30, 0, 0 }, { 12, 34, 1, 0 }, { 14, 31, 0, -1 }, { 16, 36, 0, 1 }, { 18, 30, -1, 0 },
    { 20, 33, 0, 0 }, { 21, 33, 0, 0 }, { 22, 29, 1, 1 }, { 24, 37, 0, 0 }, { 26, 32, 2, -2 },
    { 28, 32, 0, 0 }, { 30, 38, 0, 1 }, { 31, 20, 0, 0 }, { 29, 22, 0, 0 }, { 27, 18, 1, 0 },
    { 25, 23, 0, -1 }, { 23, 17, 0, 0 }, { 21, 17, 0, 0 }, { 19, 21, -1, 1 }, { 17, 16, 0, 0 },
    { 15, 24, 0, 0 }, { 13, 19, 0, 1 }, { 11, 25, 0, 0 }, { 9, 22, 0, -1 } };
  static const int sq1[4][4] = { { 40, 10, 0, 0 }, { 60, 10, 0, 0 }, { 60, 30, 0, 0 },
                                 { 40, 30, 0, 0 } };
  static const int sq2[4][4] = { { 50, 20, 0, 1 }, { 70, 20, 1, 0 }, { 70, 40, 0, 0 },
                                 { 50, 40, -1, 0 } };
  static const int hole[8][4] = { { 5, 40, 0, 0 }, { 35, 40, 0, 0 }, { 35, 70, 0, 0 },
                                  { 5, 70, 0, 0 }, { 12, 48, 0, 0 }, { 12, 62, 1, 0 },
                                  { 28, 62, 0, 0 }, { 28, 48, 0, -1 } };
  static const int wide_[4][4] = { { -6, 2, 0, 0 }, { 110, 5, 0, 0 }, { 109, 8, 0, 1 },
                                   { -4, 7, 0, 0 } };
  static const int disc[23][4] = {   /* long chains, each point on a row's line, each with
                                        an edge along one */
    { 92, 50, 0, 0 }, { 91, 46, 0, 0 }, { 88, 46, 0, 0 }, { 90, 43, 1, 0 }, { 87, 40, 0, 0 },
    { 84, 39, 0, 0 }, { 80, 38, 0, 0 }, { 76, 39, 0, 0 }, { 73, 40, -1, 0 }, { 70, 43, 0, 0 },
    { 69, 46, 0, 0 }, { 72, 46, 0, 0 }, { 68, 50, 0, 0 }, { 69, 54, 0, 0 }, { 70, 57, 0, 0 },
    { 73, 60, 1, 0 }, { 76, 61, 0, 0 }, { 80, 62, 0, 0 }, { 84, 61, 0, 0 }, { 87, 60, -1, 0 },
    { 90, 57, 0, 0 }, { 88, 57, 0, 0 }, { 91, 54, 0, 0 } };
  const int r1[2] = { 0, 24 }, r4[2] = { 0, 4 }, r8[3] = { 0, 4, 8 }, r23[2] = { 0, 23 };
  /* (the object's faces are seen at about i 33 .. 66, j 24 .. 52) */
  add_rings(&m.cuts, &d.g, 1, r1, zz, 25, 8, o);
  add_rings(&m.cuts, &d.g, 1, r4, sq1, 0, 15, o);
  add_rings(&m.cuts, &d.g, 1, r4, sq2, -10, 12, o);
  add_rings(&m.cuts, &d.g, 2, r8, hole, 28, -12, o);
  add_rings(&m.cuts, &d.g, 1, r4, wide_, 0, 28, o);
  add_rings(&m.cuts, &d.g, 1, r23, disc, -25, -12, o);
  long cut = 0, kept = 0;
  for (int K = 1; K <= 3; K++)
    for (int pass = 0; pass < 2; pass++) {
      struct fx_lines *L;
      assert_int_equal(fx_lines_open(&L, &m, false, &cost, &err), T74_OK);
      assert_false(fx_lines_have_spans(L));
      struct fx_see *plain, *behind;
      assert_int_equal(fx_see_open(&plain, &d.eng[1], NULL, &cost, &err), T74_OK);
      assert_int_equal(fx_see_open(&behind, &d.eng[1], m.cut_skip[0], &cost, &err), T74_OK);
      const int nk = K * (d.W + 2), k0 = -K, nrow = K * (d.H + 2);
      int *fa = calloc((size_t)nk, sizeof *fa), *fp = calloc((size_t)nk, sizeof *fp);
      int *fb = calloc((size_t)nk, sizeof *fb);
      unsigned *ba = calloc((size_t)nk, sizeof *ba);
      assert_true(fa && fp && fb && ba);
      for (int t = 0; t < nrow; t++) {
        /* pass 0: the bottom row first; pass 1: rows 97 apart round the range */
        const int mr = (pass == 0 ? nrow - 1 - t : (int)((97L * t) % nrow)) - K;
        assert_int_equal(fx_lines_samples(L, K, mr, k0, nk, fa, ba, &err), T74_OK);
        assert_int_equal(fx_see_row(plain, K, mr, k0, nk, fp, &err), T74_OK);
        assert_int_equal(fx_see_row(behind, K, mr, k0, nk, fb, &err), T74_OK);
        const int64_t xd = 2 * (int64_t)K * d.W, yd = 2 * (int64_t)K * d.H;
        const int32_t *w = d.g.window;
        const int64_t yn = GRID_ONE * (yd * w[3] - (2 * (int64_t)mr + 1) * (w[3] - w[1]));
        for (int i = 0; i < nk; i++) {
          const int64_t xn = GRID_ONE * (xd * w[0] + (2 * (int64_t)(k0 + i) + 1) * (w[2] - w[0]));
          const bool in = cut_by_count(m.cuts.p, m.cuts.n, yn, yd, xn, xd);
          const bool obj = fp[i] >= 0 && m.cut_skip[0][fp[i]];
          const int want = in && obj ? fb[i] : fp[i];
          if (fa[i] != want)
            print_message("K=%d row %d sample %d: cut %d, want %d (plain %d, in %d)\n", K, mr,
                          k0 + i, fa[i], want, fp[i], in);
          assert_int_equal(fa[i], want);
          cut += in && obj;
          kept += !in && obj;
        }
      }
      free(fa); free(fp); free(fb); free(ba);
      fx_see_close(plain);
      fx_see_close(behind);
      fx_lines_close(L);
    }
  print_message("cuts on the points engine's samples: %ld cut, %ld of the object's kept\n", cut,
                kept);
  assert_true(cut > 1000 && kept > 1000);
  fx_model_free(&m);
  duo_close(&d);
  scene_free(sc);
}

/* The value of counter name in st (0 where it has none). */
static double count_of(const struct fx_stats *st, const char *name)
{
  for (int k = 0; k < st->n; k++)
    if (!strcmp(st->name[k], name)) return st->value[k];
  return 0;
}

/* The points engine's point frame (fx_points: its greys worked out a run of neighbouring
   points of one face at a time: a smoothed face's, a flat face's with its normal found
   once and its lights' directions two points an instruction) is fx_shade's point by
   point, at every point: on the shipped scenes with point lights, shadows and textures,
   on some with smoothing, each with shadows, and on a textured face turned out of every
   coordinate plane (tests/data/scene/tex-slant.s74: fig6-room's are in one, half of the
   reflectance's terms zero). And the frame taken in place (the engine's buffer as its
   faces, where fx_points writes the cuts into the row itself and counts them from the
   samples the cuts wrote) has the same faces, greys and counts as the frame on a copy. */
static void test_points_frame_is_pointwise(void **state)
{
  (void)state;
  static const char *const cases[][2] = {   /* the scene's own effects and more */
    { "fig6-room", "" }, { "fig6-building", "" }, { "lprism", "shadows=on" },
    { "t1-h", "shadows=on" }, { "t1-a", "shadows=on" }, { "edges-telephone", "shadows=on" },
    { "t1-g", "" }, { "../tests/data/scene/tex-slant", "" } };
  static const char *const counts[] = { "contour_points_cut", "contour_points_show_face",
                                        "contour_points_show_background", "shadow_points" };
  enum { NCOUNT = sizeof counts / sizeof counts[0] };
  double counted[NCOUNT] = { 0 };           /* over the cases, on the copy */
  long points = 0, lit_runs = 0, textured = 0, slant = 0;
  int greys[256] = { 0 };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char path[256];
    snprintf(path, sizeof path, "scenes/%s.s74", cases[k][0]);
    struct scene *sc = load_quiet(path);
    struct t74_error err = { 0, "" };
    struct effects e;
    char fx[512];
    snprintf(fx, sizeof fx, "%s %s", sc->effects ? sc->effects : "", cases[k][1]);
    if (effects_parse(fx, &e, "test", 1, &err) != T74_OK) fail_msg("%s", err.msg);
    struct duo d;
    struct fx_model m;
    struct fx_stats st;
    struct cost cost = { { 0 } };
    model_open(&d, &m, sc, &e, e.halftone, 1, &st, &cost);
    assert_false(m.count);                  /* the points engine: greys in runs */
    struct fx_frame f;
    frame_of_points(&f, &d);
    double c0[NCOUNT], c1[NCOUNT];
    for (int c = 0; c < NCOUNT; c++) c0[c] = count_of(&st, counts[c]);
    assert_int_equal(fx_points(&m, &f, &st, &cost, &err), T74_OK);
    for (int c = 0; c < NCOUNT; c++) c1[c] = count_of(&st, counts[c]);
    /* point by point: the faces and lights blocked after the regions, then fx_shade */
    struct fx_lines *L = NULL;
    int *row = malloc((size_t)d.W * sizeof *row);
    unsigned *blocked = calloc((size_t)d.W, sizeof *blocked);
    assert_true(row && blocked);
    if (fx_model_regions(&m)) assert_int_equal(fx_lines_open(&L, &m, false, &cost, &err), T74_OK);
    long bad = 0, shadowed = 0;
    for (int j = d.H - 1; j >= 0; j--) {
      if (L) assert_int_equal(fx_lines_samples(L, 1, j, 0, d.W, row, blocked, &err), T74_OK);
      else memcpy(row, d.face[1] + (size_t)j * (size_t)d.W, (size_t)d.W * sizeof *row);
      for (int i = 0; L && i < d.W; i++) shadowed += blocked[i] != 0;
      for (int i = 0; i < d.W; i++) {
        const size_t at = (size_t)j * (size_t)d.W + (size_t)i;
        assert_int_equal(f.face[at], row[i]);
        int face = row[i];
        int g = fx_shade(&m, face, blocked[i], i + 0.5, j + 0.5, i, j, NULL, NULL);
        if (g != f.grey[at] && bad++ < 4)
          print_message("%s [%s] point (%d, %d) face %d blocked %u: frame %d, fx_shade %d\n",
                        cases[k][0], fx, i, j, face, blocked[i], f.grey[at], g);
        points++;
        greys[f.grey[at]] = 1;
        if (face < 0) continue;
        const struct mface *mf = &m.map->f[face];
        const bool lit = sc->f[mf->sface].grey < 0 && sc->has_light;
        const bool smoothed = m.smooth && e.smooth != EFFECTS_SMOOTH_NONE &&
                              m.sm.tri_of_mface[face] >= 0;
        lit_runs += lit && !smoothed && blocked[i] != 0;
        textured += sc->f[mf->sface].texture != NULL;
        slant += sc->f[mf->sface].texture != NULL && blocked[i] != 0 && strstr(path, "slant");
      }
    }
    assert_int_equal(bad, 0);
    /* fx_points' count of the points in shadow (shadow_ranges', as it sets the masks) */
    if (e.shadows) assert_int_equal((long)(c1[3] - c0[3]), shadowed);
    fx_lines_close(L);
    /* the frame taken in place, the engine's own buffer as fx_points' faces (the
       pipeline's points frame without aa: run_effects): the same faces and greys as on
       the copy (fx_points asks the engine for a row before it writes that row) */
    const size_t np = (size_t)d.W * (size_t)d.H;
    struct fx_frame fin = f;
    assert_non_null(fin.grey = calloc(np, 1));
    fin.face = d.p.face;
    assert_int_equal(fx_points(&m, &fin, &st, &cost, &err), T74_OK);
    long in_place = 0;
    for (size_t at = 0; at < np; at++) in_place += fin.face[at] != f.face[at] || fin.grey[at] != f.grey[at];
    if (in_place) print_message("%s [%s]: %ld points differ in place\n", cases[k][0], fx, in_place);
    assert_int_equal(in_place, 0);
    for (int c = 0; c < NCOUNT; c++) {
      const double on_copy = c1[c] - c0[c], placed = count_of(&st, counts[c]) - c1[c];
      if (placed != on_copy)
        print_message("%s [%s]: %s %.0f in place, %.0f on a copy\n", cases[k][0], fx,
                      counts[c], placed, on_copy);
      assert_true(placed == on_copy);
      counted[c] += on_copy;
    }
    free(fin.grey);
    free(row); free(blocked); free(f.face); free(f.grey);
    fx_model_free(&m);
    duo_close(&d);
    scene_free(sc);
  }
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += greys[g];
  print_message("points frame: %ld points, %ld lit flat points in shadow, %ld textured "
                "(%ld on the turned face in shadow), %d greys; cut %.0f (to a face %.0f, to "
                "none %.0f), in shadow %.0f\n", points, lit_runs, textured, slant, distinct,
                counted[0], counted[1], counted[2], counted[3]);
  assert_true(lit_runs > 1000 && textured > 1000 && slant > 20 && distinct > 100);
  assert_true(counted[0] > 100 && counted[2] > 100 && counted[3] > 1000);
}

/* fx_points' runs of points that see no face, whose ends it finds sixteen points a step
   (the row's last sixteen loaded again where fewer are left): the engine's faces taken
   away in runs of every length from 1 to 40, at the end of rows (0 to 18 points), and at
   every third point of some rows, then each point's grey against fx_shade's. Scenes
   without regions, where fx_points takes the faces as given: smoothed faces (t1-a) and
   plain ones (the street). */
static void test_points_frame_runs_of_none(void **state)
{
  (void)state;
  static const char *const names[] = { "t1-a", "street" };
  long points = 0, none = 0, shaded = 0;
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
    struct effects e;
    struct scene *sc = shipped_with_effects(names[k], &e);
    struct t74_error err = { 0, "" };
    struct duo d;
    struct fx_model m;
    struct fx_stats st;
    struct cost cost = { { 0 } };
    model_open(&d, &m, sc, &e, e.halftone, 1, &st, &cost);
    assert_false(m.count);
    assert_false(fx_model_regions(&m));
    struct fx_frame f;
    frame_of_points(&f, &d);
    for (int j = 0; j < d.H; j++) {
      int *fr = f.face + (size_t)j * (size_t)d.W;
      const int len = 1 + j % 40, a = (j * 37) % d.W, tail = j % 19;
      for (int i = a; i < a + len && i < d.W; i++) fr[i] = -1;
      for (int i = d.W - tail; i < d.W; i++) fr[i] = -1;
      if (j % 5 == 0)
        for (int i = j % 3; i < d.W; i += 3) fr[i] = -1;
    }
    assert_int_equal(fx_points(&m, &f, &st, &cost, &err), T74_OK);
    long bad = 0;
    for (int j = 0; j < d.H; j++)
      for (int i = 0; i < d.W; i++) {
        const size_t at = (size_t)j * (size_t)d.W + (size_t)i;
        const int face = f.face[at];
        const int g = fx_shade(&m, face, 0, i + 0.5, j + 0.5, i, j, NULL, NULL);
        if (g != f.grey[at] && bad++ < 4)
          print_message("%s point (%d, %d) face %d: frame %d, fx_shade %d\n", names[k], i, j,
                        face, f.grey[at], g);
        points++;
        none += face < 0;
        shaded += face >= 0 && g != 0;
      }
    assert_int_equal(bad, 0);
    free(f.face); free(f.grey);
    fx_model_free(&m);
    duo_close(&d);
    scene_free(sc);
  }
  print_message("runs of none: %ld points, %ld see no face, %ld a face's grey other than 0\n",
                points, none, shaded);
  assert_true(none > 2000 && shaded > 4000);
}

/* A row's space points two an instruction (fx_space_points, fx_points' runs of a smoothed
   face) are the doubles of the one-point path (n = 1), bit for bit: every mapped face of
   the smoothed scenes at every point centre of every row, and at positions between them,
   from even and odd starts. */
static void test_space_points_are_single(void **state)
{
  (void)state;
  static const char *const names[] = { "t1-a", "t1-e", "lprism", "sphere", "fig6-room" };
  long compared = 0, bad = 0;
  for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
    struct effects e;
    struct scene *sc = shipped_with_effects(names[k], &e);
    struct duo d;
    struct fx_model m;
    struct fx_stats st;
    struct cost cost = { { 0 } };
    model_open(&d, &m, sc, &e, e.halftone, 1, &st, &cost);
    assert_non_null(m.ray);
    const int W = d.W, n = 2 * W;
    double *px = malloc((size_t)n * sizeof *px), (*X)[3] = malloc((size_t)n * sizeof *X);
    assert_true(px && X);
    const int32_t *win = m.g->window;
    for (int i = 0; i < n; i++)               /* centres, then halfway between them */
      px[i] = win[0] + ((i % W) + (i < W ? 0.5 : 0.25)) * (double)(win[2] - win[0]) / W;
    for (int f = 0; f < m.map->nface; f++)
      for (int j = 0; j < d.H; j++) {
        const double py = win[3] - (j + 0.5) * (double)(win[3] - win[1]) / d.H;
        for (int s0 = 0; s0 < 2; s0++) {      /* pairs from an even start, then an odd one */
          fx_space_points(&m, f, n - s0, px + s0, py, X + s0);
          for (int i = s0; i < n; i++) {
            double one[1][3];
            fx_space_points(&m, f, 1, px + i, py, one);
            compared++;
            if (memcmp(one[0], X[i], sizeof one[0]) && bad++ < 4)
              print_message("%s face %d row %d point %d: %.17g %.17g %.17g, alone %.17g "
                            "%.17g %.17g\n", names[k], f, j, i, X[i][0], X[i][1], X[i][2],
                            one[0][0], one[0][1], one[0][2]);
          }
        }
      }
    free(px); free(X);
    fx_model_free(&m);
    duo_close(&d);
    scene_free(sc);
  }
  print_message("space points: %ld compared\n", compared);
  assert_int_equal(bad, 0);
  assert_true(compared > 1000000);
}

/* The points engine's answer with faces taken away (fx_see_row over a skip list) is
   points_at_row's at every centre and on a finer lattice: with every face taken away (a
   cut object alone in its scene: fx_see_row's shortcut, every sample -1), with all but
   one (the shortcut must not be taken: that face is seen), with none; on a scene of one
   object (t1-e) and one of several (fig5). */
static void test_see_row_without_faces(void **state)
{
  (void)state;
  static const char *const names[] = { "t1-e", "fig5" };
  long seen_one = 0, rows_none = 0;
  for (size_t c = 0; c < sizeof names / sizeof names[0]; c++) {
    char path[256];
    snprintf(path, sizeof path, "scenes/%s.s74", names[c]);
    struct scene *sc = load_quiet(path);
    struct duo d;
    char msg[1024];
    assert_int_equal(duo_open(&d, sc, 3, msg, sizeof msg), T74_OK);
    const int nf = d.p.map.nface;
    uint8_t *skip = calloc((size_t)nf + 1, 1);
    int *a = calloc((size_t)d.W * 2 + 4, sizeof *a), *b = calloc((size_t)d.W * 2 + 4, sizeof *b);
    assert_true(skip && a && b);
    struct points_at q;
    memset(&q, 0, sizeof q);
    struct t74_error err = { 0, "" };
    for (int kind = 0; kind < 3; kind++) {
      for (int k = 0; k < nf; k++) skip[k] = kind == 0 || (kind == 1 && k + 1 < nf);
      struct fx_see *see;
      assert_int_equal(fx_see_open(&see, &d.eng[1], skip, NULL, &err), T74_OK);
      for (int K = 1; K <= 2; K++)
        for (int64_t m = -K; m < (int64_t)K * (d.H + 1); m++) {
          const int64_t k0s[] = { 0, 1, -K };
          for (int h = 0; h < 3; h++) {
            const int64_t k0 = k0s[h];
            const int n = K * d.W - (int)k0 - (h == 1);
            assert_int_equal(fx_see_row(see, K, m, k0, n, a, &err), T74_OK);
            assert_int_equal(points_at_row(&q, &d.p, &d.g, K, m, k0, n, skip, b, &err), T74_OK);
            bool none = true;
            for (int i = 0; i < n; i++) {
              assert_int_equal(a[i], b[i]);
              none = none && a[i] < 0;
              seen_one += kind == 1 && a[i] == nf - 1;
            }
            rows_none += kind == 0 && none;
          }
        }
      fx_see_close(see);
    }
    points_at_free(&q);
    free(skip); free(a); free(b);
    duo_close(&d);
    scene_free(sc);
  }
  print_message("faces taken away: %ld rows of none, %ld samples of the one face left\n",
                rows_none, seen_one);
  assert_true(rows_none > 0 && seen_one > 0);
}

/* fx_x_cmp (effects/poly.h: the order of two crossings from their doubles, exactly) is
   geom_rat_cmp's on 2,000,000 pairs of rationals, their products within 2^126 as the
   crossings' are: random ones, neighbours (numerators 1 or 2 apart), near multiples and
   equal ones; the keys decide most, the exact compare the rest. */
static void test_x_order(void **state)
{
  (void)state;
  uint64_t x = 88172645463325252u;
#define XRND() (x ^= x << 13, x ^= x >> 7, x ^= x << 17, x)
  long bad = 0, keyed = 0, exact = 0;
  for (long it = 0; it < 2000000; it++) {
    const int bn = 1 + (int)(XRND() % 62), bd = 1 + (int)(XRND() % 44);
    wide an = (wide)(XRND() & (((uint64_t)1 << bn) - 1)), ad = (wide)(XRND() % ((uint64_t)1 << bd));
    wide bn2 = (wide)(XRND() & (((uint64_t)1 << bn) - 1));
    if (XRND() & 1) an = -an;
    if (XRND() & 1) bn2 = -bn2;
    struct grat a = { an, ad > 0 ? ad : 1 }, b;
    switch (XRND() % 4) {
    case 0: b = (struct grat){ bn2, 1 + (wide)(XRND() % ((uint64_t)1 << bd)) }; break;
    case 1: b = (struct grat){ a.num + (wide)(XRND() % 5) - 2, a.den }; break;
    case 2: { const wide k = 1 + (wide)(XRND() % 1000);
              b = (struct grat){ a.num * k + (wide)(XRND() % 3) - 1, a.den * k }; break; }
    default: b = (struct grat){ a.num * 3, a.den * 3 }; break;
    }
    const double ka = geom_rat_key(a), kb = geom_rat_key(b);
    bad += fx_x_cmp(&a, ka, &b, kb) != geom_rat_cmp(a, b);
    const double d = kb - ka, t = (fabs(ka) + fabs(kb)) * 0x1p-49;
    if (d > t || -d > t) keyed++; else exact++;
  }
#undef XRND
  print_message("crossing order: %ld pairs by the keys, %ld exactly, %ld wrong\n", keyed, exact, bad);
  assert_int_equal(bad, 0);
  assert_true(keyed > 500000 && exact > 500000);
}

/* Every shipped scene whose effects the points engine runs, as it is and with more. */
static void test_fx_shipped(void **state)
{
  (void)state;
  static const char *const scenes[] = {
    "sphere", "lprism", "t1-a", "t1-b", "t1-c", "t1-d", "t1-e", "t1-f", "t1-g", "t1-h",
    "t1-i", "t1-j", "fig6-building", "fig6-room", "street", "fig10a", "fig7b" };
  struct fx_tally t;
  memset(&t, 0, sizeof t);
  for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; k++) {
    char path[256], name[1024], fx[512];
    snprintf(path, sizeof path, "scenes/%s.s74", scenes[k]);
    struct scene *sc = load_quiet(path);
    struct t74_error err = { 0, "" };
    const char *own = sc->effects ? sc->effects : "";
    struct effects e;
    assert_int_equal(effects_parse(own, &e, "test", 1, &err), T74_OK);
    int cell = e.halftone;
    check_points_at(sc, cell);
    if (!fx_needs_1974(&e) && (sc->effects || sc->has_light)) {
      snprintf(name, sizeof name, "%s [%s]", scenes[k], own);
      judge_fx(sc, cell, own, name, &t);
    }
    /* the same with supersampling (and shadows where there is light) */
    snprintf(fx, sizeof fx, "%s aa=super%s%s", fx_needs_1974(&e) ? "" : own,
             sc->has_light && !e.shadows ? " shadows=on" : "", k % 3 == 1 ? " super=4" : "");
    snprintf(name, sizeof name, "%s [%s]", scenes[k], fx);
    judge_fx(sc, cell, fx, name, &t);
    scene_free(sc);
  }
  fx_report("effects, shipped scenes", &t);
  assert_int_equal(t.bad, 0);
  assert_true(t.scenes >= 25);
  assert_true(t.smoothed >= 12 && t.cut >= 6 && t.shadowed >= 3);
  /* the engines are compared where they differ, and agree nearly everywhere */
  assert_true(t.differ > 0);
  assert_true(t.differ * 1000 < t.samples);
  assert_true(t.grey_differ * 1000 < t.points);
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
  int n = snprintf(cmd, sizeof cmd, "%s %s >/dev/null%s", bin ? bin : "./tube74", args,
                   strstr(args, " 2>") ? "" : " 2>&1");
  assert_true(n > 0 && (size_t)n < sizeof cmd);
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
  /* the points engine's own work: point visits of its spans (some), tiles skipped (none:
     six faces do not cover the grid three times over, render/points.c "Tiles") */
  const char *pv = strstr(js, "\"points_visited\": ");
  assert_non_null(pv);
  assert_true(atol(pv + strlen("\"points_visited\": ")) > 0);
  assert_non_null(strstr(js, "\"points_tiles_skipped\": 0,"));
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
  /* the effects the points engine computes point by point: the same pictures as the 1974
     program's on the shipped scenes that use them (smoothing and contour, a texture and
     shadows, supersampling) */
  static const char *const same[][2] = {
    { "scenes/sphere.s74", "" }, { "scenes/t1-h.s74", "" }, { "scenes/fig6-room.s74", "" },
    { "scenes/fig6-building.s74", "" }, { "scenes/sphere.s74", "--effects 'smooth=phong aa=super'" } };
  for (size_t k = 0; k < sizeof same / sizeof same[0]; k++) {
    for (int e = 0; e < 2; e++) {
      snprintf(a, sizeof a, "render %s %s --engine %s -o %s/s%d.png --dump grey=%s/g%d.pgm "
               "--dump ids=%s/i%d.pgm --stats %s/s%d.json", same[k][0], same[k][1],
               e ? "points" : "1974", dir, e, dir, e, dir, e, dir, e);
      assert_int_equal(run(a), 0);
    }
    for (int f = 0; f < 3; f++) {
      static const char *const kind[] = { "s%d.png", "g%d.pgm", "i%d.pgm" };
      char fa[64], fb[64];
      snprintf(fa, sizeof fa, kind[f], 0);
      snprintf(fb, sizeof fb, kind[f], 1);
      snprintf(path, sizeof path, "%s/%s", dir, fa);
      snprintf(path2, sizeof path2, "%s/%s", dir, fb);
      snprintf(a, sizeof a, "cmp -s %s %s", path, path2);
      assert_int_equal(system(a), 0);
    }
    snprintf(path, sizeof path, "%s/s1.json", dir);
    js = slurp_file(path);
    assert_non_null(js);
    assert_non_null(strstr(js, "\"engine\": \"points\""));
    assert_non_null(strstr(js, "\"hitac10_seconds\": null"));
    assert_non_null(strstr(js, "\"effects\", \"halftone\""));
    free(js);
  }
  /* the effects' own counters under points, and --frames runs them in every frame */
  snprintf(path, sizeof path, "%s/c.json", dir);
  snprintf(a, sizeof a, "render scenes/sphere.s74 --engine points --effects 'smooth=gouraud "
           "aa=super' --frames 2 --stats %s", path);
  assert_int_equal(run(a), 0);
  js = slurp_file(path);
  assert_non_null(strstr(js, "\"smooth_points\": "));
  assert_non_null(strstr(js, "\"aa_samples\": "));
  assert_non_null(strstr(js, "\"operations\": null"));
  free(js);
  /* auto: an import with effects the points engine computes takes it; with an effect on
     the 1974 program's stretches or cuts, the 1974 program */
  static const struct { const char *fx, *engine; } pick[] = {
    { "aa=super", "points" }, { "smooth=gouraud contour=0.5 shadows=on", "points" },
    { "aa=multiscan", "1974" }, { "aa=area", "1974" }, { "edges=on", "1974" } };
  for (size_t k = 0; k < sizeof pick / sizeof pick[0]; k++) {
    snprintf(a, sizeof a, "render tests/data/scene/cube.off --effects '%s' --stats %s", pick[k].fx, path);
    assert_int_equal(run(a), 0);
    js = slurp_file(path);
    char want[64];
    snprintf(want, sizeof want, "\"engine\": \"%s\"", pick[k].engine);
    assert_non_null(strstr(js, want));
    free(js);
  }
  /* what only the 1974 program does is refused under --engine points: exit 2, a message
     naming the effect and why, no output */
  static const char *const refused[][2] = {
    { "aa=multiscan", "aa=multiscan integrates" }, { "aa=area", "aa=area integrates" },
    { "aa=exact", "aa=exact integrates" }, { "'smooth=phong edges=on'", "edges= draws" } };
  snprintf(path, sizeof path, "%s/never.png", dir);
  snprintf(path2, sizeof path2, "%s/err.txt", dir);
  for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
    snprintf(a, sizeof a, "render scenes/sphere.s74 --engine points --effects %s -o %s --stats "
             "%s/never.json 2>%s", refused[k][0], path, dir, path2);
    assert_int_equal(run(a), 2);
    assert_int_equal(access(path, F_OK), -1);
    char *msg = slurp_file(path2);
    assert_non_null(msg);
    assert_non_null(strstr(msg, refused[k][1]));
    assert_non_null(strstr(msg, "--engine 1974"));
    free(msg);
  }
  /* a scene's own effects line is named by its line */
  snprintf(a, sizeof a, "render scenes/edges-prism.s74 --engine points -o %s 2>%s", path, path2);
  assert_int_equal(run(a), 2);
  assert_int_equal(access(path, F_OK), -1);
  char *msg = slurp_file(path2);
  assert_non_null(strstr(msg, "scenes/edges-prism.s74:"));
  free(msg);
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

/* The effects' points to the tube alone a row at a time (cli/pipeline.c run_effects:
   greys_cells and greys_run, tube_write_cells), and the points engine's frame without
   effects (points_emit: runs of one face; over a background picture, the street), give
   what each point in turn gives (emit_point: the path taken when another sink takes the
   dots too, here tube74 tek's): the same picture, ids, greys and tube dots in their order
   (the row paths leave the ids, and without effects or a background the greys, to be
   written from the frame's faces when a dump asks: dumps_settle), under the points engine
   on smoothed, contoured, shadowed and textured scenes and scenes without effects, at the
   first frame and after one. */
static void test_rows_are_pointwise(void **state)
{
  (void)state;
  static const char *const cases[][2] = {
    { "t1-a", "" }, { "t1-e", "" }, { "t1-j", "" }, { "sphere", "" }, { "lprism", "" },
    { "lprism", "halftone=4x4 smooth=prop:0.15" }, { "fig6-room", "" }, { "crossing", "" },
    { "t1-h", "halftone=3x3 smooth=fixed:0.05 shadows=on" }, { "street", "" },
    { "fig5", "" }, { "fig5", "halftone=3x3" } };
  char dir[] = "/tmp/tube74-engines-rows-XXXXXX";
  assert_non_null(mkdtemp(dir));
  static const char *const kinds[] = { "png", "ids", "grey", "tube" };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
    for (int frames = 1; frames <= 2; frames++) {
      char fx[256] = "", a[4096], c[2048];
      if (cases[k][1][0]) snprintf(fx, sizeof fx, "--effects '%s'", cases[k][1]);
      for (int w = 0; w < 2; w++) {         /* w = 0: render; 1: tek */
        snprintf(a, sizeof a, "%s scenes/%s.s74 --engine points --frames %d %s%s -o %s/%d.png "
                 "--dump ids=%s/%d.ids --dump grey=%s/%d.grey --dump tube=%s/%d.tube",
                 w ? "tek" : "render", cases[k][0], frames, fx, w ? " -o /dev/null" : "",
                 dir, w, dir, w, dir, w, dir, w);
        assert_int_equal(run(a), 0);
      }
      for (size_t q = 0; q < sizeof kinds / sizeof kinds[0]; q++) {
        snprintf(c, sizeof c, "cmp -s %s/0.%s %s/1.%s", dir, kinds[q], dir, kinds[q]);
        if (system(c) != 0) fail_msg("%s [%s] --frames %d: the %s differ", cases[k][0],
                                     cases[k][1], frames, kinds[q]);
      }
    }
  char a[600];
  snprintf(a, sizeof a, "rm -rf %s", dir);
  assert_int_equal(system(a), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_cli),
    cmocka_unit_test(test_rows_are_pointwise),
    cmocka_unit_test(test_shipped),
    cmocka_unit_test(test_fuzz_corpus),
    cmocka_unit_test(test_fx_shipped),
    cmocka_unit_test(test_regions_on_samples),
    cmocka_unit_test(test_cuts_on_points),
    cmocka_unit_test(test_points_frame_is_pointwise),
    cmocka_unit_test(test_points_frame_runs_of_none),
    cmocka_unit_test(test_space_points_are_single),
    cmocka_unit_test(test_see_row_without_faces),
    cmocka_unit_test(test_x_order),
    cmocka_unit_test(test_scenegen_families),
    cmocka_unit_test(test_hard_families),
    cmocka_unit_test(test_far_vertices),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
