/*
** outfile.c — outputs that never destroy what a path names (see outfile.h).
**
** This file contains code to make every output of tube74 all-or-nothing (CONTRACT.md: a
** failed run leaves "no output file created or changed") without replacing what is not a
** plain file. A path is first followed through its symlinks, link by link (at most
** OUT_MAX_LINKS, the kernel's own limit), so that the temporary of a linked file sits
** beside the file itself — rename() is atomic only within one file system, and renaming
** over the link would replace the link. A link into /proc/self/fd/N or /dev/fd/N (as
** /dev/stdout is) names an open descriptor: that descriptor is written, duplicated, so
** the shell's offset and append mode hold. What the final name is (stat) decides the rest:
** a regular file or a new name goes through a temporary ".NAME.XXXXXX" that is flushed,
** fsync'd and renamed; a FIFO or a character device is opened and written directly.
** The first failure of any step is kept (sticky) and reported once, naming the file as
** it was given, as status.h asks.
*/
#include "display/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#define OUT_MAX_LINKS 40        /* symlinks followed before ELOOP (Linux's MAXSYMLINKS) */
#define OUT_TMP_NAME_MAX 200    /* a longer final name gets the temporary ".tube74.XXXXXX" */

enum out_kind {
  OUT_REPLACE,                  /* temporary in the target's folder, renamed at commit */
  OUT_DIRECT                    /* a descriptor written directly (stdout, FIFO, device) */
};

enum out_state {
  OS_OPEN,                      /* being written */
  OS_FINISHED,                  /* in a set: written and closed, waiting for the commit */
  OS_DONE                       /* committed or discarded: nothing left to undo */
};

struct outfile {
  char *path;                   /* the name as given, for messages */
  char *final;                  /* OUT_REPLACE: the name renamed over (symlinks followed) */
  char *tmp;                    /* OUT_REPLACE: the temporary, same folder */
  enum out_kind kind;
  enum out_state state;
  int fd;                       /* OUT_DIRECT: the descriptor written (ours, closed at end) */
  bool streamed;                /* OUT_DIRECT: f writes fd itself (else f is a buffer) */
  bool is_stdout;               /* `-` or a name of descriptor 1 */
  FILE *f;                      /* what the writer writes: temporary, buffer or fd */
  /* identity, for "the same file" */
  bool exists;                  /* dev/ino are the file's own */
  bool is_chr;                  /* a character device: may take several outputs */
  dev_t dev;                    /* existing: the file's; new: its folder's */
  ino_t ino;
  char *base;                   /* new name: its last component (with dev/ino of folder) */
  struct t74_error err;         /* first write failure, reported at commit */
  struct outset *set;           /* the set it belongs to, or NULL */
  struct outfile *next;         /* the set's list */
};

struct outset {
  struct outfile *first;        /* outputs in the order opened */
  bool stdout_taken;            /* standard output is written by someone outside the set */
};

/* ---- small helpers ------------------------------------------------------------------ */

