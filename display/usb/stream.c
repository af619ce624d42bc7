/*
** stream.c — a USB device profile as a point sink, with acknowledgement bookkeeping,
** --repeat passes, the resume file and the progress line (see stream.h).
**
** This file contains code to stand between the rendering job and a device profile. It keeps
** every dot produced (in production order, for later passes and for the resume file), a
** bitmap of the dots the device acknowledged in the current pass, and the acknowledged
** PREFIX: the longest run of production order that is wholly acknowledged. Invariant: a
** dot is acknowledged at most once per pass (ack() ignores a repeat), and prefix only grows.
** Hardware source: none (profiles hold the device facts).
*/
#include "display/usb/stream.h"

#include "display/usb/preview.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NDOTS (TUBE_W * TUBE_H)

struct usb_stream {
  struct usb_stream_opts o;
  struct usb_link *link;
  void *dev;                    /* the profile's context */
  struct usb_point *order;      /* dots of the picture in production order */
  int produced;                 /* how many (this pass's render, or the whole picture) */
  unsigned char *seen;          /* [y*W+x]: dot produced already (dedupe) */
  unsigned char *acked;         /* [y*W+x]: acknowledged in the current pass */
  unsigned char *skip;          /* [y*W+x]: acknowledged by the run being resumed */
  int skip_prefix;              /* ... and its first skip_prefix dots */
  uint32_t pass;                /* the pass being drawn */
  int nacked;                   /* dots acknowledged in this pass */
  int prefix;                   /* order[0..prefix-1] all acknowledged */
  long long sent_total, acked_total;    /* over all passes */
  int render_done;              /* the job's sink end() came */
  long long acked_before_end;   /* acknowledged while the scene was still rendering */
  double t_first_ack;           /* usb_now() of the first acknowledgement, 0 none */
  double hitac;                 /* 1974 seconds so far */
  double last_progress;
  int failed;                   /* a point/end call failed */
  struct t74_error err;         /* its message */
  int interrupted;
  struct preview *pv;           /* --svg, or NULL */
};

double usb_estimate_seconds(const struct usb_tally *t)
{
  return t->device_s > t->line_s ? t->device_s : t->line_s;
}

uint64_t usb_hash(uint64_t h, const void *p, size_t n)
{
  const unsigned char *b = p;
  for (size_t k = 0; k < n; k++) {
    h ^= b[k];
    h *= 0x100000001b3ull;      /* FNV-1a 64 prime */
  }
  return h;
}

/* ---- progress --------------------------------------------------------------------- */

static void progress(struct usb_stream *s, int force)
{
  if (!s->o.progress) return;
  double now = usb_now();
  if (!force && now - s->last_progress < 0.1) return;
  s->last_progress = now;
  double real = now - s->o.t0;
  double rate = s->t_first_ack > 0 && now > s->t_first_ack
                  ? (double)s->acked_total / (now - s->t_first_ack) : 0;
  /* the whole run's dots: known from the estimate, else once this pass is rendered */
  long long per = s->o.expect_dots > 0 ? s->o.expect_dots : s->render_done ? s->produced : 0;
  long long total = s->o.repeat > 0 ? per * s->o.repeat : per;
  long long done = s->o.repeat > 0 ? s->acked_total + (long long)s->skip_prefix : s->nacked;
  char bar[24] = "", eta[48] = "";
  if (total > 0) {
    double f = (double)done / (double)total;
    if (f > 1) f = 1;
    int fill = (int)(20.0 * f);
    for (int k = 0; k < 20; k++) bar[k] = k < fill ? '#' : '.';
    bar[20] = 0;
    if (s->o.repeat > 0) {
      /* measured once some of the run is done, else the estimate's */
      double left = -1;
      if (f >= 0.02 && s->t_first_ack > 0) left = (now - s->t_first_ack) * (1 - f) / f;
      else if (s->o.expect_seconds > 0) left = s->o.expect_seconds * (1 - f);
      if (left >= 0) {
        char d[32];
        usb_duration(d, sizeof d, left);
        snprintf(eta, sizeof eta, " | ETA %s", d);
      }
    }
  }
  fprintf(s->o.progress, "\r%s %s%s%spass %" PRIu32 ": sent %lld, acknowledged %lld | 1974 %.1f s"
          " | real %.1f s | %.0f points/s%s   ", s->o.prof->name, bar[0] ? "[" : "", bar,
          bar[0] ? "] " : "", s->pass + 1, s->sent_total, s->acked_total, s->hitac, real, rate, eta);
  fflush(s->o.progress);
}

