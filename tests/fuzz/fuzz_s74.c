/*
** fuzz_s74.c — libFuzzer target for the .s74 scene reader (render/scene.c), with a full render.
**
** This file contains code to take arbitrary bytes as a .s74 scene: scene_load reads them
** from a temporary file; a scene it accepts is rendered through the library (Mapper,
** Segment Generator, Priority Matrix, Visible Surface Procedure: tests/ref/memrender.c)
** and rendered again with its face list and every ring reversed. AddressSanitizer and
** UBSan watch every stage; the target abort()s when a refusal is not status 2 or 4 with
** a message naming the file, or when the two pictures differ in a single point.
**
** Build and run with tools/fuzz.sh s74 (clang -fsanitize=fuzzer,address,undefined). The
** kept corpus is tests/fuzz/corpus_s74/, replayed by tests/test_import.c on every
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
  if (mr_check(data, size, "s74", 4, NULL, why, sizeof why)) {
    fprintf(stderr, "fuzz_s74: %s\n", why);
    abort();
  }
  return 0;
}
