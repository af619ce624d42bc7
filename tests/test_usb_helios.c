/*
** test_usb_helios.c — the `helios` USB profile against an emulated Helios laser DAC
** (display/usb/helios.c; docs/hardware.md "Helios laser DAC").
**
** This file contains code to play a Helios DAC under umockdev (tests/usbmock/usbmock.c):
** it answers the interrupt-endpoint status (0x03 -> 0x83, ready) and version (0x04 -> 0x84)
** requests, takes frames on bulk OUT 0x02, checks each frame's trailer (point count, pps)
** and limits (at most 4095 points, never (n-45) % 64 == 0), and decodes the lit points back
** into tube dots. The dots must equal `tube74 render --dump points` EXACTLY, in order, once
** per --repeat pass; every jump of more than one dot must be preceded by a blanked point on
** the target. Runs both through the library (display/usb/stream.h) and the real binary.
** Also: double-buffer pacing (a slow DAC that is busy while it plays a frame at the pps
** rate), transfers split into 16 KiB URBs, a DAC that answers garbage, a DAC that vanishes
** in the middle of a frame's transfer (exit 4, resume file; --resume then completes: the
** frames both runs delivered hold every dot exactly once), and the figures for docs/usb.md
** (points/s, time to first point).
** The program re-runs itself under umockdev-wrapper; without it, it exits 77 (skip).
*/
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/usbmock/usbmock.c"

#include "display/sink.h"
#include "display/usb/usb.h"
#include "display/usb/stream.h"

#define SCENE "tests/data/usb/small.s74"

struct dac {                    /* the emulated DAC's state (under m->lock) */
  GByteArray *frame;            /* bytes of the frame being received */
  struct dots lit;              /* decoded dots, in the order shown */
  int frames, max_points, bad_size, bad_pps, bad_count, unblanked_jumps, off_grid;
  int expect_pps;
  int stops, shutter_closed;
  /* the firmware's state (Grix/helios_dac firmware main.c): shutter_set(LOW) at power-up;
     a frame whose flags lack bit 1 is looped until the next one, one with it plays once */
  int shutter;                  /* 1 open */
  int shutter_opens;            /* 0x02,1 requests */
  int dark_frames;              /* frames that arrived while the shutter was closed */
  int looping_frames;           /* frames without the play-once flag */
  int last_flags;               /* flags of the last frame */
  int stopped_after_last;       /* a stop (0x01) came after the last frame */
  int early_frames;             /* frames written while the DAC reported not ready */
  double busy_until;            /* the DAC's buffers are full until then (a previous run's
                                   frames still playing): status says not ready */
  int garbage;                  /* answer status requests with garbage */
  int paced;                    /* busy while a frame plays (double buffer at pps) */
  double last_start, play_end;  /* paced: start of the last frame, end of all */
  int have_last, lx, ly;        /* last lit point, tube dots */
  int last_blank_x, last_blank_y, last_was_blank;
  double t_first_dot;           /* when the first frame with a lit dot arrived */
  long lit_points;              /* lit points of whole frames (dwell points per dot) */
  long points;                  /* all points of whole frames */
  int vanish_frame;             /* vanish inside the frame after this many whole frames */
  int vanish_bytes;             /* ... once it has taken this many bytes of it (0: never) */
  int vanish_armed;
  int frame_cover_min;          /* per mille: the smallest share of the picture's extent in x
                                   and y that one frame's lit dots span (steady pictures) */
  int ref_x0, ref_x1, ref_y0, ref_y1;   /* the picture's extent, for frame_cover_min */
};

/* The DAC is ready for a frame (firmware: its second buffer is free). */
static int dac_ready(struct dac *d)
{
  double now = mock_now();
  if (now < d->busy_until) return 0;
  return !d->paced || d->last_start <= now;
}

static void dac_paint(struct dac *d, int x, int y, int *fx0, int *fx1, int *fy0, int *fy1)
{
  if (d->t_first_dot == 0) d->t_first_dot = mock_now();
  dots_add(&d->lit, x, y);
  if (x < *fx0) *fx0 = x;
  if (x > *fx1) *fx1 = x;
  if (y < *fy0) *fy0 = y;
  if (y > *fy1) *fy1 = y;
}

