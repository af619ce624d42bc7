/*
** hpgl.c — the `hpgl` USB profile: an HP-GL pen plotter behind a USB printer-class
** interface (display stage, paper 003 §4 dots drawn by a pen instead of a beam).
**
** This file contains code to draw the tube's dots with HP-GL, inside the plotter's own
** limits, on a device that says it speaks HP-GL. Hardware sources (docs/usb.md lists them
** rule by rule):
**   USB Printer Class 1.1: §4.2.1 GET_DEVICE_ID (bmRequestType 0xA1, bRequest 0, wValue the
**     configuration index, wIndex interface << 8 | alternate setting — as Linux usblp sends
**     it): a 2-byte big-endian length, then the IEEE 1284 device id "KEY:value;..." whose
**     COMMAND SET (CMD) lists the languages; §4.2.2 GET_PORT_STATUS (bRequest 1): one byte,
**     bit 5 paper empty, bit 4 selected, bit 3 not error (the bits usblp reads); protocol 2
**     interfaces are bidirectional (a bulk IN endpoint carries the device's answers);
**   the HP 7475A Interfacing and Programming Manual: plotter units of 0.025 mm (40 per mm);
**     the origin (0, 0) is the lower left HARD-CLIP corner, not the paper's; pen moves are
**     clipped at the hard-clip limits; OH outputs them as "XLL,YLL,XUR,YUR" CR; IN resets P1
**     and P2 (A4: 603,521 / 10603,7721); the A4 hard-clip area is 0..11040 x 0..7721 and the
**     US A (letter) one 0..10365 x 0..7962 (the letter figures also in WesleyAC/plotter-tools
**     plotters/hp7475a/README.md).
**
** What is sent:
**   open      GET_DEVICE_ID: refused unless the command set names HP-GL (--force overrides)
**             GET_PORT_STATUS: ready?
**             "IN;OH;"  and the answer read from bulk IN (bidirectional link), within
**                       query_ms; no answer: the model's documented limits (table below),
**                       else the area_* settings, measured from the origin
**   a dot     "PU<x>,<y>;PD;"                            move pen up, put it down once
**   a stroke  "PU<x0>,<y>;PD<x1>,<y>;"                   a run of dots on a row (penplan.h)
**   close     "PU;SP0;"                                  pen up, pen back in the carousel
** Dot (x, y) of the tube is plotter point (ox + x*pitch, oy + y*pitch): the largest whole
** pitch that fits 400 x 300 dots inside the hard-clip limits less margin_mm on each side,
** centred there. Plotter y grows upwards, as the tube's does.
**
** Order: dots are buffered per band of rows and planned by penplan.c (strokes when faster,
** nearest-first order). Transfers carry whole commands, at most chunk_bytes each, and are
** waited for one by one: a small plotter buffer then simply NAKs until it has room (the
** transport restarts its retry count whenever bytes move, usb.c).
** ACKNOWLEDGED: a dot is acknowledged when every byte up to the end of the command that
** draws it has been taken by the device (the bulk transfer's actual length, also when it
** failed part way). GET_PORT_STATUS is checked at open and before each band.
**
** OVER RS-232 (--serial, display/usb/serial.h; the HP 7470A / 7475A interfacing manuals'
** device-control instructions, "ESC ." sequences the plotter obeys at once, outside its
** buffer): there is no device id and no port status; OH is answered on the line. The
** handshake (setting `handshake`):
**   auto (0)   with the link's flow `none`: SOFTWARE CHECKING — before a block the plotter
**              is asked ESC.B ("output buffer space": a decimal number of free bytes, then
**              the output terminator, CR by default) and sent at most that many bytes, so
**              its buffer (1,024 bytes on the 7475A) never overflows whatever the cable;
**              with flow XON/XOFF: the plotter's Xon-Xoff handshake is switched on first,
**              ESC.I<xoff_bytes>;;17: (Xoff threshold, no enquiry character, DC1 as the Xon
**              trigger) and ESC.N;19: (DC3 as the Xoff trigger), then serial.c obeys them;
**              with flow RTS/CTS: nothing is sent for it (the 7475A wakes up with its
**              hardwire handshake on: DTR low while fewer than 80 bytes are free)
**   ESC.B (1)  software checking whatever the link's flow
**   none (2)   nothing: the bytes are only paced (a plotter slower than its line overflows)
** Acknowledged: bytes the plotter took into its buffer, as over USB.
** A FILE (--to, --dry-run) gets exactly the bytes a plotter would; with no OH answer and no
** device id, the picture is fitted to the 7475A's documented limits for `sheet` (`limits=1`:
** to the area_* settings instead).
**
** TIME MODEL (the estimate, usb_tally): every stroke costs the pen-up move to its start at
** pen_up_speed, a pen drop and a lift (pen_lift_ms each) and its length at pen_down_speed;
** no acceleration is modelled (the 7475A's manual gives none), so the estimate is a lower
** bound of the plotter's motion. Over a serial line the bytes' own time at the baud may be
** longer; the stream takes the longer of the two.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/usb/penplan.h"
#include "display/sink.h"
#include "display/usb/preview.h"
#include "display/usb/serial.h"
#include "display/usb/usb.h"

enum {                          /* rows of hpgl_params, in order */
  HP_AREA_X, HP_AREA_Y, HP_AREA_W, HP_AREA_H, HP_UNITS, HP_V_UP, HP_V_DOWN, HP_LIFT,
  HP_RUNS, HP_BAND, HP_CHUNK, HP_PEN, HP_MARGIN, HP_SHEET, HP_QUERY, HP_FORCE, HP_HANDSHAKE,
  HP_XOFF, HP_POLL, HP_LIMITS, HP_NPARAMS
};

