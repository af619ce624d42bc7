/*
** ebb.c — an emulated EiBotBoard (AxiDraw) on its CDC data endpoints, for tests/test_usb_ebb.c
** (#included after usbmock.c). It models the firmware as its documentation describes it,
** not as display/usb/ebb.c uses it.
**
** This file contains code to play the board. Sources (docs/usb.md has the list):
**   EBB command reference (evil-mad/EggBot docs/ebb.html): commands end in CR, answered
**     "OK\r\n"; SC and QM execute at once, EM, SP and SM go through the motion FIFO; with the
**     boot FIFO of one command there are at most three motion commands in play — one
**     running, one in the FIFO, one held in the USB parser, which answers nothing (not even
**     QM) until the FIFO has room: OK means QUEUED; QM answers
**     "QM,CommandStatus,Motor1,Motor2,FIFOStatus\n\r"; SM at most 25,000 steps/s; SP,v,ms
**     moves the servo to SC,4 (v = 1) or SC,5 (v = 0) and holds the next motion command ms;
**     servo position changes by the rate (SC,11 up / SC,12 down) each servo period of
**     channels x 3 ms (SC,8; 8 at boot: 24 ms); EM,m,m sets the step mode (1 = 1/16 .. 5 =
**     full), EM,0,0 turns the motors off;
**   EBB firmware RCServo2.c: at reset pen-up 22565, pen-down 15302, both rates 400;
**   AxiDraw software: 2032 steps per inch at 1/16 step along X or Y on each motor, motor 1
**     = X + Y, motor 2 = X - Y (so 1/8 step is 1016 steps per inch).
** The board runs its motion clock `speed` times faster than real time and skips ahead while
** the host waits for a reply that only the motion queue can free, so a run takes the host's
** time, not the plotter's; every check below is on the order of events, none on real time.
** Checks: a dot is INKED when SP,0's wait covers the servo's travel to pen-down (the board
** guarantees no more than that wait before the next motion); a pen-down SM draws the dots
** on its path only while the pen is down; a move that starts before SP,1's wait covers the
** servo's travel to pen-up drags the pen (a stray line); a step-rate change between two SMs
** larger than a_lim x their mean duration (from rest or to rest: half the SM's duration)
** loses steps — a_lim is inferred (twice the AxiDraw software's own pen-up acceleration on
** a motor axis), the documentation gives none. Dots are recorded when the command that
** draws them has RUN; positions in 1/16-step units (0.0125 mm).
*/
#include <math.h>

#include "display/sink.h"
#include "display/usb/penplan.h"

#define BD_FIFO   1             /* EBB: the FIFO is one command deep at boot */
#define BD_UNIT16 (25.4 / 2032) /* mm per 1/16 step (AxiDraw: 2032 steps/inch) */

struct bcmd {                   /* a motion command in the board */
  char op;                      /* 'M' SM, 'P' SP, 'E' EM */
  long ms, a, b;                /* SM: duration, motor steps; SP: value in a, wait in ms;
                                   EM: modes in a, b */
  double start, end;            /* board time, ms */
  int seq;                      /* its number among the commands received */
  int drawing;                  /* SM: the pen was down when it started */
};

struct board {                  /* the emulated EBB (under m->lock) */
  GByteArray *inbuf;            /* received bytes not yet parsed */
  double t0, ff, speed;         /* board time = (now - t0) * 1000 * speed + ff, ms */
  double cursor;                /* board time of the last event */
  struct bcmd exec, fifo[BD_FIFO];
  int running, nfifo;
  /* state */
  long A, B;                    /* motor positions, in their current step mode's steps */
  int mode1;                    /* step mode of EM: 1 = 1/16 .. 5 = full */
  int motors_on;
  int servo_up_pos, servo_down_pos, rate_up, rate_down, channels;
  int servo_pos;                /* the servo's target reached (pulse units) */
  int pen_down;                 /* last SP was SP,0 and its wait covered the travel */
  int lowered;                  /* last SP was SP,0 */
  int raise_short;              /* last SP was SP,1 whose wait did not cover the travel */
  double va, vb, vdur;          /* step rates (steps/s) and duration (s) of the SM before;
                                   vdur 0: motors at rest */
  struct pen_geom g;            /* the dot grid, in 1/16 steps (the profile's defaults) */
  int corexy;
  /* records */
  struct dots drawn;            /* tube dots inked, in the order they were drawn */
  long min16x, max16x, min16y, max16y;  /* extent of the inked dots, 1/16 steps */
  int received, executed, bad_cmd, bad_rate, accel_viol, stray, uninked, off_grid, qm;
  int sm_after_garbage, em_off_after_garbage;  /* sent after the host saw the garbage */
  long long replied, delivered, garbage_end;      /* reply bytes queued / taken by the host */
  int host_saw_garbage;
  int garbage_at, garbage_sent;
  int vanish_after;             /* vanish when this many motion commands have run (0 never) */
  int sc4, sc5, sc11, sc12, sc8;        /* what SC set (0: never) */
  double t_first_dot;
  double t_last_end;            /* board time when the last command finished, ms */
  double a_lim;                 /* steps/s^2 on a motor axis, 1/16 steps */
};

