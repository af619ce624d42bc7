/*
** test_usb_ebb.c — the `ebb` USB profile against an emulated EiBotBoard (display/usb/ebb.c;
** the board: tests/usbmock/ebb.c, modelled on the EBB command reference and firmware).
**
** This file contains code to check, under umockdev (tests/usbmock/usbmock.c), that what the
** profile sends draws `tube74 render --dump points` EXACTLY (the same set, each dot once:
** the plotter reorders within a band) at its true size in millimetres (the AxiDraw's 2032
** steps/inch at 1/16 step); that the servo is configured as the AxiDraw software does
** (SC,4/5/11/12, SC,8) and every pen move waits its travel, so each dot is inked and no
** move drags the pen; that moves are ramped (no step-rate jump the steppers cannot follow)
** and stay under 25 kHz; that a dot is acknowledged only when the board has RUN the command
** that draws it (the board vanishing with commands queued loses none); that SIGTERM leaves
** the pen up after its wait, the carriage home and the motors off; that after a reply that
** is not OK the board is not driven home; that both CDC interfaces go back to cdc_acm.
** The program re-runs itself under umockdev-wrapper; without it, it exits 77 (skip).
*/
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/usbmock/usbmock.c"
#include "tests/usbmock/ebb.c"

#include "display/sink.h"
#include "display/usb/usb.h"
#include "display/usb/stream.h"

#define SCENE "tests/data/usb/tiny.s74"      /* every command waits for its OK: keep it short */
#define MICRO "tests/data/usb/micro.s74"     /* the runs that fail on purpose and resume */

struct fixture {
  struct mock m;
  struct board b;
  struct dots ref;              /* SCENE's dots */
  struct dots small;            /* MICRO's dots */
  struct dots *cur;             /* the picture of the test running */
  const char *scene;            /* ... and its scene */
  char *dir;
};

/* The test uses the small scene (1) or the tiny one (0). */
static void use_small(struct fixture *fx, int small)
{
  fx->cur = small ? &fx->small : &fx->ref;
  fx->scene = small ? MICRO : SCENE;
}

static struct fixture *F(void **state) { return *state; }

static void reset(struct fixture *fx, int corexy)
{
  use_small(fx, 0);
  mock_reset(&fx->m);
  mock_lock(&fx->m);
  board_reset(&fx->b, corexy);
  mock_unlock(&fx->m);
}

/* The board runs what it still holds (the host has gone). */
static void finish(struct fixture *fx)
{
  mock_lock(&fx->m);
  if (!fx->m.gone) board_finish(&fx->m, &fx->b);
  mock_unlock(&fx->m);
}

static int stream_lib(struct fixture *fx, const char *const *sets, struct t74_error *err)
{
  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.prof = &usb_profile_ebb;
  o.match = o.prof->match;
  usb_settings_default(&o.set, o.prof);
  for (int k = 0; sets && sets[k]; k++)
    if (usb_settings_set(&o.set, o.prof, sets[k], err) != T74_OK) return err->status;
  o.repeat = 1;
  o.scene = fx->scene;
  o.t0 = usb_now();
  struct usb_stream *s;
  if (usb_stream_open(&s, &o, err) != T74_OK) return err->status;
  struct sink k = usb_stream_sink(s);
  int st = T74_OK;
  for (int i = 0; i < fx->cur->n && st == T74_OK; i++)
    st = sink_point(&k, fx->cur->xy[i][0], fx->cur->xy[i][1]);
  if (st == T74_OK) st = sink_end(&k, err);
  return usb_stream_finish(s, st, err);
}

