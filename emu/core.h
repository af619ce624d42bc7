/*
** core.h — the HITAC-10's core memory of 16-bit words, and how the renderer's tables
** are laid out in it.
** Where described: paper 003 appendix (core 16 kW/16 bit), §3 and Figs. 6, 8, 9 (the
** tables: XSORT, IPL, PBS, LWS, UPS, the face data blocks, the Priority Matrix);
** docs/hardware.md; CONTRACT.md (--core WORDS, exit status 3,
** core_words / core_words_used in --stats).
**
** This file contains code to make the renderer live inside the 1974 machine's memory.
** Every table the paper names is allocated from a model of the core (default 16,384
** words, --core), so a scene that would not have fitted does not fit here either and
** the run ends with T74_ECORE (exit 3) and a message giving the words needed and the
** words available, never with a crash or a silently wrong picture.
**
** Layout.  Two regions grow towards each other, as a program of the time would have
** laid out its working store:
**
**   address 0                                                          size-1
**   +---------+----------+------+-------+------------+ .. +------------------+
**   | PROGRAM | VERTICES | FACE | YSORT | XSORT  IPL | .. | PRIORITY MATRIX  |
**   |         |          | DATA |       | PBS LWS UPS| .. | (2 bits a pair)  |
**   +---------+----------+------+-------+------------+ .. +------------------+
**   low region: allocated upward, released in stack      high region: ONE table,
**   order (core_mark / core_release), so the scratch     growing downward as pairs
**   tables of one face vanish when the face is done      of faces get a priority
**
** The low region is a stack: a stage marks the top, allocates its scratch tables, and
** releases back to the mark.  The Priority Matrix (003 Fig. 9) is filled in lazily,
** "only when needed" (003 §4), so it grows during the scan; it lives at the top of core,
** word k of it at address size-1-k, so growing it never moves what is already there.
** The two regions meet exactly: with L low words and H high words, L + H <= size.
**
** Statistics: the most words ever in use at once (core_peak, the --stats field
** core_words_used) and, for each table name, the most words that name ever held
** (core_tables), so a report can say which tables took the core.
**
** Addresses are 32-bit so that --core may exceed the HITAC-10's 32 K words for study.
*/
#ifndef T74_CORE_H
#define T74_CORE_H

#include <stdint.h>
#include <stdio.h>

#include "emu/hitac10.h"
#include "emu/status.h"

/* Names of the paper's tables, for core_alloc / core_high_grow (free text is allowed). */
#define CORE_T_PROGRAM   "PROGRAM"          /* the 1974 program itself (program_words) */
#define CORE_T_VERTICES  "VERTICES"         /* input vertices, mapped by eq. (1) */
#define CORE_T_FACES     "FACE DATA"        /* Fig. 8 A/B/C/D blocks */
/* YSORT (003 §2.2): the projected vertices' y coordinates, smallest first; each is a
   horizontal line y = const the face is met with. XSORT (§2.2, Fig. 3): the crossings of
   one such line with the face's sides, smallest x first, each with its code (the side
   crossed in its middle, at an end point, or lying on the line), the side's number and the
   crossing's coordinates; crossings of equal x in the order met going counter-clockwise
   with the face on the left. */
#define CORE_T_YSORT     "YSORT"            /* vertex y values, ascending (003 §2.2) */
#define CORE_T_XSORT     "XSORT"            /* crossings of one line, by x (Fig. 3) */
#define CORE_T_IPL       "IPL"              /* intersection point list (Fig. 6) */
#define CORE_T_PBS       "PBS"              /* boundary sequence with crossings (Fig. 6) */
#define CORE_T_LWS       "LWS"              /* lower sub-faces (Fig. 6) */
#define CORE_T_UPS       "UPS"              /* upper sub-faces (Fig. 6) */
#define CORE_T_PRIORITY  "PRIORITY MATRIX"  /* 2-bit a_ij (Fig. 9), the high region */

#define CORE_NAME_MAX 32                     /* table names are kept to 31 characters */

struct core;                                   /* opaque */

/* A core of `words` words (1 .. 2^31), all zero; NULL when words is out of range or the
   host cannot allocate it. */
struct core *core_new(uint32_t words);
/* core_new for a core mostly reserved and seldom written (the points engine's: the
   Mapper's rows reserved, never written): the same core, its block's pages zero until
   touched (a mapping of its own from 1 MB on, never given huge pages), so only the words
   written cost the host memory. */
struct core *core_new_lazy(uint32_t words);
void core_free(struct core *c);
uint32_t core_words(const struct core *c);     /* size */
/* The core as core_new(core_words(c)) makes it: no tables, no statistics, no growth, no
   injected exhaustion; its host memory kept (issue 19: a core for each frame of --frames
   without touching fresh pages). What the words held is never seen: a table's words are
   zeroed when it is allocated, the high region's when it grows. */
void core_reset(struct core *c);
/* The core as core_new(words) makes it, as core_reset does, its host memory kept (issue
   19: a core that grew in one frame of --frames serves the next, which starts small and
   grows again, without a block freed and another taken). -1 (c unchanged) when words is
   out of range or the host cannot allocate it. */
int core_renew(struct core *c, uint32_t words);

