/*
** cmd_teach.c — `tube74 teach SCENE [-o DIR] [--line J] [render's options]`: the paper's
** figures, drawn step by step from one run of the 1974 program, as one self-contained HTML
** page (README "teach"; the page itself: cli/teach_page.html).
** Sources: paper 003 §2.2 (the Mapper, YSORT, XSORT, crossing types of Fig. 4), §3.1 and
** Fig. 5, 6 (cuts through concave vertices, eq. (3), the tables PBS, IPL, LWS, UPS), §3.2
** and Fig. 8 (D-blocks), §4 and Fig. 9 (the Priority Matrix filled during the scan, the
** halftone cells, the picture displayed while it is computed).
**
** This file contains code to watch the ordinary job (cli/pipeline.h) as it draws the scene
** and to write down what it did. The page is one trace of one program: the dots, the
** teaching dump and every number on the page come from the same run that `tube74 render`
** makes with the same options (the scan cutting each face when it reaches it, so piece
** numbers are the ones `render --dump tables` prints). Nothing here decides anything:
**   the teaching dump (the text of --dump tables), whole       -> YSORT, XSORT, the cuts and
**                                                                 their Fig. 6 tables, the
**                                                                 pieces, PRIORITY and
**                                                                 INTERSECT lines, the matrix
**   at the first point of every grid row (job_hooks.watch):
**     where the dump had got to (its length then)              -> which row each line of it
**                                                                 belongs to: the matrix as
**                                                                 it filled (Fig. 9)
**     the active pieces' D-blocks (struct vis_item)            -> xb, xe, dxb, dxe, y-max
**     and the visible stretches (struct vis_span)                 (Fig. 8) on that line
**   every point's visible face                                 -> the picture by rows
**   after the scan: the Mapper's faces, every piece's vertices -> the figures' geometry
**   the job's dots (its sink) and its halftone cells           -> the halftone and the tube
** Exact values are written as decimals in world units for drawing only. The data is one
** JSON object placed between the page's two fixed parts; the page needs no network.
**
** The file is DIR/NAME.html (NAME: the scene's file name without its extension), written
** atomically (display/outfile.h); DIR is made when it does not exist (one level).
*/
#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "cli/commands.h"
#include "cli/pipeline.h"
#include "cli/teach_page.h"
#include "display/outfile.h"
#include "display/sink.h"
#include "display/tek.h"
#include "emu/status.h"
#include "patterns/halftone.h"
#include "render/geom.h"
#include "render/render.h"

/* A growing string (the JSON of the rows and of the geometry). */
struct buf { char *s; size_t n, cap; bool oom; };

