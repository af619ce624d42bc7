/*
** render.c — the renderer's stages in the order of paper 003, Fig. 1.
**
** This file contains code to run, for one scene, the Mapper (eq. (1), (2)), the Segment
** Generator on every face (§3.1), then set up the Priority Matrix (Fig. 9) and the Visible
** Surface Procedure (§4), all with their tables in the machine's core. Operations are
** counted per stage so the 1974 time can be reported stage by stage.
**
** Cut while displaying (§3.1: faces are cut bottom to top "so that the picture is shown
** while it is computed"): with render_prepare_lazy the scan drives the Segment Generator
** through the Visible Surface Procedure's feed hook: before each line every face whose
** lowest vertex the line has reached is cut (order: lowest y, then the Mapper's number),
** and render_scan cuts the faces above its last line at the end, so the pieces never
** depend on the window. The Priority Matrix's store is then chosen from an estimate of
** the pieces (pieces_estimate), the pieces themselves not existing yet.
*/
#include "render/render.h"

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/rsort.h"
#include "render/segment.h"

/* A face whose grid polygon the Segment Generator refuses was simple in the scene (the
   scene reader checked it exactly): the rounding of its vertices folded it. It is split
   into triangles in space (mapper_split_face, holes joined by bridges) and the triangles
   are segmented instead; a face that cannot be split so is refused at its line, naming
   the rounding. */
static int segment_face(struct render *r, const struct scene *s, int k, struct t74_error *err)
{
  struct cost *cost = &r->cost[RS_SEGMENT];
  struct cost *was = r->seg.cost;
  r->seg.cost = cost;
  int st = T74_OK;
  {
    const struct mface *f = &r->map.f[k];
    struct seg_input in = { f->id, f->nring, f->ring_start, f->pt, f->vid, r->seg.n + 1 };
    struct seg_result res = { 0 };
    struct gline cl[SEG_CONVEX_MAX];       /* a convex face's one piece (seg_convex) */
    int cn = 0;
    st = seg_convex(&in, &r->seg.yname, cl, &cn, r->tables, r->core, cost, err);
    if (st == T74_OK && cn == 0) st = seg_generate(&in, &res, r->tables, r->core, cost, err);
    if (st == T74_EINPUT && r->arith == GEOM_HITAC) {
      /* --arith hitac: the 1974 coordinates folded the face; that program would have
         drawn nothing sensible of it: skip it, with a counted warning */
      fprintf(stderr, "%s:%d: warning: face %u: its 1974 (one-word) coordinates fold it "
              "(%s); not drawn (--arith hitac)\n", s->file, f->sline, (unsigned)f->id, err->msg);
      memset(err, 0, sizeof *err);
      seg_result_free(&res);
      r->arith_skipped++;
      st = T74_OK;
      goto out;
    }
    if (st == T74_EINPUT) {
      seg_result_free(&res);
      char why[sizeof err->msg];
      snprintf(why, sizeof why, "%s", err->msg);
      memset(err, 0, sizeof *err);
      int ntri = 0;
      st = mapper_split_face(&r->map, k, r->core, cost, &ntri, err);
      if (st == T74_EINPUT) {
        st = t74_fail_at(err, T74_EINPUT, s->file, f->sline,
                           "face %u: rounded onto the plane grid (1/%d unit) its boundary is "
                           "no longer simple (%s), and no split into triangles was found; it "
                           "is seen almost edge-on or from far away: move the eye or the face",
                           (unsigned)f->id, (int)GRID_ONE, why);
        goto out;
      }
      if (st != T74_OK) goto out;
      if (ntri == 0) goto out;
      f = &r->map.f[k];
      struct seg_input tin = { f->id, f->nring, f->ring_start, f->pt, f->vid, r->seg.n + 1 };
      st = seg_generate(&tin, &res, r->tables, r->core, cost, err);
      if (st == T74_EINPUT) {
        snprintf(why, sizeof why, "%s", err->msg);
        memset(err, 0, sizeof *err);
        seg_result_free(&res);
        st = t74_fail_at(err, T74_EINPUT, s->file, f->sline,
                         "face %u: a triangle of it, rounded onto the plane grid, was "
                         "refused: %s", (unsigned)f->id, why);
        goto out;
      }
    }
    if (st != T74_OK) {
      seg_result_free(&res);
      goto out;
    }
    r->concave_splits += res.ncut;
    if (cn > 0 && seginfo_add_face(&r->seg, k, cn, f->pt, cl, err) < 0) st = err->status;
    for (int p = 0; p < res.npiece && st == T74_OK; p++)
      if (seginfo_add(&r->seg, k, res.piece[p].n, res.piece[p].line, err) < 0) st = err->status;
    seg_result_free(&res);
  }
out:
  r->seg.cost = was;
  return st;
}

