/*
** test_reference.c — checks the checker: the OSMesa reference and the scene generators.
**
** This file contains the self-tests of tests/ref/: before the reference may judge
** ./tube74 (test_crosscheck.c), it must get hand-made scenes with known answers right:
**   - a square in front of a larger one (ids at chosen points, 16-bit ids);
**   - a concave L (GLU tessellation): the notch shows what is behind;
**   - a plate with a hole, in both hole orientations: the wall shows through the hole;
**   - two interpenetrating quads: the visible face switches exactly at the intersection
**     line, checked against the analytic answer at every point;
**   - every face number 1..65535 survives the RGB encoding;
** and on generated scenes it must agree with an independent double-precision ray caster
** (written here, sharing nothing with GL) under the cross-check's own 3 x 3 rule, both
** ways — so depth-precision fights away from boundaries would show up here first.
** The generators are checked for determinism, for validity (sg_validate), and the .s74
** writer's variants (shuffled, reversed, rotated) are read back by a small parser here
** and must render exactly like the original.
** The speed bench's warm peer (warmpeer.h) is checked here too: its ids mode and its
** Phong-shaded mode give the same ids point for point, and the shaded greys follow
** tube74's lighting law worked out here by rays in doubles (within one grey), with
** interpolated normals on a sphere-like mesh (not the flat grey).
** Runs without ./tube74.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>

#include "tests/ref/osmesa_ref.h"
#include "tests/ref/scenegen.h"
#include "tests/ref/warmpeer.h"

/* Generated scenes per family and cell size in the ray-cast comparison. */
#ifndef RT_SEEDS
#define RT_SEEDS 8
#endif

typedef struct fixture {
  ref_renderer *r;
} fixture;

static int group_setup(void **state)
{
  char err[256];
  fixture *fx = calloc(1, sizeof *fx);
  if (!fx) return -1;
  fx->r = ref_open(err, sizeof err);
  if (!fx->r) {
    fprintf(stderr, "reference: %s\n", err);
    free(fx);
    return -1;
  }
  *state = fx;
  return 0;
}

static int group_teardown(void **state)
{
  fixture *fx = *state;
  if (fx) {
    ref_close(fx->r);
    free(fx);
  }
  return 0;
}

/* --- helpers ------------------------------------------------------------------------ */

static void view(ref_scene *s, long x0, long y0, long z0, long xl, long yb, long xr, long yt)
{
  s->x0 = x0, s->y0 = y0, s->z0 = z0;
  s->xl = xl, s->yb = yb, s->xr = xr, s->yt = yt;
}

/* Add a one-ring face from n (x, y, z) triples. */
static void poly(ref_scene *s, unsigned id, int n, const long (*p)[3])
{
  int vi[64];
  assert_true(n <= 64);
  for (int k = 0; k < n; k++) {
    vi[k] = sg_add_vertex(s, (unsigned)s->nv + 1, p[k][0], p[k][1], p[k][2]);
    assert_true(vi[k] >= 0);
  }
  assert_true(sg_add_face(s, id, 128, 1, &n, vi) >= 0);
}

/* Axis-aligned rectangle on the plane z = const. */
static void rect(ref_scene *s, unsigned id, long x0, long y0, long x1, long y1, long z)
{
  const long p[4][3] = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  poly(s, id, 4, p);
}

/* Point (i, j) whose centre is nearest to the plane point (px, py). */
static void point_at(const ref_scene *s, int cell, double px, double py, int *i, int *j)
{
  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  *i = (int)floor((px - (double)s->xl) * w / (double)(s->xr - s->xl));
  *j = (int)floor(((double)s->yt - py) * h / (double)(s->yt - s->yb));
  assert_true(*i >= 0 && *i < w && *j >= 0 && *j < h);
}

/* Centre of point (i, j) on the plane z = 0 (CONTRACT.md). */
static void centre(const ref_scene *s, int cell, int i, int j, double *px, double *py)
{
  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  *px = (double)s->xl + (i + 0.5) * (double)(s->xr - s->xl) / w;
  *py = (double)s->yt - (j + 0.5) * (double)(s->yt - s->yb) / h;
}

static uint16_t *render(fixture *fx, const ref_scene *s, int cell)
{
  char err[256] = "";
  uint16_t *ids = malloc((size_t)ref_grid_w(cell) * (size_t)ref_grid_h(cell) * sizeof *ids);
  assert_non_null(ids);
  if (ref_render_ids(fx->r, s, cell, ids, err, sizeof err) != 0) fail_msg("reference: %s", err);
  return ids;
}

static unsigned id_at(const ref_scene *s, const uint16_t *ids, int cell, double px, double py)
{
  int i, j;
  point_at(s, cell, px, py, &i, &j);
  return ids[(size_t)j * (size_t)ref_grid_w(cell) + (size_t)i];
}

/* --- hand-made cases ------------------------------------------------------------------ */

