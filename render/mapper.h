/*
** mapper.h — the Mapper of paper 003 (§2.2, eq. (1), eq. (2)): space to perspective plane.
**
** The Mapper projects every vertex onto the plane z = 0 seen from the eye (eq. (1)),
** rounds it once onto the plane grid (geom.h), computes each face's plane a x + b y + c z
** + d = 0 exactly from three of its vertices (eq. (2)), and orients the projected rings so
** that the face lies on the left of every edge (outer ring counter-clockwise, holes
** clockwise), whatever orientation the scene gave. Faces seen exactly edge-on (their plane
** contains the eye) cover no point and are dropped.
*/
#ifndef T74_MAPPER_H
#define T74_MAPPER_H

#include <stdint.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"
#include "render/scene.h"
#include "render/pool.h"

struct mface {               /* 96 bytes: the 32-bit fields first, then the 64-bit ones */
  uint32_t id;              /* input face number */
  uint32_t on;              /* `on F`: the number F of the face this pattern lies on, 0 none
                               (a coplanar tie goes to the pattern: render/priority.c) */
  int      sface;           /* index in scene.f */
  int      sline;           /* source line of the face statement */
  int      nring;
  uint8_t  grey;            /* 0..255: the face's uniform intensity (grey, or Lambert) */
  bool     pooled;          /* ring_start, pt, vid and vix live in the mapped scene's pool
                               (mapper_run's faces), freed by mapper_free; else each is
                               its own allocation (faces split into triangles) */
  int64_t  plane[4];        /* a, b, c, d of eq. (2), signed so that plane(eye) < 0 */
  int64_t  deye;            /* |plane(eye)| > 0 */
  int     *ring_start;      /* nring + 1 offsets into pt/vid/vix */
  struct gpoint *pt;        /* projected, on the grid; outer CCW, holes CW */
  uint32_t *vid;            /* vertex ids */
  int32_t  *vix;            /* the vertices' indices in scene.v: their places in space
                               (exact), for tests on both planes (mface_coord) */
};

struct mapped {
  int nface;                /* faces kept */
  struct mface *f;
  int dropped;              /* faces dropped: edge-on to the eye or zero projected area */
  int cap;                  /* entries f has room for */
  int split;                /* faces split into triangles because rounding made them
                               not simple (mapper_split_face) */
  int64_t eye[3];           /* X0, Y0, Z0 (world units) */
  const struct scene_vertex *sv;   /* the scene's vertices (what vix indexes): the scene
                               outlives its mapped faces */
  struct gpoint *proj;      /* each scene vertex projected onto the plane grid (pt[k] is
                               proj[vix[k]]): kept by a run without a cost (the points
                               engine, which works out each vertex's row and column once
                               a frame), else NULL; freed by mapper_free */
  struct pool pool;         /* host blocks holding pooled faces' arrays (issue 12: one
                               malloc a face fewer), freed by mapper_free */
};

/* Coordinate c (0 x, 1 y, 2 z) of point k of face f in space, exactly: its scene vertex
   (the Mapper keeps no copy of it). */
static inline int32_t mface_coord(const struct mapped *m, const struct mface *f, int k, int c)
{
  const struct scene_vertex *v = &m->sv[f->vix[k]];
  return c == 0 ? v->x : c == 1 ? v->y : v->z;
}

/* The tie between coplanar faces (both engines' rule): is A in front of B? A pattern lying
   on the other face (`on F`; paper 000 §3.2: a pattern is in front of its face) is; else a
   pattern is in front of a face that is none; else the larger face number is. */
static inline bool mface_coplanar_front(const struct mface *A, const struct mface *B)
{
  if (A->on && A->on == B->id) return true;
  if (B->on && B->on == A->id) return false;
  if ((A->on != 0) != (B->on != 0)) return A->on != 0;
  return A->id > B->id;
}

/* Equal depth at a point (it lies on the two planes' intersection line): is A in front of
   B? The face in front just right of the point, then just above it: the sign of
   |D_B| a_A - |D_A| a_B, then of the b's (the tie rule of the edges, the point shifted by
   (e, e^2); |D| < 2^52, |a|, |b| < 2^34: 128-bit); planes of equal depth everywhere
   (coplanar): mface_coplanar_front. Both engines' rule (render/points.c, points_at.c). */
static inline bool mface_tie_front(const struct mface *A, const struct mface *B)
{
  for (int c = 0; c < 2; c++) {
    wide l = (wide)B->deye * A->plane[c], r = (wide)A->deye * B->plane[c];
    if (l != r) return l > r;
  }
  return mface_coplanar_front(A, B);
}

