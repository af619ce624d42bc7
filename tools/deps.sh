#!/bin/sh
# tube74 dependencies: Debian 12 packages, checked through pkg-config and dpkg.
# As root, missing packages are installed; otherwise the exact apt-get line is printed.
#   need       to build tube74 and its tests (missing ones stop the build)
#   testneed   tools some tests drive (gnuplot and plotutils write Tek streams for
#              tests/test_tek_tools.c, Chromium loads the teaching page, xmllint checks the
#              stream SVG previews in tests/test_stream_files.c); without them
#              those tests are skipped (exit 77), so a missing one does not stop the build
set -u
need="pkg-config python3 gnuplot-nox libpng-dev libcmocka-dev libosmesa6-dev libglu1-mesa-dev libusb-1.0-0-dev libsdl2-dev umockdev libumockdev-dev xvfb xauth libgif-dev jq"
testneed="plotutils chromium libxml2-utils"
missing=""
for p in $need; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
tmissing=""
for p in $testneed; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || tmissing="$tmissing $p"
done
[ -z "$missing$tmissing" ] && exit 0
if [ "$(id -u)" = 0 ]; then
  echo "tube74: installing missing Debian packages:$missing$tmissing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq || { echo "tube74: apt-get update failed" >&2; [ -z "$missing" ] || exit 1; exit 0; }
  if [ -n "$missing" ]; then
    apt-get install -y -qq $missing >/dev/null || {
      echo "tube74: apt-get install failed for:$missing" >&2; exit 1; }
  fi
  if [ -n "$tmissing" ]; then
    apt-get install -y -qq $tmissing >/dev/null ||
      echo "tube74: could not install the test tools:$tmissing (their tests will be skipped)" >&2
  fi
else
  if [ -n "$tmissing" ]; then
    echo "tube74: some tests will be skipped without:$tmissing" >&2
    echo "  sudo apt-get install -y$tmissing" >&2
  fi
  if [ -n "$missing" ]; then
    echo "tube74: missing Debian packages. Install them with:" >&2
    echo "  sudo apt-get install -y$missing" >&2
    exit 1
  fi
fi
exit 0
