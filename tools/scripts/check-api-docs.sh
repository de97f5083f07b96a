#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The API reference's check (ctest: api_docs): Debian's doxygen over the installed public headers
# (the Doxyfile CMake writes from docs/Doxyfile.in) must print no warning; an undocumented public
# symbol is one. doxygen checks the members of a file only when the file itself is documented, so
# every header must also carry a `@file` comment.
#   Usage: tools/scripts/check-api-docs.sh BUILD_DIR     (writes BUILD_DIR/docs/html)
set -euo pipefail
build=$(cd "${1:?usage: check-api-docs.sh BUILD_DIR}" && pwd)
doxyfile=$build/docs/Doxyfile
command -v doxygen > /dev/null || {
  echo "check-api-docs: doxygen not found (Debian package doxygen; tools/scripts/install-deps.sh)" >&2
  exit 1
}
[[ -f $doxyfile ]] || { echo "check-api-docs: no $doxyfile: configure the build first" >&2; exit 1; }
status=0
read -r -a inputs <<< "$(sed -n 's/^INPUT *= *//p' "$doxyfile")"
headers=0
for f in "${inputs[@]}"; do
  [[ $f == *.h ]] || continue
  headers=$((headers + 1))
  grep -q '@file' "$f" || {
    echo "check-api-docs: $f has no @file comment (its functions and macros would go unchecked)" >&2
    status=1
  }
done
log=$build/docs/doxygen-warnings.txt
rc=0
(cd "$build/docs" && doxygen "$doxyfile") > "$log" 2>&1 || rc=$?
if ((rc != 0)) || [[ -s $log ]]; then
  cat "$log" >&2
  echo "check-api-docs: FAILED: doxygen reported $(grep -c . "$log") lines (exit $rc); document" \
    "every public symbol of the installed headers (/// before it, or ///< after it)" >&2
  status=1
fi
((status == 0)) && echo "check-api-docs: $headers installed headers, no warning: $build/docs/html/index.html"
exit $status
