/*
** import.h — reading text input files, and Wavefront .obj / .off import (internal to the
** scene module: only render/scene.c includes this).
**
** Paper reference: the 1974 system took its vertices as integers typed in (paper 003
** §2.1); tube74 keeps that integer grid and maps polygon meshes onto it, so everything the
** renderer sees downstream is exact. Contract: shared/CONTRACT.md, "Scene files".
**
** The line reader (import_reader) is shared with the .s74 parser: it reads the whole
** file, refuses NUL bytes and files over IMPORT_FILE_MAX bytes, skips a UTF-8 byte order
** mark at the start, ends lines at LF, CR LF or a lone CR, strips `#` comments, and splits
** each line into blank-separated tokens (NUL-terminated, in place). Blank lines are
** skipped.
**
** Grid mapping of an import (documented in README "Scene files"):
**   the model's bounding box (all vertices) is scaled uniformly so that its largest side is
**   IMPORT_EXTENT units; x and y are centred on 0 (so |x|, |y| <= IMPORT_EXTENT/2); the
**   .obj/.off z axis is negated (right-handed mesh, eye looking along +z here, so the
**   default view shows what a usual mesh viewer at +z shows, not a mirror image) and
**   shifted so that the nearest point has z = 0; coordinates are rounded to nearest.
**   Default eye: (0, 0, -2.5 * IMPORT_EXTENT). Default window: the projection of the
**   bounding box on z = 0, grown to 4:3 around its centre, plus 5% margin on every side.
** Faces: numbered 1, 2, ... in file order (what --dump ids shows, while they fit its 16
** bits), any count up to IMPORT_COUNT_MAX; fewer than 3 vertices,
** or edges crossing in the file, are refused; one not planar once rounded is split by
** exact ear clipping (every triangle keeps the face's number), see import.c.
*/
#ifndef T74_IMPORT_H
#define T74_IMPORT_H

#include <stddef.h>
#include "emu/status.h"
#include "render/scene.h"

#define IMPORT_FILE_MAX ((size_t)1 << 30)  /* larger input files are refused */
/* Most vertices, faces (and vertices of one face) an import may have: more than a file
   of IMPORT_FILE_MAX bytes can hold (a vertex or face line takes at least 6 bytes), so
   only an absurd .off header count meets it; below it the count is limited by memory
   alone. Face and vertex numbers are 32-bit inside the renderer (docs/scale.md); a .s74
   file keeps ids 1..65535 (SCENE_ID_MAX). */
#define IMPORT_COUNT_MAX 200000000L
#define IMPORT_EXTENT   12800              /* largest bounding-box side after mapping;
                                              2.5x of it (32000) still fits an eye z */

struct import_reader {
  const char *file;     /* name for messages */
  char   *buf;          /* whole file, NUL-terminated; tokens point into it */
  size_t  len, pos;
  int     line;         /* line number of the tokens now held (1-based) */
  int     nlines;       /* lines seen so far (the last line number at the end) */
  char  **tok;          /* tokens of the current line */
  int     ntok, cap;
};

/* Read the whole file. T74_EIO "FILE: cannot read: reason" when it cannot be read. */
int import_open(struct import_reader *r, const char *path, struct t74_error *err);

/* Next line that holds tokens: returns 1 with r->tok / r->ntok / r->line set, 0 at the end
   of the file, or an error status (NUL byte, out of memory) recorded in err. */
int import_next(struct import_reader *r, struct t74_error *err);

void import_close(struct import_reader *r);

/* A token as it may be echoed in a message: printable, at most ~40 bytes. */
const char *import_show(const char *tok, char *buf, size_t n);

/* qsort for the per-face checks: cmp must be a total order (ties broken by a unique
   index), so the result is the one qsort gives; a few elements (most faces: 3 to 16) are
   sorted by insertion, without qsort's set-up and calls (issue 12: qsort was 15% of an
   import of 100,000 faces). Elements of at most 64 bytes. */
void import_sort(void *base, size_t n, size_t size, int (*cmp)(const void *, const void *));

/* Parse a whole-token decimal integer (optional sign). Returns 0 and sets *out when it
   is one inside lo..hi, 1 when it is not an integer, 2 when it is out of range. */
int import_int(const char *tok, long lo, long hi, long *out);

/* A finite floating-point number filling the whole token, as strtod reads it (plain
   decimals of up to 15 significant digits without strtod, giving the same double). */
bool import_real(const char *tok, double *out);

/* (double)lround(x), the grid's rounding (halves away from zero), without the libm call
   where |x| < 2^52 (issue 19: lround was 2% of an import of 100,000 faces). */
double import_round(double x);

/* Import a .obj (kind "obj") or .off (kind "off") file onto the integer grid. */
int import_load(const char *path, const char *kind, const struct scene_opts *opts,
                struct scene **out, struct t74_error *err);

#endif
