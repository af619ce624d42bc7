/*
** cdp.c — a headless Chromium driven over the DevTools protocol (see cdp.h).
**
** This file contains code to start the browser with --remote-debugging-pipe, open one page
** (Target.createTarget, attached with flatten: its commands carry its sessionId), and send
** the few commands the tests need (Page.navigate, Runtime.evaluate, Page.captureScreenshot),
** each answered by a reply with the same id. Events that arrive meanwhile are looked at
** for the page's faults (Runtime.exceptionThrown, Runtime.consoleAPICalled of type error or
** warning, Log.entryAdded of level error or warning, Network.requestWillBeSent) and for
** Page.loadEventFired. Messages are read just far enough to find these: a string value by
** its key, a reply by the id it starts with (Chromium writes replies as {"id":N,...}).
*/
#include "tests/ref/cdp.h"

#include <errno.h>
#include <fcntl.h>
#include <png.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define CDP_WAIT_MS 60000        /* the longest wait for one reply */

/* ---- JSON, as far as needed ---------------------------------------------------------- */

/* s as the body of a JSON string (no quotes), appended to a malloc'd buffer. */
static char *json_quote(const char *s)
{
  size_t n = strlen(s), k = 0;
  char *o = malloc(6 * n + 1);
  if (!o) return NULL;
  for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
    if (*p == '"' || *p == '\\') { o[k++] = '\\'; o[k++] = (char)*p; }
    else if (*p < 0x20) k += (size_t)sprintf(o + k, "\\u%04x", *p);
    else o[k++] = (char)*p;
  }
  o[k] = 0;
  return o;
}

/* The JSON string that starts at p (just after its opening quote), decoded into a malloc'd
   UTF-8 text. */
static char *json_unquote(const char *p)
{
  size_t cap = 256, k = 0;
  char *o = malloc(cap);
  while (o && *p && *p != '"') {
    if (k + 8 >= cap) {
      char *no = realloc(o, cap *= 2);
      if (!no) { free(o); return NULL; }
      o = no;
    }
    if (*p != '\\') { o[k++] = *p++; continue; }
    p++;
    switch (*p) {
    case 'n': o[k++] = '\n'; break;
    case 't': o[k++] = '\t'; break;
    case 'r': o[k++] = '\r'; break;
    case 'b': o[k++] = '\b'; break;
    case 'f': o[k++] = '\f'; break;
    case 'u': {
      unsigned u = 0;
      for (int i = 1; i <= 4 && p[i]; i++) {
        char ch = p[i];
        u = u * 16 + (unsigned)(ch <= '9' ? ch - '0' : (ch | 32) - 'a' + 10);
      }
      p += 4;
      if (u >= 0xD800 && u < 0xDC00 && p[1] == '\\' && p[2] == 'u') {   /* a surrogate pair */
        unsigned lo = 0;
        for (int i = 3; i <= 6 && p[i]; i++) {
          char ch = p[i];
          lo = lo * 16 + (unsigned)(ch <= '9' ? ch - '0' : (ch | 32) - 'a' + 10);
        }
        u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
        p += 6;
      }
      if (u < 0x80) o[k++] = (char)u;
      else if (u < 0x800) { o[k++] = (char)(0xC0 | u >> 6); o[k++] = (char)(0x80 | (u & 63)); }
      else if (u < 0x10000) {
        o[k++] = (char)(0xE0 | u >> 12); o[k++] = (char)(0x80 | (u >> 6 & 63));
        o[k++] = (char)(0x80 | (u & 63));
      } else {
        o[k++] = (char)(0xF0 | u >> 18); o[k++] = (char)(0x80 | (u >> 12 & 63));
        o[k++] = (char)(0x80 | (u >> 6 & 63)); o[k++] = (char)(0x80 | (u & 63));
      }
      break;
    }
    default: o[k++] = *p; break;          /* \" \\ \/ */
    }
    if (*p) p++;
  }
  if (o) o[k] = 0;
  return o;
}

/* The string value of the first "key":"..." in msg, decoded; NULL if none. */
static char *json_get(const char *msg, const char *key)
{
  char want[64];
  snprintf(want, sizeof want, "\"%s\":\"", key);
  const char *p = strstr(msg, want);
  return p ? json_unquote(p + strlen(want)) : NULL;
}

