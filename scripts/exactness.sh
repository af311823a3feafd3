#!/usr/bin/env bash
# The exactness figures of docs/exactness.md on the shared data: three overlapping RF volumes
# (two isosurfaces each, opacity 0.3-0.6) and a slice, over N44W072 and over the Utah mosaic,
# drawn in the tree's order (bsp), by VTK's exact depth peeling (peel: the reference), by VTK's
# default translucency (vtk) and with vtkDepthSortPolyData (sort). Prints, per scene, the share
# of pixels within 3/255 of the reference and the merge figures. Usage:
#   scripts/exactness.sh [OUT_DIR]      (default build/exactness; needs ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/exactness}
shared=${TERRAVOL_SHARED:-../shared/data}
[ -d "$shared/dem" ] || { echo "exactness.sh: $shared/dem not found (the shared data)" >&2; exit 1; }
t=build/app/terravol
[ -x $t ] || scripts/build.sh
mkdir -p "$out"
x=()
command -v xvfb-run >/dev/null && x=(xvfb-run -a -s "-screen 0 1920x1080x24")

# scene NAME DEM CAMERA TX1 TX2 TX3
scene() {
  local name=$1 dem=$2 camera=$3
  shift 3
  local k=0
  for tx in "$@"; do
    $t rf --quiet --tx "$tx" --dem "$dem" --radius-km 12 --heights 0:2000:100 -o "$out/$name-rf$k.vdb" --force >/dev/null
    k=$((k + 1))
  done
  cat >"$out/$name.json" <<JSON
{"dem": ["$(realpath "$dem")"], "volumes": [
  {"file": "$name-rf0.vdb", "isosurfaces": [{"value": 105, "opacity": 0.4}, {"value": 125, "opacity": 0.3}],
   "slices": [{"agl": 400, "opacity": 0.5, "colormap": "viridis", "range": [80, 160]}]},
  {"file": "$name-rf1.vdb", "isosurfaces": [{"value": 110, "opacity": 0.6}, {"value": 120, "opacity": 0.35}]},
  {"file": "$name-rf2.vdb", "isosurfaces": [{"value": 100, "opacity": 0.5}, {"value": 115, "opacity": 0.45}]}],
 "camera": $camera}
JSON
  for order in bsp peel vtk sort; do
    "${x[@]}" $t render --scene "$out/$name.json" --order $order -o "$out/$name-$order.png" --force \
      --stats "$out/$name-$order-stats.json" >"$out/$name-$order.log"
  done
  echo "$name: $(grep '^volumes:' "$out/$name-bsp.log")"
  for order in bsp vtk sort; do
    printf '  %-4s against peel: ' $order
    $t compare-images "$out/$name-peel.png" "$out/$name-$order.png" --tolerance 3
  done
}

scene n44w072 "$shared/dem/N44W072.hgt" \
  '{"lat": 44.12, "lon": -71.55, "alt": 3000, "heading": 40, "pitch": -15}' \
  44.27,-71.30,30 44.32,-71.22,60 44.22,-71.20,20
scene utah "$shared/dem/utah_sdf" \
  '{"lat": 40.45, "lon": -112.05, "alt": 4500, "heading": 35, "pitch": -14}' \
  40.6589,-112.2019,30 40.76,-111.89,30 40.60,-111.80,40