static void check_exact(struct fixture *fx)
{
  finish(fx);
  mock_lock(&fx->m);
  struct board *b = &fx->b;
  if (b->bad_cmd || b->bad_rate || b->off_grid || b->accel_viol || b->stray || b->uninked ||
      b->drawn.n != fx->cur->n)
    fprintf(stderr, "board: bad %d rate %d off-grid %d accel %d stray %d uninked %d, drawn %d of %d\n",
            b->bad_cmd, b->bad_rate, b->off_grid, b->accel_viol, b->stray, b->uninked,
            b->drawn.n, fx->cur->n);
  assert_int_equal(b->bad_cmd, 0);
  assert_int_equal(b->bad_rate, 0);             /* never above 25 kHz */
  assert_int_equal(b->off_grid, 0);
  assert_int_equal(b->accel_viol, 0);           /* ramped: no step lost */
  assert_int_equal(b->stray, 0);                /* no move before the pen was up */
  assert_int_equal(b->uninked, 0);              /* every pen-down waited its travel */
  assert_int_equal(b->drawn.n, fx->cur->n);
  assert_true(dots_same_set(&b->drawn, fx->cur));
  assert_false(b->lowered);                     /* pen up at the end */
  assert_false(b->motors_on);                   /* motors off */
  assert_true(bd_X(b) == 0 && bd_Y(b) == 0);    /* and home */
  mock_unlock(&fx->m);
}

/* dots a and b together hold every dot of ref and nothing else (repeats allowed). */
static int dots_cover(const struct dots *a, const struct dots *b, const struct dots *ref)
{
  static unsigned char in_ref[TUBE_W * TUBE_H], seen[TUBE_W * TUBE_H];
  memset(in_ref, 0, sizeof in_ref);
  memset(seen, 0, sizeof seen);
  for (int k = 0; k < ref->n; k++) in_ref[ref->xy[k][1] * TUBE_W + ref->xy[k][0]] = 1;
  const struct dots *ab[2] = { a, b };
  for (int j = 0; j < 2; j++)
    for (int k = 0; k < ab[j]->n; k++) {
      int at = ab[j]->xy[k][1] * TUBE_W + ab[j]->xy[k][0];
      if (!in_ref[at]) return 0;
      seen[at] = 1;
    }
  for (int k = 0; k < ref->n; k++)
    if (!seen[ref->xy[k][1] * TUBE_W + ref->xy[k][0]]) return 0;
  return 1;
}

static void copy_drawn(struct fixture *fx, struct dots *d)
{
  mock_lock(&fx->m);
  for (int k = 0; k < fx->b.drawn.n; k++) dots_add(d, fx->b.drawn.xy[k][0], fx->b.drawn.xy[k][1]);
  mock_unlock(&fx->m);
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_library_exact(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  struct t74_error err = { T74_OK, "" };
  double t0 = mock_now();
  int st = stream_lib(fx, NULL, &err);
  double t = mock_now() - t0;
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);
  mock_lock(&fx->m);
  double board_s = fx->b.t_last_end / 1000.0;
  int received = fx->b.received, qm = fx->b.qm;
  mock_unlock(&fx->m);
  printf("BENCH ebb emulated board (library): %d dots, %d commands (%d QM) in %.3f s host time; "
         "the board's own motion time %.1f s = %.2f dots/s on a real AxiDraw at these settings\n",
         fx->ref.n, received, qm, t, board_s, fx->ref.n / board_s);
}

/* The servo is set up as the AxiDraw software sets it (standard servo, its default heights
** and rates), so the waits the profile sends cover the travel the board will make. */
static void test_servo_configured(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  use_small(fx, 1);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(stream_lib(fx, NULL, &err), T74_OK);
  check_exact(fx);
  mock_lock(&fx->m);
  struct board b = fx->b;
  mock_unlock(&fx->m);
  assert_int_equal(b.sc4, 20641);               /* 9855 + 17976 x 60 % */
  assert_int_equal(b.sc5, 15248);               /* 9855 + 17976 x 30 % */
  assert_int_equal(b.sc11, 1618);               /* 17976 x 0.24 / 200 x 75 */
  assert_int_equal(b.sc12, 1079);               /* 17976 x 0.24 / 200 x 50 */
  assert_int_equal(b.sc8, 8);
}

