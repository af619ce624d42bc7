/*
** plotter.c — an emulated HP-GL pen plotter behind a USB printer-class interface, for
** tests/test_usb_hpgl.c and tests/test_usb_faults.c (#included after usbmock.c).
**
** This file contains code to interpret what display/usb/hpgl.c sends: HP-GL commands ended
** by ';' (IN, SP, PU, PD with absolute x,y pairs; hardware-facts.md "HP-GL pen plotters"),
** arriving on bulk OUT 0x01 in whatever pieces the URBs carry. A dot is drawn when the pen
** goes down (PD) and along every pen-down line; plotter units are turned back into tube
** dots with the profile's default geometry (A4 landscape, 10 mm margins, 40 units/mm:
** pitch 25). It answers the printer-class GET_PORT_STATUS request (0xA1, 1) with a status
** byte the test sets (0x18: selected, no error; 0x38: paper out). It also adds up the
** pen-up travel, so a test can compare the plotted order with the production order.
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
};

MOCK_UNUSED static void plotter_dot(struct plotter *p)
{
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
  else if (!strcmp(op, "SP")) p->pen = nv ? (int)v[0] : 0;
  else if (!strcmp(op, "PU")) {
    p->pen_down = 0;
    if (nv % 2) { p->bad_cmd++; return; }
    for (int k = 0; k < nv; k += 2) {
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
    } else if (p->ncmd < (int)sizeof p->cmd - 1) {
      p->cmd[p->ncmd++] = (char)b[k];
    }
  }
}

MOCK_UNUSED static int plotter_ctrl(struct mock *m, const unsigned char *setup, unsigned char *data, int n)
{
  struct plotter *p = m->user;
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
  p->g = pen_geom_fit(10 * 40, 10 * 40, 277 * 40, 190 * 40);   /* the profile's defaults */
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