/* The lowest grid y of mapped face k (its lowest vertex). */
static int64_t face_ymin(const struct mface *f)
{
  int64_t y = f->pt[0].y;
  for (int i = 1; i < f->ring_start[f->nring]; i++) if (f->pt[i].y < y) y = f->pt[i].y;
  return y;
}

/* Put face k into the order faces are cut in, among those not cut yet: lazily by lowest
   y (after the faces of equal y, so ties go by number in the Mapper's table: exact
   integers); otherwise last, the Mapper's order. */
static int order_add(struct render *r, int k)
{
  if (r->cut_n == r->cut_cap) {
    int cap = r->cut_cap ? 2 * r->cut_cap : 16;
    int *o = realloc(r->cut_order, (size_t)cap * sizeof *o);
    if (!o) return 0;
    r->cut_order = o;
    int64_t *yy = realloc(r->cut_y, (size_t)cap * sizeof *yy);
    if (!yy) return 0;
    r->cut_y = yy;
    r->cut_cap = cap;
  }
  int i = r->cut_n++;
  int64_t y = face_ymin(&r->map.f[k]);
  if (r->lazy) {
    while (i > r->cut_next && r->cut_y[i - 1] > y) {
      r->cut_order[i] = r->cut_order[i - 1];
      r->cut_y[i] = r->cut_y[i - 1];
      i--;
    }
  }
  r->cut_order[i] = k;
  r->cut_y[i] = y;
  return 1;
}

/* The Mapper's faces in the order they are cut: lazily by lowest y, ties by number in
   the Mapper's table, exactly as order_add would put them one by one (whose insertion
   grows as n^2 when faces come in no y order: 44% of a frame at 100,000 boxes), by one
   sort of (lowest y, number) pairs (render/rsort.h); otherwise the Mapper's order. */

static int order_init(struct render *r)
{
  int n = r->map.nface;
  r->cut_cap = n > 16 ? n : 16;
  r->cut_order = malloc((size_t)r->cut_cap * sizeof *r->cut_order);
  r->cut_y = malloc((size_t)r->cut_cap * sizeof *r->cut_y);
  if (!r->cut_order || !r->cut_y) return 0;
  r->cut_n = n;
  if (!r->lazy) {
    for (int k = 0; k < n; k++) { r->cut_order[k] = k; r->cut_y[k] = face_ymin(&r->map.f[k]); }
    return 1;
  }
  struct rs_pair *t = malloc((size_t)(n ? 2 * n : 1) * sizeof *t);
  if (!t) return 0;
  for (int k = 0; k < n; k++) { t[k].key = face_ymin(&r->map.f[k]); t[k].idx = k; }
  rsort_pairs(t, t + n, n);
  for (int k = 0; k < n; k++) { r->cut_order[k] = t[k].idx; r->cut_y[k] = t[k].key; }
  free(t);
  return 1;
}

/* Cut, in order, every face not yet cut whose lowest vertex is at or below the line
   y = yn / yd (yd > 0; every face when yd == 0). A face split into triangles
   (mapper_split_face) appends the others to the Mapper's table: they join the order. */
