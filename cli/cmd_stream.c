/*
** cmd_stream.c — `tube74 stream` and `tube74 devices`: the picture to vector hardware over
** USB while the scene renders (CONTRACT.md "stream"; display stage, paper 003 §4).
**
** This file contains code to read the stream command's options, open the device profile
** (display/usb/usb.h, display/usb/stream.h) and hand it to the rendering job as its extra sink,
** so that each dot leaves for the device the moment the renderer produces it, as the 1974
** program displayed each point while it computed. Hardware source: the profiles' files.
**
**   tube74 stream SCENE --device hpgl|ebb|helios|tek [--usb VID:PID | --serial DEV
**                 [--baud N] [--flow none|xonxoff|rtscts] | --dry-run | --to FILE]
**                 [--svg FILE | --no-svg] [--repeat N] [--resume FILE] [--save FILE] [--pps N]
**                 [--paper a4|a3|letter|WxH] [--set NAME=VALUE]... [--settings] [--force]
**                 [--no-estimate] [--progress|--no-progress] [render's options]
**   tube74 devices [PROFILE]
**
** THE LINK: USB by default; --serial DEV an RS-232 tty (hpgl, tek, ebb); --to FILE the
** device's own commands into FILE instead (HP-GL, EBB commands, ILDA .ild, a Tek stream),
** --dry-run the same into nowhere. With a file link nothing is sent anywhere and a summary
** (dots, strokes, pen moves, commands, estimated time) is printed at the end: on stdout, or
** on stderr when the file itself goes to stdout (`--to -`). --svg FILE: the pen / beam path
** as an SVG picture, with any link; --to FILE (a regular file or a new name) brings
** FILE.svg beside it unless --svg names another or --no-svg. The files are outputs of the job's set
** (display/outfile.h): written only when everything succeeded, all or none.
** THE ESTIMATE: before a real run (USB or serial) the picture is first rendered into a file
** link that goes nowhere, with the same profile and settings: its tally is the device's
** time by the profile's timing model (usb.h, each profile's file head). It is printed on
** stderr, with a warning beyond STREAM_LONG_SECONDS, and gives the progress bar its total
** and ETA. The render costs twice (milliseconds to seconds; --no-estimate skips it).
**
** Ctrl-C, SIGTERM, SIGHUP: the handler only sets a flag (below); the sink sees it at the
** next dot and the profiles in their waits, the profile leaves the device safe (laser
** stopped and shutter closed; pen raised with its wait, carriage home, motors off) and the
** resume file is written. Exit statuses: those of CONTRACT.md; a device failure or Ctrl-C is 4, except
** that Ctrl-C ends `--repeat 0` (until stopped) normally, with 0.
*/
#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/commands.h"
#include "cli/pipeline.h"
#include "display/outfile.h"
#include "display/usb/serial.h"
#include "display/usb/usb.h"
#include "display/usb/stream.h"
#include "emu/status.h"

/* The one piece of global state (style.md allows it here only): a signal handler can reach
** nothing else, and it must do no more than set a flag of type volatile sig_atomic_t
** (C11 7.14.1.1). The stream's sink checks it before every dot and between passes. */
static volatile sig_atomic_t stream_stop;

static void on_sigint(int sig)
{
  stream_stop = sig;            /* SIGINT, SIGTERM or SIGHUP: the stream names it */
}

#define STREAM_MAX_SETS 32
#define STREAM_SETBUF   8       /* --pps, --paper (2), --baud, --flow as NAME=VALUE */
#define STREAM_LONG_SECONDS 3600.0   /* a run longer than this gets a warning first */

struct stream_args {            /* the options job_parse does not know */
  const char *device;
  const char *usb;
  const char *resume;
  const char *save;
  int repeat;
  int progress;                 /* -1 auto (stderr is a tty), 0 no, 1 yes */
  int settings;                 /* --settings: list and stop */
  const char *sets[STREAM_MAX_SETS];    /* NAME=VALUE, applied in order */
  int nsets;
  char setbuf[STREAM_SETBUF][64];       /* --pps / --paper / --baud / --flow as NAME=VALUE */
  int nsetbuf;
  int dry_run;                  /* --dry-run: a file link to nowhere */
  const char *to;               /* --to FILE: the device's commands */
  const char *svg;              /* --svg FILE: the pen / beam path */
  const char *serial;           /* --serial DEV */
  int no_estimate;              /* --no-estimate */
  int no_svg;                   /* --no-svg: no preview beside the --to file */
  char svgbuf[1024];            /* FILE.svg beside --to FILE */
};

