/*
** usb.c — the libusb transfer layer shared by the USB device profiles (see usb.h).
**
** This file contains code to find, open and claim a vector device and to move bytes to and
** from it with libusb-1.0's asynchronous API, applying one fault policy everywhere: a
** stall is cleared (libusb_clear_halt) and the rest of the transfer sent again; a timeout
** or a transient error is retried with doubling backoff and then fails, except that a
** timeout after which bytes had moved starts the count again (a slow device); a vanished device
** (LIBUSB_ERROR_NO_DEVICE / LIBUSB_TRANSFER_NO_DEVICE) fails at once. Bytes the device took
** before a failure are always reported (*done), because profiles acknowledge exactly those.
**
** Hardware source: the USB 2.0 specification for the transfer types and halt feature; the
** Linux usbfs backend of libusb 1.0.26 for how faults surface (stall = urb status -EPIPE,
** disconnect = -ENODEV / ESHUTDOWN, timeout = libusb cancels the URB).
** Asynchronous transfers are waited for with libusb_handle_events_timeout_completed on the
** link's own context: no threads, no global libusb state. libusb itself is opened with
** dlopen when a USB link is opened or the devices are listed (display/dynlib.h): a render,
** a file or a serial line never loads it (issue 19), and a missing libusb is a failure of
** that command alone ("PROFILE: cannot load libusb-1.0 (why)", exit 4).
*/
#include "display/usb/usb.h"

#include <libusb.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "display/dynlib.h"
#include "display/outfile.h"
#include "display/usb/serial.h"

#define USB_LIB "libusb-1.0.so.0"

/* The libusb functions this file calls, opened with the library (dynlib.h); the slots are
   named as the functions are. (libusb_fill_*_transfer and libusb_fill_control_setup are
   inline functions of the header: not looked up.) */
struct usblib {
  void *lib;                    /* dlopen handle, NULL: not loaded (first: dynlib.h) */
  int (LIBUSB_CALL *libusb_init)(libusb_context **);
  void (LIBUSB_CALL *libusb_exit)(libusb_context *);
  ssize_t (LIBUSB_CALL *libusb_get_device_list)(libusb_context *, libusb_device ***);
  void (LIBUSB_CALL *libusb_free_device_list)(libusb_device **, int);
  int (LIBUSB_CALL *libusb_get_device_descriptor)(libusb_device *,
                                                  struct libusb_device_descriptor *);
  uint8_t (LIBUSB_CALL *libusb_get_bus_number)(libusb_device *);
  uint8_t (LIBUSB_CALL *libusb_get_device_address)(libusb_device *);
  int (LIBUSB_CALL *libusb_open)(libusb_device *, libusb_device_handle **);
  void (LIBUSB_CALL *libusb_close)(libusb_device_handle *);
  libusb_device *(LIBUSB_CALL *libusb_get_device)(libusb_device_handle *);
  int (LIBUSB_CALL *libusb_get_active_config_descriptor)(libusb_device *,
                                                         struct libusb_config_descriptor **);
  int (LIBUSB_CALL *libusb_get_config_descriptor)(libusb_device *, uint8_t,
                                                  struct libusb_config_descriptor **);
  void (LIBUSB_CALL *libusb_free_config_descriptor)(struct libusb_config_descriptor *);
  int (LIBUSB_CALL *libusb_kernel_driver_active)(libusb_device_handle *, int);
  int (LIBUSB_CALL *libusb_detach_kernel_driver)(libusb_device_handle *, int);
  int (LIBUSB_CALL *libusb_attach_kernel_driver)(libusb_device_handle *, int);
  int (LIBUSB_CALL *libusb_claim_interface)(libusb_device_handle *, int);
  int (LIBUSB_CALL *libusb_release_interface)(libusb_device_handle *, int);
  int (LIBUSB_CALL *libusb_set_interface_alt_setting)(libusb_device_handle *, int, int);
  const char *(LIBUSB_CALL *libusb_error_name)(int);
  struct libusb_transfer *(LIBUSB_CALL *libusb_alloc_transfer)(int);
  void (LIBUSB_CALL *libusb_free_transfer)(struct libusb_transfer *);
  int (LIBUSB_CALL *libusb_submit_transfer)(struct libusb_transfer *);
  int (LIBUSB_CALL *libusb_clear_halt)(libusb_device_handle *, unsigned char);
  int (LIBUSB_CALL *libusb_handle_events_timeout_completed)(libusb_context *, struct timeval *,
                                                            int *);
};

#define USB_FNS(X) X(libusb_init) X(libusb_exit) X(libusb_get_device_list)                 \
  X(libusb_free_device_list) X(libusb_get_device_descriptor) X(libusb_get_bus_number)     \
  X(libusb_get_device_address) X(libusb_open) X(libusb_close) X(libusb_get_device)        \
  X(libusb_get_active_config_descriptor) X(libusb_get_config_descriptor)                  \
  X(libusb_free_config_descriptor) X(libusb_kernel_driver_active)                         \
  X(libusb_detach_kernel_driver) X(libusb_attach_kernel_driver) X(libusb_claim_interface) \
  X(libusb_release_interface) X(libusb_set_interface_alt_setting) X(libusb_error_name)    \
  X(libusb_alloc_transfer) X(libusb_free_transfer) X(libusb_submit_transfer)              \
  X(libusb_clear_halt) X(libusb_handle_events_timeout_completed)

