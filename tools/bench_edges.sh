#!/bin/sh
# tools/bench_edges.sh — what enhanced edges (paper 002, edges=on) cost: each
# scenes/edges-*.s74 rendered plain and with edges=on, host time (median of RUNS runs of
# the program's own host_seconds; also host instructions by callgrind when valgrind is
# there, which do not scatter) and the 1974 estimate hitac10_seconds. A benchmark, not a
# test: figures, not pass/fail. Paper 002's Table 1 (SPARCstation 20, z-buffer): 8 -> 21 s,
# 11 -> 28 s, 9 -> 22 s (about 2.5 times); tube74's goal is under 1.3 times on the host.
# Called by tools/bench.sh; alone: sh tools/bench_edges.sh [OUT.md]
set -eu
B=build/bench
RUNS=${RUNS:-15}
out=${1:-$B/bench_edges.md}
mkdir -p "$B"
make -s tube74 >/dev/null

field() { sed -n "s/.*\"$2\": \([0-9.eE+-]*\).*/\1/p" "$1" | head -n 1; }
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
host_median() { # SCENE EFFECTS
  i=0
  while [ $i -lt "$RUNS" ]; do
    ./tube74 render "$1" --core 1048576 --effects "$2" --stats "$B/e.json" >/dev/null 2>&1 || { echo nan; return; }
    field "$B/e.json" host_seconds
    i=$((i + 1))
  done | median
}
ir() { # SCENE EFFECTS: host instructions of one render
  valgrind --tool=callgrind --callgrind-out-file=/dev/null ./tube74 render "$1" --core 1048576 \
           --effects "$2" 2>&1 | sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'
}
{
  echo "## Enhanced edges: edges=on against the plain render (median of $RUNS runs; --core 2^20)"
  echo
  echo "| scene | edges | host ms plain | host ms edges | host ratio | instructions ratio | hitac10 s plain | hitac10 s edges | 1974 ratio |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
} >"$out"
for s in scenes/edges-*.s74; do
  base=$(sed -n 's/^effects //p' "$s" | sed 's/ *edges=on//')
  [ -n "$base" ] || base="halftone=4x4"
  plain="$base"; edges="$base edges=on"
  ./tube74 render "$s" --core 1048576 --effects "$plain" --stats "$B/p.json" >/dev/null
  ./tube74 render "$s" --core 1048576 --effects "$edges" --stats "$B/q.json" >/dev/null
  hp=$(host_median "$s" "$plain"); he=$(host_median "$s" "$edges")
  if command -v valgrind >/dev/null 2>&1; then
    ip=$(ir "$s" "$plain"); ie=$(ir "$s" "$edges"); iratio=$(awk -v a="$ie" -v b="$ip" 'BEGIN { printf "%.2f", a / b }')
  else
    iratio="-"
  fi
  n=$(( $(field "$B/q.json" edges_outline) + $(field "$B/q.json" edges_inner) + $(field "$B/q.json" edges_intersection) ))
  awk -v s="$(basename "$s")" -v n="$n" -v hp="$hp" -v he="$he" -v ir="$iratio" \
      -v tp="$(field "$B/p.json" hitac10_seconds)" -v te="$(field "$B/q.json" hitac10_seconds)" \
      'BEGIN { printf "| %s | %d | %.2f | %.2f | %.2f | %s | %.2f | %.2f | %.2f |\n", s, n, hp*1000, he*1000,
               he/hp, ir, tp, te, te/tp }' >>"$out"
done
cat "$out"
