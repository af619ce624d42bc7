/*
** dynlib.c — shared libraries opened with dlopen when first needed (see dynlib.h).
**
** This file contains code to open a library and copy the address of each function a
** caller's table lists into its slot; the loader's own words say why a library is
** missing, and a missing function is named.
*/
#include "display/dynlib.h"

#include <dlfcn.h>
#include <string.h>

int dynlib_open(void *table, size_t size, const char *soname, const char *label,
                const char *package, const struct dynlib_sym *syms, size_t n,
                const char *what, struct t74_error *err)
{
  memset(table, 0, size);
  void *h = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    const char *why = dlerror();
    return t74_fail(err, T74_EIO, "%s: cannot load %s (%s); install the Debian package %s",
                    what, label, why ? why : soname, package);
  }
  for (size_t k = 0; k < n; k++) {
    void *sym = dlsym(h, syms[k].name);
    if (!sym) {
      dlclose(h);
      memset(table, 0, size);
      return t74_fail(err, T74_EIO, "%s: %s has no %s", what, soname, syms[k].name);
    }
    memcpy((char *)table + syms[k].at, &sym, sizeof sym);
  }
  memcpy(table, &h, sizeof h);          /* the first member, void *lib */
  return T74_OK;
}

void dynlib_close(void *table, size_t size)
{
  void *h;
  memcpy(&h, table, sizeof h);
  if (h) dlclose(h);
  memset(table, 0, size);
}
