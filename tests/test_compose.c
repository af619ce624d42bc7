/*
** test_compose.c — the effects compose (issue 18): every combination of
** {flat, smooth, partial, contour} x {aa none, multiscan box, multiscan gauss, area, super}
** x {edges off, on} x {shadows off, on} on one scene (a smoothable octahedron over a
** ground, a parallel and a point light), each held to what an effect may change and what
** it may not:
**   - the face at each point centre (--dump ids) is the shading's own: anti-aliasing,
**     edges and shadows never change it; only the contour cut does;
**   - a shadow only darkens: every point's grey with shadows=on is at most its grey
**     without, under every filter and with edges;
**   - point-sampled shadows agree with an independent ray test written here (doubles,
**     Moller-Trumbore against the octahedron's triangles) at every point whose four
**     neighbours agree too (the shadow's vertices are rounded once onto the plane grid,
**     so a point at a boundary may go either way);
**   - smooth shading under any filter has no seams: inside the surface (a point and its
**     eight neighbours all on the object) the anti-aliased grey stays within 12 levels of
**     the point-sampled one (the Gaussian reaches into the neighbours, whose shading
**     differs) (the old code mixed in the neighbouring face's flat grey,
**     up to 70 levels off);
**   - the contour cut stays cut under every filter: at the cut points (showing what lies
**     behind where the uncut picture shows the object, no neighbour on the object) the
**     filtered picture is on the whole well below the uncut object's light (a cut point's
**     square may still hold some of the object beyond the curve, so not zero);
**   - a smoothed object has no inner edges (edges_inner 0), a flat one has;
**   - the exact reference (aa=exact, box and Gaussian) of every shading with and without
**     shadows holds the cut and the shadows, leaves no band unmatched and agrees with
**     supersampling at 16 x 16 of its filter; every method (multiscan box and gauss,
**     area, super) stays within its bound of the exact reference of its own filter in
**     every combination (tests/test_aa.c holds aa=exact to clipping on a shadow and a cut).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/ref/testkit.h"

static char dir[256];

static const char *scene_text =
  "# an octahedron over a ground, two lights\n"
  "view 0 500 -1600\n"
  "window -300 -150 300 300\n"
  "light 2 5 -1\n"
  "light point -500 900 300\n"
  "vertex 1 -700 0 100\nvertex 2 700 0 100\nvertex 3 700 0 1500\nvertex 4 -700 0 1500\n"
  "face 1 1 4 3 2\n"
  "vertex 10 0 480 700\nvertex 11 0 120 700\nvertex 12 -180 300 700\nvertex 13 180 300 700\n"
  "vertex 14 0 300 520\nvertex 15 0 300 880\n"
  "face 21 10 14 13\nface 22 10 13 15\nface 23 10 15 12\nface 24 10 12 14\n"
  "face 25 11 13 14\nface 26 11 15 13\nface 27 11 12 15\nface 28 11 14 12\n"
  "object 1 21 22 23 24 25 26 27 28\n";

/* the octahedron's vertices and triangles (as above) for the ray test */
static const double OV[6][3] = { { 0, 480, 700 }, { 0, 120, 700 }, { -180, 300, 700 },
                                 { 180, 300, 700 }, { 0, 300, 520 }, { 0, 300, 880 } };
static const int OT[8][3] = { { 0, 4, 3 }, { 0, 3, 5 }, { 0, 5, 2 }, { 0, 2, 4 },
                              { 1, 3, 4 }, { 1, 5, 3 }, { 1, 2, 5 }, { 1, 4, 2 } };

#define W 100
#define H 75

struct pic { int w, h; unsigned v[W * H]; };