/* Open libusb into f; `what` names the command or profile in the message. */
static int usblib_load(struct usblib *f, const char *what, struct t74_error *err)
{
#define SYM(name) { #name, offsetof(struct usblib, name) },
  static const struct dynlib_sym syms[] = { USB_FNS(SYM) };
#undef SYM
#define CHECK(name) DYNLIB_CHECK(f, name, name);
  USB_FNS(CHECK)
#undef CHECK
  return dynlib_open(f, sizeof *f, USB_LIB, "libusb-1.0", "libusb-1.0-0", syms,
                     sizeof syms / sizeof *syms, what, err);
}

/* The link's rows (usb.h). The defaults are the usual USB host-side choices: a bulk
** transfer to a plotter may wait while the plotter moves its pen, so the timeout is long. */
const struct param_row usb_link_params[USB_NLINK] = {
  /* name, unit, default, accepted range, whole numbers only, source (emu/param.h) */
  { "timeout_ms", "ms", 2000, 10, 600000, 0, "inferred: longest pen move plus margin" },
  { "retries",    "",   3,    0,  100,    0, "inferred" },
  { "backoff_ms", "ms", 20,   0,  60000,  0, "inferred: first pause, doubled each retry" },
  { "baud",       "bit/s", 9600, 50, 4000000, 1, "--serial: line rate, 8N1 (the 4014's "
                                                  "and the 7475A's usual 9600)" },
  { "flow",       "",   0,    0,  2,      1, "--serial: 0 none, 1 XON/XOFF, 2 RTS/CTS (serial.h)" },
  { "pace",       "",   1,    0,  1,      1, "--serial: 1 writes timed to baud/10 bytes/s" },
};

struct usb_link {
  enum usb_link_kind kind;
  struct serial_line *ser;      /* SERIAL: the tty */
  struct outfile *to;           /* FILE: where OUT bytes go, or NULL */
  int line;                     /* FILE: count the bytes' time at the baud (an estimate) */
  double baud;                  /* SERIAL, or FILE with line: bits a second */
  int flow;                     /* SERIAL: enum serial_flow */
  char name[280];               /* "067b:2305", the tty's path, "a file" */
  struct usb_tally tally;
  struct preview *preview;      /* --svg, or NULL */
  struct usblib u;              /* USB: libusb, opened for this link */
  libusb_context *ctx;
  libusb_device_handle *h;
  int iface;                    /* claimed interface number */
  int alt;                      /* its selected alternate setting */
  unsigned had_driver;          /* bit i: interface i had a kernel driver at open: give
                                   it back on close (a CDC ACM pair unbinds together) */
  uint16_t vid, pid;
  int gone;                     /* LIBUSB_ERROR_NO_DEVICE seen */
  int timeout_ms, retries, backoff_ms;
  const char *profile;
  volatile sig_atomic_t *stop;  /* the stream's stop flag (Ctrl-C, SIGTERM), or NULL */
  struct usb_counts counts;
  /* endpoints of the claimed interface: address, or -1 */
  int ep_bulk_in, ep_bulk_out, ep_int_in, ep_int_out;
};

double usb_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void usb_sleep_ms(double ms)
{
  if (ms <= 0) return;
  struct timespec ts;
  ts.tv_sec = (time_t)(ms / 1000);
  ts.tv_nsec = (long)((ms - (double)ts.tv_sec * 1000) * 1e6);
  nanosleep(&ts, NULL);
}

void usb_duration(char *buf, size_t n, double t)
{
  if (t < 0) t = 0;
  if (t < 60) snprintf(buf, n, "%.1f s", t);
  else if (t < 3600) snprintf(buf, n, "%d min %02d s", (int)(t / 60), (int)t % 60);
  else snprintf(buf, n, "%d h %02d min", (int)(t / 3600), (int)(t / 60) % 60);
}

void usb_udev_rule(char *buf, size_t n, uint16_t vid, uint16_t pid)
{
  /* TAG+="uaccess" lets systemd-logind give the seat's user access; MODE/GROUP cover
     systems without logind (add yourself to plugdev). */
  snprintf(buf, n,
           "SUBSYSTEM==\"usb\", ATTRS{idVendor}==\"%04x\", ATTRS{idProduct}==\"%04x\", "
           "MODE=\"0660\", GROUP=\"plugdev\", TAG+=\"uaccess\"", vid, pid);
}

/* ---- finding the device ----------------------------------------------------------- */

/* The interface of dev that m asks for (its number), or -1. */
static int match_interface(const struct usblib *u, libusb_device *dev, const struct usb_match *m)
{
  struct libusb_config_descriptor *cfg;
  if (u->libusb_get_active_config_descriptor(dev, &cfg) != 0 &&
      u->libusb_get_config_descriptor(dev, 0, &cfg) != 0)
    return -1;
  int found = -1;
  for (int i = 0; i < cfg->bNumInterfaces && found < 0; i++) {
    const struct libusb_interface *itf = &cfg->interface[i];
    for (int a = 0; a < itf->num_altsetting && found < 0; a++) {
      const struct libusb_interface_descriptor *d = &itf->altsetting[a];
      if (m->iface_class < 0 ? d->bInterfaceNumber == 0 : d->bInterfaceClass == m->iface_class)
        found = d->bInterfaceNumber;
    }
  }
  u->libusb_free_config_descriptor(cfg);
  return found;
}

