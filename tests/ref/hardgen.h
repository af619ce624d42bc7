/*
** hardgen.h — generator of the hard configurations of issue 7, by the thousands.
**
** This file declares a deterministic generator of small valid .s74 scenes (as xr_scene,
** exactref.h) built around the cases where exact hidden-surface removal is hardest:
**   wall      a wall, a coplanar window touching the wall's outline, a face piercing the
**             wall with one vertex exactly in the wall's plane;
**   coplanar  two overlapping coplanar faces pierced by a third;
**   vshare    two faces sharing an edge and a third sharing only one vertex position;
**   tjunc     T-junctions: a vertex exactly inside another face's edge, faces sharing
**             only part of an edge;
**   sliver    slivers and near-collinear vertices, some on point centres;
**   far       concave faces far from the eye, whose projections round into
**             near-degenerate (even non-simple) grid polygons;
**   edgeon    faces seen almost edge-on;
**   snapped   random faces with vertices placed exactly in other faces' planes;
**   fold      combs whose notches end within a grid unit of the opposite edge once
**             projected: rounding touches or folds them;
**   holes     plates with holes, a coplanar face filling a hole (sharing its edges),
**             faces piercing the plate at a hole's corner;
**   mix       two or three of the above in one scene;
**   crowd     ten to twenty-four triangles through a few shared planes and points,
**             crossing each other many times over.
** Every face is exactly planar (O + a U + b V with integer O, U, V, a, b), every ring is
** simple in the plane (checked exactly), every vertex lies in front of the eye, in range.
** The stream is splitmix64, so (family, seed) gives the same scene on every machine.
*/
#ifndef TUBE74_TESTS_REF_HARDGEN_H
#define TUBE74_TESTS_REF_HARDGEN_H

#include <stdint.h>
#include "tests/ref/exactref.h"

enum hg_family {
  HG_WALL, HG_COPLANAR, HG_VSHARE, HG_TJUNC, HG_SLIVER, HG_FAR, HG_EDGEON, HG_SNAPPED,
  HG_FOLD, HG_HOLES, HG_MIX, HG_CROWD, HG_NFAMILIES
};

const char *hg_family_name(int fam);

/* Fill *s (zeroed) with scene (fam, seed). 0, or -1 when out of memory. */
int hg_generate(int fam, uint64_t seed, struct xr_scene *s);

#endif
