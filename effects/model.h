/*
** model.h — the frame model: what every effect reads and writes, so that they compose.
**
** Paper 000 §3 treats faces, patterns and shadows alike as polygons met along each
** (sub-)scanline, and gives each visible stretch its polygon's colour I(S): reflectance
** (a texture's, §3.3 (1)) times illumination. Paper 004 gives a smoothed patch its
** intensity point by point and cuts its contour. tube74 holds all of it here, once:
**
**   the region   what is seen along a line, from the engine that drew the frame
**                (effects/see.h), with the contour cut's regions (effects/contour.h)
**                taken out of their object — where the object is cut away the line shows
**                what the object hid, asked of the engine again without the object's
**                faces — and the set of lights a shadow polygon (effects/shadow.h) blocks
**                there. With the 1974 engine, fx_lines_get gives it as the visible
**                stretches of any horizontal line (the Visible Surface Procedure's, each
**                split where a shadow begins or ends); with either engine,
**                fx_lines_samples gives it at the samples of a lattice row (the point
**                centres, or supersampling's samples), sample by sample from the engine's
**                answers when it gives no stretches (the points engine);
**   the shading  fx_shade: the grey of a face at any position of the plane: flat, or the
**                patch's smooth / partial shading (effects/smooth.h), times the texture's
**                reflectance, from the lights not blocked (render/shade.h).
**
** The point frame (fx_points: the face and grey at each point centre, as --dump ids and
** grey show them) is the model sampled at the centres; anti-aliasing (effects/aa.h)
** integrates the same model over sub-scanlines, or samples it (aa=super), its fragments
** shaded at their own positions (000 §3.3 (1): the midpoint of each stretch within a
** point); enhanced edges draw over the result. A region decided stretch by stretch and
** sample by sample is the same region: a point on a polygon's boundary belongs to the
** stretch on its right either way (effects/poly.h), and tests/test_engines.c checks the
** two ways against each other on the 1974 engine. So a cut corner stays cut under every
** filter, a smooth surface has no seams under anti-aliasing, and a shadow's edge is
** anti-aliased like a face's.
*/
#ifndef T74_MODEL_H
#define T74_MODEL_H

#include <stdbool.h>
#include <stdint.h>
#include "effects/contour.h"
#include "effects/fx.h"
#include "effects/poly.h"
#include "effects/smooth.h"
#include "render/shade.h"

struct pic;
struct fx_tex;

struct fx_model {
  const struct fx_engine *eng;    /* the engine that drew the frame */
  const struct mapped *map;       /* its faces */
  const struct scene *s;
  const struct effects *e;
  const struct vis_grid *g;
  const uint8_t *bg;        /* background grey per point, or NULL */
  int W, H;
  bool smooth;              /* smooth= or contour= given: sm holds the patches */
  struct smooth_model sm;
  struct fx_tex *tex;       /* per scene face: its texture, or NULL entries */
  int ntex;                 /* faces with a texture */
  bool tex_kept;            /* tex belongs to the engine's tex_keep (effects/see.h) */
  struct fx_polys cuts;     /* contour cut regions (owner: object id) */
  struct contour_corners corners;   /* their corners, one a region, in the same order */
  int ncut;                 /* objects with a cut */
  int *cut_obj;             /* their ids */
  uint8_t **cut_skip;       /* per cut object: per mapped face, 1 = a face of the object */
  struct fx_polys shadows;  /* shadow polygons (owner: mapped face), sorted by owner */
  int *shadow_first;        /* per mapped face + 1: its shadows are [first[f], first[f+1]) */
  /* made once a frame for the shading of every point (fx_shade), when the model shades */
  bool count;               /* count the shading's work (the 1974 engine; the points
                               engine models no machine and counts nothing) */
  struct shade_lights lights;   /* the scene's lights made ready (render/shade.h) */
  double eye[3];            /* the Mapper's eye */
  double (*ray)[4];         /* per mapped face: its plane's a, b, c and the ray's numerator
                               -(a, b, c, d) . (eye, 1) (eq. (2), as space_point takes them) */
  /* Tests only: flat_sse2 makes the flat lit rows take their SSE2 code (flat_lit_pairs)
     where the processor has AVX-512 (effects/model.c, flat_rowt8). */
  bool flat_sse2;
  /* Tests only (false after a build): uv_sse2 makes a row's smoothed space points (and
     fx_space_uv) take their SSE2 way, two an instruction, where the processor has AVX-512F
     (not eight: model.c, uv_avx512). */
  bool uv_sse2;
};

