/*
** readers.c — independent readers of what tube74 sends to plotters and terminals, for
** tests/test_stream_files.c and tests/test_serial.c (#included; the Makefile links no helpers).
**
** This file contains code written from the devices' documents, not from tube74's code, so a
** test can catch a protocol mistake:
**   an HP-GL reader (HP 7475A Interfacing and Programming Manual; hardware-facts.md): an
**     instruction is a two-letter mnemonic and its parameters — numbers separated by commas
**     or blanks — ended by `;` (blanks, CR and LF between instructions ignored). IN resets
**     (pen up, absolute plotting, the pen at the origin); SP n selects a pen (0: back in
**     its stall); PU and PD raise / lower the pen and then move to each x,y pair given (a
**     line when the pen is down); PA moves absolute to its pairs with the pen as it is, PR
**     relative; OH asks for the hard-clip limits. A pen lowered onto the paper marks the
**     point it touches; a pen-down move marks every point along it. Marks are turned into
**     tube dots with the geometry the test states (pitch, origin); a mark off that grid, a
**     pen-down line that is not along a row of dots, a point outside the hard-clip limits,
**     or an instruction not in this list is counted as bad.
**   a PLOT 10 decoder (Tektronix 4010/4014; hardware-facts.md): GS graph mode, FS point plot
**     (each address plots a point), US and CR alpha mode, ESC FF erase, ESC ` .. o beam
**     modes (ignored). An address is HiY (tag 01) [Extra (tag 11)] LoY (tag 11) HiX (tag
**     01, known as HiX because a LoY came before it) LoX (tag 10): LoX completes it, bytes
**     not sent keep their old value; of two tag-11 bytes in a row the first is the Extra
**     byte (bits 3-2 low Y, bits 1-0 low X).
** Plus small helpers: running the binary, reading files, tube dots and their comparison.
*/
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#if defined(__GNUC__)
#define DEV_UNUSED __attribute__((unused))
#else
#define DEV_UNUSED
#endif

/* ---- helpers ----------------------------------------------------------------------- */

DEV_UNUSED static const char *dev_tube74(void)
{
  const char *t = getenv("TUBE74");
  return t && *t ? t : "./tube74";
}

/* Run argv as a child, stdout to out and stderr to errf (NULL: inherited). Exit status,
** or -1 when it did not exit. */
DEV_UNUSED static int dev_run(char *const argv[], const char *out, const char *errf)
{
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (out && !freopen(out, "w", stdout)) _exit(127);
    if (errf && !freopen(errf, "w", stderr)) _exit(127);
    execv(argv[0], argv);
    _exit(127);
  }
  int st;
  if (waitpid(pid, &st, 0) < 0) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* The whole file, NUL-terminated (*n its length without the NUL); NULL (*n 0) when
   unreadable. */
DEV_UNUSED static unsigned char *dev_slurp(const char *path, size_t *n)
{
  if (n) *n = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 65536, len = 0;
  unsigned char *b = malloc(cap + 1);
  size_t got;
  while ((got = fread(b + len, 1, cap - len, f)) > 0) {
    len += got;
    if (len == cap) b = realloc(b, (cap *= 2) + 1);
  }
  fclose(f);
  b[len] = 0;
  if (n) *n = len;
  return b;
}

DEV_UNUSED static int dev_exists(const char *path)
{
  struct stat st;
  return stat(path, &st) == 0;
}

struct dev_dots {               /* tube dots */
  int n, cap;
  int (*xy)[2];
};

DEV_UNUSED static void dev_dots_add(struct dev_dots *d, int x, int y)
{
  if (d->n == d->cap) {
    d->cap = d->cap ? d->cap * 2 : 4096;
    d->xy = realloc(d->xy, sizeof *d->xy * (size_t)d->cap);
  }
  d->xy[d->n][0] = x;
  d->xy[d->n][1] = y;
  d->n++;
}

/* `tube74 render SCENE --dump points=DIR/ref.points`: the dots the tube stores. */
DEV_UNUSED static int dev_reference(const char *scene, const char *dir, struct dev_dots *d)
{
  char pts[512], arg[600];
  snprintf(pts, sizeof pts, "%s/ref.points", dir);
  snprintf(arg, sizeof arg, "points=%s", pts);
  char *argv[] = { (char *)dev_tube74(), "render", (char *)scene, "--dump", arg, NULL };
  if (dev_run(argv, NULL, NULL) != 0) return -1;
  FILE *f = fopen(pts, "r");
  if (!f) return -1;
  int x, y;
  d->n = 0;
  while (fscanf(f, "%d %d", &x, &y) == 2) dev_dots_add(d, x, y);
  fclose(f);
  return 0;
}

