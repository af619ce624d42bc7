/*
** hitac10.h — the HITAC-10 (Hitachi, 1969) described as tables: word, instruction
** format, registers, instruction set and how the cost model's classes map onto it.
** Where described: paper 003, appendix "システム構成" (CPU HITAC-10, core 16 kW/16 bit);
** docs/hardware.md; the FPGA reconstruction hi631/FPGA_HITAC10
** (H10/H10.v for the instruction set and its state sequence, H10/IP/cgen.v for the clock).
**
** This file contains code to describe the machine that ran the 1974 renderer, in the
** manner of SIMH's pdp8_defs.h: the instruction word drawn as a bit diagram with _V_
** (bit position) and _M_ (mask) names, the register set as a table of rows (name,
** width, description), and the instruction set as a table whose rows say which cost
** class (emu/cost.h) an instruction is counted under.  tube74 does not execute HITAC-10
** code: the renderer is C, and it COUNTS the operations the 1974 program would have done
** (emu/cost.h), keeps its tables in a model of the core (emu/core.h), and the cost model
** turns the counts into 1974 seconds with the parameter table (emu/params.c).  This
** header is the reference those two modules are checked against.
**
** Change history
**   tube74 first version: instruction format and state timing read from
**   hi631/FPGA_HITAC10 H10.v (the only timing evidence found; the primary source, Hitachi
**   Review Nov. 1969, was not available); core sizes from paper 003 and docs/hardware.md.
*/
#ifndef T74_HITAC10_H
#define T74_HITAC10_H

#include <limits.h>
#include <stdint.h>
#include <stdio.h>

/* ---------------------------------------------------------------------------------
** The word.  Everything in core is a 16-bit word; multi-word integers are stored most
** significant word first (emu/core.h, core_put_int).
*/
#define H10_WORD_BITS    16            /* bits in a word of core and in AC */
#define H10_WORD_MASK    0xFFFFu       /* all bits of a word */
typedef uint16_t h10_word;             /* one word of core */

_Static_assert(sizeof(h10_word) * CHAR_BIT == H10_WORD_BITS,
               "the HITAC-10 word is 16 bits");

/* ---------------------------------------------------------------------------------
** Core memory (paper 003 appendix; docs/hardware.md).
*/
#define H10_CORE_UNIT     4096u        /* core is bought in 4 K-word units */
#define H10_CORE_PAPER    16384u       /* the paper's machine: 16 kW x 16 bit */
#define H10_PC_BITS       15           /* 15-bit program counter ... */
#define H10_CORE_MAX      32768u       /* ... so 32 K words at most */
#define H10_PAGE_BITS     9            /* address field of an instruction */
#define H10_PAGE_WORDS    512u         /* words in a page */

/* ---------------------------------------------------------------------------------
** Instruction format (H10.v: H_IR <= MBR[15:9], H_AD <= MBR[8:0]).
**
**    15  14  13  12  11  10   9   8   7   6   5   4   3   2   1   0
**  +---+---+---+---+---+---+---+---+---+---+---+---+---+---+---+---+
**  |      opcode       | I | M |          address in page          |
**  +---+---+---+---+---+---+---+---+---+---+---+---+---+---+---+---+
**
**  I = 1: indirect.  The word at the effective address holds a 15-bit address
**         (bits 14..0) of the operand.  One level only (H10.v clears req_ind after
**         one extra fetch); costs 3 more states.
**  M = 0: page 0, effective address = 0 .. 511 (constants and pointers live there).
**  M = 1: the current page, effective address = PC<14:9> : address.
**  Non-memory instructions (skips, shifts, I/O) use bits 8..0 as sub-operation bits;
**  shifts take their count, 1..16, from bits 3..0 (0 meaning 16).
*/
#define H10_V_OP      11               /* opcode position */
#define H10_M_OP      0x1Fu            /* opcode mask (5 bits) */
#define H10_V_IND     10               /* indirect bit position */
#define H10_V_PAGE    9                /* page bit position: 1 current page, 0 page 0 */
#define H10_M_ADDR    0x1FFu           /* 9-bit address in page */
#define H10_M_SHCNT   0xFu             /* shift count field (bits 3..0) */

#define H10_OPCODE(w) (((unsigned)(w) >> H10_V_OP) & H10_M_OP)      /* opcode of a word */
#define H10_IND(w)    (((unsigned)(w) >> H10_V_IND) & 1u)           /* its I bit */
#define H10_PAGE(w)   (((unsigned)(w) >> H10_V_PAGE) & 1u)          /* its M bit */
#define H10_ADDR(w)   ((unsigned)(w) & H10_M_ADDR)                  /* its address field */
#define H10_INSTR(op, i, m, a)                                      /* assemble one */ \
  ((h10_word)((((unsigned)(op) & H10_M_OP) << H10_V_OP) | (((unsigned)(i) & 1u) << H10_V_IND) | \
              (((unsigned)(m) & 1u) << H10_V_PAGE) | ((unsigned)(a) & H10_M_ADDR)))

/* Effective address of a direct memory-reference instruction at pc. */
#define H10_EA(w, pc) (H10_PAGE(w) ? (((unsigned)(pc) & 0x7E00u) | H10_ADDR(w)) : H10_ADDR(w))