/* A whole frame arrived: decode it as the beam draws it. A lit point after a blanked one on
** the same spot lights that dot; a lit point after a lit one lights the path between them
** (along a row: every dot on it; a neighbour: that dot; anything else is a stray line). */
static void dac_frame(struct dac *d, const unsigned char *b, int len)
{
  int n = (len - 5) / 7;
  int pps = b[len - 5] | b[len - 4] << 8;
  d->frames++;
  d->last_flags = b[len - 1];
  d->stopped_after_last = 0;
  if (!(d->last_flags & 2)) d->looping_frames++;
  if (!d->shutter) d->dark_frames++;
  if (!dac_ready(d)) d->early_frames++;
  d->points += n;
  if (n > d->max_points) d->max_points = n;
  if (n > 4095 || (n - 45) % 64 == 0) d->bad_size++;
  if (d->expect_pps && pps != d->expect_pps) d->bad_pps++;
  int fx0 = 9999, fx1 = -1, fy0 = 9999, fy1 = -1;
  for (int k = 0; k < n; k++) {
    const unsigned char *p = b + 7 * k;
    int X = p[0] << 4 | p[1] >> 4, Y = (p[1] & 15) << 8 | p[2];
    int lit = p[3] || p[4] || p[5] || p[6];
    if (lit) d->lit_points++;
    if (!lit) {
      d->last_was_blank = 1;
      d->last_blank_x = X;
      d->last_blank_y = Y;
      continue;
    }
    if ((X - 48) % 10 || (Y - 548) % 10) { d->off_grid++; continue; }
    int x = (X - 48) / 10, y = (Y - 548) / 10;
    if (d->have_last && !d->last_was_blank) {   /* lit to lit */
      int dx = x - d->lx, dy = y - d->ly;
      if (dx == 0 && dy == 0) { /* dwell */ }
      else if (abs(dx) <= 1 && abs(dy) <= 1) dac_paint(d, x, y, &fx0, &fx1, &fy0, &fy1);
      else if (dy == 0)
        for (int xx = d->lx + (dx > 0 ? 1 : -1);; xx += dx > 0 ? 1 : -1) {
          dac_paint(d, xx, y, &fx0, &fx1, &fy0, &fy1);
          if (xx == x) break;
        }
      else { d->unblanked_jumps++; dac_paint(d, x, y, &fx0, &fx1, &fy0, &fy1); }
    } else {
      if (d->last_was_blank && (d->last_blank_x != X || d->last_blank_y != Y)) d->unblanked_jumps++;
      if (!d->last_was_blank && !d->have_last) d->unblanked_jumps++;
      dac_paint(d, x, y, &fx0, &fx1, &fy0, &fy1);
    }
    d->have_last = 1;
    d->lx = x;
    d->ly = y;
    d->last_was_blank = 0;
  }
  if (fx1 >= 0 && d->ref_x1 > d->ref_x0 && d->ref_y1 > d->ref_y0) {
    int cx = 1000 * (fx1 - fx0) / (d->ref_x1 - d->ref_x0), cy = 1000 * (fy1 - fy0) / (d->ref_y1 - d->ref_y0);
    int c = cx < cy ? cx : cy;
    if (d->frame_cover_min < 0 || c < d->frame_cover_min) d->frame_cover_min = c;
  }
  if (d->paced) {
    double now = mock_now(), start = d->play_end > now ? d->play_end : now;
    d->last_start = start;
    d->play_end = start + (double)n / (pps ? pps : 1);
  }
}

