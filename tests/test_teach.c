/*
** test_teach.c — `tube74 teach SCENE [-o DIR]`: the teaching page (cli/cmd_teach.c,
** cli/teach_page.c), loaded and stepped through in a real headless Chromium.
**
** This file contains code to check that:
**   every shipped scene gets its page: one self-contained file (no src=, no <link>, no
**   address other than the SVG namespace name); an import's warnings are printed once;
**   in Chromium (--dump-dom after the page's own key handler has been driven through its
**   #keys= hash, which presses the keys on load):
**     step 0 is the projected scene with one marker per projected vertex; Back at the
**     first step stays there, Right/Left move one step;
**     the first cut step marks as many XSORT crossings, of each type, as `render --dump
**     tables` lists for that cut;
**     the last Priority Matrix step shows as many known pairs (10 and 11 cells) as the
**     matrix `render --dump tables` prints at the end of the scan;
**     the D-block step lists the pieces whose D-blocks are on the line, Up moves the line;
**     the last step, the tube, counts exactly the dots of `render --dump tube`;
**   screenshots: the tube step shows the dots' green in many pixels, the first step none,
**   and the two pictures differ.
** Exits 77 (a skip) when Chromium is not installed (tools/deps.sh installs it).
** A standalone cmocka program run from the repository root; $TUBE74 (default ./tube74).
*/
#include <ctype.h>
#include <png.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
#define sh(...) tk_sh(scratch, __VA_ARGS__) /* a command run in the scratch folder */
static char root[256];
static const char *chromium;

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

#define CHROMIUM_FLAGS "--headless --no-sandbox --disable-gpu --disable-quic --no-first-run " \
  "--disable-background-networking --disable-component-update --disable-sync " \
  "--virtual-time-budget=3000"

static int run_no = 0;

/* Load page#keys=KEYS in a fresh profile; the DOM after the keys (caller frees). */
static char *dom(const char *page, const char *keys)
{
  run_no++;
  assert_int_equal(sh("%s " CHROMIUM_FLAGS " --user-data-dir=%s/prof%d --dump-dom "
                      "'file://%s/%s#keys=%s' > dom%d.html 2> chromium%d.log",
                      chromium, scratch, run_no, scratch, page, keys, run_no, run_no), 0);
  char name[32];
  snprintf(name, sizeof name, "dom%d.html", run_no);
  char *d = slurp(name);
  assert_non_null(d);
  assert_non_null(strstr(d, "data-kind="));           /* the script ran */
  return d;
}

static void screenshot(const char *page, const char *keys, const char *png)
{
  run_no++;
  assert_int_equal(sh("%s " CHROMIUM_FLAGS " --user-data-dir=%s/prof%d --window-size=1280,800 "
                      "--screenshot=%s/%s 'file://%s/%s#keys=%s' > /dev/null 2> chromium%d.log",
                      chromium, scratch, run_no, scratch, png, scratch, page, keys, run_no), 0);
}

/* The body's data-NAME value. */
static int body_data(const char *d, const char *name)
{
  char want[64];
  snprintf(want, sizeof want, "data-%s=\"", name);
  const char *b = strstr(d, "<body");
  assert_non_null(b);
  const char *p = strstr(b, want);
  assert_non_null(p);
  return atoi(p + strlen(want));
}

static int body_kind(const char *d, const char *kind)
{
  char want[64];
  snprintf(want, sizeof want, "data-kind=\"%s\"", kind);
  const char *b = strstr(d, "<body");
  const char *e = b ? strchr(b, '>') : NULL;
  const char *p = b ? strstr(b, want) : NULL;
  return p && e && p < e;
}

/* Pixels of one colour in a PNG. */
static long colour_pixels(const char *png, int r, int g, int b)
{
  char p[300];
  snprintf(p, sizeof p, "%s/%s", scratch, png);
  png_image im;
  memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  assert_true(png_image_begin_read_from_file(&im, p));
  im.format = PNG_FORMAT_RGB;
  uint8_t *px = malloc(PNG_IMAGE_SIZE(im));
  assert_non_null(px);
  assert_true(png_image_finish_read(&im, NULL, px, 0, NULL));
  long n = 0;
  for (size_t k = 0; k < (size_t)im.width * im.height; k++)
    n += px[3 * k] == r && px[3 * k + 1] == g && px[3 * k + 2] == b;
  free(px);
  return n;
}

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
}

