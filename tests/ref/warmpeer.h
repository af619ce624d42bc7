/*
** warmpeer.h — the warm z-buffer peer of `tube74 bench speed` (tools/refbench.c --warm).
**
** This file declares a scene made ready for OSMesa before any clock starts (tessellated by
** GLU into one vertex array of triangles, the context made, the shader compiled) and one
** timed frame of it: clear, glDrawArrays, glFinish, the buffer read back. Two modes:
**
**   ids      every triangle in its face number's colour (24 bits, flat); the frame reads
**            the face numbers back. This is the peer of every scene (issue 12).
**   shaded   per-fragment Phong shading (issue 19's peer for the scenes whose `effects`
**            ask smooth=): a normal at every vertex, interpolated, normalised in the
**            fragment shader and lit by the scene's lights with tube74's law
**            (render/shade.h: grey = 48 + round(207 sum max(0, n.l)), clamped to 255, the
**            normal turned to the eye's side); the face number in R, G, B and the grey in
**            A, both read back a frame.
**
** The vertex normals of the shaded mode: for a face that is a triangle in an object with
** no `grey` of its own (the faces tube74 smooths), the mean of the unit normals of the
** object's such triangles at that vertex, normalised; every other face gets its own unit
** normal at its vertices (flat, but through the same per-fragment work). The normals take
** the scene's winding as it is (tube74 first turns an object's triangles to agree with
** each other, effects/smooth.h): the same normals where a scene's winding agrees (the
** shipped smooth scenes: smooth_orient_flips 0), good enough for timing otherwise. A
** face's normals are turned to the eye's side by its own plane, as tube74 does by the
** triangle's. tube74 takes a point back onto its face's exact plane and interpolates in
** space; GL interpolates perspective-correct in float: the same barycentric weights up to
** float rounding. Needs a GL with GLSL 1.30 (Mesa's OSMesa: 4.5 compatibility with
** llvmpipe, 3.3 with softpipe); otherwise ref_peer_new says why.
**
** Grid: ids[j * w + i] and grey[j * w + i] are pixel (i, j), j from the TOP; the window
** maps onto the w x h viewport (the point grid when w x h is 400/cell x 300/cell).
*/
#ifndef TUBE74_TESTS_REF_WARMPEER_H
#define TUBE74_TESTS_REF_WARMPEER_H

#include <stddef.h>
#include <stdint.h>

#include "tests/ref/osmesa_ref.h"

/* One light, in scene coordinates (CONTRACT.md `light DX DY DZ`, `light point X Y Z`). */
typedef struct ref_light {
  int    point;           /* 1: a point light at v; 0: a parallel light towards v */
  double v[3];
} ref_light;

typedef struct ref_peer_input {
  const ref_scene *s;     /* faces may carry ids up to 2^24 - 1 */
  const int *object;      /* s->nf entries: the object a face belongs to (0: none), or NULL */
  int nlight;
  const ref_light *light;
  int shade;              /* 0: ids; 1: Phong-shaded */
  int w, h;               /* the viewport */
} ref_peer_input;

typedef struct ref_peer ref_peer;

/* Tessellate, make the context, compile the shader (all before any clock). NULL on
   failure, with a reason in err. */
ref_peer *ref_peer_new(const ref_peer_input *in, char *err, size_t errlen);

/* One frame: clear, draw, finish, read back the face numbers into ids (w * h) and, in the
   shaded mode, the greys into grey (w * h; may be NULL in the ids mode). 0, or -1 on a GL
   error. */
int ref_peer_frame(ref_peer *p, uint32_t *ids, uint8_t *grey);

size_t ref_peer_triangles(const ref_peer *p);
void ref_peer_free(ref_peer *p);

#endif
