/*
** core.c — the core memory model: 16-bit words, a low stack of tables and one
** high table growing down, with "does not fit" as an explicit result.
** Where described: emu/core.h (layout and API); paper 003 appendix (16 kW/16 bit) and
** Fig. 9 (the Priority Matrix, 2 bits a pair of faces).
**
** This file contains code to hand out the emulated core to the renderer's tables and
** to account for it.  The words themselves are an array of uint16_t; beside them the
** host keeps a record of each live low-region table (for the layout dump and for
** core_release) and a row per table name with the words it holds now and the most it
** ever held.  That bookkeeping lives in host memory, not in the emulated core: the 1974
** program knew its tables by fixed addresses and needed no directory.
**
** Invariants: low_top + high_len <= size; peak >= low_top + high_len at all times;
** the live records are in address order and tile [0, low_top) exactly.
*/
#define _DEFAULT_SOURCE        /* madvise, MAP_ANONYMOUS: the host block below */
#include "emu/core.h"

#include <assert.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define STAT_HINTS 8

struct core_stat {
  char     name[CORE_NAME_MAX];   /* table name (truncated copy) */
  uint64_t cur;                   /* words held now under this name */
  uint32_t peak;                  /* the most held at once */
};

struct core_rec {                 /* its first word: the words of those below it (they
                                     tile the low region: issue 19, 12 bytes a table was
                                     6 MB at 100,000 boxes) */
  uint32_t words;                 /* length */
  int      stat;                  /* index into stats */
};

struct core {
  uint32_t          size;         /* words of core */
  uint32_t          cap;          /* words the host block w has room for, >= size (a core
                                     renewed smaller keeps its block: core_renew) */
  uint16_t         *w;            /* the words */
  uint32_t          low_top;      /* first free word above the low region */
  uint32_t          high_len;     /* words of the high region (at the top) */
  int               high_stat;    /* its stats row, -1 before first use */
  uint32_t          peak;         /* most words in use at once */
  struct core_rec  *rec;          /* live low-region tables, in address order */
  int               nrec, caprec;
  struct core_stat *stat;         /* one row per table name, first-use order */
  int               nstat, capstat;
  /* where a table name was last found, by the name's address (a hint only: the row is
     still compared; issue 12: 300,000 scans of the rows at 100,000 boxes) */
  const char       *hint_name[STAT_HINTS];
  int               hint_row[STAT_HINTS];
  int               hint_next;    /* the hint replaced next (round robin) */
  uint64_t          gen;          /* rows as now since (core_reset: a new generation;
                                     struct core_name) */
  uint32_t          grow_max;     /* core_set_growth: the core grows up to this many
                                     words instead of refusing (0: it never grows) */
  uint32_t          first_size;   /* the size it was made with */
  int               inject_on;    /* fault injection armed */
  int               inject_tripped; /* the budget has been exceeded: all requests fail */
  uint64_t          inject_left;  /* words that may still be requested */
  size_t            map_bytes;    /* w is a mapping of its own this long (block_new), or 0:
                                     from malloc */
  bool              huge;         /* that mapping has been given huge pages (block_huge) */
  bool              lazy;         /* core_new_lazy's: never given huge pages */
};

/* ---- the host block ----------------------------------------------------------------------
   A core as large as the bench's (--core 268435456: 512 MB of address space, of which a
   scene touches a few MB at its two ends) is a mapping of its own, starting at a 2 MB
   boundary; its pages are zero until written, as calloc's are. Each 4 kB page touched
   first costs a fault, about 12 us on the machine measured (30,000 box faces touch 3 MB
   of core: some 750 faults, a tenth of their whole process; 1,280 triangles 1.4 MB). So
   once either region holds CORE_HUGE_WORDS words (a scene that will touch more), the
   mapping is given transparent huge pages (MADV_HUGEPAGE: where Linux gives them for
   the asking) and the 2 MB stretches in use are collapsed into huge pages
   (MADV_COLLAPSE, their words kept), so what follows faults in 2 MB at a time. A small
   scene (the street: 15,000 words) stays on 4 kB pages, which cost it less than
   zeroing a 2 MB page at each end. Only advice: where the kernel ignores it (or
   without Linux, or for a smaller core, from malloc) nothing changes but host time. */
