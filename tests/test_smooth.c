/*
** test_smooth.c — cmocka tests of smooth shading, partial smoothing and contour smoothing
** (paper 004; effects/smooth.h, effects/contour.h).
**
** This file contains two kinds of test. Through the real program ($TUBE74, default
** ./tube74) on the shipped Table 1 scenes and on small scenes written at test time: that
** prop:0 and fixed:0 are the flat picture byte for byte, that the flat share of a
** triangle under prop:c is (1-3c)^2 of its points, that the whole smoothing with a
** contour shades like smooth=phong wherever the contour did not cut, that contour=none
** changes nothing and contour=0 (Table 1 row i) does, that the points cut show the face
** behind, that the region cut matches the closed form, and that a cube given with mixed
** face orientations is drawn as the consistently given one. And on the library: normals
** agree along every shared edge (no seams) and are continuous inside each triangle,
** Lambert per point is the Mapper's formula, and the Bezier of Def. 9 starts at Q0, ends
** at Q4 with tangents along the contour sides, and cuts the closed-form area; and that the
** model built with its scene part kept from an earlier frame is a fresh build's, bit for
** bit, after another scene and after the eye moves round an open surface.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "effects/contour.h"
#include "render/effects.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/shade.h"
#include "effects/smooth.h"
#include "tests/ref/testkit.h"

static char tmpdir[64];
static const char *tube74;

static int group_setup(void **state)
{
  (void)state;
  tube74 = getenv("TUBE74");
  if (!tube74 || !*tube74) tube74 = "./tube74";
  return tk_mkscratch(tmpdir, sizeof tmpdir, "/tmp/t74smooth.XXXXXX");
}

static int group_teardown(void **state)
{
  (void)state;
  return tk_rmscratch(tmpdir);
}

static const char *tpath(const char *name)
{
  static char buf[16][256];
  static int k;
  k = (k + 1) % 16;
  snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
  return buf[k];
}

static void write_text(const char *name, const char *text)
{
  FILE *f = fopen(tpath(name), "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static char *slurp(const char *path, size_t *len)
{
  char *b = tk_slurp(path, len);
  assert_non_null(b);
  return b;
}

/* A render's dumps: ids (16-bit), grey, tube, and its stats text. */
struct out {
  int W, H;
  uint16_t *ids;
  uint8_t *grey;
  char *tube; size_t tube_len;
  char *stats;
};

static void out_free(struct out *o)
{
  free(o->ids); free(o->grey); free(o->tube); free(o->stats);
  memset(o, 0, sizeof *o);
}

/* Parse a binary PGM; returns the start of its raster. */
static const unsigned char *pgm(const char *b, size_t len, int *W, int *H, int *maxv)
{
  int off = 0;
  assert_int_equal(sscanf(b, "P5 %d %d %d%n", W, H, maxv, &off), 3);
  assert_true((size_t)off + 1 <= len);
  return (const unsigned char *)b + off + 1;
}

/* render with further options (extra: "" for none) */
static void render_with(const char *scene, const char *effects, const char *extra, struct out *o)
{
  char cmd[2048];
  snprintf(cmd, sizeof cmd,
           "'%s' render '%s' %s%s%s %s --dump ids='%s' --dump grey='%s' --dump tube='%s' "
           "--stats '%s' 2>'%s'",
           tube74, scene, effects ? "--effects '" : "", effects ? effects : "",
           effects ? "'" : "", extra, tpath("ids.pgm"), tpath("grey.pgm"), tpath("tube.pbm"),
           tpath("stats.json"), tpath("err.txt"));
  int rc = system(cmd);
  if (rc != 0) {
    char *e = slurp(tpath("err.txt"), NULL);
    print_message("%s\n%s\n", cmd, e ? e : "");
    free(e);
  }
  assert_int_equal(rc, 0);
  memset(o, 0, sizeof *o);
  size_t n;
  int mv;
  char *b = slurp(tpath("ids.pgm"), &n);
  assert_non_null(b);
  const unsigned char *r = pgm(b, n, &o->W, &o->H, &mv);
  assert_int_equal(mv, 65535);
  o->ids = malloc((size_t)o->W * (size_t)o->H * sizeof *o->ids);
  for (int k = 0; k < o->W * o->H; k++) o->ids[k] = (uint16_t)(r[2 * k] << 8 | r[2 * k + 1]);
  free(b);
  b = slurp(tpath("grey.pgm"), &n);
  assert_non_null(b);
  int W, H;
  r = pgm(b, n, &W, &H, &mv);
  assert_int_equal(W, o->W);
  o->grey = malloc((size_t)W * (size_t)H);
  memcpy(o->grey, r, (size_t)W * (size_t)H);
  free(b);
  o->tube = slurp(tpath("tube.pbm"), &o->tube_len);
  o->stats = slurp(tpath("stats.json"), NULL);
  assert_non_null(o->tube);
  assert_non_null(o->stats);
}

static void render(const char *scene, const char *effects, struct out *o)
{
  render_with(scene, effects, "", o);
}

static double stat(const struct out *o, const char *name)
{
  char key[96];
  snprintf(key, sizeof key, "\"%s\": ", name);
  const char *p = strstr(o->stats, key);
  if (!p) fail_msg("no %s in the stats", name);
  return strtod(p + strlen(key), NULL);
}

/* ---- through the program --------------------------------------------------------- */

static void test_zero_band_is_flat(void **state)
{
  (void)state;
  const char *scenes[] = { "scenes/t1-a.s74", "scenes/t1-g.s74", "scenes/sphere.s74" };
  for (size_t k = 0; k < sizeof scenes / sizeof *scenes; k++) {
    struct out flat, p0, f0, p5;
    render(scenes[k], "halftone=3x3", &flat);
    render(scenes[k], "halftone=3x3 smooth=prop:0", &p0);
    render(scenes[k], "halftone=3x3 smooth=fixed:0", &f0);
    render(scenes[k], "halftone=3x3 smooth=prop:0.05", &p5);
    size_t n = (size_t)flat.W * (size_t)flat.H;
    assert_memory_equal(flat.grey, p0.grey, n);
    assert_memory_equal(flat.grey, f0.grey, n);
    assert_memory_equal(flat.ids, p0.ids, n * sizeof *flat.ids);
    assert_int_equal(flat.tube_len, p0.tube_len);
    assert_memory_equal(flat.tube, p0.tube, flat.tube_len);
    assert_memory_equal(flat.tube, f0.tube, flat.tube_len);
    assert_true(stat(&p0, "smooth_points") > 0);
    assert_true(stat(&p0, "smooth_points") == stat(&p0, "smooth_points_flat"));
    /* and a band at all changes the picture */
    assert_true(memcmp(flat.grey, p5.grey, n) != 0);
    out_free(&flat); out_free(&p0); out_free(&f0); out_free(&p5);
  }
}

/* One big triangle in the plane z = 0 (seen exactly, no perspective distortion). */
static const char *big_triangle =
  "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
  "vertex 1 -190 -140 0\nvertex 2 190 -140 0\nvertex 3 10 145 0\n"
  "face 1 1 2 3\nobject 1 1\n";

static void test_flat_share(void **state)
{
  (void)state;
  write_text("tri.s74", big_triangle);
  const double cs[] = { 0.05, 0.10, 0.15, 0.25 };
  for (size_t k = 0; k < sizeof cs / sizeof *cs; k++) {
    char eff[64];
    snprintf(eff, sizeof eff, "halftone=3x3 smooth=prop:%g", cs[k]);
    struct out o;
    render(tpath("tri.s74"), eff, &o);
    double share = stat(&o, "smooth_points_flat") / stat(&o, "smooth_points");
    double want = (1 - 3 * cs[k]) * (1 - 3 * cs[k]);
    print_message("prop:%g flat share %.4f, (1-3c)^2 = %.4f (%.0f points)\n", cs[k], share,
                  want, stat(&o, "smooth_points"));
    /* about 6000 points: the sampling of two triangles' borders by point centres */
    assert_true(fabs(share - want) < 0.01);
    out_free(&o);
  }
}

static void test_whole_is_phong(void **state)
{
  (void)state;
  const char *scenes[] = { "scenes/t1-f.s74", "scenes/t1-g.s74", "scenes/t1-h.s74", "scenes/t1-i.s74" };
  for (size_t k = 0; k < sizeof scenes / sizeof *scenes; k++) {
    struct out row, phong;
    render(scenes[k], NULL, &row);             /* the scene's own effects line */
    render(scenes[k], "halftone=3x3 smooth=phong", &phong);
    int same = 0, cut = 0;
    for (int q = 0; q < row.W * row.H; q++) {
      if (row.ids[q] == phong.ids[q]) {
        assert_int_equal(row.grey[q], phong.grey[q]);
        same++;
      } else {
        assert_int_equal(row.ids[q], 0);       /* the cut shows the black background */
        cut++;
      }
    }
    assert_int_equal(cut, (int)stat(&row, "contour_points_cut"));
    assert_true(cut > 0);
    out_free(&row); out_free(&phong);
  }
}

static void test_contour_none(void **state)
{
  (void)state;
  struct out flat, none, zero;
  render("scenes/t1-g.s74", "halftone=3x3", &flat);
  render("scenes/t1-g.s74", "halftone=3x3 smooth=phong contour=none", &none);
  render("scenes/t1-g.s74", "halftone=3x3 smooth=phong contour=0", &zero);
  size_t n = (size_t)flat.W * (size_t)flat.H;
  assert_memory_equal(flat.ids, none.ids, n * sizeof *flat.ids);
  assert_null(strstr(none.stats, "contour_points_cut"));
  /* Cc = 0 is a visible case (Table 1 row i), not "off" */
  assert_true(memcmp(flat.ids, zero.ids, n * sizeof *flat.ids) != 0);
  assert_true(stat(&zero, "contour_points_cut") > 0);
  out_free(&flat); out_free(&none); out_free(&zero);
}

static bool in_poly(const double (*p)[2], int n, double x, double y)
{
  bool c = false;
  for (int i = 0; i < n; i++) {
    const double *a = p[i], *b = p[(i + 1) % n];
    if ((a[1] <= y) != (b[1] <= y) && x >= a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
      c = !c;
  }
  return c;
}

/* Point centres of the 133 x 100 grid inside the regions cut at the big triangle's
   three corners under whole smoothing (Q0, Q4 the side midpoints). */
static int lattice_cut(double cc)
{
  static const double V[3][2] = { { -190, -140 }, { 190, -140 }, { 10, 145 } };
  enum { NS = 4000 };
  static double poly[3][NS + 2][2];
  for (int k = 0; k < 3; k++) {
    const double *a = V[(k + 2) % 3], *b = V[k], *c = V[(k + 1) % 3];
    double q0[2] = { (a[0] + b[0]) / 2, (a[1] + b[1]) / 2 }, q4[2] = { (c[0] + b[0]) / 2, (c[1] + b[1]) / 2 };
    double q[5][2];
    contour_controls(q0, b, q4, cc, q);
    poly[k][0][0] = b[0]; poly[k][0][1] = b[1];
    for (int m = 0; m <= NS; m++) contour_bezier(q, 1 - (double)m / NS, poly[k][1 + m]);
  }
  int n = 0;
  for (int j = 0; j < 100; j++)
    for (int i = 0; i < 133; i++) {
      double x = -200 + (i + 0.5) * 400.0 / 133, y = 150 - (j + 0.5) * 3.0;
      for (int k = 0; k < 3; k++)
        if (in_poly(poly[k], NS + 2, x, y)) { n++; break; }
    }
  return n;
}

static void test_cut_area_closed_form(void **state)
{
  (void)state;
  write_text("tri.s74", big_triangle);
  const double ccs[] = { 0.0, 0.25, 0.5, 0.75, 1.0 };
  /* whole smoothing: Q0, Q4 are the side midpoints, so each corner's triangle Q0 Q2 Q4
     is a quarter of the face; three corners */
  double area = 0.5 * 380.0 * 285.0, point = (400.0 / 133) * (300.0 / 100);
  for (size_t k = 0; k < sizeof ccs / sizeof *ccs; k++) {
    char eff[64];
    snprintf(eff, sizeof eff, "halftone=3x3 smooth=phong contour=%g", ccs[k]);
    struct out o;
    render(tpath("tri.s74"), eff, &o);
    double want = 3 * 0.25 * area * contour_cut_share(ccs[k]) / point;
    double got = stat(&o, "contour_points_cut");
    print_message("contour=%g: %.0f points cut, closed form %.1f\n", ccs[k], got, want);
    assert_int_equal((int)stat(&o, "contour_corners_convex"), 3);
    /* the sampling of these thin regions by point centres: within 5% and 20 points */
    assert_true(fabs(got - want) < 0.05 * want + 20);
    /* and, exactly, the point centres inside the three regions of a fine reference
       curve (4000 segments, in space: the triangle is on z = 0, seen straight on) */
    int ref = lattice_cut(ccs[k]);
    print_message("   reference count %d\n", ref);
    assert_true(abs((int)got - ref) <= 4);
    out_free(&o);
  }
}

static void test_cut_shows_what_is_behind(void **state)
{
  (void)state;
  /* the cube of row g in front of a big grey wall (face 99, in no object) */
  char *cube = slurp("scenes/t1-g.s74", NULL);
  assert_non_null(cube);
  char *text = malloc(strlen(cube) + 512);
  strcpy(text, cube);
  strcat(text, "vertex 901 -400 -300 900\nvertex 902 400 -300 900\nvertex 903 400 300 900\n"
               "vertex 904 -400 300 900\nface 99 901 902 903 904 grey 200\n");
  write_text("wall.s74", text);
  free(text); free(cube);
  struct out flat, row;
  render(tpath("wall.s74"), "halftone=3x3", &flat);
  render(tpath("wall.s74"), "halftone=3x3 smooth=phong contour=1.0", &row);
  int uncovered = 0;
  for (int q = 0; q < row.W * row.H; q++)
    if (row.ids[q] != flat.ids[q]) {
      assert_int_equal(row.ids[q], 99);
      assert_int_equal(row.grey[q], 200);
      uncovered++;
    }
  assert_true(uncovered > 0);
  assert_int_equal(uncovered, (int)stat(&row, "contour_points_show_face"));
  assert_int_equal(0, (int)stat(&row, "contour_points_show_background"));
  out_free(&flat); out_free(&row);
}

/* Two triangles of one object meeting at one vertex (a bow tie): two contour sides end
   there and two begin, so both sides beginning there are junctions, not corners; the four
   other vertices are convex corners (contour_build counts the sides ending at each). */
static void test_contour_junction(void **state)
{
  (void)state;
  write_text("bowtie.s74",
             "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
             "vertex 1 -150 -100 0\nvertex 2 -10 -100 0\nvertex 3 0 0 0\n"
             "vertex 4 150 10 0\nvertex 5 10 100 0\n"
             "face 1 1 2 3\nface 2 3 4 5\nobject 1 1 2\n");
  struct out row;
  render(tpath("bowtie.s74"), "halftone=3x3 smooth=phong contour=1.0", &row);
  assert_int_equal((int)stat(&row, "contour_sides"), 6);
  assert_int_equal((int)stat(&row, "contour_corners_convex"), 4);
  assert_int_equal((int)stat(&row, "contour_corners_concave"), 0);
  assert_int_equal((int)stat(&row, "contour_corners_junction"), 2);
  out_free(&row);
}

static void test_concave_vertex_kept(void **state)
{
  (void)state;
  /* a flat sheet with a notch: A B C convex, D the notch (concave), E convex */
  write_text("notch.s74",
             "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
             "vertex 1 -150 -100 0\nvertex 2 150 -100 0\nvertex 3 150 100 0\n"
             "vertex 4 0 20 0\nvertex 5 -150 100 0\n"
             "face 1 1 2 4\nface 2 2 3 4\nface 3 1 4 5\nobject 1 1 2 3\n");
  struct out flat, row;
  render(tpath("notch.s74"), "halftone=3x3", &flat);
  render(tpath("notch.s74"), "halftone=3x3 smooth=phong contour=1.0", &row);
  assert_int_equal((int)stat(&row, "contour_sides"), 5);
  assert_int_equal((int)stat(&row, "contour_corners_convex"), 4);
  assert_int_equal((int)stat(&row, "contour_corners_concave"), 1);
  assert_true(stat(&row, "contour_points_cut") > 100);
  /* the notch at (0, 20): point (66, 43) of the 133 x 100 grid; its neighbourhood is as
     flat shading drew it */
  int changed_near = 0;
  for (int j = 43 - 6; j <= 43 + 6; j++)
    for (int i = 66 - 6; i <= 66 + 6; i++)
      changed_near += row.ids[j * row.W + i] != flat.ids[j * row.W + i];
  assert_int_equal(changed_near, 0);
  out_free(&flat); out_free(&row);
}

static void test_lone_triangle_is_flat(void **state)
{
  (void)state;
  /* one triangle alone in its object: every vertex normal is the face normal, so
     gouraud and phong (and any band) must give the flat picture */
  write_text("tri.s74", big_triangle);
  struct out flat, o;
  render(tpath("tri.s74"), "halftone=3x3", &flat);
  const char *effs[] = { "halftone=3x3 smooth=gouraud", "halftone=3x3 smooth=phong",
                         "halftone=3x3 smooth=prop:0.2", "halftone=3x3 smooth=fixed:0.3" };
  for (size_t k = 0; k < sizeof effs / sizeof *effs; k++) {
    render(tpath("tri.s74"), effs[k], &o);
    assert_memory_equal(flat.grey, o.grey, (size_t)flat.W * (size_t)flat.H);
    assert_true(stat(&o, "smooth_points") > 5000);
    out_free(&o);
  }
  out_free(&flat);
}

static void test_nothing_to_smooth_warns(void **state)
{
  (void)state;
  /* no light: nothing can be smoothed; drawn flat, with a warning at the effects line */
  write_text("nolight.s74", "view 0 0 -1000\nwindow -200 -150 200 150\n"
             "vertex 1 0 0 0\nvertex 2 50 0 0\nvertex 3 0 50 0\nface 1 1 2 3\nobject 1 1\n"
             "effects smooth=phong contour=0.5\n");
  struct out flat, o;
  render(tpath("nolight.s74"), "halftone=4x4", &flat);
  render(tpath("nolight.s74"), NULL, &o);
  char *e = slurp(tpath("err.txt"), NULL);
  assert_non_null(e);
  assert_non_null(strstr(e, "nolight.s74:8: warning: smooth=/contour=:"));
  free(e);
  assert_memory_equal(flat.ids, o.ids, (size_t)flat.W * (size_t)flat.H * sizeof *flat.ids);
  assert_memory_equal(flat.grey, o.grey, (size_t)flat.W * (size_t)flat.H);
  out_free(&flat); out_free(&o);
}

/* Scene file src written to dst with the triangles whose id is a multiple of `every`
   given the other way round (corners b and c swapped); how many were turned. */
static int write_turned(const char *src, const char *dst, int every)
{
  char *text = slurp(src, NULL);
  assert_non_null(text);
  FILE *f = fopen(dst, "w");
  assert_non_null(f);
  int turned = 0;
  for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
    int id, a, b, c;
    if (sscanf(line, "face %d %d %d %d", &id, &a, &b, &c) == 4 && id % every == 0) {
      fprintf(f, "face %d %d %d %d\n", id, a, c, b);
      turned++;
    } else {
      fprintf(f, "%s\n", line);
    }
  }
  assert_int_equal(fclose(f), 0);
  free(text);
  return turned;
}

