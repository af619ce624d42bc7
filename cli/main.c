/*
** main.c — the tube74 command line.
**
** This file contains code to dispatch the commands (shared/CONTRACT.md fixes `render`,
** `tek` and `stream`; the README describes the others). The rendering itself is a job
** (pipeline.c). Only this file turns result codes into exit statuses.
*/
#define _DEFAULT_SOURCE        /* sbrk, madvise: the host allocator's set-up below */
#include <errno.h>
#include <inttypes.h>
#ifdef __GLIBC__
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif
#include <stdint.h>
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
    "       tube74 --help | --version\n"
    "       tube74 COMMAND --help            that command's options\n");
  job_usage(f);
  timing_usage(f);
}

/* `tube74 render SCENE [options]`: the job with the tube's timing and look (cli/timing.h). */
static int cmd_render(int argc, char **argv, struct t74_error *err)
{
  struct job j;
  struct timing tm;                       /* tube_seconds, total_1974_seconds, --look */
  struct job_hooks h;
  timing_init(&tm);
  int st = job_parse(argc, argv, 2, &j, timing_opt, &tm, err);
  if (st == T74_OK) st = timing_prepare(&tm, &j, err);
  timing_hooks(&tm, &j, &h);
  if (st == T74_OK) st = job_run(&j, &h, NULL, err);
  timing_free(&tm);
  return st;
}

/* `tube74 params`: the cost model's constants, each with its source. */
static int cmd_params(int argc, char **argv, struct t74_error *err)
{
  if (argc > 2)
    return t74_fail(err, T74_EINPUT, "tube74: params takes no arguments (got `%s`)", argv[2]);
  struct cost_params prm;
  cost_params_default(&prm);
  cost_params_list(&prm, stdout);
  return T74_OK;
}

/* ---- each command's --help ----------------------------------------------------------- */

static void help_render(FILE *f)
{
  fprintf(f, "usage: tube74 render SCENE [options]   a scene (.s74, .obj, .off) or a Tek stream\n"
             "                                       on the emulated storage tube\n");
  job_usage(f);
  timing_usage(f);
}

static void help_tek(FILE *f) { tek_usage(f); job_usage(f); }
static void help_stream(FILE *f) { stream_usage(f); job_usage(f); }
static void help_play(FILE *f) { play_usage(f); job_usage(f); timing_usage(f); }
static void help_teach(FILE *f) { teach_usage(f); job_usage(f); }

static void help_params(FILE *f)
{
  fprintf(f, "usage: tube74 params   the HITAC-10 cost model's constants, each with its source\n"
             "                       (change one for a run with render's --hitac NAME=VALUE)\n");
}

/* The commands: name, entry point, --help (bench's help depends on its subcommand). */
static const struct command {
  const char *name;
  int (*run)(int argc, char **argv, struct t74_error *err);
  void (*help)(FILE *f);                 /* NULL: bench */
} commands[] = {
  { "render",  cmd_render,  help_render },
  { "tek",     cmd_tek,     help_tek },
  { "stream",  cmd_stream,  help_stream },
  { "devices", cmd_devices, devices_usage },
  { "play",    cmd_play,    help_play },
  { "teach",   cmd_teach,   help_teach },
  { "params",  cmd_params,  help_params },
  { "bench",   cmd_bench,   NULL },
};

/* --help or -h among a command's arguments. */
static int asks_help(int argc, char **argv)
{
  for (int k = 2; k < argc; k++)
    if (!strcmp(argv[k], "--help") || !strcmp(argv[k], "-h")) return 1;
  return 0;
}

/* The host's allocator, set for one command's run (issue 19). A page the process touches for
** the first time costs about 10 us on the machine measured (2,000 fresh pages: 29 ms; the
** street's whole render touched 800 before this work), so memory one stage frees should
** serve the next rather than go back to the kernel: glibc gives each block above 128 kB its
** own mapping, unmapped when freed, and the next stage's blocks are then fresh pages again
** (100,000 box faces: the file and the mesh freed before the Mapper fills as much). Blocks
** up to 32 MB (glibc's largest setting) come from the heap instead, and the heap is not
** trimmed; what the process holds at its peak is unchanged.
** And the heap takes huge pages where the kernel gives them for the asking (Linux
** transparent huge pages in "madvise" mode), so that it faults in 2 MB at a time, not
** 4 kB (100,000 box faces: 12,600 page faults and 270 ms of CPU -> 650 and 95 ms). Its
** next growth is made HOST_HEAP_RESERVE larger than asked (address space only: nothing is
** touched) and marked MADV_HUGEPAGE. A huge page is given only to a 2 MB stretch none of
** whose 4 kB pages is in use yet, so the growth is asked for by a block that ends below a
** 2 MB boundary (the heap's top, whose header malloc writes, starts there) and is held
** until the end, untouched; the run's blocks then fill the stretches from that boundary.
** Without THP, or under another allocator (sanitizers, valgrind: the break does not
** move), nothing changes. Returns that block (NULL: none), for main to free. */
#define HOST_HEAP_RESERVE ((size_t)256 << 20)
#define HOST_HEAP_SLACK ((uintptr_t)512 << 10)  /* more than a young heap has free: it grows */
#define HOST_HUGE_PAGE ((uintptr_t)2 << 20)     /* x86-64's transparent huge page */

static void *host_allocator(void)
{
  void *gap = NULL;
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#ifdef MADV_HUGEPAGE
  char *first = malloc(1);                /* the heap made if it is not: its top follows */
  if (!first) return NULL;
  uintptr_t top = (uintptr_t)first + 64;  /* at or above where the top now starts */
  uintptr_t boundary = (top + HOST_HEAP_SLACK + HOST_HUGE_PAGE - 1) & ~(HOST_HUGE_PAGE - 1);
  mallopt(M_TOP_PAD, (int)HOST_HEAP_RESERVE);
  char *before = sbrk(0);
  gap = malloc(boundary - top - 256);     /* from the top; ends below the boundary */
  char *after = sbrk(0);
  mallopt(M_TOP_PAD, 128 << 10);          /* glibc's default for any later growth */
  free(first);
  if (gap && before != (char *)-1 && after != (char *)-1 &&
      (uintptr_t)after - (uintptr_t)before >= HOST_HEAP_RESERVE) {
    uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE);
    uintptr_t from = ((uintptr_t)before + page - 1) & ~(page - 1);
    madvise((void *)from, (uintptr_t)after - from, MADV_HUGEPAGE);   /* advice: errors ignored */
  }
#endif
#endif
  return gap;
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
  const struct command *c = NULL;
  for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
    if (!strcmp(argv[1], commands[k].name)) c = &commands[k];
  int st;
  if (!c) {
    usage(stderr);
    st = t74_fail(&err, T74_EINPUT, "tube74: unknown command `%s`", argv[1]);
  } else if (asks_help(argc, argv)) {
    if (c->help) c->help(stdout);
    else bench_usage(stdout, argc > 2 ? argv[2] : NULL);
    st = fflush(stdout) == 0 && !ferror(stdout) ? T74_OK
         : t74_fail(&err, T74_EIO, "tube74: cannot write the usage to stdout");
  } else {
    void *heap_gap = host_allocator();
    st = c->run(argc, argv, &err);
    free(heap_gap);
  }
  if (st != T74_OK) fprintf(stderr, "%s\n", err.msg[0] ? err.msg : "tube74: failed");
  return st;
}