static int add_set(struct stream_args *a, const char *kv, struct t74_error *err)
{
  if (a->nsets == STREAM_MAX_SETS)
    return t74_fail(err, T74_EINPUT, "tube74: too many --set options (at most %d)", STREAM_MAX_SETS);
  a->sets[a->nsets++] = kv;
  return 1;
}

/* --paper NAME|WxH: the area of a landscape sheet inside 10 mm margins. */
static int paper(struct stream_args *a, const char *v, struct t74_error *err)
{
  double w = 0, h = 0;
  if (!strcmp(v, "a4")) { w = 297; h = 210; }
  else if (!strcmp(v, "a3")) { w = 420; h = 297; }
  else if (!strcmp(v, "letter")) { w = 279.4; h = 215.9; }
  else if (sscanf(v, "%lfx%lf", &w, &h) != 2 || w <= 20 || h <= 20)
    return t74_fail(err, T74_EINPUT, "tube74: --paper takes a4, a3, letter or WxH in mm: %s", v);
  if (a->nsetbuf + 2 > STREAM_SETBUF) return t74_fail(err, T74_EINPUT, "tube74: --paper given twice");
  snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "area_w_mm=%g", w - 20);
  if (add_set(a, a->setbuf[a->nsetbuf++], err) < 0) return -1;
  snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "area_h_mm=%g", h - 20);
  if (add_set(a, a->setbuf[a->nsetbuf++], err) < 0) return -1;
  /* hpgl: which of the model's documented hard-clip areas, when the plotter cannot be asked */
  if (a->device && !strcmp(a->device, "hpgl") && (!strcmp(v, "a4") || !strcmp(v, "letter")))
    return add_set(a, !strcmp(v, "letter") ? "sheet=1" : "sheet=0", err);
  return 1;
}

static int stream_opt(void *ctx, int argc, char **argv, int *k, struct t74_error *err)
{
  struct stream_args *a = ctx;
  const char *o = argv[*k];
  int needs = !strcmp(o, "--device") || !strcmp(o, "--usb") || !strcmp(o, "--repeat") ||
              !strcmp(o, "--resume") || !strcmp(o, "--save") || !strcmp(o, "--pps") ||
              !strcmp(o, "--paper") || !strcmp(o, "--set") || !strcmp(o, "--to") ||
              !strcmp(o, "--svg") || !strcmp(o, "--serial") || !strcmp(o, "--baud") ||
              !strcmp(o, "--flow");
  if (needs && *k + 1 >= argc) {
    t74_fail(err, T74_EINPUT, "tube74: missing value after %s", o);
    return -1;
  }
  if (!strcmp(o, "--device")) a->device = argv[++*k];
  else if (!strcmp(o, "--usb")) a->usb = argv[++*k];
  else if (!strcmp(o, "--resume")) a->resume = argv[++*k];
  else if (!strcmp(o, "--save")) a->save = argv[++*k];
  else if (!strcmp(o, "--progress")) a->progress = 1;
  else if (!strcmp(o, "--no-progress")) a->progress = 0;
  else if (!strcmp(o, "--settings")) a->settings = 1;
  else if (!strcmp(o, "--dry-run")) a->dry_run = 1;
  else if (!strcmp(o, "--no-estimate")) a->no_estimate = 1;
  else if (!strcmp(o, "--no-svg")) a->no_svg = 1;
  else if (!strcmp(o, "--to")) a->to = argv[++*k];
  else if (!strcmp(o, "--svg")) a->svg = argv[++*k];
  else if (!strcmp(o, "--serial")) a->serial = argv[++*k];
  else if (!strcmp(o, "--baud") || !strcmp(o, "--flow")) {
    const char *v = argv[++*k];
    if (a->nsetbuf == STREAM_SETBUF) { t74_fail(err, T74_EINPUT, "tube74: %s given twice", o); return -1; }
    if (!strcmp(o, "--flow")) {
      int f = !strcmp(v, "none") ? 0 : !strcmp(v, "xonxoff") ? 1 : !strcmp(v, "rtscts") ? 2 : -1;
      if (f < 0) {
        t74_fail(err, T74_EINPUT, "tube74: --flow takes none, xonxoff or rtscts: %s", v);
        return -1;
      }
      snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "flow=%d", f);
    } else {
      snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "baud=%s", v);
    }
    return add_set(a, a->setbuf[a->nsetbuf++], err);
  }
  else if (!strcmp(o, "--force")) return add_set(a, "force=1", err);  /* hpgl: see --help */
  else if (!strcmp(o, "--set")) return add_set(a, argv[++*k], err);
  else if (!strcmp(o, "--paper")) return paper(a, argv[++*k], err) < 0 ? -1 : 1;
  else if (!strcmp(o, "--repeat")) {
    char *end;
    errno = 0;
    long n = strtol(argv[++*k], &end, 10);
    if (errno || *end || end == argv[*k] || n < 0 || n > 1000000000L) {
      t74_fail(err, T74_EINPUT, "tube74: --repeat takes a number of passes, 0 = until stopped: %s",
               argv[*k]);
      return -1;
    }
    a->repeat = (int)n;
  } else if (!strcmp(o, "--pps")) {
    if (a->nsetbuf == STREAM_SETBUF) { t74_fail(err, T74_EINPUT, "tube74: --pps given twice"); return -1; }
    snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "pps=%s", argv[++*k]);
    return add_set(a, a->setbuf[a->nsetbuf++], err);
  } else return 0;
  return 1;
}