static void test_orientation(void **state)
{
  (void)state;
  /* row h's cube with every second triangle written the other way round */
  assert_int_equal(write_turned("scenes/t1-h.s74", tpath("mixed.s74"), 2), 6);
  struct out given, mixed;
  render("scenes/t1-h.s74", NULL, &given);
  render(tpath("mixed.s74"), NULL, &mixed);
  size_t n = (size_t)given.W * (size_t)given.H;
  assert_memory_equal(given.ids, mixed.ids, n * sizeof *given.ids);
  assert_memory_equal(given.grey, mixed.grey, n);
  assert_int_equal((int)stat(&given, "smooth_orient_flips") + (int)stat(&mixed, "smooth_orient_flips"), 6);
  out_free(&given); out_free(&mixed);
}

static void test_core_limit(void **state)
{
  (void)state;
  /* the smoothing tables are in core: a core the flat picture fits but they do not */
  struct out flat;
  render("scenes/t1-d.s74", "halftone=3x3", &flat);
  int used = (int)stat(&flat, "core_words_used");
  out_free(&flat);
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "'%s' render scenes/t1-d.s74 --core %d -o '%s' 2>'%s'", tube74,
           used + 20, tpath("no.png"), tpath("err.txt"));
  int rc = system(cmd);
  assert_true(WIFEXITED(rc) && WEXITSTATUS(rc) == 3);
  char *e = slurp(tpath("err.txt"), NULL);
  assert_non_null(strstr(e, "does not fit the core"));
  free(e);
  assert_int_equal(access(tpath("no.png"), F_OK), -1);
}

/* ---- the library ------------------------------------------------------------------- */

struct lib { struct scene *s; struct render r; struct smooth_model m; struct effects e; };

static void lib_open(struct lib *L, const char *scene, const char *effects)
{
  memset(L, 0, sizeof *L);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct t74_error err = { 0, "" };
  assert_int_equal(scene_load(scene, &so, &L->s, &err), T74_OK);
  struct render_opts o;
  memset(&o, 0, sizeof o);
  o.core_words = 1u << 20;
  assert_int_equal(render_prepare(&L->r, L->s, &o, &err), T74_OK);
  assert_int_equal(effects_parse(effects, &L->e, NULL, 0, &err), T74_OK);
  assert_int_equal(smooth_model_build(&L->m, &L->r.map, L->s, &L->e, &err), T74_OK);
}

static void lib_close(struct lib *L)
{
  smooth_model_free(&L->m);
  render_free(&L->r);
  scene_free(L->s);
}

static void normal_at(const struct smooth_tri *t, const double l[3], double n[3])
{
  smooth_partial_normal(t, l, n);
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  assert_true(len > 0.1);
  for (int c = 0; c < 3; c++) n[c] /= len;
}

static int corner_of(const struct smooth_tri *t, int v)
{
  for (int k = 0; k < 3; k++) if (t->v[k] == v) return k;
  return -1;
}

static void test_no_seams(void **state)
{
  (void)state;
  const char *effs[] = { "smooth=prop:0.05", "smooth=prop:0.15", "smooth=fixed:0.05",
                         "smooth=fixed:0.15", "smooth=prop:0.3", "smooth=fixed:0.5" };
  const char *scenes[] = { "scenes/t1-d.s74", "scenes/t1-g.s74", "scenes/sphere.s74" };
  for (size_t si = 0; si < 3; si++)
    for (size_t ei = 0; ei < sizeof effs / sizeof *effs; ei++) {
      struct lib L;
      lib_open(&L, scenes[si], effs[ei]);
      int edges = 0;
      for (int a = 0; a < L.m.ntri; a++)
        for (int b = a + 1; b < L.m.ntri; b++) {
          const struct smooth_tri *A = &L.m.tri[a], *B = &L.m.tri[b];
          for (int k = 0; k < 3; k++) {
            int p = A->v[k], q = A->v[(k + 1) % 3];
            int bp = corner_of(B, p), bq = corner_of(B, q);
            if (bp < 0 || bq < 0) continue;
            edges++;
            for (int m = 0; m <= 40; m++) {
              double s = m / 40.0, la[3] = { 0, 0, 0 }, lb[3] = { 0, 0, 0 }, na[3], nb[3];
              la[k] = 1 - s; la[(k + 1) % 3] = s;
              lb[bp] = 1 - s; lb[bq] = s;
              normal_at(A, la, na);
              normal_at(B, lb, nb);
              for (int c = 0; c < 3; c++) assert_true(fabs(na[c] - nb[c]) < 1e-9);
            }
          }
        }
      assert_true(edges > 0);
      lib_close(&L);
    }
}

/* A space point of triangle t at barycentric weights w (on its plane). */
static void tri_point(const struct lib *L, int t, const double w[3], double X[3])
{
  const struct smooth_tri *tr = &L->m.tri[t];
  for (int c = 0; c < 3; c++) {
    X[c] = 0;
    for (int k = 0; k < 3; k++) {
      const struct scene_vertex *v = &L->s->v[tr->v[k]];
      X[c] += w[k] * (c == 0 ? v->x : c == 1 ? v->y : v->z);
    }
  }
}

/* The tiny-sum tests' triangle: L's triangle t made *keep with bV and bE scaled by c and
   btot by c^2 (its areas' sums below the filters' floors), and its centre as the rows take
   it (X on the triangle's axes bu and bw scaled by c) into X. */
static void tri_tiny(struct lib *L, int t, const struct smooth_tri *keep, double c, double X[3])
{
  struct smooth_tri *tr = &L->m.tri[t];
  *tr = *keep;
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < 2; a++) {
      tr->bV[k][a] *= c;
      tr->bE[k][a] *= c;
    }
  tr->btot *= c * c;
  tri_point(L, t, (const double[3]) { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, X);
  X[tr->bu] *= c;
  X[tr->bw] *= c;
}


/* A second parallel light, from below on the left, added to the scene's one light. */
static void second_light(struct shade_lights *lights)
{
  if (lights->n != 1) return;
  const double v[3] = { -0.48, -0.6, -0.64 };   /* |v| = 1 */
  memcpy(lights->v[1], v, sizeof v);
  lights->point[1] = false;
  lights->n = 2;
}

/* Points shaded in runs (smooth_grey_run, the points engine's path) give the greys and
   regions each gives alone (smooth_grey_at), bit for bit, under each smoothing: runs of 1
   to SMOOTH_RUN points inside and outside each triangle of the globe (the clamps, the
   bands and corners of the partial smoothing), a texture's reflectance, under the scene's
   light and under it with a second parallel light, each blocked at some of the points. */
static void test_run_is_single(void **state)
{
  (void)state;
  static const char *const kinds[] = { "smooth=phong", "smooth=gouraud", "smooth=fixed:0.15",
                                       "smooth=prop:0.3" };
  const double w[][3] = { { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.7, 0.2, 0.1 }, { 1, 0, 0 },
                          { 0.5, 0.5, 0 }, { 1.2, -0.1, -0.1 }, { -0.3, 0.6, 0.7 },
                          { 0.05, 0.9, 0.05 }, { 2, -1, 0 }, { 0.02, 0.49, 0.49 },
                          { 0.9, 0.05, 0.05 }, { 0.1, 0.1, 0.8 } };
  const int nw = (int)(sizeof w / sizeof *w);
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    int differ = 0, greys[256] = { 0 }, regions[3] = { 0 };
    for (int two = 0; two < 2; two++)
    for (int t = 0; t < L.m.ntri; t++) {
      if (two) second_light(&lights);
      const int n = 1 + t % SMOOTH_RUN;
      double X[SMOOTH_RUN][3];
      unsigned blocked[SMOOTH_RUN];
      int run[SMOOTH_RUN], rrun[SMOOTH_RUN];
      for (int p = 0; p < n; p++) {
        tri_point(&L, t, w[(p + t) % nw], X[p]);
        blocked[p] = (unsigned)((t + p) % 3 == 0) | (unsigned)((t + p) % 5 == 0) << 1;
      }
      const double refl = t % 2 ? 1.0 : 0.6;
      smooth_grey_run(&L.m, &L.r.map, L.s, &L.e, t, n, (const double (*)[3])X, refl, blocked,
                      &lights, run, rrun);
      for (int p = 0; p < n; p++) {
        int region;
        int one = smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[p], refl, blocked[p], &lights,
                                 NULL, &region);
        differ += run[p] != one || rrun[p] != region;
        greys[one & 255] = 1;
        if (region >= 0 && region <= 2) regions[region]++;
      }
    }
    assert_int_equal(differ, 0);
    int distinct = 0;                     /* the greys vary: the test can tell points apart */
    for (int g = 0; g < 256; g++) distinct += greys[g];
    assert_true(distinct > 20);
    if (kind >= 2) assert_true(regions[0] > 0 && regions[1] > 0 && regions[2] > 0);
    lib_close(&L);
  }
}

/* smooth_row over a stretch (nseg triangles tri[k], points at[k] .. at[k + 1] - 1 of X
   and blocked) against smooth_grey_at point by point: returns how many points' greys
   differ plus how many regions' counts differ (and, declines non-NULL, 1 when the Phong
   filter declines another count of points in the row than one at a time, whose count is
   added to *declines); the greys met are marked in greys[], each region's points added
   to seen[]. Under smooth=phong with the lights all parallel, smooth_phong_row too, from
   the points' coordinates on their triangles' axes alone (the third coordinate of each
   space point left out): each grey that differs from smooth_grey_at's, and (declines
   non-NULL) another count of declines than smooth_row's, counted too. Under smooth=fixed
   or prop with the lights all parallel, smooth_partial_row likewise (in both its builds,
   AVX's encoding where the processor has it and SSE2's: rows_sse2): each grey that
   differs, each region's count that differs from smooth_row's, another count of the
   points the inner filter leaves to the chain (inner_declines) than smooth_row's, and
   another count of pairs the lit pairs' filter declines (lit_declines) in one build than
   in the other. */

/* smooth_phong_row on m by one of the ways its rows are built: 0, eight points a step
   (AVX-512, where the processor has AVX-512F and AVX-512VL) with the short chain, else as
   1; 1, four points a step (AVX, where the processor has it) with AVX-512's short chain
   (where it has AVX-512VL: phong_ymm); 2, four with the square root and divide
   (phong_sqrt); 3, two points a step (SSE2, rows_sse2). The points it declines are
   counted into *dec where dec is not NULL. */
static void phong_row_way(struct smooth_model *m, int way, int nseg, const int *tri,
                          const int *at, const double *xu, const double *xw,
                          const unsigned *blocked, const struct shade_lights *lights, int *grey,
                          long *dec)
{
  m->phong_ymm = way == 1;
  m->phong_sqrt = way == 2;
  m->rows_sse2 = way == 3;
  m->phong_declines = dec;
  smooth_phong_row(m, nseg, tri, at, xu, xw, blocked, lights, grey);
  m->phong_declines = NULL;
  m->phong_ymm = m->phong_sqrt = m->rows_sse2 = false;
}

static int row_vs_single(struct lib *L, int nseg, const int *tri, const int *at,
                         const double (*X)[3], const unsigned *blocked,
                         const struct shade_lights *lights, int greys[256], long seen[3],
                         long *declines)
{
  int g[SMOOTH_ROW], differ = 0;
  long regions[3] = { 0, 0, 0 }, single[3] = { 0, 0, 0 }, dec_row = 0, dec_one = 0;
  if (declines) L->m.phong_declines = &dec_row;
  smooth_row(&L->m, &L->r.map, &L->e, nseg, tri, at, X, blocked, lights, g, regions);
  if (declines) L->m.phong_declines = &dec_one;
  for (int k = 0; k < nseg; k++)
    for (int p = at[k]; p < at[k + 1]; p++) {
      int region;
      const int one = smooth_grey_at(&L->m, &L->r.map, L->s, &L->e, tri[k], X[p], 1.0,
                                     blocked[p], lights, NULL, &region);
      differ += g[p] != one;
      greys[one & 255] = 1;
      single[region]++;
    }
  bool parallel = true;
  for (int k = 0; k < lights->n; k++) parallel = parallel && !lights->point[k];
  if (L->e.smooth != EFFECTS_SMOOTH_PHONG && parallel && smooth_rows(&L->m, &L->e, lights)) {
    double xu[SMOOTH_ROW], xw[SMOOTH_ROW];
    int gu[SMOOTH_ROW];
    long ru[3] = { 0, 0, 0 }, rx[3] = { 0, 0, 0 }, dec_x = 0, dec_u = 0, lit_dec[3] = { 0, 0, 0 };
    for (int k = 0; k < nseg; k++)
      for (int p = at[k]; p < at[k + 1]; p++) {
        xu[p] = X[p][L->m.tri[tri[k]].bu];
        xw[p] = X[p][L->m.tri[tri[k]].bw];
      }
    L->m.inner_declines = &dec_x;
    smooth_row(&L->m, &L->r.map, &L->e, nseg, tri, at, X, blocked, lights, gu, rx);
    L->m.inner_declines = NULL;
    /* each of its builds: AVX-512F and VL's (where the processor has them), AVX's
       (where it has AVX; AVX-512's processors: partial_ymm) and SSE2's (rows_sse2) */
    for (int way = 0; way < 3; way++) {
      for (int r = 0; r < 3; r++) ru[r] = 0;
      dec_u = 0;
      for (int p = 0; p < at[nseg]; p++) gu[p] = -1;
      L->m.rows_sse2 = way == 1;
      L->m.partial_ymm = way == 2;
      L->m.inner_declines = &dec_u;
      L->m.lit_declines = &lit_dec[way];
      smooth_partial_row(&L->m, &L->r.map, nseg, tri, at, xu, xw, blocked, lights, gu, ru);
      L->m.inner_declines = NULL;
      L->m.lit_declines = NULL;
      L->m.rows_sse2 = L->m.partial_ymm = false;
      for (int k = 0; k < nseg; k++)
        for (int p = at[k]; p < at[k + 1]; p++)
          differ += gu[p] != g[p];
      for (int r = 0; r < 3; r++) differ += ru[r] != regions[r];
      differ += dec_u != dec_x;
    }
    /* the lit pairs' filter declines the same pairs */
    differ += (lit_dec[0] != lit_dec[1]) + (lit_dec[0] != lit_dec[2]);
  }
  if (L->e.smooth == EFFECTS_SMOOTH_PHONG && parallel && smooth_rows(&L->m, &L->e, lights)) {
    double xu[SMOOTH_ROW], xw[SMOOTH_ROW];
    int gu[SMOOTH_ROW];
    long dec_uv = 0;
    for (int k = 0; k < nseg; k++)
      for (int p = at[k]; p < at[k + 1]; p++) {
        xu[p] = X[p][L->m.tri[tri[k]].bu];
        xw[p] = X[p][L->m.tri[tri[k]].bw];
      }
    /* each of its ways: eight points a step (AVX-512F) with the short chain, four (AVX,
       where the processor has it) with AVX-512's short chain (where it has AVX-512VL:
       phong_ymm) or with the square root and divide (phong_sqrt), and two (SSE2,
       rows_sse2) */
    for (int way = 0; way < 4; way++) {
      dec_uv = 0;
      phong_row_way(&L->m, way, nseg, tri, at, xu, xw, blocked, lights, gu,
                    declines ? &dec_uv : NULL);
      for (int k = 0; k < nseg; k++)
        for (int p = at[k]; p < at[k + 1]; p++)
          differ += gu[p] != smooth_grey_at(&L->m, &L->r.map, L->s, &L->e, tri[k], X[p], 1.0,
                                            blocked[p], lights, NULL, NULL);
      /* the same points declined (the short chain's wider margin: at least those) */
      if (declines) differ += way >= 2 ? dec_uv != dec_row : dec_uv < dec_row;
    }
  }
  L->m.phong_declines = NULL;
  for (int r = 0; r < 3; r++) {
    differ += regions[r] != single[r];
    seen[r] += single[r];
  }
  if (declines) {
    /* the filter declines the same points in the row as one at a time (a lane of a pair
       across two triangles with the other triangle's constants would still get its grey,
       from the exact chain, but be declined) */
    differ += dec_row != dec_one;
    *declines += dec_one;
  }
  return differ;
}

