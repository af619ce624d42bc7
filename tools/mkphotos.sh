#!/bin/sh
# tools/mkphotos.sh — make the Fig. 10 background photographs (scenes/photo-*.pgm) from
# the sample photographs the Debian package python3-skimage ships (skimage/data), with
# netpbm. The sources and licences (from skimage/data/_fetchers.py, the docstrings):
#   camera.png  "No copyright restrictions. CC0 by the photographer (Lav Varshney)."
#   rocket.jpg  "Launch photo of DSCOVR on Falcon 9 by SpaceX ... released in the public
#               domain" (SpaceX, 2015)
#   grass.png   "... from CC0Textures ... licensed under the Creative Commons CC0 License."
# Each is cut to 4:3 and scaled to 200 x 150 grey samples (as scenes/harbour.pgm), which
# the drum-scanner model then samples (patterns/scanner.h). scenes/README.md records this.
# Usage: sh tools/mkphotos.sh        (needs apt-get download, dpkg-deb and netpbm)
set -eu
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
( cd "$T" && apt-get download python3-skimage >/dev/null 2>&1 )
dpkg-deb -x "$T"/python3-skimage_*.deb "$T/x"
D="$T/x/usr/lib/python3/dist-packages/skimage/data"
dpkg-deb -f "$T"/python3-skimage_*.deb Package Version
# camera: 512 x 512, keep the upper 512 x 384 (the buildings and the sky)
pngtopnm "$D/camera.png" | pamcut -left 0 -top 0 -width 512 -height 384 |
  pamscale -xsize 200 -ysize 150 | pamtopnm | ppmtopgm > scenes/photo-camera.pgm
# rocket: 640 x 427, the middle 568 x 426
jpegtopnm "$D/rocket.jpg" 2>/dev/null | pamcut -left 36 -top 0 -width 568 -height 426 |
  pamscale -xsize 200 -ysize 150 | ppmtopgm > scenes/photo-rocket.pgm
# grass: 512 x 512, the lower 512 x 384
pngtopnm "$D/grass.png" | pamcut -left 0 -top 128 -width 512 -height 384 |
  pamscale -xsize 200 -ysize 150 | pamtopnm | ppmtopgm > scenes/photo-grass.pgm
ls -l scenes/photo-*.pgm
