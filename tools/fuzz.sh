#!/bin/sh
# tools/fuzz.sh [SECONDS] — build the libFuzzer target of the Tek stream decoder and run it.
#
# Builds build/fuzz/fuzz_tek from tests/fuzz/fuzz_tek.c and the decoder's sources with
# clang -fsanitize=fuzzer,address,undefined, then fuzzes for SECONDS (default 120) seconds,
# starting from tests/fuzz/corpus_tek/ (the kept corpus). New inputs go to
# build/fuzz/corpus_new/. With MERGE=1 those that reach code the kept corpus does not
# (new edges only: -use_counters=0 keeps the corpus small) are then added to
# tests/fuzz/corpus_tek/; keep it under 200 files and 1 MB. A crash is written to
# build/fuzz/crash-*: fix the decoder, then copy the file into the corpus, which
# tests/test_tek.c replays on every `make test`.
# Needs clang and its libFuzzer runtime (Debian: apt-get install clang libclang-rt-14-dev).
set -eu
secs=${1:-120}
out=build/fuzz
corpus=tests/fuzz/corpus_tek
CLANG=${CLANG:-clang}
mkdir -p "$out/corpus_new" "$corpus"
$CLANG -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -D_POSIX_C_SOURCE=200809L -I. -o "$out/fuzz_tek" \
  tests/fuzz/fuzz_tek.c display/tek.c display/tube.c display/outfile.c emu/status.c
echo "fuzzing for $secs s (corpus: $corpus)"
"$out/fuzz_tek" -max_total_time="$secs" -max_len=4096 -timeout=10 \
  -artifact_prefix="$out/" "$out/corpus_new" "$corpus" 2>&1 | tail -n 3
if [ "${MERGE:-0}" = 1 ]; then
  "$out/fuzz_tek" -merge=1 -use_counters=0 "$corpus" "$out/corpus_new" 2>&1 | tail -n 1
  echo "kept corpus: $(ls "$corpus" | wc -l) files, $(du -sk "$corpus" | cut -f1) KB"
fi