static int read_pgm(const char *path, struct pic *p)
{
  size_t n;
  char *b = tk_slurp(path, &n);
  if (!b) return -1;
  int w, h, mv, off = 0;
  if (sscanf(b, "P5 %d %d %d%n", &w, &h, &mv, &off) != 3 || w != W || h != H) { free(b); return -1; }
  off++;
  int bytes = mv > 255 ? 2 : 1;
  if ((size_t)off + (size_t)(w * h * bytes) > n) { free(b); return -1; }
  const unsigned char *q = (const unsigned char *)b + off;
  for (int k = 0; k < w * h; k++) p->v[k] = bytes == 2 ? (unsigned)(q[2 * k] << 8 | q[2 * k + 1]) : q[k];
  p->w = w; p->h = h;
  free(b);
  return 0;
}

struct run { struct pic ids, grey; long edges_inner, unmatched; };

static const char *shades[4] = { "", "smooth=phong", "smooth=prop:0.15", "smooth=phong contour=1.0" };
static const char *aas[5] = { "", "aa=multiscan filter=box n=3", "aa=multiscan filter=gauss n=3",
                              "aa=area", "aa=super super=3" };

static void render(const char *effects, struct run *out)
{
  char sp[512], ip[512], gp[512], jp[512], ia[600], ga[600], ja[600];
  snprintf(sp, sizeof sp, "%s/s.s74", dir);
  snprintf(ip, sizeof ip, "%s/ids.pgm", dir);
  snprintf(gp, sizeof gp, "%s/grey.pgm", dir);
  snprintf(jp, sizeof jp, "%s/st.json", dir);
  snprintf(ia, sizeof ia, "ids=%s", ip);
  snprintf(ga, sizeof ga, "grey=%s", gp);
  snprintf(ja, sizeof ja, "%s", jp);
  int rc = tk_runl(NULL, NULL, "render", sp, "--effects", effects[0] ? effects : "halftone=4x4",
                   "--dump", ia, "--dump", ga, "--stats", ja, (char *)NULL);
  if (rc != 0) print_message("render --effects '%s': exit %d\n", effects, rc);
  assert_int_equal(rc, 0);
  assert_int_equal(read_pgm(ip, &out->ids), 0);
  assert_int_equal(read_pgm(gp, &out->grey), 0);
  char *js = tk_slurp(jp, NULL);
  assert_non_null(js);
  const char *k = strstr(js, "\"edges_inner\": ");
  out->edges_inner = k ? atol(k + 15) : -1;
  k = strstr(js, "\"aa_exact_unmatched\": ");
  out->unmatched = k ? atol(k + 22) : -1;
  free(js);
}

static void effects_text(char *buf, size_t n, int s, int a, int e, int sh)
{
  snprintf(buf, n, "%s %s %s %s", shades[s], aas[a], e ? "edges=on" : "", sh ? "shadows=on" : "");
  /* squeeze blanks */
  char *w = buf;
  for (char *r = buf; *r; r++) if (*r != ' ' || (w > buf && w[-1] != ' ')) *w++ = *r;
  while (w > buf && w[-1] == ' ') w--;
  *w = '\0';
}

static int is_obj(unsigned id) { return id >= 21 && id <= 28; }

/* the ray test: is the ground point seen at point (i, j) in light k's shadow? -1: the
   point does not show the ground */
static int ray_blocked(int i, int j, int k)
{
  double E[3] = { 0, 500, -1600 };
  double px = -300 + (i + 0.5) * 600.0 / W, py = 300 - (j + 0.5) * 450.0 / H;
  double D[3] = { px - E[0], py - E[1], 0 - E[2] };
  if (D[1] >= 0) return -1;
  double t = -E[1] / D[1];
  double P[3] = { E[0] + t * D[0], 0, E[2] + t * D[2] };
  double L[3];
  bool point = k == 1;
  if (point) { L[0] = -500 - P[0]; L[1] = 900 - P[1]; L[2] = 300 - P[2]; }
  else { L[0] = 2; L[1] = 5; L[2] = -1; }
  for (int q = 0; q < 8; q++) {
    const double *a = OV[OT[q][0]], *b = OV[OT[q][1]], *c = OV[OT[q][2]];
    double e1[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, e2[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    double pv[3] = { L[1] * e2[2] - L[2] * e2[1], L[2] * e2[0] - L[0] * e2[2], L[0] * e2[1] - L[1] * e2[0] };
    double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
    if (fabs(det) < 1e-12) continue;
    double tv[3] = { P[0] - a[0], P[1] - a[1], P[2] - a[2] };
    double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) / det;
    if (u < 0 || u > 1) continue;
    double qv[3] = { tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0] };
    double v = (L[0] * qv[0] + L[1] * qv[1] + L[2] * qv[2]) / det;
    if (v < 0 || u + v > 1) continue;
    double s = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
    if (s > 0 && (!point || s < 1)) return 1;
  }
  return 0;
}

