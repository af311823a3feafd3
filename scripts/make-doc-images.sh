#!/usr/bin/env bash
# Renders the images of docs/images/ from ../shared/data (N44W072, White Mountains) and the
# bundled DEM. Needs a built terravol (scripts/build.sh) and runs under xvfb-run.
set -euo pipefail
cd "$(dirname "$0")/.."
dem=../shared/data/dem/N44W072.hgt
[ -f "$dem" ] || { echo "make-doc-images: $dem not found (needs ../shared/data)" >&2; exit 1; }
mkdir -p docs/images
run() { xvfb-run -a -s "-screen 0 1920x1080x24" build/app/terravol render "$@" --size 960x540 --force; }
run "$dem" --camera 44.02,-71.78,9000,35,-30 -o docs/images/overview.png
run "$dem" --camera 44.12,-71.5,2200,40,-5 -o docs/images/low-oblique.png
run "$dem" --camera 44.12,-71.5,2200,40,-5 --lod-colors -o docs/images/lod-colors.png
run "$dem" --camera 44.2,-71.35,1800,20,-12 --wireframe --background 255,255,255 -o docs/images/wireframe.png
# The main command's scene (its volume from terravol rf), and three overlapping volumes over
# N44W072 as scripts/exactness.sh makes them.
build/app/terravol rf --quiet --tx 45.5,6.5,30,900,50 --dem data/dem/N45E006.hgt -o build/default-rf.vdb --force
xvfb-run -a -s "-screen 0 1920x1080x24" build/app/terravol render --scene examples/default-scene.json \
  -o docs/images/default-scene.png --force
scripts/exactness.sh build/exactness
cp build/exactness/n44w072-bsp.png docs/images/three-volumes.png
