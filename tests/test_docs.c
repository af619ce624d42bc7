/*
** test_docs.c — what the README and `tube74 params` promise a user, as written (issue 20,
** "Everyday use").
**
** This file contains code to check that:
**   the import example  the README's "import views" commands (`./tube74 render
**                 scenes/cube.obj ...`) run exactly as they stand there (in a scratch
**                 folder with `scenes` and `tube74` linked in): exit 0, a picture that is
**                 not one colour; scenes/cube.obj is a closed unit cube (six faces, each
**                 edge shared by two of them);
**   params        `tube74 params` cites no file that is not shipped (no notes outside the
**                 repository) and every passage it quotes from docs/hardware.md is there;
**   the papers    the README's "The papers" section names each of papers 000-004 with its
**                 authors and title;
**   --turn        on a .s74 scene or a Tek stream is refused (exit 2, a message naming
**                 --turn and the scene, no output), on an .obj it turns;
**   UTF-16        an .obj or .off in UTF-16 (with a byte-order mark either way round, or
**                 without one) is refused as UTF-16 at line 1, not as a NUL byte;
**   the figures   every `<!-- docs:NAME begin/end -->` table of README.md and the docs/ pages
**                 that tools/figures.sh makes (1974 seconds, core words, pieces, dots) is
**                 exactly what it prints from this tree now; every other one (host
**                 times) says the date, the machine and the commit it was measured on.
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
#include <png.h>

#include "tests/ref/testkit.h"

static char scratch[64];
static char exe[512];
static char root[256];

static void path(char *out, size_t cap, const char *name)
{
  snprintf(out, cap, "%s/%s", scratch, name);
}

/* The repository's README (malloc'd), *sec at its first `heading`; the test fails when
   either is missing. */
static char *readme_at(const char *heading, const char **sec)
{
  char p[400];
  snprintf(p, sizeof p, "%s/README.md", root);
  char *readme = tk_slurp(p, NULL);
  assert_non_null(readme);
  *sec = strstr(readme, heading);
  assert_non_null(*sec);
  return readme;
}

/* Distinct colours in an RGB PNG (up to 3 counted), or -1 if unreadable. */
static int png_colours(const char *p)
{
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, p)) return -1;
  img.format = PNG_FORMAT_RGB;
  uint8_t *rgb = malloc(PNG_IMAGE_SIZE(img));
  if (!rgb || !png_image_finish_read(&img, NULL, rgb, 0, NULL)) { free(rgb); return -1; }
  int n = 1;
  size_t npx = (size_t)img.width * img.height;
  const uint8_t *c0 = rgb, *c1 = NULL;
  for (size_t k = 1; k < npx && n < 3; k++) {
    const uint8_t *c = rgb + 3 * k;
    if (!memcmp(c, c0, 3) || (c1 && !memcmp(c, c1, 3))) continue;
    if (!c1) c1 = c;
    n++;
  }
  free(rgb);
  return n;
}

static void test_readme_import_example(void **state)
{
  (void)state;
  const char *sec;
  char *readme = readme_at("### import views", &sec);
  assert_int_equal(tk_sh(scratch, "ln -s '%s/scenes' scenes && ln -s '%s' tube74", root, exe), 0);
  /* the section's first code block */
  const char *b0 = strstr(sec, "\n```\n"), *b1 = b0 ? strstr(b0 + 5, "\n```") : NULL;
  assert_non_null(b1);
  int ran = 0;
  for (const char *l = strstr(b0, "\n./tube74 render "); l && l < b1;
       l = strstr(l + 1, "\n./tube74 render ")) {
    const char *e = strchr(l + 1, '\n');
    char cmd[256];
    snprintf(cmd, sizeof cmd, "%.*s", (int)(e - l - 1), l + 1);
    char *hash = strchr(cmd, '#');
    if (hash) *hash = '\0';
    assert_non_null(strstr(cmd, "scenes/cube.obj"));
    int rc = tk_sh(scratch, "%s 2> err.txt", cmd);
    if (rc != 0) fail_msg("the README's `%s`: exit %d", cmd, rc);
    char *o = strstr(cmd, "-o ");
    assert_non_null(o);
    char out[64];
    assert_int_equal(sscanf(o + 3, "%63s", out), 1);
    char png[128];
    path(png, sizeof png, out);
    assert_true(png_colours(png) >= 2);
    ran++;
  }
  assert_int_equal(ran, 2);
  free(readme);
}

