/*
** pool.h — host memory handed out from a chain of large blocks and freed all at once.
**
** For the many small arrays that live and die together: an imported scene's faces, the
** Mapper's faces, the pieces' lines and vertices. One malloc a megabyte instead of one an
** array, and one free a megabyte at the end (issues 12, 19). A pool emptied by pool_reset
** keeps its blocks for what is allocated next (the frames of --frames: memory already
** touched, not given back to the system and faulted in again). Host memory only: the 1974
** program's tables are in the core model (emu/core.h).
*/
#ifndef T74_POOL_H
#define T74_POOL_H

#include <stddef.h>
#include <stdint.h>

struct pool_block;
struct pool {
  struct pool_block *used;             /* blocks handed out from, the newest first */
  struct pool_block *spare;            /* blocks kept by pool_reset, to be handed out again */
  char *at, *end;                      /* the newest block's bytes not handed out (NULL:
                                          no block) */
};                                     /* all zero: an empty pool */

/* pool_alloc from a new block (a spare one, or one from the host): its data start at
   max_align_t, so at any alignment pool_alloc takes. */
void *pool_alloc_block(struct pool *p, size_t bytes);

/* `bytes` bytes at a multiple of `align` (a power of two, at most _Alignof(max_align_t));
   they live until pool_reset or pool_free. NULL when the host is out of memory. (Inline:
   one a face of the Mapper's every frame, issue 19.) */
static inline void *pool_alloc(struct pool *p, size_t bytes, size_t align)
{
  if (p->at) {
    uintptr_t a = ((uintptr_t)p->at + (align - 1)) & ~(uintptr_t)(align - 1);
    if (a <= (uintptr_t)p->end && (uintptr_t)p->end - a >= bytes) {
      p->at = (char *)a + bytes;
      return (char *)a;
    }
  }
  return pool_alloc_block(p, bytes);
}

/* Everything handed out is given back; the blocks are kept for later pool_alloc. */
void pool_reset(struct pool *p);

/* Free every block; the pool is empty. */
void pool_free(struct pool *p);

#endif
