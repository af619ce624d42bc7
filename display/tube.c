/*
** tube.c — the storage tube's memory (paper 003 §4; docs/hardware.md "The storage tube").
**
** This file contains code to store lit dots the way a bistable storage tube does: a dot
** once written stays lit, writing it again changes nothing. Two structures:
**   lit[]    one bit per dot, row-major from y = 0 (bottom), bit (y*TUBE_W + x) — answers
**            "is it lit" and keeps each dot once;
**   order[]  the dots in the order they were first written, each as y*TUBE_W + x; it can
**            hold every dot of the tube, so storing never fails for lack of room.
** order[] is written late (issue 19: a frame of --frames nobody reads the order of wrote
** every dot into it, half of a small scene's frame): order[0 .. done) holds dots, and
** after them order[done .. done + nlog) holds writes not yet spelled out, each one word
** for one or more new dots (a dot; a row of up to 4 dots; an aligned 4x4 cell; a 3x3 cell;
** a row of cells written where no dot was lit), spelled out in place when the order is
** first read (settle).
** Invariant: the set bits in lit[] are the dots of order[0 .. done) and the new dots of the
** nlog writes; spelled out, order[0 .. done) holds each lit dot exactly once.
*/
#include "display/tube.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#define TUBE_DOTS (TUBE_W * TUBE_H)      /* 120,000 addressable dots */

struct tube {
  _Alignas(8)                            /* (whole 64-bit words are stored: put_row3) */
  uint8_t  lit[(TUBE_DOTS + 7) / 8 + 8]; /* bit (y*TUBE_W + x): dot lit; 8 last bytes spare
                                            (dots are read up to eight bytes at a time) */
  uint8_t  left[(TUBE_DOTS + 7) / 8 + 8];/* settle's scratch: the dots not yet spelled out */
  uint32_t order[TUBE_DOTS];             /* first-write order, y*TUBE_W + x each, then the
                                            writes not yet spelled out */
  int      done;                         /* order[0 .. done): dots */
  int      nlog;                         /* order[done .. done + nlog): writes */
  uint32_t lit_end;                      /* every lit dot's y*TUBE_W + x is below it */
  struct t74_error err;                  /* first out-of-tube write, for tube_end */
};

/* A write of order[], one word: bit 31 set, an aligned 4x4 cell: bits 0-14 its dot
** (x0, y0) over 4, bits 15-30 its new dots as tube_write_dots' mask; bits 31-30 01, a 3x3
** cell: bits 0-16 its dot (x0, y0), bits 17-25 its new dots as that mask; bits 31-30 00, a
** row: bits 0-16 its first dot, bits 17-20 its new dots (bit b: that dot + b), not all 0;
** bits 31-30 00 and 17-20 0, a run: count cells (bits 22-29, 1 .. 255) of 3x3 (bit 21
** clear) or 4x4 (set) abutting left to right from dot (x0, y0) (bits 0-16), written where
** none of their dots was lit, each cell's new dots its dots lit just after the write. A
** run keeps no masks: settle finds them in lit[] (see there). */
_Static_assert(TUBE_DOTS <= 1 << 17 && TUBE_DOTS / 4 <= 1 << 15, "a dot in a write's bits");
_Static_assert(TUBE_W / 3 <= 255, "a row's cells in a run's count");
_Static_assert(((TUBE_DOTS + 7) / 8 + 8) % 8 == 0 && (TUBE_DOTS + 63) / 64 * 8 <= (TUBE_DOTS + 7) / 8 + 8,
               "lit[] is whole 64-bit words, the last dot's word within it (put_row3)");
_Static_assert(TUBE_W % 8 == 0, "a row of lit[] starts on a byte; an aligned 4x4 cell's "
               "rows are the low or high half of a byte each");

void tube_free(struct tube *t)
{
  free(t);
}

/* b[0 .. n) cleared, at most 2 kB a memset: the C library clears a larger block with
** `rep stosb`, which valgrind counts as an instruction a byte (the project's measure is
** callgrind's count; the work is the same either way). */
static void clear_bytes(uint8_t *b, size_t n)
{
  for (size_t at = 0; at < n; at += 2048) memset(b + at, 0, n - at < 2048 ? n - at : 2048);
}

struct tube *tube_new(void)
{
  struct tube *t = malloc(sizeof *t);
  if (!t) return NULL;
  t->lit_end = UINT32_MAX;                 /* tube_erase clears all of lit[] (the spare bytes
                                              too): nothing of it is known yet */
  tube_erase(t);
  return t;
}

/* Every lit dot is below lit_end: lit[] is 0 from byte lit_end / 8 + 1 on (a write stores
** no bit but a lit dot's), so only the bytes before are cleared. */
void tube_erase(struct tube *t)
{
  size_t n = (size_t)(t->lit_end >> 3) + 1;
  clear_bytes(t->lit, n < sizeof t->lit ? n : sizeof t->lit);
  t->done = t->nlog = 0;
  t->lit_end = 0;
  t->err.status = T74_OK;
  t->err.msg[0] = '\0';
}

/* A write's first dot, its new dots as a cell's mask, and that cell's width (not a run). */
static inline uint32_t write_of(uint32_t v, unsigned *m, unsigned *cell)
{
  if (v >> 31) { *m = (v >> 15) & 0xffffu; *cell = 4; return (v & 0x7fffu) << 2; }
  if (v >> 30) { *m = (v >> 17) & 0x1ffu; *cell = 3; return v & 0x1ffffu; }
  *m = (v >> 17) & 15u;                    /* a row: the top row of a 4-wide cell */
  *cell = 4;
  return v & 0x1ffffu;
}

/* Is write v a run (bits 31-30 and 17-20 clear)? Its cells' width and count. */
static inline bool run_of(uint32_t v, unsigned *cell, unsigned *count)
{
  if (v & (3u << 30 | 15u << 17)) return false;
  *cell = v >> 21 & 1 ? 4 : 3;
  *count = v >> 22 & 0xffu;
  return true;
}

/* The run's word: count (1 .. 255) cells of cell (3 or 4) from dot base. */
static inline uint32_t run_word(uint32_t base, int cell, int count)
{
  return (uint32_t)count << 22 | (uint32_t)(cell == 4) << 21 | base;
}

/* The dots lit: the set bits of lit[] (the invariant at the top), those below lit_end. */
static int count(const struct tube *t)
{
  const size_t nb = ((size_t)t->lit_end + 63) / 64 * 8;   /* whole words: lit[] has 8 spare
                                                             bytes, all 0 past lit_end */
  int n = 0;
  for (size_t b = 0; b < nb; b += 8) {
    uint64_t w;
    memcpy(&w, t->lit + b, sizeof w);
    n += __builtin_popcountll(w);
  }
  return n;
}

