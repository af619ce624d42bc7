#!/bin/sh
# tube74 dependencies: Debian 12 packages, checked through pkg-config and dpkg.
# As root, missing packages are installed; otherwise the exact apt-get line is printed.
set -u
need="pkg-config libpng-dev libcmocka-dev libosmesa6-dev libglu1-mesa-dev libusb-1.0-0-dev libsdl2-dev umockdev libumockdev-dev xvfb xauth jq"
missing=""
for p in $need; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" = 0 ]; then
  echo "tube74: installing missing Debian packages:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq && apt-get install -y -qq $missing >/dev/null || {
    echo "tube74: apt-get install failed for:$missing" >&2; exit 1; }
else
  echo "tube74: missing Debian packages. Install them with:" >&2
  echo "  sudo apt-get install -y$missing" >&2
  exit 1
fi
