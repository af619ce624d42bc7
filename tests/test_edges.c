/*
** test_edges.c — enhanced edges (paper 002, effects/edges.c) against what the paper and
** issue 9 ask for, linked against build/libtube74.a (and the CLI for --stats / --dump).
**
** Classification counts (inner / outline / not drawn) on cubes seen corner-on, showing two
** faces and head-on, a hexagonal prism showing its top and three sides, a smooth prism
** and the same prism not smooth; strip widths: the mean number of points per row of a long
** edge against w / sin(theta) at 90, 60, 45, 42 (both passes), 30 (column pass only) and
** 0 degrees (per column), a horizontal edge gone with the column pass off; occlusion: no
** edge point over a nearer face (a box behind a box, stacked boxes, interpenetrating
** faces) and no edge lost where its own face shows; the halo only where a face lies
** outside the outline. Each scene is made here with integer coordinates (rotations by
** the 3-4-5 triangle keep faces exactly planar). Run from the repository root.
*/
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "emu/status.h"
#include "effects/edges.h"
#include "render/effects.h"
#include "effects/fx.h"
#include "render/render.h"
#include "render/scene.h"
#include "tests/ref/testkit.h"

#define GW 100                 /* the grid of a 4x4 cell: 100 x 75 points */
#define GH 75
#define LINE_G 128             /* outline grey the width tests look for */

static char tmpdir[64];

