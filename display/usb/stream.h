/*
** stream.h — a USB device profile as a point sink: dots go to the device while the scene
** renders, acknowledgements are counted, and a resume file records them (display stage,
** paper 003 §4: the 1974 program displayed each point as soon as it was computed).
**
** This file contains code to put one device profile (usb.h) behind the sink interface of
** display/sink.h, so that `tube74 stream` hands it to the rendering job as its extra sink:
**
**   usb_stream_open(&s, &opts, err)      open the device, read --resume FILE if given
**   usb_stream_sink(s)                   the sink: point() passes each NEW dot on (a dot
**                                        written twice is sent once, like the tube stores it)
**                                        and checks the Ctrl-C flag; end() flushes the pass
**   usb_stream_clock(s, seconds)         the 1974 computing time so far (progress line)
**   usb_stream_finish(s, status, err)    the remaining --repeat passes, then close the device
**                                        safely (pen up / laser blanked); after a failure or
**                                        Ctrl-C, write the resume file; frees s
**   usb_stream_stats(s, outfile)         "usb_..." lines for --stats
**
** RESUME FILE (text, written atomically through display/outfile.h):
**     tube74-resume 1
**     scene <path>                       the scene given
**     hash <16 hex digits>               FNV-1a 64 of the scene bytes and the picture options
**     device <profile>
**     pass <P>                           the --repeat pass being drawn, from 0
**     produced <N>                       dots produced in that pass when it stopped
**     acked <K>                          dots the device acknowledged in that pass
**     prefix <M>                         the first M dots in production order: all acknowledged
**     extra <E>                          then E lines "X Y": acknowledged dots beyond the prefix
**                                        (pen plotters reorder inside a band)
** `--resume FILE` renders the same picture again and skips, in pass P, the first M dots and
** the E listed ones; passes after P are sent whole. Production order is deterministic, so the
** union of both runs is every dot, each once. A file for another scene, other options or
** another profile is refused (exit 2). After a run that completes, the resume file it would
** write is removed (nothing is left to resume).
**
** LINKS (opts.kind): USB (libusb, the default), SERIAL (opts.serial, an RS-232 tty), FILE
** (opts.to: the device's own commands into an output, or NULL for nowhere: a dry run and the
** estimate made before a real run). A file link writes no resume file.
** OUTPUTS: opts.to and opts.svg are finished (outfile_commit) by usb_stream_finish when the
** run completed, and discarded (outfile_abort) otherwise; in a set (display/outfile.h) the
** caller then commits the set, so a failed run leaves no partial file behind.
** THE ESTIMATE: opts.expect_dots / expect_seconds (from a FILE run of the same picture,
** usb_estimate_seconds of its tally) give the progress line a bar and an ETA from the start;
** once dots are acknowledged the ETA follows the measured rate.
*/
#ifndef T74_USB_STREAM_H
#define T74_USB_STREAM_H

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "display/outfile.h"
#include "display/sink.h"
#include "display/usb/usb.h"

struct usb_stream;

struct usb_stream_result {      /* what a run did (usb_stream_finish fills it) */
  long long dots;               /* dots of the picture (one pass) */
  long long sent, acked;        /* dots sent / acknowledged over all passes */
  int passes;                   /* passes drawn (complete or not) */
  struct usb_tally tally;       /* the link's tally (usb.h) */
  char device[320];             /* "hpgl 067b:2305", "tek /dev/ttyUSB0", "ebb file" */
};

/* The device's time for a tally: its own timing model, or its line's time when that is
** longer (a plotter cannot draw faster than its bytes arrive). */
double usb_estimate_seconds(const struct usb_tally *t);

struct usb_stream_opts {
  const struct usb_profile *prof;
  struct usb_match match;       /* the profile's, or --usb VID:PID */
  struct usb_settings set;      /* its settings (--set, --pps, --paper) */
  int repeat;                   /* passes; 0 = until stopped (default 1) */
  const char *resume_in;        /* --resume FILE, or NULL */
  const char *resume_out;       /* where to save progress on failure, or NULL */
  const char *scene;            /* for the resume file */
  uint64_t hash;                /* scene bytes + picture options */
  volatile sig_atomic_t *stop;  /* set by the SIGINT handler; may be NULL */
  FILE *progress;               /* progress line goes here, or NULL for none */
  double t0;                    /* usb_now() when the command started */
  enum usb_link_kind kind;      /* USB (0, the default), SERIAL, FILE */
  const char *serial;           /* SERIAL: the tty's path */
  struct outfile *to;           /* FILE: the device's commands go here (NULL: nowhere) */
  int line_estimate;            /* FILE: count the bytes at the baud (estimating --serial) */
  struct outfile *svg;          /* --svg: the pen / beam path (display/usb/preview.h) */
  long long expect_dots;        /* the estimate: dots a pass, 0 unknown */
  double expect_seconds;        /* the estimate: device seconds of the whole run, 0 unknown */
  struct usb_stream_result *result;   /* filled by usb_stream_finish; may be NULL */
};

int usb_stream_open(struct usb_stream **s, const struct usb_stream_opts *o, struct t74_error *err);
struct sink usb_stream_sink(struct usb_stream *s);
void usb_stream_clock(void *s, double hitac10_seconds);
int usb_stream_stats(void *s, struct outfile *of);
/* status: what the rendering job returned. Returns the run's final status. */
int usb_stream_finish(struct usb_stream *s, int status, struct t74_error *err);

/* FNV-1a 64 of n bytes, continuing from h (start with USB_HASH_INIT). */
#define USB_HASH_INIT 0xcbf29ce484222325ull
uint64_t usb_hash(uint64_t h, const void *p, size_t n);

#endif
