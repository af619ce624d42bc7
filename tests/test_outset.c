/*
** test_outset.c — outputs that never destroy anything (display/outfile.h; CONTRACT.md:
** "every output path may be `-`; a symlink is written through to its target, a device or
** FIFO written directly, a regular file replaced atomically; when any output fails, none
** is created or changed").
**
** This file contains code to check, through the library and through $TUBE74 (default
** ./tube74, run with fork/exec as a user would), that:
**   a symlink stays a link and its target gets the picture (also a dangling one and a
**     chain of links in another folder);
**   a FIFO stays a FIFO and a reader process gets the same bytes a file would;
**   a character device node (a copy of /dev/null, made with mknod) stays a device;
**   `-`, and a link to /proc/self/fd/1, are standard output for -o, --dump, --stats, tek -o;
**   when one output fails (--stats into a missing folder) no other output is created or
**     changed, for render, tek -o and play --movie, and no temporary is left behind;
**   two outputs on one file (by name, through a link, `-` twice) and an output that is the
**     scene or its background are refused with exit 2, nothing written;
**   an existing file keeps its permission bits;
**   --stats stays valid JSON (checked by jq, a real parser) for a scene path holding
**     quotes, backslashes, a tab, a control character and bytes that are not UTF-8, and
**     outfile_json_string writes what jq reads back.
** A standalone cmocka program, run from the repository root. Scratch files go to a fresh
** folder under /tmp, removed at the end.
*/
#define _DEFAULT_SOURCE         /* mknod, makedev: a device node for the device test */
#include <dirent.h>
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
#include <sys/sysmacros.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "display/outfile.h"
#include "emu/status.h"
#include "tests/ref/testkit.h"

#define SCENE "scenes/fig6.s74"         /* small and fast; no background */
#define BG_SCENE "scenes/street.s74"    /* has `background harbour.pgm` */

/* ---- scratch folder ----------------------------------------------------------------- */

static char scratch[64];

static int group_setup(void **state)
{
  (void)state;
  return tk_mkscratch(scratch, sizeof scratch, "/tmp/t74outset.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(scratch);
}

/* Each test starts with an empty scratch folder. */
static int test_setup(void **state)
{
  (void)state;
  return tk_clear(scratch);
}

/* scratch/name in one of a few rotating buffers (several live at once in a test). */
static const char *in_dir(const char *name)
{
  static char buf[8][512];
  static int k;
  char *b = buf[k++ & 7];
  snprintf(b, sizeof buf[0], "%s/%s", scratch, name);
  return b;
}

/* Entries of the scratch folder, hidden ones (temporaries) included. */
static int entries(void)
{
  DIR *d = opendir(scratch);
  assert_non_null(d);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) n++;
  closedir(d);
  return n;
}

static void put(const char *path, const char *text)
{
  assert_int_equal(tk_put(path, text, strlen(text)), 0);
}

/* The whole file (NUL added), malloc'd; *n its length. */
static char *slurp(const char *path, size_t *n)
{
  char *b = tk_slurp(path, n);
  if (!b) fail_msg("cannot read %s: %s", path, strerror(errno));
  return b;
}

static int same_bytes(const char *a, const char *b)
{
  size_t na, nb;
  char *x = slurp(a, &na), *y = slurp(b, &nb);
  int same = na == nb && memcmp(x, y, na) == 0;
  free(x);
  free(y);
  return same;
}

static int is_png(const char *path)
{
  size_t n;
  char *b = slurp(path, &n);
  int ok = n > 8 && memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0;
  free(b);
  return ok;
}

static mode_t lmode(const char *path)
{
  struct stat st;
  if (lstat(path, &st) != 0) return 0;
  return st.st_mode;
}

/* ---- running the program ------------------------------------------------------------ */

/* run(OUT, ERR, ARG..., NULL): $TUBE74 ARG... with stdout to OUT and stderr to ERR (each
** NULL for /dev/null); the exit status, or -1. */
#define run tk_runl

/* A reference picture of SCENE, written to a plain new file. */
static const char *reference_png(void)
{
  static char ref[512];
  snprintf(ref, sizeof ref, "/tmp/t74outset-ref-%d.png", (int)getpid());
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", ref, (char *)NULL), 0);
  return ref;
}

/* ---- symlinks --------------------------------------------------------------------- */