/* Map a checked scene. T74_EINPUT when a vertex projects outside the plane grid. The 1974
   program's operations are added to cost; cost NULL: not counted (the points engine
   reports no 1974 figures), and the VERTEX and A-BLOCK rows are reserved in core
   (core_reserve: not zeroed) but not written (nothing under the points engine reads
   them: --dump core and tables need the 1974 program). */
int mapper_run(const struct scene *s, struct mapped *out, struct core *core,
               struct cost *cost, struct t74_error *err);

/* What mapper_run keeps from one run to the next of the same scene (issue 19, --frames):
   the T-junctions as it found them, each face's rings with the vertices lying on its
   edges inserted, and the operations the search was charged; and the host blocks and the
   table of the last run's faces (mapper_keep_faces). Host memory only. */
struct mapper_keep {
  const struct scene *s;    /* the scene the T-junctions are of; NULL: none found yet */
  int *ring;                /* scene ring g (face f's ring r is g = f's first + r):
                               ring[start[g] .. start[g + 1]) */
  int *start;               /* one more than the scene's rings */
  int  n, cap;              /* entries of ring, room */
  struct cost cost;         /* what the search charged (the 1974 program's x-slab scans
                               and exact tests), when counted */
  bool counted;             /* the search was run with a cost (the 1974 engine), so cost
                               holds its charges; else (the points engine, cost NULL) they
                               were not counted, and a run with a cost searches again */
  int64_t (*plane)[4];      /* scene face f's plane of eq. (2), as found from three of
                               its vertices (all zero: none), kept with the T-junctions
                               (it depends on the scene alone; its sign, on the eye, is
                               taken every run) */
  uint8_t (*lgrey)[2];      /* scene face f's grey by Lambert's law under the scene's one
                               parallel light, of its plane as kept ([0]) and turned
                               ([1]: the plane's sign taken from the eye, the one a run
                               uses); kept with the planes (the scene alone: a replay
                               makes neither the denominator's root nor the divide) */
  struct pool pool;         /* blocks for the next run's faces */
  struct mface *f;          /* the last run's table of faces, for the next run (NULL:
                               none); every entry a run uses is written whole */
  int fcap;                 /* entries f has room for */
  bool whole_boxes;         /* the search looks at every cell of an edge's box, not only
                               those a slanted edge can reach, and at every edge, also
                               one met before the other way (the long way, which tests
                               compare with: the same vertices found, the same charges) */
  int  replayed;            /* edges not searched: met before (host statistic) */
  bool once;                /* set by the caller: the scene is mapped once (one frame), so
                               nothing is kept for a next run: the face planes are not
                               stored and the rings are freed when mapped (issue 19: 100,000
                               boxes, 5 MB less alive at the frame's peak); the faces, the
                               T-junctions found and the charges are those of any run */
};

/* mapper_run with what k keeps: when k holds the T-junctions of s, they are taken from it
   and its charges added to cost, as the search would have charged them (the mapped scene,
   the core and the counts are those of mapper_run); otherwise they are searched for as
   mapper_run does and, when the scene maps, kept in k. The faces' arrays take k's blocks. */
int mapper_run_kept(const struct scene *s, struct mapped *out, struct core *core,
                    struct cost *cost, struct mapper_keep *k, struct t74_error *err);

/* Before mapper_free: m's blocks and table of faces to k, for the next mapper_run_kept
   (m is left without faces). */
void mapper_keep_faces(struct mapped *m, struct mapper_keep *k);

void mapper_keep_free(struct mapper_keep *k);

/* Face k, whose grid polygon the Segment Generator refused as not simple (the rounding
   of its vertices, seen almost edge-on or from far away, folded it), is split into
   triangles by exact ear clipping in its own plane, before rounding matters (holes first
   joined to the outer ring by bridges between vertices in sight of each other): every
   triangle keeps the face's number, plane and grid points, and is simple on the grid
   (or covers no point). Face k becomes the first triangle, the others are appended;
   *ntri is how many remain (0: none covers a point, face k is left as it was).
   T74_EINPUT (err untouched) when the rings are not simple in the plane either (the
   Mapper dropped vertices that rounded onto their predecessor) or no split was found. */
int mapper_split_face(struct mapped *m, int k, struct core *core, struct cost *cost,
                      int *ntri, struct t74_error *err);

void mapper_free(struct mapped *m);

/* Vertex v (index in scene.v) on the plane grid, exactly as mapper_run places it (eq. (1),
   rounded once, half up); for later stages that need a vertex the Mapper's faces dropped. */
struct gpoint mapper_point(const struct scene *s, int v);

#endif
