#!/bin/sh
# scene_dumps.sh — the byte-identity check used when the Segment Generator changes: write
# `--dump ids`, `--dump points` and `--dump tables` of every scene in scenes/ with one
# tube74 binary, so two binaries (before and after a change) can be compared.
#   tools/scene_dumps.sh BIN OUTDIR             write OUTDIR/<scene>.{ids,points,tables}
#   tools/scene_dumps.sh BIN_OLD BIN_NEW        write both under a temporary directory and
#                                              diff them (exit 1 and the diff if any differ)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
dumps() {
  mkdir -p "$2"
  for s in "$here"/scenes/*.s74; do
    n=$(basename "$s" .s74)
    rc=0
    "$1" render "$s" --dump ids="$2/$n.ids" --dump points="$2/$n.points" \
      --dump tables="$2/$n.tables" >"$2/$n.log" 2>&1 || rc=$?
    echo "$n $rc" >>"$2/status"
  done
}
if [ -x "$2" ] && [ ! -d "$2" ]; then
  t=$(mktemp -d)
  dumps "$1" "$t/old"
  dumps "$2" "$t/new"
  if diff -r "$t/old" "$t/new"; then echo "identical: $(wc -l <"$t/old/status") scenes"; rm -rf "$t"; exit 0; fi
  echo "differ (kept in $t)"; exit 1
fi
dumps "$1" "$2"
