#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures a preset with CMake's trace on and prints every package look-up made from the
# project's own CMake files, one per line: find_package(NAME) or pkg_check_modules(PREFIX module).
# check-decoder-only.sh and check-libraries-only.sh hold the list to what their build may need.
#   Usage: tools/scripts/configure-lookups.sh PRESET BUILD_DIR [CMAKE_ARGS...]
# The configure output goes to BUILD_DIR/configure.log, the trace to BUILD_DIR/configure-trace.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
preset=${1:?usage: configure-lookups.sh PRESET BUILD_DIR [CMAKE_ARGS...]}
build=${2:?usage: configure-lookups.sh PRESET BUILD_DIR [CMAKE_ARGS...]}
shift 2
mkdir -p "$build"
trace=$build/configure-trace.json
(cd "$root" && cmake --preset "$preset" -B "$build" "$@" --trace-format=json-v1 \
  --trace-redirect="$trace") > "$build/configure.log" || { cat "$build/configure.log" >&2; exit 1; }
python3 - "$trace" "$root" <<'PY'
import json, sys
trace, root = sys.argv[1], sys.argv[2].rstrip("/") + "/"
for line in open(trace):
    try:
        e = json.loads(line)
    except ValueError:
        continue
    cmd = e.get("cmd", "").lower()
    if cmd in ("find_package", "pkg_check_modules", "pkg_search_module") \
            and e.get("file", "").startswith(root):
        print(f'{cmd}({e["args"][0]}{" " + e["args"][-1] if cmd != "find_package" else ""})')
PY
