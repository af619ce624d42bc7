/*
** test_usb_helios.c — the `helios` USB profile against an emulated Helios laser DAC
** (display/usb/helios.c; hardware-facts.md "Helios laser DAC").
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
  int garbage;                  /* answer status requests with garbage */
  int paced;                    /* busy while a frame plays (double buffer at pps) */
  double last_start, play_end;  /* paced: start of the last frame, end of all */
  int have_last, lx, ly;        /* last lit dot */
  int last_blank_x, last_blank_y, last_was_blank;
  double t_first_dot;           /* when the first frame with a lit dot arrived */
  long lit_points;              /* lit points of whole frames (dwell points per dot) */
  int vanish_frame;             /* vanish inside the frame after this many whole frames */
  int vanish_bytes;             /* ... once it has taken this many bytes of it (0: never) */
  int vanish_armed;
};

static void dac_frame(struct dac *d, const unsigned char *b, int len)
{
  int n = (len - 5) / 7;
  int pps = b[len - 5] | b[len - 4] << 8;
  d->frames++;
  if (n > d->max_points) d->max_points = n;
  if (n > 4095 || (n - 45) % 64 == 0) d->bad_size++;
  if (d->expect_pps && pps != d->expect_pps) d->bad_pps++;
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
    if (d->have_last && x == d->lx && y == d->ly) { d->last_was_blank = 0; continue; }  /* dwell */
    if (!d->have_last || abs(x - d->lx) > 1 || abs(y - d->ly) > 1)
      if (!d->last_was_blank || d->last_blank_x != X || d->last_blank_y != Y) d->unblanked_jumps++;
    if (d->t_first_dot == 0) d->t_first_dot = mock_now();
    dots_add(&d->lit, x, y);
    d->have_last = 1;
    d->lx = x;
    d->ly = y;
    d->last_was_blank = 0;
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
      r[0] = 0x83;
      r[1] = !d->paced || d->last_start <= mock_now();
      mock_reply(m, 0x83, r, 32);
    } else if (b[0] == 0x04) {
      r[0] = 0x84;
      r[1] = 6;
      mock_reply(m, 0x83, r, 32);
    } else if (b[0] == 0x01) d->stops++;
    else if (b[0] == 0x02 && n > 1 && b[1] == 0) d->shutter_closed++;
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

static void dac_clear(struct dac *d)
{
  GByteArray *f = d->frame;
  struct dots l = d->lit;
  memset(d, 0, sizeof *d);
  d->frame = f;
  g_byte_array_set_size(f, 0);
  d->lit = l;
  d->lit.n = 0;
}

struct fixture {
  struct mock m;
  struct dac d;
  struct dots ref;
  char *dir;
};

static struct fixture *F(void **state) { return *state; }

/* Stream ref through the library (no renderer: the dots as produced). */
static int stream_lib(struct fixture *fx, const char *const *sets, int repeat, struct t74_error *err)
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
  for (int i = 0; i < fx->ref.n && st == T74_OK; i++)
    st = sink_point(&k, fx->ref.xy[i][0], fx->ref.xy[i][1]);
  if (st == T74_OK) st = sink_end(&k, err);
  return usb_stream_finish(s, st, err);
}

static void check_passes(struct fixture *fx, int passes)
{
  g_mutex_lock(&fx->m.lock);
  assert_int_equal(fx->d.lit.n, fx->ref.n * passes);
  for (int p = 0; p < passes; p++)
    assert_memory_equal(fx->d.lit.xy + (size_t)p * fx->ref.n, fx->ref.xy,
                        sizeof *fx->ref.xy * (size_t)fx->ref.n);
  assert_int_equal(fx->d.bad_size, 0);
  assert_int_equal(fx->d.off_grid, 0);
  assert_int_equal(fx->d.unblanked_jumps, 0);
  g_mutex_unlock(&fx->m.lock);
}

static void reset(struct fixture *fx)
{
  mock_reset(&fx->m);
  g_mutex_lock(&fx->m.lock);
  dac_clear(&fx->d);
  g_mutex_unlock(&fx->m.lock);
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
  assert_true(fx->d.max_points <= 1000);
  assert_true(fx->d.frames > 1);
  assert_int_equal(fx->d.stops, 1);             /* laser blanked at the end */
}

static void test_binary_exact_and_first_point(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  g_mutex_lock(&fx->m.lock);
  fx->d.expect_pps = 20000;
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  fx->m.caps = USBDEVFS_CAP_BULK_CONTINUATION;  /* libusb splits into 16 KiB URBs */
  g_mutex_unlock(&fx->m.lock);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "frame_points=4000", NULL };
  int st = stream_lib(fx, sets, 1, &err);
  g_mutex_lock(&fx->m.lock);
  fx->m.caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
               USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_ZERO_PACKET;
  int max_urb = fx->m.max_urb, frames = fx->d.frames, big = fx->d.max_points;
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  fx->d.paced = 1;
  g_mutex_unlock(&fx->m.lock);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "pps=30000", "frame_points=500", NULL };
  double t0 = mock_now();
  int st = stream_lib(fx, sets, 2, &err);
  double t = mock_now() - t0;
  assert_int_equal(st, T74_OK);
  check_passes(fx, 2);
  /* double buffering: all but the last two frames must have been played out first */
  g_mutex_lock(&fx->m.lock);
  int frames = fx->d.frames;
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  fx->d.garbage = 1;
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  fx->d.vanish_frame = WHOLE;
  fx->d.vanish_bytes = CUT;
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  int gone = fx->m.gone, frames = fx->d.frames, partial = (int)fx->d.frame->len;
  int bad = fx->d.bad_size + fx->d.off_grid + fx->d.unblanked_jumps;
  int stops = fx->d.stops;
  long lit_points = fx->d.lit_points;
  for (int k = 0; k < fx->d.lit.n; k++) dots_add(&all, fx->d.lit.xy[k][0], fx->d.lit.xy[k][1]);
  g_mutex_unlock(&fx->m.lock);
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
  g_mutex_lock(&fx->m.lock);
  bad = fx->d.bad_size + fx->d.off_grid + fx->d.unblanked_jumps;
  stops = fx->d.stops;
  lit_points = fx->d.lit_points;
  partial = (int)fx->d.frame->len;
  int second = fx->d.lit.n;
  for (int k = 0; k < fx->d.lit.n; k++) dots_add(&all, fx->d.lit.xy[k][0], fx->d.lit.xy[k][1]);
  g_mutex_unlock(&fx->m.lock);
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
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->d.lit.xy);
  g_byte_array_free(fx->d.frame, TRUE);
  free(fx);
  return rc;
}
