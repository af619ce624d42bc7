/*
** test_badinput.c — bad input gets a clear FILE:LINE message and exit 2, in bounded work
** (CONTRACT.md "Exit status"; README "Known limits").
**
** This file contains code to check, through the library and through $TUBE74 (default
** ./tube74, fork/exec), that:
**   the .s74 reader takes a UTF-8 byte-order mark and lone-CR (classic Mac) line ends,
**     with the line numbers an editor shows, and refuses UTF-16 by name at line 1;
**   every tube=fade:S is range-checked as --look fade:S is (EFFECTS_FADE_MIN .. MAX):
**     tiny values (which once overflowed a float-to-int conversion and crashed, or ran for
**     minutes) are refused with FILE:LINE, in the scene and in --effects;
**   `pattern=foo` names the effects line of the scene;
**   a `background` that is a folder, /dev/zero or a file over PIC_FILE_MAX is refused
**     with the scene's FILE:LINE and exit 2, without reading it whole (a sparse file of
**     the limit plus one byte is refused by its size alone);
**   the fastest fade seen long after, at any spread, renders (once it never finished).
** A standalone cmocka program, run from the repository root. Scratch files go to a fresh
** folder under /tmp, removed at the end.
*/
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "emu/status.h"
#include "patterns/picture.h"
#include "render/effects.h"
#include "render/scene.h"
#include "tests/ref/testkit.h"

static char scratch[64];

