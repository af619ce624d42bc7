/*
** import.c — the text line reader of the scene module, and Wavefront .obj / .off import
** onto the integer grid (shared/CONTRACT.md "Scene files"; paper 003 §2.1 for the grid).
**
** This file contains code to read scene text safely and to turn polygon meshes into a
** tube74 scene. The reader takes the whole file into memory and hands out one line at a
** time as blank-separated tokens with `#` comments removed; lines end at LF, CR LF or a
** lone CR, and a UTF-8 byte order mark at the start is skipped; it refuses a file in
** UTF-16 by name, NUL bytes and over-large files, so no later stage meets them. Imports then map the mesh onto the
** integer grid the 1974 system used (import.h gives the mapping): uniform scale, round to
** nearest. A face with fewer than 3 vertices in the file, or whose edges cross in the file
** (a bow-tie; decided exactly on the file's numbers), is refused with FILE:LINE.
** Rounding can break what held in floating point: a planar quad usually stops being
** exactly planar, a thin face can collapse. Each face is therefore re-checked with the
** same exact test a .s74 face must pass (scene_check_face); a face that is no longer
** planar is split by exact ear clipping into triangles covering exactly its region (seen
** along its dominant axis), the same triangles however its ring is written; one that has
** collapsed is dropped, each with a warning "FILE:LINE: warning: ..." on stderr, counted
** in scene->warnings; one that rounding made self-intersecting is refused. Every face is
** handled on its own, so the scene does not depend on the order faces are listed in
** (only the face numbers, which are the file's order, do).
*/
#include "render/import.h"
#include "render/plane.h"
#include "render/turn.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Coordinates of .obj/.off files: 0, or of magnitude COORD_SMALL .. COORD_BIG, so that
   products of two stay exact as double pairs (check_file_face). */
#define COORD_BIG   0x1p400
#define COORD_SMALL 0x1p-400

/* ---- the line reader -------------------------------------------------------------- */

/* A text in UTF-16, as some Windows editors save it: a byte-order mark (FF FE, FE FF), or
   none but the first line's characters all ASCII with a NUL beside each (every second
   byte zero, the others not). The kind, for the message, or NULL. */
static const char *utf16_kind(const unsigned char *b, size_t len)
{
  if (len >= 2 && b[0] == 0xFF && b[1] == 0xFE) return "it starts with a byte-order mark FF FE";
  if (len >= 2 && b[0] == 0xFE && b[1] == 0xFF) return "it starts with a byte-order mark FE FF";
  size_t n = len < 64 ? len & ~(size_t)1 : 64;
  if (n < 4) return NULL;
  int even0 = 0, odd0 = 0;               /* zero bytes at even and at odd offsets */
  for (size_t k = 0; k < n; k++) {
    if (b[k] == 0) { if (k % 2) odd0++; else even0++; }
    else if (b[k] >= 0x80) return NULL;
  }
  if (odd0 == (int)(n / 2) && even0 == 0) return "little-endian, no byte-order mark";
  if (even0 == (int)(n / 2) && odd0 == 0) return "big-endian, no byte-order mark";
  return NULL;
}

int import_open(struct import_reader *r, const char *path, struct t74_error *err)
{
  memset(r, 0, sizeof *r);
  r->file = path;
  FILE *fp = fopen(path, "rb");
  if (!fp) return t74_fail(err, T74_EIO, "%s: cannot read: %s", path, strerror(errno));
  size_t cap = 1 << 16, len = 0;
  char *buf = malloc(cap);
  if (!buf) {
    fclose(fp);
    return t74_fail(err, T74_EIO, "%s: cannot read: out of memory", path);
  }
  for (;;) {
    if (len + 1 >= cap) {
      char *nb = realloc(buf, cap * 2);
      if (!nb) {
        free(buf);
        fclose(fp);
        return t74_fail(err, T74_EIO, "%s: cannot read: out of memory", path);
      }
      buf = nb;
      cap *= 2;
    }
    size_t got = fread(buf + len, 1, cap - 1 - len, fp);
    len += got;
    if (got == 0 || len > IMPORT_FILE_MAX) break;   /* so cap stays <= 2 * the limit */
  }
  if (ferror(fp)) {
    int e = errno;
    free(buf);
    fclose(fp);
    return t74_fail(err, T74_EIO, "%s: cannot read: %s", path, strerror(e ? e : EIO));
  }
  fclose(fp);
  if (len > IMPORT_FILE_MAX) {
    free(buf);
    return t74_fail(err, T74_EINPUT, "%s: too large (more than %zu bytes)", path,
                    (size_t)IMPORT_FILE_MAX);
  }
  buf[len] = '\0';
  const char *u16 = utf16_kind((const unsigned char *)buf, len);
  if (u16) {
    free(buf);
    return t74_fail_at(err, T74_EINPUT, path, 1, "the file is UTF-16 (%s): save it as ASCII "
                       "or UTF-8", u16);
  }
  r->buf = buf;
  r->len = len;
  if (len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0) r->pos = 3;   /* UTF-8 byte order mark */
  return T74_OK;
}

/* Byte classes of the line reader, one table look-up a byte (issue 12): BC_END ends the
   line scan (LF, CR, NUL); in a line BC_BLANK separates tokens (blank, tab, CR, FF, VT) and BC_STOP
   ends the last one (NUL, or the `#` of a comment). */
enum { BC_END = 1, BC_BLANK = 2, BC_STOP = 4 };
static const unsigned char byte_class[256] = {
  ['\0'] = BC_END | BC_STOP, ['\n'] = BC_END, ['\r'] = BC_END | BC_BLANK, [' '] = BC_BLANK,
  ['\t'] = BC_BLANK, ['\f'] = BC_BLANK, ['\v'] = BC_BLANK, ['#'] = BC_STOP,
};

static unsigned char byte_of(const char *p) { return byte_class[(unsigned char)*p]; }

int import_next(struct import_reader *r, struct t74_error *err)
{
  while (r->pos < r->len) {
    char *start = r->buf + r->pos, *last = r->buf + r->len;   /* *last is the NUL */
    /* the tokens and the line's end in one pass (issue 19): blanks (not CR, which ends
       the line) between tokens; the scan stops at the line's end or a comment's `#` */
    r->ntok = 0;
    char *p = start;
    for (;;) {
      while (byte_of(p) == BC_BLANK) p++;
      if (byte_of(p) & (BC_END | BC_STOP)) break;
      if (r->ntok == r->cap) {
        int ncap = r->cap ? r->cap * 2 : 16;   /* tokens < 2^30 (file size): no overflow */
        char **nt = realloc(r->tok, (size_t)ncap * sizeof *nt);
        if (!nt) return t74_fail(err, T74_EIO, "%s: out of memory", r->file);
        r->tok = nt;
        r->cap = ncap;
      }
      r->tok[r->ntok++] = p;
      while (!(byte_of(p) & (BC_BLANK | BC_END | BC_STOP))) p++;
      if (byte_of(p) != BC_BLANK) break;
      *p++ = '\0';
    }
    char *end = p;                           /* the first LF, CR or NUL of the line */
    while (!(byte_of(end) & BC_END)) end++;  /* (past a comment) */
    bool nul = end < last && *end == '\0';   /* a NUL before the line's end */
    /* the line ends at LF, CR LF or a lone CR (old Mac files): each counts one line */
    r->pos = (size_t)(end - r->buf) + 1;
    if (end < last && *end == '\r' && end + 1 < last && end[1] == '\n') r->pos++;
    r->line = ++r->nlines;
    if (nul) {
      r->ntok = 0;
      return t74_fail_at(err, T74_EINPUT, r->file, r->line, "NUL byte in the line");
    }
    *p = '\0';                               /* the last token's end */
    *end = '\0';
    if (r->ntok > 0) return 1;
  }
  r->ntok = 0;
  return 0;
}

void import_close(struct import_reader *r)
{
  free(r->buf);
  free(r->tok);
  memset(r, 0, sizeof *r);
}

void import_sort(void *base, size_t n, size_t size, int (*cmp)(const void *, const void *))
{
  if (n > 16 || size > 64) {
    qsort(base, n, size, cmp);
    return;
  }
  unsigned char *b = base, t[64];
  for (size_t i = 1; i < n; i++) {
    size_t j = i;
    memcpy(t, b + i * size, size);
    while (j > 0 && cmp(b + (j - 1) * size, t) > 0) {
      memcpy(b + j * size, b + (j - 1) * size, size);
      j--;
    }
    if (j != i) memcpy(b + j * size, t, size);
  }
}

const char *import_show(const char *tok, char *buf, size_t n)
{
  if (n == 0) return "";
  size_t k = 0, limit = n > 44 ? 40 : (n > 4 ? n - 4 : 0);
  for (; tok[k] && k < limit; k++) {
    unsigned char c = (unsigned char)tok[k];
    buf[k] = (c >= 0x20 && c < 0x7f) ? (char)c : '?';
  }
  if (tok[k] && n >= 4) { memcpy(buf + k, "...", 3); k += 3; }
  buf[k] = '\0';
  return buf;
}

int import_int(const char *tok, long lo, long hi, long *out)
{
  const char *p = tok;
  bool neg = false;
  if (*p == '+' || *p == '-') neg = *p++ == '-';
  if (!*p) return 1;
  long long v = 0;
  bool big = false;
  for (; *p; p++) {
    if (*p < '0' || *p > '9') return 1;
    if (!big) {
      v = v * 10 + (*p - '0');
      if (v > 1000000000000LL) big = true;     /* beyond every range: stop before overflow */
    }
  }
  if (neg) v = -v;
  if (big || v < lo || v > hi) return 2;
  *out = (long)v;
  return 0;
}

/* ---- mesh as read ----------------------------------------------------------------- */

struct mesh {
  double *xyz;            /* 3 per vertex */
  int    *vline;
  int     nv, capv;
  long   *idx;            /* face vertex indices, 0-based (positive .obj refs unchecked) */
  size_t  nidx, capidx;
  size_t *fstart;         /* nf + 1 offsets into idx */
  int    *fline;
  int     nf, capf;
};