static const struct param_row hpgl_params[HP_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "area_x_mm",      "mm",    10,  0,  2000,  0, "no limits known: from the origin; A4 landscape" },
  { "area_y_mm",      "mm",    10,  0,  2000,  0, "no limits known: from the origin; A4 landscape" },
  { "area_w_mm",      "mm",    277, 10, 2000,  0, "no limits known: A4 landscape: 297 - 2 x 10" },
  { "area_h_mm",      "mm",    190, 10, 2000,  0, "no limits known: A4 landscape: 210 - 2 x 10" },
  { "units_per_mm",   "1/mm",  40,  1,  1000,  0, "docs/hardware.md: HP-GL 40 units/mm" },
  { "pen_up_speed",   "mm/s",  500, 1,  5000,  0, "inferred: typical desk plotter slew" },
  { "pen_down_speed", "mm/s",  380, 1,  5000,  0, "inferred: HP 7475A-class 38 cm/s" },
  { "pen_lift_ms",    "ms",    30,  0,  2000,  0, "inferred: one solenoid lift or drop" },
  { "runs",           "",      1,   0,  1,     0, "1: strokes where penplan.h rule says faster" },
  { "band_rows",      "rows",  12,  1,  300,   0, "whole 3x3 and 4x4 cells (penplan.h)" },
  { "chunk_bytes",    "bytes", 512, 16, 65536, 0, "docs/hardware.md: buffers 60 B .. 1 KiB" },
  { "pen",            "",      1,   1,  8,     0, "HP-GL SP: carousel stall" },
  { "margin_mm",      "mm",    5,   0,  100,   0, "inside the hard-clip limits; inferred" },
  { "sheet",          "",      0,   0,  1,     1, "model defaults without OH: 0 A4, 1 US A (letter)" },
  { "query_ms",       "ms",    500, 0,  10000, 0, "wait for the OH answer; 0: do not ask" },
  { "force",          "",      0,   0,  1,     1, "1: drive a device whose id lacks HP-GL (--force)" },
  { "handshake",      "",      0,   0,  2,     1, "--serial: 0 auto, 1 ESC.B checking, 2 none "
                                                   "(7475A manual; hpgl.c)" },
  { "xoff_bytes",     "bytes", 80,  16, 1000,  1, "--flow xonxoff: ESC.I Xoff threshold (7470A/"
                                                   "7475A default block size 80)" },
  { "poll_ms",        "ms",    50,  1,  5000,  0, "ESC.B: pause before asking again when full; "
                                                   "inferred" },
  { "limits",         "",      0,   0,  1,     1, "0 OH, else the model's (7475A for files), "
                                                   "else area_*; 1 area_* always" },
};

