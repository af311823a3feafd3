#!/usr/bin/env bash
# The main job on a fresh clone: install what is missing, build, then describe the bundled DEM.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
[ -f data/dem/N45E006.hgt ] || build/app/terravol sample-dem -o data/dem
build/app/terravol info data/dem/N45E006.hgt
