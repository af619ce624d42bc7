/*
** priority.h — the Priority Matrix of paper 003 (§4, Fig. 9) and interpenetration (§3.1,
** Fig. 7, eq. (5)).
**
** The relative priority of two pieces is computed the first time the Visible Surface
** Procedure finds both covering one stretch of a scanline, and never again. Codes as in
** Fig. 9, for i < j: 00 not yet known, 10 piece i lower than piece j, 11 piece i higher.
** At that first meeting the pieces are also tested for interpenetration; pieces that cross
** are cut along their intersection line and the caller is told to look again.
*/
#ifndef T74_PRIORITY_H
#define T74_PRIORITY_H

#include <stdint.h>
#include <stdio.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/mapper.h"
#include "render/seginfo.h"

enum prio_result {
  PRIO_ERROR  = -1,   /* err holds why (T74_ECORE: the matrix does not fit) */
  PRIO_FIRST  = 1,    /* the first piece is in front */
  PRIO_SECOND = 2,    /* the second piece is in front */
  PRIO_SPLIT  = 3     /* they interpenetrated: both were cut, pieces were added */
};

enum prio_store { PRIO_AUTO = 0, PRIO_DENSE = 1, PRIO_SPARSE = 2 };

/* A stretch [x0, x1) (x0 < x1) of the line y = yn/yd that two pieces were both found to
   cover, each within its exact span there (the Visible Surface Procedure in exact
   arithmetic): their interiors then meet just above it, which answers some of decide's
   overlap tests before they are made (priority.c, "The stretch"). */
struct prio_meet { struct grat x0, x1; int64_t yn, yd; };

/* One pair of faces found crossing, and the line L~ both were cut along (kept for the
   intersection lines of enhanced edges, paper 002 e4; host memory, one entry a pair). */
struct prio_cut { int fa, fb; struct gline line; };

struct prio {
  struct seginfo *seg;
  const struct mapped *map;
  struct core *core;
  struct cost *cost;
  int      store;           /* PRIO_DENSE: Fig. 9's 2-bit triangle; PRIO_SPARSE: hashed pairs */
  uint64_t cover;           /* dense: pieces the triangle covers now */
  uint64_t hcap;            /* sparse: slots (4 words a slot) */
  uint64_t hused;           /* pairs held (either store) */
  int      migrate;         /* PRIO_AUTO: the triangle may be given up for the sparse store */
  int      migrated;        /* it was: the store began dense and became sparse */
  uint8_t *tag;             /* sparse: one byte a slot beside the table, host only
                               (priority.c, "The tags"), or NULL */
  int      tag_off;         /* tests: every look probes the table itself, one at a time,
                               each charged as it is made (the same answers and charges:
                               the tags' argument in priority.c, prio_order_lineage) */
  uint64_t tag_looks;       /* looks the tags answered (host statistic) */
  uint64_t pend_mem, pend_home;  /* counted, not yet charged (prio_charge_pending): the
                               looks' words loaded and home slots found, */
  uint64_t pend_faces, pend_fverts;  /* the face pairs found (charge_faces) and their vertices, */
  uint64_t pend_sides;      /* the overlap and clip products (88 x 58 bits) decide spares */
  int      meet_off;        /* tests: decide makes every overlap test, whatever stretch the
                               pair was met on (the same answers and charges) */
  uint64_t meet_known;      /* overlap tests a stretch answered (host statistic) */
  struct prio_faces *faces; /* host: what decide found of the last face pairs met (priority.c,
                               "Face pairs"), or NULL */
  unsigned faces_bits;      /* that table's size, 2^faces_bits slots */
  unsigned faces_first_bits; /* tests: its first size (0: priority.c's FACE_BITS_FIRST) */
  uint64_t faces_new, faces_hit;  /* pairs found and kept ones used since it last grew */
  uint32_t faces_gen;       /* this frame's stamp: a slot stamped otherwise holds nothing (a
                               table kept from the last frame, prio_keep_take) */
  int      faces_off;       /* tests: decide finds it afresh for every pair */
  uint64_t faces_kept;      /* pairs decided with it kept (host statistic) */
  int      faces_grown;     /* times the table grew (host statistic) */
  uint64_t computed;        /* pairs whose priority was computed */
  int      splits;          /* interpenetrating pairs cut along their intersection */
  FILE    *trace;           /* teaching dump of each decision, or NULL */
  struct prio_cut *cut;     /* the face pairs cut along their intersection, in order found */
  int      ncut, cutcap;
  uint64_t *cuth;           /* host index of the pairs in cut (priority.c note_cut) */
  uint32_t cuthcap;         /* its slots: 0, or a power of two above 2 ncut */
  int      arith;           /* GEOM_EXACT, or GEOM_HITAC: depth from the 1974 planes */
  struct cpoly clip[4];     /* host scratch of decide's clipped halves, kept from pair to
                               pair (freed by prio_free) */
  int      verts_off;       /* tests: the vertices of a piece on its face's points made by
                               geom_meet, not taken from the points (priority.c face_verts;
                               the same answers and charges) */
};