/* Build the model the effects e call for over the frame engine eng drew on its grid eng->g
   (contour regions, shadows, textures, smoothing patches; tables in eng->core, work in
   cost). */
int fx_model_build(struct fx_model *m, const struct fx_engine *eng, const struct scene *s,
                   const struct effects *e, const uint8_t *bg,
                   struct fx_stats *st, struct cost *cost, struct t74_error *err);
void fx_model_free(struct fx_model *m);

/* Does the model change regions (a contour cut or shadows)? */
bool fx_model_regions(const struct fx_model *m);

/* Does the model shade point by point (smoothing, textures or shadows)? */
bool fx_model_shades(const struct fx_model *m);

/* The grey 0..255 of face (index in map->f; -1: the background of point (i, j)) at
   position (u, v) of the plane in point units (u across from the window's left, v down
   from its top), with the lights in blocked in shadow. *region (may be NULL): the
   smoothing region (smooth.h), -1 for a flat face. */
int fx_shade(const struct fx_model *m, int face, unsigned blocked, double u, double v,
             int i, int j, struct cost *cost, int *region);

/* The space points of face f (index in map->f) at n plane positions (px[p], py) of one
   row into X[p]: the ray from the eye onto the face's plane (eq. (2)), as fx_shade takes
   it at each; the same doubles for any n (a run of a smoothed face's points takes them
   two an instruction). */
void fx_space_points(const struct fx_model *m, int f, int n, const double *px, double py,
                     double (*X)[3]);

/* fx_space_points' coordinates u and (u + 1) % 3 (u 0, 1 or 2) of each point into xu[p] and
   xw[p], as fx_points takes them for a run of a smoothed face's points (two an instruction,
   only the two coordinates made): n even, px[] non-decreasing (as a row's point centres
   are). The same doubles as fx_space_points'. */
void fx_space_uv(const struct fx_model *m, int f, int n, const double *px, double py, int u,
                 double *xu, double *xw);

/* One visible stretch of a line after the region effects. */
struct fx_span {
  struct grat x0, x1;       /* [x0, x1), grid units */
  int piece, face;          /* the piece and face seen (-1, -1 never: gaps are left out) */
  unsigned blocked;         /* lights whose shadow covers the stretch (bit k: light k) */
};

struct fx_lines;

/* Lines of the model, asked in non-decreasing y like vis_spans: by the engine's
   stretches when it gives them (the 1974 engine) and by_samples is false, else sample by
   sample (the points engine; by_samples: the 1974 engine too, for the tests). */
int fx_lines_open(struct fx_lines **out, const struct fx_model *m, bool by_samples,
                  struct cost *cost, struct t74_error *err);
bool fx_lines_have_spans(const struct fx_lines *L);

/* The stretches of the line y = yn / yd (only when fx_lines_have_spans). */
int fx_lines_get(struct fx_lines *L, int64_t yn, int64_t yd, const struct fx_span **span,
                 int *nspan, struct t74_error *err);

/* The face seen (after the cuts) and the lights blocked at samples k0 .. k0 + n - 1 of
   row m of the lattice K times finer than the points (effects/see.h, fx_see_row). */
int fx_lines_samples(struct fx_lines *L, int K, int64_t m, int64_t k0, int n, int *face,
                     unsigned *blocked, struct t74_error *err);
void fx_lines_close(struct fx_lines *L);

/* The point frame: f->face (after the cut) and f->grey from the model at each point
   centre; f->face holds the Visible Surface Procedure's faces on entry. */
int fx_points(const struct fx_model *m, struct fx_frame *f, struct fx_stats *st,
              struct cost *cost, struct t74_error *err);

#endif