static int device_matches(const struct usblib *u, libusb_device *dev, const struct usb_match *m,
                          int *iface)
{
  struct libusb_device_descriptor dd;
  if (u->libusb_get_device_descriptor(dev, &dd) != 0) return 0;
  if ((m->vid || m->pid) && (dd.idVendor != m->vid || dd.idProduct != m->pid)) return 0;
  if (!m->vid && !m->pid && m->iface_class < 0) return 0;   /* nothing to match by */
  *iface = match_interface(u, dev, m);
  return *iface >= 0;
}

/* Record the endpoints of the claimed interface's selected alt setting. */
static void find_endpoints(struct usb_link *l)
{
  l->ep_bulk_in = l->ep_bulk_out = l->ep_int_in = l->ep_int_out = -1;
  struct libusb_config_descriptor *cfg;
  if (l->u.libusb_get_active_config_descriptor(l->u.libusb_get_device(l->h), &cfg) != 0) return;
  for (int i = 0; i < cfg->bNumInterfaces; i++) {
    const struct libusb_interface *itf = &cfg->interface[i];
    for (int a = 0; a < itf->num_altsetting; a++) {
      const struct libusb_interface_descriptor *d = &itf->altsetting[a];
      if (d->bInterfaceNumber != l->iface || d->bAlternateSetting != (l->alt < 0 ? 0 : l->alt))
        continue;
      for (int e = 0; e < d->bNumEndpoints; e++) {
        const struct libusb_endpoint_descriptor *ep = &d->endpoint[e];
        int in = (ep->bEndpointAddress & LIBUSB_ENDPOINT_IN) != 0;
        int type = ep->bmAttributes & 3;
        int *slot = type == LIBUSB_TRANSFER_TYPE_BULK ? (in ? &l->ep_bulk_in : &l->ep_bulk_out)
                  : type == LIBUSB_TRANSFER_TYPE_INTERRUPT ? (in ? &l->ep_int_in : &l->ep_int_out)
                  : NULL;
        if (slot && *slot < 0) *slot = ep->bEndpointAddress;
      }
    }
  }
  l->u.libusb_free_config_descriptor(cfg);
}

int usb_link_open(struct usb_link **out, const struct usb_match *m, const char *profile,
                  const struct usb_settings *s, struct t74_error *err)
{
  return usb_link_open_at(out, m, -1, -1, profile, s, err);
}

