/*
** commands.h — tube74 commands beyond `render`, each in its own cli/cmd_*.c file.
**
** This file contains the declarations main.c dispatches to. A command parses its own
** options together with render's (job_parse, cli/pipeline.h), runs the job, and returns a
** status of emu/status.h with the message in err; only main() turns it into an exit status.
*/
#ifndef T74_COMMANDS_H
#define T74_COMMANDS_H

#include <stdio.h>

#include "emu/status.h"

/* Each command's own part of its --help (main.c adds render's options where they apply):
** printed to stdout with exit status 0 by `tube74 COMMAND --help` (or -h anywhere in its
** arguments); tests/test_help.c checks them against the man page tube74.1. */
void tek_usage(FILE *f);
void play_usage(FILE *f);
void stream_usage(FILE *f);
void devices_usage(FILE *f);
void teach_usage(FILE *f);
void bench_usage(FILE *f, const char *sub);   /* sub: accuracy, speed, arith; else all */

/* `tube74 tek SCENE [-o FILE] [render's options]`: the picture as a Tektronix 4010/4014
** byte stream (display/tek.h), written while the scene renders; stdout without -o. */
int cmd_tek(int argc, char **argv, struct t74_error *err);

/* `tube74 play SCENE`: watch the picture build up as on the 1974 tube (cli/cmd_play.c). */
int cmd_play(int argc, char **argv, struct t74_error *err);

/* `tube74 stream SCENE --device PROFILE [--usb VID:PID] [--repeat N] [--resume FILE] ...`:
** the dots to vector hardware over USB while the scene renders (cli/cmd_stream.c). */
int cmd_stream(int argc, char **argv, struct t74_error *err);

/* `tube74 devices [PROFILE]`: connected USB devices that match a profile (cli/cmd_stream.c). */
int cmd_devices(int argc, char **argv, struct t74_error *err);

/* `tube74 bench SUBCOMMAND [--out DIR]`: measured figures; dispatches on the subcommand
** and refuses unknown ones (cli/cmd_bench.c; this version: accuracy, speed, arith). */
int cmd_bench(int argc, char **argv, struct t74_error *err);

/* `tube74 bench speed [--out DIR] [--runs N] [--quick] [--peer PATH]`: against OSMesa
** (cli/bench_speed.c); cmd_bench dispatches to it. */
int bench_speed(int argc, char **argv, struct t74_error *err);

/* `tube74 bench arith [--out DIR]`: exact against 1974 arithmetic (cli/bench_arith.c). */
int bench_arith(int argc, char **argv, struct t74_error *err);

/* `tube74 teach SCENE [-o DIR] [--line J]`: the paper's figures step by step as one HTML
   page (cli/cmd_teach.c). */
int cmd_teach(int argc, char **argv, struct t74_error *err);

#endif
