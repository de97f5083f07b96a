#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs a built tree into a temporary prefix and builds programs against it out of tree, as
# users would, then runs them:
#   - C through `pkg-config cbrdf-decoder`, linked with the shared decoder and, fully static
#     (`cc -static`, `pkg-config --static`), with libcbrdf_decoder.a; and (with an encoder) through
#     `pkg-config cbrdf`, the whole C API from libcbrdf_encoder.so;
#   - C++ through find_package(cbrdf) with no C++ standard flag of its own: the static decoder,
#     and (when the build has an encoder) the static encoder encoding a built-in sample.
# Also checks what the shared decoder needs (NEEDED), its SONAME, and that the shared libraries
# export the C API and nothing else.   Usage: tools/scripts/test-install.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: test-install.sh BUILD_DIR}" && pwd)
work=$(mktemp -d /tmp/cbrdf-install.XXXXXX)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { echo "test-install: FAILED: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
echo "test-install: installed into $prefix:"
(cd "$prefix" && find . -type f -o -type l | sort | sed 's/^\.\//  /')
libdir=$(ls -d "$prefix"/lib* | head -n 1)
has_encoder=0
[[ -e $libdir/libcbrdf_encoder.a ]] && has_encoder=1
if ((has_encoder)); then
  # The measured samples' weights are compiled into the encoder library; their licence is installed.
  [[ -s $prefix/share/doc/cbrdf/measured/LICENSE-nbrdf.txt ]] ||
    fail "share/doc/cbrdf/measured/LICENSE-nbrdf.txt not installed"
fi

# The decoder's closure: nothing beyond zstd, xxhash, the C/C++ runtime, libm and pthread.
needed=$(readelf -d "$libdir/libcbrdf_decoder.so" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
echo "test-install: libcbrdf_decoder.so needs:" $needed
for lib in $needed; do
  case "$lib" in
    libzstd.so.* | libxxhash.so.* | libstdc++.so.* | libgcc_s.so.* | libc.so.* | libm.so.* | \
      libpthread.so.* | ld-linux*) ;;
    *) fail "libcbrdf_decoder.so needs $lib" ;;
  esac
done
# Only the C API is exported (cmake/cbrdf.map): every other name would be an ABI promise.
for lib in "$libdir"/libcbrdf_*.so; do
  soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
  base=$(basename "$lib")
  [[ "$soname" =~ ^${base}\.[0-9]+$ ]] || fail "SONAME '$soname' of $base is not $base.MAJOR"
  exports=$(nm -D --defined-only "$lib" | awk '{print $3}')
  others=$(grep -v '^cbrdf_' <<<"$exports" || true)
  [[ -z $others ]] || fail "$base exports names outside the C API: $(head -5 <<<"$others" | tr '\n' ' ')"
  echo "test-install: $base ($soname) exports $(wc -l <<<"$exports") functions, all cbrdf_*"
done

export PKG_CONFIG_PATH="$libdir/pkgconfig"
golden=$root/tests/data/golden/v1.1-mixture3-b12.cbrdf
# C through pkg-config, decoder only, shared.
cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/main.c" \
  $(pkg-config --cflags --libs cbrdf-decoder) -lm -Wl,-rpath,"$libdir" -o "$work/consumer_c"
needed_c=$(readelf -d "$work/consumer_c" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
echo "test-install: consumer_c needs: $needed_c"
case " $needed_c " in *libcbrdf_decoder.so*) ;; *) fail "consumer_c does not link libcbrdf_decoder.so" ;; esac
case " $needed_c " in *libcbrdf_encoder*) fail "the C consumer links the encoder" ;; esac
"$work/consumer_c" "$golden"
# The same, fully static: everything it needs must come from pkg-config --static.
cc -std=c99 -static "$root/tests/install/consumer_c/main.c" \
  $(pkg-config --static --cflags --libs cbrdf-decoder) -lm -o "$work/consumer_c_static" \
  2> "$work/static-link.log" || { cat "$work/static-link.log" >&2; fail "static link of consumer_c"; }
if readelf -d "$work/consumer_c_static" | grep -q NEEDED; then fail "consumer_c_static is not static"; fi
echo "test-install: consumer_c_static links statically (pkg-config --static --libs cbrdf-decoder:" \
  "$(pkg-config --static --libs cbrdf-decoder))"
"$work/consumer_c_static" "$golden"

# C through pkg-config cbrdf: the whole C API from libcbrdf_encoder alone.
if ((has_encoder)); then
  cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/encoder_main.c" \
    $(pkg-config --cflags --libs cbrdf) -lm -Wl,-rpath,"$libdir" -o "$work/consumer_c_encoder"
  needed_e=$(readelf -d "$work/consumer_c_encoder" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' ')
  echo "test-install: consumer_c_encoder needs: $needed_e"
  case " $needed_e " in *libcbrdf_decoder*) fail "consumer_c_encoder links the decoder beside the encoder" ;; esac
  # A 6-slice single-component Frank file: its own table refits within 10% at the test direction.
  "$work/consumer_c_encoder" "$root/tests/data/golden/v1.0-frank6-b10.cbrdf"
fi

# C++ through the CMake package, on a pkg-config that knows no package at all: the package itself
# must not need zstd's or xxhash's .pc files.
mkdir -p "$work/no-pc"
PKG_CONFIG_LIBDIR=$work/no-pc PKG_CONFIG_PATH= \
  cmake -S "$root/tests/install/consumer_cpp" -B "$work/cpp" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCBRDF_CONSUMER_ENCODER=$((has_encoder ? 1 : 0)) \
  > "$work/cpp-configure.log" 2>&1 || { cat "$work/cpp-configure.log" >&2; fail "configure"; }
cmake --build "$work/cpp" > "$work/cpp-build.log" 2>&1 || { cat "$work/cpp-build.log" >&2; fail "C++ build"; }
"$work/cpp/consumer_cpp_decoder" "$golden"
if ((has_encoder)); then "$work/cpp/consumer_cpp"; fi
echo "test-install: passed"
