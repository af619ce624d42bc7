/*
** exactref.h — an exact reference renderer for the differential tests (issue 7).
**
** This file declares a second, independent answer to "which face is seen at the centre of
** perspective-plane point (i, j)", written from shared/CONTRACT.md and the README's
** "Exactness" section only: it shares no code with render/. It is deliberately simple —
** a point-in-polygon test against every face and an exact depth comparison — so that it
** can be trusted where the renderer is clever (cuts, priority pairs, D-blocks).
**
** What it computes, exactly, in integers (int64 / __int128 and a small 256-bit product):
**   - the grid polygon: every vertex projected by the contract's eq. (1) onto z = 0 and
**     rounded half up to 1/256 world unit; a vertex lying exactly inside another face's
**     edge in space (a T-junction) is first inserted into that edge (README "Exactness");
**     a face whose plane holds the eye covers nothing;
**   - coverage: even-odd rule over all rings of the grid polygon, with the documented tie
**     rule for centres on a boundary — a point on a non-horizontal edge belongs to the
**     side of larger x, on a horizontal edge to the side of larger y — implemented as the
**     symbolic shift of the centre by (e, e^2);
**   - depth: the ray from the eye through the centre meets face plane n.x + d = 0 at
**     t = |D| / n.(r - E) (D = n.E + d); smaller t is in front, compared exactly as
**     |D_B| n_A.u versus |D_A| n_B.u in 256 bits. Coplanar faces: the larger face number
**     is in front.
**
** Tolerance band (the only points where a different answer is accepted): the renderer
** cuts interpenetrating faces along a carrier line that is exact to within a few grid
** units of the true intersection line (README "Exactness"). A point is in the band when
** the face the renderer shows covers the point too and the point's centre lies within
** XR_BAND grid units of the projected intersection line of that face's plane and the
** reference's front face's plane. And a face whose grid polygon is not simple (rounding
** folded it: seen almost edge-on or from far away) has no exact region on the grid; the
** renderer covers it by its triangles' grid polygons, which differ from the folded
** polygon's even-odd region only in slivers along the chords between its grid vertices:
** a point differing there, within XR_FOLD_BAND grid units of such a chord, is in the band
** too. Distances are measured in long double: they decide only whether a point is judged,
** never which face is seen.
*/
#ifndef TUBE74_TESTS_REF_EXACTREF_H
#define TUBE74_TESTS_REF_EXACTREF_H

#include <stdint.h>
#include <stdio.h>

#define XR_BAND 5.0L          /* grid units (1/256 world unit each) */
#define XR_FOLD_BAND 1.5L     /* grid units, around the chords of a folded face */

struct xr_face {
  unsigned id;                /* face number */
  unsigned on;                /* `on F`: the face it lies on (a pattern), 0 none */
  int grey;                   /* -1: not given */
  int line;                   /* line in the written .s74 (xr_write fills it), 0 unknown */
  int nring;
  int *rs;                    /* nring + 1 ring starts into vi */
  int *vi;                    /* vertex indices into xr_scene.v */
};

struct xr_scene {
  int32_t eye[3];
  int32_t win[4];
  int nv, capv;
  int32_t (*v)[3];            /* vertex k has id k + 1 */
  int nf, capf;
  struct xr_face *f;
};

/* Building scenes (vertex ids are index + 1). Return the new index, or -1 (no memory). */
int xr_vertex(struct xr_scene *s, int32_t x, int32_t y, int32_t z);
/* A face from nv vertex indices; holes added with xr_hole. */
int xr_face(struct xr_scene *s, unsigned id, int nv, const int *vi);
int xr_hole(struct xr_scene *s, int face, int nv, const int *vi);
void xr_scene_free(struct xr_scene *s);

/* Write as .s74 text (records each face's line); read the subset xr_write writes plus
   comments (view, window, vertex, face with `*` holes and `grey`). */
int xr_write(struct xr_scene *s, FILE *f);
int xr_read(const char *text, struct xr_scene *s, char *err, size_t errlen);

/* The reference, prepared once per scene. */
struct xr_ring { int n; int64_t *x, *y; };
struct xr_pface {
  unsigned id;
  unsigned on;                /* as xr_face.on */
  int used;                   /* 0: the plane holds the eye (covers nothing) */
  int nring;
  struct xr_ring *ring;       /* grid polygon rings */
  __int128 n[3], D;           /* plane, signed so that D = n.E + d < 0 */
  int64_t bx0, by0, bx1, by1; /* bounding box of the grid polygon */
  int folded;                 /* the grid polygon is not simple (exact test) */
};
struct xr_ref {
  int W, H;
  int64_t eye[3];
  int32_t win[4];
  int nf;
  struct xr_pface *f;
};

/* Prepare for cell size 3 or 4 (grid floor(400/cell) x floor(300/cell)). 0 ok, -1 memory. */
int xr_prepare(const struct xr_scene *s, int cell, struct xr_ref *r);
void xr_ref_free(struct xr_ref *r);

/* The face id seen at point (i, j) (j counted from the top), 0 for none. */
unsigned xr_visible(const struct xr_ref *r, int i, int j);

/* Judge the renderer's answer got (face id, 0 none) at (i, j): 0 agrees, 1 differs but in
   the tolerance band, -1 wrong. *want receives the reference's answer. */
int xr_judge(const struct xr_ref *r, int i, int j, unsigned got, unsigned *want);

#endif
