#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing, builds cbrdf with warnings as errors and runs every test; then builds
# and tests the decoder alone with clang (tools/scripts/check-decoder-only.sh), runs the suite again under
# AddressSanitizer + UBSan, and replays and fuzzes every parser for a bounded time.   Usage: tools/scripts/run-tests.sh [BUILD_DIR]
#   CBRDF_FUZZ_SECONDS: fuzzing time per target (default 60; 0 replays the corpus only).
#   CBRDF_QUICK=1: the first build and its tests only.
# Tests that need the real materials in ../shared skip with a message when it is absent.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
start=$(date +%s)
"$root/tools/scripts/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCBRDF_WERROR=ON -DCBRDF_TESTS=ON \
  -DCBRDF_BENCH=ON -DCBRDF_PYTHON=ON > /dev/null
cmake --build "$build" -j "$(nproc)"
# python_tests is left out here: python_wheel runs the same pytest suite against the wheel built
# from this tree and installed in a fresh virtual environment (ctest -R python_tests runs it
# against the build tree, for development).
ctest --test-dir "$build" --no-tests=error --output-on-failure -j "$(nproc)" --timeout 900 \
  -E '^python_tests$'
echo "run-tests: release suite passed at $(( $(date +%s) - start )) s"
if [ "${CBRDF_QUICK:-0}" = 1 ]; then exit 0; fi
# The decoder alone, built with clang (the release build above is GCC's): only zstd and xxhash
# looked up, warning-free, its tests, its install and consumers, its ABI. It reuses the release
# build's real-material tables (making them again took 37 s of its tests) and cbrdf.wasm.
CC=clang CXX=clang++ CBRDF_REAL_MATERIALS_DIR="$build/real-materials" \
  CBRDF_WASM_BUILD_DIR="$build/wasm-build" "$root/tools/scripts/check-decoder-only.sh" "$build-decoder"
echo "run-tests: decoder-only build passed at $(( $(date +%s) - start )) s"
# The sanitizer suite (clang) reuses the release build's real-material tables and cbrdf.wasm (for
# the viewer's test, whose HTTP server it checks under ASan).
CBRDF_REAL_MATERIALS_DIR="$build/real-materials" CBRDF_WASM_BUILD_DIR="$build/wasm-build" \
  CBRDF_RELEASE_CLI="$build/cbrdf" "$root/tools/scripts/run-sanitizers.sh" "$build-sanitize"
echo "run-tests: sanitizer suite passed at $(( $(date +%s) - start )) s"
"$root/tools/scripts/run-fuzz.sh" "${CBRDF_FUZZ_SECONDS:-60}"
echo "run-tests: everything passed in $(( $(date +%s) - start )) s"