/* scenes/cube.obj: 8 vertices, 6 faces of 4, every edge in two faces, once each way. */
static void test_cube_closed(void **state)
{
  (void)state;
  char p[400];
  snprintf(p, sizeof p, "%s/scenes/cube.obj", root);
  FILE *f = fopen(p, "r");
  assert_non_null(f);
  char line[256];
  int nv = 0, nf = 0, edge[9][9];
  memset(edge, 0, sizeof edge);
  while (fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') nv++;
    if (line[0] != 'f') continue;
    int a[4];
    assert_int_equal(sscanf(line, "f %d %d %d %d", &a[0], &a[1], &a[2], &a[3]), 4);
    for (int k = 0; k < 4; k++) edge[a[k]][a[(k + 1) % 4]]++;
    nf++;
  }
  fclose(f);
  assert_int_equal(nv, 8);
  assert_int_equal(nf, 6);
  int edges = 0;
  for (int i = 1; i <= 8; i++)
    for (int j = 1; j <= 8; j++)
      if (edge[i][j]) {
        assert_int_equal(edge[i][j], 1);
        assert_int_equal(edge[j][i], 1);            /* the neighbour runs it the other way */
        edges++;
      }
  assert_int_equal(edges, 24);                    /* 12 edges, each way */
}

/* s with every run of blanks and line ends as one blank */
static void squeeze(char *s)
{
  char *w = s;
  for (const char *r = s; *r; r++) {
    if (isspace((unsigned char)*r)) {
      if (w > s && w[-1] != ' ') *w++ = ' ';
    } else {
      *w++ = *r;
    }
  }
  *w = 0;
}

static void test_params_cites_shipped(void **state)
{
  (void)state;
  char out[128], p[400];
  path(out, sizeof out, "params.txt");
  assert_int_equal(tk_runl(out, NULL, "params", (char *)NULL), 0);
  char *t = tk_slurp(out, NULL);
  assert_non_null(t);
  assert_null(strstr(t, "hardware-facts"));
  assert_null(strstr(t, "shared/notes"));
  snprintf(p, sizeof p, "%s/docs/hardware.md", root);
  char *doc = tk_slurp(p, NULL);
  assert_non_null(doc);
  squeeze(doc);
  int quotes = 0;
  for (const char *c = strstr(t, "docs/hardware.md: '"); c; c = strstr(c + 1, "docs/hardware.md: '")) {
    const char *q = c + strlen("docs/hardware.md: '");
    /* the quote ends at a ' not followed by a letter (HITAC-10's is inside one) */
    const char *e = q;
    while (*e && !(*e == '\'' && !isalpha((unsigned char)e[1]))) e++;
    assert_true(*e == '\'');
    char quote[512];
    snprintf(quote, sizeof quote, "%.*s", (int)(e - q), q);
    squeeze(quote);
    if (!strstr(doc, quote)) fail_msg("params quotes docs/hardware.md: '%s', not there", quote);
    quotes++;
  }
  assert_true(quotes >= 12);
  free(doc);
  free(t);
}

static void test_papers_cited(void **state)
{
  (void)state;
  const char *sec;
  char *readme = readme_at("\n## The papers\n", &sec);
  static const struct { const char *num, *authors[3], *title; } paper[] = {
    { "**000**", { "Tomoyuki Nishita", "Nakamae", NULL },
      "Half-Tone Representation of 3-D Objects with Smooth Edges by Using a Multi-Scanning Method" },
    { "**001**", { "隈元 玄", "Kumamoto", NULL }, "スキャンラインZバッファ法におけるエリアス除去の一手法" },
    { "**002**", { "Yoshinori Mochizuki", "Kunio Kondo", "Hisashi Sato" },
      "Enhanced Edge Drawing Technique for Communicating Impression of 3-D Shapes" },
    { "**003**", { "Hiroyuki Yamauchi", "Setsuo Osuga", NULL },
      "On the Hidden-surface Problem and Half-tone Computer Graphics Representations" },
    { "**004**", { "Kei Inaba", "Shin-ichi Murakami", NULL },
      "Partial Smooth Shading for Triangular Patch Model" },
  };
  for (size_t k = 0; k < sizeof paper / sizeof *paper; k++) {
    const char *at = strstr(sec, paper[k].num);
    if (!at) fail_msg("README \"The papers\": no %s", paper[k].num);
    const char *next = k + 1 < sizeof paper / sizeof *paper ? strstr(at, paper[k + 1].num) : NULL;
    size_t len = next ? (size_t)(next - at) : strlen(at);
    char *entry = malloc(len + 1);
    assert_non_null(entry);
    memcpy(entry, at, len);
    entry[len] = 0;
    squeeze(entry);
    for (int a = 0; a < 3 && paper[k].authors[a]; a++)
      if (!strstr(entry, paper[k].authors[a]))
        fail_msg("%s: no author %s", paper[k].num, paper[k].authors[a]);
    if (!strstr(entry, paper[k].title)) fail_msg("%s: no title \"%s\"", paper[k].num, paper[k].title);
    free(entry);
  }
  free(readme);
}