int usb_link_open_at(struct usb_link **out, const struct usb_match *m, int bus, int address,
                     const char *profile, const struct usb_settings *s, struct t74_error *err)
{
  *out = NULL;
  struct usb_link *l = calloc(1, sizeof *l);
  if (!l) return t74_fail(err, T74_EIO, "%s: out of memory", profile);
  l->profile = profile;
  l->timeout_ms = (int)s->link[USB_P_TIMEOUT];
  l->retries = (int)s->link[USB_P_RETRIES];
  l->backoff_ms = (int)s->link[USB_P_BACKOFF];
  if (usblib_load(&l->u, profile, err) != T74_OK) {
    free(l);
    return err->status;
  }
  int r = l->u.libusb_init(&l->ctx);
  if (r != 0) {
    t74_fail(err, T74_EIO, "%s: cannot start libusb: %s", profile, l->u.libusb_error_name(r));
    dynlib_close(&l->u, sizeof l->u);
    free(l);
    return err->status;
  }
  libusb_device **list;
  ssize_t n = l->u.libusb_get_device_list(l->ctx, &list);
  if (n < 0) {
    t74_fail(err, T74_EIO, "%s: cannot list USB devices: %s", profile,
             l->u.libusb_error_name((int)n));
    usb_link_close(l);
    return err->status;
  }
  libusb_device *dev = NULL;
  for (ssize_t i = 0; i < n && !dev; i++)
    if ((bus < 0 || (l->u.libusb_get_bus_number(list[i]) == bus &&
                     l->u.libusb_get_device_address(list[i]) == address)) &&
        device_matches(&l->u, list[i], m, &l->iface))
      dev = list[i];
  if (!dev) {
    l->u.libusb_free_device_list(list, 1);
    usb_link_close(l);
    if (m->vid || m->pid)
      return t74_fail(err, T74_EIO, "%s: no USB device %04x:%04x is connected "
                      "(`tube74 devices` lists what is)", profile, m->vid, m->pid);
    return t74_fail(err, T74_EIO, "%s: no USB device with a class-%d interface is connected "
                    "(`tube74 devices` lists what is)", profile, m->iface_class);
  }
  struct libusb_device_descriptor dd;
  l->u.libusb_get_device_descriptor(dev, &dd);
  l->vid = dd.idVendor;
  l->pid = dd.idProduct;
  r = l->u.libusb_open(dev, &l->h);
  l->u.libusb_free_device_list(list, 1);
  if (r != 0) {
    char rule[256];
    usb_udev_rule(rule, sizeof rule, l->vid, l->pid);
    if (r == LIBUSB_ERROR_ACCESS)
      t74_fail(err, T74_EIO,
               "%s: permission denied opening USB device %04x:%04x. Give your user "
               "access with a udev rule: put this line in "
               "/etc/udev/rules.d/70-tube74.rules\n  %s\nthen run `sudo udevadm control "
               "--reload && sudo udevadm trigger` and plug the device in again",
               profile, dd.idVendor, dd.idProduct, rule);
    else
      t74_fail(err, T74_EIO, "%s: cannot open USB device %04x:%04x: %s", profile,
               dd.idVendor, dd.idProduct, l->u.libusb_error_name(r));
    l->h = NULL;
    usb_link_close(l);                  /* (libusb's strings go with it: the message first) */
    return err->status;
  }
  /* A kernel driver (usblp for printers, cdc_acm for the EBB) may own the interface. Note
     every interface that has one now: detaching cdc_acm from its data interface unbinds it
     from the communication interface too (Linux drivers/usb/class/cdc-acm.c, acm_disconnect
     releases both), and only a probe of the communication interface binds it again. */
  struct libusb_config_descriptor *cfg;
  if (l->u.libusb_get_active_config_descriptor(l->u.libusb_get_device(l->h), &cfg) == 0) {
    for (int i = 0; i < cfg->bNumInterfaces && i < 32; i++) {
      int num = cfg->interface[i].altsetting[0].bInterfaceNumber;
      if (num < 32 && l->u.libusb_kernel_driver_active(l->h, num) == 1)
        l->had_driver |= 1u << num;
    }
    l->u.libusb_free_config_descriptor(cfg);
  }
  r = l->u.libusb_kernel_driver_active(l->h, l->iface);
  if (r == 1) {
    r = l->u.libusb_detach_kernel_driver(l->h, l->iface);
    if (r != 0 && r != LIBUSB_ERROR_NOT_FOUND) {
      int st = t74_fail(err, T74_EIO, "%s: cannot detach the kernel driver from interface %d "
                        "of %04x:%04x: %s", profile, l->iface, l->vid, l->pid,
                        l->u.libusb_error_name(r));
      usb_link_close(l);
      return st;
    }
  }
  r = l->u.libusb_claim_interface(l->h, l->iface);
  if (r != 0) {
    int st = t74_fail(err, T74_EIO, "%s: cannot claim interface %d of %04x:%04x: %s%s", profile,
                      l->iface, l->vid, l->pid, l->u.libusb_error_name(r),
                      r == LIBUSB_ERROR_BUSY ? " (another program is using it)" : "");
    usb_link_close(l);
    return st;
  }
  l->alt = m->alt;
  if (m->alt >= 0 && (r = l->u.libusb_set_interface_alt_setting(l->h, l->iface, m->alt)) != 0) {
    int st = t74_fail(err, T74_EIO, "%s: cannot select alternate setting %d: %s", profile,
                      m->alt, l->u.libusb_error_name(r));
    usb_link_close(l);
    return st;
  }
  find_endpoints(l);
  snprintf(l->name, sizeof l->name, "%04x:%04x", l->vid, l->pid);
  *out = l;
  return T74_OK;
}

/* A link that is not libusb: the common fields. */
static struct usb_link *other_link(enum usb_link_kind kind, const char *profile,
                                   const struct usb_settings *s)
{
  struct usb_link *l = calloc(1, sizeof *l);
  if (!l) return NULL;
  l->kind = kind;
  l->profile = profile;
  l->timeout_ms = (int)s->link[USB_P_TIMEOUT];
  l->retries = (int)s->link[USB_P_RETRIES];
  l->backoff_ms = (int)s->link[USB_P_BACKOFF];
  l->baud = s->link[USB_P_BAUD];
  l->ep_bulk_out = 0x01;                        /* the line out / the file */
  l->ep_bulk_in = kind == USB_LINK_SERIAL ? 0x81 : -1;   /* what the device sends */
  l->ep_int_in = l->ep_int_out = -1;
  return l;
}

int usb_link_open_serial(struct usb_link **out, const char *path, const char *profile,
                         const struct usb_settings *s, struct t74_error *err)
{
  *out = NULL;
  struct usb_link *l = other_link(USB_LINK_SERIAL, profile, s);
  if (!l) return t74_fail(err, T74_EIO, "%s: out of memory", profile);
  struct serial_opts so = { (long)s->link[USB_P_BAUD], (int)s->link[USB_P_FLOW],
                            (int)s->link[USB_P_PACE] };
  if (serial_open(&l->ser, path, &so, err) != T74_OK) {
    free(l);
    return err->status;
  }
  l->flow = so.flow;
  snprintf(l->name, sizeof l->name, "%s", path);
  *out = l;
  return T74_OK;
}

int usb_link_open_file(struct usb_link **out, struct outfile *to, int line, const char *profile,
                       const struct usb_settings *s, struct t74_error *err)
{
  *out = NULL;
  struct usb_link *l = other_link(USB_LINK_FILE, profile, s);
  if (!l) return t74_fail(err, T74_EIO, "%s: out of memory", profile);
  l->to = to;
  l->line = line;
  snprintf(l->name, sizeof l->name, "%s", to ? outfile_path(to) : "nowhere (dry run)");
  *out = l;
  return T74_OK;
}

