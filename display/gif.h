/*
** gif.h — animated GIF files (giflib): the movie `tube74 play --movie FILE.gif` writes.
**
** This file contains code to write an animated GIF, frame by frame, through the atomic
** output files of display/outfile.h: a 256-colour global palette (the tube's face is one
** phosphor colour at many intensities, so a palette of one ramp of P1 green holds it
** exactly, display/look.h), a NETSCAPE2.0 block so that viewers loop it, and for each
** frame a graphic control block (its delay) and only the rectangle that changed since the
** previous frame (disposal "do not dispose": the rest of the earlier frame stays), which
** keeps a picture building up in scan order small. Frames are colour indices, one byte a
** pixel, row 0 at the top.
**
**   gif_open(&g, path, w, h, palette, err)   palette: 256 RGB triples
**   gif_frame(g, idx, delay_cs, err)         delay in hundredths of a second
**   gif_commit(g, err) or gif_abort(g)       exactly one; both free g
** Errors are T74_EIO "FILE: what failed"; a failed or aborted movie leaves no file. giflib
** is opened with dlopen by gif_open (display/dynlib.h): when it cannot be, that is the
** failure ("FILE: cannot load giflib (why); install the Debian package libgif7").
*/
#ifndef T74_GIF_H
#define T74_GIF_H

#include <stdint.h>

#include "emu/status.h"

struct gif;                     /* opaque: giflib handle, output file, previous frame */

int  gif_open(struct gif **out, const char *path, int w, int h, const uint8_t palette[256][3],
              struct t74_error *err);
/* The same into an output already opened (one of a set, display/outfile.h): gif_commit
   finishes it (the set publishes it), gif_abort discards it; on failure of gif_open_to
   itself `of` is discarded too. */
struct outfile;
int  gif_open_to(struct gif **out, struct outfile *of, const char *path, int w, int h,
                 const uint8_t palette[256][3], struct t74_error *err);
int  gif_frame(struct gif *g, const uint8_t *idx, int delay_cs, struct t74_error *err);
long gif_frames(const struct gif *g);
int  gif_commit(struct gif *g, struct t74_error *err);
void gif_abort(struct gif *g);

#endif
