#!/bin/sh
# tools/figures.sh — the deterministic figures of the README and docs/, as Markdown tables.
#
#   sh tools/figures.sh NAME [TUBE74]     one table to stdout
#   sh tools/figures.sh --list            the names
#
# Every figure here comes from the tree's own program (TUBE74, default ./tube74) and does
# not depend on the host: the 1974 seconds (hitac10_seconds, total_1974_seconds: the machine
# model, docs/machine.md), words of core, pieces, pairs and dots lit. `make docs`
# (tools/docs.sh) writes each table between `<!-- docs:NAME begin -->` and
# `<!-- docs:NAME end -->` in README.md and docs/*.md; tests/test_docs.c runs this script for
# every such block it finds and fails when the text there is not what the tree computes now.
# Host times are not here: they are measured (tools/docs.sh), with date and machine.
#
#   scenes   every shipped .s74 at its own settings (16 kW core, as a user runs it)
#   growth   boxes of 10 .. 10,000 faces (tools/mkgrowth.py), a core of 2^28 words, cell 4
#   effects  each effect and a composition of them on four scenes: 1974 seconds and core
#   edges    the paper-002 scenes plain and with edges=on
set -eu
name=${1:-}
bin=${2:-./tube74}
tmp=${TMPDIR:-/tmp}/t74figures.$$
mkdir -p "$tmp"
trap 'rm -rf "$tmp"' EXIT INT TERM

# stats SCENE OPTIONS...: the --stats JSON of one render (no picture kept) into $tmp/s.json
stats() {
  _scene=$1; shift
  rm -f "$tmp/s.json"
  if ! "$bin" render "$_scene" --stats "$tmp/s.json" -o "$tmp/s.png" "$@" >/dev/null 2>"$tmp/err"; then
    echo "tools/figures.sh: $bin render $_scene $* failed:" >&2
    cat "$tmp/err" >&2
    exit 1
  fi
}
# f KEY: one field of the last stats, printed as jq prints it
f() { jq -r ".$1" "$tmp/s.json"; }
# s2 KEY: a number of seconds with 2 decimals
s2() { jq -r ".$1" "$tmp/s.json" | awk '{ printf "%.2f", $1 }'; }
yesno() { [ "$1" = true ] && echo yes || echo no; }

case $name in
--list)
  echo "scenes growth effects edges" ;;
scenes)
  echo "| scene | faces | pieces | dots lit | hitac10_seconds | total_1974_seconds | core words used | fits 16 kW |"
  echo "|---|---:|---:|---:|---:|---:|---:|---|"
  for s in scenes/*.s74; do
    stats "$s" --core 1048576
    printf '| %s | %s | %s | %s | %s | %s | %s | %s |\n' "$(basename "$s")" "$(f faces_in)" \
      "$(f faces_after_split)" "$(f points_lit)" "$(s2 hitac10_seconds)" \
      "$(s2 total_1974_seconds)" "$(f core_words_used)" "$(yesno "$(f fits_16k)")"
  done ;;
growth)
  echo "| faces | pieces | pairs computed | pairs possible | hitac10_seconds | core words used |"
  echo "|---:|---:|---:|---:|---:|---:|"
  for n in 10 30 100 300 1000 3000 10000; do
    python3 tools/mkgrowth.py "$n" >"$tmp/g.s74"
    stats "$tmp/g.s74" --core 268435456 --cell 4
    printf '| %s | %s | %s | %s | %s | %s |\n' "$(f faces_in)" "$(f faces_after_split)" \
      "$(f priority_pairs_computed)" "$(f priority_pairs_possible)" "$(s2 hitac10_seconds)" \
      "$(f core_words_used)"
  done ;;
effects)
  # rows (tools/effects_rows.sh): each effect alone, then composed; columns: the 1974
  # seconds (x the plain render, the first row) and the most core any of the scenes used
  # (a core of 2^28 words, so that every combination is drawn; "fits" says whether that
  # most is within 16 kW)
  . tools/effects_rows.sh
  printf '| effects |'; for s in $FX_SCENES; do printf ' %s 1974 s (x plain) |' "$s"; done
  echo ' most core words | fits 16 kW |'
  printf '|---|'; for s in $FX_SCENES; do printf -- '---:|'; done; echo '---:|---|'
  while IFS= read -r e; do
    label=$e; [ "$e" = aa=none ] && label=none
    printf '| `%s` |' "$label"
    most=0
    for s in $FX_SCENES; do
      stats "scenes/$s.s74" --core 268435456 --effects "$e"
      t=$(f hitac10_seconds); w=$(f core_words_used)
      [ "$e" = aa=none ] && echo "$t" >"$tmp/plain-$s"
      [ "$w" -gt "$most" ] && most=$w
      awk -v t="$t" -v p="$(cat "$tmp/plain-$s")" 'BEGIN { printf " %.3f (%.2f) |", t, t / p }'
    done
    printf ' %s | %s |\n' "$most" "$([ "$most" -le 16384 ] && echo yes || echo no)"
  done <<EOF
$FX_ROWS
EOF
  ;;
edges)
  echo "| scene | edges drawn | hitac10 s plain | hitac10 s edges | 1974 ratio | core words edges | fits 16 kW |"
  echo "|---|---:|---:|---:|---:|---:|---|"
  for s in scenes/edges-*.s74; do
    eff=$(sed -n 's/^effects //p' "$s" | sed 's/edges=on//')
    stats "$s" --core 268435456 --effects "aa=none $eff"
    plain=$(f hitac10_seconds)
    stats "$s" --core 268435456
    awk -v n="$(basename "$s")" -v d="$(jq -r '.edges_outline + .edges_inner + .edges_intersection' "$tmp/s.json")" -v p="$plain" \
        -v t="$(f hitac10_seconds)" -v w="$(f core_words_used)" \
        'BEGIN { printf "| %s | %s | %.2f | %.2f | %.2f | %s | %s |\n", n, d, p, t, t / p, w,
                 (w <= 16384 ? "yes" : "no") }'
  done ;;
*)
  echo "usage: sh tools/figures.sh scenes|growth|effects|edges [TUBE74] (or --list)" >&2
  exit 2 ;;
esac