/* The narrow-band servo: its own range, rates and a 3 ms servo period (SC,8,1). */
static void test_narrow_band_servo(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  use_small(fx, 1);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "narrow_band=1", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
  mock_lock(&fx->m);
  struct board b = fx->b;
  mock_unlock(&fx->m);
  assert_int_equal(b.sc4, 9720);                /* 5400 + 7200 x 60 % */
  assert_int_equal(b.sc5, 7560);
  assert_int_equal(b.sc8, 1);
}

/* The picture's true size: dot pitch 0.625 mm (A4 landscape, 10 mm margins), measured on
** the board in 1/16 steps of 0.0125 mm; also at 1/8 step (EM,2) with steps_per_mm 40. */
static void true_size(struct fixture *fx, const char *const *sets, int small)
{
  reset(fx, 1);
  use_small(fx, small);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
  int x0 = 999, x1 = -1, y0 = 999, y1 = -1;
  for (int k = 0; k < fx->cur->n; k++) {
    int x = fx->cur->xy[k][0], y = fx->cur->xy[k][1];
    if (x < x0) x0 = x;
    if (x > x1) x1 = x;
    if (y < y0) y0 = y;
    if (y > y1) y1 = y;
  }
  mock_lock(&fx->m);
  double w = (fx->b.max16x - fx->b.min16x) * BD_UNIT16, h = (fx->b.max16y - fx->b.min16y) * BD_UNIT16;
  mock_unlock(&fx->m);
  printf("BENCH ebb picture size: %.3f x %.3f mm for %d x %d dots (pitch 0.625 mm)\n", w, h,
         x1 - x0, y1 - y0);
  assert_true(fabs(w - 0.625 * (x1 - x0)) < 0.02);
  assert_true(fabs(h - 0.625 * (y1 - y0)) < 0.02);
}

static void test_true_size_mm(void **state)
{
  true_size(F(state), NULL, 1);
}

static void test_true_size_eighth_step(void **state)
{
  const char *sets[] = { "microstep=2", "steps_per_mm=40", NULL };
  true_size(F(state), sets, 1);
}

static void test_native_axes_dots_only(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 0);
  use_small(fx, 1);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "corexy=0", "runs=0", "queue=16", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
}

