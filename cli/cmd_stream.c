/*
** cmd_stream.c — `tube74 stream` and `tube74 devices`: the picture to vector hardware over
** USB while the scene renders (CONTRACT.md "stream"; display stage, paper 003 §4).
**
** This file contains code to read the stream command's options, open the device profile
** (display/usb/usb.h, display/usb/stream.h) and hand it to the rendering job as its extra sink,
** so that each dot leaves for the device the moment the renderer produces it, as the 1974
** program displayed each point while it computed. Hardware source: the profiles' files.
**
**   tube74 stream SCENE --device hpgl|ebb|helios [--usb VID:PID] [--repeat N]
**                 [--resume FILE] [--save FILE] [--pps N] [--paper a4|a3|letter|WxH]
**                 [--set NAME=VALUE]... [--settings] [--force] [--progress|--no-progress]
**                 [render's options]
**   tube74 devices [PROFILE]
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
#include <unistd.h>

#include "cli/commands.h"
#include "cli/pipeline.h"
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
  char setbuf[4][64];           /* --pps / --paper turned into NAME=VALUE */
  int nsetbuf;
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
  if (a->nsetbuf + 2 > 4) return t74_fail(err, T74_EINPUT, "tube74: --paper given twice");
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
              !strcmp(o, "--paper") || !strcmp(o, "--set");
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
    if (a->nsetbuf == 4) { t74_fail(err, T74_EINPUT, "tube74: --pps given twice"); return -1; }
    snprintf(a->setbuf[a->nsetbuf], sizeof a->setbuf[0], "pps=%s", argv[++*k]);
    return add_set(a, a->setbuf[a->nsetbuf++], err);
  } else return 0;
  return 1;
}

void stream_usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 stream SCENE --device PROFILE [options] [render's options]\n"
    "  --device hpgl|ebb|helios  the kind of device (tube74 devices lists connected ones)\n"
    "  --usb VID:PID           pick the device by its USB ids (hex)\n"
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
    "  --progress, --no-progress  progress line on stderr (default: when it is a terminal)\n");
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
    return t74_fail(err, T74_EINPUT, "tube74: stream needs --device hpgl, ebb or helios");
  }
  if (!prof)
    return t74_fail(err, T74_EINPUT, "tube74: unknown device profile `%s` (hpgl, ebb, helios)",
                    a.device);

  struct usb_stream_opts o;
  memset(&o, 0, sizeof o);
  o.t0 = usb_now();
  o.prof = prof;
  o.match = prof->match;
  if (a.usb && parse_usb(a.usb, &o.match, err) != T74_OK) return err->status;
  usb_settings_default(&o.set, prof);
  for (int k = 0; k < a.nsets; k++)
    if (usb_settings_set(&o.set, prof, a.sets[k], err) != T74_OK) return err->status;
  o.repeat = a.repeat;
  o.resume_in = a.resume;
  char defsave[512];
  if (!a.save && !a.resume) {
    const char *base = strrchr(j.scene, '/');
    base = base ? base + 1 : j.scene;
    snprintf(defsave, sizeof defsave, "%s.%s.resume", base, prof->name);
  }
  o.resume_out = a.save ? a.save : a.resume ? a.resume : defsave;
  o.scene = j.scene;
  if (scene_hash(&j, &o.hash, err) != T74_OK) return err->status;
  o.stop = &stream_stop;
  o.progress = (a.progress == 1 || (a.progress < 0 && isatty(2))) ? stderr : NULL;

  /* SIGINT (Ctrl-C), SIGTERM (kill, shutdown) and SIGHUP (terminal closed) all end the run
     the same safe way: the device is left blanked / pen up / motors off (issue 13) */
  static const int sigs[3] = { SIGINT, SIGTERM, SIGHUP };
  struct sigaction sa, old[3];
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  stream_stop = 0;
  for (int k = 0; k < 3; k++) sigaction(sigs[k], &sa, &old[k]);

  struct usb_stream *s;
  int st = usb_stream_open(&s, &o, err);
  if (st == T74_OK) {
    struct job_hooks h;
    memset(&h, 0, sizeof h);
    h.extra = usb_stream_sink(s);
    h.clock = usb_stream_clock;
    h.clock_ctx = s;
    h.stats = usb_stream_stats;
    h.stats_ctx = s;
    st = job_run(&j, &h, NULL, err);
    st = usb_stream_finish(s, st, err);
  }
  for (int k = 0; k < 3; k++) sigaction(sigs[k], &old[k], NULL);
  return st;
}

void devices_usage(FILE *f)
{
  fprintf(f, "usage: tube74 devices [hpgl|ebb|helios]   connected USB devices a profile can drive\n");
}

int cmd_devices(int argc, char **argv, struct t74_error *err)
{
  const struct usb_profile *only = NULL;
  if (argc > 2) {
    if (!(only = usb_profile_find(argv[2])))
      return t74_fail(err, T74_EINPUT, "tube74: unknown device profile `%s` (hpgl, ebb, helios)",
                      argv[2]);
  }
  int n = usb_list_devices(stdout, only, err);
  if (n < 0) return err->status;
  if (n == 0)
    fprintf(stderr, "no connected USB device matches %s%s (helios 1209:e500, ebb 04d8:fd92, "
            "hpgl: a printer-class interface)\n", only ? "the profile " : "a profile",
            only ? only->name : "");
  return T74_OK;
}
