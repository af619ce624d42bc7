/*
** test_invariance.c — ./tube74's output must not depend on how a scene is written down.
**
** This file contains the outside check that the picture is a function of the scene, not
** of its text: for generated scenes (tests/ref/scenegen.c, every family, cells 3 and 4)
** the same scene is written four ways —
**   base      the generator's order;
**   shuffled  vertex statements and face statements in another order (face and vertex
**             numbers unchanged; vertices still before faces);
**   reversed  about half of the boundaries and holes in the opposite orientation;
**   mixed     shuffled, reversed, every ring starting at another vertex, holes of a face
**             listed in another order —
** and `$TUBE74 render SCENE --cell C --dump ids=... --dump points=...` must give
** byte-identical `ids` dumps and byte-identical `points` dumps (the order points are
** written to the tube included) for all four.
**
** Every run gets --core 65536: "does not fit" (exit 3) is not what this test is about; a
** scene that does not fit in any writing is noted and skipped, one that fits in only some
** writings is a difference.
**
** A difference names family, seed, cell, the variant, and where the files first differ,
** and keeps the scene files. TUBE74_INVAR_SEEDS (default 10) sets seeds per family and cell.
** Exit 77 (skip) when $TUBE74 (default ./tube74) is not executable.
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

#include "tests/ref/osmesa_ref.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/tuberun.h"

#define IV_DEFAULT_SEEDS 10
#define IV_TIMEOUT_S 20.0     /* one tube74 run */
#define IV_MAX_TIMEOUTS 3     /* after this many, the remaining scenes are not run */
#define IV_NVAR 4
#define IV_CORE "65536"       /* generous core: "does not fit" (exit 3) is not what is tested */

static const char *const iv_name[IV_NVAR] = {"base", "shuffled", "reversed", "mixed"};

typedef struct iv_state {
  char dir[64];
  int seeds;
  long scenes, runs, failures, kept, timeouts, not_run, no_fit;
} iv_state;

static int group_setup(void **state)
{
  iv_state *x = calloc(1, sizeof *x);
  if (!x) return -1;
  snprintf(x->dir, sizeof x->dir, "/tmp/tube74-invar-XXXXXX");
  if (!mkdtemp(x->dir)) {
    perror("mkdtemp");
    free(x);
    return -1;
  }
  const char *e = getenv("TUBE74_INVAR_SEEDS");
  x->seeds = (e && atoi(e) > 0) ? atoi(e) : IV_DEFAULT_SEEDS;
  *state = x;
  return 0;
}

static int group_teardown(void **state)
{
  iv_state *x = *state;
  if (!x) return 0;
  printf("invariance: %ld scenes, %ld tube74 runs, %ld scenes with differences or failed runs\n",
         x->scenes, x->runs, x->failures);
  if (x->no_fit) printf("invariance: %ld scenes did not fit --core %s\n", x->no_fit, IV_CORE);
  if (x->not_run)
    printf("invariance: %ld scenes not run after %d timeouts\n", x->not_run, IV_MAX_TIMEOUTS);
  if (x->kept) printf("invariance: failing scenes kept in %s\n", x->dir);
  else rmdir(x->dir);
  free(x);
  return 0;
}

/* Where two files first differ, as text for the report. */
static void first_difference(const char *a, size_t na, const char *b, size_t nb, int is_text,
                             int cell, char *out, size_t outlen)
{
  size_t k = 0;
  while (k < na && k < nb && a[k] == b[k]) k++;
  if (is_text) {
    long line = 1;
    size_t start = 0;
    for (size_t q = 0; q < k; q++)
      if (a[q] == '\n') line++, start = q + 1;
    int la = 0, lb = 0;
    while (start + (size_t)la < na && a[start + la] != '\n' && la < 40) la++;
    while (start + (size_t)lb < nb && b[start + lb] != '\n' && lb < 40) lb++;
    snprintf(out, outlen, "line %ld: base \"%.*s\", variant \"%.*s\" (%zu vs %zu bytes)", line,
             la, start < na ? a + start : "", lb, start < nb ? b + start : "", na, nb);
  } else {
    /* ids dump: the samples are the last w * h * 2 bytes, whatever the header's layout */
    const int w = ref_grid_w(cell);
    const size_t data = (size_t)w * (size_t)ref_grid_h(cell) * 2;
    if (na >= data && k >= na - data) {
      const size_t smp = (k - (na - data)) / 2;
      snprintf(out, outlen, "point (%zu,%zu) (%zu vs %zu bytes)", smp % (size_t)w,
               smp / (size_t)w, na, nb);
    } else {
      snprintf(out, outlen, "byte %zu (%zu vs %zu bytes)", k, na, nb);
    }
  }
}