/* Dot d of left[] (settle's scratch): lit and not yet spelled out; and cleared. */
static inline unsigned left_has(const uint8_t *left, uint32_t d)
{
  return left[d >> 3] >> (d & 7) & 1u;
}

static inline void left_clear(uint8_t *left, uint32_t d)
{
  left[d >> 3] &= (uint8_t)~(1u << (d & 7));
}

/* The writes spelled out into dots, in place from the last: each write's dots take at
** least its one word, so no write is overwritten before it is read. A tube is only read
** through const pointers: what it stores does not change, and every tube is tube_new's
** (never a const object).
** A run's cells' new dots are found in left[], a copy of lit[] from which each write's dots
** are cleared as it is spelled out, the last write first: when the run is reached, the
** dots of its cells in left[] are its own. (Its cells' dots were all unlit before it; the
** dots lit after it are the new dots of the writes after it, each of one of them, and
** cleared already; the dots of the writes before it are not among its cells'.) */
static void settle(const struct tube *ct)
{
  if (!ct->nlog) return;
  struct tube *t = (struct tube *)ct;
  uint32_t *o = t->order;
  uint8_t *left = t->left;
  const size_t nb = (size_t)(t->lit_end >> 3) + 1;    /* lit[] is 0 past it */
  memcpy(left, t->lit, nb < sizeof t->lit ? nb : sizeof t->lit);
  const int n = count(t);
  int w = n;
  for (int e = t->done + t->nlog - 1; e >= t->done; e--) {
    const uint32_t v = o[e];
    unsigned m, cell, cnt;
    if (run_of(v, &cell, &cnt)) {
      for (int c = (int)cnt - 1; c >= 0; c--) {   /* the last cell first */
        const uint32_t d = (v & 0x1ffffu) + (uint32_t)c * cell;
        for (int k = (int)(cell * cell) - 1; k >= 0; k--) {   /* its last dot first */
          const uint32_t dk = d - ((unsigned)k / cell) * TUBE_W + (unsigned)k % cell;
          if (!left_has(left, dk)) continue;
          left_clear(left, dk);
          o[--w] = dk;
        }
      }
      continue;
    }
    uint32_t d = write_of(v, &m, &cell);
    for (; m; ) {                          /* the last dot first */
      unsigned k = 31u - (unsigned)__builtin_clz(m);
      const uint32_t dk = d - (k / cell) * TUBE_W + k % cell;
      left_clear(left, dk);
      o[--w] = dk;
      m &= ~(1u << k);
    }
  }
  t->done = n;
  t->nlog = 0;
}

/* Dots d + b for each bit b of row (at most 4, in one row of the tube): the new ones lit,
** one write for them. */
static inline __attribute__((always_inline)) void write_row(struct tube *t, uint32_t d,
                                                            unsigned row)
{
  uint8_t *l = t->lit + (d >> 3);
  unsigned sh = d & 7, v = (unsigned)l[0] | (unsigned)l[1] << 8;
  unsigned fresh = row & ~(v >> sh);
  if (!fresh) return;                      /* stored already: they keep their first places */
  v |= fresh << sh;
  l[0] = (uint8_t)v;
  l[1] = (uint8_t)(v >> 8);
  t->order[t->done + t->nlog++] = fresh << 17 | d;
}

int tube_write(struct tube *t, int x, int y)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H)
    return t74_fail(&t->err, T74_EINPUT,
                    "tube: dot (%d, %d) is outside the %d x %d tube", x, y, TUBE_W, TUBE_H);
  const uint32_t d = (uint32_t)y * TUBE_W + (uint32_t)x;
  if (d >= t->lit_end) t->lit_end = d + 1;
  write_row(t, d, 1);
  return T74_OK;
}

/* tube_write_dots with every dot on the tube; base: the dot (x0, y0); a row at a time */
static inline __attribute__((always_inline)) void write_dots(struct tube *t, uint32_t base,
                                                             int cell, unsigned mask)
{
  const unsigned full = (1u << cell) - 1;
  for (int cy = 0; mask; cy++, mask >>= cell)
    if (mask & full) write_row(t, base - (uint32_t)cy * TUBE_W, mask & full);
}

/* A 4x4 cell's mask, row r (bits 4r .. 4r + 3) to the low half of byte r; and back. */
static inline uint32_t spread4(unsigned m)
{
  uint32_t v = m & 0xffffu;
  v = (v | v << 8) & 0x00ff00ffu;
  return (v | v << 4) & 0x0f0f0f0fu;
}

static inline unsigned gather4(uint32_t v)
{
  v &= 0x0f0f0f0fu;
  v = (v | v >> 4) & 0x00ff00ffu;
  return (v | v >> 8) & 0xffffu;
}

/* The lit[] bytes of an aligned 4x4 cell's rows, l its top row's: byte r of the word is
** the cell's row r (one row of the tube lower each); and stored back. */
enum { ROW_BYTES = TUBE_W / 8 };

static inline uint32_t rows_of(const uint8_t *l)
{
  return (uint32_t)l[0] | (uint32_t)l[-ROW_BYTES] << 8 | (uint32_t)l[-2 * ROW_BYTES] << 16 |
         (uint32_t)l[-3 * ROW_BYTES] << 24;
}

static inline void rows_put(uint8_t *l, uint32_t v)
{
  l[0] = (uint8_t)v;
  l[-ROW_BYTES] = (uint8_t)(v >> 8);
  l[-2 * ROW_BYTES] = (uint8_t)(v >> 16);
  l[-3 * ROW_BYTES] = (uint8_t)(v >> 24);
}

/* An aligned 4x4 cell (x0 a multiple of 4) on the tube, base its dot (x0, y0): each row
** of the cell is 4 dots in one byte of lit[] (TUBE_W is a multiple of 8), at the same
** shift in each; its new dots are one write at *next. */
static inline __attribute__((always_inline)) void write_cell4(uint8_t *lit, uint32_t **next,
                                                              uint32_t base, unsigned mask)
{
  uint8_t *l = lit + (base >> 3);
  const unsigned sh = base & 7;
  uint32_t have = rows_of(l), fresh = spread4(mask) << sh & ~have;
  if (!fresh) return;                      /* stored already: they keep their first places */
  rows_put(l, have | fresh);
  *(*next)++ = 1u << 31 | gather4(fresh >> sh) << 15 | base >> 2;
}

