/*
** test_core_need.c — imports drawn with the core they need; "does not fit" giving the whole
** need in one message (issue 20, "Everyday use"; cli/pipeline.c job_run, emu/core.c
** core_set_growth).
**
** This file contains code to check, on a sphere of 1,536 quadrilaterals generated here (far
** more than the HITAC-10's 16,384 words hold) and on the shipped street scene:
**   import     `render big.obj` without --core: exit 0, the picture written, the warning
**              "big.obj: warning: the model needs N words of core; the HITAC-10 had 16384",
**              and --stats core_words_needed N (= core_words_used), fits_16k false,
**              core_grown true, core_words >= N; a small cube: no warning, fits_16k true;
**   --core     `--core 16384` (and any core below N): exit 3, nothing written, one message
**              "needs N words in all, C available ... run it with --core N" with the same N
**              whatever C was; `--core N` draws the same dots as the growing core,
**              core_words_used N; `--core N-1` exit 3 naming N again;
**   .s74       the street with --core 9000: exit 3 with its whole need, which is the
**              core_words_used of a run on the default core, and --core of that fits;
**   growing    the core model itself: a growing core keeps the low tables and the high
**              region's words as they were, and ends where a fixed core of its final size
**              would.
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "emu/core.h"
#include "tests/ref/testkit.h"

#define PI 3.14159265358979323846

static char scratch[64];

static void path(char *out, size_t cap, const char *name)
{
  snprintf(out, cap, "%s/%s", scratch, name);
}

/* A UV sphere of 48 x 32 quadrilaterals (non-planar once rounded: split). */
static void write_sphere(const char *p)
{
  FILE *f = fopen(p, "w");
  assert_non_null(f);
  const int N = 48, M = 32;
  for (int j = 0; j <= M; j++)
    for (int i = 0; i < N; i++) {
      double th = PI * j / M, ph = 2 * PI * i / N;
      fprintf(f, "v %.6f %.6f %.6f\n", sin(th) * cos(ph), cos(th), sin(th) * sin(ph));
    }
  for (int j = 0; j < M; j++)
    for (int i = 0; i < N; i++)
      fprintf(f, "f %d %d %d %d\n", j * N + i + 1, j * N + (i + 1) % N + 1,
              (j + 1) * N + (i + 1) % N + 1, (j + 1) * N + i + 1);
  assert_int_equal(fclose(f), 0);
}

/* KEY's number (true 1, false 0) in the --stats file; the test fails when it is absent or
   null. */
static double field(const char *json, const char *key)
{
  double v;
  int r = tk_stat(json, key, &v);
  if (r) fail_msg("%s: %s is %s", json, key, r > 0 ? "null" : "missing");
  return v;
}

/* Whether KEY's value in the --stats file is `null` (the test fails when it is absent). */
static int field_null(const char *json, const char *key)
{
  double v;
  int r = tk_stat(json, key, &v);
  if (r < 0) fail_msg("%s: no %s", json, key);
  return r == 1;
}

/* The N of "needs N words in all" in the file, checking the rest of the message. */
static long need_in(const char *errfile, long avail)
{
  char *e = tk_slurp(errfile, NULL);
  assert_non_null(e);
  const char *m = strstr(e, "does not fit the core: needs ");
  if (!m) fail_msg("no message: %s", e);
  long n = strtol(m + 29, NULL, 10);
  char want[96];
  snprintf(want, sizeof want, "needs %ld words in all, %ld available", n, avail);
  if (!strstr(e, want)) fail_msg("wanted \"%s\" in: %s", want, e);
  snprintf(want, sizeof want, "run it with --core %ld", n);
  assert_non_null(strstr(e, want));
  free(e);
  return n;
}

