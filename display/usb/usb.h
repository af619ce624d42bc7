/*
** usb.h — vector hardware over USB: the device-profile interface and the libusb transfer
** layer every profile shares (display stage, paper 003 §4; docs/hardware.md "Vector
** hardware over USB").
**
** This file contains code to drive real pen plotters and laser/XY DACs with the tube's
** dots. Paper 003 §4 wrote each lit dot to a storage CRT as one beam command; here each
** dot goes to a USB device instead, through one of a few PROFILES (hpgl, ebb, helios),
** each a small module behind one interface. All device I/O is libusb-1.0 and nothing else.
**
** THE PROFILE INTERFACE (struct usb_profile)
**
**   open(&ctx, link, settings, ack, err)   take the opened link, send the device's
**                                          preamble (IN;SP1 / EM+pen up / firmware query)
**   send(ctx, pts, n, err)                 n dots in production order; the profile may
**                                          buffer, reorder (pen plotters, inside one band)
**                                          and send whenever it likes
**   flush(ctx, err)                        everything given so far is out AND acknowledged
**   status(ctx, &st, err)                  poll the device: ready, paper out, error
**   close(ctx, clean)                      leave the device safe (pen up / laser blanked);
**                                          clean = 0 after a failure: no waiting, best effort
**   Every dot the device ACKNOWLEDGES is reported back, once, through ack.fn(ack.ctx, p):
**   what acknowledged means is the profile's (documented in each file, docs/usb.md) — it is
**   what the resume file records, so that `--resume` loses and repeats nothing.
**
** THE TRANSFER LAYER (struct usb_link)
**
**   usb_link_open    find the first device that matches a profile (VID:PID and/or an
**                    interface class), open it (ACCESS -> the udev rule to add), detach a
**                    bound kernel driver, claim, select the alt setting; on close every
**                    interface that had a driver gets it back (a CDC ACM pair: both)
**   usb_submit / usb_wait   one asynchronous transfer (bulk, interrupt or control) and its
**                    completion, with the fault policy below; a profile may keep one transfer
**                    in flight while it prepares the next (helios double-buffering)
**   usb_transfer     submit + wait
**   FAULT POLICY (usb_wait):
**     stall (LIBUSB_TRANSFER_STALL)   libusb_clear_halt, then the REST of the transfer is sent
**                                     again (bytes before the stall were taken by the device)
**     timeout, no bytes moved         retried `retries` times, sleeping backoff_ms, 2x, 4x...
**                                     between tries, then T74_EIO
**     timeout, bytes moved            a slow device (a plotter NAKing while its buffer is
**                                     full): the rest is sent again at once and the count
**                                     of tries starts again
**     device gone (NO_DEVICE)         T74_EIO at once, usb_link_gone() turns true
**     other errors                    retried like timeouts
**   *done always tells how many bytes the device took, also when the transfer failed:
**   a profile acknowledges exactly what was taken, never more.
**
** OTHER LINKS (the same calls, so a profile does not care which it drives):
**   usb_link_open_serial   an RS-232 tty (display/usb/serial.h): bulk OUT is the line out,
**                    bulk IN what the device sends; no control transfers (T74_EIO), no
**                    interrupt endpoints. HP-GL plotters on RS-232 (HP 7475A), Tektronix
**                    terminals, an EBB as /dev/ttyACM0.
**   usb_link_open_file     the device's commands written to a file (or nowhere, for a dry
**                    run or the estimate): every OUT byte is taken at once, nothing ever
**                    answers (IN reads give 0 bytes, at once), no control transfers. Profiles
**                    that wait for replies (EBB OK / QM, Helios status) skip them when
**                    usb_link_kind() says FILE and count everything sent as acknowledged.
** THE TALLY (struct usb_tally, usb_link_tally): what went over the link and how long the
**   device needs for it, by the profile's own timing model (each profile says which); the
**   link counts bytes and, on a serial line, their time at the baud. The stream's estimate
**   and the dry run's summary are read from it.
** THE PREVIEW (usb_link_preview): the --svg recorder (display/usb/preview.h) or NULL; the
**   profiles report every pen / beam move to it in device units.
**
** PARAMETERS: every number a user may want to change is a row of a profile's parameter
** table (name, default, range, unit, source), set with `--set NAME=VALUE` (SIMH's MTAB
** idea, style.md). The link's own rows (timeout_ms, retries, backoff_ms; baud, flow, pace
** for serial lines) are in usb_link_params.
*/
#ifndef T74_USB_H
#define T74_USB_H

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "emu/param.h"
#include "emu/status.h"