/* store: PRIO_AUTO starts with the paper's dense matrix when the triangle for the `expect`
   pieces expected at the start takes at most half of the historical 16 kW, else with the
   sparse store of the pairs that actually meet; the dense store turns sparse (the pairs
   known are moved over) when growing the triangle would take more than the sparse table
   the pairs held then would be rebuilt to (12 words a pair, twice their fullest need),
   and back when that table would take more than twice the triangle (priority.c). Every
   step depends on the scene alone, never on --core. PRIO_DENSE and PRIO_SPARSE keep
   their store. */
/* The store PRIO_AUTO starts with for a scene of n pieces: PRIO_DENSE or PRIO_SPARSE. */
int prio_auto_store(uint64_t n);

int prio_init(struct prio *pr, struct seginfo *seg, const struct mapped *map,
              struct core *core, struct cost *cost, int store, uint64_t expect,
              struct t74_error *err);

/* The priority of pieces p and q (p != q), computed if not yet known. */
int prio_order(struct prio *pr, int p, int q, struct t74_error *err);

/* The priority of p and q if it is already known (PRIO_FIRST or PRIO_SECOND), else 0;
   never decides (one look at the matrix). */
int prio_known(struct prio *pr, int p, int q);

/* The Visible Surface Procedure's order of b and c (its order_of): when b or c was cut
   from another piece (pb, pc: their parents, -1 for none), the first known of: b and c,
   an ancestor of b (its parent, the parent's parent, ...: seginfo's parent, at most
   anc_max of them) and c, b and an ancestor of c, the parents pb and pc; else, or when
   none is known, prio_order of b and c. Each parent looked up is charged one load to
   `cost`. The looks, decisions and charges are those of these calls made one by one
   (which the sparse store's tags turned off makes, for tests: priority.c); the host
   counts the looks and charges them at once, and looks once where they look at the same
   pair again in a table that has not changed. `at`: NULL, or a stretch both pieces cover
   (struct prio_meet), which spares the host overlap tests whose answer it gives. */
/* prio_order_lineage counts the looks it makes through the sparse store's tags, and
   decide some of its products, and charges them here: the caller calls this before
   anything reads pr->cost (each counter is a sum of the same increments, so when they
   are added does not change it; prio_order calls it itself). */
void prio_charge_pending(struct prio *pr);

int prio_order_lineage(struct prio *pr, int b, int c, int pb, int pc, int anc_max,
                       struct cost *cost, const struct prio_meet *at, struct t74_error *err);

/* What a render keeps of the face-pair table for the next frame of its scene
   (render_keep): the block and its size only, with the stamp of the frame that filled it.
   What the table held depends on the view, so the next frame's table holds nothing at
   first all the same (a new stamp); it only starts as large as the last one grew, instead
   of small. */
struct prio_keep {
  struct prio_faces *faces;
  unsigned faces_bits;
  uint32_t faces_gen;
};

/* After prio_init: the face-pair table kept in k (if any) becomes pr's, empty. */
void prio_keep_take(struct prio *pr, struct prio_keep *k);

/* Before prio_free: pr's face-pair table (if any) is given to k for the next frame. */
void prio_keep_give(struct prio *pr, struct prio_keep *k);

void prio_keep_free(struct prio_keep *k);

/* Free the host-side list of cuts (the matrix itself lives in core). */
void prio_free(struct prio *pr);

/* The matrix in Fig. 9 form (or as a list of known pairs when large). The dump and the
   trace number pieces from 1 (piece k is seg->p[k - 1]), as the Segment Generator's
   listing of each face's pieces does. */
void prio_dump(const struct prio *pr, FILE *f);

#endif