static void bput(struct buf *b, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;

static void bput(struct buf *b, const char *fmt, ...)
{
  va_list ap;
  for (;;) {
    size_t room = b->cap - b->n;
    va_start(ap, fmt);
    int k = b->cap ? vsnprintf(b->s + b->n, room, fmt, ap) : -1;
    va_end(ap);
    if (k >= 0 && (size_t)k < room) { b->n += (size_t)k; return; }
    if (b->oom) return;
    size_t nc = b->cap ? b->cap * 2 : 4096;
    while (k >= 0 && nc - b->n <= (size_t)k) nc *= 2;
    char *ns = realloc(b->s, nc);
    if (!ns) { b->oom = true; return; }
    b->s = ns;
    b->cap = nc;
  }
}

struct teach {
  FILE *tables;                 /* the teaching dump, as the job writes it */
  int W, H;                     /* the job's grid (known from its result, after the run) */
  int SW, SH;                   /* the largest grid (3x3 cells): room while the job runs */
  int *face;                    /* SW x SH: visible face (index in the Mapper's table), -1 none */
  char **row;                   /* SH: each grid row's JSON, by j */
  struct buf geom;              /* "faces" and "pieces", written after the scan */
  long end_at;                  /* the dump's length after the scan */
  bool watched_end;
  uint8_t *lit;                 /* 400 x 300 dots, y up */
  int status;                   /* the first failure (out of memory) */
};

static double gx(wide num, wide den) { return (double)num / (double)den / (double)GRID_ONE; }

/* Row j's state at its first point: where the dump is, the D-blocks, the visible stretches. */
static void snap_row(struct teach *t, const struct render *r, int j)
{
  const struct vis *v = &r->vis;
  /* the scan's line step in yn units: y = yn / yd with yd = 2H and yn stepping by
     2 GRID_ONE (YT - YB) (vis_scan) */
  const int32_t *w = r->scene->window;
  double step = 2.0 * (double)GRID_ONE * ((double)w[3] - (double)w[1]);
  struct buf b = { 0 };
  bput(&b, "{\"at\":%ld,\"n\":%d,\"d\":[", ftell(t->tables), r->seg.n);
  int first = 1;
  for (int k = 0; k < v->nact; k++) {
    const struct vis_item *it = &v->act[k];
    if (!it->on) continue;
    /* dxb, dxe as the D-block holds them (in units of xb's and xe's denominators); on
       the line that opened it (no step yet) the sides' slopes times the scan's step, which
       the next line sets (the slopes are per the exact denominators, hdl and hdr with
       --arith hitac) */
    bool fresh = it->dyn == 0, h10 = v->arith == GEOM_HITAC;
    double dxl = fresh ? (double)it->sl * step / (double)(h10 ? it->hdl : it->xl.den)
                       : (double)it->dxl / (double)it->xl.den;
    double dxr = fresh ? (double)it->sr * step / (double)(h10 ? it->hdr : it->xr.den)
                       : (double)it->dxr / (double)it->xr.den;
    bput(&b, "%s[%d,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d]", first ? "" : ",", it->piece + 1,
         gx(it->xl.num, it->xl.den), gx(it->xr.num, it->xr.den), dxl / (double)GRID_ONE,
         dxr / (double)GRID_ONE, gx(it->ymax.Y, it->ymax.W), it->kl, it->kr, fresh ? 1 : 0);
    first = 0;
  }
  bput(&b, "],\"s\":[");
  for (int k = 0; k < v->nspan; k++)
    bput(&b, "%s[%.6g,%.6g,%d,%d]", k ? "," : "", gx(v->span[k].x0.num, v->span[k].x0.den),
         gx(v->span[k].x1.num, v->span[k].x1.den), v->span[k].piece + 1, v->span[k].face);
  bput(&b, "]}");
  if (b.oom) { free(b.s); t->status = T74_EIO; return; }
  free(t->row[j]);
  t->row[j] = b.s;
}

/* After the scan: the Mapper's faces (rings, vertex numbers, grey) and every piece. */
static void snap_end(struct teach *t, const struct render *r)
{
  struct buf *b = &t->geom;
  fflush(t->tables);
  t->end_at = ftell(t->tables);
  const int32_t *w = r->scene->window;
  bput(b, "\"window\":[%d,%d,%d,%d],\n\"faces\":[", (int)w[0], (int)w[1], (int)w[2], (int)w[3]);
  for (int f = 0; f < r->map.nface; f++) {
    const struct mface *m = &r->map.f[f];
    bput(b, "%s\n{\"id\":%u,\"grey\":%d,\"rings\":[", f ? "," : "", (unsigned)m->id, m->grey);
    for (int g = 0; g < m->nring; g++) {
      bput(b, "%s[", g ? "," : "");
      for (int k = m->ring_start[g]; k < m->ring_start[g + 1]; k++)
        bput(b, "%s[%.6g,%.6g,%u]", k > m->ring_start[g] ? "," : "",
             (double)m->pt[k].x / GRID_ONE, (double)m->pt[k].y / GRID_ONE, (unsigned)m->vid[k]);
      bput(b, "]");
    }
    bput(b, "]}");
  }
  bput(b, "],\n\"pieces\":[");
  for (int k = 0; k < r->seg.n; k++) {
    const struct piece *p = &r->seg.p[k];
    bput(b, "%s\n{\"n\":%d,\"face\":%d,\"alive\":%d,\"parent\":%d,\"v\":[", k ? "," : "", k + 1,
         p->face, p->alive ? 1 : 0, p->parent + 1);
    for (int i = 0; i < p->n; i++)
      bput(b, "%s[%.6g,%.6g]", i ? "," : "", gx(piece_v(p, i).X, piece_v(p, i).W),
           gx(piece_v(p, i).Y, piece_v(p, i).W));
    bput(b, "]}");
  }
  bput(b, "],\n");
  if (b->oom) t->status = T74_EIO;
  t->watched_end = true;
}

static int watch(void *ctx, const struct render *r, int i, int j, int face)
{
  struct teach *t = ctx;
  if (i < 0) { snap_end(t, r); return t->status; }
  if (i >= t->SW || j < 0 || j >= t->SH) return T74_OK;
  if (i == 0) snap_row(t, r, j);
  t->face[(size_t)j * (size_t)t->SW + (size_t)i] = face;
  return t->status;
}

/* The job's dots (display/sink.h). */
static int keep_dot(void *ctx, int x, int y)
{
  struct teach *t = ctx;
  if (x >= 0 && x < TUBE_W && y >= 0 && y < TUBE_H) t->lit[(size_t)y * TUBE_W + (size_t)x] = 1;
  return T74_OK;
}

static int keep_end(void *ctx, struct t74_error *err) { (void)ctx; (void)err; return T74_OK; }
static void keep_abort(void *ctx) { (void)ctx; }

/* ---- the page ---------------------------------------------------------------------- */

/* s[0..n) as a JSON string: printable ASCII kept, except what could end the script
   element or be read as markup; everything else escaped. */
static void json_str(struct outfile *of, const char *s, size_t n)
{
  outfile_write(of, "\"", 1);
  for (size_t k = 0; k < n; k++) {
    unsigned char c = (unsigned char)s[k];
    if (c == '"' || c == '\\') outfile_printf(of, "\\%c", c);
    else if (c == '\n') outfile_write(of, "\\n", 2);
    else if (c < 0x20 || c >= 0x7F || c == '<' || c == '>' || c == '&') outfile_printf(of, "\\u%04x", c);
    else outfile_write(of, s + k, 1);
  }
  outfile_write(of, "\"", 1);
}

static int write_page(const char *path, const char *name, const struct teach *t,
                      const struct job_result *res, const char *tables, size_t tlen, int line,
                      struct t74_error *err)
{
  struct outfile *of;
  int st = outfile_open(&of, path, err);
  if (st != T74_OK) return st;
  outfile_printf(of, "%s", teach_page_head);
  outfile_printf(of, "<script>\nconst T = {\n\"scene\":");
  json_str(of, name, strlen(name));
  outfile_printf(of, ",\n\"W\":%d,\"H\":%d,\"cell\":%d,\"line\":%d,\"lineGiven\":%s,\"one\":%d,"
                 "\"seconds\":%.4g,\"lit\":%d,\"pattern\":", t->W, t->H, res->cell, line < 0 ? t->H / 2 : line,
                 line < 0 ? "false" : "true", (int)GRID_ONE, res->hitac10_seconds, res->points_lit);
  json_str(of, pat_cell_name(res->pat), strlen(pat_cell_name(res->pat)));
  /* the halftone cells of every level, and each grey's level (patterns/halftone.h) */
  outfile_printf(of, ",\n\"cells\":[");
  for (int l = 0; l <= res->cell * res->cell; l++) {
    uint16_t m;
    pat_cell_dots(res->pat, l, &m);
    outfile_printf(of, "%s%u", l ? "," : "", (unsigned)m);
  }
  outfile_printf(of, "],\n\"levelOf\":[");
  for (int g = 0; g < 256; g++) outfile_printf(of, "%s%d", g ? "," : "", pat_level(res->cell, g));
  outfile_printf(of, "],\n%.*s", (int)t->geom.n, t->geom.s);
  outfile_printf(of, "\"end\":%ld,\n\"rows\":[", t->end_at);
  for (int j = 0; j < t->H; j++)
    outfile_printf(of, "%s\n%s", j ? "," : "", t->row[j] ? t->row[j] : "{\"at\":0,\"n\":0,\"d\":[],\"s\":[]}");
  /* the picture by grid rows: runs [i0, i1, face] */
  outfile_printf(of, "],\n\"grid\":[");
  for (int j = 0; j < t->H; j++) {
    outfile_printf(of, "%s\n[", j ? "," : "");
    int i = 0, first = 1;
    while (i < t->W) {
      int f = t->face[(size_t)j * (size_t)t->W + (size_t)i], i1 = i;
      while (i1 + 1 < t->W && t->face[(size_t)j * (size_t)t->W + (size_t)i1 + 1] == f) i1++;
      if (f >= 0) { outfile_printf(of, "%s[%d,%d,%d]", first ? "" : ",", i, i1, f); first = 0; }
      i = i1 + 1;
    }
    outfile_printf(of, "]");
  }
  /* the tube's dots by rows (y up): runs [x0, x1] */
  outfile_printf(of, "],\n\"tube\":[");
  for (int y = 0; y < TUBE_H; y++) {
    outfile_printf(of, "%s[", y ? "," : "");
    int x = 0, first = 1;
    while (x < TUBE_W) {
      if (!t->lit[(size_t)y * TUBE_W + (size_t)x]) { x++; continue; }
      int x1 = x;
      while (x1 + 1 < TUBE_W && t->lit[(size_t)y * TUBE_W + (size_t)x1 + 1]) x1++;
      outfile_printf(of, "%s[%d,%d]", first ? "" : ",", x, x1);
      first = 0;
      x = x1 + 1;
    }
    outfile_printf(of, "]");
  }
  /* the teaching dump, byte for byte what --dump tables writes */
  outfile_printf(of, "],\n\"tables\":");
  json_str(of, tables, tlen);
  outfile_printf(of, "\n};\n</script>\n%s", teach_page_tail);
  return outfile_commit(of, err);
}

/* ---- the command ------------------------------------------------------------------- */

void teach_usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 teach SCENE [-o DIR] [--line J] [render's options]\n"
    "  -o DIR                 where to write NAME.html (default: the current folder;\n"
    "                         made if missing)\n"
    "  --line J               the grid row whose D-blocks are shown first (0 = top;\n"
    "                         default: the middle row, or the row nearest it that\n"
    "                         meets a piece)\n"
    "the page steps through the figures with Next/Back or the arrow keys; NAME.html#step=N\n"
    "opens step N, NAME.html#all shows every step on one page\n");
}

