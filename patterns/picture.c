/*
** picture.c — background pictures: PGM / PNG loading and box sampling.
**
** This file contains code to read the grey picture a scene names with `background FILE`
** and to sample it at the perspective-plane points, where it shows behind all faces
** (lowest priority). In the 1974 system a picture was scanned on the drum scanner into
** 8-bit samples (docs/hardware.md); here it is a file, read whole into memory and then
** parsed, so that every read failure is an I/O error (T74_EIO) and everything found in
** the bytes themselves is an input error (T74_EINPUT "FILE: not a PGM/PNG picture: why").
** The kind is told by the first bytes ("P2", "P5", or the PNG signature), not the name.
**
** SAMPLING. The picture (pw x ph pixels) is stretched over the W x H grid. Measuring x in
** units of 1/W of a picture pixel and y in units of 1/H, every boundary is an integer:
** pixel x spans [x*W, (x+1)*W), point i spans [i*pw, (i+1)*pw) (likewise in y), so the
** area a pixel shares with a point's footprint is an integer product wx*wy, the weights
** add up to exactly pw*ph, and the mean is
**     grey(i, j) = floor((sum of pixel * wx * wy + pw*ph/2) / (pw*ph))
** — rounded to nearest, halves up, with no error at all before that one rounding.
*/
#include "patterns/picture.h"

#include "emu/file.h"

#include <png.h>
#include <setjmp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct pic {
  int w, h;                     /* width and height in pixels, 1..PIC_MAX_SIDE */
  uint8_t px[];                 /* w*h grey pixels, row-major, row 0 at the top */
};

#define NOT_PIC "not a PGM/PNG picture"   /* the common part of every T74_EINPUT message */

static struct pic *pic_alloc(int w, int h)
{
  if (w < 1 || h < 1 || w > PIC_MAX_SIDE || h > PIC_MAX_SIDE) return NULL;
  struct pic *p = malloc(sizeof *p + (size_t)w * (size_t)h);
  if (p) { p->w = w; p->h = h; }
  return p;
}

struct pic *pic_new(int w, int h, const uint8_t *grey)
{
  struct pic *p = pic_alloc(w, h);
  if (p) memcpy(p->px, grey, (size_t)w * (size_t)h);
  return p;
}

void pic_free(struct pic *p)
{
  free(p);
}

int pic_width(const struct pic *p) { return p->w; }

int pic_height(const struct pic *p) { return p->h; }

int pic_pixel(const struct pic *p, int x, int y)
{
  if (x < 0 || x >= p->w || y < 0 || y >= p->h) return -1;
  return p->px[(size_t)y * p->w + x];
}

const uint8_t *pic_rows(const struct pic *p) { return p->px; }

/* ---- PGM (Netpbm P2 / P5) -------------------------------------------------------- */

struct cursor {
  const uint8_t *b;             /* the file */
  size_t n;                     /* its length */
  size_t pos;                   /* next byte to look at */
};

