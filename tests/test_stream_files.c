/*
** test_stream_files.c — `tube74 stream --to FILE`, `--dry-run` and `--svg FILE`: the device's
** own commands in a file, the pen / beam path as SVG, the summary and the time estimate
** (cli/cmd_stream.c, the display/usb profiles; issue 20).
**
** This file contains code to check, with readers written from the devices' documents
** (tests/devices/readers.c, and the ILDA and EBB readers here), that:
**   HP-GL    the file parses back (IN, SP, PU, PD, PA) into exactly the dots `tube74 render
**            --dump points` stores, each once, every point inside the 7475A's A4 hard-clip
**            limits, on the grid derived by hand below; the pen is put away at the end;
**   EBB      the commands (SC, EM, SP, SM; motors mixed as the AxiDraw's: a = dX + dY,
**            b = dX - dY) draw the same dots, end with the pen up at home and EM,0,0, and
**            their durations add up to the summary's estimate;
**   ILDA     the .ild file has valid section headers (ILDA, format 1, names, record counts
**            matching the bytes, frame numbers 0..n-1, the total in every header, the last-
**            point bit on each frame's last record only, an end header of 0 records), and
**            its lit points are the picture's dots;
**   Tek      the stream decodes (GS, FS, ESC FF) to the dots' addresses;
**   SVG      every preview is well-formed XML (xmllint --noout when installed, and a tag
**            balance check here), of the device's area;
**   estimate against hand computations from the documented rates (hpgl: pen speeds and
**            lift time; ebb: the AxiDraw ramps and servo waits of docs/usb.md), and fig5 (41,435
**            dots) at about 4 hours on an AxiDraw drawing each dot with its own lift;
**   bad input  no file is created (or changed) when the scene is bad or the options clash;
**            exit statuses 2 / 4 as the contract says.
** A standalone cmocka program run from the repository root; it runs $TUBE74 (./tube74).
*/
#define _DEFAULT_SOURCE
#define _XOPEN_SOURCE 700      /* posix_openpt, grantpt, unlockpt, ptsname */

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/devices/readers.c"

#include "display/sink.h"
#include "display/usb/stream.h"
#include "display/usb/usb.h"

#define SCENE "tests/data/usb/small.s74"

struct fx {
  char *dir;
  struct dev_dots ref;
};

static struct fx *F(void **state) { return *state; }

static char *path(struct fx *f, const char *name)
{
  static char buf[4][600];
  static int k;
  k = (k + 1) % 4;
  snprintf(buf[k], sizeof buf[k], "%s/%s", f->dir, name);
  return buf[k];
}

/* The HP 7475A's A4 hard-clip limits (its manual: 0..11040 x 0..7721 plotter units of
** 0.025 mm) less the 5 mm margin of docs/usb.md (200 units) leave 10640 x 7321 units; the
** largest whole pitch for 400 x 300 dots: min(10640/400, 7321/300) = min(26, 24) = 24 units;
** centred: ox = 200 + (10640 - 400*24)/2 = 720, oy = 200 + (7321 - 300*24)/2 = 260. */
#define HP_PITCH 24
#define HP_OX    720
#define HP_OY    260

/* ---- HP-GL ------------------------------------------------------------------------- */