struct teach_args { const char *dir; long line; };

static int teach_opt(void *ctx, int argc, char **argv, int *k, struct t74_error *err)
{
  struct teach_args *a = ctx;
  const char *o = argv[*k];
  if (strcmp(o, "-o") && strcmp(o, "--line")) return 0;
  if (*k + 1 >= argc) { t74_fail(err, T74_EINPUT, "tube74: missing value after: %s", o); return -1; }
  const char *v = argv[++*k];
  if (!strcmp(o, "-o")) { a->dir = v; return 1; }
  char *e;
  errno = 0;
  a->line = strtol(v, &e, 10);
  if (errno || *e || e == v || a->line < 0 || a->line > 1000) {
    t74_fail(err, T74_EINPUT, "tube74: --line takes a grid row 0..1000: %s", v);
    return -1;
  }
  return 1;
}

/* The whole of f (rewound), NUL-terminated; NULL when out of memory. */
static char *read_all(FILE *f, size_t *n)
{
  fflush(f);
  rewind(f);
  size_t cap = 1 << 16, len = 0;
  char *s = malloc(cap);
  while (s) {
    len += fread(s + len, 1, cap - len - 1, f);
    if (len < cap - 1) break;
    char *ns = realloc(s, cap * 2);
    if (!ns) { free(s); return NULL; }
    s = ns;
    cap *= 2;
  }
  if (s) s[len] = 0;
  *n = len;
  return s;
}

