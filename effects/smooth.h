/*
** smooth.h — smooth shading, partial smoothing (paper 004 §2-4) in the effects stage.
**
** This file declares the 004 model of a scene's triangle patches and the intensity of a
** patch at any point of it (smooth_grey_at), which the frame model (effects/model.h)
** uses for the point frame and for every anti-aliased fragment alike.
**
**   smooth=gouraud  004 §2(a): intensities at the vertices, interpolated in the triangle
**   smooth=phong    004 §2(b): normals at the vertices, interpolated, Lambert per point
**                   (this is also the "whole" smoothing of 004 Table 1, rows f-i)
**   smooth=fixed:C  004 Def. 2/3, procedure (A): a band of one width along every side
**   smooth=prop:C   004 Def. 4/5, procedure (B): bands proportional to the sides
**
** The patches: every face of an object that is a triangle (no holes) and is shaded from
** `light` (no `grey` of its own). Faces outside any object, other polygons and faces
** with a grey keep their flat intensity. Within one object the triangles are oriented
** consistently (smooth_model_build: across every edge two triangles share, the two run
** the edge in opposite directions; closed surfaces are then turned outward by the sign
** of their volume), and a vertex normal is the mean of the unit normals of the object's
** triangles at that vertex (004 §2(a)(1)).
**
** The normal at a point: the point centre on the plane z = 0 is taken back along the ray
** from the eye onto its face's exact plane (eq. (2) from the Mapper); the barycentric
** coordinates of that space point in the triangle place it in the regions of procedure
** (A) (see smooth.c). Floating point is used only for these intensities; which face a
** point shows is never changed here (contour smoothing, effects/contour.h, does that).
**
** Machine model: the vertex normals (3 words of Q1.14 each) and the band table (the
** three insets of every triangle, Q0.16) are allocated in the engine's core for the run, and the
** work per point is counted into the effects' cost (smooth.c lists the sequence).
*/
#ifndef T74_SMOOTH_H
#define T74_SMOOTH_H

#include <stdbool.h>
#include "effects/fx.h"

struct shade_lights;

/* One triangle patch of an object. Corner k is scene vertex v[k]; side k is the side
   opposite corner k (where the barycentric coordinate l[k] is 0). */
struct smooth_tri {
  int    sface;            /* index in scene.f */
  int    mface;            /* index in the Mapper's faces, or -1 when it dropped it */
  int    object;           /* object id */
  int    v[3];             /* scene vertex indices, in the object's consistent order */
  double n[3];             /* unit normal, outward by that order */
  double area2;            /* twice its area in space */
  double len[3];           /* length of side k */
  bool   front;            /* its outward side faces the eye (exact, integer test) */
  double cn[3][3];         /* unit vertex normals at the corners (outward) */
  int    ni[3];            /* their rows in the vertex-normal table */
  double t[3];             /* band inset of side k as a barycentric coordinate, 0..1;
                              t[0]+t[1]+t[2] <= 1 */
  int    bu, bw;           /* barycentric coordinates are taken on these two axes (the
                              plane's dominant one left out) */
  double bV[3][2];         /* the corners on them */
  double bE[3][2];         /* side k on them: corner (k + 2) % 3 less corner (k + 1) % 3 */
  double btot;             /* twice the signed area of the triangle so projected */
  double ends[6][2][3];    /* the normals at the ends of the bands' borders (procedure (A)
                              (3)), made with the insets: side k's band at l_a = t_a and
                              at l_b = t_b (a, b the corners after k) in ends[k], corner
                              k's quadrilateral on its sides towards a and b in ends[3 + k] */
};

/* A triangle's shading constants, two lanes each (smooth.c): made with its insets, for the
   model's triangles only (not the scene's part kept between frames). */
struct smooth_lanes;

