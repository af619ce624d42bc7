/*
** test_tek_tools.c — the Tek stream reader (display/tek.h) against streams that real
** programs write: gnuplot (`set terminal tek40xx`, `set terminal xterm`) and GNU plotutils
** (`graph -T tek`), generated here at test time, and xterm's reading of them (Tekproc.c).
**
** This file contains code to check, each on a real tool's stream:
**   the erase     `render x.tek --look glow --look-at 1` of a stream that begins with ESC FF
**                 shows the same face as the stream without it (the dots given during the
**                 erase are written when it is over, display/look.c), and not a blank face;
**   GS BEL        BEL right after GS makes the first address a drawn vector, as xterm
**                 does (neither tool writes GS BEL, so BEL is put after each of gnuplot's
**                 GS: every move becomes a vector, and the old dots all stay);
**   LoY HiX LoY   plotutils' full point addresses HiY Extra LoY HiX LoX, rewritten as the
**                 malformed HiY Extra HiX LoY LoX, decode to the same dots (xterm takes the
**                 earlier LoY as the Extra byte), with one warning each; the Extra bits
**                 matter (zeroing them moves dots);
**   mode switches ESC [ ? 3 8 h and ESC ETX, which plotutils and gnuplot's `xterm`
**                 terminal write, give no warning and draw nothing; another ESC [ sequence
**                 is skipped whole with one warning; warnings name the byte of the ESC;
**   the cursor    text after LF (and VT) inside gnuplot's labels lands one line height
**                 (88 address units) below (above) the cursor, not on xterm's 88-unit grid
**                 (docs/tek.md "Alpha cursor").
** Exits 77 (a skip) when gnuplot or graph is not installed (tools/deps.sh installs both).
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "display/sink.h"
#include "display/tek.h"
#include "display/tube.h"
#include "emu/status.h"
#include "tests/ref/testkit.h"

static char scratch[64];

/* ---- files and tools --------------------------------------------------------------- */

static uint8_t *slurp(const char *path, size_t *n)
{
  return (uint8_t *)tk_slurp(path, n);
}

static void spit(const char *path, const uint8_t *b, size_t n)
{
  assert_int_equal(tk_put(path, b, n), 0);
}

static int have(const char *tool)
{
  char cmd[128];
  snprintf(cmd, sizeof cmd, "command -v %s >/dev/null 2>&1", tool);
  return system(cmd) == 0;
}

/* Run a shell command in the scratch folder; it must succeed. */
static void sh(const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  int rc = tk_vsh(scratch, fmt, ap);
  va_end(ap);
  if (rc != 0) fprintf(stderr, "command failed (%d): %s\n", rc, fmt);
  assert_int_equal(rc, 0);
}

/* A stream written by a tool (name in the scratch folder) read whole. */
static uint8_t *tool_stream(const char *name, size_t *n)
{
  char p[256];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  uint8_t *b = slurp(p, n);
  assert_non_null(b);
  assert_true(*n > 16);
  return b;
}

static void gnuplot_tek(void)
{
  sh("printf 'set terminal tek40xx\\nset output \"g.tek\"\\nset samples 200\\n"
     "plot [-10:10] sin(x)*x with lines, cos(x) with lines\\n' | gnuplot");
}

/* ---- decoding ---------------------------------------------------------------------- */

struct seen {
  size_t n, at[64];             /* warnings and their offsets */
};

static void on_warn(void *ctx, size_t offset, const char *msg)
{
  struct seen *s = ctx;
  (void)msg;
  if (s->n < 64) s->at[s->n] = offset;
  s->n++;
}

/* Decode into a fresh tube (caller frees); warnings into *w when given. */
static struct tube *decode(const uint8_t *b, size_t n, struct tek_report *rep, struct seen *w)
{
  struct tube *t = tube_new();
  assert_non_null(t);
  struct sink s = tube_sink(t);
  memset(rep, 0, sizeof *rep);
  if (w) { memset(w, 0, sizeof *w); rep->warn = on_warn; rep->ctx = w; }
  assert_int_equal(tek_decode(b, n, &s, rep), T74_OK);
  return t;
}

