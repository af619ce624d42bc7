/*
** preview.c — the pen / beam path of a device run as an SVG file (see preview.h).
**
** This file contains code to keep two SVG path strings while a profile drives its device:
** `down` (what is drawn) and `up` (pen-up travel, blanked jumps), in the device's units,
** and to wrap them in one well-formed SVG document at the end. Invariant: `down` gets an
** "M" whenever the pen goes down, so every drawn subpath starts where the pen touched;
** `moved` says whether the pen moved since, so a pen lifted without a move leaves "h0" (a
** dot). Source: SVG 1.1 (path data M L h; zero-length subpaths with round caps are drawn).
*/
#include "display/usb/preview.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct pv_buf {                 /* a growing string */
  char *s;
  size_t n, cap;
  int failed;                   /* out of memory: the preview says so at write */
};

struct preview {
  double x0, y0, x1, y1;        /* the device's area */
  int y_up;
  double per_mm;
  char what[96];
  int have_area;
  double x, y;                  /* where the pen is */
  int down, moved;
  int up_open;                  /* the last thing in `up` ended at (x, y): continue it */
  struct pv_buf dn, up;
  long long dots, lines, travels;
};

static void pv_add(struct pv_buf *b, const char *fmt, double u, double v, int two)
{
  char t[64];
  int n = two ? snprintf(t, sizeof t, fmt, u, v) : snprintf(t, sizeof t, fmt, u);
  if (n <= 0 || b->failed) return;
  if (b->n + (size_t)n + 1 > b->cap) {
    size_t cap = b->cap ? b->cap * 2 : 65536;
    while (cap < b->n + (size_t)n + 1) cap *= 2;
    char *s = realloc(b->s, cap);
    if (!s) { b->failed = 1; return; }
    b->s = s;
    b->cap = cap;
  }
  memcpy(b->s + b->n, t, (size_t)n + 1);
  b->n += (size_t)n;
}

int preview_new(struct preview **out, struct t74_error *err)
{
  *out = calloc(1, sizeof **out);
  if (!*out) return t74_fail(err, T74_EIO, "svg preview: out of memory");
  return T74_OK;
}

void preview_free(struct preview *p)
{
  if (!p) return;
  free(p->dn.s);
  free(p->up.s);
  free(p);
}

void preview_area(struct preview *p, double x0, double y0, double x1, double y1, int y_up,
                  double per_mm, const char *what)
{
  if (!p) return;
  p->x0 = x0 < x1 ? x0 : x1;
  p->x1 = x0 < x1 ? x1 : x0;
  p->y0 = y0 < y1 ? y0 : y1;
  p->y1 = y0 < y1 ? y1 : y0;
  p->y_up = y_up;
  p->per_mm = per_mm;
  snprintf(p->what, sizeof p->what, "%s", what ? what : "");
  p->have_area = 1;
}

/* SVG y of device y. */
static double sy(const struct preview *p, double y)
{
  return p->y_up ? p->y0 + p->y1 - y : y;
}

void preview_at(struct preview *p, double x, double y)
{
  if (!p) return;
  p->x = x;
  p->y = y;
  p->up_open = 0;
}

void preview_pen(struct preview *p, int down)
{
  if (!p || (down != 0) == p->down) return;
  if (down) {
    pv_add(&p->dn, "M%g", p->x, 0, 0);
    pv_add(&p->dn, " %g", sy(p, p->y), 0, 0);
    p->moved = 0;
  } else if (!p->moved) {
    pv_add(&p->dn, "h0", 0, 0, 0);
    p->dots++;
  }
  p->down = down != 0;           /* (a pen lowered and lifted in place: `up` goes on) */
}

void preview_to(struct preview *p, double x, double y)
{
  if (!p || (x == p->x && y == p->y)) return;
  if (p->down) {
    pv_add(&p->dn, "L%g %g", x, sy(p, y), 1);
    p->moved = 1;
    p->lines++;
    p->up_open = 0;
  } else {
    if (!p->up_open) pv_add(&p->up, "M%g %g", p->x, sy(p, p->y), 1);
    pv_add(&p->up, "L%g %g", x, sy(p, y), 1);
    p->up_open = 1;
    p->travels++;
  }
  p->x = x;
  p->y = y;
}

/* text with & < > " escaped (element content and attribute values alike). */
static void put_escaped(struct outfile *of, const char *t)
{
  for (; *t; t++) {
    if (*t == '&') outfile_printf(of, "&amp;");
    else if (*t == '<') outfile_printf(of, "&lt;");
    else if (*t == '>') outfile_printf(of, "&gt;");
    else if (*t == '"') outfile_printf(of, "&quot;");
    else if ((unsigned char)*t < 0x20 && *t != '\n') outfile_printf(of, " ");
    else outfile_printf(of, "%c", *t);
  }
}

int preview_write(const struct preview *p, struct outfile *of, const char *title,
                  const char *desc, struct t74_error *err)
{
  if (p->dn.failed || p->up.failed)
    return t74_fail(err, T74_EIO, "%s: svg preview: out of memory", outfile_path(of));
  double x0 = p->have_area ? p->x0 : 0, x1 = p->have_area ? p->x1 : 1;
  double y0 = p->have_area ? p->y0 : 0, y1 = p->have_area ? p->y1 : 1;
  double w = x1 - x0, h = y1 - y0;
  if (w <= 0) w = 1;
  if (h <= 0) h = 1;
  double pen = (w > h ? w : h) / 800.0;          /* a stroke about 1 px of an 800 px view */
  if (p->per_mm > 0 && 0.3 * p->per_mm < pen * 3) pen = 0.3 * p->per_mm;   /* 0.3 mm pen */
  outfile_printf(of, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  if (p->per_mm > 0)
    outfile_printf(of, "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" "
                   "width=\"%.2fmm\" height=\"%.2fmm\" viewBox=\"%g %g %g %g\">\n",
                   w / p->per_mm, h / p->per_mm, x0, y0, w, h);
  else
    outfile_printf(of, "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" "
                   "width=\"800\" height=\"%.0f\" viewBox=\"%g %g %g %g\">\n", 800.0 * h / w,
                   x0, y0, w, h);
  outfile_printf(of, "<title>");
  put_escaped(of, title ? title : "tube74 stream");
  outfile_printf(of, "</title>\n<desc>");
  put_escaped(of, p->what);
  if (desc) {
    outfile_printf(of, "; ");
    put_escaped(of, desc);
  }
  outfile_printf(of, "; %lld dots, %lld drawn lines, %lld pen-up moves</desc>\n", p->dots,
                 p->lines, p->travels);
  outfile_printf(of, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"#fbfbf6\" "
                 "stroke=\"#c8c8c0\" stroke-width=\"%g\"/>\n", x0, y0, w, h, pen);
  outfile_printf(of, "<path fill=\"none\" stroke=\"#4a7fd0\" stroke-opacity=\"0.5\" "
                 "stroke-width=\"%g\" stroke-dasharray=\"%g %g\" d=\"%s\"/>\n", pen / 2, pen * 2,
                 pen * 2, p->up.s ? p->up.s : "");
  outfile_printf(of, "<path fill=\"none\" stroke=\"#111\" stroke-width=\"%g\" "
                 "stroke-linecap=\"round\" stroke-linejoin=\"round\" d=\"%s\"/>\n", pen * 1.5,
                 p->dn.s ? p->dn.s : "");
  return outfile_printf(of, "</svg>\n");
}
