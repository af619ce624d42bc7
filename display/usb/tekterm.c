/*
** tekterm.c — the `tek` profile: a real Tektronix 4010/4014 storage-tube terminal on an
** RS-232 line (`tube74 stream SCENE --device tek --serial /dev/ttyUSB0`; display stage,
** paper 003 §4: the tube's dots on the storage tube that followed the paper's).
**
** This file contains code to send the picture as the PLOT 10 point-plot stream of `tube74
** tek` (display/tek.h: the same header, addresses and omissions, through tek_addr_bytes),
** dot by dot while the scene renders, to a terminal that has no input buffer to speak of.
** Hardware sources: hardware-facts.md "Tektronix 4010/4014 byte stream" (GS, FS point plot,
** ESC FF erase, 4014 extra byte, US back to alpha); the Tektronix 4010 manual (1974) as
** cited by the Wikipedia article "Tektronix 4010": the terminal "lacked any significant data
** buffering", a screen clear takes "on the order of a second", and "it was up to the host
** computer to delay further data to avoid it being lost" (hardware-facts.md: the related
** 613 erases in about 0.9 s).
**
** What is sent:   ESC FF               erase, then NOTHING for erase_ms (bytes sent while
**                                      the tube erases would be lost)
**                 ESC ` GS FS          normal stored beam, graph mode, point plot
**                 an address a dot     HiY [Extra] LoY HiX LoX, unchanged bytes omitted
**                 US                   at the end: alpha mode, as the terminal was found
** The line is paced at the baud (serial.c), so the terminal never gets bytes faster than
** its line carries; no flow control by default (the 4010/4014 has none; --flow if an
** interface or adapter offers it). ACKNOWLEDGED: the address bytes of a dot were written to
** the line. TIME MODEL: erase_ms plus every byte at the baud (the tube stores a point as
** fast as its address arrives).
** A FILE (--to FILE.tek, --dry-run) gets the same bytes (the erase wait only counted).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "display/sink.h"
#include "display/tek.h"
#include "display/usb/preview.h"
#include "display/usb/usb.h"

enum { TK_ERASE, TK_CHUNK, TK_NPARAMS };

static const struct param_row tek_params[TK_NPARAMS] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "erase_ms",    "ms",    1000, 0, 10000, 0, "4010 manual via Wikipedia: a clear takes "
                                               "about a second, the host waits" },
  { "chunk_bytes", "bytes", 64,   1, 4096,  1, "bytes a write (the line paces them); inferred" },
};

#define TK_ERASE_STEP_MS 50     /* the erase wait, in steps that look at the stop flag */

struct tekterm {
  struct usb_link *l;
  struct usb_ack ack;
  int ep;
  struct tek_regs r;
  int started;                  /* the erase and the header have been sent */
  int offline;
  double erase_ms, baud;
  unsigned char *buf;           /* bytes not yet written */
  int nbuf, chunk;
  struct usb_point *pend;       /* their dots, and where each one's address ends in buf */
  int *pend_end;
  int npend, cap;
  struct usb_tally *t;
  struct preview *pv;
};

/* Write the buffer; acknowledge every dot whose address went. */
static int tk_write(struct tekterm *k, struct t74_error *err)
{
  if (k->nbuf == 0) return T74_OK;
  int done = 0;
  int rc = usb_transfer(k->l, USB_BULK, (unsigned char)k->ep, k->buf, k->nbuf, &done, err);
  if (k->baud > 0) k->t->device_s += done * 10.0 / k->baud;
  for (int j = 0; j < k->npend && k->pend_end[j] <= done; j++) k->ack.fn(k->ack.ctx, &k->pend[j]);
  k->nbuf = k->npend = 0;
  return rc;
}

static int tk_put(struct tekterm *k, const unsigned char *b, int n, struct t74_error *err)
{
  if (k->nbuf + n > k->chunk + 8 && tk_write(k, err) != T74_OK) return err->status;
  memcpy(k->buf + k->nbuf, b, (size_t)n);
  k->nbuf += n;
  return T74_OK;
}

/* ESC FF, the wait the erase needs, then the point-plot header. */
static int tk_start(struct tekterm *k, struct t74_error *err)
{
  static const unsigned char erase[] = { TEK_ESC, TEK_FF };
  static const unsigned char head[] = { TEK_ESC, 0x60, TEK_GS, TEK_FS };
  k->started = 1;
  if (tk_put(k, erase, 2, err) != T74_OK || tk_write(k, err) != T74_OK) return err->status;
  k->t->device_s += k->erase_ms / 1000.0;
  if (!k->offline) {
    /* the line is paced: the ESC FF is on the wire within a slice; then nothing until the
       tube has erased */
    for (double w = 0; w < k->erase_ms; w += TK_ERASE_STEP_MS) {
      if (usb_link_stopped(k->l)) return t74_fail(err, T74_EIO, "tek: stopped");
      usb_sleep_ms(k->erase_ms - w < TK_ERASE_STEP_MS ? k->erase_ms - w : TK_ERASE_STEP_MS);
    }
  }
  k->t->commands++;
  return tk_put(k, head, 4, err);
}

