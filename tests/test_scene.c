/*
** test_scene.c — cmocka tests of scene input: the .s74 parser and its exact checks,
** .obj / .off import onto the integer grid, and the effects line.
**
** Paper reference: paper 003 §2.1 (the scene data of the 1974 system); the rules tested
** are those of shared/CONTRACT.md "Scene files", "Effects" and "Exit status".
**
** This file contains code to provoke every error the scene module reports and to check
** the structures it builds from valid input. Each error comes from a small scene written
** into a temporary folder at test time; the test checks the status (2, or 4 for I/O) and
** that the message starts with exactly "FILE:LINE: " and names the problem. Valid inputs
** come from tests/data/scene/ (run from the repository root), checked field by field.
** Random garbage and corrupted scenes check that no input crashes the reader.
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "emu/status.h"
#include "render/effects.h"
#include "render/scene.h"

#define DATA "tests/data/scene/"

/* ---- fixture: a temporary folder for generated scenes -------------------------------- */

struct fx { char dir[64]; char path[256]; };

static int group_setup(void **state)
{
  struct fx *f = calloc(1, sizeof *f);
  if (!f) return -1;
  strcpy(f->dir, "/tmp/t74sceneXXXXXX");
  if (!mkdtemp(f->dir)) { free(f); return -1; }
  *state = f;
  return 0;
}

static int group_teardown(void **state)
{
  struct fx *f = *state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
  if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", f->dir);
  free(f);
  return 0;
}

/* Write len bytes of text to DIR/name; the path is left in f->path. */
static void write_file(struct fx *f, const char *name, const char *text, size_t len)
{
  snprintf(f->path, sizeof f->path, "%s/%s", f->dir, name);
  FILE *fp = fopen(f->path, "wb");
  assert_non_null(fp);
  assert_int_equal(fwrite(text, 1, len, fp), len);
  assert_int_equal(fclose(fp), 0);
}

/* Load DIR/name holding text; returns the status, err keeps the message. */
static int load_text(struct fx *f, const char *name, const char *text, struct scene **s,
                     struct t74_error *err)
{
  write_file(f, name, text, strlen(text));
  memset(err, 0, sizeof *err);
  return scene_load(f->path, NULL, s, err);
}

/* The scene text must fail with status 2 at `line`, the message naming `what`. */
static void expect_error(void **state, const char *name, const char *text, int line,
                         const char *what)
{
  struct fx *f = *state;
  struct scene *s = (struct scene *)1;
  struct t74_error err;
  int st = load_text(f, name, text, &s, &err);
  char prefix[300];
  snprintf(prefix, sizeof prefix, "%s:%d: ", f->path, line);
  if (st != T74_EINPUT || strncmp(err.msg, prefix, strlen(prefix)) != 0 ||
      !strstr(err.msg, what))
    fail_msg("%s: status %d, message \"%s\"; wanted 2, \"%s...%s\"", name, st, err.msg,
             prefix, what);
  assert_int_equal(err.status, T74_EINPUT);
  assert_null(s);
}

/* The scene text must load; returns it (caller frees). */
static struct scene *expect_ok(void **state, const char *name, const char *text)
{
  struct fx *f = *state;
  struct scene *s = NULL;
  struct t74_error err;
  int st = load_text(f, name, text, &s, &err);
  if (st != T74_OK) fail_msg("%s: status %d: %s", name, st, err.msg);
  assert_non_null(s);
  return s;
}

/* ---- every .s74 error ------------------------------------------------------------------ */

/* Lines 1-6 of most generated scenes; a case's own lines start at line 7. */
#define BASE                                                                              \
  "view 0 0 -1000\n"                                                                      \
  "window -100 -100 200 200\n"                                                            \
  "vertex 1 0 0 10\n"                                                                     \
  "vertex 2 100 0 10\n"                                                                   \
  "vertex 3 100 100 10\n"                                                                 \
  "vertex 4 0 100 10\n"

/* A square 0..100 at z = 10 with hole vertices 5.. around it (lines 1-13). */
#define HOLES                                                                             \
  BASE                                                                                    \
  "vertex 5 10 10 10\n"                                                                   \
  "vertex 6 50 10 10\n"                                                                   \
  "vertex 7 10 50 10\n"                                                                   \
  "vertex 8 150 10 10\n"                                                                  \
  "vertex 9 50 50 10\n"                                                                   \
  "vertex 10 20 20 10\n"                                                                  \
  "vertex 11 30 20 10\n"