/* Two aligned 4x4 cells side by side, the first at a byte's start (x0 a multiple of 8):
** their rows share the bytes; as write_cell4 of each in turn. */
static inline __attribute__((always_inline)) void write_cell4_pair(uint8_t *lit,
                                                                   uint32_t **next,
                                                                   uint32_t base,
                                                                   unsigned ma, unsigned mb)
{
  uint8_t *l = lit + (base >> 3);
  uint32_t have = rows_of(l), want = spread4(ma) | spread4(mb) << 4, fresh = want & ~have;
  if (!fresh) return;
  rows_put(l, have | fresh);
  unsigned fa = ma, fb = mb;               /* every dot new (a tube being drawn) */
  if (fresh != want) {
    fa = gather4(fresh);
    fb = gather4(fresh >> 4);
  }
  if (fa) *(*next)++ = 1u << 31 | fa << 15 | base >> 2;
  if (fb) *(*next)++ = 1u << 31 | fb << 15 | (base + 4) >> 2;
}

/* A 3x3 cell on the tube, base its dot (x0, y0): a row of the cell is 3 dots in two bytes
** of lit[]; its new dots are one write at *next. */
static inline __attribute__((always_inline)) void write_cell3(uint8_t *lit, uint32_t **next,
                                                              uint32_t base, unsigned mask)
{
  unsigned fresh = 0;
  for (int cy = 0; cy < 3; cy++) {
    uint32_t d = base - (uint32_t)cy * TUBE_W;
    uint8_t *l = lit + (d >> 3);
    unsigned sh = d & 7, v = (unsigned)l[0] | (unsigned)l[1] << 8;
    unsigned f = (mask >> (3 * cy)) & 7u & ~(v >> sh);
    v |= f << sh;
    l[0] = (uint8_t)v;
    l[1] = (uint8_t)(v >> 8);
    fresh |= f << (3 * cy);
  }
  if (fresh) *(*next)++ = 1u << 30 | fresh << 17 | base;
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
  if (base + (uint32_t)cell > t->lit_end) t->lit_end = base + (uint32_t)cell;  /* its top row */
  if (cell == 3 || (cell == 4 && (x0 & 3) == 0)) {
    uint32_t *next = t->order + t->done + t->nlog;
    if (cell == 4) write_cell4(t->lit, &next, base, mask);
    else write_cell3(t->lit, &next, base, mask);
    t->nlog = (int)(next - (t->order + t->done));
  } else write_dots(t, base, cell, mask);
  return T74_OK;
}

/* The OR of count cells' masks (within the cell full when it has no bit past full; 0 when
** no cell has a dot). */
static unsigned masks_or(const uint16_t *masks, int count)
{
  unsigned any = 0;
  int c = 0;
#ifdef __SSE2__
  __m128i mv = _mm_setzero_si128();         /* eight masks an OR */
  for (; c + 8 <= count; c += 8)
    mv = _mm_or_si128(mv, _mm_loadu_si128((const __m128i *)(const void *)(masks + c)));
  if (c < count && count >= 8) {            /* the last eight, some again */
    mv = _mm_or_si128(mv, _mm_loadu_si128((const __m128i *)(const void *)(masks + count - 8)));
    c = count;
  }
  mv = _mm_or_si128(mv, _mm_srli_si128(mv, 8));
  mv = _mm_or_si128(mv, _mm_srli_si128(mv, 4));
  mv = _mm_or_si128(mv, _mm_srli_si128(mv, 2));
  any = (unsigned)_mm_cvtsi128_si32(mv) & 0xffffu;
#endif
  for (; c < count; c++) any |= masks[c];
  return any;
}

/* Are the cell (3 or 4) rows of lit[] under count cells abutting from dot base (on the
** tube) all unlit? (The bytes that hold the cells' dots are asked for, a few dots either
** side too: a no is only a loss of speed.) */
static bool blank_cells(const uint8_t *lit, uint32_t base, int cell, int count)
{
  const uint32_t b0 = base >> 3, b1 = (base + (uint32_t)(cell * count) - 1) >> 3;
  for (int r = 0; r < cell; r++) {
    const uint8_t *l = lit + b0 - (uint32_t)r * ROW_BYTES;
    uint32_t k = 0, n = b1 - b0 + 1;
    uint64_t v = 0;
    for (; k + 8 <= n; k += 8) {
      uint64_t w;
      memcpy(&w, l + k, sizeof w);
      v |= w;
    }
    for (; k < n; k++) v |= l[k];
    if (v) return false;
  }
  return true;
}

#ifdef __SSE2__
/* Eight aligned 4x4 cells side by side on unlit rows, the first at a byte's start (base,
** a multiple of 8), their masks within the cell: a 32-bit word of each of the 4 rows of
** lit[] (cell 2k the low half of byte k, cell 2k + 1 the high), stored as it is (the
** cells' dots are those 32 dots of each row, all unlit before): rows8 makes the words
** (row r in 32-bit lane r), write_blank8 stores them. */
static inline __m128i rows8v(__m128i m)
{
  /* 32-bit lane k holds cells 2k (x, low half) and 2k + 1 (y), a nibble a row:
     x0 x1 x2 x3 y0 y1 y2 y3 from the lowest bits. The even rows' nibbles are the low
     halves of its bytes (a: x0, x2, y0, y2), the odd rows' the high halves (b: x1, x3,
     y1, y3); a | a >> 12 has x0 | y0 << 4 in byte 0 and x2 | y2 << 4 in byte 1: row 0's
     and row 2's byte of the pair (c), likewise rows 1 and 3 (d). Those 16 bits of each
     lane, sign-extended (so that the signed pack keeps them as they are), packed to 16
     bits: c0 .. c3 d0 .. d3; their low bytes, then their high bytes, packed to bytes:
     rows 0, 1, 2, 3, a 32-bit word each (pairs 0 .. 3 from its low byte). */
  const __m128i low = _mm_set1_epi32(0x0f0f0f0f);
  const __m128i a = _mm_and_si128(m, low), b = _mm_and_si128(_mm_srli_epi32(m, 4), low);
  const __m128i c = _mm_or_si128(a, _mm_srli_epi32(a, 12));
  const __m128i d = _mm_or_si128(b, _mm_srli_epi32(b, 12));
  const __m128i cd = _mm_packs_epi32(_mm_srai_epi32(_mm_slli_epi32(c, 16), 16),
                                     _mm_srai_epi32(_mm_slli_epi32(d, 16), 16));
  return _mm_packus_epi16(_mm_and_si128(cd, _mm_set1_epi16(0xff)), _mm_srli_epi16(cd, 8));
}

