#!/bin/sh
# tools/bench.sh — the measured figures of tube74 (make bench). Figures, not pass/fail.
#
#  1. every shipped scene: host time per frame (median of RUNS runs), the 1974 estimate
#     hitac10_seconds, words of core used and whether the scene fits 16 kW;
#  2. accounting overhead: the same program built with -DT74_NO_COST (no counting) as the
#     peer, compared in host instructions (callgrind): overhead = counted / uncounted - 1;
#  3. growth from 10 to 10,000 faces (tools/mkgrowth.py), with the OSMesa z-buffer
#     (tests/ref, llvmpipe) drawing the same scene as the peer where it is built;
#  4. what accuracy costs: `tube74 bench accuracy` (anti-aliasing, papers 000/001), its
#     tables, plots and panels in build/bench/accuracy (ACC_RUNS runs a frame, default 5).
#  4a. every effect alone and composed (tools/bench_effects.sh per frame on the host,
#     tools/figures.sh effects in 1974 time), on fig5, sphere, street and fig6-building.
#  4b. exact against 1974 arithmetic: `tube74 bench arith` (dots that differ, hitac10_seconds
#     and core words for both) in build/bench/arith (arith.md, arith.png).
#  5. paper 004's Table 1 scenes against flat shading (`tools/bench.sh smooth`: only this).
#  6. speed against a warm OSMesa (llvmpipe on one thread, softpipe) and whole processes:
#     `tube74 bench speed --quick` into build/bench/speed (SPEED_FULL=1: to 100,000 box faces
#     and 2,560 interpenetrating triangles, which takes many minutes).
# Results go to stdout and build/bench/bench.md (+ growth.png when gnuplot is there).
set -eu
B=build/bench
RUNS=${RUNS:-15}
mkdir -p "$B"
make -s tube74 >/dev/null
make -s BUILD=build/nocost PROG=build/nocost/tube74 \
     CPPFLAGS="-D_POSIX_C_SOURCE=200809L -I. -DT74_NO_COST" build/nocost/tube74 >/dev/null
PEER=""
if make -s build/bench/refbench >/dev/null 2>&1; then PEER=build/bench/refbench; fi

field() { sed -n "s/.*\"$2\": \([0-9.eE+-]*\).*/\1/p" "$1" | head -n 1; }
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

# host seconds of RUNS renders (median), from the program's own host_seconds
host_median() { # BIN SCENE EXTRA...
  bin=$1; scene=$2; shift 2
  i=0
  while [ $i -lt "$RUNS" ]; do
    "$bin" render "$scene" --stats "$B/run.json" "$@" >/dev/null 2>&1 || { echo "nan"; return; }
    field "$B/run.json" host_seconds
    i=$((i + 1))
  done | median
}

# Paper 004's Table 1 (tools/mksmooth.py scenes): each row against flat shading of the
# same scene (the scene's own cell, no other effect), host and 1974 time.
# `tools/bench.sh smooth` runs this section alone (to build/bench/smooth.md).
smooth_bench() {
  {
    echo "## Smooth shading, paper 004 Table 1 (median of $RUNS runs; host = this machine)"
    echo
    echo "| row | effects | host ms flat | host ms | host x flat | host Minstr flat | host Minstr | host Minstr added | hitac10 s flat | hitac10 s | 1974 x flat | points smoothed | points cut | core words used |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
  }
  for s in scenes/t1-?.s74 scenes/sphere.s74; do
    eff=$(sed -n 's/^effects //p' "$s")
    ./tube74 render "$s" --effects halftone=3x3 --stats "$B/flat.json" >/dev/null
    ./tube74 render "$s" --stats "$B/row.json" >/dev/null
    hf=$(host_median ./tube74 "$s" --effects halftone=3x3)
    hr=$(host_median ./tube74 "$s")
    cut=$(field "$B/row.json" contour_points_cut); cut=${cut:-0}
    # host instructions of the whole run (callgrind: exact and repeatable under load)
    irf=nan; irr=nan
    if command -v valgrind >/dev/null 2>&1; then
      irf=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null ./tube74 render "$s" \
            --effects halftone=3x3 2>&1 | sed -n 's/.*Collected : *\([0-9]*\).*/\1/p')
      irr=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null ./tube74 render "$s" 2>&1 |
            sed -n 's/.*Collected : *\([0-9]*\).*/\1/p')
    fi
    awk -v s="$(basename "$s" .s74)" -v e="$eff" -v hf="$hf" -v hr="$hr" -v irf="$irf" -v irr="$irr" \
        -v tf="$(field "$B/flat.json" hitac10_seconds)" -v tr="$(field "$B/row.json" hitac10_seconds)" \
        -v n="$(field "$B/row.json" smooth_points)" -v c="$cut" -v u="$(field "$B/row.json" core_words_used)" \
        'BEGIN { printf "| %s | `%s` | %.2f | %.2f | %.2f | %s | %s | %s | %.2f | %.2f | %.2f | %d | %d | %d |\n",
                 s, e, hf*1000, hr*1000, hr/hf,
                 (irf == "nan" ? "-" : sprintf("%.2f", irf/1e6)), (irr == "nan" ? "-" : sprintf("%.2f", irr/1e6)),
                 (irf == "nan" ? "-" : sprintf("%+.2f", (irr-irf)/1e6)), tf, tr, tr/tf, n, c, u }'
  done
}
if [ "${1:-}" = smooth ]; then
  smooth_bench | tee "$B/smooth.md"
  exit 0
