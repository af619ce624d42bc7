/*
** priority.c — the Priority Matrix (paper 003 §4, Fig. 9) and interpenetration (§3.1,
** Fig. 7, eq. (5)).
**
** This file contains code to decide, once per pair, which of two convex pieces is nearer
** the eye where they overlap on the perspective plane, and to cut pieces that
** interpenetrate. Two convex plane pieces that do not cross keep one order over their
** whole overlap (003 §1): that is what makes a matrix of pairwise priorities enough.
**
** Depth, exactly. Along the ray from the eye E through a plane point r, face plane
** n.x + d = 0 (signed so n.E + d = D < 0) is hit at t = |D| / (n.(r - E)). Face A is in
** front of face B at r exactly when
**     G(r) = |D_B| n_A.(r - E) - |D_A| n_B.(r - E) > 0,
** and G is linear on the plane: G(x, y) = k0 x + k1 y + K on the grid, |k| < 2^86,
** |K| < 2^111. G = 0 is the projected intersection line of the two planes.
**
** Interpenetration. The line G = 0 is carried by two grid points: where it leaves the
** square of the plane grid (|x|, |y| <= GRID_LIMIT), each rounded to the grid. This line
** L~ lies within half a grid unit of G = 0 everywhere pieces can be, and it depends only
** on the two faces, so every piece of A meets every piece of B on the same L~. The pair
** is then judged by L~ alone, exactly: the part of the overlap left of L~ is where A is in
** front, the part right of it where B is. Overlap on both sides means the faces cross:
** both pieces are cut along L~ (eq. (5); case (b) of Fig. 7, where the crossing ends
** inside a face, is reduced to case (a) by cutting along the whole line), and their
** halves, lying on one side of L~, never cross again. The half-grid-unit between L~ and
** the true line is the only place where depth order is approximated.
**
** Ties. Coplanar overlapping faces (G = 0 everywhere): a pattern (`face N ... on F`) is in
** front of the face it lies on whatever the numbering (paper 000 §3.2), and of any face
** that is not a pattern; otherwise the face with the larger number is in front (a window
** numbered after its wall shows). Pieces of one face never overlap.
**
** Storage (in core). Dense: the triangle of 2-bit codes a_ij, i < j, at field
** j(j-1)/2 + i of the core's high region, growing as pieces are added. Sparse: an open-
** addressed table of the pairs actually met, 4 words a slot, 3 slots a pair after each
** rebuild (see SLOT_WORDS). PRIO_AUTO starts dense when the triangle for the pieces
** expected at the start takes at most half of the historical 16 kW, else sparse. It
** then follows what the scene needs: a dense store whose triangle, grown for the pieces
** the interpenetration cuts add, would take more than half of 16 kW and more than the
** sparse table the pairs held would be rebuilt to, moves the pairs to the sparse store;
** a sparse store whose next rebuild would take more than twice the triangle goes back to
** the triangle. Each move reads the old store through and lists the pairs held beyond
** both stores (list_pairs), so for a moment the core holds the larger store and the list:
** the peak that core_words_used reports. Each lookup in the sparse store is charged its
** home slot (a hash and one multiply) and the words its probes compare. Every step
** depends on the scene alone (the pieces and the pairs met, in scan order), never on
** --core, so a scene needs the same words whatever core it is given; the scenes of the
** papers (a few hundred pieces at most) never leave the triangle.
*/
#include "render/priority.h"

#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#define CODE_UNKNOWN 0u     /* 00 */
#define CODE_LOWER   2u     /* 10: piece i lower than piece j */
#define CODE_HIGHER  3u     /* 11: piece i higher than piece j */
#define PRIO_DENSE_MAX_WORDS 8192u  /* the triangle is always kept while it takes at most
                                       half of the historical 16 kW (about 360 pieces) */
#define DECIDED_SPLIT 4u   /* decide(): the pair was cut (not a code) */

/* The sparse store. A slot is 4 words: code (2 bits) and piece i (30 bits) in words 0-1,
   piece j in words 2-3; code 0 is an empty slot. Open addressing, linear probing, any
   number of slots, the home slot from the pair's hash scaled to the count (slot_hash).
   Load factor: the table is rebuilt when a pair would make it more than 2/3 full, to
   three slots per pair held (load 1/3), so the load stays between 1/3 and 2/3 and the
   store takes 6 to 12 words a pair (expected probes at 2/3: 2 for a pair held, 5 for
   one not yet held). */
#define SLOT_WORDS   4
#define SPARSE_MIN_SLOTS 64u
#define SPARSE_PIECE_LIMIT (1u << 30)
/* Dense to sparse (PRIO_AUTO only): the triangle is given up when growing it would take
   more than PRIO_DENSE_MAX_WORDS and more than PRIO_MIGRATE_FACTOR times the words the
   sparse store would be rebuilt to for the pairs held then (12 words a pair: twice what
   they take when the table is fullest, which leaves room for the pairs still to come).
   The move's list adds 4 words a pair, a third of the table, for a moment.
   Sparse to dense (PRIO_AUTO only): when a rebuild of the sparse table would take more
   than PRIO_RETURN_FACTOR times the triangle for the pieces there are. The triangle grows
   with the square of the pieces, the sparse table with the pairs that meet; the gap
   between the two factors keeps a scene from going to and fro. */
#define PRIO_MIGRATE_FACTOR 1u
#define PRIO_RETURN_FACTOR 2u

static uint64_t tri_words(uint64_t n)
{
  uint64_t pairs = n * (n - (n > 0)) / 2;
  return (pairs + 7) / 8;
}

/* the slots a rebuild makes for h pairs */
static uint64_t sparse_slots_for(uint64_t h)
{
  uint64_t s = 3 * h;
  return s < SPARSE_MIN_SLOTS ? SPARSE_MIN_SLOTS : s;
}

static uint64_t slot_hash(uint64_t i, uint64_t j, uint64_t cap)
{
  /* the pair as one 64-bit key through splitmix64's finaliser: every bit of i and j
     reaches the bits that choose the slot (the earlier mix left long probe runs at 640
     interpenetrating triangles, issue 12), scaled to [0, cap) by the high half of its
     product with cap (a mask below a power of two folded back into the table makes
     runs that a 2/3 load cannot bear). Where a pair lands changes nothing but the
     probe count: the code found is the same. */
  uint64_t h = i << 32 | j;
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  return (uint64_t)(((core_uwide)h * cap) >> 64);
}

/* the code held in slot s */
static unsigned slot_code(const struct prio *pr, uint64_t s)
{
  return core_high_get(pr->core, (uint32_t)(s * SLOT_WORDS)) >> 14;
}

/* The tags. Beside the sparse table the host keeps one byte a slot, pr->tag[s]: 0 for an
   empty slot, else TAG_USED, TAG_LOW when the slot's piece i is below 2^16 (its first
   word then holds 0 beside the code), and six bits of a hash of i. A look walks its
   probe sequence through the tags instead of the table: every slot whose tag says how
   its words compare with the pair's is counted without reading it (a different i: when
   both are below 2^16 the first words agree and the second differs, two loads; when one
   is and the other is not the first words differ, one load), an empty slot ends the walk
   (one load: the pair is not held), and only a slot whose tag cannot tell (the same tag,
   or both pieces above 2^16) is compared in the table itself, word by word as the probe
   does. So the answer and the words charged are the probe's exactly; the host reads a
   byte a slot, from a table an eighth of the size, instead of four words. Each slot's tag
   is written with its words (slot_put), and a rebuild starts both afresh. */
#define TAG_USED 0x80u
#define TAG_LOW  0x40u
#define TAG_PAD  16u     /* empty tags beyond the table's end (tag_walk reads 16 at once) */

static uint8_t slot_tag(uint32_t i)
{
  return (uint8_t)(TAG_USED | (i < 0x10000u ? TAG_LOW : 0) | ((i * 0x9E3779B1u) >> 26));
}

static void slot_put(struct prio *pr, uint64_t s, uint32_t i, uint32_t j, unsigned code)
{
  /* words k .. k + 3 of the high region, at core addresses size - 1 - k down to
     size - 4 - k: written in one call, from the lowest address up */
  uint32_t k = (uint32_t)(s * SLOT_WORDS);
  const uint16_t w[SLOT_WORDS] = { (uint16_t)j, (uint16_t)(j >> 16), (uint16_t)i,
                                   (uint16_t)(code << 14 | i >> 16) };
  memcpy(core_high_top_w(pr->core) - k - (SLOT_WORDS - 1), w, sizeof w);
  if (pr->tag) pr->tag[s] = slot_tag(i);
  COST_ADD_N(pr->cost, COST_MEM, SLOT_WORDS);
}

/* The stored program's home slot of a pair: the words of i, j and the slot count loaded,
   j shifted and exclusive-ored into i twice (a one-word hash), and the hash scaled to the
   count by the high half of its product with it (one word by two). The host mixes the
   pair more thoroughly (slot_hash), which spreads the same probes better; the 1974 work
   charged is this. */
static inline void charge_home_n(struct cost *c, uint64_t n)
{
  COST_ADD_N(c, COST_MEM, 3 * n);
  COST_ADD_N(c, COST_SHIFT, 2 * n);
  COST_ADD_N(c, COST_LOGIC, 2 * n);
  cost_mw_mul_n(c, 16, 32, n);
}

static void charge_home(const struct prio *pr)
{
  charge_home_n(pr->cost, 1);
}

