/*
** scanner.c — the drum scanner, A-D converter and disk of paper 003 (§2, §4, appendix).
** Where described: patterns/scanner.h (the model, step by step); emu/params.c (the rows
** drum_rev_s, drum_pts_mm, drum_lines_mm, adc_us, adc_bits, disk_*, with their sources).
**
** This file contains code to carry a background photograph through the 1974 input path:
** drum scan -> A-D -> scale conversion -> levels -> 4 to a word -> disk, and to read the
** rows back while the picture is displayed, counting the time each step takes. All the
** picture arithmetic is integer (pic_sample's exact box means, taken for both grids, the
** drum's and the perspective plane's, by pic_sample_twice; integer rounding; A-D through a
** table of the 256 greys); only the
** times are doubles, as they are in emu/cost.c.
*/
#include "patterns/scanner.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "patterns/halftone.h"

struct scan_image {
  int cell, W, H;               /* halftone cell and grid */
  int samples, lines;           /* drum scan geometry */
  double photo_w_mm, photo_h_mm;/* the print on the drum */
  int row_words;                /* ceil(W / 4) */
  uint16_t *words;              /* H * row_words: the picture as on the disk, disk row r =
                                   grid row H-1-r (bottom row first) */
  uint8_t *grey;                /* W * H greys after scale conversion, row-major from the top
                                   (host-side, for --dump grey only: not on the disk) */
  uint8_t *level;               /* W * H: the levels in words, unpacked, row-major from the
                                   top (host-side: scan_row's row at a time) */
  int buffered;                 /* grid row in the one-row core buffer, -1 none */
  struct scan_disk disk;        /* display-time reads */
  struct scan_disk disk0;       /* the disk as it stood before the first display read */
  double drum_seconds;          /* input: the drum's revolutions */
  double input_disk_seconds;    /* input: writing every row */
  double last_write_seconds;    /* input: the last row's write (not overlapped) */
};

/* ---- the steps ------------------------------------------------------------------- */

/* The print's size on the drum (step 1): width SCAN_PHOTO_W_MM, height by the picture's
** aspect, scaled down as a whole when it would be longer than SCAN_DRUM_MM. */
static void photo_mm(int pw, int ph, double *w_mm, double *h_mm)
{
  double w = SCAN_PHOTO_W_MM, h = SCAN_PHOTO_W_MM * (double)ph / (double)pw;
  if (h > SCAN_DRUM_MM) { w = w * SCAN_DRUM_MM / h; h = SCAN_DRUM_MM; }
  *w_mm = w;
  *h_mm = h;
}

void scan_geometry(const struct cost_params *prm, int pw, int ph, int *samples, int *lines)
{
  double w, h;
  photo_mm(pw < 1 ? 1 : pw, ph < 1 ? 1 : ph, &w, &h);
  /* a small epsilon keeps exact products (100 mm x 5.87 = 587) from rounding down */
  double s = floor(w * prm->v[CP_DRUM_PTS_MM] + 1e-9);
  double l = floor(h * prm->v[CP_DRUM_LINES_MM] + 1e-9);
  if (s < 1) s = 1;
  if (l < 1) l = 1;
  if (s > PIC_MAX_SIDE) s = PIC_MAX_SIDE;   /* absurd densities: bounded, like pictures */
  if (l > PIC_MAX_SIDE) l = PIC_MAX_SIDE;
  *samples = (int)s;
  *lines = (int)l;
}

int scan_photo_mv(int grey)
{
  if (grey < 0) grey = 0;
  if (grey > 255) grey = 255;
  return (grey * SCAN_FULL_MV + 127) / 255;
}

int scan_adc(int mv, int bits)
{
  if (bits < 1) bits = 1;
  if (bits > 16) bits = 16;
  int64_t top = ((int64_t)1 << bits) - 1;
  if (mv <= 0) return 0;
  if (mv >= SCAN_FULL_MV) return (int)top;
  return (int)(((int64_t)mv * top + SCAN_FULL_MV / 2) / SCAN_FULL_MV);
}

int scan_code_grey(int code, int bits)
{
  if (bits < 1) bits = 1;
  if (bits > 16) bits = 16;
  int64_t top = ((int64_t)1 << bits) - 1;
  if (code <= 0) return 0;
  if (code >= top) return 255;
  return (int)(((int64_t)code * 255 + top / 2) / top);
}

int scan_code_of_level(int level)
{
  if (level < 0) return 0;
  return level > SCAN_LEVEL_MAX ? SCAN_LEVEL_MAX : level;
}

uint16_t scan_pack(const uint8_t v[SCAN_WORD_LEVELS])
{
  unsigned w = 0;
  for (int k = 0; k < SCAN_WORD_LEVELS; k++) w = (w << SCAN_LEVEL_BITS) | (v[k] & 0xFu);
  return (uint16_t)w;
}