static double rms(const struct pic *a, const struct pic *b)
{
  double s = 0;
  for (int k = 0; k < W * H; k++) {
    double d = (double)a->v[k] - (double)b->v[k];
    s += d * d;
  }
  return sqrt(s / (W * H));
}

static struct run base[4][2];          /* [shade][shadows]: aa none, edges off */

static int setup(void **state)
{
  (void)state;
  if (tk_mkscratch(dir, sizeof dir, "/tmp/t74compose.XXXXXX")) return -1;
  char sp[512];
  snprintf(sp, sizeof sp, "%s/s.s74", dir);
  if (tk_put(sp, scene_text, strlen(scene_text))) return -1;
  return 0;
}

static int teardown(void **state)
{
  (void)state;
  return tk_rmscratch(dir);
}

static void test_bases(void **state)
{
  (void)state;
  char fx[256];
  for (int sh = 0; sh < 4; sh++)
    for (int d = 0; d < 2; d++) {
      effects_text(fx, sizeof fx, sh, 0, 0, d);
      render(fx, &base[sh][d]);
      /* shadows never change what is seen */
      if (d) assert_memory_equal(base[sh][1].ids.v, base[sh][0].ids.v, sizeof base[sh][0].ids.v);
    }
  /* the contour cut changes what is seen, and only there: object points become ground or
     background, nothing else moves */
  long cut = 0;
  for (int k = 0; k < W * H; k++) {
    unsigned a = base[1][0].ids.v[k], b = base[3][0].ids.v[k];
    if (a != b) { assert_true(is_obj(a) && !is_obj(b)); cut++; }
  }
  print_message("contour=1.0 cuts %ld points\n", cut);
  assert_true(cut > 20);
}

static void test_shadows_exact(void **state)
{
  (void)state;
  /* point-sampled, flat: where the ground is seen, is it darker exactly where the ray
     test finds a light blocked? */
  const struct pic *off = &base[0][0].grey, *on = &base[0][1].grey, *ids = &base[0][0].ids;
  long checked = 0, boundary = 0, shaded = 0;
  for (int j = 1; j < H - 1; j++)
    for (int i = 1; i < W - 1; i++) {
      int k = j * W + i;
      if (ids->v[k] != 1) continue;
      int b = ray_blocked(i, j, 0) | ray_blocked(i, j, 1);
      bool edge = false;
      static const int di[4] = { 1, -1, 0, 0 }, dj[4] = { 0, 0, 1, -1 };
      for (int q = 0; q < 4; q++) {
        int bq = ray_blocked(i + di[q], j + dj[q], 0) | ray_blocked(i + di[q], j + dj[q], 1);
        for (int l = 0; l < 2; l++)
          if (ray_blocked(i + di[q], j + dj[q], l) != ray_blocked(i, j, l)) edge = true;
        (void)bq;
      }
      if (edge) { boundary++; continue; }
      checked++;
      shaded += b;
      if ((on->v[k] < off->v[k]) != (b == 1))
        print_message("point (%d, %d): ray test %s, grey %u -> %u\n", i, j, b ? "blocked" : "lit",
                      off->v[k], on->v[k]);
      assert_int_equal(on->v[k] < off->v[k], b == 1);
    }
  print_message("shadows: %ld ground points checked (%ld in shadow), %ld at a boundary\n",
                checked, shaded, boundary);
  assert_true(shaded > 50 && checked > 1000);
}

