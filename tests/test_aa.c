/*
** test_aa.c — tests of the anti-aliasing methods (effects/aa*.c; papers 000 and 001).
**
** Each scene here lies flat on the plane z = 0 (seen straight on, so the plane is the
** picture) in a window of 40000 x 30000 world units: with cell 4 a point is 400 units,
** so vertices fall on a 1/400-point grid and the coverages expected are computed here,
** independently, by clipping each point's square against the face (double precision).
** Light is compared, not grey: a white face (255) on black shows light = coverage.
**
** Known areas: half-planes at many slopes and triangles (exact against clipping), a
** polygon and its complement summing to one, a flat field giving exactly its grey for
** every method. Multiscan box within 1/(2n) of exact where one edge crosses a point's
** top and bottom, its error falling with n; the F table's volume; the area table and
** area sampling on single-edge points within 1/64; stacked faces (the hidden one never
** shows); aa=exact with the frame model's regions, against clipping: a shadow (paper 000
** §3) and the corners a contour cut takes away (paper 004); the slivers of paper 000
** Fig. 3; the command line's refusal and exit 3.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "patterns/halftone.h"
#include "effects/aa.h"
#include "effects/contour.h"
#include "render/render.h"
#include "render/scene.h"

#define UX(u) ((int)lround(-20000 + 400.0 * (u)))     /* point units -> world */
#define VY(v) ((int)lround(15000 - 400.0 * (v)))
#define W4 100
#define H4 75

static char dir[64];
static int nscene;

struct tface { int n; double u[8], v[8]; int z, grey; int hole_n; double hu[8], hv[8]; };

/* Write a scene of the faces given; returns its path (static buffer per call slot). */
static const char *scene(const struct tface *f, int nf)
{
  static char path[8][128];
  char *p = path[nscene % 8];
  snprintf(p, 128, "%s/s%d.s74", dir, nscene++);
  FILE *o = fopen(p, "w");
  assert_non_null(o);
  fprintf(o, "view 0 0 -1000\nwindow -20000 -15000 20000 15000\n");
  int vid = 1;
  for (int k = 0; k < nf; k++) {
    int first = vid;
    for (int m = 0; m < f[k].n; m++)
      fprintf(o, "vertex %d %d %d %d\n", vid++, UX(f[k].u[m]), VY(f[k].v[m]), f[k].z);
    int hfirst = vid;
    for (int m = 0; m < f[k].hole_n; m++)
      fprintf(o, "vertex %d %d %d %d\n", vid++, UX(f[k].hu[m]), VY(f[k].hv[m]), f[k].z);
    fprintf(o, "face %d", k + 1);
    for (int m = 0; m < f[k].n; m++) fprintf(o, " %d", first + m);
    if (f[k].hole_n) {
      fprintf(o, " *");
      for (int m = 0; m < f[k].hole_n; m++) fprintf(o, " %d", hfirst + m);
    }
    fprintf(o, " grey %d\n", f[k].grey);
  }
  fclose(o);
  return p;
}

static void render(const char *path, const char *eff, struct aa_frame *fr)
{
  struct t74_error err = { 0, "" };
  int st = aa_frame_render(path, eff, 4, 1u << 20, fr, &err);
  if (st) print_message("%s: %s\n", eff, err.msg);
  assert_int_equal(st, T74_OK);
  assert_int_equal(fr->W, W4);
  assert_int_equal(fr->H, H4);
}

/* ---- independent coverage: a unit square clipped by a convex polygon (ccw or cw) ---- */

static double clip_area(double i, double j, const double *u, const double *v, int n)
{
  double px[40], py[40], qx[40], qy[40];
  int m = 4;
  px[0] = i; py[0] = j; px[1] = i + 1; py[1] = j; px[2] = i + 1; py[2] = j + 1; px[3] = i; py[3] = j + 1;
  double s = 0;
  for (int k = 0; k < n; k++) s += u[k] * v[(k + 1) % n] - u[(k + 1) % n] * v[k];
  double orient = s > 0 ? 1 : -1;
  for (int k = 0; k < n && m > 0; k++) {
    double ax = u[k], ay = v[k], bx = u[(k + 1) % n], by = v[(k + 1) % n];
    int q = 0;
    for (int e = 0; e < m; e++) {
      double cx = px[e], cy = py[e], dx = px[(e + 1) % m], dy = py[(e + 1) % m];
      double fc = orient * ((bx - ax) * (cy - ay) - (by - ay) * (cx - ax));
      double fd = orient * ((bx - ax) * (dy - ay) - (by - ay) * (dx - ax));
      if (fc >= 0) { qx[q] = cx; qy[q] = cy; q++; }
      if ((fc >= 0) != (fd >= 0)) {
        double t = fc / (fc - fd);
        qx[q] = cx + t * (dx - cx); qy[q] = cy + t * (dy - cy); q++;
      }
    }
    m = q;
    memcpy(px, qx, sizeof px);
    memcpy(py, qy, sizeof py);
  }
  double a = 0;
  for (int k = 0; k < m; k++) a += px[k] * py[(k + 1) % m] - px[(k + 1) % m] * py[k];
  return fabs(a) / 2;
}

/* snap to the 1/400 grid the scene file holds */
static double snap(double u) { return lround(u * 400) / 400.0; }