/* One scene, four ways; all four runs at once (they are independent processes). */
static long check_scene(iv_state *x, sg_family fam, uint64_t seed, int cell)
{
  char err[512], cells[4], note[120];
  char scene[IV_NVAR][160], ids[IV_NVAR][160], pts[IV_NVAR][160], png[IV_NVAR][160];
  char dids[IV_NVAR][200], dpts[IV_NVAR][200], log[IV_NVAR][160];
  const char *name = sg_family_name(fam);
  if (x->timeouts >= IV_MAX_TIMEOUTS) { /* a hanging tube74 must not hang the suite */
    x->not_run++;
    return 1;
  }
  ref_scene s = {0};
  if (sg_generate(fam, seed, &s, err, sizeof err) != 0) fail_msg("generator: %s", err);
  snprintf(cells, sizeof cells, "%d", cell);
  pid_t pid[IV_NVAR];
  for (int v = 0; v < IV_NVAR; v++) {
    const sg_variant var = {seed * 31 + (uint64_t)v, v == 1 || v == 3, v == 2 || v == 3, v == 3};
    snprintf(scene[v], sizeof scene[v], "%s/%s-%llu-c%d-%s.s74", x->dir, name,
             (unsigned long long)seed, cell, iv_name[v]);
    snprintf(ids[v], sizeof ids[v], "%s/ids-%d.pgm", x->dir, v);
    snprintf(pts[v], sizeof pts[v], "%s/points-%d.txt", x->dir, v);
    snprintf(png[v], sizeof png[v], "%s/out-%d.png", x->dir, v);
    snprintf(log[v], sizeof log[v], "%s/log-%d.txt", x->dir, v);
    snprintf(dids[v], sizeof dids[v], "ids=%s", ids[v]);
    snprintf(dpts[v], sizeof dpts[v], "points=%s", pts[v]);
    snprintf(note, sizeof note, "invariance %s seed %llu cell %d, written %s", name,
             (unsigned long long)seed, cell, iv_name[v]);
    if (sg_write_s74(&s, scene[v], note, v ? &var : NULL, err, sizeof err) != 0) fail_msg("%s", err);
    unlink(ids[v]);
    unlink(pts[v]);
    unlink(png[v]);
    unlink(log[v]);
    char *argv[] = {(char *)tr_program(), "render", scene[v], "--cell", cells, "--dump", dids[v],
                    "--dump", dpts[v], "-o", png[v], "--core", IV_CORE, NULL};
    pid[v] = tr_spawn(argv, log[v], err, sizeof err);
    if (pid[v] < 0) fail_msg("%s", err);
  }
  long bad = 0;
  int rc[IV_NVAR], fit3 = 0;
  for (int v = 0; v < IV_NVAR; v++) {
    int sig = 0;
    rc[v] = tr_wait(pid[v], IV_TIMEOUT_S, &sig);
    x->runs++;
    if (rc[v] == -2) x->timeouts++;
    if (rc[v] == 3) fit3++;
    if (rc[v] != 0 && rc[v] != 3) {
      char how[80];
      tr_describe(rc[v], sig, IV_TIMEOUT_S, how, sizeof how);
      printf("FAIL %s seed %llu cell %d (%s): tube74 %s\n", name, (unsigned long long)seed,
             cell, iv_name[v], how);
      tr_print_tail(log[v], 5, "     | ");
      bad++;
    }
  }
  if (!bad && fit3 == IV_NVAR) { /* too big for the machine whichever way it is written */
    printf("NOTE %s seed %llu cell %d: does not fit --core %s (exit 3); not compared\n", name,
           (unsigned long long)seed, cell, IV_CORE);
    x->no_fit++;
    fit3 = -1;
  } else if (!bad && fit3) {
    printf("DIFF %s seed %llu cell %d: exit status 3 (does not fit) for only some writings:", name,
           (unsigned long long)seed, cell);
    for (int v = 0; v < IV_NVAR; v++) printf(" %s %d", iv_name[v], rc[v]);
    printf("\n");
    bad++;
  }
  if (!bad && fit3 == 0) {
    size_t n0i = 0, n0p = 0;
    char *i0 = tr_slurp(ids[0], &n0i), *p0 = tr_slurp(pts[0], &n0p);
    if (!i0 || !p0 || n0p == 0) { /* an empty picture would make the test vacuous */
      printf("FAIL %s seed %llu cell %d: base run wrote %s %s dump\n", name,
             (unsigned long long)seed, cell, (i0 && p0) ? "an empty" : "no",
             !i0 ? "ids" : "points");
      bad++;
    }
    for (int v = 1; v < IV_NVAR && !bad; v++) {
      size_t ni = 0, np = 0;
      char *iv = tr_slurp(ids[v], &ni), *pv = tr_slurp(pts[v], &np);
      char where[200];
      if (!iv || ni != n0i || memcmp(i0, iv, ni) != 0) {
        if (iv) first_difference(i0, n0i, iv, ni, 0, cell, where, sizeof where);
        else snprintf(where, sizeof where, "no ids dump");
        printf("DIFF %s seed %llu cell %d: --dump ids differs for %s scene at %s\n", name,
               (unsigned long long)seed, cell, iv_name[v], where);
        bad++;
      }
      if (!pv || np != n0p || memcmp(p0, pv, np) != 0) {
        if (pv) first_difference(p0, n0p, pv, np, 1, cell, where, sizeof where);
        else snprintf(where, sizeof where, "no points dump");
        printf("DIFF %s seed %llu cell %d: --dump points differs for %s scene at %s\n", name,
               (unsigned long long)seed, cell, iv_name[v], where);
        bad++;
      }
      free(iv);
      free(pv);
    }
    free(i0);
    free(p0);
  }
  x->scenes++;
  if (bad) {
    x->failures++;
    x->kept++;
    printf("     scenes kept: %s/%s-%llu-c%d-{base,shuffled,reversed,mixed}.s74\n", x->dir, name,
           (unsigned long long)seed, cell);
  }
  for (int v = 0; v < IV_NVAR; v++) {
    if (!bad) unlink(scene[v]);
    unlink(ids[v]);
    unlink(pts[v]);
    unlink(png[v]);
    unlink(log[v]);
  }
  sg_free(&s);
  return bad;
}