/* A row's stretch of points on several triangles (smooth_row, the points engine's path
   where smooth_rows says so) gives the greys each gives alone (smooth_grey_at, reflectance
   1) and the same count of points in each region, bit for bit: stretches of 1 to
   SMOOTH_ROW points on one to a dozen triangles of the globe one after another (front and
   back ones; runs of one point, odd and even runs), the points inside and outside each
   triangle and in its bands and corners, under the phong and partial smoothings, under the
   scene's light, with a second parallel light, and (the partial smoothing) with a point
   light, each blocked at some points, and under the scene's light blocked nowhere; under
   parallel lights smooth_phong_row (smooth=phong) and smooth_partial_row (the partial
   smoothings) too, from two coordinates a point (row_vs_single). */
static void band_point(const struct lib *L, int t, int k, double lk, double sp, double X[3]);
static void test_row_is_single(void **state)
{
  (void)state;
  static const char *const kinds[] = { "smooth=phong", "smooth=fixed:0.15", "smooth=prop:0.3",
                                       "smooth=prop:0.4", "smooth=fixed:0.05" };
  const double w[][3] = { { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.7, 0.2, 0.1 }, { 1, 0, 0 },
                          { 0.5, 0.5, 0 }, { 1.2, -0.1, -0.1 }, { -0.3, 0.6, 0.7 },
                          { 0.05, 0.9, 0.05 }, { 0.02, 0.49, 0.49 }, { 0.9, 0.05, 0.05 } };
  const int nw = (int)(sizeof w / sizeof *w);
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    int differ = 0, rows = 0, greys[256] = { 0 }, back = 0;
    long seen[3] = { 0, 0, 0 }, declines = 0;
    for (int light = 0; light < 4; light++) {
      struct shade_lights lights;
      shade_lights_init(&lights, L.s);
      if (light == 1 || light == 2) second_light(&lights);
      if (light == 2) {                     /* the second one a point light, up and in front */
        const double at[3] = { 100, 400, -300 };
        memcpy(lights.v[1], at, sizeof at);
        lights.point[1] = true;
      }
      if (!smooth_rows(&L.m, &L.e, &lights)) continue;
      rows++;
      for (int t0 = 0; t0 < L.m.ntri; t0++) {
        double X[SMOOTH_ROW][3];
        unsigned blocked[SMOOTH_ROW];
        int tri[SMOOTH_ROW], at[SMOOTH_ROW + 1], nseg = 0, n = 0;
        at[0] = 0;
        /* triangles t0, t0 + 1, .. with 1 .. 7 points each */
        for (int t = t0; t < L.m.ntri && nseg < 12; t++) {
          const int len = 1 + (t * 5 + t0) % 7;
          if (n + len > SMOOTH_ROW) break;
          back += !L.m.tri[t].front;
          for (int p = n; p < n + len; p++) {
            if ((p + t) % 3 == 2) {             /* in a band, maybe a corner */
              const double *ti = L.m.tri[t].t;
              band_point(&L, t, p % 3, ti[p % 3] * ((p % 4) + 0.5) / 4, ((p * 7) % 13) / 12.0,
                         X[p]);
            } else {
              tri_point(&L, t, w[(p + t) % nw], X[p]);
            }
            blocked[p] = light == 3 ? 0     /* no light blocked in the stretch (no shadows) */
                         : light ? (unsigned)((t + p) % 3 == 0) | (unsigned)((t + p) % 5 == 0) << 1
                                 : (unsigned)((t + p) % 4 == 0);
          }
          n += len;
          tri[nseg] = t;
          at[++nseg] = n;
        }
        differ += row_vs_single(&L, nseg, tri, at, (const double (*)[3])X, blocked, &lights,
                                greys, seen, &declines);
      }
    }
    assert_int_equal(differ, 0);
    if (kind == 0) assert_true(declines > 0);
    assert_true(rows >= 2);
    assert_true(back > 0);
    int distinct = 0;                     /* the greys vary: the test can tell points apart */
    for (int gv = 0; gv < 256; gv++) distinct += greys[gv];
    assert_true(distinct > 20);
    if (kind >= 1) assert_true(seen[0] > 0 && seen[1] > 0 && seen[2] > 0);
    lib_close(&L);
  }
}

/* The Phong rows (smooth_phong_row) on stretches of long runs, in each of their ways
   (row_vs_single: eight points a step where the processor has AVX-512F, four, two),
   against smooth_grey_at point by point: runs of 1 to 21 points of one triangle (so that
   the eight-point rows take whole steps of eight, steps of a run's last 1 to 7 points
   with the next run's first ones or alone, and runs longer than two steps), rows of up
   to SMOOTH_ROW points (the four-point rows' second pass: a last step of 1 to 4), under
   one parallel light unblocked, one blocked at some points and two blocked at some (each
   light's lanes apart); then again with every fourth triangle's btot made 0 (its lanes
   made again: smooth_lanes_remake), whose points every way leaves to the exact chain
   (the eight-point rows then put no other run's points in a step with them). Every grey
   the same, the same points declined (the short chain: at least the filter's). */
static void test_phong_rows_long(void **state)
{
  (void)state;
  const double w[][3] = { { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.7, 0.2, 0.1 }, { 1, 0, 0 },
                          { 0.5, 0.5, 0 }, { 0.05, 0.9, 0.05 }, { 0.02, 0.49, 0.49 },
                          { 0.9, 0.05, 0.05 }, { 0.3, 0.3, 0.4 }, { 0.15, 0.25, 0.6 } };
  const int nw = (int)(sizeof w / sizeof *w);
  struct lib L;
  lib_open(&L, "scenes/sphere.s74", "smooth=phong");
  int differ = 0, greys[256] = { 0 }, lens[SMOOTH_ROW + 1] = { 0 }, ends[9] = { 0 };
  long seen[3] = { 0, 0, 0 }, declines = 0, points = 0;
  struct smooth_tri *keep = malloc((size_t)L.m.ntri * sizeof *keep);
  assert_non_null(keep);
  memcpy(keep, L.m.tri, (size_t)L.m.ntri * sizeof *keep);
  for (int light = 0; light < 4; light++) {
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    if (light == 2) second_light(&lights);
    if (light == 3)                         /* one light, every fourth triangle's btot 0 */
      for (int t = 1; t < L.m.ntri; t += 4) {
        L.m.tri[t].btot = 0;
        smooth_lanes_remake(&L.m, t);
      }
    assert_true(smooth_rows(&L.m, &L.e, &lights));
    for (int t0 = 0; t0 < L.m.ntri; t0++) {
      double X[SMOOTH_ROW][3];
      unsigned blocked[SMOOTH_ROW];
      int tri[SMOOTH_ROW], at[SMOOTH_ROW + 1], nseg = 0, n = 0;
      at[0] = 0;
      for (int t = t0; t < L.m.ntri; t++) {
        int len = 1 + (t0 + nseg * 4) % 21;
        if (n + len > SMOOTH_ROW) len = SMOOTH_ROW - n - t0 % 9;
        if (len <= 0) break;
        for (int p = n; p < n + len; p++) {
          tri_point(&L, t, w[(p * 5 + t) % nw], X[p]);
          blocked[p] = light % 3 == 0 ? 0
                                      : (unsigned)((t + p) % 3 == 0) |
                                        (unsigned)(light == 2 && (t + 2 * p) % 5 == 0) << 1;
        }
        lens[len]++;
        n += len;
        tri[nseg] = t;
        at[++nseg] = n;
      }
      ends[n % 8 ? n % 8 : 8]++;
      points += n;
      differ += row_vs_single(&L, nseg, tri, at, (const double (*)[3])X, blocked, &lights,
                              greys, seen, &declines);
    }
  }
  for (int t = 1; t < L.m.ntri; t += 4) {
    L.m.tri[t] = keep[t];
    smooth_lanes_remake(&L.m, t);
  }
  free(keep);
  print_message("Phong rows, long runs: %ld points, %ld declined\n", points, declines);
  assert_int_equal(differ, 0);
  for (int len = 1; len <= 21; len++) assert_true(lens[len] > 0);
  for (int c = 1; c <= 8; c++) assert_true(ends[c] > 0);
  int distinct = 0;                       /* the greys vary: the test can tell points apart */
  for (int gv = 0; gv < 256; gv++) distinct += greys[gv];
  assert_true(distinct > 20);
  lib_close(&L);
}

/* A row's stretch whose points come two or more at a time from one edge band or one corner
   band of a triangle (the pairs whose coordinates smooth_row makes as the inner filter
   declines them: inner_split's row), with inner points, points of another band and points outside
   between them: the greys each gives alone (smooth_grey_at) and the same count of points
   in each region, bit for bit, under the partial smoothings, one light and two (parallel),
   a light blocked at some points; under one light also with the inner filter off
   (inner_exact: every point's coordinates made alone). */
static void test_row_band_pairs(void **state)
{
  (void)state;
  static const char *const kinds[] = { "smooth=fixed:0.15", "smooth=prop:0.3", "smooth=prop:0.4",
                                       "smooth=fixed:0.05" };
  long pairs = 0;
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    int differ = 0, greys[256] = { 0 };
    long seen[3] = { 0, 0, 0 }, exact_points = 0;
    for (int light = 0; light < 2; light++) {
      struct shade_lights lights;
      shade_lights_init(&lights, L.s);
      if (light) second_light(&lights);
      assert_true(smooth_rows(&L.m, &L.e, &lights));
      for (int t0 = 0; t0 < L.m.ntri; t0++) {
        double X[SMOOTH_ROW][3];
        unsigned blocked[SMOOTH_ROW];
        int tri[SMOOTH_ROW], at[SMOOTH_ROW + 1], nseg = 0, n = 0, kinds_of[SMOOTH_ROW];
        at[0] = 0;
        for (int t = t0; t < L.m.ntri && nseg < 4; t++) {
          const int len = 9 + (t * 7 + t0) % 11;
          if (n + len > SMOOTH_ROW) break;
          const double *ti = L.m.tri[t].t;
          for (int p = n; p < n + len; p++) {
            /* groups of two to four points of one kind: edge band k (0 .. 2), corner cv
               (3 .. 5), the inner triangle (6), outside (7) */
            const int g = (p / (2 + (t + p / 5) % 3) + t) % 8;
            const double f = ((p * 7 + t) % 13 + 0.5) / 13.0, h = ((p * 5 + t) % 11 + 0.5) / 11.0;
            if (g < 3) {
              band_point(&L, t, g, ti[g] * f, h, X[p]);
            } else if (g < 6) {
              const int cv = g - 3, a = (cv + 1) % 3, b = (cv + 2) % 3;
              double w[3];
              w[a] = ti[a] * f;
              w[b] = ti[b] * h;
              w[cv] = 1 - w[a] - w[b];
              tri_point(&L, t, w, X[p]);
            } else if (g == 6) {
              const double w[3] = { 1.0 / 3 + 0.01 * f, 1.0 / 3 - 0.01 * h, 1.0 / 3 };
              tri_point(&L, t, w, X[p]);
            } else {
              const double w[3] = { 1.1 + 0.1 * f, -0.05 * h, -0.1 };
              tri_point(&L, t, w, X[p]);
            }
            kinds_of[p] = g;
            blocked[p] = (unsigned)((t + p) % 7 == 0) | (unsigned)(light && (t + p) % 5 == 0) << 1;
            if (p > n && g < 6 && kinds_of[p - 1] == g) pairs++;
          }
          n += len;
          tri[nseg] = t;
          at[++nseg] = n;
        }
        differ += row_vs_single(&L, nseg, tri, at, (const double (*)[3])X, blocked, &lights,
                                greys, seen, NULL);
        if (!light) {
          /* the same stretch with every point left to the chain (inner_exact): the row's
             coordinates then made one point at a time (inner_split's row, bary_one) */
          long seen_exact[3] = { 0, 0, 0 };
          L.m.inner_exact = true;
          differ += row_vs_single(&L, nseg, tri, at, (const double (*)[3])X, blocked, &lights,
                                  greys, seen_exact, NULL);
          L.m.inner_exact = false;
          exact_points += seen_exact[0] + seen_exact[1] + seen_exact[2];
        }
      }
    }
    assert_int_equal(differ, 0);
    assert_true(exact_points > 1000);
    int distinct = 0;                     /* the greys vary: the test can tell points apart */
    for (int gv = 0; gv < 256; gv++) distinct += greys[gv];
    assert_true(distinct > 20);
    /* prop:0.4's insets sum past 1: no inner triangle */
    assert_true((kind == 2 || seen[0] > 0) && seen[1] > 0 && seen[2] > 0);
    lib_close(&L);
  }
  assert_true(pairs > 1000);
}

/* The space point of triangle t at l_k = lk (side k's band) and parameter sp along the
   band: l_a = t_a + sp (1 - lk - t_a - t_b), l_b the rest (a, b the corners after k). */
static void band_point(const struct lib *L, int t, int k, double lk, double sp, double X[3])
{
  const double *ti = L->m.tri[t].t;
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  double w[3];
  w[k] = lk;
  w[a] = ti[a] + sp * (1 - lk - ti[a] - ti[b]);
  w[b] = 1 - lk - w[a];
  tri_point(L, t, w, X);
}

/* Runs of points along each side's band of each triangle of the globe (most of them two
   by two in one edge band, which smooth_grey_run shades two points an instruction, as it
   does two of one corner band; the ends of a run in the corner bands) give the greys and regions each gives alone
   (smooth_grey_at), bit for bit: under partial smoothings of several insets (prop:0.4: the
   insets scaled to sum 1), at several depths into the band, with reflectances 1 and 0.6,
   under the scene's light and with a second one, blocked at some points. */