static int group_setup(void **state)
{
  (void)state;
  return tk_mkscratch(scratch, sizeof scratch, "/tmp/t74bad.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(scratch);
}

static const char *in_dir(const char *name)
{
  static char buf[4][512];
  static int k;
  char *b = buf[k++ & 3];
  snprintf(b, sizeof buf[0], "%s/%s", scratch, name);
  return b;
}

static void put(const char *path, const char *text, size_t n)
{
  assert_int_equal(tk_put(path, text, n), 0);
}

/* Run $TUBE74 with args (NULL-terminated), stdout to /dev/null, stderr into msg (cap
** bytes, NUL-terminated). The exit status, or -1. */
static int run(char *msg, size_t cap, ...)
{
  const char *errf = in_dir("stderr.txt");
  va_list ap;
  va_start(ap, cap);
  int rc = tk_vrunl(NULL, errf, ap);
  va_end(ap);
  FILE *f = fopen(errf, "rb");
  assert_non_null(f);
  size_t got = fread(msg, 1, cap - 1, f);
  msg[got] = 0;
  fclose(f);
  return rc;
}

/* A small valid scene (lines 1-8), with line separator sep, then extra. */
static void scene_text(char *out, size_t cap, const char *sep, const char *extra)
{
  const char *lines[] = { "view 0 0 -1000", "window -100 -100 200 200", "vertex 1 0 0 10",
                          "vertex 2 100 0 10", "vertex 3 100 100 10", "vertex 4 0 100 10",
                          "face 1 1 2 3 4 grey 200", "# line 8" };
  out[0] = 0;
  for (size_t k = 0; k < sizeof lines / sizeof *lines; k++) {
    strncat(out, lines[k], cap - strlen(out) - 1);
    strncat(out, sep, cap - strlen(out) - 1);
  }
  strncat(out, extra, cap - strlen(out) - 1);
}

static int load(const char *path, struct scene **s, struct t74_error *err)
{
  memset(err, 0, sizeof *err);
  *s = NULL;
  return scene_load(path, NULL, s, err);
}

/* ---- text conventions --------------------------------------------------------------- */

static void test_bom_and_cr_line_ends(void **state)
{
  (void)state;
  char text[1024], bom[1100];
  struct scene *s;
  struct t74_error err;
  /* a UTF-8 byte-order mark: read as if absent */
  scene_text(text, sizeof text, "\n", "");
  snprintf(bom, sizeof bom, "\xEF\xBB\xBF%s", text);
  put(in_dir("bom.s74"), bom, strlen(bom));
  if (load(in_dir("bom.s74"), &s, &err) != T74_OK) fail_msg("BOM: %s", err.msg);
  assert_int_equal(s->nf, 1);
  scene_free(s);
  /* lone CR line ends, and CR LF: the same scene */
  const char *seps[] = { "\r", "\r\n" };
  for (int k = 0; k < 2; k++) {
    scene_text(text, sizeof text, seps[k], "");
    put(in_dir("cr.s74"), text, strlen(text));
    if (load(in_dir("cr.s74"), &s, &err) != T74_OK) fail_msg("sep %d: %s", k, err.msg);
    assert_int_equal(s->nv, 4);
    assert_int_equal(s->nf, 1);
    assert_int_equal(s->f[0].line, 7);                  /* the editor's line number */
    scene_free(s);
    /* an error on line 9 of such a file is reported at line 9 */
    scene_text(text, sizeof text, seps[k], "vertx 9 1 2 3\r");
    put(in_dir("cr.s74"), text, strlen(text));
    assert_int_equal(load(in_dir("cr.s74"), &s, &err), T74_EINPUT);
    char want[600];
    snprintf(want, sizeof want, "%s:9: unknown statement", in_dir("cr.s74"));
    if (strncmp(err.msg, want, strlen(want)) != 0) fail_msg("sep %d: %s", k, err.msg);
  }
  /* BOM and CR together */
  scene_text(text, sizeof text, "\r", "");
  snprintf(bom, sizeof bom, "\xEF\xBB\xBF%s", text);
  put(in_dir("both.s74"), bom, strlen(bom));
  assert_int_equal(load(in_dir("both.s74"), &s, &err), T74_OK);
  scene_free(s);
  /* UTF-16: refused by name at line 1 */
  put(in_dir("u16.s74"), "\xFF\xFEv\0i\0", 6);
  assert_int_equal(load(in_dir("u16.s74"), &s, &err), T74_EINPUT);
  char want[600];
  snprintf(want, sizeof want, "%s:1: the file is UTF-16", in_dir("u16.s74"));
  if (strncmp(err.msg, want, strlen(want)) != 0) fail_msg("%s", err.msg);
}

/* ---- effect values ranged as their options ----------------------------------------- */

static void test_fade_range_as_the_option(void **state)
{
  (void)state;
  static const char *const bad[] = { "tube=fade:1e-9", "tube=fade:0.0009", "tube=fade:1e-300",
                                     "tube=fade:0", "tube=fade:1000001", "tube=fade:-1" };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    struct effects e;
    struct t74_error err = { 0 };
    if (effects_parse(bad[k], &e, "s.s74", 9, &err) != T74_EINPUT ||
        strncmp(err.msg, "s.s74:9: effects: bad value", 27) != 0)
      fail_msg("`%s`: %s", bad[k], err.msg);
    /* the option refuses the same value */
    char look[64], msg[600];
    snprintf(look, sizeof look, "fade:%s", bad[k] + 10);
    assert_int_equal(run(msg, sizeof msg, "render", "scenes/fig6.s74", "--look", look,
                         (char *)NULL), 2);
  }
  /* the ends of the range are taken by both */
  static const char *const good[] = { "tube=fade:0.001", "tube=fade:1000000" };
  for (size_t k = 0; k < 2; k++) {
    struct effects e;
    struct t74_error err = { 0 };
    assert_int_equal(effects_parse(good[k], &e, "s.s74", 9, &err), T74_OK);
  }
  assert_true(EFFECTS_FADE_MIN == 1e-3 && EFFECTS_FADE_MAX == 1e6);
  /* in a scene: FILE:LINE of its effects line, exit 2, and no output */
  char text[1024], msg[600];
  scene_text(text, sizeof text, "\n", "effects tube=fade:1e-9\n");
  put(in_dir("fade.s74"), text, strlen(text));
  assert_int_equal(run(msg, sizeof msg, "render", in_dir("fade.s74"), "-o", in_dir("f.png"),
                       (char *)NULL), 2);
  char want[600];
  snprintf(want, sizeof want, "%s:9: effects: bad value", in_dir("fade.s74"));
  if (strncmp(msg, want, strlen(want)) != 0) fail_msg("%s", msg);
  assert_int_equal(access(in_dir("f.png"), F_OK), -1);
  assert_int_equal(run(msg, sizeof msg, "render", "scenes/fig6.s74", "--effects",
                       "tube=fade:1e-9", (char *)NULL), 2);
  assert_non_null(strstr(msg, "--effects:1: effects: bad value"));
}

