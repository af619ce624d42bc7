/*
** model.h — the frame model: what every effect reads and writes, so that they compose.
**
** Paper 000 §3 treats faces, patterns and shadows alike as polygons met along each
** (sub-)scanline, and gives each visible stretch its polygon's colour I(S): reflectance
** (a texture's, §3.3 (1)) times illumination. Paper 004 gives a smoothed patch its
** intensity point by point and cuts its contour. tube74 holds all of it here, once:
**
**   the region   fx_lines_get: the visible stretches of any horizontal line, from the
**                Visible Surface Procedure (render/visible.h), with the contour cut's
**                regions (effects/contour.h) taken out of their object — where the object
**                is cut away the line shows what the object hid, found by a second
**                Visible Surface Procedure without the object's faces — and each stretch
**                split where a shadow polygon (effects/shadow.h) begins or ends, carrying
**                the set of lights blocked there;
**   the shading  fx_shade: the grey of a face at any position of the plane: flat, or the
**                patch's smooth / partial shading (effects/smooth.h), times the texture's
**                reflectance, from the lights not blocked (render/shade.h).
**
** The point frame (fx_points: the face and grey at each point centre, as --dump ids and
** grey show them) is the model sampled at the centres; anti-aliasing (effects/aa.h)
** integrates the same model over sub-scanlines, its fragments shaded at their own
** positions (000 §3.3 (1): the midpoint of each stretch within a point); enhanced edges
** draw over the result. So a cut corner stays cut under every filter, a smooth surface
** has no seams under anti-aliasing, and a shadow's edge is anti-aliased like a face's.
*/
#ifndef T74_MODEL_H
#define T74_MODEL_H

#include <stdbool.h>
#include <stdint.h>
#include "effects/contour.h"
#include "effects/fx.h"
#include "effects/poly.h"
#include "effects/smooth.h"

struct pic;
struct fx_tex;

struct fx_model {
  struct render *r;
  const struct scene *s;
  const struct effects *e;
  const struct vis_grid *g;
  const uint8_t *bg;        /* background grey per point, or NULL */
  int W, H;
  bool smooth;              /* smooth= or contour= given: sm holds the patches */
  struct smooth_model sm;
  struct fx_tex *tex;       /* per scene face: its texture, or NULL entries */
  int ntex;                 /* faces with a texture */
  struct fx_polys cuts;     /* contour cut regions (owner: object id) */
  struct contour_corners corners;   /* their corners, one a region, in the same order */
  int ncut;                 /* objects with a cut */
  int *cut_obj;             /* their ids */
  uint8_t **cut_skip;       /* per cut object: per mapped face, 1 = a face of the object */
  struct fx_polys shadows;  /* shadow polygons (owner: mapped face), sorted by owner */
  int *shadow_first;        /* per mapped face + 1: its shadows are [first[f], first[f+1]) */
};

/* Build the model the effects e call for over the prepared, scanned render r (contour
   regions, shadows, textures, smoothing patches; tables in r->core, work in cost). */
int fx_model_build(struct fx_model *m, struct render *r, const struct scene *s,
                   const struct effects *e, const struct vis_grid *g, const uint8_t *bg,
                   struct fx_stats *st, struct cost *cost, struct t74_error *err);
void fx_model_free(struct fx_model *m);

/* Does the model change regions (a contour cut or shadows)? */
bool fx_model_regions(const struct fx_model *m);

/* Does the model shade point by point (smoothing, textures or shadows)? */
bool fx_model_shades(const struct fx_model *m);

/* The grey 0..255 of face (index in r->map.f; -1: the background of point (i, j)) at
   position (u, v) of the plane in point units (u across from the window's left, v down
   from its top), with the lights in blocked in shadow. *region (may be NULL): the
   smoothing region (smooth.h), -1 for a flat face. */
int fx_shade(const struct fx_model *m, int face, unsigned blocked, double u, double v,
             int i, int j, struct cost *cost, int *region);

/* One visible stretch of a line after the region effects. */
struct fx_span {
  struct grat x0, x1;       /* [x0, x1), grid units */
  int piece, face;          /* the piece and face seen (-1, -1 never: gaps are left out) */
  unsigned blocked;         /* lights whose shadow covers the stretch (bit k: light k) */
};

struct fx_lines;

/* Lines of the model, asked in non-decreasing y like vis_spans. */
int fx_lines_open(struct fx_lines **out, const struct fx_model *m, struct cost *cost,
                  struct t74_error *err);
int fx_lines_get(struct fx_lines *L, int64_t yn, int64_t yd, const struct fx_span **span,
                 int *nspan, struct t74_error *err);
void fx_lines_close(struct fx_lines *L);

/* The point frame: f->face (after the cut) and f->grey from the model at each point
   centre; f->face holds the Visible Surface Procedure's faces on entry. */
int fx_points(const struct fx_model *m, struct fx_frame *f, struct fx_stats *st,
              struct cost *cost, struct t74_error *err);

#endif