#define HP_REQ_GET_DEVICE_ID   0        /* Printer Class 1.1 §4.2.1 */
#define HP_REQ_GET_PORT_STATUS 1        /* Printer Class 1.1 §4.2.2 */
#define HP_RT_CLASS_IN_IFACE   0xA1     /* device-to-host, class, interface */
#define HP_ST_PAPER_EMPTY      0x20     /* bit 5: 1 = paper empty */
#define HP_ST_SELECTED         0x10     /* bit 4: 1 = selected (on line) */
#define HP_ST_NOT_ERROR        0x08     /* bit 3: 0 = error */
#define HP_MIN_BLOCK           32       /* ESC.B: wait for this much room (or all that is left) */

/* Hard-clip limits of the models whose manuals give them, in plotter units: the picture is
** fitted inside when the plotter does not answer OH (a one-way adapter). */
struct hp_model {
  const char *mdl;              /* the MODEL of the 1284 id (a prefix match) */
  int sheet;                    /* 0 A4, 1 US A */
  int x0, y0, x1, y1;
};

static const struct hp_model hp_models[] = {
  { "7475A", 0, 0, 0, 11040, 7721 },    /* 7475A manual: A4 */
  { "7475A", 1, 0, 0, 10365, 7962 },    /* 7475A manual: US A (letter) */
};

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
  int ep_in;                    /* bulk IN (bidirectional link), or -1 */
  char model[64];               /* MODEL of the device id, "" unknown */
  int clip[4];                  /* hard-clip limits used: xll, yll, xur, yur */
  const char *clip_from;        /* where they came from (OH, the model table, settings) */
  int usb;                      /* the link is USB (device id, port status exist) */
  int escb;                     /* software checking: ESC.B before each block */
  int room;                     /* ESC.B: bytes the plotter said it had free, less those sent */
  double poll_ms, query_ms;
  double upm, v_up, v_down, lift_s;   /* the time model (TIME MODEL above) */
  long px, py;                  /* where the pen is, plotter units */
  struct usb_tally *t;
  struct preview *pv;
};

static int hpgl_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  struct hpgl *h = ctx;
  unsigned char b[4] = { 0 };
  int got = 0;
  memset(st, 0, sizeof *st);
  if (!h->usb) {                /* RS-232 and files have no port status */
    st->ready = 1;
    snprintf(st->text, sizeof st->text, "no port status on %s", usb_link_name(h->l));
    return T74_OK;
  }
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

/* One answer line of the plotter (CR or LF ends it; blank lines skipped) within ms into
** line; 0 bytes when none came. A serial line is read a byte at a time, so that nothing
** after the terminator is taken from the next answer. */
static int read_answer(struct hpgl *h, double ms, char *line, int cap, struct t74_error *err)
{
  int n = 0;
  double t_end = usb_now() + ms / 1000.0;
  while (n < cap - 1) {
    unsigned char in[64];
    int got = 0;
    double left = (t_end - usb_now()) * 1000.0;
    if (left <= 0) break;
    if (usb_read_once(h->l, USB_BULK, (unsigned char)h->ep_in, in, h->usb ? (int)sizeof in : 1,
                      left < 1 ? 1 : (int)left, &got, err) != T74_OK)
      return -1;
    int done = 0;
    for (int k = 0; k < got && n < cap - 1; k++) {
      if (in[k] == '\r' || in[k] == '\n') { if (n) { done = 1; break; } continue; }
      line[n++] = (char)in[k];
    }
    if (done) break;
  }
  line[n] = 0;
  return n;
}