int cmd_teach(int argc, char **argv, struct t74_error *err)
{
  struct teach_args a = { ".", -1 };
  struct job j;
  int st = job_parse(argc, argv, 2, &j, teach_opt, &a, err);
  j.need_1974 = true;                    /* the page shows the 1974 program's steps */
  if (st == T74_OK && (j.ndump || j.stats || j.frames > 1))
    st = t74_fail(err, T74_EINPUT, "tube74 teach: -o names the folder; --dump, --stats and "
                  "--frames belong to render");
  if (st == T74_OK) {                    /* a Tek stream has no tables to show */
    uint8_t head[8];
    size_t got = 0;
    FILE *f = fopen(j.scene, "rb");
    if (f) { got = fread(head, 1, sizeof head, f); fclose(f); }
    if ((j.sopts.input && !strcmp(j.sopts.input, "tek")) ||
        (!j.sopts.input && got && tek_sniff(head, got)))
      st = t74_fail(err, T74_EINPUT, "%s: a Tektronix stream: teach needs a scene (.s74, "
                    ".obj, .off)", j.scene);
  }
  if (st != T74_OK) return st;

  struct teach t;
  memset(&t, 0, sizeof t);
  /* the job's grid (--cell or the scene's halftone) is known only inside it: the points
     are kept on the largest grid's stride while it runs */
  t.SW = pat_grid_w(PAT_CELL_MIN);
  t.SH = pat_grid_h(PAT_CELL_MIN);
  t.lit = calloc((size_t)TUBE_W * TUBE_H, 1);
  t.face = malloc((size_t)t.SW * (size_t)t.SH * sizeof *t.face);
  t.row = calloc((size_t)t.SH, sizeof *t.row);
  t.tables = tmpfile();
  if (!t.lit || !t.face || !t.row || !t.tables)
    st = t74_fail(err, T74_EIO, "out of host memory (or no temporary file for the tables)");

  /* the one run: the picture, the dump and the states the page shows */
  struct job_hooks h;
  memset(&h, 0, sizeof h);
  h.extra = (struct sink){ &t, keep_dot, keep_end, keep_abort };
  h.tables = t.tables;
  h.watch = watch;
  h.watch_ctx = &t;
  struct job_result res;
  memset(&res, 0, sizeof res);
  if (st == T74_OK) {
    for (size_t k = 0; k < (size_t)t.SW * (size_t)t.SH; k++) t.face[k] = -1;
    st = job_run(&j, &h, &res, err);
    if (st != T74_OK && !err->msg[0]) t74_fail(err, st, "tube74 teach: out of host memory");
  }
  if (st == T74_OK && !t.watched_end)
    st = t74_fail(err, T74_EIO, "tube74 teach: the 1974 program was not run");
  char *tables = NULL;
  size_t tlen = 0;
  if (st == T74_OK && !(tables = read_all(t.tables, &tlen)))
    st = t74_fail(err, T74_EIO, "out of host memory");
  if (st == T74_OK) {
    /* the points were kept on the largest grid's stride: close it up to the job's */
    t.W = res.W;
    t.H = res.H;
    for (int jj = 0; jj < t.H; jj++)
      memmove(t.face + (size_t)jj * (size_t)t.W, t.face + (size_t)jj * (size_t)t.SW,
              (size_t)t.W * sizeof *t.face);
    const char *base = strrchr(j.scene, '/');
    base = base ? base + 1 : j.scene;
    char name[256];
    snprintf(name, sizeof name, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot && dot != name) *dot = 0;
    if (mkdir(a.dir, 0777) != 0 && errno != EEXIST)
      st = t74_fail(err, T74_EIO, "%s: cannot make the folder: %s", a.dir, strerror(errno));
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.html", a.dir, name);
    int ln = a.line >= 0 ? (int)(a.line < t.H ? a.line : t.H - 1) : -1;   /* -1: the page picks */
    if (st == T74_OK) st = write_page(path, name, &t, &res, tables, tlen, ln, err);
    if (st == T74_OK) printf("teach: wrote %s\n", path);
  }
  free(tables);
  if (t.row)
    for (int k = 0; k < t.SH; k++) free(t.row[k]);
  free(t.row);
  free(t.face);
  free(t.lit);
  free(t.geom.s);
  if (t.tables) fclose(t.tables);
  return st;
}
