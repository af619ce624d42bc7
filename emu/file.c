/*
** file.c — the whole of an input file in memory (see file.h).
**
** This file contains code to read a file of unknown size in one go, never more than the
** caller's limit: a regular file is sized first (fstat) and refused at once when larger;
** anything else that can be read (a FIFO, a character device) is read until the limit
** plus one byte, which tells "larger" apart from "exactly the limit". The buffer doubles
** until a short read, and only then is the end of the file told apart from a read error.
*/
#include "emu/file.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int file_read_all(const char *path, size_t max, uint8_t **buf, size_t *len,
                  struct t74_error *err)
{
  FILE *f = fopen(path, "rb");
  if (!f) return t74_fail(err, T74_EIO, "%s: cannot open: %s", path, strerror(errno));
  struct stat st;
  if (fstat(fileno(f), &st) == 0) {
    const char *what = S_ISDIR(st.st_mode) ? "is a folder, not a file"
                     : S_ISBLK(st.st_mode) ? "is a block device, not a file"
                     : S_ISSOCK(st.st_mode) ? "is a socket, not a file" : NULL;
    if (!what && S_ISREG(st.st_mode) && (uintmax_t)st.st_size > (uintmax_t)max) {
      fclose(f);
      return t74_fail(err, T74_EINPUT, "%s: too large: %jd bytes (the limit is %zu bytes)",
                      path, (intmax_t)st.st_size, max);
    }
    if (what) {
      fclose(f);
      return t74_fail(err, T74_EINPUT, "%s: %s", path, what);
    }
  }
  size_t cap = max < (1 << 16) ? max + 1 : 1 << 16, n = 0;  /* bytes allocated, read */
  uint8_t *b = malloc(cap);
  bool oom = !b, large = false;
  while (b) {
    n += fread(b + n, 1, cap - n, f);
    if (n < cap) break;         /* end of file or a read error: told apart below */
    if (n > max) { large = true; break; }    /* max + 1 bytes: more than the limit */
    size_t nc = cap <= (max + 1) / 2 ? cap * 2 : max + 1;
    uint8_t *nb = realloc(b, nc);
    if (!nb) { oom = true; break; }
    b = nb;
    cap = nc;
  }
  int e = errno;
  bool bad = oom || (!large && ferror(f));
  fclose(f);
  if (large) {
    free(b);
    return t74_fail(err, T74_EINPUT, "%s: too large: more than %zu bytes (the limit)", path, max);
  }
  if (bad) {
    free(b);
    return t74_fail(err, T74_EIO, "%s: cannot read: %s", path,
                    oom ? "out of memory" : strerror(e));
  }
  *buf = b;
  *len = n;
  return T74_OK;
}