static void test_symlink_written_through(void **state)
{
  (void)state;
  const char *ref = reference_png();
  /* a link beside its target */
  put(in_dir("real.png"), "old");
  assert_int_equal(symlink("real.png", in_dir("link.png")), 0);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", in_dir("link.png"), (char *)NULL), 0);
  assert_true(S_ISLNK(lmode(in_dir("link.png"))));      /* still a link */
  assert_true(S_ISREG(lmode(in_dir("real.png"))));
  assert_true(same_bytes(in_dir("real.png"), ref));     /* the target got the picture */
  /* a chain: link -> sub/link2 -> ../sub/target (relative to each link's folder) */
  assert_int_equal(mkdir(in_dir("sub"), 0777), 0);
  assert_int_equal(symlink("../sub/target.png", in_dir("sub/link2.png")), 0);
  assert_int_equal(symlink("sub/link2.png", in_dir("chain.png")), 0);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", in_dir("chain.png"), (char *)NULL), 0);
  assert_true(S_ISLNK(lmode(in_dir("chain.png"))));
  assert_true(S_ISLNK(lmode(in_dir("sub/link2.png"))));
  assert_true(same_bytes(in_dir("sub/target.png"), ref));
  /* a dangling link: its target is created, as `>` would */
  assert_int_equal(symlink("made.txt", in_dir("dangling")), 0);
  char spec[600];
  snprintf(spec, sizeof spec, "points=%s", in_dir("dangling"));
  assert_int_equal(run(NULL, NULL, "render", SCENE, "--dump", spec, (char *)NULL), 0);
  assert_true(S_ISLNK(lmode(in_dir("dangling"))));
  assert_true(S_ISREG(lmode(in_dir("made.txt"))));
  unlink(ref);
}

/* ---- FIFOs and devices --------------------------------------------------------------- */

static void test_fifo_read_by_a_reader(void **state)
{
  (void)state;
  const char *ref = reference_png();
  const char *fifo = in_dir("pipe");
  assert_int_equal(mkfifo(fifo, 0644), 0);
  /* this process is the reader: it opens the FIFO first (so tube74's open does not wait),
     and the picture (a few kB) fits the pipe's buffer until tube74 has exited; a writer
     that replaced the FIFO instead leaves the reader with nothing, and the test cannot
     hang */
  size_t rn;
  char *want = slurp(ref, &rn);
  assert_true(rn < 65536);
  int rd = open(fifo, O_RDONLY | O_NONBLOCK);
  assert_true(rd >= 0);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", fifo, (char *)NULL), 0);
  char *got = malloc(65536);
  assert_non_null(got);
  size_t n = 0;
  ssize_t k;
  while (n < 65536 && (k = read(rd, got + n, 65536 - n)) > 0) n += (size_t)k;
  close(rd);
  assert_true(S_ISFIFO(lmode(fifo)));                   /* not replaced by a file */
  assert_int_equal(n, rn);                              /* the reader got the picture */
  assert_memory_equal(got, want, rn);
  /* all or nothing holds for a FIFO too: when another output fails, its reader gets
     nothing at all */
  rd = open(fifo, O_RDONLY | O_NONBLOCK);
  assert_true(rd >= 0);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", fifo, "--stats", in_dir("no/s.json"),
                       (char *)NULL), 4);
  assert_true(read(rd, got, 65536) <= 0);
  close(rd);
  free(got);
  free(want);
  unlink(ref);
}

static void test_char_device_stays(void **state)
{
  (void)state;
  /* a node of our own, the same device as /dev/null (1, 3): as root the old writer would
     have renamed a file over it */
  const char *dev = in_dir("null");
  const char *nodes[1] = { dev };
  int n = 1, own = 1;
  /* not root: /dev/null itself (which a failing writer could not replace then) */
  if (mknod(dev, S_IFCHR | 0666, makedev(1, 3)) != 0) { nodes[0] = "/dev/null"; own = 0; }
  for (int k = 0; k < n; k++) {
    char spec[600];
    snprintf(spec, sizeof spec, "points=%s", nodes[k]);
    assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", nodes[k], "--dump", spec,
                         "--stats", nodes[k], (char *)NULL), 0);   /* a device may take several */
    assert_true(S_ISCHR(lmode(nodes[k])));
  }
  assert_int_equal(entries(), own);                     /* no temporary left */
  /* a device that fails at the commit (/dev/full: ENOSPC) leaves the regular outputs
     unwritten: direct outputs get their bytes before any rename */
  if (access("/dev/full", W_OK) == 0) {
    assert_int_equal(run(NULL, NULL, "render", SCENE, "--stats", in_dir("s.json"), "-o",
                         "/dev/full", (char *)NULL), 4);
    assert_int_equal(access(in_dir("s.json"), F_OK), -1);
    assert_true(S_ISCHR(lmode("/dev/full")));
  }
  /* a block device is refused, and stays what it was */
  const char *blk = in_dir("blk");
  if (own && mknod(blk, S_IFBLK | 0600, makedev(7, 0)) == 0) {
    assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", blk, (char *)NULL), 4);
    assert_true(S_ISBLK(lmode(blk)));
    unlink(blk);
  }
}

