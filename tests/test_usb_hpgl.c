/*
** test_usb_hpgl.c — the `hpgl` USB profile against an emulated HP-GL plotter on a USB
** printer-class interface (display/usb/hpgl.c, display/usb/penplan.c).
**
** This file contains code to check, with the plotter of tests/usbmock/plotter.c under
** umockdev, that the HP-GL the profile sends draws `tube74 render --dump points` EXACTLY
** (the same dots, each once), through the library and through the real binary; that runs
** of dots become strokes when the timing rule says so (and not with runs=0); that the
** plotted pen-up travel is shorter than drawing the dots in production order; that a
** bound kernel driver (usblp) is detached and given back; that GET_PORT_STATUS is asked
** before each band and "paper out" stops the run with exit 4 and a resume file from which
** the run continues without losing or repeating a dot; and a plotter that vanishes
** mid-stream, then --resume; `tube74 devices` lists the plotter and says whether its
** device id declares HP-GL.
** The program re-runs itself under umockdev-wrapper; without it, it exits 77 (skip).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/usbmock/usbmock.c"
#include "tests/usbmock/plotter.c"

#include "display/sink.h"
#include "display/usb/penplan.h"
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
  assert_int_equal(fx->p.clipped, 0);           /* all inside the hard-clip limits */
  assert_int_equal(fx->p.off_grid, 0);
  assert_int_equal(fx->p.drawn.n, fx->ref.n);
  assert_true(dots_same_set(&fx->p.drawn, &fx->ref));
  assert_false(fx->p.pen_down);
  assert_string_equal(fx->p.last, "SP0");       /* pen put away at the end */
  mock_unlock(&fx->m);
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_library_exact_strokes_order(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  struct t74_error err = { T74_OK, "" };
  double t0 = mock_now();
  int st = stream_lib(fx, NULL, &err);
  double t = mock_now() - t0;
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);
  double naive = travel_in_order(&fx->ref);
  assert_true(fx->p.strokes > 0);
  assert_true(fx->p.travel < naive);
  assert_true(fx->p.status_queries >= 2);       /* at open and before each band */
  printf("BENCH hpgl emulated plotter (library): %d dots in %.3f s = %.0f dots/s; %d strokes + "
         "%d single dots; pen-up travel %.0f dots (production order: %.0f)\n", fx->ref.n, t,
         fx->ref.n / t, fx->p.strokes, fx->p.singles, fx->p.travel, naive);
}

static void test_dots_only(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "runs=0", "chunk_bytes=64", NULL };
  assert_int_equal(stream_lib(fx, sets, &err), T74_OK);
  check_exact(fx);
  assert_int_equal(fx->p.strokes, 0);
  /* the rule itself: slow pen-down drawing and instant lifts make dots faster */
  assert_false(penplan_rule(0.625, 500, 1, 0));
  assert_true(penplan_rule(0.625, 500, 380, 30));
}

static void test_binary_exact_driver_detached(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  snprintf(fx->m.drv[0], sizeof fx->m.drv[0], "usblp");
  mock_unlock(&fx->m);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--usb", "067b:2305",
                   NULL };
  double t0 = mock_now();
  int rc = mock_run(argv, NULL);
  double t = mock_now() - t0;
  assert_int_equal(rc, 0);
  check_exact(fx);
  mock_lock(&fx->m);
  assert_int_equal(fx->m.detaches, 1);
  assert_int_equal(fx->m.attaches, 1);
  assert_string_equal(fx->m.drv[0], "usblp");   /* the printer driver is back */
  double first = fx->m.t_first_out - t0, dot = fx->p.t_first_dot - t0;
  mock_unlock(&fx->m);
  printf("BENCH hpgl binary: %d dots in %.3f s = %.0f dots/s; first byte at the device after "
         "%.1f ms, first dot after %.1f ms\n", fx->ref.n, t, fx->ref.n / t, first * 1e3, dot * 1e3);
}