static int dev_cmp(const void *a, const void *b)
{
  const int *p = a, *q = b;
  return p[1] != q[1] ? p[1] - q[1] : p[0] - q[0];
}

/* 1 when a and b hold the same dots, each once, in any order. */
DEV_UNUSED static int dev_same_set(const struct dev_dots *a, const struct dev_dots *b)
{
  if (a->n != b->n) return 0;
  size_t sz = sizeof *a->xy * (size_t)(a->n + 1);
  int (*x)[2] = malloc(sz), (*y)[2] = malloc(sz);
  memcpy(x, a->xy, sizeof *x * (size_t)a->n);
  memcpy(y, b->xy, sizeof *y * (size_t)b->n);
  qsort(x, (size_t)a->n, sizeof *x, dev_cmp);
  qsort(y, (size_t)b->n, sizeof *y, dev_cmp);
  int same = memcmp(x, y, sizeof *x * (size_t)a->n) == 0;
  for (int k = 1; k < a->n && same; k++)
    if (!dev_cmp(x[k - 1], x[k])) same = 0;
  free(x);
  free(y);
  return same;
}

/* A fresh scratch folder under /tmp. */
DEV_UNUSED static char *dev_tmpdir(void)
{
  static const char tmpl[] = "/tmp/tube74-dev-XXXXXX";
  char *t = malloc(sizeof tmpl);
  memcpy(t, tmpl, sizeof tmpl);
  if (!mkdtemp(t)) { free(t); return NULL; }
  return t;
}

DEV_UNUSED static void dev_rmdir(const char *dir)
{
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) { /* scratch only */ }
}

/* ---- HP-GL ------------------------------------------------------------------------- */

struct hpgl_reader {
  /* set by the test: the grid tube dots are expected on, and the hard-clip limits */
  long pitch, ox, oy;
  long clip[4];
  /* state */
  char ins[128];                /* the instruction being read */
  int nins;
  long X, Y;
  int down, pen, relative;
  /* what was drawn */
  struct dev_dots marks;
  int inits, bad, off_grid, clipped, diagonal, oh;
  char last[16];                /* the last mnemonic */
};

DEV_UNUSED static void hpgl_reader_init(struct hpgl_reader *r, long pitch, long ox, long oy,
                                        long x0, long y0, long x1, long y1)
{
  struct dev_dots keep = r->marks;
  memset(r, 0, sizeof *r);
  r->marks = keep;
  r->marks.n = 0;
  r->pitch = pitch;
  r->ox = ox;
  r->oy = oy;
  r->clip[0] = x0; r->clip[1] = y0; r->clip[2] = x1; r->clip[3] = y1;
}

static void hpgl_mark(struct hpgl_reader *r)
{
  if (r->X < r->clip[0] || r->X > r->clip[2] || r->Y < r->clip[1] || r->Y > r->clip[3]) {
    r->clipped++;
    return;
  }
  long dx = r->X - r->ox, dy = r->Y - r->oy;
  if (dx < 0 || dy < 0 || dx % r->pitch || dy % r->pitch) { r->off_grid++; return; }
  dev_dots_add(&r->marks, (int)(dx / r->pitch), (int)(dy / r->pitch));
}

/* Move to (x, y) with the pen as it is: a pen-down line marks every grid point on it. */
static void hpgl_move(struct hpgl_reader *r, long x, long y)
{
  if (x < r->clip[0] || x > r->clip[2] || y < r->clip[1] || y > r->clip[3]) r->clipped++;
  if (r->down) {
    if (y != r->Y && x != r->X) { r->diagonal++; r->X = x; r->Y = y; return; }
    if (y != r->Y) { r->diagonal++; r->X = x; r->Y = y; return; }   /* the tube's runs are rows */
    if ((x - r->X) % r->pitch) { r->off_grid++; r->X = x; return; }
    long step = x > r->X ? r->pitch : -r->pitch;
    while (r->X != x) { r->X += step; hpgl_mark(r); }
  } else {
    r->X = x;
    r->Y = y;
  }
}

