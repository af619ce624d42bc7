/*
** hpgl.c — the `hpgl` USB profile: an HP-GL pen plotter behind a USB printer-class
** interface (display stage, paper 003 §4 dots drawn by a pen instead of a beam).
**
** This file contains code to draw the tube's dots with HP-GL. Hardware source:
** hardware-facts.md "HP-GL pen plotters" (40 plotter units per mm; IN; SP1; PU x,y; PD;
** over USB through printer-class adapters: bulk OUT, class request GET_PORT_STATUS for
** paper/error/select); USB Printer Class 1.1 §4.2.2 (GET_PORT_STATUS: bmRequestType 0xA1,
** bRequest 1, wIndex = interface, one status byte: bit 5 paper empty, bit 4 selected,
** bit 3 not error — the bits Linux usblp reads).
**
** What is sent:
**   open      "IN;SP<pen>;"                              initialise, take the pen
**   a dot     "PU<x>,<y>;PD;"                            move pen up, put it down once
**   a stroke  "PU<x0>,<y>;PD<x1>,<y>;"                   a run of dots on a row (penplan.h)
**   close     "PU;SP0;"                                  pen up, pen back in the carousel
** Dot (x, y) of the tube is plotter point (ox + x*pitch, oy + y*pitch) in plotter units,
** pitch the largest whole number of units that fits 400 x 300 dots into the paper area
** (settings area_*_mm; default A4 landscape, 297 x 210 mm, less 10 mm margins: pitch 25
** units = 0.625 mm). Plotter y grows upwards, as the tube's does.
**
** Order: dots are buffered per band of rows and planned by penplan.c (strokes when faster,
** nearest-first order). Transfers carry whole commands, at most chunk_bytes each, and are
** waited for one by one: a small plotter buffer then simply NAKs until it has room.
** ACKNOWLEDGED: a dot is acknowledged when every byte up to the end of the command that
** draws it has been taken by the device (the bulk transfer's actual length, also when it
** failed part way). GET_PORT_STATUS is checked at open and before each band.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/usb/penplan.h"
#include "display/sink.h"
#include "display/usb/usb.h"

enum {                          /* rows of hpgl_params, in order */
  HP_AREA_X, HP_AREA_Y, HP_AREA_W, HP_AREA_H, HP_UNITS, HP_V_UP, HP_V_DOWN, HP_LIFT,
  HP_RUNS, HP_BAND, HP_CHUNK, HP_PEN, HP_NPARAMS
};

static const struct param_row hpgl_params[HP_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "area_x_mm",      "mm",    10,  0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_y_mm",      "mm",    10,  0,  2000,  0, "A4 landscape with 10 mm margins" },
  { "area_w_mm",      "mm",    277, 10, 2000,  0, "A4 landscape: 297 - 2 x 10" },
  { "area_h_mm",      "mm",    190, 10, 2000,  0, "A4 landscape: 210 - 2 x 10" },
  { "units_per_mm",   "1/mm",  40,  1,  1000,  0, "hardware-facts.md: HP-GL 40 units/mm" },
  { "pen_up_speed",   "mm/s",  500, 1,  5000,  0, "inferred: typical desk plotter slew" },
  { "pen_down_speed", "mm/s",  380, 1,  5000,  0, "inferred: HP 7475A-class 38 cm/s" },
  { "pen_lift_ms",    "ms",    30,  0,  2000,  0, "inferred: one solenoid lift or drop" },
  { "runs",           "",      1,   0,  1,     0, "1: strokes where penplan.h rule says faster" },
  { "band_rows",      "rows",  12,  1,  300,   0, "whole 3x3 and 4x4 cells (penplan.h)" },
  { "chunk_bytes",    "bytes", 512, 16, 65536, 0, "hardware-facts.md: buffers 60 B .. 1 KiB" },
  { "pen",            "",      1,   1,  8,     0, "HP-GL SP: carousel stall" },
};

#define HP_REQ_GET_PORT_STATUS 1        /* Printer Class 1.1 §4.2.2 */
#define HP_RT_CLASS_IN_IFACE   0xA1     /* device-to-host, class, interface */
#define HP_ST_PAPER_EMPTY      0x20     /* bit 5: 1 = paper empty */
#define HP_ST_SELECTED         0x10     /* bit 4: 1 = selected (on line) */
#define HP_ST_NOT_ERROR        0x08     /* bit 3: 0 = error */

struct hp_rec {                 /* a command whose acknowledgement acknowledges dots */
  long long end;                /* stream offset just past its last byte */
  int first, n;                 /* its dots in pend[] */
};

