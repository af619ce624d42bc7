/*
** turn.c — turning an imported mesh for its view (see turn.h): the pose an .obj/.off
** model is drawn in, applied on import, before the vertices are rounded to the grid and
** long before paper 003's Mapper.
**
** This file contains code to parse `--turn AZ,EL` and to rotate a mesh's floating-point
** vertices about the centre of its bounding box. Floating point is right here: the turn
** prepares input as the import's scaling does, and the renderer's exact arithmetic starts
** from the rounded integer vertices the import makes afterwards.
*/
#include "render/turn.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

#define TURN_PI 3.14159265358979323846    /* M_PI is not in strict C11 */

int turn_parse(const char *s, double *az, double *el)
{
  char *end;
  errno = 0;
  double a = strtod(s, &end);
  if (end == s || *end != ',' || errno) return -1;
  const char *t = end + 1;
  double e = strtod(t, &end);
  if (end == t || *end != 0 || errno) return -1;
  if (!isfinite(a) || !isfinite(e) || fabs(a) > TURN_LIMIT || fabs(e) > TURN_LIMIT) return -1;
  *az = a;
  *el = e;
  return 0;
}

void turn_apply(double *xyz, int nv, double az, double el)
{
  if (nv <= 0 || (az == 0 && el == 0)) return;
  double lo[3], hi[3];
  for (int a = 0; a < 3; a++) lo[a] = hi[a] = xyz[a];
  for (int v = 1; v < nv; v++)
    for (int a = 0; a < 3; a++) {
      double c = xyz[3 * v + a];
      if (c < lo[a]) lo[a] = c;
      if (c > hi[a]) hi[a] = c;
    }
  double c[3] = { (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2 };
  double ca = cos(az * TURN_PI / 180), sa = sin(az * TURN_PI / 180);
  double ce = cos(el * TURN_PI / 180), se = sin(el * TURN_PI / 180);
  for (int v = 0; v < nv; v++) {
    double *p = xyz + 3 * v;
    double x = p[0] - c[0], y = p[1] - c[1], z = p[2] - c[2];
    /* Ry(-AZ): the eye's bearing AZ comes round to +z */
    double x1 = x * ca - z * sa, z1 = x * sa + z * ca;
    /* Rx(EL): the eye's height EL comes down to +z */
    double y2 = y * ce - z1 * se, z2 = y * se + z1 * ce;
    p[0] = c[0] + x1;
    p[1] = c[1] + y2;
    p[2] = c[2] + z2;
  }
}

void turn_import(double *xyz, int nv, const struct scene_opts *opts)
{
  if (opts && opts->has_turn) turn_apply(xyz, nv, opts->turn[0], opts->turn[1]);
  else turn_apply(xyz, nv, TURN_DEFAULT_AZ, TURN_DEFAULT_EL);
}