static double bd_now(struct board *b)
{
  return (mock_now() - b->t0) * 1000.0 * b->speed + b->ff;
}

static long bd_scale(const struct board *b) { return 1L << (b->mode1 - 1); }  /* to 1/16 */

static void bd_ink(struct board *b, long X16, long Y16)
{
  long dx = X16 - b->g.ox, dy = Y16 - b->g.oy;
  if (dx % b->g.pitch || dy % b->g.pitch || dx < 0 || dy < 0) { b->off_grid++; return; }
  if (b->t_first_dot == 0) b->t_first_dot = mock_now();
  dots_add(&b->drawn, (int)(dx / b->g.pitch), TUBE_H - 1 - (int)(dy / b->g.pitch));
  if (b->drawn.n == 1 || X16 < b->min16x) b->min16x = X16;
  if (b->drawn.n == 1 || X16 > b->max16x) b->max16x = X16;
  if (b->drawn.n == 1 || Y16 < b->min16y) b->min16y = Y16;
  if (b->drawn.n == 1 || Y16 > b->max16y) b->max16y = Y16;
}

/* Pen position in 1/16 steps. */
static long bd_X(const struct board *b)
{
  return (b->corexy ? (b->A + b->B) / 2 : b->A) * bd_scale(b);
}
static long bd_Y(const struct board *b)
{
  return (b->corexy ? (b->A - b->B) / 2 : b->B) * bd_scale(b);
}

/* The servo's travel time to target, ms: rate pulse units per period. */
static double bd_travel(const struct board *b, int target, int rate)
{
  double period = 3.0 * b->channels;
  long d = labs((long)target - b->servo_pos);
  if (d == 0) return 0;
  return rate > 0 ? ceil((double)d / rate) * period : period;
}

/* A motion command starts: servo moves, acceleration checks. */
static void bd_start(struct board *b, struct bcmd *c, double t)
{
  c->start = t;
  c->end = t + (c->op == 'M' ? c->ms : c->op == 'P' ? c->ms : 0);
  if (c->op == 'M') {
    double d = c->ms / 1000.0;
    double va = c->a / d * bd_scale(b), vb = c->b / d * bd_scale(b);
    double lim = b->a_lim * (d + b->vdur) / 2;
    if (fabs(va - b->va) > lim || fabs(vb - b->vb) > lim) b->accel_viol++;
    b->va = va;
    b->vb = vb;
    b->vdur = d;
    if ((c->a || c->b) && b->raise_short && !b->lowered) b->stray++;
    b->raise_short = 0;
    c->drawing = b->lowered && b->pen_down;
  } else {
    double lim = b->a_lim * b->vdur / 2;        /* the SM before stopped the motors */
    if (fabs(b->va) > lim || fabs(b->vb) > lim) b->accel_viol++;
    b->va = b->vb = b->vdur = 0;
  }
  if (c->op == 'P') {
    int up = c->a == 1;
    int target = up ? b->servo_up_pos : b->servo_down_pos;
    double need = bd_travel(b, target, up ? b->rate_up : b->rate_down);
    b->servo_pos = target;
    b->lowered = !up;
    b->pen_down = !up && c->ms >= need;
    b->raise_short = up && c->ms < need;
    if (!up && !b->pen_down) b->uninked++;      /* the carriage moves before the pen lands */
  }
}