static char *dup_str(const char *s)
{
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

/* Free o and everything it owns (its temporary must already be gone or renamed). */
static void release(struct outfile *o)
{
  free(o->path);
  free(o->final);
  free(o->tmp);
  free(o->base);
  free(o);
}

/* The mode fopen would give a new file: 0666 less the process umask. */
static mode_t new_file_mode(void)
{
  mode_t mask = umask(0);       /* umask can only be read by setting it: restore at once */
  umask(mask);
  return (mode_t)(0666 & ~mask);
}

/* The descriptor a name stands for: /proc/self/fd/N, /proc/thread-self/fd/N,
** /proc/PID/fd/N (PID ours) or /dev/fd/N; -1 for any other name. */
static int fd_alias(const char *p)
{
  static const char *const prefix[] = { "/proc/self/fd/", "/proc/thread-self/fd/", "/dev/fd/" };
  const char *rest = NULL;
  for (size_t k = 0; k < sizeof prefix / sizeof *prefix && !rest; k++)
    if (strncmp(p, prefix[k], strlen(prefix[k])) == 0) rest = p + strlen(prefix[k]);
  if (!rest && strncmp(p, "/proc/", 6) == 0) {
    char *end;
    long pid = strtol(p + 6, &end, 10);
    if (end != p + 6 && pid == (long)getpid() && strncmp(end, "/fd/", 4) == 0) rest = end + 4;
  }
  if (!rest || !*rest) return -1;
  long n = 0;
  for (const char *c = rest; *c; c++) {
    if (*c < '0' || *c > '9' || n > 1000000) return -1;
    n = n * 10 + (*c - '0');
  }
  return (int)n;
}

/* Follow path's symlinks to the name that is written: *alias >= 0 when that is an open
** descriptor. A malloc'd name, or NULL with errno set (ELOOP, ENOMEM). */
static char *resolve(const char *path, int *alias)
{
  *alias = -1;
  char *cur = dup_str(path);
  for (int hops = 0; cur; hops++) {
    if ((*alias = fd_alias(cur)) >= 0) return cur;
    struct stat st;
    if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) return cur;  /* not a link: it */
    if (hops == OUT_MAX_LINKS) { free(cur); errno = ELOOP; return NULL; }
    size_t cap = st.st_size > 0 ? (size_t)st.st_size + 1 : 256;
    char *lnk = NULL;
    ssize_t n;
    for (;;) {                  /* the link may change under us: grow until it fits */
      char *nl = realloc(lnk, cap);
      if (!nl) { free(lnk); free(cur); errno = ENOMEM; return NULL; }
      lnk = nl;
      n = readlink(cur, lnk, cap);
      if (n < 0) { free(lnk); return cur; }            /* gone meanwhile: write the name */
      if ((size_t)n < cap) break;
      cap *= 2;
    }
    lnk[n] = '\0';
    char *next;
    const char *slash = strrchr(cur, '/');
    if (lnk[0] == '/' || !slash) {
      next = lnk;               /* absolute, or relative to the current folder (as cur) */
    } else {                    /* relative to the link's own folder */
      size_t dl = (size_t)(slash - cur) + 1;
      next = malloc(dl + (size_t)n + 1);
      if (next) { memcpy(next, cur, dl); memcpy(next + dl, lnk, (size_t)n + 1); }
      free(lnk);
      if (!next) { free(cur); errno = ENOMEM; return NULL; }
    }
    free(cur);
    cur = next;
  }
  errno = ENOMEM;
  return NULL;
}

/* The temporary's name beside final: ".NAME.XXXXXX" in final's folder. */
static char *temp_name(const char *final)
{
  const char *slash = strrchr(final, '/');
  size_t dirlen = slash ? (size_t)(slash - final) + 1 : 0;    /* folder part, with its '/' */
  const char *name = final + dirlen;
  bool longname = strlen(name) > OUT_TMP_NAME_MAX;
  char *t = malloc(dirlen + (longname ? 0 : strlen(name)) + 16);
  if (!t) return NULL;
  memcpy(t, final, dirlen);
  if (longname) strcpy(t + dirlen, ".tube74.XXXXXX");
  else sprintf(t + dirlen, ".%s.XXXXXX", name);
  return t;
}

/* The folder of a new name and its last component, for "the same new name". */
static int new_identity(struct outfile *o, const char *final)
{
  const char *slash = strrchr(final, '/');
  char *dir = slash ? malloc((size_t)(slash - final) + 2) : dup_str(".");
  if (!dir) return -1;
  if (slash) {
    size_t dl = slash == final ? 1 : (size_t)(slash - final);   /* "/x": the root */
    memcpy(dir, final, dl);
    dir[dl] = '\0';
  }
  struct stat st;
  int rc = stat(dir, &st);
  free(dir);
  o->base = dup_str(slash ? slash + 1 : final);
  if (!o->base) return -1;
  if (rc == 0) { o->dev = st.st_dev; o->ino = st.st_ino; }
  return 0;
}

