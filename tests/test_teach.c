/*
** test_teach.c — `tube74 teach SCENE [-o DIR]`: the teaching page (cli/cmd_teach.c,
** cli/teach_page.html), loaded and stepped through in a real headless Chromium.
**
** This file contains code to check that:
**   every shipped scene of the list gets its page: one self-contained file (no src=, no
**   <link>, no address other than the SVG namespace name); bad input and a Tek stream get
**   their messages and no page; an import's warnings are printed once (one run);
**   in Chromium (one browser for everything, driven over the DevTools protocol,
**   tests/ref/cdp.h), for fig6 (a face cut three times, one face: an empty matrix),
**   fig7b (faces that pierce each other: pieces numbered while the scan runs) and the
**   street (126 faces: the matrix shown in part):
**     the page makes no network request and raises no error or console warning;
**     the dump the page carries is, byte for byte, what `render --dump tables` writes;
**     at every step: the heading's "Step k of N" and the counter's "Step k / N" agree with
**     the step shown; the step draws something (its marks) or says why it is empty; its
**     labels are at least 14 px, dark and do not overlap; its figure's screenshot is not
**     blank and differs from the previous step's;
**     the piece numbers and vertex lists of the pieces steps are those of the dump;
**     fig6's first cut marks its IPL crossings with the dump's numbers (11, 10, 12, 13, 8,
**     14), the middle ones as many as XSORT's middle rows;
**     fig6's matrix steps say why every entry is 00; the last matrix step's known pairs
**     are the final matrix of the dump;
**     the D-block step lists every D-block with its five fields and each visible stretch
**     lies in a D-block of its piece; Up moves its line (#keys=);
**     the halftone step's levels are the lit dots of `render --dump tube` in those cells;
**     the tube step counts exactly the dots of `render --dump tube`;
**     #all shows every step, each under its own heading; Right, Left and Back at the
**     first step move as they should.
** Exits 77 (a skip) when Chromium is not installed (tools/deps.sh installs it).
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
#include <unistd.h>

#include <cmocka.h>

#include "tests/ref/cdp.h"
#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */
static char root[256];
static const char *chromium;
static struct cdp browser;
static int browser_up;

/* A file of the scratch folder, whole; NULL if unreadable. */
static char *slurp(const char *name)
{
  char p[300];
  snprintf(p, sizeof p, "%s/%s", scratch, name);
  return tk_slurp(p, NULL);
}

static int count(const char *hay, const char *needle)
{
  int n = 0;
  for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle)) n++;
  return n;
}

/* The value of a JavaScript expression in the page (a string), asserted to exist. */
static char *js(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char *js(const char *fmt, ...)
{
  char e[8192];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e, sizeof e, fmt, ap);
  va_end(ap);
  char *v = cdp_eval(&browser, e);
  if (!v) print_message("evaluating %.200s: %s\n", e, browser.error);
  assert_non_null(v);
  return v;
}

static int js_int(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int js_int(const char *fmt, ...)
{
  char e[8192];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e, sizeof e, fmt, ap);
  va_end(ap);
  char *v = js("String(%s)", e);
  int n = atoi(v);
  free(v);
  return n;
}

static int setup_browser(void);

static void load(const char *page, const char *hash)
{
  assert_int_equal(setup_browser(), 0);
  char url[700];
  snprintf(url, sizeof url, "file://%s/%s%s", scratch, page, hash);
  assert_int_equal(cdp_goto(&browser, url), 0);
}

/* The page's faults so far: none. */
static void no_faults(void)
{
  if (browser.errors) print_message("page error: %s\n", browser.error);
  assert_int_equal(browser.errors, 0);
  if (browser.requests) print_message("page asked the network for %s\n", browser.request);
  assert_int_equal(browser.requests, 0);
}

/* ---- the dump, read here on its own ----------------------------------------------------- */

