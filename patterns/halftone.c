/*
** halftone.c — halftone cells and the grey -> level mapping (paper 003 §4).
**
** This file contains code to turn one perspective-plane point of grey G (0..255) into
** the lit dots of its 3x3 or 4x4 cell on the 400 x 300 binary storage tube. Paper 003 §4:
** "each point of the perspective plane maps to a 3x3 or 4x4 area on the display; the
** number and distribution of lit dots gives intermediate tones; the patterns were chosen
** empirically, but should properly follow the eye's response: when a light stimulus grows
** geometrically the sensation grows arithmetically". The paper does not print its
** patterns; the ones below are the classic ones, chosen as the paper asks.
**
** HOW MANY DOTS (the level tables). A cell of L dots (L = 9 or 16) gives light n/L of a
** fully lit cell when n dots are lit. G is a perceived brightness: equal steps of G look
** like equal steps. By the law the paper quotes (Weber-Fechner: sensation ~ log stimulus)
** equal steps of sensation are equal RATIOS of light. A pure logarithm never reaches
** "no light", so the ratio is taken on n + 1 (the +1 being one dot's worth of light, the
** smallest step the cell can show, playing the eye's threshold):
**        n + 1 = (L+1)^(G/255)          G = 0 -> n = 0,   G = 255 -> n = L,
** i.e.   luminance(G) = ((L+1)^(G/255) - 1) / L,   level(G) = round(L * luminance(G)),
** every +255/log2(L+1) of G (about 77 for 3x3, 62 for 4x4) doubles n + 1. The level is
** rounded to nearest; no value lies within 1e-4 of a half (closest: 3x3 at G = 237,
** n = 7.49986 -> 7), so the table does not depend on how a half would round. The tables
** were printed, 16 values a row, by
**   python3 -c "import math; L=9; print([math.floor((L+1)**(g/255)-1+0.5) for g in range(256)])"
** (L=16 for 4x4) and are used as integers: no floating point at run time. The first G of
** each level (the step points) are
**   3x3:  0  45 102 139 167 189 208 224 238 250                      (levels 0..9)
**   4x4:  0  37  83 113 136 154 169 182 193 203 212 220 228 235 241 247 253  (0..16)
** Both tables are monotone non-decreasing; level(0) = 0 and level(255) = L.
**
** WHICH DOTS (the families). Each family is a threshold matrix rank[cy][cx], cy from the
** top of the cell: the dot is lit at level n iff rank < n. The ranks are a permutation
** of 0..L-1, so level n lights exactly n dots and the lit sets are nested (a brighter
** level only adds dots: tones never flicker between patterns).
**   dispersed  ordered dither (Bayer): each new dot as far as possible from those lit;
**              finest texture, the default.
**   clustered  one cluster growing from the centre of the cell in a spiral: reads as a
**              dot screen, like print; coarser but steadier on a blooming tube.
**   line       dots fill horizontal lines first: reads as a raster of scan lines.
*/
#include "patterns/halftone.h"

#include <assert.h>
#include <stddef.h>
#include <string.h>

/* ---- grey -> level (Weber-Fechner, derivation above) ------------------------------ */

/* 3x3 cell: level(G) = round(10^(G/255) - 1), 0..9. */
static const uint8_t level3[256] = {
   0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,   /* G   0.. 15 */
   0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,   /* G  16.. 31 */
   0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  1,  1,  1,   /* G  32.. 47 */
   1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  48.. 63 */
   1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  64.. 79 */
   1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  80.. 95 */
   1,  1,  1,  1,  1,  1,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,   /* G  96..111 */
   2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,   /* G 112..127 */
   2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  3,  3,  3,  3,  3,   /* G 128..143 */
   3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,   /* G 144..159 */
   3,  3,  3,  3,  3,  3,  3,  4,  4,  4,  4,  4,  4,  4,  4,  4,   /* G 160..175 */
   4,  4,  4,  4,  4,  4,  4,  4,  4,  4,  4,  4,  4,  5,  5,  5,   /* G 176..191 */
   5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,  5,   /* G 192..207 */
   6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,  6,   /* G 208..223 */
   7,  7,  7,  7,  7,  7,  7,  7,  7,  7,  7,  7,  7,  7,  8,  8,   /* G 224..239 */
   8,  8,  8,  8,  8,  8,  8,  8,  8,  8,  9,  9,  9,  9,  9,  9,   /* G 240..255 */
};