/* A half-plane: the box [-30, 130] x [-40, 115] (points) cut by the line through
   (cu, cv) at angle a (radians); the kept side is left of the direction. The line's two
   points go to hu/hv[0..1] (for crosses_top_bottom), snapped to the file's grid. */
static struct tface halfplane(double cu, double cv, double a)
{
  struct tface f = { 0 };
  double du = cos(a), dv = sin(a);
  double bx[4] = { -30, 130, 130, -30 }, by[4] = { -40, -40, 115, 115 };
  double p0u = snap(cu - 20 * du), p0v = snap(cv - 20 * dv);
  double p1u = snap(cu + 20 * du), p1v = snap(cv + 20 * dv);
  for (int k = 0; k < 4; k++) {
    double ax = bx[k], ay = by[k], cx = bx[(k + 1) % 4], cy = by[(k + 1) % 4];
    double fa = (p1u - p0u) * (ay - p0v) - (p1v - p0v) * (ax - p0u);
    double fc = (p1u - p0u) * (cy - p0v) - (p1v - p0v) * (cx - p0u);
    if (fa >= 0) { f.u[f.n] = ax; f.v[f.n] = ay; f.n++; }
    if ((fa >= 0) != (fc >= 0)) {
      double t = fa / (fa - fc);
      f.u[f.n] = snap(ax + t * (cx - ax)); f.v[f.n] = snap(ay + t * (cy - ay)); f.n++;
    }
  }
  /* the edge as the file holds it: the two snapped points on the line */
  for (int k = 0, m = 0; k < f.n && m < 2; k++) {
    double bu = f.u[k], bv = f.v[k];
    bool corner = (bu == -30 || bu == 130) && (bv == -40 || bv == 115);
    if (!corner) { f.hu[m] = bu; f.hv[m] = bv; m++; }
  }
  (void)p0u; (void)p0v; (void)p1u; (void)p1v;
  f.grey = 255;
  return f;
}

static double rnd(unsigned *s) { *s = *s * 1103515245u + 12345u; return ((*s >> 8) & 0xffffff) / 16777216.0; }

/* ---- light ------------------------------------------------------------------------------ */

static void test_light_roundtrip(void **state)
{
  (void)state;
  for (int cell = 3; cell <= 4; cell++) {
    assert_int_equal(aa_light(cell, 0), 0);
    assert_int_equal(aa_light(cell, 255), AA_LIGHT_ONE);
    for (int g = 0; g < 256; g++) {
      if (g) assert_true(aa_light(cell, g) > aa_light(cell, g - 1));
      assert_int_equal(aa_grey(cell, aa_light(cell, g) / (double)AA_LIGHT_ONE), g);
    }
  }
  /* mixing in light: a half-covered edge between 0 and 255 lights half the dots
     (the mean grey 128 would light 3 of 16) */
  assert_int_equal(pat_level(4, aa_grey(4, 0.5)), 8);
  assert_int_equal(pat_level(3, aa_grey(3, 0.5)), 5);
  assert_true(pat_level(4, 128) < 5);
}

/* ---- known areas ------------------------------------------------------------------------- */

static void test_halfplanes_exact(void **state)
{
  (void)state;
  unsigned seed = 7;
  for (int k = 0; k < 26; k++) {
    double a = k * (3.14159265358979 / 26) + 0.013;
    struct tface f = halfplane(50 + 10 * rnd(&seed), 37 + 8 * rnd(&seed), a);
    struct aa_frame fr;
    render(scene(&f, 1), "aa=exact", &fr);
    double worst = 0;
    for (int j = 0; j < H4; j++)
      for (int i = 0; i < W4; i++) {
        double want = clip_area(i, j, f.u, f.v, f.n);
        worst = fmax(worst, fabs(fr.light[j * W4 + i] - want));
      }
    aa_frame_free(&fr);
    if (worst > 1e-6) print_message("angle %d: %g\n", k, worst);
    assert_true(worst <= 1e-6);
  }
}

static void test_triangles_exact(void **state)
{
  (void)state;
  unsigned seed = 11;
  for (int k = 0; k < 12; k++) {
    struct tface f = { 3, { 0 }, { 0 }, 0, 255, 0, { 0 }, { 0 } };
    for (int m = 0; m < 3; m++) { f.u[m] = snap(5 + 90 * rnd(&seed)); f.v[m] = snap(5 + 65 * rnd(&seed)); }
    double ar = (f.u[1] - f.u[0]) * (f.v[2] - f.v[0]) - (f.u[2] - f.u[0]) * (f.v[1] - f.v[0]);
    if (fabs(ar) < 20) continue;
    struct aa_frame fr;
    render(scene(&f, 1), "aa=exact", &fr);
    double worst = 0, total = 0;
    for (int j = 0; j < H4; j++)
      for (int i = 0; i < W4; i++) {
        worst = fmax(worst, fabs(fr.light[j * W4 + i] - clip_area(i, j, f.u, f.v, 3)));
        total += fr.light[j * W4 + i];
      }
    aa_frame_free(&fr);
    assert_true(worst <= 1e-6);
    assert_true(fabs(total - fabs(ar) / 2) < 1e-4);
  }
}

