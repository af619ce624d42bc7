/*
** params.c — the one table of HITAC-10 machine constants, and the register and
** instruction tables of emu/hitac10.h.
** Where described: docs/hardware.md; paper 003 appendix (system
** configuration); hi631/FPGA_HITAC10 H10/H10.v and H10/IP/cgen.v.
**
** This file contains code to hold every number the machine model uses, one row each,
** with its source, in the manner of SIMH's REG/MTAB tables: a reader checking a
** hitac10_seconds figure finds here what each instruction class was charged and why.
** Numbers that a document gives are quoted as docs/hardware.md (or the paper) gives
** them; numbers that no document gives are marked "inferred" with the reasoning, and
** every row can be changed by the user (cost_params_set, "name=value").
**
** Timing evidence.  No primary figure was found (the primary source, Hitachi Review,
** Nov. 1969, was not available).  The FPGA reconstruction clocks its CPU at
** 50 MHz x 42857 / 500000 = 4.2857 MHz (cgen.v, clk1), one state = 233.3 ns, an odd
** ratio evidently chosen so that 6 states make 1.4 us.  Its sequencer (H10.v, mseq)
** runs EVERY instruction that is not trapped through states 0-2 (fetch) and 3-5
** (execute), whether it touches core or not; a shift repeats state 4 once per position
** beyond the first; an indirect address repeats the fetch states (3 more).  The brief
** for this file expected register, logic and skip instructions to be cheaper than a
** memory reference; the reconstruction says otherwise, and it is the only evidence,
** so those rows are 6 states too.  On a real core machine such instructions might end
** with the fetch cycle (PDP-8: operate 1.5 us, memory reference 3.0 us): set
** logic_states=3 and branch_states=3 to assume that.
*/
#include "emu/cost.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------------------
** The parameter table.  Rows are in the order of enum cost_param (checked by the
** designated initialisers); the groups are: core, instruction timing, multiply/divide,
** then the peripherals of paper 003 that later stages (background picture, disk) use.
*/
#define HF "docs/hardware.md: "
#define P003 "paper 003 appendix: "

