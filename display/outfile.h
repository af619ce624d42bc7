/*
** outfile.h — output files that appear complete or not at all, and sets of them that are
** committed together (CONTRACT.md: "no output file created or changed"; every output path
** may be `-`; a symlink is written through, a device or FIFO written directly).
**
** This file contains code to write tube74's outputs without ever destroying what a path
** names. What a path is decides how it is written:
**   a regular file, or a new name  written to a temporary in the SAME folder as the file
**                       (".NAME.XXXXXX", mkstemp), flushed and synced, then renamed over
**                       it: rename() is atomic on POSIX, a reader sees the old file or the
**                       new one. An existing file keeps its permission bits. A symlink is
**                       followed to its final target (the link itself stays a link), also
**                       a dangling one: the file it names is created, as `>` would.
**   `-`, /dev/stdout, /dev/fd/N, /proc/self/fd/N   the open descriptor itself (standard
**                       output for `-`), written directly: its offset and append mode are
**                       the shell's.
**   a FIFO, a character device (/dev/null, a terminal)   opened and written directly,
**                       never replaced.
**   a folder, a block device, a socket   refused.
** Replacing gives the file a new inode: a hard link elsewhere keeps the old content, and
** a file whose folder we may not write cannot be replaced (T74_EIO, nothing changed).
** A direct output cannot be taken back once written, so in a set its bytes wait in an
** anonymous temporary until the commit (unless OUTFILE_STREAM asks for them as written,
** for a Tek stream that a terminal shows growing).
**
** One output alone (outfile_open ... outfile_commit) is committed at once. A SET makes
** all of a run's outputs one transaction (the two phases of style.md, "SQLite commits a
** transaction in one place"):
**   1. outset_open every output BEFORE the work starts: each path is classified and
**      opened (a missing folder or a folder as the name fail here; a FIFO waits here for
**      its reader),
**      two outputs naming the same file are refused (T74_EINPUT), and outset_check_input
**      refuses an output that is one of the run's inputs (same device and inode);
**   2. each writer writes its outfile and calls outfile_commit, which in a set only
**      finishes it (flush, sync, close); outfile_abort discards it;
**   3. outset_commit: the direct outputs get their bytes, then every temporary is renamed.
**      A failure in 1 or 2, or in writing a direct output, leaves every regular file and
**      every new name untouched (outset_free removes the temporaries).
** Two outputs are the same file when they are the same standard output, the same
** existing file (device and inode, after symlinks), or the same new name in the same
** folder. Character devices other than standard output may take several outputs
** (`-o /dev/null --stats /dev/null`): writing them stores nothing.
**
**   struct outset *set;  outset_new(&set, err);
**   struct outfile *png; outset_open(set, "-", 0, &png, err);   ... check inputs
**   ... work ...;  image_write_png_to(t, png, err);             // finishes png
**   outset_commit(set, err);  outset_free(set);
**
** Errors: T74_EIO with "FILE: what failed: why", T74_EINPUT for a refused path. New files
** get mode 0666 less the umask, as fopen would give them.
*/
#ifndef T74_OUTFILE_H
#define T74_OUTFILE_H

#include <stddef.h>
#include <stdio.h>
#include "emu/status.h"

struct outfile;                 /* opaque: the path, how it is written, stream, error */
struct outset;                  /* opaque: the outputs of one run */

enum {
  OUTFILE_STREAM = 1u << 0      /* a direct output gets its bytes as they are written */
};

/* One output alone: open PATH (classified as above). T74_OK with *out set, else an error
** and nothing created. */
int outfile_open(struct outfile **out, const char *path, struct t74_error *err);

/* The stream to write to (binary mode). Write errors are noticed at commit. */
FILE *outfile_stream(struct outfile *o);

/* The path as given, for messages. */
const char *outfile_path(const struct outfile *o);

/* Write n bytes; T74_OK or T74_EIO (the error is also kept for commit). */
int outfile_write(struct outfile *o, const void *buf, size_t n);

/* printf to the file; T74_OK or T74_EIO (kept for commit). */
int outfile_printf(struct outfile *o, const char *fmt, ...)
#if defined(__GNUC__)
  __attribute__((format(printf, 2, 3)))
#endif
  ;

/* s as a JSON string with its quotes (RFC 8259): `"` `\` and control characters escaped,
** valid UTF-8 kept, every byte that is not part of valid UTF-8 written as U+FFFD. The one
** JSON string writer of --stats: any path or name stays valid JSON. */
int outfile_json_string(struct outfile *o, const char *s);

/* Finish. Alone: flush, sync, close and rename over the final name (or, direct, close).
** In a set: flush, sync and close only; the set's commit publishes it. On any failure the
** temporary is removed, the final name is untouched and T74_EIO is returned with its
** message in err. Alone, o is freed either way; a set's outfile belongs to the set. */
int outfile_commit(struct outfile *o, struct t74_error *err);

/* Discard: close and remove the temporary; the final name is untouched. Alone, frees o. */
void outfile_abort(struct outfile *o);

/* ---- sets --------------------------------------------------------------------------- */

/* A new, empty set. T74_OK, or T74_EIO when out of memory. */
int outset_new(struct outset **out, struct t74_error *err);

/* Open PATH as one more output of the set (flags: OUTFILE_STREAM). T74_EINPUT when it is
** the same file as an output already in the set, T74_EIO when it cannot be written. */
int outset_open(struct outset *s, const char *path, unsigned flags, struct outfile **out,
                struct t74_error *err);

/* Standard output is taken by a writer outside the set (a Tek stream on stdout): a later
** `-` or /dev/stdout in the set is refused as the same file. */
int outset_reserve_stdout(struct outset *s, struct t74_error *err);

/* Refuse (T74_EINPUT, "OUTPUT: is the WHAT INPUT") when any output of the set is the file
** INPUT (same device and inode). An INPUT that cannot be looked up is no output's. */
int outset_check_input(const struct outset *s, const char *input, const char *what,
                       struct t74_error *err);

/* Publish every output: all must have been finished by outfile_commit. Direct outputs
** are written first, then the temporaries renamed. T74_OK, or the first failure. */
int outset_commit(struct outset *s, struct t74_error *err);

/* Free the set: every output not committed is discarded (temporaries removed). */
void outset_free(struct outset *s);

#endif
