/*
** teach_page.h — the fixed parts of the teaching page `tube74 teach` writes: the head
** (style, layout, buttons) before the data and the tail (the script that draws every step
** from the data) after it.
**
** Both come from cli/teach_page.html, split at its line "<!-- data -->" and turned into
** C strings at build time (tools/text2c.sh, the Makefile); edit that file. The data is one
** script element defining `const T = {...}` (cli/cmd_teach.c). The page reads, besides the
** buttons and the arrow keys, its address's fragment: #step=N opens step N (1 = the
** first), #all shows every step one below the other, #line=J picks the D-blocks' grid row,
** and #keys=RLUDHE presses ArrowRight, ArrowLeft, ArrowUp, ArrowDown, Home, End in turn
** after loading, through the same key handler a reader's keys go to (for checking).
*/
#ifndef T74_TEACH_PAGE_H
#define T74_TEACH_PAGE_H

extern const char teach_page_head[];
extern const char teach_page_tail[];

#endif
