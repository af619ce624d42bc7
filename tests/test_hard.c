/*
** test_hard.c — the hard cases, run through the real program ($TUBE74, default ./tube74).
**
** Each test writes small .s74 scenes into a temporary folder, runs `tube74 render` with
** --dump ids / tube / points and --stats, parses the outputs here (P5 16-bit big-endian
** ids, row 0 = top row j = 0; P4 tube; the points text; the stats JSON) and checks exact
** results. Most scenes use view 0 0 -1000, window -200 -150 200 150 and cell 4, so the
** grid is 100 x 75, point (i, j) has its centre at x = -198 + 4i, y = 148 - 4j, and a face
** at z = 0 projects onto itself: the expected ids then follow exactly from the tie rule
** (render/geom.h: a point on a non-horizontal boundary belongs to the side of larger x,
** on a horizontal one to the side of larger y), computed here independently as a
** half-open ray cast. Scenes in depth are checked against a floating-point ray cast at
** points well away from every edge and every intersection line.
** Beyond the fifteen cases of the issue: cell 3 with an odd window, projections near the
** plane grid's limit, three planes through one line, T-junctions in depth, a touch
** anchored on two close vertices, the core limit with a large priority matrix, the stats
** fields, and random scenes (T74_RANDOM_ROUNDS / T74_RANDOM_SEED run more of them).
** Run from the repository root; T74_KEEP=1 keeps the temporary folder.
*/
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <setjmp.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cmocka.h>

#include "patterns/halftone.h"
#include "tests/ref/exactref.h"

extern char **environ;

__extension__ typedef __int128 i128;

/* ---- scenes ------------------------------------------------------------------------- */

#define SC_MAXV 512
#define SC_MAXF 48
#define SC_MAXR 8
#define SC_MAXFV 64

struct sface {
  int id, grey;                  /* grey < 0: not given */
  int nring;
  int rs[SC_MAXR + 1];           /* ring starts into vid */
  int vid[SC_MAXFV];             /* vertex ids */
};

struct scn {
  int view[3];
  int window[4];
  int nv;
  int v[SC_MAXV][3];             /* vertex id k + 1 */
  int nf;
  struct sface f[SC_MAXF];
};

static void sc_init(struct scn *s, int x0, int y0, int z0, int xl, int yb, int xr, int yt)
{
  memset(s, 0, sizeof *s);
  s->view[0] = x0; s->view[1] = y0; s->view[2] = z0;
  s->window[0] = xl; s->window[1] = yb; s->window[2] = xr; s->window[3] = yt;
}

static void sc_std(struct scn *s) { sc_init(s, 0, 0, -1000, -200, -150, 200, 150); }

static int sc_vertex(struct scn *s, int x, int y, int z)
{
  assert_true(s->nv < SC_MAXV);
  s->v[s->nv][0] = x; s->v[s->nv][1] = y; s->v[s->nv][2] = z;
  return ++s->nv;
}

/* A face from n points (x, y, z triples), new vertices. */
static struct sface *sc_face3(struct scn *s, int id, int grey, int n, const int *xyz)
{
  assert_true(s->nf < SC_MAXF && n <= SC_MAXFV);
  struct sface *f = &s->f[s->nf++];
  memset(f, 0, sizeof *f);
  f->id = id;
  f->grey = grey;
  f->nring = 1;
  for (int k = 0; k < n; k++) f->vid[k] = sc_vertex(s, xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]);
  f->rs[1] = n;
  return f;
}

/* A face at z = z0 from n points (x, y pairs). */
static struct sface *sc_face2(struct scn *s, int id, int grey, int n, const int *xy, int z0)
{
  int xyz[3 * SC_MAXFV];
  for (int k = 0; k < n; k++) {
    xyz[3 * k] = xy[2 * k];
    xyz[3 * k + 1] = xy[2 * k + 1];
    xyz[3 * k + 2] = z0;
  }
  return sc_face3(s, id, grey, n, xyz);
}

/* A hole ring of existing vertex ids appended to face f. */
static void sc_hole_ids(struct sface *f, int n, const int *ids)
{
  assert_true(f->nring < SC_MAXR && f->rs[f->nring] + n <= SC_MAXFV);
  int b = f->rs[f->nring];
  for (int k = 0; k < n; k++) f->vid[b + k] = ids[k];
  f->nring++;
  f->rs[f->nring] = b + n;
}

enum { SC_REV_FACES = 1, SC_REV_RINGS = 2 };

static void sc_write(const struct scn *s, const char *path, int flags)
{
  FILE *o = fopen(path, "w");
  assert_non_null(o);
  fprintf(o, "# written by tests/test_hard.c\n");
  fprintf(o, "view %d %d %d\n", s->view[0], s->view[1], s->view[2]);
  fprintf(o, "window %d %d %d %d\n", s->window[0], s->window[1], s->window[2], s->window[3]);
  for (int k = 0; k < s->nv; k++)
    fprintf(o, "vertex %d %d %d %d\n", k + 1, s->v[k][0], s->v[k][1], s->v[k][2]);
  for (int q = 0; q < s->nf; q++) {
    const struct sface *f = &s->f[(flags & SC_REV_FACES) ? s->nf - 1 - q : q];
    fprintf(o, "face %d", f->id);
    for (int r = 0; r < f->nring; r++) {
      if (r) fprintf(o, " *");
      int a = f->rs[r], b = f->rs[r + 1];
      for (int k = a; k < b; k++)
        fprintf(o, " %d", f->vid[(flags & SC_REV_RINGS) ? a + b - 1 - k : k]);
    }
    if (f->grey >= 0) fprintf(o, " grey %d", f->grey);
    fprintf(o, "\n");
  }
  fclose(o);
}

/* ---- files and the program ------------------------------------------------------------ */

static char tmpdir[64];
static const char *tube74;

static int group_setup(void **state)
{
  (void)state;
  tube74 = getenv("TUBE74");
  if (!tube74 || !*tube74) tube74 = "./tube74";
  strcpy(tmpdir, "/tmp/t74hard.XXXXXX");
  return mkdtemp(tmpdir) ? 0 : -1;
}

static void rm_tree(const char *dir)
{
  DIR *d = opendir(dir);
  if (!d) return;
  struct dirent *e;
  char p[512];
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
    struct stat st;
    if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) { rm_tree(p); rmdir(p); }
    else unlink(p);
  }
  closedir(d);
}

static int group_teardown(void **state)
{
  (void)state;
  if (!getenv("T74_KEEP")) { rm_tree(tmpdir); rmdir(tmpdir); }
  else fprintf(stderr, "kept %s\n", tmpdir);
  return 0;
}

static const char *tpath(const char *name)
{
  static char buf[32][256];          /* a ring of buffers: copy a path that must live long */
  static int k;
  char *b = buf[k++ % 32];
  snprintf(b, 256, "%s/%s", tmpdir, name);
  return b;
}

static bool exists(const char *path)
{
  struct stat st;
  return stat(path, &st) == 0;
}

static char *slurp(const char *path, size_t *len)
{
  if (len) *len = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 4096, n = 0;
  char *b = malloc(cap + 1);
  size_t r;
  while ((r = fread(b + n, 1, cap - n, f)) > 0) {
    n += r;
    if (n == cap) { cap *= 2; b = realloc(b, cap + 1); }
  }
  fclose(f);
  b[n] = 0;
  if (len) *len = n;
  return b;
}

static void put_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

/* Run tube74 with argv (NULL-terminated, without the program), stdout and stderr to
   files. Returns the exit status, or 128 + signal. *err gets stderr's text (malloc). */
static int run_prog(const char *const *args, char **err)
{
  const char *argv[64];
  int n = 0;
  argv[n++] = tube74;
  for (; args[n - 1] && n < 63; n++) argv[n] = args[n - 1];
  argv[n] = NULL;
  const char *outp = tpath("prog.stdout"), *errp = tpath("prog.stderr");
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, outp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, errp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid;
  int rc = posix_spawn(&pid, tube74, &fa, NULL, (char *const *)argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) fail_msg("cannot run %s: %s", tube74, strerror(rc));
  int ws;
  while (waitpid(pid, &ws, 0) < 0)
    if (errno != EINTR) fail_msg("waitpid: %s", strerror(errno));
  char *e = slurp(errp, NULL);
  if (err) *err = e;
  else free(e);
  unlink(outp);
  unlink(errp);
  if (WIFSIGNALED(ws)) return 128 + WTERMSIG(ws);
  return WEXITSTATUS(ws);
}

/* ---- outputs ------------------------------------------------------------------------- */

struct out {
  int status;
  char *err;
  int W, H;
  uint16_t *ids;                 /* ids[j * W + i] */
  uint8_t *tube;                 /* tube[y * 400 + x], y from the BOTTOM */
  int npts;
  int (*pts)[2];
  char *points_text;
  char *stats;
};

static void out_free(struct out *o)
{
  free(o->err); free(o->ids); free(o->tube); free(o->pts); free(o->points_text); free(o->stats);
  memset(o, 0, sizeof *o);
}

/* Netpbm header: magic, then n integers, separated by whitespace / comments, then one
   whitespace byte. Returns the offset of the data. */
static size_t pnm_header(const char *b, size_t len, const char *magic, int n, int *val)
{
  assert_true(len >= 2 && b[0] == magic[0] && b[1] == magic[1]);
  size_t p = 2;
  for (int k = 0; k < n; k++) {
    for (;;) {
      while (p < len && (b[p] == ' ' || b[p] == '\n' || b[p] == '\r' || b[p] == '\t')) p++;
      if (p < len && b[p] == '#') { while (p < len && b[p] != '\n') p++; continue; }
      break;
    }
    assert_true(p < len && b[p] >= '0' && b[p] <= '9');
    int v = 0;
    while (p < len && b[p] >= '0' && b[p] <= '9') v = v * 10 + (b[p++] - '0');
    val[k] = v;
  }
  assert_true(p < len);
  return p + 1;
}

static void read_ids(struct out *o, const char *path)
{
  size_t len;
  char *b = slurp(path, &len);
  assert_non_null(b);
  int v[3];
  size_t p = pnm_header(b, len, "P5", 3, v);
  assert_int_equal(v[2], 65535);
  o->W = v[0];
  o->H = v[1];
  assert_true(len - p == (size_t)2 * o->W * o->H);
  o->ids = malloc((size_t)o->W * o->H * sizeof *o->ids);
  for (int k = 0; k < o->W * o->H; k++)
    o->ids[k] = (uint16_t)((uint8_t)b[p + 2 * k] << 8 | (uint8_t)b[p + 2 * k + 1]);
  free(b);
}

static void read_pbm(struct out *o, const char *path)
{
  size_t len;
  char *b = slurp(path, &len);
  assert_non_null(b);
  int v[2];
  size_t p = pnm_header(b, len, "P4", 2, v);
  assert_int_equal(v[0], 400);
  assert_int_equal(v[1], 300);
  assert_true(len - p == (size_t)50 * 300);
  o->tube = calloc(400 * 300, 1);
  for (int r = 0; r < 300; r++)
    for (int x = 0; x < 400; x++)
      o->tube[(299 - r) * 400 + x] = ((uint8_t)b[p + r * 50 + x / 8] >> (7 - x % 8)) & 1;
  free(b);
}

static void read_points(struct out *o, const char *path)
{
  size_t len;
  o->points_text = slurp(path, &len);
  assert_non_null(o->points_text);
  int cap = 1024;
  o->pts = malloc((size_t)cap * sizeof *o->pts);
  o->npts = 0;
  const char *s = o->points_text;
  while (*s) {
    int x, y, used;
    if (sscanf(s, "%d %d%n", &x, &y, &used) != 2) fail_msg("bad points line: %.40s", s);
    s += used;
    assert_true(*s == '\n');
    s++;
    if (o->npts == cap) { cap *= 2; o->pts = realloc(o->pts, (size_t)cap * sizeof *o->pts); }
    o->pts[o->npts][0] = x;
    o->pts[o->npts][1] = y;
    o->npts++;
  }
}

/* A number field of the stats JSON; fails when missing. */
static double stat_num(const struct out *o, const char *key)
{
  char pat[96];
  snprintf(pat, sizeof pat, "\"%s\":", key);
  const char *p = o->stats ? strstr(o->stats, pat) : NULL;
  if (!p) fail_msg("stats has no field %s", key);
  return strtod(p + strlen(pat), NULL);
}