/* ---- standard output ------------------------------------------------------------------ */

static void test_dash_is_stdout(void **state)
{
  (void)state;
  const char *ref = reference_png();
  const char *out = in_dir("stdout.bin");
  assert_int_equal(run(out, NULL, "render", SCENE, "-o", "-", (char *)NULL), 0);
  assert_true(same_bytes(out, ref));
  assert_int_equal(access("-", F_OK), -1);              /* no file named "-" was made */
  /* --dump points=- and a file give the same bytes */
  char spec[600];
  snprintf(spec, sizeof spec, "points=%s", in_dir("points.txt"));
  assert_int_equal(run(NULL, NULL, "render", SCENE, "--dump", spec, (char *)NULL), 0);
  assert_int_equal(run(out, NULL, "render", SCENE, "--dump", "points=-", (char *)NULL), 0);
  assert_true(same_bytes(out, in_dir("points.txt")));
  /* a link to /proc/self/fd/1 (what /dev/stdout is) writes the descriptor itself */
  assert_int_equal(symlink("/proc/self/fd/1", in_dir("my-stdout")), 0);
  snprintf(spec, sizeof spec, "points=%s", in_dir("my-stdout"));
  assert_int_equal(run(out, NULL, "render", SCENE, "--dump", spec, (char *)NULL), 0);
  assert_true(S_ISLNK(lmode(in_dir("my-stdout"))));
  assert_true(same_bytes(out, in_dir("points.txt")));
  /* --stats - */
  assert_int_equal(run(out, NULL, "render", SCENE, "--stats", "-", (char *)NULL), 0);
  char cmd[700];
  snprintf(cmd, sizeof cmd, "jq -e '.faces_in > 0' '%s' >/dev/null", out);
  assert_int_equal(system(cmd), 0);
  /* tek -o - */
  assert_int_equal(run(out, NULL, "tek", SCENE, "-o", "-", (char *)NULL), 0);
  size_t n;
  char *b = slurp(out, &n);
  assert_true(n > 6 && b[0] == 0x1b && b[1] == 0x0c);  /* ESC FF: a Tek stream */
  free(b);
  unlink(ref);
}

/* ---- all or nothing ------------------------------------------------------------------- */

