/*
** test_play.c — `tube74 play`: the movie, the no-display failure, and a real window on
** an X server (Xvfb). Sources: paper 003 §4 (the picture built up dot by dot on a
** 400 x 300 point storage tube); CONTRACT.md (--dump tube, exit 4 on a device failure).
**
** This file contains code to run the tube74 program ($TUBE74, default ./tube74, from the
** repository root) and check what it shows:
**   movie     `play --movie` with no display at all writes FILE-0001.png ...: as many
**             frames as the 1974 timing asks for, the first a bare glowing face, the
**             middle ones partly built, the last exactly the final picture (`render
**             --look glow` of the same scene), and the dots of `--dump tube` lit in it;
**   nodisplay `play` without DISPLAY fails with exit 4 and a message saying so;
**   xvfb      with an Xvfb server (started here on a free display number): `play
**             --speed 1000 --quit-after 2 --screenshot` opens a window, which the X server
**             really shows — read back from the server's root window through Xlib
**             (loaded with dlopen, so the test needs no X library at link time) — and both
**             the screenshot and the server's pixels are the final tube picture, with the
**             --dump tube dots bright at their places at the chosen scale.
** When Xvfb is not installed, the other tests run and the program exits 77 (skip) with a
** line saying why.
*/
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#include <cmocka.h>
#include <png.h>

#define SCENE "scenes/fig5.s74"

static char g_dir[64];              /* scratch folder of this run */

static const char *tube74(void)
{
  const char *t = getenv("TUBE74");
  return t && *t ? t : "./tube74";
}

static char *in_dir(char *buf, size_t n, const char *name)
{
  snprintf(buf, n, "%s/%s", g_dir, name);
  return buf;
}

static void sleep_s(double s)
{
  struct timespec ts = { (time_t)s, (long)((s - floor(s)) * 1e9) };
  nanosleep(&ts, NULL);
}

/* Start argv with stdout/stderr to files (NULL: /dev/null); display: DISPLAY value, "" to
** unset it, NULL to leave it. Returns the child's pid. */
static pid_t spawn(char *const argv[], const char *out, const char *errf, const char *display)
{
  pid_t pid = fork();
  if (pid != 0) return pid;
  int fo = open(out ? out : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  int fe = open(errf ? errf : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fo >= 0) dup2(fo, 1);
  if (fe >= 0) dup2(fe, 2);
  if (display && !*display) { unsetenv("DISPLAY"); unsetenv("WAYLAND_DISPLAY"); unsetenv("SDL_VIDEODRIVER"); }
  else if (display) {
    setenv("DISPLAY", display, 1);
    /* under `make asan`: the X, GL and D-Bus libraries SDL loads keep memory to the end;
       those leaks are not tube74's, so leak checking is off for windowed runs */
    const char *old = getenv("ASAN_OPTIONS");
    char opts[512];
    snprintf(opts, sizeof opts, "detect_leaks=0%s%s", old && *old ? ":" : "", old ? old : "");
    setenv("ASAN_OPTIONS", opts, 1);
  }
  execvp(argv[0], argv);
  _exit(127);
}

/* Wait for pid at most `limit` seconds (then kill it); its exit status, or -1. */
static int wait_for(pid_t pid, double limit)
{
  for (double t = 0; t < limit; t += 0.02) {
    int status;
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    sleep_s(0.02);
  }
  kill(pid, SIGKILL);
  waitpid(pid, NULL, 0);
  return -1;
}

static int run(char *const argv[], const char *out, const char *errf, const char *display)
{
  return wait_for(spawn(argv, out, errf, display), 60);
}

static char *slurp(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = calloc(1, 1 << 16);
  if (buf) { size_t n = fread(buf, 1, (1 << 16) - 1, f); buf[n] = '\0'; }
  fclose(f);
  return buf;
}

/* An RGB picture read back with libpng's simplified API. */
struct rgb { int w, h; uint8_t *px; };

static int read_png(const char *path, struct rgb *p)
{
  png_image im;
  memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&im, path)) return -1;
  im.format = PNG_FORMAT_RGB;
  p->w = (int)im.width;
  p->h = (int)im.height;
  p->px = malloc(PNG_IMAGE_SIZE(im));
  if (!p->px || !png_image_finish_read(&im, NULL, p->px, 0, NULL)) { free(p->px); return -1; }
  return 0;
}

