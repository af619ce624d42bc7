/*
** test_arith.c — the 1974 cost model and --arith (issue 11): the program charged to core,
** the 1974 arithmetic beside the exact one, --arith hitac, and `tube74 bench arith`.
**
** This file contains tests that drive ./tube74 (TUBE74) as a user would: statistics,
** exit statuses and messages, and the dumped tube dots of both arithmetics.
*/
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

#include "tests/ref/hardgen.h"
#include "tests/ref/testkit.h"

static char dir[64];

/* Run a shell command from the working folder; its exit status. */
#define run(...) tk_sh(".", __VA_ARGS__)

static double field(const char *path, const char *key)
{
  char *js = tk_slurp(path, NULL);
  assert_non_null(js);
  char k[96];
  snprintf(k, sizeof k, "\"%s\":", key);
  const char *p = strstr(js, k);
  assert_non_null(p);
  double v = strtod(p + strlen(k), NULL);
  free(js);
  return v;
}

/* Tube dots lit in one PBM and not in the other (-1: unreadable). */
static long pbm_diff(const char *a, const char *b)
{
  char *x = tk_slurp(a, NULL), *y = tk_slurp(b, NULL);
  long d = -1;
  if (x && y && strncmp(x, "P4\n400 300\n", 11) == 0 && strncmp(y, "P4\n400 300\n", 11) == 0) {
    d = 0;
    for (int k = 11; k < 11 + 50 * 300; k++)
      for (unsigned m = (unsigned char)(x[k] ^ y[k]); m; m &= m - 1) d++;
  }
  free(x);
  free(y);
  return d;
}

static int setup(void **state)
{
  (void)state;
  return tk_mkscratch(dir, sizeof dir, "/tmp/t74arith.XXXXXX");
}

static int teardown(void **state)
{
  (void)state;
  return tk_rmscratch(dir);
}

/* The program is charged to core by default (program_words, 4096), and "fits" includes it:
   a core that holds the tables alone but not the program too gives exit 3, naming the words. */
static void test_program_charged(void **state)
{
  (void)state;
  assert_int_equal(run("%s render scenes/fig6.s74 --stats %s/p.json 2>/dev/null", tk_prog(), dir), 0);
  assert_int_equal(run("%s render scenes/fig6.s74 --hitac program_words=0 --stats %s/n.json 2>/dev/null",
                       tk_prog(), dir), 0);
  char p[128], n[128];
  snprintf(p, sizeof p, "%s/p.json", dir);
  snprintf(n, sizeof n, "%s/n.json", dir);
  double with = field(p, "core_words_used"), without = field(n, "core_words_used");
  assert_true(field(p, "program_words") == 4096);
  assert_true(with == without + 4096);
  int core = (int)without + 64;                      /* the tables fit, the program not */
  assert_int_equal(run("%s render scenes/fig6.s74 --core %d --hitac program_words=0 -o %s/a.png "
                       "2>/dev/null", tk_prog(), core, dir), 0);
  assert_int_equal(run("%s render scenes/fig6.s74 --core %d -o %s/b.png 2>%s/err.txt", tk_prog(), core,
                       dir, dir), 3);
  char e[128], b[128];
  snprintf(e, sizeof e, "%s/err.txt", dir);
  snprintf(b, sizeof b, "%s/b.png", dir);
  assert_int_equal(access(b, F_OK), -1);             /* no output on exit 3 */
  char *msg = tk_slurp(e, NULL);
  assert_non_null(msg);
  char want[96];
  snprintf(want, sizeof want, "%d available", core);
  assert_non_null(strstr(msg, "needs"));
  assert_non_null(strstr(msg, want));
  free(msg);
}

/* hitac10_seconds prices the 1974 program's arithmetic; exact_hitac10_seconds the same run
   at tube74's exact widths, which costs more on the same machine. */
static void test_exact_costs_more(void **state)
{
  (void)state;
  assert_int_equal(run("%s render scenes/fig5.s74 --stats %s/c.json 2>/dev/null", tk_prog(), dir), 0);
  char c[128];
  snprintf(c, sizeof c, "%s/c.json", dir);
  double h = field(c, "hitac10_seconds"), x = field(c, "exact_hitac10_seconds");
  assert_true(h > 0);
  assert_true(x > 1.5 * h);
}

/* --arith hitac: a scene where 1974 arithmetic changes the picture (fig7a: vertices that
   project between whole world units, a T-junction-free but sloped face pair) ... */
