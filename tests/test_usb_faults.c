/*
** test_usb_faults.c — the fault policy of the USB transfer layer (display/usb/usb.c) and the
** stream's resume file and Ctrl-C handling (display/usb/stream.c, cli/cmd_stream.c).
**
** This file contains code to inject faults into the emulated HP-GL plotter of
** tests/usbmock/plotter.c (a pure bulk-OUT device: every byte counts) and check, each time,
** that the dots drawn equal `tube74 render --dump points` EXACTLY, each once:
**   a stall           cleared with CLEAR_HALT and the transfer sent again
**   a timeout         the host discards the URB and retries after a backoff
**   two timeouts      the backoff doubles (the run takes at least the timeouts + pauses)
**   a dead device     (it never completes a transfer) retries, then exit 4 with a resume
**                     file; --resume on a working device completes the picture
**   Ctrl-C            (SIGINT to the real binary on a slow plotter) the pen is put away,
**                     exit 4, a resume file; --resume completes the picture
**   split transfers   with only USBDEVFS_CAP_BULK_CONTINUATION libusb cuts transfers into
**                     16 KiB URBs; the plotter still reads the same HP-GL
**   a wrong resume    file (another scene's hash) is refused with exit 2
** The program re-runs itself under umockdev-wrapper; without it, it exits 77 (skip).
*/
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/usbmock/usbmock.c"
#include "tests/usbmock/plotter.c"

#include "display/sink.h"
#include "display/usb/usb.h"
#include "display/usb/stream.h"

#define SCENE "tests/data/usb/small.s74"

struct fixture {
  struct mock m;
  struct plotter p;
  struct dots ref;
  char *dir;
};

static struct fixture *F(void **state) { return *state; }

static void reset(struct fixture *fx)
{
  mock_reset(&fx->m);
  mock_lock(&fx->m);
  plotter_clear(&fx->p);
  fx->m.caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
               USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_ZERO_PACKET;
  mock_unlock(&fx->m);
}

static int stream_lib(struct fixture *fx, const char *const *sets, struct t74_error *err)
{
  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.prof = &usb_profile_hpgl;
  o.match = o.prof->match;
  usb_settings_default(&o.set, o.prof);
  for (int k = 0; sets && sets[k]; k++)
    if (usb_settings_set(&o.set, o.prof, sets[k], err) != T74_OK) return err->status;
  o.repeat = 1;
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

static void check_exact(struct fixture *fx)
{
  mock_lock(&fx->m);
  assert_int_equal(fx->p.bad_cmd, 0);
  assert_int_equal(fx->p.drawn.n, fx->ref.n);
  assert_true(dots_same_set(&fx->p.drawn, &fx->ref));
  mock_unlock(&fx->m);
}

static void keep_drawn(struct fixture *fx, struct dots *all)
{
  mock_lock(&fx->m);
  for (int k = 0; k < fx->p.drawn.n; k++) dots_add(all, fx->p.drawn.xy[k][0], fx->p.drawn.xy[k][1]);
  mock_unlock(&fx->m);
}

/* --resume FILE on a working plotter; then all = every dot, each once. */
static void resume_completes(struct fixture *fx, const char *save, struct dots *all)
{
  reset(fx);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--resume",
                   (char *)save, NULL };
  assert_int_equal(mock_run(argv, NULL), 0);
  keep_drawn(fx, all);
  assert_int_equal(all->n, fx->ref.n);
  assert_true(dots_same_set(all, &fx->ref));
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_stall_cleared(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.stall_at = 4;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(stream_lib(fx, NULL, &err), T74_OK);
  check_exact(fx);
  assert_int_equal(fx->m.clear_halts, 1);
}

static void test_timeout_retried(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.hold_from = 5;
  fx->m.hold_n = 2;                             /* two timeouts in a row */
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "timeout_ms=100", "backoff_ms=50", NULL };
  double t0 = mock_now();
  int st = stream_lib(fx, sets, &err);
  double t = mock_now() - t0;
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);
  assert_int_equal(fx->m.discards, 2);
  assert_true(t >= 0.2 + 0.05 + 0.1);           /* two timeouts, backoff 50 then 100 ms */
}

/* A slow plotter takes 100 bytes of each 512-byte chunk before the timeout, over and over:
** bytes move, so the retry counter starts again each time and the run completes (with
** retries=1 it would give up on the second timeout of the first chunk otherwise). */
static void test_slow_bytes_reset_retries(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.trickle_bytes = 100;
  fx->m.trickle_urbs = 12;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "timeout_ms=40", "retries=1", "backoff_ms=0", "chunk_bytes=512", NULL };
  int st = stream_lib(fx, sets, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);
  mock_lock(&fx->m);
  int discards = fx->m.discards;
  mock_unlock(&fx->m);
  assert_int_equal(discards, 12);               /* every trickled URB timed out */
}

