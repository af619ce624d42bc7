/*
** pipeline.c — one rendering job (see pipeline.h).
**
** This file contains code to read render's options and run the pipeline of paper 003
** Fig. 1 point by point: each point, as soon as its visible face is known, becomes a
** halftone cell whose dots go to the sinks in the order the 1974 program displayed them.
** Outputs are one set (display/outfile.h): all opened and checked before the work starts,
** written when everything succeeded and committed together, so a failure leaves no file
** created or changed.
**
** A background picture goes the 1974 way (patterns/scanner.h): scanned on the drum,
** converted to halftone levels, packed 4 to a word onto the modelled disk, and read back a
** row at a time while the grid is scanned; its disk time and unpacking count in
** hitac10_seconds (stage "scanner"), the scanning itself (input time) in scanner_seconds.
**
** A Tektronix stream (`--input tek`, or a file whose first byte is a Tek control code,
** display/tek.h) is not a scene: it is decoded straight onto the tube (run_tek below), and
** only the outputs that a tube alone can give are written (-o, --dump tube, --dump points,
** --stats with the renderer's fields at zero).
*/
#include "cli/pipeline.h"

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "display/image.h"
#include "display/sink.h"
#include "display/tek.h"
#include "display/tube.h"
#include "emu/core.h"
#include "emu/cost.h"
#include "emu/file.h"
#include "emu/status.h"
#include "patterns/halftone.h"
#include "patterns/picture.h"
#include "patterns/scanner.h"
#include "render/effects.h"
#include "effects/fx.h"
#include "effects/shadow.h"
#include "effects/smooth.h"
#include "render/face_run.h"
#include "render/points.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/turn.h"

#define DEFAULT_CORE_WORDS 16384u       /* HITAC-10 of paper 003: 16 kW x 16 bit */

static const char *const dump_names[] = { "ids", "grey", "tube", "points", "tables", "core" };


/* What the point callback needs: renderer, halftone, sinks, dump buffers. */
struct pipeline {
  struct render *r;                 /* the 1974 engine (NULL under --engine points) */
  const struct points *pts;         /* the points engine (NULL under --engine 1974) */
  const struct mapped *map;         /* the Mapper's faces, of either engine */
  bool timed;                       /* the 1974 engine: its clock, first dot, figures */
  const struct pat_cell *pat;
  int cell, W, H;
  struct scan_image *scan;          /* the background picture as on the disk, or NULL */
  struct cost scanner;              /* display-time work of the background: unpacking, and
                                       moving the rows read from the disk into core */
  struct sink out;
  struct tube *tube_direct;         /* out is this tube, then `also` when set: each cell
                                       stored in one write (tube_write_dots), or NULL */
  const struct sink *also;          /* with tube_direct: the one other sink, given the
                                       cell's dots one by one after it is stored, or NULL */
  uint8_t level[256];               /* pat_level(cell, grey) for grey 0..255 */
  uint16_t mask[PAT_CELL_MAX * PAT_CELL_MAX + 1];  /* pat_cell_dots(pat, level) */
  uint32_t *ids;                    /* face number seen per point, 0 none (--dump ids) */
  uint8_t *grey;
  int *face;                        /* the effects stage's frame (NULL: no effects) */
  bool grey_pending;                /* points_emit left grey to the effects (fx_frame's
                                       face_grey) */
  int *face_drawn;                  /* not NULL: points_emit left the frame's faces in the
                                       points engine's buffer, not copied to face */
  const int *ids_face;              /* not NULL: the frame's faces (an index in map->f, or
                                       -1), ids not yet written from them (dumps_settle) */
  bool greys_face;                  /* and the greys neither (each the face's; for none,
                                       greys_bg's, or 0 without it) */
  const uint8_t *greys_bg;          /* with greys_face: the background's greys, W x H, or NULL */
  struct cost display;              /* halftone + display stage */
  struct cost fx;                   /* the effects stage (effects/fx.h) */
  struct core **fx_keep;            /* the points engine's effects core between frames */
  struct smooth_scene **fx_smooth;  /* the smoothing's scene part between frames */
  struct fx_textures **fx_tex;      /* the scene's textures between frames */
  struct shadow_keep **fx_shadow;   /* the shadows in space between frames */
  const struct bg_cells *bgc;       /* the background's cells, kept for every frame, or NULL */
  struct tube_keys **tk_keep;       /* run_effects' table of a row's cells by grey (the job's
                                       pattern alone: p->level, p->mask), made at its first
                                       frame and kept for the others; NULL: made each frame */
  const struct job_hooks *hooks;
  const struct cost_params *params;
  double states[COST_NCLASS];       /* machine states of one operation of each class */
  double first_dot;                 /* 1974 time the first lit dot reached the tube (< 0: none yet) */
};

void job_usage(FILE *f)
{
  fprintf(f,
    "render options:\n"
    "  -o FILE.png            the picture as the storage tube shows it\n"
    "  --cell 3|4             halftone cell (overrides the scene)\n"
    "  --effects \"K=V ...\"    replaces the scene's effects line\n"
    "  --core WORDS           core memory in 16-bit words (default 16384)\n"
    "  --stats FILE.json      statistics\n"
    "  --dump KIND=FILE       ids | grey | tube | points | tables | core (repeatable)\n"
    "  --view X0 Y0 Z0        eye for .obj/.off imports\n"
    "  --window XL YB XR YT   window for .obj/.off imports\n"
    "  --turn AZ,EL           turn an .obj/.off model (degrees; default 30,20)\n"
    "  --input s74|obj|off|tek  input format (default: a Tek stream by its first byte,\n"
    "                         else by extension)\n"
    "  --hitac NAME=VALUE     change a cost-model constant (see `tube74 params`)\n"
    "  --matrix auto|dense|sparse   priority matrix store (default auto)\n"
    "  --frames K             render the loaded scene K times (outputs written once;\n"
    "                         --stats gives frame_seconds, the median frame)\n"
    "  --arith exact|hitac    decisions in exact arithmetic (default) or in the HITAC-10's\n"
    "                         word sizes as the 1974 program would make them\n"
    "  --engine 1974|points|auto  the 1974 program with every HITAC-10 figure, or exact\n"
    "                         visibility at each point centre without them (not\n"
    "                         aa=multiscan|area|exact, edges=, --arith hitac, --dump\n"
    "                         tables|core); auto (default): points for .obj/.off imports\n"
    "                         that need nothing of the 1974 program, else 1974\n");
}

static int parse_long(const char *s, long lo, long hi, long *out)
{
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi) return 0;
  *out = v;
  return 1;
}

static int bad_usage(struct t74_error *err, const char *msg, const char *arg)
{
  return t74_fail(err, T74_EINPUT, "tube74: %s%s%s", msg, arg ? ": " : "", arg ? arg : "");
}

static int turn_misplaced(const struct job *o, struct t74_error *err);

int job_parse(int argc, char **argv, int first, struct job *o, job_opt_fn extra, void *ctx,
              struct t74_error *err)
{
  memset(o, 0, sizeof *o);
  o->core_words = DEFAULT_CORE_WORDS;
  o->store = PRIO_AUTO;
  cost_params_default(&o->params);
  for (int k = first; k < argc; k++) {
    const char *a = argv[k];
    long v;
    if (extra) {
      int took = extra(ctx, argc, argv, &k, err);
      if (took < 0 || took > 1) return err->status ? err->status : T74_EINPUT;
      if (took == 1) continue;
    }
#define NEED(n) do { if (k + (n) >= argc) return bad_usage(err, "missing value after", a); } while (0)
    if (!strcmp(a, "-o")) { NEED(1); o->png = argv[++k]; }
    else if (!strcmp(a, "--engine")) {
      NEED(1);
      const char *m = argv[++k];
      if (!strcmp(m, "auto")) o->engine = JOB_ENGINE_AUTO;
      else if (!strcmp(m, "1974")) o->engine = JOB_ENGINE_1974;
      else if (!strcmp(m, "points")) o->engine = JOB_ENGINE_POINTS;
      else return bad_usage(err, "--engine takes 1974, points or auto", m);
    }
    else if (!strcmp(a, "--stats")) { NEED(1); o->stats = argv[++k]; }
    else if (!strcmp(a, "--effects")) { NEED(1); o->effects = argv[++k]; }
    else if (!strcmp(a, "--cell")) {
      NEED(1);
      if (!parse_long(argv[++k], 3, 4, &v)) return bad_usage(err, "--cell takes 3 or 4", argv[k]);
      o->cell = (int)v;
    } else if (!strcmp(a, "--core")) {
      NEED(1);
      if (!parse_long(argv[++k], 1, 2147483647L, &v))
        return bad_usage(err, "--core takes a number of words, 1 .. 2^31-1", argv[k]);
      o->core_words = (uint32_t)v;
      o->machine_given = true;
      o->core_given = true;
    } else if (!strcmp(a, "--dump")) {
      NEED(1);
      const char *spec = argv[++k], *eq = strchr(spec, '=');
      if (!eq || !eq[1]) return bad_usage(err, "--dump takes KIND=FILE", spec);
      int kind = -1;
      for (int d = 0; d < (int)(sizeof dump_names / sizeof *dump_names); d++)
        if (strlen(dump_names[d]) == (size_t)(eq - spec) && !strncmp(spec, dump_names[d], (size_t)(eq - spec)))
          kind = d;
      if (kind < 0) return bad_usage(err, "unknown --dump kind (ids, grey, tube, points, tables, core)", spec);
      if (o->ndump == JOB_MAX_DUMPS) return bad_usage(err, "too many --dump options", spec);
      o->dump_kind[o->ndump] = kind;
      o->dump_path[o->ndump++] = eq + 1;
    } else if (!strcmp(a, "--view")) {
      NEED(3);
      for (int c = 0; c < 3; c++) {
        if (!parse_long(argv[++k], -32768, 32767, &v)) return bad_usage(err, "--view takes three integers", argv[k]);
        o->sopts.view[c] = (int32_t)v;
      }
      o->sopts.has_view = true;
    } else if (!strcmp(a, "--window")) {
      NEED(4);
      for (int c = 0; c < 4; c++) {
        if (!parse_long(argv[++k], -32768, 32767, &v)) return bad_usage(err, "--window takes four integers", argv[k]);
        o->sopts.window[c] = (int32_t)v;
      }
      if (o->sopts.window[0] >= o->sopts.window[2] || o->sopts.window[1] >= o->sopts.window[3])
        return bad_usage(err, "--window needs XL < XR and YB < YT", NULL);
      o->sopts.has_window = true;
    } else if (!strcmp(a, "--turn")) {
      NEED(1);
      if (turn_parse(argv[++k], &o->sopts.turn[0], &o->sopts.turn[1]))
        return bad_usage(err, "--turn takes AZ,EL in degrees (e.g. 30,20), got", argv[k]);
      o->sopts.has_turn = true;
    } else if (!strcmp(a, "--input")) {
      NEED(1);
      o->sopts.input = argv[++k];
      if (strcmp(o->sopts.input, "s74") && strcmp(o->sopts.input, "obj") && strcmp(o->sopts.input, "off") &&
          strcmp(o->sopts.input, "tek"))
        return bad_usage(err, "--input takes s74, obj, off or tek", o->sopts.input);
    } else if (!strcmp(a, "--hitac")) {
      NEED(1);
      if (cost_params_set(&o->params, argv[++k], err) != T74_OK) return err->status;
      o->machine_given = true;
    } else if (!strcmp(a, "--frames")) {
      NEED(1);
      if (!parse_long(argv[++k], 1, 1000000L, &v))
        return bad_usage(err, "--frames takes a number of frames, 1 .. 1000000", argv[k]);
      o->frames = (int)v;
    } else if (!strcmp(a, "--arith")) {
      NEED(1);
      const char *m = argv[++k];
      if (!strcmp(m, "exact")) o->arith = GEOM_EXACT;
      else if (!strcmp(m, "hitac")) o->arith = GEOM_HITAC;
      else return bad_usage(err, "--arith takes exact or hitac", m);
    } else if (!strcmp(a, "--matrix")) {
      NEED(1);
      const char *m = argv[++k];
      if (!strcmp(m, "auto")) o->store = PRIO_AUTO;
      else if (!strcmp(m, "dense")) o->store = PRIO_DENSE;
      else if (!strcmp(m, "sparse")) o->store = PRIO_SPARSE;
      else return bad_usage(err, "--matrix takes auto, dense or sparse", m);
      o->machine_given = true;
    } else if (a[0] == '-') {
      return bad_usage(err, "unknown option", a);
    } else if (!o->scene) {
      o->scene = a;
    } else {
      return bad_usage(err, "more than one scene given", a);
    }
#undef NEED
  }
  if (!o->scene) return bad_usage(err, "no scene given", NULL);
  if (turn_misplaced(o, err)) return err->status;   /* before any device or output opens */
  return T74_OK;
}

