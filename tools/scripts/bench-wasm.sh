#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# cbrdf.wasm against the native library in one run: evaluation time per pair of both on the same
# pairs through cbrdf_model_eval_batch (one thread each, alternated three times; the medians'
# ratio: tests/wasm/bench.mjs), and cbrdf.wasm's size, plain and gzip -9.
#   usage: tools/scripts/bench-wasm.sh NATIVE_BUILD WASM_BUILD [FILE.cbrdf] [PAIRS] [MS]
#   NATIVE_BUILD: a build with CBRDF_TESTS=ON (its tests/wasm/wasm_reference is built here);
#   WASM_BUILD: an Emscripten build (tools/wasm/README.md); FILE: default the paper's model
#   (tests/data/golden/v1.0-frank6-b10.cbrdf); PAIRS: default 65536; MS: per measurement, 2000.
# A GCC build evaluates with AVX-512 or AVX2 kernels where the CPU has them (8 or 4 doubles a
# vector); a clang build has only the baseline x86-64 kernels (SSE2, 2 doubles, as SIMD128):
#   CC=clang CXX=clang++ cmake -S . -B build-clang -G Ninja -DCMAKE_BUILD_TYPE=Release \
#     -DCBRDF_DECODER_ONLY=ON -DCBRDF_SHARED=OFF     # then: bench-wasm.sh build-clang WASM_BUILD
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
native=${1:?usage: bench-wasm.sh NATIVE_BUILD WASM_BUILD [FILE.cbrdf] [PAIRS] [MS]}
wasm=${2:?usage: bench-wasm.sh NATIVE_BUILD WASM_BUILD [FILE.cbrdf] [PAIRS] [MS]}
file=${3:-$root/tests/data/golden/v1.0-frank6-b10.cbrdf}
module=$wasm/wasm/cbrdf.wasm
if [[ ! -f $module ]]; then
  echo "bench-wasm: no $module (build it: tools/wasm/README.md)" >&2
  exit 1
fi
cmake --build "$native" --target wasm_reference >/dev/null
bytes=$(stat -c %s "$module")
gzipped=$(gzip -9c "$module" | wc -c)
echo "cbrdf.wasm: $bytes bytes, $gzipped gzipped (gzip -9)"
compiler=$(sed -n 's/^set(CMAKE_CXX_COMPILER_ID "\(.*\)")$/\1/p' "$native"/CMakeFiles/*/CMakeCXXCompiler.cmake |
           head -1)
kernels="baseline kernels"
if [[ $compiler == GNU ]]; then kernels="AVX-512 or AVX2 kernels where the CPU has them"; fi
echo "native: $compiler build $native ($kernels)"
node --no-experimental-fetch "$root/tests/wasm/bench.mjs" "$wasm/wasm/cbrdf.mjs" \
  "$native/tests/wasm/wasm_reference" "$file" "${4:-65536}" "${5:-2000}"
