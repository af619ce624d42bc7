#!/bin/sh
# ab74_pairs.sh — tools/ab_pairs.sh for the 1974 engine's whole process, as `tube74 bench
# speed` times it: `render SCENE --engine 1974 --core 268435456 -o` (an .obj or .off import
# with --turn 0,0), OLD then NEW back to back, the figure the median of the pairs' NEW/OLD
# ratios, beside the least and the median times of each (issue 19, round 41).
# Usage: tools/ab74_pairs.sh OLD_BINARY NEW_BINARY [PAIRS [SCENE...]]
#   PAIRS 15; a SCENE is a path, or a name under scenes/ (SCENE.s74)
# Prints a line a scene; exit 1 when a run fails.
set -u
old=$1; new=$2; pairs=${3:-15}
[ $# -ge 3 ] && shift 3 || shift $#
scenes=${*:-"/tmp/bs-base41/tris640.s74 /tmp/bs-base41/tris1280.s74"}
out=$(mktemp -d) || exit 1
trap 'rm -rf "$out"' EXIT
now() { date +%s%N; }
for s in $scenes; do
  f=$s
  [ -f "$f" ] || f=scenes/$s.s74
  case "$f" in *.obj|*.off) turn="--turn 0,0" ;; *) turn="" ;; esac
  name=$(basename "$f")
  i=0
  while [ "$i" -lt "$pairs" ]; do
    for b in old new; do
      eval bin=\$$b
      t0=$(now)
      # shellcheck disable=SC2086
      "$bin" render "$f" --engine 1974 --core 268435456 -o "$out/$b.png" $turn >/dev/null 2>&1 ||
        { echo "ab74_pairs: $bin failed on $f" >&2; exit 1; }
      t1=$(now)
      echo "$name $b $(( (t1 - t0) / 1000 ))" >>"$out/times"
    done
    i=$((i + 1))
  done
done
awk '
  function median(a, m,   i, j, x) {
    for (i = 2; i <= m; i++)                  # insertion sort
      for (j = i; j > 1 && a[j - 1] > a[j]; j--) { x = a[j]; a[j] = a[j - 1]; a[j - 1] = x }
    return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
  }
  { t[$1, $2, ++n[$1, $2]] = $3; if (!($1 in seen)) { seen[$1] = 1; order[++ns] = $1 } }
  END {
    for (k = 1; k <= ns; k++) {
      s = order[k]; m = n[s, "old"]; lo = hi = 0
      for (i = 1; i <= m; i++) {
        r[i] = t[s, "new", i] / t[s, "old", i]; a[i] = t[s, "old", i]; b[i] = t[s, "new", i]
        if (!lo || a[i] < lo) lo = a[i]
        if (!hi || b[i] < hi) hi = b[i]
      }
      printf "%-18s least %8.1f -> %8.1f ms  median %8.1f -> %8.1f ms  median pair ratio %.3f\n",
             s, lo / 1000, hi / 1000, median(a, m) / 1000, median(b, m) / 1000, median(r, m)
    }
  }' "$out/times"