static void mesh_free(struct mesh *m)
{
  free(m->xyz);
  free(m->vline);
  free(m->idx);
  free(m->fstart);
  free(m->fline);
}

static int oom(const char *file, struct t74_error *err)
{
  return t74_fail(err, T74_EIO, "%s: out of memory", file);
}

static int add_vertex(struct mesh *m, const double p[3], int line, const char *file,
                      struct t74_error *err)
{
  if (m->nv >= IMPORT_COUNT_MAX)
    return t74_fail_at(err, T74_EINPUT, file, line, "more than %ld vertices", IMPORT_COUNT_MAX);
  if (m->nv == m->capv) {
    int nc = m->capv ? m->capv * 2 : 64;
    double *nx = realloc(m->xyz, (size_t)nc * 3 * sizeof *nx);
    if (!nx) return oom(file, err);
    m->xyz = nx;
    int *nl = realloc(m->vline, (size_t)nc * sizeof *nl);
    if (!nl) return oom(file, err);
    m->vline = nl;
    m->capv = nc;
  }
  memcpy(m->xyz + 3 * m->nv, p, 3 * sizeof *p);
  m->vline[m->nv++] = line;
  return T74_OK;
}

/* Start a face at this line; indices follow with add_index. */
static int begin_face(struct mesh *m, int line, const char *file, struct t74_error *err)
{
  if (m->nf >= IMPORT_COUNT_MAX)
    return t74_fail_at(err, T74_EINPUT, file, line, "more than %ld faces", IMPORT_COUNT_MAX);
  if (m->nf + 1 >= m->capf) {
    int nc = m->capf ? m->capf * 2 : 64;
    size_t *ns = realloc(m->fstart, (size_t)(nc + 1) * sizeof *ns);
    if (!ns) return oom(file, err);
    m->fstart = ns;
    int *nl = realloc(m->fline, (size_t)nc * sizeof *nl);
    if (!nl) return oom(file, err);
    m->fline = nl;
    m->capf = nc;
  }
  m->fstart[m->nf] = m->nidx;
  m->fline[m->nf] = line;
  m->nf++;
  m->fstart[m->nf] = m->nidx;
  return T74_OK;
}

static int add_index(struct mesh *m, long i, const char *file, struct t74_error *err)
{
  if (m->nidx == m->capidx) {
    size_t nc = m->capidx ? m->capidx * 2 : 256;
    long *ni = realloc(m->idx, nc * sizeof *ni);
    if (!ni) return oom(file, err);
    m->idx = ni;
    m->capidx = nc;
  }
  m->idx[m->nidx++] = i;
  m->fstart[m->nf] = m->nidx;
  return T74_OK;
}

/* Clinger's fast path (issue 12: strtod was 5% of an import of 100,000 faces): a plain
   decimal [+-]digits[.digits] of at most 15 significant digits and at most 22 after the
   point is m / 10^k with m < 10^15 < 2^53 and 10^k = 2^k 5^k, 5^22 < 2^53: both exact
   doubles, so one IEEE division gives the correctly rounded value, the double strtod gives
   (glibc rounds correctly; round to nearest, no excess precision: FLT_EVAL_METHOD 0).
   Anything else (exponents, hex, inf, nan, more digits) is left to strtod: false.
   decimal_at reads such a number at *at and, when it takes it, sets *at past its last
   byte (the caller decides whether the token ends there: fast_decimal, obj_fast). */
static bool decimal_at(const char **at, double *out)
{
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
  static const double pow10[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
  };
  const char *p = *at;
  bool neg = false;
  if (*p == '+' || *p == '-') neg = *p++ == '-';
  /* the digits before the point, then those after it, each run in a loop of its own;
     zeros before the first other digit are not significant (those after the point still
     count as places). m wraps (unsigned) only past 15 significant digits: refused. */
  uint64_t m = 0;
  const char *d0 = p;
  while (*p == '0') p++;
  const char *s = p;
  while ((unsigned)(*p - '0') < 10) m = m * 10 + (uint64_t)(*p++ - '0');
  long digits = p - s, frac = 0;
  bool any = p > d0;
  if (*p == '.') {
    const char *f0 = ++p;
    if (m == 0) while (*p == '0') p++;
    s = p;
    while ((unsigned)(*p - '0') < 10) m = m * 10 + (uint64_t)(*p++ - '0');
    digits += p - s;
    frac = p - f0;
    any = any || frac > 0;
  }
  if (!any || digits > 15 || frac > 22) return false;
  double v = (double)m;                         /* exact: m < 10^15 < 2^53 */
  if (frac) v /= pow10[frac];                   /* one rounding */
  *out = neg ? -v : v;
  *at = p;
  return true;
#else
  (void)at;
  (void)out;
  return false;
#endif
}

/* The token whole as decimal_at reads it: the end it reaches must be the token's. */
static bool fast_decimal(const char *tok, double *out)
{
  const char *p = tok;
  double v;
  if (!decimal_at(&p, &v) || *p) return false;
  *out = v;
  return true;
}

bool import_real(const char *tok, double *out)
{
  if (fast_decimal(tok, out)) return true;
  char *end;
  errno = 0;
  double v = strtod(tok, &end);
  if (end == tok || *end || !isfinite(v)) return false;
  *out = v;
  return true;
}

/* The range in which a file's faces are checked exactly (check_file_face). */
static bool coord_in_range(double v)
{
  double a = fabs(v);
  return a == 0 || (a >= COORD_SMALL && a <= COORD_BIG);
}

static int bad_number(struct import_reader *r, const char *tok, struct t74_error *err)
{
  char b[48];
  return t74_fail_at(err, T74_EINPUT, r->file, r->line, "bad number `%s`",
                     import_show(tok, b, sizeof b));
}

/* Coordinates x y z from tokens t[0..2]; further tokens t[3..n) must be numbers too
   (w, or vertex colours), and are ignored. */
static int read_xyz(struct import_reader *r, char **t, int n, struct mesh *m,
                    struct t74_error *err)
{
  double p[3], dummy;
  char b[48];
  for (int k = 0; k < 3; k++) {
    if (!import_real(t[k], &p[k])) return bad_number(r, t[k], err);
    if (!coord_in_range(p[k]))
      return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                         "coordinate `%s` out of range (0, or magnitude 2^-400 .. 2^400)",
                         import_show(t[k], b, sizeof b));
  }
  for (int k = 3; k < n; k++)
    if (!import_real(t[k], &dummy)) return bad_number(r, t[k], err);
  return add_vertex(m, p, r->line, r->file, err);
}

/* ---- .obj ------------------------------------------------------------------------- */

static const char *const obj_ignored[] = {
  "vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib", "l", "p", "cstype", "deg", "bmat",
  "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con",
  "mg", "bevel", "c_interp", "d_interp", "lod", "shadow_obj", "trace_obj", "ctech",
  "stech", "maplib", "usemap", NULL
};

/* An integer (possibly empty when may_be_empty) ending at '/' or the end of the token. */
static bool obj_part(const char **p, bool may_be_empty, long *out)
{
  /* as import_int on the part (at most 23 bytes) in range +-2000000000, read in place
     in one pass */
  const char *start = *p, *s = start;
  bool neg = false;
  if (*s == '+' || *s == '-') neg = *s++ == '-';
  const char *digits = s;
  long long v = 0;
  for (; *s >= '0' && *s <= '9'; s++)
    if (v <= 1000000000000LL) v = v * 10 + (*s - '0');   /* beyond the range: stop */
  if (*s && *s != '/') return false;                       /* not an integer */
  *p = s;
  if (s - start > 23) return false;
  if (s == start) return may_be_empty;
  if (s == digits || v > 2000000000LL) return false;
  *out = (long)(neg ? -v : v);
  return true;
}

/* One face reference: i, i/t, i//n or i/t/n. Sets the 0-based vertex index. */
static int obj_ref(struct import_reader *r, const char *tok, struct mesh *m,
                   struct t74_error *err)
{
  char b[48];
  const char *p = tok;
  long i = 0, dummy = 0;
  if (!obj_part(&p, false, &i)) goto bad;
  if (*p == '/') {
    p++;
    if (!obj_part(&p, true, &dummy)) goto bad;
    if (*p == '/') {
      p++;
      if (!obj_part(&p, false, &dummy)) goto bad;
    }
  }
  if (*p) goto bad;
  if (i == 0)
    return t74_fail_at(err, T74_EINPUT, r->file, r->line, "vertex index 0 (indices start at 1)");
  if (i < 0) {
    long at = (long)m->nv + i;      /* -1 is the last vertex defined so far */
    if (at < 0)
      return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                         "relative vertex index %ld: only %d vertices defined so far", i,
                         m->nv);
    return add_index(m, at, r->file, err);
  }
  return add_index(m, i - 1, r->file, err);   /* checked against nv at the end */
bad:
  return t74_fail_at(err, T74_EINPUT, r->file, r->line, "bad face vertex `%s`",
                     import_show(tok, b, sizeof b));
}

/* ---- .obj: the common lines in one pass (issue 19) ----------------------------------
   Most lines of a large .obj are `v X Y Z` and `f I J K ...` with single blanks and plain
   numbers. obj_fast reads such a line straight from the buffer, without the tokens and
   NULs import_next makes and without reading its bytes twice. It takes a line only when
   it is sure the general path (import_next, then read_xyz or obj_ref) would accept it
   and give the same values: it ends at LF; it starts with `v ` or `f ` at r->pos; tokens
   are separated by blanks (' ') only; each coordinate is a plain decimal fast_decimal
   takes whole (what the tokenizer would cut out: the accepted bytes, digits, signs and
   `.`, never end a token, and the byte after is a blank or the LF) and in range; each
   face reference is a plain positive index of at most 9 digits (so 1 .. 999,999,999,
   inside obj_part's range), with at most 32 of them. Anything else (comments, tabs, CR,
   other statements, w or colours, slashes, signs in indices, any doubt) returns 0 with
   nothing read: the general path then reads the line and gives its value or its message.
   On 1 the line is read: r->pos is past its LF, r->line / r->nlines count it, and the
   vertex or face is added by the same add_vertex / begin_face / add_index calls (whose
   own refusals, counts and out of memory, are the general path's). Returns 1, 0, or an
   error status (> 1) from those calls. */
