/*
** commands.h — tube74 commands beyond `render`, each in its own cli/cmd_*.c file.
**
** This file contains the declarations main.c dispatches to. A command parses its own
** options together with render's (job_parse, cli/pipeline.h), runs the job, and returns a
** status of emu/status.h with the message in err; only main() turns it into an exit status.
*/
#ifndef T74_COMMANDS_H
#define T74_COMMANDS_H

#include "emu/status.h"

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
** and refuses unknown ones (cli/cmd_bench.c; this version: accuracy). */
int cmd_bench(int argc, char **argv, struct t74_error *err);

/* `tube74 bench arith [--out DIR]`: exact against 1974 arithmetic (cli/bench_arith.c). */
int bench_arith(int argc, char **argv, struct t74_error *err);

/* `tube74 teach SCENE [-o DIR] [--line J]`: the paper's figures step by step as one HTML
   page (cli/cmd_teach.c). */
int cmd_teach(int argc, char **argv, struct t74_error *err);

#endif
