/*
** pipeline.h — one rendering job: scene -> renderer -> halftone -> sinks -> outputs.
**
** Every command that draws a scene (render, tek, play, stream) parses render's options
** with job_parse and runs job_run, adding its own sink (a Tek stream, a window, a USB
** device) through job_hooks: that sink receives every tube dot the moment it is produced,
** in scan order, as the 1974 program displayed while it computed, and a clock tells it
** the 1974 computing time spent so far. Outputs (-o, --dump, --stats, and the hooks'
** own) form one set (display/outfile.h): every path is opened and checked before the
** work starts — two outputs on one file, or an output that is the scene or its
** background, are refused (exit 2) — and all are committed together only when
** everything succeeded; `-` is standard output.
*/
#ifndef T74_PIPELINE_H
#define T74_PIPELINE_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "display/outfile.h"
#include "display/sink.h"
#include "emu/cost.h"
#include "emu/status.h"
#include "render/effects.h"
#include "render/scene.h"

struct render;
struct pat_cell;

#define JOB_MAX_DUMPS 8

enum job_dump { DUMP_IDS, DUMP_GREY, DUMP_TUBE, DUMP_POINTS, DUMP_TABLES, DUMP_CORE };

/* --engine (CONTRACT.md "Engines"): which program decides visibility. */
enum job_engine {
  JOB_ENGINE_AUTO = 0,              /* 1974 for .s74 scenes and wherever something needs
                                       the 1974 program; points for imports otherwise */
  JOB_ENGINE_1974,                  /* paper 003's program in the memory model (render.h) */
  JOB_ENGINE_POINTS                 /* exact visibility at each point centre (points.h) */
};

struct job {
  const char *scene;
  const char *png;                  /* -o */
  const char *stats;                /* --stats */
  const char *effects;              /* --effects: replaces the scene's line */
  int cell;                         /* --cell, 0 = from the scene */
  uint32_t core_words;              /* --core */
  bool core_given;                  /* --core was given: the core is that, never grown */
  int store;                        /* --matrix */
  const struct scene *preloaded;    /* the scene already read (with these sopts) by the
                                       caller, who owns it; NULL: the job reads it */
  double preload_seconds;           /* the time that reading took (in host_seconds) */
  const struct t74_error *preload_failed; /* the caller's reading failed with this (owned
                                       by the caller; NULL: it did not fail or did not
                                       read): the job reports it and does not read again */
  int frames;                       /* --frames: the loaded scene rendered this many times
                                       (0 = 1); outputs come from one of them */
  int arith;                        /* --arith: GEOM_EXACT (default) or GEOM_HITAC */
  int engine;                       /* --engine: enum job_engine (default auto) */
  bool machine_given;               /* --core, --matrix or --hitac given: questions about
                                       the 1974 machine (auto then takes the 1974 engine) */
  bool need_1974;                   /* the command needs the 1974 program (teach, bench
                                       arith): auto takes it, --engine points is refused */
  int ndump;
  int dump_kind[JOB_MAX_DUMPS];
  const char *dump_path[JOB_MAX_DUMPS];
  struct scene_opts sopts;          /* --view, --window, --input */
  struct cost_params params;        /* --hitac */
};

/* A command's own options: return 1 when argv[*k] (and any values, advancing *k) was
   taken, 0 when it is not the command's, or a status on error. */
typedef int (*job_opt_fn)(void *ctx, int argc, char **argv, int *k, struct t74_error *err);

/* Parse argv[first..] as render's options plus the command's own (extra may be NULL). */
int job_parse(int argc, char **argv, int first, struct job *j, job_opt_fn extra, void *ctx,
              struct t74_error *err);

