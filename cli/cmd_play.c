/*
** cmd_play.c — `tube74 play SCENE`: watch the picture build up as on the 1974 tube.
** Sources: paper 003 §4 and appendix (the program displayed while it computed; a 400 x
** 300 point storage tube); display/beam.h (when each dot was written: computing time,
** Tektronix 613 settling, dwell); display/look.h (the look: flash, glow, erase).
**
** This file contains code to run the render job with the timing hooks (cli/timing.h), so
** that every tube dot comes back with its 1974 write time, and then to play those dots
** back against a clock of emulated time: in an SDL2 window (emulated time runs at
** --speed times wall time; the window paces itself by the wall clock, it never sleeps in
** place of deflection time), or, with --movie, as a sequence of PNG frames written
** without any window. The clock of emulated time is drawn in a strip under the face with
** a small seven-segment font drawn here (no font library).
**
** Keys: space pause, + / - double / halve the speed, e erase (with its flash),
** r erase and redraw the whole picture, q or Esc quit.
**
** The movie, chosen by the name's extension: --movie FILE.gif writes one animated GIF
** (display/gif.h, giflib) that any browser plays; any other name a PNG sequence FILE-0001.png,
** FILE-0002.png, ... (FILE without a trailing ".png"; Debian 12's libpng 1.6.39 has no
** APNG: png_set_acTL is absent from png.h). Either way one frame every --speed / --fps
** seconds of emulated time, the last frame the settled final picture (after the last
** dot's flash). The GIF's palette is one ramp of the look's colour (look_colour) at
** PLAY_GIF_LEVELS intensities from 0 to PLAY_GIF_IMAX: the face is one phosphor at many
** brightnesses, so each pixel takes the nearest level (steps of 0.008 of the bright spot;
** brighter light, only in the writing flash and the erase, is shown at PLAY_GIF_IMAX,
** already white with bloom). Each frame is shown 1/--fps s; the last one 3 s longer, so a
** looping viewer rests on the finished picture.
*/
#define SDL_MAIN_HANDLED

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "cli/pipeline.h"
#include "cli/sdl_load.h"
#include "cli/timing.h"
#include "display/gif.h"
#include "display/look.h"
#include "display/sink.h"
#include "emu/status.h"

#define PLAY_STRIP_H   28       /* pixels of the clock strip under the face */
#define PLAY_MAX_FRAMES_DEF 1000 /* default cap on --movie frames */
#define PLAY_GIF_LEVELS 256     /* GIF palette: intensity levels (the whole palette) */
#define PLAY_GIF_IMAX   2.0     /* intensity of the top level (1.0 = the bright spot) */
#define PLAY_GIF_HOLD_CS 300    /* the last frame's extra time, hundredths of a second */

struct play_opts {
  struct timing *tm;            /* --scale, --look, ... go to the timing options */
  double speed;                 /* emulated seconds per wall second */
  const char *movie;            /* --movie FILE, or NULL */
  double fps;                   /* --fps: movie frames per wall second of playback */
  int max_frames;               /* --max-frames */
  double quit_after;            /* --quit-after: wall seconds after the picture settled; <0 never */
  const char *screenshot;       /* --screenshot FILE.png: the window when quitting */
  bool list;                    /* --list: print the beam and look constants */
};

void play_usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 play SCENE [--speed X] [--movie FILE] [render's options]\n"
    "  --speed X              emulated seconds per wall second (default 1: 1974 speed)\n"
    "  --movie FILE           write the build-up (no window needed): FILE.gif as an\n"
    "                         animated GIF, any other name as FILE-0001.png ...\n"
    "  --fps N                movie frames per second of playback (default 10)\n"
    "  --max-frames N         at most N movie frames (default 1000; longer plays are sampled)\n"
    "  --quit-after S         close the window S seconds after the picture is complete\n"
    "  --screenshot FILE.png  save the window's contents when it closes\n"
    "  --list                 print the beam timing and look constants with their sources\n"
    "keys: space pause, + faster, - slower, e erase, r redraw, q / Esc quit\n");
}

