#!/usr/bin/env bash
# Installs missing packages, then configures and builds Terravol into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTERRAVOL_WERROR=ON >/dev/null
cmake --build build -j"$(nproc)"
