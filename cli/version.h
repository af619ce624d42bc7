/*
** version.h — the version `tube74 --version` prints and the man page (tube74.1) names.
** One place: change it here and in tube74.1's .TH line (tests/test_install.c checks they
** agree).
*/
#ifndef T74_VERSION_H
#define T74_VERSION_H

#define TUBE74_VERSION "1.0"

#endif
