#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian packages cbrdf needs for a purpose, only those missing. Safe to run
# repeatedly; needs root (or sudo) only when something must be installed.
#   Usage: tools/scripts/install-deps.sh [--list] [PURPOSE...]   (--list: print the packages only)
# PURPOSE (several add up):
#   libraries  build and install the libraries alone (cmake --preset libraries-only without tests)
#   main       the quickstart: build the cbrdf command, compress the built-in materials, report
#   python     the Python module (pip install ., cmake --preset python) and its tests
#   docs       the API reference (cmake --build build --target docs) on top of main
#   wasm       cbrdf.wasm (cmake --preset wasm, tools/wasm) and its node tests
#   browser    the headless chromium tests and the npm package's (the report page, the viewer,
#              tests/npm: npm ci in tests/viewer and tests/npm/types)
#   test       everything CI runs (tools/scripts/run-tests.sh): all of the above and the test,
#              sanitizer, fuzzing, benchmark and ABI tools
# With no PURPOSE: test, everything.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

declare -A groups
groups[build]="build-essential cmake ninja-build pkg-config"
groups[libraries]="${groups[build]} libzstd-dev libxxhash-dev libceres-dev libeigen3-dev"
# The tools' packages (tools/CMakeLists.txt): the report's xz and ZFP baselines, images, meshes,
# the command's options, JSON and formatting, cbrdf view's HTTP server.
groups[main]="${groups[libraries]} liblzma-dev libzfp-dev libopenexr-dev libdraco-dev libpng-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev libcpp-httplib-dev"
groups[python]="${groups[main]} pybind11-dev python3-pybind11 python3-dev python3-numpy
  python3-pytest python3-matplotlib python3-setuptools python3-wheel python3-venv python3-build"
groups[docs]="${groups[main]} doxygen"
# cbrdf.wasm compiles zstd's decompressor from Debian's source package (dpkg-dev, a deb-src entry),
# fetched below into the cache its configure reads.
groups[wasm]="${groups[build]} emscripten nodejs node-acorn dpkg-dev"
# npm: Debian's only where no npm is on the PATH (a machine's own Node.js comes with its own npm,
# which Debian's package conflicts with).
groups[browser]="${groups[main]} chromium nodejs npm"
# The test suites' own tools: GoogleTest, Google Benchmark, clang (the decoder-only, sanitizer and
# fuzz builds, clang-format), abigail-tools (tools/scripts/check-abi.sh), ccache (shared by the
# builds of tools/scripts/run-tests.sh).
groups[test]="${groups[python]} ${groups[docs]} ${groups[wasm]} ${groups[browser]} clang clang-format
  libclang-rt-14-dev libgtest-dev libgmock-dev libbenchmark-dev abigail-tools ccache"

list_only=0
if [[ ${1:-} == --list ]]; then list_only=1; shift; fi
purposes=("$@")
((${#purposes[@]})) || purposes=(test)
packages=()
for purpose in "${purposes[@]}"; do
  if [[ $purpose == build || -z ${groups[$purpose]+set} ]]; then
    echo "install-deps: unknown purpose '$purpose' (libraries, main, python, docs, wasm," \
         "browser, test)" >&2
    exit 2
  fi
  read -r -d '' -a more <<<"${groups[$purpose]}" || true
  packages+=("${more[@]}")
done
mapfile -t packages < <(printf '%s\n' "${packages[@]}" | sort -u)
if ((list_only)); then printf '%s\n' "${packages[@]}"; exit 0; fi
wants() { [[ " ${purposes[*]} " =~ " $1 " || " ${purposes[*]} " =~ " test " ]]; }

sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi

missing=()
for p in "${packages[@]}"; do
  if [[ $p == npm ]] && command -v npm > /dev/null; then continue; fi
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "install-deps: all ${#packages[@]} packages for ${purposes[*]} present"
fi

# cbrdf.wasm's configure fetches nothing: zstd's sources go once into the cache it looks in
# (tools/wasm/fetch-zstd-source.sh, which adds a deb-src entry if apt has none), as the user who
# ran this script through sudo, whose builds read that cache.
if wants wasm; then
  fetch=("$here/../wasm/fetch-zstd-source.sh")
  if [[ $(id -u) -eq 0 && -n ${SUDO_USER:-} && $SUDO_USER != root ]]; then
    "${fetch[0]}" --deb-src-only
    fetch=(sudo -u "$SUDO_USER" -H "${fetch[@]}")
  fi
  echo "install-deps: zstd's sources for cbrdf.wasm in $("${fetch[@]}")"
fi

# The tests' npm packages, each pinned by its package-lock.json and installed there with npm ci
# (when npm ls finds one missing): the viewer's browser tests (tests/viewer: puppeteer-core), the
# npm package's type check (tests/npm/types: typescript, @types/three; about 5 s).
if wants browser; then
  for rel in tests/viewer tests/npm/types; do
    dir=$(cd "$here/../.." && pwd)/$rel
    [[ -f $dir/package-lock.json ]] || continue
    if ! (cd "$dir" && npm ls --depth=0 >/dev/null 2>&1); then
      echo "install-deps: npm ci in $rel"
      (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
    fi
  done
  # The package test (tests/npm: npm_package) installs three from its consumer's lock file into an
  # empty folder each run; with three in npm's cache it runs without the registry.
  three=$(sed -n 's/^ *"three": "\([0-9.]*\)".*/\1/p' "$here/../../tests/npm/consumer/package.json")
  if [[ -n $three ]] && ! npm cache ls "three@$three" 2>/dev/null | grep -q "three"; then
    npm cache add "three@$three" --loglevel=error
  fi
fi
((${#missing[@]} == 0)) || echo "install-deps: done"