/* The 1974 display-run time so far: every stage's counted work, the background's
** unpacking and its disk reads. Read at every lit point, so it adds up only the counts
** the 1974 figure uses (n[], not x[]) with the classes' states taken once (p->states):
** the same double as cost_seconds of the stages' merged counts (issue 19: merging the
** stages' whole counters and working out each class's states anew at every point was
** 11% of the street's run). */
static double pipeline_seconds(const struct pipeline *p)
{
  if (!p->timed) return 0;                  /* --engine points: no 1974 time */
  uint64_t n[COST_NCLASS];
  for (int k = 0; k < COST_NCLASS; k++) {
    uint64_t sum = p->display.n[k] + p->scanner.n[k] + p->fx.n[k];
    for (int s = 0; s < RS_NSTAGE; s++) sum += p->r->cost[s].n[k];
    n[k] = sum;
  }
  double t = cost_seconds_of(n, p->states, p->params);
  if (p->scan) t += scan_disk_seconds(p->scan);
  return t;
}

/* A point's halftone level: grey is its intensity; a background point whose intensity no
** effect changed takes its level off the disk (4 bits: 4x4's level 16 is 15). */
static inline __attribute__((always_inline))
int point_level(struct pipeline *p, int i, int j, int face, int grey, bool bg_level)
{
  return face < 0 && bg_level && p->scan ? scan_level(p->scan, i, j, &p->scanner)
           : (unsigned)grey < 256 ? p->level[grey] : pat_level(p->cell, grey);
}

/* The tube: pat_emit_point's dots of point (i, j) in its order, as one cell write (dots:
** the cell's pattern word; a cell of the grid lies on the tube: no dot fails); then the
** other sink also, if any, each dot as pat_emit_point gives it (it does not read the tube). */
static inline __attribute__((always_inline))
int cell_to_tube(struct tube *t, const struct sink *also, int cell, int i, int j, unsigned dots)
{
  if (!dots) return T74_OK;
  int x0, y0;
  pat_cell_origin(cell, i, j, &x0, &y0);
  int st = tube_write_dots(t, x0, y0, cell, dots);
  if (st != T74_OK || !also) return st;
  return pat_emit_dots(cell, x0, y0, dots, also);
}

/* A point's halftone cell of that level to the sinks. */
static inline __attribute__((always_inline))
int cell_out(struct pipeline *p, int i, int j, int level)
{
  if (p->tube_direct && i >= 0 && i < p->W && j >= 0 && j < p->H && level >= 0 &&
      level <= p->cell * p->cell)
    return cell_to_tube(p->tube_direct, p->also, p->cell, i, j, p->mask[level]);
  return pat_emit_point(p->pat, i, j, level, &p->out);
}

/* A point's halftone cell to the sinks, its time and counts. */
static inline __attribute__((always_inline))
int emit_point(struct pipeline *p, int i, int j, int face, int grey, bool bg_level)
{
  int level = point_level(p, i, j, face, grey, bg_level);
  bool tick = p->hooks && p->hooks->clock;
  if (p->timed && level > 0 && (tick || p->first_dot < 0)) {
    /* the clock before a point that lights dots (a point with none gives the beam no work,
       and the clock only goes forward: the beam takes the larger time, and the last tick
       comes after the scan) */
    double now = pipeline_seconds(p);
    if (tick) p->hooks->clock(p->hooks->clock_ctx, now);
    /* the first dot: 003 cuts and scans bottom to top so that the picture shows while it
       is computed; this is when the viewer first sees something (its own lookups not
       counted) */
    if (p->first_dot < 0) p->first_dot = now;
  }
  /* per point: intensity and level lookups, the cell's pattern word, then one display
     command per lit dot */
  COST_ADD_N(&p->display, COST_MEM, 4);
  COST_ADD_N(&p->display, COST_SHIFT, p->cell * p->cell);
  COST_ADD_N(&p->display, COST_IO, level);
  return cell_out(p, i, j, level);
}

/* Point (i, j) (at = j W + i) sees face (< 0: none): its id and grey kept for the dumps;
** its grey. */
static inline __attribute__((always_inline))
int point_seen(struct pipeline *p, int i, int j, size_t at, int face)
{
  int grey;
  uint32_t id = 0;
  if (face >= 0) {
    grey = p->map->f[face].grey;
    id = p->map->f[face].id;
  } else {
    grey = p->scan ? scan_grey(p->scan, i, j) : 0;
  }
  p->ids[at] = id;
  p->grey[at] = (uint8_t)grey;
  return grey;
}

static int on_point(void *ctx, int i, int j, int face)
{
  struct pipeline *p = ctx;
  if (p->hooks && p->hooks->watch) {
    int ws = p->hooks->watch(p->hooks->watch_ctx, p->r, i, j, face);
    if (ws != T74_OK) return ws;
  }
  size_t at = (size_t)j * (size_t)p->W + (size_t)i;
  int grey = point_seen(p, i, j, at, face);
  if (p->face) { p->face[at] = face; return T74_OK; }   /* effects: emitted after fx_run */
  return emit_point(p, i, j, face, grey, true);
}

/* A grid row's cells to the tube alone (p->tube_direct, no other sink, untimed), each
** point's as emit_point stores it: the cells of levels 0 .. cell * cell gathered into one
** tube_write_cells, a cell of any other level through cell_out in its turn. */
struct row_cells {
  int j, x0, y0, i0;                /* row j's cell 0 at (x0, y0); cells i0 .. not stored */
  uint16_t masks[TUBE_W];           /* W <= TUBE_W */
};

static void row_start(const struct pipeline *p, struct row_cells *rc, int j)
{
  rc->j = j;
  rc->i0 = 0;
  pat_cell_origin(p->cell, 0, j, &rc->x0, &rc->y0);
}

/* point i of the row, of a level that is not 0 .. cell * cell */
static int row_odd(struct pipeline *p, struct row_cells *rc, int i, int level)
{
  int st = tube_write_cells(p->tube_direct, rc->x0 + rc->i0 * p->cell, rc->y0, p->cell,
                            rc->masks + rc->i0, i - rc->i0);
  rc->i0 = i + 1;
  return st == T74_OK ? cell_out(p, i, rc->j, level) : st;
}

static int row_end(struct pipeline *p, struct row_cells *rc)
{
  return tube_write_cells(p->tube_direct, rc->x0 + rc->i0 * p->cell, rc->y0, p->cell,
                          rc->masks + rc->i0, p->W - rc->i0);
}

/* Each mapped face's flat grey at its index + 1, 0 at 0 (no face); NULL when the host has
   no room. */
static uint8_t *face_greys(const struct mapped *map)
{
  uint8_t *g = malloc((size_t)map->nface + 1);
  if (!g) return NULL;
  g[0] = 0;
  for (int k = 0; k < map->nface; k++) g[k + 1] = (uint8_t)map->f[k].grey;
  return g;
}

/* A grey's cell (greys_run's table): the cell's pattern word in the low 16 bits; GREY_ODD
** where the grey's level is not 0 .. cell * cell. */
#define GREY_ODD UINT32_MAX

/* The effects' points i .. of a row whose greys' levels are 0 .. cc, up to the first other
** one: their cells as emit_point gives them; its index, or n. cell_of: each grey's cell
** (GREY_ODD). Four points a step, no branch but the loop's and the odd grey's. */
static int greys_run(const uint8_t *greys, int i, int n, const uint32_t *cell_of,
                     uint16_t *masks)
{
  for (; i + 4 <= n; i += 4) {
    const uint32_t c0 = cell_of[greys[i]], c1 = cell_of[greys[i + 1]];
    const uint32_t c2 = cell_of[greys[i + 2]], c3 = cell_of[greys[i + 3]];
    if ((c0 & c1 & c2 & c3) == GREY_ODD || c0 == GREY_ODD || c1 == GREY_ODD ||
        c2 == GREY_ODD || c3 == GREY_ODD)
      break;                                /* the points one by one below */
    masks[i] = (uint16_t)c0;
    masks[i + 1] = (uint16_t)c1;
    masks[i + 2] = (uint16_t)c2;
    masks[i + 3] = (uint16_t)c3;
  }
  for (; i < n; i++) {
    const uint32_t c = cell_of[greys[i]];
    if (c == GREY_ODD) break;
    masks[i] = (uint16_t)c;
  }
  return i;
}

/* masks[0 .. n) the cells of greys[0 .. n) by mask_of, a point at a time, four a step (an
** empty asm: no vector form of the loop, which gcc would build of 16 scalar lookups
** through the stack, half again as many instructions). */
static inline void greys_lookup(const uint8_t *greys, int n, const uint16_t *mask_of,
                                uint16_t *masks)
{
  int i = 0;
  for (; i + 4 <= n; i += 4) {
#ifdef __GNUC__
    __asm__("" : "+r"(i));
#endif
    masks[i] = mask_of[greys[i]];
    masks[i + 1] = mask_of[greys[i + 1]];
    masks[i + 2] = mask_of[greys[i + 2]];
    masks[i + 3] = mask_of[greys[i + 3]];
  }
  for (; i < n; i++) masks[i] = mask_of[greys[i]];
}

