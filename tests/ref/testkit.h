/*
** testkit.h — the scratch folder, shell and file helpers the test programs share.
**
** This file declares what most tests/test_*.c programs need around the code they test:
** a fresh scratch folder under /tmp and its removal, the program under test ($TUBE74),
** a shell command run inside the scratch folder, $TUBE74 run directly (no shell) with
** its output sent to files, and whole-file reading and writing. Plain POSIX, no cmocka
** and no project headers: the callers make their own assertions.
*/
#ifndef TUBE74_TESTS_REF_TESTKIT_H
#define TUBE74_TESTS_REF_TESTKIT_H

#include <stdarg.h>
#include <stddef.h>

/* Make a new folder from a mkdtemp template such as "/tmp/t74turn.XXXXXX" into dir
   (cap bytes). 0, or -1 if it could not be made. */
int tk_mkscratch(char *dir, size_t cap, const char *template);

/* Remove dir and everything below it (links are removed, not followed). 0, or -1 with a
   message on stderr. */
int tk_rmscratch(const char *dir);

/* Remove everything below dir, hidden entries included, keeping dir. 0 or -1. */
int tk_clear(const char *dir);

/* The program under test: $TUBE74 when set and not empty, else "./tube74". */
const char *tk_prog(void);

/* tk_prog() as an absolute path (a relative one is taken from the working folder), for
   commands that run in another folder. 0, or -1 if it does not fit or getcwd fails. */
int tk_exe(char *out, size_t cap);

/* Run "cd DIR && COMMAND" through system(3), COMMAND formatted like printf.
   Its exit status, or -1 if the shell did not exit normally. */
int tk_sh(const char *dir, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int tk_vsh(const char *dir, const char *fmt, va_list ap);

/* Run argv[0] (a path, not searched) with argv, no shell: stdout to out_path, stderr to
   err_path (each NULL for /dev/null; files are created or truncated). Its exit status
   0..255, or -1 if it could not be started or a signal ended it. */
int tk_run(const char *const argv[], const char *out_path, const char *err_path);

/* tk_run of tk_prog() with the arguments that follow, up to a NULL (at most 62). */
int tk_runl(const char *out_path, const char *err_path, ...);
int tk_vrunl(const char *out_path, const char *err_path, va_list ap);

/* The whole file, NUL-terminated, malloc'd; *n its length (n may be NULL).
   NULL if it cannot be read. */
char *tk_slurp(const char *path, size_t *n);

/* Write n bytes to path (created or truncated). 0, or -1 if any step failed. */
int tk_put(const char *path, const void *data, size_t n);

/* The value of "key" in the --stats JSON file at path, as *v (true 1, false 0).
   0 for a number or a truth value, 1 for null, -1 when the file cannot be read or has
   no such key. */
int tk_stat(const char *path, const char *key, double *v);

#endif
