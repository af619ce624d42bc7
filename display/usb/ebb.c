/*
** ebb.c — the `ebb` USB profile: an EiBotBoard (AxiDraw, EggBot) pen plotter over its USB
** CDC bulk endpoints (display stage, paper 003 §4 dots drawn by a pen instead of a beam).
**
** This file contains code to draw the tube's dots with EBB commands. Hardware source:
** hardware-facts.md "EiBotBoard" (USB CDC, VID:PID 04D8:FD92; ASCII commands ending in CR,
** each answered OK CR LF; SP,0|1[,ms] pen; SM,ms,steps1,steps2 straight move; EM motor
** enable; 25 kHz step rate; about 1016 steps/inch; only a few motion commands queued) and
** the EBB command reference (evil-mad.github.io/EggBot/ebb.html: SP,1 moves the servo to
** its pen-UP position, SP,0 to pen-DOWN; SM steps are relative; AxiDraw's mixed axes drive
** motor 1 with X+Y and motor 2 with X-Y).
**
** What is sent (all commands end in CR):
**   open      EM,1,1                 motors on, 1/16 microstepping
**             SP,1                   pen up
**   a stroke  SM,<ms>,<a>,<b>        pen-up move to the stroke's first dot (if it moved)
**             SP,0,<lift_ms>         pen down: draws the first dot
**             SM,<ms>,<a>,<b>        (a run only) pen-down move along the row: the other dots
**             SP,1,<lift_ms>         pen up
**   close     SP,1 and a pen-up SM back to where the pen started
** Dot (x, y) is at X = ox + x*pitch, Y = oy + (299-y)*pitch steps from the start (the home
** corner, top left: the carriage's Y grows towards the user, the tube's upwards). With
** corexy = 1 the motors get a = dX + dY, b = dX - dY (AxiDraw); with 0, a = dX, b = dY.
** Move times: ceil(max(|a|,|b|) * 1000 / speed) ms, at least 1 (the board's unit).
**
** Flow: commands are queued in one buffer; when `queue` commands are waiting (the board's
** motion queue depth) they go out in one bulk transfer and every one of their OKs is read
** before more are sent — at most `queue` commands are ever in flight. Any reply line that
** is not "OK" (an "!8 Err" or noise) fails the run: the board's state is then unknown.
** ACKNOWLEDGED: a dot is acknowledged by the OK of the command that draws it (SP,0 for the
** first dot of a stroke, the pen-down SM for the rest).
** Strokes, bands and order: penplan.h, as for hpgl.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/usb/penplan.h"
#include "display/sink.h"
#include "display/usb/usb.h"

enum {                          /* rows of ebb_params, in order */
  EB_AREA_X, EB_AREA_Y, EB_AREA_W, EB_AREA_H, EB_SPMM, EB_V_UP, EB_V_DOWN, EB_LIFT, EB_RUNS,
  EB_BAND, EB_QUEUE, EB_COREXY, EB_NPARAMS
};

static const struct param_row ebb_params[EB_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "area_x_mm",      "mm",       10,   0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_y_mm",      "mm",       10,   0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_w_mm",      "mm",       277,  10, 2000,  0, "A4 landscape: 297 - 2 x 10" },
  { "area_h_mm",      "mm",       190,  10, 2000,  0, "A4 landscape: 210 - 2 x 10" },
  { "steps_per_mm",   "1/mm",     40,   1,  1000,  0, "hardware-facts.md: ~1016 steps/inch" },
  { "pen_up_speed",   "steps/s",  8000, 2,  25000, 0, "below the EBB's 25 kHz step rate; inferred" },
  { "pen_down_speed", "steps/s",  3000, 2,  25000, 0, "inferred: AxiDraw default drawing speed" },
  { "pen_lift_ms",    "ms",       150,  0,  65535, 0, "inferred: servo travel of one lift" },
  { "runs",           "",         1,    0,  1,     0, "1: strokes where penplan.h rule says faster" },
  { "band_rows",      "rows",     12,   1,  300,   0, "whole 3x3 and 4x4 cells (penplan.h)" },
  { "queue",          "commands", 3,    1,  64,    0, "hardware-facts.md: a few queued; inferred 3" },
  { "corexy",         "",         1,    0,  1,     0, "1: AxiDraw mixed axes, 0: EggBot native" },
};

#define EB_MAX_CMD 48           /* longest command: "SM,16777215,-99999999,-99999999\r" */

struct eb_cmd {                 /* a command waiting for its OK */
  char text[EB_MAX_CMD];
  int first, n;                 /* the dots its OK acknowledges, in pend[] */
};

struct ebb {
  struct usb_link *l;
  struct usb_ack ack;
  int ep_out, ep_in;
  struct pen_geom g;
  struct penplan plan;
  int queue, corexy;
  double v_up, v_down;          /* steps/s */
  int lift_ms;
  long X, Y;                    /* where the pen is, steps from the start */
  int pen_down;
  struct eb_cmd *cmd;           /* queued commands, sent or not */
  int ncmd;
  struct usb_point *pend;       /* their dots */
  int npend, cappend;
  char line[128];               /* reply line being read */
  int nline;
};