/* A row's cells from its greys, every grey's level 0 .. cc (no GREY_ODD in mask_of, a
** grey's pattern word): as greys_run, with nothing to test. */
static void greys_cells(const uint8_t *greys, int n, const uint16_t *mask_of, uint16_t *masks)
{
  int i = 0;
#ifdef __SSE2__
  /* sixteen points of one grey (a background, a flat face): one cell for them all */
  for (; i + 16 <= n; i += 16) {
    const __m128i g = _mm_loadu_si128((const __m128i *)(const void *)(greys + i));
    if ((unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(g, _mm_set1_epi8((char)greys[i]))) == 0xffffu) {
      const __m128i mv = _mm_set1_epi16((short)mask_of[greys[i]]);
      _mm_storeu_si128((__m128i *)(void *)(masks + i), mv);
      _mm_storeu_si128((__m128i *)(void *)(masks + i + 8), mv);
      continue;
    }
    greys_lookup(greys + i, 16, mask_of, masks + i);   /* else a point at a time */
  }
#endif
  greys_lookup(greys + i, n - i, mask_of, masks + i);
}

/* The effects stage: run the effects over the scanned frame, then send its points to the
** sinks in the scan's order (bottom row first, left to right). */
static int run_effects(struct pipeline *p, const struct scene *s, const struct effects *e,
                       const struct vis_grid *g, struct fx_stats *fst, struct t74_error *err)
{
  size_t n = (size_t)p->W * (size_t)p->H;
  uint8_t *bg = NULL;
  if (p->scan) {
    if (!(bg = malloc(n))) return t74_fail(err, T74_EIO, "out of host memory");
    for (int j = 0; j < p->H; j++)
      for (int i = 0; i < p->W; i++) bg[(size_t)j * (size_t)p->W + (size_t)i] = (uint8_t)scan_grey(p->scan, i, j);
  }
  /* the greys before the effects: a background point no effect changed takes its level
     off the disk (point_level), so only with a background */
  uint8_t *flat = p->scan ? malloc(n) : NULL;
  if (p->scan && !flat) { free(bg); return t74_fail(err, T74_EIO, "out of host memory"); }
  if (flat) memcpy(flat, p->grey, n);
  int *face = p->face;                      /* the frame's faces */
  if (p->face_drawn) {
    /* the points engine's buffer, the faces as drawn, taken as the frame unless an
       effect after fx_points asks the engine for a row as drawn (aa=super: fx_see_row
       reads the buffer); fx_points itself asks for a row before it writes that row */
    if (e->aa == EFFECTS_AA_NONE) face = p->face_drawn;
    else memcpy(face, p->face_drawn, n * sizeof *face);
    p->face_drawn = NULL;
  }
  struct fx_frame f = { p->W, p->H, p->cell, face, p->grey, bg, NULL, NULL };
  uint8_t *fgrey = NULL;                    /* each face's grey at its index + 1 */
  if (p->grey_pending) {
    p->grey_pending = false;
    if (!(fgrey = face_greys(p->map))) {
      free(flat); free(bg);
      return t74_fail(err, T74_EIO, "out of host memory");
    }
    f.face_grey = fgrey;
  }
  struct fx_engine eng;                     /* the engine that drew the frame (effects/see.h) */
  int st = T74_OK;
  if (p->r) fx_engine_1974(&eng, p->r, g);
  else st = fx_engine_points(&eng, p->pts, g, p->fx_keep, err);
  eng.smooth_keep = p->fx_smooth;
  eng.tex_keep = p->fx_tex;
  eng.shadow_keep = p->fx_shadow;
  if (st == T74_OK) st = fx_run(&eng, s, e, &f, fst, &p->fx, err);
  fx_engine_free(&eng);
  free(fgrey);
  if (st == T74_OK && p->tube_direct && !p->also && !p->timed) {
    /* to the tube alone, untimed (the points engine): emit_point's cells a row at a time
       (issue 19); the ids are left in the frame's faces until a dump asks (dumps_settle),
       and no display counts are kept (only the 1974 engine's figures report them) */
    struct row_cells rc;
    const int cc = p->cell * p->cell;
    uint32_t gcell[256];                    /* each grey's cell (greys_run) */
    uint16_t gmask[256];                    /* the same when none is odd (greys_cells) */
    bool odd = false;
    for (int v = 0; v < 256; v++) {
      gcell[v] = p->level[v] <= cc ? p->mask[p->level[v]] : GREY_ODD;
      gmask[v] = (uint16_t)gcell[v];
      odd |= gcell[v] == GREY_ODD;
    }
    /* 3x3 or 4x4 cells, no background, no odd grey: a row's cells stored from its greys
       at once (tube_write_cells_keyed: each cell's dots looked up by its grey) */
    struct tube_keys tk_frame;
    const struct tube_keys *tk = NULL;
    const bool keyed = (p->cell == 3 || p->cell == 4) && !p->scan && !odd;
    if (keyed && p->tk_keep && !*p->tk_keep && (*p->tk_keep = malloc(sizeof **p->tk_keep)))
      tube_keys_init(*p->tk_keep, p->cell, gmask);
    if (keyed && p->tk_keep && *p->tk_keep) tk = *p->tk_keep;
    else if (keyed) {                       /* (not kept, or no room to keep it) */
      tube_keys_init(&tk_frame, p->cell, gmask);
      tk = &tk_frame;
    }
    p->ids_face = face;
    p->greys_face = false;                  /* the effects wrote them */
    for (int j = p->H - 1; st == T74_OK && j >= 0; j--) {
      row_start(p, &rc, j);
      const size_t at0 = (size_t)j * (size_t)p->W;
      const int *fr = face + at0;
      const uint8_t *greys = p->grey + at0, *flats = flat ? flat + at0 : NULL;
      if (keyed) {
        st = tube_write_cells_keyed(p->tube_direct, rc.x0, rc.y0, tk, greys, p->W);
        continue;
      }
      if (!p->scan && !odd) {               /* no background, no odd grey: every cell */
        greys_cells(greys, p->W, gmask, rc.masks);
        st = row_end(p, &rc);
        continue;
      }
      for (int i = 0; st == T74_OK && i < p->W; i++) {
        if (!p->scan) {                     /* no background: the greys' levels */
          i = greys_run(greys, i, p->W, gcell, rc.masks);
          if (i == p->W) break;
        }
        int level = point_level(p, i, j, fr[i], greys[i], flats && greys[i] == flats[i]);
        if (level >= 0 && level <= cc) rc.masks[i] = p->mask[level];
        else st = row_odd(p, &rc, i, level);
      }
      if (st == T74_OK) st = row_end(p, &rc);
    }
  } else {
    for (int j = p->H - 1; st == T74_OK && j >= 0; j--)
      for (int i = 0; st == T74_OK && i < p->W; i++) {
        size_t at = (size_t)j * (size_t)p->W + (size_t)i;
        const int fa = face[at];
        p->ids[at] = fa >= 0 ? p->map->f[fa].id : 0;
        st = emit_point(p, i, j, fa, p->grey[at], flat && p->grey[at] == flat[at]);
      }
  }
  free(flat);
  free(bg);
  return st;
}

static double now_seconds(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* The job's outputs, opened into its set before any work (display/outfile.h). */
struct job_outs {
  struct outset *set;               /* the set they belong to */
  bool own;                         /* the job made the set: it commits and frees it */
  struct outfile *png;              /* -o, or NULL */
  struct outfile *stats;            /* --stats, or NULL */
  struct outfile *dump[JOB_MAX_DUMPS];  /* --dump KIND=FILE, in the order given */
};

/* Open every output of the job, then the hooks' own, into one set, and refuse any that is
** one of the inputs (the scene; the background when there is one). Before any work. */
static int outs_open(const struct job *o, const struct job_hooks *h, const char *background,
                     struct job_outs *jo, struct t74_error *err)
{
  memset(jo, 0, sizeof *jo);
  if (h && h->outs) jo->set = h->outs;
  else if (outset_new(&jo->set, err) != T74_OK) return err->status;
  else jo->own = true;
  if (o->png && outset_open(jo->set, o->png, 0, &jo->png, err) != T74_OK) return err->status;
  for (int d = 0; d < o->ndump; d++)
    if (outset_open(jo->set, o->dump_path[d], 0, &jo->dump[d], err) != T74_OK) return err->status;
  if (o->stats && outset_open(jo->set, o->stats, 0, &jo->stats, err) != T74_OK) return err->status;
  if (h && h->open_outputs && h->open_outputs(h->outputs_ctx, jo->set, err) != T74_OK)
    return err->status ? err->status : T74_EIO;
  if (outset_check_input(jo->set, o->scene, "scene", err) != T74_OK) return err->status;
  if (background && outset_check_input(jo->set, background, "background", err) != T74_OK)
    return err->status;
  return T74_OK;
}

/* After a good run: publish the set when it is the job's own. */
static int outs_commit(struct job_outs *jo, struct t74_error *err)
{
  return jo->own ? outset_commit(jo->set, err) : T74_OK;
}

/* Discard whatever was not committed (the job's own set only; a caller's is the caller's). */
static void outs_free(struct job_outs *jo)
{
  if (jo->own) outset_free(jo->set);
  jo->set = NULL;
}

/* ---- engines (CONTRACT.md "Engines") --------------------------------------------- */

const char *job_engine_name(int engine)
{
  return engine == JOB_ENGINE_POINTS ? "points" : "1974";
}

/* Is the job's scene an import (.obj, .off), as scene_load decides it? */
static bool job_is_import(const struct job *o)
{
  const char *kind = scene_kind(o->scene, &o->sopts);
  return !strcmp(kind, "obj") || !strcmp(kind, "off");
}

int job_engine_for(const struct job *o, const struct scene *s, const struct effects *e,
                   struct t74_error *err)
{
  /* what only the 1974 program does: effects on its stretches and cuts (effects/see.h) */
  const char *why = fx_needs_1974(e);
  int at = why && !o->effects ? s->effects_line : 0;   /* the scene line the refusal names */
  if (!why && o->arith == GEOM_HITAC)
    why = "--arith hitac is the 1974 program's arithmetic";
  else if (!why && o->need_1974)
    why = "this command shows the 1974 program at work";
  for (int d = 0; d < o->ndump && !why; d++)
    if (o->dump_kind[d] == DUMP_TABLES || o->dump_kind[d] == DUMP_CORE)
      why = "--dump tables and --dump core show the 1974 program's tables and core";
  if (o->engine == JOB_ENGINE_1974) return JOB_ENGINE_1974;
  if (o->engine == JOB_ENGINE_POINTS) {
    if (!why) return JOB_ENGINE_POINTS;
    if (at > 0)
      t74_fail_at(err, T74_EINPUT, s->file, at, "--engine points cannot run this: %s; use "
                  "--engine 1974 or auto", why);
    else
      t74_fail(err, T74_EINPUT, "tube74: --engine points cannot run this: %s; use --engine "
               "1974 or auto", why);
    return -1;
  }
  if (why || o->machine_given || !job_is_import(o)) return JOB_ENGINE_1974;
  return JOB_ENGINE_POINTS;
}

/* The ids (and greys) the points engine's frame left in its faces (p->ids_face), written
** out for the dumps: each point's face's id and grey, 0 and 0 where none is seen, as
** on_point gives them. */
static void dumps_settle(struct pipeline *p)
{
  const int *face = p->ids_face;
  if (!face) return;
  const size_t n = (size_t)p->W * (size_t)p->H;
  for (size_t at = 0; at < n; at++) {
    const int f = face[at];
    p->ids[at] = f >= 0 ? p->map->f[f].id : 0;
    if (p->greys_face)
      p->grey[at] = f >= 0 ? (uint8_t)p->map->f[f].grey : p->greys_bg ? p->greys_bg[at] : 0;
  }
  p->ids_face = NULL;
  p->greys_face = false;
  p->greys_bg = NULL;
}

/* `--dump ids`: a 16-bit PGM (CONTRACT.md). A face number above 65535 (an import of more
   faces, docs/scale.md) cannot be written in it: refused at the face's line, status 2,
   naming the first point (scan order: top row first) that shows such a face; the caller
   then commits no output. */
static int write_ids(const struct pipeline *p, const struct scene *s, struct outfile *of,
                     struct t74_error *err)
{
  size_t n = (size_t)p->W * (size_t)p->H;
  for (size_t at = 0; at < n; at++) {
    if (p->ids[at] <= 0xFFFFu) continue;
    int line = 0;
    for (int k = 0; k < p->map->nface && !line; k++)
      if (p->map->f[k].id == p->ids[at]) line = s->f[p->map->f[k].sface].line;
    return t74_fail_at(err, T74_EINPUT, s->file, line > 0 ? line : 1,
                       "face %lu is seen at point (%d, %d), but --dump ids %s is a 16-bit "
                       "PGM of face numbers 0..65535; no output written (docs/scale.md)",
                       (unsigned long)p->ids[at], (int)(at % (size_t)p->W),
                       (int)(at / (size_t)p->W), outfile_path(of));
  }
  uint16_t *w = malloc((n ? n : 1) * sizeof *w);
  if (!w) return t74_fail(err, T74_EIO, "out of host memory");
  for (size_t at = 0; at < n; at++) w[at] = (uint16_t)p->ids[at];
  int st = image_write_ids_to(w, p->W, p->H, of, err);
  free(w);
  return st;
}

static int copy_to_outfile(FILE *from, struct outfile *of, struct t74_error *err)
{
  const char *path = outfile_path(of);
  rewind(from);
  char buf[8192];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, from)) > 0)
    if (outfile_write(of, buf, n) != T74_OK) { outfile_abort(of); return t74_fail(err, T74_EIO, "%s: write failed", path); }
  return outfile_commit(of, err);
}

