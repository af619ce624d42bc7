/*
** plotter.c — an emulated HP-GL pen plotter behind a USB printer-class interface, for
** tests/test_usb_hpgl.c and tests/test_usb_faults.c (#included after usbmock.c).
**
** This file contains code to interpret what display/usb/hpgl.c sends: HP-GL commands ended
** by ';' (IN, SP, PU, PD with absolute x,y pairs, OH; docs/hardware.md "HP-GL pen plotters"),
** arriving on bulk OUT 0x01 in whatever pieces the URBs carry. Modelled on the HP 7475A
** manual: the origin is the lower left hard-clip corner; a point outside the hard-clip
** limits (A4: 0..11040 x 0..7721) is clipped, not drawn (counted); OH answers the limits as
** "XLL,YLL,XUR,YUR" CR on bulk IN 0x82 (a bidirectional link; `answers` = 0 plays a one-way
** adapter). It answers the printer-class GET_DEVICE_ID request (0xA1, 0: a 2-byte big-endian
** length, then the IEEE 1284 id; USB Printer Class 1.1 §4.2.1) with the id the test sets,
** and GET_PORT_STATUS (0xA1, 1) with a status byte (0x18: selected, no error; 0x38: paper
** out). A dot is drawn when the pen goes down (PD) and along every pen-down line; plotter
** units are turned back into tube dots with the geometry the test expects (`g`: by default
** the 7475A's A4 limits less 5 mm, the profile's rule). It also adds up the pen-up travel,
** so a test can compare the plotted order with the production order.
*/
#include <math.h>

#include "display/usb/penplan.h"
#include "display/sink.h"

struct plotter {                /* under m->lock */
  char cmd[96];
  int ncmd;
  struct pen_geom g;
  long X, Y;
  int pen_down, pen;
  struct dots drawn;
  int strokes, singles, bad_cmd, off_grid, inits, status_queries;
  double travel;                /* pen-up travel, in dots */
  unsigned char port_status;
  int paper_out_at;             /* from this status query on: paper out (0: never) */
  char last[96];                /* the last command */
  double t_first_dot;           /* when the first dot was drawn */
  int clip[4];                  /* hard-clip limits: xll, yll, xur, yur */
  int clipped;                  /* points outside them (not drawn) */
  int answers;                  /* 1: OH is answered on bulk IN 0x82 */
  int oh_queries, id_queries;
  char id[200];                 /* the IEEE 1284 device id */
};

MOCK_UNUSED static int plotter_inside(const struct plotter *p, long X, long Y)
{
  return X >= p->clip[0] && X <= p->clip[2] && Y >= p->clip[1] && Y <= p->clip[3];
}

MOCK_UNUSED static void plotter_dot(struct plotter *p)
{
  if (!plotter_inside(p, p->X, p->Y)) { p->clipped++; return; }
  long dx = p->X - p->g.ox, dy = p->Y - p->g.oy;
  if (dx % p->g.pitch || dy % p->g.pitch) { p->off_grid++; return; }
  if (p->t_first_dot == 0) p->t_first_dot = mock_now();
  dots_add(&p->drawn, (int)(dx / p->g.pitch), (int)(dy / p->g.pitch));
}

MOCK_UNUSED static void plotter_exec(struct plotter *p, char *c)
{
  snprintf(p->last, sizeof p->last, "%s", c);
  char op[3] = { c[0], c[1], 0 };
  long v[32];
  int nv = 0;
  for (char *s = c + 2; *s && nv < 32;) {
    char *end;
    v[nv] = strtol(s, &end, 10);
    if (end == s) { p->bad_cmd++; return; }
    nv++;
    s = *end == ',' ? end + 1 : end;
    if (*end && *end != ',') { p->bad_cmd++; return; }
  }
  if (!strcmp(op, "IN")) { p->inits++; p->pen_down = 0; p->X = p->Y = 0; }
  else if (!strcmp(op, "OH")) p->oh_queries++;
  else if (!strcmp(op, "SP")) p->pen = nv ? (int)v[0] : 0;
  else if (!strcmp(op, "PU")) {
    p->pen_down = 0;
    if (nv % 2) { p->bad_cmd++; return; }
    for (int k = 0; k < nv; k += 2) {
      if (!plotter_inside(p, v[k], v[k + 1])) p->clipped++;
      p->travel += hypot((double)(v[k] - p->X), (double)(v[k + 1] - p->Y)) / p->g.pitch;
      p->X = v[k];
      p->Y = v[k + 1];
    }
  } else if (!strcmp(op, "PD")) {
    if (nv % 2 || !p->pen) { p->bad_cmd++; return; }
    if (!p->pen_down) plotter_dot(p);
    p->pen_down = 1;
    if (nv == 0) p->singles++;
    else p->strokes++;
    for (int k = 0; k < nv; k += 2) {          /* lines: along a row only, dot by dot */
      if (v[k + 1] != p->Y || (v[k] - p->X) % p->g.pitch) { p->bad_cmd++; return; }
      long dir = v[k] > p->X ? p->g.pitch : -p->g.pitch;
      while (p->X != v[k]) { p->X += dir; plotter_dot(p); }
    }
  } else p->bad_cmd++;
}