/* One probe of slot s for (i, j): it loads the slot's first word (empty, or code and i's
   high bits) and goes on comparing word by word only while they match. Returns 1 when
   the slot holds (i, j) or is empty (where the probe stops), with *loads the words it
   loaded. */
static inline int slot_probe(const uint16_t *top, uint64_t s, uint32_t i, uint32_t j,
                             uint64_t *loads)
{
  const uint16_t *w = top - s * SLOT_WORDS;
  *loads = 1;
  if ((w[0] >> 14) == CODE_UNKNOWN) return 1;
  if ((w[0] & 0x3fff) != (uint16_t)(i >> 16)) return 0;
  ++*loads;
  if (w[-1] != (uint16_t)i) return 0;
  ++*loads;
  if (w[-3] != (uint16_t)j) return 0;
  ++*loads;
  return w[-2] == (uint16_t)(j >> 16);
}

/* The probe of (i, j) walked through the tags (pr->tag): the code found (CODE_UNKNOWN: not
   held), the slot where the probe stopped (*slot: the pair's, or the empty one where it
   belongs) and the words it compared, added to *loads; nothing charged. top:
   core_high_top, read once by the caller (the table does not move while it looks). */
static inline unsigned tag_walk(const struct prio *pr, const uint16_t *top, uint64_t cap,
                                uint32_t i, uint32_t j, uint64_t *slot, uint64_t *loads)
{
  const uint8_t *tag = pr->tag;
  const uint8_t q = slot_tag(i);
  uint64_t s = slot_hash(i, j, cap), l = 0;
  unsigned code;
#ifdef __SSE2__
  /* Sixteen tags at a time (TAG_PAD empty tags lie beyond the table's end: reached, the
     walk goes on from slot 0, as the scalar walk wraps). The first slot that is empty,
     has the same tag or has a used tag without TAG_LOW (below -64 as a signed byte: the
     slot's i is above 2^16) is found from three masks; each slot before it has a tag
     with TAG_LOW and another than q, which the scalar walk counts two loads when i is
     below 2^16 (both i below it: the first words agree) and one when i is above (the
     first words differ). At that slot the walk goes on as the scalar one: empty, it
     ends; a tag without TAG_LOW when q has it (one above 2^16, one below), one load and
     the next slot; else the table tells. The same slots and words, without a branch a
     slot. */
  const __m128i vq = _mm_set1_epi32((int)(q * 0x01010101u)), v64 = _mm_set1_epi8(-64);
  const unsigned low = q & TAG_LOW ? 1u : 0u;             /* i below 2^16 */
  for (;;) {
    const __m128i t = _mm_loadu_si128((const void *)(tag + s));
    const unsigned z = (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(t, _mm_setzero_si128()));
    const unsigned e = (unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(t, vq));
    const unsigned h = (unsigned)_mm_movemask_epi8(_mm_cmplt_epi8(t, v64));
    const unsigned p = (unsigned)__builtin_ctz(z | e | h | 0x10000u);
    l += p << low;
    s += p;
    if (p == 16) continue;
    if (z >> p & 1u) {                                      /* empty */
      if (s < cap) { l++; code = CODE_UNKNOWN; goto done; }
      s = 0;                                                /* the pad: wrap */
      continue;
    }
    if (low && !(e >> p & 1u)) { l++; s++; continue; }       /* its i above 2^16 */
    uint64_t pl;
    int found = slot_probe(top, s, i, j, &pl);               /* the table must tell */
    l += pl;
    if (found) { code = top[-(int64_t)(s * SLOT_WORDS)] >> 14; goto done; }
    s++;
  }
#else
  for (;; s = s + 1 == cap ? 0 : s + 1) {
    const uint8_t t = tag[s];
    if (!t) { l++; code = CODE_UNKNOWN; goto done; }   /* empty: where the pair belongs */
    if (t != q) {
      if (t & q & TAG_LOW) { l += 2; continue; }        /* i differs, both below 2^16 */
      if ((t ^ q) & TAG_LOW) { l += 1; continue; }       /* one above 2^16, one below */
    }
    uint64_t pl;
    int stop = slot_probe(top, s, i, j, &pl);         /* the table must tell */
    l += pl;
    if (stop) { code = top[-(int64_t)(s * SLOT_WORDS)] >> 14; goto done; }
  }
#endif
done:
  *slot = s;
  *loads += l;
  return code;
}

/* The slot holding (i, j), or the empty slot where it belongs, and its code (*code:
   CODE_UNKNOWN for an empty slot); the words the probes compared are charged (and the
   home slot). Through the tags when there are (and tests have not turned them off), else
   through the table. */
static inline uint64_t slot_find(struct prio *pr, uint64_t cap, uint32_t i, uint32_t j,
                                 unsigned *code)
{
  uint64_t s, loads = 0, l;
  charge_home(pr);
  if (pr->tag && !pr->tag_off) {
    *code = tag_walk(pr, core_high_top(pr->core), cap, i, j, &s, &loads);
    pr->tag_looks++;
  } else {
    const uint16_t *top = core_high_top(pr->core);      /* word k at top[-k] */
    s = slot_hash(i, j, cap);
    while (!slot_probe(top, s, i, j, &l)) {
      loads += l;
      s = s + 1 == cap ? 0 : s + 1;
    }
    loads += l;
    *code = top[-(int64_t)(s * SLOT_WORDS)] >> 14;
  }
  COST_ADD_N(pr->cost, COST_MEM, loads);
  return s;
}

/* Moving the pairs to a new store. The stored program reads the old store through and
   lists the pairs held (4 words a pair, as in a slot) in the words beyond both the old
   store and the new one, clears the new store over the old one's place and enters the
   list: the high region's peak is the larger of the two stores plus the list. (The list
   is kept on the host here; its words are taken from the core while it exists.) */
static uint32_t (*list_pairs(struct prio *pr, uint64_t newwords, uint64_t *count,
                             struct t74_error *err))[3]
{
  uint64_t old = core_high_words(pr->core), held = pr->hused;
  uint64_t room = (old > newwords ? old : newwords) + held * SLOT_WORDS;
  if (room > UINT32_MAX) {
    t74_fail(err, T74_ECORE, "scene does not fit the core: the priority pairs need %llu "
             "words", (unsigned long long)room);
    return NULL;
  }
  const char *name = pr->store == PRIO_DENSE ? CORE_T_PRIORITY : "PRIORITY PAIRS";
  if (core_high_grow(pr->core, name, (uint32_t)room, err) != T74_OK) return NULL;
  uint32_t (*list)[3] = malloc((size_t)(held ? held : 1) * sizeof *list);
  if (!list) {
    t74_fail(err, T74_EIO, "out of host memory");
    return NULL;
  }
  uint64_t n = 0;
  if (pr->store == PRIO_DENSE) {
    /* the triangle, word by word; field f = j(j-1)/2 + i */
    uint64_t tw = tri_words(pr->cover), j = 1, row = 0;   /* row: field of (0, j) */
    for (uint64_t w = 0; w < tw && n < held; w++) {
      uint16_t v = core_high_get(pr->core, (uint32_t)w);
      COST_ADD_N(pr->cost, COST_MEM, 1);
      for (unsigned b = 0; v; b++, v >>= 2) {
        unsigned code = v & 3u;
        if (!code) continue;
        uint64_t f = 8 * w + b;
        while (f >= row + j) { row += j; j++; }
        list[n][0] = (uint32_t)(f - row);
        list[n][1] = (uint32_t)j;
        list[n][2] = code;
        n++;
      }
    }
  } else {
    const uint16_t *top = core_high_top(pr->core);      /* word k at top[-k] */
    uint64_t s = 0;
    for (; s < pr->hcap && n < held; s++) {             /* a load a slot (charged below) */
      const uint16_t *w = top - s * SLOT_WORDS;
      unsigned code = w[0] >> 14;
      if (code == CODE_UNKNOWN) continue;
      list[n][0] = (uint32_t)(w[0] & 0x3fff) << 16 | w[-1];
      list[n][1] = (uint32_t)w[-2] << 16 | w[-3];
      list[n][2] = code;
      n++;
    }
    COST_ADD_N(pr->cost, COST_MEM, s);
  }
  COST_ADD_N(pr->cost, COST_MEM, n * SLOT_WORDS);       /* the list written */
  core_high_free(pr->core);
  *count = n;
  return list;
}

/* Rebuild the store as a sparse table of `slots` slots holding every pair known now. */
static int sparse_rebuild(struct prio *pr, uint64_t slots, struct t74_error *err)
{
  uint64_t words = slots * SLOT_WORDS, n = 0;
  uint32_t (*list)[3] = list_pairs(pr, words, &n, err);
  if (!list) return err->status;
  if (core_high_grow(pr->core, "PRIORITY PAIRS", (uint32_t)words, err) != T74_OK) {
    free(list);
    return err->status;
  }
  COST_ADD_N(pr->cost, COST_MEM, words);                 /* the new table cleared */
  pr->store = PRIO_SPARSE;
  pr->hcap = slots;
  pr->cover = 0;
  free(pr->tag);                                         /* NULL: probes read the table */
  pr->tag = slots <= SIZE_MAX - TAG_PAD ? calloc((size_t)slots + TAG_PAD, 1) : NULL;
  /* each entry read from the list (4 words), its home slot and probe, its slot written;
     through the tags the probes' words are counted and charged at once, as slot_find
     would have charged each */
  bool counted = pr->tag && !pr->tag_off;
  uint64_t loads = 0;
  const uint16_t *top = core_high_top(pr->core);
  for (uint64_t k = 0; k < n; k++) {
    uint64_t at;
    unsigned held;
    if (counted) tag_walk(pr, top, slots, list[k][0], list[k][1], &at, &loads);
    else at = slot_find(pr, slots, list[k][0], list[k][1], &held);
    slot_put(pr, at, list[k][0], list[k][1], list[k][2]);
  }
  COST_ADD_N(pr->cost, COST_MEM, SLOT_WORDS * n + loads);
  if (counted) {
    charge_home_n(pr->cost, n);
    pr->tag_looks += n;
  }
  free(list);
  pr->hused = n;
  return T74_OK;
}