/* printf into a malloc'd text; NULL when out of memory. */
static char *vfmt(const char *fmt, va_list ap)
{
  va_list aq;
  va_copy(aq, ap);
  int n = vsnprintf(NULL, 0, fmt, aq);
  va_end(aq);
  char *o = n >= 0 ? malloc((size_t)n + 1) : NULL;
  if (o) vsnprintf(o, (size_t)n + 1, fmt, ap);
  return o;
}

static char *fmt(const char *f, ...) __attribute__((format(printf, 1, 2)));
static char *fmt(const char *f, ...)
{
  va_list ap;
  va_start(ap, f);
  char *o = vfmt(f, ap);
  va_end(ap);
  return o;
}

/* ---- the pipe -------------------------------------------------------------------------- */

static int send_msg(struct cdp *c, const char *text)
{
  size_t n = strlen(text) + 1, done = 0;       /* with its NUL */
  while (done < n) {
    ssize_t w = write(c->to, text + done, n - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return -1;
    done += (size_t)w;
  }
  return 0;
}

/* An event: note what the page did wrong, and its loading. */
static void event(struct cdp *c, const char *m)
{
  const char *method = strstr(m, "\"method\":\"");
  if (!method) return;
  method += 10;
  if (!strncmp(method, "Page.loadEventFired", 19)) c->loaded = 1;
  if (!strncmp(method, "Page.navigatedWithinDocument", 28)) c->within = 1;
  int bad = 0;
  if (!strncmp(method, "Runtime.exceptionThrown", 23)) bad = 1;
  if (!strncmp(method, "Runtime.consoleAPICalled", 24) &&
      (strstr(m, "\"type\":\"error\"") || strstr(m, "\"type\":\"warning\"") || strstr(m, "\"type\":\"assert\"")))
    bad = 1;
  if (!strncmp(method, "Log.entryAdded", 14) &&
      (strstr(m, "\"level\":\"error\"") || strstr(m, "\"level\":\"warning\"")))
    bad = 1;
  if (bad) {
    if (!c->errors++) {
      char *d = json_get(m, "description");
      if (!d) d = json_get(m, "text");
      if (!d) d = json_get(m, "value");
      snprintf(c->error, sizeof c->error, "%.24s: %s", method, d ? d : m);
      free(d);
    }
  }
  if (!strncmp(method, "Network.requestWillBeSent", 25)) {
    const char *r = strstr(m, "\"request\":{\"url\":\"");
    char *url = r ? json_unquote(r + 18) : NULL;
    if (url && strncmp(url, "file:", 5) && strncmp(url, "data:", 5) && strncmp(url, "about:", 6)) {
      if (!c->requests++) snprintf(c->request, sizeof c->request, "%s", url);
    }
    free(url);
  }
}

/* Read messages until the reply to `id` (returned, malloc'd) or, with id 0, until the page
   has loaded (returns an empty string). NULL on a timeout or a closed pipe. */
static char *wait_for(struct cdp *c, int id)
{
  char head[32];
  int hn = snprintf(head, sizeof head, "{\"id\":%d,", id);
  struct timespec t0;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (;;) {
    char *z;
    while (c->n > 0 && (z = memchr(c->buf, 0, c->n))) {   /* every whole message (buf may be NULL while empty) */
      size_t len = (size_t)(z - c->buf);
      char *m = malloc(len + 1);
      if (!m) return NULL;
      memcpy(m, c->buf, len + 1);
      memmove(c->buf, z + 1, c->n - len - 1);
      c->n -= len + 1;
      if (id && !strncmp(m, head, (size_t)hn)) return m;
      if (strncmp(m, "{\"id\":", 6)) event(c, m);
      free(m);
      if (!id && (c->loaded || c->within)) return strdup("");
    }
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    long spent = (t1.tv_sec - t0.tv_sec) * 1000L + (t1.tv_nsec - t0.tv_nsec) / 1000000L;
    if (spent > CDP_WAIT_MS) {
      fprintf(stderr, "cdp: no answer from the browser in %d s\n", CDP_WAIT_MS / 1000);
      return NULL;
    }
    struct pollfd pf = { c->from, POLLIN, 0 };
    int pr = poll(&pf, 1, 1000);
    if (pr < 0 && errno == EINTR) continue;
    if (pr <= 0) continue;
    if (c->n + 65536 + 1 > c->cap) {
      size_t nc = c->cap ? c->cap * 2 : 1 << 20;
      while (nc < c->n + 65536 + 1) nc *= 2;
      char *nb = realloc(c->buf, nc);
      if (!nb) return NULL;
      c->buf = nb;
      c->cap = nc;
    }
    ssize_t r = read(c->from, c->buf + c->n, 65536);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) { fprintf(stderr, "cdp: the browser closed its pipe\n"); return NULL; }
    c->n += (size_t)r;
  }
}

