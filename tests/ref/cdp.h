/*
** cdp.h — a headless Chromium driven over the DevTools protocol, for the tests of pages
** tube74 writes (tests/test_teach.c).
**
** This file declares a small client of the Chrome DevTools Protocol over a pipe (Chromium's
** --remote-debugging-pipe: commands are JSON texts ending in a NUL byte, written to the
** browser's file descriptor 3, replies and events read from its descriptor 4). One browser
** process is started with a fresh profile and one page; the test then loads addresses,
** evaluates expressions in the page and takes screenshots, as many as it likes, without
** starting the browser again. While waiting for replies the client counts what the page
** did wrong: script exceptions, console errors and warnings, and network requests for
** anything but file:, data: and about: addresses (a self-contained page makes none).
** Plain POSIX and libpng, no cmocka: the callers make their own assertions.
*/
#ifndef TUBE74_TESTS_REF_CDP_H
#define TUBE74_TESTS_REF_CDP_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

struct cdp {
  pid_t pid;
  int to, from;                 /* the browser's command pipe, its reply pipe */
  char *buf;                    /* bytes read and not yet taken */
  size_t n, cap;
  int next_id;
  char session[80];             /* the page's session */
  int loaded;                   /* Page.loadEventFired seen since the last navigation */
  int within;                   /* Page.navigatedWithinDocument seen since then */
  int errors;                   /* exceptions and console errors and warnings seen */
  char error[1024];             /* the first of them */
  int requests;                 /* network requests other than file:, data:, about: */
  char request[512];            /* the first of them */
};

/* Start `chromium` headless with a fresh profile in profile_dir and one page of w x h CSS
   pixels. 0, or -1 with a message on stderr. */
int cdp_start(struct cdp *c, const char *chromium, const char *profile_dir, int w, int h);

/* Load url in the page and wait until it has loaded (an address that differs from the
   page's only in its fragment is loaded afresh too). 0 or -1. */
int cdp_goto(struct cdp *c, const char *url);

/* The value of the JavaScript expression js in the page, which must be a string (use
   String(...) or JSON.stringify): malloc'd, NUL-terminated; NULL when it threw (counted
   in errors) or the browser did not answer. */
char *cdp_eval(struct cdp *c, const char *js);

/* A screenshot of the page's rectangle (x, y, w, h), in CSS pixels from the top left of
   the document, as RGB bytes (3 a pixel, row by row, malloc'd); *pw, *ph its size. NULL
   on failure. */
uint8_t *cdp_shot(struct cdp *c, double x, double y, double w, double h, int *pw, int *ph);

/* The same screenshot as PNG bytes (malloc'd, *n its length), for writing to a file. */
uint8_t *cdp_shot_png(struct cdp *c, double x, double y, double w, double h, size_t *n);

/* Close the browser and wait for it (killed when it does not end within seconds). */
void cdp_stop(struct cdp *c);

#endif