const struct param_row cost_param_rows[CP_NPARAM] = {
  [CP_CORE_WORDS] = { "core_words", "words", 16384, 1, 2147483648.0, 1,
    P003 "'コア・メモリ 16 kW/16 BIT'; " HF "'The HITAC-10's core came in units of 4,096 "
    "words; the machine of paper 003 had 16,384 words of 16 bits. Its program counter has "
    "15 bits, so 32,768 words is the most it can address.' "
    "(larger values model a bigger machine than ever existed, for study)" },
  [CP_PROGRAM_WORDS] = { "program_words", "words", 4096, 0, 2147483648.0, 1,
    "inferred: paper 003 does not give the size of its program. Estimate, one 16-bit "
    "instruction or constant a word, by routine (docs/machine.md): typewriter input of "
    "vertices, faces and objects 400, Mapper (eq. 1, 2) 300, YSORT/XSORT 250, Segment "
    "Generator (types, rules (3), IPL/PBS/LWS/UPS) 1000, interpenetration test and cut "
    "(eq. 5) 450, Priority Matrix and depth 300, Visible Surface Procedure and D-blocks "
    "600, halftone and display 200, background picture from the disk 250, double-word "
    "arithmetic routines 146, device drivers 200 = 4096 words, one 4 K core unit. "
    "0 charges the tables only" },
  [CP_STATE_NS] = { "state_ns", "ns", 233.33, 1, 1e6, 0,
    HF "'No primary timing figure was found' ... 'The FPGA reconstruction runs a "
    "memory-reference instruction in 6 states of about 233 ns: 1.4 us.' (inferred; "
    "hi631/FPGA_HITAC10 H10/IP/cgen.v: CPU clock "
    "50 MHz x 42857/500000 = 4.2857 MHz)" },
  [CP_MEM_STATES] = { "mem_states", "states", 6, 0, 1000, 0,
    HF "'The FPGA reconstruction runs a memory-reference instruction in 6 states of "
    "about 233 ns: 1.4 us.' (H10.v: fetch states 0-2, execute 3-5). COST_MEM: L or ST of "
    "a table word" },
  [CP_ADD_STATES] = { "add_states", "states", 6, 0, 1000, 0,
    "inferred: A and S are memory-reference instructions in H10.v (opcodes 02, 03), so "
    "6 states like L and ST" },
  [CP_LOGIC_STATES] = { "logic_states", "states", 6, 0, 1000, 0,
    "inferred: N, X, O are memory-reference (H10.v opcodes 04-06); register operations "
    "(LCAR, SCAR) also run all 6 states in H10.v. A core machine might end them after "
    "the fetch (3 states): set 3 to assume that" },
  [CP_BRANCH_STATES] = { "branch_states", "states", 6, 0, 1000, 0,
    "inferred: B, BAL, KCT and the skips (opcodes 08-0A, 0D) run states 0-5 in H10.v; "
    "a skip adds nothing, it only steps PC by 2" },
  [CP_SHIFT_STATES] = { "shift_states", "states", 6, 0, 1000, 0,
    "inferred: H10.v runs a shift by one position through states 0-5" },
  [CP_SHIFT_STEP_STATES] = { "shift_step_states", "states", 1, 0, 1000, 0,
    "inferred: H10.v repeats state 4 once for each position beyond the first (count in "
    "address bits 3..0)" },
  [CP_SHIFT_N] = { "shift_n", "positions", 4, 1, 16, 0,
    "inferred: typical shift count. The renderer's packed data are 4-bit picture "
    "samples (docs/hardware.md: 'Pictures are stored four samples to a 16-bit word.') and "
    "2-bit priority fields "
    "(003 Fig. 9): shifts of 2..12; 4 taken as typical" },
  [CP_IND_STATES] = { "ind_states", "states", 3, 0, 1000, 0,
    HF "'An indirect address costs 3 more states.' (H10.v repeats fetch states 0-2). "
    "COST_IND" },
  [CP_IO_STATES] = { "io_states", "states", 6, 0, 1000, 0,
    "inferred: IOC (opcode 0E) runs states 0-5 in H10.v; waiting for the device is not "
    "included" },
  [CP_MULDIV] = { "muldiv", "hw|sw", 0, 0, 1, 1,
    "assumption: " HF "'Multiply and divide came as an option: a unit that adds an "
    "extension register (AC and EC together 32 bits). Without it, those instructions trap "
    "to software routines, slower but invisible to the program.' Paper 003 does not say "
    "which its machine had; hw "
    "is assumed (plane equations and perspective division are its main arithmetic). "
    "sw: the trap to a software routine" },
  [CP_MUL_HW_STATES] = { "mul_hw_states", "states", 22, 0, 100000, 0,
    "inferred, no figure found: 6 states of a memory reference + 16 add-and-shift steps "
    "of one state each (H10.v shifts one position a state) = 22 states, 5.1 us" },
  [CP_DIV_HW_STATES] = { "div_hw_states", "states", 38, 0, 100000, 0,
    "inferred, no figure found: 6 states + 16 subtract-and-shift steps of 2 states "
    "(trial subtract, then shift in the quotient bit) = 38 states, 8.9 us" },
  [CP_TRAP_STATES] = { "trap_states", "states", 6, 0, 100000, 0,
    "inferred: H10.v fetches the trapped instruction (states 0-2) then runs the 3-state "
    "interrupt cycle (states 6-8) that saves PC in word 0 and enters the handler" },
  [CP_MUL_SW_INSTR] = { "mul_sw_instr", "instructions", 138, 0, 1e6, 0,
    "inferred: software multiply routine: 10 instructions to save AC, fetch the operand "
    "through the saved PC and return, + 16 steps x 8 (test the low bit, skip, add, two "
    "shifts of the AC:EC pair, carry, KCT count, branch); each charged mem_states" },
  [CP_DIV_SW_INSTR] = { "div_sw_instr", "instructions", 172, 0, 1e6, 0,
    "inferred: software divide routine: 12 instructions of entry, exit and sign "
    "handling + 16 steps x 10 (shift the pair, trial subtract, skip, restore on borrow, "
    "set the quotient bit, KCT count, branch); each charged mem_states" },
  [CP_DISK_TRACK_MS] = { "disk_track_ms", "ms", 30, 0, 1e6, 0,
    HF "'The disk of paper 003 holds 10 Mbit; moving one track takes 30 ms, a seek 60 ms "
    "on average and the rotational delay is 20 ms on average.' (" P003 "IOMEC, "
    "'トラック間 30 ms')" },
  [CP_DISK_SEEK_MS] = { "disk_seek_ms", "ms", 60, 0, 1e6, 0,
    HF "'a seek 60 ms on average' (" P003 "'平均ランダム移動 60 ms')" },
  [CP_DISK_ROT_MS] = { "disk_rot_ms", "ms", 20, 0, 1e6, 0,
    HF "'the rotational delay is 20 ms on average' (" P003 "'平均回転遅延 20 ms')" },
  [CP_DISK_MBIT] = { "disk_mbit", "Mbit", 10, 0, 1e6, 0,
    HF "'The disk of paper 003 holds 10 Mbit' (" P003 "'容量 10 Mbit'). 'Pictures are "
    "stored four samples to a 16-bit word.'" },
  [CP_DRUM_REV_S] = { "drum_rev_s", "s", 0.75, 0, 1e6, 0,
    HF "'The drum scanner turns at 82.758 rpm, given as 0.75 s a turn'. The two figures the "
    "paper prints ('82.758 rpm (0.75 sec/rev)') disagree: 60 / 82.758 = 0.725 s a turn. "
    "The 0.75 s is kept (the paper's own per-turn figure); set drum_rev_s=0.725 for the "
    "rpm" },
  [CP_DRUM_PTS_MM] = { "drum_pts_mm", "points/mm", 5.87, 0, 1e6, 0,
    HF "'5.87 points per mm around the drum'" },
  [CP_DRUM_LINES_MM] = { "drum_lines_mm", "lines/mm", 7.4, 0, 1e6, 0,
    HF "'7.4 lines per mm along its axis'" },
  [CP_ADC_US] = { "adc_us", "us", 50, 0, 1e6, 0,
    HF "'an 8-bit A-D converter taking 50 us a conversion over 0 to +10 V'" },
  [CP_ADC_BITS] = { "adc_bits", "bits", 8, 1, 32, 1,
    HF "'an 8-bit A-D converter' (" P003 "'純 2 進 8 BIT')" },
};