void stream_usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 stream SCENE --device PROFILE [options] [render's options]\n"
    "  --device hpgl|ebb|helios|tek  the kind of device (tube74 devices lists USB ones)\n"
    "  --usb VID:PID           pick the device by its USB ids (hex)\n"
    "  --serial DEV            an RS-232 line instead of USB (hpgl, tek; ebb as ttyACM)\n"
    "  --baud N                --serial: bits a second, 8N1 (default 9600)\n"
    "  --flow none|xonxoff|rtscts  --serial: flow control (default none; hpgl then asks\n"
    "                          the plotter ESC.B for its free buffer before each block)\n"
    "  --dry-run               send nothing: print dots, pen moves and the estimated time\n"
    "  --to FILE               the device's commands into FILE instead of the device\n"
    "                          (HP-GL, EBB commands, ILDA .ild, Tek stream); `-` stdout\n"
    "  --svg FILE              the pen / beam path as an SVG picture (with --to FILE:\n"
    "                          FILE.svg beside it unless --svg or --no-svg says otherwise)\n"
    "  --no-estimate           no time estimate (and no second render) before a real run\n"
    "  --repeat N              send the picture N times; 0 = until Ctrl-C (default 1)\n"
    "  --resume FILE           continue a run that failed or was stopped\n"
    "  --save FILE             where to save progress on failure (default: the --resume\n"
    "                          file, else SCENE-NAME.PROFILE.resume here)\n"
    "  --pps N                 helios: points per second (7..65535)\n"
    "  --paper a4|a3|letter|WxH  hpgl, ebb: landscape sheet in mm, 10 mm margins (hpgl:\n"
    "                          used when the plotter's limits are not known)\n"
    "  --force                 hpgl: drive a printer-class device whose device id does not\n"
    "                          declare HP-GL\n"
    "  --set NAME=VALUE        any profile setting; --settings lists them\n"
    "  --progress, --no-progress  progress line with ETA on stderr (default: when it is a\n"
    "                          terminal)\n");
}

static int parse_usb(const char *s, struct usb_match *m, struct t74_error *err)
{
  unsigned vid, pid;
  char tail;
  if (sscanf(s, "%x:%x%c", &vid, &pid, &tail) != 2 || vid > 0xFFFF || pid > 0xFFFF)
    return t74_fail(err, T74_EINPUT, "tube74: --usb takes VID:PID in hex, e.g. 1209:e500: %s", s);
  m->vid = (uint16_t)vid;
  m->pid = (uint16_t)pid;
  return T74_OK;
}

