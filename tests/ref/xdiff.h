/*
** xdiff.h — one differential check: a scene through the real renderer (the library, as
** `tube74 render --dump ids` runs it) and through the exact reference (exactref.h).
**
** The scene is written as .s74 text to a temporary file and read back by scene_load, so
** the renderer sees exactly what a user's file would give it; the ids of every point are
** then compared with xr_judge. Shared by tests/test_differential.c, tests/test_exact.c
** and the soak program (tools/soak.c).
*/
#ifndef TUBE74_TESTS_REF_XDIFF_H
#define TUBE74_TESTS_REF_XDIFF_H

#include <stdint.h>
#include <stdio.h>
#include "tests/ref/exactref.h"
#include "tests/ref/scenegen.h"
#include "render/scene.h"
#include "emu/status.h"

struct xd_result {
  int status;                /* the renderer's status (0: rendered) */
  char msg[1024];            /* its message when it refused */
  long points;               /* points judged */
  long band;                 /* points that differ inside the tolerance band */
  long wrong;                /* points wrong outside it */
  int first_i, first_j;      /* the first wrong point */
  unsigned first_got, first_want;
  uint64_t pairs_computed;   /* priority pairs the renderer decided */
  int faces_split;           /* faces split into triangles because rounding folded them */
};

/* store: 0 auto, 1 dense, 2 sparse (enum prio_store). Returns 0, or -1 when the check
   itself could not run (temporary file, memory; msg says why). */
int xd_check(struct xr_scene *s, int cell, int store, struct xd_result *res);

/* The same, handing back the renderer's ids (W x H, row j = 0 at the top; free them),
   or NULL when it refused. */
int xd_check_ids(struct xr_scene *s, int cell, int store, struct xd_result *res,
                 unsigned **ids);

/* Write s as .s74 to path. 0 or -1. */
int xd_save(struct xr_scene *s, const char *path);

/* Scene `seed` of the cross-check's family fam (tests/ref/scenegen.h) as the reference
   takes it: eye, window, vertices, faces with their greys and holes; 0, or -1 when it
   could not be generated or memory ran out. */
int xd_scenegen(sg_family fam, uint64_t seed, struct xr_scene *s);

/* s written to a temporary .s74 and read back as a user's file would be (the file is gone
   on return): scene_load's status, with *out and err as it leaves them; -1 (err says why)
   when the temporary file could not be made or written. */
int xd_load(struct xr_scene *s, struct scene **out, struct t74_error *err);

/* Seeds a generated family runs: T74_DIFF_SEEDS, default 400. */
int xd_seeds(void);

#endif