/* Send method(params) to the page's session (or the browser, when session is 0) and wait
   for its reply (malloc'd). */
static char *call(struct cdp *c, int session, const char *method, const char *pfmt, ...)
  __attribute__((format(printf, 4, 5)));

static char *call(struct cdp *c, int session, const char *method, const char *pfmt, ...)
{
  va_list ap;
  va_start(ap, pfmt);
  char *params = vfmt(pfmt, ap);
  va_end(ap);
  if (!params) return NULL;
  int id = ++c->next_id;
  char *msg = session ? fmt("{\"id\":%d,\"method\":\"%s\",\"params\":%s,\"sessionId\":\"%s\"}",
                            id, method, params, c->session)
                      : fmt("{\"id\":%d,\"method\":\"%s\",\"params\":%s}", id, method, params);
  free(params);
  if (!msg) return NULL;
  int st = send_msg(c, msg);
  free(msg);
  if (st) return NULL;
  char *r = wait_for(c, id);
  if (r && strstr(r, "\"error\":{\"code\"") && !strstr(r, "\"result\"")) {
    fprintf(stderr, "cdp: %s failed: %.300s\n", method, r);
    free(r);
    return NULL;
  }
  return r;
}

/* Move fd to a descriptor >= 10 (so that dup2 onto 3 and 4 cannot clobber it). */
static int high(int fd)
{
  int h = fcntl(fd, F_DUPFD_CLOEXEC, 10);
  close(fd);
  return h;
}

int cdp_start(struct cdp *c, const char *chromium, const char *profile_dir, int w, int h)
{
  memset(c, 0, sizeof *c);
  c->to = c->from = -1;
  int cmd[2], rep[2];
  if (pipe(cmd) || pipe(rep)) { perror("cdp: pipe"); return -1; }
  cmd[0] = high(cmd[0]); cmd[1] = high(cmd[1]);
  rep[0] = high(rep[0]); rep[1] = high(rep[1]);
  char prof[600];
  snprintf(prof, sizeof prof, "--user-data-dir=%s", profile_dir);
  c->pid = fork();
  if (c->pid < 0) { perror("cdp: fork"); return -1; }
  if (c->pid == 0) {
    if (dup2(cmd[0], 3) < 0 || dup2(rep[1], 4) < 0) _exit(127);
    int nul = open("/dev/null", O_RDWR);
    if (nul >= 0) { dup2(nul, 0); dup2(nul, 1); dup2(nul, 2); }
    execl(chromium, chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
          "--no-first-run", "--disable-background-networking", "--disable-component-update",
          "--disable-sync", "--hide-scrollbars", "--remote-debugging-pipe", prof, "about:blank",
          (char *)NULL);
    _exit(127);
  }
  close(cmd[0]);
  close(rep[1]);
  c->to = cmd[1];
  c->from = rep[0];
  signal(SIGPIPE, SIG_IGN);
  char *r = call(c, 0, "Target.createTarget", "{\"url\":\"about:blank\"}");
  char *target = r ? json_get(r, "targetId") : NULL;
  free(r);
  if (!target) { fprintf(stderr, "cdp: no page from %s\n", chromium); cdp_stop(c); return -1; }
  r = call(c, 0, "Target.attachToTarget", "{\"targetId\":\"%s\",\"flatten\":true}", target);
  free(target);
  char *sid = r ? json_get(r, "sessionId") : NULL;
  free(r);
  if (!sid) { fprintf(stderr, "cdp: cannot attach to the page\n"); cdp_stop(c); return -1; }
  snprintf(c->session, sizeof c->session, "%s", sid);
  free(sid);
  static const char *const domains[] = { "Page.enable", "Runtime.enable", "Log.enable", "Network.enable" };
  for (size_t k = 0; k < sizeof domains / sizeof *domains; k++) {
    r = call(c, 1, domains[k], "{}");
    if (!r) { cdp_stop(c); return -1; }
    free(r);
  }
  r = call(c, 1, "Emulation.setDeviceMetricsOverride",
           "{\"width\":%d,\"height\":%d,\"deviceScaleFactor\":1,\"mobile\":false}", w, h);
  if (!r) { cdp_stop(c); return -1; }
  free(r);
  return 0;
}