/* A concave polygon P, and a rectangle over the whole window with P as its hole. */
static void test_complement(void **state)
{
  (void)state;
  struct tface p = { 7, { 20.3, 70.1, 55.7, 81.2, 33.3, 40.05, 12.9 },
                        { 10.2, 14.6, 30.3, 61.8, 58.1, 35.5, 44.4 }, 0, 255, 0, { 0 }, { 0 } };
  struct tface c = { 4, { -5, 105, 105, -5 }, { -5, -5, 80, 80 }, 0, 255, 7, { 0 }, { 0 } };
  memcpy(c.hu, p.u, sizeof p.u);
  memcpy(c.hv, p.v, sizeof p.v);
  const char *sp = scene(&p, 1), *sc = scene(&c, 1);
  static const char *const methods[] = {
    "aa=exact", "aa=multiscan n=3", "aa=multiscan n=6", "aa=multiscan filter=gauss n=3",
    "aa=super super=3 filter=box", "aa=super super=3", "aa=exact filter=gauss", "aa=area depth=3" };
  for (size_t m = 0; m < sizeof methods / sizeof *methods; m++) {
    struct aa_frame a, b;
    render(sp, methods[m], &a);
    render(sc, methods[m], &b);
    double worst = 0, inside = 0;
    for (int k = 0; k < W4 * H4; k++) {
      worst = fmax(worst, fabs(a.light[k] + b.light[k] - 1));
      inside += a.light[k];
    }
    aa_frame_free(&a);
    aa_frame_free(&b);
    /* area sampling classifies the two pictures differently (the hole's face is cut in
       convex pieces whose inner boundaries make it divide): within its table's 1/64 */
    double tol = strstr(methods[m], "area") ? 2.0 / 64 : strstr(methods[m], "exact filter") ? 1e-5 : 1e-9;
    if (worst > tol) print_message("%s: %g\n", methods[m], worst);
    assert_true(worst <= tol);
    assert_true(inside > 500);
  }
}

static const char *const all_methods[] = {
  "aa=exact", "aa=exact filter=gauss", "aa=multiscan n=3", "aa=multiscan n=12",
  "aa=multiscan filter=gauss n=3", "aa=multiscan filter=gauss n=6", "aa=area depth=1",
  "aa=area depth=4", "aa=super super=3", "aa=super super=4", "aa=super super=3 filter=box" };

static void test_flat_field(void **state)
{
  (void)state;
  static const int greys[] = { 0, 37, 128, 200, 255 };
  for (size_t g = 0; g < sizeof greys / sizeof *greys; g++) {
    struct tface f = { 4, { -3, 103, 103, -3 }, { -3, -3, 78, 78 }, 0, greys[g], 0, { 0 }, { 0 } };
    const char *s = scene(&f, 1);
    for (size_t m = 0; m < sizeof all_methods / sizeof *all_methods; m++) {
      struct aa_frame fr;
      render(s, all_methods[m], &fr);
      int bad = 0;
      for (int k = 0; k < W4 * H4; k++) bad += fr.grey[k] != greys[g];
      aa_frame_free(&fr);
      if (bad) print_message("%s grey %d: %d points off\n", all_methods[m], greys[g], bad);
      assert_int_equal(bad, 0);
    }
  }
}

/* ---- multiscan box ------------------------------------------------------------------------ */

/* Points whose top and bottom borders the one edge (p0 -> p1, far beyond) crosses. */
static bool crosses_top_bottom(const struct tface *f, int i, int j)
{
  double u0 = f->hu[0], v0 = f->hv[0], u1 = f->hu[1], v1 = f->hv[1];
  if (v1 == v0) return false;
  double ut = u0 + (u1 - u0) * (j - v0) / (v1 - v0), ub = u0 + (u1 - u0) * (j + 1 - v0) / (v1 - v0);
  return ut > i && ut < i + 1 && ub > i && ub < i + 1;
}

static void test_multiscan_box_bound(void **state)
{
  (void)state;
  unsigned seed = 3;
  static const int ns[] = { 1, 3, 6, 12 };
  double rms[4] = { 0 };
  int count[4] = { 0 }, checked = 0;
  for (int k = 0; k < 24; k++) {
    double a = 3.14159265358979 * rnd(&seed);
    struct tface f = halfplane(30 + 40 * rnd(&seed), 20 + 35 * rnd(&seed), a);
    const char *s = scene(&f, 1);
    struct aa_frame ex;
    render(s, "aa=exact", &ex);
    for (int q = 0; q < 4; q++) {
      char eff[64];
      snprintf(eff, sizeof eff, "aa=multiscan filter=box n=%d", ns[q]);
      struct aa_frame ms;
      render(s, eff, &ms);
      for (int j = 0; j < H4; j++)
        for (int i = 0; i < W4; i++) {
          double e = ms.light[j * W4 + i] - ex.light[j * W4 + i];
          if (crosses_top_bottom(&f, i, j)) {
            /* the bound, and the stronger fact behind it: the covered length is
               linear in y there, so the trapezoid rule of eq. (1) is exact */
            assert_true(fabs(e) <= 1.0 / (2 * ns[q]) + 1e-9);
            assert_true(fabs(e) <= 1e-9);
            checked++;
          }
          if (ex.light[j * W4 + i] > 0 && ex.light[j * W4 + i] < 1) { rms[q] += e * e; count[q]++; }
        }
      aa_frame_free(&ms);
    }
    aa_frame_free(&ex);
  }
  for (int q = 0; q < 4; q++) {
    rms[q] = sqrt(rms[q] / count[q]);
    print_message("multiscan box n=%d: rms error %.5f over %d edge points\n", ns[q], rms[q], count[q]);
  }
  print_message("%d points where the edge crosses top and bottom\n", checked);
  assert_true(checked > 500);
  for (int q = 1; q < 4; q++) assert_true(rms[q] < rms[q - 1]);
  assert_true(rms[3] < rms[1] / 2);
}

