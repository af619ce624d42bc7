/*
** pool.c — host memory handed out from a chain of large blocks (pool.h).
**
** This file contains code to keep a pool as a chain of blocks, the newest first, each
** handed out from its start; a request that does not fit the newest block takes a spare
** block when one is large enough, else a new one (of its own size when larger than
** POOL_BLOCK_BYTES). Nothing is given back before pool_reset or pool_free.
*/
#include "render/pool.h"

#include <stdint.h>
#include <stdlib.h>

struct pool_block {
  struct pool_block *next;
  size_t cap;                          /* bytes of data there are */
  max_align_t data[];
};

#define POOL_BLOCK_BYTES ((size_t)1 << 20)

void *pool_alloc_block(struct pool *p, size_t bytes)
{
  struct pool_block **s = &p->spare;
  while (*s && (*s)->cap < bytes) s = &(*s)->next;
  struct pool_block *nb = *s;
  if (nb) {
    *s = nb->next;                     /* a spare block, used again */
  } else {
    size_t cap = bytes > POOL_BLOCK_BYTES ? bytes : POOL_BLOCK_BYTES;
    if (cap > SIZE_MAX - sizeof *nb) return NULL;
    nb = malloc(sizeof *nb + cap);
    if (!nb) return NULL;
    nb->cap = cap;
  }
  nb->next = p->used;
  p->used = nb;
  p->at = (char *)nb->data + bytes;
  p->end = (char *)nb->data + nb->cap;
  return nb->data;
}

void pool_reset(struct pool *p)
{
  p->at = p->end = NULL;
  while (p->used) {
    struct pool_block *b = p->used;
    p->used = b->next;
    b->next = p->spare;
    p->spare = b;
  }
}

void pool_free(struct pool *p)
{
  pool_reset(p);
  for (struct pool_block *b = p->spare, *nx; b; b = nx) {
    nx = b->next;
    free(b);
  }
  p->spare = NULL;
}
