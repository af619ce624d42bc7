/*
** cmd_teach.c — `tube74 teach SCENE [-o DIR] [--line J] [render's options]`: the paper's
** figures, drawn step by step, as one self-contained HTML page (README "teach").
** Sources: paper 003 §2.2 (YSORT, XSORT, crossing types), §3.1 and Fig. 6 (cuts through
** concave vertices, the rules, the numbered pieces), §4 and Fig. 8 (D-blocks), Fig. 9
** (the Priority Matrix filling during the scan), §4 (the picture displayed while computed).
**
** This file contains code to run the renderer once more with its own trace and write what
** it did as data for a teaching page. Nothing here decides anything: the numbers come from
** the renderer's structures and its teaching dump, read after each stage:
**   the Mapper's projected rings (render/mapper.h)           -> the projected faces
**   the --dump tables text of the Segment Generator          -> YSORT order, each cut's
**     (render_opts.tables: "YSORT", "cut", "XSORT" lines)       line, rule and crossings
**   the Segment Information (render/seginfo.h)               -> the numbered pieces
**   at the first point of every grid row of the scan:
**     the Priority Matrix as prio_dump prints it              -> Fig. 9 as it fills
**     the active pieces' D-blocks and the visible stretches   -> the D-blocks of a line
**     (struct vis: act[], span[], render/visible.h)
**   the point callback's visible face per grid point          -> the picture by rows
**   a normal job (cli/pipeline.h) with a sink that keeps dots -> the tube's dots
** Exact values are shown as decimals in world units (grid units / GRID_ONE); they are only
** drawn. The page (a fixed script and style below, the data as one JSON object) needs no
** network: inline SVG built by the script, Next/Back buttons and the arrow keys (Up/Down
** move the chosen line on the D-block step).
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
#include "emu/cost.h"
#include "emu/status.h"
#include "patterns/halftone.h"
#include "render/geom.h"
#include "render/render.h"
#include "render/scene.h"

#define TEACH_MATRIX_MAX 48     /* prio_dump prints the whole matrix up to this many pieces */

/* ---- what the scan showed, row by row ---------------------------------------------- */

struct snap {                   /* the state at the first point of one grid row */
  int j;                        /* grid row (0 = top) */
  char *dblocks;                /* JSON array text: [piece, xl, xr, kl, kr] ... */
  char *spans;                  /* JSON array text: [x0, x1, piece, face] ... */
};

struct mstep {                  /* the Priority Matrix when it changed */
  int j;                        /* the row whose scan changed it */
  int n;                        /* pieces (rows and columns) */
  char *codes;                  /* n*n codes: '-' diagonal, '0' 00, 'L' 10, 'H' 11 */
};

struct teach {
  struct render *r;
  int W, H;
  int *face;                    /* W x H: visible face index per grid point, -1 none */
  struct snap *row;             /* H rows, by j */
  struct mstep *ms;
  int nms, capms;
  int status;                   /* first failure (out of memory) */
  /* the tube's dots, from the job */
  uint8_t *lit;                 /* 400 x 300, y up */
};

static double rat(struct grat q) { return (double)q.num / (double)q.den / (double)GRID_ONE; }

/* A growing string, for the JSON of one row or of the trace. */
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
    size_t nc = b->cap ? b->cap * 2 : 256;
    while (k >= 0 && nc - b->n <= (size_t)k) nc *= 2;
    char *ns = realloc(b->s, nc);
    if (!ns) { b->oom = true; return; }
    b->s = ns;
    b->cap = nc;
  }
}