/* ESC.B: the plotter's free buffer space into h->room. */
static int ask_room(struct hpgl *h, struct t74_error *err)
{
  static const char q[] = "\x1b.B";          /* output buffer space (no parameters) */
  if (usb_transfer(h->l, USB_BULK, (unsigned char)h->ep, (void *)q, 3, NULL, err) != T74_OK)
    return err->status;
  char line[32];
  int n = read_answer(h, h->query_ms, line, sizeof line, err);
  if (n < 0) return err->status;
  char *end;
  long v = strtol(line, &end, 10);
  if (n == 0 || *end || v < 0)
    return t74_fail(err, T74_EIO, "hpgl: the plotter %s ESC.B (its free buffer space) within "
                    "%.0f ms%s%s%s: check the cable's receive line and the baud", n ? "answered" : "did not answer",
                    h->query_ms, n ? " `" : "", n ? line : "", n ? "`" : "");
  h->room = (int)v;
  return T74_OK;
}

/* Write b[0..n) to the plotter: with software checking, never more than it has room for. */
static int hp_write(struct hpgl *h, const unsigned char *b, int n, int *done, struct t74_error *err)
{
  if (!h->escb) return usb_transfer(h->l, USB_BULK, (unsigned char)h->ep, (void *)b, n, done, err);
  *done = 0;
  double t_room = usb_now();                    /* since the room last grew */
  while (*done < n) {
    int want = n - *done < HP_MIN_BLOCK ? n - *done : HP_MIN_BLOCK;
    if (h->room < want) {
      int before = h->room;
      if (ask_room(h, err) != T74_OK) return err->status;
      if (h->room > before) t_room = usb_now();
      if (h->room < want) {                     /* full: the pen is busy, ask again soon */
        if (usb_link_stopped(h->l)) return t74_fail(err, T74_EIO, "hpgl: stopped");
        if ((usb_now() - t_room) * 1000 > usb_link_timeout_ms(h->l))
          return t74_fail(err, T74_EIO, "hpgl: the plotter's buffer stayed full for %.0f ms "
                          "(ESC.B answered %d free bytes)", usb_link_timeout_ms(h->l), h->room);
        usb_sleep_ms(h->poll_ms);
        continue;
      }
    }
    int k = n - *done < h->room ? n - *done : h->room, d = 0;
    int rc = usb_transfer(h->l, USB_BULK, (unsigned char)h->ep, (void *)(b + *done), k, &d, err);
    *done += d;
    h->room -= d;
    if (rc != T74_OK) return rc;
  }
  return T74_OK;
}

