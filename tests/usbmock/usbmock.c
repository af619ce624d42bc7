/*
** usbmock.c — an emulated USB device for the USB profile tests (umockdev testbed + usbdevfs
** ioctl handler), #included by each tests/test_usb_*.c (the Makefile links no helpers).
**
** This file contains code to play a USB device to libusb. Hardware source: shared/notes/
** usb-testing.md and its proven example (umockdev: a testbed device whose /dev node is
** answered by an ioctl handler on umockdev's worker thread); Linux usbdevfs (<linux/
** usbdevice_fs.h>) for the URB life cycle: SUBMITURB, then REAPURB(NDELAY) hands back the
** finished URB; DISCARDURB cancels one (status -ENOENT); status -EPIPE is a stall, -ENODEV a
** vanished device.
**
** The mock keeps byte streams per endpoint and leaves the protocol to the test: on_out gets
** every byte the host sends (OUT URBs, in order), on_ctrl answers control requests, and the
** test queues replies with mock_reply(); an IN URB is answered from that queue, or stays
** pending until data arrives (or the host gives up and discards it). on_in_done tells the
** test how many reply bytes reached the host: only then does a protocol count a command as
** acknowledged. Faults, set before or during a run (under m->lock):
**   delay_us        each OUT URB completes this long after submission (a slow device)
**   stall_at        the N-th OUT URB stalls (-EPIPE, no data taken); cleared by CLEAR_HALT
**   hold_from/n     OUT URBs N .. N+n-1 never complete (the host times out, discards them)
**   vanish_after    the device disappears once it has taken this many OUT bytes: the URB
**                   that crosses it takes the bytes up to it and ends -ENODEV; every later
**                   ioctl fails with ENODEV
**   vanish_in_at    the device disappears instead of answering the N-th IN URB
**   caps            GET_CAPABILITIES (default: one URB per transfer; BULK_CONTINUATION only
**                   makes libusb split bulk transfers into 16 KiB URBs)
** All state is guarded by m->lock: the handler runs on umockdev's worker thread.
*/
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <linux/usbdevice_fs.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <umockdev.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#define MOCK_NODE "/dev/bus/usb/001/002"

/* Not every test uses every helper. */
#if defined(__GNUC__)
#define MOCK_UNUSED __attribute__((unused))
#else
#define MOCK_UNUSED
#endif

struct mock;
typedef void (*mock_out_fn)(struct mock *m, unsigned char ep, const unsigned char *b, int n);
typedef int (*mock_ctrl_fn)(struct mock *m, const unsigned char *setup, unsigned char *data, int n);
typedef void (*mock_in_fn)(struct mock *m, unsigned char ep, int n);
typedef void (*mock_tick_fn)(struct mock *m);

struct mock_urb {               /* a URB the device holds */
  UMockdevIoctlData *urb;       /* the usbdevfs_urb (client memory, resolved) */
  UMockdevIoctlData *buf;       /* its buffer */
  double due;                   /* complete at this time (slow device), 0 = now */
};

