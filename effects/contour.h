/*
** contour.h — contour smoothing (paper 004 §5, Def. 6-9, procedures (C) and (D)).
**
** This file declares the construction of the regions that round the corners of each
** object's outer contour; the frame model (effects/model.h) takes them out of the object's
** stretches on every line, before any shading, so a face uncovered by the cut is shaded
** like any other and every filter sees the curve.
**
** The contour (instead of procedure (C)'s walk over projected vertices): for each object,
** the projected sides of its front triangles (outward side towards the eye, decided
** exactly in integers) that no other front triangle of the object shares. Each such side
** is directed with its triangle on the left (the Mapper's counter-clockwise rings), so the
** sides link into the contour, counter-clockwise round the object. For a convex object
** this is exactly the outline of its projection.
**
** At a contour vertex Q2 where the contour turns left (a convex corner), with patch A on
** the side coming in and patch B on the side going out: Q0 is where A's smoothing
** boundary line through Q2's other side meets the incoming side, Q4 likewise in B
** (the edge midpoints under whole smoothing), Q1 = Q2 + Cc(Q0 - Q2), Q3 = Q2 + Cc(Q4 -
** Q2) (Def. 8), and the quartic Bezier of Def. 9 replaces the corner. Q0..Q4 are rounded
** once onto the plane grid (1/256 world unit); the curve is taken as the polygon through
** its points at t = m/CONTOUR_STEPS, rounded onto the grid likewise, with Q0 and Q4 exact.
** From there every decision is exact: for each row (procedure (D) (6)) the row's
** crossings with the region between the corner and the curve give the stretches cut
** away, with the renderer's tie rule (a stretch owns its left end, not its right).
**
** Where the object is what is seen inside a region, the line shows what lies behind: what
** the engine sees there with the object's faces taken away (effects/see.h: under the 1974
** engine the stretches of a second Visible Surface Procedure over the pieces of every
** other face, vis_init_without; under the points engine its exact answer at the point),
** or the background. Faces of the object itself do not show through: beyond its smoothed
** contour, the object is not there.
**
** Concave contour vertices (where the contour turns right, or goes straight on) are left
** as they are; the paper treats convex objects only (004 §7 names concave ones as future
** work), and a curve there would have to add points outside the object's faces.
*/
#ifndef T74_CONTOUR_H
#define T74_CONTOUR_H

#include "effects/poly.h"
#include "effects/smooth.h"

#define CONTOUR_STEPS 64          /* segments of the curve polygon */

/* The quartic Bezier of Def. 9 at t (0..1): out = sum C(4,i) (1-t)^(4-i) t^i q[i]. */
void contour_bezier(const double q[5][2], double t, double out[2]);

/* Its derivative with respect to t. */
void contour_bezier_d(const double q[5][2], double t, double out[2]);

/* Control points of Def. 8/9 from Q0, Q2, Q4 and Cc. */
void contour_controls(const double q0[2], const double q2[2], const double q4[2], double cc,
                      double q[5][2]);

/* The closed form: the area between the corner Q0 Q2 Q4 and the curve, as a share of the
   triangle Q0 Q2 Q4: (8 Cc^2 + 8 Cc + 1) / 35. */
double contour_cut_share(double cc);

/* The region cut away at a corner, as the polygon Q2, Q4, the curve back to Q0, on the
   grid: writes CONTOUR_STEPS + 2 points into poly (Q0..Q4 as grid points). */
void contour_region(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2]);
/* contour_region, and the blocks and box fx_polys_close would make of the polygon (the
   one ring's fx_ring_blocks: the count returned, (CONTOUR_STEPS + 2) / FX_POLY_BLOCK
   rounded up, into blk; box xlo, xhi, ylo, yhi), made on the way. */
int contour_region_blocked(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2],
                           gcoord (*blk)[2], gcoord box[4]);
/* Tests only: contour_region_blocked the way the build's target takes it (SSE2's, or
   without), where the processor has AVX-512 (contour.c, region_exact512). */
int contour_region_sse2(const struct gpoint q[5], struct gpoint poly[CONTOUR_STEPS + 2],
                        gcoord (*blk)[2], gcoord box[4]);

/* One convex corner the contour smoothing rounds, as the enhanced edges (effects/edges.h)
   need it to draw the outline along the curve: the object; the contour's scene vertices
   a (before the corner), b (the corner, Q2) and c (after it), so that the side a-b ends
   at Q0 and the side b-c begins at Q4; the mapped faces of patch A (on side a-b) and
   patch B (on side b-c); Q0..Q4 on the grid. contour_region(q, ...) gives the curve's
   points, the same the cut is made with: region points CONTOUR_STEPS + 1 down to 1 run
   along the curve from Q0 to Q4, the contour's direction (the object on the left). */
struct contour_corner {
  int object;
  int va, vb, vc;
  int mface_a, mface_b;
  struct gpoint q[5];
};

struct contour_corners { struct contour_corner *c; int n, cap; };

void contour_corners_free(struct contour_corners *cs);

/* The regions the contour smoothing cuts away (see above), one polygon per convex corner
   (owner: the object), appended to cuts, and each corner appended to corners; m is the
   smoothing model of the scene, map the Mapper's faces. The corner's region polygon passes
   through core (one at a time), counted in cost; cost NULL (the points engine, which
   models no machine): nothing counted nor written to core, the table still allocated.
   The frame model (effects/model.h) cuts them out of the object's stretches. */
int contour_build(const struct mapped *map, struct core *core, const struct scene *s,
                  const struct effects *e, const struct smooth_model *m, struct fx_polys *cuts,
                  struct contour_corners *corners, struct fx_stats *st, struct cost *cost,
                  struct t74_error *err);

#endif
