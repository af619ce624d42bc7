/*
** sink.h — the point sink: where lit tube dots go (display stage, paper 003 §4).
**
** This file contains code to pass the picture on, dot by dot, to whatever shows or keeps
** it. Paper 003 §4 drives a binary storage CRT: every perspective-plane point becomes a
** 3x3 or 4x4 cell of dots (patterns/halftone.h) and each lit dot is one beam write. A sink
** receives exactly those writes, in the order the beam would make them. The emulated tube
** memory (display/tube.h), a Tektronix byte stream, a USB plotter profile and a window are
** all sinks; the halftone stage does not know which one it feeds.
**
** THE WHOLE INTERFACE
**
**   struct sink { ctx, point, end, abort }   one small struct of function pointers
**
**     int  point(ctx, x, y)     one lit dot at tube coordinates (x, y): x 0..399 left to
**                               right, y 0..299 bottom to top (as on the CRT; CONTRACT.md).
**                               Returns T74_OK, or an error status (emu/status.h). After an
**                               error the caller stops and calls abort; a sink may keep the
**                               message and report it from end (sticky, first error only).
**     int  end(ctx, err)        the picture is complete: flush / commit. Returns T74_OK or
**                               a status, with its message recorded in err.
**     void abort(ctx)           discard: whatever the sink was going to create (an output
**                               file, a device job) is not left behind.
**
**   Exactly one of end or abort is called, once, after the last point. Any of the three
**   pointers may be NULL, meaning "nothing to do" (point: dot ignored).
**
**   sink_point(s, x, y), sink_end(s, err), sink_abort(s)   NULL-safe callers of the above.
**
**   struct sink_tee   a fan-out: one sink that forwards every call to up to SINK_TEE_MAX
**                     others, in the order they were added.
**       sink_tee_init(&tee); sink_tee_add(&tee, a); sink_tee_add(&tee, b);
**       struct sink s = sink_tee_sink(&tee);   ... feed s ...
**     point: forwarded to each; the first failure is kept (sticky) and returned for this
**            and every later point, which are then no longer forwarded.
**     end:   ends each in order; if one fails, the ones after it are aborted instead and
**            the first failure is returned. Outputs of sinks ended before the failure are
**            already committed: a tee is not a transaction across files.
**     abort: aborts each.
**
** The functions here are small and static inline, so the interface is this header alone.
*/
#ifndef T74_SINK_H
#define T74_SINK_H

#include <stddef.h>
#include "emu/status.h"

/* The tube's addressable points (paper 003 §4; docs/hardware.md: 400 x 300). Every sink
** speaks these coordinates. */
#define TUBE_W 400              /* dots across: x = 0 .. TUBE_W-1, left to right */
#define TUBE_H 300              /* dots up:     y = 0 .. TUBE_H-1, bottom to top */

struct sink {
  void *ctx;                                      /* the sink's own state */
  int  (*point)(void *ctx, int x, int y);         /* one lit tube dot; T74_OK or a status */
  int  (*end)(void *ctx, struct t74_error *err);  /* picture complete: flush / commit */
  void (*abort)(void *ctx);                       /* discard: no output left behind */
};

/* Send one lit dot to s. */
static inline int sink_point(const struct sink *s, int x, int y)
{
  return s->point ? s->point(s->ctx, x, y) : T74_OK;
}

/* Tell s the picture is complete. */
static inline int sink_end(const struct sink *s, struct t74_error *err)
{
  return s->end ? s->end(s->ctx, err) : T74_OK;
}

/* Tell s to discard the picture. */
static inline void sink_abort(const struct sink *s)
{
  if (s->abort) s->abort(s->ctx);
}

/* ---- fan-out ---------------------------------------------------------------------- */

#define SINK_TEE_MAX 8          /* outputs one tee can feed (tube, png, tek, usb, ...) */

struct sink_tee {
  struct sink out[SINK_TEE_MAX];  /* the sinks fed, in the order added */
  int n;                          /* how many of out[] are in use */
  int status;                     /* first failure of a point call, else T74_OK */
};

/* Make t an empty fan-out. */
static inline void sink_tee_init(struct sink_tee *t)
{
  t->n = 0;
  t->status = T74_OK;
}

/* Add s to t's outputs; T74_EINPUT (a usage error of the caller) when t is full. */
static inline int sink_tee_add(struct sink_tee *t, struct sink s)
{
  if (t->n >= SINK_TEE_MAX) return T74_EINPUT;
  t->out[t->n++] = s;
  return T74_OK;
}

static inline int sink_tee_point_(void *ctx, int x, int y)
{
  struct sink_tee *t = ctx;
  if (t->status != T74_OK) return t->status;
  for (int k = 0; k < t->n; k++) {
    int rc = sink_point(&t->out[k], x, y);
    if (rc != T74_OK) return t->status = rc;
  }
  return T74_OK;
}

static inline int sink_tee_end_(void *ctx, struct t74_error *err)
{
  struct sink_tee *t = ctx;
  int first = t->status;          /* first failure: of a point call, else of an end */
  if (first != T74_OK)
    t74_fail(err, first, "sink: picture ended after a failed point write");
  for (int k = 0; k < t->n; k++) {
    if (first != T74_OK) { sink_abort(&t->out[k]); continue; }
    first = sink_end(&t->out[k], err);
  }
  return first;
}

static inline void sink_tee_abort_(void *ctx)
{
  struct sink_tee *t = ctx;
  for (int k = 0; k < t->n; k++) sink_abort(&t->out[k]);
}

/* The sink view of t (t must outlive it). */
static inline struct sink sink_tee_sink(struct sink_tee *t)
{
  struct sink s = { t, sink_tee_point_, sink_tee_end_, sink_tee_abort_ };
  return s;
}

#endif