static void test_square_in_front(void **state)
{
  for (int cell = 3; cell <= 4; cell++) {
    ref_scene s = {0};
    view(&s, 0, 0, -1000, -400, -300, 400, 300);
    rect(&s, 258, -100, -100, 100, 100, 0);     /* front, on the plane: 0x0102 */
    rect(&s, 65535, -450, -450, 450, 450, 500); /* behind: projects to +-300 */
    uint16_t *ids = render(*state, &s, cell);
    assert_int_equal(id_at(&s, ids, cell, 0, 0), 258);
    assert_int_equal(id_at(&s, ids, cell, 90, -90), 258);
    assert_int_equal(id_at(&s, ids, cell, 150, 0), 65535);
    assert_int_equal(id_at(&s, ids, cell, -250, 250), 65535);
    assert_int_equal(id_at(&s, ids, cell, 350, 0), 0);
    assert_int_equal(id_at(&s, ids, cell, -390, 290), 0);
    /* the same with the faces listed the other way round */
    ref_face t = s.f[0];
    s.f[0] = s.f[1];
    s.f[1] = t;
    uint16_t *ids2 = render(*state, &s, cell);
    assert_memory_equal(ids, ids2, (size_t)ref_grid_w(cell) * (size_t)ref_grid_h(cell) * 2);
    free(ids);
    free(ids2);
    sg_free(&s);
  }
}

static void test_concave_L(void **state)
{
  for (int cell = 3; cell <= 4; cell++) {
    ref_scene s = {0};
    view(&s, 0, 0, -1000, -400, -300, 400, 300);
    /* L in the plane z = 0: arms along +x and +y from (-200, -200), notch top-right */
    const long L[6][3] = {{-200, -200, 0}, {200, -200, 0}, {200, -100, 0},
                          {-100, -100, 0}, {-100, 200, 0}, {-200, 200, 0}};
    poly(&s, 5, 6, L);
    rect(&s, 9, -375, -270, 375, 270, 500); /* wall behind: projects to +-250, +-180 */
    uint16_t *ids = render(*state, &s, cell);
    assert_int_equal(id_at(&s, ids, cell, -150, 150), 5);  /* upper arm */
    assert_int_equal(id_at(&s, ids, cell, 150, -150), 5);  /* right arm */
    assert_int_equal(id_at(&s, ids, cell, -150, -150), 5); /* corner */
    assert_int_equal(id_at(&s, ids, cell, 100, 100), 9);   /* notch: wall shows */
    assert_int_equal(id_at(&s, ids, cell, 0, 0), 9);
    assert_int_equal(id_at(&s, ids, cell, 270, 0), 0);     /* beside the wall (+-250) */
    free(ids);
    sg_free(&s);
  }
}

static void test_plate_with_hole(void **state)
{
  for (int cell = 3; cell <= 4; cell++)
    for (int flip = 0; flip < 2; flip++) {
      ref_scene s = {0};
      view(&s, 0, 0, -1000, -400, -300, 400, 300);
      const long P[8][3] = {{-300, -250, 0}, {300, -250, 0}, {300, 250, 0}, {-300, 250, 0},
                            {-100, -100, 0}, {100, -100, 0}, {100, 100, 0}, {-100, 100, 0}};
      int vi[8];
      for (int k = 0; k < 8; k++) vi[k] = sg_add_vertex(&s, (unsigned)k + 1, P[k][0], P[k][1], P[k][2]);
      if (flip) { /* hole in the opposite orientation */
        int t = vi[5];
        vi[5] = vi[7];
        vi[7] = t;
      }
      const int len[2] = {4, 4};
      assert_true(sg_add_face(&s, 300, 200, 2, len, vi) >= 0);
      rect(&s, 301, -600, -600, 600, 600, 1000); /* wall: projects to +-300 */
      char err[200];
      if (sg_validate(&s, err, sizeof err)) fail_msg("%s", err);
      uint16_t *ids = render(*state, &s, cell);
      assert_int_equal(id_at(&s, ids, cell, 0, 0), 301);      /* through the hole */
      assert_int_equal(id_at(&s, ids, cell, 80, -80), 301);
      assert_int_equal(id_at(&s, ids, cell, 200, 200), 300);  /* on the plate */
      assert_int_equal(id_at(&s, ids, cell, 0, -170), 300);
      assert_int_equal(id_at(&s, ids, cell, 0, 280), 301);    /* above the plate */
      free(ids);
      sg_free(&s);
    }
}

