/*
** points.h — the points engine (--engine points): the visible face at every point centre of
** the perspective-plane grid, decided exactly point by point, without the 1974 program.
**
** The question is the one the Visible Surface Procedure answers for each point (paper 003
** §4), asked directly: which of the Mapper's faces (render/mapper.h, the same grid
** polygons and exact planes as the 1974 engine) covers the point's centre and is nearest
** the eye there. Each face's grid polygon is rasterised by exact scanline crossings into a
** per-point buffer of (face, depth bounds); depths are compared exactly: in doubles where
** a proven error bound decides, else in 128-bit integers (points.c). Where faces overlap
** deeply, tiles of the grid keep a bound of the depth stored, so that a face's parts
** proven behind are skipped without visiting their points, and the faces are drawn nearest
** first: the frame is the same in any order (points.c, "Tiles" and "Order").
** Nothing of the HITAC-10 is modelled: no core budget, no operation counts, no 1974 times.
**
** Rules (the same as the 1974 engine's, README "Exactness"):
**   - coverage: even-odd over the face's rings with the tie rule of render/geom.h (a point
**     on a non-horizontal edge belongs to the side of larger x, on a horizontal edge to
**     the side of larger y: the symbolic shift of the centre by (e, e^2));
**   - depth: the ray from the eye through the centre meets plane A at t_A = |D_A| / n_A.u
**     (u = centre - eye); A is in front of B when t_A < t_B, compared as
**     |D_B| n_A.u > |D_A| n_B.u; a plane met at or behind the eye (n.u <= 0) is never in
**     front; equal depth at the centre (it lies on the two planes' intersection line):
**     the face in front just right of it, then just above it (the edges' tie rule, as the
**     1974 program's cut lines give it); planes of equal depth everywhere (coplanar): the
**     larger face number in front;
**   - a face whose grid polygon the Segment Generator refuses as not simple (rounding
**     folded it) is split into triangles by mapper_split_face, exactly as the 1974 engine
**     splits it, so both engines see the same faces.
*/
#ifndef T74_POINTS_H
#define T74_POINTS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "emu/status.h"
#include "render/mapper.h"
#include "render/scene.h"
#include "render/visible.h"

struct points_edge;                 /* scratch, points.c */
struct points_z;
struct points_plane;
struct points_box;
struct points_tile;

struct points {
  struct mapped map;                /* the Mapper's faces (plus triangles of folded faces) */
  int W, H;
  int32_t *face;                    /* W x H, index (j * W + i), j from the top: the face
                                       seen (index in map.f), or -1 */
  int faces_split;                  /* faces folded by rounding, drawn as their triangles */
  int faces_culled;                 /* faces that cover no point centre */
  /* coarse coverage (points.c, "Tiles"): set by the caller before points_render; zero is
     the engine as it runs */
  bool no_tiles;                    /* true: no tiles, faces drawn in the Mapper's order
                                       (the engine without coarse coverage, for tests) */
  bool retest_bands;                /* true: a face drawn with the tiles has each band
                                       tested where it is drawn, none of the tests made
                                       before it is drawn taken (tests: the same work) */
  uint64_t shuffle;                 /* not 0: tiles used whatever the scene, the faces
                                       drawn in an order shuffled by this seed instead of
                                       nearest first (tests: the picture does not depend
                                       on the order) */
  /* what the last points_render did (work counts, not times) */
  long tiles_skipped;               /* (face, tile) pairs where the face was proven behind
                                       all along and its points were not visited */
  long points_visited;              /* point visits of the faces' spans (the per-point work) */
  /* host scratch, kept from frame to frame (points_render reuses it) */
  struct core *core;                /* room for the Mapper's tables (never reported) */
  struct core *segcore;             /* room for the Segment Generator's simplicity check */
  struct seg_scratch *segscr;       /* and its scratch tables (segment.h seg_check) */
  struct points_z *z;               /* W x H: bounds on the depth of the face seen where
                                       tiles are kept (points.c) */
  double *zhi;                      /* W x H: the upper bound alone where none are */
  double *m3; size_t m3cap;         /* each face's margin (points.c, "One bound") */
  struct points_plane *plane; size_t planecap; /* each face's exact depth over the grid */
  struct points_edge *edge; size_t edgecap;
  const struct scene *words_s;      /* the scene whose core size words_n is (map_faces:
                                       taken again while p->keep holds that scene's rings,
                                       as the Mapper replays them) */
  uint64_t words_n;
  int32_t *vrc; size_t vrccap;      /* each scene vertex's row and column numbers this
                                       frame, clamped (points.c, "Vertices") */
  int32_t *cross; size_t crosscap;  /* column thresholds of one face, row by row */
  int *rowcount; size_t rowcap;
  uint8_t *skip; size_t skipcap;    /* faces left out (folded, no triangle covers a point) */
  struct points_box *box; size_t boxcap;      /* the faces kept to draw nearest first: box,
                                                 depth in doubles */
  int *order; size_t ordercap;                /* their drawing order (indices in box) */
  double *key; size_t keycap;                 /* and their nearest depths (the order's key) */
  int *bucket; size_t bucketcap;
  struct points_tile *tile; size_t tilecap;   /* the tiles' depth bounds */
  int32_t *ready; size_t readycap;            /* per row, its ready columns this frame where
                                                 rows are made ready span by span (points.c,
                                                 "Clearing"); with ready_kept, the last
                                                 frame's after them (rows H .. 2H - 1) */
  bool ready_kept;                              /* the last frame kept no tiles and ended
                                                 whole: face is -1 outside its ready columns,
                                                 kept in rows H .. 2H - 1 (a frame cleared
                                                 over the faces' boxes keeps the boxes'
                                                 columns on their rows; points.c, "Clearing") */
  /* set by the caller: the Mapper's T-junctions (each face's rings) and face blocks kept
     from call to call of one scene (--frames, issue 19); NULL: searched for at every call */
  struct mapper_keep *keep;
};

/* Map scene s and find the face seen at every point of grid g. Returns T74_OK, T74_EINPUT
   (a face that cannot be drawn, with the same message as the 1974 engine) or T74_EIO.
   p must be zeroed before the first call; a later call reuses its scratch. With p->keep
   set, every call until p->keep is freed must be of the same scene s (its rings are taken
   from the first call's search, which mapper_run_kept keys by s's address). */
int points_render(struct points *p, const struct scene *s, const struct vis_grid *g,
                  struct t74_error *err);

void points_free(struct points *p);

#endif