/* What the core would hold if the tables kept tube74's exact values instead of the 1974
   program's words (docs/machine.md): the peak plus, for each table, what its exact rows
   add at that table's own peak (VERTEX 8 words for 6, A-BLOCK 19 for 10, B-BLOCK 10 for 6,
   C-BLOCK 8 a side for 1 + 4 a side: at most as much again, D-BLOCK 28 for 10). An upper
   estimate: the tables' peaks need not fall together. */
static uint64_t exact_core_words(const struct core *c)
{
  static const struct { const char *name; int num, den; } extra[] = {
    { "VERTEX", 2, 6 }, { "A-BLOCK", 9, 10 }, { "B-BLOCK", 4, 6 }, { "C-BLOCK", 1, 1 },
    { "D-BLOCK", 18, 10 } };
  const char *names[64];
  uint32_t peak[64];
  int n = core_tables(c, names, peak, 64);
  uint64_t w = core_peak(c);
  for (int k = 0; k < n && k < 64; k++)
    for (size_t e = 0; e < sizeof extra / sizeof extra[0]; e++)
      if (!strcmp(names[k], extra[e].name))
        w += ((uint64_t)peak[k] * (uint64_t)extra[e].num + (uint64_t)extra[e].den - 1) /
             (uint64_t)extra[e].den;
  return w;
}

static const char *const stage_names[RS_NSTAGE] = { "mapper", "segment", "priority+visible" };

/* The fields both engines' --stats share: the host's times, the picture, the effects. */
static void write_run_fields(struct outfile *of, const struct job *o, const struct pipeline *p,
                             const struct tube *t, double host, double frame, const char *effbuf)
{
  outfile_printf(of, "  \"host_seconds\": %.6f,\n", host);
  outfile_printf(of, "  \"frame_seconds\": %.6f,\n", frame);
  outfile_printf(of, "  \"frames\": %d,\n", o->frames > 1 ? o->frames : 1);
  outfile_printf(of, "  \"points_lit\": %d,\n", tube_count(t));
  outfile_printf(of, "  \"cell\": %d,\n  \"grid\": [%d, %d],\n", p->cell, p->W, p->H);
  outfile_printf(of, "  \"effects\": ");
  outfile_json_string(of, effbuf);
  outfile_printf(of, ",\n");
}

/* The effects' own counters (fx_count), either engine. */
static void write_fx_fields(struct outfile *of, const struct fx_stats *fst)
{
  for (int k = 0; k < fst->n; k++) {
    if (fst->integer[k]) outfile_printf(of, "  \"%s\": %.0f,\n", fst->name[k], fst->value[k]);
    else outfile_printf(of, "  \"%s\": %.6f,\n", fst->name[k], fst->value[k]);
  }
}

static int write_stats(const struct job *o, const struct render *r, const struct pipeline *p,
                       const struct tube *t, double host, double frame, const struct effects *eff,
                       const struct fx_stats *fst, struct outfile *of, struct t74_error *err)
{
  struct cost total = { { 0 } };
  for (int s = 0; s < RS_NSTAGE; s++) cost_merge(&total, &r->cost[s]);
  cost_merge(&total, &p->display);
  struct scan_stats ss;
  memset(&ss, 0, sizeof ss);
  if (p->scan) scan_report(p->scan, &ss);
  uint64_t alive = (uint64_t)render_pieces_alive(r);
  char effbuf[512];
  effects_format(eff, effbuf, sizeof effbuf);
  outfile_printf(of, "{\n");
  outfile_printf(of, "  \"scene\": ");
  outfile_json_string(of, o->scene);                   /* any path stays valid JSON */
  outfile_printf(of, ",\n  \"engine\": \"1974\",\n");
  outfile_printf(of, "  \"faces_in\": %d,\n", r->faces_in);
  outfile_printf(of, "  \"faces_dropped\": %d,\n", r->map.dropped);
  outfile_printf(of, "  \"faces_after_split\": %" PRIu64 ",\n", alive);
  outfile_printf(of, "  \"concave_splits\": %d,\n", r->concave_splits);
  outfile_printf(of, "  \"intersection_splits\": %d,\n", r->prio.splits);
  outfile_printf(of, "  \"priority_pairs_computed\": %" PRIu64 ",\n", r->prio.computed);
  outfile_printf(of, "  \"priority_pairs_possible\": %" PRIu64 ",\n", alive * (alive - (alive > 0)) / 2);
  outfile_printf(of, "  \"priority_store\": \"%s\",\n", r->prio.store == PRIO_DENSE ? "dense" : "sparse");
  outfile_printf(of, "  \"core_words\": %u,\n", core_words(r->core));
  outfile_printf(of, "  \"core_words_used\": %u,\n", core_peak(r->core));
  /* what the HITAC-10 would have needed: the peak, whatever core it was drawn with */
  outfile_printf(of, "  \"core_words_needed\": %u,\n  \"fits_16k\": %s,\n", core_peak(r->core),
                 core_peak(r->core) <= DEFAULT_CORE_WORDS ? "true" : "false");
  outfile_printf(of, "  \"core_grown\": %s,\n", core_words(r->core) > core_first_words(r->core)
                 ? "true" : "false");
  outfile_printf(of, "  \"exact_core_words\": %llu,\n", (unsigned long long)exact_core_words(r->core));
  outfile_printf(of, "  \"hitac10_seconds\": %.6f,\n", pipeline_seconds(p));
  {
    /* the same run with every counted operation at its exact width (emu/cost.h) */
    struct cost all = total;
    cost_merge(&all, &p->scanner);
    cost_merge(&all, &p->fx);
    double prog = 0;
    cost_params_get(&o->params, "program_words", &prog);
    outfile_printf(of, "  \"exact_hitac10_seconds\": %.6f,\n",
                   pipeline_seconds(p) - cost_seconds(&all, &o->params) +
                   cost_seconds_exact(&all, &o->params));
    outfile_printf(of, "  \"arith\": \"%s\",\n  \"arith_faces_skipped\": %d,\n"
                   "  \"program_words\": %.0f,\n",
                   o->arith == GEOM_HITAC ? "hitac" : "exact", r->arith_skipped, prog);
  }
  outfile_printf(of, "  \"scanner_seconds\": %.6f,\n", ss.scanner_seconds);
  outfile_printf(of, "  \"disk_seconds\": %.6f,\n", ss.disk_seconds);
  if (p->first_dot >= 0)
    outfile_printf(of, "  \"first_dot_1974_seconds\": %.6f,\n", p->first_dot);
  else
    outfile_printf(of, "  \"first_dot_1974_seconds\": null,\n");
  if (p->scan)
    outfile_printf(of, "  \"scanner\": {\"photo_mm\": [%.1f, %.1f], \"samples\": %d, \"lines\": %d, "
                   "\"drum_seconds\": %.6f, \"input_disk_seconds\": %.6f, \"disk_words\": %u, "
                   "\"disk_tracks\": %d, \"disk_reads\": %llu},\n", ss.photo_w_mm, ss.photo_h_mm,
                   ss.samples, ss.lines, ss.drum_seconds, ss.input_disk_seconds, (unsigned)ss.words,
                   ss.tracks, (unsigned long long)ss.disk_reads);
  write_run_fields(of, o, p, t, host, frame, effbuf);
  write_fx_fields(of, fst);
  if (p->hooks && p->hooks->stats && p->hooks->stats(p->hooks->stats_ctx, of) != T74_OK) {
    outfile_abort(of);
    return t74_fail(err, T74_EIO, "%s: cannot write statistics", o->stats);
  }
  outfile_printf(of, "  \"stages\": [");
  int first = 1;
  if (p->scan) { outfile_printf(of, "\"scanner\""); first = 0; }
  for (int s = 0; s < RS_NSTAGE; s++)
    if (r->ran[s]) { outfile_printf(of, "%s\"%s\"", first ? "" : ", ", stage_names[s]); first = 0; }
  if (p->face) { outfile_printf(of, "%s\"effects\"", first ? "" : ", "); first = 0; }
  outfile_printf(of, "%s\"halftone\", \"tube\"],\n", first ? "" : ", ");
  outfile_printf(of, "  \"stage_hitac10_seconds\": {");
  for (int s = 0; s < RS_NSTAGE; s++)
    outfile_printf(of, "\"%s\": %.6f, ", stage_names[s], cost_seconds(&r->cost[s], &o->params));
  if (p->scan)
    outfile_printf(of, "\"scanner\": %.6f, ", cost_seconds(&p->scanner, &o->params) + ss.disk_seconds);
  if (p->face) outfile_printf(of, "\"effects\": %.6f, ", cost_seconds(&p->fx, &o->params));
  outfile_printf(of, "\"halftone+tube\": %.6f},\n", cost_seconds(&p->display, &o->params));
  outfile_printf(of, "  \"operations\": {");
  cost_merge(&total, &p->scanner);
  cost_merge(&total, &p->fx);
  for (int c = 0; c < COST_NCLASS; c++)
    outfile_printf(of, "%s\"%s\": %" PRIu64, c ? ", " : "", cost_class_name(c), total.n[c]);
  outfile_printf(of, "}\n}\n");
  return outfile_commit(of, err);
}