struct job_hooks {
  struct sink extra;                /* receives every dot as produced (point == NULL: none);
                                       its end() runs before the outputs are written */
  void (*clock)(void *ctx, double hitac10_seconds); /* before each point that lights dots,
                                       and once after the last point: 1974 time so far */
  void *clock_ctx;
  /* what a Tek stream shows beyond stored dots (NULL: ignored): write-through traces
     (dim, never stored; a point when x0 == x1 and y0 == y1) and erases (ESC FF) */
  void (*writethrough)(void *ctx, int x0, int y0, int x1, int y1);
  void (*erase)(void *ctx);
  void *events_ctx;
  /* more "key": value lines for --stats (each ending with ",\n"), or NULL */
  int (*stats)(void *ctx, struct outfile *of);
  void *stats_ctx;
  /* the hook owner's own outputs (the look's -o), opened into the job's set after the
     job's own and before any work, so that all are checked first and committed together
     (display/outfile.h); NULL: none */
  int (*open_outputs)(void *ctx, struct outset *set, struct t74_error *err);
  void *outputs_ctx;
  /* a set made by the caller, holding outputs the caller writes (tek -o): the job adds
     its outputs to it and leaves the commit to the caller. NULL: the job makes its own
     set and commits it when everything succeeded. */
  struct outset *outs;
  /* called once, before the first point, when the engine keeps no 1974 time (--engine
     points): the clock above will not tick (NULL: not told) */
  void (*untimed)(void *ctx);
  void *untimed_ctx;
  /* the 1974 program watched as it runs (tube74 teach; NULL: not watched): its teaching
     dump, the text --dump tables writes, goes to `tables` as it is made (a seekable file
     when the job has --dump tables as well); watch() sees the renderer at every point of
     the scan, before the point is displayed (i, j and face as render_scan gives them:
     face an index in r->map.f, or -1), and once more after the scan with i = j = -1,
     when the faces above the window have been cut and the final matrix written. A
     status other than T74_OK from it ends the job with that status. */
  FILE *tables;
  int (*watch)(void *ctx, const struct render *r, int i, int j, int face);
  void *watch_ctx;
};

struct job_result {
  double hitac10_seconds;           /* the 1974 computing time of the whole picture */
  double host_seconds;
  double frame_seconds;             /* median of the frames: Mapper to the last dot stored */
  int points_lit;                   /* tube dots lit */
  int W, H, cell;
  int engine;                       /* the engine that ran: JOB_ENGINE_1974 or _POINTS */
  uint32_t core_words;              /* the core the picture was drawn with */
  uint32_t core_words_used;         /* the most of it in use at once: what it needs */
  const struct pat_cell *pat;       /* the halftone cells the dots were drawn with */
};

/* The engine job j runs with effects e (parsed from its scene or --effects) on its scene s:
   JOB_ENGINE_1974 or JOB_ENGINE_POINTS, or -1 with a usage error in err (T74_EINPUT: an
   explicit --engine points with something only the 1974 program does: an effect, a
   texture, --arith hitac, a dump of its tables). */
int job_engine_for(const struct job *j, const struct scene *s, const struct effects *e,
                   struct t74_error *err);

/* "1974" or "points" */
const char *job_engine_name(int engine);

/* The same job with no outputs (-o, --stats, --dump) and one frame: for a run that only
   wants its dots or its figures (a plotter's estimate, the core a scene needs). */
struct job job_dots_only(const struct job *j);

/* Core: a .s74 scene, a Tek stream, or any scene with --core gets the core given (16384
** words by default); one that does not fit it ends with T74_ECORE (exit 3), the message
** giving the words it needs in all (found by a second run, without outputs, on a core
** that grows: emu/core.h core_set_growth), the words available, and --core. An .obj/.off
** import without --core is drawn with the core it needs (a growing core), with a warning
** "FILE: warning: the model needs N words of core; the HITAC-10 had 16384" when that is
** more; --stats gives core_words_needed and fits_16k either way. */
int job_run(const struct job *j, const struct job_hooks *h, struct job_result *res,
            struct t74_error *err);

/* render's options, for --help */
void job_usage(FILE *f);

#endif