enum { OBJ_FAST_REFS = 32 };

/* The run of decimal digits at p read 8 bytes at once, where 8 bytes remain before end
   (a little-endian host): its length, 1 to 7, and its value in *val; -1 where the byte
   loop must read it (no digit, a run of 8 or more, too near the end, another host).
   A byte b is a digit when its high nibble is 3, and b + 6's too (b <= 0x39); a byte of
   0xFA or more carries into the next one, which lies after a non-digit and is not read.
   The digits, first one in the lowest byte, are moved to the top (zeros before them) and
   combined in three steps: pairs, fours, the eight (each lane holds its sum: no carry).
   A face of 100,000 boxes' file: 4 indices of about 6 digits, 9 instructions a digit in
   the loop. */
static int digits8(const char *p, const char *end, uint64_t *val)
{
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  if (end - p < 8) return -1;
  uint64_t w;
  memcpy(&w, p, 8);
  const uint64_t hi = 0xF0F0F0F0F0F0F0F0u, z = 0x3030303030303030u;
  const uint64_t lo7 = 0x7F7F7F7F7F7F7F7Fu;
  uint64_t nd = ((w & hi) ^ z) | (((w + 0x0606060606060606u) & hi) ^ z);  /* 0: a digit */
  uint64_t top = (((nd & lo7) + lo7) | nd) & ~lo7;     /* the high bit of each non-digit */
  if (top == 0) return -1;
  int len = __builtin_ctzll(top) >> 3;
  if (len == 0) return -1;
  int sh = 8 * (8 - len);
  uint64_t x = (w << sh) - (z << sh);
  x = (x * 10 + (x >> 8)) & 0x00FF00FF00FF00FFu;
  x = (x * 100 + (x >> 16)) & 0x0000FFFF0000FFFFu;
  x = (x * 10000 + (x >> 32)) & 0xFFFFFFFFu;
  *val = x;
  return len;
#else
  (void)p;
  (void)end;
  (void)val;
  return -1;
#endif
}

static int obj_fast(struct import_reader *r, struct mesh *m, struct t74_error *err)
{
  const char *p = r->buf + r->pos;
  if ((p[0] != 'v' && p[0] != 'f') || p[1] != ' ') return 0;
  int st;
  if (p[0] == 'v') {
    double c[3];
    p += 1;
    for (int k = 0; k < 3; k++) {
      while (*p == ' ') p++;
      /* the token is the bytes decimal_at takes (digits, signs, `.`: none ends a token)
         when a blank or the LF follows them */
      if (!decimal_at(&p, &c[k]) || (*p != ' ' && *p != '\n') || !coord_in_range(c[k]))
        return 0;
    }
    while (*p == ' ') p++;
    if (*p != '\n') return 0;
    r->pos = (size_t)(p - r->buf) + 1;
    r->line = ++r->nlines;
    return (st = add_vertex(m, c, r->line, r->file, err)) ? st : 1;
  }
  long ref[OBJ_FAST_REFS];
  int n = 0;
  p += 1;
  for (;;) {
    while (*p == ' ') p++;
    if (*p == '\n') break;
    if (n == OBJ_FAST_REFS) return 0;
    const char *d = p;
    uint64_t v = 0;           /* wraps (unsigned) only past 19 digits: refused below */
    int len = digits8(p, r->buf + r->len, &v);
    if (len > 0) p += len;
    else while ((unsigned)(*p - '0') < 10) v = v * 10 + (uint64_t)(*p++ - '0');
    if (p == d || p - d > 9 || v == 0 || (*p != ' ' && *p != '\n')) return 0;
    ref[n++] = (long)v;
  }
  if (n < 3) return 0;
  r->pos = (size_t)(p - r->buf) + 1;
  r->line = ++r->nlines;
  if ((st = begin_face(m, r->line, r->file, err))) return st;
  for (int k = 0; k < n; k++)
    if ((st = add_index(m, ref[k] - 1, r->file, err))) return st;
  return 1;
}

static int read_obj(struct import_reader *r, struct mesh *m, struct t74_error *err)
{
  int st;
  char b[48];
  for (;;) {
    if (r->pos < r->len && (st = obj_fast(r, m, err)) != 0) {
      if (st != 1) return st;
      continue;
    }
    if ((st = import_next(r, err)) != 1) break;
    const char *k = r->tok[0];
    if (strcmp(k, "v") == 0) {
      if (r->ntok < 4 || r->ntok > 8)
        return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                           "`v` needs x y z (and at most 4 more numbers)");
      if ((st = read_xyz(r, r->tok + 1, r->ntok - 1, m, err))) return st;
    } else if (strcmp(k, "f") == 0 || strcmp(k, "fo") == 0) {
      if (r->ntok < 4)
        return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                           "`%s` needs at least 3 vertices, has %d", k, r->ntok - 1);
      if ((st = begin_face(m, r->line, r->file, err))) return st;
      for (int t = 1; t < r->ntok; t++)
        if ((st = obj_ref(r, r->tok[t], m, err))) return st;
    } else {
      bool known = false;
      for (int q = 0; obj_ignored[q]; q++)
        if (strcmp(k, obj_ignored[q]) == 0) known = true;
      if (!known)
        return t74_fail_at(err, T74_EINPUT, r->file, r->line, "unknown statement `%s`",
                           import_show(k, b, sizeof b));
    }
  }
  if (st != 0) return st;
  for (int f = 0; f < m->nf; f++)
    for (size_t q = m->fstart[f]; q < m->fstart[f + 1]; q++)
      if (m->idx[q] >= m->nv)
        return t74_fail_at(err, T74_EINPUT, r->file, m->fline[f],
                           "face %d: vertex index %ld but only %d vertices", f + 1,
                           m->idx[q] + 1, m->nv);
  return T74_OK;
}

/* ---- .off ------------------------------------------------------------------------- */

/* OFF, or its variants with colours / normals / texture coordinates (ST, C, N, 4 are
   not supported as 4D: "4OFF" is refused). Extra per-vertex numbers are ignored. */
static bool off_header(const char *t)
{
  if (strncmp(t, "ST", 2) == 0) t += 2;
  if (*t == 'C') t++;
  if (*t == 'N') t++;
  return strcmp(t, "OFF") == 0;
}

static int read_off(struct import_reader *r, struct mesh *m, struct t74_error *err)
{
  int st;
  char b[48];
  long nv = -1, nf = -1, dummy;
  if ((st = import_next(r, err)) != 1)
    return st ? st : t74_fail_at(err, T74_EINPUT, r->file, r->nlines > 0 ? r->nlines : 1,
                                 "empty file: expected `OFF`");
  if (!off_header(r->tok[0]))
    return t74_fail_at(err, T74_EINPUT, r->file, r->line, "expected `OFF`, not `%s`",
                       import_show(r->tok[0], b, sizeof b));
  int first = 1;                        /* counts may follow OFF on the same line */
  if (r->ntok == 1) {
    if ((st = import_next(r, err)) != 1)
      return st ? st : t74_fail_at(err, T74_EINPUT, r->file, r->nlines,
                                   "missing vertex and face counts");
    first = 0;
  }
  if (r->ntok - first < 2 || r->ntok - first > 3)
    return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                       "expected the counts: vertices faces [edges]");
  for (int k = first; k < r->ntok; k++) {
    long *dst = k == first ? &nv : k == first + 1 ? &nf : &dummy;
    int e = import_int(r->tok[k], 0, k == first + 2 ? 2000000000L : IMPORT_COUNT_MAX, dst);
    if (e == 1) return bad_number(r, r->tok[k], err);
    if (e == 2)
      return t74_fail_at(err, T74_EINPUT, r->file, r->line, "count `%s` out of range 0..%ld",
                         import_show(r->tok[k], b, sizeof b),
                         k == first + 2 ? 2000000000L : IMPORT_COUNT_MAX);
  }
  for (long v = 0; v < nv; v++) {
    if ((st = import_next(r, err)) != 1)
      return st ? st : t74_fail_at(err, T74_EINPUT, r->file, r->nlines,
                                   "file ends after %ld of %ld vertices", v, nv);
    if (r->ntok < 3)
      return t74_fail_at(err, T74_EINPUT, r->file, r->line, "a vertex needs x y z");
    if ((st = read_xyz(r, r->tok, r->ntok, m, err))) return st;
  }
  for (long f = 0; f < nf; f++) {
    if ((st = import_next(r, err)) != 1)
      return st ? st : t74_fail_at(err, T74_EINPUT, r->file, r->nlines,
                                   "file ends after %ld of %ld faces", f, nf);
    long n;
    int e = import_int(r->tok[0], 0, IMPORT_COUNT_MAX, &n);
    if (e) return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                              "bad vertex count `%s`", import_show(r->tok[0], b, sizeof b));
    if (n < 3)
      return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                         "a face needs at least 3 vertices, this one has %ld", n);
    if (r->ntok - 1 < n)
      return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                         "face needs %ld vertex indices, has %d", n, r->ntok - 1);
    if ((st = begin_face(m, r->line, r->file, err))) return st;
    for (long k = 1; k <= n; k++) {
      long i;
      e = import_int(r->tok[k], 0, nv - 1, &i);
      if (e == 1) return bad_number(r, r->tok[k], err);
      if (e == 2)
        return t74_fail_at(err, T74_EINPUT, r->file, r->line,
                           "vertex index `%s` out of range 0..%ld",
                           import_show(r->tok[k], b, sizeof b), nv - 1);
      if ((st = add_index(m, i, r->file, err))) return st;
    }
    double d;
    for (long k = n + 1; k < r->ntok; k++)      /* a colour may follow */
      if (!import_real(r->tok[k], &d)) return bad_number(r, r->tok[k], err);
  }
  if ((st = import_next(r, err)) == 1)
    return t74_fail_at(err, T74_EINPUT, r->file, r->line, "unexpected data after the last face");
  return st;
}