/* The matrix as prio_dump prints it (dense form), read back into codes. */
static char *matrix_codes(const struct prio *pr, int *n_out)
{
  int n = pr->seg->n;
  *n_out = n;
  if (n > TEACH_MATRIX_MAX) return NULL;
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (!f) return NULL;
  prio_dump(pr, f);
  fclose(f);
  char *codes = malloc((size_t)n * (size_t)n + 1);
  if (!codes) { free(text); return NULL; }
  memset(codes, '0', (size_t)n * (size_t)n);
  codes[(size_t)n * (size_t)n] = 0;
  /* rows: "  %3d " then n tokens; they follow the column header line */
  char *line = text;
  int row = -3;                   /* two header lines and the column numbers come first */
  while (line && *line) {
    char *nl = strchr(line, '\n');
    if (nl) *nl = 0;
    if (row >= 0 && row < n) {
      char *p = line;
      int i = (int)strtol(p, &p, 10);
      for (int c = 0; c < n && i == row; c++) {
        while (*p == ' ') p++;
        char code = p[0] == '-' ? '-' : p[0] == '1' && p[1] == '0' ? 'L' : p[0] == '1' ? 'H' : '0';
        codes[(size_t)row * (size_t)n + (size_t)c] = code;
        while (*p && *p != ' ') p++;
      }
    }
    row++;
    line = nl ? nl + 1 : NULL;
  }
  free(text);
  return codes;
}

static void snap_row(struct teach *t, int j)
{
  const struct vis *v = &t->r->vis;
  struct buf d = { 0 }, s = { 0 };
  bput(&d, "[");
  int first = 1;
  for (int k = 0; k < v->nact; k++) {
    const struct vis_item *it = &v->act[k];
    if (!it->on) continue;
    bput(&d, "%s[%d,%.6g,%.6g,%d,%d]", first ? "" : ",", it->piece, rat(it->xl), rat(it->xr),
         it->kl, it->kr);
    first = 0;
  }
  bput(&d, "]");
  bput(&s, "[");
  for (int k = 0; k < v->nspan; k++)
    bput(&s, "%s[%.6g,%.6g,%d,%d]", k ? "," : "", rat(v->span[k].x0), rat(v->span[k].x1),
         v->span[k].piece, v->span[k].face);
  bput(&s, "]");
  if (d.oom || s.oom) { free(d.s); free(s.s); t->status = T74_EIO; return; }
  t->row[j].j = j;
  t->row[j].dblocks = d.s;
  t->row[j].spans = s.s;
  /* the matrix, when it changed on this row */
  int n;
  char *codes = matrix_codes(&t->r->prio, &n);
  if (!codes) return;             /* too many pieces to draw (or no memory: just fewer steps) */
  const struct mstep *last = t->nms ? &t->ms[t->nms - 1] : NULL;
  if (last && last->n == n && !strcmp(last->codes, codes)) { free(codes); return; }
  if (t->nms == t->capms) {
    int nc = t->capms ? 2 * t->capms : 16;
    struct mstep *nm = realloc(t->ms, (size_t)nc * sizeof *nm);
    if (!nm) { free(codes); t->status = T74_EIO; return; }
    t->ms = nm;
    t->capms = nc;
  }
  t->ms[t->nms++] = (struct mstep){ j, n, codes };
}

static int on_point(void *ctx, int i, int j, int face)
{
  struct teach *t = ctx;
  if (i == 0) snap_row(t, j);
  t->face[(size_t)j * (size_t)t->W + (size_t)i] = face;
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

/* A JSON string of s (ASCII; anything else escaped). */
static void json_str(struct outfile *of, const char *s)
{
  outfile_write(of, "\"", 1);
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\') outfile_printf(of, "\\%c", c);
    else if (c < 0x20 || c >= 0x7F || c == '<' || c == '>' || c == '&') outfile_printf(of, "\\u%04x", c);
    else outfile_write(of, s, 1);
  }
  outfile_write(of, "\"", 1);
}

/* "a/b" or "a" (grid units) as world units. */
static double grid_num(const char *s)
{
  char *e;
  double a = strtod(s, &e);
  if (*e == '/') { double b = strtod(e + 1, NULL); if (b != 0) a /= b; }
  return a / (double)GRID_ONE;
}

