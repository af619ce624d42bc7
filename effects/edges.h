/*
** edges.h — enhanced edges (paper 002, Mochizuki, Kondo & Sato, §3): the edges of the
** input faces classified by the faces on either side and drawn as strips of a chosen
** width and grey, hidden exactly like the faces.
**
** This file declares the last effect of the effects stage (effects/fx.h): it runs after
** smooth and anti-aliasing, on the frame the Visible Surface Procedure scanned, and draws
** over the frame's greys. The method and every rule it follows are in edges.c's opening
** comment and docs/edges.md.
*/
#ifndef T74_EDGES_H
#define T74_EDGES_H

#include "emu/cost.h"
#include "emu/status.h"
#include "render/effects.h"
#include "effects/fx.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/visible.h"

/* The two scans of §3.3.1 (both in a render; tests switch one off). */
#define EDGE_PASS_ROW 1u      /* along rows: edges whose tangent against the row is >= 0.9 */
#define EDGE_PASS_COL 2u      /* along columns: tangent against the column >= 0.9 */

/* The classes of §3.2. */
enum edge_class {
  EDGE_E1,                /* not drawn: both faces turned away, or both seen in a smooth
                             group, or its face seen exactly edge-on */
  EDGE_E2,                /* outline: one face seen (silhouettes, edges of one face) */
  EDGE_E3,                /* inner: both faces seen */
  EDGE_E4_INNER,          /* intersection line within one object */
  EDGE_E4_OUTLINE         /* intersection line between different parts */
};

/* Classify and draw the edges of the scene r was prepared from into f (f->grey), with the
   widths and greys of e, in the passes asked for (EDGE_PASS_*). Counts go to st, the
   1974 operations to cost, the edge tables into r->core (T74_ECORE when they do not fit),
   and a line per edge to r->tables when it is open (--dump tables). */
int edge_run(struct render *r, const struct scene *s, const struct effects *e,
             const struct vis_grid *g, struct fx_frame *f, unsigned passes,
             struct fx_stats *st, struct cost *cost, struct t74_error *err);

#endif