/* 4x4 cell: level(G) = round(17^(G/255) - 1), 0..16. */
static const uint8_t level4[256] = {
   0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,   /* G   0.. 15 */
   0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,  0,   /* G  16.. 31 */
   0,  0,  0,  0,  0,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  32.. 47 */
   1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  48.. 63 */
   1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,  1,   /* G  64.. 79 */
   1,  1,  1,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,   /* G  80.. 95 */
   2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,  2,   /* G  96..111 */
   2,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,  3,   /* G 112..127 */
   3,  3,  3,  3,  3,  3,  3,  3,  4,  4,  4,  4,  4,  4,  4,  4,   /* G 128..143 */
   4,  4,  4,  4,  4,  4,  4,  4,  4,  4,  5,  5,  5,  5,  5,  5,   /* G 144..159 */
   5,  5,  5,  5,  5,  5,  5,  5,  5,  6,  6,  6,  6,  6,  6,  6,   /* G 160..175 */
   6,  6,  6,  6,  6,  6,  7,  7,  7,  7,  7,  7,  7,  7,  7,  7,   /* G 176..191 */
   7,  8,  8,  8,  8,  8,  8,  8,  8,  8,  8,  9,  9,  9,  9,  9,   /* G 192..207 */
   9,  9,  9,  9, 10, 10, 10, 10, 10, 10, 10, 10, 11, 11, 11, 11,   /* G 208..223 */
  11, 11, 11, 11, 12, 12, 12, 12, 12, 12, 12, 13, 13, 13, 13, 13,   /* G 224..239 */
  13, 14, 14, 14, 14, 14, 14, 15, 15, 15, 15, 15, 15, 16, 16, 16,   /* G 240..255 */
};

/* ---- level -> dots: the families -------------------------------------------------- */

struct pat_cell {
  const char *name;               /* family name, as pattern=NAME spells it */
  int cell;                       /* 3 or 4 */
  uint8_t rank[PAT_CELL_MAX][PAT_CELL_MAX];  /* rank[cy][cx], cy from the top of the cell;
                                     lit at level n iff rank < n; unused entries 0 */
  uint16_t mask[PAT_CELL_MAX * PAT_CELL_MAX + 1];  /* mask[n]: the dots lit at level n
                                     (bit cy*cell + cx), from the same ranks at compile
                                     time (PAT_MASKS3/4 below) */
};

/* The dot masks of a family, as constant expressions of its ranks r0.. (row by row from
   the top): bit k is set at level n iff r_k < n. */
#define PAT_B_(r, k, n) ((unsigned)((r) < (n)) << (k))
#define PAT_M3_(n, a, b, c, d, e, f, g, h, i)                                              \
  (uint16_t)(PAT_B_(a, 0, n) | PAT_B_(b, 1, n) | PAT_B_(c, 2, n) | PAT_B_(d, 3, n) |       \
             PAT_B_(e, 4, n) | PAT_B_(f, 5, n) | PAT_B_(g, 6, n) | PAT_B_(h, 7, n) |       \
             PAT_B_(i, 8, n))
#define PAT_MASKS3(...)                                                                    \
  { PAT_M3_(0, __VA_ARGS__), PAT_M3_(1, __VA_ARGS__), PAT_M3_(2, __VA_ARGS__),             \
    PAT_M3_(3, __VA_ARGS__), PAT_M3_(4, __VA_ARGS__), PAT_M3_(5, __VA_ARGS__),             \
    PAT_M3_(6, __VA_ARGS__), PAT_M3_(7, __VA_ARGS__), PAT_M3_(8, __VA_ARGS__),             \
    PAT_M3_(9, __VA_ARGS__) }