/* A motion command has run: its effects. */
static void bd_complete(struct mock *m, struct board *b, struct bcmd *c)
{
  if (c->op == 'M') {
    long x0 = bd_X(b);
    b->A += c->a;
    b->B += c->b;
    if (b->corexy && (b->A + b->B) % 2) {
      b->bad_cmd++;
      if (getenv("EBB_TRACE")) fprintf(stderr, "board: odd SM %ld %ld\n", c->a, c->b);
    }
    long x1 = bd_X(b), y1 = bd_Y(b);
    if (c->drawing && (c->a || c->b)) {         /* drawing: along a row only */
      if (b->corexy && c->a != c->b) {
        b->bad_cmd++;
        if (getenv("EBB_TRACE")) fprintf(stderr, "board: pen-down SM off the row %ld %ld\n", c->a, c->b);
      }
      long dir = x1 > x0 ? 1 : -1;
      for (long x = x0 + dir; x1 != x0; x += dir) {
        long dx = x - b->g.ox;
        if (dx >= 0 && dx % b->g.pitch == 0) bd_ink(b, x, y1);
        if (x == x1) break;
      }
    }
  } else if (c->op == 'P') {
    if (c->a == 0 && b->pen_down) bd_ink(b, bd_X(b), bd_Y(b));
  } else if (c->op == 'E') {
    b->motors_on = c->a != 0 || c->b != 0;
    if (c->a) b->mode1 = (int)c->a;
  }
  b->executed++;
  b->t_last_end = c->end;
  if (b->vanish_after && b->executed == b->vanish_after) {
    b->running = b->nfifo = 0;
    g_byte_array_set_size(b->inbuf, 0);
    vanish(m);
  }
}

static void bd_reply(struct mock *m, const char *s)
{
  struct board *b = m->user;
  mock_reply_stream(m, 0x82, s, (int)strlen(s));   /* CDC: a byte stream */
  b->replied += (long long)strlen(s);
}

static void board_in(struct mock *m, unsigned char ep, int n)
{
  struct board *b = m->user;
  if (ep != 0x82) return;
  b->delivered += n;
  if (b->garbage_sent && b->delivered >= b->garbage_end) b->host_saw_garbage = 1;
}

/* Take one command from the parser; 0 when it must wait (FIFO full) or none is there. */
static int bd_parse_one(struct mock *m, struct board *b, double t)
{
  if (b->inbuf->len == 0) return 0;
  guint8 *cr = memchr(b->inbuf->data, '\r', b->inbuf->len);
  if (!cr) return 0;
  char cmd[128];
  int len = (int)(cr - b->inbuf->data);
  snprintf(cmd, sizeof cmd, "%.*s", len < 127 ? len : 127, (const char *)b->inbuf->data);
  int queued = !strncmp(cmd, "SM,", 3) || !strncmp(cmd, "SP,", 3) || !strncmp(cmd, "EM,", 3);
  if (queued && b->running && b->nfifo == BD_FIFO) return 0;   /* held in the parser */
  g_byte_array_remove_range(b->inbuf, 0, (guint)len + 1);
  b->received++;
  if (b->garbage_at && b->received == b->garbage_at) {
    bd_reply(m, "!8 Err: Unknown command\r\n");  /* noise on the line: the command is lost */
    b->garbage_sent = 1;
    b->garbage_end = b->replied;
    return 1;
  }
  struct bcmd c;
  memset(&c, 0, sizeof c);
  c.seq = b->received;
  long v1, v2, v3;
  int n;
  if (!strcmp(cmd, "QM")) {
    char r[40];
    b->qm++;
    snprintf(r, sizeof r, "QM,%d,%d,%d,%d\n\r", b->running,
             b->running && b->exec.op == 'M' && b->exec.a != 0,
             b->running && b->exec.op == 'M' && b->exec.b != 0, b->nfifo > 0);
    bd_reply(m, r);
    return 1;
  }
  if (sscanf(cmd, "SC,%ld,%ld", &v1, &v2) == 2) {
    if (v1 == 4) b->servo_up_pos = (int)(b->sc4 = (int)v2);
    else if (v1 == 5) b->servo_down_pos = (int)(b->sc5 = (int)v2);
    else if (v1 == 10) b->rate_up = b->rate_down = (int)v2;
    else if (v1 == 11) b->rate_up = (int)(b->sc11 = (int)v2);
    else if (v1 == 12) b->rate_down = (int)(b->sc12 = (int)v2);
    else if (v1 == 8) b->channels = (int)(b->sc8 = (int)v2);
    bd_reply(m, "OK\r\n");
    return 1;
  }
  if ((n = sscanf(cmd, "SM,%ld,%ld,%ld", &v1, &v2, &v3)) >= 2) {
    c.op = 'M';
    c.ms = v1;
    c.a = v2;
    c.b = n == 3 ? v3 : 0;
    long most = labs(c.a) > labs(c.b) ? labs(c.a) : labs(c.b);
    if (c.ms < 1 || most * 1000 > 25000 * c.ms) b->bad_rate++;
    if (c.ms < 1) c.ms = 1;
  } else if ((n = sscanf(cmd, "SP,%ld,%ld", &v1, &v2)) >= 1) {
    c.op = 'P';
    c.a = v1;
    c.ms = n == 2 ? v2 : 0;
  } else if (sscanf(cmd, "EM,%ld,%ld", &v1, &v2) == 2) {
    c.op = 'E';
    c.a = v1;
    c.b = v2;
  } else {
    b->bad_cmd++;
    if (getenv("EBB_TRACE")) fprintf(stderr, "board: unknown command `%s`\n", cmd);
    bd_reply(m, "!8 Err: Unknown command\r\n");
    return 1;
  }
  if (!b->running) {
    b->exec = c;
    b->running = 1;
    bd_start(b, &b->exec, t);
  } else {
    b->fifo[b->nfifo++] = c;
  }
  bd_reply(m, "OK\r\n");
  return 1;
}

