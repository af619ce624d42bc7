/*
** helios.c — the `helios` USB profile: a Helios laser / XY DAC showing the tube's dots as a
** refreshed vector picture (display stage, paper 003 §4; a display that does not store).
**
** This file contains code to turn dots into Helios frames and to leave the laser safe.
** Hardware sources (docs/usb.md lists them rule by rule):
**   the Helios SDK, Grix/helios_dac sdk/cpp/HeliosDac.{h,cpp}: a point is 7 bytes (x>>4,
**     (x&15)<<4 | y>>8, y&255, r, g, b, i; 12-bit x, y), a frame its points then pps (16-bit
**     LE), point count (16-bit LE), flags; at most 0xFFF points, 7..0xFFFF points/s; poll
**     status (0x03 on interrupt OUT 0x06, reply 0x83 with byte 1 = 1 when ready) before each
**     frame; 0x01 stop, 0x02 shutter (byte 1: 1 open, 0 closed), 0x04 firmware version ->
**     0x84; at start "catch any lingering transfers" (interrupt IN read with 5 ms timeout
**     until none comes); WriteFrame opens the shutter before the first frame
**     (`if (!shutterIsOpen) SetShutter(1)`); flags bit 1 HELIOS_FLAGS_SINGLE_MODE "played
**     exactly once ... If a new frame has not arrived before the currently playing one is
**     done, the laser will turn off" (the SDK's default flags); frames of n points with
**     (n - 45) % 64 == 0 are not received correctly by the DAC's MCU (SDK note);
**   the Helios firmware, firmware/.../src/main.c: at power-up shutter_set(LOW) and a blanked
**     stop; two frame buffers, one playing and one filling; a finished frame is looped unless
**     its flag bit 1 is set, then output stops blanked; status reply [0x83, 1] re-arms the
**     bulk endpoint for the next frame only when the second buffer is free.
**
** What is sent, per dot (steady = 0, the default): a BLANKED move (r = g = b = i = 0) to it
** when it is not a neighbour of the previous dot — one blanked point per blank_step dots of
** distance, the last exactly on the dot, so the mirrors settle dark — then `dwell` lit points
** on it (green: the tube's P1 phosphor). Tube dot (x, y) is DAC point (48 + 10x, 548 + 10y):
** 10 DAC units a dot keeps the 4:3 picture square-pixelled and centred in the 12-bit field.
** Dots go out as they are produced, frames of at most frame_points: a picture of more points
** than one frame is shown band by band, so it refreshes at pps / (its points) Hz (docs/usb.md).
** steady = 1: each pass is buffered and sent as K = ceil(points / frame_points) frames that
**   each cover the whole picture: frame j holds the dots j, j+K, j+2K... of production order
**   (interleaved), so the eye sees the whole picture at pps / frame_points Hz, each frame a
**   thinned copy. steady = 2: as 1, but the dots are first joined into runs along rows
**   (serpentine), each run drawn as a LIT LINE with one point every run_step dots and on
**   its last dot (a laser's galvos and an XY display's beam light the path between points),
**   and the rows interleaved: far fewer points, often one frame for the whole picture.
** Frames are sent with flags = SINGLE (play once): if tube74 dies, the DAC plays what it has
** once and blanks; it never loops the last frame with the laser on. Double-buffering with
** asynchronous transfers: while one frame is on the wire the next is filled; before a frame
** is sent the previous transfer is waited for and the status polled until the DAC is ready,
** for at most status_margin_ms beyond the duration of the frames the DAC already holds.
** Open: drain stale status replies, ask the firmware version, open the shutter just before
** the first frame. Close: after a completed run the last frame plays out; in every case
** 0x01 stop (blanked) and 0x02,0 shutter closed — also after Ctrl-C, SIGTERM or SIGHUP
** (cli/cmd_stream.c turns them into the stream's stop flag).
** ACKNOWLEDGED: a dot is acknowledged when the bulk transfer of its frame has completed
** (the DAC took the whole frame). --repeat passes are the stream's (stream.c): each pass
** sends every dot again, as a refresh.
** A FILE (--to FILE.ild, --dry-run) gets the same frames as ILDA IDTF format-1 sections
** (display/usb/ilda.h), one a frame, no status polls and no shutter commands; the DAC's pps
** is not in the file. TIME MODEL (the estimate): a frame of n points plays in n / pps s.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/sink.h"
#include "display/usb/ilda.h"
#include "display/usb/preview.h"
#include "display/usb/usb.h"

enum { HE_PPS, HE_FRAME, HE_BLANK_STEP, HE_DWELL, HE_INTENSITY, HE_STATUS_MS, HE_POLL_MS,
       HE_STEADY, HE_RUN_STEP, HE_NPARAMS };

static const struct param_row helios_params[HE_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "pps",               "points/s", 30000, 7,  65535,  1, "Helios SDK: HELIOS_MIN_PPS 7, HELIOS_MAX_PPS 0xFFFF" },
  { "frame_points",      "points",   1000,  64, 4094,   1, "Helios SDK: HELIOS_MAX_POINTS 0xFFF "
                                                          "(one kept for the SDK's size quirk)" },
  { "blank_step",        "dots",     40,    1,  400,    1, "inferred: one blanked point per 40 dots moved" },
  { "dwell",             "points",   1,     1,  16,     1, "lit points per dot; inferred" },
  { "intensity",         "",         255,   1,  255,    1, "green and intensity of a lit point" },
  { "status_margin_ms",  "ms",       1000,  10, 600000, 0, "inferred: beyond the duration of the "
                                                          "frames the DAC holds (2 buffers, firmware)" },
  { "poll_ms",           "ms",       1,     0,  1000,   0, "pause between status polls; inferred" },
  { "steady",            "",         0,     0,  2,      1, "0 dots as produced, 1 interleaved whole-"
                                                          "picture frames, 2 also runs as lit lines" },
  { "run_step",          "dots",     4,     1,  64,     1, "steady=2: a point every N dots along a "
                                                          "run; inferred (galvo/beam draws between)" },
};

#define HE_POINT_BYTES 7        /* x>>4, x&15<<4|y>>8, y&255, r, g, b, i */
#define HE_TRAILER     5        /* pps lo, pps hi, count lo, count hi, flags */
#define HE_DOT_UNITS   10       /* DAC units per tube dot */
#define HE_X0          48       /* (4096 - 400*10) / 2 */
#define HE_Y0          548      /* (4096 - 300*10) / 2 */
#define HE_CMD_STOP    0x01     /* SDK Stop(): output stops, blanked */
#define HE_CMD_SHUTTER 0x02     /* SDK SetShutter(level) */
#define HE_CMD_STATUS  0x03     /* SDK GetStatus(): reply 0x83, byte 1 = 1 ready */
#define HE_CMD_VERSION 0x04     /* SDK: firmware version, reply 0x84 + 32-bit LE */
#define HE_FLAG_SINGLE (1 << 1) /* SDK HELIOS_FLAGS_SINGLE_MODE: play once, then blank */
#define HE_DRAIN_MS    5        /* SDK constructor: lingering replies read with 5 ms timeout */
#define HE_MAX_BLANKS  16       /* blanked points of the longest move (the move is then split
                                   into at most 16 steps) */