MOCK_UNUSED static void plotter_out(struct mock *m, unsigned char ep, const unsigned char *b, int n)
{
  struct plotter *p = m->user;
  if (ep != 0x01) return;
  for (int k = 0; k < n; k++) {
    if (b[k] == ';') {
      p->cmd[p->ncmd] = 0;
      plotter_exec(p, p->cmd);
      p->ncmd = 0;
      if (!strcmp(p->last, "OH") && p->answers) {
        char r[64];
        int len = snprintf(r, sizeof r, "%d,%d,%d,%d\r", p->clip[0], p->clip[1], p->clip[2], p->clip[3]);
        mock_reply(m, 0x82, r, len);
      }
    } else if (p->ncmd < (int)sizeof p->cmd - 1) {
      p->cmd[p->ncmd++] = (char)b[k];
    }
  }
}

MOCK_UNUSED static int plotter_ctrl(struct mock *m, const unsigned char *setup, unsigned char *data, int n)
{
  struct plotter *p = m->user;
  if (setup[0] == 0xA1 && setup[1] == 0) {             /* GET_DEVICE_ID */
    int len = (int)strlen(p->id) + 2;
    p->id_queries++;
    if (!p->id[0]) return -1;                          /* not supported: stall */
    unsigned char full[256];
    full[0] = (unsigned char)(len >> 8);
    full[1] = (unsigned char)len;
    memcpy(full + 2, p->id, (size_t)len - 2);
    int give = len < n ? len : n;
    memcpy(data, full, (size_t)give);
    return give;
  }
  if (setup[0] == 0xA1 && setup[1] == 1 && n >= 1) {   /* GET_PORT_STATUS */
    p->status_queries++;
    if (p->paper_out_at && p->status_queries >= p->paper_out_at) p->port_status = 0x38;
    data[0] = p->port_status;
    return 1;
  }
  return -1;                                           /* anything else: stall */
}

/* A fresh plotter (keeps the drawn list's memory). */
MOCK_UNUSED static void plotter_clear(struct plotter *p)
{
  struct dots keep = p->drawn;
  memset(p, 0, sizeof *p);
  p->drawn = keep;
  p->drawn.n = 0;
  p->clip[0] = 0;                                      /* 7475A manual: A4 hard-clip */
  p->clip[1] = 0;
  p->clip[2] = 11040;
  p->clip[3] = 7721;
  p->answers = 1;
  snprintf(p->id, sizeof p->id, "MFG:Hewlett-Packard;MDL:7475A;CMD:HP-GL;CLS:PLOTTER;"
           "DES:HP 7475A Graphics Plotter;");
  /* the picture the profile should fit: inside the limits less 5 mm (200 units) */
  p->g = pen_geom_fit(200, 200, 11040 - 400, 7721 - 400);
  p->port_status = 0x18;
}

/* Pen-up travel, in dots, of drawing d's dots one by one in its order from (0, 0). */
MOCK_UNUSED static double travel_in_order(const struct dots *d)
{
  double t = 0;
  int x = 0, y = 0;
  for (int k = 0; k < d->n; k++) {
    t += hypot(d->xy[k][0] - x, d->xy[k][1] - y);
    x = d->xy[k][0];
    y = d->xy[k][1];
  }
  return t;
}
