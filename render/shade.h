/*
** shade.h — a face's intensity from the scene's lights (Lambert's law with an ambient
** floor; paper 003 reads intensities from its input, paper 000 §3.3 (1) makes a polygon's
** colour I(S) its reflectance times its illumination, from several lights).
**
** This file declares the one shading law every stage uses: the Mapper for a face's flat
** grey, the effects (effects/) for the intensity at a point of a face (smooth shading's
** interpolated normals, a texture's reflectance, the lights a shadow blocks).
**
**   grey = AMBIENT + (255 - AMBIENT) * r * sum over the lights k not blocked of max(0, n.l_k)
**
** clamped to 255 and rounded to nearest, with n the unit normal on the eye's side, l_k
** the unit direction towards light k (a parallel light's own direction; a point light's
** from the shaded point), r the reflectance 0..1 (1 without a texture). The ambient floor
** is what a face turned away from every light (or in every light's shadow) shows; it is
** not scaled by r, so a texture's dark parts stay visible as the ambient grey (the tube
** cannot go below it for a lit face). With one parallel light and r = 1 this is exactly
** the Mapper's integer law (render/mapper.c), which it keeps for that case.
*/
#ifndef T74_SHADE_H
#define T74_SHADE_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include "render/scene.h"

#define SHADE_AMBIENT 48            /* the grey of a face no light reaches (tuned by eye) */

/* The unit direction from space point at towards light k of s. */
void shade_dir(const struct scene *s, int k, const double at[3], double l[3]);

/* Grey at space point at with unit normal n (on the eye's side) and reflectance r; the
   lights whose bit is set in blocked (bit k: light k) are in shadow there. */
int shade_grey(const struct scene *s, const double n[3], const double at[3], double r,
               unsigned blocked);

/* The scene's lights made ready for shading many points (the effects' per-point work):
   a parallel light's unit direction found once (shade_dir's, the same doubles), a point
   light's position as doubles. */
struct shade_lights {
  int n;
  bool point[SCENE_LIGHT_MAX];
  double v[SCENE_LIGHT_MAX][3];     /* unit direction (parallel) or position (point) */
};
void shade_lights_init(struct shade_lights *L, const struct scene *s);

/* The unit direction from at towards a point light at v (shade_dir's). */
void shade_point_dir(const double v[3], const double at[3], double l[3]);

/* The grey of reflectance r under the lights' sum of n.l (shade_grey_lit's last step). */
static inline int shade_grey_of_sum(double r, double sum)
{
  /* floor of a non-negative double below 2^62 is its truncation: no library call */
  double f = (255 - SHADE_AMBIENT) * r * sum + 0.5;
  double g = SHADE_AMBIENT + (f >= 0 && f < 0x1p62 ? (double)(int64_t)f : floor(f));
  return g > 255 ? 255 : (int)g;
}

/* shade_grey with the lights made ready: the same value, bit for bit. Inline: the effects
   call it at every shaded point. */
static inline int shade_grey_lit(const struct shade_lights *L, const double n[3],
                                 const double at[3], double r, unsigned blocked)
{
  double sum = 0;
  for (int k = 0; k < L->n; k++) {
    if (blocked >> k & 1u) continue;
    const double *l = L->v[k];
    double pl[3];
    if (L->point[k]) {
      shade_point_dir(l, at, pl);
      l = pl;
    }
    double d = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    if (d > 0) sum += d;
  }
  return shade_grey_of_sum(r, sum);
}

/* shade_grey_lit at np <= SHADE_RUN points at[p] that share the unit normal n (a flat
   face's), with reflectance r[p] and the lights blocked[p]: the same greys, bit for bit
   (each point's own operations on its own values, in its own order), found together: a
   parallel light's n.l once for all of them, a point light's directions with two points'
   square roots and divides an instruction (SSE2's are correctly rounded, as the scalar
   ones are). */
#define SHADE_RUN 16
void shade_grey_lit_run(const struct shade_lights *L, const double n[3], int np,
                        const double (*at)[3], const double *r, const unsigned *blocked,
                        int *grey);

#endif