/* Render scene file `scene` with cell `cell` plus extra arguments; read every output. */
static void render_file(const char *scene, int cell, const char *const *extra, struct out *o)
{
  memset(o, 0, sizeof *o);
  char cellarg[8], dids[300], dtube[300], dpts[300];
  snprintf(cellarg, sizeof cellarg, "%d", cell);
  const char *ids = tpath("out.ids.pgm"), *tube = tpath("out.tube.pbm"),
             *pts = tpath("out.points.txt"), *stats = tpath("out.stats.json");
  snprintf(dids, sizeof dids, "ids=%s", ids);
  snprintf(dtube, sizeof dtube, "tube=%s", tube);
  snprintf(dpts, sizeof dpts, "points=%s", pts);
  unlink(ids); unlink(tube); unlink(pts); unlink(stats);
  const char *args[48] = { "render", scene, "--cell", cellarg, "--dump", dids, "--dump", dtube,
                           "--dump", dpts, "--stats", stats };
  int n = 12;
  for (int k = 0; extra && extra[k]; k++) args[n++] = extra[k];
  args[n] = NULL;
  o->status = run_prog(args, &o->err);
  if (o->status != 0) return;
  read_ids(o, ids);
  read_pbm(o, tube);
  read_points(o, pts);
  o->stats = slurp(stats, NULL);
  assert_non_null(o->stats);
}

static int nscene;

/* The points engine (--engine points) on the same scene and grid as o (the 1974 engine):
   every point the same, or the 1974 answer inside the exact reference's tolerance band
   (the carrier line of an interpenetration; a folded face's chords) while the points
   engine's answer is the reference's own or on an exact depth tie (issue 19). */
static void engines_agree(const char *path, int cell, const struct out *o)
{
  struct out p;
  const char *const extra[] = { "--engine", "points", NULL };
  render_file(path, cell, extra, &p);
  if (p.status != 0) fail_msg("tube74 render %s --engine points: exit %d: %s", path, p.status, p.err);
  assert_true(strstr(p.stats, "\"engine\": \"points\"") != NULL);
  char *text = slurp(path, NULL);
  assert_non_null(text);
  struct xr_scene xs;
  memset(&xs, 0, sizeof xs);
  char err[256];
  bool judged = xr_read(text, &xs, err, sizeof err) == 0;
  struct xr_ref ref;
  if (judged) assert_int_equal(xr_prepare(&xs, cell, &ref), 0);
  int bad = 0;
  for (int j = 0; j < o->H; j++)
    for (int i = 0; i < o->W; i++) {
      unsigned a = o->ids[j * o->W + i], b = p.ids[j * p.W + i], want;
      if (a == b) continue;
      if (judged && xr_judge(&ref, i, j, a, &want) > 0 && xr_judge(&ref, i, j, b, &want) >= 0)
        continue;
      if (bad++ < 4)
        print_message("%s: point (%d, %d): 1974 engine %u, points engine %u\n", path, i, j, a, b);
    }
  if (judged) xr_ref_free(&ref);
  xr_scene_free(&xs);
  free(text);
  out_free(&p);
  assert_int_equal(bad, 0);
}

/* Write s (with flags) and render it; the run must succeed. Plain renders (no extra
   options) are rendered by the points engine too and must agree (engines_agree). */
static void render_scn(const struct scn *s, int flags, int cell, const char *const *extra,
                       struct out *o)
{
  char name[64];
  snprintf(name, sizeof name, "scene%d.s74", nscene++);
  const char *path = tpath(name);
  sc_write(s, path, flags);
  render_file(path, cell, extra, o);
  if (o->status != 0) fail_msg("tube74 render %s: exit %d: %s", path, o->status, o->err);
  assert_int_equal(o->W, 400 / cell);
  assert_int_equal(o->H, 300 / cell);
  if (!extra) engines_agree(path, cell, o);
}

/* Standard grid (window -200 -150 200 150, cell 4): id at the centre (x, y). */
static int id_at(const struct out *o, int x, int y)
{
  assert_true((x + 198) % 4 == 0 && (148 - y) % 4 == 0);
  int i = (x + 198) / 4, j = (148 - y) / 4;
  assert_true(i >= 0 && i < o->W && j >= 0 && j < o->H);
  return o->ids[j * o->W + i];
}

/* ---- exact reference for faces at z = 0 seen from (0, 0, -1000): the tie rule ---------- */

/* Is (px, py) in the face's projected polygon (all rings, even-odd) under the tie rule?
   The rule is the same as testing the point moved by (e, e^2), e -> 0+, which is the
   half-open ray cast below: an edge counts when it straddles py with lower ends at or
   below it, and crosses strictly right of px. xy: the rings' points in world units. */
static bool tie_in(int nring, const int *rs, const long long *xy, long long px, long long py)
{
  bool in = false;
  for (int r = 0; r < nring; r++)
    for (int k = rs[r]; k < rs[r + 1]; k++) {
      int k2 = k + 1 < rs[r + 1] ? k + 1 : rs[r];
      long long ax = xy[2 * k], ay = xy[2 * k + 1], bx = xy[2 * k2], by = xy[2 * k2 + 1];
      if ((ay <= py) == (by <= py)) continue;
      /* crossing x = ax + (py - ay)(bx - ax)/(by - ay) > px ? */
      i128 lhs = (i128)(ax - px) * (by - ay) + (i128)(py - ay) * (bx - ax);
      if ((by - ay > 0) ? lhs > 0 : lhs < 0) in = !in;
    }
  return in;
}

/* Face k of s, at z = 0 (identity projection): its rings in world units. */
static bool face_tie_in(const struct scn *s, int k, long long px, long long py)
{
  const struct sface *f = &s->f[k];
  long long xy[2 * SC_MAXFV];
  for (int q = 0; q < f->rs[f->nring]; q++) {
    const int *v = s->v[f->vid[q] - 1];
    assert_int_equal(v[2], 0);
    xy[2 * q] = v[0];
    xy[2 * q + 1] = v[1];
  }
  return tie_in(f->nring, f->rs, xy, px, py);
}

/* Compare every point with `want(i, j)`; print the first few differences. */
typedef int (*want_fn)(const void *ctx, int i, int j);

static int compare_ids(const struct out *o, want_fn want, const void *ctx, const char *what)
{
  int bad = 0;
  for (int j = 0; j < o->H; j++)
    for (int i = 0; i < o->W; i++) {
      int w = want(ctx, i, j);
      if (w < 0) continue;
      int got = o->ids[j * o->W + i];
      if (got != w) {
        if (bad < 8)
          print_message("%s: point (%d, %d): id %d, expected %d\n", what, i, j, got, w);
        bad++;
      }
    }
  if (bad) print_message("%s: %d points differ\n", what, bad);
  return bad;
}

/* Flat scenes (every face at z = 0): the largest id among faces containing the centre. */
static int want_flat(const void *ctx, int i, int j)
{
  const struct scn *s = ctx;
  long long x = -198 + 4 * i, y = 148 - 4 * j;
  int best = 0;
  for (int k = 0; k < s->nf; k++)
    if (s->f[k].id > best && face_tie_in(s, k, x, y)) best = s->f[k].id;
  return best;
}

static int count_id(const struct out *o, int id)
{
  int n = 0;
  for (int k = 0; k < o->W * o->H; k++) n += o->ids[k] == id;
  return n;
}

/* ---- floating-point reference for scenes in depth -------------------------------------- */

struct fref { const struct scn *s; double margin; int cell; };

static void plane_of(const struct scn *s, int k, i128 pl[4])
{
  const struct sface *f = &s->f[k];
  const int *p0 = s->v[f->vid[0] - 1];
  int n = f->rs[1];
  for (int a = 1; a < n; a++)
    for (int b = a + 1; b < n; b++) {
      const int *p1 = s->v[f->vid[a] - 1], *p2 = s->v[f->vid[b] - 1];
      i128 ux = p1[0] - p0[0], uy = p1[1] - p0[1], uz = p1[2] - p0[2];
      i128 vx = p2[0] - p0[0], vy = p2[1] - p0[1], vz = p2[2] - p0[2];
      pl[0] = uy * vz - uz * vy; pl[1] = uz * vx - ux * vz; pl[2] = ux * vy - uy * vx;
      if (pl[0] || pl[1] || pl[2]) {
        pl[3] = -(pl[0] * p0[0] + pl[1] * p0[1] + pl[2] * p0[2]);
        return;
      }
    }
  fail_msg("face %d has no plane", f->id);
}

static bool coplanar(const struct scn *s, int a, int b)
{
  i128 p[4], q[4];
  plane_of(s, a, p);
  plane_of(s, b, q);
  for (int i = 0; i < 4; i++)
    for (int j = i + 1; j < 4; j++)
      if (p[i] * q[j] != p[j] * q[i]) return false;
  return true;
}

/* Point centre of the grid of s (any window) in plane units. */
static void centre(const struct scn *s, int cell, int i, int j, double *x, double *y)
{
  int W = 400 / cell, H = 300 / cell;
  *x = s->window[0] + (i + 0.5) * (double)(s->window[2] - s->window[0]) / W;
  *y = s->window[3] - (j + 0.5) * (double)(s->window[3] - s->window[1]) / H;
}

static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
  double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
  if (t < 0) t = 0;
  if (t > 1) t = 1;
  double ex = ax + t * dx - px, ey = ay + t * dy - py;
  return sqrt(ex * ex + ey * ey);
}

/* 1 inside, 0 outside, -1 within margin of an edge. */
static int fin(const struct scn *s, int k, double px, double py, double margin)
{
  const struct sface *f = &s->f[k];
  const double X0 = s->view[0], Y0 = s->view[1], Z0 = s->view[2];
  double xy[2 * SC_MAXFV];
  for (int q = 0; q < f->rs[f->nring]; q++) {
    const int *v = s->v[f->vid[q] - 1];
    double w = v[2] - Z0;
    xy[2 * q] = X0 + -Z0 * (v[0] - X0) / w;
    xy[2 * q + 1] = Y0 + -Z0 * (v[1] - Y0) / w;
  }
  bool in = false;
  for (int r = 0; r < f->nring; r++)
    for (int q = f->rs[r]; q < f->rs[r + 1]; q++) {
      int q2 = q + 1 < f->rs[r + 1] ? q + 1 : f->rs[r];
      double ax = xy[2 * q], ay = xy[2 * q + 1], bx = xy[2 * q2], by = xy[2 * q2 + 1];
      if (seg_dist(px, py, ax, ay, bx, by) < margin) return -1;
      if ((ay <= py) != (by <= py) && ax + (py - ay) * (bx - ax) / (by - ay) > px) in = !in;
    }
  return in;
}

/* Ray parameter where the ray from the eye through (px, py, 0) meets face k's plane. */
static double fdepth(const struct scn *s, int k, double px, double py)
{
  i128 pl[4];
  plane_of(s, k, pl);
  double a = (double)pl[0], b = (double)pl[1], c = (double)pl[2], d = (double)pl[3];
  double ex = s->view[0], ey = s->view[1], ez = s->view[2];
  double dx = px - ex, dy = py - ey, dz = -ez;
  return -(a * ex + b * ey + c * ez + d) / (a * dx + b * dy + c * dz);
}

/* Expected id at (i, j): nearest face containing the centre, ties between coplanar faces
   to the larger id; -1 (not checked) near an edge or where two faces are nearly as deep. */
static int want_float(const void *ctx, int i, int j)
{
  const struct fref *fr = ctx;
  const struct scn *s = fr->s;
  double px, py;
  centre(s, fr->cell, i, j, &px, &py);
  int best = -1, second = -1;
  double tb = 0, ts = 0;
  for (int k = 0; k < s->nf; k++) {
    int r = fin(s, k, px, py, fr->margin);
    if (r < 0) return -1;
    if (!r) continue;
    double t = fdepth(s, k, px, py);
    if (best < 0 || t < tb) { second = best; ts = tb; best = k; tb = t; }
    else if (second < 0 || t < ts) { second = k; ts = t; }
  }
  if (best < 0) return 0;
  if (second >= 0 && fabs(ts - tb) <= 1e-7 * fabs(tb)) {
    if (!coplanar(s, best, second)) return -1;
    /* coplanar: the largest id among all coplanar faces containing the point */
    int id = 0;
    for (int k = 0; k < s->nf; k++)
      if (fin(s, k, px, py, fr->margin) == 1 && coplanar(s, k, best) && s->f[k].id > id)
        id = s->f[k].id;
    return id;
  }
  return s->f[best].id;
}