/* Every lit dot of a is lit in b. */
static int subset(const struct tube *a, const struct tube *b)
{
  for (int y = 0; y < TUBE_H; y++)
    for (int x = 0; x < TUBE_W; x++)
      if (tube_lit(a, x, y) && !tube_lit(b, x, y)) return 0;
  return 1;
}

static int same(const struct tube *a, const struct tube *b)
{
  return subset(a, b) && subset(b, a);
}

/* ---- the erase and the look -------------------------------------------------------- */

static void test_erase_first_dots_shown(void **state)
{
  (void)state;
  const char *tube74 = getenv("TUBE74") ? getenv("TUBE74") : "./tube74";
  char exe[512];
  if (tube74[0] == '/') snprintf(exe, sizeof exe, "%s", tube74);
  else {
    char cwd[256];
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(exe, sizeof exe, "%s/%s", cwd, tube74);
  }
  gnuplot_tek();
  size_t n;
  uint8_t *g = tool_stream("g.tek", &n);
  assert_true(g[0] == TEK_ESC && g[1] == TEK_FF);       /* gnuplot begins with an erase */
  char p[128];
  snprintf(p, sizeof p, "%s/noerase.tek", scratch);
  spit(p, g + 2, n - 2);
  uint8_t erase_only[] = { TEK_ESC, TEK_FF };
  snprintf(p, sizeof p, "%s/empty.tek", scratch);
  spit(p, erase_only, 2);
  sh("%s render g.tek -o a.png --look glow --look-at 1 2>/dev/null", exe);
  sh("%s render noerase.tek -o b.png --look glow --look-at 1 2>/dev/null", exe);
  sh("%s render empty.tek -o c.png --look glow --look-at 1 2>/dev/null", exe);
  sh("cmp -s a.png b.png");                              /* the same face */
  sh("! cmp -s a.png c.png");                            /* and not a blank one */
  free(g);
}

/* ---- GS BEL ------------------------------------------------------------------------ */

static void test_gs_bel_draws_first_vector(void **state)
{
  (void)state;
  gnuplot_tek();
  size_t n;
  uint8_t *g = tool_stream("g.tek", &n);
  uint8_t *h = malloc(2 * n);
  assert_non_null(h);
  size_t m = 0, gs = 0;
  for (size_t k = 0; k < n; k++) {
    h[m++] = g[k];
    if (g[k] == TEK_GS) { h[m++] = TEK_BEL; gs++; }
  }
  assert_true(gs > 10);
  struct tek_report r0, r1;
  struct seen w;
  struct tube *t0 = decode(g, n, &r0, NULL), *t1 = decode(h, m, &r1, &w);
  assert_int_equal(w.n, 0);
  assert_int_equal(r0.moves, gs);                       /* each GS: a dark move ... */
  assert_int_equal(r1.moves, 0);                        /* ... after GS BEL: drawn */
  assert_int_equal(r1.vectors, r0.vectors + gs);
  assert_true(subset(t0, t1));
  assert_true(tube_count(t1) > tube_count(t0));         /* the joins are drawn */
  /* BEL elsewhere in graph mode is only the bell */
  uint8_t late[] = { TEK_GS, 0x20, 0x60, 0x20, 0x40, TEK_BEL, 0x2F, 0x60, 0x2F, 0x40 };
  struct tek_report r2;
  struct tube *t2 = decode(late, sizeof late, &r2, NULL);
  assert_int_equal(r2.moves, 1);
  assert_int_equal(r2.vectors, 1);
  tube_free(t0); tube_free(t1); tube_free(t2);
  free(g); free(h);
}

/* ---- LoY HiX LoY LoX --------------------------------------------------------------- */

static int tag(uint8_t c) { return c >> 5; }

