/*
** segment.h — the Segment Generator of paper 003 (§3.1, eq. (3), Fig. 4-6): concave faces
** and faces with holes cut into convex pieces by horizontal lines through concave vertices.
**
** Input: one projected face on the plane grid, its rings already oriented by the Mapper
** (outer boundary counter-clockwise, holes clockwise, so the face is always on the LEFT
** of every directed edge). Output: convex pieces, each the intersection of the half-planes
** left of its oriented lines (geom.h), listed counter-clockwise. A piece's sides lie on the
** face's own edges or on horizontal cut lines y = c through concave vertices; no vertex is
** ever rounded, so two faces that share an edge still share it exactly after the split.
*/
#ifndef T74_SEGMENT_H
#define T74_SEGMENT_H

#include <stdint.h>
#include <stdio.h>
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/geom.h"

struct seg_input {
  uint32_t face_id;            /* input face number (for tables) */
  int      nring;              /* 1 + holes */
  const int *ring_start;       /* nring + 1 offsets into pt/vid; ring 0 = outer (CCW), others holes (CW) */
  const struct gpoint *pt;     /* grid positions; consecutive points distinct, >= 3 per ring */
  const uint32_t *vid;         /* vertex ids as typed (tables and dumps show these) */
  int      first_piece;        /* the number the trace gives the face's first piece (the
                                  Segment Information's number, from 1); 0: 1 */
};

enum seg_vkind { SEGV_ORIG = 0, SEGV_CROSS = 1 };

struct seg_vertex {
  uint8_t  kind;               /* SEGV_ORIG: an input vertex; SEGV_CROSS: a crossing point */
  uint32_t num;                /* ORIG: vertex id; CROSS: crossing number (11, 12, ... as Fig. 6) */
  struct hpoint p;             /* exact position */
};

struct seg_piece {
  int n;                       /* sides, >= 3 */
  struct gline *line;          /* n oriented lines, CCW; side k runs from v[k] to v[k+1] */
  struct seg_vertex *v;        /* n vertices, CCW */
};

struct seg_result {
  int npiece;
  struct seg_piece *piece;
  int ncut;                    /* horizontal cut lines applied (concave splits) */
};

/* Split one face. trace (nullable) receives the teaching dump: YSORT, XSORT rows with each
   crossing's type (a)-(e), the rules of eq. (3) matched on them, and for each cut the
   states (a)-(d) of Fig. 6 (PBS, IPL, LWS, UPS). A cut names the part it cuts ("in part
   P": 1 is the face, then the pieces the cuts make, each cut's lower ones first); the
   convex pieces are listed with numbers from in->first_piece on. Tables are allocated in core for their lifetime (T74_ECORE when they
   do not fit) and operations are counted in cost. Returns T74_OK or an error status. */
int seg_generate(const struct seg_input *in, struct seg_result *out, FILE *trace,
                 struct core *core, struct cost *cost, struct t74_error *err);

void seg_result_free(struct seg_result *r);

/* Would seg_generate take the face (issue 19)? T74_OK when it would, else the status and
   message seg_generate gives: every decision it makes for taking or refusing the face,
   in its order, the core's tables taken as it takes them (so T74_ECORE where it runs out
   of core) but nothing written into them, nothing counted, no output pieces built. The
   face's and each cut's own tables come from scr, a scratch kept between calls (nothing
   of one call is seen by the next); seg_generate keeps one of its own for its call. */
struct seg_scratch;
struct seg_scratch *seg_scratch_new(void);     /* NULL: out of host memory */
void seg_scratch_free(struct seg_scratch *s);
int seg_check(const struct seg_input *in, struct seg_scratch *scr, struct core *core,
              struct t74_error *err);

/* seg_generate for the faces most scenes are made of (issue 19): no trace, one ring of
   at most SEG_CONVEX_MAX vertices, no concave vertex. Its one piece's lines go to line[]
   (room for SEG_CONVEX_MAX), *n of them; the operations charged, the core tables made
   and released and any refusal are seg_generate's, without its host allocations. For
   any other face: T74_OK with *n = 0, nothing done, nothing charged (seg_generate's).
   ysort: NULL, or the name CORE_T_YSORT as the caller keeps it for this core (struct
   core_name: its statistics row found once for all faces, issue 19). */
#define SEG_CONVEX_MAX 32
int seg_convex(const struct seg_input *in, struct core_name *ysort, struct gline *line, int *n,
               FILE *trace, struct core *core, struct cost *cost, struct t74_error *err);

#endif
