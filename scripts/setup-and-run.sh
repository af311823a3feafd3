#!/usr/bin/env bash
# The main job on a fresh clone: install what is missing, build, describe the bundled DEM, then
# render the default scene (terrain and an RF volume) to terravol-default.png (offscreen, in a virtual X
# display when xvfb-run is there).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
[ -f data/dem/N45E006.hgt ] || build/app/terravol sample-dem -o data/dem
build/app/terravol info data/dem/N45E006.hgt
# The default scene (examples/default-scene.json): a transmitter 30 m above the tile's centre
# (900 MHz, 50 W), its path-loss volume from the built-in model, two translucent isosurfaces
# (110 and 130 dB) and a slice 300 m above the ground, seen from 9000 m south-west of it.
build/app/terravol rf --tx 45.5,6.5,30,900,50 --dem data/dem/N45E006.hgt -o build/default-rf.vdb --force
render=(build/app/terravol render --scene examples/default-scene.json -o terravol-default.png --force)
if command -v xvfb-run >/dev/null; then
  xvfb-run -a -s "-screen 0 1920x1080x24" "${render[@]}"
else
  "${render[@]}"
fi