static struct run exact[4][2][2];      /* [shade][shadows][gauss]: aa=exact, edges off */

/* The exact reference (aa=exact, box and Gaussian) of every shading with and without
   shadows: it agrees with supersampling at 16 x 16 of the same filter (which samples the
   frame model point by point), the cut and the shadows are in it (where the reference
   with shadows is darker than the one without, the ray test finds a light blocked; at
   the cut points it shows what lies behind, not the object), and no band of it was left
   unmatched. tests/test_aa.c holds it to clipping, within 1e-6, on a shadow and a cut. */
static void test_reference(void **state)
{
  (void)state;
  char fx[256], full[300];
  for (int sh = 0; sh < 4; sh++)
    for (int d = 0; d < 2; d++)
      for (int g = 0; g < 2; g++) {
        effects_text(fx, sizeof fx, sh, 0, 0, d);
        snprintf(full, sizeof full, "%s aa=exact%s", fx, g ? " filter=gauss" : "");
        render(full, &exact[sh][d][g]);
        assert_int_equal(exact[sh][d][g].unmatched, 0);
        struct run R;
        snprintf(full, sizeof full, "%s aa=super super=16%s", fx, g ? "" : " filter=box");
        render(full, &R);
        double e2 = rms(&exact[sh][d][g].grey, &R.grey);
        print_message("%-44s aa=exact%s: rms %.2f from super=16\n", fx, g ? " filter=gauss" : "", e2);
        assert_true(e2 < (g ? 1.0 : 2.0));
      }
  /* the shadows are in the reference: ground points darker with shadows=on are where the
     ray test finds a light blocked (or next to such a point: the filter reaches one point) */
  long darker = 0, stray = 0;
  for (int j = 1; j < H - 1; j++)
    for (int i = 1; i < W - 1; i++) {
      int k = j * W + i;
      if (base[0][0].ids.v[k] != 1) continue;
      if (exact[0][1][0].grey.v[k] + 20 > exact[0][0][0].grey.v[k]) continue;
      darker++;
      bool blocked = false;
      for (int dj = -1; dj <= 1; dj++)
        for (int di = -1; di <= 1; di++)
          blocked = blocked || ray_blocked(i + di, j + dj, 0) == 1 || ray_blocked(i + di, j + dj, 1) == 1;
      stray += !blocked;
    }
  /* the cut is in it: at the cut points (no neighbour on the object) what lies behind
     shows instead of the object (the background, or the ground) */
  long cut = 0, same = 0;
  for (int k = 0; k < W * H; k++) {
    if (!is_obj(base[1][0].ids.v[k]) || is_obj(base[3][0].ids.v[k])) continue;
    int i = k % W, j = k / W;
    bool inner = i > 0 && j > 0 && i < W - 1 && j < H - 1;
    for (int dj = -1; inner && dj <= 1; dj++)
      for (int di = -1; di <= 1; di++) inner = inner && !is_obj(base[3][0].ids.v[k + dj * W + di]);
    if (!inner) continue;
    cut++;
    same += abs((int)exact[3][0][0].grey.v[k] - (int)exact[1][0][0].grey.v[k]) < 20;
  }
  print_message("reference: %ld ground points darker by shadows (%ld away from a blocked ray); "
                "%ld cut points, %ld of them within 20 grey levels of the uncut object\n", darker,
                stray, cut, same);
  assert_true(darker > 100);
  assert_int_equal(stray, 0);
  assert_true(cut >= 20);
  assert_int_equal(same, 0);
}

