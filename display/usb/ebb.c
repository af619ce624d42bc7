/*
** ebb.c — the `ebb` USB profile: an EiBotBoard (AxiDraw, EggBot) pen plotter over its USB
** CDC bulk endpoints (display stage, paper 003 §4 dots drawn by a pen instead of a beam).
**
** This file contains code to draw the tube's dots with EBB commands the way the AxiDraw
** software drives the board. Hardware sources (docs/usb.md lists them rule by rule):
**   the EBB command reference (evil-mad/EggBot docs/ebb.html): commands end in CR and are
**     answered OK CR LF (legacy mode); EM,1,1 enables both motors at 1/16 step (the reset
**     default); SM,ms,a,b moves at constant speed, at most 25,000 steps/s; SP,1,ms / SP,0,ms
**     move the servo to SC,4 (up) / SC,5 (down) and hold the NEXT motion command for ms;
**     SC,11 / SC,12 set the raise / lower rates, in pulse units (83.3 ns) per servo period
**     (8 channels x 3 ms = 24 ms; SC,8,1 makes it 3 ms); EM, SM and SP are "added to the
**     FIFO motion queue", SC and QM execute at once; with the boot FIFO of one command "there
**     can only be three motion commands in play": one executing, one in the FIFO, one stuck
**     in the USB parser, which then answers nothing until the FIFO has room; QM answers
**     QM,CommandStatus,Motor1,Motor2,FIFOStatus;
**   the EBB firmware (EBB_firmware/app.X/source/RCServo2.c): at reset the pen-up position
**     is 22565 and pen-down 15302, both rates 400: a full lower takes 7263 / 400 periods of
**     24 ms = 436 ms;
**   the AxiDraw software (evil-mad/axidraw, inkscape driver/axidraw_conf.py, pen_handling.py,
**     motion.py, axidraw.py): 16x microstepping gives step_scale = 2 x 1016 = 2032 steps per
**     inch of travel along X or Y on each motor (about 80 steps/mm), motor 1 = X + Y, motor
**     2 = X - Y; servo_min 9855 / servo_max 27831 (narrow-band servo: 5400 / 12600, output
**     pin RB2, SC,8,1), pen heights 60 % up / 30 % down, rates 75 % raise / 50 % lower,
**     SC,11/12 = range x period / sweep_time x rate (period 0.24, or 0.03 narrow-band;
**     sweep 200 ms or 70 ms); the wait after a pen move is the 4th-power blend of
**     slope x travel + min (2.69 ms/% + 45 ms; 1.28 + 20) and sweep x travel / rate;
**     speeds 25 % (pen down) and 75 % (pen up) of 8.6979 in/s / 1.1; accelerations 40 and
**     60 in/s^2 x 75 %; trapezoid (or triangle) speed profiles cut into 25 ms time slices,
**     cruise in pieces of at most 20 slices; at the end EM,0,0 (sendDisableMotors).
**
** What is sent (all commands end in CR):
**   open      SC,4 SC,5 SC,11 SC,12 [SC,8]   servo positions and rates, as the AxiDraw does
**             EM,1,1                         motors on, 1/16 microstepping
**             SP,1,<raise ms>                pen up, waiting its travel
**   a stroke  SM...                          ramped pen-up move to the stroke's first dot
**             SP,0,<lower ms>                pen down: draws the first dot
**             SM...                          (a run only) ramped pen-down move along the row
**             SP,1,<raise ms>                pen up
**   close     SP,1,<raise ms>, a ramped pen-up move home, EM,0,0 — after Ctrl-C, SIGTERM or
**             SIGHUP too; after a reply that was not OK the board's state is unknown: only
**             SP,1 and EM,0,0, no move
** Dot (x, y) is at X = ox + x*pitch, Y = oy + (299-y)*pitch steps from the start (the home
** corner, top left: the carriage's Y grows towards the user, the tube's upwards). With
** corexy = 1 the motors get a = dX + dY, b = dX - dY (AxiDraw); with 0, a = dX, b = dY.
**
** Flow and ACKNOWLEDGEMENT: commands are queued in one buffer; when `queue` commands wait
** they go out in one bulk transfer and their OKs are read (the wait allowed grows with the
** motion time ahead of them). OK means QUEUED, not drawn, so then QM is asked: with every
** command sent answered, CommandStatus 0 means all have run, FIFO 0 all but the last, else
** all but the last two (the one-command FIFO). A dot is acknowledged when the command that
** draws it (SP,0 for a stroke's first dot, the pen-down SM that passes it for the rest) is
** known to have run, so that a reset or an unplug loses nothing the resume file claims.
** flush() polls QM until the board is idle. Any reply line that is not "OK" (an "!8 Err" or
** noise) fails the run.
** Strokes, bands and order: penplan.h, as for hpgl.
** A FILE (--to, --dry-run) gets the same commands and no QM: nothing answers, so every
** command counts as run once written. Over --serial (the board's own /dev/ttyACM0, cdc_acm
** bound) the same commands and replies go over the tty (not tested against an emulator).
** TIME MODEL (the estimate, usb_tally): the board runs its motion commands one after the
** other, so the time is the sum of what they ask: each SM's duration and each SP's wait
** (the ramps and servo waits above) — the figure the emulated board's motion clock gives.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/sink.h"
#include "display/usb/penplan.h"
#include "display/usb/preview.h"
#include "display/usb/usb.h"

enum {                          /* rows of ebb_params, in order */
  EB_AREA_X, EB_AREA_Y, EB_AREA_W, EB_AREA_H, EB_SPMM, EB_MICRO, EB_V_UP, EB_V_DOWN, EB_A_UP,
  EB_A_DOWN, EB_SLICE, EB_POS_UP, EB_POS_DOWN, EB_RATE_UP, EB_RATE_DOWN, EB_DELAY_UP,
  EB_DELAY_DOWN, EB_NARROW, EB_RUNS, EB_BAND, EB_QUEUE, EB_COREXY, EB_POLL, EB_NPARAMS
};