static void dac_out(struct mock *m, unsigned char ep, const unsigned char *b, int n)
{
  struct dac *d = m->user;
  if (ep == 0x06) {                             /* control on the interrupt endpoint */
    unsigned char r[32] = { 0 };
    if (d->garbage && (b[0] == 0x03 || b[0] == 0x04)) {
      memset(r, 0x5a, sizeof r);
      mock_reply(m, 0x83, r, 32);
    } else if (b[0] == 0x03) {
      /* the status poll just before the next frame: that frame's URB will cross the limit
      ** (m->out_bytes already counts this poll; nothing else goes out in between) */
      if (d->vanish_bytes && !d->vanish_armed && d->frames == d->vanish_frame) {
        m->vanish_after = m->out_bytes + d->vanish_bytes;
        d->vanish_armed = 1;
      }
      r[0] = 0x83;                              /* firmware: a 2-byte reply */
      r[1] = (unsigned char)dac_ready(d);
      mock_reply(m, 0x83, r, 2);
    } else if (b[0] == 0x04) {
      r[0] = 0x84;                              /* firmware: 0x84 + version, 32-bit LE */
      r[1] = 6;
      mock_reply(m, 0x83, r, 5);
    } else if (b[0] == 0x01) {
      d->stops++;
      d->stopped_after_last = 1;
    } else if (b[0] == 0x02 && n > 1) {
      d->shutter = b[1] != 0;
      if (b[1]) d->shutter_opens++;
      else d->shutter_closed++;
    }
    return;
  }
  if (ep != 0x02) return;
  g_byte_array_append(d->frame, b, (guint)n);
  int len = (int)d->frame->len;
  const unsigned char *f = d->frame->data;
  if (len >= 5 && (len - 5) % 7 == 0 && (f[len - 3] | f[len - 2] << 8) == (len - 5) / 7) {
    dac_frame(d, f, len);
    g_byte_array_set_size(d->frame, 0);
  }
}

/* After the run: the laser can be on no longer (a stop came after the last frame, or the
** last frame plays once) and the shutter is closed. */
static int dac_safe(const struct dac *d)
{
  return (d->stopped_after_last || (d->frames > 0 && (d->last_flags & 2))) && !d->shutter;
}

static void dac_clear(struct dac *d)
{
  GByteArray *f = d->frame;
  struct dots l = d->lit;
  memset(d, 0, sizeof *d);
  d->frame = f;
  g_byte_array_set_size(f, 0);
  d->lit = l;
  d->lit.n = 0;
  d->frame_cover_min = -1;
}

struct fixture {
  struct mock m;
  struct dac d;
  struct dots ref;
  char *dir;
};

static struct fixture *F(void **state) { return *state; }

/* Stream ref through the library (no renderer: the dots as produced). */
static int stream_lib_n(struct fixture *fx, const char *const *sets, int repeat, int ndots,
                        struct t74_error *err)
{
  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.prof = &usb_profile_helios;
  o.match = o.prof->match;
  usb_settings_default(&o.set, o.prof);
  for (int k = 0; sets && sets[k]; k++)
    if (usb_settings_set(&o.set, o.prof, sets[k], err) != T74_OK) return err->status;
  o.repeat = repeat;
  o.scene = SCENE;
  o.t0 = usb_now();
  struct usb_stream *s;
  if (usb_stream_open(&s, &o, err) != T74_OK) return err->status;
  struct sink k = usb_stream_sink(s);
  int st = T74_OK;
  for (int i = 0; i < ndots && st == T74_OK; i++)
    st = sink_point(&k, fx->ref.xy[i][0], fx->ref.xy[i][1]);
  if (st == T74_OK) st = sink_end(&k, err);
  return usb_stream_finish(s, st, err);
}

static int stream_lib(struct fixture *fx, const char *const *sets, int repeat, struct t74_error *err)
{
  return stream_lib_n(fx, sets, repeat, fx->ref.n, err);
}

static void check_passes(struct fixture *fx, int passes)
{
  mock_lock(&fx->m);
  assert_int_equal(fx->d.lit.n, fx->ref.n * passes);
  for (int p = 0; p < passes; p++)
    assert_memory_equal(fx->d.lit.xy + (size_t)p * fx->ref.n, fx->ref.xy,
                        sizeof *fx->ref.xy * (size_t)fx->ref.n);
  assert_int_equal(fx->d.bad_size, 0);
  assert_int_equal(fx->d.off_grid, 0);
  assert_int_equal(fx->d.unblanked_jumps, 0);
  mock_unlock(&fx->m);
}

