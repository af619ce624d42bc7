/*
** fx.c — the effects stage (see fx.h): which effects run, in what order.
*/
#include "effects/fx.h"

#include <stdio.h>
#include <string.h>

#include "effects/aa.h"
#include "effects/edges.h"
#include "effects/smooth.h"

bool fx_wanted(const struct effects *e)
{
  return e->aa != EFFECTS_AA_NONE || e->edges || e->smooth != EFFECTS_SMOOTH_NONE ||
         e->contour_on;
}

void fx_count(struct fx_stats *st, const char *name, double v, bool integer)
{
  for (int k = 0; k < st->n; k++)
    if (!strcmp(st->name[k], name)) { st->value[k] += v; return; }
  if (st->n == FX_MAX_COUNTERS) return;
  snprintf(st->name[st->n], FX_NAME_MAX, "%s", name);
  st->value[st->n] = v;
  st->integer[st->n] = integer;
  st->n++;
}

int fx_run(struct render *r, const struct scene *s, const struct effects *e,
           const struct vis_grid *g, struct fx_frame *f, struct fx_stats *st,
           struct cost *cost, struct t74_error *err)
{
  /* smooth (paper 004), then aa (papers 000/001), then edges (paper 002) */
  if (e->smooth != EFFECTS_SMOOTH_NONE || e->contour_on) {
    int rc = smooth_run(r, s, e, g, f, st, cost, err);
    if (rc != T74_OK) return rc;
  }
  if (e->aa != EFFECTS_AA_NONE) {
    int rc = aa_run(r, e, g, f, st, cost, err);
    if (rc != T74_OK) return rc;
  }
  if (e->edges) {
    int rc = edge_run(r, s, e, g, f, EDGE_PASS_ROW | EDGE_PASS_COL, st, cost, err);
    if (rc != T74_OK) return rc;
  }
  return T74_OK;
}