/* Run the board up to time t (ms). */
static void bd_advance(struct mock *m, struct board *b, double t)
{
  for (;;) {
    while (!m->gone && bd_parse_one(m, b, b->cursor > t ? b->cursor : t)) {}
    if (m->gone || !b->running || b->exec.end > t) break;
    b->cursor = b->exec.end;
    struct bcmd done = b->exec;
    b->running = 0;
    bd_complete(m, b, &done);
    if (m->gone) break;
    if (b->nfifo) {
      b->exec = b->fifo[0];
      memmove(b->fifo, b->fifo + 1, sizeof *b->fifo * (size_t)(--b->nfifo));
      b->running = 1;
      bd_start(b, &b->exec, done.end);
    }
  }
  if (b->cursor < t) b->cursor = t;
}

static void board_tick(struct mock *m)
{
  struct board *b = m->user;
  bd_advance(m, b, bd_now(b));
  /* the host waits for a reply only the motion queue can free: skip ahead */
  while (!m->gone && m->pending_in.length > 0 && m->reply[2]->len == 0 && b->running) {
    double now = bd_now(b);
    if (b->exec.end > now) b->ff += b->exec.end - now;
    bd_advance(m, b, bd_now(b));
  }
}

/* After the host is gone: the board runs what it holds to the end. */
static void board_finish(struct mock *m, struct board *b)
{
  bd_advance(m, b, 1e18);
}

static void board_out(struct mock *m, unsigned char ep, const unsigned char *d, int n)
{
  struct board *b = m->user;
  if (ep != 0x02) return;
  if (b->host_saw_garbage)                      /* what the host sends knowing of it */
    for (int k = 0; k + 3 <= n; k++) {
      if (!memcmp(d + k, "SM,", 3)) b->sm_after_garbage++;
      if (k + 6 <= n && !memcmp(d + k, "EM,0,0", 6)) b->em_off_after_garbage++;
    }
  g_byte_array_append(b->inbuf, d, (guint)n);
  bd_advance(m, b, bd_now(b));
}

/* Power-up state (firmware defaults) and a home position (the user put the carriage home). */
static void board_reset(struct board *b, int corexy)
{
  GByteArray *in = b->inbuf;
  struct dots keep = b->drawn;
  memset(b, 0, sizeof *b);
  b->inbuf = in ? in : g_byte_array_new();
  g_byte_array_set_size(b->inbuf, 0);
  b->drawn = keep;
  b->drawn.n = 0;
  b->t0 = mock_now();
  b->speed = 20;
  b->mode1 = 1;
  b->servo_up_pos = 22565;      /* RCServo2.c */
  b->servo_down_pos = 15302;
  b->rate_up = b->rate_down = 400;
  b->channels = 8;
  b->servo_pos = 22565;         /* "Start servo up" */
  b->corexy = corexy;
  b->g = pen_geom_fit(10 * 80, 10 * 80, 277 * 80, 190 * 80);   /* the profile's defaults */
  b->a_lim = 2 * sqrt(2.0) * 60 * 0.75 * 2032;   /* inferred: see the file's head */
}