/* ---- the F table ------------------------------------------------------------------------------ */

static double simpson_gauss(double x, double d, double s)
{
  /* integral_0^x exp(-(t^2 + d^2)/2 s^2) dt by Simpson's rule, 2000 panels */
  if (x <= 0) return 0;
  int m = 2000;
  double h = x / m, sum = 0;
  for (int k = 0; k <= m; k++) {
    double t = k * h, w = (k == 0 || k == m) ? 1 : (k % 2 ? 4 : 2);
    sum += w * exp(-(t * t + d * d) / (2 * s * s));
  }
  return sum * h / 3;
}

static void test_ftable(void **state)
{
  (void)state;
  static const int ns[] = { 1, 2, 3, 6, 12, 16 };
  static const double sig[] = { 0.3, 0.5, 1.0 };
  uint16_t t[16 * (AA_FSTEPS + 1)];
  for (size_t a = 0; a < sizeof ns / sizeof *ns; a++)
    for (size_t b = 0; b < sizeof sig / sizeof *sig; b++) {
      int n = ns[a];
      aa_ftable(n, sig[b], t);
      long vol = 2L * t[AA_FSTEPS];
      for (int l = 1; l < n; l++) vol += 4L * t[l * (AA_FSTEPS + 1) + AA_FSTEPS];
      assert_int_equal(vol, AA_FONE);          /* the filter's volume is 1 */
      /* against an independent integration, normalised by its own discrete volume */
      double V = 0, ref[16];
      for (int l = 0; l < n; l++) {
        double d = (double)l / n;
        ref[l] = simpson_gauss(sqrt(1 - d * d), d, sig[b]) / n;
        V += (l == 0 ? 2 : 4) * ref[l];
      }
      for (int l = 0; l < n; l++) {
        double d = (double)l / n, hw = sqrt(1 - d * d);
        assert_int_equal(t[l * (AA_FSTEPS + 1)], 0);
        for (int k = 0; k < AA_FSTEPS; k++) {
          if (k) assert_true(t[l * (AA_FSTEPS + 1) + k] >= t[l * (AA_FSTEPS + 1) + k - 1]);
          double want = AA_FONE * simpson_gauss(fmin((double)k / AA_FSTEPS, hw), d, sig[b]) / n / V;
          assert_true(fabs(t[l * (AA_FSTEPS + 1) + k] - want) <= 1.0);
        }
        /* interpolation: at a step the table, half way the mean (floored) */
        assert_int_equal(aa_ftable_at(t, l, 10 << 10), t[l * (AA_FSTEPS + 1) + 10]);
        assert_int_equal(aa_ftable_at(t, l, (10 << 10) + 512),
                         (t[l * (AA_FSTEPS + 1) + 10] + t[l * (AA_FSTEPS + 1) + 11]) / 2);
        assert_int_equal(aa_ftable_at(t, l, 65536), t[l * (AA_FSTEPS + 1) + AA_FSTEPS]);
      }
    }
}

/* ---- area sampling ------------------------------------------------------------------------------ */

static void test_area_table(void **state)
{
  (void)state;
  uint16_t t[AA_AREA_WORDS];
  aa_area_table(t);
  assert_true(fabs(aa_area_cover_exact(0.25, HUGE_VAL) - 0.75) < 1e-12);   /* vertical edge */
  assert_true(fabs(aa_area_cover_exact(HUGE_VAL, 0.1) - 0.6) < 1e-12);     /* horizontal */
  assert_true(fabs(aa_area_cover_exact(0.5, 0.5) - 0.875) < 1e-12);         /* corner cut */
  assert_true(fabs(aa_area_cover_exact(2, 2) - 1) < 1e-12);                 /* misses it */
  unsigned seed = 5;
  double worst = 0;
  for (int k = 0; k < 200000; k++) {
    double h = rnd(&seed), v = rnd(&seed);
    h = h / (1.0001 - h);                       /* all distances, 0 .. 10^4 */
    v = v / (1.0001 - v);
    if (k % 97 == 0) h = HUGE_VAL;
    worst = fmax(worst, fabs(aa_area_lookup(t, h, v) - aa_area_cover_exact(h, v)));
  }
  print_message("area table: worst error %.5f\n", worst);
  assert_true(worst <= 1.0 / 64);
}