struct mock {
  UMockdevTestbed *tb;
  UMockdevIoctlBase *handler;
  GMutex lock;
  GQueue reapable;              /* struct mock_urb*: finished, waiting for REAPURB */
  GQueue delayed;               /* finished later (delay_us) */
  GQueue pending_in;            /* IN URBs waiting for reply bytes */
  GQueue held;                  /* OUT URBs never completed (timeouts) */
  GByteArray *reply[16];        /* reply bytes per IN endpoint number */
  GQueue packets[16];           /* ... cut into the packets the device sent (lengths): an
                                   IN URB ends with the first short packet (USB 2.0 5.8.3),
                                   so one reply never runs into the next */
  /* behaviour */
  guint32 caps;
  int delay_us;
  int stall_at;
  int hold_from, hold_n;
  int trickle_bytes, trickle_urbs;  /* the first trickle_urbs OUT URBs take only trickle_bytes
                                   each and then hang until the host times out (a slow device
                                   that NAKs after a few packets: bytes move, the URB ends in
                                   a timeout with actual_length = what was taken) */
  long long vanish_after;       /* -1: never */
  int vanish_in_at;             /* 0: never */
  int gone;
  /* kernel drivers, per interface, as Linux binds them (drivers/usb/core/devio.c: CLAIM of a
     bound interface is EBUSY; USBDEVFS_CONNECT probes an unbound, unclaimed interface) */
  char drv[4][16];              /* the driver bound to interface i now, "" none */
  char probe[4][16];            /* the driver a probe of interface i binds, "" none */
  unsigned probe_also[4];       /* ... binding these interfaces too (cdc_acm: comm -> data) */
  unsigned unbind_also[4];      /* unbinding i unbinds these too (cdc_acm: acm_disconnect
                                   releases both interfaces of the pair) */
  int claimed[4];               /* claimed by the host (usbfs) */
  /* counts */
  int out_urbs, in_urbs, ctrl_urbs, clear_halts, discards, detaches, attaches, max_urb;
  long long out_bytes;
  double t_first_out;           /* when the first OUT byte on a bulk endpoint arrived */
  /* the protocol (the test's) */
  mock_out_fn on_out;
  mock_ctrl_fn on_ctrl;
  mock_in_fn on_in_done;
  mock_tick_fn on_tick;         /* called at every ioctl (under the lock): a device with its
                                   own clock (the EBB's motion queue) catches up */
  void *user;
  int test_holds;               /* the test thread holds lock (mock_lock): a failed assertion
                                   jumps out holding it; mock_reset lets it go */
};

/* The test thread's side of the lock. */
#define mock_lock(m) do { g_mutex_lock(&(m)->lock); (m)->test_holds = 1; } while (0)
#define mock_unlock(m) do { (m)->test_holds = 0; g_mutex_unlock(&(m)->lock); } while (0)

MOCK_UNUSED static double mock_now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Queue reply bytes as a byte stream (a CDC serial line): they join the last packet not yet
** taken by the host while it has room (64 bytes, a full-speed bulk packet), as a device's
** transmit buffer fills its next IN packet. Lock held. */
MOCK_UNUSED static void mock_reply_stream(struct mock *m, unsigned char ep, const void *b, int n)
{
  GQueue *pk = &m->packets[ep & 15];
  if (n > 0 && pk->tail && GPOINTER_TO_INT(pk->tail->data) + n <= 64) {
    g_byte_array_append(m->reply[ep & 15], b, (guint)n);
    pk->tail->data = GINT_TO_POINTER(GPOINTER_TO_INT(pk->tail->data) + n);
    return;
  }
  if (n <= 0) return;
  g_byte_array_append(m->reply[ep & 15], b, (guint)n);
  g_queue_push_tail(pk, GINT_TO_POINTER(n));
}

/* Queue reply bytes on IN endpoint ep (call with the lock held: from on_out / on_ctrl). */
MOCK_UNUSED static void mock_reply(struct mock *m, unsigned char ep, const void *b, int n)
{
  if (n <= 0) return;
  g_byte_array_append(m->reply[ep & 15], b, (guint)n);
  g_queue_push_tail(&m->packets[ep & 15], GINT_TO_POINTER(n));
}

MOCK_UNUSED static void urb_free(struct mock_urb *u)
{
  g_object_unref(u->buf);
  g_object_unref(u->urb);
  g_free(u);
}

MOCK_UNUSED static struct usbdevfs_urb *U(struct mock_urb *u) { return (struct usbdevfs_urb *)u->urb->data; }

/* The device vanishes: every URB it holds ends with -ENODEV. */
MOCK_UNUSED static void vanish(struct mock *m)
{
  m->gone = 1;
  GQueue *qs[3] = { &m->pending_in, &m->held, &m->delayed };
  for (int q = 0; q < 3; q++) {
    struct mock_urb *u;
    while ((u = g_queue_pop_head(qs[q]))) {
      U(u)->status = -ENODEV;
      g_queue_push_tail(&m->reapable, u);
    }
  }
}

