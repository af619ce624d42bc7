/*
** ilda.h — ILDA Image Data Transfer Format (.ild) files of the laser frames the `helios`
** profile would send (`tube74 stream --device helios --to FILE.ild`; display stage).
**
** This file contains code to write laser frames as the ILDA IDTF (ILDA Technical Committee,
** "ILDA Image Data Transfer Format Specification", revision 011, 2014): a file is a series of
** SECTIONS, each a 32-byte header and its records, big-endian throughout:
**
**   header   bytes 0-3 "ILDA", 4-6 reserved (0), 7 format code, 8-15 frame name, 16-23
**            company name (ASCII, NUL-padded), 24-25 number of records, 26-27 frame number
**            (from 0), 28-29 total frames, 30 projector number, 31 reserved (0)
**   format 1 (2D coordinates, indexed colour), 6 bytes a record: X, Y (signed 16-bit,
**            -32768 left / bottom .. +32767 right / top), status code (bit 7: last point of
**            the frame; bit 6: blanking, laser off), colour index (the default ILDA palette:
**            24 = green, 0, 255, 0 — the P1 phosphor's colour)
**   the end  a header with 0 records closes the file.
** A Helios point (12-bit X, Y: 0..4095; r, g, b, i) becomes X' = (X - 2048) * 16 (the same
** position on the full ILDA range, exactly invertible), blanked when its colour and intensity
** are 0. Frames are kept in memory until ilda_finish, because every header holds the total
** frame count. The ILDA file holds no scan rate: play it at the --pps the estimate assumed.
**
**   ilda_init(&w)  ilda_frame(&w, helios_points, n, err)  ilda_finish(&w, &bytes, &len, err)
**   ilda_free(&w)
*/
#ifndef T74_ILDA_H
#define T74_ILDA_H

#include <stddef.h>
#include <stdint.h>

#include "emu/status.h"

#define ILDA_HEADER   32        /* bytes of a section header */
#define ILDA_REC1     6         /* bytes of a format-1 record */
#define ILDA_GREEN    24        /* default ILDA palette: index 24 is (0, 255, 0) */
#define ILDA_LAST     0x80      /* status bit 7: last point of the frame */
#define ILDA_BLANK    0x40      /* status bit 6: laser off */
#define ILDA_MAX_FRAMES 65535   /* total frames: 16 bits */

struct ilda_writer {
  unsigned char *buf;           /* frames written so far (headers' totals filled at finish) */
  size_t n, cap;
  int frames;
};

void ilda_init(struct ilda_writer *w);
/* One frame of n Helios points (7 bytes each, as helios.c packs them). */
int ilda_frame(struct ilda_writer *w, const unsigned char *pts, int n, struct t74_error *err);
/* The whole file: the totals set, the end header added. *bytes stays owned by w. */
int ilda_finish(struct ilda_writer *w, const unsigned char **bytes, size_t *len,
                struct t74_error *err);
void ilda_free(struct ilda_writer *w);

#endif