/* rows8v of the eight masks at masks */
static inline __m128i rows8(const uint16_t *masks)
{
  return rows8v(_mm_loadu_si128((const __m128i *)(const void *)masks));
}

static inline void write_blank8(uint8_t *lit, uint32_t base, const uint16_t *masks)
{
  const __m128i rows = rows8(masks);
  uint8_t *l = lit + (base >> 3);
  const uint32_t w0 = (uint32_t)_mm_cvtsi128_si32(rows),
                 w1 = (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(rows, 4)),
                 w2 = (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(rows, 8)),
                 w3 = (uint32_t)_mm_cvtsi128_si32(_mm_srli_si128(rows, 12));
  memcpy(l, &w0, sizeof w0);
  memcpy(l - ROW_BYTES, &w1, sizeof w1);
  memcpy(l - 2 * ROW_BYTES, &w2, sizeof w2);
  memcpy(l - 3 * ROW_BYTES, &w3, sizeof w3);
}

/* write_blank8 of sixteen cells: the two eights' row words side by side, 64 bits a row,
** stored from the vectors (no word taken out of them; a high half through
** _mm_storel_epi64, whose store may be unaligned: _mm_storeh_pd's double may not, and the
** row bytes are not 8-aligned); nothing when no cell has a dot (the rows' 64 bits are the
** cells' dots, unlit: 0 already). */
static inline void write_blank16v(uint8_t *lit, uint32_t base, __m128i ma, __m128i mb)
{
  const __m128i a = rows8v(ma), b = rows8v(mb);
  const __m128i r01 = _mm_unpacklo_epi32(a, b), r23 = _mm_unpackhi_epi32(a, b);
  uint8_t *l = lit + (base >> 3);
  _mm_storel_epi64((__m128i *)(void *)l, r01);
  _mm_storel_epi64((__m128i *)(void *)(l - ROW_BYTES), _mm_unpackhi_epi64(r01, r01));
  _mm_storel_epi64((__m128i *)(void *)(l - 2 * ROW_BYTES), r23);
  _mm_storel_epi64((__m128i *)(void *)(l - 3 * ROW_BYTES), _mm_unpackhi_epi64(r23, r23));
}

static inline void write_blank16(uint8_t *lit, uint32_t base, const uint16_t *masks)
{
  const __m128i ma = _mm_loadu_si128((const __m128i *)(const void *)masks);
  const __m128i mb = _mm_loadu_si128((const __m128i *)(const void *)(masks + 8));
  const __m128i none = _mm_cmpeq_epi16(_mm_or_si128(ma, mb), _mm_setzero_si128());
  if (_mm_movemask_epi8(none) == 0xffff) return;
  write_blank16v(lit, base, ma, mb);
}
#endif

/* A 3x3 cell's mask with its rows apart: row r (bits 3r .. 3r + 2) to bits 21r .. 21r + 2,
** so that seven cells side by side are three lanes of 21 bits, a lane the cells' dots of
** one row of the tube (`acc << 3 | LANES3(m)` from the last cell to the first). */
#define LANES3(m) ((uint64_t)((m) & 7) | (uint64_t)((m) >> 3 & 7) << 21 | \
                   (uint64_t)((m) >> 6 & 7) << 42)
#define LANES3_8(m) LANES3(m), LANES3((m) + 1), LANES3((m) + 2), LANES3((m) + 3), \
                    LANES3((m) + 4), LANES3((m) + 5), LANES3((m) + 6), LANES3((m) + 7)
#define LANES3_64(m) LANES3_8(m), LANES3_8((m) + 8), LANES3_8((m) + 16), LANES3_8((m) + 24), \
                     LANES3_8((m) + 32), LANES3_8((m) + 40), LANES3_8((m) + 48), \
                     LANES3_8((m) + 56)
static const uint64_t lanes3[512] = { LANES3_64(0), LANES3_64(64), LANES3_64(128),
                                      LANES3_64(192), LANES3_64(256), LANES3_64(320),
                                      LANES3_64(384), LANES3_64(448) };
enum { LANE3 = 21, RUN3 = 7 };              /* a lane's bits, cells a run */

/* The inverse: the cell at the bottom of lanes v, its mask. */
static inline unsigned unlanes3(uint64_t v)
{
  return (unsigned)(v & 7) | (unsigned)(v >> LANE3 & 7) << 3 | (unsigned)(v >> 2 * LANE3 & 7) << 6;
}

/* The writes of n <= RUN3 3x3 cells abutting from dot base (on the tube), their masks
** within the cell and every dot of them new: one for each cell with a dot, left to right,
** from o; the new end of the writes. */
static inline __attribute__((always_inline)) uint32_t *write_words3(uint32_t *o, uint32_t base,
                                                                  const uint16_t *masks, int n)
{
#ifdef __SSE2__
  uint64_t w0, w1;                         /* cells 0-3 and 3-6 of seven */
  const uint64_t ones = 0x0001000100010001u, highs = 0x8000800080008000u;
  if (n == RUN3 && (memcpy(&w0, masks, sizeof w0), memcpy(&w1, masks + 3, sizeof w1),
                    !((w0 - ones) & ~w0 & highs) && !((w1 - ones) & ~w1 & highs))) {
    /* seven cells, none of no dot (the borrow test finds a 16-bit lane of 0 exactly
       when there is one): their seven writes, the fourth stored twice (the same word);
       a mask is within the cell, 9 bits, and base + 18 a dot, below 2^17 */
    const __m128i z = _mm_setzero_si128();
    const __m128i b0 = _mm_add_epi32(_mm_set1_epi32((int)(1u << 30 | base)),
                                     _mm_setr_epi32(0, 3, 6, 9));
    const __m128i b1 = _mm_add_epi32(b0, _mm_set1_epi32(9));
    const __m128i m0 = _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)masks), z);
    const __m128i m1 = _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)(masks + 3)), z);
    _mm_storeu_si128((__m128i *)(void *)o, _mm_or_si128(_mm_slli_epi32(m0, 17), b0));
    _mm_storeu_si128((__m128i *)(void *)(o + 3), _mm_or_si128(_mm_slli_epi32(m1, 17), b1));
    return o + RUN3;
  }
#endif
  for (int c = 0; c < n; c++, base += 3)
    if (masks[c]) *o++ = 1u << 30 | (uint32_t)masks[c] << 17 | base;
  return o;
}

