/*
** sdl_load.c — SDL2 through dlopen for `tube74 play` (see sdl_load.h).
**
** This file contains the list of the SDL2 functions `play` calls: display/dynlib.h opens
** libSDL2-2.0.so.0 and looks each one up; a missing library or function is an I/O
** failure with the loader's reason, never a crash.
*/
#include "cli/sdl_load.h"

#include <string.h>

#include "display/dynlib.h"

#define SDL_LIB "libSDL2-2.0.so.0"

/* every slot of struct sdl_fns, by its name without SDL_ */
#define SDL_FNS(X) X(Init) X(Quit) X(GetError) X(GetCurrentVideoDriver) X(CreateWindow)    \
  X(CreateRenderer) X(CreateTexture) X(DestroyTexture) X(DestroyRenderer) X(DestroyWindow) \
  X(UpdateTexture) X(SetRenderDrawColor) X(RenderClear) X(RenderCopy) X(RenderDrawLine)    \
  X(RenderFillRect) X(RenderPresent) X(RenderReadPixels) X(PollEvent)                      \
  X(GetPerformanceCounter) X(GetPerformanceFrequency) X(Delay)

int sdl_load(struct sdl_fns *f, const char *what, struct t74_error *err)
{
#define SYM(name) { "SDL_" #name, offsetof(struct sdl_fns, name) },
  static const struct dynlib_sym syms[] = { SDL_FNS(SYM) };
#undef SYM
#define CHECK(name) DYNLIB_CHECK(f, name, SDL_##name);
  SDL_FNS(CHECK)
#undef CHECK
  return dynlib_open(f, sizeof *f, SDL_LIB, "SDL2", "libsdl2-2.0-0", syms,
                     sizeof syms / sizeof *syms, what, err);
}

void sdl_unload(struct sdl_fns *f)
{
  dynlib_close(f, sizeof *f);
}
