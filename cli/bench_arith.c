/*
** bench_arith.c — `tube74 bench arith [--out DIR]`: what 1974 arithmetic gets wrong, and
** what exact arithmetic would have cost on the same machine (issue 11).
**
** This file contains code to render each scene twice through the whole pipeline (job_run,
** cli/pipeline.h), once with --arith exact and once with --arith hitac (the decisions in
** the HITAC-10's word sizes, render/geom.h), and to compare the stored tube dots:
**   dots differing  tube dots lit in one picture and not in the other (400 x 300 dots);
**   1974 time       hitac10_seconds of the hitac run: the 1974 program (emu/cost.h n[]);
**   exact time      exact_hitac10_seconds of the exact run: every counted operation at
**                   the exact width it has in tube74 (emu/cost.h x[]), same machine;
**   core words      hitac: core_words_used, the program (program_words) included, tables
**                   in the paper's formats; exact: exact_core_words, the same with the
**                   tables' rows as wide as tube74's exact values (an upper estimate,
**                   cli/pipeline.c; docs/machine.md).
** Scenes: the shipped scenes that exercise the paper (scenes/), and generated hard ones
** written to DIR: a comb (concave, many cuts), shallow crossings (two plates meeting at a
** small angle), a sliver fan, far-away concave faces, nearly parallel plates crossing. Output in DIR (default
** build/bench/arith): arith.md (a Markdown table) and arith.png (every scene's dots:
** grey where both agree, red where only the exact picture has a dot, green where only the
** 1974 arithmetic's has one). The renders run at --core 1048576 so that every scene is
** measured; the words a scene needs are reported, and whether it fits 16 kW.
*/
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/bench_util.h"
#include "cli/commands.h"
#include "cli/pipeline.h"
#include "display/image.h"

#define BA_W 400
#define BA_H 300
#define BA_MAX 32

struct ba_run { double h74, exact74; long core; int lit; uint8_t *dots; };
struct ba_scene { char path[256]; char name[64]; struct ba_run r[2]; long diff; };


/* ---- generated hard scenes ------------------------------------------------------------ */

/* A comb: one concave face with n notches (n cuts of the Segment Generator), seen from
   far enough that its teeth are a few points wide. */
static void gen_comb(FILE *f, int n)
{
  fprintf(f, "# generated: a comb of %d teeth, one concave face (bench arith)\n", n);
  fprintf(f, "view 0 0 -3000\nwindow -200 -150 200 150\n");
  int w = 300 / n, id = 1;
  fprintf(f, "vertex %d -150 -100 0\nvertex %d 150 -100 0\n", id, id + 1);
  id += 2;
  for (int k = n - 1; k >= 0; k--) {      /* right to left along the top */
    int x1 = -150 + (k + 1) * w, x0 = -150 + k * w;
    fprintf(f, "vertex %d %d 110 0\nvertex %d %d 110 0\nvertex %d %d -60 0\n",
            id, x1, id + 1, x1 - w / 2, id + 2, x0 + 1);
    id += 3;
  }
  fprintf(f, "face 1");
  for (int k = 1; k < id; k++) fprintf(f, " %d", k);
  fprintf(f, " grey 200\n");
  /* a backing plate behind, so that cracks show its grey */
  fprintf(f, "vertex %d -190 -140 50\nvertex %d 190 -140 50\nvertex %d 190 140 50\n"
          "vertex %d -190 140 50\nface 2 %d %d %d %d grey 90\n",
          id, id + 1, id + 2, id + 3, id, id + 1, id + 2, id + 3);
}

/* Two plates crossing at a small angle: the intersection line and the depth order come
   from plane coefficients, which the 1974 program held in one word each. */
static void gen_shallow(FILE *f, int tilt)
{
  fprintf(f, "# generated: plates crossing at a small angle (tilt %d in 300) (bench arith)\n", tilt);
  fprintf(f, "view 7 3 -900\nwindow -200 -150 200 150\n");
  fprintf(f, "vertex 1 -170 -120 0\nvertex 2 170 -120 0\nvertex 3 170 120 0\nvertex 4 -170 120 0\n");
  fprintf(f, "vertex 5 -160 -130 %d\nvertex 6 160 -130 %d\nvertex 7 160 130 %d\nvertex 8 -160 130 %d\n",
          -tilt, tilt, tilt, -tilt);
  fprintf(f, "vertex 9 -100 -90 %d\nvertex 10 120 -70 %d\nvertex 11 20 140 %d\n", 3, -2, 1);
  fprintf(f, "face 1 1 2 3 4 grey 220\nface 2 5 6 7 8 grey 120\nface 3 9 10 11 grey 60\n");
}