/* n <= RUN3 3x3 cells abutting from dot base (on the tube), their masks within the cell
** (as lanes, acc): as write_cell3 of each in turn. A row of the cells is one lane: 21 dots
** from the same shift in a 32-bit word of lit[] (TUBE_W a multiple of 8: the same in each
** row). */
static inline __attribute__((always_inline)) void write_run3(uint8_t *lit, uint32_t **next,
                                                             uint32_t base, uint64_t acc,
                                                             const uint16_t *masks, int n)
{
  const uint32_t sh = base & 7;
  uint64_t fresh = 0;
  for (int r = 0; r < 3; r++) {
    uint8_t *l = lit + ((base - (uint32_t)r * TUBE_W) >> 3);
    uint32_t have;
    memcpy(&have, l, sizeof have);
    const uint32_t f = (uint32_t)(acc >> LANE3 * r) & ((1u << LANE3) - 1) & ~(have >> sh);
    have |= f << sh;
    memcpy(l, &have, sizeof have);
    fresh |= (uint64_t)f << LANE3 * r;
  }
  uint32_t *o = *next;
  if (fresh == acc) {                      /* every dot new (a tube being drawn) */
    *next = write_words3(o, base, masks, n);
    return;
  } else {
    for (int c = 0; c < n; c++, base += 3, fresh >>= 3) {
      const unsigned m = unlanes3(fresh);
      if (m) *o++ = 1u << 30 | m << 17 | base;
    }
  }
  *next = o;
}

/* n <= RUN3 3x3 cells abutting from dot base (on the tube) as lanes acc, their dots all
** unlit: each row's lane put into lit[] as it is (no write of order[]). */
static inline __attribute__((always_inline)) void put_lanes3(uint8_t *lit, uint32_t base,
                                                             uint64_t acc)
{
  const uint32_t sh = base & 7;
  for (int r = 0; r < 3; r++) {
    uint8_t *l = lit + ((base - (uint32_t)r * TUBE_W) >> 3);
    uint32_t have;
    memcpy(&have, l, sizeof have);
    have |= (uint32_t)(acc >> LANE3 * r & ((1u << LANE3) - 1)) << sh;
    memcpy(l, &have, sizeof have);
  }
}

/* Whole groups of three runs (21 cells, 63 dots a row) for put_rows3: a row of cells on
** the tube is at most TUBE_W / 3 cells, GROUPS3 groups. */
enum { GROUP3 = 3 * RUN3, GROUPS3 = (TUBE_W / 3 + GROUP3 - 1) / GROUP3 };

/* Row r (0: the top row of the cells, 2: the bottom) of ngroups groups of 3x3 cells, the
** runs' lanes at acc (3 * ngroups of them; a run of no cell is 0), from dot s to the
** row's end e (s < e), lit[]'s dots from s on all unlit. The row's bits go into
** lit[] as whole aligned 64-bit words (lit[] is 8-aligned and a whole number of words
** long; bit d of word k is dot 64k + d, the host little-endian as everywhere in this file),
** each built in a register: only the first word is read (for the dots below s, which
** it keeps), so no load reads bytes that a store before it wrote in part (a 32-bit
** read-modify-write of each run's lane, overlapping the last run's store, failed to take
** the stored bytes forward at every run: issue 19). A group is 63 dots from pos of word
** p: the group's bits fill word p from pos on (its first 64 - pos bits) and the next word
** below pos - 1, so the position falls by one a group and each group but one in 64 ends
** a word, stored whole. The dots past the row's end in its last word are stored 0: they
** are unlit (past s), and the rows above, which may have dots there, are stored after. */
static inline __attribute__((always_inline)) void put_row3(uint8_t *lit, uint32_t s,
                                                           uint32_t e, const uint64_t *acc,
                                                           int ngroups, int r)
{
  const uint64_t lane = (1u << LANE3) - 1;
  uint8_t *p = lit + (s >> 6 << 3);
  unsigned pos = s & 63;
  uint64_t w;
  memcpy(&w, p, sizeof w);                 /* the dots below s kept (those from s on: 0) */
  for (int g = 0; g < ngroups; g++, acc += 3) {
    /* lane r of each run, the three side by side (r a constant: each lane moved once; a
       run's lanes are below bit 63, so lane 2 needs no mask) */
    const uint64_t v =
      r == 0 ? (acc[0] & lane) | (acc[1] & lane) << LANE3 | (acc[2] & lane) << 2 * LANE3
      : r == 1 ? (acc[0] >> LANE3 & lane) | (acc[1] & lane << LANE3) |
                 (acc[2] & lane << LANE3) << LANE3
      : acc[0] >> 2 * LANE3 | (acc[1] >> LANE3 & lane << LANE3) | (acc[2] & lane << 2 * LANE3);
    const uint64_t lo = w | v << pos, hi = v >> 1 >> (pos ^ 63);   /* (v >> (64 - pos)) */
    memcpy(p, &lo, sizeof lo);             /* word p: whole when pos > 0 */
    const bool next = pos != 0;            /* pos + 63 >= 64: the group ends word p */
    p += next ? 8 : 0;
    w = next ? hi : lo;
    pos = (pos + 63) & 63;
  }
  if ((size_t)(p - lit) <= (size_t)((e - 1) >> 6 << 3)) memcpy(p, &w, sizeof w);  /* the last
                                              word, when the row has a dot in it */
}

/* count 3x3 cells abutting from dot base (on the tube) as the lanes of their runs at acc
** (RUN3 cells a run, a run of no cell 0 up to a whole number of groups), their dots all
** unlit: each row's lanes put into lit[] as they are (no write of order[]), a row after
** another from the bottom, so that a row's first word, read, has the bits of the row
** below it if they share it. */
static inline __attribute__((always_inline)) void put_rows3(uint8_t *lit, uint32_t base,
                                                            const uint64_t *acc, int count)
{
  const int ngroups = (count + GROUP3 - 1) / GROUP3;
  const uint32_t s = base - 2 * TUBE_W, e = s + 3 * (uint32_t)count;
  put_row3(lit, s, e, acc, ngroups, 2);    /* (r a constant in each: its shifts too) */
  put_row3(lit, s + TUBE_W, e + TUBE_W, acc, ngroups, 1);
  put_row3(lit, s + 2 * TUBE_W, e + 2 * TUBE_W, acc, ngroups, 0);
}

