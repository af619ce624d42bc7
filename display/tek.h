/*
** tek.h — Tektronix 4010/4014 PLOT 10 byte streams: writing the tube as one, reading one
** onto the tube (CONTRACT.md `tek` and `render FILE.tek`; docs/hardware.md "Tektronix
** 4010/4014 byte stream").
**
** This file contains code to speak the language of the storage-tube terminals that
** followed the 1974 system: the Tektronix 4010 (1024 x 780 addresses) and 4014 (4096 x
** 3120, with the "extra byte" of its Enhanced Graphics Module). Their tubes are bistable
** storage tubes like paper 003's Sony-Tektronix CRT, so a picture of stored dots goes over
** unchanged: every tube dot becomes one point-plot address, and any Tek stream can be
** shown on the emulated 400 x 300 tube.
**
** THE MAPPING (tube dot <-> 4014 address), the same on both axes:
**     encode   X = (256 x + 128) / 25      Y = (256 y + 128) / 25      (integer division)
**     decode   x = X * 25 / 256            y = Y * 25 / 256
** i.e. one tube dot is 4096/400 = 10.24 address units wide AND high, and the tube's
** 400 x 300 dots fill the 4096 x 3072 part of the 4014 screen (the 4:3 area that xterm's
** Tek window shows, TEKWIDTH x TEKHEIGHT), dot (x, y) covering addresses
** [10.24 x, 10.24 (x+1)) and encoded at the centre of that range. The centre decodes back
** to the same dot because 10.24 x <= floor(10.24 x + 5.12) < 10.24 (x + 1). Units are
** square, so circles stay round. Addresses with Y >= 3072 (the top 48 rows of the 4014
** screen, and the 3120..4095 that are off any screen) lie above the tube: they are not
** stored, and the decoder warns.
**
** ENCODER (a sink, display/sink.h): tek_enc_open(&e, path, err) -> tek_enc_sink(e).
**   The stream is: ESC FF (erase: the picture starts on a clean screen), ESC ` (normal,
**   stored beam, solid lines), GS (graph mode: a 4010 without point plot at least draws),
**   FS (4014 point plot: every address that follows is one stored dot), one address per
**   dot in the order the dots arrive, and at the end US (back to alpha mode, so a terminal
**   is left as it was found). An address is [HiY] [Extra] [LoY] [HiX] LoX with the usual
**   omissions: HiY, Extra and HiX only when they changed, LoY when it changed or when Extra
**   or HiX is sent (the terminal tells HiX from HiY by a LoY before it; an Extra byte is
**   recognised only as the first of two tag-11 bytes). The first address after the header
**   is sent whole. The Extra byte's low bits are kept by the terminal until the next Extra
**   byte (the 4014's registers, and xterm, keep them), so it too is sent only on a change.
**   path NULL writes to stdout as the dots come (a terminal shows the picture growing; no
**   atomicity on a stream); a path is written through display/outfile.h, atomically.
**   Exactly one of the sink's end or abort runs (sink.h); tek_enc_free then releases e and,
**   if neither ran (the job failed before drawing), aborts first.
**
** DECODER: tek_decode(buf, n, stored, rep) reads a whole stream and sends every STORED
**   dot to `stored` (normally the tube), in order. It understands
**     GS          graph mode; the first address after GS is a dark move, later ones draw
**                 vectors (rasterised onto the 400 x 300 dots: stored traces); GS BEL
**                 (BEL right after GS) makes the first one a drawn vector too, as in xterm
**     FS          point plot: each address stores one dot
**     RS          incremental plot: SP pen up, P pen down, then A E D F B J H I step one
**                 address unit E, NE, N, NW, W, SW, S, SE; each step with the pen down
**                 stores the dot under the beam
**     US, CR      back to alpha mode (CR also returns the cursor to the left margin)
**     alpha text  printable ASCII drawn with the stroke font in tek.c at the 4014 character
**                 sizes (size 1 = 74 columns, as the 4010), BS HT LF VT move the cursor
**     ESC FF      erase: rep->erase is called (the caller erases the tube), alpha mode, home
**     ESC ` .. o  normal / defocused beam: stored (line styles are drawn solid)
**     ESC p .. w  write-through: not stored; each trace goes to rep->write_through
**     ESC 8 .. ;  character size 1 .. 4
**     ESC SUB, ESC ENQ, ESC ETB, ESC SO, ESC SI, ESC BEL  ignored without a warning
**                 (GIN crosshair, status enquiry, hard copy, character sets, bell)
**     ESC [ ? 3 8 h, ESC ETX   xterm's switches into and out of its Tek window (gnuplot's
**                 `xterm` terminal and plotutils write them): ignored without a warning;
**                 any other ESC [ sequence is skipped whole, with a warning
**     LoY HiX LoY LoX  (a malformed order) read as xterm reads it, the first LoY as the
**                 Extra byte, with a warning
**     NUL, SYN, BEL, DEL (outside addresses)   fill and bell: ignored
**   and warns, with the byte offset (of the ESC, for an escape sequence), about everything else: bytes 0x80..0xFF, control
**   codes that mean nothing in the current mode, unknown ESC sequences, addresses off the
**   tube, and a stream that ends inside an address or an ESC sequence. A malformed stream
**   is shown as far as it is valid; nothing in the bytes can make the decoder fail.
**   It returns T74_OK, or the first failure of stored's point call (decoding stops there).
**
** tek_sniff(buf, n): the stream starts with a Tektronix control code (ESC GS FS RS US).
*/
#ifndef T74_TEK_H
#define T74_TEK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "display/sink.h"
#include "display/outfile.h"
#include "emu/status.h"

