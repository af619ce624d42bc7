/*
** test_mapper.c — tests of the Mapper's T-junction search (render/mapper.c, issue 19).
**
** The search looks, for each edge, at the vertices in the cells of a grid that meet the
** edge's box on the plane grid; of a slanted edge's box only at the cells its line can
** reach, the others' vertices counted for the 1974 charge without being looked at (the
** short way). mapper_keep.whole_boxes makes it look at every cell of every box (the long
** way). Under the points engine (no cost) nothing is counted, and the search looks, in
** every row of a slanted edge's box, only at the cells its line can reach (tj_edge_near).
** On scenes built with many vertices lying exactly on long slanted edges in space (fans
** of triangles along the edge of a large one, in depth), on random triangles, and on
** random triangles through one another with corners put on earlier ones' edges, all ways
** must find the very same vertices in the same order and map the same faces, the
** counting ones charge the same operations; and every vertex put on an edge must be
** found. Run from the repository root.
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

#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/mapper.h"
#include "render/scene.h"

/* ---- scenes ------------------------------------------------------------------------- */

struct text { char *t; size_t len, cap; };

static void put(struct text *x, const char *fmt, ...)
{
  va_list ap;
  for (;;) {
    va_start(ap, fmt);
    int n = vsnprintf(x->t + x->len, x->cap - x->len, fmt, ap);
    va_end(ap);
    assert_true(n >= 0);
    if ((size_t)n < x->cap - x->len) { x->len += (size_t)n; return; }
    x->cap = 2 * x->cap + (size_t)n + 64;
    x->t = realloc(x->t, x->cap);
    assert_non_null(x->t);
  }
}

static uint32_t rnd_state;
static int rnd(int lo, int hi)
{
  rnd_state = rnd_state * 1103515245u + 12345u;
  return lo + (int)((rnd_state >> 8) % (uint32_t)(hi - lo + 1));
}

/* nfan fans: a large triangle (P0, Pk, Q) whose edge P0-Pk, slanted on the picture and in
   depth, holds P1 .. Pk-1 (Pj = P0 + j d exactly), each the corner of small triangles
   (Pj, Pj+1, Rj) on the other side; then nrand random triangles. With `shared`, each fan
   also has a triangle with the edge Pk-P0 (the other way) and one with P0-Pk (the same
   way), and a second vertex at one of the Pj (another id at the same point, the corner of
   a triangle of its own), so the edge's vertices include two at one point. *inserted: how
   many vertices lie inside the large triangles' edges by construction. */
static char *fan_scene(int nfan, int nrand, uint32_t seed, bool shared, int *inserted)
{
  struct text x = { NULL, 0, 0 };
  put(&x, "view 0 0 -3000\nwindow -200 -150 200 150\n");
  rnd_state = seed;
  int v = 0, f = 0;
  *inserted = 0;
  for (int q = 0; q < nfan; q++) {
    int k = rnd(3, 12);
    int dx = rnd(-9, 9) * 3 + 1, dy = rnd(-9, 9) * 2 + 1, dz = rnd(-40, 40);
    int ax = rnd(-180, 180) - k * dx / 2, ay = rnd(-130, 130) - k * dy / 2;
    int az = rnd(400, 2400) - k * dz / 2;
    if (az < 200) az = 200;
    if (az + k * dz < 200) dz = 0;
    int p0 = v + 1;
    for (int j = 0; j <= k; j++)
      put(&x, "vertex %d %d %d %d\n", ++v, ax + j * dx, ay + j * dy, az + j * dz);
    /* Q and the R's on either side of the line (the normal (-dy, dx) on the picture) */
    int s = rnd(20, 60);
    put(&x, "vertex %d %d %d %d\n", ++v, ax + k * dx / 2 - dy * s / 8 - 1,
        ay + k * dy / 2 + dx * s / 8, az + k * dz / 2 + 7);
    put(&x, "face %d %d %d %d grey %d\n", ++f, p0, p0 + k, v, rnd(60, 255));
    for (int j = 0; j < k; j++) {
      put(&x, "vertex %d %d %d %d\n", ++v, ax + j * dx + dy * 2 + 1, ay + j * dy - dx * 2,
          az + j * dz + 3);
      put(&x, "face %d %d %d %d grey %d\n", ++f, p0 + j, v, p0 + j + 1, rnd(60, 255));
    }
    *inserted += k - 1;
    if (shared) {
      int j = rnd(1, k - 1), t = ++v;                   /* the second vertex at Pj */
      put(&x, "vertex %d %d %d %d\n", t, ax + j * dx, ay + j * dy, az + j * dz);
      put(&x, "vertex %d %d %d %d\n", ++v, ax + j * dx + dy * 3, ay + j * dy - dx * 3 + 2,
          az + j * dz + 11);
      put(&x, "face %d %d %d %d grey %d\n", ++f, t, v, p0 + k, rnd(60, 255));
      put(&x, "vertex %d %d %d %d\n", ++v, ax + k * dx / 2 + dy * s / 8 + 1,
          ay + k * dy / 2 - dx * s / 8, az + k * dz / 2 + 5);
      put(&x, "face %d %d %d %d grey %d\n", ++f, p0 + k, p0, v, rnd(60, 255));
      put(&x, "vertex %d %d %d %d\n", ++v, ax + k * dx / 2 - dy * s / 5 - 2,
          ay + k * dy / 2 + dx * s / 5, az + k * dz / 2 + 13);
      put(&x, "face %d %d %d %d grey %d\n", ++f, p0, p0 + k, v, rnd(60, 255));
      *inserted += 2 * (k - 1) + 2 * 1;                 /* both triangles' edges: Pj twice */
    }
  }
  for (int q = 0; q < nrand; q++) {
    int cx = rnd(-150, 150), cy = rnd(-110, 110), r = rnd(20, 120);
    for (int j = 0; j < 3; j++)
      put(&x, "vertex %d %d %d %d\n", ++v, cx + rnd(-r, r), cy + rnd(-r, r), rnd(300, 2500));
    put(&x, "face %d %d %d %d grey %d\n", ++f, v - 2, v - 1, v, rnd(60, 255));
  }
  return x.t;
}