/* Answer pending IN URBs from the reply queues. */
MOCK_UNUSED static void pump(struct mock *m)
{
  for (GList *l = m->pending_in.head; l;) {
    GList *next = l->next;
    struct mock_urb *u = l->data;
    struct usbdevfs_urb *urb = U(u);
    GByteArray *q = m->reply[urb->endpoint & 15];
    GQueue *pk = &m->packets[urb->endpoint & 15];
    if (q->len > 0) {
      m->in_urbs++;
      if (m->vanish_in_at && m->in_urbs == m->vanish_in_at) { vanish(m); return; }
      int plen = GPOINTER_TO_INT(g_queue_pop_head(pk));
      int n = MIN(urb->buffer_length, plen);
      if (n < plen) g_queue_push_head(pk, GINT_TO_POINTER(plen - n));   /* the rest: next URB */
      memcpy(u->buf->data, q->data, (size_t)n);
      g_byte_array_remove_range(q, 0, (guint)n);
      urb->actual_length = n;
      urb->status = 0;
      g_queue_delete_link(&m->pending_in, l);
      g_queue_push_tail(&m->reapable, u);
      if (m->on_in_done) m->on_in_done(m, urb->endpoint, n);
    }
    l = next;
  }
}

static gboolean mock_ioctl(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer ud)
{
  struct mock *m = ud;
  gulong req = umockdev_ioctl_client_get_request(client);
  UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
  gsize size = _IOC_SIZE(req);
  GError *err = NULL;
  (void)h;
  g_mutex_lock(&m->lock);
  if (m->on_tick && !m->gone) {
    m->on_tick(m);
    if (!m->gone) pump(m);
  }
  if (m->gone && req != USBDEVFS_REAPURB && req != USBDEVFS_REAPURBNDELAY &&
      req != USBDEVFS_DISCARDURB) {
    g_mutex_unlock(&m->lock);
    umockdev_ioctl_client_complete(client, -1, ENODEV);
    return TRUE;
  }
  UMockdevIoctlData *data = NULL;
  if (size && req != USBDEVFS_DISCARDURB) {
    data = umockdev_ioctl_data_resolve(arg, 0, size, &err);
    if (!data) {
      /* the client's memory cannot be read: it died in the middle of the call (a test kills
         tube74 with SIGKILL while it streams). A real usbfs call has no caller left to
         answer; nothing here may touch the argument (a NULL IoctlData: the silent SIGSEGV
         at address 0x18 that test_usb_helios met about one run in fifteen) */
      g_clear_error(&err);
      g_mutex_unlock(&m->lock);
      umockdev_ioctl_client_complete(client, -1, EFAULT);
      return TRUE;
    }
  }
  int rc = 0, e = 0;
  switch (req) {
  case USBDEVFS_GET_CAPABILITIES:
    *(guint32 *)data->data = m->caps;
    break;
  case USBDEVFS_CLAIMINTERFACE:
  case USBDEVFS_RELEASEINTERFACE: {
    unsigned i = *(unsigned *)data->data;
    if (i >= 4) { rc = -1; e = EINVAL; break; }
    if (req == USBDEVFS_CLAIMINTERFACE && m->drv[i][0]) { rc = -1; e = EBUSY; break; }
    m->claimed[i] = req == USBDEVFS_CLAIMINTERFACE;
    break;
  }
  case USBDEVFS_SETINTERFACE:
  case USBDEVFS_RESET:
    break;
  case USBDEVFS_CLEAR_HALT:
    m->clear_halts++;
    break;
  case USBDEVFS_GETDRIVER: {
    struct usbdevfs_getdriver *gd = (struct usbdevfs_getdriver *)data->data;
    if (gd->interface < 4 && m->drv[gd->interface][0])
      snprintf(gd->driver, sizeof gd->driver, "%s", m->drv[gd->interface]);
    else if (gd->interface < 4 && m->claimed[gd->interface])
      snprintf(gd->driver, sizeof gd->driver, "usbfs");
    else { rc = -1; e = ENODATA; }
    break;
  }
  case USBDEVFS_IOCTL: {
    struct usbdevfs_ioctl *io = (struct usbdevfs_ioctl *)data->data;
    int i = io->ifno;
    if (i < 0 || i >= 4) { rc = -1; e = EINVAL; }
    else if (io->ioctl_code == (int)USBDEVFS_DISCONNECT) {
      if (!m->drv[i][0]) { rc = -1; e = ENODATA; }
      else {
        unsigned also = m->unbind_also[i] | 1u << i;
        for (int k = 0; k < 4; k++)
          if (also >> k & 1) m->drv[k][0] = 0;
        m->detaches++;
      }
    } else if (io->ioctl_code == (int)USBDEVFS_CONNECT) {
      if (m->claimed[i]) { rc = -1; e = EBUSY; }
      else if (!m->drv[i][0] && m->probe[i][0]) {
        unsigned also = m->probe_also[i] | 1u << i;
        for (int k = 0; k < 4; k++)
          if ((also >> k & 1) && !m->claimed[k] && !m->drv[k][0])
            memcpy(m->drv[k], m->probe[i], sizeof m->drv[k]);
        m->attaches++;
      }                                         /* no driver for it: nothing binds, 0 */
    } else { rc = -1; e = ENOTTY; }
    break;
  }
  case USBDEVFS_SUBMITURB: {
    struct usbdevfs_urb *urb = (struct usbdevfs_urb *)data->data;
    struct mock_urb *u = g_new0(struct mock_urb, 1);
    u->urb = data;
    data = NULL;                                /* owned by u now */
    u->buf = umockdev_ioctl_data_resolve(u->urb, G_STRUCT_OFFSET(struct usbdevfs_urb, buffer),
                                         (gsize)urb->buffer_length, &err);
    if (!u->buf) {                              /* the client died: as above */
      g_clear_error(&err);
      g_object_unref(u->urb);
      g_free(u);
      rc = -1;
      e = EFAULT;
      break;
    }
    if (urb->buffer_length > m->max_urb) m->max_urb = urb->buffer_length;
    urb->actual_length = 0;
    urb->status = 0;
    if (urb->type == USBDEVFS_URB_TYPE_CONTROL) {
      m->ctrl_urbs++;
      int n = m->on_ctrl ? m->on_ctrl(m, u->buf->data, u->buf->data + 8, urb->buffer_length - 8) : -1;
      if (n < 0) urb->status = -EPIPE;
      else urb->actual_length = n;
      g_queue_push_tail(&m->reapable, u);
    } else if (urb->endpoint & 0x80) {
      g_queue_push_tail(&m->pending_in, u);
      pump(m);
    } else {
      m->out_urbs++;
      int n = urb->buffer_length;
      if (m->stall_at && m->out_urbs == m->stall_at) {
        urb->status = -EPIPE;
        g_queue_push_tail(&m->reapable, u);
      } else if (m->hold_n && m->out_urbs >= m->hold_from && m->out_urbs < m->hold_from + m->hold_n) {
        g_queue_push_tail(&m->held, u);
      } else if (m->trickle_urbs && m->out_urbs <= m->trickle_urbs) {
        int t = MIN(n, m->trickle_bytes);
        m->out_bytes += t;
        if (t > 0 && m->on_out) m->on_out(m, urb->endpoint, u->buf->data, t);
        urb->actual_length = t;
        g_queue_push_tail(&m->held, u);
      } else {
        int vanish_now = m->vanish_after >= 0 && m->out_bytes + n > m->vanish_after;
        if (vanish_now) n = (int)(m->vanish_after - m->out_bytes);
        if (n > 0 && m->t_first_out == 0 && urb->type == USBDEVFS_URB_TYPE_BULK)
          m->t_first_out = mock_now();
        m->out_bytes += n;
        if (n > 0 && m->on_out) m->on_out(m, urb->endpoint, u->buf->data, n);
        urb->actual_length = n;
        if (vanish_now) {
          urb->status = -ENODEV;
          g_queue_push_tail(&m->reapable, u);
          vanish(m);
        } else if (m->delay_us) {
          u->due = mock_now() + m->delay_us * 1e-6;
          g_queue_push_tail(&m->delayed, u);
        } else {
          g_queue_push_tail(&m->reapable, u);
        }
        pump(m);
      }
    }
    break;
  }
  case USBDEVFS_REAPURB:
  case USBDEVFS_REAPURBNDELAY: {
    double now = mock_now();
    while (m->delayed.head && ((struct mock_urb *)m->delayed.head->data)->due <= now)
      g_queue_push_tail(&m->reapable, g_queue_pop_head(&m->delayed));
    struct mock_urb *u = g_queue_pop_head(&m->reapable);
    if (u) {
      umockdev_ioctl_data_set_ptr(data, 0, u->urb);
      urb_free(u);
    } else {
      rc = -1;
      e = EAGAIN;
    }
    break;
  }
  case USBDEVFS_DISCARDURB: {
    gulong addr = *(gulong *)arg->data;
    GQueue *qs[3] = { &m->pending_in, &m->held, &m->delayed };
    int found = 0;
    for (int q = 0; q < 3 && !found; q++)
      for (GList *l = qs[q]->head; l; l = l->next) {
        struct mock_urb *u = l->data;
        if (u->urb->client_addr == addr) {
          U(u)->status = -ENOENT;
          g_queue_delete_link(qs[q], l);
          g_queue_push_tail(&m->reapable, u);
          m->discards++;
          found = 1;
          break;
        }
      }
    if (!found) { rc = -1; e = EINVAL; }
    break;
  }
  default:
    rc = -1;
    e = ENOTTY;
  }
  g_mutex_unlock(&m->lock);
  if (data) g_object_unref(data);
  umockdev_ioctl_client_complete(client, rc, e);
  return TRUE;
}