static void test_malformed_address_as_xterm(void **state)
{
  (void)state;
  /* 300 points along a curve, as plotutils' point plot (FS) */
  sh("awk 'BEGIN { for (i = 0; i < 300; i++) print i / 299, (i * 37 %% 101) / 100.0 }' | "
     "graph -T tek -m 0 -S 1 -x 0 1 -y 0 1 > p.tek");
  size_t n;
  uint8_t *p = tool_stream("p.tek", &n);
  uint8_t *bad = malloc(n), *zero = malloc(n);
  assert_non_null(bad);
  assert_non_null(zero);
  memcpy(bad, p, n);
  memcpy(zero, p, n);
  size_t full = 0, extra_set = 0;
  /* a full address: tag 01 (HiY), 11 (Extra), 11 (LoY), 01 (HiX), 10 (LoX) */
  for (size_t k = 0; k + 5 <= n; k++) {
    if (tag(p[k]) == 1 && tag(p[k + 1]) == 3 && tag(p[k + 2]) == 3 && tag(p[k + 3]) == 1 &&
        tag(p[k + 4]) == 2 && (k == 0 || tag(p[k - 1]) != 3)) {
      bad[k + 2] = p[k + 3];                            /* HiY Extra HiX LoY LoX */
      bad[k + 3] = p[k + 2];
      zero[k + 1] = 0x60;                               /* Extra bits cleared */
      if (p[k + 1] != 0x60) extra_set++;
      full++;
      k += 4;
    }
  }
  assert_true(full > 20);
  assert_true(extra_set > 0);
  struct tek_report r0, r1, r2;
  struct seen w0, w1;
  struct tube *t0 = decode(p, n, &r0, &w0), *t1 = decode(bad, n, &r1, &w1);
  struct tube *t2 = decode(zero, n, &r2, NULL);
  assert_int_equal(w0.n, 0);                            /* plotutils' own stream: clean */
  assert_int_equal(w1.n, full);                         /* one warning a malformed address */
  assert_int_equal(r1.points, r0.points);
  assert_true(same(t0, t1));                            /* read as xterm reads it */
  assert_false(same(t0, t2));                           /* and the Extra bits count */
  tube_free(t0); tube_free(t1); tube_free(t2);
  free(p); free(bad); free(zero);
}

/* ---- xterm's mode switches, warning offsets ---------------------------------------- */

static void test_xterm_mode_switches(void **state)
{
  (void)state;
  sh("echo '0 0 1 1 2 0.5 3 2' | graph -T tek > p.tek");
  sh("gnuplot -e 'set terminal xterm; set samples 50; plot x*x' > x.tek");
  const char *names[] = { "p.tek", "x.tek" };
  for (int f = 0; f < 2; f++) {
    size_t n;
    uint8_t *b = tool_stream(names[f], &n);
    static const uint8_t dectek[] = { TEK_ESC, '[', '?', '3', '8', 'h' };
    assert_memory_equal(b, dectek, sizeof dectek);       /* the tool writes both */
    assert_true(b[n - 2] == TEK_ESC && b[n - 1] == 0x03);
    struct tek_report r0, r1;
    struct seen w0;
    struct tube *t0 = decode(b, n, &r0, &w0);
    struct tube *t1 = decode(b + 6, n - 8, &r1, NULL);  /* without the two switches */
    assert_int_equal(w0.n, 0);
    assert_int_equal(r0.chars, r1.chars);               /* "?38h" is not drawn as text */
    assert_true(same(t0, t1));
    tube_free(t0); tube_free(t1);
    /* another control sequence and an unknown ESC: one warning each, at the ESC */
    uint8_t *c = malloc(n + 16);
    assert_non_null(c);
    size_t at1 = 6, m = 0;
    memcpy(c, b, at1); m = at1;
    memcpy(c + m, "\033[2J", 4); m += 4;                 /* ESC [ 2 J at byte 6 */
    size_t at2 = m;
    memcpy(c + m, "\033Z", 2); m += 2;                   /* ESC Z at byte 10 */
    memcpy(c + m, b + at1, n - at1); m += n - at1;
    struct tek_report r2;
    struct seen w2;
    struct tube *t2 = decode(c, m, &r2, &w2);
    assert_int_equal(w2.n, 2);
    assert_int_equal(w2.at[0], at1);
    assert_int_equal(w2.at[1], at2);
    assert_true(same(t0 = decode(b, n, &r0, NULL), t2));
    tube_free(t0); tube_free(t2);
    free(c); free(b);
  }
}

