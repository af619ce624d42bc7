/*
** test_install.c — Unix conventions: `tube74 --version`, the man page tube74.1 and
** `make install` (tools/install.sh; PREFIX, DESTDIR).
**
** This file contains code to check that:
**   --version     prints "tube74 VERSION", the version the man page's .TH line names;
**   the man page  names every option that `tube74 --help` and the commands' own --help
**                 (play, stream, teach) list, and every command of the usage; it formats
**                 without a warning (groff -man -ww, when groff is installed);
**   install       puts the program (mode 755) and the man page (644) under
**                 DESTDIR/PREFIX/bin and DESTDIR/PREFIX/share/man/man1, the installed
**                 program runs; a relative PREFIX is refused (exit 2) and installs nothing.
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <ctype.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */
static char root[256];

/* The man page as text: roff's "\-" read as "-", font escapes removed. */
static char *man_text(void)
{
  char p[300];
  snprintf(p, sizeof p, "%s/tube74.1", root);
  char *m = tk_slurp(p, NULL);
  assert_non_null(m);
  char *w = m;
  for (const char *r = m; *r; r++) {
    if (r[0] == '\\' && r[1] == '-') { *w++ = '-'; r++; continue; }
    if (r[0] == '\\' && r[1] == 'f' && r[2]) { r += 2; continue; }
    *w++ = *r;
  }
  *w = 0;
  return m;
}

/* The word `opt` appears in text, not as part of a longer option. */
static int has_word(const char *text, const char *opt)
{
  size_t n = strlen(opt);
  for (const char *p = strstr(text, opt); p; p = strstr(p + 1, opt)) {
    char before = p == text ? ' ' : p[-1], after = p[n];
    if ((isalnum((unsigned char)before) || before == '-') && opt[0] != '-') continue;
    if (before == '-' ) continue;
    if (isalnum((unsigned char)after) || after == '-') continue;
    return 1;
  }
  return 0;
}

static void test_version(void **state)
{
  (void)state;
  assert_int_equal(sh("%s --version > v.txt", exe), 0);
  char p[128];
  snprintf(p, sizeof p, "%s/v.txt", scratch);
  char *v = tk_slurp(p, NULL);
  assert_non_null(v);
  assert_true(!strncmp(v, "tube74 ", 7));
  char ver[32] = { 0 };
  assert_int_equal(sscanf(v + 7, "%31s", ver), 1);
  assert_true(isdigit((unsigned char)ver[0]));
  char *m = man_text();
  char want[64];
  snprintf(want, sizeof want, "\"tube74 %s\"", ver);     /* .TH ... "tube74 VERSION" */
  assert_non_null(strstr(m, want));
  free(m);
  free(v);
}

static void test_man_has_every_option(void **state)
{
  (void)state;
  assert_int_equal(sh("%s --help > h.txt && %s play --help >> h.txt && "
                      "%s stream --help >> h.txt && { %s teach --help >> h.txt 2>/dev/null || true; }",
                      exe, exe, exe, exe), 0);
  char p[128];
  snprintf(p, sizeof p, "%s/h.txt", scratch);
  char *h = tk_slurp(p, NULL);
  assert_non_null(h);
  char *m = man_text();
  int options = 0, missing = 0, commands = 0;
  for (const char *q = h; *q; q++) {
    /* an option: "-x" or "--word" starting a word */
    if (q[0] == '-' && (q == h || q[-1] == ' ' || q[-1] == '[' || q[-1] == '|' || q[-1] == '(' ||
                        q[-1] == ',' || q[-1] == '\n' || q[-1] == '`')) {
      const char *e = q + 1;
      if (*e == '-') e++;
      if (!isalpha((unsigned char)*e)) continue;
      while (isalnum((unsigned char)*e) || *e == '-') e++;
      char opt[64];
      size_t n = (size_t)(e - q);
      if (n >= sizeof opt) continue;
      memcpy(opt, q, n);
      opt[n] = 0;
      options++;
      if (!has_word(m, opt)) { fprintf(stderr, "not in tube74.1: %s\n", opt); missing++; }
      q = e - 1;
    }
  }
  /* the commands: "tube74 WORD" at the start of the usage lines */
  for (const char *q = strstr(h, "tube74 "); q; q = strstr(q + 1, "tube74 ")) {
    const char *e = q + 7;
    if (!islower((unsigned char)*e)) continue;
    char cmd[32];
    size_t n = 0;
    while (islower((unsigned char)e[n]) && n < sizeof cmd - 1) { cmd[n] = e[n]; n++; }
    cmd[n] = 0;
    char want[64];
    snprintf(want, sizeof want, ".B tube74 %s", cmd);
    commands++;
    if (!strstr(m, want)) { fprintf(stderr, "command not in the SYNOPSIS: %s\n", cmd); missing++; }
  }
  assert_true(options > 40);
  assert_true(commands >= 6);
  assert_int_equal(missing, 0);
  free(h);
  free(m);
}

static void test_man_formats_clean(void **state)
{
  (void)state;
  if (sh("command -v groff > /dev/null") != 0) { skip(); return; }
  assert_int_equal(sh("groff -man -ww -z -Tutf8 %s/tube74.1 2> g.txt && ! test -s g.txt", root), 0);
}

static void test_install(void **state)
{
  (void)state;
  assert_int_equal(sh("sh %s/tools/install.sh %s/stage /opt/t74 %s %s/tube74.1 > /dev/null",
                      root, scratch, exe, root), 0);
  char p[256];
  struct stat st;
  snprintf(p, sizeof p, "%s/stage/opt/t74/bin/tube74", scratch);
  assert_int_equal(stat(p, &st), 0);
  assert_int_equal(st.st_mode & 0777, 0755);
  snprintf(p, sizeof p, "%s/stage/opt/t74/share/man/man1/tube74.1", scratch);
  assert_int_equal(stat(p, &st), 0);
  assert_int_equal(st.st_mode & 0777, 0644);
  assert_int_equal(sh("./stage/opt/t74/bin/tube74 --version | grep -q '^tube74 '"), 0);
  assert_int_equal(sh("cmp -s %s/tube74.1 stage/opt/t74/share/man/man1/tube74.1", root), 0);
  /* a relative PREFIX: refused, nothing installed */
  assert_int_equal(sh("sh %s/tools/install.sh %s/stage2 opt %s %s/tube74.1 2> /dev/null",
                      root, scratch, exe, root), 2);
  assert_int_equal(sh("! test -e stage2"), 0);
}

int main(void)
{
  if (!getcwd(root, sizeof root)) return 1;
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74inst.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_version),
    cmocka_unit_test(test_man_has_every_option),
    cmocka_unit_test(test_man_formats_clean),
    cmocka_unit_test(test_install),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
