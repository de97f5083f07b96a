#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing, builds cbrdf, and runs the main job: compress the built-in sample
# materials and print the size/PSNR table.   Usage: tools/quickstart.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
"$root/tools/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCBRDF_TESTS=OFF > /dev/null
cmake --build "$build" --target cbrdf_cli -j "$(nproc)"
echo
"$build/cbrdf" report --builtin -o "$build/report-builtin"
