#!/bin/sh
# ab_pairs.sh — two tube74 binaries timed in turn, for a change smaller than the host's noise.
# Each pair runs OLD then NEW back to back (`render SCENE --engine points --frames N -o`,
# wall time of the whole process), so both see the same phase of a busy host; the figure
# is the median of the pairs' NEW/OLD ratios, beside the ratio of the least times (the two
# agree when the pairs are enough). Used for issue 19's round 39, whose host changed speed
# by up to 1.8x in phases of seconds, when `tube74 bench speed`'s ratios to the peer moved
# by a fifth from run to run.
# AB_ENGINE=1974 times the 1974 engine's whole process instead, as `tube74 bench speed` does
# (`--engine 1974 --core 268435456`, FRAMES 1 unless given; round 41, its 1974 goals).
# Usage: tools/ab_pairs.sh OLD_BINARY NEW_BINARY [PAIRS [FRAMES [SCENE...]]]
#   PAIRS 15, FRAMES 1000, scenes: t1-a t1-e t1-g sphere lprism fig6-room fig6-building street
#   (a SCENE is a name under scenes/ or a path; an .obj or .off is read with --turn 0,0)
# Prints a line a scene: the least times (ms) and both ratios; exit 1 when a run fails.
set -u
engine=${AB_ENGINE:-points}
case "$engine" in
  points) eargs="--engine points"; dframes=1000 ;;
  1974) eargs="--engine 1974 --core 268435456"; dframes=1 ;;
  *) echo "ab_pairs: AB_ENGINE is points or 1974" >&2; exit 2 ;;
esac
old=$1; new=$2; pairs=${3:-15}; frames=${4:-$dframes}
[ $# -ge 4 ] && shift 4 || shift $#
scenes=${*:-"t1-a t1-e t1-g sphere lprism fig6-room fig6-building street"}
out=$(mktemp -d) || exit 1
trap 'rm -rf "$out"' EXIT
now() { date +%s%N; }
for s in $scenes; do
  f=scenes/$s.s74
  [ -f "$f" ] || f=$s
  case "$f" in *.obj|*.off) turn="--turn 0,0" ;; *) turn="" ;; esac
  i=0
  while [ "$i" -lt "$pairs" ]; do
    for b in old new; do
      eval bin=\$$b
      t0=$(now)
      # shellcheck disable=SC2086
      "$bin" render "$f" $eargs --frames "$frames" -o "$out/$b.png" $turn >/dev/null 2>&1 ||
        { echo "ab_pairs: $bin failed on $f" >&2; exit 1; }
      t1=$(now)
      echo "$s $b $(( (t1 - t0) / 1000 ))" >>"$out/times"
    done
    i=$((i + 1))
  done
done
awk '
  { t[$1, $2, ++n[$1, $2]] = $3; if (!($1 in seen)) { seen[$1] = 1; order[++ns] = $1 } }
  END {
    for (k = 1; k <= ns; k++) {
      s = order[k]; m = n[s, "old"]; lo = hi = 0
      for (i = 1; i <= m; i++) {
        r[i] = t[s, "new", i] / t[s, "old", i]
        if (!lo || t[s, "old", i] < lo) lo = t[s, "old", i]
        if (!hi || t[s, "new", i] < hi) hi = t[s, "new", i]
      }
      for (i = 2; i <= m; i++)                  # insertion sort of the ratios
        for (j = i; j > 1 && r[j - 1] > r[j]; j--) { x = r[j]; r[j] = r[j - 1]; r[j - 1] = x }
      med = m % 2 ? r[(m + 1) / 2] : (r[m / 2] + r[m / 2 + 1]) / 2
      printf "%-16s least %8.1f -> %8.1f ms  ratio %.3f  median pair ratio %.3f\n",
             s, lo / 1000, hi / 1000, hi / lo, med
    }
  }' "$out/times"