/* Rows counted in states whose time may also be given as "CLASS_us=V". */
static int row_in_states(int i)
{
  return strcmp(cost_param_rows[i].unit, "states") == 0;
}

static int find_row(const char *name, size_t len)
{
  return param_find(cost_param_rows, CP_NPARAM, name, len);
}

void cost_params_default(struct cost_params *p)
{
  param_defaults(cost_param_rows, CP_NPARAM, p->v);
}

int cost_params_get(const struct cost_params *p, const char *name, double *value)
{
  int i = find_row(name, strlen(name));
  if (i < 0) return T74_EINPUT;
  *value = p->v[i];
  return T74_OK;
}

static int set_fail(struct t74_error *err, const char *fmt, const char *a, const char *b)
{
  if (err) t74_fail(err, T74_EINPUT, fmt, a, b);
  return T74_EINPUT;
}

int cost_params_set(struct cost_params *p, const char *s, struct t74_error *err)
{
  const char *eq = strchr(s, '=');
  if (!eq || eq == s) return set_fail(err, "machine parameter '%s%s': expected NAME=VALUE", s, "");
  size_t len = (size_t)(eq - s);
  const char *val = eq + 1;
  int i = find_row(s, len);
  double scale = 1;                        /* value -> row unit */
  if (i < 0 && len > 3 && strncmp(s + len - 3, "_us", 3) == 0) {
    /* "mem_us=1.6": the time of a class counted in states */
    char buf[64];
    if (len - 3 + sizeof "_states" <= sizeof buf) {
      memcpy(buf, s, len - 3);
      memcpy(buf + len - 3, "_states", sizeof "_states");
      i = find_row(buf, strlen(buf));
      if (i >= 0 && !row_in_states(i)) i = -1;
      if (i >= 0) scale = 1000.0 / p->v[CP_STATE_NS];
    }
  }
  if (i < 0) {
    char name[64];
    snprintf(name, sizeof name, "%.*s", (int)(len < 63 ? len : 63), s);
    return set_fail(err, "unknown machine parameter '%s'%s (see the parameter list)", name, "");
  }
  const struct param_row *r = &cost_param_rows[i];
  double v;
  if (i == CP_MULDIV) {
    if (strcmp(val, "hw") == 0) v = 0;
    else if (strcmp(val, "sw") == 0) v = 1;
    else return set_fail(err, "machine parameter muldiv: '%s' is not hw or sw%s", val, "");
  } else {
    /* read unchecked, then scale ("_us" to states) and check the row's range */
    struct param_row any = { r->name, r->unit, 0, -HUGE_VAL, HUGE_VAL, 0, r->source };
    if (param_parse(&any, val, &v) != PARAM_OK)
      return set_fail(err, "machine parameter %s: '%s' is not a number", r->name, val);
    v *= scale;
    if (v < r->min || v > r->max || (r->integer && v != floor(v))) {
      char range[96];
      snprintf(range, sizeof range, "%s (%g .. %g %s%s)", val, r->min, r->max, r->unit,
               r->integer ? ", whole" : "");
      return set_fail(err, "machine parameter %s: out of range: %s", r->name, range);
    }
  }
  p->v[i] = v;
  return T74_OK;
}

int cost_params_list(const struct cost_params *p, FILE *f)
{
  fprintf(f, "%-18s %12s  %-12s %s\n", "name", "value", "unit", "source");
  for (int i = 0; i < CP_NPARAM; i++) {
    const struct param_row *r = &cost_param_rows[i];
    if (i == CP_MULDIV)
      fprintf(f, "%-18s %12s  %-12s %s\n", r->name, p->v[i] != 0 ? "sw" : "hw", r->unit, r->source);
    else
      fprintf(f, "%-18s %12.6g  %-12s %s\n", r->name, p->v[i], r->unit, r->source);
  }
  fprintf(f, "time per counted operation (us):");
  for (int k = 0; k < COST_NCLASS; k++) fprintf(f, " %s %.4g", cost_class_name(k), cost_class_us(p, k));
  fprintf(f, "\n");
  return ferror(f) ? T74_EIO : T74_OK;
}

