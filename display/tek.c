/*
** tek.c — Tektronix 4010/4014 PLOT 10 streams: encoder (a sink) and decoder (onto the tube).
** Where described: display/tek.h (the interface, the dot <-> address mapping);
** docs/hardware.md "Tektronix 4010/4014 byte stream"; the Tektronix 4014 user manual
** (070-1647-00) as summarised there; character sizes as xterm and GNU tek2plot use them.
**
** This file contains code to turn the stored dots of the emulated tube into the byte
** stream a Tektronix storage-tube terminal draws, and back. A 4014 address is 12 bits a
** side, sent as 5-bit groups in bytes whose top two bits (the "tag") say which group it
** is:
**
**     byte     tag   bits      carries
**     HiY      01    0x20-3F   Y bits 11..7
**     Extra    11    0x60-7F   Y bits 1..0 (in bits 3..2), X bits 1..0 (in bits 1..0);
**                              4014 only, and only as the FIRST of two tag-11 bytes
**     LoY      11    0x60-7F   Y bits 6..2
**     HiX      01    0x20-3F   X bits 11..7; recognised as HiX because a LoY came before
**     LoX      10    0x40-5F   X bits 6..2; completes the address: the beam moves / draws
**
** THE DECODER is a state machine in the manner of rricharz/Tek4010 but with its states
** named (enum tek_mode; an ESC flag; the tag of the previous address byte) and kept in one
** context struct passed to every helper (style.md). The address registers are updated a
** group at a time, as the terminal's registers are, so omitted bytes keep their old
** value; LoX then acts by the mode: GS draws a vector from the beam (the first address
** after GS only moves), FS stores a dot, and in write-through mode neither stores. Lines
** are rasterised in tube dots with an integer Bresenham walk: both ends are mapped to dots
** first (tek_dot_of_addr), then every dot of the walk is stored, ends included.
** Nothing in the bytes can stop the decoder: every surprise is a warning with its byte
** offset, and decoding goes on with the next byte.
**
** THE STROKE FONT draws alpha text as stored vectors, as the 4014 did. Each printable
** ASCII character is a few strokes on a 5 x 9 grid (x 0..4, y 0..8; baseline y = 2, cap
** height y = 8, descenders to y = 0), scaled to the character cell of the current size
** (size 1: 56 x 88 address units = 74 columns x 35 lines, the 4010's size): grid x times
** width/6, grid y - 2 times height/11, from the cursor at the left end of the baseline.
** At the tube's resolution a size-1 character is about 5.5 x 8.6 dots, so the glyphs are
** small, as 74 columns on 400 dots must be.
*/
#include "display/tek.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/outfile.h"

/* ---------------------------------------------------------------------------------
** Tables.
*/

/* Character sizes of the 4014 (ESC 8 .. ESC ;), in address units (xterm Tekproc.c and GNU
** tek2plot give the same figures). */
static const struct tek_charsize {
  int w, h;                     /* cell width and line height, address units */
  int lines;                    /* lines on the screen (home is the top one) */
} tek_sizes[4] = {
  { 56, 88, 35 },               /* ESC 8: size 1, 74 columns (the 4010's only size) */
  { 51, 82, 38 },               /* ESC 9: size 2, 81 columns */
  { 34, 53, 58 },               /* ESC ':': size 3, 121 columns */
  { 31, 48, 64 },               /* ESC ';': size 4, 133 columns */
};

/* Incremental plot (RS) commands: the byte, and the step it makes (address units). */
static const struct tek_step {
  uint8_t code;
  int8_t dx, dy;
} tek_steps[8] = {
  { 'A',  1,  0 },              /* east */
  { 'E',  1,  1 },              /* north-east */
  { 'D',  0,  1 },              /* north */
  { 'F', -1,  1 },              /* north-west */
  { 'B', -1,  0 },              /* west */
  { 'J', -1, -1 },              /* south-west */
  { 'H',  0, -1 },              /* south */
  { 'I',  1, -1 },              /* south-east */
};