static int is_space(int c)
{
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skip white space and '#' comments (to the end of their line). */
static void skip_blank(struct cursor *c)
{
  while (c->pos < c->n) {
    if (is_space(c->b[c->pos])) c->pos++;
    else if (c->b[c->pos] == '#')
      while (c->pos < c->n && c->b[c->pos] != '\n') c->pos++;
    else break;
  }
}

/* Read an unsigned decimal number after optional blanks: 1 and *v, or 0 if there is no
** digit there or the number exceeds limit. */
static int read_number(struct cursor *c, unsigned long limit, unsigned long *v)
{
  skip_blank(c);
  if (c->pos >= c->n || c->b[c->pos] < '0' || c->b[c->pos] > '9') return 0;
  unsigned long x = 0;
  while (c->pos < c->n && c->b[c->pos] >= '0' && c->b[c->pos] <= '9') {
    x = x * 10 + (unsigned long)(c->b[c->pos++] - '0');
    if (x > limit) return 0;
  }
  *v = x;
  return 1;
}

/* Parse a P2 or P5 file in b. */
static int load_pgm(const char *path, const uint8_t *b, size_t n, struct pic **out,
                    struct t74_error *err)
{
  struct cursor c = { b, n, 2 };
  int plain = b[1] == '2';      /* P2: decimal samples; P5: binary samples */
  unsigned long w, h, maxval;
  if (!read_number(&c, PIC_MAX_SIDE, &w) || !read_number(&c, PIC_MAX_SIDE, &h) || w < 1
      || h < 1)
    return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": width and height must be 1..%d",
                    path, PIC_MAX_SIDE);
  if (!read_number(&c, 65535, &maxval) || maxval < 1)
    return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": maxval must be 1..65535", path);
  if ((long)w * (long)h > PIC_MAX_PIXELS)
    return t74_fail(err, T74_EINPUT, "%s: %lu x %lu pixels is more than the limit of %ld",
                    path, w, h, PIC_MAX_PIXELS);
  if (c.pos >= c.n || !is_space(b[c.pos]))
    return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": no white space after maxval", path);
  c.pos++;                      /* the single white-space byte before the raster */

  struct pic *p = pic_alloc((int)w, (int)h);
  if (!p) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  size_t count = (size_t)w * h;           /* samples to read */
  size_t bps = maxval < 256 ? 1 : 2;      /* P5: bytes per sample, big-endian */
  if (!plain && c.n - c.pos < count * bps) {
    pic_free(p);
    return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": truncated: %zu of %zu samples",
                    path, (c.n - c.pos) / bps, count);
  }
  if (!plain && maxval == 255) {        /* bytes as they are: round(v * 255 / 255) = v */
    memcpy(p->px, b + c.pos, count);
    *out = p;
    return T74_OK;
  }
  for (size_t k = 0; k < count; k++) {
    unsigned long v;
    if (plain) {
      if (!read_number(&c, 65535, &v)) {
        skip_blank(&c);
        pic_free(p);
        if (c.pos >= c.n)
          return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": truncated: %zu of %zu samples",
                          path, k, count);
        return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": bad sample %zu", path, k);
      }
    } else {
      v = bps == 1 ? b[c.pos] : (unsigned long)b[c.pos] << 8 | b[c.pos + 1];
      c.pos += bps;
    }
    if (v > maxval) {
      pic_free(p);
      return t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": sample %lu at (%zu, %zu) exceeds "
                      "maxval %lu", path, v, k % w, k / w, maxval);
    }
    p->px[k] = (uint8_t)((v * 255 + maxval / 2) / maxval);  /* to 0..255, to nearest */
  }
  *out = p;
  return T74_OK;
}

/* ---- PNG (libpng, from memory) --------------------------------------------------- */

struct png_in {
  jmp_buf jb;                   /* back to load_png on a libpng error */
  const uint8_t *b;             /* the file */
  size_t n, pos;                /* its length, next byte to read */
  struct t74_error *err;
  const char *path;
};

static void png_in_error(png_structp png, png_const_charp msg)
{
  struct png_in *in = png_get_error_ptr(png);
  t74_fail(in->err, T74_EINPUT, "%s: " NOT_PIC ": %s", in->path, msg);
  longjmp(in->jb, 1);
}

static void png_in_warning(png_structp png, png_const_charp msg)
{
  (void)png;                    /* warnings (bad CRC in an ancillary chunk, ...) are */
  (void)msg;                    /* about data libpng skips: the picture is still good */
}

static void png_in_read(png_structp png, png_bytep out, size_t len)
{
  struct png_in *in = png_get_io_ptr(png);
  if (in->n - in->pos < len) png_error(png, "truncated");
  memcpy(out, in->b + in->pos, len);
  in->pos += len;
}

