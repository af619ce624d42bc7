/*
** outfile.c — atomic output files: temporary in the same folder, then rename.
**
** This file contains code to make every output of tube74 all-or-nothing (CONTRACT.md: a
** failed run leaves "no output file created or changed"). The temporary sits beside the
** final file — not in /tmp — because rename() is atomic only within one file system.
** It is named ".NAME.XXXXXX" (hidden, recognisably ours). Before the rename the data are
** flushed and fsync'd, so a crash after the rename cannot leave a renamed but empty file.
** The first failure of any step is kept (sticky) and reported once at commit, naming the
** final file, as status.h asks.
*/
#include "display/outfile.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

struct outfile {
  char *path;                   /* the final name, as given */
  char *tmp;                    /* the temporary: same folder, ".NAME.XXXXXX" */
  FILE *f;                      /* stream on the temporary */
  struct t74_error err;         /* first write failure, reported at commit */
};

/* Free o and everything it owns (the temporary must already be gone or renamed). */
static void release(struct outfile *o)
{
  free(o->path);
  free(o->tmp);
  free(o);
}

/* The mode fopen would give a new file: 0666 less the process umask. */
static mode_t new_file_mode(void)
{
  mode_t mask = umask(0);       /* umask can only be read by setting it: restore at once */
  umask(mask);
  return (mode_t)(0666 & ~mask);
}

int outfile_open(struct outfile **out, const char *path, struct t74_error *err)
{
  struct outfile *o = calloc(1, sizeof *o);
  if (!o) return t74_fail(err, T74_EIO, "%s: out of memory", path);
  size_t len = strlen(path);
  o->path = malloc(len + 1);
  o->tmp = malloc(len + 9);     /* "." + path + ".XXXXXX" + NUL */
  if (!o->path || !o->tmp) {
    release(o);
    return t74_fail(err, T74_EIO, "%s: out of memory", path);
  }
  memcpy(o->path, path, len + 1);
  const char *slash = strrchr(path, '/');
  size_t dirlen = slash ? (size_t)(slash - path) + 1 : 0;  /* folder part, with its '/' */
  memcpy(o->tmp, path, dirlen);
  sprintf(o->tmp + dirlen, ".%s.XXXXXX", path + dirlen);

  int fd = mkstemp(o->tmp);
  if (fd < 0) {
    int e = errno;
    release(o);
    return t74_fail(err, T74_EIO, "%s: cannot create: %s", path, strerror(e));
  }
  if (fchmod(fd, new_file_mode()) != 0 || (o->f = fdopen(fd, "wb")) == NULL) {
    int e = errno;
    close(fd);
    unlink(o->tmp);
    release(o);
    return t74_fail(err, T74_EIO, "%s: cannot create: %s", path, strerror(e));
  }
  *out = o;
  return T74_OK;
}

FILE *outfile_stream(struct outfile *o)
{
  return o->f;
}

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

int outfile_commit(struct outfile *o, struct t74_error *err)
{
  int status = o->err.status;
  if (status != T74_OK) t74_fail(err, status, "%s", o->err.msg);

  /* Each step runs only if all before it succeeded; the first failure is the message. */
  if (status == T74_OK && (fflush(o->f) != 0 || ferror(o->f)))
    status = t74_fail(err, T74_EIO, "%s: write failed: %s", o->path, strerror(errno));
  if (status == T74_OK && fsync(fileno(o->f)) != 0)
    status = t74_fail(err, T74_EIO, "%s: sync failed: %s", o->path, strerror(errno));
  if (fclose(o->f) != 0 && status == T74_OK)
    status = t74_fail(err, T74_EIO, "%s: close failed: %s", o->path, strerror(errno));
  if (status == T74_OK && rename(o->tmp, o->path) != 0)
    status = t74_fail(err, T74_EIO, "%s: cannot replace: %s", o->path, strerror(errno));

  if (status != T74_OK) unlink(o->tmp);
  release(o);
  return status;
}

void outfile_abort(struct outfile *o)
{
  fclose(o->f);
  unlink(o->tmp);
  release(o);
}