#define CORE_MAP_BYTES ((size_t)64 << 20)   /* a block this large is a mapping of its own */
#define CORE_HUGE_BYTES ((size_t)2 << 20)   /* x86-64's transparent huge page */
#define CORE_HUGE_WORDS (UINT32_C(1) << 16) /* a region this large: huge pages from then on */
#if defined(__linux__) && !defined(MADV_COLLAPSE)
#define MADV_COLLAPSE 25                    /* Linux 6.1: <asm-generic/mman-common.h> */
#endif

/* A zeroed block of `words` words: *bytes the length of its own mapping, or 0 when it
   came from calloc. NULL when the host has no room. */
static uint16_t *block_new(size_t words, size_t *bytes)
{
  *bytes = 0;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (words * sizeof(uint16_t) >= CORE_MAP_BYTES) {
    size_t len = (words * sizeof(uint16_t) + CORE_HUGE_BYTES - 1) & ~(CORE_HUGE_BYTES - 1);
    char *m = mmap(NULL, len + CORE_HUGE_BYTES, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m != MAP_FAILED) {                 /* the 2 MB-aligned part kept, the rest unmapped */
      char *a = (char *)(((uintptr_t)m + CORE_HUGE_BYTES - 1) & ~(uintptr_t)(CORE_HUGE_BYTES - 1));
      if (a > m) munmap(m, (size_t)(a - m));
      if (a + len < m + len + CORE_HUGE_BYTES) munmap(a + len, (size_t)(m + CORE_HUGE_BYTES - a));
      *bytes = len;
      return (uint16_t *)(void *)a;
    }
  }
#endif
  return calloc(words, sizeof(uint16_t));
}

/* core_new_lazy's block: from LAZY_MAP_BYTES on, a mapping of its own on 4 kB pages,
   zero until touched and never touched but where written (the points engine reserves
   some 18 MB at 100,000 boxes and writes a few words; calloc took it from the heap, where
   main.c keeps blocks below 32 MB, and cleared every byte); smaller, as block_new. */
#define LAZY_MAP_BYTES ((size_t)1 << 20)
static uint16_t *block_lazy(size_t words, size_t *bytes)
{
  *bytes = 0;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  size_t len = (words * sizeof(uint16_t) + 4095) & ~(size_t)4095;
  if (len >= LAZY_MAP_BYTES) {
    void *m = mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m != MAP_FAILED) {
      *bytes = len;
      return m;
    }
  }
#endif
  return block_new(words, bytes);
}

static void block_free(uint16_t *w, size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes) { munmap(w, bytes); return; }
#endif
  (void)bytes;
  free(w);
}

/* The block made room for `words` words (> c->cap). Returns 0 when it was realloc'd (its
   first c->cap words kept, the rest unspecified), 1 when it is a new block whose words
   are zero but the regions' (the low region's and the high region's, at the same
   addresses), -1 when the host has no room (c unchanged). */
static int block_grow(struct core *c, size_t words)
{
  if (!c->map_bytes && words * sizeof(uint16_t) < CORE_MAP_BYTES) {
    uint16_t *w = realloc(c->w, words * sizeof *w);
    if (!w) return -1;
    c->w = w;
    c->cap = (uint32_t)words;
    return 0;
  }
  size_t bytes;
  uint16_t *w = block_new(words, &bytes);
  if (!w) return -1;
  uint32_t hi = c->size - c->high_len;
  memcpy(w, c->w, (size_t)c->low_top * sizeof *w);
  memcpy(w + hi, c->w + hi, (size_t)c->high_len * sizeof *w);
  block_free(c->w, c->map_bytes);
  c->w = w;
  c->cap = (uint32_t)words;
  c->map_bytes = bytes;
  c->huge = false;
  return 1;
}

/* The regions are about to hold `low` and `high` words: at CORE_HUGE_WORDS, the mapping
   given huge pages (see above), before the new words are touched. */
static void block_huge(struct core *c, uint32_t low, uint32_t high)
{
  if (c->huge || c->lazy || !c->map_bytes ||
      (low < CORE_HUGE_WORDS && high < CORE_HUGE_WORDS)) return;
  c->huge = true;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  char *a = (char *)c->w;
  madvise(a, c->map_bytes, MADV_HUGEPAGE);  /* advice: errors ignored */
  uintptr_t top = (uintptr_t)(c->w + c->size) - 1;           /* the high region's last byte */
  char *hi = (char *)(top & ~(uintptr_t)(CORE_HUGE_BYTES - 1));
  if (c->low_top) madvise(a, CORE_HUGE_BYTES, MADV_COLLAPSE);
  if (c->high_len) madvise(hi, CORE_HUGE_BYTES, MADV_COLLAPSE);
#endif
}