/* ---- onto the grid ------------------------------------------------------------------ */

/* The warnings of one import, gathered and written to stderr a buffer at a time (stderr
   is unbuffered: three writes a warning before; an import of 100,000 boxes warns 66,566
   times). NULL where the options ask quiet. warn_flush writes what is held; build calls
   it before it returns, so the warnings come before any message its caller prints. */
struct warn_out {
  size_t n;
  char buf[8192];
};

static void warn_flush(struct warn_out *wo)
{
  if (!wo || !wo->n) return;
  fwrite(wo->buf, 1, wo->n, stderr);
  wo->n = 0;
}

static void warn(struct scene *s, struct warn_out *wo, int line, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 4, 5)))
#endif
  ;

/* Bytes of a decimal int at o (room for 11 is the caller's), as printf's %d writes it. */
static size_t put_int(char *o, int v)
{
  char t[12];
  size_t n = 0, k = 0;
  unsigned u = v < 0 ? 0u - (unsigned)v : (unsigned)v;
  do { t[n++] = (char)('0' + u % 10); u /= 10; } while (u);
  if (v < 0) o[k++] = '-';
  while (n) o[k++] = t[--n];
  return k;
}

/* "FILE:LINE: warning: " fmt "\n" into o (room bytes) as snprintf would write it, for
   the conversions warn's formats use: %d (int), %s, %%. The bytes written, or 0 when they
   do not fit (or fmt has another conversion: the caller takes printf then). vsnprintf
   was five sixths of warn's cost (100,000 boxes: 156 M instructions of 66,566 warnings). */
static size_t warn_format(char *o, size_t room, const char *file, int line, const char *fmt,
                          va_list ap)
{
  size_t k = 0;
  size_t fl = strlen(file);
  if (fl + 11 + 12 > room) return 0;
  memcpy(o, file, fl);
  k = fl;
  o[k++] = ':';
  k += put_int(o + k, line);
  memcpy(o + k, ": warning: ", 11);
  k += 11;
  size_t fmtl = strlen(fmt);
  if (k + 6 * fmtl + 1 > room) return 0;   /* a conversion of 2 bytes writes 11 at most */
  for (const char *f = fmt; *f; f++) {
    const char *pc = strchr(f, '%');        /* the text up to the next conversion */
    size_t run = pc ? (size_t)(pc - f) : strlen(f);
    memcpy(o + k, f, run);
    k += run;
    if (!pc) break;
    f = pc + 1;
    if (*f == 'd') k += put_int(o + k, va_arg(ap, int));
    else if (*f == '%') o[k++] = '%';
    else if (*f == 's') {
      const char *a = va_arg(ap, const char *);
      size_t al = strlen(a);
      if (k + al + 6 * fmtl + 1 > room) return 0;
      memcpy(o + k, a, al);
      k += al;
    } else return 0;
  }
  o[k++] = '\n';
  return k;
}

/* "FILE:LINE: warning: ...\n" to wo (unless NULL: scene_opts.quiet), counted either way.
   A warning longer than the buffer is written as it is made. */
static void warn(struct scene *s, struct warn_out *wo, int line, const char *fmt, ...)
{
  s->warnings++;
  if (!wo) return;
  for (int pass = 0; pass < 2; pass++) {
    va_list ap;
    va_start(ap, fmt);
    size_t n = warn_format(wo->buf + wo->n, sizeof wo->buf - wo->n, s->file, line, fmt, ap);
    va_end(ap);
    if (n) { wo->n += n; return; }
    warn_flush(wo);                         /* no room: what is held out, and again */
  }
  va_list ap;                               /* longer than the whole buffer */
  fprintf(stderr, "%s:%d: warning: ", s->file, line);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
}

/* Append a face of one ring (n vertex indices) to s; the arrays are copied. */
static int add_face(struct scene *s, int *cap, int id, int line, const int *v, int n,
                    struct t74_error *err)
{
  if (s->nf == *cap) {
    int nc = *cap ? *cap * 2 : 64;
    struct scene_face *nfa = realloc(s->f, (size_t)nc * sizeof *nfa);
    if (!nfa) return oom(s->file, err);
    s->f = nfa;
    *cap = nc;
  }
  struct scene_face *f = &s->f[s->nf];
  memset(f, 0, sizeof *f);
  f->ring_start = scene_pool_ints(s, (size_t)n + 2);   /* ring_start[2], then vidx */
  if (!f->ring_start) return oom(s->file, err);
  f->vidx = f->ring_start + 2;
  f->pooled = true;
  f->id = (uint32_t)id;
  f->line = line;
  f->grey = -1;
  f->object = 0;
  f->nring = 1;
  f->ring_start[0] = 0;
  f->ring_start[1] = n;
  memcpy(f->vidx, v, (size_t)n * sizeof *v);
  s->nf++;
  return T74_OK;
}

static bool same_pos(const struct scene *s, int a, int b)
{
  return s->v[a].x == s->v[b].x && s->v[a].y == s->v[b].y && s->v[a].z == s->v[b].z;
}

/* Defect of a one-ring face given by n indices (a scratch face, nothing kept). */
static int defect(const struct scene *s, int id, int line, int *v, int n)
{
  int rs[2] = { 0, n };
  struct scene_face f = { .id = (uint32_t)id, .line = line, .grey = -1, .nring = 1,
                          .ring_start = rs, .vidx = v };
  return scene_check_face(s, &f, NULL);   /* the verdict: its message is not used */
}

/* A ring of 4 whose vertices 0, 1, 2 span a plane vertex 3 is off: scene_check_face's
   verdict is SCENE_FACE_NONPLANAR when the four positions are distinct (as place_face
   has made sure: ring_repeats), and this finds it without the rest of its work (its
   convex quad test fails on the same plane; the ring has 3 or more distinct positions;
   its normal is the same first triple's, vertex 3 the first off it). At 100,000 boxes
   66,566 of the faces rounded are such quads. The same products as scene.c's: coordinates
   of 16 bits, so each fits 64 bits. */
static bool quad_off_plane(const struct scene *s, const int *v, int n)
{
  if (n != 4) return false;
  const struct scene_vertex *p0 = &s->v[v[0]], *p1 = &s->v[v[1]], *p2 = &s->v[v[2]];
  const struct scene_vertex *p3 = &s->v[v[3]];
  int64_t ax = p1->x - p0->x, ay = p1->y - p0->y, az = p1->z - p0->z;
  int64_t bx = p2->x - p0->x, by = p2->y - p0->y, bz = p2->z - p0->z;
  int64_t nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
  if (!(nx || ny || nz)) return false;
  return nx * (p3->x - p0->x) + ny * (p3->y - p0->y) + nz * (p3->z - p0->z) != 0;
}

/* ---- the face in the file: exact orientation on doubles ------------------------------
   A face whose edges cross in the file (a bow-tie) was never simple: it is refused, not
   blamed on rounding. The test is exact on the file's own numbers: the orientation
   determinant of three points, expanded into six products, each an exact pair
   (product, fma error), summed exactly as a non-overlapping expansion (Shewchuk's
   Grow-Expansion); its sign is the sign of its largest component. Exact while every
   coordinate is 0 or of magnitude 2^-400 .. 2^400 (read_xyz refuses others). */


static void two_sum(double a, double b, double *x, double *y)
{
  double s = a + b, bv = s - a, av = s - bv;
  *x = s;
  *y = (a - av) + (b - bv);
}

/* e[0..*n) grows by b, exactly; components stay in increasing magnitude, zeros dropped */
static void grow(double *e, int *n, double b)
{
  double q = b;
  int k = 0;
  for (int i = 0; i < *n; i++) {
    double x, y;
    two_sum(q, e[i], &x, &y);
    q = x;
    if (y != 0) e[k++] = y;
  }
  if (q != 0) e[k++] = q;
  *n = k;
}

static void add_product(double *e, int *n, double a, double b)
{
  double x = a * b;
  double y = fma(a, b, -x);           /* exact: no overflow or underflow in range */
  grow(e, n, y);
  grow(e, n, x);
}

/* Within the range a file's coordinates are read in (0, or magnitude 2^-400 .. 2^400),
   with a little room for the turn (render/turn.h) to grow them. */
static bool filter_coord(double x)
{
  double a = fabs(x);
  return a == 0 || (a >= COORD_SMALL && a <= 2 * COORD_BIG);
}

/* sign of (b - a) x (c - a), exactly.
   First a floating-point filter (Shewchuk, "Adaptive precision floating-point arithmetic
   and fast robust geometric predicates", 1997, orient2d's first stage): with
   l = fl(fl(a0 - c0) * fl(b1 - c1)), r = fl(fl(a1 - c1) * fl(b0 - c0)) and det = fl(l - r),
   the exact (a - c) x (b - c), which is (b - a) x (c - a), has det's sign whenever
   |det| > (3 + 16 eps) eps (|l| + |r|), eps = 2^-53; his proof asks only that nothing
   underflows or overflows. It is taken only when the six coordinates are 0 or of
   magnitude 2^-400 .. 2^401: then each difference is 0 exactly when its two terms are
   equal, otherwise of magnitude 2^-452 or more (both terms are multiples of 2^-452) and
   at most 2^402, so every nonzero product lies in 2^-904 .. 2^804, normal and finite.
   In that range the expansion below is exact too (each product's error term is a normal
   double: no underflow in fma), so both decide the same sign. Undecided (|det| within
   the bound), or outside the range: the expansion, as before. A split quad's bow-tie
   test at 100,000 boxes: 42,670 calls, about 750 instructions each by the expansion. */