static int num(const char *s, double lo, double hi, double *out)
{
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

/* job_opt_fn: play's own options, then the timing options. */
static int play_opt(void *ctx, int argc, char **argv, int *k, struct t74_error *err)
{
  struct play_opts *o = ctx;
  const char *a = argv[*k];
  double d;
  if (!strcmp(a, "--list")) { o->list = true; return 1; }
  int own = !strcmp(a, "--speed") || !strcmp(a, "--movie") || !strcmp(a, "--fps") ||
            !strcmp(a, "--max-frames") || !strcmp(a, "--quit-after") || !strcmp(a, "--screenshot");
  if (!own) return timing_opt(o->tm, argc, argv, k, err);
  if (*k + 1 >= argc) { t74_fail(err, T74_EINPUT, "tube74: missing value after: %s", a); return -1; }
  const char *v = argv[++*k];
  if (!strcmp(a, "--movie")) o->movie = v;
  else if (!strcmp(a, "--screenshot")) o->screenshot = v;
  else if (!strcmp(a, "--speed")) {
    if (!num(v, 1e-3, 1e7, &d)) { t74_fail(err, T74_EINPUT, "tube74: --speed takes 0.001 .. 1e7: %s", v); return -1; }
    o->speed = d;
  } else if (!strcmp(a, "--fps")) {
    if (!num(v, 0.1, 240, &d)) { t74_fail(err, T74_EINPUT, "tube74: --fps takes 0.1 .. 240: %s", v); return -1; }
    o->fps = d;
  } else if (!strcmp(a, "--max-frames")) {
    if (!num(v, 2, 100000, &d) || d != floor(d)) { t74_fail(err, T74_EINPUT, "tube74: --max-frames takes 2 .. 100000: %s", v); return -1; }
    o->max_frames = (int)d;
  } else {
    if (!num(v, 0, 1e6, &d)) { t74_fail(err, T74_EINPUT, "tube74: --quit-after takes seconds >= 0: %s", v); return -1; }
    o->quit_after = d;
  }
  return 1;
}

/* ---- the movie --------------------------------------------------------------------- */

/* The name of movie frame i (1-based) into name (base + 32 bytes). */
static void frame_name(char *name, const struct play_opts *o, size_t base, long i)
{
  snprintf(name, base + 32, "%.*s-%04ld.png", (int)base, o->movie, i);
}

/* The movie's name without a trailing ".png". */
static size_t movie_base(const struct play_opts *o)
{
  size_t base = strlen(o->movie);
  if (base > 4 && !strcmp(o->movie + base - 4, ".png")) base -= 4;
  return base;
}

/* The frames join the job's set (display/outfile.h): frame 1 is opened before the job
** (first, so its folder is checked before any work), the rest once their number is known;
** all are committed with the job's other outputs by the caller. */

/* The name ends in ".gif" (any case). */
static bool is_gif(const char *name)
{
  size_t n = strlen(name);
  if (n < 4) return false;
  const char *e = name + n - 4;
  return e[0] == '.' && (e[1] | 0x20) == 'g' && (e[2] | 0x20) == 'i' && (e[3] | 0x20) == 'f';
}

/* The animated GIF: frames at times t_i, each the look's intensities quantised to the
** palette's ramp. */
static int write_gif(const struct look *l, const struct play_opts *o, int scale, long n,
                     double dt, double end, struct outfile *of, struct t74_error *err)
{
  int W = TUBE_W * scale, H = TUBE_H * scale;
  size_t npx = (size_t)W * (size_t)H;
  uint8_t pal[PLAY_GIF_LEVELS][3], rgba[4];
  for (int k = 0; k < PLAY_GIF_LEVELS; k++) {
    look_colour(look_get_params(l), (float)(k * PLAY_GIF_IMAX / (PLAY_GIF_LEVELS - 1)), rgba);
    memcpy(pal[k], rgba, 3);
  }
  float *I = malloc(npx * sizeof *I);
  uint8_t *idx = malloc(npx);
  struct gif *g = NULL;
  int st;
  if (!I || !idx) { outfile_abort(of); st = t74_fail(err, T74_EIO, "out of host memory"); }
  else st = gif_open_to(&g, of, o->movie, W, H, (const uint8_t (*)[3])pal, err);
  int delay = (int)lround(100.0 / o->fps);
  for (long i = 0; i < n && st == T74_OK; i++) {
    double t = i == n - 1 ? end : (double)i * dt;
    if (t > end) t = end;
    st = look_intensity(l, t, scale, I);
    if (st != T74_OK) { t74_fail(err, st, "%s: cannot render frame %ld", o->movie, i + 1); break; }
    for (size_t p = 0; p < npx; p++) {
      double q = I[p] / PLAY_GIF_IMAX * (PLAY_GIF_LEVELS - 1);
      idx[p] = (uint8_t)(q <= 0 ? 0 : q >= PLAY_GIF_LEVELS - 1 ? PLAY_GIF_LEVELS - 1 : lrint(q));
    }
    st = gif_frame(g, idx, i == n - 1 ? delay + PLAY_GIF_HOLD_CS : delay, err);
  }
  if (st == T74_OK) { st = gif_commit(g, err); g = NULL; }
  if (g) gif_abort(g);
  free(I);
  free(idx);
  return st;
}

static int write_movie(const struct look *l, const struct play_opts *o, int scale,
                       struct outset *set, struct outfile *first, long *frames,
                       double *frame_dt, struct t74_error *err)
{
  double end = look_settled(l);                 /* the final picture, flash faded */
  double dt = o->speed / o->fps;                /* emulated seconds per frame */
  long n = (long)ceil(end / dt) + 1;            /* frames at 0, dt, ..., then `end` */
  if (n < 2) n = 2;
  if (n > o->max_frames) { n = o->max_frames; dt = end / (double)(n - 1); }
  *frames = n;
  *frame_dt = dt;
  if (is_gif(o->movie)) return write_gif(l, o, scale, n, dt, end, first, err);
  size_t base = movie_base(o);
  char *name = malloc(base + 32);
  uint8_t *rgba = malloc((size_t)TUBE_W * scale * (size_t)TUBE_H * scale * 4);
  if (!name || !rgba) { free(name); free(rgba); return t74_fail(err, T74_EIO, "out of host memory"); }
  int st = T74_OK;
  for (long i = 0; i < n && st == T74_OK; i++) {
    double t = i == n - 1 ? end : (double)i * dt;
    if (t > end) t = end;
    frame_name(name, o, base, i + 1);
    struct outfile *of = first;
    if (i > 0 && (st = outset_open(set, name, 0, &of, err)) != T74_OK) break;
    st = look_render(l, t, scale, rgba);
    if (st != T74_OK) { outfile_abort(of); t74_fail(err, st, "%s: cannot render the frame", name); break; }
    st = look_png_rgba_to(rgba, TUBE_W * scale, TUBE_H * scale, of, err);
  }
  *frames = n;
  *frame_dt = dt;
  free(name);
  free(rgba);
  return st;
}

/* ---- the clock: a seven-segment font --------------------------------------------- */

/* Segments, bit 0..6 = a (top), b (top right), c (bottom right), d (bottom), e (bottom
** left), f (top left), g (middle). */
static int seg_mask(char c)
{
  switch (c) {
  case '0': return 0x3f; case '1': return 0x06; case '2': return 0x5b; case '3': return 0x4f;
  case '4': return 0x66; case '5': return 0x6d; case '6': return 0x7d; case '7': return 0x07;
  case '8': return 0x7f; case '9': return 0x6f; case '-': return 0x40;
  case 'P': return 0x73; case 'A': return 0x77; case 'U': return 0x3e; case 'S': return 0x6d;
  case 'E': return 0x79; case 'r': return 0x50; case 't': return 0x78; case 'd': return 0x5e;
  default:  return 0;
  }
}

/* Draw text at (x, y) with digits w x h pixels; returns the x after it. '.' is a dot,
** 'x' a stroke-drawn multiplication sign, ' ' a gap. */
static int draw_text(const struct sdl_fns *S, SDL_Renderer *r, int x, int y, int w, int h, const char *s)
{
  int t = w / 5 > 1 ? w / 5 : 1;                /* stroke thickness */
  for (; *s; s++) {
    if (*s == '.') { SDL_Rect d = { x, y + h - t, t, t }; S->RenderFillRect(r, &d); x += 2 * t + 1; continue; }
    if (*s == ' ') { x += w / 2 + 2; continue; }
    if (*s == 'x') {
      for (int k = 0; k < t; k++) {
        S->RenderDrawLine(r, x + k, y + h / 2, x + w - t + k, y + h - 1);
        S->RenderDrawLine(r, x + k, y + h - 1, x + w - t + k, y + h / 2);
      }
      x += w + 3;
      continue;
    }
    int m = seg_mask(*s), hh = h / 2;
    SDL_Rect seg[7] = {
      { x, y, w, t },                   /* a */
      { x + w - t, y, t, hh },          /* b */
      { x + w - t, y + hh, t, h - hh }, /* c */
      { x, y + h - t, w, t },           /* d */
      { x, y + hh, t, h - hh },         /* e */
      { x, y, t, hh },                  /* f */
      { x, y + hh - t / 2, w, t },      /* g */
    };
    for (int k = 0; k < 7; k++) if (m & (1 << k)) S->RenderFillRect(r, &seg[k]);
    x += w + 3;
  }
  return x;
}

/* ---- the window -------------------------------------------------------------------- */

struct player {
  SDL_Window *win;
  SDL_Renderer *ren;
  SDL_Texture *tex;
  struct sdl_fns sdl;           /* SDL2, loaded when the window opens */
  int scale, W, H;              /* face pixels: W x H; window W x (H + strip) */
  uint8_t *rgba;                /* the face, W x H x 4 */
};

static void player_close(struct player *p)
{
  const struct sdl_fns *S = &p->sdl;
  if (p->tex) S->DestroyTexture(p->tex);
  if (p->ren) S->DestroyRenderer(p->ren);
  if (p->win) S->DestroyWindow(p->win);
  free(p->rgba);
  S->Quit();
  sdl_unload(&p->sdl);
}

static int player_open(struct player *p, int scale, const char *scene, struct t74_error *err)
{
  memset(p, 0, sizeof *p);
  p->scale = scale;
  p->W = TUBE_W * scale;
  p->H = TUBE_H * scale;
  if (!getenv("DISPLAY") && !getenv("WAYLAND_DISPLAY") && !getenv("SDL_VIDEODRIVER"))
    return t74_fail(err, T74_EIO, "tube74 play: cannot open a window: no display (DISPLAY is "
                    "not set); use --movie FILE to write the build-up as PNG frames instead");
  if (sdl_load(&p->sdl, "tube74 play: cannot open a window", err) != T74_OK) return err->status;
  const struct sdl_fns *S = &p->sdl;
  if (S->Init(SDL_INIT_VIDEO) != 0) {
    t74_fail(err, T74_EIO, "tube74 play: cannot open a window: no display (%s); "
                    "use --movie FILE to write the build-up as PNG frames instead", S->GetError());
    sdl_unload(&p->sdl);
    return T74_EIO;
  }
  /* SDL falls back to its offscreen driver when there is no display: that is no window
     anyone can see, so it counts as "no display" unless asked for by SDL_VIDEODRIVER. */
  const char *drv = S->GetCurrentVideoDriver(), *want = getenv("SDL_VIDEODRIVER");
  if (drv && (!strcmp(drv, "offscreen") || !strcmp(drv, "dummy")) && !(want && !strcmp(want, drv))) {
    S->Quit();
    sdl_unload(&p->sdl);
    return t74_fail(err, T74_EIO, "tube74 play: cannot open a window: no display (DISPLAY is "
                    "not set or unreachable); use --movie FILE to write the build-up as PNG "
                    "frames instead");
  }
  char title[256];
  snprintf(title, sizeof title, "tube74 play %s", scene);
  p->win = S->CreateWindow(title, SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                            p->W, p->H + PLAY_STRIP_H, 0);
  if (p->win) p->ren = S->CreateRenderer(p->win, -1, 0);
  if (p->ren) p->tex = S->CreateTexture(p->ren, SDL_PIXELFORMAT_RGBA32,
                                         SDL_TEXTUREACCESS_STREAMING, p->W, p->H);
  p->rgba = malloc((size_t)p->W * (size_t)p->H * 4);
  if (!p->tex || !p->rgba) {
    t74_fail(err, T74_EIO, "tube74 play: cannot open a window: %s", S->GetError());
    player_close(p);
    return T74_EIO;
  }
  return T74_OK;
}

/* Draw the face at emulated time t and the clock strip; T74_OK or a status. */
static int player_draw(struct player *p, const struct look *l, double t, double speed,
                       bool paused, struct t74_error *err)
{
  const struct sdl_fns *S = &p->sdl;
  int st = look_render(l, t, p->scale, p->rgba);
  if (st != T74_OK) return t74_fail(err, st, "tube74 play: cannot render the face");
  S->UpdateTexture(p->tex, NULL, p->rgba, p->W * 4);
  S->SetRenderDrawColor(p->ren, 0, 0, 0, 255);
  S->RenderClear(p->ren);
  SDL_Rect face = { 0, 0, p->W, p->H };
  S->RenderCopy(p->ren, p->tex, NULL, &face);
  char buf[64];
  S->SetRenderDrawColor(p->ren, 80, 255, 120, 255);
  snprintf(buf, sizeof buf, "t %09.3f", t);               /* emulated 1974 seconds */
  int x = draw_text(S, p->ren, 6, p->H + 5, 10, PLAY_STRIP_H - 10, buf);
  snprintf(buf, sizeof buf, "  x%g", speed);
  x = draw_text(S, p->ren, x, p->H + 5, 10, PLAY_STRIP_H - 10, buf);
  if (paused) draw_text(S, p->ren, x, p->H + 5, 10, PLAY_STRIP_H - 10, "  PAUSE");
  return T74_OK;
}

static int player_screenshot(struct player *p, const char *path, struct t74_error *err)
{
  int w = p->W, h = p->H + PLAY_STRIP_H;
  uint8_t *buf = malloc((size_t)w * (size_t)h * 4);
  if (!buf) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  const struct sdl_fns *S = &p->sdl;
  int st;
  if (S->RenderReadPixels(p->ren, NULL, SDL_PIXELFORMAT_RGBA32, buf, w * 4) != 0)
    st = t74_fail(err, T74_EIO, "%s: cannot read the window: %s", path, S->GetError());
  else
    st = look_png_rgba(buf, w, h, path, err);
  free(buf);
  return st;
}

/* Redraw: erase now, then the whole picture again after the erase, with its own timing. */
static int redraw(struct look *l, const struct look *orig, double now)
{
  int st = look_erase(l, now);
  double start = now + look_get_params(l)->v[LP_ERASE_S];
  for (size_t k = 0; k < look_count(orig) && st == T74_OK; k++) {
    int x, y;
    double t;
    look_event(orig, k, &x, &y, &t);
    st = look_dot(l, x, y, start + t);
  }
  return st;
}

static int run_window(struct look *l, const struct look *orig, const struct play_opts *o,
                      int scale, const char *scene, struct t74_error *err)
{
  struct player p;
  int st = player_open(&p, scale, scene, err);
  if (st != T74_OK) return st;
  const struct sdl_fns *S = &p.sdl;
  double speed = o->speed, te = 0;              /* emulated time now */
  double done_at = look_settled(l);             /* the picture is complete and settled */
  double quit_wall = -1;                        /* wall time to close, once known */
  bool paused = false, running = true;
  Uint64 freq = S->GetPerformanceFrequency(), last = S->GetPerformanceCounter();
  double wall = 0;
  while (running && st == T74_OK) {
    SDL_Event ev;
    while (S->PollEvent(&ev)) {
      if (ev.type == SDL_QUIT) running = false;
      if (ev.type != SDL_KEYDOWN) continue;
      switch (ev.key.keysym.sym) {
      case SDLK_q: case SDLK_ESCAPE: running = false; break;
      case SDLK_SPACE: paused = !paused; break;
      case SDLK_PLUS: case SDLK_EQUALS: case SDLK_KP_PLUS: if (speed < 1e7) speed *= 2; break;
      case SDLK_MINUS: case SDLK_KP_MINUS: if (speed > 1e-3) speed /= 2; break;
      case SDLK_e:
        if (look_erase(l, te) != T74_OK) st = t74_fail(err, T74_EIO, "out of host memory");
        break;
      case SDLK_r:
        if (redraw(l, orig, te) != T74_OK) st = t74_fail(err, T74_EIO, "out of host memory");
        done_at = look_settled(l);
        quit_wall = -1;
        break;
      default: break;
      }
    }
    Uint64 now = S->GetPerformanceCounter();
    double dwall = (double)(now - last) / (double)freq;
    last = now;
    wall += dwall;
    if (!paused) te += dwall * speed;           /* emulated time follows the wall clock */
    if (te >= done_at && quit_wall < 0 && o->quit_after >= 0) quit_wall = wall + o->quit_after;
    if (st == T74_OK) st = player_draw(&p, l, te, speed, paused, err);
    bool closing = !running || (quit_wall >= 0 && wall >= quit_wall);
    if (closing && o->screenshot && st == T74_OK) st = player_screenshot(&p, o->screenshot, err);
    S->RenderPresent(p.ren);
    if (closing) running = false;
    else S->Delay(10);                         /* frame pacing only: time comes from the clock */
  }
  player_close(&p);
  return st;
}

/* ---- the command ------------------------------------------------------------------- */

int cmd_play(int argc, char **argv, struct t74_error *err)
{
  struct timing tm;
  timing_init(&tm);
  tm.record = true;
  struct play_opts o = { &tm, 1.0, NULL, 10.0, PLAY_MAX_FRAMES_DEF, -1, NULL, false };
  struct job j;
  int st = job_parse(argc, argv, 2, &j, play_opt, &o, err);
  if (st != T74_OK && o.list && !strcmp(err->msg, "tube74: no scene given")) {
    err->status = T74_OK;
    err->msg[0] = '\0';
    st = T74_OK;
    j.scene = NULL;
  }
  if (st != T74_OK) { timing_free(&tm); return st; }
  if (o.list) {
    printf("beam timing (display/beam.c):\n");
    beam_params_list(&tm.bp, stdout);
    printf("look (display/look.c):\n");
    look_params_list(&tm.lp, stdout);
    if (!j.scene) { timing_free(&tm); return T74_OK; }
  }
  st = timing_prepare(&tm, &j, err);
  struct job_hooks h;
  timing_hooks(&tm, &j, &h);
  struct outset *set = NULL;    /* with --movie: the frames and the job's outputs, one set */
  struct outfile *first = NULL; /* frame 1 (or the GIF), opened before the job */
  if (st == T74_OK && o.movie && (st = outset_new(&set, err)) == T74_OK) {
    size_t base = movie_base(&o);
    char *name = malloc(base + 32);
    if (!name) st = t74_fail(err, T74_EIO, "out of host memory");
    else if (is_gif(o.movie)) {
      st = outset_open(set, o.movie, 0, &first, err);
      free(name);
    }
    else {
      frame_name(name, &o, base, 1);
      st = outset_open(set, name, 0, &first, err);
      free(name);
    }
    h.outs = set;
  }
  struct job_result res;
  if (st == T74_OK) st = job_run(&j, &h, &res, err);
  struct look *l = NULL;
  if (st == T74_OK) {
    /* the played face: the recorded dots, with the flash unless a look was named */
    unsigned flags = tm.look_given ? tm.look_flags : LOOK_FLASH;
    l = look_new(&tm.lp, flags);
    if (!l) st = t74_fail(err, T74_EIO, "out of host memory");
    for (size_t k = 0; st == T74_OK && k < look_count(tm.look); k++) {
      int x, y;
      double t;
      look_event(tm.look, k, &x, &y, &t);
      if (look_dot(l, x, y, t) != T74_OK) st = t74_fail(err, T74_EIO, "out of host memory");
    }
  }
  if (st == T74_OK)
    fprintf(stderr, "play: %zu dots; beam busy %.3f s; picture complete at %.3f s of 1974 time "
            "(computing %.3f s)\n", look_count(l), timing_tube_seconds(&tm),
            timing_total_seconds(&tm), res.hitac10_seconds);
  int scale = tm.scale_given ? tm.scale : 2;
  if (st == T74_OK && o.movie) {
    long n = 0;
    double dt = 0;
    st = write_movie(l, &o, scale, set, first, &n, &dt, err);
    if (st == T74_OK) st = outset_commit(set, err);
    size_t base = movie_base(&o);
    if (st == T74_OK && is_gif(o.movie))  /* told once every frame is in place */
      printf("play: wrote %s: %ld frames (%.3f s of 1974 time each)\n", o.movie, n, dt);
    else if (st == T74_OK)
      printf("play: wrote %ld frames %.*s-0001.png .. %.*s-%04ld.png (%.3f s of 1974 time "
             "each; PNG sequence: this libpng has no APNG)\n",
             n, (int)base, o.movie, (int)base, o.movie, n, dt);
  } else if (st == T74_OK) {
    st = run_window(l, tm.look, &o, scale, j.scene, err);
  }
  outset_free(set);             /* whatever was not committed is discarded */
  look_free(l);
  timing_free(&tm);
  return st;
}