#define ERROR_CASES(X)                                                                     \
  X(unknown_statement, BASE "vertx 5 1 2 3\n", 7, "unknown statement `vertx`")             \
  X(unknown_statement_case, BASE "Vertex 5 1 2 3\n", 7, "unknown statement")               \
  X(bad_number_junk, BASE "vertex 5 1 2 12x\n", 7, "bad number `12x`")                     \
  X(bad_number_decimal, BASE "vertex 5 1.5 2 3\n", 7, "bad number `1.5`")                  \
  X(bad_number_sign_only, BASE "vertex 5 - 2 3\n", 7, "bad number `-`")                    \
  X(bad_number_hex, BASE "vertex 5 0x10 2 3\n", 7, "bad number")                           \
  X(bad_number_face_vertex, BASE "face 1 1 2 3a\n", 7, "bad number `3a`")                  \
  X(bad_number_view, "view 0 0 -1e3\n", 1, "bad number")                                   \
  X(count_vertex_short, BASE "vertex 5 1 2\n", 7, "wrong number of values")                \
  X(count_vertex_long, BASE "vertex 5 1 2 3 4\n", 7, "wrong number of values")             \
  X(count_view, "view 0 0\n", 1, "wrong number of values")                                 \
  X(count_window, "view 0 0 -10\nwindow 0 0 1\n", 2, "wrong number of values")             \
  X(count_light, BASE "light 1 2\n", 7, "wrong number of values")                          \
  X(count_background, BASE "background a b\n", 7, "wrong number of values")               \
  X(count_face, BASE "face 3\n", 7, "fewer than 3 distinct vertices")                      \
  X(count_face_no_id, BASE "face\n", 7, "wrong number of values")                          \
  X(count_object, BASE "face 1 1 2 3\nobject 4\n", 8, "wrong number of values")            \
  X(range_coord_high, BASE "vertex 5 32768 0 10\n", 7, "out of range -32768..32767")       \
  X(range_coord_low, BASE "vertex 5 0 -32769 10\n", 7, "out of range")                     \
  X(range_coord_huge, BASE "vertex 5 0 0 99999999999999999999999\n", 7, "out of range")    \
  X(range_vertex_id_0, BASE "vertex 0 1 1 10\n", 7, "vertex id `0` out of range 1..65535") \
  X(range_vertex_id_big, BASE "vertex 65536 1 1 10\n", 7, "out of range")                  \
  X(range_face_id, BASE "face 65536 1 2 3\n", 7, "face id `65536` out of range")           \
  X(range_face_vertex_id, BASE "face 1 1 2 -3\n", 7, "vertex id `-3` out of range")        \
  X(range_object_id, BASE "face 1 1 2 3\nobject 0 1\n", 8, "object id `0` out of range")   \
  X(range_object_face_id, BASE "face 1 1 2 3\nobject 1 70000\n", 8, "face id")             \
  X(range_view, "view 0 0 -40000\n", 1, "out of range")                                    \
  X(range_window, "view 0 0 -1\nwindow 0 0 1 33000\n", 2, "out of range")                  \
  X(repeat_vertex, BASE "vertex 2 5 5 10\n", 7, "vertex 2 already defined at line 4")      \
  X(repeat_face, BASE "face 1 1 2 3\nface 1 1 3 4\n", 8, "face 1 already defined at line 7") \
  X(repeat_object, BASE "face 1 1 2 3\nface 2 1 3 4\nobject 5 1\nobject 5 2\n", 10,        \
    "object 5 already defined at line 9")                                                  \
  X(unknown_vertex, BASE "face 1 1 2 9\n", 7, "face 1: unknown vertex 9")                  \
  X(unknown_vertex_in_hole, HOLES "face 1 1 2 3 4 * 5 6 99\n", 14, "unknown vertex 99")    \
  X(unknown_face, BASE "face 1 1 2 3\nobject 1 1 2\n", 8, "object 1: unknown face 2")      \
  X(face_in_two_objects, BASE "face 1 1 2 3\nobject 1 1\nobject 2 1\n", 9,                 \
    "face 1 is already in object 1 (line 8)")                                              \
  X(face_twice_in_object, BASE "face 1 1 2 3\nobject 1 1 1\n", 8, "listed twice")          \
  X(star_first, BASE "face 1 * 1 2 3\n", 7, "`*` must come between vertex ids, not first") \
  X(star_doubled, HOLES "face 1 1 2 3 4 * * 5 6 7\n", 14, "`* *`")                         \
  X(star_last, BASE "face 1 1 2 3 *\n", 7, "not last")                                     \
  X(star_before_grey, BASE "face 1 1 2 3 * grey 9\n", 7, "not last")                       \
  X(star_alone, BASE "face 1 *\n", 7, "not first")                                         \
  X(grey_no_value, BASE "face 1 1 2 3 grey\n", 7, "`grey` must be followed by exactly one") \
  X(grey_two_values, BASE "face 1 1 2 3 grey 1 2\n", 7, "`grey` must be followed")         \
  X(grey_in_middle, BASE "face 1 1 2 grey 5 3\n", 7, "`grey` must be followed")            \
  X(grey_twice, BASE "face 1 1 2 3 grey 5 grey 6\n", 7, "`grey` must be followed")         \
  X(grey_range, BASE "face 1 1 2 3 grey 256\n", 7, "grey `256` out of range 0..255")       \
  X(grey_negative, BASE "face 1 1 2 3 grey -1\n", 7, "out of range 0..255")                \
  X(grey_not_number, BASE "face 1 1 2 3 grey x\n", 7, "bad number `x`")                    \
  X(few_vertices, BASE "face 1 1 2\n", 7, "fewer than 3 distinct vertices in its outer")   \
  X(few_after_duplicates, BASE "face 1 1 2 2 1 1\n", 7, "fewer than 3 distinct vertices") \
  X(few_in_hole, HOLES "face 1 1 2 3 4 * 5 6 6\n", 14, "fewer than 3 distinct vertices in its hole 1") \
  X(vertex_twice, BASE "face 1 1 2 3 1 4\n", 7, "vertex 1 appears twice in its outer boundary") \
  X(vertex_twice_in_hole, HOLES "face 1 1 2 3 4 * 5 6 5 7\n", 14, "vertex 5 appears twice in its hole 1") \
  X(same_position, BASE "vertex 5 100 100 10\nface 1 1 2 3 5 4\n", 8, "vertices 3 and 5")  \
  X(same_position_apart, BASE "vertex 5 100 0 10\nface 1 1 2 3 5 4\n", 8, "not a simple")  \
  X(zero_area, BASE "vertex 5 50 0 10\nface 1 1 5 2\n", 8, "face 1 has zero area")         \
  X(zero_area_diagonal, BASE "vertex 5 50 50 10\nface 1 1 5 3\n", 8, "zero area")          \
  X(not_planar_by_one, BASE "vertex 5 0 100 11\nface 1 1 2 3 5\n", 8,                      \
    "face 1 is not planar: vertex 5")                                                      \
  X(not_planar_hole, HOLES "vertex 12 40 40 11\nface 1 1 2 3 4 * 5 6 12\n", 15,            \
    "not planar: vertex 12")                                                               \
  X(bowtie, BASE "face 1 1 2 4 3\n", 7, "face 1 is not simple")                             \
  X(vertex_on_own_edge, BASE "vertex 5 50 0 10\nvertex 6 50 50 10\nface 1 1 2 3 4 6 5\n", 9, \
    "not simple")                                                                          \
  X(hole_crosses_boundary, HOLES "face 1 1 2 3 4 * 5 8 9\n", 14,                           \
    "edge 2-3 of its outer boundary and edge 5-8 of its hole 1 intersect")                 \
  X(hole_outside, BASE "vertex 5 200 200 10\nvertex 6 300 200 10\nvertex 7 200 300 10\n"   \
    "face 1 1 2 3 4 * 5 6 7\n", 10, "hole 1 is outside the face (vertex 5)")               \
  X(hole_touches_edge_inside, BASE "vertex 5 50 0 10\nvertex 6 60 40 10\nvertex 7 40 40 10\n" \
    "face 1 1 2 3 4 * 5 6 7\n", 10, "not simple")                                          \
  X(hole_overlaps_boundary_edge, BASE "vertex 5 100 50 10\nvertex 6 50 50 10\n"            \
    "face 1 1 2 3 4 * 2 3 6\n", 9, "intersect")                                            \
  X(hole_equals_face, BASE "face 1 1 2 3 4 * 1 2 3 4\n", 7, "intersect")                   \
  X(hole_in_hole, HOLES "vertex 12 11 11 10\nvertex 13 14 11 10\nvertex 14 11 14 10\n"      \
    "face 1 1 2 3 4 * 5 6 7 * 12 13 14\n", 17, "hole 2 overlaps hole 1")                   \
  X(holes_cross, HOLES "vertex 12 30 5 10\nvertex 13 30 30 10\nvertex 14 20 5 10\n"         \
    "face 1 1 2 3 4 * 5 6 7 * 12 13 14\n", 17, "of its hole 2 intersect")                  \
  X(hole_leaves_through_vertices, "view 0 0 -1000\nwindow -10 -10 110 110\n"               \
    "vertex 1 0 0 10\nvertex 2 100 0 10\nvertex 3 50 50 10\nvertex 4 100 100 10\n"          \
    "vertex 5 0 100 10\nvertex 6 120 50 10\nface 1 1 2 3 4 5 * 2 6 4\n", 9,                 \
    "hole 1 is outside the face (vertex 6)")                                               \
  X(hole_chord_outside, "view 0 0 -1000\nwindow -10 -10 110 110\n"                         \
    "vertex 1 0 0 10\nvertex 2 100 0 10\nvertex 3 50 50 10\nvertex 4 100 100 10\n"          \
    "vertex 5 0 100 10\nvertex 6 40 50 10\nface 1 1 2 3 4 5 * 2 6 4\n", 9,                  \
    "hole 1 leaves the face along edge 4-2")                                               \
  X(hole_folded, HOLES "vertex 12 40 20 10\nface 1 1 2 3 4 * 10 11 12\n", 15, "not simple")                     \
  X(eye_positive, "view 0 0 5\nwindow 0 0 1 1\n", 1,                                       \
    "the eye must be on the negative side: view Z0 = 5 must be < 0")                       \
  X(eye_zero, "view 0 0 0\nwindow 0 0 1 1\n", 1, "must be < 0")                            \
  X(vertex_behind_eye, BASE "vertex 5 0 0 -1000\nvertex 6 9 9 -1000\n"                     \
    "vertex 7 0 0 -2000\nface 1 1 2 5\n", 7, "vertex 5 (z = -1000) is not in front of the eye") \
  X(missing_view, "window 0 0 1 1\n\n# end\n", 3, "missing `view` statement")             \
  X(missing_window, "view 0 0 -1\n", 1, "missing `window` statement")                      \
  X(empty_file, "", 1, "missing `view` statement")                                         \
  X(window_x, "view 0 0 -1\nwindow 5 0 5 1\n", 2, "XL must be < XR")                       \
  X(window_y, "view 0 0 -1\nwindow 0 2 5 1\n", 2, "YB must be < YT")                       \
  X(light_zero, BASE "light 0 0 0\n", 7, "light direction (0, 0, 0)")                      \
  X(repeat_view, BASE "view 0 0 -5\n", 7, "`view` given twice (first at line 1)")          \
  X(repeat_window, BASE "window 0 0 1 1\n", 7, "`window` given twice (first at line 2)")   \
  X(too_many_lights, BASE "light 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\nlight 1 0 0\n", 23, "more than 16 lights")                   \
  X(light_point_count, BASE "light point 1 2\n", 7, "expected `light point X Y Z`")        \
  X(light_point_range, BASE "light point 1 2 99999\n", 7, "light position")               \
  X(on_unknown, BASE "face 1 1 2 3 4 on 9\n", 7, "face 1: `on 9`: no face 9")              \
  X(on_itself, BASE "face 1 1 2 3 4 on 1\n", 7, "face 1 cannot lie on itself")            \
  X(on_twice, BASE "face 1 1 2 3 4 on 2 on 3\n", 7, "`on` must be followed by exactly one face id") \
  X(on_not_coplanar, BASE "vertex 5 10 10 10\nvertex 6 50 10 10\nvertex 7 50 50 11\n"       \
    "face 1 1 2 3 4\nface 2 5 6 7 on 1\n", 11, "face 2 is `on 1` but its vertex 7 is not in face 1's plane") \
  X(on_outside, BASE "vertex 5 10 10 10\nvertex 6 150 10 10\nvertex 7 50 50 10\n"          \
    "face 1 1 2 3 4\nface 2 5 6 7 on 1\n", 11, "face 2 is `on 1` but its vertex 6 lies outside face 1") \
  X(on_circle, BASE "face 1 1 2 3 4 on 2\nface 2 4 3 2 1 on 1\n", 7, "face 1: its `on` faces go round in a circle") \
  X(texture_unknown, BASE "face 1 1 2 3 4\ntexture 2 a.pgm\n", 8, "texture: no face 2")      \
  X(texture_twice, BASE "face 1 1 2 3 4\ntexture 1 a.pgm\ntexture 1 b.pgm\n", 9, "texture: face 1 already has one (line 8)") \
  X(texture_count, BASE "face 1 1 2 3 4\ntexture 1\n", 8, "expected `texture F FILE`")      \
  X(repeat_background, BASE "background a.pgm\nbackground b.pgm\n", 8, "(first at line 7)") \
  X(repeat_effects, BASE "effects aa\neffects\n", 8, "`effects` given twice (first at line 7)") \
  X(effects_unknown_key, BASE "effects halftone=3x3 glow=on\n", 7, "effects: unknown key `glow`") \
  X(effects_bad_value, BASE "effects aa=fast\n", 7, "effects: bad value in `aa=fast`")     \
  X(garbage_bytes, BASE "\x01\x02\xff\xfe\n", 7, "unknown statement `????`")               \
  X(crlf_garbage, BASE "vertex 5 1 2 3x\r\n", 7, "bad number `3x`")