/* FNV-1a of the scene file and the options that change which dots are lit. */
static int scene_hash(const struct job *j, uint64_t *out, struct t74_error *err)
{
  FILE *f = fopen(j->scene, "rb");
  if (!f) return t74_fail(err, T74_EINPUT, "%s: cannot read: %s", j->scene, strerror(errno));
  uint64_t h = USB_HASH_INIT;
  unsigned char buf[8192];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = usb_hash(h, buf, n);
  fclose(f);
  char opts[512];
  snprintf(opts, sizeof opts, "|cell=%d|effects=%s|view=%d:%" PRId32 ",%" PRId32 ",%" PRId32
           "|window=%d:%" PRId32 ",%" PRId32 ",%" PRId32 ",%" PRId32 "|input=%s",
           j->cell, j->effects ? j->effects : "", j->sopts.has_view, j->sopts.view[0],
           j->sopts.view[1], j->sopts.view[2], j->sopts.has_window, j->sopts.window[0],
           j->sopts.window[1], j->sopts.window[2], j->sopts.window[3],
           j->sopts.input ? j->sopts.input : "");
  if (j->sopts.has_turn) {                /* only when given: older hashes stay valid */
    size_t used = strlen(opts);
    snprintf(opts + used, sizeof opts - used, "|turn=%.17g,%.17g", j->sopts.turn[0],
             j->sopts.turn[1]);
  }
  *out = usb_hash(h, opts, strlen(opts));
  return T74_OK;
}

/* The summary of a file run (--dry-run, --to): what the device would be sent and do. */
static void summary(FILE *f, const struct job *j, const struct usb_stream_opts *o,
                    const struct usb_stream_result *r, const char *to)
{
  const struct usb_tally *t = &r->tally;
  char d[32];
  double sec = usb_estimate_seconds(t);
  usb_duration(d, sizeof d, sec);
  fprintf(f, "tube74 stream: %s on %s — %s\n", j->scene, o->prof->name,
          to ? "written to a file, nothing sent" : "dry run, nothing sent");
  if (to) fprintf(f, "  %-22s %s (%s)\n", "file", to, o->prof->file_kind);
  fprintf(f, "  %-22s %lld a pass, %d pass%s\n", "dots", r->dots, r->passes,
          r->passes == 1 ? "" : "es");
  if (t->frames > 0)
    fprintf(f, "  %-22s %lld frames, %lld points at %.0f points/s\n", "laser frames", t->frames,
            t->points, usb_setting(&o->set, o->prof, "pps"));
  else if (t->up_mm > 0 || t->down_mm > 0)
    fprintf(f, "  %-22s %lld (single dots and runs), %.1f mm drawn\n", "pen-down strokes",
            t->strokes, t->down_mm);
  if (t->frames > 0)
    fprintf(f, "  %-22s %lld\n", "blanked jumps", t->pen_moves);
  else if (t->up_mm > 0)
    fprintf(f, "  %-22s %lld, %.1f mm of pen-up travel\n", "pen moves", t->pen_moves, t->up_mm);
  else
    fprintf(f, "  %-22s %lld\n", "dark moves", t->pen_moves);
  fprintf(f, "  %-22s %lld commands, %lld bytes\n", "sent", t->commands, t->bytes);
  fprintf(f, "  %-22s %s (%.0f s) by the %s profile's timing model\n", "estimated time", d, sec,
          o->prof->name);
}

/* Before a real run: the same picture through a file link to nowhere, for its tally. */
static int estimate(const struct job *j, struct usb_stream_opts *o, struct t74_error *err)
{
  struct job je = job_dots_only(j);
  struct usb_stream_result r;
  memset(&r, 0, sizeof r);
  struct usb_stream_opts oe = *o;
  oe.kind = USB_LINK_FILE;
  oe.to = NULL;
  oe.svg = NULL;
  oe.line_estimate = o->kind == USB_LINK_SERIAL;
  oe.progress = NULL;
  oe.resume_out = NULL;
  oe.repeat = o->repeat > 0 ? o->repeat : 1;
  oe.result = &r;
  struct usb_stream *s;
  int st = usb_stream_open(&s, &oe, err);
  if (st != T74_OK) return st;
  struct job_hooks h;
  memset(&h, 0, sizeof h);
  h.extra = usb_stream_sink(s);
  st = job_run(&je, &h, NULL, err);
  st = usb_stream_finish(s, st, err);
  if (st != T74_OK) return st;
  double sec = usb_estimate_seconds(&r.tally);
  char d[32];
  usb_duration(d, sizeof d, sec);
  if (o->repeat == 0)
    fprintf(stderr, "tube74: %s: %lld dots; a pass takes about %s on the device, repeated until "
            "Ctrl-C (estimate from the profile's rates)\n", o->prof->name, r.dots, d);
  else
    fprintf(stderr, "tube74: %s: %lld dots%s; about %s on the device (estimate from the "
            "profile's rates)\n", o->prof->name, r.dots, o->repeat > 1 ? " a pass" : "", d);
  if (o->repeat != 0 && sec > STREAM_LONG_SECONDS)
    fprintf(stderr, "tube74: warning: this plot will take about %s; Ctrl-C stops it safely and "
            "--resume continues where it stopped\n", d);
  o->expect_dots = r.dots;
  o->expect_seconds = sec;
  return T74_OK;
}