/* "N:labels" of every "  piece N: labels" line, one a line, in the dump's order. */
static char *dump_pieces(const char *t)
{
  size_t cap = strlen(t) + 1, k = 0;
  char *o = malloc(cap);
  assert_non_null(o);
  for (const char *p = t; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL) {
    int n, used = 0;
    if (sscanf(p, "  piece %d:%n", &n, &used) == 1 && used) {
      const char *e = strchr(p, '\n');
      k += (size_t)snprintf(o + k, cap - k, "%d:%.*s\n", n, (int)(e - p - used - 1), p + used + 1);
    }
  }
  o[k] = 0;
  return o;
}

/* Known pairs (i < j) of the dump's final PRIORITY MATRIX (dense rows or a(i,j) lines). */
static int dump_known(const char *t)
{
  const char *pm = strstr(t, "PRIORITY MATRIX");
  assert_non_null(pm);
  int known = 0;
  for (const char *p = strchr(pm, '\n'); p && *++p; p = strchr(p, '\n')) {
    int i, j;
    char code[4];
    if (sscanf(p, "  a(%d,%d) = %2s", &i, &j, code) == 3) { known++; continue; }
    char *q;
    const char *eol = strchr(p, '\n');
    const char *dash = strstr(p, " -");
    if (!dash || (eol && dash > eol)) continue;        /* not a row: no diagonal */
    i = (int)strtol(p, &q, 10);
    if (q == p || i <= 0) continue;
    int col = 1;
    while (*q && *q != '\n') {
      while (*q == ' ') q++;
      if (*q == '\n' || !*q) break;
      if (q[0] == '1' && (q[1] == '0' || q[1] == '1') && col > i) known++;
      while (*q && *q != ' ' && *q != '\n') q++;
      col++;
    }
  }
  return known;
}

/* The dots of `render --dump tube` (P4, 400 x 300, top row first). */
static uint8_t *pbm_dots(const char *name, long *lit)
{
  char *pbm = slurp(name);
  assert_non_null(pbm);
  int w, h, off = 0;
  assert_int_equal(sscanf(pbm, "P4 %d %d%n", &w, &h, &off), 2);
  assert_int_equal(w, 400);
  assert_int_equal(h, 300);
  uint8_t *d = calloc(400 * 300, 1);
  assert_non_null(d);
  *lit = 0;
  for (int y = 0; y < 300; y++)
    for (int x = 0; x < 400; x++)
      if ((unsigned char)pbm[off + 1 + y * 50 + x / 8] >> (7 - x % 8) & 1) {
        d[(299 - y) * 400 + x] = 1;                   /* y up, as on the tube */
        (*lit)++;
      }
  free(pbm);
  return d;
}

/* ---- every step ------------------------------------------------------------------------ */

/* What the test reads of the step shown: heading, counter, kind, marks, the why line, and
   each label's size, colour and overlaps (measured in the page, independently of how the
   page placed them), and the first figure's place. */
static const char step_facts[] =
  "(function (k) {"
  " teach.show(k);"
  " const sec = document.querySelector('section.step');"
  " const why = sec.querySelector('.why');"
  " let small = 0, pale = 0, over = 0, n = 0; const boxes = [];"
  " sec.querySelectorAll('svg text').forEach(t => {"
  "  const r = t.getBoundingClientRect(); if (!r.width) return; n++;"
  "  const svg = t.ownerSVGElement, cs = getComputedStyle(t);"
  "  if (parseFloat(cs.fontSize) * svg.getScreenCTM().a < 14) small++;"
  "  const c = cs.fill.match(/[0-9.]+/g).map(Number);"
  "  if ((0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) / 255 > 0.3) pale++;"
  "  boxes.push([r.left, r.top, r.right, r.bottom, svg]); });"
  " for (let a = 0; a < boxes.length; a++) for (let b = a + 1; b < boxes.length; b++) {"
  "  const p = boxes[a], q = boxes[b]; if (p[4] !== q[4]) continue;"
  "  if (Math.min(p[2], q[2]) - Math.max(p[0], q[0]) > 1 && Math.min(p[3], q[3]) - Math.max(p[1], q[1]) > 1) over++; }"
  " sec.querySelectorAll('p, li, td, th, h2, h3, .note, .why').forEach(e => {"
  "  if (e.textContent.trim() && parseFloat(getComputedStyle(e).fontSize) < 14) small++; });"
  " const f = sec.querySelector('.figs svg'), fr = f.getBoundingClientRect();"
  " return [sec.querySelector('h2.title').textContent, document.getElementById('count').textContent,"
  "  sec.dataset.kind, sec.dataset.marks, why && !why.hidden ? why.textContent.trim().length : 0, n, small, pale,"
  "  over, fr.left + scrollX, fr.top + scrollY, fr.width, fr.height, f.classList.contains('dark') ? 1 : 0].join('|');"
  "})(%d)";

