/*
** test_usb_ebb.c — the `ebb` USB profile against an emulated EiBotBoard (display/usb/ebb.c;
** hardware-facts.md "EiBotBoard").
**
** This file contains code to play an EBB on its CDC data endpoints under umockdev
** (tests/usbmock/usbmock.c): it reads CR-terminated commands from bulk OUT 0x02, executes
** EM, SP and SM (AxiDraw mixed axes or native), answers each with "OK\r\n" on bulk IN 0x82,
** and counts a command's dots as drawn only when its OK has reached the host — the
** acknowledgement the profile relies on. A dot is drawn when the pen goes down (SP,0) and
** along every pen-down move (SM); decoded back to tube dots they must equal `tube74 render
** --dump points` EXACTLY (the same set, each dot once: the plotter reorders within a band).
** Also checked: never more commands in flight than the queue depth, the step rate stays
** under 25 kHz, the pen ends up and home; a slow board; a board answering garbage and one
** that vanishes, each followed by --resume (the union of both runs is every dot, once).
** The program re-runs itself under umockdev-wrapper; without it, it exits 77 (skip).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/usbmock/usbmock.c"

#include "display/usb/penplan.h"
#include "display/sink.h"
#include "display/usb/usb.h"
#include "display/usb/stream.h"

#define SCENE "tests/data/usb/tiny.s74"      /* every command waits for its OK: keep it short */

struct ecmd {                   /* a command answered, its OK not yet delivered */
  int n;                        /* dots it drew */
  int (*xy)[2];
};

struct board {                  /* the emulated EBB (under m->lock) */
  char cmd[128];
  int ncmd;
  struct pen_geom g;
  int corexy;
  long X, Y;
  int pen_down;
  struct dots drawn;            /* dots whose OK reached the host */
  GQueue unacked;               /* struct ecmd*, oldest first */
  int delivered;                /* OK bytes delivered beyond whole OKs */
  int received, answered, max_inflight;
  int garbage_at;               /* answer command N with an error line (0: never) */
  int dead;                     /* after that: executes and answers nothing more */
  int bad_rate, bad_cmd, off_grid, sm_count;
  double t_first_dot;           /* when the pen first went down on a dot */
};

static void board_dot(struct board *b, struct ecmd *c)
{
  long dx = b->X - b->g.ox, dy = b->Y - b->g.oy;
  if (dx % b->g.pitch || dy % b->g.pitch) { b->off_grid++; return; }
  if (b->t_first_dot == 0) b->t_first_dot = mock_now();
  c->xy = realloc(c->xy, sizeof *c->xy * (size_t)(c->n + 1));
  c->xy[c->n][0] = (int)(dx / b->g.pitch);
  c->xy[c->n][1] = TUBE_H - 1 - (int)(dy / b->g.pitch);
  c->n++;
}

static void board_exec(struct mock *m, struct board *b, const char *t)
{
  if (b->dead) return;
  struct ecmd *c = g_new0(struct ecmd, 1);
  long ms, a1, a2, v;
  b->received++;
  if (b->garbage_at && b->received == b->garbage_at) {
    mock_reply(m, 0x82, "!8 Err: Unknown command\r\n", 25);
    b->dead = 1;                                /* nothing after the error is answered */
    g_free(c);
    return;
  }
  if (!strncmp(t, "EM,", 3)) {
  } else if (sscanf(t, "SP,%ld", &v) == 1) {
    if (v == 0 && !b->pen_down) board_dot(b, c);
    b->pen_down = v == 0;
  } else if (sscanf(t, "SM,%ld,%ld,%ld", &ms, &a1, &a2) == 3) {
    b->sm_count++;
    long m1 = labs(a1) > labs(a2) ? labs(a1) : labs(a2);
    if (ms < 1 || m1 * 1000 > 25000 * ms) b->bad_rate++;
    long dX = b->corexy ? (a1 + a2) / 2 : a1, dY = b->corexy ? (a1 - a2) / 2 : a2;
    if (b->corexy && (a1 + a2) % 2) b->bad_cmd++;
    if (b->pen_down) {                          /* drawing: along a row only */
      if (dY != 0 || dX % b->g.pitch) b->bad_cmd++;
      long steps = labs(dX) / b->g.pitch, dir = dX > 0 ? 1 : -1;
      for (long k = 0; k < steps; k++) {
        b->X += dir * b->g.pitch;
        board_dot(b, c);
      }
    } else {
      b->X += dX;
      b->Y += dY;
    }
  } else {
    b->bad_cmd++;
  }
  mock_reply(m, 0x82, "OK\r\n", 4);
  g_queue_push_tail(&b->unacked, c);
  int inflight = b->received - b->answered;
  if (inflight > b->max_inflight) b->max_inflight = inflight;
}

