/*
** test_crosscheck.c — ./tube74 against an independent z-buffer reference (OSMesa).
**
** This file contains the outside check of hidden-surface removal: for a few hundred
** generated scenes (tests/ref/scenegen.c: boxes, interpenetrating triangles, combs,
** stars, plates with holes, pierced solids; halftone cells 3 and 4) it writes the scene,
** runs `$TUBE74 render SCENE --cell C --dump ids=IDS.pgm` (no shell), and compares the
** dump with tests/ref/osmesa_ref.c at every perspective-plane point.
**
** The rule (strict, no tolerance): where the reference's point and its 8 neighbours all
** show the same face (0 = nothing), tube74 must show that face there. Points next to a
** change of face are not compared: there GL's rasterisation rule and depth quantisation
** may legitimately differ from tube74's exact integer geometry. Nor are the few points
** whose centre lies within REF_EDGE_MARGIN_PX (0.02 point) of a projected face edge: GL
** snaps vertices to 1/256 pixel, so on a sliver thinner than a point (a star's tip) it
** can miss or hit such a centre while all 8 neighbours agree (osmesa_ref.h). In particular a point
** uniformly covered in the reference must never be 0 in tube74 (counted separately as
** "hole" mismatches: a face dropped or cut away).
**
** Exit 3 (the scene does not fit the default core) is a legal answer, not a visibility
** error: such a scene is rerun with --core 65536 and compared; one that never fits is
** noted and skipped (a family fails if more than 5% of its scenes are skipped so).
**
** A mismatch names the family, seed, cell, point (i, j), expected and got, and keeps the
** scene file (its path is printed) so `tube74 render` can be rerun on it by hand.
** TUBE74_XCHECK_SEEDS (default 25) sets the seeds per family and cell: 6 x 2 x 25 = 300
** scenes. Exit 77 (skip) when $TUBE74 (default ./tube74) is not executable.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "tests/ref/osmesa_ref.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/tuberun.h"

#define XC_DEFAULT_SEEDS 25   /* per family and cell size */
#define XC_TIMEOUT_S 20.0     /* one tube74 run */
#define XC_MAX_TIMEOUTS 3     /* after this many, the remaining scenes are not run */
#define XC_BIG_CORE "65536"   /* --core for a rerun after exit 3 (the default core is too small) */
#define XC_MAX_NO_FIT_PCT 5   /* a family fails if more of its scenes never fit */
#define XC_REPORT_POINTS 8    /* mismatching points listed per scene */

typedef struct xc_state {
  ref_renderer *r;
  char dir[64];               /* scratch folder for scenes and dumps */
  int seeds;
  long scenes, points, face_points, mismatches, holes, failures, kept, timeouts, not_run;
  long edge_points;           /* points skipped: an edge passes within REF_EDGE_MARGIN_PX */
  long core_retries, no_fit;  /* reruns with XC_BIG_CORE after exit 3; still exit 3 */
  long fam_no_fit;            /* no_fit within the current family */
} xc_state;

static int group_setup(void **state)
{
  char err[256];
  xc_state *x = calloc(1, sizeof *x);
  if (!x) return -1;
  x->r = ref_open(err, sizeof err);
  if (!x->r) {
    fprintf(stderr, "reference: %s\n", err);
    free(x);
    return -1;
  }
  snprintf(x->dir, sizeof x->dir, "/tmp/tube74-xcheck-XXXXXX");
  if (!mkdtemp(x->dir)) {
    perror("mkdtemp");
    ref_close(x->r);
    free(x);
    return -1;
  }
  const char *e = getenv("TUBE74_XCHECK_SEEDS");
  x->seeds = (e && atoi(e) > 0) ? atoi(e) : XC_DEFAULT_SEEDS;
  *state = x;
  return 0;
}

static int group_teardown(void **state)
{
  xc_state *x = *state;
  if (!x) return 0;
  printf("crosscheck: %ld scenes, %ld points compared (%ld on faces), %ld mismatching points "
         "(%ld of them empty in tube74), %ld failed runs\n",
         x->scenes, x->points, x->face_points, x->mismatches, x->holes, x->failures);
  printf("crosscheck: %ld points have a projected face edge within %.2f point of their centre "
         "(never compared)\n", x->edge_points, REF_EDGE_MARGIN_PX);
  printf("crosscheck: %ld scenes needed --core %s (exit 3 with the default core), %ld did not "
         "fit even then\n", x->core_retries, XC_BIG_CORE, x->no_fit);
  if (x->not_run)
    printf("crosscheck: %ld scenes not run after %d timeouts\n", x->not_run, XC_MAX_TIMEOUTS);
  if (x->kept) printf("crosscheck: failing scenes kept in %s\n", x->dir);
  else rmdir(x->dir);
  ref_close(x->r);
  free(x);
  return 0;
}

/* One scene: generate, write, run tube74 (while the reference renders), compare.
   Returns the number of problems (mismatching points, or 1 for a failed run). */