static const struct param_row ebb_params[EB_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "area_x_mm",      "mm",     10,    0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_y_mm",      "mm",     10,    0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_w_mm",      "mm",     277,   10, 2000,  0, "A4 landscape: 297 - 2 x 10" },
  { "area_h_mm",      "mm",     190,   10, 2000,  0, "A4 landscape: 210 - 2 x 10" },
  { "steps_per_mm",   "1/mm",   80,    1,  1000,  0, "AxiDraw: 2032 steps/inch at 16x (EM,1)" },
  { "microstep",      "EM",     1,     1,  5,     1, "EBB EM: 1 = 1/16 .. 5 = full step" },
  { "pen_up_speed",   "mm/s",   150.6, 1,  500,   0, "AxiDraw: 75 % of 8.6979 in/s / 1.1" },
  { "pen_down_speed", "mm/s",   50.2,  1,  500,   0, "AxiDraw: 25 % of 8.6979 in/s / 1.1" },
  { "accel_up",       "mm/s2",  1143,  10, 20000, 0, "AxiDraw: 60 in/s^2 x 75 %" },
  { "accel_down",     "mm/s2",  762,   10, 20000, 0, "AxiDraw: 40 in/s^2 x 75 %" },
  { "time_slice_ms",  "ms",     25,    5,  200,   0, "AxiDraw time_slice 0.025 s" },
  { "pen_pos_up",     "%",      60,    0,  100,   0, "AxiDraw pen_pos_up" },
  { "pen_pos_down",   "%",      30,    0,  100,   0, "AxiDraw pen_pos_down" },
  { "pen_rate_raise", "%",      75,    1,  100,   0, "AxiDraw pen_rate_raise" },
  { "pen_rate_lower", "%",      50,    1,  100,   0, "AxiDraw pen_rate_lower" },
  { "pen_delay_up",   "ms",     0,     0,  5000,  0, "AxiDraw pen_delay_up (extra wait)" },
  { "pen_delay_down", "ms",     0,     0,  5000,  0, "AxiDraw pen_delay_down (extra wait)" },
  { "narrow_band",    "",       0,     0,  1,     1, "1: AxiDraw penlift 3 brushless servo" },
  { "runs",           "",       1,     0,  1,     1, "1: strokes where penplan.h rule says faster" },
  { "band_rows",      "rows",   12,    1,  300,   1, "whole 3x3 and 4x4 cells (penplan.h)" },
  { "queue",          "commands", 3,   1,  64,    1, "EBB: three motion commands in play (FIFO 1)" },
  { "corexy",         "",       1,     0,  1,     1, "1: AxiDraw mixed axes, 0: EggBot native" },
  { "poll_ms",        "ms",     10,    1,  1000,  0, "pause between QM polls; inferred" },
};