/* Two nearly parallel triangles crossing far from the eye: their intersection line comes
   from plane coefficients that no longer fit one word, so the 1974 program's truncated
   planes put it elsewhere (wrong faces along it). */
static void gen_plates(FILE *f)
{
  fprintf(f, "# generated: nearly parallel plates crossing (bench arith)\n"
          "view 0 0 -1400\nwindow -400 -300 400 300\n"
          "vertex 1 -300 -200 2000\nvertex 2 300 -193 2003\nvertex 3 -290 207 2001\n"
          "vertex 4 -301 -198 2001\nvertex 5 299 -203 2002\nvertex 6 -295 204 2000\n"
          "face 1 1 2 3 grey 220\nface 2 4 5 6 grey 90\n");
}

/* A fan of slivers sharing one vertex: long, nearly collinear edges. */
static void gen_fan(FILE *f, int n)
{
  fprintf(f, "# generated: a fan of %d slivers (bench arith)\n", n);
  fprintf(f, "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 -190 -140 0\n");
  for (int k = 0; k <= n; k++) fprintf(f, "vertex %d 190 %d %d\n", k + 2, -140 + k * 280 / n, k % 3);
  for (int k = 0; k < n; k++) {
    /* keep every face planar: the three vertices define it */
    fprintf(f, "face %d 1 %d %d grey %d\n", k + 1, k + 2, k + 3, 60 + (k * 37) % 190);
  }
}

/* Concave L faces far from the eye, overlapping in depth order. */
static void gen_far(FILE *f)
{
  fprintf(f, "# generated: far concave faces in a row (bench arith)\n");
  fprintf(f, "view 0 0 -20000\nwindow -200 -150 200 150\n");
  int id = 1;
  for (int k = 0; k < 4; k++) {
    int x = -160 + 70 * k, y = -110 + 40 * k, z = 30 * k;
    fprintf(f, "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n"
            "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n",
            id, x, y, z, id + 1, x + 150, y, z, id + 2, x + 150, y + 40, z,
            id + 3, x + 40, y + 40, z, id + 4, x + 40, y + 180, z, id + 5, x, y + 180, z);
    fprintf(f, "face %d %d %d %d %d %d %d grey %d\n", k + 1, id, id + 1, id + 2, id + 3,
            id + 4, id + 5, 80 + 40 * k);
    id += 6;
  }
}

static int write_gen(const char *dir, int k, char *path, size_t len, char *name, size_t nlen)
{
  static const char *const names[] = { "gen-comb24", "gen-comb60", "gen-shallow3",
                                       "gen-shallow1", "gen-fan40", "gen-far", "gen-plates" };
  if (k >= (int)(sizeof names / sizeof names[0])) return 0;
  snprintf(path, len, "%s/%s.s74", dir, names[k]);
  snprintf(name, nlen, "%s", names[k]);
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  switch (k) {
  case 0: gen_comb(f, 24); break;
  case 1: gen_comb(f, 60); break;
  case 2: gen_shallow(f, 3); break;
  case 3: gen_shallow(f, 1); break;
  case 4: gen_fan(f, 40); break;
  case 5: gen_far(f); break;
  default: gen_plates(f); break;
  }
  return fclose(f) == 0 ? 1 : -1;
}

/* ---- one run ------------------------------------------------------------------------- */

static double json_num(const char *js, const char *key)
{
  char k[96];
  snprintf(k, sizeof k, "\"%s\":", key);
  const char *p = strstr(js, k);
  return p ? strtod(p + strlen(k), NULL) : -1;
}

static char *slurp(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *b = NULL;
  size_t n = 0, cap = 0;
  for (;;) {
    if (n + 4096 + 1 > cap) {
      cap = cap ? 2 * cap : 8192;
      char *nb = realloc(b, cap);
      if (!nb) { free(b); fclose(f); return NULL; }
      b = nb;
    }
    size_t got = fread(b + n, 1, 4096, f);
    n += got;
    if (got == 0) break;
  }
  fclose(f);
  b[n] = 0;
  return b;
}