/* Rebuild the store as the triangle for the pieces there are now (PRIO_AUTO, when the
   pairs held have come to need more than the triangle). */
static int dense_rebuild(struct prio *pr, struct t74_error *err)
{
  uint64_t pieces = (uint64_t)pr->seg->n, words = tri_words(pieces), n = 0;
  uint32_t (*list)[3] = list_pairs(pr, words, &n, err);
  if (!list) return err->status;
  if (core_high_grow(pr->core, CORE_T_PRIORITY, (uint32_t)words, err) != T74_OK) {
    free(list);
    return err->status;
  }
  COST_ADD_N(pr->cost, COST_MEM, words);                 /* the triangle cleared */
  pr->store = PRIO_DENSE;
  pr->hcap = 0;
  free(pr->tag);
  pr->tag = NULL;
  pr->cover = pieces;
  for (uint64_t k = 0; k < n; k++) {
    COST_ADD_N(pr->cost, COST_MEM, SLOT_WORDS + 1);      /* read from the list, stored */
    core_high_set2(pr->core, (uint64_t)list[k][1] * (list[k][1] - 1) / 2 + list[k][0],
                   list[k][2]);
  }
  free(list);
  pr->hused = n;
  return T74_OK;
}

static int dense_cover(struct prio *pr, uint64_t n, struct t74_error *err)
{
  if (n <= pr->cover) return T74_OK;
  uint64_t w = tri_words(n);
  if (w > UINT32_MAX)
    return t74_fail(err, T74_ECORE, "scene does not fit the core: the priority matrix for "
                    "%llu pieces needs %llu words, %u available", (unsigned long long)n,
                    (unsigned long long)w, core_words(pr->core));
  if (core_high_grow(pr->core, CORE_T_PRIORITY, (uint32_t)w, err) != T74_OK) return err->status;
  pr->cover = n;
  return T74_OK;
}

static inline unsigned code_get(struct prio *pr, uint32_t i, uint32_t j)
{
  COST_ADD_N(pr->cost, COST_MEM, 1);
  if (pr->store == PRIO_DENSE) {
    if (j >= pr->cover) return CODE_UNKNOWN;
    return core_high_get2(pr->core, (uint64_t)j * (j - 1) / 2 + i);
  }
  if (pr->hcap == 0) return CODE_UNKNOWN;
  unsigned code;
  slot_find(pr, pr->hcap, i, j, &code);
  return code;
}

/* A probe of a pair not held, made through the tags while the table stays as it is: the
   empty slot where the pair belongs and the words the probe compared. */
struct probe { uint64_t slot, loads; };

/* Store the code of (i, j). `miss`: NULL, or the probe of (i, j) made since the table last
   changed, which the store's own probe repeats (the same slot, the same words charged) as
   long as the table is not rebuilt first. */
static int code_set(struct prio *pr, uint32_t i, uint32_t j, unsigned code,
                    const struct probe *miss, struct t74_error *err)
{
  COST_ADD_N(pr->cost, COST_MEM, 2);
  if (pr->store == PRIO_DENSE) {
    uint64_t n = (uint64_t)pr->seg->n;
    uint64_t w = tri_words(n);
    if (pr->migrate && n > pr->cover && w > PRIO_DENSE_MAX_WORDS &&
        w > PRIO_MIGRATE_FACTOR * SLOT_WORDS * sparse_slots_for(pr->hused + 1)) {
      if (sparse_rebuild(pr, sparse_slots_for(pr->hused + 1), err) != T74_OK) return err->status;
      pr->migrated = 1;
      miss = NULL;
    } else {
      if (dense_cover(pr, n, err) != T74_OK) return err->status;
      core_high_set2(pr->core, (uint64_t)j * (j - 1) / 2 + i, code);
      pr->hused++;
      return T74_OK;
    }
  }
  if (j >= SPARSE_PIECE_LIMIT)
    return t74_fail(err, T74_ECORE, "scene does not fit the core: piece %u, the priority "
                    "pairs hold piece numbers below 2^30", (unsigned)j);
  if (3 * (pr->hused + 1) > 2 * pr->hcap) {
    uint64_t slots = sparse_slots_for(pr->hused + 1);
    if (pr->migrate && SLOT_WORDS * slots > PRIO_RETURN_FACTOR * tri_words((uint64_t)pr->seg->n)) {
      /* the pairs now need more than the triangle: back to the paper's matrix */
      if (dense_rebuild(pr, err) != T74_OK) return err->status;
      core_high_set2(pr->core, (uint64_t)j * (j - 1) / 2 + i, code);
      pr->hused++;
      return T74_OK;
    }
    if (sparse_rebuild(pr, slots, err) != T74_OK) return err->status;
    miss = NULL;
  }
  unsigned held;
  if (miss) {              /* only prio_order_lineage has one: charged with its looks */
    pr->pend_mem += miss->loads;
    pr->pend_home++;
    pr->tag_looks++;
    slot_put(pr, miss->slot, i, j, code);
  } else
    slot_put(pr, slot_find(pr, pr->hcap, i, j, &held), i, j, code);
  pr->hused++;
  return T74_OK;
}

int prio_auto_store(uint64_t n)
{
  return tri_words(n) <= PRIO_DENSE_MAX_WORDS ? PRIO_DENSE : PRIO_SPARSE;
}

int prio_init(struct prio *pr, struct seginfo *seg, const struct mapped *map,
              struct core *core, struct cost *cost, int store, uint64_t expect,
              struct t74_error *err)
{
  memset(pr, 0, sizeof *pr);
  pr->seg = seg;
  pr->map = map;
  pr->core = core;
  pr->cost = cost;
  /* The choice depends on the scene only, never on --core, so that the words a scene
     needs are the same whatever core it is given. */
  if (store == PRIO_AUTO) {
    store = prio_auto_store(expect);
    pr->migrate = 1;
  }
  pr->store = store;
  if (store == PRIO_DENSE) return dense_cover(pr, (uint64_t)seg->n, err);
  return sparse_rebuild(pr, sparse_slots_for(0), err);
}

/* Sixteen bytes stored at once: a 128-bit number, or two 64-bit ones side by side. What
   face_pair and face_line store is read back soon after (decide, depth_line) by loads
   the compiler makes 16 bytes wide; stored as two 8-byte halves, such a load waited for
   both stores to reach the cache instead of taking their data (a store-forwarding
   stall: about a sixth of decide's samples at 640 interpenetrating triangles). */
static inline void store16(void *dst, uint64_t lo, uint64_t hi)
{
#ifdef __SSE2__
  _mm_storeu_si128((__m128i *)dst, _mm_set_epi64x((long long)hi, (long long)lo));
#else
  memcpy(dst, &lo, 8);
  memcpy((char *)dst + 8, &hi, 8);
#endif
}

static inline void store_wide(wide *dst, wide v)
{
  store16(dst, (uint64_t)(uwide)v, (uint64_t)((uwide)v >> 64));
}

/* ---- depth ------------------------------------------------------------------------- */

struct depth { wide k0, k1, K; int h10; };  /* G(x, y) = k0 x + k1 y + K on the grid;
                                                h10: --arith hitac (depth_sign) */

static struct depth depth_of(const struct prio *pr, const struct mface *A, const struct mface *B)
{
  const int64_t *e = pr->map->eye;
  wide k[3];
  if (pr->arith == GEOM_HITAC) {
    /* --arith hitac: the planes as the 1974 program held them (one-word a, b, c; double-
       word d), so depth order and the intersection line come from truncated planes */
    int64_t a[4], b[4];
    geom_h10_plane(A->plane, a);
    geom_h10_plane(B->plane, b);
    wide da = -((wide)a[0] * e[0] + (wide)a[1] * e[1] + (wide)a[2] * e[2] + a[3]);  /* |plane(eye)| */
    wide db = -((wide)b[0] * e[0] + (wide)b[1] * e[1] + (wide)b[2] * e[2] + b[3]);
    for (int c = 0; c < 3; c++) k[c] = db * a[c] - da * b[c];
  } else
    for (int c = 0; c < 3; c++) k[c] = (wide)B->deye * A->plane[c] - (wide)A->deye * B->plane[c];
  struct depth g;
  g.h10 = pr->arith == GEOM_HITAC;
  g.k0 = k[0];
  g.k1 = k[1];
  /* r' = (x - 256 X0, y - 256 Y0, 256 f) with f = -Z0 */
  g.K = -GRID_ONE * (k[0] * e[0] + k[1] * e[1]) + GRID_ONE * (-e[2]) * k[2];
  return g;            /* charged by charge_faces */
}