#define EB_MAX_CMD   48         /* a command's text and its NUL (the longest is
                                   "SM,16777215,-99999999,-99999999", 31 characters) */
#define EB_STEP_RATE 25000.0    /* EBB: at most 25,000 steps/s */
#define EB_MAX_SM    64         /* SM pieces of one ramped move */
#define EB_QM_EVERY  24         /* ask QM once this many answered commands wait to be known
                                   as run (acknowledging late is safe, early is not) */

struct eb_cmd {                 /* a command sent or waiting to be */
  char text[EB_MAX_CMD + 1];    /* the command and its "\r" */
  int queued;                   /* goes through the motion FIFO (EM, SP, SM) */
  double ms;                    /* its motion time */
  int first, n;                 /* the dots it draws, in pend[] */
};

struct ebb {
  struct usb_link *l;
  struct usb_ack ack;
  int ep_out, ep_in;
  struct pen_geom g;
  struct penplan plan;
  int queue, corexy, poll_ms;
  double spmm;                  /* steps per mm */
  double v_up, v_down, a_up, a_down;    /* steps/s, steps/s^2 */
  double slice;                 /* s */
  int raise_ms, lower_ms;       /* SP durations */
  int pin;                      /* servo output pin (0: the default RB1) */
  long X, Y;                    /* where the pen is, steps from the start */
  int unknown;                  /* a reply was not OK: the board's state is unknown */
  struct eb_cmd *cmd;           /* commands not yet known to have run, oldest first:
                                   cmd[0 .. nsent-1] sent and answered, the rest waiting */
  int ncmd, nsent, capcmd;
  struct usb_point *pend;       /* their dots */
  int npend, cappend;
  char line[128];               /* reply line being read */
  int nline;
  unsigned char in[64];         /* reply bytes read, in[ipos .. nin-1] not yet used */
  int ipos, nin;
  int offline;                  /* a file link: nothing answers, all written counts as run */
  struct usb_tally *t;
  struct preview *pv;
};

/* ---- servo: positions, rates and waits, as the AxiDraw software sets them ------------- */

struct eb_servo {
  int up, down, rate_up, rate_down, raise_ms, lower_ms, pin, channels;
  int first_raise_ms;           /* the first SP,1: from the firmware's reset position */
};

#define EB_RESET_UP 22565       /* EBB firmware RCServo2.c: pen-up position at reset */

static struct eb_servo servo_setup(const struct usb_settings *s)
{
  struct eb_servo v;
  int nb = s->p[EB_NARROW] != 0;
  double smin = nb ? 5400 : 9855, smax = nb ? 12600 : 27831;     /* 83.3 ns units */
  double sweep = nb ? 70 : 200, period = nb ? 0.03 : 0.24;       /* ms; ms/100 */
  double mmin = nb ? 20 : 45, slope = nb ? 1.28 : 2.69;          /* ms, ms per % */
  double slope_u = (smax - smin) / 100.0;
  v.up = (int)lround(smin + slope_u * s->p[EB_POS_UP]);
  v.down = (int)lround(smin + slope_u * s->p[EB_POS_DOWN]);
  double scale = (smax - smin) * period / sweep;
  v.rate_up = (int)lround(scale * s->p[EB_RATE_UP]);
  v.rate_down = (int)lround(scale * s->p[EB_RATE_DOWN]);
  if (v.rate_up < 1) v.rate_up = 1;
  if (v.rate_down < 1) v.rate_down = 1;
  double d = fabs(s->p[EB_POS_UP] - s->p[EB_POS_DOWN]);
  double a = slope * d + mmin;
  double up = d < 0.9 ? 0 : floor(pow(pow(a, 4) + pow(sweep * d / s->p[EB_RATE_UP], 4), 0.25));
  double dn = d < 0.9 ? 0 : floor(pow(pow(a, 4) + pow(sweep * d / s->p[EB_RATE_DOWN], 4), 0.25));
  v.raise_ms = (int)(up + s->p[EB_DELAY_UP]);
  v.lower_ms = (int)(dn + s->p[EB_DELAY_DOWN]);
  if (v.raise_ms < 1) v.raise_ms = 1;           /* SP's Duration is 1..65535 */
  if (v.lower_ms < 1) v.lower_ms = 1;
  v.pin = nb ? 2 : 0;
  v.channels = nb ? 1 : 8;
  /* at reset the servo sits at the firmware's own pen-up position: the first raise travels
     from there at the configured rate (periods of channels x 3 ms), then settles */
  double periods = ceil(fabs((double)EB_RESET_UP - v.up) / v.rate_up);
  double first = periods * 3.0 * v.channels + mmin;
  v.first_raise_ms = first > v.raise_ms ? (int)first : v.raise_ms;
  return v;
}