static void test_interpenetrating(void **state)
{
  for (int cell = 3; cell <= 4; cell++) {
    ref_scene s = {0};
    view(&s, 0, 0, -1000, -400, -300, 400, 300);
    rect(&s, 1, -600, -450, 600, 450, 500); /* A: z = 500 */
    /* B: the plane z = 500 + x, through A along x = 0 */
    const long B[4][3] = {{-300, -300, 200}, {300, -300, 800}, {300, 300, 800}, {-300, 300, 200}};
    poly(&s, 2, 4, B);
    uint16_t *ids = render(*state, &s, cell);
    const int w = ref_grid_w(cell), h = ref_grid_h(cell);
    long checked = 0;
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        double px, py;
        centre(&s, cell, i, j, &px, &py);
        /* A: z = 500 -> world (1.5 px, 1.5 py). B: x = 1500 px / (1000 - px). */
        const double xb = 1500 * px / (1000 - px), zb = 500 + xb, yb = py * (zb + 1000) / 1000;
        const double ax = 1.5 * px, ay = 1.5 * py;
        const int in_a = fabs(ax) < 600 - 20 && fabs(ay) < 450 - 20;
        const int in_b = fabs(xb) < 300 - 20 && fabs(yb) < 300 - 20;
        const int out_a = fabs(ax) > 600 + 20 || fabs(ay) > 450 + 20;
        const int out_b = fabs(xb) > 300 + 20 || fabs(yb) > 300 + 20;
        unsigned want;
        if (in_b && (in_a || out_a)) want = (!in_a || px < 0) ? 2 : 1;
        else if (out_b && in_a) want = 1;
        else if (out_a && out_b) want = 0;
        else continue; /* near an edge */
        if (fabs(px) < 1e-9) continue;
        assert_int_equal(ids[(size_t)j * (size_t)w + (size_t)i], want);
        checked++;
      }
    assert_true(checked > w * h / 2);
    /* the switch is between the last centre left of x = 0 and the first right of it
       (for odd w the middle centre lies exactly on x = 0: skipped) */
    const int jm = h / 2, il = (w - 1) / 2 - (w & 1), ir = w / 2 + (w & 1);
    double pl, pr, py;
    centre(&s, cell, il, jm, &pl, &py);
    centre(&s, cell, ir, jm, &pr, &py);
    assert_true(pl < 0 && pr > 0 && ir - il == 1 + (w & 1));
    assert_int_equal(ids[(size_t)jm * (size_t)w + (size_t)il], 2);
    assert_int_equal(ids[(size_t)jm * (size_t)w + (size_t)ir], 1);
    free(ids);
    sg_free(&s);
  }
}

/* Every face number 1..65535 comes back from the colour encoding: tile the window with
   one small square per point, 9 frames. */
static void test_id_encoding(void **state)
{
  const int cell = 4, w = ref_grid_w(cell), h = ref_grid_h(cell);
  for (long base = 1; base <= 65535; base += (long)w * h) {
    ref_scene s = {0};
    view(&s, 0, 0, -1000, -400, -300, 400, 300);
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        const long id = base + (long)j * w + i;
        if (id > 65535) continue;
        const long x0 = -400 + 8L * i, y1 = 300 - 8L * j;
        rect(&s, (unsigned)id, x0 + 2, y1 - 6, x0 + 6, y1 - 2, 0);
      }
    uint16_t *ids = render(*state, &s, cell);
    for (int j = 0; j < h; j++)
      for (int i = 0; i < w; i++) {
        long id = base + (long)j * w + i;
        if (id > 65535) id = 0;
        assert_int_equal(ids[(size_t)j * (size_t)w + (size_t)i], id);
      }
    free(ids);
    sg_free(&s);
  }
}

/* --- an independent ray caster ---------------------------------------------------------- */

typedef struct rc_face {
  double n[3], d;   /* plane n.X = d */
  int ax, ay;       /* the two kept coordinates */
  double *p;        /* 2-D ring points back to back */
  int nring;
  const int *ring_len;
  unsigned id;
} rc_face;

