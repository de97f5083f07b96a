#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian packages cbrdf needs, only when one is missing.
# Safe to run repeatedly; needs root (or sudo) only when something must be installed.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang clang-format libclang-rt-14-dev
  libzstd-dev liblzma-dev libxxhash-dev
  libzfp-dev  # the report's ZFP baseline (cbrdf report --ladder)
  libopenexr-dev libdraco-dev libpng-dev
  libceres-dev libeigen3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libcpp-httplib-dev  # cbrdf view's HTTP server (tools/cli/view_server.cc)
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest python3-matplotlib
  python3-setuptools python3-wheel python3-venv python3-build  # pip install . (pyproject.toml)
  chromium  # headless check of the report page (tests/tools/report_html_test.cc)
  abigail-tools  # the ABI check of the shared libraries (tools/scripts/check-abi.sh)
  doxygen  # the API reference and its check (docs/Doxyfile.in, tools/scripts/check-api-docs.sh)
  emscripten nodejs node-acorn dpkg-dev  # cbrdf.wasm and its node tests (tools/wasm, tests/wasm)
)

# The WebAssembly build compiles zstd's decompressor from Debian's source package, which needs a
# deb-src entry (the build fetches the sources into its own tree: tools/wasm/fetch-zstd-source.sh).
"$(dirname "$0")/../wasm/fetch-zstd-source.sh" --deb-src-only

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# The viewer's browser tests (tests/viewer) drive chromium with puppeteer-core, pinned in
# tests/viewer/package-lock.json: installed there with npm (Debian's npm where none is present).
viewer_npm() {
  local dir
  dir="$(cd "$(dirname "$0")/../../tests/viewer" && pwd)"
  if ! command -v npm >/dev/null; then
    ${sudo:-} apt-get install -y -qq --no-install-recommends npm >/dev/null
  fi
  if ! (cd "$dir" && npm ls puppeteer-core >/dev/null 2>&1); then
    echo "install-deps: npm ci in tests/viewer"
    (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error)
  fi
}

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  sudo=""
  if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
  viewer_npm
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
viewer_npm
echo "install-deps: done"
