/*
** memrender.c — a scene rendered in memory (memrender.h), for the scene fuzz targets and
** tests/test_import.c: the library's own stages, no command line, no output files.
*/
#include "tests/ref/memrender.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "patterns/halftone.h"
#include "render/render.h"

char *mr_temp_file(const uint8_t *data, size_t size, const char *suffix)
{
  const char *tmp = getenv("TMPDIR");
  if (!tmp || !*tmp) tmp = "/tmp";
  size_t n = strlen(tmp) + strlen(suffix) + 40;
  char *path = malloc(n);
  if (!path) return NULL;
  snprintf(path, n, "%s/tube74-mr-XXXXXX", tmp);
  if (!mkdtemp(path)) { free(path); return NULL; }
  size_t dl = strlen(path);
  snprintf(path + dl, n - dl, "/scene.%s", suffix);
  FILE *f = fopen(path, "wb");
  if (!f || (size && fwrite(data, 1, size, f) != size)) {
    if (f) fclose(f);
    mr_temp_remove(path);
    return NULL;
  }
  if (fclose(f) != 0) { mr_temp_remove(path); return NULL; }
  return path;
}

void mr_temp_remove(char *path)
{
  if (!path) return;
  unlink(path);
  char *slash = strrchr(path, '/');
  if (slash) { *slash = '\0'; rmdir(path); }
  free(path);
}

struct grab { uint16_t *ids; int W; const struct render *r; };

static int on_point(void *ctx, int i, int j, int face)
{
  struct grab *g = ctx;
  g->ids[(size_t)j * (size_t)g->W + (size_t)i] = face >= 0 ? g->r->map.f[face].id : 0;
  return T74_OK;
}

int mr_render_ids(const struct scene *s, int cell, uint16_t *ids, struct t74_error *err)
{
  struct render r;
  struct render_opts o = { MR_CORE_WORDS, 0, PRIO_AUTO, NULL, 0, NULL };
  int W = pat_grid_w(cell), H = pat_grid_h(cell);
  memset(ids, 0, (size_t)W * (size_t)H * sizeof *ids);
  int st = render_prepare(&r, s, &o, err);
  if (st == T74_OK) {
    struct vis_grid g = { W, H, { s->window[0], s->window[1], s->window[2], s->window[3] } };
    struct grab gr = { ids, W, &r };
    st = render_scan(&r, &g, on_point, &gr, err);
  }
  render_free(&r);
  return st;
}

static void reverse_ints(int *a, int n)
{
  for (int i = 0, j = n - 1; i < j; i++, j--) { int t = a[i]; a[i] = a[j]; a[j] = t; }
}

void mr_reverse(struct scene *s)
{
  for (int i = 0, j = s->nf - 1; i < j; i++, j--) {
    struct scene_face t = s->f[i]; s->f[i] = s->f[j]; s->f[j] = t;
  }
  for (int k = 0; k < s->nf; k++) {
    struct scene_face *f = &s->f[k];
    for (int r = 0; r < f->nring; r++)
      reverse_ints(f->vidx + f->ring_start[r], f->ring_start[r + 1] - f->ring_start[r]);
  }
  for (int o = 0; o < s->nobj; o++)          /* objects hold face indices */
    for (int q = 0; q < s->obj[o].nface; q++) s->obj[o].face[q] = s->nf - 1 - s->obj[o].face[q];
}

long mr_diff(const uint16_t *a, const uint16_t *b, size_t n)
{
  long d = 0;
  for (size_t k = 0; k < n; k++) d += a[k] != b[k];
  return d;
}

int mr_check(const uint8_t *data, size_t size, const char *kind, int cell, int *rendered,
             char *why, size_t whylen)
{
  if (rendered) *rendered = 0;
  char *path = mr_temp_file(data, size, kind);
  if (!path) { snprintf(why, whylen, "cannot write a temporary file"); return 1; }
  struct scene_opts o = { .input = kind };
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  int bad = 0;
  int st = scene_load(path, &o, &s, &err);
  if (st != T74_OK) {
    if ((st != T74_EINPUT && st != T74_EIO) || s != NULL ||
        strncmp(err.msg, path, strlen(path)) != 0) {
      snprintf(why, whylen, "refused with status %d and message \"%s\"", st, err.msg);
      bad = 1;
    }
    mr_temp_remove(path);
    return bad;
  }
  size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
  uint16_t *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
  if (!a || !b) {
    snprintf(why, whylen, "out of memory");
    bad = 1;
  } else {
    struct t74_error e1 = { 0 }, e2 = { 0 };
    int s1 = mr_render_ids(s, cell, a, &e1);
    mr_reverse(s);
    int s2 = mr_render_ids(s, cell, b, &e2);
    if (s1 != s2) {
      snprintf(why, whylen, "status %d (%s), reversed %d (%s)", s1, e1.msg, s2, e2.msg);
      bad = 1;
    } else if (s1 != T74_OK && s1 != T74_EINPUT && s1 != T74_ECORE) {
      snprintf(why, whylen, "render status %d: %s", s1, e1.msg);
      bad = 1;
    } else if (s1 == T74_OK) {
      long d = mr_diff(a, b, n);
      if (rendered) *rendered = 1;
      if (d) {
        snprintf(why, whylen, "%ld points differ when faces and rings are reversed", d);
        bad = 1;
      }
    }
  }
  free(a);
  free(b);
  scene_free(s);
  mr_temp_remove(path);
  return bad;
}

int mr_load_bytes(const uint8_t *data, size_t size, const char *kind, struct scene **out)
{
  *out = NULL;
  char *path = mr_temp_file(data, size, kind);
  if (!path) return T74_EIO;
  struct scene_opts o = { .input = kind };
  struct t74_error err = { 0 };
  int st = scene_load(path, &o, out, &err);
  mr_temp_remove(path);
  return st;
}