enum usb_link_kind usb_link_kind(const struct usb_link *l) { return l->kind; }
const char *usb_link_name(const struct usb_link *l) { return l->name; }
struct usb_tally *usb_link_tally(struct usb_link *l) { return &l->tally; }
void usb_link_set_preview(struct usb_link *l, struct preview *p) { l->preview = p; }
struct preview *usb_link_preview(const struct usb_link *l) { return l->preview; }
int usb_link_flow(const struct usb_link *l) { return l->kind == USB_LINK_SERIAL ? l->flow : 0; }

/* One transfer on a serial or file link (no control transfers there). */
static int other_transfer(struct usb_link *l, enum usb_type type, unsigned char ep, void *buf,
                          int len, int timeout_ms, int *done, struct t74_error *err)
{
  int d = 0, st = T74_OK;
  if (done) *done = 0;
  if (type == USB_CONTROL)
    return t74_fail(err, T74_EIO, "%s: %s has no USB control requests", l->profile, l->name);
  if (!(ep & 0x80)) {                           /* out */
    if (l->kind == USB_LINK_FILE) {
      if (l->to && len > 0) st = outfile_write(l->to, buf, (size_t)len);
      if (st != T74_OK) st = t74_fail(err, T74_EIO, "%s: cannot write", outfile_path(l->to));
      d = st == T74_OK ? len : 0;
    } else {
      st = serial_write(l->ser, buf, len, timeout_ms, l->stop, &d, err);
    }
    l->counts.bytes_out += d;
    l->tally.bytes += d;
    if ((l->kind == USB_LINK_SERIAL || l->line) && l->baud > 0) l->tally.line_s += d * 10.0 / l->baud;
    if (st == T74_OK) l->counts.transfers++;
  } else if (l->kind == USB_LINK_SERIAL) {      /* in: what the device sent */
    st = serial_read(l->ser, buf, len, timeout_ms, &d, err);
    l->counts.bytes_in += d;
  }
  if (done) *done = d;
  return st;
}

void usb_link_close(struct usb_link *l)
{
  if (!l) return;
  if (l->kind != USB_LINK_USB) {
    serial_close(l->ser);                       /* NULL-safe; a file link's output is the stream's */
    free(l);
    return;
  }
  if (l->h) {
    if (!l->gone) {
      l->u.libusb_release_interface(l->h, l->iface);
      /* every interface that had a driver and has none now, lowest first: the CDC
         communication interface (0) rebinds cdc_acm to both, so /dev/ttyACM returns */
      for (int i = 0; i < 32; i++)
        if ((l->had_driver >> i & 1) && l->u.libusb_kernel_driver_active(l->h, i) == 0)
          l->u.libusb_attach_kernel_driver(l->h, i);
    }
    l->u.libusb_close(l->h);
  }
  if (l->ctx) l->u.libusb_exit(l->ctx);
  dynlib_close(&l->u, sizeof l->u);
  free(l);
}

int usb_link_endpoint(const struct usb_link *l, enum usb_type type, int in)
{
  if (type == USB_BULK) return in ? l->ep_bulk_in : l->ep_bulk_out;
  if (type == USB_INTERRUPT) return in ? l->ep_int_in : l->ep_int_out;
  return 0;
}

int usb_link_interface(const struct usb_link *l) { return l->iface; }
int usb_link_alt(const struct usb_link *l) { return l->alt < 0 ? 0 : l->alt; }
void usb_link_set_stop(struct usb_link *l, volatile sig_atomic_t *stop) { l->stop = stop; }
int usb_link_stopped(const struct usb_link *l) { return l->stop && *l->stop; }
double usb_link_timeout_ms(const struct usb_link *l) { return l->timeout_ms; }
int usb_link_gone(const struct usb_link *l)
{
  return l->kind == USB_LINK_SERIAL ? serial_gone(l->ser) : l->gone;
}
const struct usb_counts *usb_link_counts(const struct usb_link *l) { return &l->counts; }

void usb_link_ids(const struct usb_link *l, uint16_t *vid, uint16_t *pid)
{
  *vid = l->vid;
  *pid = l->pid;
}

/* ---- transfers -------------------------------------------------------------------- */

static void LIBUSB_CALL on_done(struct libusb_transfer *t)
{
  struct usb_xfer *x = t->user_data;
  x->completed = 1;
}

static const char *type_name(enum usb_type t)
{
  return t == USB_CONTROL ? "control" : t == USB_BULK ? "bulk" : "interrupt";
}