void usb_stream_clock(void *ctx, double hitac10_seconds)
{
  struct usb_stream *s = ctx;
  s->hitac = hitac10_seconds;
}

/* ---- acknowledgements ------------------------------------------------------------- */

/* Mark p acknowledged in this pass; mine = 0 for dots the resumed run already had. */
static void mark_acked(struct usb_stream *s, const struct usb_point *p, int mine)
{
  if (p->pass != s->pass) return;               /* passes are flushed apart: never */
  int at = p->y * TUBE_W + p->x;
  if (s->acked[at]) return;
  s->acked[at] = 1;
  s->nacked++;
  if (mine) {
    s->acked_total++;
    if (!s->render_done) s->acked_before_end++;
    if (s->t_first_ack == 0) s->t_first_ack = usb_now();
  }
  while (s->prefix < s->produced &&
         s->acked[s->order[s->prefix].y * TUBE_W + s->order[s->prefix].x])
    s->prefix++;
  progress(s, 0);
}

static void on_ack(void *ctx, const struct usb_point *p)
{
  mark_acked(ctx, p, 1);
}

/* ---- resume file ------------------------------------------------------------------ */

static int read_resume(struct usb_stream *s, struct t74_error *err)
{
  const char *path = s->o.resume_in;
  FILE *f = fopen(path, "r");
  if (!f) return t74_fail(err, T74_EINPUT, "%s: cannot read the resume file: %s", path, strerror(errno));
  char line[512], key[32], val[400];
  int lineno = 0, version = 0, extra = -1, nextra = 0;
  int prefix = -1;
  long pass = -1;
  int st = T74_OK;
  while (fgets(line, sizeof line, f)) {
    lineno++;
    if (extra >= 0) {                           /* the "X Y" lines */
      int x, y;
      if (sscanf(line, "%d %d", &x, &y) != 2 || x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) {
        st = t74_fail_at(err, T74_EINPUT, path, lineno, "expected a dot `X Y` on the tube");
        break;
      }
      s->skip[y * TUBE_W + x] = 1;
      nextra++;
      continue;
    }
    if (sscanf(line, "%31s %399[^\n]", key, val) != 2) {
      st = t74_fail_at(err, T74_EINPUT, path, lineno, "expected `KEY VALUE`");
      break;
    }
    if (!strcmp(key, "tube74-resume")) version = atoi(val);
    else if (!strcmp(key, "hash")) {
      char want[32];
      snprintf(want, sizeof want, "%016" PRIx64, s->o.hash);
      if (strcmp(val, want)) {
        st = t74_fail_at(err, T74_EINPUT, path, lineno, "this resume file is for another scene "
                         "or other picture options (hash %s, this run %s)", val, want);
        break;
      }
    } else if (!strcmp(key, "device")) {
      if (strcmp(val, s->o.prof->name)) {
        st = t74_fail_at(err, T74_EINPUT, path, lineno, "this resume file is for the %s "
                         "profile, not %s", val, s->o.prof->name);
        break;
      }
    } else if (!strcmp(key, "pass")) pass = atol(val);
    else if (!strcmp(key, "prefix")) prefix = atoi(val);
    else if (!strcmp(key, "extra")) extra = atoi(val);
    /* scene, produced, acked: informative */
  }
  fclose(f);
  if (st != T74_OK) return st;
  if (version != 1 || pass < 0 || prefix < 0 || extra < 0 || nextra != extra)
    return t74_fail(err, T74_EINPUT, "%s: not a complete tube74 resume file (version 1)", path);
  if (s->o.repeat > 0 && pass >= s->o.repeat)
    return t74_fail(err, T74_EINPUT, "%s: pass %ld is beyond --repeat %d", path, pass + 1,
                    s->o.repeat);
  s->pass = (uint32_t)pass;
  s->skip_prefix = prefix;
  return T74_OK;
}

