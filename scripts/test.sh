#!/usr/bin/env bash
# Builds everything (installing missing packages first) and runs the whole test suite
# through ctest, which prints its summary line at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600
