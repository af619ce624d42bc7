/*
** status.h — tube74 result codes and the sticky error record.
**
** Every module returns one of these codes; only main() turns them into an exit status.
** The numbers are the exit statuses of the interface contract (shared/CONTRACT.md):
**   2 bad input or usage, 3 the scene does not fit the core, 4 a device or I/O failure.
** An error record keeps the FIRST error only (like SQLite's accError): later failures
** caused by the first do not overwrite its message, so the user sees the root cause once,
** as "FILE:LINE: what is wrong".
*/
#ifndef T74_STATUS_H
#define T74_STATUS_H

enum t74_status {
  T74_OK     = 0,   /* done */
  T74_EINPUT = 2,   /* bad input or usage: FILE:LINE: message */
  T74_ECORE  = 3,   /* the scene does not fit the core: words needed and available */
  T74_EIO    = 4    /* a device or I/O failure */
};

struct t74_error {
  int  status;      /* first non-zero status reported, else T74_OK */
  char msg[1024];   /* its message, complete (with FILE:LINE where there is one) */
};

/* Record an error unless one is already recorded; returns the status now held. e may be
   NULL (a caller that wants only the verdict): nothing is formatted or recorded, and
   status is returned. */
int t74_fail(struct t74_error *e, int status, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 3, 4)))
#endif
  ;

/* Record an error at a place in an input file: "FILE:LINE: message" (e NULL: as t74_fail). */
int t74_fail_at(struct t74_error *e, int status, const char *file, int line,
                const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 5, 6)))
#endif
  ;

#endif
