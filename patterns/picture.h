/*
** picture.h — background pictures (CONTRACT.md `background FILE`; paper 003 §4).
**
** This file contains code to bring a grey picture in behind the scene: it has the
** lowest priority, showing wherever no face covers a perspective-plane point. In 1974
** such pictures came from the drum scanner with its 8-bit A-D converter (docs/hardware.md);
** here they come from files:
**   PGM  P2 (plain) and P5 (binary), maxval 1..65535, samples scaled to 0..255 by
**        round(v * 255 / maxval);
**   PNG  grey or colour, any bit depth, via libpng: colour is turned to grey with libpng's
**        default weights (0.2126 R + 0.7152 G + 0.0722 B on the stored values), 16-bit
**        samples keep their high byte, and alpha, if any, composites the picture over
**        black (the dark tube face).
** Stored values are taken as perceived grey, like a face's `grey` (no gamma decoding).
**
** The picture is stretched over the window (the whole grid the tube shows): point (i, j)
** of a W x H grid covers picture x in [i*pw/W, (i+1)*pw/W) and y in [j*ph/H, (j+1)*ph/H)
** (pw x ph the picture, row 0 at the top like j = 0). pic_sample() box-averages the
** pixels under that footprint, weighting each by the exact area it shares with it.
**
** Errors (emu/status.h): a file that cannot be opened or read is T74_EIO "FILE: ...";
** one that is not a picture we read is T74_EINPUT "FILE: not a PGM/PNG picture: why".
*/
#ifndef T74_PICTURE_H
#define T74_PICTURE_H

#include <stdint.h>
#include "emu/status.h"

#define PIC_MAX_SIDE 16384      /* largest width or height accepted (a sanity bound) */
#define PIC_MAX_PIXELS (1L << 26) /* largest width x height (64 Mpixel, 8192 x 8192):
                                   the decoded picture stays under 64 MiB */
#define PIC_FILE_MAX ((size_t)64 << 20) /* largest picture file read (64 MiB); a folder,
                                   a device, /dev/zero or a larger file is refused
                                   (T74_EINPUT) without reading more */

struct pic;                     /* opaque: width, height, 8-bit grey pixels */

/* Load a PGM or PNG picture (recognised by its first bytes, not its name). T74_OK with
** *out set, else T74_EIO or T74_EINPUT with err's message naming path. At most
** PIC_FILE_MAX bytes are read and PIC_MAX_PIXELS pixels decoded. */
int pic_load(const char *path, struct pic **out, struct t74_error *err);

/* A picture from w x h grey pixels, row 0 at the top (copied); NULL when out of memory
** or when w or h is outside 1..PIC_MAX_SIDE. */
struct pic *pic_new(int w, int h, const uint8_t *grey);

void pic_free(struct pic *p);

int pic_width(const struct pic *p);
int pic_height(const struct pic *p);

/* Pixel (x, y), y = 0 at the top: 0..255, or -1 outside the picture. */
int pic_pixel(const struct pic *p, int x, int y);

/* The pixels row by row from the top, pic_width a row: pixel (x, y) at [y w + x], as
   pic_pixel gives it inside the picture (for a caller that reads a pixel at each of many
   points: no call each). Valid while p is. */
const uint8_t *pic_rows(const struct pic *p);

/* Grey 0..255 of point (i, j) of a W x H grid: the area-weighted mean of the pixels under
** the point's footprint, rounded to nearest (halves up), in exact integer arithmetic.
** -1 when W or H < 1 or (i, j) is outside the grid. */
int pic_sample(const struct pic *p, int i, int j, int W, int H);

/* Every point of the W x H grid at once into out[j * W + i]: exactly pic_sample's values
** (the same integer sums, taken row by row: each picture row sampled along x once, then
** added with its weight into the grid rows it lies under), with no division in the
** loops; it holds two rows of sums, not the picture's. 0, or -1 when W or H < 1 or out of
** host memory (out unchanged). */
int pic_sample_grid(const struct pic *p, int W, int H, uint8_t *out);

/* Sampled twice, as the drum scanner's picture is (patterns/scanner.h): p's W1 x H1 grid,
** each value through map[256], sampled again onto a W x H grid into out[j * W + i]. The
** same values as pic_sample_grid onto W1 x H1, the map applied, pic_new of the result and
** pic_sample_grid of that onto W x H; but the first grid is made a row at a time as the
** second needs it and is never held whole. 0, or -1 when a side is < 1 or out of host
** memory (out unchanged). */
int pic_sample_twice(const struct pic *p, int W1, int H1, const uint8_t map[256], int W,
                     int H, uint8_t *out);

#endif
