#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The installed `cbrdf view` serves the installed page and cbrdf.wasm with no --viewer or --wasm:
# installs BUILD into a temporary prefix, starts <prefix>/bin/cbrdf view on a free port (with
# CBRDF_VIEWER_DIR and CBRDF_WASM_DIR unset) and fetches /, /app.mjs, /cbrdf.wasm, /cbrdf.mjs,
# /glsl.mjs and /files/0, which must be the installed files byte for byte (the installed page and
# modules carry a marker the source tree's do not, so a command serving the build's folders fails). Then, with the
# installed wasm removed (or none built), the command must refuse with a message naming how to
# build one. WASM_DIRS: the wasm builds `cmake --install` looks in (cmake/install_viewer.cmake);
# when one holds cbrdf.wasm and cbrdf.mjs, the install must hold them too.
#   usage: installed_view_test.sh BUILD_DIR FILE.cbrdf [WASM_DIRS...]
set -euo pipefail
usage="usage: installed_view_test.sh BUILD_DIR FILE.cbrdf [WASM_DIRS...]"
build=${1:?$usage}
file=${2:?$usage}
shift 2
fail() { echo "installed_view_test: FAILED: $*" >&2; exit 1; }
expect_wasm=0
wasm_from=
for dir in "$@"; do
  if [[ -f $dir/cbrdf.wasm && -f $dir/cbrdf.mjs ]]; then
    expect_wasm=1
    wasm_from=$dir
    echo "installed_view_test: a wasm build is in $dir: the install must hold it"
    [[ -f $dir/glsl.mjs ]] || fail "$dir has no glsl.mjs, which the page imports: a wasm build" \
      "older than the npm package's staging; build it again (cmake --build ${dir%/wasm})"
    break
  fi
done
work=$(mktemp -d "${TMPDIR:-/tmp}/cbrdf-installed-view.XXXXXX")
pid=
cleanup() {
  [[ -n $pid ]] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
unset CBRDF_VIEWER_DIR CBRDF_WASM_DIR

prefix=$work/prefix
start=$(date +%s%N)
cmake --install "$build" --prefix "$prefix" > "$work/install.log" ||
  fail "cmake --install failed: $(tail -n 5 "$work/install.log")"
echo "installed_view_test: cmake --install took $((($(date +%s%N) - start) / 1000000)) ms"
share=$prefix/share/cbrdf
[[ -x $prefix/bin/cbrdf ]] || fail "bin/cbrdf not installed"
[[ -f $share/viewer/index.html && -f $share/viewer/app.mjs ]] ||
  fail "the viewer's page is not installed in share/cbrdf/viewer: $(ls "$share" 2>&1)"
# Markers: only the installed copies carry them.
printf '\n<!-- installed -->\n' >> "$share/viewer/index.html"
printf '\n// installed\n' >> "$share/viewer/app.mjs"

# Without an installed cbrdf.wasm: a refusal naming how to build it (not the build tree's wasm).
no_wasm() {
  rm -rf "$share/wasm"
  if "$prefix/bin/cbrdf" view --no-open --port 0 "$file" > "$work/out" 2> "$work/err"; then
    fail "cbrdf view without an installed cbrdf.wasm succeeded"
  fi
  if ! grep -q "made without a WebAssembly build" "$work/err" ||
     ! grep -q "tools/wasm/README.md" "$work/err"; then
    fail "cbrdf view without cbrdf.wasm: unexpected message: $(cat "$work/err")"
  fi
  echo "installed_view_test: without cbrdf.wasm the command says: $(cat "$work/err")"
}
if ((!expect_wasm)); then
  no_wasm
  echo "installed_view_test: passed (no wasm build: the page's files not served)"
  exit 0
fi
[[ -f $share/wasm/cbrdf.wasm && -f $share/wasm/cbrdf.mjs && -f $share/wasm/glsl.mjs ]] ||
  fail "cbrdf.wasm, cbrdf.mjs and glsl.mjs are not installed in share/cbrdf/wasm: $(ls "$share/wasm" 2>&1)"
# The rest of the npm package the build staged (tools/npm/README.md) is installed beside them.
for f in package.json README.md LICENSE LICENSE.zstd cbrdf.d.ts glsl.d.ts three.mjs three.d.ts; do
  if [[ -f $wasm_from/$f ]] && ! cmp -s "$wasm_from/$f" "$share/wasm/$f"; then
    fail "share/cbrdf/wasm/$f is not the npm package's $wasm_from/$f"
  fi
done
printf '\n// installed\n' >> "$share/wasm/cbrdf.mjs"
printf '\n// installed\n' >> "$share/wasm/glsl.mjs"

"$prefix/bin/cbrdf" view --no-open --port 0 "$file" > "$work/out" 2> "$work/err" &
pid=$!
url=
for _ in $(seq 100); do
  url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$work/out" || true)
  [[ -n $url ]] && break
  kill -0 "$pid" 2>/dev/null || fail "the installed cbrdf view exited: $(cat "$work/err")"
  sleep 0.1
done
[[ -n $url ]] || fail "the installed cbrdf view printed no address: $(cat "$work/err")"
# One fetcher for all the paths (a python3 start costs more than the requests).
paths=(/ /app.mjs /cbrdf.wasm /cbrdf.mjs /glsl.mjs /files/0)
expected=("$share/viewer/index.html" "$share/viewer/app.mjs" "$share/wasm/cbrdf.wasm"
          "$share/wasm/cbrdf.mjs" "$share/wasm/glsl.mjs" "$file")
python3 -c 'import sys, urllib.request
for i, path in enumerate(sys.argv[3:]):
    with urllib.request.urlopen(sys.argv[1] + path[1:], timeout=10) as r:
        open("%s/got%d" % (sys.argv[2], i), "wb").write(r.read())' "$url" "$work" "${paths[@]}" ||
  fail "fetching ${paths[*]} from the installed cbrdf view failed"
for i in "${!paths[@]}"; do
  cmp -s "$work/got$i" "${expected[$i]}" ||
    fail "GET ${paths[$i]} is not ${expected[$i]} ($(wc -c < "$work/got$i") bytes)"
  echo "installed_view_test: GET ${paths[$i]} is ${expected[$i]} ($(wc -c < "${expected[$i]}") bytes)"
done
kill "$pid"
wait "$pid" || true
pid=
no_wasm
echo "installed_view_test: passed"