/* The device's sysfs record: ids and descriptors (hex of device + configuration). */
MOCK_UNUSED static char *mock_sysfs(unsigned vid, unsigned pid, const char *desc_hex)
{
  return g_strdup_printf(
    "P: /devices/pci0000:00/0000:00:14.0/usb1/1-1\n"
    "N: bus/usb/001/002\n"
    "E: SUBSYSTEM=usb\nE: DEVTYPE=usb_device\nE: DRIVER=usb\n"
    "E: DEVNAME=/dev/bus/usb/001/002\nE: BUSNUM=001\nE: DEVNUM=002\n"
    "E: PRODUCT=%x/%x/100\n"
    "A: busnum=1\\n\nA: devnum=2\\n\nA: speed=480\\n\nA: bConfigurationValue=1\\n\n"
    "A: idVendor=%04x\nA: idProduct=%04x\nA: dev=189:1\n"
    "H: descriptors=%s\n", vid, pid, vid, pid, desc_hex);
}

/* Device descriptors of the three kinds of device (USB 2.0 ch. 9). */
#define MOCK_DESC_HELIOS \
  "1201000200000040" "0912" "00e5" "0001" "000000" "01"                              \
  "0902" "3700" "01" "01" "00" "80" "32"                                              \
  "090400000000ff0000"                          /* interface 0 alt 0: no endpoints */ \
  "090400010400ff0000"                          /* interface 0 alt 1 */               \
  "0705020240000007058102400000" "0705060320000107058303200001"
