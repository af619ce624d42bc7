/*
** soak.c — the differential soak: new hard scenes against the exact reference until the
** time is up (`make soak SOAK_SECONDS=N`), and a checker of single scene files.
**
** This file contains a test program (not part of tube74): it generates scenes with
** tests/ref/hardgen.c from seeds not used by `make test`, renders each through the
** library (tests/ref/xdiff.c) at both cell sizes and with the dense and the sparse
** priority matrix, and judges every point with the exact reference. A scene that is
** refused, or has a point wrong outside the reference's tolerance band, is saved as
** DIR/fail-FAMILY-SEED.s74 (default build/soak) with the finding on stderr.
**
**   soak [--seconds N] [--seed S] [--out DIR]   run new seeds for N seconds (default 60)
**   soak --check FILE.s74 [--cell C]           judge one scene, list its wrong points
**   soak --write FAMILY SEED FILE.s74          write one generated scene
** Exit status: 0 nothing found, 1 failures found, 2 usage.
*/
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "tests/ref/exactref.h"
#include "tests/ref/hardgen.h"
#include "tests/ref/xdiff.h"

static char *slurp(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char *b = malloc(cap);
  while (b) {
    size_t k = fread(b + n, 1, cap - n - 1, f);
    n += k;
    if (k == 0) break;
    if (n + 1 == cap) { char *nb = realloc(b, cap *= 2); if (!nb) { free(b); b = NULL; } else b = nb; }
  }
  fclose(f);
  if (b) b[n] = '\0';
  return b;
}

static int check_file(const char *path, int cell)
{
  char *text = slurp(path), err[256];
  if (!text) { fprintf(stderr, "%s: cannot read\n", path); return 2; }
  struct xr_scene s;
  if (xr_read(text, &s, err, sizeof err) != 0) { fprintf(stderr, "%s: %s\n", path, err); free(text); return 2; }
  free(text);
  int bad = 0;
  for (int c = 3; c <= 4; c++) {
    if (cell && c != cell) continue;
    for (int store = 1; store <= 2; store++) {
      struct xd_result r;
      unsigned *ids = NULL;
      if (xd_check_ids(&s, c, store, &r, &ids) != 0) { fprintf(stderr, "%s\n", r.msg); bad = 1; continue; }
      if (ids && r.wrong && getenv("SOAK_MAP")) {
        struct xr_ref ref;
        if (xr_prepare(&s, c, &ref) == 0) {
          for (int j = 0; j < ref.H; j++) {
            for (int i = 0; i < ref.W; i++) {
              unsigned want, got = ids[j * ref.W + i];
              int v = xr_judge(&ref, i, j, got, &want);
              putchar(v < 0 ? 'a' + (int)(want % 26) : v > 0 ? '~' : got ? '0' + (int)(got % 10) : '.');
            }
            putchar('\n');
          }
          xr_ref_free(&ref);
        }
      }
      free(ids);
      printf("cell %d %s: status %d%s%s, %ld points, %ld in band, %ld wrong, %llu pairs",
             c, store == 1 ? "dense" : "sparse", r.status, r.status ? " " : "", r.msg,
             r.points, r.band, r.wrong, (unsigned long long)r.pairs_computed);
      if (r.wrong) printf(" (first (%d, %d): got %u, want %u)", r.first_i, r.first_j,
                          r.first_got, r.first_want);
      printf("\n");
      bad |= r.status != 0 || r.wrong != 0;
    }
  }
  xr_scene_free(&s);
  return bad;
}

int main(int argc, char **argv)
{
  double seconds = 60;
  uint64_t seed = (uint64_t)time(NULL) * 1000003u;
  const char *out = "build/soak";
  for (int a = 1; a < argc; a++) {
    if (!strcmp(argv[a], "--check") && a + 1 < argc) {
      int cell = 0;
      if (a + 3 < argc && !strcmp(argv[a + 2], "--cell")) cell = atoi(argv[a + 3]);
      return check_file(argv[a + 1], cell);
    }
    if (!strcmp(argv[a], "--write") && a + 3 < argc) {
      int fam = -1;
      for (int k = 0; k < HG_NFAMILIES; k++) if (!strcmp(argv[a + 1], hg_family_name(k))) fam = k;
      if (fam < 0) { fprintf(stderr, "unknown family %s\n", argv[a + 1]); return 2; }
      struct xr_scene s;
      if (hg_generate(fam, strtoull(argv[a + 2], NULL, 10), &s) != 0) return 2;
      int st = xd_save(&s, argv[a + 3]);
      xr_scene_free(&s);
      return st ? 2 : 0;
    }
    if (!strcmp(argv[a], "--seconds") && a + 1 < argc) seconds = atof(argv[++a]);
    else if (!strcmp(argv[a], "--seed") && a + 1 < argc) seed = strtoull(argv[++a], NULL, 10);
    else if (!strcmp(argv[a], "--out") && a + 1 < argc) out = argv[++a];
    else { fprintf(stderr, "usage: soak [--seconds N] [--seed S] [--out DIR] | --check FILE "
                   "[--cell C] | --write FAMILY SEED FILE\n"); return 2; }
  }
  if (mkdir(out, 0777) != 0 && errno != EEXIST) { perror(out); return 2; }
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  long scenes = 0, points = 0, fails = 0;
  for (uint64_t n = 0;; n++) {
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if ((double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec) >= seconds) break;
    int fam = (int)(n % HG_NFAMILIES);
    uint64_t sd = seed + n / HG_NFAMILIES;
    struct xr_scene s;
    if (hg_generate(fam, sd, &s) != 0) continue;
    int cell = (n / HG_NFAMILIES) % 2 ? 3 : 4, store = (n / (2 * HG_NFAMILIES)) % 2 ? 2 : 1;
    struct xd_result r;
    if (xd_check(&s, cell, store, &r) == 0) {
      scenes++;
      points += r.points;
      if (r.status != 0 || r.wrong != 0) {
        char path[4096];
        snprintf(path, sizeof path, "%s/fail-%s-%llu.s74", out, hg_family_name(fam),
                 (unsigned long long)sd);
        if (xd_save(&s, path) != 0) fprintf(stderr, "%s: cannot write\n", path);
        fails++;
        if (r.status) fprintf(stderr, "%s (cell %d): refused: %s\n", path, cell, r.msg);
        else fprintf(stderr, "%s (cell %d, %s): %ld points wrong, first (%d, %d) got %u want %u\n",
                     path, cell, store == 1 ? "dense" : "sparse", r.wrong, r.first_i,
                     r.first_j, r.first_got, r.first_want);
      }
    }
    xr_scene_free(&s);
  }
  printf("soak: %ld scenes, %ld points, %ld failing scenes saved in %s\n", scenes, points,
         fails, out);
  return fails ? 1 : 0;
}
