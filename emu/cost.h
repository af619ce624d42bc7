/*
** cost.h — the cost model: operations counted by class, turned into 1974 seconds.
** Where described: emu/hitac10.h (the instruction classes), shared/notes/
** docs/hardware.md (timings), emu/params.c (the one table of machine constants).
** Paper 003 gives no run times of its own, so hitac10_seconds is an estimate.
**
** This file contains code to account for the time the renderer would have taken on the
** HITAC-10.  The renderer does its work in C but, at each step, adds to a `struct cost`
** the instructions the 1974 program would have executed, by class (a load is COST_MEM,
** an add COST_ADD, ...; emu/hitac10.h says which instruction is which class).  Counting
** is a plain increment through the COST_ADD_N macro, cheap enough for inner loops
** (tools/bench_cost.c measures it).  Arithmetic wider than the 16-bit word (plane
** equations, priority tests on products of coordinates) is counted by cost_mw_*, which
** name the exact widths tube74 uses and charge the multi-word sequence a single-
** accumulator machine needs twice over: at the 1974 program's widths (one word, double
** word: n[], hitac10_seconds) and, apart, what the exact widths add (x[],
** exact_hitac10_seconds); see "Two sets of counters" below and docs/machine.md.  At the
** end cost_seconds multiplies each class's count by its time from the parameter table.
**
** The parameter table (struct cost_params) has one row per constant, each with its
** name, value, unit and source ("inferred" with the reasoning where no document gives
** the number).  cost_params_set changes a row from a "name=value" string, as --param
** options or tests do; cost_params_list prints the table.
*/
#ifndef T74_COST_H
#define T74_COST_H

#include <stdint.h>
#include <stdio.h>

#include "emu/hitac10.h"
#include "emu/param.h"
#include "emu/status.h"

/* Classes of counted operations; emu/hitac10.h maps each onto HITAC-10 instructions. */
enum cost_class {
  COST_MEM,      /* L or ST of a table word: one memory-reference instruction */
  COST_ADD,      /* A or S (add, subtract, compare) with its operand in core */
  COST_LOGIC,    /* N, X, O with an operand in core, or a register operation */
  COST_SHIFT,    /* one shift instruction (count 1..16; typical count: shift_n) */
  COST_BRANCH,   /* B, BAL, KCT, skips */
  COST_MUL,      /* 16 x 16 -> 32 multiply (hardware unit or software routine) */
  COST_DIV,      /* 32 / 16 divide (hardware unit or software routine) */
  COST_IO,       /* one IOC instruction */
  COST_IND,      /* one indirection (",I") added to another instruction */
  COST_NCLASS
};

/*
** Two sets of counters.  n[] is the 1974 program as paper 003 describes it: its arithmetic
** is the HITAC-10 programmer's (docs/machine.md, "Which quantity is held in what"): one
** 16-bit word for a coordinate or a coefficient, a double word (32 bits, truncating fixed
** point) for a product or a sum of products, a 16 x 16 -> 32 multiply and a 32 / 16 divide.
** x[] (n[COST_NCLASS + k], read through COST_X; one array so that "= { { 0 } }" still
** clears both) is what tube74's exact arithmetic needs ON TOP of that, on the same machine: the
** renderer's counting calls name the exact widths of their operands (cost_mw_*), and
** each call charges the capped widths to n[] and the difference to x[].  So
**   hitac10_seconds        = seconds of n[]          (the 1974 program)
**   exact_hitac10_seconds  = seconds of n[] + x[]    (the same run in exact arithmetic)
** Plain COST_ADD_N counts (loads, stores, compares of one word, branches) are the same in
** both and go to n[] only.
*/
struct cost { uint64_t n[2 * COST_NCLASS]; };
#define COST_X(c, cls) ((c)->n[COST_NCLASS + (cls)])   /* x[cls] */

/* Count k operations of class cls: a plain add, for hot paths. */
/* T74_NO_COST builds the renderer without counting (make bench uses it to measure what
   counting costs the host); the 1974 figures are then zero. */
#ifdef T74_NO_COST
#define COST_ADD_N(c, cls, k) ((void)(c), (void)(k))
#define COST_OFF_(c) do { (void)(c); return; } while (0)
#else
#define COST_ADD_N(c, cls, k) ((c)->n[(cls)] += (uint64_t)(k))
#define COST_OFF_(c) do { } while (0)
#endif

/* Words a `bits`-bit operand takes on a 16-bit machine (at least one). */
static inline uint64_t cost_words(int bits)
{
  return bits <= H10_WORD_BITS ? 1u : (uint64_t)(bits + H10_WORD_BITS - 1) / H10_WORD_BITS;
}

