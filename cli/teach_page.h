/*
** teach_page.h — the fixed parts of the teaching page `tube74 teach` writes
** (cli/teach_page.c): the head (style, layout, buttons) before the data and the tail
** (the script that draws each step from the data) after it.
**
** The data is one script element defining `const T = {...}` (cli/cmd_teach.c). The page
** reads, besides the buttons and the arrow keys, one hash parameter for checking it
** without a person at the keyboard: `#keys=RRLUD` presses ArrowRight, ArrowRight,
** ArrowLeft, ArrowUp, ArrowDown in turn after loading, through the same key handler a
** reader's keys go to (tests/test_teach.c drives headless Chromium with it).
*/
#ifndef T74_TEACH_PAGE_H
#define T74_TEACH_PAGE_H

extern const char teach_page_head[];
extern const char teach_page_tail[];

#endif
