/*
** outfile.h — atomic output files (CONTRACT.md: "no output file created or changed").
**
** This file contains code to write an output file so that it appears complete or not at
** all. The contract asks that a run which fails leaves no output file created or changed.
** So every output is written to a temporary file in the SAME folder as the final name
** (".NAME.XXXXXX", made by mkstemp), and only when all of it has been written, flushed
** and synced is it renamed over the final name — rename() within one file system is
** atomic on POSIX: a reader sees the old file or the new one, never a part. On failure
** or abort the temporary is removed, so an existing file keeps its old content.
**
**   struct outfile *o;
**   if (outfile_open(&o, path, err) != T74_OK) return err->status;
**   fwrite(..., outfile_stream(o));            // or outfile_write / outfile_printf
**   return outfile_commit(o, err);             // or outfile_abort(o) to discard
**
** outfile_commit and outfile_abort both free o; exactly one of them must be called.
** Errors are T74_EIO with a message naming the final file: "FILE: what failed: why".
** The new file gets mode 0666 less the umask, as fopen would give it.
*/
#ifndef T74_OUTFILE_H
#define T74_OUTFILE_H

#include <stddef.h>
#include <stdio.h>
#include "emu/status.h"

struct outfile;                 /* opaque: final path, temporary path, stream, error */

/* Start writing PATH: create its temporary. T74_OK with *out set, else T74_EIO. */
int outfile_open(struct outfile **out, const char *path, struct t74_error *err);

/* The stream to write to (binary mode). Write errors are noticed at commit. */
FILE *outfile_stream(struct outfile *o);

/* Write n bytes; T74_OK or T74_EIO (the error is also kept for commit). */
int outfile_write(struct outfile *o, const void *buf, size_t n);

/* printf to the file; T74_OK or T74_EIO (kept for commit). */
int outfile_printf(struct outfile *o, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;

/* Finish: flush, sync, close and rename over the final name. On any failure the
** temporary is removed, the final name is untouched and T74_EIO is returned with its
** message in err. Frees o either way. */
int outfile_commit(struct outfile *o, struct t74_error *err);

/* Discard: close and remove the temporary; the final name is untouched. Frees o. */
void outfile_abort(struct outfile *o);

#endif
