/*
** sdl_load.h — SDL2 loaded when a window is wanted, not at start-up (issue 12).
**
** This file contains the table of the SDL2 functions `tube74 play` calls. The program is
** not linked against SDL2: a render never opens a window, and loading SDL2 with the some
** fifty libraries it depends on cost every run milliseconds before main(). sdl_load opens
** libSDL2-2.0.so.0 with dlopen (display/dynlib.h) and fills the table; the types and
** constants still come from <SDL.h> at compile time, and each slot's type is checked
** against its declaration there, so a call through the table is checked as a direct call
** would be.
*/
#ifndef T74_SDL_LOAD_H
#define T74_SDL_LOAD_H

#include <SDL.h>

#include "emu/status.h"

struct sdl_fns {
  void *lib;                                    /* dlopen handle, NULL: not loaded (first:
                                                   display/dynlib.h) */
  int (*Init)(Uint32);
  void (*Quit)(void);
  const char *(*GetError)(void);
  const char *(*GetCurrentVideoDriver)(void);
  SDL_Window *(*CreateWindow)(const char *, int, int, int, int, Uint32);
  SDL_Renderer *(*CreateRenderer)(SDL_Window *, int, Uint32);
  SDL_Texture *(*CreateTexture)(SDL_Renderer *, Uint32, int, int, int);
  void (*DestroyTexture)(SDL_Texture *);
  void (*DestroyRenderer)(SDL_Renderer *);
  void (*DestroyWindow)(SDL_Window *);
  int (*UpdateTexture)(SDL_Texture *, const SDL_Rect *, const void *, int);
  int (*SetRenderDrawColor)(SDL_Renderer *, Uint8, Uint8, Uint8, Uint8);
  int (*RenderClear)(SDL_Renderer *);
  int (*RenderCopy)(SDL_Renderer *, SDL_Texture *, const SDL_Rect *, const SDL_Rect *);
  int (*RenderDrawLine)(SDL_Renderer *, int, int, int, int);
  int (*RenderFillRect)(SDL_Renderer *, const SDL_Rect *);
  void (*RenderPresent)(SDL_Renderer *);
  int (*RenderReadPixels)(SDL_Renderer *, const SDL_Rect *, Uint32, void *, int);
  int (*PollEvent)(SDL_Event *);
  Uint64 (*GetPerformanceCounter)(void);
  Uint64 (*GetPerformanceFrequency)(void);
  void (*Delay)(Uint32);
};

/* Load SDL2 into f: T74_OK, or T74_EIO with "what: SDL2 ..." in err (f->lib NULL). */
int sdl_load(struct sdl_fns *f, const char *what, struct t74_error *err);

/* Close the library (nothing when not loaded). */
void sdl_unload(struct sdl_fns *f);

#endif