static void reset(struct fixture *fx)
{
  mock_reset(&fx->m);
  mock_lock(&fx->m);
  dac_clear(&fx->d);
  mock_unlock(&fx->m);
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_library_exact(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  struct t74_error err = { T74_OK, "" };
  int st = stream_lib(fx, NULL, 1, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_passes(fx, 1);
  mock_lock(&fx->m);
  struct dac d = fx->d;
  mock_unlock(&fx->m);
  assert_true(d.max_points <= 1000);
  assert_true(d.frames > 1);
  assert_int_equal(d.stops, 1);                 /* laser blanked at the end */
  assert_int_equal(d.shutter_opens, 1);         /* the shutter opened once ... */
  assert_int_equal(d.dark_frames, 0);           /* ... before the first frame */
  assert_int_equal(d.looping_frames, 0);        /* every frame plays once */
  assert_int_equal(d.shutter, 0);               /* and closed at the end */
  assert_true(dac_safe(&d));
  printf("BENCH helios refresh, steady=0 (dots as produced): %d dots = %ld points in %d frames; "
         "the whole picture every %ld/30000 s = %.1f Hz at 30 kpps, shown band by band\n",
         fx->ref.n, d.points, d.frames, d.points, 30000.0 / (double)d.points);
}

/* Run the binary with --repeat 0 (a refreshed picture) and signal it once `frames` frames
** have arrived; its exit status (-1: did not exit). */
static int binary_signalled(struct fixture *fx, int sig, int frames, const char *const *extra)
{
  char *save = g_strdup_printf("%s/sig.resume", fx->dir);   /* not in the working folder */
  char *argv[16] = { (char *)mock_tube74(), "stream", SCENE, "--device", "helios", "--repeat", "0",
                     "--save", save };
  int a = 9;
  for (int k = 0; extra && extra[k] && a < 15; k++) argv[a++] = (char *)extra[k];
  argv[a] = NULL;
  pid_t pid = fork();
  if (pid == 0) {
    if (!freopen("/dev/null", "w", stderr)) _exit(127);
    execv(argv[0], argv);
    _exit(127);
  }
  for (int waited = 0; waited < 2000; waited++) {   /* up to 20 s: the machine may be busy */
    mock_lock(&fx->m);
    int got = fx->d.frames;
    mock_unlock(&fx->m);
    if (got >= frames) break;
    usb_sleep_ms(10);
  }
  kill(pid, sig);
  int wst;
  waitpid(pid, &wst, 0);
  unlink(save);
  g_free(save);
  return WIFEXITED(wst) ? WEXITSTATUS(wst) : -1;
}

/* SIGTERM in the middle of a refreshed picture: tube74 stops the DAC (blanked) and closes
** the shutter before it exits; the picture had the shutter open and played each frame once. */
static void test_sigterm_leaves_laser_safe(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  int rc = binary_signalled(fx, SIGTERM, 12, NULL);
  assert_true(rc == 0 || rc == 4);              /* between pictures 0, inside one 4 */
  mock_lock(&fx->m);
  struct dac d = fx->d;
  mock_unlock(&fx->m);
  assert_true(d.frames >= 12);
  assert_true(d.stopped_after_last);            /* blanked after the last frame */
  assert_int_equal(d.shutter, 0);               /* shutter closed */
  assert_int_equal(d.dark_frames, 0);
  assert_int_equal(d.looping_frames, 0);
  assert_true(dac_safe(&d));
}

/* tube74 killed outright (SIGKILL, as a crash): it can send nothing more, but every frame
** it sent plays once, so the DAC blanks by itself instead of scanning the last frame. */
static void test_sigkill_frames_play_once(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  int rc = binary_signalled(fx, SIGKILL, 8, NULL);
  assert_int_equal(rc, -1);
  mock_lock(&fx->m);
  struct dac d = fx->d;
  mock_unlock(&fx->m);
  assert_true(d.frames >= 8);
  assert_int_equal(d.looping_frames, 0);
  assert_true(d.last_flags & 2);                /* the firmware stops after it: blanked */
}

/* Replies a previous program left on the interrupt IN endpoint (status "ready") while the
** DAC is still busy: they are drained, not taken as answers, so no frame is written before
** the DAC is ready (the firmware would not have armed its bulk endpoint). */
static void test_stale_status_drained(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  static const unsigned char stale[2] = { 0x83, 1 };
  mock_lock(&fx->m);
  for (int k = 0; k < 3; k++) mock_reply(&fx->m, 0x83, stale, 2);
  fx->d.busy_until = mock_now() + 0.2;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  int st = stream_lib(fx, NULL, 1, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_passes(fx, 1);
  mock_lock(&fx->m);
  int early = fx->d.early_frames;
  mock_unlock(&fx->m);
  assert_int_equal(early, 0);
}

/* Slow frames (250 points at 1,000 points/s: 250 ms each) with a status margin of 60 ms:
** from the third frame on the DAC is ready only after about 250 ms; the wait for a free
** buffer is derived from the frames the DAC holds, not a fixed time. */
static void test_status_timeout_from_frames(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->d.paced = 1;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "pps=1000", "frame_points=250", "status_margin_ms=60", NULL };
  int st = stream_lib_n(fx, sets, 1, 900, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  mock_lock(&fx->m);
  assert_int_equal(fx->d.lit.n, 900);
  assert_memory_equal(fx->d.lit.xy, fx->ref.xy, sizeof *fx->ref.xy * 900);
  assert_true(fx->d.frames >= 4);
  mock_unlock(&fx->m);
}

/* The steady picture: frames that each span the whole picture. */
static void steady_run(struct fixture *fx, const char *mode, long *points, int *frames)
{
  reset(fx);
  mock_lock(&fx->m);
  for (int k = 0; k < fx->ref.n; k++) {
    int x = fx->ref.xy[k][0], y = fx->ref.xy[k][1];
    if (!k || x < fx->d.ref_x0) fx->d.ref_x0 = x;
    if (!k || x > fx->d.ref_x1) fx->d.ref_x1 = x;
    if (!k || y < fx->d.ref_y0) fx->d.ref_y0 = y;
    if (!k || y > fx->d.ref_y1) fx->d.ref_y1 = y;
  }
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { mode, NULL };
  int st = stream_lib(fx, sets, 1, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  mock_lock(&fx->m);
  struct dac d = fx->d;
  assert_true(dots_same_set(&fx->d.lit, &fx->ref));     /* every dot once, nothing else */
  mock_unlock(&fx->m);
  assert_int_equal(d.unblanked_jumps, 0);
  assert_int_equal(d.off_grid, 0);
  assert_int_equal(d.bad_size, 0);
  assert_true(d.max_points <= 1000);
  assert_true(d.frame_cover_min >= 800);        /* each frame spans >= 80 % both ways */
  *points = d.points;
  *frames = d.frames;
}

static void test_steady_interleaved(void **state)
{
  struct fixture *fx = F(state);
  long pts;
  int frames;
  steady_run(fx, "steady=1", &pts, &frames);
  assert_true(frames > 1);
  printf("BENCH helios refresh, steady=1 (interleaved): %d dots = %ld points in %d frames of "
         "the whole picture: %.0f Hz frames, every dot %.1f Hz, at 30 kpps\n", fx->ref.n, pts,
         frames, 30000.0 * frames / (double)pts, 30000.0 / (double)pts);
}

static void test_steady_runs_as_lines(void **state)
{
  struct fixture *fx = F(state);
  long pts0, pts;
  int frames0, frames;
  steady_run(fx, "steady=1", &pts0, &frames0);
  steady_run(fx, "steady=2", &pts, &frames);
  assert_true(pts < pts0);                      /* lines: fewer points for the same dots */
  printf("BENCH helios refresh, steady=2 (runs as lines, run_step 4): %d dots = %ld points in "
         "%d frame(s): %.0f Hz frames, every dot %.1f Hz, at 30 kpps\n", fx->ref.n, pts, frames,
         30000.0 * frames / (double)pts, 30000.0 / (double)pts);
}

static void test_binary_exact_and_first_point(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->d.expect_pps = 20000;
  mock_unlock(&fx->m);
  char *stats = g_strdup_printf("%s/s.json", fx->dir);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "helios", "--pps", "20000",
                   "--stats", stats, NULL };
  double t0 = mock_now();
  int rc = mock_run(argv, NULL);
  double t1 = mock_now();
  assert_int_equal(rc, 0);
  check_passes(fx, 1);
  assert_int_equal(fx->d.bad_pps, 0);
  gchar *js = NULL;
  assert_true(g_file_get_contents(stats, &js, NULL, NULL));
  const char *k = strstr(js, "\"usb_acknowledged_before_render_end\": ");
  assert_non_null(k);
  long before = atol(k + strlen("\"usb_acknowledged_before_render_end\": "));
  assert_true(before > 0);                      /* dots left while the scene rendered */
  printf("BENCH helios binary: %d dots; first frame byte at the device %.1f ms after start, "
         "first whole frame (dots) %.1f ms; whole run %.1f ms; %ld dots acknowledged before "
         "rendering ended\n", fx->ref.n, (fx->m.t_first_out - t0) * 1e3,
         (fx->d.t_first_dot - t0) * 1e3, (t1 - t0) * 1e3, before);
  g_free(js);
  g_free(stats);
}

static void test_repeat(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(stream_lib(fx, NULL, 3, &err), T74_OK);
  check_passes(fx, 3);
}

static void test_split_urbs(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.caps = USBDEVFS_CAP_BULK_CONTINUATION;  /* libusb splits into 16 KiB URBs */
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "frame_points=4000", NULL };
  int st = stream_lib(fx, sets, 1, &err);
  mock_lock(&fx->m);
  fx->m.caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
               USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_ZERO_PACKET;
  int max_urb = fx->m.max_urb, frames = fx->d.frames, big = fx->d.max_points;
  mock_unlock(&fx->m);
  assert_int_equal(st, T74_OK);
  check_passes(fx, 1);
  assert_true(big * 7 > 16384);                 /* a frame needed several URBs */
  assert_true(max_urb <= 16384);
  assert_true(frames >= 2);
}

static void test_slow_dac_paced(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->d.paced = 1;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "pps=30000", "frame_points=500", NULL };
  double t0 = mock_now();
  int st = stream_lib(fx, sets, 2, &err);
  double t = mock_now() - t0;
  assert_int_equal(st, T74_OK);
  check_passes(fx, 2);
  /* double buffering: all but the last two frames must have been played out first */
  mock_lock(&fx->m);
  int frames = fx->d.frames;
  mock_unlock(&fx->m);
  double min = (frames - 2) * 300 / 30000.0;    /* frames hold at least ~300 points */
  assert_true(t >= min * 0.9);
  printf("BENCH helios paced at 30000 points/s: %d dots x 2 passes in %.3f s = %.0f dots/s "
         "(%d frames)\n", fx->ref.n, t, 2 * fx->ref.n / t, frames);
}

static void test_throughput(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "frame_points=4000", NULL };
  double t0 = mock_now();
  int st = stream_lib(fx, sets, 5, &err);
  double t = mock_now() - t0;
  assert_int_equal(st, T74_OK);
  check_passes(fx, 5);
  printf("BENCH helios unpaced emulated DAC: %d dots in %.3f s = %.0f dots/s\n", 5 * fx->ref.n, t,
         5 * fx->ref.n / t);
}