/* ---- the scenes of the hard cases -------------------------------------------------- */

static void scene_centres(struct scn *s)
{
  sc_std(s);
  const int sq[] = { -102, -52, -62, -52, -62, -12, -102, -12 };   /* edges on centres */
  sc_face2(s, 1, -1, 4, sq, 0);
  const int tri[] = { 2, -52, 82, -52, 42, 28 };                    /* slopes through centres */
  sc_face2(s, 2, -1, 3, tri, 0);
  const int dia[] = { 130, -52, 150, -32, 130, -12, 110, -32 };
  sc_face2(s, 3, -1, 4, dia, 0);
  const int off[] = { -180, 60, -150, 60, -150, 100, -180, 100 };   /* edges between centres */
  sc_face2(s, 4, -1, 4, off, 0);
  const int tall[] = { 170, -148, 174, -148, 174, 148, 170, 148 };  /* one column wide */
  sc_face2(s, 5, -1, 4, tall, 0);
}

static void scene_horizontal(struct scn *s)
{
  sc_std(s);
  const int stair[] = { -102, -52, -22, -52, -22, -12, -62, -12, -62, 28, -102, 28 };
  sc_face2(s, 1, -1, 6, stair, 0);
  const int trap[] = { 10, -50, 90, -50, 70, -10, 30, -10 };       /* y between centres */
  sc_face2(s, 2, -1, 4, trap, 0);
  const int para[] = { 10, 0, 90, 0, 110, 40, 30, 40 };            /* y on centre rows */
  sc_face2(s, 3, -1, 4, para, 0);
  const int row[] = { -150, -92, 150, -92, 150, -91, -150, -91 };   /* one row: y = -92 */
  sc_face2(s, 4, -1, 4, row, 0);
  const int none[] = { -150, -103, 150, -103, 150, -100, -150, -100 };  /* no row (-100 top) */
  sc_face2(s, 5, -1, 4, none, 0);
  const int spike[] = { 120, 60, 180, 60, 150, 61 };               /* flat triangle on a row */
  sc_face2(s, 6, -1, 3, spike, 0);
  const int vee[] = { 120, 100, 150, 80, 180, 100 };                /* apex down, top on a row */
  sc_face2(s, 7, -1, 3, vee, 0);
}

static void scene_comb(struct scn *s)
{
  sc_std(s);
  const int up[] = { -182, -52, -86, -52, -86, -32, -98, -32, -98, 28, -110, 28, -110, -32,
                     -122, -32, -122, 28, -134, 28, -134, -32, -146, -32, -146, 28, -158, 28,
                     -158, -32, -170, -32, -170, 28, -182, 28 };
  sc_face2(s, 1, -1, 18, up, 0);
  const int down[] = { 2, -52, 14, -52, 14, 8, 26, 8, 26, -52, 38, -52, 38, 8, 50, 8, 50, -52,
                       62, -52, 62, 8, 74, 8, 74, -52, 86, -52, 86, 8, 98, 8, 98, 28, 2, 28 };
  sc_face2(s, 2, -1, 18, down, 0);
  const int saw[] = { -182, 60, -86, 60, -86, 120, -98, 100, -110, 120, -122, 100, -134, 120,
                      -146, 100, -158, 120, -170, 100, -182, 120 };
  sc_face2(s, 3, -1, 11, saw, 0);
}

static void scene_holes(struct scn *s)
{
  sc_std(s);
  /* back face at z = 1000: world +-300 x +-200 projects onto [-150, 150] x [-100, 100] */
  const int back[] = { -300, -200, 300, -200, 300, 200, -300, 200 };
  sc_face2(s, 9, 100, 4, back, 1000);
  /* front face: outer ring with a vertex in the middle of its top side */
  const int outer[] = { -102, -52, 98, -52, 98, 48, -2, 48, -102, 48 };
  struct sface *f = sc_face2(s, 4, -1, 5, outer, 0);
  int corner = f->vid[0];
  /* hole 1 shares the outer ring's corner vertex (same id) */
  int h1[3] = { corner, sc_vertex(s, -22, -12, 0), sc_vertex(s, -62, 28, 0) };
  sc_hole_ids(f, 3, h1);
  /* hole 2 touches the outer ring's top-middle vertex with a vertex of its own there */
  int h2[3] = { sc_vertex(s, -2, 48, 0), sc_vertex(s, 38, 8, 0), sc_vertex(s, -22, 8, 0) };
  sc_hole_ids(f, 3, h2);
  /* hole 3 touches the corner (98, -52) with a vertex of its own */
  int h3[3] = { sc_vertex(s, 98, -52, 0), sc_vertex(s, 78, -12, 0), sc_vertex(s, 58, -32, 0) };
  sc_hole_ids(f, 3, h3);
}

static void scene_tiling(struct scn *s)
{
  sc_std(s);
  /* R1 = [-102, 98] x [-52, 48]; T-junction at (-2, 0) in the middle of face 1's side */
  const int f1[] = { -102, -52, -2, -52, -2, 48 };
  const int f2[] = { -102, -52, -2, 48, -102, 48 };
  const int f3[] = { -2, -52, 98, -52, 98, 0, -2, 0 };
  const int f4[] = { -2, 0, 46, 48, -2, 48 };
  const int f5[] = { -2, 0, 98, 0, 98, 48, 46, 48 };
  sc_face2(s, 1, 250, 3, f1, 0);
  sc_face2(s, 2, 200, 3, f2, 0);
  sc_face2(s, 3, 150, 4, f3, 0);
  sc_face2(s, 4, 100, 3, f4, 0);
  sc_face2(s, 5, 50, 4, f5, 0);
  /* R2 = [-102, 98] x [60, 120]: a flat face and one folded away from the eye along the
     shared edge x = -2 (projects exactly onto [-2, 98] x [60, 120]) */
  const int f6[] = { -102, 60, -2, 60, -2, 120, -102, 120 };
  sc_face2(s, 6, 255, 4, f6, 0);
  const int f7[] = { -2, 60, 0, 196, 120, 1000, 196, 240, 1000, -2, 120, 0 };
  sc_face3(s, 7, 120, 4, f7);
  /* R3 = [110, 190] x [-140, -60]: a fan of six triangles around an inner point that is
     not a centre, so the shared slanted edges pass between centres */
  const int g1[] = { 110, -140, 150, -140, 137, -101 };
  const int g2[] = { 150, -140, 190, -140, 137, -101 };
  const int g3[] = { 190, -140, 190, -97, 137, -101 };
  const int g4[] = { 190, -97, 190, -60, 137, -101 };
  const int g5[] = { 190, -60, 110, -60, 137, -101 };
  const int g6[] = { 110, -60, 110, -140, 137, -101 };
  sc_face2(s, 11, 255, 3, g1, 0);
  sc_face2(s, 12, 200, 3, g2, 0);
  sc_face2(s, 13, 150, 3, g3, 0);
  sc_face2(s, 14, 100, 3, g4, 0);
  sc_face2(s, 15, 60, 3, g5, 0);
  sc_face2(s, 16, 30, 3, g6, 0);
  /* R4 = [-190, -122] x [-140, -64]: a T-junction of three faces where the stem's vertex
     (-154, -100) lies in the middle of a long side, edges through centres */
  const int t1[] = { -190, -140, -122, -140, -122, -100, -190, -100 };
  const int t2[] = { -190, -100, -154, -100, -154, -64, -190, -64 };
  const int t3[] = { -154, -100, -122, -100, -122, -64, -154, -64 };
  sc_face2(s, 21, 255, 4, t1, 0);
  sc_face2(s, 22, 180, 4, t2, 0);
  sc_face2(s, 23, 90, 4, t3, 0);
}

static void scene_shallow(struct scn *s)
{
  sc_std(s);
  /* A: z = (x + 150)/300, B: z = (150 - x)/300; they cross along x = 0 at z = 1/2 */
  const int a[] = { -150, -100, 0, 150, -100, 1, 150, 100, 1, -150, 100, 0 };
  const int b[] = { -150, -100, 1, 150, -100, 0, 150, 100, 0, -150, 100, 1 };
  sc_face3(s, 1, 255, 4, a);
  sc_face3(s, 2, 120, 4, b);
}

static void scene_shallow2(struct scn *s)
{
  sc_std(s);
  /* A: z = 0; B: z = -x/300 - y/200, crossing A along y = -2x/3 */
  const int a[] = { -150, -100, 0, 150, -100, 0, 150, 100, 0, -150, 100, 0 };
  const int b[] = { -150, -100, 1, 150, -100, 0, 150, 100, -1, -150, 100, 0 };
  sc_face3(s, 1, 255, 4, a);
  sc_face3(s, 2, 120, 4, b);
}

static void scene_cyclic(struct scn *s)
{
  sc_std(s);
  /* S1 over S2 (right), S2 over S3 (top), S3 over S1 (left): a triangle of sticks */
  const int s1[] = { -140, -60, 400, 140, -60, 0, 140, -20, 0, -140, -20, 400 };
  const int s2[] = { 80, -120, 400, 120, -120, 400, -20, 120, 0, -60, 120, 0 };
  const int s3[] = { -120, -120, 0, -80, -120, 0, 60, 120, 400, 20, 120, 400 };
  sc_face3(s, 1, 90, 4, s1);
  sc_face3(s, 2, 160, 4, s2);
  sc_face3(s, 3, 230, 4, s3);
}

static void scene_coplanar(struct scn *s)
{
  sc_std(s);
  const int a[] = { -102, -100, 50, -100, 50, 48, -102, 48 };
  const int b[] = { -50, -52, 98, -52, 98, 100, -50, 100 };
  const int c[] = { -150, -20, 150, -20, 2, 128 };
  sc_face2(s, 7, 255, 4, a, 0);
  sc_face2(s, 3, 160, 4, b, 0);
  sc_face2(s, 12, 80, 3, c, 0);
  /* a coplanar pair on the slanted plane z = x + 300, face 19 inside face 20 */
  const int d[] = { -190, -140, 110, -110, -140, 190, -110, -40, 190, -190, -40, 110 };
  const int e[] = { -170, -130, 130, -130, -130, 170, -130, -60, 170, -170, -60, 130 };
  sc_face3(s, 20, 255, 4, d);
  sc_face3(s, 19, 100, 4, e);
}

static void scene_sliver(struct scn *s)
{
  /* eye at z = -1: z = 0 projects onto itself and z = 255 shrinks 256 times, so a vertex
     at x = 513, z = 255 lands one grid unit right of x = 2 */
  sc_init(s, 0, 0, -1, -200, -150, 200, 150);
  const int back[] = { -30000, -30000, 299, 30000, -30000, 299, 30000, 30000, 299,
                       -30000, 30000, 299 };
  sc_face3(s, 6, 100, 4, back);                     /* projects onto [-100, 100]^2 */
  const int vs[] = { 2, -100, 0, 2, 100, 0, 513, 0, 255 };
  sc_face3(s, 5, 255, 3, vs);                       /* x from 2 to 2 + 1/256 */
  const int hs[] = { 10, 60, 0, 150, 60, 0, 20480, 15361, 255 };
  sc_face3(s, 7, 255, 3, hs);                       /* y from 60 to 60 + 1/256 */
  const int none[] = { 32, -100, 0, 32, -60, 0, 8193, -20480, 255 };
  sc_face3(s, 8, 255, 3, none);                     /* x in [32, 32 + 1/256]: no centre */
}

/* ---- 1. vertices on point centres and scanlines --------------------------------------- */

/* The tie rule at exact point centres: left and bottom edges through centres cover them,
   right and top edges do not; every point equals the exact reference. */
