/*
** image.c — picture files: the tube as PNG / PBM / point list; ids and grey as PGM.
**
** This file contains code to turn the stored tube (display/tube.h) and the renderer's
** per-point arrays into the files CONTRACT.md names. Two views of one tube:
**   the exact one (PBM, points) — what is stored, bit for bit, for checks and teaching;
**   the look (PNG) — the plain stored-tube look: each lit dot one pixel of phosphor green
**     on the dark tube face. Glow, bright spot and fade (tube=fade/flash) are not drawn
**     here; they belong to a looks layer and never to a checked output (style.md).
** Tube y counts from the BOTTOM (as on the CRT) while image files store the top row
** first, so file row r shows tube row y = TUBE_H-1-r. The ids and grey arrays are already
** in grid order (row j = 0 at the top) and are written as they are.
** All files go through display/outfile.h: complete or not at all. Each writer comes in
** two forms: NAME(..., path, err) writes one file alone, NAME_to(..., outfile, err) writes
** an output a caller opened (in a set, committed with the others) and finishes it.
*/
#include "display/image.h"

#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

#include "display/outfile.h"

/* The plain tube look (tuned by eye; docs/hardware.md: P1 phosphor, green):           */
static const uint8_t IMAGE_DOT_RGB[3]  = { 80, 255, 120 };  /* a stored, lit dot: P1 green */
static const uint8_t IMAGE_FACE_RGB[3] = { 8, 20, 12 };     /* the unlit tube face: dark,
                                                               faintly green (flood glow) */

/* ---- PNG ------------------------------------------------------------------------- */

struct png_fail {               /* where libpng's error callback reports */
  jmp_buf jb;                   /* back to image_write_png */
  struct t74_error *err;        /* the caller's error record */
  const char *path;             /* the file being written */
};

/* libpng error callback: record "FILE: PNG: message", return to the setjmp. */
static void png_error_cb(png_structp png, png_const_charp msg)
{
  struct png_fail *pf = png_get_error_ptr(png);
  t74_fail(pf->err, T74_EIO, "%s: cannot write PNG: %s", pf->path, msg);
  longjmp(pf->jb, 1);
}

/* libpng warning callback: warnings do not change the picture; ignored. */
static void png_warning_cb(png_structp png, png_const_charp msg)
{
  (void)png;
  (void)msg;
}

int image_write_rgb_png(int w, int h, image_row_fn fill, void *ctx, const char *path,
                        struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_rgb_png_to(w, h, fill, ctx, o, err);
}

/* One PNG into o: w x h pixels of `depth` bits in `colour` (a PNG_COLOR_TYPE_), with a
** palette when pal is given (then no row filter and zlib's level 6, the right choice for
** palette data); fill(ctx, r, row) gives file row r (0 = the top) as rowbytes bytes.
** o is finished with outfile_commit, or outfile_abort on failure. */
static int write_png(int w, int h, int depth, int colour, const png_color *pal, int npal,
                     size_t rowbytes, image_row_fn fill, void *ctx, struct outfile *o,
                     struct t74_error *err)
{
  const char *path = outfile_path(o);
  uint8_t *row = malloc(rowbytes);
  struct png_fail pf;
  pf.err = err;
  pf.path = path;
  png_structp png = row ? png_create_write_struct(PNG_LIBPNG_VER_STRING, &pf,
                                                  png_error_cb, png_warning_cb) : NULL;
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!info) {
    if (png) png_destroy_write_struct(&png, NULL);
    free(row);
    outfile_abort(o);
    return t74_fail(err, T74_EIO, "%s: out of memory", path);
  }
  /* Nothing the error path needs is changed after this setjmp. */
  if (setjmp(pf.jb)) {
    png_destroy_write_struct(&png, &info);
    free(row);
    outfile_abort(o);
    return err->status;
  }
  png_init_io(png, outfile_stream(o));
  png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, depth, colour, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (pal) {
    png_set_PLTE(png, info, pal, npal);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_compression_level(png, 6);
  }
  png_write_info(png, info);
  for (int r = 0; r < h; r++) {
    fill(ctx, r, row);
    png_write_row(png, row);
  }
  png_write_end(png, NULL);
  png_destroy_write_struct(&png, &info);
  free(row);
  return outfile_commit(o, err);
}

