/*
** ilda.c — Helios frames as ILDA IDTF format-1 sections (see ilda.h for the layout and the
** source). This file contains code to append one section per frame and to close the file
** with the end header; the headers' total-frames field is written once all are known.
*/
#include "display/usb/ilda.h"

#include <stdlib.h>
#include <string.h>

void ilda_init(struct ilda_writer *w)
{
  memset(w, 0, sizeof *w);
}

void ilda_free(struct ilda_writer *w)
{
  free(w->buf);
  memset(w, 0, sizeof *w);
}

static int room(struct ilda_writer *w, size_t more, struct t74_error *err)
{
  if (w->n + more <= w->cap) return T74_OK;
  size_t cap = w->cap ? w->cap * 2 : 65536;
  while (cap < w->n + more) cap *= 2;
  unsigned char *b = realloc(w->buf, cap);
  if (!b) return t74_fail(err, T74_EIO, "ilda: out of memory");
  w->buf = b;
  w->cap = cap;
  return T74_OK;
}

static void be16(unsigned char *b, unsigned v)
{
  b[0] = (unsigned char)(v >> 8);
  b[1] = (unsigned char)v;
}

/* A section header at b: records, frame number (total frames filled later). */
static void header(unsigned char *b, int records, int number)
{
  memset(b, 0, ILDA_HEADER);
  memcpy(b, "ILDA", 4);
  b[7] = 1;                                     /* format 1: 2D, indexed colour */
  memcpy(b + 8, "tube74", 6);                   /* frame name, NUL-padded */
  memcpy(b + 16, "tube74", 6);                  /* company name */
  be16(b + 24, (unsigned)records);
  be16(b + 26, (unsigned)number);
}

int ilda_frame(struct ilda_writer *w, const unsigned char *pts, int n, struct t74_error *err)
{
  if (n <= 0) return T74_OK;
  if (n > 65535) return t74_fail(err, T74_EIO, "ilda: a frame of %d points (at most 65535)", n);
  if (w->frames >= ILDA_MAX_FRAMES)
    return t74_fail(err, T74_EIO, "ilda: more than %d frames in one file", ILDA_MAX_FRAMES);
  if (room(w, ILDA_HEADER + (size_t)n * ILDA_REC1, err) != T74_OK) return err->status;
  unsigned char *b = w->buf + w->n;
  header(b, n, w->frames);
  b += ILDA_HEADER;
  for (int k = 0; k < n; k++, b += ILDA_REC1) {
    const unsigned char *p = pts + (size_t)k * 7;
    int X = (p[0] << 4) | (p[1] >> 4), Y = ((p[1] & 0x0F) << 8) | p[2];
    int lit = p[3] || p[4] || p[5] || p[6];
    int16_t ix = (int16_t)((X - 2048) * 16), iy = (int16_t)((Y - 2048) * 16);
    be16(b, (uint16_t)ix);
    be16(b + 2, (uint16_t)iy);
    b[4] = (unsigned char)((k == n - 1 ? ILDA_LAST : 0) | (lit ? 0 : ILDA_BLANK));
    b[5] = lit ? ILDA_GREEN : 0;
  }
  w->n += ILDA_HEADER + (size_t)n * ILDA_REC1;
  w->frames++;
  return T74_OK;
}

int ilda_finish(struct ilda_writer *w, const unsigned char **bytes, size_t *len,
                struct t74_error *err)
{
  if (room(w, ILDA_HEADER, err) != T74_OK) return err->status;
  header(w->buf + w->n, 0, w->frames);          /* the end: a header with no records */
  w->n += ILDA_HEADER;
  for (size_t at = 0; at < w->n;) {             /* every header gets the total */
    be16(w->buf + at + 28, (unsigned)w->frames);
    at += ILDA_HEADER + (size_t)((w->buf[at + 24] << 8) | w->buf[at + 25]) * ILDA_REC1;
  }
  *bytes = w->buf;
  *len = w->n;
  return T74_OK;
}