#define MOCK_DESC_EBB \
  "1201000202000040" "d804" "92fd" "0001" "000000" "01"                              \
  "0902" "3000" "02" "01" "00" "80" "32"                                              \
  "090400000102020100" "0705810308000a"         /* CDC communication, notify EP */     \
  "0904010002" "0a0000" "00" "07050202000200" "07058202000200"  /* CDC data */
#define MOCK_DESC_HPGL \
  "1201000200000040" "7b06" "0523" "0001" "000000" "01"                              \
  "0902" "2000" "01" "01" "00" "80" "32"                                              \
  "090400000207010200" "07050102000200" "07058202000200"      /* printer, bidirectional */

/* Testbed with one device; m->... zeroed first by the caller. */
MOCK_UNUSED static int mock_start(struct mock *m, unsigned vid, unsigned pid, const char *desc)
{
  GError *err = NULL;
  g_mutex_init(&m->lock);
  for (int k = 0; k < 16; k++) {
    m->reply[k] = g_byte_array_new();
    g_queue_init(&m->packets[k]);
  }
  m->caps = USBDEVFS_CAP_BULK_SCATTER_GATHER | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
            USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_ZERO_PACKET;
  m->vanish_after = -1;
  m->tb = umockdev_testbed_new();
  if (!umockdev_in_mock_environment()) {
    fprintf(stderr, "SKIP: not running under umockdev-wrapper\n");
    return 77;
  }
  m->handler = umockdev_ioctl_base_new();
  g_signal_connect(m->handler, "handle-ioctl", G_CALLBACK(mock_ioctl), m);
  char *s = mock_sysfs(vid, pid, desc);
  int ok = umockdev_testbed_add_from_string(m->tb, s, &err);
  g_free(s);
  if (!ok) { fprintf(stderr, "mock: %s\n", err->message); return 1; }
  if (!umockdev_testbed_attach_ioctl(m->tb, MOCK_NODE, m->handler, &err)) {
    fprintf(stderr, "mock: %s\n", err->message);
    return 1;
  }
  return 0;
}