#define PAT_M4_(n, a, b, c, d, e, f, g, h, i, j, k, l, m, o, p, q)                         \
  (uint16_t)(PAT_B_(a, 0, n) | PAT_B_(b, 1, n) | PAT_B_(c, 2, n) | PAT_B_(d, 3, n) |       \
             PAT_B_(e, 4, n) | PAT_B_(f, 5, n) | PAT_B_(g, 6, n) | PAT_B_(h, 7, n) |       \
             PAT_B_(i, 8, n) | PAT_B_(j, 9, n) | PAT_B_(k, 10, n) | PAT_B_(l, 11, n) |     \
             PAT_B_(m, 12, n) | PAT_B_(o, 13, n) | PAT_B_(p, 14, n) | PAT_B_(q, 15, n))
#define PAT_MASKS4(...)                                                                    \
  { PAT_M4_(0, __VA_ARGS__), PAT_M4_(1, __VA_ARGS__), PAT_M4_(2, __VA_ARGS__),             \
    PAT_M4_(3, __VA_ARGS__), PAT_M4_(4, __VA_ARGS__), PAT_M4_(5, __VA_ARGS__),             \
    PAT_M4_(6, __VA_ARGS__), PAT_M4_(7, __VA_ARGS__), PAT_M4_(8, __VA_ARGS__),             \
    PAT_M4_(9, __VA_ARGS__), PAT_M4_(10, __VA_ARGS__), PAT_M4_(11, __VA_ARGS__),           \
    PAT_M4_(12, __VA_ARGS__), PAT_M4_(13, __VA_ARGS__), PAT_M4_(14, __VA_ARGS__),          \
    PAT_M4_(15, __VA_ARGS__), PAT_M4_(16, __VA_ARGS__) }
/* A family: its ranks written once, row by row, giving both rank[][] and mask[]. */
#define PAT_CELL3(name, a, b, c, d, e, f, g, h, i)                                          \
  { name, 3, { { a, b, c }, { d, e, f }, { g, h, i } }, PAT_MASKS3(a, b, c, d, e, f, g, h, i) }
#define PAT_CELL4(name, a, b, c, d, e, f, g, h, i, j, k, l, m, o, p, q)                     \
  { name, 4, { { a, b, c, d }, { e, f, g, h }, { i, j, k, l }, { m, o, p, q } },           \
    PAT_MASKS4(a, b, c, d, e, f, g, h, i, j, k, l, m, o, p, q) }

/* The ranks below read as the cell looks on the tube: first row = top row of the cell. */
static const struct pat_cell families[] = {
  PAT_CELL3("dispersed", /* 3x3 ordered dither (the classic 3x3 dither matrix) */
     0,  7,  3,          /* top:    1st, 8th, 4th dot */
     6,  5,  2,          /* middle: 7th, 6th, 3rd */
     4,  1,  8),         /* bottom: 5th, 2nd, 9th */
  PAT_CELL4("dispersed", /* 4x4 Bayer matrix: each dot far from those lit */
     0,  8,  2, 10,      /* top row:  1st, 9th, 3rd, 11th dot */
    12,  4, 14,  6,      /* row 2:    13th, 5th, 15th, 7th */
     3, 11,  1,  9,      /* row 3:    4th, 12th, 2nd, 10th */
    15,  7, 13,  5),     /* bottom:   16th, 8th, 14th, 6th */
  PAT_CELL3("clustered", /* 3x3 cluster: centre, then the 4 sides, then corners */
     5,  2,  6,          /* top:    corner, side (3rd), corner */
     3,  0,  1,          /* middle: side (4th), CENTRE first, side (2nd) */
     8,  4,  7),         /* bottom: corner (last), side (5th), corner */
  PAT_CELL4("clustered", /* 4x4 cluster: the middle 2x2, then a spiral outward */
    12,  5,  6, 13,      /* top row: corners late */
     4,  0,  1,  7,      /* row 2:   middle dots 1st and 2nd */
    11,  3,  2,  8,      /* row 3:   middle dots 4th and 3rd */
    15, 10,  9, 14),     /* bottom:  last corner 16th */
  PAT_CELL3("line", /* 3x3 lines: the middle row fills first */
     3,  7,  5,          /* top:    after the middle row, alternating with bottom */
     0,  2,  1,          /* middle: 1st, 3rd, 2nd dot (full line at level 3) */
     4,  8,  6),         /* bottom: alternating with the top row */
  PAT_CELL4("line", /* 4x4 lines: rows 2 and 4 first (every other line) */
     8, 12, 10, 14,      /* top row: third line to fill */
     0,  4,  2,  6,      /* row 2:   first line (with row 4, dot by dot) */
     9, 13, 11, 15,      /* row 3:   fourth line */
     1,  5,  3,  7),     /* bottom:  second line; rows 2 and 4 full at level 8 */
};