static void test_area_single_edge(void **state)
{
  (void)state;
  unsigned seed = 17;
  for (int k = 0; k < 16; k++) {
    double a = 3.14159265358979 * rnd(&seed);
    struct tface f = halfplane(30 + 40 * rnd(&seed), 20 + 35 * rnd(&seed), a);
    const char *s = scene(&f, 1);
    struct aa_frame ex, ar;
    render(s, "aa=exact", &ex);
    render(s, "aa=area depth=3", &ar);
    double worst = 0;
    for (int q = 0; q < W4 * H4; q++) worst = fmax(worst, fabs(ar.light[q] - ex.light[q]));
    double edges = 0;
    for (int q = 0; q < ar.st.n; q++) if (!strcmp(ar.st.name[q], "aa_one_edge")) edges = ar.st.value[q];
    aa_frame_free(&ex);
    aa_frame_free(&ar);
    if (worst > 1.0 / 64) print_message("edge %d: %g\n", k, worst);
    assert_true(worst <= 1.0 / 64);
    assert_true(edges > 50);                   /* it was the table, not subdivision */
  }
}

/* ---- the frame model's regions, exactly: a shadow, a contour cut ---------------------------- */

/* The area of the simple polygon (u, v)[0..n) (convex or not) inside point (i, j): the
   polygon clipped by the square's four sides, which are convex (Sutherland-Hodgman). */
static double poly_in_square(int i, int j, const double *u, const double *v, int n)
{
  static double px[1024], py[1024], qx[1024], qy[1024];
  assert_true(n <= 256);
  int m = n;
  memcpy(px, u, (size_t)n * sizeof *u);
  memcpy(py, v, (size_t)n * sizeof *v);
  for (int side = 0; side < 4 && m > 0; side++) {
    int q = 0;
    for (int e = 0; e < m; e++) {
      double cx = px[e], cy = py[e], dx = px[(e + 1) % m], dy = py[(e + 1) % m];
      double fc = side == 0 ? cx - i : side == 1 ? i + 1 - cx : side == 2 ? cy - j : j + 1 - cy;
      double fd = side == 0 ? dx - i : side == 1 ? i + 1 - dx : side == 2 ? dy - j : j + 1 - dy;
      if (fc >= 0) { qx[q] = cx; qy[q] = cy; q++; }
      if ((fc >= 0) != (fd >= 0)) {
        double t = fc / (fc - fd);
        qx[q] = cx + t * (dx - cx); qy[q] = cy + t * (dy - cy); q++;
      }
    }
    m = q;
    memcpy(px, qx, (size_t)m * sizeof *px);
    memcpy(py, qy, (size_t)m * sizeof *py);
  }
  double a = 0;
  for (int k = 0; k < m; k++) a += px[k] * py[(k + 1) % m] - px[(k + 1) % m] * py[k];
  return fabs(a) / 2;
}

static double stat_of(const struct aa_frame *fr, const char *name)
{
  for (int k = 0; k < fr->st.n; k++) if (!strcmp(fr->st.name[k], name)) return fr->st.value[k];
  return -1;
}

static double lt(int g) { return aa_light(4, g) / (double)AA_LIGHT_ONE; }

/* world -> point units (the window of these tests: 400 units a point) */
static double wu(double x) { return (x + 20000) / 400; }
static double wv(double y) { return (15000 - y) / 400; }

/* A shadow (paper 000 §3): a lit ground filling the window, and a triangle 50 units
   before the eye, outside the window, throwing its shadow down the parallel light (2, 0,
   -1) onto the ground, shifted by 1900 units in x: on the grid exactly. aa=exact gives
   each point the light of the shadow's area in it and the lit ground's in the rest,
   computed here by clipping, within 1e-6; no band is left unmatched. */
static void test_exact_shadow(void **state)
{
  (void)state;
  static const double T[3][2] = { { 1050, -3000 }, { 3000, 200 }, { 1200, 2500 } };
  char path[128];
  snprintf(path, sizeof path, "%s/shadow.s74", dir);
  FILE *o = fopen(path, "w");
  assert_non_null(o);
  fprintf(o, "view 0 0 -1000\nwindow -20000 -15000 20000 15000\nlight 2 0 -1\n"
          "vertex 1 -30000 -20000 0\nvertex 2 30000 -20000 0\nvertex 3 30000 20000 0\n"
          "vertex 4 -30000 20000 0\nface 1 1 2 3 4\n");
  for (int k = 0; k < 3; k++) fprintf(o, "vertex %d %d %d -950\n", 5 + k, (int)T[k][0], (int)T[k][1]);
  fprintf(o, "face 2 5 6 7 grey 0\n");
  fclose(o);
  double u[3], v[3];
  for (int k = 0; k < 3; k++) { u[k] = wu(T[k][0] - 1900); v[k] = wv(T[k][1]); }
  struct aa_frame pt, ex, plain;
  render(path, "shadows=on", &pt);
  render(path, "shadows=on aa=exact", &ex);
  render(path, "aa=exact", &plain);
  int lit = pt.grey[5 * W4 + 90];                        /* far from the shadow */
  int sh = pt.grey[(int)((v[0] + v[1] + v[2]) / 3) * W4 + (int)((u[0] + u[1] + u[2]) / 3)];
  print_message("ground grey %d lit, %d in the shadow; %g shadow polygons\n", lit, sh,
                stat_of(&ex, "shadow_polygons"));
  assert_true(lit > sh + 40);
  double worst = 0, moved = 0;
  int partial = 0;
  for (int j = 0; j < H4; j++)
    for (int i = 0; i < W4; i++) {
      double c = poly_in_square(i, j, u, v, 3), want = c * lt(sh) + (1 - c) * lt(lit);
      partial += c > 1e-9 && c < 1 - 1e-9;
      worst = fmax(worst, fabs(ex.light[j * W4 + i] - want));
      moved = fmax(moved, fabs(plain.light[j * W4 + i] - want));
    }
  print_message("exact against clipping: worst %.2g; without the shadow %.3f; %d points "
                "partly in it; unmatched bands %g\n", worst, moved, partial,
                stat_of(&ex, "aa_exact_unmatched"));
  assert_true(partial > 20);
  assert_true(moved > 0.1);                   /* the shadow is what the picture is about */
  assert_true(worst <= 1e-6);
  assert_true(stat_of(&ex, "aa_exact_unmatched") == 0);
  aa_frame_free(&pt);
  aa_frame_free(&ex);
  aa_frame_free(&plain);
}