struct smooth_model {
  int ntri;
  struct smooth_tri *tri;
  struct smooth_lanes *lanes;  /* ntri entries: triangle t's shading constants in lanes[t] */
  int *tri_of_mface;       /* map->nface entries: triangle index, or -1 (flat) */
  int objects;             /* objects with at least one triangle */
  int flips;               /* triangles turned to agree with their object */
  int conflicts;           /* edges two triangles could not be made to agree on
                              (a one-sided surface, or more than 2 faces on an edge) */
  int vertex_normals;      /* distinct (object, vertex) normals */
  int *edge_group;         /* 3 ntri entries: side k of triangle t (from v[k] to
                              v[(k + 1) % 3]) is in group edge_group[3 t + k], shared by
                              the sides of the object's triangles on the same two vertices */
  int ngroup;              /* groups, 0 .. ngroup - 1 */
  struct smooth_scene *lent;   /* tri and edge_group are this kept part's (not freed with
                                  the model), or NULL */
  /* Tests only (0 after a build): phong_exact gives every Phong grey by the exact chain,
     without the filter that finds most of them with one divide (smooth.c, "The Phong
     grey's filter"); phong_declines, when set, counts the points the filter left to it. */
  bool phong_exact;
  long *phong_declines;
  /* Tests only too: rows_sse2 makes the rows built twice take their SSE2 build where the
     processor has AVX: smooth_phong_row two points a step (not four), smooth_row and
     smooth_partial_row the partial smoothing's rows in SSE2's encoding (not VEX's:
     smooth.c, rows_avx). */
  bool rows_sse2;
  /* Tests only too: phong_sqrt makes the AVX rows of smooth_phong_row take the square root
     and divide where the processor has AVX-512VL (not its reciprocal square root's short
     chain: smooth.c, rows_r14). */
  bool phong_sqrt;
  /* Tests only too: phong_ymm makes smooth_phong_row take its AVX rows four points a step
     where the processor has AVX-512F (not its eight-point rows: smooth.c, rows_zmm). */
  bool phong_ymm;
  /* Tests only too: partial_ymm makes smooth_row and smooth_partial_row take the partial
     smoothing's AVX rows built for AVX alone where the processor has AVX-512F and VL (not
     the same rows built for AVX-512F and VL: smooth.c, rows_partial_zmm). */
  bool partial_ymm;
  /* Tests only too: inner_exact gives every point of the partial smoothing its region by
     the exact chain, without the filter that finds the inner triangle's points (smooth.c,
     "The inner triangle's filter"); inner_declines, when set, counts the points the
     filter left to the chain. */
  bool inner_exact;
  long *inner_declines;
  /* Tests only too: lit_exact lights every point of the partial smoothing by the exact
     chain, without the filter that finds most greys with one divide a pair (smooth.c,
     "The lit pairs' filter"); lit_declines, when set, counts the pairs it left to it. */
  bool lit_exact;
  long *lit_declines;
};

/* Build the model: triangles, orientation, vertex normals, band insets for e's smooth=.
   Only host memory (T74_EIO when out of it). */
int smooth_model_build(struct smooth_model *m, const struct mapped *map,
                       const struct scene *s, const struct effects *e,
                       struct t74_error *err);
void smooth_model_free(struct smooth_model *m);

/* What of the model depends on the scene alone: each object's triangles, oriented
   consistently across their shared edges (the edge sort and the search), a closed
   object's turned outward, and their geometry so oriented (normals, sides, barycentric
   set-up, vertex normals). The rest depends on the view and is made every frame: an open
   surface turned towards the eye (its geometry carried over with the signs changed and
   two corners swapped: the same doubles its own arithmetic gives), which triangles the
   Mapper kept and which face the eye, the vertex normals' rows, bands. */
struct smooth_scene;

/* smooth_model_build, with the scene's part kept in *keep (may be NULL: made and freed)
   for the frames that follow: taken from there when it was made for s, else made and
   left there (the one before freed). The caller frees *keep (smooth_scene_free) before
   s goes, and after the model. The model is the same either way; its triangles as this
   frame orients them are kept there too, rewritten only where the frame changes them
   (the view's fields every frame; the rest when an object turns the other way or smooth=
   changes), while no other model holds them (else the model gets its own). */
int smooth_model_build_kept(struct smooth_model *m, const struct mapped *map,
                            const struct scene *s, const struct effects *e,
                            struct smooth_scene **keep, struct t74_error *err);
void smooth_scene_free(struct smooth_scene *ss);

/* The band insets of one triangle for smooth= (fixed: width w in space units): t[k] is
   the barycentric coordinate of side k's inset line; scaled down so the three sum to at
   most 1 (then the flat inner triangle is a point). Whole smoothing gives t = 1/2
   (the edge midpoints, used by contour smoothing only). */
void smooth_insets(enum effects_smooth kind, double c, double w, const double len[3],
                   double area2, double t[3]);

/* The normal at barycentric coordinates l (sum 1, each >= 0) of triangle tr under the
   partial smoothing with insets t (procedure (A)): out is not normalised. Returns the
   region: 0 the flat inner triangle (out = face normal), 1 an edge quadrilateral, 2 a
   corner quadrilateral. */
int smooth_partial_normal(const struct smooth_tri *tr, const double l[3], double out[3]);

/* Lambert's law with the Mapper's ambient floor, for a unit normal facing the eye's side
   and a unit light direction: 48 + 207 max(0, n.l), rounded (as render/mapper.c). */
int smooth_lambert(const double n[3], const double l[3]);

/* The patches' tables in core (vertex normals, bands): allocated for the effects' run
   and counted (T74_ECORE when they do not fit); cost NULL (the points engine, which models
   no machine): allocated only, not written nor counted. */
int smooth_tables(struct core *core, const struct smooth_model *m, struct cost *cost,
                  struct t74_error *err);

/* The grey of triangle t of m at space point X on its plane (the shaded point), with
   reflectance refl (a texture's, else 1) and the lights whose bits are set in blocked in
   shadow (render/shade.h); *region (may be NULL) gets the region of procedure (A) (0 the
   flat inner triangle, 1 an edge band, 2 a corner band; Gouraud and Phong: 1). Counted in
   cost as the 16-bit program's sequence (smooth.c; cost NULL: not counted). The lights
   are s's, made ready (render/shade.h). The inner triangle with refl 1 and no light
   blocked is exactly the face's flat grey. */