static void test_matrix(void **state)
{
  (void)state;
  /* rms grey levels from the exact reference, per method (measured 6.6, 3.6, 0.25, 3.2
     at most over the 16 shadings and shadows) */
  static const double bound[5] = { 0, 7.5, 4.5, 0.6, 4.0 };
  char fx[256];
  long seams = 0, cutpts = 0, combos = 0;
  double cutsum = 0, uncutsum = 0;
  for (int sh = 0; sh < 4; sh++)
    for (int a = 0; a < 5; a++)
      for (int e = 0; e < 2; e++) {
        struct run r[2];
        for (int d = 0; d < 2; d++) {
          effects_text(fx, sizeof fx, sh, a, e, d);
          render(fx, &r[d]);
          combos++;
          /* aa, edges, shadows never change the face at a point centre */
          assert_memory_equal(r[d].ids.v, base[sh][0].ids.v, sizeof r[d].ids.v);
          /* a smoothed object has no inner edges; a flat one has */
          if (e) {
            if (sh == 0) assert_true(r[d].edges_inner > 0);
            else assert_int_equal(r[d].edges_inner, 0);
          }
        }
        /* a shadow only darkens */
        for (int k = 0; k < W * H; k++) {
          if (r[1].grey.v[k] > r[0].grey.v[k])
            print_message("%s: point %d: %u with shadows, %u without\n", fx, k, r[1].grey.v[k], r[0].grey.v[k]);
          assert_true(r[1].grey.v[k] <= r[0].grey.v[k]);
        }
        if (e || a == 0) continue;
        for (int d = 0; d < 2; d++) {
          const struct pic *ids = &base[sh][d].ids, *pt = &base[sh][d].grey, *g = &r[d].grey;
          const struct pic *uncut = &base[1][d].ids;
          for (int j = 1; j < H - 1; j++)
            for (int i = 1; i < W - 1; i++) {
              int k = j * W + i;
              bool inner = true, ground = true;
              for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++) {
                  unsigned id = ids->v[k + dj * W + di];
                  if (!is_obj(id)) inner = false;
                  if (is_obj(id)) ground = false;
                }
              /* no seams inside a smoothed surface */
              if (inner && sh > 0 && sh < 3) {
                int dv = abs((int)g->v[k] - (int)pt->v[k]);
                if (dv > 12) print_message("%s: seam at (%d, %d): %u against %u\n", fx, i, j, g->v[k], pt->v[k]);
                assert_true(dv <= 12);
                seams++;
              }
              /* the cut stays cut */
              if (is_obj(ids->v[k]) || !is_obj(uncut->v[k])) ground = false;
              if (ground && sh == 3 && d == 0) {   /* (a shadow's edge would blur it too) */
                cutsum += g->v[k];
                uncutsum += base[1][d].grey.v[k];
                cutpts++;
              }
            }
        }
        /* every method near the exact reference of its filter (box: multiscan box, area;
           Gaussian: multiscan gauss, super's default), which integrates the cut and the
           shadows exactly (test_reference below, tests/test_aa.c) */
        for (int d = 0; d < 2; d++) {
          bool gauss = a == 2 || a == 4;
          double e2 = rms(&r[d].grey, &exact[sh][d][gauss].grey);
          effects_text(fx, sizeof fx, sh, a, 0, d);
          print_message("%-52s rms %.2f grey levels from aa=exact%s\n", fx, e2,
                        gauss ? " filter=gauss" : "");
          assert_true(e2 < bound[a]);
        }
      }
  print_message("%ld combinations; %ld seam checks, %ld cut checks\n", combos, seams, cutpts);
  /* where the contour cut took the object away, the filtered picture is darker than the
     uncut object's point samples (the old code lit every cut point again) */
  print_message("cut points: mean grey %.1f filtered, %.1f where the object was\n",
                cutpts ? cutsum / cutpts : 0, cutpts ? uncutsum / cutpts : 0);
  assert_true(seams > 500 && cutpts > 0);
  assert_true(cutsum < 0.75 * uncutsum);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_bases),
    cmocka_unit_test(test_shadows_exact),
    cmocka_unit_test(test_reference),
    cmocka_unit_test(test_matrix),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