void scan_unpack(uint16_t w, uint8_t v[SCAN_WORD_LEVELS])
{
  for (int k = 0; k < SCAN_WORD_LEVELS; k++)
    v[k] = (uint8_t)((w >> (SCAN_LEVEL_BITS * (SCAN_WORD_LEVELS - 1 - k))) & 0xFu);
}

/* ---- the disk -------------------------------------------------------------------- */

void scan_disk_init(struct scan_disk *d, const struct cost_params *prm)
{
  memset(d, 0, sizeof *d);
  d->track_ms = prm->v[CP_DISK_TRACK_MS];
  d->seek_ms = prm->v[CP_DISK_SEEK_MS];
  d->rot_ms = prm->v[CP_DISK_ROT_MS];
  d->track_words = SCAN_TRACK_WORDS;
  double t = floor(prm->v[CP_DISK_MBIT] * 1e6 / (SCAN_TRACK_WORDS * 16.0));
  d->tracks = t > 1e6 ? 1000000 : (int)t;
  d->head = -1;
}

double scan_disk_access(struct scan_disk *d, uint32_t addr, uint32_t nwords)
{
  double ms = 0;
  double word_ms = 2 * d->rot_ms / d->track_words;  /* a track passes in one revolution */
  uint32_t left = nwords ? nwords : 1;               /* an access touches a word at least */
  int track = (int)(addr / (uint32_t)d->track_words);
  uint32_t in = addr % (uint32_t)d->track_words;      /* position on the track */
  d->accesses++;
  for (;;) {
    if (d->head < 0 || abs(track - d->head) > 1) { ms += d->seek_ms; d->seeks++; }
    else if (track != d->head) { ms += d->track_ms; d->track_moves++; }
    d->head = track;
    ms += d->rot_ms;                                  /* wait for the first word */
    uint32_t here = (uint32_t)d->track_words - in;    /* words left on this track */
    if (here > left) here = left;
    ms += here * word_ms;
    d->words += here;
    left -= here;
    if (left == 0) break;
    track++;
    in = 0;
  }
  d->seconds += ms / 1000;
  return ms / 1000;
}

/* ---- the whole road -------------------------------------------------------------- */

/* Point i's level in a row of packed words (SCAN_WORD_LEVELS a word, the first in the
** high bits). */
static inline unsigned level_of(const uint16_t *row, int i)
{
  return (unsigned)(row[i / SCAN_WORD_LEVELS] >>
                    (SCAN_LEVEL_BITS * (SCAN_WORD_LEVELS - 1 - i % SCAN_WORD_LEVELS))) & 0xFu;
}

void scan_free(struct scan_image *s)
{
  if (!s) return;
  free(s->words);
  free(s->grey);
  free(s->level);
  free(s);
}

int scan_photo(const struct pic *photo, int cell, const struct cost_params *prm,
               struct scan_image **out, struct t74_error *err)
{
  if (pat_levels(cell) == 0)
    return t74_fail(err, T74_EINPUT, "scanner: no halftone cell %d (3 or 4)", cell);
  struct scan_image *s = calloc(1, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "scanner: out of host memory");
  s->cell = cell;
  s->W = pat_grid_w(cell);
  s->H = pat_grid_h(cell);
  s->row_words = (s->W + SCAN_WORD_LEVELS - 1) / SCAN_WORD_LEVELS;
  s->buffered = -1;
  int pw = pic_width(photo), ph = pic_height(photo);
  photo_mm(pw, ph, &s->photo_w_mm, &s->photo_h_mm);
  scan_geometry(prm, pw, ph, &s->samples, &s->lines);
  int bits = (int)prm->v[CP_ADC_BITS];

  /* disk room */
  struct scan_disk in_disk;
  scan_disk_init(&in_disk, prm);
  uint64_t need = (uint64_t)s->row_words * (uint64_t)s->H;
  uint64_t have = (uint64_t)in_disk.tracks * (uint64_t)in_disk.track_words;
  if (need > have) {
    scan_free(s);
    return t74_fail(err, T74_EINPUT, "scanner: the picture needs %llu disk words, the "
                    "disk holds %llu", (unsigned long long)need, (unsigned long long)have);
  }

  /* step 2: the drum, one line a revolution, each sample through photocell and A-D; steps
     3-4: scale conversion onto the grid. Each sample is the print's mean grey under its
     footprint (pic_sample's exact values) and photocell and A-D are a function of that
     grey alone, so a table of 256; the samples are made a drum line at a time as the
     conversion takes them (pic_sample_twice) */
  s->words = calloc((size_t)need ? (size_t)need : 1, sizeof *s->words);
  s->grey = malloc((size_t)s->W * (size_t)s->H);
  uint8_t adc_grey[256];
  for (int g = 0; g < 256; g++) adc_grey[g] = (uint8_t)scan_code_grey(scan_adc(scan_photo_mv(g), bits), bits);
  if (!s->words || !s->grey
      || pic_sample_twice(photo, s->samples, s->lines, adc_grey, s->W, s->H, s->grey) != 0) {
    scan_free(s);
    return t74_fail(err, T74_EIO, "scanner: out of host memory");
  }
  double rev_s = prm->v[CP_DRUM_REV_S];
  double line_s = s->samples * prm->v[CP_ADC_US] * 1e-6;   /* conversions of one line */
  double revs = rev_s > 0 ? ceil(line_s / rev_s - 1e-12) : 1;
  if (revs < 1) revs = 1;
  s->drum_seconds = s->lines * revs * rev_s;

