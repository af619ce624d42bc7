/*
** fuzz_tek.c — libFuzzer target for the Tektronix stream decoder (display/tek.h).
**
** This file contains code to feed arbitrary bytes to tek_decode onto a real tube, with the
** erase and write-through callbacks in place, so that AddressSanitizer and UBSan watch the
** whole decoding path: the address registers, the Bresenham walk, the stroke font and the
** tube's storage. The decoder promises that nothing in the bytes can make it fail or
** crash; this target checks the promise and a few invariants (every byte read, the tube
** never holds more dots than it has, warnings counted).
**
** Build and run with tools/fuzz.sh (clang -fsanitize=fuzzer,address,undefined). Interesting
** inputs are kept in tests/fuzz/corpus_tek/, which tests/test_tek.c replays on every
** `make test`.
*/
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "display/sink.h"
#include "display/tek.h"
#include "display/tube.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

struct fuzz_ctx {
  struct tube *tube;            /* erased on ESC FF */
  size_t wt;                    /* write-through traces seen */
};

static void on_erase(void *ctx)
{
  struct fuzz_ctx *c = ctx;
  tube_erase(c->tube);
}

static void on_wt(void *ctx, int x0, int y0, int x1, int y1)
{
  struct fuzz_ctx *c = ctx;
  (void)x0; (void)y0; (void)x1; (void)y1;
  c->wt++;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  struct fuzz_ctx c;
  c.tube = tube_new();
  c.wt = 0;
  if (!c.tube) return 0;
  struct sink s = tube_sink(c.tube);
  struct tek_report rep;
  memset(&rep, 0, sizeof rep);
  rep.erase = on_erase;
  rep.write_through = on_wt;
  rep.ctx = &c;
  int st = tek_decode(data, size, &s, &rep);
  if (st != T74_OK) abort();                          /* a tube never refuses clipped dots */
  if (rep.bytes != size) abort();                     /* every byte read */
  if (tube_count(c.tube) > TUBE_W * TUBE_H) abort();
  if (rep.wt_traces != c.wt) abort();
  tube_free(c.tube);
  return 0;
}