/* A contour cut (paper 004): a square of two triangles, turned, on the plane, in front of
   a wall of its own grey; contour=1.0 alone rounds each corner between the sides'
   midpoints. aa=exact gives each point the light of the square's area in it less the
   four regions contour_region makes (the polygons the cut is made with), and the wall's
   in the rest, within 1e-6. */
static void test_exact_contour_cut(void **state)
{
  (void)state;
  static const double C[4][2] = { { 8400, -1200 }, { 1200, 8400 }, { -8400, 1200 }, { -1200, -8400 } };
  char path[128];
  snprintf(path, sizeof path, "%s/cut.s74", dir);
  FILE *o = fopen(path, "w");
  assert_non_null(o);
  fprintf(o, "view 0 0 -1000\nwindow -20000 -15000 20000 15000\nlight 1 2 -4\n");
  for (int k = 0; k < 4; k++) fprintf(o, "vertex %d %d %d 0\n", k + 1, (int)C[k][0], (int)C[k][1]);
  fprintf(o, "face 1 1 2 3\nface 2 1 3 4\nobject 1 1 2\n"
          "vertex 11 -30000 -25000 300\nvertex 12 30000 -25000 300\nvertex 13 30000 25000 300\n"
          "vertex 14 -30000 25000 300\nface 3 11 12 13 14 grey 30\n");
  fclose(o);
  /* the cut regions: Q0, Q4 the sides' midpoints, Q1 = Q0 and Q3 = Q4 at Cc = 1 */
  static double ru[4][CONTOUR_STEPS + 2], rv[4][CONTOUR_STEPS + 2];
  double su[4], sv[4];
  for (int k = 0; k < 4; k++) {
    const double *q2 = C[k], *a = C[(k + 3) % 4], *b = C[(k + 1) % 4];
    struct gpoint q[5];
    q[2] = (struct gpoint){ (gcoord)q2[0] * GRID_ONE, (gcoord)q2[1] * GRID_ONE };
    q[0] = q[1] = (struct gpoint){ (gcoord)(q2[0] + a[0]) / 2 * GRID_ONE, (gcoord)(q2[1] + a[1]) / 2 * GRID_ONE };
    q[3] = q[4] = (struct gpoint){ (gcoord)(q2[0] + b[0]) / 2 * GRID_ONE, (gcoord)(q2[1] + b[1]) / 2 * GRID_ONE };
    struct gpoint poly[CONTOUR_STEPS + 2];
    contour_region(q, poly);
    for (int m = 0; m < CONTOUR_STEPS + 2; m++) {
      ru[k][m] = wu((double)poly[m].x / GRID_ONE);
      rv[k][m] = wv((double)poly[m].y / GRID_ONE);
    }
    su[k] = wu(C[k][0]);
    sv[k] = wv(C[k][1]);
  }
  struct aa_frame pt, ex;
  render(path, "contour=1.0", &pt);
  render(path, "contour=1.0 aa=exact", &ex);
  int obj = pt.grey[37 * W4 + 50], wall = pt.grey[2 * W4 + 2];
  print_message("square grey %d, wall %d; %g convex corners\n", obj, wall,
                stat_of(&ex, "contour_corners_convex"));
  assert_int_equal(wall, 30);
  assert_true(abs(obj - wall) > 40);
  assert_true(stat_of(&ex, "contour_corners_convex") == 4);
  double worst = 0;
  int cut = 0;
  for (int j = 0; j < H4; j++)
    for (int i = 0; i < W4; i++) {
      double whole = poly_in_square(i, j, su, sv, 4), c = whole;
      for (int k = 0; k < 4; k++) c -= poly_in_square(i, j, ru[k], rv[k], CONTOUR_STEPS + 2);
      double want = c * lt(obj) + (1 - c) * lt(wall), got = ex.light[j * W4 + i];
      if (fabs(got - (whole * lt(obj) + (1 - whole) * lt(wall))) > 0.05) cut++;
      worst = fmax(worst, fabs(got - want));
    }
  print_message("exact against clipping: worst %.2g; %d points 0.05 or more from the "
                "uncut square's light; unmatched bands %g\n", worst, cut,
                stat_of(&ex, "aa_exact_unmatched"));
  assert_true(cut >= 40);
  assert_true(worst <= 1e-6);
  assert_true(stat_of(&ex, "aa_exact_unmatched") == 0);
  aa_frame_free(&pt);
  aa_frame_free(&ex);
}

/* ---- occlusion --------------------------------------------------------------------------------- */