static int write_resume(struct usb_stream *s, struct t74_error *err)
{
  struct outfile *of;
  if (outfile_open(&of, s->o.resume_out, err) != T74_OK) return err->status;
  int extra = 0;
  for (int k = s->prefix; k < s->produced; k++)
    extra += s->acked[s->order[k].y * TUBE_W + s->order[k].x];
  outfile_printf(of, "tube74-resume 1\nscene %s\nhash %016" PRIx64 "\ndevice %s\n", s->o.scene,
                 s->o.hash, s->o.prof->name);
  outfile_printf(of, "pass %" PRIu32 "\nproduced %d\nacked %d\nprefix %d\nextra %d\n", s->pass,
                 s->produced, s->nacked, s->prefix, extra);
  for (int k = s->prefix; k < s->produced; k++)
    if (s->acked[s->order[k].y * TUBE_W + s->order[k].x])
      outfile_printf(of, "%d %d\n", s->order[k].x, s->order[k].y);
  return outfile_commit(of, err);
}

/* ---- the sink --------------------------------------------------------------------- */

/* The stop flag holds the signal that set it (cli/cmd_stream.c). */
static const char *stop_words(int sig)
{
  return sig == SIGTERM ? "stopped by SIGTERM" : sig == SIGHUP ? "stopped by SIGHUP"
                                                               : "stopped by Ctrl-C";
}

static int fail_point(struct usb_stream *s, int st, const struct t74_error *e)
{
  if (!s->failed) {
    s->failed = 1;
    s->err = *e;
  }
  return st;
}

static int stream_point(void *ctx, int x, int y)
{
  struct usb_stream *s = ctx;
  if (s->failed) return s->err.status;
  if (s->o.stop && *s->o.stop) {
    struct t74_error e = { T74_OK, "" };
    s->interrupted = 1;
    t74_fail(&e, T74_EIO, "%s: %s", s->o.prof->name, stop_words(*s->o.stop));
    return fail_point(s, T74_EIO, &e);
  }
  if (x < 0 || x >= TUBE_W || y < 0 || y >= TUBE_H) return T74_OK;   /* the tube reports it */
  int at = y * TUBE_W + x;
  if (s->seen[at]) return T74_OK;
  s->seen[at] = 1;
  struct usb_point p = { (int16_t)x, (int16_t)y, (uint32_t)s->produced, s->pass };
  s->order[s->produced++] = p;
  if ((int)p.seq < s->skip_prefix || s->skip[at]) {     /* acknowledged by the earlier run */
    mark_acked(s, &p, 0);
    return T74_OK;
  }
  struct t74_error e = { T74_OK, "" };
  if (s->o.prof->send(s->dev, &p, 1, &e) != T74_OK) return fail_point(s, e.status, &e);
  s->sent_total++;
  progress(s, 0);
  return T74_OK;
}

static int stream_end(void *ctx, struct t74_error *err)
{
  struct usb_stream *s = ctx;
  struct t74_error e = { T74_OK, "" };
  s->render_done = 1;                           /* rendering is over: end() comes after it */
  if (!s->failed && s->o.prof->flush(s->dev, &e) != T74_OK) fail_point(s, e.status, &e);
  progress(s, 1);
  if (s->failed) return t74_fail(err, s->err.status, "%s", s->err.msg);
  return T74_OK;
}

static void stream_abort(void *ctx)
{
  (void)ctx;                    /* usb_stream_finish closes the device and saves progress */
}

struct sink usb_stream_sink(struct usb_stream *s)
{
  struct sink k = { s, stream_point, stream_end, stream_abort };
  return k;
}

/* ---- open / finish ---------------------------------------------------------------- */

static void stream_free(struct usb_stream *s)
{
  free(s->order);
  free(s->seen);
  free(s->acked);
  free(s->skip);
  free(s);
}