/* The widths of the 1974 program (docs/machine.md): an add or compare is on at most a
   double word; a multiply takes one word by one word (a double-word operand is first cut
   to its high word, fixed point); a divide is a double word by one word. */
#define COST_1974_ADD_WORDS 2u
#define COST_1974_MUL_WORDS 1u
#define COST_1974_DIVN_WORDS 2u
#define COST_1974_DIVD_WORDS 1u

static inline uint64_t cost_cap_(uint64_t w, uint64_t cap) { return w < cap ? w : cap; }

/* The counting calls below are always inlined: nearly every call site names its widths as
   constants, so the words, the caps, the branches and the two counter sets fold at compile
   time into a few adds of constants to memory (with x[]'s plus and minus merged into one
   add per class).  Left to itself the compiler kept cost_mw_mul out of line, some 40 host
   instructions a call (tools/bench.sh, "Cost of counting"). */
#if defined(__GNUC__) || defined(__clang__)
#define COST_INLINE_ static inline __attribute__((always_inline))
#else
#define COST_INLINE_ static inline
#endif

/*
** Multi-word add, subtract or compare of two w-word operands in core, result to core.
** Word by word from the least significant: L a_i, A b_i, ST c_i (2 MEM + 1 ADD per
** word); each of the w-1 upper words also takes the carry of the word below: a skip on
** carry and an add of the constant 1 (1 BRANCH + 1 ADD).
**   w = 1: MEM 2, ADD 1.   w = 2: MEM 4, ADD 3, BRANCH 1.   w = 8: MEM 16, ADD 15, BRANCH 7.
*/
COST_INLINE_ void cost_mw_add_w_(uint64_t *n, uint64_t w, uint64_t sg)
{
  n[COST_MEM]    += sg * (2 * w);
  n[COST_ADD]    += sg * (w + (w - 1));
  n[COST_BRANCH] += sg * (w - 1);
}

/*
** Multi-word multiply, schoolbook on 16-bit digits (the hardware, or the software
** routine, multiplies one word by one word into AC:EC).
** One word by one word: L a, M b, ST low, EC->AC, ST high: MEM 3, MUL 1, LOGIC 1.
** Otherwise, for an wa-word by wb-word product of wa+wb words:
**   clear the product:                      MEM wa+wb
**   each of the wa*wb partial products:     L a_i, M b_j, A r_k, ST r_k, EC->AC, skip on
**                                           carry, A one, A r_k+1, ST r_k+1:
**                                           MEM 3, MUL 1, ADD 3, LOGIC 1, BRANCH 1
**   each of the wa rows ripples its carry:  L, skip, A one, ST: MEM 2, ADD 1, BRANCH 1
**   signs (two's complement operands):      2 skips + a multi-word negate of the product,
**                                           charged as a multi-word add of its width
*/
COST_INLINE_ void cost_mw_mul_w_(uint64_t *n, uint64_t wa, uint64_t wb, uint64_t sg)
{
  uint64_t pp = wa * wb;
  if (pp == 1) {
    n[COST_MEM] += sg * 3; n[COST_MUL] += sg; n[COST_LOGIC] += sg;
    return;
  }
  n[COST_MEM]    += sg * ((wa + wb) + 3 * pp + 2 * wa);
  n[COST_MUL]    += sg * pp;
  n[COST_ADD]    += sg * (3 * pp + wa);
  n[COST_LOGIC]  += sg * pp;
  n[COST_BRANCH] += sg * (pp + wa + 2);
  cost_mw_add_w_(n, wa + wb, sg);
}

/*
** Multi-word divide, n-bit dividend by d-bit divisor (long division on 16-bit digits).
** A one-word divisor: one 32/16 divide per dividend word, the remainder staying in the
** high half: L n_i, D d, ST q_i, EC->AC: MEM 2, DIV 1, LOGIC 1 per word.
** A wider divisor (Knuth's algorithm D, wn >= wd words, q = wn - wd + 1 quotient words):
**   normalise divisor and dividend:         SHIFT 2(wn + wd), MEM 2(wn + wd)
**   each quotient word: estimate (1 DIV, 2 MEM, 1 ADD test), multiply and subtract
**   (wd MUL, 3 wd MEM, 2 wd ADD, wd LOGIC, wd BRANCH), add back test (1 BRANCH), store
**   (1 MEM)
**   signs:                                  2 skips + a negate of the quotient (mw_add)
** (A double word by one word, the 1974 program's divide, is one DIV per dividend word
** here: two; the paper's machine divided AC:EC by a word in one instruction, so this is
** one DIV more than it needed at worst.)
*/
COST_INLINE_ void cost_mw_div_w_(uint64_t *n, uint64_t wn, uint64_t wd, uint64_t sg)
{
  if (wd == 1) {
    n[COST_MEM] += sg * (2 * wn); n[COST_DIV] += sg * wn; n[COST_LOGIC] += sg * wn;
    return;
  }
  if (wn < wd) wn = wd;                         /* quotient 0: one trial still runs */
  uint64_t q = wn - wd + 1;
  n[COST_SHIFT]  += sg * (2 * (wn + wd));
  n[COST_MEM]    += sg * (2 * (wn + wd) + q * (2 + 3 * wd + 1));
  n[COST_DIV]    += sg * q;
  n[COST_MUL]    += sg * (q * wd);
  n[COST_ADD]    += sg * (q * (1 + 2 * wd));
  n[COST_LOGIC]  += sg * (q * wd);
  n[COST_BRANCH] += sg * (q * (wd + 1) + 2);
  cost_mw_add_w_(n, q, sg);
}