static int cut_upto(struct render *r, int64_t yn, int64_t yd, struct t74_error *err)
{
  while (r->cut_next < r->cut_n) {
    int k = r->cut_order[r->cut_next];
    if (yd > 0) {
      COST_ADD_N(&r->cost[RS_SEGMENT], COST_MEM, 2);   /* the face's y-min against the line */
      if ((wide)r->cut_y[r->cut_next] * yd > (wide)yn) break;
    }
    r->cut_next++;
    int before = r->map.nface;
    int st = segment_face(r, r->scene, k, err);
    if (st != T74_OK) return st;
    for (int n = before; n < r->map.nface; n++)
      if (!order_add(r, n)) return t74_fail(err, T74_EIO, "out of host memory");
  }
  return T74_OK;
}

static int feed(void *ctx, int64_t yn, int64_t yd, struct t74_error *err)
{
  return cut_upto(ctx, yn, yd, err);
}

/* An estimate of the pieces a scene is cut into, from the scene alone (for the Priority
   Matrix's dense/sparse choice before the pieces exist): one per face plus two per
   concave vertex (each cut through concave vertices adds at most two pieces per vertex
   on its line). */
static uint64_t pieces_estimate(const struct mapped *m)
{
  uint64_t n = 0;
  for (int k = 0; k < m->nface; k++) {
    const struct mface *f = &m->f[k];
    n++;
    for (int r = 0; r < f->nring; r++) {
      int lo = f->ring_start[r], cnt = f->ring_start[r + 1] - lo;
      const struct gpoint *p = f->pt + lo;
      for (int i = 0, h = cnt - 1; i < cnt; h = i++)       /* (no divide a vertex) */
        if (geom_orient(p[h], p[i], p[i + 1 < cnt ? i + 1 : 0]) < 0) n += 2;
    }
  }
  return n;
}

/* --arith hitac: X', Y' as the 1974 Mapper held them, one word each in whole world units
   (eq. (1) by a 16 x 16 multiply and a 32 / 16 divide: the quotient, truncated toward
   zero). A vertex that lay exactly on another face's edge (a T-junction) may now lie
   beside it: the cracks of 1974 arithmetic. */
static void hold_h10(struct mapped *m)
{
  for (int k = 0; k < m->nface; k++) {
    struct mface *f = &m->f[k];
    for (int v = 0; v < f->ring_start[f->nring]; v++) {
      f->pt[v].x = f->pt[v].x / GRID_ONE * GRID_ONE;
      f->pt[v].y = f->pt[v].y / GRID_ONE * GRID_ONE;
    }
  }
}

static int prepare(struct render *r, const struct scene *s, const struct render_opts *o,
                   bool lazy, int arith, struct t74_error *err)
{
  memset(r, 0, sizeof *r);
  r->tables = o->tables;
  r->faces_in = s->nf;
  r->keep = o->keep;
  if (o->keep && o->keep->core && core_renew(o->keep->core, o->core_words) == 0) {
    r->core = o->keep->core;                 /* a core of the last frame, made as new */
    o->keep->core = NULL;
  } else
    r->core = core_new(o->core_words);
  if (!r->core) return t74_fail(err, T74_EIO, "out of host memory for %u words of core",
                                o->core_words);
  core_set_growth(r->core, o->core_max);
  seginfo_init(&r->seg, r->core, &r->cost[RS_SEGMENT]);
  uint32_t prog;
  if (o->program_words && core_alloc(r->core, CORE_T_PROGRAM, o->program_words, &prog, err) != T74_OK)
    return err->status;

  r->ran[RS_MAPPER] = 1;
  if (o->keep) {                             /* the last frame's blocks for the pieces */
    r->seg.pool = o->keep->seg;
    memset(&o->keep->seg, 0, sizeof o->keep->seg);
  }
  int st = mapper_run_kept(s, &r->map, r->core, &r->cost[RS_MAPPER],
                           o->keep ? &o->keep->map : NULL, err);
  if (st != T74_OK) return st;
  r->arith = arith;
  if (arith == GEOM_HITAC) hold_h10(&r->map);

  r->ran[RS_SEGMENT] = 1;
  r->scene = s;
  r->lazy = lazy;
  if (!order_init(r)) return t74_fail(err, T74_EIO, "out of host memory");
  uint64_t expect;
  if (lazy) {
    /* the scan drives the Segment Generator (cut_upto, from vis_spans): the matrix's
       starting store is chosen from the pieces the scene is expected to be cut into */
    expect = pieces_estimate(&r->map);
    /* the pieces' table from it, an eighth more for the cuts along intersection lines
       (beyond that it doubles) */
    uint64_t room = expect + expect / 8 + 64;
    if (room < INT_MAX / 2 && !seginfo_reserve(&r->seg, (int)room))
      return t74_fail(err, T74_EIO, "out of host memory");
  } else {
    st = cut_upto(r, 0, 0, err);
    if (st != T74_OK) return st;
    expect = (uint64_t)r->seg.n;
  }

  r->seg.cost = &r->cost[RS_VISIBLE];
  st = prio_init(&r->prio, &r->seg, &r->map, r->core, &r->cost[RS_VISIBLE], o->store,
                  expect, err);
  if (st != T74_OK) return st;
  if (o->keep) prio_keep_take(&r->prio, &o->keep->prio);
  r->prio.trace = o->tables;
  r->prio.arith = arith;
  st = vis_init(&r->vis, &r->seg, &r->prio, &r->cost[RS_VISIBLE], err);
  if (st != T74_OK) return st;
  r->vis.arith = arith;
  if (lazy) {
    r->vis.feed = feed;
    r->vis.feed_ctx = r;
  }
  return T74_OK;
}