/* The stroke font, 0x20..0x7E: points "xy" on the 5 x 9 grid, strokes separated by
** blanks, a one-point stroke is a dot. tube74's own, drawn for it in the manner of a 5 x 7
** terminal dot-matrix font (caps and digits 5 x 7 from the baseline, lower case 5 x 5,
** descenders 2 below). Each row: the glyph, then the character it draws. */
static const char *const tek_font[95] = {
  "",                                        /* 0x20 */
  "2824 22",                                 /* '!' */
  "1817 3837",                               /* '"' */
  "1713 3733 0646 0444",                     /* '#' */
  "473818070615354443321203 2822",           /* '$' */
  "0248 08 42",                              /* '%' */
  "4216172837360403122244",                  /* '&' */
  "2827",                                    /* ''' */
  "38272332",                                /* '(' */
  "18272312",                                /* ')' */
  "2723 0644 0446",                          /* '*' */
  "2723 0545",                               /* '+' */
  "232211",                                  /* ',' */
  "0545",                                    /* '-' */
  "22",                                      /* '.' */
  "0248",                                    /* '/' */
  "183847433212030718 1336",                 /* '0' */
  "172822 1232",                             /* '1' */
  "07183847460242",                          /* '2' */
  "07183847463525 354443321203",             /* '3' */
  "32380444",                                /* '4' */
  "480805354443321203",                      /* '5' */
  "4738180703123243443505",                  /* '6' */
  "084812",                                  /* '7' */
  "183847463515060718 1504031232434435",     /* '8' */
  "4515060718384743321203",                  /* '9' */
  "26 23",                                   /* ':' */
  "26 232211",                               /* ';' */
  "470543",                                  /* '<' */
  "0646 0444",                               /* '=' */
  "074503",                                  /* '>' */
  "071838474624 22",                         /* '?' */
  "343616144447381807031242",                /* '@' */
  "0206284642 0545",                         /* 'A' */
  "02083847463505 3544433202",               /* 'B' */
  "4738180703123243",                        /* 'C' */
  "02083847433202",                          /* 'D' */
  "48080242 0535",                           /* 'E' */
  "480802 0535",                             /* 'F' */
  "47381807031232434525",                    /* 'G' */
  "0802 4842 0545",                          /* 'H' */
  "1838 2822 1232",                          /* 'I' */
  "2848 3833221203",                         /* 'J' */
  "0802 4804 1542",                          /* 'K' */
  "080242",                                  /* 'L' */
  "0208254842",                              /* 'M' */
  "02084248",                                /* 'N' */
  "183847433212030718",                      /* 'O' */
  "02083847463505",                          /* 'P' */
  "183847433212030718 2442",                 /* 'Q' */
  "02083847463505 2542",                     /* 'R' */
  "473818070615354443321203",                /* 'S' */
  "0848 2822",                               /* 'T' */
  "080312324348",                            /* 'U' */
  "082248",                                  /* 'V' */
  "0812253248",                              /* 'W' */
  "0842 4802",                               /* 'X' */
  "082548 2522",                             /* 'Y' */
  "08480242",                                /* 'Z' */
  "38181232",                                /* '[' */
  "0842",                                    /* '\' */
  "18383212",                                /* ']' */
  "062846",                                  /* '^' */
  "0141",                                    /* '_' */
  "1827",                                    /* '`' */
  "16364542 441403123243",                   /* 'a' */
  "0802 0516364543321203",                   /* 'b' */
  "4536160503123243",                        /* 'c' */
  "4842 4536160503123243",                   /* 'd' */
  "04444536160503123242",                    /* 'e' */
  "1217283847 0535",                         /* 'f' */
  "4536160504133344 4641301001",             /* 'g' */
  "0802 0516364542",                         /* 'h' */
  "2622 28",                                 /* 'i' */
  "3631201001 38",                           /* 'j' */
  "0802 3603 1442",                          /* 'k' */
  "18282332",                                /* 'l' */
  "0206 05162522 25364542",                  /* 'm' */
  "0206 0516364542",                         /* 'n' */
  "163645433212030516",                      /* 'o' */
  "0600 0516364543321203",                   /* 'p' */
  "4640 4536160503123243",                   /* 'q' */
  "0602 04263645",                           /* 'r' */
  "45361605143443321203",                    /* 's' */
  "1813223243 0636",                         /* 't' */
  "0603123243 4642",                         /* 'u' */
  "062246",                                  /* 'v' */
  "0612243246",                              /* 'w' */
  "0642 4602",                               /* 'x' */
  "0622 461000",                             /* 'y' */
  "06460242",                                /* 'z' */
  "38272615242332",                          /* '{' */
  "2821",                                    /* '|' */
  "18272635242312",                          /* '}' */
  "05163445",                                /* '~' */
};

