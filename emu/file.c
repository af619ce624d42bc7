/*
** file.c — the whole of an input file in memory (see file.h).
**
** This file contains code to read a file of unknown size in one go: the buffer doubles
** until a short read, and only then is the end of the file told apart from a read error.
*/
#include "emu/file.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int file_read_all(const char *path, uint8_t **buf, size_t *len, struct t74_error *err)
{
  FILE *f = fopen(path, "rb");
  if (!f) return t74_fail(err, T74_EIO, "%s: cannot open: %s", path, strerror(errno));
  size_t cap = 1 << 16, n = 0;  /* bytes allocated, bytes read */
  uint8_t *b = malloc(cap);
  bool oom = !b;
  while (b) {
    n += fread(b + n, 1, cap - n, f);
    if (n < cap) break;         /* end of file or a read error: told apart below */
    uint8_t *nb = cap <= SIZE_MAX / 2 ? realloc(b, cap * 2) : NULL;
    if (!nb) { oom = true; break; }
    b = nb;
    cap *= 2;
  }
  int e = errno;
  bool bad = oom || ferror(f);
  fclose(f);
  if (bad) {
    free(b);
    return t74_fail(err, T74_EIO, "%s: cannot read: %s", path,
                    oom ? "out of memory" : strerror(e));
  }
  *buf = b;
  *len = n;
  return T74_OK;
}
