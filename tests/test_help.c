/*
** test_help.c — every command's --help against the man page (issue 20, "Everyday use").
**
** This file contains code to read tube74.1 the way a user reads it and check each
** command's own --help against it:
**   - the commands are the SYNOPSIS entries (".B tube74 render", ".B tube74 bench arith",
**     ...), each with the options its synopsis block lists;
**   - an "X OPTIONS" section adds its tagged options (the line after each .TP) to the
**     commands its opening paragraph names in bold ("These apply to render, tek, ..."), or,
**     when it names none, to the command X itself (PLAY OPTIONS: play);
**   - `tube74 CMD --help` must print a usage starting "usage: tube74 CMD" on stdout, nothing
**     on stderr, exit 0, and name every one of those options (as a word, not inside a
**     longer option); `-h` anywhere among the arguments does the same.
** test_install.c checks the other way round (every option of the --help texts is in the
** man page). A standalone cmocka program run from the repository root; $TUBE74.
*/
#include <ctype.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "tests/ref/testkit.h"

static char scratch[64];

#define MAX_CMDS 16
#define MAX_OPTS 64

struct mcmd {
  char name[32];                     /* "render", "bench arith" */
  int nopt;
  char opt[MAX_OPTS][32];            /* "--cell", "-o" */
};

struct manpage {
  int ncmd;
  struct mcmd cmd[MAX_CMDS];
};

/* One roff line as text: "\-" read as "-", "\(dq" as '"', font escapes removed. */
static void plain(const char *in, char *out, size_t cap)
{
  size_t w = 0;
  for (const char *r = in; *r && w + 1 < cap; r++) {
    if (r[0] == '\\' && r[1] == '-') { out[w++] = '-'; r++; continue; }
    if (r[0] == '\\' && r[1] == '(' && r[2] && r[3]) { out[w++] = '"'; r += 3; continue; }
    if (r[0] == '\\' && r[1] == 'f' && r[2]) { r += 2; continue; }
    out[w++] = *r;
  }
  out[w] = 0;
}

static struct mcmd *find_cmd(struct manpage *m, const char *name)
{
  for (int k = 0; k < m->ncmd; k++)
    if (!strcmp(m->cmd[k].name, name)) return &m->cmd[k];
  return NULL;
}

static void add_opt(struct mcmd *c, const char *opt)
{
  for (int k = 0; k < c->nopt; k++)
    if (!strcmp(c->opt[k], opt)) return;
  assert_true(c->nopt < MAX_OPTS);
  snprintf(c->opt[c->nopt++], sizeof c->opt[0], "%s", opt);
}

/* Each option word in text ("-o", "--look-at") to c. */
static void add_opts_of(struct mcmd *c, const char *text)
{
  for (const char *q = text; *q; q++) {
    if (q[0] != '-' || (q > text && (isalnum((unsigned char)q[-1]) || q[-1] == '-'))) continue;
    const char *e = q + 1;
    if (*e == '-') e++;
    if (!isalpha((unsigned char)*e)) continue;
    while (isalnum((unsigned char)*e) || *e == '-') e++;
    char opt[32];
    size_t n = (size_t)(e - q);
    if (n >= sizeof opt) continue;
    memcpy(opt, q, n);
    opt[n] = 0;
    if (!strcmp(opt, "--help") || !strcmp(opt, "-h")) { q = e - 1; continue; }
    add_opt(c, opt);
    q = e - 1;
  }
}