/* A core that grows instead of refusing (for study: an imported model drawn with the core
   it needs, and the words a scene needs found in one run): a table that does not fit
   makes the core twice as large (repeatedly, at most max_words) before it is placed,
   the high region moved to the new top with its words' numbering kept. The tables and
   every decision are those of a core of the final size; core_peak is what a fixed core
   must hold. max_words at or below the size: it never grows (the default). */
void core_set_growth(struct core *c, uint32_t max_words);
uint32_t core_first_words(const struct core *c);   /* the size it was made with */

/* ---- Low region: tables allocated upward from address 0, released in stack order. */

/* Allocate `words` zeroed words for `table`; *addr receives the first address.  When it
   does not fit: T74_ECORE, "scene does not fit the core: needs N words, M available
   (table T could not take K more words)", nothing allocated. */
int core_alloc(struct core *c, const char *table, uint32_t words, uint32_t *addr,
               struct t74_error *err);
/* core_alloc for a table nobody will read or write (the Mapper's rows under the points
   engine): the same reservation, records, statistics and refusals, its words left as
   they are, not zeroed (issue 19). */
int core_reserve(struct core *c, const char *table, uint32_t words, uint32_t *addr,
                 struct t74_error *err);
/* A table name as a caller keeps it for core_alloc_named: the name, and where the core
   found its statistics row (issue 19: the name looked up once, not at each of 300,000
   tables a frame at 100,000 boxes). Zero it and set name; the core fills the rest, and
   looks the name up again after core_reset or when given another core. */
struct core_name {
  const char        *name;
  const struct core *core;   /* the core it was found in, its generation, its row */
  uint64_t           gen;
  int                row;
};
/* core_alloc(c, t->name, words, addr, err): the same table, statistics and refusals. */
int core_alloc_named(struct core *c, struct core_name *t, uint32_t words, uint32_t *addr,
                     struct t74_error *err);
uint32_t core_mark(const struct core *c);      /* current top of the low region */
void core_release(struct core *c, uint32_t mark); /* free everything at or above mark */

/* ---- High region: ONE growable table at the top of core, growing downward.
   core_high_grow makes it at least `words` long, keeping its contents (word k of the
   region is at core address size-1-k; new words are zero); T74_ECORE when it would
   meet the low region. */
int core_high_grow(struct core *c, const char *table, uint32_t words, struct t74_error *err);
uint32_t core_high_words(const struct core *c);
void core_high_free(struct core *c);           /* drop the high region (length 0) */
uint16_t core_high_get(const struct core *c, uint32_t k);
void core_high_set(struct core *c, uint32_t k, uint16_t w);
/* Reading the high region in an inner loop: word k (k < core_high_words) is at p[-k] for
   p = core_high_top(c), until the region next grows or is freed, or a growing core
   (core_set_growth) grows. */
const uint16_t *core_high_top(const struct core *c);
/* The same pointer, to write through: word k is p[-k] (k < core_high_words), under the
   same terms (issue 19: a slot's words stored at once, without a call). */
uint16_t *core_high_top_w(struct core *c);
/* 2-bit fields in the high region: field i is in word i/8, bits 2*(i%8) .. 2*(i%8)+1. */
unsigned core_high_get2(const struct core *c, uint64_t i);
void core_high_set2(struct core *c, uint64_t i, unsigned v);

/* ---- Words. */
uint16_t core_read(const struct core *c, uint32_t addr);
void core_write(struct core *c, uint32_t addr, uint16_t w);
/* core_write of w[0..n) to addr .. addr + n - 1, in one call (issue 19: a table's rows
   written at once, not a call a word). */
void core_write_n(struct core *c, uint32_t addr, const uint16_t *w, uint32_t n);

/* Multi-word integers, two's complement, most significant word first at addr.
   core_put_int stores the low 16*nwords bits of v (nwords 1..4); core_get_int
   sign-extends.  The _wide pair does the same for 128-bit values, nwords 1..8. */
__extension__ typedef __int128 core_wide;            /* 128-bit signed */
__extension__ typedef unsigned __int128 core_uwide;  /* and unsigned */
void core_put_int(struct core *c, uint32_t addr, int nwords, int64_t v);
int64_t core_get_int(const struct core *c, uint32_t addr, int nwords);
void core_put_wide(struct core *c, uint32_t addr, int nwords, core_wide v);
core_wide core_get_wide(const struct core *c, uint32_t addr, int nwords);

/* ---- Statistics. */
uint32_t core_used(const struct core *c);       /* low + high words in use now */
uint32_t core_peak(const struct core *c);       /* the most ever in use at once */
/* Tables by name, in the order first allocated: fills up to max names and their peak
   words (the most words the name ever held at once); returns how many tables there are. */
int core_tables(const struct core *c, const char **names, uint32_t *peak_words, int max);
/* Readable table of the tables now allocated (name, address, words), the free gap, the
   high region, the use and peak, and each table's peak; 0, or T74_EIO. */
int core_layout_dump(const struct core *c, FILE *f);

/* ---- Fault injection for tests (like SQLite's fault.c): the first allocation
   (core_alloc, or the growth in core_high_grow) that would bring the words requested
   from now on past `after` fails with T74_ECORE, and so does every one after it.  Words
   released in between do not count back.  UINT32_MAX disarms. */
void core_inject_exhaustion(struct core *c, uint32_t after);

#endif
