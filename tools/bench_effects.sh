#!/bin/sh
# tools/bench_effects.sh DIR — what each effect costs a frame on this host, alone and
# composed, as a Markdown table on stdout (run by make bench and make docs).
# For each row and scene of tools/effects_rows.sh (the same rows as `sh tools/figures.sh
# effects`, the 1974 side), `render --frames FRAMES` (default 20) reports frame_seconds,
# the median frame from the Mapper to the last dot stored (reading the scene excluded);
# RUNS (default 5) runs with the rows and scenes taking turns, so load on a shared machine
# falls on all of them; the figure is the median run, in ms and as a ratio to the plain
# render (aa=none) measured in the same runs.
set -eu
B=${1:-build/bench/effects}
RUNS=${RUNS:-5}
FRAMES=${FRAMES:-20}
mkdir -p "$B"
. tools/effects_rows.sh
: >"$B/frames.txt"
r=0
while [ $r -lt "$RUNS" ]; do
  while IFS= read -r e; do
    for s in $FX_SCENES; do
      rm -f "$B/run.json"
      ./tube74 render "scenes/$s.s74" --core 268435456 --effects "$e" --frames "$FRAMES" \
        --stats "$B/run.json" >/dev/null 2>&1 || { echo "bench_effects: $s [$e] failed" >&2; exit 1; }
      printf '%s\t%s\t%s\n' "$e" "$s" "$(jq -r .frame_seconds "$B/run.json")" >>"$B/frames.txt"
    done
  done <<ROWS
$FX_ROWS
ROWS
  r=$((r + 1))
done
# median EFFECTS SCENE: the median frame_seconds of that cell
median() {
  awk -F '\t' -v e="$1" -v s="$2" '$1 == e && $2 == s { print $3 }' "$B/frames.txt" | sort -g |
    awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'
}
printf '| effects |'; for s in $FX_SCENES; do printf ' %s ms (x plain) |' "$s"; done; echo
printf '|---|'; for s in $FX_SCENES; do printf -- '---:|'; done; echo
while IFS= read -r e; do
  label=$e; [ "$e" = aa=none ] && label=none
  printf '| `%s` |' "$label"
  for s in $FX_SCENES; do
    awk -v t="$(median "$e" "$s")" -v p="$(median aa=none "$s")" \
      'BEGIN { printf " %.3f (%.2f) |", 1000 * t, t / p }'
  done
  echo
done <<ROWS
$FX_ROWS
ROWS