static void test_stacked(void **state)
{
  (void)state;
  /* A (grey 60) in front at z = 0, B (grey 250) behind at z = 400, larger than the window
     once projected; B's projection scales by 1000/1400 */
  struct tface f[2] = {
    { 4, { 30, 70, 70, 30 }, { 20, 20, 50, 50 }, 0, 60, 0, { 0 }, { 0 } },
    { 4, { -30, 130, 130, -30 }, { -30, -30, 110, 110 }, 400, 250, 0, { 0 }, { 0 } } };
  const char *s = scene(f, 2);
  for (size_t m = 0; m < sizeof all_methods / sizeof *all_methods; m++) {
    struct aa_frame fr;
    render(s, all_methods[m], &fr);
    for (int j = 0; j < H4; j++)
      for (int i = 0; i < W4; i++) {
        int g = fr.grey[j * W4 + i];
        bool in = i >= 32 && i < 68 && j >= 22 && j < 48;
        bool out = i < 27 || i >= 73 || j < 17 || j >= 53;
        if (in && g != 60) print_message("%s (%d,%d): %d\n", all_methods[m], i, j, g);
        if (in) assert_int_equal(g, 60);
        if (out) assert_int_equal(g, 250);
      }
    aa_frame_free(&fr);
  }
}

/* ---- paper 000 Fig. 3 ------------------------------------------------------------------------- */

static void test_fig3_slivers(void **state)
{
  (void)state;
  /* (a) a vertical sliver 0.1 point wide, between the super 3 sample columns (1/6, 1/2, 5/6) */
  struct tface v = { 4, { 40.2, 40.3, 40.3, 40.2 }, { 10, 10, 60, 60 }, 0, 255, 0, { 0 }, { 0 } };
  const char *sv = scene(&v, 1);
  struct aa_frame ms, su, sb;
  render(sv, "aa=multiscan n=3", &ms);
  render(sv, "aa=super super=3 filter=box", &sb);
  render(sv, "aa=super super=3", &su);
  for (int j = 12; j < 58; j++) {
    assert_true(fabs(ms.light[j * W4 + 40] - 0.1) < 1e-9);   /* seen, exactly */
    for (int i = 38; i < 43; i++) {
      assert_true(sb.light[j * W4 + i] == 0);                 /* missed by 3 x 3 samples */
      assert_true(su.light[j * W4 + i] == 0);                 /* and by the 5 x 5 Gaussian */
    }
  }
  aa_frame_free(&ms); aa_frame_free(&su); aa_frame_free(&sb);

  /* (b) a 45-degree sliver 0.1 point wide across: every sample line finds it at the same
     phase between samples (u0 = 10.05), so super 3 misses all of it, multiscan none */
  struct tface d = { 4, { 10.05, 10.15, 50.15, 50.05 }, { 10, 10, 50, 50 }, 0, 255, 0, { 0 }, { 0 } };
  const char *sd = scene(&d, 1);
  render(sd, "aa=multiscan n=3", &ms);
  render(sd, "aa=super super=3 filter=box", &sb);
  for (int j = 12; j < 48; j++) {
    double rm = 0, rs = 0;
    for (int i = 0; i < W4; i++) { rm += ms.light[j * W4 + i]; rs += sb.light[j * W4 + i]; }
    assert_true(fabs(rm - 0.1) < 1e-9);
    assert_true(rs == 0);
  }
  aa_frame_free(&ms); aa_frame_free(&sb);

  /* (c) the near-horizontal sliver between two sub-scanlines (v in j + 0.40 .. 0.47, lines
     at j + 1/3 and j + 2/3 for n = 3): multiscan misses it (paper 000 Fig. 3(a) b, the
     method's known blind spot), the exact area sees 0.07 of each point, n = 12 finds it */
  struct tface h = { 4, { 20, 80, 80, 20 }, { 30.40, 30.41, 30.48, 30.47 }, 0, 255, 0, { 0 }, { 0 } };
  const char *sh = scene(&h, 1);
  struct aa_frame ex, m12;
  render(sh, "aa=multiscan n=3", &ms);
  render(sh, "aa=multiscan n=12", &m12);
  render(sh, "aa=exact", &ex);
  for (int i = 22; i < 78; i++) {
    assert_true(ms.light[30 * W4 + i] == 0);
    assert_true(fabs(ex.light[30 * W4 + i] - 0.07) < 1e-3);
    assert_true(m12.light[30 * W4 + i] > 0.03);
  }
  aa_frame_free(&ms); aa_frame_free(&m12); aa_frame_free(&ex);
}

/* ---- per-point intensities from an effect before aa --------------------------------------- */

struct fr_ctx { int *face; uint8_t *grey; const struct render *r; };

static int fr_point(void *ctx, int i, int j, int face)
{
  struct fr_ctx *c = ctx;
  c->face[j * W4 + i] = face;
  c->grey[j * W4 + i] = (uint8_t)(face >= 0 ? c->r->map.f[face].grey : 0);
  return T74_OK;
}

/* A smooth effect (paper 004) runs before aa and leaves its intensity per point in the
   frame; aa must mix those, not the flat grey: a white field whose frame says 200
   everywhere (and a dark ramp on the left half) comes out as the frame says. */
