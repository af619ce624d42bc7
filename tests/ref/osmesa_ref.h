/*
** osmesa_ref.h — the independent reference renderer of the cross-check tests.
**
** This file declares a scene held in memory (ref_scene, the same data a generated .s74
** file carries) and a renderer that answers, for every perspective-plane point of
** shared/CONTRACT.md, which face is visible at the point's centre — the same question
** `tube74 render --dump ids=` answers, computed a completely different way: an ordinary
** depth-buffered GL rendering (OSMesa, no lighting, no blending, no multisampling) at
** exactly the point grid, each face drawn in a flat colour that encodes its number.
** Concave faces and holes go through GLU's tessellator (odd winding rule).
**
** Every GL call lives in osmesa_ref.c behind the four functions below, so the reference
** can move to EGL (surfaceless llvmpipe) when OSMesa goes away.
**
** Grid (CONTRACT.md "Perspective-plane grid"): W = floor(400 / cell), H = floor(300 / cell);
** ids[j * W + i] is point (i, j), i from the left, j from the TOP.
*/
#ifndef TUBE74_TESTS_REF_OSMESA_REF_H
#define TUBE74_TESTS_REF_OSMESA_REF_H

#include <stddef.h>
#include <stdint.h>

/* One vertex statement: `vertex ID X Y Z`. */
typedef struct ref_vertex {
  unsigned id;            /* 1..65535 */
  long     x, y, z;       /* -32768..32767, z > the eye's Z0 */
} ref_vertex;

/* One face statement: `face ID ring0 [* ring1]... [grey G]`. */
typedef struct ref_face {
  unsigned id;            /* face number 1..65535: what --dump ids reports */
  int      grey;          /* 0..255, or -1 for no `grey` token */
  int      nring;         /* 1 (outer boundary) + number of holes */
  int     *ring_len;      /* nring lengths, each >= 3 */
  int     *vi;            /* all rings back to back, as indices into ref_scene.v (not ids) */
} ref_face;

/* A scene: eye, window, vertices, faces. Owned by whoever built it (scenegen.c). */
typedef struct ref_scene {
  long x0, y0, z0;        /* `view`: the eye, z0 < 0 */
  long xl, yb, xr, yt;    /* `window` on the plane z = 0 */
  int nv, cap_v;
  ref_vertex *v;
  int nf, cap_f;
  ref_face *f;
} ref_scene;

typedef struct ref_renderer ref_renderer;

/* Grid size for a halftone cell of 3 or 4 (contract: floor(400/cell) x floor(300/cell)). */
int ref_grid_w(int cell);
int ref_grid_h(int cell);

/* Create the GL context (sets GALLIUM_DRIVER to llvmpipe unless it already names
   llvmpipe or softpipe). NULL on failure, with a reason in err. */
ref_renderer *ref_open(char *err, size_t errlen);
void ref_close(ref_renderer *r);

/* Render s and store the visible face number (0 = none) of every point in ids, which must
   hold ref_grid_w(cell) * ref_grid_h(cell) entries, row j = 0 at the top.
   Returns 0, or -1 with a reason in err. */
int ref_render_ids(ref_renderer *r, const ref_scene *s, int cell, uint16_t *ids,
                   char *err, size_t errlen);

/* GL snaps vertices to 1/256 of a pixel (llvmpipe) and works in floats, so where a face edge
   passes within a tiny distance of a point centre, GL may put the centre on the wrong
   side. Usually a neighbour then shows the other face and the 3 x 3 rule below skips the
   point; but for a sliver or spike thinner than a point (star tips, thin triangles) the
   neighbours may all agree while the centre is a coin toss. ref_edge_points marks in
   near_edge (w * h bytes, row 0 at the top) every point whose centre lies within
   REF_EDGE_MARGIN_PX point widths of any projected face edge (hidden or not), and returns
   how many it marked. Measured near-misses that flipped GL were 0.00003..0.0005 px. */
#define REF_EDGE_MARGIN_PX 0.02
long ref_edge_points(const ref_scene *s, int cell, unsigned char *near_edge);

/* The comparison rule of the cross-checks: if point (i, j) and its (up to 8) neighbours
   inside the grid all show the same face, and (when near_edge is not NULL) no face edge
   passes within REF_EDGE_MARGIN_PX of the point's centre, return that face number
   (possibly 0); else return -1 (the point is at a face boundary and is not compared). */
long ref_uniform_face(const uint16_t *ids, const unsigned char *near_edge, int w, int h, int i,
                      int j);

#endif