static void test_centres(void **state)
{
  (void)state;
  struct scn s;
  scene_centres(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  /* square [-102, -62] x [-52, -12] */
  assert_int_equal(id_at(&o, -102, -32), 1);        /* left edge: covered */
  assert_int_equal(id_at(&o, -62, -32), 0);         /* right edge: not */
  assert_int_equal(id_at(&o, -82, -52), 1);         /* bottom edge: covered */
  assert_int_equal(id_at(&o, -82, -12), 0);         /* top edge: not */
  assert_int_equal(id_at(&o, -102, -52), 1);        /* lower-left corner */
  assert_int_equal(id_at(&o, -62, -52), 0);
  assert_int_equal(id_at(&o, -102, -12), 0);
  assert_int_equal(id_at(&o, -66, -16), 1);
  assert_int_equal(count_id(&o, 1), 100);           /* 10 x 10 exactly */
  /* triangle (2,-52) (82,-52) (42,28) */
  assert_int_equal(id_at(&o, 2, -52), 2);
  assert_int_equal(id_at(&o, 82, -52), 0);
  assert_int_equal(id_at(&o, 42, 28), 0);           /* apex */
  assert_int_equal(id_at(&o, 6, -44), 2);           /* on the left side */
  assert_int_equal(id_at(&o, 78, -44), 0);          /* on the right side */
  assert_int_equal(id_at(&o, 42, 24), 2);
  /* diamond: left vertex covered, the other three not */
  assert_int_equal(id_at(&o, 110, -32), 3);
  assert_int_equal(id_at(&o, 130, -52), 0);
  assert_int_equal(id_at(&o, 150, -32), 0);
  assert_int_equal(id_at(&o, 130, -12), 0);
  assert_int_equal(id_at(&o, 130, -32), 3);
  /* one column wide [170, 174): exactly the column x = 170, rows -148 .. 144 */
  assert_int_equal(count_id(&o, 5), 74);
  assert_int_equal(id_at(&o, 170, -148), 5);
  assert_int_equal(id_at(&o, 170, 148), 0);
  assert_int_equal(compare_ids(&o, want_flat, &s, "centres"), 0);
  out_free(&o);
}

/* ---- 1b. cell 3, an odd window, an eye off the axis -------------------------------------- */

/* With cell 3, window -66 -50 67 50 (one unit a point: centres at half units) and the eye
   at (37, -23, -1000), faces at z = 1000 land on half units: edges through centres obey
   the tie rule exactly there too. */
static void test_cell3_window(void **state)
{
  (void)state;
  struct scn s;
  sc_init(&s, 37, -23, -1000, -66, -50, 67, 50);
  /* at z = 1000: x' = (x + 37)/2, y' = (y - 23)/2; doubled: X = x + 37, Y = y - 23 */
  const int sq[] = { -78, 2, 1000, -16, 2, 1000, -16, 64, 1000, -78, 64, 1000 };
  sc_face3(&s, 1, 255, 4, sq);                       /* doubled [-41, 21] x [-21, 41] */
  const int tri[] = { 6, -56, 1000, 46, -56, 1000, 26, -16, 1000 };
  sc_face3(&s, 2, 255, 3, tri);                      /* doubled (43,-79) (83,-79) (63,-39) */
  const int flat[] = { -60, -40, -40, -40, -50, -25 };
  sc_face2(&s, 3, 255, 3, flat, 0);                  /* at z = 0: integers, between centres */
  struct out o;
  render_scn(&s, 0, 3, NULL, &o);
  assert_int_equal(o.W, 133);
  assert_int_equal(o.H, 100);
  int bad = 0;
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      long long X = -131 + 2 * i, Y = 99 - 2 * j;    /* doubled centre */
      int want = 0;
      for (int k = 0; k < s.nf; k++) {
        const struct sface *f = &s.f[k];
        long long xy[2 * SC_MAXFV];
        for (int q = 0; q < f->rs[1]; q++) {
          const int *v = s.v[f->vid[q] - 1];
          if (v[2] == 1000) { xy[2 * q] = v[0] + 37; xy[2 * q + 1] = v[1] - 23; }
          else { xy[2 * q] = 2 * v[0]; xy[2 * q + 1] = 2 * v[1]; }
        }
        if (tie_in(1, f->rs, xy, X, Y)) want = f->id;
      }
      int got = o.ids[j * o.W + i];
      if (got != want && bad++ < 8)
        print_message("cell 3: point (%d, %d) centre (%g, %g): id %d, expected %d\n", i, j,
                      X / 2.0, Y / 2.0, got, want);
    }
  assert_int_equal(bad, 0);
  assert_int_equal(count_id(&o, 1), 31 * 31);        /* i 45..75, j 30..60 */
  assert_int_equal(o.ids[45 + 60 * 133], 1);          /* lower-left corner on a centre */
  assert_int_equal(o.ids[76 + 60 * 133], 0);          /* lower-right */
  assert_int_equal(o.ids[45 + 29 * 133], 0);          /* upper-left */
  out_free(&o);
}

/* ---- 11b. near the plane grid's limit ------------------------------------------------ */

/* Faces just in front of the eye project to nearly +-2^20 units (the plane grid's limit):
   their crossing is still found (x' = 0) and the ids switch there; very shallow crossing
   faces 60000 units wide with z differing by 1 also switch at x' = 0. */
static void test_extreme_depth(void **state)
{
  (void)state;
  struct scn s;
  sc_init(&s, 0, 0, -32768, -32768, -32768, 32767, 32767);
  const int a[] = { -800, -800, -32736, 800, -800, -32736, 800, 800, -32736, -800, 800, -32736 };
  const int b[] = { -800, -800, -32740, 800, -800, -32732, 800, 800, -32732, -800, 800, -32740 };
  sc_face3(&s, 1, 255, 4, a);
  sc_face3(&s, 2, 120, 4, b);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_true(stat_num(&o, "intersection_splits") >= 1);
  int bad = 0;
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      int want = i < 50 ? 2 : 1, got = o.ids[j * o.W + i];
      if (got != want && bad++ < 8) print_message("near eye: point (%d, %d): %d, expected %d\n", i, j, got, want);
    }
  assert_int_equal(bad, 0);
  out_free(&o);

  sc_init(&s, 0, 0, -32768, -32768, -32768, 32767, 32767);
  const int c[] = { -30000, -30000, 0, 30000, -30000, 1, 30000, 30000, 1, -30000, 30000, 0 };
  const int d[] = { -30000, -30000, 1, 30000, -30000, 0, 30000, 30000, 0, -30000, 30000, 1 };
  sc_face3(&s, 1, 255, 4, c);
  sc_face3(&s, 2, 120, 4, d);
  render_scn(&s, 0, 4, NULL, &o);
  assert_true(stat_num(&o, "intersection_splits") >= 1);
  int both = 0;
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      double px, py;
      centre(&s, 4, i, j, &px, &py);
      if (fin(&s, 0, px, py, 1.0) != 1 || fin(&s, 1, px, py, 1.0) != 1) continue;
      both++;
      int want = px < 0 ? 1 : 2, got = o.ids[j * o.W + i];
      if (got != want && bad++ < 8)
        print_message("wide shallow: point (%d, %d) at (%g, %g): %d, expected %d\n", i, j, px, py, got, want);
    }
  assert_true(both > 5000);
  assert_int_equal(bad, 0);
  struct fref fr = { &s, 1.0, 4 };
  assert_int_equal(compare_ids(&o, want_float, &fr, "wide shallow"), 0);
  out_free(&o);
}

/* ---- 8b. three faces through one line ---------------------------------------------- */

/* Three squares whose planes share one line (x = 0, z = 500): every pair crosses on the same
   projected line; left of it the steepest face is nearest, right of it the falling one. */
static void test_three_through_line(void **state)
{
  (void)state;
  struct scn s;
  sc_std(&s);
  const int f1[] = { -100, -80, 400, 100, -80, 600, 100, 80, 600, -100, 80, 400 };
  const int f2[] = { -100, -80, 600, 100, -80, 400, 100, 80, 400, -100, 80, 600 };
  const int f3[] = { -100, -80, 300, 100, -80, 700, 100, 80, 700, -100, 80, 300 };
  sc_face3(&s, 1, 255, 4, f1);
  sc_face3(&s, 2, 170, 4, f2);
  sc_face3(&s, 3, 90, 4, f3);
  for (int flags = 0; flags <= SC_REV_FACES; flags += SC_REV_FACES) {
    struct out o;
    render_scn(&s, flags, 4, NULL, &o);
    assert_true(stat_num(&o, "intersection_splits") >= 1);
    int n = 0, bad = 0;
    for (int j = 0; j < o.H; j++)
      for (int i = 0; i < o.W; i++) {
        double px, py;
        centre(&s, 4, i, j, &px, &py);
        bool all = true;
        for (int k = 0; k < 3; k++) all &= fin(&s, k, px, py, 1.0) == 1;
        if (!all) continue;
        n++;
        int want = px < 0 ? 3 : 2, got = o.ids[j * o.W + i];
        if (got != want && bad++ < 8)
          print_message("three planes: (%g, %g) shows %d, expected %d\n", px, py, got, want);
      }
    assert_true(n > 300);
    assert_int_equal(bad, 0);
    struct fref fr = { &s, 0.5, 4 };
    assert_int_equal(compare_ids(&o, want_float, &fr, "three planes"), 0);
    out_free(&o);
  }
}

/* ---- 2. horizontal edges ------------------------------------------------------------ */

/* Horizontal edges on and between centre rows: bottom rows covered, top rows not, a face
   one unit tall covers exactly its bottom row, one between rows covers nothing. */
