/*
** tuberun.h — running ./tube74 from the cross-check tests and reading what it dumps.
**
** This file declares the small process and file helpers that test_crosscheck.c and
** test_invariance.c share: start `$TUBE74 ...` with posix_spawn (no shell; stdout and
** stderr into a log file), wait for it with a time limit, read a 16-bit binary PGM
** (`--dump ids=`), read a whole file, and show the tail of a log. Plain POSIX, no GL, no
** project headers.
*/
#ifndef TUBE74_TESTS_REF_TUBERUN_H
#define TUBE74_TESTS_REF_TUBERUN_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

/* The program under test: $TUBE74, or "./tube74". */
const char *tr_program(void);

/* Start argv[0] (a path, not searched in PATH) with stdout and stderr appended to log.
   Returns the child's pid, or -1 with a reason in err. */
pid_t tr_spawn(char *const argv[], const char *log, char *err, size_t errlen);

/* Wait for pid at most timeout_s seconds (then kill it with SIGKILL).
   Returns the exit status 0..255; -2 on timeout; -3 if a signal ended it (*sig set);
   -1 if waiting failed. */
int tr_wait(pid_t pid, double timeout_s, int *sig);

/* "exit status N", "timed out after N s", "killed by signal N" for a tr_wait result. */
void tr_describe(int rc, int sig, double timeout_s, char *out, size_t outlen);

/* Read a binary PGM with maxval 65535 (P5, big-endian samples). Returns a malloc'd
   w * h array (row 0 at the top), or NULL with a reason in err. */
uint16_t *tr_read_pgm16(const char *path, int *w, int *h, char *err, size_t errlen);

/* A whole file, NUL-terminated, malloc'd; *n = its length. NULL if unreadable. */
char *tr_slurp(const char *path, size_t *n);

/* Print the last `lines` lines of a text file, each prefixed, to stdout. */
void tr_print_tail(const char *path, int lines, const char *prefix);

#endif