struct preview;                 /* display/usb/preview.h */
struct outfile;                 /* display/outfile.h */

/* ---- parameters ------------------------------------------------------------------- */

#define USB_MAX_PARAMS 28       /* rows in one profile's table (checked at start) */

/* The link's own rows: indices into usb_settings.link[]. */
enum { USB_P_TIMEOUT, USB_P_RETRIES, USB_P_BACKOFF, USB_P_BAUD, USB_P_FLOW, USB_P_PACE,
       USB_NLINK };
extern const struct param_row usb_link_params[USB_NLINK];   /* emu/param.h */

struct usb_settings {
  double link[USB_NLINK];       /* usb_link_params values */
  double p[USB_MAX_PARAMS];     /* the profile's values, in its table's order */
};

/* ---- the transfer layer ----------------------------------------------------------- */

struct usb_link;                /* opaque: libusb context, handle, interface, counters */

enum usb_link_kind {            /* what a link is (a bit each, for usb_profile.links) */
  USB_LINK_USB = 0,             /* libusb */
  USB_LINK_SERIAL = 1,          /* an RS-232 tty (serial.h) */
  USB_LINK_FILE = 2             /* commands to a file or nowhere (dry run, estimate) */
};
#define USB_LINKS(k) (1u << (k))

/* What went over a link and how long the device needs for it (see THE TALLY). */
struct usb_tally {
  long long bytes;              /* bytes sent (the link counts them) */
  long long commands;           /* device commands: HP-GL instructions, EBB commands, Helios
                                   frames, Tektronix addresses */
  long long strokes;            /* pen plotters: pen-down strokes (a dot or a run); laser /
                                   terminal: lit dots */
  long long pen_moves;          /* pen-up moves, blanked jumps, dark moves */
  double up_mm, down_mm;        /* pen-up and pen-down travel, mm (0: no physical scale) */
  long long points, frames;     /* helios: DAC points and frames */
  double device_s;              /* seconds the device needs (the profile's timing model) */
  double line_s;                /* serial (or a file estimating one): the bytes at the baud */
};

struct usb_match {              /* which device a profile drives */
  uint16_t vid, pid;            /* 0, 0: any device (then iface_class decides) */
  int iface_class;              /* the interface to claim: its class, or -1 = interface 0 */
  int alt;                      /* alternate setting to select, or -1 to leave it */
};

enum usb_type { USB_CONTROL, USB_BULK, USB_INTERRUPT };

/* Fault counters, for the progress line, --stats and the tests. */
struct usb_counts {
  long transfers;               /* transfers completed */
  long stalls;                  /* stalls cleared (libusb_clear_halt) */
  long timeouts;                /* timeouts retried */
  long errors;                  /* other transfer errors retried */
  long long bytes_out, bytes_in;
};

/* Open the first device matching m. `profile` names it in messages. On LIBUSB_ERROR_ACCESS
** the message gives the udev rule (usb_udev_rule). T74_EIO on any failure. */
int usb_link_open(struct usb_link **out, const struct usb_match *m, const char *profile,
                  const struct usb_settings *s, struct t74_error *err);
/* The same for the device at bus:address only (it must match m too). */
int usb_link_open_at(struct usb_link **out, const struct usb_match *m, int bus, int address,
                     const char *profile, const struct usb_settings *s, struct t74_error *err);