static void test_frame_intensities(void **state)
{
  (void)state;
  struct tface f = { 4, { -3, 103, 103, -3 }, { -3, -3, 78, 78 }, 0, 255, 0, { 0 }, { 0 } };
  const char *path = scene(&f, 1);
  static const char *const eff[] = { "aa=multiscan n=3 smooth=gouraud", "aa=exact smooth=gouraud",
                                     "aa=super super=3 smooth=gouraud", "aa=area depth=2 smooth=gouraud",
                                     "aa=multiscan filter=gauss smooth=gouraud" };
  for (size_t m = 0; m < sizeof eff / sizeof *eff; m++) {
    struct scene *s;
    struct scene_opts so;
    memset(&so, 0, sizeof so);
    struct t74_error err = { 0, "" };
    assert_int_equal(scene_load(path, &so, &s, &err), T74_OK);
    struct effects e;
    assert_int_equal(effects_parse(eff[m], &e, NULL, 0, &err), T74_OK);
    struct render r;
    struct render_opts ro = { 1u << 20, 0, PRIO_AUTO, NULL, 0, NULL };
    assert_int_equal(render_prepare(&r, s, &ro, &err), T74_OK);
    int face[W4 * H4];
    uint8_t grey[W4 * H4];
    struct fr_ctx fc = { face, grey, &r };
    struct vis_grid g = { W4, H4, { s->window[0], s->window[1], s->window[2], s->window[3] } };
    assert_int_equal(render_scan(&r, &g, fr_point, &fc, &err), T74_OK);
    for (int j = 0; j < H4; j++)
      for (int i = 0; i < W4; i++) grey[j * W4 + i] = (uint8_t)(i < 50 ? 2 * i : 200);
    struct fx_frame fr = { W4, H4, 4, face, grey, NULL, NULL, NULL };
    struct fx_stats st;
    memset(&st, 0, sizeof st);
    struct cost cost = { { 0 } };
    double light[W4 * H4];
    struct fx_engine eng;
    fx_engine_1974(&eng, &r, &g);
    assert_int_equal(aa_light_map(&eng, &e, &fr, &st, &cost, light, &err), T74_OK);
    for (int j = 2; j < H4 - 2; j++) {
      assert_int_equal(aa_grey(4, light[j * W4 + 70]), 200);
      /* on the ramp every method mixes neighbouring greys: within the ramp's range */
      int gr = aa_grey(4, light[j * W4 + 20]);
      assert_true(gr >= 36 && gr <= 44);
    }
    render_free(&r);
    scene_free(s);
  }
}

/* ---- the command line ------------------------------------------------------------------------- */

static void test_cli(void **state)
{
  (void)state;
  const char *bin = getenv("TUBE74");
  if (!bin) bin = "./tube74";
  char cmd[512];
  snprintf(cmd, sizeof cmd, "%s render scenes/fig5.s74 --effects 'aa=multiscan n=3' --dump grey=%s/g.pgm 2>/dev/null", bin, dir);
  assert_int_equal(system(cmd), 0);
  snprintf(cmd, sizeof cmd, "%s/g.pgm", dir);
  assert_int_equal(access(cmd, F_OK), 0);
  /* a core too small for the method's tables (aa=none fits 1463 words and the program's
     4096): exit 3, no file */
  snprintf(cmd, sizeof cmd, "%s render scenes/fig5.s74 --core 6096 --effects 'aa=multiscan n=3' -o %s/small.png 2>%s/err.txt", bin, dir, dir);
  int rc = system(cmd);
  assert_true(WIFEXITED(rc) && WEXITSTATUS(rc) == 3);
  snprintf(cmd, sizeof cmd, "%s/small.png", dir);
  assert_int_equal(access(cmd, F_OK), -1);
  snprintf(cmd, sizeof cmd, "%s render scenes/fig5.s74 --core 6096 -o %s/small.png 2>/dev/null", bin, dir);
  assert_int_equal(system(cmd), 0);
  /* bench dispatches on its subcommand and refuses others (exit 2) */
  snprintf(cmd, sizeof cmd, "%s bench nosuch 2>/dev/null", bin);
  rc = system(cmd);
  assert_true(WIFEXITED(rc) && WEXITSTATUS(rc) == 2);
  snprintf(cmd, sizeof cmd, "%s bench 2>/dev/null", bin);
  rc = system(cmd);
  assert_true(WIFEXITED(rc) && WEXITSTATUS(rc) == 2);
}

static int setup(void **state)
{
  (void)state;
  strcpy(dir, "/tmp/t74aa.XXXXXX");
  return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
  (void)state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  return getenv("AA_KEEP") ? 0 : (system(cmd) == 0 ? 0 : -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_light_roundtrip),
    cmocka_unit_test(test_halfplanes_exact),
    cmocka_unit_test(test_triangles_exact),
    cmocka_unit_test(test_complement),
    cmocka_unit_test(test_flat_field),
    cmocka_unit_test(test_multiscan_box_bound),
    cmocka_unit_test(test_ftable),
    cmocka_unit_test(test_area_table),
    cmocka_unit_test(test_area_single_edge),
    cmocka_unit_test(test_stacked),
    cmocka_unit_test(test_exact_shadow),
    cmocka_unit_test(test_exact_contour_cut),
    cmocka_unit_test(test_fig3_slivers),
    cmocka_unit_test(test_frame_intensities),
    cmocka_unit_test(test_cli),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
