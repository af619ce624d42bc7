/*
** file.h — the whole of an input file in memory, for every layer that reads one.
**
** Beside status.h at the bottom of the layers: the scene reader's picture loader
** (patterns/) and the Tek stream reader (cli/) both take a file whole before parsing it,
** so that a read failure (T74_EIO) is told apart from bad contents (T74_EINPUT).
*/
#ifndef T74_FILE_H
#define T74_FILE_H

#include <stddef.h>
#include <stdint.h>
#include "emu/status.h"

/* Read all of path: T74_OK with *buf (malloc'd, the caller frees it) and *len, or T74_EIO
   with "PATH: cannot open|read: why" in err and *buf untouched. */
int file_read_all(const char *path, uint8_t **buf, size_t *len, struct t74_error *err);

#endif
