/*
** serial.c — an RS-232 line configured with termios: raw 8N1 at a baud rate, paced writes,
** XON/XOFF handled byte by byte, RTS/CTS by the kernel (see serial.h).
**
** This file contains code to talk to serial devices without surprises from the tty layer:
** every character mapping, echo and line editing is off, and flow control is done where
** tube74 can see it (XON/XOFF) or by the hardware (RTS/CTS). Sources: POSIX termios (the
** flags cleared are those of a raw mode: IGNBRK BRKINT PARMRK ISTRIP INLCR IGNCR ICRNL IXON
** IXOFF IXANY, OPOST, ECHO ECHONL ICANON ISIG IEXTEN, CSIZE PARENB CSTOPB, then CS8 CREAD);
** an 8N1 character is 10 bits on the line (start bit, 8 data bits, stop bit); DC1 / DC3 as
** XON / XOFF (ASCII; the HP 7470A/7475A interfacing manuals' Xon-Xoff handshake uses them).
** Invariant: `stopped` is 1 from an XOFF read to the next XON, and no byte is written while
** it is 1; bytes read that are not XON/XOFF are kept in order in `in` for serial_read.
*/
#define _DEFAULT_SOURCE         /* CRTSCTS and the baud rates above 38400 (glibc: __USE_MISC) */

#include "display/usb/serial.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#define SERIAL_SLICE_XON   16   /* bytes a write with XON/XOFF: little overshoot after XOFF */
#define SERIAL_SLICE       64   /* bytes a write otherwise */
#define SERIAL_IN          4096 /* bytes of input kept for serial_read */
#define SERIAL_BITS        10.0 /* bits a character on the line: start + 8 data + stop (8N1) */

struct serial_line {
  int fd;
  char path[256];               /* for messages */
  struct termios saved;         /* the tty's settings before, put back at close */
  int flow, pace;
  double bps;                   /* bytes a second on the line: baud / 10 */
  double t_free;                /* monotonic seconds when the line has sent what we wrote */
  int stopped;                  /* an XOFF came and no XON yet */
  int gone;                     /* hang-up / I/O error */
  unsigned char in[SERIAL_IN];  /* received bytes not yet read, in[ipos .. nin-1] */
  int ipos, nin;
};

static const struct { long baud; speed_t sp; } serial_speeds[] = {
  /* the rates termios names (POSIX up to 38400; Linux beyond) */
  { 50, B50 }, { 75, B75 }, { 110, B110 }, { 134, B134 }, { 150, B150 }, { 200, B200 },
  { 300, B300 }, { 600, B600 }, { 1200, B1200 }, { 1800, B1800 }, { 2400, B2400 },
  { 4800, B4800 }, { 9600, B9600 }, { 19200, B19200 }, { 38400, B38400 },
#ifdef B57600
  { 57600, B57600 },
#endif
#ifdef B115200
  { 115200, B115200 },
#endif
#ifdef B230400
  { 230400, B230400 },
#endif
#ifdef B460800
  { 460800, B460800 },
#endif
#ifdef B921600
  { 921600, B921600 },
#endif
};