/* The Segment Generator's trace: YSORT, cuts and XSORT lines of the tables text, as JSON
** arrays "ysort" and "cuts". */
static void write_trace(struct outfile *of, char *tables)
{
  struct buf ys = { 0 }, cuts = { 0 };
  int face = 0, nys = 0, ncut = 0;
  bool in_cut = false;
  bput(&ys, "[");
  bput(&cuts, "[");
  for (char *line = tables; line && *line;) {
    char *nl = strchr(line, '\n');
    if (nl) *nl = 0;
    if (!strncmp(line, "face ", 5) && (strstr(line, " ring,") || strstr(line, " rings,"))) {
      face = atoi(line + 5);
      in_cut = false;
    } else if (!strncmp(line, "YSORT", 5)) {
      bput(&ys, "%s{\"face\":%d,\"order\":[", nys++ ? "," : "", face);
      int k = 0;
      for (char *p = strstr(line, "y:"); p && (p = strchr(p, '(')); p++) {
        char *q = strchr(p, ')');
        if (!q) break;
        bput(&ys, "%s\"%.*s\"", k++ ? "," : "", (int)(q - p - 1), p + 1);
      }
      bput(&ys, "]}");
    } else if (!strncmp(line, "cut ", 4)) {
      if (in_cut) bput(&cuts, "]}");
      char *y = strstr(line, "at y = ");
      char *rule = strchr(line, ':');
      bput(&cuts, "%s{\"face\":%d,\"y\":%.6g,\"text\":", ncut++ ? "," : "", face,
           y ? grid_num(y + 7) : 0.0);
      /* the text as a JSON string, by hand (no outfile here) */
      bput(&cuts, "\"");
      for (const char *p = rule ? rule + 2 : line; *p; p++)
        bput(&cuts, (*p == '"' || *p == '\\') ? "\\%c" : "%c", *p);
      bput(&cuts, "\",\"head\":\"");
      for (const char *p = line; *p && p != rule; p++)
        bput(&cuts, (*p == '"' || *p == '\\') ? "\\%c" : "%c", *p);
      bput(&cuts, "\",\"xsort\":[");
      in_cut = true;
    } else if (in_cut && !strncmp(line, "XSORT", 5)) {
      int k = 0;
      for (char *p = strstr(line, "x="); p; p = strstr(p + 1, "x=")) {
        char *e = strstr(p, " edge ");
        if (!e) break;
        char edge[64] = "", type[16] = "";
        if (sscanf(e + 6, "%63s %15s", edge, type) != 2) break;
        bput(&cuts, "%s[%.6g,\"%s\",\"%s\"]", k++ ? "," : "", grid_num(p + 2), edge, type);
      }
    } else if (in_cut && (!strncmp(line, "PBS", 3) || !strncmp(line, "IPL", 3) ||
                          !strncmp(line, "LWS", 3) || !strncmp(line, "UPS", 3) ||
                          !strncmp(line, "       above", 12))) {
      /* the steps' lists stay in the dump (--dump tables); the page names the rule */
    } else if (in_cut && strstr(line, "convex pieces after")) {
      bput(&cuts, "]}");
      in_cut = false;
    }
    line = nl ? nl + 1 : NULL;
  }
  if (in_cut) bput(&cuts, "]}");
  bput(&ys, "]");
  bput(&cuts, "]");
  if (!ys.oom && !cuts.oom) {
    outfile_printf(of, "\"ysort\":%s,\n\"cuts\":%s,\n", ys.s, cuts.s);
  } else {
    outfile_printf(of, "\"ysort\":[],\n\"cuts\":[],\n");
  }
  free(ys.s);
  free(cuts.s);
}