/* ---- commands, replies and the motion queue ----------------------------------------- */

/* Read one reply line into e->line (CR and LF end it, blank lines skipped) within
** timeout_ms; bytes after it stay in e->in for the next call. */
static int read_line(struct ebb *e, double timeout_ms, const char *to, struct t74_error *err)
{
  double t_end = usb_now() + timeout_ms / 1000.0;
  for (;;) {
    while (e->ipos < e->nin) {
      unsigned char c = e->in[e->ipos++];
      if (c == '\r' || c == '\n') {
        if (e->nline == 0) continue;            /* the other half of CR LF, blank lines */
        e->line[e->nline] = 0;
        e->nline = 0;
        return T74_OK;
      }
      if (c < 0x20 || c > 0x7e || e->nline >= (int)sizeof e->line - 1) {
        e->unknown = 1;
        return t74_fail(err, T74_EIO, "ebb: the board sent garbage (byte 0x%02x) instead of "
                        "a reply to `%s`", c, to);
      }
      e->line[e->nline++] = (char)c;
    }
    double left = (t_end - usb_now()) * 1000.0;
    if (left <= 0)
      return t74_fail(err, T74_EIO, "ebb: the board did not answer `%s` within %.0f ms", to,
                      timeout_ms);
    e->ipos = e->nin = 0;
    if (usb_read_once(e->l, USB_BULK, (unsigned char)e->ep_in, e->in, sizeof e->in,
                      left < 1 ? 1 : (int)left, &e->nin, err) != T74_OK)
      return err->status;
  }
}

/* The command's text without its CR, for messages. */
static const char *shown(const struct eb_cmd *c, char *buf, size_t n)
{
  snprintf(buf, n, "%.*s", (int)strcspn(c->text, "\r"), c->text);
  return buf;
}

/* Motion time of cmd[from ..] (what the board must run before it answers the last). */
static double ms_from(const struct ebb *e, int from)
{
  double ms = 0;
  for (int k = from; k < e->ncmd; k++) ms += e->cmd[k].ms;
  return ms;
}

/* Acknowledge the dots of the first n commands (they have run) and forget them. */
static void ran(struct ebb *e, int n)
{
  if (n <= 0) return;
  for (int k = 0; k < n; k++)
    for (int d = 0; d < e->cmd[k].n; d++) e->ack.fn(e->ack.ctx, &e->pend[e->cmd[k].first + d]);
  int shift = n < e->ncmd ? e->cmd[n].first : e->npend;
  if (e->npend > shift) memmove(e->pend, e->pend + shift, sizeof *e->pend * (size_t)(e->npend - shift));
  e->npend -= shift;
  if (e->ncmd > n) memmove(e->cmd, e->cmd + n, sizeof *e->cmd * (size_t)(e->ncmd - n));
  e->ncmd -= n;
  e->nsent -= n;
  for (int k = 0; k < e->ncmd; k++) e->cmd[k].first -= shift;
}

/* Ask QM; *busy = CommandStatus, *fifo = FIFOStatus. */
static int query_motion(struct ebb *e, int *busy, int *fifo, struct t74_error *err)
{
  static const char q[] = "QM\r";
  if (usb_transfer(e->l, USB_BULK, (unsigned char)e->ep_out, (void *)q, 3, NULL, err) != T74_OK)
    return err->status;
  if (read_line(e, usb_link_timeout_ms(e->l), "QM", err) != T74_OK) return err->status;
  int c, m1, m2, f;
  if (sscanf(e->line, "QM,%d,%d,%d,%d", &c, &m1, &m2, &f) != 4) {
    e->unknown = 1;
    return t74_fail(err, T74_EIO, "ebb: the board answered `%s` to QM", e->line);
  }
  *busy = c != 0;
  *fifo = f != 0;
  return T74_OK;
}

