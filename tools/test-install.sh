#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs a built tree into a temporary prefix and builds two programs against it out of tree, as
# users would: a C++ one through find_package(cbrdf) that encodes a built-in sample and decodes it,
# and a C one through `pkg-config cbrdf-decoder` that links only the decoder and evaluates a golden
# file. Both run and check their results. Also checks what the shared decoder library needs.
#   Usage: tools/test-install.sh BUILD_DIR        (run by ctest as install_and_consume)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:?usage: test-install.sh BUILD_DIR}" && pwd)
work=$(mktemp -d /tmp/cbrdf-install.XXXXXX)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
echo "test-install: installed into $prefix:"
(cd "$prefix" && find . -type f -o -type l | sort | sed 's/^\.\//  /')
libdir=$(ls -d "$prefix"/lib* | head -n 1)
# The measured samples' weights are compiled into the encoder library; their licence is installed.
[[ -s $prefix/share/doc/cbrdf/measured/LICENSE-nbrdf.txt ]] || {
  echo "test-install: FAILED: share/doc/cbrdf/measured/LICENSE-nbrdf.txt not installed" >&2; exit 1; }

# The decoder's closure: nothing beyond zstd, xxhash, the C/C++ runtime, libm and pthread.
needed=$(readelf -d "$libdir/libcbrdf_decoder.so" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
echo "test-install: libcbrdf_decoder.so needs:" $needed
for lib in $needed; do
  case "$lib" in
    libzstd.so.* | libxxhash.so.* | libstdc++.so.* | libgcc_s.so.* | libc.so.* | libm.so.* | \
      libpthread.so.* | ld-linux*) ;;
    *) echo "test-install: FAILED: libcbrdf_decoder.so needs $lib" >&2; exit 1 ;;
  esac
done
soname=$(readelf -d "$libdir/libcbrdf_decoder.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[[ "$soname" =~ ^libcbrdf_decoder\.so\.[0-9]+$ ]] || {
  echo "test-install: FAILED: SONAME '$soname' is not libcbrdf_decoder.so.MAJOR" >&2; exit 1; }

# C++ through the CMake package.
cmake -S "$root/tests/install/consumer_cpp" -B "$work/cpp" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$work/cpp-configure.log" || {
  cat "$work/cpp-configure.log" >&2; exit 1; }
cmake --build "$work/cpp" > "$work/cpp-build.log" || { cat "$work/cpp-build.log" >&2; exit 1; }
"$work/cpp/consumer_cpp"

# C through pkg-config, decoder only.
export PKG_CONFIG_PATH="$libdir/pkgconfig"
cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/main.c" \
  $(pkg-config --cflags --libs cbrdf-decoder) -lm -Wl,-rpath,"$libdir" -o "$work/consumer_c"
needed_c=$(readelf -d "$work/consumer_c" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
echo "test-install: consumer_c needs: $needed_c"
case " $needed_c " in *libcbrdf_encoder*) echo "test-install: FAILED: the C consumer links the encoder" >&2; exit 1 ;; esac
"$work/consumer_c" "$root/tests/data/golden/v1.1-mixture3-b12.cbrdf"
echo "test-install: passed"
