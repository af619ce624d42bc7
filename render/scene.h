/*
** scene.h — scene input: the data typed into the 1974 system (paper 003 §2.1).
**
** This file declares the scene as the renderer receives it: vertices with integer
** coordinates, faces as rings of vertex indices (outer boundary first, then one ring per
** hole, the paper's "*"), objects, the eye, the window, and the optional light,
** background picture and effects line. It is read from a .s74 file (shared/CONTRACT.md)
** or imported from Wavefront .obj / .off onto the same integer grid.
**
** Everything a scene promises is checked here, exactly, in integers, before the Mapper
** runs: ids, ranges, at least 3 distinct vertices, non-zero area, exact coplanarity,
** simple (non-self-intersecting) rings, holes inside their face, eye on the negative side.
** A failure is reported as "FILE:LINE: message" with status T74_EINPUT.
*/
#ifndef T74_SCENE_H
#define T74_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "emu/status.h"
#include "render/pool.h"

#define SCENE_COORD_MIN (-32768)
#define SCENE_COORD_MAX 32767
#define SCENE_ID_MAX    65535

struct scene_vertex {
  uint32_t id;            /* 1..65535 as written in .s74; imports: 1..nv */
  int32_t  x, y, z;       /* -32768..32767 */
  int      line;          /* source line (for messages) */
};

struct scene_face {       /* the ints first, the pointers last: 56 bytes, no padding
                             (an import of 100,000 boxes holds 166,848 of them) */
  uint32_t id;            /* .s74: 1..65535; imports: 1..faces in the file (any count
                             that fits memory, docs/scale.md): the number --dump ids
                             reports (refused there above 65535). Unique in a .s74
                             scene; the triangles an import splits a face into all keep
                             that face's id (its input number) */
  int      line;          /* source line */
  uint32_t on_id;         /* `on F`: the number F of the face this pattern lies on (paper
                             000 §3: drawn over F whatever the numbering); 0: none */
  int      on;            /* when on_id: F's index in scene.f */
  int      texture_line;  /* the `texture` line's source line */
  int      object;        /* object id it belongs to, 0 if none */
  int      nring;         /* 1 + number of holes */
  int16_t  grey;          /* 0..255, or -1 when not given (shaded from `light`, else 255) */
  bool     pooled;        /* ring_start and vidx live in the scene's pool (imports:
                             scene_pool_ints), freed with the scene, not one by one */
  char    *texture;       /* `texture F FILE`: the reflectance picture's path (resolved
                             against the scene's folder), or NULL */
  int     *ring_start;    /* nring + 1 offsets into vidx: ring r is vidx[ring_start[r] ..
                             ring_start[r+1]) ; ring 0 is the outer boundary */
  int     *vidx;          /* indices into scene.v (not ids); consecutive duplicates removed */
};

struct scene_object {
  uint32_t id;
  int      line;
  int      nface;
  int     *face;          /* indices into scene.f */
  bool     smooth;        /* `smooth`: a smoothing group (paper 002 §3.2, e'1): its shared
                             edges are not drawn by enhanced edges, its silhouette is */
};

/* A light (CONTRACT.md `light DX DY DZ`, `light point X Y Z`; several add up). */
struct scene_light {
  bool    point;          /* a point light at v; else a parallel light towards v */
  int32_t v[3];           /* direction towards the light (not all zero), or position */
  int     line;           /* source line (0: an import's default light) */
};

#define SCENE_LIGHT_MAX 16     /* lights a scene may have */

struct scene {
  char   *file;                     /* path as given, for messages */
  int     nv, nf, nobj;
  struct scene_vertex *v;
  struct scene_face   *f;
  struct scene_object *obj;
  bool    has_view, has_window, has_light;
  int32_t view[3];                  /* X0 Y0 Z0: eye; Z0 < 0 and every vertex z > Z0 */
  int32_t window[4];                /* XL YB XR YT on the plane z = 0; XL < XR, YB < YT */
  int     nlight;                   /* lights given (has_light: nlight > 0) */
  struct scene_light light[SCENE_LIGHT_MAX];
  char   *background;               /* PGM path resolved against the scene's folder, or NULL */
  int     background_line;          /* its source line (0: none) */
  char   *effects;                  /* the effects line's KEY=VALUE text, or NULL */
  int     effects_line;             /* its source line */
  int     warnings;                 /* how many warnings were printed (imports) */
  struct pool pool;                 /* host blocks holding pooled faces' arrays (issue 12:
                                       two mallocs a face fewer), freed by scene_free */
};

/* Options for reading: camera for .obj/.off imports (ignored for .s74 unless given). */
struct scene_opts {
  bool    has_view, has_window;
  int32_t view[3];
  int32_t window[4];
  const char *input;                /* "s74", "obj", "off" or NULL to decide by extension */
  bool    has_turn;                 /* --turn AZ,EL given (imports only; render/turn.h) */
  double  turn[2];                  /* AZ, EL in degrees */
  bool    quiet;                    /* import warnings counted (scene.warnings), not
                                       printed: for a second read of one file */
};

/* The kind of scene a path is read as: opts->input when given (--input), else "obj" or
   "off" by the extension (any case), else "s74". */
const char *scene_kind(const char *path, const struct scene_opts *opts);

/* Read and check a scene. On failure returns T74_EINPUT (or T74_EIO when the file cannot
   be read), fills err, and *out is NULL. Warnings go to stderr as FILE:LINE: warning: ...
   (not when opts->quiet). */
int scene_load(const char *path, const struct scene_opts *opts, struct scene **out,
               struct t74_error *err);

void scene_free(struct scene *s);

/* n ints (n >= 1) from the scene's pool, for a face's arrays (the face is then marked
   pooled); they live until scene_free. NULL when the host is out of memory. */
int *scene_pool_ints(struct scene *s, size_t n);

/* What is wrong with a face's geometry (scene_check_face). */
enum scene_defect {
  SCENE_FACE_OK = 0,
  SCENE_FACE_DEGENERATE,    /* two vertices of a ring at one position, or zero area */
  SCENE_FACE_NONPLANAR,     /* not exactly coplanar */
  SCENE_FACE_NONSIMPLE,     /* edges cross, touch or overlap */
  SCENE_FACE_HOLE           /* a hole outside its face, or inside / over another hole */
};

/* Check one face's geometry exactly, in integers. Precondition: f->vidx are valid
   indices into s->v (a ring of fewer than 3 entries is reported as degenerate, a vertex
   or position repeated inside a ring as not simple; a zero-length edge as degenerate).
   Returns an enum scene_defect; when not SCENE_FACE_OK, records
   "FILE:LINE: face N ..." (T74_EINPUT, at f->line) in err. Returns -1 when out of
   memory (T74_EIO recorded). err may be NULL: the verdict alone, no message made (an
   import tests every face it rounds; at 100,000 boxes the messages it threw away were
   a fifth of the whole process). */
int scene_check_face(const struct scene *s, const struct scene_face *f,
                     struct t74_error *err);

/* Check the camera: view Z0 < 0, window XL < XR and YB < YT, every value in
   SCENE_COORD_MIN..MAX, and every vertex used by a face strictly in front of the eye
   (z > Z0; reported at the vertex's line). view_line/window_line are where they were
   given (0: from options, reported as --view / --window). */
int scene_check_camera(const struct scene *s, int view_line, int window_line,
                       struct t74_error *err);

#endif