const char *tek_glyph(int c)
{
  return c >= 0x20 && c <= 0x7E ? tek_font[c - 0x20] : "";
}

bool tek_sniff(const uint8_t *buf, size_t n)
{
  if (n == 0) return false;
  uint8_t c = buf[0];
  return c == TEK_ESC || c == TEK_GS || c == TEK_FS || c == TEK_RS || c == TEK_US;
}

/* ---------------------------------------------------------------------------------
** Encoder.
*/

void tek_regs_reset(struct tek_regs *r)
{
  r->hiy = r->extra = r->loy = r->hix = -1;
}

size_t tek_addr_bytes(struct tek_regs *r, int x, int y, uint8_t b[5])
{
  int X = tek_addr_of_dot(x), Y = tek_addr_of_dot(y);
  int hiy = 0x20 | ((Y >> 7) & 0x1F);
  int extra = 0x60 | ((Y & 3) << 2) | (X & 3);
  int loy = 0x60 | ((Y >> 2) & 0x1F);
  int hix = 0x20 | ((X >> 7) & 0x1F);
  int lox = 0x40 | ((X >> 2) & 0x1F);
  size_t n = 0;
  bool send_extra = extra != r->extra, send_hix = hix != r->hix;
  if (hiy != r->hiy) b[n++] = (uint8_t)hiy;
  if (send_extra) b[n++] = (uint8_t)extra;
  if (send_extra || send_hix || loy != r->loy) b[n++] = (uint8_t)loy;
  if (send_hix) b[n++] = (uint8_t)hix;
  b[n++] = (uint8_t)lox;
  r->hiy = hiy; r->extra = extra; r->loy = loy; r->hix = hix;
  return n;
}

struct tek_enc {
  struct outfile *of;           /* the output file, NULL when writing stdout */
  FILE *f;                      /* where the bytes go: outfile_stream(of) or stdout */
  struct tek_regs r;            /* what the terminal holds of the last address */
  bool started;                 /* the header has been written */
  bool finished;                /* end or abort has run */
  uint64_t points, bytes;       /* dots encoded, bytes written */
  struct t74_error err;         /* first failure of a point call, for end */
};

static void enc_put(struct tek_enc *e, const uint8_t *b, size_t n)
{
  fwrite(b, 1, n, e->f);        /* errors are noticed at the end (ferror / commit) */
  e->bytes += n;
}

int tek_enc_open(struct tek_enc **out, const char *path, struct t74_error *err)
{
  struct tek_enc *e = calloc(1, sizeof *e);
  if (!e) return t74_fail(err, T74_EIO, "%s: out of memory", path ? path : "stdout");
  if (path) {
    if (outfile_open(&e->of, path, err) != T74_OK) { free(e); return err->status; }
    e->f = outfile_stream(e->of);
  } else {
    e->f = stdout;
  }
  tek_regs_reset(&e->r);
  *out = e;
  return T74_OK;
}

int tek_enc_open_to(struct tek_enc **out, struct outfile *of, struct t74_error *err)
{
  struct tek_enc *e = calloc(1, sizeof *e);
  if (!e) {
    outfile_abort(of);
    return t74_fail(err, T74_EIO, "%s: out of memory", outfile_path(of));
  }
  e->of = of;
  e->f = outfile_stream(of);
  tek_regs_reset(&e->r);
  *out = e;
  return T74_OK;
}

/* The header, written before the first dot (or at the end of an empty picture), so that a
** job that fails before drawing sends nothing to a terminal: erase, normal stored beam
** with solid lines, graph mode, point plot. */
static void enc_start(struct tek_enc *e)
{
  static const uint8_t head[] = { TEK_ESC, TEK_FF, TEK_ESC, 0x60, TEK_GS, TEK_FS };
  if (e->started) return;
  e->started = true;
  enc_put(e, head, sizeof head);
}