static void test_edge_pairs_are_single(void **state)
{
  (void)state;
  static const char *const kinds[] = { "smooth=fixed:0.05", "smooth=fixed:0.15",
                                       "smooth=prop:0.15", "smooth=prop:0.4" };
  const double depth[] = { 0.01, 0.3, 0.5, 0.77, 0.999 };
  long band = 0, points = 0, borders = 0;
  int differ = 0, greys[256] = { 0 };
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    for (int two = 0; two < 2; two++) {
      if (two) second_light(&lights);
      for (int t = 0; t < L.m.ntri; t++)
        for (int k = 0; k < 3; k++)
          for (size_t d = 0; d < sizeof depth / sizeof *depth; d++) {
            const double lk = depth[d] * L.m.tri[t].t[k];
            double X[SMOOTH_RUN][3];
            unsigned blocked[SMOOTH_RUN];
            for (int p = 0; p < SMOOTH_RUN; p++) {
              band_point(&L, t, k, lk, -0.1 + 1.2 * p / (SMOOTH_RUN - 1), X[p]);
              blocked[p] = two && (t + p) % 7 == 0 ? 2u : 0u;
            }
            const double refl = (t + k) % 2 ? 1.0 : 0.6;
            int run[SMOOTH_RUN], rrun[SMOOTH_RUN];
            smooth_grey_run(&L.m, &L.r.map, L.s, &L.e, t, SMOOTH_RUN, (const double (*)[3])X,
                            refl, blocked, &lights, run, rrun);
            int single[SMOOTH_RUN], sregion[SMOOTH_RUN];
            for (int p = 0; p < SMOOTH_RUN; p++) {
              single[p] = smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[p], refl, blocked[p],
                                         &lights, NULL, &sregion[p]);
              differ += run[p] != single[p] || rrun[p] != sregion[p];
              greys[single[p] & 255] = 1;
              band += sregion[p] == 1;
              points++;
            }
            /* where two neighbours in the band differ in grey, the border between them
               bisected to neighbouring parameters, and the two points shaded as a pair: a
               normal one unit in the last place off would show as the other grey */
            for (int p = 0; p + 1 < SMOOTH_RUN && d == 2 && !two; p++) {
              if (single[p] == single[p + 1] || sregion[p] != 1 || sregion[p + 1] != 1 ||
                  blocked[p] || blocked[p + 1])
                continue;
              double s0 = -0.1 + 1.2 * p / (SMOOTH_RUN - 1);
              double s1 = -0.1 + 1.2 * (p + 1) / (SMOOTH_RUN - 1);
              double B[2][3];
              int gb[2], rb[2];
              const unsigned none[2] = { 0, 0 };
              for (int it = 0; it < 200; it++) {
                const double sm = 0.5 * (s0 + s1);
                if (!(sm > s0 && sm < s1)) break;
                band_point(&L, t, k, lk, sm, B[0]);
                const int g = smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, B[0], refl, 0,
                                             &lights, NULL, NULL);
                if (g == single[p]) s0 = sm; else s1 = sm;
              }
              for (int h = 0; h < 2; h++) band_point(&L, t, k, lk, h ? s1 : s0, B[h]);
              smooth_grey_run(&L.m, &L.r.map, L.s, &L.e, t, 2, (const double (*)[3])B, refl,
                              none, &lights, gb, rb);
              for (int h = 0; h < 2; h++) {
                int region;
                const int one = smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, B[h], refl, 0,
                                               &lights, NULL, &region);
                differ += gb[h] != one || rb[h] != region;
              }
              borders += gb[0] != gb[1];
            }
          }
    }
    lib_close(&L);
  }
  print_message("%ld points, %ld in edge bands, %ld borders\n", points, band, borders);
  assert_int_equal(differ, 0);
  int distinct = 0;                       /* the greys vary: the test can tell points apart */
  for (int g = 0; g < 256; g++) distinct += greys[g];
  assert_true(distinct > 20);
  assert_true(band > points / 2 && borders > 100);
}

/* Both doubles the same: bit for bit, or both NaN. */
static bool same_double(double a, double b)
{
  return (isnan(a) && isnan(b)) || memcmp(&a, &b, sizeof a) == 0;
}

/* The grey of normal v (not normalised) as the scalar chain lights it: unit()'s steps,
   turned by sgn, shade_grey_lit at reflectance 1, clamped. */
static int scalar_lit(const double v[3], double sgn, const struct shade_lights *L)
{
  double u[3] = { v[0], v[1], v[2] };
  const double len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  if (len > 0) for (int c = 0; c < 3; c++) u[c] /= len;
  for (int c = 0; c < 3; c++) u[c] *= sgn;
  const double at[3] = { 0, 0, 0 };
  const int g = shade_grey_lit(L, u, at, 1.0, 0);
  return g < 0 ? 0 : g > 255 ? 255 : g;
}

/* The shading pass's two-lane band steps (band_lanes: edge_lanes, corner_lanes; then
   lit_pair) give smooth_partial_normal's normals bit for bit and the scalar chain's greys,
   at coordinates made to reach every selection in them: in an edge band, the band
   coordinate s from 0 up past 1 (l_a large: the clamp to 1), l_a a NaN (the clamp to 0
   keeps a NaN, as the scalar if does), den at and below 1e-12 (then 0.5); in a corner
   band, u and w inside and past 1. Fails when a clamp is dropped or its operands swapped
   (maxpd and minpd are not symmetric in a NaN). And lit_pair at a normal too short to
   square (its length 0: the normal is kept, not divided by 0) beside a unit one. */
static void test_band_lanes_selections(void **state)
{
  (void)state;
#ifdef __SSE2__
  static const char *const kinds[] = { "smooth=prop:0.15", "smooth=prop:0.4",
                                       "smooth=fixed:0.05" };
  long pairs = 0, over = 0, nan = 0, tiny = 0;
  int differ = 0;
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    for (int two = 0; two < 2; two++) {
      if (two) second_light(&lights);
      for (int t = 0; t < L.m.ntri; t++) {
        const struct smooth_tri *tr = &L.m.tri[t];
        const double *ti = tr->t;
        for (int k = 0; k < 3; k++) {
          const int a = (k + 1) % 3, b = (k + 2) % 3;
          /* candidate points, then taken two at a time */
          double c[24][3];
          int nc = 0;
          for (int j = 0; j < 6; j++) {       /* edge band k: l_k < t_k, l_a, l_b >= t_a, t_b */
            const double lk = ti[k] * (j + 0.5) / 6;
            const double den = 1 - lk - ti[a] - ti[b];
            const double sv[6] = { 0, 0.3, 1, 1.25, 2, 7 };  /* s = (l_a - t_a) / den */
            c[nc][k] = lk;
            c[nc][a] = ti[a] + sv[j] * (den > 0 ? den : 1);
            c[nc][b] = ti[b] + 0.01 * j;
            nc++;
          }
          c[nc][k] = 0.5 * ti[k]; c[nc][a] = NAN; c[nc][b] = ti[b]; nc++;
          c[nc][k] = 0.25 * ti[k]; c[nc][a] = NAN; c[nc][b] = ti[b] + 0.1; nc++;
          /* den = 1 - l_k - t_a - t_b at and near 0 (insets summing to 1) */
          const double lk0 = 1 - ti[a] - ti[b];
          if (lk0 < ti[k]) {
            c[nc][k] = lk0; c[nc][a] = ti[a] + 0.1; c[nc][b] = ti[b]; nc++;
            c[nc][k] = nextafter(lk0, 0); c[nc][a] = ti[a] + 0.1; c[nc][b] = ti[b]; nc++;
          }
          for (int j = 0; j < 6; j++) {       /* corner band k: l_a < t_a, l_b < t_b */
            const double f[6] = { 0, 0.2, 0.5, 0.9, 0.99, 0.999999 };
            c[nc][k] = ti[k] + 0.1;
            c[nc][a] = f[j] * ti[a];
            c[nc][b] = f[5 - j] * ti[b];
            nc++;
          }
          for (int i = 0; i < nc; i++)
            for (int j = 0; j < nc; j++) {
              double l[2][3], n[2][3];
              int g[2];
              memcpy(l[0], c[i], sizeof l[0]);
              memcpy(l[1], c[j], sizeof l[1]);
              const double sgn = (t + i + j) % 2 ? 1 : -1;
              const int r = smooth_lanes_pair(&L.m, t, (const double (*)[3])l, sgn, &lights,
                                              n, g);
              double o[2][3];
              const int r0 = smooth_partial_normal(tr, l[0], o[0]);
              const int r1 = smooth_partial_normal(tr, l[1], o[1]);
              if (r == 0) {                    /* not one band: so said only when so */
                const bool one = (r0 == r1 && r0 > 0 &&
                                  (l[0][0] < ti[0]) == (l[1][0] < ti[0]) &&
                                  (l[0][1] < ti[1]) == (l[1][1] < ti[1]) &&
                                  (l[0][2] < ti[2]) == (l[1][2] < ti[2]));
                differ += one;
                continue;
              }
              pairs++;
              differ += r != r0 || r != r1;
              for (int h = 0; h < 2; h++) {
                const double *lh = l[h], *oh = o[h];
                for (int cc = 0; cc < 3; cc++) differ += !same_double(n[h][cc], oh[cc]);
                differ += g[h] != scalar_lit(oh, sgn, &lights);
                nan += isnan(lh[a]);
                if (r0 == 1 && !isnan(lh[a]) && lh[k] < ti[k]) {
                  const double den = 1 - lh[k] - ti[a] - ti[b];
                  over += den > 1e-12 && (lh[a] - ti[a]) / den > 1;
                }
              }
            }
        }
      }
      /* lit_pair: a normal whose squares underflow (length 0) beside a unit one; the first
         along the light's signs, so that divided by its length 0 it would light fully */
      double vs[4][3] = { { 0 }, { -1e-200, 3e-170, 2e-300 }, { 0, 0, 0 }, { 0 } };
      for (int cc = 0; cc < 3; cc++) {
        vs[0][cc] = lights.v[0][cc] < 0 ? -1e-200 : 1e-200;
        vs[3][cc] = lights.v[0][cc] < 0 ? -3e-165 : 3e-165;
      }
      for (int i = 0; i < 4; i++)
        for (int h = 0; h < 2; h++)
          for (int sg = -1; sg <= 1; sg += 2) {
            double v[2][3];
            for (int cc = 0; cc < 3; cc++) {
              v[h][cc] = (sg > 0 ? 1 : -1) * vs[i][cc];
              v[1 - h][cc] = lights.v[0][cc];
            }
            int g[2];
            assert_true(smooth_lit_pair((const double (*)[3])v, sg, &lights, g));
            for (int q = 0; q < 2; q++) differ += g[q] != scalar_lit(v[q], sg, &lights);
            tiny++;
          }
    }
    lib_close(&L);
  }
  print_message("%ld pairs, %ld with s past 1, %ld with a NaN l_a, %ld tiny normals\n",
                pairs, over, nan, tiny);
  assert_int_equal(differ, 0);
  assert_true(pairs > 1000 && over > 100 && nan > 100);
#else
  (void)state;
#endif
}

/* A run of a flat face's points (shade_grey_lit_run: one normal, the point lights'
   directions two points an instruction) gives each point shade_grey_lit's grey: at
   points spread through space under parallel and point lights, with reflectances and
   blocked lights varied, and at points bisected onto the borders between two greys
   (neighbouring doubles of the parameter), where a result one unit in the last place
   off would show as another grey. */
static void test_flat_run_is_single(void **state)
{
  (void)state;
  struct shade_lights L;
  memset(&L, 0, sizeof L);
  static const double lv[][4] = {           /* point?, position or direction */
    { 0, 4, 3, -2 }, { 1, -300, 650, 1200 }, { 1, 900, 500, -200 }, { 0, -3, 2, -2 },
    { 1, 40, -2000, 310 } };
  L.n = (int)(sizeof lv / sizeof *lv);
  for (int k = 0; k < L.n; k++) {
    L.point[k] = lv[k][0] != 0;
    for (int c = 0; c < 3; c++) L.v[k][c] = lv[k][c + 1];
    if (!L.point[k]) {                      /* a parallel light's unit direction */
      double n = sqrt(L.v[k][0] * L.v[k][0] + L.v[k][1] * L.v[k][1] + L.v[k][2] * L.v[k][2]);
      for (int c = 0; c < 3; c++) L.v[k][c] /= n;
    }
  }
  static const int planes[][3] = { { 0, 0, -1 }, { -3, 2, -5 }, { 7, -1, -4 }, { 1, 1, 1 },
                                   { 0, -1, 0 }, { -20, 3, 11 } };
  enum { NPT = 4096 };
  double (*X)[3] = malloc(NPT * sizeof *X), *r = malloc(NPT * sizeof *r);
  unsigned *b = malloc(NPT * sizeof *b);
  assert_true(X && r && b);
  uint64_t seed = 12345;
  long differ = 0, borders = 0, runs = 0;
  int greys[256] = { 0 };
  for (size_t pl = 0; pl < sizeof planes / sizeof *planes; pl++) {
    double n[3];
    for (int c = 0; c < 3; c++) n[c] = -(double)planes[pl][c];
    const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int c = 0; c < 3; c++) n[c] /= len;
    int np = 0, tries = 0;
    while (np + 2 <= NPT && tries++ < 8 * NPT) {
      double A[3], B[3];
      for (int c = 0; c < 3; c++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        A[c] = (double)(seed >> 40) / (1 << 24) * 3000 - 1500;
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        B[c] = (double)(seed >> 40) / (1 << 24) * 3000 - 1500;
      }
      seed = seed * 6364136223846793005u + 1442695040888963407u;
      const bool border = np % 4 == 0 && tries < 4 * NPT;   /* a quarter in border pairs */
      const unsigned bl = border ? 0 : (unsigned)(seed >> 33) & 31u;
      const double rf = border || (seed >> 60) % 3 == 0 ? 1.0 : (double)((seed >> 50) & 255) / 255;
      if (border) {
        const int ga = shade_grey_lit(&L, n, A, 1.0, 0), gb = shade_grey_lit(&L, n, B, 1.0, 0);
        if (ga == gb) continue;
        double s0 = 0, s1 = 1;
        for (int it = 0; it < 200; it++) {
          const double sm = 0.5 * (s0 + s1);
          if (!(sm > s0 && sm < s1)) break;
          double M[3];
          for (int c = 0; c < 3; c++) M[c] = A[c] + sm * (B[c] - A[c]);
          if (shade_grey_lit(&L, n, M, 1.0, 0) == ga) s0 = sm; else s1 = sm;
        }
        for (int c = 0; c < 3; c++) {
          X[np][c] = A[c] + s0 * (B[c] - A[c]);
          X[np + 1][c] = A[c] + s1 * (B[c] - A[c]);
        }
        borders++;
      } else {
        memcpy(X[np], A, sizeof A);
        memcpy(X[np + 1], B, sizeof B);
      }
      for (int q = 0; q < 2; q++) { r[np + q] = rf; b[np + q] = bl; }
      np += 2;
    }
    /* runs of 1 .. SHADE_RUN points */
    for (int p = 0, len_ = 1; p < np; p += len_, len_ = len_ % SHADE_RUN + 1) {
      const int m = p + len_ <= np ? len_ : np - p;
      int g[SHADE_RUN];
      shade_grey_lit_run(&L, n, m, (const double (*)[3])(X + p), r + p, b + p, g);
      for (int q = 0; q < m; q++) {
        const int one = shade_grey_lit(&L, n, X[p + q], r[p + q], b[p + q]);
        differ += g[q] != one;
        greys[one & 255] = 1;
      }
      runs++;
    }
  }
  free(X); free(r); free(b);
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += greys[g];
  print_message("flat runs: %ld runs, %ld borders, %d greys, %ld differ\n", runs, borders,
                distinct, differ);
  assert_int_equal(differ, 0);
  assert_true(borders > 1000 && distinct > 100);
}

/* The Phong grey at X by the filter (and the exact chain where it declines) and by the
   exact chain alone; counts the filter's declines in *declines. The filter's grey and
   declines are also checked in a run of two points (both X). */
static void phong_both(struct lib *L, int t, const double X[3], double refl, unsigned blocked,
                       const struct shade_lights *lights, long *declines, int g[2])
{
  long one = 0, two = 0;
  L->m.phong_declines = &one;
  g[0] = smooth_grey_at(&L->m, &L->r.map, L->s, &L->e, t, X, refl, blocked, lights, NULL, NULL);
  /* the point twice in a run (two points an instruction, phong_pairs, under parallel
     lights): the same grey each time, declined where it alone is */
  L->m.phong_declines = &two;
  double XX[2][3];
  memcpy(XX[0], X, sizeof XX[0]);
  memcpy(XX[1], X, sizeof XX[1]);
  const unsigned bb[2] = { blocked, blocked };
  int gg[2], rr[2];
  smooth_grey_run(&L->m, &L->r.map, L->s, &L->e, t, 2, (const double (*)[3])XX, refl, bb,
                  lights, gg, rr);
  assert_int_equal(gg[0], g[0]);
  assert_int_equal(gg[1], g[0]);
  assert_int_equal(two, 2 * one);
  *declines += one;
  L->m.phong_declines = NULL;
  L->m.phong_exact = true;
  g[1] = smooth_grey_at(&L->m, &L->r.map, L->s, &L->e, t, X, refl, blocked, lights, NULL, NULL);
  L->m.phong_exact = false;
}

