/*
** halftone.h — halftone cells: grey levels out of a binary tube (paper 003 §4).
**
** This file contains code to show intermediate tones on a display whose every dot is
** either lit or dark. Paper 003 §4: "each point of the perspective plane maps to a 3x3 or
** 4x4 area on the display; the number and distribution of lit dots gives intermediate
** tones". A cell of N dots (N = 9 or 16) shows N+1 levels, 0 (no dot) .. N (all dots).
**
** Two steps, both integer tables:
**   grey -> level   pat_level(): grey 0..255 is a PERCEIVED brightness; the level is the
**                   number of dots whose light gives that sensation (Weber-Fechner, as the
**                   paper asks; derivation in halftone.c).
**   level -> dots   a family of cells (dispersed, clustered, line) given as a threshold
**                   matrix: the dot at (cx, cy) is lit at level L iff rank[cy][cx] < L, so
**                   the lit sets are nested and level L lights exactly L dots.
**
** Cell coordinates: cx 0..cell-1 left to right, cy 0..cell-1 from the TOP of the cell.
** A dot mask is a uint16_t with bit (cy * cell + cx) set for each lit dot.
**
** Placement on the tube (CONTRACT.md): point (i, j) of the W x H grid (i from the left,
** j from the top; W = floor(400/cell), H = floor(300/cell)) is the cell whose lower-left
** dot is X = cell*i, Y = 299 - cell*(j+1) + 1; its dot (cx, cy) is at
**     X = cell*i + cx,   Y = 299 - cell*j - cy.
** pat_emit_point() writes a point's lit dots in scan order: top row of the cell first,
** each row left to right (the order the beam moves down the raster).
*/
#ifndef T74_HALFTONE_H
#define T74_HALFTONE_H

#include <stdint.h>
#include "display/sink.h"

#define PAT_CELL_MIN 3          /* smallest cell: 3x3 dots, 10 levels */
#define PAT_CELL_MAX 4          /* largest cell:  4x4 dots, 17 levels */
#define PAT_DEFAULT "dispersed" /* family used when none is named */

struct pat_cell;                /* one family at one cell size (opaque, const tables) */

/* Find family NAME (NULL or "" = PAT_DEFAULT) at cell size 3 or 4. T74_OK with *out set,
** or T74_EINPUT for an unknown name or cell size (*out untouched). */
int pat_find(const char *name, int cell, const struct pat_cell **out);

/* Name of the k-th family (k = 0, 1, ...), NULL past the last: for --help and tests. */
const char *pat_family(int k);

/* Number of levels of a cell size: 10 for 3, 17 for 4, 0 for any other size. */
int pat_levels(int cell);

/* Level 0 .. cell*cell for grey 0..255 (perceived brightness), by the Weber-Fechner
** table; grey outside 0..255 is clamped; an unknown cell size gives 0. */
int pat_level(int cell, int grey);

/* Cell size (3 or 4) and family name of p. */
int pat_cell_size(const struct pat_cell *p);
const char *pat_cell_name(const struct pat_cell *p);

/* Threshold rank of dot (cx, cy): it is lit at level L iff rank < L. */
int pat_rank(const struct pat_cell *p, int cx, int cy);

/* *mask = the dots of p lit at level (clamped to 0..cell*cell); bit cy*cell + cx. */
void pat_cell_dots(const struct pat_cell *p, int level, uint16_t *mask);

/* Grid size for a cell size: W = floor(400/cell), H = floor(300/cell). */
int pat_grid_w(int cell);
int pat_grid_h(int cell);

/* Tube coordinates of dot (cx, cy) of point (i, j) (formula above). */
void pat_dot_xy(int cell, int i, int j, int cx, int cy, int *x, int *y);

/* Write the lit dots of point (i, j) at level to s, in scan order (top row first, left to
** right). Returns T74_OK, the first failure of s's point call (the rest of the cell is
** not written), or T74_EINPUT when (i, j) is outside the grid. */
int pat_emit_point(const struct pat_cell *p, int i, int j, int level,
                   const struct sink *s);
/* Write the dots of mask (bit cy*cell + cx, as pat_cell_dots gives them) of a cell of 3 or
** 4 whose dot (0, 0) is at (x0, y0) to s, in pat_emit_point's order. T74_OK, or the first
** failure of s's point call (the rest of the cell is not written). */
int pat_emit_dots(int cell, int x0, int y0, unsigned mask, const struct sink *s);

/* The tube coordinates of dot (0, 0) of point (i, j), the top left dot of its cell: dot
** (cx, cy) is at (x0 + cx, y0 - cy) (pat_dot_xy). */
static inline void pat_cell_origin(int cell, int i, int j, int *x0, int *y0)
{
  *x0 = cell * i;                         /* cells abut left to right from X = 0 */
  *y0 = (TUBE_H - 1) - cell * j;          /* and downward from the top row Y = 299 */
}

#endif
