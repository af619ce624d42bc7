/*
** test_serial.c — `tube74 stream --serial DEV` against devices emulated on a pty
** (display/usb/serial.c, the hpgl and tek profiles; issue 20).
**
** This file contains code to play, on the master side of a pseudo-terminal (posix_openpt),
** two RS-232 devices from their manuals, and to run the real binary on the slave side:
**
**   THE LINE (both): the device reads the line settings the host gave the tty (a pty's
**     master sees its slave's termios): a speed other than the device's, or two stop bits,
**     garble every character (the device then ignores them). A pty cannot carry parity or
**     character size (the kernel keeps them 8N), nor modem lines (RTS/CTS is not
**     emulated). A real line cannot bring bytes faster than baud / 10 a second: bytes
**     beyond that (a bucket filled by each byte and emptied at the line's rate, with two
**     write slices of slack; a batch read late is taken as spread over the time since the
**     last read) are counted as `too_fast`.
**   AN HP 7475A (HP 7470A / 7475A interfacing manuals; softsolder.com on the 7475A): a
**     1,024-byte buffer; HP-GL is executed from it at the pen's pace (here DRAIN_BPS bytes
**     a second); a byte that arrives when the buffer is full is lost (an overflow, the
**     plotter's error). Device-control instructions ("ESC ." then a letter) are obeyed on
**     arrival, not buffered: ESC.B answers the free buffer space in decimal and CR;
**     ESC.I<thr>;<enq>;<xon>: and ESC.N<delay>;<xoff>: set the Xoff threshold, enquiry
**     character and Xon / Xoff trigger characters; with no enquiry character and both
**     triggers the Xon-Xoff handshake is on: the plotter sends Xoff when no more than the
**     threshold of free bytes is left, and Xon when the data stored has dropped to 128
**     bytes. OH is answered (when executed) with the A4 hard-clip limits. The drawn HP-GL
**     goes through the HP-GL reader of tests/devices/readers.c.
**   A TEKTRONIX 4014 at 9600 baud (hardware-facts.md; the 4010 manual via Wikipedia: no
**     input buffer to speak of, and an erase "on the order of a second" during which the
**     host must send nothing): bytes are decoded as they arrive (the PLOT 10 decoder of
**     tests/devices/readers.c); after ESC FF the tube is busy ERASE_S and a byte arriving
**     then is lost.
** Each run's picture is compared with `tube74 render --dump points` (hpgl: the same dots
** each once; tek: the same 4014 addresses). Negative runs show each emulator catches what
** it is for: no handshake overflows the plotter, no erase wait loses bytes on the 4014, a
** wrong baud garbles the line.
*/
#define _DEFAULT_SOURCE
#define _XOPEN_SOURCE 700       /* posix_openpt, grantpt, unlockpt, ptsname */

#include <poll.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <termios.h>
#include <time.h>

#include <cmocka.h>

#include "tests/devices/readers.c"

#define SCENE      "tests/data/usb/micro.s74"
#define BUF_7475   1024         /* the 7475A's buffer (softsolder.com: "internal 1 KB buffer") */
#define XON_LEVEL  128          /* 7470A manual: Xon when stored data drops to 128 bytes */
#define DRAIN_BPS  1200.0       /* HP-GL bytes the emulated pen gets through a second */
#define HP_BAUD    19200
#define ERASE_S    0.9          /* the 4014's erase (hardware-facts.md: the 613, about 0.9 s) */
#define SLACK      (2 * 64 + 8) /* bytes a paced host may be ahead of the line */