/* Read a P4 400 x 300 PBM into one byte a dot (row 0 at the top, as the file). */
static int read_pbm(const char *path, uint8_t *dots)
{
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  int w, h;
  if (fscanf(f, "P4 %d %d", &w, &h) != 2 || w != BA_W || h != BA_H || fgetc(f) == EOF) {
    fclose(f);
    return -1;
  }
  uint8_t row[(BA_W + 7) / 8];
  for (int y = 0; y < BA_H; y++) {
    if (fread(row, 1, sizeof row, f) != sizeof row) { fclose(f); return -1; }
    for (int x = 0; x < BA_W; x++) dots[y * BA_W + x] = (row[x / 8] >> (7 - x % 8)) & 1;
  }
  fclose(f);
  return 0;
}

static int run_one(const char *scene, const char *dir, int hitac, struct ba_run *r,
                   struct t74_error *err)
{
  char pbm[600], stats[600], dump[640];
  snprintf(pbm, sizeof pbm, "%s/run.pbm", dir);
  snprintf(stats, sizeof stats, "%s/run.json", dir);
  snprintf(dump, sizeof dump, "tube=%s", pbm);
  char *argv[] = { "tube74", "render", (char *)scene, "--dump", dump, "--stats", stats,
                   "--arith", hitac ? "hitac" : "exact", "--core", "1048576", NULL };
  int argc = (int)(sizeof argv / sizeof argv[0]) - 1;
  struct job j;
  int st = job_parse(argc, argv, 2, &j, NULL, NULL, err);
  if (st != T74_OK) return st;
  j.need_1974 = true;                     /* exact against 1974 arithmetic: the 1974 program */
  struct job_result res;
  st = job_run(&j, NULL, &res, err);
  if (st != T74_OK) return st;
  char *js = slurp(stats);
  r->dots = malloc(BA_W * BA_H);
  if (!js || !r->dots || read_pbm(pbm, r->dots) != 0) {
    free(js);
    return t74_fail(err, T74_EIO, "%s: cannot read back the run's outputs in %s", scene, dir);
  }
  r->h74 = json_num(js, "hitac10_seconds");
  r->exact74 = json_num(js, "exact_hitac10_seconds");
  r->core = (long)json_num(js, hitac ? "core_words_used" : "exact_core_words");
  r->lit = (int)json_num(js, "points_lit");
  free(js);
  remove(pbm);
  remove(stats);
  return T74_OK;
}

/* ---- the picture of the differences ------------------------------------------------- */

struct ba_pic { struct ba_scene *s; int n, cols; };

#define BA_GAP 6

static void pic_row(void *ctx, int r, uint8_t *rgb)
{
  const struct ba_pic *p = ctx;
  int W = p->cols * (BA_W + BA_GAP) - BA_GAP;
  memset(rgb, 40, (size_t)W * 3);
  int row = r / (BA_H + BA_GAP), y = r % (BA_H + BA_GAP);
  if (y >= BA_H) return;
  for (int c = 0; c < p->cols; c++) {
    int k = row * p->cols + c;
    if (k >= p->n) break;
    const uint8_t *e = p->s[k].r[0].dots, *h = p->s[k].r[1].dots;
    for (int x = 0; x < BA_W; x++) {
      uint8_t *o = rgb + 3 * (c * (BA_W + BA_GAP) + x);
      int a = e[y * BA_W + x], b = h[y * BA_W + x];
      if (a && b) { o[0] = o[1] = o[2] = 120; }
      else if (a) { o[0] = 255; o[1] = 40; o[2] = 40; }
      else if (b) { o[0] = 40; o[1] = 255; o[2] = 40; }
      else { o[0] = o[1] = o[2] = 0; }
    }
  }
}

/* ---- the command ---------------------------------------------------------------------- */