static void tk_free(struct tekterm *k)
{
  free(k->buf);
  free(k->pend);
  free(k->pend_end);
  free(k);
}

static int tk_open(void **ctx, struct usb_link *l, const struct usb_settings *s,
                   struct usb_ack ack, struct t74_error *err)
{
  struct tekterm *k = calloc(1, sizeof *k);
  if (!k) return t74_fail(err, T74_EIO, "tek: out of memory");
  k->l = l;
  k->ack = ack;
  k->ep = usb_link_endpoint(l, USB_BULK, 0);
  k->offline = usb_link_kind(l) == USB_LINK_FILE;
  k->erase_ms = s->p[TK_ERASE];
  k->chunk = (int)s->p[TK_CHUNK];
  k->baud = s->link[USB_P_BAUD];
  k->t = usb_link_tally(l);
  k->pv = usb_link_preview(l);
  k->cap = k->chunk + 16;       /* a dot is at least one byte: at most this many pending */
  k->buf = malloc((size_t)k->chunk + 16);
  k->pend = malloc(sizeof *k->pend * (size_t)k->cap);
  k->pend_end = malloc(sizeof *k->pend_end * (size_t)k->cap);
  if (!k->buf || !k->pend || !k->pend_end) {
    tk_free(k);
    return t74_fail(err, T74_EIO, "tek: out of memory");
  }
  tek_regs_reset(&k->r);
  preview_area(k->pv, 0, 0, TEK_ADDR_MAX - 1, TEK_SCREEN_H - 1, 1, 0,
               "Tektronix 4014 screen, 4096 x 3120 addresses");
  *ctx = k;
  return T74_OK;
}

static int tk_send(void *ctx, const struct usb_point *p, int n, struct t74_error *err)
{
  struct tekterm *k = ctx;
  for (int j = 0; j < n; j++) {
    if (!k->started && tk_start(k, err) != T74_OK) return err->status;
    uint8_t b[5];
    size_t m = tek_addr_bytes(&k->r, p[j].x, p[j].y, b);
    if (tk_put(k, b, (int)m, err) != T74_OK) return err->status;
    k->pend[k->npend] = p[j];
    k->pend_end[k->npend++] = k->nbuf;
    k->t->commands++;
    k->t->strokes++;
    k->t->pen_moves++;
    preview_pen(k->pv, 0);
    preview_to(k->pv, tek_addr_of_dot(p[j].x), tek_addr_of_dot(p[j].y));
    preview_pen(k->pv, 1);
    preview_pen(k->pv, 0);
    if (k->nbuf >= k->chunk && tk_write(k, err) != T74_OK) return err->status;
  }
  return T74_OK;
}

static int tk_flush(void *ctx, struct t74_error *err)
{
  return tk_write(ctx, err);
}

static int tk_status(void *ctx, struct usb_status *st, struct t74_error *err)
{
  (void)ctx;
  (void)err;
  memset(st, 0, sizeof *st);
  st->ready = 1;
  snprintf(st->text, sizeof st->text, "a terminal has no status to ask");
  return T74_OK;
}

/* Back to alpha mode (an empty picture: an erased screen). */
static void tk_close(void *ctx, int clean)
{
  struct tekterm *k = ctx;
  struct t74_error e = { T74_OK, "" };
  static const unsigned char us[] = { TEK_US };
  if (!usb_link_gone(k->l)) {
    if (!clean) k->nbuf = k->npend = 0;         /* stopping: what waits stays unsent */
    int st = T74_OK;
    if (clean && !k->started) st = tk_start(k, &e);
    if (st == T74_OK && k->started && tk_put(k, us, 1, &e) == T74_OK) tk_write(k, &e);
  }
  tk_free(k);
}

const struct usb_profile usb_profile_tek = {
  "tek", "Tektronix 4010/4014 storage-tube terminal on RS-232 (PLOT 10 point plot)",
  { 0, 0, -1, -1 },             /* no USB device: --serial (or --to / --dry-run) only */
  tek_params, TK_NPARAMS,
  tk_open, tk_send, tk_flush, tk_status, tk_close, NULL,
  USB_LINKS(USB_LINK_SERIAL) | USB_LINKS(USB_LINK_FILE), "Tektronix PLOT 10 stream"
};
