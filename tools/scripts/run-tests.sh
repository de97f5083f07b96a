#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# CI's test command. Installs what is missing, builds cbrdf with warnings as errors and runs every
# test (CMakePresets.json: release); then builds and tests the decoder alone with clang
# (check-decoder-only.sh) and the libraries without the tools (check-libraries-only.sh), runs the
# suite again under AddressSanitizer + UBSan (run-sanitizers.sh), and replays and fuzzes every
# parser for a bounded time (run-fuzz.sh).   Usage: tools/scripts/run-tests.sh
#   CBRDF_BUILD_PREFIX: where the builds go (default the repository: build, build-decoder,
#     build-libraries-only, build-sanitize; a prefix such as /tmp/x/ gives /tmp/x/build, ...).
#   CBRDF_FUZZ_SECONDS: fuzzing time per target (default 60; 0 replays the corpus only).
#   CBRDF_QUICK=1: the first build and its tests only.
# Tests that need the real materials in ../shared skip with a message when it is absent.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
build=$(realpath -m "${CBRDF_BUILD_PREFIX:-}build")
start=$(date +%s)
tools/scripts/install-deps.sh test
# ccache, when present, is the compiler launcher of every build: the libraries-only build then
# takes the release build's library objects from the cache (same compiler, flags and sources).
if command -v ccache > /dev/null; then
  export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache
  export CCACHE_BASEDIR=$root CCACHE_NOHASHDIR=1
fi
cmake --preset release > /dev/null
cmake --build --preset release -j "$(nproc)"
# python_tests is left out here (test preset release): python_wheel runs the same pytest suite
# against the wheel built from this tree and installed in a fresh virtual environment.
ctest --preset release -j "$(nproc)"
echo "run-tests: release suite passed at $(( $(date +%s) - start )) s"
if [ "${CBRDF_QUICK:-0}" = 1 ]; then exit 0; fi
# The decoder alone, built with clang (the release build above is GCC's): only zstd and xxhash
# looked up, warning-free, its tests, its install and consumers, its ABI. It reuses the release
# build's real-material tables and cbrdf.wasm.
CC=clang CXX=clang++ CBRDF_REAL_MATERIALS_DIR="$build/real-materials" \
  CBRDF_WASM_BUILD_DIR="$build/wasm-build" tools/scripts/check-decoder-only.sh
echo "run-tests: decoder-only build passed at $(( $(date +%s) - start )) s"
# The libraries without the tools: only zstd, xxhash, Ceres and Eigen looked up.
CBRDF_REAL_MATERIALS_DIR="$build/real-materials" tools/scripts/check-libraries-only.sh
echo "run-tests: libraries-only build passed at $(( $(date +%s) - start )) s"
# The sanitizer suite (clang) reuses the release build's real-material tables, their models (for
# the rejected-draw tests) and cbrdf.wasm (for the viewer's test, whose HTTP server it checks
# under ASan).
CBRDF_REAL_MATERIALS_DIR="$build/real-materials" CBRDF_WASM_BUILD_DIR="$build/wasm-build" \
  CBRDF_RELEASE_CLI="$build/cbrdf" CBRDF_REAL_MODELS_DIR="$build/real-models" \
  tools/scripts/run-sanitizers.sh
echo "run-tests: sanitizer suite passed at $(( $(date +%s) - start )) s"
tools/scripts/run-fuzz.sh "${CBRDF_FUZZ_SECONDS:-60}"
echo "run-tests: everything passed in $(( $(date +%s) - start )) s"