/* Send every queued command in one transfer, then read one OK per command. */
static int ebb_sync(struct ebb *e, struct t74_error *err)
{
  if (e->ncmd == 0) return T74_OK;
  char out[EB_MAX_CMD * 64];
  int n = 0;
  for (int k = 0; k < e->ncmd; k++) {
    int len = (int)strlen(e->cmd[k].text);
    memcpy(out + n, e->cmd[k].text, (size_t)len);
    n += len;
  }
  int done = 0;
  if (usb_transfer(e->l, USB_BULK, (unsigned char)e->ep_out, out, n, &done, err) != T74_OK)
    return err->status;
  for (int k = 0; k < e->ncmd;) {
    unsigned char in[64];
    int got = 0;
    if (usb_transfer(e->l, USB_BULK, (unsigned char)e->ep_in, in, sizeof in, &got, err) != T74_OK)
      return err->status;
    for (int b = 0; b < got && k < e->ncmd; b++) {
      unsigned char c = in[b];
      if (c == '\r' || c == '\n') {
        if (e->nline == 0) continue;            /* the other half of CR LF, blank lines */
        e->line[e->nline] = 0;
        if (strcmp(e->line, "OK") != 0) {
          char shown[64];
          size_t sl = strcspn(e->cmd[k].text, "\r");
          snprintf(shown, sizeof shown, "%.*s", (int)sl, e->cmd[k].text);
          return t74_fail(err, T74_EIO, "ebb: the board answered `%s` to `%s` instead of OK",
                          e->line, shown);
        }
        for (int d = 0; d < e->cmd[k].n; d++) e->ack.fn(e->ack.ctx, &e->pend[e->cmd[k].first + d]);
        k++;
        e->nline = 0;
      } else if (c < 0x20 || c > 0x7e || e->nline >= (int)sizeof e->line - 1) {
        return t74_fail(err, T74_EIO, "ebb: the board sent garbage (byte 0x%02x) instead of "
                        "OK to `%.*s`", c, (int)strcspn(e->cmd[k].text, "\r"), e->cmd[k].text);
      } else {
        e->line[e->nline++] = (char)c;
      }
    }
  }
  e->ncmd = 0;
  e->npend = 0;
  return T74_OK;
}

/* Queue one command (its OK acknowledges dots[0..n-1]); send when the queue is full. */
static int ebb_cmd(struct ebb *e, const char *text, const struct usb_point *dots, int n,
                   struct t74_error *err)
{
  struct eb_cmd *c = &e->cmd[e->ncmd];
  snprintf(c->text, sizeof c->text, "%s\r", text);
  c->first = e->npend;
  c->n = n;
  if (e->npend + n > e->cappend) {
    int cap = (e->npend + n) * 2;
    struct usb_point *p = realloc(e->pend, sizeof *p * (size_t)cap);
    if (!p) return t74_fail(err, T74_EIO, "ebb: out of memory");
    e->pend = p;
    e->cappend = cap;
  }
  if (n) memcpy(e->pend + e->npend, dots, sizeof *dots * (size_t)n);
  e->npend += n;
  e->ncmd++;
  return e->ncmd >= e->queue ? ebb_sync(e, err) : T74_OK;
}

/* A straight move to (X, Y) steps at speed v (steps/s); nothing when already there. */
static int ebb_move(struct ebb *e, long X, long Y, double v, const struct usb_point *dots,
                    int n, struct t74_error *err)
{
  long dx = X - e->X, dy = Y - e->Y;
  if (dx == 0 && dy == 0) return T74_OK;
  long a = e->corexy ? dx + dy : dx, b = e->corexy ? dx - dy : dy;
  long m = labs(a) > labs(b) ? labs(a) : labs(b);
  long ms = (long)((double)m * 1000.0 / v + 0.999999);
  if (ms < 1) ms = 1;
  char t[EB_MAX_CMD];
  snprintf(t, sizeof t, "SM,%ld,%ld,%ld", ms, a, b);
  e->X = X;
  e->Y = Y;
  return ebb_cmd(e, t, dots, n, err);
}

static long ebb_X(const struct ebb *e, int x) { return e->g.ox + (long)x * e->g.pitch; }
static long ebb_Y(const struct ebb *e, int y) { return e->g.oy + (long)(TUBE_H - 1 - y) * e->g.pitch; }