static void test_import_grows(void **state)
{
  (void)state;
  char obj[128], png[128], js[128], err[128], pts[128], arg[140];
  path(obj, sizeof obj, "big.obj");
  path(png, sizeof png, "big.png");
  path(js, sizeof js, "big.json");
  path(err, sizeof err, "big.err");
  path(pts, sizeof pts, "big.pts");
  snprintf(arg, sizeof arg, "points=%s", pts);
  write_sphere(obj);
  assert_int_equal(tk_runl(NULL, err, "render", obj, "--engine", "1974", "-o", png, "--stats", js,
                           "--dump", arg, (char *)NULL), 0);
  assert_int_equal(access(png, F_OK), 0);
  long need = (long)field(js, "core_words_needed");
  assert_true(need > 16384);
  assert_int_equal((long)field(js, "core_words_used"), need);
  assert_true(field(js, "core_words") >= need);
  assert_true(field(js, "fits_16k") == 0);
  assert_true(field(js, "core_grown") == 1);
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  char want[160];
  snprintf(want, sizeof want, "big.obj: warning: the model needs %ld words of core; the "
           "HITAC-10 had 16384", need);
  if (!strstr(e, want)) fail_msg("wanted \"%s\" in: %s", want, e);
  free(e);
  char *auto_pts = tk_slurp(pts, NULL);
  assert_non_null(auto_pts);
  assert_true(strlen(auto_pts) > 1000);

  /* --core too small: exit 3, nothing written, the whole need in one go */
  static const char *const small[] = { "16384", "30000", "60000" };
  for (size_t k = 0; k < sizeof small / sizeof *small; k++) {
    char png2[128];
    path(png2, sizeof png2, "small.png");
    assert_int_equal(tk_runl(NULL, err, "render", obj, "--core", small[k], "-o", png2,
                             (char *)NULL), 3);
    assert_int_equal(access(png2, F_OK), -1);
    assert_int_equal(need_in(err, atol(small[k])), need);
  }
  /* --core N: the same dots, exactly N used; N - 1: exit 3 naming N */
  char nbuf[32], pts2[128], arg2[140];
  snprintf(nbuf, sizeof nbuf, "%ld", need);
  path(pts2, sizeof pts2, "exact.pts");
  snprintf(arg2, sizeof arg2, "points=%s", pts2);
  assert_int_equal(tk_runl(NULL, NULL, "render", obj, "--core", nbuf, "--stats", js, "--dump",
                           arg2, (char *)NULL), 0);
  assert_int_equal((long)field(js, "core_words_used"), need);
  assert_int_equal((long)field(js, "core_words"), need);
  assert_true(field(js, "core_grown") == 0);
  char *exact_pts = tk_slurp(pts2, NULL);
  assert_non_null(exact_pts);
  assert_string_equal(exact_pts, auto_pts);
  snprintf(nbuf, sizeof nbuf, "%ld", need - 1);
  assert_int_equal(tk_runl(NULL, err, "render", obj, "--core", nbuf, (char *)NULL), 3);
  assert_int_equal(need_in(err, need - 1), need);
  free(auto_pts);
  free(exact_pts);
}

static void test_small_import_fits(void **state)
{
  (void)state;
  char obj[128], js[128], err[128];
  path(obj, sizeof obj, "cube.obj");
  path(js, sizeof js, "cube.json");
  path(err, sizeof err, "cube.err");
  static const char cube[] =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  assert_int_equal(tk_put(obj, cube, sizeof cube - 1), 0);
  assert_int_equal(tk_runl(NULL, err, "render", obj, "--engine", "1974", "--stats", js,
                           (char *)NULL), 0);
  assert_true(field(js, "fits_16k") == 1);
  assert_true(field(js, "core_grown") == 0);
  assert_int_equal((long)field(js, "core_words"), 16384);
  assert_true(field(js, "core_words_needed") <= 16384);
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_null(strstr(e, "words of core"));
  free(e);
}

/* The default engine for an import is `points` (issue 19), which has no core: the core figures
   are null, no warning, and the picture is the one the 1974 engine draws with the core it
   needs. */
