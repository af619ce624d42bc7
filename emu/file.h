/*
** file.h — the whole of an input file in memory, for every layer that reads one.
**
** Beside status.h at the bottom of the layers: the scene reader's picture loader
** (patterns/) and the Tek stream reader (cli/) both take a file whole before parsing it,
** so that a read failure (T74_EIO) is told apart from bad contents (T74_EINPUT).
** Every read is bounded: the caller names the largest file it accepts, and a folder, a
** block device, or anything larger (a huge file, /dev/zero, an endless FIFO) is refused
** as bad input without reading more than the limit and one byte.
*/
#ifndef T74_FILE_H
#define T74_FILE_H

#include <stddef.h>
#include <stdint.h>
#include "emu/status.h"

/* Read all of path, at most max bytes: T74_OK with *buf (malloc'd, the caller frees it)
   and *len; T74_EIO with "PATH: cannot open|read: why" in err; T74_EINPUT with "PATH: is
   a folder" or "PATH: too large ... (the limit is MAX bytes)". *buf is untouched on
   failure. */
int file_read_all(const char *path, size_t max, uint8_t **buf, size_t *len,
                  struct t74_error *err);

#endif