/* Each operation is charged at the 1974 widths to n[], and x[] gets the exact one minus
   that (as unsigned sums modulo 2^64: a class may take fewer operations at the exact
   widths, e.g. one DIV of a long division against two of the 1974 divide, so one x[k]
   may run below zero; n[k] + x[k] is always the exact count, which is all that is read:
   cost_seconds_exact). When the exact widths are the 1974 ones, x[] is not touched. */
#define COST_PLUS_  ((uint64_t)1)
#define COST_MINUS_ (~(uint64_t)0)

/* k adds, subtracts or compares of `bits`-bit operands (the exact width), charged at once
   (every count is a sum of the same increments, x[]'s modulo 2^64 too: a loop may count
   its operations and charge them once, issue 19); cost_mw_add is one of them. */
COST_INLINE_ void cost_mw_add_n(struct cost *c, int bits, uint64_t k)
{
  (void)bits; (void)k;
  COST_OFF_(c);
  uint64_t w = cost_words(bits), w74 = cost_cap_(w, COST_1974_ADD_WORDS);
  cost_mw_add_w_(c->n, w74, k * COST_PLUS_);
  if (w == w74) return;
  cost_mw_add_w_(&COST_X(c, 0), w, k * COST_PLUS_);
  cost_mw_add_w_(&COST_X(c, 0), w74, k * COST_MINUS_);
}

COST_INLINE_ void cost_mw_add(struct cost *c, int bits) { cost_mw_add_n(c, bits, 1); }

/* k products of a bits_a-bit by a bits_b-bit operand (the exact widths); cost_mw_mul one. */
COST_INLINE_ void cost_mw_mul_n(struct cost *c, int bits_a, int bits_b, uint64_t k)
{
  (void)bits_a; (void)bits_b; (void)k;
  COST_OFF_(c);
  uint64_t wa = cost_words(bits_a), wb = cost_words(bits_b);
  uint64_t a74 = cost_cap_(wa, COST_1974_MUL_WORDS), b74 = cost_cap_(wb, COST_1974_MUL_WORDS);
  cost_mw_mul_w_(c->n, a74, b74, k * COST_PLUS_);
  if (wa == a74 && wb == b74) return;
  cost_mw_mul_w_(&COST_X(c, 0), wa, wb, k * COST_PLUS_);
  cost_mw_mul_w_(&COST_X(c, 0), a74, b74, k * COST_MINUS_);
}

COST_INLINE_ void cost_mw_mul(struct cost *c, int bits_a, int bits_b)
{
  cost_mw_mul_n(c, bits_a, bits_b, 1);
}

/* k quotients of a bits_n-bit dividend by a bits_d-bit divisor (the exact widths);
   cost_mw_div one. */
COST_INLINE_ void cost_mw_div_n(struct cost *c, int bits_n, int bits_d, uint64_t k)
{
  (void)bits_n; (void)bits_d; (void)k;
  COST_OFF_(c);
  uint64_t wn = cost_words(bits_n), wd = cost_words(bits_d);
  uint64_t n74 = cost_cap_(wn, COST_1974_DIVN_WORDS), d74 = cost_cap_(wd, COST_1974_DIVD_WORDS);
  cost_mw_div_w_(c->n, n74, d74, k * COST_PLUS_);
  if (wn == n74 && wd == d74) return;
  cost_mw_div_w_(&COST_X(c, 0), wn, wd, k * COST_PLUS_);
  cost_mw_div_w_(&COST_X(c, 0), n74, d74, k * COST_MINUS_);
}

COST_INLINE_ void cost_mw_div(struct cost *c, int bits_n, int bits_d)
{
  cost_mw_div_n(c, bits_n, bits_d, 1);
}