int image_write_rgb_png_to(int w, int h, image_row_fn fill, void *ctx, struct outfile *o,
                           struct t74_error *err)
{
  return write_png(w, h, 8, PNG_COLOR_TYPE_RGB, NULL, 0, 3 * (size_t)w, fill, ctx, o, err);
}

/* File row r (0 = the top of the tube) packed one bit a dot: MSB = leftmost, 1 = lit. */
static void tube_row(void *ctx, int r, uint8_t *row)
{
  tube_row_packed(ctx, TUBE_H - 1 - r, row);
}

/* The tube has two colours: a 1-bit palette PNG (dark face, lit dot) — the same pixels as
** an RGB file, about a twentieth of the bytes to compress. */
int image_write_png_to(const struct tube *t, struct outfile *o, struct t74_error *err)
{
  png_color pal[2];                       /* index 0 the face, 1 a lit dot */
  pal[0].red = IMAGE_FACE_RGB[0]; pal[0].green = IMAGE_FACE_RGB[1]; pal[0].blue = IMAGE_FACE_RGB[2];
  pal[1].red = IMAGE_DOT_RGB[0]; pal[1].green = IMAGE_DOT_RGB[1]; pal[1].blue = IMAGE_DOT_RGB[2];
  return write_png(TUBE_W, TUBE_H, 1, PNG_COLOR_TYPE_PALETTE, pal, 2, TUBE_ROW_BYTES,
                   tube_row, (void *)t, o, err);
}

int image_write_png(const struct tube *t, const char *path, struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_png_to(t, o, err);
}

/* ---- PBM, points ----------------------------------------------------------------- */

int image_write_pbm(const struct tube *t, const char *path, struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_pbm_to(t, o, err);
}

int image_write_pbm_to(const struct tube *t, struct outfile *o, struct t74_error *err)
{
  outfile_printf(o, "P4\n%d %d\n", TUBE_W, TUBE_H);
  uint8_t row[TUBE_ROW_BYTES];            /* the same packing as the PNG's */
  for (int r = 0; r < TUBE_H; r++) {
    tube_row((void *)t, r, row);
    outfile_write(o, row, sizeof row);
  }
  return outfile_commit(o, err);          /* reports the first write failure, if any */
}

int image_write_points(const struct tube *t, const char *path, struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_points_to(t, o, err);
}

int image_write_points_to(const struct tube *t, struct outfile *o, struct t74_error *err)
{
  int n = tube_count(t);
  for (int k = 0; k < n; k++) {
    int x, y;
    tube_order(t, k, &x, &y);
    outfile_printf(o, "%d %d\n", x, y);
  }
  return outfile_commit(o, err);
}

/* ---- PGM of the grid ------------------------------------------------------------- */

int image_write_ids(const uint16_t *ids, int w, int h, const char *path,
                    struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_ids_to(ids, w, h, o, err);
}

int image_write_ids_to(const uint16_t *ids, int w, int h, struct outfile *o,
                       struct t74_error *err)
{
  const char *path = outfile_path(o);
  outfile_printf(o, "P5\n%d %d\n65535\n", w, h);
  uint8_t *row = malloc(2 * (size_t)w);   /* one row of big-endian 16-bit samples */
  if (!row) {
    outfile_abort(o);
    return t74_fail(err, T74_EIO, "%s: out of memory", path);
  }
  for (int j = 0; j < h; j++) {
    for (int i = 0; i < w; i++) {
      uint16_t v = ids[(size_t)j * w + i];
      row[2 * i] = (uint8_t)(v >> 8);     /* PGM: most significant byte first */
      row[2 * i + 1] = (uint8_t)(v & 0xff);
    }
    outfile_write(o, row, 2 * (size_t)w);
  }
  free(row);
  return outfile_commit(o, err);
}

int image_write_grey(const uint8_t *grey, int w, int h, const char *path,
                     struct t74_error *err)
{
  struct outfile *o;
  if (outfile_open(&o, path, err) != T74_OK) return err->status;
  return image_write_grey_to(grey, w, h, o, err);
}

int image_write_grey_to(const uint8_t *grey, int w, int h, struct outfile *o,
                        struct t74_error *err)
{
  outfile_printf(o, "P5\n%d %d\n255\n", w, h);
  outfile_write(o, grey, (size_t)w * (size_t)h);
  return outfile_commit(o, err);
}
