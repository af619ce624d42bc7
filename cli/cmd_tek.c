/*
** cmd_tek.c — `tube74 tek SCENE [-o FILE] [render's options]` (CONTRACT.md; display/tek.h).
**
** This file contains code to render a scene and write what the tube stores as a Tektronix
** 4010/4014 PLOT 10 byte stream. The encoder (display/tek.h) is the job's extra sink
** (cli/pipeline.h), so every dot goes out the moment the 1974 program would have written
** it: sent to a terminal (`./tube74 tek scenes/street.s74 > /dev/tty` in `xterm -t`), the
** picture grows as it renders. SCENE may itself be a Tek stream (render reads those): the
** stream is then shown on the tube and written again, as point plot.
**
** Options: the FIRST -o names the Tek output (`-` or no -o: stdout); the command's option
** function sees it before render's parser does. A second -o goes on to render: the PNG.
** Everything else is render's (job_usage). With -o FILE the file appears only when the
** whole job succeeded, together with the job's other outputs (one set, display/outfile.h;
** a FIFO or a terminal named by -o gets the bytes as they come); on stdout a failed job
** has sent either nothing (it failed before the first dot) or a partial picture followed
** by US, and no other output may be `-`.
*/
#include "cli/commands.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli/pipeline.h"
#include "display/outfile.h"
#include "display/tek.h"
#include "emu/status.h"

struct tek_cli {
  const char *out;              /* the Tek output, NULL or "-" for stdout */
  bool have_out;                /* the first -o has been taken */
};

/* job_opt_fn: the first -o FILE is the Tek output. */
static int tek_option(void *ctx, int argc, char **argv, int *k, struct t74_error *err)
{
  struct tek_cli *c = ctx;
  if (strcmp(argv[*k], "-o") != 0 || c->have_out) return 0;
  if (*k + 1 >= argc) {
    t74_fail(err, T74_EINPUT, "tube74: missing value after -o (the Tek output)");
    return -1;
  }
  c->out = argv[++*k];
  c->have_out = true;
  return 1;
}

/* job_hooks.stats: the stream's size, for --stats. */
static int tek_stats(void *ctx, struct outfile *of)
{
  const struct tek_enc *e = ctx;
  outfile_printf(of, "  \"tek_points\": %llu,\n", (unsigned long long)tek_enc_points(e));
  return outfile_printf(of, "  \"tek_bytes\": %llu,\n", (unsigned long long)tek_enc_bytes(e));
}

void tek_usage(FILE *f)
{
  fprintf(f,
    "usage: tube74 tek SCENE [-o FILE] [render's options]\n"
    "  -o FILE                the Tek 4010/4014 stream (default or `-`: stdout, streamed as\n"
    "                         the dots come); a second -o is render's PNG\n");
}

int cmd_tek(int argc, char **argv, struct t74_error *err)
{
  struct tek_cli c = { NULL, false };
  struct job j;
  int st = job_parse(argc, argv, 2, &j, tek_option, &c, err);
  if (st != T74_OK) return st;
  /* the Tek output is one of the job's outputs: checked with the others before any work,
     committed with them; on stdout (`-` or no -o) it streams as the dots come */
  struct outset *set;
  if (outset_new(&set, err) != T74_OK) return err->status;
  struct tek_enc *e = NULL;
  struct outfile *of;
  const char *path = c.out && strcmp(c.out, "-") != 0 ? c.out : NULL;
  if (!path) st = outset_reserve_stdout(set, err);
  if (st == T74_OK && !path) st = tek_enc_open(&e, NULL, err);
  if (st == T74_OK && path && (st = outset_open(set, path, OUTFILE_STREAM, &of, err)) == T74_OK)
    st = tek_enc_open_to(&e, of, err);
  if (st != T74_OK) { outset_free(set); return st; }
  struct job_hooks h;
  memset(&h, 0, sizeof h);
  h.extra = tek_enc_sink(e);
  h.stats = tek_stats;
  h.stats_ctx = e;
  h.outs = set;
  st = job_run(&j, &h, NULL, err);
  if (st == T74_OK) st = outset_commit(set, err);
  tek_enc_free(e);               /* aborts the output if the job never ended it */
  outset_free(set);
  return st;
}
