/*
** fx.c — the effects stage (see fx.h): which effects run, in what order.
*/
#include "render/fx.h"

#include "render/aa.h"
#include "render/edges.h"

#include <stdio.h>
#include <string.h>

bool fx_wanted(const struct effects *e)
{
  return e->aa != EFFECTS_AA_NONE || e->edges || e->smooth != EFFECTS_SMOOTH_NONE ||
         e->contour_on;
}

int fx_check(const struct effects *e, const char *file, int line, struct t74_error *err)
{
  const char *missing = NULL;
  if (e->smooth != EFFECTS_SMOOTH_NONE || e->contour_on) missing = "smooth/contour (paper 004)";
  if (!missing) return T74_OK;
  return t74_fail_at(err, T74_EINPUT, file, line,
                     "effect %s is not implemented in this version of tube74 "
                     "(implemented: halftone=, pattern=, tube=)", missing);
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
  (void)r; (void)s; (void)e; (void)g; (void)f; (void)st; (void)cost; (void)err;
  /* smooth (paper 004), then aa (papers 000/001), then edges (paper 002): each is
     called here when built; fx_check has refused the others before any work was done. */
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
