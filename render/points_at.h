/*
** points_at.h — the points engine at any sample: the face seen at the samples of a lattice
** K times finer than the points, decided exactly, without the 1974 program.
**
** The effects ask which face is seen at points other than the centres (effects/see.h):
** supersampling (aa=super, paper 000 method D) at K x K samples a point, a contour cut
** (paper 004 §5) at the centres without the faces of the object it cuts. Sample (k, m)
** lies at u = (k + 1/2) / K across and v = (m + 1/2) / K down, in point units from the
** window's top left (k and m may reach up to one point beyond the grid, where a filter
** does). For K = 1 without faces left out the samples are the point centres, and the
** answer is the face points_render keeps there (tests/test_engines.c checks it).
**
** The rules are the points engine's (points.h): the Mapper's faces as points_render left
** them (folded faces as their triangles), coverage even-odd with the tie rule of
** render/geom.h, depth |D_B| n_A.u > |D_A| n_B.u exactly, equal depth decided just right of
** the sample, then just above it, then coplanar faces by mface_coplanar_front. The faces
** are walked in the order points_render rasterises them, with its replacement rule, so the
** answer is the same whatever order it had to fall back on.
**
** This file adds a function beside points.c and leaves its rasteriser alone: a row of
** samples is one horizontal line y = yn / yd met by every face's edges in exact rationals,
** the crossings turned into the first sample at or right of them, and the samples between
** pairs of crossings given to the face in front, in 128-bit integers (256 bits where a
** depth product needs them; the bounds are proven in points_at.c).
*/
#ifndef T74_POINTS_AT_H
#define T74_POINTS_AT_H

#include <stdint.h>
#include "emu/status.h"
#include "render/points.h"
#include "render/visible.h"

#define POINTS_AT_KMAX 16           /* the finest lattice: K samples a point across and down */

/* Scratch kept from row to row; zero it before the first call. It belongs to one rendered
   frame: the faces' extents are taken from p on the first call. */
struct points_at {
  const struct points *of;          /* the frame the extents below belong to */
  int64_t *ylo, *yhi;               /* per face: its lowest and highest grid y */
  int nface;
  int32_t *col; int colcap;         /* one face's crossings on the row, as samples */
  __int128 *depth; int depthcap;    /* per sample of the row: n.u of the face seen, scaled */
};

/* The face seen (index in p->map.f, or -1) at samples k0 .. k0 + n - 1 of row m of the
   lattice K times finer than grid g (the grid p was rendered on), written to face[0..n),
   with the faces whose skip[face] is set left out (skip NULL: none). 1 <= K <= POINTS_AT_KMAX;
   samples at most one point beyond the grid (-K <= k, k < K (W + 1), likewise m). Returns
   T74_OK, or T74_EIO (out of host memory, or a lattice out of range). */
int points_at_row(struct points_at *q, const struct points *p, const struct vis_grid *g, int K,
                  int64_t m, int64_t k0, int n, const uint8_t *skip, int *face,
                  struct t74_error *err);

/* Whether points_at_row takes the lattice (K, row m, samples k0 .. k0 + n - 1) of grid g,
   rather than refusing it as out of range. */
bool points_at_lattice_ok(const struct vis_grid *g, int K, int64_t m, int64_t k0, int n);

void points_at_free(struct points_at *q);

#endif