static double now_s(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- the line ---------------------------------------------------------------------- */

struct line {
  int master, keep;             /* the pty's master; a slave fd held so it never hangs up */
  char slave[128];
  long baud;                    /* the device's own setting */
  speed_t speed;
  int checked, garbled;         /* the host's termios looked at; not the device's settings */
  double level, t_level;        /* bytes ahead of what the line could have carried (a
                                   bucket that empties at baud / 10 bytes a second) */
  long long rx;                 /* bytes received */
  int too_fast;
  pthread_t th;
  pthread_mutex_t lock;
  int stop;                     /* set by the test when the host has exited */
  void (*on_byte)(struct line *l, int c, double t);
  void (*tick)(struct line *l, double t);
  void *dev;
};

static void line_reply(struct line *l, const char *s, int n)
{
  if (write(l->master, s, (size_t)n) != n) { /* the host has gone: nothing to answer */ }
}

static void *line_thread(void *arg)
{
  struct line *l = arg;
  for (;;) {
    struct pollfd p = { l->master, POLLIN, 0 };
    const double t_poll = now_s();              /* a poll that times out saw the line empty
                                                   from here on */
    int r = poll(&p, 1, 2);
    pthread_mutex_lock(&l->lock);
    int stop = l->stop;
    double t = now_s();
    if (r > 0 && (p.revents & POLLIN)) {
      /* everything the line holds now, in one batch: a pty hands it over in reads of up
         to its buffer's size, and a batch cut into several reads would give the later
         reads none of the time the bytes took to come (the bucket below) */
      unsigned char b[16384];
      ssize_t n = read(l->master, b, sizeof b);
      while (n > 0 && (size_t)n < sizeof b) {
        struct pollfd more = { l->master, POLLIN, 0 };
        if (poll(&more, 1, 0) <= 0 || !(more.revents & POLLIN)) break;
        const ssize_t k = read(l->master, b + n, sizeof b - (size_t)n);
        if (k <= 0) break;
        n += k;
      }
      t = now_s();                              /* every byte read had arrived by now */
      if (n > 0 && !l->checked) {               /* the host has set the line up by now */
        struct termios tt;
        l->checked = 1;
        if (tcgetattr(l->master, &tt) == 0)
          l->garbled = cfgetospeed(&tt) != l->speed || (tt.c_cflag & CSTOPB);
      }
      if (n > 0) {
        /* The bucket over the time since the last read: when this thread was late (a
           loaded machine), the batch arrived somewhere in that time, not all at its end;
           it is taken as spread over it (the line empties the bucket as the bytes come),
           so a paced host is never judged by this thread's lateness. An unpaced host
           still fills it: bytes come faster than the line empties it, read after read
           (test_4014_unpaced_too_fast). The time since the last read or the last poll
           that found the line empty, whichever is later (below). */
        double level = l->level + (double)n - (t - l->t_level) * l->baud / 10.0;
        if (level < 0) level = 0;
        if (level > SLACK) l->too_fast += (int)(level - SLACK < (double)n ? level - SLACK : (double)n);
        l->level = level;
        l->t_level = t;
        l->rx += n;
      }
      for (ssize_t k = 0; k < n; k++)
        if (!l->garbled) l->on_byte(l, b[k], t);
    }
    if (r == 0) {
      /* the line seen empty since t_poll: the bucket drains to there, and the next batch
         is given only the time since (an idle line banks nothing: a burst after a pause
         is not excused by the pause) */
      if (t_poll > l->t_level) {
        double level = l->level - (t_poll - l->t_level) * l->baud / 10.0;
        l->level = level < 0 ? 0 : level;
        l->t_level = t_poll;
      }
    }
    if (l->tick) l->tick(l, t);
    pthread_mutex_unlock(&l->lock);
    if (stop && r <= 0) break;                  /* the host is gone and nothing is left */
  }
  return NULL;
}

static int line_open(struct line *l, long baud, speed_t speed, void *dev,
                     void (*on_byte)(struct line *, int, double), void (*tick)(struct line *, double))
{
  memset(l, 0, sizeof *l);
  l->master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (l->master < 0 || grantpt(l->master) || unlockpt(l->master)) return -1;
  snprintf(l->slave, sizeof l->slave, "%s", ptsname(l->master));
  l->keep = open(l->slave, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (l->keep < 0) return -1;
  l->baud = baud;
  l->speed = speed;
  l->dev = dev;
  l->on_byte = on_byte;
  l->tick = tick;
  pthread_mutex_init(&l->lock, NULL);
  return pthread_create(&l->th, NULL, line_thread, l);
}

static void line_close(struct line *l)
{
  pthread_mutex_lock(&l->lock);
  l->stop = 1;
  pthread_mutex_unlock(&l->lock);
  pthread_join(l->th, NULL);
  close(l->keep);
  close(l->master);
  pthread_mutex_destroy(&l->lock);
}

/* ---- the HP 7475A ------------------------------------------------------------------ */

struct p7475 {
  unsigned char buf[BUF_7475]; /* a ring: used bytes from head */
  int head, used;
  double credit, last;          /* pen time not yet spent on bytes */
  int esc;                      /* 0 data, 1 after ESC, 2 after ESC ., 3 reading parameters */
  char op, par[64];
  int npar;
  int xoff_thr, enq, xon_char, xoff_char, xonxoff, xoff_sent;
  int overflow, escb, xoffs, xons, bad_esc;
  struct hpgl_reader r;
};

static void p75_set(struct p7475 *p)
{
  /* parameters "a;b;c" (empty ones default) */
  int v[4] = { -1, -1, -1, -1 }, k = 0;
  for (char *s = p->par; k < 4; k++) {
    if (*s && *s != ';') v[k] = atoi(s);
    char *semi = strchr(s, ';');
    if (!semi) break;
    s = semi + 1;
  }
  if (p->op == 'I') {           /* Xoff threshold (or block size); enquiry; Xon trigger */
    p->xoff_thr = v[0] >= 0 ? v[0] : 80;
    p->enq = v[1] > 0 ? v[1] : 0;
    p->xon_char = v[2] > 0 ? v[2] : 0;
  } else if (p->op == 'N') {    /* intercharacter delay; Xoff trigger */
    p->xoff_char = v[1] > 0 ? v[1] : 0;
  } else if (p->op != '@' && p->op != 'H' && p->op != 'M') {
    p->bad_esc++;
  }
  p->xonxoff = !p->enq && p->xon_char && p->xoff_char;
}

static void p75_byte(struct line *l, int c, double t)
{
  struct p7475 *p = l->dev;
  (void)t;
  if (p->esc == 1) { p->esc = c == '.' ? 2 : 0; if (c != '.') p->bad_esc++; return; }
  if (p->esc == 2) {
    p->op = (char)c;
    if (strchr("@HIMN", c)) { p->esc = 3; p->npar = 0; return; }
    p->esc = 0;
    if (c == 'B') {             /* output buffer space: free bytes, then CR */
      char a[16];
      int n = snprintf(a, sizeof a, "%d\r", BUF_7475 - p->used);
      p->escb++;
      line_reply(l, a, n);
    } else {
      p->bad_esc++;
    }
    return;
  }
  if (p->esc == 3) {
    if (c == ':') { p->par[p->npar] = 0; p->esc = 0; p75_set(p); }
    else if (p->npar < (int)sizeof p->par - 1) p->par[p->npar++] = (char)c;
    return;
  }
  if (c == 0x1B) { p->esc = 1; return; }
  if (p->used == BUF_7475) { p->overflow++; return; }   /* lost */
  p->buf[(p->head + p->used) % BUF_7475] = (unsigned char)c;
  p->used++;
  if (p->xonxoff && !p->xoff_sent && BUF_7475 - p->used <= p->xoff_thr) {
    char x = (char)p->xoff_char;
    line_reply(l, &x, 1);
    p->xoff_sent = 1;
    p->xoffs++;
  }
}

/* The pen at work: execute buffered HP-GL at DRAIN_BPS. */
static void p75_run(struct line *l, struct p7475 *p, double budget)
{
  p->credit += budget;
  while (p->used > 0 && p->credit >= 1) {
    unsigned char c = p->buf[p->head];
    p->head = (p->head + 1) % BUF_7475;
    p->used--;
    p->credit -= 1;
    int oh = p->r.oh;
    hpgl_feed(&p->r, &c, 1);
    if (p->r.oh != oh) line_reply(l, "0,0,11040,7721\r", 15);   /* 7475A, A4 */
    if (p->xoff_sent && p->used <= XON_LEVEL) {
      char x = (char)p->xon_char;
      line_reply(l, &x, 1);
      p->xoff_sent = 0;
      p->xons++;
    }
  }
  if (p->used == 0) p->credit = 0;              /* an idle pen saves no time */
}

static void p75_tick(struct line *l, double t)
{
  struct p7475 *p = l->dev;
  if (p->last > 0) p75_run(l, p, (t - p->last) * DRAIN_BPS);
  p->last = t;
}

/* ---- the 4014 ---------------------------------------------------------------------- */

struct t4014 {
  struct plot10 d;
  double busy_until;            /* erasing until then */
  int lost, erases;
  unsigned char last;
};

static void t14_byte(struct line *l, int c, double t)
{
  struct t4014 *k = l->dev;
  if (t < k->busy_until) { k->lost++; return; }
  plot10_byte(&k->d, c);
  k->last = (unsigned char)c;
  if (k->d.erases != k->erases) {
    k->erases = k->d.erases;
    k->busy_until = t + ERASE_S;
  }
}

/* ---- fixture ----------------------------------------------------------------------- */

struct fx {
  char *dir;
  struct dev_dots ref;
};

static struct fx *F(void **state) { return *state; }

static char *errpath(struct fx *f)
{
  static char b[600];
  snprintf(b, sizeof b, "%s/stderr.txt", f->dir);
  return b;
}

/* Run tube74 stream SCENE --device DEV --serial SLAVE extra... with the line live. */
static int run_on(struct fx *f, struct line *l, const char *dev, const char *const *extra)
{
  char *argv[32];
  int n = 0;
  argv[n++] = (char *)dev_tube74();
  argv[n++] = "stream";
  argv[n++] = SCENE;
  argv[n++] = "--device";
  argv[n++] = (char *)dev;
  argv[n++] = "--serial";
  argv[n++] = l->slave;
  char save[600];
  snprintf(save, sizeof save, "%s/run.resume", f->dir);
  argv[n++] = "--save";
  argv[n++] = save;
  for (int k = 0; extra && extra[k]; k++) argv[n++] = (char *)extra[k];
  argv[n] = NULL;
  int rc = dev_run(argv, "/dev/null", errpath(f));
  if (rc) {
    unsigned char *e = dev_slurp(errpath(f), NULL);
    fprintf(stderr, "tube74 exited %d: %s\n", rc, e ? (char *)e : "");
    free(e);
  }
  return rc;
}

/* One run on an emulated 7475A; the plotter is left in p (line closed, buffer run out). */
static int hp_run(struct fx *f, struct p7475 *p, const char *what, long baud, speed_t speed,
                  const char *const *extra)
{
  memset(p, 0, sizeof *p);
  /* the grid of the 7475A's A4 limits less 5 mm (test_stream_files.c derives it) */
  hpgl_reader_init(&p->r, 24, 720, 260, 0, 0, 11040, 7721);
  struct line l;
  assert_int_equal(line_open(&l, baud, speed, p, p75_byte, p75_tick), 0);
  double t0 = now_s();
  int rc = run_on(f, &l, "hpgl", extra);
  double t = now_s() - t0;
  line_close(&l);
  p75_run(&l, p, 1e9);                          /* the plotter finishes its buffer */
  printf("BENCH 7475A on a pty: %s: %.2f s, %lld bytes, ESC.B %d, Xoff %d / Xon %d, overflow %d, "
         "too fast %d\n", what, t, l.rx, p->escb, p->xoffs,
         p->xons, p->overflow, l.too_fast);
  assert_int_equal(l.too_fast, 0);              /* paced at the baud */
  if (l.garbled) p->bad_esc = -1;               /* tell the caller */
  return rc;
}

static void check_plot(struct fx *f, struct p7475 *p)
{
  assert_int_equal(p->overflow, 0);
  assert_int_equal(p->bad_esc, 0);
  assert_int_equal(p->r.bad, 0);
  assert_int_equal(p->r.off_grid, 0);
  assert_int_equal(p->r.clipped, 0);
  assert_int_equal(p->r.diagonal, 0);
  assert_int_equal(p->r.oh, 1);                 /* the limits were asked on the line */
  assert_false(p->r.down);
  assert_int_equal(p->r.pen, 0);                /* SP0 at the end */
  assert_true(dev_same_set(&p->r.marks, &f->ref));
}

/* Default: no flow control on the line, so the plotter is asked ESC.B before each block. */
static void test_7475a_escb(void **state)
{
  struct fx *f = F(state);
  struct p7475 p;
  const char *extra[] = { "--baud", "19200", NULL };
  assert_int_equal(hp_run(f, &p, "ESC.B checking", HP_BAUD, B19200, extra), 0);
  check_plot(f, &p);
  assert_true(p.escb >= 2);
  assert_int_equal(p.xoffs, 0);
  /* the estimate came first, on stderr */
  unsigned char *e = dev_slurp(errpath(f), NULL);
  assert_non_null(strstr((char *)e, "hpgl: 300 dots; about"));
  free(e);
  free(p.r.marks.xy);
}

/* --flow xonxoff: the plotter's Xon-Xoff handshake switched on (ESC.I / ESC.N) and obeyed. */
static void test_7475a_xonxoff(void **state)
{
  struct fx *f = F(state);
  struct p7475 p;
  const char *extra[] = { "--flow", "xonxoff", "--baud", "19200", NULL };
  assert_int_equal(hp_run(f, &p, "Xon-Xoff", HP_BAUD, B19200, extra), 0);
  check_plot(f, &p);
  assert_true(p.xonxoff);
  assert_int_equal(p.xoff_thr, 80);
  assert_int_equal(p.xon_char, 0x11);
  assert_int_equal(p.xoff_char, 0x13);
  assert_true(p.xoffs >= 1);                    /* the buffer did fill: the handshake worked */
  assert_int_equal(p.escb, 0);
  free(p.r.marks.xy);
}

/* No handshake at all: a plotter slower than its line overflows (the emulator catches it). */
static void test_7475a_no_handshake_overflows(void **state)
{
  struct fx *f = F(state);
  struct p7475 p;
  const char *extra[] = { "--set", "handshake=2", "--baud", "19200", "--set", "query_ms=300", NULL };
  hp_run(f, &p, "no handshake", HP_BAUD, B19200, extra);
  assert_true(p.overflow > 0);
  assert_false(dev_same_set(&p.r.marks, &f->ref));
  free(p.r.marks.xy);
}

/* A plotter set to 9600 baud, the host at 19200: nothing it receives makes sense, ESC.B is
** never answered, and tube74 stops with a device failure (exit 4). */
static void test_7475a_wrong_baud(void **state)
{
  struct fx *f = F(state);
  struct p7475 p;
  const char *extra[] = { "--baud", "19200", "--set", "query_ms=300", "--no-estimate", NULL };
  assert_int_equal(hp_run(f, &p, "host 19200, plotter 9600", 9600, B9600, extra), 4);
  assert_int_equal(p.bad_esc, -1);              /* garbled */
  assert_int_equal(p.r.marks.n, 0);
  unsigned char *e = dev_slurp(errpath(f), NULL);
  assert_non_null(strstr((char *)e, "did not answer ESC.B"));
  free(e);
  free(p.r.marks.xy);
}

/* The 4014 at 9600 baud: the PLOT 10 stream decodes to the dots' addresses; nothing lost in
** the erase; a progress line with an ETA on stderr (--progress). */
static void test_4014(void **state)
{
  struct fx *f = F(state);
  struct t4014 k;
  memset(&k, 0, sizeof k);
  plot10_init(&k.d);
  struct line l;
  assert_int_equal(line_open(&l, 9600, B9600, &k, t14_byte, NULL), 0);
  const char *extra[] = { "--progress", NULL };
  double t0 = now_s();
  assert_int_equal(run_on(f, &l, "tek", extra), 0);
  double t = now_s() - t0;
  line_close(&l);
  printf("BENCH 4014 on a pty at 9600 baud: %d dots in %.2f s, %lld bytes (%.0f bytes/s), "
         "lost %d, too fast %d\n", k.d.pts.n, t, l.rx, l.rx / t, k.lost, l.too_fast);
  assert_false(l.garbled);
  assert_int_equal(l.too_fast, 0);
  assert_int_equal(k.lost, 0);
  assert_int_equal(k.d.bad, 0);
  assert_int_equal(k.erases, 1);
  assert_int_equal(k.last, 0x1F);               /* US: back to alpha */
  struct dev_dots want = { 0, 0, NULL };
  for (int j = 0; j < f->ref.n; j++)
    dev_dots_add(&want, (256 * f->ref.xy[j][0] + 128) / 25, (256 * f->ref.xy[j][1] + 128) / 25);
  assert_true(dev_same_set(&k.d.pts, &want));
  /* no faster than the line: the bytes take at least their time at 9600 baud */
  assert_true(t >= l.rx * 10.0 / 9600 + ERASE_S - 0.2);
  unsigned char *e = dev_slurp(errpath(f), NULL);
  assert_non_null(strstr((char *)e, "tek: 300 dots; about"));
  assert_non_null(strstr((char *)e, "ETA"));
  free(e);
  free(want.xy);
  free(k.d.pts.xy);
}

/* Without the erase wait the 4014 loses what comes while it erases. */
static void test_4014_no_erase_wait_loses(void **state)
{
  struct fx *f = F(state);
  struct t4014 k;
  memset(&k, 0, sizeof k);
  plot10_init(&k.d);
  struct line l;
  assert_int_equal(line_open(&l, 9600, B9600, &k, t14_byte, NULL), 0);
  const char *extra[] = { "--set", "erase_ms=0", "--no-estimate", NULL };
  assert_int_equal(run_on(f, &l, "tek", extra), 0);
  line_close(&l);
  assert_true(k.lost > 0);
  assert_true(k.d.pts.n < f->ref.n);
  free(k.d.pts.xy);
}

/* Writes not paced: more than a 9600-baud line carries reaches the terminal (caught). */
static void test_4014_unpaced_too_fast(void **state)
{
  struct fx *f = F(state);
  struct t4014 k;
  memset(&k, 0, sizeof k);
  plot10_init(&k.d);
  struct line l;
  assert_int_equal(line_open(&l, 9600, B9600, &k, t14_byte, NULL), 0);
  const char *extra[] = { "--set", "pace=0", "--no-estimate", NULL };
  assert_int_equal(run_on(f, &l, "tek", extra), 0);
  line_close(&l);
  assert_true(l.too_fast > 0);
  free(k.d.pts.xy);
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
  int m = posix_openpt(O_RDWR | O_NOCTTY);
  if (m < 0) {
    printf("SKIP: no pseudo-terminals here (posix_openpt: %s)\n", strerror(errno));
    return 77;
  }
  close(m);
  const struct CMUnitTest tests[] = {
    cmocka_unit_test(test_7475a_escb),
    cmocka_unit_test(test_7475a_xonxoff),
    cmocka_unit_test(test_7475a_no_handshake_overflows),
    cmocka_unit_test(test_7475a_wrong_baud),
    cmocka_unit_test(test_4014),
    cmocka_unit_test(test_4014_no_erase_wait_loses),
    cmocka_unit_test(test_4014_unpaced_too_fast),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
