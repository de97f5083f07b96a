#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds cbrdf and every test with AddressSanitizer + UndefinedBehaviorSanitizer (CMakePresets.json:
# sanitize; clang, or whatever CC and CXX name) and runs the suite under them (test preset
# sanitize). Any sanitizer report fails the test that triggered it (UBSan is built with
# -fno-sanitize-recover, ASan aborts, LeakSanitizer reports at exit).
# The tests labelled slow or wasm are left to the release suite (tools/scripts/run-tests.sh runs it
# first): they repeat, on more or larger data or more often, code paths that other tests run here,
# and CI's 2 cores cannot afford them twice; tests/*/labels.cmake says which and why.
# The viewer's browser test (viewer_browser) runs here, so that `cbrdf view`'s HTTP server is
# checked under ASan: it needs a cbrdf.wasm build, CBRDF_WASM_BUILD_DIR (tools/scripts/run-tests.sh
# passes the release suite's); without one it is left out, with a message.
#   Usage: tools/scripts/run-sanitizers.sh
# CBRDF_BUILD_PREFIX: where the preset's build-sanitize goes (default the repository).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
jobs=$(nproc)
excluded=()
wasm_build_dir=${CBRDF_WASM_BUILD_DIR:-}
if [[ -z $wasm_build_dir || ! -f $wasm_build_dir/wasm/cbrdf.wasm ]]; then
  echo "run-sanitizers: viewer_browser left out: no cbrdf.wasm in CBRDF_WASM_BUILD_DIR" \
       "('${wasm_build_dir}'; tools/scripts/run-tests.sh passes the release build's wasm-build)" >&2
  wasm_build_dir=""
  excluded=(-E '^viewer_browser$')
fi

# CBRDF_RELEASE_CLI (tools/scripts/run-tests.sh passes the release build's cbrdf): the viewer's test
# encodes its files with it, and spends its time here on the server under test.
viewer_encoder=${CBRDF_RELEASE_CLI:-}
if [[ -n $viewer_encoder && ! -x $viewer_encoder ]]; then
  echo "run-sanitizers: CBRDF_RELEASE_CLI '$viewer_encoder' is not an executable" >&2
  exit 1
fi

# The preset: -O1 -g1 without NDEBUG, as the ASan documentation advises (reports carry line
# numbers and asserts are on). Warnings are not errors here: the release build is the warning
# gate, and GCC's flow analysis under sanitizer instrumentation reports false
# -Wmaybe-uninitialized positives inside libstdc++. Clang by default: it builds this faster than
# GCC and its UBSan checks more (pointer overflow, enum values).
compilers=()
[[ -n ${CC:-} ]] && compilers+=("-DCMAKE_C_COMPILER=$CC")
[[ -n ${CXX:-} ]] && compilers+=("-DCMAKE_CXX_COMPILER=$CXX")
cmake --preset sanitize "${compilers[@]}" "-DCBRDF_WASM_BUILD_DIR=${wasm_build_dir}" \
  "-DCBRDF_VIEWER_ENCODER=${viewer_encoder}" > /dev/null
cmake --build --preset sanitize -j "$jobs"

start=$(date +%s)
ctest --preset sanitize -j "$jobs" "${excluded[@]}"
echo "run-sanitizers: the suite passed under ASan + UBSan in $(( $(date +%s) - start )) s"
