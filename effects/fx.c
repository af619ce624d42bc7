/*
** fx.c — the effects stage (see fx.h): which effects run, in what order.
*/
#include "effects/fx.h"

#include <stdint.h>
#include <string.h>

#include "effects/aa.h"
#include "effects/edges.h"
#include "effects/model.h"

bool fx_wanted(const struct effects *e, const struct scene *s)
{
  if (e->aa != EFFECTS_AA_NONE || e->edges || e->smooth != EFFECTS_SMOOTH_NONE ||
      e->contour_on || (e->shadows && s->has_light))
    return true;
  for (int k = 0; k < s->nf; k++)
    if (s->f[k].texture) return true;
  return false;
}

/* A name's hash over its first FX_NAME_MAX - 1 characters (as many as name[] keeps): its
** length, then its bytes eight a step, the last step the eight ending at the last byte
** (overlapping the step before) or, for a name under eight bytes, its bytes alone; *len set
** to that length, *cut when the name has more. Equal names have equal hashes, so a hash
** that differs rules a name out; one that agrees is confirmed by strcmp. */
static uint64_t fx_name_hash(const char *name, size_t *len, bool *cut)
{
  const size_t n0 = strnlen(name, FX_NAME_MAX);
  *cut = n0 > FX_NAME_MAX - 1;
  const size_t n = *cut ? FX_NAME_MAX - 1 : n0;
  *len = n;
  uint64_t h = n * 0x9e3779b97f4a7c15u, w;
  if (n < 8) {
    w = 0;
    for (size_t b = 0; b < n; b++) w |= (uint64_t)(uint8_t)name[b] << (8 * b);
    h = (h ^ w) * 0x9e3779b97f4a7c15u;
    return h ^ (h >> 29);
  }
  for (size_t at = 0; at + 8 < n; at += 8) {
    memcpy(&w, name + at, 8);
    h = (h ^ w) * 0x9e3779b97f4a7c15u;
    h ^= h >> 29;
  }
  memcpy(&w, name + n - 8, 8);
  h = (h ^ w) * 0x9e3779b97f4a7c15u;
  return h ^ (h >> 29);
}

void fx_count(struct fx_stats *st, const char *name, double v, bool integer)
{
  /* found by its hash, confirmed by strcmp (one strcmp a count, not one a name kept); a
     name too long for name[] equals none kept (each is at most FX_NAME_MAX - 1) */
  size_t len;
  bool cut;
  const uint64_t h = fx_name_hash(name, &len, &cut);
  for (int k = 0; k < st->n && !cut; k++)
    if (st->hash[k] == h && !strcmp(st->name[k], name)) {
      st->value[k] += v;
      return;
    }
  if (st->n == FX_MAX_COUNTERS) return;
  memcpy(st->name[st->n], name, len);       /* cut as snprintf cut it */
  st->name[st->n][len] = '\0';
  st->hash[st->n] = h;                      /* the hash of the name kept */
  st->value[st->n] = v;
  st->integer[st->n] = integer;
  st->n++;
}

int fx_run(const struct fx_engine *eng, const struct scene *s, const struct effects *e,
           struct fx_frame *f, struct fx_stats *st, struct cost *cost, struct t74_error *err)
{
  const char *why = eng->r ? NULL : fx_needs_1974(e);
  if (why) return t74_fail(err, T74_EINPUT, "the points engine cannot run this: %s", why);
  /* the model (contour regions, shadows, textures, smoothing), the point frame from it,
     then aa (papers 000/001) over the same model, then edges (paper 002) */
  uint32_t mark = core_mark(eng->core);
  struct fx_model m;
  int rc = fx_model_build(&m, eng, s, e, f->bg, st, cost, err);
  const bool points = rc == T74_OK && (fx_model_shades(&m) || fx_model_regions(&m));
  if (rc == T74_OK && !points && f->face_grey) {   /* the flat greys, as the frame had them */
    const size_t n = (size_t)f->W * (size_t)f->H;
    const int *face = f->face;
    uint8_t *grey = f->grey;
    const uint8_t *fg = f->face_grey;
    for (size_t at = 0; at < n; at++) grey[at] = fg[face[at] + 1];
  }
  f->face_grey = NULL;
  if (points) rc = fx_points(&m, f, st, cost, err);   /* every point's grey written */
  f->model = &m;
  if (rc == T74_OK && e->aa != EFFECTS_AA_NONE) rc = aa_run(eng, e, f, st, cost, err);
  if (rc == T74_OK && e->edges)
    rc = edge_run(eng->r, s, e, eng->g, f, EDGE_PASS_ROW | EDGE_PASS_COL, st, cost, err);
  f->model = NULL;
  fx_model_free(&m);
  core_release(eng->core, mark);
  return rc;
}