static void run_family(void **state, sg_family fam)
{
  iv_state *x = *state;
  long problems = 0;
  for (int cell = 3; cell <= 4; cell++)
    for (int k = 1; k <= x->seeds; k++)
      problems += check_scene(x, fam, (uint64_t)k + 500000u + (cell == 4 ? 100000u : 0u), cell);
  printf("%-9s %d scenes x %d writings, %ld problems\n", sg_family_name(fam), 2 * x->seeds,
         IV_NVAR, problems);
  assert_int_equal(problems, 0);
}

static void test_boxes(void **state) { run_family(state, SG_BOXES); }
static void test_triangles(void **state) { run_family(state, SG_TRIANGLES); }
static void test_combs(void **state) { run_family(state, SG_COMBS); }
static void test_stars(void **state) { run_family(state, SG_STARS); }
static void test_plates(void **state) { run_family(state, SG_PLATES); }
static void test_pierced(void **state) { run_family(state, SG_PIERCED); }

int main(void)
{
  const char *prog = tr_program();
  if (access(prog, X_OK) != 0) {
    printf("skip: %s is not executable (set TUBE74 or build ./tube74)\n", prog);
    return 77;
  }
  setvbuf(stdout, NULL, _IOLBF, 0);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_boxes),  cmocka_unit_test(test_triangles),
      cmocka_unit_test(test_combs),  cmocka_unit_test(test_stars),
      cmocka_unit_test(test_plates), cmocka_unit_test(test_pierced),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