/* write_run3 where the cells' dots are all unlit: every dot new (its fresh is acc), so
** each row's lane is put into lit[] as it is; the new end of the writes. */
static inline __attribute__((always_inline)) uint32_t *write_new3(uint8_t *lit, uint32_t *next,
                                                                uint32_t base, uint64_t acc,
                                                                const uint16_t *masks, int n)
{
  put_lanes3(lit, base, acc);
  return write_words3(next, base, masks, n);
}

int tube_write_cells(struct tube *t, int x0, int y0, int cell, const uint16_t *masks, int count)
{
  if (count <= 0) return T74_OK;
  if ((cell != 3 && cell != 4) || x0 < 0 || x0 > TUBE_W - cell * count || y0 < cell - 1 ||
      y0 >= TUBE_H || (cell == 4 && (x0 & 3))) {
    for (int c = 0; c < count; c++) {      /* one by one */
      int rc = tube_write_dots(t, x0 + c * cell, y0, cell, masks[c]);
      if (rc != T74_OK) return rc;
    }
    return T74_OK;
  }
  uint32_t base = (uint32_t)y0 * TUBE_W + (uint32_t)x0;   /* every cell is on the tube */
  const unsigned full = (1u << (cell * cell)) - 1;
  uint8_t *lit = t->lit;
  /* the cells' rows are unlit when their lowest dot is at or past lit_end (a tube being
     drawn bottom row first); after this call every lit dot is below the top row's end */
  const bool above = base - (uint32_t)(cell - 1) * TUBE_W >= t->lit_end;
  if (base + (uint32_t)(cell * count) > t->lit_end) t->lit_end = base + (uint32_t)(cell * count);
  /* the writes go to `next` (kept out of the tube while lit[] is written through bytes,
     which could alias it) */
  uint32_t *next = t->order + t->done + t->nlog;
  /* cells over unlit dots (above, or blank_cells for 4x4), their masks within the cell:
     every dot is new; their dots go into lit[] and one run write into order[] (settle
     finds the cells' dots in lit[]), none when no cell has a dot */
  const unsigned any = masks_or(masks, count);
  if (!(any & ~full) && cell == 4 && (above || blank_cells(lit, base, 4, count))) {
    /* a byte of lit[] is the row of two cells of this row, or of one and nothing */
    const uint32_t base0 = base;
    for (int c = 0; c < count; c++, base += 4) {
#ifdef __SSE2__
      if ((base & 7) == 0 && c + 16 <= count) { /* sixteen cells: 64 bits of each row */
        write_blank16(lit, base, masks + c);
        c += 15;
        base += 60;
        continue;
      }
      if ((base & 7) == 0 && c + 8 <= count) {  /* eight cells: a word of each row */
        write_blank8(lit, base, masks + c);
        c += 7;
        base += 28;
        continue;
      }
#endif
      unsigned m = masks[c];
      if ((base & 7) == 0 && c + 1 < count) {   /* two cells: a byte of each row */
        unsigned mb = masks[c + 1];
        if (m | mb) rows_put(lit + (base >> 3), spread4(m) | spread4(mb) << 4);
        c++;
        base += 4;
      } else if (m) {
        uint8_t *l = lit + (base >> 3);
        rows_put(l, rows_of(l) | spread4(m) << (base & 7));
      }
    }
    if (any) { *next = run_word(base0, 4, count); t->nlog++; }
    return T74_OK;
  }
  if (!(any & ~full) && cell == 3 && above) {
    /* runs of RUN3 cells, a row of them a lane, the rows stored a word at a time
       (put_rows3); nothing when no cell has a dot */
    if (!any) return T74_OK;
    uint64_t acc[3 * GROUPS3];              /* the runs' lanes, then 0 to a whole group */
    int n = 0;
    for (int c0 = 0; c0 < count; c0 += RUN3, n++) {
      const uint16_t *m = masks + c0;
      acc[n] = 0;
      if (count - c0 >= RUN3) {
        uint64_t w4, w3;                    /* cells 0 .. 3 and 3 .. 6 */
        memcpy(&w4, m, sizeof w4);
        memcpy(&w3, m + 3, sizeof w3);
        if (!(w4 | w3)) continue;           /* seven cells of no dot (a background) */
        if (w4 == w3 && w4 == m[0] * 0x0001000100010001u)
          /* seven cells of one mask: the loop's lanes, each cell's bits three above the
             last's within a lane of 21 (no two meet: a sum is their OR) */
          acc[n] = lanes3[m[0]] * 01111111u;
        else
          acc[n] = lanes3[m[0]] | lanes3[m[1]] << 3 | lanes3[m[2]] << 6 | lanes3[m[3]] << 9 |
                   lanes3[m[4]] << 12 | lanes3[m[5]] << 15 | lanes3[m[6]] << 18;
      } else {
        for (int c = count - 1; c >= c0; c--) acc[n] = acc[n] << 3 | lanes3[masks[c]];
      }
    }
    for (; n % 3; n++) acc[n] = 0;
    put_rows3(lit, base, acc, count);
    *next = run_word(base, 3, count);
    t->nlog++;
    return T74_OK;
  }
  if (cell == 3) {                         /* runs of RUN3 cells, a row of them a lane */
    for (int c0 = 0; c0 < count; c0 += RUN3, base += 3 * RUN3) {
      const int n = count - c0 < RUN3 ? count - c0 : RUN3;
      if (n == RUN3) {                      /* seven cells of no dot (a background) */
        uint64_t w4;
        uint32_t w2;
        uint16_t w1;
        memcpy(&w4, masks + c0, sizeof w4);
        memcpy(&w2, masks + c0 + 4, sizeof w2);
        memcpy(&w1, masks + c0 + 6, sizeof w1);
        if (!(w4 | w2 | w1)) continue;
        uint64_t w3;                        /* cells 3 .. 6 */
        memcpy(&w3, masks + c0 + 3, sizeof w3);
        const unsigned m = masks[c0];
        if (w4 == w3 && w4 == m * 0x0001000100010001u && !(m & ~full)) {
          /* seven cells of one mask within the cell: the loop's lanes, each cell's bits
             three above the last's within a lane of 21 (no two meet: a sum is their OR) */
          if (above) next = write_new3(lit, next, base, lanes3[m] * 01111111u, masks + c0, n);
          else write_run3(lit, &next, base, lanes3[m] * 01111111u, masks + c0, n);
          continue;
        }
      }
      uint64_t acc = 0;
      unsigned run_or = 0;
      for (int c = c0 + n - 1; c >= c0; c--) {
        run_or |= masks[c];
        acc = acc << 3 | lanes3[masks[c] & 0x1ffu];
      }
      if (!(run_or & ~full)) {
        if (acc && above) next = write_new3(lit, next, base, acc, masks + c0, n);
        else if (acc) write_run3(lit, &next, base, acc, masks + c0, n);
        continue;
      }
      for (int c = c0; c < c0 + n; c++) {   /* dots past a cell: one cell at a time */
        const unsigned m = masks[c];
        if (!(m & ~full)) {
          if (m) write_cell3(lit, &next, base + 3 * (uint32_t)(c - c0), m);
          continue;
        }
        t->nlog = (int)(next - (t->order + t->done));
        int rc = tube_write_dots(t, x0 + c * 3, y0, 3, m);
        if (rc != T74_OK) return rc;
        next = t->order + t->done + t->nlog;
      }
    }
    t->nlog = (int)(next - (t->order + t->done));
    return T74_OK;
  }
  for (int c = 0; c < count; c++, base += 4) {       /* 4x4 cells */
    unsigned m = masks[c];
    if (!m) continue;
    if (m & ~full) {                        /* dots past the cell: one by one */
      t->nlog = (int)(next - (t->order + t->done));
      int rc = tube_write_dots(t, x0 + c * cell, y0, cell, m);
      if (rc != T74_OK) return rc;
      next = t->order + t->done + t->nlog;
    } else if ((base & 7) == 0 && c + 1 < count && !(masks[c + 1] & ~full)) {
      write_cell4_pair(lit, &next, base, m, masks[c + 1]);
      c++;
      base += 4;
    } else write_cell4(lit, &next, base, m);
  }
  t->nlog = (int)(next - (t->order + t->done));
  return T74_OK;
}