static void test_unknown_pattern_names_its_line(void **state)
{
  (void)state;
  char text[1024], msg[600], want[600];
  scene_text(text, sizeof text, "\n", "effects pattern=foo\n");
  put(in_dir("pat.s74"), text, strlen(text));
  assert_int_equal(run(msg, sizeof msg, "render", in_dir("pat.s74"), (char *)NULL), 2);
  snprintf(want, sizeof want, "%s:9: effects: unknown halftone pattern `foo`", in_dir("pat.s74"));
  if (strncmp(msg, want, strlen(want)) != 0) fail_msg("%s", msg);
  assert_int_equal(run(msg, sizeof msg, "render", "scenes/fig6.s74", "--effects", "pattern=foo",
                       (char *)NULL), 2);
  assert_non_null(strstr(msg, "--effects:1: effects: unknown halftone pattern `foo`"));
}

/* ---- bounded background ------------------------------------------------------------ */

static void expect_background_refused(const char *bg, const char *what)
{
  char text[1024], line[600], msg[900], want[600];
  snprintf(line, sizeof line, "background %s\n", bg);
  scene_text(text, sizeof text, "\n", line);
  put(in_dir("bg.s74"), text, strlen(text));
  int st = run(msg, sizeof msg, "render", in_dir("bg.s74"), "-o", in_dir("bg.png"), (char *)NULL);
  snprintf(want, sizeof want, "%s:9: background: ", in_dir("bg.s74"));
  if (st != 2 || strncmp(msg, want, strlen(want)) != 0 || !strstr(msg, what))
    fail_msg("background %s: exit %d, \"%s\"", bg, st, msg);
  assert_int_equal(access(in_dir("bg.png"), F_OK), -1);
}

static void test_background_bounded(void **state)
{
  (void)state;
  expect_background_refused(scratch, "is a folder");
  expect_background_refused("/dev/zero", "too large");
  /* a sparse file one byte over the limit: refused by its size, never read */
  const char *huge = in_dir("huge.pgm");
  int fd = open(huge, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  assert_true(fd >= 0);
  assert_int_equal(write(fd, "P5\n", 3), 3);
  assert_int_equal(ftruncate(fd, (off_t)PIC_FILE_MAX + 1), 0);
  close(fd);
  expect_background_refused(huge, "too large");
  unlink(huge);
  /* a picture header asking for more pixels than the limit */
  put(in_dir("big.pgm"), "P5 16384 16384 255\n", 19);
  expect_background_refused(in_dir("big.pgm"), "more than the limit");
  /* and the library alone: T74_EINPUT for a folder */
  struct pic *p = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(pic_load(scratch, &p, &err), T74_EINPUT);
  assert_null(p);
}

/* ---- bounded looks --------------------------------------------------------------------- */

/* The fastest fade, seen long after: every spot has spread over the whole face. Once each
** spot was stamped with a kernel 5 sigma wide (here millions of pixels a side: the run
** never ended; a shorter fade overflowed the int kernel radius). Now it is skipped or
** drawn on a coarse grid, and the run ends like any other. */
static void test_look_bounded(void **state)
{
  (void)state;
  char msg[600];
  const char *png = in_dir("look.png");
  assert_int_equal(run(msg, sizeof msg, "render", "scenes/fig6.s74", "--look", "fade:0.001",
                       "--look-at", "10000000", "-o", png, (char *)NULL), 0);
  assert_int_equal(access(png, F_OK), 0);
  assert_int_equal(run(msg, sizeof msg, "render", "scenes/fig6.s74", "--look", "fade:0.001",
                       "--look-param", "fade_spread_mm=10", "--look-at", "0.002", "--scale", "2",
                       "-o", png, (char *)NULL), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_bom_and_cr_line_ends),
    cmocka_unit_test(test_fade_range_as_the_option),
    cmocka_unit_test(test_unknown_pattern_names_its_line),
    cmocka_unit_test(test_background_bounded),
    cmocka_unit_test(test_look_bounded),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