/* ---------------------------------------------------------------------------------
** Registers (H10.v names without the H_ prefix).
*/
const struct h10_reg h10_regs[] = {
  { "AC",  16, "accumulator: the one arithmetic register" },
  { "C",    1, "carry: set by A, S and the left shifts; tested by KNC/KC skips" },
  { "EC",  16, "extension register of the optional multiply/divide unit: AC:EC is the "
               "32-bit product and dividend" },
  { "PC",  15, "program counter: 32 K words at most" },
  { "MA",  15, "memory address register" },
  { "MB",  16, "memory buffer: the word read from or written to core" },
  { "IR",   7, "instruction register: opcode, I and M bits" },
  { "IM",   1, "interrupt mask: set by SIM, cleared by RIM and on interrupt" },
  { "ERR",  4, "error flags: power, memory, address, option (a trapped instruction)" },
  { "DSW", 16, "front-panel data switches (LDSW)" },
};
const int h10_nregs = (int)(sizeof h10_regs / sizeof h10_regs[0]);

/* ---------------------------------------------------------------------------------
** Instructions and the cost class each is counted as (emu/hitac10.h explains).
*/
const struct h10_op h10_ops[] = {
  { H10_TRP, "TRP",  1, COST_BRANCH, "no operation (H10.v)" },
  { H10_L,   "L",    1, COST_MEM,    "AC = (EA)" },
  { H10_A,   "A",    1, COST_ADD,    "C,AC = AC + (EA)" },
  { H10_S,   "S",    1, COST_ADD,    "C,AC = AC - (EA); with a skip, the compare" },
  { H10_N,   "N",    1, COST_LOGIC,  "AC = AC & (EA)" },
  { H10_X,   "X",    1, COST_LOGIC,  "AC = AC ^ (EA)" },
  { H10_O,   "O",    1, COST_LOGIC,  "AC = AC | (EA)" },
  { H10_ST,  "ST",   1, COST_MEM,    "(EA) = AC" },
  { H10_B,   "B",    1, COST_BRANCH, "PC = EA" },
  { H10_BAL, "BAL",  1, COST_BRANCH, "(EA) = return address, PC = EA: subroutine call" },
  { H10_KCT, "KCT",  1, COST_BRANCH, "(EA) += 1, skip if zero: loop counter" },
  { H10_K,   "K..",  0, COST_BRANCH, "skips on AC minus/zero and carry; LCAR, SCAR "
                                     "(COST_LOGIC), LDSW, SIM, RIM, HOLT" },
  { H10_IOC, "IOC",  0, COST_IO,     "device select, skip on ready, byte transfer" },
  { H10_SRL, "SRL",  0, COST_SHIFT,  "AC >>= n, logical" },
  { H10_SLL, "SLL",  0, COST_SHIFT,  "C,AC <<= n, logical" },
  { H10_SRA, "SRA",  0, COST_SHIFT,  "AC >>= n, arithmetic" },
  { H10_SLA, "SLA",  0, COST_SHIFT,  "AC <<= n, arithmetic, C = overflow" },
  { H10_EXT, "MUL",  1, COST_MUL,    "AC:EC = AC x (EA), optional unit or trapped "
                                     "(opcode among 14-1F, not documented which)" },
  { H10_EXT, "DIV",  1, COST_DIV,    "AC = AC:EC / (EA), EC = remainder, optional unit "
                                     "or trapped (opcode among 14-1F)" },
};
const int h10_nops = (int)(sizeof h10_ops / sizeof h10_ops[0]);

int h10_list(FILE *f)
{
  fprintf(f, "HITAC-10 registers\n");
  for (int i = 0; i < h10_nregs; i++)
    fprintf(f, "  %-4s %2d bits  %s\n", h10_regs[i].name, h10_regs[i].width, h10_regs[i].desc);
  fprintf(f, "HITAC-10 instructions (opcode, mnemonic, format, counted as)\n");
  for (int i = 0; i < h10_nops; i++) {
    char code[8];
    if (h10_ops[i].code == H10_EXT) snprintf(code, sizeof code, "1x");  /* 14..1F, unknown */
    else snprintf(code, sizeof code, "%02X", h10_ops[i].code);
    fprintf(f, "  %-2s %-4s %-6s %-6s %s\n", code, h10_ops[i].mnem,
            h10_ops[i].mref ? "memref" : "other", cost_class_name(h10_ops[i].cls), h10_ops[i].desc);
  }
  return ferror(f) ? T74_EIO : T74_OK;
}