/* Every command sent is answered: learn from QM which have run (see the file's head). */
static int learn_ran(struct ebb *e, struct t74_error *err)
{
  int nq = 0;
  for (int k = 0; k < e->nsent; k++) nq += e->cmd[k].queued;
  if (nq == 0) { ran(e, e->nsent); return T74_OK; }
  int busy, fifo;
  if (query_motion(e, &busy, &fifo, err) != T74_OK) return err->status;
  int keep = !busy ? 0 : fifo ? 2 : 1;          /* queued commands still in the board */
  int n = e->nsent;
  for (int k = e->nsent - 1; k >= 0 && keep > 0; k--) {
    n = k;
    keep -= e->cmd[k].queued;
  }
  ran(e, n);
  return T74_OK;
}

/* Send every waiting command in one transfer, read one OK each, then ask what has run. */
static int ebb_sync(struct ebb *e, struct t74_error *err)
{
  if (e->nsent == e->ncmd) return T74_OK;
  char out[EB_MAX_CMD * 64];
  int n = 0;
  for (int k = e->nsent; k < e->ncmd; k++) {
    int len = (int)strlen(e->cmd[k].text);
    memcpy(out + n, e->cmd[k].text, (size_t)len);
    n += len;
  }
  if (usb_transfer(e->l, USB_BULK, (unsigned char)e->ep_out, out, n, NULL, err) != T74_OK)
    return err->status;
  if (e->offline) {             /* a file: written is all there is */
    e->nsent = e->ncmd;
    ran(e, e->nsent);
    return T74_OK;
  }
  double link_ms = usb_link_timeout_ms(e->l);
  while (e->nsent < e->ncmd) {
    struct eb_cmd *c = &e->cmd[e->nsent];
    char what[EB_MAX_CMD];
    /* the parser answers a queued command once the FIFO has room: after everything before
       it has run, at worst */
    if (read_line(e, link_ms + ms_from(e, 0), shown(c, what, sizeof what), err) != T74_OK)
      return err->status;
    if (strcmp(e->line, "OK") != 0) {
      e->unknown = 1;
      return t74_fail(err, T74_EIO, "ebb: the board answered `%s` to `%s` instead of OK",
                      e->line, what);
    }
    e->nsent++;
  }
  return e->nsent >= EB_QM_EVERY ? learn_ran(e, err) : T74_OK;
}

/* Wait until the board has run everything it was sent (QM idle). */
static int ebb_drain(struct ebb *e, struct t74_error *err)
{
  if (ebb_sync(e, err) != T74_OK) return err->status;
  if (e->offline) return T74_OK;
  double t_end = usb_now() + (usb_link_timeout_ms(e->l) + ms_from(e, 0)) / 1000.0;
  while (e->ncmd > 0) {
    if (learn_ran(e, err) != T74_OK) return err->status;
    if (e->ncmd == 0) break;
    if (usb_now() > t_end)
      return t74_fail(err, T74_EIO, "ebb: the board is still moving long after its commands "
                      "should have run");
    if (usb_link_stopped(e->l))                 /* close() takes over; the rest is resumable */
      return t74_fail(err, T74_EIO, "ebb: stopped while the board was still drawing");
    usb_sleep_ms(e->poll_ms);
  }
  return T74_OK;
}

/* Queue one command (drawing dots[0..n-1]); send when `queue` wait. */
static int ebb_cmd(struct ebb *e, const char *text, int queued, double ms,
                   const struct usb_point *dots, int n, struct t74_error *err)
{
  if (e->ncmd == e->capcmd) {
    int cap = e->capcmd ? e->capcmd * 2 : 64;
    struct eb_cmd *c = realloc(e->cmd, sizeof *c * (size_t)cap);
    if (!c) return t74_fail(err, T74_EIO, "ebb: out of memory");
    e->cmd = c;
    e->capcmd = cap;
  }
  if (e->npend + n > e->cappend) {
    int cap = (e->npend + n) * 2 + 64;
    struct usb_point *p = realloc(e->pend, sizeof *p * (size_t)cap);
    if (!p) return t74_fail(err, T74_EIO, "ebb: out of memory");
    e->pend = p;
    e->cappend = cap;
  }
  struct eb_cmd *c = &e->cmd[e->ncmd++];
  snprintf(c->text, sizeof c->text, "%s\r", text);
  e->t->commands++;
  if (queued) e->t->device_s += ms / 1000.0;
  c->queued = queued;
  c->ms = ms;
  c->first = e->npend;
  c->n = n;
  if (n) memcpy(e->pend + e->npend, dots, sizeof *dots * (size_t)n);
  e->npend += n;
  return e->ncmd - e->nsent >= e->queue ? ebb_sync(e, err) : T74_OK;
}