#define DEFINE_CASE(name, text, line, what)                                              \
  static void err_##name(void **state) { expect_error(state, #name ".s74", text, line, what); }
ERROR_CASES(DEFINE_CASE)

/* A NUL byte cannot be written in a C string literal case: written with its length. */
static void err_nul_byte(void **state)
{
  struct fx *f = *state;
  static const char text[] = BASE "vertex 5 1\0 2 3\n";
  write_file(f, "nul.s74", text, sizeof text - 1);
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(f->path, NULL, &s, &err), T74_EINPUT);
  char prefix[300];
  snprintf(prefix, sizeof prefix, "%s:7: NUL byte in the line", f->path);
  assert_string_equal(err.msg, prefix);
  assert_null(s);
}

static void err_missing_file(void **state)
{
  struct fx *f = *state;
  char path[300];
  snprintf(path, sizeof path, "%s/no-such-file.s74", f->dir);
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(path, NULL, &s, &err), T74_EIO);
  assert_non_null(strstr(err.msg, ": cannot read: No such file or directory"));
  assert_int_equal(strncmp(err.msg, path, strlen(path)), 0);
  assert_null(s);
  /* a folder opens but cannot be read */
  memset(&err, 0, sizeof err);
  assert_int_equal(scene_load(f->dir, NULL, &s, &err), T74_EIO);
  assert_non_null(strstr(err.msg, ": cannot read: "));
  assert_null(s);
}

static void err_unknown_kind(void **state)
{
  (void)state;
  struct scene_opts o = { .input = "tek" };
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(DATA "valid.s74", &o, &s, &err), T74_EINPUT);
  assert_non_null(strstr(err.msg, "unknown input kind `tek`"));
}

/* ---- valid .s74 ------------------------------------------------------------------------ */

static const struct scene_vertex *vtx(const struct scene *s, const struct scene_face *f,
                                      int k)
{
  assert_in_range(f->vidx[k], 0, s->nv - 1);
  return &s->v[f->vidx[k]];
}

