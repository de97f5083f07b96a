#!/usr/bin/env bash
# Installs what is missing, builds cbrdf with warnings as errors, and runs every test.
#   Usage: tools/run-tests.sh [BUILD_DIR]
# Tests that need the real materials in ../shared skip with a message when it is absent.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCBRDF_WERROR=ON \
  -DCBRDF_BENCH=ON > /dev/null
cmake --build "$build" -j "$(nproc)"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)"