static int pen(struct ebb *e, int up, const struct usb_point *dot, struct t74_error *err)
{
  char t[EB_MAX_CMD];
  int ms = up ? e->raise_ms : e->lower_ms;
  if (e->pin) snprintf(t, sizeof t, "SP,%d,%d,%d", up, ms, e->pin);
  else snprintf(t, sizeof t, "SP,%d,%d", up, ms);
  preview_pen(e->pv, !up);
  return ebb_cmd(e, t, 1, ms, dot, dot ? 1 : 0, err);
}

/* ---- ramped moves --------------------------------------------------------------------- */

/* Distance along a move of length D (steps) at time t of a trapezoid (or triangle) profile
** with top speed v and acceleration a, from rest to rest; T is its whole time. */
static double ramp_s(double t, double D, double v, double a, double *T)
{
  double ta = v / a, da = 0.5 * a * ta * ta;
  if (2 * da > D) {                             /* triangle */
    ta = sqrt(D / a);
    da = D / 2;
    v = a * ta;
  }
  double tc = (D - 2 * da) / v;
  *T = 2 * ta + tc;
  if (t <= 0) return 0;
  if (t < ta) return 0.5 * a * t * t;
  if (t < ta + tc) return da + v * (t - ta);
  if (t < *T) { double r = *T - t; return D - 0.5 * a * r * r; }
  return D;
}

/* A straight move to (X, Y) steps, ramped as the AxiDraw software does: time slices through
** the acceleration and deceleration, cruise in pieces of at most 20 slices, each piece one
** SM at constant speed. Pen-down moves along a row carry the dots each piece passes. */
static int ebb_move(struct ebb *e, long X, long Y, int down, const struct usb_point *dots,
                    int n, struct t74_error *err)
{
  long dx = X - e->X, dy = Y - e->Y;
  if (dx == 0 && dy == 0) return T74_OK;
  double D = sqrt((double)dx * dx + (double)dy * dy);
  double v = down ? e->v_down : e->v_up, a = down ? e->a_down : e->a_up, T;
  if (down) e->t->down_mm += D / e->spmm;
  else {
    e->t->up_mm += D / e->spmm;
    e->t->pen_moves++;
  }
  ramp_s(0, D, v, a, &T);
  double ta = fmin(v / a, sqrt(D / a)), tc = T - 2 * ta;
  /* piece boundaries in time */
  double tb[EB_MAX_SM + 1];
  int nb = 0;
  int na = (int)ceil(ta / e->slice - 1e-9);
  if (na < 1) na = 1;
  int nc = tc > 1e-9 ? (int)ceil(tc / (20 * e->slice) - 1e-9) : 0;
  if (nc > EB_MAX_SM / 2) nc = EB_MAX_SM / 2;   /* a very long cruise: longer pieces */
  if (2 * na + nc > EB_MAX_SM) na = (EB_MAX_SM - nc) / 2;   /* >= 16: coarser slices */
  tb[nb++] = 0;
  for (int k = 1; k <= na; k++) tb[nb++] = ta * k / na;
  for (int k = 1; k <= nc; k++) tb[nb++] = ta + tc * k / nc;
  for (int k = 1; k <= na; k++) tb[nb++] = ta + tc + ta * k / na;
  tb[nb - 1] = T;
  long x0 = e->X, y0 = e->Y, px = e->X, py = e->Y;
  long ms_prev = 0;
  int d0 = 0;                                   /* next dot to carry */
  for (int k = 1; k < nb; k++) {
    double s = k == nb - 1 ? D : ramp_s(tb[k], D, v, a, &T);
    long qx = k == nb - 1 ? X : x0 + lround(dx * s / D);
    long qy = k == nb - 1 ? Y : y0 + lround(dy * s / D);
    long ms = lround(tb[k] * 1000.0) - ms_prev;
    long sx = qx - px, sy = qy - py;
    long ma = e->corexy ? sx + sy : sx, mb = e->corexy ? sx - sy : sy;
    long most = labs(ma) > labs(mb) ? labs(ma) : labs(mb);
    if (most == 0) continue;                    /* nothing moves in this piece: join the next */
    if (ms < 1) ms = 1;
    long ms_rate = (long)ceil(most * 1000.0 / EB_STEP_RATE);
    if (ms < ms_rate) ms = ms_rate;             /* never above the board's step rate */
    ms_prev += ms;
    int nd = 0;                                 /* the dots this piece reaches */
    if (dots)
      while (d0 + nd < n) {
        long at = e->g.ox + (long)dots[d0 + nd].x * e->g.pitch;
        if ((sx > 0 && at > qx) || (sx < 0 && at < qx)) break;
        nd++;
      }
    char t[EB_MAX_CMD];
    snprintf(t, sizeof t, "SM,%ld,%ld,%ld", ms, ma, mb);
    px = qx;
    py = qy;
    e->X = qx;
    e->Y = qy;
    preview_to(e->pv, (double)qx, (double)qy);
    if (ebb_cmd(e, t, 1, (double)ms, dots ? dots + d0 : NULL, nd, err) != T74_OK) return err->status;
    d0 += nd;
  }
  return T74_OK;
}

