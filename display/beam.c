/*
** beam.c — the writing beam's timing (see beam.h).
** Sources: paper 003 appendix (21 cm x 16.3 cm face, 400 x 300 points); docs/hardware.md
** "The storage tube" (Tektronix 613: settling to 0.025 cm takes 14 us + 6 us/cm for moves
** up to 2 cm, then 3 us/cm for longer moves).
**
** This file contains code to time each beam write. A move from dot a to dot b covers the
** straight distance between them on the face: with a pitch of 21/400 = 0.0525 cm across
** and 16.3/300 = 0.0543 cm up, d = sqrt((dx * 0.0525)^2 + (dy * 0.0543)^2) cm. The 613
** figure is read as one continuous curve:
**
**     settle(d) = 14 us + 6 us/cm * min(d, 2 cm) + 3 us/cm * max(d - 2 cm, 0)      d > 0
**     settle(0) = 0      (the beam is already there: nothing to settle)
**
** (The 613 text says "for larger movements 3 us per cm"; read as the whole move it would
** make a 3 cm move faster than a 2 cm one, so the 3 us/cm is taken as the rate beyond
** 2 cm.) The dwell is not documented anywhere we found; see its row.
*/
#include "display/beam.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "display/sink.h"

/* One row per constant: name, unit, default, accepted range, whole numbers only, source. */
const struct param_row beam_param_rows[BP_NPARAM] = {
  [BP_FACE_W_CM]         = { "face_w_cm", "cm", 21.0, 1, 100, 0,
                             "paper 003 appendix: screen 21 cm x 16.3 cm, 400 points across" },
  [BP_FACE_H_CM]         = { "face_h_cm", "cm", 16.3, 1, 100, 0,
                             "paper 003 appendix: screen 21 cm x 16.3 cm, 300 points up" },
  [BP_SETTLE_BASE_US]    = { "settle_base_us", "us", 14.0, 0, 1e6, 0,
                             "Tektronix 613 (1973): settling to 0.025 cm takes 14 us + 6 us/cm" },
  [BP_SETTLE_NEAR_US_CM] = { "settle_near_us_cm", "us/cm", 6.0, 0, 1e6, 0,
                             "Tektronix 613: 6 us per cm for moves up to 2 cm" },
  [BP_SETTLE_NEAR_CM]    = { "settle_near_cm", "cm", 2.0, 0, 100, 0,
                             "Tektronix 613: the 6 us/cm rate holds up to 2 cm" },
  [BP_SETTLE_FAR_US_CM]  = { "settle_far_us_cm", "us/cm", 3.0, 0, 1e6, 0,
                             "Tektronix 613: 3 us per cm for longer moves (read as the rate "
                             "beyond 2 cm, so settling grows with distance)" },
  [BP_DWELL_US]          = { "dwell_us", "us", 10.0, 0, 1e6, 0,
                             "inferred: no figure found for the time a bistable tube needs to "
                             "store one dot; taken of the order of the 613's shortest settle "
                             "(14 us), so a dot next to the last costs about 24 us (~40,000 "
                             "dots/s), the same order as one HITAC-10 display command loop" },
  [BP_HOME_X]            = { "home_x", "point", 0, 0, TUBE_W - 1, 1,
                             "inferred: the beam starts at the lower-left corner (after erase)" },
  [BP_HOME_Y]            = { "home_y", "point", 0, 0, TUBE_H - 1, 1,
                             "inferred: the beam starts at the lower-left corner (after erase)" },
};

void beam_params_default(struct beam_params *p)
{
  param_defaults(beam_param_rows, BP_NPARAM, p->v);
}

int beam_params_set(struct beam_params *p, const char *s, struct t74_error *err)
{
  const char *eq = strchr(s, '=');
  if (!eq) return t74_fail(err, T74_EINPUT, "beam: expected NAME=VALUE, got `%s`", s);
  size_t n = (size_t)(eq - s);
  int k = param_find(beam_param_rows, BP_NPARAM, s, n);
  if (k < 0)
    return t74_fail(err, T74_EINPUT, "beam: unknown constant `%.*s` (see `tube74 play --list`)",
                    (int)n, s);
  const struct param_row *r = &beam_param_rows[k];
  if (param_parse(r, eq + 1, &p->v[k]) != PARAM_OK)
    return t74_fail(err, T74_EINPUT, "beam: %s takes a %s in %g .. %g %s, got `%s`", r->name,
                    r->integer ? "whole number" : "number", r->min, r->max, r->unit, eq + 1);
  return T74_OK;
}

int beam_params_list(const struct beam_params *p, FILE *f)
{
  param_list(beam_param_rows, BP_NPARAM, p->v, 18, f);
  return ferror(f) ? T74_EIO : T74_OK;
}

double beam_settle_us(const struct beam_params *p, double cm)
{
  if (cm <= 0) return 0;
  double near = p->v[BP_SETTLE_NEAR_CM];
  double a = cm < near ? cm : near;         /* part of the move at the near rate */
  double b = cm > near ? cm - near : 0;     /* part beyond */
  return p->v[BP_SETTLE_BASE_US] + p->v[BP_SETTLE_NEAR_US_CM] * a + p->v[BP_SETTLE_FAR_US_CM] * b;
}

double beam_distance_cm(const struct beam_params *p, int x0, int y0, int x1, int y1)
{
  double dx = (x1 - x0) * p->v[BP_FACE_W_CM] / TUBE_W;
  double dy = (y1 - y0) * p->v[BP_FACE_H_CM] / TUBE_H;
  return sqrt(dx * dx + dy * dy);
}

void beam_init(struct beam *b, const struct beam_params *p)
{
  memset(b, 0, sizeof *b);
  b->p = *p;
  b->x = (int)p->v[BP_HOME_X];
  b->y = (int)p->v[BP_HOME_Y];
}

double beam_dot(struct beam *b, int x, int y, double compute_s)
{
  beam_clock(b, compute_s);
  double start = compute_s > b->free_s ? compute_s : b->free_s;
  double busy = (beam_settle_us(&b->p, beam_distance_cm(&b->p, b->x, b->y, x, y)) +
                 b->p.v[BP_DWELL_US]) * 1e-6;
  b->tube_s += busy;
  b->free_s = start + busy;
  b->x = x;
  b->y = y;
  b->dots++;
  return b->free_s;
}

void beam_clock(struct beam *b, double compute_s)
{
  if (compute_s > b->compute_s) b->compute_s = compute_s;
}

void beam_wait(struct beam *b, double until_s)
{
  if (until_s > b->free_s) b->free_s = until_s;
}

double beam_tube_seconds(const struct beam *b) { return b->tube_s; }

double beam_total_seconds(const struct beam *b)
{
  return b->free_s > b->compute_s ? b->free_s : b->compute_s;
}

uint64_t beam_dots(const struct beam *b) { return b->dots; }