int smooth_grey_at(const struct smooth_model *m, const struct mapped *map, const struct scene *s,
                   const struct effects *e, int t, const double X[3], double refl,
                   unsigned blocked, const struct shade_lights *lights, struct cost *cost,
                   int *region);

/* smooth_grey_at, uncounted, at n <= SMOOTH_RUN points X[p] of triangle t (their lights
   blocked[p]), the greys in grey[p] and the regions in region[p]: the same greys, bit for
   bit, worked out a step for all points at a time, so that the processor overlaps their
   divides and square roots (issue 19). */
#define SMOOTH_RUN 16
void smooth_grey_run(const struct smooth_model *m, const struct mapped *map, const struct scene *s,
                     const struct effects *e, int t, int n, const double (*X)[3], double refl,
                     const unsigned *blocked, const struct shade_lights *lights, int *grey,
                     int *region);

/* Whether smooth_row serves m under e and the lights L: smooth=phong with the lights all
   parallel and the Phong filter on (not a test's phong_exact), or smooth=fixed or prop;
   the processor with SSE2. */
bool smooth_rows(const struct smooth_model *m, const struct effects *e,
                 const struct shade_lights *L);

/* smooth_grey_run at the points X[p] of nseg triangles of m one after another, at most
   SMOOTH_ROW points: points at[k] <= p < at[k + 1] of triangle tri[k], every run holding
   at least one (at[k] < at[k + 1]: an odd last point of a run is paired with the next
   run's first) (reflectance 1, their lights blocked[p], the greys in grey[p]; regions[r]
   counts up the points of region r), where smooth_rows says so: the same greys and
   regions, bit for bit, each step two points an instruction
   whether or not they are on one triangle, so that a row's points on a smoothed object go
   together without a run's fixed cost at each triangle (issue 19). */
#define SMOOTH_ROW 64
void smooth_row(const struct smooth_model *m, const struct mapped *map,
                const struct effects *e, int nseg, const int *tri, const int *at,
                const double (*X)[3], const unsigned *blocked, const struct shade_lights *L,
                int *grey, long regions[3]);

/* smooth_row's greys under smooth=phong (where smooth_rows says so: the lights all
   parallel), its regions left to the caller (all 1), from each point's space point given
   by its two coordinates on its triangle's axes bu and bw only (xu[p] = X[p][bu], xw[p] =
   X[p][bw]: all that the greys depend on under parallel lights): the same greys, bit for
   bit, two points' coordinates a load. */
void smooth_phong_row(const struct smooth_model *m, int nseg, const int *tri, const int *at,
                      const double *xu, const double *xw, const unsigned *blocked,
                      const struct shade_lights *L, int *grey);

/* smooth_row's greys and regions under smooth=fixed or prop (where smooth_rows says so)
   with the lights all parallel, from each point's space point given by its two
   coordinates on its triangle's axes bu and bw only (xu[p] = X[p][bu], xw[p] = X[p][bw]:
   all that the regions and greys depend on under parallel lights): the same greys and
   regions, bit for bit. A triangle's points are read two a 16-byte load from its first
   on, at[k] + 2j and the next (its odd last point alone): stored likewise (16 bytes a
   store, 8 for that last point), each load is forwarded whole from its store. */
void smooth_partial_row(const struct smooth_model *m, const struct mapped *map, int nseg,
                        const int *tri, const int *at, const double *xu, const double *xw,
                        const unsigned *blocked, const struct shade_lights *L, int *grey,
                        long regions[3]);

/* For tests: the shading pass's two-lane steps on triangle t of m at two points given by
   their barycentric coordinates l[h] (any values, as the steps take them): the region
   band_lanes gives the pair (0 when the two are not in one edge band nor one corner band;
   then nothing else written), the two normals into n[h] (as smooth_partial_normal's, not
   normalised) and, under the lights L (all parallel, reflectance 1, none blocked, turned
   by the side sgn), their greys into g[h]. The processor without SSE2: 0. */
int smooth_lanes_pair(const struct smooth_model *m, int t, const double l[2][3], double sgn,
                      const struct shade_lights *L, double n[2][3], int g[2]);

/* For tests: the shading pass's lighting of two normals v[h] (not normalised) as a pair
   (parallel lights L, reflectance 1, none blocked, turned by the side sgn), the greys into
   g[h]; false (nothing written) without SSE2. */
bool smooth_lit_pair(const double v[2][3], double sgn, const struct shade_lights *L, int g[2]);

/* For tests: triangle t's constants of the rows (m->lanes[t]) made again from m->tri[t],
   after a test changed the triangle's corners, sides or btot. */
void smooth_lanes_remake(struct smooth_model *m, int t);

/* The model's statistics into st (smooth_triangles, ...). */
void smooth_count(const struct smooth_model *m, struct fx_stats *st);

#endif