static void test_garbage(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->d.garbage = 1;
  mock_unlock(&fx->m);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  char *save = g_strdup_printf("%s/g.resume", fx->dir);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "helios", "--save", save, NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, "garbage"));
  g_free(msg);
  g_free(errf);
  g_free(save);
}

/* The DAC vanishes in the middle of a frame (ENODEV part way through its bulk transfer):
** exit 4 naming the vanished device, a resume file whose acknowledged dots are exactly the
** whole frames the DAC took (the cut frame's dots are not acknowledged); then --resume on a
** connected DAC completes. What the DAC decoded from whole frames in the two runs is
** `--dump points` exactly: each dot once (the cut frame's dots re-sent, none lost), and,
** helios keeping production order, in the reference's order. */
static void test_vanish_then_resume(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  enum { WHOLE = 3, CUT = 7 * 211 + 4 };         /* 4 bytes into point 211 of frame 4 */
  mock_lock(&fx->m);
  fx->d.vanish_frame = WHOLE;
  fx->d.vanish_bytes = CUT;
  mock_unlock(&fx->m);
  char *save = g_strdup_printf("%s/v.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "helios", "--save", save,
                   "--set", "frame_points=500", NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  if (rc != 4 || !msg || !strstr(msg, "vanished")) fprintf(stderr, "first run: rc %d: %s\n", rc, msg);
  assert_int_equal(rc, 4);
  assert_non_null(msg);
  assert_non_null(strstr(msg, "vanished"));
  assert_non_null(strstr(msg, "--resume"));
  g_free(msg);

  struct dots all = { 0, 0, NULL };
  mock_lock(&fx->m);
  int gone = fx->m.gone, frames = fx->d.frames, partial = (int)fx->d.frame->len;
  int bad = fx->d.bad_size + fx->d.off_grid + fx->d.unblanked_jumps;
  int stops = fx->d.stops;
  long lit_points = fx->d.lit_points;
  for (int k = 0; k < fx->d.lit.n; k++) dots_add(&all, fx->d.lit.xy[k][0], fx->d.lit.xy[k][1]);
  mock_unlock(&fx->m);
  assert_true(gone);
  assert_int_equal(frames, WHOLE);              /* it vanished inside the next frame ... */
  assert_int_equal(partial, CUT);               /* ... mid-point, with part of it taken */
  assert_int_equal(bad, 0);
  assert_int_equal(stops, 0);                   /* nothing could reach a vanished DAC */
  assert_int_equal(lit_points, all.n);          /* dwell 1: each dot lit once */
  int first = all.n;
  assert_true(first > 0 && first < fx->ref.n);

  /* the resume file: acknowledged = the dots of the whole frames, a prefix, no extras */
  gchar *res = NULL;
  assert_true(g_file_get_contents(save, &res, NULL, NULL));
  const char *a = strstr(res, "\nacked "), *pf = strstr(res, "\nprefix "), *ex = strstr(res, "\nextra ");
  assert_non_null(a);
  assert_non_null(pf);
  assert_non_null(ex);
  if (atoi(a + 7) != first || atoi(pf + 8) != first || atoi(ex + 7) != 0)
    fprintf(stderr, "resume file (the DAC took %d dots in %d whole frames):\n%.400s\n", first,
            frames, res);
  assert_int_equal(atoi(a + 7), first);
  assert_int_equal(atoi(pf + 8), first);
  assert_int_equal(atoi(ex + 7), 0);
  g_free(res);

  reset(fx);                                    /* plugged in again */
  char *argv2[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "helios", "--resume", save,
                    "--set", "frame_points=500", NULL };
  rc = mock_run(argv2, errf);
  if (rc != 0) {
    gchar *m2 = NULL;
    g_file_get_contents(errf, &m2, NULL, NULL);
    fprintf(stderr, "resumed run: rc %d: %s\n", rc, m2);
    g_free(m2);
  }
  assert_int_equal(rc, 0);
  mock_lock(&fx->m);
  bad = fx->d.bad_size + fx->d.off_grid + fx->d.unblanked_jumps;
  stops = fx->d.stops;
  lit_points = fx->d.lit_points;
  partial = (int)fx->d.frame->len;
  int second = fx->d.lit.n;
  for (int k = 0; k < fx->d.lit.n; k++) dots_add(&all, fx->d.lit.xy[k][0], fx->d.lit.xy[k][1]);
  mock_unlock(&fx->m);
  assert_int_equal(bad, 0);
  assert_int_equal(partial, 0);                 /* every frame arrived whole */
  assert_int_equal(stops, 1);                   /* laser blanked at the end */
  assert_int_equal(lit_points, second);
  assert_false(g_file_test(save, G_FILE_TEST_EXISTS));   /* complete: nothing to resume */
  if (all.n != fx->ref.n || !dots_same_set(&all, &fx->ref))
    fprintf(stderr, "union: %d + %d = %d dots, the reference %d\n", first, second, all.n, fx->ref.n);
  assert_int_equal(all.n, fx->ref.n);
  assert_true(dots_same_set(&all, &fx->ref));   /* every dot, each once */
  assert_true(dots_same_order(&all, &fx->ref)); /* and in production order */
  free(all.xy);
  g_free(save);
  g_free(errf);
}

static void test_bad_settings(void **state)
{
  (void)state;
  struct usb_settings s;
  struct t74_error err = { T74_OK, "" };
  usb_settings_default(&s, &usb_profile_helios);
  assert_int_equal(usb_settings_set(&s, &usb_profile_helios, "pps=5", &err), T74_EINPUT);
  err.status = T74_OK;
  assert_int_equal(usb_settings_set(&s, &usb_profile_helios, "frame_points=4095", &err), T74_EINPUT);
  err.status = T74_OK;
  assert_int_equal(usb_settings_set(&s, &usb_profile_helios, "pps=65535", &err), T74_OK);
  assert_int_equal((int)usb_setting(&s, &usb_profile_helios, "pps"), 65535);
  char rule[256];
  usb_udev_rule(rule, sizeof rule, 0x1209, 0xE500);
  assert_string_equal(rule, "SUBSYSTEM==\"usb\", ATTRS{idVendor}==\"1209\", "
                      "ATTRS{idProduct}==\"e500\", MODE=\"0660\", GROUP=\"plugdev\", TAG+=\"uaccess\"");
}

static int fixture_start(struct fixture *fx)
{
  int rc = mock_begin(&fx->m, 0x1209, 0xE500, MOCK_DESC_HELIOS, SCENE, &fx->ref, &fx->dir);
  if (rc) return rc;
  fx->d.frame = g_byte_array_new();
  fx->m.on_out = dac_out;
  fx->m.user = &fx->d;
  return 0;
}

int main(int argc, char **argv)
{
  int rc = mock_reexec(argc, argv);
  if (rc) return rc;
  struct fixture *fx = calloc(1, sizeof *fx);
  if ((rc = fixture_start(fx)) != 0) return rc;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test_prestate(test_bad_settings, fx),
    cmocka_unit_test_prestate(test_library_exact, fx),
    cmocka_unit_test_prestate(test_binary_exact_and_first_point, fx),
    cmocka_unit_test_prestate(test_repeat, fx),
    cmocka_unit_test_prestate(test_split_urbs, fx),
    cmocka_unit_test_prestate(test_slow_dac_paced, fx),
    cmocka_unit_test_prestate(test_throughput, fx),
    cmocka_unit_test_prestate(test_garbage, fx),
    cmocka_unit_test_prestate(test_vanish_then_resume, fx),
    cmocka_unit_test_prestate(test_sigterm_leaves_laser_safe, fx),
    cmocka_unit_test_prestate(test_sigkill_frames_play_once, fx),
    cmocka_unit_test_prestate(test_stale_status_drained, fx),
    cmocka_unit_test_prestate(test_status_timeout_from_frames, fx),
    cmocka_unit_test_prestate(test_steady_interleaved, fx),
    cmocka_unit_test_prestate(test_steady_runs_as_lines, fx),
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->d.lit.xy);
  g_byte_array_free(fx->d.frame, TRUE);
  free(fx);
  return rc;
}