struct step {
  char kind[24];
  int marks, why;
};

/* Show every step of the page loaded, check each, and return their kinds and marks
   (*n of them). */
static struct step *every_step(const char *page, int *n)
{
  int steps = js_int("teach.steps");
  assert_true(steps >= 6);
  struct step *s = calloc((size_t)steps, sizeof *s);
  assert_non_null(s);
  uint8_t *prev = NULL;
  int pw = 0, ph = 0;
  for (int k = 1; k <= steps; k++) {
    char *f = js(step_facts, k);
    char head[400], counter[64];
    int hk = 0, hn = 0, ck = 0, cn = 0, nlab, small, pale, over, dark;
    double fx, fy, fw, fh;
    char *field[14] = { 0 };
    int nf = 0;
    for (char *p = f; nf < 14; nf++) { field[nf] = p; p = strchr(p, '|'); if (!p) { nf++; break; } *p++ = 0; }
    assert_int_equal(nf, 14);
    snprintf(head, sizeof head, "%s", field[0]);
    snprintf(counter, sizeof counter, "%s", field[1]);
    assert_int_equal(sscanf(head, "Step %d of %d", &hk, &hn), 2);
    assert_int_equal(sscanf(counter, "Step %d / %d", &ck, &cn), 2);
    if (hk != k || ck != k || hn != steps || cn != steps)
      print_message("%s step %d: heading \"%s\", counter \"%s\"\n", page, k, head, counter);
    assert_int_equal(hk, k);
    assert_int_equal(ck, k);
    assert_int_equal(hn, steps);
    assert_int_equal(cn, steps);
    snprintf(s[k - 1].kind, sizeof s[k - 1].kind, "%s", field[2]);
    s[k - 1].marks = atoi(field[3]);
    s[k - 1].why = atoi(field[4]);
    nlab = atoi(field[5]);
    small = atoi(field[6]);
    pale = atoi(field[7]);
    over = atoi(field[8]);
    fx = atof(field[9]); fy = atof(field[10]); fw = atof(field[11]); fh = atof(field[12]);
    dark = atoi(field[13]);
    if (small || pale || over || (!s[k - 1].marks && !s[k - 1].why))
      print_message("%s step %d (%s): %d labels, %d small, %d pale, %d overlapping; marks %d, why %d\n",
                    page, k, s[k - 1].kind, nlab, small, pale, over, s[k - 1].marks, s[k - 1].why);
    assert_int_equal(small, 0);
    assert_int_equal(pale, 0);
    assert_int_equal(over, 0);
    assert_true(s[k - 1].marks > 0 || s[k - 1].why > 20);   /* drawn, or says why not */
    free(f);
    /* its figure: not blank, and not the previous step's */
    int w, h;
    uint8_t *px = cdp_shot(&browser, fx, fy, fw, fh, &w, &h);
    assert_non_null(px);
    long ink = 0;
    const int bg = dark ? 0 : 255;
    for (int y = 3; y < h - 3; y++)
      for (int x = 3; x < w - 3; x++) {
        const uint8_t *q = px + 3 * ((size_t)y * (size_t)w + (size_t)x);
        ink += abs(q[0] - bg) > 24 || abs(q[1] - bg) > 24 || abs(q[2] - bg) > 24;
      }
    if (ink < 300) print_message("%s step %d (%s): its figure is blank (%ld pixels)\n", page, k, s[k - 1].kind, ink);
    assert_true(ink >= 300);
    if (prev && pw == w && ph == h && !memcmp(prev, px, (size_t)w * (size_t)h * 3)) {
      print_message("%s step %d (%s) shows the figure of step %d\n", page, k, s[k - 1].kind, k - 1);
      fail();
    }
    free(prev);
    prev = px;
    pw = w;
    ph = h;
  }
  free(prev);
  no_faults();
  *n = steps;
  return s;
}