static int orient_d(const double a[2], const double b[2], const double c[2])
{
  if (filter_coord(a[0]) && filter_coord(a[1]) && filter_coord(b[0]) &&
      filter_coord(b[1]) && filter_coord(c[0]) && filter_coord(c[1])) {
    double l = (a[0] - c[0]) * (b[1] - c[1]), r = (a[1] - c[1]) * (b[0] - c[0]);
    double det = l - r, bound = (3.0 + 16.0 * 0x1p-53) * 0x1p-53 * (fabs(l) + fabs(r));
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  double e[32];
  int n = 0;
  add_product(e, &n, b[0], c[1]);
  add_product(e, &n, -b[0], a[1]);
  add_product(e, &n, -a[0], c[1]);
  add_product(e, &n, -b[1], c[0]);
  add_product(e, &n, b[1], a[0]);
  add_product(e, &n, a[1], c[0]);
  if (n == 0) return 0;
  return e[n - 1] > 0 ? 1 : -1;
}

/* The axis a face is seen along to split it: the largest component of its normal (ties:
   z before y before x). Returns 0, 1 or 2; the polygon is then read in the plane of the
   other two axes, (u, v) = ((a+1)%3, (a+2)%3), a right-handed pair. */
static int dominant_axis(const double n[3])
{
  double ax = fabs(n[0]), ay = fabs(n[1]), az = fabs(n[2]);
  if (az >= ax && az >= ay) return 2;
  return ay >= ax ? 1 : 0;
}

/* Pairs of edges of a closed polygon whose bounding boxes meet, found by a sweep over u
   (edge k runs from point k to point k+1): test(ctx, n, i, j), i < j, is asked for each
   such pair until it holds. Returns 1 (the pair in *ea < *eb), 0 when it never holds,
   -1 when out of memory. The points are given as doubles (exact for the grid's
   integers), the test reads its own exact copy through ctx. */
struct ebox { double u0, u1, v0, v1; int k; };

static int ebox_cmp(const void *a, const void *b)
{
  const struct ebox *x = a, *y = b;
  if (x->u0 != y->u0) return x->u0 < y->u0 ? -1 : 1;
  return (x->k > y->k) - (x->k < y->k);
}

typedef bool (*pair_fn)(const void *ctx, int n, int i, int j);

/* The larger and smaller of two finite doubles (as fmax and fmin, to the sign of a zero,
   which no compare here sees: -0 and +0 compare equal; no library call: a file face's
   quad test made four, the sweep four an edge). */
static double dmax(double a, double b) { return a > b ? a : b; }
static double dmin(double a, double b) { return a < b ? a : b; }


#define SMALL_FACE 32    /* faces of up to this many vertices: scratch on the stack */

static int sweep(const double (*p)[2], int n, pair_fn test, const void *ctx, int *ea, int *eb)
{
  struct ebox small[SMALL_FACE];
  struct ebox *e = n <= SMALL_FACE ? small : malloc((size_t)n * sizeof *e);
  if (!e) return -1;
  for (int k = 0; k < n; k++) {
    const double *a = p[k], *b = p[(k + 1) % n];
    e[k] = (struct ebox){ dmin(a[0], b[0]), dmax(a[0], b[0]), dmin(a[1], b[1]),
                          dmax(a[1], b[1]), k };
  }
  if (n > 16) {
    qsort(e, (size_t)n, sizeof *e, ebox_cmp);
  } else {                /* a few: by insertion, the comparison inlined (same order) */
    for (int i = 1; i < n; i++) {
      struct ebox t = e[i];
      int j = i;
      for (; j > 0 && ebox_cmp(&e[j - 1], &t) > 0; j--) e[j] = e[j - 1];
      e[j] = t;
    }
  }
  int found = 0;
  for (int i = 0; i < n && !found; i++)
    for (int j = i + 1; j < n && e[j].u0 <= e[i].u1; j++) {
      if (e[j].v0 > e[i].v1 || e[j].v1 < e[i].v0) continue;
      int a = e[i].k < e[j].k ? e[i].k : e[j].k, b = e[i].k < e[j].k ? e[j].k : e[i].k;
      if (test(ctx, n, a, b)) { *ea = a; *eb = b; found = 1; break; }
    }
  if (e != small) free(e);
  return found;
}

/* Non-adjacent edges i < j of the file's polygon cross properly (each strictly through
   the other). */
static bool file_cross_pair(const void *ctx, int n, int i, int j)
{
  const double (*p)[2] = ctx;
  if (j == i + 1 || (i == 0 && j == n - 1)) return false;       /* adjacent */
  const double *a = p[i], *b = p[(i + 1) % n], *c = p[j], *d = p[(j + 1) % n];
  int o1 = orient_d(a, b, c), o2 = orient_d(a, b, d);
  if (o1 == 0 || o2 == 0 || o1 == o2) return false;
  int o3 = orient_d(c, d, a), o4 = orient_d(c, d, b);
  return o3 != 0 && o4 != 0 && o3 != o4;
}

/* The boxes of segments a-b and c-d meet (closed): a proper crossing needs it. */
static bool boxes_meet(const double *a, const double *b, const double *c, const double *d)
{
  return dmax(a[0], b[0]) >= dmin(c[0], d[0]) && dmax(c[0], d[0]) >= dmin(a[0], b[0]) &&
         dmax(a[1], b[1]) >= dmin(c[1], d[1]) && dmax(c[1], d[1]) >= dmin(a[1], b[1]);
}

static int file_crossing(const double (*p)[2], int n, int *ea, int *eb)
{
  return sweep(p, n, file_cross_pair, p, ea, eb);
}

/* Refuse mesh face k when two of its edges cross properly in the file, seen along the
   dominant axis of its (floating-point) Newell normal; when that normal is exactly zero
   (a bow-tie with lobes of equal area) seen along each axis. Touching edges and
   collinear folds are left to the checks after rounding. */
static int check_file_face(const struct scene *s, const struct mesh *m, int k,
                           struct t74_error *err)
{
  size_t b = m->fstart[k], e = m->fstart[k + 1];
  int n = 0;
  double nn[3] = { 0, 0, 0 };
  for (size_t q = b; q < e; q++) {
    const double *p = m->xyz + 3 * m->idx[q], *r = m->xyz + 3 * m->idx[q + 1 < e ? q + 1 : b];
    nn[0] += (p[1] - r[1]) * (p[2] + r[2]);
    nn[1] += (p[2] - r[2]) * (p[0] + r[0]);
    nn[2] += (p[0] - r[0]) * (p[1] + r[1]);
  }
  if (e - b < 4) return T74_OK;                 /* a triangle cannot cross itself */
  int ax = dominant_axis(nn), u = (ax + 1) % 3, v = (ax + 2) % 3;
  double sp[SMALL_FACE][2];
  long ssrc[SMALL_FACE];
  bool small = e - b <= SMALL_FACE;
  double (*p)[2] = small ? sp : malloc((e - b) * sizeof *p);
  long *src = small ? ssrc : malloc((e - b) * sizeof *src);
  if (!p || !src) {
    if (!small) { free(p); free(src); }
    return oom(s->file, err);
  }
  for (size_t q = b; q < e; q++) {
    const double *c = m->xyz + 3 * m->idx[q];
    if (n > 0 && p[n - 1][0] == c[u] && p[n - 1][1] == c[v]) continue;
    p[n][0] = c[u];
    p[n][1] = c[v];
    src[n++] = (long)(q - b);
  }
  while (n > 1 && p[n - 1][0] == p[0][0] && p[n - 1][1] == p[0][1]) n--;
  int ea, eb, st = T74_OK;
  /* a quadrilateral: its only non-adjacent pairs are edges 0, 2 and 1, 3, and at most one
     of them crosses properly (of the three ways to pair four points, one at most), so
     the sweep would find the pair tested here */
  int crossed = 0;
  if (n == 4) {             /* (as the sweep: only pairs whose boxes meet are tested) */
    if (boxes_meet(p[0], p[1], p[2], p[3]) && file_cross_pair(p, 4, 0, 2)) {
      ea = 0; eb = 2; crossed = 1;
    } else if (boxes_meet(p[1], p[2], p[3], p[0]) && file_cross_pair(p, 4, 1, 3)) {
      ea = 1; eb = 3; crossed = 1;
    }
  } else if (n > 4) {
    crossed = file_crossing((const double (*)[2])p, n, &ea, &eb);
  }
  for (int a = 0; crossed == 0 && n >= 4 && nn[0] == 0 && nn[1] == 0 && nn[2] == 0 && a < 2;
       a++) {
    u = (a + 1) % 3;                  /* no normal (balanced lobes): every axis is tried */
    v = (a + 2) % 3;
    for (int q = 0; q < n; q++) {
      const double *c = m->xyz + 3 * m->idx[b + (size_t)src[q]];
      p[q][0] = c[u];
      p[q][1] = c[v];
    }
    crossed = file_crossing((const double (*)[2])p, n, &ea, &eb);
  }
  if (crossed < 0) st = oom(s->file, err);
  else if (crossed)
    st = t74_fail_at(err, T74_EINPUT, s->file, m->fline[k],
                     "face %d is not simple in the file: its edges %ld-%ld and %ld-%ld "
                     "(vertex positions in the face) cross", k + 1, src[ea] + 1,
                     src[(ea + 1) % n] + 1, src[eb] + 1, src[(eb + 1) % n] + 1);
  if (!small) {
    free(p);
    free(src);
  }
  return st;
}

/* ---- splitting on the grid: exact ear clipping -----------------------------------------
   A face that is not planar once rounded is split into triangles that cover exactly the
   region it covers seen along the dominant axis of its exact (integer) Newell normal, so
   no notch is filled and no part is lost; each triangle is planar by construction. The
   split is a function of the face alone, not of how it is written: the ring is turned
   counter-clockwise in that view and started at its smallest vertex (x, then y, then z),
   so reversing or rotating the ring in the file gives the same triangles. Ears are taken
   in ring order from there: an ear is a vertex whose turn is strictly convex and whose
   triangle (closed) holds no other remaining vertex. A straight vertex (collinear with
   its neighbours) is never an ear itself but is kept as a corner of the triangles beside
   it; a last triangle of zero area (all remaining vertices on one line) covers nothing
   and is left out. The projected polygon must be simple (exact, 64-bit): one that is not
   (rounding folded it, or the file's outline touches itself, as a keyhole's bridge does)
   is split in the file's own coordinates instead (file_split, below). */

#define SPLIT_IN_FILE (-1)   /* ear_split: not simple on the grid; file_split takes it */

static int dominant_axis_i(const int64_t n[3])
{
  int64_t ax = n[0] < 0 ? -n[0] : n[0], ay = n[1] < 0 ? -n[1] : n[1];
  int64_t az = n[2] < 0 ? -n[2] : n[2];
  if (az >= ax && az >= ay) return 2;
  return ay >= ax ? 1 : 0;
}

/* Edges i < j of the rounded polygon meet where they must not: non-adjacent ones at any
   point, adjacent ones anywhere but their common vertex (folding back along each other). */
static bool bad_pair_2d(const void *ctx, int n, int i, int j)
{
  const struct pl_pt *p = ctx;
  struct pl_pt a = p[i], b = p[(i + 1) % n], c = p[j], d = p[(j + 1) % n];
  if (j == i + 1) return pl_fold(b, a, d);           /* b is their common end */
  if (i == 0 && j == n - 1) return pl_fold(a, b, c);  /* a (= d) is */
  return pl_meet(a, b, c, d);
}

/* The closed boxes of segments a-b and c-d meet. */
static bool pl_boxes_meet(struct pl_pt a, struct pl_pt b, struct pl_pt c, struct pl_pt d)
{
  return (a.u > b.u ? a.u : b.u) >= (c.u < d.u ? c.u : d.u) &&
         (c.u > d.u ? c.u : d.u) >= (a.u < b.u ? a.u : b.u) &&
         (a.v > b.v ? a.v : b.v) >= (c.v < d.v ? c.v : d.v) &&
         (c.v > d.v ? c.v : d.v) >= (a.v < b.v ? a.v : b.v);
}

/* 1 when simple, 0 when not (*ea, *eb an offending pair), -1 when out of memory. */
static int simple_2d(const struct pl_pt *p, int n, int *ea, int *eb)
{
  /* A quadrilateral (a split quad: 66,566 of 100,000 boxes' faces) without the sweep:
     its four adjacent pairs share a point, so their boxes always meet and the sweep
     tests each; the two others it tests where their boxes meet, as here. A pair the
     test holds for has a point in common, so its boxes meet: whichever pair is found
     (the caller reads only the verdict), the verdict is the sweep's. */
  if (n == 4) {
    static const int pair[6][2] = { { 0, 1 }, { 1, 2 }, { 2, 3 }, { 0, 3 }, { 0, 2 }, { 1, 3 } };
    for (int q = 0; q < 6; q++) {
      int i = pair[q][0], j = pair[q][1];
      if (q >= 4 && !pl_boxes_meet(p[i], p[i + 1], p[j], p[(j + 1) % 4])) continue;
      if (bad_pair_2d(p, 4, i, j)) { *ea = i; *eb = j; return 0; }
    }
    return 1;
  }
  double sd[SMALL_FACE][2];
  double (*d)[2] = n <= SMALL_FACE ? sd : malloc((size_t)n * sizeof *d);
  if (!d) return -1;
  for (int k = 0; k < n; k++) { d[k][0] = (double)p[k].u; d[k][1] = (double)p[k].v; }
  int r = sweep((const double (*)[2])d, n, bad_pair_2d, p, ea, eb);
  if (d != sd) free(d);
  return r < 0 ? -1 : !r;
}

static bool in_tri(struct pl_pt a, struct pl_pt b, struct pl_pt c, struct pl_pt p)
{
  return pl_orient(a, b, p) >= 0 && pl_orient(b, c, p) >= 0 && pl_orient(c, a, p) >= 0;
}

static int vcmp(const struct scene_vertex *a, const struct scene_vertex *b)
{
  if (a->x != b->x) return a->x < b->x ? -1 : 1;
  if (a->y != b->y) return a->y < b->y ? -1 : 1;
  if (a->z != b->z) return a->z < b->z ? -1 : 1;
  return 0;
}

/* Split the rounded ring v[0..n) (scene vertex indices, no two consecutive at one
   position) into triangles added as faces of `id`. */
static int ear_split(struct scene *s, int *cap, int id, int line, const int *v, int n,
                     struct warn_out *wo, struct t74_error *err)
{
  int64_t nn[3] = { 0, 0, 0 };     /* exact Newell normal: |terms| < 2^30 (|coords| <= 2^14) */
  for (int k = 0; k < n; k++) {
    const struct scene_vertex *p = &s->v[v[k]], *q = &s->v[v[(k + 1) % n]];
    nn[0] += (int64_t)(p->y - q->y) * (p->z + q->z);
    nn[1] += (int64_t)(p->z - q->z) * (p->x + q->x);
    nn[2] += (int64_t)(p->x - q->x) * (p->y + q->y);
  }
  int ax = dominant_axis_i(nn);
  if (nn[ax] == 0) {
    warn(s, wo, line, "face %d degenerate after rounding (no area); dropped", id);
    return T74_OK;
  }
  int u = (ax + 1) % 3, w = (ax + 2) % 3;
  int nf0 = s->nf;                 /* faces before this one's triangles (taken back when
                                      the split goes to the file's coordinates) */
  /* scratch on the stack for a small ring (a split quad: 66,566 of 100,000 boxes' faces,
     four allocations each before) */
  struct pl_pt sp[SMALL_FACE];
  int sring[SMALL_FACE], snx[SMALL_FACE], spv[SMALL_FACE];
  bool small = n <= SMALL_FACE;
  struct pl_pt *p = small ? sp : malloc((size_t)n * sizeof *p);
  int *ring = small ? sring : malloc((size_t)n * sizeof *ring);
  int *nx = small ? snx : malloc((size_t)n * sizeof *nx);
  int *pv = small ? spv : malloc((size_t)n * sizeof *pv);
  int st = T74_OK;
  if (!p || !ring || !nx || !pv) { st = oom(s->file, err); goto done; }
  /* counter-clockwise seen along -axis (nn[ax] > 0), from the smallest vertex */
  int first = 0;
  for (int k = 1; k < n; k++) if (vcmp(&s->v[v[k]], &s->v[v[first]]) < 0) first = k;
  for (int k = 0; k < n; k++) {
    int at = nn[ax] > 0 ? (first + k) % n : (first - k + n) % n;
    ring[k] = v[at];
    const struct scene_vertex *sv = &s->v[v[at]];
    int32_t c[3] = { sv->x, sv->y, sv->z };
    p[k].u = c[u];
    p[k].v = c[w];
  }
  int ea, eb;
  int simple = simple_2d(p, n, &ea, &eb);
  if (simple < 0) { st = oom(s->file, err); goto done; }
  if (!simple) { st = SPLIT_IN_FILE; goto done; }   /* folded: split in the file instead */
  for (int k = 0; k < n; k++) { nx[k] = (k + 1) % n; pv[k] = (k + n - 1) % n; }
  int left = n, at = 0, tried = 0, made = 0;
  while (left > 3) {
    int a = pv[at], c = nx[at];
    bool ear = pl_orient(p[a], p[at], p[c]) > 0;
    for (int q = nx[c]; ear && q != a; q = nx[q])
      if (in_tri(p[a], p[at], p[c], p[q])) ear = false;
    if (!ear) {
      at = c;
      if (++tried > left) {           /* no ear: impossible for a simple polygon */
        st = SPLIT_IN_FILE;
        goto done;
      }
      continue;
    }
    int tri[3] = { ring[a], ring[at], ring[c] };
    if ((st = add_face(s, cap, id, line, tri, 3, err))) goto done;
    made++;
    nx[a] = c;
    pv[c] = a;
    left--;
    tried = 0;
    at = c;
  }
  {
    int a = pv[at], c = nx[at];
    if (pl_orient(p[a], p[at], p[c]) > 0) {
      int tri[3] = { ring[a], ring[at], ring[c] };
      if ((st = add_face(s, cap, id, line, tri, 3, err))) goto done;
      made++;
    }
  }
  warn(s, wo, line, "face %d not planar after rounding; split into %d triangles", id, made);
done:
  if (st == SPLIT_IN_FILE) s->nf = nf0;   /* (their arrays stay in the scene's pool) */
  if (!small) {
    free(p);
    free(ring);
    free(nx);
    free(pv);
  }
  return st;
}

/* ---- faces the grid cannot take whole: split in the file's own coordinates -----------
   A face whose outline, rounded onto the grid, is not simple (rounding folded it: a sliver
   seen from afar, vertices finer than the grid), or whose outline touches itself in the
   file (a keyhole: a ring with a hole joined by a bridge walked there and back, as
   LightWave writes a face with a hole), cannot be one scene face, and ear clipping on the
   grid needs a simple polygon. It is cut into triangles on the file's own numbers instead
   (after the turn, as check_file_face sees them: along the dominant axis of the face's
   Newell normal, every orientation exact, orient_d), where the outline is simple or only
   touches itself (no proper crossing: check_file_face refused those); then each triangle is
   rounded onto the grid, where three points are always planar, and a triangle that
   rounding collapsed is left out. So such a face is drawn, never refused for the grid.
   The clipping is O'Rourke's with the guards a touching outline needs (as
   mapper_split_face's): an ear's diagonal must leave both its ends into the face (in-cone)
   and cross no edge, and no vertex other than copies of its corners may lie in its
   triangle. */

static bool same_d(const double *a, const double *b) { return a[0] == b[0] && a[1] == b[1]; }

/* p strictly inside segment a-b (a != b); the comparisons are exact on doubles */
static bool on_open_seg_d(const double *a, const double *b, const double *p)
{
  if (orient_d(a, b, p) != 0 || same_d(p, a) || same_d(p, b)) return false;
  return p[0] >= fmin(a[0], b[0]) && p[0] <= fmax(a[0], b[0]) &&
         p[1] >= fmin(a[1], b[1]) && p[1] <= fmax(a[1], b[1]);
}

/* The cut m-w (m != w) meets edge a-b elsewhere than at its own ends. */
static bool cut_hits_d(const double *m, const double *w, const double *a, const double *b)
{
  if (same_d(a, b)) return on_open_seg_d(m, w, a);
  if (on_open_seg_d(m, w, a) || on_open_seg_d(m, w, b) || on_open_seg_d(a, b, m) ||
      on_open_seg_d(a, b, w))
    return true;
  int d1 = orient_d(a, b, m), d2 = orient_d(a, b, w), d3 = orient_d(m, w, a), d4 = orient_d(m, w, b);
  return d1 * d2 < 0 && d3 * d4 < 0;
}

static bool in_tri_d(const double *a, const double *b, const double *c, const double *p)
{
  return orient_d(a, b, p) >= 0 && orient_d(b, c, p) >= 0 && orient_d(c, a, p) >= 0;
}

/* The diagonal a-p leaves vertex a (ap before it, an after it, counter-clockwise) into the
   polygon's inside: O'Rourke's in-cone test, strict. */
static bool in_cone_d(const double *ap, const double *a, const double *an, const double *p)
{
  if (orient_d(ap, a, an) >= 0) return orient_d(a, p, ap) > 0 && orient_d(p, a, an) > 0;
  return !(orient_d(a, p, an) >= 0 && orient_d(p, a, ap) >= 0);
}

/* The sign of the polygon's area, exactly (sum of the edges' cross products as one
   expansion, as orient_d); -2 when out of memory. */
static int area_sign_d(const double (*p)[2], int n)
{
  double *e = malloc((4 * (size_t)n + 4) * sizeof *e);
  if (!e) return -2;
  int len = 0;
  for (int i = 0; i < n; i++) {
    const double *a = p[i], *b = p[(i + 1) % n];
    add_product(e, &len, a[0], b[1]);
    add_product(e, &len, -b[0], a[1]);
  }
  int sg = len == 0 ? 0 : e[len - 1] > 0 ? 1 : -1;
  free(e);
  return sg;
}

/* Triangle (a, b, c) of scene vertex indices, rounded, as a face of `id` unless rounding
   collapsed it. 1 when added, 0 when left out, or a status (< 0 never). */
static int add_rounded_tri(struct scene *s, int *cap, int id, int line, int a, int b, int c,
                           struct t74_error *err)
{
  if (same_pos(s, a, b) || same_pos(s, b, c) || same_pos(s, c, a)) return 0;
  int tri[3] = { a, b, c };
  int d = defect(s, id, line, tri, 3);
  if (d < 0) return -oom(s->file, err);
  if (d != SCENE_FACE_OK) return 0;                 /* collinear once rounded */
  int st = add_face(s, cap, id, line, tri, 3, err);
  return st ? -st : 1;
}

static bool same_file_pos(const struct mesh *m, long a, long b)
{
  const double *p = m->xyz + 3 * a, *q = m->xyz + 3 * b;
  return a == b || (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]);
}

