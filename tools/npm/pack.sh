#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Packs the npm package `cbrdf` from a wasm build's staging folder (WASM_BUILD/wasm, filled by the
# build: tools/wasm/CMakeLists.txt) into OUT/cbrdf-<version>.tgz with `npm pack`, and fails unless
# the tarball holds exactly the package's files: package.json, README.md, LICENSE, LICENSE.zstd,
# cbrdf.wasm, the three modules and their declarations, and tools/npm/example/'s files. Prints the
# tarball's path.
#   usage: tools/npm/pack.sh WASM_BUILD OUT
set -euo pipefail
usage="usage: pack.sh WASM_BUILD OUT"
build=${1:?$usage}
out=${2:?$usage}
here=$(cd "$(dirname "$0")" && pwd)
stage=$build/wasm
fail() { echo "pack.sh: FAILED: $*" >&2; exit 1; }
command -v npm > /dev/null || fail "npm not found (Debian: npm, or Node.js's own)"
[[ -f $stage/package.json && -f $stage/cbrdf.wasm ]] ||
  fail "$stage has no package.json and cbrdf.wasm: build the wasm first (tools/wasm/README.md)"
mkdir -p "$out"
out=$(cd "$out" && pwd)

expected=(package.json README.md LICENSE LICENSE.zstd cbrdf.wasm cbrdf.mjs cbrdf.d.ts glsl.mjs
          glsl.d.ts three.mjs three.d.ts)
if [[ -d $here/example ]]; then
  while IFS= read -r f; do expected+=("example/$f"); done < <(cd "$here/example" && find . -type f -printf '%P\n')
fi
for f in "${expected[@]}"; do
  [[ -f $stage/$f ]] || fail "$stage/$f is missing: the build stages it from tools/npm or tools/wasm" \
    "(cmake --build $build)"
done

json=$(cd "$stage" && npm pack --json --pack-destination "$out" --loglevel=error \
  --no-update-notifier --ignore-scripts) || fail "npm pack in $stage failed"
listing=$(node -e '
  const [p] = JSON.parse(process.argv[1]);
  console.log(p.filename, p.size, p.unpackedSize);
  for (const f of p.files) console.log(f.path);' "$json") || fail "npm pack printed no listing"
read -r tgz size unpacked <<< "$(head -n 1 <<< "$listing")"
got=$(tail -n +2 <<< "$listing" | sort)
want=$(printf '%s\n' "${expected[@]}" | sort)
if [[ $got != "$want" ]]; then
  rm -f "${out:?}/$tgz"
  fail "$tgz does not hold exactly the package's files:
$(diff <(echo "$want") <(echo "$got") | grep '^[<>]' | sed 's/^</  missing:/; s/^>/  extra:  /')
(an extra file: one the build staged before its source was removed, to delete from $stage, or a
new file to add to package.json.in's files and to this script's list)"
fi
echo "pack.sh: $out/$tgz: ${#expected[@]} files, $size bytes ($unpacked unpacked)" >&2
echo "$out/$tgz"