static void test_dead_device_then_resume(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.hold_from = 8;
  fx->m.hold_n = 1000;                          /* it stops answering for good */
  mock_unlock(&fx->m);
  char *save = g_strdup_printf("%s/d.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--save", save,
                   "--set", "timeout_ms=60", "--set", "retries=2", "--set", "backoff_ms=10",
                   "--set", "chunk_bytes=200", NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, "timed out"));
  assert_non_null(strstr(msg, "--resume"));
  g_free(msg);
  assert_true(g_file_test(save, G_FILE_TEST_EXISTS));
  struct dots all = { 0, 0, NULL };
  keep_drawn(fx, &all);
  assert_true(all.n > 0 && all.n < fx->ref.n);
  resume_completes(fx, save, &all);
  free(all.xy);
  g_free(save);
  g_free(errf);
}

static void test_ctrl_c_then_resume(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.delay_us = 10000;                       /* 10 ms a transfer: a slow plotter */
  mock_unlock(&fx->m);
  char *save = g_strdup_printf("%s/c.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--save", save,
                   "--set", "chunk_bytes=64", "--progress", NULL };
  pid_t pid = fork();
  if (pid == 0) {
    if (!freopen(errf, "w", stderr)) _exit(127);
    execv(argv[0], argv);
    _exit(127);
  }
  for (int waited = 0; waited < 2000; waited++) {   /* until it draws: the machine may be busy */
    mock_lock(&fx->m);
    int got = fx->p.drawn.n;
    mock_unlock(&fx->m);
    if (got >= 50) break;
    usb_sleep_ms(10);
  }
  kill(pid, SIGINT);
  int wst;
  waitpid(pid, &wst, 0);
  assert_true(WIFEXITED(wst));
  assert_int_equal(WEXITSTATUS(wst), 4);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  assert_non_null(strstr(msg, "Ctrl-C"));
  assert_non_null(strstr(msg, "acknowledged"));  /* the progress line was drawn too */
  g_free(msg);
  mock_lock(&fx->m);
  assert_string_equal(fx->p.last, "SP0");       /* pen up and put away */
  assert_false(fx->p.pen_down);
  mock_unlock(&fx->m);
  struct dots all = { 0, 0, NULL };
  keep_drawn(fx, &all);
  assert_true(all.n > 0 && all.n < fx->ref.n);
  resume_completes(fx, save, &all);
  free(all.xy);
  g_free(save);
  g_free(errf);
}

static void test_split_urbs(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->m.caps = USBDEVFS_CAP_BULK_CONTINUATION;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "chunk_bytes=65536", "band_rows=300", NULL };  /* one 60 KB transfer */
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
  assert_true(fx->m.max_urb <= 16384);
  assert_true(fx->m.out_urbs >= 4);
}

static void test_wrong_resume_file(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  char *bad = g_strdup_printf("%s/bad.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  assert_true(g_file_set_contents(bad, "tube74-resume 1\nscene x\nhash 0123456789abcdef\n"
                                  "device hpgl\npass 0\nproduced 0\nacked 0\nprefix 0\nextra 0\n",
                                  -1, NULL));
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--resume", bad, NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  assert_int_equal(rc, 2);
  assert_non_null(strstr(msg, "another scene"));
  mock_lock(&fx->m);
  assert_int_equal(fx->p.drawn.n, 0);           /* nothing was drawn */
  mock_unlock(&fx->m);
  g_free(msg);
  g_free(bad);
  g_free(errf);
}

static int fixture_start(struct fixture *fx)
{
  int rc = mock_begin(&fx->m, 0x067b, 0x2305, MOCK_DESC_HPGL, SCENE, &fx->ref, &fx->dir);
  if (rc) return rc;
  fx->m.on_out = plotter_out;
  fx->m.on_ctrl = plotter_ctrl;
  fx->m.user = &fx->p;
  return 0;
}

int main(int argc, char **argv)
{
  int rc = mock_reexec(argc, argv);
  if (rc) return rc;
  struct fixture *fx = calloc(1, sizeof *fx);
  if ((rc = fixture_start(fx)) != 0) return rc;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test_prestate(test_stall_cleared, fx),
    cmocka_unit_test_prestate(test_timeout_retried, fx),
    cmocka_unit_test_prestate(test_slow_bytes_reset_retries, fx),
    cmocka_unit_test_prestate(test_dead_device_then_resume, fx),
    cmocka_unit_test_prestate(test_ctrl_c_then_resume, fx),
    cmocka_unit_test_prestate(test_split_urbs, fx),
    cmocka_unit_test_prestate(test_wrong_resume_file, fx),
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->p.drawn.xy);
  free(fx);
  return rc;
}