static void test_steps_in_chromium(void **state)
{
  (void)state;
  const char *page = "pages/fig7b.html";
  assert_int_equal(sh("%s teach %s/scenes/fig7b.s74 -o pages > /dev/null", exe, root), 0);
  assert_int_equal(sh("%s render %s/scenes/fig7b.s74 --dump tables=t.txt --dump tube=t.pbm",
                      exe, root), 0);
  char *tables = slurp("t.txt");
  assert_non_null(tables);

  /* step 0: the projected faces, a marker per vertex (counted from the scene's face
     lines below) */
  char *d = dom(page, "");
  assert_int_equal(body_data(d, "step"), 0);
  assert_true(body_kind(d, "projected"));
  int steps = body_data(d, "steps");
  assert_true(steps >= 7);
  int vertices = count(d, "class=\"vertex\"");
  free(d);
  char sc[300];
  snprintf(sc, sizeof sc, "%s/scenes/fig7b.s74", root);
  FILE *f = fopen(sc, "r");
  assert_non_null(f);
  char ln[512];
  int want_v = 0;
  while (fgets(ln, sizeof ln, f)) {
    if (strncmp(ln, "face ", 5)) continue;
    char *p = ln + 5;
    strtol(p, &p, 10);                                   /* the face id */
    for (;;) {
      while (*p == ' ') p++;
      if (!isdigit((unsigned char)*p)) break;
      strtol(p, &p, 10);
      want_v++;
    }
  }
  fclose(f);
  assert_int_equal(vertices, want_v);

  /* step 1: YSORT of the first face, one rank a vertex, as many as the tables list */
  const char *ys = strstr(tables, "YSORT");
  assert_non_null(ys);
  int ranks = 0;
  for (const char *p = ys; *p && *p != '\n'; p++) ranks += p[0] == '(' && p[1] == 'v';
  assert_true(ranks >= 3);
  d = dom(page, "R");
  assert_true(body_kind(d, "ysort"));
  assert_int_equal(count(d, "class=\"vertex ysort-rank\""), ranks);
  free(d);

  /* Back at the first step stays; Right, Right, Left is step 1 */
  d = dom(page, "L");
  assert_int_equal(body_data(d, "step"), 0);
  free(d);
  d = dom(page, "RRL");
  assert_int_equal(body_data(d, "step"), 1);
  free(d);

  /* the first cut of fig6 (fig7b has no concave vertex): its XSORT crossings by type,
     as the tables list them */
  assert_int_equal(sh("%s teach %s/scenes/fig6.s74 -o pages > /dev/null && %s render "
                      "%s/scenes/fig6.s74 --dump tables=t6.txt", exe, root, exe, root), 0);
  char *t6 = slurp("t6.txt");
  assert_non_null(t6);
  const char *cut = strstr(t6, "\ncut 1 ");
  assert_non_null(cut);
  const char *xs = strstr(cut, "\nXSORT");
  assert_non_null(xs);
  const char *xe = strchr(xs + 1, '\n');
  int endp = 0, mid = 0;
  for (const char *p = strstr(xs, " endpoint"); p && p < xe; p = strstr(p + 1, " endpoint")) endp++;
  for (const char *p = strstr(xs, " middle"); p && p < xe; p = strstr(p + 1, " middle")) mid++;
  assert_true(endp + mid > 0);
  char keys[64] = "";
  int found = 0;
  for (int k = 1; k < steps && !found; k++) {
    strcat(keys, "R");
    d = dom("pages/fig6.html", keys);
    if (body_kind(d, "cut")) {
      found = 1;
      assert_int_equal(count(d, "class=\"xsort-endpoint\""), endp + 1);   /* + the legend */
      assert_int_equal(count(d, "class=\"xsort-middle\""), mid + 1);
      /* the pieces the cut borders, numbered, on both sides */
      assert_true(count(d, "data-side=\"below\"") >= 1);
      assert_true(count(d, "data-side=\"above\"") >= 1);
      assert_int_equal(count(d, "class=\"piece cutpiece\""),
                       count(d, "data-side=\"below\"") + count(d, "data-side=\"above\""));
    }
    free(d);
  }
  assert_true(found);
  free(t6);

  /* the last matrix step: as many known pairs as the final matrix of the tables */
  const char *pm = strstr(tables, "PRIORITY MATRIX");
  assert_non_null(pm);
  /* rows after the two header lines and the column numbers: "  %3d " then the codes */
  int known = 0;                                          /* both triangles, as drawn */
  const char *row = pm;
  for (int k = 0; k < 3 && row; k++) row = strchr(row, '\n') ? strchr(row, '\n') + 1 : NULL;
  while (row && *row == ' ') {
    char *p;
    strtol(row, &p, 10);                                  /* the row's number */
    const char *end = strchr(p, '\n');
    if (!end) end = p + strlen(p);
    for (; p < end; p++)
      if (p[0] == '1' && (p[1] == '0' || p[1] == '1') && p[-1] == ' ') known++;
    row = *end ? end + 1 : NULL;
  }
  d = dom(page, "ELL");                                   /* tube, D-blocks, last matrix */
  assert_true(body_kind(d, "matrix"));
  assert_int_equal(count(d, "data-code=\"L\"") + count(d, "data-code=\"H\""), known);
  assert_true(known > 0);
  assert_true(count(d, "class=\"gridrun\"") > 0);          /* the picture so far */
  free(d);

  /* the D-blocks: the line moves with Up */
  d = dom(page, "EL");
  assert_true(body_kind(d, "dblocks"));
  int line = body_data(d, "line");
  int bars = count(d, "class=\"dblock\"");
  assert_true(bars > 0);
  assert_int_equal(count(d, "\npiece ") + count(d, "\">piece "), bars * 2);  /* text + labels */
  free(d);
  d = dom(page, "ELU");
  assert_int_equal(body_data(d, "line"), line - 1);
  free(d);

  /* the tube: the dots of --dump tube */
  char *pbm = slurp("t.pbm");
  assert_non_null(pbm);
  int w, h, off = 0;
  assert_int_equal(sscanf(pbm, "P4 %d %d%n", &w, &h, &off), 2);
  long lit = 0;
  for (int k = 0; k < (w + 7) / 8 * h; k++)
    for (unsigned c = (unsigned char)pbm[off + 1 + k]; c; c &= c - 1) lit++;
  free(pbm);
  d = dom(page, "E");
  assert_true(body_kind(d, "tube"));
  char want[64];
  snprintf(want, sizeof want, " %ld dots lit", lit);
  assert_non_null(strstr(d, want));
  free(d);

  /* screenshots: the tube's green in the last step only */
  screenshot(page, "", "first.png");
  screenshot(page, "E", "tube.png");
  long g0 = colour_pixels("first.png", 0x50, 0xff, 0x78);
  long g1 = colour_pixels("tube.png", 0x50, 0xff, 0x78);
  assert_int_equal(g0, 0);
  assert_true(g1 > 5000);
  assert_int_not_equal(sh("cmp -s first.png tube.png"), 0);
  free(tables);
}

/* An import's warnings are printed once, as `render` prints them (the traced second read
   of the scene is quiet). */
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

int main(void)
{
  if (system("command -v chromium > /dev/null 2>&1") != 0) {
    printf("chromium is not installed (tools/deps.sh installs it)\n");
    return 77;
  }
  chromium = "chromium";
  if (!getcwd(root, sizeof root)) return 1;
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74teach.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_every_scene_self_contained),
    cmocka_unit_test(test_import_warns_once),
    cmocka_unit_test(test_steps_in_chromium),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
