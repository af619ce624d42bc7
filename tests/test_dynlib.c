/*
** test_dynlib.c — libraries opened when a command first needs them (display/dynlib.h,
** issue 19).
**
** This file contains code to check that: the program needs libpng, zlib and the C library
** at start-up and nothing else of its own (ldd names no libusb, libudev, giflib or SDL2);
** dynlib_open fills a table from a real library (libm's cos and sqrt, called through it),
** refuses a missing library with T74_EIO, the loader's reason and the package to install,
** and names a function the library lacks; and, running $TUBE74 with LD_LIBRARY_PATH at a
** folder whose libusb-1.0.so.0 and libgif.so.7 are the loader's own failures (a file that
** is no library at all; zlib under libusb's name, a library without libusb_init), that
** `devices`, `stream --device hpgl` and `play --movie` stop with exit status 4 and a
** message naming the library, leave no output, and that `render`, which loads neither,
** still draws the same picture there.
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "display/dynlib.h"
#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
static char root[512];                     /* the repository (the working folder) */
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */

static int group_setup(void **state)
{
  (void)state;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74dynlib.XXXXXX") != 0) return -1;
  if (!getcwd(root, sizeof root)) return -1;
  return tk_exe(exe, sizeof exe);
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(scratch);
}

static int exists(const char *name)
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  struct stat sb;
  return stat(p, &sb) == 0;
}

/* The program's start-up libraries, as the loader resolves them: libpng (and its zlib)
   and the C library's own, no more. */
static void test_startup_libraries(void **state)
{
  (void)state;
  assert_int_equal(sh("ldd '%s' > ldd.txt 2>&1", exe), 0);
  char p[256];
  snprintf(p, sizeof p, "%s/ldd.txt", scratch);
  char *t = tk_slurp(p, NULL);
  assert_non_null(t);
  assert_non_null(strstr(t, "libpng"));          /* the listing is real */
  const char *absent[] = { "libusb", "libudev", "libgif", "libSDL2", "libpthread" };
  for (size_t k = 0; k < sizeof absent / sizeof *absent; k++)
    if (strstr(t, absent[k])) fail_msg("%s is loaded at start-up:\n%s", absent[k], t);
  free(t);
}

struct mathfns {
  void *lib;                     /* first, as dynlib_open wants */
  double (*cos)(double);
  double (*sqrt)(double);
};

static void test_open_fills_table(void **state)
{
  (void)state;
  static const struct dynlib_sym syms[] = { { "cos", offsetof(struct mathfns, cos) },
                                            { "sqrt", offsetof(struct mathfns, sqrt) } };
  struct mathfns f;
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(dynlib_open(&f, sizeof f, "libm.so.6", "libm", "libc6", syms, 2, "t", &err),
                   T74_OK);
  assert_non_null(f.lib);
  assert_true(f.cos(0.0) == 1.0);
  assert_true(f.sqrt(2.25) == 1.5);
  dynlib_close(&f, sizeof f);
  assert_null(f.lib);
  assert_null(f.cos);
}

static void test_open_missing_library(void **state)
{
  (void)state;
  static const struct dynlib_sym syms[] = { { "cos", offsetof(struct mathfns, cos) } };
  struct mathfns f;
  memset(&f, 0xA5, sizeof f);     /* not left as it was: all zero */
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(dynlib_open(&f, sizeof f, "libt74-not-installed.so.9", "the thing", "thing9",
                               syms, 1, "what", &err), T74_EIO);
  assert_null(f.lib);
  assert_null(f.cos);
  assert_int_equal(err.status, T74_EIO);
  assert_non_null(strstr(err.msg, "what: cannot load the thing ("));
  assert_non_null(strstr(err.msg, "libt74-not-installed.so.9"));   /* the loader's reason */
  assert_non_null(strstr(err.msg, "install the Debian package thing9"));
}