static int load_png(const char *path, const uint8_t *b, size_t n, struct pic **out,
                    struct t74_error *err)
{
  struct png_in in;
  in.b = b; in.n = n; in.pos = 0; in.err = err; in.path = path;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &in, png_in_error,
                                           png_in_warning);
  png_infop info = png ? png_create_info_struct(png) : NULL;
  if (!info) {
    if (png) png_destroy_read_struct(&png, NULL, NULL);
    return t74_fail(err, T74_EIO, "%s: out of memory", path);
  }
  /* Set after the setjmp, used on the error path: hence volatile. */
  uint8_t *volatile image = NULL;          /* the decoded rows, rowbytes each */
  png_bytep *volatile rows = NULL;         /* pointers into image */
  struct pic *volatile p = NULL;
  if (setjmp(in.jb)) {
    png_destroy_read_struct(&png, &info, NULL);
    free(image);
    free(rows);
    pic_free(p);
    return err->status;
  }
  png_set_read_fn(png, &in, png_in_read);
  png_set_user_limits(png, PIC_MAX_SIDE, PIC_MAX_SIDE);
  png_read_info(png, info);
  int type = png_get_color_type(png, info);
  png_set_expand(png);                     /* palette -> RGB, grey < 8 bit -> 8, tRNS -> alpha */
  png_set_strip_16(png);                   /* 16-bit: keep the high byte */
  if (type & PNG_COLOR_MASK_COLOR)         /* RGB or palette: to grey, libpng's weights */
    png_set_rgb_to_gray_fixed(png, 1, -1, -1);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  int w = (int)png_get_image_width(png, info);
  int h = (int)png_get_image_height(png, info);
  int ch = png_get_channels(png, info);    /* 1 grey, or 2 grey + alpha */
  size_t rowbytes = png_get_rowbytes(png, info);
  if ((ch != 1 && ch != 2) || png_get_bit_depth(png, info) != 8)
    png_error(png, "unexpected sample layout after conversion");
  if ((long)w * (long)h > PIC_MAX_PIXELS) {
    t74_fail(err, T74_EINPUT, "%s: %d x %d pixels is more than the limit of %ld", path, w, h,
             PIC_MAX_PIXELS);
    longjmp(in.jb, 1);
  }
  p = pic_alloc(w, h);
  image = malloc(rowbytes * (size_t)h);
  rows = malloc(sizeof(png_bytep) * (size_t)h);
  if (!p || !image || !rows) {
    t74_fail(err, T74_EIO, "%s: out of memory", path);
    longjmp(in.jb, 1);
  }
  for (int y = 0; y < h; y++) rows[y] = image + rowbytes * (size_t)y;
  png_read_image(png, rows);
  png_read_end(png, NULL);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const uint8_t *s = rows[y] + ch * x;
      /* grey + alpha: over the black tube face, g*a/255 to nearest */
      p->px[(size_t)y * w + x] = ch == 1 ? s[0] : (uint8_t)((s[0] * s[1] + 127) / 255);
    }
  png_destroy_read_struct(&png, &info, NULL);
  free(image);
  free(rows);
  *out = p;
  return T74_OK;
}

/* ---- loading --------------------------------------------------------------------- */

int pic_load(const char *path, struct pic **out, struct t74_error *err)
{
  uint8_t *b = NULL;            /* the whole file */
  size_t n = 0;                 /* its length */
  int rc = file_read_all(path, PIC_FILE_MAX, &b, &n, err);
  if (rc != T74_OK) return rc;
  if (n >= 8 && png_sig_cmp(b, 0, 8) == 0)
    rc = load_png(path, b, n, out, err);
  else if (n >= 2 && b[0] == 'P' && (b[1] == '2' || b[1] == '5'))
    rc = load_pgm(path, b, n, out, err);
  else if (n >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '7')
    rc = t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": Netpbm P%c is not a grey PGM "
                  "(P2 or P5)", path, b[1]);
  else
    rc = t74_fail(err, T74_EINPUT, "%s: " NOT_PIC ": unknown signature", path);
  free(b);
  return rc;
}

/* ---- sampling -------------------------------------------------------------------- */

