/*
** test_writethrough.c — write-through traces and erases of a Tek stream reach the look.
**
** A Tek stream drawn in write-through mode (ESC p) shows dim traces that the storage tube
** does not keep. This test takes a scene through `tube74 tek`, switches the stream's
** stored beam (ESC `) to write-through (ESC p), reads it back with `render --look glow`,
** and checks that nothing was stored while the most recently written dots glow on the
** face; and that an erase (ESC FF) at the end of a stored stream flashes the whole face
** while it erases and leaves it bare once it is over (when the picture is complete).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define SCENE "scenes/fig7a.s74"

static const char *tube74(void)
{
  const char *t = getenv("TUBE74");
  return t && *t ? t : "./tube74";
}

/* run argv with stdout to `out` (NULL: /dev/null); exit status */
static int run(char *const argv[], const char *out)
{
  pid_t pid = fork();
  if (pid == 0) {
    FILE *f = freopen(out ? out : "/dev/null", "w", stdout);
    if (!f) _exit(127);
    execvp(argv[0], argv);
    _exit(127);
  }
  int st;
  if (pid < 0 || waitpid(pid, &st, 0) != pid || !WIFEXITED(st)) return -1;
  return WEXITSTATUS(st);
}

static uint8_t *slurp(const char *path, size_t *n)
{
  *n = 0;
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  uint8_t *b = malloc(1 << 22);
  *n = b ? fread(b, 1, 1 << 22, f) : 0;
  fclose(f);
  return b;
}

/* green channel of an RGB(A) PNG, row 0 at the top */
static uint8_t *read_green(const char *path, int *w, int *h)
{
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path)) return NULL;
  img.format = PNG_FORMAT_RGB;
  uint8_t *rgb = malloc(PNG_IMAGE_SIZE(img));
  if (!rgb || !png_image_finish_read(&img, NULL, rgb, 0, NULL)) { free(rgb); return NULL; }
  *w = (int)img.width;
  *h = (int)img.height;
  uint8_t *g = malloc((size_t)*w * (size_t)*h);
  for (size_t k = 0; k < (size_t)*w * (size_t)*h; k++) g[k] = rgb[3 * k + 1];
  free(rgb);
  return g;
}

struct paths { char dir[64], tek[96], wt[96], png[96], pbm[96], pts[96]; };

static void make_paths(struct paths *p)
{
  strcpy(p->dir, "/tmp/tube74-wt-XXXXXX");
  assert_non_null(mkdtemp(p->dir));
  snprintf(p->tek, sizeof p->tek, "%s/a.tek", p->dir);
  snprintf(p->wt, sizeof p->wt, "%s/wt.tek", p->dir);
  snprintf(p->png, sizeof p->png, "%s/wt.png", p->dir);
  snprintf(p->pbm, sizeof p->pbm, "%s/wt.pbm", p->dir);
  snprintf(p->pts, sizeof p->pts, "%s/pts.txt", p->dir);
}

static void drop_paths(struct paths *p)
{
  unlink(p->tek); unlink(p->wt); unlink(p->png); unlink(p->pbm); unlink(p->pts);
  rmdir(p->dir);
}