int render_prepare(struct render *r, const struct scene *s, const struct render_opts *o,
                   struct t74_error *err)
{
  return prepare(r, s, o, false, GEOM_EXACT, err);
}

int render_prepare_lazy(struct render *r, const struct scene *s, const struct render_opts *o,
                        struct t74_error *err)
{
  return prepare(r, s, o, true, GEOM_EXACT, err);
}

int render_prepare_lazy_arith(struct render *r, const struct scene *s,
                              const struct render_opts *o, int arith, struct t74_error *err)
{
  return prepare(r, s, o, true, arith, err);
}

int render_scan(struct render *r, const struct vis_grid *g, vis_point_fn point, void *ctx,
                struct t74_error *err)
{
  r->ran[RS_VISIBLE] = 1;
  int st = vis_scan(&r->vis, g, point, ctx, err);
  /* the faces the scan never reached (above the window's top row) are cut too, so that
     the pieces and their counts do not depend on the window */
  if (st == T74_OK) st = cut_upto(r, 0, 0, err);
  r->vis.feed = NULL;
  if (st == T74_OK && r->tables) {
    fprintf(r->tables, "\n");
    prio_dump(&r->prio, r->tables);
  }
  return st;
}

int render_pieces_alive(const struct render *r)
{
  int n = 0;
  for (int k = 0; k < r->seg.n; k++) n += r->seg.p[k].alive;
  return n;
}

void render_keep_free(struct render_keep *k)
{
  mapper_keep_free(&k->map);
  core_free(k->core);
  k->core = NULL;
  pool_free(&k->seg);
  prio_keep_free(&k->prio);
}

void render_free(struct render *r)
{
  free(r->cut_order);
  free(r->cut_y);
  r->cut_order = NULL;
  r->cut_y = NULL;
  vis_free(&r->vis);
  if (r->keep) prio_keep_give(&r->prio, &r->keep->prio);
  prio_free(&r->prio);
  if (r->keep) {                             /* the blocks, for the next frame */
    pool_reset(&r->seg.pool);
    pool_free(&r->keep->seg);
    r->keep->seg = r->seg.pool;
    memset(&r->seg.pool, 0, sizeof r->seg.pool);
    mapper_keep_faces(&r->map, &r->keep->map);
  }
  seginfo_free(&r->seg);
  mapper_free(&r->map);
  if (r->keep && r->core) {
    core_free(r->keep->core);
    r->keep->core = r->core;
  } else
    core_free(r->core);
  r->core = NULL;
}