static int find_kind(const struct step *s, int n, const char *kind, int last)
{
  int at = 0;
  for (int k = 0; k < n; k++)
    if (!strcmp(s[k].kind, kind)) { at = k + 1; if (!last) break; }
  return at;
}

/* The page's embedded dump is the dump render writes with the same options. */
static void same_dump(const char *dumpfile)
{
  char *want = slurp(dumpfile);
  assert_non_null(want);
  char *got = js("T.tables");
  if (strcmp(got, want)) print_message("the page's dump differs from %s\n", dumpfile);
  assert_string_equal(got, want);
  free(got);
  free(want);
}

/* The pieces listed on step k: "N:labels" lines, in the table's order. */
static char *page_pieces(int k)
{
  return js("(teach.show(%d), Array.from(document.querySelectorAll('section.step tr[data-piece]'),"
            " r => r.dataset.piece + ':' + r.dataset.labels + '\\n').join(''))", k);
}

/* The last matrix step shows the dump's final matrix; every matrix step that shows no
   known pair says why. */
static void matrix_steps(const struct step *s, int n, const char *tables)
{
  int last = find_kind(s, n, "matrix", 1);
  assert_true(last > 0);
  int known = js_int("(teach.show(%d), document.querySelector('svg[data-kind=matrix]').dataset.known)", last);
  assert_int_equal(known, dump_known(tables));
  char *ok = js("document.querySelector('section.step [data-check]').dataset.check");
  assert_string_equal(ok, "ok");
  free(ok);
  for (int k = 0; k < n; k++)
    if (!strcmp(s[k].kind, "matrix") && !s[k].marks) assert_true(s[k].why > 20);
}

/* The D-block step: every D-block with its five fields; each visible stretch inside a
   D-block of its piece; Up moves the line by one. */
static void dblock_step(const char *page, const struct step *s, int n)
{
  int k = find_kind(s, n, "dblocks", 0);
  assert_true(k > 0);
  char *rows = js("(teach.show(%d), Array.from(document.querySelectorAll('section.step tr.drow'),"
                  " r => Array.from(r.cells, c => c.textContent).join(';')).join('\\n'))", k);
  int nrows = 0;
  for (char *p = rows; *p; ) {
    char *e = strchr(p, '\n');
    if (e) *e = 0;
    int cells = 1;
    for (char *q = p; *q; q++) cells += *q == ';';
    assert_int_equal(cells, 8);                          /* piece face xb xe dxb dxe y-max sides */
    assert_null(strstr(p, ";;"));                        /* no field empty */
    nrows++;
    p = e ? e + 1 : p + strlen(p);
  }
  free(rows);
  assert_int_equal(nrows, s[k - 1].marks);
  /* each stretch [x0, x1) of piece P lies within [xb, xe] of P's D-block */
  int bad = js_int("(() => { const j = +document.body.dataset.line, r = T.rows[j]; let bad = 0;"
                   " r.s.forEach(sp => { const d = r.d.find(x => x[0] === sp[2]);"
                   "  if (!d || sp[0] < d[1] - 1e-9 || sp[1] > d[2] + 1e-9) bad++; });"
                   " return bad + (r.s.length === document.querySelectorAll('li.vspan').length ? 0 : 1000); })()");
  assert_int_equal(bad, 0);
  char hash[64];
  snprintf(hash, sizeof hash, "#step=%d&keys=", k);
  load(page, hash);
  int line = js_int("document.body.dataset.line");
  snprintf(hash, sizeof hash, "#step=%d&keys=U", k);
  load(page, hash);
  assert_int_equal(js_int("document.body.dataset.step"), k);
  assert_int_equal(js_int("document.body.dataset.line"), line - 1);
}