int pic_sample(const struct pic *p, int i, int j, int W, int H)
{
  if (W < 1 || H < 1 || i < 0 || i >= W || j < 0 || j >= H) return -1;
  int64_t pw = p->w, ph = p->h;
  int64_t x0 = i * pw, x1 = (i + 1) * pw;   /* footprint in 1/W pixel units */
  int64_t y0 = j * ph, y1 = (j + 1) * ph;   /* and in 1/H pixel units */
  uint64_t sum = 0;                         /* sum of pixel * shared area */
  for (int64_t y = y0 / H; y <= (y1 - 1) / H; y++) {
    int64_t top = y * H > y0 ? y * H : y0;
    int64_t bot = (y + 1) * H < y1 ? (y + 1) * H : y1;
    uint64_t row = 0;                       /* sum of pixel * wx along this row */
    for (int64_t x = x0 / W; x <= (x1 - 1) / W; x++) {
      int64_t lo = x * W > x0 ? x * W : x0;
      int64_t hi = (x + 1) * W < x1 ? (x + 1) * W : x1;
      row += (uint64_t)p->px[y * pw + x] * (uint64_t)(hi - lo);
    }
    sum += row * (uint64_t)(bot - top);
  }
  uint64_t total = (uint64_t)(pw * ph);     /* the weights add up to exactly this */
  return (int)((sum + total / 2) / total);
}

/* One axis of the stretch, npx picture pixels over m grid points, in pic_sample's units:
** pixel x spans [x*m, (x+1)*m), point k spans [k*npx, (k+1)*npx). Point k overlaps
** pixels first[k] .. last[k] (consecutive): the first and the last by wfirst[k] and
** wlast[k] (wlast 0 when they are the same pixel), every pixel between them wholly, by m.
** Made by walking both axes together, with no division. */
struct pic_axis {
  int32_t *first, *last;        /* m each */
  uint32_t *wfirst, *wlast;     /* m each: shared lengths, 1..m (wlast 0..m) */
  bool wide;                    /* some point has pixels between its first and last */
};

static void axis_free(struct pic_axis *a)
{
  free(a->first);
  free(a->last);
  free(a->wfirst);
  free(a->wlast);
}

static int axis_make(int64_t npx, int m, struct pic_axis *a)
{
  size_t n = (size_t)(unsigned)m;
  a->first = malloc(n * sizeof *a->first);
  a->last = malloc(n * sizeof *a->last);
  a->wfirst = malloc(n * sizeof *a->wfirst);
  a->wlast = malloc(n * sizeof *a->wlast);
  if (!a->first || !a->last || !a->wfirst || !a->wlast) { axis_free(a); return -1; }
  a->wide = false;
  int64_t x = 0;                              /* the pixel the point starts in */
  for (int k = 0; k < m; k++) {
    int64_t lo = k * npx, hi = lo + npx;      /* the point's footprint */
    a->first[k] = (int32_t)x;
    if ((x + 1) * m >= hi) {                  /* all in pixel x */
      a->last[k] = (int32_t)x;
      a->wfirst[k] = (uint32_t)npx;
      a->wlast[k] = 0;
    } else {
      a->wfirst[k] = (uint32_t)((x + 1) * m - lo);
      while ((x + 2) * m < hi) x++;           /* pixels wholly inside */
      x++;                                    /* the last pixel it reaches into */
      a->last[k] = (int32_t)x;
      a->wlast[k] = (uint32_t)(hi - x * m);
      if (a->last[k] > a->first[k] + 1) a->wide = true;
    }
    if ((x + 1) * m == hi) x++;               /* the next point starts in the next pixel */
  }
  return 0;
}

/* One picture row of npx pixels along the x axis: r[i] = the sum over x of line[x] x
** (x-overlap with column i), at most 255 x npx < 2^22. When points take whole pixels
** between their first and last (ax->wide), those are one difference of the row's running
** sums, pre[npx + 1]. */
static void sample_row(const uint8_t *line, int64_t npx, const struct pic_axis *ax, int W,
                       uint32_t m, uint32_t *pre, uint32_t *r)
{
  const int32_t *first = ax->first, *last = ax->last;
  const uint32_t *wfirst = ax->wfirst, *wlast = ax->wlast;
  if (!ax->wide) {
    for (int i = 0; i < W; i++) r[i] = line[first[i]] * wfirst[i] + line[last[i]] * wlast[i];
    return;
  }
  uint32_t sum = 0;
  pre[0] = 0;
  int64_t x = 0;
  for (; x + 4 <= npx; x += 4) {              /* four a step: a loop's count and test */
    pre[x + 1] = sum += line[x];
    pre[x + 2] = sum += line[x + 1];
    pre[x + 3] = sum += line[x + 2];
    pre[x + 4] = sum += line[x + 3];
  }
  for (; x < npx; x++) pre[x + 1] = sum += line[x];
  for (int i = 0; i < W; i++) {
    int32_t a = first[i], b = last[i], e = b > a + 1 ? b : a + 1;
    r[i] = line[a] * wfirst[i] + line[b] * wlast[i] + (pre[e] - pre[a + 1]) * m;
  }
}