/* sign of G at a homogeneous point (256-bit: 2^86 * 2^88) */
static int depth_sign(const struct depth *g, struct hpoint p)
{
  if (g->h10) {
    /* --arith hitac: the 1974 program compares depths at a point whose coordinates it
       holds in one word each, whole world units (truncated) */
    p.X = p.X / p.W / GRID_ONE * GRID_ONE;
    p.Y = p.Y / p.W / GRID_ONE * GRID_ONE;
    p.W = 1;
  }
  return geom_dot3_sign(g->k0, p.X, g->k1, p.Y, g->K, p.W);
}

/* round(n / d) half up, d != 0 */
static wide round_div(wide n, wide d)
{
  if (d < 0) { n = -n; d = -d; }
  wide q = n / d, r = n % d;
  if (r < 0) { q -= 1; r += d; }
  /* half up, 2r >= d: d - 1 - 2r < 0 (|terms| < 2^117), its sign bit added rather than
     branched on (a coin toss) */
  return q + (wide)((uwide)(d - 1 - 2 * r) >> 127);
}

/* round_div(n, d) = floor(n/d + 1/2) lies in [-lim, lim], decided without the divide
   (|n| < 2^115, |d| < 2^86, lim = 2^28: every product below 2^117) */
static bool round_in(wide n, wide d, wide lim)
{
  if (d < 0) { n = -n; d = -d; }
  return 2 * n + d >= -2 * lim * d && 2 * n < (2 * lim + 1) * d;
}

/* plane(V) == 0 for a vertex in space, exactly (|terms| < 2^51) */
static bool on_plane(const int64_t pl[4], const struct scene_vertex *v)
{
  return pl[0] * v->x + pl[1] * v->y + pl[2] * v->z + pl[3] == 0;
}

/* Grid points of the vertices of A and B that lie on both planes: the projected
   intersection line passes exactly through them (a shared edge, a T-junction). */
static int common_points(const struct mapped *m, const struct mface *A, const struct mface *B,
                         struct gpoint out[2])
{
  int n = 0;
  const struct mface *F[2] = { A, B };
  for (int s = 0; s < 2; s++) {
    const struct mface *f = F[s], *o = F[1 - s];   /* a product a vertex: charge_faces */
    for (int k = 0; k < f->ring_start[f->nring]; k++) {
      if (!on_plane(o->plane, &m->sv[f->vix[k]])) continue;
      struct gpoint p = f->pt[k];
      if (n == 0 || (n == 1 && (p.x != out[0].x || p.y != out[0].y))) out[n++] = p;
      else if (n == 2) {               /* keep the two farthest apart */
        for (int r = 0; r < 2; r++) {
          wide d_old = (wide)(out[0].x - out[1].x) * (out[0].x - out[1].x) +
                       (wide)(out[0].y - out[1].y) * (out[0].y - out[1].y);
          wide d_new = (wide)(out[r].x - p.x) * (out[r].x - p.x) +
                       (wide)(out[r].y - p.y) * (out[r].y - p.y);
          if (d_new > d_old) { out[1 - r] = p; break; }
        }
      }
    }
  }
  return n;
}

/* The largest squared distance from p to a vertex of face A or B (grid units). */
static wide reach2(const struct mface *A, const struct mface *B, struct gpoint p)
{
  wide r = 0;
  const struct mface *F[2] = { A, B };
  for (int s = 0; s < 2; s++)
    for (int k = 0; k < F[s]->ring_start[F[s]->nring]; k++) {
      wide dx = F[s]->pt[k].x - p.x, dy = F[s]->pt[k].y - p.y;
      if (dx * dx + dy * dy > r) r = dx * dx + dy * dy;
    }
  return r;
}

/* L~: G = 0 carried by two grid points, oriented so its left side is G > 0. Each point
   is within half a grid unit of the true line, so between them L~ is too; beyond them
   the error grows with the distance. The points are:
   - two vertices lying on both planes (a shared edge), when the faces reach no farther
     than COMMON_REACH times their distance from the first: then L~ is exactly the shared
     edge of the grid polygons, and within 0.5 (1 + 2 COMMON_REACH) units of the line
     wherever the faces are;
   - else one such vertex and the farthest point where G = 0 leaves the square of the
     plane grid (within 1.5 units wherever the faces are);
   - else the two points where G = 0 leaves the square (within 0.5 units).
   Returns false when G = 0 misses the square. */
#define COMMON_REACH 4
static bool depth_line(const struct depth *g, const struct gpoint *common, int ncommon, wide reach,
                       struct gline *out)
{
  const wide lim = GRID_LIMIT;
  struct gpoint pt[6];
  int n = 0;
  if (ncommon == 2) {
    wide dx = common[1].x - common[0].x, dy = common[1].y - common[0].y;
    if (reach > COMMON_REACH * COMMON_REACH * (dx * dx + dy * dy)) ncommon = 1;
  }
  for (int k = 0; k < ncommon; k++) pt[n++] = common[k];
  if (ncommon < 2) {
    if (g->k1 != 0) {            /* sides x = -lim and x = +lim */
      for (int s = -1; s <= 1; s += 2) {
        wide num = -(g->k0 * (s * lim) + g->K);
        if (!round_in(num, g->k1, lim)) continue;
        pt[n].x = (gcoord)(s * lim);
        pt[n].y = (gcoord)round_div(num, g->k1);
        n++;
      }
    }
    if (g->k0 != 0) {            /* sides y = -lim and y = +lim */
      for (int s = -1; s <= 1; s += 2) {
        wide num = -(g->k1 * (s * lim) + g->K);
        if (!round_in(num, g->k0, lim)) continue;
        pt[n].x = (gcoord)round_div(num, g->k0);
        pt[n].y = (gcoord)(s * lim);
        n++;
      }
    }
  }
  /* the two points farthest apart (a common vertex first, when there is one) */
  int bi = -1, bj = -1;
  wide best = 0;
  for (int i = 0; i < (ncommon == 1 ? 1 : n); i++)
    for (int j = i + 1; j < n; j++) {
      wide dx = pt[i].x - pt[j].x, dy = pt[i].y - pt[j].y;
      wide d = dx * dx + dy * dy;
      if (d > best) { best = d; bi = i; bj = j; }
    }
  if (bi < 0) return false;
  struct gline l = geom_line(pt[bi], pt[bj]);
  /* the normal (a, b) must point where G grows: |a|,|b| < 2^29, |k| < 2^86 */
  if ((wide)l.a * g->k0 + (wide)l.b * g->k1 < 0) l = geom_line(pt[bj], pt[bi]);
  store16(&out->a, (uint64_t)l.a, (uint64_t)l.b);   /* a and b side by side (geom.h) */
  out->c = l.c;
  return true;
}

/* Face pairs. What decide finds of two faces alone (G, the vertices on both planes, the
   reach from the first of them, L~) is the same for every pair of their pieces, and the
   pieces of one face pair are decided again and again as the interpenetration cuts them.
   The host keeps it for the face pairs met last, one a slot of a small table the ordered
   pair hashes into (the newest kept), and charges every use what finding it charges
   (charge_faces), so the counts are those of finding it again. faces_off (tests) finds
   it every time. The table may grow to about two slots a face, from 2^6 to 2^15 (2,560
   interpenetrating triangles: 55,600 of a frame's 157,000 decisions find theirs kept
   with 2^13 slots, 1.2 MB, against 66,800 with 2^15 slots, 4.7 MB, eight a face; the
   paper's scenes need a few kB). The smaller table is the faster whole process (issue
   19, round 42: -2 to -3% at 640 to 2,560 triangles, the frame level): the heap a run
   touches is faulted in 2 MB at a time, each zeroed by the kernel. It starts at 2^10 slots
   (147 kB) and grows eightfold only while the pairs kept are used: when as many pairs
   as it has slots have been found since it last grew and at least one in
   FACE_HIT_SHARE of them was found kept (the entries move to their slots in the larger
   table). Boxes that do not pierce each other meet each face pair once (30,000 faces:
   29,000 pairs, none found twice), and a 4.7 MB table written whole before the first
   and then missed at every pair cost their whole process some 5% of its time; a frame of
   the triangles still finds nearly all it found with the largest table from the
   start. Which pairs are kept changes no answer and no charge, only host time. */
#define FACE_BITS_MIN 6u
#define FACE_BITS_MAX 15u
#define FACE_BITS_FIRST 10u
#define FACE_BITS_STEP 3u
#define FACE_HIT_SHARE 16u
struct prio_faces {
  int fa, fb;              /* the faces of the first and the second piece; fa < 0: empty */
  uint32_t gen;            /* the frame's stamp (pr->faces_gen) when filled: another, empty */
  uint32_t fverts;         /* both faces' vertex counts summed (charge_faces): a pair found
                              kept is charged from it, its faces not read */
  struct depth g;
  struct gpoint common[2];
  int ncommon;
  int line;                /* -1 not yet found, 0 none (G = 0 misses the square, or G is
                              constant), 1 L~ below */
  struct gline L;
};

/* The 1974 work of finding G and the common vertices of faces A and B: depth_of's four
   products, common_points' product a vertex of each face. */
static uint32_t face_verts_sum(const struct mface *A, const struct mface *B)
{
  return (uint32_t)A->ring_start[A->nring] + (uint32_t)B->ring_start[B->nring];
}

/* fverts: face_verts_sum of the two faces */
static void charge_faces(struct prio *pr, uint32_t fverts)
{
  pr->pend_faces++;                          /* charged by prio_charge_pending */
  pr->pend_fverts += fverts;
}

/* A hint that a host block will be read soon (issue 19: the frame of 2,560 interpenetrating
   triangles waits on host blocks read at random: the face-pair table, the tags, the
   slots); nothing where the compiler has no such builtin. */