static void test_failing_stats_leaves_others(void **state)
{
  (void)state;
  /* copies: more than in_dir's 8 buffers are taken below (which one a call's arguments
     take depends on the compiler's order of evaluating them) */
  char png[512], bad[512];
  snprintf(png, sizeof png, "%s", in_dir("out.png"));
  snprintf(bad, sizeof bad, "%s", in_dir("missing/s.json"));
  char spec[600];
  snprintf(spec, sizeof spec, "points=%s", in_dir("new.txt"));
  put(png, "old picture");
  /* render: -o exists, --dump is new, --stats cannot be created */
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", png, "--dump", spec, "--stats", bad,
                       (char *)NULL), 4);
  size_t n;
  char *b = slurp(png, &n);
  assert_string_equal(b, "old picture");
  free(b);
  assert_int_equal(access(in_dir("new.txt"), F_OK), -1);
  assert_int_equal(entries(), 1);                       /* out.png only: no temporary */
  /* the same through the look layer (-o drawn by the look at --scale 2) */
  assert_int_equal(run(NULL, NULL, "render", SCENE, "--scale", "2", "-o", png, "--stats", bad,
                       (char *)NULL), 4);
  b = slurp(png, &n);
  assert_string_equal(b, "old picture");
  free(b);
  /* tek -o FILE with a failing --stats: no stream file */
  assert_int_equal(run(NULL, NULL, "tek", SCENE, "-o", in_dir("t.tek"), "--stats", bad,
                       (char *)NULL), 4);
  assert_int_equal(access(in_dir("t.tek"), F_OK), -1);
  /* play --movie: no frame */
  assert_int_equal(run(NULL, NULL, "play", SCENE, "--movie", in_dir("m"), "--max-frames", "3",
                       "--stats", bad, (char *)NULL), 4);
  assert_int_equal(access(in_dir("m-0001.png"), F_OK), -1);
  /* and a failing movie folder: no -o */
  assert_int_equal(run(NULL, NULL, "play", SCENE, "--movie", in_dir("missing/m"),
                       "--max-frames", "3", "-o", in_dir("p.png"), (char *)NULL), 4);
  assert_int_equal(access(in_dir("p.png"), F_OK), -1);
  assert_int_equal(entries(), 1);
  /* the good runs write everything */
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", png, "--dump", spec, "--stats",
                       in_dir("s.json"), (char *)NULL), 0);
  assert_true(is_png(png));
  assert_int_equal(access(in_dir("new.txt"), F_OK), 0);
  assert_int_equal(run(NULL, NULL, "play", SCENE, "--movie", in_dir("m"), "--max-frames", "3",
                       "--stats", in_dir("p.json"), (char *)NULL), 0);
  assert_true(is_png(in_dir("m-0001.png")));
  assert_true(is_png(in_dir("m-0003.png")));
}

static void test_same_file_twice_refused(void **state)
{
  (void)state;
  const char *a = in_dir("a.png");
  char spec[600];
  snprintf(spec, sizeof spec, "tube=%s", a);
  /* a new name twice */
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", a, "--dump", spec, (char *)NULL), 2);
  assert_int_equal(entries(), 0);
  /* an existing file, once by name and once through a link */
  put(a, "keep");
  assert_int_equal(symlink("a.png", in_dir("alias.png")), 0);
  snprintf(spec, sizeof spec, "tube=%s", in_dir("alias.png"));
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", a, "--dump", spec, (char *)NULL), 2);
  size_t n;
  char *b = slurp(a, &n);
  assert_string_equal(b, "keep");
  free(b);
  /* the same new name spelled two ways */
  char other[600];
  snprintf(other, sizeof other, "%s/./b.json", scratch);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", in_dir("b.json"), "--stats", other,
                       (char *)NULL), 2);
  /* standard output twice: `-` and `-`, `-` and /proc/self/fd/1, tek's stdout and `-` */
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", "-", "--stats", "-", (char *)NULL), 2);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", "-", "--dump", "points=/proc/self/fd/1",
                       (char *)NULL), 2);
  assert_int_equal(run(NULL, NULL, "tek", SCENE, "--dump", "points=-", (char *)NULL), 2);
  assert_int_equal(entries(), 2);                       /* a.png, alias.png */
}

static void test_output_is_an_input_refused(void **state)
{
  (void)state;
  /* a copy of the street and its background in the scratch folder */
  char cmd[700];
  snprintf(cmd, sizeof cmd, "cp scenes/street.s74 scenes/harbour.pgm '%s'/", scratch);
  assert_int_equal(system(cmd), 0);
  const char *scene = in_dir("street.s74"), *bg = in_dir("harbour.pgm");
  size_t n0, n1;
  char *before = slurp(scene, &n0), *bgbefore = slurp(bg, &n1);
  assert_int_equal(run(NULL, NULL, "render", scene, "-o", scene, (char *)NULL), 2);
  char spec[600];
  snprintf(spec, sizeof spec, "grey=%s", bg);
  assert_int_equal(run(NULL, NULL, "render", scene, "--dump", spec, (char *)NULL), 2);
  assert_int_equal(symlink("street.s74", in_dir("sl")), 0);
  assert_int_equal(run(NULL, NULL, "render", scene, "--stats", in_dir("sl"), (char *)NULL), 2);
  assert_int_equal(run(NULL, NULL, "tek", scene, "-o", scene, (char *)NULL), 2);
  size_t m0, m1;
  char *after = slurp(scene, &m0), *bgafter = slurp(bg, &m1);
  assert_true(m0 == n0 && memcmp(before, after, n0) == 0);
  assert_true(m1 == n1 && memcmp(bgbefore, bgafter, n1) == 0);
  free(before); free(after); free(bgbefore); free(bgafter);
  assert_int_equal(entries(), 3);
  (void)BG_SCENE;
}