  /* steps 4-6: levels, packing, one disk write per row; each point's level also kept
     unpacked, as scan_level unpacks it (a code of 4 bits: its nibble is the code) */
  s->level = malloc((size_t)s->W * (size_t)s->H);
  if (!s->level) {
    scan_free(s);
    return t74_fail(err, T74_EIO, "scanner: out of host memory");
  }
  uint8_t code_of[256];                         /* a grey's level, as stored */
  for (int g = 0; g < 256; g++) code_of[g] = (uint8_t)scan_code_of_level(pat_level(cell, g));
  for (int r = 0; r < s->H; r++) {
    int j = s->H - 1 - r;                       /* disk row r holds grid row j */
    const uint8_t *grey = s->grey + (size_t)j * (size_t)s->W;
    uint8_t *level = s->level + (size_t)j * (size_t)s->W;
    uint16_t *w = s->words + (size_t)r * (size_t)s->row_words;
    for (int i = 0; i < s->W; i++) {
      const unsigned code = code_of[grey[i]];
      level[i] = (uint8_t)code;
      w[i / SCAN_WORD_LEVELS] |= (uint16_t)(code << SCAN_LEVEL_BITS *
                                            (SCAN_WORD_LEVELS - 1 - i % SCAN_WORD_LEVELS));
    }
    s->last_write_seconds =
      scan_disk_access(&in_disk, (uint32_t)(r * s->row_words), (uint32_t)s->row_words);
  }
  s->input_disk_seconds = in_disk.seconds;
  scan_disk_init(&s->disk, prm);
  s->disk0 = s->disk;
  *out = s;
  return T74_OK;
}

int scan_level(struct scan_image *s, int i, int j, struct cost *c)
{
  if (i < 0 || i >= s->W || j < 0 || j >= s->H) return -1;
  size_t r = (size_t)(s->H - 1 - j);
  if (s->buffered != j) {
    /* one disk access for the row; the program moves each word into the buffer */
    scan_disk_access(&s->disk, (uint32_t)(r * (size_t)s->row_words), (uint32_t)s->row_words);
    s->buffered = j;
    if (c) {
      COST_ADD_N(c, COST_IO, s->row_words);
      COST_ADD_N(c, COST_MEM, s->row_words);
    }
  }
  if (c) {                                      /* L word, shift the nibble down, N 0xF */
    COST_ADD_N(c, COST_MEM, 1);
    COST_ADD_N(c, COST_SHIFT, 1);
    COST_ADD_N(c, COST_LOGIC, 1);
  }
  return (int)level_of(s->words + r * (size_t)s->row_words, i);
}

void scan_row(const struct scan_image *s, int j, uint8_t *level, uint8_t *grey)
{
  memcpy(level, s->level + (size_t)j * (size_t)s->W, (size_t)s->W);
  memcpy(grey, s->grey + (size_t)j * (size_t)s->W, (size_t)s->W);
}

void scan_display_reset(struct scan_image *s)
{
  s->buffered = -1;
  s->disk = s->disk0;
}

int scan_grey(const struct scan_image *s, int i, int j)
{
  if (i < 0 || i >= s->W || j < 0 || j >= s->H) return -1;
  return s->grey[(size_t)j * (size_t)s->W + (size_t)i];
}

double scan_disk_seconds(const struct scan_image *s)
{
  return s->disk.seconds;
}

void scan_report(const struct scan_image *s, struct scan_stats *st)
{
  memset(st, 0, sizeof *st);
  st->samples = s->samples;
  st->lines = s->lines;
  st->W = s->W;
  st->H = s->H;
  st->cell = s->cell;
  st->row_words = s->row_words;
  st->words = (uint32_t)(s->row_words * s->H);
  st->tracks = (int)((st->words + SCAN_TRACK_WORDS - 1) / SCAN_TRACK_WORDS);
  st->photo_w_mm = s->photo_w_mm;
  st->photo_h_mm = s->photo_h_mm;
  st->drum_seconds = s->drum_seconds;
  st->input_disk_seconds = s->input_disk_seconds;
  st->scanner_seconds = s->drum_seconds + s->last_write_seconds;
  st->disk_seconds = scan_disk_seconds(s);
  st->disk_reads = s->disk.accesses;
}
