#!/bin/sh
# teach_shots.sh [BIN] — the README's two pictures of the teaching page, made afresh from
# the page `tube74 teach` writes now: docs/teach-cut.png (fig6, the first cut's state (b):
# the lower pieces cut off, the Fig. 6 tables, the legend) and docs/teach-matrix.png (the
# street, the Priority Matrix filling at grid row 38), each a headless Chromium screenshot
# 1400 pixels wide. BIN: the tube74 to use (default ./tube74).
set -eu
bin=${1:-./tube74}
browser=$(command -v chromium || command -v chromium-browser)
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
"$bin" teach scenes/fig6.s74 -o "$t" >/dev/null
"$bin" teach scenes/street.s74 -o "$t" >/dev/null
shot() {   # PAGE STEP HEIGHT OUT
  "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --hide-scrollbars --user-data-dir="$t/profile-$2" --window-size=1400,"$3" \
    --screenshot="$4" "file://$t/$1#step=$2" >/dev/null 2>&1
}
shot fig6.html 4 1120 docs/teach-cut.png
shot street.html 7 1120 docs/teach-matrix.png
echo "wrote docs/teach-cut.png and docs/teach-matrix.png"