static int emit_band(struct ebb *e, struct t74_error *err)
{
  if (e->plan.nin == 0) return T74_OK;
  if (penplan_plan(&e->plan, err) != T74_OK) return err->status;
  char t[EB_MAX_CMD];
  for (int k = 0; k < e->plan.nst; k++) {
    const struct pen_stroke *s = &e->plan.st[k];
    const struct usb_point *d = &e->plan.pts[s->first];
    if (ebb_move(e, ebb_X(e, s->x0), ebb_Y(e, s->y), e->v_up, NULL, 0, err) != T74_OK)
      return err->status;
    snprintf(t, sizeof t, "SP,0,%d", e->lift_ms);
    e->pen_down = 1;
    if (ebb_cmd(e, t, d, 1, err) != T74_OK) return err->status;
    if (s->n > 1 &&
        ebb_move(e, ebb_X(e, s->x1), ebb_Y(e, s->y), e->v_down, d + 1, s->n - 1, err) != T74_OK)
      return err->status;
    snprintf(t, sizeof t, "SP,1,%d", e->lift_ms);
    e->pen_down = 0;
    if (ebb_cmd(e, t, NULL, 0, err) != T74_OK) return err->status;
  }
  return T74_OK;
}

static void ebb_free(struct ebb *e)
{
  penplan_free(&e->plan);
  free(e->cmd);
  free(e->pend);
  free(e);
}

static int ebb_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                    struct usb_ack ack, struct t74_error *err)
{
  struct ebb *e = calloc(1, sizeof *e);
  if (!e) return t74_fail(err, T74_EIO, "ebb: out of memory");
  e->l = l;
  e->ack = ack;
  e->ep_out = usb_link_endpoint(l, USB_BULK, 0);
  e->ep_in = usb_link_endpoint(l, USB_BULK, 1);
  double spmm = s->p[EB_SPMM];
  e->g = pen_geom_fit(s->p[EB_AREA_X] * spmm, s->p[EB_AREA_Y] * spmm, s->p[EB_AREA_W] * spmm,
                      s->p[EB_AREA_H] * spmm);
  e->v_up = s->p[EB_V_UP];
  e->v_down = s->p[EB_V_DOWN];
  e->lift_ms = (int)s->p[EB_LIFT];
  e->queue = (int)s->p[EB_QUEUE];
  e->corexy = s->p[EB_COREXY] != 0;
  int runs = s->p[EB_RUNS] != 0 &&
             penplan_rule(e->g.pitch / spmm, e->v_up / spmm, e->v_down / spmm, e->lift_ms);
  e->cmd = calloc((size_t)e->queue, sizeof *e->cmd);
  if (!e->cmd || penplan_init(&e->plan, (int)s->p[EB_BAND], runs, err) != T74_OK) {
    ebb_free(e);
    return t74_fail(err, T74_EIO, "ebb: out of memory");
  }
  if (e->ep_out < 0 || e->ep_in < 0) {
    ebb_free(e);
    return t74_fail(err, T74_EIO, "ebb: the CDC data interface lacks bulk endpoints");
  }
  if (ebb_cmd(e, "EM,1,1", NULL, 0, err) != T74_OK || ebb_cmd(e, "SP,1", NULL, 0, err) != T74_OK ||
      ebb_sync(e, err) != T74_OK) {
    ebb_free(e);
    return err->status;
  }
  *ctx = e;
  return T74_OK;
}

static int ebb_send(void *ctx, const struct usb_point *p, int n, struct t74_error *err)
{
  struct ebb *e = ctx;
  for (int k = 0; k < n; k++) {
    if (penplan_new_band(&e->plan, &p[k]) && emit_band(e, err) != T74_OK) return err->status;
    if (penplan_add(&e->plan, &p[k], err) != T74_OK) return err->status;
  }
  return T74_OK;
}

static int ebb_flush(void *ctx, struct t74_error *err)
{
  struct ebb *e = ctx;
  if (emit_band(e, err) != T74_OK) return err->status;
  return ebb_sync(e, err);
}

/* QM (query motors) would need its own reply format; the EBB has no paper sensor. */
static int ebb_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  (void)ctx;
  (void)err;
  memset(st, 0, sizeof *st);
  st->ready = 1;
  snprintf(st->text, sizeof st->text, "EBB: no status beyond OK replies");
  return T74_OK;
}

static void ebb_close(void *ctx, int clean)
{
  struct ebb *e = ctx;
  struct t74_error err = { T74_OK, "" };
  if (!usb_link_gone(e->l)) {
    /* whatever was queued and not sent is dropped; what was sent has been answered */
    e->ncmd = 0;
    e->npend = 0;
    e->nline = 0;
    if (ebb_cmd(e, "SP,1", NULL, 0, &err) == T74_OK &&
        (!clean || ebb_move(e, 0, 0, e->v_up, NULL, 0, &err) == T74_OK))
      ebb_sync(e, &err);
  }
  ebb_free(e);
}

const struct usb_profile usb_profile_ebb = {
  "ebb", "EiBotBoard (AxiDraw, EggBot) pen plotter, USB CDC",
  { 0x04D8, 0xFD92, 10, -1 },   /* hardware-facts.md; the CDC data interface (class 10) */
  ebb_params, EB_NPARAMS,
  ebb_open, ebb_send, ebb_flush, ebb_status, ebb_close
};