static void test_mode_kept(void **state)
{
  (void)state;
  const char *p = in_dir("private.png");
  put(p, "x");
  assert_int_equal(chmod(p, 0600), 0);
  assert_int_equal(run(NULL, NULL, "render", SCENE, "-o", p, (char *)NULL), 0);
  assert_int_equal(lmode(p) & 07777, 0600);
  assert_true(is_png(p));
}

/* ---- JSON ------------------------------------------------------------------------------ */

/* jq's reading of .KEY in file as raw bytes into out (NUL-terminated); jq's exit status. */
static int jq_raw(const char *file, const char *key, char *out, size_t cap)
{
  char cmd[900];
  snprintf(cmd, sizeof cmd, "jq -j '.%s' '%s' 2>/dev/null", key, file);
  FILE *p = popen(cmd, "r");
  assert_non_null(p);
  size_t n = fread(out, 1, cap - 1, p);
  out[n] = 0;
  return pclose(p);
}

static void test_stats_json_any_path(void **state)
{
  (void)state;
  /* a scene whose name holds a quote, a backslash, a tab, ESC, and bytes that are not UTF-8
     (0xff alone; a truncated 3-byte sequence), beside valid UTF-8 (e acute) */
  const char *name = "we\"ird\\\t\x1b\xff\xe2\x82 \xc3\xa9.s74";
  char cmd[900];
  snprintf(cmd, sizeof cmd, "cp " SCENE " '%s/%s'", scratch, name);
  assert_int_equal(system(cmd), 0);
  const char *json = in_dir("s.json");
  assert_int_equal(run(NULL, NULL, "render", in_dir(name), "--stats", json, (char *)NULL), 0);
  snprintf(cmd, sizeof cmd, "jq -e . '%s' >/dev/null", json);
  assert_int_equal(system(cmd), 0);                     /* a real parser accepts it */
  char got[1024], want[1024];
  assert_int_equal(jq_raw(json, "scene", got, sizeof got), 0);
  snprintf(want, sizeof want, "%s/we\"ird\\\t\x1b\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd \xc3\xa9.s74",
           scratch);                                    /* each bad byte: U+FFFD */
  assert_string_equal(got, want);
  /* the Tek input's --stats too */
  snprintf(cmd, sizeof cmd, "%s tek " SCENE " -o '%s/x\"\\y.tek'", tk_prog(), scratch);
  assert_int_equal(system(cmd), 0);
  char tek[600];
  snprintf(tek, sizeof tek, "%s/x\"\\y.tek", scratch);
  assert_int_equal(run(NULL, NULL, "render", tek, "--stats", json, (char *)NULL), 0);
  assert_int_equal(jq_raw(json, "scene", got, sizeof got), 0);
  assert_string_equal(got, tek);
}

static void test_json_string_writer(void **state)
{
  (void)state;
  static const char *const in[] = {
    "plain", "", "q\"uote", "back\\slash", "tab\there", "nl\ncr\r", "\x01\x1f\x7f",
    "\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80",          /* valid 2-, 3- and 4-byte UTF-8 */
    "\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\x80", "\xe2\x82",   /* invalid */
  };
  static const char *const want[] = {
    "plain", "", "q\"uote", "back\\slash", "tab\there", "nl\ncr\r", "\x01\x1f\x7f",
    "\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80",
    "\xef\xbf\xbd\xef\xbf\xbd", "\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd",
    "\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd", "\xef\xbf\xbd", "\xef\xbf\xbd\xef\xbf\xbd",
  };
  size_t n = sizeof in / sizeof *in;
  const char *path = in_dir("w.json");
  struct outfile *o;
  struct t74_error err = { 0 };
  assert_int_equal(outfile_open(&o, path, &err), T74_OK);
  outfile_printf(o, "[");
  for (size_t k = 0; k < n; k++) {
    if (k) outfile_printf(o, ", ");
    assert_int_equal(outfile_json_string(o, in[k]), T74_OK);
  }
  /* a long string: the writer's buffer fills and flushes many times */
  char longs[3000];
  for (size_t k = 0; k < sizeof longs - 1; k++) longs[k] = "a\"\\\t\xff"[k % 5];
  longs[sizeof longs - 1] = 0;
  outfile_printf(o, ", ");
  assert_int_equal(outfile_json_string(o, longs), T74_OK);
  outfile_printf(o, "]\n");
  assert_int_equal(outfile_commit(o, &err), T74_OK);
  for (size_t k = 0; k < n; k++) {
    char key[32], got[256];
    snprintf(key, sizeof key, "[%zu]", k);
    assert_int_equal(jq_raw(path, key, got, sizeof got), 0);
    assert_string_equal(got, want[k]);
  }
  char got[8192], key[32];
  snprintf(key, sizeof key, "[%zu] | length", n);
  assert_int_equal(jq_raw(path, key, got, sizeof got), 0);
  assert_string_equal(got, "2999");                     /* one character per byte in */
}