struct hpgl {
  struct usb_link *l;
  struct usb_ack ack;
  int ep;                       /* bulk OUT */
  struct pen_geom g;
  struct penplan plan;
  int chunk;
  unsigned char *buf;           /* the chunk being filled */
  int nbuf;
  long long sent;               /* stream bytes the device has taken */
  long long queued;             /* stream bytes produced (sent + nbuf) */
  struct usb_point *pend;       /* dots of commands not yet acknowledged */
  int npend, cappend;
  struct hp_rec *rec;
  int nrec, caprec, rec0;       /* rec[rec0 .. nrec-1] are pending */
};

static int hpgl_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  struct hpgl *h = ctx;
  unsigned char b[4] = { 0 };
  int got = 0;
  memset(st, 0, sizeof *st);
  int rc = usb_control_in(h->l, HP_RT_CLASS_IN_IFACE, HP_REQ_GET_PORT_STATUS, 0,
                          (uint16_t)usb_link_interface(h->l), b, 1, &got, err);
  if (rc != T74_OK) return rc;
  if (got != 1)
    return t74_fail(err, T74_EIO, "hpgl: GET_PORT_STATUS answered %d bytes instead of 1 "
                    "(not a printer-class device?)", got);
  st->paper_out = (b[0] & HP_ST_PAPER_EMPTY) != 0;
  st->error = !(b[0] & HP_ST_NOT_ERROR);
  st->ready = !st->paper_out && !st->error && (b[0] & HP_ST_SELECTED);
  snprintf(st->text, sizeof st->text, "port status 0x%02x%s%s%s", b[0],
           st->paper_out ? ", paper out" : "", st->error ? ", error" : "",
           b[0] & HP_ST_SELECTED ? "" : ", off line");
  return T74_OK;
}

/* Fail unless the plotter can draw. */
static int check_ready(struct hpgl *h, struct t74_error *err)
{
  struct usb_status st;
  int rc = hpgl_status(h, &st, err);
  if (rc != T74_OK) return rc;
  if (st.paper_out) return t74_fail(err, T74_EIO, "hpgl: the plotter is out of paper (%s)", st.text);
  if (st.error) return t74_fail(err, T74_EIO, "hpgl: the plotter reports an error (%s)", st.text);
  if (!st.ready) return t74_fail(err, T74_EIO, "hpgl: the plotter is off line (%s)", st.text);
  return T74_OK;
}

/* Send the filled chunk; acknowledge every command it completed. */
static int send_chunk(struct hpgl *h, struct t74_error *err)
{
  if (h->nbuf == 0) return T74_OK;
  int done = 0;
  int rc = usb_transfer(h->l, USB_BULK, (unsigned char)h->ep, h->buf, h->nbuf, &done, err);
  h->sent += done;
  while (h->rec0 < h->nrec && h->rec[h->rec0].end <= h->sent) {
    const struct hp_rec *r = &h->rec[h->rec0++];
    for (int k = 0; k < r->n; k++) h->ack.fn(h->ack.ctx, &h->pend[r->first + k]);
  }
  if (h->rec0 == h->nrec) h->rec0 = h->nrec = h->npend = 0;
  h->nbuf = 0;
  return rc;
}

/* Append one command; dots (may be none) are acknowledged with it. */
static int put_cmd(struct hpgl *h, const char *cmd, const struct usb_point *dots, int n,
                   struct t74_error *err)
{
  int len = (int)strlen(cmd);
  if (h->nbuf + len > h->chunk && send_chunk(h, err) != T74_OK) return err->status;
  memcpy(h->buf + h->nbuf, cmd, (size_t)len);
  h->nbuf += len;
  h->queued += len;
  if (n == 0) return T74_OK;
  if (h->npend + n > h->cappend) {
    int cap = (h->npend + n) * 2;
    struct usb_point *p = realloc(h->pend, sizeof *p * (size_t)cap);
    if (!p) return t74_fail(err, T74_EIO, "hpgl: out of memory");
    h->pend = p;
    h->cappend = cap;
  }
  if (h->nrec == h->caprec) {
    int cap = h->caprec ? h->caprec * 2 : 256;
    struct hp_rec *r = realloc(h->rec, sizeof *r * (size_t)cap);
    if (!r) return t74_fail(err, T74_EIO, "hpgl: out of memory");
    h->rec = r;
    h->caprec = cap;
  }
  h->rec[h->nrec].end = h->queued;
  h->rec[h->nrec].first = h->npend;
  h->rec[h->nrec].n = n;
  h->nrec++;
  memcpy(h->pend + h->npend, dots, sizeof *dots * (size_t)n);
  h->npend += n;
  return T74_OK;
}