static void board_out(struct mock *m, unsigned char ep, const unsigned char *d, int n)
{
  struct board *b = m->user;
  if (ep != 0x02) return;
  for (int k = 0; k < n; k++) {
    if (d[k] == '\r') {
      b->cmd[b->ncmd] = 0;
      board_exec(m, b, b->cmd);
      b->ncmd = 0;
    } else if (b->ncmd < (int)sizeof b->cmd - 1) {
      b->cmd[b->ncmd++] = (char)d[k];
    }
  }
}

/* Reply bytes reached the host: every whole OK commits its command's dots. */
static void board_in(struct mock *m, unsigned char ep, int n)
{
  struct board *b = m->user;
  if (ep != 0x82) return;
  b->delivered += n;
  while (b->delivered >= 4 && b->unacked.head) {
    struct ecmd *c = g_queue_pop_head(&b->unacked);
    for (int k = 0; k < c->n; k++) dots_add(&b->drawn, c->xy[k][0], c->xy[k][1]);
    free(c->xy);
    g_free(c);
    b->delivered -= 4;
    b->answered++;
  }
}

struct fixture {
  struct mock m;
  struct board b;
  struct dots ref;
  char *dir;
};

static struct fixture *F(void **state) { return *state; }

static void reset(struct fixture *fx, int corexy)
{
  mock_reset(&fx->m);
  g_mutex_lock(&fx->m.lock);
  struct board *b = &fx->b;
  struct ecmd *c;
  while ((c = g_queue_pop_head(&b->unacked))) { free(c->xy); g_free(c); }
  struct dots keep = b->drawn;
  memset(b, 0, sizeof *b);
  g_queue_init(&b->unacked);
  b->drawn = keep;
  b->drawn.n = 0;
  b->g = pen_geom_fit(10 * 40, 10 * 40, 277 * 40, 190 * 40);  /* the profile's defaults */
  b->corexy = corexy;
  g_mutex_unlock(&fx->m.lock);
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

static void check_exact(struct fixture *fx, int queue)
{
  g_mutex_lock(&fx->m.lock);
  struct board *b = &fx->b;
  assert_int_equal(b->bad_cmd, 0);
  assert_int_equal(b->bad_rate, 0);
  assert_int_equal(b->off_grid, 0);
  assert_true(b->max_inflight <= queue);
  assert_int_equal(b->drawn.n, fx->ref.n);
  assert_true(dots_same_set(&b->drawn, &fx->ref));
  assert_false(b->pen_down);                    /* pen up at the end */
  g_mutex_unlock(&fx->m.lock);
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
  check_exact(fx, 3);
  assert_true(fx->b.X == 0 && fx->b.Y == 0);    /* and home */
  printf("BENCH ebb emulated board (library): %d dots, %d commands in %.3f s = %.0f dots/s\n",
         fx->ref.n, fx->b.received, t, fx->ref.n / t);
}

static void test_native_axes_dots_only(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 0);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "corexy=0", "runs=0", "queue=16", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx, 16);
}

