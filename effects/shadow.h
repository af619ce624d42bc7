/*
** shadow.h — shadows (paper 000 §3, Nishita & Nakamae): the polygons the scene's lights
** cast on the faces, extracted before the scan (§3.1 step (3)), as polygons lying on the
** faces they fall on.
**
** For every face R shaded from the lights, every light k that reaches R's seen side and
** every other face A of the scene (its holes let light through): the part of A between
** the light and R's plane is projected through the light onto R's plane (a point light:
** centrally from its position; a parallel light: along its direction), clipped to R's box
** in space, and mapped onto the perspective plane by eq. (1). Each vertex is computed in
** extended precision from the exact integer data and rounded once onto the plane grid;
** from there the shadow IS that grid polygon (effects/poly.h) and every decision is exact:
** a point of R is in light k's shadow when a shadow polygon of light k on R covers it.
** The clipping to the box keeps far-flung projections on the grid and changes nothing on
** R itself (R lies inside its box).
**
** Faces with a `grey` of their own are not lit by the lights, and get no shadows. Faces
** coplanar with R (R's patterns, R's own face) cast none on it.
*/
#ifndef T74_SHADOW_H
#define T74_SHADOW_H

#include "effects/fx.h"
#include "effects/poly.h"

/* The shadow polygons of scene s on its Mapper's faces map (owner: the mapped face,
   light: the light), appended to out. Counted in cost (NULL: not counted, the points
   engine, which models no machine); statistics shadow_polygons and
   shadow_receivers into st.
   keep (may be NULL; used only when cost is NULL): what depends on the scene and its
   lights alone, kept from one frame of s to the next (issue 19, --frames): each face's
   shadows in space, clipped once; a frame does only the view's part (onto the perspective
   plane and the grid), with the same long double operations on the same values, so the
   polygons are the same, in the same order. *keep is made on first use (or remade for
   another scene); the caller frees it with shadow_keep_free. */
struct shadow_keep;
int shadow_build(const struct mapped *map, const struct scene *s, struct shadow_keep **keep,
                 struct fx_polys *out, struct fx_stats *st, struct cost *cost,
                 struct t74_error *err);
void shadow_keep_free(struct shadow_keep *k);    /* NULL: nothing */
/* Tests only: the keep's frames take each face's shadow vertices onto the grid with SSE2's
   code (on) where the processor has AVX-512 (effects/shadow.c, grid_all4); NULL: nothing. */
void shadow_keep_sse2(struct shadow_keep *k, bool on);

/* A shadow vertex onto the grid, a frame's step for each kept vertex (exposed for
   test_shadow). The eye E (world units) as the projection uses it: set once a frame. */
struct shadow_eye {
  long double E[3];
  double e[3];              /* the same integers */
  bool near;                /* |E[c]| < 2^40: e exact, the filter usable */
};
void shadow_eye_set(struct shadow_eye *v, const int64_t E[3]);

/* Vertex Y in space (on the receiving face's plane) seen from the eye by eq. (1),
   Y' = E + (-E_z) (Y - E) / (Y_z - E_z), in long double, times GRID_ONE and rounded half
   away from zero onto the grid: true and *g, or false when Y is not before the eye or a
   coordinate lies past GRID_LIMIT (the vertex dropped). */
bool shadow_grid_ld(const struct shadow_eye *v, const long double Y[3], struct gpoint *g);

/* Y's nearest doubles yd for shadow_grid_near (NaN, which it declines, where Y is not 0
   and not a normal double's size, 2^-1000 <= |Y| < 2^1000). */
void shadow_near(const long double Y[3], double yd[3]);

/* shadow_grid_ld's answer from yd, in doubles, with a bound on how far its value and
   shadow_grid_ld's lie apart (the proof is in shadow.c): 1 and *g (shadow_grid_ld's
   point) when every grid point within the bound rounds to the same, -1 (undecided) when
   not, or when the vertex might be dropped. */
int shadow_grid_near(const struct shadow_eye *v, const double yd[3], struct gpoint *g);

/* The extent of a set of vertices' nearest doubles yd (shadow_near), for a bound that
   holds for all of them: ax[c] >= |yd[c]| (c = x, y), zlo <= yd[2] <= zhi; ok false when
   one of them is NaN (then no bound is made). Start from shadow_span_init. */
struct shadow_span { double ax[2], zlo, zhi; bool ok; };
void shadow_span_init(struct shadow_span *sp);
void shadow_span_add(struct shadow_span *sp, const double yd[3]);

/* A frame's bound for the vertices within span sp seen from eye v, for
   shadow_grid_spanned: B[c] not below shadow_grid_near's bound for coordinate c at any
   of them (the proof is in shadow.c). false when there is none (v not near, sp not ok,
   or a vertex in sp might lie at or behind the eye): then the caller takes
   shadow_grid_near, vertex by vertex. */
struct shadow_bound { double B[2]; };
bool shadow_bound_set(struct shadow_bound *b, const struct shadow_eye *v,
                      const struct shadow_span *sp);

/* shadow_grid_near's answer for a vertex yd within the span b was made for, with b's
   bound in place of its own: 1 and *g (shadow_grid_ld's point, and shadow_grid_near's)
   when it decides, -1 when not (then shadow_grid_near may still decide). */
int shadow_grid_spanned(const struct shadow_eye *v, const struct shadow_bound *b,
                        const double yd[3], struct gpoint *g);

#endif