/* A faulty run of the binary (exit 4 with `word` in the message, resume file), the fault
** cleared, then --resume: together, every dot once. */
static void fault_then_resume(struct fixture *fx, int paper_out_at, long long vanish_after,
                              const char *word)
{
  reset(fx);
  mock_lock(&fx->m);
  fx->p.paper_out_at = paper_out_at;
  fx->m.vanish_after = vanish_after;
  mock_unlock(&fx->m);
  char *save = g_strdup_printf("%s/h.resume", fx->dir);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  unlink(save);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--save", save,
                   "--set", "chunk_bytes=100", NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  if (rc != 4 || !strstr(msg, word)) fprintf(stderr, "first run: rc %d: %s\n", rc, msg);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, word));
  g_free(msg);
  struct dots all = { 0, 0, NULL };
  mock_lock(&fx->m);
  for (int k = 0; k < fx->p.drawn.n; k++) dots_add(&all, fx->p.drawn.xy[k][0], fx->p.drawn.xy[k][1]);
  mock_unlock(&fx->m);
  assert_true(all.n < fx->ref.n);
  assert_true(g_file_test(save, G_FILE_TEST_EXISTS));

  reset(fx);
  char *argv2[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--resume", save,
                    NULL };
  rc = mock_run(argv2, errf);
  assert_int_equal(rc, 0);
  mock_lock(&fx->m);
  for (int k = 0; k < fx->p.drawn.n; k++) dots_add(&all, fx->p.drawn.xy[k][0], fx->p.drawn.xy[k][1]);
  mock_unlock(&fx->m);
  assert_int_equal(all.n, fx->ref.n);
  assert_true(dots_same_set(&all, &fx->ref));
  free(all.xy);
  g_free(save);
  g_free(errf);
}

static void test_paper_out_then_resume(void **state)
{
  fault_then_resume(F(state), 6, -1, "out of paper");    /* paper runs out at band 5 */
}

static void test_vanish_then_resume(void **state)
{
  /* 7,777 bytes: inside a command, inside a band, after several strokes of it */
  fault_then_resume(F(state), 0, 7777, "vanished");
}

/* The picture is fitted inside the limits the plotter gives (OH): a letter-size 7475A. */
static void test_oh_limits_fitted(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->p.clip[2] = 10365;                        /* 7475A, US A paper */
  fx->p.clip[3] = 7962;
  fx->p.g = pen_geom_fit(200, 200, 10365 - 400, 7962 - 400);
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  int st = stream_lib(fx, NULL, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);
  assert_int_equal(fx->p.oh_queries, 1);
}

/* A one-way link (OH never answered): the 7475A's documented A4 limits are used, or its
** letter limits with --paper letter. */
static void test_model_limits_without_oh(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  fx->p.answers = 0;
  mock_unlock(&fx->m);
  struct t74_error err = { T74_OK, "" };
  const char *sets[] = { "query_ms=100", NULL };
  int st = stream_lib(fx, sets, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  assert_int_equal(st, T74_OK);
  check_exact(fx);

  reset(fx);                                    /* letter paper, told with --paper */
  mock_lock(&fx->m);
  fx->p.answers = 0;
  fx->p.clip[2] = 10365;
  fx->p.clip[3] = 7962;
  fx->p.g = pen_geom_fit(200, 200, 10365 - 400, 7962 - 400);
  mock_unlock(&fx->m);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--paper", "letter",
                   "--set", "query_ms=100", NULL };
  assert_int_equal(mock_run(argv, NULL), 0);
  check_exact(fx);
}

/* A printer-class device whose id does not declare HP-GL (a laser printer) is refused with
** a clear message and nothing sent to it; --force drives it anyway. */
static void test_not_hpgl_refused_then_forced(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  mock_lock(&fx->m);
  snprintf(fx->p.id, sizeof fx->p.id, "MFG:Hewlett-Packard;MDL:LaserJet 4;CMD:PCL,PJL;CLS:PRINTER;");
  mock_unlock(&fx->m);
  char *errf = g_strdup_printf("%s/err.txt", fx->dir);
  char *argv[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--save",
                   "/dev/null", NULL };
  int rc = mock_run(argv, errf);
  gchar *msg = NULL;
  g_file_get_contents(errf, &msg, NULL, NULL);
  assert_int_equal(rc, 4);
  assert_non_null(strstr(msg, "does not declare HP-GL"));
  assert_non_null(strstr(msg, "PCL,PJL"));
  assert_non_null(strstr(msg, "--force"));
  g_free(msg);
  mock_lock(&fx->m);
  assert_int_equal(fx->p.id_queries, 1);
  assert_int_equal(fx->m.out_bytes, 0);         /* not one byte went to the printer */
  mock_unlock(&fx->m);

  reset(fx);
  mock_lock(&fx->m);
  snprintf(fx->p.id, sizeof fx->p.id, "MFG:Hewlett-Packard;MDL:7475A;CMD:PCL;");
  mock_unlock(&fx->m);
  char *argv2[] = { (char *)mock_tube74(), "stream", SCENE, "--device", "hpgl", "--force", NULL };
  assert_int_equal(mock_run(argv2, errf), 0);
  check_exact(fx);
  g_free(errf);
}