static double now_s(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void sleep_s(double s)
{
  if (s <= 0) return;
  struct timespec ts;
  ts.tv_sec = (time_t)s;
  ts.tv_nsec = (long)((s - (double)ts.tv_sec) * 1e9);
  nanosleep(&ts, NULL);
}

int serial_baud_known(long baud)
{
  for (size_t k = 0; k < sizeof serial_speeds / sizeof serial_speeds[0]; k++)
    if (serial_speeds[k].baud == baud) return 1;
  return 0;
}

int serial_open(struct serial_line **out, const char *path, const struct serial_opts *o,
                struct t74_error *err)
{
  *out = NULL;
  speed_t sp = 0;
  int known = 0;
  for (size_t k = 0; k < sizeof serial_speeds / sizeof serial_speeds[0]; k++)
    if (serial_speeds[k].baud == o->baud) { sp = serial_speeds[k].sp; known = 1; }
  if (!known)
    return t74_fail(err, T74_EINPUT, "%s: %ld baud is not a rate the serial port can be set to "
                    "(e.g. 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200)", path, o->baud);
  struct serial_line *s = calloc(1, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  snprintf(s->path, sizeof s->path, "%s", path);
  s->fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (s->fd < 0) {
    int e = errno;
    free(s);
    return t74_fail(err, T74_EIO, "%s: cannot open the serial port: %s%s", path, strerror(e),
                    e == EACCES ? " (add yourself to the group that owns it, e.g. dialout)" : "");
  }
  if (!isatty(s->fd) || tcgetattr(s->fd, &s->saved) != 0) {
    close(s->fd);
    free(s);
    return t74_fail(err, T74_EIO, "%s: not a serial port (a terminal device)", path);
  }
  struct termios t = s->saved;
  t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                           IXOFF | IXANY | INPCK);
  t.c_oflag &= ~(tcflag_t)OPOST;
  t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
  t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB | CRTSCTS);
  t.c_cflag |= CS8 | CREAD;
  if (o->flow == SERIAL_FLOW_RTSCTS) {
    t.c_cflag |= CRTSCTS;       /* the kernel holds output while CTS is low */
    t.c_cflag &= ~(tcflag_t)CLOCAL;
  } else {
    t.c_cflag |= CLOCAL;        /* no modem: ignore DCD */
  }
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (cfsetispeed(&t, sp) != 0 || cfsetospeed(&t, sp) != 0 || tcsetattr(s->fd, TCSANOW, &t) != 0) {
    int e = errno;
    tcsetattr(s->fd, TCSANOW, &s->saved);
    close(s->fd);
    free(s);
    return t74_fail(err, T74_EIO, "%s: cannot set %ld baud 8N1: %s", path, o->baud, strerror(e));
  }
  tcflush(s->fd, TCIFLUSH);     /* what came before this run is not a reply to it */
  s->flow = o->flow;
  s->pace = o->pace;
  s->bps = (double)o->baud / SERIAL_BITS;
  s->t_free = now_s();
  *out = s;
  return T74_OK;
}

/* Read what has arrived (waiting up to ms), sorting XON/XOFF out of the data. */
static int take_input(struct serial_line *s, int ms, struct t74_error *err)
{
  if (s->gone) return t74_fail(err, T74_EIO, "%s: the serial line hung up", s->path);
  struct pollfd p = { s->fd, POLLIN, 0 };
  int r = poll(&p, 1, ms);
  if (r < 0) return errno == EINTR ? T74_OK : t74_fail(err, T74_EIO, "%s: %s", s->path, strerror(errno));
  if (r == 0) return T74_OK;
  if (p.revents & (POLLHUP | POLLERR) && !(p.revents & POLLIN)) {
    s->gone = 1;
    return t74_fail(err, T74_EIO, "%s: the serial line hung up (the device or adapter went away)",
                    s->path);
  }
  if (s->ipos > 0 && s->ipos == s->nin) s->ipos = s->nin = 0;
  if (s->nin == SERIAL_IN && s->ipos > 0) {
    memmove(s->in, s->in + s->ipos, (size_t)(s->nin - s->ipos));
    s->nin -= s->ipos;
    s->ipos = 0;
  }
  unsigned char b[512];
  ssize_t n = read(s->fd, b, sizeof b);
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return T74_OK;
    s->gone = 1;
    return t74_fail(err, T74_EIO, "%s: reading the serial line: %s", s->path, strerror(errno));
  }
  if (n == 0 && (p.revents & POLLHUP)) {
    s->gone = 1;
    return t74_fail(err, T74_EIO, "%s: the serial line hung up (the device or adapter went away)",
                    s->path);
  }
  for (ssize_t k = 0; k < n; k++) {
    if (s->flow == SERIAL_FLOW_XONXOFF && (b[k] == SERIAL_XON || b[k] == SERIAL_XOFF)) {
      s->stopped = b[k] == SERIAL_XOFF;
      continue;
    }
    if (s->nin < SERIAL_IN) s->in[s->nin++] = b[k];   /* beyond: replies nobody reads */
  }
  return T74_OK;
}