/* The halftone step's levels are the lit dots of those cells in --dump tube; the tube
   step counts the dump's dots. */
static void display_steps(const struct step *s, int n, const char *pbm, int cell)
{
  long lit;
  uint8_t *d = pbm_dots(pbm, &lit);
  int k = find_kind(s, n, "halftone", 0);
  assert_true(k > 0);
  char *lv = js("(teach.show(%d), Array.from(document.querySelectorAll('section.step text[data-level]'),"
                " t => t.dataset.i + ' ' + t.dataset.j + ' ' + t.dataset.level + ' ' + t.textContent).join('\\n'))", k);
  int cells = 0, lit_cells = 0;
  for (char *p = lv; *p; ) {
    int i, j, level, shown;
    assert_int_equal(sscanf(p, "%d %d %d %d", &i, &j, &level, &shown), 4);
    int dots = 0;
    for (int cy = 0; cy < cell; cy++)
      for (int cx = 0; cx < cell; cx++) dots += d[(299 - cell * j - cy) * 400 + cell * i + cx];
    assert_int_equal(shown, dots);
    cells++;
    lit_cells += dots > 0;
    p = strchr(p, '\n') ? strchr(p, '\n') + 1 : p + strlen(p);
  }
  free(lv);
  assert_int_equal(cells, 12 * 8);
  assert_true(lit_cells > 0);
  k = find_kind(s, n, "tube", 0);
  assert_true(k > 0);
  char want[64];
  snprintf(want, sizeof want, " %ld dots lit", lit);
  char *text = js("(teach.show(%d), document.querySelector('section.step .explain').textContent)", k);
  if (!strstr(text, want)) print_message("tube step: \"%s\" wanted in \"%s\"\n", want, text);
  assert_non_null(strstr(text, want));
  free(text);
  free(d);
}

/* #all: every step, each under its own heading. */
static void all_steps(const char *page, int n)
{
  load(page, "#all");
  char *h = js("Array.from(document.querySelectorAll('section.step h2.title'), t => t.textContent.split(' \\u00b7 ')[0]).join('|')");
  char want[64];
  int at = 0;
  for (int k = 1; k <= n; k++) {
    snprintf(want, sizeof want, "Step %d of %d", k, n);
    assert_memory_equal(h + at, want, strlen(want));
    at += (int)strlen(want) + 1;
  }
  assert_int_equal((int)strlen(h) + 1, at);
  free(h);
  no_faults();
}

static void make_page(const char *scene)
{
  assert_int_equal(sh("%s teach %s/scenes/%s.s74 -o pages > /dev/null && %s render %s/scenes/%s.s74 "
                      "--dump tables=%s.txt --dump tube=%s.pbm", exe, root, scene, exe, root, scene,
                      scene, scene), 0);
}

/* ---- the tests --------------------------------------------------------------------------- */