/* The Phong grey's filter (smooth.c) gives the exact chain's grey, bit for bit: on a
   grid of points in and around every triangle of the globe, under the scene's light and
   under three lights (a parallel one, two point lights near the surface, one of them
   blocked at some points), reflectances 1, 0.6 and 0; and on points found on the
   borders between two greys, where the filter must decline and leave them to the exact
   chain (it does: the count is checked). */
static void test_phong_filter_is_exact(void **state)
{
  (void)state;
  struct lib L;
  lib_open(&L, "scenes/sphere.s74", "smooth=phong");
  struct shade_lights set[2];
  shade_lights_init(&set[0], L.s);
  set[1] = set[0];
  set[1].n = 3;
  set[1].point[1] = set[1].point[2] = true;
  const double p1[3] = { 150, 120, 400 }, p2[3] = { -200, -30, 350 };
  memcpy(set[1].v[1], p1, sizeof p1);
  memcpy(set[1].v[2], p2, sizeof p2);
  const double refls[3] = { 1.0, 0.6, 0.0 };
  long grid = 0, grid_declines = 0, inside = 0, inside_declines = 0;
  int differ = 0, greys[256] = { 0 };
  for (int t = 0; t < L.m.ntri; t++)
    for (int a = -2; a <= 14; a++)
      for (int b = -2; a + b <= 14; b++) {
        const double w[3] = { a / 12.0, b / 12.0, (12 - a - b) / 12.0 };
        const bool in = a > 0 && b > 0 && a + b < 12;   /* strictly inside */
        double X[3];
        tri_point(&L, t, w, X);
        for (int q = 0; q < 2; q++) {
          const double refl = refls[(a + b + q + 6) % 3];   /* a + b >= -4 */
          const unsigned blocked = q && (a + t) % 4 == 0 ? 2u : 0u;
          int g[2];
          long declines = 0;
          phong_both(&L, t, X, refl, blocked, &set[q], &declines, g);
          differ += g[0] != g[1];
          greys[g[1] & 255] = 1;
          grid++;
          grid_declines += declines;
          inside += in;
          inside_declines += in ? declines : 0;
        }
      }
  assert_int_equal(differ, 0);
  int distinct = 0;
  for (int g = 0; g < 256; g++) distinct += greys[g];
  assert_true(distinct > 40);
  /* the filter decides nearly every point strictly inside (on a side or outside, where a
     clamped area is 0, phong_pairs leaves the point to the exact chain) */
  print_message("Phong filter: %ld grid points, %ld declined (%ld inside, %ld declined)\n",
                grid, grid_declines, inside, inside_declines);
  assert_true(inside > grid / 4 && inside_declines * 1000 < inside);
  /* borders: between a triangle's corner and its opposite side's middle the grey changes;
     bisect (exact chain) down to neighbouring doubles of the parameter s */
  long borders = 0, border_declines = 0;
  for (int t = 0; t < L.m.ntri; t++) {
    double A[3], B[3];
    tri_point(&L, t, (const double[3]) { 0.9, 0.05, 0.05 }, A);
    tri_point(&L, t, (const double[3]) { 0.05, 0.475, 0.475 }, B);
    int ga[2], gb[2];
    long ignore = 0;
    phong_both(&L, t, A, 1.0, 0, &set[0], &ignore, ga);
    phong_both(&L, t, B, 1.0, 0, &set[0], &ignore, gb);
    if (ga[1] == gb[1]) continue;
    double s0 = 0, s1 = 1;
    for (int it = 0; it < 200; it++) {
      double sm = 0.5 * (s0 + s1);
      if (!(sm > s0 && sm < s1)) break;
      double X[3];
      for (int c = 0; c < 3; c++) X[c] = A[c] + sm * (B[c] - A[c]);
      int g[2];
      phong_both(&L, t, X, 1.0, 0, &set[0], &ignore, g);
      if (g[1] == ga[1]) s0 = sm; else s1 = sm;
    }
    for (int side = 0; side < 2; side++) {
      double X[3], sm = side ? s1 : s0;
      for (int c = 0; c < 3; c++) X[c] = A[c] + sm * (B[c] - A[c]);
      int g[2];
      phong_both(&L, t, X, 1.0, 0, &set[0], &border_declines, g);
      assert_int_equal(g[0], g[1]);
      assert_int_equal(g[1] == ga[1], side == 0);
    }
    borders++;
  }
  /* the two points of each border lie within far less than the filter's bound of a
     change of grey: it declines both */
  print_message("Phong filter: %ld borders, %ld points declined\n", borders, border_declines);
  assert_true(borders > 50);
  assert_int_equal(border_declines, 2 * borders);
  lib_close(&L);
}

/* The Phong rows (smooth_phong_row) on points found on the borders between two greys, as
   test_phong_filter_is_exact finds them (bisected by the exact chain down to neighbouring
   doubles of the parameter), each border's two points in a row with the two ends they
   were bisected between (a step of four points; the third coordinate left out), in each
   of the rows' ways: AVX-512's short chain eight points a step where the processor has
   AVX-512F, four where it has AVX-512VL (phong_ymm), the AVX rows' square root and divide
   (phong_sqrt), SSE2's two points a step (rows_sse2). Every
   grey is the exact chain's, and every way declines both points of each border (they lie
   far within any of the filters' margins of a change of grey). Fails with the short
   chain's margin (smooth.c, phong_tail4) cut from 2^-15 to 2^-30. */
static void test_phong_rows_borders(void **state)
{
  (void)state;
  struct lib L;
  lib_open(&L, "scenes/sphere.s74", "smooth=phong");
  struct shade_lights one;
  shade_lights_init(&one, L.s);
  assert_true(smooth_rows(&L.m, &L.e, &one));
  long borders = 0, declines[4] = { 0, 0, 0, 0 };
  int differ = 0;
  for (int t = 0; t < L.m.ntri; t++) {
    const struct smooth_tri *tr = &L.m.tri[t];
    double A[3], B[3];
    tri_point(&L, t, (const double[3]) { 0.9, 0.05, 0.05 }, A);
    tri_point(&L, t, (const double[3]) { 0.05, 0.475, 0.475 }, B);
    int ga[2], gb[2];
    long ignore = 0;
    phong_both(&L, t, A, 1.0, 0, &one, &ignore, ga);
    phong_both(&L, t, B, 1.0, 0, &one, &ignore, gb);
    if (ga[1] == gb[1]) continue;
    double s0 = 0, s1 = 1;
    for (int it = 0; it < 200; it++) {
      const double sm = 0.5 * (s0 + s1);
      if (!(sm > s0 && sm < s1)) break;
      double X[3];
      for (int c = 0; c < 3; c++) X[c] = A[c] + sm * (B[c] - A[c]);
      int g[2];
      phong_both(&L, t, X, 1.0, 0, &one, &ignore, g);
      if (g[1] == ga[1]) s0 = sm; else s1 = sm;
    }
    double X[4][3];                         /* A, the border's two points, B */
    for (int c = 0; c < 3; c++) {
      X[0][c] = A[c];
      X[1][c] = A[c] + s0 * (B[c] - A[c]);
      X[2][c] = A[c] + s1 * (B[c] - A[c]);
      X[3][c] = B[c];
    }
    int exact[4];
    double xu[4], xw[4];
    for (int p = 0; p < 4; p++) {
      int g[2];
      phong_both(&L, t, X[p], 1.0, 0, &one, &ignore, g);
      exact[p] = g[1];
      xu[p] = X[p][tr->bu];
      xw[p] = X[p][tr->bw];
    }
    assert_true(exact[1] == ga[1] && exact[2] != ga[1]);
    borders++;
    const int tri1[1] = { t }, at1[2] = { 0, 4 };
    const unsigned none[4] = { 0, 0, 0, 0 };
    for (int way = 0; way < 4; way++) {
      int gr[4];
      long dec = 0;
      phong_row_way(&L.m, way, 1, tri1, at1, xu, xw, none, &one, gr, &dec);
      for (int p = 0; p < 4; p++) differ += gr[p] != exact[p];
      declines[way] += dec;
    }
  }
  print_message("Phong rows: %ld borders, declined %ld / %ld / %ld / %ld (short chain eight "
                "and four a step, AVX, SSE2)\n",
                borders, declines[0], declines[1], declines[2], declines[3]);
  assert_int_equal(differ, 0);
  assert_true(borders > 50);
  for (int way = 0; way < 4; way++) assert_true(declines[way] >= 2 * borders);
  lib_close(&L);
}

/* The Phong filter's range test (smooth.c, phong_filter and phong_pairs): a point whose
   clamped area w_k is positive but below |tot| 2^-1000 is declined and left to the exact
   chain, under parallel lights (phong_pairs, and the rows: smooth_phong_row both ways)
   and with a point light (phong_filter). Two
   triangles share a side on the line x = 0 (their plane's first barycentric axis): a
   point at x = +-e from the side's middle, inside, has that side's area of e's size (the
   two corners' x are 0, so nothing of e is lost), the others of the triangle's: at
   e = 2^-1010 far below the bound, at e = 2^-900 far above it. */
static void test_phong_filter_range(void **state)
{
  (void)state;
  write_text("pair.s74",
             "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
             "vertex 1 0 0 0\nvertex 2 0 100 10\nvertex 3 100 50 20\nvertex 4 -100 50 0\n"
             "face 1 1 2 3\nface 2 2 1 4\nobject 1 1 2\n");
  struct lib L;
  lib_open(&L, tpath("pair.s74"), "smooth=phong");
  struct shade_lights set[2];
  shade_lights_init(&set[0], L.s);
  set[1] = set[0];
  set[1].n = 2;
  set[1].point[1] = true;
  const double p1[3] = { 30, -40, -300 };
  memcpy(set[1].v[1], p1, sizeof p1);
  assert_int_equal(L.m.ntri, 2);
  for (int t = 0; t < L.m.ntri; t++) {
    const struct smooth_tri *tr = &L.m.tri[t];
    assert_true(tr->bu == 0 && tr->bw == 1);
    double w[3], side = 0;                  /* the side's middle; side: the third's x */
    for (int k = 0; k < 3; k++) {
      const int x = L.s->v[tr->v[k]].x;
      w[k] = x ? 0 : 0.5;
      side += x;
    }
    for (int q = 0; q < 2; q++)
      for (int tiny = 0; tiny < 2; tiny++) {
        double X[3];
        tri_point(&L, t, w, X);
        assert_true(X[0] == 0);
        X[0] = (side > 0 ? 1 : -1) * (tiny ? 0x1p-1010 : 0x1p-900);
        int g[2];
        long declines = 0;
        phong_both(&L, t, X, 1.0, 0, &set[q], &declines, g);
        assert_int_equal(g[0], g[1]);
        assert_int_equal(declines, tiny);
        if (q)
          continue;
        /* the point as a row of one (smooth_phong_row, the lights parallel), each of its
           ways (eight and four points a step where the processor has AVX-512F and AVX,
           and SSE2's): the same grey, declined alike (the eight- and four-point ways make
           the range test in their second pass) */
        assert_true(smooth_rows(&L.m, &L.e, &set[0]));
        for (int way = 0; way < 4; way++) {
          const int tri1[1] = { t }, at1[2] = { 0, 1 };
          const double xu[1] = { X[tr->bu] }, xw[1] = { X[tr->bw] };
          const unsigned none[1] = { 0 };
          int gr[1];
          long row_declines = 0;
          phong_row_way(&L.m, way, 1, tri1, at1, xu, xw, none, &set[0], gr,
                        &row_declines);
          assert_int_equal(gr[0], g[1]);
          assert_int_equal(row_declines, tiny);
        }
      }
  }
  lib_close(&L);
}

/* The Phong filter's lower bound on the sum s of the clamped areas (smooth.c,
   phong_filter): a point whose s is below 2^-500 is declined (its length test's s * s *
   2^-20 would no longer be a normal number, and the filter's constant margin rests on that
   test). The scene's coordinates are integers, so each triangle of test_phong_filter_range's
   pair is scaled on its axes bu, bw by a power of two c (its corners, sides and btot: the
   areas scale by c^2 exactly); its centre's s is then |btot| c^2 (10,000: 2^13.3): with c =
   2^-260 about 2^-507, declined; with c = 2^-255 about 2^-497, taken. Under a point light
   (phong_filter, which reads the triangle's constants as scaled); the grey is the exact
   chain's either way. Fails if the bound is s > 0 (the point at 2^-507 taken). */
static void test_phong_filter_tiny_sum(void **state)
{
  (void)state;
  write_text("pair2.s74",
             "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
             "vertex 1 0 0 0\nvertex 2 0 100 10\nvertex 3 100 50 20\nvertex 4 -100 50 0\n"
             "face 1 1 2 3\nface 2 2 1 4\nobject 1 1 2\n");
  struct lib L;
  lib_open(&L, tpath("pair2.s74"), "smooth=phong");
  struct shade_lights set;
  shade_lights_init(&set, L.s);
  set.n = 2;
  set.point[1] = true;
  const double p1[3] = { 30, -40, -300 };
  memcpy(set.v[1], p1, sizeof p1);
  assert_int_equal(L.m.ntri, 2);
  for (int t = 0; t < L.m.ntri; t++) {
    struct smooth_tri *tr = &L.m.tri[t];
    const struct smooth_tri keep = *tr;
    assert_true(fabs(tr->btot) == 10000);
    for (int tiny = 0; tiny < 2; tiny++) {
      const double c = tiny ? 0x1p-260 : 0x1p-255;
      double X[3];
      tri_tiny(&L, t, &keep, c, X);
      int g[2];
      long declines = 0;
      phong_both(&L, t, X, 1.0, 0, &set, &declines, g);
      assert_int_equal(g[0], g[1]);
      assert_int_equal(declines, tiny);
    }
    *tr = keep;
  }
  lib_close(&L);
}

/* test_phong_filter_tiny_sum's scaled triangles through the rows (smooth_phong_row, under
   the scene's parallel light), whose constants are the triangle's lanes (made again from
   the scaled triangle: smooth_lanes_remake): a step of four points at the triangle's
   centre, its coordinates on the axes bu, bw scaled by c, in each of the rows' ways (the
   short chain eight points a step where the processor has AVX-512F, four where it has
   AVX-512VL: phong_ymm, the square root and divide: phong_sqrt, SSE2's: rows_sse2). Each takes the four at c = 2^-255 (s about 2^-497) and declines
   them at c = 2^-260 (s about 2^-507: the AVX rows' test s >= 2^-500 in their second
   pass), every grey the exact chain's. Fails if the rows' bound is s > 0. */
static void test_phong_rows_tiny_sum(void **state)
{
  (void)state;
  write_text("pair3.s74",
             "view 0 0 -1000\nwindow -200 -150 200 150\nlight -40 50 -80\n"
             "vertex 1 0 0 0\nvertex 2 0 100 10\nvertex 3 100 50 20\nvertex 4 -100 50 0\n"
             "face 1 1 2 3\nface 2 2 1 4\nobject 1 1 2\n");
  struct lib L;
  lib_open(&L, tpath("pair3.s74"), "smooth=phong");
  struct shade_lights one;
  shade_lights_init(&one, L.s);
  assert_true(smooth_rows(&L.m, &L.e, &one));
  assert_int_equal(L.m.ntri, 2);
  for (int t = 0; t < L.m.ntri; t++) {
    struct smooth_tri *tr = &L.m.tri[t];
    const struct smooth_tri keep = *tr;
    for (int tiny = 0; tiny < 2; tiny++) {
      const double c = tiny ? 0x1p-260 : 0x1p-255;
      double X[3];
      tri_tiny(&L, t, &keep, c, X);
      smooth_lanes_remake(&L.m, t);
      int g[2];
      long ignore = 0;
      phong_both(&L, t, X, 1.0, 0, &one, &ignore, g);
      assert_int_equal(g[0], g[1]);
      const double xu[4] = { X[tr->bu], X[tr->bu], X[tr->bu], X[tr->bu] };
      const double xw[4] = { X[tr->bw], X[tr->bw], X[tr->bw], X[tr->bw] };
      const int tri1[1] = { t }, at1[2] = { 0, 4 };
      const unsigned none[4] = { 0, 0, 0, 0 };
      for (int way = 0; way < 4; way++) {
        int gr[4];
        long dec = 0;
        phong_row_way(&L.m, way, 1, tri1, at1, xu, xw, none, &one, gr, &dec);
        for (int p = 0; p < 4; p++) assert_int_equal(gr[p], g[1]);
        assert_int_equal(dec, 4 * tiny);
      }
    }
    *tr = keep;
    smooth_lanes_remake(&L.m, t);
  }
  lib_close(&L);
}