int cdp_goto(struct cdp *c, const char *url)
{
  char *q = json_quote(url);
  if (!q) return -1;
  c->loaded = c->within = 0;
  char *r = call(c, 1, "Page.navigate", "{\"url\":\"%s\"}", q);
  free(q);
  if (!r) return -1;
  free(r);
  if (!c->loaded && !c->within) {
    char *l = wait_for(c, 0);
    if (!l) return -1;
    free(l);
  }
  if (c->loaded) return 0;
  /* the same document with another fragment: no load; load it afresh, as a reader's
     browser does when given the address */
  c->loaded = c->within = 0;
  r = call(c, 1, "Page.reload", "{}");
  if (!r) return -1;
  free(r);
  while (!c->loaded) {
    char *l = wait_for(c, 0);
    if (!l) return -1;
    free(l);
  }
  return 0;
}

char *cdp_eval(struct cdp *c, const char *js)
{
  char *q = json_quote(js);
  if (!q) return NULL;
  char *r = call(c, 1, "Runtime.evaluate", "{\"expression\":\"%s\",\"returnByValue\":true}", q);
  free(q);
  if (!r) return NULL;
  if (strstr(r, "\"exceptionDetails\"")) {
    if (!c->errors++) {
      char *d = json_get(r, "description");
      snprintf(c->error, sizeof c->error, "evaluating: %s", d ? d : r);
      free(d);
    }
    free(r);
    return NULL;
  }
  char *v = json_get(r, "value");
  free(r);
  return v;
}

static const signed char *b64_table(void)
{
  static signed char t[256];
  static int made = 0;
  if (!made) {
    memset(t, -1, sizeof t);
    const char *a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int k = 0; k < 64; k++) t[(unsigned char)a[k]] = (signed char)k;
    made = 1;
  }
  return t;
}

uint8_t *cdp_shot_png(struct cdp *c, double x, double y, double w, double h, size_t *n)
{
  char *r = call(c, 1, "Page.captureScreenshot",
                 "{\"format\":\"png\",\"captureBeyondViewport\":true,"
                 "\"clip\":{\"x\":%.1f,\"y\":%.1f,\"width\":%.1f,\"height\":%.1f,\"scale\":1}}",
                 x, y, w, h);
  char *data = r ? json_get(r, "data") : NULL;
  free(r);
  if (!data) return NULL;
  const signed char *t = b64_table();
  size_t len = strlen(data), k = 0;
  uint8_t *out = malloc(len / 4 * 3 + 3);
  unsigned acc = 0;
  int bits = 0;
  for (size_t i = 0; out && i < len; i++) {
    int v = t[(unsigned char)data[i]];
    if (v < 0) continue;                         /* '=' and anything else */
    acc = acc << 6 | (unsigned)v;
    bits += 6;
    if (bits >= 8) { bits -= 8; out[k++] = (uint8_t)(acc >> bits); }
  }
  free(data);
  *n = k;
  return out;
}

uint8_t *cdp_shot(struct cdp *c, double x, double y, double w, double h, int *pw, int *ph)
{
  size_t n;
  uint8_t *png = cdp_shot_png(c, x, y, w, h, &n);
  if (!png) return NULL;
  png_image im;
  memset(&im, 0, sizeof im);
  im.version = PNG_IMAGE_VERSION;
  uint8_t *px = NULL;
  if (png_image_begin_read_from_memory(&im, png, n)) {
    im.format = PNG_FORMAT_RGB;
    px = malloc(PNG_IMAGE_SIZE(im));
    if (px && !png_image_finish_read(&im, NULL, px, 0, NULL)) { free(px); px = NULL; }
  }
  free(png);
  *pw = (int)im.width;
  *ph = (int)im.height;
  return px;
}

void cdp_stop(struct cdp *c)
{
  if (c->to >= 0 && c->session[0]) {
    char *r = call(c, 0, "Browser.close", "{}");
    free(r);
  }
  if (c->to >= 0) close(c->to);
  if (c->from >= 0) close(c->from);
  c->to = c->from = -1;
  if (c->pid > 0) {
    for (int k = 0; k < 100; k++) {              /* up to 5 s to end by itself */
      if (waitpid(c->pid, NULL, WNOHANG) == c->pid) { c->pid = 0; break; }
      nanosleep(&(struct timespec){ 0, 50000000 }, NULL);
    }
    if (c->pid > 0) {
      kill(c->pid, SIGKILL);
      waitpid(c->pid, NULL, 0);
      c->pid = 0;
    }
  }
  free(c->buf);
  c->buf = NULL;
  c->n = c->cap = 0;
}