static int write_page(const char *path, const char *name, const struct scene *s,
                      struct teach *t, char *tables, int cell, int line, struct t74_error *err)
{
  struct outfile *of;
  int st = outfile_open(&of, path, err);
  if (st != T74_OK) return st;
  const struct render *r = t->r;
  outfile_printf(of, "%s", teach_page_head);
  outfile_printf(of, "<script>\nconst T = {\n\"scene\":");
  json_str(of, name);
  outfile_printf(of, ",\n\"window\":[%d,%d,%d,%d],\"W\":%d,\"H\":%d,\"cell\":%d,\"line\":%d,\n",
                 (int)s->window[0], (int)s->window[1], (int)s->window[2], (int)s->window[3],
                 t->W, t->H, cell, line);
  /* faces: projected rings */
  outfile_printf(of, "\"faces\":[");
  for (int f = 0; f < r->map.nface; f++) {
    const struct mface *m = &r->map.f[f];
    outfile_printf(of, "%s\n{\"id\":%u,\"grey\":%d,\"rings\":[", f ? "," : "", (unsigned)m->id, m->grey);
    for (int g = 0; g < m->nring; g++) {
      outfile_printf(of, "%s[", g ? "," : "");
      for (int k = m->ring_start[g]; k < m->ring_start[g + 1]; k++)
        outfile_printf(of, "%s[%.6g,%.6g,%u]", k > m->ring_start[g] ? "," : "",
                       (double)m->pt[k].x / GRID_ONE, (double)m->pt[k].y / GRID_ONE, (unsigned)m->vid[k]);
      outfile_printf(of, "]");
    }
    outfile_printf(of, "]}");
  }
  outfile_printf(of, "],\n");
  write_trace(of, tables);
  /* pieces: every piece the Segment Information holds, with its face and vertices */
  outfile_printf(of, "\"pieces\":[");
  for (int k = 0; k < r->seg.n; k++) {
    const struct piece *p = &r->seg.p[k];
    outfile_printf(of, "%s\n{\"n\":%d,\"face\":%d,\"alive\":%s,\"v\":[", k ? "," : "", k,
                   p->face, p->alive ? "true" : "false");
    for (int i = 0; i < p->n; i++)
      outfile_printf(of, "%s[%.6g,%.6g]", i ? "," : "",
                     (double)p->v[i].X / (double)p->v[i].W / GRID_ONE,
                     (double)p->v[i].Y / (double)p->v[i].W / GRID_ONE);
    outfile_printf(of, "]}");
  }
  outfile_printf(of, "],\n\"matrix\":[");
  for (int k = 0; k < t->nms; k++)
    outfile_printf(of, "%s\n{\"row\":%d,\"n\":%d,\"codes\":\"%s\"}", k ? "," : "", t->ms[k].j,
                   t->ms[k].n, t->ms[k].codes);
  outfile_printf(of, "],\n\"rows\":[");
  for (int j = 0; j < t->H; j++)
    outfile_printf(of, "%s\n{\"dblocks\":%s,\"spans\":%s}", j ? "," : "",
                   t->row[j].dblocks ? t->row[j].dblocks : "[]",
                   t->row[j].spans ? t->row[j].spans : "[]");
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
  outfile_printf(of, "]\n};\n</script>\n%s", teach_page_tail);
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
    "                         default: the middle row)\n"
    "the page steps through the figures with Next/Back or the arrow keys\n");
}