static void test_hpgl_file_parses_back(void **state)
{
  struct fx *f = F(state);
  char *out = path(f, "small.hpgl"), *sum = path(f, "summary.txt");
  char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "hpgl", "--to", out, NULL };
  assert_int_equal(dev_run(argv, sum, NULL), 0);
  size_t n;
  unsigned char *b = dev_slurp(out, &n);
  assert_non_null(b);
  assert_true(n > 0);
  assert_memory_equal(b, "IN;", 3);             /* the plotter is initialised first */
  struct hpgl_reader r;
  memset(&r, 0, sizeof r);
  hpgl_reader_init(&r, HP_PITCH, HP_OX, HP_OY, 0, 0, 11040, 7721);
  hpgl_feed(&r, b, n);
  assert_int_equal(r.bad, 0);
  assert_int_equal(r.nins, 0);                  /* nothing after the last `;` */
  assert_int_equal(r.off_grid, 0);
  assert_int_equal(r.clipped, 0);
  assert_int_equal(r.diagonal, 0);
  assert_int_equal(r.inits, 1);
  assert_false(r.down);
  assert_string_equal(r.last, "SP");            /* SP0 last: the pen back in its stall */
  assert_int_equal(r.pen, 0);
  assert_int_equal(r.marks.n, f->ref.n);
  assert_true(dev_same_set(&r.marks, &f->ref));
  /* the summary is on stdout (the file is not) and names the file and the estimate */
  unsigned char *s = dev_slurp(sum, NULL);
  assert_non_null(strstr((char *)s, "estimated time"));
  assert_non_null(strstr((char *)s, out));
  free(s);
  /* the SVG preview beside it (--to FILE brings FILE.svg) */
  char svg[700];
  snprintf(svg, sizeof svg, "%s.svg", out);
  assert_true(dev_exists(svg));
  free(b);
  free(r.marks.xy);
}

/* --to - : the HP-GL on stdout, the summary on stderr; the same bytes as a file. */
static void test_hpgl_stdout(void **state)
{
  struct fx *f = F(state);
  char *out = path(f, "stdout.hpgl"), *errf = path(f, "stderr.txt"), *file = path(f, "small.hpgl");
  char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "hpgl", "--to", "-", NULL };
  assert_int_equal(dev_run(argv, out, errf), 0);
  size_t n1, n2;
  unsigned char *a = dev_slurp(out, &n1), *b = dev_slurp(file, &n2);
  assert_non_null(b);                           /* (written by the test before) */
  assert_int_equal(n1, n2);
  assert_memory_equal(a, b, n1);
  unsigned char *e = dev_slurp(errf, NULL);
  assert_non_null(strstr((char *)e, "estimated time"));
  free(a);
  free(b);
  free(e);
}

/* ---- EBB --------------------------------------------------------------------------- */

/* The EBB's geometry by hand (docs/usb.md): 80 steps a mm (2032 steps/inch at 1/16 step),
** the A4 area 10 + 277 mm x 10 + 190 mm from the home corner: 22160 x 15200 steps from
** (800, 800); pitch min(22160/400, 15200/300) = min(55, 50) = 50 steps; ox = 800 + (22160 -
** 20000)/2 = 1880, oy = 800 + (15200 - 15000)/2 = 900; tube row y is Y = oy + (299 - y) 50. */
#define EB_PITCH 50
#define EB_OX    1880
#define EB_OY    900

struct ebb_read {
  long X, Y;
  int down, motors, bad, off_grid, ended_home, em_off_last;
  double ms;                    /* SM and SP durations added */
  struct dev_dots marks;
};

static void ebb_mark(struct ebb_read *e)
{
  long dx = e->X - EB_OX, dy = e->Y - EB_OY;
  if (dx < 0 || dy < 0 || dx % EB_PITCH || dy % EB_PITCH) { e->off_grid++; return; }
  dev_dots_add(&e->marks, (int)(dx / EB_PITCH), 299 - (int)(dy / EB_PITCH));
}

