#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Readers in the decoder, writers in the encoder: fails when the decoder's static archive
# (libcbrdf_decoder.a) or shared library (libcbrdf_decoder.so, every symbol table it has, not only
# the exported C API) defines a function of a cbrdf namespace whose name starts with encode_,
# write_ or fit_: the chunk payloads' writers, the exact table's writer and the residual
# prediction's fit belong to libcbrdf_encoder (codec/encoder/src/bitstream/).
#
# Allowed, because libcbrdf_decoder.a carries the format layer too and these write no chunk
# payload (a program that only decodes still needs them):
#   write_merl         format/: the MERL .binary writer, the decoder's output (cbrdf_model_write_merl)
#   write_file_atomic  format/: whole-file replace by rename, which write_merl writes through
#   write_container    format/: the container's framing (signature, chunk headers, zstd, XXH64)
#                      around payloads it is given; public in cbrdf/container.h, a layer below
#                      every chunk's writer
# Usage: tools/scripts/check-decoder-symbols.sh BUILD_DIR     (ctest: decoder_symbols)
set -euo pipefail
build=$(cd "${1:?usage: check-decoder-symbols.sh BUILD_DIR}" && pwd)
allowed='^cbrdf::(write_merl|write_file_atomic|write_container)$'
command -v nm > /dev/null || { echo "check-decoder-symbols: nm not found (Debian: binutils)" >&2; exit 1; }

libs=()
[[ -e $build/libcbrdf_decoder.a ]] && libs+=("$build/libcbrdf_decoder.a")
[[ -e $build/libcbrdf_decoder.so ]] && libs+=("$(readlink -f "$build/libcbrdf_decoder.so")")
((${#libs[@]} > 0)) || { echo "check-decoder-symbols: no libcbrdf_decoder.a or .so in $build" >&2; exit 1; }

status=0
for lib in "${libs[@]}"; do
  # Defined symbols only (a reference to a writer is not one); the .so's full table and its
  # dynamic one (a stripped .so has only the latter).
  symbols=$( { nm -C --defined-only "$lib" 2> /dev/null || true; nm -C -D --defined-only "$lib" 2> /dev/null || true; } |
             sed -n 's/^[0-9a-fA-F]* *[A-Za-z] //p' | sort -u)
  [[ -n $symbols ]] || { echo "check-decoder-symbols: nm found no symbols in $lib" >&2; status=1; continue; }
  # Every cbrdf-qualified name in a symbol (a lambda's or a std::function handler's included) that
  # starts with a writer's prefix, minus the allowed ones.
  bad=$(grep -oE 'cbrdf::([A-Za-z_][A-Za-z0-9_]*::)*(encode_|write_|fit_)[A-Za-z0-9_]*' <<< "$symbols" |
        sort -u | grep -vE "$allowed" || true)
  if [[ -n $bad ]]; then
    echo "check-decoder-symbols: $(basename "$lib") defines writers, which belong to the encoder:" >&2
    while IFS= read -r name; do
      echo "  $name:" >&2
      { grep -F "$name" <<< "$symbols" || true; } | head -n 3 | sed 's/^/    /' >&2
    done <<< "$bad"
    status=1
  else
    echo "check-decoder-symbols: $(basename "$lib"): no writer ($(wc -l <<< "$symbols") symbols)"
  fi
done
exit $status