static void test_open_missing_function(void **state)
{
  (void)state;
  static const struct dynlib_sym syms[] = { { "cos", offsetof(struct mathfns, cos) },
                                            { "t74_no_such_function",
                                              offsetof(struct mathfns, sqrt) } };
  struct mathfns f;
  memset(&f, 0xA5, sizeof f);
  struct t74_error err = { T74_OK, "" };
  assert_int_equal(dynlib_open(&f, sizeof f, "libm.so.6", "libm", "libc6", syms, 2, "what", &err),
                   T74_EIO);
  assert_null(f.lib);
  assert_null(f.cos);                  /* found before the missing one, then cleared */
  assert_string_equal(err.msg, "what: libm.so.6 has no t74_no_such_function");
}

/* A folder of libraries that fail to load, ahead of the system's on the search path. */
static void make_broken_libs(int zlib_as_usb)
{
  assert_int_equal(sh("rm -rf lib && mkdir lib && printf 'not a library' > lib/libgif.so.7"),
                   0);
  if (zlib_as_usb)
    assert_int_equal(sh("cp \"$(ldd '%s' | sed -n 's/.*libz.so.1 => \\([^ ]*\\).*/\\1/p')\" "
                        "lib/libusb-1.0.so.0", exe), 0);
  else
    assert_int_equal(sh("printf 'not a library' > lib/libusb-1.0.so.0"), 0);
}

/* Run $TUBE74 ARGS with the broken libraries first; its exit status. */
static int run_broken(const char *args)
{
  return sh("LD_LIBRARY_PATH=\"$PWD/lib\" '%s' %s > out.txt 2> err.txt", exe, args);
}

static void err_says(const char *what)
{
  char p[256];
  snprintf(p, sizeof p, "%s/err.txt", scratch);
  char *t = tk_slurp(p, NULL);
  assert_non_null(t);
  if (!strstr(t, what)) fail_msg("stderr does not say \"%s\":\n%s", what, t);
  free(t);
}

static void test_devices_without_libusb(void **state)
{
  (void)state;
  make_broken_libs(0);
  assert_int_equal(run_broken("devices"), 4);
  err_says("devices: cannot load libusb-1.0 (");
  err_says("install the Debian package libusb-1.0-0");
  make_broken_libs(1);
  assert_int_equal(run_broken("devices"), 4);
  err_says("devices: libusb-1.0.so.0 has no libusb_");
}

static void test_stream_without_libusb(void **state)
{
  (void)state;
  make_broken_libs(0);
  char args[1024];
  snprintf(args, sizeof args, "stream '%s/tests/data/usb/small.s74' --device hpgl "
           "--save s.resume", root);
  assert_int_equal(run_broken(args), 4);
  err_says("hpgl: cannot load libusb-1.0 (");
  assert_false(exists("s.resume"));
}

static void test_movie_without_giflib(void **state)
{
  (void)state;
  make_broken_libs(0);
  char args[1024];
  snprintf(args, sizeof args, "play '%s/scenes/fig5.s74' --speed 50 --movie m.gif", root);
  assert_int_equal(run_broken(args), 4);
  err_says("m.gif: cannot load giflib (");
  err_says("install the Debian package libgif7");
  assert_false(exists("m.gif"));
}

/* render needs neither: the same picture with the broken libraries on the path. */
static void test_render_without_them(void **state)
{
  (void)state;
  make_broken_libs(0);
  char args[1024];
  snprintf(args, sizeof args, "render '%s/scenes/fig5.s74' -o a.png", root);
  assert_int_equal(run_broken(args), 0);
  assert_int_equal(sh("'%s' render '%s/scenes/fig5.s74' -o b.png && cmp -s a.png b.png", exe, root),
                   0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_startup_libraries),
    cmocka_unit_test(test_open_fills_table),
    cmocka_unit_test(test_open_missing_library),
    cmocka_unit_test(test_open_missing_function),
    cmocka_unit_test(test_devices_without_libusb),
    cmocka_unit_test(test_stream_without_libusb),
    cmocka_unit_test(test_movie_without_giflib),
    cmocka_unit_test(test_render_without_them),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