static void ok_valid_structure(void **state)
{
  (void)state;
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  int st = scene_load(DATA "valid.s74", NULL, &s, &err);
  if (st) fail_msg("%s", err.msg);
  assert_string_equal(s->file, DATA "valid.s74");
  assert_int_equal(s->nv, 17);
  assert_int_equal(s->nf, 3);
  assert_int_equal(s->nobj, 2);
  assert_true(s->has_view && s->has_window && s->has_light);
  assert_int_equal(s->view[0], 50);
  assert_int_equal(s->view[2], -500);
  assert_int_equal(s->window[0], -20);
  assert_int_equal(s->window[3], 120);
  assert_int_equal(s->light[0].v[1], 2);
  assert_int_equal(s->light[0].v[2], -3);
  assert_string_equal(s->background, DATA "pics/sky.pgm");
  assert_string_equal(s->effects, "halftone=3x3 aa=multiscan n=4");
  assert_int_equal(s->effects_line, 7);
  assert_int_equal(s->warnings, 0);

  const struct scene_face *f = &s->f[0];
  assert_int_equal(f->id, 10);
  assert_int_equal(f->line, 9);
  assert_int_equal(f->grey, 200);
  assert_int_equal(f->object, 7);
  assert_int_equal(f->nring, 3);
  assert_int_equal(f->ring_start[0], 0);
  assert_int_equal(f->ring_start[1], 4);
  assert_int_equal(f->ring_start[2], 7);
  assert_int_equal(f->ring_start[3], 10);
  static const int ids0[] = { 1, 2, 3, 4, 11, 12, 13, 21, 22, 23 };
  for (int k = 0; k < 10; k++) assert_int_equal(vtx(s, f, k)->id, ids0[k]);
  assert_int_equal(vtx(s, f, 5)->x, 40);        /* vertex 12 = (40, 10, 100) */
  assert_int_equal(vtx(s, f, 5)->line, 20);

  f = &s->f[1];                                  /* 31 32 33 33 31 -> 31 32 33 */
  assert_int_equal(f->id, 20);
  assert_int_equal(f->grey, -1);
  assert_int_equal(f->object, 8);
  assert_int_equal(f->nring, 1);
  assert_int_equal(f->ring_start[1], 3);
  assert_int_equal(vtx(s, f, 0)->id, 31);
  assert_int_equal(vtx(s, f, 1)->id, 32);
  assert_int_equal(vtx(s, f, 2)->id, 33);

  f = &s->f[2];
  assert_int_equal(f->id, 30);
  assert_int_equal(f->object, 7);
  assert_int_equal(f->ring_start[1], 4);
  assert_int_equal(vtx(s, f, 3)->id, 8);

  assert_int_equal(s->obj[0].id, 7);
  assert_int_equal(s->obj[0].nface, 2);
  assert_int_equal(s->obj[0].face[0], 0);       /* indices into s->f, not ids */
  assert_int_equal(s->obj[0].face[1], 2);
  assert_int_equal(s->obj[1].face[0], 1);
  assert_int_equal(s->obj[1].line, 13);
  scene_free(s);
}

static void ok_hole_touches_outer_vertex(void **state)
{
  /* A triangular hole with one corner on the square's corner 3 (by its own vertex id at
     the same position) and one sharing vertex 1 itself. */
  struct scene *s = expect_ok(state, "touch.s74",
                              BASE "vertex 5 100 100 10\nvertex 6 60 30 10\n"
                                   "vertex 7 30 60 10\nface 1 1 2 3 4 * 5 6 7\n"
                                   "face 2 1 2 3 4 * 1 6 7\n");
  assert_int_equal(s->nf, 2);
  assert_int_equal(s->f[0].nring, 2);
  assert_int_equal(s->f[1].nring, 2);
  scene_free(s);
}

static void ok_holes_touch_each_other(void **state)
{
  struct scene *s = expect_ok(state, "touch2.s74",
                              BASE "vertex 5 10 10 10\nvertex 6 50 10 10\nvertex 7 50 50 10\n"
                                   "vertex 8 90 50 10\nvertex 9 90 90 10\n"
                                   "vertex 10 50 50 10\n"
                                   "face 1 1 2 3 4 * 5 6 7 * 7 8 9 # shared id\n"
                                   "face 2 1 2 3 4 * 5 6 7 * 10 8 9 # shared position\n");
  assert_int_equal(s->f[0].nring, 3);
  assert_int_equal(s->f[1].nring, 3);
  scene_free(s);
}

static void ok_oblique_plane(void **state)
{
  /* A plane not parallel to any axis, with a hole: x + 2y + 3z = 600 */
  struct scene *s = expect_ok(state, "oblique.s74",
                              "view 0 0 -1000\nwindow -10 -10 10 10\n"
                              "vertex 1 600 0 0\nvertex 2 0 300 0\nvertex 3 0 0 200\n"
                              "vertex 4 300 60 60\nvertex 5 200 110 60\nvertex 6 300 90 40\n"
                              "face 1 1 2 3 * 4 5 6 grey 0\n");
  assert_int_equal(s->f[0].grey, 0);
  assert_int_equal(s->f[0].nring, 2);
  scene_free(s);
}

static void ok_crlf_comments_blanks(void **state)
{
  struct scene *s = expect_ok(state, "crlf.s74",
                              "# comment line\r\n\r\n  view 0 0 -9   # eye\r\n"
                              "window\t-1 -1 1 1\r\nvertex 1 0 0 0\r\nvertex 2 5 0 0#x\r\n"
                              "vertex 3 0 5 0\r\nface 1 1 2 3 grey 255\r\n"
                              "effects\r\n   \t\r\n");
  assert_int_equal(s->nf, 1);
  assert_int_equal(s->f[0].grey, 255);
  assert_int_equal(s->view[2], -9);
  assert_string_equal(s->effects, "");
  assert_null(s->background);
  assert_false(s->has_light);
  scene_free(s);
}

static void ok_background_absolute(void **state)
{
  struct scene *s = expect_ok(state, "bg.s74", BASE "background /abs/pic.pgm\n");
  assert_string_equal(s->background, "/abs/pic.pgm");
  assert_int_equal(s->nf, 0);
  assert_null(s->effects);
  scene_free(s);
}

static void ok_opts_override_camera(void **state)
{
  struct fx *f = *state;
  static const char text[] = "vertex 1 0 0 0\nvertex 2 5 0 0\nvertex 3 0 5 0\nface 1 1 2 3\n";
  write_file(f, "nocam.s74", text, sizeof text - 1);
  struct scene_opts o = { .has_view = true, .has_window = true, .view = { 1, 2, -3 },
                          .window = { -4, -5, 6, 7 } };
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(f->path, &o, &s, &err), T74_OK);
  assert_int_equal(s->view[2], -3);
  assert_int_equal(s->window[3], 7);
  scene_free(s);
  /* an option eye at z = 0 is refused, naming the option */
  o.view[2] = 0;
  memset(&err, 0, sizeof err);
  assert_int_equal(scene_load(f->path, &o, &s, &err), T74_EINPUT);
  assert_non_null(strstr(err.msg, "--view"));
  assert_null(s);
}