/* Send the filled chunk; acknowledge every command it completed. */
static int send_chunk(struct hpgl *h, struct t74_error *err)
{
  if (h->nbuf == 0) return T74_OK;
  int done = 0;
  int rc = hp_write(h, h->buf, h->nbuf, &done, err);
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
  for (int k = 0; k < len; k++) h->t->commands += cmd[k] == ';';
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
  if (h->usb && check_ready(h, err) != T74_OK) return err->status;
  if (penplan_plan(&h->plan, err) != T74_OK) return err->status;
  for (int k = 0; k < h->plan.nst; k++) {
    const struct pen_stroke *s = &h->plan.st[k];
    char cmd[64];
    int y = h->g.oy + s->y * h->g.pitch;
    long xa = h->g.ox + (long)s->x0 * h->g.pitch, xb = h->g.ox + (long)s->x1 * h->g.pitch;
    double up = hypot((double)(xa - h->px), (double)(y - h->py)) / h->upm;
    double down = labs(xb - xa) / h->upm;
    h->t->device_s += up / h->v_up + 2 * h->lift_s + down / h->v_down;
    h->t->up_mm += up;
    h->t->down_mm += down;
    h->t->strokes++;
    if (up > 0) h->t->pen_moves++;
    preview_to(h->pv, (double)xa, y);
    preview_pen(h->pv, 1);
    preview_to(h->pv, (double)xb, y);
    preview_pen(h->pv, 0);
    h->px = xb;
    h->py = y;
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

/* The value of key (or its short form) in a 1284 device id, into out; 0 when absent. */
static int id_field(const char *id, const char *key, const char *alt, char *out, size_t n)
{
  for (const char *p = id; *p;) {
    const char *colon = strchr(p, ':'), *semi = strchr(p, ';');
    if (!colon || (semi && semi < colon)) break;
    size_t kl = (size_t)(colon - p);
    while (kl && p[0] == ' ') { p++; kl--; }
    const char *end = semi ? semi : colon + strlen(colon);
    if ((strlen(key) == kl && !strncmp(p, key, kl)) || (strlen(alt) == kl && !strncmp(p, alt, kl))) {
      snprintf(out, n, "%.*s", (int)(end - colon - 1), colon + 1);
      return 1;
    }
    if (!semi) break;
    p = semi + 1;
  }
  return 0;
}

/* 1 when a command set list ("HPGL,PCL" ...) names HP-GL (HPGL, HP-GL, HPGL2, HP-GL/2). */
static int names_hpgl(const char *cmds)
{
  char u[256];
  size_t k = 0;
  for (; cmds[k] && k < sizeof u - 1; k++) u[k] = (char)(cmds[k] >= 'a' && cmds[k] <= 'z' ? cmds[k] - 32 : cmds[k]);
  u[k] = 0;
  return strstr(u, "HPGL") || strstr(u, "HP-GL");
}

/* The IEEE 1284 device id string by GET_DEVICE_ID into id ("" when none is given).
   T74_OK, or the error status (in e) of the request. */
static int read_device_id(struct usb_link *l, char *id, size_t n, struct t74_error *e)
{
  unsigned char b[256];
  int got = 0;
  uint16_t idx = (uint16_t)(usb_link_interface(l) << 8 | usb_link_alt(l));
  id[0] = 0;
  int rc = usb_control_in(l, HP_RT_CLASS_IN_IFACE, HP_REQ_GET_DEVICE_ID, 0, idx, b,
                          (int)sizeof b, &got, e);
  if (rc == T74_OK && got >= 2) {
    int len = b[0] << 8 | b[1];                 /* big-endian, the 2 length bytes included */
    if (len > got) len = got;
    if (len > 2) snprintf(id, n, "%.*s", len - 2, (const char *)b + 2);
  }
  return rc;
}

/* GET_DEVICE_ID: the device must declare HP-GL (unless force). */
static int check_device_id(struct hpgl *h, int force, struct t74_error *err)
{
  struct t74_error e = { T74_OK, "" };
  char id[256] = "", cmd[128] = "", mfg[64] = "";
  int rc = read_device_id(h->l, id, sizeof id, &e);
  if (rc != T74_OK && usb_link_gone(h->l)) return t74_fail(err, e.status, "%s", e.msg);
  id_field(id, "MODEL", "MDL", h->model, sizeof h->model);
  id_field(id, "MANUFACTURER", "MFG", mfg, sizeof mfg);
  int has = id_field(id, "COMMAND SET", "CMD", cmd, sizeof cmd);
  if (has && names_hpgl(cmd)) return T74_OK;
  if (force) return T74_OK;
  uint16_t vid, pid;
  usb_link_ids(h->l, &vid, &pid);
  if (!id[0])
    return t74_fail(err, T74_EIO, "hpgl: the printer-class device %04x:%04x gives no device id "
                    "(GET_DEVICE_ID), so it is not known to speak HP-GL; if it is a pen plotter, "
                    "run again with --force", vid, pid);
  return t74_fail(err, T74_EIO, "hpgl: the printer-class device %04x:%04x (%s%s%s) does not "
                  "declare HP-GL: its command set is `%s`. It is probably a printer, not a pen "
                  "plotter; if it does speak HP-GL, run again with --force", vid, pid,
                  mfg[0] ? mfg : "?", " ", h->model[0] ? h->model : "?", has ? cmd : "none given");
}

/* The hard-clip limits: OH where the link answers, else the model's, else the settings. */
static int find_limits(struct hpgl *h, const struct usb_settings *s, struct t74_error *err)
{
  if (h->ep_in >= 0 && s->p[HP_QUERY] > 0) {
    if (put_cmd(h, "OH;", NULL, 0, err) != T74_OK || send_chunk(h, err) != T74_OK)
      return err->status;
    char line[128];
    int n = read_answer(h, s->p[HP_QUERY], line, sizeof line, err);
    if (n < 0) return err->status;
    int c[4];
    if (n && sscanf(line, "%d,%d,%d,%d", &c[0], &c[1], &c[2], &c[3]) == 4 && c[2] > c[0] &&
        c[3] > c[1]) {
      memcpy(h->clip, c, sizeof c);
      h->clip_from = "OH";
      return T74_OK;
    }
  }
  for (size_t k = 0; k < sizeof hp_models / sizeof hp_models[0]; k++)
    if (h->model[0] && !strncmp(h->model, hp_models[k].mdl, strlen(hp_models[k].mdl)) &&
        hp_models[k].sheet == (int)s->p[HP_SHEET]) {
      h->clip[0] = hp_models[k].x0;
      h->clip[1] = hp_models[k].y0;
      h->clip[2] = hp_models[k].x1;
      h->clip[3] = hp_models[k].y1;
      h->clip_from = "the model's documented limits";
      return T74_OK;
    }
  double upm = s->p[HP_UNITS];
  h->clip[0] = (int)(s->p[HP_AREA_X] * upm);
  h->clip[1] = (int)(s->p[HP_AREA_Y] * upm);
  h->clip[2] = (int)((s->p[HP_AREA_X] + s->p[HP_AREA_W]) * upm);
  h->clip[3] = (int)((s->p[HP_AREA_Y] + s->p[HP_AREA_H]) * upm);
  h->clip_from = "the area_* settings";
  return T74_OK;
}

static int hpgl_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                     struct usb_ack ack, struct t74_error *err)
{
  struct hpgl *h = calloc(1, sizeof *h);
  if (!h) return t74_fail(err, T74_EIO, "hpgl: out of memory");
  h->l = l;
  h->ack = ack;
  h->usb = usb_link_kind(l) == USB_LINK_USB;
  h->t = usb_link_tally(l);
  h->pv = usb_link_preview(l);
  h->upm = s->p[HP_UNITS];
  h->v_up = s->p[HP_V_UP];
  h->v_down = s->p[HP_V_DOWN];
  h->lift_s = s->p[HP_LIFT] / 1000.0;
  h->poll_ms = s->p[HP_POLL];
  h->query_ms = s->p[HP_QUERY] > 0 ? s->p[HP_QUERY] : 500;
  int hs = (int)s->p[HP_HANDSHAKE], flow = usb_link_flow(l);
  int serial = usb_link_kind(l) == USB_LINK_SERIAL;
  h->escb = serial && (hs == 1 || (hs == 0 && flow == SERIAL_FLOW_NONE));
  h->ep = usb_link_endpoint(l, USB_BULK, 0);
  h->ep_in = usb_link_endpoint(l, USB_BULK, 1);
  h->chunk = (int)s->p[HP_CHUNK];
  h->buf = malloc((size_t)h->chunk + 64);
  if (!h->buf) {
    hpgl_free(h);
    return t74_fail(err, T74_EIO, "hpgl: out of memory");
  }
  if (h->ep < 0) {
    hpgl_free(h);
    return t74_fail(err, T74_EIO, "hpgl: the printer interface has no bulk OUT endpoint");
  }
  if (h->usb && (check_device_id(h, s->p[HP_FORCE] != 0, err) != T74_OK ||
                 check_ready(h, err) != T74_OK)) {
    hpgl_free(h);
    return err->status;
  }
  if (!h->usb && s->p[HP_LIMITS] == 0)
    snprintf(h->model, sizeof h->model, "7475A");   /* no device id: the reference plotter */
  if (serial && hs == 0 && flow == SERIAL_FLOW_XONXOFF) {
    /* the plotter's Xon-Xoff handshake: Xoff threshold, no enquiry character, DC1 as the
       Xon trigger (ESC.I); DC3 as the Xoff trigger (ESC.N) — device control, not buffered */
    char x[48];
    int n = snprintf(x, sizeof x, "\x1b.I%d;;17:\x1b.N;19:", (int)s->p[HP_XOFF]);
    if (usb_transfer(l, USB_BULK, (unsigned char)h->ep, x, n, NULL, err) != T74_OK) {
      hpgl_free(h);
      return err->status;
    }
  }
  if (put_cmd(h, "IN;", NULL, 0, err) != T74_OK || find_limits(h, s, err) != T74_OK) {
    hpgl_free(h);
    return err->status;
  }
  double upm = s->p[HP_UNITS], m = s->p[HP_MARGIN] * upm;
  h->g = pen_geom_fit(h->clip[0] + m, h->clip[1] + m, h->clip[2] - h->clip[0] - 2 * m,
                      h->clip[3] - h->clip[1] - 2 * m);
  if (h->g.pitch < 1) {
    int st = t74_fail(err, T74_EINPUT, "hpgl: the plotter's limits (%d,%d)..(%d,%d) from %s, "
                      "less margin_mm, hold no picture of 400 x 300 dots", h->clip[0], h->clip[1],
                      h->clip[2], h->clip[3], h->clip_from);
    hpgl_free(h);
    return st;
  }
  double pitch_mm = h->g.pitch / upm;
  int runs = s->p[HP_RUNS] != 0 &&
             penplan_rule(pitch_mm, s->p[HP_V_UP], s->p[HP_V_DOWN], s->p[HP_LIFT]);
  if (penplan_init(&h->plan, (int)s->p[HP_BAND], runs, err) != T74_OK) {
    hpgl_free(h);
    return t74_fail(err, T74_EIO, "hpgl: out of memory");
  }
  preview_area(h->pv, h->clip[0], h->clip[1], h->clip[2], h->clip[3], 1, upm,
               "HP-GL plotter, hard-clip limits in plotter units (40 a mm)");
  preview_at(h->pv, 0, 0);
  char sp[16];
  snprintf(sp, sizeof sp, "SP%d;", (int)s->p[HP_PEN]);
  if (put_cmd(h, sp, NULL, 0, err) != T74_OK || send_chunk(h, err) != T74_OK) {
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

/* For `devices`: does the device declare HP-GL (the check of streaming, without --force)? */
static void hpgl_note(struct usb_link *l, char *out, size_t n)
{
  struct t74_error e = { T74_OK, "" };
  char id[256], cmd[128] = "";
  read_device_id(l, id, sizeof id, &e);
  if (!id[0]) snprintf(out, n, "gives no device id: not known to speak HP-GL (--force)");
  else if (!id_field(id, "COMMAND SET", "CMD", cmd, sizeof cmd))
    snprintf(out, n, "declares no command set: not known to speak HP-GL (--force)");
  else if (names_hpgl(cmd)) snprintf(out, n, "declares HP-GL (command set `%s`)", cmd);
  else snprintf(out, n, "does not declare HP-GL (command set `%s`): a printer? (--force)", cmd);
}

const struct usb_profile usb_profile_hpgl = {
  "hpgl", "HP-GL pen plotter on a USB printer-class interface or RS-232",
  { 0, 0, 7, -1 },              /* any device with a printer-class (7) interface */
  hpgl_params, HP_NPARAMS,
  hpgl_open, hpgl_send, hpgl_flush, hpgl_status, hpgl_close, hpgl_note,
  USB_LINKS(USB_LINK_USB) | USB_LINKS(USB_LINK_SERIAL) | USB_LINKS(USB_LINK_FILE), "HP-GL"
};