/* ---- opening ------------------------------------------------------------------------ */

/* Open a direct output on descriptor fd (ours): a buffer unless streamed. */
static int open_direct(struct outfile *o, int fd, bool stream, struct t74_error *err)
{
  struct stat st;
  if (fstat(fd, &st) == 0) {
    o->exists = true;
    o->dev = st.st_dev;
    o->ino = st.st_ino;
    o->is_chr = S_ISCHR(st.st_mode);
  }
  o->kind = OUT_DIRECT;
  o->fd = fd;
  o->streamed = stream;
  if (stream) {
    int fd2 = dup(fd);          /* the FILE owns fd2; o->fd stays for the identity */
    o->f = fd2 >= 0 ? fdopen(fd2, "wb") : NULL;
    if (!o->f && fd2 >= 0) close(fd2);
  } else {
    o->f = tmpfile();
  }
  if (!o->f) return t74_fail(err, T74_EIO, "%s: cannot write: %s", o->path, strerror(errno));
  return T74_OK;
}

/* Classify and open path into o (o->path set). */
static int prepare(struct outfile *o, unsigned flags, bool in_set, struct t74_error *err)
{
  const char *path = o->path;
  bool stream = !in_set || (flags & OUTFILE_STREAM);
  o->fd = -1;
  if (!path[0]) return t74_fail(err, T74_EINPUT, "tube74: an output's name is empty");
  if (strcmp(path, "-") == 0) {
    int fd = fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3);
    if (fd < 0) return t74_fail(err, T74_EIO, "-: standard output: %s", strerror(errno));
    o->is_stdout = true;
    return open_direct(o, fd, stream, err);
  }
  int alias;
  char *final = resolve(path, &alias);
  if (!final) return t74_fail(err, T74_EIO, "%s: cannot write: %s", path, strerror(errno));
  if (alias >= 0) {
    free(final);
    int fd = fcntl(alias, F_DUPFD_CLOEXEC, 3);
    if (fd < 0) return t74_fail(err, T74_EIO, "%s: descriptor %d: %s", path, alias, strerror(errno));
    o->is_stdout = alias == STDOUT_FILENO;
    return open_direct(o, fd, stream, err);
  }
  struct stat st;
  bool exists = stat(final, &st) == 0;
  if (!exists && errno != ENOENT) {
    int e = errno;
    free(final);
    return t74_fail(err, T74_EIO, "%s: cannot write: %s", path, strerror(e));
  }
  if (exists && (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))) {
    /* never replaced: opened as it is (a FIFO waits here for its reader) */
    int fd = open(final, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    int e = errno;
    free(final);
    if (fd < 0) return t74_fail(err, T74_EIO, "%s: cannot write: %s", path, strerror(e));
    return open_direct(o, fd, stream, err);
  }
  if (exists && !S_ISREG(st.st_mode)) {
    free(final);
    return t74_fail(err, T74_EIO, "%s: cannot write: %s", path,
                    S_ISDIR(st.st_mode) ? "it is a folder" :
                    S_ISBLK(st.st_mode) ? "it is a block device (tube74 does not write disks)" :
                    "it is not a file, a FIFO or a character device");
  }
  if (exists && access(final, W_OK) != 0) {
    int e = errno;
    free(final);
    return t74_fail(err, T74_EIO, "%s: cannot write: %s", path, strerror(e));
  }
  o->kind = OUT_REPLACE;
  o->final = final;
  if (exists) { o->exists = true; o->dev = st.st_dev; o->ino = st.st_ino; }
  else if (new_identity(o, final) != 0) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  o->tmp = temp_name(final);
  if (!o->tmp) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  int fd = mkstemp(o->tmp);
  if (fd < 0) {
    int e = errno;
    free(o->tmp);
    o->tmp = NULL;
    return t74_fail(err, T74_EIO, "%s: cannot create: %s", path, strerror(e));
  }
  /* the new file keeps an existing file's permission bits (and, as root, its owner) */
  mode_t mode = exists ? (mode_t)(st.st_mode & 07777) : new_file_mode();
  if (exists && geteuid() == 0 && fchown(fd, st.st_uid, st.st_gid) != 0) { /* best effort */ }
  if (fchmod(fd, mode) != 0 || (o->f = fdopen(fd, "wb")) == NULL) {
    int e = errno;
    close(fd);
    unlink(o->tmp);
    free(o->tmp);
    o->tmp = NULL;
    return t74_fail(err, T74_EIO, "%s: cannot create: %s", path, strerror(e));
  }
  return T74_OK;
}