/* (Re)submit the part of x not yet moved. */
static int submit_rest(struct usb_link *l, struct usb_xfer *x, struct t74_error *err)
{
  struct libusb_transfer *t = x->t;
  x->completed = 0;
  if (x->type == USB_CONTROL) {
    /* a control transfer is never split: setup packet + data, all again */
    libusb_fill_control_transfer(t, l->h, x->buf, on_done, x, (unsigned)l->timeout_ms);
  } else {
    unsigned timeout = (unsigned)l->timeout_ms;
    if (x->type == USB_BULK)
      libusb_fill_bulk_transfer(t, l->h, x->ep, x->buf + x->done, x->len - x->done, on_done, x, timeout);
    else
      libusb_fill_interrupt_transfer(t, l->h, x->ep, x->buf + x->done, x->len - x->done, on_done, x, timeout);
  }
  int r = l->u.libusb_submit_transfer(t);
  if (r == 0) { x->busy = 1; return T74_OK; }
  x->busy = 0;
  if (r == LIBUSB_ERROR_NO_DEVICE) l->gone = 1;
  return t74_fail(err, T74_EIO, "%s: %s", l->profile,
                  r == LIBUSB_ERROR_NO_DEVICE
                    ? "the USB device vanished (unplugged or powered off)"
                    : l->u.libusb_error_name(r));
}

int usb_submit(struct usb_link *l, struct usb_xfer *x, enum usb_type type, unsigned char ep,
               void *buf, int len, struct t74_error *err)
{
  if (l->kind != USB_LINK_USB) {                /* done at once: usb_wait has nothing to wait */
    x->type = type;
    x->ep = ep;
    x->buf = buf;
    x->len = len;
    x->busy = 0;
    return other_transfer(l, type, ep, buf, len, l->timeout_ms, &x->done, err);
  }
  if (!x->t && !(x->t = l->u.libusb_alloc_transfer(0)))
    return t74_fail(err, T74_EIO, "%s: out of memory", l->profile);
  x->type = type;
  x->ep = ep;
  x->buf = buf;
  x->len = len;
  x->done = 0;
  x->tries = 0;
  x->stalls = 0;
  if (l->gone) return t74_fail(err, T74_EIO, "%s: the USB device vanished", l->profile);
  return submit_rest(l, x, err);
}

/* Handle libusb events until x completes. */
static void await(struct usb_link *l, struct usb_xfer *x)
{
  while (!x->completed) {
    struct timeval tv = { 0, 100000 };
    int c = 0;
    /* an interrupted poll (SIGINT) returns LIBUSB_ERROR_INTERRUPTED: keep waiting, the
       transfer ends by itself (completion or timeout) and the caller checks the flag */
    l->u.libusb_handle_events_timeout_completed(l->ctx, &tv, &c);
  }
  x->busy = 0;
}

int usb_wait(struct usb_link *l, struct usb_xfer *x, int *done, struct t74_error *err)
{
  if (done) *done = x->done;
  if (!x->busy) return T74_OK;
  for (;;) {
    await(l, x);
    struct libusb_transfer *t = x->t;
    int moved = t->actual_length;
    if (x->type != USB_CONTROL) x->done += moved;
    else x->done = moved;                       /* control: data bytes of the last try */
    if (x->ep & LIBUSB_ENDPOINT_IN || x->type == USB_CONTROL) l->counts.bytes_in += moved;
    else {
      l->counts.bytes_out += moved;
      l->tally.bytes += moved;
    }
    if (done) *done = x->done;
    int in = (x->ep & LIBUSB_ENDPOINT_IN) != 0;
    switch (t->status) {
    case LIBUSB_TRANSFER_COMPLETED:
      l->counts.transfers++;
      /* an OUT transfer is complete when everything went; an IN transfer may be short */
      if (x->type == USB_CONTROL || in || x->done >= x->len) return T74_OK;
      break;                                    /* (never seen: libusb completes fully) */
    case LIBUSB_TRANSFER_NO_DEVICE:
      l->gone = 1;
      return t74_fail(err, T74_EIO, "%s: the USB device %04x:%04x vanished during a %s "
                      "transfer (unplugged or powered off)", l->profile, l->vid, l->pid,
                      type_name(x->type));
    case LIBUSB_TRANSFER_STALL: {
      l->counts.stalls++;
      if (++x->stalls > l->retries + 1)
        return t74_fail(err, T74_EIO, "%s: endpoint 0x%02x stalled %d times in a row", l->profile,
                        x->ep, x->stalls);
      if (x->type != USB_CONTROL) {
        int r = l->u.libusb_clear_halt(l->h, x->ep);
        if (r == LIBUSB_ERROR_NO_DEVICE) {
          l->gone = 1;
          return t74_fail(err, T74_EIO, "%s: the USB device vanished while clearing a stall",
                          l->profile);
        }
        if (r != 0)
          return t74_fail(err, T74_EIO, "%s: cannot clear the stall on endpoint 0x%02x: %s",
                          l->profile, x->ep, l->u.libusb_error_name(r));
      } else {
        /* a stalled control request is the device refusing it: no retry helps */
        return t74_fail(err, T74_EIO, "%s: the device refused control request 0x%02x",
                        l->profile, x->buf[1]);
      }
      if (in && x->done > 0) return T74_OK;     /* data came before the stall: take it */
      break;
    }
    case LIBUSB_TRANSFER_TIMED_OUT:
    default:
      if (t->status == LIBUSB_TRANSFER_TIMED_OUT) l->counts.timeouts++;
      else l->counts.errors++;
      if (in && x->done > 0 && x->type != USB_CONTROL) return T74_OK;  /* partial reply */
      /* bytes moved in this try: the device is slow, not stuck; only tries in a row that
         move nothing count towards giving up, and no pause is needed */
      if (!in && x->type != USB_CONTROL && x->done >= x->len) return T74_OK;  /* all went */
      if (moved > 0 && x->type != USB_CONTROL) {
        x->tries = 0;
        break;
      }
      if (++x->tries > l->retries)
        return t74_fail(err, T74_EIO, "%s: %s transfer on endpoint 0x%02x %s %d times "
                        "(%d ms each, backoff from %d ms); giving up", l->profile,
                        type_name(x->type), x->ep,
                        t->status == LIBUSB_TRANSFER_TIMED_OUT ? "timed out" : "failed",
                        x->tries, l->timeout_ms, l->backoff_ms);
      usb_sleep_ms((double)l->backoff_ms * (double)(1 << (x->tries - 1 < 16 ? x->tries - 1 : 16)));
      break;
    }
    if (submit_rest(l, x, err) != T74_OK) return err->status;
  }
}