/* ---- LF, VT: one line from the cursor ---------------------------------------------- */

static void test_line_feed_from_cursor(void **state)
{
  (void)state;
  gnuplot_tek();
  size_t n;
  uint8_t *g = tool_stream("g.tek", &n);
  /* A: after each label's LF, draw "Q", then VT and "R". B: the same letters placed by
     graph-mode addresses at the cursor the 4014 rules give: Q one line (88 units) below
     the label's start plus its width, R one line above Q and one cell right (the x-axis
     labels sit less than a line from the bottom, so their Q wraps to the top line). */
  uint8_t *a = malloc(2 * n + 64), *b = malloc(4 * n + 64);
  assert_non_null(a);
  assert_non_null(b);
  size_t ma = 0, mb = 0, labels = 0, off_grid = 0;
  int X = 0, Y = 0, hiy = 0, hix = 0, lox = 0, loy = 0, seen_loy = 0;
  int mode = 0, chars = 0;                              /* 0 alpha, 1 graph */
  for (size_t k = 0; k < n; k++) {
    uint8_t c = g[k];
    if (c == TEK_GS) { mode = 1; seen_loy = 0; }
    else if (c == TEK_US) { mode = 0; chars = 0; }
    else if (mode == 1 && c >= 0x20) {                  /* gnuplot: 4010 addresses */
      if (tag(c) == 1) { if (seen_loy) hix = c & 31; else hiy = c & 31; }
      else if (tag(c) == 3) { loy = c & 31; seen_loy = 1; }
      else { lox = c & 31; seen_loy = 0; X = (hix << 7) | (lox << 2); Y = (hiy << 7) | (loy << 2); }
    } else if (mode == 0 && c >= 0x20 && c < 0x7F) chars++;
    a[ma++] = c;
    b[mb++] = c;
    if (mode == 0 && c == TEK_LF) {
      labels++;
      if (Y % 88) off_grid++;
      memcpy(a + ma, "Q\013R", 3); ma += 3;
      /* below the bottom line: the top line (34 x 88); above the top line: 0 */
      int qx = X + chars * 56, qy = Y - 88 < 0 ? 34 * 88 : Y - 88;
      int rx = qx + 56, ry = qy + 88 > 34 * 88 ? 0 : qy + 88;
      const int pos[2][2] = { { qx, qy }, { rx, ry } };
      const char letter[2] = { 'Q', 'R' };
      for (int j = 0; j < 2; j++) {
        int px = pos[j][0], py = pos[j][1];
        b[mb++] = TEK_GS;
        b[mb++] = (uint8_t)(0x20 | ((py >> 7) & 31));
        b[mb++] = (uint8_t)(0x60 | ((py & 3) << 2) | (px & 3));
        b[mb++] = (uint8_t)(0x60 | ((py >> 2) & 31));
        b[mb++] = (uint8_t)(0x20 | ((px >> 7) & 31));
        b[mb++] = (uint8_t)(0x40 | ((px >> 2) & 31));
        b[mb++] = TEK_US;
        b[mb++] = (uint8_t)letter[j];
      }
    }
  }
  assert_true(labels > 5);
  assert_true(off_grid > 0);                            /* xterm would snap these */
  struct tek_report ra, rb;
  struct seen wa;
  struct tube *ta = decode(a, ma, &ra, &wa), *tb = decode(b, mb, &rb, NULL);
  assert_int_equal(wa.n, 0);
  assert_true(same(ta, tb));
  free(g); free(a); free(b);
  tube_free(ta); tube_free(tb);
}

int main(void)
{
  if (!have("gnuplot") || !have("graph")) {
    printf("gnuplot or plotutils' graph is not installed (tools/deps.sh installs them)\n");
    return 77;
  }
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74tektools.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_erase_first_dots_shown),
    cmocka_unit_test(test_gs_bel_draws_first_vector),
    cmocka_unit_test(test_malformed_address_as_xterm),
    cmocka_unit_test(test_xterm_mode_switches),
    cmocka_unit_test(test_line_feed_from_cursor),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