/* A 4x4 cell's mask with its rows apart: row r (bits 4r .. 4r + 3) to bits 16r .. 16r + 3,
** so that four cells side by side (cell c's shifted up 4c) are four lanes of 16 bits, a lane
** the cells' dots of one row of the tube, the leftmost in the lowest bits, as lit[] has them. */
static inline uint64_t lanes4(unsigned m)
{
  return (uint64_t)(m & 15) | (uint64_t)(m >> 4 & 15) << 16 | (uint64_t)(m >> 8 & 15) << 32 |
         (uint64_t)(m >> 12 & 15) << 48;
}

void tube_keys_init(struct tube_keys *tk, int cell, const uint16_t *mask_of)
{
  const unsigned full = cell >= 1 && cell <= 4 ? (1u << (cell * cell)) - 1 : 0;
  unsigned any = 0;
  for (int k = 0; k < 256; k++) {
    tk->mask[k] = mask_of[k];
    any |= mask_of[k];
  }
  if (cell == 3 && !(any & ~full))          /* (else not asked for) */
    for (int k = 0; k < 256; k++) {
      const uint64_t l = lanes3[mask_of[k]];
      for (int c = 0; c < RUN3; c++) tk->lanes[c][k] = l << 3 * c;
    }
  if (cell == 4 && !(any & ~full))
    for (int k = 0; k < 256; k++) {
      const uint64_t l = lanes4(mask_of[k]);
      for (int c = 0; c < 4; c++) tk->lanes[c][k] = l << 4 * c;
    }
  tk->cell = cell;
  tk->within = (cell == 3 || cell == 4) && !(any & ~full);
}

#ifdef __SSE2__
/* Are the sixteen keys at k all k0's byte (k0: that byte in every lane)? */
static inline bool keys16_are(const uint8_t *k, __m128i k0)
{
  const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)k);
  return _mm_movemask_epi8(_mm_cmpeq_epi8(v, k0)) == 0xffff;
}
#endif