static void raycast_ids(const ref_scene *s, int cell, uint16_t *ids)
{
  rc_face *rf = calloc((size_t)s->nf + 1, sizeof *rf);
  assert_non_null(rf);
  for (int k = 0; k < s->nf; k++) {
    const ref_face *f = &s->f[k];
    rc_face *q = &rf[k];
    int total = 0;
    for (int r = 0; r < f->nring; r++) total += f->ring_len[r];
    double n[3] = {0, 0, 0};
    for (int m = 0; m < f->ring_len[0]; m++) {
      const ref_vertex *a = &s->v[f->vi[m]], *b = &s->v[f->vi[(m + 1) % f->ring_len[0]]];
      n[0] += (double)(a->y - b->y) * (double)(a->z + b->z);
      n[1] += (double)(a->z - b->z) * (double)(a->x + b->x);
      n[2] += (double)(a->x - b->x) * (double)(a->y + b->y);
    }
    const ref_vertex *v0 = &s->v[f->vi[0]];
    memcpy(q->n, n, sizeof n);
    q->d = n[0] * (double)v0->x + n[1] * (double)v0->y + n[2] * (double)v0->z;
    const int drop = (fabs(n[0]) >= fabs(n[1]) && fabs(n[0]) >= fabs(n[2])) ? 0
                     : fabs(n[1]) >= fabs(n[2])                             ? 1
                                                                            : 2;
    q->ax = drop == 0 ? 1 : 0;
    q->ay = drop == 2 ? 1 : 2;
    q->p = malloc((size_t)total * 2 * sizeof *q->p);
    assert_non_null(q->p);
    for (int m = 0; m < total; m++) {
      const ref_vertex *v = &s->v[f->vi[m]];
      const double c[3] = {(double)v->x, (double)v->y, (double)v->z};
      q->p[2 * m] = c[q->ax];
      q->p[2 * m + 1] = c[q->ay];
    }
    q->nring = f->nring;
    q->ring_len = f->ring_len;
    q->id = f->id;
  }
  const int w = ref_grid_w(cell), h = ref_grid_h(cell);
  const double E[3] = {(double)s->x0, (double)s->y0, (double)s->z0};
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double px, py;
      centre(s, cell, i, j, &px, &py);
      const double D[3] = {px - E[0], py - E[1], -E[2]};
      double best = INFINITY;
      unsigned bid = 0;
      for (int k = 0; k < s->nf; k++) {
        const rc_face *q = &rf[k];
        const double nd = q->n[0] * D[0] + q->n[1] * D[1] + q->n[2] * D[2];
        if (nd == 0) continue;
        const double t = (q->d - (q->n[0] * E[0] + q->n[1] * E[1] + q->n[2] * E[2])) / nd;
        if (!(t > 0) || t >= best) continue;
        const double H[3] = {E[0] + t * D[0], E[1] + t * D[1], E[2] + t * D[2]};
        const double hx = H[q->ax], hy = H[q->ay];
        int in = 0, at = 0;
        for (int r = 0; r < q->nring; r++) {
          const int m = q->ring_len[r];
          for (int e = 0; e < m; e++) {
            const double *a = &q->p[2 * (at + e)], *b = &q->p[2 * (at + (e + 1) % m)];
            if ((a[1] > hy) != (b[1] > hy)) {
              const double x = a[0] + (hy - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
              if (x > hx) in = !in;
            }
          }
          at += m;
        }
        if (in) best = t, bid = q->id;
      }
      ids[(size_t)j * (size_t)w + (size_t)i] = (uint16_t)bid;
    }
  for (int k = 0; k < s->nf; k++) free(rf[k].p);
  free(rf);
}

/* GL against the ray caster on generated scenes, with the cross-check's 3 x 3 rule both
   ways: where either side's neighbourhood is uniform, the other must show that face. */
static void test_generated_vs_raycast(void **state)
{
  long compared = 0, bad = 0, scenes = 0, near = 0;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (int cell = 3; cell <= 4; cell++)
      for (uint64_t seed = 1; seed <= RT_SEEDS; seed++) {
        ref_scene s = {0};
        char err[256];
        if (sg_generate((sg_family)fam, seed + 1000 * (uint64_t)cell, &s, err, sizeof err))
          fail_msg("%s", err);
        const int w = ref_grid_w(cell), h = ref_grid_h(cell);
        uint16_t *gl = render(*state, &s, cell);
        uint16_t *rc = malloc((size_t)w * (size_t)h * sizeof *rc);
        unsigned char *edge = malloc((size_t)w * (size_t)h);
        assert_non_null(rc);
        assert_non_null(edge);
        near += ref_edge_points(&s, cell, edge);
        raycast_ids(&s, cell, rc);
        long scene_bad = 0;
        for (int j = 0; j < h; j++)
          for (int i = 0; i < w; i++) {
            const size_t at = (size_t)j * (size_t)w + (size_t)i;
            const long ug = ref_uniform_face(gl, edge, w, h, i, j);
            const long ur = ref_uniform_face(rc, edge, w, h, i, j);
            if (ug >= 0 || ur >= 0) compared++;
            if ((ug >= 0 && rc[at] != ug) || (ur >= 0 && gl[at] != ur)) {
              if (scene_bad++ < 5)
                print_message("  %s seed %llu cell %d point (%d,%d): GL %u, ray cast %u\n",
                              sg_family_name((sg_family)fam),
                              (unsigned long long)(seed + 1000 * (uint64_t)cell), cell, i, j,
                              gl[at], rc[at]);
            }
          }
        bad += scene_bad;
        scenes++;
        free(gl);
        free(rc);
        free(edge);
        sg_free(&s);
      }
  print_message("reference vs ray caster: %ld scenes, %ld points compared, %ld disagree "
                "(%ld points within %.2f of an edge skipped)\n",
                scenes, compared, bad, near, REF_EDGE_MARGIN_PX);
  assert_int_equal(bad, 0);
}

/* --- generators --------------------------------------------------------------------- */

static char *slurp(const char *path, size_t *n)
{
  FILE *fp = fopen(path, "rb");
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  long len = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  char *b = malloc((size_t)len + 1);
  assert_non_null(b);
  assert_int_equal(fread(b, 1, (size_t)len, fp), (size_t)len);
  b[len] = 0;
  fclose(fp);
  *n = (size_t)len;
  return b;
}