/* --stats under --engine points: the contract's fields, the 1974 figures null. */
static int write_stats_points(const struct job *o, const struct scene *s, const struct points *pt,
                              const struct pipeline *p, const struct tube *t, double host,
                              double frame, const struct effects *eff,
                              const struct fx_stats *fst, struct outfile *of,
                              struct t74_error *err)
{
  char effbuf[512];
  effects_format(eff, effbuf, sizeof effbuf);
  int drawn = 0;
  for (int k = 0; k < pt->map.nface; k++) drawn += !pt->skip[k];
  outfile_printf(of, "{\n");
  outfile_printf(of, "  \"scene\": ");
  outfile_json_string(of, o->scene);
  outfile_printf(of, ",\n  \"engine\": \"points\",\n");
  outfile_printf(of, "  \"faces_in\": %d,\n", s->nf);
  outfile_printf(of, "  \"faces_dropped\": %d,\n", pt->map.dropped);
  outfile_printf(of, "  \"faces_after_split\": %d,\n", drawn);
  outfile_printf(of, "  \"faces_folded\": %d,\n", pt->faces_split);
  outfile_printf(of, "  \"faces_culled\": %d,\n", pt->faces_culled);
  outfile_printf(of, "  \"points_visited\": %ld,\n  \"points_tiles_skipped\": %ld,\n",
                 pt->points_visited, pt->tiles_skipped);
  outfile_printf(of, "  \"concave_splits\": null,\n  \"intersection_splits\": null,\n"
                 "  \"priority_pairs_computed\": null,\n  \"priority_pairs_possible\": null,\n"
                 "  \"priority_store\": null,\n");
  outfile_printf(of, "  \"core_words\": %u,\n", o->core_words);
  outfile_printf(of, "  \"core_words_used\": null,\n  \"core_words_needed\": null,\n"
                 "  \"fits_16k\": null,\n  \"core_grown\": false,\n  \"exact_core_words\": null,\n"
                 "  \"hitac10_seconds\": null,\n  \"exact_hitac10_seconds\": null,\n"
                 "  \"arith\": \"exact\",\n  \"arith_faces_skipped\": null,\n"
                 "  \"program_words\": null,\n  \"scanner_seconds\": null,\n"
                 "  \"disk_seconds\": null,\n  \"first_dot_1974_seconds\": null,\n");
  write_run_fields(of, o, p, t, host, frame, effbuf);
  write_fx_fields(of, fst);
  if (p->hooks && p->hooks->stats && p->hooks->stats(p->hooks->stats_ctx, of) != T74_OK) {
    outfile_abort(of);
    return t74_fail(err, T74_EIO, "%s: cannot write statistics", o->stats);
  }
  outfile_printf(of, "  \"stages\": [%s\"mapper\", \"points\", %s\"halftone\", \"tube\"],\n",
                 p->scan ? "\"scanner\", " : "", p->face ? "\"effects\", " : "");
  outfile_printf(of, "  \"stage_hitac10_seconds\": null,\n  \"operations\": null\n}\n");
  return outfile_commit(of, err);
}

/* ---- Tektronix streams onto the tube ------------------------------------------------ */

#define TEK_WARN_SHOWN 100              /* warnings printed; the rest are only counted */
#define TEK_FILE_MAX ((size_t)256 << 20) /* largest Tek stream read (256 MiB; a full 4014
                                           screen of point plot is under 1 MiB) */

/* Is the job's input a Tek stream: --input tek, or (no --input) a first byte that is a Tek
** control code. A file that cannot be read is left to the scene reader to report. Only a
** regular file is looked at: the first byte of a pipe or FIFO cannot be looked at without
** taking it from the reader (such an input is a scene unless --input tek says otherwise),
** and a scene already read (o->preloaded) is not opened again. */
static bool job_is_tek(const struct job *o)
{
  if (o->sopts.input) return strcmp(o->sopts.input, "tek") == 0;
  if (o->preloaded) return false;       /* read once already, as a scene */
  struct stat sb;
  if (stat(o->scene, &sb) != 0 || !S_ISREG(sb.st_mode)) return false;
  FILE *f = fopen(o->scene, "rb");
  if (!f) return false;
  uint8_t b[1];
  size_t n = fread(b, 1, sizeof b, f);
  fclose(f);
  return tek_sniff(b, n);
}

struct tek_ctx {
  const char *file;             /* for the warnings */
  struct tube *tube;            /* erased by ESC FF */
  size_t shown;                 /* warnings printed */
  const struct job_hooks *h;    /* write-through traces and erases go on to these */
};

static void tek_warn(void *ctx, size_t offset, const char *msg)
{
  struct tek_ctx *c = ctx;
  if (c->shown++ < TEK_WARN_SHOWN) fprintf(stderr, "%s: warning: byte %zu: %s\n", c->file, offset, msg);
}

static void tek_erase(void *ctx)
{
  struct tek_ctx *c = ctx;
  tube_erase(c->tube);
  if (c->h && c->h->erase) c->h->erase(c->h->events_ctx);
}

static void tek_writethrough(void *ctx, int x0, int y0, int x1, int y1)
{
  struct tek_ctx *c = ctx;
  if (c->h && c->h->writethrough) c->h->writethrough(c->h->events_ctx, x0, y0, x1, y1);
}

static int write_tek_stats(const struct job *o, const struct job_hooks *h, const struct tube *t,
                           const struct tek_report *rep, double host, struct outfile *of,
                           struct t74_error *err)
{
  outfile_printf(of, "{\n");
  outfile_printf(of, "  \"scene\": ");
  outfile_json_string(of, o->scene);
  outfile_printf(of, ",\n  \"input\": \"tek\",\n");
  /* the contract's renderer fields: no scene, nothing rendered */
  outfile_printf(of, "  \"faces_in\": 0,\n  \"faces_after_split\": 0,\n  \"concave_splits\": 0,\n"
                 "  \"intersection_splits\": 0,\n  \"priority_pairs_computed\": 0,\n"
                 "  \"priority_pairs_possible\": 0,\n");
  outfile_printf(of, "  \"core_words\": %u,\n  \"core_words_used\": 0,\n"
                 "  \"core_words_needed\": 0,\n  \"fits_16k\": true,\n", o->core_words);
  outfile_printf(of, "  \"hitac10_seconds\": 0.000000,\n  \"scanner_seconds\": 0.000000,\n"
                 "  \"disk_seconds\": 0.000000,\n");
  outfile_printf(of, "  \"host_seconds\": %.6f,\n", host);
  outfile_printf(of, "  \"points_lit\": %d,\n", tube_count(t));
  outfile_printf(of, "  \"tek_in\": {\"bytes\": %zu, \"warnings\": %zu, \"points\": %zu, "
                 "\"vectors\": %zu, \"moves\": %zu, \"chars\": %zu, \"erases\": %zu, "
                 "\"write_through\": %zu, \"dots\": %zu},\n", rep->bytes, rep->warnings,
                 rep->points, rep->vectors, rep->moves, rep->chars, rep->erases, rep->wt_traces,
                 rep->dots);
  if (h && h->stats && h->stats(h->stats_ctx, of) != T74_OK) {
    outfile_abort(of);
    return t74_fail(err, T74_EIO, "%s: cannot write statistics", o->stats);
  }
  outfile_printf(of, "  \"stages\": [\"tek\", \"tube\"]\n}\n");
  return outfile_commit(of, err);
}

/* Show a Tek stream on the tube, then write the outputs a tube can give. */
static int run_tek(const struct job *o, const struct job_hooks *h, struct job_result *res,
                   struct t74_error *err)
{
  for (int d = 0; d < o->ndump; d++)
    if (o->dump_kind[d] != DUMP_TUBE && o->dump_kind[d] != DUMP_POINTS)
      return t74_fail(err, T74_EINPUT, "%s: --dump %s needs a scene; a Tek stream gives only "
                      "the tube's dots (--dump tube, --dump points)", o->scene,
                      dump_names[o->dump_kind[d]]);
  double t0 = now_seconds();
  struct job_outs jo;
  int st = outs_open(o, h, NULL, &jo, err);
  if (st != T74_OK) { outs_free(&jo); return st; }
  uint8_t *buf = NULL;
  size_t n = 0;
  st = file_read_all(o->scene, TEK_FILE_MAX, &buf, &n, err);
  if (st != T74_OK) { outs_free(&jo); return st; }
  struct tube *t = tube_new();
  if (!t) { free(buf); outs_free(&jo); return t74_fail(err, T74_EIO, "out of host memory"); }
  bool extra = h && h->extra.point;
  struct sink_tee tee;
  sink_tee_init(&tee);
  sink_tee_add(&tee, tube_sink(t));
  if (extra) sink_tee_add(&tee, h->extra);
  struct sink out = sink_tee_sink(&tee);
  struct tek_ctx tc = { o->scene, t, 0, h };
  struct tek_report rep;
  memset(&rep, 0, sizeof rep);
  rep.warn = tek_warn;
  rep.erase = tek_erase;
  rep.write_through = tek_writethrough;
  rep.ctx = &tc;
  st = tek_decode(buf, n, &out, &rep);
  free(buf);
  if (rep.warnings > TEK_WARN_SHOWN)
    fprintf(stderr, "%s: warning: %zu more warnings not shown\n", o->scene,
            rep.warnings - TEK_WARN_SHOWN);
  if (st != T74_OK) {
    if (extra) sink_abort(&h->extra);
    st = t74_fail(err, st, "%s: the stream's dots could not be stored", o->scene);
    goto done;
  }
  if (extra && (st = sink_end(&h->extra, err)) != T74_OK) goto done;
  double host = now_seconds() - t0;
  if (res) {
    res->hitac10_seconds = 0;
    res->host_seconds = host;
    res->frame_seconds = 0;
    res->points_lit = tube_count(t);
    res->W = res->H = res->cell = 0;
  }
  if (jo.png && (st = image_write_png_to(t, jo.png, err)) != T74_OK) goto done;
  for (int d = 0; d < o->ndump; d++) {
    st = o->dump_kind[d] == DUMP_TUBE ? image_write_pbm_to(t, jo.dump[d], err)
                                      : image_write_points_to(t, jo.dump[d], err);
    if (st != T74_OK) goto done;
  }
  if (jo.stats && (st = write_tek_stats(o, h, t, &rep, host, jo.stats, err)) != T74_OK) goto done;
  st = outs_commit(&jo, err);
done:
  outs_free(&jo);
  tube_free(t);
  return st;
}