#if defined(__GNUC__) || defined(__clang__)
#define PREFETCH(a) __builtin_prefetch(a)
#else
#define PREFETCH(a) ((void)(a))
#endif

/* The slot of pr->faces (made) that the face pair (fa, fb) is kept in. */
static inline struct prio_faces *face_slot(const struct prio *pr, int fa, int fb)
{
  return &pr->faces[((uint32_t)fa * 0x9E3779B1u ^ (uint32_t)fb * 0x85EBCA77u) >>
                    (32 - pr->faces_bits)];
}

/* The face-pair table made or grown to 2^bits slots, what it held moved there; as it was
   when the host has no room. */
static void faces_resize(struct prio *pr, unsigned bits)
{
  struct prio_faces *t = malloc(((size_t)1 << bits) * sizeof *t), *old = pr->faces;
  if (!t) return;
  for (size_t k = 0; k < (size_t)1 << bits; k++) t[k].fa = -1;
  size_t nold = old ? (size_t)1 << pr->faces_bits : 0;
  pr->faces = t;
  pr->faces_bits = bits;
  for (size_t k = 0; k < nold; k++)
    if (old[k].fa >= 0 && old[k].gen == pr->faces_gen)
      *face_slot(pr, old[k].fa, old[k].fb) = old[k];
  free(old);
  pr->faces_new = pr->faces_hit = 0;
}

/* The face-pair table's largest size: about two slots a face. */
static unsigned faces_most(const struct prio *pr)
{
  unsigned most = FACE_BITS_MIN;
  while (most < FACE_BITS_MAX && (1u << most) < 2u * (unsigned)pr->map->nface) most++;
  return most;
}

/* The face pair (fa, fb), charged: kept in pr->faces, or found into *own. */
static struct prio_faces *face_pair(struct prio *pr, int fa, int fb, struct prio_faces *own)
{
  struct prio_faces *e = own;
  if (!pr->faces_off) {
    if (!pr->faces) {
      unsigned first = pr->faces_first_bits ? pr->faces_first_bits : FACE_BITS_FIRST, most;
      faces_resize(pr, first < (most = faces_most(pr)) ? first : most);
    }
    if (pr->faces) {
      e = face_slot(pr, fa, fb);
      if (e->fa == fa && e->fb == fb && e->gen == pr->faces_gen) {
        charge_faces(pr, e->fverts);           /* what finding it charges */
        pr->faces_kept++;
        pr->faces_hit++;
        return e;
      }
      if (++pr->faces_new >= (uint64_t)1 << pr->faces_bits) {   /* as many as its slots */
        unsigned most = faces_most(pr);
        if (pr->faces_bits < most && pr->faces_hit * FACE_HIT_SHARE >= pr->faces_new) {
          unsigned to = pr->faces_bits + FACE_BITS_STEP;
          faces_resize(pr, to < most ? to : most);
          pr->faces_grown++;
          e = face_slot(pr, fa, fb);
        } else {
          pr->faces_new = pr->faces_hit = 0;
        }
      }
    }
  }
  const struct mface *A = &pr->map->f[fa], *B = &pr->map->f[fb];
  e->fa = fa;
  e->fb = fb;
  e->gen = pr->faces_gen;
  e->fverts = face_verts_sum(A, B);
  charge_faces(pr, e->fverts);
  const struct depth g = depth_of(pr, A, B);
  store_wide(&e->g.k0, g.k0);
  store_wide(&e->g.k1, g.k1);
  store_wide(&e->g.K, g.K);
  e->g.h10 = g.h10;
  e->ncommon = common_points(pr->map, A, B, e->common);
  e->line = g.k0 == 0 && g.k1 == 0 ? 0 : -1;   /* G constant: no L~ (face_line) */
  return e;
}

/* L~ of the face pair (found the first time it is asked for): false when there is none. */
static bool face_line(const struct prio *pr, struct prio_faces *e)
{
  if (e->line < 0) {
    const struct mface *A = &pr->map->f[e->fa], *B = &pr->map->f[e->fb];
    wide reach = e->ncommon > 0 ? reach2(A, B, e->common[0]) : 0;
    /* G is not constant here: face_pair set line to 0 for a constant G */
    e->line = depth_line(&e->g, e->common, e->ncommon, reach, &e->L);
  }
  return e->line == 1;
}

/* Does a side of piece X (its lines xl, or NULL for piece_line) lie on line l (either
   way round)? A piece's sides and L~ are lines through grid points or horizontal
   (geom.h: |a|, |b| <= 2^29), so the first products are below 2^58 and compared in 64
   bits. */
static inline bool on_line_side(const struct piece *X, const struct gline *xl,
                                struct gline l)
{
  if (!xl && X->onface) {
    /* its lines not made: side k lies on l when pt[k] and pt[k + 1] do (they differ:
       seginfo_add_face, so side k's line is not 0, and it is a multiple of l, as the test
       below asks, exactly when both points are on l). l(pt) is first summed modulo 2^64
       (not 0 there: not 0), then, where that is 0, exactly (|a x|, |b y| < 2^58 and
       |c| < 2^63: geom.h) */
    bool on0 = false, on = false;
    for (int k = 0; k < X->n; k++) {
      struct gpoint q = X->pt[k];
      bool onk = (uint64_t)l.a * (uint64_t)q.x + (uint64_t)l.b * (uint64_t)q.y +
                 (uint64_t)l.c == 0 &&
                 (wide)l.a * q.x + (wide)l.b * q.y + l.c == 0;
      if (k == 0) on0 = onk;
      else if (on && onk) return true;
      on = onk;
    }
    return on && on0;
  }
  for (int k = 0; k < X->n; k++) {
    struct gline m = xl ? xl[k] : piece_line(X, k);
    if (m.a * l.b == m.b * l.a && (wide)m.a * l.c == (wide)m.c * l.a &&
        (wide)m.b * l.c == (wide)m.c * l.b)
      return true;
  }
  return false;
}

#define ONE_SIDE_KEPT 64             /* pieces of up to so many sides keep one_side's signs */

/* 1 when every vertex of X is on or left of l and one strictly left, -1 the same on the
   right, and X has an interior (the test seginfo_clip ends with); else 0. xv: X's vertices
   (piece_verts). side: NULL, or room for X->n signs, each vertex's side of l
   (geom_side_h). */
static int one_side(const struct piece *X, const struct gline *xl, const struct hpoint *xv,
                    struct gline l, signed char *side)
{
  bool pos = false, neg = false;
  for (int k = 0; k < X->n; k++) {
    int sg = geom_side_hw(l, xv[k]);
    if (side) side[k] = (signed char)sg;
    pos |= sg > 0;
    neg |= sg < 0;
  }
  if (pos == neg || X->n < 3) return 0;
  for (int k = 0; k < X->n; k++)
    for (int j = 0; j < X->n; j++)
      if (geom_side_hw(xl[k], xv[j]) > 0) return pos ? 1 : -1;
  return 0;
}

/* one_side of piece X on its face's points (onface), from those points, its vertices not
   made. Exact, the same result and signs: vertex k of such a piece is where the lines
   through pt[k-1], pt[k] and through pt[k], pt[k+1] meet (never parallel:
   seginfo_add_face), so geom_meet gives it as (W x, W y, W), W > 0 (Cramer's rule on
   integers, exact), and a W x + b W y + c W = W (a x + b y + c): the same sign for every
   line; and, W >= 1, each term no larger than the vertex's (geom.h's bounds hold).
   Issue 19: a piece's vertices are made where read (seginfo.h), and most pairs on one
   side of L~ read nothing else of them. */
static int one_side_face(const struct piece *X, struct gline l, signed char *side)
{
  bool pos = false, neg = false;
  for (int k = 0; k < X->n; k++) {
    wide v = (wide)l.a * X->pt[k].x + (wide)l.b * X->pt[k].y + l.c;
    int sg = (v > 0) - (v < 0);
    if (side) side[k] = (signed char)sg;
    pos |= sg > 0;
    neg |= sg < 0;
  }
  if (pos == neg || X->n < 3) return 0;
  for (int k = 0; k < X->n; k++) {
    struct gline m = piece_line(X, k);
    for (int j = 0; j < X->n; j++)
      if ((wide)m.a * X->pt[j].x + (wide)m.b * X->pt[j].y + m.c > 0) return pos ? 1 : -1;
  }
  return 0;
}

/* Add a clipped half as a new piece. */
static int add_half(struct prio *pr, int face, const struct cpoly *c, struct t74_error *err)
{
  return seginfo_add(pr->seg, face, c->n, c->line, err);
}

/* The unordered face pair {fa, fb} as a key of the host's index of pr->cut (never 0). */
static uint64_t cut_key(int fa, int fb)
{
  return ((uint64_t)(uint32_t)(fa < fb ? fa : fb) << 32 | (uint32_t)(fa < fb ? fb : fa)) + 1;
}

/* The slot of {fa, fb} in that index (open addressing, cuthcap a power of two): the slot
   holding it, or the empty one where it belongs. */
static uint32_t cut_slot(const struct prio *pr, int fa, int fb)
{
  uint64_t key = cut_key(fa, fb);
  uint32_t m = pr->cuthcap - 1, s = (uint32_t)((key * 0x9E3779B97F4A7C15ull) >> 32) & m;
  while (pr->cuth[s] && pr->cuth[s] != key) s = (s + 1) & m;
  return s;
}