/* A minimal reader of what sg_write_s74 writes (view, window, vertex, face [* ...] [grey]). */
static void parse_s74(const char *text, ref_scene *s)
{
  int *index = malloc(65536 * sizeof *index);
  assert_non_null(index);
  for (int k = 0; k < 65536; k++) index[k] = -1;
  const char *line = text;
  while (*line) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    char buf[8192];
    assert_true(n < sizeof buf);
    memcpy(buf, line, n);
    buf[n] = 0;
    line += n + (end ? 1 : 0);
    char *save = NULL, *tok = strtok_r(buf, " \t", &save);
    if (!tok || tok[0] == '#') continue;
    if (!strcmp(tok, "view")) {
      s->x0 = atol(strtok_r(NULL, " ", &save));
      s->y0 = atol(strtok_r(NULL, " ", &save));
      s->z0 = atol(strtok_r(NULL, " ", &save));
    } else if (!strcmp(tok, "window")) {
      s->xl = atol(strtok_r(NULL, " ", &save));
      s->yb = atol(strtok_r(NULL, " ", &save));
      s->xr = atol(strtok_r(NULL, " ", &save));
      s->yt = atol(strtok_r(NULL, " ", &save));
    } else if (!strcmp(tok, "vertex")) {
      long id = atol(strtok_r(NULL, " ", &save));
      long x = atol(strtok_r(NULL, " ", &save));
      long y = atol(strtok_r(NULL, " ", &save));
      long z = atol(strtok_r(NULL, " ", &save));
      assert_true(id >= 1 && id <= 65535 && index[id] < 0);
      index[id] = sg_add_vertex(s, (unsigned)id, x, y, z);
    } else if (!strcmp(tok, "face")) {
      long id = atol(strtok_r(NULL, " ", &save));
      int vi[1024], len[64], nring = 1, total = 0, grey = -1;
      len[0] = 0;
      while ((tok = strtok_r(NULL, " ", &save)) != NULL) {
        if (!strcmp(tok, "grey")) {
          grey = atoi(strtok_r(NULL, " ", &save));
        } else if (!strcmp(tok, "*")) {
          len[nring++] = 0;
        } else {
          long v = atol(tok);
          assert_true(v >= 1 && v <= 65535 && index[v] >= 0 && total < 1024);
          vi[total++] = index[v];
          len[nring - 1]++;
        }
      }
      assert_true(sg_add_face(s, (unsigned)id, grey, nring, len, vi) >= 0);
    } else {
      fail_msg("unexpected statement %s", tok);
    }
  }
  free(index);
}

static void test_generators(void **state)
{
  char dir[] = "/tmp/tube74-reftest-XXXXXX";
  assert_non_null(mkdtemp(dir));
  char a[300], b[300], err[256];
  long faces = 0, holes = 0, verts = 0;
  for (int fam = 0; fam < SG_NFAMILIES; fam++)
    for (uint64_t seed = 1; seed <= 40; seed++) {
      ref_scene s = {0}, t = {0};
      if (sg_generate((sg_family)fam, seed, &s, err, sizeof err)) fail_msg("%s", err);
      if (sg_validate(&s, err, sizeof err)) fail_msg("%s", err);
      assert_true(sg_generate((sg_family)fam, seed, &t, err, sizeof err) == 0);
      snprintf(a, sizeof a, "%s/a.s74", dir);
      snprintf(b, sizeof b, "%s/b.s74", dir);
      assert_int_equal(sg_write_s74(&s, a, "x", NULL, err, sizeof err), 0);
      assert_int_equal(sg_write_s74(&t, b, "x", NULL, err, sizeof err), 0);
      size_t na, nb;
      char *ta = slurp(a, &na), *tb = slurp(b, &nb);
      assert_int_equal(na, nb);
      assert_memory_equal(ta, tb, na); /* deterministic */
      faces += s.nf;
      verts += s.nv;
      for (int k = 0; k < s.nf; k++) holes += s.f[k].nring - 1;

      /* canonical text reads back to the same picture; so do the variants */
      const int cell = 3 + (int)(seed & 1);
      uint16_t *ids0 = render(*state, &s, cell);
      unsigned char *edge = malloc((size_t)ref_grid_w(cell) * (size_t)ref_grid_h(cell));
      assert_non_null(edge);
      ref_edge_points(&s, cell, edge);
      for (int v = 0; v < 4; v++) {
        const sg_variant var = {seed * 7 + (uint64_t)v, v & 1, (v >> 1) & 1, v == 3};
        assert_int_equal(sg_write_s74(&s, b, NULL, &var, err, sizeof err), 0);
        char *tv = slurp(b, &nb);
        ref_scene u = {0};
        parse_s74(tv, &u);
        if (sg_validate(&u, err, sizeof err)) fail_msg("variant %d: %s", v, err);
        uint16_t *ids1 = render(*state, &u, cell);
        /* GL's output may depend on triangulation only at edges: compare with 3x3 rule */
        const int w = ref_grid_w(cell), h = ref_grid_h(cell);
        for (int j = 0; j < h; j++)
          for (int i = 0; i < w; i++) {
            long uf = ref_uniform_face(ids0, edge, w, h, i, j);
            if (uf >= 0 && ids1[(size_t)j * (size_t)w + (size_t)i] != uf)
              fail_msg("%s seed %llu variant %d: (%d,%d) %ld vs %u", sg_family_name((sg_family)fam),
                       (unsigned long long)seed, v, i, j, uf, ids1[(size_t)j * (size_t)w + (size_t)i]);
          }
        free(ids1);
        free(tv);
        sg_free(&u);
      }
      free(ids0);
      free(edge);
      free(ta);
      free(tb);
      sg_free(&s);
      sg_free(&t);
    }
  unlink(a);
  unlink(b);
  rmdir(dir);
  print_message("generators: %d scenes, %ld faces (%ld holes), %ld vertices, all valid\n",
                SG_NFAMILIES * 40, faces, holes, verts);
}