/* The --dump tube PBM: lit[y * 400 + x], y counted from the bottom. */
static int read_pbm(const char *path, uint8_t *lit)
{
  FILE *f = fopen(path, "rb");
  if (!f) return -1;
  int w, h;
  if (fscanf(f, "P4 %d %d", &w, &h) != 2 || w != 400 || h != 300) { fclose(f); return -1; }
  fgetc(f);
  uint8_t row[50];
  for (int r = 0; r < 300; r++) {
    if (fread(row, 1, 50, f) != 50) { fclose(f); return -1; }
    for (int x = 0; x < 400; x++) lit[(299 - r) * 400 + x] = (row[x >> 3] >> (7 - (x & 7))) & 1;
  }
  fclose(f);
  return 0;
}

/* Mean green of dot (x, y)'s s x s block in an RGB picture of stride w. */
static double dot_green(const uint8_t *px, int w, int s, int x, int y)
{
  double g = 0;
  for (int j = 0; j < s; j++)
    for (int i = 0; i < s; i++) g += px[3 * ((size_t)((299 - y) * s + j) * w + x * s + i) + 1];
  return g / (s * s);
}

/* Check that the face (top 300s rows of pic) shows the dots of lit: every lit dot is
** brighter than the glow by far, and every unlit dot with no lit neighbour is as dark as
** the glow. Returns the number of dots that break this. */
static int check_dots(const struct rgb *pic, int s, const uint8_t *lit, int *nlit)
{
  int bad = 0;
  *nlit = 0;
  for (int y = 0; y < 300; y++)
    for (int x = 0; x < 400; x++) {
      double g = dot_green(pic->px, pic->w, s, x, y);
      if (lit[y * 400 + x]) {
        (*nlit)++;
        if (g < 60) bad++;                   /* a lone stored dot's block is >= ~80 */
        continue;
      }
      int near = 0;
      for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
          int xx = x + dx, yy = y + dy;
          if (xx >= 0 && xx < 400 && yy >= 0 && yy < 300) near |= lit[yy * 400 + xx];
        }
      if (!near && g > 30) bad++;           /* the glow alone is 0.08 * 255 = 20 */
    }
  return bad;
}

/* Render the final look of SCENE at scale s to path (the reference picture). */
static void render_ref(const char *path, int s)
{
  char sc[8];
  snprintf(sc, sizeof sc, "%d", s);
  char *argv[] = { (char *)tube74(), "render", SCENE, "--look", "glow", "--scale", sc,
                   "-o", (char *)path, NULL };
  assert_int_equal(run(argv, NULL, NULL, NULL), 0);
}

/* ---- the movie --------------------------------------------------------------------- */

static void test_movie(void **state)
{
  (void)state;
  char movie[128], stats[128], pbm[128], out[128], errf[128], ref[128], frame[160];
  in_dir(movie, sizeof movie, "m.png");
  char *argv[] = { (char *)tube74(), "play", SCENE, "--movie", movie, "--scale", "1",
                   "--fps", "2", "--stats", in_dir(stats, sizeof stats, "s.json"),
                   "--dump", NULL, NULL };
  char dump[160];
  snprintf(dump, sizeof dump, "tube=%s", in_dir(pbm, sizeof pbm, "t.pbm"));
  argv[12] = dump;
  /* no display at all: the movie needs none */
  assert_int_equal(run(argv, in_dir(out, sizeof out, "out.txt"), in_dir(errf, sizeof errf, "err.txt"), ""), 0);
  char *o = slurp(out), *js = slurp(stats);
  assert_non_null(o);
  assert_non_null(js);
  long n = 0;
  const char *w = strstr(o, "wrote ");
  assert_non_null(w);
  n = strtol(w + 6, NULL, 10);
  /* frames every --speed / --fps = 0.5 s of 1974 time, until the last dot's flash is
     over (flash_s = 1 s after the last dot, which is written by total_1974_seconds) */
  char *tt = strstr(js, "\"total_1974_seconds\":");
  assert_non_null(tt);
  double total = strtod(tt + 21, NULL);
  assert_true(total > 0.5);
  long want = (long)ceil((total + 1.0) / 0.5) + 1;
  assert_true(n >= want - 1 && n <= want);
  for (long k = 1; k <= n; k++) {
    snprintf(frame, sizeof frame, "%s/m-%04ld.png", g_dir, k);
    assert_int_equal(access(frame, R_OK), 0);
  }
  snprintf(frame, sizeof frame, "%s/m-%04ld.png", g_dir, n + 1);
  assert_int_equal(access(frame, F_OK), -1);

  /* the first frame: the bare face, flood glow everywhere */
  struct rgb first, mid, last, r;
  snprintf(frame, sizeof frame, "%s/m-0001.png", g_dir);
  assert_int_equal(read_png(frame, &first), 0);
  assert_int_equal(first.w, 400);
  assert_int_equal(first.h, 300);
  for (int k = 0; k < 400 * 300; k++) assert_int_equal(first.px[3 * k + 1], first.px[1]);
  assert_true(first.px[1] > 0 && first.px[1] < 40);
  /* the last frame is the final picture, exactly */
  snprintf(frame, sizeof frame, "%s/m-%04ld.png", g_dir, n);
  assert_int_equal(read_png(frame, &last), 0);
  render_ref(in_dir(ref, sizeof ref, "ref1.png"), 1);
  assert_int_equal(read_png(ref, &r), 0);
  assert_memory_equal(last.px, r.px, (size_t)400 * 300 * 3);
  /* a middle frame is partly built: more light than the first, less than the last (the
     frame at three quarters of the 1974 time: later ones still show the writing flash) */
  snprintf(frame, sizeof frame, "%s/m-%04ld.png", g_dir, (long)(0.75 * total / 0.5) + 1);
  assert_int_equal(read_png(frame, &mid), 0);
  long s0 = 0, s1 = 0, s2 = 0;
  for (int k = 0; k < 400 * 300; k++) { s0 += first.px[3 * k + 1]; s1 += mid.px[3 * k + 1]; s2 += last.px[3 * k + 1]; }
  assert_true(s0 < s1 && s1 < s2);
  /* the stored dots are lit in the final frame */
  uint8_t *lit = malloc(400 * 300);
  assert_int_equal(read_pbm(pbm, lit), 0);
  int nlit, bad = check_dots(&last, 1, lit, &nlit);
  assert_true(nlit > 1000);
  assert_int_equal(bad, 0);
  free(lit);
  free(first.px); free(mid.px); free(last.px); free(r.px);
  free(o);
  free(js);
}