/* ---- the scene pipeline ------------------------------------------------------------- */

/* What point_seen and point_level give a point that sees face f - 1 (f = 0: none, where
** there is no background picture): its id, grey, level and the cell's dots; for every
** face, malloc'd (NULL when out of memory: the caller takes the way a point at a time). */
struct face_out {
  uint32_t id;
  int level;
  uint16_t mask;                    /* p->mask[level] */
  bool odd;                         /* level is not 0 .. cell * cell: no mask, cell_out */
  uint8_t grey;
};

/* Each face's entry at its index + 1 (none's at 0); with them, when fmask is not NULL
** and no face's level is odd, each one's mask in a table of its own, at the same places
** (*fmask; else NULL, as when the host has no room: none is needed). NULL: no room. */
static struct face_out *face_outs(const struct pipeline *p, uint16_t **fmask)
{
  const size_t n = (size_t)p->map->nface + 1;
  struct face_out *fo = malloc(n * sizeof *fo);
  uint16_t *fm = fmask && fo ? malloc(n * sizeof *fm) : NULL;
  bool odd = false;
  for (int f = 0; fo && f <= p->map->nface; f++) {
    int grey = f ? p->map->f[f - 1].grey : 0;
    fo[f].id = f ? p->map->f[f - 1].id : 0;
    fo[f].grey = (uint8_t)grey;
    fo[f].level = (unsigned)grey < 256 ? p->level[grey] : pat_level(p->cell, grey);
    fo[f].odd = fo[f].level < 0 || fo[f].level > p->cell * p->cell;
    fo[f].mask = fo[f].odd ? 0 : p->mask[fo[f].level];
    odd |= fo[f].odd;
    if (fm) fm[f] = fo[f].mask;
  }
  if (fm && odd) { free(fm); fm = NULL; }
  if (fmask) *fmask = fm;
  return fo;
}

/* A row's background points: the levels and greys the disk gives them (faces_run). */
struct row_bg {
  const uint8_t *level, *grey;      /* scan_row's */
  const uint16_t *mask;             /* p->mask */
  const uint16_t *cells;            /* with bg_ok: each point's p->mask[level] */
  int cc;                           /* cell * cell */
};

/* The background picture's points as the points engine's frames show them, worked out
** once for a job's frames (they depend on the scene alone: the picture, the cell and its
** pattern): each row's levels and greys (scan_row), cells (p->mask of each level, 0 for a
** level past the cell) and whether every level of the row is within the cell. */
struct bg_cells {
  uint8_t *level, *grey;            /* W x H, row j at j W */
  uint16_t *cells;
  bool *ok;                         /* H */
};

static void bg_cells_free(struct bg_cells *b)
{
  if (!b) return;
  free(b->level);
  free(b->grey);
  free(b->cells);
  free(b->ok);
  free(b);
}

/* p's background's cells (p->scan, p->mask, p->W, p->H set); NULL when out of memory. */
static struct bg_cells *bg_cells_new(const struct pipeline *p)
{
  const size_t n = (size_t)p->W * (size_t)p->H;
  const int cc = p->cell * p->cell;
  struct bg_cells *b = calloc(1, sizeof *b);
  if (!b) return NULL;
  b->level = malloc(n);
  b->grey = malloc(n);
  b->cells = malloc(n * sizeof *b->cells);
  b->ok = malloc((size_t)p->H * sizeof *b->ok);
  if (!b->level || !b->grey || !b->cells || !b->ok) { bg_cells_free(b); return NULL; }
  for (int j = 0; j < p->H; j++) {
    const size_t at = (size_t)j * (size_t)p->W;
    scan_row(p->scan, j, b->level + at, b->grey + at);   /* no 1974 time: uncounted */
    uint8_t top = 0;
    for (int i = 0; i < p->W; i++) {
      const uint8_t l = b->level[at + (size_t)i];
      top = l > top ? l : top;
      b->cells[at + (size_t)i] = l <= cc ? p->mask[l] : 0;
    }
    b->ok[j] = top <= cc;
  }
  return b;
}

/* m[0 .. n) = mask and (g not NULL) g[0 .. n) = grey (n >= 1); room >= n: the points to
** the row's end. Eight points a store (SSE2): a run of eight or more ends with eight
** stores that overlap its last ones; a shorter run with room for eight is written eight
** wide past its end, at points of the same row that later runs (or the odd cell's own
** writes) write again before the row is stored; else a point at a time. */
static inline void run_fill(uint16_t *m, uint8_t *g, int n, int room, uint16_t mask,
                            uint8_t grey)
{
  int q = 0;
#ifdef __SSE2__
  const __m128i mv = _mm_set1_epi16((short)mask), gv = _mm_set1_epi8((char)grey);
  if (n < 8 && room >= 8) n = 8;
  if (n >= 8) {
    for (;; q += 8) {
      if (q + 8 > n) q = n - 8;             /* the last eight: overlapping */
      _mm_storeu_si128((__m128i *)(void *)(m + q), mv);
      if (g) _mm_storel_epi64((__m128i *)(void *)(g + q), gv);
      if (q + 8 == n) return;
    }
  }
#else
  (void)room;
#endif
  for (; q < n; q++) {
    m[q] = mask;
    if (g) g[q] = grey;
  }
}

/* The points i .. of a row whose cells are of a level 0 .. cell * cell, up to the first
** other one: their cells, and (greys not NULL) their greys, from their faces' entries, or
** from the background picture's levels and greys of the row (bg, NULL: none; bg_ok: every
** level of the row's background is 0 .. cell * cell); its index, or n. (A loop of its own:
** few values live, none spilled.) */
static int faces_run(const struct face_out *fo, const int *face, int i, int n,
                     const struct row_bg *bg, bool bg_ok, uint8_t *greys, uint16_t *masks,
                     int *nrun)
{
  for (; i < n; i++) {
    int f = face[i];
    ++*nrun;
    if (f < 0 && bg) {                      /* a run of background points */
      const int e = face_run_end(face, i, n);
      int q = i;
      if (bg_ok && bg->cells) {
        memcpy(masks + i, bg->cells + i, (size_t)(e - i) * sizeof *masks);
        q = e;
      } else if (bg_ok)
        for (; q < e; q++) masks[q] = bg->mask[bg->level[q]];
      else
        for (; q < e && bg->level[q] <= bg->cc; q++) masks[q] = bg->mask[bg->level[q]];
      if (greys) memcpy(greys + i, bg->grey + i, (size_t)(q - i));
      if (q < e) { i = q; break; }          /* a level past the cell */
      i = e - 1;
      continue;
    }
    const struct face_out *o = &fo[f + 1];
    if (o->odd) break;
    const int e = face_run_end(face, i, n);   /* the run of points that see this face */
    run_fill(masks + i, greys ? greys + i : NULL, e - i, n - i, o->mask, o->grey);
    i = e - 1;
  }
  return i;
}

/* A row's cells from its faces, a point at a time (mask1: each face's cell from face 0, at
** -1 none's; no background, no face of an odd level): as faces_run gives them. Four points
** a step (an empty asm: no vector form, which gcc would build of scalar lookups through
** the stack). */
static void faces_cells(const int *face, int n, const uint16_t *mask1, uint16_t *masks)
{
  int i = 0;
  for (; i + 4 <= n; i += 4) {
#ifdef __GNUC__
    __asm__("" : "+r"(i));
#endif
    masks[i] = mask1[face[i]];
    masks[i + 1] = mask1[face[i + 1]];
    masks[i + 2] = mask1[face[i + 2]];
    masks[i + 3] = mask1[face[i + 3]];
  }
  for (; i < n; i++) masks[i] = mask1[face[i]];
}

/* faces_cells over a background (no level of the row's past the cell): a point that sees
** no face takes the background's cell (bgcells, the row's). */
static void faces_cells_bg(const int *face, int n, const uint16_t *mask1,
                           const uint16_t *bgcells, uint16_t *masks)
{
  int i = 0;
  for (; i + 4 <= n; i += 4) {
#ifdef __GNUC__
    __asm__("" : "+r"(i));
#endif
    for (int q = i; q < i + 4; q++) {
      const int f = face[q];
      const uint16_t m = mask1[f], b = bgcells[q];   /* (mask1[-1]: none's, read, unused) */
      masks[q] = f < 0 ? b : m;
    }
  }
  for (; i < n; i++) masks[i] = face[i] < 0 ? bgcells[i] : mask1[face[i]];
}

/* Runs of faces a row above which faces_cells, a point at a time, costs fewer instructions
** than faces_run's runs (speed only: both give the same cells). */
#define RUNS_BY_POINT 3
#define RUNS_BY_POINT_BG 10                 /* the same over a background (faces_cells_bg) */