int cmd_stream(int argc, char **argv, struct t74_error *err)
{
  struct stream_args a;
  memset(&a, 0, sizeof a);
  a.repeat = 1;
  a.progress = -1;
  for (int k = 2; k < argc; k++) {
    if (!strcmp(argv[k], "--settings")) a.settings = 1;
    if (!strcmp(argv[k], "--device") && k + 1 < argc) a.device = argv[k + 1];
  }
  const struct usb_profile *prof = a.device ? usb_profile_find(a.device) : NULL;
  if (a.settings && prof) {                     /* no scene needed to list the settings */
    struct usb_settings s;
    usb_settings_default(&s, prof);
    usb_settings_list(&s, prof, stdout);
    return T74_OK;
  }
  struct job j;
  if (job_parse(argc, argv, 2, &j, stream_opt, &a, err) != T74_OK) return err->status;
  if (!a.device) {
    stream_usage(stderr);
    return t74_fail(err, T74_EINPUT, "tube74: stream needs --device hpgl, ebb, helios or tek");
  }
  if (!prof)
    return t74_fail(err, T74_EINPUT, "tube74: unknown device profile `%s` (hpgl, ebb, helios, "
                    "tek)", a.device);
  enum usb_link_kind kind = a.to || a.dry_run ? USB_LINK_FILE
                          : a.serial ? USB_LINK_SERIAL : USB_LINK_USB;
  if ((a.to || a.dry_run) && (a.serial || a.usb))
    return t74_fail(err, T74_EINPUT, "tube74: --%s writes a file and sends nothing: not with %s",
                    a.to ? "to" : "dry-run", a.serial ? "--serial" : "--usb");
  if (a.serial && a.usb)
    return t74_fail(err, T74_EINPUT, "tube74: --serial and --usb name two links: give one");
  if (!(prof->links & USB_LINKS(kind)))
    return t74_fail(err, T74_EINPUT, "tube74: the %s profile has no %s link%s", prof->name,
                    kind == USB_LINK_USB ? "USB" : kind == USB_LINK_SERIAL ? "serial" : "file",
                    kind == USB_LINK_USB ? ": give --serial DEV (or --to FILE / --dry-run)" : "");
  if (a.to && !a.svg && !a.no_svg) {          /* the preview beside the commands */
    struct stat sb;
    int plain = stat(a.to, &sb) != 0 ? errno == ENOENT : S_ISREG(sb.st_mode);
    if (plain && strcmp(a.to, "-") && strlen(a.to) + 5 <= sizeof a.svgbuf) {
      snprintf(a.svgbuf, sizeof a.svgbuf, "%s.svg", a.to);
      a.svg = a.svgbuf;
    }
  }
  if (a.no_svg) a.svg = NULL;
  if (kind == USB_LINK_FILE && a.repeat == 0)
    return t74_fail(err, T74_EINPUT, "tube74: --repeat 0 (until stopped) needs a device; a file "
                    "holds a number of passes");

  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.t0 = usb_now();
  o.prof = prof;
  o.match = prof->match;
  if (a.usb && parse_usb(a.usb, &o.match, err) != T74_OK) return err->status;
  usb_settings_default(&o.set, prof);
  for (int k = 0; k < a.nsets; k++)
    if (usb_settings_set(&o.set, prof, a.sets[k], err) != T74_OK) return err->status;
  if (kind == USB_LINK_SERIAL && !serial_baud_known((long)o.set.link[USB_P_BAUD]))
    return t74_fail(err, T74_EINPUT, "tube74: --baud %.0f is not a rate a serial port can be set to "
                    "(1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200 ...)", o.set.link[USB_P_BAUD]);
  o.repeat = a.repeat;
  o.resume_in = a.resume;
  o.kind = kind;
  o.serial = a.serial;
  char defsave[512];
  if (!a.save && !a.resume) {
    const char *base = strrchr(j.scene, '/');
    base = base ? base + 1 : j.scene;
    snprintf(defsave, sizeof defsave, "%s.%s.resume", base, prof->name);
  }
  o.resume_out = kind == USB_LINK_FILE ? NULL : a.save ? a.save : a.resume ? a.resume : defsave;
  o.scene = j.scene;
  if (scene_hash(&j, &o.hash, err) != T74_OK) return err->status;
  o.stop = &stream_stop;
  o.progress = (a.progress == 1 || (a.progress < 0 && kind != USB_LINK_FILE && isatty(2)))
               ? stderr : NULL;

  /* SIGINT (Ctrl-C), SIGTERM (kill, shutdown) and SIGHUP (terminal closed) all end the run
     the same safe way: the device is left blanked / pen up / motors off (issue 13) */
  static const int sigs[3] = { SIGINT, SIGTERM, SIGHUP };
  struct sigaction sa, old[3];
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  stream_stop = 0;
  for (int k = 0; k < 3; k++) sigaction(sigs[k], &sa, &old[k]);

  int st = T74_OK;
  if (kind != USB_LINK_FILE && !a.no_estimate) st = estimate(&j, &o, err);

  struct usb_stream_result res;
  memset(&res, 0, sizeof res);
  o.result = &res;
  struct outset *set = NULL;
  if (st == T74_OK) st = outset_new(&set, err);
  if (st == T74_OK && a.to) st = outset_open(set, a.to, 0, &o.to, err);
  if (st == T74_OK && a.svg) st = outset_open(set, a.svg, 0, &o.svg, err);
  if (st == T74_OK) st = outset_check_input(set, j.scene, "scene", err);
  struct usb_stream *s = NULL;
  if (st == T74_OK) st = usb_stream_open(&s, &o, err);
  if (st == T74_OK) {
    struct job_hooks h;
    memset(&h, 0, sizeof h);
    h.extra = usb_stream_sink(s);
    h.clock = usb_stream_clock;
    h.clock_ctx = s;
    h.stats = usb_stream_stats;
    h.stats_ctx = s;
    h.outs = set;
    st = job_run(&j, &h, NULL, err);
    st = usb_stream_finish(s, st, err);
    if (st == T74_OK) st = outset_commit(set, err);
  }
  outset_free(set);
  if (st == T74_OK && kind == USB_LINK_FILE) {
    int on_stdout = a.to && (!strcmp(a.to, "-") || !strcmp(a.to, "/dev/stdout"));
    summary(on_stdout ? stderr : stdout, &j, &o, &res, a.to);
  }
  for (int k = 0; k < 3; k++) sigaction(sigs[k], &old[k], NULL);
  return st;
}

void devices_usage(FILE *f)
{
  fprintf(f, "usage: tube74 devices [hpgl|ebb|helios|tek]   connected USB devices a profile can drive\n");
}

int cmd_devices(int argc, char **argv, struct t74_error *err)
{
  const struct usb_profile *only = NULL;
  if (argc > 2) {
    if (!(only = usb_profile_find(argv[2])))
      return t74_fail(err, T74_EINPUT, "tube74: unknown device profile `%s` (hpgl, ebb, helios, "
                      "tek)", argv[2]);
  }
  if (only && !(only->links & USB_LINKS(USB_LINK_USB))) {
    printf("%s: not a USB device (%s): drive it with `tube74 stream SCENE --device %s --serial "
           "DEV`\n", only->name, only->what, only->name);
    return T74_OK;
  }
  int n = usb_list_devices(stdout, only, err);
  if (n < 0) return err->status;
  if (n == 0)
    fprintf(stderr, "no connected USB device matches %s%s (helios 1209:e500, ebb 04d8:fd92, "
            "hpgl: a printer-class interface)\n", only ? "the profile " : "a profile",
            only ? only->name : "");
  return T74_OK;
}