static long ebb_X(const struct ebb *e, int x) { return e->g.ox + (long)x * e->g.pitch; }
static long ebb_Y(const struct ebb *e, int y) { return e->g.oy + (long)(TUBE_H - 1 - y) * e->g.pitch; }

static int emit_band(struct ebb *e, struct t74_error *err)
{
  if (e->plan.nin == 0) return T74_OK;
  if (penplan_plan(&e->plan, err) != T74_OK) return err->status;
  for (int k = 0; k < e->plan.nst; k++) {
    const struct pen_stroke *s = &e->plan.st[k];
    const struct usb_point *d = &e->plan.pts[s->first];
    e->t->strokes++;
    if (ebb_move(e, ebb_X(e, s->x0), ebb_Y(e, s->y), 0, NULL, 0, err) != T74_OK ||
        pen(e, 0, d, err) != T74_OK)
      return err->status;
    if (s->n > 1 && ebb_move(e, ebb_X(e, s->x1), ebb_Y(e, s->y), 1, d + 1, s->n - 1, err) != T74_OK)
      return err->status;
    if (pen(e, 1, NULL, err) != T74_OK) return err->status;
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
  e->offline = usb_link_kind(l) == USB_LINK_FILE;
  e->t = usb_link_tally(l);
  e->pv = usb_link_preview(l);
  e->ep_out = usb_link_endpoint(l, USB_BULK, 0);
  e->ep_in = usb_link_endpoint(l, USB_BULK, 1);
  e->spmm = s->p[EB_SPMM];
  e->g = pen_geom_fit(s->p[EB_AREA_X] * e->spmm, s->p[EB_AREA_Y] * e->spmm,
                      s->p[EB_AREA_W] * e->spmm, s->p[EB_AREA_H] * e->spmm);
  e->v_up = s->p[EB_V_UP] * e->spmm;
  e->v_down = s->p[EB_V_DOWN] * e->spmm;
  e->a_up = s->p[EB_A_UP] * e->spmm;
  e->a_down = s->p[EB_A_DOWN] * e->spmm;
  e->slice = s->p[EB_SLICE] / 1000.0;
  e->queue = (int)s->p[EB_QUEUE];
  e->corexy = s->p[EB_COREXY] != 0;
  e->poll_ms = (int)s->p[EB_POLL];
  struct eb_servo sv = servo_setup(s);
  e->raise_ms = sv.raise_ms;
  e->lower_ms = sv.lower_ms;
  e->pin = sv.pin;
  int runs = s->p[EB_RUNS] != 0 &&
             penplan_rule(e->g.pitch / e->spmm, s->p[EB_V_UP], s->p[EB_V_DOWN],
                          0.5 * (e->raise_ms + e->lower_ms));
  if (penplan_init(&e->plan, (int)s->p[EB_BAND], runs, err) != T74_OK) {
    ebb_free(e);
    return t74_fail(err, T74_EIO, "ebb: out of memory");
  }
  if (e->ep_out < 0 || (e->ep_in < 0 && !e->offline)) {
    ebb_free(e);
    return t74_fail(err, T74_EIO, "ebb: the CDC data interface lacks bulk endpoints");
  }
  preview_area(e->pv, 0, 0, (s->p[EB_AREA_X] + s->p[EB_AREA_W]) * e->spmm,
               (s->p[EB_AREA_Y] + s->p[EB_AREA_H]) * e->spmm, 0, e->spmm,
               "EiBotBoard plotter, steps from the home corner (top left)");
  preview_at(e->pv, 0, 0);
  char t[5][EB_MAX_CMD];
  snprintf(t[0], sizeof t[0], "SC,4,%d", sv.up);
  snprintf(t[1], sizeof t[1], "SC,5,%d", sv.down);
  snprintf(t[2], sizeof t[2], "SC,11,%d", sv.rate_up);
  snprintf(t[3], sizeof t[3], "SC,12,%d", sv.rate_down);
  snprintf(t[4], sizeof t[4], "SC,8,%d", sv.channels);
  char em[EB_MAX_CMD];
  snprintf(em, sizeof em, "EM,%d,%d", (int)s->p[EB_MICRO], (int)s->p[EB_MICRO]);
  int st = T74_OK;
  for (int k = 0; k < 5 && st == T74_OK; k++) st = ebb_cmd(e, t[k], 0, 0, NULL, 0, err);
  if (st == T74_OK) st = ebb_cmd(e, em, 1, 0, NULL, 0, err);
  if (st == T74_OK) {
    e->raise_ms = sv.first_raise_ms;
    st = pen(e, 1, NULL, err);
    e->raise_ms = sv.raise_ms;
  }
  if (st == T74_OK) st = ebb_drain(e, err);
  if (st != T74_OK) {
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
  return ebb_drain(e, err);
}

static int ebb_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  struct ebb *e = ctx;
  memset(st, 0, sizeof *st);
  int busy = 0, fifo = 0;
  if (!e->offline && query_motion(e, &busy, &fifo, err) != T74_OK) return err->status;
  st->ready = 1;                /* the EBB has no paper sensor */
  snprintf(st->text, sizeof st->text, "EBB: %s%s", busy ? "moving" : "idle",
           fifo ? ", a command waits in the FIFO" : "");
  return T74_OK;
}

/* Leave the board safe: pen up (waiting its travel), home, motors off. */
static void ebb_close(void *ctx, int clean)
{
  struct ebb *e = ctx;
  struct t74_error err = { T74_OK, "" };
  (void)clean;
  if (!usb_link_gone(e->l)) {
    /* commands not yet sent are dropped; those sent run on the board before these */
    e->ncmd = e->nsent;
    e->npend = e->ncmd ? e->cmd[e->ncmd - 1].first + e->cmd[e->ncmd - 1].n : 0;
    int home = !e->unknown && e->nline == 0;
    e->nline = 0;
    if (!home) {                /* after a reply that was not OK: nothing more is read */
      e->nsent = e->ncmd = 0;
      e->npend = 0;
    }
    int q = e->queue;
    e->queue = 64;              /* one transfer */
    if (pen(e, 1, NULL, &err) == T74_OK && (!home || ebb_move(e, 0, 0, 0, NULL, 0, &err) == T74_OK) &&
        ebb_cmd(e, "EM,0,0", 1, 0, NULL, 0, &err) == T74_OK) {
      if (home) {
        e->queue = q;
        ebb_drain(e, &err);     /* acknowledges what ran before the stop */
      } else {
        char out[EB_MAX_CMD * 4];
        int n = 0;
        for (int k = 0; k < e->ncmd; k++) n += snprintf(out + n, sizeof out - (size_t)n, "%s", e->cmd[k].text);
        usb_transfer(e->l, USB_BULK, (unsigned char)e->ep_out, out, n, NULL, &err);
      }
    }
  }
  ebb_free(e);
}

const struct usb_profile usb_profile_ebb = {
  "ebb", "EiBotBoard (AxiDraw, EggBot) pen plotter, USB CDC",
  { 0x04D8, 0xFD92, 10, -1 },   /* docs/hardware.md; the CDC data interface (class 10) */
  ebb_params, EB_NPARAMS,
  ebb_open, ebb_send, ebb_flush, ebb_status, ebb_close, NULL,
  USB_LINKS(USB_LINK_USB) | USB_LINKS(USB_LINK_SERIAL) | USB_LINKS(USB_LINK_FILE), "EBB commands"
};
