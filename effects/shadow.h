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

#endif
