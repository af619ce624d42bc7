/*
** tube.h — the storage tube's memory: 400 x 300 binary dots (paper 003 §4).
**
** This file contains code to model what a bistable storage CRT keeps: once the beam has
** written a dot, the dot stays lit until the whole screen is erased (docs/hardware.md:
** stores for 15 min or more). It is binary — a dot written twice is still one lit dot —
** and this model also remembers the order in which dots were FIRST written, which is the
** order `--dump points` reports and the order a plotter or Tek stream would draw them.
**
** The tube is a sink (display/sink.h): tube_sink() feeds it point by point. It is the
** exact stored picture that `--dump tube` shows; glow, flash and fade are looks layered
** on top elsewhere, never stored here (style.md).
**
** Coordinates: x 0..TUBE_W-1 left to right, y 0..TUBE_H-1 bottom to top (CONTRACT.md).
*/
#ifndef T74_TUBE_H
#define T74_TUBE_H

#include <stdint.h>

#include "display/sink.h"
#include "emu/status.h"

struct tube;                    /* opaque: bitmap + first-write order + sticky error */

/* A new, erased tube; NULL when out of memory. */
struct tube *tube_new(void);
void tube_free(struct tube *t);

/* Erase: no dot lit, the order forgotten, the sticky error cleared. */
void tube_erase(struct tube *t);

/* Store dot (x, y). T74_OK (also when it was lit already: it keeps its first place), or
** T74_EINPUT for a dot outside the tube (recorded, first one only, for tube_end). */
int tube_write(struct tube *t, int x, int y);

/* The lit dots of one halftone cell (patterns/halftone.h): bit k of mask is the dot
** (x0 + k % cell, y0 - k / cell), cell >= 1 (3 or 4 for the halftone cells); written in
** rising bit order, each as tube_write would (the same order, the same first failure,
** after which the rest are not written). */
int tube_write_dots(struct tube *t, int x0, int y0, int cell, unsigned mask);

/* count cells abutting left to right, cell c at (x0 + c * cell, y0) with masks[c]: as
** tube_write_dots of each in turn (the first failure ends it). */
int tube_write_cells(struct tube *t, int x0, int y0, int cell, const uint16_t *masks,
                     int count);

/* A row of 3x3 or 4x4 cells by key (a grey): the cells' masks of the 256 keys, and for
** 3x3 and 4x4 the same as tube.c stores a row of cells, made once for many rows
** (tube_keys_init); the fields are tube.c's. */
struct tube_keys {
  uint16_t mask[256];
  uint64_t lanes[7][256];       /* 3x3: of a cell c places on (0 .. 6) in a run of seven;
                                   4x4: lanes[0 .. 3], of a cell c places on in four */
  int cell;
  int within;                   /* cell 3 or 4, every mask within the cell */
};

/* tk for cells of cell x cell (any size; only 3 and 4 are faster) with mask_of[k] the mask
** of key k. */
void tube_keys_init(struct tube_keys *tk, int cell, const uint16_t *mask_of);

/* tube_write_cells(t, x0, y0, tk->cell, masks, count) with masks[c] = tk->mask[keys[c]]. */
int tube_write_cells_keyed(struct tube *t, int x0, int y0, const struct tube_keys *tk,
                           const uint8_t *keys, int count);

/* 1 if dot (x, y) is lit, else 0 (also for any dot outside the tube). */
int tube_lit(const struct tube *t, int x, int y);

/* Row y (0 = the bottom) packed one bit a dot, 1 = lit, the leftmost dot in the most
** significant bit of out[0] (the packing of PBM and 1-bit PNG rows): TUBE_ROW_BYTES bytes;
** all 0 for a row outside the tube. */
#define TUBE_ROW_BYTES (TUBE_W / 8)
void tube_row_packed(const struct tube *t, int y, uint8_t *out);

/* How many dots are lit. */
int tube_count(const struct tube *t);

/* The k-th lit dot in first-write order, k = 0 .. tube_count-1: sets *x, *y and returns
** T74_OK, or returns T74_EINPUT for k out of range. */
int tube_order(const struct tube *t, int k, int *x, int *y);

/* The tube as a sink: point = tube_write; end reports the first out-of-tube write, if any,
** into err; abort leaves the stored dots as they are (the tube is memory, not a file). */
struct sink tube_sink(struct tube *t);

#endif