/* --- the warm peer's shaded mode (tests/ref/warmpeer.h, issue 19) --------------------- */

/* The greys of the shaded peer are float GL (varyings interpolated perspective-correct,
   normalised, dotted in float) against the same law in doubles here: they may differ by
   one grey where 207 sum lands within float error of a half. */
#define SHADE_TOL 1

/* The scene's unit normal of the triangle (a, b, c) (scene space, by its winding). */
static void tri_normal(const ref_scene *s, const int *vi, double n[3])
{
  const ref_vertex *a = &s->v[vi[0]], *b = &s->v[vi[1]], *c = &s->v[vi[2]];
  const double u[3] = { (double)(b->x - a->x), (double)(b->y - a->y), (double)(b->z - a->z) };
  const double v[3] = { (double)(c->x - a->x), (double)(c->y - a->y), (double)(c->z - a->z) };
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  const double m = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int d = 0; d < 3; d++) n[d] /= m;
}

/* What the shaded peer must show at point (i, j) of the w x h grid where triangle face k
   is seen, worked out here in scene space: the ray from the eye through the point's
   centre meets the face's plane at X; X's barycentric coordinates weight the corners'
   normals vn (smooth: the mean of the unit normals of the triangles at each vertex; flat:
   NULL, the face's normal); normalised, turned to the eye's side, Lambert over the lights
   with the ambient floor of render/shade.h. */