static void ok_max_values(void **state)
{
  struct scene *s = expect_ok(state, "max.s74",
                              "view -32768 32767 -32768\nwindow -32768 -32768 32767 32767\n"
                              "vertex 65535 32767 32767 32767\nvertex 1 -32768 32767 32767\n"
                              "vertex 2 -32768 -32768 -32767\nface 65535 65535 1 2\n"
                              "object 65535 65535\n");
  assert_int_equal(s->f[0].id, 65535);
  assert_int_equal(s->f[0].object, 65535);
  assert_int_equal(s->v[0].x, 32767);
  scene_free(s);
}

static void ok_check_face_direct(void **state)
{
  /* scene_check_face on a hand-made face: off by one in z is non-planar, exactly. */
  (void)state;
  struct scene_vertex v[4] = {
    { 1, 0, 0, 0, 1 }, { 2, 30000, 0, 0, 2 }, { 3, 30000, 30000, 0, 3 }, { 4, 0, 30000, 1, 4 }
  };
  int rs[2] = { 0, 4 }, idx[4] = { 0, 1, 2, 3 };
  struct scene sc = { .file = "mem", .nv = 4, .v = v };
  struct scene_face f = { .id = 9, .line = 5, .grey = -1, .nring = 1, .ring_start = rs,
                          .vidx = idx };
  struct t74_error err = { 0 };
  assert_int_equal(scene_check_face(&sc, &f, &err), SCENE_FACE_NONPLANAR);
  assert_string_equal(err.msg, "mem:5: face 9 is not planar: vertex 4 is off the plane of "
                               "vertices 1, 2, 3");
  assert_int_equal(scene_check_face(&sc, &f, NULL), SCENE_FACE_NONPLANAR);
  assert_int_equal(t74_fail(NULL, T74_EIO, "x"), T74_EIO);      /* nothing to record in */
  assert_int_equal(t74_fail_at(NULL, T74_EINPUT, "f", 1, "x"), T74_EINPUT);
  v[3].z = 0;
  memset(&err, 0, sizeof err);
  assert_int_equal(scene_check_face(&sc, &f, &err), SCENE_FACE_OK);
  assert_int_equal(err.status, T74_OK);
}

/* Quadrilaterals, which scene_check_face passes by a convexity test when every corner
   turns strictly one way, and sends the whole way otherwise: convex either way round and
   tilted in space (projected along x or y) pass; a bow-tie, a fold back, a repeated
   vertex and a non-planar one are refused as before; a dart (concave) and one with a
   straight corner still pass the whole check. */
static void quad_check_face(void **state)
{
  (void)state;
  static const struct { int32_t p[4][3]; int want; } cases[] = {
    { { { 0, 0, 0 }, { 40, 0, 0 }, { 40, 30, 0 }, { 0, 30, 0 } }, SCENE_FACE_OK },
    { { { 0, 30, 0 }, { 40, 30, 0 }, { 40, 0, 0 }, { 0, 0, 0 } }, SCENE_FACE_OK },
    { { { 5, 0, 0 }, { 5, 40, 1 }, { 5, 40, 31 }, { 5, 0, 30 } }, SCENE_FACE_OK },
    { { { 0, 7, 0 }, { 40, 7, 0 }, { 40, 7, 30 }, { 0, 7, 30 } }, SCENE_FACE_OK },
    { { { 0, 0, 0 }, { 40, 30, 0 }, { 40, 0, 0 }, { 0, 30, 0 } }, SCENE_FACE_NONSIMPLE },
    { { { 0, 0, 0 }, { 40, 0, 0 }, { 20, 0, 0 }, { 20, 20, 0 } }, SCENE_FACE_NONSIMPLE },
    { { { 0, 0, 0 }, { 40, 0, 0 }, { 40, 0, 0 }, { 20, 20, 0 } }, SCENE_FACE_DEGENERATE },
    { { { 0, 0, 0 }, { 40, 0, 0 }, { 40, 30, 1 }, { 0, 30, 0 } }, SCENE_FACE_NONPLANAR },
    { { { 0, 0, 0 }, { 40, 0, 0 }, { 10, 10, 0 }, { 0, 40, 0 } }, SCENE_FACE_OK },
    { { { 0, 0, 0 }, { 20, 0, 0 }, { 40, 0, 0 }, { 20, 20, 0 } }, SCENE_FACE_OK },
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    struct scene_vertex v[4];
    for (int k = 0; k < 4; k++)
      v[k] = (struct scene_vertex){ (uint32_t)(k + 1), cases[c].p[k][0], cases[c].p[k][1],
                                    cases[c].p[k][2], k + 1 };
    int rs[2] = { 0, 4 }, idx[4] = { 0, 1, 2, 3 };
    struct scene sc = { .file = "mem", .nv = 4, .v = v };
    struct scene_face f = { .id = 3, .line = 7, .grey = -1, .nring = 1, .ring_start = rs,
                            .vidx = idx };
    struct t74_error err = { 0 };
    int d = scene_check_face(&sc, &f, &err);
    if (d != cases[c].want) fail_msg("quad %zu: defect %d, want %d", c, d, cases[c].want);
    assert_int_equal(err.status, d == SCENE_FACE_OK ? T74_OK : T74_EINPUT);
    /* without a record (an import's verdict alone): the same verdict */
    assert_int_equal(scene_check_face(&sc, &f, NULL), cases[c].want);
  }
}

/* ---- robustness ---------------------------------------------------------------------- */

/* Random garbage, and random corruptions of a valid scene: never a crash, never a status
   other than 0 or 2, and a 2 always comes with "FILE:" at the start of its message. */
static void robust_fuzz(void **state)
{
  struct fx *f = *state;
  static const char valid[] = HOLES "face 1 1 2 3 4 * 5 6 7 grey 9\nobject 1 1\n"
                                    "light 1 1 1\neffects aa=area edges\n";
  static const char alphabet[] = "0123456789 -*\n#gveftrxyz\t\r";
  char buf[1024];
  unsigned seed = 12345;
  int failures = 0, oks = 0;
  for (int round = 0; round < 600; round++) {
    size_t n;
    if (round % 2 == 0) {
      n = (size_t)(rand_r(&seed) % 400);
      for (size_t k = 0; k < n; k++)
        buf[k] = round % 4 == 0 ? (char)(rand_r(&seed) & 0xff)
                                : alphabet[rand_r(&seed) % (sizeof alphabet - 1)];
    } else {
      n = sizeof valid - 1;
      memcpy(buf, valid, n);
      int edits = 1 + rand_r(&seed) % 3;
      for (int e = 0; e < edits; e++)
        buf[rand_r(&seed) % n] = alphabet[rand_r(&seed) % (sizeof alphabet - 1)];
    }
    write_file(f, "fuzz.s74", buf, n);
    struct scene *s = NULL;
    struct t74_error err = { 0 };
    int st = scene_load(f->path, NULL, &s, &err);
    if (st == T74_OK) {
      assert_non_null(s);
      oks++;
      scene_free(s);
    } else {
      assert_int_equal(st, T74_EINPUT);
      assert_null(s);
      assert_int_equal(strncmp(err.msg, f->path, strlen(f->path)), 0);
      failures++;
    }
  }
  assert_true(failures > 0);
  assert_true(oks > 0);          /* some corruptions only touch comments or blanks */
}

