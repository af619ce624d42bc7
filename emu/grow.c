/*
** grow.c — t74_grow's growth (grow.h).
*/
#include "emu/grow.h"

#include <stdint.h>
#include <stdlib.h>

bool t74_grow_to(void **buf, size_t *cap, size_t need, size_t size)
{
  if (need <= *cap) return true;
  if (size == 0 || need > SIZE_MAX / size) return false;
  size_t c = *cap ? *cap : 64;
  while (c < need) c = c > SIZE_MAX / 2 ? need : 2 * c;
  if (c > SIZE_MAX / size) c = need;           /* the doubling would not fit: just need */
  void *nb = realloc(*buf, c * size);
  if (!nb) return false;
  *buf = nb;
  *cap = c;
  return true;
}
