/*
** sdl_load.c — SDL2 through dlopen for `tube74 play` (see sdl_load.h).
**
** This file contains code to open libSDL2-2.0.so.0 and look up each function `play` uses;
** a missing library or symbol is an I/O failure with the loader's reason, never a crash.
*/
#include "cli/sdl_load.h"

#include <dlfcn.h>
#include <string.h>

#define SDL_LIB "libSDL2-2.0.so.0"

int sdl_load(struct sdl_fns *f, const char *what, struct t74_error *err)
{
  memset(f, 0, sizeof *f);
  void *lib = dlopen(SDL_LIB, RTLD_NOW | RTLD_LOCAL);
  if (!lib) return t74_fail(err, T74_EIO, "%s: cannot load SDL2 (%s)", what, dlerror());
  const char *missing = NULL;
  /* POSIX: a dlsym result converts to a function pointer; copied bytewise, as ISO C
     has no cast between object and function pointers */
#define LOAD(name) do {                                          \
    void *sym = dlsym(lib, "SDL_" #name);                        \
    if (!sym && !missing) missing = "SDL_" #name;                \
    memcpy(&f->name, &sym, sizeof sym);                          \
  } while (0)
  LOAD(Init); LOAD(Quit); LOAD(GetError); LOAD(GetCurrentVideoDriver);
  LOAD(CreateWindow); LOAD(CreateRenderer); LOAD(CreateTexture);
  LOAD(DestroyTexture); LOAD(DestroyRenderer); LOAD(DestroyWindow);
  LOAD(UpdateTexture); LOAD(SetRenderDrawColor); LOAD(RenderClear); LOAD(RenderCopy);
  LOAD(RenderDrawLine); LOAD(RenderFillRect); LOAD(RenderPresent); LOAD(RenderReadPixels);
  LOAD(PollEvent); LOAD(GetPerformanceCounter); LOAD(GetPerformanceFrequency); LOAD(Delay);
#undef LOAD
  if (missing) {
    dlclose(lib);
    memset(f, 0, sizeof *f);
    return t74_fail(err, T74_EIO, "%s: %s has no %s", what, SDL_LIB, missing);
  }
  f->lib = lib;
  return T74_OK;
}

void sdl_unload(struct sdl_fns *f)
{
  if (f->lib) dlclose(f->lib);
  memset(f, 0, sizeof *f);
}