static void test_import_default_engine(void **state)
{
  (void)state;
  char obj[128], js[128], err[128], p1[128], p2[128], a1[140], a2[140];
  path(obj, sizeof obj, "big2.obj");
  path(js, sizeof js, "big2.json");
  path(err, sizeof err, "big2.err");
  path(p1, sizeof p1, "big2-auto.pts");
  path(p2, sizeof p2, "big2-1974.pts");
  snprintf(a1, sizeof a1, "points=%s", p1);
  snprintf(a2, sizeof a2, "points=%s", p2);
  write_sphere(obj);
  assert_int_equal(tk_runl(NULL, err, "render", obj, "--stats", js, "--dump", a1, (char *)NULL), 0);
  char *s = tk_slurp(js, NULL);
  assert_non_null(s);
  assert_non_null(strstr(s, "\"engine\": \"points\""));
  free(s);
  assert_true(field_null(js, "core_words_needed"));
  assert_true(field_null(js, "fits_16k"));
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_null(strstr(e, "words of core"));
  free(e);
  assert_int_equal(tk_runl(NULL, NULL, "render", obj, "--engine", "1974", "--dump", a2,
                           (char *)NULL), 0);
  char *d1 = tk_slurp(p1, NULL), *d2 = tk_slurp(p2, NULL);
  assert_non_null(d1);
  assert_non_null(d2);
  assert_true(strlen(d1) > 1000);
  assert_string_equal(d1, d2);
  free(d1);
  free(d2);
}

static void test_s74_exit_3(void **state)
{
  (void)state;
  char js[128], err[128], png[128];
  path(js, sizeof js, "street.json");
  path(err, sizeof err, "street.err");
  path(png, sizeof png, "street.png");
  assert_int_equal(tk_runl(NULL, NULL, "render", "scenes/street.s74", "--stats", js,
                           (char *)NULL), 0);
  long used = (long)field(js, "core_words_used");
  assert_true(field(js, "fits_16k") == 1);
  assert_true(used > 9000);
  assert_int_equal(tk_runl(NULL, err, "render", "scenes/street.s74", "--core", "9000", "-o", png,
                           (char *)NULL), 3);
  assert_int_equal(need_in(err, 9000), used);
  assert_int_equal(access(png, F_OK), -1);
  char nbuf[32];
  snprintf(nbuf, sizeof nbuf, "%ld", used);
  assert_int_equal(tk_runl(NULL, NULL, "render", "scenes/street.s74", "--core", nbuf,
                           (char *)NULL), 0);
}

/* The model: a growing core keeps what its tables hold. */
static void test_growing_core(void **state)
{
  (void)state;
  struct core *c = core_new(64);
  assert_non_null(c);
  core_set_growth(c, 1024);
  struct t74_error err = { T74_OK, "" };
  uint32_t a, b;
  assert_int_equal(core_alloc(c, "LOW", 40, &a, &err), T74_OK);
  core_write(c, a + 39, 0x1234);
  assert_int_equal(core_high_grow(c, "HIGH", 20, &err), T74_OK);
  core_high_set(c, 19, 0xbeef);
  core_high_set(c, 0, 0x0042);
  assert_int_equal(core_words(c), 64);
  assert_int_equal(core_alloc(c, "MORE", 100, &b, &err), T74_OK);   /* 160 > 64: grows */
  assert_int_equal(core_words(c), 256);
  assert_int_equal(core_first_words(c), 64);
  assert_int_equal(core_read(c, a + 39), 0x1234);
  assert_int_equal(core_high_get(c, 19), 0xbeef);
  assert_int_equal(core_high_get(c, 0), 0x0042);
  assert_int_equal(core_read(c, 255), 0x0042);        /* word 0 of the high region: the top */
  assert_int_equal(core_read(c, b + 99), 0);          /* the new words are zero */
  assert_int_equal(core_peak(c), 160);
  /* beyond the limit it refuses as a fixed core does */
  assert_int_equal(core_alloc(c, "HUGE", 2000, &b, &err), T74_ECORE);
  assert_non_null(strstr(err.msg, "available (table HUGE"));
  core_free(c);
  /* a fixed core never grows */
  c = core_new(64);
  assert_non_null(c);
  struct t74_error e2 = { T74_OK, "" };
  assert_int_equal(core_alloc(c, "LOW", 65, &a, &e2), T74_ECORE);
  assert_int_equal(core_words(c), 64);
  core_free(c);
}

int main(void)
{
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74core.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_growing_core),
    cmocka_unit_test(test_small_import_fits),
    cmocka_unit_test(test_import_grows),
    cmocka_unit_test(test_import_default_engine),
    cmocka_unit_test(test_s74_exit_3),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
