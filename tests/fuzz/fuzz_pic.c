/*
** fuzz_pic.c — libFuzzer target for the background picture loader (patterns/picture.c).
**
** This file contains code to take arbitrary bytes as a background picture: pic_load reads
** them from a temporary file, as PGM (P2, P5) or PNG, whichever the first bytes say. The
** loader promises to refuse what it cannot read with status 2 (or 4) and a message naming
** the file, never to crash or read out of bounds; a picture it accepts must have sides in
** 1..PIC_MAX_SIDE, and its pixels and box-averaged samples must be 0..255.
** AddressSanitizer and UBSan watch libpng's callbacks and the PGM parser alike.
**
** Build and run with tools/fuzz.sh pic. The kept corpus is tests/fuzz/corpus_pic/,
** replayed by tests/test_import.c on every `make test`.
*/
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "patterns/picture.h"
#include "tests/ref/memrender.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char *path = mr_temp_file(data, size, "pic");
  if (!path) return 0;
  struct pic *p = NULL;
  struct t74_error err = { 0 };
  int st = pic_load(path, &p, &err);
  if (st == T74_OK) {
    int w = pic_width(p), h = pic_height(p);
    if (w < 1 || h < 1 || w > PIC_MAX_SIDE || h > PIC_MAX_SIDE) abort();
    if (pic_pixel(p, 0, 0) < 0 || pic_pixel(p, w - 1, h - 1) < 0 || pic_pixel(p, w, 0) != -1)
      abort();
    for (int j = 0; j < 3; j++)
      for (int i = 0; i < 4; i++) {
        int g = pic_sample(p, i, j, 4, 3);
        if (g < 0 || g > 255) abort();
      }
    pic_free(p);
  } else if ((st != T74_EINPUT && st != T74_EIO) || p != NULL ||
             strncmp(err.msg, path, strlen(path)) != 0) {
    fprintf(stderr, "fuzz_pic: status %d, message \"%s\"\n", st, err.msg);
    abort();
  }
  mr_temp_remove(path);
  return 0;
}
