/*
** scanner.h — the drum scanner and the disk of paper 003: how a background photograph got
** into the 1974 system (003 §2 "パターン・データ入力", §4 "画像データ処理", appendix).
**
** This file contains code to model the road a background picture took before it could be
** shown behind the computed faces. Paper 003 §2: the photograph is wrapped on the rotating
** drum of the mechanical scanner, a light beam falls on it, a photocell takes the
** reflected light, its analogue output is A-D converted and read by the computer; the
** program converts the data "to suitable gradation levels", packs 4 data to a word and
** stores them on the disk. §4: the picture data are quantised to suitable levels by scale
** conversion and brightness conversion (尺度変換や明暗変換) and shown as the background,
** the lowest priority. The numbers are the appendix's (emu/params.c rows):
**     drum        0.75 s a turn (drum_rev_s), 5.87 points/mm around (drum_pts_mm),
**                 7.4 lines/mm along the axis (drum_lines_mm)
**     A-D         8 bits (adc_bits), 0..+10 V, 50 us a conversion (adc_us)
**     disk        10 Mbit (disk_mbit); track-to-track 30 ms (disk_track_ms), mean seek
**                 60 ms (disk_seek_ms), mean rotational delay 20 ms (disk_rot_ms)
**
** THE MODEL, step by step (scanner.c has the arithmetic):
**   1 the print   the picture file is a print SCAN_PHOTO_W_MM wide (around the drum) and as
**                 high as its aspect makes it (along the axis), at most SCAN_DRUM_MM; a
**                 taller print is scaled down to that length (both inferred, documented).
**   2 the drum    one line a revolution: samples = floor(width x 5.87), lines =
**                 floor(height x 7.4); each sample is the print's mean grey under the
**                 sample's footprint (pic_sample), a photocell voltage 0..10 V linear in
**                 that grey (0 V black, 10 V white), and an A-D code round(V/10 x 255)
**                 (with 8 bits exactly the grey again: the model's A-D loses nothing; fewer
**                 adc_bits would). Scanning time: lines x revolutions a line x 0.75 s; a
**                 line needs more than one revolution only if its conversions (samples x
**                 50 us) outlast one.
**   3 scale conversion   the samples are box-averaged onto the W x H perspective-plane
**                 grid (the picture stretched over the window, as pic_sample does now).
**   4 brightness conversion   grey -> halftone level of the cell in use (pat_level).
**   5 packing     4 levels to a 16-bit word, 4 bits each, the first (leftmost) point in bits
**                 15..12. 3x3 levels 0..9 fit. 4x4 has 17 levels, 0..16, one too many for
**                 4 bits: level 16 is stored as 15 (a background point never lights all 16
**                 dots of its cell; only grey >= 253 is affected). A row of W points takes
**                 ceil(W/4) words (25 for 4x4, 34 for 3x3, padded with zeros).
**   6 the disk    rows are stored one after another from word 0 of track 0, bottom row
**                 first (the order the Visible Surface Procedure scans, render.h). A track
**                 holds SCAN_TRACK_WORDS words; SCAN_TRACK_WORDS x 16 bits into disk_mbit
**                 gives the tracks (203 of 3072 words = 9.98 Mbit: inferred, the cylinder
**                 count of the IBM 2311 family of the time). An access costs: a mean seek
**                 (first access, or a move of more than one track) or a track-to-track move
**                 (next track), then a mean rotational delay, then the transfer at one
**                 track per revolution (revolution = 2 x mean rotational delay = 40 ms). The
**                 display's work between two rows is far longer than a revolution, so where
**                 the disk stands when the next row is wanted is as good as random: the mean
**                 delay is the honest figure.
**   7 display     during the scan, the first time a background point of grid row j is
**                 needed, row j's words are read into a one-row buffer (one disk access),
**                 then each point's level is unpacked (load, shift, mask).
** Times are kept apart: scanner_seconds is INPUT time (the drum, before the picture could
** be shown: the rows are written while the drum turns, so only the last write adds to it);
** disk_seconds and the unpacking operations belong to the display run (hitac10_seconds).
*/
#ifndef T74_SCANNER_H
#define T74_SCANNER_H

#include <stdint.h>

#include "emu/cost.h"
#include "emu/status.h"
#include "patterns/picture.h"

#define SCAN_PHOTO_W_MM   100   /* inferred: print width around the drum, mm (a 10 cm print;
                                   the paper gives no size) */
#define SCAN_DRUM_MM      250   /* inferred: longest print along the drum axis, mm */
#define SCAN_TRACK_WORDS 3072   /* inferred: 16-bit words a disk track holds */
#define SCAN_WORD_LEVELS    4   /* samples packed to a word (paper 003 §2) */
#define SCAN_LEVEL_BITS     4   /* bits a packed sample takes */
#define SCAN_LEVEL_MAX     15   /* largest storable level */
#define SCAN_FULL_MV    10000   /* A-D full scale: +10 V (paper 003 appendix) */