void usb_link_close(struct usb_link *l);
/* An RS-232 line: path, with s's baud, flow and pace rows. T74_EIO (or T74_EINPUT for a baud
** termios has no constant for) on failure. */
int usb_link_open_serial(struct usb_link **out, const char *path, const char *profile,
                         const struct usb_settings *s, struct t74_error *err);
/* A file link: OUT bytes go to `to` (NULL: nowhere). line: 1 to count the bytes' time at
** s's baud as a serial line would (an estimate made for a --serial run). */
int usb_link_open_file(struct usb_link **out, struct outfile *to, int line, const char *profile,
                       const struct usb_settings *s, struct t74_error *err);
enum usb_link_kind usb_link_kind(const struct usb_link *l);
/* Where it goes, for messages and --stats: "067b:2305", "/dev/ttyUSB0", "a file". */
const char *usb_link_name(const struct usb_link *l);
struct usb_tally *usb_link_tally(struct usb_link *l);
void usb_link_set_preview(struct usb_link *l, struct preview *p);
struct preview *usb_link_preview(const struct usb_link *l);
/* The link's serial flow setting (enum serial_flow; 0 for USB and files). */
int usb_link_flow(const struct usb_link *l);

/* The claimed interface's first endpoint of a type (USB_BULK / USB_INTERRUPT) and
** direction (in = 1: device to host), or -1. */
int usb_link_endpoint(const struct usb_link *l, enum usb_type type, int in);
int usb_link_interface(const struct usb_link *l);
int usb_link_alt(const struct usb_link *l);       /* its alternate setting */
void usb_link_ids(const struct usb_link *l, uint16_t *vid, uint16_t *pid);
int usb_link_gone(const struct usb_link *l);      /* the device vanished */
/* The stream's stop flag (set by Ctrl-C / SIGTERM / SIGHUP): profiles check it in their
** own waiting loops (status polls, motion-queue polls) so that a stop is not held up. */
void usb_link_set_stop(struct usb_link *l, volatile sig_atomic_t *stop);
int usb_link_stopped(const struct usb_link *l);
/* The link's timeout_ms setting (a profile adds the motion time it expects on top). */
double usb_link_timeout_ms(const struct usb_link *l);
const struct usb_counts *usb_link_counts(const struct usb_link *l);

struct usb_xfer {               /* one transfer in flight; owned by the profile */
  void *t;                      /* the libusb_transfer (opaque here) */
  enum usb_type type;
  unsigned char ep;
  unsigned char *buf;           /* data (control: 8-byte setup packet first) */
  int len;                      /* bytes to move (control: setup + data) */
  int done;                     /* bytes the device took / gave so far */
  int tries;                    /* timeouts/errors so far */
  int stalls;                   /* stalls so far */
  volatile int completed;       /* set by the libusb callback */
  int busy;                     /* submitted and not yet waited for */
};

/* Start one transfer. T74_OK, or T74_EIO (device gone, submit refused). */
int usb_submit(struct usb_link *l, struct usb_xfer *x, enum usb_type type, unsigned char ep,
               void *buf, int len, struct t74_error *err);
/* Wait for x with the fault policy. *done (may be NULL): bytes moved in all. */
int usb_wait(struct usb_link *l, struct usb_xfer *x, int *done, struct t74_error *err);
/* Free x's libusb transfer (x must not be busy: usb_wait first); l is x's link. */
void usb_xfer_free(struct usb_link *l, struct usb_xfer *x);
/* submit + wait. For IN transfers a short read is success; *done says how much came. */
int usb_transfer(struct usb_link *l, enum usb_type type, unsigned char ep, void *buf,
                 int len, int *done, struct t74_error *err);
/* One IN transfer with its own timeout and no retries: T74_OK with *got bytes (0 when
** nothing came in time: draining stale replies, reading a reply that may never come), or
** T74_EIO when the device vanished. */
int usb_read_once(struct usb_link *l, enum usb_type type, unsigned char ep, void *buf, int len,
                  int timeout_ms, int *got, struct t74_error *err);
