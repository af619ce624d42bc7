/*
** gif.c — animated GIF writing with giflib (see gif.h); the movie of `play --movie
** FILE.gif`, after the face has been rendered by display/look.c.
**
** This file contains code to put frames of palette indices into a GIF89a file: the
** screen descriptor with the global palette, the looping block, then per frame a graphic
** control extension and the changed rectangle. giflib (Debian libgif-dev, 5.2) does the
** LZW coding; its output goes through our write callback into display/outfile.h, so the
** file appears complete or not at all. giflib is opened with dlopen when a movie is
** begun (display/dynlib.h): no other command loads it.
*/
#include "display/gif.h"

#include <gif_lib.h>
#include <stdlib.h>
#include <string.h>

#include "display/dynlib.h"
#include "display/outfile.h"

#define GIF_LIB "libgif.so.7"   /* giflib 5.1 and 5.2 (Debian 12 and 13: libgif7) */

/* The giflib functions a movie calls, opened with the library (dynlib.h). */
struct giflib {
  void *lib;                    /* dlopen handle, NULL: not loaded (first: dynlib.h) */
  GifFileType *(*EGifOpen)(void *, OutputFunc, int *);
  void (*EGifSetGifVersion)(GifFileType *, bool);
  ColorMapObject *(*GifMakeMapObject)(int, const GifColorType *);
  void (*GifFreeMapObject)(ColorMapObject *);
  int (*EGifPutScreenDesc)(GifFileType *, int, int, int, int, const ColorMapObject *);
  int (*EGifPutExtensionLeader)(GifFileType *, int);
  int (*EGifPutExtensionBlock)(GifFileType *, int, const void *);
  int (*EGifPutExtensionTrailer)(GifFileType *);
  size_t (*EGifGCBToExtension)(const GraphicsControlBlock *, GifByteType *);
  int (*EGifPutExtension)(GifFileType *, int, int, const void *);
  int (*EGifPutImageDesc)(GifFileType *, int, int, int, int, bool, const ColorMapObject *);
  int (*EGifPutLine)(GifFileType *, GifPixelType *, int);
  int (*EGifCloseFile)(GifFileType *, int *);
  const char *(*GifErrorString)(int);
};

#define GIF_FNS(X) X(EGifOpen) X(EGifSetGifVersion) X(GifMakeMapObject) X(GifFreeMapObject) \
  X(EGifPutScreenDesc) X(EGifPutExtensionLeader) X(EGifPutExtensionBlock)                   \
  X(EGifPutExtensionTrailer) X(EGifGCBToExtension) X(EGifPutExtension) X(EGifPutImageDesc) \
  X(EGifPutLine) X(EGifCloseFile) X(GifErrorString)

static int giflib_load(struct giflib *f, const char *path, struct t74_error *err)
{
#define SYM(name) { #name, offsetof(struct giflib, name) },
  static const struct dynlib_sym syms[] = { GIF_FNS(SYM) };
#undef SYM
#define CHECK(name) DYNLIB_CHECK(f, name, name);
  GIF_FNS(CHECK)
#undef CHECK
  return dynlib_open(f, sizeof *f, GIF_LIB, "giflib", "libgif7", syms,
                     sizeof syms / sizeof *syms, path, err);
}

struct gif {
  struct giflib fn;             /* giflib, opened for this movie */
  GifFileType *gf;              /* giflib's encoder */
  struct outfile *of;           /* where its bytes go */
  const char *path;             /* for messages (the caller's string) */
  int w, h;
  uint8_t *prev;                /* the previous frame (w x h), valid when frames > 0 */
  long frames;
  int io_failed;                /* a write of the callback failed */
};

static int gif_put(GifFileType *gf, const GifByteType *b, int n)
{
  struct gif *g = gf->UserData;
  if (n <= 0) return 0;
  if (outfile_write(g->of, b, (size_t)n) != T74_OK) { g->io_failed = 1; return 0; }
  return n;
}

static int fail(struct gif *g, struct t74_error *err, const char *what, int code)
{
  return t74_fail(err, T74_EIO, "%s: cannot write the GIF (%s: %s)", g->path, what,
                  g->io_failed ? "write error" : g->fn.GifErrorString(code));
}