/* Forget every URB and fault, empty the reply queues, the device is back (a new run). */
MOCK_UNUSED static void mock_reset(struct mock *m)
{
  if (m->test_holds) mock_unlock(m);            /* left by an assertion that failed */
  g_mutex_lock(&m->lock);
  GQueue *qs[4] = { &m->reapable, &m->delayed, &m->pending_in, &m->held };
  for (int q = 0; q < 4; q++) {
    struct mock_urb *u;
    while ((u = g_queue_pop_head(qs[q]))) urb_free(u);
  }
  for (int k = 0; k < 16; k++) {
    g_byte_array_set_size(m->reply[k], 0);
    g_queue_clear(&m->packets[k]);
  }
  m->delay_us = m->stall_at = m->hold_from = m->hold_n = m->vanish_in_at = m->gone = 0;
  m->trickle_bytes = m->trickle_urbs = 0;
  m->vanish_after = -1;
  m->out_urbs = m->in_urbs = m->ctrl_urbs = m->clear_halts = m->discards = 0;
  m->detaches = m->attaches = m->max_urb = 0;
  memset(m->drv, 0, sizeof m->drv);
  memset(m->claimed, 0, sizeof m->claimed);
  m->out_bytes = 0;
  m->t_first_out = 0;
  g_mutex_unlock(&m->lock);
}

MOCK_UNUSED static void mock_stop(struct mock *m)
{
  mock_reset(m);
  umockdev_testbed_detach_ioctl(m->tb, MOCK_NODE, NULL);
  g_object_unref(m->handler);
  g_object_unref(m->tb);
  for (int k = 0; k < 16; k++) g_byte_array_free(m->reply[k], TRUE);
  g_mutex_clear(&m->lock);
}

/* ---- running under umockdev-wrapper ------------------------------------------------- */

/* Re-run this program under umockdev-wrapper unless already there; 77 when impossible. */
MOCK_UNUSED static int mock_reexec(int argc, char **argv)
{
  (void)argc;
  const char *pre = getenv("LD_PRELOAD");
  if (getenv("TUBE74_UNDER_UMOCKDEV") || (pre && strstr(pre, "libumockdev-preload"))) return 0;
  char *path = g_find_program_in_path("umockdev-wrapper");
  if (!path) {
    printf("SKIP: umockdev-wrapper not found (install the Debian package umockdev)\n");
    return 77;
  }
  setenv("TUBE74_UNDER_UMOCKDEV", "1", 1);
  const char *asan = getenv("ASAN_OPTIONS");
  char *opts = g_strdup_printf("%s%sverify_asan_link_order=0", asan ? asan : "", asan ? ":" : "");
  setenv("ASAN_OPTIONS", opts, 1);
  g_free(opts);
  char **nargv = g_new0(char *, argc + 2);
  nargv[0] = path;
  for (int k = 0; k < argc; k++) nargv[k + 1] = argv[k];
  execv(path, nargv);
  printf("SKIP: cannot run umockdev-wrapper: %s\n", strerror(errno));
  return 77;
}

/* ---- helpers around the tube74 binary ------------------------------------------------ */

MOCK_UNUSED static const char *mock_tube74(void)
{
  const char *t = getenv("TUBE74");
  return t && *t ? t : "./tube74";
}

/* Run argv (NULL-terminated) as a child; its exit status, -1 if it did not exit. stderr
** of the child goes to errfile when not NULL. */
MOCK_UNUSED static int mock_run(char *const argv[], const char *errfile)
{
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (errfile && !freopen(errfile, "w", stderr)) _exit(127);
    execv(argv[0], argv);
    _exit(127);
  }
  int st;
  if (waitpid(pid, &st, 0) < 0) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