static int enc_point(void *ctx, int x, int y)
{
  struct tek_enc *e = ctx;
  if (e->err.status != T74_OK) return e->err.status;
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H)
    return t74_fail(&e->err, T74_EINPUT, "tek: dot (%d, %d) is outside the %d x %d tube",
                    x, y, TUBE_W, TUBE_H);
  enc_start(e);
  uint8_t b[5];
  size_t n = tek_addr_bytes(&e->r, x, y, b);
  enc_put(e, b, n);
  e->points++;
  return T74_OK;
}

static int enc_end(void *ctx, struct t74_error *err)
{
  struct tek_enc *e = ctx;
  if (e->finished) return T74_OK;
  e->finished = true;
  if (e->err.status != T74_OK) {
    int st = t74_fail(err, e->err.status, "%s", e->err.msg);
    if (e->of) { outfile_abort(e->of); e->of = NULL; }
    return st;
  }
  static const uint8_t tail[] = { TEK_US };     /* back to alpha mode */
  enc_start(e);
  enc_put(e, tail, sizeof tail);
  if (e->of) {
    struct outfile *of = e->of;
    e->of = NULL;
    return outfile_commit(of, err);
  }
  if (fflush(e->f) != 0 || ferror(e->f))
    return t74_fail(err, T74_EIO, "stdout: cannot write the Tek stream: %s", strerror(errno));
  return T74_OK;
}

static void enc_abort(void *ctx)
{
  struct tek_enc *e = ctx;
  if (e->finished) return;
  e->finished = true;
  if (e->of) { outfile_abort(e->of); e->of = NULL; return; }
  /* a stream already under way on stdout cannot be taken back: leave the terminal in
     alpha mode at least; one not begun stays unsent */
  static const uint8_t tail[] = { TEK_US };
  if (!e->started) return;
  enc_put(e, tail, sizeof tail);
  fflush(e->f);
}

struct sink tek_enc_sink(struct tek_enc *e)
{
  struct sink s = { e, enc_point, enc_end, enc_abort };
  return s;
}

uint64_t tek_enc_points(const struct tek_enc *e) { return e->points; }
uint64_t tek_enc_bytes(const struct tek_enc *e) { return e->bytes; }

void tek_enc_free(struct tek_enc *e)
{
  if (!e) return;
  if (!e->finished) enc_abort(e);
  free(e);
}

/* ---------------------------------------------------------------------------------
** Decoder.
*/

enum tek_mode {
  TEK_ALPHA,                    /* text: printable bytes are characters */
  TEK_GRAPH,                    /* GS: addresses draw vectors */
  TEK_POINT,                    /* FS: addresses store dots */
  TEK_INCR                      /* RS: pen and step commands */
};

enum tek_beam {
  TEK_BEAM_STORE,               /* ESC ` .. o: normal or defocused beam, traces stored */
  TEK_BEAM_WRITE_THROUGH        /* ESC p .. w: dim traces, not stored */
};

struct tek_dec {
  enum tek_mode mode;           /* current mode */
  enum tek_beam beam;           /* stored or write-through */
  bool esc;                     /* the previous byte was ESC */
  size_t esc_at;                /* its offset */
  bool addr_open;               /* some bytes of an address came, its LoX not yet */
  size_t addr_at;               /* offset of the address's first byte */
  bool seen_loy;                /* a LoY came in this address: a tag-01 byte is HiX */
  int prev_tag;                 /* tag of the previous byte of this address: 0 none, 1 Hi,
                                   3 LoY (or Extra) */
  int ax, ay;                   /* address registers, 12 bits each, set group by group */
  bool dark;                    /* GS: the next address is a dark move */
  bool after_gs;                /* the previous byte was GS: a BEL now makes the first
                                   vector bright (GS BEL, xterm's CASE_PLT_STATE) */
  int csi;                      /* inside ESC [ ... (an ANSI control sequence): bytes so
                                   far, 0 when not in one */
  size_t csi_at;                /* offset of its ESC */
  char csi_buf[16];             /* its parameter and intermediate bytes, NUL-ended */
  bool pen;                     /* RS: pen down */
  int bx, by;                   /* beam (and alpha cursor) position, address units */
  int size;                     /* character size 0..3 */
  size_t at;                    /* offset of the byte being handled */
  const struct sink *stored;    /* where stored dots go */
  struct tek_report *rep;       /* callbacks and counts */
  int status;                   /* first failure of stored's point call */
};