static struct core *core_make(uint32_t words, bool lazy)
{
  if (words < 1 || words > (UINT32_C(1) << 31)) return NULL;
  struct core *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->lazy = lazy;
  c->w = lazy ? block_lazy(words, &c->map_bytes) : block_new(words, &c->map_bytes);
  if (!c->w) { free(c); return NULL; }
  c->size = words;
  c->cap = words;
  c->first_size = words;
  c->high_stat = -1;
  return c;
}

struct core *core_new(uint32_t words)
{
  return core_make(words, false);
}

struct core *core_new_lazy(uint32_t words)
{
  return core_make(words, true);
}

int core_renew(struct core *c, uint32_t words)
{
  if (words < 1 || words > (UINT32_C(1) << 31)) return -1;
  if (words > c->cap && block_grow(c, words) < 0) return -1;
  c->size = words;
  core_reset(c);
  return 0;
}

void core_reset(struct core *c)
{
  c->low_top = 0;
  c->high_len = 0;
  c->high_stat = -1;
  c->peak = 0;
  c->nrec = 0;
  c->nstat = 0;
  c->gen++;                                 /* every struct core_name looks again */
  memset(c->hint_name, 0, sizeof c->hint_name);
  memset(c->hint_row, 0, sizeof c->hint_row);
  c->hint_next = 0;
  c->grow_max = 0;
  c->first_size = c->size;
  c->inject_on = 0;
  c->inject_tripped = 0;
  c->inject_left = 0;
}

void core_set_growth(struct core *c, uint32_t max_words)
{
  c->grow_max = max_words > c->size ? max_words : 0;
}

uint32_t core_first_words(const struct core *c) { return c->first_size; }

/* A growing core (core_set_growth) made room for `need` words in all: the size doubled
** until it holds them (at most grow_max), the new words zero, the high region moved to
** the new top (word k of it stays word k: only core_high_top's pointer changes, which is
** valid until the region next grows anyway). Returns 0, or -1 when it may not or the host
** cannot. */
static int grow_core(struct core *c, uint64_t need)
{
  if (!c->grow_max || need > c->grow_max) return -1;
  uint64_t size = c->size;
  while (size < need) size *= 2;
  if (size > c->grow_max) size = c->grow_max;
  int fresh = 0;                           /* else the block has room (core_renew) */
  if (size > c->cap && (fresh = block_grow(c, (size_t)size)) < 0) return -1;
  uint16_t *w = c->w;
  uint32_t old = c->size, ns = (uint32_t)size;
  memmove(w + (ns - c->high_len), w + (old - c->high_len), (size_t)c->high_len * sizeof *w);
  if (fresh) {        /* zero but where the high region was and is no longer (a size
                         capped at grow_max may leave the two overlapping) */
    const uint32_t from = old - c->high_len, to = old < ns - c->high_len ? old : ns - c->high_len;
    if (to > from) memset(w + from, 0, (size_t)(to - from) * sizeof *w);
  } else
    memset(w + c->low_top, 0, (size_t)(ns - c->high_len - c->low_top) * sizeof *w);
  c->w = w;
  c->size = ns;
  return 0;
}

void core_free(struct core *c)
{
  if (!c) return;
  block_free(c->w, c->map_bytes);
  free(c->rec);
  free(c->stat);
  free(c);
}

uint32_t core_words(const struct core *c) { return c->size; }
uint32_t core_mark(const struct core *c) { return c->low_top; }
uint32_t core_used(const struct core *c) { return c->low_top + c->high_len; }
uint32_t core_peak(const struct core *c) { return c->peak; }
uint32_t core_high_words(const struct core *c) { return c->high_len; }

/* The name `key` as kept (its first CORE_NAME_MAX - 1 bytes) is the row's name `row`. */
static bool same_name(const char *row, const char *key)
{
  for (size_t k = 0; k < CORE_NAME_MAX - 1; k++) {
    if (row[k] != key[k]) return false;
    if (!key[k]) return true;
  }
  return row[CORE_NAME_MAX - 1] == '\0';
}