int cmd_teach(int argc, char **argv, struct t74_error *err)
{
  /* teach's own options out, render's to job_parse */
  const char *dir = ".";
  long line = -1;
  char **rest = malloc((size_t)argc * sizeof *rest);
  if (!rest) return t74_fail(err, T74_EIO, "out of host memory");
  int nrest = 0;
  for (int k = 0; k < argc; k++) {
    if (k >= 2 && !strcmp(argv[k], "-o")) {
      if (k + 1 >= argc) { free(rest); return t74_fail(err, T74_EINPUT, "tube74: missing value after: -o"); }
      dir = argv[++k];
    } else if (k >= 2 && !strcmp(argv[k], "--line")) {
      char *e;
      if (k + 1 >= argc || (errno = 0, line = strtol(argv[k + 1], &e, 10), errno) || *e ||
          e == argv[k + 1] || line < 0 || line > 1000) {
        free(rest);
        return t74_fail(err, T74_EINPUT, "tube74: --line takes a grid row 0..1000");
      }
      k++;
    } else {
      rest[nrest++] = argv[k];
    }
  }
  struct job j;
  int st = job_parse(nrest, rest, 2, &j, NULL, NULL, err);
  j.need_1974 = true;                    /* the page shows the 1974 program's steps */
  if (st == T74_OK && (j.png || j.ndump || j.stats))
    st = t74_fail(err, T74_EINPUT, "tube74 teach: -o names the folder; --dump and --stats "
                  "belong to render");
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
  if (st != T74_OK) { free(rest); return st; }

  struct teach t;
  memset(&t, 0, sizeof t);
  t.lit = calloc((size_t)TUBE_W * TUBE_H, 1);
  if (!t.lit) { free(rest); return t74_fail(err, T74_EIO, "out of host memory"); }
  /* 1. the picture, by the ordinary job (its checks and messages too) */
  struct job_hooks h;
  memset(&h, 0, sizeof h);
  h.extra = (struct sink){ &t, keep_dot, keep_end, keep_abort };
  struct job_result res;
  st = job_run(&j, &h, &res, err);

  /* 2. the renderer again, traced */
  struct scene *s = NULL;
  struct render r;
  memset(&r, 0, sizeof r);
  char *tables = NULL;
  size_t tlen = 0;
  FILE *tf = NULL;
  bool prepared = false;
  struct scene_opts again = j.sopts;
  again.quiet = true;              /* the job has printed the import's warnings once */
  if (st == T74_OK) st = scene_load(j.scene, &again, &s, err);
  if (st == T74_OK && !(tf = open_memstream(&tables, &tlen)))
    st = t74_fail(err, T74_EIO, "out of host memory");
  if (st == T74_OK) {
    double prog = 0;
    cost_params_get(&j.params, "program_words", &prog);
    /* the core the job was drawn with (an import may have needed more than --core's default) */
    struct render_opts ro = { res.core_words, (uint32_t)prog, j.store, tf, 0, NULL };
    st = render_prepare(&r, s, &ro, err);
    prepared = true;
  }
  t.r = &r;
  t.W = res.W;
  t.H = res.H;
  if (st == T74_OK) {
    t.face = malloc((size_t)t.W * (size_t)t.H * sizeof *t.face);
    t.row = calloc((size_t)t.H, sizeof *t.row);
    if (!t.face || !t.row) st = t74_fail(err, T74_EIO, "out of host memory");
  }
  if (st == T74_OK) {
    struct vis_grid g = { t.W, t.H, { s->window[0], s->window[1], s->window[2], s->window[3] } };
    st = render_scan(&r, &g, on_point, &t, err);
    if (st != T74_OK && !err->msg[0]) t74_fail(err, st, "tube74 teach: out of host memory");
  }
  if (tf) fclose(tf);
  if (st == T74_OK) {
    /* the page's name */
    const char *base = strrchr(j.scene, '/');
    base = base ? base + 1 : j.scene;
    char name[256];
    snprintf(name, sizeof name, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot && dot != name) *dot = 0;
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
      st = t74_fail(err, T74_EIO, "%s: cannot make the folder: %s", dir, strerror(errno));
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.html", dir, name);
    int ln = line >= 0 ? (int)(line < t.H ? line : t.H - 1) : t.H / 2;
    if (st == T74_OK) st = write_page(path, name, s, &t, tables ? tables : (char *)"", res.cell, ln, err);
    if (st == T74_OK)
      printf("teach: wrote %s (%d faces, %d pieces, %d matrix steps)\n", path, r.map.nface,
             r.seg.n, t.nms);
  }
  if (t.row)
    for (int k = 0; k < t.H; k++) { free(t.row[k].dblocks); free(t.row[k].spans); }
  for (int k = 0; k < t.nms; k++) free(t.ms[k].codes);
  free(t.ms);
  free(t.row);
  free(t.face);
  free(t.lit);
  free(tables);
  if (prepared) render_free(&r);
  scene_free(s);
  free(rest);
  return st;
}