int bench_arith(int argc, char **argv, struct t74_error *err)
{
  const char *out = "build/bench/arith";
  for (int k = 3; k < argc; k++) {
    if (!strcmp(argv[k], "--out") && k + 1 < argc) out = argv[++k];
    else return t74_fail(err, T74_EINPUT, "tube74: bench arith: unknown option `%s` "
                         "(usage: tube74 bench arith [--out DIR])", argv[k]);
  }
  if (bench_mkdirs(out) != 0) return t74_fail(err, T74_EIO, "%s: cannot make the directory", out);

  static const char *const shipped[] = {
    "fig5", "fig6", "fig7a", "fig7b", "crossing", "lprism", "street", "sphere", "t1-a",
    "t1-e", "t1-g", "fig10a", "fig10b", "fig10c" };
  struct ba_scene *s = calloc(BA_MAX, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "out of host memory");
  int n = 0, st = T74_OK;
  for (size_t k = 0; k < sizeof shipped / sizeof shipped[0] && n < BA_MAX; k++) {
    snprintf(s[n].path, sizeof s[n].path, "scenes/%s.s74", shipped[k]);
    if (access(s[n].path, R_OK) != 0) continue;         /* run from elsewhere: skip */
    snprintf(s[n].name, sizeof s[n].name, "%s", shipped[k]);
    n++;
  }
  for (int k = 0; n < BA_MAX; k++) {
    int g = write_gen(out, k, s[n].path, sizeof s[n].path, s[n].name, sizeof s[n].name);
    if (g == 0) break;
    if (g < 0) { st = t74_fail(err, T74_EIO, "%s: cannot write a generated scene", out); goto done; }
    n++;
  }
  for (int k = 0; k < n; k++) {
    fprintf(stderr, "bench arith: %s\n", s[k].name);
    for (int m = 0; m < 2; m++)
      if ((st = run_one(s[k].path, out, m, &s[k].r[m], err)) != T74_OK) goto done;
    s[k].diff = 0;
    for (int d = 0; d < BA_W * BA_H; d++) s[k].diff += s[k].r[0].dots[d] != s[k].r[1].dots[d];
  }

  char md[600];
  snprintf(md, sizeof md, "%s/arith.md", out);
  FILE *f = fopen(md, "w");
  if (!f) { st = t74_fail(err, T74_EIO, "%s: cannot write", md); goto done; }
  fprintf(f, "# Exact against 1974 arithmetic (`tube74 bench arith`)\n\n"
          "Each scene rendered with `--arith exact` and `--arith hitac` (decisions in the "
          "HITAC-10's word sizes: docs/machine.md). *Dots differing*: tube dots (of 400 x 300) "
          "lit in one picture only. *1974 s*: `hitac10_seconds` of the hitac run (the 1974 "
          "program's arithmetic); *exact s*: `exact_hitac10_seconds` of the exact run (every "
          "counted operation at tube74's exact width, same machine). Both are estimates "
          "from inferred instruction times: the paper reports no computing times. *Core*, "
          "the program's 4096 words (program_words) included: hitac `core_words_used`, "
          "tables in the paper's formats; exact `exact_core_words`, the tables as wide as "
          "the exact values (an upper estimate). Picture: arith.png (grey both, red exact "
          "only, green 1974 only).\n\n");
  fprintf(f, "| scene | dots lit (exact) | dots differing | %% of lit | 1974 s | exact s | "
          "exact / 1974 | core (hitac) | core (exact) | fits 16 kW |\n"
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n");
  for (int k = 0; k < n; k++) {
    const struct ba_run *e = &s[k].r[0], *h = &s[k].r[1];
    fprintf(f, "| %s | %d | %ld | %.2f | %.3f | %.3f | %.1f | %ld | %ld | %s |\n", s[k].name,
            e->lit, s[k].diff, e->lit ? 100.0 * (double)s[k].diff / e->lit : 0.0, h->h74,
            e->exact74, h->h74 > 0 ? e->exact74 / h->h74 : 0.0, h->core, e->core,
            h->core <= 16384 ? (e->core <= 16384 ? "both" : "1974 only") : "no");
  }
  fprintf(f, "\nPanels of arith.png, left to right and top to bottom:");
  for (int k = 0; k < n; k++) fprintf(f, "%s %s", k ? "," : "", s[k].name);
  fprintf(f, ".\n");
  if (fclose(f) != 0) { st = t74_fail(err, T74_EIO, "%s: cannot write", md); goto done; }

  struct ba_pic pic = { s, n, 4 };
  int rows = (n + pic.cols - 1) / pic.cols;
  char png[600];
  snprintf(png, sizeof png, "%s/arith.png", out);
  st = image_write_rgb_png(pic.cols * (BA_W + BA_GAP) - BA_GAP, rows * (BA_H + BA_GAP) - BA_GAP,
                           pic_row, &pic, png, err);
  if (st == T74_OK) printf("bench arith: %d scenes; wrote %s and %s\n", n, md, png);
done:
  for (int k = 0; k < BA_MAX; k++) { free(s[k].r[0].dots); free(s[k].r[1].dots); }
  free(s);
  return st;
}