/* --engine points: the buffer's faces to the sinks in the 1974 program's order (bottom row
** first, left to right), through the same per-point path; or into the effects stage's
** frame. Unwatched (always, but for tube74 teach's 1974 engine), on_point's steps are
** looked up per face once, not a call a point; to the tube alone without effects (each
** --frames frame after the first), a row's cells are stored in one write and the
** display's counts added once (issue 19). */
static int points_emit(struct pipeline *p, const struct points *pt)
{
  const bool watched = p->hooks && p->hooks->watch;
  const int W = p->W, H = p->H, cc = p->cell * p->cell;
  uint8_t *fgrey;                           /* each face's grey, at its index + 1 */
  if (p->face && !watched && !p->scan) {
    /* the effects' frame: the faces, left in pt's buffer (run_effects takes them from
       there; points_render writes all of it again next frame); their greys are left to
       the effects (fx_frame's face_grey: the point frame writes every one; run_effects
       makes the table) and the ids to run_effects, written with the cells after fx_run */
    p->face_drawn = pt->face;
    p->grey_pending = true;
    return T74_OK;
  }
  if (p->face && !watched && (fgrey = face_greys(p->map))) {
    /* the effects' frame over a background: the faces, and their greys or the
       background's */
    const struct scan_image *scan = p->scan;
    p->face_drawn = pt->face;               /* as above */
    for (int j = 0; j < H; j++)
      for (int i = 0; i < W; i++) {
        const size_t at = (size_t)j * (size_t)W + (size_t)i;
        const int f = pt->face[at];
        p->grey[at] = f < 0 ? (uint8_t)scan_grey(scan, i, j) : fgrey[f + 1];
      }
    free(fgrey);
    return T74_OK;
  }
  const bool direct = p->tube_direct && !p->also && !p->timed;
  uint16_t *fmask = NULL;                   /* (faces_cells: no background or the job's) */
  struct face_out *fo = !watched && !p->face && direct
                          ? face_outs(p, !p->scan || p->bgc ? &fmask : NULL) : NULL;
  if (fo) {
    /* the ids are left in the frame's faces until a dump asks (dumps_settle), and without
       a background the greys too; no display counts are kept (only the 1974 engine's
       figures report them) */
    const bool scan = p->scan != NULL;
    struct row_cells rc;
    uint8_t row_level[TUBE_W], row_grey[TUBE_W];   /* a row's background points' (no bgc) */
    struct row_bg bg = { row_level, row_grey, p->mask, NULL, cc };
    int st = T74_OK;
    p->ids_face = pt->face;
    /* the greys left to dumps_settle too where the background's are the job's (bgc) */
    p->greys_face = !scan || p->bgc;
    p->greys_bg = scan && p->bgc ? p->bgc->grey : NULL;
    /* no face of an odd level, and no background or the job's background cells (bgc): a
       row whose runs are short (as the row before, run by run, had more than
       RUNS_BY_POINT, over a background RUNS_BY_POINT_BG and every level of the row's
       background within the cell) is looked up a point at a time; every fourth row run
       by run, to count again */
    const bool by_point = fmask != NULL;    /* (no room: run by run) */
    int nrun = 0;                           /* the last row taken run by run: its runs */
    for (int j = H - 1; j >= 0 && st == T74_OK; j--) {
      row_start(p, &rc, j);
      const int *face = pt->face + (size_t)j * (size_t)W;
      if (by_point && nrun > (scan ? RUNS_BY_POINT_BG : RUNS_BY_POINT) && (j & 3) &&
          (!scan || p->bgc->ok[j])) {
        if (scan)
          faces_cells_bg(face, W, fmask + 1, p->bgc->cells + (size_t)j * (size_t)W, rc.masks);
        else
          faces_cells(face, W, fmask + 1, rc.masks);
        st = row_end(p, &rc);
        continue;
      }
      nrun = 0;
      uint8_t *greys = scan && !p->bgc ? p->grey + (size_t)j * (size_t)W : NULL;
      bool bg_ok = false;                   /* every background level of the row in the cell */
      if (scan && p->bgc) {                 /* the job's, worked out once */
        const size_t at = (size_t)j * (size_t)W;
        bg.level = p->bgc->level + at;
        bg.grey = p->bgc->grey + at;
        bg.cells = p->bgc->cells + at;
        bg_ok = p->bgc->ok[j];
      } else if (scan) {
        scan_row(p->scan, j, row_level, row_grey);   /* no 1974 time: uncounted */
        uint8_t top = 0;
        for (int i = 0; i < W; i++) top = row_level[i] > top ? row_level[i] : top;
        bg_ok = top <= cc;
      }
      const uint8_t *bg_level = bg.level, *bg_grey = bg.grey;
      for (int i = 0; i < W && st == T74_OK; i++) {
        i = faces_run(fo, face, i, W, scan ? &bg : NULL, bg_ok, greys, rc.masks, &nrun);
        if (i == W) break;
        int f = face[i], level;             /* a cell of another level */
        if (f < 0 && scan) {                /* the background's, from the disk */
          if (greys) greys[i] = bg_grey[i];
          level = bg_level[i];
        } else {
          if (greys) greys[i] = fo[f + 1].grey;
          level = fo[f + 1].level;
        }
        st = row_odd(p, &rc, i, level);
      }
      if (st == T74_OK) st = row_end(p, &rc);
    }
    free(fmask);
    free(fo);
    return st;
  }
  for (int j = H - 1; j >= 0; j--)
    for (int i = 0; i < W; i++) {
      int st = on_point(p, i, j, pt->face[(size_t)j * (size_t)W + (size_t)i]);
      if (st != T74_OK) return st;          /* as vis_scan: the sink's status */
    }
  return T74_OK;
}

/* One more frame of the loaded scene for --frames (the job's outputs come from the frame
** after these), by the job's engine: the 1974 program (Mapper, Segment Generator,
** priorities, visible surfaces, a render of its own on ro, its core to ro->keep) or the
** points engine (pt's scratch reused); then effects and halftone into t (erased first),
** the machine model counting as in that frame, no hooks (a command's sink sees one
** picture). The pipeline's counters are the copy's; the background's display-time disk
** state starts afresh (and afresh again for the frame after these), so the statistics are
** those of one frame. */
static int spare_frame(const struct pipeline *p0, const struct scene *s, const struct effects *e,
                       int engine, const struct render_opts *ro, int arith, struct points *pt,
                       const struct vis_grid *g, struct tube *t, double *secs,
                       struct t74_error *err)
{
  struct pipeline p = *p0;
  struct render r;
  memset(&r, 0, sizeof r);
  double t0 = now_seconds();
  if (p.scan) scan_display_reset(p.scan);
  tube_erase(t);                            /* the job's spare tube, blank as a new one */
  p.hooks = NULL;
  p.out = tube_sink(t);
  p.tube_direct = t;
  p.also = NULL;
  memset(&p.display, 0, sizeof p.display);
  memset(&p.fx, 0, sizeof p.fx);
  memset(&p.scanner, 0, sizeof p.scanner);
  struct fx_stats fst;
  memset(&fst, 0, sizeof fst);
  int st;
  if (engine == JOB_ENGINE_POINTS) {
    p.r = NULL;
    p.pts = pt;
    p.map = &pt->map;
    st = points_render(pt, s, g, err);
    if (st == T74_OK) st = points_emit(&p, pt);
  } else {
    p.r = &r;
    p.pts = NULL;
    p.map = &r.map;
    st = render_prepare_lazy_arith(&r, s, ro, arith, err);   /* as the first frame */
    if (st == T74_OK) st = render_scan(&r, g, on_point, &p, err);
  }
  if (st == T74_OK && p.face) st = run_effects(&p, s, e, g, &fst, err);
  *secs = now_seconds() - t0;
  if (engine == JOB_ENGINE_1974) render_free(&r);   /* its core to ro->keep, for the next frame */
  return st;
}

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The scene through the pipeline into the sinks and outputs, on a core of o->core_words
   words that grows up to `grow_max` words (0: it does not grow); `dry`: a run only to
   measure the core (no outputs, no sinks, no warnings). */