static void test_turn_refused(void **state)
{
  (void)state;
  char err[128], png[128];
  path(err, sizeof err, "turn.err");
  path(png, sizeof png, "turn.png");
  assert_int_equal(tk_runl(NULL, err, "render", "scenes/fig6.s74", "--turn", "0,0", "-o", png,
                           (char *)NULL), 2);
  assert_int_equal(access(png, F_OK), -1);
  char *e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_non_null(strstr(e, "--turn turns .obj and .off imports only"));
  assert_non_null(strstr(e, "scenes/fig6.s74"));
  free(e);
  /* and for every command that reads a scene */
  assert_int_equal(tk_runl(NULL, NULL, "tek", "scenes/fig6.s74", "--turn", "10,10", (char *)NULL), 2);
  /* a Tek stream is not turned either */
  char tek[128];
  path(tek, sizeof tek, "fig6.tek");
  assert_int_equal(tk_runl(NULL, NULL, "tek", "scenes/fig6.s74", "-o", tek, (char *)NULL), 0);
  assert_int_equal(tk_runl(NULL, err, "render", tek, "--turn", "0,0", "-o", png, (char *)NULL), 2);
  assert_int_equal(access(png, F_OK), -1);
  e = tk_slurp(err, NULL);
  assert_non_null(e);
  assert_non_null(strstr(e, "is a Tek stream"));
  free(e);
  /* an import turns */
  assert_int_equal(tk_runl(NULL, NULL, "render", "scenes/cube.obj", "--turn", "0,0", "-o", png,
                           (char *)NULL), 0);
}

static void test_utf16_import(void **state)
{
  (void)state;
  static const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  static const struct { const char *name, *kind; int bom, big; } cases[] = {
    { "le.obj", "byte-order mark FF FE", 1, 0 },
    { "be.obj", "byte-order mark FE FF", 1, 1 },
    { "nobom.obj", "little-endian, no byte-order mark", 0, 0 },
    { "nobom-be.off", "big-endian, no byte-order mark", 0, 1 },
    { "le.off", "byte-order mark FF FE", 1, 0 },
  };
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    unsigned char buf[256];
    size_t n = 0;
    if (cases[c].bom) {
      buf[n++] = cases[c].big ? 0xFE : 0xFF;
      buf[n++] = cases[c].big ? 0xFF : 0xFE;
    }
    for (const char *t = text; *t; t++) {
      buf[n++] = cases[c].big ? 0 : (unsigned char)*t;
      buf[n++] = cases[c].big ? (unsigned char)*t : 0;
    }
    char file[128], err[128], png[128];
    path(file, sizeof file, cases[c].name);
    path(err, sizeof err, "u16.err");
    path(png, sizeof png, "u16.png");
    assert_int_equal(tk_put(file, buf, n), 0);
    assert_int_equal(tk_runl(NULL, err, "render", file, "-o", png, (char *)NULL), 2);
    assert_int_equal(access(png, F_OK), -1);
    char *e = tk_slurp(err, NULL);
    assert_non_null(e);
    char want[256];
    snprintf(want, sizeof want, "%s:1: the file is UTF-16 (", file);
    if (!strstr(e, want) || !strstr(e, cases[c].kind) || strstr(e, "NUL"))
      fail_msg("%s: %s", cases[c].name, e);
    free(e);
  }
  /* plain ASCII with the same content is read */
  char file[128];
  path(file, sizeof file, "ascii.obj");
  assert_int_equal(tk_put(file, text, sizeof text - 1), 0);
  assert_int_equal(tk_runl(NULL, NULL, "render", file, (char *)NULL), 0);
}