/* Plan the buffered band and send its strokes. */
static int emit_band(struct hpgl *h, struct t74_error *err)
{
  if (h->plan.nin == 0) return T74_OK;
  if (check_ready(h, err) != T74_OK) return err->status;
  if (penplan_plan(&h->plan, err) != T74_OK) return err->status;
  for (int k = 0; k < h->plan.nst; k++) {
    const struct pen_stroke *s = &h->plan.st[k];
    char cmd[64];
    int y = h->g.oy + s->y * h->g.pitch;
    if (s->n == 1)
      snprintf(cmd, sizeof cmd, "PU%d,%d;PD;", h->g.ox + s->x0 * h->g.pitch, y);
    else
      snprintf(cmd, sizeof cmd, "PU%d,%d;PD%d,%d;", h->g.ox + s->x0 * h->g.pitch, y,
               h->g.ox + s->x1 * h->g.pitch, y);
    if (put_cmd(h, cmd, &h->plan.pts[s->first], s->n, err) != T74_OK) return err->status;
  }
  return T74_OK;
}

static void hpgl_free(struct hpgl *h)
{
  penplan_free(&h->plan);
  free(h->buf);
  free(h->pend);
  free(h->rec);
  free(h);
}

static int hpgl_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                     struct usb_ack ack, struct t74_error *err)
{
  struct hpgl *h = calloc(1, sizeof *h);
  if (!h) return t74_fail(err, T74_EIO, "hpgl: out of memory");
  h->l = l;
  h->ack = ack;
  h->ep = usb_link_endpoint(l, USB_BULK, 0);
  double upm = s->p[HP_UNITS];
  h->g = pen_geom_fit(s->p[HP_AREA_X] * upm, s->p[HP_AREA_Y] * upm, s->p[HP_AREA_W] * upm,
                      s->p[HP_AREA_H] * upm);
  double pitch_mm = h->g.pitch / upm;
  int runs = s->p[HP_RUNS] != 0 &&
             penplan_rule(pitch_mm, s->p[HP_V_UP], s->p[HP_V_DOWN], s->p[HP_LIFT]);
  h->chunk = (int)s->p[HP_CHUNK];
  h->buf = malloc((size_t)h->chunk + 64);
  if (!h->buf || penplan_init(&h->plan, (int)s->p[HP_BAND], runs, err) != T74_OK) {
    hpgl_free(h);
    return t74_fail(err, T74_EIO, "hpgl: out of memory");
  }
  if (h->ep < 0) {
    hpgl_free(h);
    return t74_fail(err, T74_EIO, "hpgl: the printer interface has no bulk OUT endpoint");
  }
  char init[32];
  snprintf(init, sizeof init, "IN;SP%d;", (int)s->p[HP_PEN]);
  if (check_ready(h, err) != T74_OK || put_cmd(h, init, NULL, 0, err) != T74_OK ||
      send_chunk(h, err) != T74_OK) {
    hpgl_free(h);
    return err->status;
  }
  *ctx = h;
  return T74_OK;
}

static int hpgl_send(void *ctx, const struct usb_point *p, int n, struct t74_error *err)
{
  struct hpgl *h = ctx;
  for (int k = 0; k < n; k++) {
    if (penplan_new_band(&h->plan, &p[k]) && emit_band(h, err) != T74_OK) return err->status;
    if (penplan_add(&h->plan, &p[k], err) != T74_OK) return err->status;
  }
  return T74_OK;
}

static int hpgl_flush(void *ctx, struct t74_error *err)
{
  struct hpgl *h = ctx;
  if (emit_band(h, err) != T74_OK) return err->status;
  return send_chunk(h, err);
}

static void hpgl_close(void *ctx, int clean)
{
  struct hpgl *h = ctx;
  struct t74_error e = { T74_OK, "" };
  if (!usb_link_gone(h->l)) {
    /* pen up and back in its stall; after a failure only what is already queued is lost */
    h->nbuf = 0;
    h->nrec = h->rec0 = h->npend = 0;
    if (put_cmd(h, "PU;SP0;", NULL, 0, &e) == T74_OK) send_chunk(h, &e);
  }
  (void)clean;
  hpgl_free(h);
}

const struct usb_profile usb_profile_hpgl = {
  "hpgl", "HP-GL pen plotter on a USB printer-class interface",
  { 0, 0, 7, -1 },              /* any device with a printer-class (7) interface */
  hpgl_params, HP_NPARAMS,
  hpgl_open, hpgl_send, hpgl_flush, hpgl_status, hpgl_close
};