/* A class/vendor control transfer, device to host: wLength = len bytes into buf. */
int usb_control_in(struct usb_link *l, uint8_t bmRequestType, uint8_t bRequest,
                   uint16_t wValue, uint16_t wIndex, void *buf, int len, int *got,
                   struct t74_error *err);

/* The udev rule line that gives the logged-in user access to VID:PID. */
void usb_udev_rule(char *buf, size_t n, uint16_t vid, uint16_t pid);

/* Sleep ms milliseconds (nanosleep; an interrupted sleep ends early). */
void usb_sleep_ms(double ms);
/* Monotonic seconds. */
double usb_now(void);
/* A duration for people: "45.2 s", "12 min 30 s", "4 h 05 min". */
void usb_duration(char *buf, size_t n, double seconds);

/* ---- the profile interface -------------------------------------------------------- */

struct usb_point {              /* one tube dot on its way to a device */
  int16_t x, y;                 /* tube coordinates (sink.h): x 0..399, y 0..299 up */
  uint32_t seq;                 /* its place in production order within the pass */
  uint32_t pass;                /* which pass of --repeat */
};

struct usb_ack {                /* where a profile reports acknowledged dots */
  void *ctx;
  void (*fn)(void *ctx, const struct usb_point *p);
};

struct usb_status {
  int ready;                    /* can take more now */
  int paper_out;                /* printer class: paper empty */
  int error;                    /* device reports an error */
  char text[96];                /* what it said, for messages */
};

struct usb_profile {
  const char *name;             /* "hpgl", "ebb", "helios" */
  const char *what;             /* one line for --help and `devices` */
  struct usb_match match;       /* how its device is found */
  const struct param_row *params;   /* its settings (emu/param.h) */
  int nparams;
  int  (*open)(void **ctx, struct usb_link *l, const struct usb_settings *s,
               struct usb_ack ack, struct t74_error *err);
  int  (*send)(void *ctx, const struct usb_point *p, int n, struct t74_error *err);
  int  (*flush)(void *ctx, struct t74_error *err);
  int  (*status)(void *ctx, struct usb_status *st, struct t74_error *err);
  void (*close)(void *ctx, int clean);
  /* Optional, for `devices`: what the device says of itself on an opened link (the
     printer class's GET_DEVICE_ID for hpgl), one short phrase into out. NULL: nothing. */
  void (*note)(struct usb_link *l, char *out, size_t n);
  unsigned links;               /* USB_LINKS() of the link kinds it can drive */
  const char *file_kind;        /* what --to writes: "HP-GL", "EBB commands", ... */
};

extern const struct usb_profile usb_profile_hpgl;     /* hpgl.c */
extern const struct usb_profile usb_profile_ebb;      /* ebb.c */
extern const struct usb_profile usb_profile_helios;   /* helios.c */
extern const struct usb_profile usb_profile_tek;      /* tekterm.c */

/* The profile called name, or NULL. */
const struct usb_profile *usb_profile_find(const char *name);
/* All profiles, NULL-terminated. */
extern const struct usb_profile *const usb_profiles[];

/* Defaults of s for profile p. */
void usb_settings_default(struct usb_settings *s, const struct usb_profile *p);
/* Apply "NAME=VALUE" to s (link rows or p's rows). T74_EINPUT with a message if unknown
** or out of range. */
int usb_settings_set(struct usb_settings *s, const struct usb_profile *p, const char *kv,
                     struct t74_error *err);
/* The value of p's row called name (must exist). */
double usb_setting(const struct usb_settings *s, const struct usb_profile *p, const char *name);
/* List p's rows and the link's (name, value, unit, source). */
void usb_settings_list(const struct usb_settings *s, const struct usb_profile *p, FILE *f);

/* List connected devices matching any profile (or only `only`, if not NULL) on f.
** Returns the number listed, or -1 with err set when libusb cannot start. */
int usb_list_devices(FILE *f, const struct usb_profile *only, struct t74_error *err);

#endif
