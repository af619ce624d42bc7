/*
** memrender.h — a scene rendered in memory, for the scene fuzz targets and test_import.
**
** This file declares the small harness the libFuzzer targets of the scene readers
** (tests/fuzz/fuzz_s74.c, fuzz_obj.c, fuzz_off.c) and tests/test_import.c share: write
** bytes to a temporary file, read it with scene_load as a given kind, render it through
** the library (render_prepare + render_scan: the Mapper to the Visible Surface Procedure)
** and keep the face number seen at every perspective-plane point, as `--dump ids` does.
** mr_check renders a scene twice, the second time with its face list and every ring
** reversed (ids unchanged): the picture of a scene must not depend on the order its faces
** and vertices are listed in.
*/
#ifndef TUBE74_TESTS_REF_MEMRENDER_H
#define TUBE74_TESTS_REF_MEMRENDER_H

#include <stddef.h>
#include <stdint.h>
#include "render/scene.h"

#define MR_CORE_WORDS (1u << 22)      /* generous: "does not fit" is not what is checked */

/* Write data to a fresh temporary folder as scene.SUFFIX (suffix "obj"); returns the
   malloc'd path, or NULL. mr_temp_remove deletes file and folder and frees the path. */
char *mr_temp_file(const uint8_t *data, size_t size, const char *suffix);
void mr_temp_remove(char *path);

/* Render s at cell 3 or 4: ids[W*H] (row 0 at the top) gets the visible face number, 0
   for none. Returns the renderer's status (T74_OK, or a status with err filled). */
int mr_render_ids(const struct scene *s, int cell, uint16_t *ids, struct t74_error *err);

/* Reverse the order of s's faces, and of every ring of every face, in place (ids,
   objects and everything else kept). */
void mr_reverse(struct scene *s);

/* Points where a and b (n entries) differ. */
long mr_diff(const uint16_t *a, const uint16_t *b, size_t n);

/* Read data as a scene of kind ("s74", "obj", "off"); when it is accepted, render it at
   `cell`, then reversed (mr_reverse), and compare. Returns 0 when all is as promised:
   refused with status 2 (bad input) or 4 and a message naming the file, or rendered (or
   refused by the renderer with status 2 or 3) the same both ways. Else 1, with the
   reason in why. *rendered (may be NULL) is set when a picture was made. */
int mr_check(const uint8_t *data, size_t size, const char *kind, int cell, int *rendered,
             char *why, size_t whylen);

/* Read data as a scene of kind: scene_load's status, *out set when T74_OK. */
int mr_load_bytes(const uint8_t *data, size_t size, const char *kind, struct scene **out);

/* 1 when a and b render alike at cell (same status, and the same face at every point). */
int mr_same_picture(const struct scene *a, const struct scene *b, int cell);

/* The .obj text with the vertex references of every `f` / `fo` line in reverse order
   (the line kept where it is, its comment dropped; lines split as the reader splits
   them: LF, CR LF, CR). malloc'd, length in *outn; NULL when out of memory. */
uint8_t *mr_obj_reverse_rings(const uint8_t *data, size_t size, size_t *outn);

/* The same for .off: every face line's vertex indices in reverse order (its count and
   any colour after them kept; lines of more than 63 tokens, and everything after a line
   this reading does not understand, left as they are). */
uint8_t *mr_off_reverse_rings(const uint8_t *data, size_t size, size_t *outn);

#endif