#define NFAMILY_ROWS ((int)(sizeof families / sizeof families[0]))

int pat_find(const char *name, int cell, const struct pat_cell **out)
{
  if (name == NULL || name[0] == '\0') name = PAT_DEFAULT;
  for (int k = 0; k < NFAMILY_ROWS; k++)
    if (families[k].cell == cell && strcmp(families[k].name, name) == 0) {
      *out = &families[k];
      return T74_OK;
    }
  return T74_EINPUT;
}

const char *pat_family(int k)
{
  /* Each family has one row per cell size, 3x3 first: the 3x3 rows name them. */
  int seen = 0;
  for (int r = 0; r < NFAMILY_ROWS; r++)
    if (families[r].cell == PAT_CELL_MIN && seen++ == k) return families[r].name;
  return NULL;
}

int pat_levels(int cell)
{
  return (cell == 3 || cell == 4) ? cell * cell + 1 : 0;
}

int pat_level(int cell, int grey)
{
  if (grey < 0) grey = 0;
  if (grey > 255) grey = 255;
  if (cell == 3) return level3[grey];
  if (cell == 4) return level4[grey];
  return 0;
}

int pat_cell_size(const struct pat_cell *p) { return p->cell; }

const char *pat_cell_name(const struct pat_cell *p) { return p->name; }

int pat_rank(const struct pat_cell *p, int cx, int cy)
{
  assert(cx >= 0 && cx < p->cell && cy >= 0 && cy < p->cell);
  return p->rank[cy][cx];
}

void pat_cell_dots(const struct pat_cell *p, int level, uint16_t *mask)
{
  int top = p->cell * p->cell;
  *mask = p->mask[level < 0 ? 0 : level > top ? top : level];
}

int pat_grid_w(int cell) { return cell > 0 ? TUBE_W / cell : 0; }

int pat_grid_h(int cell) { return cell > 0 ? TUBE_H / cell : 0; }

void pat_dot_xy(int cell, int i, int j, int cx, int cy, int *x, int *y)
{
  int x0, y0;
  pat_cell_origin(cell, i, j, &x0, &y0);
  *x = x0 + cx;
  *y = y0 - cy;
}

/* Dot k of a cell (bit k of a mask): its column and row, for 3x3 and 4x4 cells. */
static const uint8_t dot_cx[2][16] = { { 0, 1, 2, 0, 1, 2, 0, 1, 2 },
                                       { 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3 } };
static const uint8_t dot_cy[2][16] = { { 0, 0, 0, 1, 1, 1, 2, 2, 2 },
                                       { 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3 } };

int pat_emit_point(const struct pat_cell *p, int i, int j, int level,
                   const struct sink *s)
{
  int cell = p->cell;
  /* in the grid: i < floor(TUBE_W / cell) exactly when cell (i + 1) <= TUBE_W */
  if (i < 0 || i >= TUBE_W || cell * (i + 1) > TUBE_W || j < 0 || j >= TUBE_H ||
      cell * (j + 1) > TUBE_H)
    return T74_EINPUT;
  uint16_t mask;                          /* the dots lit at this level */
  pat_cell_dots(p, level, &mask);
  int x0, y0;
  pat_cell_origin(cell, i, j, &x0, &y0);
  return pat_emit_dots(cell, x0, y0, mask, s);
}

int pat_emit_dots(int cell, int x0, int y0, unsigned mask, const struct sink *s)
{
  /* bit k = cy * cell + cx: rising bits are the top row of the cell first, each row left
     to right (pat_dot_xy's placement, one dot at a time) */
  const uint8_t *cxs = dot_cx[cell - PAT_CELL_MIN], *cys = dot_cy[cell - PAT_CELL_MIN];
  for (unsigned m = mask; m; m &= m - 1) {
    int k = __builtin_ctz(m);
    int rc = sink_point(s, x0 + cxs[k], y0 - cys[k]);
    if (rc != T74_OK) return rc;
  }
  return T74_OK;
}
