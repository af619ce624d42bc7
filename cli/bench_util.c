/*
** bench_util.c — the output folder and the progress bar of the bench commands
** (see bench_util.h).
*/
#include "cli/bench_util.h"

#include <errno.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

int bench_mkdirs(const char *dir)
{
  char buf[1024];
  if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf) { errno = ENAMETOOLONG; return -1; }
  for (char *p = buf + 1; *p; p++)
    if (*p == '/') {
      *p = 0;
      if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
      *p = '/';
    }
  return mkdir(buf, 0777) == 0 || errno == EEXIST ? 0 : -1;
}

struct bench_bar bench_bar_new(int total)
{
  struct bench_bar b = { 0, total, isatty(2) != 0 };
  return b;
}

void bench_bar_step(struct bench_bar *b, const char *what)
{
  b->done++;
  if (!b->tty) return;
  int w = 40, fill = b->total ? b->done * w / b->total : w;
  if (fill > w) fill = w;
  fprintf(stderr, "\r[%.*s%*s] %3d%% %-40.40s", fill, "########################################",
          w - fill, "", b->total ? 100 * b->done / b->total : 100, what);
  if (b->done == b->total) fprintf(stderr, "\n");
}