/* A new outfile for path, opened; NULL with err set. */
static struct outfile *make(const char *path, unsigned flags, struct outset *set,
                            struct t74_error *err)
{
  struct outfile *o = calloc(1, sizeof *o);
  if (!o || !(o->path = dup_str(path))) {
    free(o);
    t74_fail(err, T74_EIO, "%s: out of memory", path);
    return NULL;
  }
  o->set = set;
  if (prepare(o, flags, set != NULL, err) != T74_OK) {
    if (o->fd >= 0) close(o->fd);
    if (o->f) fclose(o->f);
    release(o);
    return NULL;
  }
  return o;
}

int outfile_open(struct outfile **out, const char *path, struct t74_error *err)
{
  struct outfile *o = make(path, 0, NULL, err);
  if (!o) return err->status;
  *out = o;
  return T74_OK;
}

FILE *outfile_stream(struct outfile *o) { return o->f; }

const char *outfile_path(const struct outfile *o) { return o->path; }

/* ---- writing ------------------------------------------------------------------------ */

int outfile_write(struct outfile *o, const void *buf, size_t n)
{
  if (o->err.status != T74_OK) return o->err.status;
  if (n > 0 && fwrite(buf, 1, n, o->f) != n)
    return t74_fail(&o->err, T74_EIO, "%s: write failed: %s", o->path, strerror(errno));
  return T74_OK;
}

int outfile_printf(struct outfile *o, const char *fmt, ...)
{
  if (o->err.status != T74_OK) return o->err.status;
  va_list ap;
  va_start(ap, fmt);
  int rc = vfprintf(o->f, fmt, ap);
  va_end(ap);
  if (rc < 0)
    return t74_fail(&o->err, T74_EIO, "%s: write failed: %s", o->path, strerror(errno));
  return T74_OK;
}

/* Length of the valid UTF-8 sequence at s (RFC 3629: no overlong forms, no surrogates,
** nothing above U+10FFFF), or 0 when the byte at s does not start one. */
static size_t utf8_len(const unsigned char *s)
{
  unsigned char c = s[0];
  unsigned char lo = 0x80, hi = 0xBF;     /* the range of the second byte */
  size_t n;
  if (c >= 0xC2 && c <= 0xDF) n = 2;
  else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) lo = 0xA0;             /* overlong below U+0800 */
    if (c == 0xED) hi = 0x9F;             /* U+D800..DFFF: surrogates */
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) lo = 0x90;             /* overlong below U+10000 */
    if (c == 0xF4) hi = 0x8F;             /* above U+10FFFF */
  } else return 0;
  if (s[1] < lo || s[1] > hi) return 0;
  for (size_t k = 2; k < n; k++)
    if (s[k] < 0x80 || s[k] > 0xBF) return 0;   /* also stops at the NUL */
  return n;
}