static void robust_huge_line(void **state)
{
  struct fx *f = *state;
  size_t n = 3u << 20;
  char *text = malloc(n + 64);
  assert_non_null(text);
  strcpy(text, "face 1 ");
  size_t k = strlen(text);
  while (k + 2 < n) { text[k++] = '7'; text[k++] = ' '; }
  text[k++] = '\n';
  write_file(f, "huge.s74", text, k);
  free(text);
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(f->path, NULL, &s, &err), T74_EINPUT);
  assert_non_null(strstr(err.msg, ":1: face 1: unknown vertex 7"));
}

/* ---- .obj / .off ------------------------------------------------------------------------ */

/* --turn 0,0: the mesh as written (imports are turned to a three-quarter view by default,
   render/turn.h; these tests check the grid mapping itself) */
static const struct scene_opts straight = { .has_turn = true };

static void obj_split_and_drop(void **state)
{
  (void)state;
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  int st = scene_load(DATA "quads.obj", &straight, &s, &err);
  if (st) fail_msg("%s", err.msg);
  assert_int_equal(s->nv, 11);
  assert_int_equal(s->warnings, 2);          /* face 2 split, face 3 dropped */
  assert_int_equal(s->nf, 4);
  assert_int_equal(s->f[0].id, 1);
  assert_int_equal(s->f[0].ring_start[1], 4);
  assert_int_equal(s->f[1].id, 2);           /* both triangles keep the input number */
  assert_int_equal(s->f[2].id, 2);
  assert_int_equal(s->f[1].ring_start[1], 3);
  assert_int_equal(s->f[2].ring_start[1], 3);
  assert_int_equal(s->f[3].id, 4);
  assert_int_equal(s->f[3].line, 24);
  assert_int_equal(s->v[s->f[3].vidx[0]].id, 3);   /* -9 of 11 */
  assert_int_equal(s->v[s->f[3].vidx[1]].id, 2);
  assert_int_equal(s->v[s->f[3].vidx[2]].id, 6);
  /* the grid: largest side 12800, x and y centred, z negated with its minimum at 0 */
  int32_t lo[3] = { 99999, 99999, 99999 }, hi[3] = { -99999, -99999, -99999 };
  for (int i = 0; i < s->nv; i++) {
    int32_t c[3] = { s->v[i].x, s->v[i].y, s->v[i].z };
    for (int a = 0; a < 3; a++) {
      if (c[a] < lo[a]) lo[a] = c[a];
      if (c[a] > hi[a]) hi[a] = c[a];
    }
  }
  assert_int_equal(lo[2], 0);
  assert_int_equal(hi[2], 12800);
  assert_int_equal(lo[0], -4923);            /* 1 / 1.3 * 12800 / 2 = 4923.08 */
  assert_int_equal(hi[0], 4923);
  assert_int_equal(s->v[0].z, 12800);        /* obj z = 0 is the farthest */
  assert_int_equal(s->v[5].z, 0);            /* obj z = 1.3 the nearest */
  /* the default camera: eye in front on the axis, window 4:3 around the projection */
  assert_true(s->has_view && s->has_window);
  assert_int_equal(s->view[0], 0);
  assert_int_equal(s->view[2], -32000);
  int w = s->window[2] - s->window[0], h = s->window[3] - s->window[1];
  assert_in_range(w * 3, h * 4 - 8, h * 4 + 8);
  assert_true(s->window[0] < -4923 && s->window[2] > 4923);
  /* the front square (z = 0, scale 1) is 9846 tall: 4:3 makes it 13128 wide, +10% */
  assert_in_range(w, 14440, 14443);
  assert_in_range(h, 10830, 10833);
  int centre = s->window[0] + s->window[2];                /* centred on the axis */
  assert_true(centre >= -2 && centre <= 2);
  scene_free(s);
}

static void obj_with_camera_opts(void **state)
{
  (void)state;
  struct scene_opts o = { .has_view = true, .view = { 10, 20, -5000 }, .input = "obj" };
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(DATA "quads.obj", &o, &s, &err), T74_OK);
  assert_int_equal(s->view[0], 10);
  assert_int_equal(s->view[2], -5000);
  assert_true(s->window[0] < s->window[2]);
  scene_free(s);
}

static void obj_eye_option(void **state)
{
  /* an import's vertices all have z >= 0, so only an option eye with Z0 >= 0 can fail */
  (void)state;
  struct scene_opts o = { .has_view = true, .view = { 0, 0, 100 } };
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  assert_int_equal(scene_load(DATA "cube.off", &o, &s, &err), T74_EINPUT);
  assert_string_equal(err.msg, "--view: the eye must be on the negative side: Z0 = 100 "
                               "must be < 0");
  assert_null(s);
  struct scene_opts w = { .has_window = true, .window = { 5, 0, 5, 1 } };
  memset(&err, 0, sizeof err);
  assert_int_equal(scene_load(DATA "cube.off", &w, &s, &err), T74_EINPUT);
  assert_non_null(strstr(err.msg, "--window 5 0 5 1: XL must be < XR"));
}

static void off_cube(void **state)
{
  (void)state;
  struct scene *s = NULL;
  struct t74_error err = { 0 };
  int st = scene_load(DATA "cube.off", &straight, &s, &err);
  if (st) fail_msg("%s", err.msg);
  assert_int_equal(s->nv, 8);
  assert_int_equal(s->nf, 6);
  assert_int_equal(s->warnings, 0);
  for (int i = 0; i < 6; i++) {
    assert_int_equal(s->f[i].id, i + 1);
    assert_int_equal(s->f[i].nring, 1);
    assert_int_equal(s->f[i].ring_start[1], 4);
    assert_int_equal(s->f[i].grey, -1);
  }
  assert_int_equal(s->f[0].line, 12);
  assert_int_equal(s->v[6].x, 6400);         /* (1,1,1) */
  assert_int_equal(s->v[6].y, 6400);
  assert_int_equal(s->v[6].z, 0);
  assert_int_equal(s->v[0].x, -6400);
  assert_int_equal(s->v[0].z, 12800);
  assert_int_equal(s->v[s->f[5].vidx[3]].id, 8);   /* OFF indices are 0-based */
  scene_free(s);
}

