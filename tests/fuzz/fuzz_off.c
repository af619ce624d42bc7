/*
** fuzz_off.c — libFuzzer target for the .off import (render/import.c), with a full render.
**
** This file contains code to take arbitrary bytes as a .off scene: scene_load reads them
** from a temporary file; a scene it accepts is rendered through the library (Mapper,
** Segment Generator, Priority Matrix, Visible Surface Procedure: tests/ref/memrender.c)
** and rendered again with its face list and every ring reversed. AddressSanitizer and
** UBSan watch every stage; the target abort()s when a refusal is not status 2 or 4 with
** a message naming the file, or when the two pictures differ in a single point.
** It also reads the file a second time with the vertex indices of every face line
** reversed: accepted or refused alike, and the same picture.
**
** Build and run with tools/fuzz.sh off (clang -fsanitize=fuzzer,address,undefined). The
** kept corpus is tests/fuzz/corpus_off/, replayed by tests/test_import.c on every
** `make test`.
*/
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/ref/memrender.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char why[600];
  if (mr_check(data, size, "off", 4, NULL, why, sizeof why)) {
    fprintf(stderr, "fuzz_off: %s\n", why);
    abort();
  }
  size_t rn = 0;
  uint8_t *rev = mr_off_reverse_rings(data, size, &rn);
  if (!rev) return 0;
  struct scene *a = NULL, *b = NULL;
  int st = mr_load_bytes(data, size, "off", &a), st2 = mr_load_bytes(rev, rn, "off", &b);
  if ((st == 0) != (st2 == 0)) {
    fprintf(stderr, "fuzz_off: status %d, with the rings reversed %d\n", st, st2);
    abort();
  }
  if (st == 0 && mr_same_picture(a, b, 4) == 0) {
    fprintf(stderr, "fuzz_off: the picture changes when the rings are reversed\n");
    abort();
  }
  scene_free(a);
  scene_free(b);
  free(rev);
  return 0;
}