static void warn(struct tek_dec *d, size_t at, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

static void warn(struct tek_dec *d, size_t at, const char *fmt, ...)
{
  struct tek_report *r = d->rep;
  char msg[96];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  if (r->warnings < TEK_WARN_KEEP) {
    r->warn_offset[r->warnings] = at;
    memcpy(r->warn_msg[r->warnings], msg, sizeof msg);
  }
  r->warnings++;
  if (r->warn) r->warn(r->ctx, at, msg);
}

/* Store one dot (tube coordinates); dots off the tube are skipped. Returns 1 if off. */
static int store_dot(struct tek_dec *d, int x, int y)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) return 1;
  if (d->status != T74_OK) return 0;
  d->rep->dots++;
  d->status = sink_point(d->stored, x, y);
  return 0;
}

/* Trace from address (X0, Y0) to (X1, Y1) with the current beam (a point when the ends
** are equal): stored, every dot of an integer Bresenham walk between the ends' tube dots,
** both ends included; write-through, one call of rep->write_through. Returns the number of
** dots that fell off the tube (0 for write-through). */
static int trace(struct tek_dec *d, int X0, int Y0, int X1, int Y1)
{
  int x0 = tek_dot_of_addr(X0), y0 = tek_dot_of_addr(Y0);
  int x1 = tek_dot_of_addr(X1), y1 = tek_dot_of_addr(Y1);
  if (d->beam == TEK_BEAM_WRITE_THROUGH) {
    d->rep->wt_traces++;
    if (d->rep->write_through) d->rep->write_through(d->rep->ctx, x0, y0, x1, y1);
    return 0;
  }
  int dx = abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
  int dy = -abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
  int e = dx + dy, off = 0;               /* e: the walk's error term, exact integers */
  for (;;) {
    off += store_dot(d, x0, y0);
    if (x0 == x1 && y0 == y1) break;
    int e2 = 2 * e;
    if (e2 >= dy) { e += dy; x0 += sx; }
    if (e2 <= dx) { e += dx; y0 += sy; }
  }
  return off;
}

/* Forget a partly received address (the registers keep what it set, as the terminal's
** do), warning when there was one. */
static void address_reset(struct tek_dec *d, const char *why)
{
  if (d->addr_open && why)
    warn(d, d->at, "%s interrupts the address begun at byte %zu (no LoX)", why, d->addr_at);
  d->addr_open = false;
  d->prev_tag = 0;
}

/* LoX has completed an address: act on it by the mode. */
static void address_done(struct tek_dec *d)
{
  int X = d->ax, Y = d->ay;
  size_t at = d->addr_at;
  d->addr_open = false;
  d->prev_tag = 0;
  if (d->mode == TEK_GRAPH) {
    if (d->dark) {
      d->dark = false;
      d->rep->moves++;
    } else {
      d->rep->vectors++;
      if (trace(d, d->bx, d->by, X, Y))
        warn(d, at, "vector to (%d, %d) leaves the tube (Y >= %d)", X, Y, TEK_TUBE_H);
    }
  } else {                                /* TEK_POINT */
    d->rep->points++;
    if (trace(d, X, Y, X, Y))
      warn(d, at, "point (%d, %d) is above the tube (Y >= %d)", X, Y, TEK_TUBE_H);
  }
  d->bx = X;
  d->by = Y;
}

