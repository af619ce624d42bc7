/*
** timing.c — beam timing and the look layer hung onto a job (see timing.h).
** Sources: display/beam.c (Tektronix 613 settling; paper 003: 21 x 16.3 cm, 400 x 300),
** display/look.c (rricharz/Tek4010 look constants), CONTRACT.md (tube= effect, --stats).
**
** This file contains code to parse the timing and look options shared by `render` and
** `play`, and to give a job the three hooks that time its dots: the clock hook records
** the 1974 computing time before each perspective-plane point that lights dots; the
** extra sink passes each of the point's dots to the beam (which answers when the dot was
** written) and, when a look or a recording is wanted, to the look model; its end()
** writes the -o look picture (before the job's other outputs, so a failure there leaves
** nothing written); the stats hook adds "tube_seconds" and "total_1974_seconds".
*/
#include "cli/timing.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "display/outfile.h"
#include "display/sink.h"
#include "render/effects.h"
#include "render/scene.h"

/* The plain tube look, as display/image.c draws it (kept equal to its colours): the
** scaled plain picture (--scale N without --look) is that picture with each dot an
** N x N block. */
static const uint8_t PLAIN_DOT_RGB[3]  = { 80, 255, 120 };   /* a stored dot: P1 green */
static const uint8_t PLAIN_FACE_RGB[3] = { 8, 20, 12 };      /* the unlit face */

void timing_init(struct timing *t)
{
  memset(t, 0, sizeof *t);
  beam_params_default(&t->bp);
  look_params_default(&t->lp);
  beam_init(&t->beam, &t->bp);
  t->scale = 1;
}

void timing_free(struct timing *t)
{
  look_free(t->look);
  t->look = NULL;
  scene_free(t->scene);
  t->scene = NULL;
}

void timing_usage(FILE *f)
{
  fprintf(f,
    "tube look and timing options (render, play):\n"
    "  --scale N              picture scale 1..8 (each tube dot N x N pixels)\n"
    "  --look LIST            draw -o with the tube's look: comma-separated\n"
    "                         glow | flash | fade[:SECONDS] | plain\n"
    "  --look-at SECONDS      show the face this long after the picture is complete\n"
    "                         (negative: before, while it is still being written)\n"
    "  --beam NAME=VALUE      change a beam timing constant (`tube74 play --list`)\n"
    "  --look-param NAME=VALUE  change a look constant (tube74 play --list)\n");
}

