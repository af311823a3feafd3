#!/bin/sh
# Makes the two RF path-loss volumes examples/utah-flight.json shows (about 15 s): 600 MHz
# transmitters on Farnsworth Peak (Oquirrh Mountains) and Francis Peak (Wasatch), 60 m masts,
# over the SPLAT! tiles of ../shared/data/dem/utah_sdf. Written to examples/rf/ (generated, not
# committed). Usage: examples/make-utah-volumes.sh [path/to/terravol]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
terravol=${1:-"$here/../build/app/terravol"}
dem="$here/../../shared/data/dem/utah_sdf"
mkdir -p "$here/rf"
"$terravol" rf --tx 40.659,-112.202,60,600 --dem "$dem" -o "$here/rf/farnsworth.vdb" \
    --radius-km 20 --heights 0:3000:150 --force --quiet
"$terravol" rf --tx 41.034,-111.840,60,600 --dem "$dem" -o "$here/rf/francis.vdb" \
    --radius-km 20 --heights 0:3000:150 --force --quiet