int tube_write_cells_keyed(struct tube *t, int x0, int y0, const struct tube_keys *tk,
                           const uint8_t *keys, int count)
{
  const uint32_t base0 = (uint32_t)y0 * TUBE_W + (uint32_t)x0;
#ifdef __SSE2__
  if (count > 0 && tk->cell == 4 && tk->within && x0 >= 0 && (x0 & 7) == 0 &&
      x0 <= TUBE_W - 4 * count && y0 >= 3 && y0 < TUBE_H && base0 - 3 * TUBE_W >= t->lit_end) {
    /* 4x4 cells on the tube from a byte's start over unlit rows (their lowest dot at or
       past lit_end), every mask within the cell: tube_write_cells' cells over unlit
       dots (the same bits of lit[], the same run write). Sixteen cells: four words of
       four cells' lanes (lanes4: a lane a row, looked up by key, each cell's at its
       place), their 16-bit lanes turned about in two vectors to the four rows' 64 bits
       (four unpacks, where the masks' 16 inserts and their spreading were all shuffles);
       one word for all four when the sixteen keys are one (a background, a flat face) */
    if (base0 + (uint32_t)(4 * count) > t->lit_end) t->lit_end = base0 + (uint32_t)(4 * count);
    uint8_t *lit = t->lit;
    const uint16_t *mask = tk->mask;
    const uint64_t (*L)[256] = tk->lanes;
    uint64_t any = 0;                       /* not 0 when a cell has a dot */
    uint32_t base = base0;
    int c = 0;
    for (; c + 16 <= count; c += 16, base += 64) {
      const uint8_t *k = keys + c;
      const __m128i k16 = _mm_loadu_si128((const __m128i *)(const void *)k);
      uint64_t w0, w1, w2, w3;              /* cells 0 .. 3, 4 .. 7, 8 .. 11, 12 .. 15 */
      if ((unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(k16, _mm_set1_epi8((char)k[0]))) ==
          0xffffu) {
        /* four cells of one mask: each cell's nibbles four above the last's within a
           lane of 16 (no two meet: a sum is their OR) */
        w0 = w1 = w2 = w3 = L[0][k[0]] * 0x1111u;
        if (!w0) continue;                  /* sixteen cells of no dot: 0 already */
      } else {
        w0 = L[0][k[0]] | L[1][k[1]] | L[2][k[2]] | L[3][k[3]];
        w1 = L[0][k[4]] | L[1][k[5]] | L[2][k[6]] | L[3][k[7]];
        w2 = L[0][k[8]] | L[1][k[9]] | L[2][k[10]] | L[3][k[11]];
        w3 = L[0][k[12]] | L[1][k[13]] | L[2][k[14]] | L[3][k[15]];
        if (!(w0 | w1 | w2 | w3)) continue;
      }
      /* a = (w0, w1), b = (w2, w3) as 16-bit lanes (row r of word i: element 4i + r);
         interleaved twice, row r's lanes of w0 .. w3 come side by side: rows 0 and 1 in
         u0, rows 2 and 3 in u1 */
      const __m128i a = _mm_set_epi64x((long long)w1, (long long)w0),
                    b = _mm_set_epi64x((long long)w3, (long long)w2);
      const __m128i t0 = _mm_unpacklo_epi16(a, b), t1 = _mm_unpackhi_epi16(a, b);
      const __m128i u0 = _mm_unpacklo_epi16(t0, t1), u1 = _mm_unpackhi_epi16(t0, t1);
      uint8_t *l = lit + (base >> 3);
      /* the high halves through _mm_storel_epi64 too (a row's bytes are not 8-aligned:
         _mm_storeh_pd's double store may not be unaligned, as write_blank16v says) */
      _mm_storel_epi64((__m128i *)(void *)l, u0);
      _mm_storel_epi64((__m128i *)(void *)(l - ROW_BYTES), _mm_unpackhi_epi64(u0, u0));
      _mm_storel_epi64((__m128i *)(void *)(l - 2 * ROW_BYTES), u1);
      _mm_storel_epi64((__m128i *)(void *)(l - 3 * ROW_BYTES), _mm_unpackhi_epi64(u1, u1));
      any = 1;
    }
    for (; c < count; c += 2, base += 8) {  /* two cells: a byte of each row (of one: its
                                               low half, the high half's dots unlit) */
      const unsigned m = mask[keys[c]], mb = c + 1 < count ? mask[keys[c + 1]] : 0;
      any |= m | mb;
      if (m | mb) rows_put(lit + (base >> 3), spread4(m) | spread4(mb) << 4);
    }
    if (any) t->order[t->done + t->nlog++] = run_word(base0, 4, count);
    return T74_OK;
  }
#endif
  if (count > 0 && tk->cell == 3 && tk->within && x0 >= 0 && x0 <= TUBE_W - 3 * count && y0 >= 2 &&
      y0 < TUBE_H && base0 - 2 * TUBE_W >= t->lit_end) {
    /* 3x3 cells on the tube over unlit rows (their lowest dot at or past lit_end), every
       mask within the cell: tube_write_cells' run of them, each cell's lanes looked up
       by its key at once */
    if (base0 + (uint32_t)(3 * count) > t->lit_end) t->lit_end = base0 + (uint32_t)(3 * count);
    const uint64_t (*L)[256] = tk->lanes;
#ifdef __SSE2__
    if (count >= 16 && !L[0][keys[0]]) {
      /* a row of one key whose cell has no dot (a blank row: the background's grey): every
         lane 0, nothing to store, as the loop below finds run by run. Sixteen keys a
         compare, the last sixteen (which may overlap the ones before) last */
      const __m128i k0 = _mm_set1_epi8((char)keys[0]);
      int c = 0;
      while (c + 16 <= count && keys16_are(keys + c, k0)) c += 16;
      if (c + 16 > count && keys16_are(keys + count - 16, k0)) return T74_OK;
    }
#endif
    uint64_t seen = 0;                     /* the OR of the lanes: not 0 when a cell has a dot */
    uint64_t acc[3 * GROUPS3];             /* the runs' lanes, then 0 to a whole group */
    int n = 0, c0 = 0;
    for (; c0 + RUN3 <= count; c0 += RUN3) {
      const uint8_t *k = keys + c0;
      uint32_t k4, k3;                      /* keys 0 .. 3 and 3 .. 6 */
      memcpy(&k4, k, sizeof k4);
      memcpy(&k3, k + 3, sizeof k3);
      if (k4 == k3 && k4 == k[0] * 0x01010101u)
        /* seven cells of one key (a background, a flat face): the loop's lanes, each
           cell's bits three above the last's within a lane of 21 (no two meet: a sum is
           their OR) */
        acc[n] = L[0][k[0]] * 01111111u;
      else
        acc[n] = L[0][k[0]] | L[1][k[1]] | L[2][k[2]] | L[3][k[3]] | L[4][k[4]] | L[5][k[5]] |
                 L[6][k[6]];
      seen |= acc[n++];
    }
    if (c0 < count) {
      acc[n] = 0;
      for (int c = c0; c < count; c++) acc[n] |= L[c - c0][keys[c]];
      seen |= acc[n++];
    }
    if (!seen) return T74_OK;              /* no dot: nothing to store */
    for (; n % 3; n++) acc[n] = 0;
    /* only the groups (GROUP3 cells, 63 dots a row) from the first with a dot to the last
       with one (seen: there is one) put into lit[]: the dots of the groups before and
       after them are unlit before and after the write, 0 in lit[] already (storing them
       was half of the t1 scenes' groups). put_rows3 then starts at the first such group's
       dot, reading the word that holds it as it reads the row's first (the dots below it
       kept), and stops at the last group's end; the run's word is the whole row's, as
       settle finds its cells' dots in lit[]. */
    int g0 = 0, g1 = n / 3;
    while (!(acc[3 * g0] | acc[3 * g0 + 1] | acc[3 * g0 + 2])) g0++;
    while (!(acc[3 * g1 - 3] | acc[3 * g1 - 2] | acc[3 * g1 - 1])) g1--;
    const int c1 = GROUP3 * g1 < count ? GROUP3 * g1 : count;
    put_rows3(t->lit, base0 + 3 * GROUP3 * (uint32_t)g0, acc + 3 * g0, c1 - GROUP3 * g0);
    t->order[t->done + t->nlog++] = run_word(base0, 3, count);
    return T74_OK;
  }
  uint16_t masks[TUBE_W];                   /* (count <= TUBE_W on the tube; else one by one) */
  if (count > TUBE_W) {
    for (int c = 0; c < count; c++) {
      const int rc = tube_write_cells(t, x0 + c * tk->cell, y0, tk->cell, &tk->mask[keys[c]], 1);
      if (rc != T74_OK) return rc;
    }
    return T74_OK;
  }
  for (int c = 0; c < count; c++) masks[c] = tk->mask[keys[c]];
  return tube_write_cells(t, x0, y0, tk->cell, masks, count);
}

int tube_lit(const struct tube *t, int x, int y)
{
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) return 0;
  uint32_t k = (uint32_t)y * TUBE_W + (uint32_t)x;
  return (t->lit[k >> 3] >> (k & 7)) & 1;
}

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
  return count(t);
}

int tube_order(const struct tube *t, int k, int *x, int *y)
{
  settle(t);                               /* the order spelled out on its first read */
  if (k < 0 || k >= t->done) return T74_EINPUT;
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