/* floor(n / d) for a quotient known to be 0..255, with mul = floor(2^40 / d): floor(n x mul
** / 2^40) is the quotient or one less (n x mul < 256 x 2^40: no overflow; the error is
** under n / 2^40 < 256 d / 2^40 <= 1/16, d being a picture's pixels, at most
** PIC_MAX_SIDE^2 = 2^28), set right by one comparison. */
static inline uint8_t quotient(uint64_t n, uint64_t d, uint64_t mul)
{
  uint64_t q = n * mul >> 40;
  return (uint8_t)(q + ((q + 1) * d <= n));
}

/* A piece of a grid row: n points wholly inside pixel x (wl 0), or one point (n 1) reaching
** into pixels x and x + 1 by wf and wl. */
struct pic_piece {
  int32_t x, n;
  uint32_t wf, wl;
};

/* A picture's W x H grid made a grid row at a time, in increasing order; its picture is a
** struct pic, or (src) the grid of another sampler, whose rows it asks for in increasing
** order as it needs them: so a grid of a grid holds no more than a few rows. */
struct sampler {
  const uint8_t *px;            /* the picture's pixels, or NULL: rows from src */
  struct sampler *src;          /* the sampler whose grid is the picture */
  const uint8_t *map;           /* each value through map[256] */
  int64_t pw, ph;               /* the picture's size */
  int W, H;                     /* the grid */
  struct pic_axis ax, ay;
  uint64_t total, mul;          /* pw x ph, floor(2^40 / total) (see quotient) */
  uint32_t *row;                /* W: picture row `have` sampled along x */
  uint64_t *acc;                /* W: one grid row's sums */
  uint8_t *line;                /* pw: src's row `have`, when the picture is src's grid */
  uint32_t *pre;                /* pw + 1: sample_row's running sums (ax.wide), else NULL */
  int32_t have;                 /* the picture row in row[], -1 none */
  /* narrow (pixels px, neither axis wide: sampler_row_narrow): the grid's columns, left to
     right, in nseg pieces (see struct pic_piece) */
  bool narrow;
  int32_t nseg;
  struct pic_piece *seg;
};

static void sampler_free(struct sampler *s)
{
  axis_free(&s->ax);
  axis_free(&s->ay);
  free(s->row);
  free(s->acc);
  free(s->line);
  free(s->pre);
  free(s->seg);
}

/* The pieces of a narrow sampler's columns (see struct sampler). */
static int sampler_pieces(struct sampler *s)
{
  s->seg = malloc((size_t)(unsigned)s->W * sizeof *s->seg);
  if (!s->seg) return -1;
  for (int32_t i = 0; i < s->W; i++) {
    struct pic_piece *p = s->nseg > 0 ? &s->seg[s->nseg - 1] : NULL;
    if (p && s->ax.wlast[i] == 0 && p->wl == 0 && p->x == s->ax.first[i])
      p->n++;
    else
      s->seg[s->nseg++] = (struct pic_piece){ s->ax.first[i], 1, s->ax.wfirst[i],
                                              s->ax.wlast[i] };
  }
  return 0;
}