/* Row of the stats for `name`, created if new; -1 when the host is out of memory. */
static int stat_row(struct core *c, const char *name)
{
  /* the name as kept: at most CORE_NAME_MAX - 1 bytes of it (compared in place: this runs
     for every table of every face and piece, 500,000 times a frame at 100,000 boxes) */
  const char *key = name ? name : "(unnamed)";
  int h = 0;
  while (h < STAT_HINTS && c->hint_name[h] != key) h++;
  if (h < STAT_HINTS) {                    /* rows have distinct names: a match is the row */
    int i = c->hint_row[h];
    if (same_name(c->stat[i].name, key)) return i;
    /* else a stale hint (the caller's buffer was rewritten): it is reused below */
  } else {                                 /* no hint for this address: the next in turn */
    h = c->hint_next;
    c->hint_next = (h + 1) % STAT_HINTS;
  }
  for (int i = 0; i < c->nstat; i++)
    if (same_name(c->stat[i].name, key)) {
      c->hint_name[h] = key;
      c->hint_row[h] = i;
      return i;
    }
  if (c->nstat == c->capstat) {
    int cap = c->capstat ? 2 * c->capstat : 16;
    struct core_stat *s = realloc(c->stat, (size_t)cap * sizeof *s);
    if (!s) return -1;
    c->stat = s;
    c->capstat = cap;
  }
  struct core_stat *s = &c->stat[c->nstat];
  size_t len = strnlen(key, CORE_NAME_MAX - 1);
  memcpy(s->name, key, len);
  s->name[len] = '\0';
  s->cur = 0;
  s->peak = 0;
  c->hint_name[h] = key;
  c->hint_row[h] = c->nstat;
  return c->nstat++;
}

static void stat_add(struct core *c, int i, uint32_t words)
{
  struct core_stat *s = &c->stat[i];
  s->cur += words;
  if (s->cur > s->peak) s->peak = s->cur > UINT32_MAX ? UINT32_MAX : (uint32_t)s->cur;
}

static void note_peak(struct core *c)
{
  uint32_t used = c->low_top + c->high_len;
  if (used > c->peak) c->peak = used;
}

/*
** May `words` more words be given to `table`?  They fit when the two regions do not
** cross and the injected budget (if armed) is not exceeded.  On refusal, the message of
** CONTRACT.md exit status 3: words needed, words available, and which table asked.
*/
static int grant(struct core *c, const char *table, uint32_t words, const char *verb,
                 struct t74_error *err)
{
  uint64_t used = (uint64_t)c->low_top + c->high_len;
  uint64_t need = used + words;
  uint64_t avail = c->size;
  const char *why = "";
  if (need > avail && grow_core(c, need) == 0) avail = c->size;   /* a growing core */
  if (need <= avail) {
    if (!c->inject_on) return T74_OK;
    if (!c->inject_tripped && words <= c->inject_left) {
      c->inject_left -= words;
      return T74_OK;
    }
    avail = used + (c->inject_tripped ? 0 : c->inject_left);    /* as if core ended there */
    c->inject_tripped = 1;
    why = "; injected exhaustion";
  }
  if (err)
    t74_fail(err, T74_ECORE,
             "scene does not fit the core: needs %" PRIu64 " words, %" PRIu64 " available "
             "(table %s could not %s %" PRIu32 " words%s)",
             need, avail, table ? table : "(unnamed)", verb, words, why);
  return T74_ECORE;
}

static int take(struct core *c, const char *table, struct core_name *t, uint32_t words,
                uint32_t *addr, struct t74_error *err, bool zero)
{
  int rc = grant(c, table, words, "take", err);
  if (rc != T74_OK) return rc;
  int s;
  if (t && t->core == c && t->gen == c->gen) {
    s = t->row;                                       /* found before, rows as then */
  } else {
    s = stat_row(c, table);
    if (t && s >= 0) { t->core = c; t->gen = c->gen; t->row = s; }
  }
  if (s >= 0 && c->nrec == c->caprec) {
    int cap = c->caprec ? 2 * c->caprec : 32;
    struct core_rec *r = realloc(c->rec, (size_t)cap * sizeof *r);
    if (r) { c->rec = r; c->caprec = cap; } else s = -1;
  }
  if (s < 0) {
    if (c->inject_on) c->inject_left += words;        /* nothing was given */
    if (err) t74_fail(err, T74_EIO, "host out of memory recording core table %s",
                      table ? table : "(unnamed)");
    return T74_EIO;
  }
  uint32_t a = c->low_top;
  block_huge(c, a + words, c->high_len);
  if (zero) memset(c->w + a, 0, (size_t)words * sizeof *c->w);
  c->rec[c->nrec++] = (struct core_rec){ words, s };
  c->low_top = a + words;
  stat_add(c, s, words);
  note_peak(c);
  if (addr) *addr = a;
  return T74_OK;
}

