/*
** shade.c — Lambert's law over the scene's lights (see shade.h).
*/
#include "render/shade.h"

#include <math.h>

void shade_dir(const struct scene *s, int k, const double at[3], double l[3])
{
  const struct scene_light *L = &s->light[k];
  for (int c = 0; c < 3; c++) l[c] = L->point ? L->v[c] - at[c] : L->v[c];
  double n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  if (n > 0) for (int c = 0; c < 3; c++) l[c] /= n;
}

int shade_grey(const struct scene *s, const double n[3], const double at[3], double r,
               unsigned blocked)
{
  double sum = 0;
  for (int k = 0; k < s->nlight; k++) {
    if (blocked >> k & 1u) continue;
    double l[3];
    shade_dir(s, k, at, l);
    double d = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    if (d > 0) sum += d;
  }
  double g = SHADE_AMBIENT + floor((255 - SHADE_AMBIENT) * r * sum + 0.5);
  return g > 255 ? 255 : (int)g;
}