static void hpgl_exec(struct hpgl_reader *r, char *c)
{
  while (*c == ' ' || *c == '\r' || *c == '\n' || *c == '\t') c++;
  if (!*c) return;
  if (!(c[0] >= 'A' && c[0] <= 'Z' && c[1] >= 'A' && c[1] <= 'Z')) { r->bad++; return; }
  char op[3] = { c[0], c[1], 0 };
  snprintf(r->last, sizeof r->last, "%s", op);
  long v[64];
  int nv = 0;
  for (char *s = c + 2; *s;) {
    if (*s == ',' || *s == ' ') { s++; continue; }
    char *end;
    long x = strtol(s, &end, 10);
    if (end == s || nv == 64) { r->bad++; return; }
    v[nv++] = x;
    s = end;
  }
  if (!strcmp(op, "IN")) { r->inits++; r->down = 0; r->relative = 0; r->X = r->Y = 0; }
  else if (!strcmp(op, "SP")) r->pen = nv ? (int)v[0] : 0;
  else if (!strcmp(op, "OH")) r->oh++;
  else if (!strcmp(op, "PU") || !strcmp(op, "PD") || !strcmp(op, "PA") || !strcmp(op, "PR")) {
    if (nv % 2) { r->bad++; return; }
    if (op[1] == 'A') r->relative = 0;
    if (op[1] == 'R') r->relative = 1;
    if (op[1] == 'D') {
      if (!r->pen) { r->bad++; return; }        /* drawing with no pen selected */
      if (!r->down) hpgl_mark(r);               /* the pen touches the paper */
      r->down = 1;
    }
    if (op[1] == 'U') r->down = 0;
    for (int k = 0; k < nv; k += 2) {
      long x = r->relative ? r->X + v[k] : v[k], y = r->relative ? r->Y + v[k + 1] : v[k + 1];
      hpgl_move(r, x, y);
    }
  } else r->bad++;
}

/* Feed n bytes (any pieces). */
DEV_UNUSED static void hpgl_feed(struct hpgl_reader *r, const unsigned char *b, size_t n)
{
  for (size_t k = 0; k < n; k++) {
    if (b[k] == ';') {
      r->ins[r->nins] = 0;
      hpgl_exec(r, r->ins);
      r->nins = 0;
    } else if (r->nins < (int)sizeof r->ins - 1) {
      r->ins[r->nins++] = (char)b[k];
    } else {
      r->bad++;
    }
  }
}

/* ---- PLOT 10 ----------------------------------------------------------------------- */

enum p10_mode { P10_ALPHA, P10_GRAPH, P10_POINT };

struct plot10 {
  enum p10_mode mode;
  int esc;                      /* the previous byte was ESC */
  int hiy, loy, hix, lox, extra;
  int prev_tag;                 /* tag of the previous address byte, -1 none */
  int first_after_gs;
  struct dev_dots pts;          /* addresses point-plotted (X, Y), in order */
  int erases, bad, vectors;
  int bytes_before_first_point; /* stream offset of the first point */
  long offset;
};

DEV_UNUSED static void plot10_init(struct plot10 *d)
{
  struct dev_dots keep = d->pts;
  memset(d, 0, sizeof *d);
  d->pts = keep;
  d->pts.n = 0;
  d->prev_tag = -1;
  d->bytes_before_first_point = -1;
}

DEV_UNUSED static void plot10_byte(struct plot10 *d, int c)
{
  d->offset++;
  if (d->esc) {
    d->esc = 0;
    if (c == 0x0C) { d->erases++; d->mode = P10_ALPHA; d->pts.n = 0; return; }   /* erase */
    if (c >= 0x60 && c <= 0x6F) return;         /* beam and line modes, stored */
    d->bad++;
    return;
  }
  if (c == 0x1B) { d->esc = 1; return; }
  if (c == 0x1D) { d->mode = P10_GRAPH; d->first_after_gs = 1; d->prev_tag = -1; return; }
  if (c == 0x1C) { d->mode = P10_POINT; d->prev_tag = -1; return; }
  if (c == 0x1F || c == 0x0D) { d->mode = P10_ALPHA; return; }
  if (c == 0x00 || c == 0x16 || c == 0x7F) return;      /* fill */
  if (d->mode == P10_ALPHA) return;             /* text: not what these tests send */
  int tag = c >> 5;
  if (c < 0x20 || tag > 3) { d->bad++; return; }
  int v = c & 0x1F;
  if (tag == 1) {                               /* HiY, or HiX after a LoY */
    if (d->prev_tag == 3) d->hix = v;
    else d->hiy = v;
  } else if (tag == 3) {                        /* LoY; of two in a row the first was Extra */
    if (d->prev_tag == 3) d->extra = d->loy;
    d->loy = v;
  } else if (tag == 2) {                        /* LoX: the address is complete */
    d->lox = v;
    int X = d->hix << 7 | d->lox << 2 | (d->extra & 3);
    int Y = d->hiy << 7 | d->loy << 2 | (d->extra >> 2 & 3);
    if (d->mode == P10_POINT) {
      if (d->bytes_before_first_point < 0) d->bytes_before_first_point = (int)d->offset;
      dev_dots_add(&d->pts, X, Y);
    } else if (d->first_after_gs) {
      d->first_after_gs = 0;
    } else {
      d->vectors++;
    }
  }
  d->prev_tag = tag;
}
