/*
** image.h — picture files written from the tube and the renderer (CONTRACT.md --dump).
**
** This file contains code to write what tube74 shows and keeps as ordinary files:
**   image_write_png     `-o FILE.png`: the tube as it looks, RGB 400 x 300, lit dots in
**                       P1-phosphor green on the dark tube face (colours in image.c)
**   image_write_pbm     `--dump tube`: P4 PBM 400 x 300, 1 = lit, file row 0 = tube y 299
**   image_write_points  `--dump points`: "X Y" per lit dot, in the order first written
**   image_write_ids     `--dump ids`: P5 PGM, maxval 65535, big-endian, one face number
**                       per perspective-plane point, file row 0 = grid row j = 0 (top)
**   image_write_grey    `--dump grey`: P5 PGM, maxval 255, grey per point, row 0 = top
** Every writer is atomic (display/outfile.h): it returns T74_OK, or T74_EIO with a message
** naming the file in err, and then no file was created or changed. A symlink is written
** through, `-`, a FIFO or a device written directly (outfile.h).
*/
#ifndef T74_IMAGE_H
#define T74_IMAGE_H

#include <stdint.h>
#include "display/outfile.h"
#include "display/tube.h"
#include "emu/status.h"

/* Write an 8-bit RGB PNG of w x h pixels atomically: fill(ctx, r, rgb) gives file row r
   (0 = the top) as 3*w bytes. */
typedef void (*image_row_fn)(void *ctx, int r, uint8_t *rgb);
int image_write_rgb_png(int w, int h, image_row_fn fill, void *ctx, const char *path,
                        struct t74_error *err);

int image_write_png(const struct tube *t, const char *path, struct t74_error *err);
int image_write_pbm(const struct tube *t, const char *path, struct t74_error *err);
int image_write_points(const struct tube *t, const char *path, struct t74_error *err);

/* ids / grey: w x h values, row-major, row 0 = top row of the grid (j = 0). */
int image_write_ids(const uint16_t *ids, int w, int h, const char *path,
                    struct t74_error *err);
int image_write_grey(const uint8_t *grey, int w, int h, const char *path,
                     struct t74_error *err);

/* The same writers onto an output already opened (display/outfile.h, e.g. one of a set):
   they write o and finish it with outfile_commit (outfile_abort on failure). */
int image_write_rgb_png_to(int w, int h, image_row_fn fill, void *ctx, struct outfile *o,
                           struct t74_error *err);
int image_write_png_to(const struct tube *t, struct outfile *o, struct t74_error *err);
int image_write_pbm_to(const struct tube *t, struct outfile *o, struct t74_error *err);
int image_write_points_to(const struct tube *t, struct outfile *o, struct t74_error *err);
int image_write_ids_to(const uint16_t *ids, int w, int h, struct outfile *o,
                       struct t74_error *err);
int image_write_grey_to(const uint8_t *grey, int w, int h, struct outfile *o,
                        struct t74_error *err);

#endif