/* The greys and regions at a run of n points X[p] by the inner triangle's filter (and the
   chain where it declines) in g[0], r[0] and by the chain alone in g[1], r[1]; counts the
   points the filter does not take in *declines. */
static void inner_both(struct lib *L, int t, int n, const double (*X)[3], double refl,
                       const unsigned *blocked, const struct shade_lights *lights,
                       long *declines, int g[2][SMOOTH_RUN], int r[2][SMOOTH_RUN])
{
  L->m.inner_declines = declines;
  smooth_grey_run(&L->m, &L->r.map, L->s, &L->e, t, n, X, refl, blocked, lights, g[0], r[0]);
  L->m.inner_declines = NULL;
  L->m.inner_exact = true;
  smooth_grey_run(&L->m, &L->r.map, L->s, &L->e, t, n, X, refl, blocked, lights, g[1], r[1]);
  L->m.inner_exact = false;
}

/* The inner triangle's filter (smooth.c) gives the chain's region and grey, bit for bit,
   under partial smoothings of several insets (prop:0.4: insets scaled to sum 1, the inner
   triangle a point), in runs of 1 to SMOOTH_RUN points (two a step, and one alone): on a
   grid of points in and around every triangle of the globe, with reflectances 1 and 0.6
   and the light blocked at some points; and on points bisected onto the inner triangle's
   border (between its centre and a side's middle), where the one inside must be declined
   by the filter and left to the chain (it is: counted), alone and in a run of the two. */
static void test_inner_filter_is_exact(void **state)
{
  (void)state;
  static const char *const kinds[] = { "smooth=fixed:0.05", "smooth=fixed:0.15",
                                       "smooth=prop:0.15", "smooth=prop:0.3",
                                       "smooth=prop:0.4" };
  long grid = 0, inner = 0, borders = 0, border_declines = 0;
  int differ = 0;
  for (size_t kind = 0; kind < sizeof kinds / sizeof *kinds; kind++) {
    struct lib L;
    lib_open(&L, "scenes/sphere.s74", kinds[kind]);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    for (int t = 0; t < L.m.ntri; t++) {
      for (int a = -2; a <= 26; a++) {
        double X[SMOOTH_RUN][3];
        unsigned blocked[SMOOTH_RUN];
        const double refl = a % 3 ? 1.0 : 0.6;
        int n = 0;
        const int len = 1 + (a + t) % SMOOTH_RUN;
        for (int b = -2; a + b <= 26; b++) {
          const double w[3] = { a / 24.0, b / 24.0, (24 - a - b) / 24.0 };
          tri_point(&L, t, w, X[n]);
          blocked[n++] = (b + t) % 5 == 0;
          if (n < len && a + b + 1 <= 26) continue;
          int g[2][SMOOTH_RUN], r[2][SMOOTH_RUN];
          long ignore = 0;
          inner_both(&L, t, n, (const double (*)[3])X, refl, blocked, &lights, &ignore, g, r);
          for (int q = 0; q < n; q++) {
            differ += g[0][q] != g[1][q] || r[0][q] != r[1][q];
            inner += r[1][q] == 0;
            grid++;
          }
          n = 0;
        }
      }
      /* the border on the way from the centre to side k's middle, bisected (the chain) */
      for (int k = 0; k < 3; k++) {
        double AB[2][3], wb[3] = { 0.5, 0.5, 0.5 };
        const double *A = AB[0], *B = AB[1];
        const unsigned none[2] = { 0, 0 };
        wb[k] = 0;
        tri_point(&L, t, (const double[3]) { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, AB[0]);
        tri_point(&L, t, wb, AB[1]);
        int g[2][SMOOTH_RUN], r[2][SMOOTH_RUN];
        long ignore = 0;
        inner_both(&L, t, 2, (const double (*)[3])AB, 1.0, none, &lights, &ignore, g, r);
        if (r[1][0] != 0 || r[1][1] == 0) continue;
        double s0 = 0, s1 = 1;
        for (int it = 0; it < 200; it++) {
          const double sm = 0.5 * (s0 + s1);
          if (!(sm > s0 && sm < s1)) break;
          double X[1][3];
          for (int c = 0; c < 3; c++) X[0][c] = A[c] + sm * (B[c] - A[c]);
          inner_both(&L, t, 1, (const double (*)[3])X, 1.0, none, &lights, &ignore, g, r);
          if (r[1][0] == 0) s0 = sm; else s1 = sm;
        }
        double X[2][3];
        for (int c = 0; c < 3; c++) {
          X[0][c] = A[c] + s0 * (B[c] - A[c]);
          X[1][c] = A[c] + s1 * (B[c] - A[c]);
        }
        for (int way = 0; way < 3; way++) {  /* each alone, then the two in a run */
          const int n = way < 2 ? 1 : 2;
          long declines = 0;
          inner_both(&L, t, n, (const double (*)[3])(X + (way == 1)), 1.0, none, &lights,
                     &declines, g, r);
          for (int q = 0; q < n; q++) {
            assert_int_equal(g[0][q], g[1][q]);
            assert_int_equal(r[0][q], r[1][q]);
            assert_int_equal(r[1][q] == 0, q == 0 && way != 1);
          }
          border_declines += way == 0 && declines == 1;
          border_declines += way == 2 && declines == 2;   /* the outside one is not taken */
        }
        borders++;
      }
    }
    lib_close(&L);
  }
  print_message("inner filter: %ld grid points (%ld inner), %ld borders, %ld declined\n",
                grid, inner, borders, border_declines);
  assert_int_equal(differ, 0);
  assert_true(inner > 1000 && inner * 4 < grid);
  assert_true(borders > 1000);
  assert_int_equal(border_declines, 2 * borders);
}

/* smooth_grey_run's greys and regions at n points of triangle t with the lit pairs' filter
   (g[0], r[0]; the pairs it declines added to *declines) and by the exact chain (lit_exact:
   g[1], r[1]). */
static void lit_both(struct lib *L, int t, int n, const double (*X)[3], double refl,
                     const unsigned *blocked, const struct shade_lights *lights,
                     long *declines, int g[2][SMOOTH_RUN], int r[2][SMOOTH_RUN])
{
  L->m.lit_declines = declines;
  smooth_grey_run(&L->m, &L->r.map, L->s, &L->e, t, n, X, refl, blocked, lights, g[0], r[0]);
  L->m.lit_declines = NULL;
  L->m.lit_exact = true;
  smooth_grey_run(&L->m, &L->r.map, L->s, &L->e, t, n, X, refl, blocked, lights, g[1], r[1]);
  L->m.lit_exact = false;
}

/* The point of triangle t at coordinates a + s (b - a) (a, b: barycentric). */
static void lit_seg_point(const struct lib *L, int t, const double a[3], const double b[3],
                          double s, double X[3])
{
  const double w[3] = { a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]),
                        a[2] + s * (b[2] - a[2]) };
  tri_point(L, t, w, X);
}

/* Three segments in barycentric coordinates through triangle t's bands (ti: its band
   widths) at its side k: along side k's band, across it, and from vertex k to the inner
   corner; seg[j][0] and seg[j][1] are segment j's ends. */
static void band_segments(const double ti[3], int k, double seg[3][2][3])
{
  const int ka = (k + 1) % 3, kb = (k + 2) % 3;
  seg[0][0][k] = seg[0][1][k] = 0.4 * ti[k];
  seg[0][0][ka] = 0.95 - 0.4 * ti[k]; seg[0][0][kb] = 0.05;
  seg[0][1][ka] = 0.05; seg[0][1][kb] = 0.95 - 0.4 * ti[k];
  seg[1][0][k] = 0; seg[1][1][k] = ti[k];
  seg[1][0][ka] = seg[1][1][ka] = 0.5 * (1 - 0.5 * ti[k]);
  seg[1][0][kb] = 1 - seg[1][0][ka]; seg[1][1][kb] = 1 - ti[k] - seg[1][1][ka];
  seg[2][0][k] = 1; seg[2][0][ka] = seg[2][0][kb] = 0;
  seg[2][1][k] = 1 - ti[ka] - ti[kb]; seg[2][1][ka] = ti[ka]; seg[2][1][kb] = ti[kb];
}

/* The lit pairs' filter (smooth.c) gives the chain's grey, bit for bit, under partial
   smoothings of several insets on the globe and the t1 objects: on a grid of points in
   and around every triangle (the bands, the corners and the inner triangle lit), with
   reflectances 1 and 0.6, one light and two, some blocked, in runs of 1 to SMOOTH_RUN
   points (pairs and a lone last one); and on points bisected onto the borders between two
   of the chain's greys (along a band's side, across it, and from a vertex to the inner
   triangle's corner), where the filter must decline each (it does: counted), as its
   margin requires. */
static void test_lit_filter_is_exact(void **state)
{
  (void)state;
  static const struct { const char *scene, *fx; } cases[] = {
    { "scenes/sphere.s74", "smooth=fixed:0.05" }, { "scenes/sphere.s74", "smooth=fixed:0.15" },
    { "scenes/sphere.s74", "smooth=prop:0.15" },  { "scenes/sphere.s74", "smooth=prop:0.4" },
    { "scenes/t1-a.s74", "smooth=fixed:0.05" },   { "scenes/t1-e.s74", "smooth=prop:0.15" },
    { "scenes/t1-j.s74", "smooth=prop:0.15" },
  };
  long grid = 0, band = 0, grid_declines = 0, borders = 0, border_declines = 0;
  int differ = 0;
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    struct lib L;
    lib_open(&L, cases[c].scene, cases[c].fx);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    for (int two = 0; two < 2; two++) {
      if (two) second_light(&lights);
      for (int t = 0; t < L.m.ntri; t++)
        for (int a = -1; a <= 25; a++) {
          double X[SMOOTH_RUN][3];
          unsigned blocked[SMOOTH_RUN];
          const double refl = a % 3 ? 1.0 : 0.6;
          int n = 0;
          const int len = 1 + (a + t) % SMOOTH_RUN;
          for (int b = -1; a + b <= 25; b++) {
            const double w[3] = { a / 24.0, b / 24.0, (24 - a - b) / 24.0 };
            tri_point(&L, t, w, X[n]);
            blocked[n++] = (unsigned)((b + t) % 7 == 0) | (unsigned)((a + b) % 5 == 0) << 1;
            if (n < len && a + b + 1 <= 25) continue;
            int g[2][SMOOTH_RUN], r[2][SMOOTH_RUN];
            lit_both(&L, t, n, (const double (*)[3])X, refl, blocked, &lights, &grid_declines,
                     g, r);
            for (int q = 0; q < n; q++) {
              differ += g[0][q] != g[1][q] || r[0][q] != r[1][q];
              band += r[1][q] != 0;
              grid++;
            }
            n = 0;
          }
        }
    }
    shade_lights_init(&lights, L.s);         /* the scene's light alone */
    const unsigned none[1] = { 0 };
    for (int t = 0; t < L.m.ntri; t++) {
      const double *ti = L.m.tri[t].t;
      for (int k = 0; k < 3; k++) {
        double seg[3][2][3];
        band_segments(ti, k, seg);
        for (int j = 0; j < 3; j++) {
          const double *A = seg[j][0], *B = seg[j][1];
          double X[1][3];
          int g[2][SMOOTH_RUN], r[2][SMOOTH_RUN];
          long ignore = 0;
          lit_seg_point(&L, t, A, B, 0, X[0]);
          lit_both(&L, t, 1, (const double (*)[3])X, 1.0, none, &lights, &ignore, g, r);
          const int g0 = g[1][0];
          lit_seg_point(&L, t, A, B, 1, X[0]);
          lit_both(&L, t, 1, (const double (*)[3])X, 1.0, none, &lights, &ignore, g, r);
          if (g[1][0] == g0) continue;
          double s0 = 0, s1 = 1;              /* the chain's grey g0 at s0, another at s1 */
          for (int it = 0; it < 200; it++) {
            const double sm = 0.5 * (s0 + s1);
            if (!(sm > s0 && sm < s1)) break;
            lit_seg_point(&L, t, A, B, sm, X[0]);
            lit_both(&L, t, 1, (const double (*)[3])X, 1.0, none, &lights, &ignore, g, r);
            if (g[1][0] == g0) s0 = sm; else s1 = sm;
          }
          for (int h = 0; h < 2; h++) {       /* each side of the border: declined */
            long declines = 0;
            lit_seg_point(&L, t, A, B, h ? s1 : s0, X[0]);
            lit_both(&L, t, 1, (const double (*)[3])X, 1.0, none, &lights, &declines, g, r);
            differ += g[0][0] != g[1][0] || r[0][0] != r[1][0];
            border_declines += declines == 1;
          }
          borders++;
        }
      }
    }
    lib_close(&L);
  }
  print_message("lit filter: %ld grid points (%ld lit in bands), %ld pairs declined; %ld "
                "borders, %ld of their points declined\n",
                grid, band, grid_declines, borders, border_declines);
  assert_int_equal(differ, 0);
  assert_true(band > 10000 && band * 8 < grid * 7);
  assert_true(grid_declines * 1000 < grid);
  assert_true(borders > 1000);
  assert_int_equal(border_declines, 2 * borders);
}

/* smooth_partial_row at points bisected onto the borders between two of the chain's greys
   (lit_seg_point's segments of test_lit_filter_is_exact, bisected by smooth_grey_at),
   the two points of a border among other points of the segment in a triangle's stretch
   of 2 to 9 points, so that they fall in every lane of the AVX build's four-slot steps
   (lit_quads) and of the SSE2 build's pairs: both builds give each point smooth_grey_at's
   grey (lit_exact's chain, where the filter declines), and decline the same pairs, at
   least one a border (the filter's margin: its tests must not take a border's point). */
static void test_partial_row_lit_borders(void **state)
{
  (void)state;
  static const struct { const char *scene, *fx; } cases[] = {
    { "scenes/sphere.s74", "smooth=prop:0.15" }, { "scenes/sphere.s74", "smooth=fixed:0.15" },
    { "scenes/t1-e.s74", "smooth=prop:0.15" },   { "scenes/t1-j.s74", "smooth=prop:0.15" },
  };
  long borders = 0, rows = 0, declined_rows = 0, points = 0;
  int differ = 0;
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    struct lib L;
    lib_open(&L, cases[c].scene, cases[c].fx);
    struct shade_lights lights;
    shade_lights_init(&lights, L.s);
    assert_true(smooth_rows(&L.m, &L.e, &lights));
    for (int t = 0; t < L.m.ntri; t++) {
      const double *ti = L.m.tri[t].t;
      for (int k = 0; k < 3; k++) {
        double seg[3][2][3];
        band_segments(ti, k, seg);
        for (int j = 0; j < 3; j++) {
          const double *A = seg[j][0], *B = seg[j][1];
          double X[SMOOTH_ROW][3];
          lit_seg_point(&L, t, A, B, 0, X[0]);
          const int g0 = smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[0], 1.0, 0, &lights,
                                        NULL, NULL);
          lit_seg_point(&L, t, A, B, 1, X[0]);
          if (smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[0], 1.0, 0, &lights, NULL,
                             NULL) == g0)
            continue;
          double s0 = 0, s1 = 1;              /* the chain's grey g0 at s0, another at s1 */
          for (int it = 0; it < 200; it++) {
            const double sm = 0.5 * (s0 + s1);
            if (!(sm > s0 && sm < s1)) break;
            lit_seg_point(&L, t, A, B, sm, X[0]);
            if (smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[0], 1.0, 0, &lights, NULL,
                               NULL) == g0)
              s0 = sm;
            else
              s1 = sm;
          }
          borders++;
          /* stretches of n points: the border's two at slots f and f + 1 (or f + 2), the
             others along the segment */
          const int n = 2 + (t + 3 * k + j) % 8, f = (t + k + 2 * j) % (n - 1);
          const int f1 = f + 2 < n && (t + j) % 2 ? f + 2 : f + 1;
          unsigned blocked[SMOOTH_ROW];
          for (int p = 0; p < n; p++) {
            const double sp = p == f ? s0 : p == f1 ? s1 : (p + 0.5) / n;
            lit_seg_point(&L, t, A, B, sp, X[p]);
            blocked[p] = 0;
          }
          const int tri[1] = { t }, at[2] = { 0, n };
          double xu[SMOOTH_ROW], xw[SMOOTH_ROW];
          for (int p = 0; p < n; p++) {
            xu[p] = X[p][L.m.tri[t].bu];
            xw[p] = X[p][L.m.tri[t].bw];
          }
          long dec[3] = { 0, 0, 0 };
          /* AVX-512F and VL's build, AVX's (partial_ymm; each where the processor has
             it), SSE2's */
          for (int way = 0; way < 3; way++) {
            int g[SMOOTH_ROW];
            long regions[3] = { 0, 0, 0 };
            L.m.rows_sse2 = way == 1;
            L.m.partial_ymm = way == 2;
            L.m.lit_declines = &dec[way];
            smooth_partial_row(&L.m, &L.r.map, 1, tri, at, xu, xw, blocked, &lights, g,
                               regions);
            L.m.lit_declines = NULL;
            L.m.rows_sse2 = L.m.partial_ymm = false;
            for (int p = 0; p < n; p++)
              differ += g[p] != smooth_grey_at(&L.m, &L.r.map, L.s, &L.e, t, X[p], 1.0, 0,
                                               &lights, NULL, NULL);
          }
          differ += (dec[0] != dec[1]) + (dec[0] != dec[2]);
          declined_rows += dec[0] > 0;
          rows++;
          points += n;
        }
      }
    }
    lib_close(&L);
  }
  print_message("partial rows at lit borders: %ld borders, %ld rows (%ld points), %ld with "
                "declines\n", borders, rows, points, declined_rows);
  assert_int_equal(differ, 0);
  assert_true(rows > 500);
  assert_true(declined_rows * 10 > rows * 9);
}