/* ---- the steps, each testable on its own ------------------------------------------ */

/* Samples around and lines along of a pw x ph picture (step 1-2). */
void scan_geometry(const struct cost_params *prm, int pw, int ph, int *samples, int *lines);

/* Photocell voltage in millivolts for grey 0..255 (clamped): round(grey x 10000 / 255). */
int scan_photo_mv(int grey);

/* A-D code of mv millivolts with `bits` bits (1..16): round(mv x (2^bits - 1) / 10000),
** clamped to 0 .. 2^bits - 1. */
int scan_adc(int mv, int bits);

/* A code of `bits` bits back on the 0..255 grey scale: round(code x 255 / (2^bits - 1)). */
int scan_code_grey(int code, int bits);

/* The 4-bit code stored for a halftone level: the level, 16 -> 15 (step 5). */
int scan_code_of_level(int level);

/* Pack v[0..3] (each masked to 4 bits) into a word, v[0] in bits 15..12; and back. */
uint16_t scan_pack(const uint8_t v[SCAN_WORD_LEVELS]);
void scan_unpack(uint16_t w, uint8_t v[SCAN_WORD_LEVELS]);

/* The disk model (step 6). */
struct scan_disk {
  double track_ms;              /* track-to-track move */
  double seek_ms;               /* mean random seek */
  double rot_ms;                /* mean rotational delay (a revolution is twice this) */
  int track_words;              /* words a track holds */
  int tracks;                   /* tracks on the disk */
  int head;                     /* track under the heads, -1 not known yet */
  double seconds;               /* time of every access so far */
  uint64_t accesses;            /* accesses made */
  uint64_t seeks;               /* of them (or of their track changes) mean seeks */
  uint64_t track_moves;         /* track-to-track moves */
  uint64_t words;               /* words transferred */
};

void scan_disk_init(struct scan_disk *d, const struct cost_params *prm);

/* Read or write nwords words from word address addr: the time it takes, in seconds (also
** added to d->seconds); the heads end on the last track touched. */
double scan_disk_access(struct scan_disk *d, uint32_t addr, uint32_t nwords);

/* ---- the whole road: scan, convert, pack, store; then read back while displaying ---- */

struct scan_image;              /* opaque: packed rows on the modelled disk, timings */

/* Scan photo for halftone cell 3 or 4 (steps 1-6). T74_OK with *out set; T74_EINPUT for a
** bad cell; T74_EIO when out of host memory; T74_EINPUT when the picture does not fit the
** disk (message says the words needed and available). */
int scan_photo(const struct pic *photo, int cell, const struct cost_params *prm,
               struct scan_image **out, struct t74_error *err);

void scan_free(struct scan_image *s);

/* Level stored for grid point (i, j) (0..9 for 3x3, 0..15 for 4x4), reading row j from
** the disk first when it is not the row in the buffer (step 7); the unpacking and the
** transfer instructions are counted into c (may be NULL). -1 for a point off the grid. */
int scan_level(struct scan_image *s, int i, int j, struct cost *c);

/* Row j's levels and greys, W each (W the grid's), as scan_level and scan_grey give them,
** with no disk read and nothing counted: for the points engine, which has no 1974 time
** (issue 19). j on the grid. */
void scan_row(const struct scan_image *s, int j, uint8_t *level, uint8_t *grey);

/* The display-time state back to just after scan_photo: no row in the buffer, the disk's
** heads not known, no display-time reads (for rendering the same picture again). */
void scan_display_reset(struct scan_image *s);

/* Grey 0..255 of point (i, j) after scale conversion (the value the level was made from:
** for --dump grey); -1 off the grid. */
int scan_grey(const struct scan_image *s, int i, int j);

struct scan_stats {
  int samples, lines;           /* the drum scan: samples a line, lines */
  int W, H, cell;               /* the grid the picture was converted to */
  int row_words;                /* words a row takes on the disk */
  uint32_t words;               /* words the picture takes */
  int tracks;                   /* tracks it spans */
  double photo_w_mm, photo_h_mm;/* the print's size on the drum */
  double drum_seconds;          /* revolutions x drum_rev_s */
  double input_disk_seconds;    /* writing the rows at input time (overlapped, but for the
                                   last row) */
  double scanner_seconds;       /* input time: drum_seconds + the last row's write */
  double disk_seconds;          /* display time so far: reading rows back */
  uint64_t disk_reads;          /* display-time row reads */
};

void scan_report(const struct scan_image *s, struct scan_stats *st);

/* scan_report's disk_seconds alone (read at every lit point by the display's clock). */
double scan_disk_seconds(const struct scan_image *s);

#endif
