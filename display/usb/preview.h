/*
** preview.h — an SVG picture of the path a device's pen or beam takes (`tube74 stream
** --svg FILE`; display stage, paper 003 §4: where each dot of the tube went on the device).
**
** This file contains code to record, in the device's own units, every move a profile
** commands — pen down or up (HP-GL PD / PU, EBB SP), beam lit or blanked (Helios points,
** Tektronix point plot) — and to write it as one SVG 1.1 file:
**
**   preview_new(&p, err)                     an empty preview
**   preview_area(p, x0, y0, x1, y1, y_up, per_mm, what)
**                                            the device's drawing area (hard-clip limits,
**                                            paper, DAC field, screen) in its units; y_up:
**                                            its y grows upwards (HP-GL, Helios, Tek) or
**                                            downwards (EBB steps from the home corner);
**                                            per_mm: units a millimetre, 0 when the device
**                                            has no physical scale (the SVG is then 800 px wide)
**   preview_at(p, x, y)                      where the pen / beam starts
**   preview_pen(p, down)                     pen down (beam on) / up (blanked)
**   preview_to(p, x, y)                      move there: drawn when down, a travel when up
**   preview_write(p, of, title, err)         the SVG onto an output (display/outfile.h)
**   preview_free(p)
** Every call is NULL-safe on p (no --svg: the profiles call the same functions on NULL).
**
** THE SVG: the area as a light rectangle; pen-up travel as one thin dashed blue path; the
** drawing as one black path with round caps, so that a dot (pen down and up again without
** a move) is a zero-length subpath "M x y h0", shown as a round dot of the pen's width (the
** SVG 1.1 rule for zero-length subpaths with round caps). Coordinates are the device's,
** flipped in y when y_up, so the picture is the right way up; width and height are in mm
** when per_mm is known, so the file prints at the plot's size. A <title> and a <desc>
** (escaped) name the device and the figures.
*/
#ifndef T74_PREVIEW_H
#define T74_PREVIEW_H

#include "display/outfile.h"
#include "emu/status.h"

struct preview;

int preview_new(struct preview **out, struct t74_error *err);
void preview_free(struct preview *p);
void preview_area(struct preview *p, double x0, double y0, double x1, double y1, int y_up,
                  double per_mm, const char *what);
void preview_at(struct preview *p, double x, double y);
void preview_pen(struct preview *p, int down);
void preview_to(struct preview *p, double x, double y);
/* desc: a line of figures for the <desc> element (may be NULL). T74_OK or T74_EIO. */
int preview_write(const struct preview *p, struct outfile *of, const char *title,
                  const char *desc, struct t74_error *err);

#endif
