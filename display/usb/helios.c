/*
** helios.c — the `helios` USB profile: a Helios laser / XY DAC showing the tube's dots as
** a refreshed vector picture (display stage, paper 003 §4; a display that does not store).
**
** This file contains code to turn dots into Helios frames. Hardware source:
** hardware-facts.md "Helios laser DAC" (VID 0x1209 PID 0xE500, interface 0 alt 1; bulk OUT
** 0x02, interrupt OUT 0x06, interrupt IN 0x83; a point is 7 bytes: x>>4, (x&15)<<4 | y>>8,
** y&255, r, g, b, i with 12-bit x, y; a frame is its points then pps (16-bit LE), point
** count (16-bit LE), flags; at most 4095 points; 7..65535 points/s; status: send 0x03 on
** the interrupt OUT endpoint, the reply 0x83 has byte 1 = 1 when the DAC can take a frame;
** 0x01 stop; 0x04 firmware version -> 0x84) and the open Helios SDK (Grix/helios_dac,
** sdk/cpp/HeliosDac.cpp: the DAC is double-buffered; status is polled before each frame;
** frames of n points with (n - 45) % 64 == 0 are not received correctly by the DAC's MCU;
** 0x02 sets the shutter; flags bit 1 = play once).
**
** What is sent, per dot: a BLANKED move (r = g = b = i = 0) to it when it is not a
** neighbour of the previous dot (more than one dot away in x or y) — one blanked point per
** blank_step dots of distance, the last exactly on the dot, so the mirrors settle dark —
** then `dwell` lit points on it (green: the tube's P1 phosphor). Tube dot (x, y) is DAC point
** (48 + 10x, 548 + 10y): 10 DAC units a dot keeps the 4:3 picture square-pixelled and
** centred in the 12-bit field.
** Frames: points are packed into frames of at most frame_points; a dot's points never
** straddle two frames. Double-buffering with asynchronous transfers: while one frame is on
** the wire the next is filled (rendering goes on); before a frame is sent the previous
** transfer is waited for and the status polled until the DAC is ready.
** ACKNOWLEDGED: a dot is acknowledged when the bulk transfer of its frame has completed
** (the DAC took the whole frame). --repeat passes are the stream's (usb_stream.c): each pass
** sends every dot again, as a refresh.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/usb/usb.h"

enum { HE_PPS, HE_FRAME, HE_BLANK_STEP, HE_DWELL, HE_INTENSITY, HE_STATUS_MS, HE_POLL_MS,
       HE_NPARAMS };

static const struct param_row helios_params[HE_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "pps",               "points/s", 30000, 7,  65535,  0, "hardware-facts.md: 7..65535 points/s" },
  { "frame_points",      "points",   1000,  64, 4094,   0, "hardware-facts.md: at most 4095 "
                                                          "(one kept for the SDK's size quirk)" },
  { "blank_step",        "dots",     40,    1,  400,    0, "inferred: one blanked point per 40 dots moved" },
  { "dwell",             "points",   1,     1,  16,     0, "lit points per dot; inferred" },
  { "intensity",         "",         255,   1,  255,    0, "green and intensity of a lit point" },
  { "status_timeout_ms", "ms",       5000,  10, 600000, 0, "inferred: a frame lasts at most 4095/7 s" },
  { "poll_ms",           "ms",       1,     0,  1000,   0, "pause between status polls; inferred" },
};

#define HE_POINT_BYTES 7        /* x>>4, x&15<<4|y>>8, y&255, r, g, b, i */
#define HE_TRAILER     5        /* pps lo, pps hi, count lo, count hi, flags */
#define HE_DOT_UNITS   10       /* DAC units per tube dot */
#define HE_X0          48       /* (4096 - 400*10) / 2 */
#define HE_Y0          548      /* (4096 - 300*10) / 2 */
#define HE_CMD_STOP    0x01
#define HE_CMD_SHUTTER 0x02
#define HE_CMD_STATUS  0x03
#define HE_CMD_VERSION 0x04
#define HE_MAX_BLANKS  16       /* blanked points of the longest move (500 dots / blank_step >= 1
                                   capped: the move is then split into at most 16 steps) */

struct he_frame {
  unsigned char *buf;           /* points, then room for the trailer */
  int npts;
  struct usb_point *dots;       /* dots lit in this frame, acknowledged with it */
  int ndots;
};

struct helios {
  struct usb_link *l;
  struct usb_ack ack;
  int ep_bulk, ep_iout, ep_iin;
  int pps, frame_points, blank_step, dwell, intensity, status_ms, poll_ms;
  struct he_frame f[2];
  int cur;                      /* frame being filled */
  int inflight;                 /* frame on the wire, or -1 */
  struct usb_xfer x;
  int have_pos;                 /* a dot was drawn: lx, ly valid */
  int lx, ly;                   /* last dot, tube coordinates */
  double frame_seconds;         /* duration of the last frame sent */
};