/* The EBB command reference: commands end in CR; SP,value[,duration[,pin]]: 0 lowers,
** 1 raises, duration ms before the next motion; SM,duration,steps1,steps2; EM,e1,e2 (0
** disables); SC,... configuration. */
static void ebb_parse(struct ebb_read *e, char *text)
{
  for (char *c = strtok(text, "\r"); c; c = strtok(NULL, "\r")) {
    long v[4] = { 0, 0, 0, 0 };
    int nv = sscanf(c + 3, "%ld,%ld,%ld,%ld", &v[0], &v[1], &v[2], &v[3]);
    e->em_off_last = 0;
    if (!strncmp(c, "SC,", 3)) continue;
    if (!strncmp(c, "EM,", 3)) {
      e->motors = v[0] != 0;
      e->em_off_last = v[0] == 0 && v[1] == 0;
    } else if (!strncmp(c, "SP,", 3) && nv >= 2) {
      if (v[0] == 0 && !e->down) ebb_mark(e);   /* the pen touches the paper */
      e->down = v[0] == 0;
      e->ms += (double)v[1];
    } else if (!strncmp(c, "SM,", 3) && nv == 3) {
      if (!e->motors) e->bad++;
      if ((v[1] + v[2]) % 2) { e->bad++; continue; }
      long dX = (v[1] + v[2]) / 2, dY = (v[1] - v[2]) / 2;   /* a = dX + dY, b = dX - dY */
      long x1 = e->X + dX, y1 = e->Y + dY;
      if (e->down) {
        if (dY) { e->bad++; }                   /* drawn runs lie on rows */
        long step = dX > 0 ? 1 : -1;            /* every grid point passed */
        for (long x = e->X + step; dX && x != x1 + step; x += step)
          if ((x - EB_OX) % EB_PITCH == 0) { e->X = x; ebb_mark(e); }
      }
      e->X = x1;
      e->Y = y1;
      e->ms += (double)v[0];
    } else {
      e->bad++;
    }
  }
  e->ended_home = e->X == 0 && e->Y == 0 && !e->down;
}

/* The estimated seconds printed in a summary ("... (N s) ..."). */
static double summary_seconds(const char *s)
{
  const char *p = strstr(s, "estimated time");
  if (!p) return -1;
  p = strchr(p, '(');
  return p ? atof(p + 1) : -1;
}

static void test_ebb_file(void **state)
{
  struct fx *f = F(state);
  char *out = path(f, "small.ebb"), *sum = path(f, "ebb-summary.txt");
  char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "ebb", "--to", out, NULL };
  assert_int_equal(dev_run(argv, sum, NULL), 0);
  unsigned char *b = dev_slurp(out, NULL);
  assert_non_null(b);
  struct ebb_read e;
  memset(&e, 0, sizeof e);
  ebb_parse(&e, (char *)b);
  assert_int_equal(e.bad, 0);
  assert_int_equal(e.off_grid, 0);
  assert_true(e.ended_home);
  assert_true(e.em_off_last);
  assert_true(dev_same_set(&e.marks, &f->ref));
  unsigned char *s = dev_slurp(sum, NULL);
  double est = summary_seconds((char *)s);
  /* the estimate is what the board's commands take, run one after the other */
  assert_true(fabs(est - e.ms / 1000.0) <= 1.0);
  free(s);
  free(b);
  free(e.marks.xy);
}

/* ---- ILDA -------------------------------------------------------------------------- */

static unsigned rd16(const unsigned char *p) { return (unsigned)p[0] << 8 | p[1]; }