static long check_scene(xc_state *x, sg_family fam, uint64_t seed, int cell)
{
  char err[512], scene[160], ids_path[160], png[160], log[160], cells[4], dump[200], note[120];
  const char *name = sg_family_name(fam);
  if (x->timeouts >= XC_MAX_TIMEOUTS) { /* a hanging tube74 must not hang the suite */
    x->not_run++;
    return 1;
  }
  ref_scene s = {0};
  if (sg_generate(fam, seed, &s, err, sizeof err) != 0) fail_msg("generator: %s", err);
  snprintf(scene, sizeof scene, "%s/%s-%llu-c%d.s74", x->dir, name, (unsigned long long)seed, cell);
  snprintf(ids_path, sizeof ids_path, "%s/ids.pgm", x->dir);
  snprintf(png, sizeof png, "%s/out.png", x->dir);
  snprintf(log, sizeof log, "%s/log.txt", x->dir);
  snprintf(note, sizeof note, "crosscheck %s seed %llu cell %d", name, (unsigned long long)seed, cell);
  snprintf(cells, sizeof cells, "%d", cell);
  snprintf(dump, sizeof dump, "ids=%s", ids_path);
  if (sg_write_s74(&s, scene, note, NULL, err, sizeof err) != 0) fail_msg("%s", err);
  unlink(ids_path);
  unlink(png);
  unlink(log);

  char *argv[] = {(char *)tr_program(), "render", scene, "--cell", cells, "--dump", dump,
                  "-o", png, NULL};
  const pid_t pid = tr_spawn(argv, log, err, sizeof err);
  if (pid < 0) fail_msg("%s", err);

  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  uint16_t *want = malloc((size_t)w * (size_t)h * sizeof *want);
  unsigned char *edge = malloc((size_t)w * (size_t)h);
  assert_non_null(want);
  assert_non_null(edge);
  x->edge_points += ref_edge_points(&s, cell, edge);
  if (ref_render_ids(x->r, &s, cell, want, err, sizeof err) != 0) fail_msg("reference: %s", err);

  int sig = 0;
  int rc = tr_wait(pid, XC_TIMEOUT_S, &sig);
  if (rc == 3) { /* exit 3: does not fit the default core (a legal answer): give it more */
    x->core_retries++;
    char *argv2[] = {(char *)tr_program(), "render", scene, "--cell", cells, "--dump", dump,
                     "-o", png, "--core", XC_BIG_CORE, NULL};
    unlink(log);
    const pid_t pid2 = tr_spawn(argv2, log, err, sizeof err);
    if (pid2 < 0) fail_msg("%s", err);
    rc = tr_wait(pid2, XC_TIMEOUT_S, &sig);
    if (rc == 3) {
      printf("NOTE %s seed %llu cell %d: does not fit even --core %s; not compared\n", name,
             (unsigned long long)seed, cell, XC_BIG_CORE);
      tr_print_tail(log, 2, "     | ");
      x->no_fit++;
      x->fam_no_fit++;
      unlink(scene);
      unlink(log);
      free(want);
      free(edge);
      sg_free(&s);
      return 0;
    }
  }
  long bad = 0;
  uint16_t *got = NULL;
  int gw = 0, gh = 0;
  x->scenes++;
  if (rc != 0) {
    char how[80];
    tr_describe(rc, sig, XC_TIMEOUT_S, how, sizeof how);
    printf("FAIL %s seed %llu cell %d: tube74 %s\n", name, (unsigned long long)seed, cell, how);
    tr_print_tail(log, 5, "     | ");
    bad = 1;
  } else if (!(got = tr_read_pgm16(ids_path, &gw, &gh, err, sizeof err))) {
    printf("FAIL %s seed %llu cell %d: ids dump: %s\n", name, (unsigned long long)seed, cell, err);
    bad = 1;
  } else if (gw != w || gh != h) {
    printf("FAIL %s seed %llu cell %d: ids dump is %d x %d, want %d x %d\n", name,
           (unsigned long long)seed, cell, gw, gh, w, h);
    bad = 1;
  }
  if (rc == -2) x->timeouts++;
  if (bad) x->failures++;
  if (got && !bad) {
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        const long u = ref_uniform_face(want, edge, w, h, i, j);
        if (u < 0) continue;
        x->points++;
        if (u > 0) x->face_points++;
        const unsigned g = got[(size_t)j * (size_t)w + (size_t)i];
        if (g == (unsigned)u) continue;
        if (bad < XC_REPORT_POINTS)
          printf("MISMATCH %s seed %llu cell %d point (%d,%d): expected %ld got %u\n", name,
                 (unsigned long long)seed, cell, i, j, u, g);
        bad++;
        x->mismatches++;
        if (g == 0) x->holes++;
      }
    if (bad > XC_REPORT_POINTS) printf("MISMATCH ... %ld points in all\n", bad);
  }
  if (bad) {
    x->kept++;
    printf("     scene kept: %s\n", scene);
    printf("     rerun: %s render %s --cell %d --dump ids=ids.pgm\n", tr_program(), scene, cell);
  } else {
    unlink(scene);
  }
  unlink(ids_path);
  unlink(png);
  unlink(log);
  free(want);
  free(edge);
  free(got);
  sg_free(&s);
  return bad;
}

static double wall_s(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void run_family(void **state, sg_family fam)
{
  xc_state *x = *state;
  long problems = 0, before = x->points;
  const double t0 = wall_s();
  x->fam_no_fit = 0;
  for (int cell = 3; cell <= 4; cell++)
    for (int k = 1; k <= x->seeds; k++)
      problems += check_scene(x, fam, (uint64_t)k + (cell == 4 ? 100000u : 0u), cell);
  printf("%-9s %d scenes, %ld points compared, %ld problems (%.1f s)\n", sg_family_name(fam),
         2 * x->seeds, x->points - before, problems, wall_s() - t0);
  assert_int_equal(problems, 0);
  if (100 * x->fam_no_fit > XC_MAX_NO_FIT_PCT * 2 * x->seeds)
    fail_msg("%ld of %d %s scenes never fit the core: too few compared", x->fam_no_fit,
             2 * x->seeds, sg_family_name(fam));
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