static struct scene *load_text(const char *text)
{
  char path[] = "/tmp/t74mapper.XXXXXX";
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  FILE *fp = fdopen(fd, "w");
  assert_non_null(fp);
  fputs(text, fp);
  fclose(fp);
  struct scene_opts so;
  memset(&so, 0, sizeof so);
  struct scene *s = NULL;
  struct t74_error err = { 0, "" };
  int st = scene_load(path, &so, &s, &err);
  unlink(path);
  if (st) print_message("scene_load: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  return s;
}

/* Issue 19: the VERTEX and A-BLOCK rows the Mapper writes (a row at once) hold, word for
   word, a vertex's id, x, y, z and projection in whole units, and a face's id, grey,
   y-min, y-max, the 1974 plane's a, b, c and d (two words, the high one first), the
   tenth word 0. Vertices with coordinates below 0 and an id above 32767. */
static void test_core_rows(void **state)
{
  (void)state;
  struct scene *s = load_text("view 0 0 -500\n"
                              "window -200 -150 200 150\n"
                              "vertex 60001 -120 -80 40\n"
                              "vertex 2 130 -70 60\n"
                              "vertex 3 90 110 90\n"
                              "vertex 4 -100 95 30\n"
                              "face 1 60001 2 3 grey 200\n"
                              "face 2 60001 3 4 grey 90\n");
  struct core *core = core_new(1u << 16);
  struct cost c;
  memset(&c, 0, sizeof c);
  struct mapped m;
  struct t74_error err = { 0, "" };
  assert_int_equal(mapper_run(s, &m, core, &c, &err), T74_OK);
  assert_int_equal(m.nface, 2);
  int nv = 4;
  for (int f = 0; f < m.nface; f++)
    for (int k = 0; k < m.f[f].ring_start[m.f[f].nring]; k++) {
      int v = m.f[f].vix[k];
      uint32_t a = 6 * (uint32_t)v;
      const struct scene_vertex *sv = &s->v[v];
      assert_int_equal(core_read(core, a), (uint16_t)sv->id);
      assert_int_equal(core_read(core, a + 1), (uint16_t)sv->x);
      assert_int_equal(core_read(core, a + 2), (uint16_t)sv->y);
      assert_int_equal(core_read(core, a + 3), (uint16_t)sv->z);
      assert_int_equal(core_read(core, a + 4), (uint16_t)(m.f[f].pt[k].x / GRID_ONE));
      assert_int_equal(core_read(core, a + 5), (uint16_t)(m.f[f].pt[k].y / GRID_ONE));
    }
  for (int f = 0; f < m.nface; f++) {
    const struct mface *mf = &m.f[f];
    uint32_t a = 6 * (uint32_t)nv + 10 * (uint32_t)f;
    gcoord lo = mf->pt[0].y, hi = mf->pt[0].y;
    for (int k = 1; k < mf->ring_start[1]; k++) {
      if (mf->pt[k].y < lo) lo = mf->pt[k].y;
      if (mf->pt[k].y > hi) hi = mf->pt[k].y;
    }
    int64_t h[4];
    geom_h10_plane(mf->plane, h);
    assert_int_equal(core_read(core, a), (uint16_t)mf->id);
    assert_int_equal(core_read(core, a + 1), (uint16_t)mf->grey);
    assert_int_equal(core_read(core, a + 2), (uint16_t)(lo / GRID_ONE));
    assert_int_equal(core_read(core, a + 3), (uint16_t)(hi / GRID_ONE));
    for (int k = 0; k < 3; k++) assert_int_equal(core_read(core, a + 4 + (uint32_t)k), (uint16_t)h[k]);
    assert_int_equal(core_get_int(core, a + 7, 2), (int64_t)(int32_t)(uint32_t)h[3]);
    assert_int_equal(core_read(core, a + 9), 0);
  }
  mapper_free(&m);
  core_free(core);
  scene_free(s);
}

/* ---- the two ways compared ------------------------------------------------------------ */

struct run { struct mapped m; struct mapper_keep k; struct cost c; struct core *core; };

/* With `counted`, as the 1974 engine runs it (a cost); else as the points engine does
   (cost NULL: no charges counted, so the search looks only where a T-junction can be). */
static void map_run(const struct scene *s, bool whole, bool counted, struct run *r)
{
  memset(r, 0, sizeof *r);
  r->k.whole_boxes = whole;
  r->core = core_new(1u << 22);
  assert_non_null(r->core);
  struct t74_error err = { 0, "" };
  int st = mapper_run_kept(s, &r->m, r->core, counted ? &r->c : NULL, &r->k, &err);
  if (st) print_message("mapper_run_kept: %s\n", err.msg);
  assert_int_equal(st, T74_OK);
  assert_true(r->k.s == s);
  assert_true(r->k.counted == counted);
}

static void map_way(const struct scene *s, bool whole, struct run *r)
{
  map_run(s, whole, true, r);
}

static void run_free(struct run *r)
{
  mapper_free(&r->m);
  mapper_keep_free(&r->k);
  core_free(r->core);
}

/* a and b map the same faces: their rings, points, vertices, planes, depths, greys, ids. */
static void faces_equal(const struct mapped *a, const struct mapped *b)
{
  assert_int_equal(a->nface, b->nface);
  for (int f = 0; f < a->nface; f++) {
    const struct mface *x = &a->f[f], *y = &b->f[f];
    assert_int_equal(x->nring, y->nring);
    int n = x->ring_start[x->nring];
    assert_int_equal(n, y->ring_start[y->nring]);
    assert_memory_equal(x->ring_start, y->ring_start, ((size_t)x->nring + 1) * sizeof *x->ring_start);
    assert_memory_equal(x->pt, y->pt, (size_t)n * sizeof *x->pt);
    assert_memory_equal(x->vid, y->vid, (size_t)n * sizeof *x->vid);
    assert_memory_equal(x->vix, y->vix, (size_t)n * sizeof *x->vix);
    assert_memory_equal(x->plane, y->plane, sizeof x->plane);
    assert_true(x->deye == y->deye && x->grey == y->grey && x->id == y->id);
  }
}

/* a and b kept the same rings (the T-junctions found, in the same order) and mapped the
   same faces. */
static void same_rings(const struct scene *s, const struct run *a, const struct run *b)
{
  int nrings = 0;
  for (int f = 0; f < s->nf; f++) nrings += s->f[f].nring;
  assert_int_equal(a->k.n, b->k.n);
  assert_memory_equal(a->k.ring, b->k.ring, (size_t)a->k.n * sizeof *a->k.ring);
  assert_memory_equal(a->k.start, b->k.start, ((size_t)nrings + 1) * sizeof *a->k.start);
  assert_int_equal(a->m.nface, b->m.nface);
  assert_int_equal(a->m.dropped, b->m.dropped);
  faces_equal(&a->m, &b->m);
}

/* The short and the long way agree on s: the rings kept, the charges, the faces mapped;
   and the points engine's ways (no charges: every row of a slanted box only where its
   line can reach, short and long) keep the same rings and map the same faces. Returns how
   many vertices were inserted into edges. */
static int same_ways(const struct scene *s)
{
  struct run a, b;
  map_way(s, false, &a);
  map_way(s, true, &b);
  same_rings(s, &a, &b);
  assert_memory_equal(&a.k.cost, &b.k.cost, sizeof a.k.cost);
  assert_memory_equal(&a.c, &b.c, sizeof a.c);
  for (int whole = 0; whole < 2; whole++) {
    struct run p;
    map_run(s, whole, false, &p);
    same_rings(s, &p, &b);
    run_free(&p);
  }
  int given = 0;
  for (int f = 0; f < s->nf; f++) given += s->f[f].ring_start[s->f[f].nring];
  int inserted = a.k.n - given;
  run_free(&a);
  run_free(&b);
  return inserted;
}

/* The scene of a text (taken). */
static struct scene *load_text_taken(char *text)
{
  struct scene *s = load_text(text);
  free(text);
  return s;
}

/* A generated scene's text (taken): both ways alike, and at least the `inserted` vertices
   the generator put on edges found. */
static void check_text(char *text, int inserted)
{
  struct scene *s = load_text_taken(text);
  int found = same_ways(s);
  if (found < inserted) print_message("found %d of the %d put on edges\n", found, inserted);
  assert_true(found >= inserted);
  scene_free(s);
}

/* Fans in depth: every vertex put on a large triangle's edge is found, both ways alike. */
static void test_fans_both_ways(void **state)
{
  (void)state;
  for (uint32_t seed = 1; seed <= 12; seed++) {
    int inserted;
    char *text = fan_scene(40 + 10 * (int)seed, 0, seed, false, &inserted);
    check_text(text, inserted);
  }
}

/* An edge met again, the other way or the same way, is not searched again (render/mapper.c
   tj_edge_memo): its vertices are copied, those at one point still by index; the long way
   searches every edge. Both alike, every edge met again taken from the first. */
static void test_edges_met_again(void **state)
{
  (void)state;
  for (uint32_t seed = 200; seed < 208; seed++) {
    int inserted;
    struct scene *s = load_text_taken(fan_scene(25, seed % 2 ? 200 : 0, seed, true, &inserted));
    struct run a;
    map_way(s, false, &a);
    assert_true(a.k.replayed >= 25);   /* two a fan (but where another edge took the slot) */
    run_free(&a);
    map_way(s, true, &a);
    assert_int_equal(a.k.replayed, 0);
    run_free(&a);
    assert_true(same_ways(s) >= inserted);
    scene_free(s);
  }
}

/* One frame (mapper_keep.once): the faces, the charges and the edges taken from the memo
   are those of a run that keeps its rings for the next; nothing is left kept (the planes
   never made, the rings freed), so a next run searches again and maps the same. */
static void test_once_keeps_nothing(void **state)
{
  (void)state;
  for (uint32_t seed = 300; seed < 306; seed++) {
    int inserted;
    struct scene *s = load_text_taken(fan_scene(30, seed % 2 ? 200 : 0, seed, true, &inserted));
    struct run a, o;
    map_way(s, false, &a);
    memset(&o, 0, sizeof o);
    o.k.once = true;
    o.core = core_new(1u << 22);
    assert_non_null(o.core);
    for (int pass = 0; pass < 2; pass++) {          /* the second: after a run kept nothing */
      struct t74_error err = { 0, "" };
      mapper_free(&o.m);
      memset(&o.c, 0, sizeof o.c);
      core_free(o.core);
      o.core = core_new(1u << 22);
      assert_non_null(o.core);
      assert_int_equal(mapper_run_kept(s, &o.m, o.core, &o.c, &o.k, &err), T74_OK);
      assert_null(o.k.s);
      assert_null(o.k.ring);
      assert_null(o.k.start);
      assert_null(o.k.plane);
      assert_int_equal(o.k.replayed, a.k.replayed);
      assert_memory_equal(&o.k.cost, &a.k.cost, sizeof a.k.cost);
      assert_memory_equal(&o.c, &a.c, sizeof a.c);
      assert_int_equal(o.m.nface, a.m.nface);
      assert_int_equal(o.m.dropped, a.m.dropped);
      faces_equal(&a.m, &o.m);
    }
    assert_true(a.k.replayed >= 25);
    run_free(&a);
    run_free(&o);
    scene_free(s);
  }
}

/* Fans among random triangles (the cells crowded, most vertices near no edge). */
static void test_fans_among_triangles(void **state)
{
  (void)state;
  for (uint32_t seed = 100; seed < 106; seed++) {
    int inserted;
    char *text = fan_scene(30, 400, seed, false, &inserted);
    check_text(text, inserted);
  }
}

/* Fans seen from an eye one unit before the plane (view 0 0 -1), far off in depth: the
   vertices crowd some hundred grid units, so the search's cells are one grid unit wide
   and a T-junction vertex whose rounded point lies off the rounded segment a'-b' (by up
   to a grid unit, each end and the vertex rounded their own way) often sits in a cell
   the thin line itself does not reach: only the band's margin (mapper.c) keeps that
   cell. Edges steep, shallow and in depth (strong perspective: the points along an edge
   unevenly spaced); random triangles among them fill the cells. */
static bool in_box(int x, int y, int z)
{
  return x >= -1200 && x <= 1200 && y >= -1200 && y <= 1200 && z >= 6000 && z <= 30000;
}

static char *margin_scene(int nfan, int nrand, uint32_t seed, int *inserted)
{
  struct text x = { NULL, 0, 0 };
  put(&x, "view 0 0 -1\nwindow -1 -1 1 1\n");
  rnd_state = seed;
  int v = 0, f = 0;
  *inserted = 0;
  for (int q = 0; q < nfan; q++) {
    int k, dx, dy, dz, ax, ay, az;
    do {                                    /* an edge P0-Pk wholly in the box */
      k = rnd(3, 24);
      int steep = rnd(0, 3);                /* 0 steep, 1 shallow, 2 3 any slope */
      dx = steep == 0 ? rnd(-8, 8) : rnd(-160, 160);
      dy = steep == 1 ? rnd(-8, 8) : rnd(-160, 160);
      dz = rnd(-900, 900);
      ax = rnd(-1200, 1200); ay = rnd(-1200, 1200); az = rnd(6000, 30000);
    } while ((dx == 0 && dy == 0) || (dx > -3 && dx < 3 && dy > -3 && dy < 3) ||
             !in_box(ax + k * dx, ay + k * dy, az + k * dz));
    int p0 = v + 1;
    for (int j = 0; j <= k; j++)
      put(&x, "vertex %d %d %d %d\n", ++v, ax + j * dx, ay + j * dy, az + j * dz);
    /* Q and the R's on either side of the line (the normal (-dy, dx)); may leave the box */
    put(&x, "vertex %d %d %d %d\n", ++v, ax + k * dx / 2 - dy * 3, ay + k * dy / 2 + dx * 3,
        az + k * dz / 2 + 11);
    put(&x, "face %d %d %d %d grey %d\n", ++f, p0, p0 + k, v, rnd(60, 255));
    for (int j = 0; j < k; j++) {
      put(&x, "vertex %d %d %d %d\n", ++v, ax + j * dx + dx / 2 + dy, ay + j * dy + dy / 2 - dx,
          az + j * dz + dz / 2 + 5);
      put(&x, "face %d %d %d %d grey %d\n", ++f, p0 + j, v, p0 + j + 1, rnd(60, 255));
    }
    *inserted += k - 1;
  }
  for (int q = 0; q < nrand; q++) {
    int cx = rnd(-1100, 1100), cy = rnd(-1100, 1100), cz = rnd(7000, 29000);
    for (int j = 0; j < 3; j++)
      put(&x, "vertex %d %d %d %d\n", ++v, cx + rnd(-100, 100), cy + rnd(-100, 100),
          cz + rnd(-900, 900));
    put(&x, "face %d %d %d %d grey %d\n", ++f, v - 2, v - 1, v, rnd(60, 255));
  }
  return x.t;
}

/* The band's margin (mapper.c): a T-junction vertex's point off the thin line by up to a
   grid unit, in one-unit cells: with either end of its y margin a unit nearer, or either
   x end (floor(xlo), floor(xhi) + 1, tight), this fails. */
static void test_margin_one_unit_cells(void **state)
{
  (void)state;
  for (uint32_t seed = 200; seed < 230; seed++) {
    int inserted;
    char *text = margin_scene(150, 600, seed, &inserted);
    check_text(text, inserted);
  }
}

/* Random triangles through one another (as tools/mktris.py makes them: large, slanted,
   in depth), each new one with a corner placed exactly on an edge of an earlier one (the
   corners are multiples of 12, the point at k/m of the edge, m dividing 12 and the
   edge's differences: an edge with an end so placed takes only such m), some with two; seen from far (view 0 0 -3000, cells of many grid units) or from one unit before
   the plane (one-unit cells). Every corner put on an edge is found, by each way. */
static char *on_edge_scene(int ntri, bool near, uint32_t seed, int *inserted)
{
  struct text x = { NULL, 0, 0 };
  put(&x, near ? "view 0 0 -1\nwindow -1 -1 1 1\n" : "view 0 0 -3000\nwindow -200 -150 200 150\n");
  rnd_state = seed;
  int (*c)[3] = malloc((size_t)ntri * 3 * sizeof *c);     /* every corner's point */
  assert_non_null(c);
  int v = 0;
  *inserted = 0;
  for (int q = 0; q < ntri; q++) {
    int n = near ? 100 : 15, z0 = near ? 500 : 25, z1 = near ? 2500 : 210;
    for (int j = 0; j < 3; j++) {
      c[3 * q + j][0] = 12 * rnd(-n, n);
      c[3 * q + j][1] = 12 * rnd(-n, n);
      c[3 * q + j][2] = 12 * rnd(z0, z1);
    }
    for (int j = 0; j < (q > 0) + (q > 1 && rnd(0, 2) == 0); j++) {   /* onto an edge */
      int o = rnd(0, q - 1), e = rnd(0, 2), m = (int[]){ 2, 3, 4, 6, 12 }[rnd(0, 4)];
      int k = rnd(1, m - 1);
      const int *P = c[3 * o + e], *Q = c[3 * o + (e + 1) % 3];
      int dx = Q[0] - P[0], dy = Q[1] - P[1], dz = Q[2] - P[2];
      while (m > 1 && (dx % m || dy % m || dz % m)) m /= 2;   /* ends placed on edges */
      if ((!dx && !dy && !dz) || m == 1) continue;            /* earlier: not all of 12 */
      if (k >= m) k = m - 1;
      int w[3], *o1 = c[3 * q + (j + 1) % 3], *o2 = c[3 * q + (j + 2) % 3];
      for (int i = 0; i < 3; i++) w[i] = P[i] + k * (Q[i] - P[i]) / m;
      int64_t u[3], r[3];                   /* a triangle still (not at a line) */
      for (int i = 0; i < 3; i++) { u[i] = o1[i] - w[i]; r[i] = o2[i] - w[i]; }
      if (u[1] * r[2] == u[2] * r[1] && u[2] * r[0] == u[0] * r[2] && u[0] * r[1] == u[1] * r[0])
        continue;
      memcpy(c[3 * q + j], w, sizeof w);
      (*inserted)++;
    }
    for (int j = 0; j < 3; j++)
      put(&x, "vertex %d %d %d %d\n", ++v, c[3 * q + j][0], c[3 * q + j][1], c[3 * q + j][2]);
    put(&x, "face %d %d %d %d grey %d\n", q + 1, v - 2, v - 1, v, rnd(60, 255));
  }
  free(c);
  return x.t;
}

static void test_on_edges_all_ways(void **state)
{
  (void)state;
  for (uint32_t seed = 400; seed < 424; seed++) {
    int inserted;
    char *text = on_edge_scene(seed % 2 ? 300 : 120, seed % 3 == 0, seed, &inserted);
    check_text(text, inserted);
  }
}

/* The points engine's search (cost NULL) counts no charges, so what it kept is not
   replayed by a run that wants them: that run searches again and charges as a first. */
static void test_uncounted_not_replayed(void **state)
{
  (void)state;
  int inserted;
  struct scene *s = load_text_taken(fan_scene(30, 100, 77, true, &inserted));
  struct run a, p;
  map_way(s, false, &a);
  map_run(s, false, false, &p);
  mapper_free(&p.m);
  struct t74_error err = { 0, "" };
  assert_int_equal(mapper_run_kept(s, &p.m, p.core, &p.c, &p.k, &err), T74_OK);
  assert_true(p.k.counted);
  assert_memory_equal(&p.c, &a.c, sizeof a.c);
  assert_memory_equal(&p.k.cost, &a.k.cost, sizeof a.k.cost);
  same_rings(s, &p, &a);
  run_free(&a);
  run_free(&p);
  scene_free(s);
}

/* An edge steep in depth, a = (0, 0, 100) to b = (64, 32, 900) (|b - a|^2 = 800^2 + ...,
   most of it in z), with a vertex of a small triangle at each eighth of it, P_k = a + k (b
   - a) / 8, k = 1 .. 7: both searches (the 1974 engine's, counted, and the points
   engine's) put all seven into the large face's ring, in order from a to b (or from b to
   a, as the Mapper turned the ring), and keep the same rings. The fields in space of an
   edge are set only when a vertex is to be tested (tj_seg_space): one wrong (|b - a|^2
   without the z term, say) loses the P_k near b, or all. */
static void test_steep_edge_all_found(void **state)
{
  (void)state;
  char text[2048];
  int at = snprintf(text, sizeof text,
                    "view 0 0 -500\nwindow -200 -150 200 150\n"
                    "vertex 1 0 0 100\nvertex 2 64 32 900\nvertex 3 -150 90 400\n"
                    "face 1 1 2 3 grey 200\n");
  for (int k = 1; k <= 7; k++)
    at += snprintf(text + at, sizeof text - (size_t)at,
                   "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n"
                   "face %d %d %d %d grey 100\n",
                   10 * k, 8 * k, 4 * k, 100 + 100 * k,
                   10 * k + 1, 8 * k + 30, 4 * k - 20, 100 + 100 * k,
                   10 * k + 2, 8 * k + 25, 4 * k - 40, 110 + 100 * k,
                   1 + k, 10 * k, 10 * k + 1, 10 * k + 2);
  struct scene *s = load_text(text);
  struct run r[2];
  for (int counted = 0; counted < 2; counted++) {
    map_run(s, false, counted, &r[counted]);
    const struct mface *f = NULL;
    for (int q = 0; q < r[counted].m.nface; q++)
      if (r[counted].m.f[q].id == 1) f = &r[counted].m.f[q];
    assert_non_null(f);
    assert_int_equal(f->ring_start[f->nring], 10);
    int ia = -1;                             /* where a is in the ring */
    for (int q = 0; q < 10; q++) if (f->vid[q] == 1) ia = q;
    assert_true(ia >= 0);
    int dir = f->vid[(ia + 1) % 10] == 10 ? 1 : -1;   /* towards P_1 */
    for (int k = 1; k <= 7; k++)
      assert_int_equal(f->vid[(ia + 10 + dir * k) % 10], 10 * k);
    assert_int_equal(f->vid[(ia + 10 + dir * 8) % 10], 2);
  }
  same_rings(s, &r[0], &r[1]);
  run_free(&r[0]);
  run_free(&r[1]);
  scene_free(s);
}

/* Faces of 3, 4 and 5 corners (ring_area2's triangle, quadrilateral and general sums),
   planar, convex, given clockwise or counter-clockwise: every one mapped (none covers no
   point), its ring counter-clockwise on the grid (twice its area, summed here in 128
   bits, above 0), the same points as given in one order or the other. A sign wrong in
   either short form turns those rings the wrong way. */
static void test_rings_turned_ccw(void **state)
{
  (void)state;
  struct text x = { NULL, 0, 0 };
  put(&x, "view 0 0 -500\nwindow -200 -150 200 150\n");
  rnd_state = 1974;
  int v = 0, nf = 0;
  for (int q = 0; q < 60; q++) {
    int n = 3 + q % 3, cx = rnd(-120, 120), cy = rnd(-90, 90), r = rnd(8, 40);
    bool cw = rnd(0, 1);
    /* corners on a circle of radius r at angles a quarter turn apart (n = 4) or so,
       jittered by at most r / 8: convex */
    static const int ux[5][5] = { { 0 }, { 0 }, { 0 }, { 8, -4, -4 }, { 8, 0, -8, 0 } };
    static const int uy[5][5] = { { 0 }, { 0 }, { 0 }, { 0, 7, -7 }, { 0, 8, 0, -8 } };
    static const int px[5] = { 8, 2, -6, -6, 2 }, py[5] = { 0, 8, 5, -5, -8 };
    for (int k = 0; k < n; k++) {
      int kk = cw ? n - 1 - k : k;
      int dx = n == 5 ? px[kk] : ux[n][kk], dy = n == 5 ? py[kk] : uy[n][kk];
      int X = cx + dx * r / 8 + rnd(-r / 16, r / 16), Y = cy + dy * r / 8 + rnd(-r / 16, r / 16);
      put(&x, "vertex %d %d %d %d\n", ++v, X, Y, 600 + q * 10);
    }
    put(&x, "face %d", ++nf);
    for (int k = n - 1; k >= 0; k--) put(&x, " %d", v - k);
    put(&x, " grey 150\n");
  }
  struct scene *s = load_text_taken(x.t);
  for (int counted = 0; counted < 2; counted++) {
    struct run r;
    map_run(s, false, counted, &r);
    assert_int_equal(r.m.nface, nf);
    assert_int_equal(r.m.dropped, 0);
    for (int f = 0; f < r.m.nface; f++) {
      const struct mface *m = &r.m.f[f];
      assert_int_equal(m->nring, 1);
      int n = m->ring_start[1];
      assert_int_equal(n, 3 + (int)(m->id - 1) % 3);
      wide a = 0;
      for (int j = n - 1, k = 0; k < n; j = k++)
        a += (wide)m->pt[j].x * m->pt[k].y - (wide)m->pt[k].x * m->pt[j].y;
      assert_true(a > 0);
    }
    run_free(&r);
  }
  scene_free(s);
}

/* The Lambert greys kept with the planes (struct mapper_keep's lgrey, one for each sign the
   eye may give the plane): a scene lit by one parallel light, of triangles with no grey of
   their own (their greys by Lambert's law), every other one listed the other way round (so
   that both of a plane's signs are taken), some turned from the light, some edge-on to it,
   mapped with a keep three times
   (the search, then two replays), counted and not, and on a keep that held another
   scene's: every run maps the faces a run without a keep maps, greys too. */
static void test_kept_greys(void **state)
{
  (void)state;
  for (int lights = 1; lights <= 2; lights++) {
    struct text x = { NULL, 0, 0 };
    put(&x, "view 0 0 -500\nwindow -200 -150 200 150\nlight -45 60 -80\n");
    if (lights == 2) put(&x, "light 30 -20 -90\n");     /* (shade_grey's case) */
    rnd_state = 2026 + (uint32_t)lights;
    int v = 0;
    for (int q = 0; q < 80; q++) {
      const int cx = rnd(-150, 150), cy = rnd(-110, 110), z = rnd(100, 900);
      static const int ox[3] = { -25, 25, 0 }, oy[3] = { -20, -20, 25 };
      for (int k = 0; k < 3; k++)
        put(&x, "vertex %d %d %d %d\n", ++v, cx + ox[k] + rnd(-5, 5), cy + oy[k] + rnd(-5, 5),
            z + (q % 4 == 3 ? 0 : rnd(-60, 60)));
      if (q % 2)                                /* the other way round: its plane turned */
        put(&x, "face %d %d %d %d\n", q + 1, v, v - 1, v - 2);
      else
        put(&x, "face %d %d %d %d\n", q + 1, v - 2, v - 1, v);
    }
    struct scene *s = load_text_taken(x.t), *other = load_text_taken(strdup(
        "view 0 0 -500\nwindow -200 -150 200 150\nlight 1 2 -3\n"
        "vertex 1 -50 -50 100\nvertex 2 50 -50 120\nvertex 3 0 50 140\nface 1 1 2 3\n"));
    struct core *core = core_new(1u << 22);
    assert_non_null(core);
    struct t74_error err = { 0, "" };
    struct mapped want;
    assert_int_equal(mapper_run(s, &want, core, NULL, &err), T74_OK);
    int lit = 0;
    for (int f = 0; f < want.nface; f++) lit += want.f[f].grey != want.f[0].grey;
    assert_true(lit > 0);                       /* greys that differ: the law at work */
    for (int counted = 0; counted < 2; counted++)
      for (int first_other = 0; first_other < 2; first_other++) {
        struct mapper_keep k;
        memset(&k, 0, sizeof k);
        struct cost c;
        memset(&c, 0, sizeof c);
        if (first_other) {
          struct mapped o;
          assert_int_equal(mapper_run_kept(other, &o, core, counted ? &c : NULL, &k, &err),
                           T74_OK);
          mapper_keep_faces(&o, &k);
          mapper_free(&o);
        }
        for (int run = 0; run < 3; run++) {
          struct mapped m;
          assert_int_equal(mapper_run_kept(s, &m, core, counted ? &c : NULL, &k, &err),
                           T74_OK);
          faces_equal(&m, &want);
          mapper_keep_faces(&m, &k);
          mapper_free(&m);
        }
        mapper_keep_free(&k);
      }
    mapper_free(&want);
    core_free(core);
    scene_free(other);
    scene_free(s);
  }
}

/* Faces of three and four corners (mapper_run_kept takes such a ring without its ring
   loop, ring_three and ring_four, when no two consecutive grid points are one and the
   ring's area is not 0): random triangles and convex quadrilaterals (flat in z), each in a
   cell of its own (no T-junctions), some near, some so far from the eye that rounding puts
   corners on one grid point or on one line (a few grid units across, or less than one).
   Every run, counted or not, the first and a replay, maps exactly the faces whose
   consecutive grid points (mapper_point) are apart and whose area is not 0, in the
   scene's order, each ring its corners in the scene's order where it turns left on the
   grid and reversed where it turns right, with their ids and scene vertices; a face with
   two consecutive corners on one point is the loop's, which keeps fewer points (or none). */
static void test_small_rings(void **state)
{
  (void)state;
  struct text x = { NULL, 0, 0 };
  put(&x, "view 0 0 -10\nwindow -200 -150 200 150\n");
  rnd_state = 3838;
  int v = 0;
  const int nt = 600;
  for (int q = 0; q < nt; q++) {
    const int n = 3 + q % 2, far = q / 2 % 3;   /* near, a few grid units, under one */
    const int cx = -190 + (q % 25) * 15, cy = -140 + (q / 25) * 11, r = far == 2 ? 4 : 5;
    const int z = far == 2 ? rnd(25000, 32000) : far ? rnd(1500, 4000) : rnd(10, 300);
    int P[4][3];
    if (n == 4) {                               /* convex, in the plane of z */
      static const int sx[4] = { -1, 1, 1, -1 }, sy[4] = { -1, -1, 1, 1 };
      const bool cw = rnd(0, 1);
      for (int k = 0; k < 4; k++) {
        const int kk = cw ? 3 - k : k;
        P[k][0] = cx + sx[kk] * r + rnd(-1, 1);
        P[k][1] = cy + sy[kk] * r + rnd(-1, 1);
        P[k][2] = z;
      }
    } else {
      long long c[3] = { 0, 0, 0 };
      while (!(c[0] | c[1] | c[2])) {           /* three corners not on one line in space */
        for (int k = 0; k < 3; k++) {
          P[k][0] = cx + rnd(-r, r);
          P[k][1] = cy + rnd(-r, r);
          P[k][2] = z + rnd(-r, r);
        }
        const long long u[3] = { P[1][0] - P[0][0], P[1][1] - P[0][1], P[1][2] - P[0][2] },
                        t[3] = { P[2][0] - P[0][0], P[2][1] - P[0][1], P[2][2] - P[0][2] };
        c[0] = u[1] * t[2] - u[2] * t[1];
        c[1] = u[2] * t[0] - u[0] * t[2];
        c[2] = u[0] * t[1] - u[1] * t[0];
      }
    }
    for (int k = 0; k < n; k++) put(&x, "vertex %d %d %d %d\n", ++v, P[k][0], P[k][1], P[k][2]);
    put(&x, "face %d", q + 1);
    for (int k = n - 1; k >= 0; k--) put(&x, " %d", v - k);
    put(&x, " grey 120\n");
  }
  struct scene *s = load_text_taken(x.t);
  int kept[5] = { 0 }, flat[5] = { 0 }, turned[5] = { 0 };   /* by corners, of the scene */
  for (int counted = 0; counted < 2; counted++) {
    struct run r;
    map_run(s, false, counted, &r);
    for (int again = 0; again < 2; again++) {
      int f = 0;
      for (int q = 0; q < s->nf; q++) {
        const int *w = s->f[q].vidx, n = s->f[q].ring_start[1];
        struct gpoint p[4];
        bool apart = true;
        for (int k = 0; k < n; k++) p[k] = mapper_point(s, w[k]);
        for (int k = 0; k < n; k++) {
          const struct gpoint a = p[k], b = p[(k + 1) % n];
          apart = apart && !(a.x == b.x && a.y == b.y);
        }
        if (!apart) {                           /* the loop's: a point dropped, or the face */
          if (f < r.m.nface && r.m.f[f].sface == q) {
            assert_true(r.m.f[f].ring_start[1] < n);
            f++;
          }
          continue;
        }
        const wide area = n == 3 ? (wide)(p[1].x - p[0].x) * (p[2].y - p[0].y) -
                                       (wide)(p[1].y - p[0].y) * (p[2].x - p[0].x)
                                 : (wide)(p[2].x - p[0].x) * (p[3].y - p[1].y) -
                                       (wide)(p[2].y - p[0].y) * (p[3].x - p[1].x);
        if (!counted && !again) {
          kept[n] += area != 0;
          flat[n] += area == 0;
          turned[n] += area < 0;
        }
        if (area == 0) {                        /* dropped */
          assert_true(f == r.m.nface || r.m.f[f].sface != q);
          continue;
        }
        assert_true(f < r.m.nface);
        const struct mface *m = &r.m.f[f++];
        assert_int_equal(m->sface, q);
        assert_int_equal(m->nring, 1);
        assert_int_equal(m->ring_start[0], 0);
        assert_int_equal(m->ring_start[1], n);
        for (int k = 0; k < n; k++) {
          const int o = area > 0 ? k : n - 1 - k;
          assert_int_equal(m->vix[k], w[o]);
          assert_int_equal(m->vid[k], s->v[w[o]].id);
          assert_true(m->pt[k].x == p[o].x && m->pt[k].y == p[o].y);
        }
      }
      assert_int_equal(f, r.m.nface);
      /* a replay from the keep */
      struct t74_error err = { 0, "" };
      mapper_keep_faces(&r.m, &r.k);
      mapper_free(&r.m);
      assert_int_equal(mapper_run_kept(s, &r.m, r.core, counted ? &r.c : NULL, &r.k, &err),
                       T74_OK);
    }
    run_free(&r);
  }
  for (int n = 3; n <= 4; n++)                  /* every kind there */
    assert_true(kept[n] > 0 && flat[n] > 0 && turned[n] > 0 && turned[n] < kept[n]);
  scene_free(s);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_core_rows),
    cmocka_unit_test(test_fans_both_ways),
    cmocka_unit_test(test_fans_among_triangles),
    cmocka_unit_test(test_edges_met_again),
    cmocka_unit_test(test_once_keeps_nothing),
    cmocka_unit_test(test_margin_one_unit_cells),
    cmocka_unit_test(test_on_edges_all_ways),
    cmocka_unit_test(test_uncounted_not_replayed),
    cmocka_unit_test(test_steep_edge_all_found),
    cmocka_unit_test(test_rings_turned_ccw),
    cmocka_unit_test(test_kept_greys),
    cmocka_unit_test(test_small_rings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
