/*
** tuberun.c — running ./tube74 from the cross-check tests and reading what it dumps.
**
** This file contains the process and file helpers of the outside tests: posix_spawn with
** the output sent to a log (no shell, so scene paths need no quoting), a bounded wait that
** kills a hung renderer instead of hanging the test suite, and a strict reader of the
** contract's `--dump ids` format (P5, maxval 65535, big-endian 16-bit samples).
*/
#include "tests/ref/tuberun.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ; /* POSIX: the environment passed on to the child */

const char *tr_program(void)
{
  const char *p = getenv("TUBE74");
  return (p && *p) ? p : "./tube74";
}

pid_t tr_spawn(char *const argv[], const char *log, char *err, size_t errlen)
{
  posix_spawn_file_actions_t fa;
  pid_t pid = -1;
  int rc = posix_spawn_file_actions_init(&fa);
  if (rc == 0) rc = posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (rc == 0) rc = posix_spawn_file_actions_adddup2(&fa, 1, 2);
  if (rc == 0) rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    if (err && errlen) snprintf(err, errlen, "posix_spawn %s: %s", argv[0], strerror(rc));
    return -1;
  }
  return pid;
}

static double now_s(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int tr_wait(pid_t pid, double timeout_s, int *sig)
{
  const double deadline = now_s() + timeout_s;
  int st = 0;
  for (;;) {
    pid_t w = waitpid(pid, &st, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) return -1;
    if (now_s() > deadline) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &st, 0) < 0 && errno == EINTR) {
      }
      return -2;
    }
    const struct timespec nap = {0, 500000}; /* 0.5 ms */
    nanosleep(&nap, NULL);
  }
  if (WIFEXITED(st)) return WEXITSTATUS(st);
  if (WIFSIGNALED(st)) {
    if (sig) *sig = WTERMSIG(st);
    return -3;
  }
  return -1;
}

void tr_describe(int rc, int sig, double timeout_s, char *out, size_t outlen)
{
  if (rc == -2) snprintf(out, outlen, "timed out after %.0f s (killed)", timeout_s);
  else if (rc == -3) snprintf(out, outlen, "killed by signal %d", sig);
  else if (rc == -1) snprintf(out, outlen, "could not be waited for");
  else snprintf(out, outlen, "exit status %d", rc);
}

char *tr_slurp(const char *path, size_t *n)
{
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  size_t cap = 1 << 16, len = 0;
  char *b = malloc(cap + 1);
  while (b) {
    size_t got = fread(b + len, 1, cap - len, fp);
    len += got;
    if (len < cap) break;
    char *nb = realloc(b, 2 * cap + 1);
    if (!nb) {
      free(b);
      b = NULL;
      break;
    }
    b = nb;
    cap *= 2;
  }
  int bad = ferror(fp);
  fclose(fp);
  if (!b || bad) {
    free(b);
    return NULL;
  }
  b[len] = 0;
  if (n) *n = len;
  return b;
}

/* Next header number of a PNM file: skips blanks and # comments. -1 on error. */
static long pnm_number(const unsigned char *b, size_t n, size_t *at)
{
  for (;;) {
    while (*at < n && (b[*at] == ' ' || b[*at] == '\t' || b[*at] == '\n' || b[*at] == '\r'))
      (*at)++;
    if (*at < n && b[*at] == '#') {
      while (*at < n && b[*at] != '\n') (*at)++;
      continue;
    }
    break;
  }
  if (*at >= n || b[*at] < '0' || b[*at] > '9') return -1;
  long v = 0;
  while (*at < n && b[*at] >= '0' && b[*at] <= '9' && v < 100000000) v = 10 * v + (b[(*at)++] - '0');
  return v;
}

uint16_t *tr_read_pgm16(const char *path, int *w, int *h, char *err, size_t errlen)
{
  size_t n = 0;
  unsigned char *b = (unsigned char *)tr_slurp(path, &n);
  if (!b) {
    if (err && errlen) snprintf(err, errlen, "%s: cannot read", path);
    return NULL;
  }
  size_t at = 2;
  long ww = -1, hh = -1, mx = -1;
  if (n >= 2 && b[0] == 'P' && b[1] == '5') {
    ww = pnm_number(b, n, &at);
    hh = pnm_number(b, n, &at);
    mx = pnm_number(b, n, &at);
  }
  const char *why = NULL;
  if (ww <= 0 || hh <= 0 || mx < 0) why = "not a binary PGM (P5)";
  else if (mx != 65535) why = "maxval is not 65535";
  else if (at >= n || !(b[at] == ' ' || b[at] == '\t' || b[at] == '\n' || b[at] == '\r'))
    why = "no blank after the header";
  else if (n - at - 1 != (size_t)ww * (size_t)hh * 2) why = "sample data has the wrong length";
  if (why) {
    if (err && errlen) snprintf(err, errlen, "%s: %s", path, why);
    free(b);
    return NULL;
  }
  at++;
  uint16_t *ids = malloc((size_t)ww * (size_t)hh * sizeof *ids);
  if (ids)
    for (size_t k = 0; k < (size_t)ww * (size_t)hh; k++)
      ids[k] = (uint16_t)((b[at + 2 * k] << 8) | b[at + 2 * k + 1]);
  else if (err && errlen)
    snprintf(err, errlen, "out of memory");
  free(b);
  *w = (int)ww;
  *h = (int)hh;
  return ids;
}

void tr_print_tail(const char *path, int lines, const char *prefix)
{
  size_t n = 0;
  char *t = tr_slurp(path, &n);
  if (!t) return;
  size_t at = n;
  int seen = 0;
  while (at > 0) {
    if (t[at - 1] == '\n' && at != n && ++seen == lines) break;
    at--;
  }
  char *save = NULL;
  for (char *l = strtok_r(t + at, "\n", &save); l; l = strtok_r(NULL, "\n", &save))
    printf("%s%s\n", prefix, l);
  free(t);
}
