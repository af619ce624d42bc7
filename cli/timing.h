/*
** timing.h — the tube's 1974 timing and look for any rendering job (render, play).
** Sources: display/beam.h (Tektronix 613 settling, paper 003 face size), display/look.h
** (the look constants), CONTRACT.md (tube=stored|fade:SECONDS|flash).
**
** This file contains code to hang the beam timing and the look layer onto a job
** (cli/pipeline.h) through its hooks: an extra sink that times every dot as the 1974
** program displayed it (display/beam.h), a clock hook that tells it the computing time so
** far, and a stats hook that adds "tube_seconds" and "total_1974_seconds" to --stats.
** When a look is asked for (--look, --scale N > 1, or the effect tube=flash / tube=fade:S)
** the -o picture is drawn by the look layer instead of the plain one; otherwise the job's
** outputs are untouched and the plain picture costs nothing extra.
**
** Use (render, play):
**   struct timing tm;  timing_init(&tm);
**   st = job_parse(argc, argv, 2, &j, timing_opt, &tm, &err);     // takes --scale, --look..
**   if (st == T74_OK) st = timing_prepare(&tm, &j, &err);          // may take over -o
**   struct job_hooks h;  timing_hooks(&tm, &j, &h);
**   if (st == T74_OK) st = job_run(&j, &h, NULL, &err);
**   timing_free(&tm);
*/
#ifndef T74_TIMING_H
#define T74_TIMING_H

#include <stdbool.h>
#include <stdio.h>

#include "cli/pipeline.h"
#include "display/beam.h"
#include "display/look.h"
#include "emu/status.h"

struct timing {
  struct beam_params bp;        /* --beam NAME=VALUE */
  struct look_params lp;        /* --look-param NAME=VALUE */
  struct beam beam;             /* the beam, during the job */
  struct look *look;            /* dots with their write times (made by timing_prepare
                                   when a look or a recording is wanted), else NULL */
  double clock;                 /* latest computing time from the clock hook */
  bool untimed;                 /* the engine keeps no 1974 time (--engine points) */
  int scale;                    /* --scale 1..8 (default 1; play: 2) */
  bool scale_given;
  unsigned look_flags;          /* LOOK_FLASH | LOOK_FADE */
  bool look_given;              /* --look named (plain = false: the scaled plain picture) */
  bool want_look;               /* -o is drawn by the look layer */
  bool record;                  /* keep every dot's time even without a look (play) */
  double look_at;               /* --look-at: seconds after the picture is complete */
  bool look_at_given;
  const char *png;              /* -o taken over from the job, or NULL */
  struct outfile *png_out;      /* that -o, opened in the job's set (open_outputs hook) */
  struct scene *scene;          /* the scene timing_prepare read for its effects line, lent
                                   to the job (j->preloaded) so that it is read once; freed
                                   by timing_free */
  struct t74_error scene_err;   /* why that reading failed (j->preload_failed) */
};

void timing_init(struct timing *t);
void timing_free(struct timing *t);

/* job_opt_fn for job_parse: takes --scale N, --look LIST, --look-at S, --beam NAME=V,
** --look-param NAME=V. LIST: comma-separated plain | glow | flash | fade[:SECONDS]. */
int timing_opt(void *ctx, int argc, char **argv, int *k, struct t74_error *err);

/* After job_parse: read the tube= effect (from --effects or the scene's effects line),
** decide whether -o is a look picture and, if so, take it over from j. A .s74 scene read
** for its effects line is lent to the job (j->preloaded), not read again; when reading it
** failed, the failure is lent instead (j->preload_failed), for the job to report. */
int timing_prepare(struct timing *t, struct job *j, struct t74_error *err);

/* Fill h: the extra sink (beam + look), the clock and the stats hook; or leave h empty
** when none of j's outputs would show the beam's times (no --stats, look, recording or
** scaled picture). */
void timing_hooks(struct timing *t, const struct job *j, struct job_hooks *h);

/* When the picture was complete (1974 seconds) and how long the beam was busy. */
double timing_total_seconds(const struct timing *t);
double timing_tube_seconds(const struct timing *t);

/* The time the -o look picture shows: complete + look_at (default: 0, or fade_s when
** fading; a negative look_at shows the picture still being written), at least 0. */
double timing_show_time(const struct timing *t);

/* For --help. */
void timing_usage(FILE *f);

#endif
