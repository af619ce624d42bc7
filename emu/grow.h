/*
** grow.h — the room of a growable array, in one place.
**
** A module that keeps a scratch array across calls (a row's spans, a frame's boxes) asks
** for room before it writes: t74_grow(&a, &cap, need, sizeof *a). The room is doubled
** from *cap (64 when it is 0) until it holds `need` elements, the contents kept (realloc),
** so n appends cost O(n) copies in all. The test against *cap is inline (it runs once a
** face or a row on the hot paths); the growth is out of line.
*/
#ifndef T74_GROW_H
#define T74_GROW_H

#include <stdbool.h>
#include <stddef.h>

/* The growth of t74_grow: false, *buf and *cap left as they were, when the host has no
   memory or need * size does not fit a size_t. */
bool t74_grow_to(void **buf, size_t *cap, size_t need, size_t size);

/* Make *buf (elements of `size` bytes, *cap of them) hold at least `need` elements. */
static inline bool t74_grow(void **buf, size_t *cap, size_t need, size_t size)
{
  return need <= *cap || t74_grow_to(buf, cap, need, size);
}

#endif
