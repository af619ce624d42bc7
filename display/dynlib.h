/*
** dynlib.h — a shared library opened when a command first needs it, not at start-up
** (issues 12 and 19).
**
** This file contains code to open a library with dlopen and fill a caller's table of
** function pointers from it. tube74 is linked against libpng alone (every render writes a
** PNG); SDL2 (`play`'s window, cli/sdl_load.h), libusb-1.0 (`stream` to a USB device and
** `devices`, display/usb/usb.c) and giflib (`play --movie`, display/gif.c) are opened by
** the code that uses them, when it runs: mapping and relocating each of them, with the
** libraries they need in turn, cost every render time before main() (issue 19: nine
** libraries loaded for a render that uses three). Their headers still give the types at
** compile time, and each table's slots are checked against the header's declarations
** (DYNLIB_CHECK), so a call through a table is typed as a direct call would be.
**
** A table is a struct of function pointers; a list of dynlib_sym names each function and
** the offset of its slot. ISO C has no conversion between object and function pointers;
** POSIX gives dlsym's result as an address that converts to one, so it is copied into the
** slot bytewise. A library that cannot be opened, or lacks a function, is a device or I/O
** failure (T74_EIO, exit 4) with the loader's reason, never a crash.
*/
#ifndef T74_DYNLIB_H
#define T74_DYNLIB_H

#include <stddef.h>

#include "emu/status.h"

struct dynlib_sym {
  const char *name;             /* the function, as the library exports it */
  size_t at;                    /* offset of its slot in the table (offsetof) */
};

/* A slot's type is the header's declaration of the function: a compile-time check (the
   operand of sizeof is not evaluated, so the program holds no reference to the function
   and the linker does not make it need the library). */
#define DYNLIB_CHECK(table, slot, function) ((void)sizeof((table)->slot = (function)))

/* Open soname (e.g. "libusb-1.0.so.0") into table, a struct of `size` bytes whose first
** member is `void *lib`: the handle goes there and each slot of syms[0..n-1] is filled.
** T74_OK; else T74_EIO with the table all zero and err's message "what: cannot load LABEL
** (the loader's reason); install the Debian package PACKAGE" or "what: SONAME has no
** FUNCTION". */
int dynlib_open(void *table, size_t size, const char *soname, const char *label,
                const char *package, const struct dynlib_sym *syms, size_t n,
                const char *what, struct t74_error *err);

/* Close the library of a table from dynlib_open and zero the table (nothing to close
** when its handle is NULL). */
void dynlib_close(void *table, size_t size);

#endif