static int parse_double(const char *s, double lo, double hi, double *out)
{
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

/* One item of --look LIST. */
static int look_item(struct timing *t, const char *it, size_t n, struct t74_error *err)
{
  char buf[64];
  if (n >= sizeof buf) n = sizeof buf - 1;
  memcpy(buf, it, n);
  buf[n] = '\0';
  if (!strcmp(buf, "glow")) return T74_OK;             /* the base look: spot + glow */
  if (!strcmp(buf, "plain")) { t->look_given = false; return T74_OK; }
  if (!strcmp(buf, "flash")) { t->look_flags |= LOOK_FLASH; return T74_OK; }
  if (!strncmp(buf, "fade", 4) && (buf[4] == '\0' || buf[4] == ':')) {
    t->look_flags |= LOOK_FADE;
    double s;
    if (buf[4] == ':') {
      if (!parse_double(buf + 5, EFFECTS_FADE_MIN, EFFECTS_FADE_MAX, &s))
        return t74_fail(err, T74_EINPUT, "tube74: --look fade:SECONDS takes %g .. %g, got `%s`",
                        EFFECTS_FADE_MIN, EFFECTS_FADE_MAX, buf + 5);
      t->lp.v[LP_FADE_S] = s;
    }
    return T74_OK;
  }
  return t74_fail(err, T74_EINPUT, "tube74: --look takes glow, flash, fade[:SECONDS] or plain, got `%s`", buf);
}

int timing_opt(void *ctx, int argc, char **argv, int *k, struct t74_error *err)
{
  struct timing *t = ctx;
  const char *a = argv[*k];
  int takes = !strcmp(a, "--scale") || !strcmp(a, "--look") || !strcmp(a, "--look-at") ||
              !strcmp(a, "--beam") || !strcmp(a, "--look-param");
  if (!takes) return 0;
  if (*k + 1 >= argc) { t74_fail(err, T74_EINPUT, "tube74: missing value after: %s", a); return -1; }
  const char *v = argv[++*k];
  double d;
  int st = T74_OK;
  if (!strcmp(a, "--scale")) {
    if (!parse_double(v, 1, LOOK_SCALE_MAX, &d) || d != floor(d))
      st = t74_fail(err, T74_EINPUT, "tube74: --scale takes 1 .. %d: %s", LOOK_SCALE_MAX, v);
    else {
      t->scale = (int)d;
      t->scale_given = true;
    }
  } else if (!strcmp(a, "--look")) {
    t->look_given = true;
    for (const char *p = v; st == T74_OK; ) {
      const char *c = strchr(p, ',');
      size_t n = c ? (size_t)(c - p) : strlen(p);
      st = look_item(t, p, n, err);
      if (!c) break;
      p = c + 1;
    }
  } else if (!strcmp(a, "--look-at")) {
    if (!parse_double(v, -1e7, 1e7, &d))
      st = t74_fail(err, T74_EINPUT, "tube74: --look-at takes seconds (negative: before the "
                    "picture is complete): %s", v);
    else {
      t->look_at = d;
      t->look_at_given = true;
    }
  } else if (!strcmp(a, "--beam")) {
    st = beam_params_set(&t->bp, v, err);
  } else {
    st = look_params_set(&t->lp, v, err);
  }
  return st == T74_OK ? 1 : -1;
}

/* The tube= effect named by --effects or by the scene's effects line (if the scene is a
** .s74 file that loads: anything wrong with it is the job's to report). A scene read here
** is kept (t->scene) and lent to the job with the time its reading took, so the job does
** not read it again; a scene that fails to load lends its failure the same way. */
static int tube_effect(struct timing *t, struct job *j, struct effects *eff, struct t74_error *err)
{
  effects_default(eff);
  const char *dot = strrchr(j->scene, '.');
  bool s74 = j->sopts.input ? !strcmp(j->sopts.input, "s74") : (dot && !strcmp(dot, ".s74"));
  if (j->effects) return effects_parse(j->effects, eff, "--effects", 1, err);
  if (!s74) return T74_OK;
  struct scene *s = NULL;
  struct t74_error quiet = { T74_OK, "" };
  struct timespec a, b;
  clock_gettime(CLOCK_MONOTONIC, &a);
  if (scene_load(j->scene, &j->sopts, &s, &quiet) != T74_OK) {
    t->scene_err = quiet;       /* the job reports it, without reading the file again */
    j->preload_failed = &t->scene_err;
    return T74_OK;
  }
  clock_gettime(CLOCK_MONOTONIC, &b);
  int st = T74_OK;
  if (s->effects) st = effects_parse(s->effects, eff, s->file, s->effects_line, &quiet);
  (void)st;                     /* a bad effects line is the job's to report */
  scene_free(t->scene);
  t->scene = s;
  j->preloaded = s;
  j->preload_seconds = (double)(b.tv_sec - a.tv_sec) + (double)(b.tv_nsec - a.tv_nsec) * 1e-9;
  return T74_OK;
}

int timing_prepare(struct timing *t, struct job *j, struct t74_error *err)
{
  struct effects eff;
  int st = tube_effect(t, j, &eff, err);
  if (st != T74_OK) return st;
  if (eff.tube == EFFECTS_TUBE_FLASH) { t->look_flags |= LOOK_FLASH; t->look_given = true; }
  if (eff.tube == EFFECTS_TUBE_FADE) {
    t->look_flags |= LOOK_FADE;
    t->look_given = true;
    t->lp.v[LP_FADE_S] = eff.fade_seconds;
  }
  t->want_look = t->look_given || t->scale > 1;
  if (t->want_look && j->png) {             /* -o is ours: drawn in the sink's end() */
    t->png = j->png;
    j->png = NULL;
  }
  beam_init(&t->beam, &t->bp);
  t->clock = 0;
  t->untimed = false;
  look_free(t->look);
  t->look = NULL;
  if (t->want_look || t->record) {
    t->look = look_new(&t->lp, t->look_given ? t->look_flags : 0);
    if (!t->look) return t74_fail(err, T74_EIO, "out of host memory");
  }
  return T74_OK;
}

double timing_total_seconds(const struct timing *t) { return beam_total_seconds(&t->beam); }
double timing_tube_seconds(const struct timing *t) { return beam_tube_seconds(&t->beam); }

double timing_show_time(const struct timing *t)
{
  double at = t->look_at_given ? t->look_at
            : (t->look_flags & LOOK_FADE) ? t->lp.v[LP_FADE_S] : 0;
  double when = timing_total_seconds(t) + at;
  return when > 0 ? when : 0;
}

/* ---- hooks ------------------------------------------------------------------------- */

static void on_clock(void *ctx, double hitac10_seconds)
{
  struct timing *t = ctx;
  t->clock = hitac10_seconds;
  beam_clock(&t->beam, hitac10_seconds);
}

static int on_dot(void *ctx, int x, int y)
{
  struct timing *t = ctx;
  double when = beam_dot(&t->beam, x, y, t->clock);
  if (!t->look) return T74_OK;
  int st = look_dot(t->look, x, y, when);
  return st == T74_EINPUT ? T74_OK : st;    /* outside the tube: the tube sink reports it */
}

/* A write-through trace from a Tek stream: each of its dots (an integer line walk) is
   written by the beam, dim and not stored. */
static void on_writethrough(void *ctx, int x0, int y0, int x1, int y1)
{
  struct timing *t = ctx;
  int dx = x1 > x0 ? x1 - x0 : x0 - x1, sx = x0 < x1 ? 1 : -1;
  int dy = y1 > y0 ? y0 - y1 : y1 - y0, sy = y0 < y1 ? 1 : -1;
  int e = dx + dy;
  for (;;) {
    if (x0 >= 0 && x0 < TUBE_W && y0 >= 0 && y0 < TUBE_H) {
      double when = beam_dot(&t->beam, x0, y0, t->clock);
      if (t->look) look_writethrough(t->look, x0, y0, when);
    }
    if (x0 == x1 && y0 == y1) break;
    int e2 = 2 * e;
    if (e2 >= dy) { e += dy; x0 += sx; }
    if (e2 <= dx) { e += dx; y0 += sy; }
  }
}

/* ESC FF in a Tek stream: the erase flash, then a clear face. The tube stores nothing
** while it erases, so the beam waits for the erase to end (erase_s, the look's constant):
** the dots after it are written, and the picture is complete, only then. That keeps the
** beam's times and the look's (display/look.c writes a dot given inside an erase at its
** end) the same, and puts the -o picture of a stream that begins with ESC FF (gnuplot's
** tek40xx) after the flash has died, showing its dots, as a viewer saw them. */
static void on_erase(void *ctx)
{
  struct timing *t = ctx;
  double te = beam_total_seconds(&t->beam);
  if (t->look) look_erase(t->look, te);
  beam_wait(&t->beam, te + t->lp.v[LP_ERASE_S]);
}

/* The scaled plain picture: image.c's look with each dot an s x s block. */
static int write_plain(const struct timing *t, struct outfile *of, struct t74_error *err)
{
  int s = t->scale, W = TUBE_W * s, H = TUBE_H * s;
  uint8_t *lit = calloc((size_t)TUBE_W * TUBE_H, 1);
  uint8_t *rgba = malloc((size_t)W * (size_t)H * 4);
  if (!lit || !rgba) {
    free(lit);
    free(rgba);
    t74_fail(err, T74_EIO, "%s: out of memory", outfile_path(of));
    outfile_abort(of);
    return T74_EIO;
  }
  for (size_t k = 0; k < look_count(t->look); k++) {
    int x, y;
    double when;
    look_event(t->look, k, &x, &y, &when);
    lit[(size_t)y * TUBE_W + (size_t)x] = 1;
  }
  for (int Y = 0; Y < H; Y++)
    for (int X = 0; X < W; X++) {
      const uint8_t *c = lit[(size_t)(TUBE_H - 1 - Y / s) * TUBE_W + (size_t)(X / s)]
                         ? PLAIN_DOT_RGB : PLAIN_FACE_RGB;
      uint8_t *p = rgba + 4 * ((size_t)Y * (size_t)W + (size_t)X);
      p[0] = c[0]; p[1] = c[1]; p[2] = c[2]; p[3] = 255;
    }
  int st = look_png_rgba_to(rgba, W, H, of, err);
  free(lit);
  free(rgba);
  return st;
}

static int on_end(void *ctx, struct t74_error *err)
{
  struct timing *t = ctx;
  beam_clock(&t->beam, t->clock);
  if (!t->png_out) return T74_OK;
  struct outfile *of = t->png_out;        /* finished (or discarded) by the writer; the */
  t->png_out = NULL;                      /* job's set commits it with the others */
  if (!t->look_given) return write_plain(t, of, err);
  return look_write_png_to(t->look, timing_show_time(t), t->scale, of, err);
}

/* job_hooks.open_outputs: the look's -o joins the job's outputs, checked before any work. */
static int on_open_outputs(void *ctx, struct outset *set, struct t74_error *err)
{
  struct timing *t = ctx;
  t->png_out = NULL;
  if (!t->png) return T74_OK;
  return outset_open(set, t->png, 0, &t->png_out, err);
}

static int on_stats(void *ctx, struct outfile *of)
{
  struct timing *t = ctx;
  outfile_printf(of, "  \"tube_seconds\": %.6f,\n", timing_tube_seconds(t));
  if (t->untimed)       /* --engine points: no 1974 computing time to add the beam's to */
    outfile_printf(of, "  \"total_1974_seconds\": null,\n");
  else
    outfile_printf(of, "  \"total_1974_seconds\": %.6f,\n", timing_total_seconds(t));
  return outfile_printf(of, "  \"beam_dwell_us\": %g,\n", t->bp.v[BP_DWELL_US]);
}

static void on_untimed(void *ctx)
{
  struct timing *t = ctx;
  t->untimed = true;
}

void timing_hooks(struct timing *t, const struct job *j, struct job_hooks *h)
{
  memset(h, 0, sizeof *h);
  /* Without --stats, a look, a recording or a picture of ours, no output shows the beam's
     times: the job runs without it (issue 19: timing every dot was a sixth of a plain
     render of the street), and its pictures are the same (the tube sink draws them). */
  if (!j->stats && !t->look && !t->png) return;
  h->extra.ctx = t;
  h->extra.point = on_dot;
  h->extra.end = on_end;
  h->extra.abort = NULL;        /* nothing written before end() */
  h->clock = on_clock;
  h->clock_ctx = t;
  h->stats = on_stats;
  h->stats_ctx = t;
  h->writethrough = on_writethrough;
  h->erase = on_erase;
  h->events_ctx = t;
  h->open_outputs = on_open_outputs;
  h->outputs_ctx = t;
  h->untimed = on_untimed;
  h->untimed_ctx = t;
}