static int group_setup(void **state)
{
  (void)state;
  return tk_mkscratch(tmpdir, sizeof tmpdir, "/tmp/t74edges.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(tmpdir);
}

/* ---- running the renderer and the edges over one scene ---------------------------- */

struct run {
  struct scene *s;
  struct render r;
  int face[GW * GH];
  uint8_t grey[GW * GH];
  uint8_t flat[GW * GH];       /* the greys before the edges */
  struct fx_stats st;
};

static int on_pt(void *ctx, int i, int j, int face)
{
  struct run *u = ctx;
  u->face[j * GW + i] = face;
  u->grey[j * GW + i] = (uint8_t)(face >= 0 ? u->r.map.f[face].grey : 0);
  return T74_OK;
}

static void run_free(struct run *u)
{
  render_free(&u->r);
  scene_free(u->s);
  free(u);
}

static struct run *run_scene(const char *text, const char *fx, unsigned passes)
{
  char path[128];
  snprintf(path, sizeof path, "%s/s.s74", tmpdir);
  FILE *fp = fopen(path, "w");
  assert_non_null(fp);
  fputs(text, fp);
  fclose(fp);
  struct run *u = calloc(1, sizeof *u);
  assert_non_null(u);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct t74_error err = { 0, "" };
  int st = scene_load(path, &so, &u->s, &err);
  if (st) print_message("scene_load: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  struct effects e;
  assert_int_equal(effects_parse(fx, &e, "test", 1, &err), T74_OK);
  struct render_opts ro = { 1u << 20, 0, PRIO_AUTO, NULL, 0, NULL };
  assert_int_equal(render_prepare(&u->r, u->s, &ro, &err), T74_OK);
  struct vis_grid g = { GW, GH, { u->s->window[0], u->s->window[1], u->s->window[2],
                                  u->s->window[3] } };
  assert_int_equal(render_scan(&u->r, &g, on_pt, u, &err), T74_OK);
  memcpy(u->flat, u->grey, sizeof u->grey);
  struct fx_frame f = { GW, GH, 4, u->face, u->grey, NULL, NULL, NULL };
  struct cost c = { { 0 } };
  st = edge_run(&u->r, u->s, &e, &g, &f, passes, &u->st, &c, &err);
  if (st) print_message("edge_run: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  return u;
}

static double stat(const struct run *u, const char *name)
{
  for (int k = 0; k < u->st.n; k++)
    if (!strcmp(u->st.name[k], name)) return u->st.value[k];
  fail_msg("no statistic %s", name);
  return -1;
}

static void expect_counts(const struct run *u, int inner, int outline, int not_drawn)
{
  print_message("inner %g outline %g not drawn %g\n", stat(u, "edges_inner"),
                stat(u, "edges_outline"), stat(u, "edges_not_drawn"));
  assert_int_equal((int)stat(u, "edges_inner"), inner);
  assert_int_equal((int)stat(u, "edges_outline"), outline);
  assert_int_equal((int)stat(u, "edges_not_drawn"), not_drawn);
}

/* ---- scenes ------------------------------------------------------------------------ */

/* A cube of side 2a (object 1 unless obj is 0) turned by Ry (c1, s1)/5 then Rx (c2, s2)/5,
   scaled by 25, centred at (cx, cy, cz). */
static int put_cube(char *b, size_t n, int first_v, int first_f, int obj, int a, int c1,
                    int s1, int c2, int s2, int cx, int cy, int cz, int grey)
{
  static const int corner[8][3] = { {-1,-1,-1}, {1,-1,-1}, {1,1,-1}, {-1,1,-1},
                                    {-1,-1,1}, {1,-1,1}, {1,1,1}, {-1,1,1} };
  static const int quad[6][4] = { {1,2,3,4}, {5,6,7,8}, {1,2,6,5}, {2,3,7,6}, {3,4,8,7},
                                  {4,1,5,8} };
  int w = 0;
  for (int k = 0; k < 8; k++) {
    int x = corner[k][0] * a, y = corner[k][1] * a, z = corner[k][2] * a;
    int x1 = c1 * x + s1 * z, z1 = -s1 * x + c1 * z, y1 = 5 * y;
    int y2 = c2 * y1 - s2 * z1, z2 = s2 * y1 + c2 * z1;
    w += snprintf(b + w, n - (size_t)w, "vertex %d %d %d %d\n", first_v + k, 5 * x1 + cx,
                  y2 + cy, z2 + cz);
  }
  for (int k = 0; k < 6; k++)
    w += snprintf(b + w, n - (size_t)w, "face %d %d %d %d %d grey %d\n", first_f + k,
                  first_v + quad[k][0] - 1, first_v + quad[k][1] - 1, first_v + quad[k][2] - 1,
                  first_v + quad[k][3] - 1, grey + 10 * k);
  if (obj)
    w += snprintf(b + w, n - (size_t)w, "object %d %d %d %d %d %d %d\n", obj, first_f,
                  first_f + 1, first_f + 2, first_f + 3, first_f + 4, first_f + 5);
  return w;
}

static const char *HEAD = "view 0 0 -1000\nwindow -200 -150 200 150\n";

static void cube_counts(int c1, int s1, int c2, int s2, int inner, int outline, int nd)
{
  char b[4096];
  int w = snprintf(b, sizeof b, "%s", HEAD);
  put_cube(b + w, sizeof b - (size_t)w, 1, 1, 1, 4, c1, s1, c2, s2, 0, 0, 600, 100);
  struct run *u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
  expect_counts(u, inner, outline, nd);
  run_free(u);
}

static void test_cube_corner_on(void **state) { (void)state; cube_counts(4, 3, 4, 3, 3, 6, 3); }
static void test_cube_two_faces(void **state) { (void)state; cube_counts(4, 3, 5, 0, 1, 6, 5); }
static void test_cube_head_on(void **state) { (void)state; cube_counts(5, 0, 5, 0, 0, 4, 8); }

/* A cube in no object: every edge is its face's own (a face in no object is its own
   part), so all twelve edges of the six faces are outlines, twice each. */
static void test_cube_no_object(void **state)
{
  (void)state;
  char b[4096];
  int w = snprintf(b, sizeof b, "%s", HEAD);
  put_cube(b + w, sizeof b - (size_t)w, 1, 1, 0, 4, 4, 3, 4, 3, 0, 0, 600, 100);
  struct run *u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
  expect_counts(u, 0, 24, 0);
  run_free(u);
}

/* An n-sided prism around the y axis (radius R, from y = -h to h, centre z = cz), its sides
   in object 1 (smooth when asked), with or without caps in the object. */
static void put_prism(char *b, size_t n, int sides, const int (*xz)[2], int h, int cz,
                      bool smooth, const char *view)
{
  int w = snprintf(b, n, "%swindow -200 -150 200 150\n", view);
  for (int k = 0; k < sides; k++) {
    w += snprintf(b + w, n - (size_t)w, "vertex %d %d %d %d\n", k + 1, xz[k][0], -h, xz[k][1] + cz);
    w += snprintf(b + w, n - (size_t)w, "vertex %d %d %d %d\n", sides + k + 1, xz[k][0], h, xz[k][1] + cz);
  }
  for (int k = 0; k < sides; k++) {
    int k1 = (k + 1) % sides;
    w += snprintf(b + w, n - (size_t)w, "face %d %d %d %d %d grey %d\n", k + 1, k + 1, k1 + 1,
                  sides + k1 + 1, sides + k + 1, 100 + 10 * (k % 10));
  }
  w += snprintf(b + w, n - (size_t)w, "face %d", sides + 1);
  for (int k = 0; k < sides; k++) w += snprintf(b + w, n - (size_t)w, " %d", k + 1);
  w += snprintf(b + w, n - (size_t)w, " grey 90\nface %d", sides + 2);
  for (int k = 0; k < sides; k++) w += snprintf(b + w, n - (size_t)w, " %d", sides + k + 1);
  w += snprintf(b + w, n - (size_t)w, " grey 240\nobject 1");
  for (int k = 0; k < sides + 2; k++) w += snprintf(b + w, n - (size_t)w, " %d", k + 1);
  snprintf(b + w, n - (size_t)w, "%s\n", smooth ? " smooth" : "");
}

static void test_hex_prism(void **state)
{
  (void)state;
  static const int hex[6][2] = { {80, 0}, {40, 80}, {-40, 80}, {-80, 0}, {-40, -80}, {40, -80} };
  char b[4096];
  put_prism(b, sizeof b, 6, hex, 60, 400, false, "view 0 300 -1000\n");
  struct run *u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
  expect_counts(u, 5, 8, 5);
  run_free(u);
}

/* 24 sides, the eye level with the prism's middle (both caps turned away): not smooth,
   the v sides seen give v - 1 inner edges; smooth, none, and the two side silhouettes
   stay outlines, as do the rims of the sides seen. */
static void test_smooth_prism(void **state)
{
  (void)state;
  enum { N = 24 };
  int xz[N][2];
  for (int k = 0; k < N; k++) {
    xz[k][0] = (int)lround(150 * cos(2 * 3.14159265358979323846 * k / N));
    xz[k][1] = (int)lround(150 * sin(2 * 3.14159265358979323846 * k / N));
  }
  /* sides seen from the eye (0, 0, -1000): outward normal . (E - p) > 0, exactly */
  int seen = 0;
  for (int k = 0; k < N; k++) {
    int k1 = (k + 1) % N;
    long nx = xz[k1][1] - xz[k][1], nz = -(xz[k1][0] - xz[k][0]);   /* outward (ccw ring) */
    long ex = 0 - xz[k][0], ez = -1000 - (xz[k][1] + 500);
    if (nx * ex + nz * ez > 0) seen++;
  }
  assert_true(seen > 2 && seen < N);
  char b[8192];
  put_prism(b, sizeof b, N, (const int (*)[2])xz, 80, 500, false, "view 0 0 -1000\n");
  struct run *u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
  expect_counts(u, seen - 1, 2 + 2 * seen, 3 * N - (seen - 1) - (2 + 2 * seen));
  run_free(u);
  put_prism(b, sizeof b, N, (const int (*)[2])xz, 80, 500, true, "view 0 0 -1000\n");
  u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
  expect_counts(u, 0, 2 + 2 * seen, 3 * N - (2 + 2 * seen));
  run_free(u);
}

/* ---- widths ------------------------------------------------------------------------ */

/* One big triangle in the plane z = 0 whose edge c - d .. c + d crosses the window at the
   angle of d; its other two edges stay far outside. The window is 4000 x 3000 world units
   (40 a point), so the offset ox (world units) moves the edge by ox/40 point. Outline
   w = 3 points, grey LINE_G. */
static struct run *long_edge_at(int dx, int dy, int ox, unsigned passes)
{
  char b[1024];
  double L = sqrt((double)dx * dx + (double)dy * dy);
  int sx = (int)lround(dx * 15000.0 / L), sy = (int)lround(dy * 15000.0 / L);
  snprintf(b, sizeof b,
           "view 0 0 -10000\nwindow -2000 -1500 2000 1500\n"
           "vertex 1 %d %d 0\nvertex 2 %d %d 0\nvertex 3 %d %d 0\nface 1 1 2 3 grey 255\n",
           ox - sx, -sy, ox + sx, sy, ox - 3 * sy / 2, 3 * sx / 2);
  char fx[64];
  snprintf(fx, sizeof fx, "edges=on outline=3,%d inner=1,200 halo=0,255", LINE_G);
  return run_scene(b, fx, passes);
}

static struct run *long_edge(int dx, int dy, unsigned passes)
{
  return long_edge_at(dx, dy, 7, passes);
}

/* points of grey LINE_G per row (by_row) or per column, added over the rows (columns)
   whose run does not touch the window's border */
static void add_runs(const struct run *u, bool by_row, long *total, int *lines)
{
  int n = by_row ? GH : GW, m = by_row ? GW : GH;
  for (int a = 0; a < n; a++) {
    int cnt = 0;
    bool edge = false;
    for (int t = 0; t < m; t++) {
      int at = by_row ? a * GW + t : t * GW + a;
      if (u->grey[at] == LINE_G) { cnt++; if (t == 0 || t == m - 1) edge = true; }
    }
    if (cnt && !edge) { *total += cnt; (*lines)++; }
  }
}

/* The mean over 20 offsets of the edge, 1/20 point apart and never where a band's end
   falls exactly on a centre (so that a line whose rows all meet the grid in the same
   phase, as at 45 and 90 degrees, is measured over the phases, not at one): the mean is
   then within 1/20 point of the true l; the test allows 0.07. */
static void width_at(double deg, int dx, int dy, bool by_row)
{
  long total = 0;
  int lines = 0;
  for (int ph = 0; ph < 20; ph++) {
    struct run *u = long_edge_at(dx, dy, 2 * ph + 1, EDGE_PASS_ROW | EDGE_PASS_COL);
    add_runs(u, by_row, &total, &lines);
    run_free(u);
  }
  double mean = lines ? (double)total / lines : 0;
  double theta = atan2((double)dy, (double)dx);
  double want = 3.0 / (by_row ? sin(theta) : cos(theta));
  print_message("%4.0f deg: %.3f points per %s over %d, w/sin = %.3f\n", deg, mean,
                by_row ? "row" : "column", lines, want);
  assert_true(lines >= 20 * 20);
  assert_true(fabs(mean - want) <= 0.07);
}

static void test_width_90(void **state) { (void)state; width_at(90, 0, 1000, true); }
static void test_width_60(void **state) { (void)state; width_at(60, 1000, 1732, true); }
static void test_width_45(void **state) { (void)state; width_at(45, 1000, 1000, true); }
static void test_width_42(void **state) { (void)state; width_at(42, 10000, 9004, true); }
static void test_width_30(void **state) { (void)state; width_at(30, 1000, 577, true); }
static void test_width_0(void **state) { (void)state; width_at(0, 1000, 0, false); }

static int count_grey(const struct run *u, int grey)
{
  int n = 0;
  for (int k = 0; k < GW * GH; k++) n += u->grey[k] == grey;
  return n;
}

/* Which pass draws what: 42 degrees by both, 30 by the column pass alone, 60 by the row
   pass alone; a horizontal edge vanishes with the column pass off. */
static void test_passes(void **state)
{
  (void)state;
  struct { int dx, dy; bool row, col; } c[] = {
    { 10000, 9004, true, true }, { 1000, 577, false, true }, { 1000, 1732, true, false },
    { 1000, 0, false, true }, { 0, 1000, true, false },
  };
  for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
    struct run *r1 = long_edge(c[k].dx, c[k].dy, EDGE_PASS_ROW);
    struct run *r2 = long_edge(c[k].dx, c[k].dy, EDGE_PASS_COL);
    int nr = count_grey(r1, LINE_G), nc = count_grey(r2, LINE_G);
    print_message("(%d, %d): row pass %d points, column pass %d\n", c[k].dx, c[k].dy, nr, nc);
    assert_int_equal(nr > 0, c[k].row);
    assert_int_equal(nc > 0, c[k].col);
    /* both passes: the column pass adds only what the row pass did not draw */
    struct run *r3 = long_edge(c[k].dx, c[k].dy, EDGE_PASS_ROW | EDGE_PASS_COL);
    assert_int_equal((int)stat(r3, "edge_points_row_pass"), nr);
    assert_true(count_grey(r3, LINE_G) <= nr + nc);
    assert_true(count_grey(r3, LINE_G) >= (nr > nc ? nr : nc));
    run_free(r1); run_free(r2); run_free(r3);
  }
}

/* ---- occlusion --------------------------------------------------------------------- */

static bool is_line(const struct run *u, int k) { return u->grey[k] != u->flat[k]; }

/* Object of the face seen at point k (0: background or no object). */
static int obj_at(const struct run *u, int k)
{
  int f = u->face[k];
  return f < 0 ? 0 : u->s->f[u->r.map.f[f].sface].object;
}

/* Objects 1 and 2 rendered together and each alone: where object `front` is seen, every
   edge point comes from its own edges (as when alone); where object `back` is seen and
   its own edges are drawn when alone, they are drawn together too (inner and outline). */
static void occlusion_fx(const char *both, const char *front_only, const char *back_only,
                         int front, int back, const char *fx)
{
  struct run *ub = run_scene(both, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  struct run *uf = run_scene(front_only, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  struct run *uk = run_scene(back_only, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  int over_front = 0, lost = 0, seen_front = 0, kept_back = 0;
  for (int k = 0; k < GW * GH; k++) {
    if (obj_at(ub, k) == front) {
      seen_front++;
      if (is_line(ub, k) && !is_line(uf, k)) over_front++;
    }
    if (obj_at(ub, k) == back && obj_at(uk, k) == back && is_line(uk, k)) {
      if (is_line(ub, k)) kept_back++; else lost++;
    }
  }
  print_message("front seen at %d points, foreign edge points on it %d; back edge points "
                "kept %d, lost %d\n", seen_front, over_front, kept_back, lost);
  assert_true(seen_front > 100);
  assert_int_equal(over_front, 0);
  assert_true(kept_back > 20);
  assert_int_equal(lost, 0);
  run_free(ub); run_free(uf); run_free(uk);
}

static void occlusion(const char *both, const char *front_only, const char *back_only,
                      int front, int back)
{
  occlusion_fx(both, front_only, back_only, front, back,
               "edges=on outline=1.5,40 inner=1.5,200 halo=0,255");
}

static void test_box_behind_box(void **state)
{
  (void)state;
  char both[8192], a[4096], c[4096];
  int w = snprintf(both, sizeof both, "%s", HEAD);
  w += put_cube(both + w, sizeof both - (size_t)w, 1, 1, 1, 3, 4, 3, 4, 3, -40, -20, 400, 100);
  put_cube(both + w, sizeof both - (size_t)w, 11, 11, 2, 4, 4, -3, 4, 3, 60, 30, 900, 120);
  w = snprintf(a, sizeof a, "%s", HEAD);
  put_cube(a + w, sizeof a - (size_t)w, 1, 1, 1, 3, 4, 3, 4, 3, -40, -20, 400, 100);
  w = snprintf(c, sizeof c, "%s", HEAD);
  put_cube(c + w, sizeof c - (size_t)w, 11, 11, 2, 4, 4, -3, 4, 3, 60, 30, 900, 120);
  occlusion(both, a, c, 1, 2);
}

/* a small box standing on a big one, seen from above: the big box's far edges go behind
   the small box */
static void test_stacked_boxes(void **state)
{
  (void)state;
  static const char *BOX = "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n"
    "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n"
    "vertex %d %d %d %d\n";
  char lower[2048], upper[2048], both[8192], a[8192], c[8192];
  int v = 1;
  /* lower: x -150..150, y -100..0, z 300..600; upper: x -60..60, y 0..100, z 350..450 */
  int L[6] = { -150, 150, -100, 0, 300, 600 }, U[6] = { -60, 60, 0, 100, 350, 450 };
  int *bx[2] = { L, U };
  char *out[2] = { lower, upper };
  for (int q = 0; q < 2; q++) {
    int *B = bx[q];
    int n = snprintf(out[q], 2048, BOX,
      v, B[0], B[2], B[4], v + 1, B[1], B[2], B[4], v + 2, B[1], B[3], B[4], v + 3, B[0], B[3], B[4],
      v + 4, B[0], B[2], B[5], v + 5, B[1], B[2], B[5], v + 6, B[1], B[3], B[5], v + 7, B[0], B[3], B[5]);
    int f = 1 + 6 * q;
    snprintf(out[q] + n, 2048 - (size_t)n,
             "face %d %d %d %d %d grey 200\nface %d %d %d %d %d grey 210\n"
             "face %d %d %d %d %d grey 150\nface %d %d %d %d %d grey 160\n"
             "face %d %d %d %d %d grey 250\nface %d %d %d %d %d grey 170\n"
             "object %d %d %d %d %d %d %d\n",
             f, v, v + 1, v + 2, v + 3, f + 1, v + 4, v + 5, v + 6, v + 7,
             f + 2, v, v + 1, v + 5, v + 4, f + 3, v + 1, v + 2, v + 6, v + 5,
             f + 4, v + 2, v + 3, v + 7, v + 6, f + 5, v + 3, v, v + 4, v + 7,
             q + 1, f, f + 1, f + 2, f + 3, f + 4, f + 5);
    v += 8;
  }
  const char *view = "view 40 300 -900\nwindow -200 -100 200 200\n";
  snprintf(both, sizeof both, "%s%s%s", view, lower, upper);
  snprintf(a, sizeof a, "%s%s", view, upper);
  snprintf(c, sizeof c, "%s%s", view, lower);
  occlusion(both, a, c, 2, 1);
}

/* A floor seen from above (y = 0, z 200..600) and, just in front of its near edge, a box
   (z 190..400, top at y = -5) in a smooth group (its front-top edge is not drawn), so that
   below the floor's edge in the picture the box's top and then its front show. Beyond
   the edge the floor's plane comes towards the eye: held against that plane alone the
   box's front (z = 190) would lie "behind" and the floor's wide outline would show over
   it; the front is nearer than the whole edge (z = 200), so it hides it. */
static void test_face_in_front_of_whole_edge(void **state)
{
  (void)state;
  const char *scene =
    "view 0 300 -1000\nwindow -200 -150 200 150\n"
    "vertex 1 -100 0 200\nvertex 2 100 0 200\nvertex 3 100 0 600\nvertex 4 -100 0 600\n"
    "face 1 1 2 3 4 grey 230\nobject 1 1\n"
    "vertex 11 -150 -100 190\nvertex 12 150 -100 190\nvertex 13 150 -5 190\n"
    "vertex 14 -150 -5 190\nvertex 15 -150 -100 400\nvertex 16 150 -100 400\n"
    "vertex 17 150 -5 400\nvertex 18 -150 -5 400\n"
    "face 11 11 12 13 14 grey 90\nface 12 15 16 17 18 grey 90\n"
    "face 13 14 13 17 18 grey 120\nface 14 11 12 16 15 grey 90\n"
    "face 15 11 14 18 15 grey 90\nface 16 12 13 17 16 grey 90\n"
    "object 2 11 12 13 14 15 16 smooth\n";
  struct run *u = run_scene(scene, "edges=on outline=8,40 inner=1,200 halo=0,255",
                            EDGE_PASS_ROW | EDGE_PASS_COL);
  /* rows 18..34: around the floor's edge (row 24.5), away from the box's own bottom
     outline (row 46) */
  int on_front = 0, on_floor = 0, front_seen = 0;
  for (int j = 18; j <= 34; j++)
    for (int i = 30; i <= 70; i++) {
      int k = j * GW + i;
      int id = u->face[k] >= 0 ? u->r.map.f[u->face[k]].id : 0;
      if (id == 11) front_seen++;
      if (u->grey[k] != 40) continue;
      if (id == 11) on_front++;
      if (id == 1) on_floor++;
    }
  print_message("outline points over the box's front %d (front seen at %d), over the floor "
                "%d\n", on_front, front_seen, on_floor);
  assert_true(front_seen > 100);
  assert_true(on_floor > 20);
  assert_int_equal(on_front, 0);
  run_free(u);
}

/* Fig. 7 (a) of paper 003: two faces cut through each other. Each face's own edges never
   show over the other where it is nearer; the intersection line is drawn (e4, outline:
   the faces are in no object). */
static void test_interpenetrating(void **state)
{
  (void)state;
  const char *F1 = "vertex 1 -150 -100 100\nvertex 2 100 -100 100\nvertex 3 100 100 100\n"
                   "vertex 4 -150 100 100\nface 1 1 2 3 4 grey 240\n";
  const char *F2 = "vertex 5 -100 -130 -100\nvertex 6 150 -130 300\nvertex 7 150 130 300\n"
                   "vertex 8 -100 130 -100\nface 2 5 6 7 8 grey 120\n";
  const char *fx = "edges=on outline=1.5,40 inner=1.5,200 halo=0,255";
  char both[2048], a[1024], b[1024];
  snprintf(both, sizeof both, "%s%s%s", HEAD, F1, F2);
  snprintf(a, sizeof a, "%s%s", HEAD, F1);
  snprintf(b, sizeof b, "%s%s", HEAD, F2);
  struct run *ub = run_scene(both, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  struct run *u1 = run_scene(a, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  struct run *u2 = run_scene(b, fx, EDGE_PASS_ROW | EDGE_PASS_COL);
  assert_int_equal((int)stat(ub, "edges_intersection"), 1);
  assert_int_equal((int)stat(ub, "edges_intersection_outline"), 1);
  /* The line is at x = 22.73 (column 55.2 of the grid): to its left face 2 is in front,
     to its right face 1. Where a face is in front, the edge points over it are its own
     (as when rendered alone); where it shows its own edges, they stay. */
  int foreign = 0, lost = 0, on_line = 0, kept = 0;
  for (int j = 0; j < GH; j++)
    for (int i = 0; i < GW; i++) {
      int k = j * GW + i;
      int id = ub->face[k] >= 0 ? ub->r.map.f[ub->face[k]].id : 0;
      if (i == 55 && id && is_line(ub, k)) on_line++;
      if (i >= 54 && i <= 56) continue;
      const struct run *front = i < 54 ? u2 : u1;
      int fid = i < 54 ? 2 : 1;
      if (id == fid && is_line(ub, k) && !is_line(front, k)) foreign++;
      const struct run *own = id == 1 ? u1 : u2;
      if (id && own->face[k] >= 0 && is_line(own, k)) { if (is_line(ub, k)) kept++; else lost++; }
    }
  print_message("intersection line points %d, foreign edge points %d, own kept %d, lost %d\n",
                on_line, foreign, kept, lost);
  assert_int_equal(foreign, 0);
  assert_int_equal(lost, 0);
  assert_true(kept > 100);
  assert_true(on_line >= 40);
  run_free(ub); run_free(u1); run_free(u2);
}

/* e4 within one object is inner, between objects (or faces in no object) outline. */
static void test_intersection_classes(void **state)
{
  (void)state;
  const char *plates = "vertex 1 -100 -80 200\nvertex 2 100 -80 200\nvertex 3 100 80 200\n"
                       "vertex 4 -100 80 200\nface 1 1 2 3 4 grey 200\n"
                       "vertex 5 0 -80 100\nvertex 6 0 -80 300\nvertex 7 0 80 300\n"
                       "vertex 8 0 80 100\nface 2 5 6 7 8 grey 120\n";
  const char *tail[3] = { "object 1 1 2\n", "object 1 1\nobject 2 2\n", "" };
  int inner[3] = { 1, 0, 0 }, outline[3] = { 0, 1, 1 };
  for (int k = 0; k < 3; k++) {
    char b[1024];
    snprintf(b, sizeof b, "view 300 0 -1000\nwindow -200 -150 200 150\n%s%s", plates, tail[k]);
    struct run *u = run_scene(b, "edges=on", EDGE_PASS_ROW | EDGE_PASS_COL);
    assert_int_equal((int)stat(u, "edges_intersection"), 1);
    assert_int_equal((int)stat(u, "edges_intersection_inner"), inner[k]);
    assert_int_equal((int)stat(u, "edges_intersection_outline"), outline[k]);
    /* the line is drawn: points of the inner (or outline) grey along x = 0 */
    int g = inner[k] ? 160 : 0, n = 0;
    for (int j = 0; j < GH; j++)
      for (int i = 0; i < GW; i++) {
        int at = j * GW + i;
        if (u->face[at] >= 0 && u->grey[at] == g && u->flat[at] != g) n++;
      }
    print_message("case %d: %d points of the line's grey\n", k, n);
    assert_true(n >= 20);
    run_free(u);
  }
}

/* Rule 3: a square in front of a big face that covers only the left half of the window;
   the square's halo shows only over the big face, never over the empty background. */
static void test_halo(void **state)
{
  (void)state;
  char b[2048];
  snprintf(b, sizeof b, "%s"
           "vertex 1 -190 -140 200\nvertex 2 0 -140 200\nvertex 3 0 140 200\nvertex 4 -190 140 200\n"
           "face 1 1 2 3 4 grey 100\n"
           "vertex 5 -60 -60 0\nvertex 6 60 -60 0\nvertex 7 60 60 0\nvertex 8 -60 60 0\n"
           "face 2 5 6 7 8 grey 220\n", HEAD);
  struct run *u = run_scene(b, "edges=on outline=1.5,40 inner=1,200 halo=1.5,250",
                            EDGE_PASS_ROW | EDGE_PASS_COL);
  int on_face = 0, on_bg = 0, on_square = 0;
  for (int k = 0; k < GW * GH; k++) {
    if (u->grey[k] != 250) continue;
    int id = u->face[k] >= 0 ? u->r.map.f[u->face[k]].id : 0;
    if (id == 1) on_face++; else if (id == 2) on_square++; else on_bg++;
  }
  print_message("halo points over the face behind %d, over the background %d, over the "
                "square %d\n", on_face, on_bg, on_square);
  assert_true(on_face >= 40);
  assert_int_equal(on_bg, 0);
  assert_int_equal(on_square, 0);
  assert_int_equal((int)stat(u, "edge_points_halo"), on_face);
  run_free(u);
}

/* `object N F1 F2 ... smooth`: the flag is read, the faces are still all listed; `smooth`
   with no face is an error at its line. */
static void test_smooth_parse(void **state)
{
  (void)state;
  char b[4096];
  int w = snprintf(b, sizeof b, "%s", HEAD);
  w += put_cube(b + w, sizeof b - (size_t)w, 1, 1, 0, 4, 4, 3, 4, 3, 0, 0, 600, 100);
  snprintf(b + w, sizeof b - (size_t)w, "object 7 1 2 3 smooth\nobject 8 4 5 6\n");
  char path[128];
  snprintf(path, sizeof path, "%s/s.s74", tmpdir);
  FILE *fp = fopen(path, "w");
  assert_non_null(fp);
  fputs(b, fp);
  fclose(fp);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct scene *s = NULL;
  struct t74_error err = { 0, "" };
  assert_int_equal(scene_load(path, &so, &s, &err), T74_OK);
  assert_int_equal(s->nobj, 2);
  assert_true(s->obj[0].smooth);
  assert_int_equal(s->obj[0].nface, 3);
  assert_false(s->obj[1].smooth);
  assert_int_equal(s->obj[1].nface, 3);
  assert_int_equal(s->f[2].object, 7);
  scene_free(s);
  fp = fopen(path, "w");
  assert_non_null(fp);
  fprintf(fp, "%svertex 1 0 0 0\nvertex 2 9 0 0\nvertex 3 0 9 0\nface 1 1 2 3\n"
          "object 1 smooth\n", HEAD);
  fclose(fp);
  s = NULL;
  assert_int_equal(scene_load(path, &so, &s, &err), T74_EINPUT);
  assert_null(s);
  print_message("%s\n", err.msg);
  assert_non_null(strstr(err.msg, ":7:"));
}

/* ---- the command line: --stats fields and --dump tables -------------------------- */

static void test_cli_stats_and_dump(void **state)
{
  (void)state;
  const char *bin = getenv("TUBE74");
  if (!bin) bin = "./tube74";
  char b[4096], cmd[1024], path[128], json[128], dump[128];
  int w = snprintf(b, sizeof b, "%s", HEAD);
  put_cube(b + w, sizeof b - (size_t)w, 1, 1, 1, 4, 4, 3, 4, 3, 0, 0, 600, 100);
  snprintf(path, sizeof path, "%s/s.s74", tmpdir);
  snprintf(json, sizeof json, "%s/o.json", tmpdir);
  snprintf(dump, sizeof dump, "%s/t.txt", tmpdir);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(b, f);
  fclose(f);
  snprintf(cmd, sizeof cmd, "%s render %s --effects edges=on --stats %s --dump tables=%s",
           bin, path, json, dump);
  assert_int_equal(system(cmd), 0);
  f = fopen(json, "r");
  assert_non_null(f);
  char text[16384];
  size_t n = fread(text, 1, sizeof text - 1, f);
  text[n] = 0;
  fclose(f);
  assert_non_null(strstr(text, "\"edges_not_drawn\": 3,"));
  assert_non_null(strstr(text, "\"edges_outline\": 6,"));
  assert_non_null(strstr(text, "\"edges_inner\": 3,"));
  assert_non_null(strstr(text, "\"edges_intersection\": 0,"));
  assert_non_null(strstr(text, "\"edge_points_row_pass\": "));
  assert_non_null(strstr(text, "\"edge_points_column_pass\": "));
  f = fopen(dump, "r");
  assert_non_null(f);
  int edges = 0;
  char line[512];
  while (fgets(line, sizeof line, f))
    if (!strncmp(line, "  edge ", 7)) {
      edges++;
      assert_true(strstr(line, ": e1 ") || strstr(line, ": e2 ") || strstr(line, ": e3 "));
    }
  fclose(f);
  assert_int_equal(edges, 12);
  /* without edges=on the fields are absent */
  snprintf(cmd, sizeof cmd, "%s render %s --stats %s", bin, path, json);
  assert_int_equal(system(cmd), 0);
  f = fopen(json, "r");
  assert_non_null(f);
  n = fread(text, 1, sizeof text - 1, f);
  text[n] = 0;
  fclose(f);
  assert_null(strstr(text, "edges_outline"));
}

/* The two triangles an import splits a non-planar face into keep its number; the side
   between them is not an edge (tests/data/scene/quads.obj: face 2, vertices 5 and 7). */
static void test_import_split_not_an_edge(void **state)
{
  (void)state;
  const char *bin = getenv("TUBE74");
  if (!bin) bin = "./tube74";
  char cmd[512], dump[128], line[512];
  snprintf(dump, sizeof dump, "%s/t.txt", tmpdir);
  snprintf(cmd, sizeof cmd, "%s render tests/data/scene/quads.obj --effects edges=on "
           "--dump tables=%s 2>/dev/null", bin, dump);
  assert_int_equal(system(cmd), 0);
  FILE *f = fopen(dump, "r");
  assert_non_null(f);
  int not_edge = 0, face2 = 0;
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "  edge ", 7)) continue;
    if (strstr(line, "not an edge")) {
      not_edge++;
      assert_non_null(strstr(line, "edge 5-7 "));
    } else if (strstr(line, " faces 2:")) face2++;
  }
  fclose(f);
  assert_int_equal(not_edge, 1);
  assert_int_equal(face2, 4);            /* the quad's own four sides */
}

/* ---- the outline along the contour curve (contour= with edges=on, paper 004 + 002) ---- */

/* A square turned by the 3-4-5 triangle (corners C[k] = (±u ± v), |u| = |v| = 100) at
   z = 0, where the perspective plane is the scene itself (a point is 4 units), in front
   of a wall at z = 400 that fills the window. The test's own model of what paper 004
   asks: at corner C[k], Q0 = C[k] + t (C[k-1] - C[k]), Q4 = C[k] + t (C[k+1] - C[k]),
   Q1, Q3 by Cc (Def. 8), the quartic Bezier (Def. 9) between; the outline is the curves
   and the sides' straight parts between Q4 of one corner and Q0 of the next. */
static const double SQ[4][2] = { { 140, -20 }, { 20, 140 }, { -140, 20 }, { -20, -140 } };

#define OUT_G 7                /* outline grey, inner grey and halo grey of these tests */
#define INN_G 160
#define HAL_G 250
#define SLACK 0.3              /* points: the curve's 64 chords and the grid's rounding */

struct cpic { unsigned ids[GW * GH]; uint8_t grey[GW * GH]; char json[160]; };

static const char *WALL = "vertex 91 -390 -340 400\nvertex 92 390 -340 400\n"
                          "vertex 93 390 340 400\nvertex 94 -390 340 400\n"
                          "face 90 91 92 93 94 grey 120\n";

/* The square as two triangles (fan 0) or four round its centre (fan 1), object 1. */
static int put_square(char *b, size_t n, int fan)
{
  int w = snprintf(b, n, "view 0 0 -1000\nwindow -200 -150 200 150\nlight 0 0 -1\n");
  for (int k = 0; k < 4; k++)
    w += snprintf(b + w, n - (size_t)w, "vertex %d %d %d 0\n", k + 1, (int)SQ[k][0], (int)SQ[k][1]);
  if (fan)
    w += snprintf(b + w, n - (size_t)w, "vertex 5 0 0 0\nface 1 1 2 5\nface 2 2 3 5\n"
                  "face 3 3 4 5\nface 4 4 1 5\nobject 1 1 2 3 4\n");
  else
    w += snprintf(b + w, n - (size_t)w, "face 1 1 2 3\nface 2 1 3 4\nobject 1 1 2\n");
  return w;
}

static void cli_render(const char *scene, const char *fx, struct cpic *p)
{
  static int runs;                         /* each run its own --stats file */
  char sp[128], ip[128], gp[128], ia[160], ga[160];
  snprintf(sp, sizeof sp, "%s/c.s74", tmpdir);
  snprintf(ip, sizeof ip, "%s/ids.pgm", tmpdir);
  snprintf(gp, sizeof gp, "%s/grey.pgm", tmpdir);
  snprintf(p->json, sizeof p->json, "%s/c%d.json", tmpdir, ++runs);
  snprintf(ia, sizeof ia, "ids=%s", ip);
  snprintf(ga, sizeof ga, "grey=%s", gp);
  assert_int_equal(tk_put(sp, scene, strlen(scene)), 0);
  int rc = tk_runl(NULL, NULL, "render", sp, "--effects", fx, "--dump", ia, "--dump", ga,
                   "--stats", p->json, (char *)NULL);
  if (rc) print_message("render --effects '%s': exit %d\n", fx, rc);
  assert_int_equal(rc, 0);
  size_t n;
  char *b = tk_slurp(ip, &n);
  assert_non_null(b);
  assert_true(n >= 2 * GW * GH);
  const unsigned char *q = (const unsigned char *)b + n - 2 * GW * GH;
  for (int k = 0; k < GW * GH; k++) p->ids[k] = (unsigned)(q[2 * k] << 8 | q[2 * k + 1]);
  free(b);
  b = tk_slurp(gp, &n);
  assert_non_null(b);
  assert_true(n >= GW * GH);
  memcpy(p->grey, b + n - GW * GH, GW * GH);
  free(b);
}

static double cstat(const struct cpic *p, const char *key)
{
  double v = -1;
  if (tk_stat(p->json, key, &v) != 0) fail_msg("no statistic %s", key);
  return v;
}

/* point centre (i, j) in scene units on the plane z = 0 */
static void centre(int i, int j, double c[2])
{
  c[0] = -200 + (i + 0.5) * 4;
  c[1] = 150 - (j + 0.5) * 4;
}

static double seg_dist(const double p[2], const double a[2], const double b[2])
{
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
  t = t < 0 ? 0 : t > 1 ? 1 : t;
  double ex = a[0] + t * dx - p[0], ey = a[1] + t * dy - p[1];
  return sqrt(ex * ex + ey * ey);
}

#define CURVE_N 400

/* corner k's curve (CURVE_N + 1 points from Q0 to Q4) and its region (Q2, the curve) */
static void corner_curve(int k, double t, double cc, double pts[CURVE_N + 1][2])
{
  const double *q2 = SQ[k], *pv = SQ[(k + 3) % 4], *nx = SQ[(k + 1) % 4];
  double Q[5][2];
  for (int c = 0; c < 2; c++) {
    Q[0][c] = q2[c] + t * (pv[c] - q2[c]);
    Q[4][c] = q2[c] + t * (nx[c] - q2[c]);
    Q[2][c] = q2[c];
    Q[1][c] = q2[c] + cc * (Q[0][c] - q2[c]);
    Q[3][c] = q2[c] + cc * (Q[4][c] - q2[c]);
  }
  for (int m = 0; m <= CURVE_N; m++) {
    double s = (double)m / CURVE_N, u = 1 - s;
    double w[5] = { u * u * u * u, 4 * u * u * u * s, 6 * u * u * s * s, 4 * u * s * s * s, s * s * s * s };
    for (int c = 0; c < 2; c++)
      pts[m][c] = w[0] * Q[0][c] + w[1] * Q[1][c] + w[2] * Q[2][c] + w[3] * Q[3][c] + w[4] * Q[4][c];
  }
}

/* even-odd: p inside the polygon pts[0..n) */
static bool inside(const double p[2], const double (*pts)[2], int n)
{
  bool in = false;
  for (int a = 0, b = n - 1; a < n; b = a++)
    if ((pts[a][1] > p[1]) != (pts[b][1] > p[1]) &&
        p[0] < pts[b][0] + (pts[a][0] - pts[b][0]) * (p[1] - pts[b][1]) / (pts[a][1] - pts[b][1]))
      in = !in;
  return in;
}

struct shape {
  double curve[4][CURVE_N + 1][2];
  double region[4][CURVE_N + 2][2];        /* Q2 and the curve: what the cut takes away */
  double side[4][2][2];                     /* the straight part of side k (C[k] -> C[k+1]) */
};

static void shape_make(struct shape *S, double t, double cc)
{
  for (int k = 0; k < 4; k++) {
    corner_curve(k, t, cc, S->curve[k]);
    S->region[k][0][0] = SQ[k][0];
    S->region[k][0][1] = SQ[k][1];
    memcpy(S->region[k] + 1, S->curve[k], sizeof S->curve[k]);
  }
  for (int k = 0; k < 4; k++) {
    const double *a = SQ[k], *b = SQ[(k + 1) % 4];
    for (int c = 0; c < 2; c++) {
      S->side[k][0][c] = a[c] + t * (b[c] - a[c]);
      S->side[k][1][c] = b[c] + t * (a[c] - b[c]);
    }
  }
}

/* distance in points from centre p to the curves (and the straight parts, sides) */
static double shape_dist(const struct shape *S, const double p[2], bool sides)
{
  double d = 1e30;
  for (int k = 0; k < 4; k++) {
    for (int m = 0; m < CURVE_N; m++) d = fmin(d, seg_dist(p, S->curve[k][m], S->curve[k][m + 1]));
    if (sides) d = fmin(d, seg_dist(p, S->side[k][0], S->side[k][1]));
  }
  return d / 4;
}

static int in_region(const struct shape *S, const double p[2])
{
  for (int k = 0; k < 4; k++)
    if (inside(p, (const double (*)[2])S->region[k], CURVE_N + 2)) return k;
  return -1;
}

/* The outline goes along the curve: every outline point lies within w/2 of the curves or
   of the sides' straight parts, none deeper in a cut-away corner, every centre within
   w/2 of them (less the slack) is one, the halo lies outside over the wall; away from
   the corners the picture is the one without contour=; the statistics add up. */
static void test_contour_outline_follows_curve(void **state)
{
  (void)state;
  static struct cpic on, off;
  static struct shape S;
  char b[2048];
  int w = put_square(b, sizeof b, 0);
  snprintf(b + w, sizeof b - (size_t)w, "%s", WALL);
  cli_render(b, "smooth=prop:0.2 contour=1.0 edges=on outline=1.5,7 inner=0.75,160 "
             "halo=0.75,250", &on);
  cli_render(b, "smooth=prop:0.2 edges=on outline=1.5,7 inner=0.75,160 halo=0.75,250", &off);
  shape_make(&S, 0.2, 1.0);
  int outline = 0, deep = 0, deep_out = 0, near = 0, near_miss = 0, halo = 0, corner_old = 0;
  double worst = 0;
  for (int j = 0; j < GH; j++)
    for (int i = 0; i < GW; i++) {
      int at = j * GW + i;
      double p[2];
      centre(i, j, p);
      double d = shape_dist(&S, p, true), dc = shape_dist(&S, p, false);
      int reg = in_region(&S, p);
      if (reg >= 0 && dc > 0.75 + SLACK) {
        deep++;
        if (on.grey[at] == OUT_G) deep_out++;
        if (off.grey[at] == OUT_G) corner_old++;
      }
      if (on.grey[at] == OUT_G) {
        outline++;
        if (d > worst) worst = d;
      }
      if (d < 0.75 - SLACK) { near++; if (on.grey[at] != OUT_G) near_miss++; }
      if (on.grey[at] == HAL_G) {
        halo++;
        /* outside the rounded square (in a cut corner or beyond the sides), over the wall */
        bool out = reg >= 0 || !inside(p, SQ, 4);
        if (!out || on.ids[at] != 90 || d > 0.75 + 0.75 + SLACK)
          print_message("halo point (%d, %d): d %.2f, on face %u, outside %d\n", i, j, d, on.ids[at], out);
        assert_true(out);
        assert_int_equal(on.ids[at], 90);
        assert_true(d <= 1.5 + SLACK);
      }
      /* far from every corner the picture is the one without contour= */
      bool far = true;
      for (int k = 0; k < 4; k++)
        if (hypot(p[0] - SQ[k][0], p[1] - SQ[k][1]) < 0.25 * 200 + 12) far = false;
      if (far && on.grey[at] != off.grey[at])
        print_message("(%d, %d) far from the corners: grey %u with contour, %u without\n", i, j,
                      on.grey[at], off.grey[at]);
      if (far) assert_int_equal(on.grey[at], off.grey[at]);
    }
  print_message("outline points %d (farthest %.2f points from the curves and sides); cut "
                "corners: %d points deeper than w/2, %d of them outline (%d without contour=); "
                "%d centres within w/2 - %.1f, %d not outline; halo %d\n", outline, worst, deep,
                deep_out, corner_old, near, SLACK, near_miss, halo);
  assert_true(outline > 200);
  assert_true(worst <= 0.75 + SLACK);
  assert_true(deep >= 20);
  assert_int_equal(deep_out, 0);
  assert_true(corner_old >= 8);             /* the old outline ran through the corners */
  assert_true(near > 150);
  assert_int_equal(near_miss, 0);
  assert_true(halo > 100);
  /* the statistics: the edges are the same edges, 4 curves of 64 segments, each corner
     ends two sides, nothing else leaves a corner inwards, no side is gone */
  assert_int_equal((int)cstat(&on, "edges_outline"), (int)cstat(&off, "edges_outline"));
  assert_int_equal((int)cstat(&on, "edges_not_drawn"), (int)cstat(&off, "edges_not_drawn"));
  assert_int_equal((int)cstat(&on, "contour_corners_convex"), 4);
  assert_int_equal((int)cstat(&on, "edges_contour_curve_segments"), 4 * 64);
  assert_int_equal((int)cstat(&on, "edges_contour_sides_cut"), 8);
  assert_int_equal((int)cstat(&on, "edges_contour_inner_cut"), 0);
  assert_int_equal((int)cstat(&on, "edges_contour_gone"), 0);
  double v;
  assert_int_equal(tk_stat(off.json, "edges_contour_curve_segments", &v), -1);
}

/* contour= alone rounds with the sides' midpoints (whole smoothing's insets): the four
   sides are cut away whole, the inner edges from the corners to the centre stop at the
   curves; no line of either kind lies deeper in a cut corner. */
static void test_contour_inner_edges_stop_at_curve(void **state)
{
  (void)state;
  static struct cpic on;
  static struct shape S;
  char b[2048];
  int w = put_square(b, sizeof b, 1);
  snprintf(b + w, sizeof b - (size_t)w, "%s", WALL);
  cli_render(b, "contour=1.0 edges=on outline=1.5,7 inner=1,160 halo=0.75,250", &on);
  shape_make(&S, 0.5, 1.0);
  int deep = 0, deep_line = 0, inner = 0, inner_far = 0;
  double worst = 0;
  for (int j = 0; j < GH; j++)
    for (int i = 0; i < GW; i++) {
      int at = j * GW + i;
      double p[2];
      centre(i, j, p);
      double dc = shape_dist(&S, p, false);
      if (in_region(&S, p) >= 0 && dc > 0.75 + SLACK) {
        deep++;
        if (on.grey[at] == OUT_G || on.grey[at] == INN_G) deep_line++;
      }
      if (on.grey[at] == OUT_G && dc > worst) worst = dc;
      if (on.grey[at] == INN_G) {
        inner++;
        /* on a diagonal, from the centre out to the curve */
        double d = fmin(seg_dist(p, SQ[0], SQ[2]), seg_dist(p, SQ[1], SQ[3])) / 4;
        if (d > 0.5 + SLACK) inner_far++;
      }
    }
  print_message("cut corners: %d points deeper than w/2, %d on a line; outline at most %.2f "
                "points from the curves; %d inner points, %d off the diagonals\n", deep,
                deep_line, worst, inner, inner_far);
  assert_true(deep >= 40);
  assert_int_equal(deep_line, 0);
  assert_true(worst <= 0.75 + SLACK);
  assert_true(inner > 60);
  assert_int_equal(inner_far, 0);
  assert_int_equal((int)cstat(&on, "edges_contour_curve_segments"), 4 * 64);
  assert_int_equal((int)cstat(&on, "edges_contour_sides_cut"), 8);
  assert_int_equal((int)cstat(&on, "edges_contour_inner_cut"), 4);
  assert_int_equal((int)cstat(&on, "edges_contour_gone"), 4);
  assert_int_equal((int)cstat(&on, "edges_inner"), 4);
}

/* The curve is an outline like any other: a face in front of a corner hides it. */
static void test_contour_outline_hidden(void **state)
{
  (void)state;
  static struct cpic open, hid;
  char b[2048];
  int w = put_square(b, sizeof b, 0);
  w += snprintf(b + w, sizeof b - (size_t)w, "%s", WALL);
  const char *fx = "smooth=prop:0.2 contour=1.0 edges=on outline=1.5,7 inner=0.75,160 halo=0,250";
  cli_render(b, fx, &open);
  /* a card at z = -300 (seen 1/0.7 times larger) over the corner (20, 140) */
  snprintf(b + w, sizeof b - (size_t)w, "vertex 81 -21 63 -300\nvertex 82 35 63 -300\n"
           "vertex 83 35 98 -300\nvertex 84 -21 98 -300\nface 80 81 82 83 84 grey 200\n");
  cli_render(b, fx, &hid);
  int under = 0, before = 0, after = 0;
  for (int j = 2; j < GH - 2; j++)
    for (int i = 2; i < GW - 2; i++) {
      bool card = true;                    /* the card all round: not its own outline */
      for (int dj = -2; dj <= 2; dj++)
        for (int di = -2; di <= 2; di++) card = card && hid.ids[(j + dj) * GW + i + di] == 80;
      if (!card) continue;
      under++;
      before += open.grey[j * GW + i] == OUT_G;
      after += hid.grey[j * GW + i] == OUT_G;
    }
  print_message("%d points inside the card: %d outline points there without it, %d with it\n",
                under, before, after);
  assert_true(under > 50);
  assert_true(before >= 10);
  assert_int_equal(after, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_cube_corner_on),
    cmocka_unit_test(test_cube_two_faces),
    cmocka_unit_test(test_cube_head_on),
    cmocka_unit_test(test_cube_no_object),
    cmocka_unit_test(test_hex_prism),
    cmocka_unit_test(test_smooth_prism),
    cmocka_unit_test(test_width_90),
    cmocka_unit_test(test_width_60),
    cmocka_unit_test(test_width_45),
    cmocka_unit_test(test_width_42),
    cmocka_unit_test(test_width_30),
    cmocka_unit_test(test_width_0),
    cmocka_unit_test(test_passes),
    cmocka_unit_test(test_box_behind_box),
    cmocka_unit_test(test_stacked_boxes),
    cmocka_unit_test(test_face_in_front_of_whole_edge),
    cmocka_unit_test(test_interpenetrating),
    cmocka_unit_test(test_intersection_classes),
    cmocka_unit_test(test_halo),
    cmocka_unit_test(test_smooth_parse),
    cmocka_unit_test(test_cli_stats_and_dump),
    cmocka_unit_test(test_import_split_not_an_edge),
    cmocka_unit_test(test_contour_outline_follows_curve),
    cmocka_unit_test(test_contour_inner_edges_stop_at_curve),
    cmocka_unit_test(test_contour_outline_hidden),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