static void test_hitac_differs(void **state)
{
  (void)state;
  assert_int_equal(run("%s render scenes/fig7a.s74 --dump tube=%s/e.pbm 2>/dev/null", tk_prog(), dir), 0);
  assert_int_equal(run("%s render scenes/fig7a.s74 --arith hitac --dump tube=%s/h.pbm "
                       "--stats %s/h.json 2>/dev/null", tk_prog(), dir, dir), 0);
  char e[128], h[128], j[128];
  snprintf(e, sizeof e, "%s/e.pbm", dir);
  snprintf(h, sizeof h, "%s/h.pbm", dir);
  snprintf(j, sizeof j, "%s/h.json", dir);
  long d = pbm_diff(e, h);
  assert_true(d > 100);
  char *js = tk_slurp(j, NULL);
  assert_non_null(js);
  assert_non_null(strstr(js, "\"arith\": \"hitac\""));
  free(js);
}

/* ... and one where it agrees: rectangles in the plane z = 0 with whole-unit vertices
   project onto themselves, and their crossings need no fraction, so every value the 1974
   program holds is exact. (A sloped edge through point centres already differs: its
   truncated increments drift off the exact ties.) The faces are coplanar: the larger
   number is in front, in both arithmetics. */
static void test_hitac_agrees(void **state)
{
  (void)state;
  char s[128];
  snprintf(s, sizeof s, "%s/flat.s74", dir);
  FILE *f = fopen(s, "w");
  assert_non_null(f);
  fprintf(f, "view 0 0 -1000\nwindow -200 -150 200 150\n"
          "vertex 1 -150 -100 0\nvertex 2 100 -100 0\nvertex 3 100 100 0\nvertex 4 -150 100 0\n"
          "vertex 5 -50 -50 0\nvertex 6 150 -50 0\nvertex 7 150 130 0\nvertex 12 -50 130 0\n"
          "vertex 8 -180 -140 0\nvertex 9 180 -140 0\nvertex 10 180 140 0\nvertex 11 -180 140 0\n"
          "face 2 1 2 3 4 grey 200\nface 3 5 6 7 12 grey 100\nface 1 8 9 10 11 grey 40\n");
  assert_int_equal(fclose(f), 0);
  assert_int_equal(run("%s render %s --dump tube=%s/fe.pbm 2>/dev/null", tk_prog(), s, dir), 0);
  assert_int_equal(run("%s render %s --arith hitac --dump tube=%s/fh.pbm 2>/dev/null", tk_prog(), s, dir), 0);
  char e[128], h[128];
  snprintf(e, sizeof e, "%s/fe.pbm", dir);
  snprintf(h, sizeof h, "%s/fh.pbm", dir);
  assert_int_equal(pbm_diff(e, h), 0);
}

/* --arith takes exact or hitac; anything else is a usage error (exit 2). */
static void test_arith_usage(void **state)
{
  (void)state;
  assert_int_equal(run("%s render scenes/fig6.s74 --arith float -o %s/u.png 2>/dev/null", tk_prog(), dir), 2);
  char u[128];
  snprintf(u, sizeof u, "%s/u.png", dir);
  assert_int_equal(access(u, F_OK), -1);
}

/* hitac never crashes on scenes its coordinates fold: the sphere's small faces fold, are
   skipped with a counted warning, and the run succeeds. */
static void test_hitac_folds_gracefully(void **state)
{
  (void)state;
  assert_int_equal(run("%s render scenes/sphere.s74 --arith hitac --stats %s/s.json -o %s/s.png "
                       "2>%s/s.err", tk_prog(), dir, dir, dir), 0);
  char j[128], e[128];
  snprintf(j, sizeof j, "%s/s.json", dir);
  snprintf(e, sizeof e, "%s/s.err", dir);
  double skipped = field(j, "arith_faces_skipped");
  assert_true(skipped >= 1);
  char *msg = tk_slurp(e, NULL);
  assert_non_null(msg);
  int warnings = 0;
  for (const char *q = strstr(msg, "warning: face"); q; q = strstr(q + 1, "warning: face")) warnings++;
  assert_int_equal(warnings, (int)skipped);
  free(msg);
}

/* bench arith: a Markdown table with a row per scene (shipped and generated) and the
   picture of the differences. */
static void test_bench_arith(void **state)
{
  (void)state;
  assert_int_equal(run("%s bench arith --out %s/bench >/dev/null 2>&1", tk_prog(), dir), 0);
  char md[128], png[128];
  snprintf(md, sizeof md, "%s/bench/arith.md", dir);
  snprintf(png, sizeof png, "%s/bench/arith.png", dir);
  char *t = tk_slurp(md, NULL), *p = tk_slurp(png, NULL);
  assert_non_null(t);
  assert_non_null(p);
  assert_memory_equal(p, "\x89PNG", 4);
  assert_non_null(strstr(t, "| scene | dots lit (exact) | dots differing |"));
  /* fig7a differs (above): its row's third column is not 0 */
  const char *r = strstr(t, "| fig7a | ");
  assert_non_null(r);
  long lit = 0, diff = -1;
  assert_int_equal(sscanf(r, "| fig7a | %ld | %ld |", &lit, &diff), 2);
  assert_true(lit > 0 && diff > 0);
  /* the exact tables take more core than the 1974 program's (columns 9 and 10) */
  long c74 = 0, cex = 0;
  assert_int_equal(sscanf(r, "| fig7a | %*d | %*d | %*f | %*f | %*f | %*f | %ld | %ld |", &c74, &cex), 2);
  assert_true(c74 > 4096 && cex > c74);
  assert_non_null(strstr(t, "| gen-comb24 | "));
  assert_non_null(strstr(t, "| gen-shallow1 | "));
  free(t);
  free(p);
  assert_int_equal(run("%s bench arith --bogus 2>/dev/null", tk_prog()), 2);
}