/* Remember that faces fa and fb were cut along l (once a pair: the first line stays). */
static int note_cut(struct prio *pr, int fa, int fb, struct gline l, struct t74_error *err)
{
  if (2 * ((uint64_t)pr->ncut + 1) > pr->cuthcap) {      /* the index at most half full */
    uint32_t cap = pr->cuthcap ? 2 * pr->cuthcap : 64;
    uint64_t *h = calloc(cap, sizeof *h);
    if (!h) return t74_fail(err, T74_EIO, "out of host memory");
    free(pr->cuth);
    pr->cuth = h;
    pr->cuthcap = cap;
    for (int k = 0; k < pr->ncut; k++) {
      const struct prio_cut *c = &pr->cut[k];
      h[cut_slot(pr, c->fa, c->fb)] = cut_key(c->fa, c->fb);
    }
  }
  uint32_t s = cut_slot(pr, fa, fb);
  if (pr->cuth[s]) return T74_OK;
  if (pr->ncut == pr->cutcap) {
    int c = pr->cutcap ? 2 * pr->cutcap : 16;
    struct prio_cut *n = realloc(pr->cut, (size_t)c * sizeof *n);
    if (!n) return t74_fail(err, T74_EIO, "out of host memory");
    pr->cut = n;
    pr->cutcap = c;
  }
  pr->cuth[s] = cut_key(fa, fb);
  pr->cut[pr->ncut].fa = fa;
  pr->cut[pr->ncut].fb = fb;
  pr->cut[pr->ncut].line = l;
  pr->ncut++;
  return T74_OK;
}

void prio_keep_take(struct prio *pr, struct prio_keep *k)
{
  if (!k->faces) return;
  free(pr->faces);
  pr->faces = k->faces;
  pr->faces_bits = k->faces_bits;
  pr->faces_gen = k->faces_gen + 1;    /* every slot stamped otherwise: empty */
  if (pr->faces_gen == 0)              /* the stamp wrapped: empty them by hand */
    for (size_t s = 0; s < (size_t)1 << pr->faces_bits; s++) pr->faces[s].fa = -1;
  k->faces = NULL;
}

void prio_keep_give(struct prio *pr, struct prio_keep *k)
{
  if (!pr->faces) return;
  free(k->faces);
  k->faces = pr->faces;
  k->faces_bits = pr->faces_bits;
  k->faces_gen = pr->faces_gen;
  pr->faces = NULL;
}

void prio_keep_free(struct prio_keep *k)
{
  free(k->faces);
  k->faces = NULL;
}

void prio_free(struct prio *pr)
{
  free(pr->tag);
  pr->tag = NULL;
  free(pr->faces);
  pr->faces = NULL;
  for (int k = 0; k < 4; k++) cpoly_free(&pr->clip[k]);
  free(pr->cut);
  pr->cut = NULL;
  pr->ncut = pr->cutcap = 0;
  free(pr->cuth);
  pr->cuth = NULL;
  pr->cuthcap = 0;
}

/* The stretch. When the two pieces of a pair both cover a stretch [x0, x1) of a line y
   (x0 < x1, each within its exact span there), their interiors meet: a point z of the
   open stretch lies strictly inside each piece's span, and a convex piece whose span at y
   holds z strictly, y below its top, holds the points just above z in its interior. So
   seginfo_overlap of the two is true (a side of one with every vertex of the other on
   or outside it would leave no interior point of the other inside that side, yet z is
   one), and so is that of a half of P cut along L with Q where the open stretch has
   points strictly on that half's side of L (z taken there). Such a test's answer is
   known: the host charges what it charges when true (a product a side of both) and does
   not make it. *side gets which sides of L the open stretch reaches: bit 0 left (L > 0),
   bit 1 right; L at x0 and x1 in 128 bits (|a num yd|, |b yn den|, |c den yd| < 2^121). */
static int meet_sides(const struct prio_meet *at, struct gline L)
{
  int sides = 0;
  const struct grat *x[2] = { &at->x0, &at->x1 };
  /* the same sum, grouped: a yd num + (b yn + c yd) den, with |a yd| < 2^63 (|a| <=
     2^29, yd < 2^34: vis_spans) and den < 2^63 (the sweep's x_cmp); each part is one
     of the three terms above or the sum of two, so the sum stays below 2^123 */
  const wide ayd = (wide)(L.a * at->yd), bc = (wide)L.b * at->yn + (wide)L.c * at->yd;
  for (int k = 0; k < 2; k++) {
    wide v = ayd * x[k]->num + bc * (wide)(uint64_t)x[k]->den;
    sides |= v > 0 ? 1 : v < 0 ? 2 : 0;
  }
  return sides;
}

/* seginfo_overlap of the n1-sided first with the n2-sided second when known true: its
   charge alone (the host statistic counted). */
static bool overlap_known(struct prio *pr, int n1, int n2)
{
  pr->pend_sides += (uint64_t)n1 + (uint64_t)n2;
  pr->meet_known++;
  return true;
}

/* ---- the pieces' vertices -----------------------------------------------------------
   decide reads both pieces' vertices. A piece of its own lines (seginfo_add: a half of a
   cut, or a piece of a face the Segment Generator cut) keeps them (seginfo.h piece_kept,
   geom_meet's values); a piece on its face's points has them from the points. */

/* The vertices of a piece on its face's points (struct piece: onface), into buf: vertex k,
   where sides k - 1 and k meet, is pt[k] (both sides run through it and are not
   parallel: seginfo_add_face), made as (x, y, 1) rather than by geom_meet, which gives
   (W x, W y, W), W > 0: the same point. decide reads vertices only through what a
   positive W does not change: the sign of a line at them (geom_side_hw), the ratio of
   such a value to W (the farthest from the common edge, geom_cross_sign), the depth
   sign there (geom_dot3_sign, or X / W and Y / W under --arith hitac, exact quotients
   here), and the clipped halves' vertices, read as those are (their sides alone make
   the halves kept: add_half). So the same decisions, without the n meets (verts_off,
   for tests: made by geom_meet). */
static const struct hpoint *face_verts(const struct piece *p, struct hpoint *buf)
{
  for (int k = 0; k < p->n; k++) buf[k] = (struct hpoint){ p->pt[k].x, p->pt[k].y, 1 };
  return buf;
}

/* Piece i's vertices, and its lines in *lines: its own (kept), or made into buf and lbuf
   (room for PIECE_VBUF) for a piece on its face's points. */
static const struct hpoint *piece_verts_lines(const struct prio *pr, int i, struct hpoint *buf,
                                              struct gline *lbuf, const struct gline **lines)
{
  const struct piece *p = &pr->seg->p[i];
  *lines = piece_lines(p, lbuf);
  if (!p->onface) return piece_kept(p);
  return pr->verts_off ? piece_verts_of(p, *lines, buf) : face_verts(p, buf);
}

/* Decide pieces i < j, met on the stretch `at` (or NULL). Returns the code for (i, j),
   DECIDED_SPLIT, or PRIO_ERROR. */
static int decide(struct prio *pr, int i, int j, const struct prio_meet *at,
                  struct t74_error *err)
{
  if (pr->meet_off) at = NULL;
  struct piece *P = &pr->seg->p[i], *Q = &pr->seg->p[j];
  const struct mface *A = &pr->map->f[P->face], *B = &pr->map->f[Q->face];
  pr->computed++;
  if (P->face == Q->face) return CODE_HIGHER;           /* never overlap: any order */
  /* the two pieces' vertices and lines, made when first read (lazy:
     most pairs on one side of L~ met on a stretch read neither piece's vertices) */
  struct hpoint pvb[PIECE_VBUF], qvb[PIECE_VBUF];
  struct gline plb[PIECE_VBUF], qlb[PIECE_VBUF];
  const struct gline *pln = NULL, *qln = NULL;
  const struct hpoint *pv = NULL, *qv = NULL;
#define P_VERTS() (pv ? pv : (pv = piece_verts_lines(pr, i, pvb, plb, &pln)))
#define Q_VERTS() (qv ? qv : (qv = piece_verts_lines(pr, j, qvb, qlb, &qln)))
#define P_LINES() (pln ? pln : (pln = piece_lines(P, plb)))
#define Q_LINES() (qln ? qln : (qln = piece_lines(Q, qlb)))