/* A byte 0x20..0x7F in graph or point plot mode: one group of an address. */
static void address_byte(struct tek_dec *d, int c)
{
  int tag = c >> 5, v = c & 0x1F;
  if (!d->addr_open) {
    d->addr_open = true;
    d->addr_at = d->at;
    d->seen_loy = false;
  }
  switch (tag) {
  case 1:                                 /* HiX after a LoY, else HiY */
    if (d->seen_loy) d->ax = (d->ax & ~(0x1F << 7)) | v << 7;
    else             d->ay = (d->ay & ~(0x1F << 7)) | v << 7;
    break;
  case 3:                                 /* LoY; an earlier tag-11 byte was Extra */
    if (d->seen_loy) {
      /* The 4014 takes a tag-11 byte as Extra only when the next byte is tag 11 too.
         xterm's getpoint takes ANY earlier LoY of the address as the Extra byte, so for
         the malformed order LoY HiX LoY LoX it moves the first LoY's bits to the low
         bits and keeps the second as LoY. Follow xterm (the picture the user sees), and
         say that the order was wrong. */
      if (d->prev_tag != 3)
        warn(d, d->at, "LoY after HiX in the address begun at byte %zu: the first LoY "
             "taken as the Extra byte, as xterm does", d->addr_at);
      int e = (d->ay >> 2) & 0x1F;        /* it was loaded as LoY: take it back */
      d->ax = (d->ax & ~3) | (e & 3);
      d->ay = (d->ay & ~3) | ((e >> 2) & 3);
    }
    d->ay = (d->ay & ~(0x1F << 2)) | v << 2;
    d->seen_loy = true;
    break;
  default:                                /* tag 10: LoX, the address is complete */
    d->ax = (d->ax & ~(0x1F << 2)) | v << 2;
    address_done(d);
    return;
  }
  d->prev_tag = tag;
}

/* Alpha cursor motions (the 4014's, without its second margin: a line past the bottom
** wraps to the top line, at the left margin). LF and VT move the cursor ONE LINE HEIGHT
** from where it is, and the right-margin wrap moves down one line from the current Y:
** the 4014's alpha cursor is the beam position itself (a graph-mode address followed by
** US puts text anywhere), and a line feed steps that Y register by the line height.
** xterm instead snaps Y to a multiple of the line height (TCursorDown/Up/Forward in
** Tekproc.c); rricharz/Tek4010, written from the 4014 manual, steps as here. See
** docs/tek.md "Alpha cursor". */
static void line_down(struct tek_dec *d)
{
  const struct tek_charsize *cs = &tek_sizes[d->size];
  d->by -= cs->h;
  if (d->by < 0) d->by = (cs->lines - 1) * cs->h;
}

static void line_up(struct tek_dec *d)
{
  const struct tek_charsize *cs = &tek_sizes[d->size];
  d->by += cs->h;
  if (d->by > (cs->lines - 1) * cs->h) d->by = 0;
}

static void cursor_right(struct tek_dec *d)
{
  d->bx += tek_sizes[d->size].w;
  if (d->bx > TEK_ADDR_MAX) { d->bx = 0; line_down(d); }
}

/* Draw printable character c at the cursor with the stroke font, then move right. Dots off
** the tube are clipped without a warning (text at the screen's edges is normal). */
static void draw_char(struct tek_dec *d, int c)
{
  const struct tek_charsize *cs = &tek_sizes[d->size];
  const char *g = tek_glyph(c);
  d->rep->chars++;
  while (*g) {
    int px = 0, py = 0, n = 0;            /* previous point of the stroke, points so far */
    for (; g[0] && g[0] != ' ' && g[1] && g[1] != ' '; g += 2) {
      int X = d->bx + (g[0] - '0') * cs->w / 6;
      int Y = d->by + (g[1] - '2') * cs->h / 11;
      if (n > 0) trace(d, px, py, X, Y);
      px = X; py = Y; n++;
    }
    if (n == 1) trace(d, px, py, px, py);  /* a one-point stroke is a dot */
    while (*g && *g != ' ') g++;          /* (a malformed odd digit: skipped) */
    while (*g == ' ') g++;
  }
  cursor_right(d);
}