/* fx_round_ld (effects/poly.h, the shadows' grid points) is llroundl: at integers and
   halves and the long doubles next to them on both sides, positive and negative, from 0
   to 2^61, at random long doubles, and past 2^62 (the library's way). */
static void test_round_ld_is_llroundl(void **state)
{
  (void)state;
  long checked = 0, differ = 0;
  uint64_t seed = 99;
  for (int e = 0; e <= 61; e++)
    for (int j = -2; j <= 2; j++) {
      const long double k = ldexpl(1, e) + j;
      const long double d[] = { 0, 0.5L, 0.25L, 0.75L, nextafterl(0.5L, 0), nextafterl(0.5L, 1),
                                nextafterl(1, 0) };
      for (size_t q = 0; q < sizeof d / sizeof *d; q++)
        for (int sg = -1; sg <= 1; sg += 2) {
          const long double x[3] = { sg * (k + d[q]), nextafterl(sg * (k + d[q]), 0),
                                     nextafterl(sg * (k + d[q]), sg * INFINITY) };
          for (int m = 0; m < 3; m++) {
            differ += fx_round_ld(x[m]) != (gcoord)llroundl(x[m]);
            checked++;
          }
        }
    }
  for (int r = 0; r < 100000; r++) {
    seed = seed * 6364136223846793005u + 1442695040888963407u;
    const long double x = ldexpl((long double)(int64_t)seed, -(int)(seed >> 58) - 8);
    differ += fx_round_ld(x) != (gcoord)llroundl(x);
    checked++;
  }
  const long double big[] = { 0x1p62L, -0x1p62L, 0x1p62L + 3, -0x1.8p62L };
  for (size_t q = 0; q < sizeof big / sizeof *big; q++) {
    differ += fx_round_ld(big[q]) != (gcoord)llroundl(big[q]);
    checked++;
  }
  print_message("fx_round_ld: %ld values, %ld differ\n", checked, differ);
  assert_int_equal(differ, 0);
}

/* Two models the same, bit for bit (the kept scene part against a fresh build). */
static void same_model(const struct smooth_model *a, const struct smooth_model *b, int nface)
{
  assert_int_equal(a->ntri, b->ntri);
  assert_int_equal(a->objects, b->objects);
  assert_int_equal(a->flips, b->flips);
  assert_int_equal(a->conflicts, b->conflicts);
  assert_int_equal(a->vertex_normals, b->vertex_normals);
  for (int t = 0; t < a->ntri; t++) {
    const struct smooth_tri *x = &a->tri[t], *y = &b->tri[t];
    assert_int_equal(x->sface, y->sface);
    assert_int_equal(x->mface, y->mface);
    assert_int_equal(x->object, y->object);
    assert_memory_equal(x->v, y->v, sizeof x->v);
    assert_memory_equal(x->ni, y->ni, sizeof x->ni);
    assert_int_equal(x->front, y->front);
    assert_memory_equal(x->n, y->n, sizeof x->n);
    assert_memory_equal(x->cn, y->cn, sizeof x->cn);
    assert_memory_equal(x->t, y->t, sizeof x->t);
    assert_memory_equal(x->len, y->len, sizeof x->len);
    assert_memory_equal(x->bV, y->bV, sizeof x->bV);
    assert_memory_equal(x->bE, y->bE, sizeof x->bE);
    assert_true(x->area2 == y->area2 && x->btot == y->btot);
    assert_true(x->bu == y->bu && x->bw == y->bw);
  }
  assert_memory_equal(a->tri_of_mface, b->tri_of_mface, (size_t)nface * sizeof *a->tri_of_mface);
  assert_int_equal(a->ngroup, b->ngroup);
  if (a->ntri)
    assert_memory_equal(a->edge_group, b->edge_group, 3 * (size_t)a->ntri * sizeof *a->edge_group);
  /* each side's group is the side's two vertices: two sides share one exactly when they
     join the same two vertices in the same object */
  for (int p = 0; p < 3 * a->ntri; p++)
    for (int q = p + 1; q < 3 * a->ntri; q++) {
      const struct smooth_tri *x = &a->tri[p / 3], *y = &a->tri[q / 3];
      int x0 = x->v[p % 3], x1 = x->v[(p % 3 + 1) % 3], y0 = y->v[q % 3], y1 = y->v[(q % 3 + 1) % 3];
      bool same = x->object == y->object &&
                  ((x0 == y0 && x1 == y1) || (x0 == y1 && x1 == y0));
      assert_int_equal(same, a->edge_group[p] == a->edge_group[q]);
    }
}

/* The model built with the scene's part kept from an earlier frame (issue 19): the same
   as a fresh build on a second frame, after another scene (remade), and after the eye
   moves to the other side of an open surface (turned anew, the part only kept). */