struct he_frame {
  unsigned char *buf;           /* points, then room for the trailer */
  int npts;
  struct usb_point *dots;       /* dots lit in this frame, acknowledged with it */
  int ndots, capdots;
};

struct helios {
  struct usb_link *l;
  struct usb_ack ack;
  int ep_bulk, ep_iout, ep_iin;
  int pps, frame_points, blank_step, dwell, intensity, poll_ms, steady, run_step;
  double margin_ms;
  struct he_frame f[2];
  int cur;                      /* frame being filled */
  int inflight;                 /* frame on the wire, or -1 */
  struct usb_xfer x;
  int have_pos;                 /* a dot was drawn: lx, ly valid */
  int lx, ly;                   /* last dot, tube coordinates */
  double held_s[2];             /* durations of the last two frames sent (the DAC's buffers) */
  int shutter_open;
  struct usb_point *pass;       /* steady: the pass's dots, buffered until flush */
  int npass;
  int *order;                   /* steady: scratch (indices) */
  int offline;                  /* a file link: frames become ILDA sections */
  struct ilda_writer ilda;
  struct usb_tally *t;
  struct preview *pv;
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

static int frame_dot(struct he_frame *f, const struct usb_point *p, struct t74_error *err)
{
  if (f->ndots == f->capdots) {
    int cap = f->capdots ? f->capdots * 2 : 1024;
    struct usb_point *d = realloc(f->dots, sizeof *d * (size_t)cap);
    if (!d) return t74_fail(err, T74_EIO, "helios: out of memory");
    f->dots = d;
    f->capdots = cap;
  }
  f->dots[f->ndots++] = *p;
  return T74_OK;
}

/* Send a control byte pair on the interrupt OUT endpoint. */
static int he_control(struct helios *h, unsigned char cmd, unsigned char arg, struct t74_error *err)
{
  unsigned char b[2] = { cmd, arg };
  return usb_transfer(h->l, USB_INTERRUPT, (unsigned char)h->ep_iout, b, 2, NULL, err);
}

/* Read and drop replies left on the interrupt IN endpoint (a previous program's, or ours
** from a request that timed out), as the SDK does before talking to the DAC. */
static int he_drain(struct helios *h, struct t74_error *err)
{
  for (int k = 0; k < 64; k++) {
    unsigned char r[32];
    int got = 0;
    if (usb_read_once(h->l, USB_INTERRUPT, (unsigned char)h->ep_iin, r, sizeof r, HE_DRAIN_MS,
                      &got, err) != T74_OK)
      return err->status;
    if (got == 0) return T74_OK;
  }
  return T74_OK;
}

/* Ask (cmd) and read the reply that starts with want. A reply that is not it (a stale one
** left over) is dropped and the next one read, if one comes within HE_DRAIN_MS; after that
** the request is sent again; three requests without the answer fail. */
static int he_ask(struct helios *h, unsigned char cmd, unsigned char want, unsigned char *reply,
                  struct t74_error *err)
{
  int junk = 0, first = 0;
  for (int tries = 0;; tries++) {
    if (he_control(h, cmd, 0, err) != T74_OK) return err->status;
    int got = 0;
    if (usb_transfer(h->l, USB_INTERRUPT, (unsigned char)h->ep_iin, reply, 32, &got, err) != T74_OK)
      return err->status;
    for (int k = 0; k < 4 && got > 0; k++) {    /* the answer, after up to 3 stale replies */
      if (got >= 2 && reply[0] == want) return T74_OK;
      if (!junk++) first = reply[0];
      if (usb_read_once(h->l, USB_INTERRUPT, (unsigned char)h->ep_iin, reply, 32, HE_DRAIN_MS,
                        &got, err) != T74_OK)
        return err->status;
    }
    if (tries == 2)
      return t74_fail(err, T74_EIO, "helios: the DAC answered garbage to request 0x%02x "
                      "(%d replies, the first 0x%02x; expected 0x%02x)", cmd, junk, first, want);
  }
}

/* Poll until the DAC has a free buffer: at most margin_ms beyond the frames it holds. */
static int wait_ready(struct helios *h, struct t74_error *err)
{
  double t0 = usb_now();
  double limit = h->margin_ms + 1000.0 * (h->held_s[0] + h->held_s[1]);
  for (;;) {
    unsigned char r[32];
    if (he_ask(h, HE_CMD_STATUS, 0x80 | HE_CMD_STATUS, r, err) != T74_OK) return err->status;
    if (r[1]) return T74_OK;
    if ((usb_now() - t0) * 1000 > limit)
      return t74_fail(err, T74_EIO, "helios: the DAC was not ready for a frame within %.0f ms "
                      "(its two buffers hold %.0f ms of points at %d points/s)", limit,
                      1000.0 * (h->held_s[0] + h->held_s[1]), h->pps);
    if (usb_link_stopped(h->l))
      return t74_fail(err, T74_EIO, "helios: stopped while waiting for the DAC");
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

/* Put the frame being filled on the wire, asynchronously, to be played once. */
static int send_frame(struct helios *h, struct t74_error *err)
{
  struct he_frame *f = &h->f[h->cur];
  if (f->npts == 0) return T74_OK;
  if ((f->npts - 45) % 64 == 0) {               /* the SDK's MCU quirk: one blank point more */
    const unsigned char *last = f->buf + (size_t)(f->npts - 1) * HE_POINT_BYTES;
    int X = (last[0] << 4) | (last[1] >> 4), Y = ((last[1] & 0x0F) << 8) | last[2];
    put_point(f, X, Y, 0, 0);
  }
  h->t->frames++;
  h->t->commands++;
  h->t->points += f->npts;
  h->t->device_s += (double)f->npts / h->pps;
  for (int k = 0; k < f->npts; k++) {           /* the beam's path, for --svg */
    const unsigned char *b = f->buf + (size_t)k * HE_POINT_BYTES;
    preview_pen(h->pv, b[4] != 0 || b[6] != 0);
    preview_to(h->pv, (b[0] << 4) | (b[1] >> 4), ((b[1] & 0x0F) << 8) | b[2]);
  }
  if (h->offline) {             /* a file: the frame as an ILDA section, taken at once */
    if (ilda_frame(&h->ilda, f->buf, f->npts, err) != T74_OK) return err->status;
    for (int k = 0; k < f->ndots; k++) h->ack.fn(h->ack.ctx, &f->dots[k]);
    f->npts = f->ndots = 0;
    return T74_OK;
  }
  if (wait_inflight(h, err) != T74_OK || wait_ready(h, err) != T74_OK) return err->status;
  if (!h->shutter_open) {                       /* the SDK opens it before the first frame */
    if (he_control(h, HE_CMD_SHUTTER, 1, err) != T74_OK) return err->status;
    h->shutter_open = 1;
  }
  unsigned char *t = f->buf + (size_t)f->npts * HE_POINT_BYTES;
  t[0] = (unsigned char)(h->pps & 0xFF);
  t[1] = (unsigned char)(h->pps >> 8);
  t[2] = (unsigned char)(f->npts & 0xFF);
  t[3] = (unsigned char)(f->npts >> 8);
  t[4] = HE_FLAG_SINGLE;
  h->held_s[0] = h->held_s[1];
  h->held_s[1] = (double)f->npts / h->pps;
  if (usb_submit(h->l, &h->x, USB_BULK, (unsigned char)h->ep_bulk, f->buf,
                 f->npts * HE_POINT_BYTES + HE_TRAILER, err) != T74_OK)
    return err->status;
  h->inflight = h->cur;
  h->cur = 1 - h->cur;
  return T74_OK;
}

/* Blanked points of a move from the last dot to (x, y): 0 for a neighbour. */
static int blanks_to(const struct helios *h, int x, int y)
{
  if (!h->have_pos) return 1;
  int dx = abs(x - h->lx), dy = abs(y - h->ly);
  if (dx <= 1 && dy <= 1) return 0;
  int nb = 1 + (dx > dy ? dx : dy) / h->blank_step;
  return nb > HE_MAX_BLANKS ? HE_MAX_BLANKS : nb;
}

/* Move the beam to dot (x, y): blanked unless it is a neighbour, then `lit` lit points. */
static void beam_to(struct helios *h, struct he_frame *f, int x, int y, int lit)
{
  int nb = blanks_to(h, x, y);
  int X = HE_X0 + HE_DOT_UNITS * x, Y = HE_Y0 + HE_DOT_UNITS * y;
  int lx = h->have_pos ? HE_X0 + HE_DOT_UNITS * h->lx : X;
  int ly = h->have_pos ? HE_Y0 + HE_DOT_UNITS * h->ly : Y;
  if (nb > 0) h->t->pen_moves++;
  h->t->strokes += lit > 0;
  for (int k = 1; k <= nb; k++)                 /* blanked, interpolated; the last on the dot */
    put_point(f, lx + (X - lx) * k / nb, ly + (Y - ly) * k / nb, 0, 0);
  for (int k = 0; k < lit; k++) put_point(f, X, Y, h->intensity, h->intensity);
  h->have_pos = 1;
  h->lx = x;
  h->ly = y;
}

/* One dot: its points never straddle two frames. */
static int add_dot(struct helios *h, const struct usb_point *p, struct t74_error *err)
{
  if (h->f[h->cur].npts + blanks_to(h, p->x, p->y) + h->dwell > h->frame_points &&
      send_frame(h, err) != T74_OK)
    return err->status;
  struct he_frame *f = &h->f[h->cur];
  beam_to(h, f, p->x, p->y, h->dwell);
  return frame_dot(f, p, err);
}

/* steady = 2: a run of n dots on one row, in drawing order (x steps by +-1), drawn as a lit
** line: a point on its first dot (after the blanked move), then one every run_step dots and
** one on the last; the beam lights every dot between two points. A run that does not fit
** the frame continues in the next one (from a blanked point on the dot reached). */
static int add_run(struct helios *h, const struct usb_point *d, int n, struct t74_error *err)
{
  int k = 0;
  while (k < n) {
    struct he_frame *f = &h->f[h->cur];
    int need = blanks_to(h, d[k].x, d[k].y) + h->dwell;
    if (f->npts + need + 1 > h->frame_points) {
      if (send_frame(h, err) != T74_OK) return err->status;
      h->have_pos = 0;                          /* a new frame starts with a blanked point */
      continue;
    }
    beam_to(h, f, d[k].x, d[k].y, h->dwell);
    if (frame_dot(f, &d[k], err) != T74_OK) return err->status;
    k++;
    while (k < n && f->npts < h->frame_points) {  /* lit segments along the row */
      int next = k - 1 + h->run_step < n - 1 ? k - 1 + h->run_step : n - 1;
      put_point(f, HE_X0 + HE_DOT_UNITS * d[next].x, HE_Y0 + HE_DOT_UNITS * d[next].y,
                h->intensity, h->intensity);
      for (; k <= next; k++)
        if (frame_dot(f, &d[k], err) != T74_OK) return err->status;
      h->lx = d[next].x;
    }
  }
  return T74_OK;
}

/* Points a dot costs after the dot before it (for choosing the interleave). */
static int dot_cost(const struct helios *h, const struct usb_point *a, const struct usb_point *b)
{
  int dx = a ? abs(b->x - a->x) : 999, dy = a ? abs(b->y - a->y) : 999;
  int nb = a && dx <= 1 && dy <= 1 ? 0 : 1 + (dx > dy ? dx : dy) / h->blank_step;
  return (nb > HE_MAX_BLANKS ? HE_MAX_BLANKS : nb) + h->dwell;
}

static int cmp_row(const void *a, const void *b)   /* top row first, then left to right */
{
  const struct usb_point *p = a, *q = b;
  return p->y != q->y ? q->y - p->y : p->x - q->x;
}

/* steady = 1 or 2: the buffered pass as K frames that each cover the whole picture. */
static int send_steady(struct helios *h, struct t74_error *err)
{
  int n = h->npass;
  if (n == 0) return T74_OK;
  struct usb_point *d = h->pass;
  /* units: dots (steady 1) or runs (steady 2); unit u is d[first[u] .. first[u+1]-1] */
  int *first = h->order, nu = 0;
  if (h->steady == 2) {
    qsort(d, (size_t)n, sizeof *d, cmp_row);
    int row = 0;
    for (int k = 0; k < n;) {                   /* runs of neighbours; serpentine rows */
      int r0 = k;
      while (k < n && d[k].y == d[r0].y) k++;
      if (row++ & 1)
        for (int a = r0, b = k - 1; a < b; a++, b--) { struct usb_point t = d[a]; d[a] = d[b]; d[b] = t; }
      for (int j = r0; j < k; j++)
        if (j == r0 || abs(d[j].x - d[j - 1].x) != 1) first[nu++] = j;
    }
  } else {
    for (int k = 0; k < n; k++) first[nu++] = k;
  }
  first[nu] = n;
  /* the fewest interleaved frames K such that every frame's points fit */
  long total = 0;
  for (int u = 0; u < nu; u++) {
    int len = first[u + 1] - first[u];
    total += 1 + h->dwell + (h->steady == 2 ? (len - 1 + h->run_step - 1) / h->run_step : 0);
  }
  int K = (int)((total + h->frame_points - 1) / h->frame_points);
  if (K < 1) K = 1;
  for (;; K++) {
    int fits = 1;
    for (int j = 0; j < K && fits; j++) {
      long pts = 0;
      const struct usb_point *prev = NULL;
      for (int u = j; u < nu; u += K) {
        int len = first[u + 1] - first[u];
        pts += dot_cost(h, prev, &d[first[u]]) +
               (h->steady == 2 ? (len - 1 + h->run_step - 1) / h->run_step : 0);
        prev = &d[first[u + 1] - 1];
      }
      fits = pts + 1 <= h->frame_points;
    }
    if (fits || K >= nu) break;
  }
  for (int j = 0; j < K; j++) {
    h->have_pos = 0;
    for (int u = j; u < nu; u += K) {
      int st = h->steady == 2 ? add_run(h, &d[first[u]], first[u + 1] - first[u], err)
                              : add_dot(h, &d[first[u]], err);
      if (st != T74_OK) return st;
    }
    if (send_frame(h, err) != T74_OK) return err->status;
  }
  h->npass = 0;
  return T74_OK;
}

static void helios_free(struct helios *h)
{
  for (int k = 0; k < 2; k++) {
    free(h->f[k].buf);
    free(h->f[k].dots);
  }
  usb_xfer_free(h->l, &h->x);
  ilda_free(&h->ilda);
  free(h->pass);
  free(h->order);
  free(h);
}

static int helios_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                       struct usb_ack ack, struct t74_error *err)
{
  struct helios *h = calloc(1, sizeof *h);
  if (!h) return t74_fail(err, T74_EIO, "helios: out of memory");
  h->l = l;
  h->ack = ack;
  h->offline = usb_link_kind(l) == USB_LINK_FILE;
  h->t = usb_link_tally(l);
  h->pv = usb_link_preview(l);
  ilda_init(&h->ilda);
  preview_area(h->pv, 0, 0, 4095, 4095, 1, 0, "Helios DAC field, 12-bit X and Y");
  h->ep_bulk = usb_link_endpoint(l, USB_BULK, 0);
  h->ep_iout = usb_link_endpoint(l, USB_INTERRUPT, 0);
  h->ep_iin = usb_link_endpoint(l, USB_INTERRUPT, 1);
  h->pps = (int)s->p[HE_PPS];
  h->frame_points = (int)s->p[HE_FRAME];
  h->blank_step = (int)s->p[HE_BLANK_STEP];
  h->dwell = (int)s->p[HE_DWELL];
  h->intensity = (int)s->p[HE_INTENSITY];
  h->margin_ms = s->p[HE_STATUS_MS];
  h->poll_ms = (int)s->p[HE_POLL_MS];
  h->steady = (int)s->p[HE_STEADY];
  h->run_step = (int)s->p[HE_RUN_STEP];
  h->inflight = -1;
  int ok = 1;
  for (int k = 0; k < 2; k++)
    ok &= (h->f[k].buf = malloc((size_t)(h->frame_points + 1) * HE_POINT_BYTES + HE_TRAILER)) != NULL;
  if (h->steady) {
    ok &= (h->pass = malloc(sizeof *h->pass * TUBE_W * TUBE_H)) != NULL;
    ok &= (h->order = malloc(sizeof *h->order * (TUBE_W * TUBE_H + 1))) != NULL;
  }
  if (!ok) {
    helios_free(h);
    return t74_fail(err, T74_EIO, "helios: out of memory");
  }
  if (h->offline) {             /* nothing to ask a file */
    *ctx = h;
    return T74_OK;
  }
  if (h->ep_bulk < 0 || h->ep_iout < 0 || h->ep_iin < 0) {
    helios_free(h);
    return t74_fail(err, T74_EIO, "helios: interface 0 alt 1 lacks the bulk OUT / interrupt "
                    "endpoints of a Helios DAC");
  }
  unsigned char r[32];
  if (he_drain(h, err) != T74_OK || he_ask(h, HE_CMD_VERSION, 0x80 | HE_CMD_VERSION, r, err) != T74_OK) {
    helios_free(h);
    return err->status;
  }
  *ctx = h;
  return T74_OK;
}

static int helios_send(void *ctx, const struct usb_point *p, int n, struct t74_error *err)
{
  struct helios *h = ctx;
  for (int k = 0; k < n; k++) {
    if (h->steady) {
      if (h->npass < TUBE_W * TUBE_H) h->pass[h->npass++] = p[k];
    } else if (add_dot(h, &p[k], err) != T74_OK) {
      return err->status;
    }
  }
  return T74_OK;
}

static int helios_flush(void *ctx, struct t74_error *err)
{
  struct helios *h = ctx;
  if (h->steady && send_steady(h, err) != T74_OK) return err->status;
  if (send_frame(h, err) != T74_OK) return err->status;
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

/* Leave the laser safe: stop (blanked output) and close the shutter, on every exit path
** where the DAC is still there. After a completed run the last frame plays out first. */
static void helios_close(void *ctx, int clean)
{
  struct helios *h = ctx;
  struct t74_error err = { T74_OK, "" };
  if (h->offline) {             /* the ILDA file: every frame, then the end header */
    const unsigned char *b;
    size_t n;
    if (clean && ilda_finish(&h->ilda, &b, &n, &err) == T74_OK)
      usb_transfer(h->l, USB_BULK, (unsigned char)h->ep_bulk, (void *)b, (int)n, NULL, &err);
    helios_free(h);
    return;
  }
  if (!usb_link_gone(h->l)) {
    if (h->inflight >= 0) {
      if (!clean) h->f[h->inflight].ndots = 0;  /* stopping: nothing more counts as shown */
      wait_inflight(h, &err);                   /* its dots count if it arrives */
    }
    if (clean && err.status == T74_OK && wait_ready(h, &err) == T74_OK)
      usb_sleep_ms(h->held_s[1] * 1000);        /* let the last frame play once */
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
  helios_open, helios_send, helios_flush, helios_status, helios_close, NULL,
  USB_LINKS(USB_LINK_USB) | USB_LINKS(USB_LINK_FILE), "ILDA IDTF (.ild, format 1)"
};
