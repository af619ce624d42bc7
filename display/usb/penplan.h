/*
** penplan.h — the pen plotters' plan: dots of one row band joined into strokes and put in
** a short drawing order (shared by the hpgl and ebb USB profiles; paper 003 §4 dots on a pen
** plotter instead of a storage tube).
**
** This file contains code to turn the tube's dots, which arrive in production order (cell
** by cell, as the 1974 program displayed them), into pen work. A pen plotter pays for every
** pen lift and every pen-up move, so:
**
**  1. BANDS. Dots are buffered per band of `band_rows` tube rows (rows 299-y counted from
**     the top, band = (299 - y) / band_rows; 12 rows hold whole cells of both 3x3 and 4x4
**     halftones). When a dot of another band arrives the buffered band is planned and sent.
**     This keeps streaming (the first stroke leaves after one band, not after the picture)
**     while giving the planner whole rows to work with.
**  2. STROKES. A run of k lit dots side by side on a row (x, x+1, ... x+k-1) is drawn as ONE
**     pen-down stroke when that is faster than k separate dots. With p the dot pitch (mm),
**     v_down / v_up the pen-down / pen-up speeds (mm/s) and t_lift the time of one pen
**     lift or drop (s):
**         k dots:    k * 2 t_lift + (k-1) p / v_up
**         a stroke:  2 t_lift + (k-1) p / v_down
**     so the stroke wins for every k >= 2 exactly when   2 t_lift + p / v_up > p / v_down
**     (the rule does not depend on k). `runs = 0` turns strokes off (dots only).
**  3. ORDER. Within the band, strokes are drawn nearest-first (greedy): from where the pen
**     is, the stroke with the nearest END (either end: a stroke may be drawn right to left)
**     goes next. O(n^2) in the strokes of one band, at most 400 * band_rows / 2 of them.
**
** Every dot is in exactly one stroke; a stroke's dots are listed in drawing order, so a
** profile can acknowledge each dot the moment the command that draws it is acknowledged.
*/
#ifndef T74_PENPLAN_H
#define T74_PENPLAN_H

#include "display/usb/usb.h"

struct pen_geom {               /* where dots land, in device units (plotter units, steps) */
  int pitch;                    /* units between neighbouring dots */
  int ox, oy;                   /* position of dot (0, 0) */
};

/* The largest whole pitch that fits the 400 x 300 dots into an area of w x h units
** starting at (x0, y0), the picture centred in it. */
struct pen_geom pen_geom_fit(double x0, double y0, double w, double h);

struct pen_stroke {
  int y;                        /* tube row */
  int x0, x1;                   /* drawn from dot x0 to dot x1 (x1 < x0: right to left) */
  int first, n;                 /* its dots: pts[first .. first+n-1] in drawing order */
};

struct penplan {
  int band_rows;                /* rows per band */
  int band;                     /* band being buffered, -1 for none */
  int runs;                     /* join runs into strokes (the rule of 2. said yes) */
  struct usb_point *in;         /* buffered dots of the band */
  int nin, capin;
  struct usb_point *pts;        /* planned: dots in drawing order */
  struct pen_stroke *st;        /* planned: strokes in drawing order */
  int nst;
  int pen_x, pen_y;             /* where the pen is, in dots (after the last plan) */
};

/* Set up pp. runs: decided by penplan_rule. T74_EIO when out of memory. */
int penplan_init(struct penplan *pp, int band_rows, int runs, struct t74_error *err);
void penplan_free(struct penplan *pp);

/* The rule of 2.: 1 when strokes are faster, for pitch_mm, speeds in mm/s, lift in ms. */
int penplan_rule(double pitch_mm, double v_up, double v_down, double lift_ms);

/* 1 when p belongs to another band than the buffered one (plan and emit first). */
int penplan_new_band(const struct penplan *pp, const struct usb_point *p);
/* Buffer p. */
int penplan_add(struct penplan *pp, const struct usb_point *p, struct t74_error *err);
/* Plan the buffered band: fills pts / st / nst and empties the buffer. */
int penplan_plan(struct penplan *pp, struct t74_error *err);

#endif