int gif_open_to(struct gif **out, struct outfile *of, const char *path, int w, int h,
                const uint8_t palette[256][3], struct t74_error *err)
{
  *out = NULL;
  if (w < 1 || h < 1 || w > 65535 || h > 65535) {
    outfile_abort(of);
    return t74_fail(err, T74_EIO, "%s: a GIF frame must be 1..65535 pixels a side", path);
  }
  struct gif *g = calloc(1, sizeof *g);
  if (!g) { outfile_abort(of); return t74_fail(err, T74_EIO, "%s: out of memory", path); }
  g->path = path;
  g->w = w;
  g->h = h;
  g->prev = malloc((size_t)w * (size_t)h);
  if (!g->prev) { outfile_abort(of); free(g); return t74_fail(err, T74_EIO, "%s: out of memory", path); }
  g->of = of;
  int st = giflib_load(&g->fn, path, err);
  if (st != T74_OK) { gif_abort(g); return st; }
  int code = 0;
  const struct giflib *fn = &g->fn;
  g->gf = fn->EGifOpen(g, gif_put, &code);
  if (!g->gf) { st = fail(g, err, "open", code); gif_abort(g); return st; }
  fn->EGifSetGifVersion(g->gf, true);
  GifColorType cols[256];
  for (int k = 0; k < 256; k++) {
    cols[k].Red = palette[k][0];
    cols[k].Green = palette[k][1];
    cols[k].Blue = palette[k][2];
  }
  ColorMapObject *map = fn->GifMakeMapObject(256, cols);
  if (!map) { gif_abort(g); return t74_fail(err, T74_EIO, "%s: out of memory", path); }
  int ok = fn->EGifPutScreenDesc(g->gf, w, h, 8, 0, map) == GIF_OK;
  fn->GifFreeMapObject(map);
  /* loop for ever: the NETSCAPE2.0 application block, sub-block 1, count 0 */
  static const GifByteType app[11] = { 'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0' };
  static const GifByteType loop[3] = { 1, 0, 0 };
  ok = ok && fn->EGifPutExtensionLeader(g->gf, APPLICATION_EXT_FUNC_CODE) == GIF_OK &&
       fn->EGifPutExtensionBlock(g->gf, sizeof app, app) == GIF_OK &&
       fn->EGifPutExtensionBlock(g->gf, sizeof loop, loop) == GIF_OK &&
       fn->EGifPutExtensionTrailer(g->gf) == GIF_OK;
  if (!ok) { st = fail(g, err, "header", g->gf->Error); gif_abort(g); return st; }
  *out = g;
  return T74_OK;
}

int gif_frame(struct gif *g, const uint8_t *idx, int delay_cs, struct t74_error *err)
{
  int x0 = 0, y0 = 0, x1 = g->w - 1, y1 = g->h - 1;   /* the rectangle to send */
  if (g->frames > 0) {
    x0 = g->w; y0 = g->h; x1 = -1; y1 = -1;
    for (int y = 0; y < g->h; y++) {
      const uint8_t *a = idx + (size_t)y * (size_t)g->w, *b = g->prev + (size_t)y * (size_t)g->w;
      if (!memcmp(a, b, (size_t)g->w)) continue;
      if (y < y0) y0 = y;
      y1 = y;
      for (int x = 0; x < g->w; x++)
        if (a[x] != b[x]) { if (x < x0) x0 = x; if (x > x1) x1 = x; }
    }
    if (x1 < 0) { x0 = x1 = 0; y0 = y1 = 0; }          /* unchanged: one pixel, same value */
  }
  GraphicsControlBlock gcb = { DISPOSE_DO_NOT, false, delay_cs < 0 ? 0 : delay_cs,
                               NO_TRANSPARENT_COLOR };
  GifByteType ext[4];
  const struct giflib *fn = &g->fn;
  fn->EGifGCBToExtension(&gcb, ext);
  int ok = fn->EGifPutExtension(g->gf, GRAPHICS_EXT_FUNC_CODE, 4, ext) == GIF_OK &&
           fn->EGifPutImageDesc(g->gf, x0, y0, x1 - x0 + 1, y1 - y0 + 1, false, NULL) == GIF_OK;
  for (int y = y0; ok && y <= y1; y++)
    ok = fn->EGifPutLine(g->gf, (GifPixelType *)(idx + (size_t)y * (size_t)g->w + (size_t)x0),
                         x1 - x0 + 1) == GIF_OK;
  if (!ok) return fail(g, err, "frame", g->gf->Error);
  memcpy(g->prev, idx, (size_t)g->w * (size_t)g->h);
  g->frames++;
  return T74_OK;
}

int gif_open(struct gif **out, const char *path, int w, int h, const uint8_t palette[256][3],
             struct t74_error *err)
{
  struct outfile *of;
  *out = NULL;
  int st = outfile_open(&of, path, err);
  if (st != T74_OK) return st;
  return gif_open_to(out, of, path, w, h, palette, err);
}

long gif_frames(const struct gif *g) { return g->frames; }

int gif_commit(struct gif *g, struct t74_error *err)
{
  int code = 0, st = T74_OK;
  if (g->fn.EGifCloseFile(g->gf, &code) != GIF_OK) {
    g->gf = NULL;                       /* freed by giflib even on failure */
    st = fail(g, err, "close", code);
    outfile_abort(g->of);
  } else {
    st = outfile_commit(g->of, err);
  }
  dynlib_close(&g->fn, sizeof g->fn);
  free(g->prev);
  free(g);
  return st;
}

void gif_abort(struct gif *g)
{
  if (!g) return;
  if (g->gf) { int code; g->fn.EGifCloseFile(g->gf, &code); }
  if (g->of) outfile_abort(g->of);
  dynlib_close(&g->fn, sizeof g->fn);
  free(g->prev);
  free(g);
}