/* Add every counter of `from` into `into`. */
void cost_merge(struct cost *into, const struct cost *from);

/* Total of all counters (instructions, counting an indirection as one). */
uint64_t cost_total(const struct cost *c);

/* Name of a class ("mem", "add", ...), or "?" for a value out of range. */
const char *cost_class_name(int cls);

/* ---------------------------------------------------------------------------------
** The parameter table.  One row per constant; emu/params.c holds each row's name, unit,
** default, limits and source.  `muldiv` is a choice row: 0 = hw, 1 = sw.
*/
enum cost_param {
  CP_CORE_WORDS,        /* core size, words */
  CP_PROGRAM_WORDS,     /* words of core the 1974 program itself is taken to occupy */
  CP_STATE_NS,          /* one machine state */
  CP_MEM_STATES,        /* memory-reference instruction (L, ST): COST_MEM */
  CP_ADD_STATES,        /* A, S: COST_ADD */
  CP_LOGIC_STATES,      /* N, X, O, register operations: COST_LOGIC */
  CP_BRANCH_STATES,     /* B, BAL, KCT, skips: COST_BRANCH */
  CP_SHIFT_STATES,      /* shift by one position: COST_SHIFT base */
  CP_SHIFT_STEP_STATES, /* each further position of a shift */
  CP_SHIFT_N,           /* typical shift count */
  CP_IND_STATES,        /* one indirection: COST_IND */
  CP_IO_STATES,         /* IOC: COST_IO */
  CP_MULDIV,            /* 0 hw: optional multiply/divide unit fitted; 1 sw: trapped */
  CP_MUL_HW_STATES,     /* multiply with the unit */
  CP_DIV_HW_STATES,     /* divide with the unit */
  CP_TRAP_STATES,       /* entering the software routine of a trapped instruction */
  CP_MUL_SW_INSTR,      /* instructions of the software multiply routine */
  CP_DIV_SW_INSTR,      /* instructions of the software divide routine */
  CP_DISK_TRACK_MS,     /* disk: track-to-track move */
  CP_DISK_SEEK_MS,      /* disk: mean random seek */
  CP_DISK_ROT_MS,       /* disk: mean rotational delay */
  CP_DISK_MBIT,         /* disk: capacity */
  CP_DRUM_REV_S,        /* drum scanner: one turn */
  CP_DRUM_PTS_MM,       /* drum scanner: points per mm around the drum */
  CP_DRUM_LINES_MM,     /* drum scanner: lines per mm along the axis */
  CP_ADC_US,            /* A-D converter: one conversion */
  CP_ADC_BITS,          /* A-D converter: resolution */
  CP_NPARAM
};

struct cost_params { double v[CP_NPARAM]; };   /* indexed by enum cost_param */

/* One row of the table (emu/params.c). */
extern const struct param_row cost_param_rows[CP_NPARAM];   /* emu/param.h */

void cost_params_default(struct cost_params *p);

/*
** Set one row from "name=value" ("mem_states=7", "state_ns=250", "muldiv=sw").  For each
** row counted in states, "CLASS_us=V" is accepted too and sets the states to V us at the
** current state time (e.g. "mem_us=1.6").  Unknown name or bad value: T74_EINPUT, the
** row unchanged.
*/
int cost_params_set(struct cost_params *p, const char *name_eq_value, struct t74_error *err);

/* Value of the row called `name`; T74_EINPUT when there is none. */
int cost_params_get(const struct cost_params *p, const char *name, double *value);

/* Print the table: name, value, unit, source; 0, or T74_EIO when the stream fails. */
int cost_params_list(const struct cost_params *p, FILE *f);

/* Time of one operation of class cls, in microseconds, with the table's values. */
double cost_class_us(const struct cost_params *p, int cls);

/* Estimated 1974 run time of the counted operations (the 1974 program's arithmetic, n[]),
   in seconds. */
double cost_seconds(const struct cost *c, const struct cost_params *p);

/* The same in two steps, for a clock read often (cli/pipeline.c, at every lit point): the
   states one operation of each class takes, once; then the seconds of the class counts
   n[] with them: exactly cost_seconds's value for a struct cost holding those counts. */
void cost_class_states(const struct cost_params *p, double states[COST_NCLASS]);
double cost_seconds_of(const uint64_t n[COST_NCLASS], const double states[COST_NCLASS],
                       const struct cost_params *p);

/* The same run with exact arithmetic on the same machine (n[] + x[]), in seconds. */
double cost_seconds_exact(const struct cost *c, const struct cost_params *p);

/* Print counts and seconds per class; 0, or T74_EIO when the stream fails. */
int cost_report(const struct cost *c, const struct cost_params *p, FILE *f);

#endif