  struct prio_faces own, *F = face_pair(pr, P->face, Q->face, &own);
  const struct depth *g = &F->g;
  const struct gpoint *common = F->common;
  if (F->ncommon == 2) {
    /* Faces meeting along an edge or at a T-junction: the true intersection line runs
       through c0 c1 exactly. A piece that keeps to one side of the grid line E = c0' c1'
       holds the whole overlap of the pair on that side, so in the exact geometry the pair
       does not cross (the grid line and the true one part only by rounding). Their order
       is then the true depth sign at that piece's vertex farthest from E (exact, 256-bit).
       Both pieces cut by E means the faces cross along the edge: handled below. */
    struct gline E = geom_line(common[0], common[1]);
    const struct piece *PQ[2] = { P, Q };
    (void)P_VERTS();
    (void)Q_VERTS();
    const struct hpoint *PQv[2] = { pv, qv };
    for (int s2 = 0; s2 < 2; s2++) {
      const struct piece *X = PQ[s2];
      const struct hpoint *xv = PQv[s2];
      int side = 0;
      bool mixed = false;
      struct hpoint far = xv[0];
      wide farv = 0;
      for (int k = 0; k < X->n && !mixed; k++) {
        struct hpoint v = xv[k];
        wide val = E.a * v.X + E.b * v.Y + E.c * v.W;   /* < 2^119: geom.h */
        int sg = (val > 0) - (val < 0);
        if (sg && side && sg != side) mixed = true;
        if (sg) side = sg;
        wide av = val < 0 ? -val : val;                 /* distance = av / (W |(a,b)|) */
        if (geom_cross_sign(av, far.W, farv, v.W) > 0) {
          far = v;
          farv = av;
        }
      }
      if (mixed || farv == 0) continue;
      int sg = depth_sign(g, far);
      if (sg == 0) sg = mface_coplanar_front(A, B) ? 1 : -1;
      if (pr->trace)
        fprintf(pr->trace, "PRIORITY pieces %d (face %u) and %d (face %u): %s in front "
                "(they meet along an edge)\n", i + 1, (unsigned)A->id, j + 1, (unsigned)B->id,
                sg > 0 ? "first" : "second");
      return sg > 0 ? CODE_HIGHER : CODE_LOWER;
    }
  }
  if (!face_line(pr, F)) {
    /* one face in front of the other wherever they can be */
    int s;
    if (g->k0 == 0 && g->k1 == 0) s = (g->K > 0) - (g->K < 0);
    else s = depth_sign(g, Q_VERTS()[0]);
    if (s == 0) s = mface_coplanar_front(A, B) ? 1 : -1;   /* coplanar: render/mapper.h */
    if (pr->trace)
      fprintf(pr->trace, "PRIORITY pieces %d (face %u) and %d (face %u): %s in front%s\n",
              i + 1, (unsigned)A->id, j + 1, (unsigned)B->id, s > 0 ? "first" : "second",
              g->k0 == 0 && g->k1 == 0 && g->K == 0 ? (A->on || B->on ? " (coplanar: the pattern)"
                                                                  : " (coplanar: larger face number)") : "");
    return s > 0 ? CODE_HIGHER : CODE_LOWER;
  }

  const struct gline L = F->L;
  /* the halves in host scratch kept from pair to pair (no allocation a decision) */
  struct cpoly *pl = &pr->clip[0], *pr_ = &pr->clip[1], *ql = &pr->clip[2], *qr = &pr->clip[3];
  int result;
  bool hasl, hasr, ovl, ovr;
  signed char sides[ONE_SIDE_KEPT];
  signed char *sv = P->n <= ONE_SIDE_KEPT ? sides : NULL;   /* each vertex's side, for the clip */
  int side = P->onface && !pv ? one_side_face(P, L, sv)
                               : (P_VERTS(), one_side(P, pln, pv, L, sv));
  if (side) {
    /* P on one side of L: the clip to that side is P itself (its sides are merged, its
       vertices kept: seginfo_add), the clip to the other has no interior. Host work
       spared, the 1974 work of both clips charged as seginfo_clip does (one product a
       vertex). */
    pr->pend_sides += 2 * (uint64_t)P->n;
    hasl = side > 0;
    hasr = side < 0;
    bool ov = at ? overlap_known(pr, P->n, Q->n)
                 : (P_VERTS(), Q_VERTS(),
                    seginfo_overlap_n(P->n, pln, pv, Q->n, qln, qv, &pr->pend_sides));
    ovl = hasl && ov;
    ovr = hasr && ov;
  } else {
    /* A half the stretch reaches on one side of L has an interior (the points just above
       the stretch there, struct prio_meet): when only one is reached, only its count of
       sides is asked for (the overlap test it is spared is charged by it), so it is
       counted and not made, unless the pair is then cut (below: made again, its
       charges already made). */
    int met = at ? meet_sides(at, L) : 0;
    int known = met == 1 || met == 2 ? met : 0;
    (void)P_VERTS();
    seginfo_clip_both_known(P, pln, pv, L, sv, known, pl, &hasl, pr_, &hasr, &pr->pend_sides);
    ovl = hasl && (met & 1 ? overlap_known(pr, pl->n, Q->n)
                           : (Q_VERTS(), seginfo_overlap_n(pl->n, pl->line, pl->v, Q->n, qln,
                                                           qv, &pr->pend_sides)));
    ovr = hasr && (met & 2 ? overlap_known(pr, pr_->n, Q->n)
                           : (Q_VERTS(), seginfo_overlap_n(pr_->n, pr_->line, pr_->v, Q->n,
                                                           qln, qv, &pr->pend_sides)));
    if (known && ovl && ovr) {
      uint64_t uncounted = 0;             /* its charges made already (above) */
      seginfo_clip_both_known(P, pln, pv, L, NULL, 0, pl, &hasl, pr_, &hasr, &uncounted);
    }
  }
  if (ovl && ovr) {
    /* Fig. 7 (a), eq. (5): A p' B p'' -> p' p'' A, p'' p' B, for both pieces */
    bool qhl, qhr;
    uint64_t qprod = 0;                   /* seginfo_clip_both, Q's vertices made already */
    (void)Q_VERTS();
    seginfo_clip_both_known(Q, qln, qv, L, NULL, 0, ql, &qhl, qr, &qhr, &qprod);
    cost_mw_mul_n(pr->cost, 88, 58, qprod);
    int pf = P->face, qf = Q->face;
    if (add_half(pr, pf, pl, err) < 0 || add_half(pr, pf, pr_, err) < 0) return PRIO_ERROR;
    if (qhl && qhr && (add_half(pr, qf, ql, err) < 0 || add_half(pr, qf, qr, err) < 0))
      return PRIO_ERROR;
    /* seginfo may have moved: index afresh */
    pr->seg->p[i].alive = false;
    if (qhl && qhr) pr->seg->p[j].alive = false;
    for (int k = pr->seg->n - (qhl && qhr ? 4 : 2); k < pr->seg->n; k++)
      pr->seg->p[k].parent = pr->seg->p[k].face == pf ? i : j;
    pr->splits++;
    if (note_cut(pr, pf, qf, L, err) != T74_OK) return PRIO_ERROR;
    if (pr->trace)
      fprintf(pr->trace, "INTERSECT pieces %d (face %u) and %d (face %u) cross: cut along "
              "%lld x + %lld y + %lld = 0 into pieces %d..%d\n", i + 1, (unsigned)A->id, j + 1,
              (unsigned)B->id, (long long)L.a, (long long)L.b, (long long)L.c,
              pr->seg->n - (qhl && qhr ? 4 : 2) + 1, pr->seg->n);
    result = DECIDED_SPLIT;
  } else {
    result = ovr && !ovl ? CODE_LOWER : CODE_HIGHER;
    /* No crossing inside this pair's overlap; but where one of the pieces was cut before
       along this very line (by a third face in the same plane as one of these), the two
       faces still meet along it: the line is noted for enhanced edges (paper 002 e4),
       so which pairs happen to be decided first does not choose the lines drawn. */
    if ((on_line_side(P, P->onface ? pln : P_LINES(), L) ||
         on_line_side(Q, Q->onface ? qln : Q_LINES(), L)) &&
        note_cut(pr, P->face, Q->face, L, err) != T74_OK)
      return PRIO_ERROR;
    if (pr->trace)
      fprintf(pr->trace, "PRIORITY pieces %d (face %u) and %d (face %u): %s in front\n",
              i + 1, (unsigned)A->id, j + 1, (unsigned)B->id, result == CODE_HIGHER ? "first" : "second");
  }
  return result;
#undef P_VERTS
#undef Q_VERTS
#undef P_LINES
#undef Q_LINES
}

/* Decide pieces i < j (the pair not held) and store the code; `miss` as for code_set. The
   order of p and q as prio_order gives it. */
static int order_new(struct prio *pr, uint32_t i, uint32_t j, int p, const struct probe *miss,
                     const struct prio_meet *at, struct t74_error *err)
{
  int d = decide(pr, (int)i, (int)j, at, err);
  if (d == PRIO_ERROR) return PRIO_ERROR;
  if (d == (int)DECIDED_SPLIT) return PRIO_SPLIT;
  if (code_set(pr, i, j, (unsigned)d, miss, err) != T74_OK) return PRIO_ERROR;
  return ((unsigned)d == CODE_HIGHER) == ((uint32_t)p == i) ? PRIO_FIRST : PRIO_SECOND;
}

/* prio_order, the pair met on the stretch `at` (or NULL) */
static int order_at(struct prio *pr, int p, int q, const struct prio_meet *at,
                    struct t74_error *err)
{
  uint32_t i = (uint32_t)(p < q ? p : q), j = (uint32_t)(p < q ? q : p);
  unsigned code = code_get(pr, i, j);
  if (code == CODE_UNKNOWN) return order_new(pr, i, j, p, NULL, at, err);
  bool i_front = code == CODE_HIGHER;
  return (i_front == ((uint32_t)p == i)) ? PRIO_FIRST : PRIO_SECOND;
}

int prio_order(struct prio *pr, int p, int q, struct t74_error *err)
{
  int r = order_at(pr, p, q, NULL, err);
  prio_charge_pending(pr);
  return r;
}

static inline int known(struct prio *pr, int p, int q)
{
  uint32_t i = (uint32_t)(p < q ? p : q), j = (uint32_t)(p < q ? q : p);
  unsigned code = code_get(pr, i, j);
  if (code == CODE_UNKNOWN) return 0;
  bool i_front = code == CODE_HIGHER;
  return (i_front == ((uint32_t)p == i)) ? PRIO_FIRST : PRIO_SECOND;
}

int prio_known(struct prio *pr, int p, int q)
{
  return known(pr, p, q);
}