int core_alloc(struct core *c, const char *table, uint32_t words, uint32_t *addr,
               struct t74_error *err)
{
  return take(c, table, NULL, words, addr, err, true);
}

int core_alloc_named(struct core *c, struct core_name *t, uint32_t words, uint32_t *addr,
                     struct t74_error *err)
{
  return take(c, t->name, t, words, addr, err, true);
}

int core_reserve(struct core *c, const char *table, uint32_t words, uint32_t *addr,
                 struct t74_error *err)
{
  return take(c, table, NULL, words, addr, err, false);
}

void core_release(struct core *c, uint32_t mark)
{
  if (mark >= c->low_top) return;
  uint32_t top = c->low_top;                           /* the end of the last record */
  while (c->nrec > 0) {
    struct core_rec *r = &c->rec[c->nrec - 1];
    uint32_t addr = top - r->words;
    if (addr >= mark) {                                /* wholly above: drop it */
      c->stat[r->stat].cur -= r->words;
      c->nrec--;
      top = addr;
    } else {                                           /* straddles the mark: shorten */
      uint32_t keep = mark - addr;
      if (keep < r->words) {
        c->stat[r->stat].cur -= r->words - keep;
        r->words = keep;
      }
      break;
    }
  }
  c->low_top = mark;
}

int core_high_grow(struct core *c, const char *table, uint32_t words, struct t74_error *err)
{
  if (words <= c->high_len) return T74_OK;
  uint32_t more = words - c->high_len;
  int rc = grant(c, table, more, "grow by", err);
  if (rc != T74_OK) return rc;
  if (c->high_stat < 0 || c->high_len == 0) {
    int s = stat_row(c, table);
    if (s < 0) {
      if (c->inject_on) c->inject_left += more;
      if (err) t74_fail(err, T74_EIO, "host out of memory recording core table %s",
                        table ? table : "(unnamed)");
      return T74_EIO;
    }
    c->high_stat = s;
  }
  block_huge(c, c->low_top, words);
  /* new words: addresses size-words .. size-high_len-1, zeroed (they may hold what a
     released low table left there) */
  memset(c->w + (c->size - words), 0, (size_t)more * sizeof *c->w);
  c->high_len = words;
  stat_add(c, c->high_stat, more);
  note_peak(c);
  return T74_OK;
}

void core_high_free(struct core *c)
{
  if (c->high_stat >= 0) c->stat[c->high_stat].cur -= c->high_len;
  c->high_len = 0;
}

uint16_t core_high_get(const struct core *c, uint32_t k)
{
  assert(k < c->high_len);
  return c->w[c->size - 1 - k];
}

const uint16_t *core_high_top(const struct core *c)
{
  return c->w + (c->size - 1);
}

uint16_t *core_high_top_w(struct core *c)
{
  return c->w + (c->size - 1);
}

void core_high_set(struct core *c, uint32_t k, uint16_t w)
{
  assert(k < c->high_len);
  c->w[c->size - 1 - k] = w;
}

unsigned core_high_get2(const struct core *c, uint64_t i)
{
  assert(i / 8 < c->high_len);
  uint16_t w = c->w[c->size - 1 - (uint32_t)(i / 8)];
  return (unsigned)(w >> (2 * (i % 8))) & 3u;
}

void core_high_set2(struct core *c, uint64_t i, unsigned v)
{
  assert(i / 8 < c->high_len);
  assert(v <= 3);
  uint16_t *w = &c->w[c->size - 1 - (uint32_t)(i / 8)];
  unsigned sh = (unsigned)(2 * (i % 8));
  *w = (uint16_t)((*w & ~(3u << sh)) | ((v & 3u) << sh));
}

uint16_t core_read(const struct core *c, uint32_t addr)
{
  assert(addr < c->size);
  return c->w[addr];
}

void core_write(struct core *c, uint32_t addr, uint16_t w)
{
  assert(addr < c->size);
  c->w[addr] = w;
}