/* Fig. 10: three scenes over real photographs, each exercising concave faces (cut by the
   Segment Generator), holes, and interpenetration (cut along intersection lines); every
   photograph's source and licence is recorded in scenes/README.md. */
static void test_fig10_scenes(void **state)
{
  (void)state;
  char *readme = tk_slurp("scenes/README.md", NULL);
  assert_non_null(readme);
  static const char *const names[] = { "fig10a", "fig10b", "fig10c" };
  for (int k = 0; k < 3; k++) {
    char path[64], js[128];
    snprintf(path, sizeof path, "scenes/%s.s74", names[k]);
    snprintf(js, sizeof js, "%s/%s.json", dir, names[k]);
    assert_int_equal(run("%s render %s --stats %s -o %s/%s.png 2>/dev/null", tk_prog(), path, js, dir,
                         names[k]), 0);
    assert_true(field(js, "concave_splits") > 0);
    assert_true(field(js, "intersection_splits") > 0);
    assert_true(field(js, "core_words_used") <= 16384);     /* fits, program included */
    char *sc = tk_slurp(path, NULL);
    assert_non_null(sc);
    assert_non_null(strstr(sc, " * "));                      /* a face with a hole */
    const char *bg = strstr(sc, "background ");
    assert_non_null(bg);
    char photo[64];
    assert_int_equal(sscanf(bg, "background %63s", photo), 1);
    char where[96];
    snprintf(where, sizeof where, "scenes/%s", photo);
    assert_int_equal(access(where, R_OK), 0);
    char row[96];
    snprintf(row, sizeof row, "| `%s` |", photo);
    const char *r = strstr(readme, row);
    assert_non_null(r);                                      /* source and licence row */
    const char *eol = strchr(r, '\n');
    assert_non_null(eol);
    char line[1024];
    snprintf(line, sizeof line, "%.*s", (int)(eol - r), r);
    assert_true(strstr(line, "CC0") || strstr(line, "public domain"));
    free(sc);
  }
  free(readme);
}

/* The hard configurations of issue 7 (tests/ref/hardgen.c), 3 seeds of every family, under
   both arithmetics: hitac never crashes and never refuses a scene exact accepts (a fold is
   skipped with a warning), and on these scenes it does change pictures. */
static void test_hitac_hardgen(void **state)
{
  (void)state;
  int ndiff = 0, nrun = 0;
  for (int fam = 0; fam < HG_NFAMILIES; fam++)
    for (uint64_t seed = 0; seed < 3; seed++) {
      struct xr_scene sc;
      memset(&sc, 0, sizeof sc);
      assert_int_equal(hg_generate(fam, seed, &sc), 0);
      char path[128];
      snprintf(path, sizeof path, "%s/hg.s74", dir);
      FILE *f = fopen(path, "w");
      assert_non_null(f);
      assert_int_equal(xr_write(&sc, f), 0);
      assert_int_equal(fclose(f), 0);
      xr_scene_free(&sc);
      int a = run("%s render %s --dump tube=%s/hge.pbm 2>/dev/null", tk_prog(), path, dir);
      int b = run("%s render %s --arith hitac --dump tube=%s/hgh.pbm 2>/dev/null", tk_prog(), path, dir);
      assert_int_equal(b, a);
      if (a != 0) continue;
      char e[128], h[128];
      snprintf(e, sizeof e, "%s/hge.pbm", dir);
      snprintf(h, sizeof h, "%s/hgh.pbm", dir);
      long d = pbm_diff(e, h);
      assert_true(d >= 0);
      nrun++;
      ndiff += d > 0;
    }
  assert_true(nrun >= HG_NFAMILIES);
  assert_true(ndiff > nrun / 2);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_program_charged),
    cmocka_unit_test(test_exact_costs_more),
    cmocka_unit_test(test_hitac_differs),
    cmocka_unit_test(test_hitac_agrees),
    cmocka_unit_test(test_arith_usage),
    cmocka_unit_test(test_hitac_folds_gracefully),
    cmocka_unit_test(test_bench_arith),
    cmocka_unit_test(test_fig10_scenes),
    cmocka_unit_test(test_hitac_hardgen),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
