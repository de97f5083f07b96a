#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The npm package's TypeScript declarations as a consumer sees them: packs WASM_BUILD's staging
# folder (tools/npm/pack.sh, which checks the tarball's file list), unpacks the tarball as
# WORK/node_modules/cbrdf beside this folder's pinned typescript and @types/three (npm ci here:
# tools/scripts/install-deps.sh browser), then type-checks consumer.ts, which uses every export
# of cbrdf, cbrdf/glsl and cbrdf/three, with tools/npm/tsconfig.json's options (the declarations
# themselves checked too) under node's resolution, and under a bundler's (coverage.mjs, which also
# checks that the consumer leaves no export or method unused).
#   usage: tests/npm/types/types_test.sh WASM_BUILD WORK
set -euo pipefail
usage="usage: types_test.sh WASM_BUILD WORK"
build=${1:?$usage}
work=${2:?$usage}
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../../.." && pwd)
fail() { echo "types_test: FAILED: $*" >&2; exit 1; }
tsc=$here/node_modules/typescript/bin/tsc
[[ -f $tsc && -d $here/node_modules/@types/three ]] ||
  fail "no typescript or @types/three in $here/node_modules: run npm ci there" \
       "(tools/scripts/install-deps.sh browser does)"

rm -rf "$work"
mkdir -p "$work/node_modules/cbrdf"
tgz=$("$src/tools/npm/pack.sh" "$build" "$work")
tar -xzf "$tgz" -C "$work/node_modules/cbrdf" --strip-components=1
# The pinned packages by symlink: each resolves its own dependencies from its real folder.
for dep in "$here"/node_modules/* "$here"/node_modules/@*/*; do
  [[ -e $dep && $(basename "$dep") != .* && $(basename "$dep") != @* ]] || continue
  rel=${dep#"$here/node_modules/"}
  mkdir -p "$(dirname "$work/node_modules/$rel")"
  ln -s "$dep" "$work/node_modules/$rel"
done
cp "$here/consumer.ts" "$here/package.json" "$work/"
cat > "$work/tsconfig.json" <<JSON
{ "extends": "$src/tools/npm/tsconfig.json", "files": ["consumer.ts"] }
JSON
echo "types_test: typescript $(node "$tsc" --version), @types/three" \
     "$(node -p "require('$here/node_modules/@types/three/package.json').version")"
# Node's resolution with every declaration checked (about 11 s of CPU, mostly @types/three's);
# then coverage.mjs: a bundler's resolution (Vite, webpack: the exports' types conditions) on the
# consumer, and that it uses every declared export and method (3 s).
start=$(date +%s%N)
(cd "$work" && node "$tsc" -p tsconfig.json) ||
  fail "tsc --noEmit (module and moduleResolution nodenext, declarations checked) reported errors"
echo "types_test: module and moduleResolution nodenext, declarations checked: no errors" \
     "($((($(date +%s%N) - start) / 1000000)) ms)"
node "$here/coverage.mjs" "$work" ||
  fail "consumer.ts does not type-check under a bundler's resolution or leaves part of the API unchecked"
echo "types_test: passed"