/* The byte after ESC. */
static void escape_byte(struct tek_dec *d, int c)
{
  d->esc = false;
  if (c == TEK_FF) {                      /* erase: alpha mode, cursor home */
    d->rep->erases++;
    if (d->rep->erase) d->rep->erase(d->rep->ctx);
    address_reset(d, "ESC FF");
    d->mode = TEK_ALPHA;
    d->bx = 0;
    d->by = (tek_sizes[d->size].lines - 1) * tek_sizes[d->size].h;
  } else if (c >= 0x60 && c <= 0x6F) {    /* normal (60-67) or defocused (68-6F) beam,
                                             line styles 0..7: stored, drawn solid */
    d->beam = TEK_BEAM_STORE;
  } else if (c >= 0x70 && c <= 0x77) {    /* write-through, line styles 0..7 */
    d->beam = TEK_BEAM_WRITE_THROUGH;
  } else if (c >= '8' && c <= ';') {      /* character size 1..4 */
    d->size = c - '8';
  } else if (c == 0x1A || c == 0x05 || c == 0x17 || c == 0x0E || c == 0x0F ||
             c == TEK_BEL || c == 0x00 || c == 0x16) {
    /* SUB (GIN crosshair), ENQ (status), ETB (hard copy), SO / SI (character sets),
       BEL, NUL, SYN: interactive or no effect on the picture */
  } else if (c == TEK_ESC) {
    d->esc = true;                        /* ESC ESC: the second one counts */
    d->esc_at = d->at;
  } else if (c == 0x03) {
    /* ESC ETX: xterm leaves its Tek window for the VT window (Tekparse CASE_VT_MODE);
       the stored picture stays. gnuplot's `xterm` terminal and plotutils end with it. */
  } else if (c == '[') {
    d->csi = 1;                           /* ESC [ : an ANSI control sequence follows */
    d->csi_at = d->esc_at;
    d->csi_buf[0] = 0;
  } else if (c >= 0x80) {
    warn(d, d->esc_at, "byte 0x%02X after ESC is not a 7-bit code", c);
  } else {
    warn(d, d->esc_at, "unknown escape sequence ESC 0x%02X", c);
  }
}

/* A byte of an ANSI control sequence ESC [ P..P I..I F (parameters 0x30-3F, intermediates
** 0x20-2F, final 0x40-7E). xterm's switch into its Tek window, ESC [ ? 3 8 h (DECTEK),
** begins the streams of gnuplot's `xterm` terminal and of plotutils: no warning. Any
** other sequence is skipped whole with one warning (the 4014 has none). Returns false
** when c is not part of the sequence (a control code: the sequence is cut off and c is
** handled as usual). */
static bool csi_byte(struct tek_dec *d, int c)
{
  if (c < 0x20 || c >= 0x7F) {
    warn(d, d->csi_at, "control sequence ESC [ %s cut off by byte 0x%02X", d->csi_buf, c);
    d->csi = 0;
    return false;
  }
  if (c >= 0x40) {                        /* the final byte */
    if (!(c == 'h' && !strcmp(d->csi_buf, "?38")))
      warn(d, d->csi_at, "ANSI control sequence ESC [ %s%c ignored", d->csi_buf, c);
    d->csi = 0;
    return true;
  }
  if ((size_t)d->csi < sizeof d->csi_buf) {
    d->csi_buf[d->csi - 1] = (char)c;
    d->csi_buf[d->csi] = 0;
    d->csi++;
  } else if ((size_t)d->csi == sizeof d->csi_buf) {
    warn(d, d->csi_at, "control sequence ESC [ %s... is too long: skipped", d->csi_buf);
    d->csi++;
  }
  return true;
}

/* Enter mode m (GS, FS, RS, US, CR). */
static void enter(struct tek_dec *d, enum tek_mode m, const char *name)
{
  address_reset(d, name);
  d->mode = m;
  if (m == TEK_GRAPH) d->dark = true;
  if (m == TEK_INCR) d->pen = false;
}