static void test_every_scene_self_contained(void **state)
{
  (void)state;
  const char *scenes[] = { "crossing", "fig5", "fig6", "fig7a", "fig7b", "street" };
  for (size_t k = 0; k < sizeof scenes / sizeof *scenes; k++) {
    assert_int_equal(sh("%s teach %s/scenes/%s.s74 -o pages > /dev/null", exe, root, scenes[k]), 0);
    char name[64];
    snprintf(name, sizeof name, "pages/%s.html", scenes[k]);
    char *h = slurp(name);
    assert_non_null(h);
    assert_null(strstr(h, "src="));
    assert_null(strstr(h, "<link"));
    assert_null(strstr(h, "https:"));
    assert_int_equal(count(h, "http:"), count(h, "http://www.w3.org/2000/svg"));
    free(h);
  }
  /* bad input: the job's own message and status, no page */
  assert_int_equal(sh("printf 'vertex 1 0 0\\n' > bad.s74 && %s teach bad.s74 -o badpages "
                      "2> /dev/null", exe), 2);
  assert_int_equal(sh("! test -e badpages/bad.html"), 0);
  /* a Tek stream is no scene: refused, no page */
  assert_int_equal(sh("%s tek %s/scenes/fig5.s74 -o f5.tek > /dev/null && "
                      "%s teach f5.tek -o tekpages 2> /dev/null", exe, root, exe), 2);
  assert_int_equal(sh("! test -e tekpages/f5.html"), 0);
  /* render's outputs are render's */
  assert_int_equal(sh("%s teach %s/scenes/fig5.s74 -o pages --dump tube=x.pbm 2> /dev/null", exe, root), 2);
}

/* An import's warnings are printed once, as `render` prints them: one run. */
static void test_import_warns_once(void **state)
{
  (void)state;
  static const char obj[] = "v 0 0 0\nv 100 0 0\nv 100 100 1\nv 0 100 0\nv 50 50 30\n"
                            "f 1 2 3 4\nf 1 2 5\n";   /* face 1 is not planar */
  char p[300];
  snprintf(p, sizeof p, "%s/np.obj", scratch);
  assert_int_equal(tk_put(p, obj, sizeof obj - 1), 0);
  assert_int_equal(sh("%s render np.obj -o np.png 2> r.txt && %s teach np.obj -o pages > /dev/null "
                      "2> t.txt", exe, exe), 0);
  char *r = slurp("r.txt"), *t = slurp("t.txt");
  assert_non_null(r);
  assert_non_null(t);
  assert_int_equal(count(r, "np.obj:6: warning: face 1 not planar"), 1);
  assert_string_equal(t, r);
  free(r);
  free(t);
}

/* What every page gets checked for: made, loaded, no fault, its dump render's byte for
   byte, every step (every_step), the pieces listed on its first step of kind pieces_kind
   the dump's (returned in *pieces, "N:labels" lines), the matrix steps, the D-block step,
   the halftone and tube steps. Returns the steps (*n), the dump in *tables. */
static struct step *check_page(const char *scene, const char *pieces_kind, char **tables,
                               char **pieces, int *n)
{
  char page[64], name[64];
  snprintf(page, sizeof page, "pages/%s.html", scene);
  make_page(scene);
  snprintf(name, sizeof name, "%s.txt", scene);
  *tables = slurp(name);
  assert_non_null(*tables);
  load(page, "#step=1");
  no_faults();
  same_dump(name);
  struct step *s = every_step(scene, n);
  int k = find_kind(s, *n, pieces_kind, 0);
  assert_true(k > 0);
  char *want = dump_pieces(*tables);
  *pieces = page_pieces(k);
  assert_string_equal(*pieces, want);
  free(want);
  matrix_steps(s, *n, *tables);
  dblock_step(page, s, *n);
  snprintf(name, sizeof name, "%s.pbm", scene);
  display_steps(s, *n, name, 4);
  return s;
}

