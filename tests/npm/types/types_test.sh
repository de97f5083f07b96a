#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The npm package's TypeScript declarations as a consumer sees them: packs WASM_BUILD's staging
# folder (tools/npm/pack.sh, which checks the tarball's file list), unpacks the tarball as
# WORK/node_modules/cbrdf beside this folder's pinned typescript and @types/three (npm ci here:
# tools/scripts/install-deps.sh browser), then type-checks consumer.ts, which uses every export
# of cbrdf, cbrdf/glsl and cbrdf/three, with tools/npm/tsconfig.json's options (the declarations
# themselves checked too under node's resolution), and under a bundler's.
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
# Node's resolution with every declaration checked (about 11 s of CPU, mostly @types/three's),
# then a bundler's (Vite, webpack: the exports' types conditions) on the consumer alone (3 s).
status=0
for pass in "nodenext nodenext false" "esnext bundler true"; do
  read -r module res skip <<< "$pass"
  start=$(date +%s%N)
  if (cd "$work" && node "$tsc" -p tsconfig.json --module "$module" --moduleResolution "$res" \
        --skipLibCheck "$skip"); then
    echo "types_test: module $module, moduleResolution $res, skipLibCheck $skip: no errors" \
         "($((($(date +%s%N) - start) / 1000000)) ms)"
  else
    echo "types_test: module $module, moduleResolution $res: errors above" >&2
    status=1
  fi
done
((status == 0)) || fail "tsc --noEmit reported errors"
echo "types_test: passed"