/* ---- PLOT 10 codes ----------------------------------------------------------------- */
#define TEK_BEL 0x07            /* bell: ignored */
#define TEK_BS  0x08            /* alpha: cursor left */
#define TEK_HT  0x09            /* alpha: cursor right (a space) */
#define TEK_LF  0x0A            /* alpha: cursor down a line */
#define TEK_VT  0x0B            /* alpha: cursor up a line */
#define TEK_FF  0x0C            /* after ESC: erase the screen */
#define TEK_CR  0x0D            /* return to the margin, alpha mode */
#define TEK_ESC 0x1B            /* escape: the next byte is a command */
#define TEK_FS  0x1C            /* point plot mode (4014 EGM) */
#define TEK_GS  0x1D            /* graph (vector) mode */
#define TEK_RS  0x1E            /* incremental plot mode (4014 EGM) */
#define TEK_US  0x1F            /* alpha mode */

/* Address space of the 4014 (12-bit) and the part the tube covers (mapping above). */
#define TEK_ADDR_MAX 4096       /* addresses 0..4095 on both axes */
#define TEK_SCREEN_H 3120       /* the 4014 screen shows Y 0..3119 */
#define TEK_TUBE_W   4096       /* the tube's 400 dots cover X 0..4095 */
#define TEK_TUBE_H   3072       /* its 300 dots cover Y 0..3071 (same 10.24 per dot) */

/* Address of the centre of dot x (or y), and the dot of an address (floor: may lie off
** the tube, e.g. >= TUBE_H for Y >= 3072 or negative for a text descender). */
static inline int tek_addr_of_dot(int d) { return (256 * d + 128) / 25; }
static inline int tek_dot_of_addr(int a) { return a >= 0 ? a * 25 / 256 : -((-a * 25 + 255) / 256); }

/* ---- encoder ----------------------------------------------------------------------- */

/* What the terminal holds of the last address: the last byte of each group sent (-1: none
** yet, so the next address goes whole). The encoder below and the `tek` serial profile
** (display/usb/tekterm.c) share the address rules through these two. */
struct tek_regs { int hiy, extra, loy, hix; };
void tek_regs_reset(struct tek_regs *r);
/* The bytes of the point-plot address of tube dot (x, y) into b (1..5 bytes, the omissions
** of ENCODER above), r updated. */
size_t tek_addr_bytes(struct tek_regs *r, int x, int y, uint8_t b[5]);

struct tek_enc;                 /* opaque: output, last address bytes sent, counts */

/* Start a stream to path (NULL: stdout). The header goes out with the first dot (or at
** the end of an empty picture): a job that fails before drawing sends nothing to stdout.
** T74_OK with *out set, or T74_EIO with err naming the file. */
int tek_enc_open(struct tek_enc **out, const char *path, struct t74_error *err);

/* The same onto an output already opened (display/outfile.h, one of a set): the encoder
** finishes it at the end (outfile_commit) or discards it on abort; the set publishes it. */
int tek_enc_open_to(struct tek_enc **out, struct outfile *of, struct t74_error *err);

/* The encoder as a sink (valid until tek_enc_free). */
struct sink tek_enc_sink(struct tek_enc *e);

/* Dots encoded and bytes written so far. */
uint64_t tek_enc_points(const struct tek_enc *e);
uint64_t tek_enc_bytes(const struct tek_enc *e);

/* Release e; aborts the output first when neither end nor abort has run. NULL-safe. */
void tek_enc_free(struct tek_enc *e);

/* ---- decoder ----------------------------------------------------------------------- */

#define TEK_WARN_KEEP 8         /* warnings whose text a report keeps (all are counted) */

struct tek_report {
  /* in: optional callbacks (NULL: nothing to do) and their context */
  void (*warn)(void *ctx, size_t offset, const char *msg);  /* every warning, as found */
  void (*erase)(void *ctx);                                 /* ESC FF: erase the tube */
  void (*write_through)(void *ctx, int x0, int y0, int x1, int y1);
                                /* a write-through trace in tube dots (a point: x0 == x1
                                   and y0 == y1); may lie partly outside the tube */
  void *ctx;
  /* out: what the stream held */
  size_t bytes;                 /* bytes read (all of them: decoding never stops early
                                   except on a sink failure) */
  size_t warnings;              /* warnings found */
  size_t warn_offset[TEK_WARN_KEEP];  /* byte offsets of the first warnings */
  char   warn_msg[TEK_WARN_KEEP][96]; /* and their text */
  size_t points;                /* points plotted (FS addresses, RS steps with the pen
                                   down), stored or write-through */
  size_t vectors;               /* vectors drawn (GS addresses after the first) */
  size_t moves;                 /* dark moves (the first address after GS) */
  size_t chars;                 /* alpha characters drawn (blanks included) */
  size_t erases;                /* ESC FF */
  size_t wt_traces;             /* points, vectors and strokes drawn write-through (not
                                   stored); each also went to write_through */
  size_t dots;                  /* dots sent to the stored sink (with repeats) */
};

/* Decode buf[0..n) (rep: callbacks in, counts out; the counts are cleared first). */
int tek_decode(const uint8_t *buf, size_t n, const struct sink *stored, struct tek_report *rep);

/* The stream starts with ESC, GS, FS, RS or US. */
bool tek_sniff(const uint8_t *buf, size_t n);

/* The stroke font: the strokes of printable character c (0x20..0x7E) as a string of
** grid points "xy" (x 0..4, y 0..8, baseline y = 2), strokes separated by blanks; ""
** for a blank or a character outside the font. For tests and documentation. */
const char *tek_glyph(int c);

#endif
