/*
** bench_cost.c — how much the HITAC-10 cost accounting slows the host down.
** Where described: emu/cost.h (COST_ADD_N, the counting rules); used by `make bench`.
**
** This file contains code to measure the overhead of counting.  The renderer counts
** the 1974 machine's instructions as it works (COST_ADD_N, a plain increment), and that
** must stay cheap.  The kernel below is representative of the renderer's inner loops:
** a scan over perspective-plane points, stepping active segments (D-block xb, xe and
** their increments, 003 Fig. 8), testing which cover a point, and settling overlaps
** through the 2-bit Priority Matrix (003 Fig. 9).  It is compiled twice from one source,
** once counting and once not (the `counting` argument is a compile-time constant in each
** copy), timed best-of-N, and the ratio counted/plain is printed.
**
** Build: cc -O2 -std=c11 -D_POSIX_C_SOURCE=200809L -I. tools/bench_cost.c emu/cost.c
**        emu/params.c emu/status.c -lm -o bench_cost
** Usage: bench_cost [REPEATS]   (prints ratio=R on its last line)
*/
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "emu/cost.h"

#if defined(__GNUC__)
#define BENCH_INLINE static inline __attribute__((always_inline))
#define BENCH_NOINLINE static __attribute__((noinline))
#else
#define BENCH_INLINE static inline
#define BENCH_NOINLINE static
#endif

#define NSEG   24                      /* active segments on a scanline */
#define WIDTH  133                     /* points across: 400 / 3 */
#define HEIGHT 100                     /* scanlines: 300 / 3 */

struct seg {
  int32_t  xb, xe;                     /* extent on this line, 8 fraction bits */
  int32_t  dxb, dxe;                   /* increments per line */
  uint16_t face;                       /* face number, 0 .. NSEG-1 */
};

struct bench {
  struct seg seg[NSEG];                /* the active segments */
  uint16_t   prio[(NSEG * NSEG + 7) / 8];  /* 2-bit a_ij, 4 per word (in 16 bits) */
  uint16_t   out[WIDTH];               /* visible face per point */
};

static uint32_t lcg(uint32_t *s) { *s = *s * 1664525u + 1013904223u; return *s >> 8; }

static void bench_init(struct bench *b, uint32_t seed)
{
  for (int i = 0; i < NSEG; i++) {
    int32_t x0 = (int32_t)(lcg(&seed) % (WIDTH * 256));
    int32_t w = (int32_t)(lcg(&seed) % (WIDTH * 64)) + 256;
    b->seg[i] = (struct seg){ x0, x0 + w, (int32_t)(lcg(&seed) % 129) - 64,
                              (int32_t)(lcg(&seed) % 129) - 64, (uint16_t)i };
  }
  for (size_t k = 0; k < sizeof b->prio / sizeof b->prio[0]; k++)
    b->prio[k] = (uint16_t)lcg(&seed);
}

/* One frame; counts into c when `counting` (a constant in each instantiation). */
BENCH_INLINE uint64_t kernel(struct bench *b, struct cost *c, const int counting)
{
  uint64_t sum = 0;
  for (int y = 0; y < HEIGHT; y++) {
    for (int i = 0; i < NSEG; i++) {                   /* step the D-blocks */
      b->seg[i].xb += b->seg[i].dxb;
      b->seg[i].xe += b->seg[i].dxe;
      if (counting) { COST_ADD_N(c, COST_MEM, 4); COST_ADD_N(c, COST_ADD, 2); }
    }
    if (counting) COST_ADD_N(c, COST_BRANCH, NSEG);
    for (int x = 0; x < WIDTH; x++) {
      int32_t px = (x << 8) + 128;
      int best = -1;
      for (int i = 0; i < NSEG; i++) {
        const struct seg *s = &b->seg[i];
        if (counting) { COST_ADD_N(c, COST_MEM, 1); COST_ADD_N(c, COST_ADD, 1);
                        COST_ADD_N(c, COST_BRANCH, 2); }
        if (px < s->xb) continue;
        if (counting) { COST_ADD_N(c, COST_ADD, 1); COST_ADD_N(c, COST_BRANCH, 1); }
        if (px >= s->xe) continue;
        if (best < 0) { best = s->face; continue; }
        unsigned k = (unsigned)best * NSEG + s->face;   /* a_ij of (best, s) */
        unsigned a = (b->prio[k / 8] >> (2 * (k % 8))) & 3u;
        if (counting) {
          cost_mw_mul(c, 16, 16);                       /* the index */
          COST_ADD_N(c, COST_MEM, 1); COST_ADD_N(c, COST_SHIFT, 2);
          COST_ADD_N(c, COST_LOGIC, 1); COST_ADD_N(c, COST_BRANCH, 2);
        }
        if (a == 2) best = s->face;                     /* 10: best is lower */
      }
      b->out[x] = (uint16_t)(best + 1);
      sum += b->out[x];
      if (counting) { COST_ADD_N(c, COST_MEM, 1); COST_ADD_N(c, COST_BRANCH, 1); }
    }
  }
  return sum;
}

BENCH_NOINLINE uint64_t run_plain(struct bench *b) { return kernel(b, NULL, 0); }
BENCH_NOINLINE uint64_t run_counted(struct bench *b, struct cost *c) { return kernel(b, c, 1); }

/* The same, counting into a local struct merged at the end (counters may stay in registers). */
BENCH_NOINLINE uint64_t run_local(struct bench *b, struct cost *c)
{
  struct cost l = { { 0 } };
  uint64_t s = kernel(b, &l, 1);
  cost_merge(c, &l);
  return s;
}

static double now(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
  int reps = argc > 1 ? atoi(argv[1]) : 7;
  const int frames = 40;
  if (reps < 1) reps = 1;
  struct bench b;
  struct cost c = { { 0 } }, cl = { { 0 } };
  double best[3] = { 1e30, 1e30, 1e30 };   /* plain, counted through a pointer, local */
  uint64_t check[3] = { 0, 0, 0 };
  for (int r = 0; r < reps; r++) {
    struct cost one = { { 0 } }, onel = { { 0 } };
    for (int v = 0; v < 3; v++) {
      bench_init(&b, 12345);
      double t0 = now();
      for (int f = 0; f < frames; f++)
        check[v] += v == 0 ? run_plain(&b) : v == 1 ? run_counted(&b, &one) : run_local(&b, &onel);
      double t = now() - t0;
      if (t < best[v]) best[v] = t;
    }
    c = one;
    cl = onel;
  }
  if (check[0] != check[1] || check[0] != check[2] || cost_total(&c) != cost_total(&cl)) {
    fprintf(stderr, "bench_cost: the kernels disagree\n");
    return 1;
  }
  struct cost_params p;
  cost_params_default(&p);
  printf("kernel: %d frames of %d x %d points, %d segments, best of %d\n", frames, WIDTH,
         HEIGHT, NSEG, reps);
  printf("host seconds without counting:           %.6f\n", best[0]);
  printf("host seconds counting through a pointer: %.6f  (ratio %.3f)\n", best[1], best[1] / best[0]);
  printf("host seconds counting into a local:      %.6f  (ratio %.3f)\n", best[2], best[2] / best[0]);
  printf("operations counted: %llu (HITAC-10 estimate %.1f s)\n",
         (unsigned long long)cost_total(&c), cost_seconds(&c, &p));
  printf("ratio=%.3f\n", best[1] / best[0]);
  return 0;
}