static int run_scene(const struct job *o, const struct job_hooks *h, uint32_t grow_max,
                     bool dry, struct job_result *res, struct t74_error *err)
{
  struct scene *own = NULL;                 /* the scene when the job reads it */
  struct render r;
  struct points pts;
  struct pipeline p;
  struct tube *t = NULL;
  struct pic *bg = NULL;
  FILE *tables = NULL;
  struct job_outs jo;
  double *frame_t = NULL;                   /* --frames: each frame's host seconds */
  struct render_keep keep;                  /* what a frame leaves for the next */
  struct core *fx_core = NULL;              /* the effects' core, kept for the next frame */
  struct smooth_scene *fx_smooth = NULL;    /* the smoothing's scene part, likewise */
  struct fx_textures *fx_tex = NULL;        /* the scene's textures, likewise */
  struct shadow_keep *fx_shadow = NULL;     /* the shadows in space, likewise */
  struct bg_cells *bgc = NULL;              /* the background's cells, likewise */
  struct tube_keys *tkeys = NULL;           /* run_effects' cells by grey, likewise */
  int st;
  memset(&keep, 0, sizeof keep);
  memset(&r, 0, sizeof r);
  memset(&pts, 0, sizeof pts);
  pts.keep = &keep.map;                     /* the points engine's frames keep its rings too */
  memset(&p, 0, sizeof p);
  p.first_dot = -1;
  p.fx_keep = &fx_core;
  p.fx_smooth = &fx_smooth;
  p.fx_tex = &fx_tex;
  p.fx_shadow = &fx_shadow;
  p.tk_keep = &tkeys;
  int engine = JOB_ENGINE_1974;
  memset(&jo, 0, sizeof jo);

  double t0 = now_seconds() - o->preload_seconds;  /* reading the scene counts */
  const struct scene *s;
  if (o->preload_failed) {
    *err = *o->preload_failed;              /* read once, by the caller: it failed */
    return err->status;
  }
  if (o->preloaded) {
    s = o->preloaded;                       /* read once, by the caller */
  } else {
    st = scene_load(o->scene, &o->sopts, &own, err);
    if (st != T74_OK) return st;
    s = own;
  }

  struct effects eff;
  if (o->effects) st = effects_parse(o->effects, &eff, "--effects", 1, err);
  else if (s->effects) st = effects_parse(s->effects, &eff, s->file, s->effects_line, err);
  else { effects_default(&eff); st = T74_OK; }
  if (st != T74_OK) goto done;
  engine = job_engine_for(o, s, &eff, err);
  if (engine < 0) { st = err->status; goto done; }
  p.timed = engine == JOB_ENGINE_1974;
  p.cell = o->cell ? o->cell : eff.halftone;
  st = pat_find(eff.pattern[0] ? eff.pattern : NULL, p.cell, &p.pat);
  if (st != T74_OK) {
    /* the name came from the effects line (or --effects): point at it */
    st = t74_fail(err, T74_EINPUT, "%s:%d: effects: unknown halftone pattern `%s` for the "
                  "%dx%d cell", o->effects ? "--effects" : s->file,
                  o->effects ? 1 : s->effects_line, eff.pattern, p.cell, p.cell);
    goto done;
  }
  p.W = pat_grid_w(p.cell);
  p.H = pat_grid_h(p.cell);
  for (int g = 0; g < 256; g++) p.level[g] = (uint8_t)pat_level(p.cell, g);
  for (int l = 0; l <= p.cell * p.cell; l++) pat_cell_dots(p.pat, l, &p.mask[l]);
  /* every output opened and checked before any work: all or nothing */
  st = outs_open(o, h, s->background, &jo, err);
  if (st != T74_OK) goto done;
  if (s->background) {
    struct t74_error pe = { T74_OK, "" };
    st = pic_load(s->background, &bg, &pe);
    if (st != T74_OK) {   /* the scene's line that named it, then the loader's reason */
      st = t74_fail(err, st, "%s:%d: background: %s", s->file, s->background_line, pe.msg);
      goto done;
    }
    /* input time: the photograph through drum, A-D and packing onto the disk */
    st = scan_photo(bg, p.cell, &o->params, &p.scan, err);
    if (st != T74_OK) goto done;
  }

  bool want_tables = false;
  for (int d = 0; d < o->ndump; d++) want_tables |= o->dump_kind[d] == DUMP_TABLES;
  if (h && h->tables) tables = h->tables;   /* the watcher's file: the job does not close it */
  else if (want_tables && !(tables = tmpfile())) {
    st = t74_fail(err, T74_EIO, "cannot make a temporary file for --dump tables");
    goto done;
  }
  double prog = 0;
  cost_params_get(&o->params, "program_words", &prog);
  struct render_opts ro = { o->core_words, (uint32_t)prog, o->store, tables, grow_max, &keep };
  const int nframes = o->frames > 1 ? o->frames : 1;
  keep.map.once = nframes == 1;             /* no next frame: the Mapper keeps nothing for one */
  frame_t = calloc((size_t)nframes, sizeof *frame_t);
  if (!frame_t) { st = t74_fail(err, T74_EIO, "out of host memory"); goto done; }
  struct vis_grid g = { p.W, p.H, { s->window[0], s->window[1], s->window[2], s->window[3] } };
  t = tube_new();
  p.ids = calloc((size_t)p.W * (size_t)p.H, sizeof *p.ids);
  p.grey = calloc((size_t)p.W * (size_t)p.H, sizeof *p.grey);
  if (fx_wanted(&eff, s)) p.face = calloc((size_t)p.W * (size_t)p.H, sizeof *p.face);
  if (!t || !p.ids || !p.grey || (fx_wanted(&eff, s) && !p.face)) {
    st = t74_fail(err, T74_EIO, "out of host memory");
    goto done;
  }
  p.params = &o->params;
  cost_class_states(p.params, p.states);
  if (engine == JOB_ENGINE_POINTS && p.scan && !p.face) {
    /* points_emit's cells of the background (the scene's alone), once for every frame */
    if (!(bgc = bg_cells_new(&p))) { st = t74_fail(err, T74_EIO, "out of host memory"); goto done; }
    p.bgc = bgc;
  }
  if (nframes > 1) {
    /* --frames: the scene rendered K - 1 times more, each frame timed, before the frame
       whose outputs are written (so that one render is alive at a time, each taking what
       the last left in `keep`); the scene stays loaded */
    struct render_opts ro2 = ro;
    ro2.tables = NULL;
    /* one tube for the spare frames, erased at each (a buffer: half a megabyte the host
       would otherwise map and fault in afresh every frame) */
    struct tube *spare = tube_new();
    if (!spare) st = t74_fail(err, T74_EIO, "out of host memory");
    for (int k = 1; k < nframes && st == T74_OK; k++)
      st = spare_frame(&p, s, &eff, engine, &ro2, o->arith, &pts, &g, spare, &frame_t[k], err);
    tube_free(spare);
    if (st != T74_OK) { if (h && h->extra.point) sink_abort(&h->extra); goto done; }
    if (p.scan) scan_display_reset(p.scan);
  }
  double f0 = now_seconds();                /* the frame: the Mapper to the last dot stored */
  if (engine == JOB_ENGINE_POINTS) st = points_render(&pts, s, &g, err);
  else st = render_prepare_lazy_arith(&r, s, &ro, o->arith, err);
  if (st != T74_OK) goto done;
  p.r = engine == JOB_ENGINE_1974 ? &r : NULL;
  p.pts = engine == JOB_ENGINE_POINTS ? &pts : NULL;
  p.map = engine == JOB_ENGINE_1974 ? &r.map : &pts.map;
  p.hooks = h;
  struct sink_tee tee;
  sink_tee_init(&tee);
  sink_tee_add(&tee, tube_sink(t));
  if (h && h->extra.point) sink_tee_add(&tee, h->extra);
  p.out = sink_tee_sink(&tee);
  if (tee.n <= 2) {                         /* the tube, and the job's other sink if any */
    p.tube_direct = t;
    p.also = tee.n == 2 ? &tee.out[1] : NULL;
  }
  struct fx_stats fst;
  memset(&fst, 0, sizeof fst);
  if (engine == JOB_ENGINE_POINTS) {
    if (h && h->untimed) h->untimed(h->untimed_ctx);
    st = points_emit(&p, &pts);
  } else
    st = render_scan(&r, &g, on_point, &p, err);
  if (st == T74_OK && engine == JOB_ENGINE_1974 && h && h->watch)
    st = h->watch(h->watch_ctx, &r, -1, -1, -1);
  if (st == T74_OK && p.face) st = run_effects(&p, s, &eff, &g, &fst, err);
  if (st != T74_OK) { if (h && h->extra.point) sink_abort(&h->extra); goto done; }
  frame_t[0] = now_seconds() - f0;
  dumps_settle(&p);                         /* the ids and greys of the frame, for dumps */
  qsort(frame_t, (size_t)nframes, sizeof *frame_t, cmp_double);
  const double frame_med = nframes % 2 ? frame_t[nframes / 2]
                                       : (frame_t[nframes / 2 - 1] + frame_t[nframes / 2]) / 2;
  /* the clock's last tick: the last point's own display work is done too */
  if (p.timed && h && h->clock) h->clock(h->clock_ctx, pipeline_seconds(&p));
  if (h && h->extra.point && (st = sink_end(&h->extra, err)) != T74_OK) goto done;
  double host = now_seconds() - t0;
  if (res) {
    res->hitac10_seconds = pipeline_seconds(&p);
    res->host_seconds = host;
    res->frame_seconds = frame_med;
    res->points_lit = tube_count(t);
    res->W = p.W; res->H = p.H; res->cell = p.cell;
    res->engine = engine;
    res->core_words = r.core ? core_words(r.core) : 0;
    res->core_words_used = r.core ? core_peak(r.core) : 0;
    res->pat = p.pat;
  }
  if (!dry && r.core && core_words(r.core) > core_first_words(r.core) && core_peak(r.core) > DEFAULT_CORE_WORDS)
    fprintf(stderr, "%s: warning: the model needs %u words of core; the HITAC-10 had %u "
            "(drawn with %u; --stats: core_words_needed, fits_16k)\n", o->scene,
            core_peak(r.core), DEFAULT_CORE_WORDS, core_words(r.core));

  /* outputs: each written into its place in the set, then all committed together */
  if (jo.png && (st = image_write_png_to(t, jo.png, err)) != T74_OK) goto done;
  for (int d = 0; d < o->ndump; d++) {
    struct outfile *of = jo.dump[d];
    switch (o->dump_kind[d]) {
    case DUMP_IDS:    st = write_ids(&p, s, of, err); break;
    case DUMP_GREY:   st = image_write_grey_to(p.grey, p.W, p.H, of, err); break;
    case DUMP_TUBE:   st = image_write_pbm_to(t, of, err); break;
    case DUMP_POINTS: st = image_write_points_to(t, of, err); break;
    case DUMP_TABLES: st = copy_to_outfile(tables, of, err); break;
    case DUMP_CORE: {
      FILE *tmp = tmpfile();
      if (!tmp) { st = t74_fail(err, T74_EIO, "cannot make a temporary file"); break; }
      core_layout_dump(r.core, tmp);
      st = copy_to_outfile(tmp, of, err);
      fclose(tmp);
      break;
    }
    }
    if (st != T74_OK) goto done;
  }
  if (jo.stats && engine == JOB_ENGINE_POINTS &&
      (st = write_stats_points(o, s, &pts, &p, t, host, frame_med, &eff, &fst, jo.stats,
                               err)) != T74_OK)
    goto done;
  if (jo.stats && engine == JOB_ENGINE_1974 &&
      (st = write_stats(o, &r, &p, t, host, frame_med, &eff, &fst, jo.stats, err)) != T74_OK)
    goto done;
  st = outs_commit(&jo, err);

done:
  free(frame_t);
  outs_free(&jo);
  if (tables && !(h && h->tables == tables)) fclose(tables);
  free(p.ids);
  free(p.grey);
  free(p.face);
  if (t) tube_free(t);
  if (bg) pic_free(bg);
  scan_free(p.scan);
  render_free(&r);
  render_keep_free(&keep);
  core_free(fx_core);
  smooth_scene_free(fx_smooth);
  fx_textures_free(fx_tex);
  shadow_keep_free(fx_shadow);
  bg_cells_free(bgc);
  free(tkeys);
  points_free(&pts);
  scene_free(own);
  return st;
}

struct job job_dots_only(const struct job *o)
{
  struct job d = *o;
  d.png = NULL;
  d.stats = NULL;
  d.ndump = 0;
  d.frames = 1;
  return d;
}

/* --turn turns imports (render/turn.h); a .s74 scene places its eye by its own `view`
   line and a Tek stream is a picture already, so a turn there would be silently lost: it
   is refused (exit 2). 1 when refused (err set), else 0. */
static int turn_misplaced(const struct job *o, struct t74_error *err)
{
  if (!o->sopts.has_turn) return 0;
  bool tek = job_is_tek(o);
  if (!tek && job_is_import(o)) return 0;
  t74_fail(err, T74_EINPUT, "tube74: --turn turns .obj and .off imports only; %s is %s",
           o->scene, tek ? "a Tek stream"
           : "a .s74 scene, seen from its own `view` line (change that instead)");
  return 1;
}

#define CORE_GROW_MAX (UINT32_C(1) << 31)   /* the largest core: core_new's limit */

/* A core that was too small for a table: a "does not fit" of emu/core.c's (the words
   needed and available), which a larger core would cure. */
static bool core_too_small(const struct t74_error *e)
{
  return e->status == T74_ECORE && strstr(e->msg, "available (table ") != NULL;
}

int job_run(const struct job *o, const struct job_hooks *h, struct job_result *res,
            struct t74_error *err)
{
  /* (--turn on a .s74 scene or a Tek stream was refused by job_parse, which alone sets it) */
  if (job_is_tek(o)) return run_tek(o, h, res, err);
  /* an import without --core: drawn with the core it needs */
  int st = run_scene(o, h, job_is_import(o) && !o->core_given ? CORE_GROW_MAX : 0, false, res,
                     err);
  if (!core_too_small(err)) return st;
  /* it did not fit the core given: how much it needs in all, from one more run on a
     growing core with no outputs and no sinks (the program is the same at any size) */
  struct job d = job_dots_only(o);
  d.sopts.quiet = true;                     /* its warnings were printed by the first run */
  struct job_result dr;
  struct t74_error de = { T74_OK, "" };
  if (run_scene(&d, NULL, CORE_GROW_MAX, true, &dr, &de) != T74_OK) return st;   /* keep the first */
  char first[sizeof err->msg];
  const char *why = strstr(err->msg, "(table ");
  snprintf(first, sizeof first, "%s", why ? why + 7 : "");
  size_t n = strlen(first);
  if (n && first[n - 1] == ')') first[n - 1] = '\0';
  err->status = T74_OK;                     /* the first message, replaced by the whole */
  return t74_fail(err, T74_ECORE, "%s: scene does not fit the core: needs %u words in all, "
                  "%u available (the first table short: %s); run it with --core %u",
                  o->scene, dr.core_words_used, o->core_words, first, dr.core_words_used);
}