/* The W x H grid of a pw x ph picture (pixels px, or src's grid when px is NULL). */
static int sampler_init(struct sampler *s, const uint8_t *px, struct sampler *src, int pw,
                        int ph, const uint8_t *map, int W, int H)
{
  memset(s, 0, sizeof *s);
  s->px = px;
  s->src = src;
  s->map = map;
  s->pw = pw;
  s->ph = ph;
  s->W = W;
  s->H = H;
  s->total = (uint64_t)pw * (uint64_t)ph;
  s->mul = ((uint64_t)1 << 40) / s->total;
  s->have = -1;
  int ok = axis_make(pw, W, &s->ax) == 0;
  ok = ok && axis_make(ph, H, &s->ay) == 0;
  s->row = ok ? malloc((size_t)W * sizeof *s->row) : NULL;
  s->acc = ok ? malloc((size_t)W * sizeof *s->acc) : NULL;
  s->line = ok && !px ? malloc((size_t)pw) : NULL;
  s->pre = ok && s->ax.wide ? malloc(((size_t)pw + 1) * sizeof *s->pre) : NULL;
  s->narrow = ok && px && !s->ax.wide && !s->ay.wide;
  if (!s->row || !s->acc || (!px && !s->line) || (ok && s->ax.wide && !s->pre) ||
      (s->narrow && sampler_pieces(s) != 0)) {
    sampler_free(s);
    memset(s, 0, sizeof *s);
    return -1;
  }
  return 0;
}

/* Picture row y sampled along x into s->row (once: a row a grid row shares with the next
** is the last of the one and the first of the other). */
static void sampler_take(struct sampler *s, int32_t y);

/* d[0 .. n-1] = v, n >= 1, stored one by one up to three (a run of the street's drum
** lines: one to three points; a library call for each cost more than its stores); n. */
static inline int32_t pic_fill(uint8_t *d, uint8_t v, int32_t n)
{
  d[0] = v;
  if (n > 1) {
    d[1] = v;
    if (n > 2) {
      d[2] = v;
      if (n > 3) memset(d + 3, v, (size_t)(n - 3));
    }
  }
  return n;
}

/* sampler_row of a grid over the pixels px whose points each reach into at most two
** picture rows and two columns (neither axis wide: the drum's grid of the street's picture,
** 587 x 555 over 200 x 150), straight from the pixels, with no row of sums held. The points
** of a run (wholly inside one pixel x) have the same sum, x's values by the row weights
** times pw, so one quotient serves the run; in a grid row wholly inside one picture row that
** sum is v x pw x ph + floor(total / 2), whose quotient by total is v, the pixel's value.
** Every sum is sampler_row's, the same products added (exact integers: the order does not
** matter), taken with the same quotient. */
static void sampler_row_narrow(const struct sampler *s, int j, uint8_t *dst)
{
  const uint64_t total = s->total, mul = s->mul, half = total / 2, pw = (uint64_t)s->pw;
  const struct pic_piece *seg = s->seg;
  const int32_t nseg = s->nseg;
  const uint8_t *map = s->map;
  const int32_t y0 = s->ay.first[j];
  const uint8_t *l0 = s->px + y0 * s->pw;
  const uint64_t w0 = s->ay.wfirst[j];
  uint8_t *d = dst;
  if (s->ay.last[j] == y0) {                    /* one picture row, weighed by its whole ph */
    for (int32_t k = 0; k < nseg; k++) {
      const int32_t x = seg[k].x, n = seg[k].n;
      const uint32_t wl = seg[k].wl;
      const uint8_t v = wl == 0 ? map[l0[x]]
                        : map[quotient((l0[x] * seg[k].wf + l0[x + 1] * wl) * w0 + half, total,
                                       mul)];
      d += pic_fill(d, v, n);
    }
    return;
  }
  const uint8_t *l1 = l0 + s->pw;               /* rows y0 and y0 + 1 */
  const uint64_t w1 = s->ay.wlast[j];
  for (int32_t k = 0; k < nseg; k++) {
    const int32_t x = seg[k].x, n = seg[k].n;
    const uint32_t wf = seg[k].wf, wl = seg[k].wl;
    const uint64_t sum = wl == 0 ? (l0[x] * w0 + l1[x] * w1) * pw + half
                                 : (l0[x] * wf + l0[x + 1] * wl) * w0
                                   + (l1[x] * wf + l1[x + 1] * wl) * w1 + half;
    const uint8_t v = map[quotient(sum, total, mul)];
    d += pic_fill(d, v, n);
  }
}

