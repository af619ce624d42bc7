#!/bin/sh
# tools/install.sh DESTDIR PREFIX PROG MANPAGE — what `make install` does: the program to
# DESTDIR/PREFIX/bin/tube74 (mode 755) and the man page to DESTDIR/PREFIX/share/man/man1/
# (mode 644), creating the folders. DESTDIR may be empty (staged installs set it).
set -eu
destdir=$1 prefix=$2 prog=$3 man=$4
case "$prefix" in /*) ;; *) echo "tools/install.sh: PREFIX must be an absolute path: $prefix" >&2; exit 2;; esac
[ -x "$prog" ] || { echo "tools/install.sh: no program $prog (run make first)" >&2; exit 2; }
[ -f "$man" ] || { echo "tools/install.sh: no man page $man" >&2; exit 2; }
bindir="$destdir$prefix/bin" mandir="$destdir$prefix/share/man/man1"
install -d -m 755 "$bindir" "$mandir"
install -m 755 "$prog" "$bindir/tube74"
install -m 644 "$man" "$mandir/tube74.1"
echo "installed $bindir/tube74 and $mandir/tube74.1"