static int expected_grey(const ref_scene *s, int k, const double (*vn)[3], int nlight,
                         const ref_light *light, int w, int h, int i, int j)
{
  const ref_face *f = &s->f[k];
  const ref_vertex *V[3] = { &s->v[f->vi[0]], &s->v[f->vi[1]], &s->v[f->vi[2]] };
  double fn[3];
  tri_normal(s, f->vi, fn);
  const double E[3] = { (double)s->x0, (double)s->y0, (double)s->z0 };
  const double P[3] = { (double)s->xl + (i + 0.5) * (double)(s->xr - s->xl) / w,
                        (double)s->yt - (j + 0.5) * (double)(s->yt - s->yb) / h, 0 };
  const double A[3] = { (double)V[0]->x, (double)V[0]->y, (double)V[0]->z };
  double num = 0, den = 0;
  for (int d = 0; d < 3; d++) { num += fn[d] * (A[d] - E[d]); den += fn[d] * (P[d] - E[d]); }
  double X[3];
  for (int d = 0; d < 3; d++) X[d] = E[d] + num / den * (P[d] - E[d]);
  /* barycentric coordinates: the sub-triangles' signed areas along the normal */
  double l[3], n[3] = { 0, 0, 0 };
  for (int c = 0; c < 3; c++) {
    const ref_vertex *a = V[(c + 1) % 3], *b = V[(c + 2) % 3];
    const double u[3] = { (double)a->x - X[0], (double)a->y - X[1], (double)a->z - X[2] };
    const double v[3] = { (double)b->x - X[0], (double)b->y - X[1], (double)b->z - X[2] };
    const double cr[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
    l[c] = cr[0] * fn[0] + cr[1] * fn[1] + cr[2] * fn[2];
  }
  const double sum_l = l[0] + l[1] + l[2];
  for (int c = 0; c < 3; c++)
    for (int d = 0; d < 3; d++) n[d] += l[c] / sum_l * (vn ? vn[f->vi[c]][d] : fn[d]);
  const double m = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double side = fn[0] * (E[0] - A[0]) + fn[1] * (E[1] - A[1]) + fn[2] * (E[2] - A[2]) > 0 ? 1 : -1;
  double sum = 0;
  for (int q = 0; q < nlight; q++) {
    double L[3], lm = 0;
    for (int d = 0; d < 3; d++) { L[d] = light[q].point ? light[q].v[d] - X[d] : light[q].v[d]; lm += L[d] * L[d]; }
    double dot = 0;
    for (int d = 0; d < 3; d++) dot += side * n[d] / m * L[d] / sqrt(lm);
    if (dot > 0) sum += dot;
  }
  const double g = 48 + floor(207 * sum + 0.5);
  return g > 255 ? 255 : (int)g;
}

/* Both modes of the peer on s: the ids must agree point for point; then every point whose
   3 x 3 neighbourhood shows one face (GL's edge rule and the float rays may differ at
   boundaries) must have the expected grey within SHADE_TOL. Returns the points compared;
   *not_flat counts those whose grey is more than SHADE_TOL from the face's flat grey. */
static long check_shaded(const ref_scene *s, const int *object, const double (*vn)[3],
                         int nlight, const ref_light *light, long *not_flat)
{
  const int w = ref_grid_w(3), h = ref_grid_h(3);
  char err[600] = "";
  ref_peer_input in = { s, object, nlight, light, 0, w, h };
  ref_peer *plain = ref_peer_new(&in, err, sizeof err);
  if (!plain) fail_msg("plain peer: %s", err);
  in.shade = 1;
  ref_peer *shaded = ref_peer_new(&in, err, sizeof err);
  if (!shaded) fail_msg("shaded peer: %s", err);
  uint32_t *ids0 = malloc((size_t)w * (size_t)h * sizeof *ids0), *ids1 = malloc((size_t)w * (size_t)h * sizeof *ids1);
  uint8_t *grey = malloc((size_t)w * (size_t)h);
  assert_true(ids0 && ids1 && grey);
  assert_int_equal(ref_peer_frame(plain, ids0, NULL), 0);
  assert_int_equal(ref_peer_frame(shaded, ids1, grey), 0);
  assert_memory_equal(ids0, ids1, (size_t)w * (size_t)h * sizeof *ids0);
  long compared = 0;
  *not_flat = 0;
  for (int j = 1; j < h - 1; j++)
    for (int i = 1; i < w - 1; i++) {
      const uint32_t id = ids1[(size_t)j * (size_t)w + (size_t)i];
      int uniform = id != 0;
      for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++) uniform &= ids1[(size_t)(j + dj) * (size_t)w + (size_t)(i + di)] == id;
      if (!uniform) continue;
      int k = 0;
      while (k < s->nf && s->f[k].id != id) k++;
      assert_true(k < s->nf);
      const int want = expected_grey(s, k, object && object[k] ? vn : NULL, nlight, light, w, h, i, j);
      const int got = grey[(size_t)j * (size_t)w + (size_t)i];
      if (abs(got - want) > SHADE_TOL)
        fail_msg("point (%d, %d) face %u: grey %d, the law gives %d", i, j, id, got, want);
      if (abs(got - expected_grey(s, k, NULL, nlight, light, w, h, i, j)) > SHADE_TOL) (*not_flat)++;
      compared++;
    }
  free(ids0);
  free(ids1);
  free(grey);
  ref_peer_free(plain);
  ref_peer_free(shaded);
  return compared;
}

/* A flat quad (no object: its own normal everywhere), tilted, under a parallel light (one
   grey all over) and under a point light (the grey varies with the light's direction). */
static void test_shaded_peer_quad(void **state)
{
  (void)state;
  ref_scene s = {0};
  view(&s, 0, 0, -1000, -200, -150, 200, 150);
  const long q[4][3] = { { -150, -100, 0 }, { 150, -100, 200 }, { 150, 100, 200 }, { -150, 100, 0 } };
  int vi[4];
  for (int k = 0; k < 4; k++) vi[k] = sg_add_vertex(&s, (unsigned)k + 1, q[k][0], q[k][1], q[k][2]);
  const int len = 4;
  assert_true(sg_add_face(&s, 70000, -1, 1, &len, vi) >= 0);     /* an id above 16 bits */
  const ref_light par = { 0, { -45, 60, -80 } }, pt = { 1, { 300, 200, -300 } };
  long not_flat;
  const long n1 = check_shaded(&s, NULL, NULL, 1, &par, &not_flat);
  assert_true(n1 > 2000);
  assert_int_equal(not_flat, 0);
  /* the point light: against the flat law with the light's direction from the quad's
     centre, most points differ */
  const ref_light far = { 0, { 300 - 0, 200 - 0, -300 - 100 } };
  const long n2 = check_shaded(&s, NULL, NULL, 1, &pt, &not_flat);
  assert_true(n2 == n1);
  long differ = 0;
  {
    const int w = ref_grid_w(3), h = ref_grid_h(3);
    int lo = 255, hi = 0;
    for (int j = 20; j < h - 20; j++)
      for (int i = 20; i < w - 20; i++) {
        const int g = expected_grey(&s, 0, NULL, 1, &pt, w, h, i, j);
        lo = g < lo ? g : lo;
        hi = g > hi ? g : hi;
        differ += abs(g - expected_grey(&s, 0, NULL, 1, &far, w, h, i, j)) > SHADE_TOL;
      }
    assert_true(hi - lo >= 10);
  }
  assert_true(differ > 100);
  print_message("shaded peer, quad: %ld points compared under a parallel light, %ld under a point light\n", n1, n2);
  sg_free(&s);
}

