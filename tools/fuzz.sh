#!/bin/sh
# tools/fuzz.sh [SECONDS] [TARGET...] — build the libFuzzer targets and run each in turn.
#
# Targets (tests/fuzz/fuzz_NAME.c, corpus tests/fuzz/corpus_NAME/):
#   tek  the Tektronix stream decoder (display/tek.c)
#   s74  the .s74 scene reader, with a full render, reversed faces and rings compared
#   obj  the .obj import, the same, and every `f` line's references reversed compared
#   off  the .off import, the same
#   pic  the PGM/PNG background loader (patterns/picture.c: pic_load)
# With no TARGET, all of them, one after the other, each in one process (the machine is
# shared: no -jobs).
#
# Builds build/fuzz/fuzz_NAME with clang -fsanitize=fuzzer,address,undefined (the library's
# sources compiled with the same sanitizers into build/fuzz/obj/), then fuzzes each target
# for SECONDS (default 120) seconds, starting from its kept corpus. New inputs go to
# build/fuzz/new_NAME/. With MERGE=1 those that reach code the kept corpus does not (new
# edges only: -use_counters=0 keeps it small) are added to the kept corpus; keep each
# under 200 files and 1 MB. A crash or a broken promise (abort) is written to
# build/fuzz/NAME-crash-* (with KEEP_GOING=1 fuzzing goes on after a find): fix the code,
# then copy the file into the corpus, which `make test` replays (tests/test_tek.c for tek,
# tests/test_import.c for the others). The exit status is 1 when anything was found.
# Needs clang and its libFuzzer runtime (Debian: apt-get install clang libclang-rt-14-dev).
set -eu
secs=${1:-120}
[ $# -gt 0 ] && shift
targets=${*:-tek s74 obj off pic}
out=build/fuzz
CLANG=${CLANG:-clang}
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
FLAGS="-std=c11 -g -O1 -D_POSIX_C_SOURCE=200809L -I. $(pkg-config --cflags libpng)"
mkdir -p "$out/obj"

# the library, instrumented once for all scene and picture targets
libobjs=""
build_lib() {
  for src in emu/*.c render/*.c effects/*.c patterns/*.c tests/ref/memrender.c; do
    o="$out/obj/$(echo "$src" | tr / _ | sed 's/\.c$/.o/')"
    if [ ! -f "$o" ] || [ "$src" -nt "$o" ] || [ -n "$(find render emu patterns tests/ref \
         -name '*.h' -newer "$o" 2>/dev/null | head -n 1)" ]; then
      $CLANG $FLAGS $SAN -fsanitize=fuzzer-no-link -c "$src" -o "$o"
    fi
    libobjs="$libobjs $o"
  done
}

for t in $targets; do
  corpus=tests/fuzz/corpus_$t
  mkdir -p "$out/new_$t" "$corpus"
  case $t in
    tek)
      $CLANG $FLAGS -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
        -o "$out/fuzz_tek" tests/fuzz/fuzz_tek.c display/tek.c display/tube.c \
        display/outfile.c emu/status.c
      maxlen=4096 ;;
    s74|obj|off|pic)
      [ -n "$libobjs" ] || build_lib
      # shellcheck disable=SC2086
      $CLANG $FLAGS -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
        -o "$out/fuzz_$t" "tests/fuzz/fuzz_$t.c" $libobjs $(pkg-config --libs libpng) -lm
      maxlen=2048 ;;
    *) echo "tools/fuzz.sh: unknown target $t (tek s74 obj off pic)" >&2; exit 2 ;;
  esac
  echo "fuzz_$t: fuzzing for $secs s (corpus: $corpus)"
  # KEEP_GOING=1: one worker process (-fork=1) that saves a find and goes on (slower)
  keep=""
  [ "${KEEP_GOING:-0}" = 1 ] && keep="-fork=1 -ignore_crashes=1"
  # shellcheck disable=SC2086
  "$out/fuzz_$t" -max_total_time="$secs" -max_len=$maxlen -timeout=10 -rss_limit_mb=2048 \
    $keep -artifact_prefix="$out/$t-" \
    "$out/new_$t" "$corpus" 2>&1 | grep -v 'warning: face' | grep -E '^#|^==|^SUMMARY|Done|crash|timeout|leak|oom|artifact' | tail -n 4 || true
  for a in "$out/$t-"crash-* "$out/$t-"timeout-* "$out/$t-"leak-* "$out/$t-"oom-*; do
    [ -e "$a" ] || continue
    echo "fuzz_$t: FOUND $a"
    found=1
  done
  if [ "${MERGE:-0}" = 1 ]; then
    "$out/fuzz_$t" -merge=1 -use_counters=0 -max_len=$maxlen "$corpus" "$out/new_$t" 2>&1 | tail -n 1
    echo "kept corpus: $(ls "$corpus" | wc -l) files, $(du -sk "$corpus" | cut -f1) KB"
  fi
done
[ "${found:-0}" = 0 ]