static void test_ilda_file(void **state)
{
  struct fx *f = F(state);
  char *out = path(f, "small.ild");
  char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "helios", "--to", out,
                   "--no-progress", NULL };
  assert_int_equal(dev_run(argv, "/dev/null", NULL), 0);
  size_t n;
  unsigned char *b = dev_slurp(out, &n);
  assert_non_null(b);
  struct dev_dots lit = { 0, 0, NULL };
  size_t at = 0;
  unsigned frames = 0, total = 0;
  int ended = 0;
  while (at < n) {
    assert_true(at + 32 <= n);
    const unsigned char *h = b + at;
    assert_memory_equal(h, "ILDA", 4);
    assert_true(h[4] == 0 && h[5] == 0 && h[6] == 0 && h[31] == 0);   /* reserved */
    assert_int_equal(h[7], 1);                  /* format 1: 2D, indexed colour */
    assert_memory_equal(h + 8, "tube74\0\0", 8);
    unsigned recs = rd16(h + 24), number = rd16(h + 26), tot = rd16(h + 28);
    if (frames == 0) total = tot;
    assert_int_equal(tot, total);               /* the same total in every header */
    at += 32;
    if (recs == 0) { ended = 1; break; }        /* the end header */
    assert_int_equal(number, frames);
    assert_true(at + (size_t)recs * 6 <= n);
    for (unsigned k = 0; k < recs; k++) {
      const unsigned char *p = b + at + (size_t)k * 6;
      int16_t X = (int16_t)rd16(p), Y = (int16_t)rd16(p + 2);
      int last = (p[4] & 0x80) != 0, blank = (p[4] & 0x40) != 0;
      assert_int_equal(last, k == recs - 1);
      assert_int_equal(p[4] & 0x3F, 0);
      if (blank) continue;
      assert_int_equal(p[5], 24);               /* the default palette's green */
      /* ILDA -32768..32767 is the DAC's 0..4095 (x 16); dot x is DAC 48 + 10 x, dot y
         548 + 10 y (docs/usb.md, helios) */
      int dx = X / 16 + 2048 - 48, dy = Y / 16 + 2048 - 548;
      assert_int_equal(X % 16, 0);
      assert_int_equal(dx % 10, 0);
      assert_int_equal(dy % 10, 0);
      dev_dots_add(&lit, dx / 10, dy / 10);
    }
    at += (size_t)recs * 6;
    frames++;
  }
  assert_true(ended);
  assert_int_equal(at, n);                      /* nothing after the end header */
  assert_int_equal(total, frames);
  assert_true(frames >= 2);                     /* 4,432 dots do not fit one frame */
  /* dwell points repeat a dot: each dot lit at least once, nothing else lit */
  qsort(lit.xy, (size_t)lit.n, sizeof *lit.xy, dev_cmp);
  int u = 0;
  for (int k = 0; k < lit.n; k++)
    if (!u || dev_cmp(lit.xy[u - 1], lit.xy[k])) { lit.xy[u][0] = lit.xy[k][0]; lit.xy[u][1] = lit.xy[k][1]; u++; }
  lit.n = u;
  assert_true(dev_same_set(&lit, &f->ref));
  free(lit.xy);
  free(b);
}

/* ---- Tek --------------------------------------------------------------------------- */

static void test_tek_file(void **state)
{
  struct fx *f = F(state);
  char *out = path(f, "small.tek");
  char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "tek", "--to", out, NULL };
  assert_int_equal(dev_run(argv, "/dev/null", NULL), 0);
  size_t n;
  unsigned char *b = dev_slurp(out, &n);
  assert_non_null(b);
  struct plot10 d;
  memset(&d, 0, sizeof d);
  plot10_init(&d);
  for (size_t k = 0; k < n; k++) plot10_byte(&d, b[k]);
  assert_int_equal(d.bad, 0);
  assert_int_equal(d.erases, 1);
  assert_int_equal(b[0], 0x1B);                 /* ESC FF first: a clean screen */
  assert_int_equal(b[1], 0x0C);
  assert_int_equal(b[n - 1], 0x1F);             /* US last: alpha mode */
  /* each dot at the centre of its 10.24 x 10.24 addresses (display/tek.h) */
  struct dev_dots want = { 0, 0, NULL };
  for (int k = 0; k < f->ref.n; k++)
    dev_dots_add(&want, (256 * f->ref.xy[k][0] + 128) / 25, (256 * f->ref.xy[k][1] + 128) / 25);
  assert_true(dev_same_set(&d.pts, &want));
  free(want.xy);
  free(d.pts.xy);
  free(b);
}

/* ---- SVG --------------------------------------------------------------------------- */