/* Opcodes, as decoded by H10.v (H_IR[6:2] = word bits 15..11). */
enum h10_opcode {
  H10_TRP = 0x00,   /* no operation in H10.v (memory-reference format) */
  H10_L   = 0x01,   /* load:       AC = (EA) */
  H10_A   = 0x02,   /* add:        C,AC = AC + (EA) */
  H10_S   = 0x03,   /* subtract:   C,AC = AC - (EA); also the compare */
  H10_N   = 0x04,   /* AND:        AC = AC & (EA) */
  H10_X   = 0x05,   /* XOR:        AC = AC ^ (EA) */
  H10_O   = 0x06,   /* OR:         AC = AC | (EA) */
  H10_ST  = 0x07,   /* store:      (EA) = AC */
  H10_B   = 0x08,   /* branch:     PC = EA */
  H10_BAL = 0x09,   /* branch and link: (EA) = PC+1, PC = EA (+1 in use) */
  H10_KCT = 0x0A,   /* count:      (EA) += 1, skip if it became 0 */
  H10_TRB = 0x0B,   /* traps (H10.v: "Trap(58)") */
  H10_EX  = 0x0C,   /* execute; trapped in H10.v */
  H10_K   = 0x0D,   /* skips on AC sign/zero and carry (KNC, KZA, KMA ...), LCAR, SCAR,
                       LDSW, SIM/RIM, HOLT: non-memory, sub-operation in bits 8..0 */
  H10_IOC = 0x0E,   /* I/O control: select device, skip on ready, transfer a byte */
  H10_TRF = 0x0F,   /* traps */
  H10_SRL = 0x10,   /* shift right logical by 1..16 */
  H10_SLL = 0x11,   /* shift left logical, carry = bit shifted out */
  H10_SRA = 0x12,   /* shift right arithmetic */
  H10_SLA = 0x13,   /* shift left arithmetic, carry = overflow */
  H10_EXT = 0x14    /* 0x14..0x1F: the optional unit's instructions (multiply, divide,
                       EC transfers).  H10.v traps them; its README loads "extension
                       mechanism software" from tape to emulate them.  Which code is
                       multiply and which divide is not documented there. */
};

/* ---------------------------------------------------------------------------------
** Registers (SIMH's REG table: name, width, description).  tube74 keeps no register
** state (it does not execute HITAC-10 code); the table documents the machine, and
** h10_list prints it with the instruction table below.
*/
struct h10_reg {
  const char *name;                    /* as in H10.v without the H_ prefix */
  int         width;                   /* bits */
  const char *desc;                    /* what it holds */
};
extern const struct h10_reg h10_regs[];  /* defined in emu/params.c */
extern const int h10_nregs;

/* ---------------------------------------------------------------------------------
** Instruction table with the cost class each is counted under.
**
** How the counted classes of emu/cost.h map onto instructions.  A count is one
** instruction of the class, so a renderer step is counted as the instructions the 1974
** program would spend on it.  The HITAC-10 has ONE accumulator and no register-to-
** register arithmetic: add, subtract and the logic operations take their second operand
** from core, and their time includes that fetch.
**   COST_MEM    L or ST of a word of one of the renderer's tables (memory reference).
**   COST_ADD    A or S: add, subtract, or compare (S then a skip) with an operand in
**               core.  Do not count a COST_MEM for that operand as well.
**   COST_LOGIC  N, X, O with an operand in core, or a register operation (LCAR, SCAR,
**               complement via X with a page-0 mask, EC transfer).
**   COST_SHIFT  one shift instruction (SRL, SLL, SRA, SLA) by any count 1..16; the
**               parameter shift_n says which count is typical.
**   COST_BRANCH B, BAL, KCT (loop counter), and the skips on AC/carry.
**   COST_MUL    one 16 x 16 -> 32-bit multiply (AC:EC); operand fetch included.
**   COST_DIV    one 32 / 16-bit divide; operand fetch included.
**   COST_IO     one IOC instruction (a byte to or from a device; device waits are not
**               included: the disk and drum rows of the parameter table give those).
**   COST_IND    one level of indirection (an ",I" address: a pointer chain such as
**               the D-block chain of 003 Fig. 8) on top of the instruction it modifies.
**
** Word sizes of the 1974 program (docs/machine.md, "Which quantity is held in what"): a
** coordinate, a plane or edge coefficient, a number in one word; a product, a sum of
** products, a scanline crossing and its increment in a double word (AC:EC, 32 bits,
** truncating fixed point). emu/cost.h prices the counted arithmetic at those widths
** (hitac10_seconds) and, apart, at the exact widths tube74 uses (exact_hitac10_seconds).
*/
struct h10_op {
  unsigned    code;                    /* enum h10_opcode */
  const char *mnem;                    /* mnemonic (H10.v comments) */
  int         mref;                    /* 1: memory-reference format (I, M, address) */
  int         cls;                     /* enum cost_class (emu/cost.h) it is counted as */
  const char *desc;                    /* what it does */
};
extern const struct h10_op h10_ops[];    /* defined in emu/params.c */
extern const int h10_nops;

/* Print the register and instruction tables; 0, or T74_EIO when the stream fails. */
int h10_list(FILE *f);

#endif