static void test_no_display(void **state)
{
  (void)state;
  char errf[128];
  char *argv[] = { (char *)tube74(), "play", SCENE, NULL };
  assert_int_equal(run(argv, NULL, in_dir(errf, sizeof errf, "nd.txt"), ""), 4);
  char *e = slurp(errf);
  assert_non_null(e);
  assert_non_null(strstr(e, "no display"));
  assert_non_null(strstr(e, "--movie"));
  free(e);
}

/* ---- a real X server ---------------------------------------------------------------- */

/* Xlib, loaded at run time. */
struct xlib {
  void *so;
  Display *(*open)(const char *);
  int (*close)(Display *);
  Window (*root)(Display *);
  Status (*query_tree)(Display *, Window, Window *, Window *, Window **, unsigned *);
  Status (*fetch_name)(Display *, Window, char **);
  int (*xfree)(void *);
  Status (*attrs)(Display *, Window, XWindowAttributes *);
  XImage *(*get_image)(Display *, Drawable, int, int, unsigned, unsigned, unsigned long, int);
  KeyCode (*keycode)(Display *, KeySym);
  int (*flush)(Display *);
  void *tst;                        /* libXtst, for pressing keys (optional) */
  int (*fake_key)(Display *, unsigned, int, unsigned long);
};

static int xlib_load(struct xlib *x)
{
  memset(x, 0, sizeof *x);
  x->so = dlopen("libX11.so.6", RTLD_NOW);
  if (!x->so) return -1;
#define SYM(f, name) (*(void **)(&x->f) = dlsym(x->so, name))
  if (!SYM(open, "XOpenDisplay") || !SYM(close, "XCloseDisplay") ||
      !SYM(root, "XDefaultRootWindow") || !SYM(query_tree, "XQueryTree") ||
      !SYM(fetch_name, "XFetchName") || !SYM(xfree, "XFree") ||
      !SYM(attrs, "XGetWindowAttributes") || !SYM(get_image, "XGetImage") ||
      !SYM(keycode, "XKeysymToKeycode") || !SYM(flush, "XFlush")) return -1;
  x->tst = dlopen("libXtst.so.6", RTLD_NOW);
  if (x->tst && !(*(void **)(&x->fake_key) = dlsym(x->tst, "XTestFakeKeyEvent"))) {
    dlclose(x->tst);
    x->tst = NULL;
  }
#undef SYM
  return 0;
}

/* A mapped top-level window whose title starts with "tube74 play": its geometry. */
static int find_window(struct xlib *x, Display *d, XWindowAttributes *out)
{
  Window root = x->root(d), r, parent, *kids = NULL;
  unsigned n = 0;
  int found = 0;
  if (!x->query_tree(d, root, &r, &parent, &kids, &n)) return 0;
  for (unsigned k = 0; k < n && !found; k++) {
    char *name = NULL;
    XWindowAttributes a;
    if (!x->attrs(d, kids[k], &a) || a.map_state != IsViewable) continue;
    if (x->fetch_name(d, kids[k], &name) && name) {
      if (!strncmp(name, "tube74 play", 11)) { *out = a; found = 1; }
      x->xfree(name);
    }
  }
  if (kids) x->xfree(kids);
  return found;
}