int usb_stream_open(struct usb_stream **out, const struct usb_stream_opts *o, struct t74_error *err)
{
  *out = NULL;
  struct usb_stream *s = calloc(1, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "out of host memory");
  s->o = *o;
  s->order = malloc(sizeof *s->order * NDOTS);
  s->seen = calloc(NDOTS, 1);
  s->acked = calloc(NDOTS, 1);
  s->skip = calloc(NDOTS, 1);
  if (!s->order || !s->seen || !s->acked || !s->skip) {
    stream_free(s);
    return t74_fail(err, T74_EIO, "out of host memory");
  }
  if (o->resume_in && read_resume(s, err) != T74_OK) {
    stream_free(s);
    return err->status;
  }
  if (!(o->prof->links & USB_LINKS(o->kind))) {
    stream_free(s);
    return t74_fail(err, T74_EINPUT, "tube74: the %s profile cannot be driven %s", o->prof->name,
                    o->kind == USB_LINK_SERIAL ? "over a serial line" : o->kind == USB_LINK_USB
                    ? "over USB (give --serial DEV, or --to FILE / --dry-run)" : "into a file");
  }
  if (o->svg && preview_new(&s->pv, err) != T74_OK) {
    stream_free(s);
    return err->status;
  }
  int lst = o->kind == USB_LINK_SERIAL
              ? usb_link_open_serial(&s->link, o->serial, o->prof->name, &o->set, err)
          : o->kind == USB_LINK_FILE
              ? usb_link_open_file(&s->link, o->to, o->line_estimate, o->prof->name, &o->set, err)
              : usb_link_open(&s->link, &o->match, o->prof->name, &o->set, err);
  if (lst != T74_OK) {
    preview_free(s->pv);
    stream_free(s);
    return err->status;
  }
  usb_link_set_stop(s->link, o->stop);
  usb_link_set_preview(s->link, s->pv);
  struct usb_ack ack = { s, on_ack };
  if (o->prof->open(&s->dev, s->link, &o->set, ack, err) != T74_OK) {
    usb_link_close(s->link);
    preview_free(s->pv);
    stream_free(s);
    return err->status;
  }
  *out = s;
  return T74_OK;
}

/* One more pass of the whole picture, from the kept order. */
static int pass_again(struct usb_stream *s, struct t74_error *err)
{
  s->pass++;
  memset(s->acked, 0, NDOTS);
  s->nacked = 0;
  s->prefix = 0;
  for (int k = 0; k < s->produced; k++) {
    if (s->o.stop && *s->o.stop) {
      s->interrupted = 1;
      return t74_fail(err, T74_EIO, "%s: %s", s->o.prof->name, stop_words(*s->o.stop));
    }
    struct usb_point p = s->order[k];
    p.pass = s->pass;
    if (s->o.prof->send(s->dev, &p, 1, err) != T74_OK) return err->status;
    s->sent_total++;
    progress(s, 0);
  }
  return s->o.prof->flush(s->dev, err);
}