/* Well-formed enough: one root <svg>, every element closed in order, quotes balanced. */
static int svg_balanced(const char *s)
{
  char stack[16][32];
  int depth = 0, roots = 0;
  if (strncmp(s, "<?xml", 5)) return 0;
  s = strstr(s, "?>") + 2;
  while ((s = strchr(s, '<'))) {
    if (s[1] == '/') {
      char name[32];
      if (sscanf(s + 2, "%31[a-zA-Z]", name) != 1 || !depth || strcmp(stack[depth - 1], name)) return 0;
      depth--;
      s = strchr(s, '>');
      if (!s) return 0;
      continue;
    }
    char name[32];
    if (sscanf(s + 1, "%31[a-zA-Z]", name) != 1) return 0;
    const char *e = s + 1;
    int q = 0;
    while (*e && (q || *e != '>')) { if (*e == '"') q = !q; e++; }
    if (!*e) return 0;
    if (depth == 0) roots++;
    if (e[-1] != '/') {
      if (depth == 16) return 0;
      snprintf(stack[depth++], sizeof stack[0], "%s", name);
    }
    s = e;
  }
  return depth == 0 && roots == 1;
}

static int have_xmllint(void)
{
  return system("command -v xmllint >/dev/null 2>&1") == 0;
}

static void test_svg_previews(void **state)
{
  struct fx *f = F(state);
  static const char *const dev[4] = { "hpgl", "ebb", "helios", "tek" };
  static const char *const box[4] = { "viewBox=\"0 0 11040 7721\"", "viewBox=\"0 0 22960 16000\"",
                                      "viewBox=\"0 0 4095 4095\"", "viewBox=\"0 0 4095 3119\"" };
  for (int k = 0; k < 4; k++) {
    char name[32];
    snprintf(name, sizeof name, "%s.svg", dev[k]);
    char *svg = path(f, name);
    char *argv[] = { (char *)dev_tube74(), "stream", SCENE, "--device", (char *)dev[k],
                     "--dry-run", "--svg", svg, NULL };
    assert_int_equal(dev_run(argv, "/dev/null", NULL), 0);
    unsigned char *b = dev_slurp(svg, NULL);
    assert_non_null(b);
    assert_true(svg_balanced((char *)b));
    assert_non_null(strstr((char *)b, box[k]));  /* the device's area, in its units */
    assert_non_null(strstr((char *)b, "d=\"M"));   /* a drawn path */
    if (have_xmllint()) {
      char cmd[700];
      snprintf(cmd, sizeof cmd, "xmllint --noout '%s'", svg);
      assert_int_equal(system(cmd), 0);
    }
    free(b);
  }
  /* the tag check can fail */
  assert_false(svg_balanced("<?xml version=\"1.0\"?><svg><path d=\"M0 0\"></svg>"));
}

/* ---- estimates against hand computations -------------------------------------------- */

/* A file run of the library to nowhere with dots d: its result. */
static int lib_run(const struct usb_profile *p, const int (*d)[2], int n, const char *const *sets,
                   struct usb_stream_result *r)
{
  struct t74_error err = { T74_OK, "" };
  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.prof = p;
  o.match = p->match;
  usb_settings_default(&o.set, p);
  for (int k = 0; sets && sets[k]; k++)
    if (usb_settings_set(&o.set, p, sets[k], &err) != T74_OK) return err.status;
  o.repeat = 1;
  o.scene = "hand";
  o.kind = USB_LINK_FILE;
  o.result = r;
  o.t0 = usb_now();
  struct usb_stream *s;
  if (usb_stream_open(&s, &o, &err) != T74_OK) return err.status;
  struct sink k = usb_stream_sink(s);
  int st = T74_OK;
  for (int i = 0; i < n && st == T74_OK; i++) st = sink_point(&k, d[i][0], d[i][1]);
  if (st == T74_OK) st = sink_end(&k, &err);
  st = usb_stream_finish(s, st, &err);
  if (st) fprintf(stderr, "%s\n", err.msg);
  return st;
}