/* fig6: the paper's face, cut three times. */
static void test_fig6(void **state)
{
  (void)state;
  char *tables, *pieces;
  int n;
  struct step *s = check_page("fig6", "facepieces", &tables, &pieces, &n);
  /* the first cut, state (a): the crossings of IPL with the dump's numbers */
  int k = find_kind(s, n, "cut", 0);
  assert_true(k > 0);
  char *marks = js("(teach.show(%d), Array.from(document.querySelectorAll('section.step text[data-crossing]'),"
                   " t => t.dataset.crossing).join(' '))", k);
  assert_string_equal(marks, "11 10 12 13 8 14");           /* IPL of Fig. 6 (a) */
  free(marks);
  const char *xs = strstr(tables, "\nXSORT");
  assert_non_null(xs);
  int mid = 0;
  for (const char *p = strstr(xs, " middle"); p && p < strchr(xs + 1, '\n'); p = strstr(p + 1, " middle")) mid++;
  assert_int_equal(js_int("document.querySelectorAll('section.step .xmark-middle').length"), mid);
  char *rows = js("Array.from(document.querySelectorAll('section.step tr.now[data-row]'), r => r.dataset.row).join(' ')");
  assert_string_equal(rows, "PBS IPL");                     /* the rows state (a) writes */
  free(rows);
  /* state (b) shades the lower pieces of LWS */
  assert_int_equal(js_int("(teach.show(%d), document.querySelectorAll('section.step [data-side=below]').length)", k + 1), 2);
  /* one face: the matrix stays empty (and every matrix step says why: matrix_steps) */
  assert_int_equal(dump_known(tables), 0);
  all_steps("pages/fig6.html", n);
  /* the keys: Back at the first step stays; Right, Right, Left is step 2 */
  load("pages/fig6.html", "#keys=L");
  assert_int_equal(js_int("document.body.dataset.step"), 1);
  load("pages/fig6.html", "#keys=RRL");
  assert_int_equal(js_int("document.body.dataset.step"), 2);
  no_faults();
  free(pieces);
  free(s);
  free(tables);
}

/* fig7b: pierced faces, their halves numbered while the scan runs. */
static void test_fig7b(void **state)
{
  (void)state;
  char *tables, *pieces;
  int n;
  struct step *s = check_page("fig7b", "pieces", &tables, &pieces, &n);
  assert_non_null(strstr(pieces, "7:9 10 11\n"));   /* face 3, cut when the scan reached it */
  assert_true(dump_known(tables) > 0);
  free(pieces);
  free(s);
  free(tables);
}

/* The street: 126 faces; the matrix in part, the page still every step. */
static void test_street(void **state)
{
  (void)state;
  char *tables, *pieces;
  int n;
  struct step *s = check_page("street", "pieces", &tables, &pieces, &n);
  /* the matrix steps show a part of the matrix and say so */
  int m = find_kind(s, n, "matrix", 1);
  char *note = js("(teach.show(%d), document.querySelector('section.step .side').textContent)", m);
  assert_non_null(strstr(note, "too many to read"));
  free(note);
  free(pieces);
  free(s);
  free(tables);
}

/* The one browser, started by the first test that needs it and stopped by main. */
static int setup_browser(void)
{
  if (browser_up) return 0;
  char prof[128];
  snprintf(prof, sizeof prof, "%s/profile", scratch);
  if (cdp_start(&browser, chromium, prof, 1400, 1000) != 0) return -1;
  browser_up = 1;
  return 0;
}

int main(void)
{
  static const char *const places[] = { "/usr/bin/chromium", "/usr/bin/chromium-browser",
                                        "/usr/lib/chromium/chromium" };
  for (size_t k = 0; k < sizeof places / sizeof *places && !chromium; k++)
    if (access(places[k], X_OK) == 0) chromium = places[k];
  if (!chromium) {
    printf("chromium is not installed (tools/deps.sh installs it)\n");
    return 77;
  }
  if (!getcwd(root, sizeof root)) return 1;
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74teach.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_every_scene_self_contained),
    cmocka_unit_test(test_import_warns_once),
    cmocka_unit_test(test_fig6),
    cmocka_unit_test(test_fig7b),
    cmocka_unit_test(test_street),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  if (browser_up) cdp_stop(&browser);
  tk_rmscratch(scratch);
  return rc;
}