static void put_point(struct he_frame *f, int X, int Y, int g, int i)
{
  unsigned char *b = f->buf + (size_t)f->npts * HE_POINT_BYTES;
  b[0] = (unsigned char)(X >> 4);
  b[1] = (unsigned char)(((X & 0x0F) << 4) | (Y >> 8));
  b[2] = (unsigned char)(Y & 0xFF);
  b[3] = 0;                     /* red */
  b[4] = (unsigned char)g;      /* green: P1 phosphor */
  b[5] = 0;                     /* blue */
  b[6] = (unsigned char)i;
  f->npts++;
}

/* Send a control byte pair on the interrupt OUT endpoint. */
static int he_control(struct helios *h, unsigned char cmd, unsigned char arg, struct t74_error *err)
{
  unsigned char b[2] = { cmd, arg };
  return usb_transfer(h->l, USB_INTERRUPT, (unsigned char)h->ep_iout, b, 2, NULL, err);
}

/* Ask (cmd) and read the reply that starts with want; garbage three times fails. */
static int he_ask(struct helios *h, unsigned char cmd, unsigned char want, unsigned char *reply,
                  struct t74_error *err)
{
  for (int tries = 0;; tries++) {
    int got = 0;
    if (he_control(h, cmd, 0, err) != T74_OK) return err->status;
    if (usb_transfer(h->l, USB_INTERRUPT, (unsigned char)h->ep_iin, reply, 32, &got, err) != T74_OK)
      return err->status;
    if (got >= 2 && reply[0] == want) return T74_OK;
    if (tries == 2)
      return t74_fail(err, T74_EIO, "helios: the DAC answered garbage to request 0x%02x "
                      "(%d bytes, first 0x%02x; expected 0x%02x) three times", cmd, got,
                      got ? reply[0] : 0, want);
  }
}

/* Poll until the DAC has a free buffer. */
static int wait_ready(struct helios *h, struct t74_error *err)
{
  double t0 = usb_now();
  for (;;) {
    unsigned char r[32];
    if (he_ask(h, HE_CMD_STATUS, 0x80 | HE_CMD_STATUS, r, err) != T74_OK) return err->status;
    if (r[1]) return T74_OK;
    if ((usb_now() - t0) * 1000 > h->status_ms)
      return t74_fail(err, T74_EIO, "helios: the DAC was not ready for a frame within %d ms",
                      h->status_ms);
    usb_sleep_ms(h->poll_ms);
  }
}

/* Wait for the frame on the wire; acknowledge its dots. */
static int wait_inflight(struct helios *h, struct t74_error *err)
{
  if (h->inflight < 0) return T74_OK;
  struct he_frame *f = &h->f[h->inflight];
  int done = 0;
  int rc = usb_wait(h->l, &h->x, &done, err);
  h->inflight = -1;
  if (rc != T74_OK) return rc;                  /* a frame is all or nothing */
  for (int k = 0; k < f->ndots; k++) h->ack.fn(h->ack.ctx, &f->dots[k]);
  f->npts = f->ndots = 0;
  return T74_OK;
}

/* Put the frame being filled on the wire, asynchronously. */
static int send_frame(struct helios *h, unsigned char flags, struct t74_error *err)
{
  struct he_frame *f = &h->f[h->cur];
  if (f->npts == 0) return T74_OK;
  if ((f->npts - 45) % 64 == 0) {               /* the SDK's MCU quirk: one blank point more */
    const unsigned char *last = f->buf + (size_t)(f->npts - 1) * HE_POINT_BYTES;
    int X = (last[0] << 4) | (last[1] >> 4), Y = ((last[1] & 0x0F) << 8) | last[2];
    put_point(f, X, Y, 0, 0);
  }
  if (wait_inflight(h, err) != T74_OK || wait_ready(h, err) != T74_OK) return err->status;
  unsigned char *t = f->buf + (size_t)f->npts * HE_POINT_BYTES;
  t[0] = (unsigned char)(h->pps & 0xFF);
  t[1] = (unsigned char)(h->pps >> 8);
  t[2] = (unsigned char)(f->npts & 0xFF);
  t[3] = (unsigned char)(f->npts >> 8);
  t[4] = flags;
  h->frame_seconds = (double)f->npts / h->pps;
  if (usb_submit(h->l, &h->x, USB_BULK, (unsigned char)h->ep_bulk, f->buf,
                 f->npts * HE_POINT_BYTES + HE_TRAILER, err) != T74_OK)
    return err->status;
  h->inflight = h->cur;
  h->cur = 1 - h->cur;
  return T74_OK;
}

