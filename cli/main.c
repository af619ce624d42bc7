/*
** main.c — the tube74 command line.
**
** This file contains code to dispatch the commands (shared/CONTRACT.md fixes `render`,
** `tek` and `stream`; the README describes the others). The rendering itself is a job
** (pipeline.c). Only this file turns result codes into exit statuses.
*/
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "emu/cost.h"
#include "emu/status.h"
#include "cli/pipeline.h"
#include "cli/commands.h"
#include "cli/timing.h"
#include "cli/version.h"

static void usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 render SCENE [options]     render a scene (.s74, .obj, .off, or a Tek stream)\n"
    "       tube74 tek SCENE [-o FILE] [options]   the picture as a Tektronix 4010/4014 stream\n"
    "       tube74 stream SCENE --device hpgl|ebb|helios|tek [--usb VID:PID | --serial DEV |\n"
    "                     --dry-run | --to FILE] [--svg FILE] [--repeat N] [--resume FILE]\n"
    "                     [options]   the dots to vector hardware (USB, RS-232) or its file\n"
    "       tube74 devices [PROFILE]          connected USB devices that match a profile\n"
    "       tube74 play SCENE [--speed X] [--movie FILE] [options]   watch the picture build up\n"
    "       tube74 teach SCENE [-o DIR] [--line J] [options]   the paper's figures, step by\n"
    "                     step, as one HTML page\n"
    "       tube74 params                     the HITAC-10 cost model's constants and sources\n"
    "       tube74 bench accuracy [--out DIR] [--runs N]   what anti-aliasing costs in time\n"
    "       tube74 bench speed [--out DIR] [--runs N] [--quick] [--boxes-max N]\n"
    "                     [--triangles-max N] [--peer PATH]   speed against OSMesa\n"
    "       tube74 bench arith [--out DIR]    exact against 1974 arithmetic: dots, time, core\n"
    "       tube74 --help | --version\n");
  job_usage(f);
  timing_usage(f);
}

int main(int argc, char **argv)
{
  struct t74_error err = { T74_OK, "" };
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? T74_EINPUT : 0;
  }
  if (!strcmp(argv[1], "--version") || !strcmp(argv[1], "-V")) {
    printf("tube74 " TUBE74_VERSION "\n");
    return 0;
  }
  int st;
  if (!strcmp(argv[1], "render")) {
    struct job j;
    struct timing tm;                       /* tube_seconds, total_1974_seconds, --look */
    struct job_hooks h;
    timing_init(&tm);
    st = job_parse(argc, argv, 2, &j, timing_opt, &tm, &err);
    if (st == T74_OK) st = timing_prepare(&tm, &j, &err);
    timing_hooks(&tm, &h);
    if (st == T74_OK) st = job_run(&j, &h, NULL, &err);
    timing_free(&tm);
  } else if (!strcmp(argv[1], "params")) {
    struct cost_params prm;
    cost_params_default(&prm);
    cost_params_list(&prm, stdout);
    st = T74_OK;
  } else if (!strcmp(argv[1], "tek")) {
    st = cmd_tek(argc, argv, &err);
  } else if (!strcmp(argv[1], "stream")) {
    st = cmd_stream(argc, argv, &err);
  } else if (!strcmp(argv[1], "devices")) {
    st = cmd_devices(argc, argv, &err);
  } else if (!strcmp(argv[1], "play")) {
    st = cmd_play(argc, argv, &err);
  } else if (!strcmp(argv[1], "bench")) {
    st = cmd_bench(argc, argv, &err);
  } else if (!strcmp(argv[1], "teach")) {
    st = cmd_teach(argc, argv, &err);
  } else {
    usage(stderr);
    st = t74_fail(&err, T74_EINPUT, "tube74: unknown command `%s`", argv[1]);
  }
  if (st != T74_OK) fprintf(stderr, "%s\n", err.msg[0] ? err.msg : "tube74: failed");
  return st;
}