/* One byte of the stream. */
static void byte(struct tek_dec *d, int c)
{
  bool after_gs = d->after_gs;
  d->after_gs = false;
  if (d->esc) { escape_byte(d, c); return; }
  if (d->csi && csi_byte(d, c)) return;
  if (c >= 0x80) {
    warn(d, d->at, "byte 0x%02X is not a 7-bit code: ignored", c);
    return;
  }
  if (c < 0x20) {
    switch (c) {
    case TEK_BEL:                         /* the bell; right after GS: the first
                                             vector is drawn, not a dark move (xterm) */
      if (after_gs && d->mode == TEK_GRAPH) d->dark = false;
      return;
    case 0x00: case 0x16:                 /* NUL, SYN: fill */
      return;
    case TEK_ESC: d->esc = true; d->esc_at = d->at; return;
    case TEK_GS:  enter(d, TEK_GRAPH, "GS"); d->after_gs = true; return;
    case TEK_FS:  enter(d, TEK_POINT, "FS"); return;
    case TEK_RS:  enter(d, TEK_INCR, "RS"); return;
    case TEK_US:  enter(d, TEK_ALPHA, "US"); return;
    case TEK_CR:  enter(d, TEK_ALPHA, "CR"); d->bx = 0; return;
    case TEK_LF:
      if (d->mode == TEK_ALPHA) line_down(d);   /* in graph modes: a line break, ignored */
      return;
    case TEK_BS: case TEK_HT: case TEK_VT:
      if (d->mode == TEK_ALPHA) {
        if (c == TEK_BS) { d->bx -= tek_sizes[d->size].w; if (d->bx < 0) d->bx = 0; }
        else if (c == TEK_HT) cursor_right(d);
        else line_up(d);
        return;
      }
      break;
    default:
      break;
    }
    warn(d, d->at, "control code 0x%02X means nothing in %s mode", c,
         d->mode == TEK_ALPHA ? "alpha" : d->mode == TEK_GRAPH ? "graph" :
         d->mode == TEK_POINT ? "point plot" : "incremental plot");
    return;
  }
  switch (d->mode) {
  case TEK_ALPHA:
    if (c != 0x7F) draw_char(d, c);       /* DEL: fill, ignored */
    return;
  case TEK_GRAPH:
  case TEK_POINT:
    address_byte(d, c);                   /* DEL too: a tag-11 byte, as on the 4014 */
    return;
  case TEK_INCR:
    if (c == ' ') { d->pen = false; return; }
    if (c == 'P') { d->pen = true; return; }
    if (c == 0x7F) return;
    for (int k = 0; k < 8; k++) {
      if (tek_steps[k].code != c) continue;
      int X = d->bx + tek_steps[k].dx, Y = d->by + tek_steps[k].dy;
      if (X < 0 || X >= TEK_ADDR_MAX || Y < 0 || Y >= TEK_ADDR_MAX) {
        warn(d, d->at, "incremental step off the 4096 x 4096 address space");
        return;
      }
      d->bx = X; d->by = Y;
      if (d->pen) {
        d->rep->points++;
        if (trace(d, X, Y, X, Y))
          warn(d, d->at, "point (%d, %d) is above the tube (Y >= %d)", X, Y, TEK_TUBE_H);
      }
      return;
    }
    warn(d, d->at, "byte 0x%02X means nothing in incremental plot mode", c);
    return;
  }
}

int tek_decode(const uint8_t *buf, size_t n, const struct sink *stored, struct tek_report *rep)
{
  static const struct sink none = { NULL, NULL, NULL, NULL };
  struct tek_report in = *rep;            /* keep the callbacks, clear the counts */
  memset(rep, 0, sizeof *rep);
  rep->warn = in.warn;
  rep->erase = in.erase;
  rep->write_through = in.write_through;
  rep->ctx = in.ctx;

  struct tek_dec d;
  memset(&d, 0, sizeof d);
  d.mode = TEK_ALPHA;                     /* a terminal starts in alpha mode, at home */
  d.beam = TEK_BEAM_STORE;
  d.by = (tek_sizes[0].lines - 1) * tek_sizes[0].h;
  d.stored = stored ? stored : &none;
  d.rep = rep;
  d.status = T74_OK;
  size_t k;
  for (k = 0; k < n && d.status == T74_OK; k++) {
    d.at = k;
    byte(&d, buf[k]);
  }
  rep->bytes = k;
  if (d.status != T74_OK) return d.status;
  d.at = n;
  if (d.esc) warn(&d, d.esc_at, "the stream ends after ESC");
  if (d.csi) warn(&d, d.csi_at, "the stream ends inside the control sequence begun here");
  if (d.addr_open) warn(&d, d.addr_at, "the stream ends inside the address begun here (no LoX)");
  return T74_OK;
}