/* `tube74 devices` run against the mock: its stdout, g_free'd by the caller. */
static gchar *devices_text(struct fixture *fx)
{
  char *out = g_strdup_printf("%s/devices.txt", fx->dir);
  pid_t pid = fork();
  if (pid == 0) {
    if (!freopen(out, "w", stdout)) _exit(127);
    execl(mock_tube74(), mock_tube74(), "devices", (char *)NULL);
    _exit(127);
  }
  int st;
  waitpid(pid, &st, 0);
  assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  gchar *txt = NULL;
  assert_true(g_file_get_contents(out, &txt, NULL, NULL));
  g_free(out);
  return txt;
}

/* devices lists the printer-class device and says whether its GET_DEVICE_ID declares
** HP-GL (what streaming requires), sending nothing to it. */
static void test_devices_lists_plotter(void **state)
{
  struct fixture *fx = F(state);
  reset(fx);
  gchar *txt = devices_text(fx);
  assert_non_null(strstr(txt, "hpgl    067b:2305"));   /* a printer-class interface */
  assert_non_null(strstr(txt, "; declares HP-GL"));
  assert_null(strstr(txt, "helios"));                   /* and nothing else matches */
  g_free(txt);

  reset(fx);
  mock_lock(&fx->m);
  snprintf(fx->p.id, sizeof fx->p.id, "MFG:Hewlett-Packard;MDL:LaserJet 4;CMD:PCL,PJL;CLS:PRINTER;");
  mock_unlock(&fx->m);
  txt = devices_text(fx);
  assert_non_null(strstr(txt, "hpgl    067b:2305"));
  assert_non_null(strstr(txt, "; does not declare HP-GL (command set `PCL,PJL`)"));
  g_free(txt);
  mock_lock(&fx->m);
  assert_int_equal(fx->p.id_queries, 1);
  assert_int_equal(fx->m.out_bytes, 0);         /* listing sends nothing to the device */
  mock_unlock(&fx->m);

  reset(fx);
  mock_lock(&fx->m);
  fx->p.id[0] = 0;                              /* GET_DEVICE_ID not supported: a stall */
  mock_unlock(&fx->m);
  txt = devices_text(fx);
  assert_non_null(strstr(txt, "; gives no device id"));
  g_free(txt);
}

static int fixture_start(struct fixture *fx)
{
  int rc = mock_begin(&fx->m, 0x067b, 0x2305, MOCK_DESC_HPGL, SCENE, &fx->ref, &fx->dir);
  if (rc) return rc;
  fx->m.on_out = plotter_out;
  fx->m.on_ctrl = plotter_ctrl;
  snprintf(fx->m.probe[0], sizeof fx->m.probe[0], "usblp");   /* the printer-class driver */
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
    cmocka_unit_test_prestate(test_library_exact_strokes_order, fx),
    cmocka_unit_test_prestate(test_dots_only, fx),
    cmocka_unit_test_prestate(test_binary_exact_driver_detached, fx),
    cmocka_unit_test_prestate(test_paper_out_then_resume, fx),
    cmocka_unit_test_prestate(test_vanish_then_resume, fx),
    cmocka_unit_test_prestate(test_oh_limits_fitted, fx),
    cmocka_unit_test_prestate(test_model_limits_without_oh, fx),
    cmocka_unit_test_prestate(test_not_hpgl_refused_then_forced, fx),
    cmocka_unit_test_prestate(test_devices_lists_plotter, fx),
  };
  rc = cmocka_run_group_tests(tests, NULL, NULL);
  mock_end(&fx->m, &fx->ref, fx->dir);     /* first: the device thread stops */
  free(fx->p.drawn.xy);
  free(fx);
  return rc;
}