int usb_read_once(struct usb_link *l, enum usb_type type, unsigned char ep, void *buf, int len,
                  int timeout_ms, int *got, struct t74_error *err)
{
  *got = 0;
  if (l->kind != USB_LINK_USB) return other_transfer(l, type, ep | 0x80, buf, len, timeout_ms, got, err);
  if (l->gone) return t74_fail(err, T74_EIO, "%s: the USB device vanished", l->profile);
  struct usb_xfer x;
  memset(&x, 0, sizeof x);
  if (!(x.t = l->u.libusb_alloc_transfer(0)))
    return t74_fail(err, T74_EIO, "%s: out of memory", l->profile);
  struct libusb_transfer *t = x.t;
  if (type == USB_BULK)
    libusb_fill_bulk_transfer(t, l->h, ep, buf, len, on_done, &x, (unsigned)timeout_ms);
  else
    libusb_fill_interrupt_transfer(t, l->h, ep, buf, len, on_done, &x, (unsigned)timeout_ms);
  int r = l->u.libusb_submit_transfer(t);
  if (r != 0) {
    l->u.libusb_free_transfer(t);
    if (r == LIBUSB_ERROR_NO_DEVICE) l->gone = 1;
    return t74_fail(err, T74_EIO, "%s: %s", l->profile, r == LIBUSB_ERROR_NO_DEVICE
                    ? "the USB device vanished (unplugged or powered off)"
                    : l->u.libusb_error_name(r));
  }
  x.busy = 1;
  await(l, &x);
  int st = T74_OK;
  *got = t->actual_length;
  l->counts.bytes_in += t->actual_length;
  if (t->status == LIBUSB_TRANSFER_COMPLETED) l->counts.transfers++;
  else if (t->status == LIBUSB_TRANSFER_TIMED_OUT) { /* nothing came: *got says so */ }
  else if (t->status == LIBUSB_TRANSFER_NO_DEVICE) {
    l->gone = 1;
    st = t74_fail(err, T74_EIO, "%s: the USB device %04x:%04x vanished during a %s transfer "
                  "(unplugged or powered off)", l->profile, l->vid, l->pid, type_name(type));
  } else if (t->status == LIBUSB_TRANSFER_STALL) {
    l->counts.stalls++;
    l->u.libusb_clear_halt(l->h, ep);
  } else l->counts.errors++;
  l->u.libusb_free_transfer(t);
  return st;
}

void usb_xfer_free(struct usb_link *l, struct usb_xfer *x)
{
  if (x->t && !x->busy) l->u.libusb_free_transfer(x->t);   /* (other links never allocate one) */
  x->t = NULL;
}

int usb_transfer(struct usb_link *l, enum usb_type type, unsigned char ep, void *buf,
                 int len, int *done, struct t74_error *err)
{
  if (l->kind != USB_LINK_USB) return other_transfer(l, type, ep, buf, len, l->timeout_ms, done, err);
  struct usb_xfer x;
  memset(&x, 0, sizeof x);
  int st = usb_submit(l, &x, type, ep, buf, len, err);
  if (st == T74_OK) st = usb_wait(l, &x, done, err);
  else if (done) *done = 0;
  if (x.t) l->u.libusb_free_transfer(x.t);
  return st;
}

int usb_control_in(struct usb_link *l, uint8_t bmRequestType, uint8_t bRequest,
                   uint16_t wValue, uint16_t wIndex, void *buf, int len, int *got,
                   struct t74_error *err)
{
  unsigned char tb[LIBUSB_CONTROL_SETUP_SIZE + 256];
  if (got) *got = 0;
  if (l->kind != USB_LINK_USB)
    return t74_fail(err, T74_EIO, "%s: %s has no USB control requests", l->profile, l->name);
  if (len > 256) len = 256;
  libusb_fill_control_setup(tb, bmRequestType, bRequest, wValue, wIndex, (uint16_t)len);
  int done = 0;
  int st = usb_transfer(l, USB_CONTROL, 0, tb, LIBUSB_CONTROL_SETUP_SIZE + len, &done, err);
  if (st == T74_OK) memcpy(buf, tb + LIBUSB_CONTROL_SETUP_SIZE, (size_t)done);
  if (got) *got = st == T74_OK ? done : 0;
  return st;
}