/* The server's pixels of root rectangle (x, y, w, h) as RGB. */
static int grab(struct xlib *x, Display *d, int x0, int y0, int w, int h, struct rgb *p)
{
  XImage *im = x->get_image(d, x->root(d), x0, y0, (unsigned)w, (unsigned)h, AllPlanes, ZPixmap);
  if (!im) return -1;
  p->w = w;
  p->h = h;
  p->px = malloc((size_t)w * h * 3);
  unsigned long m[3] = { im->red_mask, im->green_mask, im->blue_mask };
  int sh[3];
  for (int c = 0; c < 3; c++) { sh[c] = 0; while (m[c] && !((m[c] >> sh[c]) & 1)) sh[c]++; }
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      unsigned long v = XGetPixel(im, i, j);
      for (int c = 0; c < 3; c++) p->px[3 * ((size_t)j * w + i) + c] = (uint8_t)((v & m[c]) >> sh[c]);
    }
  XDestroyImage(im);
  return 0;
}

static int g_have_xvfb;             /* Xvfb found on PATH */

/* An Xvfb server on a free display number, and a connection to it. */
struct xserver {
  struct xlib x;
  pid_t pid;
  char disp[16];
  Display *d;
};

static void xserver_start(struct xserver *xs)
{
  assert_int_equal(xlib_load(&xs->x), 0);
  int num = -1;
  char sock[64], lock[64];
  for (int k = 99; k < 160 && num < 0; k++) {
    snprintf(sock, sizeof sock, "/tmp/.X11-unix/X%d", k);
    snprintf(lock, sizeof lock, "/tmp/.X%d-lock", k);
    if (access(sock, F_OK) != 0 && access(lock, F_OK) != 0) num = k;
  }
  assert_true(num >= 0);
  snprintf(xs->disp, sizeof xs->disp, ":%d", num);
  char *xargv[] = { "Xvfb", xs->disp, "-screen", "0", "1024x768x24", "-nolisten", "tcp", NULL };
  xs->pid = spawn(xargv, NULL, NULL, NULL);
  int up = 0;
  for (int k = 0; k < 500 && !up; k++) { up = access(sock, F_OK) == 0; if (!up) sleep_s(0.02); }
  assert_true(up);
  sleep_s(0.2);
  xs->d = xs->x.open(xs->disp);
  assert_non_null(xs->d);
}

static void xserver_stop(struct xserver *xs)
{
  if (xs->d) xs->x.close(xs->d);
  kill(xs->pid, SIGTERM);
  wait_for(xs->pid, 5);
  if (xs->x.tst) dlclose(xs->x.tst);
  dlclose(xs->x.so);
}

/* Wait for play's window; its attributes. */
static void await_window(struct xserver *xs, XWindowAttributes *a)
{
  memset(a, 0, sizeof *a);
  int seen = 0;
  for (int k = 0; k < 500 && !seen; k++) { seen = find_window(&xs->x, xs->d, a); if (!seen) sleep_s(0.02); }
  assert_true(seen);
}