int outfile_json_string(struct outfile *o, const char *str)
{
  const unsigned char *s = (const unsigned char *)str;
  char buf[256];                /* escaped text, flushed when nearly full */
  size_t n = 0;
  buf[n++] = '"';
  while (*s) {
    if (n > sizeof buf - 16) { outfile_write(o, buf, n); n = 0; }
    unsigned char c = *s;
    if (c == '"' || c == '\\') { buf[n++] = '\\'; buf[n++] = (char)c; s++; }
    else if (c == '\n') { memcpy(buf + n, "\\n", 2); n += 2; s++; }
    else if (c == '\t') { memcpy(buf + n, "\\t", 2); n += 2; s++; }
    else if (c == '\r') { memcpy(buf + n, "\\r", 2); n += 2; s++; }
    else if (c < 0x20 || c == 0x7F) { n += (size_t)sprintf(buf + n, "\\u%04x", c); s++; }
    else if (c < 0x80) { buf[n++] = (char)c; s++; }
    else {
      size_t len = utf8_len(s);
      if (len) { memcpy(buf + n, s, len); n += len; s += len; }
      else { memcpy(buf + n, "\\ufffd", 6); n += 6; s++; }   /* not UTF-8: U+FFFD */
    }
  }
  buf[n++] = '"';
  return outfile_write(o, buf, n);
}

/* ---- finishing ---------------------------------------------------------------------- */

/* Remove whatever o still holds (stream, temporary, descriptor); o->state = OS_DONE. */
static void discard(struct outfile *o)
{
  if (o->f) fclose(o->f);
  o->f = NULL;
  if (o->tmp) unlink(o->tmp);
  if (o->fd >= 0) close(o->fd);
  o->fd = -1;
  o->state = OS_DONE;
}

/* Flush and (a temporary) sync; a regular output's stream is closed. T74_OK or the
** first failure, with the temporary removed. */
static int finish(struct outfile *o, struct t74_error *err)
{
  int status = o->err.status;
  if (status != T74_OK) t74_fail(err, status, "%s", o->err.msg);
  if (status == T74_OK && (fflush(o->f) != 0 || ferror(o->f)))
    status = t74_fail(err, T74_EIO, "%s: write failed: %s", o->path, strerror(errno));
  if (status == T74_OK && o->kind == OUT_REPLACE && fsync(fileno(o->f)) != 0)
    status = t74_fail(err, T74_EIO, "%s: sync failed: %s", o->path, strerror(errno));
  if (o->kind == OUT_REPLACE || o->streamed) {
    if (fclose(o->f) != 0 && status == T74_OK)
      status = t74_fail(err, T74_EIO, "%s: close failed: %s", o->path, strerror(errno));
    o->f = NULL;
  }
  if (status != T74_OK) discard(o);
  else o->state = OS_FINISHED;
  return status;
}

/* Publish a finished output: a buffered direct one gets its bytes, a temporary is
** renamed. Then nothing is left to undo. */
static int publish(struct outfile *o, struct t74_error *err)
{
  int status = T74_OK;
  if (o->kind == OUT_DIRECT && !o->streamed) {
    if (o->is_stdout) fflush(stdout);       /* anything printf'd before goes first */
    rewind(o->f);
    char buf[16384];
    size_t n;
    while (status == T74_OK && (n = fread(buf, 1, sizeof buf, o->f)) > 0)
      for (size_t at = 0; status == T74_OK && at < n; ) {
        ssize_t w = write(o->fd, buf + at, n - at);
        if (w > 0) at += (size_t)w;
        else if (w < 0 && errno == EINTR) continue;
        else status = t74_fail(err, T74_EIO, "%s: write failed: %s", o->path,
                               w < 0 ? strerror(errno) : "nothing written");
      }
    if (status == T74_OK && ferror(o->f))
      status = t74_fail(err, T74_EIO, "%s: write failed: cannot read back the buffer", o->path);
  }
  if (o->kind == OUT_REPLACE) {
    if (rename(o->tmp, o->final) != 0)
      status = t74_fail(err, T74_EIO, "%s: cannot replace: %s", o->path, strerror(errno));
    else { free(o->tmp); o->tmp = NULL; }
  }
  discard(o);
  return status;
}