static void test_kept_scene_part(void **state)
{
  (void)state;
  struct t74_error err = { 0, "" };
  struct smooth_scene *keep = NULL;
  struct smooth_model k;
  struct lib L;
  lib_open(&L, "scenes/sphere.s74", "smooth=phong contour=1.0");
  assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  assert_non_null(keep);
  same_model(&k, &L.m, L.r.map.nface);
  smooth_model_free(&k);
  struct smooth_scene *made = keep;
  assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  assert_ptr_equal(keep, made);                      /* taken, not made again */
  same_model(&k, &L.m, L.r.map.nface);
  /* while k holds the kept triangles, another model gets its own: the same model, and
     k's left as they were */
  struct smooth_model k2;
  assert_int_equal(smooth_model_build_kept(&k2, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  assert_true(k2.tri != k.tri && k2.lent == NULL && k.lent == keep);
  same_model(&k2, &L.m, L.r.map.nface);
  smooth_model_free(&k2);
  same_model(&k, &L.m, L.r.map.nface);
  smooth_model_free(&k);
  /* another smooth= on the same scene and keep: the insets made again (each kind against
     a fresh build), then back to the first */
  const enum effects_smooth kinds[] = { EFFECTS_SMOOTH_FIXED, EFFECTS_SMOOTH_PROP,
                                        EFFECTS_SMOOTH_PROP, EFFECTS_SMOOTH_PHONG };
  const double cs[] = { 0.15, 0.3, 0.2, 0 };
  const struct effects e0 = L.e;
  for (size_t q = 0; q < sizeof kinds / sizeof *kinds; q++) {
    struct smooth_model fresh;
    L.e.smooth = kinds[q];
    L.e.smooth_c = cs[q] ? cs[q] : e0.smooth_c;
    assert_int_equal(smooth_model_build(&fresh, &L.r.map, L.s, &L.e, &err), T74_OK);
    assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
    assert_ptr_equal(k.lent, keep);
    same_model(&k, &fresh, L.r.map.nface);
    smooth_model_free(&k);
    smooth_model_free(&fresh);
  }
  L.e = e0;
  /* another scene (the first still loaded: a part lives no longer than its scene): the
     part is made for it, freeing the first's */
  struct lib L2;
  lib_open(&L2, "scenes/lprism.s74", "smooth=prop:0.15");
  assert_int_equal(smooth_model_build_kept(&k, &L2.r.map, L2.s, &L2.e, &keep, &err), T74_OK);
  assert_true(keep != made);
  same_model(&k, &L2.m, L2.r.map.nface);
  smooth_model_free(&k);
  smooth_scene_free(keep);
  keep = NULL;
  lib_close(&L2);
  lib_close(&L);
  /* an open sheet in the plane x = 0 seen from either side */
  write_text("sheet.s74", "view -600 0 -1000\nwindow -200 -150 200 150\nlight -45 60 -80\n"
             "vertex 1 0 -50 100\nvertex 2 0 50 100\nvertex 3 0 50 300\nvertex 4 0 -50 300\n"
             "face 1 1 2 3\nface 2 1 3 4\nobject 1 1 2\neffects smooth=phong\n");
  lib_open(&L, tpath("sheet.s74"), "smooth=phong");
  assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  same_model(&k, &L.m, L.r.map.nface);
  int v1[3];
  memcpy(v1, L.m.tri[0].v, sizeof v1);
  smooth_model_free(&k);
  made = keep;
  L.s->view[0] = 600;                                /* the other side */
  smooth_model_free(&L.m);
  render_free(&L.r);
  struct render_opts o;
  memset(&o, 0, sizeof o);
  o.core_words = 1u << 20;
  assert_int_equal(render_prepare(&L.r, L.s, &o, &err), T74_OK);
  assert_int_equal(smooth_model_build(&L.m, &L.r.map, L.s, &L.e, &err), T74_OK);
  assert_true(memcmp(v1, L.m.tri[0].v, sizeof v1) != 0);   /* turned the other way */
  assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  assert_ptr_equal(keep, made);
  same_model(&k, &L.m, L.r.map.nface);
  smooth_model_free(&k);
  /* and back to the first side: turned back in the kept triangles */
  L.s->view[0] = -600;
  smooth_model_free(&L.m);
  render_free(&L.r);
  assert_int_equal(render_prepare(&L.r, L.s, &o, &err), T74_OK);
  assert_int_equal(smooth_model_build(&L.m, &L.r.map, L.s, &L.e, &err), T74_OK);
  assert_memory_equal(v1, L.m.tri[0].v, sizeof v1);
  assert_int_equal(smooth_model_build_kept(&k, &L.r.map, L.s, &L.e, &keep, &err), T74_OK);
  assert_ptr_equal(k.lent, keep);
  same_model(&k, &L.m, L.r.map.nface);
  smooth_model_free(&k);
  smooth_scene_free(keep);
  lib_close(&L);
}

/* An open surface whose faces are given facing away is turned towards the eye a frame at
   a time, its geometry carried over from the kept part (sign changes and corners
   swapped): the model, bit for bit, of the same surface given facing the eye; and a
   later frame of --frames draws the first's picture. */
static void test_turned_is_given(void **state)
{
  (void)state;
  assert_int_equal(write_turned("scenes/sphere.s74", tpath("away.s74"), 1), 160);
  /* through the program: a third frame (the scene's part kept from the first) draws the
     picture a single frame draws, under both engines */
  const char *engs[] = { "--engine points", "--engine 1974" };
  for (size_t k = 0; k < 2; k++) {
    char one[64], three[64];
    snprintf(one, sizeof one, "%s --frames 1", engs[k]);
    snprintf(three, sizeof three, "%s --frames 3", engs[k]);
    struct out a, b;
    render_with(tpath("away.s74"), NULL, one, &a);
    render_with(tpath("away.s74"), NULL, three, &b);
    size_t n = (size_t)a.W * (size_t)a.H;
    assert_memory_equal(a.ids, b.ids, n * sizeof *a.ids);
    assert_memory_equal(a.grey, b.grey, n);
    assert_int_equal(a.tube_len, b.tube_len);
    assert_memory_equal(a.tube, b.tube, a.tube_len);
    out_free(&a); out_free(&b);
  }
  struct lib given, away;
  const char *effs[] = { "smooth=phong contour=1.0", "smooth=fixed:0.15", "smooth=prop:0.3" };
  for (size_t k = 0; k < sizeof effs / sizeof *effs; k++) {
    lib_open(&given, "scenes/sphere.s74", effs[k]);
    lib_open(&away, tpath("away.s74"), effs[k]);
    assert_int_equal(given.m.ntri, 160);
    same_model(&away.m, &given.m, given.r.map.nface);
    lib_close(&away);
    lib_close(&given);
  }
}

static void test_continuous_inside(void **state)
{
  (void)state;
  struct lib L;
  lib_open(&L, "scenes/t1-d.s74", "smooth=fixed:0.15");
  unsigned seed = 12345;
  int regions[3] = { 0, 0, 0 };
  for (int t = 0; t < L.m.ntri; t++)
    for (int k = 0; k < 2000; k++) {
      seed = seed * 1103515245u + 12345u;
      double u = (seed >> 8) / 16777216.0;
      seed = seed * 1103515245u + 12345u;
      double v = (seed >> 8) / 16777216.0;
      if (u + v > 1) { u = 1 - u; v = 1 - v; }
      double l[3] = { u, v, 1 - u - v }, n0[3], n1[3];
      int r = smooth_partial_normal(&L.m.tri[t], l, n0);
      regions[r]++;
      const double d = 1e-7;
      double l2[3] = { u + d, v, 1 - u - v - d };
      if (l2[2] < 0) continue;
      normal_at(&L.m.tri[t], l, n0);
      normal_at(&L.m.tri[t], l2, n1);
      for (int c = 0; c < 3; c++) assert_true(fabs(n0[c] - n1[c]) < 1e-4);
    }
  assert_true(regions[0] > 0 && regions[1] > 0 && regions[2] > 0);
  lib_close(&L);
}

static void test_lambert_is_the_mappers(void **state)
{
  (void)state;
  struct lib L;
  lib_open(&L, "scenes/sphere.s74", "smooth=phong");
  double l[3] = { (double)L.s->light[0].v[0], (double)L.s->light[0].v[1], (double)L.s->light[0].v[2] };
  double ll = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  for (int c = 0; c < 3; c++) l[c] /= ll;
  int checked = 0;
  for (int t = 0; t < L.m.ntri; t++) {
    const struct smooth_tri *tr = &L.m.tri[t];
    if (tr->mface < 0) continue;
    double sg = tr->front ? 1 : -1, n[3] = { sg * tr->n[0], sg * tr->n[1], sg * tr->n[2] };
    assert_int_equal(smooth_lambert(n, l), L.r.map.f[tr->mface].grey);
    checked++;
  }
  assert_true(checked > 50);
  lib_close(&L);
}

static void test_insets(void **state)
{
  (void)state;
  double len[3] = { 3, 4, 5 }, t[3];
  smooth_insets(EFFECTS_SMOOTH_PROP, 0.15, 0, len, 12, t);   /* right triangle, area 6 */
  for (int k = 0; k < 3; k++) assert_true(t[k] == 0.15);
  /* fixed: width w over the height on each side (2 area / side) */
  smooth_insets(EFFECTS_SMOOTH_FIXED, 0, 0.6, len, 12, t);
  assert_true(fabs(t[0] - 0.6 / 4) < 1e-12 && fabs(t[1] - 0.6 / 3) < 1e-12 &&
              fabs(t[2] - 0.6 / 2.4) < 1e-12);
  /* too wide: scaled to sum 1 */
  smooth_insets(EFFECTS_SMOOTH_PROP, 0.5, 0, len, 12, t);
  assert_true(fabs(t[0] + t[1] + t[2] - 1) < 1e-12);
}

static void test_bezier(void **state)
{
  (void)state;
  const double ccs[] = { 0.0, 0.1, 0.3, 0.5, 0.8, 1.0 };
  const double q0[2] = { 1000, 200 }, q2[2] = { 3000, 900 }, q4[2] = { 2600, 4100 };
  for (size_t k = 0; k < sizeof ccs / sizeof *ccs; k++) {
    double q[5][2], p[2], d[2];
    contour_controls(q0, q2, q4, ccs[k], q);
    contour_bezier(q, 0, p);
    assert_true(p[0] == q0[0] && p[1] == q0[1]);
    contour_bezier(q, 1, p);
    assert_true(p[0] == q4[0] && p[1] == q4[1]);
    /* tangents along the contour sides (Q0 -> Q2 at the start, Q2 -> Q4 at the end),
       pointing the right way; for Cc = 1 the start tangent vanishes (Q1 = Q0) */
    double a[2] = { q2[0] - q0[0], q2[1] - q0[1] }, b[2] = { q4[0] - q2[0], q4[1] - q2[1] };
    contour_bezier_d(q, 0, d);
    assert_true(fabs(d[0] * a[1] - d[1] * a[0]) < 1e-6 * (fabs(d[0]) + fabs(d[1]) + 1) * 5000);
    if (ccs[k] < 1) assert_true(d[0] * a[0] + d[1] * a[1] > 0);
    contour_bezier_d(q, 1, d);
    assert_true(fabs(d[0] * b[1] - d[1] * b[0]) < 1e-6 * (fabs(d[0]) + fabs(d[1]) + 1) * 5000);
    if (ccs[k] < 1) assert_true(d[0] * b[0] + d[1] * b[1] > 0);
    /* the area between the corner and the curve: numerically (Green, on the curve; the
       two straight sides through Q2 add nothing about Q2), against the closed form */
    double tri = 0.5 * fabs(a[0] * b[1] - a[1] * b[0]), num = 0;
    const int N = 20000;
    for (int m = 0; m < N; m++) {
      double p0[2], p1[2];
      contour_bezier(q, (double)m / N, p0);
      contour_bezier(q, (double)(m + 1) / N, p1);
      num += 0.5 * ((p0[0] - q2[0]) * (p1[1] - q2[1]) - (p1[0] - q2[0]) * (p0[1] - q2[1]));
    }
    assert_true(fabs(fabs(num) / tri - contour_cut_share(ccs[k])) < 1e-6);
    /* and the grid polygon the renderer cuts with */
    struct gpoint g[5], poly[CONTOUR_STEPS + 2];
    for (int c = 0; c < 5; c++) { g[c].x = (gcoord)llround(q[c][0]); g[c].y = (gcoord)llround(q[c][1]); }
    contour_region(g, poly);
    assert_true(poly[0].x == g[2].x && poly[0].y == g[2].y);
    assert_true(poly[1].x == g[4].x && poly[1].y == g[4].y);
    assert_true(poly[CONTOUR_STEPS + 1].x == g[0].x && poly[CONTOUR_STEPS + 1].y == g[0].y);
    double sh = 0;
    for (int v = 0; v < CONTOUR_STEPS + 2; v++) {
      struct gpoint u = poly[v], w = poly[(v + 1) % (CONTOUR_STEPS + 2)];
      sh += 0.5 * ((double)u.x * (double)w.y - (double)w.x * (double)u.y);
    }
    print_message("Cc %.1f: share %.5f, polygon %.5f, closed form %.5f\n", ccs[k],
                  fabs(num) / tri, fabs(sh) / tri, contour_cut_share(ccs[k]));
    assert_true(fabs(fabs(sh) / tri - contour_cut_share(ccs[k])) < 2e-3);
  }
  assert_true(fabs(contour_cut_share(0.5) - 0.2) < 1e-15);
}

/* The curve polygon's points (contour_region: a point's x and y an instruction) are
   contour_bezier's at t = m / CONTOUR_STEPS rounded half away from zero, bit for bit, for
   5,600 random corners of control points up to 2^52 grid units (where a result one unit
   in the last place off rounds to another integer) and beyond, up to 2^62 (control points
   from 2^61 on: each point by round_grid's test, not without it), on a corner whose
   points at odd m lie halfway between two integers, and on 2,000 corners whose coordinates
   are drawn from +-(2^29 - 1), +-2^29, 0 and small values: the largest the curve's integer
   path (region_exact, below 2^29) takes and the smallest it leaves to the doubles. */
static void test_region_is_bezier(void **state)
{
  (void)state;
  uint64_t x = 0x9e3779b97f4a7c15u;
  long differ = 0, points = 0;
  static const gcoord edge[8] = { (1 << 29) - 1, -(1 << 29) + 1, 1 << 29, -(1 << 29), 0, 1, -1, 3 };
  for (int it = 0; it < 7600; it++) {
    struct gpoint g[5], poly[CONTOUR_STEPS + 2];
    double q[5][2];
    const int bits = 8 + it % 56;
    for (int k = 0; k < 5; k++) {
      x ^= x << 13; x ^= x >> 7; x ^= x << 17;
      g[k].x = (gcoord)(x % (1ull << bits)) - (gcoord)(1ull << (bits - 1));
      x ^= x << 13; x ^= x >> 7; x ^= x << 17;
      g[k].y = (gcoord)(x % (1ull << bits)) - (gcoord)(1ull << (bits - 1));
      if (it >= 5600) {                     /* the integer path's bounds */
        g[k].x = edge[(x >> 3) % (it % 2 ? 8 : 2)];
        g[k].y = edge[(x >> 7) % (it % 2 ? 8 : 2)];
      }
      /* the first corner: Q0 at (2^23, -2^23), the rest at 0, so that each point at an
         odd 64 - m lies on a half, (64 - m)^4 / 2 and its negative: the ties */
      if (it == 0) g[k] = k ? (struct gpoint){ 0, 0 } : (struct gpoint){ 1 << 23, -(1 << 23) };
      q[k][0] = (double)g[k].x;
      q[k][1] = (double)g[k].y;
    }
    contour_region(g, poly);
    for (int m = 1; m < CONTOUR_STEPS; m++) {
      double o[2];
      contour_bezier(q, (double)m / CONTOUR_STEPS, o);
      const struct gpoint p = poly[1 + CONTOUR_STEPS - m];
      differ += p.x != (gcoord)llround(o[0]) || p.y != (gcoord)llround(o[1]);
      points++;
    }
  }
  print_message("curve polygons: %ld points, %ld differ\n", points, differ);
  assert_int_equal(differ, 0);
}

/* The region polygon's blocks and box made on the way (contour_region_blocked: on the
   integer path, in doubles a lane for x and one for y) are fx_ring_blocks' over the
   polygon contour_region makes, block by block, and the polygon the same: 6,000 random
   corners of control points from 2^4 to 2^62 grid units (either path), and 2,000 from
   +-(2^29 - 1), +-2^29, 0 and small values (the integer path's bounds, where a point
   within 2^29 of the origin is the largest the doubles' bits carry); the extremes fall on
   Q0, Q2, Q4 (poly[65], poly[0], poly[1]) and on the curve, and on the block ends each
   block shares with the next. Fails if a block misses its last point (poly[8 b + 8], or
   poly[0] for the last), a lane's min or max, or a point's conversion. Both ways where the
   processor has AVX-512 (four points a step, region_exact512; and contour_region_sse2):
   the same polygon, blocks and box byte for byte. */
static void test_region_blocks(void **state)
{
  (void)state;
  uint64_t x = 0x2545f4914f6cdd1du;
  long differ = 0, exact = 0;
  static const gcoord edge[8] = { (1 << 29) - 1, -(1 << 29) + 1, 1 << 29, -(1 << 29), 0, 1, -1, 3 };
  enum { NB = (CONTOUR_STEPS + 2 + FX_POLY_BLOCK - 1) / FX_POLY_BLOCK };
  for (int it = 0; it < 8000; it++) {
    struct gpoint g[5], poly[CONTOUR_STEPS + 2], ref[CONTOUR_STEPS + 2];
    const int bits = 5 + it % 58;
    bool small = true;
    for (int k = 0; k < 5; k++) {
      x ^= x << 13; x ^= x >> 7; x ^= x << 17;
      g[k].x = (gcoord)(x % (1ull << bits)) - (gcoord)(1ull << (bits - 1));
      x ^= x << 13; x ^= x >> 7; x ^= x << 17;
      g[k].y = (gcoord)(x % (1ull << bits)) - (gcoord)(1ull << (bits - 1));
      if (it >= 6000) {
        g[k].x = edge[(x >> 3) % (it % 2 ? 8 : 4)];
        g[k].y = edge[(x >> 9) % (it % 2 ? 8 : 4)];
      }
      small = small && llabs(g[k].x) < (1 << 29) && llabs(g[k].y) < (1 << 29);
    }
    exact += small;
    gcoord blk[NB + 1][2], box[4], rblk[NB][2];
    gcoord rbox[4] = { INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN };
    blk[NB][0] = blk[NB][1] = 12345;          /* nothing written past the blocks */
    const int nb = contour_region_blocked(g, poly, blk, box);
    contour_region(g, ref);
    const size_t rnb = fx_ring_blocks(ref, CONTOUR_STEPS + 2, rblk, 0, rbox);
    bool bad = nb != NB || rnb != NB || memcmp(poly, ref, sizeof poly) != 0 ||
               memcmp(box, rbox, sizeof box) != 0 || blk[NB][0] != 12345 || blk[NB][1] != 12345;
    for (int b = 0; b < NB && !bad; b++) bad = blk[b][0] != rblk[b][0] || blk[b][1] != rblk[b][1];
    /* and the build's own way (where the processor has AVX-512, the one above is
       region_exact512's on the integer path): the same polygon, blocks and box */
    struct gpoint p2[CONTOUR_STEPS + 2];
    gcoord blk2[NB + 1][2], box2[4];
    blk2[NB][0] = blk2[NB][1] = 12345;
    const int nb2 = contour_region_sse2(g, p2, blk2, box2);
    bad = bad || nb2 != NB || memcmp(p2, poly, sizeof p2) != 0 || memcmp(blk2, blk, sizeof blk2) != 0 ||
          memcmp(box2, box, sizeof box2) != 0;
    differ += bad;
  }
  print_message("region blocks: %ld corners (%ld on the integer path), %ld differ\n", 8000L,
                exact, differ);
  assert_true(exact > 2500);
  assert_int_equal(differ, 0);
}

/* A polygon's crossings with a line, found edge by edge (fx_poly_cross's answer without
   its blocks): the crossings sorted stably, their count, or -1 past max. */
static int cross_ref(const struct fx_poly *p, int64_t yn, int64_t yd, struct grat *x, int max)
{
  const int64_t fy = fx_line_row(yn, yd);
  int nx = 0;
  for (int r = 0; r < p->nring; r++) {
    const int a = p->rs[r], n = p->rs[r + 1] - a;
    for (int v = 0; v < n; v++) {
      const struct gpoint p0 = p->pt[a + v], p1 = p->pt[a + (v + 1) % n];
      if ((p0.y <= fy) == (p1.y <= fy)) continue;
      if (nx == max) return -1;
      const struct grat xc = geom_x_at(geom_line(p0, p1), yn, yd);
      int h = nx++;
      while (h > 0 && geom_rat_cmp(x[h - 1], xc) > 0) { x[h] = x[h - 1]; h--; }
      x[h] = xc;
    }
  }
  return nx;
}

/* fx_poly_cross passes a block of edges whose points lie on one side of the line (issue
   19): the same crossings as edge by edge, on every row through contour regions and
   rings of many points, points on the rows, horizontal edges, a last block short. */
static void test_region_crossings(void **state)
{
  (void)state;
  struct fx_polys ps = { 0 };
  const gcoord U = GRID_ONE / 4;
  const struct gpoint ctl[3][5] = {
    { { 10 * U, 2 * U }, { 14 * U, 5 * U }, { 30 * U, 9 * U }, { 27 * U, 20 * U }, { 26 * U, 41 * U } },
    { { 0, 0 }, { 3 * U, 0 }, { 9 * U, 0 }, { 9 * U, 4 * U }, { 9 * U, 12 * U } },
    { { 5 * U, 30 * U }, { 6 * U, 12 * U }, { 7 * U, -7 * U }, { 20 * U, -2 * U }, { 40 * U, 3 * U } } };
  for (int c = 0; c < 3; c++) {
    struct gpoint poly[CONTOUR_STEPS + 2];
    contour_region(ctl[c], poly);
    const int rs[2] = { 0, CONTOUR_STEPS + 2 };
    assert_true(fx_polys_add(&ps, 1, rs, poly, c, 0));
  }
  /* two rings of a zigzag (19 and 26 points, on whole rows and between), a hole */
  struct gpoint z[45];
  unsigned seed = 7;
  for (int v = 0; v < 45; v++) {
    seed = seed * 1103515245u + 12345u;
    const int ring = v >= 19, k = ring ? v - 19 : v, n = ring ? 26 : 19;
    const double t = 6.283185307179586 * k / n, rad = (ring ? 6 : 16) + (double)(seed >> 28);
    z[v].x = (gcoord)(rad * cos(t) * (double)U);
    z[v].y = seed & 0x100 ? (gcoord)llround(rad * sin(t)) * U : (gcoord)(rad * sin(t) * (double)U);
  }
  const int zr[3] = { 0, 19, 45 };
  assert_true(fx_polys_add(&ps, 2, zr, z, 3, 0));
  /* a ring of two points (dropped, far outside) before a region: not in the box */
  struct gpoint dz[2 + CONTOUR_STEPS + 2] = { { -900 * U, 900 * U }, { 900 * U, -900 * U } };
  contour_region(ctl[0], dz + 2);
  const int dr[3] = { 0, 2, 2 + CONTOUR_STEPS + 2 };
  assert_true(fx_polys_add(&ps, 2, dr, dz, 4, 0));
  assert_int_equal(ps.p[4].nring, 1);
  for (int k = 0; k < ps.n; k++) {                /* each box: its points' */
    const struct fx_poly *p = &ps.p[k];
    gcoord b[4] = { p->pt[0].x, p->pt[0].x, p->pt[0].y, p->pt[0].y };
    for (int v = 1; v < p->rs[p->nring]; v++) {
      b[0] = p->pt[v].x < b[0] ? p->pt[v].x : b[0];
      b[1] = p->pt[v].x > b[1] ? p->pt[v].x : b[1];
      b[2] = p->pt[v].y < b[2] ? p->pt[v].y : b[2];
      b[3] = p->pt[v].y > b[3] ? p->pt[v].y : b[3];
    }
    assert_true(p->xlo == b[0] && p->xhi == b[1] && p->ylo == b[2] && p->yhi == b[3]);
  }
  long rows = 0, crossings = 0;
  struct cost cost = { { 0 } };
  for (int k = 0; k < ps.n; k++) {
    const struct fx_poly *p = &ps.p[k];
    for (int64_t yd = 1; yd <= 3; yd += 2)
      for (int64_t yn = (p->ylo - 2) * yd; yn <= (p->yhi + 2) * yd; yn += U / 8 + 1) {
        struct grat a[80], b[80];
        const int na = fx_poly_cross(p, yn, yd, a, 80, &cost), nb = cross_ref(p, yn, yd, b, 80);
        assert_int_equal(na, nb);
        for (int h = 0; h < na; h++) assert_true(a[h].num == b[h].num && a[h].den == b[h].den);
        assert_int_equal(fx_poly_cross(p, yn, yd, a, 1, &cost), cross_ref(p, yn, yd, b, 1));
        rows++;
        crossings += na;
      }
  }
  print_message("%ld lines, %ld crossings\n", rows, crossings);
  assert_true(rows > 1000 && crossings > 2 * rows / 3);
  fx_polys_free(&ps);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_zero_band_is_flat),
    cmocka_unit_test(test_flat_share),
    cmocka_unit_test(test_whole_is_phong),
    cmocka_unit_test(test_contour_none),
    cmocka_unit_test(test_cut_area_closed_form),
    cmocka_unit_test(test_cut_shows_what_is_behind),
    cmocka_unit_test(test_contour_junction),
    cmocka_unit_test(test_concave_vertex_kept),
    cmocka_unit_test(test_lone_triangle_is_flat),
    cmocka_unit_test(test_nothing_to_smooth_warns),
    cmocka_unit_test(test_orientation),
    cmocka_unit_test(test_core_limit),
    cmocka_unit_test(test_no_seams),
    cmocka_unit_test(test_run_is_single),
    cmocka_unit_test(test_row_is_single),
    cmocka_unit_test(test_phong_rows_long),
    cmocka_unit_test(test_row_band_pairs),
    cmocka_unit_test(test_edge_pairs_are_single),
    cmocka_unit_test(test_band_lanes_selections),
    cmocka_unit_test(test_flat_run_is_single),
    cmocka_unit_test(test_phong_filter_is_exact),
    cmocka_unit_test(test_phong_filter_range),
    cmocka_unit_test(test_phong_filter_tiny_sum),
    cmocka_unit_test(test_phong_rows_borders),
    cmocka_unit_test(test_phong_rows_tiny_sum),
    cmocka_unit_test(test_inner_filter_is_exact),
    cmocka_unit_test(test_lit_filter_is_exact),
    cmocka_unit_test(test_partial_row_lit_borders),
    cmocka_unit_test(test_round_ld_is_llroundl),
    cmocka_unit_test(test_kept_scene_part),
    cmocka_unit_test(test_turned_is_given),
    cmocka_unit_test(test_continuous_inside),
    cmocka_unit_test(test_lambert_is_the_mappers),
    cmocka_unit_test(test_insets),
    cmocka_unit_test(test_bezier),
    cmocka_unit_test(test_region_is_bezier),
    cmocka_unit_test(test_region_blocks),
    cmocka_unit_test(test_region_crossings),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