/* The parent of piece p (seginfo), one word loaded. */
static inline int parent(const struct prio *pr, int p, struct cost *cost)
{
  COST_ADD_N(cost, COST_MEM, 1);
  return pr->seg->p[p].parent;
}

/* known(b, c), else of an ancestor of b and c, else of b and an ancestor of c, else of the
   parents: the first known, or 0. Each look charged as it is made. */
static int known_lineage(struct prio *pr, int b, int c, int pb, int pc, int anc_max,
                         struct cost *cost)
{
  int r = known(pr, b, c);
  if (r) return r;
  for (int a = pb, k = 0; a >= 0 && k < anc_max; a = parent(pr, a, cost), k++)
    if ((r = known(pr, a, c))) return r;
  for (int a = pc, k = 0; a >= 0 && k < anc_max; a = parent(pr, a, cost), k++)
    if ((r = known(pr, b, a))) return r;
  if (pb >= 0 && pc >= 0 && (r = known(pr, pb, pc))) return r;
  return 0;
}

/* The order of p and q as held in the sparse store (0: not held), looked at through the
   tags: the look counted in *n and the words its probe compared added to *loads, for
   charge_looks. */
static inline int known_counted(const struct prio *pr, const uint16_t *top, int p, int q,
                                uint64_t *n, uint64_t *loads)
{
  uint32_t i = (uint32_t)(p < q ? p : q), j = (uint32_t)(p < q ? q : p);
  uint64_t s;
  unsigned code = tag_walk(pr, top, pr->hcap, i, j, &s, loads);
  ++*n;
  if (code == CODE_UNKNOWN) return 0;
  return (code == CODE_HIGHER) == ((uint32_t)p == i) ? PRIO_FIRST : PRIO_SECOND;
}

/* n looks at the sparse store whose probes compared `loads` words, charged at once: what
   code_get and slot_find charge for each (the look, the home slot, the words), summed
   (each counter is a sum of the same increments: emu/cost.h). */
static void charge_looks(struct prio *pr, uint64_t n, uint64_t loads)
{
  pr->pend_mem += n + loads;                 /* charged by prio_charge_pending */
  pr->pend_home += n;
  pr->tag_looks += n;
}

void prio_charge_pending(struct prio *pr)
{
  COST_ADD_N(pr->cost, COST_MEM, pr->pend_mem);
  charge_home_n(pr->cost, pr->pend_home);
  /* the face pairs' finding (charge_faces): depth_of's four products, common_points'
     product a vertex of each face */
  cost_mw_mul_n(pr->cost, 51, 34, 3 * pr->pend_faces);
  cost_mw_mul_n(pr->cost, 86, 24, pr->pend_faces);
  cost_mw_mul_n(pr->cost, 34, 17, pr->pend_fverts);
  cost_mw_mul_n(pr->cost, 88, 58, pr->pend_sides);   /* a vertex by a side, as seginfo's */
  pr->pend_mem = pr->pend_home = pr->pend_faces = pr->pend_fverts = pr->pend_sides = 0;
}

int prio_order_lineage(struct prio *pr, int b, int c, int pb, int pc, int anc_max,
                       struct cost *cost, const struct prio_meet *at, struct t74_error *err)
{
  bool lineage = pb >= 0 || pc >= 0;
  if (pr->store != PRIO_SPARSE || !pr->tag || pr->tag_off) {
    /* the long way: each look made and charged one by one */
    int r = lineage ? known_lineage(pr, b, c, pb, pc, anc_max, cost) : 0;
    return r ? r : order_at(pr, b, c, at, err);
  }
  /* Through the tags, the looks counted and charged at once. The table does not change
     while they are made, so prio_order's look at (b, c) after the lineage is the first
     one again (the same slot, the same words), and so is the store's probe when the
     pair is decided and no rebuild comes first (code_set). */
  uint32_t i = (uint32_t)(b < c ? b : c), j = (uint32_t)(b < c ? c : b);
  uint64_t n = 1, loads = 0;
  struct probe first;
  const uint16_t *top = core_high_top(pr->core);
  unsigned code = tag_walk(pr, top, pr->hcap, i, j, &first.slot, &loads);
  first.loads = loads;
  if (code == CODE_UNKNOWN && pr->faces && !pr->faces_off) {
    /* the pair may be decided next (unless its lineage tells): its faces' slot in the
       face-pair table and the faces asked for while the lineage is walked */
    int fa = pr->seg->p[i].face, fb = pr->seg->p[j].face;
    PREFETCH(face_slot(pr, fa, fb));
    PREFETCH(&pr->map->f[fa]);
    PREFETCH(&pr->map->f[fb]);
  }
  int r = code == CODE_UNKNOWN ? 0
          : (code == CODE_HIGHER) == ((uint32_t)b == i) ? PRIO_FIRST : PRIO_SECOND;
  if (!r && lineage) {
    /* each parent looked up is a load (parent), counted here and charged once */
    const struct piece *sp = pr->seg->p;
    uint64_t up = 0;
    for (int a = pb, k = 0; !r && a >= 0 && k < anc_max; k++) {
      if ((r = known_counted(pr, top, a, c, &n, &loads))) break;
      a = sp[a].parent;
      up++;
    }
    for (int a = pc, k = 0; !r && a >= 0 && k < anc_max; k++) {
      if ((r = known_counted(pr, top, b, a, &n, &loads))) break;
      a = sp[a].parent;
      up++;
    }
    COST_ADD_N(cost, COST_MEM, up);
    if (!r && pb >= 0 && pc >= 0) r = known_counted(pr, top, pb, pc, &n, &loads);
    if (!r) {                                   /* prio_order's own look */
      n++;
      loads += first.loads;
    }
  }
  charge_looks(pr, n, loads);
  return r ? r : order_new(pr, i, j, b, &first, at, err);
}

/* qsort order of listed pairs {i, j, code}: by j, then i */
static int pair_cmp(const void *a, const void *b)
{
  const uint32_t *x = a, *y = b;
  if (x[1] != y[1]) return x[1] < y[1] ? -1 : 1;
  return (x[0] > y[0]) - (x[0] < y[0]);
}

void prio_dump(const struct prio *pr, FILE *f)
{
  struct prio *m = (struct prio *)pr;      /* reading only; code_get counts no cost here */
  struct cost *saved = m->cost, scratch = { { 0 } };
  m->cost = &scratch;
  int n = pr->seg->n;
  fprintf(f, "PRIORITY MATRIX (Fig. 9): %d pieces, %s store, %llu pairs computed\n", n,
          pr->store == PRIO_DENSE ? "dense 2-bit" : "sparse", (unsigned long long)pr->computed);
  fprintf(f, "  a_ij = 00 undefined, 10 piece i lower than piece j, 11 piece i higher\n");
  if (n <= 48) {
    fprintf(f, "      ");
    for (int j = 0; j < n; j++) fprintf(f, "%3d", j + 1);
    fprintf(f, "\n");
    for (int i = 0; i < n; i++) {
      fprintf(f, "  %3d ", i + 1);
      for (int j = 0; j < n; j++) {
        if (i == j) { fprintf(f, "  -"); continue; }
        unsigned c = i < j ? code_get(m, (uint32_t)i, (uint32_t)j)
                           : code_get(m, (uint32_t)j, (uint32_t)i);
        if (i > j && c != CODE_UNKNOWN) c = c == CODE_HIGHER ? CODE_LOWER : CODE_HIGHER;
        fprintf(f, " %s", c == CODE_UNKNOWN ? "00" : c == CODE_LOWER ? "10" : "11");
      }
      fprintf(f, "\n");
    }
  } else if (pr->store == PRIO_SPARSE) {
    /* the pairs held, in the triangle's order (j, then i), without asking for every pair */
    uint64_t count = 0;
    uint32_t (*list)[3] = malloc((size_t)(pr->hused ? pr->hused : 1) * sizeof *list);
    for (uint64_t sl = 0; list && sl < pr->hcap && count < pr->hused; sl++) {
      unsigned c = slot_code(pr, sl);
      if (c == CODE_UNKNOWN) continue;
      uint32_t k = (uint32_t)(sl * SLOT_WORDS);
      list[count][0] = (uint32_t)(core_high_get(pr->core, k) & 0x3fff) << 16 | core_high_get(pr->core, k + 1);
      list[count][1] = (uint32_t)core_high_get(pr->core, k + 2) << 16 | core_high_get(pr->core, k + 3);
      list[count][2] = c;
      count++;
    }
    if (list) {
      qsort(list, (size_t)count, sizeof *list, pair_cmp);
      for (uint64_t k = 0; k < count; k++)
        fprintf(f, "  a(%u,%u) = %s\n", (unsigned)list[k][0] + 1, (unsigned)list[k][1] + 1,
                list[k][2] == CODE_LOWER ? "10" : "11");
      free(list);
    } else
      fprintf(f, "  (out of host memory listing the pairs)\n");
  } else {
    for (int j = 1; j < n; j++)
      for (int i = 0; i < j; i++) {
        unsigned c = code_get(m, (uint32_t)i, (uint32_t)j);
        if (c != CODE_UNKNOWN)
          fprintf(f, "  a(%d,%d) = %s\n", i + 1, j + 1, c == CODE_LOWER ? "10" : "11");
      }
  }
  for (int k = 0; k < n; k++)
    if (!pr->seg->p[k].alive) fprintf(f, "  piece %d was cut along an intersection line\n", k + 1);
  m->cost = saved;
}
