/*
** bench_util.h — what the `tube74 bench` commands share (cli/cmd_bench.c for accuracy,
** cli/bench_speed.c, cli/bench_arith.c): the output folder and the progress bar.
*/
#ifndef T74_BENCH_UTIL_H
#define T74_BENCH_UTIL_H

#include <stdbool.h>

/* Make dir and its missing parents (like mkdir -p). 0, or -1 with errno set. */
int bench_mkdirs(const char *dir);

/* A progress bar on standard error, drawn only when it is a terminal. */
struct bench_bar {
  int done, total;                /* steps done, steps in all */
  bool tty;                       /* standard error is a terminal */
};

/* A bar of `total` steps (tty from isatty(2)). */
struct bench_bar bench_bar_new(int total);

/* One step done, `what` shown beside the bar; a newline after the last. */
void bench_bar_step(struct bench_bar *b, const char *what);

#endif