#define IMPORT_ERRORS(X)                                                                   \
  X(obj_unknown_statement, "obj", "v 0 0 0\nfrobnicate 1\n", 2, "unknown statement")      \
  X(obj_bad_coordinate, "obj", "v 0 0 x\n", 1, "bad number `x`")                          \
  X(obj_nan, "obj", "v 0 0 nan\n", 1, "bad number")                                       \
  X(obj_short_vertex, "obj", "v 0 0\n", 1, "`v` needs x y z")                             \
  X(obj_index_zero, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, "vertex index 0")   \
  X(obj_index_range, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4,                    \
    "face 1: vertex index 4 but only 3 vertices")                                         \
  X(obj_relative_range, "obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", 3,              \
    "relative vertex index -3")                                                            \
  X(obj_bad_ref, "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n", 4,                  \
    "bad face vertex `1/2/3/4`")                                                           \
  X(obj_no_faces, "obj", "v 0 0 0\nv 1 1 1\n", 2, "no faces")                             \
  X(off_header, "off", "FOO\n3 1 0\n", 1, "expected `OFF`")                              \
  X(off_counts, "off", "OFF\n3 x\n", 2, "bad number `x`")                                 \
  X(off_truncated, "off", "OFF 3 1 0\n0 0 0\n1 0 0\n", 3, "file ends after 2 of 3 vertices") \
  X(off_face_short, "off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", 6,                  \
    "face needs 4 vertex indices")                                                         \
  X(off_index_range, "off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 6,                 \
    "vertex index `3` out of range 0..2")                                                  \
  X(off_trailing, "off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n9 9\n", 7,               \
    "unexpected data after the last face")                                                 \
  X(off_nul, "off", "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 \0\n", 6, "NUL byte")

static void expect_import_error(void **state, const char *name, const char *kind,
                                const char *text, size_t len, int line, const char *what)
{
  struct fx *f = *state;
  char file[64];
  snprintf(file, sizeof file, "%s.%s", name, kind);
  write_file(f, file, text, len);
  struct scene *s = (struct scene *)1;
  struct t74_error err = { 0 };
  int st = scene_load(f->path, NULL, &s, &err);
  char prefix[300];
  snprintf(prefix, sizeof prefix, "%s:%d: ", f->path, line);
  if (st != T74_EINPUT || strncmp(err.msg, prefix, strlen(prefix)) != 0 ||
      !strstr(err.msg, what))
    fail_msg("%s: status %d, message \"%s\"; wanted 2, \"%s...%s\"", name, st, err.msg,
             prefix, what);
  assert_null(s);
}

#define DEFINE_IMPORT(name, kind, text, line, what)                                      \
  static void imp_##name(void **state)                                                   \
  {                                                                                      \
    static const char t[] = text;                                                        \
    expect_import_error(state, #name, kind, t, sizeof t - 1, line, what);                 \
  }
IMPORT_ERRORS(DEFINE_IMPORT)

static void obj_fuzz(void **state)
{
  struct fx *f = *state;
  static const char alphabet[] = "0123456789 -/.e\nvf#\t";
  char buf[512];
  unsigned seed = 777;
  int ok = 0;
  for (int round = 0; round < 400; round++) {
    size_t n = (size_t)(rand_r(&seed) % sizeof buf);
    for (size_t k = 0; k < n; k++) buf[k] = alphabet[rand_r(&seed) % (sizeof alphabet - 1)];
    write_file(f, round % 2 ? "fuzz.obj" : "fuzz.off", buf, n);
    struct scene *s = NULL;
    struct t74_error err = { 0 };
    int st = scene_load(f->path, NULL, &s, &err);
    assert_true(st == T74_OK || st == T74_EINPUT);
    if (st == T74_OK) { ok++; scene_free(s); }
    else assert_int_equal(strncmp(err.msg, f->path, strlen(f->path)), 0);
  }
  (void)ok;
}

/* ---- effects ---------------------------------------------------------------------------- */

static void fx_defaults(void **state)
{
  (void)state;
  struct effects e;
  struct t74_error err = { 0 };
  assert_int_equal(effects_parse(NULL, &e, "f", 1, &err), T74_OK);
  assert_int_equal(e.given, 0);
  assert_int_equal(e.halftone, 4);
  assert_int_equal(e.aa, EFFECTS_AA_NONE);
  assert_false(e.edges);
  assert_int_equal(e.smooth, EFFECTS_SMOOTH_NONE);
  assert_int_equal(e.tube, EFFECTS_TUBE_STORED);
  assert_int_equal(e.n, 3);
  char buf[64];
  assert_int_equal(effects_format(&e, buf, sizeof buf), 0);
  assert_string_equal(buf, "");
  assert_int_equal(effects_parse("  \t ", &e, "f", 1, &err), T74_OK);
  assert_int_equal(e.given, 0);
}

static void fx_keys_without_values(void **state)
{
  (void)state;
  struct effects e;
  struct t74_error err = { 0 };
  assert_int_equal(effects_parse("halftone aa filter n super edges smooth tube", &e, "f", 1,
                                 &err), T74_OK);
  assert_int_equal(e.halftone, 4);
  assert_int_equal(e.aa, EFFECTS_AA_NONE);
  assert_int_equal(e.filter, EFFECTS_FILTER_BOX);
  assert_int_equal(e.n, 3);
  assert_int_equal(e.super, 3);
  assert_true(e.edges);
  assert_int_equal(e.smooth, EFFECTS_SMOOTH_GOURAUD);
  assert_int_equal(e.tube, EFFECTS_TUBE_STORED);
  assert_int_equal(e.given, EFFECTS_HALFTONE | EFFECTS_AA | EFFECTS_FILTER | EFFECTS_N |
                                EFFECTS_SUPER | EFFECTS_EDGES | EFFECTS_SMOOTH | EFFECTS_TUBE);
  char buf[256];
  effects_format(&e, buf, sizeof buf);
  assert_string_equal(buf, "halftone=4x4 aa=none filter=box n=3 super=3 edges=on "
                           "smooth=gouraud tube=stored");
}

static void fx_every_key(void **state)
{
  (void)state;
  struct effects e;
  struct t74_error err = { 0 };
  const char *text = "tube=fade:2.5 contour=0.25 smooth=prop:0.25 inner=2,128 outline=3.5,0 "
                     "halo=0.5,200 edges=off depth=4 sigma=0.75 super=16 n=1 filter=gauss "
                     "aa=exact pattern=clustered halftone=3x3";
  assert_int_equal(effects_parse(text, &e, "f", 1, &err), T74_OK);
  assert_int_equal(e.halftone, 3);
  assert_string_equal(e.pattern, "clustered");
  assert_int_equal(e.aa, EFFECTS_AA_EXACT);
  assert_int_equal(e.filter, EFFECTS_FILTER_GAUSS);
  assert_int_equal(e.n, 1);
  assert_int_equal(e.super, 16);
  assert_false(e.edges);
  assert_true(e.sigma == 0.75);
  assert_int_equal(e.depth, 4);
  assert_true(e.outline_w == 3.5);
  assert_int_equal(e.outline_g, 0);
  assert_true(e.inner_w == 2);
  assert_true(e.halo_w == 0.5);
  assert_int_equal(e.halo_g, 200);
  assert_int_equal(e.inner_g, 128);
  assert_int_equal(e.smooth, EFFECTS_SMOOTH_PROP);
  assert_true(e.smooth_c == 0.25);
  assert_true(e.contour_on);
  assert_true(e.contour == 0.25);
  assert_int_equal(e.tube, EFFECTS_TUBE_FADE);
  assert_true(e.fade_seconds == 2.5);
  char buf[512];
  int n = effects_format(&e, buf, sizeof buf);
  const char *canon = "halftone=3x3 pattern=clustered aa=exact filter=gauss n=1 super=16 "
                      "sigma=0.75 depth=4 edges=off outline=3.5,0 inner=2,128 halo=0.5,200 "
                      "smooth=prop:0.25 contour=0.25 tube=fade:2.5";
  assert_string_equal(buf, canon);
  assert_int_equal(n, (int)strlen(canon));
  /* round trip, and truncation keeps the full length and a terminated prefix */
  struct effects e2;
  assert_int_equal(effects_parse(buf, &e2, "f", 1, &err), T74_OK);
  assert_int_equal(e2.given, e.given);
  char small[10];
  assert_int_equal(effects_format(&e, small, sizeof small), n);
  assert_string_equal(small, "halftone=");
  /* the remaining values of each enumerated key */
  assert_int_equal(effects_parse("aa=multiscan smooth=phong tube=flash halftone=4", &e, "f",
                                 1, &err), T74_OK);
  assert_int_equal(e.aa, EFFECTS_AA_MULTISCAN);
  assert_int_equal(e.smooth, EFFECTS_SMOOTH_PHONG);
  assert_int_equal(e.tube, EFFECTS_TUBE_FLASH);
  assert_int_equal(e.halftone, 4);
  assert_int_equal(effects_parse("aa=area smooth=fixed:3", &e, "f", 1, &err), T74_OK);
  assert_int_equal(e.aa, EFFECTS_AA_AREA);
  assert_int_equal(e.smooth, EFFECTS_SMOOTH_FIXED);
  assert_true(e.smooth_c == 3.0);
  assert_int_equal(effects_parse("aa=super", &e, "f", 1, &err), T74_OK);
  assert_int_equal(e.aa, EFFECTS_AA_SUPER);
  assert_int_equal(err.status, T74_OK);
}

static void fx_bad(void **state)
{
  (void)state;
  static const struct { const char *text, *what; } bad[] = {
    { "halftone=5x5", "bad value in `halftone=5x5`" },
    { "glow", "unknown key `glow`" },
    { "aa=none aa=area", "key given twice: `aa`" },
    { "n=0", "bad value" }, { "n=17", "bad value" }, { "n=3x", "bad value" },
    { "super=", "empty value in `super=`" }, { "edges=yes", "bad value" },
    { "outline=1", "bad value" }, { "outline=1,256", "bad value" },
    { "outline=17,0", "bad value" }, { "inner=,5", "bad value" },
    { "outline", "outline needs W,G" }, { "inner", "inner needs W,G" },
    { "pattern", "pattern needs a name" }, { "pattern=a/b", "bad value" },
    { "smooth=fixed:", "bad value" }, { "smooth=fixed:x", "bad value" },
    { "smooth=prop:nan", "bad value" }, { "smooth=prop:-1", "bad value" },
    { "smooth=flat", "bad value" }, { "contour", "contour needs a value" },
    { "contour=256", "bad value" }, { "contour=1.5", "bad value" },
    { "contour=-0.1", "bad value" }, { "sigma", "sigma needs a value" },
    { "sigma=0", "bad value" }, { "sigma=5", "bad value" }, { "depth=0", "bad value" },
    { "depth=9", "bad value" }, { "halo=1", "bad value" }, { "outline=16.5,0", "bad value" }, { "tube=fade", "bad value" },
    { "tube=fade:0", "bad value" }, { "tube=fade:1e9", "bad value" },
    { "tube=fade:inf", "bad value" }, { "tube=storage", "bad value" },
    { "filter=tent", "bad value" }, { "=3", "missing key" }, { "AA=none", "unknown key" },
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    struct effects e;
    struct t74_error err = { 0 };
    int st = effects_parse(bad[i].text, &e, "scene.s74", 42, &err);
    if (st != T74_EINPUT || strncmp(err.msg, "scene.s74:42: effects: ", 23) != 0 ||
        !strstr(err.msg, bad[i].what))
      fail_msg("`%s`: status %d, message \"%s\"", bad[i].text, st, err.msg);
  }
  /* without a file (the --effects option) the message starts "effects: " */
  struct effects e;
  struct t74_error err = { 0 };
  assert_int_equal(effects_parse("x=1", &e, NULL, 0, &err), T74_EINPUT);
  assert_string_equal(err.msg, "effects: unknown key `x`");
}

/* ---- main -------------------------------------------------------------------------------- */

#define LIST_CASE(name, text, line, what) cmocka_unit_test(err_##name),
#define LIST_IMPORT(name, kind, text, line, what) cmocka_unit_test(imp_##name),

int main(void)
{
  const struct CMUnitTest tests[] = {
    ERROR_CASES(LIST_CASE)
    cmocka_unit_test(err_nul_byte),
    cmocka_unit_test(err_missing_file),
    cmocka_unit_test(err_unknown_kind),
    cmocka_unit_test(ok_valid_structure),
    cmocka_unit_test(ok_hole_touches_outer_vertex),
    cmocka_unit_test(ok_holes_touch_each_other),
    cmocka_unit_test(ok_oblique_plane),
    cmocka_unit_test(ok_crlf_comments_blanks),
    cmocka_unit_test(ok_background_absolute),
    cmocka_unit_test(ok_opts_override_camera),
    cmocka_unit_test(ok_max_values),
    cmocka_unit_test(ok_check_face_direct),
    cmocka_unit_test(robust_fuzz),
    cmocka_unit_test(robust_huge_line),
    cmocka_unit_test(obj_split_and_drop),
    cmocka_unit_test(obj_with_camera_opts),
    cmocka_unit_test(obj_eye_option),
    cmocka_unit_test(off_cube),
    IMPORT_ERRORS(LIST_IMPORT)
    cmocka_unit_test(obj_fuzz),
    cmocka_unit_test(fx_defaults),
    cmocka_unit_test(quad_check_face),
    cmocka_unit_test(fx_keys_without_values),
    cmocka_unit_test(fx_every_key),
    cmocka_unit_test(fx_bad),
  };
  return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
