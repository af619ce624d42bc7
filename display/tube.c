/*
** tube.c — the storage tube's memory (paper 003 §4; docs/hardware.md "The storage tube").
**
** This file contains code to store lit dots the way a bistable storage tube does: a dot
** once written stays lit, writing it again changes nothing. Two structures:
**   lit[]    one bit per dot, row-major from y = 0 (bottom), bit (y*TUBE_W + x) — answers
**            "is it lit" and keeps each dot once;
**   order[]  the dots in the order they were first written, each as y*TUBE_W + x; it can
**            hold every dot of the tube, so storing never fails for lack of room.
** Invariant: n == number of set bits in lit[] == number of entries in order[], and
** order[] holds each lit dot exactly once.
*/
#include "display/tube.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define TUBE_DOTS (TUBE_W * TUBE_H)      /* 120,000 addressable dots */

struct tube {
  uint8_t  lit[(TUBE_DOTS + 7) / 8];     /* bit (y*TUBE_W + x): dot lit */
  uint32_t order[TUBE_DOTS];             /* first-write order, y*TUBE_W + x each */
  int      n;                            /* dots lit == entries of order[] in use */
  struct t74_error err;                  /* first out-of-tube write, for tube_end */
};

struct tube *tube_new(void)
{
  struct tube *t = malloc(sizeof *t);
  if (t) tube_erase(t);
  return t;
}

void tube_free(struct tube *t)
{
  free(t);
}

void tube_erase(struct tube *t)
{
  memset(t->lit, 0, sizeof t->lit);
  t->n = 0;
  t->err.status = T74_OK;
  t->err.msg[0] = '\0';
}

int tube_write(struct tube *t, int x, int y)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H)
    return t74_fail(&t->err, T74_EINPUT,
                    "tube: dot (%d, %d) is outside the %d x %d tube", x, y, TUBE_W, TUBE_H);
  uint32_t k = (uint32_t)y * TUBE_W + (uint32_t)x;
  uint8_t bit = (uint8_t)(1u << (k & 7));
  if (t->lit[k >> 3] & bit) return T74_OK;       /* stored already: keeps its first place */
  t->lit[k >> 3] |= bit;
  t->order[t->n++] = k;
  return T74_OK;
}

/* tube_write_dots with every dot on the tube; base: the dot (x0, y0) */
static inline __attribute__((always_inline)) void write_dots(struct tube *t, uint32_t base,
                                                             int cell, unsigned mask)
{
  uint8_t *lit = t->lit;
  uint32_t *next = t->order + t->n;
  for (; mask; mask &= mask - 1) {
    int k = __builtin_ctz(mask);
    uint32_t d = base - (uint32_t)(k / cell) * TUBE_W + (uint32_t)(k % cell);
    uint8_t bit = (uint8_t)(1u << (d & 7));
    if (lit[d >> 3] & bit) continue;       /* stored already: keeps its first place */
    lit[d >> 3] |= bit;
    *next++ = d;
  }
  t->n = (int)(next - t->order);
}

int tube_write_dots(struct tube *t, int x0, int y0, int cell, unsigned mask)
{
  if (cell < 1 || cell > 4 || (mask >> (cell * cell)) != 0 || x0 < 0 || x0 > TUBE_W - cell ||
      y0 < cell - 1 || y0 >= TUBE_H) {
    for (; mask; mask &= mask - 1) {       /* a dot may be off the tube: one by one */
      int k = __builtin_ctz(mask);
      int rc = tube_write(t, x0 + k % (cell > 0 ? cell : 1), y0 - k / (cell > 0 ? cell : 1));
      if (rc != T74_OK) return rc;
    }
    return T74_OK;
  }
  uint32_t base = (uint32_t)y0 * TUBE_W + (uint32_t)x0;   /* every dot is on the tube */
  if (cell == 4 && (x0 & 3) == 0 && t->n <= TUBE_DOTS - 16) {
    /* a row of the cell is 4 dots in one byte of lit[] (TUBE_W is a multiple of 8); its
       new dots go to order[] as four entries of which the first `count` are kept (room
       for all 16 of the cell's is left at the end of order[]) */
    static const uint8_t bit_at[16][4] = {   /* the set bits of a row, lowest first */
      {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0},
      {1, 2, 0, 0}, {0, 1, 2, 0}, {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0},
      {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3} };
    static const uint8_t count[16] = { 0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4 };
    uint8_t *lit = t->lit;
    uint32_t *next = t->order + t->n;
    for (int cy = 0; mask; cy++, mask >>= 4) {
      unsigned row = mask & 15u;
      if (!row) continue;
      uint32_t d = base - (uint32_t)cy * TUBE_W;
      unsigned sh = d & 7, fresh = row & ~((unsigned)lit[d >> 3] >> sh);
      lit[d >> 3] |= (uint8_t)(fresh << sh);
      const uint8_t *b = bit_at[fresh];
      next[0] = d + b[0]; next[1] = d + b[1]; next[2] = d + b[2]; next[3] = d + b[3];
      next += count[fresh];
    }
    t->n = (int)(next - t->order);
  } else if (cell == 4) write_dots(t, base, 4, mask);   /* constant cells: no divide per dot */
  else if (cell == 3) write_dots(t, base, 3, mask);
  else write_dots(t, base, cell, mask);
  return T74_OK;
}

int tube_lit(const struct tube *t, int x, int y)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) return 0;
  uint32_t k = (uint32_t)y * TUBE_W + (uint32_t)x;
  return (t->lit[k >> 3] >> (k & 7)) & 1;
}

_Static_assert(TUBE_W % 8 == 0, "a row of lit[] starts on a byte");

void tube_row_packed(const struct tube *t, int y, uint8_t *out)
{
  if (y < 0 || y >= TUBE_H) { memset(out, 0, TUBE_ROW_BYTES); return; }
  const uint8_t *lit = t->lit + (size_t)y * TUBE_ROW_BYTES;  /* TUBE_W: a multiple of 8 */
  for (int b = 0; b < TUBE_ROW_BYTES; b++) {     /* lit[] has the leftmost dot in bit 0 */
    unsigned v = lit[b];
    v = (v & 0xF0u) >> 4 | (v & 0x0Fu) << 4;
    v = (v & 0xCCu) >> 2 | (v & 0x33u) << 2;
    v = (v & 0xAAu) >> 1 | (v & 0x55u) << 1;
    out[b] = (uint8_t)v;
  }
}

int tube_count(const struct tube *t)
{
  return t->n;
}

int tube_order(const struct tube *t, int k, int *x, int *y)
{
  if (k < 0 || k >= t->n) return T74_EINPUT;
  *x = (int)(t->order[k] % TUBE_W);
  *y = (int)(t->order[k] / TUBE_W);
  return T74_OK;
}

static int sink_tube_point(void *ctx, int x, int y)
{
  return tube_write(ctx, x, y);
}

static int sink_tube_end(void *ctx, struct t74_error *err)
{
  struct tube *t = ctx;
  if (t->err.status == T74_OK) return T74_OK;
  return t74_fail(err, t->err.status, "%s", t->err.msg);
}

struct sink tube_sink(struct tube *t)
{
  struct sink s = { t, sink_tube_point, sink_tube_end, NULL };
  return s;
}
