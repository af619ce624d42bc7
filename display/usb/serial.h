/*
** serial.h — an RS-232 line (a tty: /dev/ttyUSB0, /dev/ttyS0, /dev/ttyACM0) for the device
** links of display/usb/usb.h: HP-GL pen plotters (HP 7475A) and Tektronix 4010/4014 terminals
** (display stage, paper 003 §4: the dots sent to a device instead of the storage tube).
**
** This file contains code to configure a tty with termios and to move bytes over it the way
** an RS-232 device expects them:
**
**   serial_open(&s, path, &opts, err)    open the tty (O_NOCTTY), save its settings, then
**                                        raw 8N1 at opts.baud: 8 data bits, no parity, one
**                                        stop bit, no echo, no line editing, no character
**                                        mapping; receiver on, modem control lines ignored
**                                        (CLOCAL) unless hardware flow control is asked for
**   serial_write(s, buf, n, ...)         n bytes out, PACED at the line rate and held while
**                                        the device says stop (below)
**   serial_read(s, buf, n, timeout, ...) what the device sent (replies: OH, ESC.B), the flow
**                                        control characters taken out
**   serial_close(s)                      the tty's own settings back (tcsetattr), closed
**
** FLOW CONTROL (opts.flow):
**   SERIAL_FLOW_NONE      the bytes go as fast as the pacing lets them
**   SERIAL_FLOW_XONXOFF   the device sends DC3 (XOFF, 0x13) when its buffer is nearly full
**                         and DC1 (XON, 0x11) when it may take more. Handled HERE, not by the
**                         kernel (IXON off): between slices of at most 16 bytes the input is
**                         read, and after an XOFF nothing is written until the XON comes, so
**                         no more than one slice (plus what is on the wire) follows an XOFF,
**                         and "written" means the device had room (what a profile may
**                         acknowledge). An XON that does not come within the timeout fails.
**   SERIAL_FLOW_RTSCTS    hardware handshake: CRTSCTS, the kernel holds the bytes while the
**                         device's line (wired to our CTS) is low — the HP 7475A raises DTR
**                         while its buffer has room, so its DTR goes to the host's CTS (the
**                         cable of the 7475A's interfacing manual). Ptys have no modem lines:
**                         this mode is not testable without a real port.
** PACING (opts.pace = 1): a byte on an 8N1 line is 10 bits (start, 8 data, stop), so at B baud
** the line carries B / 10 bytes a second. Writes are timed to that rate (at most one slice
** ahead of the line), so that a device with little or no buffer — a Tektronix terminal,
** which has none — is never sent more than the line could have carried, whatever the tty
** (a USB-serial adapter or a pty buffers kilobytes), and so that "written" is close to "on
** the wire". A real UART paces itself; pacing then only keeps the kernel's buffer short.
**
** Errors: T74_EIO with "DEVICE: what failed: why" (not a tty, unsupported baud, hang-up).
*/
#ifndef T74_SERIAL_H
#define T74_SERIAL_H

#include <signal.h>

#include "emu/status.h"

enum serial_flow {
  SERIAL_FLOW_NONE = 0,
  SERIAL_FLOW_XONXOFF = 1,
  SERIAL_FLOW_RTSCTS = 2
};

#define SERIAL_XON  0x11        /* DC1: the device may take more */
#define SERIAL_XOFF 0x13        /* DC3: the device's buffer is nearly full */

struct serial_opts {
  long baud;                    /* bits a second: 50 .. 4000000, a rate termios knows */
  int flow;                     /* enum serial_flow */
  int pace;                     /* 1: writes timed to baud / 10 bytes a second */
};

struct serial_line;             /* opaque: fd, saved termios, pacing clock, input buffer */

int serial_open(struct serial_line **out, const char *path, const struct serial_opts *o,
                struct t74_error *err);
/* Write buf[0..n) (see FLOW CONTROL and PACING). *done: bytes written, also on failure.
** timeout_ms bounds a wait for XON (or for the kernel to take bytes, RTS/CTS); stop: a flag
** (Ctrl-C) that ends a wait, may be NULL. */
int serial_write(struct serial_line *s, const void *buf, int n, int timeout_ms,
                 volatile sig_atomic_t *stop, int *done, struct t74_error *err);
/* Read at most n bytes: what is buffered, else wait up to timeout_ms for more. *got = 0
** when nothing came (T74_OK); T74_EIO when the line hung up. */
int serial_read(struct serial_line *s, void *buf, int n, int timeout_ms, int *got,
                struct t74_error *err);
int serial_gone(const struct serial_line *s);         /* the line hung up */
double serial_bytes_per_second(const struct serial_line *s);
void serial_close(struct serial_line *s);

/* The termios speed constant of baud, or 0 when termios has none (for option checks). */
int serial_baud_known(long baud);

#endif
