/*
** render.c — the renderer's stages in the order of paper 003, Fig. 1.
**
** This file contains code to run, for one scene, the Mapper (eq. (1), (2)), the Segment
** Generator on every face (§3.1), then set up the Priority Matrix (Fig. 9) and the Visible
** Surface Procedure (§4), all with their tables in the machine's core. Operations are
** counted per stage so the 1974 time can be reported stage by stage.
*/
#include "render/render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/segment.h"

/* A face whose grid polygon the Segment Generator refuses was simple in the scene (the
   scene reader checked it exactly): the rounding of its vertices folded it. It is split
   into triangles in space (mapper_split_face, holes joined by bridges) and the triangles
   are segmented instead; a face that cannot be split so is refused at its line, naming
   the rounding. */
static int segment_all(struct render *r, const struct scene *s, struct t74_error *err)
{
  struct cost *cost = &r->cost[RS_SEGMENT];
  r->seg.cost = cost;
  for (int k = 0; k < r->map.nface; k++) {
    const struct mface *f = &r->map.f[k];
    struct seg_input in = { f->id, f->nring, f->ring_start, f->pt, f->vid };
    struct seg_result res = { 0 };
    int st = seg_generate(&in, &res, r->tables, r->core, cost, err);
    if (st == T74_EINPUT && r->arith == GEOM_HITAC) {
      /* --arith hitac: the 1974 coordinates folded the face; that program would have
         drawn nothing sensible of it: skip it, with a counted warning */
      fprintf(stderr, "%s:%d: warning: face %u: its 1974 (one-word) coordinates fold it "
              "(%s); not drawn (--arith hitac)\n", s->file, f->sline, (unsigned)f->id, err->msg);
      memset(err, 0, sizeof *err);
      seg_result_free(&res);
      r->arith_skipped++;
      continue;
    }
    if (st == T74_EINPUT) {
      seg_result_free(&res);
      char why[sizeof err->msg];
      snprintf(why, sizeof why, "%s", err->msg);
      memset(err, 0, sizeof *err);
      int ntri = 0;
      st = mapper_split_face(&r->map, k, r->core, cost, &ntri, err);
      if (st == T74_EINPUT)
        return t74_fail_at(err, T74_EINPUT, s->file, f->sline,
                           "face %u: rounded onto the plane grid (1/%d unit) its boundary is "
                           "no longer simple (%s), and no split into triangles was found; it "
                           "is seen almost edge-on or from far away: move the eye or the face",
                           (unsigned)f->id, (int)GRID_ONE, why);
      if (st != T74_OK) return st;
      if (ntri == 0) continue;
      f = &r->map.f[k];
      struct seg_input tin = { f->id, f->nring, f->ring_start, f->pt, f->vid };
      st = seg_generate(&tin, &res, r->tables, r->core, cost, err);
      if (st == T74_EINPUT) {
        snprintf(why, sizeof why, "%s", err->msg);
        memset(err, 0, sizeof *err);
        seg_result_free(&res);
        return t74_fail_at(err, T74_EINPUT, s->file, f->sline,
                           "face %u: a triangle of it, rounded onto the plane grid, was "
                           "refused: %s", (unsigned)f->id, why);
      }
    }
    if (st != T74_OK) {
      seg_result_free(&res);
      return st;
    }
    r->concave_splits += res.ncut;
    for (int p = 0; p < res.npiece; p++)
      if (seginfo_add(&r->seg, k, res.piece[p].n, res.piece[p].line, err) < 0) {
        seg_result_free(&res);
        return err->status;
      }
    seg_result_free(&res);
  }
  return T74_OK;
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

int render_prepare(struct render *r, const struct scene *s, const struct render_opts *o,
                   struct t74_error *err)
{
  return render_prepare_arith(r, s, o, GEOM_EXACT, err);
}

int render_prepare_arith(struct render *r, const struct scene *s, const struct render_opts *o,
                         int arith, struct t74_error *err)
{
  memset(r, 0, sizeof *r);
  r->tables = o->tables;
  r->faces_in = s->nf;
  r->core = core_new(o->core_words);
  if (!r->core) return t74_fail(err, T74_EIO, "out of host memory for %u words of core",
                                o->core_words);
  seginfo_init(&r->seg, r->core, &r->cost[RS_SEGMENT]);
  uint32_t prog;
  if (o->program_words && core_alloc(r->core, CORE_T_PROGRAM, o->program_words, &prog, err) != T74_OK)
    return err->status;

  r->ran[RS_MAPPER] = 1;
  int st = mapper_run(s, &r->map, r->core, &r->cost[RS_MAPPER], err);
  if (st != T74_OK) return st;
  r->arith = arith;
  if (arith == GEOM_HITAC) hold_h10(&r->map);

  r->ran[RS_SEGMENT] = 1;
  st = segment_all(r, s, err);
  if (st != T74_OK) return st;

  r->seg.cost = &r->cost[RS_VISIBLE];
  st = prio_init(&r->prio, &r->seg, &r->map, r->core, &r->cost[RS_VISIBLE], o->store, err);
  if (st != T74_OK) return st;
  r->prio.trace = o->tables;
  r->prio.arith = arith;
  st = vis_init(&r->vis, &r->seg, &r->prio, &r->cost[RS_VISIBLE], err);
  r->vis.arith = arith;
  return st;
}

int render_scan(struct render *r, const struct vis_grid *g, vis_point_fn point, void *ctx,
                struct t74_error *err)
{
  r->ran[RS_VISIBLE] = 1;
  int st = vis_scan(&r->vis, g, point, ctx, err);
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

void render_free(struct render *r)
{
  vis_free(&r->vis);
  prio_free(&r->prio);
  seginfo_free(&r->seg);
  mapper_free(&r->map);
  core_free(r->core);
  r->core = NULL;
}