/* hpgl: three lone dots and a run of ten on row 150. The documented rates of the profile
** (docs/usb.md, --settings): pen up 500 mm/s, pen down 380 mm/s (the 7475A's 38 cm/s), 30 ms
** a pen lift or drop; 40 units a mm; the grid of HP_PITCH above. The pen starts at the
** origin and goes nearest-first: dots 10, 20, 30, then the run 40..49 as one stroke. */
static void test_estimate_hpgl_by_hand(void **state)
{
  (void)state;
  int d[13][2];
  int n = 0;
  for (int x = 10; x <= 30; x += 10) { d[n][0] = x; d[n][1] = 150; n++; }
  for (int x = 40; x <= 49; x++) { d[n][0] = x; d[n][1] = 150; n++; }
  struct usb_stream_result r;
  assert_int_equal(lib_run(&usb_profile_hpgl, d, n, NULL, &r), T74_OK);
  double X1 = HP_OX + 10 * HP_PITCH, Y = HP_OY + 150 * HP_PITCH;
  double up_mm = (hypot(X1, Y) + 3 * 10 * HP_PITCH) / 40.0;   /* to dot 10, then 3 hops of 10 */
  double down_mm = 9 * HP_PITCH / 40.0;                        /* the run, 40 to 49 */
  double hand = up_mm / 500.0 + 4 * 2 * 0.030 + down_mm / 380.0;
  assert_int_equal(r.dots, n);
  assert_int_equal(r.tally.strokes, 4);
  assert_true(fabs(r.tally.device_s - hand) < 1e-9);
  assert_true(fabs(usb_estimate_seconds(&r.tally) - hand) < 1e-9);
  assert_true(fabs(r.tally.up_mm - up_mm) < 1e-9);
}

/* A move of D steps from rest to rest, as docs/usb.md says the AxiDraw ramps it: trapezoid
** (triangle when too short to reach v) at speed v, acceleration a. */
static double ramp_time(double D, double v, double a)
{
  return D >= v * v / a ? D / v + v / a : 2 * sqrt(D / a);
}

/* ebb: five lone dots two apart on row 150. docs/usb.md: pen-up speed 150.6 mm/s, 1143 mm/s^2,
** 80 steps a mm; the pen raised in 130 ms and lowered in 146 ms at the defaults (the first
** raise, from the firmware's reset position, also 130 ms: 2 servo periods of 24 ms + 45 ms is
** less). Board time: raise at open; per dot the move, a lower and a raise; at the end the
** raise of close() and the move home. Each SM lasts whole ms: within 1 ms a move. */
static void test_estimate_ebb_by_hand(void **state)
{
  (void)state;
  int d[5][2];
  for (int k = 0; k < 5; k++) { d[k][0] = 100 + 2 * k; d[k][1] = 150; }
  struct usb_stream_result r;
  assert_int_equal(lib_run(&usb_profile_ebb, d, 5, NULL, &r), T74_OK);
  double v = 150.6 * 80, a = 1143 * 80;
  double X = EB_OX + 100 * EB_PITCH, Y = EB_OY + (299 - 150) * EB_PITCH;
  double hand = 0.130;                                          /* open: pen up */
  hand += ramp_time(hypot(X, Y), v, a) + 0.146 + 0.130;         /* home -> first dot */
  for (int k = 1; k < 5; k++) hand += ramp_time(2 * EB_PITCH, v, a) + 0.146 + 0.130;
  double Xl = X + 8 * EB_PITCH;
  hand += 0.130 + ramp_time(hypot(Xl, Y), v, a);                /* close: up, home */
  assert_true(fabs(r.tally.device_s - hand) < 6 * 0.001);
  printf("BENCH estimate ebb: 5 dots by hand %.4f s, the profile %.4f s\n", hand, r.tally.device_s);
}

/* tek: every byte at 9600 baud (10 bits a byte, 8N1) and the erase wait (1000 ms). */
static void test_estimate_tek_by_hand(void **state)
{
  (void)state;
  int d[3][2] = { { 0, 0 }, { 1, 0 }, { 200, 150 } };
  struct usb_stream_result r;
  assert_int_equal(lib_run(&usb_profile_tek, d, 3, NULL, &r), T74_OK);
  /* ESC FF, ESC ` GS FS, the first address whole (HiY Extra LoY HiX LoX = 5 bytes), the
     next one differs only in its Extra and LoX... : counted from the bytes the file holds */
  double hand = 1.0 + r.tally.bytes * 10.0 / 9600.0;
  assert_true(r.tally.bytes >= 2 + 4 + 5 + 2 + 2 + 1);
  assert_true(fabs(r.tally.device_s - hand) < 1e-9);
}

