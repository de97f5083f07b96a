#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The libraries without the tools, as a project that embeds cbrdf would build them (preset
# libraries-only, -DCBRDF_BUILD_TOOLS=OFF): checks from CMake's own trace that the project looked
# up zstd, xxhash, Ceres and Eigen and no other package (Threads, PkgConfig and GoogleTest for the
# tests aside), builds the libraries with warnings as errors, runs the tests this configuration
# can differ in (the C API from C, the golden files, the install consumed from outside; the release
# suite runs every test on the same library sources) and installs. `cmake --build --preset
# libraries-only && ctest --preset libraries-only` builds and runs all the libraries' tests.
#   Usage: tools/scripts/check-libraries-only.sh
# CBRDF_BUILD_PREFIX: where the preset's build-libraries-only goes (default the repository).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
build=$(realpath -m "${CBRDF_BUILD_PREFIX:-}build-libraries-only")
lookups=$(tools/scripts/configure-lookups.sh libraries-only "$build")
echo "check-libraries-only: the configure step looked up:"
sed 's/^/  /' <<<"$lookups"
allowed='^(find_package\((PkgConfig|Threads|GTest|Ceres|Eigen3)\)|pkg_check_modules\((ZSTD libzstd|XXHASH libxxhash)\))$'
unexpected=$(grep -Ev "$allowed" <<<"$lookups" || true)
if [[ -n $unexpected ]]; then
  echo "check-libraries-only: FAILED: a build without the tools looked up more than zstd," \
       "xxhash, Ceres and Eigen:" >&2
  echo "$unexpected" >&2
  exit 1
fi
for needed in 'pkg_check_modules(ZSTD libzstd)' 'pkg_check_modules(XXHASH libxxhash)' \
              'find_package(Ceres)' 'find_package(Eigen3)'; do
  grep -qF "$needed" <<<"$lookups" || {
    echo "check-libraries-only: FAILED: $needed was not in the trace (trace format changed?)" >&2
    exit 1; }
done
# The libraries (static and shared) and the tests run below: each test executable costs compile
# time that the release build has already spent on the same sources.
tests=(c_api_test codec_io_test container_test base_coding_test status_macros_test)
cmake --build --preset libraries-only -j "$(nproc)" --target cbrdf_decoder cbrdf_encoder \
  cbrdf_decoder_shared cbrdf_encoder_shared "${tests[@]}"
for tool in cbrdf libcbrdf_extras.a; do
  if [[ -e $build/$tool ]]; then
    echo "check-libraries-only: FAILED: $tool was built without the tools" >&2
    exit 1
  fi
done
ctest --preset libraries-only -j "$(nproc)" \
  -R '^(c_api_test|install_and_consume|CodecIo|Container\.|BaseCoding|StatusMacros)'
prefix=$(mktemp -d /tmp/cbrdf-libraries.XXXXXX)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > /dev/null
for f in 'lib*/libcbrdf_decoder.a' 'lib*/libcbrdf_encoder.a' 'lib*/libcbrdf_encoder.so' \
         include/cbrdf/cbrdf.h 'lib*/cmake/cbrdf/cbrdfConfig.cmake'; do
  compgen -G "$prefix/$f" > /dev/null ||
    { echo "check-libraries-only: FAILED: $f not installed" >&2; exit 1; }
done
[[ ! -e $prefix/bin/cbrdf ]] || { echo "check-libraries-only: FAILED: bin/cbrdf installed" >&2; exit 1; }
echo "check-libraries-only: passed"
