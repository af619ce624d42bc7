#!/bin/sh
# cmp_stats.sh — checks that two tube74 binaries report the same figures.
# Renders every scene in scenes/ and build/bench/g1000.s74, g10000.s74 (tools/mkgrowth.py)
# with each binary and compares the --stats JSON byte for byte, minus host_seconds and
# frame_seconds (host timings). Used for issue 12 (counting overhead): a change to how the
# 1974 operations are counted must leave hitac10_seconds, exact_hitac10_seconds, the
# operations counts and every other field as they were.
# Usage: tools/cmp_stats.sh OLD_BINARY NEW_BINARY [WORKDIR]; exit 0 when all agree.
set -u
old=$1; new=$2; dir=${3:-build/cmp_stats}
mkdir -p build/bench "$dir/old" "$dir/new"
for n in 1000 10000; do
  [ -f build/bench/g$n.s74 ] || python3 tools/mkgrowth.py $n >build/bench/g$n.s74
done
bad=0; count=0
for g in scenes/*.s74 build/bench/g1000.s74 build/bench/g10000.s74; do
  b=$(basename "$g")
  for side in old new; do
    eval bin=\$$side
    rm -f "$dir/$side/$b.json"
    "$bin" render "$g" --core 268435456 --stats "$dir/$side/$b.json" -o "$dir/$side/$b.png" \
      >/dev/null 2>&1
    sed -E 's/"(host_seconds|frame_seconds)": *[-0-9.eE+]+,? *//g' "$dir/$side/$b.json" \
      >"$dir/$side/$b.cmp" 2>/dev/null || : >"$dir/$side/$b.cmp"
  done
  count=$((count + 1))
  if [ ! -s "$dir/old/$b.cmp" ] || ! cmp -s "$dir/old/$b.cmp" "$dir/new/$b.cmp"; then
    echo "differs (or no stats): $b"; bad=$((bad + 1))
  fi
done
echo "$count scenes, $bad differ"
[ "$bad" -eq 0 ]