fi

out="$B/bench.md"
{
  echo "## Shipped scenes (median of $RUNS runs; host = this machine, cell from the scene)"
  echo
  echo "| scene | faces | pieces | host ms/frame | OSMesa ms | tube74 / OSMesa | hitac10_seconds | total_1974_seconds | core words used | fits 16 kW |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"
} >"$out"
for s in scenes/*.s74; do
  ./tube74 render "$s" --core 1048576 --stats "$B/one.json" >/dev/null
  h=$(host_median ./tube74 "$s" --core 1048576)
  used=$(field "$B/one.json" core_words_used)
  fits=yes; [ "$used" -gt 16384 ] && fits=no
  if [ -n "$PEER" ]; then
    r=$(i=0; while [ $i -lt "$RUNS" ]; do "$PEER" "$s"; i=$((i + 1)); done | median)
  else
    r=nan
  fi
  awk -v s="$(basename "$s")" -v f="$(field "$B/one.json" faces_in)" \
      -v p="$(field "$B/one.json" faces_after_split)" -v h="$h" -v r="$r" \
      -v t="$(field "$B/one.json" hitac10_seconds)" -v tt="$(field "$B/one.json" total_1974_seconds)" \
      -v u="$used" -v fit="$fits" \
      'BEGIN { printf "| %s | %d | %d | %.2f | %s | %s | %.1f | %.1f | %d | %s |\n", s, f, p, h*1000,
               (r == "nan" ? "-" : sprintf("%.2f", r*1000)), (r == "nan" ? "-" : sprintf("%.2f", h/r)),
               t, tt, u, fit }' >>"$out"
done

{
  echo
  echo "## Growth (tools/mkgrowth.py boxes; --core 2^28 words; cell 4)"
  echo
  echo "| faces | pieces | pairs computed | pairs possible | host ms | host / host(10 faces) | OSMesa ms | tube74 / OSMesa | hitac10_seconds | core words used |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
} >>"$out"
: >"$B/growth.dat"
base=""
for n in 10 30 100 300 1000 3000 10000; do
  g="$B/g$n.s74"
  python3 tools/mkgrowth.py "$n" >"$g"
  ./tube74 render "$g" --core 268435456 --stats "$B/one.json" >/dev/null
  h=$(host_median ./tube74 "$g" --core 268435456)
  [ -z "$base" ] && base=$h
  if [ -n "$PEER" ]; then
    r=$(i=0; while [ $i -lt "$RUNS" ]; do "$PEER" "$g"; i=$((i + 1)); done | median)
  else
    r=nan
  fi
  echo "$n $h $r" >>"$B/growth.dat"
  awk -v n="$n" -v p="$(field "$B/one.json" faces_after_split)" \
      -v pc="$(field "$B/one.json" priority_pairs_computed)" \
      -v pp="$(field "$B/one.json" priority_pairs_possible)" -v h="$h" -v b="$base" -v r="$r" \
      -v t="$(field "$B/one.json" hitac10_seconds)" -v u="$(field "$B/one.json" core_words_used)" \
      'BEGIN { printf "| %d | %d | %d | %d | %.2f | %.1f | %s | %s | %.1f | %d |\n", n, p, pc, pp, h*1000, h/b,
               (r == "nan" ? "-" : sprintf("%.2f", r*1000)), (r == "nan" ? "-" : sprintf("%.2f", h/r)), t, u }' >>"$out"
done

echo >>"$out"
smooth_bench >>"$out"

# Counting the 1974 operations costs the host: measured in instructions (callgrind counts
# them exactly and repeatably, where millisecond timings scatter by tens of percent),
# the counting build against the -DT74_NO_COST build on the same scene.
if command -v valgrind >/dev/null 2>&1; then
  {
    echo
    echo "## Cost of counting the 1974 operations (host instructions, callgrind)"
    echo
    echo "| scene | instructions counted | without counting | overhead |"
    echo "|---|---:|---:|---:|"
  } >>"$out"
  for g in scenes/street.s74 "$B/g1000.s74" "$B/g10000.s74"; do
    ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$1" render "$g" --core 268435456 2>&1 |
           sed -n 's/.*Collected : *\([0-9]*\).*/\1/p'; }
    a=$(ir ./tube74); z=$(ir build/nocost/tube74)
    awk -v g="$(basename "$g")" -v a="$a" -v z="$z" \
        'BEGIN { printf "| %s | %d | %d | %+.1f%% |\n", g, a, z, (a/z-1)*100 }' >>"$out"
  done