/* fig5: 41,435 dots. An AxiDraw drawing each dot with its own lift at the defaults
** (docs/usb.md: 2.8 dots/s on tiny.s74) needs about 41,435 / 2.8 s = 4.1 hours; the
** profile's estimate with runs=0 must agree within 15 %, and joining runs into strokes
** must make it shorter. */
static void test_estimate_fig5_axidraw(void **state)
{
  struct fx *f = F(state);
  char *s1 = path(f, "fig5-dots.txt"), *s2 = path(f, "fig5-runs.txt");
  char *argv1[] = { (char *)dev_tube74(), "stream", "scenes/fig5.s74", "--device", "ebb",
                    "--dry-run", "--set", "runs=0", NULL };
  char *argv2[] = { (char *)dev_tube74(), "stream", "scenes/fig5.s74", "--device", "ebb",
                    "--dry-run", NULL };
  assert_int_equal(dev_run(argv1, s1, NULL), 0);
  assert_int_equal(dev_run(argv2, s2, NULL), 0);
  unsigned char *a = dev_slurp(s1, NULL), *b = dev_slurp(s2, NULL);
  assert_non_null(strstr((char *)a, "41435 a pass"));
  double dots = summary_seconds((char *)a), runs = summary_seconds((char *)b);
  double hand = 41435 / 2.8;
  printf("BENCH estimate fig5 on an AxiDraw: a lift a dot %.0f s (%.2f h; by hand %.2f h), "
         "with strokes %.0f s (%.2f h)\n", dots, dots / 3600, hand / 3600, runs, runs / 3600);
  assert_true(fabs(dots - hand) < 0.15 * hand);
  assert_true(runs < dots);
  assert_non_null(strstr((char *)a, " h "));    /* printed in hours */
  free(a);
  free(b);
}

/* A long plot gets a warning before anything is sent, with the estimate; a board that
** never answers (a pty nobody reads) then fails with exit 4 and no --svg file. */
static void test_warning_before_long_plot(void **state)
{
  struct fx *f = F(state);
  int m = posix_openpt(O_RDWR | O_NOCTTY);
  assert_true(m >= 0);
  assert_int_equal(grantpt(m), 0);
  assert_int_equal(unlockpt(m), 0);
  char *slave = ptsname(m);
  char *errf = path(f, "long.txt"), *svg = path(f, "long.svg"), *save = path(f, "long.resume");
  char *argv[] = { (char *)dev_tube74(), "stream", "scenes/fig5.s74", "--device", "ebb",
                   "--serial", slave, "--set", "timeout_ms=200", "--set", "retries=0",
                   "--svg", svg, "--save", save, "--no-progress", NULL };
  assert_int_equal(dev_run(argv, "/dev/null", errf), 4);
  unsigned char *e = dev_slurp(errf, NULL);
  assert_non_null(strstr((char *)e, "41435 dots; about 2 h"));
  assert_non_null(strstr((char *)e, "warning: this plot will take about"));
  assert_non_null(strstr((char *)e, "did not answer"));
  assert_false(dev_exists(svg));
  free(e);
  close(m);
}

/* ---- bad input ---------------------------------------------------------------------- */

