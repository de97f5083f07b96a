#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The decoder-only build, as a renderer's build would make it (preset decoder-only,
# -DCBRDF_DECODER_ONLY=ON): checks from CMake's own trace that the project looked up zstd and
# xxhash and no other package (GoogleTest for the tests aside), builds with warnings as errors,
# runs the decoder's tests (golden files, malformed files, evaluation, sampling, the C API test),
# checks the ABI against the baseline and installs it for the out-of-tree consumers
# (tools/scripts/test-install.sh).
#   Usage: tools/scripts/check-decoder-only.sh
# CBRDF_BUILD_PREFIX: where the preset's build-decoder goes (CMakePresets.json; default the
# repository). CBRDF_WASM_BUILD_DIR: a cbrdf.wasm build to test against this decoder (tests/wasm),
# instead of making one.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
build=$(cd "$root" && realpath -m "${CBRDF_BUILD_PREFIX:-}build-decoder")
lookups=$(tools/scripts/configure-lookups.sh decoder-only "$build" \
  -DCBRDF_WASM_BUILD_DIR="${CBRDF_WASM_BUILD_DIR:-}")
echo "check-decoder-only: the configure step looked up:"
sed 's/^/  /' <<<"$lookups"
allowed='^(find_package\((PkgConfig|Threads|GTest)\)|pkg_check_modules\((ZSTD libzstd|XXHASH libxxhash)\))$'
unexpected=$(grep -Ev "$allowed" <<<"$lookups" || true)
if [[ -n $unexpected ]]; then
  echo "check-decoder-only: FAILED: a decoder-only build looked up more than zstd and xxhash:" >&2
  echo "$unexpected" >&2
  exit 1
fi
grep -q 'pkg_check_modules(ZSTD libzstd)' <<<"$lookups" && grep -q 'pkg_check_modules(XXHASH libxxhash)' <<<"$lookups" || {
  echo "check-decoder-only: FAILED: zstd or xxhash was not looked up (trace format changed?)" >&2; exit 1; }
{ grep '^-- Found\|^--   Found' "$build/configure.log" || true; } | sed 's/^/check-decoder-only: configure: /'
cmake --build --preset decoder-only -j "$(nproc)"
ctest --preset decoder-only -j "$(nproc)"
echo "check-decoder-only: passed"
