#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs a built tree into a temporary prefix and builds programs against it out of tree, as
# users would, then runs them as they are, with LD_LIBRARY_PATH unset (the prefix is not a system
# one, so the programs find the shared libraries through the RUNPATH that the .pc files and the
# CMake build give them):
#   - C through `pkg-config cbrdf-decoder`, linked with the shared decoder; through
#     `pkg-config cbrdf-decoder-static`, with libcbrdf_decoder.a (no NEEDED cbrdf entry); fully
#     static (`cc -static`, `pkg-config --static cbrdf-decoder`); and (with an encoder) through
#     `pkg-config cbrdf` (the whole C API from libcbrdf_encoder.so) and `cbrdf-static`;
#   - C through find_package(cbrdf): cbrdf::decoder, run from its build tree and after its own
#     install (CMAKE_INSTALL_RPATH_USE_LINK_PATH), and cbrdf::decoder_static;
#   - C++ through find_package(cbrdf) with no C++ standard flag of its own: the static decoder,
#     and (when the build has an encoder) the static encoder encoding a built-in sample.
# Installed under /usr (DESTDIR), the .pc files carry no rpath.
# Also checks what the shared decoder needs (NEEDED), its SONAME, and that the shared libraries
# export the C API and nothing else.   Usage: tools/scripts/test-install.sh BUILD_DIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: test-install.sh BUILD_DIR}" && pwd)
work=$(mktemp -d /tmp/cbrdf-install.XXXXXX)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { echo "test-install: FAILED: $*" >&2; exit 1; }
needed_of() { readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | tr '\n' ' '; }
runpath_of() { readelf -d "$1" | sed -n 's/.*(\(RUNPATH\|RPATH\)).*\[\(.*\)\]/\2/p'; }
# A program linked with the shared LIB (libcbrdf_decoder or libcbrdf_encoder) finds it through its
# RUNPATH in the installed libdir, with LD_LIBRARY_PATH unset; then runs it with ARGS.
#   check_shared PROGRAM LIB ARGS...
check_shared() {
  local program=$1 lib=$2 name found
  shift 2
  name=$(basename "$program")
  case " $(needed_of "$program") " in *" $lib.so.2 "*) ;; *) fail "$name does not need $lib.so.2" ;; esac
  [[ -n $(runpath_of "$program") ]] || fail "$name has no RUNPATH or RPATH"
  found=$(env -u LD_LIBRARY_PATH ldd "$program" | sed -n "s/^[[:space:]]*$lib\.so\.2 => \([^ ]*\).*/\1/p")
  [[ -n $found && $found != "not" ]] || fail "$name: $lib.so.2 not found without LD_LIBRARY_PATH" \
    "(RUNPATH '$(runpath_of "$program")'; ldd: $(env -u LD_LIBRARY_PATH ldd "$program" | grep cbrdf))"
  [[ $(realpath "$found") == $(realpath "$libdir/$lib.so.2") ]] ||
    fail "$name finds $lib.so.2 at $found, not in $libdir"
  echo "test-install: $name needs $lib.so.2, found at $found through RUNPATH $(runpath_of "$program")"
  env -u LD_LIBRARY_PATH "$program" "$@"
}
# A program linked with a static cbrdf archive: no NEEDED cbrdf entry, every library it needs
# found; then runs it with ARGS, if any.   check_static PROGRAM [ARGS...]
check_static() {
  local program=$1 name
  shift
  name=$(basename "$program")
  case " $(needed_of "$program") " in *libcbrdf*) fail "$name needs $(needed_of "$program")" ;; esac
  if env -u LD_LIBRARY_PATH ldd "$program" | grep -q 'not found'; then
    fail "$name: $(env -u LD_LIBRARY_PATH ldd "$program" | grep 'not found' | tr '\n' ' ')"
  fi
  echo "test-install: $name links cbrdf statically (needs: $(needed_of "$program"))"
  if (($# > 0)); then env -u LD_LIBRARY_PATH "$program" "$@"; fi
}

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
# C through pkg-config, decoder only, shared: runs as built, with nothing set.
cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/main.c" \
  $(pkg-config --cflags --libs cbrdf-decoder) -lm -o "$work/consumer_c"
case " $(needed_of "$work/consumer_c") " in *libcbrdf_encoder*) fail "the C consumer links the encoder" ;; esac
check_shared "$work/consumer_c" libcbrdf_decoder "$golden"
# The static archive, the system libraries shared (pkg-config cbrdf-decoder-static).
cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/main.c" \
  $(pkg-config --cflags --libs cbrdf-decoder-static) -lm -o "$work/consumer_c_archive"
check_static "$work/consumer_c_archive" "$golden"
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
    $(pkg-config --cflags --libs cbrdf) -lm -o "$work/consumer_c_encoder"
  case " $(needed_of "$work/consumer_c_encoder") " in
    *libcbrdf_decoder*) fail "consumer_c_encoder links the decoder beside the encoder" ;;
  esac
  # A 6-slice single-component Frank file: its own table refits within 10% at the test direction.
  check_shared "$work/consumer_c_encoder" libcbrdf_encoder "$root/tests/data/golden/v1.0-frank6-b10.cbrdf"
  cc -std=c99 -Wall -Wextra -Werror -pedantic "$root/tests/install/consumer_c/encoder_main.c" \
    $(pkg-config --cflags --libs cbrdf-static) -lm -o "$work/consumer_c_encoder_archive"
  # Not run: its encode would repeat consumer_c_encoder's (2 s); the C++ consumer runs the archive.
  check_static "$work/consumer_c_encoder_archive"
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
# C through the CMake package: cbrdf::decoder from the consumer's build tree (CMake's build RPATH)
# and from the consumer's own install, whose RUNPATH CMAKE_INSTALL_RPATH_USE_LINK_PATH keeps (set
# in its CMakeLists.txt, as docs/renderer.md tells a consumer to); cbrdf::decoder_static.
check_shared "$work/cpp/consumer_c_shared" libcbrdf_decoder "$golden"
cmake --install "$work/cpp" --prefix "$work/consumer-prefix" > /dev/null
check_shared "$work/consumer-prefix/bin/consumer_c_shared" libcbrdf_decoder "$golden"
check_static "$work/cpp/consumer_c_static" "$golden"

# Installed under /usr, as a distribution package is (DESTDIR), the .pc files carry no rpath:
# the loader finds the libraries there itself.
DESTDIR=$work/stage cmake --install "$build" --prefix /usr > /dev/null
staged_pc=$(ls -d "$work"/stage/usr/lib*/pkgconfig)
for pc in "$staged_pc"/*.pc; do
  libs=$(PKG_CONFIG_PATH=$staged_pc pkg-config --libs "$(basename "$pc" .pc)")
  case "$libs" in *rpath*) fail "$(basename "$pc") installed under /usr gives an rpath: $libs" ;; esac
done
echo "test-install: under /usr, $(cd "$staged_pc" && echo *.pc) give no rpath"
echo "test-install: passed"