static void test_horizontal(void **state)
{
  (void)state;
  struct scn s;
  scene_horizontal(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal(id_at(&o, -42, -12), 0);         /* top of the lower step: not */
  assert_int_equal(id_at(&o, -62, -12), 0);         /* the concave corner: right, above */
  assert_int_equal(id_at(&o, -66, -12), 1);         /* inside: the steps join here */
  assert_int_equal(id_at(&o, -102, 28), 0);
  assert_int_equal(id_at(&o, -102, 24), 1);
  assert_int_equal(id_at(&o, -26, -52), 1);
  assert_int_equal(id_at(&o, -22, -52), 0);
  assert_int_equal(count_id(&o, 4), 75);            /* row y = -92, x in [-150, 150) */
  for (int x = -150; x < 150; x += 4) assert_int_equal(id_at(&o, x, -92), 4);
  assert_int_equal(count_id(&o, 5), 0);
  assert_int_equal(id_at(&o, 30, 40), 0);
  assert_int_equal(id_at(&o, 10, 0), 3);
  assert_int_equal(id_at(&o, 90, 0), 0);
  assert_int_equal(count_id(&o, 6), 15);            /* x in [120, 180) on row 60 */
  assert_int_equal(id_at(&o, 150, 100), 0);          /* top of the vee */
  assert_int_equal(id_at(&o, 150, 80), 0);           /* its apex */
  assert_int_equal(compare_ids(&o, want_flat, &s, "horizontal"), 0);
  out_free(&o);
}

/* ---- 3. comb ------------------------------------------------------------------------- */

/* Several concave vertices on one scanline: teeth and base points have the face, gap
   points are 0, also on the scanline through the concave vertices. */
static void test_comb(void **state)
{
  (void)state;
  struct scn s;
  scene_comb(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  /* teeth up: the concave vertices are on row y = -32 */
  for (int x = -182; x < -86; x += 4) {
    bool tooth = ((x + 182) % 24) < 12;
    assert_int_equal(id_at(&o, x, -32), tooth ? 1 : 0);
    assert_int_equal(id_at(&o, x, 24), tooth ? 1 : 0);
    assert_int_equal(id_at(&o, x, -36), 1);
    assert_int_equal(id_at(&o, x, -52), 1);
    assert_int_equal(id_at(&o, x, 28), 0);
  }
  assert_int_equal(id_at(&o, -86, -36), 0);
  /* teeth down: the concave vertices are on row y = 8 */
  for (int x = 2; x < 98; x += 4) {
    bool tooth = ((x - 2) % 24) < 12;
    assert_int_equal(id_at(&o, x, 8), 2);        /* base's bottom: owned */
    assert_int_equal(id_at(&o, x, 4), tooth ? 2 : 0);
    assert_int_equal(id_at(&o, x, -52), tooth ? 2 : 0);
    assert_int_equal(id_at(&o, x, 24), 2);
    assert_int_equal(id_at(&o, x, 28), 0);
  }
  /* saw: valleys on row y = 100 */
  for (int x = -182; x < -86; x += 4) assert_int_equal(id_at(&o, x, 96), 3);
  for (int x = -182; x < -86; x += 4)               /* the row through the valleys */
    assert_int_equal(id_at(&o, x, 100), 3);
  assert_int_equal(id_at(&o, -86, 100), 0);
  assert_int_equal(compare_ids(&o, want_flat, &s, "comb"), 0);
  out_free(&o);
}

/* ---- 4. holes touching the outer boundary ------------------------------------------- */

static int want_holes(const void *ctx, int i, int j)
{
  const struct scn *s = ctx;
  long long x = -198 + 4 * i, y = 148 - 4 * j;
  if (face_tie_in(s, 1, x, y)) return 4;            /* the front face (index 1) */
  if (x >= -150 && x < 150 && y >= -100 && y < 100) return 9;
  return 0;
}

/* Holes touching the outer ring at a vertex (shared id or same position): points in the
   holes show the face behind, the rest the face. */
static void test_holes(void **state)
{
  (void)state;
  struct scn s;
  scene_holes(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal(id_at(&o, -90, 40), 4);
  assert_int_equal(id_at(&o, -50, 0), 9);           /* hole 1 */
  assert_int_equal(id_at(&o, -62, 20), 9);          /* hole 1 */
  assert_int_equal(id_at(&o, -2, 20), 9);           /* hole 2 */
  assert_int_equal(id_at(&o, 82, -32), 9);          /* hole 3 */
  assert_int_equal(id_at(&o, -102, -52), 4);        /* the touching corner itself */
  assert_int_equal(id_at(&o, -102, 0), 4);
  assert_int_equal(id_at(&o, 130, 0), 9);
  assert_int_equal(id_at(&o, 170, 0), 0);
  assert_int_equal(compare_ids(&o, want_holes, &s, "holes"), 0);
  out_free(&o);
}

/* ---- 5. slivers --------------------------------------------------------------------- */

static int want_sliver(const void *ctx, int i, int j)
{
  (void)ctx;
  int x = -198 + 4 * i, y = 148 - 4 * j;
  if (x == 2 && y >= -96 && y <= 96) return 5;      /* left side of the vertical sliver */
  if (y == 60 && x >= 10 && x < 150) return 7;      /* bottom side of the horizontal one */
  if (x >= -100 && x < 100 && y >= -100 && y < 100) return 6;
  return 0;
}

/* Slivers one grid unit (1/256) wide: no crash, and the points on their owned sides are
   theirs exactly; a sliver holding no centre shows nowhere. */
static void test_sliver(void **state)
{
  (void)state;
  struct scn s;
  scene_sliver(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal(count_id(&o, 8), 0);
  for (int k = 0; k < o.W * o.H; k++)
    assert_true(o.ids[k] == 0 || (o.ids[k] >= 5 && o.ids[k] <= 8));
  assert_int_equal(count_id(&o, 5), 49);
  assert_int_equal(count_id(&o, 7), 35);
  assert_int_equal(compare_ids(&o, want_sliver, &s, "sliver"), 0);
  out_free(&o);
}

/* ---- 6. edge-on faces --------------------------------------------------------------- */

/* Faces whose plane holds the eye are dropped: nothing drawn, faces_dropped counts them. */
static void test_edge_on(void **state)
{
  (void)state;
  struct scn s;
  sc_std(&s);
  const int xplane[] = { 0, -50, 0, 0, 50, 0, 0, 50, 500, 0, -50, 500 };
  sc_face3(&s, 1, 255, 4, xplane);
  const int diag[] = { 10, 10, 0, 50, 50, 0, 100, 100, 1000, 20, 20, 1000 };
  sc_face3(&s, 2, 255, 4, diag);
  const int sq[] = { -102, -52, -62, -52, -62, -12, -102, -12 };
  sc_face2(&s, 3, 255, 4, sq, 0);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal((int)stat_num(&o, "faces_in"), 3);
  assert_int_equal((int)stat_num(&o, "faces_dropped"), 2);
  assert_int_equal((int)stat_num(&o, "faces_after_split"), 1);
  assert_int_equal(count_id(&o, 1), 0);
  assert_int_equal(count_id(&o, 2), 0);
  assert_int_equal(count_id(&o, 3), 100);
  assert_int_equal(o.npts, 100 * pat_level(4, 255));
  assert_int_equal((int)stat_num(&o, "points_lit"), o.npts);
  out_free(&o);
  /* only edge-on faces: an empty picture */
  sc_std(&s);
  sc_face3(&s, 1, 255, 4, xplane);
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal((int)stat_num(&o, "faces_dropped"), 1);
  assert_int_equal(count_id(&o, 0), o.W * o.H);
  assert_int_equal(o.npts, 0);
  assert_int_equal((int)stat_num(&o, "points_lit"), 0);
  out_free(&o);
}

/* ---- 7. tilings, T-junctions, shared edges ------------------------------------------- */

struct tiling_ctx { const struct scn *s; int bad_double; };

static int want_tiling(const void *ctx, int i, int j)
{
  struct tiling_ctx *t = (struct tiling_ctx *)ctx;
  const struct scn *s = t->s;
  long long x = -198 + 4 * i, y = 148 - 4 * j;
  int id = 0, n = 0;
  for (int k = 0; k < s->nf; k++) {
    bool in;
    if (s->f[k].id == 7) {                          /* the folded face: its projection */
      static const int rs[2] = { 0, 4 };
      static const long long xy[] = { -2, 60, 98, 60, 98, 120, -2, 120 };
      in = tie_in(1, rs, xy, x, y);
    } else {
      in = face_tie_in(s, k, x, y);
    }
    if (in) { id = s->f[k].id; n++; }
  }
  if (n > 1) t->bad_double++;                        /* the reference tiling is a partition */
  return id;
}

static bool in_rects(int x, int y)
{
  return (x >= -102 && x < 98 && y >= -52 && y < 48) || (x >= -102 && x < 98 && y >= 60 && y < 120) ||
         (x >= 110 && x < 190 && y >= -140 && y < -60) ||
         (x >= -190 && x < -122 && y >= -140 && y < -64);
}

/* Faces tiling rectangles (T-junctions, shared slanted edges through centres, a fold):
   every point of each rectangle covered exactly once — no 0 inside, no point outside —
   and each face's points are exactly its own under the tie rule. */
static void test_tiling(void **state)
{
  (void)state;
  struct scn s;
  scene_tiling(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  int holes = 0, spill = 0;
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      int x = -198 + 4 * i, y = 148 - 4 * j, id = o.ids[j * o.W + i];
      if (in_rects(x, y) && id == 0) {
        if (holes++ < 8) print_message("crack at (%d, %d)\n", x, y);
      }
      if (!in_rects(x, y) && id != 0) spill++;
    }
  assert_int_equal(holes, 0);
  assert_int_equal(spill, 0);
  struct tiling_ctx t = { &s, 0 };
  assert_int_equal(compare_ids(&o, want_tiling, &t, "tiling"), 0);
  assert_int_equal(t.bad_double, 0);
  assert_int_equal(id_at(&o, -2, 0), 5);            /* the T-junction point */
  assert_int_equal(id_at(&o, -6, 0), 1);
  assert_int_equal(id_at(&o, -2, -4), 3);
  assert_int_equal(id_at(&o, -2, 60), 7);           /* the fold's edge belongs to the fold */
  assert_int_equal(id_at(&o, -6, 60), 6);
  assert_int_equal((int)stat_num(&o, "intersection_splits"), 0);
  out_free(&o);
}

/* ---- 7b. T-junctions in depth ------------------------------------------------------ */

/* A quad P1 R P2 Q split into A = (P1, P2, Q) and, across P1-P2, B = (P1, M, R) and
   C = (M, P2, R) with M the midpoint of P1-P2 in space: a T-junction (M lies in the middle
   of A's side) away from the plane z = 0, so the projected vertices are rounded to the
   grid. Once coplanar, once folded along P1-P2. Every centre inside the quad (half a unit
   from its outline) must show a face: a 0 there is a crack between A and B/C. */
static void test_tjunction_depth(void **state)
{
  (void)state;
  static const struct { int v[5][3]; int cx, cy; } cases[] = {
    { { { -28, -75, 1867 }, { -126, -101, 1769 }, { -77, -88, 1818 }, { -69, -121, 1826 },
        { -85, -55, 1810 } }, -30, -32 },                                    /* coplanar */
    { { { 106, -54, 1535 }, { 194, 12, 1733 }, { 150, -21, 1634 }, { 128, 8, 1539 },
        { 172, -50, 1929 } }, 66, 0 },                                       /* folded */
  };
  int bad = 0;
  for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
    struct scn s, outline;
    sc_std(&s);
    for (int k = 0; k < 5; k++) sc_vertex(&s, cases[c].v[k][0], cases[c].v[k][1], cases[c].v[k][2]);
    /* vertices 1 P1, 2 P2, 3 M, 4 Q, 5 R */
    static const int fa[] = { 1, 2, 4 }, fb[] = { 1, 3, 5 }, fc[] = { 3, 2, 5 };
    const int *fv[3] = { fa, fb, fc };
    for (int k = 0; k < 3; k++) {
      struct sface *f = &s.f[s.nf++];
      memset(f, 0, sizeof *f);
      f->id = k + 1;
      f->grey = 255;
      f->nring = 1;
      f->rs[1] = 3;
      for (int q = 0; q < 3; q++) f->vid[q] = fv[k][q];
    }
    sc_std(&outline);
    const int *v = &cases[c].v[0][0];
    const int quad[] = { v[0], v[1], v[2], v[12], v[13], v[14], v[3], v[4], v[5], v[9], v[10], v[11] };
    sc_face3(&outline, 1, 255, 4, quad);              /* only its projection is used */
    struct out o;
    render_scn(&s, 0, 4, NULL, &o);
    int inside = 0;
    for (int j = 0; j < o.H; j++)
      for (int i = 0; i < o.W; i++) {
        double px, py;
        centre(&s, 4, i, j, &px, &py);
        if (fin(&outline, 0, px, py, 0.5) != 1) continue;
        inside++;
        if (o.ids[j * o.W + i] == 0) {
          print_message("case %zu: crack at centre (%g, %g) inside the quad\n", c, px, py);
          bad++;
        }
      }
    assert_true(inside > 20);
    print_message("    case %zu: centre (%d, %d) shows %d\n", c, cases[c].cx, cases[c].cy,
                  id_at(&o, cases[c].cx, cases[c].cy));
    out_free(&o);
  }
  assert_int_equal(bad, 0);
}

/* ---- 8. shallow interpenetration ----------------------------------------------------- */

/* Two squares crossing at a tiny angle (1 unit of z over 300): split at least once, and
   the ids switch exactly between the columns x = -2 and x = 2 along the line x = 0; a
   slanted variant switches along y = -2x/3. */
static void test_shallow(void **state)
{
  (void)state;
  struct scn s;
  scene_shallow(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_true(stat_num(&o, "intersection_splits") >= 1);
  int left = 0, right = 0;
  for (int y = -96; y <= 96; y += 4)
    for (int x = -146; x <= 146; x += 4) {
      int want = x < 0 ? 1 : 2;
      if (id_at(&o, x, y) != want) {
        fail_msg("shallow: centre (%d, %d) shows %d, expected %d", x, y, id_at(&o, x, y), want);
      }
      left += x < 0;
      right += x > 0;
    }
  assert_true(left > 1000 && right > 1000);
  struct fref fr = { &s, 0.5, 4 };
  assert_int_equal(compare_ids(&o, want_float, &fr, "shallow"), 0);
  out_free(&o);

  scene_shallow2(&s);
  render_scn(&s, 0, 4, NULL, &o);
  assert_true(stat_num(&o, "intersection_splits") >= 1);
  int checked = 0;
  for (int y = -96; y <= 96; y += 4)
    for (int x = -146; x <= 146; x += 4) {
      int v = 2 * x + 3 * y;                          /* > 0 above the line */
      if (v == 0) continue;                           /* on the intersection line */
      int want = v > 0 ? 2 : 1;
      if (id_at(&o, x, y) != want)
        fail_msg("shallow2: centre (%d, %d) shows %d, expected %d", x, y, id_at(&o, x, y), want);
      checked++;
    }
  assert_true(checked > 3000);
  fr.s = &s;
  assert_int_equal(compare_ids(&o, want_float, &fr, "shallow2"), 0);
  out_free(&o);
}

/* ---- 8c. a long touch anchored on two close vertices ------------------------------- */

/* Face 2 touches face 1 (the plane z = 30000) only along its short edge (0,1)-(2,0) and is
   in front of it everywhere else. The two vertices are 2 units apart in space and 16
   grid units apart on the plane, so the intersection line carried through their rounded
   positions turns by about 1.5 degrees; far away (x' ~ 150) it passes several units from
   the true line. Face 2 must still be seen wherever it is (zoomed window, 0.2 a point). */
static void test_close_common_vertices(void **state)
{
  (void)state;
  struct scn s;
  sc_init(&s, 0, 0, -1000, 140, -80, 160, -65);
  const int b[] = { -6000, -6000, 30000, 6000, -6000, 30000, 6000, 6000, 30000, -6000, 6000, 30000 };
  sc_face3(&s, 1, 80, 4, b);
  /* plane 100x + 200y + 5z = 150200: through (0,1,30000) and (2,0,30000), nearer elsewhere */
  const int a[] = { 0, 1, 30000, 2, 0, 30000, 6042, -2920, 26000, -5960, 3081, 26000 };
  sc_face3(&s, 2, 255, 4, a);
  for (int flags = 0; flags <= SC_REV_FACES; flags += SC_REV_FACES) {
    struct out o;
    render_scn(&s, flags, 4, NULL, &o);
    int in2 = 0;
    for (int j = 0; j < o.H; j++)
      for (int i = 0; i < o.W; i++) {
        double px, py;
        centre(&s, 4, i, j, &px, &py);
        in2 += fin(&s, 1, px, py, 0.05) == 1;
      }
    assert_true(in2 > 100);
    print_message("    %d centres inside face 2, %d show it\n", in2, count_id(&o, 2));
    struct fref fr = { &s, 0.05, 4 };
    assert_int_equal(compare_ids(&o, want_float, &fr, "close common vertices"), 0);
    out_free(&o);
  }
}

/* ---- 9. cyclic overlap ---------------------------------------------------------------- */

/* Three strips each over the next (no interpenetration): in each pairwise overlap the
   designed strip is on top; no split is made. */
static void test_cyclic(void **state)
{
  (void)state;
  struct scn s;
  scene_cyclic(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  /* pairs (a, b) -> the strip on top: S1 over S2, S2 over S3, S3 over S1 */
  const int top[3][3] = { { 0, 1, 3 }, { 1, 0, 2 }, { 3, 2, 0 } };
  int seen[3][3] = { { 0 } };
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      double px, py;
      centre(&s, 4, i, j, &px, &py);
      int in[3];
      bool amb = false;
      for (int k = 0; k < 3; k++) {
        in[k] = fin(&s, k, px, py, 1.0);
        amb |= in[k] < 0;
      }
      if (amb) continue;
      for (int a = 0; a < 3; a++)
        for (int b = a + 1; b < 3; b++) {
          if (!in[a] || !in[b]) continue;
          int got = o.ids[j * o.W + i];
          if (got != top[a][b])
            fail_msg("cyclic: strips %d and %d overlap at (%g, %g): shows %d, expected %d",
                     a + 1, b + 1, px, py, got, top[a][b]);
          seen[a][b]++;
        }
    }
  assert_true(seen[0][1] >= 20 && seen[1][2] >= 20 && seen[0][2] >= 20);
  assert_int_equal((int)stat_num(&o, "intersection_splits"), 0);
  struct fref fr = { &s, 1.0, 4 };
  assert_int_equal(compare_ids(&o, want_float, &fr, "cyclic"), 0);
  out_free(&o);
}

/* ---- 10. coplanar faces ------------------------------------------------------------- */

/* Coplanar overlapping faces (flat and slanted): the larger face number is seen. */
static void test_coplanar(void **state)
{
  (void)state;
  struct scn s;
  scene_coplanar(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal(id_at(&o, 2, 4), 12);            /* all three */
  assert_int_equal(id_at(&o, -30, -32), 7);         /* 7 and 3 */
  assert_int_equal(id_at(&o, 70, 72), 3);           /* 3 alone */
  assert_int_equal(id_at(&o, -50, -52), 7);         /* both own this corner: 7 */
  struct fref fr = { &s, 0.5, 4 };
  assert_int_equal(compare_ids(&o, want_float, &fr, "coplanar"), 0);
  /* the flat ones exactly */
  int bad = 0;
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      long long x = -198 + 4 * i, y = 148 - 4 * j;
      int want = 0;
      for (int k = 0; k < 3; k++)
        if (s.f[k].id > want && face_tie_in(&s, k, x, y)) want = s.f[k].id;
      int got = o.ids[j * o.W + i];
      if (want && got != want) bad++;
    }
  assert_int_equal(bad, 0);
  /* the slanted pair: 20 seen where both are */
  assert_true(count_id(&o, 20) > 200);
  assert_true(count_id(&o, 19) == 0);               /* 19 lies inside 20 */
  out_free(&o);
}

/* ---- 11. the ends of the 16-bit range ------------------------------------------------ */

/* Coordinates -32768 and 32767 in vertices, view and window: renders, no crash, and the
   ids are the expected ones. */
static void test_extremes(void **state)
{
  (void)state;
  struct scn s;
  sc_init(&s, 0, 0, -32768, -32768, -32768, 32767, 32767);
  const int f1[] = { -32768, -32768, 0, 32767, -32768, 0, 32767, 32767, 0, -32768, 32767, 0 };
  const int f2[] = { -32768, -32768, 32767, 32767, -32768, 32767, 32767, 32767, 32767,
                     -32768, 32767, 32767 };
  const int f3[] = { -8000, -8000, -16384, 8000, -8000, -16384, 0, 8000, -16384 };
  sc_face3(&s, 1, 100, 4, f1);
  sc_face3(&s, 2, 200, 4, f2);
  sc_face3(&s, 3, 255, 3, f3);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  assert_int_equal(count_id(&o, 2), 0);
  assert_int_equal(count_id(&o, 0), 0);             /* face 1 fills the window */
  assert_true(count_id(&o, 3) > 500);
  struct fref fr = { &s, 1.0, 4 };
  assert_int_equal(compare_ids(&o, want_float, &fr, "extremes"), 0);
  out_free(&o);

  /* eye at a corner: the far face projects onto [-1, 32767]^2 */
  sc_init(&s, 32767, 32767, -32768, -32768, -32768, 32767, 32767);
  sc_face3(&s, 2, 200, 4, f2);
  render_scn(&s, 0, 4, NULL, &o);
  for (int j = 0; j < o.H; j++)
    for (int i = 0; i < o.W; i++) {
      int want = (i >= 50 && j <= 37) ? 2 : 0;
      if (o.ids[j * o.W + i] != want)
        fail_msg("corner eye: point (%d, %d) shows %d, expected %d", i, j, o.ids[j * o.W + i], want);
    }
  out_free(&o);

  /* a vertex that projects out of the plane grid: a clean input error, not a crash */
  sc_init(&s, 0, 0, -32768, -32768, -32768, 32767, 32767);
  const int near[] = { 32767, 0, -32767, 32767, 10, -32767, 32760, 10, -32767 };
  sc_face3(&s, 1, 255, 3, near);
  const char *p = tpath("near.s74");
  sc_write(&s, p, 0);
  render_file(p, 4, NULL, &o);
  assert_int_equal(o.status, 2);
  assert_true(strncmp(o.err, p, strlen(p)) == 0 && o.err[strlen(p)] == ':');
  out_free(&o);
}

/* ---- 12. core exactly full, and one word short ---------------------------------------- */

static bool dir_has_only(const char *const *names)
{
  DIR *d = opendir(tmpdir);
  assert_non_null(d);
  struct dirent *e;
  bool ok = true;
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    bool known = false;
    for (int k = 0; names[k]; k++) known |= !strcmp(e->d_name, names[k]);
    if (!known) { print_message("unexpected file %s\n", e->d_name); ok = false; }
  }
  closedir(d);
  return ok;
}

static void clean_dir(void)
{
  rm_tree(tmpdir);
}

/* A scene that exactly fills the core runs with --core N (same ids) and fails with
   --core N-1: exit 3, a message naming the words needed and available, no output file. */
static void test_core_limit(void **state)
{
  (void)state;
  clean_dir();
  struct scn s;
  scene_comb(&s);
  const int a[] = { -150, -100, 10, 150, -100, 11, 150, 100, 11, -150, 100, 10 };
  sc_face3(&s, 8, 255, 4, a);                        /* just behind the combs */
  const int s2[] = { 80, -120, 300, 120, -120, 300, -20, 120, -100, -60, 120, -100 };
  sc_face3(&s, 9, 160, 4, s2);
  const char *scene = "core.s74";
  sc_write(&s, tpath(scene), 0);
  struct out big;
  const char *xbig[] = { "--core", "1000000", NULL };
  render_file(tpath(scene), 4, xbig, &big);
  if (big.status) fail_msg("core run: exit %d: %s", big.status, big.err);
  long used = (long)stat_num(&big, "core_words_used");
  assert_true(used > 0 && used < 1000000);
  assert_int_equal((long)stat_num(&big, "core_words"), 1000000);

  char nbuf[32];
  snprintf(nbuf, sizeof nbuf, "%ld", used);
  const char *xn[] = { "--core", nbuf, NULL };
  struct out exact;
  render_file(tpath(scene), 4, xn, &exact);
  if (exact.status) fail_msg("--core %ld (= core_words_used): exit %d: %s", used, exact.status, exact.err);
  assert_memory_equal(exact.ids, big.ids, (size_t)big.W * big.H * sizeof *big.ids);
  assert_string_equal(exact.points_text, big.points_text);
  assert_int_equal((long)stat_num(&exact, "core_words_used"), used);
  out_free(&exact);

  clean_dir();
  sc_write(&s, tpath(scene), 0);
  snprintf(nbuf, sizeof nbuf, "%ld", used - 1);
  char dids[300], dtube[300], dpts[300];
  snprintf(dids, sizeof dids, "ids=%s", tpath("o.ids.pgm"));
  snprintf(dtube, sizeof dtube, "tube=%s", tpath("o.tube.pbm"));
  snprintf(dpts, sizeof dpts, "points=%s", tpath("o.points.txt"));
  const char *args[] = { "render", tpath(scene), "--cell", "4", "--core", nbuf, "-o",
                         tpath("o.png"), "--dump", dids, "--dump", dtube, "--dump", dpts,
                         "--stats", tpath("o.json"), NULL };
  char *err = NULL;
  int st = run_prog(args, &err);
  assert_int_equal(st, 3);
  assert_non_null(err);
  print_message("    --core %ld: %s", used - 1, err);
  /* the message names the words needed (> N-1) and the words available (N-1) */
  const char *m = strstr(err, "needs ");
  assert_non_null(m);
  long need = strtol(m + 6, NULL, 10);
  assert_true(need >= used);
  char avail[48];
  snprintf(avail, sizeof avail, "%ld available", used - 1);
  assert_non_null(strstr(err, avail));
  free(err);
  assert_false(exists(tpath("o.png")));
  assert_false(exists(tpath("o.ids.pgm")));
  assert_false(exists(tpath("o.tube.pbm")));
  assert_false(exists(tpath("o.points.txt")));
  assert_false(exists(tpath("o.json")));
  const char *only[] = { scene, NULL };
  assert_true(dir_has_only(only));
  out_free(&big);
}

/* The same with 1000 small faces, so that the priority matrix is large: --core N (N the
   core_words_used of a run with a large core) must still be the exact need, so --core N-1
   must fail with exit 3 and --core N succeed with the same ids. */
static void test_core_limit_many_faces(void **state)
{
  (void)state;
  clean_dir();
  const char *scene = tpath("many.s74");
  FILE *f = fopen(scene, "w");
  assert_non_null(f);
  fprintf(f, "view 0 0 -1000\nwindow -200 -150 200 150\n");
  int v = 1;
  for (int k = 0; k < 1000; k++) {
    int x = -195 + (k % 39) * 10, y = -145 + (k / 39) * 11, z = (k * 7) % 50;
    fprintf(f, "vertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\nvertex %d %d %d %d\n",
            v, x, y, z, v + 1, x + 8, y, z, v + 2, x + 8, y + 8, z, v + 3, x, y + 8, z);
    fprintf(f, "face %d %d %d %d %d\n", k + 1, v, v + 1, v + 2, v + 3);
    v += 4;
  }
  fclose(f);
  char scenebuf[256];
  snprintf(scenebuf, sizeof scenebuf, "%s", scene);
  struct out big, exact, less;
  const char *xbig[] = { "--core", "1000000", NULL };
  render_file(scenebuf, 4, xbig, &big);
  if (big.status) fail_msg("core run: exit %d: %s", big.status, big.err);
  long used = (long)stat_num(&big, "core_words_used");
  char nbuf[32];
  snprintf(nbuf, sizeof nbuf, "%ld", used);
  const char *xn[] = { "--core", nbuf, NULL };
  render_file(scenebuf, 4, xn, &exact);
  if (exact.status) fail_msg("--core %ld: exit %d: %s", used, exact.status, exact.err);
  assert_memory_equal(exact.ids, big.ids, (size_t)big.W * big.H * sizeof *big.ids);
  snprintf(nbuf, sizeof nbuf, "%ld", used - 1);
  const char *xl[] = { "--core", nbuf, NULL };
  render_file(scenebuf, 4, xl, &less);
  if (less.status != 3)
    fail_msg("core_words_used %ld with --core 1000000, yet --core %ld exits %d (core_words_used "
             "%ld there)", used, used - 1, less.status,
             less.status == 0 ? (long)stat_num(&less, "core_words_used") : -1L);
  out_free(&big);
  out_free(&exact);
  out_free(&less);
}

/* ---- 13. bad input leaves every file as it was --------------------------------------- */

/* Malformed scenes: exit 2, stderr starts with FILE:LINE:, and an existing -o file (and
   dump and stats files) keep their content; no new file appears. */
static void test_bad_input(void **state)
{
  (void)state;
  clean_dir();
  static const struct { const char *text; int line; } bad[] = {
    { "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 0 0 0\nsphere 1 2 3\n", 4 },
    { "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 0 0 0\nvertex 2 10 0 0\n"
      "vertex 3 10 10 0\nvertex 4 0 10 5\nface 1 1 2 3 4\n", 7 },             /* not planar */
    { "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 0 0 32768\n", 3 },  /* range */
    { "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 0 0 0\nvertex 2 10 0 0\n"
      "face 1 1 2 7\n", 5 },                                                  /* no vertex 7 */
    { "view 0 0 -1000\nwindow -200 -150 200 150\n# comment\nvertex 1 0 0 0\n"
      "vertex 2 10 0 -1000\nvertex 3 10 10 0\nface 1 1 2 3\n", 5 },          /* behind eye */
    { "view 0 0 -1000\nwindow -200 -150 200 150\nvertex 1 0 0 0\nvertex 2 10 0 0\n"
      "vertex 3 0 10 0\nface 1 1 2 3 grey 256\n", 6 },                       /* grey range */
    { "view 0 0 -1000\nwindow 200 -150 -200 150\n", 2 },                      /* window */
  };
  char png[256], ids[256], json[256], scene[256];
  snprintf(png, sizeof png, "%s", tpath("keep.png"));
  snprintf(ids, sizeof ids, "%s", tpath("keep.pgm"));
  snprintf(json, sizeof json, "%s", tpath("keep.json"));
  snprintf(scene, sizeof scene, "%s", tpath("bad.s74"));
  for (size_t b = 0; b < sizeof bad / sizeof *bad; b++) {
    put_file(png, "old picture\n");
    put_file(ids, "old ids\n");
    put_file(json, "old stats\n");
    put_file(scene, bad[b].text);
    char dids[300];
    snprintf(dids, sizeof dids, "ids=%s", ids);
    const char *args[] = { "render", scene, "-o", png, "--dump", dids, "--stats", json, NULL };
    char *err = NULL;
    int st = run_prog(args, &err);
    if (st != 2) fail_msg("bad scene %zu: exit %d (stderr: %s)", b, st, err);
    char prefix[300];
    snprintf(prefix, sizeof prefix, "%s:%d:", scene, bad[b].line);
    if (strncmp(err, prefix, strlen(prefix)) != 0)
      fail_msg("bad scene %zu: stderr does not start with %s: %s", b, prefix, err);
    free(err);
    char *c = slurp(png, NULL);
    assert_string_equal(c, "old picture\n");
    free(c);
    c = slurp(ids, NULL);
    assert_string_equal(c, "old ids\n");
    free(c);
    c = slurp(json, NULL);
    assert_string_equal(c, "old stats\n");
    free(c);
    const char *only[] = { "keep.png", "keep.pgm", "keep.json", "bad.s74", NULL };
    assert_true(dir_has_only(only));
  }
  /* a usage error (bad --cell) changes nothing either */
  const char *args[] = { "render", scene, "--cell", "5", "-o", png, NULL };
  char *err = NULL;
  assert_int_equal(run_prog(args, &err), 2);
  assert_true(err && *err);
  free(err);
  char *c = slurp(png, NULL);
  assert_string_equal(c, "old picture\n");
  free(c);
}

/* ---- 14. --dump points order ----------------------------------------------------------- */

static void check_points(const struct scn *s, const struct out *o, int cell)
{
  /* the points are the PBM's lit dots, each once */
  uint8_t *seen = calloc(400 * 300, 1);
  for (int k = 0; k < o->npts; k++) {
    int x = o->pts[k][0], y = o->pts[k][1];
    assert_true(x >= 0 && x < 400 && y >= 0 && y < 300);
    assert_int_equal(seen[y * 400 + x], 0);
    seen[y * 400 + x] = 1;
    assert_int_equal(o->tube[y * 400 + x], 1);
  }
  int lit = 0;
  for (int k = 0; k < 400 * 300; k++) lit += o->tube[k];
  assert_int_equal(lit, o->npts);
  assert_int_equal((int)stat_num(o, "points_lit"), o->npts);
  free(seen);
  /* order: bottom grid row first, each row left to right, in a cell top dot row first */
  int W = 400 / cell, H = 300 / cell, maxj = -1;
  for (int k = 0; k < o->npts; k++) {
    int j = (299 - o->pts[k][1]) / cell;
    if (j > maxj) maxj = j;
  }
  for (int k = 0; k < o->npts; k++) {
    int x = o->pts[k][0], y = o->pts[k][1];
    int i = x / cell, j = (299 - y) / cell, cy = (299 - y) % cell;
    assert_true(i < W && j < H);
    if (k == 0) { assert_int_equal(j, maxj); continue; }
    int px = o->pts[k - 1][0], py = o->pts[k - 1][1];
    int pi = px / cell, pj = (299 - py) / cell, pcy = (299 - py) % cell;
    bool ok = j < pj || (j == pj && (i > pi || (i == pi && (cy > pcy || (cy == pcy && x > px)))));
    if (!ok) fail_msg("points %d, %d out of order: (%d, %d) then (%d, %d)", k - 1, k, px, py, x, y);
  }
  /* every point's cell has exactly pat_level(grey of its face) dots */
  for (int j = 0; j < H; j++)
    for (int i = 0; i < W; i++) {
      int id = o->ids[j * W + i], grey = 0;
      for (int f = 0; f < s->nf; f++)
        if (s->f[f].id == id) grey = s->f[f].grey < 0 ? 255 : s->f[f].grey;
      int n = 0;
      for (int cy = 0; cy < cell; cy++)
        for (int cx = 0; cx < cell; cx++) n += o->tube[(299 - cell * j - cy) * 400 + cell * i + cx];
      if (n != (id ? pat_level(cell, grey) : 0))
        fail_msg("point (%d, %d), face %d grey %d: %d dots lit, expected %d", i, j, id, grey, n,
                 id ? pat_level(cell, grey) : 0);
    }
}

/* --dump points lists the PBM's lit dots exactly once each, bottom grid rows first and
   left to right (as the 1974 program displayed while computing), for cells 4 and 3. */
static void test_points_order(void **state)
{
  (void)state;
  struct scn s;
  scene_tiling(&s);
  for (int cell = 4; cell >= 3; cell--) {
    struct out o;
    render_scn(&s, 0, cell, NULL, &o);
    assert_true(o.npts > 1000);
    check_points(&s, &o, cell);
    out_free(&o);
  }
  scene_cyclic(&s);
  struct out o;
  render_scn(&s, 0, 3, NULL, &o);
  check_points(&s, &o, 3);
  out_free(&o);
}

/* ---- stats ------------------------------------------------------------------------ */

/* --stats holds every field the contract names, with values that fit the scene. */
static void test_stats_fields(void **state)
{
  (void)state;
  struct scn s;
  scene_comb(&s);
  struct out o;
  render_scn(&s, 0, 4, NULL, &o);
  static const char *const fields[] = { "faces_in", "faces_after_split", "concave_splits",
    "intersection_splits", "priority_pairs_computed", "priority_pairs_possible", "core_words",
    "core_words_used", "hitac10_seconds", "host_seconds", "points_lit" };
  for (size_t k = 0; k < sizeof fields / sizeof *fields; k++) (void)stat_num(&o, fields[k]);
  assert_non_null(strstr(o.stats, "\"stages\": ["));
  assert_int_equal((int)stat_num(&o, "faces_in"), 3);
  assert_true(stat_num(&o, "concave_splits") >= 3);          /* every comb is concave */
  assert_true(stat_num(&o, "faces_after_split") > 3);
  assert_int_equal((int)stat_num(&o, "core_words"), 16384);  /* the default core */
  assert_true(stat_num(&o, "core_words_used") > 0 && stat_num(&o, "core_words_used") <= 16384);
  assert_true(stat_num(&o, "hitac10_seconds") > 0);
  /* the first dot reaches the tube after the Mapper (the Segment Generator runs as the
     scan reaches each face: tests/test_segment.c test_cut_while_scanning) and before the
     run ends */
  double first = stat_num(&o, "first_dot_1974_seconds");
  assert_true(first >= stat_num(&o, "mapper"));
  assert_true(first > 0 && first < stat_num(&o, "hitac10_seconds"));
  assert_int_equal((int)stat_num(&o, "points_lit"), o.npts);
  int n = (int)stat_num(&o, "faces_after_split");
  assert_int_equal((long)stat_num(&o, "priority_pairs_possible"), (long)n * (n - 1) / 2);
  out_free(&o);
}

/* ---- 16. random scenes ---------------------------------------------------------------- */

static uint64_t rng_state;

static int rnd(int lo, int hi)             /* uniform in lo..hi */
{
  rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
  return lo + (int)((rng_state >> 33) % (uint64_t)(hi - lo + 1));
}

/* Face k of s projected from (0, 0, -1000): every vertex has z in {0, 1000, 3000} and x, y
   multiples of (z + 1000)/1000, so the projection is exact integers. */
static bool face_tie_in_proj(const struct scn *s, int k, long long px, long long py)
{
  const struct sface *f = &s->f[k];
  long long xy[2 * SC_MAXFV];
  for (int q = 0; q < f->rs[f->nring]; q++) {
    const int *v = s->v[f->vid[q] - 1];
    int m = (v[2] + 1000) / 1000;
    assert_true(v[0] % m == 0 && v[1] % m == 0);
    xy[2 * q] = v[0] / m;
    xy[2 * q + 1] = v[1] / m;
  }
  return tie_in(f->nring, f->rs, xy, px, py);
}

/* Distance (plane units) from (px, py) to the line where faces a and b are equally deep;
   -1 when they are coplanar. */
static double equal_depth_dist(const struct scn *s, int a, int b, double px, double py)
{
  if (coplanar(s, a, b)) return -1;
  i128 pa[4], pb[4];
  plane_of(s, a, pa);
  plane_of(s, b, pb);
  const double E[3] = { s->view[0], s->view[1], s->view[2] };
  double DA = (double)pa[0] * E[0] + (double)pa[1] * E[1] + (double)pa[2] * E[2] + (double)pa[3];
  double DB = (double)pb[0] * E[0] + (double)pb[1] * E[1] + (double)pb[2] * E[2] + (double)pb[3];
  /* H(v) = DA nB.v - DB nA.v with v = (x - E0, y - E1, -E2) */
  double h[3];
  for (int c = 0; c < 3; c++) h[c] = DA * (double)pb[c] - DB * (double)pa[c];
  double H = h[0] * (px - E[0]) + h[1] * (py - E[1]) + h[2] * -E[2];
  double g = sqrt(h[0] * h[0] + h[1] * h[1]);
  if (g == 0) return 1e30;                /* never equally deep inside the plane */
  return fabs(H) / g;
}

/* Random scenes of triangles in depth, flat concave stars, coplanar copies: the points lit
   are exactly the union of the faces under the tie rule (no cracks, no spill, however the
   faces were cut), a point shows a face that covers it, and away from edges and from lines
   of equal depth it shows the nearest face (a larger number among coplanar ones). */
static void test_random_scenes(void **state)
{
  (void)state;
  rng_state = getenv("T74_RANDOM_SEED") ? strtoull(getenv("T74_RANDOM_SEED"), NULL, 0) : 0x74197419ull;
  int rounds = getenv("T74_RANDOM_ROUNDS") ? atoi(getenv("T74_RANDOM_ROUNDS")) : 120;
  int scenes = 0, splits = 0, checked_all = 0;
  for (int round = 0; round < rounds; round++) {
    struct scn s;
    sc_std(&s);
    int nf = rnd(2, 9), id = 1, tries = 0;
    for (int k = 0; k < nf; k++) {
      int kind = rnd(0, 9);
      if (kind < 6) {                                  /* a triangle in depth */
        int xyz[9];
        int cx = rnd(-150, 150), cy = rnd(-110, 110), r = rnd(10, 120);
        for (int v = 0; v < 3; v++) {
          static const int zs[3] = { 0, 1000, 3000 };
          int z = zs[rnd(0, 2)], m = (z + 1000) / 1000;
          int x = cx + rnd(-r, r), y = cy + rnd(-r, r);
          if (x < -199) x = -199;
          if (x > 199) x = 199;
          if (y < -149) y = -149;
          if (y > 149) y = 149;
          xyz[3 * v] = x * m; xyz[3 * v + 1] = y * m; xyz[3 * v + 2] = z;
        }
        /* not a line in space */
        long long ux = xyz[3] - xyz[0], uy = xyz[4] - xyz[1], uz = xyz[5] - xyz[2];
        long long vx = xyz[6] - xyz[0], vy = xyz[7] - xyz[1], vz = xyz[8] - xyz[2];
        if (!(uy * vz - uz * vy) && !(uz * vx - ux * vz) && !(ux * vy - uy * vx)) { k--; continue; }
        sc_face3(&s, id++, rnd(0, 255), 3, xyz);
      } else if (kind < 8) {                           /* a flat star, concave */
        static const int zs[3] = { 0, 1000, 3000 };
        int z = zs[rnd(0, 2)], m = (z + 1000) / 1000;
        int n = rnd(5, 12), cx = rnd(-120, 120), cy = rnd(-90, 90);
        int xy[2 * 12];
        for (int v = 0; v < n; v++) {
          double ang = 2 * 3.14159265358979 * (v + 0.1 * rnd(0, 8)) / n;
          int r = rnd(8, 60);
          xy[2 * v] = (cx + (int)lround(r * cos(ang))) * m;
          xy[2 * v + 1] = (cy + (int)lround(r * sin(ang))) * m;
        }
        bool dup = false;
        for (int a = 0; a < n; a++)
          for (int b = a + 1; b < n; b++)
            dup |= xy[2 * a] == xy[2 * b] && xy[2 * a + 1] == xy[2 * b + 1];
        if (dup) { k--; continue; }
        sc_face2(&s, id++, rnd(0, 255), n, xy, z);
      } else if (s.nf > 0) {                           /* coplanar with an earlier face */
        /* a triangle of points of an earlier triangle's plane: its vertices a, b, c and the
           parallelogram points a+b-c, a+c-b, b+c-a that keep the projection exact */
        const struct sface *f = &s.f[rnd(0, s.nf - 1)];
        if (f->nring != 1 || f->rs[1] != 3) { if (++tries < 50) k--; continue; }
        int P[6][3];
        for (int c = 0; c < 3; c++) {
          const int *a = s.v[f->vid[0] - 1], *b = s.v[f->vid[1] - 1], *d = s.v[f->vid[2] - 1];
          P[0][c] = a[c]; P[1][c] = b[c]; P[2][c] = d[c];
          P[3][c] = a[c] + b[c] - d[c]; P[4][c] = a[c] + d[c] - b[c]; P[5][c] = b[c] + d[c] - a[c];
        }
        int ok[6], nok = 0;
        for (int q = 0; q < 6; q++) {
          int z = P[q][2];
          if (z != 0 && z != 1000 && z != 3000) continue;
          int m = (z + 1000) / 1000;
          if (P[q][0] % m || P[q][1] % m) continue;
          if (abs(P[q][0] / m) > 199 || abs(P[q][1] / m) > 149) continue;
          ok[nok++] = q;
        }
        if (nok < 4) { if (++tries < 50) k--; continue; }
        int q0 = ok[rnd(0, nok - 1)], q1, q2;
        do q1 = ok[rnd(0, nok - 1)]; while (q1 == q0);
        do q2 = ok[rnd(0, nok - 1)]; while (q2 == q0 || q2 == q1);
        long long ux = P[q1][0] - P[q0][0], uy = P[q1][1] - P[q0][1], uz = P[q1][2] - P[q0][2];
        long long vx = P[q2][0] - P[q0][0], vy = P[q2][1] - P[q0][1], vz = P[q2][2] - P[q0][2];
        if (!(uy * vz - uz * vy) && !(uz * vx - ux * vz) && !(ux * vy - uy * vx)) {
          if (++tries < 50) k--;
          continue;
        }
        int xyz[9] = { P[q0][0], P[q0][1], P[q0][2], P[q1][0], P[q1][1], P[q1][2],
                       P[q2][0], P[q2][1], P[q2][2] };
        sc_face3(&s, id++, rnd(0, 255), 3, xyz);
      } else {
        k--;
      }
    }
    struct out o;
    render_scn(&s, rnd(0, 1) ? SC_REV_FACES : 0, 4, NULL, &o);
    scenes++;
    splits += (int)stat_num(&o, "intersection_splits");
    int union_bad = 0, owner_bad = 0, depth_bad = 0, checked = 0;
    for (int j = 0; j < o.H; j++)
      for (int i = 0; i < o.W; i++) {
        long long x = -198 + 4 * i, y = 148 - 4 * j;
        int got = o.ids[j * o.W + i], cover = 0, gotk = -1;
        for (int k = 0; k < s.nf; k++)
          if (face_tie_in_proj(&s, k, x, y)) {
            cover++;
            if (s.f[k].id == got) gotk = k;
          }
        if ((got != 0) != (cover > 0)) {
          if (union_bad++ < 5)
            print_message("scene %d: (%lld, %lld) shows %d but %d faces cover it\n", round, x, y,
                          got, cover);
          continue;
        }
        if (got && gotk < 0) {
          if (owner_bad++ < 5)
            print_message("scene %d: (%lld, %lld) shows face %d, which does not cover it\n",
                          round, x, y, got);
          continue;
        }
        if (!got) continue;
        /* the nearest covering face, where that is clear */
        int near = -1;
        double tn = 0;
        bool amb = false;
        for (int k = 0; k < s.nf && !amb; k++) {
          int r = fin(&s, k, (double)x, (double)y, 0.5);
          if (r < 0) amb = true;
          if (r != 1) continue;
          double t = fdepth(&s, k, (double)x, (double)y);
          if (near < 0 || t < tn) { near = k; tn = t; }
        }
        if (amb || near < 0) continue;
        int want = s.f[near].id;
        for (int k = 0; k < s.nf && !amb; k++) {
          if (k == near || fin(&s, k, (double)x, (double)y, 0.5) != 1) continue;
          double d = equal_depth_dist(&s, near, k, (double)x, (double)y);
          if (d < 0) { if (s.f[k].id > want) want = s.f[k].id; }
          else if (d < 0.5) amb = true;
        }
        if (amb) continue;
        checked++;
        if (got != want && depth_bad++ < 5)
          print_message("scene %d: (%lld, %lld) shows %d, nearest is %d\n", round, x, y, got, want);
      }
    checked_all += checked;
    if (union_bad || owner_bad || depth_bad) {
      char keep[300];
      snprintf(keep, sizeof keep, "/tmp/t74_random_%d.s74", round);
      sc_write(&s, keep, 0);
      fail_msg("random scene %d (kept as %s): %d union, %d owner, %d depth errors", round, keep,
               union_bad, owner_bad, depth_bad);
    }
    out_free(&o);
  }
  print_message("    %d random scenes, %d intersection splits, %d points checked in depth\n",
                scenes, splits, checked_all);
  assert_true(splits > rounds / 6);
  assert_true(checked_all > rounds * 400);
}

/* ---- 15. invariance ------------------------------------------------------------------ */

/* Faces listed in reverse order (and rings written the other way round) give identical
   --dump points and ids on every hard scene. */
static void test_invariance(void **state)
{
  (void)state;
  void (*make[])(struct scn *) = { scene_centres, scene_horizontal, scene_comb, scene_holes,
                                   scene_tiling, scene_shallow, scene_shallow2, scene_cyclic,
                                   scene_coplanar, scene_sliver };
  static const char *names[] = { "centres", "horizontal", "comb", "holes", "tiling", "shallow",
                                 "shallow2", "cyclic", "coplanar", "sliver" };
  int bad = 0;
  for (size_t k = 0; k < sizeof make / sizeof *make; k++) {
    struct scn s;
    make[k](&s);
    struct out a, b, c;
    render_scn(&s, 0, 4, NULL, &a);
    render_scn(&s, SC_REV_FACES, 4, NULL, &b);
    render_scn(&s, SC_REV_RINGS, 4, NULL, &c);
    if (strcmp(a.points_text, b.points_text) != 0 ||
        memcmp(a.ids, b.ids, (size_t)a.W * a.H * sizeof *a.ids) != 0) {
      int n = 0;
      for (int q = 0; q < a.W * a.H; q++) n += a.ids[q] != b.ids[q];
      print_message("%s: faces reversed changes %d ids\n", names[k], n);
      bad++;
    }
    if (strcmp(a.points_text, c.points_text) != 0 ||
        memcmp(a.ids, c.ids, (size_t)a.W * a.H * sizeof *a.ids) != 0) {
      int n = 0;
      for (int q = 0; q < a.W * a.H; q++) n += a.ids[q] != c.ids[q];
      print_message("%s: rings reversed changes %d ids\n", names[k], n);
      bad++;
    }
    out_free(&a);
    out_free(&b);
    out_free(&c);
  }
  assert_int_equal(bad, 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_centres),
    cmocka_unit_test(test_cell3_window),
    cmocka_unit_test(test_horizontal),
    cmocka_unit_test(test_comb),
    cmocka_unit_test(test_holes),
    cmocka_unit_test(test_sliver),
    cmocka_unit_test(test_edge_on),
    cmocka_unit_test(test_tiling),
    cmocka_unit_test(test_tjunction_depth),
    cmocka_unit_test(test_shallow),
    cmocka_unit_test(test_close_common_vertices),
    cmocka_unit_test(test_cyclic),
    cmocka_unit_test(test_coplanar),
    cmocka_unit_test(test_extremes),
    cmocka_unit_test(test_extreme_depth),
    cmocka_unit_test(test_three_through_line),
    cmocka_unit_test(test_core_limit),
    cmocka_unit_test(test_core_limit_many_faces),
    cmocka_unit_test(test_bad_input),
    cmocka_unit_test(test_points_order),
    cmocka_unit_test(test_invariance),
    cmocka_unit_test(test_stats_fields),
    cmocka_unit_test(test_random_scenes),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