/* The whole stream in write-through: nothing stored, the newest dots glow. */
static void test_writethrough_shows_but_does_not_store(void **state)
{
  (void)state;
  if (access(tube74(), X_OK) != 0) skip();
  struct paths p;
  make_paths(&p);
  char *tek[] = { (char *)tube74(), "tek", SCENE, "-o", p.tek, NULL };
  assert_int_equal(run(tek, NULL), 0);
  char *pts[] = { (char *)tube74(), "render", SCENE, "--dump", NULL, NULL };
  char dump[128];
  snprintf(dump, sizeof dump, "points=%s", p.pts);
  pts[4] = dump;
  assert_int_equal(run(pts, NULL), 0);

  size_t n;
  uint8_t *b = slurp(p.tek, &n);
  assert_non_null(b);
  int switched = 0;
  for (size_t k = 0; k + 1 < n; k++)
    if (b[k] == 0x1B && b[k + 1] == 0x60) { b[k + 1] = 0x70; switched++; }  /* ESC ` -> ESC p */
  assert_true(switched >= 1);
  FILE *f = fopen(p.wt, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(b, 1, n, f), n);
  fclose(f);
  free(b);

  char pngarg[128], pbmarg[128];
  snprintf(pbmarg, sizeof pbmarg, "tube=%s", p.pbm);
  snprintf(pngarg, sizeof pngarg, "%s", p.png);
  char *rd[] = { (char *)tube74(), "render", p.wt, "--look", "glow", "--scale", "1",
                 "-o", pngarg, "--dump", pbmarg, NULL };
  assert_int_equal(run(rd, NULL), 0);

  /* nothing stored: the PBM is all zero bits */
  b = slurp(p.pbm, &n);
  assert_non_null(b);
  size_t hdr = (size_t)(strstr((char *)b, "300\n") - (char *)b) + 4;
  for (size_t k = hdr; k < n; k++) assert_int_equal(b[k], 0);
  free(b);

  /* the last dots written glow above the bare face; a far corner does not */
  int w, h;
  uint8_t *g = read_green(p.png, &w, &h);
  assert_non_null(g);
  assert_int_equal(w, 400);
  assert_int_equal(h, 300);
  f = fopen(p.pts, "r");
  assert_non_null(f);
  int xs[60000], ys[60000], np = 0;
  while (np < 60000 && fscanf(f, "%d %d", &xs[np], &ys[np]) == 2) np++;
  fclose(f);
  assert_true(np > 100);
  int bare = g[(size_t)(299 - 0) * 400 + 0];             /* corner (0, 0): never drawn */
  int brighter = 0;
  for (int k = np - 50; k < np; k++)
    if (g[(size_t)(299 - ys[k]) * 400 + (size_t)xs[k]] > bare + 20) brighter++;
  assert_true(brighter >= 40);
  free(g);
  drop_paths(&p);
}

/* An erase at the end of a stored stream: the face flashes, the dots are gone. */
static void test_erase_flashes_the_look(void **state)
{
  (void)state;
  if (access(tube74(), X_OK) != 0) skip();
  struct paths p;
  make_paths(&p);
  char *tek[] = { (char *)tube74(), "tek", SCENE, "-o", p.tek, NULL };
  assert_int_equal(run(tek, NULL), 0);
  size_t n;
  uint8_t *b = slurp(p.tek, &n);
  assert_non_null(b);
  FILE *f = fopen(p.wt, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(b, 1, n, f), n);
  fputs("\x1b\x0c", f);                                  /* ESC FF at the end */
  fclose(f);
  free(b);
  char pbmarg[128];
  snprintf(pbmarg, sizeof pbmarg, "tube=%s", p.pbm);
  /* the picture is complete when the erase is over (the tube stores nothing meanwhile):
     --look-at -0.2 is 0.2 s before that, inside the 0.45 s erase */
  char *rd[] = { (char *)tube74(), "render", p.wt, "--look", "glow", "--scale", "1",
                 "-o", p.png, "--dump", pbmarg, "--look-at", "-0.2", NULL };
  assert_int_equal(run(rd, NULL), 0);
  int w, h;
  uint8_t *g = read_green(p.png, &w, &h);
  assert_non_null(g);
  /* during the erase the whole face is lit by the flash, evenly: the corner that was
     never drawn is as bright as the middle */
  int corner = g[0], middle = g[(size_t)150 * 400 + 200];
  assert_true(corner > 60);
  assert_true(abs(corner - middle) < 30);
  free(g);
  /* by default the face as it is once the erase is over: dark and bare, every dot gone */
  char *rd2[] = { (char *)tube74(), "render", p.wt, "--look", "glow", "--scale", "1",
                  "-o", p.png, NULL };
  assert_int_equal(run(rd2, NULL), 0);
  g = read_green(p.png, &w, &h);
  assert_non_null(g);
  int lo = 255, hi = 0;
  for (size_t k = 0; k < (size_t)w * (size_t)h; k++) {
    if (g[k] < lo) lo = g[k];
    if (g[k] > hi) hi = g[k];
  }
  assert_true(hi < 40);
  assert_true(hi - lo <= 1);
  free(g);
  drop_paths(&p);
}

int main(void)
{
  if (access(tube74(), X_OK) != 0) {
    printf("skip: %s is not an executable program\n", tube74());
    return 77;
  }
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_writethrough_shows_but_does_not_store),
    cmocka_unit_test(test_erase_flashes_the_look),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
