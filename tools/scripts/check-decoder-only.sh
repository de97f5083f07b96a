#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The decoder-only build, as a renderer's build would make it: configures with
# -DCBRDF_DECODER_ONLY=ON, checks from CMake's own trace that the project looked up zstd and xxhash
# and no other package (GoogleTest for the tests aside), builds with warnings as errors, runs the
# decoder's tests (golden files, malformed files, evaluation, sampling, the C API test), checks the
# ABI against the baseline and installs it for the out-of-tree consumers (tools/scripts/test-install.sh).
#   Usage: tools/scripts/check-decoder-only.sh [BUILD_DIR]      (default build-decoder)
# CBRDF_WASM_BUILD_DIR: a cbrdf.wasm build to test against this decoder (tests/wasm), instead of
# making one.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-decoder}
trace=$build/configure-trace.json
mkdir -p "$build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCBRDF_WERROR=ON \
  -DCBRDF_DECODER_ONLY=ON -DCBRDF_TESTS=ON -DCBRDF_WASM_BUILD_DIR="${CBRDF_WASM_BUILD_DIR:-}" \
  --trace-format=json-v1 --trace-redirect="$trace" \
  > "$build/configure.log"
# Every package look-up made from the project's own CMake files.
lookups=$(python3 - "$trace" "$root" <<'PY'
import json, sys
trace, root = sys.argv[1], sys.argv[2].rstrip("/") + "/"
seen = []
for line in open(trace):
    try:
        e = json.loads(line)
    except ValueError:
        continue
    if e.get("cmd", "").lower() in ("find_package", "pkg_check_modules", "pkg_search_module") \
            and e.get("file", "").startswith(root):
        seen.append(f'{e["cmd"].lower()}({e["args"][0]}{" " + e["args"][-1] if e["cmd"].lower() != "find_package" else ""})')
print("\n".join(seen))
PY
)
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
cmake --build "$build" -j "$(nproc)"
ctest --test-dir "$build" --no-tests=error --output-on-failure -j "$(nproc)" --timeout 900
echo "check-decoder-only: passed"
