#!/usr/bin/env bash
# The main job on a fresh clone: install what is missing, build, describe the bundled DEM, then
# render the default terrain view of it to terravol-default.png (offscreen, in a virtual X
# display when xvfb-run is there).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
[ -f data/dem/N45E006.hgt ] || build/app/terravol sample-dem -o data/dem
build/app/terravol info data/dem/N45E006.hgt
# 7000 m above the south-west of the tile, looking north-east over the lake basin and the ridges.
render=(build/app/terravol render data/dem/N45E006.hgt --camera 45.02,6.1,7000,40,-22
        -o terravol-default.png --force)
if command -v xvfb-run >/dev/null; then
  xvfb-run -a -s "-screen 0 1920x1080x24" "${render[@]}"
else
  "${render[@]}"
fi