static int add_dot(struct helios *h, const struct usb_point *p, struct t74_error *err)
{
  int dx = h->have_pos ? p->x - h->lx : 0, dy = h->have_pos ? p->y - h->ly : 0;
  int far = !h->have_pos || abs(dx) > 1 || abs(dy) > 1;
  int nb = 0;
  if (far) {
    int d = abs(dx) > abs(dy) ? abs(dx) : abs(dy);
    nb = 1 + d / h->blank_step;
    if (nb > HE_MAX_BLANKS) nb = HE_MAX_BLANKS;
  }
  if (h->f[h->cur].npts + nb + h->dwell > h->frame_points &&
      send_frame(h, 0, err) != T74_OK)
    return err->status;
  struct he_frame *f = &h->f[h->cur];
  int X = HE_X0 + HE_DOT_UNITS * p->x, Y = HE_Y0 + HE_DOT_UNITS * p->y;
  for (int k = 1; k <= nb; k++) {               /* blanked, interpolated; the last on the dot */
    int lx = h->have_pos ? HE_X0 + HE_DOT_UNITS * h->lx : X;
    int ly = h->have_pos ? HE_Y0 + HE_DOT_UNITS * h->ly : Y;
    put_point(f, lx + (X - lx) * k / nb, ly + (Y - ly) * k / nb, 0, 0);
  }
  for (int k = 0; k < h->dwell; k++) put_point(f, X, Y, h->intensity, h->intensity);
  f->dots[f->ndots++] = *p;
  h->have_pos = 1;
  h->lx = p->x;
  h->ly = p->y;
  return T74_OK;
}

static void helios_free(struct helios *h)
{
  for (int k = 0; k < 2; k++) {
    free(h->f[k].buf);
    free(h->f[k].dots);
  }
  usb_xfer_free(&h->x);
  free(h);
}

static int helios_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                       struct usb_ack ack, struct t74_error *err)
{
  struct helios *h = calloc(1, sizeof *h);
  if (!h) return t74_fail(err, T74_EIO, "helios: out of memory");
  h->l = l;
  h->ack = ack;
  h->ep_bulk = usb_link_endpoint(l, USB_BULK, 0);
  h->ep_iout = usb_link_endpoint(l, USB_INTERRUPT, 0);
  h->ep_iin = usb_link_endpoint(l, USB_INTERRUPT, 1);
  h->pps = (int)s->p[HE_PPS];
  h->frame_points = (int)s->p[HE_FRAME];
  h->blank_step = (int)s->p[HE_BLANK_STEP];
  h->dwell = (int)s->p[HE_DWELL];
  h->intensity = (int)s->p[HE_INTENSITY];
  h->status_ms = (int)s->p[HE_STATUS_MS];
  h->poll_ms = (int)s->p[HE_POLL_MS];
  h->inflight = -1;
  for (int k = 0; k < 2; k++) {
    h->f[k].buf = malloc((size_t)(h->frame_points + 1) * HE_POINT_BYTES + HE_TRAILER);
    h->f[k].dots = malloc(sizeof *h->f[k].dots * (size_t)h->frame_points);
    if (!h->f[k].buf || !h->f[k].dots) {
      helios_free(h);
      return t74_fail(err, T74_EIO, "helios: out of memory");
    }
  }
  if (h->ep_bulk < 0 || h->ep_iout < 0 || h->ep_iin < 0) {
    helios_free(h);
    return t74_fail(err, T74_EIO, "helios: interface 0 alt 1 lacks the bulk OUT / interrupt "
                    "endpoints of a Helios DAC");
  }
  unsigned char r[32];
  if (he_ask(h, HE_CMD_VERSION, 0x80 | HE_CMD_VERSION, r, err) != T74_OK) {
    helios_free(h);
    return err->status;
  }
  *ctx = h;
  return T74_OK;
}

static int helios_send(void *ctx, const struct usb_point *p, int n, struct t74_error *err)
{
  struct helios *h = ctx;
  for (int k = 0; k < n; k++)
    if (add_dot(h, &p[k], err) != T74_OK) return err->status;
  return T74_OK;
}

static int helios_flush(void *ctx, struct t74_error *err)
{
  struct helios *h = ctx;
  if (send_frame(h, 0, err) != T74_OK) return err->status;
  return wait_inflight(h, err);
}

static int helios_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  struct helios *h = ctx;
  unsigned char r[32];
  memset(st, 0, sizeof *st);
  if (he_ask(h, HE_CMD_STATUS, 0x80 | HE_CMD_STATUS, r, err) != T74_OK) return err->status;
  st->ready = r[1] != 0;
  snprintf(st->text, sizeof st->text, "%s", st->ready ? "ready for a frame" : "both buffers full");
  return T74_OK;
}

static void helios_close(void *ctx, int clean)
{
  struct helios *h = ctx;
  struct t74_error err = { T74_OK, "" };
  if (!usb_link_gone(h->l)) {
    wait_inflight(h, &err);                     /* its dots count if it arrives */
    if (clean && err.status == T74_OK && wait_ready(h, &err) == T74_OK)
      usb_sleep_ms(h->frame_seconds * 1000);    /* let the last frame play once */
    struct t74_error e2 = { T74_OK, "" };
    he_control(h, HE_CMD_STOP, 0, &e2);         /* blank: output stops */
    he_control(h, HE_CMD_SHUTTER, 0, &e2);      /* and the shutter closes */
  }
  helios_free(h);
}

const struct usb_profile usb_profile_helios = {
  "helios", "Helios laser / XY DAC (refreshed vector picture)",
  { 0x1209, 0xE500, -1, 1 },    /* interface 0, alt setting 1 (Helios SDK) */
  helios_params, HE_NPARAMS,
  helios_open, helios_send, helios_flush, helios_status, helios_close
};