struct dots {                   /* a list of tube dots */
  int n, cap;
  int (*xy)[2];
};

MOCK_UNUSED static void dots_add(struct dots *d, int x, int y)
{
  if (d->n == d->cap) {
    d->cap = d->cap ? d->cap * 2 : 4096;
    d->xy = realloc(d->xy, sizeof *d->xy * (size_t)d->cap);
  }
  d->xy[d->n][0] = x;
  d->xy[d->n][1] = y;
  d->n++;
}

/* The reference: `tube74 render SCENE --dump points=...` read back. 0 on success. */
MOCK_UNUSED static int mock_reference(const char *scene, struct dots *d, const char *dir)
{
  char *pts = g_strdup_printf("%s/ref.points", dir);
  char *arg = g_strdup_printf("points=%s", pts);
  char *argv[] = { (char *)mock_tube74(), "render", (char *)scene, "--dump", arg, NULL };
  int rc = mock_run(argv, NULL);
  FILE *f = rc == 0 ? fopen(pts, "r") : NULL;
  int x, y;
  d->n = 0;
  while (f && fscanf(f, "%d %d", &x, &y) == 2) dots_add(d, x, y);
  if (f) fclose(f);
  g_free(pts);
  g_free(arg);
  return f ? 0 : -1;
}

MOCK_UNUSED static int cmp_dot(const void *a, const void *b)
{
  const int *p = a, *q = b;
  return p[1] != q[1] ? p[1] - q[1] : p[0] - q[0];
}

/* 1 when a and b hold the same dots (each once), in any order. */
MOCK_UNUSED static int dots_same_set(const struct dots *a, const struct dots *b)
{
  if (a->n != b->n) return 0;
  int (*x)[2] = malloc(sizeof *x * (size_t)(a->n + 1)), (*y)[2] = malloc(sizeof *y * (size_t)(b->n + 1));
  memcpy(x, a->xy, sizeof *x * (size_t)a->n);
  memcpy(y, b->xy, sizeof *y * (size_t)b->n);
  qsort(x, (size_t)a->n, sizeof *x, cmp_dot);
  qsort(y, (size_t)b->n, sizeof *y, cmp_dot);
  int same = memcmp(x, y, sizeof *x * (size_t)a->n) == 0;
  for (int k = 1; k < a->n && same; k++)
    if (!cmp_dot(x[k - 1], x[k])) same = 0;    /* a dot twice */
  free(x);
  free(y);
  return same;
}

/* 1 when a and b are the same dots in the same order. */
MOCK_UNUSED static int dots_same_order(const struct dots *a, const struct dots *b)
{
  return a->n == b->n && !memcmp(a->xy, b->xy, sizeof *a->xy * (size_t)a->n);
}

/* A fresh scratch folder. */
MOCK_UNUSED static char *mock_tmpdir(void)
{
  char *t = g_strdup("/tmp/tube74-usb-XXXXXX");
  if (!mkdtemp(t)) { g_free(t); return NULL; }
  return t;
}

MOCK_UNUSED static void mock_rmdir(const char *dir)
{
  char *cmd = g_strdup_printf("rm -rf '%s'", dir);
  if (system(cmd) != 0) { /* scratch only */ }
  g_free(cmd);
}

/* What every USB test program starts with: the emulated device (vid:pid, descriptors
   desc), a scratch folder, and the reference dots of scene from the real program.
   0, or the status to exit with (a line on stderr says why). */
MOCK_UNUSED static int mock_begin(struct mock *m, unsigned vid, unsigned pid, const char *desc,
                                  const char *scene, struct dots *ref, char **dir)
{
  int rc = mock_start(m, vid, pid, desc);
  if (rc) return rc;
  *dir = mock_tmpdir();
  if (!*dir || mock_reference(scene, ref, *dir) != 0 || ref->n == 0) {
    fprintf(stderr, "cannot get the reference dots from `%s render %s`\n", mock_tube74(), scene);
    return 1;
  }
  return 0;
}

/* ... and ends with: the device gone, the scratch folder removed. */
MOCK_UNUSED static void mock_end(struct mock *m, struct dots *ref, char *dir)
{
  mock_stop(m);
  mock_rmdir(dir);
  free(ref->xy);
  g_free(dir);
}