static void test_xvfb_window(void **state)
{
  (void)state;
  if (!g_have_xvfb) { skip(); return; }
  struct xserver xs;
  xserver_start(&xs);
  struct xlib x = xs.x;
  Display *d = xs.d;
  const char *disp = xs.disp;
  char shot[128], pbm[128], ref[128], errf[128], dump[160];
  in_dir(shot, sizeof shot, "shot.png");
  snprintf(dump, sizeof dump, "tube=%s", in_dir(pbm, sizeof pbm, "tx.pbm"));
  char *pargv[] = { (char *)tube74(), "play", SCENE, "--speed", "1000", "--scale", "2",
                    "--quit-after", "2", "--screenshot", shot, "--dump", dump, NULL };
  pid_t ppid = spawn(pargv, NULL, in_dir(errf, sizeof errf, "play.txt"), disp);
  /* the window appears; the picture (about 4 s of 1974 time at x1000) is soon complete */
  XWindowAttributes a;
  await_window(&xs, &a);
  assert_int_equal(a.width, 800);
  assert_int_equal(a.height, 600 + 28);
  sleep_s(0.8);
  struct rgb server;
  int grabbed = grab(&x, d, a.x, a.y, 800, 600, &server);
  int rc = wait_for(ppid, 20);
  xserver_stop(&xs);
  assert_int_equal(grabbed, 0);
  assert_int_equal(rc, 0);

  /* the window's own screenshot: the face is the final picture, exactly */
  struct rgb s, r;
  assert_int_equal(read_png(shot, &s), 0);
  assert_int_equal(s.w, 800);
  assert_int_equal(s.h, 628);
  render_ref(in_dir(ref, sizeof ref, "ref2.png"), 2);
  assert_int_equal(read_png(ref, &r), 0);
  assert_memory_equal(s.px, r.px, (size_t)800 * 600 * 3);
  /* the clock strip under the face has something drawn in it (the digits) */
  long strip = 0;
  for (size_t k = (size_t)800 * 600; k < (size_t)800 * 628; k++) strip += s.px[3 * k + 1];
  assert_true(strip > 0);
  /* what the X server showed is the same picture */
  long diff = 0;
  for (size_t k = 0; k < (size_t)800 * 600 * 3; k++) diff += abs((int)server.px[k] - (int)r.px[k]);
  assert_true(diff <= (long)800 * 600 / 100);        /* at most a stray pixel or two */
  /* and the stored dots are bright at their places at scale 2 */
  uint8_t *lit = malloc(400 * 300);
  assert_int_equal(read_pbm(pbm, lit), 0);
  int nlit;
  assert_int_equal(check_dots(&server, 2, lit, &nlit), 0);
  assert_int_equal(check_dots(&s, 2, lit, &nlit), 0);
  assert_true(nlit > 1000);
  free(lit);
  free(s.px); free(r.px); free(server.px);
}

/* Press the `e` key in the window: the face flashes and is then bare (glow only). */
static void test_xvfb_erase_key(void **state)
{
  (void)state;
  if (!g_have_xvfb) { skip(); return; }
  struct xserver xs;
  xserver_start(&xs);
  if (!xs.x.tst) { xserver_stop(&xs); skip(); return; }   /* no XTest: cannot press keys */
  char shot[128], errf[128];
  in_dir(shot, sizeof shot, "erased.png");
  char *pargv[] = { (char *)tube74(), "play", SCENE, "--speed", "1000", "--scale", "1",
                    "--quit-after", "2.5", "--screenshot", shot, NULL };
  pid_t ppid = spawn(pargv, NULL, in_dir(errf, sizeof errf, "play2.txt"), xs.disp);
  XWindowAttributes a;
  await_window(&xs, &a);
  sleep_s(0.8);                                 /* the picture is complete */
  KeyCode e = xs.x.keycode(xs.d, XK_e);
  xs.x.fake_key(xs.d, e, True, CurrentTime);    /* the pointer-less server sends keys to */
  xs.x.fake_key(xs.d, e, False, CurrentTime);   /* the focused (only) window */
  xs.x.flush(xs.d);
  int rc = wait_for(ppid, 20);
  xserver_stop(&xs);
  assert_int_equal(rc, 0);
  struct rgb s;
  assert_int_equal(read_png(shot, &s), 0);
  assert_int_equal(s.w, 400);
  int g0 = s.px[1], lit = 0;
  for (size_t k = 0; k < (size_t)400 * 300; k++) lit += s.px[3 * k + 1] != g0;
  assert_true(g0 > 0 && g0 < 40);               /* the glow */
  assert_int_equal(lit, 0);                     /* nothing stored any more */
  free(s.px);
}

/* ---- main -------------------------------------------------------------------------- */

static int on_path(const char *prog)
{
  const char *path = getenv("PATH");
  if (!path) return 0;
  char buf[512];
  for (const char *p = path; *p; ) {
    const char *c = strchr(p, ':');
    size_t n = c ? (size_t)(c - p) : strlen(p);
    snprintf(buf, sizeof buf, "%.*s/%s", (int)n, p, prog);
    if (access(buf, X_OK) == 0) return 1;
    if (!c) break;
    p = c + 1;
  }
  return 0;
}

static void rm_dir(const char *dir)
{
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
}

int main(void)
{
  strcpy(g_dir, "/tmp/t74play.XXXXXX");
  if (!mkdtemp(g_dir)) { perror("mkdtemp"); return 1; }
  g_have_xvfb = on_path("Xvfb");
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_movie),
    cmocka_unit_test(test_no_display),
    cmocka_unit_test(test_xvfb_window),
    cmocka_unit_test(test_xvfb_erase_key),
  };
  int failed = cmocka_run_group_tests(tests, NULL, NULL);
  rm_dir(g_dir);
  if (failed) return failed;
  if (!g_have_xvfb) {
    printf("SKIP: Xvfb is not installed (Debian package xvfb): the window test did not run\n");
    return 77;
  }
  return 0;
}