/* ---- profiles and their settings ---------------------------------------------------- */

const struct usb_profile *const usb_profiles[] = {
  &usb_profile_hpgl, &usb_profile_ebb, &usb_profile_helios, &usb_profile_tek, NULL
};

const struct usb_profile *usb_profile_find(const char *name)
{
  for (int k = 0; usb_profiles[k]; k++)
    if (!strcmp(usb_profiles[k]->name, name)) return usb_profiles[k];
  return NULL;
}

void usb_settings_default(struct usb_settings *s, const struct usb_profile *p)
{
  memset(s, 0, sizeof *s);
  param_defaults(usb_link_params, USB_NLINK, s->link);
  param_defaults(p->params, p->nparams < USB_MAX_PARAMS ? p->nparams : USB_MAX_PARAMS, s->p);
}

int usb_settings_set(struct usb_settings *s, const struct usb_profile *p, const char *kv,
                     struct t74_error *err)
{
  const char *eq = strchr(kv, '=');
  if (!eq || eq == kv || !eq[1])
    return t74_fail(err, T74_EINPUT, "tube74: --set takes NAME=VALUE: %s", kv);
  size_t n = (size_t)(eq - kv);
  const struct param_row *row;
  double *slot;
  int k = param_find(p->params, p->nparams, kv, n);
  if (k >= 0) {
    row = &p->params[k];
    slot = &s->p[k];
  } else if ((k = param_find(usb_link_params, USB_NLINK, kv, n)) >= 0) {
    row = &usb_link_params[k];
    slot = &s->link[k];
  } else {
    return t74_fail(err, T74_EINPUT, "tube74: the %s profile has no setting `%.*s` "
                    "(`tube74 stream --device %s --settings` lists them)", p->name, (int)n, kv,
                    p->name);
  }
  if (param_parse(row, eq + 1, slot) != PARAM_OK)
    return t74_fail(err, T74_EINPUT, "tube74: %s takes a number from %g to %g: %s", row->name,
                    row->min, row->max, eq + 1);
  return T74_OK;
}

double usb_setting(const struct usb_settings *s, const struct usb_profile *p, const char *name)
{
  int k = param_find(p->params, p->nparams, name, strlen(name));
  if (k >= 0) return s->p[k];
  k = param_find(usb_link_params, USB_NLINK, name, strlen(name));
  return k >= 0 ? s->link[k] : 0;
}

void usb_settings_list(const struct usb_settings *s, const struct usb_profile *p, FILE *f)
{
  fprintf(f, "%s: %s\n%-18s %12s  %-12s %s\n", p->name, p->what, "setting", "value", "unit",
          "source");
  param_list(p->params, p->nparams, s->p, 18, f);
  param_list(usb_link_params, USB_NLINK, s->link, 18, f);
}

int usb_list_devices(FILE *f, const struct usb_profile *only, struct t74_error *err)
{
  struct usblib u;
  if (usblib_load(&u, "devices", err) != T74_OK) return -1;
  libusb_context *ctx;
  int r = u.libusb_init(&ctx);
  if (r != 0) {
    t74_fail(err, T74_EIO, "devices: cannot start libusb: %s", u.libusb_error_name(r));
    dynlib_close(&u, sizeof u);
    return -1;
  }
  libusb_device **list;
  ssize_t n = u.libusb_get_device_list(ctx, &list);
  if (n < 0) {
    t74_fail(err, T74_EIO, "devices: cannot list USB devices: %s", u.libusb_error_name((int)n));
    u.libusb_exit(ctx);
    dynlib_close(&u, sizeof u);
    return -1;
  }
  int shown = 0;
  for (ssize_t i = 0; i < n; i++) {
    for (int k = 0; usb_profiles[k]; k++) {
      const struct usb_profile *p = usb_profiles[k];
      int iface;
      if (only && p != only) continue;
      if (!device_matches(&u, list[i], &p->match, &iface)) continue;
      struct libusb_device_descriptor dd;
      u.libusb_get_device_descriptor(list[i], &dd);
      fprintf(f, "%-7s %04x:%04x  bus %03u device %03u  interface %d  %s", p->name,
              dd.idVendor, dd.idProduct, u.libusb_get_bus_number(list[i]),
              u.libusb_get_device_address(list[i]), iface, p->what);
      if (p->note) {            /* what the device says of itself, on a link of its own */
        char note[160] = "";
        struct usb_settings us;
        usb_settings_default(&us, p);
        struct usb_link *l = NULL;
        struct t74_error e = { T74_OK, "" };
        if (usb_link_open_at(&l, &p->match, u.libusb_get_bus_number(list[i]),
                             u.libusb_get_device_address(list[i]), p->name, &us, &e) == T74_OK) {
          p->note(l, note, sizeof note);
          usb_link_close(l);
        } else {
          snprintf(note, sizeof note, "not opened (%s)",
                   strstr(e.msg, "permission denied") ? "permission denied" : "see `tube74 stream`");
        }
        if (note[0]) fprintf(f, "; %s", note);
      }
      fputc('\n', f);
      shown++;
    }
  }
  u.libusb_free_device_list(list, 1);
  u.libusb_exit(ctx);
  dynlib_close(&u, sizeof u);
  return shown;
}
