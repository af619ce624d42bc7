/*
** testkit.c — the scratch folder, shell and file helpers the test programs share.
**
** This file contains the small process and file plumbing of the tests (tests/ref/
** testkit.h): mkdtemp scratch folders removed with readdir/lstat (no shell, so names need
** no quoting), system(3) commands run inside a folder, fork/exec of the program under
** test with its output redirected, and whole-file reading that grows its buffer as it
** reads (pipes and /proc files have no size to ask for).
*/
#include "tests/ref/testkit.h"

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

int tk_mkscratch(char *dir, size_t cap, const char *template)
{
  if (strlen(template) >= cap) return -1;
  strcpy(dir, template);
  return mkdtemp(dir) ? 0 : -1;
}

/* Remove what is below path; remove path itself too when self. */
static int rm_tree(const char *path, int self)
{
  struct stat st;
  if (lstat(path, &st) != 0) return -1;
  int rc = 0;
  if (S_ISDIR(st.st_mode)) {
    DIR *d = opendir(path);
    if (!d) return -1;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
      if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
      size_t n = strlen(path) + strlen(e->d_name) + 2;
      char *p = malloc(n);
      if (!p) { rc = -1; break; }
      snprintf(p, n, "%s/%s", path, e->d_name);
      if (rm_tree(p, 1) != 0) rc = -1;
      free(p);
    }
    closedir(d);
    if (self && rmdir(path) != 0) rc = -1;
  } else if (self && unlink(path) != 0) {
    rc = -1;
  }
  return rc;
}

int tk_rmscratch(const char *dir)
{
  if (rm_tree(dir, 1) == 0) return 0;
  fprintf(stderr, "could not remove %s\n", dir);
  return -1;
}

int tk_clear(const char *dir)
{
  return rm_tree(dir, 0);
}

const char *tk_prog(void)
{
  const char *p = getenv("TUBE74");
  return p && *p ? p : "./tube74";
}

int tk_exe(char *out, size_t cap)
{
  const char *t = tk_prog();
  int k;
  if (t[0] == '/') {
    k = snprintf(out, cap, "%s", t);
  } else {
    char cwd[512];
    if (!getcwd(cwd, sizeof cwd)) return -1;
    k = snprintf(out, cap, "%s/%s", cwd, t);
  }
  return k >= 0 && (size_t)k < cap ? 0 : -1;
}

int tk_vsh(const char *dir, const char *fmt, va_list ap)
{
  va_list aq;
  va_copy(aq, ap);
  int n = vsnprintf(NULL, 0, fmt, aq);
  va_end(aq);
  if (n < 0) return -1;
  size_t cap = strlen(dir) + (size_t)n + 8;
  char *cmd = malloc(cap);
  if (!cmd) return -1;
  int k = snprintf(cmd, cap, "cd %s && ", dir);
  vsnprintf(cmd + k, cap - (size_t)k, fmt, ap);
  int rc = system(cmd);
  free(cmd);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

int tk_sh(const char *dir, const char *fmt, ...)
{
  va_list ap;
  va_start(ap, fmt);
  int rc = tk_vsh(dir, fmt, ap);
  va_end(ap);
  return rc;
}

int tk_run(const char *const argv[], const char *out_path, const char *err_path)
{
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    int fo = open(out_path ? out_path : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int fe = open(err_path ? err_path : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fo < 0 || fe < 0) _exit(126);
    dup2(fo, 1);
    dup2(fe, 2);
    execv(argv[0], (char *const *)argv);
    _exit(127);
  }
  int st;
  if (waitpid(pid, &st, 0) != pid) return -1;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int tk_vrunl(const char *out_path, const char *err_path, va_list ap)
{
  const char *argv[64];
  int n = 0;
  argv[n++] = tk_prog();
  const char *a;
  while ((a = va_arg(ap, const char *)) != NULL && n < 63) argv[n++] = a;
  argv[n] = NULL;
  return tk_run(argv, out_path, err_path);
}

int tk_runl(const char *out_path, const char *err_path, ...)
{
  va_list ap;
  va_start(ap, err_path);
  int rc = tk_vrunl(out_path, err_path, ap);
  va_end(ap);
  return rc;
}

char *tk_slurp(const char *path, size_t *n)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 1 << 16, len = 0;
  char *b = malloc(cap + 1);
  while (b) {
    len += fread(b + len, 1, cap - len, f);
    if (len < cap) break;
    char *nb = realloc(b, 2 * cap + 1);
    if (!nb) { free(b); b = NULL; break; }
    b = nb;
    cap *= 2;
  }
  int bad = ferror(f);
  fclose(f);
  if (b && bad) { free(b); b = NULL; }
  if (!b) return NULL;
  b[len] = 0;
  if (n) *n = len;
  return b;
}

int tk_put(const char *path, const void *data, size_t n)
{
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  int ok = fwrite(data, 1, n, f) == n;
  if (fclose(f) != 0) ok = 0;
  return ok ? 0 : -1;
}

int tk_stat(const char *path, const char *key, double *v)
{
  char *s = tk_slurp(path, NULL);
  if (!s) return -1;
  char k[96];
  snprintf(k, sizeof k, "\"%s\":", key);
  const char *p = strstr(s, k);
  int r = p ? 0 : -1;
  *v = 0;
  if (p) {
    p += strlen(k);
    while (*p == ' ') p++;
    if (!strncmp(p, "null", 4)) r = 1;
    else *v = !strncmp(p, "true", 4) ? 1 : !strncmp(p, "false", 5) ? 0 : atof(p);
  }
  free(s);
  return r;
}
