#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for SECONDS (default 60), seeded with
# the real files of ../shared/data when present. Findings land in build-fuzz/findings/.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (targets: srtm dted usgs_dem esri_ascii geotiff sdf decompress)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(srtm dted usgs_dem esri_ascii geotiff sdf decompress)
scripts/install-deps.sh
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTERRAVOL_FUZZ=ON >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target $(printf 'fuzz_%s ' "${targets[@]}")
data=../shared/data/dem
mkdir -p build-fuzz/findings
for t in "${targets[@]}"; do
  corpus=build-fuzz/corpus/$t
  mkdir -p "$corpus"
  if [ -d "$data" ]; then
    # Seeds: the real file's first 64 KiB (libFuzzer's -max_len), decompressed where needed.
    case $t in
      srtm) head -c 65536 "$data/N44W072.hgt" > "$corpus/seed" ;;
      dted) head -c 65536 "$data/n33_w116_3arc_v2.dt1" > "$corpus/seed" ;;
      usgs_dem) head -c 65536 "$data/SainteHelens.dem" > "$corpus/seed" ;;
      esri_ascii) head -c 65536 "$data/front_range_srtmgl3.asc" > "$corpus/seed" ;;
      geotiff) cp "$data/olinda_dem_utm25s.tif" "$corpus/seed" ;;
      sdf) (bzcat "$data/utah_sdf/40_41_111_112.sdf.bz2" || true) | head -c 65536 > "$corpus/seed" ;;  # bzcat ends on SIGPIPE
      decompress) head -c 65536 "$data/S46W066.hgt.gz" > "$corpus/seed.gz"; head -c 65536 "$data/utah_sdf/40_41_111_112.sdf.bz2" > "$corpus/seed.bz2"
        head -c 30000 "$data/N44W072.hgt" > "$corpus/N44W072.hgt"
        if command -v xz >/dev/null; then xz -0 -c "$corpus/N44W072.hgt" > "$corpus/seed.xz"; fi
        if command -v zip >/dev/null; then (cd "$corpus" && zip -q seed.zip N44W072.hgt); fi
        rm "$corpus/N44W072.hgt" ;;
    esac
  fi
  echo "== fuzz_$t for ${seconds}s" >&2
  build-fuzz/fuzz/fuzz_$t "$corpus" -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 \
    -timeout=10 -artifact_prefix=build-fuzz/findings/"$t"- -print_final_stats=1 2>&1 |
    grep -E "^(#[0-9]+ +DONE|stat::number_of_executed_units|stat::peak_rss|==[0-9]+==ERROR|SUMMARY|artifact_prefix|Test unit written)" || true
done
ls build-fuzz/findings