static void test_binary_exact(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "ebb", NULL };
  double t0 = mock_now();
  int rc = mock_run(argv, NULL);
  double t = mock_now() - t0;
  assert_int_equal(rc, 0);
  check_exact(fx, 3);
  printf("BENCH ebb binary: %d dots in %.3f s = %.0f dots/s; first byte at the device after "
         "%.1f ms, first dot after %.1f ms\n", fx->ref.n, t, fx->ref.n / t,
         (fx->m.t_first_out - t0) * 1e3, (fx->b.t_first_dot - t0) * 1e3);
}

static void test_slow_board(void **state)
{
  struct fixture *fx = F(state);
  reset(fx, 1);
  g_mutex_lock(&fx->m.lock);
  fx->m.delay_us = 300;                         /* each transfer takes 0.3 ms */
  g_mutex_unlock(&fx->m.lock);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "queue=12", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx, 12);
}

/* Run the binary twice: a faulty run (exit 4, resume file), then --resume. */
static void fault_then_resume(struct fixture *fx, int garbage_at, int vanish_in_at, const char *word)
{
  reset(fx, 1);
  g_mutex_lock(&fx->m.lock);
  fx->b.garbage_at = garbage_at;
  fx->m.vanish_in_at = vanish_in_at;
  g_mutex_unlock(&fx->m.lock);
  char *save = g_strdup_printf("%s/e.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  /* queue=12: fewer round trips (the default depth of 3 is checked above) */
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "ebb", "--save", save,
                   "--set", "queue=12", NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  if (rc != 4 || !strstr(msg, word)) fprintf(stderr, "first run: rc %d: %s\n", rc, msg);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, word));
  assert_non_null(strstr(msg, "--resume"));
  g_free(msg);
  g_mutex_lock(&fx->m.lock);
  struct dots first = { 0, 0, NULL };
  for (int k = 0; k < fx->b.drawn.n; k++) dots_add(&first, fx->b.drawn.xy[k][0], fx->b.drawn.xy[k][1]);
  g_mutex_unlock(&fx->m.lock);
  assert_true(first.n > 0 && first.n < fx->ref.n);
  assert_true(g_file_test(save, G_FILE_TEST_EXISTS));

  reset(fx, 1);
  char *argv2[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "ebb", "--resume", save,
                    "--set", "queue=12", NULL };
  rc = mock_run(argv2, errf);
  assert_int_equal(rc, 0);
  g_mutex_lock(&fx->m.lock);
  for (int k = 0; k < fx->b.drawn.n; k++) dots_add(&first, fx->b.drawn.xy[k][0], fx->b.drawn.xy[k][1]);
  g_mutex_unlock(&fx->m.lock);
  assert_int_equal(first.n, fx->ref.n);         /* nothing lost, nothing twice */
  assert_true(dots_same_set(&first, &fx->ref));
  assert_false(g_file_test(save, G_FILE_TEST_EXISTS));  /* done: nothing left to resume */
  free(first.xy);
  g_free(save);
  g_free(errf);
}

static void test_garbage_then_resume(void **state)
{
  fault_then_resume(F(state), 900, 0, "instead of OK");
}

static void test_vanish_then_resume(void **state)
{
  fault_then_resume(F(state), 0, 100, "vanished");   /* ~1,200 commands in */
}

static int fixture_start(struct fixture *fx)
{
  int rc = mock_begin(&fx->m, 0x04D8, 0xFD92, MOCK_DESC_EBB, SCENE, &fx->ref, &fx->dir);
  if (rc) return rc;
  g_queue_init(&fx->b.unacked);
  fx->m.on_out = board_out;
  fx->m.on_in_done = board_in;
  fx->m.user = &fx->b;
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
    cmocka_unit_test_prestate(test_native_axes_dots_only, fx),
    cmocka_unit_test_prestate(test_binary_exact, fx),
    cmocka_unit_test_prestate(test_slow_board, fx),
    cmocka_unit_test_prestate(test_garbage_then_resume, fx),
    cmocka_unit_test_prestate(test_vanish_then_resume, fx),
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->b.drawn.xy);
  free(fx);
  return rc;
}