/* The commands and their options, read from tube74.1. */
static void read_man(struct manpage *m)
{
  memset(m, 0, sizeof *m);
  char *src = tk_slurp("tube74.1", NULL);
  assert_non_null(src);
  char section[64] = "";
  struct mcmd *syn = NULL;                /* the SYNOPSIS block being read */
  struct mcmd *applies[MAX_CMDS];         /* an OPTIONS section's commands */
  int napplies = 0, in_intro = 0, tag_next = 0;
  char own[32] = "";                      /* the command an OPTIONS section is named after */
  char *save = NULL;
  for (char *line = strtok_r(src, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
    char t[512];
    plain(line, t, sizeof t);
    if (!strncmp(t, ".SH ", 4)) {
      snprintf(section, sizeof section, "%.60s", t + 4);
      syn = NULL;
      napplies = 0;
      in_intro = strstr(section, " OPTIONS") != NULL && strncmp(section, "GENERAL", 7) != 0;
      tag_next = 0;
      own[0] = 0;
      for (size_t k = 0; section[k] && section[k] != ' ' && k + 1 < sizeof own; k++) {
        own[k] = (char)tolower((unsigned char)section[k]);
        own[k + 1] = 0;
      }
      continue;
    }
    if (!strcmp(section, "SYNOPSIS")) {
      if (!strcmp(t, ".br")) { syn = NULL; continue; }
      if (!strncmp(t, ".B tube74 ", 10) && islower((unsigned char)t[10])) {
        assert_true(m->ncmd < MAX_CMDS);
        syn = &m->cmd[m->ncmd++];
        size_t n = 0;
        for (const char *p = t + 10; *p && n + 1 < sizeof syn->name; p++) {
          if (!islower((unsigned char)*p) && *p != ' ') break;
          syn->name[n++] = *p;
        }
        while (n > 0 && syn->name[n - 1] == ' ') n--;
        syn->name[n] = 0;
        continue;
      }
      if (syn) add_opts_of(syn, t);
      continue;
    }
    if (strstr(section, " OPTIONS") == NULL || !strncmp(section, "GENERAL", 7)) continue;
    if (!strncmp(t, ".TP", 3)) {
      if (in_intro) {                      /* the opening paragraph is over */
        in_intro = 0;
        if (napplies == 0) {
          struct mcmd *c = find_cmd(m, own);
          assert_non_null(c);              /* "PLAY OPTIONS" names a command of the synopsis */
          applies[napplies++] = c;
        }
      }
      tag_next = 1;
      continue;
    }
    if (in_intro) {
      /* ".B render", ".BR tek ," ...: a command the section applies to */
      if (!strncmp(t, ".B ", 3) || !strncmp(t, ".BR ", 4)) {
        char word[32];
        if (sscanf(t + (t[2] == ' ' ? 3 : 4), "%31[a-z]", word) == 1) {
          struct mcmd *c = find_cmd(m, word);
          if (c && napplies < MAX_CMDS) applies[napplies++] = c;
        }
      }
      continue;
    }
    if (tag_next) {
      for (int k = 0; k < napplies; k++) add_opts_of(applies[k], t);
      tag_next = 0;
    }
  }
  free(src);
}

/* The word `opt` appears in text, not as part of a longer option. */
static int has_word(const char *text, const char *opt)
{
  size_t n = strlen(opt);
  for (const char *p = strstr(text, opt); p; p = strstr(p + 1, opt)) {
    char before = p == text ? ' ' : p[-1], after = p[n];
    if (isalnum((unsigned char)before) || before == '-') continue;
    if (isalnum((unsigned char)after) || after == '-') continue;
    return 1;
  }
  return 0;
}

/* The man page's reading itself: the commands and options it must find. */
static void test_man_read(void **state)
{
  (void)state;
  struct manpage m;
  read_man(&m);
  static const char *const want[] = {
    "render", "tek", "stream", "devices", "play", "teach", "params",
    "bench arith", "bench accuracy", "bench speed" };
  for (size_t k = 0; k < sizeof want / sizeof *want; k++) {
    if (!find_cmd(&m, want[k])) fprintf(stderr, "not in the SYNOPSIS: %s\n", want[k]);
    assert_non_null(find_cmd(&m, want[k]));
  }
  struct mcmd *r = find_cmd(&m, "render"), *p = find_cmd(&m, "play"),
              *s = find_cmd(&m, "stream"), *b = find_cmd(&m, "bench speed");
  assert_true(r->nopt >= 18);
  int cell = 0, look = 0;
  for (int k = 0; k < r->nopt; k++) {
    cell |= !strcmp(r->opt[k], "--cell");
    look |= !strcmp(r->opt[k], "--look-at");
  }
  assert_true(cell && look);
  assert_true(p->nopt > r->nopt);         /* play: render's, the look's and its own */
  assert_true(s->nopt >= r->nopt - 5);
  assert_true(b->nopt >= 6);
  int set = 0;                             /* every tag of STREAM OPTIONS is read */
  for (int k = 0; k < s->nopt; k++) set |= !strcmp(s->opt[k], "--set");
  assert_true(set);
}

/* `tube74 CMD --help` (and `-h` after other arguments): usage on stdout, exit 0, naming
   every option the man page gives CMD. */
static void test_every_command_help(void **state)
{
  (void)state;
  struct manpage m;
  read_man(&m);
  int checked = 0, missing = 0;
  for (int c = 0; c < m.ncmd; c++) {
    for (int form = 0; form < 2; form++) {
      char out[128], err[128], cmd[64];
      snprintf(out, sizeof out, "%s/out.txt", scratch);
      snprintf(err, sizeof err, "%s/err.txt", scratch);
      snprintf(cmd, sizeof cmd, "%s", m.cmd[c].name);
      char *sub = strchr(cmd, ' ');
      if (sub) *sub++ = 0;
      int rc;
      if (form == 0)
        rc = sub ? tk_runl(out, err, cmd, sub, "--help", (char *)NULL)
                 : tk_runl(out, err, cmd, "--help", (char *)NULL);
      else                                 /* -h after a scene and an option */
        rc = sub ? tk_runl(out, err, cmd, sub, "--out", "x", "-h", (char *)NULL)
                 : tk_runl(out, err, cmd, "scenes/fig6.s74", "-h", (char *)NULL);
      if (rc != 0) fprintf(stderr, "tube74 %s %s: exit %d\n", m.cmd[c].name, form ? "-h" : "--help", rc);
      assert_int_equal(rc, 0);
      char *o = tk_slurp(out, NULL), *e = tk_slurp(err, NULL);
      assert_non_null(o);
      assert_non_null(e);
      assert_string_equal(e, "");
      char head[64];
      snprintf(head, sizeof head, "usage: tube74 %s", m.cmd[c].name);
      if (!strstr(o, head)) fprintf(stderr, "tube74 %s --help: no \"%s\"\n", m.cmd[c].name, head);
      assert_non_null(strstr(o, head));
      for (int k = 0; k < m.cmd[c].nopt; k++) {
        checked++;
        if (!has_word(o, m.cmd[c].opt[k])) {
          if (form == 0)
            fprintf(stderr, "tube74 %s --help does not name %s\n", m.cmd[c].name, m.cmd[c].opt[k]);
          missing++;
        }
      }
      free(o);
      free(e);
    }
  }
  assert_true(checked > 100);
  assert_int_equal(missing, 0);
}

/* An unknown command still fails with the usage on stderr (exit 2), and the top-level
   --help names the per-command --help. */
static void test_top_help(void **state)
{
  (void)state;
  char out[128], err[128];
  snprintf(out, sizeof out, "%s/out.txt", scratch);
  snprintf(err, sizeof err, "%s/err.txt", scratch);
  assert_int_equal(tk_runl(out, err, "--help", (char *)NULL), 0);
  char *o = tk_slurp(out, NULL);
  assert_non_null(o);
  assert_non_null(strstr(o, "tube74 COMMAND --help"));
  free(o);
  assert_int_equal(tk_runl(out, err, "frobnicate", "--help", (char *)NULL), 2);
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_non_null(strstr(e, "unknown command `frobnicate`"));
  free(e);
  o = tk_slurp(out, NULL);
  assert_non_null(o);
  assert_string_equal(o, "");
  free(o);
  /* params takes nothing else */
  assert_int_equal(tk_runl(out, err, "params", "extra", (char *)NULL), 2);
}

int main(void)
{
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74help.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_man_read),
    cmocka_unit_test(test_every_command_help),
    cmocka_unit_test(test_top_help),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