int outfile_commit(struct outfile *o, struct t74_error *err)
{
  if (o->state != OS_OPEN) {    /* finished twice, or after an abort */
    int st = o->state == OS_FINISHED ? T74_OK
           : t74_fail(err, T74_EIO, "%s: output already discarded", o->path);
    if (!o->set) release(o);
    return st;
  }
  int st = finish(o, err);
  if (!o->set) {
    if (st == T74_OK) st = publish(o, err);
    release(o);
  }
  return st;
}

void outfile_abort(struct outfile *o)
{
  discard(o);
  if (!o->set) release(o);
}

/* ---- sets --------------------------------------------------------------------------- */

int outset_new(struct outset **out, struct t74_error *err)
{
  struct outset *s = calloc(1, sizeof *s);
  if (!s) return t74_fail(err, T74_EIO, "out of host memory");
  *out = s;
  return T74_OK;
}

/* Are a and b the same file, as outfile.h defines it? */
static bool same_file(const struct outfile *a, const struct outfile *b)
{
  if (a->is_stdout && b->is_stdout) return true;
  if (a->exists && b->exists)
    return a->dev == b->dev && a->ino == b->ino && !a->is_chr;   /* /dev/null twice: fine */
  if (!a->exists && !b->exists && a->base && b->base)
    return a->dev == b->dev && a->ino == b->ino && strcmp(a->base, b->base) == 0;
  return false;
}

int outset_open(struct outset *s, const char *path, unsigned flags, struct outfile **out,
                struct t74_error *err)
{
  struct outfile *o = make(path, flags, s, err);
  if (!o) return err->status;
  int st = T74_OK;
  if (o->is_stdout && s->stdout_taken)
    st = t74_fail(err, T74_EINPUT, "tube74: %s: standard output already takes another output; "
                  "each output needs its own file", path);
  for (struct outfile *p = s->first; p && st == T74_OK; p = p->next)
    if (same_file(o, p))
      st = t74_fail(err, T74_EINPUT, "tube74: %s: the same file as the output %s; each output "
                    "needs its own file", path, p->path);
  if (st != T74_OK) {
    discard(o);
    release(o);
    return st;
  }
  struct outfile **end = &s->first;       /* keep the order: committed as opened */
  while (*end) end = &(*end)->next;
  *end = o;
  *out = o;
  return T74_OK;
}

int outset_reserve_stdout(struct outset *s, struct t74_error *err)
{
  for (struct outfile *p = s->first; p; p = p->next)
    if (p->is_stdout)
      return t74_fail(err, T74_EINPUT, "tube74: %s: standard output already takes another "
                      "output; each output needs its own file", p->path);
  s->stdout_taken = true;
  return T74_OK;
}

int outset_check_input(const struct outset *s, const char *input, const char *what,
                       struct t74_error *err)
{
  struct stat st;
  if (!input || stat(input, &st) != 0) return T74_OK;
  for (const struct outfile *p = s->first; p; p = p->next)
    if (p->exists && !p->is_chr && p->dev == st.st_dev && p->ino == st.st_ino)
      return t74_fail(err, T74_EINPUT, "tube74: %s: is the %s %s; an output may not "
                      "overwrite an input", p->path, what, input);
  return T74_OK;
}

int outset_commit(struct outset *s, struct t74_error *err)
{
  for (struct outfile *p = s->first; p; p = p->next)
    if (p->state != OS_FINISHED)
      return t74_fail(err, T74_EIO, "%s: the output was not written", p->path);
  int st = T74_OK;
  /* direct outputs first: a write that fails there (a full device, a closed pipe) still
     leaves every regular file untouched */
  for (struct outfile *p = s->first; p && st == T74_OK; p = p->next)
    if (p->kind == OUT_DIRECT) st = publish(p, err);
  for (struct outfile *p = s->first; p && st == T74_OK; p = p->next)
    if (p->kind == OUT_REPLACE) st = publish(p, err);
  return st;
}

void outset_free(struct outset *s)
{
  if (!s) return;
  for (struct outfile *p = s->first, *next; p; p = next) {
    next = p->next;
    if (p->state != OS_DONE) discard(p);
    release(p);
  }
  free(s);
}