int mr_same_picture(const struct scene *a, const struct scene *b, int cell)
{
  size_t n = (size_t)pat_grid_w(cell) * (size_t)pat_grid_h(cell);
  uint16_t *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
  int same = 0;
  if (x && y) {
    struct t74_error e1 = { 0 }, e2 = { 0 };
    int s1 = mr_render_ids(a, cell, x, &e1), s2 = mr_render_ids(b, cell, y, &e2);
    same = s1 == s2 && (s1 != T74_OK || mr_diff(x, y, n) == 0);
  }
  free(x);
  free(y);
  return same;
}

static int is_blank(uint8_t c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }

uint8_t *mr_obj_reverse_rings(const uint8_t *data, size_t size, size_t *outn)
{
  uint8_t *out = malloc(size + 1);
  if (!out) return NULL;
  size_t o = 0, p = 0;
  while (p < size) {
    size_t e = p;
    while (e < size && data[e] != '\n' && data[e] != '\r') e++;
    size_t q = p;
    while (q < e && is_blank(data[q])) q++;
    size_t kw = q;
    while (q < e && !is_blank(data[q]) && data[q] != '#') q++;
    bool face = (q - kw == 1 && data[kw] == 'f') ||
                (q - kw == 2 && data[kw] == 'f' && data[kw + 1] == 'o');
    size_t hash = p;
    while (hash < e && data[hash] != '#') hash++;
    bool has_nul = memchr(data + p, 0, e - p) != NULL;
    if (!face || has_nul || hash <= q) {
      memcpy(out + o, data + p, e - p);        /* not a face line: as it is */
      o += e - p;
    } else {
      memcpy(out + o, data + kw, q - kw);      /* the keyword, then the refs reversed */
      o += q - kw;
      size_t end = hash;
      for (;;) {
        while (end > q && is_blank(data[end - 1])) end--;
        if (end <= q) break;
        size_t start = end;
        while (start > q && !is_blank(data[start - 1])) start--;
        out[o++] = ' ';
        memcpy(out + o, data + start, end - start);
        o += end - start;
        end = start;
      }
    }
    if (e < size) {                            /* the line end as it was */
      size_t le = data[e] == '\r' && e + 1 < size && data[e + 1] == '\n' ? 2 : 1;
      memcpy(out + o, data + e, le);
      o += le;
      e += le;
    }
    p = e;
  }
  *outn = o;
  return out;
}

/* The tokens of one line (before any `#`), as offsets into data: at most max of them. */
static int line_tokens(const uint8_t *data, size_t p, size_t e, size_t *ts, size_t *te, int max)
{
  int n = 0;
  size_t q = p;
  while (q < e && data[q] != '#') {
    while (q < e && is_blank(data[q])) q++;
    if (q >= e || data[q] == '#') break;
    size_t b = q;
    while (q < e && !is_blank(data[q]) && data[q] != '#') q++;
    if (n < max) { ts[n] = b; te[n] = q; }
    n++;
  }
  return n;
}

/* A token as a whole decimal integer 0..2^31-1, or -1. */
static long token_count(const uint8_t *data, size_t b, size_t e)
{
  long v = 0;
  if (b < e && data[b] == '+') b++;
  if (b >= e || e - b > 9) return -1;
  for (; b < e; b++) {
    if (data[b] < '0' || data[b] > '9') return -1;
    v = v * 10 + (data[b] - '0');
  }
  return v;
}

uint8_t *mr_off_reverse_rings(const uint8_t *data, size_t size, size_t *outn)
{
  uint8_t *out = malloc(size + 1);
  enum { MAXT = 64 };
  size_t *ts = malloc(MAXT * sizeof *ts), *te = malloc(MAXT * sizeof *te);
  if (!out || !ts || !te) { free(out); free(ts); free(te); return NULL; }
  size_t o = 0, p = 0;
  int state = 0;                 /* 0 header, 1 counts, 2 vertices, 3 faces, 4 copy */
  long nv = 0;
  while (p < size) {
    size_t e = p;
    while (e < size && data[e] != '\n' && data[e] != '\r') e++;
    int nt = memchr(data + p, 0, e - p) ? 0 : line_tokens(data, p, e, ts, te, MAXT);
    bool rewritten = false;
    if (nt > 0 && state < 4) {
      if (state == 0) {
        state = 1;
        if (nt > 1) { nv = token_count(data, ts[1], te[1]); state = nv < 0 ? 4 : nv ? 2 : 3; }
      } else if (state == 1) {
        nv = token_count(data, ts[0], te[0]);
        state = nv < 0 ? 4 : nv ? 2 : 3;
      } else if (state == 2) {
        if (--nv == 0) state = 3;
      } else {
        long n = token_count(data, ts[0], te[0]);
        if (n < 0 || nt > MAXT || n > nt - 1) state = 4;
        else {
          for (int k = 0; k < nt; k++) {
            int at = k >= 1 && k <= n ? (int)(n + 1 - k) : k;   /* 1..n reversed */
            if (k) out[o++] = ' ';
            memcpy(out + o, data + ts[at], te[at] - ts[at]);
            o += te[at] - ts[at];
          }
          rewritten = true;
        }
      }
    }
    if (!rewritten) {
      memcpy(out + o, data + p, e - p);
      o += e - p;
    }
    if (e < size) {
      size_t le = data[e] == '\r' && e + 1 < size && data[e + 1] == '\n' ? 2 : 1;
      memcpy(out + o, data + e, le);
      o += le;
      e += le;
    }
    p = e;
  }
  free(ts);
  free(te);
  *outn = o;
  return out;
}