static void test_bad_input_no_file(void **state)
{
  struct fx *f = F(state);
  char *bad = path(f, "bad.s74"), *out = path(f, "bad.hpgl"), *svg = path(f, "bad.svg");
  FILE *s = fopen(bad, "w");
  fprintf(s, "view 0 0 -1000\nvertex 1 0 0\n");
  fclose(s);
  char *errf = path(f, "bad.txt");
  char *argv[] = { (char *)dev_tube74(), "stream", bad, "--device", "hpgl", "--to", out,
                   "--svg", svg, NULL };
  assert_int_equal(dev_run(argv, "/dev/null", errf), 2);
  assert_false(dev_exists(out));
  assert_false(dev_exists(svg));
  char beside[700];
  snprintf(beside, sizeof beside, "%s.svg", out);
  char *argv_b[] = { (char *)dev_tube74(), "stream", bad, "--device", "hpgl", "--to", out, NULL };
  assert_int_equal(dev_run(argv_b, "/dev/null", "/dev/null"), 2);
  assert_false(dev_exists(beside));
  unsigned char *e = dev_slurp(errf, NULL);
  assert_non_null(strstr((char *)e, "bad.s74:2:"));     /* FILE:LINE: message */
  free(e);
  /* an existing file is left as it was */
  s = fopen(out, "w");
  fprintf(s, "old");
  fclose(s);
  assert_int_equal(dev_run(argv, "/dev/null", "/dev/null"), 2);
  unsigned char *o = dev_slurp(out, NULL);
  assert_string_equal((char *)o, "old");
  free(o);
  /* usage clashes: exit 2, nothing written */
  unlink(out);
  char *a1[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "tek", NULL };
  char *a2[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "helios", "--serial",
                 "/dev/null", NULL };
  char *a3[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "hpgl", "--to", out,
                 "--serial", "/dev/null", NULL };
  char *a4[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "ebb", "--to", out,
                 "--repeat", "0", NULL };
  char *a5[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "tek", "--serial",
                 "/dev/null", "--baud", "1234", NULL };
  char *a6[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "hpgl", "--serial",
                 "/dev/null", "--flow", "maybe", NULL };
  assert_int_equal(dev_run(a1, "/dev/null", "/dev/null"), 2);
  assert_int_equal(dev_run(a2, "/dev/null", "/dev/null"), 2);
  assert_int_equal(dev_run(a3, "/dev/null", "/dev/null"), 2);
  assert_int_equal(dev_run(a4, "/dev/null", "/dev/null"), 2);
  assert_int_equal(dev_run(a5, "/dev/null", "/dev/null"), 2);
  assert_int_equal(dev_run(a6, "/dev/null", "/dev/null"), 2);
  assert_false(dev_exists(out));
  /* not a serial port: a device failure, exit 4 */
  char *a7[] = { (char *)dev_tube74(), "stream", SCENE, "--device", "tek", "--serial",
                 "/dev/null", "--no-estimate", NULL };
  assert_int_equal(dev_run(a7, "/dev/null", errf), 4);
  e = dev_slurp(errf, NULL);
  assert_non_null(strstr((char *)e, "/dev/null: not a serial port"));
  free(e);
}

static int setup(void **state)
{
  struct fx *f = calloc(1, sizeof *f);
  f->dir = dev_tmpdir();
  if (!f->dir || dev_reference(SCENE, f->dir, &f->ref) != 0 || f->ref.n == 0) {
    fprintf(stderr, "cannot get the reference dots from `%s render %s`\n", dev_tube74(), SCENE);
    return -1;
  }
  *state = f;
  return 0;
}

static int teardown(void **state)
{
  struct fx *f = *state;
  dev_rmdir(f->dir);
  free(f->dir);
  free(f->ref.xy);
  free(f);
  return 0;
}

int main(void)
{
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_hpgl_file_parses_back),
    cmocka_unit_test(test_hpgl_stdout),
    cmocka_unit_test(test_ebb_file),
    cmocka_unit_test(test_ilda_file),
    cmocka_unit_test(test_tek_file),
    cmocka_unit_test(test_svg_previews),
    cmocka_unit_test(test_estimate_hpgl_by_hand),
    cmocka_unit_test(test_estimate_ebb_by_hand),
    cmocka_unit_test(test_estimate_tek_by_hand),
    cmocka_unit_test(test_estimate_fig5_axidraw),
    cmocka_unit_test(test_warning_before_long_plot),
    cmocka_unit_test(test_bad_input_no_file),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
