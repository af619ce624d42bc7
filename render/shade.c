/*
** shade.c — Lambert's law over the scene's lights (see shade.h).
*/
#include "render/shade.h"

#include <math.h>
#include <stdint.h>

/* Normalise l (shade_dir's last step). */
static void unit_dir(double l[3])
{
  double n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  if (n > 0) for (int c = 0; c < 3; c++) l[c] /= n;
}

void shade_dir(const struct scene *s, int k, const double at[3], double l[3])
{
  const struct scene_light *L = &s->light[k];
  for (int c = 0; c < 3; c++) l[c] = L->point ? L->v[c] - at[c] : L->v[c];
  unit_dir(l);
}

void shade_lights_init(struct shade_lights *L, const struct scene *s)
{
  L->n = s->nlight;
  for (int k = 0; k < s->nlight; k++) {
    L->point[k] = s->light[k].point;
    for (int c = 0; c < 3; c++) L->v[k][c] = s->light[k].v[c];
    if (!L->point[k]) unit_dir(L->v[k]);
  }
}

void shade_point_dir(const double v[3], const double at[3], double l[3])
{
  for (int c = 0; c < 3; c++) l[c] = v[c] - at[c];
  unit_dir(l);
}

int shade_grey(const struct scene *s, const double n[3], const double at[3], double r,
               unsigned blocked)
{
  struct shade_lights L;
  shade_lights_init(&L, s);
  return shade_grey_lit(&L, n, at, r, blocked);
}