/* A sphere-like mesh: the octahedron split once, its new vertices pushed out onto the
   sphere (rounded to the integer grid), 32 triangles in one object. Smooth: the grey
   varies inside a face and differs from the face's flat grey. */
static void test_shaded_peer_sphere(void **state)
{
  (void)state;
  ref_scene s = {0};
  view(&s, 0, 0, -1000, -200, -150, 200, 150);
  const double C[3] = { 10, -5, 600 }, R = 200;
  double unitv[64][3];
  int nu = 0;
  static const int oct[8][3] = { { 4, 0, 2 }, { 4, 2, 1 }, { 4, 1, 3 }, { 4, 3, 0 },
                                 { 5, 2, 0 }, { 5, 1, 2 }, { 5, 3, 1 }, { 5, 0, 3 } };
  static const double axis[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 },
                                     { 0, 0, -1 }, { 0, 0, 1 } };
  for (int k = 0; k < 6; k++) memcpy(unitv[nu++], axis[k], sizeof axis[k]);
  /* the index of the unit vector (mid of a and b, normalised), added once */
  int face_vi[32][3], nfaces = 0;
  for (int t = 0; t < 8; t++) {
    int m[3];
    for (int e = 0; e < 3; e++) {
      const double *a = unitv[oct[t][e]], *b = unitv[oct[t][(e + 1) % 3]];
      double v[3] = { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
      const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int d = 0; d < 3; d++) v[d] /= n;
      int found = -1;
      for (int u = 0; u < nu; u++)
        if (fabs(unitv[u][0] - v[0]) + fabs(unitv[u][1] - v[1]) + fabs(unitv[u][2] - v[2]) < 1e-9) found = u;
      if (found < 0) { memcpy(unitv[nu], v, sizeof v); found = nu++; }
      m[e] = found;
    }
    const int a = oct[t][0], b = oct[t][1], c = oct[t][2];
    const int sub[4][3] = { { a, m[0], m[2] }, { m[0], b, m[1] }, { m[2], m[1], c }, { m[0], m[1], m[2] } };
    memcpy(face_vi[nfaces], sub[0], sizeof sub);
    nfaces += 4;
  }
  assert_int_equal(nu, 18);
  for (int u = 0; u < nu; u++)
    assert_true(sg_add_vertex(&s, (unsigned)u + 1, lround(C[0] + R * unitv[u][0]), lround(C[1] + R * unitv[u][1]),
                              lround(C[2] + R * unitv[u][2])) == u);
  int object[32];
  const int len = 3;
  for (int k = 0; k < nfaces; k++) {
    assert_true(sg_add_face(&s, (unsigned)k + 1, -1, 1, &len, face_vi[k]) >= 0);
    object[k] = 1;
  }
  /* the vertex normals, worked out here: the mean of the triangles' unit normals */
  double vn[18][3];
  memset(vn, 0, sizeof vn);
  for (int k = 0; k < nfaces; k++) {
    double n[3];
    tri_normal(&s, s.f[k].vi, n);
    for (int c = 0; c < 3; c++)
      for (int d = 0; d < 3; d++) vn[s.f[k].vi[c]][d] += n[d];
  }
  for (int u = 0; u < nu; u++) {
    const double m = sqrt(vn[u][0] * vn[u][0] + vn[u][1] * vn[u][1] + vn[u][2] * vn[u][2]);
    for (int d = 0; d < 3; d++) vn[u][d] /= m;
  }
  const ref_light light[2] = { { 0, { -45, 60, -80 } }, { 1, { -300, -200, 100 } } };
  long not_flat;
  const long n1 = check_shaded(&s, object, (const double (*)[3])vn, 1, light, &not_flat);
  assert_true(n1 > 1500);
  assert_true(not_flat > n1 / 4);          /* smooth, not flat shading */
  long nf2;
  const long n2 = check_shaded(&s, object, (const double (*)[3])vn, 2, light, &nf2);
  assert_true(n2 == n1 && nf2 > n2 / 4);
  print_message("shaded peer, sphere: %ld points compared, %ld of them not the flat grey\n", n1, not_flat);
  sg_free(&s);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_square_in_front),   cmocka_unit_test(test_concave_L),
      cmocka_unit_test(test_plate_with_hole),   cmocka_unit_test(test_interpenetrating),
      cmocka_unit_test(test_id_encoding),       cmocka_unit_test(test_generators),
      cmocka_unit_test(test_generated_vs_raycast),
      cmocka_unit_test(test_shaded_peer_quad),  cmocka_unit_test(test_shaded_peer_sphere),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