/* ---- the figures between docs markers ----------------------------------------------- */

/* Each `<!-- docs:NAME begin -->` .. `<!-- docs:NAME end -->` block of file `rel`: the
   deterministic ones (names tools/figures.sh --list prints) must be exactly what the
   script prints now from this tree's tube74; the measured ones must name the day, the
   machine and the commit they were measured on. Counts the blocks of each kind. */
static void check_blocks(const char *rel, const char *names, int *det, int *host)
{
  char p[600];
  snprintf(p, sizeof p, "%s/%s", root, rel);
  char *text = tk_slurp(p, NULL);
  assert_non_null(text);
  for (const char *at = text; (at = strstr(at, "\n<!-- docs:")) != NULL; ) {
    at += strlen("\n<!-- docs:");
    char name[64];
    int len = 0;
    while (len < 63 && (isalnum((unsigned char)at[len]) || at[len] == '-')) { name[len] = at[len]; len++; }
    name[len] = 0;
    if (strncmp(at + len, " begin -->\n", 11) != 0) continue;
    const char *body = at + len + 11;
    char endmark[96];
    snprintf(endmark, sizeof endmark, "<!-- docs:%s end -->", name);
    const char *end = strstr(body, endmark);
    if (!end) fail_msg("%s: block docs:%s has no end marker", rel, name);
    char word[72];
    snprintf(word, sizeof word, " %s ", name);
    if (strstr(names, word)) {
      char out[400];
      path(out, sizeof out, "figure.md");
      assert_int_equal(tk_sh(root, "sh tools/figures.sh %s '%s' >'%s'", name, exe, out), 0);
      char *want = tk_slurp(out, NULL);
      assert_non_null(want);
      size_t n = (size_t)(end - body);
      if (strlen(want) != n || memcmp(want, body, n) != 0)
        fail_msg("%s: the figures in docs:%s are not what the tree computes; run "
                 "`DOCS_HOST=0 make docs` (now:\n%s)", rel, name, want);
      free(want);
      (*det)++;
    } else {
      /* a measured table: dated, with its machine and commit */
      int y, m, d;
      const char *h = strstr(body, "Measured ");
      if (!h || h > end || sscanf(h, "Measured %4d-%2d-%2d on ", &y, &m, &d) != 3 ||
          !strstr(h, ", commit ") || strstr(h, ", commit ") > end)
        fail_msg("%s: docs:%s holds host figures without the date, machine and commit", rel, name);
      (*host)++;
    }
    at = end;
  }
  free(text);
}

static void test_figures_current(void **state)
{
  (void)state;
  char out[400];
  path(out, sizeof out, "names.txt");
  assert_int_equal(tk_sh(root, "sh tools/figures.sh --list >'%s'", out), 0);
  char *list = tk_slurp(out, NULL);
  assert_non_null(list);
  char names[400];
  snprintf(names, sizeof names, " %s", list);
  for (char *c = names; *c; c++) if (*c == '\n') *c = ' ';
  free(list);
  int det = 0, host = 0;
  check_blocks("README.md", names, &det, &host);
  check_blocks("docs/aa.md", names, &det, &host);
  check_blocks("docs/edges.md", names, &det, &host);
  check_blocks("docs/smooth.md", names, &det, &host);
  /* the README carries every deterministic table and the measured ones */
  assert_true(det >= 4);
  assert_true(host >= 5);
}

int main(void)
{
  if (!getcwd(root, sizeof root)) return 1;
  if (tk_exe(exe, sizeof exe) != 0) return 1;
  if (tk_mkscratch(scratch, sizeof scratch, "/tmp/t74docs.XXXXXX") != 0) return 1;
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_cube_closed),
    cmocka_unit_test(test_readme_import_example),
    cmocka_unit_test(test_params_cites_shipped),
    cmocka_unit_test(test_papers_cited),
    cmocka_unit_test(test_turn_refused),
    cmocka_unit_test(test_utf16_import),
    cmocka_unit_test(test_figures_current),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  tk_rmscratch(scratch);
  return rc;
}