fi

# The look layer's work is bounded by the picture (display/look.c "wide spots"): the
# slowest fade (fade:0.001: every spot spread far) at the largest scale, beside the
# plain glow look at the same scale as the peer. Wall seconds of whole runs (median;
# under load only the ratios to the glow row, measured in the same run, are fair).
{
  echo
  echo "## The tube's look at --scale 8 (street, median of 5 whole runs, wall seconds)"
  echo
  echo "| look | seconds | / glow |"
  echo "|---|---:|---:|"
} >>"$out"
wall() { # LOOK...
  i=0
  while [ $i -lt 5 ]; do
    t0=$(date +%s.%N)
    ./tube74 render scenes/street.s74 --scale 8 -o "$B/look.png" "$@" >/dev/null 2>&1
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN { print b - a }'
    i=$((i + 1))
  done | median
}
g=$(wall --look glow)
for l in glow fade:0.001 fade:1 fade:100 "fade:10 --look-param fade_spread_mm=10"; do
  # shellcheck disable=SC2086
  w=$(wall --look $l)
  awk -v l="$l" -v w="$w" -v g="$g" 'BEGIN { printf "| %s | %.2f | %.2f |\n", l, w, w/g }' >>"$out"
done

if command -v gnuplot >/dev/null 2>&1; then
  gnuplot <<EOF 2>/dev/null || true
set terminal pngcairo size 640,400
set output "$B/growth.png"
set logscale xy
set xlabel "faces"
set ylabel "host seconds per frame"
set key left top
plot "$B/growth.dat" using 1:2 with linespoints title "tube74", \
     "$B/growth.dat" using 1:3 with linespoints title "OSMesa z-buffer (peer)"
EOF
fi
# enhanced edges (paper 002): edges=on against the plain render of each edges scene
sh tools/bench_edges.sh "$B/bench_edges.md" >/dev/null
{ echo; cat "$B/bench_edges.md"; } >>"$out"
cat "$out"
echo
./tube74 bench accuracy --out "$B/accuracy" --runs "${ACC_RUNS:-5}"
echo
# every effect alone and composed: per frame on this host, and in 1974 time
echo "## What each effect costs a frame (host: tools/bench_effects.sh; 1974: tools/figures.sh effects)"
echo
sh tools/bench_effects.sh "$B/effects"
echo
sh tools/figures.sh effects
echo
./tube74 bench arith --out "$B/arith" 2>/dev/null && cat "$B/arith/arith.md"
if [ "${SPEED_FULL:-0}" = 1 ]; then ./tube74 bench speed --out "$B/speed"
else ./tube74 bench speed --quick --out "$B/speed"; fi