/* Split mesh face k, its ring ring[0..n) (vertex indices, no two consecutive at one file
   position), into triangles on the file's numbers, each rounded onto the grid. */
static int file_split(struct scene *s, int *cap, const struct mesh *m, int k, const int *ring,
                      int n, struct warn_out *wo, struct t74_error *err)
{
  int id = k + 1, line = m->fline[k];
  bool touches = false;           /* the file's ring itself passes a position twice */
  for (int i = 0; i < n && !touches && n <= 4096; i++)
    for (int j = i + 1; j < n && !touches; j++)
      touches = same_file_pos(m, ring[i], ring[j]);
  double nn[3] = { 0, 0, 0 };
  for (int i = 0; i < n; i++) {
    const double *a = m->xyz + 3 * ring[i], *b = m->xyz + 3 * ring[(i + 1) % n];
    nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
    nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
    nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  int ax = dominant_axis(nn), u = (ax + 1) % 3, v = (ax + 2) % 3;
  double (*p)[2] = malloc((size_t)n * sizeof *p);
  int *left = malloc((size_t)n * sizeof *left);
  int st = T74_OK, made = 0;
  if (!p || !left) { st = oom(s->file, err); goto done; }
  for (int i = 0; i < n; i++) {
    p[i][0] = m->xyz[3 * ring[i] + u];
    p[i][1] = m->xyz[3 * ring[i] + v];
  }
  int o = area_sign_d((const double (*)[2])p, n);
  if (o == -2) { st = oom(s->file, err); goto done; }
  if (o == 0) {
    warn(s, wo, line, "face %d has no area in the file; dropped", id);
    goto done;
  }
  for (int i = 0; i < n; i++) left[i] = o > 0 ? i : n - 1 - i;   /* counter-clockwise */
  int nl = n;
  while (nl > 3) {
    int ear = -1;
    for (int i = 0; i < nl && ear < 0; i++) {
      const double *a = p[left[(i + nl - 1) % nl]], *b = p[left[i]], *c = p[left[(i + 1) % nl]];
      if (orient_d(a, b, c) <= 0) continue;
      const double *ap = p[left[(i + nl - 2) % nl]], *cn = p[left[(i + 2) % nl]];
      if (!in_cone_d(ap, a, b, c) || !in_cone_d(b, c, cn, a)) continue;
      bool empty = true;
      for (int j = 0; j < nl && empty; j++)
        empty = !cut_hits_d(a, c, p[left[j]], p[left[(j + 1) % nl]]);
      for (int j = 0; j < nl && empty; j++) {
        const double *q = p[left[j]];
        if (same_d(q, a) || same_d(q, b) || same_d(q, c)) continue;
        empty = !in_tri_d(a, b, c, q);
      }
      if (empty) ear = i;
    }
    if (ear < 0) {
      st = t74_fail_at(err, T74_EINPUT, s->file, line,
                       "face %d is not simple in the file: its outline runs over itself "
                       "and cannot be cut into triangles", id);
      s->nf -= made;                  /* none of its triangles stays */
      goto done;
    }
    int r = add_rounded_tri(s, cap, id, line, ring[left[(ear + nl - 1) % nl]], ring[left[ear]],
                            ring[left[(ear + 1) % nl]], err);
    if (r < 0) { st = -r; goto done; }
    made += r;
    for (int j = ear; j + 1 < nl; j++) left[j] = left[j + 1];
    nl--;
  }
  if (orient_d(p[left[0]], p[left[1]], p[left[2]]) != 0) {
    int r = add_rounded_tri(s, cap, id, line, ring[left[0]], ring[left[1]], ring[left[2]], err);
    if (r < 0) { st = -r; goto done; }
    made += r;
  }
  if (made == 0) warn(s, wo, line, "face %d degenerate after rounding; dropped", id);
  else if (touches)
    warn(s, wo, line, "face %d passes one point twice in the file (a bridge to a hole, "
         "say); split into %d triangles", id, made);
  else
    warn(s, wo, line, "face %d not simple once rounded onto the grid; split into %d "
         "triangles in the file's coordinates", id, made);
done:
  free(p);
  free(left);
  return st;
}

/* Mesh face k's ring as in the file, into out: consecutive repeats of one position
   dropped (and the closing one), and an outline traced several times over (`f 1 2 3 4 1 2
   3 4 ...`) taken once; *times says how often it was traced. Returns its length. */
static int file_ring(const struct mesh *m, int k, int *out, int *times)
{
  int n = 0;
  for (size_t q = m->fstart[k]; q < m->fstart[k + 1]; q++) {
    long v = m->idx[q];
    if (n > 0 && same_file_pos(m, out[n - 1], v)) continue;
    out[n++] = (int)v;
  }
  while (n > 1 && same_file_pos(m, out[n - 1], out[0])) n--;
  *times = 1;
  for (int per = 1; per <= n / 2; per++) {
    if (n % per) continue;
    int i = per;
    while (i < n && same_file_pos(m, out[i], out[i - per])) i++;
    if (i == n) { *times = n / per; return per; }
  }
  return n;
}

static int pos_cmp(const void *a, const void *b)
{
  const int32_t *x = a, *y = b;
  for (int c = 0; c < 3; c++)
    if (x[c] != y[c]) return x[c] < y[c] ? -1 : 1;
  return 0;
}

/* Two vertices of the ring v[0..n) at one grid position (-1 when out of memory): by pairs
   for a small ring, by sorting the positions for a large one. */
static int ring_repeats(const struct scene *s, const int *v, int n)
{
  if (n <= SMALL_FACE) {
    for (int i = 0; i < n; i++)
      for (int j = i + 1; j < n; j++)
        if (same_pos(s, v[i], v[j])) return 1;
    return 0;
  }
  int32_t (*c)[3] = malloc((size_t)n * sizeof *c);
  if (!c) return -1;
  for (int i = 0; i < n; i++) {
    c[i][0] = s->v[v[i]].x;
    c[i][1] = s->v[v[i]].y;
    c[i][2] = s->v[v[i]].z;
  }
  qsort(c, (size_t)n, sizeof *c, pos_cmp);
  int r = 0;
  for (int i = 1; i < n && !r; i++) r = pos_cmp(c[i - 1], c[i]) == 0;
  free(c);
  return r;
}

/* Turn mesh face k into scene faces: kept, split into triangles (on the grid, or in the
   file's coordinates when the grid cannot take its outline), or dropped (with a warning);
   refused only when its edges cross in the file. fbuf and buf: room for its ring each. */
static int place_face(struct scene *s, int *cap, const struct mesh *m, int k, int *fbuf,
                      int *buf, struct warn_out *wo, struct t74_error *err)
{
  int id = k + 1, line = m->fline[k], n = 0, times;
  int st = check_file_face(s, m, k, err);
  if (st) return st;
  int nfile = file_ring(m, k, fbuf, &times);
  if (times > 1)
    warn(s, wo, line, "face %d traces its outline %d times; taken once", id, times);
  for (int q = 0; q < nfile; q++) {
    int v = fbuf[q];
    if (n > 0 && same_pos(s, buf[n - 1], v)) continue;   /* rounded onto one point */
    buf[n++] = v;
  }
  while (n > 1 && same_pos(s, buf[n - 1], buf[0])) n--;  /* closing repeat */
  if (n < 3) {
    warn(s, wo, line, "face %d degenerate after rounding; dropped", id);
    return T74_OK;
  }
  /* a ring through one grid position twice (a keyhole's bridge, or rounding pinched it)
     is no scene face: straight to the file's triangles */
  int rep = ring_repeats(s, buf, n);
  if (rep < 0) return oom(s->file, err);
  if (rep) return file_split(s, cap, m, k, fbuf, nfile, wo, err);
  int d = quad_off_plane(s, buf, n) ? SCENE_FACE_NONPLANAR : defect(s, id, line, buf, n);
  if (d < 0) return oom(s->file, err);
  if (d == SCENE_FACE_OK) return add_face(s, cap, id, line, buf, n, err);
  if (d == SCENE_FACE_DEGENERATE) {
    warn(s, wo, line, "face %d degenerate after rounding; dropped", id);
    return T74_OK;
  }
  st = ear_split(s, cap, id, line, buf, n, wo, err);
  if (st != SPLIT_IN_FILE) return st;
  return file_split(s, cap, m, k, fbuf, nfile, wo, err);
}

double import_round(double x)
{
  /* below 2^52 in magnitude, t = trunc(x) by the conversion (exact: |x| < 2^63), and
     x - t, the fraction, is exact (its bits are x's own below the point); so the
     comparisons with 1/2 decide as lround does, halves away from zero. Larger, infinite
     or NaN: lround itself. */
  if (fabs(x) < 0x1p52) {
    double t = (double)(long long)x, d = x - t;
    if (d >= 0.5) return t + 1;
    if (d <= -0.5) return t - 1;
    return t;
  }
  return (double)lround(x);
}

static int32_t clamp_coord(double v)
{
  if (!(v > SCENE_COORD_MIN)) return SCENE_COORD_MIN;   /* also catches NaN */
  if (v > SCENE_COORD_MAX) return SCENE_COORD_MAX;
  return (int32_t)v;
}

/* The window: the bounding box [lo, hi] projected from the eye onto z = 0, grown to 4:3
   around its centre, plus 5% of its size on every side, rounded outwards. */
static void fit_window(struct scene *s, const int32_t lo[3], const int32_t hi[3])
{
  double ex = s->view[0], ey = s->view[1], ez = s->view[2];
  if (ez >= 0 || lo[2] <= ez) {     /* camera invalid: scene_check_camera reports it */
    s->window[0] = -1; s->window[1] = -1; s->window[2] = 1; s->window[3] = 1;
    return;
  }
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (int c = 0; c < 8; c++) {
    double x = (c & 1) ? hi[0] : lo[0], y = (c & 2) ? hi[1] : lo[1];
    double z = (c & 4) ? hi[2] : lo[2];
    double t = -ez / (z - ez);      /* z > ez: 0 < t */
    double px = ex + (x - ex) * t, py = ey + (y - ey) * t;
    if (px < x0) x0 = px;
    if (px > x1) x1 = px;
    if (py < y0) y0 = py;
    if (py > y1) y1 = py;
  }
  double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2, w = x1 - x0, h = y1 - y0;
  if (w * 3 < h * 4) w = h * 4 / 3; else h = w * 3 / 4;
  if (w < 4) { w = 4; h = 3; }
  w *= 1.1;
  h *= 1.1;
  s->window[0] = clamp_coord(floor(cx - w / 2));
  s->window[1] = clamp_coord(floor(cy - h / 2));
  s->window[2] = clamp_coord(ceil(cx + w / 2));
  s->window[3] = clamp_coord(ceil(cy + h / 2));
  if (s->window[0] >= s->window[2]) {
    if (s->window[2] < SCENE_COORD_MAX) s->window[2] = s->window[0] + 1;
    else s->window[0] = s->window[2] - 1;
  }
  if (s->window[1] >= s->window[3]) {
    if (s->window[3] < SCENE_COORD_MAX) s->window[3] = s->window[1] + 1;
    else s->window[1] = s->window[3] - 1;
  }
}

static int build(const struct mesh *m, const char *path, const struct scene_opts *opts,
                 int nlines, struct scene **out, struct t74_error *err)
{
  if (m->nv == 0)
    return t74_fail_at(err, T74_EINPUT, path, nlines > 0 ? nlines : 1, "no vertices");
  if (m->nf == 0)
    return t74_fail_at(err, T74_EINPUT, path, nlines > 0 ? nlines : 1, "no faces");
  double lo[3], hi[3];
  for (int a = 0; a < 3; a++) lo[a] = hi[a] = m->xyz[a];
  for (int v = 1; v < m->nv; v++)
    for (int a = 0; a < 3; a++) {
      double c = m->xyz[3 * v + a];
      if (c < lo[a]) lo[a] = c;
      if (c > hi[a]) hi[a] = c;
    }
  double ext = 0;
  for (int a = 0; a < 3; a++) {
    double e = hi[a] - lo[a];      /* may overflow to inf for huge inputs */
    if (!isfinite(e)) return t74_fail(err, T74_EINPUT, "%s: coordinates too large", path);
    if (e > ext) ext = e;
  }
  if (ext <= 0)
    return t74_fail(err, T74_EINPUT, "%s: the model has no extent (one point)", path);
  double scale = IMPORT_EXTENT / ext;
  if (!isfinite(scale))
    return t74_fail(err, T74_EINPUT, "%s: the model is too small to map", path);

  struct scene *s = calloc(1, sizeof *s);
  if (!s) return oom(path, err);
  int st = T74_OK, cap = 0;
  int *buf = NULL;
  struct warn_out wbuf;                     /* the warnings (none: quiet) */
  wbuf.n = 0;
  struct warn_out *wo = opts && opts->quiet ? NULL : &wbuf;
  s->file = malloc(strlen(path) + 1);
  s->v = calloc((size_t)m->nv, sizeof *s->v);
  if (!s->file || !s->v) { st = oom(path, err); goto fail; }
  strcpy(s->file, path);
  s->nv = m->nv;
  /* |x - centre| <= ext/2, so |x'| <= IMPORT_EXTENT/2 and 0 <= z' <= IMPORT_EXTENT */
  double cx = (lo[0] + hi[0]) / 2, cy = (lo[1] + hi[1]) / 2;
  int32_t blo[3] = { SCENE_COORD_MAX, SCENE_COORD_MAX, SCENE_COORD_MAX };
  int32_t bhi[3] = { SCENE_COORD_MIN, SCENE_COORD_MIN, SCENE_COORD_MIN };
  for (int v = 0; v < m->nv; v++) {
    struct scene_vertex *sv = &s->v[v];
    sv->id = (uint32_t)(v + 1);
    sv->line = m->vline[v];
    sv->x = clamp_coord(import_round((m->xyz[3 * v] - cx) * scale));
    sv->y = clamp_coord(import_round((m->xyz[3 * v + 1] - cy) * scale));
    sv->z = clamp_coord(import_round((hi[2] - m->xyz[3 * v + 2]) * scale));
    int32_t c[3] = { sv->x, sv->y, sv->z };
    for (int a = 0; a < 3; a++) {
      if (c[a] < blo[a]) blo[a] = c[a];
      if (c[a] > bhi[a]) bhi[a] = c[a];
    }
  }
  s->has_view = s->has_window = true;
  if (opts && opts->has_view) memcpy(s->view, opts->view, sizeof s->view);
  else { s->view[0] = 0; s->view[1] = 0; s->view[2] = -(IMPORT_EXTENT * 5 / 2); }
  /* imports carry no intensities: shade them by a light from above left, in front */
  s->has_light = true;
  s->nlight = 1;
  s->light[0] = (struct scene_light){ false, { -1, 2, -3 }, 0 };
  if (opts && opts->has_window) memcpy(s->window, opts->window, sizeof s->window);
  else fit_window(s, blo, bhi);

  size_t longest = 0;
  for (int k = 0; k < m->nf; k++)
    if (m->fstart[k + 1] - m->fstart[k] > longest) longest = m->fstart[k + 1] - m->fstart[k];
  buf = malloc(2 * (longest + 1) * sizeof *buf);
  if (!buf) { st = oom(path, err); goto fail; }
  for (int k = 0; k < m->nf; k++)
    if ((st = place_face(s, &cap, m, k, buf, buf + longest + 1, wo, err))) goto fail;
  warn_flush(wo);
  free(buf);
  buf = NULL;
  /* the faces' table to its size: it doubled as the faces came (100,000 boxes: 166,848
     faces in room for 262,144, 5.3 MB unused for the whole run) */
  if (s->nf > 0 && cap > s->nf) {     /* (realloc to 0 bytes may free) */
    struct scene_face *fit = realloc(s->f, (size_t)s->nf * sizeof *fit);
    if (fit) s->f = fit;                    /* else the larger table serves as well */
  }
  if ((st = scene_check_camera(s, 0, 0, err))) goto fail;
  *out = s;
  return T74_OK;
fail:
  warn_flush(wo);                           /* the faces' warnings before the error */
  free(buf);
  scene_free(s);
  return st;
}

int import_load(const char *path, const char *kind, const struct scene_opts *opts,
                struct scene **out, struct t74_error *err)
{
  struct import_reader r;
  struct mesh m;
  memset(&m, 0, sizeof m);
  *out = NULL;
  int st = import_open(&r, path, err);
  if (st) return st;
  st = strcmp(kind, "off") == 0 ? read_off(&r, &m, err) : read_obj(&r, &m, err);
  if (st == T74_OK) turn_import(m.xyz, m.nv, opts);      /* the view: render/turn.h */
  if (st == T74_OK) st = build(&m, path, opts, r.nlines, out, err);
  import_close(&r);
  mesh_free(&m);
  return st;
}