/* ---- the set, through the library --------------------------------------------------------- */

static void test_set_two_phases(void **state)
{
  (void)state;
  struct outset *s;
  struct outfile *a, *b;
  struct t74_error err = { 0 };
  put(in_dir("a.txt"), "old a");
  /* phase 1 and 2, then a failure: nothing published */
  assert_int_equal(outset_new(&s, &err), T74_OK);
  assert_int_equal(outset_open(s, in_dir("a.txt"), 0, &a, &err), T74_OK);
  assert_int_equal(outset_open(s, in_dir("b.txt"), 0, &b, &err), T74_OK);
  outfile_printf(a, "new a");
  assert_int_equal(outfile_commit(a, &err), T74_OK);   /* finished, not yet published */
  size_t n;
  char *t = slurp(in_dir("a.txt"), &n);
  assert_string_equal(t, "old a");
  free(t);
  outfile_abort(b);
  assert_int_equal(outset_commit(s, &err), T74_EIO);   /* b was never written */
  outset_free(s);
  t = slurp(in_dir("a.txt"), &n);
  assert_string_equal(t, "old a");
  free(t);
  assert_int_equal(entries(), 1);
  /* a good run: both appear at the commit (err is sticky: a fresh one) */
  memset(&err, 0, sizeof err);
  assert_int_equal(outset_new(&s, &err), T74_OK);
  assert_int_equal(outset_open(s, in_dir("a.txt"), 0, &a, &err), T74_OK);
  assert_int_equal(outset_open(s, in_dir("b.txt"), 0, &b, &err), T74_OK);
  assert_int_equal(outset_open(s, in_dir("b.txt"), 0, &b, &err), T74_EINPUT);  /* twice */
  memset(&err, 0, sizeof err);
  outfile_printf(a, "new a");
  outfile_printf(b, "new b");
  assert_int_equal(outfile_commit(a, &err), T74_OK);
  assert_int_equal(outfile_commit(b, &err), T74_OK);
  assert_int_equal(access(in_dir("b.txt"), F_OK), -1);
  assert_int_equal(outset_commit(s, &err), T74_OK);
  outset_free(s);
  t = slurp(in_dir("b.txt"), &n);
  assert_string_equal(t, "new b");
  free(t);
  assert_int_equal(entries(), 2);
  /* refused kinds: a folder */
  memset(&err, 0, sizeof err);
  assert_int_equal(outset_new(&s, &err), T74_OK);
  assert_int_equal(outset_open(s, scratch, 0, &a, &err), T74_EIO);
  assert_non_null(strstr(err.msg, "folder"));
  outset_free(s);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test_setup(test_symlink_written_through, test_setup),
    cmocka_unit_test_setup(test_fifo_read_by_a_reader, test_setup),
    cmocka_unit_test_setup(test_char_device_stays, test_setup),
    cmocka_unit_test_setup(test_dash_is_stdout, test_setup),
    cmocka_unit_test_setup(test_failing_stats_leaves_others, test_setup),
    cmocka_unit_test_setup(test_same_file_twice_refused, test_setup),
    cmocka_unit_test_setup(test_output_is_an_input_refused, test_setup),
    cmocka_unit_test_setup(test_mode_kept, test_setup),
    cmocka_unit_test_setup(test_stats_json_any_path, test_setup),
    cmocka_unit_test_setup(test_json_string_writer, test_setup),
    cmocka_unit_test_setup(test_set_two_phases, test_setup),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
