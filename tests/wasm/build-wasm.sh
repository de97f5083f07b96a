#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Configures and builds cbrdf.wasm and cbrdf.mjs (tools/wasm/) with Emscripten into DIR/wasm.
#   usage: tests/wasm/build-wasm.sh SOURCE_DIR DIR [extra cmake arguments]
set -euo pipefail
src=${1:?usage: build-wasm.sh SOURCE_DIR DIR}
dir=${2:?usage: build-wasm.sh SOURCE_DIR DIR}
shift 2
# Debian's emscripten runs its JavaScript optimizer with Debian's node-acorn.
export NODE_PATH=${NODE_PATH:+$NODE_PATH:}/usr/share/nodejs
generator=()
if command -v ninja >/dev/null; then generator=(-G Ninja); fi
emcmake cmake -S "$src" -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCBRDF_DECODER_ONLY=ON -DCBRDF_WERROR=ON "$@"
cmake --build "$dir" -j "${CBRDF_WASM_JOBS:-2}"
ls -l "$dir/wasm/cbrdf.wasm" "$dir/wasm/cbrdf.mjs"