int serial_write(struct serial_line *s, const void *buf, int n, int timeout_ms,
                 volatile sig_atomic_t *stop, int *done, struct t74_error *err)
{
  const unsigned char *b = buf;
  int slice = s->flow == SERIAL_FLOW_XONXOFF ? SERIAL_SLICE_XON : SERIAL_SLICE;
  *done = 0;
  double waited_since = now_s();
  while (*done < n) {
    if (s->flow == SERIAL_FLOW_XONXOFF) {
      if (take_input(s, 0, err) != T74_OK) return err->status;
      while (s->stopped) {      /* the device asked us to stop: wait for its XON */
        if (stop && *stop)
          return t74_fail(err, T74_EIO, "%s: stopped while the device held the line (XOFF)", s->path);
        if ((now_s() - waited_since) * 1000 > timeout_ms)
          return t74_fail(err, T74_EIO, "%s: the device sent XOFF and no XON for %d ms", s->path,
                          timeout_ms);
        if (take_input(s, 20, err) != T74_OK) return err->status;
      }
    }
    int k = n - *done < slice ? n - *done : slice;
    if (s->pace) {              /* at most one slice ahead of the line */
      double ahead = s->t_free - now_s(), slice_s = slice / s->bps;
      if (ahead > slice_s) sleep_s(ahead - slice_s);
    }
    ssize_t w = write(s->fd, b + *done, (size_t)k);
    if (w < 0) {
      if (errno == EAGAIN || errno == EINTR) {      /* kernel buffer full (or CTS low) */
        if (stop && *stop) return t74_fail(err, T74_EIO, "%s: stopped", s->path);
        if ((now_s() - waited_since) * 1000 > timeout_ms)
          return t74_fail(err, T74_EIO, "%s: the device took no bytes for %d ms%s", s->path,
                          timeout_ms, s->flow == SERIAL_FLOW_RTSCTS ? " (CTS low)" : "");
        struct pollfd p = { s->fd, POLLOUT, 0 };
        poll(&p, 1, 20);
        continue;
      }
      s->gone = errno == EIO || errno == ENXIO || errno == ENODEV;
      return t74_fail(err, T74_EIO, "%s: writing to the serial line: %s", s->path, strerror(errno));
    }
    double t = now_s();
    if (s->t_free < t) s->t_free = t;
    s->t_free += (double)w / s->bps;
    *done += (int)w;
    waited_since = t;
  }
  return T74_OK;
}

int serial_read(struct serial_line *s, void *buf, int n, int timeout_ms, int *got,
                struct t74_error *err)
{
  *got = 0;
  double t_end = now_s() + timeout_ms / 1000.0;
  for (;;) {
    if (s->ipos < s->nin) {
      int k = s->nin - s->ipos < n ? s->nin - s->ipos : n;
      memcpy(buf, s->in + s->ipos, (size_t)k);
      s->ipos += k;
      *got = k;
      return T74_OK;
    }
    double left = (t_end - now_s()) * 1000.0;
    if (left <= 0) return T74_OK;
    if (take_input(s, left < 1 ? 1 : (int)left, err) != T74_OK) return err->status;
  }
}

int serial_gone(const struct serial_line *s) { return s->gone; }
double serial_bytes_per_second(const struct serial_line *s) { return s->bps; }

void serial_close(struct serial_line *s)
{
  if (!s) return;
  if (!s->gone) {
    /* let what is written reach the device (bounded: a held line must not hang us) */
    double left = s->t_free - now_s();
    if (s->pace && left > 0) sleep_s(left < 5 ? left : 5);
    tcsetattr(s->fd, TCSANOW, &s->saved);     /* not TCSADRAIN: CTS held low would hang */
  }
  close(s->fd);
  free(s);
}
