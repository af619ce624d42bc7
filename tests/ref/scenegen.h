/*
** scenegen.h — deterministic scene generators for the cross-check and invariance tests.
**
** This file declares generators of .s74 scenes built to stress hidden-surface removal:
** boxes (axis-aligned and rotated by integer vectors), interpenetrating triangles, combs
** (concave faces with many teeth), stars (concave), plates with several holes, and solids
** pierced by plates and rods. One generator call fills a ref_scene (what the reference
** renders, osmesa_ref.h); sg_write_s74 writes the very same data as .s74 text, so the
** renderer under test and the reference always see one scene.
**
** Exactness (shared/CONTRACT.md): every face is exactly planar on the integer grid — each
** is a triangle, or its 2-D integer outline placed as O + a U + b V with integer O, U, V —
** every vertex has z > Z0, ids are 1..65535, coordinates within -32768..32767, rings are
** simple, holes strictly inside and apart. sg_validate checks all of this exactly in
** integers (plus: no two faces on one plane, which would leave visibility undefined).
**
** Determinism: a (family, seed) pair always gives the same scene, on every machine: the
** generators use their own splitmix64 stream (never rand()); the few doubles (sizes, star
** and polygon angles) come from plain IEEE operations, sqrt and floor only (cos/sin are a
** Taylor series of our own, not libm's), and are rounded to whole grid units.
*/
#ifndef TUBE74_TESTS_REF_SCENEGEN_H
#define TUBE74_TESTS_REF_SCENEGEN_H

#include <stdint.h>
#include <stdio.h>
#include "tests/ref/osmesa_ref.h"

typedef enum sg_family {
  SG_BOXES,
  SG_TRIANGLES,
  SG_COMBS,
  SG_STARS,
  SG_PLATES,
  SG_PIERCED,
  SG_NFAMILIES
} sg_family;

/* "boxes", "triangles", "combs", "stars", "plates", "pierced". */
const char *sg_family_name(sg_family fam);

/* The generator's random stream (splitmix64). */
typedef struct sg_rng {
  uint64_t s;
} sg_rng;
uint64_t sg_next(sg_rng *r);
/* Uniform integer in lo..hi inclusive (lo <= hi). */
long sg_range(sg_rng *r, long lo, long hi);

/* Fill *out (which must be zeroed or freshly sg_free'd) with the scene of (fam, seed).
   Returns 0, or -1 (out of memory, or no valid scene after many tries) with a reason. */
int sg_generate(sg_family fam, uint64_t seed, ref_scene *out, char *err, size_t errlen);

/* Release what a scene owns and zero it. */
void sg_free(ref_scene *s);

/* How to write a scene: canonical (all zero), or the same scene said another way. */
typedef struct sg_variant {
  uint64_t seed;          /* drives the choices below */
  int shuffle;            /* permute vertex statements and face statements */
  int reverse;            /* reverse the orientation of about half the rings */
  int rotate;             /* start each ring at another vertex, permute each face's holes */
} sg_variant;

/* Write s as .s74 text to path; `comment` (may be NULL) becomes a leading # line.
   Returns 0, or -1 with a reason. */
int sg_write_s74(const ref_scene *s, const char *path, const char *comment,
                 const sg_variant *var, char *err, size_t errlen);

/* Check every promise listed at the top of this file, exactly. 0 = valid. */
int sg_validate(const ref_scene *s, char *err, size_t errlen);

/* Scene building blocks (used by the generators, and by hand-made test scenes). */
int sg_add_vertex(ref_scene *s, unsigned id, long x, long y, long z); /* index or -1 */
/* Add a face whose rings are given as vertex INDICES back to back. Returns index or -1. */
int sg_add_face(ref_scene *s, unsigned id, int grey, int nring, const int *ring_len,
                const int *vi);

#endif