int usb_stream_finish(struct usb_stream *s, int status, struct t74_error *err)
{
  int st = status;
  if (s->failed && st == T74_OK) st = t74_fail(err, s->err.status, "%s", s->err.msg);
  if (s->failed) {                              /* the device's message, not the job's echo */
    *err = s->err;
    st = s->err.status;
  }
  /* s->pass is the pass just drawn (from 0): passes s->pass + 1 are complete */
  while (st == T74_OK && (s->o.repeat == 0 || s->pass + 1 < (uint32_t)s->o.repeat)) {
    /* --repeat 0 is "until stopped": Ctrl-C between whole pictures is the normal end */
    if (s->o.repeat == 0 && s->o.stop && *s->o.stop) break;
    if (pass_again(s, err) != T74_OK) st = err->status;
  }
  /* clean: the run completed; otherwise (failure, stop) the profile leaves the device safe
     at once. A vanished device the profile sees itself (usb_link_gone). */
  s->o.prof->close(s->dev, st == T74_OK);       /* pen up / laser blanked; acks may still come */
  progress(s, 1);
  if (s->o.progress) fputc('\n', s->o.progress);
  /* the file of commands and the preview: finished when the run completed, else discarded */
  if (st == T74_OK && s->o.svg) {
    char title[400], desc[200];
    snprintf(title, sizeof title, "tube74 stream %s --device %s", s->o.scene ? s->o.scene : "",
             s->o.prof->name);
    snprintf(desc, sizeof desc, "%d dots a pass, %u pass(es)", s->produced, s->pass + 1);
    if (preview_write(s->pv, s->o.svg, title, desc, err) != T74_OK) st = err->status;
  }
  if (st == T74_OK && s->o.svg && outfile_commit(s->o.svg, err) != T74_OK) st = err->status;
  else if (st != T74_OK && s->o.svg) outfile_abort(s->o.svg);
  if (s->o.kind == USB_LINK_FILE && s->o.to) {
    if (st == T74_OK) {
      if (outfile_commit(s->o.to, err) != T74_OK) st = err->status;
    } else {
      outfile_abort(s->o.to);
    }
  }
  if (s->o.result) {
    struct usb_stream_result *r = s->o.result;
    r->dots = s->produced;
    r->sent = s->sent_total;
    r->acked = s->acked_total;
    r->passes = (int)s->pass + 1;
    r->tally = *usb_link_tally(s->link);
    snprintf(r->device, sizeof r->device, "%s %s", s->o.prof->name,
             s->o.kind == USB_LINK_FILE ? (s->o.to ? "file" : "dry run") : usb_link_name(s->link));
  }
  int complete = st == T74_OK;
  if (!complete && st == T74_EIO && s->o.resume_out && s->o.kind != USB_LINK_FILE) {
    struct t74_error e = { T74_OK, "" };
    char note[1200];                            /* e.msg (1024) and the words around it */
    if (write_resume(s, &e) == T74_OK)
      snprintf(note, sizeof note, "\n%s: the device acknowledged %d of %d%s dots of pass %" PRIu32
               "; saved in %s — continue with --resume %s", s->o.prof->name, s->nacked,
               s->produced, s->render_done ? "" : " (so far)", s->pass + 1, s->o.resume_out,
               s->o.resume_out);
    else
      snprintf(note, sizeof note, "\n%s: and the resume file could not be written: %s",
               s->o.prof->name, e.msg);
    size_t n = strlen(err->msg);
    snprintf(err->msg + n, sizeof err->msg - n, "%s", note);
  } else if (complete && s->o.resume_out && s->o.kind != USB_LINK_FILE) {
    if (unlink(s->o.resume_out) != 0 && errno != ENOENT) { /* nothing left to resume */ }
  }
  usb_link_close(s->link);
  preview_free(s->pv);
  stream_free(s);
  return st;
}

int usb_stream_stats(void *ctx, struct outfile *of)
{
  struct usb_stream *s = ctx;
  const struct usb_counts *c = usb_link_counts(s->link);
  char dev[320];
  snprintf(dev, sizeof dev, "%s %s", s->o.prof->name,
           s->o.kind == USB_LINK_FILE ? (s->o.to ? "file" : "dry run") : usb_link_name(s->link));
  outfile_printf(of, "  \"usb_device\": ");
  outfile_json_string(of, dev);
  outfile_printf(of, ",\n  \"stream_link\": \"%s\",\n", s->o.kind == USB_LINK_USB ? "usb"
                 : s->o.kind == USB_LINK_SERIAL ? "serial" : "file");
  outfile_printf(of, "  \"stream_estimated_seconds\": %.3f,\n", s->o.expect_seconds);
  outfile_printf(of, "  \"usb_points_sent\": %lld,\n", s->sent_total);
  outfile_printf(of, "  \"usb_points_acknowledged\": %lld,\n", s->acked_total);
  outfile_printf(of, "  \"usb_acknowledged_before_render_end\": %lld,\n", s->acked_before_end);
  outfile_printf(of, "  \"usb_seconds_to_first_ack\": %.6f,\n",
                 s->t_first_ack > 0 ? s->t_first_ack - s->o.t0 : -1.0);
  outfile_printf(of, "  \"usb_transfers\": %ld,\n  \"usb_stalls\": %ld,\n  \"usb_timeouts\": %ld,\n",
                 c->transfers, c->stalls, c->timeouts);
  return T74_OK;
}
