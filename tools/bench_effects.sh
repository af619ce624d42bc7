#!/bin/sh
# tools/bench_effects.sh DIR — what each effect costs a frame on this host, alone and
# composed, as a Markdown table on stdout (run by make bench and make docs).
# For each effect row and scene, `render --frames FRAMES` (default 20) reports
# frame_seconds, the median frame from the Mapper to the last dot stored (reading the
# scene excluded); RUNS (default 5) runs with the rows and scenes taking turns, so load on
# a shared machine falls on all of them; the figure is the median run, in ms and as a ratio
# to the plain render (aa=none) measured in the same runs. The 1974 side of the same rows
# is `sh tools/figures.sh effects` (deterministic).
set -eu
B=${1:-build/bench/effects}
RUNS=${RUNS:-5}
FRAMES=${FRAMES:-20}
mkdir -p "$B"
scenes="fig5 sphere street fig6-building"
effects="aa=none|edges=on|smooth=phong|smooth=phong contour=1.0|shadows=on|aa=multiscan filter=box n=3|aa=area depth=2|aa=exact|smooth=phong contour=1.0 edges=on shadows=on|smooth=phong contour=1.0 edges=on shadows=on aa=multiscan n=3"
: >"$B/frames.txt"
r=0
while [ $r -lt "$RUNS" ]; do
  echo "$effects" | tr '|' '\n' | while IFS= read -r e; do
    for s in $scenes; do
      rm -f "$B/run.json"
      ./tube74 render "scenes/$s.s74" --core 268435456 --effects "$e" --frames "$FRAMES" \
        --stats "$B/run.json" >/dev/null 2>&1 || { echo "bench_effects: $s [$e] failed" >&2; exit 1; }
      printf '%s\t%s\t%s\n' "$e" "$s" "$(jq -r .frame_seconds "$B/run.json")" >>"$B/frames.txt"
    done
  done
  r=$((r + 1))
done
printf '| effects |'; for s in $scenes; do printf ' %s ms (x plain) |' "$s"; done; echo
printf '|---|'; for s in $scenes; do printf -- '---:|'; done; echo
echo "$effects" | tr '|' '\n' | while IFS= read -r e; do
  label=$e; [ "$e" = aa=none ] && label=none
  printf '| `%s` |' "$label"
  for s in $scenes; do
    awk -F '\t' -v e="$e" -v s="$s" '
      function med(v, k,   i, j, t) {
        for (i = 2; i <= k; i++) for (j = i; j > 1 && v[j-1] > v[j]; j--) { t = v[j]; v[j] = v[j-1]; v[j-1] = t }
        return v[int((k + 1) / 2)] }
      $2 == s && $1 == e { a[++n] = $3 }
      $2 == s && $1 == "aa=none" { b[++m] = $3 }
      END { t = med(a, n); q = med(b, m); printf " %.3f (%.2f) |", 1000 * t, t / q }' "$B/frames.txt"
  done
  echo
done