void core_write_n(struct core *c, uint32_t addr, const uint16_t *w, uint32_t n)
{
  assert((uint64_t)addr + n <= c->size);
  if (n) memcpy(c->w + addr, w, (size_t)n * sizeof *w);
}

void core_put_int(struct core *c, uint32_t addr, int nwords, int64_t v)
{
  assert(nwords >= 1 && nwords <= 4);
  assert((uint64_t)addr + (uint64_t)nwords <= c->size);
  uint64_t u = (uint64_t)v;
  for (int i = nwords - 1; i >= 0; i--, u >>= 16) c->w[addr + (uint32_t)i] = (uint16_t)u;
}

int64_t core_get_int(const struct core *c, uint32_t addr, int nwords)
{
  assert(nwords >= 1 && nwords <= 4);
  assert((uint64_t)addr + (uint64_t)nwords <= c->size);
  uint64_t u = 0;
  for (int i = 0; i < nwords; i++) u = (u << 16) | c->w[addr + (uint32_t)i];
  int bits = 16 * nwords;
  if (bits < 64 && (u >> (bits - 1)) & 1u) u |= ~UINT64_C(0) << bits;     /* sign-extend */
  return (u >> 63) ? -(int64_t)(~u) - 1 : (int64_t)u;          /* no implementation-defined cast */
}

void core_put_wide(struct core *c, uint32_t addr, int nwords, core_wide v)
{
  assert(nwords >= 1 && nwords <= 8);
  assert((uint64_t)addr + (uint64_t)nwords <= c->size);
  core_uwide u = (core_uwide)v;
  for (int i = nwords - 1; i >= 0; i--, u >>= 16) c->w[addr + (uint32_t)i] = (uint16_t)u;
}

core_wide core_get_wide(const struct core *c, uint32_t addr, int nwords)
{
  assert(nwords >= 1 && nwords <= 8);
  assert((uint64_t)addr + (uint64_t)nwords <= c->size);
  core_uwide u = 0;
  for (int i = 0; i < nwords; i++) u = (u << 16) | c->w[addr + (uint32_t)i];
  int bits = 16 * nwords;
  if (bits < 128 && (u >> (bits - 1)) & 1u) u |= ~(core_uwide)0 << bits;
  return (u >> 127) ? -(core_wide)(~u) - 1 : (core_wide)u;
}

int core_tables(const struct core *c, const char **names, uint32_t *peak_words, int max)
{
  for (int i = 0; i < c->nstat && i < max; i++) {
    if (names) names[i] = c->stat[i].name;
    if (peak_words) peak_words[i] = c->stat[i].peak;
  }
  return c->nstat;
}

int core_layout_dump(const struct core *c, FILE *f)
{
  fprintf(f, "core: %" PRIu32 " words of 16 bits; in use %" PRIu32 ", peak %" PRIu32 "\n",
          c->size, core_used(c), c->peak);
  fprintf(f, "  %10s %8s %10s  %s\n", "address", "(hex)", "words", "table");
  uint32_t addr = 0;
  for (int i = 0; i < c->nrec; i++) {
    fprintf(f, "  %10" PRIu32 " %08" PRIX32 " %10" PRIu32 "  %s\n", addr, addr,
            c->rec[i].words, c->stat[c->rec[i].stat].name);
    addr += c->rec[i].words;
  }
  uint32_t gap = c->size - c->low_top - c->high_len;
  fprintf(f, "  %10" PRIu32 " %08" PRIX32 " %10" PRIu32 "  (free)\n", c->low_top, c->low_top, gap);
  if (c->high_len > 0) {
    uint32_t a = c->size - c->high_len;
    fprintf(f, "  %10" PRIu32 " %08" PRIX32 " %10" PRIu32 "  %s (high region, word k at %" PRIu32
            "-k)\n", a, a, c->high_len, c->stat[c->high_stat].name, c->size - 1);
  }
  fprintf(f, "most words each table held at once:\n");
  for (int i = 0; i < c->nstat; i++)
    fprintf(f, "  %-31s %10" PRIu32 "\n", c->stat[i].name, c->stat[i].peak);
  return ferror(f) ? T74_EIO : T74_OK;
}

void core_inject_exhaustion(struct core *c, uint32_t after)
{
  c->inject_on = after != UINT32_MAX;
  c->inject_tripped = 0;
  c->inject_left = after;
}