/* Grid row j into dst[0 .. W-1]: down the picture rows under it, the sums pic_sample makes,
** exact integers (the order they are added in does not matter), at most 255 x pw x ph
** < 2^36; then floor((sum + total/2) / total) through the map. */
static void sampler_row(struct sampler *s, int j, uint8_t *dst)
{
  if (s->narrow) {
    sampler_row_narrow(s, j, dst);
    return;
  }
  const int W = s->W;
  const uint64_t total = s->total, mul = s->mul, half = total / 2;
  int32_t y0 = s->ay.first[j], y1 = s->ay.last[j];
  for (int32_t y = y0; y < y1; y++) {         /* all but the last */
    uint64_t wy = y == y0 ? s->ay.wfirst[j] : (uint64_t)s->H;
    sampler_take(s, y);
    uint32_t *row = s->row;
    uint64_t *acc = s->acc;
    if (y == y0)
      for (int i = 0; i < W; i++) acc[i] = row[i] * wy;
    else
      for (int i = 0; i < W; i++) acc[i] += row[i] * wy;
  }
  sampler_take(s, y1);                        /* the last, taken with the quotient */
  const uint32_t *row = s->row;
  const uint64_t *acc = s->acc;
  const uint8_t *map = s->map;
  if (y0 == y1) {
    const uint64_t wy = s->ay.wfirst[j];
    for (int i = 0; i < W; i++) dst[i] = map[quotient(row[i] * wy + half, total, mul)];
  } else {
    const uint64_t wy = s->ay.wlast[j];
    for (int i = 0; i < W; i++) dst[i] = map[quotient(acc[i] + row[i] * wy + half, total, mul)];
  }
}

/* Grid rows that lie within one picture row are that row's values, alike (each takes it
** with the weight of its whole footprint): row j's key is that picture row, or -1 - j for
** a row made of several. Rows with the same key hold the same values (when the grid is
** finer than the picture, most rows: the street's drum lines, 555 from 150). */
static int64_t sampler_key(const struct sampler *s, int j)
{
  return s->ay.first[j] == s->ay.last[j] ? s->ay.first[j] : -1 - (int64_t)j;
}

static void sampler_take(struct sampler *s, int32_t y)
{
  if (y == s->have) return;
  if (s->px) {
    sample_row(s->px + y * s->pw, s->pw, &s->ax, s->W, (uint32_t)s->W, s->pre, s->row);
  } else if (s->have < 0 || sampler_key(s->src, y) != sampler_key(s->src, s->have)) {
    sampler_row(s->src, y, s->line);
    sample_row(s->line, s->pw, &s->ax, s->W, (uint32_t)s->W, s->pre, s->row);
  }                                           /* else: row `have`'s values, its sums stand */
  s->have = y;
}

/* Every grid row into out[j * W ..], a row with the key of the one before copied. */
static void sampler_all(struct sampler *s, uint8_t *out)
{
  const size_t W = (size_t)s->W;
  for (int j = 0; j < s->H; j++)
    if (j > 0 && sampler_key(s, j) == sampler_key(s, j - 1))
      memcpy(out + (size_t)j * W, out + (size_t)(j - 1) * W, W);
    else
      sampler_row(s, j, out + (size_t)j * W);
}

/* The map that leaves every value as it is. */
static void same_map(uint8_t map[256])
{
  for (int g = 0; g < 256; g++) map[g] = (uint8_t)g;
}

int pic_sample_grid(const struct pic *p, int W, int H, uint8_t *out)
{
  if (W < 1 || H < 1) return -1;
  uint8_t same[256];
  same_map(same);
  struct sampler s;
  if (sampler_init(&s, p->px, NULL, p->w, p->h, same, W, H) != 0) return -1;
  sampler_all(&s, out);
  sampler_free(&s);
  return 0;
}

int pic_sample_twice(const struct pic *p, int W1, int H1, const uint8_t map[256], int W,
                     int H, uint8_t *out)
{
  if (W1 < 1 || H1 < 1 || W < 1 || H < 1) return -1;
  struct sampler first, second;
  if (sampler_init(&first, p->px, NULL, p->w, p->h, map, W1, H1) != 0) return -1;
  uint8_t same[256];
  same_map(same);
  if (sampler_init(&second, NULL, &first, W1, H1, same, W, H) != 0) {
    sampler_free(&first);
    return -1;
  }
  sampler_all(&second, out);
  sampler_free(&second);
  sampler_free(&first);
  return 0;
}