/* The real binary; both CDC interfaces had cdc_acm and have it again (/dev/ttyACM0). */
static void test_binary_exact_cdc_returned(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  use_small(fx, 1);
  mock_lock(&fx->m);
  snprintf(fx->m.drv[0], sizeof fx->m.drv[0], "cdc_acm");
  snprintf(fx->m.drv[1], sizeof fx->m.drv[1], "cdc_acm");
  mock_unlock(&fx->m);
  char *argv[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", NULL };
  double t0 = mock_now();
  int rc = mock_run(argv, NULL);
  double t = mock_now() - t0;
  assert_int_equal(rc, 0);
  check_exact(fx);
  mock_lock(&fx->m);
  assert_string_equal(fx->m.drv[0], "cdc_acm");
  assert_string_equal(fx->m.drv[1], "cdc_acm");
  double first = fx->m.t_first_out - t0, dot = fx->b.t_first_dot - t0;
  mock_unlock(&fx->m);
  printf("BENCH ebb binary: %d dots in %.3f s host time; first byte at the device after %.1f ms, "
         "first dot run after %.1f ms\n", fx->small.n, t, first * 1e3, dot * 1e3);
}

static void test_slow_board(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  use_small(fx, 1);
  mock_lock(&fx->m);
  fx->m.delay_us = 300;                         /* each transfer takes 0.3 ms */
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "queue=12", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
}

/* A faulty run of the binary (exit 4 with `word`, a resume file), then --resume on a board
** reset at home: together the two runs ink every dot, and nothing else. */
static void fault_then_resume(struct fixture *fx, int garbage_at, int vanish_after,
                              const char *word, struct dots *first)
{
  reset(fx, 1);
  use_small(fx, 1);
  mock_lock(&fx->m);
  fx->b.garbage_at = garbage_at;
  fx->b.vanish_after = vanish_after;
  mock_unlock(&fx->m);
  char *save = g_strdup_printf("%s/e.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", "--save", save, NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  if (rc != 4 || !strstr(msg, word)) fprintf(stderr, "first run: rc %d: %s\n", rc, msg);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, word));
  assert_non_null(strstr(msg, "--resume"));
  g_free(msg);
  finish(fx);
  copy_drawn(fx, first);
  assert_true(first->n > 0 && first->n < fx->small.n);
  assert_true(g_file_test(save, G_FILE_TEST_EXISTS));

  reset(fx, 1);
  char *argv2[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", "--resume", save, NULL };
  rc = mock_run(argv2, errf);
  assert_int_equal(rc, 0);
  finish(fx);
  struct dots second = { 0, 0, NULL };
  copy_drawn(fx, &second);
  if (!dots_cover(first, &second, &fx->small))
    fprintf(stderr, "runs drew %d + %d dots, the picture has %d\n", first->n, second.n, fx->small.n);
  assert_true(dots_cover(first, &second, &fx->small));    /* nothing lost, nothing stray */
  assert_true(first->n + second.n <= fx->small.n + 8);    /* at most a few drawn twice */
  assert_false(g_file_test(save, G_FILE_TEST_EXISTS));  /* done: nothing left to resume */
  free(second.xy);
  g_free(save);
  g_free(errf);
}

/* A reply that is not OK: the board's state is unknown, so the pen is raised and the
** motors turned off, but the carriage is not driven home. */
static void test_garbage_no_homing_then_resume(void **state)
{
  struct fixture *fx = F(state);
  struct dots first = { 0, 0, NULL };
  fault_then_resume(fx, 300, 0, "instead of OK", &first);
  free(first.xy);
  reset(fx, 1);                                 /* the same fault again, to look at it */
  mock_lock(&fx->m);
  fx->b.garbage_at = 300;
  mock_unlock(&fx->m);
  char *argv[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", "--save",
                   "/dev/null", NULL };
  assert_int_equal(mock_run(argv, NULL), 4);
  finish(fx);
  mock_lock(&fx->m);
  int sm = fx->b.sm_after_garbage, off = fx->b.em_off_after_garbage, down = fx->b.lowered;
  mock_unlock(&fx->m);
  assert_int_equal(sm, 0);                      /* no move after the garbage */
  assert_int_equal(off, 1);                     /* motors off */
  assert_false(down);                           /* pen up */
}

/* The board vanishes (reset, unplugged) with commands still queued: the dots it had been
** sent and answered OK for, but had not yet run, are not acknowledged; --resume draws them. */
static void test_vanish_queued_not_acked(void **state)
{
  struct fixture *fx = F(state);
  struct dots first = { 0, 0, NULL };
  fault_then_resume(fx, 0, 600, "vanished", &first);
  free(first.xy);
}

/* A signal while plotting (SIGTERM; Ctrl-C is SIGINT): the pen is raised with its wait, the
** carriage goes home, the motors are turned off; exit 4 with a resume file from which the
** picture completes (resume: checked for SIGTERM). */
static void signalled(struct fixture *fx, int sig, int resume)
{
  reset(fx, 1);
  char *save = g_strdup_printf("%s/t.resume", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", "--save", save, NULL };
  pid_t pid = fork();
  if (pid == 0) {
    if (!freopen("/dev/null", "w", stderr)) _exit(127);
    execv(argv[0], argv);
    _exit(127);
  }
  for (int waited = 0; waited < 2000; waited++) {   /* up to 20 s: the machine may be busy */
    mock_lock(&fx->m);
    int got = fx->b.drawn.n;
    mock_unlock(&fx->m);
    if (got >= 60) break;
    usb_sleep_ms(10);
  }
  kill(pid, sig);
  int wst;
  waitpid(pid, &wst, 0);
  assert_true(WIFEXITED(wst));
  assert_int_equal(WEXITSTATUS(wst), 4);
  finish(fx);
  struct dots first = { 0, 0, NULL };
  copy_drawn(fx, &first);
  mock_lock(&fx->m);
  struct board b = fx->b;
  mock_unlock(&fx->m);
  assert_true(first.n >= 60 && first.n < fx->small.n);
  assert_int_equal(b.stray, 0);                 /* raised with its wait before the move */
  assert_int_equal(b.accel_viol, 0);
  assert_false(b.lowered);                      /* pen up */
  assert_true(bd_X(&b) == 0 && bd_Y(&b) == 0);  /* home */
  assert_false(b.motors_on);                    /* motors off */
  assert_true(g_file_test(save, G_FILE_TEST_EXISTS));
  if (resume) {
    reset(fx, 1);
    char *argv2[] = { (char *)mock_tube74(), "stream", MICRO, "--device", "ebb", "--resume", save, NULL };
    assert_int_equal(mock_run(argv2, NULL), 0);
    finish(fx);
    struct dots second = { 0, 0, NULL };
    copy_drawn(fx, &second);
    assert_true(dots_cover(&first, &second, &fx->small));
    free(second.xy);
  }
  free(first.xy);
  g_free(save);
}

static void test_sigterm_pen_up_home_motors_off(void **state)
{
  signalled(F(state), SIGTERM, 1);
}

static void test_ctrl_c_pen_up_home_motors_off(void **state)
{
  signalled(F(state), SIGINT, 0);
}

static int fixture_start(struct fixture *fx)
{
  int rc = mock_begin(&fx->m, 0x04D8, 0xFD92, MOCK_DESC_EBB, SCENE, &fx->ref, &fx->dir);
  if (rc) return rc;
  if (mock_reference(MICRO, &fx->small, fx->dir) != 0 || fx->small.n == 0) {
    fprintf(stderr, "cannot get the reference dots of %s\n", MICRO);
    return 1;
  }
  fx->m.on_out = board_out;
  fx->m.on_tick = board_tick;
  fx->m.on_in_done = board_in;
  fx->m.user = &fx->b;
  /* cdc_acm: bound to both interfaces by a probe of the communication interface (0);
     unbinding either unbinds both (Linux drivers/usb/class/cdc-acm.c) */
  snprintf(fx->m.probe[0], sizeof fx->m.probe[0], "cdc_acm");
  fx->m.probe_also[0] = 3;
  fx->m.unbind_also[0] = fx->m.unbind_also[1] = 3;
  return 0;
}

int main(int argc, char **argv)
{
  int rc = mock_reexec(argc, argv);
  if (rc) return rc;
  struct fixture *fx = calloc(1, sizeof *fx);
  if ((rc = fixture_start(fx)) != 0) return rc;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test_prestate(test_library_exact, fx),
    cmocka_unit_test_prestate(test_servo_configured, fx),
    cmocka_unit_test_prestate(test_narrow_band_servo, fx),
    cmocka_unit_test_prestate(test_true_size_mm, fx),
    cmocka_unit_test_prestate(test_true_size_eighth_step, fx),
    cmocka_unit_test_prestate(test_native_axes_dots_only, fx),
    cmocka_unit_test_prestate(test_binary_exact_cdc_returned, fx),
    cmocka_unit_test_prestate(test_slow_board, fx),
    cmocka_unit_test_prestate(test_garbage_no_homing_then_resume, fx),
    cmocka_unit_test_prestate(test_vanish_queued_not_acked, fx),
    cmocka_unit_test_prestate(test_sigterm_pen_up_home_motors_off, fx),
    cmocka_unit_test_prestate(test_ctrl_c_pen_up_home_motors_off, fx),
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->b.drawn.xy);
  free(fx->small.xy);
  if (fx->b.inbuf) g_byte_array_free(fx->b.inbuf, TRUE);
  free(fx);
  return rc;
}
