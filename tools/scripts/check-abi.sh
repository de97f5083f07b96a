#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Holds the shared libraries' binary interface to the committed baseline (tests/abi/*.abi, written
# by Debian's abigail-tools). Exported functions are the C API only (cmake/cbrdf.map).
#   - A removed function, or a changed signature, struct or enum (abidiff's "incompatible"), fails
#     unless the library's SONAME major differs from the baseline's (CBRDF_ABI_VERSION raised).
#   - The experimental section's functions (tests/abi/experimental.suppr) are not compared.
#   - A compatible change (a function added) fails too, so that the baseline never lags: rerun
#     with --update and commit tests/abi/.
# Usage: tools/scripts/check-abi.sh BUILD_DIR [--update]     (ctest: abi_check)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: check-abi.sh BUILD_DIR [--update]}" && pwd)
update=${2:-}
command -v abidw > /dev/null || { echo "check-abi: abidw not found (Debian: abigail-tools)" >&2; exit 1; }
work=$(mktemp -d /tmp/cbrdf-abi.XXXXXX)
trap 'rm -rf "$work"' EXIT
headers=(--headers-dir "$root/codec/decoder/include/cbrdf")
[[ -d $root/codec/encoder/include/cbrdf ]] && headers+=(--headers-dir "$root/codec/encoder/include/cbrdf")
status=0
checked=0
for lib in decoder encoder; do
  so=$build/libcbrdf_$lib.so
  [[ -e $so ]] || continue
  so=$(readlink -f "$so")
  baseline=$root/tests/abi/libcbrdf_$lib.abi
  abidw --no-corpus-path --no-comp-dir-path --no-show-locs --no-elf-needed --exported-interfaces-only \
    --drop-private-types "${headers[@]}" "$so" > "$work/$lib.abi"
  checked=$((checked + 1))
  if [[ $update == --update ]]; then
    cp "$work/$lib.abi" "$baseline"
    echo "check-abi: wrote tests/abi/libcbrdf_$lib.abi ($(grep -c '<elf-symbol name=' "$baseline") symbols)"
    continue
  fi
  [[ -f $baseline ]] || { echo "check-abi: no baseline tests/abi/libcbrdf_$lib.abi: run with --update" >&2; status=1; continue; }
  rc=0
  abidiff --suppressions "$root/tests/abi/experimental.suppr" "$baseline" "$work/$lib.abi" > "$work/$lib.diff" 2>&1 || rc=$?
  old_soname=$(sed -n "s/.*soname='\([^']*\)'.*/\1/p" "$baseline" | head -n 1)
  new_soname=$(sed -n "s/.*soname='\([^']*\)'.*/\1/p" "$work/$lib.abi" | head -n 1)
  if ((rc == 0)); then
    echo "check-abi: libcbrdf_$lib ($new_soname): no change against the baseline"
  elif ((rc & 8)) && [[ $old_soname == "$new_soname" ]]; then
    cat "$work/$lib.diff" >&2
    echo "check-abi: FAILED: libcbrdf_$lib breaks its ABI under the same SONAME $new_soname;" \
      "keep the old function, or raise CBRDF_ABI_VERSION in CMakeLists.txt and rerun with --update" >&2
    status=1
  elif ((rc & (4 | 8))); then
    cat "$work/$lib.diff" >&2
    echo "check-abi: FAILED: libcbrdf_$lib ($old_soname -> $new_soname) changed its ABI; the" \
      "baseline lags: rerun with --update and commit tests/abi/" >&2
    status=1
  else
    cat "$work/$lib.diff" >&2
    echo "check-abi: FAILED: abidiff could not compare libcbrdf_$lib (exit $rc)" >&2
    status=1
  fi
done
((checked > 0)) || { echo "check-abi: no libcbrdf_*.so in $build (CBRDF_SHARED=OFF?)" >&2; exit 1; }
exit $status
